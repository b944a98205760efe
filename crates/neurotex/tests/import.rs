//! Importing CSV logs and stacked arrays.

use std::path::{Path, PathBuf};

use ndarray::{Array, Array1, ArrayD, IxDyn};
use ndarray_npy::write_npy;
use neurotex::csvlog::{read_csv_log, Column, CsvFormat, DuplicateStamps};
use neurotex::import::{
    csv_files, import_csv, import_stacked, Axes, ChannelSelect, CsvImportParams, ImportWarning,
    NamePattern, StackedParams,
};
use neurotex::pipeline::{Pipeline, PipelineParams};
use neurotex::recording::{
    read_recording, read_recording_as, Baseline, Dataset, LayoutFile, TimeUnit,
};
use neurotex::signal::{PreprocessParams, Preprocessor};
use neurotex::Speed;

fn params() -> CsvImportParams {
    CsvImportParams {
        pattern: Some(NamePattern::parse("{label}_V{speed}_{trial}.csv").unwrap()),
        format: CsvFormat {
            time_column: Some(Column::Name("stamp".into())),
            time_unit: TimeUnit::Milliseconds,
            ..CsvFormat::default()
        },
        grid: None,
        channel_map: None,
        drop_channels: None,
        fs: None,
        baseline: None,
        skip_bad: false,
    }
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn name_patterns_take_fields_from_file_names() {
    let p = NamePattern::parse("{label}_F{force}_V{speed}mmps_{trial}.csv").unwrap();
    let f = p.matches("BeigeCotton_F120_V-100mmps_2.csv").unwrap();
    assert_eq!(f["label"], "BeigeCotton");
    assert_eq!(f["force"], "120");
    assert_eq!(f["speed"], "-100");
    assert_eq!(f["trial"], "2");
    // a label with the separator in it still matches: fields take as little as possible
    let f = p.matches("Denim_Flex_F150_V20mmps_0.csv").unwrap();
    assert_eq!(f["label"], "Denim_Flex");
    assert!(p.matches("BeigeCotton_F120_100mmps_2.csv").is_none());
    assert!(p.matches("BeigeCotton_F120_V-100mmps_2.txt").is_none());
    for bad in ["{label", "label}", "{}_x", "{a}{b}", "plain.csv"] {
        assert!(NamePattern::parse(bad).is_err(), "{bad}");
    }
}

/// A logger's whole-millisecond stamps (here since the epoch) are the encoder's grid: the
/// recording is read as sampled uniformly, bit for bit what resampling it would give, and
/// not said to be resampled; one stamp off the grid makes it resampled.
#[test]
fn whole_millisecond_stamps_are_not_resampled() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("src");
    std::fs::create_dir(&src).unwrap();
    let csv = |shift_ms: f64| {
        let mut text = String::from("stamp,a,b\n");
        for i in 0..400 {
            let t = 1_700_000_000_000.0 + i as f64 + if i == 200 { shift_ms } else { 0.0 };
            let a = 500.0 + 20.0 * (i as f64 / 37.0).sin();
            text.push_str(&format!("{t},{a:.3},{:.3}\n", 480.0 + (i % 7) as f64));
        }
        text
    };
    write(&src, "X_V5_0.csv", &csv(0.0));
    write(&src, "Y_V5_0.csv", &csv(0.5));
    let out = dir.path().join("ds");
    import_csv(&csv_files(&[src]).unwrap(), &params(), &out, &|| {}).unwrap();
    let ds = Dataset::open(&out).unwrap();
    let pre = Preprocessor::new(&PreprocessParams::default()).unwrap();
    let on_grid = ds.load(0).unwrap();
    let times = neurotex::signal::relative_times(&on_grid);
    let cond = pre.apply(&on_grid, Baseline::None).unwrap();
    assert!(!cond.resampled);
    // What resampling the stamps would give: every sample as it is.
    let resampled = neurotex::signal::resample_linear(&on_grid.samples, 2, &times, 1000.0);
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&resampled), bits(&on_grid.samples));
    let uniform = neurotex::recording::Recording {
        times_s: None,
        ..on_grid.clone()
    };
    let plain = pre.apply(&uniform, Baseline::None).unwrap();
    assert_eq!(bits(&cond.samples), bits(&plain.samples));
    let off_grid = ds.load(1).unwrap();
    assert!(pre.apply(&off_grid, Baseline::None).unwrap().resampled);
}

#[test]
fn irregular_stamps_and_gaps_are_kept_then_resampled_to_1_ms() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("src");
    std::fs::create_dir(&src).unwrap();
    // jittered 25 ms stamps with a 100 ms gap; channel a rises linearly with time
    let stamps = [
        1000.0, 1026.0, 1049.0, 1075.0, 1175.0, 1201.0, 1224.0, 1250.0, 1276.0, 1300.0,
    ];
    let mut text = String::from("stamp,a,b\n");
    for t in stamps {
        text.push_str(&format!("{t},{},{}\n", (t - 1000.0) / 10.0, 5));
    }
    write(&src, "X_V5_0.csv", &text);
    write(&src, "Y_V5_0.csv", &text);
    let out = dir.path().join("ds");
    let summary = import_csv(&csv_files(&[src]).unwrap(), &params(), &out, &|| {}).unwrap();
    assert_eq!(summary.written, 2);
    let ds = Dataset::open(&out).unwrap();
    assert_eq!(ds.entries[0].speed_mm_s, Some(5.0));
    let rec = ds.load(0).unwrap();
    let times = rec.times_s.as_ref().unwrap();
    assert_eq!(times.len(), stamps.len());
    assert!((times[4] - times[3] - 0.1).abs() < 1e-12, "the gap is kept");
    let pre = Preprocessor::new(&PreprocessParams {
        cutoff_hz: 0.0,
        ..Default::default()
    })
    .unwrap();
    let cond = pre.apply(&rec, Baseline::None).unwrap();
    assert!(cond.resampled);
    assert_eq!(cond.n_steps(), 301, "300 ms on the 1 ms grid");
    // linear interpolation: a(t) = t / 10 ms, normalised by its maximum 30 at 300 ms;
    // b = 5 everywhere (the maximum is over all taxels, so b/30).
    for step in [0usize, 13, 100, 120, 299] {
        let a = cond.samples[step * 2];
        assert!(
            (a - step as f64 / 10.0 / 30.0).abs() < 1e-9,
            "step {step}: {a}"
        );
        assert!((cond.samples[step * 2 + 1] - 5.0 / 30.0).abs() < 1e-9);
    }
}

#[test]
fn channels_by_list_or_regex_and_a_masked_6x10_grid() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("src");
    std::fs::create_dir(&src).unwrap();
    let names: Vec<String> = (0..52).map(|k| format!("tax{k}")).collect();
    let mut text = format!("stamp,temp,{}\n", names.join(","));
    for t in 0..20 {
        let values: Vec<String> = (0..52).map(|k| format!("{}", k * 100 + t)).collect();
        text.push_str(&format!("{},{},{}\n", t * 10, 36.6, values.join(",")));
    }
    write(&src, "A_V10_0.csv", &text);
    // a regular expression picks the 52 taxels and leaves the temperature out;
    // 52 channels on a 6x10 grid: the last 8 cells are masked
    let mut p = params();
    p.format.channels = ChannelSelect::parse(r"^tax\d+$").unwrap();
    p.grid = Some("6x10".parse().unwrap());
    let out = dir.path().join("grid");
    let summary = import_csv(
        &csv_files(std::slice::from_ref(&src)).unwrap(),
        &p,
        &out,
        &|| {},
    )
    .unwrap();
    let mask = summary.layout.mask.clone().unwrap();
    assert_eq!(mask[5], "1100000000");
    assert_eq!(mask[4], "1111111111");
    let rec = Dataset::open(&out).unwrap().load(0).unwrap();
    assert_eq!((rec.layout.rows, rec.layout.cols), (6, 10));
    assert_eq!(rec.layout.present.iter().filter(|&&x| x).count(), 52);
    assert_eq!(
        rec.samples[60 + 51],
        5101.0,
        "frame 1, channel 51 at row 5, col 1"
    );
    // a list picks channels in the given order
    let mut p = params();
    p.format.channels = ChannelSelect::parse("tax3, tax1").unwrap();
    let out = dir.path().join("list");
    import_csv(&csv_files(&[src]).unwrap(), &p, &out, &|| {}).unwrap();
    let rec = Dataset::open(&out).unwrap().load(0).unwrap();
    assert_eq!(&rec.samples[..2], &[300.0, 100.0]);
}

#[test]
fn bad_csv_files_are_named_or_left_out() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("src");
    std::fs::create_dir(&src).unwrap();
    write(&src, "A_V5_0.csv", "stamp,a\n0,1\n10,2\n20,3\n");
    write(&src, "A_V5_1.csv", "stamp,a\n0,1\n10,NaN\n20,3\n");
    let files = csv_files(std::slice::from_ref(&src)).unwrap();
    let err = import_csv(&files, &params(), &dir.path().join("x"), &|| {})
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("A_V5_1.csv") && err.contains("line 3") && err.contains("NaN"),
        "{err}"
    );
    assert!(!dir.path().join("x").exists());
    let mut p = params();
    p.skip_bad = true;
    let s = import_csv(&files, &p, &dir.path().join("y"), &|| {}).unwrap();
    assert_eq!((s.written, s.skipped.len()), (1, 1));
    std::fs::remove_file(src.join("A_V5_1.csv")).unwrap();
    write(&src, "wrong.csv", "stamp,a\n0,1\n");
    let err = import_csv(
        &csv_files(&[src]).unwrap(),
        &params(),
        &dir.path().join("z"),
        &|| {},
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("wrong.csv") && err.contains("does not match"),
        "{err}"
    );
}

/// A stacked array `(N, T, rows, cols)` whose value encodes its own indices.
fn reference(n: usize, t: usize, r: usize, c: usize) -> ArrayD<f32> {
    Array::from_shape_fn(IxDyn(&[n, t, r, c]), |i| {
        (i[0] * 1000 + i[1] * 100 + i[2] * 10 + i[3]) as f32
    })
}

#[test]
fn every_axes_order_gives_the_same_recordings() {
    let dir = tempfile::tempdir().unwrap();
    let base = reference(4, 5, 2, 3);
    let labels = Array1::from(vec![1i64, 2, 1, 2]);
    write_npy(dir.path().join("labels.npy"), &labels).unwrap();
    let names = ["n", "t", "row", "col"];
    let mut orders = Vec::new();
    for a in 0..4 {
        for b in 0..4 {
            for c in 0..4 {
                for d in 0..4 {
                    let o = [a, b, c, d];
                    if (0..4).all(|k| o.contains(&k)) {
                        orders.push(o);
                    }
                }
            }
        }
    }
    assert_eq!(orders.len(), 24);
    for (k, order) in orders.iter().enumerate() {
        // stored with axis j of the file being axis order[j] of the reference
        let data = base
            .clone()
            .permuted_axes(IxDyn(order))
            .as_standard_layout()
            .into_owned();
        let data_path = dir.path().join(format!("data{k}.npy"));
        write_npy(&data_path, &data).unwrap();
        let axes = order
            .iter()
            .map(|&a| names[a])
            .collect::<Vec<_>>()
            .join(",");
        let out = dir.path().join(format!("ds{k}"));
        let p = StackedParams {
            axes: axes.parse().unwrap(),
            fs: 1000.0,
            grid: None,
        };
        import_stacked(&data_path, &dir.path().join("labels.npy"), None, &p, &out).unwrap();
        let ds = Dataset::open(&out).unwrap();
        assert_eq!(ds.labels(), vec!["1", "2"]);
        for i in 0..4 {
            let rec = ds.load(i).unwrap();
            assert_eq!(
                (rec.len(), rec.layout.rows, rec.layout.cols),
                (5, 2, 3),
                "{axes}"
            );
            let expected: Vec<f64> = (0..5)
                .flat_map(|t| {
                    (0..2).flat_map(move |r| {
                        (0..3).map(move |c| (i * 1000 + t * 100 + r * 10 + c) as f64)
                    })
                })
                .collect();
            assert_eq!(rec.samples, expected, "{axes}, sample {i}");
        }
    }
    // channel axes in both orders, placed on a grid
    let chans = Array::from_shape_fn(IxDyn(&[2, 6, 4]), |i| {
        (i[0] * 100 + i[1] * 10 + i[2]) as f32
    });
    write_npy(dir.path().join("labels2.npy"), &Array1::from(vec![0i32, 1])).unwrap();
    for (k, axes) in ["n,t,channel", "n,channel,t"].iter().enumerate() {
        let data = if k == 0 {
            chans.clone()
        } else {
            chans
                .clone()
                .permuted_axes(IxDyn(&[0, 2, 1]))
                .as_standard_layout()
                .into_owned()
        };
        let path = dir.path().join(format!("chan{k}.npy"));
        write_npy(&path, &data).unwrap();
        let out = dir.path().join(format!("chan_ds{k}"));
        let p = StackedParams {
            axes: axes.parse().unwrap(),
            fs: 500.0,
            grid: Some("2x2".parse().unwrap()),
        };
        import_stacked(&path, &dir.path().join("labels2.npy"), None, &p, &out).unwrap();
        let rec = Dataset::open(&out).unwrap().load(1).unwrap();
        assert_eq!((rec.layout.rows, rec.layout.cols, rec.fs), (2, 2, 500.0));
        assert_eq!(&rec.samples[4..8], &[110.0, 111.0, 112.0, 113.0], "{axes}");
    }
}

#[test]
fn string_labels_and_speeds_and_bad_stacks() {
    let dir = tempfile::tempdir().unwrap();
    let data = reference(3, 4, 1, 2);
    write_npy(dir.path().join("x.npy"), &data).unwrap();
    // numpy.save("labels.npy", numpy.array(["silk", "wool", "silk"])) writes '<U4'
    let mut npy = b"\x93NUMPY\x01\x00".to_vec();
    let mut header = "{'descr': '<U4', 'fortran_order': False, 'shape': (3,), }".to_string();
    while !(10 + header.len() + 1).is_multiple_of(64) {
        header.push(' ');
    }
    header.push('\n');
    npy.extend((header.len() as u16).to_le_bytes());
    npy.extend(header.as_bytes());
    for word in ["silk", "wool", "silk"] {
        for ch in word.chars() {
            npy.extend((ch as u32).to_le_bytes());
        }
    }
    std::fs::write(dir.path().join("labels.npy"), &npy).unwrap();
    write_npy(
        dir.path().join("speeds.npy"),
        &Array1::from(vec![5.0f64, 5.0, 10.0]),
    )
    .unwrap();
    let p = StackedParams {
        axes: "n,t,row,col".parse().unwrap(),
        fs: 1000.0,
        grid: None,
    };
    let out = dir.path().join("ds");
    import_stacked(
        &dir.path().join("x.npy"),
        &dir.path().join("labels.npy"),
        Some(&dir.path().join("speeds.npy")),
        &p,
        &out,
    )
    .unwrap();
    let ds = Dataset::open(&out).unwrap();
    assert_eq!(ds.labels(), vec!["silk", "wool"]);
    assert_eq!(ds.speeds(), vec![Speed::of(5.0), Speed::of(10.0)]);
    // bad: axes count, axes names, label count
    let x = dir.path().join("x.npy");
    let lab = dir.path().join("labels.npy");
    let err = |axes: &str, labels: &Path, out: &str| {
        let p = StackedParams {
            axes: axes.parse().unwrap(),
            fs: 1000.0,
            grid: None,
        };
        import_stacked(&x, labels, None, &p, &dir.path().join(out))
            .unwrap_err()
            .to_string()
    };
    assert!(err("n,t,channel", &lab, "a").contains("names 3 axes but the data has 4"));
    // axes that cannot describe a stack do not parse, naming the rule
    for (axes, rule) in [
        ("n,t,row,row", "axes must name"),
        ("n,t,x,col", "n, t, row, col or channel"),
    ] {
        let e = axes.parse::<Axes>().unwrap_err();
        assert_eq!(e.name, "axes");
        assert!(e.to_string().contains(rule), "{e}");
    }
    assert_eq!(
        "n, row,col ,t".parse::<Axes>().unwrap().to_string(),
        "n,row,col,t"
    );
    write_npy(dir.path().join("two.npy"), &Array1::from(vec![1i64, 2])).unwrap();
    assert!(err("n,t,row,col", &dir.path().join("two.npy"), "d").contains("2 labels for 3 samples"));
    assert!(!dir.path().join("d").exists());
}

#[test]
fn name_patterns_match_brackets_and_dots_literally() {
    let p = NamePattern::parse(
        "Data[Texture({label})][Speed({speed})][Force({force})][Trial({trial})].csv",
    )
    .unwrap();
    let f = p
        .matches("Data[Texture(003)][Speed(2400)][Force(1.0)][Trial(1)].csv")
        .unwrap();
    assert_eq!(
        (
            &f["label"][..],
            &f["speed"][..],
            &f["force"][..],
            &f["trial"][..]
        ),
        ("003", "2400", "1.0", "1")
    );
    // `.` is a dot, not any character; `(` is a parenthesis, not a group
    assert!(p
        .matches("Data[Texture(003)][Speed(2400)][Force(1.0)][Trial(1)]xcsv")
        .is_none());
    let p = NamePattern::parse("a.b+({label})|x.csv").unwrap();
    assert_eq!(p.matches("a.b+(q)|x.csv").unwrap()["label"], "q");
    assert!(p.matches("aXbb+(q)|x.csv").is_none());
    assert!(NamePattern::parse("{label}_{label}.csv").is_err());
}

#[test]
fn a_hundred_fields_match_in_well_under_a_second() {
    // the old backtracking matcher took over a minute on this
    let pattern: String =
        (0..100).map(|k| format!("{{f{k}}}_")).collect::<String>() + "{label}.csv";
    let name: String = (0..100).map(|k| format!("v{k}_")).collect::<String>() + "x.csv";
    let p = NamePattern::parse(&pattern).unwrap();
    let start = std::time::Instant::now();
    let f = p.matches(&name).unwrap();
    assert_eq!((&f["f7"][..], &f["label"][..]), ("v7", "x"));
    // and a name that almost matches, the worst case for backtracking
    let bad = "a_".repeat(100) + "x.txt";
    assert!(p.matches(&bad).is_none());
    assert!(start.elapsed().as_secs_f64() < 0.5, "{:?}", start.elapsed());
}

fn log_format(time: Option<Column>, policy: DuplicateStamps) -> CsvFormat {
    CsvFormat {
        time_column: time,
        duplicate_stamps: policy,
        ..CsvFormat::default()
    }
}

#[test]
fn headerless_semicolon_logs_by_index_ranges() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(
        dir.path(),
        "log.csv",
        "10;7;1;2;3\n20;7;4;5;6\n30;7;7;8;9\n",
    );
    let format = CsvFormat {
        header: false,
        time_column: Some(Column::Index(0)),
        channels: "2-3,4".parse().unwrap(),
        ..CsvFormat::default()
    };
    let log = read_csv_log(&p, &format).unwrap();
    assert_eq!(log.delimiter.byte(), b';', "detected");
    assert_eq!(log.channel_names, ["column2", "column3", "column4"]);
    assert_eq!(log.samples, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]);
    assert_eq!(log.times.as_deref(), Some(&[10.0, 20.0, 30.0][..]));
    // tab-separated, detected; every column but the time column by default
    let p = write(dir.path(), "tab.csv", "0\t1\t2\n5\t3\t4\n");
    let format = CsvFormat {
        header: false,
        time_column: Some(Column::Index(0)),
        ..CsvFormat::default()
    };
    let log = read_csv_log(&p, &format).unwrap();
    assert_eq!((log.delimiter.byte(), log.samples.len()), (b'\t', 4));
    // the same rules hold in a dataset's layout.toml: indices without a header
    let layout: LayoutFile =
        toml::from_str("header = false\ntime_column = \"0\"\nchannels = [\"2\", \"4\"]\n").unwrap();
    let rec = read_recording(&dir.path().join("log.csv"), &layout).unwrap();
    assert_eq!(rec.samples, [1.0, 3.0, 4.0, 6.0, 7.0, 9.0]);
    // seconds from the first stamp
    assert_eq!(rec.times_s.as_deref(), Some(&[0.0, 0.01, 0.02][..]));
}

#[test]
fn repeated_stamps_are_averaged_or_kept_first_or_last_or_refused() {
    let dir = tempfile::tempdir().unwrap();
    // 10 ms: two rows with other values and one exact repeat; 20 ms: one row
    let p = write(
        dir.path(),
        "r.csv",
        "t,a,b\n10,1,2\n10,3,6\n10,1,2\n20,5,5\n20,5,5\n",
    );
    let t = Some(Column::Name("t".into()));
    let read = |policy| read_csv_log(&p, &log_format(t.clone(), policy));
    let avg = read(DuplicateStamps::Average).unwrap();
    assert_eq!(avg.samples, [2.0, 4.0, 5.0, 5.0]);
    assert_eq!(avg.times.as_deref(), Some(&[10.0, 20.0][..]));
    assert_eq!((avg.merged_rows, avg.duplicate_rows), (1, 2));
    assert_eq!(
        read(DuplicateStamps::First).unwrap().samples,
        [1.0, 2.0, 5.0, 5.0]
    );
    assert_eq!(
        read(DuplicateStamps::Last).unwrap().samples,
        [3.0, 6.0, 5.0, 5.0]
    );
    let err = read(DuplicateStamps::Error).unwrap_err().to_string();
    assert!(
        err.contains("r.csv") && err.contains("line 3") && err.contains("repeats line 2"),
        "{err}"
    );
    // exact repeats alone are dropped even under `error`
    let q = write(dir.path(), "q.csv", "t,a\n10,1\n20,2\n20,2\n");
    let log = read_csv_log(&q, &log_format(t.clone(), DuplicateStamps::Error)).unwrap();
    assert_eq!((log.samples.len(), log.duplicate_rows), (2, 1));
    // a stamp that goes back is always an error naming the line
    let back = write(dir.path(), "back.csv", "t,a\n10,1\n20,2\n15,2\n");
    let err = read_csv_log(&back, &log_format(t, DuplicateStamps::Average))
        .unwrap_err()
        .to_string();
    assert!(err.contains("back.csv") && err.contains("line 4"), "{err}");
}

#[test]
fn bad_column_choices_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "h.csv", "1,2,3\n4,5,6\n");
    let headerless = |time: Option<Column>, channels: &str| CsvFormat {
        header: false,
        time_column: time,
        channels: channels.parse().unwrap(),
        ..CsvFormat::default()
    };
    let cases = [
        (
            headerless(Some(Column::Index(3)), "1"),
            "time column 3 (0-based) does not exist",
        ),
        (
            headerless(None, "1-5"),
            "channel column 3 (0-based) does not exist",
        ),
        (headerless(None, "a,b"), "without a header row"),
        (headerless(None, r"^c\d$"), "not a regular expression"),
        (
            headerless(Some(Column::Index(0)), "0-1"),
            "both the time and a channel",
        ),
        (
            headerless(Some(Column::Name("t".into())), "1"),
            "0-based index, got `t`",
        ),
    ];
    for (format, expected) in cases {
        let err = read_csv_log(&p, &format).unwrap_err().to_string();
        assert!(
            err.contains("h.csv") && err.contains(expected),
            "{expected}: {err}"
        );
    }
    assert!("3-1".parse::<neurotex::csvlog::ChannelSelect>().is_err());
    assert!("0-99999999"
        .parse::<neurotex::csvlog::ChannelSelect>()
        .is_err());
    assert!("pipe".parse::<neurotex::csvlog::Delimiter>().is_err());
    assert!("mean".parse::<DuplicateStamps>().is_err());
}

#[test]
fn repeated_names_are_refused_and_a_trailing_delimiter_is_no_column() {
    let dir = tempfile::tempdir().unwrap();
    // every reader would resolve `channel1` to the first column: 16 taxels, one signal
    let header = vec!["channel1"; 16].join(",");
    let row: Vec<String> = (0..16).map(|j| j.to_string()).collect();
    let p = write(
        dir.path(),
        "same.csv",
        &format!("{header}\n{}\n", row.join(",")),
    );
    let err = read_csv_log(&p, &CsvFormat::default())
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("columns 1 and 2 of line 1 are both named `channel1`"),
        "{err}"
    );
    // a logger that ends every line with the delimiter
    let p = write(dir.path(), "trail.csv", "t_ms,a,b,\n0,1,2,\n1,3,4,\n");
    let detect = CsvFormat {
        detect_time: true,
        ..CsvFormat::default()
    };
    let log = read_csv_log(&p, &detect).unwrap();
    assert_eq!(log.channel_names, ["a", "b"]);
    assert_eq!(log.samples, [1.0, 2.0, 3.0, 4.0]);
    // a huge cell is quoted in part, not whole
    let cell = "x".repeat(1 << 20);
    let p = write(dir.path(), "big.csv", &format!("a,b\n1,{cell}\n"));
    let err = read_csv_log(&p, &CsvFormat::default())
        .unwrap_err()
        .to_string();
    assert!(err.contains("expected a finite number, got `xxx"), "{err}");
    assert!(err.len() < 400, "{} bytes", err.len());
}

#[test]
fn the_time_unit_comes_from_the_column_name_and_an_implausible_rate_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let by_name = |name: &str| CsvFormat {
        time_column: Some(Column::Name(name.into())),
        ..CsvFormat::default()
    };
    // seconds at 35.7 Hz, in a column whose name says so
    let rows: String = (0..20)
        .map(|i| format!("{},{}\n", f64::from(i) * 0.028, i))
        .collect();
    for (name, unit) in [
        ("t_s", TimeUnit::Seconds),
        ("time (s)", TimeUnit::Seconds),
        ("Stamp_S", TimeUnit::Seconds),
    ] {
        let p = write(dir.path(), "s.csv", &format!("{name},a\n{rows}"));
        let log = read_csv_log(&p, &by_name(name)).unwrap();
        assert_eq!(log.time_unit, unit, "{name}");
    }
    let p = write(dir.path(), "us.csv", "stamp_us,a\n0,1\n1000,2\n2000,3\n");
    let log = read_csv_log(&p, &by_name("stamp_us")).unwrap();
    assert_eq!(log.time_unit, TimeUnit::Microseconds);
    // the same seconds under a name that says nothing: read as ms they would be 35714 Hz
    let p = write(dir.path(), "stamp.csv", &format!("timestamp,a\n{rows}"));
    let err = read_csv_log(&p, &by_name("timestamp"))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("stamp.csv") && err.contains("`timestamp`") && err.contains("--time-unit"),
        "{err}"
    );
    // said explicitly, either unit is taken as given
    let given = |unit| CsvFormat {
        time_unit: unit,
        unit_given: true,
        ..by_name("timestamp")
    };
    assert_eq!(
        read_csv_log(&p, &given(TimeUnit::Seconds))
            .unwrap()
            .time_unit,
        TimeUnit::Seconds
    );
    assert!(read_csv_log(&p, &given(TimeUnit::Milliseconds)).is_ok());
    // a name's unit is checked too: a 1 kHz logger's microseconds under `t_ms` are 1 Hz
    let micros: String = (0..20).map(|i| format!("{},{i}\n", i * 1000)).collect();
    let p = write(dir.path(), "named.csv", &format!("t_ms,a\n{micros}"));
    let err = read_csv_log(&p, &by_name("t_ms")).unwrap_err().to_string();
    assert!(
        err.contains("1.0 Hz if its stamps are in ms, as its name says")
            && err.contains("overrides the name"),
        "{err}"
    );
    let us = CsvFormat {
        time_unit: TimeUnit::Microseconds,
        unit_given: true,
        ..by_name("t_ms")
    };
    assert_eq!(
        read_csv_log(&p, &us).unwrap().time_unit,
        TimeUnit::Microseconds
    );
    // milliseconds at a plausible rate need nothing
    let p = write(dir.path(), "ms.csv", "timestamp,a\n0,1\n28,2\n57,3\n");
    assert_eq!(
        read_csv_log(&p, &by_name("timestamp")).unwrap().time_unit,
        TimeUnit::Milliseconds
    );
    assert_eq!("us".parse::<TimeUnit>().unwrap(), TimeUnit::Microseconds);
}

#[test]
fn stamps_read_as_a_taxel_are_refused_with_the_option_to_name() {
    let dir = tempfile::tempdir().unwrap();
    // FabricSlide's layout: a `timestamp` column first, in ms
    let p = write(
        dir.path(),
        "f.csv",
        "timestamp, channel1, channel2\n89819,116,197\n89848,119,195\n89877,117,190\n",
    );
    let err = read_csv_log(&p, &CsvFormat::default())
        .unwrap_err()
        .to_string();
    assert!(err.contains("--time-column timestamp"), "{err}");
    // chosen as time, or left out of the channels, it reads
    let format = CsvFormat {
        time_column: Some(Column::Name("timestamp".into())),
        ..CsvFormat::default()
    };
    assert_eq!(
        read_csv_log(&p, &format).unwrap().channel_names,
        ["channel1", "channel2"]
    );
    // a rising taxel of another name is a taxel
    let p = write(dir.path(), "g.csv", "a,b\n1,5\n2,5\n3,5\n");
    assert!(read_csv_log(&p, &CsvFormat::default()).is_ok());
}

#[test]
fn a_long_gap_in_the_stamps_is_an_error_not_a_straight_line() {
    let dir = tempfile::tempdir().unwrap();
    // 300 rows at 28 ms, then one fifty minutes later
    let mut text = String::from("t_ms,a\n");
    for i in 0..300 {
        text.push_str(&format!("{},{}\n", i * 28, i % 7));
    }
    text.push_str(&format!("{},3\n", 299 * 28 + 50 * 60 * 1000));
    let p = write(dir.path(), "gap.csv", &text);
    let format = CsvFormat {
        detect_time: true,
        ..CsvFormat::default()
    };
    let err = read_csv_log(&p, &format).unwrap_err().to_string();
    assert!(
        err.contains("jump by 3000 s between frames 300 and 301") && err.contains("max_gap_s"),
        "{err}"
    );
    let raised = CsvFormat {
        max_gap_s: 3600.0,
        ..format.clone()
    };
    assert_eq!(read_csv_log(&p, &raised).unwrap().samples.len(), 301);
    let zero = CsvFormat {
        max_gap_s: 0.0,
        ..format
    };
    assert!(read_csv_log(&p, &zero).is_err());
}

/// A 1 kHz log of 4 channels over 3 s, as CSV text with a `t_ms` column stamping row `i`
/// with `stamp(i)` (or no time column), values a few sines that cross the encoder's
/// threshold often.
fn log_1khz(stamp: Option<&dyn Fn(u64) -> String>) -> String {
    let mut text = String::from(if stamp.is_some() { "t_ms," } else { "" });
    text.push_str("c0,c1,c2,c3\n");
    for i in 0..3000u64 {
        if let Some(stamp) = stamp {
            text.push_str(&format!("{},", stamp(i)));
        }
        let values: Vec<String> = (0..4)
            .map(|c| {
                let x = i as f64 * 0.0131 * (c + 1) as f64;
                format!("{}", 0.55 + 0.45 * x.sin() + 0.05 * (7.3 * x).sin())
            })
            .collect();
        text.push_str(&values.join(","));
        text.push('\n');
    }
    text
}

#[test]
fn stamps_on_the_1_ms_grid_give_the_spikes_of_the_unstamped_log_wherever_they_start() {
    let dir = tempfile::tempdir().unwrap();
    let epoch = |i: u64| format!("{}", 1_700_000_000_000u64 + i);
    let zero = |i: u64| format!("{i}");
    let seconds = |i: u64| format!("{}", i as f64 / 1000.0);
    let files = [
        ("plain.csv", log_1khz(None), None),
        (
            "epoch.csv",
            log_1khz(Some(&epoch)),
            Some(TimeUnit::Milliseconds),
        ),
        (
            "zero.csv",
            log_1khz(Some(&zero)),
            Some(TimeUnit::Milliseconds),
        ),
        (
            "seconds.csv",
            log_1khz(Some(&seconds)),
            Some(TimeUnit::Seconds),
        ),
    ];
    let layout = LayoutFile {
        fs: Some(1000.0),
        rows: Some(2),
        cols: Some(2),
        ..LayoutFile::default()
    };
    let pipeline = Pipeline::new(PipelineParams::default()).unwrap();
    let spikes: Vec<_> = files
        .iter()
        .map(|(name, text, unit)| {
            let path = write(dir.path(), name, text);
            let format = CsvFormat {
                time_column: unit.map(|_| Column::Name("t_ms".into())),
                time_unit: unit.unwrap_or_default(),
                unit_given: true,
                ..CsvFormat::default()
            };
            let rec = read_recording_as(&path, &layout, &format).unwrap();
            let encoded = pipeline.encode(&rec, Baseline::None).unwrap();
            assert!(encoded.spikes.total_spikes() > 100, "{name}");
            encoded.spikes
        })
        .collect();
    for (k, (name, ..)) in files.iter().enumerate().skip(1) {
        assert!(
            spikes[k] == spikes[0],
            "{name}: spikes differ from the unstamped log's"
        );
    }
}

/// `numpy.save` of a `|S{width}` byte-string array.
fn byte_labels_npy(labels: &[&[u8]], width: usize) -> Vec<u8> {
    let mut npy = b"\x93NUMPY\x01\x00".to_vec();
    let shape = labels.len();
    let mut header =
        format!("{{'descr': '|S{width}', 'fortran_order': False, 'shape': ({shape},), }}");
    while !(10 + header.len() + 1).is_multiple_of(64) {
        header.push(' ');
    }
    header.push('\n');
    npy.extend((header.len() as u16).to_le_bytes());
    npy.extend(header.as_bytes());
    for label in labels {
        npy.extend(*label);
        npy.extend(std::iter::repeat_n(0u8, width - label.len()));
    }
    npy
}

#[test]
fn labels_that_would_merge_are_refused_not_merged() {
    let dir = tempfile::tempdir().unwrap();
    write_npy(dir.path().join("x.npy"), &reference(3, 4, 1, 2)).unwrap();
    let p = StackedParams {
        axes: "n,t,row,col".parse().unwrap(),
        fs: 1000.0,
        grid: None,
    };
    let stacked = |labels: &[&[u8]], out: &str| {
        let path = dir.path().join(format!("{out}.npy"));
        std::fs::write(&path, byte_labels_npy(labels, 5)).unwrap();
        import_stacked(
            &dir.path().join("x.npy"),
            &path,
            None,
            &p,
            &dir.path().join(out),
        )
    };
    // two non-UTF-8 byte labels would both decode to U+FFFD
    let e = stacked(&[b"\xffa", b"\xfea", b"silk"], "bytes").unwrap_err();
    assert!(e.to_string().contains("label 0 is not valid text"), "{e}");
    let e = stacked(&[b"silk", b" silk", b"wool"], "spaces").unwrap_err();
    assert!(
        e.to_string().contains(
            "label 1: label ` silk` and `silk` (label 0) differ only by surrounding spaces"
        ),
        "{e}"
    );
    assert!(!dir.path().join("spaces").exists());
    stacked(&[b"silk", b"wool", b"silk"], "fine").unwrap();
    assert_eq!(
        Dataset::open(dir.path().join("fine")).unwrap().labels(),
        vec!["silk", "wool"]
    );

    // CSV logs: labels from file names
    let logs = dir.path().join("logs");
    std::fs::create_dir(&logs).unwrap();
    let text = "stamp,c0\n0,1\n1,2\n2,3\n3,4\n";
    let a = write(&logs, "silk_V5_0.csv", text);
    let b = write(&logs, "silk _V5_1.csv", text);
    let e = import_csv(&[a.clone(), b], &params(), &dir.path().join("csv"), &|| {}).unwrap_err();
    assert!(
        e.to_string().contains(
            "label `silk ` and `silk` (file `silk_V5_0.csv`) differ only by surrounding spaces"
        ),
        "{e}"
    );
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        let name = std::ffi::OsStr::from_bytes(b"\xff_V5_0.csv");
        let bad = write(&logs, name.to_str().unwrap_or("unused"), text);
        let bad = if name.to_str().is_none() {
            let p = logs.join(name);
            std::fs::rename(&bad, &p).unwrap();
            p
        } else {
            bad
        };
        let e = import_csv(&[a, bad], &params(), &dir.path().join("csv"), &|| {}).unwrap_err();
        assert!(e.to_string().contains("not valid UTF-8"), "{e}");
    }
}

#[test]
fn import_warns_of_channels_short_of_the_grid_and_of_resting_offsets() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("src");
    std::fs::create_dir(&src).unwrap();
    // Nine channels resting at 300 with a swing of 100 (a ratio of 3 by hand), and one
    // file resting at 0, in the minority.
    let log = |rest: f64| {
        let mut text = String::from("stamp,c0,c1,c2,c3,c4,c5,c6,c7,c8\n");
        for i in 0..20 {
            let v = rest + 100.0 * f64::from(i % 2);
            let row: Vec<String> = (0..9).map(|_| v.to_string()).collect();
            text.push_str(&format!("{},{}\n", 10 * i, row.join(",")));
        }
        text
    };
    write(&src, "A_V5_0.csv", &log(300.0));
    write(&src, "B_V5_0.csv", &log(300.0));
    write(&src, "C_V5_0.csv", &log(0.0));
    let files = csv_files(&[src]).unwrap();
    let import = |p: &CsvImportParams, name: &str| {
        import_csv(&files, p, &dir.path().join(name), &|| {})
            .unwrap()
            .warnings
    };
    let on_4x4 = CsvImportParams {
        grid: Some(neurotex::Grid::full(4, 4).unwrap()),
        ..params()
    };
    assert_eq!(
        import(&on_4x4, "a"),
        [
            ImportWarning::GridNotFilled {
                channels: 9,
                rows: 4,
                cols: 4
            },
            ImportWarning::RestingOffset {
                ratio: 3.0,
                files: 2,
                total: 3
            },
        ]
    );
    let text = ImportWarning::GridNotFilled {
        channels: 9,
        rows: 4,
        cols: 4,
    }
    .to_string();
    assert!(
        text.contains("leave 7 cells empty") && text.contains("--grid 3x3"),
        "{text}"
    );
    // The sensor's own grid and a baseline: nothing to say.
    let fitting = CsvImportParams {
        grid: Some(neurotex::Grid::full(3, 3).unwrap()),
        baseline: Some(Baseline::Min),
        ..params()
    };
    assert!(import(&fitting, "b").is_empty());
}
