//! A paired comparison of two methods on the same recordings: the sign-flip test of their
//! differences, McNemar's exact test of their discordant recordings, and the verdict.

use serde::{Deserialize, Serialize};

use crate::classify::draws::Signs;
use crate::classify::stats::{binomial_half_cdf, StatsError};

use super::ALPHA;

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
