"""Writes a synthetic address-event dataset of FabricSlide's size for timing `neurotex
features` on events: 1 000 recordings of 10^5 events each on a 4x4 grid, two polarities,
12 s long, as tonic's structured .npy (x, y, t, p as int64, t in microseconds), 7 labels at
two speeds. Usage: python3 tools/event_dataset.py OUT [RECORDINGS] [EVENTS]."""

import os
import sys

import numpy as np


def main() -> None:
    out = sys.argv[1]
    recordings = int(sys.argv[2]) if len(sys.argv) > 2 else 1000
    n = int(sys.argv[3]) if len(sys.argv) > 3 else 100_000
    os.makedirs(out, exist_ok=False)
    rng = np.random.default_rng(0)
    dtype = np.dtype([("x", "<i8"), ("y", "<i8"), ("t", "<i8"), ("p", "<i8")])
    lines = ["file,label,speed_mm_s,duration_s"]
    for i in range(recordings):
        a = np.zeros(n, dtype=dtype)
        a["t"] = np.sort(rng.integers(0, 12_000_000, n))
        a["x"] = rng.integers(0, 4, n)
        a["y"] = rng.integers(0, 4, n)
        a["p"] = rng.integers(0, 2, n)
        np.save(os.path.join(out, f"{i:04d}.npy"), a)
        lines.append(f"{i:04d}.npy,c{i % 7},{[10, 50][i % 2]},12")
    with open(os.path.join(out, "manifest.csv"), "w") as f:
        f.write("\n".join(lines) + "\n")
    with open(os.path.join(out, "layout.toml"), "w") as f:
        f.write('rows = 4\ncols = 4\n\n[events]\ntime_unit = "us"\n')


if __name__ == "__main__":
    main()
