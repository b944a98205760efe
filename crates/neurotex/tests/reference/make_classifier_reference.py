"""Generates crates/neurotex/tests/reference/classifiers.json: scikit-learn's logistic
regression and random forest on small fixed data sets, which
crates/neurotex/tests/classifiers.rs compares neurotex's classifiers against.

Provenance (recorded in the JSON too): Python 3.11, numpy and scikit-learn at the versions
printed into the file (written with numpy 2.4.6, scikit-learn 1.9.1). Re-run with

    python -m venv /tmp/clf && /tmp/clf/bin/pip install numpy scikit-learn
    /tmp/clf/bin/python crates/neurotex/tests/reference/make_classifier_reference.py

The inputs are generated here from fixed seeds, rounded to 6 decimals and stored beside
the outputs, so the Rust tests read both and never depend on Python.
"""
import json
import os
import sys

import numpy as np
import sklearn
from sklearn.ensemble import RandomForestClassifier
from sklearn.linear_model import LogisticRegression
from sklearn.preprocessing import StandardScaler

rng = np.random.default_rng(20261122)


def blobs(n, dims, classes, spread):
    """`n` rows of `dims` features around one random centre per class, rounded."""
    centres = rng.normal(0.0, 1.0, size=(classes, dims))
    y = np.arange(n) % classes
    x = centres[y] + spread * rng.normal(0.0, 1.0, size=(n, dims))
    return np.round(x, 6), y


def logistic_case(n_train, classes, c):
    """Overlapping classes on 4 features of different scales, plus a constant column."""
    x, y = blobs(n_train + 12, 4, classes, 1.2)
    x = x * np.array([1.0, 10.0, 0.1, 3.0]) + np.array([0.0, 50.0, -2.0, 1.0])
    x = np.round(np.hstack([x, np.full((len(x), 1), 2.5)]), 6)
    train_x, train_y, test_x = x[:n_train], y[:n_train], x[n_train:]
    scaler = StandardScaler().fit(train_x)
    # lbfgs is the default solver; with more than two classes the loss is multinomial.
    model = LogisticRegression(C=c, tol=1e-12, max_iter=100000)
    model.fit(scaler.transform(train_x), train_y)
    return {
        "c": c,
        "train_x": train_x.tolist(),
        "train_y": train_y.tolist(),
        "test_x": test_x.tolist(),
        "coef": model.coef_.tolist(),
        "intercept": model.intercept_.tolist(),
        "proba": model.predict_proba(scaler.transform(test_x)).tolist(),
        "snippet": f"LogisticRegression(C={c}, tol=1e-12, max_iter=100000).fit(StandardScaler().fit_transform(train_x), train_y)",
    }


def forest_case():
    """4 overlapping classes on 10 features: 200 rows to train on, 400 to test on."""
    x, y = blobs(600, 10, 4, 1.5)
    train_x, train_y, test_x, test_y = x[:200], y[:200], x[200:], y[200:]
    accuracies = []
    for seed in range(5):
        forest = RandomForestClassifier(n_estimators=200, random_state=seed)
        accuracies.append(float((forest.fit(train_x, train_y).predict(test_x) == test_y).mean()))
    return {
        "train_x": train_x.tolist(),
        "train_y": train_y.tolist(),
        "test_x": test_x.tolist(),
        "test_y": test_y.tolist(),
        "accuracies": accuracies,
        "snippet": "RandomForestClassifier(n_estimators=200, random_state=seed) for seed in 0..5, accuracy on test",
    }


out = {
    "provenance": {
        "script": "crates/neurotex/tests/reference/make_classifier_reference.py",
        "python": sys.version.split()[0],
        "numpy": np.__version__,
        "scikit-learn": sklearn.__version__,
    },
    "logistic_multinomial": logistic_case(60, 3, 1.0),
    # Two classes: scikit-learn fits one weight vector u (binary loss, penalty |u|^2/2);
    # neurotex's softmax with w_1 = -w_0 = u/2 has penalty |u|^2/4, the same problem at
    # half the C, so scikit-learn runs at C = 2 against neurotex's C = 1.
    "logistic_binary": logistic_case(40, 2, 2.0),
    "forest": forest_case(),
}
path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "classifiers.json")
with open(path, "w") as f:
    json.dump(out, f)
print(path, out["forest"]["accuracies"])
