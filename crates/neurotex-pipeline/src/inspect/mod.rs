//! A quick, read-only check of a dataset or of raw logs before any analysis: the design
//! (recordings per class and condition, what the folds and neighbours need), the signals
//! (rate, jitter, gaps, offsets, dead, clipped, rising and copied channels), the layout
//! (grid, map, neighbours) and the encoder at the chosen gain (silent and saturated taxels,
//! the gain `--gain auto` would choose). Every finding has a severity and the option that
//! addresses it.
//!
//! Recordings are read one at a time in parallel and reduced to their statistics, so a
//! dataset's raw samples are never all in memory; a few are read again for the traces a
//! person looks at.

pub mod design;
pub mod events;
mod findings;
pub mod signals;

use rayon::prelude::*;
use serde::Serialize;

use crate::calibrate::{calibrate_gain, DEFAULT_TARGET_HZ};
use crate::classify::{CvParams, KnnParams};
use crate::diagnostics::ceiling_rate;
use crate::error::Result;
use std::path::{Path, PathBuf};

use crate::error::{DataError, ParamError};
use crate::import::{csv_files, CsvImportParams, Logs, MergedRows};
use crate::model::GainCalibration;
use crate::pipeline::{Pipeline, PipelineParams};
use crate::recording::{Baseline, Dataset, Layout, LayoutFile, Meta, Recording};
pub use design::{Condition, Design, GroupColumn, Support};
pub use findings::{Finding, Severity};
pub use signals::{Channel, SignalStats, Stamps};

/// Classes whose first recording is drawn as a trace.
pub const TRACE_CLASSES: usize = 6;
/// Points a trace keeps per channel.
const TRACE_POINTS: usize = 600;

/// What to check, and with which analysis settings.
#[derive(Debug, Clone)]
pub struct InspectParams {
    /// The pipeline whose conditioning and encoder are checked (its gain the one judged).
    pub pipeline: PipelineParams,
    /// Whether to encode every recording (the encoder at the gain, `--gain auto`'s
    /// choice); without it only the design, layout and signals are checked.
    pub encoder: bool,
    /// Cross-validation folds the design is judged for.
    pub folds: usize,
    /// KNN's neighbours the design is judged for.
    pub k: usize,
    /// `--gain auto`'s target rate, Hz: the encoder is then checked at the gain it
    /// chooses on these recordings rather than at the pipeline's.
    pub gain_target: Option<f64>,
    /// Whether to read again the recordings drawn as traces (for the figures).
    pub traces: bool,
}

impl Default for InspectParams {
    fn default() -> Self {
        InspectParams {
            pipeline: PipelineParams::default(),
            encoder: true,
            folds: CvParams::default().folds,
            k: KnnParams::default().k,
            gain_target: None,
            traces: true,
        }
    }
}

/// What is inspected: a dataset folder, or raw logs read as `import csv` would read them.
#[derive(Debug, Clone, Copy)]
pub enum Source<'a> {
    /// A dataset folder.
    Dataset(&'a Dataset),
    /// Raw CSV logs.
    Logs(&'a Logs),
}

impl Source<'_> {
    fn len(&self) -> usize {
        match self {
            Source::Dataset(d) => d.entries.len(),
            Source::Logs(l) => l.files.len(),
        }
    }

    fn layout(&self) -> &LayoutFile {
        match self {
            Source::Dataset(d) => &d.layout,
            Source::Logs(l) => &l.layout,
        }
    }

    fn file(&self, i: usize) -> String {
        match self {
            Source::Dataset(d) => d.entries[i].file.clone(),
            Source::Logs(l) => l.files[i].file_name().map_or_else(
                || l.files[i].display().to_string(),
                |n| n.to_string_lossy().into_owned(),
            ),
        }
    }

    fn load(&self, i: usize) -> Result<(Recording, Option<MergedRows>)> {
        match self {
            Source::Dataset(d) => Ok((d.load(i)?, None)),
            Source::Logs(l) => l.read(i).map(|(r, m)| (r, Some(m))),
        }
    }
}

/// What `inspect` reads, opened: a dataset folder, or raw logs.
#[derive(Debug)]
pub enum Opened {
    /// A dataset folder.
    Dataset(Box<Dataset>),
    /// Raw CSV logs.
    Logs(Box<Logs>),
}

impl Opened {
    /// `paths` opened: one folder holding `manifest.csv` is a dataset (refused when
    /// `reading_given`: the reading options are for raw logs); anything else is raw logs,
    /// files or folders whose `.csv` files are all read, under `reading`.
    ///
    /// # Errors
    /// A dataset given reading options, a dataset that does not open, no logs, or logs
    /// that cannot be read under `reading`.
    pub fn open(
        paths: &[PathBuf],
        reading: CsvImportParams,
        reading_given: bool,
        allow_outside_paths: bool,
    ) -> Result<Self> {
        let first = paths
            .first()
            .map_or_else(|| Path::new("."), |p| p.as_path());
        if paths.len() == 1 && first.join("manifest.csv").is_file() {
            if reading_given {
                let rule = "the reading options (time column, grid, channels, ...) are for raw logs; a dataset folder is read with its layout.toml";
                let got = format!("a dataset folder, {}", first.display());
                return Err(ParamError::new("reading options", rule, got).into());
            }
            let dataset = Dataset::open_with(first, allow_outside_paths)?;
            return Ok(Opened::Dataset(Box::new(dataset)));
        }
        let files = csv_files(paths)?;
        if files.is_empty() {
            let message = "holds no manifest.csv and no .csv logs: give a dataset folder, or raw CSV logs (files or folders)";
            return Err(DataError::invalid(first, message).into());
        }
        Ok(Opened::Logs(Box::new(Logs::open(files, reading)?)))
    }

    /// The source to inspect.
    pub fn source(&self) -> Source<'_> {
        match self {
            Opened::Dataset(d) => Source::Dataset(d),
            Opened::Logs(l) => Source::Logs(l),
        }
    }

    /// Recordings (files) to read.
    pub fn len(&self) -> usize {
        self.source().len()
    }

    /// Whether there is nothing to read.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The grid, the channels on it and the neighbours the GLCM compares.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LayoutSummary {
    /// Grid rows.
    pub rows: usize,
    /// Grid columns.
    pub cols: usize,
    /// The channels' names, in file order.
    pub channels: Vec<String>,
    /// Each channel's cell, `[row, col]`.
    pub cells: Vec<[usize; 2]>,
    /// Whether a channel map placed the channels (rather than row-major order).
    pub mapped: bool,
    /// Cells without a channel.
    pub empty_cells: usize,
    /// Pairs of channels side by side or one above the other on the grid.
    pub neighbour_pairs: usize,
    /// The baseline removed before encoding.
    pub baseline: String,
    /// The nominal rate, Hz.
    pub fs_hz: f64,
}

/// One channel over every recording.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChannelSummary {
    /// Its name.
    pub name: String,
    /// The median over recordings of its range (max - min).
    pub range: f64,
    /// The median over recordings of how far above zero it rests, in ranges.
    pub resting_ratio: Option<f64>,
    /// How far its resting level (its least sample) moves between recordings, in ranges:
    /// the 10th to 90th percentile of its minima over the median range. `None` when it
    /// does not move or fewer than two recordings read.
    pub resting_spread: Option<f64>,
    /// Share of recordings in which it is dead (one value throughout).
    pub dead_share: f64,
    /// Share of recordings in which it rises at every frame, as a clock.
    pub rising_share: f64,
    /// Share of recordings with at least 1 % of its samples at a converter's full scale.
    pub clipped_share: f64,
    /// The channel it copies, in most of the recordings where it copies one.
    pub copy_of: Option<String>,
    /// Share of recordings in which it is a copy of another channel.
    pub copy_share: f64,
}

/// A file that could not be read, and why.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Unreadable {
    /// The file.
    pub file: String,
    /// The reader's error.
    pub reason: String,
}

/// A recording with gaps in its stamps.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Gappy {
    /// The file.
    pub file: String,
    /// Intervals of at least [`signals::GAP_FACTOR`] median intervals.
    pub gaps: usize,
    /// The longest interval, s.
    pub longest_s: f64,
}

/// The signals over every recording.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SignalSummary {
    /// Recordings read.
    pub recordings: usize,
    /// Files that could not be read.
    pub unreadable: Vec<Unreadable>,
    /// The stamps' rate per recording, `[min, median, max]`, Hz; `None` without stamps.
    pub fs_hz: Option<[f64; 3]>,
    /// Recordings whose stamps' rate is more than 5 % off the median recording's.
    pub off_rate: Vec<String>,
    /// The stamps' jitter (5-95 % spread of the intervals over the median), median and
    /// largest over recordings.
    pub jitter: Option<[f64; 2]>,
    /// Recordings with gaps in their stamps.
    pub gappy: Vec<Gappy>,
    /// Rows merged or dropped as repeated stamps, and the files they were in.
    pub merged_rows: [usize; 2],
    /// Duration `[min, median, max]`, s.
    pub duration_s: [f64; 3],
    /// Recordings shorter than one bin of the rate volume.
    pub too_short: Vec<String>,
    /// Recordings shorter than a quarter of the median recording.
    pub short: Vec<String>,
    /// Per channel.
    pub channels: Vec<ChannelSummary>,
}

/// One taxel at the encoder's gain.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TaxelRate {
    /// The channel's name.
    pub name: String,
    /// Its cell, `[row, col]`.
    pub cell: [usize; 2],
    /// The median over recordings of its firing rate, Hz.
    pub median_hz: f64,
    /// Share of recordings in which it never fires.
    pub silent_share: f64,
    /// Share of recordings in which it fires at the ceiling.
    pub saturated_share: f64,
}

/// The encoder at the chosen gain.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EncoderCheck {
    /// The gain checked.
    pub gain: f64,
    /// The rate of a neuron held at the largest input, Hz.
    pub ceiling_hz: f64,
    /// Per channel, in file order.
    pub taxels: Vec<TaxelRate>,
    /// Recordings with no positive signal in the selected phase (left silent).
    pub flat: usize,
    /// What `--gain auto` would choose on these recordings; `None` when it cannot.
    pub auto: Option<GainCalibration>,
    /// Why `--gain auto` cannot choose, when it cannot.
    pub auto_error: Option<String>,
}

/// Times in s, then one series of values per channel.
pub type Series = (Vec<f64>, Vec<Vec<f64>>);

/// One recording's channels, raw and conditioned, for a figure.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Trace {
    /// The class.
    pub label: String,
    /// The file.
    pub file: String,
    /// Raw samples: times in s, then one series per channel.
    pub raw: Series,
    /// The conditioned input of the encoder (1 kHz, baseline removed, low-passed, over
    /// the recording's maximum): times in s, then one series per channel; `None` when the
    /// recording cannot be conditioned.
    pub conditioned: Option<Series>,
}

/// Everything `inspect` found.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Inspection {
    /// What was inspected: `dataset` or `raw logs`.
    pub kind: String,
    /// Recordings (files) found.
    pub files: usize,
    /// The design of the recordings read.
    pub design: Design,
    /// The layout.
    pub layout: LayoutSummary,
    /// The signals.
    pub signals: SignalSummary,
    /// The encoder at the gain, when checked.
    pub encoder: Option<EncoderCheck>,
    /// An address-event dataset's events (its `signals` hold the recordings' lengths only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub events: Option<crate::events::EventSummary>,
    /// Findings, the most severe first.
    pub findings: Vec<Finding>,
    /// A trace of the first recording of each of the first [`TRACE_CLASSES`] classes.
    #[serde(skip)]
    pub traces: Vec<Trace>,
}

impl Inspection {
    /// The findings of at least `severity`.
    pub fn at_least(&self, severity: Severity) -> impl Iterator<Item = &Finding> {
        self.findings.iter().filter(move |f| f.severity >= severity)
    }
}

/// The most recordings the check at a workflow's start reads ([`severe_findings`]): what
/// it looks for (a clock read as a channel, resting offsets, a layout the channels do not
/// fit, event stamps from a sensor's clock) holds in most recordings when it holds at all,
/// so a sample spread over the manifest finds it at a bounded cost.
pub const CHECK_SAMPLE: usize = 32;

/// What the check at a workflow's start found, and on how many recordings.
#[derive(Debug, Clone, PartialEq)]
pub struct SevereFindings {
    /// The severe findings on the signals and layout (or the events' timing).
    pub findings: Vec<Finding>,
    /// Recordings read.
    pub checked: usize,
    /// Recordings in the dataset.
    pub total: usize,
}

impl SevereFindings {
    /// Each finding as a line of advice, saying what was read when not every recording.
    pub fn lines(&self) -> Vec<String> {
        let read = match self.checked < self.total {
            true => format!(
                "checked on {} of the {} recordings, spread over the manifest; neurotex inspect reads them all",
                self.checked, self.total
            ),
            false => "neurotex inspect says more".to_string(),
        };
        (self.findings.iter())
            .map(|f| format!("{} ({read})", f.line()))
            .collect()
    }
}

/// The severe findings on a dataset's signals and layout, for a workflow to say at its start
/// (its design and its taxels' responses it judges itself): reads at most [`CHECK_SAMPLE`]
/// recordings, evenly spaced in manifest order, without encoding.
///
/// # Errors
/// As [`inspect`].
pub fn severe_findings(dataset: &Dataset, pipeline: &PipelineParams) -> Result<SevereFindings> {
    let total = dataset.entries.len();
    let checked = total.min(CHECK_SAMPLE);
    let mut sample = dataset.clone();
    sample.entries = (0..checked)
        .map(|j| dataset.entries[j * total / checked].clone())
        .collect();
    let params = InspectParams {
        pipeline: pipeline.clone(),
        encoder: false,
        traces: false,
        ..InspectParams::default()
    };
    let findings = if sample.is_events() {
        // Address events carry no signal to check, but their timing can mislead (a
        // sensor's clock read from time 0): the events' own findings.
        let i = events::inspect_events(&sample, &params, &|| {})?;
        let severe = i.at_least(Severity::Severe).filter(|f| f.area == "events");
        severe.cloned().collect()
    } else {
        let i = inspect(Source::Dataset(&sample), &params, &|| {})?;
        let severe = i.at_least(Severity::Severe).filter(|f| f.area != "design");
        severe.cloned().collect()
    };
    Ok(SevereFindings {
        findings,
        checked,
        total,
    })
}

/// One recording, reduced.
struct Checked {
    /// The recording's index in the source.
    index: usize,
    meta: Meta,
    /// The recording's layout and rate (the summary's layout is the first readable one's).
    layout: Layout,
    fs: f64,
    stats: SignalStats,
    merged: usize,
    /// Spikes per second of each channel's taxel; `None` when not encoded.
    rates: Option<Vec<f64>>,
    flat: bool,
}

/// Inspects `source` (see the module's description). `on_done` is called once per
/// recording read.
///
/// # Errors
/// Parameters that break a rule, or a layout that does not fit the channels. A recording
/// that cannot be read is a finding, not an error.
pub fn inspect(
    source: Source<'_>,
    params: &InspectParams,
    on_done: &(dyn Fn() + Sync),
) -> Result<Inspection> {
    params.pipeline.check()?;
    if let Source::Dataset(ds) = source {
        if ds.is_events() {
            return events::inspect_events(ds, params, on_done);
        }
    }
    let mut pipeline = Pipeline::new(params.pipeline.clone())?;
    let baseline = params
        .pipeline
        .preprocess
        .baseline
        .or(source.layout().baseline)
        .unwrap_or_default();
    // Under `--gain auto` the gain is chosen on the recordings that read, then they are
    // encoded at it in a second pass.
    let auto = params.encoder && params.gain_target.is_some();
    let indices: Vec<usize> = (0..source.len()).collect();
    let (mut checked, unreadable) = check_all(
        source,
        &indices,
        &pipeline,
        baseline,
        params.encoder && !auto,
        on_done,
    );
    let mut calibration = None;
    if let (true, Some(target), false) = (auto, params.gain_target, checked.is_empty()) {
        let readable: Vec<usize> = checked.iter().map(|c| c.index).collect();
        let load = |i: usize| source.load(i).map(|(r, _)| r);
        let c = calibrate_gain(&pipeline, &load, &readable, baseline, target)?;
        let mut p = params.pipeline.clone();
        p.encoder.gain = c.gain;
        pipeline = Pipeline::new(p)?;
        let (again, _) = check_all(source, &readable, &pipeline, baseline, true, &|| {});
        checked = again;
        calibration = Some(c);
    }
    let layout = layout_summary(source, &checked, baseline);
    let metas: Vec<Meta> = checked.iter().map(|c| c.meta.clone()).collect();
    let design = design::design(&metas, params.folds, params.k);
    let bin_s = params.pipeline.volume.bin_ms as f64 / 1000.0;
    let signals = signal_summary(&checked, unreadable, &layout.channels, bin_s);
    let encoder = match params.encoder && !checked.is_empty() {
        true => Some(encoder_check(
            source,
            &pipeline,
            &checked,
            &layout,
            baseline,
            calibration,
        )?),
        false => None,
    };
    let traces = match params.traces {
        true => traces(source, &pipeline, &checked, baseline),
        false => Vec::new(),
    };
    let mut inspection = Inspection {
        kind: match source {
            Source::Dataset(_) => "dataset",
            Source::Logs(_) => "raw logs",
        }
        .to_string(),
        files: source.len(),
        design,
        layout,
        signals,
        encoder,
        events: None,
        findings: Vec::new(),
        traces,
    };
    inspection.findings = findings::findings(&inspection, source.layout(), params);
    Ok(inspection)
}

/// Every recording of `indices` checked in parallel: those that read, and those that do not
/// with their reasons.
fn check_all(
    source: Source<'_>,
    indices: &[usize],
    pipeline: &Pipeline,
    baseline: Baseline,
    encode: bool,
    on_done: &(dyn Fn() + Sync),
) -> (Vec<Checked>, Vec<Unreadable>) {
    let results: Vec<Result<Checked>> = indices
        .par_iter()
        .map(|&i| {
            let out = check_one(source, i, pipeline, baseline, encode);
            on_done();
            out
        })
        .collect();
    let mut checked = Vec::new();
    let mut unreadable = Vec::new();
    for (&i, r) in indices.iter().zip(results) {
        match r {
            Ok(c) => checked.push(c),
            Err(e) => unreadable.push(Unreadable {
                file: source.file(i),
                reason: e.to_string(),
            }),
        }
    }
    (checked, unreadable)
}

fn check_one(
    source: Source<'_>,
    i: usize,
    pipeline: &Pipeline,
    baseline: Baseline,
    encode: bool,
) -> Result<Checked> {
    let (rec, merged) = source.load(i)?;
    let stats = signals::signal_stats(&rec);
    let merged = merged.map_or(0, |m| m.merged_rows + m.duplicate_rows);
    let (rates, flat) = match encode {
        false => (None, false),
        true => match pipeline.condition(&rec, baseline) {
            Ok(cond) => {
                let spikes = pipeline.encode_conditioned(&rec, &cond)?;
                let seconds = spikes.n_steps.max(1) as f64 / 1000.0;
                let rates = (rec.layout.channel_map.iter())
                    .map(|&cell| spikes.train(cell).len() as f64 / seconds)
                    .collect();
                (Some(rates), cond.flat)
            }
            // too short for a bin: said by the signals' check
            Err(_) => (None, false),
        },
    };
    Ok(Checked {
        index: i,
        meta: rec.meta,
        layout: rec.layout,
        fs: rec.fs,
        stats,
        merged,
        rates,
        flat,
    })
}

/// The channels' names: the layout's, else each channel's cell as `r{row}c{col}`.
fn channel_names(layout: &LayoutFile, cells: &[[usize; 2]]) -> Vec<String> {
    match &layout.channels {
        Some(names) if names.len() == cells.len() => names.clone(),
        _ => cells.iter().map(|[r, c]| format!("r{r}c{c}")).collect(),
    }
}

fn layout_summary(source: Source<'_>, checked: &[Checked], baseline: Baseline) -> LayoutSummary {
    let file = source.layout();
    // The grid as the first readable recording has it (a dataset of grid-shaped arrays
    // may give no grid in its layout).
    let Some(first) = checked.first() else {
        return LayoutSummary {
            rows: file.rows.unwrap_or(1),
            cols: file.cols.unwrap_or(0),
            channels: Vec::new(),
            cells: Vec::new(),
            mapped: file.channel_map.is_some(),
            empty_cells: 0,
            neighbour_pairs: 0,
            baseline: baseline.to_string(),
            fs_hz: file.fs.unwrap_or(1000.0),
        };
    };
    let l = &first.layout;
    let cells: Vec<[usize; 2]> = (l.channel_map.iter())
        .map(|&c| [c / l.cols, c % l.cols])
        .collect();
    let used = |r: usize, c: usize| cells.contains(&[r, c]);
    let mut pairs = 0;
    for &[r, c] in &cells {
        pairs += usize::from(c + 1 < l.cols && used(r, c + 1));
        pairs += usize::from(r + 1 < l.rows && used(r + 1, c));
    }
    LayoutSummary {
        rows: l.rows,
        cols: l.cols,
        channels: channel_names(file, &cells),
        mapped: match source {
            Source::Logs(logs) => logs.mapped(),
            // A dataset's layout keeps no trace of whether its map was chosen: a map other
            // than row-major order was, and so was a row-major one unless the channels
            // make a square other than the grid (9 channels row by row on 4x4).
            Source::Dataset(_) => {
                let n = l.channel_map.len();
                let side = (n as f64).sqrt().round() as usize;
                let square_elsewhere = side * side == n && (side, side) != (l.rows, l.cols);
                !l.channel_map.iter().copied().eq(0..n) || !square_elsewhere
            }
        },
        empty_cells: l.rows * l.cols - cells.len(),
        cells,
        neighbour_pairs: pairs,
        baseline: baseline.to_string(),
        fs_hz: first.fs,
    }
}

/// The median of `values` (0 when empty).
fn median(mut values: Vec<f64>) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}

/// `[min, median, max]` of `values`.
fn spread(values: Vec<f64>) -> Option<[f64; 3]> {
    let lo = values.iter().copied().reduce(f64::min)?;
    let hi = values.iter().copied().reduce(f64::max)?;
    Some([lo, median(values), hi])
}

fn signal_summary(
    checked: &[Checked],
    unreadable: Vec<Unreadable>,
    names: &[String],
    bin_s: f64,
) -> SignalSummary {
    let stamps: Vec<(&str, &Stamps)> = checked
        .iter()
        .filter_map(|c| Some((c.meta.file.as_str(), c.stats.stamps.as_ref()?)))
        .collect();
    let fs_hz = spread(stamps.iter().map(|s| s.1.fs_hz).collect());
    let off_rate = match fs_hz {
        Some([_, mid, _]) => (stamps.iter())
            .filter(|s| (s.1.fs_hz - mid).abs() > 0.05 * mid)
            .map(|s| s.0.to_string())
            .collect(),
        None => Vec::new(),
    };
    let jitters: Vec<f64> = stamps.iter().map(|s| s.1.jitter).collect();
    let jitter = spread(jitters).map(|[_, mid, hi]| [mid, hi]);
    let gappy = (stamps.iter())
        .filter(|s| s.1.gaps > 0)
        .map(|s| Gappy {
            file: s.0.to_string(),
            gaps: s.1.gaps,
            longest_s: s.1.longest_s,
        })
        .collect();
    let merged = checked.iter().map(|c| c.merged).filter(|&m| m > 0);
    let durations: Vec<f64> = checked.iter().map(|c| c.stats.duration_s).collect();
    let too_short = (checked.iter())
        .filter(|c| c.stats.duration_s < bin_s)
        .map(|c| c.meta.file.clone())
        .collect();
    let quarter = 0.25 * median(durations.clone());
    let short = (checked.iter())
        .filter(|c| c.stats.duration_s < quarter && c.stats.duration_s >= bin_s)
        .map(|c| c.meta.file.clone())
        .collect();
    SignalSummary {
        recordings: checked.len(),
        unreadable,
        fs_hz,
        off_rate,
        jitter,
        gappy,
        merged_rows: [merged.clone().sum(), merged.count()],
        duration_s: spread(durations).unwrap_or_default(),
        too_short,
        short,
        channels: channel_summaries(checked, names),
    }
}

fn channel_summaries(checked: &[Checked], names: &[String]) -> Vec<ChannelSummary> {
    let n = checked.len().max(1) as f64;
    let share = |f: &dyn Fn(&Checked) -> bool| checked.iter().filter(|c| f(c)).count() as f64 / n;
    (0..names.len())
        .map(|k| {
            let of = |c: &Checked| c.stats.channels.get(k).cloned();
            let all: Vec<Channel> = checked.iter().filter_map(of).collect();
            let ratios: Vec<f64> = all.iter().filter_map(|c| c.resting_ratio).collect();
            let originals: Vec<usize> = (checked.iter())
                .filter_map(|c| c.stats.copies.iter().find(|p| p.1 == k).map(|p| p.0))
                .collect();
            let copy_of = mode(&originals).map(|o| names[o].clone());
            ChannelSummary {
                name: names[k].clone(),
                range: median(all.iter().map(|c| c.max - c.min).collect()),
                resting_ratio: (!ratios.is_empty()).then(|| median(ratios)),
                resting_spread: resting_spread(&all),
                dead_share: share(&|c| of(c).is_some_and(|ch| ch.dead)),
                rising_share: share(&|c| of(c).is_some_and(|ch| ch.rising)),
                clipped_share: share(&|c| of(c).is_some_and(|ch| ch.full_scale_share >= 0.01)),
                copy_of,
                copy_share: originals.len() as f64 / n,
            }
        })
        .collect()
}

/// [`ChannelSummary::resting_spread`] of one channel's recordings.
fn resting_spread(all: &[Channel]) -> Option<f64> {
    let range = median(all.iter().map(|c| c.max - c.min).collect());
    if all.len() < 2 || !(range > 0.0 && range.is_finite()) {
        return None;
    }
    let mut minima: Vec<f64> = all.iter().map(|c| c.min).collect();
    minima.sort_by(f64::total_cmp);
    let at = |q: f64| minima[((minima.len() - 1) as f64 * q).round() as usize];
    let spread = (at(0.9) - at(0.1)) / range;
    spread.is_finite().then_some(spread)
}

/// The most frequent value (the smallest of equally frequent ones).
fn mode(values: &[usize]) -> Option<usize> {
    let mut best: Option<(usize, usize)> = None;
    for &v in values {
        let count = values.iter().filter(|&&w| w == v).count();
        if best.is_none_or(|(b, n)| count > n || (count == n && v < b)) {
            best = Some((v, count));
        }
    }
    best.map(|b| b.0)
}

fn encoder_check(
    source: Source<'_>,
    pipeline: &Pipeline,
    checked: &[Checked],
    layout: &LayoutSummary,
    baseline: Baseline,
    calibrated: Option<GainCalibration>,
) -> Result<EncoderCheck> {
    let encoder = pipeline.params().encoder;
    let ceiling_hz = ceiling_rate(encoder)?;
    let encoded: Vec<&Vec<f64>> = checked.iter().filter_map(|c| c.rates.as_ref()).collect();
    let n = encoded.len().max(1) as f64;
    let taxels = (layout.channels.iter().zip(&layout.cells).enumerate())
        .map(|(k, (name, &cell))| {
            let rates: Vec<f64> = encoded.iter().filter_map(|r| r.get(k).copied()).collect();
            let count =
                |f: &dyn Fn(f64) -> bool| rates.iter().filter(|&&r| f(r)).count() as f64 / n;
            TaxelRate {
                name: name.clone(),
                cell,
                silent_share: count(&|r| r == 0.0),
                saturated_share: count(&|r| r >= crate::diagnostics::SATURATION_SHARE * ceiling_hz),
                median_hz: median(rates),
            }
        })
        .collect();
    let auto = match calibrated {
        Some(c) => Ok(c),
        None => {
            let readable: Vec<usize> = checked.iter().map(|c| c.index).collect();
            let load = |i: usize| source.load(i).map(|(r, _)| r);
            calibrate_gain(pipeline, &load, &readable, baseline, DEFAULT_TARGET_HZ)
        }
    };
    Ok(EncoderCheck {
        gain: encoder.gain,
        ceiling_hz,
        taxels,
        flat: checked.iter().filter(|c| c.flat).count(),
        auto_error: auto.as_ref().err().map(ToString::to_string),
        auto: auto.ok(),
    })
}

/// Every `k`-th value of `values`, so that at most [`TRACE_POINTS`] are kept.
fn thin<T: Copy>(values: impl ExactSizeIterator<Item = T>) -> Vec<T> {
    let step = values.len().div_ceil(TRACE_POINTS).max(1);
    values.step_by(step).collect()
}

/// The first recording of each of the first [`TRACE_CLASSES`] classes (in label order),
/// read again; a recording that no longer reads is left out.
fn traces(
    source: Source<'_>,
    pipeline: &Pipeline,
    checked: &[Checked],
    baseline: Baseline,
) -> Vec<Trace> {
    let mut labels: Vec<&str> = checked.iter().map(|c| c.meta.label.as_str()).collect();
    labels.sort();
    labels.dedup();
    labels.truncate(TRACE_CLASSES);
    (labels.iter())
        .filter_map(|l| checked.iter().find(|c| c.meta.label == *l))
        .filter_map(|c| source.load(c.index).ok())
        .map(|(rec, _)| trace(&rec, pipeline, baseline))
        .collect()
}

fn trace(rec: &Recording, pipeline: &Pipeline, baseline: Baseline) -> Trace {
    let n = rec.layout.channel_map.len();
    let frames = rec.len();
    let times: Vec<f64> = match &rec.times_s {
        Some(t) => t.clone(),
        None => (0..frames).map(|k| k as f64 / rec.fs).collect(),
    };
    let raw_series = (0..n)
        .map(|c| {
            thin(
                signals::channel_series(rec, c)
                    .collect::<Vec<_>>()
                    .into_iter(),
            )
        })
        .collect();
    let conditioned = pipeline.condition(rec, baseline).ok().map(|cond| {
        let steps = cond.n_steps();
        let cells = cond.cells.max(1);
        let t = thin((0..steps).map(|k| k as f64 / 1000.0));
        let series = (rec.layout.channel_map.iter())
            .map(|&cell| thin((0..steps).map(|k| cond.samples[k * cells + cell])))
            .collect();
        (t, series)
    });
    Trace {
        label: rec.meta.label.clone(),
        file: rec.meta.file.clone(),
        raw: (thin(times.into_iter()), raw_series),
        conditioned,
    }
}
