"""The NIR export checked against the reference implementation: the graph `neurotex
export nir` writes is read with the `nir` package and run, on the tensors `neurotex export
inputs` writes, by a small simulator of NIR's published equations written here (forward
Euler at the graph's `dt`, the current before the membrane); its predictions are those of
`neurotex predict`, and so are those of the graph read back by neurotex."""

import csv

import nir
import numpy as np
import pytest


def run_graph(graph, x):
    """Class scores of one recording `x` (steps, inputs): NIR's node equations stepped at
    the metadata's dt, scores the readout's mean (or max) over time. A recurrent loop
    (`lif → Linear → lif`) feeds a step's spikes into the next step's input."""
    dt = float(np.asarray(graph.metadata["dt"]))
    edges = [tuple(e) for e in graph.edges]
    linear = {n for n, node in graph.nodes.items() if isinstance(node, nir.Linear)}
    loops = {}  # CubaLIF -> the Linear nodes of its loop, in order
    for src, dst in edges:
        path = [dst]
        while path[-1] in linear and len(path) < 3:
            path.append(next(d for s, d in edges if s == path[-1]))
        if isinstance(graph.nodes[src], nir.CubaLIF) and path[-1] == src and len(path) > 1:
            loops[src] = path[:-1]
    on_loop = {n for path in loops.values() for n in path}
    follow = {src: dst for src, dst in edges if src not in on_loop and dst not in on_loop}
    order = [name for name, node in graph.nodes.items() if isinstance(node, nir.Input)]
    while order[-1] in follow:
        order.append(follow[order[-1]])
    readout = order[-2]
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
                if name in loops:
                    fed = state.get(name + "/spikes", np.zeros_like(node.tau_mem))
                    for linear_node in loops[name]:
                        fed = graph.nodes[linear_node].weight.astype(np.float64) @ fed
                    a = a + fed
                i = i + dt / node.tau_syn * (-i + node.w_in * a)
                v = v + dt / node.tau_mem * (node.v_leak - v + node.r * i)
                spikes = v >= node.v_threshold
                v_reset = getattr(node, "v_reset", None)
                v = np.where(spikes, 0.0 if v_reset is None else v_reset, v)
                state[name] = (i, v)
                a = spikes.astype(np.float64)
                state[name + "/spikes"] = a
                if name == readout:
                    a = v  # a readout that never fires is read by its membrane
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


@pytest.mark.parametrize("recurrent", [False, True])
def test_exported_graph_runs_in_nirs_equations_as_in_neurotex(cli, sim_dir, tmp_path, recurrent):
    model = tmp_path / "snn.json"
    cli("train", "--dataset", sim_dir, "--speeds", "5", "--classifier", "snn",
        "--encoding", "sa+fa", "--snn-epochs", "10", "--out", model,
        *(["--snn-recurrent"] if recurrent else []))
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
        "Input", "Affine", "CubaLIF", "Affine", "CubaLIF", "Output"]
    assert ("rec" in graph.nodes) == recurrent
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


def test_a_graph_written_by_the_nir_package_runs_with_a_pipeline_given_by_like(cli, sim_dir, tmp_path):
    """A graph as another tool writes it (`nir.write`, h5py's layout, only `dt` in the
    metadata, constants in float32) runs in `neurotex predict` with --like."""
    model = tmp_path / "snn.json"
    cli("train", "--dataset", sim_dir, "--speeds", "10", "--classifier", "snn",
        "--snn-epochs", "8", "--out", model)
    ours = tmp_path / "ours.nir"
    cli("export", "nir", "--model", model, "--out", ours)
    graph = nir.read(str(ours))
    nodes = {}
    for name, node in graph.nodes.items():
        if isinstance(node, nir.CubaLIF):
            node = nir.CubaLIF(**{k: np.asarray(getattr(node, k), dtype=np.float32) for k in (
                "tau_syn", "tau_mem", "r", "v_leak", "v_threshold", "w_in")})
        elif isinstance(node, nir.LI):
            node = nir.LI(tau=node.tau.astype(np.float32), r=node.r.astype(np.float32),
                          v_leak=node.v_leak.astype(np.float32))
        nodes[name] = node
    theirs = tmp_path / "theirs.nir"
    nir.write(str(theirs), nir.NIRGraph(nodes=nodes, edges=graph.edges,
                                        metadata={"dt": float(np.asarray(graph.metadata["dt"]))}))
    out = tmp_path / "never.csv"
    err = cli("predict", "--model", theirs, "--dataset", sim_dir, "--out", out, ok=False)
    assert err.returncode != 0 and "--like" in err.stderr and not out.exists()
    expected = tmp_path / "pred.csv"
    cli("predict", "--model", model, "--dataset", sim_dir, "--out", expected)
    got = tmp_path / "pred_theirs.csv"
    cli("predict", "--model", theirs, "--like", model, "--dataset", sim_dir, "--out", got)
    a = list(csv.reader(open(expected)))
    b = list(csv.reader(open(got)))
    assert [r[:3] for r in a] == [r[:3] for r in b]
    # float32 constants shift the decays by about 1e-7: shares agree closely, not exactly.
    np.testing.assert_allclose(np.array([r[3:] for r in a[1:]], dtype=float),
                               np.array([r[3:] for r in b[1:]], dtype=float), atol=1e-4)


def test_the_python_package_moves_a_spiking_model_to_nir_and_back(cli, sim_dir, sim, tmp_path):
    import neurotex

    path = tmp_path / "snn.json"
    cli("train", "--dataset", sim_dir, "--speeds", "5", "--classifier", "snn",
        "--snn-epochs", "8", "--out", path)
    model = neurotex.SpikingModel.load(path)
    assert "128 LIF neurons" in repr(model) and model.classes_ == ["FT1", "SB", "CP"]
    graph = model.to_nir()
    assert isinstance(graph, nir.NIRGraph) and float(np.asarray(graph.metadata["dt"])) == 0.01
    back = neurotex.SpikingModel.from_nir(graph)
    expected = tmp_path / "pred.csv"
    cli("predict", "--model", path, "--dataset", sim_dir, "--out", expected)
    rows = list(csv.DictReader(open(expected)))
    for m in (model, back):
        labels = m.predict(sim)
        assert list(labels) == [r["predicted"] for r in rows]
        shares = m.predict_proba(sim)
        np.testing.assert_allclose(shares, [[float(r[f"share_{c}"]) for c in m.classes_] for r in rows],
                                   rtol=1e-12, atol=1e-15)
