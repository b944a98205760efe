"""Shared fixtures: the CLI binary the Python results are checked against, and a small
simulated dataset written by that binary."""

import os
import pathlib
import subprocess

import pytest

REPO = pathlib.Path(__file__).resolve().parents[3]


def cli_path() -> pathlib.Path:
    """The `neurotex` binary: $NEUROTEX_BIN, else the checkout's release build."""
    path = pathlib.Path(os.environ.get("NEUROTEX_BIN", REPO / "target" / "release" / "neurotex"))
    if not path.is_file():
        pytest.fail(
            f"the CLI binary {path} is missing: build it first "
            "(cargo build --release -p neurotex-cli) or set NEUROTEX_BIN"
        )
    return path


def run_cli(*args, ok=True):
    """Runs the CLI; returns its standard output (checks the exit code)."""
    out = subprocess.run([str(cli_path()), *map(str, args)], capture_output=True, text=True)
    if ok and out.returncode != 0:
        raise AssertionError(f"neurotex {' '.join(map(str, args))} failed:\n{out.stderr}")
    return out


@pytest.fixture(scope="session")
def cli():
    return run_cli


@pytest.fixture(scope="session")
def sim_dir(tmp_path_factory):
    """3 textures x 2 speeds x 5 trials, simulated by the CLI."""
    d = tmp_path_factory.mktemp("data") / "sim"
    run_cli("simulate", "--out", d, "--trials", "5", "--speeds", "5,10",
            "--textures", "FT1,SB,CP", "--seed", "3")
    return d


@pytest.fixture(scope="session")
def sim(sim_dir):
    import neurotex

    return neurotex.load_dataset(sim_dir)
