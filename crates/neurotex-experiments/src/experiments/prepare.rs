//! The one pass over the recordings that every analysis starts from: condition, encode at
//! the pipeline's gain and, at the slowest speed, at every E7 gain.

use std::time::Instant;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::perturb::perturbed_draws;
use super::{
    taxel_diagnostics, Progress, Provenance, Source, TaxelDiagnostics, ValidReproduceParams,
};
use crate::causal::{calibrate_conditioning, ConditioningCalibration};
use crate::compare::signal::SignalRows;
use crate::encode::encode_banks;
use crate::error::{ClassifyError, DataError, DatasetError, Result};
use crate::inspect::severe_findings;
use crate::pipeline::{events_encoded, Encoded, Encoding, Pipeline};
use crate::recording::{Dataset, Recording};
use crate::signal::Conditioned;
use crate::values::{BySpeed, Grid, Speed};

/// ISI histograms of the gain sweep, accumulated over trials and taxels.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IsiSweep {
    /// Gains, in order.
    pub gains: Vec<f64>,
    /// Texture labels, in order.
    pub labels: Vec<String>,
    /// Histogram bin, ms.
    pub bin_ms: u32,
    /// `gains x labels x bins` counts of ISIs (the last bin collects longer ones).
    pub counts: Vec<Vec<Vec<u64>>>,
    /// `gains x labels` spike totals.
    pub spikes: Vec<Vec<u64>>,
    /// `gains x labels` total encoded taxel-seconds.
    pub taxel_seconds: Vec<Vec<f64>>,
}

/// One recording's contribution to the sweep at one gain.
struct GainPoint {
    histogram: Vec<u64>,
    spikes: u64,
    taxel_seconds: f64,
}

impl IsiSweep {
    fn empty(params: &ValidReproduceParams, labels: Vec<String>) -> Self {
        let (gains, classes) = (params.e7_gains.len(), labels.len());
        IsiSweep {
            gains: params.e7_gains.clone(),
            bin_ms: params.e7_bin_ms,
            counts: vec![vec![vec![0; histogram_bins(params)]; classes]; gains],
            spikes: vec![vec![0; classes]; gains],
            taxel_seconds: vec![vec![0.0; classes]; gains],
            labels,
        }
    }

    fn add(&mut self, label: &str, points: Vec<GainPoint>) {
        let li = self.labels.iter().position(|l| l == label).unwrap_or(0);
        for (g, point) in points.into_iter().enumerate() {
            for (acc, v) in self.counts[g][li].iter_mut().zip(point.histogram) {
                *acc += v;
            }
            self.spikes[g][li] += point.spikes;
            self.taxel_seconds[g][li] += point.taxel_seconds;
        }
    }
}

fn histogram_bins(params: &ValidReproduceParams) -> usize {
    (params.e7_max_ms / params.e7_bin_ms) as usize + 1
}

/// Everything the analyses need, from one pass over the recordings.
pub struct Prepared {
    /// Every recording's spikes at the pipeline's gain (the sliding phase).
    pub encoded: Vec<Encoded>,
    /// The gain sweep at the slowest speed (no counts without E7).
    pub isi: IsiSweep,
    /// The taxel grid, the same for every recording.
    pub grid: Grid,
    /// The distinct speeds, ascending.
    pub speeds: Vec<Speed>,
    /// The slowest speed by magnitude.
    pub slowest: Speed,
    /// The labels in order of first appearance.
    pub labels: Vec<String>,
    /// Taxels silent or at the encoder's ceiling in most recordings.
    pub taxels: TaxelDiagnostics,
    /// The code, parameters, data and date of the run.
    pub provenance: Provenance,
    /// With E5c: the causal pipeline of each speed and every recording's spikes through it.
    pub causal: Option<CausalPrepared>,
    /// The further encodings of the encoder's sensitivity ([`ReproduceParams::encoder_draws`]
    /// less the one as run): each is every recording's spikes from its input perturbed
    /// independently, in the order of `encoded`.
    ///
    /// [`ReproduceParams::encoder_draws`]: super::ReproduceParams::encoder_draws
    pub perturbed: Vec<Vec<Encoded>>,
    /// Why the cross-validation within a speed cannot run with the folds and neighbours
    /// asked for ([`WITHIN_SPEED`]), found on the labels and speeds before any recording
    /// was read; the analyses resting on it are skipped with this reason.
    pub within_speed: Option<String>,
    /// With E9: each recording's rows of the baselines without spikes, from the signal it
    /// was encoded from, in the order of `encoded`; or why a recording has none.
    pub signal: Vec<std::result::Result<SignalRows, String>>,
    /// Seconds the pass took.
    pub seconds: f64,
}

/// The analyses that rest on the cross-validation within each speed.
pub const WITHIN_SPEED: &str =
    "E1-E5, E5c, E8, E9 and the encoder's sensitivity rest on the cross-validation within each speed";

impl Prepared {
    /// The recordings at `speed`.
    pub fn at(&self, speed: Speed) -> impl Iterator<Item = &Encoded> {
        self.encoded
            .iter()
            .filter(move |e| e.meta.speed() == Some(speed))
    }
}

/// E5c's recordings: the causal pipeline fixed at each speed and every recording's spikes
/// through its speed's pipeline.
pub struct CausalPrepared {
    /// Per speed, the resting values and scale fixed on all of that speed's recordings
    /// (labels unused), or why they could not be.
    pub calibration: BySpeed<std::result::Result<ConditioningCalibration, String>>,
    /// Every recording's SA spikes through the causal pipeline of its speed, in the order of
    /// [`Prepared::encoded`]; `None` at a speed whose calibration failed.
    pub encoded: Vec<Option<Encoded>>,
    /// Seconds the calibration pass took (the causal encoding is part of the main pass).
    pub seconds: f64,
}

/// One speed's causal conditioning and the pipeline applying it, or why it could not be fixed.
type CausalPipeline = std::result::Result<(ConditioningCalibration, Pipeline), String>;

/// With E5c, the causal conditioning of each speed, fixed on all of its recordings (labels
/// unused: each is in some training fold of the cross-validation), and the pipeline that
/// applies it; a speed where it cannot be fixed gets the reason instead.
fn causal_pipelines(
    source: &Source,
    params: &ValidReproduceParams,
    conditions: &[(Speed, String)],
) -> Result<Option<Vec<(Speed, CausalPipeline)>>> {
    if !params.e5_causal {
        return Ok(None);
    }
    let mut sa = params.pipeline().params().clone();
    // E5c compares the paper's SA encoding with its causal twin.
    sa.encoding = Encoding::Sa;
    let load = |i: usize| source.load(i);
    let mut out = Vec::new();
    for speed in Speed::distinct(conditions.iter().map(|c| c.0)) {
        let indices: Vec<usize> = (0..conditions.len())
            .filter(|&i| conditions[i].0 == speed)
            .collect();
        let fixed = match calibrate_conditioning(&sa, &load, &indices, source.baseline()) {
            Ok(c) => {
                let mut p = sa.clone();
                p.preprocess.causal = Some(c.conditioning.clone());
                Ok((c, Pipeline::new(p)?))
            }
            Err(e) => Err(e.to_string()),
        };
        out.push((speed, fixed));
    }
    Ok(Some(out))
}

/// The labels of `conditions` in the order they first appear.
fn distinct_labels(conditions: &[(Speed, String)]) -> Vec<String> {
    let mut labels: Vec<String> = Vec::new();
    for (_, l) in conditions {
        if !labels.contains(l) {
            labels.push(l.clone());
        }
    }
    labels
}

/// Whether the cross-validation within each speed ([`WITHIN_SPEED`]) can run with the
/// folds and neighbours asked for: checked on the recordings' labels and speeds before any
/// is read, so that a design too small is known at once, naming the speed and what the
/// design supports. Under `group_by` the folds follow the groups and are checked where
/// they are made.
///
/// # Errors
/// A class with fewer recordings than folds at some speed, or training folds smaller than
/// `k` there.
fn check_design(conditions: &[(Speed, String)], params: &ValidReproduceParams) -> Result<()> {
    let (cv, group_by) = params.folds();
    if group_by.is_some() {
        return Ok(());
    }
    let k = params.knn().params().k;
    // Each speed's recordings per class, counted once.
    let per_speed: Vec<(Speed, Vec<(&str, usize)>)> =
        Speed::distinct(conditions.iter().map(|c| c.0))
            .into_iter()
            .map(|speed| {
                let mut counts: Vec<(&str, usize)> = Vec::new();
                for (_, label) in conditions.iter().filter(|c| c.0 == speed) {
                    match counts.iter_mut().find(|(l, _)| *l == label) {
                        Some((_, n)) => *n += 1,
                        None => counts.push((label, 1)),
                    }
                }
                (speed, counts)
            })
            .collect();
    // Stratified folds deal a speed's n recordings round-robin: the largest test fold
    // holds ceil(n / folds), the smallest training fold the rest.
    let training = |counts: &[(&str, usize)], folds: usize| {
        let n: usize = counts.iter().map(|c| c.1).sum();
        n - n.div_ceil(folds.max(1))
    };
    // The most folds every class at every speed can fill, and with them the fewest
    // training recordings of any fold.
    let max_folds = per_speed
        .iter()
        .filter_map(|(_, counts)| counts.iter().map(|c| c.1).min())
        .min()
        .unwrap_or(0);
    let smallest_training = |folds: usize| {
        per_speed
            .iter()
            .map(|(_, counts)| training(counts, folds))
            .min()
            .unwrap_or(0)
    };
    let supports = match max_folds {
        0 | 1 => "this design supports no cross-validation within a speed: each class needs at least 2 recordings at each speed".to_string(),
        f => {
            let folds = cv.folds.min(f);
            let most = smallest_training(folds);
            // A class's fewest recordings in a training fold: more neighbours than that
            // let the other classes tie or outvote it whatever the features say.
            let per_class = per_speed
                .iter()
                .flat_map(|(_, counts)| counts.iter().map(|c| c.1 - c.1.div_ceil(folds)))
                .min()
                .unwrap_or(0);
            let votes = if per_class < most {
                format!("; a class has as few as {per_class} recording(s) in a training fold, so more than {per_class} neighbours can tie or outvote it")
            } else {
                String::new()
            };
            format!("this design supports at most {f} folds, and with {folds} folds at most {most} neighbours{votes}")
        }
    };
    for (speed, counts) in &per_speed {
        let what = format!("at {speed} mm/s, the cross-validation within a speed ({supports})");
        if let Some((label, count)) = counts.iter().find(|c| c.1 < cv.folds) {
            let error = ClassifyError::ClassTooSmall {
                label: label.to_string(),
                count: *count,
                folds: cv.folds,
            };
            return Err(crate::Error::from(error).in_analysis(what));
        }
        let n_train = training(counts, cv.folds);
        if k > n_train {
            let error = ClassifyError::KTooLarge { k, n_train };
            return Err(crate::Error::from(error).in_analysis(what));
        }
    }
    Ok(())
}

/// Says a dataset's severe findings on its signals and layout ([`severe_findings`]) as
/// advice, before anything is encoded.
///
/// # Errors
/// As [`severe_findings`].
fn say_severe_findings(
    source: &Source,
    params: &ValidReproduceParams,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<()> {
    if let Source::Dataset(ds) = source {
        for line in severe_findings(ds, params.pipeline().params())?.lines() {
            progress(Progress::Advice(&line));
        }
    }
    Ok(())
}

/// Every recording's encodings gathered from their one-by-one results.
struct Gathered {
    encoded: Vec<Encoded>,
    perturbed: Vec<Vec<Encoded>>,
    causal_encoded: Vec<Option<Encoded>>,
    signal: Vec<std::result::Result<SignalRows, String>>,
    isi: IsiSweep,
}

/// The recordings' results, in order, gathered by kind: the encodings as run, each
/// perturbed draw's, the causal ones, the signal baselines' rows, and E7's intervals.
fn gathered(
    results: Vec<EncodedOne>,
    params: &ValidReproduceParams,
    labels: &[String],
) -> Gathered {
    let n = results.len();
    let mut g = Gathered {
        encoded: Vec::with_capacity(n),
        perturbed: (1..params.encoder_draws)
            .map(|_| Vec::with_capacity(n))
            .collect(),
        causal_encoded: Vec::with_capacity(n),
        signal: Vec::new(),
        isi: IsiSweep::empty(params, labels.to_vec()),
    };
    for one in results {
        g.causal_encoded.push(one.causal);
        g.signal.extend(one.signal);
        if let Some(points) = one.sweep {
            g.isi.add(&one.encoded.meta.label, points);
        }
        for (all, p) in g.perturbed.iter_mut().zip(one.perturbed) {
            all.push(p);
        }
        g.encoded.push(one.encoded);
    }
    g
}

/// One pass over the recordings: condition, encode at the pipeline's gain, and for the
/// slowest speed also at every E7 gain (accumulating ISI histograms). Parallel across
/// recordings; a recording's raw samples are dropped as soon as it is encoded.
///
/// # Errors
/// No recordings, a recording that cannot be read or conditioned, or recordings of
/// different grids.
pub fn prepare(
    source: &Source,
    params: &ValidReproduceParams,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<Prepared> {
    let start = Instant::now();
    let n = source.len();
    let conditions: Vec<(Speed, String)> =
        (0..n).map(|i| source.condition(i)).collect::<Result<_>>()?;
    let slowest = Speed::slowest(conditions.iter().map(|c| c.0)).ok_or(DatasetError::Empty)?;
    let within_speed = check_design(&conditions, params).err().map(|e| {
        progress(Progress::TooSmall(&e));
        e.to_string()
    });
    say_severe_findings(source, params, progress)?;
    let labels = distinct_labels(&conditions);
    let clock = Instant::now();
    let causal = causal_pipelines(source, params, &conditions)?;
    let causal_seconds = clock.elapsed().as_secs_f64();
    let causal_at = |speed: Speed| {
        causal.as_ref().and_then(|all| {
            all.iter()
                .find(|(s, _)| *s == speed)
                .and_then(|(_, p)| p.as_ref().ok().map(|(_, p)| p))
        })
    };
    progress(Progress::Stage("recordings", n));
    let results: Vec<EncodedOne> = (0..n)
        .into_par_iter()
        .map(|i| {
            let (speed, sweep) = (conditions[i].0, params.e7 && conditions[i].0 == slowest);
            let out = encode_one(source, i, sweep, causal_at(speed), params);
            progress(Progress::Tick);
            out
        })
        .collect::<Result<_>>()?;
    let Gathered {
        encoded,
        perturbed,
        causal_encoded,
        signal,
        isi,
    } = gathered(results, params, &labels);
    for warning in encoded.iter().filter_map(Encoded::constant_warning) {
        progress(Progress::Advice(&warning));
    }
    let grid = one_grid(&encoded)?;
    let taxels = advised_taxels(&encoded, &grid, params, progress)?;
    let causal = causal.map(|all| CausalPrepared {
        calibration: all
            .into_iter()
            .map(|(s, p)| (s, p.map(|(c, _)| c)))
            .collect(),
        encoded: causal_encoded,
        seconds: causal_seconds,
    });
    Ok(Prepared {
        causal,
        provenance: Provenance::of(source, params)?,
        speeds: Speed::distinct(conditions.iter().map(|c| c.0)),
        taxels,
        perturbed,
        encoded,
        isi,
        grid,
        slowest,
        labels,
        within_speed,
        signal,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// The taxels silent or at the encoder's ceiling, with the advice about them said.
///
/// # Errors
/// As [`taxel_diagnostics`].
fn advised_taxels(
    encoded: &[Encoded],
    grid: &Grid,
    params: &ValidReproduceParams,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<TaxelDiagnostics> {
    let taxels = taxel_diagnostics(encoded, grid, params)?;
    if let Some(advice) = taxels.advice() {
        progress(Progress::Advice(&advice));
    }
    Ok(taxels)
}

/// The taxel grid every recording shares.
///
/// # Errors
/// A recording whose grid differs from the first's.
fn one_grid(encoded: &[Encoded]) -> Result<Grid> {
    let grid = encoded[0].spikes.grid();
    if let Some(e) = encoded.iter().find(|e| e.spikes.present != grid.present()) {
        let message = "its taxel grid differs from the first recording's";
        return Err(DataError::invalid(&e.meta.file, message).into());
    }
    Ok(grid)
}

/// One recording's share of the pass.
struct EncodedOne {
    encoded: Encoded,
    /// The E7 sweep's histograms, at the slowest speed.
    sweep: Option<Vec<GainPoint>>,
    /// The spikes of each perturbed encoding of the input.
    perturbed: Vec<Encoded>,
    /// The spikes through the causal pipeline of the recording's speed, with E5c.
    causal: Option<Encoded>,
    /// With E9, the baselines' rows of the signal the recording was encoded from.
    signal: Option<std::result::Result<SignalRows, String>>,
}

/// Loads, conditions and encodes recording `i`; with `sweep`, also encodes it at every E7
/// gain and returns its ISI histograms; encodes its input perturbed once for each further
/// encoding; with a `causal` pipeline, also encodes it through that.
fn encode_one(
    source: &Source,
    i: usize,
    sweep: bool,
    causal: Option<&Pipeline>,
    params: &ValidReproduceParams,
) -> Result<EncodedOne> {
    let pipeline = params.pipeline();
    if let Source::Dataset(ds) = source {
        if ds.is_events() {
            return events_one(ds, i, params);
        }
    }
    let rec = source.load(i)?;
    let causal = match causal {
        Some(p) => Some(p.encode(&rec, source.baseline())?),
        None => None,
    };
    let cond = pipeline.condition(&rec, source.baseline())?;
    let (spikes, fa) = if params.e9 && pipeline.params().encoding == Encoding::Sa {
        // E9 compares the sa+fa encoding too; the other analyses read the SA population.
        let (sa, fa) = pipeline.encode_sa_fa(&rec, &cond)?;
        (sa, Some(fa))
    } else {
        pipeline.encode_populations(&rec, &cond)?
    };
    let sweep = if sweep {
        Some(gain_sweep(&rec, &cond, params)?)
    } else {
        None
    };
    let signal = params.e9.then(|| {
        SignalRows::of(&rec, &cond, &pipeline.params().features).map_err(|e| e.to_string())
    });
    let encoded = Encoded::of(&rec, &cond, (spikes, fa));
    let perturbed = perturbed_draws(&rec, &cond, params, i)?
        .into_iter()
        .map(|(spikes, fa)| Encoded {
            spikes,
            fa,
            ..encoded.clone()
        })
        .collect();
    Ok(EncodedOne {
        encoded,
        sweep,
        perturbed,
        causal,
        signal,
    })
}

/// An address-event recording as [`encode_one`] gives an encoded one: its ON and OFF
/// trains, both when E9 compares the `sa+fa` encoding and the events have polarities; no
/// sweep, perturbation or causal twin (the events skip the encoder), and no signal for
/// E9's baselines.
fn events_one(ds: &Dataset, i: usize, params: &ValidReproduceParams) -> Result<EncodedOne> {
    let events = ds.load_events(i)?;
    let path = ds.root.join(&ds.entries[i].file);
    let mut encoding = params.pipeline().params().encoding;
    if params.e9 && encoding == Encoding::Sa && events.off.is_some() {
        encoding = Encoding::SaFa;
    }
    let encoded = events_encoded(encoding, ds.entries[i].clone(), events, &path)?;
    Ok(EncodedOne {
        encoded,
        sweep: None,
        perturbed: Vec::new(),
        causal: None,
        signal: params
            .e9
            .then(|| Err("the recordings are address events, which carry no signal".into())),
    })
}

fn gain_sweep(
    rec: &Recording,
    cond: &Conditioned,
    params: &ValidReproduceParams,
) -> Result<Vec<GainPoint>> {
    let bins = histogram_bins(params);
    let (l, encoder) = (&rec.layout, params.pipeline().params().encoder);
    // Every gain's neurons see the same signal; they run side by side.
    let signals = vec![cond.samples.as_slice(); params.e7_gains.len()];
    let gains = &params.e7_gains;
    encode_banks(&signals, gains, l.rows, l.cols, &l.present, encoder)?
        .iter()
        .map(|trains| {
            let mut histogram = vec![0u64; bins];
            for cell in 0..trains.cells() {
                for w in trains.train(cell).windows(2) {
                    let b = ((w[1] - w[0]) / params.e7_bin_ms) as usize;
                    histogram[b.min(bins - 1)] += 1;
                }
            }
            let taxels = trains.present.iter().filter(|&&p| p).count();
            Ok(GainPoint {
                histogram,
                spikes: trains.total_spikes() as u64,
                taxel_seconds: taxels as f64 * trains.n_steps as f64 / 1000.0,
            })
        })
        .collect()
}
