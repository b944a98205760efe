"""Writes a synthetic event skin's dataset: an 8x8 array of 1 mm taxels under a soft cover,
slid over four textures at three speeds, each taxel emitting ON and OFF address events when
the pressure under it rises or falls by a fixed step (a level-crossing sensor, as event
skins and DVS-based fingertips are). For checking classifiers on a sensor unlike the
simulated 4x4 rig and FabricSlide: denser in space, no analog samples, no encoder.

Textures (height fields in mm, positions in mm):
- grating2: ridges of 2 mm period across the slide;
- grating4_45: ridges of 4 mm period at 45 degrees;
- knurl: two crossed gratings of 2.5 mm period;
- dots: round bumps of 0.5 mm radius at random places, one per 6 mm^2 on average.

Each trial draws its start along and across the texture, a small rotation, the force
(contrast) and the speed's jitter; each taxel keeps a gain fixed for the whole dataset. The
pressure is the height field seen through a Gaussian of 0.6 mm (the cover), plus noise;
events fire every `step` of pressure change (at most one per taxel, polarity and 1 ms),
with background events at 1 Hz per taxel and polarity. Every choice above was made before
any classifier ran on the data.

Usage: python3 tools/event_skin.py OUT [TRIALS] [SEED] (10 trials, seed 0 by default)
Writes OUT/manifest.csv (file, label, speed_mm_s, trial, duration_s), OUT/layout.toml and
one tonic-style .npy per recording (x, y, t in microseconds, p with 1 = ON, 0 = OFF).
"""

import argparse
import os

import numpy as np

ROWS = COLS = 8
PITCH_MM = 1.0
COVER_MM = 0.6
SPEEDS_MM_S = (10.0, 20.0, 40.0)
SLIDE_MM = 30.0
FS_HZ = 1000
STEP = 0.08
NOISE = 0.01
BACKGROUND_HZ = 1.0
RASTER_MM = 0.05
SIDE_MM = 100.0
TEXTURES = ("grating2", "grating4_45", "knurl", "dots")


def height(name, x, y, dots):
    """The texture's height (0 to 1) at points x, y (mm)."""
    if name == "grating2":
        return 0.5 + 0.5 * np.cos(2 * np.pi * x / 2.0)
    if name == "grating4_45":
        return 0.5 + 0.5 * np.cos(2 * np.pi * (x + y) / np.sqrt(2) / 4.0)
    if name == "knurl":
        k = 2 * np.pi / 2.5
        return 0.25 * (2 + np.cos(k * x) + np.cos(k * y))
    # dots: a raster of the bumps at 0.05 mm, read at the nearest cell
    i = np.clip(np.rint(y / RASTER_MM).astype(int), 0, dots.shape[0] - 1)
    j = np.clip(np.rint(x / RASTER_MM).astype(int), 0, dots.shape[1] - 1)
    return dots[i, j]


def dot_raster(rng):
    """Round bumps of 0.5 mm radius at random places, one per 6 mm^2, on a 100 mm square."""
    n = int(SIDE_MM / RASTER_MM)
    raster = np.zeros((n, n))
    reach = int(np.ceil(0.5 / RASTER_MM))
    d = np.arange(-reach, reach + 1) * RASTER_MM
    cap = np.clip(1 - (d[:, None] ** 2 + d[None] ** 2) / 0.25, 0, None)
    for cy, cx in rng.integers(reach, n - reach, (int(SIDE_MM**2 / 6), 2)):
        window = raster[cy - reach : cy + reach + 1, cx - reach : cx + reach + 1]
        np.maximum(window, cap, out=window)
    return raster


def pressure(name, trial_rng, speed, dots):
    """Each taxel's pressure at 1 kHz during the slide: (steps, rows, cols)."""
    steps = int(SLIDE_MM / speed * FS_HZ)
    x0 = trial_rng.uniform(0, 40)
    y0 = trial_rng.uniform(0, 40)
    angle = np.deg2rad(trial_rng.uniform(-5, 5))
    v = speed * trial_rng.uniform(0.95, 1.05)
    force = trial_rng.uniform(0.85, 1.15)
    # The cover's spread: a few offsets within it, Gaussian-weighted.
    offsets = np.array([(dx, dy) for dx in (-0.6, 0, 0.6) for dy in (-0.6, 0, 0.6)])
    weights = np.exp(-(offsets**2).sum(1) / (2 * COVER_MM**2))
    weights /= weights.sum()
    t = np.arange(steps) / FS_HZ
    r, c = np.meshgrid(np.arange(ROWS), np.arange(COLS), indexing="ij")
    out = np.zeros((steps, ROWS, COLS))
    for (dx, dy), w in zip(offsets, weights):
        # sensor frame: columns along the slide, rows across it
        sx = c[None] * PITCH_MM + dx + v * t[:, None, None]
        sy = r[None] * PITCH_MM + dy + np.zeros_like(t)[:, None, None]
        x = x0 + np.cos(angle) * sx - np.sin(angle) * sy
        y = y0 + np.sin(angle) * sx + np.cos(angle) * sy
        out += w * height(name, x, y, dots)
    return force * out


def events(p, gain, rng):
    """Level-crossing events of a pressure array (steps, rows, cols) as (x, y, t_us, pol)."""
    steps = p.shape[0]
    p = p * gain[None] + rng.normal(0, NOISE, p.shape)
    ref = p[0].copy()
    xs, ys, ts, ps = [], [], [], []
    for k in range(1, steps):
        d = p[k] - ref
        on = d >= STEP
        off = d <= -STEP
        # one event per taxel, polarity and step; the reference follows by whole steps
        n = np.floor(np.abs(d) / STEP)
        ref = np.where(on | off, ref + np.sign(d) * n * STEP, ref)
        for mask, pol in ((on, 1), (off, 0)):
            rr, cc = np.nonzero(mask)
            xs.append(cc)
            ys.append(rr)
            ts.append(k * 1000 + rng.integers(0, 1000, len(rr)))
            ps.append(np.full(len(rr), pol))
    # background events
    duration_us = steps * 1000
    n_bg = rng.poisson(BACKGROUND_HZ * steps / FS_HZ * ROWS * COLS * 2)
    xs.append(rng.integers(0, COLS, n_bg))
    ys.append(rng.integers(0, ROWS, n_bg))
    ts.append(rng.integers(0, duration_us, n_bg))
    ps.append(rng.integers(0, 2, n_bg))
    dtype = np.dtype([("x", "<i8"), ("y", "<i8"), ("t", "<i8"), ("p", "<i8")])
    a = np.zeros(sum(len(t) for t in ts), dtype=dtype)
    for field, parts in (("x", xs), ("y", ys), ("t", ts), ("p", ps)):
        a[field] = np.concatenate(parts)
    return np.sort(a, order="t"), duration_us / 1e6


def main() -> None:
    parser = argparse.ArgumentParser(
        description="Write a synthetic 8x8 event skin's dataset (four textures, three speeds).",
        epilog="Example: python3 tools/event_skin.py /tmp/skin 10 0",
    )
    parser.add_argument("out", help="the dataset folder to create (must not exist)")
    parser.add_argument("trials", nargs="?", type=int, default=10,
                        help="trials per texture and speed (default 10)")
    parser.add_argument("seed", nargs="?", type=int, default=0, help="random seed (default 0)")
    args = parser.parse_args()
    if args.trials < 1:
        parser.error("trials must be at least 1")
    out = args.out
    if os.path.exists(out):
        parser.error(f"{out} exists: give a folder to create")
    os.makedirs(out)
    rng = np.random.default_rng(args.seed)
    trials = args.trials
    gain = rng.uniform(0.8, 1.2, (ROWS, COLS))
    dots = dot_raster(rng)
    lines = ["file,label,speed_mm_s,trial,duration_s"]
    for name in TEXTURES:
        for speed in SPEEDS_MM_S:
            for trial in range(trials):
                p = pressure(name, rng, speed, dots)
                a, duration = events(p, gain, rng)
                file = f"{name}_v{int(speed)}_t{trial:02d}.npy"
                np.save(os.path.join(out, file), a)
                lines.append(f"{file},{name},{speed:g},{trial},{duration:g}")
    with open(os.path.join(out, "manifest.csv"), "w") as f:
        f.write("\n".join(lines) + "\n")
    with open(os.path.join(out, "layout.toml"), "w") as f:
        f.write(
            f'rows = {ROWS}\ncols = {COLS}\n\n[events]\ntime_unit = "us"\n'
            'x = "x"\ny = "y"\npolarity = "p"\nvalues = [1, 0]\n'
        )
    n = len(lines) - 1
    print(f"{n} recordings ({len(TEXTURES)} textures x {len(SPEEDS_MM_S)} speeds x {trials} "
          f"trials) on an {ROWS}x{COLS} grid -> {out}")


if __name__ == "__main__":
    main()
