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
    with pytest.raises(neurotex.Error, match=r"trained for streams \(causal\)"):
        neurotex.StreamClassifier(offline)
    with pytest.raises(ParameterError):
        neurotex.StreamClassifier(offline, episode="sometimes")


def test_a_stamp_far_ahead_costs_its_own_frame(sim_dir, causal_model):
    """The library's stamp rule, as the CLI applies it: one stamp far ahead (a bit flip) is
    a bad frame and the frames after it go on; a clock that jumps and stays starts a new
    episode one frame later."""
    row = [r for r in manifest(sim_dir) if r["speed_mm_s"] == "10"][1]
    frames = slide_frames(sim_dir, row)[:3000]
    stamps = 100.0 + np.arange(len(frames)) / 1000.0

    def run(stamped):
        stream = neurotex.StreamClassifier(causal_model)
        got, bad = [], []
        for t, f in stamped:
            try:
                got.extend(stream.push(f, t=t) or [])
            except DataError as e:
                bad.append(str(e))
        got.extend(stream.finish() or [])
        return got, bad

    clean = list(zip(stamps, frames))
    expected, _ = run(clean)
    flipped = clean[:1000] + [(stamps[999] * 2.0**20, frames[999])] + clean[1000:]
    got, bad = run(flipped)
    assert got == expected
    assert len(bad) == 1 and "more than the largest gap" in bad[0]

    back = clean + [(t - 50.0, f) for t, f in clean]
    got, bad = run(back)
    ends = [e for e in got if e.get("end")]
    assert [e["ended_by"] for e in ends] == ["gap", "end_of_input"]
    assert len(bad) == 1 and "not after the previous" in bad[0]
    with pytest.raises(ParameterError, match="largest gap"):
        neurotex.StreamClassifier(causal_model, max_gap_s=3600.0)


def test_ms_stamps_on_the_grid_give_the_unstamped_lines(sim_dir, causal_model):
    """Stamps in the unit they were logged in are exact: frames stamped 1.7e12 + k ms (ms
    since an epoch) give the lines of the same frames unstamped at 1 kHz, bit for bit."""
    row = [r for r in manifest(sim_dir) if r["speed_mm_s"] == "10"][0]
    frames = slide_frames(sim_dir, row)

    def run(stamps, **options):
        stream = neurotex.StreamClassifier(causal_model, **options)
        got = []
        for t, f in zip(stamps, frames):
            got.extend(stream.push(f, t=t) or [])
        return got + (stream.finish() or [])

    unstamped = run([None] * len(frames))
    stamped = run([1.7e12 + k for k in range(len(frames))], time_unit="ms")
    assert stamped == unstamped and len(unstamped) > 20
    with pytest.raises(ParameterError, match="time_unit"):
        neurotex.StreamClassifier(causal_model, time_unit="minutes")


def test_event_errors_name_the_argument_at_fault(causal_model):
    stream = neurotex.StreamClassifier(causal_model, time_unit="ms", events=True)
    with pytest.raises(DataError, match=r"push_event\(t=nan\): .*time stamp NaN is not a finite number"):
        stream.push_event(float("nan"), 1, 1, 1)
    assert stream.bad_frames == 1
    with pytest.raises(ParameterError, match="t, the time stamp, must be a number; got str"):
        stream.push_event("soon", 1, 1, 1)
    # A plain float array where events are needed names the dtype it needs.
    with pytest.raises(ParameterError, match=r"fields t, x, y and optionally p .*got dtype float64"):
        stream.push_events(np.zeros((5, 4)))
    wrong = np.zeros(3, dtype=[("ts", "<i8"), ("x", "<u2"), ("y", "<u2")])
    with pytest.raises(ParameterError, match="without field"):
        stream.push_events(wrong)
