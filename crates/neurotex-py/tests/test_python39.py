"""Python 3.9 is declared (pyproject's requires-python) but only a newer CPython runs these
tests on the development machine, so 3.9 is checked statically: the extension is built
for the stable ABI (pyo3's abi3-py39), and vermin finds nothing in the Python files that
needs more than 3.9."""

import pathlib
import subprocess
import sys

import neurotex

PACKAGE = pathlib.Path(__file__).resolve().parents[1]


def test_the_extension_is_built_for_the_stable_abi():
    name = pathlib.Path(neurotex._native.__file__).name
    assert ".abi3." in name or name.endswith(".pyd"), name


def test_requires_python_is_3_9():
    assert 'requires-python = ">=3.9"' in (PACKAGE / "pyproject.toml").read_text()


def test_nothing_needs_more_than_python_3_9():
    """vermin (from the `test` extra) on the package, its stubs, tests, examples and
    benchmark; annotations are evaluated too, as if `from __future__ import annotations`
    were absent."""
    paths = [str(PACKAGE / p) for p in ("python", "tests", "examples", "bench")]
    out = subprocess.run(
        [sys.executable, "-c", "import sys, vermin; sys.exit(vermin.main())",
         "--no-tips", "-t=3.9-", "--violations", "--eval-annotations", *paths],
        capture_output=True, text=True)
    assert out.returncode == 0, out.stdout + out.stderr
    assert "Minimum required versions: 3." in out.stdout
    assert "Target versions not met" not in out.stdout
