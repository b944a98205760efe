"""Bad input raises the right exception with the library's message; nothing panics."""

import json

import numpy as np
import pytest

import neurotex
from neurotex import errors

GOOD = np.random.default_rng(1).random((1000, 4, 4))


@pytest.mark.parametrize("x,exc,match", [
    (np.full((1000, 4, 4), np.nan), errors.DataError, "sample 0 of channel 0 is NaN"),
    (np.where(np.arange(16000).reshape(1000, 4, 4) == 7000, np.inf, GOOD), errors.DataError,
     "sample 437 of channel 8 is inf"),
    (np.zeros((100, 4, 4)), errors.DataError, "shorter than one 200 ms bin"),
    (np.zeros((10, 2, 2, 2)), errors.DataError, "expected shape"),
    (np.zeros(1000), errors.DataError, "expected shape"),
    (np.array([["a"]]), errors.DataError, "real numbers"),
    (np.zeros((0, 4, 4)), errors.DataError, "recording holds no samples"),
])
def test_bad_samples(x, exc, match):
    with pytest.raises(exc, match=match) as info:
        neurotex.encode(x)
    assert isinstance(info.value, ValueError) and isinstance(info.value, neurotex.Error)


@pytest.mark.parametrize("kwargs,name", [
    ({"gain": -1.0}, "gain"),
    ({"levels": 1}, "levels"),
    ({"levels": 300}, "levels"),
    ({"bin_ms": 0}, "bin_ms"),
    ({"bin_ms": -5}, "bin_ms`: expected a whole number of at least 0, got -5"),
    ({"levels": True}, "levels`: expected a whole number of at least 0, got True"),
    ({"cutoff": True}, "cutoff`: expected a number, got True"),
    ({"whole": 1}, "whole`: expected True or False, got 1"),
    ({"distances": "1,2"}, "distances`: expected a list of whole numbers"),
    ({"baseline": "max"}, "^invalid parameter `baseline`: a baseline is"),
    ({"encoding": "xa"}, "^invalid parameter `encoding`: (?!.*invalid parameter).*got xa$"),
    ({"distances": ()}, "distances"),
    ({"distances": (0,)}, "distances"),
    ({"cutoff": -5.0}, "cutoff"),
    ({"encoding": "xa"}, "encoding"),
    ({"preset": "ZZ"}, "preset|firing"),
    ({"haralick": "most"}, "haralick"),
    ({"baseline": "max"}, "baseline"),
    ({"window_mm": 0.0}, "window"),
    ({"bin_widths": ()}, "bin_widths"),
    ({"gain": "high"}, "gain"),
    ({"levels": 2.5}, "levels"),
    ({"distances": (1, -2)}, "distances"),
])
def test_bad_options(kwargs, name):
    with pytest.raises(errors.ParameterError, match=name):
        neurotex.features([GOOD], "glcm3d", **kwargs)


def test_bad_method_and_fs():
    with pytest.raises(errors.ParameterError, match="method"):
        neurotex.features([GOOD], "glcm4d")
    with pytest.raises(errors.DataError, match="fs must be a positive"):
        neurotex.features([GOOD], fs=0.0)
    with pytest.raises(errors.DataError, match="speed"):
        neurotex.features([GOOD], "all-taxels-mm")


def test_mixed_grids_are_refused():
    with pytest.raises(errors.DataError, match="grid"):
        neurotex.features([GOOD, np.random.default_rng(2).random((1000, 2, 8))])


def test_rasters_and_volumes():
    with pytest.raises(errors.DataError, match="0 or 1"):
        neurotex.spike_stats(np.full((300, 2, 2), 3, dtype=np.uint8))
    with pytest.raises(errors.DataError, match="shorter"):
        neurotex.spike_stats(np.zeros((100, 2, 2), dtype=np.uint8))
    with pytest.raises(errors.DataError, match="shape"):
        neurotex.rate_volume(np.zeros((300, 4), dtype=np.uint8))
    with pytest.raises(errors.DataError, match="finite"):
        neurotex.glcm3d(np.full((2, 2, 3), np.nan))
    with pytest.raises(errors.ParameterError, match="range"):
        neurotex.glcm3d(np.ones((2, 2, 3)), range=(5.0, 1.0))
    with pytest.raises(errors.DataError, match="square"):
        neurotex.haralick(np.ones((3, 4), dtype=np.uint64))
    with pytest.raises(errors.DataError, match="non-negative"):
        neurotex.haralick(-np.ones((3, 3), dtype=np.int64))
    # no pairs, or counts whose total leaves the exact sums: errors, not [0, 1, 0]
    with pytest.raises(errors.DataError, match="no pairs"):
        neurotex.haralick(np.zeros((4, 4), dtype=np.uint64))
    for huge in (np.full((2, 2), 2**63, dtype=np.uint64), np.full((2, 2), 2**54, dtype=np.uint64)):
        with pytest.raises(errors.DataError, match="2\\^55"):
            neurotex.haralick(huge)
    assert neurotex.haralick(np.full((2, 2), 2**52, dtype=np.uint64)).shape == (3,)


def test_files(tmp_path):
    with pytest.raises(FileNotFoundError, match="no such dataset folder") as info:
        neurotex.load_dataset(tmp_path / "nowhere")
    assert isinstance(info.value, neurotex.NotFoundError)
    with pytest.raises(FileNotFoundError):
        neurotex.Model.load(tmp_path / "missing.json")
    (tmp_path / "other.json").write_text(json.dumps({"format": "something-else"}))
    with pytest.raises(errors.ModelError, match="not a neurotex model|format"):
        neurotex.Model.load(tmp_path / "other.json")
    (tmp_path / "cut.json").write_text('{"format": "neurotex-model", "version": 1, "pipe')
    with pytest.raises(errors.ModelError):
        neurotex.Model.load(tmp_path / "cut.json")
    (tmp_path / "ds").mkdir()
    (tmp_path / "ds" / "manifest.csv").write_text("file,label\nmissing.npy,a\n")
    with pytest.raises(errors.DataError, match="line 2: file `missing.npy` does not exist"):
        neurotex.load_dataset(tmp_path / "ds")
    with pytest.raises(errors.DataError, match="not empty|exists"):
        neurotex.save_dataset(tmp_path / "ds", [GOOD], ["a"])


def test_classifiers():
    X = np.random.default_rng(0).random((6, 3))
    y = ["a", "a", "a", "b", "b", "b"]
    with pytest.raises(errors.ClassifyError, match="k = 9 neighbours"):
        neurotex.cross_validate(X, y, "knn", k=9, folds=2)
    with pytest.raises(errors.ClassifyError, match="class `b` has 2 samples, fewer than the 5"):
        neurotex.cross_validate(np.random.default_rng(0).random((12, 3)), ["a"] * 10 + ["b"] * 2)
    # the hint names the keyword as Python spells it
    with pytest.raises(errors.ClassifyError, match="hint: folds=N sets the cross-validation"):
        neurotex.cross_validate(np.random.default_rng(0).random((12, 3)), ["a"] * 10 + ["b"] * 2)
    with pytest.raises(errors.ParameterError, match="classifier"):
        neurotex.cross_validate(X, y, "svm")
    with pytest.raises(errors.ParameterError, match="trees"):
        neurotex.cross_validate(X, y, "forest", trees=0, folds=2)
    with pytest.raises(errors.ParameterError, match="unknown"):
        neurotex.cross_validate(X, y, "knn", neighbours=3, folds=2)


def test_model_train_errors(tmp_path):
    recs = [GOOD, GOOD * 0.5]
    with pytest.raises(errors.ClassifyError, match="k = 5"):
        neurotex.Model.train(recs, ["a", "b"])
    with pytest.raises(errors.ParameterError, match="taxel"):
        neurotex.Model.train(recs, ["a", "b"], method="glcm3d", taxel="0,0")
    with pytest.raises(errors.ParameterError, match="labels"):
        neurotex.Model.train(recs, ["a"])


_OUT_OF_MEMORY = """
import resource, numpy as np, neurotex
resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30))
cases = {
    # broadcast views: a few bytes behind shapes far beyond the 3 GiB limit
    "glcm3d": lambda: neurotex.glcm3d(np.broadcast_to(np.float64(1.0), (40, 40, 10**6))),
    "rate_volume": lambda: neurotex.rate_volume(np.broadcast_to(np.uint8(1), (10**9, 4, 4))),
    "spike_stats": lambda: neurotex.spike_stats(np.broadcast_to(np.uint8(0), (10**9, 4, 4))),
}
for name, call in cases.items():
    try:
        call()
        print(name, "returned")
    except MemoryError as e:
        print(name, "MemoryError", e)
print("alive")
"""


def test_memory_the_machine_lacks_is_a_memory_error_not_an_abort():
    import subprocess
    import sys

    run = subprocess.run([sys.executable, "-c", _OUT_OF_MEMORY], capture_output=True,
                         text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-2000:]
    lines = run.stdout.splitlines()
    assert lines[-1] == "alive"
    assert "glcm3d MemoryError volume: 12800000000 bytes do not fit in memory" in lines
    assert "rate_volume MemoryError spikes: 16000000000 bytes do not fit in memory" in lines
    assert "spike_stats MemoryError spikes: 16000000000 bytes do not fit in memory" in lines


def test_samples_beyond_the_readers_limit_are_refused_before_copying():
    x = np.broadcast_to(np.float64(0.5), (3_600_000, 100, 100))
    with pytest.raises(errors.DataError, match="3.600e10 values once resampled to 1 kHz"):
        neurotex.encode(x, fs=1000)
