//! Where outputs go: `--out -` is standard output for a command that writes one file and
//! refused for one that writes a folder; a folder another run is writing is refused at the
//! command's start, before any input is read.

use std::path::Path;

use crate::util::{s, Dir};

/// Claims folder `name` in `dir` as a live run does: `.NAME.lock` beside it holding the id
/// of a process that runs (this test's).
fn hold_lock(dir: &Dir, name: &str) {
    let lock = dir.join(&format!(".{name}.lock"));
    std::fs::write(lock, std::process::id().to_string()).unwrap();
}

#[test]
fn a_folder_another_run_is_writing_is_refused_at_the_start() {
    let dir = Dir::new();
    let data = dir.dataset("ds", &["a", "b"], &[10.0], 2);
    // Inputs that do not exist: the claim comes first, so the run says the folder is taken
    // rather than what is wrong with its inputs.
    let cases: Vec<(&str, Vec<&str>)> = vec![
        (
            "sim",
            vec![
                "simulate",
                "--trials",
                "1",
                "--speeds",
                "10",
                "--textures",
                "FT1",
            ],
        ),
        ("logs", vec!["import", "csv", "missing.csv"]),
        (
            "ev",
            vec![
                "import",
                "events",
                "--grid",
                "2x2",
                "--time-unit",
                "ms",
                "missing.csv",
            ],
        ),
        (
            "stacked",
            vec![
                "import",
                "stacked",
                "--data",
                "x.npy",
                "--labels",
                "y.npy",
                "--axes",
                "n,t,channel",
                "--fs",
                "1000",
            ],
        ),
        (
            "inputs",
            vec![
                "export",
                "inputs",
                "--model",
                "missing.json",
                "--dataset",
                s(&data),
            ],
        ),
        ("events", vec!["export", "events", "--dataset", "missing"]),
    ];
    for (name, mut args) in cases {
        hold_lock(&dir, name);
        args.extend(["--out", name]);
        let err = dir.fails(&args);
        assert!(
            err.contains("another neurotex run")
                && err.contains("is writing this folder")
                && err.contains(name),
            "{args:?}: {err}"
        );
        assert!(!dir.join(name).exists(), "{args:?}");
        // The lock is the other run's: left as it was.
        assert!(dir.join(&format!(".{name}.lock")).exists());
    }
}

#[test]
fn out_dash_is_refused_for_a_folder() {
    let dir = Dir::new();
    let data = dir.dataset("ds", &["a", "b"], &[10.0], 2);
    let cases: Vec<Vec<&str>> = vec![
        vec![
            "simulate",
            "--trials",
            "1",
            "--speeds",
            "10",
            "--textures",
            "FT1",
        ],
        vec!["import", "csv", "missing.csv"],
        vec!["export", "events", "--dataset", s(&data)],
        vec!["reproduce", "--dataset", s(&data)],
        vec!["compare", "--dataset", s(&data)],
    ];
    for mut args in cases {
        args.extend(["--out", "-"]);
        let err = dir.fails(&args);
        assert!(
            err.contains("--out -: standard output takes one file"),
            "{args:?}: {err}"
        );
        assert!(!Path::new(&dir.join("-")).exists(), "{args:?} created `-`");
    }
}

#[test]
fn out_dash_writes_one_file_to_standard_output() {
    let dir = Dir::new();
    let data = dir.dataset("ds", &["a", "b"], &[10.0], 3);
    // A model on standard output is the model a file would hold.
    let model = dir.ok(&["train", "--dataset", s(&data), "--out", "-"]);
    assert!(!dir.join("-").exists());
    let saved = dir.join("model.json");
    dir.ok(&["train", "--dataset", s(&data), "--out", s(&saved)]);
    assert_eq!(model, std::fs::read_to_string(&saved).unwrap());
    // A spike raster and its events: the array to standard output, the events to a file
    // (and the other way round).
    let recording = data.join("a_10_0.npy");
    let events = dir.join("events.csv");
    let out = dir.run(&[
        "encode",
        s(&recording),
        "--out",
        "-",
        "--events",
        s(&events),
    ]);
    assert!(out.status.success(), "{}", out.stderr);
    assert!(out.stdout.contains("NUMPY") && out.stdout.contains("'descr': '|u1'"));
    assert!(events.exists() && !dir.join("-").exists());
    let raster = dir.join("raster.npy");
    let text = dir.ok(&[
        "encode",
        s(&recording),
        "--out",
        s(&raster),
        "--events",
        "-",
    ]);
    assert_eq!(text, std::fs::read_to_string(&events).unwrap());
    assert!(raster.exists() && !dir.join("-").exists());
    let err = dir.fails(&["encode", s(&recording), "--out", "-", "--events", "-"]);
    assert!(err.contains("name the same file, standard output"), "{err}");
}
