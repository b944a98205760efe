//! A logger's raw CSV logs after training: a model trained on their import reads the raw
//! logs as the import did (time column, unit, channels, delimiter, header), so `predict`,
//! `stream` and `encode` take them with no options and give exactly what the imported
//! copies give.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::util::{recording, s, Dir};

/// Classes and trials of the logs.
const LABELS: [&str; 3] = ["silk", "denim", "felt"];
const TRIALS: usize = 4;

/// Writes raw logs as a 4x4 sensor's host would, at 500 Hz with millisecond stamps from the
/// Unix epoch (about 1.7e12): a header `timestamp,ch0..ch15` and `,` between fields, or no
/// header and `;` when `headerless`. Returns the folder.
fn raw_logs(dir: &Dir, name: &str, headerless: bool) -> PathBuf {
    let out = dir.join(name);
    std::fs::create_dir_all(&out).unwrap();
    let sep = if headerless { ";" } else { "," };
    for (k, label) in LABELS.iter().enumerate() {
        for trial in 0..TRIALS {
            let period = 60.0 + 70.0 * k as f64;
            let rec = recording(1400, period, 0.2 + 0.1 * k as f64, (k * 100 + trial) as u64);
            let mut text = String::new();
            if !headerless {
                let names: Vec<String> = (0..16).map(|c| format!("ch{c}")).collect();
                writeln!(text, "timestamp,{}", names.join(",")).unwrap();
            }
            let t0 = 1_732_600_000_123_u64 + 97_531 * trial as u64;
            for step in (0..1400).step_by(2) {
                let values: Vec<String> = rec
                    .slice(ndarray::s![step, .., ..])
                    .iter()
                    .map(|v| format!("{v:.4}"))
                    .collect();
                writeln!(text, "{}{sep}{}", t0 + step as u64, values.join(sep)).unwrap();
            }
            std::fs::write(out.join(format!("{label}_v5_t{trial}.csv")), text).unwrap();
        }
    }
    out
}

/// Imports `logs` into `name` with `reading` options, trains a model (`causal` or not) on
/// the import, and returns the dataset and the model.
fn import_and_train(
    dir: &Dir,
    logs: &Path,
    name: &str,
    reading: &[&str],
    causal: bool,
) -> (PathBuf, PathBuf) {
    let dataset = dir.join(name);
    let mut args = vec![
        "import",
        "csv",
        s(logs),
        "--out",
        s(&dataset),
        "--name-pattern",
        "{label}_v{speed}_t{trial}.csv",
        "--grid",
        "4x4",
    ];
    args.extend_from_slice(reading);
    dir.ok(&args);
    let model = dir.join(&format!("{name}.json"));
    let mut train = vec!["train", "--dataset", s(&dataset), "--out", s(&model)];
    if causal {
        train.push("--causal");
    }
    dir.ok(&train);
    (dataset, model)
}

/// The rows of a predictions file without its `file` column.
fn predictions(path: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(path).unwrap();
    text.lines()
        .map(|l| l.split_once(',').map_or(l, |(_, rest)| rest).to_string())
        .collect()
}

/// Predicts `files` with `model` and no reading options; returns the rows.
fn predict(dir: &Dir, model: &Path, files: &[PathBuf], out: &str) -> Vec<String> {
    let out = dir.join(out);
    let mut args = vec!["predict", "--model", s(model), "--out", s(&out)];
    args.extend(files.iter().map(|f| s(f)));
    dir.ok(&args);
    predictions(&out)
}

/// Each log's file, in `dir`, in one order.
fn each_log(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for label in LABELS {
        for trial in 0..TRIALS {
            files.push(dir.join(format!("{label}_v5_t{trial}.csv")));
        }
    }
    files
}

#[test]
fn raw_logs_predict_stream_and_encode_as_their_imported_copies() {
    let dir = Dir::new();
    let logs = raw_logs(&dir, "logs", false);
    let reading = ["--time-column", "timestamp", "--baseline", "min"];
    let (dataset, model) = import_and_train(&dir, &logs, "ds", &reading, false);
    let layout = std::fs::read_to_string(dataset.join("layout.toml")).unwrap();
    assert!(layout.contains("[source]"), "{layout}");
    assert!(layout.contains("time_column = \"timestamp\""), "{layout}");

    // predict: the raw logs with no options, as the imported copies
    let raw = predict(&dir, &model, &each_log(&logs), "raw.csv");
    let copies = predict(&dir, &model, &each_log(&dataset), "copies.csv");
    assert_eq!(raw.len(), LABELS.len() * TRIALS + 1);
    assert_eq!(raw, copies);

    // encode: the raw log under the dataset's layout gives the copy's spikes, to the bit
    let (a, b) = (dir.join("raw.npy"), dir.join("copy.npy"));
    let layout = dataset.join("layout.toml");
    let first = &each_log(&logs)[0];
    dir.ok(&["encode", s(first), "--layout", s(&layout), "--out", s(&a)]);
    dir.ok(&["encode", s(&each_log(&dataset)[0]), "--out", s(&b)]);
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());

    // Another time column than the layout's has its own unit: the same log stamped in
    // seconds from 0 under `time_s` is read in seconds, not in the layout's ms.
    let text = std::fs::read_to_string(first).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().replacen("timestamp", "time_s", 1);
    let mut seconds = format!("{header}\n");
    let mut t0 = None;
    for line in lines {
        let (stamp, rest) = line.split_once(',').unwrap();
        let ms: u64 = stamp.parse().unwrap();
        let rel = ms - *t0.get_or_insert(ms);
        seconds.push_str(&format!("{}.{:03},{rest}\n", rel / 1000, rel % 1000));
    }
    let in_seconds = dir.join("seconds.csv");
    std::fs::write(&in_seconds, seconds).unwrap();
    let c = dir.join("seconds.npy");
    let args = [
        "--layout",
        s(&layout),
        "--time-column",
        "time_s",
        "--out",
        s(&c),
    ];
    dir.ok(&[&["encode", s(&in_seconds)][..], &args].concat());
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&c).unwrap());

    // stream: a causal model streams the raw log with no options, line for line as the copy
    let (_, causal) = import_and_train(&dir, &logs, "dc", &reading, true);
    let stream = |file: &Path| dir.ok(&["stream", "--model", s(&causal), "--input", s(file)]);
    let from_raw = stream(first);
    assert!(from_raw.contains("\"end\":true"), "{from_raw}");
    assert_eq!(from_raw, stream(&each_log(&dataset)[0]));
}

#[test]
fn headerless_semicolon_logs_are_read_by_index_as_imported() {
    let dir = Dir::new();
    let logs = raw_logs(&dir, "logs", true);
    // Without --time-column the epoch stamps would be a seventeenth taxel: refused.
    let out = dir.join("stamps_as_taxel");
    let err = dir.fails(&[
        "import",
        "csv",
        s(&logs),
        "--out",
        s(&out),
        "--no-header",
        "--fs",
        "500",
    ]);
    assert!(
        err.contains("column `0` rises on every row") && err.contains("--time-column 0"),
        "{err}"
    );
    assert!(!out.exists());
    let reading = ["--no-header", "--time-column", "0", "--channels", "1-16"];
    let (dataset, model) = import_and_train(&dir, &logs, "ds", &reading, false);
    let layout = std::fs::read_to_string(dataset.join("layout.toml")).unwrap();
    assert!(layout.contains("header = false"), "{layout}");
    assert!(layout.contains("delimiter = \";\""), "{layout}");
    let raw = predict(&dir, &model, &each_log(&logs), "raw.csv");
    assert_eq!(
        raw,
        predict(&dir, &model, &each_log(&dataset), "copies.csv")
    );

    // a file in neither the dataset's columns nor the raw logs' says both
    let other = dir.join("other.csv");
    std::fs::write(&other, "a,b\n1,2\n2,3\n").unwrap();
    let out = dir.join("other_p.csv");
    let err = dir.fails(&["predict", "--model", s(&model), "--out", s(&out), s(&other)]);
    assert!(
        err.contains("t_ms") && err.contains("nor read another way"),
        "{err}"
    );
    assert!(!out.exists());
}
