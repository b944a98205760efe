#!/usr/bin/env python3
"""The numbers docs/results.md quotes from a `neurotex reproduce` run, cut from its
results.json (values as written there, nothing recomputed), with the run's provenance.

    python3 tools/results_summary.py fabricslide-report/results.json \
        "neurotex reproduce --dataset fabricslide --out fabricslide-report" \
        > docs/results/fabricslide.json

The test `docs_numbers` (crates/neurotex/tests) renders the table of docs/results.md from
this file and fails when the page quotes anything else; `NEUROTEX_BLESS=1` rewrites the
table from it.
"""
import json
import sys


def pick(d, keys):
    return {k: d[k] for k in keys if k in d}


def interval(i):
    return pick(i, ["lower", "upper", "method", "n", "encodings"])


def main():
    path, command = sys.argv[1], sys.argv[2]
    r = json.load(open(path))
    out = {
        "command": command,
        "provenance": pick(r["provenance"], ["neurotex_version", "git_commit", "data", "created_utc"]),
        "recordings": r["recordings"],
        "e1": {
            s: {
                **pick(e, ["taxel_mean", "taxel_best", "taxel_best_cell", "glcm3d", "n", "classes", "chance"]),
                "taxel_mean_interval": interval(e["taxel_mean_interval"]),
                "glcm3d_interval": interval(e["glcm3d_interval"]),
            }
            for s, e in r["e1"].items()
        },
        "e4": {
            s: {"glcm2d": e["glcm2d"], "glcm2d_interval": interval(e["glcm2d_interval"])}
            for s, e in r["e4"].items()
        },
        "e6": {s: pick(e, ["taxel_mean", "glcm3d"]) for s, e in r["e6"].items()},
        "e3": pick(r["e3"], ["speed", "glcm3d", "n", "mean"]),
    }
    json.dump(out, sys.stdout, indent=1)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
