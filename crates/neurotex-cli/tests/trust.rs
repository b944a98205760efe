//! Inputs that used to give a wrong number without a word: each is now flagged, refused or
//! handled, through the binary.

use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::util::{relabel, s, xorshift, Dir};

/// Writes event logs `t_us,x,y,p` of two textures x `trials` into `logs`: 2 s of events on
/// a 2x2 grid (texture A's ON events on the left column, B's on the right), each log's
/// stamps starting `lead_s(trial)` seconds after the clock's zero.
fn clock_logs(dir: &Dir, lead_s: &dyn Fn(usize) -> f64, trials: usize) -> PathBuf {
    let logs = dir.join("logs");
    std::fs::create_dir_all(&logs).unwrap();
    for (k, label) in ["A", "B"].iter().enumerate() {
        for trial in 0..trials {
            let mut random = xorshift((k * 100 + trial) as u64);
            let start = (lead_s(trial) * 1e6) as u64;
            let mut log = String::from("t,x,y,p\n");
            let mut t = start;
            while t < start + 2_000_000 {
                t += 1_000 + random() % 20_000;
                let (x, y) = (random() % 2, random() % 2);
                let p = u64::from(x == k as u64);
                log.push_str(&format!("{t},{x},{y},{p}\n"));
            }
            std::fs::write(logs.join(format!("{label}_{trial}.csv")), log).unwrap();
        }
    }
    logs
}

/// `import events` of the clock logs in `logs` into `out`, and `extra`.
fn import_events_args<'a>(logs: &'a Path, out: &'a Path, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec![
        "import",
        "events",
        s(logs),
        "--out",
        s(out),
        "--grid",
        "2x2",
        "--time-unit",
        "us",
        "--name-pattern",
        "{label}_{trial}.csv",
    ];
    args.extend_from_slice(extra);
    args
}

fn import_events(dir: &Dir, logs: &Path, name: &str, extra: &[&str]) -> (PathBuf, String) {
    let out = dir.join(name);
    let run = dir.run(&import_events_args(logs, &out, extra));
    assert!(run.status.success(), "{}", run.stderr);
    (out, run.stderr)
}

/// The same import, which must fail; what it says on standard error.
fn import_events_fails(dir: &Dir, logs: &Path) -> String {
    dir.fails(&import_events_args(logs, &dir.join("ev"), &[]))
}

fn finding_codes(dir: &Dir, dataset: &Path) -> Vec<String> {
    let json: Value =
        serde_json::from_str(&dir.ok(&["inspect", s(dataset), "--json"])).expect("JSON");
    json["findings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["code"].as_str().unwrap().to_string())
        .collect()
}

#[test]
fn event_logs_stamped_by_a_sensor_clock_are_flagged_with_the_origin_as_the_fix() {
    let dir = Dir::new();
    // Stamps from a clock started 1 to 9 s before each trial.
    let logs = clock_logs(&dir, &|trial| 1.0 + (trial * 37 % 9) as f64, 6);
    let (zero, said) = import_events(&dir, &logs, "zero", &[]);
    assert!(
        said.contains("the first event comes") && said.contains("--origin first"),
        "{said}"
    );
    assert!(finding_codes(&dir, &zero).contains(&"late-first-events".to_string()));
    let text = dir.ok(&["inspect", s(&zero)]);
    assert!(text.contains("origin = \"first\""), "{text}");
    // The fix the finding names removes it.
    let (first, said) = import_events(&dir, &logs, "first", &["--origin", "first"]);
    assert!(!said.contains("the first event comes"), "{said}");
    assert!(!finding_codes(&dir, &first).contains(&"late-first-events".to_string()));
    // Logs whose clock starts with the trial are not flagged.
    let dir = Dir::new();
    let logs = clock_logs(&dir, &|_| 0.0, 6);
    let (prompt, said) = import_events(&dir, &logs, "prompt", &[]);
    assert!(!said.contains("the first event comes"), "{said}");
    assert!(!finding_codes(&dir, &prompt).contains(&"late-first-events".to_string()));
}

#[test]
fn raw_event_logs_are_pointed_to_import_events_not_read_as_samples() {
    let dir = Dir::new();
    let logs = clock_logs(&dir, &|_| 0.0, 2);
    for header in ["t,x,y,p", "timestamp,x,y,polarity", "t_us,taxel,pol"] {
        let log = dir.join("event_log.csv");
        let fields = header.split(',').count();
        let mut text = format!("{header}\n");
        for i in 0..50 {
            let line: Vec<String> = (0..fields)
                .map(|f| (i * 17 + f) % 2)
                .map(|v| v.to_string())
                .collect();
            text.push_str(&format!("{},{}\n", i * 1000, line[1..].join(",")));
        }
        std::fs::write(&log, text).unwrap();
        let err = dir.fails(&["inspect", s(&log), "--time-column", "0"]);
        assert!(err.contains("neurotex import events"), "{header}: {err}");
        let out = dir.join("imported");
        let err = dir.fails(&[
            "import",
            "csv",
            s(&log),
            "--out",
            s(&out),
            "--time-column",
            "0",
        ]);
        assert!(err.contains("neurotex import events"), "{header}: {err}");
        assert!(!out.exists());
    }
    let err = dir.fails(&["inspect", s(&logs)]);
    assert!(err.contains("address event"), "{err}");
}

#[test]
fn a_log_without_a_time_column_chosen_is_told_which_column_holds_time() {
    let dir = Dir::new();
    let log = dir.join("trial.csv");
    let mut text = String::from("timestamp,left,right\n");
    for i in 0..400 {
        text.push_str(&format!("{},{},{}\n", i * 2, i % 7, i % 5));
    }
    std::fs::write(&log, text).unwrap();
    let err = dir.fails(&["inspect", s(&log)]);
    assert!(err.contains("--time-column timestamp"), "{err}");
    assert!(!err.contains("--fs is needed"), "{err}");
    // And the advice works.
    dir.ok(&[
        "inspect",
        s(&log),
        "--time-column",
        "timestamp",
        "--no-encoder",
    ]);
}

/// Adds to each recording of `data` a resting level of its own, up to `factor` times the
/// recording's range, and one per taxel: a capacitive skin whose rest drifts between
/// recordings.
fn drift_offsets(data: &Path, factor: f32) {
    use ndarray::Array3;
    use ndarray_npy::{read_npy, write_npy};
    let mut random = xorshift(11);
    let mut unit = move || (random() % 1_000_000) as f32 / 1e6;
    for (file, _, _) in crate::stream::slides(data) {
        let path = data.join(&file);
        let x: Array3<f32> = read_npy(&path).unwrap();
        let span =
            x.fold(f32::NEG_INFINITY, |a, &b| a.max(b)) - x.fold(f32::INFINITY, |a, &b| a.min(b));
        let level = 2.0 + factor * span * unit();
        let taxel: Vec<f32> = (0..16).map(|_| 0.1 * span * unit()).collect();
        let y = Array3::from_shape_fn(x.dim(), |(t, r, c)| x[[t, r, c]] + level + taxel[r * 4 + c]);
        write_npy(&path, &y).unwrap();
    }
}

#[test]
fn a_drift_window_tracks_rest_identically_in_the_stream_and_predict_causal() {
    let dir = Dir::new();
    // Trained on the simulator's recordings, whose rest is 0; then every recording's rest
    // moves by up to 10 times its signal. A 2 s window, shorter than the 9 s slides, so
    // the window's blocks are replaced as the slide goes on.
    let (data, model) = crate::stream::trained(&dir, &["--drift-window-s", "2"]);
    let saved: Value = serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
    assert_eq!(
        saved["pipeline"]["preprocess"]["drift_window_ms"], 2000,
        "{saved}"
    );
    drift_offsets(&data, 10.0);
    let all = crate::stream::slides(&data);
    for row in [&all[0], &all[5]] {
        let expected = crate::stream::predicted(&dir, &model, &data, &row.0);
        assert!(expected.len() > 40, "a bin every 200 ms of a 9 s slide");
        let frames = crate::stream::slide_frames(&data, row);
        let csv = dir.join("slide.csv");
        std::fs::write(&csv, crate::stream::csv_text(&frames)).unwrap();
        let text = dir.ok(&["stream", "--model", s(&model), "--input", s(&csv)]);
        assert_eq!(crate::stream::lines(&text), expected, "{}", row.0);
    }
    // A window without causal conditioning would go unused: refused.
    let err = dir.fails(&[
        "evaluate",
        "--dataset",
        s(&data),
        "--method",
        "glcm3d",
        "--drift-window-s",
        "2",
    ]);
    assert!(err.contains("needs --causal"), "{err}");
    let err = dir.fails(&[
        "evaluate",
        "--dataset",
        s(&data),
        "--method",
        "glcm3d",
        "--causal",
        "--drift-window-s",
        "0.25",
    ]);
    assert!(err.contains("multiple of 0.1 s"), "{err}");
}

fn small_simulation(dir: &Dir) -> PathBuf {
    let data = dir.join("sim");
    let args = ["--trials", "4", "--speeds", "10", "--textures", "FT1,SB,CP"];
    let mut all = vec!["simulate", "--out", s(&data)];
    all.extend_from_slice(&args);
    dir.ok(&all);
    data
}

#[test]
fn resting_levels_that_move_between_recordings_are_found_and_not_blamed_on_the_gain() {
    let dir = Dir::new();
    let data = small_simulation(&dir);
    assert!(!finding_codes(&dir, &data).contains(&"drifting-rest".to_string()));
    drift_offsets(&data, 10.0);
    std::fs::write(data.join("layout.toml"), "baseline = { kind = \"min\" }\n").unwrap();
    assert!(finding_codes(&dir, &data).contains(&"drifting-rest".to_string()));
    let run = dir.run(&[
        "evaluate",
        "--dataset",
        s(&data),
        "--method",
        "glcm3d",
        "--causal",
        "--folds",
        "2",
        "--k",
        "1",
    ]);
    assert!(run.status.success(), "{}", run.stderr);
    assert!(run.stderr.contains("--drift-window-s"), "{}", run.stderr);
    // inspect judges the offline conditioning: a causal option there would go unused.
    let err = dir.fails(&["inspect", s(&data), "--causal"]);
    assert!(err.contains("drifting-rest"), "{err}");
}

#[test]
fn samples_beyond_any_sensor_are_refused_by_readers_and_skipped_by_streams() {
    use ndarray_npy::{read_npy, write_npy};
    let dir = Dir::new();
    let data = dir.dataset("ds", &["A", "B"], &[5.0], 3);
    // One corrupted word inside a recording: 1e308, and one beyond f32's range as f64.
    let file = data.join("A_5_0.npy");
    let mut x: ndarray::Array3<f32> = read_npy(&file).unwrap();
    x[[700, 1, 2]] = f32::MAX;
    write_npy(&file, &x).unwrap();
    let out = dir.join("features.csv");
    let err = dir.fails(&[
        "features",
        "--dataset",
        s(&data),
        "--method",
        "taxel",
        "--out",
        s(&out),
    ]);
    assert!(
        err.contains("A_5_0.npy") && err.contains("sample 700 of channel 6"),
        "{err}"
    );
    assert!(err.contains("±1e15"), "{err}");
    assert!(!out.exists());
    // The same in a CSV log, in import csv and encode.
    let log = dir.join("log.csv");
    let mut text = String::from("t_ms,a,b\n");
    for i in 0..300 {
        let b = if i == 150 {
            "1e308".to_string()
        } else {
            format!("{}", i % 9)
        };
        text.push_str(&format!("{i},{},{b}\n", i % 7));
    }
    std::fs::write(&log, &text).unwrap();
    let imported = dir.join("imported");
    let err = dir.fails(&[
        "import",
        "csv",
        s(&log),
        "--out",
        s(&imported),
        "--time-column",
        "t_ms",
    ]);
    assert!(
        err.contains("line 152, column `b`") && err.contains("±1e15"),
        "{err}"
    );
    assert!(!imported.exists());
    let spikes = dir.join("spikes.npy");
    let err = dir.fails(&[
        "encode",
        s(&log),
        "--out",
        s(&spikes),
        "--time-column",
        "t_ms",
    ]);
    assert!(err.contains("±1e15"), "{err}");
    // A stream counts such a frame as bad and goes on.
    let (sim, model) = crate::stream::trained(&dir, &[]);
    let row = &crate::stream::slides(&sim)[0];
    let mut frames = crate::stream::slide_frames(&sim, row);
    let clean = crate::stream::csv_text(&frames);
    let clean_lines = dir.ok(&[
        "stream",
        "--model",
        s(&model),
        "--input",
        s(&write(&dir, "clean.csv", &clean)),
    ]);
    frames.insert(500, vec![1e30; 16]);
    let glitch = crate::stream::csv_text(&frames);
    let run = dir.run(&[
        "stream",
        "--model",
        s(&model),
        "--input",
        s(&write(&dir, "glitch.csv", &glitch)),
    ]);
    assert!(run.status.success(), "{}", run.stderr);
    assert!(run.stderr.contains("beyond ±1e15"), "{}", run.stderr);
    let last: Value = serde_json::from_str(run.stdout.lines().last().unwrap()).unwrap();
    assert_eq!(last["bad_frames"], 1, "{last}");
    let decided = |text: &str| -> Vec<Value> {
        text.lines()
            .map(|l| {
                let mut v: Value = serde_json::from_str(l).unwrap();
                v.as_object_mut().unwrap().remove("bad_frames");
                v
            })
            .collect()
    };
    assert_eq!(decided(&run.stdout), decided(&clean_lines));
}

fn write(dir: &Dir, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn numeric_labels_never_merge_and_a_grid_the_axes_fix_is_refused() {
    use ndarray_npy::write_npy;
    let dir = Dir::new();
    let x = dir.join("x.npy");
    write_npy(
        &x,
        &ndarray::Array::from_elem(ndarray::IxDyn(&[4, 300, 2, 2]), 1.0f32),
    )
    .unwrap();
    let labels = dir.join("y.npy");
    let import = |labels: &Path, out: &Path, extra: &[&str]| {
        let mut args = vec![
            "import",
            "stacked",
            "--data",
            s(&x),
            "--labels",
            s(labels),
            "--axes",
            "n,t,row,col",
            "--fs",
            "1000",
            "--out",
            s(out),
        ];
        args.extend_from_slice(extra);
        dir.run(&args)
    };
    // Integers beyond 2^53 stay distinct.
    let big = [u64::MAX, u64::MAX - 1, u64::MAX, u64::MAX - 1];
    write_npy(&labels, &ndarray::Array1::from(big.to_vec())).unwrap();
    let out = dir.join("big");
    let run = import(&labels, &out, &[]);
    assert!(run.status.success(), "{}", run.stderr);
    let manifest = std::fs::read_to_string(out.join("manifest.csv")).unwrap();
    assert!(
        manifest.contains("18446744073709551615") && manifest.contains("18446744073709551614"),
        "{manifest}"
    );
    // Floats that cannot hold them are refused.
    write_npy(
        &labels,
        &ndarray::Array1::from(vec![1e300, 2e300, 1e300, 2e300]),
    )
    .unwrap();
    let out = dir.join("floats");
    let run = import(&labels, &out, &[]);
    assert!(!run.status.success());
    assert!(
        run.stderr.contains("label 0 is 1e300") && run.stderr.contains("2^53"),
        "{}",
        run.stderr
    );
    assert!(!out.exists());
    // --grid with row and col axes would go unused.
    write_npy(&labels, &ndarray::Array1::from(vec![0i64, 1, 0, 1])).unwrap();
    let out = dir.join("grid");
    let run = import(&labels, &out, &["--grid", "1x4"]);
    assert!(!run.status.success());
    assert!(
        run.stderr.contains("has its grid already"),
        "{}",
        run.stderr
    );
    assert!(!out.exists());
}

#[test]
fn a_broken_layout_or_model_file_is_told_in_its_own_words() {
    let dir = Dir::new();
    let data = dir.dataset("ds", &["A", "B"], &[5.0], 3);
    std::fs::write(data.join("layout.toml"), "rows = 4\nbaseline = \"min\"\n").unwrap();
    let err = dir.fails(&[
        "features",
        "--dataset",
        s(&data),
        "--method",
        "taxel",
        "--out",
        "f.csv",
    ]);
    assert!(err.contains("line 2 (`baseline = \"min\"`)"), "{err}");
    assert!(
        !err.contains("TOML parse error") && !err.contains("internally tagged"),
        "{err}"
    );
    std::fs::remove_file(data.join("layout.toml")).unwrap();
    let model = dir.join("model.json");
    dir.ok(&[
        "train",
        "--dataset",
        s(&data),
        "--method",
        "taxel",
        "--out",
        s(&model),
    ]);
    let text = std::fs::read_to_string(&model).unwrap();
    let broken = text.replacen("\"labels\": [", "\"labels\": {", 1);
    assert_ne!(broken, text);
    std::fs::write(&model, broken).unwrap();
    let err = dir.fails(&[
        "predict",
        "--model",
        s(&model),
        "--dataset",
        s(&data),
        "--out",
        "p.csv",
    ]);
    assert!(
        err.contains(", column ") && err.contains(": line "),
        "{err}"
    );
    assert!(!err.contains(" at line "), "{err}");
}

#[test]
fn a_headerless_stream_keeps_its_first_frame_even_at_rest() {
    let dir = Dir::new();
    let (sim, model) = crate::stream::trained(&dir, &[]);
    let row = &crate::stream::slides(&sim)[0];
    let mut frames = crate::stream::slide_frames(&sim, row);
    frames[0] = vec![0.0; 16];
    let text = crate::stream::csv_text(&frames);
    let body = text.split_once('\n').unwrap().1;
    let input = write(&dir, "headerless.csv", body);
    let read = dir.ok(&["stream", "--model", s(&model), "--input", s(&input)]);
    let told = dir.ok(&[
        "stream",
        "--model",
        s(&model),
        "--input",
        s(&input),
        "--no-header",
    ]);
    assert_eq!(read, told);
    let last: Value = serde_json::from_str(read.lines().last().unwrap()).unwrap();
    assert_eq!(last["bad_frames"], 0, "{last}");
}

#[test]
fn labels_never_reach_the_terminal_raw_and_inspect_refuses_what_it_cannot_honour() {
    let dir = Dir::new();
    let data = dir.dataset("ds", &["A", "B"], &[5.0], 3);
    let manifest = std::fs::read_to_string(data.join("manifest.csv")).unwrap();
    std::fs::write(
        data.join("manifest.csv"),
        manifest.replace(",B,", ",\"B\u{1b}[31m\u{7}\","),
    )
    .unwrap();
    let out = dir.ok(&[
        "evaluate",
        "--dataset",
        s(&data),
        "--method",
        "taxel",
        "--folds",
        "2",
        "--k",
        "1",
    ]);
    assert!(!out.contains('\u{1b}') && !out.contains('\u{7}'), "{out:?}");
    assert!(out.contains("B\\u{1b}[31m\\u{7}"), "{out}");
    let err = dir.fails(&["inspect", s(&data), "--out", "-"]);
    assert!(err.contains("standard output takes one file"), "{err}");
    assert!(!dir.join("-").exists());
    let err = dir.fails(&["inspect", s(&data), "--folds", "0"]);
    assert!(err.contains("at least 2 folds"), "{err}");
    let err = dir.fails(&["inspect", s(&data), "--k", "0"]);
    assert!(err.contains("at least 1 neighbour"), "{err}");
}

/// Logs `t_ms,c0..c15` of a 4x4 grid whose channel `c5` (cell 1,1) holds one value: the
/// other channels carry a wave whose phase follows the cell, so a taxel's place shows.
fn logs_with_a_dead_taxel(dir: &Dir) -> PathBuf {
    let logs = dir.join("dead-logs");
    std::fs::create_dir_all(&logs).unwrap();
    for (label, hz) in [("silk", 3.0), ("felt", 9.0)] {
        for trial in 0..2 {
            let head: Vec<String> = (0..16).map(|i| format!("c{i}")).collect();
            let mut log = format!("t_ms,{}\n", head.join(","));
            for k in 0..400 {
                let t = f64::from(k) / 1000.0;
                let row: Vec<String> = (0..16)
                    .map(|i| match i {
                        5 => "512".to_string(),
                        _ => format!("{:.3}", 500.0 + 90.0 * (hz * t + f64::from(i) * 0.1).sin()),
                    })
                    .collect();
                log.push_str(&format!("{k},{}\n", row.join(",")));
            }
            std::fs::write(logs.join(format!("{label}_{trial}.csv")), log).unwrap();
        }
    }
    logs
}

#[test]
fn a_dead_taxel_of_a_full_grid_is_dropped_with_its_cell_masked_by_one_option() {
    let dir = Dir::new();
    let logs = logs_with_a_dead_taxel(&dir);
    let read = [
        "--time-column",
        "t_ms",
        "--name-pattern",
        "{label}_{trial}.csv",
    ];
    let mut inspect = vec!["inspect", s(&logs), "--grid", "4x4"];
    inspect.extend_from_slice(&read);
    let said = dir.run(&inspect);
    assert!(
        said.stdout.contains("--drop-channels c5"),
        "the dead-channel finding names the option: {}",
        said.stdout
    );
    let out = dir.join("ds");
    let mut import = vec!["import", "csv", s(&logs), "--out", s(&out), "--grid", "4x4"];
    import.extend_from_slice(&read);
    import.extend_from_slice(&["--drop-channels", "c5"]);
    let run = dir.run(&import);
    assert!(run.status.success(), "{}", run.stderr);
    assert!(!run.stderr.contains("fill it row by row"), "{}", run.stderr);
    let layout = std::fs::read_to_string(out.join("layout.toml")).unwrap();
    let line = |key: &str| {
        layout
            .lines()
            .find(|l| l.starts_with(key))
            .unwrap_or_default()
            .to_string()
    };
    assert_eq!(line("mask"), r#"mask = ["1111", "1011", "1111", "1111"]"#);
    // c6, the fifth channel kept, stays in its own cell (1,2), not in c5's (1,1).
    assert!(
        line("channel_map").starts_with(
            "channel_map = [[0, 0], [0, 1], [0, 2], [0, 3], [1, 0], [1, 2], [1, 3], [2, 0]"
        ),
        "{layout}"
    );
    assert!(!line("channels").contains("\"c5\""), "{layout}");
    assert!(
        run.stderr
            .contains("15 channels on a 4x4 grid (1 cell masked)")
            && run
                .stderr
                .contains("dropped channel(s) c5: their cells are masked"),
        "{}",
        run.stderr
    );
    // The dataset reads: a feature run over it goes through.
    let features = dir.join("features.csv");
    dir.ok(&[
        "features",
        "--dataset",
        s(&out),
        "--method",
        "glcm2d",
        "--out",
        s(&features),
    ]);
    // Column indices count as --channels counts them (t_ms is column 0, c5 column 6).
    let by_index = dir.join("ds-index");
    let mut import = vec![
        "import",
        "csv",
        s(&logs),
        "--out",
        s(&by_index),
        "--grid",
        "4x4",
    ];
    import.extend_from_slice(&read);
    import.extend_from_slice(&["--drop-channels", "6"]);
    dir.ok(&import);
    let again = std::fs::read_to_string(by_index.join("layout.toml")).unwrap();
    assert!(again.contains(&line("mask")), "{again}");
    // A name that is not a channel, or every channel, is refused by name.
    let no = dir.join("no");
    for (drop, says) in [
        ("t_ms", "the channels are"),
        ("c99", "`c99`"),
        ("^c", "at least one"),
    ] {
        let mut import = vec!["import", "csv", s(&logs), "--out", s(&no), "--grid", "4x4"];
        import.extend_from_slice(&read);
        import.extend_from_slice(&["--drop-channels", drop]);
        let run = dir.run(&import);
        assert!(
            !run.status.success() && run.stderr.contains(says),
            "{drop}: {}",
            run.stderr
        );
        assert!(!no.exists());
    }
    // A channel map must place every channel, the dropped ones too.
    let mut import = vec!["import", "csv", s(&logs), "--out", s(&no), "--grid", "4x4"];
    import.extend_from_slice(&read);
    import.extend_from_slice(&["--channel-map", "0,0;0,1", "--drop-channels", "c5"]);
    let err = dir.fails(&import);
    assert!(err.contains("2 cells for 16 channels"), "{err}");
    assert!(!no.exists());
}

#[test]
fn the_check_at_a_workflows_start_reads_a_bounded_sample_and_says_so() {
    let dir = Dir::new();
    let data = dir.join("sim");
    let args = [
        "--trials",
        "12",
        "--speeds",
        "10",
        "--textures",
        "FT1,SB,CP",
    ];
    let mut all = vec!["simulate", "--out", s(&data)];
    all.extend_from_slice(&args);
    dir.ok(&all);
    drift_offsets(&data, 10.0);
    std::fs::write(data.join("layout.toml"), "").unwrap();
    let out = dir.join("features.csv");
    let run = dir.run(&[
        "features",
        "--dataset",
        s(&data),
        "--method",
        "glcm3d",
        "--out",
        s(&out),
    ]);
    assert!(run.status.success(), "{}", run.stderr);
    assert!(
        run.stderr.contains("resting offset")
            && run.stderr.contains("checked on 32 of the 36 recordings"),
        "{}",
        run.stderr
    );
}

/// Writes four two-channel CSV logs `{label}_{trial}.csv` (300 ms at 1 kHz) into `logs`.
fn two_channel_logs(dir: &Dir) -> PathBuf {
    let logs = dir.join("csv_logs");
    std::fs::create_dir_all(&logs).unwrap();
    for name in ["A_0", "A_1", "B_0", "B_1"] {
        std::fs::write(logs.join(format!("{name}.csv")), text_of_log()).unwrap();
    }
    logs
}

/// `import csv` of the logs `{label}_{trial}.csv` in `logs` into `out`, stamped in the
/// column `time`.
fn import_csv_args<'a>(logs: &'a Path, out: &'a Path, time: &'a str) -> Vec<&'a str> {
    let pattern = ["--name-pattern", "{label}_{trial}.csv"];
    let mut args = vec!["import", "csv", s(logs), "--out", s(out)];
    args.extend_from_slice(&pattern);
    args.extend_from_slice(&["--time-column", time]);
    args
}

#[test]
fn a_ragged_line_is_told_by_its_line_and_field_counts() {
    let dir = Dir::new();
    let logs = two_channel_logs(&dir);
    let ragged = logs.join("A_1.csv");
    let text = std::fs::read_to_string(&ragged).unwrap();
    std::fs::write(&ragged, text.replacen("\n5,5,0\n", "\n5,5\n", 1)).unwrap();
    let out = dir.join("ds");
    let args = import_csv_args(&logs, &out, "t_ms");
    let err = dir.fails(&args);
    assert!(
        err.contains("A_1.csv: line 7 has 2 field(s) where the header has 3"),
        "{err}"
    );
    assert!(
        !err.contains("previous record") && !err.contains("byte"),
        "{err}"
    );
    // An event log's ragged line in the same words.
    let events = clock_logs(&dir, &|_| 0.0, 2);
    let log = events.join("B_1.csv");
    let mut text = std::fs::read_to_string(&log).unwrap();
    text.push_str("99999999,1,1\n");
    let line = text.lines().count();
    std::fs::write(&log, text).unwrap();
    let err = import_events_fails(&dir, &events);
    let said = format!("line {line} has 3 field(s) where the header has 4");
    assert!(err.contains(&said), "{err}");
    // A blank line just before the ragged one leaves its line number as it is in the
    // file (the CSV reader counts the blank line into the record's position).
    let text = std::fs::read_to_string(&log).unwrap();
    let (head, last) = text.trim_end().rsplit_once('\n').unwrap();
    std::fs::write(&log, format!("{head}\n\n{last}\n")).unwrap();
    let err = import_events_fails(&dir, &events);
    let said = format!("line {} has 3 field(s) where the header has 4", line + 1);
    assert!(err.contains(&said), "{err}");
    let text = std::fs::read_to_string(&ragged).unwrap();
    std::fs::write(&ragged, text.replacen("\n5,5\n", "\n\n5,5\n", 1)).unwrap();
    let err = dir.fails(&args);
    assert!(
        err.contains("A_1.csv: line 8 has 2 field(s) where the header has 3"),
        "{err}"
    );
}

#[test]
fn a_bad_count_an_absurd_rate_or_a_missing_column_is_told_plainly() {
    let dir = Dir::new();
    let logs = two_channel_logs(&dir);
    let out = dir.join("ds");
    dir.ok(&import_csv_args(&logs, &out, "t_ms"));
    // A count given as a negative number, as an option and in a layout file.
    let data = s(&out);
    let err = dir.fails(&["evaluate", "--dataset", data, "--folds=-1"]);
    assert!(
        err.contains("'-1' for '--folds") && err.contains("whole number"),
        "{err}"
    );
    assert!(!err.contains("invalid digit"), "{err}");
    let layout = std::fs::read_to_string(out.join("layout.toml")).unwrap();
    let broken = layout.replacen("rows = 1", "rows = -1", 1);
    assert_ne!(broken, layout);
    std::fs::write(out.join("layout.toml"), &broken).unwrap();
    let err = dir.fails(&["inspect", data]);
    assert!(
        err.contains("`-1` where a whole number, 0 or more was expected"),
        "{err}"
    );
    assert!(!err.contains("usize"), "{err}");
    // A rate no sensor has, refused where it is given, with the range.
    let fs = layout.replacen("fs = ", "fs = 1e12 # ", 1);
    std::fs::write(out.join("layout.toml"), fs).unwrap();
    let err = dir.fails(&["inspect", data]);
    assert!(
        err.contains("layout.toml: field `fs`") && err.contains("from 1 to 1e6"),
        "{err}"
    );
    let npy = dir.dataset("npy", &["A", "B"], &[5.0], 3);
    let one = npy.join("A_5_0.npy");
    let err = dir.fails(&["encode", s(&one), "--fs", "1e-9", "--out", "x.npy"]);
    assert!(
        err.contains("from 1 to 1e6") && err.contains("--fs"),
        "{err}"
    );
    // A protocol's column the manifest lacks, with the columns it has.
    let mut args = vec!["compare", "--dataset", s(&npy), "--per", "session"];
    args.extend_from_slice(&["--methods", "glcm3d", "--classifiers", "knn", "--k", "1"]);
    let err = dir.fails(&args);
    assert!(
        err.contains("session, which no recording has a value in (columns with values: file, label, speed_mm_s"),
        "{err}"
    );
}

#[test]
fn a_loggers_microseconds_are_not_taken_for_milliseconds() {
    let dir = Dir::new();
    let logs = two_channel_logs(&dir);
    // A 1 kHz logger stamping in microseconds, its column's name without a unit.
    for name in ["A_0", "A_1", "B_0", "B_1"] {
        let text = text_of_log().replacen("t_ms,", "t,", 1);
        let micros: Vec<String> = (text.lines().enumerate())
            .map(|(i, l)| match (i, l.split_once(',')) {
                (0, _) | (_, None) => l.to_string(),
                (_, Some((t, rest))) => format!("{}000,{rest}", t),
            })
            .collect();
        std::fs::write(logs.join(format!("{name}.csv")), micros.join("\n") + "\n").unwrap();
    }
    let out = dir.join("ds");
    let mut args = import_csv_args(&logs, &out, "t");
    let err = dir.fails(&args);
    assert!(
        err.contains("steps by a median 1000 ms, which is 1.0 Hz") && err.contains("--time-unit"),
        "{err}"
    );
    assert!(!out.exists(), "a refused import writes nothing");
    args.extend_from_slice(&["--time-unit", "us"]);
    let run = dir.run(&args);
    assert!(
        run.stderr.contains("at 1000.00 Hz nominal"),
        "{}",
        run.stderr
    );
}

/// A clean two-channel log: `t_ms,a,b`, 300 rows.
/// A log written with Windows line endings: its errors name the line they are on (the CSV
/// reader counts each `\r\n`'s `\n` into the next record, one line short), for a value that
/// is not a number, a stamp that goes back, a repeated stamp (both its lines) and an event
/// log's cell outside the grid.
#[test]
fn windows_line_endings_keep_the_line_numbers() {
    let dir = Dir::new();
    let logs = two_channel_logs(&dir);
    let crlf = |text: &str| text.replace('\n', "\r\n");
    let log = logs.join("A_1.csv");
    let inspect = |edit: &dyn Fn(&str) -> String, extra: &[&str]| {
        std::fs::write(&log, crlf(&edit(&text_of_log()))).unwrap();
        let args = ["inspect", s(&log), "--time-column", "t_ms"];
        dir.fails(&[&args[..], extra].concat())
    };
    // Line 12 holds t = 10 (the header is line 1).
    let err = inspect(&|t| t.replacen("\n10,3,0\n", "\n10,n/a,0\n", 1), &[]);
    assert!(err.contains("A_1.csv: line 12, column `a`"), "{err}");
    let err = inspect(&|t| t.replacen("\n10,3,0\n", "\n2,3,0\n", 1), &[]);
    assert!(
        err.contains("A_1.csv: line 12: time stamps must not go back"),
        "{err}"
    );
    let repeat = ["--duplicate-stamps", "error"];
    let err = inspect(&|t| t.replacen("\n10,3,0\n", "\n9,3,0\n", 1), &repeat);
    assert!(
        err.contains("line 12: time stamp 9 repeats line 11"),
        "{err}"
    );
    let events = clock_logs(&dir, &|_| 0.0, 2);
    let log = events.join("B_1.csv");
    let mut text = std::fs::read_to_string(&log).unwrap();
    let line = text.lines().count() + 1;
    text.push_str("1999999,7,1,1\n");
    std::fs::write(&log, crlf(&text)).unwrap();
    let err = import_events_fails(&dir, &events);
    assert!(
        err.contains(&format!("B_1.csv: line {line}: x = 7")),
        "{err}"
    );
}

fn text_of_log() -> String {
    let mut text = String::from("t_ms,a,b\n");
    for t in 0..300 {
        text.push_str(&format!("{t},{},{}\n", t % 7, t % 5));
    }
    text
}

#[test]
fn folds_the_design_cannot_give_are_said_with_the_folds_used() {
    let dir = Dir::new();
    let data = dir.dataset("ds", &["A", "B"], &[5.0], 4);
    let args = ["--group-by", "trial", "--folds", "5", "--k", "1", "--json"];
    let mut all = vec!["evaluate", "--dataset", s(&data), "--method", "glcm3d"];
    all.extend_from_slice(&args);
    let run = dir.run(&all);
    assert!(run.status.success(), "{}", run.stderr);
    let said = "--folds 5 with --group-by trial: 4 `trial` groups, so 4 folds are used";
    assert_eq!(run.stderr.matches(said).count(), 1, "{}", run.stderr);
    let json: Value = serde_json::from_str(&run.stdout).expect("JSON");
    assert!(json["notes"][0].as_str().unwrap().contains(said), "{json}");
    // reproduce's analyses at each speed, said before any is run.
    let report = dir.join("report");
    let mut all = vec!["reproduce", "--dataset", s(&data), "--out", s(&report)];
    all.extend_from_slice(&["--quick", "--group-by", "trial", "--folds", "5", "--k", "1"]);
    let run = dir.run(&all);
    let said = "--folds 5 with --group-by trial: 4 `trial` group(s) at 5 mm/s, so 4 folds";
    assert_eq!(run.stderr.matches(said).count(), 1, "{}", run.stderr);
    // Nested selection's inner folds, fewer where a class of an outer training set is
    // smaller than the folds.
    let data = dir.dataset("six", &["A", "B"], &[5.0], 6);
    let run = dir.run(&[
        "compare",
        "--dataset",
        s(&data),
        "--nested",
        "--folds",
        "5",
        "--inner-folds",
        "5",
        "--k",
        "1",
        "--methods",
        "glcm3d",
        "--classifiers",
        "knn",
        "--json",
    ]);
    assert!(run.status.success(), "{}", run.stderr);
    let said = "nested selection's inner cross-validation uses as few as 4 folds instead of 5";
    assert_eq!(run.stderr.matches(said).count(), 1, "{}", run.stderr);
    let json: Value = serde_json::from_str(&run.stdout).expect("JSON");
    assert!(json["notes"][0].as_str().unwrap().contains(said), "{json}");
}

/// An accuracy whose interval reaches chance is said to be no result, on standard error
/// and in the JSON's notes; a separable design's accuracy is not.
#[test]
fn an_accuracy_not_above_chance_is_a_warning() {
    let dir = Dir::new();
    let data = dir.dataset("ds", &["A", "B", "C"], &[5.0], 8);
    let evaluate = |data: &Path| {
        let args = [
            "evaluate",
            "--dataset",
            s(data),
            "--method",
            "glcm3d",
            "--json",
        ];
        let run = dir.run(&args);
        assert!(run.status.success(), "{}", run.stderr);
        let json: Value = serde_json::from_str(&run.stdout).expect("JSON");
        (run.stderr, json)
    };
    let (err, json) = evaluate(&data);
    let lower = json["accuracy_interval"]["lower"].as_f64().unwrap();
    assert!(lower > 0.34, "{json}");
    assert!(!err.contains("chance"), "{err}");
    assert_eq!(json["notes"], serde_json::json!([]), "{json}");
    // The same recordings labelled by trial parity: nothing in them tells the labels.
    relabel(&data, |trial| if trial % 2 == 0 { "even" } else { "odd" });
    let (err, json) = evaluate(&data);
    let said = "chance (50.0 %, one over 2 classes)";
    assert_eq!(err.matches(said).count(), 1, "{err}");
    assert!(err.contains("warning: the accuracy's interval ["), "{err}");
    let notes = json["notes"].as_array().expect("notes");
    assert!(
        notes.iter().any(|n| n.as_str().unwrap().contains(said)),
        "{json}"
    );
    // compare names the same chance, and the candidates whose whole interval is under it.
    let args = ["compare", "--dataset", s(&data), "--nested", "--json"];
    let run = dir.run(&args);
    assert!(run.status.success(), "{}", run.stderr);
    let json: Value = serde_json::from_str(&run.stdout).expect("JSON");
    let notes: Vec<&str> = json["notes"]
        .as_array()
        .expect("notes")
        .iter()
        .map(|n| n.as_str().unwrap())
        .collect();
    assert!(
        notes
            .iter()
            .any(|n| n.contains("nested estimate's interval") && n.contains(said)),
        "{notes:?}"
    );
    let results = json["results"].as_array().unwrap();
    let under = results
        .iter()
        .filter(|r| r["ci"][1].as_f64().unwrap() < 0.5)
        .count();
    assert!(under > 0, "{json}");
    let counted = format!("{under} of {} candidates score under {said}", results.len());
    assert!(
        notes.iter().any(|n| n.starts_with(&counted)),
        "{counted} in {notes:?}"
    );
    assert_eq!(run.stderr.matches(&counted).count(), 1, "{}", run.stderr);
}

/// A design whose classes differ in size: chance is what always answering the largest
/// class scores, when that is more than one over the classes.
#[test]
fn chance_is_the_largest_class_share_when_it_is_larger() {
    let dir = Dir::new();
    let data = dir.dataset("ds", &["A", "B", "C"], &[5.0], 8);
    // Trials 0-5 one label, 6-7 another: nothing in the recordings tells them apart.
    relabel(&data, |trial| if trial < 6 { "early" } else { "late" });
    let said = "chance (75.0 %, always answering the most frequent class)";
    for command in ["evaluate", "compare"] {
        let mut args = vec![command, "--dataset", s(&data), "--json"];
        if command == "compare" {
            args.push("--nested");
        }
        let run = dir.run(&args);
        assert!(run.status.success(), "{}", run.stderr);
        let json: Value = serde_json::from_str(&run.stdout).expect("JSON");
        let ci = match command {
            "evaluate" => [
                &json["accuracy_interval"]["lower"],
                &json["accuracy_interval"]["upper"],
            ],
            _ => [&json["nested"]["ci"][0], &json["nested"]["ci"][1]],
        };
        let (lower, upper) = (ci[0].as_f64().unwrap(), ci[1].as_f64().unwrap());
        // Not above the largest class's share, though not under one over the classes.
        assert!(
            lower <= 0.75 && upper > 0.5,
            "{command}: [{lower}, {upper}]"
        );
        assert_eq!(
            run.stderr.matches(said).count(),
            1,
            "{command}: {}",
            run.stderr
        );
    }
}
