//! The bodies of the fuzz targets, one function per reader, each taking raw bytes. They are
//! shared (through `#[path]`) with the stable test `crates/neurotex/tests/hostile_input.rs`,
//! which runs them over [`seeds`] and deterministic mutations of them, so the normal test
//! suite checks the same paths that `cargo +nightly fuzz` explores.
//!
//! The readers take paths, so each call writes its bytes into a fresh folder under a
//! per-process scratch folder, and removes it afterwards. Errors are the expected answer to
//! bad bytes and are ignored; only a panic, an abort or a hang is a finding.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use neurotex::csvlog::{Column, CsvFormat, DuplicateStamps};
use neurotex::import::{import_csv, import_stacked, ChannelSelect, CsvImportParams};
use neurotex::import::{NamePattern, StackedParams};
use neurotex::recording::{read_manifest, read_recording, Dataset, LayoutFile};
use neurotex::recording::{Baseline, TimeUnit};

/// The targets, by name: the names of the fuzz targets and of the corpus folders.
pub const TARGETS: [&str; 7] = [
    "npy",
    "csv",
    "manifest",
    "layout",
    "dataset",
    "import_csv",
    "import_stacked",
];

/// Runs target `name` on `data`; whether the input was accepted all the way (read, or
/// imported and read back).
///
/// # Panics
/// On an unknown target name (a caller bug), or wherever the reader under test panics.
pub fn run(name: &str, data: &[u8]) -> bool {
    match name {
        "npy" => npy(data),
        "csv" => csv(data),
        "manifest" => manifest(data),
        "layout" => layout(data),
        "dataset" => dataset(data),
        "import_csv" => import_csv_files(data),
        "import_stacked" => import_stacked_arrays(data),
        other => panic!("unknown fuzz target {other}"),
    }
}

/// A fresh, empty folder for one input, removed when dropped.
pub struct Case(PathBuf);

impl Case {
    /// A new folder under the per-process scratch folder (unique per call, so tests may
    /// run cases on several threads).
    pub fn new() -> Case {
        static NEXT: AtomicUsize = AtomicUsize::new(0);
        let root = std::env::temp_dir().join(format!("neurotex-fuzz-{}", std::process::id()));
        let dir = root.join(NEXT.fetch_add(1, Ordering::Relaxed).to_string());
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("a scratch folder");
        Case(dir)
    }

    /// Writes `bytes` to `name` in the folder; returns its path.
    pub fn file(&self, name: &str, bytes: &[u8]) -> PathBuf {
        let path = self.0.join(name);
        std::fs::write(&path, bytes).expect("writing a scratch file");
        path
    }

    /// The folder.
    pub fn path(&self) -> &Path {
        &self.0
    }
}

impl Default for Case {
    fn default() -> Self {
        Case::new()
    }
}

impl Drop for Case {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// The separator between the files packed into one input (a line of its own).
pub const SEP: &[u8] = b"\n%%\n";

/// Splits `data` at every [`SEP`].
pub fn split(data: &[u8]) -> Vec<&[u8]> {
    let mut parts = Vec::new();
    let mut rest = data;
    while let Some(i) = rest.windows(SEP.len()).position(|w| w == SEP) {
        parts.push(&rest[..i]);
        rest = &rest[i + SEP.len()..];
    }
    parts.push(rest);
    parts
}

/// Joins files into one input, the inverse of [`split`].
pub fn join(parts: &[&[u8]]) -> Vec<u8> {
    parts.join(SEP)
}

/// The NPY recording reader.
pub fn npy(data: &[u8]) -> bool {
    let case = Case::new();
    let path = case.file("r.npy", data);
    read_recording(&path, &LayoutFile::default()).is_ok()
}

/// The layouts the CSV reader is run with, chosen by the input's first byte.
fn csv_layout(selector: u8) -> LayoutFile {
    let mut layout = LayoutFile::default();
    match selector % 5 {
        0 => {}
        1 => {
            layout.time_column = Some("t".into());
            layout.time_unit = Some(TimeUnit::Seconds);
        }
        2 => {
            layout.channels = Some(vec!["a".into(), "b".into()]);
            (layout.rows, layout.cols) = (Some(1), Some(2));
            layout.fs = Some(500.0);
        }
        3 => {
            (layout.rows, layout.cols) = (Some(2), Some(2));
            layout.channel_map = Some(vec![[1, 1], [0, 0], [0, 1]]);
            layout.mask = Some(vec!["11".into(), "01".into()]);
        }
        _ => {
            layout.time_column = Some("t_ms".into());
            layout.baseline = Some(Baseline::Mean {
                start_s: 0.0,
                end_s: 0.5,
            });
        }
    }
    layout
}

/// The CSV recording reader, with a layout variant chosen by the first byte.
pub fn csv(data: &[u8]) -> bool {
    let Some((&selector, rest)) = data.split_first() else {
        return false;
    };
    let case = Case::new();
    let path = case.file("r.csv", rest);
    read_recording(&path, &csv_layout(selector)).is_ok()
}

/// The manifest reader.
pub fn manifest(data: &[u8]) -> bool {
    let case = Case::new();
    read_manifest(&case.file("manifest.csv", data)).is_ok()
}

/// `layout.toml`, and when it is read, a small CSV recording through it.
pub fn layout(data: &[u8]) -> bool {
    let case = Case::new();
    let Ok(layout) = LayoutFile::read(&case.file("layout.toml", data)) else {
        return false;
    };
    let csv = case.file("r.csv", b"t_ms,a,b,c,d\n0,1,2,3,4\n1,2,3,4,5\n2,3,4,5,6\n");
    read_recording(&csv, &layout).is_ok()
}

/// The names the files of a packed dataset get, after `manifest.csv` and `layout.toml`.
const DATASET_FILES: [&str; 4] = ["a.csv", "b.npy", "c.csv", "d.npy"];

/// `Dataset::open` and `load` of every recording, on a folder whose `manifest.csv`,
/// `layout.toml` (when not empty) and recordings `a.csv`, `b.npy`, ... come from the input.
pub fn dataset(data: &[u8]) -> bool {
    let case = Case::new();
    let parts = split(data);
    case.file("manifest.csv", parts[0]);
    if let Some(layout) = parts.get(1).filter(|l| !l.is_empty()) {
        case.file("layout.toml", layout);
    }
    for (bytes, name) in parts.iter().skip(2).zip(DATASET_FILES) {
        case.file(name, bytes);
    }
    let Ok(ds) = Dataset::open(case.path()) else {
        return false;
    };
    let _ = (ds.labels(), ds.speeds(), ds.fs());
    let loaded = (0..ds.entries.len())
        .filter(|&i| ds.load(i).is_ok())
        .count();
    ds.fingerprint().is_ok() && loaded == ds.entries.len()
}

/// A file name taken from the input: no folder separators, not too long, ending `.csv`.
fn file_name(line: &str, fallback: &str) -> String {
    let name: String = line
        .chars()
        .filter(|c| !matches!(c, '/' | '\\' | '\0'))
        .take(100)
        .collect();
    match name.as_str() {
        "" | "." | ".." => fallback.to_string(),
        n if n.ends_with(".csv") => name,
        _ => format!("{name}.csv"),
    }
}

/// The options of a fuzzed CSV import, chosen by the bits of `flags`.
fn csv_params(flags: u8, pattern: Option<NamePattern>) -> CsvImportParams {
    let format = CsvFormat {
        time_column: (flags & 1 != 0).then(|| Column::Name("t_ms".to_string())),
        time_unit: if flags & 2 != 0 {
            TimeUnit::Seconds
        } else {
            TimeUnit::Milliseconds
        },
        channels: match (flags >> 2) & 3 {
            0 => ChannelSelect::All,
            1 => ChannelSelect::parse("a,b").expect("a list"),
            _ => ChannelSelect::parse("^[a-z]$").expect("a regex"),
        },
        duplicate_stamps: if flags & 128 != 0 {
            DuplicateStamps::Error
        } else {
            DuplicateStamps::Average
        },
        ..CsvFormat::default()
    };
    CsvImportParams {
        pattern,
        format,
        grid: (flags & 16 != 0).then(|| "1x2".parse().expect("a grid")),
        channel_map: None,
        fs: (flags & 32 != 0).then_some(100.0),
        baseline: None,
        skip_bad: flags & 64 != 0,
    }
}

/// `import csv` on one or two files. The first part of the input is a header: a flags
/// byte, then lines giving the name pattern and the files' names; the next parts are the
/// files. Patterns of any length: the matcher runs in linear time.
pub fn import_csv_files(data: &[u8]) -> bool {
    let parts = split(data);
    let Some((&flags, header)) = parts[0].split_first() else {
        return false;
    };
    let header = String::from_utf8_lossy(header);
    let mut lines = header.lines();
    let pattern = lines
        .next()
        .filter(|p| !p.is_empty())
        .and_then(|p| NamePattern::parse(p).ok());
    let case = Case::new();
    let mut files = Vec::new();
    for (i, bytes) in parts.iter().skip(1).take(2).enumerate() {
        let name = file_name(lines.next().unwrap_or(""), &format!("f{i}.csv"));
        files.push(case.file(&name, bytes));
    }
    files.dedup();
    let out = case.path().join("out");
    let params = csv_params(flags, pattern);
    import_csv(&files, &params, &out, &|| {}).is_ok() && read_back(&out)
}

/// Opens an imported dataset and loads its recordings.
fn read_back(dir: &Path) -> bool {
    let Ok(ds) = Dataset::open(dir) else {
        return false;
    };
    (0..ds.entries.len()).all(|i| ds.load(i).is_ok())
}

/// The axes a stacked import is tried with.
const AXES: [&str; 4] = ["n,t,row,col", "n,row,col,t", "n,t,channel", "n,channel,t"];

/// `import stacked`: a flags byte (axes, grid, speeds given or not), then the data, labels
/// and speeds arrays as `.npy` bytes.
pub fn import_stacked_arrays(data: &[u8]) -> bool {
    let parts = split(data);
    let Some((&flags, _)) = parts[0].split_first() else {
        return false;
    };
    let case = Case::new();
    let data_path = case.file("data.npy", parts.get(1).copied().unwrap_or_default());
    let labels = case.file("labels.npy", parts.get(2).copied().unwrap_or_default());
    let speeds = parts.get(3).map(|s| case.file("speeds.npy", s));
    let axes = AXES[usize::from(flags % 4)];
    let params = StackedParams {
        axes: axes.parse().expect("valid axes"),
        fs: if flags & 4 != 0 { 1000.0 } else { 50.0 },
        grid: (flags & 8 != 0 && axes.contains("channel")).then(|| "2x2".parse().expect("grid")),
    };
    let out = case.path().join("out");
    import_stacked(&data_path, &labels, speeds.as_deref(), &params, &out).is_ok() && read_back(&out)
}

/// An `.npy` file of `shape` holding `0, 1, 2, ...` as f32.
fn npy_bytes(shape: &[usize]) -> Vec<u8> {
    let n: usize = shape.iter().product();
    npy_values(shape, (0..n).map(|v| v as f32).collect())
}

/// An `.npy` file of `shape` holding `values` as f32.
fn npy_values(shape: &[usize], values: Vec<f32>) -> Vec<u8> {
    let array = ndarray::ArrayD::from_shape_vec(shape, values).expect("shape fits");
    let mut out = Vec::new();
    ndarray_npy::WriteNpyExt::write_npy(&array, &mut out).expect("writing to memory");
    out
}

/// An `.npy` file of strings (`<U3`), one label per sample.
fn label_bytes(labels: &[&str]) -> Vec<u8> {
    let header = format!(
        "{{'descr': '<U3', 'fortran_order': False, 'shape': ({},), }}",
        labels.len()
    );
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    let padded = format!("{header:<117}\n");
    out.extend_from_slice(&(padded.len() as u16).to_le_bytes());
    out.extend_from_slice(padded.as_bytes());
    for label in labels {
        let mut chars: Vec<char> = label.chars().collect();
        chars.resize(3, '\0');
        for c in chars {
            out.extend_from_slice(&(c as u32).to_le_bytes());
        }
    }
    out
}

/// Valid inputs for every target (tiny files of each kind): the seed corpus, written to
/// `fuzz/corpus/TARGET/` by `cargo run --bin seeds` and used by the stable test.
pub fn seeds() -> Vec<(&'static str, Vec<u8>)> {
    let grid = npy_bytes(&[6, 2, 2]);
    let flat = npy_bytes(&[6, 3]);
    let timed = b"t_ms,a,b\n0,1,2\n1,2,3\n2,3,5\n3,1,1\n".to_vec();
    let seconds = b"t,a\n0,1\n0.001,2\n0.002,3\n".to_vec();
    let untimed = b"a,b,c\n1,2,3\n2,3,4\n3,4,5\n".to_vec();
    let manifest = b"file,label,speed_mm_s,force_n,trial,slide_start_s,slide_end_s,extra\n\
a.csv,FT1,5,1,0,0.001,0.002,x\nb.npy,SB,10,1.5,1,,,y\n"
        .to_vec();
    let layout = b"fs = 1000.0\nrows = 2\ncols = 2\nchannel_map = [[0, 0], [0, 1], [1, 1], [1, 0]]\n\
mask = [\"11\", \"11\"]\nbaseline = { kind = \"min\" }\ntime_column = \"t_ms\"\ntime_unit = \"ms\"\n"
        .to_vec();
    let grid_layout = b"fs = 1000.0\nrows = 2\ncols = 2\n".to_vec();
    let timed_4 = b"t_ms,a,b,c,d\n0,1,2,3,4\n1,2,3,4,5\n2,3,4,5,6\n".to_vec();
    let mut out = vec![
        ("npy", grid.clone()),
        ("npy", flat.clone()),
        ("npy", npy_bytes(&[4, 1])),
        ("manifest", manifest.clone()),
        ("layout", layout.clone()),
        ("layout", grid_layout.clone()),
        ("layout", b"fs = 250\n".to_vec()),
        ("dataset", join(&[&manifest, b"", &timed, &grid])),
        ("dataset", join(&[&manifest, &grid_layout, &timed_4, &grid])),
    ];
    for selector in 0..5u8 {
        let body = match selector {
            1 => &seconds,
            3 => &untimed,
            _ => &timed,
        };
        out.push(("csv", [&[selector][..], body].concat()));
    }
    let sample_3 = b"t_ms,a,b,c\n0,1,2,3\n1,2,3,4\n2,3,4,5\n3,4,5,6\n".to_vec();
    let header = b"\x01{label}_{speed}_{trial}.csv\nFT1_5_0\nSB_10_1".to_vec();
    out.push(("import_csv", join(&[&header, &timed, &timed])));
    out.push(("import_csv", join(&[b"\x34\n", &untimed])));
    out.push(("import_csv", join(&[b"\x01", &sample_3])));
    let labels = label_bytes(&["FT1", "SB", "CP"]);
    out.push((
        "import_stacked",
        join(&[b"\x04", &npy_bytes(&[3, 5, 2, 2]), &labels]),
    ));
    let speeds = npy_values(&[3], vec![5.0, 10.0, 15.0]);
    let ints = npy_bytes(&[3]);
    out.push((
        "import_stacked",
        join(&[b"\x0a", &npy_bytes(&[3, 4, 4]), &ints, &speeds]),
    ));
    out
}
