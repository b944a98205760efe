//! E8: robustness of E1 to the number of neighbours k (paper section IV-A).

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::encodings::OverEncodings;
use super::tables::{cv_at, cv_sweep_at};
use super::{compare_encodings, Comparison, Context, Headline, Skip, Stop};
use crate::analysis::{Columns, FeatureTable, Outcome};
use crate::classify::{Interval, KnnSweep};
use crate::values::{BySpeed, Speed};

/// E8 at one speed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct E8Speed {
    /// Neighbour counts.
    pub k: Vec<usize>,
    /// Single taxel, mean over taxels (and over encodings) per k.
    pub taxel_mean: Vec<f64>,
    /// 3D-GLCM (mean over encodings) per k.
    pub glcm3d: Vec<f64>,
    /// Encodings of each recording the accuracies and intervals are over (1: as run).
    #[serde(default = "super::one")]
    pub encodings: usize,
    /// 95 % interval of the single taxel's mean per k (bootstrap over recordings and
    /// encodings).
    #[serde(default)]
    pub taxel_mean_interval: Vec<Interval>,
    /// 95 % interval of 3D-GLCM per k (bootstrap over recordings and encodings).
    #[serde(default)]
    pub glcm3d_interval: Vec<Interval>,
    /// Per k, 3D-GLCM against the single taxel (mean over taxels) on the same recordings
    /// and encodings.
    #[serde(default)]
    pub glcm3d_vs_taxel: Vec<Comparison>,
}

/// E8 at every speed, and the `(speed, k)` pairs the data could not support (a training
/// fold smaller than k, say) with their reasons. Each k is evaluated on every encoding, as
/// E1 is; a k that cannot run on one of them is skipped.
///
/// # Errors
/// None of its own: a `k` that cannot run is skipped, not failed.
pub fn e8_neighbours(c: &Context) -> Result<(BySpeed<E8Speed>, Vec<Skip>), Stop> {
    let (mut out, mut skipped) = (BySpeed::new(), Vec::new());
    let tables = c.tables.encoding_tables();
    for &speed in &c.prepared.speeds {
        // Each encoding's evaluations of every k, the encoding as run first.
        let per_encoding: Vec<Vec<AtK>> = tables
            .iter()
            .zip(c.tables.encodings_at(speed))
            .map(|(&encoding, headline)| evaluations(c, speed, encoding, headline))
            .collect();
        let mut e8 = E8Speed {
            k: Vec::new(),
            taxel_mean: Vec::new(),
            glcm3d: Vec::new(),
            encodings: per_encoding.len(),
            taxel_mean_interval: Vec::new(),
            glcm3d_interval: Vec::new(),
            glcm3d_vs_taxel: Vec::new(),
        };
        for (i, &k) in c.params.e8_ks.iter().enumerate() {
            let (mut taxel, mut glcm3d, mut failure) = (Vec::new(), Vec::new(), None);
            for at_k in per_encoding.iter().map(|e| &e[i]) {
                match at_k {
                    (_, Ok(t), Ok(g)) => {
                        taxel.push(t);
                        glcm3d.push(g);
                    }
                    (_, Err(e), _) | (_, _, Err(e)) => {
                        failure.get_or_insert_with(|| e.to_string());
                    }
                }
            }
            if let Some(reason) = failure {
                skipped.push(Skip::Neighbours { k, speed, reason });
                continue;
            }
            let seed = c.params.seed;
            let (t, g) = (
                OverEncodings::of(&taxel, seed)?,
                OverEncodings::of(&glcm3d, seed)?,
            );
            e8.k.push(k);
            e8.taxel_mean.push(t.mean());
            e8.glcm3d.push(g.mean());
            e8.taxel_mean_interval.push(t.combined);
            e8.glcm3d_interval.push(g.combined);
            e8.glcm3d_vs_taxel.push(compare_encodings(
                ("3D-GLCM", &glcm3d),
                ("single taxel", &taxel),
                c.params,
            )?);
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
fn evaluations(
    c: &Context,
    speed: Speed,
    (taxel, glcm3d): (&FeatureTable, &FeatureTable),
    h: &Headline,
) -> Vec<AtK> {
    let own = c.params.knn().params().k;
    let ks = &c.params.e8_ks;
    let others: Vec<usize> = ks.iter().copied().filter(|&k| k != own).collect();
    let folds = c.params.folds();
    let swept = KnnSweep::new(c.params.knn(), &others)
        .ok()
        .and_then(|sweep| {
            let (t, g) = rayon::join(
                || cv_sweep_at(taxel, Columns::EachTaxel, speed, &sweep, folds),
                || cv_sweep_at(glcm3d, Columns::All, speed, &sweep, folds),
            );
            Some(t.ok()?.into_iter().zip(g.ok()?))
        });
    let headline = |k| (k, Ok(h.taxel.clone()), Ok(h.glcm3d.clone()));
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
                || cv_at(taxel, Columns::EachTaxel, speed, &knn, folds),
                || cv_at(glcm3d, Columns::All, speed, &knn, folds),
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
            // The run's own k is E1's headline, over the same encodings.
            let e1 = crate::experiments::e1_accuracy(&c).unwrap();
            let e1 = e1.get(speed).unwrap();
            assert_eq!(e.encodings, run.params.encoder_draws);
            assert!((e.glcm3d[1] - e1.glcm3d).abs() < 1e-12);
            assert!((e.taxel_mean[1] - e1.taxel_mean).abs() < 1e-12);
            assert_eq!(e.glcm3d_vs_taxel.len(), 2);
            for ((p, g), t) in e.glcm3d_vs_taxel.iter().zip(&e.glcm3d).zip(&e.taxel_mean) {
                assert!((p.difference - (g - t)).abs() < 1e-12);
            }
        }
    }

    /// Each k's accuracies, evaluated with that k alone on each encoding and averaged.
    fn alone(c: &Context, speed: Speed, k: usize) -> (f64, f64) {
        let knn = c.params.knn_with_k(k);
        let at = |table, columns| cv_at(table, columns, speed, &knn, c.params.folds());
        let tables = c.tables.encoding_tables();
        let n = tables.len() as f64;
        let (mut taxel, mut glcm3d) = (0.0, 0.0);
        for (t, g) in tables {
            taxel += at(t, Columns::EachTaxel).unwrap().accuracy;
            glcm3d += at(g, Columns::All).unwrap().accuracy;
        }
        (taxel / n, glcm3d / n)
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
                let (taxel, glcm3d) = alone(&c, speed, k);
                assert!((e.taxel_mean[i] - taxel).abs() < 1e-12, "k={k}");
                assert!((e.glcm3d[i] - glcm3d).abs() < 1e-12, "k={k}");
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
            let (taxel, glcm3d) = alone(&c, speed, 1);
            assert!((e.taxel_mean[1] - taxel).abs() < 1e-12);
            assert!((e.glcm3d[1] - glcm3d).abs() < 1e-12);
        }
    }
}
