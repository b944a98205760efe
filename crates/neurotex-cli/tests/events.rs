//! Address-event datasets: a dataset's spikes written as events (`export events`, CSV and
//! tonic's `.npy`) read back as the same spikes, bit for bit, through features, evaluate,
//! compare and predict; and every broken event rule is an error naming the file and line.

use std::path::Path;

use serde_json::Value;

use crate::util::{s, Dir};

/// Feature rows keyed by column, without the manifest's columns (the event dataset's
/// manifest has `duration_s` where the sampled one has the slide's times).
fn feature_columns(path: &Path) -> Vec<Vec<(String, String)>> {
    let mut reader = csv::Reader::from_path(path).unwrap();
    let header: Vec<String> = reader.headers().unwrap().iter().map(String::from).collect();
    reader
        .records()
        .map(|r| {
            let r = r.unwrap();
            header
                .iter()
                .zip(r.iter())
                .filter(|(h, _)| h.starts_with("sa_") || h.starts_with("fa_") || *h == "label")
                .map(|(h, v)| (h.clone(), v.to_string()))
                .collect()
        })
        .collect()
}

/// `neurotex features --method METHOD --encoding sa+fa` on `ds`, as [`feature_columns`].
fn sa_fa_features(dir: &Dir, ds: &Path, method: &str) -> Vec<Vec<(String, String)>> {
    let name = ds.file_name().unwrap().to_string_lossy();
    let out = dir.join(&format!("{name}_{method}.csv"));
    dir.ok(&[
        "features",
        "--dataset",
        s(ds),
        "--method",
        method,
        "--encoding",
        "sa+fa",
        "--out",
        s(&out),
    ]);
    feature_columns(&out)
}

/// The `predicted` column and every share column of a predictions file.
fn predictions(path: &Path) -> Vec<Vec<String>> {
    let mut reader = csv::Reader::from_path(path).unwrap();
    let header: Vec<String> = reader.headers().unwrap().iter().map(String::from).collect();
    reader
        .records()
        .map(|r| {
            let r = r.unwrap();
            header
                .iter()
                .zip(r.iter())
                .filter(|(h, _)| *h != "file")
                .map(|(_, v)| v.to_string())
                .collect()
        })
        .collect()
}

fn accuracy_and_confusion(v: &Value) -> (Value, Value, Value) {
    (
        v["accuracy"].clone(),
        v["confusion"].clone(),
        v["labels"].clone(),
    )
}

#[test]
fn exported_events_give_the_encoded_spikes_results_bit_for_bit() {
    let dir = Dir::new();
    let sim = dir.join("sim");
    dir.ok(&[
        "simulate",
        "--out",
        s(&sim),
        "--trials",
        "5",
        "--speeds",
        "10,15",
        "--textures",
        "FT1,SB,CP",
    ]);
    let (csv, npy) = (dir.join("ev_csv"), dir.join("ev_npy"));
    for (out, format) in [(&csv, "csv"), (&npy, "npy")] {
        dir.ok(&[
            "export",
            "events",
            "--dataset",
            s(&sim),
            "--out",
            s(out),
            "--format",
            format,
            "--encoding",
            "sa+fa",
        ]);
    }
    let layout = std::fs::read_to_string(npy.join("layout.toml")).unwrap();
    assert!(layout.contains("time_unit = \"us\""), "{layout}");
    for method in ["glcm3d", "taxel", "spectrum"] {
        let of = |ds: &Path| sa_fa_features(&dir, ds, method);
        let sampled = of(&sim);
        assert_eq!(sampled.len(), 30);
        assert!(
            sampled[0].len() > 2,
            "{method}: features of both populations"
        );
        assert_eq!(of(&csv), sampled, "{method} from CSV events");
        assert_eq!(of(&npy), sampled, "{method} from .npy events");
    }
    // each population alone: `sa` reads the ON events, `fa` the OFF ones
    for encoding in ["sa", "fa"] {
        let sampled = dir.evaluate_json(&sim, "glcm3d", &["--encoding", encoding, "--folds", "3"]);
        let events = dir.evaluate_json(&npy, "glcm3d", &["--encoding", encoding, "--folds", "3"]);
        assert_eq!(
            accuracy_and_confusion(&events),
            accuracy_and_confusion(&sampled),
            "{encoding}"
        );
    }
    // a model trained on the sampled recordings predicts the events as it predicts them
    let model = dir.join("m.json");
    dir.ok(&[
        "train",
        "--dataset",
        s(&sim),
        "--method",
        "glcm3d",
        "--encoding",
        "sa+fa",
        "--out",
        s(&model),
    ]);
    let (p_sim, p_ev) = (dir.join("p_sim.csv"), dir.join("p_ev.csv"));
    dir.ok(&[
        "predict",
        "--model",
        s(&model),
        "--dataset",
        s(&sim),
        "--out",
        s(&p_sim),
    ]);
    dir.ok(&[
        "predict",
        "--model",
        s(&model),
        "--dataset",
        s(&csv),
        "--out",
        s(&p_ev),
    ]);
    assert_eq!(predictions(&p_ev), predictions(&p_sim));
    // compare ranks the same candidates with the same accuracies
    let ranked = |ds: &Path| -> Value {
        let text = dir.ok(&[
            "compare",
            "--dataset",
            s(ds),
            "--per",
            "speed_mm_s",
            "--folds",
            "3",
            "--repeats",
            "1",
            "--methods",
            "glcm3d,van-rossum",
            "--classifiers",
            "knn",
            "--json",
        ]);
        let v: Value = serde_json::from_str(&text).unwrap();
        v["results"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| serde_json::json!([r["encoding"], r["method"], r["accuracy"]]))
            .collect()
    };
    assert_eq!(ranked(&npy), ranked(&sim));
    // reproduce: every analysis the events can have gives the sampled run's numbers, and
    // those they cannot have are skipped with the reason
    let report = |ds: &Path, extra: &[&str]| -> Value {
        let out = dir.join(&format!(
            "rep_{}",
            ds.file_name().unwrap().to_string_lossy()
        ));
        let mut args = vec![
            "reproduce",
            "--dataset",
            s(ds),
            "--out",
            s(&out),
            "--quick",
            "--folds",
            "3",
            "--k",
            "1",
        ];
        args.extend_from_slice(extra);
        dir.ok(&args);
        let text = std::fs::read_to_string(out.join("results.json")).unwrap();
        without_clock_and_files(serde_json::from_str(&text).unwrap())
    };
    let (sampled, events) = (report(&sim, &["--encoder-draws", "1"]), report(&npy, &[]));
    for analysis in ["e1", "e2", "e3", "e4", "e5", "e6", "e8", "e0"] {
        assert!(!sampled[analysis].is_null(), "{analysis}");
        assert_eq!(events[analysis], sampled[analysis], "{analysis}");
    }
    assert_eq!(events["e9"]["per_speed"], sampled["e9"]["per_speed"]);
    assert_eq!(events["e9"]["held_out"], sampled["e9"]["held_out"]);
    for skipped in ["e7", "e5c", "encoder sensitivity"] {
        let why = events["skipped"][skipped].as_str().unwrap_or_default();
        assert!(why.contains("address events"), "{skipped}: {why}");
    }
}

/// `results.json` without wall-clock times and the recordings' file names (the event
/// dataset's are numbered).
fn without_clock_and_files(value: Value) -> Value {
    match value {
        Value::Object(map) => map
            .into_iter()
            .filter(|(k, _)| k != "seconds" && k != "file")
            .map(|(k, v)| (k, without_clock_and_files(v)))
            .collect(),
        Value::Array(items) => items.into_iter().map(without_clock_and_files).collect(),
        other => other,
    }
}

/// An event dataset of 2x2 cells with `files` (name, CSV text) and the layout's `[events]`
/// lines.
fn event_dataset(
    dir: &Dir,
    name: &str,
    events: &str,
    files: &[(&str, &str)],
) -> std::path::PathBuf {
    let ds = dir.join(name);
    std::fs::create_dir_all(&ds).unwrap();
    let mut manifest = String::from("file,label\n");
    for (i, (file, text)) in files.iter().enumerate() {
        std::fs::write(ds.join(file), text).unwrap();
        manifest.push_str(&format!("{file},{}\n", ["A", "B"][i % 2]));
    }
    std::fs::write(ds.join("manifest.csv"), manifest).unwrap();
    std::fs::write(
        ds.join("layout.toml"),
        format!("rows = 2\ncols = 2\n\n[events]\n{events}"),
    )
    .unwrap();
    ds
}

#[test]
fn broken_event_files_are_named_with_their_line() {
    let dir = Dir::new();
    let out = dir.join("f.csv");
    let good = "t,x,y,p\n0,0,0,1\n300,1,1,0\n";
    let features = |ds: &Path, extra: &[&str]| -> String {
        let mut args = vec![
            "features",
            "--dataset",
            s(ds),
            "--method",
            "glcm3d",
            "--out",
            s(&out),
        ];
        args.extend_from_slice(extra);
        dir.fails(&args)
    };
    let cases = [
        (
            "order",
            "t,x,y,p\n0,0,0,1\n300,1,1,0\n200,0,1,1\n",
            "line 4: time 200 comes before",
        ),
        (
            "grid",
            "t,x,y,p\n0,0,0,1\n300,2,1,0\n",
            "line 3: x = 2, y = 1 is outside the 2x2 grid",
        ),
        (
            "polarity",
            "t,x,y,p\n0,0,0,1\n300,1,1,5\n",
            "polarity 5 is neither ON (1) nor OFF (0)",
        ),
        ("column", "t,col,y,p\n0,0,0,1\n", "no column `x`"),
    ];
    for (name, text, says) in cases {
        let ds = event_dataset(
            &dir,
            name,
            "time_unit = \"ms\"\n",
            &[("a.csv", good), ("b.csv", text)],
        );
        let err = features(&ds, &[]);
        assert!(err.contains(says) && err.contains("b.csv"), "{name}: {err}");
        assert!(!out.exists());
    }
    let ds = event_dataset(
        &dir,
        "fine",
        "time_unit = \"ms\"\n",
        &[("a.csv", good), ("b.csv", good)],
    );
    dir.ok(&[
        "features",
        "--dataset",
        s(&ds),
        "--method",
        "glcm3d",
        "--out",
        s(&out),
    ]);
    std::fs::remove_file(&out).unwrap();
    for (extra, says) in [
        (
            &["--gain", "auto"][..],
            "--gain auto and --causal condition and encode a sampled signal",
        ),
        (&["--causal"][..], "holds address events"),
    ] {
        let err = features(&ds, extra);
        assert!(err.contains(says), "{extra:?}: {err}");
    }
    // without a polarity column there are no OFF events for the FA population
    let on_only = "t,x,y\n0,0,0\n300,1,1\n";
    let ds = event_dataset(
        &dir,
        "on",
        "time_unit = \"ms\"\n",
        &[("a.csv", on_only), ("b.csv", on_only)],
    );
    let err = features(&ds, &["--encoding", "sa+fa"]);
    assert!(
        err.contains("no polarity column") && err.contains("--encoding sa"),
        "{err}"
    );
    // a duration past the longest recording accepted is refused before anything is allocated
    let ds = event_dataset(
        &dir,
        "long",
        "time_unit = \"ms\"\n",
        &[("a.csv", good), ("b.csv", good)],
    );
    std::fs::write(
        ds.join("manifest.csv"),
        "file,label,duration_s\na.csv,A,1e9\nb.csv,B,1\n",
    )
    .unwrap();
    let err = features(&ds, &[]);
    assert!(
        err.contains("line 2: duration_s 1000000000 s is longer than"),
        "{err}"
    );
    // no unit
    let ds = event_dataset(&dir, "unit", "", &[("a.csv", good), ("b.csv", good)]);
    let err = features(&ds, &[]);
    assert!(
        err.contains("layout.toml") && err.contains("time_unit"),
        "{err}"
    );
    // inspect summarises the events and names an unreadable file instead of stopping
    let ds = event_dataset(
        &dir,
        "inspected",
        "time_unit = \"ms\"\n",
        &[
            ("a.csv", good),
            ("b.csv", "t,x,y,p\n0,0,0,1\n300,2,1,0\n"),
            ("c.csv", good),
        ],
    );
    let text = dir.ok(&["inspect", s(&ds)]);
    assert!(
        text.contains("3 recordings (address-event dataset): 2 read, 1 unreadable"),
        "{text}"
    );
    assert!(
        text.contains("address events on a 2x2 grid (4 cells), times in ms"),
        "{text}"
    );
    assert!(
        text.contains("2 events a recording (from 2 to 2), 50 % ON"),
        "{text}"
    );
    let json: Value = serde_json::from_str(&dir.ok(&["inspect", s(&ds), "--json"])).unwrap();
    let cells = json["events"]["cells"].as_array().unwrap();
    // cell r1c1 holds one OFF event at 300 ms of a 301 ms recording in both files read
    assert_eq!(cells.len(), 4);
    let hz = cells[3]["off_hz"].as_f64().unwrap();
    assert!((hz - 1000.0 / 301.0).abs() < 1e-9, "{hz}");
    assert_eq!(cells[1]["silent_share"].as_f64(), Some(1.0));
    assert!(json["signals"]["unreadable"][0]["reason"]
        .as_str()
        .unwrap()
        .contains("line 3"));
    // a sampled-signal step names the event file
    let ds = event_dataset(
        &dir,
        "signal",
        "time_unit = \"ms\"\n",
        &[("a.csv", good), ("b.csv", good)],
    );
    let err = dir.fails(&[
        "encode",
        "--input",
        s(&ds.join("a.csv")),
        "--out",
        s(&dir.join("r.npy")),
    ]);
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn imported_logs_read_as_the_events_they_hold() {
    let dir = Dir::new();
    let logs = dir.join("logs");
    std::fs::create_dir_all(&logs).unwrap();
    // Each log: seconds on a clock, a taxel index (row-major on 2x3), polarity 1 / -1,
    // and its lines out of time order; beside it, the same events by x and y in order.
    let direct = dir.join("direct");
    std::fs::create_dir_all(&direct).unwrap();
    let mut manifest = String::from("file,label,trial\n");
    let mut state = 7u64;
    let mut next = move |n: u64| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state % n
    };
    for label in ["silk", "wool"] {
        for trial in 0..4 {
            let mut events: Vec<(u64, u64, i64)> = (0..300)
                .map(|_| (next(900_000), next(6), if next(2) == 0 { 1 } else { -1 }))
                .collect();
            events.sort();
            let first = events[0].0;
            let mut ordered = String::from("t,x,y,p\n");
            for &(t, taxel, p) in &events {
                ordered.push_str(&format!(
                    "{},{},{},{p}\n",
                    (t - first) as f64 / 1e6,
                    taxel % 3,
                    taxel / 3
                ));
            }
            let name = format!("{label}_{trial}.csv");
            std::fs::write(direct.join(&name), ordered).unwrap();
            manifest.push_str(&format!("{name},{label},{trial}\n"));
            // event 9 moved to line 3: the five after it and the old event 3 are below it
            events.swap(3, 9);
            let mut log = String::from("clock,taxel,pol\n");
            for &(t, taxel, p) in &events {
                log.push_str(&format!("{},{taxel},{p}\n", (1_000_000 + t) as f64 / 1e6));
            }
            std::fs::write(logs.join(&name), log).unwrap();
        }
    }
    std::fs::write(direct.join("manifest.csv"), manifest).unwrap();
    std::fs::write(
        direct.join("layout.toml"),
        "rows = 2\ncols = 3\n\n[events]\ntime_unit = \"s\"\nvalues = [1, -1]\n",
    )
    .unwrap();
    let imported = dir.join("imported");
    let run = dir.run(&[
        "import",
        "events",
        s(&logs),
        "--out",
        s(&imported),
        "--grid",
        "2x3",
        "--time-unit",
        "s",
        "--time-column",
        "clock",
        "--taxel",
        "taxel",
        "--polarity",
        "pol",
        "--polarity-values",
        "1,-1",
        "--origin",
        "first",
        "--name-pattern",
        "{label}_{trial}.csv",
    ]);
    assert!(run.status.success(), "{}", run.stderr);
    assert!(
        run.stderr.contains("silk_0.csv: 6 event(s) came before"),
        "{}",
        run.stderr
    );
    assert!(
        run.stderr.contains("8 recordings, 2400 events"),
        "{}",
        run.stderr
    );
    for method in ["glcm3d", "taxel"] {
        let of = |ds: &Path| sa_fa_features(&dir, ds, method);
        assert_eq!(of(&imported), of(&direct), "{method}");
    }
    // The sensor's taxel indices stream live with the import's channel map (`--taxel`), as
    // the imported file's x and y do.
    let model = dir.join("model.json");
    dir.ok(&[
        "train",
        "--dataset",
        s(&imported),
        "--encoding",
        "sa+fa",
        "--out",
        s(&model),
    ]);
    let file = std::fs::read_dir(&imported)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.file_name().unwrap().to_string_lossy().contains("silk_1"))
        .unwrap();
    let xy = std::fs::read_to_string(&file).unwrap();
    let mut by_taxel = String::from("t,taxel,p\n");
    for line in xy.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let taxel = f[2].parse::<usize>().unwrap() * 3 + f[1].parse::<usize>().unwrap();
        by_taxel.push_str(&format!("{},{taxel},{}\n", f[0], f[3]));
    }
    let streamed = |text: &str, extra: &[&str]| {
        let input = dir.join("live.csv");
        std::fs::write(&input, text).unwrap();
        let mut args = vec!["stream", "--model", s(&model), "--format", "events"];
        args.extend_from_slice(extra);
        args.extend(["--input", s(&input)]);
        dir.ok(&args)
    };
    let expected = streamed(&xy, &[]);
    assert!(expected.lines().count() > 4, "{expected}");
    assert_eq!(streamed(&by_taxel, &["--taxel"]), expected);
    // The import's checks, on these logs: each run must fail, naming what is wrong, and
    // leave nothing behind, unless `ok`.
    let out = dir.join("bad");
    let polar = ["--polarity", "pol", "--polarity-values", "1,-1"];
    let import = |extra: &[&str], ok: bool| -> String {
        let mut args = vec![
            "import",
            "events",
            s(&logs),
            "--out",
            s(&out),
            "--grid",
            "2x3",
            "--time-column",
            "clock",
            "--taxel",
            "taxel",
        ];
        args.extend_from_slice(extra);
        for (flag, value) in [("--time-unit", "s"), ("--origin", "first")] {
            if !args.contains(&flag) {
                args.extend([flag, value]);
            }
        }
        let run = dir.run(&args);
        assert_eq!(run.status.success(), ok, "{args:?}: {}", run.stderr);
        if !ok {
            assert!(!out.exists() && !dir.partial_left(), "{args:?}");
        }
        run.stderr
    };
    let line = "clock,taxel,pol\n1.0,2,1\n1.5,6,1\n";
    std::fs::write(logs.join("wool_9.csv"), line).unwrap();
    let err = import(&polar, false);
    assert!(
        err.contains("wool_9.csv: line 3: taxel 6 is outside the layout's 6 taxels"),
        "{err}"
    );
    // a named polarity column missing from one log, or a log without events
    std::fs::write(logs.join("wool_9.csv"), "clock,taxel\n1.0,2\n").unwrap();
    let err = import(&polar, false);
    assert!(
        err.contains("wool_9.csv: no polarity column `pol`"),
        "{err}"
    );
    std::fs::write(logs.join("wool_9.csv"), "clock,taxel,pol\n").unwrap();
    assert!(import(&polar, false).contains("wool_9.csv: holds no events"));
    std::fs::remove_file(logs.join("wool_9.csv")).unwrap();
    // values given without the column's name ask for the default column, `p`
    let err = import(&["--polarity-values", "1,-1"], false);
    assert!(err.contains("no polarity column `p`"), "{err}");
    // a polarity under another name, left unnamed, would make every OFF event ON
    let err = import(&[], false);
    assert!(
        err.contains("column `pol` is not read") && err.contains("--polarity pol"),
        "{err}"
    );
    // one taxel per cell; a taxel past a shorter map is named
    let map = |cells: &'static str| [&polar[..], &["--channel-map", cells]].concat();
    assert!(import(&map("0,0;0,0"), false).contains("each cell takes one taxel"));
    let err = import(&map("1,2;1,1;1,0;0,2;0,1"), false);
    assert!(
        err.contains("taxel 5 is outside the layout's 5 taxels"),
        "{err}"
    );
    // a wrong time unit shows in the spans and is said; the dataset is written
    let err = import(&[&polar[..], &["--time-unit", "ms"]].concat(), true);
    assert!(err.contains("the unit is probably wrong"), "{err}");
    std::fs::remove_dir_all(&out).unwrap();
    // stamps from a clock read from time 0 make long spans too: the origin is named
    let clock = dir.join("clock");
    std::fs::create_dir_all(&clock).unwrap();
    for name in ["silk_0.csv", "wool_1.csv"] {
        std::fs::write(clock.join(name), "t,x,y\n1000.5,0,0\n1001.5,1,0\n").unwrap();
    }
    let run = dir.run(&[
        "import",
        "events",
        s(&clock),
        "--out",
        s(&out),
        "--grid",
        "2x3",
        "--time-unit",
        "s",
        "--name-pattern",
        "{label}_{trial}.csv",
    ]);
    assert!(run.status.success(), "{}", run.stderr);
    assert!(
        run.stderr.contains("the first event comes 1000.500 s")
            && run.stderr.contains("import again with --origin first"),
        "{}",
        run.stderr
    );
    std::fs::remove_dir_all(&out).unwrap();
    for (extra, says) in [
        (
            &["--polarity-values", "1,1"][..],
            "polarity values are two different integers",
        ),
        (&["--origin", "start"], "the origin is `zero` or `first`"),
        (&["--channel-map", "0,0", "--x", "c"], "--x"),
    ] {
        let err = import(extra, false);
        assert!(err.contains(says), "{extra:?}: {err}");
    }
}

#[test]
fn event_recordings_keep_the_bound_on_values_on_the_grid_that_sampled_ones_keep() {
    let dir = Dir::new();
    let out = dir.join("f.csv");
    // max_duration_s = 1 allows 16 000 values on the grid: 62 ms of a 16x16 grid.
    let ds = dir.join("big");
    std::fs::create_dir(&ds).unwrap();
    let events = "t,x,y,p\n0,0,0,1\n30,5,5,0\n500,15,15,1\n";
    for file in ["a.csv", "b.csv"] {
        std::fs::write(ds.join(file), events).unwrap();
    }
    let layout = "rows = 16\ncols = 16\nmax_duration_s = 1\n\n[events]\ntime_unit = \"ms\"\n";
    std::fs::write(ds.join("layout.toml"), layout).unwrap();
    std::fs::write(ds.join("manifest.csv"), "file,label\na.csv,A\nb.csv,B\n").unwrap();
    let features = [
        "features",
        "--dataset",
        s(&ds),
        "--method",
        "glcm3d",
        "--out",
        s(&out),
    ];
    let err = dir.fails(&features);
    let bound = "the 62 ms a recording on 256 grid cells may last";
    assert!(
        err.contains("a.csv")
            && err.contains("line 4: time 500 is at 500 ms, past")
            && err.contains(bound),
        "{err}"
    );
    assert!(!out.exists());
    // a duration in the manifest is checked before the file is read
    let manifest = "file,label,duration_s\na.csv,A,0.5\nb.csv,B,0.05\n";
    std::fs::write(ds.join("manifest.csv"), manifest).unwrap();
    let err = dir.fails(&features);
    assert!(
        err.contains("manifest.csv: line 2: duration_s 0.5 s is longer than")
            && err.contains(bound),
        "{err}"
    );
    // within the bound (62 steps, the last at 61 ms) it reads
    std::fs::write(ds.join("a.csv"), "t,x,y,p\n0,0,0,1\n61,5,5,0\n").unwrap();
    std::fs::write(ds.join("b.csv"), "t,x,y,p\n0,0,0,1\n61,5,5,0\n").unwrap();
    std::fs::write(ds.join("manifest.csv"), "file,label\na.csv,A\nb.csv,B\n").unwrap();
    dir.ok(&[&features[..], &["--bin-ms", "20"]].concat());
    std::fs::write(ds.join("b.csv"), "t,x,y,p\n0,0,0,1\n62,5,5,0\n").unwrap();
    let err = dir.fails(&[&features[..], &["--bin-ms", "20"]].concat());
    assert!(err.contains("b.csv") && err.contains(bound), "{err}");
    // an import onto a 1024x1024 grid: an hour allows 54 ms
    let logs = dir.join("logs");
    std::fs::create_dir(&logs).unwrap();
    for i in 0..6 {
        let text: String = (0..100)
            .map(|k| format!("{},{},{},1\n", k * 10, (k * 37 + i) % 1024, (k * 91) % 1024))
            .collect();
        std::fs::write(logs.join(format!("l{i}.csv")), format!("t,x,y,p\n{text}")).unwrap();
    }
    let imported = dir.join("imported");
    let err = dir.fails(&[
        "import",
        "events",
        s(&logs),
        "--out",
        s(&imported),
        "--grid",
        "1024x1024",
        "--time-unit",
        "ms",
    ]);
    assert!(
        err.contains("the 54 ms a recording on 1048576 grid cells may last"),
        "{err}"
    );
    assert!(!imported.exists());
}
