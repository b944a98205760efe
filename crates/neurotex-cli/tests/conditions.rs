//! Manifest columns as conditions: optional speed, force and trial; every column carried
//! into `features`; train/test splits on any column; silent and saturated taxels named.

use std::path::Path;

use ndarray::Array3;
use ndarray_npy::{read_npy, write_npy};
use serde_json::Value;

use crate::util::{s, Dir};

/// A manifest column computed from a row of the one `Dir::dataset` wrote: name and value.
type Computed<'a> = (&'a str, fn(&[&str]) -> String);

/// Replaces a dataset's manifest by `columns` of the one `Dir::dataset` wrote, plus the
/// columns `extra` computes from each row (`file,label,speed_mm_s,force_n,trial,...`).
fn rewrite_manifest(ds: &Path, columns: &[&str], extra: &[Computed]) {
    let path = ds.join("manifest.csv");
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let index: Vec<usize> = columns
        .iter()
        .map(|c| header.iter().position(|h| h == c).unwrap())
        .collect();
    let mut out: Vec<String> = columns.iter().map(|c| c.to_string()).collect();
    out.extend(extra.iter().map(|(name, _)| name.to_string()));
    let mut manifest = out.join(",") + "\n";
    for line in lines {
        let fields: Vec<&str> = line.split(',').collect();
        let mut row: Vec<String> = index.iter().map(|&j| fields[j].to_string()).collect();
        row.extend(extra.iter().map(|(_, value)| value(&fields)));
        manifest += &(row.join(",") + "\n");
    }
    std::fs::write(&path, manifest).unwrap();
}

/// Runs `features` and returns the CSV it wrote.
fn features(dir: &Dir, ds: &Path, method: &str) -> String {
    let out = dir.join("features.csv");
    let args = ["features", "--dataset", s(ds), "--method", method];
    dir.ok(&[&args[..], &["--out", s(&out)]].concat());
    std::fs::read_to_string(out).unwrap()
}

#[test]
fn a_manifest_of_only_file_and_label_is_featured_and_cross_validated() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[5.0], 6);
    rewrite_manifest(&ds, &["file", "label"], &[]);
    let text = features(&dir, &ds, "glcm3d");
    assert!(
        text.starts_with("file,label,contrast,correlation,asm\n"),
        "{text}"
    );
    assert_eq!(text.lines().count(), 13);

    let mut v = dir.evaluate_json(&ds, "glcm3d", &["--folds", "3"]);
    assert_eq!(v["n"], 12);
    // without slide times every recording is kept whole, and the parameters say so
    assert_eq!(v["pipeline"]["preprocess"]["slide_only"], false);
    // the same recordings with their conditions given: the same folds, the same result
    let full = dir.dataset("full", &["A", "B"], &[5.0], 6);
    rewrite_manifest(
        &full,
        &["file", "label", "speed_mm_s", "force_n", "trial"],
        &[],
    );
    let mut with_conditions = dir.evaluate_json(&full, "glcm3d", &["--folds", "3"]);
    // (the provenance names each dataset's own fingerprint and folder)
    assert_ne!(v["provenance"][1], with_conditions["provenance"][1]);
    v["provenance"][1] = serde_json::Value::Null;
    with_conditions["provenance"][1] = serde_json::Value::Null;
    assert_eq!(v, with_conditions);
    let args = ["evaluate", "--dataset", s(&ds), "--method", "glcm3d"];
    let text = dir.ok(&[&args[..], &["--folds", "3"]].concat());
    assert!(
        text.contains("all recordings") && !text.contains("mm/s"),
        "{text}"
    );

    // asking for speeds the manifest does not give is an error saying so
    let err = dir.fails(&[&args[..], &["--speeds", "5"]].concat());
    assert!(err.contains("no speed_mm_s"), "{err}");
    let err = dir.fails(
        &[
            &args[..],
            &["--train-where", "speed_mm_s=5"],
            &["--test-where", "speed_mm_s=10"],
        ]
        .concat(),
    );
    assert!(
        err.contains("speed_mm_s") && err.contains("file, label"),
        "{err}"
    );
}

#[test]
fn features_carry_every_manifest_column_in_manifest_order() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[5.0], 3);
    let session = |f: &[&str]| format!("s{}", f[4]);
    let subject = |_: &[&str]| String::from("p1");
    let extra: [Computed; 2] = [("session", session), ("subject", subject)];
    rewrite_manifest(&ds, &["file", "trial", "label", "speed_mm_s"], &extra);
    let text = features(&dir, &ds, "glcm2d");
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "file,trial,label,speed_mm_s,session,subject,contrast,correlation,asm"
    );
    let first: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(first[..6], ["A_5_0.npy", "0", "A", "5", "s0", "p1"]);
    let third: Vec<&str> = lines.nth(1).unwrap().split(',').collect();
    assert_eq!(third[..6], ["A_5_2.npy", "2", "A", "5", "s2", "p1"]);
}

/// `evaluate --json` with a train/test split on `train` and `test`.
fn split_json(dir: &Dir, ds: &Path, train: &str, test: &str, extra: &[&str]) -> Value {
    let args = ["--train-where", train, "--test-where", test];
    dir.evaluate_json(ds, "glcm3d", &[&args[..], extra].concat())
}

#[test]
fn train_where_and_test_where_split_on_trials_of_a_simulated_dataset() {
    let dir = Dir::new();
    let args = ["simulate", "--out", "sim", "--trials", "4", "--speeds", "5"];
    dir.ok(&[&args[..], &["--textures", "FT1,FT2,RT"]].concat());
    let ds = dir.join("sim");
    let predictions = dir.join("p.csv");
    let extra = ["--predictions", s(&predictions)];
    let v = split_json(&dir, &ds, "trial=0,1", "trial=2,3", &extra);
    assert_eq!(v["n"], 6, "3 textures x 2 test trials");
    let text = std::fs::read_to_string(&predictions).unwrap();
    let rows: Vec<Vec<&str>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), 6);
    assert!(rows.iter().all(|r| r[3] == "test"), "{text}");
    assert!(rows
        .iter()
        .all(|r| r[0].ends_with("_t02.npy") || r[0].ends_with("_t03.npy")));
    let err = dir.fails(&[
        "evaluate",
        "--dataset",
        s(&ds),
        "--method",
        "glcm3d",
        "--train-where",
        "trial=0,1,2",
        "--test-where",
        "trial=3",
        "--speeds",
        "5",
    ]);
    assert!(err.contains("--speeds"), "{err}");

    let base = ["evaluate", "--dataset", s(&ds), "--method", "glcm3d"];
    let fails = |train: &str, test: &str| {
        dir.fails(&[&base[..], &["--train-where", train, "--test-where", test]].concat())
    };
    let err = fails("trial=0,1", "trial=7");
    assert!(
        err.contains("trial = 7") && err.contains("0, 1, 2, 3"),
        "{err}"
    );
    let err = fails("trial=0,1", "trial=1,2");
    assert!(
        err.contains("both for training") && err.contains("_t01.npy"),
        "{err}"
    );
    let err = fails("session=a", "trial=2");
    assert!(err.contains("`session`") && err.contains("trial"), "{err}");
    let err = fails("label=FT1", "trial=2");
    assert!(err.contains("label"), "{err}");
    let err = fails("trial=one", "trial=2");
    assert!(err.contains("trial=one"), "{err}");
}

#[test]
fn train_where_and_test_where_split_on_a_session_column() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B", "C"], &[5.0], 6);
    let session = |f: &[&str]| String::from(if f[4] < "3" { "morning" } else { "evening" });
    let all = ["file", "label", "speed_mm_s", "force_n", "trial"];
    rewrite_manifest(&ds, &all, &[("session", session)]);
    let v = split_json(&dir, &ds, "session=morning", "session=evening", &[]);
    assert_eq!(v["n"], 9);
    let tested: u64 = v["metrics"]["per_class"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["support"].as_u64().unwrap())
        .sum();
    assert_eq!(tested, 9, "the 3 evening trials of each class");
    let args = ["evaluate", "--dataset", s(&ds), "--method", "glcm3d"];
    let split = [
        "--train-where",
        "session=morning",
        "--test-where",
        "session=evening",
    ];
    let text = dir.ok(&[&args[..], &split].concat());
    assert!(
        text.contains("train on session in morning, test on session in evening"),
        "{text}"
    );
    let split = [
        "--train-where",
        "session=morning",
        "--test-where",
        "session=noon",
    ];
    let err = dir.fails(&[&args[..], &split].concat());
    assert!(
        err.contains("session = noon") && err.contains("evening, morning"),
        "{err}"
    );
}

/// Sets taxel `(row, col)` of every `.npy` recording in `ds` to `value` throughout.
fn set_taxel(ds: &Path, row: usize, col: usize, value: f32) {
    for entry in std::fs::read_dir(ds).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "npy") {
            let mut rec: Array3<f32> = read_npy(&path).unwrap();
            rec.slice_mut(ndarray::s![.., row, col]).fill(value);
            write_npy(&path, &rec).unwrap();
        }
    }
}

#[test]
fn evaluate_taxel_names_silent_and_saturated_taxels() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[5.0], 6);
    set_taxel(&ds, 0, 0, 0.0);
    set_taxel(&ds, 3, 3, 1.2);
    let v = dir.evaluate_json(&ds, "taxel", &["--folds", "3"]);
    let taxels = &v["taxels"];
    assert_eq!(taxels["silent"], serde_json::json!(["r0c0"]), "{taxels}");
    assert_eq!(taxels["saturated"], serde_json::json!(["r3c3"]), "{taxels}");
    assert_eq!(taxels["taxels"][0]["silent_share"], 1.0);
    assert_eq!(taxels["taxels"].as_array().unwrap().len(), 16);
    let all = taxels["mean_all"].as_f64().unwrap();
    assert_eq!(all, v["accuracy"].as_f64().unwrap());
    // the mean over the 14 responsive taxels, by hand from the per-taxel accuracies
    let per = v["per_taxel"].as_array().unwrap();
    let responsive: Vec<f64> = per
        .iter()
        .filter(|t| {
            !matches!(
                (t["row"].as_u64(), t["col"].as_u64()),
                (Some(0), Some(0)) | (Some(3), Some(3))
            )
        })
        .map(|t| t["accuracy"].as_f64().unwrap())
        .collect();
    let mean = responsive.iter().sum::<f64>() / responsive.len() as f64;
    assert!((taxels["mean_responsive"].as_f64().unwrap() - mean).abs() < 1e-12);

    let args = [
        "evaluate",
        "--dataset",
        s(&ds),
        "--method",
        "taxel",
        "--folds",
        "3",
    ];
    let text = dir.ok(&args);
    assert!(
        text.contains("silent (no spike) in most recordings: r0c0;")
            && text.contains("in most recordings: r3c3")
            && text.contains("(mean over responsive taxels) beside"),
        "{text}"
    );
    // one taxel's classifier: no per-taxel diagnostics to report
    let v = dir.evaluate_json(&ds, "taxel", &["--folds", "3", "--taxel", "1,1"]);
    assert!(v.get("taxels").is_none());
}
