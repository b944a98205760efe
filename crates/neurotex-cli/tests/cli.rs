//! The real `neurotex` binary on small datasets written here: outputs, JSON keys, and bad
//! input (clear message, non-zero exit, no output file).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use ndarray::Array3;
use ndarray_npy::{read_npy, write_npy};
use serde_json::Value;

fn neurotex(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_neurotex"))
        .args(args)
        .output()
        .expect("binary runs")
}

fn ok(args: &[&str]) -> String {
    let out = neurotex(args);
    assert!(
        out.status.success(),
        "neurotex {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// Runs a command that must fail; returns its standard error.
fn fails(args: &[&str]) -> String {
    let out = neurotex(args);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success(), "neurotex {args:?} should fail");
    assert!(
        !err.contains("panicked"),
        "neurotex {args:?} panicked: {err}"
    );
    assert!(err.starts_with("error:") || err.contains("error:"), "{err}");
    err
}

/// Runs every case, each expected to fail with its message and to leave `out` (an output
/// file or folder) unwritten.
fn fails_each(cases: &[(Vec<&str>, &str)], out: &Path) {
    for (args, expected) in cases {
        let err = fails(args);
        assert!(
            err.contains(expected),
            "{args:?}: expected `{expected}` in {err}"
        );
        assert!(!out.exists(), "{args:?} left output behind at {out:?}");
    }
}

/// A texture-like 4x4 recording: a grating of `period_ms` sweeping across the rows, with
/// noise from a small generator seeded by `seed`.
fn recording(steps: usize, period_ms: f64, amp: f64, seed: u64) -> Array3<f32> {
    let mut state = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407)
        | 1;
    Array3::from_shape_fn((steps, 4, 4), |(t, r, c)| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        let noise = (state % 1000) as f64 / 1000.0 - 0.5;
        let phase = (t as f64 - 40.0 * r as f64 - 7.0 * c as f64) / period_ms;
        (0.5 + amp * (std::f64::consts::TAU * phase).sin() + 0.2 * noise) as f32
    })
}

/// A dataset of `labels` classes x `trials` at each speed, 1.2 s recordings.
fn dataset(dir: &Path, labels: &[&str], speeds: &[f64], trials: usize) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let mut manifest =
        String::from("file,label,speed_mm_s,force_n,trial,slide_start_s,slide_end_s\n");
    for (k, label) in labels.iter().enumerate() {
        for &speed in speeds {
            for trial in 0..trials {
                let file = format!("{label}_{speed}_{trial}.npy");
                let period = (60.0 + 70.0 * k as f64) * 5.0 / speed;
                let rec = recording(
                    1400,
                    period,
                    0.2 + 0.1 * k as f64,
                    (k * 1000 + trial) as u64 + speed as u64,
                );
                write_npy(dir.join(&file), &rec).unwrap();
                manifest.push_str(&format!("{file},{label},{speed},1,{trial},0.1,1.3\n"));
            }
        }
    }
    std::fs::write(dir.join("manifest.csv"), manifest).unwrap();
    dir.to_path_buf()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Adds a CSV recording of label A at 5 mm/s to a dataset's manifest.
fn add_csv(ds: &Path, name: &str, content: &str) {
    std::fs::write(ds.join(name), content).unwrap();
    let mut m = std::fs::read_to_string(ds.join("manifest.csv")).unwrap();
    m.push_str(&format!("{name},A,5,1,9,,\n"));
    std::fs::write(ds.join("manifest.csv"), &m).unwrap();
}

/// Runs `features` on a dataset, which must fail; returns standard error.
fn features_fails(ds: &Path, out: &Path, method: &str, extra: &[&str]) -> String {
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
    fails(&args)
}

#[test]
fn encode_writes_raster_and_events() {
    let tmp = tempfile::tempdir().unwrap();
    let input = tmp.path().join("in.npy");
    write_npy(&input, &recording(500, 80.0, 0.3, 1)).unwrap();
    let out = tmp.path().join("spikes.npy");
    let events = tmp.path().join("events.csv");
    ok(&[
        "encode",
        s(&input),
        "--out",
        s(&out),
        "--events",
        s(&events),
    ]);
    let raster: Array3<u8> = read_npy(&out).unwrap();
    assert_eq!(raster.shape(), &[500, 4, 4]);
    let spikes = raster.iter().filter(|&&v| v == 1).count();
    assert!(spikes > 0 && raster.iter().all(|&v| v <= 1));
    let text = std::fs::read_to_string(&events).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("t_ms,row,col"));
    let ev: Vec<Vec<usize>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(ev.len(), spikes);
    assert!(ev.iter().all(|e| raster[[e[0], e[1], e[2]]] == 1));
    // a CSV at 500 Hz is resampled onto 1 ms steps
    let csv = tmp.path().join("in.csv");
    let mut text = String::from("t_s,a,b\n");
    for i in 0..400 {
        text.push_str(&format!(
            "{},{},{}\n",
            i as f64 / 500.0,
            (i as f64 / 10.0).sin() + 1.0,
            0.5
        ));
    }
    std::fs::write(&csv, text).unwrap();
    let out2 = tmp.path().join("csv.npy");
    ok(&["encode", s(&csv), "--out", s(&out2)]);
    let raster: Array3<u8> = read_npy(&out2).unwrap();
    assert_eq!(raster.shape(), &[799, 1, 2]);
}

#[test]
fn features_and_evaluate_on_a_dataset() {
    let tmp = tempfile::tempdir().unwrap();
    let ds = dataset(&tmp.path().join("ds"), &["A", "B", "C"], &[5.0, 10.0], 10);
    let out = tmp.path().join("f.csv");
    ok(&[
        "features",
        "--dataset",
        s(&ds),
        "--method",
        "glcm3d",
        "--out",
        s(&out),
    ]);
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(
        text.starts_with("file,label,speed_mm_s,trial,contrast,correlation,asm\n"),
        "{text}"
    );
    assert_eq!(text.lines().count(), 61);
    ok(&[
        "features",
        "--dataset",
        s(&ds),
        "--method",
        "taxel",
        "--out",
        s(&out),
    ]);
    let header = std::fs::read_to_string(&out)
        .unwrap()
        .lines()
        .next()
        .unwrap()
        .to_string();
    assert!(
        header.starts_with("file,label,speed_mm_s,trial,r0c0_msr,r0c0_cv_isi,r0c0_fano,r0c1_msr")
    );
    assert!(header.ends_with("r3c3_fano"));

    let json: Value = serde_json::from_str(&ok(&[
        "evaluate",
        "--dataset",
        s(&ds),
        "--method",
        "glcm3d",
        "--speeds",
        "5",
        "--json",
    ]))
    .unwrap();
    let acc = json["accuracy"].as_f64().unwrap();
    assert!((0.0..=1.0).contains(&acc));
    assert!(
        acc > 0.6,
        "three distinct gratings should be told apart, got {acc}"
    );
    assert_eq!(json["n"], 30);
    assert_eq!(json["labels"], serde_json::json!(["A", "B", "C"]));
    let total: u64 = json["confusion"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|r| r.as_array().unwrap())
        .map(|v| v.as_u64().unwrap())
        .sum();
    assert_eq!(total, 30);

    let json: Value = serde_json::from_str(&ok(&[
        "evaluate",
        "--dataset",
        s(&ds),
        "--method",
        "taxel",
        "--json",
        "--repeats",
        "2",
    ]))
    .unwrap();
    assert_eq!(json["per_taxel"].as_array().unwrap().len(), 16);
    let mean = json["per_taxel"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["accuracy"].as_f64().unwrap())
        .sum::<f64>()
        / 16.0;
    assert!((mean - json["accuracy"].as_f64().unwrap()).abs() < 1e-12);
    assert!(json["best"]["accuracy"].as_f64().unwrap() >= mean);

    let json: Value = serde_json::from_str(&ok(&[
        "evaluate",
        "--dataset",
        s(&ds),
        "--method",
        "taxel",
        "--taxel",
        "1,2",
        "--json",
    ]))
    .unwrap();
    assert!(json.get("per_taxel").is_none());
    let json: Value = serde_json::from_str(&ok(&[
        "evaluate",
        "--dataset",
        s(&ds),
        "--method",
        "glcm2d",
        "--train-speeds",
        "5",
        "--test-speeds",
        "10",
        "--json",
    ]))
    .unwrap();
    assert_eq!(json["n"], 30);
    let text = ok(&[
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
fn same_seed_gives_the_same_result() {
    let tmp = tempfile::tempdir().unwrap();
    let ds = dataset(&tmp.path().join("ds"), &["A", "B"], &[5.0], 10);
    let run = |seed: &str| {
        ok(&[
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

#[test]
fn bad_input_is_a_clear_error_with_no_output() {
    let tmp = tempfile::tempdir().unwrap();
    let ds = dataset(&tmp.path().join("ds"), &["A", "B"], &[5.0, 10.0], 5);
    let out = tmp.path().join("out.csv");
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
            "not a dataset folder",
        ),
        (
            vec!["features", "--dataset", d, "--method", "glcm4d", "--out", o],
            "glcm4d",
        ),
        (feat(&["--gain", "0"]), "gain"),
        (feat(&["--gain", "-3"]), "gain"),
        (feat(&["--levels", "1"]), "levels"),
        (feat(&["--bin-ms", "0"]), "bin"),
        (feat(&["--distances", "0"]), "distances"),
        (feat(&["--cutoff", "600"]), "cutoff"),
        (feat(&["--preset", "XX"]), "preset"),
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
        (eval("taxel", &["--taxel", "4,0"]), "outside the 4x4 grid"),
        (eval("taxel", &["--taxel", "a"]), "ROW,COL"),
        (
            eval("glcm3d", &["--taxel", "1,1"]),
            "only to --method taxel",
        ),
        (eval("glcm3d", &["--train-speeds", "5"]), "test-speeds"),
    ];
    fails_each(&cases, &out);
    let no_tmp = std::fs::read_dir(tmp.path())
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .file_name()
                .to_string_lossy()
                .contains("partial")
        })
        .count();
    assert_eq!(no_tmp, 0, "temporary files left behind");
}

#[test]
fn bad_recordings_and_layouts_are_named() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out.csv");
    let base = |name: &str| dataset(&tmp.path().join(name), &["A", "B"], &[5.0], 5);

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
    let err = features_fails(&ds, &out, "glcm3d", &[]);
    assert!(
        err.contains("bad.csv") && err.contains("line 3") && err.contains("NaN"),
        "{err}"
    );

    // a recording shorter than one 200 ms bin
    let ds = base("short");
    write_npy(ds.join("A_5_0.npy"), &recording(150, 50.0, 0.3, 1)).unwrap();
    let err = features_fails(&ds, &out, "taxel", &["--whole"]);
    assert!(
        err.contains("A_5_0.npy") && err.contains("shorter than one 200 ms bin"),
        "{err}"
    );

    // non-increasing time stamps
    let ds = base("time");
    add_csv(
        &ds,
        "t.csv",
        "t_ms,a
0,1
1,2
1,3
",
    );
    let err = features_fails(&ds, &out, "glcm3d", &[]);
    assert!(
        err.contains("t.csv") && err.contains("line 4") && err.contains("increase"),
        "{err}"
    );

    // a layout that does not match the data
    let ds = base("layout");
    std::fs::write(ds.join("layout.toml"), "rows = 2\ncols = 2\n").unwrap();
    let err = features_fails(&ds, &out, "glcm3d", &[]);
    assert!(err.contains("4x4 grid") && err.contains("2x2"), "{err}");

    // an unreadable .npy
    let ds = base("garbage");
    std::fs::write(ds.join("A_5_0.npy"), b"not an npy").unwrap();
    let err = features_fails(&ds, &out, "glcm3d", &[]);
    assert!(err.contains("A_5_0.npy") && err.contains(".npy"), "{err}");

    // a test label the training speeds never saw
    let ds = dataset(&tmp.path().join("unknown"), &["A", "B"], &[5.0], 5);
    let extra = dataset(&tmp.path().join("unknown_c"), &["C"], &[10.0], 5);
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
    let err = fails(&[
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

#[test]
fn help_explains_the_commands() {
    let text = ok(&["--help"]);
    for cmd in ["encode", "features", "evaluate"] {
        assert!(text.contains(cmd), "{text}");
    }
    let text = ok(&["evaluate", "--help"]);
    assert!(
        text.contains("--train-speeds") && text.contains("mean over taxels"),
        "{text}"
    );
}

#[test]
fn reproduce_on_a_dataset_writes_report_json_and_figures() {
    let tmp = tempfile::tempdir().unwrap();
    let ds = dataset(&tmp.path().join("ds"), &["A", "B", "C"], &[5.0, 10.0], 6);
    let out = tmp.path().join("report");
    let out_s = out.to_str().unwrap();
    ok(&["reproduce", "--dataset", s(&ds), "--out", out_s, "--quick"]);
    let json: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap()).unwrap();
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
    assert!(report.contains("## E1") && report.contains("| 5 |") && report.contains("paper"));
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
    }
    // one speed only: E6 is skipped with a reason, not an error
    let one = dataset(&tmp.path().join("one"), &["A", "B"], &[5.0], 5);
    let out1 = tmp.path().join("r1");
    ok(&[
        "reproduce",
        "--dataset",
        s(&one),
        "--out",
        s(&out1),
        "--quick",
    ]);
    let json: Value =
        serde_json::from_str(&std::fs::read_to_string(out1.join("results.json")).unwrap()).unwrap();
    assert!(json["skipped"]["e6"]
        .as_str()
        .unwrap()
        .contains("one speed"));
}

#[test]
fn simulate_writes_a_dataset_the_pipeline_reads() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("sim");
    ok(&[
        "simulate",
        "--out",
        s(&out),
        "--trials",
        "5",
        "--speeds",
        "15",
        "--textures",
        "CP,RT",
    ]);
    let manifest = std::fs::read_to_string(out.join("manifest.csv")).unwrap();
    assert!(manifest.starts_with("file,label,speed_mm_s,force_n,trial,slide_start_s,slide_end_s\n"));
    assert_eq!(manifest.lines().count(), 11);
    let json: Value = serde_json::from_str(&ok(&[
        "evaluate",
        "--dataset",
        s(&out),
        "--method",
        "glcm3d",
        "--json",
    ]))
    .unwrap();
    assert_eq!(json["n"], 10);
    let err = fails(&["simulate", "--out", s(&out), "--trials", "5"]);
    assert!(err.contains("not empty"), "{err}");
    let err = fails(&[
        "simulate",
        "--out",
        s(&tmp.path().join("x")),
        "--textures",
        "FT9",
    ]);
    assert!(err.contains("unknown texture `FT9`"), "{err}");
    let err = fails(&[
        "simulate",
        "--out",
        s(&tmp.path().join("y")),
        "--speeds",
        "0",
    ]);
    assert!(err.contains("positive"), "{err}");
    assert!(!tmp.path().join("x").exists() && !tmp.path().join("y").exists());
}

fn fabricslide() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/fabricslide/fabric");
    dir.is_dir().then_some(dir)
}

const FABRIC_PATTERN: &str = "{label}_F{force}_V{speed}mmps_{trial}.csv";

#[test]
fn fabricslide_subset_imports_and_classifies_well_above_chance() {
    let Some(src) = fabricslide() else {
        eprintln!("skipped: ../shared/data/fabricslide is not beside the repository");
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    // every fabric at 10 mm/s in both directions, every force and repeat
    let subset = tmp.path().join("subset");
    std::fs::create_dir(&subset).unwrap();
    let mut at_10 = 0;
    for entry in std::fs::read_dir(&src).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        if name.contains("_V10mmps_") || name.contains("_V-10mmps_") {
            std::fs::copy(src.join(&name), subset.join(&name)).unwrap();
            at_10 += usize::from(name.contains("_V10mmps_"));
        }
    }
    let out = tmp.path().join("ds");
    ok(&[
        "import",
        "csv",
        s(&subset),
        "--out",
        s(&out),
        "--name-pattern",
        FABRIC_PATTERN,
        "--time-column",
        "timestamp",
        "--channels",
        r"^channel\d+$",
        "--grid",
        "4x4",
        "--baseline",
        "min",
    ]);
    let layout = std::fs::read_to_string(out.join("layout.toml")).unwrap();
    assert!(
        layout.contains("kind = \"min\"") && layout.contains("rows = 4"),
        "{layout}"
    );
    let json: Value = serde_json::from_str(&ok(&[
        "evaluate",
        "--dataset",
        s(&out),
        "--method",
        "glcm3d",
        "--speeds",
        "10",
        "--json",
    ]))
    .unwrap();
    assert_eq!(json["n"].as_u64(), Some(at_10 as u64));
    let acc = json["accuracy"].as_f64().unwrap();
    // chance is 1/7 for seven fabrics
    assert!(
        acc > 0.4,
        "3D-GLCM accuracy {acc} on seven fabrics at 10 mm/s"
    );
    let json: Value = serde_json::from_str(&ok(&[
        "evaluate",
        "--dataset",
        s(&out),
        "--method",
        "taxel",
        "--json",
    ]))
    .unwrap();
    assert!(json["best"]["accuracy"].as_f64().unwrap() > 0.4);
}

#[test]
fn import_bad_input_is_named_through_the_binary() {
    let tmp = tempfile::tempdir().unwrap();
    let src = tmp.path().join("src");
    std::fs::create_dir(&src).unwrap();
    std::fs::write(
        src.join("Silk_F1_V5mmps_0.csv"),
        "timestamp,channel1,channel2\n0,1,2\n28,1,NaN\n",
    )
    .unwrap();
    std::fs::write(
        src.join("Silk_F1_V5mmps_1.csv"),
        "timestamp,channel1,channel2\n0,1,2\n28,1,3\n",
    )
    .unwrap();
    let out = tmp.path().join("out");
    let o = s(&out);
    let csv = |extra: &[&'static str]| -> Vec<&str> {
        let mut v = vec!["import", "csv", s(&src), "--out", o];
        v.extend_from_slice(extra);
        v
    };
    // every case but the time-column ones reads the time stamps from `timestamp`
    let timed = |extra: &[&'static str]| -> Vec<&str> {
        let mut v = csv(&["--time-column", "timestamp"]);
        v.extend_from_slice(extra);
        v
    };
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            timed(&["--name-pattern", "{label}-{trial}.csv"]),
            "does not match --name-pattern",
        ),
        (timed(&["--name-pattern", "{label"]), "name-pattern"),
        (
            timed(&[
                "--name-pattern",
                FABRIC_PATTERN,
                "--channels",
                "channel1,channel9",
            ]),
            "missing channel column `channel9`",
        ),
        (
            csv(&["--time-column", "time", "--name-pattern", FABRIC_PATTERN]),
            "missing time column `time`",
        ),
        (
            timed(&["--name-pattern", FABRIC_PATTERN]),
            "line 3, column `channel2`",
        ),
        (
            timed(&[
                "--name-pattern",
                FABRIC_PATTERN,
                "--grid",
                "1x1",
                "--skip-bad",
            ]),
            "grid",
        ),
        (
            timed(&["--name-pattern", FABRIC_PATTERN, "--grid", "four"]),
            "ROWSxCOLS",
        ),
        (csv(&["--name-pattern", FABRIC_PATTERN]), "--fs"),
    ];
    fails_each(&cases, &out);
    // --skip-bad leaves the NaN file out with a warning and imports the rest
    let run = neurotex(&timed(&["--name-pattern", FABRIC_PATTERN, "--skip-bad"]));
    assert!(run.status.success());
    assert!(String::from_utf8_lossy(&run.stderr).contains("left out"));
    assert_eq!(
        std::fs::read_to_string(out.join("manifest.csv"))
            .unwrap()
            .lines()
            .count(),
        2
    );

    // stacked: shape/axes mismatch and labels of the wrong length
    let data = ndarray::Array::from_elem(ndarray::IxDyn(&[3, 10, 2, 2]), 1.0f32);
    write_npy(tmp.path().join("x.npy"), &data).unwrap();
    write_npy(
        tmp.path().join("y.npy"),
        &ndarray::Array1::from(vec![0i64, 1]),
    )
    .unwrap();
    let x = tmp.path().join("x.npy");
    let y = tmp.path().join("y.npy");
    let st = tmp.path().join("st");
    let stacked = |axes: &str, fs: &str| {
        fails(&[
            "import",
            "stacked",
            "--data",
            s(&x),
            "--labels",
            s(&y),
            "--axes",
            axes,
            "--fs",
            fs,
            "--out",
            s(&st),
        ])
    };
    let err = stacked("n,t,channel", "100");
    assert!(err.contains("names 3 axes but the data has 4"), "{err}");
    let err = stacked("n,t,row,col", "100");
    assert!(err.contains("2 labels for 3 samples"), "{err}");
    let err = stacked("n,t,row,col", "0");
    assert!(err.contains("fs"), "{err}");
    assert!(!st.exists());
}

#[test]
fn encode_takes_the_rate_from_a_layout_unless_fs_is_given() {
    let tmp = tempfile::tempdir().unwrap();
    let input = tmp.path().join("in.npy");
    write_npy(&input, &recording(400, 80.0, 0.3, 2)).unwrap();
    let layout = tmp.path().join("layout.toml");
    std::fs::write(&layout, "fs = 500.0\n").unwrap();
    let out = tmp.path().join("a.npy");
    ok(&[
        "encode",
        s(&input),
        "--out",
        s(&out),
        "--layout",
        s(&layout),
    ]);
    let raster: Array3<u8> = read_npy(&out).unwrap();
    assert_eq!(raster.shape()[0], 799, "400 samples at 500 Hz span 798 ms");
    ok(&[
        "encode",
        s(&input),
        "--out",
        s(&out),
        "--layout",
        s(&layout),
        "--fs",
        "1000",
    ]);
    let raster: Array3<u8> = read_npy(&out).unwrap();
    assert_eq!(raster.shape()[0], 400);
    let err = fails(&["encode", s(&input), "--out", s(&out), "--fs", "-5"]);
    assert!(err.contains("--fs"), "{err}");
}
