"""The table xylo.sh prints: cross-validated accuracy of the chip's integers and of the same
networks in float (95 % bootstrap intervals over recordings, the paired difference), and
XyloSim's agreement with `neurotex predict` on held-out recordings.

    python xylo_summary.py TITLE CV_XYLO.csv CV_FLOAT.csv PROBE_LOG PREDICTIONS.csv"""
import csv
import re
import sys

import numpy as np


def outcomes(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {(r["file"], r.get("repeat", "0")): r["predicted"] == r["label"] for r in rows}


def interval(values, rng):
    values = np.asarray(values, dtype=float)
    draws = rng.integers(0, len(values), size=(2000, len(values)))
    means = values[draws].mean(axis=1)
    return 100 * values.mean(), 100 * np.percentile(means, 2.5), 100 * np.percentile(means, 97.5)


def main(title, cv_xylo, cv_float, probe_log, predictions):
    rng = np.random.default_rng(0)
    a, b = outcomes(cv_xylo), outcomes(cv_float)
    keys = sorted(a)
    if sorted(b) != keys:
        sys.exit("the two cross-validations predicted different recordings")
    xa = np.array([a[k] for k in keys], dtype=float)
    xb = np.array([b[k] for k in keys], dtype=float)
    with open(predictions) as f:
        classes = len([c for c in next(csv.reader(f)) if c.startswith("share_")])
    print(f"{title}: {len(keys)} recordings, {classes} classes (chance {100 / classes:.1f} %)")
    print()
    print("| | accuracy (%) [95 % interval] |")
    print("|---|---|")
    print("| Xylo profile, the chip's integers (`evaluate --snn-target xylo`) | %.1f [%.1f, %.1f] |" % interval(xa, rng))
    print("| the same networks in float | %.1f [%.1f, %.1f] |" % interval(xb, rng))
    print("| integers - float (paired, points) | %+.1f [%+.1f, %+.1f] |" % interval(xa - xb, rng))
    log = open(probe_log).read()
    agree = re.search(r"labels agree (\d+)/(\d+); max relative score error (\S+)", log)
    acc = re.search(r"accuracy: XyloSim (\d+)/(\d+)", log)
    version = re.search(r"^(xylosim \[.*?\])", log, re.M)
    print()
    if agree and acc and version:
        print(f"{version.group(1)} on {agree.group(2)} held-out recordings: decisions agree with "
              f"`neurotex predict` on {agree.group(1)}/{agree.group(2)}, largest score error "
              f"{agree.group(3)} of the largest score; accuracy {acc.group(1)}/{acc.group(2)}")
    else:
        print("XyloSim failed: " + log.strip().splitlines()[-1] if log.strip() else "XyloSim failed")


if __name__ == "__main__":
    if len(sys.argv) != 6:
        sys.exit(__doc__)
    main(*sys.argv[1:])
