"""neurotex.reproduce writes the report `neurotex reproduce` writes for the same options:
the same results.json (but for the clock), the same figures and report text, the same
claims and predictions."""

import csv
import json
import re

import pytest

import neurotex
from neurotex.errors import NotFoundError, ParameterError

from conftest import run_cli


def comparable(results):
    """results.json without what differs between two runs of one analysis: wall-clock
    times (`timing_s`, E9's `seconds` per candidate), the start time and the commit each
    binary was built from."""
    def without_clock(value):
        if isinstance(value, dict):
            return {k: without_clock(v) for k, v in value.items()
                    if k not in ("timing_s", "seconds", "created_utc", "git_commit")}
        if isinstance(value, list):
            return [without_clock(v) for v in value]
        return value

    stripped = without_clock(results)
    assert stripped["provenance"]["parameters"] and "e9" in stripped
    return stripped


def report_text(path):
    """report.md without the command line, the clock and the commit."""
    text = path.read_text()
    text = text.split("## Timing")[0]
    text = re.sub(r"Produced by `.*`; its analyses took [0-9.]+ s", "Produced by", text)
    text = re.sub(r"\(commit \w+\), started \S+;", "", text)
    return text


def same_report(ours, theirs):
    assert comparable(json.loads((ours / "results.json").read_text())) == comparable(
        json.loads((theirs / "results.json").read_text()))
    assert report_text(ours / "report.md") == report_text(theirs / "report.md")
    figures = sorted(p.name for p in (theirs / "figures").iterdir())
    assert len(figures) > 10
    assert sorted(p.name for p in (ours / "figures").iterdir()) == figures
    for name in figures:
        assert (ours / "figures" / name).read_bytes() == (theirs / "figures" / name).read_bytes(), name


def test_quick_run_on_a_folder_equals_the_cli(sim_dir, tmp_path):
    cli = run_cli("reproduce", "--quick", "--dataset", sim_dir, "--seed", "2", "--k", "3",
                  "--encoder-draws", "3", "--snn", "--out", tmp_path / "cli",
                  "--predictions", tmp_path / "p.csv")
    run = neurotex.reproduce(tmp_path / "py", dataset=sim_dir, quick=True, seed=2, k=3,
                             encoder_draws=3, snn=True)
    same_report(tmp_path / "py", tmp_path / "cli")
    spiking = run.results["e9"]["spiking"]["per_speed"]["results"]
    # the paper's method, the inputs' rates with logistic regression, the network
    assert sorted((r["method"], r["classifier"]) for r in spiking) == [
        ("glcm3d", "knn"), ("rates", "linear"), ("spikes", "snn")]
    assert "### The spiking network beside the paper's method" in open(run.report).read()
    assert run.report == str(tmp_path / "py" / "report.md")
    assert run.results == json.loads((tmp_path / "py" / "results.json").read_text())
    assert run.results["recordings"] == 30 and run.gain_calibration is None
    assert run.results["encoder_sensitivity"]["encodings"] == 3
    # the claims the CLI prints, without its progress lines (E9 says its own), its
    # warnings and the report's place
    printed = [l for l in cli.stderr.splitlines()
               if not l.startswith(("report in ", "[", "E9: ", "warning: ", "note: "))]
    assert printed == [f"{cli_verdict(c):<40} {c['statement']}" for c in run.claims]
    assert len(printed) >= 5
    assert all(c["holds"] == (c["verdict"] in ("holds", "point_agrees")) for c in run.claims)
    # the headline is E1 of results.json, by speed
    assert sorted(run.headline) == [5.0, 10.0]
    assert run.headline[5.0]["glcm3d"] == run.results["e1"]["5"]["glcm3d"]
    assert 0.0 <= run.headline[10.0]["taxel_mean"] <= 1.0
    # the out-of-fold predictions of --predictions
    with open(tmp_path / "p.csv") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == len(run.predictions) == 30 * 2  # 30 recordings x 2 CV repeats
    for row, p in zip(rows, run.predictions):
        assert float(row["speed_mm_s"]) == p["speed_mm_s"]
        assert [row[k] for k in ("method", "file", "label", "predicted", "repeat")] == [
            str(p[k]) for k in ("method", "file", "label", "predicted", "repeat")]
        assert row["fold"] == str(p["fold"])


def cli_verdict(claim):
    """How the CLI prints a verdict."""
    return {
        "holds": "Holds (paired test)",
        "not_shown": "Not shown to hold (paired test not significant everywhere)",
        "contradicted": "Contradicted (paired test)",
        "point_agrees": "Agrees in point estimates (no test)",
        "point_disagrees": "Disagrees in point estimates (no test)",
        "not_judged": "Not judged here",
    }[claim["verdict"]]


def test_quick_run_on_the_simulator_with_gain_auto_equals_the_cli(tmp_path):
    """The built-in simulator (5 trials, so that the test stays short), the gain
    calibrated on the simulated recordings."""
    cli = run_cli("reproduce", "--quick", "--trials", "5", "--seed", "1", "--gain", "auto",
                  "--out", tmp_path / "cli")
    run = neurotex.reproduce(tmp_path / "py", quick=True, trials=5, seed=1, gain="auto")
    same_report(tmp_path / "py", tmp_path / "cli")
    said = re.search(r"--gain auto: G = ([0-9.]+) ", cli.stderr)
    assert said, cli.stderr
    assert run.gain_calibration is not None and not run.gain_calibration.clamped
    assert run.gain_calibration.gain == float(said.group(1)) != 8.0
    assert run.results["recordings"] == 8 * 3 * 5
    assert sorted(run.headline) == [5.0, 10.0, 15.0]


def test_bad_options(sim_dir, tmp_path):
    with pytest.raises(ParameterError, match="causal"):
        neurotex.reproduce(tmp_path / "a", dataset=sim_dir, quick=True, causal=True)
    # The library names options as the command line does; Python says its keywords.
    with pytest.raises(ParameterError, match="^trials and seeds apply to the built-in simulator"):
        neurotex.reproduce(tmp_path / "a", dataset=sim_dir, seeds=2)
    with pytest.raises(ParameterError, match="trials must be between 1"):
        neurotex.reproduce(tmp_path / "a", trials=0)
    with pytest.raises(ParameterError, match="seeds must be between 1 and 1000"):
        neurotex.reproduce(tmp_path / "a", seeds=1001)
    with pytest.raises(ParameterError, match="k"):
        neurotex.reproduce(tmp_path / "a", dataset=sim_dir, k=0)
    with pytest.raises(ParameterError, match="folds"):
        neurotex.reproduce(tmp_path / "a", dataset=sim_dir, folds=1)
    with pytest.raises(ParameterError, match="repeats"):
        neurotex.reproduce(tmp_path / "a", dataset=sim_dir, repeats=0)
    with pytest.raises(ParameterError, match="encoder draws must be between 1 and 100"):
        neurotex.reproduce(tmp_path / "a", dataset=sim_dir, encoder_draws=0)
    with pytest.raises(ParameterError, match="levels"):
        neurotex.reproduce(tmp_path / "a", dataset=sim_dir, levels=1)
    with pytest.raises(ParameterError, match="unknown option `speed`"):
        neurotex.reproduce(tmp_path / "a", dataset=sim_dir, speed=5)
    with pytest.raises(NotFoundError):
        neurotex.reproduce(tmp_path / "a", dataset=tmp_path / "nowhere")
    assert not (tmp_path / "a").exists()


def test_a_folder_without_speeds_is_refused_with_the_library_message(sim, tmp_path):
    recs = sim.recordings[:10]
    neurotex.save_dataset(tmp_path / "ds", [r.x for r in recs], [r.label for r in recs])
    with pytest.raises(neurotex.DataError, match="has no speed_mm_s; reproduce compares speeds"):
        neurotex.reproduce(tmp_path / "out", dataset=tmp_path / "ds", quick=True)
    assert not (tmp_path / "out").exists()


def test_a_design_too_small_for_the_folds_warns_and_runs_the_rest(sim_dir, tmp_path):
    # 5 recordings per class at each speed: 6 folds cannot hold a class
    with pytest.warns(UserWarning, match="at most 5 folds"):
        run = neurotex.reproduce(tmp_path / "r", dataset=sim_dir, quick=True, folds=6)
    assert "fewer than the 6 folds" in run.results["skipped"]["e1"]
    assert not run.results.get("e1")
    assert sorted(run.results["e6"]) == ["10", "5"]
