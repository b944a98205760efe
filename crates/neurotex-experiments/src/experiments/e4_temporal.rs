//! E4: temporal information removed. The 2D-GLCM of the time-collapsed image against both
//! approaches of E1 (paper section IV-C).

use serde::{Deserialize, Serialize};

use super::encodings::{Methods, OverEncodings};
use super::{compare_encodings, Comparison, Context, Stop};
use crate::classify::Interval;
use crate::values::BySpeed;

/// E4 at one speed; accuracies are means over encodings, as E1's.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct E4Speed {
    /// Single taxel mean.
    pub taxel_mean: f64,
    /// 2D-GLCM.
    pub glcm2d: f64,
    /// 3D-GLCM.
    pub glcm3d: f64,
    /// 95 % interval of 2D-GLCM (bootstrap over recordings and encodings; the other two
    /// are E1's).
    pub glcm2d_interval: Interval,
    /// The single taxel (mean over taxels) against 2D-GLCM, on the same recordings.
    pub taxel_vs_glcm2d: Comparison,
    /// 3D-GLCM against 2D-GLCM, on the same recordings.
    pub glcm3d_vs_glcm2d: Comparison,
}

/// E4 at every speed, over every encoding.
///
/// # Errors
/// Evaluations of different recordings.
pub fn e4_temporal(c: &Context) -> Result<BySpeed<E4Speed>, Stop> {
    let mut out = BySpeed::new();
    for &speed in &c.prepared.speeds {
        let m = Methods::of(&c.tables.encodings_at(speed));
        let over = |o| OverEncodings::of(o, c.params.seed);
        let (taxel, g2, g3) = (over(&m.taxel)?, over(&m.glcm2d)?, over(&m.glcm3d)?);
        let versus_2d =
            |name, first| compare_encodings((name, first), ("2D-GLCM", &m.glcm2d), c.params);
        let e4 = E4Speed {
            taxel_mean: taxel.mean(),
            glcm2d: g2.mean(),
            glcm3d: g3.mean(),
            glcm2d_interval: g2.combined,
            taxel_vs_glcm2d: versus_2d("single taxel", &m.taxel)?,
            glcm3d_vs_glcm2d: versus_2d("3D-GLCM", &m.glcm3d)?,
        };
        out.insert(speed, e4);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::super::testing::small_run;
    use super::*;

    #[test]
    fn means_over_the_encodings_of_the_headline() {
        let run = small_run();
        let c = run.context();
        let e4 = e4_temporal(&c).unwrap();
        for (speed, e) in e4.iter() {
            let e1 = &c.tables.encodings_at(speed);
            let mean = e1.iter().map(|h| h.glcm3d.accuracy).sum::<f64>() / e1.len() as f64;
            assert!((e.glcm3d - mean).abs() < 1e-12);
            assert!((0.0..=1.0).contains(&e.glcm2d));
            let i = &e.glcm2d_interval;
            assert!(i.lower <= e.glcm2d && e.glcm2d <= i.upper);
        }
    }
}
