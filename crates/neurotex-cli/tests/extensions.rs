//! The encodings and feature methods beyond the paper through the binary.

use crate::util::{s, Dir};

#[test]
fn features_with_both_populations_and_all_taxels() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[5.0], 3);
    let out = dir.join("f.csv");
    let args = ["features", "--dataset", s(&ds), "--out", s(&out)];
    dir.ok(&[
        &args[..],
        &["--method", "all-taxels", "--encoding", "sa+fa"],
    ]
    .concat());
    let text = std::fs::read_to_string(&out).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    // 7 manifest columns, then 16 taxels x 3 statistics x 2 populations.
    assert_eq!(header.len(), 7 + 96);
    assert_eq!(
        header[7..10],
        ["sa_r0c0_msr", "sa_r0c0_cv_isi", "sa_r0c0_fano"]
    );
    assert_eq!(header[7 + 48], "fa_r0c0_msr");
    assert_eq!(text.lines().count(), 1 + 6);
    // FA neurons fire on these noisy gratings: some FA rate is positive.
    let first: Vec<f64> = text.lines().nth(1).unwrap().split(',').collect::<Vec<_>>()[7..]
        .iter()
        .map(|v| v.parse().unwrap())
        .collect();
    assert!(first[48..].iter().step_by(3).any(|&r| r > 0.0));
    let sa_only = dir.join("sa.csv");
    let args = ["features", "--dataset", s(&ds), "--out", s(&sa_only)];
    dir.ok(&[&args[..], &["--method", "all-taxels"]].concat());
    let sa_text = std::fs::read_to_string(&sa_only).unwrap();
    assert!(sa_text
        .starts_with("file,label,speed_mm_s,force_n,trial,slide_start_s,slide_end_s,r0c0_msr,"));
    let err = dir.fails(&[&args[..], &["--method", "all-taxels", "--encoding", "ra"]].concat());
    assert!(err.contains("encoding must be sa, fa or sa+fa"), "{err}");
}

#[test]
fn evaluate_multi_scale_and_full_haralick() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B", "C"], &[5.0], 5);
    let multi = dir.evaluate_json(&ds, "glcm3d-multi", &["--folds", "2"]);
    let accuracy = multi["accuracy"].as_f64().unwrap();
    assert!((0.0..=1.0).contains(&accuracy), "{multi}");
    assert!(multi.get("per_taxel").is_none());
    let full = dir.evaluate_json(
        &ds,
        "glcm3d-multi",
        &[
            "--folds",
            "2",
            "--haralick",
            "full",
            "--bin-widths",
            "100,300",
        ],
    );
    assert!(full["accuracy"].as_f64().is_some());
    let err = dir.fails(&[
        "evaluate",
        "--dataset",
        s(&ds),
        "--method",
        "glcm3d-multi",
        "--bin-widths",
        "0",
    ]);
    assert!(err.contains("bin widths"), "{err}");
    // all-taxels is one classification, taxel evaluates each taxel alone.
    let all = dir.evaluate_json(&ds, "all-taxels", &["--folds", "2", "--encoding", "sa+fa"]);
    assert!(all.get("per_taxel").is_none());
    let each = dir.evaluate_json(&ds, "taxel", &["--folds", "2", "--encoding", "sa+fa"]);
    assert_eq!(each["per_taxel"].as_array().unwrap().len(), 16);
}

#[test]
fn distance_statistics_across_speeds_and_a_model_with_both_populations() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[5.0, 10.0], 4);
    let split = ["--train-speeds", "5", "--test-speeds", "10"];
    let held_out = dir.evaluate_json(&ds, "all-taxels-mm", &split);
    assert!(held_out["accuracy"].as_f64().is_some());
    let model = dir.join("m.json");
    let train = [
        "train",
        "--dataset",
        s(&ds),
        "--out",
        s(&model),
        "--method",
        "all-taxels",
    ];
    dir.ok(&[&train[..], &["--encoding", "sa+fa"]].concat());
    let file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
    assert_eq!(file["features"]["method"], "all-taxels");
    assert_eq!(file["pipeline"]["encoding"], "sa+fa");
    let predictions = dir.join("p.csv");
    dir.ok(&[
        "predict",
        "--model",
        s(&model),
        "--dataset",
        s(&ds),
        "--out",
        s(&predictions),
    ]);
    assert_eq!(
        std::fs::read_to_string(&predictions)
            .unwrap()
            .lines()
            .count(),
        1 + 16
    );
}
