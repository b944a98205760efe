"""The examples run: the Dask one on a LocalCluster, giving features(folder) bit for bit."""

import pathlib
import subprocess
import sys

import numpy as np
import pytest

import neurotex

EXAMPLES = pathlib.Path(__file__).resolve().parents[1] / "examples"
sys.path.insert(0, str(EXAMPLES))


def test_dask_shards_equal_local_features(sim_dir):
    distributed = pytest.importorskip("distributed")
    from dask_features import dask_features

    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            X, names = dask_features(client, str(sim_dir), "glcm3d", shard=7, levels=8)
    expected, expected_names = neurotex.features(str(sim_dir), "glcm3d", levels=8)
    assert names == expected_names
    assert X.shape == expected.shape == (30, 3)
    np.testing.assert_array_equal(X, expected)


def test_worked_example_runs(tmp_path):
    out = subprocess.run([sys.executable, str(EXAMPLES / "worked_example.py"), "--trials", "5",
                          "--out", str(tmp_path)], capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr
    assert "neurotex.cross_validate" in out.stdout
    # the Haralick values are printed, not the f-string's template
    assert "Haralick {'" in out.stdout and "{k:" not in out.stdout, out.stdout
    assert (tmp_path / "model.json").is_file()
