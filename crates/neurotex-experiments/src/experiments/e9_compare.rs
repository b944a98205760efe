//! E9 (beyond the paper): the best of the standard candidates of `neurotex compare`
//! (encodings, feature methods, classifiers) beside the paper's method (SA, 3D-GLCM, KNN),
//! cross-validated within each speed and with each speed held out (E6's question).
//!
//! The best candidate is chosen on the same recordings it is scored on, so its accuracy
//! flatters it; the held-out comparison also runs nested selection (the candidates ranked
//! inside each training set), whose accuracy is the honest one for "the best method".

use serde::{Deserialize, Serialize};

use super::{Prepared, Skip, Stop, ValidReproduceParams};
use crate::classify::CvParams;
use crate::compare::candidates::{candidates, CandidateSet};
use crate::compare::{compare, CompareParams, Comparison, Protocol};

/// E9's two comparisons.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct E9 {
    /// Cross-validation within each speed, ranked by the mean over speeds.
    pub per_speed: Comparison,
    /// Each speed held out in turn (trained on the others), with nested selection.
    pub held_out: Comparison,
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
    Ok(E9 {
        per_speed: compare(&list, &with(Protocol::Per(column.clone()), false))?,
        held_out: compare(&list, &with(Protocol::HoldOut(column), true))?,
    })
}
