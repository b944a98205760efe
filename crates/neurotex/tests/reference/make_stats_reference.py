"""Generates crates/neurotex/tests/data/stats_reference.json: the values of established
tools that `tests/stats_reference.rs` compares neurotex's metrics, intervals and tests to.

Provenance (recorded in the JSON too): statsmodels for Wilson's interval and McNemar's
exact test, scipy for the normal and Student t quantiles, the t interval and the binomial
CDF, numpy for percentiles, scikit-learn for balanced accuracy, recall and precision.
Re-run with

    python3 -m venv /tmp/statsenv
    /tmp/statsenv/bin/pip install scipy statsmodels numpy scikit-learn
    /tmp/statsenv/bin/python crates/neurotex/tests/reference/make_stats_reference.py

Every input is written literally here and stored beside its output, so the Rust test
needs no Python.
"""
import json
import math
import os
import sys
from fractions import Fraction

import numpy as np
import scipy
import sklearn
import statsmodels
from scipy import stats
from sklearn.metrics import balanced_accuracy_score, precision_score, recall_score
from statsmodels.stats.contingency_tables import mcnemar
from statsmodels.stats.proportion import proportion_confint


def exact_half_cdf(k, n):
    """P(X <= k) for X ~ Binomial(n, 1/2) in exact rational arithmetic, correctly rounded."""
    return float(Fraction(sum(math.comb(n, i) for i in range(k + 1)), 2 ** n))


def number(x):
    """A float for JSON; NaN (an undefined value) becomes null."""
    x = float(x)
    return None if np.isnan(x) else x


out = {
    "provenance": {
        "script": "crates/neurotex/tests/reference/make_stats_reference.py",
        "python": sys.version.split()[0],
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "statsmodels": statsmodels.__version__,
        "scikit-learn": sklearn.__version__,
    }
}

# scipy: stats.norm.ppf(0.975), the z of every 95 % Wilson interval.
out["norm_ppf_975"] = number(stats.norm.ppf(0.975))

# statsmodels: proportion_confint(k, n, alpha=0.05, method="wilson").
wilson_cases = [(0, 1), (1, 1), (0, 10), (10, 10), (7, 10), (1, 2), (17, 23), (50, 100),
                (80, 100), (0, 5000), (1, 5000), (3721, 5000), (4999, 5000), (5000, 5000)]
out["wilson"] = []
for k, n in wilson_cases:
    lo, hi = proportion_confint(k, n, alpha=0.05, method="wilson")
    out["wilson"].append({"correct": k, "n": n, "lower": number(lo), "upper": number(hi)})

# statsmodels: mcnemar([[a, b], [c, d]], exact=True).pvalue; a and d do not enter it.
# "exact": the same p-value, min(1, 2 P(X <= min(b, c))), from exact integer sums.
mcnemar_cases = [(0, 0), (0, 1), (1, 0), (3, 3), (7, 0), (2, 9), (9, 2), (10, 25), (40, 60),
                 (0, 60), (13, 14), (2400, 2600), (2200, 2800), (1000, 1500), (2500, 2501)]
out["mcnemar"] = []
for b, c in mcnemar_cases:
    result = mcnemar(np.array([[5, b], [c, 5]]), exact=True)
    exact = min(1.0, 2 * exact_half_cdf(min(b, c), b + c))
    out["mcnemar"].append({"b": b, "c": c, "p_value": number(result.pvalue), "exact": exact})

# scipy: stats.binom.cdf(k, n, 0.5), both halves of the distribution; "exact" as above.
binom_cases = [(0, 1), (3, 10), (5, 10), (7, 10), (12, 100), (49, 100), (50, 100), (70, 100),
               (900, 2000), (2450, 5000), (2600, 5000), (1000, 2500)]
out["binom_half_cdf"] = [{"k": k, "n": n, "cdf": number(stats.binom.cdf(k, n, 0.5)),
                          "exact": exact_half_cdf(k, n)} for k, n in binom_cases]

# scipy: stats.t.ppf(p, dof).
out["t_ppf"] = []
for dof in [1, 2, 3, 4, 5, 6, 7, 9, 10, 19, 29, 30, 49, 99, 199, 999]:
    for p in [0.975, 0.995, 0.9, 0.6, 0.025, 0.999]:
        out["t_ppf"].append({"p": p, "dof": dof, "quantile": number(stats.t.ppf(p, dof))})

# scipy: stats.t.interval(0.95, r - 1, loc=mean, scale=stats.sem(x)), clipped to [0, 1]
# as neurotex clips (the last case is clipped).
t_cases = [[0.7, 0.73], [0.81, 0.79, 0.84, 0.80, 0.83],
           [0.70, 0.72, 0.69, 0.75, 0.71, 0.73, 0.70, 0.74, 0.72, 0.68],
           [0.5, 0.55, 0.52], [1.0, 0.9]]
out["t_interval"] = []
for x in t_cases:
    x = np.array(x)
    lo, hi = stats.t.interval(0.95, len(x) - 1, loc=x.mean(), scale=stats.sem(x))
    out["t_interval"].append({"per_repeat": x.tolist(), "estimate": number(x.mean()),
                              "lower": number(max(lo, 0.0)), "upper": number(min(hi, 1.0))})

# numpy: np.percentile(values, 100 * q) (default "linear" method).
rng = np.random.default_rng(11)
out["percentile"] = []
for size in [1, 2, 7, 201]:
    values = np.sort(rng.random(size))
    qs = [0.0, 0.025, 0.5, 0.975, 1.0]
    out["percentile"].append({"sorted": values.tolist(), "q": qs,
                              "value": [number(np.percentile(values, 100 * q)) for q in qs]})

# scikit-learn: balanced_accuracy_score(y_true, y_pred), and
# precision_score / recall_score(y_true, y_pred, labels=range(k), average=None,
# zero_division=np.nan) (undefined is NaN, stored as null).
metric_cases = [
    # class 2 predicted but never true, class 1 never predicted
    (3, [0, 0, 0, 1, 1, 0, 0], [0, 0, 2, 0, 0, 0, 0]),
    (4, [0, 1, 2, 3, 0, 1, 2, 3, 3, 3, 2], [0, 1, 2, 3, 1, 1, 3, 3, 0, 3, 2]),
    (2, [0, 0, 0, 0, 0, 0, 0, 0, 1, 1], [0, 0, 0, 0, 0, 0, 0, 0, 0, 0]),
    (5, list(rng.integers(0, 5, 200)), list(rng.integers(0, 5, 200))),
]
out["sklearn_metrics"] = []
for k, y_true, y_pred in metric_cases:
    y_true, y_pred = [int(v) for v in y_true], [int(v) for v in y_pred]
    labels = list(range(k))
    out["sklearn_metrics"].append({
        "n_classes": k,
        "truth": y_true,
        "predicted": y_pred,
        "accuracy": number(np.mean(np.array(y_true) == np.array(y_pred))),
        "balanced_accuracy": number(balanced_accuracy_score(y_true, y_pred)),
        "precision": [number(v) for v in precision_score(
            y_true, y_pred, labels=labels, average=None, zero_division=np.nan)],
        "recall": [number(v) for v in recall_score(
            y_true, y_pred, labels=labels, average=None, zero_division=np.nan)],
    })

path = os.path.join(os.path.dirname(__file__), "..", "data", "stats_reference.json")
with open(path, "w") as f:
    json.dump(out, f, indent=1, allow_nan=False)
    f.write("\n")
print("wrote", os.path.normpath(path))
