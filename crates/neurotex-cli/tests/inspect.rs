//! `neurotex inspect` on fabricated raw logs, each with one footgun a newcomer meets: the
//! finding's code and its suggested option, and its absence on the clean logs.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::util::{s, Dir};

/// How the fabricated logs go wrong.
#[derive(Clone, Copy, Default)]
struct Footguns {
    /// Every channel rests this far above zero (the signals span about 1).
    offset: f64,
    /// Channels whose signal is a thousandth of the others'.
    weak: usize,
    /// The last channel repeats the one before it.
    copy: bool,
    /// The first class has three times the trials of the others.
    unbalanced: bool,
    /// The first log has a 60 ms hole in its 10 ms stamps.
    gap: bool,
    /// The stamps' column is `tick`, a name the reader does not take for time (a sample
    /// counter's), instead of `timestamp`.
    tick: bool,
}

/// Logs of a 3x3 sensor at 100 Hz: `timestamp` in ms (not a name the reader finds alone),
/// then `c0`..`c8`; three classes at 5 and 10 mm/s, 5 trials each (15 for the first class
/// when unbalanced), named `{label}_V{speed}_{trial}.csv`.
fn logs(dir: &Dir, name: &str, f: Footguns) -> PathBuf {
    let out = dir.join(name);
    std::fs::create_dir_all(&out).unwrap();
    for (k, label) in ["silk", "denim", "felt"].iter().enumerate() {
        let trials = if f.unbalanced && k == 0 { 15 } else { 5 };
        for speed in [5, 10] {
            for trial in 0..trials {
                let clock = if f.tick { "tick" } else { "timestamp" };
                let mut text = format!("{clock},c0,c1,c2,c3,c4,c5,c6,c7,c8\n");
                let period = 0.3 + 0.2 * k as f64 + 0.01 * trial as f64;
                let mut t_ms = 1000.0;
                for step in 0..400 {
                    t_ms += if f.gap && k == 0 && trial == 0 && speed == 5 && step == 200 {
                        60.0
                    } else {
                        10.0
                    };
                    let t = step as f64 / 100.0;
                    let mut values: Vec<f64> = (0..9)
                        .map(|c| {
                            let phase = 2.0 * std::f64::consts::PI * (t / period + c as f64 / 9.0);
                            let amp = if c < f.weak { 1e-3 } else { 1.0 };
                            f.offset + 0.05 + amp * 0.5 * (1.0 + phase.sin())
                        })
                        .collect();
                    if f.copy {
                        values[8] = values[7];
                    }
                    let row: Vec<String> = values.iter().map(|v| format!("{v:.6}")).collect();
                    writeln!(text, "{t_ms},{}", row.join(",")).unwrap();
                }
                let file = format!("{label}_V{speed}_{trial}.csv");
                std::fs::write(out.join(file), text).unwrap();
            }
        }
    }
    out
}

/// `inspect --json` on `logs` with the import's options and `extra`: the findings as
/// `(code, suggestion)`.
fn findings(dir: &Dir, logs: &Path, extra: &[&str]) -> Vec<(String, String)> {
    let mut args = vec![
        "inspect",
        s(logs),
        "--name-pattern",
        "{label}_V{speed}_{trial}.csv",
        "--json",
    ];
    args.extend_from_slice(extra);
    let json: Value = serde_json::from_str(&dir.ok(&args)).expect("inspect --json prints JSON");
    json["findings"]
        .as_array()
        .expect("findings")
        .iter()
        .map(|f| {
            (
                f["code"].as_str().unwrap().to_string(),
                f["suggestion"].as_str().unwrap().to_string(),
            )
        })
        .collect()
}

fn suggestion<'a>(found: &'a [(String, String)], code: &str) -> &'a str {
    match found.iter().find(|f| f.0 == code) {
        Some(f) => &f.1,
        None => panic!("no `{code}` among {found:?}"),
    }
}

const FOOTGUNS: [&str; 8] = [
    "grid-not-filled",
    "resting-offset",
    "taxels-unresponsive",
    "copied-channel",
    "time-as-channel",
    "unbalanced",
    "gaps",
    "one-row",
];

#[test]
fn clean_logs_have_none_of_the_footguns() {
    let dir = Dir::new();
    let clean = logs(&dir, "clean", Footguns::default());
    let found = findings(
        &dir,
        &clean,
        &["--time-column", "timestamp", "--grid", "3x3"],
    );
    for code in FOOTGUNS {
        assert!(found.iter().all(|f| f.0 != code), "{code} in {found:?}");
    }
}

#[test]
fn each_footgun_is_named_with_its_option() {
    let dir = Dir::new();
    let timed = ["--time-column", "timestamp"];
    let clean = logs(&dir, "clean", Footguns::default());
    // nine channels on the README's 4x4 grid; and on no grid at all
    let found = findings(&dir, &clean, &[&timed[..], &["--grid", "4x4"]].concat());
    assert!(suggestion(&found, "grid-not-filled").contains("--grid 3x3"));
    let found = findings(&dir, &clean, &timed);
    assert!(suggestion(&found, "one-row").contains("--grid 3x3"));
    // a clock column left among the channels (a rate given instead)
    let tick = logs(
        &dir,
        "tick",
        Footguns {
            tick: true,
            ..Footguns::default()
        },
    );
    let found = findings(&dir, &tick, &["--fs", "100", "--grid", "2x5"]);
    assert!(suggestion(&found, "time-as-channel").contains("--time-column tick"));
    let grid = [&timed[..], &["--grid", "3x3"]].concat();
    // a large resting offset without a baseline; none with one
    let offset = logs(
        &dir,
        "offset",
        Footguns {
            offset: 20.0,
            ..Footguns::default()
        },
    );
    let found = findings(&dir, &offset, &grid);
    assert!(suggestion(&found, "resting-offset").contains("--baseline min"));
    // taxels held at the ceiling by the offset: --gain auto, which would not lower the
    // gain here, is not the remedy offered
    let held = suggestion(&found, "taxels-unresponsive");
    assert!(held.starts_with("--baseline min"), "{held}");
    assert!(
        held.contains("so the gain is not what holds them at the ceiling"),
        "{held}"
    );
    // the offset removed and a gain too low for any neuron to fire: silent, not at the
    // ceiling, and a higher gain is what helps
    let low = [&grid[..], &["--baseline", "min", "--gain", "1"]].concat();
    let found = findings(&dir, &offset, &low);
    let silent = suggestion(&found, "taxels-unresponsive");
    assert!(
        silent.starts_with("--gain auto (it would choose"),
        "{silent}"
    );
    let found = findings(&dir, &offset, &[&grid[..], &["--baseline", "min"]].concat());
    assert!(found.iter().all(|f| f.0 != "resting-offset"), "{found:?}");
    // most taxels silent at the gain
    let weak = logs(
        &dir,
        "weak",
        Footguns {
            weak: 6,
            ..Footguns::default()
        },
    );
    let found = findings(&dir, &weak, &grid);
    assert!(suggestion(&found, "taxels-unresponsive").contains("--gain auto"));
    // a copied channel, unbalanced classes, a gap in the stamps
    let copy = logs(
        &dir,
        "copy",
        Footguns {
            copy: true,
            ..Footguns::default()
        },
    );
    let found = findings(&dir, &copy, &grid);
    assert!(suggestion(&found, "copied-channel").contains("--channels without `c8`"));
    let unbalanced = logs(
        &dir,
        "unbalanced",
        Footguns {
            unbalanced: true,
            ..Footguns::default()
        },
    );
    let found = findings(&dir, &unbalanced, &grid);
    assert!(suggestion(&found, "unbalanced").contains("largest class's share"));
    let gap = logs(
        &dir,
        "gap",
        Footguns {
            gap: true,
            ..Footguns::default()
        },
    );
    let found = findings(&dir, &gap, &grid);
    assert!(suggestion(&found, "gaps").contains("--max-gap-s"));
}

#[test]
fn a_dataset_folder_is_inspected_and_written_whole() {
    let dir = Dir::new();
    let clean = logs(
        &dir,
        "clean",
        Footguns {
            offset: 20.0,
            ..Footguns::default()
        },
    );
    let pattern = "{label}_V{speed}_{trial}.csv";
    dir.ok(&[
        "import",
        "csv",
        s(&clean),
        "--out",
        "ds",
        "--name-pattern",
        pattern,
        "--time-column",
        "timestamp",
        "--grid",
        "3x3",
    ]);
    // the same findings as on the raw logs with the same options
    let text = dir.ok(&["inspect", "ds", "--out", "checked"]);
    assert!(
        text.contains("severe: [signals]") && text.contains("--baseline min"),
        "{text}"
    );
    // the encoder's line names the neurons it checked, the paper's by default
    assert!(
        text.contains("encoder (Izhikevich neurons of type RS) at gain 8:"),
        "{text}"
    );
    let json = dir.ok(&["inspect", "ds", "--json", "--preset", "fs"]);
    let json: Value = serde_json::from_str(&json).unwrap();
    assert_eq!(json["encoder"]["neurons"], "FS", "{json}");
    for f in [
        "inspect.md",
        "inspect.json",
        "figures/traces.png",
        "figures/taxels.svg",
        "figures/design.png",
    ] {
        assert!(dir.join("checked").join(f).is_file(), "{f}");
    }
    let md = std::fs::read_to_string(dir.join("checked/inspect.md")).unwrap();
    assert!(
        md.contains("## Design") && md.contains("resting-offset"),
        "{md}"
    );
    // nine channels imported row by row onto 4x4: the dataset's inspection says so too
    dir.ok(&[
        "import",
        "csv",
        s(&clean),
        "--out",
        "ds44",
        "--name-pattern",
        pattern,
        "--time-column",
        "timestamp",
        "--grid",
        "4x4",
    ]);
    let text = dir.ok(&["inspect", "ds44", "--no-encoder"]);
    assert!(text.contains("--grid 3x3"), "{text}");
    // reading options are for raw logs; --strict turns a severe finding into status 2
    let err = dir.fails(&["inspect", "ds", "--grid", "3x3"]);
    assert!(err.contains("dataset folder"), "{err}");
    assert_eq!(
        dir.run(&["inspect", "ds", "--strict", "--no-encoder"])
            .status
            .code(),
        Some(2)
    );
}

#[test]
fn import_warns_on_a_clock_read_as_a_channel() {
    let dir = Dir::new();
    let tick = logs(
        &dir,
        "tick",
        Footguns {
            tick: true,
            ..Footguns::default()
        },
    );
    let pattern = "{label}_V{speed}_{trial}.csv";
    let run = dir.run(&[
        "import",
        "csv",
        s(&tick),
        "--out",
        "ds",
        "--name-pattern",
        pattern,
        "--fs",
        "100",
        "--grid",
        "2x5",
    ]);
    assert!(run.status.success(), "{}", run.stderr);
    assert!(
        run.stderr
            .contains("warning: channel `tick` rises at every row in 30 of 30 logs"),
        "{}",
        run.stderr
    );
    assert!(run.stderr.contains("--time-column tick"), "{}", run.stderr);
}

#[test]
fn labels_differing_only_in_case_are_named_at_every_start() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["Rough", "Smooth"], &[5.0], 6);
    let manifest = std::fs::read_to_string(ds.join("manifest.csv")).unwrap();
    // Two of Rough's six rows written `rough`: a third class, silently, before the check.
    let mut written = 0;
    let lines: Vec<String> = manifest
        .lines()
        .map(|line| match line.contains(",Rough,") && written < 2 {
            true => {
                written += 1;
                line.replace(",Rough,", ",rough,")
            }
            false => line.to_string(),
        })
        .collect();
    std::fs::write(ds.join("manifest.csv"), lines.join("\n") + "\n").unwrap();
    let text = dir.ok(&["inspect", s(&ds), "--no-encoder"]);
    assert!(
        text.contains(
            "severe: [labels] labels `Rough` and `rough` differ only in case: they are 2 classes"
        ),
        "{text}"
    );
    let run = dir.run(&["evaluate", "--dataset", s(&ds), "--folds", "2", "--k", "1"]);
    assert!(
        run.stderr
            .contains("labels `Rough` and `rough` differ only in case"),
        "{}",
        run.stderr
    );
}

#[test]
fn a_recording_without_signal_is_named() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[5.0], 6);
    let flat = ndarray::Array3::<f32>::from_elem((1400, 4, 4), 1.0);
    ndarray_npy::write_npy(ds.join("A_5_2.npy"), &flat).unwrap();
    let text = dir.ok(&["inspect", s(&ds), "--no-encoder"]);
    assert!(
        text.contains("severe: [signals] 1 recording holds no signal, every channel one value from start to end: `A_5_2.npy`"),
        "{text}"
    );
    // Every command that encodes it says so once, whichever recordings its start checked.
    let run = dir.run(&["evaluate", "--dataset", s(&ds), "--folds", "2", "--k", "1"]);
    let said = "A_5_2.npy: every channel holds one value from start to end (no signal)";
    assert_eq!(run.stderr.matches(said).count(), 1, "{}", run.stderr);
    let model = dir.join("m.json");
    dir.ok(&["train", "--dataset", s(&ds), "--k", "1", "--out", s(&model)]);
    let file = ds.join("A_5_2.npy");
    let args = ["predict", "--model", s(&model), s(&file), "--out", "-"];
    assert!(dir
        .run(&args)
        .stderr
        .contains("every channel holds one value"));
}
