//! E5c (beyond the paper; docs/analyses.md): online time to recognition. The paper's
//! 3D-GLCM + KNN with causal conditioning, classifying at every bin boundary from the slide
//! so far, as `neurotex stream` does; beside the offline E5, and the accuracy the causal
//! pipeline costs against the paper's zero-phase one on the same folds.
//!
//! Each speed's causal conditioning (forward-only low-pass, resting values and scale) is
//! fixed on all of that speed's recordings, labels unused ([`super::prepare`]): every one
//! of them is in some training fold, and fixing it inside each fold would encode every
//! recording once per fold. The classifier of each fold of E1's cross-validation is trained
//! on whole causal slides (a live classifier does not know how far into the slide it is)
//! and applied to each test recording's growing window.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::tables::cv_at;
use super::{compare_shares, Comparison, Context, E5Speed, Skip, Stop};
use crate::analysis::{seeded_bootstrap, Columns, FeatureTable, OutOfFold, Outcome};
use crate::causal::{ConditioningCalibration, Decider, DecisionRule};
use crate::classify::{Classifier, Interval, Knn, KnnModel, Predict};
use crate::error::Result;
use crate::pipeline::{Encoded, FeatureExtractor, Method};
use crate::values::{BySpeed, Speed};

/// The accuracy at one share of the slide, causal beside offline.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct E5cFraction {
    /// The share of each slide.
    pub fraction: f64,
    /// That share of the median slide, s.
    pub time_s: f64,
    /// Causal: each test recording classified at the last bin boundary within that share
    /// of its own slide by the whole-slide classifier; `None` when some share is shorter
    /// than one bin.
    pub causal: Option<f64>,
    /// 95 % interval of `causal` (bootstrap over recordings, each recording's repeats
    /// kept together).
    #[serde(default)]
    pub causal_interval: Option<Interval>,
    /// The offline E5 at that share (trained and tested on the first part of the slides).
    pub offline: Option<f64>,
    /// E5's 95 % interval of `offline`.
    #[serde(default)]
    pub offline_interval: Option<Interval>,
}

/// The time to decision under a [`DecisionRule`], over every test recording of every CV
/// repeat.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TimeToDecision {
    /// The rule.
    pub rule: DecisionRule,
    /// Recordings x repeats.
    pub episodes: usize,
    /// Episodes decided before the slide ended.
    pub decided: usize,
    /// Share of episodes never decided.
    pub never_share: f64,
    /// Share of the decisions made that were right; `None` when none was made.
    pub accuracy: Option<f64>,
    /// Quartiles (25, 50, 75 %) of the time to decision over the decided episodes, s into
    /// the slide; `None` when none was decided.
    pub quartiles_s: Option<[f64; 3]>,
    /// Share of all episodes decided by each of [`E5CausalSpeed::times_s`].
    pub decided_by: Vec<f64>,
}

/// E5c at one speed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct E5CausalSpeed {
    /// The resting values and scale, fixed on all of this speed's recordings (labels unused).
    pub calibration: ConditioningCalibration,
    /// Recordings.
    pub n: usize,
    /// Chance by guessing uniformly among the classes recorded at this speed.
    pub chance: f64,
    /// The median slide, s.
    pub median_slide_s: f64,
    /// Bin boundaries, s into the slide.
    pub times_s: Vec<f64>,
    /// Causal 3D-GLCM accuracy at each time, pooled over E1's CV repeats; a slide that has
    /// ended counts with its whole-slide classification.
    pub accuracy: Vec<f64>,
    /// Share of the recordings still sliding at each time.
    pub sliding: Vec<f64>,
    /// Causal beside offline at E5's shares of the slide.
    pub fractions: Vec<E5cFraction>,
    /// Causal 3D-GLCM on whole slides (E1's folds and repeats).
    pub whole: f64,
    /// Its 95 % interval (bootstrap over recordings).
    pub whole_interval: Interval,
    /// The paper's zero-phase 3D-GLCM (E1).
    pub offline: f64,
    /// Zero-phase (E1) against causal on the same recordings and folds: the accuracy the
    /// causal pipeline costs.
    pub offline_vs_causal: Comparison,
    /// The time to decision.
    pub decision: TimeToDecision,
}

/// One test recording in one CV repeat.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Trace {
    /// Its index among the speed's recordings.
    pub(crate) recording: usize,
    /// The repeat.
    pub(crate) repeat: usize,
    /// Its class.
    pub(crate) truth: usize,
    /// The class and that class's share at every bin boundary of its slide.
    pub(crate) bins: Vec<(usize, f64)>,
    /// Its whole-slide class.
    pub(crate) whole: usize,
    /// The decided class and time, s.
    pub(crate) decision: Option<(usize, f64)>,
}

/// One speed's recordings through the causal pipeline, their whole-slide evaluation and
/// every test recording's trace.
pub(crate) struct SpeedRun {
    /// The speed's labels, in the order of the classes.
    pub(crate) labels: Vec<String>,
    /// Its recordings' rows in the tables (and in [`super::Prepared::encoded`]).
    pub(crate) rows: Vec<usize>,
    /// The whole-slide cross-validation, rows indexing the speed's recordings.
    pub(crate) outcome: Outcome,
    /// Each recording's slide, steps.
    pub(crate) steps: Vec<usize>,
    /// Traces, repeat by repeat.
    pub(crate) traces: Vec<Trace>,
}

/// E5c at every speed where the causal conditioning could be fixed (the others are skipped
/// with the reason); nothing when the run has no causal recordings.
///
/// # Errors
/// A classification that cannot run.
pub fn e5_causal(
    c: &Context,
    e5: &BySpeed<E5Speed>,
) -> Result<(BySpeed<E5CausalSpeed>, Vec<Skip>), Stop> {
    let mut out = BySpeed::new();
    let mut skipped = Vec::new();
    let Some(causal) = &c.prepared.causal else {
        return Ok((out, skipped));
    };
    let rule = DecisionRule::default();
    for (speed, calibration) in causal.calibration.iter() {
        let calibration = match calibration {
            Ok(cal) => cal.clone(),
            Err(reason) => {
                let reason = format!("causal conditioning at {speed} mm/s: {reason}");
                skipped.push(Skip::Causal { speed, reason });
                continue;
            }
        };
        let run = speed_run(c, speed, rule)?;
        out.insert(
            speed,
            summarise(c, speed, calibration, &run, e5.get(speed), rule)?,
        );
    }
    Ok((out, skipped))
}

/// The causal evaluation at `speed`: whole slides by E1's cross-validation, then every
/// test recording's growing window classified at each bin by its fold's classifier.
pub(crate) fn speed_run(c: &Context, speed: Speed, rule: DecisionRule) -> Result<SpeedRun> {
    let (rows, encoded) = speed_recordings(c, speed);
    let extractor = extractor(c, &encoded)?;
    let owned: Vec<Encoded> = encoded.iter().map(|&e| e.clone()).collect();
    let table = FeatureTable::build(&owned, &extractor, Method::Glcm3d)?;
    let outcome = cv_at(
        &table,
        Columns::All,
        speed,
        c.params.knn(),
        c.params.folds(),
    )?;
    let bin = c.params.pipeline.volume.bin_ms;
    let windows = growing_windows(&owned, &extractor, bin)?;
    let labels = outcome.labels.clone();
    let truth = classes(&table, &labels);
    let episodes = Episodes {
        knn: c.params.knn(),
        table: &table,
        truth: &truth,
        windows: &windows,
        bin,
        rule,
    };
    let traces = episodes.every_repeat(outcome.predictions.as_deref().unwrap_or_default())?;
    Ok(SpeedRun {
        labels,
        rows,
        outcome,
        steps: owned.iter().map(|e| e.spikes.n_steps).collect(),
        traces,
    })
}

/// The rows (in [`super::Prepared::encoded`]) and causal encodings of the recordings at
/// `speed` that have a causal encoding.
fn speed_recordings<'a>(c: &Context<'a>, speed: Speed) -> (Vec<usize>, Vec<&'a Encoded>) {
    let causal = c.prepared.causal.as_ref().map(|p| &p.encoded);
    (0..c.prepared.encoded.len())
        .filter(|&i| c.prepared.encoded[i].meta.speed() == Some(speed))
        .filter_map(|i| causal.and_then(|all| all[i].as_ref()).map(|e| (i, e)))
        .unzip()
}

/// Each recording's 3D-GLCM features at every bin boundary of its slide so far, one row
/// per boundary, end to end.
fn growing_windows(
    encoded: &[Encoded],
    extractor: &FeatureExtractor,
    bin: usize,
) -> Result<Vec<Vec<f64>>> {
    encoded
        .par_iter()
        .map(|e| {
            let ends = (1..=e.spikes.n_steps / bin).map(|b| b * bin);
            let rows = ends
                .map(|end| extractor.row(&e.map_spikes(|s| s.window(0, end)), Method::Glcm3d))
                .collect::<Result<Vec<_>>>()?;
            Ok(rows.concat())
        })
        .collect()
}

/// Each row's class in `table`, as an index into `labels`.
fn classes(table: &FeatureTable, labels: &[String]) -> Vec<usize> {
    table
        .metas
        .iter()
        .map(|m| labels.iter().position(|l| *l == m.label).unwrap_or(0))
        .collect()
}

/// What the folds' classifiers need to trace their test recordings: the whole-slide table,
/// each recording's class and growing-window features, the bin and the decision rule.
struct Episodes<'a> {
    /// The classifier trained in each fold.
    knn: &'a Knn,
    /// The whole-slide features, one row per recording.
    table: &'a FeatureTable,
    /// Each recording's class.
    truth: &'a [usize],
    /// Each recording's features at every bin boundary ([`growing_windows`]).
    windows: &'a [Vec<f64>],
    /// The bin, ms.
    bin: usize,
    /// The decision rule.
    rule: DecisionRule,
}

impl Episodes<'_> {
    /// Every test recording's trace in each CV repeat of `predictions`, repeat by repeat.
    fn every_repeat(&self, predictions: &[OutOfFold]) -> Result<Vec<Trace>> {
        let repeats = predictions.iter().map(|p| p.repeat + 1).max().unwrap_or(0);
        let traces: Vec<Vec<Trace>> = (0..repeats)
            .into_par_iter()
            .map(|repeat| self.repeat(predictions, repeat))
            .collect::<Result<_>>()?;
        Ok(traces.concat())
    }

    /// The test recordings' traces in one CV repeat, fold by fold.
    fn repeat(&self, predictions: &[OutOfFold], repeat: usize) -> Result<Vec<Trace>> {
        let mut fold_of = vec![None; self.windows.len()];
        for p in predictions.iter().filter(|p| p.repeat == repeat) {
            fold_of[p.row] = p.fold;
        }
        let folds = fold_of.iter().flatten().max().map_or(0, |f| f + 1);
        let mut traces = Vec::new();
        for fold in 0..folds {
            traces.extend(self.fold(&fold_of, fold, repeat)?);
        }
        Ok(traces)
    }

    /// Trains on the recordings outside `fold` and traces the recordings in it.
    fn fold(&self, fold_of: &[Option<usize>], fold: usize, repeat: usize) -> Result<Vec<Trace>> {
        let recordings = 0..fold_of.len();
        let train: Vec<usize> = recordings
            .clone()
            .filter(|&i| fold_of[i] != Some(fold))
            .collect();
        let x: Vec<f64> = train
            .iter()
            .flat_map(|&i| self.table.row(i))
            .copied()
            .collect();
        let y: Vec<usize> = train.iter().map(|&i| self.truth[i]).collect();
        let model = self.knn.fit(&x, self.table.dims(), &y)?;
        Ok(recordings
            .filter(|&i| fold_of[i] == Some(fold))
            .map(|i| self.trace(&model, i, repeat))
            .collect())
    }

    /// One test recording's class at every bin boundary, its whole-slide class and its
    /// decision, by its fold's `model`.
    fn trace(&self, model: &KnnModel, recording: usize, repeat: usize) -> Trace {
        let bins: Vec<(usize, f64)> = model
            .predict_with_shares(&self.windows[recording])
            .into_iter()
            .map(|(class, shares)| (class, shares[class]))
            .collect();
        let mut decider = Decider::new(self.rule);
        for (b, &(class, share)) in bins.iter().enumerate() {
            decider.observe(((b + 1) * self.bin) as f64 / 1000.0, class, share);
        }
        Trace {
            recording,
            repeat,
            truth: self.truth[recording],
            whole: model.predict(self.table.row(recording))[0],
            decision: decider.decision(),
            bins,
        }
    }
}

/// The 3D-GLCM extractor of the causal recordings (SA, the pipeline's volume and GLCM).
fn extractor(c: &Context, encoded: &[&Encoded]) -> Result<FeatureExtractor> {
    let mut params = c.params.pipeline().params().clone();
    params.encoding = crate::pipeline::Encoding::Sa;
    let grid = match encoded.first() {
        Some(e) => e.spikes.grid(),
        None => c.prepared.grid.clone(),
    };
    Ok(FeatureExtractor::new(&params, &grid)?)
}

/// E5c's numbers at one speed from its run.
fn summarise(
    c: &Context,
    speed: Speed,
    calibration: ConditioningCalibration,
    run: &SpeedRun,
    e5: Option<&E5Speed>,
    rule: DecisionRule,
) -> Result<E5CausalSpeed> {
    let bin = c.params.pipeline.volume.bin_ms;
    let most_bins = run.steps.iter().map(|s| s / bin).max().unwrap_or(0);
    let times_s: Vec<f64> = (1..=most_bins).map(|b| (b * bin) as f64 / 1000.0).collect();
    let median_steps = run.median_steps();
    let fractions = match e5 {
        Some(e5) => run.fractions(e5, bin, median_steps, c.params.seed)?,
        None => Vec::new(),
    };
    let decision = run.time_to_decision(rule, &times_s);
    let offline = &c.tables.at(speed).glcm3d;
    let classes = run.labels.len().max(1);
    Ok(E5CausalSpeed {
        calibration,
        n: run.steps.len(),
        chance: 1.0 / classes as f64,
        median_slide_s: median_steps / 1000.0,
        times_s,
        accuracy: run.accuracy(most_bins),
        sliding: run.sliding(most_bins, bin),
        fractions,
        whole: run.outcome.accuracy,
        whole_interval: run.outcome.accuracy_interval(c.params.seed)?,
        offline: offline.accuracy,
        offline_vs_causal: compare_shares(
            ("zero-phase 3D-GLCM", &offline.correct_shares),
            ("causal 3D-GLCM", &run.causal_shares()),
            c.params,
        )?,
        decision,
    })
}

impl Trace {
    /// The class at bin boundary `b` (from 1); a slide that has ended keeps its whole-slide
    /// classification.
    fn class_at(&self, b: usize) -> usize {
        self.bins.get(b - 1).map_or(self.whole, |x| x.0)
    }
}

impl SpeedRun {
    /// The episodes (recordings x repeats), at least one: the shares' denominator.
    fn episodes(&self) -> f64 {
        self.traces.len().max(1) as f64
    }

    /// The share of episodes classified right at each bin boundary up to `most_bins`.
    fn accuracy(&self, most_bins: usize) -> Vec<f64> {
        (1..=most_bins)
            .map(|b| {
                let right = self.traces.iter().filter(|t| t.class_at(b) == t.truth);
                right.count() as f64 / self.episodes()
            })
            .collect()
    }

    /// The share of recordings still sliding at each bin boundary up to `most_bins`.
    fn sliding(&self, most_bins: usize, bin: usize) -> Vec<f64> {
        let n = self.steps.len();
        (1..=most_bins)
            .map(|b| self.steps.iter().filter(|&&s| s / bin >= b).count() as f64 / n.max(1) as f64)
            .collect()
    }

    /// The median slide, steps (0 without recordings).
    fn median_steps(&self) -> f64 {
        let n = self.steps.len();
        let mut durations: Vec<usize> = self.steps.clone();
        durations.sort_unstable();
        match n {
            0 => 0.0,
            _ if n % 2 == 1 => durations[n / 2] as f64,
            _ => 0.5 * (durations[n / 2 - 1] + durations[n / 2]) as f64,
        }
    }

    /// Causal beside offline at each of `e5`'s shares of the slide.
    fn fractions(
        &self,
        e5: &E5Speed,
        bin: usize,
        median_steps: f64,
        seed: u64,
    ) -> Result<Vec<E5cFraction>> {
        let mut out = Vec::new();
        for (i, (&p, &offline)) in e5.fractions.iter().zip(&e5.glcm3d).enumerate() {
            let (causal, causal_interval) = match self.right_at_share(p, bin) {
                Some(shares) => {
                    let right: f64 = shares.iter().map(|&(r, _)| r as f64).sum();
                    let all: usize = shares.iter().map(|&(_, n)| n).sum();
                    let per_recording: Vec<f64> = shares
                        .iter()
                        .filter(|&&(_, n)| n > 0)
                        .map(|&(r, n)| r as f64 / n as f64)
                        .collect();
                    (
                        Some(right / all.max(1) as f64),
                        Some(
                            seeded_bootstrap(&per_recording, seed)?
                                .or_wilson_at_the_bounds(per_recording.len()),
                        ),
                    )
                }
                None => (None, None),
            };
            out.push(E5cFraction {
                fraction: p,
                time_s: p * median_steps / 1000.0,
                causal,
                causal_interval,
                offline,
                offline_interval: e5.glcm3d_interval.get(i).cloned().flatten(),
            });
        }
        Ok(out)
    }

    /// Per recording, its episodes classified right at the last bin boundary within share
    /// `p` of its slide and its episodes; `None` when some share is shorter than one bin.
    fn right_at_share(&self, p: f64, bin: usize) -> Option<Vec<(usize, usize)>> {
        // The bins the offline E5 keeps of each slide: floor(p n) steps, whole bins.
        let at = |steps: usize| ((steps as f64) * p).floor() as usize / bin;
        if self.steps.iter().any(|&s| at(s) == 0) {
            return None;
        }
        let mut shares = vec![(0usize, 0usize); self.steps.len()];
        for t in &self.traces {
            let share = &mut shares[t.recording];
            share.1 += 1;
            if t.class_at(at(self.steps[t.recording])) == t.truth {
                share.0 += 1;
            }
        }
        Some(shares)
    }

    /// The time to decision under `rule`, with the share of episodes decided by each of
    /// `times_s`.
    fn time_to_decision(&self, rule: DecisionRule, times_s: &[f64]) -> TimeToDecision {
        let episodes = self.episodes();
        let decided: Vec<&Trace> = self
            .traces
            .iter()
            .filter(|t| t.decision.is_some())
            .collect();
        let mut when: Vec<f64> = decided
            .iter()
            .filter_map(|t| t.decision.map(|d| d.1))
            .collect();
        when.sort_by(f64::total_cmp);
        let quantile = |q: f64| when[((when.len() - 1) as f64 * q).round() as usize];
        TimeToDecision {
            rule,
            episodes: self.traces.len(),
            decided: decided.len(),
            never_share: 1.0 - decided.len() as f64 / episodes,
            accuracy: (!decided.is_empty()).then(|| {
                let right = decided
                    .iter()
                    .filter(|t| t.decision.map(|d| d.0) == Some(t.truth));
                right.count() as f64 / decided.len() as f64
            }),
            quartiles_s: (!when.is_empty())
                .then(|| [quantile(0.25), quantile(0.5), quantile(0.75)]),
            decided_by: times_s
                .iter()
                .map(|&t| when.partition_point(|&w| w <= t + 1e-9) as f64 / episodes)
                .collect(),
        }
    }

    /// Each recording's share of right whole-slide predictions, keyed by its row in the
    /// tables, so that the pairs with the zero-phase evaluation are the same recordings.
    fn causal_shares(&self) -> Vec<(usize, f64)> {
        self.outcome
            .correct_shares
            .iter()
            .map(|&(i, s)| (self.rows[i], s))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::super::testing::small_run;
    use super::*;
    use crate::causal::episode_decisions;
    use crate::classify::{ClassifierChoice, KnnParams};
    use crate::model::{Model, Provenance};
    use crate::recording::Baseline;

    #[test]
    fn the_last_bin_is_the_whole_slide_and_decisions_fall_on_bin_boundaries() {
        let run = small_run();
        let c = run.context();
        let e5 = super::super::e5_time_to_recognition(&c).unwrap();
        let (e5c, skipped) = e5_causal(&c, &e5).unwrap();
        assert!(skipped.is_empty());
        assert_eq!(e5c.len(), run.prepared.speeds.len());
        let bin_s = c.params.pipeline.volume.bin_ms as f64 / 1000.0;
        for (speed, e) in e5c.iter() {
            // Every slide has ended at the last time: the curve ends at the whole-slide
            // accuracy of the cross-validation.
            let last = *e.accuracy.last().unwrap();
            assert!(
                (last - e.whole).abs() < 1e-12,
                "{speed}: {last} vs {}",
                e.whole
            );
            assert_eq!(e.offline, c.tables.at(speed).glcm3d.accuracy);
            let diff = e.offline - e.whole;
            assert!((e.offline_vs_causal.difference - diff).abs() < 1e-12);
            let d = &e.decision;
            assert_eq!(d.episodes, e.n * c.params.cv.repeats);
            let never = (d.episodes - d.decided) as f64 / d.episodes as f64;
            assert!((d.never_share - never).abs() < 1e-12);
            assert!(d.decided_by.windows(2).all(|w| w[0] <= w[1]));
            let by_end = d.decided_by.last().copied().unwrap_or(0.0);
            assert!((by_end - d.decided as f64 / d.episodes as f64).abs() < 1e-12);
            for t in d.quartiles_s.iter().flatten() {
                let bins = t / bin_s;
                assert!((bins - bins.round()).abs() < 1e-9 && bins >= d.rule.bins as f64 - 1e-9);
            }
            assert_eq!(e.fractions.len(), e5.get(speed).unwrap().fractions.len());
        }
    }

    #[test]
    fn each_test_recording_is_classified_as_episode_decisions_classifies_it() {
        let run = small_run();
        let c = run.context();
        let speed = run.prepared.speeds[0];
        let rule = DecisionRule::default();
        let sr = speed_run(&c, speed, rule).unwrap();
        // E1's folds: the causal cross-validation assigns every recording the fold E1 did.
        let e1 = c.tables.at(speed).glcm3d.predictions.clone().unwrap();
        let causal = sr.outcome.predictions.clone().unwrap();
        assert_eq!(e1.len(), causal.len());
        for (a, b) in e1.iter().zip(&causal) {
            assert_eq!(
                (sr.rows[b.row], b.repeat, b.fold),
                (a.row, a.repeat, a.fold)
            );
        }
        // Fold 0 of repeat 0, through a saved model's path.
        let fold_of = |i: usize| {
            causal
                .iter()
                .find(|p| p.repeat == 0 && p.row == i)
                .unwrap()
                .fold
        };
        let n = sr.steps.len();
        let train: Vec<usize> = (0..n).filter(|&i| fold_of(i) != Some(0)).collect();
        let all = &c.prepared.causal.as_ref().unwrap().encoded;
        let encoded: Vec<Encoded> = sr.rows.iter().map(|&r| all[r].clone().unwrap()).collect();
        let train_encoded: Vec<Encoded> = train.iter().map(|&i| encoded[i].clone()).collect();
        let extractor = extractor(&c, &encoded.iter().collect::<Vec<_>>()).unwrap();
        let table = FeatureTable::build(&train_encoded, &extractor, Method::Glcm3d).unwrap();
        let calibration = match &c.prepared.causal.as_ref().unwrap().calibration.get(speed) {
            Some(Ok(cal)) => cal.clone(),
            _ => panic!("calibrated"),
        };
        let mut params = c.params.pipeline().params().clone();
        params.preprocess.causal = Some(calibration.conditioning);
        let knn: KnnParams = c.params.knn().params();
        let provenance = Provenance {
            fingerprint: "small design".into(),
            baseline: Baseline::None,
            speeds: Some(vec![speed]),
            gain_calibration: None,
            median_duration_ms: None,
            layout: None,
        };
        let model = Model::train(
            &params,
            &table,
            Columns::All,
            ClassifierChoice::Knn(knn),
            provenance,
        )
        .unwrap();
        let mut checked = 0;
        for t in sr.traces.iter().filter(|t| t.repeat == 0) {
            if fold_of(t.recording) != Some(0) {
                continue;
            }
            let episode =
                episode_decisions(&model, &encoded[t.recording], 3_600_000, rule).unwrap();
            assert_eq!(episode.bins.len(), t.bins.len());
            for (b, &(class, share)) in episode.bins.iter().zip(&t.bins) {
                assert_eq!(model.labels()[b.class], sr.labels[class]);
                assert_eq!(b.shares[b.class], share);
            }
            let decided = episode.summary.decision.zip(episode.summary.decided_at_s);
            let ours = t.decision.map(|(k, at)| (sr.labels[k].clone(), at));
            assert_eq!(decided.map(|(k, at)| (model.labels()[k].clone(), at)), ours);
            let whole = episode.summary.class.map(|k| model.labels()[k].clone());
            assert_eq!(whole, Some(sr.labels[t.whole].clone()));
            checked += 1;
        }
        assert!(checked > 0);
    }
}
