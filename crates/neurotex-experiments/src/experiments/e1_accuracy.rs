//! E1: accuracy per speed, single taxel (mean over taxels, and the best taxel chosen after
//! the fact) against 3D-GLCM (paper section IV-A).

use serde::{Deserialize, Serialize};

use super::encodings::{Methods, OverEncodings};
use super::{compare_encodings, Comparison, Context, Stop};
use crate::analysis::{best_taxel, Outcome, TaxelAccuracy};
use crate::classify::Interval;
use crate::values::BySpeed;

/// E1 at one speed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct E1Speed {
    /// Single taxel, mean over taxels (and over encodings).
    pub taxel_mean: f64,
    /// Single taxel, mean over the responsive taxels (neither silent nor at the ceiling in
    /// most recordings); `None` when no taxel responds.
    pub taxel_mean_responsive: Option<f64>,
    /// The best taxel (chosen after the fact), its accuracy a mean over encodings as the
    /// other columns'.
    pub taxel_best: f64,
    /// Which taxel was best, `r{row}c{col}`.
    pub taxel_best_cell: String,
    /// 3D-GLCM (mean over encodings).
    pub glcm3d: f64,
    /// 3D-GLCM standard deviation over CV repeats (the encoding as run).
    pub glcm3d_std: f64,
    /// Encodings of each recording the accuracies and intervals are over (1: as run).
    #[serde(default = "one")]
    pub encodings: usize,
    /// Samples.
    pub n: usize,
    /// Classes recorded at this speed.
    pub classes: usize,
    /// Chance by guessing uniformly among those classes, `1 / classes`.
    pub chance: f64,
    /// Chance by always answering the most frequent class at this speed.
    pub majority: f64,
    /// 95 % interval of the 3D-GLCM accuracy (bootstrap over recordings and encodings).
    pub glcm3d_interval: Interval,
    /// 95 % interval of the single taxel's mean over taxels (bootstrap over recordings and
    /// encodings).
    pub taxel_mean_interval: Interval,
    /// 3D-GLCM against the single taxel (mean over taxels) on the same recordings and
    /// encodings.
    pub glcm3d_vs_taxel: Comparison,
}

fn one() -> usize {
    1
}

/// E1 at every speed, from the headline evaluations of every encoding (the responsive
/// and the best taxel from the encoding as run).
///
/// # Errors
/// None of its own: the evaluations ran when the tables were built.
pub fn e1_accuracy(c: &Context) -> Result<BySpeed<E1Speed>, Stop> {
    c.tables
        .headline
        .iter()
        .map(|(speed, h)| -> Result<_, Stop> {
            let encodings = c.tables.encodings_at(speed);
            let m = Methods::of(&encodings);
            let glcm3d = OverEncodings::of(&m.glcm3d, c.params.seed)?;
            let taxel = OverEncodings::of(&m.taxel, c.params.seed)?;
            // Each taxel's accuracy over the encodings, as the mean over taxels is.
            let per_taxel = per_taxel_over_encodings(&m.taxel);
            let best = best_taxel(&per_taxel).unwrap_or(TaxelAccuracy {
                row: 0,
                col: 0,
                accuracy: h.taxel.accuracy,
            });
            let truth: Vec<usize> = h
                .glcm3d
                .confusion
                .rows()
                .iter()
                .map(|r| r.iter().sum())
                .collect();
            let total = truth.iter().sum::<usize>().max(1) as f64;
            let classes = truth.iter().filter(|&&n| n > 0).count();
            let e1 = E1Speed {
                taxel_mean: taxel.mean(),
                taxel_mean_responsive: c.prepared.taxels.responsive_mean(&per_taxel),
                taxel_best: best.accuracy,
                taxel_best_cell: format!("r{}c{}", best.row, best.col),
                glcm3d: glcm3d.mean(),
                glcm3d_std: h.glcm3d.accuracy_std,
                encodings: encodings.len(),
                n: h.glcm3d.n,
                classes,
                chance: 1.0 / classes.max(1) as f64,
                majority: truth.iter().copied().max().unwrap_or(0) as f64 / total,
                glcm3d_interval: glcm3d.combined,
                taxel_mean_interval: taxel.combined,
                glcm3d_vs_taxel: compare_encodings(
                    ("3D-GLCM", &m.glcm3d),
                    ("single taxel", &m.taxel),
                    c.params,
                )?,
            };
            Ok((speed, e1))
        })
        .collect()
}

/// Each taxel's accuracy as the mean over the encodings' evaluations (empty when the
/// taxels were not evaluated one by one).
fn per_taxel_over_encodings(taxel: &[&Outcome]) -> Vec<TaxelAccuracy> {
    let Some(Some(first)) = taxel.first().map(|o| o.per_taxel.as_deref()) else {
        return Vec::new();
    };
    let n = taxel.len() as f64;
    first
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let sum: f64 = taxel
                .iter()
                .filter_map(|o| o.per_taxel.as_deref().and_then(|p| p.get(i)))
                .map(|p| p.accuracy)
                .sum();
            TaxelAccuracy {
                accuracy: sum / n,
                ..*t
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::testing::small_run;
    use super::*;

    #[test]
    fn one_entry_per_speed_with_the_best_taxel_at_least_the_mean() {
        let run = small_run();
        let e1 = e1_accuracy(&run.context()).unwrap();
        assert_eq!(e1.len(), run.prepared.speeds.len());
        for e in e1.values() {
            assert!(e.taxel_best >= e.taxel_mean);
            assert!((0.0..=1.0).contains(&e.glcm3d) && e.n > 0);
            assert!(e.taxel_best_cell.starts_with('r'));
            // 4 textures x 6 trials at each speed
            assert_eq!((e.classes, e.chance, e.majority), (4, 0.25, 0.25));
            let responsive = e.taxel_mean_responsive.expect("the rig's taxels respond");
            assert!((e.glcm3d_interval.estimate - e.glcm3d).abs() < 1e-12);
            assert!((e.taxel_mean_interval.estimate - e.taxel_mean).abs() < 1e-12);
            let diff = e.glcm3d - e.taxel_mean;
            assert!((e.glcm3d_vs_taxel.difference - diff).abs() < 1e-12);
            assert!((0.0..=1.0).contains(&responsive));
        }
    }
    #[test]
    fn every_taxel_column_is_over_the_same_encodings() {
        let run = small_run();
        let c = run.context();
        let e1 = e1_accuracy(&c).unwrap();
        for (speed, e) in e1.iter() {
            let encodings = c.tables.encodings_at(speed);
            let m = Methods::of(&encodings);
            let per = per_taxel_over_encodings(&m.taxel);
            assert_eq!(per.len(), 16);
            // The mean over taxels of each taxel's mean over encodings is the headline mean.
            let mean = per.iter().map(|t| t.accuracy).sum::<f64>() / per.len() as f64;
            assert!(
                (mean - e.taxel_mean).abs() < 1e-12,
                "{mean} {}",
                e.taxel_mean
            );
            let best = per.iter().map(|t| t.accuracy).fold(0.0, f64::max);
            assert_eq!(e.taxel_best, best);
            // By hand for one taxel: its accuracy on each encoding, averaged.
            let by_hand = m
                .taxel
                .iter()
                .map(|o| o.per_taxel.as_ref().unwrap()[5].accuracy)
                .sum::<f64>()
                / m.taxel.len() as f64;
            assert_eq!(per[5].accuracy, by_hand);
        }
    }
}
