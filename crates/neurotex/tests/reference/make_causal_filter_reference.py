"""Generates crates/neurotex/tests/data/causal_filter_reference.json: scipy's causal
Butterworth filtering, which neurotex's causal conditioning (`Butterworth2::lfilter`, and the
stream's sample-by-sample filter) is checked against in tests/reference_values.rs.

Provenance (recorded in the JSON too): Python 3.11, numpy and scipy at the versions printed
into the file. Re-run with

    python3.11 -m venv /tmp/ref && /tmp/ref/bin/pip install numpy scipy
    /tmp/ref/bin/python crates/neurotex/tests/reference/make_causal_filter_reference.py

The filter: scipy.signal.butter(2, cutoff, fs=1000) run forward by scipy.signal.lfilter
from the steady state of the first sample, zi = lfilter_zi(b, a) * x[0]. The input is
generated here from a fixed seed and stored beside the output.
"""
import json
import os

import numpy as np
import scipy
import scipy.signal

rng = np.random.default_rng(20261123)
t = np.arange(400) / 1000.0
x = np.round(3.0 + np.sin(2 * np.pi * 7 * t) + 0.3 * rng.normal(size=t.size), 6)
x[150:160] += 4.0  # a step up and back down
out = {
    "provenance": {
        "python": "3.11",
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "snippet": "b, a = butter(2, cutoff, fs=1000); lfilter(b, a, x, zi=lfilter_zi(b, a) * x[0])[0]",
    },
    "x": x.tolist(),
}
for cutoff in (50, 120):
    b, a = scipy.signal.butter(2, cutoff, fs=1000)
    y, _ = scipy.signal.lfilter(b, a, x, zi=scipy.signal.lfilter_zi(b, a) * x[0])
    out[f"lfilter_{cutoff}"] = y.tolist()
path = os.path.join(os.path.dirname(__file__), "..", "data", "causal_filter_reference.json")
with open(path, "w") as f:
    json.dump(out, f, indent=1)
    f.write("\n")
