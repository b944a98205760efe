//! E8: robustness of E1 to the number of neighbours k (paper section IV-A).

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::tables::cv_at;
use super::{compare, Comparison, Context, Skip, Stop};
use crate::analysis::Columns;
use crate::values::BySpeed;

/// E8 at one speed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct E8Speed {
    /// Neighbour counts.
    pub k: Vec<usize>,
    /// Single taxel mean per k.
    pub taxel_mean: Vec<f64>,
    /// 3D-GLCM per k.
    pub glcm3d: Vec<f64>,
    /// Per k, 3D-GLCM against the single taxel (mean over taxels) on the same recordings.
    #[serde(default)]
    pub glcm3d_vs_taxel: Vec<Comparison>,
}

/// E8 at every speed, and the `(speed, k)` pairs the data could not support (a training
/// fold smaller than k, say) with their reasons.
///
/// # Errors
/// None of its own: a `k` that cannot run is skipped, not failed.
pub fn e8_neighbours(c: &Context) -> Result<(BySpeed<E8Speed>, Vec<Skip>), Stop> {
    let (mut out, mut skipped) = (BySpeed::new(), Vec::new());
    for &speed in &c.prepared.speeds {
        let mut e8 = E8Speed {
            k: Vec::new(),
            taxel_mean: Vec::new(),
            glcm3d: Vec::new(),
            glcm3d_vs_taxel: Vec::new(),
        };
        // Every k's two evaluations side by side (each is deterministic), then taken in
        // the order of k.
        let runs: Vec<_> = c
            .params
            .e8_ks
            .par_iter()
            .map(|&k| {
                // The run's own k is E1's headline evaluation, already made.
                if k == c.params.knn().params().k {
                    let h = c.tables.at(speed);
                    return (k, Ok(h.taxel.clone()), Ok(h.glcm3d.clone()));
                }
                let knn = c.params.knn_with_k(k);
                let cv = c.params.folds();
                let (t, g) = rayon::join(
                    || cv_at(&c.tables.taxel, Columns::EachTaxel, speed, &knn, cv),
                    || cv_at(&c.tables.glcm3d, Columns::All, speed, &knn, cv),
                );
                (k, t, g)
            })
            .collect();
        for (k, t, g) in runs {
            match (t, g) {
                (Ok(t), Ok(g)) => {
                    let paired = compare(("3D-GLCM", &g), ("single taxel", &t), c.params)?;
                    e8.k.push(k);
                    e8.taxel_mean.push(t.accuracy);
                    e8.glcm3d.push(g.accuracy);
                    e8.glcm3d_vs_taxel.push(paired);
                }
                (Err(e), _) | (_, Err(e)) => skipped.push(Skip::Neighbours {
                    k,
                    speed,
                    reason: e.to_string(),
                }),
            }
        }
        out.insert(speed, e8);
    }
    Ok((out, skipped))
}

#[cfg(test)]
mod tests {
    use super::super::testing::small_run;
    use super::*;

    #[test]
    fn every_k_at_every_speed_and_the_run_k_equals_e1() {
        let run = small_run();
        let c = run.context();
        let (e8, skipped) = e8_neighbours(&c).unwrap();
        assert!(skipped.is_empty());
        for (speed, e) in e8.iter() {
            assert_eq!(e.k, [1, 5]);
            assert_eq!(e.glcm3d[1], c.tables.at(speed).glcm3d.accuracy);
            assert_eq!(e.glcm3d_vs_taxel.len(), 2);
            for ((p, g), t) in e.glcm3d_vs_taxel.iter().zip(&e.glcm3d).zip(&e.taxel_mean) {
                assert!((p.difference - (g - t)).abs() < 1e-12);
            }
        }
    }
}
