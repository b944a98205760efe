//! `neurotex features` and `neurotex evaluate` on a dataset, and their bad options.

use crate::util::{floats, s, Dir};

#[test]
fn features_and_evaluate_on_a_dataset() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B", "C"], &[5.0, 10.0], 10);
    let out = dir.join("f.csv");
    let features = |method: &str| {
        dir.ok(&[
            "features",
            "--dataset",
            s(&ds),
            "--method",
            method,
            "--out",
            s(&out),
        ]);
        std::fs::read_to_string(&out).unwrap()
    };
    let text = features("glcm3d");
    assert!(
        text.starts_with(
            "file,label,speed_mm_s,force_n,trial,slide_start_s,slide_end_s,contrast,correlation,asm\n"
        ),
        "{text}"
    );
    assert_eq!(text.lines().count(), 61);
    let text = features("taxel");
    let header = text.lines().next().unwrap();
    assert!(header.starts_with(
        "file,label,speed_mm_s,force_n,trial,slide_start_s,slide_end_s,r0c0_msr,r0c0_cv_isi"
    ));
    assert!(header.ends_with("r3c3_fano"));

    let json = |method: &str, extra: &[&str]| dir.evaluate_json(&ds, method, extra);
    let v = json("glcm3d", &["--speeds", "5"]);
    let acc = v["accuracy"].as_f64().unwrap();
    assert!((0.0..=1.0).contains(&acc));
    assert!(
        acc > 0.6,
        "three distinct gratings should be told apart, got {acc}"
    );
    assert_eq!(v["n"], 30);
    assert_eq!(v["labels"], serde_json::json!(["A", "B", "C"]));
    let total: u64 = v["confusion"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|r| r.as_array().unwrap())
        .map(|v| v.as_u64().unwrap())
        .sum();
    assert_eq!(total, 30);
    // metrics and the interval: 10 recordings of each of 3 classes
    let m = &v["metrics"];
    assert_eq!(m["chance_uniform"].as_f64().unwrap(), 1.0 / 3.0);
    assert_eq!(m["chance_majority"].as_f64().unwrap(), 1.0 / 3.0);
    let recalls: Vec<f64> = m["per_class"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["recall"].as_f64().unwrap())
        .collect();
    let balanced = recalls.iter().sum::<f64>() / 3.0;
    assert!((m["balanced_accuracy"].as_f64().unwrap() - balanced).abs() < 1e-12);
    // balanced classes: balanced accuracy equals accuracy
    assert!((balanced - acc).abs() < 1e-12);
    let interval = &v["accuracy_interval"];
    assert_eq!(interval["estimate"].as_f64().unwrap(), acc);
    let (lower, upper) = (
        interval["lower"].as_f64().unwrap(),
        interval["upper"].as_f64().unwrap(),
    );
    assert!(lower <= acc && acc <= upper && (0.0..=1.0).contains(&lower) && upper <= 1.0);
    // the protocol that gave the accuracy, in words and as numbers
    assert!(v["protocol"].as_str().unwrap().contains("stratified CV"));
    assert_eq!(v["cv"]["folds"].as_u64(), Some(5));
    assert_eq!(v["cv"]["repeats"].as_u64(), Some(1));

    let v = json("taxel", &["--repeats", "2"]);
    assert_eq!(v["cv"]["repeats"].as_u64(), Some(2));
    assert_eq!(v["per_taxel"].as_array().unwrap().len(), 16);
    let mean = v["per_taxel"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["accuracy"].as_f64().unwrap())
        .sum::<f64>()
        / 16.0;
    assert!((mean - v["accuracy"].as_f64().unwrap()).abs() < 1e-12);
    assert!(v["best"]["accuracy"].as_f64().unwrap() >= mean);

    let v = json("taxel", &["--taxel", "1,2"]);
    assert!(v.get("per_taxel").is_none());
    let v = json("glcm2d", &["--train-speeds", "5", "--test-speeds", "10"]);
    assert_eq!(v["n"], 30);
    let text = dir.ok(&[
        "evaluate",
        "--dataset",
        s(&ds),
        "--method",
        "glcm3d",
        "--k",
        "3",
        "--folds",
        "4",
    ]);
    assert!(
        text.contains("accuracy") && text.contains("confusion"),
        "{text}"
    );
}

#[test]
fn evaluate_writes_each_recordings_out_of_fold_prediction() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B", "C"], &[5.0, 10.0], 5);
    let out = dir.join("oof.csv");
    let rows = |method: &str, extra: &[&str]| -> (serde_json::Value, Vec<Vec<String>>) {
        let mut args = vec!["--predictions", s(&out)];
        args.extend_from_slice(extra);
        let json = dir.evaluate_json(&ds, method, &args);
        let text = std::fs::read_to_string(&out).unwrap();
        let mut lines = text.lines();
        assert_eq!(lines.next(), Some("file,label,predicted,fold,repeat"));
        let rows = lines
            .map(|l| l.split(',').map(String::from).collect())
            .collect();
        (json, rows)
    };
    let (json, cv) = rows("glcm3d", &["--repeats", "3"]);
    assert_eq!(cv.len(), 30 * 3, "one row per recording per repeat");
    for repeat in 0..3 {
        let of_repeat: Vec<&Vec<String>> =
            cv.iter().filter(|r| r[4] == repeat.to_string()).collect();
        let mut files: Vec<&str> = of_repeat.iter().map(|r| r[0].as_str()).collect();
        files.sort();
        files.dedup();
        assert_eq!(files.len(), 30, "repeat {repeat}: every recording once");
        assert!(of_repeat.iter().all(|r| r[3].parse::<usize>().unwrap() < 5));
        assert!(
            of_repeat.iter().all(|r| r[0].starts_with(&r[1])),
            "file and its label"
        );
    }
    let right = cv.iter().filter(|r| r[1] == r[2]).count();
    let accuracy = json["accuracy"].as_f64().unwrap();
    assert!(
        (right as f64 / 90.0 - accuracy).abs() < 1e-12,
        "{right} of 90 vs {accuracy}"
    );

    let (json, split) = rows("glcm3d", &["--train-speeds", "5", "--test-speeds", "10"]);
    assert_eq!(split.len(), 15, "the test recordings");
    assert!(split
        .iter()
        .all(|r| r[3] == "test" && r[4] == "0" && r[0].contains("_10_")));
    let right = split.iter().filter(|r| r[1] == r[2]).count();
    assert!((right as f64 / 15.0 - json["accuracy"].as_f64().unwrap()).abs() < 1e-12);

    std::fs::remove_file(&out).unwrap();
    let err = dir.fails(&[
        "evaluate",
        "--dataset",
        s(&ds),
        "--method",
        "taxel",
        "--predictions",
        s(&out),
    ]);
    assert!(err.contains("--taxel ROW,COL"), "{err}");
    assert!(!out.exists());
    let (_, taxel) = rows("taxel", &["--taxel", "1,1"]);
    assert_eq!(taxel.len(), 30);
}

#[test]
fn grouped_folds_never_split_a_group() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B", "C"], &[5.0, 10.0], 4);
    let manifest = std::fs::read_to_string(ds.join("manifest.csv")).unwrap();
    let mut lines = manifest.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let (file_col, trial_col) = (0, header.iter().position(|h| *h == "trial").unwrap());
    let trial_of: std::collections::HashMap<String, String> = lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f[file_col].to_string(), f[trial_col].to_string())
        })
        .collect();
    let out = dir.join("grouped.csv");
    for folds in ["3", "5"] {
        let args = [
            "--group-by",
            "trial",
            "--folds",
            folds,
            "--repeats",
            "2",
            "--predictions",
            s(&out),
        ];
        let json = dir.evaluate_json(&ds, "glcm3d", &args);
        assert!((0.0..=1.0).contains(&json["accuracy"].as_f64().unwrap()));
        let text = std::fs::read_to_string(&out).unwrap();
        let mut fold_of_group = std::collections::HashMap::new();
        for row in text.lines().skip(1) {
            let f: Vec<&str> = row.split(',').collect();
            let key = (trial_of[f[0]].clone(), f[4].to_string());
            let fold = fold_of_group.entry(key).or_insert_with(|| f[3].to_string());
            assert_eq!(fold, f[3], "trial {} split across folds", trial_of[f[0]]);
        }
        // 4 trials: with 5 folds asked, each trial is held out on its own
        let folds_used = text
            .lines()
            .skip(1)
            .map(|r| r.split(',').nth(3).unwrap().to_string());
        let distinct: std::collections::BTreeSet<String> = folds_used.collect();
        assert_eq!(distinct.len(), if folds == "3" { 3 } else { 4 });
    }
    let err = dir.fails(&[
        "evaluate",
        "--dataset",
        s(&ds),
        "--method",
        "glcm3d",
        "--group-by",
        "session",
    ]);
    assert!(err.contains("group-by") && err.contains("session"), "{err}");
    // Grouped by the label, every test fold holds classes its model never trained on: an
    // error, not 0 % (compare's folds are evaluate's).
    for command in ["evaluate", "compare"] {
        let err = dir.fails(&[command, "--dataset", s(&ds), "--group-by", "label"]);
        assert!(
            err.contains("put every recording of class `") && err.contains("never trained on it"),
            "{err}"
        );
    }
}

#[test]
fn same_seed_gives_the_same_result() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[5.0], 10);
    let run = |seed: &str| {
        dir.ok(&[
            "evaluate",
            "--dataset",
            s(&ds),
            "--method",
            "taxel",
            "--seed",
            seed,
            "--json",
        ])
    };
    assert_eq!(run("3"), run("3"));
}

/// What an evaluation ran on and with: the text's second line names the encoding and the
/// encoder's overshoot and gain, and the JSON keeps every stage's parameter under
/// `pipeline` and the build, the data's fingerprint and the stages' lines under
/// `provenance`; the same run prints the same JSON.
#[test]
fn an_evaluation_says_what_it_ran_on_and_with() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[5.0], 10);
    let args = ["evaluate", "--dataset", s(&ds), "--encoding", "sa+fa"];
    let text = dir.ok(&[&args[..], &["--overshoot", "capped", "--gain", "3"]].concat());
    let second = text.lines().nth(1).unwrap();
    assert!(
        second.starts_with("encoding sa+fa (FA gain ")
            && second.contains("overshoot capped at the 30 mV peak, gain G = 3"),
        "{text}"
    );
    let json = || -> serde_json::Value {
        serde_json::from_str(&dir.ok(&[&args[..], &["--json"]].concat())).unwrap()
    };
    let v = json();
    assert_eq!(v, json());
    assert_eq!(v["pipeline"]["encoder"]["overshoot"], "kept");
    assert_eq!(v["pipeline"]["encoding"], "sa+fa");
    assert_eq!(v["pipeline"]["preprocess"]["slide_only"], true);
    let lines: Vec<&str> = (v["provenance"].as_array().unwrap().iter())
        .map(|l| l.as_str().unwrap())
        .collect();
    assert!(lines[0].starts_with("neurotex "), "{lines:?}");
    assert!(lines[1].starts_with("data: sha256:"), "{lines:?}");
    assert!(
        lines[1].ends_with(&format!("({})", ds.display())),
        "{lines:?}"
    );
    let encoder = lines.iter().find(|l| l.starts_with("encoder: ")).unwrap();
    assert!(
        encoder.contains("overshoot kept (Izhikevich's reference code)"),
        "{encoder}"
    );
    assert!(
        encoder.contains("neurons of type RS, a = 0.02"),
        "{encoder}"
    );
}

#[test]
fn bad_input_is_a_clear_error_with_no_output() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[5.0, 10.0], 5);
    let out = dir.join("out.csv");
    let d = s(&ds);
    let o = s(&out);
    let feat = |extra: &[&'static str]| -> Vec<&str> {
        let mut v = vec!["features", "--dataset", d, "--method", "glcm3d", "--out", o];
        v.extend_from_slice(extra);
        v
    };
    let eval = |method: &'static str, extra: &[&'static str]| -> Vec<&str> {
        let mut v = vec!["evaluate", "--dataset", d, "--method", method];
        v.extend_from_slice(extra);
        v
    };
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec![
                "features",
                "--dataset",
                "/nonexistent",
                "--method",
                "glcm3d",
                "--out",
                o,
            ],
            "/nonexistent: does not exist",
        ),
        (
            vec!["features", "--dataset", d, "--method", "glcm4d", "--out", o],
            "glcm4d",
        ),
        (feat(&["--gain", "0"]), "gain"),
        (feat(&["--gain", "-3"]), "or `auto` to choose one"),
        (feat(&["--levels", "1"]), "levels"),
        (feat(&["--bin-ms", "0"]), "bin"),
        (feat(&["--distances", "0"]), "distances"),
        (feat(&["--cutoff", "600"]), "cutoff"),
        (feat(&["--preset", "XX"]), "preset"),
        (feat(&["--overshoot", "clipped"]), "`kept` (Izhikevich"),
        (feat(&["--baseline", "max"]), "`none` or `min`"),
        (
            vec![
                "features",
                "--dataset",
                d,
                "--method",
                "glcm3d",
                "--out",
                "/nonexistent/dir/f.csv",
            ],
            "does not exist",
        ),
        (
            vec!["evaluate", "--dataset", d, "--method", "glcm3d", "--k", "0"],
            "k must be at least 1",
        ),
        (eval("glcm3d", &["--folds", "1"]), "at least 2 folds"),
        (
            eval("glcm3d", &["--folds", "6", "--speeds", "5"]),
            "fewer than the 6 folds",
        ),
        (eval("glcm3d", &["--k", "50"]), "k = 50 neighbours"),
        (
            eval("glcm3d", &["--speeds", "7"]),
            "no recordings at 7 mm/s",
        ),
        (
            eval("glcm3d", &["--train-speeds", "5", "--test-speeds", "7,10"]),
            "no recordings at 7 mm/s in",
        ),
        (eval("glcm3d", &["--speeds", "fast"]), "a speed is a number"),
        (eval("taxel", &["--taxel", "4,0"]), "outside the 4x4 grid"),
        (eval("taxel", &["--taxel", "a"]), "ROW,COL"),
        (
            eval("glcm3d", &["--taxel", "1,1"]),
            "only to --method taxel",
        ),
        (eval("glcm3d", &["--train-speeds", "5"]), "test-speeds"),
    ];
    dir.fails_each(&cases, &out);
    assert!(!dir.partial_left(), "temporary files left behind");
}

/// With more classes than a line holds, `evaluate` sums up the confusion matrix by its
/// largest confusions and each class's recall, both read here off the matrix `--json`
/// prints whole.
#[test]
fn a_wide_confusion_matrix_is_listed_by_its_largest_confusions() {
    let dir = Dir::new();
    let labels: Vec<String> = (0..20).map(|k| format!("cls{k:02}")).collect();
    let labels: Vec<&str> = labels.iter().map(String::as_str).collect();
    let ds = dir.dataset("ds", &labels, &[10.0], 5);
    let text = dir.ok(&["evaluate", "--dataset", s(&ds), "--method", "glcm2d"]);
    let json = dir.evaluate_json(&ds, "glcm2d", &[]);
    let m: Vec<Vec<u64>> = (json["confusion"].as_array().unwrap().iter())
        .map(|r| {
            r.as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_u64().unwrap())
                .collect()
        })
        .collect();
    let mut off: Vec<(u64, usize, usize)> = (0..20)
        .flat_map(|t| (0..20).map(move |p| (t, p)))
        .filter(|&(t, p)| t != p && m[t][p] > 0)
        .map(|(t, p)| (m[t][p], t, p))
        .collect();
    off.sort_by(|a, b| b.0.cmp(&a.0).then((a.1, a.2).cmp(&(b.1, b.2))));
    assert!(off.len() > 10, "a task hard enough to confuse: {off:?}");
    assert!(!text.contains("confusion (rows"), "{text}");
    assert!(text.contains("confusion over 20 classes"), "{text}");
    let listed: Vec<&str> = (text.lines())
        .filter(|l| l.starts_with("  ") && l.contains(" -> "))
        .collect();
    let expected: Vec<String> = (off.iter().take(10))
        .map(|&(n, t, p)| format!("  {} -> {}: {n}", labels[t], labels[p]))
        .collect();
    assert_eq!(listed, expected);
    assert!(
        text.contains(&format!("... {} more pairs", off.len() - 10)),
        "{text}"
    );
    let perfect = (0..20)
        .filter(|&t| m[t][t] == m[t].iter().sum::<u64>())
        .count();
    assert!(
        text.contains(&format!("recall: {perfect} of 20 classes right")),
        "{text}"
    );
}

/// `--encoder-draws N`: the accuracy of the encoding as run first, the mean over the N
/// with an interval over encodings and recordings; each further encoding perturbed by its
/// own stream, so the first draws of a run of 3 are those of a run of 2 and a run gives the
/// same numbers again. Address events skip the encoder and are refused.
#[test]
fn encoder_draws_give_the_accuracy_over_encodings() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B", "C"], &[5.0], 10);
    let draws = |n: &str| dir.evaluate_json(&ds, "glcm3d", &["--encoder-draws", n]);
    let three = draws("3");
    let over = &three["encoder_draws"];
    let accuracies = floats(&over["accuracies"]);
    assert_eq!(accuracies.len(), 3);
    assert_eq!(accuracies[0], three["accuracy"].as_f64().unwrap());
    let mean = accuracies.iter().sum::<f64>() / 3.0;
    let combined = &over["combined"];
    assert!((combined["estimate"].as_f64().unwrap() - mean).abs() < 1e-12);
    assert_eq!(combined["encodings"], 3);
    let [lower, upper] = ["lower", "upper"].map(|k| combined[k].as_f64().unwrap());
    assert!(lower <= mean && mean <= upper, "{combined}");
    assert_eq!(over["perturbation"], 1e-12);
    assert_eq!(draws("3"), three);
    let two = draws("2");
    assert_eq!(two["encoder_draws"]["accuracies"][1], over["accuracies"][1]);
    assert!(draws("1").get("encoder_draws").is_none());
    let text = dir.ok(&["evaluate", "--dataset", s(&ds), "--encoder-draws", "3"]);
    assert!(
        text.contains("over 3 encodings (the one as run and 2 with"),
        "{text}"
    );
    let err = dir.fails(&["evaluate", "--dataset", s(&ds), "--encoder-draws", "0"]);
    assert!(err.contains("--encoder-draws"), "{err}");

    let events = dir.join("ev");
    let export = ["export", "events", "--dataset", s(&ds), "--out", s(&events)];
    dir.ok(&export);
    let args = ["evaluate", "--dataset", s(&events), "--encoder-draws", "2"];
    let err = dir.fails(&args);
    assert!(
        err.contains("address events, which skip the encoder"),
        "{err}"
    );
}
