"""neurotex.inspect: the CLI's findings and numbers, as dicts; manifest columns on
recordings and datasets for grouped cross-validation."""

import json

import numpy as np
import pytest

import neurotex


def write_logs(folder, offset):
    """Raw logs of a 2x2 sensor at 100 Hz: `t_ms`, then `a`..`d`, resting at `offset`."""
    folder.mkdir()
    for k, label in enumerate(["silk", "felt"]):
        for trial in range(5):
            t = np.arange(300) / 100.0
            rows = ["t_ms,a,b,c,d"]
            for i, ti in enumerate(t):
                values = [offset + 0.5 * (1 + np.sin(2 * np.pi * ti / (0.3 + 0.2 * k) + c))
                          for c in range(4)]
                rows.append(f"{1000 + 10 * i}," + ",".join(f"{v:.6f}" for v in values))
            (folder / f"{label}_V5_{trial}.csv").write_text("\n".join(rows) + "\n")


def test_a_dataset_gives_the_clis_inspection(sim_dir, cli, tmp_path):
    found = neurotex.inspect(sim_dir, out=tmp_path / "checked")
    expected = json.loads(cli("inspect", sim_dir, "--json").stdout)
    assert found.findings == expected["findings"]
    assert found.design == expected["design"]
    assert found.encoder == expected["encoder"]
    assert (tmp_path / "checked" / "inspect.md").is_file()
    assert (tmp_path / "checked" / "figures" / "traces.png").is_file()
    assert str(found).splitlines() == cli("inspect", sim_dir).stdout.splitlines()


def test_raw_logs_with_an_offset_get_the_baseline_suggestion(tmp_path):
    logs = tmp_path / "logs"
    write_logs(logs, offset=30.0)
    found = neurotex.inspect(logs, name_pattern="{label}_V{speed}_{trial}.csv", grid="2x2",
                             time_column="t_ms",
                             encoder=False)
    codes = {f["code"]: f for f in found.severe}
    assert "--baseline min" in codes["resting-offset"]["suggestion"]
    clean = neurotex.inspect(logs, name_pattern="{label}_V{speed}_{trial}.csv", grid="2x2",
                             time_column="t_ms",
                             encoder=False, baseline="min")
    assert all(f["code"] != "resting-offset" for f in clean.findings)


def test_reading_options_are_for_raw_logs(sim_dir):
    with pytest.raises(neurotex.ParameterError, match="dataset folder"):
        neurotex.inspect(sim_dir, grid="4x4")
    with pytest.raises(neurotex.ParameterError, match="grid"):
        neurotex.inspect(sim_dir.parent, grid="four")


def test_manifest_columns_reach_recordings_and_datasets(sim_dir):
    ds = neurotex.load_dataset(sim_dir)
    trials = ds.column("trial")
    assert trials.dtype == float and len(trials) == len(ds)
    assert ds.recordings[0].meta["label"] == ds.recordings[0].label
    assert set(trials) == {float(t) for t in range(5)}
    with pytest.raises(neurotex.ParameterError, match="no column `session`"):
        ds.column("session")
