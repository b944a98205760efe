"""Rockpool on a `--for rockpool` graph: `rockpool.nn.modules.from_nir(graph)`, one call on
(1, steps, inputs); scores = the readout ExpSynTorch's output, mean over time."""
import os
import sys

import nir
import numpy as np
import torch
from rockpool.nn.modules.torch.nir import from_nir

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common

if __name__ == "__main__":
    path, inputs, preds = common.args()
    net = from_nir(nir.read(path))
    labels, items = common.load(inputs, preds)
    scores = []
    with torch.no_grad():
        for _, x, _, _ in items:
            for m in net.modules():
                if hasattr(m, "reset_state") and m is not net:
                    m.reset_state()
            out = net(torch.from_numpy(x)[None])
            out = out[0] if isinstance(out, tuple) else out
            scores.append(out[0].double().numpy().mean(axis=0))
    tool = f"rockpool [{common.versions('rockpool', 'nir', 'nirtorch', 'torch')}]"
    sys.exit(0 if common.report(tool, labels, items, scores) else 1)
