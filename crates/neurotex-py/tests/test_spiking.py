"""The spiking network from Python: `SpikingModel.train` trains the network `neurotex train
--classifier snn` trains (the same weights), a `StreamClassifier` runs it as `neurotex
stream` does, and `neurotex.sklearn.SpikingClassifier` follows scikit-learn's
conventions."""

import json
import pickle

import numpy as np
import pytest

import neurotex

from conftest import run_cli
from test_stream import manifest, slide_frames

OPTIONS = {"hidden": 24, "epochs": 4, "encoding": "sa+fa"}


@pytest.fixture(scope="module")
def trained(sim, sim_dir, tmp_path_factory):
    """A causal network trained from Python and the one the CLI trains with the same
    options, saved."""
    d = tmp_path_factory.mktemp("snn")
    model = neurotex.SpikingModel.train(sim, causal=True, **OPTIONS)
    model.save(d / "py.json")
    run_cli("train", "--dataset", sim_dir, "--causal", "--classifier", "snn",
            "--snn-hidden", "24", "--snn-epochs", "4", "--encoding", "sa+fa",
            "--out", d / "cli.json")
    return model, d


def test_python_trains_the_network_the_cli_trains(trained):
    model, d = trained
    py = json.loads((d / "py.json").read_text())
    cli = json.loads((d / "cli.json").read_text())
    assert py["format"] == "neurotex-snn-model"
    assert py["labels"] == cli["labels"] == ["FT1", "SB", "CP"]
    assert py["network"] == cli["network"]
    assert py["pipeline"] == cli["pipeline"]
    assert set(model.training) == {"epochs", "best_epoch", "validation_loss"}
    # Model.load reads every classifier's file: a spiking model file or graph gives a
    # SpikingModel, itself a Model.
    model.save_nir(d / "py.nir")
    for path in (d / "py.json", d / "py.nir"):
        back = neurotex.Model.load(path)
        assert isinstance(back, neurotex.SpikingModel) and isinstance(back, neurotex.Model)
        assert back.classes_ == model.classes_ and back.method == "spikes"
    assert 1 <= model.training["best_epoch"] <= model.training["epochs"] <= 4


def test_model_train_chooses_the_network_as_the_cli_does(sim, sim_dir, tmp_path):
    """`Model.train(classifier="snn")` and `Model.train(method="spikes")` train the network
    `neurotex train --method spikes` trains; a pairing that does not run is refused."""
    knobs = {"hidden": 8, "epochs": 2}
    by_classifier = neurotex.Model.train(sim, classifier="snn", classifier_options=knobs)
    by_method = neurotex.Model.train(sim, method="spikes", classifier_options=knobs)
    assert isinstance(by_classifier, neurotex.SpikingModel)
    by_classifier.save(tmp_path / "c.json")
    by_method.save(tmp_path / "m.json")
    run_cli("train", "--dataset", sim_dir, "--method", "spikes", "--snn-hidden", "8",
            "--snn-epochs", "2", "--out", tmp_path / "cli.json")
    cli = json.loads((tmp_path / "cli.json").read_text())
    for path in ("c.json", "m.json"):
        py = json.loads((tmp_path / path).read_text())
        assert py["network"] == cli["network"] and py["pipeline"] == cli["pipeline"]
    with pytest.raises(neurotex.ParameterError, match="spikes with snn"):
        neurotex.Model.train(sim, method="spikes", classifier="forest")


def test_a_network_the_epoch_cap_stopped_is_a_warning(sim_dir, caplog):
    """Training on a folder that the epoch cap ends, not early stopping, says so at
    WARNING with the epoch of the lowest validation loss, as `neurotex train` does."""
    with caplog.at_level("WARNING", logger="neurotex"):
        model = neurotex.Model.train(sim_dir, classifier="snn",
                                     classifier_options={"hidden": 8, "epochs": 2})
    warned = [r.getMessage() for r in caplog.records if r.levelname == "WARNING"]
    best = model.training["best_epoch"]
    lowest = ("still falling at the last of the 2 epochs" if best == 2
              else f"lowest at epoch {best} of 2")
    assert any(f"validation loss was {lowest}: training stopped at the cap" in w
               for w in warned), warned


def test_a_spiking_stream_gives_the_lines_of_the_cli(trained, sim_dir, tmp_path):
    model, d = trained
    row = manifest(sim_dir)[7]
    frames = slide_frames(sim_dir, row)
    csv = tmp_path / "slide.csv"
    header = ",".join(f"t{i}" for i in range(16))
    csv.write_text(header + "\n" + "\n".join(",".join(repr(float(v)) for v in f) for f in frames) + "\n")
    out = run_cli("stream", "--model", d / "cli.json", "--input", csv).stdout
    expected = [json.loads(l) for l in out.splitlines()]
    for e in expected:
        e.pop("bad_frames", None)
    for source in (model, d / "cli.json"):
        stream = neurotex.StreamClassifier(source)
        got = []
        for f in frames:
            got.extend(stream.push(f) or [])
        got.extend(stream.finish() or [])
        assert got == expected
    assert len(expected) > 20 and expected[-1]["end"] is True


def test_the_sklearn_estimator_fits_predicts_clones_and_pickles(sim):
    from sklearn.base import clone
    from sklearn.model_selection import cross_val_score

    from neurotex.sklearn import SpikingClassifier

    # Classes whose sorted order (classes_) is not the network's (first appearance).
    labels = np.array([{"FT1": 2, "SB": 0, "CP": 1}[l] for l in sim.labels])
    est = SpikingClassifier(hidden=24, epochs=4, encoding="sa+fa")
    assert clone(est).get_params() == est.get_params()
    est.fit(sim.recordings, labels)
    assert list(est.classes_) == [0, 1, 2]
    proba = est.predict_proba(sim.recordings)
    assert proba.shape == (len(labels), 3)
    np.testing.assert_allclose(proba.sum(axis=1), 1.0)
    # Columns in classes_ order 0, 1, 2; the network's outputs are 2, 0, 1.
    assert est.model_.classes_ == ["2", "0", "1"]
    np.testing.assert_array_equal(proba, est.model_.predict_proba(sim.recordings)[:, [1, 2, 0]])
    predicted = est.predict(sim.recordings)
    assert predicted.dtype == labels.dtype
    assert (predicted == labels).mean() > 0.5
    again = pickle.loads(pickle.dumps(est))
    np.testing.assert_array_equal(again.predict_proba(sim.recordings), proba)
    scores = cross_val_score(SpikingClassifier(hidden=16, epochs=3), sim.recordings, labels, cv=2)
    assert scores.shape == (2,) and np.all((0 <= scores) & (scores <= 1))


def python_and_cli(sim, sim_dir, tmp_path, flags, **options):
    """The model files, read, of the network `SpikingModel.train(sim, **options)` trains and
    of the one `neurotex train --classifier snn FLAGS` trains, whose networks are equal."""
    neurotex.SpikingModel.train(sim, **options).save(tmp_path / "py.json")
    run_cli("train", "--dataset", sim_dir, "--classifier", "snn", *flags,
            "--out", tmp_path / "cli.json")
    py, cli = (json.loads((tmp_path / f"{n}.json").read_text()) for n in ("py", "cli"))
    assert py["network"] == cli["network"]
    return py, cli


def test_python_trains_the_xylo_network_the_cli_trains(sim, sim_dir, tmp_path):
    """`target="xylo"` is `--snn-target xylo`: the same network file (subtractive reset
    implied, the chip's time constants); a reset to zero is refused by name."""
    opts = {"hidden": 12, "epochs": 2}
    flags = ["--snn-target", "xylo", "--snn-hidden", "12", "--snn-epochs", "2"]
    py, _ = python_and_cli(sim, sim_dir, tmp_path, flags, target="xylo", **opts)
    assert py["network"]["target"] == "xylo" and py["network"]["reset"] == "subtract"
    with pytest.raises(neurotex.errors.ParameterError, match="snn.reset"):
        neurotex.SpikingModel.train(sim, target="xylo", reset="zero", **opts)


def test_training_on_windows_gives_the_network_of_the_cli(sim, sim_dir, tmp_path):
    """`window_ms` trains the network `--snn-window-ms` trains, and records it in the file."""
    flags = ["--snn-hidden", "8", "--snn-epochs", "2", "--snn-window-ms", "500"]
    py, cli = python_and_cli(sim, sim_dir, tmp_path, flags, hidden=8, epochs=2, window_ms=500)
    assert "window_ms" in json.dumps(cli) and "500" in json.dumps(cli)
    whole = neurotex.SpikingModel.train(sim, hidden=8, epochs=2)
    whole.save(tmp_path / "whole.json")
    assert json.loads((tmp_path / "whole.json").read_text())["network"] != py["network"]
    from neurotex.sklearn import SpikingClassifier

    est = SpikingClassifier(hidden=8, epochs=2, window_ms=500).fit(sim.recordings, sim.labels)
    arrays = neurotex.SpikingModel.train(sim.recordings, sim.labels, hidden=8, epochs=2,
                                         window_ms=500)
    est.model_.save(tmp_path / "est.json")
    arrays.save(tmp_path / "arrays.json")
    est_file = json.loads((tmp_path / "est.json").read_text())
    assert est_file["network"] == json.loads((tmp_path / "arrays.json").read_text())["network"]
    assert "window_ms" in json.dumps(est_file)


def test_training_on_warped_time_gives_the_network_of_the_cli(sim, sim_dir, tmp_path):
    """`warp` trains the network `--snn-warp` trains, records it in the file, and the
    scikit-learn estimator passes it on; a bound that is no warp is refused by name."""
    flags = ["--snn-hidden", "8", "--snn-epochs", "2", "--snn-warp", "2"]
    py, cli = python_and_cli(sim, sim_dir, tmp_path, flags, hidden=8, epochs=2, warp=2.0)
    assert '"warp": 2.0' in json.dumps(cli)
    plain = neurotex.SpikingModel.train(sim, hidden=8, epochs=2)
    plain.save(tmp_path / "plain.json")
    assert json.loads((tmp_path / "plain.json").read_text())["network"] != py["network"]
    from neurotex.sklearn import SpikingClassifier

    est = SpikingClassifier(hidden=8, epochs=2, warp=2.0).fit(sim.recordings, sim.labels)
    est.model_.save(tmp_path / "est.json")
    assert '"warp": 2.0' in json.dumps(json.loads((tmp_path / "est.json").read_text()))
    with pytest.raises(neurotex.errors.ParameterError, match="`warp`"):
        neurotex.SpikingModel.train(sim, hidden=8, epochs=1, warp=1.0)


def test_adaptive_thresholds_give_the_network_of_the_cli(sim, sim_dir, tmp_path):
    """`adapt_ms` trains the network `--snn-adapt-ms` trains, whose file keeps the
    adaptation; such a network has no NIR graph, and a subtracting reset is refused by the
    option's name."""
    flags = ["--snn-hidden", "8", "--snn-epochs", "2", "--snn-adapt-ms", "150"]
    py, cli = python_and_cli(sim, sim_dir, tmp_path, flags, hidden=8, epochs=2, adapt_ms=150.0)
    assert cli["network"]["adaptation"] == {"tau_ms": 150.0, "strength": 1.0}
    assert cli["classifier"]["adapt_ms"] == 150.0
    fixed = neurotex.SpikingModel.train(sim, hidden=8, epochs=2)
    fixed.save(tmp_path / "fixed.json")
    assert "adaptation" not in json.loads((tmp_path / "fixed.json").read_text())["network"]
    from neurotex.sklearn import SpikingClassifier

    est = SpikingClassifier(hidden=8, epochs=2, adapt_ms=150.0, adapt_strength=0.5)
    est.fit(sim.recordings, sim.labels).model_.save(tmp_path / "est.json")
    saved = json.loads((tmp_path / "est.json").read_text())["network"]["adaptation"]
    assert saved == {"tau_ms": 150.0, "strength": 0.5}
    with pytest.raises(neurotex.errors.Error, match="adaptive thresholds"):
        est.model_.save_nir(tmp_path / "est.nir")
    assert not (tmp_path / "est.nir").exists()
    with pytest.raises(neurotex.errors.ParameterError, match="snn-adapt-ms|adapt_ms"):
        neurotex.SpikingModel.train(sim, hidden=8, epochs=1, adapt_ms=150.0, reset="subtract")


def test_synaptic_delays_give_the_network_of_the_cli(sim, sim_dir, tmp_path):
    """`delay_ms` trains the network `--snn-delay-ms` trains, whose file keeps one delay per
    input synapse within the longest; such a network has no NIR graph, and the Xylo
    profile is refused by the option's name."""
    flags = ["--snn-hidden", "8", "--snn-epochs", "2", "--snn-delay-ms", "40"]
    py, cli = python_and_cli(sim, sim_dir, tmp_path, flags, hidden=8, epochs=2, delay_ms=40.0)
    delays = cli["network"]["delays"]
    assert len(delays) == len(cli["network"]["w_in"])
    assert all(0.0 <= d <= 4.0 for d in delays) and len(set(delays)) > 1
    assert cli["classifier"]["delay_ms"] == 40.0
    from neurotex.sklearn import SpikingClassifier

    est = SpikingClassifier(hidden=8, epochs=2, delay_ms=40.0)
    est.fit(sim.recordings, sim.labels).model_.save(tmp_path / "est.json")
    assert len(json.loads((tmp_path / "est.json").read_text())["network"]["delays"]) == len(delays)
    with pytest.raises(neurotex.errors.Error, match="Delay"):
        est.model_.save_nir(tmp_path / "est.nir")
    assert not (tmp_path / "est.nir").exists()
    with pytest.raises(neurotex.errors.ParameterError, match="snn-delay-ms|delay_ms"):
        neurotex.SpikingModel.train(
            sim, hidden=8, epochs=1, delay_ms=40.0, target="xylo", reset="subtract"
        )


def test_trained_decays_give_the_network_of_the_cli(sim, sim_dir, tmp_path):
    """`train_decays` trains the network `--snn-train-decays` trains: one synaptic and one
    membrane decay per hidden neuron in the file, which the NIR graph carries."""
    flags = ["--snn-hidden", "8", "--snn-epochs", "2", "--snn-train-decays"]
    _, cli = python_and_cli(sim, sim_dir, tmp_path, flags, hidden=8, epochs=2, train_decays=True)
    alpha, beta = cli["network"]["alpha"], cli["network"]["beta"]
    assert len(alpha) == len(beta) == 8 and len(set(beta)) > 1
    assert all(0 < b < 1 for b in beta)
    shared = neurotex.SpikingModel.train(sim, hidden=8, epochs=2)
    shared.save(tmp_path / "shared.json")
    assert "alpha" not in json.loads((tmp_path / "shared.json").read_text())["network"]
    from neurotex.sklearn import SpikingClassifier

    est = SpikingClassifier(hidden=8, epochs=2, train_decays=True).fit(sim.recordings, sim.labels)
    est.model_.save(tmp_path / "est.json")
    assert len(json.loads((tmp_path / "est.json").read_text())["network"]["beta"]) == 8


def test_time_in_travel_gives_the_network_of_the_cli(sim, sim_dir, tmp_path):
    """`travel="median"` trains the network `--snn-travel median` trains, whose file keeps
    the training speeds' median (5 and 10 mm/s: 7.5); a speed given as a number is that
    speed, and a word that is neither is refused by the option's name."""
    flags = ["--snn-hidden", "8", "--snn-epochs", "2", "--snn-travel", "median"]
    _, cli = python_and_cli(sim, sim_dir, tmp_path, flags, hidden=8, epochs=2, travel="median")
    assert cli["network"]["travel_mm_s"] == 7.5
    at = neurotex.SpikingModel.train(sim, hidden=8, epochs=1, travel=20)
    at.save(tmp_path / "at.json")
    assert json.loads((tmp_path / "at.json").read_text())["network"]["travel_mm_s"] == 20.0
    with pytest.raises(ValueError, match="travel"):
        neurotex.SpikingModel.train(sim, hidden=8, epochs=1, travel="fast")
    from neurotex.sklearn import SpikingClassifier

    est = SpikingClassifier(hidden=8, epochs=1, travel="median").fit(sim.recordings, sim.labels)
    est.model_.save(tmp_path / "est.json")
    assert "travel_mm_s" in json.loads((tmp_path / "est.json").read_text())["network"]
