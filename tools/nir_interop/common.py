"""Shared by the probes: neurotex's exported inputs and predictions, and the comparison.

Each probe runs as `python probe_TOOL.py FILE.nir INPUTS PREDICTIONS`, where INPUTS is a
`neurotex export inputs` folder and PREDICTIONS the CSV of `neurotex predict` on the same
recordings. The reference scores are `neurotex predict`'s shares (the softmax of the class
scores), which give the scores up to one constant per recording: both sides are centred
(their mean over classes removed) before comparing. The relative error is
max |tool - reference| / max |reference| over all recordings and classes."""
import csv
import os
import sys
from importlib.metadata import version

import numpy as np


def args():
    if len(sys.argv) != 4:
        sys.exit(f"usage: python {os.path.basename(sys.argv[0])} FILE.nir INPUTS PREDICTIONS")
    return sys.argv[1:]


def versions(*packages):
    return ", ".join(f"{p} {version(p)}" for p in packages)


def readout_name(graph):
    """The node that feeds the graph's Output: the readout whose trace gives the scores."""
    import nir
    out = next(n for n, node in graph.nodes.items() if isinstance(node, nir.Output))
    return next(s for s, d in graph.edges if d == out)


def has_loop(graph):
    """Whether the graph's edges (this level's) close a cycle: a recurrent layer."""
    succ = {}
    for s, d in graph.edges:
        succ.setdefault(s, []).append(d)

    def reaches(start, goal, seen):
        for d in succ.get(start, []):
            if d == goal or (d not in seen and reaches(d, goal, seen | {d})):
                return True
        return False

    return any(reaches(n, n, set()) for n in succ)


def load(inputs_dir, predictions_csv):
    """The labels in score order and, per recording, (file, (steps, inputs) array,
    neurotex's predicted label, neurotex's shares)."""
    with open(predictions_csv) as f:
        header = next(csv.reader(f))
    labels = [c[len("share_"):] for c in header if c.startswith("share_")]
    with open(predictions_csv) as f:
        rows = {r["file"]: r for r in csv.DictReader(f)}
    with open(os.path.join(inputs_dir, "index.csv")) as f:
        index = list(csv.DictReader(f))
    items = []
    for entry in index:
        row = rows[entry["file"]]
        x = np.load(os.path.join(inputs_dir, entry["array"]))
        shares = np.array([float(row[f"share_{c}"]) for c in labels])
        items.append((entry["file"], x, row["predicted"], shares))
    return labels, items


def truth(predictions_csv):
    """(file, true label) of each recording of a `neurotex predict` CSV."""
    with open(predictions_csv) as f:
        return [(r["file"], r["label"]) for r in csv.DictReader(f)]


def centred(s):
    s = np.asarray(s, dtype=np.float64)
    return s - s.mean()


def report(tool, labels, items, scores):
    """Prints one line `TOOL (VERSIONS): labels agree A/N; max relative score error E`
    (run.sh reads it) and returns whether the tool gives neurotex's decisions and scores.
    `scores`: the tool's (classes,) class scores per recording, in `labels`' order."""
    if not all(np.all(np.isfinite(s)) for s in scores):
        print(f"{tool}: labels agree -/{len(items)}; max relative score error nan "
              "(NON-FINITE scores: the network diverged)")
        return False
    agree, num, den = 0, 0.0, 0.0
    for (_, _, predicted, shares), s in zip(items, scores):
        agree += labels[int(np.argmax(s))] == predicted
        ref = centred(np.log(shares))
        num = max(num, float(np.max(np.abs(centred(s) - ref))))
        den = max(den, float(np.max(np.abs(ref))))
    rel = num / den if den else float("nan")
    print(f"{tool}: labels agree {agree}/{len(items)}; max relative score error {rel:.1e}")
    return agree == len(items) and rel < 1e-5
