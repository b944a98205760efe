"""Ctrl-C during a long call stops the run at its next step, as it stops Python code."""

import os
import signal
import subprocess
import sys
import time

from conftest import run_cli

CHILD = r"""
import logging, signal, sys, time
import neurotex
# A shell's background job starts with SIGINT ignored; a terminal's Python has the default.
signal.signal(signal.SIGINT, signal.default_int_handler)
logging.basicConfig(level=logging.INFO, format="%(message)s", stream=sys.stderr)
data = sys.argv[1]
try:
    neurotex.compare(data, classifiers=["forest"], per="speed_mm_s", nested=True, repeats=50)
    print("finished", flush=True)
except KeyboardInterrupt as e:
    print("interrupted:", e, flush=True)
# The module still works after a stopped run.
r = neurotex.evaluate(data, speeds=[5], folds=3)
print("after", r["n"], flush=True)
"""


def test_ctrl_c_stops_a_long_run_at_its_next_step(tmp_path):
    data = tmp_path / "sim"
    run_cli("simulate", "--out", data, "--trials", "10")
    child = subprocess.Popen(
        [sys.executable, "-c", CHILD, str(data)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )
    heard = []
    for line in child.stderr:
        heard.append(line)
        if line.startswith("candidates ("):
            break
    assert heard and heard[-1].startswith("candidates ("), "".join(heard)
    child.send_signal(signal.SIGINT)
    sent = time.monotonic()
    out, err = child.communicate(timeout=120)
    stopped_in = time.monotonic() - sent
    assert child.returncode == 0, err
    assert "interrupted: neurotex: the run stopped" in out, out + err
    assert "finished" not in out, out
    assert "after 80" in out, out + err
    # A step of this comparison takes about a second; the whole of it about 15 s.
    assert stopped_in < 10, f"{stopped_in:.1f} s after the Ctrl-C"
    assert "panicked" not in err, err
