//! What an accuracy means: the summary of a confusion matrix beside its chance levels
//! ([`Metrics`]), 95 % intervals for an accuracy ([`wilson_interval`],
//! [`bootstrap_accuracy`], [`t_interval_over_repeats`]), and a paired test of two methods
//! on the same recordings ([`mcnemar_exact`]) with the verdict it allows ([`PairedVerdict`]).
//!
//! Everything here is a pure function of counts or per-recording results; the
//! distributions they rest on are in [`super::stats`].

use serde::{Deserialize, Serialize};

use super::draws::{for_each_resample, Signs, UniformIndices};
use super::stats::{binomial_half_cdf, percentile, student_t_quantile, StatsError, Z_95};
use super::ConfusionMatrix;
use crate::error::ParamError;

/// The confidence level of every interval in this module.
pub const LEVEL: f64 = 0.95;

/// The significance level at which a paired comparison counts as a result.
pub const ALPHA: f64 = 0.05;

/// Recall and precision of one class, with the counts they come from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ClassMetrics {
    /// Samples whose true class this is (the row sum).
    pub support: usize,
    /// Samples predicted as this class (the column sum).
    pub predicted: usize,
    /// Samples of this class predicted as it (the diagonal entry).
    pub correct: usize,
    /// `correct / support`; `None` when the class never occurs in the truth, where recall
    /// is undefined (0/0), rather than a 0 or 1 that would pass for a measurement.
    pub recall: Option<f64>,
    /// `correct / predicted`; `None` when the class is never predicted, where precision is
    /// undefined (scikit-learn's `zero_division=np.nan`), rather than the 0 that
    /// scikit-learn's default reports.
    pub precision: Option<f64>,
}

/// The summary of a confusion matrix (rows = true class) that an accuracy should never be
/// shown without: balanced accuracy, per-class recall and precision, and chance levels.
///
/// For a matrix summed over repeats of cross-validation the counts are the pooled ones and
/// `n` counts each recording once per repeat: the shares are right, but an interval from
/// these counts would treat repeats as new recordings (see [`wilson_interval`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Metrics {
    /// Samples counted.
    pub n: usize,
    /// Samples on the diagonal.
    pub correct: usize,
    /// `correct / n` (0 for an empty matrix).
    pub accuracy: f64,
    /// Mean recall over the classes present in the truth (scikit-learn's
    /// `balanced_accuracy_score`); a predicted class absent from the truth does not count.
    /// 0 for an empty matrix.
    pub balanced_accuracy: f64,
    /// One entry per class index (row of the matrix).
    pub per_class: Vec<ClassMetrics>,
    /// Classes that occur in the truth.
    pub classes_present: usize,
    /// The accuracy of always answering the most frequent true class: its share of the truth.
    pub chance_majority: f64,
    /// The accuracy of guessing uniformly: `1 / classes_present` (0 when none is present).
    pub chance_uniform: f64,
}

impl Metrics {
    /// Summarises `confusion` (row = true class, column = predicted class).
    pub fn from_confusion(confusion: &ConfusionMatrix) -> Metrics {
        let rows = confusion.rows();
        let per_class: Vec<ClassMetrics> = (0..rows.len())
            .map(|class| {
                let support: usize = rows[class].iter().sum();
                let predicted: usize = rows.iter().map(|row| row[class]).sum();
                let correct = rows[class][class];
                ClassMetrics {
                    support,
                    predicted,
                    correct,
                    recall: share(correct, support),
                    precision: share(correct, predicted),
                }
            })
            .collect();
        let n = confusion.total();
        let correct = per_class.iter().map(|c| c.correct).sum();
        let recalls: Vec<f64> = per_class.iter().filter_map(|c| c.recall).collect();
        let majority = per_class.iter().map(|c| c.support).max().unwrap_or(0);
        Metrics {
            n,
            correct,
            accuracy: share(correct, n).unwrap_or(0.0),
            balanced_accuracy: mean(&recalls).unwrap_or(0.0),
            classes_present: recalls.len(),
            chance_majority: share(majority, n).unwrap_or(0.0),
            chance_uniform: share(1, recalls.len()).unwrap_or(0.0),
            per_class,
        }
    }
}

fn share(part: usize, whole: usize) -> Option<f64> {
    (whole > 0).then(|| part as f64 / whole as f64)
}

fn mean(values: &[f64]) -> Option<f64> {
    (!values.is_empty()).then(|| values.iter().sum::<f64>() / values.len() as f64)
}

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

/// One of the two methods of a paired comparison.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Side {
    /// The method whose results were passed first.
    First,
    /// The method whose results were passed second.
    Second,
}

impl Side {
    /// The other method.
    pub fn other(self) -> Side {
        match self {
            Side::First => Side::Second,
            Side::Second => Side::First,
        }
    }
}

/// Most units [`sign_flip_p`] enumerates exactly (2^16 sign patterns); beyond, it samples.
pub const SIGN_FLIP_EXACT_UNITS: usize = 16;

/// The two-sided p-value of the paired sign-flip (randomisation) test of a zero mean
/// difference (Fisher 1935, The Design of Experiments, section 21; the paired case of
/// scipy's `permutation_test(..., permutation_type="samples")`): under the hypothesis that
/// two methods do equally well, each unit's difference `differences[i]` (of shares of right
/// predictions, per recording or per group of recordings) is as likely to have either sign,
/// so the observed `|mean|` is compared with the `|mean|` of every sign pattern.
///
/// With at most [`SIGN_FLIP_EXACT_UNITS`] units every pattern is enumerated and the
/// p-value is exact (the share of patterns at least as extreme). With more, `resamples`
/// patterns are drawn (ChaCha8 seeded by `seed`) and `p = (1 + hits) / (1 + resamples)`,
/// never 0 (Phipson and Smyth 2010, Stat. Appl. Genet. Mol. Biol. 9). Unlike McNemar's
/// test this takes a share per recording, so repeats of cross-validation and the mean over
/// taxels pass through without pooling predictions. Ties use a relative tolerance of 1e-12
/// (as scipy does), so a pattern equal to the observation in exact arithmetic counts as
/// extreme.
///
/// # Errors
/// No units, a difference outside [-1, 1], or no resamples for more than
/// [`SIGN_FLIP_EXACT_UNITS`] units.
pub fn sign_flip_p(differences: &[f64], resamples: usize, seed: u64) -> Result<f64, StatsError> {
    let n = differences.len();
    if n == 0 {
        return Err(StatsError::Empty {
            what: "paired differences",
        });
    }
    if let Some(index) = differences.iter().position(|d| !(-1.0..=1.0).contains(d)) {
        let value = differences[index];
        return Err(StatsError::NotAnAccuracy { index, value });
    }
    let observed = differences.iter().sum::<f64>().abs();
    let extreme = |total: f64| total.abs() >= observed * (1.0 - 1e-12);
    let signed = |pattern: u64| -> f64 {
        let flip = |i: usize| pattern >> (i % 64) & 1 == 1;
        differences
            .iter()
            .enumerate()
            .map(|(i, &d)| if flip(i) { -d } else { d })
            .sum()
    };
    if n <= SIGN_FLIP_EXACT_UNITS {
        let patterns = 1u64 << n;
        let hits = (0..patterns).filter(|&p| extreme(signed(p))).count();
        return Ok(hits as f64 / patterns as f64);
    }
    if resamples == 0 {
        return Err(StatsError::Empty {
            what: "sign-flip resamples",
        });
    }
    let mut signs = Signs::new(seed);
    let hits = (0..resamples)
        .filter(|_| {
            let total: f64 = differences.iter().map(|&d| signs.flip(d)).sum();
            extreme(total)
        })
        .count();
    Ok((1 + hits) as f64 / (1 + resamples) as f64)
}

/// McNemar's exact test of two methods on the same recordings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PairedTest {
    /// Recordings compared.
    pub n: usize,
    /// Recordings the first method got right and the second wrong.
    pub b: usize,
    /// Recordings the second method got right and the first wrong.
    pub c: usize,
    /// Two-sided exact p-value.
    pub p_value: f64,
    /// The method right on more of the discordant recordings (`None` when `b == c`),
    /// whether or not the difference is significant.
    pub winner: Option<Side>,
}

/// What a paired comparison says about an expected winner.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PairedVerdict {
    /// The expected method is better, significantly (p < [`ALPHA`]).
    Supported,
    /// No significant difference either way: the claim is neither shown nor refuted.
    NotShown,
    /// The other method is better, significantly.
    Contradicted,
}

impl PairedTest {
    /// The verdict on the claim that `expected` is the better method: significant means
    /// `p < ALPHA`.
    pub fn verdict(&self, expected: Side) -> PairedVerdict {
        match self.winner {
            Some(side) if self.p_value < ALPHA => {
                if side == expected {
                    PairedVerdict::Supported
                } else {
                    PairedVerdict::Contradicted
                }
            }
            _ => PairedVerdict::NotShown,
        }
    }
}

/// McNemar's test (McNemar 1947, Psychometrika 12) in its exact form: of the recordings on
/// which the two methods disagree, `b` went to the first and `c` to the second; with no
/// difference between the methods each disagreement is a fair coin, so the two-sided
/// p-value is `min(1, 2 P(X <= min(b, c)))` for `X ~ Binomial(b + c, 1/2)` (as statsmodels'
/// `mcnemar(exact=True)`), computed in log space ([`binomial_half_cdf`]) so that thousands
/// of recordings neither overflow nor lose accuracy.
///
/// Why McNemar here rather than the corrected resampled t-test (Nadeau and Bengio 2003):
/// both methods are scored on the same test items, and McNemar uses exactly that pairing;
/// it is exact, assuming only independent recordings and no distribution of accuracies,
/// and needs one set of out-of-fold predictions. The corrected t-test rests on a normal
/// approximation over a few overlapping splits and a heuristic correction for their
/// overlap; Dietterich (1998, Neural Computation 10) found McNemar's test to have low
/// type I error where a method can be run once.
///
/// `first[i]` and `second[i]` say whether each method got recording `i` right. Pass one
/// entry per recording (one repeat, or each recording's majority over repeats): pooling
/// repeats counts every recording several times and makes the p-value far too small.
///
/// # Errors
/// The two slices differ in length.
pub fn mcnemar_exact(first: &[bool], second: &[bool]) -> Result<PairedTest, StatsError> {
    if first.len() != second.len() {
        return Err(StatsError::LengthMismatch {
            first: first.len(),
            second: second.len(),
        });
    }
    let b = first.iter().zip(second).filter(|&(&f, &s)| f && !s).count();
    let c = first.iter().zip(second).filter(|&(&f, &s)| !f && s).count();
    Ok(PairedTest {
        n: first.len(),
        b,
        c,
        p_value: mcnemar_exact_p(b, c),
        winner: match b.cmp(&c) {
            std::cmp::Ordering::Greater => Some(Side::First),
            std::cmp::Ordering::Less => Some(Side::Second),
            std::cmp::Ordering::Equal => None,
        },
    })
}

/// The exact two-sided McNemar p-value for `b` and `c` discordant recordings (see
/// [`mcnemar_exact`]); 1 when there are none.
pub fn mcnemar_exact_p(b: usize, c: usize) -> f64 {
    if b.abs_diff(c) <= 1 {
        // The lower tail up to the middle is at least one half (exactly one half when b + c
        // is odd), so the doubled tail reaches 1; said exactly rather than summed to 1 - 1e-15.
        return 1.0;
    }
    (2.0 * binomial_half_cdf(b.min(c), b + c)).min(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metrics_by_hand_with_an_absent_and_an_unpredicted_class() {
        // Class 2 never occurs in the truth but is predicted once; class 1 is never predicted.
        let m = ConfusionMatrix::from_predictions(&[0, 0, 0, 1, 1], &[0, 0, 2, 0, 0], 3);
        let metrics = Metrics::from_confusion(&m);
        assert_eq!((metrics.n, metrics.correct), (5, 2));
        assert!((metrics.accuracy - 0.4).abs() < 1e-15);
        // Recalls 2/3 and 0 over the 2 classes present.
        assert!((metrics.balanced_accuracy - 1.0 / 3.0).abs() < 1e-15);
        assert_eq!(metrics.classes_present, 2);
        assert!((metrics.chance_majority - 0.6).abs() < 1e-15);
        assert_eq!(metrics.chance_uniform, 0.5);
        assert_eq!(metrics.per_class[1].precision, None);
        assert_eq!(metrics.per_class[1].recall, Some(0.0));
        assert_eq!(metrics.per_class[2].recall, None);
        assert_eq!(metrics.per_class[2].precision, Some(0.0));
        assert_eq!(metrics.per_class[0].precision, Some(0.5));
        let json = serde_json::to_value(&metrics).unwrap();
        assert!(json["per_class"][1]["precision"].is_null());
    }

    #[test]
    fn metrics_of_an_empty_matrix_are_zero() {
        let metrics = Metrics::from_confusion(&ConfusionMatrix::zeros(2));
        assert_eq!(metrics.n, 0);
        assert_eq!(metrics.accuracy, 0.0);
        assert_eq!(metrics.balanced_accuracy, 0.0);
        assert_eq!(metrics.chance_uniform, 0.0);
        assert_eq!(metrics.classes_present, 0);
    }

    #[test]
    fn wilson_is_exact_at_the_ends_and_rejects_bad_counts() {
        let none = wilson_interval(0, 10).unwrap();
        assert_eq!((none.lower, none.estimate), (0.0, 0.0));
        assert!(none.upper > 0.2);
        let json = serde_json::to_value(&none).unwrap();
        assert_eq!(
            (json["method"].as_str(), json["n"].as_u64()),
            (Some("wilson"), Some(10))
        );
        assert_eq!(serde_json::from_value::<Interval>(json).unwrap(), none);
        let all = wilson_interval(10, 10).unwrap();
        assert_eq!((all.estimate, all.upper), (1.0, 1.0));
        assert!(all.lower < 0.8);
        assert_eq!(
            wilson_interval(0, 0),
            Err(StatsError::Empty {
                what: "predictions"
            })
        );
        assert!(matches!(
            wilson_interval(3, 2),
            Err(StatsError::CountAboveTotal { correct: 3, n: 2 })
        ));
    }

    #[test]
    fn bootstrap_rule_and_errors() {
        assert!(BootstrapParams {
            resamples: 0,
            seed: 1
        }
        .check()
        .is_err());
        let params = BootstrapParams::default().check().unwrap();
        assert_eq!(params.resamples, 2000);
        assert!(matches!(
            bootstrap_accuracy(&[], &params),
            Err(StatsError::Empty { .. })
        ));
        assert!(matches!(
            bootstrap_mean_share(&[0.5, 1.5], &params),
            Err(StatsError::NotAnAccuracy { index: 1, .. })
        ));
        let one = bootstrap_accuracy(&[true], &params).unwrap();
        assert_eq!((one.lower, one.estimate, one.upper), (1.0, 1.0, 1.0));
    }

    #[test]
    fn a_bootstrap_point_at_the_bounds_becomes_the_wilson_interval() {
        let params = BootstrapParams::default().check().unwrap();
        // 12 of 12 right: every resample is 100 %. Wilson's lower bound at k = n is
        // n / (n + z²) = 12 / (12 + 1.959964²) = 0.757506 (by hand).
        let all = bootstrap_accuracy(&[true; 12], &params).unwrap();
        assert_eq!((all.lower, all.upper), (1.0, 1.0));
        let all = all.or_wilson_at_the_bounds(12);
        assert!((all.lower - 0.757_506).abs() < 1e-6, "{all:?}");
        assert_eq!(all.upper, 1.0);
        assert_eq!(all.described(), "Wilson score over 12 recordings");
        let none = bootstrap_accuracy(&[false; 12], &params).unwrap();
        let none = none.or_wilson_at_the_bounds(12);
        assert_eq!(none.lower, 0.0);
        assert!((none.upper - (1.0 - 0.757_506)).abs() < 1e-6, "{none:?}");
        // An interval with spread is kept as it is.
        let mixed = bootstrap_accuracy(&[true, false, true, true], &params).unwrap();
        assert_eq!(mixed.clone().or_wilson_at_the_bounds(4), mixed);
    }

    #[test]
    fn bootstrap_width_is_near_the_binomial_one() {
        // 80 of 100 correct: the bootstrap distribution is Binomial(100, 0.8) / 100, whose
        // 2.5 % and 97.5 % quantiles are 0.72 and 0.88 (scipy `binom.ppf`); 2000 resamples
        // land within a count of them.
        let correct: Vec<bool> = (0..100).map(|i| i < 80).collect();
        let params = BootstrapParams::default().check().unwrap();
        let interval = bootstrap_accuracy(&correct, &params).unwrap();
        assert_eq!(interval.estimate, 0.8);
        assert!((interval.lower - 0.72).abs() <= 0.011, "{interval:?}");
        assert!((interval.upper - 0.88).abs() <= 0.011, "{interval:?}");
    }

    #[test]
    fn one_encoding_is_the_recordings_bootstrap_and_several_widen_it_to_their_mixture() {
        let params = BootstrapParams::default().check().unwrap();
        let share = |k: usize| {
            (0..100)
                .map(|i| f64::from(u8::from(i < k)))
                .collect::<Vec<_>>()
        };
        let alone = bootstrap_mean_share(&share(80), &params).unwrap();
        assert_eq!(
            bootstrap_over_encodings(&[share(80)], &params).unwrap(),
            alone
        );
        // Encodings giving 80 and 60 of 100: each resample is Binomial(100, 0.8) / 100 or
        // Binomial(100, 0.6) / 100 with equal odds, and that mixture's 2.5 % and 97.5 %
        // quantiles are 0.52 and 0.86 (the binomial sums in exact arithmetic); 2000
        // resamples land within a count or two of them.
        let both = bootstrap_over_encodings(&[share(80), share(60)], &params).unwrap();
        assert_eq!(both.estimate, 0.7);
        assert!((both.lower - 0.52).abs() <= 0.021, "{both:?}");
        assert!((both.upper - 0.86).abs() <= 0.021, "{both:?}");
        assert!(both.upper - both.lower > 2.0 * (alone.upper - alone.lower));
        assert!(matches!(
            both.method,
            IntervalMethod::EncodingBootstrap {
                n: 100,
                encodings: 2,
                ..
            }
        ));
        assert!(bootstrap_over_encodings(&[], &params).is_err());
        assert_eq!(
            bootstrap_over_encodings(&[share(80), vec![1.0; 3]], &params),
            Err(StatsError::LengthMismatch {
                first: 100,
                second: 3
            })
        );
        assert!(bootstrap_over_encodings(&[share(80), vec![2.0; 100]], &params).is_err());
    }

    #[test]
    fn t_interval_errors_and_clipping() {
        assert_eq!(
            t_interval_over_repeats(&[0.5]),
            Err(StatsError::TooFewRepeats { got: 1 })
        );
        assert!(matches!(
            t_interval_over_repeats(&[0.5, f64::NAN]),
            Err(StatsError::NotAnAccuracy { index: 1, .. })
        ));
        let equal = t_interval_over_repeats(&[0.75, 0.75, 0.75]).unwrap();
        assert_eq!((equal.lower, equal.upper), (0.75, 0.75));
        let wide = t_interval_over_repeats(&[1.0, 0.5]).unwrap();
        assert_eq!(wide.upper, 1.0);
        assert_eq!(
            wide.method,
            IntervalMethod::StudentT {
                repeats: 2,
                clipped: true
            }
        );
    }

    #[test]
    fn mcnemar_counts_winner_and_verdicts() {
        let first = [true, true, true, true, true, true, true, false, true];
        let second = [false, false, false, false, false, false, false, false, true];
        let test = mcnemar_exact(&first, &second).unwrap();
        assert_eq!((test.n, test.b, test.c), (9, 7, 0));
        // 2 · 2^-7
        assert_eq!(test.p_value, 1.0 / 64.0);
        assert_eq!(test.winner, Some(Side::First));
        assert_eq!(test.verdict(Side::First), PairedVerdict::Supported);
        assert_eq!(test.verdict(Side::Second), PairedVerdict::Contradicted);
        let weak = mcnemar_exact(&first[..3], &second[..3]).unwrap();
        assert_eq!(weak.p_value, 0.25);
        assert_eq!(weak.verdict(Side::First), PairedVerdict::NotShown);
        let none = mcnemar_exact(&[], &[]).unwrap();
        assert_eq!((none.p_value, none.winner), (1.0, None));
        assert_eq!(none.verdict(Side::Second), PairedVerdict::NotShown);
        assert_eq!(
            mcnemar_exact(&[true], &[]),
            Err(StatsError::LengthMismatch {
                first: 1,
                second: 0
            })
        );
        assert_eq!(Side::First.other(), Side::Second);
    }
}
