"""XyloSim on an `export xylo` configuration: Rockpool's `XyloSim.from_specification`
(xylosim's bit-accurate simulator of Xylo Audio 2), run with `output_mode="Vmem"` on
neurotex's exported inputs; scores = the readout membrane's mean (or largest value) over
the window divided by the file's `score_scale`.

    python probe_xylo.py CONFIG.json INPUTS PREDICTIONS

Prints the comparison line run.sh's probes print, then `accuracy: XyloSim R/N`."""
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common
import samna_standin  # noqa: F401  (Rockpool's Xylo package imports samna, a board driver)
from rockpool.devices.xylo.syns61201 import XyloSim

if __name__ == "__main__":
    path, inputs, preds = common.args()
    with open(path) as f:
        config = json.load(f)
    spec = {k: np.array(v) if isinstance(v, list) else v for k, v in config["specification"].items()}
    sim = XyloSim.from_specification(**spec, output_mode="Vmem")
    labels, items = common.load(inputs, preds)
    if labels != config["labels"]:
        sys.exit(f"the predictions' classes {labels} are not the configuration's {config['labels']}")
    scores = []
    for _, x, _, _ in items:
        sim.reset_state()
        out, _, _ = sim(np.rint(x).astype(int))
        v = np.asarray(out, dtype=np.float64).reshape(len(x), -1)
        s = v.mean(axis=0) if config["readout"] == "mean" else v.max(axis=0)
        scores.append(s / config["score_scale"])
    tool = f"xylosim [{common.versions('rockpool', 'xylosim')}]"
    ok = common.report(tool, labels, items, scores)
    truth = dict(common.truth(preds))
    right = sum(labels[int(np.argmax(s))] == truth[name] for (name, _, _, _), s in zip(items, scores))
    print(f"accuracy: XyloSim {right}/{len(items)}")
    sys.exit(0 if ok else 1)
