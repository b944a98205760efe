"""Causal models trained in Python (Model.train(..., causal=True)) equal the CLI's
`train --causal` models: the same file, the same predictions, the same stream lines, both
ways."""

import csv
import json

import numpy as np
import pytest

import neurotex
from neurotex.errors import ParameterError

from conftest import run_cli
from test_cli_equality import read_feature_csv
from test_stream import manifest, slide_frames


def model_json(path):
    """A model file without what differs by design between the front ends: the training
    data's fingerprint, and the layout files are read with (a model trained on arrays in
    Python reads no files; the CLI's remembers its dataset's layout.toml)."""
    m = json.loads(path.read_text())
    m["training"]["dataset"].pop("fingerprint")
    m["training"]["dataset"].pop("layout", None)
    return m


@pytest.mark.parametrize("cli_options,options", [
    ([], {}),
    (["--gain", "auto", "--classifier", "forest", "--trees", "15"],
     {"gain": "auto", "classifier": "forest", "classifier_options": {"trees": 15}}),
])
def test_causal_model_equals_the_cli_model(sim_dir, sim, tmp_path, cli_options, options):
    run_cli("train", "--dataset", sim_dir, "--causal", "--out", tmp_path / "cli.json",
            *cli_options)
    model = neurotex.Model.train(sim, causal=True, **options)
    model.save(tmp_path / "py.json")
    assert model_json(tmp_path / "py.json") == model_json(tmp_path / "cli.json")
    c = model.causal
    assert c is not None and c.scale > 0 and c.offsets.shape == (16,)
    assert c.median_duration_ms > 1000
    if "gain" in options:
        assert model.gain_calibration is not None and model.gain == model.gain_calibration.gain
    # the same predictions and shares as `neurotex predict` with the CLI's model
    run_cli("predict", "--model", tmp_path / "cli.json", "--dataset", sim_dir, "--out",
            tmp_path / "p.csv")
    with open(tmp_path / "p.csv") as f:
        rows = list(csv.DictReader(f))
    assert list(model.predict(sim)) == [r["predicted"] for r in rows]
    expected = np.array([[float(r[f"share_{c}"]) for c in model.classes_] for r in rows])
    np.testing.assert_array_equal(model.predict_proba(sim), expected)


def test_python_causal_model_streams_as_the_cli(sim_dir, sim, tmp_path):
    train = [r for r in sim.recordings if r.speed == 10.0]
    run_cli("train", "--dataset", sim_dir, "--speeds", "10", "--causal", "--out",
            tmp_path / "cli.json")
    model = neurotex.Model.train(train, causal=True)
    model.save(tmp_path / "py.json")
    row = [r for r in manifest(sim_dir) if r["speed_mm_s"] == "10"][4]
    frames = slide_frames(sim_dir, row)
    slide = tmp_path / "slide.csv"
    slide.write_text(",".join(f"t{i}" for i in range(16)) + "\n"
                   + "\n".join(",".join(repr(float(v)) for v in f) for f in frames) + "\n")

    def cli_lines(model_path):
        out = run_cli("stream", "--model", model_path, "--input", slide).stdout.splitlines()
        lines = [json.loads(l) for l in out]
        for line in lines:
            line.pop("bad_frames", None)
        return lines

    expected = cli_lines(tmp_path / "cli.json")
    stream = neurotex.StreamClassifier(model)
    got = []
    for f in frames:
        got.extend(stream.push(f) or [])
    got.extend(stream.finish() or [])
    assert got == expected
    assert len(got) > 20 and got[-1]["end"] is True
    # and the CLI streams the Python model's file the same way
    assert cli_lines(tmp_path / "py.json") == expected


def test_causal_features_equal_the_cli(sim_dir, sim, tmp_path):
    out = run_cli("features", "--dataset", sim_dir, "--method", "taxel", "--causal", "--out",
                  tmp_path / "f.csv")
    _, expected, _ = read_feature_csv(tmp_path / "f.csv", len(sim.columns))
    table = neurotex.features(sim, "taxel", causal=True)
    np.testing.assert_array_equal(table.X, expected)
    assert f"scale {table.causal.scale:.6f} fixed on 30 training" in out.stderr
    assert table.causal.recordings == 30 and table.gain_calibration is None
    # not the offline pipeline's features
    assert not np.array_equal(neurotex.features(sim, "taxel").X, expected)
    np.testing.assert_array_equal(neurotex.features(str(sim_dir), "taxel", causal=True).X,
                                  expected)


def test_offline_python_models_are_refused_by_the_stream(sim):
    # every third recording: several classes (a model is trained on at least two)
    model = neurotex.Model.train(sim.recordings[::3])
    assert model.causal is None
    with pytest.raises(neurotex.Error, match=r"trained for streams \(causal\)"):
        neurotex.StreamClassifier(model)


def test_causal_needs_signal_and_is_refused_where_it_cannot_apply():
    flat = [np.zeros((1000, 4, 4))] * 6
    with pytest.raises(ParameterError, match="every recording is flat"):
        neurotex.Model.train(flat, ["a", "b"] * 3, causal=True, classifier_options={"k": 1})
    with pytest.raises(ParameterError, match="causal"):
        neurotex._native.encode(np.ones((1000, 4, 4)),
                                ("x", 1000.0, None, "", None, None, None, None),
                                {"causal": True})
