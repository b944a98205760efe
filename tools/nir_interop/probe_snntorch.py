"""snnTorch on a `--for snntorch` graph: `import_from_nir`, stepped once per time step (its
importer steps at dt = 0.1 ms whatever the metadata, which that graph is scaled to);
scores = the readout's membrane (`.mem`), mean over time."""
import os
import sys

import nir
import numpy as np
import torch
import snntorch as snn
import snntorch.utils
from snntorch.import_nir import import_from_nir

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common

if __name__ == "__main__":
    path, inputs, preds = common.args()
    graph = nir.read(path)
    net = import_from_nir(graph)
    readout = getattr(net, common.readout_name(graph))  # a Synaptic that never fires
    labels, items = common.load(inputs, preds)
    scores = []
    with torch.no_grad():
        for _, x, _, _ in items:
            snn.utils.reset(net)
            xt = torch.from_numpy(x)
            trace, state = [], None
            for t in range(xt.shape[0]):
                _, state = net(xt[t:t + 1], state)  # nirtorch returns (output, state)
                trace.append(readout.mem[0].double().numpy().copy())
            scores.append(np.mean(trace, axis=0))
    tool = f"snntorch [{common.versions('snntorch', 'nir', 'nirtorch', 'torch')}]"
    sys.exit(0 if common.report(tool, labels, items, scores) else 1)
