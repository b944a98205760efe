//! What an accuracy means: the summary of a confusion matrix beside its chance levels
//! ([`Metrics`]), 95 % intervals for an accuracy ([`wilson_interval`],
//! [`bootstrap_accuracy`], [`t_interval_over_repeats`]) and where one stands against chance
//! ([`AgainstChance`]), and a paired test of two methods on the same recordings
//! ([`mcnemar_exact`]) with the verdict it allows ([`PairedVerdict`]).
//!
//! Everything here is a pure function of counts or per-recording results; the
//! distributions they rest on are in [`super::stats`].

use serde::{Deserialize, Serialize};

use super::ConfusionMatrix;

mod intervals;
mod paired;
#[cfg(test)]
mod tests;

pub use intervals::{
    bootstrap_accuracy, bootstrap_mean_share, bootstrap_over_encodings, t_interval_over_repeats,
    wilson_at_the_bounds, wilson_interval, BootstrapParams, Interval, IntervalMethod,
    ValidBootstrap,
};
pub use paired::{
    mcnemar_exact, mcnemar_exact_p, sign_flip_p, PairedTest, PairedVerdict, Side,
    SIGN_FLIP_EXACT_UNITS,
};

/// The confidence level of every interval in this module.
pub const LEVEL: f64 = 0.95;

/// Where a 95 % interval stands against chance, when it is not above it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AgainstChance {
    /// The whole interval is under chance.
    Below,
    /// The interval reaches down to chance or under it.
    Includes,
}

impl AgainstChance {
    /// Where `ci` stands against `chance`; `None` when it is wholly above. An edge within
    /// rounding of chance (a share of the units against one over the classes) is at it.
    pub fn of(ci: [f64; 2], chance: f64) -> Option<AgainstChance> {
        const ROUNDING: f64 = 1e-9;
        if ci[1] < chance - ROUNDING {
            Some(AgainstChance::Below)
        } else if ci[0] <= chance + ROUNDING {
            Some(AgainstChance::Includes)
        } else {
            None
        }
    }
}

/// The chance level a classifier must beat to be shown better than guessing, with its
/// words for a note: one over the `classes` (`50.0 %, one over 2 classes`), or the largest
/// class's share `majority` where that is larger, since always answering that class
/// scores it (`66.7 %, always answering the most frequent class`).
pub fn chance_level(classes: usize, majority: f64) -> (f64, String) {
    let uniform = 1.0 / classes.max(1) as f64;
    match majority > uniform {
        true => (
            majority,
            format!(
                "{:.1} %, always answering the most frequent class",
                100.0 * majority
            ),
        ),
        false => (
            uniform,
            format!("{:.1} %, one over {classes} classes", 100.0 * uniform),
        ),
    }
}

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
