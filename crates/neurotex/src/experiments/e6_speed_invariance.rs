//! E6: speed invariance. Train on the other speeds, test on one (paper section IV-E).

use serde::{Deserialize, Serialize};

use super::{compare, Comparison, Context, Skip, Stop};
use crate::analysis::{evaluate, Columns, Split};
use crate::classify::Interval;
use crate::recording::Selection;
use crate::values::{BySpeed, Speed};

/// E6 at one held-out speed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct E6Speed {
    /// Training speeds.
    pub train: Vec<Speed>,
    /// Single taxel mean.
    pub taxel_mean: f64,
    /// 3D-GLCM.
    pub glcm3d: f64,
    /// 95 % interval of the single taxel's mean (bootstrap over the held-out recordings).
    pub taxel_mean_interval: Interval,
    /// 95 % interval of 3D-GLCM (bootstrap over the held-out recordings).
    pub glcm3d_interval: Interval,
    /// 3D-GLCM against the single taxel (mean over taxels) on the held-out recordings.
    pub glcm3d_vs_taxel: Comparison,
}

/// E6 with every speed held out in turn.
///
/// # Errors
/// Skipped with a single speed; a classification that cannot run (a test class never
/// trained on, say).
pub fn e6_speed_invariance(c: &Context) -> Result<BySpeed<E6Speed>, Stop> {
    let speeds = &c.prepared.speeds;
    if speeds.len() < 2 {
        return Err(Skip::OneSpeed.into());
    }
    let mut out = BySpeed::new();
    for &test in speeds {
        let train: Vec<Speed> = speeds.iter().copied().filter(|&s| s != test).collect();
        let split = Split::Where {
            train: Selection::speeds(&train),
            test: Selection::speeds(&[test]),
        };
        let knn = c.params.knn();
        let taxel = evaluate(&c.tables.taxel, Columns::EachTaxel, &split, knn)?;
        let glcm3d = evaluate(&c.tables.glcm3d, Columns::All, &split, knn)?;
        let e6 = E6Speed {
            train,
            taxel_mean: taxel.accuracy,
            glcm3d: glcm3d.accuracy,
            taxel_mean_interval: taxel.accuracy_interval(c.params.seed)?,
            glcm3d_interval: glcm3d.accuracy_interval(c.params.seed)?,
            glcm3d_vs_taxel: compare(("3D-GLCM", &glcm3d), ("single taxel", &taxel), c.params)?,
        };
        out.insert(test, e6);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::super::testing::small_run;
    use super::*;

    #[test]
    fn each_speed_held_out_and_trained_on_the_others() {
        let run = small_run();
        let e6 = e6_speed_invariance(&run.context()).unwrap();
        assert_eq!(e6.len(), 2);
        for (test, e) in e6.iter() {
            assert!(!e.train.contains(&test) && e.train.len() == 1);
        }
    }
}
