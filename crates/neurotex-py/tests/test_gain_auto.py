"""gain="auto" chooses the gain the CLI's `--gain auto` chooses on the same recordings, in
features, calibrate_gain, SpikeFeatures, Model.train and encode."""

import json
import re

import numpy as np
import pytest

import neurotex
from neurotex.errors import ParameterError

from conftest import run_cli
from test_cli_equality import read_feature_csv


def cli_gain(stderr):
    """The gain the CLI says `--gain auto` chose."""
    said = re.search(r"--gain auto: G = ([0-9.e+-]+) gives a median of ([0-9.]+) Hz "
                     r"\(target ([0-9.]+) Hz\) over (\d+) taxel x recording pairs with "
                     r"signal in the (\d+) recordings? it calibrated on", stderr)
    assert said, stderr
    g, median, target, pairs, recordings = said.groups()
    return float(g), float(median), float(target), int(pairs), int(recordings)


@pytest.mark.parametrize("gain,target", [("auto", 20.0), ("auto:35", 35.0)])
def test_features_choose_the_cli_gain(sim_dir, sim, tmp_path, gain, target):
    out = run_cli("features", "--dataset", sim_dir, "--method", "glcm3d", "--gain", gain,
                  "--out", tmp_path / "f.csv")
    g, median, cli_target, pairs, recordings = cli_gain(out.stderr)
    _, expected, _ = read_feature_csv(tmp_path / "f.csv", len(sim.columns))
    table = neurotex.features(sim, "glcm3d", gain=gain)
    c = table.gain_calibration
    assert (c.gain, round(c.median_hz, 1), c.target_hz, c.pairs, c.recordings) == (
        g, median, cli_target, pairs, recordings)
    assert c.target_hz == target and not c.clamped and c.gain != 8.0
    X, names = table  # still unpacks as (X, names)
    np.testing.assert_array_equal(X, expected)
    assert table.causal is None
    # from the folder, read by the library
    folder = neurotex.features(str(sim_dir), "glcm3d", gain=gain)
    assert folder.gain_calibration == c
    np.testing.assert_array_equal(folder.X, expected)
    # and calibrate_gain says the same
    assert neurotex.calibrate_gain(sim, target) == c
    assert neurotex.calibrate_gain(str(sim_dir), target_hz=target) == c


def test_model_trained_with_gain_auto_equals_the_cli_model(sim_dir, sim, tmp_path):
    """Calibrated on the training recordings only (5 mm/s); SpikeFeatures calibrates in
    fit on the same recordings and keeps the gain for transform."""
    train = [r for r in sim.recordings if r.speed == 5.0]
    test = [r for r in sim.recordings if r.speed == 10.0]
    run_cli("train", "--dataset", sim_dir, "--speeds", "5", "--gain", "auto", "--out",
            tmp_path / "cli.json")
    model = neurotex.Model.train(train, method="glcm3d", gain="auto")
    model.save(tmp_path / "py.json")
    ours, theirs = (json.loads((tmp_path / f).read_text()) for f in ("py.json", "cli.json"))
    for m in (ours, theirs):
        m["training"]["dataset"].pop("fingerprint")
        # the layout files are read with: the CLI's dataset's; arrays have none
        m["training"]["dataset"].pop("layout", None)
    assert theirs["training"]["dataset"].pop("speeds") == [5.0]
    assert ours["training"]["dataset"].pop("speeds", None) is None
    assert ours == theirs
    c = model.gain_calibration
    assert c is not None and model.gain == c.gain != 8.0
    assert c.recordings == len(train)
    assert theirs["training"]["dataset"]["gain_calibration"]["gain"] == c.gain

    from neurotex.sklearn import SpikeFeatures

    features = SpikeFeatures(gain="auto").fit(train)
    assert features.gain_ == model.gain and features.gain_calibration_ == c
    np.testing.assert_array_equal(features.transform(test),
                                  neurotex.features(test, "glcm3d", gain=model.gain).X)
    assert SpikeFeatures(gain=9.5).fit(train).gain_ == 9.5


def test_encode_calibrates_on_its_recording(sim_dir, tmp_path):
    rec = sim_dir / "CP_v10_t03.npy"
    out = run_cli("encode", rec, "--gain", "auto:30", "--out", tmp_path / "s.npy")
    g = cli_gain(out.stderr)[0]
    x = np.load(rec)
    spikes = neurotex.encode(x, gain="auto:30")
    np.testing.assert_array_equal(spikes, np.load(tmp_path / "s.npy"))
    np.testing.assert_array_equal(spikes, neurotex.encode(x, gain=g))
    assert neurotex.calibrate_gain([x], 30).gain == g


def test_the_choice_is_logged(sim, caplog):
    with caplog.at_level("INFO", logger="neurotex"):
        table = neurotex.features(sim.recordings[:6], "taxel", gain="auto")
    assert f"G = {table.gain_calibration.gain} gives a median" in caplog.text


def test_bad_gains_and_flat_recordings():
    x = np.random.default_rng(0).random((1000, 4, 4))
    for bad, match in [("fast", "expected a number, `auto` or `auto:HZ`, got `fast`"),
                       ("auto:0", "target rate in \\(0, 1000\\]"),
                       ("auto:x", "`x` is not a number"),
                       ([8], "expected a number, `auto` or `auto:HZ`, got `\\[8\\]`")]:
        with pytest.raises(ParameterError, match=match):
            neurotex.features([x], gain=bad)
    with pytest.raises(ParameterError, match="target rate in \\(0, 1000\\] Hz, got 2000"):
        neurotex.calibrate_gain([x], 2000.0)
    with pytest.raises(ParameterError, match="target_hz"):
        neurotex.calibrate_gain([x], "fast")
    with pytest.raises(ParameterError, match="calibrate_gain chooses the gain"):
        neurotex.calibrate_gain([x], gain=3.0)
    with pytest.raises(ParameterError, match="every taxel is flat"):
        neurotex.features([np.zeros((1000, 4, 4))], gain="auto")
    with pytest.raises(ParameterError, match="every taxel is flat"):
        neurotex.calibrate_gain([np.zeros((1000, 4, 4))])
