"""The paper's 3D-GLCM feature pipeline written the straightforward vectorised way a Python
user would: scipy's filtfilt per recording, the Izhikevich encoder batched over every neuron
of every trial (the encoder's peer in docs/performance.md), rate volumes by reshaping, the 52
co-occurrence offsets by np.bincount, Haralick features in numpy. The peer of
`neurotex features --method glcm3d` for `peers.py` and the Python package's
`bench/bench_features.py`.
"""

import csv
import pathlib

import numpy as np
from scipy.signal import butter, filtfilt

DIRECTIONS_13 = [(0, 1, 0), (-1, 1, 0), (-1, 0, 0), (-1, -1, 0), (0, 1, -1), (0, 0, -1),
                 (0, -1, -1), (-1, 0, -1), (1, 0, -1), (-1, 1, -1), (1, -1, -1),
                 (-1, -1, -1), (1, 1, -1)]


def numpy_features(arrays, slides, fs=1000.0, gain=8.0, cutoff=50.0, levels=16, bin_ms=200,
                   distances=(1, 2, 4, 8)):
    """The pipeline in numpy/scipy: condition, encode (batched), bin, quantise, GLCM,
    Haralick. Returns (n, 3) contrast, correlation, ASM."""
    b, a = butter(2, cutoff / (fs / 2))
    conditioned = []
    for x, (start, end) in zip(arrays, slides):
        seg = x[int(round(start * fs)):int(round(end * fs))]
        t, rows, cols = seg.shape
        seg = filtfilt(b, a, seg.reshape(t, rows * cols), axis=0)
        top = seg.max()
        conditioned.append(seg / top if top > 0 else np.zeros_like(seg))
    # Izhikevich RS neurons, every neuron of every recording in one batch.
    lengths = [c.shape[0] for c in conditioned]
    cells = conditioned[0].shape[1]
    steps = max(lengths)
    current = np.zeros((steps, len(conditioned) * cells))
    for i, c in enumerate(conditioned):
        current[: len(c), i * cells:(i + 1) * cells] = gain * c
    pa, pb, pc, pd = 0.02, 0.2, -65.0, 8.0
    v = np.full(current.shape[1], pc)
    u = pb * v
    spikes = np.zeros(current.shape, dtype=np.uint8)
    for t in range(steps):
        fired = v >= 30.0
        spikes[t] = fired
        v[fired] = pc
        u[fired] += pd
        i_t = current[t]
        v += 0.5 * (0.04 * v * v + 5.0 * v + 140.0 - u + i_t)
        v += 0.5 * (0.04 * v * v + 5.0 * v + 140.0 - u + i_t)
        u += pa * (pb * v - u)
    rows, cols = arrays[0].shape[1:]
    offsets = [(dr * d, dc * d, dt * d) for d in distances for dr, dc, dt in DIRECTIONS_13]
    out = np.zeros((len(conditioned), 3))
    idx = np.arange(levels)
    for n, length in enumerate(lengths):
        s = spikes[:length, n * cells:(n + 1) * cells]
        bins = length // bin_ms
        rates = s[: bins * bin_ms].reshape(bins, bin_ms, rows, cols).sum(axis=1) / (bin_ms / 1000)
        vol = np.moveaxis(rates, 0, -1)  # (rows, cols, bins)
        lo, hi = vol.min(), vol.max()
        q = (np.zeros(vol.shape, dtype=np.int64) if hi <= lo else
             np.minimum(levels - 1, np.floor((vol - lo) / (hi - lo) * levels)).astype(np.int64))
        counts = np.zeros(levels * levels)
        R, C, B = q.shape
        for dr, dc, dt in offsets:
            src = q[max(0, -dr):R - max(0, dr), max(0, -dc):C - max(0, dc),
                    max(0, -dt):B - max(0, dt)]
            dst = q[max(0, dr):R - max(0, -dr) if dr < 0 else R,
                    max(0, dc):C - max(0, -dc) if dc < 0 else C,
                    max(0, dt):B - max(0, -dt) if dt < 0 else B]
            if src.size:
                counts += np.bincount((src * levels + dst).ravel(), minlength=levels * levels)
        p = counts.reshape(levels, levels) / max(counts.sum(), 1)
        i, j = np.meshgrid(idx, idx, indexing="ij")
        px, py = p.sum(axis=1), p.sum(axis=0)
        mx, my = (idx * px).sum(), (idx * py).sum()
        sx = np.sqrt(((idx - mx) ** 2 * px).sum())
        sy = np.sqrt(((idx - my) ** 2 * py).sum())
        contrast = (p * (i - j) ** 2).sum()
        corr = 1.0 if sx < 1e-15 or sy < 1e-15 else (p * (i - mx) * (j - my)).sum() / (sx * sy)
        out[n] = (contrast, corr, (p * p).sum())
    return out


def read_dataset(folder):
    """A `neurotex simulate` folder's recordings as (arrays, slides): each `.npy` of
    (T, rows, cols) samples at 1 kHz and its sliding phase (start, end) in seconds, in the
    manifest's order."""
    folder = pathlib.Path(folder)
    arrays, slides = [], []
    with open(folder / "manifest.csv", newline="") as f:
        for row in csv.DictReader(f):
            arrays.append(np.load(folder / row["file"]))
            slides.append((float(row["slide_start_s"]), float(row["slide_end_s"])))
    return arrays, slides
