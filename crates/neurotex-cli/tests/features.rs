//! `neurotex features`: bad recordings and layouts in a dataset are named.

use std::path::Path;

use ndarray_npy::write_npy;

use crate::util::{add_csv, recording, s, Dir};

/// Runs `features` on a dataset, which must fail; returns standard error.
fn features_fails(dir: &Dir, ds: &Path, out: &Path, method: &str, extra: &[&str]) -> String {
    let mut args = vec![
        "features",
        "--dataset",
        s(ds),
        "--method",
        method,
        "--out",
        s(out),
    ];
    args.extend_from_slice(extra);
    dir.fails(&args)
}

#[test]
fn bad_recordings_and_layouts_are_named() {
    let dir = Dir::new();
    let out = dir.join("out.csv");
    let base = |name: &str| dir.dataset(name, &["A", "B"], &[5.0], 5);

    // a NaN sample in one CSV recording
    let ds = base("nan");
    add_csv(
        &ds,
        "bad.csv",
        "a,b
1,2
3,NaN
",
    );
    let err = features_fails(&dir, &ds, &out, "glcm3d", &[]);
    assert!(
        err.contains("bad.csv") && err.contains("line 3") && err.contains("NaN"),
        "{err}"
    );

    // a recording shorter than one 200 ms bin
    let ds = base("short");
    write_npy(ds.join("A_5_0.npy"), &recording(150, 50.0, 0.3, 1)).unwrap();
    let err = features_fails(&dir, &ds, &out, "taxel", &["--whole"]);
    assert!(
        err.contains("A_5_0.npy") && err.contains("shorter than one 200 ms bin"),
        "{err}"
    );

    // a time stamp that goes back (a repeated one is merged: see the import tests)
    let ds = base("time");
    add_csv(
        &ds,
        "t.csv",
        "t_ms,a
0,1
2,2
1,3
",
    );
    let err = features_fails(&dir, &ds, &out, "glcm3d", &[]);
    assert!(
        err.contains("t.csv") && err.contains("line 4") && err.contains("must not go back"),
        "{err}"
    );

    // a layout that does not match the data
    let ds = base("layout");
    std::fs::write(ds.join("layout.toml"), "rows = 2\ncols = 2\n").unwrap();
    let err = features_fails(&dir, &ds, &out, "glcm3d", &[]);
    assert!(err.contains("4x4 grid") && err.contains("2x2"), "{err}");

    // an unreadable .npy
    let ds = base("garbage");
    std::fs::write(ds.join("A_5_0.npy"), b"not an npy").unwrap();
    let err = features_fails(&dir, &ds, &out, "glcm3d", &[]);
    assert!(err.contains("A_5_0.npy") && err.contains(".npy"), "{err}");

    // recordings on two grids: a 4x4 array and a 16-channel row
    let ds = base("grids");
    add_csv(&ds, "row.csv", &row_of_channels(16, 400));
    let err = features_fails(&dir, &ds, &out, "glcm3d", &["--whole"]);
    assert!(
        err.contains("row.csv") && err.contains("a dataset needs one layout"),
        "{err}"
    );

    // a test label the training speeds never saw
    let ds = dir.dataset("unknown", &["A", "B"], &[5.0], 5);
    let extra = dir.dataset("unknown_c", &["C"], &[10.0], 5);
    let mut m = std::fs::read_to_string(ds.join("manifest.csv")).unwrap();
    for line in std::fs::read_to_string(extra.join("manifest.csv"))
        .unwrap()
        .lines()
        .skip(1)
    {
        let file = line.split(',').next().unwrap();
        std::fs::copy(extra.join(file), ds.join(file)).unwrap();
        m.push_str(line);
        m.push('\n');
    }
    std::fs::write(ds.join("manifest.csv"), &m).unwrap();
    let err = dir.fails(&[
        "evaluate",
        "--dataset",
        s(&ds),
        "--method",
        "glcm3d",
        "--train-speeds",
        "5",
        "--test-speeds",
        "10",
    ]);
    assert!(err.contains("test label `C`"), "{err}");
    assert!(!out.exists());
}

/// A CSV recording of `channels` columns and `steps` rows of a slow wave.
fn row_of_channels(channels: usize, steps: usize) -> String {
    let names: Vec<String> = (0..channels).map(|c| format!("c{c}")).collect();
    let mut text = names.join(",") + "\n";
    for t in 0..steps {
        let row: Vec<String> = (0..channels)
            .map(|c| format!("{}", 1.0 + ((t + 7 * c) as f64 / 20.0).sin()))
            .collect();
        text.push_str(&(row.join(",") + "\n"));
    }
    text
}

#[test]
fn tables_and_predictions_go_to_standard_output_with_a_dash() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[5.0], 5);
    let to_file = dir.join("table.csv");
    dir.ok(&[
        "features",
        "--dataset",
        s(&ds),
        "--method",
        "glcm3d",
        "--out",
        s(&to_file),
    ]);
    let piped = dir.ok(&[
        "features",
        "--dataset",
        s(&ds),
        "--method",
        "glcm3d",
        "--out",
        "-",
    ]);
    assert_eq!(piped, std::fs::read_to_string(&to_file).unwrap());
    assert!(!dir.join("-").exists(), "no file named `-`");
    // evaluate's predictions take standard output; the evaluation goes to standard error
    let args = [
        "evaluate",
        "--dataset",
        s(&ds),
        "--method",
        "glcm3d",
        "--predictions",
        "-",
    ];
    let run = dir.run(&args);
    assert!(run.status.success(), "{}", run.stderr);
    assert!(
        run.stdout.starts_with("file,label,predicted,fold,repeat\n"),
        "{}",
        run.stdout
    );
    assert!(run.stderr.contains("accuracy"), "{}", run.stderr);
    let err = dir.fails(&[&args[..], &["--json"]].concat());
    assert!(err.contains("both write standard output"), "{err}");
}

/// A reader that stops early (`| head`) ends the command quietly: no panic, no error.
#[cfg(unix)]
#[test]
fn a_reader_that_stops_early_ends_the_command_quietly() {
    use std::process::{Command, Stdio};
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[5.0], 5);
    for args in [
        vec![
            "features",
            "--dataset",
            s(&ds),
            "--method",
            "glcm3d",
            "--out",
            "-",
        ],
        vec![
            "evaluate",
            "--dataset",
            s(&ds),
            "--method",
            "taxel",
            "--folds",
            "2",
        ],
    ] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_neurotex"))
            .args(&args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // The reader goes before anything is written.
        drop(child.stdout.take());
        let out = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            !stderr.contains("panicked") && !stderr.contains("Broken pipe"),
            "{args:?}: {stderr}"
        );
    }
}

#[test]
fn glcm_distances_that_pair_no_cells_are_an_error_not_constant_features() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[5.0], 3);
    let out = dir.join("f.csv");
    // On the 4x4 grid no two taxels are 4 apart; 3 pairs some. In 3D, 1000 bins of 200 ms
    // outlast the 1.4 s recordings as 4 outlasts the grid.
    for (method, distances) in [("glcm2d", "4"), ("glcm3d", "1000")] {
        let err = features_fails(&dir, &ds, &out, method, &["--distances", distances]);
        assert!(
            err.contains(
                "invalid parameter `distances`: at least one distance must pair two cells"
            ) && err.contains(&format!("got {distances} on the 4x4 grid")),
            "{err}"
        );
    }
    let args = ["features", "--dataset", s(&ds), "--method", "glcm2d"];
    dir.ok(&[&args[..], &["--distances", "3,4", "--out", s(&out)]].concat());
}
