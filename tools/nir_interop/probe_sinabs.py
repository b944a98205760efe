"""sinabs on a `--for sinabs` graph: `sinabs.from_nir(graph, batch_size=1)` with its own
neurons (multi-spike, subtractive reset); scores = the readout LI's output (an ExpLeak
emits its membrane), mean over time. A feed-forward graph runs in one call on the whole
(steps, inputs) tensor; a recurrent one one time step per call, as nirtorch feeds a loop
back only between calls."""
import os
import sys

import nir
import numpy as np
import torch
import sinabs
import sinabs.layers as sl

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common

if __name__ == "__main__":
    path, inputs, preds = common.args()
    graph = nir.read(path)
    ro = common.readout_name(graph)
    recurrent = common.has_loop(graph)
    net = sinabs.from_nir(graph, batch_size=1)
    labels, items = common.load(inputs, preds)
    scores = []
    with torch.no_grad():
        for _, x, _, _ in items:
            for m in net.modules():
                if isinstance(m, sl.StatefulLayer):
                    m.reset_states()
            xt = torch.from_numpy(x)
            if recurrent:
                trace, state = [], None
                for t in range(xt.shape[0]):
                    _, state = net(xt[t:t + 1], state)
                    trace.append(state.cache[ro].double().numpy()[0])
                scores.append(np.mean(trace, axis=0))
            else:
                _, state = net(xt)
                scores.append(state.cache[ro].double().numpy().mean(axis=0))
    tool = f"sinabs [{common.versions('sinabs', 'nir', 'nirtorch', 'torch')}]"
    sys.exit(0 if common.report(tool, labels, items, scores) else 1)
