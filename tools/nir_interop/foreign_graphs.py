"""NIR graphs written by snnTorch and Norse, with the tools' own decisions, for neurotex's
tests of `predict --nir-from snntorch|norse --like MODEL.json`.

    python foreign_graphs.py LIKE.json INPUTS OUT [snntorch|norse|measure]

LIKE.json is the neurotex spiking model whose pipeline makes the input spikes (its labels
give the score order, its `network.dt_ms` the time step); INPUTS its `neurotex export
inputs` folder. Each network below is trained by its tool on INPUTS (a few epochs of
softmax cross-entropy on the mean of its readout's membrane, as neurotex trains), written
with the tool's own exporter to OUT/NAME.nir, and run by the tool on every recording:
OUT/NAME.scores.csv holds `file,predicted,score_<label>...` (the score of a class is the
mean of its readout membrane over the recording's steps, the decision its largest).

snntorch-synaptic  Linear -> Synaptic (reset zero, at once) -> Linear -> Leaky readout without
                   reset
snntorch-leaky     Linear -> Leaky (reset zero) -> Linear -> Leaky readout without reset
snntorch-rleaky    Linear -> RLeaky (all-to-all, reset zero at once) -> Linear -> Leaky
                   readout without reset (snnTorch writes the recurrent layer as a nested graph)
norse-lifbox       Linear -> LIFBoxCell -> Linear -> LIBoxCell, to_nir(dt = the step)

The Synaptic and RLeaky layers reset "at once" (`reset_delay=False`), as snnTorch's
importer runs their nodes: with snnTorch's default delayed reset to zero, their membrane
drops the step's input after each spike, which the graph cannot say (measured below for
Synaptic). RSynaptic is left out: in snnTorch 1.0.0 its reset at once fails (it reads the
call's arguments, None with `init_hidden=True`), and its delayed reset drops inputs.

It also measures, and prints, what a spiking snnTorch readout (a Leaky that fires and
subtracts its threshold, snnTorch's default) decides: by its spike counts, by the mean of
its membrane, and by the mean of a membrane that never resets (how neurotex reads the LIF
readout node), on a network trained with that readout.

Runs in a venv with snntorch 1.0.0, norse 1.1.0, nir 1.0.8, nirtorch 2.6 and torch (CPU).
Deterministic for a given torch build (seeded, one thread)."""
import csv
import json
import os
import sys
from importlib.metadata import version

import nir
import numpy as np
import torch

torch.set_num_threads(1)
HIDDEN = 16
EPOCHS = 30


def load(like_path, inputs_dir):
    with open(like_path) as f:
        like = json.load(f)
    labels = like["labels"]
    dt_s = like["network"]["dt_ms"] / 1000.0
    with open(os.path.join(inputs_dir, "index.csv")) as f:
        index = list(csv.DictReader(f))
    files = [e["file"] for e in index]
    xs = [np.load(os.path.join(inputs_dir, e["array"])).astype(np.float32) for e in index]
    y = torch.tensor([labels.index(e["label"]) for e in index])
    return labels, dt_s, files, xs, y


def batch(xs):
    """(recordings, steps, inputs), zero-padded to the longest, and each one's length."""
    steps = max(x.shape[0] for x in xs)
    out = np.zeros((len(xs), steps, xs[0].shape[1]), np.float32)
    for i, x in enumerate(xs):
        out[i, : x.shape[0]] = x
    return torch.from_numpy(out), [x.shape[0] for x in xs]


def mean_over(trace, lengths):
    """(recordings, classes): each recording's mean of `trace` (steps, recordings, classes)
    over its own steps."""
    return torch.stack([trace[:n, i].mean(0) for i, n in enumerate(lengths)])


def train(run, params, xs, y):
    """Full-batch Adam on the cross-entropy of `run(x, lengths)`'s scores."""
    x, lengths = batch(xs)
    opt = torch.optim.Adam(params, lr=0.01)
    for _ in range(EPOCHS):
        opt.zero_grad()
        loss = torch.nn.functional.cross_entropy(run(x, lengths), y)
        loss.backward()
        opt.step()
    return float(loss.detach())


def scores_each(run, xs):
    """The tool's scores, one recording at a time (no padding)."""
    with torch.no_grad():
        return [run(torch.from_numpy(x)[None], [x.shape[0]])[0].double().numpy() for x in xs]


def save(out, name, graph, labels, files, scores):
    # Uncompressed: the same graph as the default gzip, in a third of the bytes at this size.
    nir.write(os.path.join(out, f"{name}.nir"), graph, compression=None)
    with open(os.path.join(out, f"{name}.scores.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["file", "predicted"] + [f"score_{c}" for c in labels])
        for file, s in zip(files, scores):
            w.writerow([file, labels[int(np.argmax(s))]] + [repr(float(v)) for v in s])


def snntorch_net(kind, n_in, n_out, readout_reset="none", reset_delay=False):
    import snntorch as snn
    import snntorch.utils

    full = lambda v, n: torch.full((n,), v)
    if kind == "synaptic":
        hidden = snn.Synaptic(alpha=full(0.6, HIDDEN), beta=full(0.8, HIDDEN),
                              threshold=full(1.0, HIDDEN), reset_mechanism="zero",
                              reset_delay=reset_delay, init_hidden=True)
    elif kind == "leaky":
        hidden = snn.Leaky(beta=full(0.75, HIDDEN), threshold=full(1.0, HIDDEN),
                           reset_mechanism="zero", init_hidden=True)
    else:
        hidden = snn.RLeaky(beta=full(0.75, HIDDEN), threshold=full(1.0, HIDDEN),
                            reset_mechanism="zero", reset_delay=reset_delay, init_hidden=True,
                            all_to_all=True, linear_features=HIDDEN)
    readout = snn.Leaky(beta=full(0.8, n_out), threshold=full(1.0, n_out),
                        reset_mechanism=readout_reset, init_hidden=True, output=True)
    net = torch.nn.Sequential(torch.nn.Linear(n_in, HIDDEN), hidden,
                              torch.nn.Linear(HIDDEN, n_out), readout)

    def trace(x):
        """The readout's spikes and membrane, each (steps, recordings, classes)."""
        snn.utils.reset(net)
        for m in net:  # a fresh state, out of the last call's autograd graph
            for name in ("spk", "syn", "mem"):
                if isinstance(getattr(m, name, None), torch.Tensor):
                    setattr(m, name, torch.zeros_like(getattr(m, name)).detach())
        spikes, mems = [], []
        for t in range(x.shape[1]):
            spk, mem = net(x[:, t])
            spikes.append(spk)
            mems.append(mem)
        return torch.stack(spikes), torch.stack(mems)

    return net, trace


def snntorch_graphs(out, labels, files, xs, y):
    from snntorch.export_nir import export_to_nir

    for kind in ("synaptic", "leaky", "rleaky"):
        torch.manual_seed(1)
        net, trace = snntorch_net(kind, xs[0].shape[1], len(labels))
        run = lambda x, lengths: mean_over(trace(x)[1], lengths)
        loss = train(run, net.parameters(), xs, y)
        graph = export_to_nir(net, torch.zeros(xs[0].shape[1]))
        save(out, f"snntorch-{kind}", graph, labels, files, scores_each(run, xs))
        print(f"snntorch-{kind}: trained to loss {loss:.3f}")


def snntorch_spiking_readout(labels, xs, y):
    """What a spiking readout decides, three ways, on a network trained on its membrane."""
    torch.manual_seed(2)
    net, trace = snntorch_net("synaptic", xs[0].shape[1], len(labels), readout_reset="subtract")
    train(lambda x, n: mean_over(trace(x)[1], n), net.parameters(), xs, y)
    readout = net[3]
    beta = readout.beta.detach()
    agree_counts = agree_mean = fired = 0
    with torch.no_grad():
        for x in xs:
            spikes, mem = trace(torch.from_numpy(x)[None])
            # The readout's input each step, from its membrane: the change, plus the decay
            # and the threshold subtracted after a spike the step before.
            v, unreset = torch.zeros_like(mem[0, 0]), []
            prev, prev_spk = torch.zeros_like(mem[0, 0]), torch.zeros_like(mem[0, 0])
            for t in range(mem.shape[0]):
                inp = mem[t, 0] - beta * prev + prev_spk * readout.threshold
                v = beta * v + inp
                unreset.append(v.clone())
                prev, prev_spk = mem[t, 0], spikes[t, 0]
            ours = int(torch.stack(unreset).mean(0).argmax())
            by_mean = int(mem[:, 0].mean(0).argmax())
            by_counts = int(spikes[:, 0].sum(0).argmax())
            fired += int(spikes.sum() > 0)
            agree_mean += ours == by_mean
            agree_counts += ours == by_counts
    n = len(xs)
    print(f"spiking snnTorch readout (reset subtract): fired in {fired}/{n} recordings; "
          f"a never-resetting membrane's mean agrees with its membrane mean in {agree_mean}/{n}, "
          f"with its spike counts in {agree_counts}/{n}")


def snntorch_delayed_reset(labels, xs, y):
    """What a Synaptic hidden layer with snnTorch's default delayed reset decides, against
    the same weights run as snnTorch's importer runs the exported CubaLIF node (reset at
    once, `reset_delay=False`), which is how neurotex reads the graph too."""
    torch.manual_seed(1)
    net, trace = snntorch_net("synaptic", xs[0].shape[1], len(labels), reset_delay=True)
    train(lambda x, n: mean_over(trace(x)[1], n), net.parameters(), xs, y)
    delayed = scores_each(lambda x, n: mean_over(trace(x)[1], n), xs)
    net[1].reset_delay = False
    at_once = scores_each(lambda x, n: mean_over(trace(x)[1], n), xs)
    agree = sum(int(np.argmax(a) == np.argmax(b)) for a, b in zip(delayed, at_once))
    print(f"snnTorch Synaptic with the default delayed reset: its decisions agree with the "
          f"exported graph's (reset at once) in {agree}/{len(xs)}")


def norse_graph(out, labels, dt_s, files, xs, y):
    import norse.torch as norse

    torch.manual_seed(3)
    n_in, n_out = xs[0].shape[1], len(labels)
    full = lambda v, n: torch.full((n,), v)
    hidden = norse.LIFBoxCell(norse.LIFBoxParameters(
        tau_mem_inv=full(1 / 0.04, HIDDEN), v_leak=full(0.0, HIDDEN), v_th=full(1.0, HIDDEN),
        v_reset=full(0.0, HIDDEN)), dt=dt_s)
    readout = norse.LIBoxCell(norse.LIBoxParameters(
        tau_mem_inv=full(1 / 0.05, n_out), v_leak=full(0.0, n_out)), dt=dt_s)
    net = norse.SequentialState(torch.nn.Linear(n_in, HIDDEN), hidden,
                                torch.nn.Linear(HIDDEN, n_out), readout)
    with torch.no_grad():  # PyTorch's initial weights leave Norse's box neurons silent here
        net[0].weight.mul_(8.0)
        net[2].weight.mul_(4.0)

    def run(x, lengths):
        state, trace = None, []
        for t in range(x.shape[1]):
            o, state = net(x[:, t], state)
            trace.append(o)
        return mean_over(torch.stack(trace), lengths)

    loss = train(run, net.parameters(), xs, y)
    graph = norse.to_nir(net, torch.zeros(1, n_in), dt=dt_s)
    save(out, "norse-lifbox", graph, labels, files, scores_each(run, xs))
    print(f"norse-lifbox: trained to loss {loss:.3f}")


def main():
    if len(sys.argv) not in (4, 5):
        sys.exit("usage: python foreign_graphs.py LIKE.json INPUTS OUT [snntorch|norse|measure]")
    like, inputs, out = sys.argv[1:4]
    only = sys.argv[4] if len(sys.argv) == 5 else None
    os.makedirs(out, exist_ok=True)
    labels, dt_s, files, xs, y = load(like, inputs)
    print("versions: " + ", ".join(f"{p} {version(p)}" for p in
                                   ("snntorch", "norse", "nir", "nirtorch", "torch", "numpy")))
    if only in (None, "snntorch"):
        snntorch_graphs(out, labels, files, xs, y)
    if only in (None, "norse"):
        norse_graph(out, labels, dt_s, files, xs, y)
    if only in (None, "measure"):
        snntorch_spiking_readout(labels, xs, y)
        snntorch_delayed_reset(labels, xs, y)


if __name__ == "__main__":
    main()
