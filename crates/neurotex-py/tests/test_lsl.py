"""Live input over the Lab Streaming Layer, end to end on this machine with pylsl's bundled
liblsl: `neurotex stream --input lsl:NAME` gives the lines the same stamped frames give from
a file, publishes them on an LSL outlet (`--publish`), reads events from a marker stream,
and names the stream when it is missing, has the wrong channels, or comes back with others.
The Python example `examples/lsl_classify.py` gives the same decisions."""

import json
import os
import pathlib
import subprocess
import sys
import threading
import time
import uuid

import numpy as np
import pytest

from conftest import cli_path, run_cli

pylsl = pytest.importorskip("pylsl")

EXAMPLES = pathlib.Path(__file__).resolve().parents[1] / "examples"
# Stamps on a clock that does not start at 0 (LSL reads a stamp of 0 as "now"), each exact
# in a file's text as in LSL's doubles.
T0 = 1024.0


def lsl_env():
    env = dict(os.environ)
    env["PYLSL_LIB"] = pylsl.lib.lib._name
    return env


@pytest.fixture(scope="module")
def causal(sim_dir, tmp_path_factory):
    """A causal 3D-GLCM model on the simulated dataset, and one recording's frames."""
    d = tmp_path_factory.mktemp("lsl")
    model = d / "model.json"
    run_cli("train", "--dataset", sim_dir, "--causal", "--out", model)
    name = sorted(p.name for p in sim_dir.glob("*.npy"))[3]
    frames = np.load(sim_dir / name).reshape(-1, 16).astype(np.float64)[:6000]
    stamps = T0 + np.arange(len(frames)) / 1000.0
    csv = d / "frames.csv"
    with open(csv, "w") as f:
        f.write("t_s," + ",".join(f"taxel{i}" for i in range(16)) + "\n")
        for t, row in zip(stamps, frames):
            f.write(repr(float(t)) + "," + ",".join(repr(float(v)) for v in row) + "\n")
    expected = run_cli("stream", "--model", model, "--input", csv, "--time-column", "t_s",
                       "--time-unit", "s").stdout.splitlines()
    assert len(expected) > 25
    return model, frames, stamps, expected


def start(args):
    return subprocess.Popen([str(cli_path()), "stream", *map(str, args)], env=lsl_env(),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def send(name, samples, stamps, channels, fmt="float32", then=None):
    """An outlet named `name` that waits for a consumer, pushes every sample with its stamp,
    gives the consumer time to take them, and closes (then calls `then`)."""
    info = pylsl.StreamInfo(name, "Tactile", channels, pylsl.IRREGULAR_RATE, fmt, "src-" + name)
    outlet = pylsl.StreamOutlet(info)
    deadline = time.time() + 20
    while not outlet.have_consumers() and time.time() < deadline:
        time.sleep(0.01)
    time.sleep(0.3)
    for sample, t in zip(samples, stamps):
        outlet.push_sample(sample, float(t))
    time.sleep(2.0)
    del outlet
    if then is not None:
        then()


def read_markers(name, into, seconds=30.0):
    found = pylsl.resolve_byprop("name", name, timeout=10)
    inlet = pylsl.StreamInlet(found[0])
    deadline = time.time() + seconds
    while time.time() < deadline:
        x, _ = inlet.pull_sample(timeout=10.0)
        if x is None:
            break
        into.append(x[0])


def unique(prefix):
    return f"{prefix}-{uuid.uuid4().hex[:8]}"


def test_an_lsl_stream_gives_the_files_lines_and_publishes_them(causal):
    model, frames, stamps, expected = causal
    name, out = unique("neurotex-frames"), unique("neurotex-decisions")
    proc = start(["--model", model, "--input", f"lsl:{name}", "--publish", f"lsl:{out}"])
    published = []
    reader = threading.Thread(target=read_markers, args=(out, published))
    reader.start()
    send(name, frames.tolist(), stamps, 16)
    stdout, stderr = proc.communicate(timeout=60)
    reader.join(timeout=60)
    assert proc.returncode == 0, stderr
    assert stdout.splitlines() == expected
    assert published == expected
    assert f"lsl:{name}: the stream is gone" in stderr
    assert "6000 frames, 0 bad frame(s) skipped, 1 episode(s)" in stderr


def test_events_from_a_marker_stream_stream_as_the_same_events_from_a_file(causal, tmp_path):
    model, _, _, _ = causal
    rng = np.random.default_rng(1)
    t_ms = np.sort(rng.integers(0, 4000, 3000))
    cells = rng.integers(0, 4, (3000, 2))
    polarity = rng.integers(0, 2, 3000)
    stamps = T0 + t_ms / 1000.0
    text = [f"{x},{y},{p}" for (x, y), p in zip(cells, polarity)] + [""]
    stamps = np.append(stamps, T0 + 4.0)  # a tick at 4 s
    file = tmp_path / "events.csv"
    file.write_text("t,x,y,p\n" + "".join(
        f"{float(t)!r},{m}\n" if m else f"{float(t)!r}\n" for t, m in zip(stamps, text)))
    expected = run_cli("stream", "--model", model, "--format", "events", "--time-unit", "s",
                       "--input", file).stdout.splitlines()
    assert len(expected) >= 20
    name = unique("neurotex-events")
    proc = start(["--model", model, "--format", "events", "--input", f"lsl:{name}"])
    info = pylsl.StreamInfo(name, "Markers", 1, pylsl.IRREGULAR_RATE, "string", "ev-" + name)
    outlet = pylsl.StreamOutlet(info)
    while not outlet.have_consumers():
        time.sleep(0.01)
    time.sleep(0.3)
    for m, t in zip(text, stamps):
        outlet.push_sample([m], float(t))
    time.sleep(2.0)
    del outlet
    stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 0, stderr
    assert stdout.splitlines() == expected, stderr


def test_missing_streams_and_wrong_channels_are_named(causal):
    model, frames, stamps, _ = causal
    name = unique("neurotex-none")
    out = subprocess.run([str(cli_path()), "stream", "--model", str(model), "--input",
                          f"lsl:{name}", "--lsl-timeout-s", "0.5"], env=lsl_env(),
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 1, out.stderr
    assert f"lsl:{name}" in out.stderr and "no LSL stream" in out.stderr
    # 12 channels for a 16-taxel model: refused at once, naming the stream.
    name = unique("neurotex-twelve")
    proc = start(["--model", model, "--input", f"lsl:{name}"])
    sender = threading.Thread(target=send, args=(name, frames[:10, :12].tolist(), stamps, 12))
    sender.start()
    _, stderr = proc.communicate(timeout=60)
    sender.join(timeout=60)
    assert proc.returncode == 1
    assert f"lsl:{name}" in stderr and "12 numeric channel(s)" in stderr, stderr


def test_a_stream_that_comes_back_with_other_channels_ends_with_its_summary(causal):
    model, frames, stamps, _ = causal
    name = unique("neurotex-back")
    proc = start(["--model", model, "--input", f"lsl:{name}"])

    def twelve():
        info = pylsl.StreamInfo(name, "Tactile", 12, pylsl.IRREGULAR_RATE, "float32", "x")
        outlet = pylsl.StreamOutlet(info)
        time.sleep(6)
        del outlet

    send(name, frames[:2000].tolist(), stamps, 16, then=twelve)
    stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 1, stderr
    assert "came back with 12 numeric channel(s); it had 16" in stderr, stderr
    assert json.loads(stdout.splitlines()[-1])["end"] is True
    assert "2000 frames" in stderr


def test_the_python_example_decides_as_the_command_line(causal):
    sys.path.insert(0, str(EXAMPLES))
    from lsl_classify import classify

    model, frames, stamps, expected = causal
    name = unique("neurotex-py")
    sender = threading.Thread(target=send, args=(name, frames.tolist(), stamps, 16))
    sender.start()
    lines = classify(str(model), name, timeout=20)
    sender.join(timeout=60)
    cli_lines = [json.loads(l) for l in expected]
    for line in cli_lines:
        line.pop("bad_frames", None)
    assert lines == cli_lines
