"""Paper-scale timing: 3D-GLCM features of 480 simulated recordings (8 textures x 3 speeds
x 20 trials, the paper's design) from Python, against the CLI on the same folder and
against a numpy/scipy implementation of the same pipeline
(`crates/neurotex-bench/benches/peers/numpy_pipeline.py`), all in one run on one host.

    python bench/bench_features.py [--cli PATH] [--repeats 5] [--data DIR]

Prints the median of each timing. The numpy peer is the straightforward vectorised
version a Python user would write (as the peers of docs/performance.md): scipy's
filtfilt per recording, the Izhikevich encoder batched over every neuron of every trial,
rate volumes by reshaping, 52 co-occurrence offsets by np.bincount, Haralick features in
numpy.
"""

from __future__ import annotations

import argparse
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import neurotex

REPO = pathlib.Path(__file__).resolve().parents[3]
# The numpy/scipy peer lives beside the library's other peers (scipy is imported there,
# before any timing: a slow import).
sys.path.insert(0, str(REPO / "crates" / "neurotex" / "benches" / "peers"))
from numpy_pipeline import numpy_features  # noqa: E402


def median_time(f, repeats):
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), times


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cli", default=str(REPO / "target" / "release" / "neurotex"))
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--peer-repeats", type=int, default=3)
    ap.add_argument("--data", help="a simulated 480-recording folder (made when absent)")
    args = ap.parse_args()

    tmp = tempfile.TemporaryDirectory()
    data = pathlib.Path(args.data or os.path.join(tmp.name, "sim480"))
    if not data.exists():
        subprocess.run([args.cli, "simulate", "--out", str(data), "--seed", "0"], check=True,
                       capture_output=True)
    ds = neurotex.load_dataset(data)
    assert len(ds) == 480, len(ds)
    steps = sum(int(round((r.slide[1] - r.slide[0]) * 1000)) for r in ds.recordings) * 16
    print(f"machine: {os.cpu_count()} cores; {platform()}")
    print(f"data: {len(ds)} recordings, {steps / 1e6:.1f} M neuron-steps in their slides")

    out_csv = os.path.join(tmp.name, "f.csv")
    cli = lambda: subprocess.run(  # noqa: E731
        [args.cli, "features", "--dataset", str(data), "--method", "glcm3d", "--out", out_csv],
        check=True, capture_output=True)
    from_folder = lambda: neurotex.features(str(data), "glcm3d")  # noqa: E731
    in_memory = lambda: neurotex.features(ds, "glcm3d")  # noqa: E731
    load = lambda: neurotex.load_dataset(data)  # noqa: E731

    # interleaved, so that load from the machine's other users falls on every variant
    runs = {"cli": [], "folder": [], "memory": [], "load": []}
    for _ in range(args.repeats):
        for name, f in (("cli", cli), ("folder", from_folder), ("memory", in_memory),
                        ("load", load)):
            t0 = time.perf_counter()
            f()
            runs[name].append(time.perf_counter() - t0)
    med = {k: statistics.median(v) for k, v in runs.items()}
    arrays = [r.x for r in ds.recordings]
    slides = [r.slide for r in ds.recordings]
    peer, peer_runs = median_time(lambda: numpy_features(arrays, slides), args.peer_repeats)

    ours, _ = neurotex.features(ds, "glcm3d")
    theirs = numpy_features(arrays, slides)
    rel = np.abs(ours - theirs) / np.maximum(np.abs(ours), 1e-12)
    print(f"CLI `neurotex features --dataset` (process, reads files, writes CSV): "
          f"{med['cli']:.3f} s  runs {fmt(runs['cli'])}")
    print(f"Python neurotex.features(folder) (reads files):                      "
          f"{med['folder']:.3f} s  runs {fmt(runs['folder'])}")
    print(f"Python neurotex.features(dataset in memory):                          "
          f"{med['memory']:.3f} s  runs {fmt(runs['memory'])}")
    print(f"Python neurotex.load_dataset(folder):                                 "
          f"{med['load']:.3f} s  runs {fmt(runs['load'])}")
    print(f"numpy/scipy peer on the arrays in memory:                             "
          f"{peer:.3f} s  runs {fmt(peer_runs)}")
    print(f"Python over CLI (same work, from the folder): "
          f"{100 * (med['folder'] / med['cli'] - 1):+.1f} %")
    print(f"speed-up over the numpy peer, in memory: {peer / med['memory']:.1f}x; "
          f"from the folder: {peer / med['folder']:.1f}x")
    print(f"agreement with the peer (its filter edges and slide rounding differ): median "
          f"relative difference {np.median(rel):.2e}, rows within 1e-6: "
          f"{np.mean(np.all(rel < 1e-6, axis=1)):.0%}")


def fmt(xs):
    return "[" + ", ".join(f"{x:.3f}" for x in xs) + "]"


def platform():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return sys.platform


if __name__ == "__main__":
    main()
