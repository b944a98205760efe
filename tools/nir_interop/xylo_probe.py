"""Records XyloSim's states for the small cases neurotex's Xylo tests check
(crates/neurotex-learn/src/snn/xylo.rs): decays, spikes, saturation, the readout's delay.

Run in a virtual environment with Rockpool 3.1 and xylosim 0.1.3 (see run_xylo.sh):
    python tools/nir_interop/xylo_probe.py
Prints one JSON object per case."""
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import samna_standin  # noqa: F401  (Rockpool's Xylo package imports samna, a board driver)
from rockpool.devices.xylo.syns61201 import XyloSim


def run(w_in, w_out, x, **kw):
    w_in, w_out = np.array(w_in), np.array(w_out)
    n_in, n_h = w_in.shape
    n_out = w_out.shape[1]
    weights = np.zeros((n_in, n_h, 2), int)
    weights[:, :, 0] = w_in
    args = dict(dash_mem=np.full(n_h, 1), dash_syn=np.full(n_h, 1), dash_mem_out=np.full(n_out, 1),
                dash_syn_out=np.full(n_out, 1), threshold=np.full(n_h, 30000),
                threshold_out=np.full(n_out, 32767), bias=np.zeros(n_h, int), bias_out=np.zeros(n_out, int))
    args.update({k: np.array(v) if isinstance(v, list) else v for k, v in kw.items()})
    sim = XyloSim.from_specification(weights_in=weights, weights_out=w_out, dt=1e-3, output_mode="Vmem", **args)
    _, _, rec = sim(np.array(x), record=True)
    return {k: np.asarray(v).reshape(len(x), -1).T.tolist() for k, v in rec.items()}


def case(name, *a, **kw):
    print(json.dumps({"case": name, **run(*a, **kw)}))


if __name__ == "__main__":
    # Three hidden neurons, two readouts, dashes of one per layer.
    x = np.zeros((8, 2), int)
    x[0, 0], x[3, 0], x[1, 1] = 1, 2, 3
    case("small", [[10, 0, 100], [0, -20, 0]], [[50, 0], [0, 0], [0, 7]], x, dash_mem=[2, 2, 2],
         dash_syn=[1, 1, 1], dash_mem_out=[2, 2], threshold=[30, 30, 60], threshold_out=[100, 100])
    case("bias", [[0]], [[1]], np.zeros((4, 1), int), bias=[8], dash_mem=[2])
    case("cap", [[127]], [[1]], [[15], [0], [0]], threshold=[10], weight_shift_in=3)
    case("clip", [[3]], [[1]], [[20], [0]], threshold=[1000])
    x3 = np.zeros((2, 3), int)
    x3[0] = 15
    case("order", [[127], [127], [-127]], [[1]], x3, weight_shift_in=4, dash_syn=[15])
    case("negative_saturation", [[-128]], [[1]], [[15], [15], [15]], threshold=[10], weight_shift_in=7)
    # One input event into one synapse, then its decay alone, for the dashes and weights
    # of decay_follows_the_chip_to_the_last_unit.
    for d, w in [(1, 10), (1, -10), (2, 10), (2, -100), (4, -100), (15, 100)]:
        x = np.zeros((12, 1), int)
        x[0, 0] = 1
        case(f"decay_d{d}_w{w}", [[w]], [[1]], x, dash_syn=[d])
    case("readout_fires", [[100]], [[10]], [[1], [0], [0], [0], [0]], threshold=[20], threshold_out=[5])
