//! E9 (beyond the paper): the best of the standard candidates of `neurotex compare`
//! (encodings, feature methods, classifiers) beside the paper's method (SA, 3D-GLCM, KNN),
//! cross-validated within each speed and with each speed held out (E6's question).
//!
//! The best candidate is chosen on the same recordings it is scored on, so its accuracy
//! flatters it; both comparisons also run nested selection (the candidates ranked inside
//! each training set), whose accuracy is the honest one for "the best method".

use serde::{Deserialize, Serialize};

use super::{Prepared, Skip, Stop, ValidReproduceParams};
use crate::classify::CvParams;
use crate::compare::candidates::{candidates, CandidateSet};
use crate::compare::signal::baseline_candidates;
use crate::compare::{compare, CompareParams, Comparison, Protocol};

/// E9's two comparisons.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct E9 {
    /// Cross-validation within each speed, ranked by the mean over speeds, with nested
    /// selection.
    pub per_speed: Comparison,
    /// Each speed held out in turn (trained on the others), with nested selection.
    pub held_out: Comparison,
    /// The baselines without spikes on the same folds (`compare --encodings none`),
    /// within each speed and with each speed held out; not among the candidates.
    #[serde(default)]
    pub baselines: Option<Baselines>,
}

impl E9 {
    /// The best baseline without spikes with each speed held out, when they ran.
    pub fn held_out_baseline(&self) -> Option<&crate::compare::Ranked> {
        match &self.baselines {
            Some(Baselines::Compared { held_out, .. }) => Some(&held_out.best),
            _ => None,
        }
    }
}

/// E9's baselines without spikes, or why they were not run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Baselines {
    /// Within each speed and with each speed held out.
    Compared {
        /// Cross-validation within each speed.
        per_speed: Box<Comparison>,
        /// Each speed held out.
        held_out: Box<Comparison>,
    },
    /// A recording's signal could not give a baseline's row.
    Skipped(String),
}

/// Runs E9 on the prepared recordings (both populations encoded).
///
/// # Errors
/// Skipped with one speed; fails when a candidate cannot be evaluated.
pub fn e9_compare(prepared: &Prepared, params: &ValidReproduceParams) -> Result<E9, Stop> {
    if prepared.speeds.len() < 2 {
        return Err(Stop::Skipped(Skip::OneSpeedE9));
    }
    let set = CandidateSet::standard(params.knn, params.seed);
    let pipeline = params.pipeline().params().clone();
    let list = candidates(&prepared.encoded, &prepared.grid, &pipeline, &set, 0.0)?;
    let cv = CvParams {
        repeats: params.e9_repeats,
        ..params.cv
    }
    .check()
    .map_err(crate::Error::from)?;
    let with = |protocol, nested| CompareParams {
        protocol,
        cv,
        group_by: params.group_by.clone(),
        resamples: 2000,
        nested,
    };
    let column = "speed_mm_s".to_string();
    let per = || Protocol::Per(column.clone());
    let held = || Protocol::HoldOut(column.clone());
    let baselines = match prepared
        .signal
        .iter()
        .cloned()
        .collect::<Result<Vec<_>, _>>()
    {
        Ok(rows) => {
            let list = baseline_candidates(
                &rows,
                &prepared.grid,
                &pipeline.features,
                &set.classifiers,
                0.0,
            )?;
            Baselines::Compared {
                per_speed: Box::new(compare(&list, &with(per(), false))?),
                held_out: Box::new(compare(&list, &with(held(), false))?),
            }
        }
        Err(why) => Baselines::Skipped(why),
    };
    Ok(E9 {
        // A pilot too small for folds inside each speed's training folds is ranked
        // without the nested estimate (the held-out comparison trains on other speeds).
        per_speed: compare(&list, &with(per(), true))
            .or_else(|_| compare(&list, &with(per(), false)))?,
        held_out: compare(&list, &with(held(), true))?,
        baselines: Some(baselines),
    })
}
