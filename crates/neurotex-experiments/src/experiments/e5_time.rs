//! E5: time to recognition. 3D-GLCM on the first part of the slide against the single
//! taxel on all of it (paper section IV-D).

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::tables::{cv_at, table};
use super::{compare, Comparison, Context, Stop};
use crate::analysis::{Columns, Outcome};
use crate::classify::Interval;
use crate::error::Result;
use crate::pipeline::{Encoded, Method};
use crate::values::{BySpeed, Speed};

/// E5 at one speed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct E5Speed {
    /// Fractions of the slide used.
    pub fractions: Vec<f64>,
    /// 3D-GLCM accuracy per fraction (`null` where the fraction is shorter than one bin).
    pub glcm3d: Vec<Option<f64>>,
    /// 95 % interval of each share's 3D-GLCM accuracy (bootstrap over recordings).
    #[serde(default)]
    pub glcm3d_interval: Vec<Option<Interval>>,
    /// Single taxel mean on the whole slide.
    pub taxel_full: f64,
    /// 95 % interval of `taxel_full` (bootstrap over recordings).
    #[serde(default)]
    pub taxel_full_interval: Option<Interval>,
    /// Smallest fraction at which 3D-GLCM reaches the single taxel's accuracy.
    pub first_match: Option<f64>,
    /// 3D-GLCM on the largest fraction against the smallest one longer than a bin, on the
    /// same recordings; `None` with fewer than two such fractions.
    #[serde(default)]
    pub longest_vs_shortest: Option<Comparison>,
}

/// E5 at every speed.
///
/// # Errors
/// A classification that cannot run.
pub fn e5_time_to_recognition(c: &Context) -> Result<BySpeed<E5Speed>, Stop> {
    let mut out = BySpeed::new();
    for &speed in &c.prepared.speeds {
        let outcomes = c
            .params
            .e5_fractions
            .iter()
            .map(|&p| outcome_on_part(c, speed, p))
            .collect::<Result<Vec<_>>>()?;
        let accs: Vec<Option<f64>> = outcomes
            .iter()
            .map(|o| o.as_ref().map(|o| o.accuracy))
            .collect();
        let intervals = outcomes
            .iter()
            .map(|o| {
                o.as_ref()
                    .map(|o| o.accuracy_interval(c.params.seed))
                    .transpose()
            })
            .collect::<Result<Vec<_>>>()?;
        let taxel = &c.tables.at(speed).taxel;
        let taxel_full = taxel.accuracy;
        let first_match = c
            .params
            .e5_fractions
            .iter()
            .zip(&accs)
            .find(|(_, a)| a.is_some_and(|a| a >= taxel_full))
            .map(|(&p, _)| p);
        let e5 = E5Speed {
            fractions: c.params.e5_fractions.clone(),
            glcm3d: accs,
            glcm3d_interval: intervals,
            taxel_full,
            taxel_full_interval: Some(taxel.accuracy_interval(c.params.seed)?),
            first_match,
            longest_vs_shortest: longest_vs_shortest(c, &c.params.e5_fractions, &outcomes)?,
        };
        out.insert(speed, e5);
    }
    Ok(out)
}

/// The paired comparison of the largest fraction's evaluation with the smallest's, among
/// the fractions that could be evaluated.
fn longest_vs_shortest(
    c: &Context,
    fractions: &[f64],
    outcomes: &[Option<Outcome>],
) -> Result<Option<Comparison>> {
    let mut evaluated: Vec<(f64, &Outcome)> = fractions
        .iter()
        .zip(outcomes)
        .filter_map(|(&p, o)| o.as_ref().map(|o| (p, o)))
        .collect();
    evaluated.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (Some(&(short, shortest)), Some(&(long, longest))) = (evaluated.first(), evaluated.last())
    else {
        return Ok(None);
    };
    if short == long {
        return Ok(None);
    }
    let name = |p: f64| format!("{:.0} % of the slide", 100.0 * p);
    Ok(Some(compare(
        (&name(long), longest),
        (&name(short), shortest),
        c.params,
    )?))
}

/// 3D-GLCM evaluated on the first `fraction` of every slide at `speed`; `None` when a
/// recording's part is shorter than one bin.
fn outcome_on_part(c: &Context, speed: Speed, fraction: f64) -> Result<Option<Outcome>> {
    let at_speed: Vec<&Encoded> = c.prepared.at(speed).collect();
    let truncated: Vec<Encoded> = at_speed
        .par_iter()
        .map(|e| {
            let n_steps = ((e.spikes.n_steps as f64) * fraction).floor() as usize;
            e.map_spikes(|s| s.truncated(n_steps))
        })
        .collect();
    let bin = c.params.pipeline.volume.bin_ms;
    if truncated.iter().any(|e| e.spikes.n_steps < bin) {
        return Ok(None);
    }
    let features = table(&truncated, Method::Glcm3d, c.params)?;
    let outcome = cv_at(
        &features,
        Columns::All,
        speed,
        c.params.knn(),
        c.params.folds(),
    )?;
    Ok(Some(outcome))
}

#[cfg(test)]
mod tests {
    use super::super::testing::small_run;
    use super::*;

    #[test]
    fn the_whole_slide_gives_the_headline_and_the_first_match_is_reached() {
        let run = small_run();
        let c = run.context();
        let e5 = e5_time_to_recognition(&c).unwrap();
        for (speed, e) in e5.iter() {
            assert_eq!(e.fractions, [0.5, 1.0]);
            let whole = e.glcm3d[1].expect("the whole slide is longer than a bin");
            assert_eq!(whole, c.tables.at(speed).glcm3d.accuracy);
            let paired = e
                .longest_vs_shortest
                .as_ref()
                .expect("two fractions evaluated");
            let half = e.glcm3d[0].expect("half the slide is longer than a bin");
            assert!((paired.difference - (whole - half)).abs() < 1e-12);
            if let Some(p) = e.first_match {
                let i = e.fractions.iter().position(|&f| f == p).unwrap();
                assert!(e.glcm3d[i].unwrap() >= e.taxel_full);
            }
        }
    }
}
