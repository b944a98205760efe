"""Reference p-values of the paired sign-flip test for neurotex's `sign_flip_p`.

Writes tests/data/sign_flip_reference.json. Each case is a list of per-unit differences of
shares of right predictions (in [-1, 1]); `exact` cases are enumerated by scipy over all
2^n sign patterns (n_resamples=inf), `sampled` cases draw 400 000 patterns, so neurotex's
sampled p-value (another generator) may differ by sampling error only.

Run: python3 tests/reference/make_sign_flip_reference.py  (from crates/neurotex)
"""
import json
import platform

import numpy as np
import scipy
from scipy.stats import permutation_test


def p_value(d, n_resamples):
    res = permutation_test(
        (np.asarray(d, dtype=float),),
        lambda x, axis: np.mean(x, axis=axis),
        permutation_type="samples",
        alternative="two-sided",
        n_resamples=n_resamples,
        vectorized=True,
        random_state=np.random.default_rng(1),
    )
    return float(res.pvalue)


rng = np.random.default_rng(20261122)
exact = []
for n in [2, 3, 5, 8, 11, 13, 16]:
    # multiples of 0.2 and of 1/3, so that ties between patterns occur
    d = list(rng.choice([-1, -0.6, -0.4, -0.2, 0, 0.2, 1 / 3, 0.4, 2 / 3, 1], size=n))
    exact.append({"differences": d, "p": p_value(d, np.inf)})
exact.append({"differences": [0.0, 0.0, 0.0], "p": p_value([0.0, 0.0, 0.0], np.inf)})
exact.append({"differences": [1.0] * 10, "p": p_value([1.0] * 10, np.inf)})
sampled = []
for n, shift in [(40, 0.1), (120, 0.05), (300, 0.0)]:
    d = list(np.clip(rng.normal(shift, 0.4, size=n), -1, 1))
    sampled.append({"differences": d, "p": p_value(d, 400_000), "resamples": 400_000})
json.dump(
    {
        "provenance": {
            "script": "tests/reference/make_sign_flip_reference.py",
            "scipy": scipy.__version__,
            "numpy": np.__version__,
            "python": platform.python_version(),
        },
        "exact": exact,
        "sampled": sampled,
    },
    open("tests/data/sign_flip_reference.json", "w"),
    indent=1,
)
