"""`neurotex.evaluate` on a dataset folder runs the CLI's own `evaluate` workflow: the
same JSON object as `neurotex evaluate --json`, for cross-validation and for a train/test
split, for a feature classifier and the spiking network; broken options are named as
Python spells them."""

import json

import pytest

import neurotex
from neurotex.errors import ParameterError

from conftest import run_cli


def cli_json(*args):
    return json.loads(run_cli("evaluate", *args, "--json").stdout)


@pytest.mark.parametrize("py_args, cli_args", [
    ({}, []),
    ({"classifier": "forest", "classifier_options": {"trees": 20}, "folds": 3, "seed": 4},
     ["--classifier", "forest", "--trees", "20", "--folds", "3", "--seed", "4"]),
    ({"method": "all-taxels", "classifier_options": {"k": 3}, "train_speeds": [5],
      "test_speeds": [10]},
     ["--method", "all-taxels", "-k", "3", "--train-speeds", "5", "--test-speeds", "10"]),
    ({"method": "taxel", "taxel": "1,2", "train_where": "trial=0,1,2",
      "test_where": "trial=3,4", "bin_ms": 100},
     ["--method", "taxel", "--taxel", "1,2", "--train-where", "trial=0,1,2",
      "--test-where", "trial=3,4", "--bin-ms", "100"]),
    ({"speeds": [10], "encoder_draws": 3}, ["--speeds", "10", "--encoder-draws", "3"]),
    ({"classifier": "snn", "classifier_options": {"hidden": 8, "epochs": 2}, "folds": 2,
      "speeds": [5]},
     ["--classifier", "snn", "--snn-hidden", "8", "--snn-epochs", "2", "--folds", "2",
      "--speeds", "5"]),
])
def test_evaluate_on_a_folder_is_the_clis_json(sim_dir, py_args, cli_args):
    ours = neurotex.evaluate(sim_dir, **py_args)
    assert ours == cli_json("--dataset", sim_dir, *cli_args)
    assert 0.0 <= ours["accuracy"] <= 1.0
    if "encoder_draws" in py_args:
        assert len(ours["encoder_draws"]["accuracies"]) == 3
        assert ours["encoder_draws"]["accuracies"][0] == ours["accuracy"]
    else:
        assert "encoder_draws" not in ours


def test_gain_auto_is_calibrated_and_said(sim_dir):
    ours = neurotex.evaluate(sim_dir, gain="auto", folds=2)
    assert ours == cli_json("--dataset", sim_dir, "--gain", "auto", "--folds", "2")
    assert "gain_calibration" in ours


def test_broken_options_are_named_as_python_spells_them(sim_dir):
    with pytest.raises(ParameterError, match="`hidden`"):
        neurotex.evaluate(sim_dir, classifier="snn", classifier_options={"hidden": 0})
    with pytest.raises(ParameterError, match="test_speeds"):
        neurotex.evaluate(sim_dir, train_speeds=[5])
    with pytest.raises(ParameterError, match="bin_ms"):
        neurotex.evaluate(sim_dir, bin_ms=0)
    with pytest.raises(ParameterError, match="unknown option `trees` for classifier knn"):
        neurotex.evaluate(sim_dir, classifier_options={"trees": 3})
    # A switch is not a count, nor text a switch.
    with pytest.raises(ParameterError, match="`trees`: expected a whole number of at least 0, got True"):
        neurotex.evaluate(sim_dir, classifier="forest", classifier_options={"trees": True})
    with pytest.raises(ParameterError, match="`bootstrap`: expected True or False, got 'maybe'"):
        neurotex.evaluate(sim_dir, classifier="forest", classifier_options={"bootstrap": "maybe"})


def untimed(value):
    """`value` without its `seconds` fields (the time each candidate took) and its
    `provenance` (when it ran; the command line's adds its command)."""
    if isinstance(value, dict):
        return {k: untimed(v) for k, v in value.items() if k not in ("seconds", "provenance")}
    if isinstance(value, list):
        return [untimed(v) for v in value]
    return value


def test_compare_on_a_folder_is_the_clis_json(sim_dir, tmp_path):
    """`neurotex.compare` runs `neurotex compare`'s workflow: the same JSON object, and
    with `out` the same compare.json, but for the seconds each candidate took."""
    ours = neurotex.compare(sim_dir, encodings=["sa"], methods=["glcm3d", "all-taxels"],
                            classifiers=["knn", "linear"], per="speed_mm_s", folds=3,
                            knn_options={"k": 3}, nested=True, inner_folds=2,
                            out=tmp_path / "py")
    cli = json.loads(run_cli("compare", "--dataset", sim_dir, "--encodings", "sa",
                             "--methods", "glcm3d,all-taxels", "--classifiers", "knn,linear",
                             "--per", "speed_mm_s", "--folds", "3", "-k", "3", "--nested",
                             "--inner-folds", "2", "--json", "--out", tmp_path / "cli").stdout)
    assert untimed(ours) == untimed(cli)
    # The same provenance but for the time and the command the command line adds.
    same = [[line for line in c["provenance"] if not line.startswith(("created:", "command:"))]
            for c in (ours, cli)]
    assert same[0] == same[1] and any(line.startswith("data: sha256:") for line in same[0])
    assert any(line.startswith("command: neurotex compare") for line in cli["provenance"])
    assert ours["nested"]["inner"] == "2-fold cross-validation inside each outer training set"
    written = [json.loads((tmp_path / side / "compare.json").read_text()) for side in ("py", "cli")]
    assert untimed(written[0]) == untimed(written[1])
    assert (tmp_path / "py" / "compare.md").is_file()
    # Into the same folder again, and into the command line's, as `--out` writes: an
    # earlier output is replaced whole; a folder of the user's is refused before any work.
    for again in ("py", "cli"):
        neurotex.compare(sim_dir, encodings=["sa"], methods=["glcm3d"], classifiers=["knn"],
                         per="speed_mm_s", folds=3, knn_options={"k": 3}, out=tmp_path / again)
        assert json.loads((tmp_path / again / "compare.json").read_text())["best"]["method"] == "glcm3d"
    theirs = tmp_path / "theirs"
    theirs.mkdir()
    (theirs / "notes.txt").write_text("mine")
    with pytest.raises(neurotex.Error, match="notes.txt"):
        neurotex.compare(sim_dir, encodings=["sa"], methods=["glcm3d"], classifiers=["knn"],
                         per="speed_mm_s", folds=3, knn_options={"k": 3}, out=theirs)
    assert (theirs / "notes.txt").read_text() == "mine"
    with pytest.raises(ParameterError, match="only with nested=True"):
        neurotex.compare(sim_dir, per="speed_mm_s", inner_folds=3)
    with pytest.raises(ParameterError, match="2 folds or more"):
        neurotex.compare(sim_dir, per="speed_mm_s", nested=True, inner_folds=1)
    with pytest.raises(ParameterError, match="one protocol at a time"):
        neurotex.compare(sim_dir, per="speed_mm_s", hold_out="speed_mm_s")
    with pytest.raises(ParameterError, match="must be a list"):
        neurotex.compare(sim_dir, methods="glcm3d")
    with pytest.raises(ParameterError, match="for the spiking network"):
        neurotex.compare(sim_dir, snn_options={"trees": 3})


def test_compare_over_encodings_is_the_clis_json(sim_dir):
    """`encoder_draws` is `--encoder-draws`: each spike candidate's accuracy over the
    encodings, the encoding as run first."""
    ours = neurotex.compare(sim_dir, encodings=["sa"], methods=["glcm3d"],
                            classifiers=["knn"], per="speed_mm_s", folds=3, encoder_draws=2)
    cli = json.loads(run_cli("compare", "--dataset", sim_dir, "--encodings", "sa",
                             "--methods", "glcm3d", "--classifiers", "knn", "--per",
                             "speed_mm_s", "--folds", "3", "--encoder-draws", "2",
                             "--json").stdout)
    assert untimed(ours) == untimed(cli)
    over = ours["best"]["over_encodings"]
    assert len(over["accuracies"]) == 2 and over["accuracies"][0] == ours["best"]["accuracy"]


def test_an_estimate_at_chance_is_a_warning(sim_dir, tmp_path, caplog):
    """The workflow's warnings reach Python's log at WARNING, which Python shows without
    any logging set up: here labels that the textures do not carry (each recording's
    trial, odd or even), whose nested estimate and accuracy cannot be above chance."""
    import csv
    import shutil
    data = tmp_path / "parity"
    shutil.copytree(sim_dir, data)
    rows = list(csv.DictReader(open(data / "manifest.csv")))
    for r in rows:
        r["label"] = "odd" if int(r["trial"]) % 2 else "even"
    with open(data / "manifest.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    with caplog.at_level("WARNING", logger="neurotex"):
        neurotex.compare(data, encodings=["sa"], methods=["glcm3d", "all-taxels"],
                         classifiers=["knn"], per="speed_mm_s", folds=3,
                         knn_options={"k": 3}, nested=True)
    warned = [r for r in caplog.records if r.levelname == "WARNING"]
    assert any("nested estimate's interval" in r.getMessage() and "chance (60.0 %, always"
               in r.getMessage() for r in warned), [r.getMessage() for r in caplog.records]
    # evaluate says it of its accuracy, and keeps it in the result's notes.
    caplog.clear()
    with caplog.at_level("WARNING", logger="neurotex"):
        result = neurotex.evaluate(data, folds=3, classifier_options={"k": 3})
    # Trials 0-4: three even, two odd, so answering "even" always scores 60 %.
    said = "chance (60.0 %, always answering the most frequent class)"
    warned = [r.getMessage() for r in caplog.records if r.levelname == "WARNING"]
    assert any("accuracy's interval" in m and said in m for m in warned), warned
    assert any(said in n for n in result["notes"]), result


def test_a_workflow_speaks_while_it_runs(sim_dir, monkeypatch):
    """What a workflow says reaches the `neurotex` logger as it is said, each line once:
    every line is heard before the native call returns, not logged after it."""
    import logging
    from neurotex import _native
    native = _native.compare_dataset
    returned = []

    def compare_dataset(*args):
        result = native(*args)
        returned.append(True)
        return result

    monkeypatch.setattr(_native, "compare_dataset", compare_dataset)
    heard = []

    class Heard(logging.Handler):
        def emit(self, record):
            heard.append((record.getMessage(), bool(returned)))

    logger = logging.getLogger("neurotex")
    handler = Heard(level=logging.INFO)
    logger.addHandler(handler)
    old = logger.level
    logger.setLevel(logging.INFO)
    try:
        neurotex.compare(sim_dir, encodings=["sa"], methods=["glcm3d", "all-taxels"],
                         classifiers=["knn"], per="speed_mm_s", folds=3,
                         knn_options={"k": 3}, nested=True)
    finally:
        logger.removeHandler(handler)
        logger.setLevel(old)
    messages = [m for m, _ in heard]
    assert any(m.startswith("comparing ") for m in messages), messages
    # each stage's start and its tenths, as the command line's bar moves
    n = next(m for m in messages if m.startswith("candidates (")).split("(")[1].split()[0]
    assert f"candidates {n}/{n}" in messages, messages
    assert not any(after for _, after in heard), heard
    assert len(messages) == len(set(messages)), messages
