//! `neurotex train` and `neurotex predict`: a model trained on one simulated dataset,
//! applied to another; damaged and foreign model files; recordings of another grid.

use std::path::{Path, PathBuf};

use ndarray::Array3;
use ndarray_npy::write_npy;
use serde_json::Value;

use crate::util::{recording, relabel, s, Dir};

/// Simulates `name`: FT1, SB and CP x 6 trials at 5 mm/s with `seed`.
fn simulated(dir: &Dir, name: &str, seed: &str) -> PathBuf {
    let out = dir.join(name);
    dir.ok(&[
        "simulate",
        "--out",
        s(&out),
        "--seed",
        seed,
        "--trials",
        "6",
        "--speeds",
        "5",
        "--textures",
        "FT1,SB,CP",
    ]);
    out
}

/// The JSON in `path`.
fn read_json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Runs `neurotex predict --model MODEL --dataset DATASET --out OUT --json`, which must
/// succeed; returns the score it prints.
fn scored(dir: &Dir, model: &Path, dataset: &Path, out: &Path) -> Value {
    let json = dir.ok(&predict(
        s(model),
        s(out),
        &["--dataset", s(dataset), "--json"],
    ));
    serde_json::from_str(&json).expect("predict --json prints JSON")
}

/// The rows of a CSV file as fields, header first.
fn csv_rows(path: &Path) -> Vec<Vec<String>> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| l.split(',').map(String::from).collect())
        .collect()
}

#[test]
fn a_model_trained_on_one_seed_predicts_another() {
    let dir = Dir::new();
    let (a, b) = (simulated(&dir, "A", "1"), simulated(&dir, "B", "2"));
    let model = dir.join("model.json");
    dir.ok(&["train", "--dataset", s(&a), "--out", s(&model)]);
    let file = read_json(&model);
    assert_eq!(file["format"], "neurotex-model");
    assert_eq!(file["version"], 1);
    assert_eq!(file["features"]["method"], "glcm3d");
    assert_eq!(file["classifier"]["k"], 5);
    assert_eq!(file["labels"], serde_json::json!(["FT1", "SB", "CP"]));
    let fingerprint = file["training"]["dataset"]["fingerprint"].as_str().unwrap();
    assert!(fingerprint.starts_with("sha256:") && fingerprint.len() == 7 + 64);

    let out = dir.join("predictions.csv");
    let score = scored(&dir, &model, &b, &out);
    let accuracy = score["accuracy"].as_f64().unwrap();
    assert!(accuracy > 0.6, "chance is 1/3, got {accuracy}");
    assert_eq!(score["n"], 18);
    assert_eq!(score["labels"], file["labels"]);
    let rows = csv_rows(&out);
    assert_eq!(
        rows[0],
        [
            "file",
            "label",
            "predicted",
            "share_FT1",
            "share_SB",
            "share_CP"
        ]
    );
    assert_eq!(rows.len(), 1 + 18, "one row per recording");
    let mut right = 0;
    for row in &rows[1..] {
        let shares: Vec<f64> = row[3..].iter().map(|v| v.parse().unwrap()).collect();
        assert!((shares.iter().sum::<f64>() - 1.0).abs() < 1e-12, "{row:?}");
        let top = ["FT1", "SB", "CP"]
            .iter()
            .position(|l| *l == row[2])
            .unwrap();
        assert!(shares.iter().all(|&v| v <= shares[top]), "{row:?}");
        right += usize::from(row[1] == row[2]);
    }
    assert!((right as f64 / 18.0 - accuracy).abs() < 1e-12);

    // plain files: the label is unknown
    let plain = dir.join("plain.csv");
    let files = [b.join("FT1_v5_t00.npy"), b.join("CP_v5_t03.npy")];
    dir.ok(&predict(
        s(&model),
        s(&plain),
        &[s(&files[0]), s(&files[1])],
    ));
    let rows = csv_rows(&plain);
    assert_eq!(rows.len(), 3);
    assert_eq!(rows[1][0], s(&files[0]));
    assert_eq!(rows[1][1], "", "no label for a plain file");
}

#[test]
fn predict_applies_the_models_pipeline_not_the_defaults() {
    // With k = 1 every training recording is its own nearest neighbour, but only when it
    // is conditioned, encoded and binned exactly as in training.
    let dir = Dir::new();
    let a = simulated(&dir, "A", "1");
    let model = dir.join("model.json");
    dir.ok(&[
        "train",
        "--dataset",
        s(&a),
        "--method",
        "taxel",
        "-k",
        "1",
        "--gain",
        "12",
        "--cutoff",
        "20",
        "--bin-ms",
        "100",
        "--out",
        s(&model),
    ]);
    let file = read_json(&model);
    assert_eq!(file["pipeline"]["encoder"]["gain"], 12.0);
    assert_eq!(file["features"]["columns"].as_array().unwrap().len(), 48);
    let out = dir.join("p.csv");
    let score = scored(&dir, &model, &a, &out);
    assert_eq!(score["accuracy"], 1.0, "{score}");
}

#[test]
fn bad_models_and_recordings_are_named_errors() {
    let dir = Dir::new();
    let a = simulated(&dir, "A", "1");
    let model = dir.join("model.json");
    dir.ok(&["train", "--dataset", s(&a), "--out", s(&model)]);
    let text = std::fs::read_to_string(&model).unwrap();
    let damaged = dir.join("damaged.json");
    std::fs::write(&damaged, &text[..text.len() * 2 / 3]).unwrap();
    let future = dir.join("future.json");
    std::fs::write(
        &future,
        text.replacen("\"version\": 1", "\"version\": 99", 1),
    )
    .unwrap();
    let other = dir.join("other.json");
    std::fs::write(&other, r#"{"format": "something-else", "version": 1}"#).unwrap();
    let grid = dir.join("grid2x3.npy");
    write_npy(&grid, &Array3::<f32>::from_elem((1400, 2, 3), 0.5)).unwrap();
    let fine = dir.join("fine.npy");
    write_npy(&fine, &recording(1400, 80.0, 0.3, 1)).unwrap();
    let labelled = dir.dataset("letters", &["A", "B"], &[5.0], 2);

    let out = dir.join("p.csv");
    let (o, m, a) = (s(&out), s(&model), s(&a));
    let damaged_error = format!("{}: damaged or truncated model file", s(&damaged));
    let grid_error = format!("{}: its taxel grid (2x3, 6 taxels) differs", s(&grid));
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (predict(s(&damaged), o, &["--dataset", a]), &damaged_error),
        (
            predict(s(&future), o, &["--dataset", a]),
            "model file version 99 is not supported",
        ),
        (
            predict(s(&other), o, &["--dataset", a]),
            "not a neurotex model file",
        ),
        (predict(m, o, &[s(&fine), s(&grid)]), &grid_error),
        (
            predict(m, o, &["--dataset", s(&labelled), "--json"]),
            "test label `A`",
        ),
        (predict(m, o, &[s(&fine), "--json"]), "--dataset"),
        (
            vec![
                "train",
                "--dataset",
                a,
                "--method",
                "glcm3d",
                "--taxel",
                "1,1",
                "--out",
                o,
            ],
            "only to --method taxel",
        ),
        (
            vec!["train", "--dataset", a, "-k", "19", "--out", o],
            "k = 19 neighbours needs at least 19",
        ),
    ];
    dir.fails_each(&cases, &out);
    assert!(!dir.partial_left(), "temporary files left behind");
}

/// `neurotex predict --model MODEL WHAT... --out OUT`.
fn predict<'a>(model: &'a str, out: &'a str, what: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec!["predict", "--model", model];
    args.extend_from_slice(what);
    args.extend(["--out", out]);
    args
}

#[test]
fn gain_auto_is_calibrated_on_the_training_set_and_kept_in_the_model() {
    let dir = Dir::new();
    let (a, b) = (simulated(&dir, "A", "1"), simulated(&dir, "B", "2"));
    let model = dir.join("auto.json");
    let train = |gain: &str, out: &Path| {
        dir.run(&["train", "--dataset", s(&a), "--gain", gain, "--out", s(out)])
    };
    let run = train("auto:30", &model);
    assert!(run.status.success(), "{}", run.stderr);
    assert!(run.stderr.contains("--gain auto: G = "), "{}", run.stderr);
    let file = read_json(&model);
    let calibration = &file["training"]["dataset"]["gain_calibration"];
    let gain = calibration["gain"].as_f64().unwrap();
    assert_eq!(file["pipeline"]["encoder"]["gain"].as_f64(), Some(gain));
    assert_eq!(calibration["target_hz"].as_f64(), Some(30.0));
    assert!(calibration["median_hz"].as_f64().unwrap() >= 30.0);
    // A higher target needs a higher gain on the same recordings.
    let higher = dir.join("auto60.json");
    assert!(train("auto:60", &higher).status.success());
    let g60 = read_json(&higher)["pipeline"]["encoder"]["gain"]
        .as_f64()
        .unwrap();
    assert!(g60 > gain, "{g60} <= {gain}");
    // The model applies its calibrated gain to new recordings.
    let score = scored(&dir, &model, &b, &dir.join("p.csv"));
    assert!(score["accuracy"].as_f64().is_some());
    // A fixed gain records no calibration.
    let fixed = dir.join("fixed.json");
    assert!(train("8", &fixed).status.success());
    assert!(read_json(&fixed)["training"]["dataset"]
        .get("gain_calibration")
        .is_none());
    for bad in ["auto:0", "auto:x", "loud"] {
        let err = dir.fails(&[
            "train",
            "--dataset",
            s(&a),
            "--gain",
            bad,
            "--out",
            s(&fixed),
        ]);
        assert!(err.contains("--gain"), "{bad}: {err}");
    }
}

#[test]
fn gain_auto_in_evaluate_calibrates_on_the_training_speeds_only() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B", "C"], &[5.0, 10.0], 6);
    let model = dir.join("m.json");
    let trained = dir.run(&[
        "train",
        "--dataset",
        s(&ds),
        "--speeds",
        "5",
        "--gain",
        "auto",
        "--out",
        s(&model),
    ]);
    assert!(trained.status.success(), "{}", trained.stderr);
    let train_gain = read_json(&model)["pipeline"]["encoder"]["gain"]
        .as_f64()
        .unwrap();
    let split = dir.evaluate_json(
        &ds,
        "glcm3d",
        &[
            "--train-speeds",
            "5",
            "--test-speeds",
            "10",
            "--gain",
            "auto",
        ],
    );
    assert_eq!(split["gain_calibration"]["gain"].as_f64(), Some(train_gain));
    // Calibrating on the test speed as well gives another gain on these recordings (their
    // amplitude differs with speed), so the split above did not look at the test speed.
    let both = dir.evaluate_json(&ds, "glcm3d", &["--gain", "auto"]);
    let all_gain = both["gain_calibration"]["gain"].as_f64().unwrap();
    assert_ne!(all_gain, train_gain);
    let features = dir.join("f.csv");
    dir.ok(&[
        "features",
        "--dataset",
        s(&ds),
        "--method",
        "taxel",
        "--gain",
        "auto",
        "--out",
        s(&features),
    ]);
}

#[test]
fn a_spectrum_model_trains_and_predicts_but_is_refused_for_streams() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[5.0], 6);
    let model = dir.join("spectrum.json");
    dir.ok(&[
        "train",
        "--dataset",
        s(&ds),
        "--method",
        "spectrum",
        "--out",
        s(&model),
    ]);
    let out = dir.join("p.csv");
    dir.ok(&[
        "predict",
        "--model",
        s(&model),
        "--dataset",
        s(&ds),
        "--out",
        s(&out),
    ]);
    assert_eq!(csv_rows(&out).len(), 1 + 12);
    // A stream sees growing windows, not a span of the slide: refused before training.
    let causal = dir.join("causal.json");
    let err = dir.fails(&[
        "train",
        "--dataset",
        s(&ds),
        "--method",
        "spectrum",
        "--causal",
        "--out",
        s(&causal),
    ]);
    assert!(err.contains("no running form"), "{err}");
    assert!(!causal.exists());
}

#[test]
fn a_spiking_network_trains_saves_and_predicts_and_a_damaged_one_is_named() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B", "C"], &[10.0], 8);
    let model = dir.join("snn.json");
    dir.ok(&[
        "train",
        "--dataset",
        s(&ds),
        "--classifier",
        "snn",
        "--encoding",
        "sa+fa",
        "--snn-epochs",
        "15",
        "--out",
        s(&model),
    ]);
    let file: Value = serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
    assert_eq!(file["format"], "neurotex-snn-model");
    let net = &file["network"];
    // 4x4 simulated taxels, SA and FA: 32 inputs; 3 classes.
    assert_eq!(net["inputs"], 32);
    assert_eq!(net["classes"], 3);
    let out = dir.join("pred.csv");
    let score = dir.predict_json(&model, &ds, &out);
    assert_eq!(score["n"], 24);
    // Trained on these recordings (80 % of them; 20 % for early stopping).
    assert!(score["accuracy"].as_f64().unwrap() > 0.6, "{score}");
    let csv = std::fs::read_to_string(&out).unwrap();
    assert!(
        csv.starts_with("file,label,predicted,share_A,share_B,share_C"),
        "{csv}"
    );
    // A network that does not fit its pipeline: one population where it was trained on two.
    let mut wrong = file.clone();
    wrong["pipeline"]["encoding"] = Value::from("sa");
    let damaged = dir.join("damaged.json");
    std::fs::write(&damaged, serde_json::to_string(&wrong).unwrap()).unwrap();
    let never = dir.join("never.csv");
    let predict = |m: &Path| -> Vec<String> {
        [
            "predict",
            "--model",
            s(m),
            "--dataset",
            s(&ds),
            "--out",
            s(&never),
        ]
        .map(String::from)
        .to_vec()
    };
    let args = predict(&damaged);
    let err = dir.fails(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(
        err.contains("damaged.json") && err.contains("32 inputs"),
        "{err}"
    );
    // A weight list of the wrong length, and a weight JSON cannot hold as a number.
    let mut short = file.clone();
    short["network"]["b_in"].as_array_mut().unwrap().pop();
    std::fs::write(&damaged, serde_json::to_string(&short).unwrap()).unwrap();
    let err = dir.fails(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(
        err.contains("damaged.json") && err.contains("b_in"),
        "{err}"
    );
    let mut nan = file.clone();
    nan["network"]["w_out"][0] = Value::Null;
    std::fs::write(&damaged, serde_json::to_string(&nan).unwrap()).unwrap();
    let err = dir.fails(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(err.contains("damaged.json"), "{err}");
    // Decays of each neuron's own in a network its training did not give them, named as
    // such; then of the wrong count, or outside (0, 1).
    let mut own = file.clone();
    let hidden = own["network"]["hidden"].as_u64().unwrap() as usize;
    own["network"]["alpha"] = Value::from(vec![0.5; hidden]);
    own["network"]["beta"] = Value::from(vec![0.7; hidden]);
    std::fs::write(&damaged, serde_json::to_string(&own).unwrap()).unwrap();
    let err = dir.fails(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(
        err.contains("`classifier.train_decays` false) do not train each neuron's own decays, and the network has them"),
        "{err}"
    );
    own["classifier"]["train_decays"] = Value::from(true);
    own["network"]["alpha"].as_array_mut().unwrap().pop();
    std::fs::write(&damaged, serde_json::to_string(&own).unwrap()).unwrap();
    let err = dir.fails(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(err.contains("not one per hidden neuron"), "{err}");
    own["network"]["alpha"] = Value::from(vec![1.5; hidden]);
    std::fs::write(&damaged, serde_json::to_string(&own).unwrap()).unwrap();
    let err = dir.fails(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(err.contains("alpha[0] is 1.5"), "{err}");
    // Adaptive thresholds its training did not give the network, then ones of no time.
    let mut adapt = file.clone();
    adapt["network"]["adaptation"] = serde_json::json!({"tau_ms": 200.0, "strength": 1.0});
    std::fs::write(&damaged, serde_json::to_string(&adapt).unwrap()).unwrap();
    let err = dir.fails(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(err.contains("`network.adaptation`"), "{err}");
    adapt["network"]["adaptation"]["tau_ms"] = Value::from(0.0);
    adapt["classifier"]["adapt_ms"] = Value::from(0.0);
    std::fs::write(&damaged, serde_json::to_string(&adapt).unwrap()).unwrap();
    let err = dir.fails(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(err.contains("adapt"), "{err}");
    // Delays its training did not give the network, then a negative one.
    let mut delayed = file.clone();
    let synapses = delayed["network"]["w_in"].as_array().unwrap().len();
    delayed["network"]["delays"] = Value::from(vec![1.5; synapses]);
    std::fs::write(&damaged, serde_json::to_string(&delayed).unwrap()).unwrap();
    let err = dir.fails(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(err.contains("`network.delays`"), "{err}");
    delayed["classifier"]["delay_ms"] = Value::from(50.0);
    delayed["network"]["delays"][3] = Value::from(-1.0);
    std::fs::write(&damaged, serde_json::to_string(&delayed).unwrap()).unwrap();
    let err = dir.fails(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(err.contains("delays[3] is -1.0"), "{err}");
    assert!(!never.exists());
    // A graph that is not HDF5, and a feature model where a spiking one is needed.
    let junk = dir.join("junk.nir");
    std::fs::write(&junk, b"not a graph").unwrap();
    let err = dir.fails(&[
        "predict",
        "--model",
        s(&junk),
        "--dataset",
        s(&ds),
        "--out",
        s(&never),
    ]);
    assert!(
        err.contains("junk.nir: cannot run this NIR graph: not an HDF5 file"),
        "{err}"
    );
    let feature = dir.join("feature.json");
    dir.ok(&["train", "--dataset", s(&ds), "--out", s(&feature)]);
    let graph = dir.join("snn.nir");
    dir.ok(&["export", "nir", "--model", s(&model), "--out", s(&graph)]);
    let args = [
        "predict",
        "--model",
        s(&graph),
        "--like",
        s(&feature),
        "--dataset",
        s(&ds),
        "--out",
        s(&never),
    ];
    let err = dir.fails(&args);
    assert!(err.contains("feature.json: a feature model"), "{err}");
    let err = dir.export_refused("nir", &feature, &never);
    assert!(err.contains("not a spiking model"), "{err}");
    // A graph that carries its own pipeline takes no other; a truncated spiking model is
    // named as damaged, not as another kind.
    let mut args = args.to_vec();
    args[4] = s(&model);
    let err = dir.fails(&args);
    assert!(err.contains("carries its own neurotex pipeline"), "{err}");
    let text = std::fs::read_to_string(&model).unwrap();
    std::fs::write(&damaged, &text[..text.len() / 2]).unwrap();
    let err = dir.export_refused("nir", &damaged, &never);
    assert!(err.contains("damaged or truncated"), "{err}");
    // A spiking model trained without --causal where a stream needs one trained with it.
    let err = dir.fails(&["stream", "--model", s(&model), "--input", s(&never)]);
    assert!(
        err.contains("snn.json: a stream needs a model trained for streams (--causal)"),
        "{err}"
    );
    // The input tensors, written twice into the same folder: the second run replaces the
    // first.
    let inputs = dir.join("inputs");
    for _ in 0..2 {
        dir.ok(&[
            "export",
            "inputs",
            "--model",
            s(&model),
            "--dataset",
            s(&ds),
            "--out",
            s(&inputs),
        ]);
    }
    let index = std::fs::read_to_string(inputs.join("index.csv")).unwrap();
    assert_eq!(index.lines().count(), 25, "{index}");
    assert!(index.starts_with("file,label,array\n"));
}

/// `--snn-reset subtract` is written in the model file (network and training parameters),
/// predicts, and travels through a NIR graph; a zero-reset model file has no `reset` key
/// and is the same, byte for byte, with `--snn-reset zero` or without the option.
#[test]
fn a_subtractive_reset_is_written_and_a_zero_reset_left_out() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[10.0], 4);
    let train = |out: &Path, reset: &[&str]| dir.train_tiny_snn(&ds, out, reset);
    let (plain, zero, subtract) = (
        dir.join("plain.json"),
        dir.join("zero.json"),
        dir.join("subtract.json"),
    );
    train(&plain, &[]);
    train(&zero, &["--snn-reset", "zero"]);
    train(&subtract, &["--snn-reset", "subtract"]);
    let text = std::fs::read_to_string(&plain).unwrap();
    assert!(!text.contains("\"reset\""), "{text}");
    assert_eq!(text, std::fs::read_to_string(&zero).unwrap());
    let file = read_json(&subtract);
    assert_eq!(file["network"]["reset"], "subtract");
    assert_eq!(file["classifier"]["reset"], "subtract");
    let predict = |model: &Path, out: &Path| {
        let text = dir.ok(&[
            "predict",
            "--model",
            s(model),
            "--dataset",
            s(&ds),
            "--out",
            s(out),
            "--json",
        ]);
        let score: Value = serde_json::from_str(&text).unwrap();
        assert_eq!(score["n"], 8, "{score}");
        std::fs::read_to_string(out).unwrap()
    };
    let from_file = predict(&subtract, &dir.join("file.csv"));
    let graph = dir.join("subtract.nir");
    dir.ok(&["export", "nir", "--model", s(&subtract), "--out", s(&graph)]);
    assert_eq!(predict(&graph, &dir.join("graph.csv")), from_file);
    let err = dir.train_snn_fails(&ds, &dir.join("never.json"), &["--snn-reset", "half"]);
    assert!(err.contains("snn-reset"), "{err}");
}

/// `--snn-adapt-ms` is written in the model file (network and training parameters) and
/// predicts, but has no NIR graph (NIR has no adaptive threshold): the export is refused
/// and writes nothing; a time constant that is not positive, a subtracting reset and a
/// strength without a time constant are refused by the option's name.
#[test]
fn adaptive_thresholds_are_written_and_predict_but_make_no_graph() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[10.0], 4);
    let model = dir.join("adapt.json");
    dir.train_tiny_snn(
        &ds,
        &model,
        &["--snn-adapt-ms", "150", "--snn-adapt-strength", "0.5"],
    );
    let file = read_json(&model);
    assert_eq!(file["network"]["adaptation"]["tau_ms"], 150.0);
    assert_eq!(file["network"]["adaptation"]["strength"], 0.5);
    assert_eq!(file["classifier"]["adapt_ms"], 150.0);
    let score = dir.predict_json(&model, &ds, &dir.join("p.csv"));
    assert_eq!(score["n"], 8, "{score}");
    let err = dir.export_refused("nir", &model, &dir.join("adapt.nir"));
    assert!(
        err.contains("adaptive thresholds") && err.contains("--snn-adapt-ms"),
        "{err}"
    );
    let never = dir.join("never.json");
    for (flags, option) in [
        (
            ["--snn-adapt-ms", "0", "--snn-reset", "zero"],
            "snn-adapt-ms",
        ),
        (
            ["--snn-adapt-ms", "150", "--snn-reset", "subtract"],
            "snn-adapt-ms",
        ),
        (
            ["--snn-adapt-strength", "0.5", "--snn-reset", "zero"],
            "snn-adapt-strength",
        ),
    ] {
        let err = dir.train_snn_fails(&ds, &never, &flags);
        assert!(err.contains(option), "{flags:?}: {err}");
    }
    assert!(!never.exists());
}

/// Learnable delays: kept in the model file within their longest, run by `predict`, and
/// refused by NIR export, the Xylo profile and bounds.
#[test]
fn synaptic_delays_are_written_and_predict_but_make_no_graph() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[10.0], 4);
    let model = dir.join("delays.json");
    dir.train_tiny_snn(&ds, &model, &["--snn-delay-ms", "50"]);
    let file = read_json(&model);
    assert_eq!(file["classifier"]["delay_ms"], 50.0);
    let (w_in, delays) = (&file["network"]["w_in"], &file["network"]["delays"]);
    let delays: Vec<f64> = (delays.as_array().unwrap().iter())
        .map(|d| d.as_f64().unwrap())
        .collect();
    assert_eq!(delays.len(), w_in.as_array().unwrap().len());
    // Up to 50 ms in steps of 10 ms, spread rather than all alike.
    assert!(delays.iter().all(|d| (0.0..=5.0).contains(d)), "{delays:?}");
    assert!(delays.iter().any(|&d| d > 2.5) && delays.iter().any(|&d| d < 2.5));
    let score = dir.predict_json(&model, &ds, &dir.join("p.csv"));
    assert_eq!(score["n"], 8, "{score}");
    let err = dir.export_refused("nir", &model, &dir.join("delays.nir"));
    assert!(
        err.contains("--snn-delay-ms") && err.contains("Delay"),
        "{err}"
    );
    let err = dir.export_refused("xylo", &model, &dir.join("delays.xylo.json"));
    assert!(
        err.contains("--snn-target xylo, and without --snn-delay-ms"),
        "{err}"
    );
    let never = dir.join("never.json");
    for flags in [
        &["--snn-delay-ms", "0"][..],
        &["--snn-delay-ms", "5"],
        &["--snn-delay-ms", "10001"],
        &["--snn-delay-ms", "inf"],
        &[
            "--snn-delay-ms",
            "50",
            "--snn-target",
            "xylo",
            "--snn-reset",
            "subtract",
        ],
    ] {
        let err = dir.train_snn_fails(&ds, &never, flags);
        assert!(err.contains("snn-delay-ms"), "{flags:?}: {err}");
    }
    assert!(!never.exists());
}

/// Writes `file` with each `(JSON pointer, value)` of `edits` set to `damaged.json`;
/// `predict` with it must fail naming the file and `expected`, and write nothing.
fn refused_when_tampered(
    dir: &Dir,
    file: &Value,
    dataset: &Path,
    edits: &[(&str, Value)],
    expected: &str,
) {
    let mut tampered = file.clone();
    for (pointer, value) in edits {
        match tampered.pointer_mut(pointer) {
            Some(at) => *at = value.clone(),
            None => {
                // A field the file leaves out: added to its object.
                let (parent, key) = pointer.rsplit_once('/').expect(pointer);
                let object = tampered.pointer_mut(parent).and_then(Value::as_object_mut);
                object.expect(parent).insert(key.into(), value.clone());
            }
        }
    }
    let damaged = dir.join("damaged.json");
    std::fs::write(&damaged, serde_json::to_string(&tampered).unwrap()).unwrap();
    let out = dir.join("never.csv");
    let err = dir.fails(&predict(s(&damaged), s(&out), &["--dataset", s(dataset)]));
    assert!(
        err.contains("damaged.json: model file with content neurotex never writes")
            && err.contains(expected),
        "{edits:?}: expected `{expected}` in {err}"
    );
    assert!(!out.exists(), "{edits:?}: predictions written");
}

#[test]
fn every_field_training_guarantees_is_checked_when_a_spiking_model_is_read() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[10.0], 4);
    let model = dir.join("snn.json");
    dir.train_tiny_snn(&ds, &model, &[]);
    let file = read_json(&model);
    let both = |field: &str, v: Value| {
        let net = format!("/network/{field}");
        let params = format!("/classifier/{field}");
        vec![(net, v.clone()), (params, v)]
    };
    let one = |pointer: &str, v: Value| vec![(pointer.to_string(), v)];
    let cases: Vec<(Vec<(String, Value)>, &str)> = vec![
        (
            both("dt_ms", 5000.into()),
            "the training parameters (`classifier`): invalid parameter `snn-dt-ms`: the time step must be 1 to 1000 ms, got 5000",
        ),
        (
            one("/network/dt_ms", 20.into()),
            "`network.dt_ms` (20) differs from the training parameters (`classifier`: 10)",
        ),
        (both("tau_mem_ms", 1e300.into()), "tau_mem_ms is 1e300"),
        (one("/network/w_out/0", 1e300.into()), "w_out[0] is 1e300"),
        (one("/network/b_in/1", (-1e39).into()), "b_in[1] is -1e39"),
        (one("/labels/1", "A".into()), "class `A` is listed twice"),
        (
            one("/classifier/validation", 1.5.into()),
            "the training parameters (`classifier`): invalid parameter `snn-validation`",
        ),
        (one("/training/best_epoch", 99.into()), "field `training`"),
        (
            one("/training/dataset/median_duration_ms", 0.into()),
            "median_duration_ms",
        ),
        (one("/training/dataset/layout/fs", (-1.0).into()), "`fs`"),
        (
            one("/network/reset", "subtract".into()),
            "`network.reset` (\"subtract\") differs from the training parameters (`classifier`: \"zero\")",
        ),
        (
            both("reset", "sideways".into()),
            "unknown variant `sideways`",
        ),
    ];
    for (edits, expected) in &cases {
        let edits: Vec<(&str, Value)> =
            edits.iter().map(|(p, v)| (p.as_str(), v.clone())).collect();
        refused_when_tampered(&dir, &file, &ds, &edits, expected);
    }
    assert!(!dir.partial_left(), "temporary files left behind");
}

#[test]
fn every_field_training_guarantees_is_checked_when_a_feature_model_is_read() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[10.0], 4);
    let model = dir.join("causal.json");
    let train = ["train", "--dataset", s(&ds), "--causal", "-k", "1"];
    dir.ok(&[&train[..], &["--out", s(&model)]].concat());
    let file = read_json(&model);
    let labels = vec![Value::from("A"), Value::from("B"), Value::from("Z")];
    let offsets = file["pipeline"]["preprocess"]["causal"]["offsets"]
        .as_array()
        .unwrap()[1..]
        .to_vec();
    let cases: Vec<(&str, Value, &str)> = vec![
        ("/labels", labels.into(), "class `Z` has no training row"),
        ("/labels/1", "A".into(), "class `A` is listed twice"),
        (
            "/pipeline/preprocess/causal/offsets",
            offsets.into(),
            "`pipeline.preprocess.causal.offsets` holds 15 resting values for the 16 cells",
        ),
        (
            "/training/dataset/median_duration_ms",
            0.into(),
            "median_duration_ms",
        ),
        ("/training/dataset/layout/fs", (-1.0).into(), "`fs`"),
    ];
    for (pointer, value, expected) in cases {
        refused_when_tampered(&dir, &file, &ds, &[(pointer, value)], expected);
    }
    assert!(!dir.partial_left(), "temporary files left behind");
}

#[test]
fn a_model_trained_on_events_refuses_sampled_recordings() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[10.0], 4);
    let events = dir.join("ev");
    dir.ok(&["export", "events", "--dataset", s(&ds), "--out", s(&events)]);
    let out = dir.join("never.csv");
    for (name, extra) in [
        ("ev.json", &[][..]),
        (
            "ev_snn.json",
            &[
                "--classifier",
                "snn",
                "--snn-hidden",
                "8",
                "--snn-epochs",
                "2",
            ][..],
        ),
    ] {
        let model = dir.join(name);
        let train = ["train", "--dataset", s(&events), "--out", s(&model)];
        dir.ok(&[&train[..], extra].concat());
        // its own kind of recordings is predicted
        let fine = dir.join("fine.csv");
        dir.ok(&predict(s(&model), s(&fine), &["--dataset", s(&events)]));
        for causal in [&[][..], &["--causal"][..]] {
            let args = [
                &predict(s(&model), s(&out), &["--dataset", s(&ds)])[..],
                causal,
            ]
            .concat();
            let err = dir.fails(&args);
            assert!(
                err.contains("is a sampled recording, but the model was trained on address events"),
                "{name} {causal:?}: {err}"
            );
            assert!(!out.exists(), "{name} {causal:?}: output written");
        }
    }
}

/// `train` and `evaluate` choose the spiking network the same way: `--classifier snn`
/// reads the spike trains and `--method spikes` is read by the network, so either one
/// alone chooses it and both give the same model; a pairing that does not run is refused
/// by name in both commands.
#[test]
fn train_and_evaluate_choose_the_network_alike() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[10.0], 4);
    let snn = ["--snn-hidden", "8", "--snn-epochs", "2"];
    let (by_classifier, by_method) = (dir.join("c.json"), dir.join("m.json"));
    for (choice, out) in [
        (["--classifier", "snn"], &by_classifier),
        (["--method", "spikes"], &by_method),
    ] {
        let mut args = vec!["train", "--dataset", s(&ds), "--out", s(out)];
        args.extend(choice);
        args.extend(snn);
        dir.ok(&args);
    }
    let read = |p: &Path| std::fs::read_to_string(p).unwrap();
    assert!(read(&by_classifier).contains("neurotex-snn-model"));
    assert_eq!(read(&by_classifier), read(&by_method));
    let evaluate = |choice: &[&str]| {
        let mut args = vec!["evaluate", "--dataset", s(&ds), "--folds", "2", "--json"];
        args.extend(choice);
        args.extend(snn);
        let out: Value = serde_json::from_str(&dir.ok(&args)).unwrap();
        assert_eq!(out["method"], "spikes", "{out}");
        let classifier = out["classifier"].as_str().unwrap_or_default();
        assert!(classifier.starts_with("spiking network (8 LIF"), "{out}");
        out["accuracy"].clone()
    };
    assert_eq!(
        evaluate(&["--classifier", "snn"]),
        evaluate(&["--method", "spikes"])
    );
    for command in ["train", "evaluate"] {
        let mut args = vec![command, "--dataset", s(&ds), "--out", s(&by_method)];
        if command == "evaluate" {
            args.truncate(3);
        }
        args.extend(["--method", "spikes", "--classifier", "forest"]);
        let err = dir.fails(&args);
        assert!(
            err.contains("classifier") && err.contains("spikes with snn"),
            "{err}"
        );
    }
    let forest = ["--classifier", "forest", "--snn-epochs", "2"];
    let err = dir.fails(&[&["evaluate", "--dataset", s(&ds)][..], &forest].concat());
    assert!(
        err.contains("--snn-epochs applies only to --classifier snn"),
        "{err}"
    );
    let args = ["train", "--dataset", s(&ds), "--method", "van-rossum"];
    let err = dir.fails(&[&args[..], &["--out", s(&dir.join("never.json"))]].concat());
    assert!(err.contains("evaluated, not trained"), "{err}");
}

/// `--snn-window-ms` trains on windows: the model file records it (a file trained on whole
/// recordings has no such key, as before the option existed), the trained network differs
/// from the whole-recording one, `evaluate` says it (and that a window under five membrane
/// time constants is mostly the neurons' start-up), and a window shorter than the network's
/// step is refused by its flag, with the step, before anything is written.
#[test]
fn the_network_trains_on_windows_when_asked() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[10.0], 4);
    let train = |extra: &[&str], out: &Path| {
        dir.train_tiny_snn(&ds, out, extra);
        serde_json::from_str::<Value>(&std::fs::read_to_string(out).unwrap()).unwrap()
    };
    let whole = train(&[], &dir.join("whole.json"));
    let windowed = train(&["--snn-window-ms", "300"], &dir.join("windowed.json"));
    assert!(!whole.to_string().contains("window_ms"), "{whole}");
    assert!(
        windowed.to_string().contains("\"window_ms\":300"),
        "{windowed}"
    );
    assert_ne!(whole["network"], windowed["network"]);
    let never = dir.join("never.json");
    let err = dir.train_snn_fails(&ds, &never, &["--snn-window-ms", "5"]);
    assert!(err.contains("`snn-window-ms`"), "{err}");
    assert!(err.contains("under one step of 10 ms"), "{err}");
    assert!(!never.exists());
    let evaluate = [
        "evaluate",
        "--dataset",
        s(&ds),
        "--classifier",
        "snn",
        "--folds",
        "2",
    ];
    let knobs = [
        "--snn-hidden",
        "8",
        "--snn-epochs",
        "2",
        "--snn-window-ms",
        "150",
    ];
    let run = dir.run(&[&evaluate[..], &knobs].concat());
    assert!(run.status.success(), "{}", run.stderr);
    assert!(
        run.stdout.contains("trained on 150 ms windows"),
        "{}",
        run.stdout
    );
    // 150 ms is under five membrane time constants of 40 ms.
    let note = "under five membrane time constants (200 ms)";
    assert!(run.stderr.contains(note), "{}", run.stderr);
}

/// A folder given to `predict` where recordings are expected is named as a folder, with
/// the two ways to give it.
#[test]
fn predict_on_a_folder_says_how_to_give_it() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[10.0], 3);
    let model = dir.join("m.json");
    dir.ok(&["train", "--dataset", s(&ds), "--out", s(&model)]);
    let out = dir.join("p.csv");
    let err = dir.fails(&["predict", "--model", s(&model), s(&ds), "--out", s(&out)]);
    assert!(err.contains("a folder, not a recording"), "{err}");
    assert!(err.contains("--dataset"), "{err}");
    assert!(!out.exists());
}

/// `export inputs --speeds` writes the recordings at those speeds only, and names a speed
/// the dataset lacks.
#[test]
fn export_inputs_at_some_speeds() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[5.0, 10.0], 4);
    let model = dir.join("snn.json");
    dir.train_tiny_snn(&ds, &model, &[]);
    let inputs = dir.join("inputs");
    let export = |speeds: &'static str| -> Vec<String> {
        let args = [
            "export",
            "inputs",
            "--model",
            s(&model),
            "--dataset",
            s(&ds),
        ];
        let more = ["--speeds", speeds, "--out", s(&inputs)];
        args.iter().chain(&more).map(|a| a.to_string()).collect()
    };
    fn strs(v: &[String]) -> Vec<&str> {
        v.iter().map(String::as_str).collect()
    }
    dir.ok(&strs(&export("10")));
    let index = std::fs::read_to_string(inputs.join("index.csv")).unwrap();
    assert_eq!(index.lines().count(), 1 + 2 * 4, "{index}");
    let manifest = std::fs::read_to_string(ds.join("manifest.csv")).unwrap();
    for line in index.lines().skip(1) {
        let file = line.split(',').next().unwrap();
        let row = manifest.lines().find(|l| l.starts_with(file)).unwrap();
        assert!(row.contains(",10"), "{row}");
    }
    let err = dir.fails(&strs(&export("7")));
    assert!(err.contains('7'), "{err}");
}

/// Training counts its epochs, and says where early stopping ended it: the epoch the
/// model file records, of those asked for.
#[test]
fn early_stopping_is_said_with_the_epoch_it_ended_at() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[5.0], 6);
    // Labels the recordings do not carry: the validation loss soon stops falling.
    relabel(&ds, |trial| if trial % 2 == 0 { "even" } else { "odd" });
    let model = dir.join("snn.json");
    let args = ["train", "--dataset", s(&ds), "--classifier", "snn"];
    let mut args = args.to_vec();
    args.extend([
        "--snn-hidden",
        "8",
        "--snn-epochs",
        "400",
        "--out",
        s(&model),
    ]);
    let run = dir.run(&args);
    assert!(run.status.success(), "{}", run.stderr);
    let file: Value = serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
    let epochs = file["training"]["epochs"].as_u64().unwrap();
    assert!(epochs < 400, "no early stop: {epochs}");
    let said = format!("early stopping: training ended at epoch {epochs} of 400, 15 epochs after the lowest validation loss");
    assert_eq!(run.stderr.matches(&said).count(), 1, "{}", run.stderr);
    assert!(
        run.stderr.contains("training the spiking network (epochs)"),
        "{}",
        run.stderr
    );
    assert!(!run.stderr.contains("stopped at the cap"), "{}", run.stderr);
    // Ended by the cap instead: said with the epoch of the lowest validation loss.
    let capped = ["--snn-hidden", "8", "--snn-epochs", "3", "--out", s(&model)];
    let run = dir.run(&[&args[..5], &capped[..]].concat());
    assert!(run.status.success(), "{}", run.stderr);
    let file: Value = serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
    let best = file["training"]["best_epoch"].as_u64().unwrap();
    let lowest = match best {
        3 => "still falling at the last of the 3 epochs".to_string(),
        b => format!("lowest at epoch {b} of 3"),
    };
    let said = format!("note: the validation loss was {lowest}: training stopped at the cap");
    assert_eq!(run.stderr.matches(&said).count(), 1, "{}", run.stderr);
    assert!(!run.stderr.contains("early stopping:"), "{}", run.stderr);
}

/// `--snn-travel median`: a network trained on two speeds steps in travel at their median
/// and the model file keeps it; one trained by default (`off`) steps in ms. A recording without a speed is
/// refused by the first, named, with what to do, and predicted by the second; a model
/// file whose reference speed is not the one its parameters fix is refused.
#[test]
fn a_network_in_travel_keeps_its_reference_speed_and_needs_speeds() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[10.0, 30.0], 4);
    let (travel, off) = (dir.join("travel.json"), dir.join("off.json"));
    dir.train_tiny_snn(&ds, &travel, &["--snn-travel", "median"]);
    dir.train_tiny_snn(&ds, &off, &[]);
    let file = read_json(&travel);
    assert_eq!(file["network"]["travel_mm_s"], 20.0, "{}", file["network"]);
    assert_eq!(file["classifier"]["travel"], "median");
    let in_ms = read_json(&off);
    assert!(in_ms["network"].get("travel_mm_s").is_none());
    assert!(in_ms["classifier"].get("travel").is_none());
    let manifest = std::fs::read_to_string(ds.join("manifest.csv")).unwrap();
    let no_speed: String = manifest
        .lines()
        .enumerate()
        .map(|(i, l)| match (i, l.split_once(',')) {
            (1.., Some((file, rest))) => {
                let (label, rest) = rest.split_once(',').unwrap();
                let (_, rest) = rest.split_once(',').unwrap();
                format!("{file},{label},,{rest}\n")
            }
            _ => format!("{l}\n"),
        })
        .collect();
    std::fs::write(ds.join("manifest.csv"), no_speed).unwrap();
    let out = dir.join("never.csv");
    let err = dir.fails(&predict(s(&travel), s(&out), &["--dataset", s(&ds)]));
    assert!(
        err.contains("counts time in travel") && err.contains("--snn-travel off"),
        "{err}"
    );
    assert!(!out.exists());
    let in_ms_out = dir.join("in_ms.csv");
    dir.ok(&predict(s(&off), s(&in_ms_out), &["--dataset", s(&ds)]));
    std::fs::write(ds.join("manifest.csv"), manifest).unwrap();
    let at = vec![("/classifier/travel", serde_json::json!({"at": 15.0}))];
    let differs = "`network.travel_mm_s` (20.0) differs from the training parameters (`classifier`: {\"at\":15.0})";
    refused_when_tampered(&dir, &file, &ds, &at, differs);
}

/// `predict` on the dataset a model was trained on says how many of its recordings the
/// model was fitted to, on standard error and as `trained_on` in `--json`; on other
/// recordings, or other speeds (`--speeds`), it says nothing of the kind and counts 0.
#[test]
fn predicting_the_training_recordings_is_said_to_test_nothing() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[10.0, 20.0], 4);
    // Recordings of the same textures the model has not seen: the same gratings with other
    // noise (the helper's own noise would repeat `ds`'s recordings bit for bit).
    let other = dir.dataset("other", &["A", "B"], &[10.0], 3);
    for (k, label) in ["A", "B"].iter().enumerate() {
        for trial in 0..3 {
            let period = (60.0 + 70.0 * k as f64) * 5.0 / 10.0;
            let rec = recording(1400, period, 0.2 + 0.1 * k as f64, 777 + trial);
            let file = other.join(format!("{label}_10_{trial}.npy"));
            write_npy(file, &rec).unwrap();
        }
    }
    let model = dir.join("m.json");
    let train = ["train", "--dataset", s(&ds), "--speeds", "10", "-k", "1"];
    dir.ok(&[&train[..], &["--out", s(&model)]].concat());
    let predict = |data: &Path| {
        let args = [
            "predict",
            "--model",
            s(&model),
            "--dataset",
            s(data),
            "--json",
        ];
        dir.run(&[&args[..], &["--out", s(&dir.join("p.csv"))]].concat())
    };
    let trained_on = |stdout: &str| {
        let v: serde_json::Value = serde_json::from_str(stdout).unwrap();
        v["trained_on"].as_u64().unwrap()
    };
    let seen = predict(&ds);
    assert!(seen.status.success(), "{}", seen.stderr);
    assert!(
        (seen.stderr).contains("warning: 8 of these 16 recordings are ones the model was trained on (this is its training dataset, at 10 mm/s)"),
        "{}",
        seen.stderr
    );
    assert_eq!(trained_on(&seen.stdout), 8);
    let new = predict(&other);
    assert!(new.status.success(), "{}", new.stderr);
    assert!(!new.stderr.contains("trained on"), "{}", new.stderr);
    assert_eq!(trained_on(&new.stdout), 0);
    // Without --json the accuracy is a line on standard error.
    let args = ["predict", "--model", s(&model), "--dataset", s(&other)];
    let said = dir.run(&[&args[..], &["--out", s(&dir.join("p.csv"))]].concat());
    assert!(
        said.stderr
            .contains("over 6 recordings (95 % Wilson interval); chance 50.0%")
            && !said.stderr.contains("no test of it"),
        "{}",
        said.stderr
    );
    // The same recordings in another dataset (its manifest in another order: another
    // fingerprint) are met by their features.
    let copy = dir.join("copy");
    std::fs::create_dir(&copy).unwrap();
    for entry in std::fs::read_dir(&ds).unwrap() {
        let path = entry.unwrap().path();
        std::fs::copy(&path, copy.join(path.file_name().unwrap())).unwrap();
    }
    let manifest = std::fs::read_to_string(ds.join("manifest.csv")).unwrap();
    let mut lines: Vec<&str> = manifest.lines().collect();
    lines[1..].reverse();
    std::fs::write(copy.join("manifest.csv"), lines.join("\n") + "\n").unwrap();
    let copied = predict(&copy);
    assert!(copied.status.success(), "{}", copied.stderr);
    assert!(
        (copied.stderr).contains("warning: 8 of these 16 recordings have exactly the features of recordings the model was trained on"),
        "{}",
        copied.stderr
    );
    assert_eq!(trained_on(&copied.stdout), 8);
    // --speeds predicts the dataset's recordings at those speeds only: at 20 mm/s, none the
    // model was trained on.
    let out = dir.join("at20.csv");
    let args = [
        "predict",
        "--model",
        s(&model),
        "--dataset",
        s(&ds),
        "--speeds",
        "20",
        "--json",
    ];
    let at20 = dir.run(&[&args[..], &["--out", s(&out)]].concat());
    assert!(at20.status.success(), "{}", at20.stderr);
    assert!(!at20.stderr.contains("trained on"), "{}", at20.stderr);
    assert_eq!(trained_on(&at20.stdout), 0);
    let rows: Vec<String> = (std::fs::read_to_string(&out).unwrap().lines().skip(1))
        .map(|l| l.split(',').next().unwrap().to_string())
        .collect();
    assert_eq!(rows.len(), 8);
    assert!(rows.iter().all(|f| f.contains("_20_")), "{rows:?}");
    let file = ds.join(&rows[0]);
    let never = dir.join("never.csv");
    let args = [
        "predict",
        "--model",
        s(&model),
        "--speeds",
        "20",
        "--out",
        s(&never),
    ];
    let err = dir.fails(&[&args[..], &[s(&file)]].concat());
    assert!(!never.exists());
    assert!(
        err.contains("--speeds selects recordings of a --dataset"),
        "{err}"
    );
}
