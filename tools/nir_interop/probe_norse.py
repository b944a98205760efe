"""Norse on a `--for nir` or `--for snntorch` graph: `norse.torch.from_nir(graph, dt=the
metadata's dt)`, stepped once per time step; scores = the readout CubaLIF's membrane (the
second part of its state: synapse, then LIF), mean over time."""
import os
import sys

import nir
import numpy as np
import torch
import norse.torch

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common


def membrane(state):
    while isinstance(state, tuple) and len(state) == 1:
        state = state[0]
    _synapse, lif = state
    return lif.v


if __name__ == "__main__":
    path, inputs, preds = common.args()
    graph = nir.read(path)
    ro = common.readout_name(graph)
    net = norse.torch.from_nir(graph, dt=float(np.asarray(graph.metadata["dt"])))
    labels, items = common.load(inputs, preds)
    scores = []
    with torch.no_grad():
        for _, x, _, _ in items:
            xt = torch.from_numpy(x)
            trace, state = [], None
            for t in range(xt.shape[0]):
                _, state = net(xt[t:t + 1], state)
                trace.append(membrane(state.state[ro])[0].double().numpy().copy())
            scores.append(np.mean(trace, axis=0))
    tool = f"norse [{common.versions('norse', 'nir', 'nirtorch', 'torch')}]"
    sys.exit(0 if common.report(tool, labels, items, scores) else 1)
