"""Times the peers of neurotex's hot stages on this machine, for ratios against the
criterion benches (run both back to back on one host: these machines are noisy).

    python -m venv /tmp/peers && /tmp/peers/bin/pip install numpy scikit-learn \
        six pykwalify pywavelets simpleitk setuptools wheel versioneer
    # pyradiomics 3.0.1 from its sdist, as docs/correctness.md shows
    /tmp/peers/bin/python crates/neurotex-bench/benches/peers/peers.py [--data DIR] [--cli PATH]

Prints one line per stage with the median time and the work size. With `--data` (a folder
written by `neurotex simulate --out DIR`, the paper's 480 recordings by default; scipy
needed) it also times the whole path from files to 3D-GLCM features: the `neurotex
features` process against the numpy/scipy pipeline of `numpy_pipeline.py` reading the same
files, run alternately so that the machine's other load falls on both.
"""
import argparse
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
REPO = HERE.parents[3]
ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
ap.add_argument("--data", help="a `neurotex simulate` folder for the whole-path case")
ap.add_argument("--cli", default=str(REPO / "target" / "release" / "neurotex"))
ap.add_argument("--repeats", type=int, default=5, help="whole path: neurotex runs")
ap.add_argument("--peer-repeats", type=int, default=3, help="whole path: numpy runs")
args = ap.parse_args()


def median_time(fn, repeats):
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


# Izhikevich, batched over neurons with numpy (the reference scheme, f64)
def izhikevich(current):
    a, b, c, d = 0.02, 0.2, -65.0, 8.0
    v = np.full(current.shape[1], c)
    u = b * v
    fired_total = 0
    for i in current:
        fired = v >= 30
        fired_total += int(fired.sum())
        v = np.where(fired, c, v)
        u = np.where(fired, u + d, u)
        v = v + 0.5 * (0.04 * v ** 2 + 5 * v + 140 - u + i)
        v = v + 0.5 * (0.04 * v ** 2 + 5 * v + 140 - u + i)
        u = u + a * (b * v - u)
    return fired_total

neurons, steps = 480 * 16, 2000
current = 8.0 * np.random.default_rng(0).random((steps, neurons))
t = median_time(lambda: izhikevich(current), 3)
print(f"numpy izhikevich: {neurons * steps / t / 1e6:.1f} M neuron-steps/s ({neurons} neurons x {steps} steps, median of 3)")

# 3D GLCM + contrast, correlation, ASM on a 4x4x90 volume (pyradiomics 3.0.1)
try:
    import SimpleITK as sitk
    from radiomics import glcm
    vol = np.random.default_rng(1).integers(1, 17, size=(4, 4, 90)).astype(np.float64)
    img, mask = sitk.GetImageFromArray(vol), sitk.GetImageFromArray(np.ones(vol.shape, dtype=np.uint8))

    def run():
        f = glcm.RadiomicsGLCM(img, mask, binCount=16, distances=[1, 2, 4, 8], symmetricalGLCM=False)
        f.disableAllFeatures()
        for name in ["Contrast", "Correlation", "JointEnergy"]:
            f.enableFeatureByName(name, True)
        f.execute()

    t = median_time(run, 50)
    print(f"pyradiomics glcm3d 4x4x90: {t * 1e3:.2f} ms (median of 50)")
except ImportError as e:
    print(f"pyradiomics not installed: {e}")

# KNN (k = 5) with 5-fold stratified CV on 160 x 3, standardised (scikit-learn)
try:
    from sklearn.model_selection import StratifiedKFold, cross_val_score
    from sklearn.neighbors import KNeighborsClassifier
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler

    rng = np.random.default_rng(2)
    y = np.repeat(np.arange(8), 20)
    X = rng.normal(size=(160, 3)) + y[:, None] * 0.3
    clf = make_pipeline(StandardScaler(), KNeighborsClassifier(n_neighbors=5))
    cv = StratifiedKFold(5, shuffle=True, random_state=0)
    t = median_time(lambda: cross_val_score(clf, X, y, cv=cv), 20)
    print(f"scikit-learn knn 5-fold cv 160x3: {t * 1e3:.2f} ms (median of 20)")
except ImportError as e:
    print(f"scikit-learn not installed: {e}")

# The whole path: files to 3D-GLCM features of every recording of a dataset folder.
if args.data:
    sys.path.insert(0, str(HERE))
    from numpy_pipeline import numpy_features, read_dataset

    data = pathlib.Path(args.data)
    arrays, slides = read_dataset(data)
    steps = sum(round((e - s) * 1000) for s, e in slides) * arrays[0][0].size
    out_csv = pathlib.Path(tempfile.mkdtemp()) / "features.csv"
    command = [args.cli, "features", "--dataset", str(data), "--method", "glcm3d",
               "--out", str(out_csv)]
    del arrays  # the peer reads the files in its timed runs, as neurotex does
    ours, theirs = [], []
    for i in range(max(args.repeats, args.peer_repeats)):
        if i < args.repeats:
            t0 = time.perf_counter()
            subprocess.run(command, check=True, capture_output=True)
            ours.append(time.perf_counter() - t0)
        if i < args.peer_repeats:
            t0 = time.perf_counter()
            numpy_features(*read_dataset(data))
            theirs.append(time.perf_counter() - t0)
    a, b = statistics.median(ours), statistics.median(theirs)
    print(f"whole path, {len(slides)} recordings ({steps / 1e6:.1f} M neuron-steps), files to "
          f"3D-GLCM features: neurotex features {a:.3f} s (median of {len(ours)}), "
          f"numpy/scipy {b:.3f} s (median of {len(theirs)}): {b / a:.1f}x")
