"""Generates crates/neurotex/tests/data/reference.json: values from established tools
that the Rust tests compare neurotex against.

Provenance (recorded in the JSON too): Python 3.11, numpy, scipy, scikit-image,
scikit-learn and pyradiomics 3.0.1 at the versions printed into the file. Re-run with

    python -m venv /tmp/ref && /tmp/ref/bin/pip install numpy scipy scikit-learn scikit-image \
        six pykwalify pywavelets simpleitk setuptools wheel versioneer
    # pyradiomics 3.0.1 from its sdist, as docs/correctness.md shows
    /tmp/ref/bin/python crates/neurotex/tests/reference/make_reference.py

The inputs are generated here from fixed seeds and stored beside the outputs, so the Rust
tests read both and never depend on Python.
"""
import json
import os
import sys

import numpy as np
import scipy
import scipy.signal
import skimage
import sklearn
import SimpleITK as sitk
import radiomics
from radiomics import cMatrices, glcm as rglcm
from skimage.feature import graycomatrix, graycoprops
from sklearn.neighbors import KNeighborsClassifier
from sklearn.preprocessing import StandardScaler

out = {
    "provenance": {
        "script": "crates/neurotex/tests/reference/make_reference.py",
        "python": sys.version.split()[0],
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "scikit-image": skimage.__version__,
        "scikit-learn": sklearn.__version__,
        "pyradiomics": radiomics.__version__,
    }
}

# --- scikit-image: 2D GLCM, distance 1, the four in-plane angles, and graycoprops -------
rng = np.random.default_rng(7)
cases = []
for levels, shape in [(4, (4, 4)), (8, (6, 10)), (16, (4, 4))]:
    img = rng.integers(0, levels, size=shape).astype(np.uint8)
    angles = [0, np.pi / 4, np.pi / 2, 3 * np.pi / 4]
    m = graycomatrix(img, distances=[1], angles=angles, levels=levels, symmetric=False, normed=False)
    mn = graycomatrix(img, distances=[1], angles=angles, levels=levels, symmetric=False, normed=True)
    props = {p: graycoprops(mn, p)[0].tolist() for p in ["contrast", "correlation", "ASM"]}
    cases.append({
        "levels": levels,
        "image": img.tolist(),
        # graycomatrix(img, distances=[1], angles=[0, pi/4, pi/2, 3pi/4], levels, symmetric=False)
        "counts": [m[:, :, 0, a].astype(int).tolist() for a in range(4)],
        # graycoprops(normed matrices, prop)[0]
        "props": props,
    })
out["skimage_glcm2d"] = cases

# --- pyradiomics 3.0.1: 3D GLCM per angle (distance 1, 13 angles, not symmetric) --------
cases = []
for levels, shape in [(4, (4, 4, 6)), (6, (3, 5, 7))]:
    while True:
        vol = rng.integers(1, levels + 1, size=shape)
        if len(np.unique(vol)) == levels:
            break
    img = sitk.GetImageFromArray(vol.astype(np.float64))
    mask = sitk.GetImageFromArray(np.ones(shape, dtype=np.uint8))
    feat = rglcm.RadiomicsGLCM(img, mask, binWidth=1, distances=[1], symmetricalGLCM=False)
    # cMatrices.calculate_glcm(imageArray, maskArray, distances, Ng, force2D, force2Ddim)
    p, angles = cMatrices.calculate_glcm(feat.imageArray, feat.maskArray, np.array([1]),
                                         feat.coefficients["Ng"], False, 0)
    feat.disableAllFeatures()
    for name in ["Contrast", "Correlation", "JointEnergy"]:
        feat.enableFeatureByName(name, True)
    values = feat.execute()
    cases.append({
        "levels": levels,
        # volume in array order (axis0, axis1, axis2) = (row, col, time); gray levels 1..L
        "volume": vol.tolist(),
        # binned gray levels pyradiomics used (binWidth=1)
        "binned": feat.imageArray.astype(int).tolist(),
        "angles": angles.astype(int).tolist(),
        "counts": [p[0, :, :, a].astype(int).tolist() for a in range(p.shape[3])],
        # per-angle features averaged over the 13 angles (pyradiomics' aggregation)
        "features_mean_over_angles": {k: float(v) for k, v in values.items()},
    })
out["pyradiomics_glcm3d"] = cases

# --- scipy: Butterworth design and filtfilt ---------------------------------------------
x = rng.normal(size=300).cumsum()
b, a = scipy.signal.butter(2, 50, btype="low", fs=1000)
b2, a2 = scipy.signal.butter(2, 120, btype="low", fs=1000)
short = rng.normal(size=8)
out["scipy_filter"] = {
    # scipy.signal.butter(2, 50, fs=1000) and filtfilt(b, a, x) with default padding
    "b_50": b.tolist(), "a_50": a.tolist(),
    "b_120": b2.tolist(), "a_120": a2.tolist(),
    "x": x.tolist(),
    "filtfilt_50": scipy.signal.filtfilt(b, a, x).tolist(),
    "filtfilt_120": scipy.signal.filtfilt(b2, a2, x).tolist(),
    # a signal of 8 samples: filtfilt(b, a, short, padlen=7)
    "short": short.tolist(),
    "filtfilt_short": scipy.signal.filtfilt(b, a, short, padlen=7).tolist(),
}

# --- scikit-learn: KNN on fixed folds with training-fold standardisation -----------------
n, d = 60, 3
X = rng.normal(size=(n, d)) * np.array([30.0, 0.5, 2.0]) + np.array([50.0, 1.0, 0.0])
y = rng.integers(0, 3, size=n)
X[y == 1, 1] += 0.6
X[y == 2, 0] += 25.0
folds = np.arange(n) % 5
rng.shuffle(folds)
knn_cases = []
for k in [1, 3, 5, 7]:
    pred = np.zeros(n, dtype=int)
    tied = np.zeros(n, dtype=bool)
    for f in range(5):
        tr, te = folds != f, folds == f
        sc = StandardScaler().fit(X[tr])
        clf = KNeighborsClassifier(n_neighbors=k, algorithm="brute").fit(sc.transform(X[tr]), y[tr])
        pred[te] = clf.predict(sc.transform(X[te]))
        proba = clf.predict_proba(sc.transform(X[te]))
        top = proba.max(axis=1, keepdims=True)
        tied[te] = (np.isclose(proba, top)).sum(axis=1) > 1
    knn_cases.append({"k": k, "predicted": pred.tolist(), "vote_tie": tied.tolist()})
out["sklearn_knn"] = {
    # StandardScaler().fit(X[train]); KNeighborsClassifier(k, algorithm="brute"); per fold
    "x": X.tolist(), "y": y.tolist(), "folds": folds.tolist(), "cases": knn_cases,
}

# --- Izhikevich 2003 reference scheme, written from the paper's MATLAB listing ----------
def izhikevich(current, a=0.02, b=0.2, c=-65.0, d=8.0):
    v, u = c, b * c
    spikes = []
    for t, i in enumerate(current):
        if v >= 30:
            spikes.append(t)
            v, u = c, u + d
        v = v + 0.5 * (0.04 * v ** 2 + 5 * v + 140 - u + i)
        v = v + 0.5 * (0.04 * v ** 2 + 5 * v + 140 - u + i)
        u = u + a * (b * v - u)
    return spikes

izh = []
for name, current in [
    ("const_4", [4.0] * 1000),
    ("const_8", [8.0] * 1000),
    ("const_10", [10.0] * 1000),
    ("step_0_to_8_at_100", [0.0] * 100 + [8.0] * 900),
]:
    izh.append({"name": name, "current": current, "spikes": izhikevich(current)})
ramp = np.clip(rng.normal(0.5, 0.3, size=2000), 0, 1) * 8.0
izh.append({"name": "noisy_gain8", "current": ramp.tolist(), "spikes": izhikevich(ramp.tolist())})
out["izhikevich"] = izh

path = os.path.join(os.path.dirname(__file__), "..", "data", "reference.json")
with open(path, "w") as f:
    json.dump(out, f, indent=1)
print("wrote", os.path.normpath(path))
