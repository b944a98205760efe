//! E4: temporal information removed. The 2D-GLCM of the time-collapsed image against both
//! approaches of E1 (paper section IV-C).

use serde::{Deserialize, Serialize};

use super::tables::cv_at;
use super::{compare, Comparison, Context, Stop};
use crate::analysis::Columns;
use crate::values::BySpeed;

/// E4 at one speed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct E4Speed {
    /// Single taxel mean.
    pub taxel_mean: f64,
    /// 2D-GLCM.
    pub glcm2d: f64,
    /// 3D-GLCM.
    pub glcm3d: f64,
    /// The single taxel (mean over taxels) against 2D-GLCM, on the same recordings.
    pub taxel_vs_glcm2d: Comparison,
    /// 3D-GLCM against 2D-GLCM, on the same recordings.
    pub glcm3d_vs_glcm2d: Comparison,
}

/// E4 at every speed.
///
/// # Errors
/// A classification that cannot run.
pub fn e4_temporal(c: &Context) -> Result<BySpeed<E4Speed>, Stop> {
    let mut out = BySpeed::new();
    for (speed, h) in c.tables.headline.iter() {
        let g2 = cv_at(
            &c.tables.glcm2d,
            Columns::All,
            speed,
            c.params.knn(),
            c.params.folds(),
        )?;
        out.insert(
            speed,
            E4Speed {
                taxel_mean: h.taxel.accuracy,
                glcm2d: g2.accuracy,
                glcm3d: h.glcm3d.accuracy,
                taxel_vs_glcm2d: compare(("single taxel", &h.taxel), ("2D-GLCM", &g2), c.params)?,
                glcm3d_vs_glcm2d: compare(("3D-GLCM", &h.glcm3d), ("2D-GLCM", &g2), c.params)?,
            },
        );
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::super::testing::small_run;
    use super::*;

    #[test]
    fn takes_taxel_and_3d_from_the_headline() {
        let run = small_run();
        let c = run.context();
        let e4 = e4_temporal(&c).unwrap();
        for (speed, e) in e4.iter() {
            assert_eq!(e.glcm3d, c.tables.at(speed).glcm3d.accuracy);
            assert!((0.0..=1.0).contains(&e.glcm2d));
        }
    }
}
