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
use std::sync::OnceLock;

use neurotex::csvlog::{Column, CsvFormat, DuplicateStamps};
use neurotex::events::Origin;
use neurotex::events::{read_events, write_events, Event, EventFile, EventGrid, EventsFormat};
use neurotex::import::{import_csv, import_stacked, ChannelSelect, CsvImportParams};
use neurotex::import::{NamePattern, StackedParams};
use neurotex::model::Provenance;
use neurotex::nir::Convention;
use neurotex::pipeline::{Encoding, PipelineParams};
use neurotex::recording::{read_manifest, read_recording, Dataset, LayoutFile};
use neurotex::recording::{Baseline, TimeUnit};
use neurotex::saved::SavedModel;
use neurotex::snn::{Network, Readout, Reset, SnnParams, SpikeInput};
use neurotex::spiking_model::{decide, SpikingModel, SpikingTraining};
use neurotex::stream::events::{EventEncoding, EventReader, EventSource, Item};
use neurotex::stream::{StreamClassifier, StreamParams};
use neurotex::Grid;

/// The targets, by name: the names of the fuzz targets and of the corpus folders.
pub const TARGETS: [&str; 12] = [
    "npy",
    "csv",
    "manifest",
    "layout",
    "dataset",
    "import_csv",
    "import_stacked",
    "events_csv",
    "events_npy",
    "stream_events",
    "snn_model",
    "nir",
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
        "events_csv" => events_file(data, "e.csv"),
        "events_npy" => events_file(data, "e.npy"),
        "stream_events" => stream_events(data),
        "snn_model" => snn_model(data),
        "nir" => nir_graph(data),
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
            2 => ChannelSelect::parse("^[a-z]$").expect("a regex"),
            _ => ChannelSelect::All,
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
        // Every channel read, then `b` left out with its cell masked.
        drop_channels: ((flags >> 2) & 3 == 3).then(|| ChannelSelect::parse("b").expect("a name")),
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

/// The longest event recording the readers are run with, ms (an hour).
const MAX_EVENT_STEPS: u64 = 3_600_000;

/// The format, grid and duration an event file is read with, chosen by the bits of
/// `flags`: the unit (2 bits), a taxel column instead of `x` and `y`, OFF written as -1,
/// the first event as time 0, a masked cell, a duration of 50 ms.
fn event_setup(flags: u8) -> (EventsFormat, EventGrid, Option<u64>) {
    let units = [
        TimeUnit::Microseconds,
        TimeUnit::Milliseconds,
        TimeUnit::Seconds,
    ];
    let mut format = EventsFormat::new(units[usize::from(flags % 4).min(2)]);
    if flags & 4 != 0 {
        format.taxel = Some("taxel".into());
    }
    if flags & 8 != 0 {
        format.values = [1, -1];
    }
    if flags & 16 != 0 {
        format.origin = Origin::First;
    }
    let present = match flags & 32 {
        0 => vec![true; 4],
        _ => vec![true, false, true, true],
    };
    let taxels = (0..4).filter(|&c| present[c]).collect();
    let grid = EventGrid {
        rows: 2,
        cols: 2,
        present,
        taxels,
    };
    (format, grid, (flags & 64 != 0).then_some(50))
}

/// An event file (CSV or `.npy` by `name`'s extension) read on a 2x2 grid, the first byte
/// choosing the format ([`event_setup`]), the rest the file.
pub fn events_file(data: &[u8], name: &str) -> bool {
    let Some((&flags, rest)) = data.split_first() else {
        return false;
    };
    let (format, grid, duration) = event_setup(flags);
    let case = Case::new();
    let path = case.file(name, rest);
    read_events(&path, &format, &grid, duration, MAX_EVENT_STEPS).is_ok()
}

/// The model file (as JSON) of a small spiking network on a 2x2 grid's SA and FA inputs,
/// trained on events; `recurrent` adds the hidden layer's loop.
fn spiking_file(recurrent: bool) -> serde_json::Value {
    let (inputs, hidden, classes) = (8, 3, 2);
    let weights = |n: usize, k: f64| -> Vec<f64> {
        (0..n)
            .map(|i| f64::from(((i as f64 * 0.37 + k).sin() * 0.8) as f32))
            .collect()
    };
    let classifier = SnnParams {
        hidden,
        dt_ms: 5,
        epochs: 3,
        recurrent,
        ..SnnParams::default()
    };
    let network = Network {
        inputs,
        hidden,
        classes,
        dt_ms: 5,
        tau_syn_ms: classifier.tau_syn_ms,
        tau_mem_ms: classifier.tau_mem_ms,
        tau_out_ms: classifier.tau_out_ms,
        readout: Readout::Mean,
        reset: Reset::Zero,
        w_in: weights(inputs * hidden, 0.1),
        b_in: weights(hidden, 0.2),
        w_out: weights(hidden * classes, 0.3),
        b_out: weights(classes, 0.4),
        w_rec: if recurrent {
            weights(hidden * hidden, 0.5)
        } else {
            Vec::new()
        },
        target: Default::default(),
        alpha: Vec::new(),
        beta: Vec::new(),
        travel_mm_s: None,
        adaptation: None,
        delays: Vec::new(),
    };
    let layout = LayoutFile {
        rows: Some(2),
        cols: Some(2),
        events: Some(EventsFormat::new(TimeUnit::Microseconds)),
        ..LayoutFile::default()
    };
    let training = SpikingTraining {
        dataset: Provenance {
            fingerprint: "fuzz".into(),
            baseline: Baseline::default(),
            speeds: None,
            gain_calibration: None,
            median_duration_ms: Some(600),
            layout: Some(layout),
        },
        recordings: 4,
        epochs: 2,
        best_epoch: 1,
        validation_loss: 0.5,
    };
    let pipeline = PipelineParams {
        encoding: Encoding::SaFa,
        ..PipelineParams::default()
    };
    serde_json::json!({
        "format": neurotex::spiking_model::FORMAT,
        "version": neurotex::spiking_model::VERSION,
        "neurotex_version": "0.0.0",
        "pipeline": pipeline,
        "grid": Grid::masked(2, 2, vec![true; 4]).expect("a grid"),
        "classifier": classifier,
        "labels": ["a", "b"],
        "training": training,
        "network": network,
    })
}

/// The model of [`spiking_file`] (feed-forward), read once.
fn spiking_model() -> &'static SpikingModel {
    static MODEL: OnceLock<SpikingModel> = OnceLock::new();
    MODEL.get_or_init(|| {
        let case = Case::new();
        let text = spiking_file(false).to_string();
        SpikingModel::load(&case.file("m.json", text.as_bytes())).expect("the fuzz model reads")
    })
}

/// What every model that reads must give: finite shares summing to 1 on a window of
/// spikes, and a NIR graph.
///
/// # Panics
/// When it does not (the model file's checks let damage through).
fn runs_as_trained(model: &SpikingModel) {
    let net = model.network();
    let events: Vec<(u32, u32)> = (0..40u32)
        .map(|k| (k / 2, (k * 7) % net.inputs as u32))
        .collect();
    let scores = net.scores(&SpikeInput::from_events(net.inputs, 20, &events));
    let (_, shares) = decide(&scores);
    let sum: f64 = shares.iter().sum();
    assert!(
        shares.iter().all(|s| s.is_finite()) && (sum - 1.0).abs() < 1e-9,
        "a model that reads gives shares {shares:?}"
    );
    model
        .to_nir(Convention::Physical)
        .expect("a model that reads exports its graph");
}

/// A spiking model file (JSON), and when it reads, its network run and exported.
pub fn snn_model(data: &[u8]) -> bool {
    let case = Case::new();
    let Ok(model) = SpikingModel::load(&case.file("m.json", data)) else {
        return false;
    };
    runs_as_trained(&model);
    true
}

/// A NIR graph (HDF5), and when it reads, its network run and exported.
pub fn nir_graph(data: &[u8]) -> bool {
    let case = Case::new();
    let Ok(model) = SpikingModel::load(&case.file("g.nir", data)) else {
        return false;
    };
    runs_as_trained(&model);
    true
}

/// Items a stream input is read for at most: enough for every path, few enough that
/// inputs stay fast.
const MAX_STREAM_ITEMS: usize = 4096;

/// A live stream's events through [`EventReader`] and into a stream classifier of a small
/// spiking network trained on events. The first byte: binary records (bit 0) or text
/// lines; text events naming a taxel (bit 1); the text's unit (bits 2-3: the model's
/// microseconds, ms, s); the first event as time 0 (bit 4). The rest is the stream.
pub fn stream_events(data: &[u8]) -> bool {
    let Some((&flags, rest)) = data.split_first() else {
        return false;
    };
    let model = SavedModel::from(spiking_model().clone());
    let encoding = match flags & 1 {
        0 => EventEncoding::Text,
        _ => EventEncoding::Binary,
    };
    let unit = [
        None,
        Some(TimeUnit::Milliseconds),
        Some(TimeUnit::Seconds),
        None,
    ];
    let origin = (flags & 16 != 0).then_some(Origin::First);
    let unit = unit[usize::from((flags >> 2) & 3)];
    let source = EventSource::for_model(&model, unit, origin, flags & 2 != 0)
        .expect("the model was trained on events");
    let mut reader = EventReader::new(rest, "fuzz", encoding, &source.format);
    let params = StreamParams::for_model(&model);
    let mut stream = StreamClassifier::for_events(model, params, source).expect("a stream");
    let mut clean = true;
    for _ in 0..MAX_STREAM_ITEMS {
        let taken = match reader.next(&|| false) {
            Ok(Some(Item::Event { stamp, address })) => stream.push_event(stamp, address).is_ok(),
            Ok(Some(Item::Reset)) => stream.reset().is_ok(),
            Ok(Some(Item::Bad { .. })) => {
                stream.skip_bad_frame();
                false
            }
            Ok(None) => break,
            Err(_) => return false,
        };
        clean &= taken;
    }
    stream.finish().is_ok() && clean
}

/// Event files of `kind` holding a short recording's events on a 2x2 grid.
fn event_file_bytes(kind: EventFile) -> Vec<u8> {
    let events: Vec<Event> = (0..12u32)
        .map(|k| Event {
            t_ms: k * 3,
            y: k % 2,
            x: (k / 2) % 2,
            p: (k % 3 == 0) as u8,
        })
        .collect();
    let mut out = Vec::new();
    write_events(&mut out, &events, kind).expect("writing to memory");
    out
}

/// Seeds of the event, stream, spiking model and NIR targets.
fn newer_seeds() -> Vec<(&'static str, Vec<u8>)> {
    let mut out = Vec::new();
    let csv = event_file_bytes(EventFile::Csv);
    let npy = event_file_bytes(EventFile::Npy);
    // CSV in ms (unit 1), in ms from the first event, masked with a duration; a taxel
    // column with OFF as -1; tonic's .npy in us
    out.push(("events_csv", [&[1u8][..], &csv].concat()));
    out.push(("events_csv", [&[1u8 | 16][..], &csv].concat()));
    out.push((
        "events_csv",
        [&[4u8 | 8 | 1][..], b"t,taxel,p\n0,0,1\n2,3,-1\n2,1,1\n"].concat(),
    ));
    out.push((
        "events_csv",
        [&[1u8 | 64][..], b"t,x,y\n0,0,0\n7,1,1\n"].concat(),
    ));
    out.push(("events_npy", [&[0u8][..], &npy].concat()));
    out.push(("events_npy", [&[32u8 | 64][..], &event_npy_u16()].concat()));
    let text = b"t,x,y,p\n0,0,0,1\n150000,1,1,0\n400000\nreset\n1000000,1,0,1\n1900000\n".to_vec();
    out.push(("stream_events", [&[0u8][..], &text].concat()));
    out.push((
        "stream_events",
        [&[2u8 | 4][..], b"t,taxel,p\n0,0,1\n300,2,0\n700\n"].concat(),
    ));
    let mut records = Vec::new();
    for (t, x, y, p, kind) in [
        (0i64, 0u16, 0u16, 1i8, 0u8),
        (90_000, 1, 1, 0, 0),
        (500_000, 0, 0, 0, 1),
        (0, 0, 0, 0, 2),
        (700_000, 1, 0, 1, 0),
        (1_500_000, 0, 0, 0, 1),
    ] {
        records.extend_from_slice(&t.to_le_bytes());
        records.extend_from_slice(&x.to_le_bytes());
        records.extend_from_slice(&y.to_le_bytes());
        records.push(p as u8);
        records.push(kind);
        records.extend_from_slice(&[0, 0]);
    }
    out.push(("stream_events", [&[1u8][..], &records].concat()));
    for recurrent in [false, true] {
        let file = spiking_file(recurrent);
        out.push(("snn_model", serde_json::to_vec_pretty(&file).expect("JSON")));
        let case = Case::new();
        let model = SpikingModel::load(&case.file("m.json", file.to_string().as_bytes()))
            .expect("the seed model reads");
        for convention in [Convention::Physical, Convention::Snntorch] {
            out.push(("nir", model.to_nir(convention).expect("a graph")));
        }
    }
    out
}

/// A tonic-like `.npy` of events whose `x` and `y` are `<u2`, `t` `<u4` and `p` a boolean.
fn event_npy_u16() -> Vec<u8> {
    let descr = "[('t', '<u4'), ('x', '<u2'), ('y', '<u2'), ('p', '|b1')]";
    let records: [(u32, u16, u16, u8); 3] = [(0, 0, 0, 1), (1500, 1, 1, 0), (2500, 0, 1, 1)];
    let mut header = format!(
        "{{'descr': {descr}, 'fortran_order': False, 'shape': ({},), }}",
        records.len()
    );
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    for (t, x, y, p) in records {
        out.extend_from_slice(&t.to_le_bytes());
        out.extend_from_slice(&x.to_le_bytes());
        out.extend_from_slice(&y.to_le_bytes());
        out.push(p);
    }
    out
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
    out.extend(newer_seeds());
    out
}
