"""The NIR export checked against the reference implementation: the graph `neurotex
export nir` writes is read with the `nir` package and run, on the tensors `neurotex export
inputs` writes, by a small simulator of NIR's published equations written here (forward
Euler at the graph's `dt`, the current before the membrane); its predictions are those of
`neurotex predict`, and so are those of the graph read back by neurotex."""

import csv

import nir
import numpy as np


def run_graph(graph, x):
    """Class scores of one recording `x` (steps, inputs): NIR's node equations stepped at
    the metadata's dt, scores the readout's mean (or max) over time."""
    dt = float(np.asarray(graph.metadata["dt"]))
    follow = {src: dst for src, dst in graph.edges}
    order = [name for name, node in graph.nodes.items() if isinstance(node, nir.Input)]
    while order[-1] in follow:
        order.append(follow[order[-1]])
    state = {}
    trace = []
    for t in range(x.shape[0]):
        a = x[t].astype(np.float64)
        for name in order[1:-1]:
            node = graph.nodes[name]
            if isinstance(node, nir.Affine):
                a = node.weight.astype(np.float64) @ a + node.bias
            elif isinstance(node, nir.CubaLIF):
                i, v = state.get(name, (np.zeros_like(node.tau_syn), np.zeros_like(node.tau_mem)))
                i = i + dt / node.tau_syn * (-i + node.w_in * a)
                v = v + dt / node.tau_mem * (node.v_leak - v + node.r * i)
                spikes = v >= node.v_threshold
                v = np.where(spikes, node.v_reset, v)
                state[name] = (i, v)
                a = spikes.astype(np.float64)
            elif isinstance(node, nir.LI):
                v = state.get(name, np.zeros_like(node.tau))
                v = v + dt / node.tau * (node.v_leak - v + node.r * a)
                state[name] = v
                a = v
            else:
                raise AssertionError(f"unexpected node {name}: {type(node).__name__}")
        trace.append(a)
    trace = np.array(trace)
    readout = str(np.asarray(graph.metadata.get("readout", "mean")))
    return trace.max(axis=0) if readout == "max" else trace.mean(axis=0)


def test_exported_graph_runs_in_nirs_equations_as_in_neurotex(cli, sim_dir, tmp_path):
    model = tmp_path / "snn.json"
    cli("train", "--dataset", sim_dir, "--speeds", "5", "--classifier", "snn",
        "--encoding", "sa+fa", "--snn-epochs", "10", "--out", model)
    graph_file = tmp_path / "snn.nir"
    cli("export", "nir", "--model", model, "--out", graph_file)
    inputs = tmp_path / "inputs"
    cli("export", "inputs", "--model", model, "--dataset", sim_dir, "--out", inputs)
    predicted = tmp_path / "pred.csv"
    cli("predict", "--model", model, "--dataset", sim_dir, "--out", predicted)
    again = tmp_path / "pred_nir.csv"
    cli("predict", "--model", graph_file, "--dataset", sim_dir, "--out", again)

    graph = nir.read(str(graph_file))
    assert [type(graph.nodes[n]).__name__ for n in ("input", "fc1", "lif1", "fc2", "li", "output")] == [
        "Input", "Affine", "CubaLIF", "Affine", "LI", "Output"]
    labels = [c[len("share_"):] for c in next(csv.reader(open(predicted)))[3:]]
    rows = list(csv.DictReader(open(predicted)))
    index = list(csv.DictReader(open(inputs / "index.csv")))
    assert len(rows) == len(index) == 30
    agree = 0
    for row, entry in zip(rows, index):
        assert row["file"].endswith(entry["file"]) or entry["file"].endswith(row["file"])
        x = np.load(inputs / entry["array"])
        assert x.dtype == np.float32 and x.shape[1] == 32
        scores = run_graph(graph, x)
        shares = np.exp(scores - scores.max())
        shares /= shares.sum()
        theirs = np.array([float(row[f"share_{label}"]) for label in labels])
        np.testing.assert_allclose(shares, theirs, rtol=1e-6, atol=1e-9)
        agree += labels[int(np.argmax(shares))] == row["predicted"]
    assert agree == len(rows)
    # The graph read back by neurotex predicts exactly what the model file does.
    assert open(again).read() == open(predicted).read()
