//! Causal classification (the paper's own drawback: "its reliance on whole spike trains
//! making it inherently non real-time"): a decision at every rate-volume bin from what has
//! been sensed so far, and the offline twin of [`crate::stream`].
//!
//! A causal model conditions with a forward-only filter and a resting value and scale
//! fixed at training ([`CausalConditioning`], set by [`calibrate_conditioning`]), so a
//! sample is conditioned the moment it arrives. At each bin boundary of an episode (a
//! contact, or a recording's selected phase) the model classifies the spike trains of the
//! current window: the last `window_ms` of the episode, or all of it while it is shorter.
//! A [`DecisionRule`] turns the per-bin classifications into one decision.
//!
//! [`episode_decisions`] computes all of this from a whole encoded recording at once;
//! `neurotex_stream::StreamClassifier` computes it frame by frame. Both run the same
//! conditioning arithmetic, the same neurons and the same feature extractor on the same
//! windows, so their decisions are identical (tests/stream.rs).

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::{ParamError, Result};
use crate::model::Model;
use crate::pipeline::{Encoded, PipelineParams};
use crate::recording::{Baseline, Recording};
use crate::signal::{baseline_offsets, relative_times, CausalConditioning, Preprocessor};
use crate::snn::Windowed;
use crate::spiking_model::{decide, spike_input, SpikingModel};

/// The default share of the vote a label needs in a bin to count towards a decision: four
/// of KNN's five neighbours. A choice, not fitted to any accuracy.
pub const DEFAULT_DECIDE_SHARE: f64 = 0.8;

/// The default number of consecutive bins that must agree: 3 bins of 200 ms, 0.6 s. A
/// choice, not fitted to any accuracy.
pub const DEFAULT_DECIDE_BINS: usize = 3;

/// Why a model of the `spectrum` method neither streams nor runs `predict --causal`.
pub const NO_RUNNING_SPECTRUM: &str = "the spectrum method transforms a whole span of the slide at once and has no running form for a stream's growing windows; train the stream's model with another method";

/// When the per-bin classifications of an episode become a decision.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DecisionRule {
    /// The share of the vote (KNN: neighbours; forest: mean leaf share; linear:
    /// probability) the bin's label needs, in (0, 1].
    pub share: f64,
    /// The number of consecutive bins with the same label at that share.
    pub bins: usize,
}

impl Default for DecisionRule {
    fn default() -> Self {
        DecisionRule {
            share: DEFAULT_DECIDE_SHARE,
            bins: DEFAULT_DECIDE_BINS,
        }
    }
}

impl DecisionRule {
    /// Checks the rules: a share in (0, 1], between 1 and 10 000 bins.
    ///
    /// # Errors
    /// The rule broken.
    pub fn check(&self) -> Result<(), ParamError> {
        if !(self.share > 0.0 && self.share <= 1.0) {
            return Err(ParamError::new(
                "decide",
                "the decision share must be in (0, 1]",
                self.share,
            ));
        }
        if !(1..=10_000).contains(&self.bins) {
            return Err(ParamError::new(
                "decide-bins",
                "the decision needs between 1 and 10000 consecutive bins",
                self.bins,
            ));
        }
        Ok(())
    }
}

/// The decision rule's state over one episode.
#[derive(Debug, Clone, PartialEq)]
pub struct Decider {
    rule: DecisionRule,
    run_class: Option<usize>,
    run: usize,
    decision: Option<(usize, f64)>,
}

impl Decider {
    /// A fresh episode.
    pub fn new(rule: DecisionRule) -> Self {
        Decider {
            rule,
            run_class: None,
            run: 0,
            decision: None,
        }
    }

    /// Takes one bin's classification at `t_s` (its class and that class's share) and
    /// returns whether the episode is decided. The first decision stands for the rest of
    /// the episode.
    pub fn observe(&mut self, t_s: f64, class: usize, share: f64) -> bool {
        if share >= self.rule.share {
            self.run = if self.run_class == Some(class) {
                self.run + 1
            } else {
                1
            };
            self.run_class = Some(class);
        } else {
            self.run = 0;
            self.run_class = None;
        }
        if self.decision.is_none() && self.run >= self.rule.bins {
            self.decision = Some((class, t_s));
        }
        self.decision.is_some()
    }

    /// The decided class and the time it was decided at, once decided.
    pub fn decision(&self) -> Option<(usize, f64)> {
        self.decision
    }
}

/// One bin's classification.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BinDecision {
    /// The bin boundary, in s from the episode's start.
    pub t_s: f64,
    /// The predicted class, an index into [`Model::labels`].
    pub class: usize,
    /// Each class's share, in the order of [`Model::labels`].
    pub shares: Vec<f64>,
    /// Whether the episode is decided at this bin (and from now on).
    pub decided: bool,
    /// The decided class, once decided.
    pub decision: Option<usize>,
}

/// Why an episode ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EpisodeEnd {
    /// The recording or the input ended.
    EndOfInput,
    /// A reset frame or a call to reset.
    Reset,
    /// The signal stayed at rest (onset episodes).
    Rest,
    /// The time stamps jumped, ahead by more than the largest gap allowed or back, and the
    /// next frame followed the jump (or the episode reached its longest length, 49 days).
    Gap,
    /// The stream was stopped before its input ended (an interrupt).
    Stopped,
}

/// The end of an episode.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EpisodeSummary {
    /// The episode's length at 1 kHz, s.
    pub duration_s: f64,
    /// The classification of the whole episode (its last `window_ms` when longer); `None`
    /// when it is shorter than one bin.
    pub class: Option<usize>,
    /// That classification's shares.
    pub shares: Option<Vec<f64>>,
    /// The decided class, if the rule held in some bin.
    pub decision: Option<usize>,
    /// When the rule first held, s from the episode's start.
    pub decided_at_s: Option<f64>,
    /// Bins classified.
    pub bins: usize,
    /// Why the episode ended.
    pub ended_by: EpisodeEnd,
}

/// An episode's decisions: one per bin, and the summary.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Episode {
    /// One classification per bin boundary.
    pub bins: Vec<BinDecision>,
    /// The end.
    pub summary: EpisodeSummary,
}

impl Episode {
    /// Whether a decision came before the episode's end.
    pub fn decided(&self) -> bool {
        self.summary.decision.is_some()
    }
}

/// The window length in steps for `window_ms`, rounded up to whole bins (at least one): a
/// window of the training recordings' median length covers a recording of that length
/// whole, as the classifier saw it in training, when the length is not a whole number of
/// bins.
pub fn window_steps(window_ms: usize, bin_ms: usize) -> usize {
    window_ms.div_ceil(bin_ms).max(1) * bin_ms
}

/// The offline twin of `neurotex_stream::StreamClassifier`: the decisions at every bin
/// boundary of one causally encoded recording (the episode: its selected phase), each over
/// the last `window_ms` (rounded up to whole bins) or all the episode so far, and the summary.
///
/// # Errors
/// A model that is not causal is not refused here (its decisions are those of its own
/// pipeline); a recording on another grid; features that cannot be computed.
pub fn episode_decisions(
    model: &Model,
    encoded: &Encoded,
    window_ms: usize,
    rule: DecisionRule,
) -> Result<Episode> {
    rule.check()?;
    let bin = model.params().volume.bin_ms;
    let window = window_steps(window_ms, bin);
    let n = encoded.spikes.n_steps;
    let mut decider = Decider::new(rule);
    let mut bins = Vec::with_capacity(n / bin);
    for end in (1..=n / bin).map(|b| b * bin) {
        let start = end.saturating_sub(window);
        let p = model.predict_one(&encoded.map_spikes(|s| s.window(start, end)))?;
        let class = model.class_index(&p.predicted);
        let t_s = end as f64 / 1000.0;
        let decided = decider.observe(t_s, class, p.shares[class]);
        bins.push(BinDecision {
            t_s,
            class,
            shares: p.shares,
            decided,
            decision: decider.decision().map(|d| d.0),
        });
    }
    let whole = n.min(window);
    let last = match whole >= bin {
        true => Some(model.predict_one(&encoded.map_spikes(|s| s.window(n - whole, n)))?),
        false => None,
    };
    let summary = EpisodeSummary {
        duration_s: n as f64 / 1000.0,
        class: last.as_ref().map(|p| model.class_index(&p.predicted)),
        shares: last.map(|p| p.shares),
        decision: decider.decision().map(|d| d.0),
        decided_at_s: decider.decision().map(|d| d.1),
        bins: bins.len(),
        ended_by: EpisodeEnd::EndOfInput,
    };
    Ok(Episode { bins, summary })
}

/// The offline twin of a stream run by a spiking network: the network runs over the whole
/// causally encoded recording, its time steps of `dt` ms completed as the 1 ms steps reach
/// them; at each bin boundary its class scores over the last `window_ms` (rounded up to whole bins, at
/// least one network step) or all of the episode so far give the bin's classification,
/// the shares being their softmax. At the end the last partial time step is run, as
/// [`SpikingModel::predict`] runs it, and the summary reads the scores over the last window:
/// a recording shorter than the window gets `predict`'s shares.
///
/// # Errors
/// A rule out of range, or a recording on another grid than the model's.
pub fn spiking_episode_decisions(
    model: &SpikingModel,
    encoded: &Encoded,
    window_ms: usize,
    rule: DecisionRule,
) -> Result<Episode> {
    rule.check()?;
    model.check_grid(encoded)?;
    let bin = model.pipeline_params().volume.bin_ms;
    let net = model.network();
    // A stream knows no speed: a network counting time in travel steps every `dt_ms`, as
    // for a slide at its reference speed, here as live.
    let dt = net.dt_ms as usize;
    let input = spike_input(encoded, f64::from(net.dt_ms));
    let mut run = Windowed::new(net, network_window(window_ms, bin, dt));
    let n = encoded.spikes.n_steps;
    let mut decider = Decider::new(rule);
    let mut bins = Vec::with_capacity(n / bin);
    for end in (1..=n / bin).map(|b| b * bin) {
        while run.steps() < end / dt {
            run.step(net, input.at(run.steps()));
        }
        let (class, shares) = decide(&run.scores(net));
        let t_s = end as f64 / 1000.0;
        let decided = decider.observe(t_s, class, shares[class]);
        bins.push(BinDecision {
            t_s,
            class,
            shares,
            decided,
            decision: decider.decision().map(|d| d.0),
        });
    }
    while run.steps() < input.steps() {
        run.step(net, input.at(run.steps()));
    }
    let last = (n.min(window_steps(window_ms, bin)) >= bin).then(|| decide(&run.scores(net)));
    let summary = EpisodeSummary {
        duration_s: n as f64 / 1000.0,
        class: last.as_ref().map(|l| l.0),
        shares: last.map(|l| l.1),
        decision: decider.decision().map(|d| d.0),
        decided_at_s: decider.decision().map(|d| d.1),
        bins: bins.len(),
        ended_by: EpisodeEnd::EndOfInput,
    };
    Ok(Episode { bins, summary })
}

/// The window of a spiking network's scores in its time steps of `dt_ms`: the window of
/// `window_ms` rounded up to whole bins, at least one step.
pub fn network_window(window_ms: usize, bin_ms: usize, dt_ms: usize) -> usize {
    (window_steps(window_ms, bin_ms) / dt_ms).max(1)
}

/// What [`calibrate_conditioning`] found.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ConditioningCalibration {
    /// The fixed resting values and scale.
    pub conditioning: CausalConditioning,
    /// Recordings used.
    pub recordings: usize,
    /// The median length of their selected phases at 1 kHz, ms: the default window of a
    /// stream (the classifier was trained on features of slides about this long).
    pub median_duration_ms: usize,
    /// How far the recordings' own resting values spread around the fixed ones, in units
    /// of the scale: per taxel the 10th to 90th percentile over the recordings, the median
    /// taxel. From 1 on, a fixed resting value leaves some recordings silent and others
    /// at the ceiling ([`PreprocessParams::drift_window_ms`] tracks it instead).
    ///
    /// [`PreprocessParams::drift_window_ms`]: crate::signal::PreprocessParams::drift_window_ms
    #[serde(default)]
    pub rest_spread: f64,
}

/// [`ConditioningCalibration::rest_spread`] of the recordings' resting values
/// `per_recording` (one per cell each, 0 in every recording for a cell without a taxel)
/// over `scale`.
fn rest_spread(per_recording: &[Vec<f64>], scale: f64) -> f64 {
    let cells = per_recording.first().map_or(0, Vec::len);
    let spreads: Vec<f64> = (0..cells)
        .filter(|&c| per_recording.iter().any(|o| o[c] != 0.0))
        .map(|c| {
            let mut values: Vec<f64> = per_recording.iter().map(|o| o[c]).collect();
            values.sort_by(f64::total_cmp);
            let at = |q: f64| values[((values.len() - 1) as f64 * q).round() as usize];
            at(0.9) - at(0.1)
        })
        .collect();
    match per_recording.len() >= 2 && !spreads.is_empty() {
        true => median(spreads) / scale,
        false => 0.0,
    }
}

/// Fixes causal conditioning on the training recordings `indices` (loaded by `load`),
/// labels unused:
/// - each cell's resting value is the median, over the recordings, of the value the
///   offline baseline would subtract from that recording (`baseline`, or the parameters'
///   own; zeros for `none`);
/// - the scale is the median, over the recordings with any positive signal, of the
///   largest value of the causally filtered, offset-free selected phase: the divisor the
///   offline pipeline would use for a typical recording. A recording unlike the training
///   ones may then exceed 1 (the neuron takes any input current); a median, not a maximum,
///   so that one unusual recording does not shrink every other's drive.
///
/// # Errors
/// No recording, a recording that cannot be loaded or conditioned, recordings of
/// different grids, or no positive signal in any of them.
pub fn calibrate_conditioning(
    params: &PipelineParams,
    load: &(dyn Fn(usize) -> Result<Recording> + Sync),
    indices: &[usize],
    dataset_baseline: Baseline,
) -> Result<ConditioningCalibration> {
    if indices.is_empty() {
        let rule = "causal conditioning is calibrated on at least one training recording";
        return Err(ParamError::new("causal", rule, "none").into());
    }
    let baseline = params.preprocess.baseline.unwrap_or(dataset_baseline);
    // Without a baseline every recording's resting values are zeros, so one recording
    // gives the grid's size and the others need not be loaded twice (a recording of
    // another grid is still refused, by the conditioning below).
    let first_only = match baseline {
        Baseline::None => &indices[..1],
        _ => indices,
    };
    let per_recording: Vec<Vec<f64>> = first_only
        .par_iter()
        .map(|&i| {
            let rec = load(i)?;
            let offsets = baseline_offsets(&rec, &relative_times(&rec), baseline)?;
            Ok(offsets
                .into_iter()
                .zip(&rec.layout.present)
                .map(|(o, &p)| if p { o } else { 0.0 })
                .collect())
        })
        .collect::<Result<_>>()?;
    let cells = per_recording[0].len();
    if per_recording.iter().any(|o| o.len() != cells) {
        let rule = "causal conditioning needs recordings of one grid";
        return Err(ParamError::new("causal", rule, "several grids").into());
    }
    let offsets: Vec<f64> = (0..cells)
        .map(|c| median(per_recording.iter().map(|o| o[c]).collect()))
        .collect();
    let mut unscaled = params.preprocess.clone();
    unscaled.causal = Some(CausalConditioning {
        offsets: offsets.clone(),
        scale: 1.0,
    });
    let preprocessor = Preprocessor::new(&unscaled)?;
    let maxima: Vec<(f64, usize)> = indices
        .par_iter()
        .map(|&i| {
            let cond = preprocessor.apply(&load(i)?, baseline)?;
            let max = cond
                .samples
                .iter()
                .copied()
                .fold(f64::NEG_INFINITY, f64::max);
            Ok((max, cond.n_steps()))
        })
        .collect::<Result<_>>()?;
    let positive: Vec<f64> = maxima.iter().map(|m| m.0).filter(|&m| m > 0.0).collect();
    if positive.is_empty() {
        let rule = "causal conditioning needs some positive signal in the training recordings";
        return Err(ParamError::new("causal", rule, "every recording is flat").into());
    }
    let durations: Vec<f64> = maxima.iter().map(|m| m.1 as f64).collect();
    let scale = median(positive);
    Ok(ConditioningCalibration {
        rest_spread: rest_spread(&per_recording, scale),
        conditioning: CausalConditioning { offsets, scale },
        recordings: indices.len(),
        median_duration_ms: median(durations) as usize,
    })
}

/// The median (the mean of the two middle values for an even count) of a non-empty list.
fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    match n % 2 {
        1 => values[n / 2],
        _ => 0.5 * (values[n / 2 - 1] + values[n / 2]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_decision_needs_consecutive_confident_bins_and_then_stands() {
        let rule = DecisionRule {
            share: 0.8,
            bins: 3,
        };
        let mut d = Decider::new(rule);
        // confident, confident, unsure (breaks the run), then three confident: decided at
        // the sixth bin; a later change of label does not undo it.
        let seen = [(0, 1.0), (0, 0.8), (0, 0.6), (1, 0.8), (1, 1.0), (1, 0.8)];
        let decided: Vec<bool> = seen
            .iter()
            .enumerate()
            .map(|(i, &(c, s))| d.observe(i as f64, c, s))
            .collect();
        assert_eq!(decided, [false, false, false, false, false, true]);
        assert_eq!(d.decision(), Some((1, 5.0)));
        assert!(d.observe(6.0, 0, 1.0));
        assert_eq!(d.decision(), Some((1, 5.0)));
    }

    #[test]
    fn a_change_of_label_restarts_the_run() {
        let mut d = Decider::new(DecisionRule {
            share: 0.5,
            bins: 2,
        });
        assert!(!d.observe(0.2, 0, 1.0));
        assert!(!d.observe(0.4, 1, 1.0));
        assert!(d.observe(0.6, 1, 0.6));
        assert_eq!(d.decision(), Some((1, 0.6)));
    }

    #[test]
    fn rule_bounds() {
        for (share, bins) in [(0.0, 3), (1.01, 3), (f64::NAN, 3), (0.8, 0), (0.8, 10_001)] {
            assert!(
                DecisionRule { share, bins }.check().is_err(),
                "{share} {bins}"
            );
        }
        assert!(DecisionRule::default().check().is_ok());
    }

    /// Windows are whole bins, rounded up: a recording of the window's length fits in it.
    #[test]
    fn windows_are_whole_bins_rounded_up() {
        assert_eq!(window_steps(18_000, 200), 18_000);
        assert_eq!(window_steps(18_150, 200), 18_200);
        assert_eq!(window_steps(3_499, 200), 3_600);
        assert_eq!(window_steps(50, 200), 200);
        assert_eq!(network_window(3_499, 200, 10), 360);
    }

    #[test]
    fn median_of_odd_and_even_lists() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(vec![4.0, 1.0, 2.0, 3.0]), 2.5);
    }
}
