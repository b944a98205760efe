//! Several independent simulated datasets: the analyses run on each, and every headline
//! accuracy is reported as its mean over the datasets with a 95 % interval, beside how often
//! each of the paper's claims held.
//!
//! One simulated dataset is one draw of textures' surfaces and of the rig's noise; its
//! accuracies move by several points from one draw to the next (and spike encoding turns
//! even rounding-level input changes into such moves), so a conclusion drawn from one
//! dataset may be a property of that draw. Independent datasets of the same design are
//! what a new experiment would record, so the spread over them is the honest interval for
//! "this design, on this simulated rig". A dataset folder is one draw and gets no such
//! table: its intervals resample recordings instead.

use serde::{Deserialize, Serialize};

use super::{claims, prepare, run_all, Progress, Results, Source, ValidReproduceParams, Verdict};
use crate::classify::{t_interval_over_repeats, Interval};
use crate::error::Result;

/// Runs every analysis on one simulated dataset per seed (`simulate(seed)` gives the
/// design) and returns the first dataset's results with [`AcrossSeeds`] over all of them
/// attached (none with a single seed). The further datasets skip what only the first one's
/// report shows: E5c, E7 and E9
/// ([`ValidReproduceParams::for_further_datasets`]). They run one after another beside the
/// first, so at most two datasets are in memory; the results do not depend on it (every
/// analysis is deterministic), but the first dataset's clock (`timing_s`) is then shared
/// with them.
///
/// # Errors
/// No seed, or an analysis that cannot run on one of the datasets.
pub fn run_seeds(
    simulate: &(dyn Fn(u64) -> Source<'static> + Sync),
    seeds: &[u64],
    params: &ValidReproduceParams,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<Results> {
    let Some((&first, rest)) = seeds.split_first() else {
        return Err(crate::error::ParamError::new("--seeds", "at least 1", 0).into());
    };
    let run = |seed: u64, params: &ValidReproduceParams, progress: &(dyn Fn(Progress) + Sync)| {
        let prepared = prepare(&simulate(seed), params, progress)?;
        run_all(&prepared, params, progress)
    };
    if rest.is_empty() {
        return run(first, params, progress);
    }
    let total = seeds.len();
    let tagged = |p: Progress| match p {
        Progress::Stage(name, n) => {
            progress(Progress::Stage(&format!("dataset 1/{total}: {name}"), n));
        }
        other => progress(other),
    };
    // The further datasets run one after another beside the first, whose analyses leave a
    // core idle at times (E9's ranking, conditions fewer than the cores): at most two
    // datasets are in memory. They report no stages of their own while the first runs;
    // once it is done, one stage counts them (those already done at once).
    let quiet = params.for_further_datasets();
    let further = std::sync::Mutex::new((false, 0usize));
    // A failure on the first dataset ends the run: the further ones not yet begun are not.
    let failed = std::sync::atomic::AtomicBool::new(false);
    let stage = match total {
        2 => "dataset 2/2".to_string(),
        _ => format!("datasets 2-{total}"),
    };
    let (main, others) = rayon::join(
        || {
            let main = run(first, params, &tagged);
            failed.store(main.is_err(), std::sync::atomic::Ordering::Relaxed);
            let mut state = further.lock().expect("progress of the further datasets");
            state.0 = true;
            progress(Progress::Stage(&stage, rest.len()));
            (0..state.1).for_each(|_| progress(Progress::Tick));
            main
        },
        || {
            let mut others = Vec::with_capacity(rest.len());
            for &seed in rest {
                if failed.load(std::sync::atomic::Ordering::Relaxed) {
                    break;
                }
                others.push(run(seed, &quiet, &|_| ())?);
                let mut state = further.lock().expect("progress of the further datasets");
                state.1 += 1;
                if state.0 {
                    progress(Progress::Tick);
                }
            }
            Ok::<_, crate::Error>(others)
        },
    );
    let (mut main, others) = (main?, others?);
    let runs: Vec<(u64, &Results)> = std::iter::once((first, &main))
        .chain(rest.iter().copied().zip(&others))
        .collect();
    main.across_seeds = Some(across_seeds(&runs)?);
    Ok(main)
}

/// One accuracy over the simulated datasets.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SeedAccuracy {
    /// The analysis (`E1`, `E3`, `E4`, `E6`).
    pub analysis: String,
    /// The condition: a speed (`5 mm/s`), a held-out speed, a number of moved taxels.
    pub condition: String,
    /// The method (`3D-GLCM`, `single taxel (mean)`, ...).
    pub method: String,
    /// The accuracy on each dataset, in the order of [`AcrossSeeds::seeds`].
    pub values: Vec<f64>,
    /// Mean over datasets with its Student-t 95 % interval (`None` with one dataset).
    pub interval: Option<Interval>,
}

impl SeedAccuracy {
    /// The mean over datasets.
    pub fn mean(&self) -> f64 {
        self.values.iter().sum::<f64>() / self.values.len().max(1) as f64
    }

    /// The smallest and largest value.
    pub fn range(&self) -> (f64, f64) {
        let lo = self.values.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = self
            .values
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max);
        (lo, hi)
    }
}

/// One claim of the paper judged on each dataset.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ClaimAcrossSeeds {
    /// The claim, as [`claims`] states it.
    pub statement: String,
    /// Its verdict on each dataset, in the order of [`AcrossSeeds::seeds`].
    pub verdicts: Vec<Verdict>,
}

impl ClaimAcrossSeeds {
    /// On how many datasets the claim holds (by test, or in point estimates where untested).
    pub fn holds_on(&self) -> usize {
        self.verdicts.iter().filter(|v| v.holds()).count()
    }
}

/// The headline accuracies and claims over several simulated datasets.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AcrossSeeds {
    /// The simulation seed of each dataset; the first is the one the rest of the report
    /// shows.
    pub seeds: Vec<u64>,
    /// Every headline accuracy present on all datasets.
    pub accuracies: Vec<SeedAccuracy>,
    /// Every claim judged on all datasets.
    pub claims: Vec<ClaimAcrossSeeds>,
}

/// One named accuracy of one run: analysis, condition, method and value.
type Named = (&'static str, String, &'static str, f64);

/// The headline accuracies of one run, in report order: E1 and E4 per speed, E3 with the
/// fewest and the most taxels moved, E6 per held-out speed.
fn headline(r: &Results) -> Vec<Named> {
    let mut out: Vec<Named> = Vec::new();
    for (speed, e) in r.e1.iter() {
        let at = format!("{speed} mm/s");
        out.push(("E1", at.clone(), "single taxel (mean)", e.taxel_mean));
        out.push(("E1", at, "3D-GLCM", e.glcm3d));
    }
    if let Some(e3) = &r.e3 {
        // The fewest and the most taxels moved: the ends of E3's curve.
        let ends = [
            e3.n.first().zip(e3.mean.first()),
            e3.n.last().zip(e3.mean.last()),
        ];
        let mut ends: Vec<(&usize, &f64)> = ends.into_iter().flatten().collect();
        ends.dedup();
        for (n, mean) in ends {
            let at = format!("{} mm/s, {n} taxels moved", e3.speed);
            out.push(("E3", at, "3D-GLCM", *mean));
        }
    }
    for (speed, e) in r.e4.iter() {
        out.push(("E4", format!("{speed} mm/s"), "2D-GLCM", e.glcm2d));
    }
    for (speed, e) in r.e6.iter() {
        let at = format!("{speed} mm/s held out");
        out.push(("E6", at.clone(), "single taxel (mean)", e.taxel_mean));
        out.push(("E6", at, "3D-GLCM", e.glcm3d));
    }
    out
}

/// Gathers runs on independent datasets (`(simulation seed, results)`, the first the main
/// run) into one table: each headline accuracy present on every dataset with its mean and
/// interval, and each claim's verdict per dataset.
///
/// # Errors
/// An accuracy outside [0, 1] (a bug upstream).
pub fn across_seeds(runs: &[(u64, &Results)]) -> crate::error::Result<AcrossSeeds> {
    let per_run: Vec<Vec<Named>> = runs.iter().map(|(_, r)| headline(r)).collect();
    let mut accuracies = Vec::new();
    for (analysis, condition, method, _) in per_run.first().into_iter().flatten() {
        let key = |n: &&Named| n.0 == *analysis && n.1 == *condition && n.2 == *method;
        let values: Option<Vec<f64>> = per_run
            .iter()
            .map(|run| run.iter().find(key).map(|n| n.3))
            .collect();
        let Some(values) = values else { continue };
        let interval = match values.len() {
            1 => None,
            _ => Some(t_interval_over_repeats(&values)?),
        };
        accuracies.push(SeedAccuracy {
            analysis: analysis.to_string(),
            condition: condition.clone(),
            method: method.to_string(),
            values,
            interval,
        });
    }
    Ok(AcrossSeeds {
        seeds: runs.iter().map(|(s, _)| *s).collect(),
        accuracies,
        claims: claims_across(runs),
    })
}

/// Each claim of the first run with its verdict on every run (claims absent from a run are
/// left out: their analysis was skipped there).
fn claims_across(runs: &[(u64, &Results)]) -> Vec<ClaimAcrossSeeds> {
    let judged: Vec<_> = runs.iter().map(|(_, r)| claims(r)).collect();
    let Some(first) = judged.first() else {
        return Vec::new();
    };
    first
        .iter()
        .filter_map(|claim| {
            let verdicts: Option<Vec<Verdict>> = judged
                .iter()
                .map(|run| {
                    run.iter()
                        .find(|c| c.statement == claim.statement)
                        .map(|c| c.verdict)
                })
                .collect();
            Some(ClaimAcrossSeeds {
                statement: claim.statement.clone(),
                verdicts: verdicts?,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiments::testing::small_run;

    fn results() -> Results {
        let s = small_run();
        run_all(&s.prepared, &s.params, &|_| {}).unwrap()
    }

    #[test]
    fn one_run_gives_values_without_interval() {
        let r = results();
        let across = across_seeds(&[(7, &r)]).unwrap();
        assert_eq!(across.seeds, vec![7]);
        assert!(!across.accuracies.is_empty());
        let e1 = &across.accuracies[1];
        assert_eq!(
            (e1.analysis.as_str(), e1.method.as_str()),
            ("E1", "3D-GLCM")
        );
        let first = r.e1.values().next().unwrap();
        assert_eq!(e1.values, vec![first.glcm3d]);
        assert!(across.accuracies.iter().all(|a| a.interval.is_none()));
        assert_eq!(across.claims.len(), claims(&r).len());
    }

    #[test]
    fn interval_is_the_t_interval_of_the_runs_values() {
        let a = results();
        let mut b = a.clone();
        let mut c = a.clone();
        let speed = a.speeds[0];
        let base = a.e1.get(speed).unwrap().glcm3d;
        // Three datasets whose 3D-GLCM accuracy at the first speed is base, base - 0.1,
        // base - 0.2 (clamped into [0, 1] by construction below).
        let base = base.max(0.2);
        let set = |r: &mut Results, v: f64| {
            let mut e1 = r.e1.get(speed).unwrap().clone();
            e1.glcm3d = v;
            r.e1.insert(speed, e1);
        };
        let mut a = a;
        set(&mut a, base);
        set(&mut b, base - 0.1);
        set(&mut c, base - 0.2);
        let across = across_seeds(&[(0, &a), (1, &b), (2, &c)]).unwrap();
        let row = across
            .accuracies
            .iter()
            .find(|x| {
                x.analysis == "E1"
                    && x.method == "3D-GLCM"
                    && x.condition.starts_with(&speed.to_string())
            })
            .unwrap();
        let i = row.interval.as_ref().unwrap();
        // Mean base - 0.1, sd 0.1, t(0.975, 2) = 4.302653: half width 0.1 * 4.302653 / sqrt 3.
        let half = 0.1 * 4.302_652_729_749_464 / 3f64.sqrt();
        assert!((i.estimate - (base - 0.1)).abs() < 1e-12);
        assert!((i.lower - (base - 0.1 - half).max(0.0)).abs() < 1e-9);
        assert!((i.upper - (base - 0.1 + half).min(1.0)).abs() < 1e-9);
        assert_eq!(row.range(), (base - 0.2, base));
    }
}
