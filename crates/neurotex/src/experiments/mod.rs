//! The paper's analyses E0-E8 (SPEC section 4) as functions from encoded recordings and
//! parameters to result structs, and the single pass that produces the encoded recordings
//! from the simulator or a dataset folder.

mod claims;

pub use claims::{claims, Claim, Verdict};

use std::collections::BTreeMap;

use crate::values::{BySpeed, Speed};
use std::time::Instant;

use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::analysis::{evaluate, Columns, FeatureTable, Outcome, Split};
use crate::classify::{CvParams, KnnParams};
use crate::error::{DataError, Result};
use crate::pipeline::{Encoded, Method, Pipeline, PipelineParams};
use crate::recording::{same_speed, Baseline, Dataset, Recording};
use crate::sim::{simulate_trial, RigParams, Trial};

/// Parameters of a reproduction run; defaults are the and the paper's.
#[derive(Debug, Clone, PartialEq)]
pub struct ReproduceParams {
    /// The pipeline (gain 8, 200 ms bins, 16 levels, distances 1, 2, 4, 8, ...).
    pub pipeline: PipelineParams,
    /// KNN (k = 5, z-scored).
    pub knn: KnnParams,
    /// Cross-validation (5 folds, seed, repeats).
    pub cv: CvParams,
    /// E3: random perturbations per n.
    pub e3_repeats: usize,
    /// E3: the numbers of taxels moved.
    pub e3_counts: Vec<usize>,
    /// E5: fractions of the slide used.
    pub e5_fractions: Vec<f64>,
    /// E7: gains swept.
    pub e7_gains: Vec<f64>,
    /// E7: ISI histogram bin, ms.
    pub e7_bin_ms: u32,
    /// E7: ISI histogram range, ms.
    pub e7_max_ms: u32,
    /// E8: neighbour counts.
    pub e8_ks: Vec<usize>,
    /// Seed of E3's perturbations.
    pub seed: u64,
}

impl Default for ReproduceParams {
    fn default() -> Self {
        ReproduceParams {
            pipeline: PipelineParams::default(),
            knn: KnnParams::default(),
            cv: CvParams {
                folds: 5,
                seed: 0,
                repeats: 10,
            },
            e3_repeats: 10,
            e3_counts: (2..=16).collect(),
            e5_fractions: (1..=10).map(|k| k as f64 / 10.0).collect(),
            e7_gains: (5..=20).map(f64::from).collect(),
            e7_bin_ms: 5,
            e7_max_ms: 300,
            e8_ks: vec![1, 3, 5, 7, 9],
            seed: 0,
        }
    }
}

impl ReproduceParams {
    /// A smaller run for tests and CI: fewer repeats, perturbation counts, fractions and gains.
    pub fn quick() -> Self {
        ReproduceParams {
            cv: CvParams {
                folds: 5,
                seed: 0,
                repeats: 2,
            },
            e3_repeats: 3,
            e3_counts: vec![2, 4, 8, 16],
            e5_fractions: vec![0.2, 0.5, 1.0],
            e7_gains: vec![5.0, 8.0, 12.0, 20.0],
            e8_ks: vec![1, 5, 9],
            ..Self::default()
        }
    }
}

/// Where the recordings come from.
pub enum Source<'a> {
    /// The built-in simulator, trials generated in memory and never written.
    Simulated {
        /// Rig parameters.
        rig: Box<RigParams>,
        /// The trials.
        trials: Vec<Trial>,
        /// Simulation seed.
        seed: u64,
    },
    /// A dataset folder.
    Dataset(&'a Dataset),
}

/// Progress events for a progress bar.
#[derive(Debug, Clone, Copy)]
pub enum Progress<'a> {
    /// A stage begins with this many steps.
    Stage(&'a str, usize),
    /// One step of the current stage is done.
    Tick,
}

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

/// Everything the analyses need, from one pass over the recordings.
pub struct Prepared {
    /// Every recording's spikes at the pipeline's gain (the sliding phase).
    pub encoded: Vec<Encoded>,
    /// The gain sweep at the slowest speed.
    pub isi: IsiSweep,
    /// Grid present flags and columns.
    pub present: Vec<bool>,
    /// Grid columns.
    pub cols: usize,
    /// Seconds the pass took.
    pub seconds: f64,
}

/// The slowest condition: the smallest speed in magnitude (a positive one before its
/// negative twin, for rigs that record direction as the sign).
pub fn slowest_speed(speeds: impl Iterator<Item = f64>) -> f64 {
    speeds
        .min_by(|a, b| {
            a.abs()
                .total_cmp(&b.abs())
                .then((*a < 0.0).cmp(&(*b < 0.0)))
        })
        .unwrap_or(0.0)
}

/// One pass over the recordings: condition, encode at the pipeline's gain, and for the
/// slowest speed also at every E7 gain (accumulating ISI histograms). Parallel across
/// recordings; a recording's raw samples are dropped as soon as it is encoded.
///
/// # Errors
/// A recording that cannot be read or conditioned, or a bad gain.
pub fn prepare(
    source: &Source,
    params: &ReproduceParams,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<Prepared> {
    let start = Instant::now();
    let pipeline = Pipeline::new(params.pipeline.clone())?;
    let (n, metas_speed_label): (usize, Vec<(f64, String)>) = match source {
        Source::Simulated { trials, .. } => (
            trials.len(),
            trials
                .iter()
                .map(|t| (t.speed_mm_s, t.texture.name().to_string()))
                .collect(),
        ),
        Source::Dataset(ds) => (
            ds.entries.len(),
            ds.entries
                .iter()
                .map(|m| (m.speed_mm_s, m.label.clone()))
                .collect(),
        ),
    };
    let slowest = slowest_speed(metas_speed_label.iter().map(|m| m.0));
    let mut labels: Vec<String> = Vec::new();
    for (_, l) in &metas_speed_label {
        if !labels.contains(l) {
            labels.push(l.clone());
        }
    }
    let baseline = match source {
        Source::Dataset(ds) => ds.layout.baseline.unwrap_or_default(),
        Source::Simulated { .. } => Baseline::None,
    };
    let load = |i: usize| -> Result<Recording> {
        match source {
            Source::Simulated { rig, trials, seed } => Ok(simulate_trial(rig, &trials[i], *seed)?),
            Source::Dataset(ds) => ds.load(i),
        }
    };
    let bins = (params.e7_max_ms / params.e7_bin_ms.max(1)) as usize + 1;
    progress(Progress::Stage("recordings", n));
    type Sweep = Vec<(Vec<u64>, u64, f64)>;
    let results: Vec<(Encoded, Option<Sweep>)> = (0..n)
        .into_par_iter()
        .map(|i| -> Result<_> {
            let rec = load(i)?;
            let cond = pipeline.condition(&rec, baseline)?;
            let spikes = pipeline.encode_conditioned(&rec, &cond, None)?;
            let sweep = if same_speed(rec.meta.speed_mm_s, slowest) {
                let mut out = Vec::with_capacity(params.e7_gains.len());
                for &g in &params.e7_gains {
                    let trains = pipeline.encode_conditioned(&rec, &cond, Some(g))?;
                    let mut hist = vec![0u64; bins];
                    for cell in 0..trains.cells() {
                        for w in trains.train(cell).windows(2) {
                            let b = ((w[1] - w[0]) / params.e7_bin_ms.max(1)) as usize;
                            hist[b.min(bins - 1)] += 1;
                        }
                    }
                    let taxels = trains.present.iter().filter(|&&p| p).count();
                    out.push((
                        hist,
                        trains.total_spikes() as u64,
                        taxels as f64 * trains.n_steps as f64 / 1000.0,
                    ));
                }
                Some(out)
            } else {
                None
            };
            let encoded = Encoded {
                meta: rec.meta.clone(),
                spikes,
                resampled: cond.resampled,
                flat: cond.flat,
            };
            progress(Progress::Tick);
            Ok((encoded, sweep))
        })
        .collect::<Result<_>>()?;
    let mut isi = IsiSweep {
        gains: params.e7_gains.clone(),
        labels: labels.clone(),
        bin_ms: params.e7_bin_ms,
        counts: vec![vec![vec![0; bins]; labels.len()]; params.e7_gains.len()],
        spikes: vec![vec![0; labels.len()]; params.e7_gains.len()],
        taxel_seconds: vec![vec![0.0; labels.len()]; params.e7_gains.len()],
    };
    let mut encoded = Vec::with_capacity(n);
    for (e, sweep) in results {
        if let Some(sweep) = sweep {
            let li = labels.iter().position(|l| *l == e.meta.label).unwrap_or(0);
            for (g, (hist, spikes, secs)) in sweep.into_iter().enumerate() {
                for (acc, v) in isi.counts[g][li].iter_mut().zip(hist) {
                    *acc += v;
                }
                isi.spikes[g][li] += spikes;
                isi.taxel_seconds[g][li] += secs;
            }
        }
        encoded.push(e);
    }
    let first = &encoded
        .first()
        .ok_or_else(|| DataError::invalid("dataset", "no recordings"))?
        .spikes;
    let (present, cols) = (first.present.clone(), first.cols);
    if let Some(e) = encoded.iter().find(|e| e.spikes.present != present) {
        return Err(DataError::invalid(
            &e.meta.file,
            "its taxel grid differs from the first recording's",
        )
        .into());
    }
    Ok(Prepared {
        encoded,
        isi,
        present,
        cols,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// Accuracy of one approach with its spread over CV repeats.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Score {
    /// Accuracy 0..1 (for the single taxel: mean over taxels).
    pub accuracy: f64,
    /// Standard deviation over repeats.
    pub std: f64,
}

/// E1 at one speed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct E1Speed {
    /// Single taxel, mean over taxels.
    pub taxel_mean: f64,
    /// The best taxel (chosen after the fact).
    pub taxel_best: f64,
    /// Which taxel was best, `r{row}c{col}`.
    pub taxel_best_cell: String,
    /// 3D-GLCM.
    pub glcm3d: f64,
    /// 3D-GLCM standard deviation over CV repeats.
    pub glcm3d_std: f64,
    /// Samples.
    pub n: usize,
}

/// E2: confusion matrices at the slowest speed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct E2 {
    /// Speed, mm/s.
    pub speed: Speed,
    /// Labels in matrix order.
    pub labels: Vec<String>,
    /// Single taxel, summed over taxels and repeats (row = true).
    pub taxel: Vec<Vec<usize>>,
    /// 3D-GLCM, summed over repeats (row = true).
    pub glcm3d: Vec<Vec<usize>>,
}

/// E3: spatial perturbation at the slowest speed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct E3 {
    /// Speed, mm/s.
    pub speed: Speed,
    /// Random draws per n.
    pub repeats: usize,
    /// Taxels moved.
    pub n: Vec<usize>,
    /// Mean 3D-GLCM accuracy over perturbations, per n.
    pub mean: Vec<f64>,
    /// Standard deviation over perturbations, per n.
    pub std: Vec<f64>,
    /// Unperturbed 3D-GLCM (E1).
    pub glcm3d: f64,
    /// Single taxel mean (E1).
    pub taxel_mean: f64,
}

/// E4 at one speed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct E4Speed {
    /// Single taxel mean.
    pub taxel_mean: f64,
    /// 2D-GLCM.
    pub glcm2d: f64,
    /// 3D-GLCM.
    pub glcm3d: f64,
}

/// E5 at one speed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct E5Speed {
    /// Fractions of the slide used.
    pub fractions: Vec<f64>,
    /// 3D-GLCM accuracy per fraction (`null` where the fraction is shorter than one bin).
    pub glcm3d: Vec<Option<f64>>,
    /// Single taxel mean on the whole slide.
    pub taxel_full: f64,
    /// Smallest fraction at which 3D-GLCM reaches the single taxel's accuracy.
    pub first_match: Option<f64>,
}

/// E6 at one held-out speed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct E6Speed {
    /// Training speeds.
    pub train: Vec<Speed>,
    /// Single taxel mean.
    pub taxel_mean: f64,
    /// 3D-GLCM.
    pub glcm3d: f64,
}

/// E7: the gain sweep's ISI statistics at the slowest speed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct E7 {
    /// Speed, mm/s.
    pub speed: Speed,
    /// The histograms.
    pub sweep: IsiSweep,
    /// `gains x labels` mean firing rate per taxel, Hz.
    pub rate_hz: Vec<Vec<f64>>,
    /// `gains x labels` median ISI, ms (from the histogram, bin centre).
    pub median_isi_ms: Vec<Vec<Option<f64>>>,
}

/// E8 at one speed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct E8Speed {
    /// Neighbour counts.
    pub k: Vec<usize>,
    /// Single taxel mean per k.
    pub taxel_mean: Vec<f64>,
    /// 3D-GLCM per k.
    pub glcm3d: Vec<f64>,
}

/// E0: one taxel's PSTH and the rate volume, for two textures.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct E0 {
    /// Speed, mm/s.
    pub speed: Speed,
    /// The taxel shown, `[row, col]`.
    pub taxel: [usize; 2],
    /// PSTH bin, ms.
    pub psth_bin_ms: usize,
    /// Per texture.
    pub examples: Vec<E0Example>,
}

/// One texture's example for E0.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct E0Example {
    /// Texture label.
    pub label: String,
    /// Recording file.
    pub file: String,
    /// Spike counts of the taxel per PSTH bin.
    pub psth: Vec<u32>,
    /// Rate volume, `cells x bins` (row-major cells), Hz.
    pub volume: Vec<Vec<f64>>,
}

/// All results, as written to `results.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Results {
    /// Speeds found, ascending.
    pub speeds: Vec<Speed>,
    /// Labels in order.
    pub labels: Vec<String>,
    /// Recordings used.
    pub recordings: usize,
    /// Recordings resampled to 1 kHz.
    pub resampled: usize,
    /// Recordings with no positive signal.
    pub flat: usize,
    /// E0.
    pub e0: Option<E0>,
    /// E1 by speed.
    pub e1: BySpeed<E1Speed>,
    /// E2.
    pub e2: Option<E2>,
    /// E3.
    pub e3: Option<E3>,
    /// E4 by speed.
    pub e4: BySpeed<E4Speed>,
    /// E5 by speed.
    pub e5: BySpeed<E5Speed>,
    /// E6 by held-out speed.
    pub e6: BySpeed<E6Speed>,
    /// E7.
    pub e7: Option<E7>,
    /// E8 by speed.
    pub e8: BySpeed<E8Speed>,
    /// Analyses skipped, with the reason.
    pub skipped: BTreeMap<String, String>,
    /// Wall-clock seconds per analysis.
    pub timing_s: BTreeMap<String, f64>,
}

struct Ctx<'a> {
    prepared: &'a Prepared,
    pipeline: Pipeline,
    params: &'a ReproduceParams,
}

impl Ctx<'_> {
    fn table(&self, encoded: &[Encoded], method: Method) -> Result<FeatureTable> {
        let extractor = self.pipeline.extractor(
            encoded[0].spikes.rows,
            encoded[0].spikes.cols,
            &self.prepared.present,
        )?;
        FeatureTable::build(encoded, &extractor, method)
    }

    fn cv(
        &self,
        table: &FeatureTable,
        columns: Columns,
        speed: f64,
        knn: KnnParams,
    ) -> Result<Outcome> {
        let split = Split::CrossValidation {
            speeds: Some(vec![speed]),
            cv: self.params.cv,
        };
        evaluate(
            table,
            &self.prepared.present,
            self.prepared.cols,
            columns,
            &split,
            knn,
        )
    }
}

/// Runs E0-E8 on prepared recordings; an analysis the data cannot support is skipped with
/// its reason.
///
/// # Errors
/// A classification that cannot run (a class smaller than the fold count, for example).
pub fn run_all(
    prepared: &Prepared,
    params: &ReproduceParams,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<Results> {
    let ctx = Ctx {
        prepared,
        pipeline: Pipeline::new(params.pipeline.clone())?,
        params,
    };
    let enc = &prepared.encoded;
    let speeds = Speed::distinct(enc.iter().map(|e| Speed::of(e.meta.speed_mm_s)));
    let mut labels: Vec<String> = Vec::new();
    for e in enc {
        if !labels.contains(&e.meta.label) {
            labels.push(e.meta.label.clone());
        }
    }
    let slowest_s = Speed::slowest(speeds.iter().copied()).unwrap_or(Speed::of(0.0));
    let slowest = slowest_s.mm_s();
    let mut r = Results {
        speeds: speeds.clone(),
        labels: labels.clone(),
        recordings: enc.len(),
        resampled: enc.iter().filter(|e| e.resampled).count(),
        flat: enc.iter().filter(|e| e.flat).count(),
        e0: None,
        e1: BySpeed::new(),
        e2: None,
        e3: None,
        e4: BySpeed::new(),
        e5: BySpeed::new(),
        e6: BySpeed::new(),
        e7: None,
        e8: BySpeed::new(),
        skipped: BTreeMap::new(),
        timing_s: BTreeMap::new(),
    };
    r.timing_s.insert("prepare".into(), prepared.seconds);
    let mut clock = Instant::now();
    let mut lap = |name: &str, timing: &mut BTreeMap<String, f64>| {
        timing.insert(name.to_string(), clock.elapsed().as_secs_f64());
        clock = Instant::now();
    };
    progress(Progress::Stage("analyses", 8));

    // Feature tables over all recordings, reused by E1, E2, E4, E6, E8.
    let taxel = ctx.table(enc, Method::Taxel)?;
    let g3 = ctx.table(enc, Method::Glcm3d)?;
    let g2 = ctx.table(enc, Method::Glcm2d)?;

    // E1 and E2
    let mut slow_outcomes = None;
    for &sp in &speeds {
        let s = sp.mm_s();
        let t = ctx.cv(&taxel, Columns::EachTaxel, s, params.knn)?;
        let g = ctx.cv(&g3, Columns::All, s, params.knn)?;
        let best = t.best.expect("every taxel evaluated");
        r.e1.insert(
            sp,
            E1Speed {
                taxel_mean: t.accuracy,
                taxel_best: best.accuracy,
                taxel_best_cell: format!("r{}c{}", best.row, best.col),
                glcm3d: g.accuracy,
                glcm3d_std: g.accuracy_std,
                n: g.n,
            },
        );
        if same_speed(s, slowest) {
            slow_outcomes = Some((t, g));
        }
    }
    lap("e1", &mut r.timing_s);
    progress(Progress::Tick);
    if let Some((t, g)) = slow_outcomes {
        r.e2 = Some(E2 {
            speed: slowest_s,
            labels: g.labels.clone(),
            taxel: t.confusion,
            glcm3d: g.confusion,
        });
    }
    lap("e2", &mut r.timing_s);
    progress(Progress::Tick);

    // E3: perturb the slowest speed's recordings
    let slow: Vec<Encoded> = enc
        .iter()
        .filter(|e| same_speed(e.meta.speed_mm_s, slowest))
        .cloned()
        .collect();
    let taxels: Vec<usize> = prepared
        .present
        .iter()
        .enumerate()
        .filter(|(_, &p)| p)
        .map(|(i, _)| i)
        .collect();
    let counts: Vec<usize> = params
        .e3_counts
        .iter()
        .copied()
        .filter(|&n| n >= 2 && n <= taxels.len())
        .collect();
    if counts.is_empty() {
        r.skipped
            .insert("e3".into(), "fewer than 2 taxels to move".into());
    } else {
        let single_cv = CvParams {
            repeats: 1,
            ..params.cv
        };
        let mut mean = Vec::new();
        let mut std = Vec::new();
        for &n in &counts {
            let accs: Vec<f64> = (0..params.e3_repeats)
                .map(|rep| -> Result<f64> {
                    let perturbed: Vec<Encoded> = slow
                        .par_iter()
                        .enumerate()
                        .map(|(i, e)| {
                            let mut rng = ChaCha8Rng::seed_from_u64(
                                params.seed ^ ((n as u64) << 40) ^ ((rep as u64) << 20) ^ i as u64,
                            );
                            let perm = perturbation(&taxels, e.spikes.cells(), n, &mut rng);
                            Encoded {
                                spikes: e.spikes.permuted(&perm),
                                ..e.clone()
                            }
                        })
                        .collect();
                    let table = ctx.table(&perturbed, Method::Glcm3d)?;
                    let split = Split::CrossValidation {
                        speeds: None,
                        cv: single_cv,
                    };
                    Ok(evaluate(
                        &table,
                        &prepared.present,
                        prepared.cols,
                        Columns::All,
                        &split,
                        params.knn,
                    )?
                    .accuracy)
                })
                .collect::<Result<_>>()?;
            let m = accs.iter().sum::<f64>() / accs.len() as f64;
            mean.push(m);
            std.push(
                (accs.iter().map(|a| (a - m).powi(2)).sum::<f64>() / accs.len() as f64).sqrt(),
            );
        }
        let e1 = r.e1.get(slowest_s).expect("E1 ran at every speed");
        r.e3 = Some(E3 {
            speed: slowest_s,
            repeats: params.e3_repeats,
            n: counts,
            mean,
            std,
            glcm3d: e1.glcm3d,
            taxel_mean: e1.taxel_mean,
        });
    }
    lap("e3", &mut r.timing_s);
    progress(Progress::Tick);

    // E4
    for &sp in &speeds {
        let s = sp.mm_s();
        let g = ctx.cv(&g2, Columns::All, s, params.knn)?;
        let e1 = r.e1.get(sp).expect("E1 ran at every speed");
        r.e4.insert(
            sp,
            E4Speed {
                taxel_mean: e1.taxel_mean,
                glcm2d: g.accuracy,
                glcm3d: e1.glcm3d,
            },
        );
    }
    lap("e4", &mut r.timing_s);
    progress(Progress::Tick);

    // E5
    for &sp in &speeds {
        let s = sp.mm_s();
        let at_speed: Vec<&Encoded> = enc
            .iter()
            .filter(|e| same_speed(e.meta.speed_mm_s, s))
            .collect();
        let mut accs = Vec::new();
        for &p in &params.e5_fractions {
            let truncated: Vec<Encoded> = at_speed
                .par_iter()
                .map(|e| Encoded {
                    spikes: e
                        .spikes
                        .truncated(((e.spikes.n_steps as f64) * p).floor() as usize),
                    ..(*e).clone()
                })
                .collect();
            if truncated
                .iter()
                .any(|e| e.spikes.n_steps < params.pipeline.volume.bin_ms)
            {
                accs.push(None);
                continue;
            }
            let table = ctx.table(&truncated, Method::Glcm3d)?;
            accs.push(Some(ctx.cv(&table, Columns::All, s, params.knn)?.accuracy));
        }
        let taxel_full = r.e1.get(sp).expect("E1 ran at every speed").taxel_mean;
        let first_match = params
            .e5_fractions
            .iter()
            .zip(&accs)
            .find(|(_, a)| a.is_some_and(|a| a >= taxel_full))
            .map(|(&p, _)| p);
        r.e5.insert(
            sp,
            E5Speed {
                fractions: params.e5_fractions.clone(),
                glcm3d: accs,
                taxel_full,
                first_match,
            },
        );
    }
    lap("e5", &mut r.timing_s);
    progress(Progress::Tick);

    // E6
    if speeds.len() < 2 {
        r.skipped.insert(
            "e6".into(),
            "the dataset has only one speed; E6 needs at least two".into(),
        );
    } else {
        for &sp in &speeds {
            let s = sp.mm_s();
            let train: Vec<Speed> = speeds.iter().copied().filter(|&x| x != sp).collect();
            let split = Split::ByCondition {
                train: train.iter().map(|s| s.mm_s()).collect(),
                test: vec![s],
            };
            let t = evaluate(
                &taxel,
                &prepared.present,
                prepared.cols,
                Columns::EachTaxel,
                &split,
                params.knn,
            )?;
            let g = evaluate(
                &g3,
                &prepared.present,
                prepared.cols,
                Columns::All,
                &split,
                params.knn,
            )?;
            r.e6.insert(
                sp,
                E6Speed {
                    train,
                    taxel_mean: t.accuracy,
                    glcm3d: g.accuracy,
                },
            );
        }
    }
    lap("e6", &mut r.timing_s);
    progress(Progress::Tick);

    // E7
    let sweep = prepared.isi.clone();
    let rate_hz = sweep
        .spikes
        .iter()
        .zip(&sweep.taxel_seconds)
        .map(|(s, t)| {
            s.iter()
                .zip(t)
                .map(|(&s, &t)| if t > 0.0 { s as f64 / t } else { 0.0 })
                .collect()
        })
        .collect();
    let median_isi_ms = sweep
        .counts
        .iter()
        .map(|per_label| {
            per_label
                .iter()
                .map(|h| {
                    let total: u64 = h.iter().sum();
                    let mut acc = 0;
                    h.iter()
                        .position(|&c| {
                            acc += c;
                            total > 0 && acc * 2 >= total
                        })
                        .map(|b| (b as f64 + 0.5) * f64::from(sweep.bin_ms))
                })
                .collect()
        })
        .collect();
    r.e7 = Some(E7 {
        speed: slowest_s,
        sweep,
        rate_hz,
        median_isi_ms,
    });
    lap("e7", &mut r.timing_s);
    progress(Progress::Tick);

    // E8
    for &sp in &speeds {
        let s = sp.mm_s();
        let (mut tm, mut gm) = (Vec::new(), Vec::new());
        let mut ks = Vec::new();
        for &k in &params.e8_ks {
            let knn = KnnParams { k, ..params.knn };
            match (
                ctx.cv(&taxel, Columns::EachTaxel, s, knn),
                ctx.cv(&g3, Columns::All, s, knn),
            ) {
                (Ok(t), Ok(g)) => {
                    ks.push(k);
                    tm.push(t.accuracy);
                    gm.push(g.accuracy);
                }
                (Err(e), _) | (_, Err(e)) => {
                    r.skipped
                        .insert(format!("e8 k={k} at {s} mm/s"), e.to_string());
                }
            }
        }
        r.e8.insert(
            sp,
            E8Speed {
                k: ks,
                taxel_mean: tm,
                glcm3d: gm,
            },
        );
    }
    lap("e8", &mut r.timing_s);
    progress(Progress::Tick);

    // E0
    let pick = |want: &str| {
        labels
            .iter()
            .find(|l| l.eq_ignore_ascii_case(want))
            .cloned()
    };
    let chosen: Vec<String> = match (pick("SB"), pick("STF")) {
        (Some(a), Some(b)) => vec![a, b],
        _ => labels.iter().take(2).cloned().collect(),
    };
    let taxel_cell =
        if prepared.present.len() > prepared.cols + 1 && prepared.present[prepared.cols + 1] {
            prepared.cols + 1
        } else {
            taxels[0]
        };
    let psth_bin = params.pipeline.volume.bin_ms;
    let examples = chosen
        .iter()
        .filter_map(|label| slow.iter().find(|e| &e.meta.label == label))
        .map(|e| {
            let train = e.spikes.train(taxel_cell);
            let mut psth = vec![0u32; e.spikes.n_steps.div_ceil(psth_bin)];
            for &t in train {
                psth[t as usize / psth_bin] += 1;
            }
            let vol =
                crate::features::RateVolume::from_spikes(&e.spikes, params.pipeline.volume.bin_ms);
            let volume = vol
                .map(|v| v.data.chunks(v.bins).map(|c| c.to_vec()).collect())
                .unwrap_or_default();
            E0Example {
                label: e.meta.label.clone(),
                file: e.meta.file.clone(),
                psth,
                volume,
            }
        })
        .collect();
    r.e0 = Some(E0 {
        speed: slowest_s,
        taxel: [taxel_cell / prepared.cols, taxel_cell % prepared.cols],
        psth_bin_ms: psth_bin,
        examples,
    });
    lap("e0", &mut r.timing_s);
    Ok(r)
}

/// A permutation of the cells that moves `n` randomly chosen taxels: their positions are
/// shuffled among themselves and then rotated by one, so every chosen taxel lands on a
/// cell that was another's.
fn perturbation(taxels: &[usize], cells: usize, n: usize, rng: &mut ChaCha8Rng) -> Vec<usize> {
    let mut perm: Vec<usize> = (0..cells).collect();
    let chosen: Vec<usize> = taxels.choose_multiple(rng, n).copied().collect();
    for (k, &from) in chosen.iter().enumerate() {
        perm[from] = chosen[(k + 1) % chosen.len()];
    }
    perm
}
