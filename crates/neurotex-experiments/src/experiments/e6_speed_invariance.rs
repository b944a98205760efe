//! E6: speed invariance. Train on the other speeds, test on one (paper section IV-E).

use serde::{Deserialize, Serialize};

use super::encodings::OverEncodings;
use super::{compare_encodings, Comparison, Context, Skip, Stop};
use crate::analysis::{evaluate, Columns, Outcome, Split};
use crate::classify::Interval;
use crate::recording::Selection;
use crate::values::{BySpeed, Speed};
use rayon::prelude::*;

/// E6 at one held-out speed; accuracies are means over encodings, as E1's.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct E6Speed {
    /// Training speeds.
    pub train: Vec<Speed>,
    /// Chance at the test speed: one over the classes recorded there.
    #[serde(default)]
    pub chance: f64,
    /// Single taxel, mean over taxels (and over encodings).
    pub taxel_mean: f64,
    /// 3D-GLCM (mean over encodings).
    pub glcm3d: f64,
    /// Encodings of each recording the accuracies and intervals are over (1: as run).
    #[serde(default = "super::one")]
    pub encodings: usize,
    /// 95 % interval of the single taxel's mean (bootstrap over the held-out recordings and
    /// the encodings).
    pub taxel_mean_interval: Interval,
    /// 95 % interval of 3D-GLCM (bootstrap over the held-out recordings and the encodings).
    pub glcm3d_interval: Interval,
    /// 3D-GLCM against the single taxel (mean over taxels) on the held-out recordings and
    /// the same encodings.
    pub glcm3d_vs_taxel: Comparison,
}

/// E6 with every speed held out in turn.
///
/// # Errors
/// Skipped with a single speed; a classification that cannot run (a test class never
/// trained on, say).
pub fn e6_speed_invariance(c: &Context) -> Result<BySpeed<E6Speed>, Stop> {
    let speeds = &c.prepared.speeds;
    if speeds.len() < 2 {
        return Err(Skip::OneSpeed.into());
    }
    let mut out = BySpeed::new();
    for &test in speeds {
        let train: Vec<Speed> = speeds.iter().copied().filter(|&s| s != test).collect();
        let split = Split::Where {
            train: Selection::speeds(&train),
            test: Selection::speeds(&[test]),
        };
        let knn = c.params.knn();
        // Every encoding's two evaluations (each deterministic), as run first.
        let outcomes = c
            .tables
            .encoding_tables()
            .into_par_iter()
            .map(|(taxel, glcm3d)| {
                let (t, g) = rayon::join(
                    || evaluate(taxel, Columns::EachTaxel, &split, knn),
                    || evaluate(glcm3d, Columns::All, &split, knn),
                );
                Ok((t?, g?))
            })
            .collect::<crate::Result<Vec<(Outcome, Outcome)>>>()?;
        let taxel: Vec<&Outcome> = outcomes.iter().map(|o| &o.0).collect();
        let glcm3d: Vec<&Outcome> = outcomes.iter().map(|o| &o.1).collect();
        let (t, g) = (
            OverEncodings::of(&taxel, c.params.seed)?,
            OverEncodings::of(&glcm3d, c.params.seed)?,
        );
        let mut classes: Vec<&str> = c.prepared.at(test).map(|e| e.meta.label.as_str()).collect();
        classes.sort_unstable();
        classes.dedup();
        let e6 = E6Speed {
            train,
            chance: 1.0 / classes.len().max(1) as f64,
            taxel_mean: t.mean(),
            glcm3d: g.mean(),
            encodings: outcomes.len(),
            taxel_mean_interval: t.combined,
            glcm3d_interval: g.combined,
            glcm3d_vs_taxel: compare_encodings(
                ("3D-GLCM", &glcm3d),
                ("single taxel", &taxel),
                c.params,
            )?,
        };
        out.insert(test, e6);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::super::testing::small_run;
    use super::*;

    #[test]
    fn each_speed_held_out_and_trained_on_the_others() {
        let run = small_run();
        let e6 = e6_speed_invariance(&run.context()).unwrap();
        assert_eq!(e6.len(), 2);
        for (test, e) in e6.iter() {
            assert!(!e.train.contains(&test) && e.train.len() == 1);
        }
    }

    #[test]
    fn accuracies_are_means_over_every_encodings_own_evaluation() {
        let run = small_run();
        let c = run.context();
        let e6 = e6_speed_invariance(&c).unwrap();
        let tables = c.tables.encoding_tables();
        assert_eq!(tables.len(), run.params.encoder_draws);
        for (test, e) in e6.iter() {
            assert_eq!(e.encodings, run.params.encoder_draws);
            let split = Split::Where {
                train: Selection::speeds(&e.train),
                test: Selection::speeds(&[test]),
            };
            let (mut taxel, mut glcm3d) = (Vec::new(), Vec::new());
            for (t, g) in &tables {
                let knn = c.params.knn();
                taxel.push(
                    evaluate(t, Columns::EachTaxel, &split, knn)
                        .unwrap()
                        .accuracy,
                );
                glcm3d.push(evaluate(g, Columns::All, &split, knn).unwrap().accuracy);
            }
            let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
            assert!((e.taxel_mean - mean(&taxel)).abs() < 1e-12);
            assert!((e.glcm3d - mean(&glcm3d)).abs() < 1e-12);
            assert!((e.glcm3d_interval.estimate - e.glcm3d).abs() < 1e-12);
        }
    }
}
