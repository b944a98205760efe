"""StreamClassifier: the same lines as `neurotex stream` for the same frames; bad frames
raise DataError and are skipped; offline models are refused."""

import json

import numpy as np
import pytest

import neurotex
from neurotex.errors import DataError, ParameterError

from conftest import run_cli


def slide_frames(sim_dir, row):
    """The sliding phase of a recording, (frames, 16), selected as the pipeline does."""
    x = np.load(sim_dir / row["file"])
    t = np.arange(x.shape[0]) / 1000.0
    keep = (t >= float(row["slide_start_s"]) - 1e-9) & (t < float(row["slide_end_s"]) - 1e-9)
    return x[keep].reshape(int(keep.sum()), -1)


def manifest(sim_dir):
    lines = (sim_dir / "manifest.csv").read_text().splitlines()
    names = lines[0].split(",")
    return [dict(zip(names, l.split(","))) for l in lines[1:]]


@pytest.fixture(scope="module")
def causal_model(sim_dir, tmp_path_factory):
    path = tmp_path_factory.mktemp("model") / "causal.json"
    run_cli("train", "--dataset", sim_dir, "--speeds", "10", "--causal", "--out", path)
    return path


def test_stream_lines_equal_the_cli(sim_dir, causal_model, tmp_path):
    row = [r for r in manifest(sim_dir) if r["speed_mm_s"] == "10"][2]
    frames = slide_frames(sim_dir, row)
    csv = tmp_path / "slide.csv"
    header = ",".join(f"t{i}" for i in range(16))
    csv.write_text(header + "\n" + "\n".join(",".join(repr(float(v)) for v in f) for f in frames) + "\n")
    expected = [json.loads(l) for l in run_cli("stream", "--model", causal_model, "--input", csv).stdout.splitlines()]
    for e in expected:
        e.pop("bad_frames", None)
    stream = neurotex.StreamClassifier(causal_model)
    got = []
    for f in frames:
        got.extend(stream.push(f) or [])
    got.extend(stream.finish() or [])
    assert got == expected
    assert got[-1]["end"] is True and len(got) > 20


def test_bad_frames_raise_and_are_skipped(causal_model):
    stream = neurotex.StreamClassifier(causal_model, fs=1000.0)
    assert stream.push(np.zeros(16)) is None
    with pytest.raises(DataError, match="expected 16 values"):
        stream.push(np.zeros(15))
    bad = np.zeros(16)
    bad[3] = np.nan
    with pytest.raises(DataError, match="not a finite number"):
        stream.push(bad)
    assert stream.bad_frames == 2
    assert stream.finish()[-1]["end"] is True


def test_offline_models_and_bad_options_are_refused(sim_dir, tmp_path):
    offline = tmp_path / "offline.json"
    run_cli("train", "--dataset", sim_dir, "--speeds", "10", "--out", offline)
    with pytest.raises(neurotex.Error, match="--causal"):
        neurotex.StreamClassifier(offline)
    with pytest.raises(ParameterError):
        neurotex.StreamClassifier(offline, episode="sometimes")
