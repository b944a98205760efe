//! Numerical sensitivity: the headline evaluations repeated on spikes of an input changed
//! by a rounding-level relative amount. Spike trains are a discontinuous function of the
//! input (a threshold crossing moves by a whole step), so accuracies move by far more than
//! the change; the size of that move is the floor below which no difference means anything.

use serde::{Deserialize, Serialize};

use super::tables::{cv_at, table};
use super::{Context, Stop};
use crate::analysis::Columns;
use crate::error::ClassifyError;
use crate::pipeline::Method;
use crate::values::BySpeed;

/// The headline accuracies at one speed, as run and on the perturbed input.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SensitivitySpeed {
    /// 3D-GLCM as run.
    pub glcm3d: f64,
    /// 3D-GLCM on the perturbed input.
    pub glcm3d_perturbed: f64,
    /// Single taxel, mean over taxels, as run.
    pub taxel_mean: f64,
    /// Single taxel, mean over taxels, on the perturbed input.
    pub taxel_mean_perturbed: f64,
    /// Recordings whose spike trains changed at all.
    pub recordings_changed: usize,
    /// Recordings at this speed.
    pub recordings: usize,
}

/// The sensitivity check at every speed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Sensitivity {
    /// The relative change of every encoder input.
    pub relative_change: f64,
    /// Per speed.
    pub speeds: BySpeed<SensitivitySpeed>,
    /// The largest move of any accuracy, in accuracy units (0..1).
    pub largest_move: f64,
}

/// The sensitivity check, when the run asked for it (`None` otherwise).
///
/// # Errors
/// A classification that cannot run.
pub fn sensitivity(c: &Context) -> Result<Option<Sensitivity>, Stop> {
    let (Some(eps), Some(perturbed)) = (c.params.sensitivity, &c.prepared.perturbed) else {
        return Ok(None);
    };
    if perturbed.len() != c.prepared.encoded.len() {
        let (first, second) = ("the run".to_string(), "its perturbed twin".to_string());
        return Err(Stop::Failed(
            ClassifyError::Unpaired { first, second }.into(),
        ));
    }
    let glcm3d = table(perturbed, Method::Glcm3d, c.params)?;
    let taxel = table(perturbed, Method::Taxel, c.params)?;
    let (knn, cv) = (c.params.knn(), c.params.folds());
    let mut speeds = BySpeed::new();
    let mut largest_move: f64 = 0.0;
    for (speed, h) in c.tables.headline.iter() {
        let g = cv_at(&glcm3d, Columns::All, speed, knn, cv)?.accuracy;
        let t = cv_at(&taxel, Columns::EachTaxel, speed, knn, cv)?.accuracy;
        let pairs = c.prepared.encoded.iter().zip(perturbed);
        let at_speed = pairs.filter(|(e, _)| e.meta.speed() == Some(speed));
        let (mut changed, mut recordings) = (0, 0);
        for (e, p) in at_speed {
            recordings += 1;
            changed += usize::from(e.spikes != p.spikes);
        }
        largest_move = largest_move
            .max((g - h.glcm3d.accuracy).abs())
            .max((t - h.taxel.accuracy).abs());
        let entry = SensitivitySpeed {
            glcm3d: h.glcm3d.accuracy,
            glcm3d_perturbed: g,
            taxel_mean: h.taxel.accuracy,
            taxel_mean_perturbed: t,
            recordings_changed: changed,
            recordings,
        };
        speeds.insert(speed, entry);
    }
    Ok(Some(Sensitivity {
        relative_change: eps,
        speeds,
        largest_move,
    }))
}

#[cfg(test)]
mod tests {
    use super::super::testing::small_run;
    use super::*;

    #[test]
    fn every_speed_compared_and_the_largest_move_is_the_largest_difference() {
        let run = small_run();
        let s = sensitivity(&run.context()).unwrap().expect("asked for");
        assert_eq!(s.relative_change, 1e-12);
        assert_eq!(s.speeds.len(), 2);
        let mut largest: f64 = 0.0;
        for e in s.speeds.values() {
            assert_eq!(e.recordings, 24);
            assert!(e.recordings_changed <= e.recordings);
            largest = largest
                .max((e.glcm3d - e.glcm3d_perturbed).abs())
                .max((e.taxel_mean - e.taxel_mean_perturbed).abs());
        }
        assert_eq!(s.largest_move, largest);
    }
}
