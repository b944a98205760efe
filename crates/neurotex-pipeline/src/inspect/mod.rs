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
mod summary;

use rayon::prelude::*;
use serde::Serialize;

use crate::calibrate::calibrate_gain;
use crate::classify::{CvParams, KnnParams};
use crate::error::Result;
use std::path::{Path, PathBuf};

use crate::error::{DataError, ParamError};
use crate::import::{csv_files, CsvImportParams, Logs, MergedRows};
use crate::pipeline::{Pipeline, PipelineParams};
use crate::recording::{Baseline, Dataset, Layout, LayoutFile, Meta, Recording};
pub use design::{Condition, Design, GroupColumn, Support};
pub use findings::{Finding, Severity};
pub use signals::{Channel, SignalStats, Stamps};
use summary::{encoder_check, layout_summary, median, signal_summary, traces};
pub use summary::{
    ChannelSummary, EncoderCheck, Gappy, LayoutSummary, Series, SignalSummary, TaxelRate, Trace,
    Unreadable,
};

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
        // Labels are checked on every recording.
        let every = |f: &Finding| f.area == "labels";
        (self.findings.iter())
            .map(|f| match every(f) {
                true => format!("{} (checked on every recording)", f.line()),
                false => format!("{} ({read})", f.line()),
            })
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
    // Labels are checked on every recording: a label written another way on a few rows
    // may be missing from the sample.
    let labels = dataset.labels();
    let mut findings: Vec<Finding> = findings::labels_differing_in_case(&labels)
        .into_iter()
        .collect();
    findings.extend(if sample.is_events() {
        // Address events carry no signal to check, but their timing can mislead (a
        // sensor's clock read from time 0): the events' own findings.
        let i = events::inspect_events(&sample, &params, &|| {})?;
        let severe = i.at_least(Severity::Severe).filter(|f| f.area == "events");
        severe.cloned().collect()
    } else {
        let i = inspect(Source::Dataset(&sample), &params, &|| {})?;
        // Labels were checked above on every recording, and every encoding names the
        // recordings without signal (`Encoded::constant`).
        let severe = i.at_least(Severity::Severe);
        let said = |f: &&Finding| f.area == "labels" || f.code == "dead-recordings";
        let severe = severe.filter(|f| f.area != "design" && !said(f));
        severe.cloned().collect::<Vec<_>>()
    });
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
