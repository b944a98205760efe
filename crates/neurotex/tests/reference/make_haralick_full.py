"""Generates crates/neurotex/tests/data/haralick_full.json: the 13 Haralick features of
mahotas (`mahotas.features.texture.haralick_features`) that neurotex's `haralick_full`
is checked against.

Provenance (recorded in the JSON too): Python 3.11, mahotas 1.4.19, numpy 2.4.6. Re-run with

    python3.11 -m venv /tmp/ref-h && /tmp/ref-h/bin/pip install mahotas numpy
    /tmp/ref-h/bin/python crates/neurotex/tests/reference/make_haralick_full.py

Options: `use_x_minus_y_variance=True` (difference variance as the variance of |i - j|,
Haralick's definition), `preserve_haralick_bug=False` (sum variance about the sum average),
no 14th feature. The count matrices are generated here from a fixed seed and stored beside
the features: non-symmetric, some sparse, of 2, 4, 8 and 16 levels.
"""
import json
import os
import sys

import mahotas
import numpy as np
from mahotas.features.texture import haralick_features

rng = np.random.default_rng(11)
cases = []
for levels, density in [(2, 1.0), (4, 1.0), (4, 0.4), (8, 0.6), (16, 0.3), (16, 1.0)]:
    counts = rng.integers(0, 50, size=(levels, levels))
    counts = counts * (rng.random((levels, levels)) < density)
    counts[0, 0] += 1  # never an empty matrix: mahotas refuses one
    features = haralick_features(
        [counts.astype(np.float64)],
        use_x_minus_y_variance=True,
        preserve_haralick_bug=False,
    )[0]
    cases.append(
        {
            "levels": levels,
            "counts": counts.ravel().tolist(),
            "features": features.tolist(),
        }
    )

out = {
    "provenance": {
        "python": sys.version.split()[0],
        "mahotas": mahotas.__version__,
        "numpy": np.__version__,
        "call": "haralick_features([counts], use_x_minus_y_variance=True, preserve_haralick_bug=False)[0]",
    },
    "cases": cases,
}
path = os.path.join(os.path.dirname(__file__), "..", "data", "haralick_full.json")
with open(path, "w") as f:
    json.dump(out, f, indent=1)
    f.write("\n")
