//! E8: robustness of E1 to the number of neighbours k (paper section IV-A).

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::tables::{cv_at, cv_sweep_at};
use super::{compare, Comparison, Context, Skip, Stop};
use crate::analysis::{Columns, Outcome};
use crate::classify::{Interval, KnnSweep};
use crate::values::{BySpeed, Speed};

/// E8 at one speed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct E8Speed {
    /// Neighbour counts.
    pub k: Vec<usize>,
    /// Single taxel mean per k.
    pub taxel_mean: Vec<f64>,
    /// 3D-GLCM per k.
    pub glcm3d: Vec<f64>,
    /// 95 % interval of the single taxel's mean per k (bootstrap over recordings).
    #[serde(default)]
    pub taxel_mean_interval: Vec<Interval>,
    /// 95 % interval of 3D-GLCM per k (bootstrap over recordings).
    #[serde(default)]
    pub glcm3d_interval: Vec<Interval>,
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
            taxel_mean_interval: Vec::new(),
            glcm3d_interval: Vec::new(),
            glcm3d_vs_taxel: Vec::new(),
        };
        for (k, t, g) in evaluations(c, speed) {
            match (t, g) {
                (Ok(t), Ok(g)) => {
                    let paired = compare(("3D-GLCM", &g), ("single taxel", &t), c.params)?;
                    e8.k.push(k);
                    e8.taxel_mean.push(t.accuracy);
                    e8.glcm3d.push(g.accuracy);
                    e8.taxel_mean_interval
                        .push(t.accuracy_interval(c.params.seed)?);
                    e8.glcm3d_interval.push(g.accuracy_interval(c.params.seed)?);
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

/// One k's single-taxel and 3D-GLCM evaluations.
type AtK = (usize, crate::Result<Outcome>, crate::Result<Outcome>);

/// Every k's two evaluations at `speed`, in the order of the parameters' k. The run's own k
/// is E1's headline evaluation, already made; the others come from one neighbour search
/// per fold ([`KnnSweep`]), the same outcomes as one evaluation per k. When that cannot run
/// (the largest k above a training fold's size, say), each k is evaluated alone, so that
/// the k that can run still do and each of the others gets its own reason.
fn evaluations(c: &Context, speed: Speed) -> Vec<AtK> {
    let own = c.params.knn().params().k;
    let ks = &c.params.e8_ks;
    let others: Vec<usize> = ks.iter().copied().filter(|&k| k != own).collect();
    let folds = c.params.folds();
    let swept = KnnSweep::new(c.params.knn(), &others)
        .ok()
        .and_then(|sweep| {
            let (t, g) = rayon::join(
                || cv_sweep_at(&c.tables.taxel, Columns::EachTaxel, speed, &sweep, folds),
                || cv_sweep_at(&c.tables.glcm3d, Columns::All, speed, &sweep, folds),
            );
            Some(t.ok()?.into_iter().zip(g.ok()?))
        });
    let headline = |k| {
        let h = c.tables.at(speed);
        (k, Ok(h.taxel.clone()), Ok(h.glcm3d.clone()))
    };
    if let Some(swept) = swept {
        let mut swept = swept.peekable();
        return ks
            .iter()
            .map(|&k| match swept.next_if(|_| k != own) {
                Some((t, g)) => (k, Ok(t), Ok(g)),
                None => headline(k),
            })
            .collect();
    }
    // Every k's two evaluations side by side (each is deterministic), then taken in the
    // order of k.
    ks.par_iter()
        .map(|&k| {
            if k == own {
                return headline(k);
            }
            let knn = c.params.knn_with_k(k);
            let (t, g) = rayon::join(
                || cv_at(&c.tables.taxel, Columns::EachTaxel, speed, &knn, folds),
                || cv_at(&c.tables.glcm3d, Columns::All, speed, &knn, folds),
            );
            (k, t, g)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::testing::small_run;
    use super::super::ReproduceParams;
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

    /// Each k's accuracies, evaluated with that k alone.
    fn alone(c: &Context, speed: Speed, k: usize) -> (f64, f64) {
        let knn = c.params.knn_with_k(k);
        let at = |table, columns| cv_at(table, columns, speed, &knn, c.params.folds());
        let taxel = at(&c.tables.taxel, Columns::EachTaxel).unwrap();
        (
            taxel.accuracy,
            at(&c.tables.glcm3d, Columns::All).unwrap().accuracy,
        )
    }

    #[test]
    fn the_swept_k_are_each_k_alone_and_a_k_too_large_is_skipped_alone() {
        let run = small_run();
        let with_ks = |ks: Vec<usize>| {
            let params = ReproduceParams {
                e8_ks: ks,
                ..(*run.params).clone()
            };
            params.check().unwrap()
        };
        // One sweep over 3 and 1 beside the run's own 5.
        let params = with_ks(vec![3, 5, 1]);
        let c = Context {
            params: &params,
            ..run.context()
        };
        let (e8, skipped) = e8_neighbours(&c).unwrap();
        assert!(skipped.is_empty());
        for (speed, e) in e8.iter() {
            assert_eq!(e.k, [3, 5, 1]);
            for (i, &k) in e.k.iter().enumerate() {
                assert_eq!((e.taxel_mean[i], e.glcm3d[i]), alone(&c, speed, k), "k={k}");
            }
        }
        // 17 neighbours, more than a fold's 16 training recordings: the sweep cannot run,
        // so each k runs alone, and only 17 is skipped.
        let params = with_ks(vec![3, 17, 1]);
        let c = Context {
            params: &params,
            ..run.context()
        };
        let (e8, skipped) = e8_neighbours(&c).unwrap();
        assert_eq!(skipped.len(), e8.iter().count());
        assert!(skipped
            .iter()
            .all(|s| matches!(s, Skip::Neighbours { k: 17, reason, .. } if reason.contains("17"))));
        for (speed, e) in e8.iter() {
            assert_eq!(e.k, [3, 1]);
            assert_eq!((e.taxel_mean[1], e.glcm3d[1]), alone(&c, speed, 1));
        }
    }
}
