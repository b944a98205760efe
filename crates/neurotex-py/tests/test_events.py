"""Spikes as tonic's event arrays: neurotex.events gives the events `neurotex export events`
writes, an exported event dataset gives them back, and neurotex.tonic.Dataset serves them
with tonic's dataset interface (tested against tonic itself where it is installed)."""

import csv

import numpy as np
import pytest

import neurotex
import neurotex.tonic
from neurotex.errors import ParameterError

from conftest import run_cli


@pytest.fixture(scope="module")
def exported(sim_dir, tmp_path_factory):
    """The simulated dataset's sa+fa spikes written by the CLI as tonic .npy events."""
    out = tmp_path_factory.mktemp("events") / "ev"
    run_cli("export", "events", "--dataset", sim_dir, "--out", out, "--format", "npy",
            "--encoding", "sa+fa")
    return out


def exported_arrays(folder):
    with open(folder / "manifest.csv") as f:
        return [np.load(folder / row["file"]) for row in csv.DictReader(f)]


def test_events_are_the_cli_export_and_read_back_unchanged(sim_dir, exported):
    written = exported_arrays(exported)
    assert len(written) == 30
    ours = neurotex.events(sim_dir, encoding="sa+fa")
    again = neurotex.events(exported, encoding="sa+fa")
    for w, a, b in zip(written, ours, again):
        assert w.dtype.names == ("x", "y", "t", "p") and a.dtype == neurotex.EVENT_DTYPE
        assert np.array_equal(a, w.astype(neurotex.EVENT_DTYPE))
        assert np.array_equal(b, a)
        assert np.all(np.diff(a["t"]) >= 0) and set(np.unique(a["p"])) <= {0, 1}
        assert np.all(a["t"] % 1000 == 0), "1 ms spikes, in microseconds"
    # sa alone is the ON half of sa+fa; rows picks recordings
    sa = neurotex.events(sim_dir, [3, 0], encoding="sa")
    assert np.array_equal(sa[1], ours[0][ours[0]["p"] == 1])
    assert np.array_equal(sa[0], ours[3][ours[3]["p"] == 1])


def test_the_tonic_dataset_interface(exported):
    data = neurotex.tonic.Dataset(exported, encoding="sa+fa")
    assert len(data) == 30 and data.sensor_size == (4, 4, 2) and data.ordering == "xytp"
    assert data.classes == ["CP", "FT1", "SB"]
    labels = [r["label"] for r in csv.DictReader(open(exported / "manifest.csv"))]
    assert [data.classes[t] for t in data.targets] == labels
    events, target = data[4]
    assert np.array_equal(events, neurotex.events(exported, [4], encoding="sa+fa")[0])
    assert target == data.targets[4]
    assert np.array_equal(data[-1][0], data[29][0])
    with pytest.raises(IndexError):
        data[30]
    shifted = neurotex.tonic.Dataset(
        exported, encoding="sa+fa", transform=lambda e: len(e),
        target_transform=lambda t: data.classes[t],
        transforms=lambda e, t: (e * 2, t.lower()))
    assert shifted[4] == (2 * len(events), data.classes[target].lower())
    with pytest.raises(ParameterError, match="gain='auto'"):
        neurotex.tonic.Dataset(exported, gain="auto")


def test_tonic_transforms_take_the_events(exported):
    tonic = pytest.importorskip("tonic")
    data = neurotex.tonic.Dataset(
        exported, encoding="sa+fa",
        transform=tonic.transforms.ToFrame(sensor_size=(4, 4, 2), time_window=200_000))
    frames, _ = data[0]
    events, _ = neurotex.tonic.Dataset(exported, encoding="sa+fa")[0]
    # ToFrame: (frames, polarities, y, x) counts of whole 200 ms windows from the first
    # event (a last, partial window is dropped); every event inside lands in one frame
    assert frames.shape[1:] == (2, 4, 4)
    inside = events[events["t"] < events["t"][0] + frames.shape[0] * 200_000]
    assert 0 < len(events) - len(inside) < len(events) / 10
    assert frames.sum() == len(inside)
    on = inside[inside["p"] == 1]
    assert frames[:, 1].sum() == len(on)
    assert frames[:, 1, on["y"][0], on["x"][0]].sum() == np.sum(
        (on["y"] == on["y"][0]) & (on["x"] == on["x"][0]))


def test_a_python_event_stream_decides_as_the_command_line(exported, tmp_path):
    # A model trained on the exported event dataset; one recording's events streamed from
    # Python (tonic's array, t in us) and through `neurotex stream --format events-bin`.
    model = tmp_path / "ev_model.json"
    run_cli("train", "--dataset", exported, "--encoding", "sa+fa", "--out", model)
    events = neurotex.events(exported, [5], encoding="sa+fa")[0]
    with open(exported / "manifest.csv") as f:
        duration_s = float(list(csv.DictReader(f))[5]["duration_s"])
    end_us = int(round(duration_s * 1000)) * 1000
    stream = neurotex.StreamClassifier(str(model), events=True, time_unit="us")
    lines = (stream.push_events(events) or []) + (stream.push_event(end_us) or [])
    lines += stream.finish() or []
    assert len(lines) > 20 and lines[-1]["end"] is True
    record = np.dtype([("t", "<i8"), ("x", "<u2"), ("y", "<u2"), ("p", "i1"), ("kind", "u1"),
                       ("pad", "<u2")])
    records = np.zeros(len(events) + 1, record)
    for name in ("t", "x", "y", "p"):
        records[name][:-1] = events[name]
    records["t"][-1], records["kind"][-1] = end_us, 1
    path = tmp_path / "events.bin"
    records.tofile(path)
    out = run_cli("stream", "--model", model, "--format", "events-bin", "--input", path)
    import json
    cli = [json.loads(l) for l in out.stdout.splitlines()]
    for line in cli:
        line.pop("bad_frames", None)
    assert lines == cli
    # Frames are refused on an event stream, events on a frame stream.
    with pytest.raises(ParameterError, match="push_event"):
        stream.push([0.0] * 16)
    with pytest.raises(ParameterError, match="zero"):
        neurotex.StreamClassifier(str(model), events=True, origin="start")
    with pytest.raises(neurotex.DataError, match="outside the 4x4 grid"):
        stream.push_event(end_us + 1000, 7, 0, 1)


def test_an_event_dataset_trains_and_predicts_as_the_cli_does(exported, tmp_path):
    """A dataset folder of address events, given to Model.train and predict, runs the
    CLI's own train and predict workflows: the same model file, byte for byte, and the
    same predictions, for the spiking network and a feature classifier alike."""
    for name, kind, knobs, flags in [
        ("snn", "snn", {"hidden": 8, "epochs": 2}, ["--snn-hidden", "8", "--snn-epochs", "2"]),
        ("knn", "knn", {"k": 3}, ["-k", "3"]),
    ]:
        model = neurotex.Model.train(exported, classifier=kind, classifier_options=knobs,
                                     encoding="sa+fa")
        assert isinstance(model, neurotex.SpikingModel) == (kind == "snn")
        model.save(tmp_path / f"py-{name}.json")
        run_cli("train", "--dataset", exported, "--classifier", kind, "--encoding", "sa+fa",
                *flags, "--out", tmp_path / f"cli-{name}.json")
        assert (tmp_path / f"py-{name}.json").read_bytes() == \
            (tmp_path / f"cli-{name}.json").read_bytes()
        labels = model.predict(exported)
        shares = model.predict_proba(exported)
        run_cli("predict", "--model", tmp_path / f"cli-{name}.json", "--dataset", exported,
                "--out", tmp_path / f"cli-{name}.csv")
        with open(tmp_path / f"cli-{name}.csv") as f:
            rows = list(csv.DictReader(f))
        assert list(labels) == [r["predicted"] for r in rows]
        cli_shares = [[float(r[f"share_{c}"]) for c in model.classes_] for r in rows]
        assert np.array_equal(shares, np.array(cli_shares))


def test_a_sampled_folder_trains_the_cli_model_and_a_bad_path_is_named(sim_dir, tmp_path):
    model = neurotex.Model.train(sim_dir, method="glcm3d", speeds=[5])
    model.save(tmp_path / "py.json")
    run_cli("train", "--dataset", sim_dir, "--speeds", "5", "--out", tmp_path / "cli.json")
    assert (tmp_path / "py.json").read_bytes() == (tmp_path / "cli.json").read_bytes()
    with pytest.raises(neurotex.NotFoundError, match="no such dataset folder"):
        model.predict(str(tmp_path / "missing"))
    with pytest.raises(ParameterError, match="manifest"):
        neurotex.Model.train(sim_dir, ["a"] * 30)


def test_load_dataset_of_an_event_folder_says_where_its_events_go(exported):
    with pytest.raises(neurotex.DataError, match=r"neurotex.events\(path\)"):
        neurotex.load_dataset(exported)
