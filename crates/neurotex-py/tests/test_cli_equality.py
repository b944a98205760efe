"""The Python package gives the CLI's results bit for bit: spikes, features, accuracies,
models (both ways)."""

import csv
import json

import numpy as np
import pytest

import neurotex


def read_feature_csv(path, n_manifest_columns):
    with open(path) as f:
        rows = list(csv.reader(f))
    names = rows[0][n_manifest_columns:]
    values = np.array([[float(v) for v in r[n_manifest_columns:]] for r in rows[1:]])
    files = [r[0] for r in rows[1:]]
    return names, values, files


def test_encode_equals_cli_in_every_dtype_and_order(sim_dir, cli, tmp_path):
    rec = sim_dir / "SB_v10_t02.npy"
    cli("encode", rec, "--out", tmp_path / "spikes.npy")
    expected = np.load(tmp_path / "spikes.npy")
    x = np.load(rec)
    assert x.dtype == np.float32
    assert expected.sum() > 100, "the test recording must spike"
    for variant in (x, x.astype(np.float64), np.asfortranarray(x),
                    np.asfortranarray(x.astype(np.float64)), x[:, ::-1, :][:, ::-1, :],
                    x.astype(">f4"), x.astype(">f8")):
        got = neurotex.encode(variant)
        assert got.dtype == np.uint8
        assert got.shape == expected.shape
        np.testing.assert_array_equal(got, expected)


def test_encode_options_equal_cli(sim_dir, cli, tmp_path):
    rec = sim_dir / "FT1_v5_t01.npy"
    cli("encode", rec, "--out", tmp_path / "s.npy", "--gain", "12.5", "--cutoff", "0",
        "--preset", "IB", "--fs", "500")
    expected = np.load(tmp_path / "s.npy")
    got = neurotex.encode(np.load(rec), fs=500.0, gain=12.5, cutoff=0.0, preset="IB")
    np.testing.assert_array_equal(got, expected)
    # and the options matter: the default encoding differs
    assert not np.array_equal(neurotex.encode(np.load(rec)), expected)


@pytest.mark.parametrize(
    "method,cli_options,py_options",
    [
        ("glcm3d", [], {}),
        ("glcm2d", [], {}),
        ("taxel", [], {}),
        ("all-taxels-mm", [], {}),
        ("glcm3d-multi", ["--haralick", "full"], {"haralick": "full"}),
        ("spectrum", [], {}),
        ("spectrum", ["--spectrum-bins", "64", "--spectrum-bands", "8", "--travel-mm", "40"],
         {"spectrum_bins": 64, "spectrum_bands": 8, "travel_mm": 40.0}),
        ("glcm3d", ["--encoding", "sa+fa", "--levels", "8", "--distances", "1,3",
                    "--symmetric", "--gain", "10", "--cutoff", "20", "--bin-ms", "100"],
         {"encoding": "sa+fa", "levels": 8, "distances": (1, 3), "symmetric": True,
          "gain": 10.0, "cutoff": 20.0, "bin_ms": 100}),
        ("all-taxels", ["--whole", "--encoding", "fa"], {"whole": True, "encoding": "fa"}),
        ("rates", ["--encoding", "sa+fa"], {"encoding": "sa+fa"}),
    ],
)
def test_features_equal_cli(sim_dir, sim, cli, tmp_path, method, cli_options, py_options):
    out = tmp_path / "f.csv"
    cli("features", "--dataset", sim_dir, "--method", method, "--out", out, *cli_options)
    names, expected, files = read_feature_csv(out, len(sim.columns))
    # from arrays in memory (the Dataset's recordings keep their sliding phases)
    X, got_names = neurotex.features(sim, method, **py_options)
    assert got_names == names
    assert X.dtype == np.float64 and X.shape == expected.shape
    np.testing.assert_array_equal(X, expected)
    # from the folder, read by the library
    X2, _ = neurotex.features(str(sim_dir), method, **py_options)
    np.testing.assert_array_equal(X2, expected)
    assert files == [r.name for r in sim.recordings]


def test_features_of_bare_arrays_in_any_layout_are_one_result(sim):
    n = min(len(r.x) for r in sim.recordings[:6])
    arrays = [r.x[:n] for r in sim.recordings[:6]]
    base, _ = neurotex.features(arrays, "glcm3d")
    assert base.shape == (6, 3)
    for variant in ([a.astype(np.float32) for a in arrays],
                    [np.asfortranarray(a) for a in arrays],
                    [np.asfortranarray(a.astype(np.float32)) for a in arrays],
                    np.stack(arrays),
                    np.stack(arrays).astype(np.float32)):
        X, _ = neurotex.features(variant, "glcm3d")
        np.testing.assert_array_equal(X, base)


def test_single_array_functions_compose_to_features(sim):
    """spike_stats, rate_volume, glcm3d, glcm2d and haralick on one recording give the
    pipeline's feature rows."""
    x = sim.recordings[4].x
    spikes = neurotex.encode(x, whole=True)
    row = lambda m: neurotex.features([x], m, whole=True)[0][0]  # noqa: E731
    np.testing.assert_array_equal(neurotex.spike_stats(spikes).reshape(-1), row("taxel"))
    volume = neurotex.rate_volume(spikes)
    assert volume.shape == (4, 4, spikes.shape[0] // 200)
    np.testing.assert_array_equal(neurotex.haralick(neurotex.glcm3d(volume)), row("glcm3d"))
    image = neurotex.rate_volume(spikes, None)[..., 0]
    np.testing.assert_array_equal(neurotex.haralick(neurotex.glcm2d(image)), row("glcm2d"))
    # a rate volume is spikes per bin / bin width
    np.testing.assert_array_equal(
        volume[..., 0], spikes[:200].sum(axis=0) / 0.2)


@pytest.mark.parametrize("classifier,cli_options,options", [
    ("knn", [], {}),
    ("knn", ["--k", "3", "--no-standardize"], {"k": 3, "standardize": False}),
    ("forest", ["--trees", "25", "--forest-seed", "4"], {"trees": 25, "forest_seed": 4}),
    ("linear", ["--c", "0.5"], {"c": 0.5}),
    ("knn", ["--seed", "7", "--folds", "3", "--repeats", "2"],
     {"seed": 7, "folds": 3, "repeats": 2}),
])
def test_accuracy_equals_cli(sim_dir, sim, cli, classifier, cli_options, options):
    out = cli("evaluate", "--dataset", sim_dir, "--method", "glcm3d", "--json",
              "--classifier", classifier, *cli_options)
    expected = json.loads(out.stdout)
    X, _ = neurotex.features(sim, "glcm3d")
    got = neurotex.cross_validate(X, sim.labels, classifier, **options)
    assert got["accuracy"] == expected["accuracy"]
    assert got["accuracy_std"] == expected["accuracy_std"]
    assert got["confusion"] == expected["confusion"]
    assert got["labels"] == expected["labels"]


def test_model_written_by_cli_predicts_as_cli(sim_dir, sim, cli, tmp_path):
    cli("train", "--dataset", sim_dir, "--method", "glcm3d", "--speeds", "5",
        "--out", tmp_path / "m.json")
    cli("predict", "--model", tmp_path / "m.json", "--dataset", sim_dir,
        "--out", tmp_path / "p.csv")
    with open(tmp_path / "p.csv") as f:
        rows = list(csv.DictReader(f))
    model = neurotex.Model.load(tmp_path / "m.json")
    predicted = model.predict(sim)
    assert list(predicted) == [r["predicted"] for r in rows]
    shares = model.predict_proba(sim)
    expected = np.array([[float(r[f"share_{c}"]) for c in model.classes_] for r in rows])
    np.testing.assert_array_equal(shares, expected)


def test_model_written_by_python_is_read_by_cli(sim_dir, sim, cli, tmp_path):
    model = neurotex.Model.train(sim, method="taxel", taxel="1,2", classifier="forest",
                                 classifier_options={"trees": 20, "seed": 1}, gain=9.0)
    model.save(tmp_path / "py.json")
    cli("predict", "--model", tmp_path / "py.json", "--dataset", sim_dir,
        "--out", tmp_path / "p.csv")
    with open(tmp_path / "p.csv") as f:
        rows = list(csv.DictReader(f))
    assert list(model.predict(sim)) == [r["predicted"] for r in rows]
    # the same model as the CLI trains, but for the training data's fingerprint
    cli("train", "--dataset", sim_dir, "--method", "taxel", "--taxel", "1,2", "--classifier",
        "forest", "--trees", "20", "--forest-seed", "1", "--gain", "9", "--out",
        tmp_path / "cli.json")
    ours = json.loads((tmp_path / "py.json").read_text())
    theirs = json.loads((tmp_path / "cli.json").read_text())
    assert ours["training"]["dataset"].pop("fingerprint").startswith("python-arrays-sha256:")
    theirs["training"]["dataset"].pop("fingerprint")
    # the CLI's model remembers how its dataset's files were read; arrays have no layout
    assert "layout" in theirs["training"]["dataset"]
    assert "layout" not in ours["training"]["dataset"]
    theirs["training"]["dataset"].pop("layout")
    assert ours == theirs
    # and Python reads it back to the same predictions
    again = neurotex.Model.load(tmp_path / "py.json")
    assert list(again.predict(sim)) == list(model.predict(sim))


def test_saved_dataset_is_read_by_cli(sim, cli, tmp_path):
    recs = sim.recordings[:9]
    neurotex.save_dataset(tmp_path / "ds", [r.x[5000:12000].astype(np.float32) for r in recs],
                          [r.label for r in recs], speeds=[r.speed for r in recs],
                          trials=list(range(9)), extra=[{"session": "a"}] * 9)
    cli("features", "--dataset", tmp_path / "ds", "--method", "glcm3d", "--out",
        tmp_path / "f.csv")
    back = neurotex.load_dataset(tmp_path / "ds")
    assert back.columns == ["file", "label", "speed_mm_s", "trial", "session"]
    names, expected, _ = read_feature_csv(tmp_path / "f.csv", len(back.columns))
    X, _ = neurotex.features([r.x[5000:12000].astype(np.float32) for r in recs], "glcm3d")
    np.testing.assert_array_equal(X, expected)


def test_simulate_equals_cli(tmp_path, cli):
    cli("simulate", "--out", tmp_path / "c", "--trials", "2", "--speeds", "15",
        "--textures", "RT", "--seed", "9")
    ours = neurotex.simulate(tmp_path / "p", trials=2, speeds=(15,), textures=["RT"], seed=9)
    theirs = neurotex.load_dataset(tmp_path / "c")
    assert ours.rows == theirs.rows
    for a, b in zip(ours.arrays, theirs.arrays):
        np.testing.assert_array_equal(a, b)
