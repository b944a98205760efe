"""neurotex.datasets and neurotex.benchmark: a recipe of fabricated headerless logs (time
in the last column) fetched, loaded and served tonic's way; recipes refused naming the key;
and the benchmark on a local Dask cluster giving the command line's leaderboard."""

import hashlib
import io
import json
import math
import random
import zipfile

import pytest

import neurotex
from neurotex import datasets

TEXTURES = ("silk", "denim", "cork")
SPEEDS = (10, 30)
TRIALS = 6


def _log(k, speed, trial):
    rng = random.Random(k * 1000 + speed * 10 + trial)
    spacing = (0.8, 1.6, 3.2)[k]
    rows = []
    for i in range(300):
        t = i / 100.0
        values = [500.0 + 200.0 * (1.0 + math.sin(2 * math.pi * speed * t / spacing + c))
                  * (1.0 + 0.2 * c) + 40.0 * rng.random() for c in range(8)]
        rows.append(",".join(f"{v:.1f}" for v in values) + f",{i * 10}")
    return "\n".join(rows) + "\n"


def _archive():
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as z:
        for k, name in enumerate(TEXTURES):
            for speed in SPEEDS:
                for trial in range(TRIALS):
                    z.writestr(f"logs/{name}_v{speed}_{trial}.csv", _log(k, speed, trial))
    return buf.getvalue()


RECIPE = """
name = "ridges"
title = "Three fabricated ridged textures, 8 taxels, headerless logs"
citation = "neurotex's tests"
licence = "MIT"

[[source]]
url = "https://example.org/data/logs.zip"
kind = "zip"
sha256 = "{sha}"
size = {size}
folder = "logs"

[import]
kind = "csv"
no-header = true
time-column = "8"
channels = "0-7"
grid = "2x4"
name-pattern = "{{label}}_v{{speed}}_{{trial}}.csv"

[conditions]
speed_mm_s = ["10", "30"]

[[protocol]]
id = "within-speed"
per = "speed_mm_s"

[[protocol]]
id = "speed-held-out"
hold-out = "speed_mm_s"
"""


@pytest.fixture(scope="module")
def recipe(tmp_path_factory):
    d = tmp_path_factory.mktemp("recipe")
    data = _archive()
    (d / "copy").mkdir()
    (d / "copy" / "logs.zip").write_bytes(data)
    path = d / "ridges.toml"
    path.write_text(RECIPE.format(sha=hashlib.sha256(data).hexdigest(), size=len(data)))
    return d


def test_fetch_load_and_tonic(recipe, tmp_path):
    cache = tmp_path / "cache"
    name = str(recipe / "ridges.toml")
    with pytest.raises(neurotex.DataError, match="not in this cache"):
        datasets.path(name, cache=cache)
    folder = datasets.fetch(name, source=recipe / "copy", cache=cache)
    assert datasets.path(name, cache=cache) == folder
    data = datasets.load(name, cache=cache)
    assert len(data) == len(TEXTURES) * len(SPEEDS) * TRIALS
    assert sorted(set(data.labels)) == sorted(TEXTURES)
    events = datasets.tonic(name, cache=cache, encoding="sa")
    assert len(events) == len(data)
    first, target = events[0]
    assert first.dtype == neurotex.EVENT_DTYPE and 0 <= target < len(TEXTURES)
    listed = [r["recipe"]["name"] for r in datasets.list_recipes(cache=cache)]
    assert "fabricslide" in listed


def test_a_recipe_breaking_a_rule_is_refused_naming_the_key(recipe, tmp_path):
    text = (recipe / "ridges.toml").read_text().replace('grid = "2x4"', 'grid = "2x4"\ngirdle = 1')
    bad = tmp_path / "bad.toml"
    bad.write_text(text)
    with pytest.raises(neurotex.DataError, match="girdle"):
        datasets.check(bad)
    assert datasets.check("fabricslide")["published"][0]["accuracy"] == 0.96


def _without_times(value):
    if isinstance(value, dict):
        return {k: _without_times(v) for k, v in value.items()
                if k not in ("seconds", "provenance")}
    if isinstance(value, list):
        return [_without_times(v) for v in value]
    return value


def test_benchmark_on_a_dask_cluster_is_the_command_lines(recipe, tmp_path, cli, caplog):
    distributed = pytest.importorskip("distributed")
    name = str(recipe / "ridges.toml")
    cli("benchmark", name, "--from", recipe / "copy", "--cache", tmp_path / "c1",
        "--out", tmp_path / "cli", "--folds", "3", "--seed", "2")
    expected = json.loads((tmp_path / "cli" / "leaderboard.json").read_text())
    caplog.set_level("INFO", logger="neurotex")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            board = neurotex.benchmark([name], tmp_path / "py", cache=tmp_path / "c2",
                                       source=recipe / "copy", folds=3, seed=2, client=client)
    # Both protocols' pieces were computed by the cluster's tasks (three encodings each);
    # the last call took them.
    taken = [r for r in caplog.records if "finished pieces taken" in r.getMessage()]
    assert len(taken) == 2
    assert len(board["boards"]) == 2
    assert _without_times(board) == _without_times(expected)
    written = json.loads((tmp_path / "py" / "leaderboard.json").read_text())
    assert _without_times(written) == _without_times(expected)
