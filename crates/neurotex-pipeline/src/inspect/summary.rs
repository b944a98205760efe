//! What `inspect` reports of the recordings it checked: the layout, the signals, the
//! encoder at the gain and the traces, and how each is drawn from the checked recordings.

use serde::Serialize;

use super::{signals, Channel, Checked, Source, Stamps, TRACE_CLASSES, TRACE_POINTS};
use crate::calibrate::{calibrate_gain, DEFAULT_TARGET_HZ};
use crate::diagnostics::ceiling_rate;
use crate::error::Result;
use crate::model::GainCalibration;
use crate::pipeline::Pipeline;
use crate::recording::{Baseline, LayoutFile, Recording};

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
    /// Recordings in which every channel holds one value from start to end: no signal.
    pub dead: Vec<String>,
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
    /// The Izhikevich firing type of the neurons checked (`RS`, the paper's, or another
    /// preset); `None` when their `a`, `b`, `c` and `d` are no preset's.
    pub neurons: Option<String>,
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

/// The channels' names: the layout's, else each channel's cell as `r{row}c{col}`.
fn channel_names(layout: &LayoutFile, cells: &[[usize; 2]]) -> Vec<String> {
    match &layout.channels {
        Some(names) if names.len() == cells.len() => names.clone(),
        _ => cells.iter().map(|[r, c]| format!("r{r}c{c}")).collect(),
    }
}

pub(super) fn layout_summary(
    source: Source<'_>,
    checked: &[Checked],
    baseline: Baseline,
) -> LayoutSummary {
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
pub(super) fn median(mut values: Vec<f64>) -> f64 {
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

pub(super) fn signal_summary(
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
    let channels = |c: &&Checked| c.stats.channels.clone();
    let dead = (checked.iter())
        .filter(|c| !channels(c).is_empty() && channels(c).iter().all(|ch| ch.dead))
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
        dead,
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

pub(super) fn encoder_check(
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
                saturated_share: count(&|r| crate::diagnostics::at_ceiling(r, ceiling_hz)),
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
        neurons: crate::encode::FiringType::of(&encoder).map(|t| t.name().to_string()),
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
pub(super) fn traces(
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
