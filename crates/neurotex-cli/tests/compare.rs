//! `neurotex compare` through the binary: its JSON, the same splits as
//! `evaluate`, the files of `--out`, and bad options.

use serde_json::Value;

use crate::util::{floats, s, Dir};

/// `{"results": [{"encoding", "method", "classifier", "accuracy", "ci": [lo, hi],
/// "p_vs_paper"}, ...], "best": {...}}`, ranked, each accuracy inside its interval.
fn has_the_documented_shape(v: &Value) {
    let results = v["results"].as_array().unwrap();
    for r in results {
        for key in [
            "encoding",
            "method",
            "classifier",
            "accuracy",
            "ci",
            "p_vs_paper",
        ] {
            assert!(r.get(key).is_some(), "{key} missing in {r}");
        }
        let (acc, ci) = (r["accuracy"].as_f64().unwrap(), r["ci"].as_array().unwrap());
        assert!(ci[0].as_f64().unwrap() <= acc && acc <= ci[1].as_f64().unwrap());
    }
    assert_eq!(v["best"], results[0]);
    let accuracies: Vec<f64> = results
        .iter()
        .map(|r| r["accuracy"].as_f64().unwrap())
        .collect();
    assert!(
        accuracies.windows(2).all(|w| w[0] >= w[1]),
        "{accuracies:?}"
    );
}

#[test]
fn compare_ranks_candidates_on_the_splits_evaluate_uses() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B", "C"], &[5.0, 10.0], 10);
    let out = dir.join("cmp");
    let text = dir.ok(&[
        "compare",
        "--dataset",
        s(&ds),
        "--per",
        "speed_mm_s",
        "--repeats",
        "2",
        "--json",
        "--out",
        s(&out),
    ]);
    let v: Value = serde_json::from_str(&text).unwrap();
    let results = v["results"].as_array().unwrap();
    // 2 encodings x (the paper's taxel method with KNN, 5 feature methods x 3 classifiers,
    // van Rossum with KNN)
    assert_eq!(results.len(), 34);
    has_the_documented_shape(&v);
    // The paper's method at each speed is exactly what `evaluate` gives with the same folds.
    let paper = results.iter().find(|r| r["paper"] == true).unwrap();
    assert_eq!(paper["p_vs_paper"], Value::Null);
    for (i, speed) in ["5", "10"].iter().enumerate() {
        let e = dir.evaluate_json(&ds, "glcm3d", &["--speeds", speed, "--repeats", "2"]);
        let at = &paper["per_condition"][i];
        assert_eq!(at["condition"], *speed);
        assert_eq!(at["accuracy"], e["accuracy"], "speed {speed}");
    }
    let of = |encoding: &str, method: &str, classifier: &str| {
        let found = results.iter().find(|r| {
            (r["encoding"] == encoding) && r["method"] == method && r["classifier"] == classifier
        });
        found.unwrap().clone()
    };
    let forest = of("sa+fa", "all-taxels", "forest");
    let e = dir.evaluate_json(
        &ds,
        "all-taxels",
        &[
            "--speeds",
            "10",
            "--repeats",
            "2",
            "--encoding",
            "sa+fa",
            "--classifier",
            "forest",
        ],
    );
    assert_eq!(forest["per_condition"][1]["accuracy"], e["accuracy"]);
    let timing = of("sa", "van-rossum", "knn");
    let e = dir.evaluate_json(&ds, "van-rossum", &["--speeds", "5", "--repeats", "2"]);
    assert_eq!(timing["per_condition"][0]["accuracy"], e["accuracy"]);
    assert_eq!(e["method"], "van-rossum");
    let taxel = of("sa", "taxel", "knn");
    let e = dir.evaluate_json(&ds, "taxel", &["--speeds", "5", "--repeats", "2"]);
    assert_eq!(taxel["per_condition"][0]["accuracy"], e["accuracy"]);
    for file in ["compare.json", "compare.md", "ranking.svg"] {
        assert!(out.join(file).exists(), "{file}");
    }
    // each figure as PNG beside its SVG
    let png = std::fs::read(out.join("ranking.png")).unwrap();
    assert!(png.starts_with(b"\x89PNG\r\n\x1a\n"), "ranking.png");
    let md = std::fs::read_to_string(out.join("compare.md")).unwrap();
    assert!(
        md.contains("paper's method") && md.contains("Caveat"),
        "{md}"
    );
    // the folds, repeats and seed the ranking rests on
    assert!(md.contains(", seed 0; "), "{md}");
}

#[test]
fn nested_selection_over_held_out_speeds_names_its_choices() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[5.0, 10.0, 15.0], 6);
    let text = dir.ok(&[
        "compare",
        "--dataset",
        s(&ds),
        "--hold-out",
        "speed_mm_s",
        "--methods",
        "glcm2d,glcm3d,van-rossum",
        "--nested",
    ]);
    assert!(text.contains("held out in turn"), "{text}");
    assert!(text.contains("sa / van-rossum / knn"), "{text}");
    assert!(
        text.contains("nested selection:") && text.contains("of 3)"),
        "{text}"
    );
    assert!(
        text.contains("one split per held-out value, seed 0; 2000 resamples for intervals and tests; nested selection ranks inside each training set, each of its other values held out in turn"),
        "{text}"
    );
    assert!(
        text.contains("paper's method") && text.contains("caveat"),
        "{text}"
    );
    // Within each speed, an outer training set holds 4 or 5 recordings of a class: the
    // inner cross-validation uses fewer folds rather than failing.
    let text = dir.ok(&[
        "compare",
        "--dataset",
        s(&ds),
        "--per",
        "speed_mm_s",
        "--methods",
        "glcm3d,all-taxels",
        "--nested",
    ]);
    assert!(text.contains("over 15 outer splits"), "{text}");
}

#[test]
fn baselines_without_spikes_join_the_ranking_on_the_same_folds() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B", "C"], &[5.0, 10.0], 6);
    let text = dir.ok(&[
        "compare",
        "--dataset",
        s(&ds),
        "--per",
        "speed_mm_s",
        "--encodings",
        "none,sa",
        "--methods",
        "spectrum",
        "--classifiers",
        "knn,linear",
        "--json",
    ]);
    let v: Value = serde_json::from_str(&text).unwrap();
    has_the_documented_shape(&v);
    let mut names: Vec<String> = v["results"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| format!("{}/{}/{}", r["encoding"], r["method"], r["classifier"]).replace('"', ""))
        .collect();
    names.sort();
    // --methods applies to the spike encodings; `none` brings both baselines.
    assert_eq!(
        names,
        [
            "none/signal-stats/knn",
            "none/signal-stats/linear",
            "none/spectrum/knn",
            "none/spectrum/linear",
            "sa/spectrum/knn",
            "sa/spectrum/linear"
        ]
    );
    // Baselines alone need no encoding.
    let alone = dir.ok(&[
        "compare",
        "--dataset",
        s(&ds),
        "--encodings",
        "none",
        "--json",
    ]);
    let v: Value = serde_json::from_str(&alone).unwrap();
    assert_eq!(v["results"].as_array().unwrap().len(), 6);
}

#[test]
fn a_spectrum_span_longer_than_a_slide_names_the_recording_and_the_option() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[5.0, 10.0], 4);
    // Recordings are read in parallel: whichever fails first is named.
    for encodings in ["sa", "none"] {
        let err = dir.fails(&[
            "compare",
            "--dataset",
            s(&ds),
            "--encodings",
            encodings,
            "--methods",
            "spectrum",
            "--travel-mm",
            "100000",
        ]);
        assert!(
            err.contains("--travel-mm 100000") && err.contains(".npy: "),
            "{encodings}: {err}"
        );
    }
}

#[test]
fn bad_compare_options_are_clear_errors() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[5.0], 6);
    let out = dir.join("never");
    let base = ["compare", "--dataset", s(&ds), "--out", s(&out)];
    let with = |extra: &[&'static str]| -> Vec<&str> {
        base.iter().copied().chain(extra.iter().copied()).collect()
    };
    dir.fails_each(
        &[
            (with(&["--methods", "glcm9d"]), "glcm9d"),
            (with(&["--classifiers", "svm"]), "svm"),
            (with(&["--encodings", "xy"]), "xy"),
            (with(&["--spectrum-bins", "4"]), "spectrum-bins"),
            (with(&["--spectrum-bands", "0"]), "spectrum-bands"),
            (with(&["--per", "session"]), "session"),
            (with(&["--per", "speed_mm_s"]), "at least two values"),
            (with(&["--inner-folds", "3"]), "--nested"),
            (with(&["--nested", "--inner-folds", "1"]), "2 folds or more"),
        ],
        &out,
    );
}

#[test]
fn a_misspelt_protocol_column_is_named_before_any_recording_is_encoded() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[5.0, 10.0], 4);
    let err = dir.fails(&["compare", "--dataset", s(&ds), "--hold-out", "sped_mm_s"]);
    assert!(
        err.contains("sped_mm_s") && err.contains("columns with values: "),
        "{err}"
    );
    assert!(
        !err.contains("encoding") && !err.contains("comparing"),
        "{err}"
    );
}

#[test]
fn nested_selection_too_small_for_its_inner_folds_stops_before_any_candidate_runs() {
    let dir = Dir::new();
    // Two recordings per class at each speed: 2 folds leave one per class in each outer
    // training set, too few for the inner cross-validation.
    let ds = dir.dataset("pilot", &["A", "B", "C"], &[5.0, 10.0], 2);
    let base = ["compare", "--dataset", s(&ds), "--folds", "2", "--k", "1"];
    let err = dir.fails(&[&base[..], &["--nested", "--per", "speed_mm_s"]].concat());
    assert!(
        err.contains("every class needs at least 2 recordings there")
            && err.contains("speed_mm_s = 5"),
        "{err}"
    );
    assert!(!err.contains("candidates ("), "no candidate scored: {err}");
    // Without --nested the caveat's nested estimate is named as an option.
    let run = dir.run(&base);
    assert!(run.status.success(), "{}", run.stderr);
    assert!(
        run.stderr.contains("was not computed (add --nested)"),
        "{}",
        run.stderr
    );
}

#[test]
fn gain_auto_calibrates_on_the_training_side_of_a_split_and_says_so_otherwise() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B", "C"], &[5.0, 10.0], 10);
    let base = [
        "compare",
        "--dataset",
        s(&ds),
        "--gain",
        "auto",
        "--methods",
        "all-taxels",
        "--classifiers",
        "knn",
    ];
    // 30 recordings at 5 mm/s train; the 30 at 10 mm/s are never read by the calibration.
    let split = dir.run(
        &[
            &base[..],
            &[
                "--train-where",
                "speed_mm_s=5",
                "--test-where",
                "speed_mm_s=10",
            ],
        ]
        .concat(),
    );
    assert!(split.status.success(), "{}", split.stderr);
    assert!(
        split
            .stderr
            .contains("in the 30 recordings it calibrated on"),
        "{}",
        split.stderr
    );
    assert!(
        !split.stderr.contains("test folds included"),
        "{}",
        split.stderr
    );
    let cv = dir.run(&[&base[..], &["--per", "speed_mm_s"]].concat());
    assert!(cv.status.success(), "{}", cv.stderr);
    assert!(cv.stderr.contains("test folds included"), "{}", cv.stderr);
}

/// compare.md and compare.json say how the ranking was made: the build, the command, the
/// data's fingerprint and the stages as they ran, the gain `--gain auto` chose among them.
#[test]
fn the_outputs_record_the_command_the_data_and_the_gain_chosen() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[5.0, 10.0], 6);
    let out = dir.join("cmp");
    let args = [
        "--methods",
        "glcm3d",
        "--classifiers",
        "knn",
        "--encodings",
        "sa",
    ];
    let text = dir.ok(&[
        &["compare", "--dataset", s(&ds), "--gain", "auto", "--json"][..],
        &args,
        &["--out", s(&out)],
    ]
    .concat());
    let v: Value = serde_json::from_str(&text).unwrap();
    let lines: Vec<&str> = v["provenance"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l.as_str().unwrap())
        .collect();
    assert!(lines[0].starts_with("neurotex "), "{lines:?}");
    assert!(
        lines[1].starts_with("command: neurotex compare --dataset") && lines[1].contains("glcm3d"),
        "{lines:?}"
    );
    assert!(
        lines.iter().any(|l| l.starts_with("data: sha256:")),
        "{lines:?}"
    );
    // Only the encodings and methods compared, and where the gain was calibrated.
    assert!(lines.contains(&"encodings: sa"), "{lines:?}");
    assert!(
        !lines.iter().any(|l| l.starts_with("spectrum:")),
        "{lines:?}"
    );
    assert!(lines.iter().any(|l| l.starts_with("phase: ")), "{lines:?}");
    let cv = "under cross-validation they are drawn from all the recordings evaluated, test folds included (labels unused)";
    assert!(lines.iter().any(|l| l.ends_with(cv)), "{lines:?}");
    // The gain the encoder ran with is the one the calibration chose.
    let chosen = lines
        .iter()
        .find_map(|l| l.strip_prefix("--gain auto: G = "))
        .unwrap();
    let gain = chosen.split(' ').next().unwrap();
    assert!(
        lines
            .iter()
            .any(|l| l.starts_with("encoder:") && l.ends_with(&format!("gain G = {gain}"))),
        "{lines:?}"
    );
    let md = std::fs::read_to_string(out.join("compare.md")).unwrap();
    assert!(md.contains("## Provenance\n\n- neurotex "), "{md}");
    assert!(md.contains(&format!("- {}\n", lines[1])), "{md}");
}

#[test]
fn the_spiking_network_runs_in_compare_and_evaluate_on_the_same_folds() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B", "C"], &[10.0], 10);
    let text = dir.ok(&[
        "compare",
        "--dataset",
        s(&ds),
        "--methods",
        "spikes,all-taxels",
        "--classifiers",
        "linear",
        "--encodings",
        "sa+fa",
        "--snn-epochs",
        "20",
        "--json",
    ]);
    let v: Value = serde_json::from_str(&text).unwrap();
    let results = v["results"].as_array().unwrap();
    // all-taxels with linear, spikes with the network (added by the spikes method)
    assert_eq!(results.len(), 2, "{text}");
    let snn = results.iter().find(|r| r["method"] == "spikes").unwrap();
    assert_eq!(snn["classifier"], "snn");
    // The network's settings are recorded with the ranking, as the folds are.
    let design = v["design"].as_str().unwrap();
    assert!(
        design.contains("; snn: spiking network (128 LIF"),
        "{design}"
    );
    assert!(design.ends_with(", given --snn-epochs 20"), "{design}");
    let accuracy = snn["accuracy"].as_f64().unwrap();
    // Three simulated textures at one speed, 10 trials each: well above the 1/3 chance.
    assert!(accuracy > 0.6, "{accuracy}");
    let e = dir.evaluate_json(
        &ds,
        "spikes",
        &[
            "--classifier",
            "snn",
            "--encoding",
            "sa+fa",
            "--snn-epochs",
            "20",
        ],
    );
    assert_eq!(e["method"], "spikes");
    assert_eq!(snn["accuracy"], e["accuracy"]);
}

#[test]
fn the_spiking_network_options_are_checked() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[5.0], 6);
    let out = dir.join("never");
    let cmp = |extra: &[&'static str]| -> Vec<&str> {
        let base = ["compare", "--dataset", s(&ds), "--out", s(&out)];
        base.iter().copied().chain(extra.iter().copied()).collect()
    };
    let eval = |extra: &[&'static str]| -> Vec<&str> {
        let base = ["evaluate", "--dataset", s(&ds)];
        base.iter().copied().chain(extra.iter().copied()).collect()
    };
    let model = dir.join("never.json");
    // One recording per class: nothing left to train on once one is set aside for
    // validation.
    let tiny = dir.dataset("tiny", &["A", "B"], &[5.0], 1);
    let train = |extra: &[&'static str]| -> Vec<&str> {
        let base = ["train", "--dataset", s(&tiny), "--out", s(&model)];
        base.iter().copied().chain(extra.iter().copied()).collect()
    };
    dir.fails_each(
        &[
            (cmp(&["--classifiers", "snn"]), "add spikes to --methods"),
            (
                cmp(&["--snn-epochs", "3"]),
                "--snn-epochs applies only to the spiking network (`spikes` in --methods",
            ),
            (
                cmp(&["--methods", "spikes", "--snn-hidden", "0"]),
                "snn-hidden",
            ),
            (
                cmp(&["--methods", "spikes", "--snn-dt-ms", "0"]),
                "snn-dt-ms",
            ),
            (
                cmp(&["--methods", "spikes", "--snn-readout", "last"]),
                "mean or max",
            ),
            (
                eval(&["--method", "spikes", "--classifier", "forest"]),
                "spikes with snn",
            ),
            (
                eval(&["--method", "glcm3d", "--classifier", "snn"]),
                "spikes with snn",
            ),
            (
                eval(&["--method", "glcm3d", "--snn-epochs", "3"]),
                "--classifier snn",
            ),
            (
                train(&["--classifier", "snn"]),
                "class `A` has 1 training recording",
            ),
        ],
        &out,
    );
}

/// Pooled cross-validation over several speeds says so and names the per-speed and
/// held-out protocols; within each speed it says nothing of the kind.
#[test]
fn pooling_speeds_is_said_with_the_protocols_that_separate_them() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[10.0, 20.0], 4);
    let args = [
        "compare",
        "--dataset",
        s(&ds),
        "--methods",
        "rates",
        "--classifiers",
    ];
    let args = [&args[..], &["linear", "--encodings", "sa", "--folds", "2"]].concat();
    let pooled = dir.run(&args);
    assert!(pooled.status.success(), "{}", pooled.stderr);
    let note = "recordings at 2 speeds are cross-validated together";
    assert!(pooled.stderr.contains(note), "{}", pooled.stderr);
    assert!(
        pooled.stderr.contains("--per speed_mm_s"),
        "{}",
        pooled.stderr
    );
    let per = dir.run(&[&args[..], &["--per", "speed_mm_s"]].concat());
    assert!(per.status.success(), "{}", per.stderr);
    assert!(!per.stderr.contains(note), "{}", per.stderr);
}

/// The text ranking names its columns, says why a difference from the paper's method is
/// missing, and with nested selection its caveat points at the estimate it gave.
#[test]
fn the_text_ranking_names_its_columns_and_its_caveat_fits_the_protocol() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[10.0], 6);
    let args = ["compare", "--dataset", s(&ds), "--methods", "rates"];
    let args = [&args[..], &["--classifiers", "linear", "--encodings", "sa"]].concat();
    let nested = dir.ok(&[&args[..], &["--folds", "2", "--nested"]].concat());
    assert!(
        nested.contains("accuracy [95% CI]") && nested.contains("vs paper (paired test)"),
        "{nested}"
    );
    assert!(nested.contains("not among the candidates"), "{nested}");
    assert!(nested.contains("nested selection: "), "{nested}");
    assert!(
        !nested.contains("when nested selection is asked for"),
        "{nested}"
    );
    let plain = dir.ok(&[&args[..], &["--folds", "2"]].concat());
    assert!(
        plain.contains("when nested selection is asked for"),
        "{plain}"
    );
}

#[test]
fn encoder_draws_give_each_spike_candidate_its_accuracy_over_encodings() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B", "C"], &[5.0, 10.0], 6);
    let run = |draws: &str, json: bool| {
        let mut args = vec![
            "compare",
            "--dataset",
            s(&ds),
            "--per",
            "speed_mm_s",
            "--encodings",
            "none,sa",
            "--methods",
            "glcm3d,rates",
            "--classifiers",
            "knn",
            "--repeats",
            "1",
            "--encoder-draws",
            draws,
        ];
        if json {
            args.push("--json");
        }
        dir.ok(&args)
    };
    let three: Value = serde_json::from_str(&run("3", true)).unwrap();
    has_the_documented_shape(&three);
    let plain: Value = serde_json::from_str(&run("1", true)).unwrap();
    let rows = three["results"].as_array().unwrap();
    for (row, as_run) in rows.iter().zip(plain["results"].as_array().unwrap()) {
        // The ranking is that of the encoding as run.
        for key in ["encoding", "method", "accuracy", "ci", "p_vs_paper"] {
            assert_eq!(row[key], as_run[key], "{key}");
        }
        assert!(as_run.get("over_encodings").is_none());
        let Some(over) = row.get("over_encodings") else {
            assert_eq!(row["encoding"], "none", "{row}");
            continue;
        };
        let accuracies = floats(&over["accuracies"]);
        assert_eq!(accuracies.len(), 3);
        assert_eq!(accuracies[0], row["accuracy"].as_f64().unwrap());
        let mean = over["mean"].as_f64().unwrap();
        assert!((mean - accuracies.iter().sum::<f64>() / 3.0).abs() < 1e-12);
        let [lower, upper] = [0, 1].map(|k| over["ci"][k].as_f64().unwrap());
        assert!(lower <= accuracies[0] && accuracies[0] <= upper, "{over}");
        assert_eq!(over["perturbation"], 1e-12);
    }
    assert_eq!(rows.iter().filter(|r| r["encoding"] == "sa").count(), 2);
    // The same encodings and numbers on every run.
    let again: Value = serde_json::from_str(&run("3", true)).unwrap();
    let overs = |v: &Value| -> Vec<Value> {
        let rows = v["results"].as_array().unwrap();
        rows.iter().map(|r| r["over_encodings"].clone()).collect()
    };
    assert_eq!(overs(&again), overs(&three));
    let text = run("3", false);
    assert!(
        text.contains(
            "over 3 encodings (the input as run, whose accuracy the ranking shows, and 2 with"
        ),
        "{text}"
    );
    let err = dir.fails(&["compare", "--dataset", s(&ds), "--encoder-draws", "0"]);
    assert!(err.contains("--encoder-draws"), "{err}");
}
