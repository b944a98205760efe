//! `--classifier knn|forest|linear` on `evaluate` and `train`: the forest evaluated on a
//! simulated dataset, a logistic regression trained, saved and applied by `predict`, and
//! the options that belong to another classifier.

use serde_json::Value;

use crate::util::{s, Dir};

/// Simulates `name`: FT1, SB and CP x 6 trials at 5 mm/s with `seed`.
fn simulated(dir: &Dir, name: &str, seed: &str) -> std::path::PathBuf {
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

#[test]
fn evaluate_with_a_forest_is_seeded_and_classifies() {
    let dir = Dir::new();
    let a = simulated(&dir, "A", "1");
    let args = ["--classifier", "forest", "--trees", "50", "--folds", "3"];
    let forest = dir.evaluate_json(&a, "glcm3d", &args);
    let accuracy = forest["accuracy"].as_f64().unwrap();
    assert!(accuracy > 0.6, "chance is 1/3, got {accuracy}");
    assert_eq!(forest["n"], 18);
    let again = dir.evaluate_json(&a, "glcm3d", &args);
    assert_eq!(again["confusion"], forest["confusion"], "seeded");
    let text = dir.ok(&[
        "evaluate",
        "--dataset",
        s(&a),
        "--method",
        "glcm3d",
        "--classifier",
        "linear",
        "--c",
        "0.5",
    ]);
    assert!(text.contains("accuracy"), "{text}");
}

#[test]
fn a_linear_model_is_trained_saved_and_applied() {
    let dir = Dir::new();
    let (a, b) = (simulated(&dir, "A", "1"), simulated(&dir, "B", "2"));
    let model = dir.join("linear.json");
    let run = dir.run(&[
        "train",
        "--dataset",
        s(&a),
        "--classifier",
        "linear",
        "--out",
        s(&model),
    ]);
    assert!(run.status.success(), "{}", run.stderr);
    assert!(
        run.stderr.contains("logistic regression (C = 1)"),
        "{}",
        run.stderr
    );
    let file: Value = serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
    assert_eq!(
        file["classifier"],
        serde_json::json!({"kind": "linear", "c": 1.0, "max_iter": 1000, "tol": 1e-8})
    );
    let out = dir.join("predictions.csv");
    let json = dir.ok(&[
        "predict",
        "--model",
        s(&model),
        "--dataset",
        s(&b),
        "--out",
        s(&out),
        "--json",
    ]);
    let score: Value = serde_json::from_str(&json).unwrap();
    let accuracy = score["accuracy"].as_f64().unwrap();
    assert!(accuracy > 0.6, "chance is 1/3, got {accuracy}");
    assert_eq!(score["chance"].as_f64(), Some(1.0 / 3.0));
    let interval = &score["interval"];
    assert_eq!(interval["method"], "wilson", "{json}");
    let (lower, upper) = (interval["lower"].as_f64(), interval["upper"].as_f64());
    assert!(
        lower.unwrap() < accuracy && accuracy <= upper.unwrap(),
        "{json}"
    );
    let text = std::fs::read_to_string(&out).unwrap();
    let mut rows = text.lines();
    assert_eq!(
        rows.next().unwrap(),
        "file,label,predicted,share_FT1,share_SB,share_CP"
    );
    let mut fractional = 0;
    for row in rows {
        let shares: Vec<f64> = row.split(',').skip(3).map(|v| v.parse().unwrap()).collect();
        assert!((shares.iter().sum::<f64>() - 1.0).abs() < 1e-12, "{row}");
        // Probabilities, not votes over k = 5.
        fractional += usize::from(shares.iter().any(|v| (v * 5.0).fract().abs() > 1e-9));
    }
    assert!(fractional > 0, "{text}");
}

#[test]
fn options_of_another_classifier_are_refused() {
    let dir = Dir::new();
    let a = simulated(&dir, "A", "1");
    let out = dir.join("m.json");
    let train = |extra: &[&'static str]| {
        let mut args = vec!["train", "--dataset", s(&a), "--out", s(&out)];
        args.extend_from_slice(extra);
        args
    };
    let cases = [
        (
            train(&["--classifier", "svm"]),
            "classifier must be knn, forest, linear or snn",
        ),
        (
            train(&["--trees", "10"]),
            "--trees applies only to --classifier forest",
        ),
        (
            train(&["--classifier", "forest", "--c", "2"]),
            "applies only to --classifier linear",
        ),
        (
            train(&["--classifier", "forest", "--trees", "0"]),
            "trees must be at least 1",
        ),
        (
            train(&["--classifier", "linear", "--c", "0"]),
            "C must be positive",
        ),
        (
            train(&["--classifier", "snn", "--bootstrap", "false"]),
            "--bootstrap applies only to --classifier forest",
        ),
        (
            train(&["--classifier", "linear", "-k", "3"]),
            "-k applies only to --classifier knn",
        ),
        (
            train(&["--classifier", "forest", "--bootstrap", "maybe"]),
            "expected true or false, got `maybe`",
        ),
    ];
    dir.fails_each(&cases, &out);
}
