//! 95 % intervals for an accuracy: Wilson's score interval, the percentile bootstrap over
//! recordings (and over encodings), and Student's t over repeats.

use serde::{Deserialize, Serialize};

use crate::classify::draws::{for_each_resample, UniformIndices};
use crate::classify::stats::{percentile, student_t_quantile, StatsError, Z_95};
use crate::error::ParamError;

use super::LEVEL;

/// How an [`Interval`] was computed, with what it needs to be reproduced.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "method", rename_all = "snake_case")]
pub enum IntervalMethod {
    /// Wilson's score interval for `correct` of `n` ([`wilson_interval`]).
    Wilson {
        /// Correct predictions.
        correct: usize,
        /// Predictions.
        n: usize,
    },
    /// Percentile bootstrap over recordings ([`bootstrap_accuracy`]).
    PercentileBootstrap {
        /// Recordings resampled.
        n: usize,
        /// Bootstrap resamples.
        resamples: usize,
        /// The resampling generator's seed.
        seed: u64,
    },
    /// Percentile bootstrap over recordings and encodings
    /// ([`bootstrap_over_encodings`]).
    EncodingBootstrap {
        /// Recordings resampled.
        n: usize,
        /// Encodings of each recording, one drawn per resample.
        encodings: usize,
        /// Bootstrap resamples.
        resamples: usize,
        /// The resampling generator's seed.
        seed: u64,
    },
    /// Student's t over repeats ([`t_interval_over_repeats`]).
    StudentT {
        /// Repeats.
        repeats: usize,
        /// Whether a bound was clipped to [0, 1] (a sign of too few repeats).
        clipped: bool,
    },
}

/// A 95 % interval around an accuracy; `lower <= estimate <= upper`, all in [0, 1].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Interval {
    /// The point estimate.
    pub estimate: f64,
    /// Lower bound.
    pub lower: f64,
    /// Upper bound.
    pub upper: f64,
    /// Confidence level ([`LEVEL`]).
    pub level: f64,
    /// How it was computed.
    #[serde(flatten)]
    pub method: IntervalMethod,
}

impl Interval {
    /// An accuracy's bootstrap interval, or where it is a point at 0 or 1 (every recording
    /// right, or every one wrong, in every resample and encoding: no resample can differ)
    /// the [`wilson_interval`] of the `n` recordings: 12 of 12 right is [75.8 %, 100 %],
    /// not [100 %, 100 %]. Any other interval is returned as it is.
    pub fn or_wilson_at_the_bounds(self, n: usize) -> Interval {
        wilson_at_the_bounds(self.lower, self.upper, n).unwrap_or(self)
    }

    /// How the interval was computed, in a few words for a report or a terminal:
    /// `bootstrap over recordings`, `Wilson score over 12 recordings`.
    pub fn described(&self) -> String {
        match &self.method {
            IntervalMethod::Wilson { n, .. } => format!("Wilson score over {n} recordings"),
            IntervalMethod::PercentileBootstrap { .. } => "bootstrap over recordings".into(),
            IntervalMethod::EncodingBootstrap { .. } => {
                "bootstrap over recordings and encodings".into()
            }
            IntervalMethod::StudentT { repeats, .. } => {
                format!("Student t over {repeats} repeats")
            }
        }
    }
}

/// The [`wilson_interval`] of `n` units all right (or all wrong) when a bootstrap interval
/// of their accuracy, `[lower, upper]`, is a point at 1 (or 0): no resample can differ
/// there. `None` for any other interval, or no units.
pub fn wilson_at_the_bounds(lower: f64, upper: f64, n: usize) -> Option<Interval> {
    let point_at_a_bound = lower == upper && (lower == 0.0 || lower == 1.0);
    if !point_at_a_bound || n == 0 {
        return None;
    }
    wilson_interval(if lower == 1.0 { n } else { 0 }, n).ok()
}

/// The 95 % Wilson score interval for `correct` successes in `n` independent trials (Wilson
/// 1927, "Probable inference, the law of succession, and statistical inference", JASA 22):
/// the accuracies `p` that a two-sided score test at 5 % would not reject,
/// `(k + z²/2 ± z √(k(n-k)/n + z²/4)) / (n + z²)` with `z` = [`Z_95`].
///
/// Wilson rather than the normal (Wald) approximation `p̂ ± z √(p̂(1-p̂)/n)`: Wald's interval
/// has zero width at 0 % and 100 % accuracy, can leave [0, 1], and covers well below 95 %
/// for the tens of recordings and accuracies near 1 usual here (Brown, Cai and DasGupta
/// 2001, Statistical Science 16); Wilson's stays inside [0, 1] and near its nominal level.
///
/// The trials must be independent: pass one prediction per recording (one repeat), not
/// counts pooled over repeats, which count every recording once per repeat and shrink the
/// interval by about `√repeats`.
///
/// # Errors
/// `n == 0`, or `correct > n`.
pub fn wilson_interval(correct: usize, n: usize) -> Result<Interval, StatsError> {
    if n == 0 {
        return Err(StatsError::Empty {
            what: "predictions",
        });
    }
    if correct > n {
        return Err(StatsError::CountAboveTotal { correct, n });
    }
    let (k, nf, z2) = (correct as f64, n as f64, Z_95 * Z_95);
    let root = Z_95 * (k * (nf - k) / nf + z2 / 4.0).sqrt();
    let outer = k + z2 / 2.0 + root;
    // The lower bound as `(k + z²/2 - root) / (n + z²)` cancels to rounding noise near
    // k = 0; multiplying through by `outer` gives the same value as k² / (n · outer),
    // exactly 0 at k = 0 and accurate to the last bits everywhere.
    let lower = k * k / (nf * outer);
    let upper = (outer / (nf + z2)).min(1.0);
    Ok(Interval {
        estimate: k / nf,
        lower,
        upper,
        level: LEVEL,
        method: IntervalMethod::Wilson { correct, n },
    })
}

/// Parameters of the percentile bootstrap.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BootstrapParams {
    /// Resamples (default 2000; Efron and Tibshirani 1993 advise at least 1000 for
    /// percentile intervals, whose ends rest on the few resamples in each tail).
    pub resamples: usize,
    /// Seed of the ChaCha8 generator that draws the resamples.
    pub seed: u64,
}

impl Default for BootstrapParams {
    fn default() -> Self {
        BootstrapParams {
            resamples: 2000,
            seed: 0,
        }
    }
}

impl BootstrapParams {
    /// Checks the rule (at least one resample) and returns the validated form.
    ///
    /// # Errors
    /// `resamples == 0`.
    pub fn check(self) -> Result<ValidBootstrap, ParamError> {
        if self.resamples == 0 {
            return Err(ParamError::new(
                "bootstrap-resamples",
                "the bootstrap needs at least 1 resample",
                self.resamples,
            ));
        }
        Ok(ValidBootstrap(self))
    }
}

/// Bootstrap parameters that passed [`BootstrapParams::check`] (the default passes).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ValidBootstrap(BootstrapParams);

impl std::ops::Deref for ValidBootstrap {
    type Target = BootstrapParams;
    fn deref(&self) -> &BootstrapParams {
        &self.0
    }
}

/// The 95 % percentile bootstrap interval of an accuracy over recordings (Efron 1979,
/// "Bootstrap methods: another look at the jackknife"; the percentile interval as in Efron
/// and Tibshirani 1993, chapter 13): `resamples` times, draw as many recordings as there
/// are, with replacement, and take the accuracy; the interval runs from the 2.5th to the
/// 97.5th percentile of those accuracies ([`percentile`]'s interpolation).
///
/// `correct[i]` says whether recording `i` was classified correctly. The same seed gives
/// the same interval on every platform (ChaCha8, indices drawn as `u64`). The interval
/// contains the estimate except with negligible probability for a few hundred resamples or
/// more (the resampled count's median is the observed count). With few recordings it is
/// too narrow (with one, it is a point); prefer [`wilson_interval`] there.
///
/// # Errors
/// No recordings.
pub fn bootstrap_accuracy(
    correct: &[bool],
    params: &ValidBootstrap,
) -> Result<Interval, StatsError> {
    let shares: Vec<f64> = correct.iter().map(|&c| f64::from(u8::from(c))).collect();
    bootstrap_mean_share(&shares, params)
}

/// [`bootstrap_accuracy`] for recordings classified several times (repeats of
/// cross-validation): `shares[i]` is the share of recording `i`'s predictions that were
/// correct, and the estimate is their mean. Resampling recordings rather than predictions
/// keeps a recording's repeats together, as they are not independent.
///
/// # Errors
/// No recordings, or a share outside [0, 1].
pub fn bootstrap_mean_share(
    shares: &[f64],
    params: &ValidBootstrap,
) -> Result<Interval, StatsError> {
    if shares.is_empty() {
        return Err(StatsError::Empty { what: "recordings" });
    }
    check_accuracies(shares)?;
    let n = shares.len();
    let mut means: Vec<f64> = Vec::with_capacity(params.resamples);
    for_each_resample(params.seed, &[n], params.resamples, |picked| {
        let total: f64 = picked.iter().map(|&i| shares[i]).sum();
        means.push(total / n as f64);
    });
    means.sort_by(f64::total_cmp);
    let tail = (1.0 - LEVEL) / 2.0;
    Ok(Interval {
        estimate: shares.iter().sum::<f64>() / n as f64,
        lower: percentile(&means, tail),
        upper: percentile(&means, 1.0 - tail),
        level: LEVEL,
        method: IntervalMethod::PercentileBootstrap {
            n,
            resamples: params.resamples,
            seed: params.seed,
        },
    })
}

/// [`bootstrap_mean_share`] for recordings encoded several times into spikes (the same
/// input with independent rounding-level perturbations): `shares[e][i]` is the share of
/// recording `i`'s predictions that were right under encoding `e`. The estimate is the mean
/// over encodings and recordings. Each resample draws one encoding (uniformly) and then as
/// many recordings as there are, with replacement, so the interval holds both the
/// variability of the recordings and that of the encoder, whose spikes move by whole
/// threshold crossings under changes far below any sensor's resolution: it is where one
/// run's accuracy may land, not only where the mean over encodings lies.
///
/// With one encoding this is [`bootstrap_mean_share`] exactly (same draws, same interval).
///
/// # Errors
/// No encodings or recordings, encodings of different lengths, or a share outside [0, 1].
pub fn bootstrap_over_encodings(
    shares: &[Vec<f64>],
    params: &ValidBootstrap,
) -> Result<Interval, StatsError> {
    let Some(first) = shares.first() else {
        return Err(StatsError::Empty { what: "encodings" });
    };
    if shares.len() == 1 {
        return bootstrap_mean_share(first, params);
    }
    let n = first.len();
    if n == 0 {
        return Err(StatsError::Empty { what: "recordings" });
    }
    if let Some(other) = shares.iter().find(|s| s.len() != n) {
        let (first, second) = (n, other.len());
        return Err(StatsError::LengthMismatch { first, second });
    }
    shares.iter().try_for_each(|s| check_accuracies(s))?;
    let mut draws = UniformIndices::new(params.seed);
    let (mut encoding, mut picked) = (Vec::new(), Vec::new());
    let mut means: Vec<f64> = Vec::with_capacity(params.resamples);
    for _ in 0..params.resamples {
        draws.fill(shares.len(), 1, &mut encoding);
        draws.fill(n, n, &mut picked);
        let chosen = &shares[encoding[0]];
        let total: f64 = picked.iter().map(|&i| chosen[i]).sum();
        means.push(total / n as f64);
    }
    means.sort_by(f64::total_cmp);
    let tail = (1.0 - LEVEL) / 2.0;
    let all: f64 = shares.iter().flatten().sum();
    Ok(Interval {
        estimate: all / (n * shares.len()) as f64,
        lower: percentile(&means, tail),
        upper: percentile(&means, 1.0 - tail),
        level: LEVEL,
        method: IntervalMethod::EncodingBootstrap {
            n,
            encodings: shares.len(),
            resamples: params.resamples,
            seed: params.seed,
        },
    })
}

fn check_accuracies(values: &[f64]) -> Result<(), StatsError> {
    match values.iter().position(|v| !(0.0..=1.0).contains(v)) {
        Some(index) => Err(StatsError::NotAnAccuracy {
            index,
            value: values[index],
        }),
        None => Ok(()),
    }
}

/// The mean accuracy over repeats with its 95 % Student t interval,
/// `mean ± t(0.975, r - 1) · s / √r` for `r` repeats with sample standard deviation `s`
/// (the t quantile from [`student_t_quantile`]), clipped to [0, 1] (the method records
/// whether it was).
///
/// The interval is as wide as the repeats vary. Repeats over simulator seeds are
/// independent datasets, and the interval then speaks for new datasets of the same design.
/// Repeats of cross-validation over one dataset share their recordings, so the interval
/// shows only how the result moves with the split, and is too narrow for new recordings
/// (Nadeau and Bengio 2003, Machine Learning 52); use [`bootstrap_mean_share`] for that.
///
/// # Errors
/// Fewer than 2 repeats, or an accuracy outside [0, 1].
pub fn t_interval_over_repeats(per_repeat: &[f64]) -> Result<Interval, StatsError> {
    let repeats = per_repeat.len();
    if repeats < 2 {
        return Err(StatsError::TooFewRepeats { got: repeats });
    }
    check_accuracies(per_repeat)?;
    let r = repeats as f64;
    let estimate = per_repeat.iter().sum::<f64>() / r;
    let variance = per_repeat
        .iter()
        .map(|a| (a - estimate).powi(2))
        .sum::<f64>()
        / (r - 1.0);
    let quantile = student_t_quantile(0.5 + LEVEL / 2.0, repeats - 1)?;
    let half = quantile * (variance / r).sqrt();
    let (lower, upper) = (estimate - half, estimate + half);
    Ok(Interval {
        estimate,
        lower: lower.max(0.0),
        upper: upper.min(1.0),
        level: LEVEL,
        method: IntervalMethod::StudentT {
            repeats,
            clipped: lower < 0.0 || upper > 1.0,
        },
    })
}
