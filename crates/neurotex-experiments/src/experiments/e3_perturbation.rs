//! E3: spatial perturbation. In every recording of the slowest speed, n taxels chosen at
//! random swap places; 3D-GLCM accuracy falls as the spatial structure is lost (paper
//! section IV-B).

use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::{compare_shares, Comparison, Context, Skip, Stop};
use crate::analysis::{
    evaluate, seeded_bootstrap_over_encodings, Columns, FeatureTable, Outcome, Split,
};
use crate::classify::Interval;
use crate::error::Result;
use crate::pipeline::{Encoded, FeatureExtractor, Method, Quantised};
use crate::values::Speed;

/// E3: spatial perturbation at the slowest speed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct E3 {
    /// Speed, mm/s.
    pub speed: Speed,
    /// Random draws per n.
    pub repeats: usize,
    /// Taxels moved.
    pub n: Vec<usize>,
    /// Mean 3D-GLCM accuracy over perturbations, per n.
    pub mean: Vec<f64>,
    /// Standard deviation over perturbations, per n.
    pub std: Vec<f64>,
    /// Per n, the 95 % interval of `mean`: a percentile bootstrap that draws one
    /// perturbation and then the recordings ([`crate::classify::bootstrap_over_encodings`]),
    /// so it holds both the recordings' and the draws' variability.
    #[serde(default)]
    pub interval: Vec<Interval>,
    /// Unperturbed 3D-GLCM (E1).
    pub glcm3d: f64,
    /// Single taxel mean (E1).
    pub taxel_mean: f64,
    /// Per n, the unperturbed 3D-GLCM against 3D-GLCM with n taxels moved, on the same
    /// recordings (each recording's share right pooled over its draws).
    #[serde(default)]
    pub unperturbed_vs_moved: Vec<Comparison>,
}

/// The counts of taxels to move that were asked for but exceed the grid's taxels (a 3x3
/// grid cannot move 16), said in the report's Skipped list rather than dropped unseen.
pub fn counts_beyond_the_grid(c: &Context) -> Option<Skip> {
    let taxels = c.prepared.grid.taxels().count();
    let counts: Vec<usize> = c
        .params
        .e3_counts
        .iter()
        .copied()
        .filter(|&n| n > taxels)
        .collect();
    (!counts.is_empty() && taxels >= 2).then_some(Skip::TaxelsBeyondTheGrid { counts, taxels })
}

/// E3 for every asked n the grid allows (2 up to its taxel count), each over
/// `e3_repeats` draws with a single CV shuffle each.
///
/// # Errors
/// Skipped when the grid has fewer than 2 taxels; a classification that cannot run.
pub fn e3_perturbation(c: &Context) -> Result<E3, Stop> {
    let speed = c.prepared.slowest;
    let taxels: Vec<usize> = c.prepared.grid.taxels().collect();
    let counts: Vec<usize> = c
        .params
        .e3_counts
        .iter()
        .copied()
        .filter(|&n| n >= 2 && n <= taxels.len())
        .collect();
    if counts.is_empty() {
        return Err(Skip::TooFewTaxels.into());
    }
    let slow: Vec<&Encoded> = c.prepared.at(speed).collect();
    let h = c.tables.at(speed);
    // The perturbed tables hold only this speed's recordings; E1's rows name them in the
    // table of all recordings, in the same order.
    let rows = c.tables.glcm3d.rows_at(&[speed]);
    // Each recording's gray levels once: a draw only moves them between cells.
    let extractor = c
        .params
        .pipeline()
        .extractor(&slow[0].spikes.grid())
        .map_err(crate::Error::from)?;
    let levels = slow
        .par_iter()
        .map(|e| extractor.quantised_3d(e))
        .collect::<Result<Vec<_>>>()?;
    let moving = Moving {
        slow: &slow,
        levels: &levels,
        extractor: &extractor,
        taxels: &taxels,
    };
    let (mut mean, mut std, mut interval, mut unperturbed_vs_moved) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for &n in &counts {
        // The draws side by side: each is seeded by (n, draw, recording).
        let outcomes = (0..c.params.e3_repeats)
            .into_par_iter()
            .map(|rep| perturbed(c, &moving, n, rep))
            .collect::<Result<Vec<Outcome>>>()?;
        let accs: Vec<f64> = outcomes.iter().map(|o| o.accuracy).collect();
        let m = accs.iter().sum::<f64>() / accs.len() as f64;
        let var = accs.iter().map(|a| (a - m).powi(2)).sum::<f64>() / accs.len() as f64;
        mean.push(m);
        std.push(var.sqrt());
        let per_draw: Vec<Vec<f64>> = outcomes
            .iter()
            .map(|o| o.correct_shares.iter().map(|&(_, s)| s).collect())
            .collect();
        let recordings = per_draw.first().map_or(0, Vec::len);
        interval.push(
            seeded_bootstrap_over_encodings(&per_draw, c.params.seed)?
                .or_wilson_at_the_bounds(recordings),
        );
        let moved = pooled_shares(&outcomes, &rows);
        unperturbed_vs_moved.push(compare_shares(
            ("unperturbed 3D-GLCM", &h.glcm3d.correct_shares),
            (&format!("3D-GLCM, {n} taxels moved"), &moved),
            c.params,
        )?);
    }
    Ok(E3 {
        speed,
        repeats: c.params.e3_repeats,
        n: counts,
        mean,
        std,
        interval,
        glcm3d: h.glcm3d.accuracy,
        taxel_mean: h.taxel.accuracy,
        unperturbed_vs_moved,
    })
}

/// Each recording's share of right predictions over all `outcomes` (evaluations of the
/// same recordings), named by `rows[i]` for the outcomes' row `i`.
fn pooled_shares(outcomes: &[Outcome], rows: &[usize]) -> Vec<(usize, f64)> {
    let mut sums = vec![0.0; rows.len()];
    for o in outcomes {
        for &(i, share) in &o.correct_shares {
            sums[i] += share;
        }
    }
    let draws = outcomes.len().max(1) as f64;
    rows.iter()
        .zip(sums)
        .map(|(&r, s)| (r, s / draws))
        .collect()
}

/// The slowest speed's recordings with what a draw needs to move their taxels.
struct Moving<'a> {
    slow: &'a [&'a Encoded],
    /// Each recording's gray levels, per population.
    levels: &'a [Vec<Quantised>],
    extractor: &'a FeatureExtractor,
    taxels: &'a [usize],
}

/// 3D-GLCM evaluated (one CV shuffle) after draw `rep` of moving `n` taxels in every
/// recording; each recording gets its own seeded draw. The features are those of the
/// recordings' spike trains with the taxels moved ([`crate::encode::SpikeTrains::permuted`]),
/// counted from the gray levels moved.
fn perturbed(c: &Context, m: &Moving, n: usize, rep: usize) -> Result<Outcome> {
    let rows = m
        .slow
        .par_iter()
        .zip(m.levels)
        .enumerate()
        .map(|(i, (e, levels))| {
            let seed = c.params.seed ^ ((n as u64) << 40) ^ ((rep as u64) << 20) ^ i as u64;
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let perm = perturbation(m.taxels, e.spikes.cells(), n, &mut rng);
            m.extractor.glcm3d_moved(levels, &perm)
        })
        .collect::<Result<Vec<_>>>()?;
    let metas = m.slow.iter().map(|e| e.meta.clone()).collect();
    let features = FeatureTable::from_rows(m.extractor, Method::Glcm3d, metas, &rows);
    let split = Split::CrossValidation {
        speeds: None,
        cv: c.params.cv_once(),
        group_by: c.params.group_by.clone(),
    };
    evaluate(&features, Columns::All, &split, c.params.knn())
}

/// A permutation of the cells that moves `n` randomly chosen taxels: their positions are
/// shuffled among themselves and then rotated by one, so every chosen taxel lands on a
/// cell that was another's.
fn perturbation(taxels: &[usize], cells: usize, n: usize, rng: &mut ChaCha8Rng) -> Vec<usize> {
    let mut perm: Vec<usize> = (0..cells).collect();
    let chosen: Vec<usize> = taxels.choose_multiple(rng, n).copied().collect();
    for (k, &from) in chosen.iter().enumerate() {
        perm[from] = chosen[(k + 1) % chosen.len()];
    }
    perm
}

#[cfg(test)]
mod tests {
    use super::super::testing::small_run;
    use super::*;

    #[test]
    fn counts_beyond_the_grid_are_said_not_dropped() {
        let run = small_run();
        let taxels = run.prepared.grid.taxels().count();
        let params = super::super::ReproduceParams {
            e3_counts: vec![4, taxels, taxels + 1, 99],
            ..super::super::ReproduceParams::default()
        }
        .check()
        .unwrap();
        let c = Context {
            params: &params,
            ..run.context()
        };
        let skip = counts_beyond_the_grid(&c).expect("two counts beyond the grid");
        assert_eq!(
            skip,
            Skip::TaxelsBeyondTheGrid {
                counts: vec![taxels + 1, 99],
                taxels
            }
        );
        assert_eq!(skip.key(), format!("e3 n > {taxels}"));
        assert!(counts_beyond_the_grid(&run.context()).is_none());
    }

    #[test]
    fn every_chosen_taxel_moves_and_no_other_cell_does() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let taxels = [0, 2, 3, 5, 6, 7];
        for n in 2..=taxels.len() {
            let perm = perturbation(&taxels, 8, n, &mut rng);
            let moved: Vec<usize> = (0..8).filter(|&i| perm[i] != i).collect();
            assert_eq!(moved.len(), n);
            assert!(moved.iter().all(|m| taxels.contains(m)));
            let mut sorted = perm.clone();
            sorted.sort();
            assert_eq!(sorted, (0..8).collect::<Vec<_>>());
        }
    }

    #[test]
    fn one_mean_and_spread_per_allowed_count() {
        let run = small_run();
        let e3 = e3_perturbation(&run.context()).unwrap();
        assert_eq!(e3.n, vec![4, 16]);
        assert_eq!((e3.mean.len(), e3.std.len()), (2, 2));
        assert!(e3.mean.iter().all(|a| (0.0..=1.0).contains(a)));
        // paired on the slowest speed's recordings, the drop is the difference of the means
        assert_eq!(e3.unperturbed_vs_moved.len(), 2);
        for (c, m) in e3.unperturbed_vs_moved.iter().zip(&e3.mean) {
            assert_eq!(c.recordings, run.prepared.at(e3.speed).count());
            assert!((c.difference - (e3.glcm3d - m)).abs() < 1e-12);
        }
    }
}
