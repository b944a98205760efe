"""Generates crates/neurotex/tests/data/van_rossum_reference.json: van Rossum distances
from Elephant (elephant.spike_train_dissimilarity.van_rossum_distance) that
tests/spike_distance.rs compares neurotex against.

Elephant normalises so that one spike against none gives 1; neurotex (van Rossum 2001,
D^2 = (1/tau) * integral of (f - g)^2) gives sqrt(1/2). The stored values are Elephant's
divided by sqrt(2), as Elephant's docstring says to get the paper's normalisation; the raw
values are stored too. Re-run with

    python3.11 -m venv /tmp/vr && /tmp/vr/bin/pip install elephant
    /tmp/vr/bin/python crates/neurotex/tests/reference/make_van_rossum_reference.py

Spike trains are generated here from a fixed seed (integer ms, as neurotex's encoder
produces) and stored beside the distances.
"""
import json
import os

import elephant
import neo
import numpy as np
import quantities as pq
from elephant.spike_train_dissimilarity import van_rossum_distance

rng = np.random.default_rng(20170811)
cases = []
for n_steps, rate_hz in [(200, 50.0), (2000, 20.0), (18000, 20.0), (18000, 5.0)]:
    trains = []
    for _ in range(3):
        spikes = np.flatnonzero(rng.random(n_steps) < rate_hz / 1000.0)
        trains.append([int(t) for t in spikes])
    for tau_ms in [1.0, 10.0, 50.0, 200.0]:
        neo_trains = [
            neo.SpikeTrain(np.array(t, dtype=float), units="ms", t_stop=float(n_steps))
            for t in trains
        ]
        raw = van_rossum_distance(neo_trains, time_constant=tau_ms * pq.ms)
        cases.append(
            {
                "tau_ms": tau_ms,
                "trains": trains,
                "elephant": raw.tolist(),
                "distance": (raw / np.sqrt(2.0)).tolist(),
            }
        )

out = {
    "tool": f"elephant {elephant.__version__} (neo {neo.__version__}, numpy {np.__version__})",
    "function": "elephant.spike_train_dissimilarity.van_rossum_distance, divided by sqrt(2)",
    "cases": cases,
}
here = os.path.dirname(os.path.abspath(__file__))
path = os.path.join(here, "..", "data", "van_rossum_reference.json")
with open(path, "w") as f:
    json.dump(out, f)
print(path, len(cases), "cases")
