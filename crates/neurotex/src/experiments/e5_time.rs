//! E5: time to recognition. 3D-GLCM on the first part of the slide against the single
//! taxel on all of it (paper section IV-D).

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::tables::{cv_at, table};
use super::{Context, Stop};
use crate::analysis::Columns;
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
    /// Single taxel mean on the whole slide.
    pub taxel_full: f64,
    /// Smallest fraction at which 3D-GLCM reaches the single taxel's accuracy.
    pub first_match: Option<f64>,
}

/// E5 at every speed.
///
/// # Errors
/// A classification that cannot run.
pub fn e5_time_to_recognition(c: &Context) -> Result<BySpeed<E5Speed>, Stop> {
    let mut out = BySpeed::new();
    for &speed in &c.prepared.speeds {
        let accs = c
            .params
            .e5_fractions
            .iter()
            .map(|&p| accuracy_on_part(c, speed, p))
            .collect::<Result<Vec<_>>>()?;
        let taxel_full = c.tables.at(speed).taxel.accuracy;
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
            taxel_full,
            first_match,
        };
        out.insert(speed, e5);
    }
    Ok(out)
}

/// 3D-GLCM accuracy on the first `fraction` of every slide at `speed`; `None` when a
/// recording's part is shorter than one bin.
fn accuracy_on_part(c: &Context, speed: Speed, fraction: f64) -> Result<Option<f64>> {
    let at_speed: Vec<&Encoded> = c.prepared.at(speed).collect();
    let truncated: Vec<Encoded> = at_speed
        .par_iter()
        .map(|e| Encoded {
            spikes: e
                .spikes
                .truncated(((e.spikes.n_steps as f64) * fraction).floor() as usize),
            ..(*e).clone()
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
        c.params.cv(),
    )?;
    Ok(Some(outcome.accuracy))
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
            if let Some(p) = e.first_match {
                let i = e.fractions.iter().position(|&f| f == p).unwrap();
                assert!(e.glcm3d[i].unwrap() >= e.taxel_full);
            }
        }
    }
}
