"""Summarises tools/time_to_decision.sh's WORKDIR: for each model, the accuracy of whole
recordings and of the episodes' end labels, the share of episodes decided before their end,
how often a decision is right (95 % Wilson intervals) and when it comes."""

import csv
import json
import math
import statistics
import sys
from pathlib import Path


def wilson(k, n, z=1.96):
    p = k / n
    d = 1 + z * z / n
    c = (p + z * z / (2 * n)) / d
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return 100 * (c - h), 100 * (c + h)


work = Path(sys.argv[1])
truth = {r["file"]: r["label"] for r in csv.DictReader(open(work / "test" / "manifest.csv"))}
print(f"{len(truth)} test recordings, {len(set(truth.values()))} classes "
      f"(chance {100 / len(set(truth.values())):.1f} %)")
for model in ("paper", "snn"):
    ends = [l for l in map(json.loads, open(work / f"{model}.jsonl")) if l.get("end")]
    whole = json.load(open(work / f"{model}.score.json"))["accuracy"]
    right = sum(e.get("label") == truth[e["file"]] for e in ends)
    decided = [e for e in ends if e.get("decision") is not None]
    good = sum(e["decision"] == truth[e["file"]] for e in decided)
    lo, hi = wilson(good, len(decided)) if decided else (math.nan, math.nan)
    at = statistics.median(e["decided_at_s"] for e in decided) if decided else math.nan
    length = statistics.median(e["duration_s"] for e in ends)
    print(f"{model}: whole recordings {100 * whole:.1f} %, end labels {100 * right / len(ends):.1f} %; "
          f"decided {len(decided)}/{len(ends)}, right {100 * good / max(1, len(decided)):.1f} % "
          f"[{lo:.1f}, {hi:.1f}], median at {at:.1f} s of {length:.1f} s episodes")
