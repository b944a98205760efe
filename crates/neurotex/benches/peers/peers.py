"""Times the peers of neurotex's hot stages on this machine, for ratios against the
criterion benches (run both in one session: these machines are noisy).

    python -m venv /tmp/peers && /tmp/peers/bin/pip install numpy scikit-learn \
        six pykwalify pywavelets simpleitk setuptools wheel versioneer
    # pyradiomics 3.0.1 from its sdist, as SPEC section 7 describes
    /tmp/peers/bin/python crates/neurotex/benches/peers/peers.py

Prints one line per stage with the median time and the work size.
"""
import statistics
import time

import numpy as np


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
