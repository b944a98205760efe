//! `neurotex reproduce` on a dataset folder.

use std::path::Path;

use serde_json::Value;

use crate::util::{s, Dir};

#[test]
fn reproduce_on_a_dataset_writes_report_json_and_figures() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B", "C"], &[5.0, 10.0], 6);
    let out = dir.join("report");
    // a quick run on a dataset; returns its results.json
    let reproduce = |ds: &Path, out: &Path, more: &[&str]| -> Value {
        let args = ["reproduce", "--dataset", s(ds), "--out", s(out), "--quick"];
        dir.ok(&[&args[..], more].concat());
        serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap()).unwrap()
    };
    let json = reproduce(&ds, &out, &[]);
    for speed in ["5", "10"] {
        for key in ["taxel_mean", "taxel_best", "glcm3d"] {
            let v = json["e1"][speed][key].as_f64().unwrap();
            assert!((0.0..=1.0).contains(&v), "e1 {speed} {key} = {v}");
        }
        for key in ["taxel_mean", "glcm2d", "glcm3d"] {
            assert!(
                json["e4"][speed][key].as_f64().is_some(),
                "e4 {speed} {key}"
            );
        }
        for key in ["taxel_mean", "glcm3d"] {
            assert!(
                json["e6"][speed][key].as_f64().is_some(),
                "e6 {speed} {key}"
            );
        }
        assert!(json["e5"][speed]["glcm3d"].is_array());
        assert!(json["e8"][speed]["glcm3d"].is_array());
    }
    assert!(json["e3"]["mean"].is_array() && json["e7"]["sweep"]["counts"].is_array());
    for key in ["prepare", "e1", "e3", "e5", "e7", "e8"] {
        assert!(json["timing_s"][key].as_f64().is_some(), "timing {key}");
    }
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains("(E1)\n") && report.contains("| 5 |") && report.contains("paper"));
    // E1, E4 and E6 over the default eight encodings, with the section that explains them
    let encodings = &json["encoder_sensitivity"];
    assert_eq!(encodings["encodings"], 8);
    assert_eq!(json["e1"]["5"]["encodings"], 8);
    assert_eq!(json["e6"]["5"]["encodings"], 8);
    let over = encodings["speeds"]["5"]["glcm3d"]["per_encoding"]
        .as_array()
        .unwrap();
    assert_eq!(over.len(), 8);
    assert!(report.contains("## The encoder's sensitivity"));
    assert!(!report.contains("IzhikevichParams"), "no Rust debug output");
    for fig in [
        "e0_psth_volume",
        "e1_accuracy",
        "e2_confusion",
        "e3_perturbation",
        "e5_time_to_recognition",
        "e7_isi",
    ] {
        let svg = std::fs::read_to_string(out.join("figures").join(format!("{fig}.svg"))).unwrap();
        assert!(
            svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"),
            "{fig}"
        );
        // the dataset folder's name on the figure, and the same figure as PNG beside it
        assert!(svg.contains(">\nds\n<"), "{fig}: the dataset's name");
        let png = std::fs::read(out.join("figures").join(format!("{fig}.png"))).unwrap();
        assert!(png.starts_with(b"\x89PNG\r\n\x1a\n"), "{fig}.png");
    }
    // one speed only: E6 is skipped with a reason, not an error
    let one = dir.dataset("one", &["A", "B"], &[5.0], 5);
    let json = reproduce(&one, &dir.join("r1"), &["--encoder-draws", "1"]);
    assert!(json.get("encoder_sensitivity").is_none());
    assert_eq!(json["e1"]["5"]["encodings"], 1);
    assert!(json["skipped"]["e6"]
        .as_str()
        .unwrap()
        .contains("one speed"));
}

#[test]
fn reproduce_over_simulator_seeds_reports_each_accuracy_over_datasets() {
    let dir = Dir::new();
    let run = |out: &str, seeds: &str| -> Value {
        let out = dir.join(out);
        let args = ["reproduce", "--quick", "--trials", "5", "--seed", "3"];
        dir.ok(&[&args[..], &["--seeds", seeds, "--out", s(&out)]].concat());
        serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap()).unwrap()
    };
    let one = run("one", "1");
    let two = run("two", "2");
    assert!(one.get("across_seeds").is_none(), "one dataset, no table");
    // The first dataset's analyses do not depend on how many further datasets ran.
    assert_eq!(one["e1"], two["e1"]);
    let across = &two["across_seeds"];
    assert_eq!(across["seeds"], serde_json::json!([3, 4]));
    let rows = across["accuracies"].as_array().unwrap();
    let e1 = rows
        .iter()
        .find(|r| r["analysis"] == "E1" && r["method"] == "3D-GLCM" && r["condition"] == "5 mm/s")
        .expect("E1 3D-GLCM at 5 mm/s");
    let values: Vec<f64> = serde_json::from_value(e1["values"].clone()).unwrap();
    assert_eq!(values.len(), 2);
    assert_eq!(values[0], two["e1"]["5"]["glcm3d"].as_f64().unwrap());
    let mean = (values[0] + values[1]) / 2.0;
    assert!((e1["interval"]["estimate"].as_f64().unwrap() - mean).abs() < 1e-12);
    for claim in across["claims"].as_array().unwrap() {
        assert_eq!(claim["verdicts"].as_array().unwrap().len(), 2);
    }
    let report = std::fs::read_to_string(dir.join("two").join("report.md")).unwrap();
    assert!(report.contains("## Across simulated datasets") && report.contains("seeds 4"));
}

#[test]
fn reproduce_rejects_seeds_it_cannot_run() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[5.0], 5);
    let out = dir.join("r");
    dir.fails_each(
        &[
            (
                vec!["reproduce", "--out", s(&out), "--seeds", "0"],
                "--seeds",
            ),
            (
                vec!["reproduce", "--out", s(&out), "--encoder-draws", "0"],
                "--encoder-draws",
            ),
            (
                vec!["reproduce", "--out", s(&out), "--encoder-draws", "101"],
                "--encoder-draws",
            ),
            (
                vec![
                    "reproduce",
                    "--out",
                    s(&out),
                    "--seeds",
                    "2",
                    "--dataset",
                    s(&ds),
                ],
                "--dataset",
            ),
            (
                vec![
                    "reproduce",
                    "--out",
                    s(&out),
                    "--seeds",
                    "3",
                    "--seed",
                    "18446744073709551614",
                ],
                "overflows",
            ),
            (
                vec![
                    "reproduce",
                    "--out",
                    s(&out),
                    "--trials",
                    "3",
                    "--dataset",
                    s(&ds),
                ],
                "--trials and --seeds apply to the built-in simulator",
            ),
        ],
        &out,
    );
}

#[test]
fn reproduce_group_by_keeps_groups_in_folds_and_names_a_missing_column() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B", "C"], &[5.0, 10.0], 6);
    let out = dir.join("grouped");
    let predictions = dir.join("predictions.csv");
    let run = dir.run(&[
        "reproduce",
        "--dataset",
        s(&ds),
        "--quick",
        "--group-by",
        "trial",
        "--out",
        s(&out),
        "--predictions",
        s(&predictions),
    ]);
    assert!(run.status.success(), "{}", run.stderr);
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        report.contains("keeping each `trial` group in one fold"),
        "parameters line"
    );
    // Each recording is predicted once per repeat at its speed, and the recordings of one
    // trial (the group: `{label}_{speed}_{trial}.npy`) share one fold.
    let text = std::fs::read_to_string(&predictions).unwrap();
    let mut lines = text.lines();
    let header = "speed_mm_s,method,file,label,predicted,fold,repeat";
    assert_eq!(lines.next(), Some(header));
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(
        rows.len(),
        3 * 2 * 6 * 2,
        "3 classes x 2 speeds x 6 trials x 2 repeats"
    );
    let mut fold_of = std::collections::HashMap::new();
    for r in &rows {
        let trial = r[2].trim_end_matches(".npy").rsplit('_').next().unwrap();
        let key = (r[0], r[6], trial);
        let fold = *fold_of.entry(key).or_insert(r[5]);
        assert_eq!(fold, r[5], "{key:?} split over folds");
    }
    let missing = dir.join("missing");
    dir.fails_each(
        &[(
            vec![
                "reproduce",
                "--dataset",
                s(&ds),
                "--quick",
                "--group-by",
                "session",
                "--out",
                s(&missing),
            ],
            "session",
        )],
        &missing,
    );
}

#[test]
fn a_twelve_recording_pilot_runs_skipping_what_its_design_cannot_support() {
    let dir = Dir::new();
    // 3 classes x 2 speeds x 2 trials: two recordings per class at each speed.
    let ds = dir.dataset("pilot", &["A", "B", "C"], &[5.0, 10.0], 2);
    let out = dir.join("report");
    let base = [
        "reproduce",
        "--dataset",
        s(&ds),
        "--out",
        s(&out),
        "--quick",
    ];
    let read = |name: &str| std::fs::read_to_string(out.join(name)).unwrap();
    // Too few recordings for 5 folds: the analyses resting on the cross-validation within a
    // speed are skipped, saying why and what to change, and the rest run (E6 trains on one
    // speed and tests on the other: no folds).
    let run = dir.run(&base);
    assert!(run.status.success(), "{}", run.stderr);
    for said in [
        "warning: E1-E5, E5c, E8, E9 and the encoder's sensitivity rest on",
        "fewer than the 5 folds",
        "hint: --folds",
        "skipped: e1, accuracy at each speed",
        "skipped: e9",
        "done: e6",
        "done: e0",
    ] {
        assert!(run.stderr.contains(said), "{said}: {}", run.stderr);
    }
    let report = read("report.md");
    assert!(
        report.contains("# neurotex analyses of a tactile dataset"),
        "{report}"
    );
    assert!(
        report.contains("layout.toml: baseline removed: none."),
        "the layout said: {report}"
    );
    assert!(
        report.contains("(E1)\n\nSkipped, with 8 other analyses"),
        "{report}"
    );
    assert!(
        report.contains("- e1, e2, e3, e4, e5, e5c, e8, e9, encoder sensitivity: at 5 mm/s"),
        "{report}"
    );
    assert!(report.contains("| 5 | 10 |"), "E6's table: {report}");
    assert!(
        !out.join("figures/e1_accuracy.svg").exists(),
        "no empty figure"
    );
    // With 2 folds, the training folds hold 3 recordings, fewer than k = 5: checked on the
    // manifest before any recording is read, naming the speed and what the design supports.
    let run = dir.run(&[&base[..], &["--folds", "2"]].concat());
    assert!(run.status.success(), "{}", run.stderr);
    let warned = run.stderr.split("recordings (12 steps)").next().unwrap();
    for said in [
        "at 5 mm/s",
        "at most 2 folds, and with 2 folds at most 3 neighbours",
        "k = 5 neighbours needs at least 5 training samples, got 3",
        "hint: --k",
    ] {
        assert!(warned.contains(said), "{said}: {}", run.stderr);
    }
    assert_eq!(
        run.stderr.matches("got 3").count(),
        1,
        "said once: {}",
        run.stderr
    );
    let json: Value = serde_json::from_str(&read("results.json")).unwrap();
    assert!(json
        .get("e1")
        .is_none_or(|e1| e1.as_object().is_some_and(|m| m.is_empty())));
    assert!(
        json["skipped"]["e1"].as_str().unwrap().contains("got 3"),
        "{json}"
    );
    assert!(json["e6"]["5"].is_object(), "{json}");
    // Under --group-by the folds follow the groups and are checked where they are made:
    // the analyses are skipped all the same, with the speed named.
    let run = dir.run(&[&base[..], &["--folds", "2", "--group-by", "trial"]].concat());
    assert!(run.status.success(), "{}", run.stderr);
    assert!(run.stderr.contains("skipped: e1"), "{}", run.stderr);
    let json: Value = serde_json::from_str(&read("results.json")).unwrap();
    assert!(
        json["skipped"]["e1"]
            .as_str()
            .unwrap()
            .contains("at 5 mm/s"),
        "{json}"
    );
    let run = dir.run(&[&base[..], &["--folds", "2", "--k", "3", "--repeats", "1"]].concat());
    assert!(
        run.status.success(),
        "the largest k said fits: {}",
        run.stderr
    );
    let run = dir.run(&[&base[..], &["--folds", "2", "--k", "1", "--repeats", "1"]].concat());
    assert!(run.status.success(), "{}", run.stderr);
    // Standard error is not a terminal here: every analysis is said as it ends.
    for said in [
        "recordings (12 steps)",
        "done: e1, accuracy at each speed",
        "done: e9",
    ] {
        assert!(run.stderr.contains(said), "{said}: {}", run.stderr);
    }
    let json: Value = serde_json::from_str(&read("results.json")).unwrap();
    assert!(json["e1"]["5"]["glcm3d"].as_f64().is_some());
    assert!(
        json.get("skipped").is_none_or(|s| s.get("e1").is_none()),
        "{json}"
    );
    let report = read("report.md");
    assert!(
        report.contains("2-fold"),
        "the report states the folds used"
    );
}
