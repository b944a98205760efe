//! Hostile and extreme input (the limits of docs/your-data.md): headers that claim more
//! than the file holds, time spans and grids beyond the documented limits, huge counts,
//! manifest paths leaving the dataset, and inputs that would overwrite one another. Each
//! must fail with a message naming the file or option and the limit, exit 1 or 2, and leave
//! no output.

use std::path::Path;

use ndarray::{Array2, Array3};
use ndarray_npy::write_npy;

use crate::util::{s, Dir};

/// A version 1.0 `.npy` whose header says `descr` and `shape`, followed by `data` bytes
/// (whatever the header claims).
fn raw_npy(path: &Path, descr: &str, shape: &str, data: &[u8]) {
    let mut header = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend((header.len() as u16).to_le_bytes());
    bytes.extend(header.as_bytes());
    bytes.extend(data);
    std::fs::write(path, bytes).unwrap();
}

#[test]
fn npy_headers_claiming_more_than_the_file_holds_are_errors() {
    let dir = Dir::new();
    let out = dir.join("spikes.npy");
    let cases = [
        // a 192-byte file claiming 128 TB of f64
        (
            "huge.npy",
            "<f8",
            "(1000000000000, 4, 4)",
            64,
            "holds 64 bytes of data",
        ),
        (
            "zero_beside_huge.npy",
            "<f8",
            "(0, 1000000000000, 1000000000000)",
            0,
            "more elements than any array",
        ),
        (
            "empty_huge_grid.npy",
            "<f8",
            "(0, 100000, 100000)",
            0,
            "at most 1048576 cells",
        ),
        ("non_ascii.npy", "<f\u{e9}8", "(2, 4)", 64, "not ASCII"),
        (
            "unknown.npy",
            "<q16",
            "(2, 4)",
            64,
            "unsupported dtype `<q16`",
        ),
        (
            "ints.npy",
            "<i8",
            "(2, 4)",
            64,
            "float32 or float64, got dtype `<i8`",
        ),
        ("short.npy", "<f8", "(3, 4)", 64, "96 bytes of data"),
    ];
    for (name, descr, shape, data, expected) in cases {
        raw_npy(&dir.join(name), descr, shape, &vec![0u8; data]);
        let err = dir.fails(&["encode", name, "--out", s(&out)]);
        assert!(
            err.contains(name) && err.contains(expected),
            "{name}: {err}"
        );
        assert!(!out.exists());
    }
}

#[test]
fn stacked_import_refuses_bad_label_and_speed_headers() {
    let dir = Dir::new();
    let data = dir.join("data.npy");
    write_npy(&data, &Array3::<f32>::from_elem((2, 300, 1), 1.0)).unwrap();
    let out = dir.join("ds");
    raw_npy(&dir.join("good.npy"), "<i8", "(2,)", &[0; 16]);
    let cases = [
        ("labels_accent.npy", "<U\u{e9}3", "(2,)", 24, "not ASCII"),
        (
            "labels_huge.npy",
            "<U3",
            "(1000000000000,)",
            24,
            "bytes of data",
        ),
        ("labels_cplx.npy", "<c16", "(2,)", 32, "dtype `<c16`"),
    ];
    let stacked = |labels: &str, speeds: &str| {
        let mut args = vec![
            "import",
            "stacked",
            "--data",
            s(&data),
            "--axes",
            "n,t,channel",
        ];
        args.extend(["--fs", "1000", "--out", s(&out), "--labels", labels]);
        args.extend(["--speeds", speeds]);
        args.into_iter().map(String::from).collect::<Vec<_>>()
    };
    for (name, descr, shape, bytes, expected) in cases {
        raw_npy(&dir.join(name), descr, shape, &vec![0u8; bytes]);
        for args in [stacked(name, "good.npy"), stacked("good.npy", name)] {
            let args: Vec<&str> = args.iter().map(String::as_str).collect();
            let err = dir.fails(&args);
            assert!(
                err.contains(name) && err.contains(expected),
                "{args:?}: {err}"
            );
            assert!(!out.exists() && !dir.partial_left());
        }
    }
}

#[test]
fn time_spans_beyond_the_limit_are_errors_unless_raised_in_the_layout() {
    let dir = Dir::new();
    let out = dir.join("spikes.npy");
    std::fs::write(dir.join("far.csv"), "t_s,a\n0,1\n100000000,2\n").unwrap();
    write_npy(dir.join("x.npy"), &Array2::<f32>::from_elem((10, 2), 1.0)).unwrap();
    write_npy(
        dir.join("wide.npy"),
        &Array2::<f32>::from_elem((3, 4096), 1.0),
    )
    .unwrap();
    let names: Vec<String> = (0..4096).map(|j| format!("c{j}")).collect();
    let row = |t: u32| format!("{t},{}\n", vec!["1"; 4096].join(","));
    let wide = format!("t_s,{}\n{}{}", names.join(","), row(0), row(3500));
    std::fs::write(dir.join("wide.csv"), wide).unwrap();
    std::fs::write(dir.join("slow.toml"), "fs = 1e-4\n").unwrap();
    std::fs::write(dir.join("bad.toml"), "max_duration_s = -1\n").unwrap();
    dir.fails_each(
        &[
            (
                vec!["encode", "far.csv", "--time-unit", "s", "--out", s(&out)],
                "jump by 100000000 s between frames 1 and 2",
            ),
            (
                vec![
                    "encode",
                    "far.csv",
                    "--time-unit",
                    "s",
                    "--max-gap-s",
                    "1e9",
                    "--out",
                    s(&out),
                ],
                "beyond the limit of 3600 s",
            ),
            // A rate no sensor has is refused before the recording is read.
            (
                vec!["encode", "wide.npy", "--fs", "0.001", "--out", s(&out)],
                "from 1 to 1e6",
            ),
            (
                vec![
                    "encode",
                    "wide.csv",
                    "--time-unit",
                    "s",
                    "--max-gap-s",
                    "3600",
                    "--out",
                    s(&out),
                ],
                "grid cells",
            ),
            (
                vec!["encode", "x.npy", "--fs", "1e-9", "--out", s(&out)],
                "from 1 to 1e6",
            ),
            (
                vec!["encode", "x.npy", "--layout", "slow.toml", "--out", s(&out)],
                "field `fs`: a sampling rate must be a number of Hz from 1 to 1e6",
            ),
            (
                vec!["encode", "x.npy", "--layout", "bad.toml", "--out", s(&out)],
                "`max_duration_s` must be a positive",
            ),
        ],
        &out,
    );
    // 4000 s of one taxel: refused by default, read with the limit raised
    std::fs::write(dir.join("long.csv"), "t_s,a\n0,1\n2000,2\n4000,1\n").unwrap();
    let err = dir.fails(&[
        "encode",
        "long.csv",
        "--time-unit",
        "s",
        "--max-gap-s",
        "3000",
        "--out",
        s(&out),
    ]);
    assert!(err.contains("long.csv") && err.contains("4000 s"), "{err}");
    std::fs::write(
        dir.join("long.toml"),
        "max_duration_s = 5000\nmax_gap_s = 3000\ntime_unit = \"s\"\n",
    )
    .unwrap();
    dir.ok(&[
        "encode",
        "long.csv",
        "--time-unit",
        "s",
        "--layout",
        "long.toml",
        "--out",
        s(&out),
    ]);
    assert!(out.exists());
}

#[test]
fn grids_beyond_the_cap_or_overflowing_are_errors() {
    let dir = Dir::new();
    let out = dir.join("spikes.npy");
    write_npy(dir.join("x.npy"), &Array2::<f32>::from_elem((300, 2), 1.0)).unwrap();
    let huge = "rows = 100000\ncols = 100000\n";
    let wrap = "rows = 9223372036854775807\ncols = 4\n";
    let map = "rows = 100000\ncols = 100000\nchannel_map = [[0, 0], [0, 1]]\n";
    for (name, text) in [("huge.toml", huge), ("wrap.toml", wrap), ("map.toml", map)] {
        std::fs::write(dir.join(name), text).unwrap();
        let err = dir.fails(&["encode", "x.npy", "--layout", name, "--out", s(&out)]);
        assert!(err.contains(name) && err.contains("1048576 cells"), "{err}");
        assert!(!out.exists());
    }
    std::fs::create_dir(dir.join("logs")).unwrap();
    std::fs::write(dir.join("logs/a.csv"), "t_ms,x\n0,1\n1,2\n").unwrap();
    let ds = dir.join("ds");
    for grid in ["100000x100000", "4294967296x4294967296"] {
        let args = [
            "import",
            "csv",
            "logs",
            "--out",
            s(&ds),
            "--time-column",
            "t_ms",
            "--grid",
            grid,
        ];
        let err = dir.fails(&args);
        assert!(
            err.contains("--grid") && err.contains("1048576 cells"),
            "{err}"
        );
        assert!(!ds.exists());
    }
}

#[test]
fn count_options_are_bounded() {
    let dir = Dir::new();
    let data = dir.dataset("data", &["A", "B"], &[5.0], 5);
    let huge = "18446744073709551615";
    for repeats in [huge, "10001"] {
        let args = [
            "evaluate",
            "--dataset",
            s(&data),
            "--method",
            "glcm3d",
            "--repeats",
            repeats,
        ];
        let err = dir.fails(&args);
        assert!(
            err.contains("repeats") && err.contains("at most 10000"),
            "{err}"
        );
    }
    let out = dir.join("sim");
    let rep = dir.join("rep");
    dir.fails_each(
        &[
            (
                vec!["simulate", "--out", s(&out), "--speeds", "0.001"],
                "at most 600 s",
            ),
            (
                vec!["simulate", "--out", s(&out), "--speeds", "1e-300"],
                "at most 600 s",
            ),
            (
                vec!["simulate", "--out", s(&out), "--trials", "4000000000"],
                "between 1 and 10000",
            ),
            (
                vec!["simulate", "--out", s(&out), "--speeds", "5,5"],
                "5 twice",
            ),
            (
                vec!["simulate", "--out", s(&out), "--textures", "FT1,ft1"],
                "FT1 twice",
            ),
        ],
        &out,
    );
    let args = ["reproduce", "--out", s(&rep), "--trials", "4000000000"];
    let err = dir.fails(&args);
    assert!(err.contains("between 1 and 10000"), "{err}");
    assert!(!rep.exists());
}

#[test]
fn manifest_paths_must_stay_inside_the_dataset() {
    let dir = Dir::new();
    let data = dir.dataset("data", &["A", "B"], &[5.0], 5);
    std::fs::copy(data.join("A_5_0.npy"), dir.join("outside.npy")).unwrap();
    let manifest = std::fs::read_to_string(data.join("manifest.csv")).unwrap();
    let absolute = dir.join("outside.npy");
    #[cfg(unix)]
    std::os::unix::fs::symlink(&absolute, data.join("link.npy")).unwrap();
    let mut entries = vec!["../outside.npy", s(&absolute)];
    if cfg!(unix) {
        entries.push("link.npy");
    }
    let model = dir.join("model.json");
    for entry in entries {
        let changed = manifest.replacen("A_5_0.npy", entry, 1);
        std::fs::write(data.join("manifest.csv"), changed).unwrap();
        let args = ["train", "--dataset", s(&data), "--out", s(&model)];
        let err = dir.fails(&args);
        assert!(
            err.contains("manifest.csv")
                && err.contains(entry)
                && err.contains("outside the dataset folder"),
            "{entry}: {err}"
        );
        assert!(!model.exists());
        assert!(err.contains("--allow-outside-paths"), "{err}");
        // The user may let them out.
        dir.ok(&[&args[..], &["--allow-outside-paths"]].concat());
        std::fs::remove_file(&model).unwrap();
    }
    // a link that stays inside is fine
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(data.join("A_5_0.npy"), data.join("inside.npy")).unwrap();
        let changed = manifest.replacen("A_5_0.npy", "inside.npy", 1);
        std::fs::write(data.join("manifest.csv"), changed).unwrap();
        dir.ok(&["train", "--dataset", s(&data), "--out", s(&model)]);
    }
}

#[test]
fn inputs_of_one_name_are_not_merged_into_one_file() {
    let dir = Dir::new();
    for folder in ["a", "b"] {
        std::fs::create_dir(dir.join(folder)).unwrap();
        std::fs::write(dir.join(folder).join("x.csv"), "t_ms,c\n0,1\n1,2\n").unwrap();
    }
    let out = dir.join("ds");
    let args = [
        "import",
        "csv",
        "a",
        "b",
        "--out",
        s(&out),
        "--time-column",
        "t_ms",
    ];
    let err = dir.fails(&args);
    assert!(
        err.contains("two inputs have the file name `x.csv`"),
        "{err}"
    );
    assert!(!out.exists() && !dir.partial_left());
}

/// Spike times of each cell from an `encode --events` file of a one-row grid.
fn events_by_column(path: &Path, cols: usize) -> Vec<Vec<i64>> {
    let mut trains = vec![Vec::new(); cols];
    for line in std::fs::read_to_string(path).unwrap().lines().skip(1) {
        let fields: Vec<i64> = line.split(',').map(|f| f.parse().unwrap()).collect();
        trains[fields[2] as usize].push(fields[0]);
    }
    trains
}

/// Co-occurrence counts of 1 ms bins (levels 0 and 15: no spike or one) over every offset
/// the plan of `distances` has on a 1 x 2 grid, counted from spike times in u64: for one cell
/// pair and time offset, pairs of two spikes by look-up, the other three by subtraction.
fn binary_counts(trains: &[Vec<i64>], bins: i64, distances: &[i64]) -> [u64; 4] {
    use neurotex::features::DIRECTIONS_13;
    let sets: Vec<std::collections::HashSet<i64>> =
        trains.iter().map(|t| t.iter().copied().collect()).collect();
    let in_range = |t: &[i64], lo: i64, hi: i64| t.iter().filter(|&&x| lo <= x && x < hi).count();
    let mut n = [0u64; 4]; // (0,0), (0,1), (1,0), (1,1)
    for &d in distances {
        for &(dr, dc, dt) in &DIRECTIONS_13 {
            let (dr, dc, dt) = (i64::from(dr) * d, i64::from(dc) * d, i64::from(dt) * d);
            for a in 0..2i64 {
                let b = a + dc;
                if dr != 0 || !(0..2).contains(&b) {
                    continue;
                }
                let (lo, hi) = (0.max(-dt), bins.min(bins - dt));
                let (ta, tb) = (&trains[a as usize], &sets[b as usize]);
                let both = ta
                    .iter()
                    .filter(|&&t| lo <= t && t < hi && tb.contains(&(t + dt)))
                    .count() as u64;
                let first = in_range(ta, lo, hi) as u64;
                let second = in_range(&trains[b as usize], lo + dt, hi + dt) as u64;
                n[3] += both;
                n[2] += first - both;
                n[1] += second - both;
                n[0] += (hi - lo) as u64 - first - second + both;
            }
        }
    }
    n
}

#[test]
fn glcm_counts_beyond_u32_are_counted_in_u64() {
    // 2 200 s of a 1 x 2 grid in 1 ms bins with distances 1..1000: 4.4 billion pairs,
    // more than u32 counts hold.
    let dir = Dir::new();
    let data = dir.join("long");
    std::fs::create_dir_all(&data).unwrap();
    let steps = 2_200_000;
    let rec = Array3::from_shape_fn((steps, 1, 2), |(t, _, c)| {
        let phase = t as f32 / 5000.0 + c as f32;
        0.6 + 0.4 * phase.sin()
    });
    write_npy(data.join("a.npy"), &rec).unwrap();
    std::fs::write(data.join("manifest.csv"), "file,label\na.npy,x\n").unwrap();
    let distances: Vec<i64> = (1..=1000).collect();
    let list = distances
        .iter()
        .map(i64::to_string)
        .collect::<Vec<_>>()
        .join(",");
    let stages = ["--whole", "--bin-ms", "1", "--distances", &list];
    let (events, table) = (dir.join("ev.csv"), dir.join("f.csv"));
    let npy = data.join("a.npy");
    let mut encode = vec!["encode", s(&npy), "--out", "sp.npy", "--events", s(&events)];
    encode.extend(stages);
    dir.ok(&encode);
    let mut features = vec!["features", "--dataset", s(&data), "--method", "glcm3d"];
    features.extend(["--out", s(&table)]);
    features.extend(stages);
    dir.ok(&features);

    let n = binary_counts(&events_by_column(&events, 2), steps as i64, &distances);
    assert!(n.iter().sum::<u64>() > u64::from(u32::MAX), "{n:?}");
    let mut counts = vec![0u64; 256];
    (counts[0], counts[15], counts[15 * 16], counts[255]) = (n[0], n[1], n[2], n[3]);
    let expected = neurotex::features::haralick(&counts, 16).to_array();
    let csv = std::fs::read_to_string(&table).unwrap();
    let row: Vec<f64> = csv
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .skip(2)
        .map(|v| v.parse().unwrap())
        .collect();
    for (got, want) in row.iter().zip(expected) {
        assert!(
            (got - want).abs() <= 1e-12 * want.abs().max(1.0),
            "{row:?} vs {expected:?}"
        );
    }
}

/// Runs `neurotex args...` in `dir`, killing it and failing the test when it has not ended
/// within a minute (a reader blocked on a pipe never would); returns its exit code and
/// standard error.
#[cfg(unix)]
fn run_or_hang(dir: &Dir, args: &[&str]) -> (Option<i32>, String) {
    use std::io::Read;
    use std::process::{Command, Stdio};
    let mut child = Command::new(env!("CARGO_BIN_EXE_neurotex"))
        .args(args)
        .current_dir(dir.path())
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(60);
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if std::time::Instant::now() > deadline {
            child.kill().unwrap();
            child.wait().unwrap();
            panic!("neurotex {args:?} did not end within a minute");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    (status.code(), err)
}

/// A FIFO at `path`.
#[cfg(unix)]
fn fifo(path: &Path) {
    let made = std::process::Command::new("mkfifo")
        .arg(path)
        .status()
        .unwrap();
    assert!(made.success());
}

#[cfg(unix)]
#[test]
fn what_is_not_a_regular_file_is_left_out_of_folders_and_refused_by_name() {
    let dir = Dir::new();
    let logs = dir.join("logs");
    std::fs::create_dir(&logs).unwrap();
    let rows: String = (0..400).map(|i| format!("{i},{},1\n", i % 7)).collect();
    std::fs::write(logs.join("a_1.csv"), format!("t_ms,c0,c1\n{rows}")).unwrap();
    std::fs::write(logs.join("b_1.csv"), format!("t_ms,c0,c1\n{rows}")).unwrap();
    fifo(&logs.join("pipe.csv"));
    std::os::unix::fs::symlink("/dev/zero", logs.join("zero.csv")).unwrap();
    let read = ["--time-column", "t_ms"];
    // In a folder: left out, with a warning naming each.
    let (code, err) = run_or_hang(
        &dir,
        &[&["import", "csv", "logs", "--out", "ds"], &read[..]].concat(),
    );
    assert_eq!(code, Some(0), "{err}");
    assert!(
        err.contains("pipe.csv: is a pipe (FIFO), not a regular file"),
        "{err}"
    );
    assert!(
        err.contains("zero.csv: is a character device, not a regular file"),
        "{err}"
    );
    let (code, err) = run_or_hang(
        &dir,
        &[&["inspect", "logs", "--no-encoder"], &read[..]].concat(),
    );
    assert_eq!(code, Some(0), "{err}");
    assert!(err.contains("pipe.csv: is a pipe (FIFO)"), "{err}");
    // Named: refused.
    for name in ["logs/pipe.csv", "logs/zero.csv"] {
        for args in [
            vec!["inspect", name, "--no-encoder"],
            vec!["import", "csv", name, "--out", "ds2"],
            vec!["encode", name, "--out", "spikes.npy"],
        ] {
            let (code, err) = run_or_hang(&dir, &[&args[..], &read[..]].concat());
            assert_eq!(code, Some(1), "{args:?}: {err}");
            assert!(err.contains("not a regular file"), "{args:?}: {err}");
        }
    }
    // Event logs alike.
    let events = dir.join("events");
    std::fs::create_dir(&events).unwrap();
    std::fs::write(events.join("a.csv"), "t,x,y,p\n0,0,0,1\n300,1,1,0\n").unwrap();
    fifo(&events.join("pipe.csv"));
    fifo(&events.join("pipe.npy"));
    let import = [
        "import",
        "events",
        "--grid",
        "2x2",
        "--time-unit",
        "ms",
        "--out",
    ];
    let (code, err) = run_or_hang(&dir, &[&import[..], &["eds", "events"]].concat());
    assert_eq!(code, Some(0), "{err}");
    assert!(err.contains("pipe.npy: is a pipe (FIFO)"), "{err}");
    let (code, err) = run_or_hang(&dir, &[&import[..], &["eds2", "events/pipe.csv"]].concat());
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("not a regular file"), "{err}");
    // A dataset's recording, manifest or layout.
    let data = dir.dataset("data", &["A", "B"], &[5.0], 5);
    let features = [
        "features",
        "--dataset",
        "data",
        "--method",
        "glcm3d",
        "--out",
        "f.csv",
    ];
    std::fs::remove_file(data.join("A_5_0.npy")).unwrap();
    fifo(&data.join("A_5_0.npy"));
    let (code, err) = run_or_hang(&dir, &features);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("`A_5_0.npy` is a pipe (FIFO), not a regular file"),
        "{err}"
    );
    std::fs::remove_file(data.join("A_5_0.npy")).unwrap();
    fifo(&data.join("layout.toml"));
    let (code, err) = run_or_hang(&dir, &features);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("layout.toml: is a pipe (FIFO)"), "{err}");
    std::fs::remove_file(data.join("layout.toml")).unwrap();
    std::fs::remove_file(data.join("manifest.csv")).unwrap();
    fifo(&data.join("manifest.csv"));
    let (code, err) = run_or_hang(&dir, &features);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("manifest.csv: is a pipe (FIFO)"), "{err}");
    assert!(!dir.join("f.csv").exists());
}

#[test]
fn a_line_longer_than_the_limit_is_refused_naming_it() {
    let dir = Dir::new();
    // 64 MiB and one byte without a line break
    let long = vec![b'7'; (64 << 20) + 1];
    let logs = dir.join("logs");
    std::fs::create_dir(&logs).unwrap();
    std::fs::write(logs.join("long.csv"), &long).unwrap();
    let says = "line 1 is longer than 67108864 bytes";
    for args in [
        vec![
            "inspect",
            "logs/long.csv",
            "--no-encoder",
            "--time-column",
            "t_ms",
        ],
        vec![
            "import",
            "csv",
            "logs",
            "--out",
            "ds",
            "--time-column",
            "t_ms",
        ],
        vec![
            "import",
            "events",
            "logs",
            "--out",
            "ds",
            "--grid",
            "2x2",
            "--time-unit",
            "ms",
        ],
        vec![
            "encode",
            "logs/long.csv",
            "--out",
            "spikes.npy",
            "--delimiter",
            ",",
        ],
    ] {
        let err = dir.fails(&args);
        assert!(
            err.contains("long.csv") && err.contains(says),
            "{args:?}: {err}"
        );
    }
    // a dataset's manifest, and a layout larger than the limit
    let data = dir.dataset("data", &["A", "B"], &[5.0], 5);
    let features = [
        "features",
        "--dataset",
        "data",
        "--method",
        "glcm3d",
        "--out",
        "f.csv",
    ];
    let manifest = std::fs::read_to_string(data.join("manifest.csv")).unwrap();
    std::fs::write(data.join("manifest.csv"), &long).unwrap();
    let err = dir.fails(&features);
    assert!(err.contains("manifest.csv") && err.contains(says), "{err}");
    std::fs::write(data.join("manifest.csv"), manifest).unwrap();
    let mut layout = b"# ".to_vec();
    layout.extend(&long);
    std::fs::write(data.join("layout.toml"), layout).unwrap();
    let err = dir.fails(&features);
    assert!(
        err.contains("layout.toml: is longer than 67108864 bytes"),
        "{err}"
    );
    assert!(!dir.join("f.csv").exists() && !dir.join("ds").exists());
}

#[test]
fn a_repeated_column_name_is_refused_in_every_table_read() {
    let dir = Dir::new();
    let both = |i: usize, j: usize, name: &str| {
        format!("columns {i} and {j} of line 1 are both named `{name}`: each column read needs a name of its own")
    };
    // an event log, imported
    let logs = dir.join("logs");
    std::fs::create_dir(&logs).unwrap();
    std::fs::write(logs.join("a.csv"), "t,x,y,x,p\n0,0,0,1,1\n300,1,1,0,0\n").unwrap();
    let err = dir.fails(&[
        "import",
        "events",
        "logs",
        "--out",
        "eds",
        "--grid",
        "2x2",
        "--time-unit",
        "ms",
    ]);
    assert!(
        err.contains("a.csv") && err.contains(&both(2, 4, "x")),
        "{err}"
    );
    // an event dataset's file, and one column named for two roles in its layout
    let ds = dir.join("events");
    std::fs::create_dir(&ds).unwrap();
    std::fs::write(ds.join("a.csv"), "t,x,y,p\n0,0,0,1\n300,1,1,0\n").unwrap();
    std::fs::write(ds.join("b.csv"), "t,x,y,p,p\n0,0,0,1,0\n300,1,1,0,1\n").unwrap();
    std::fs::write(ds.join("manifest.csv"), "file,label\na.csv,A\nb.csv,B\n").unwrap();
    let layout = "rows = 2\ncols = 2\n\n[events]\ntime_unit = \"ms\"\n";
    std::fs::write(ds.join("layout.toml"), layout).unwrap();
    let features = |data: &str| {
        dir.fails(&[
            "features",
            "--dataset",
            data,
            "--method",
            "glcm3d",
            "--out",
            "f.csv",
        ])
    };
    let err = features("events");
    assert!(
        err.contains("b.csv") && err.contains(&both(4, 5, "p")),
        "{err}"
    );
    std::fs::write(ds.join("b.csv"), "t,x,y,p\n0,0,0,1\n300,1,1,0\n").unwrap();
    std::fs::write(
        ds.join("layout.toml"),
        format!("{layout}polarity = \"x\"\n"),
    )
    .unwrap();
    let err = features("events");
    assert!(
        err.contains("column `x` is both x and the polarity"),
        "{err}"
    );
    // a manifest
    let data = dir.dataset("data", &["A", "B"], &[5.0], 5);
    let manifest = std::fs::read_to_string(data.join("manifest.csv")).unwrap();
    for (header, name, at) in [
        ("session,session", "session", (8, 9)),
        ("label", "label", (2, 8)),
    ] {
        let changed: String = manifest
            .lines()
            .enumerate()
            .map(|(i, line)| match i {
                0 => format!("{line},{header}\n"),
                _ => format!(
                    "{line},{}\n",
                    if header.contains(',') { "s1,s2" } else { "A" }
                ),
            })
            .collect();
        std::fs::write(data.join("manifest.csv"), changed).unwrap();
        let err = features("data");
        assert!(
            err.contains("manifest.csv") && err.contains(&both(at.0, at.1, name)),
            "{err}"
        );
    }
    assert!(!dir.join("f.csv").exists() && !dir.join("eds").exists());
}

#[test]
fn layout_values_an_import_would_refuse_are_refused_on_reading() {
    let dir = Dir::new();
    let data = dir.dataset("data", &["A", "B"], &[5.0], 5);
    let grid = "rows = 4\ncols = 4\n";
    let row_major: Vec<String> = (0..16).map(|k| format!("[{}, {}]", k / 4, k % 4)).collect();
    let map = format!("channel_map = [{}]\n", row_major.join(", "));
    let cases = [
        (
            format!("{grid}mask = [\"0000\", \"0000\", \"0000\", \"0000\"]\n"),
            "field `mask` must leave at least one taxel",
        ),
        (
            format!("{grid}mask = [\"1110\", \"1111\", \"1111\", \"1111\"]\n{map}"),
            "field `channel_map`: channel 3 maps to [0, 3], a cell the mask marks empty",
        ),
        (
            format!("{grid}channels = [\"a\", \"b\", \"c\"]\n"),
            "field `channels` names 3 channels, but the 4x4 grid has 16 taxel cells",
        ),
        (
            format!("{grid}channels = [\"a\", \"b\"]\n{map}"),
            "field `channel_map` has 16 cells for the 2 channels of `channels`",
        ),
        (
            "channels = [\"a\", \"b\", \"a\"]\n".to_string(),
            "field `channels` names `a` twice (entries 1 and 3)",
        ),
        (
            format!("{grid}\n[events]\ntime_unit = \"ms\"\nvalues = [1, 1]\n"),
            "the ON and OFF polarity values must be two different integers",
        ),
    ];
    for (layout, says) in cases {
        std::fs::write(data.join("layout.toml"), &layout).unwrap();
        let err = dir.fails(&[
            "features",
            "--dataset",
            "data",
            "--method",
            "glcm3d",
            "--out",
            "f.csv",
        ]);
        assert!(
            err.contains("layout.toml") && err.contains(says),
            "{layout}: {err}"
        );
        let err = dir.fails(&[
            "encode",
            "data/A_5_0.npy",
            "--layout",
            "data/layout.toml",
            "--out",
            "s.npy",
        ]);
        assert!(err.contains(says), "{layout}: {err}");
    }
    assert!(!dir.join("f.csv").exists() && !dir.join("s.npy").exists());
}
