//! `neurotex import csv` and `neurotex import stacked`.

use std::path::Path;

use ndarray_npy::write_npy;

use crate::util::{fabricslide, s, Dir};

const FABRIC_PATTERN: &str = "{label}_F{force}_V{speed}mmps_{trial}.csv";

/// `import csv SRC --out OUT` of FabricSlide-named logs stamped in `timestamp`, then `extra`.
fn fabric_import<'a>(src: &'a Path, out: &'a Path, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec![
        "import",
        "csv",
        s(src),
        "--out",
        s(out),
        "--name-pattern",
        FABRIC_PATTERN,
        "--time-column",
        "timestamp",
    ];
    args.extend_from_slice(extra);
    args
}

#[test]
#[ignore = "needs the FabricSlide data in ../shared beside the repository; .ci/run runs it with --ignored"]
fn fabricslide_imports_every_file_and_classifies_well_above_chance() {
    let src = fabricslide();
    let dir = Dir::new();
    let out = dir.join("ds");
    // every one of the 966 files, without --skip-bad: the four whose last row repeats
    // exactly lose that row
    let run = dir.run(&fabric_import(
        &src,
        &out,
        &[
            "--channels",
            r"^channel\d+$",
            "--grid",
            "4x4",
            "--baseline",
            "min",
        ],
    ));
    assert!(run.status.success(), "{}", run.stderr);
    assert!(
        run.stderr.contains(
            "966 recordings (0 left out; 0 rows merged and 4 exact duplicates dropped in 4 files)"
        ),
        "{}",
        run.stderr
    );
    let manifest = std::fs::read_to_string(out.join("manifest.csv")).unwrap();
    assert_eq!(manifest.lines().count(), 1 + 966);
    // every fabric at 10 mm/s, every force and repeat
    let at_10 = manifest.lines().filter(|l| l.contains("_V10mmps_")).count();
    assert_eq!(at_10, 69, "the data's files at 10 mm/s");
    let layout = std::fs::read_to_string(out.join("layout.toml")).unwrap();
    assert!(
        layout.contains("kind = \"min\"") && layout.contains("rows = 4"),
        "{layout}"
    );
    let json = dir.evaluate_json(&out, "glcm3d", &["--speeds", "10"]);
    assert_eq!(json["n"].as_u64(), Some(at_10 as u64));
    let acc = json["accuracy"].as_f64().unwrap();
    // chance is 1/7 for seven fabrics
    assert!(
        acc > 0.4,
        "3D-GLCM accuracy {acc} on seven fabrics at 10 mm/s"
    );
    let json = dir.evaluate_json(&out, "taxel", &["--speeds", "10"]);
    assert!(json["best"]["accuracy"].as_f64().unwrap() > 0.4);
}

#[test]
fn import_csv_writes_the_layout_it_was_given() {
    let dir = Dir::new();
    let src = dir.join("src");
    std::fs::create_dir(&src).unwrap();
    for label in ["Silk", "Wool"] {
        std::fs::write(
            src.join(format!("{label}_F1_V5mmps_0.csv")),
            "timestamp,c1,c2,c3,c4\n0,1,2,3,4\n0.028,1,2,3,5\n0.057,2,2,3,4\n",
        )
        .unwrap();
    }
    let out = dir.join("ds");
    let run = dir.run(&fabric_import(
        &src,
        &out,
        &[
            "--time-unit",
            "s",
            "--grid",
            "2x2",
            "--channel-map",
            "1,1;1,0;0,1;0,0",
            "--baseline",
            "none",
        ],
    ));
    assert!(run.status.success(), "{}", run.stderr);
    assert!(
        run.stderr.contains("4 channels on a 2x2 grid at 34.48 Hz"),
        "{}",
        run.stderr
    );
    let layout = std::fs::read_to_string(out.join("layout.toml")).unwrap();
    assert!(
        layout.contains("channel_map = [[1, 1], [1, 0], [0, 1], [0, 0]]")
            && layout.contains("time_column = \"t_s\"")
            && layout.contains("time_unit = \"s\"")
            && !layout.contains("baseline"),
        "{layout}"
    );
    // the time stamps are rewritten from the first, in their own unit (so the copy reads
    // as the log does, to the bit)
    let first = std::fs::read_to_string(out.join("Silk_F1_V5mmps_0.csv")).unwrap();
    assert!(
        first.starts_with("t_s,c1,c2,c3,c4\n0,1,2,3,4\n0.028,"),
        "{first}"
    );
}

#[test]
fn import_bad_input_is_named_through_the_binary() {
    let dir = Dir::new();
    let src = dir.join("src");
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
    let out = dir.join("out");
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
        (
            timed(&["--name-pattern", FABRIC_PATTERN, "--channel-map", "0,0;0,1"]),
            "--grid",
        ),
        (
            timed(&["--grid", "2x2", "--channel-map", "0,0;0"]),
            "row,col entries separated by `;`",
        ),
        (timed(&["--time-unit", "min"]), "`ms`, `s` or `us`"),
        (timed(&["--baseline", "mean"]), "`none` or `min`"),
        (
            timed(&["--channels", "^(bad"]),
            "not a valid regular expression",
        ),
        (
            timed(&["--name-pattern", FABRIC_PATTERN, "--channels", "^ch[0-9]$"]),
            "no channel columns selected by --channels `^ch[0-9]$` (columns: timestamp, channel",
        ),
        (csv(&["--name-pattern", FABRIC_PATTERN]), "--fs"),
        (csv(&["--fs", "-1"]), "from 1 to 1e6"),
    ];
    dir.fails_each(&cases, &out);
    // --skip-bad leaving every file out says why the first was
    let err = dir.fails(&timed(&[
        "--name-pattern",
        "{label}-{trial}.csv",
        "--skip-bad",
    ]));
    assert!(
        err.contains("with --skip-bad); the first: ") && err.contains("does not match"),
        "{err}"
    );
    assert!(!out.exists());
    // --skip-bad leaves the NaN file out with a warning and imports the rest
    let run = dir.run(&timed(&["--name-pattern", FABRIC_PATTERN, "--skip-bad"]));
    assert!(run.status.success());
    assert!(run.stderr.contains("left out"));
    assert_eq!(
        std::fs::read_to_string(out.join("manifest.csv"))
            .unwrap()
            .lines()
            .count(),
        2
    );

    // stacked: shape/axes mismatch and labels of the wrong length
    let data = ndarray::Array::from_elem(ndarray::IxDyn(&[3, 10, 2, 2]), 1.0f32);
    write_npy(dir.join("x.npy"), &data).unwrap();
    write_npy(dir.join("y.npy"), &ndarray::Array1::from(vec![0i64, 1])).unwrap();
    let x = dir.join("x.npy");
    let y = dir.join("y.npy");
    let st = dir.join("st");
    let stacked = |axes: &str, fs: &str| {
        dir.fails(&[
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
    let err = stacked("n,t,q", "100");
    assert!(
        err.contains("axes are named n, t, row, col or channel"),
        "{err}"
    );
    assert!(!st.exists());
}

/// A headerless `;` log at about 35.7 Hz: host stamp (ms), a proximity column, then
/// `channels` taxels; the stamp of rows 3 and 4 repeats with other values, and the last
/// row is written twice.
fn raw_log(rows: usize, channels: usize, offset: f64) -> String {
    let mut text = String::new();
    let line = |stamp: usize, k: usize| {
        let values: Vec<String> = (0..channels)
            .map(|c| format!("{}", offset + (k * 3 + c) as f64))
            .collect();
        format!("{};65535;{}\n", 1000 + 28 * stamp, values.join(";"))
    };
    for k in 0..rows {
        let stamp = if k == 4 { 3 } else { k };
        text.push_str(&line(stamp, k));
    }
    text.push_str(&line(rows - 1, rows - 1));
    text
}

#[test]
fn headerless_semicolon_logs_with_brackets_in_their_names_import() {
    let dir = Dir::new();
    let src = dir.join("logs");
    std::fs::create_dir(&src).unwrap();
    for (texture, speed) in [("003", "2400"), ("017", "1200")] {
        let name = format!("Data[Texture({texture})][Speed({speed})][Force(1.0)][Trial(1)].csv");
        std::fs::write(src.join(name), raw_log(40, 4, 10.0)).unwrap();
    }
    let pattern = "Data[Texture({label})][Speed({speed})][Force({force})][Trial({trial})].csv";
    let out = dir.join("ds");
    let args = |delimiter: &'static [&'static str], out: &'static str| -> Vec<String> {
        let mut v: Vec<String> = ["import", "csv", "logs", "--out", out, "--no-header"]
            .iter()
            .map(|x| x.to_string())
            .collect();
        v.extend(delimiter.iter().map(|x| x.to_string()));
        v.extend(
            [
                "--time-column",
                "0",
                "--channels",
                "2-5",
                "--grid",
                "2x2",
                "--name-pattern",
                pattern,
            ]
            .iter()
            .map(|x| x.to_string()),
        );
        v
    };
    let given = args(&["--delimiter", ";"], "ds");
    let run = dir.run(&given.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(run.status.success(), "{}", run.stderr);
    // per file: one row merged into the frame of its stamp, one exact duplicate dropped
    assert!(
        run.stderr.contains(
            "Data[Texture(003)][Speed(2400)][Force(1.0)][Trial(1)].csv: 1 row(s) sharing a time stamp merged, 1 exact duplicate row(s) dropped"
        ),
        "{}",
        run.stderr
    );
    assert!(run.stderr.contains("2 recordings"), "{}", run.stderr);
    let manifest = std::fs::read_to_string(out.join("manifest.csv")).unwrap();
    assert!(
        manifest.contains("[Speed(2400)]") && manifest.contains(",003,2400,1,1"),
        "{manifest}"
    );
    let layout = std::fs::read_to_string(out.join("layout.toml")).unwrap();
    assert!(
        layout.contains(r#"channels = ["column2", "column3", "column4", "column5"]"#),
        "{layout}"
    );
    // 40 rows with one repeated stamp and one repeated row: 39 frames; row 4 (stamp 3)
    // averages with row 3
    let file = out.join("Data[Texture(003)][Speed(2400)][Force(1.0)][Trial(1)].csv");
    let text = std::fs::read_to_string(file).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 1 + 39, "{text}");
    assert_eq!(lines[0], "t_ms,column2,column3,column4,column5");
    assert_eq!(lines[4], "84,20.5,21.5,22.5,23.5", "{text}");
    // the delimiter is detected when not given, with the same result
    let detected = args(&[], "ds2");
    dir.ok(&detected.iter().map(String::as_str).collect::<Vec<_>>());
    let again = std::fs::read_to_string(
        dir.join("ds2/Data[Texture(003)][Speed(2400)][Force(1.0)][Trial(1)].csv"),
    )
    .unwrap();
    assert_eq!(again, text);
    // a recording of the imported dataset encodes with the layout beside it: 2x2 taxels,
    // stamps from 0 to 39 x 28 ms (one missing) resampled to 1 ms
    let spikes = dir.join("spikes.npy");
    let run = dir.run(&[
        "encode",
        "ds/Data[Texture(003)][Speed(2400)][Force(1.0)][Trial(1)].csv",
        "--out",
        s(&spikes),
    ]);
    assert!(run.status.success(), "{}", run.stderr);
    assert!(run.stderr.contains("layout beside"), "{}", run.stderr);
    let raster: ndarray::Array3<u8> = ndarray_npy::read_npy(&spikes).unwrap();
    assert_eq!(raster.shape(), &[39 * 28 + 1, 2, 2]);
}

#[test]
fn repeated_stamps_can_be_refused_or_kept_first_or_last() {
    let dir = Dir::new();
    let src = dir.join("logs");
    std::fs::create_dir(&src).unwrap();
    std::fs::write(src.join("A_1.csv"), raw_log(20, 2, 0.0)).unwrap();
    let import = |policy: &str, out: &str| {
        dir.run(&[
            "import",
            "csv",
            "logs",
            "--out",
            out,
            "--no-header",
            "--time-column",
            "0",
            "--channels",
            "2,3",
            "--duplicate-stamps",
            policy,
            "--name-pattern",
            "{label}_{trial}.csv",
        ])
    };
    let run = import("error", "e");
    let err = run.stderr;
    assert_eq!(run.status.code(), Some(1), "{err}");
    assert!(
        err.contains("A_1.csv") && err.contains("line 5") && err.contains("repeats line 4"),
        "{err}"
    );
    assert!(!dir.join("e").exists());
    for (policy, expected) in [("first", "84,9,10"), ("last", "84,12,13")] {
        let run = import(policy, policy);
        assert!(run.status.success(), "{}", run.stderr);
        let text = std::fs::read_to_string(dir.join(policy).join("A_1.csv")).unwrap();
        assert_eq!(text.lines().nth(4), Some(expected), "{policy}: {text}");
    }
}

#[test]
fn bad_csv_reading_options_are_named() {
    let dir = Dir::new();
    let src = dir.join("logs");
    std::fs::create_dir(&src).unwrap();
    std::fs::write(src.join("A_1.csv"), raw_log(20, 2, 0.0)).unwrap();
    std::fs::write(dir.join("B_1.csv"), "t;a\n0;1\n10;2\n5;3\n").unwrap();
    let out = dir.join("out");
    let o = s(&out);
    let with = |extra: &[&'static str]| -> Vec<&str> {
        let mut v = vec!["import", "csv", "logs", "--out", o, "--fs", "100"];
        v.extend_from_slice(extra);
        v
    };
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (with(&["--delimiter", "|"]), "`,`, `;` or `tab`"),
        (with(&["--duplicate-stamps", "mean"]), "`average`, `first`"),
        (with(&["--channels", "5-2"]), "FIRST <= LAST"),
        (with(&["--channels", "0-999999999"]), "at most 65536"),
        (
            with(&["--no-header", "--channels", r"^c\d$"]),
            "not a regular expression",
        ),
        (
            with(&["--no-header", "--time-column", "stamp"]),
            "0-based index, got `stamp`",
        ),
        (
            with(&["--no-header", "--channels", "2-9"]),
            "channel column 4 (0-based) does not exist",
        ),
        (
            with(&["--no-header", "--time-column", "0", "--channels", "0-3"]),
            "both the time and a channel",
        ),
        // a header row read as data names its line and column
        (
            vec![
                "import",
                "csv",
                "B_1.csv",
                "--out",
                o,
                "--no-header",
                "--fs",
                "100",
            ],
            "line 1, column `column0`: expected a finite number, got `t`",
        ),
        (
            vec!["import", "csv", "B_1.csv", "--out", o, "--time-column", "t"],
            "line 4: time stamps must not go back",
        ),
    ];
    dir.fails_each(&cases, &out);
}

#[test]
fn a_hundred_field_name_pattern_is_matched_quickly() {
    let dir = Dir::new();
    let src = dir.join("logs");
    std::fs::create_dir(&src).unwrap();
    // `a_` a hundred times: the old backtracking matcher took over a minute on the
    // name that almost matches
    let good = "a_".repeat(100) + "x.q.csv";
    let almost = "a_".repeat(100) + "y.q.csv";
    for name in [&good, &almost] {
        std::fs::write(src.join(name), "t,c\n0,1\n10,2\n").unwrap();
    }
    let pattern: String =
        (0..100).map(|k| format!("{{f{k}}}_")).collect::<String>() + "x.{label}.csv";
    let out = dir.join("ds");
    let start = std::time::Instant::now();
    let run = dir.run(&[
        "import",
        "csv",
        "logs",
        "--out",
        s(&out),
        "--time-column",
        "t",
        "--name-pattern",
        &pattern,
        "--skip-bad",
    ]);
    let took = start.elapsed().as_secs_f64();
    assert!(run.status.success(), "{}", run.stderr);
    assert!(
        run.stderr.contains("1 recordings (1 left out"),
        "{}",
        run.stderr
    );
    assert!(took < 5.0, "the import took {took} s");
}

#[test]
fn import_warns_of_labels_differing_in_case_and_of_logs_without_signal() {
    let dir = Dir::new();
    let logs = dir.join("logs");
    std::fs::create_dir(&logs).unwrap();
    // Four channels at 100 Hz: a ramp of its own per log, or one value throughout.
    let log = |step: f64| -> String {
        let rows = (0..300).map(|k| {
            let v = |c: usize| 7.0 + step * (k * 4 + c) as f64;
            format!("{},{},{},{}\n", v(0), v(1), v(2), v(3))
        });
        std::iter::once("a,b,c,d\n".to_string())
            .chain(rows)
            .collect()
    };
    let names = [
        "rough_1", "rough_2", "Rough_3", "smooth_1", "smooth_2", "smooth_3",
    ];
    for (k, name) in names.iter().enumerate() {
        std::fs::write(logs.join(format!("{name}.csv")), log(1.0 + k as f64)).unwrap();
    }
    std::fs::write(logs.join("smooth_4.csv"), log(0.0)).unwrap();
    let out = dir.join("ds");
    let args = ["import", "csv", s(&logs), "--out", s(&out), "--fs", "100"];
    let pattern = ["--name-pattern", "{label}_{trial}.csv", "--grid", "2x2"];
    let run = dir.run(&[&args[..], &pattern[..]].concat());
    assert!(run.status.success(), "{}", run.stderr);
    assert!(
        run.stderr.contains(
            "warning: labels `Rough` and `rough` differ only in case: they are 2 classes"
        ),
        "{}",
        run.stderr
    );
    assert!(
        run.stderr.contains("warning: 1 log holds no signal, every channel one value from start to end (`smooth_4.csv`)"),
        "{}",
        run.stderr
    );
}
