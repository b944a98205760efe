//! E2: confusion matrices of both approaches at the slowest speed (paper section IV-A).

use serde::{Deserialize, Serialize};

use super::{compare_shares, Comparison, Context, Stop};
use crate::values::Speed;

/// E2: confusion matrices at the slowest speed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct E2 {
    /// Speed, mm/s.
    pub speed: Speed,
    /// Labels in matrix order.
    pub labels: Vec<String>,
    /// Single taxel, summed over taxels and repeats (row = true).
    pub taxel: Vec<Vec<usize>>,
    /// 3D-GLCM, summed over repeats (row = true).
    pub glcm3d: Vec<Vec<usize>>,
    /// Per class in `labels` order, 3D-GLCM against the single taxel (mean over taxels) on
    /// that class's recordings: which method recognises the class better.
    #[serde(default)]
    pub glcm3d_vs_taxel_by_class: Vec<Comparison>,
}

/// E2 from the headline evaluations at the slowest speed.
///
/// # Errors
/// None of its own.
pub fn e2_confusion(c: &Context) -> Result<E2, Stop> {
    let speed = c.prepared.slowest;
    let h = c.tables.at(speed);
    let metas = &c.tables.glcm3d.metas;
    let of_class = |shares: &[(usize, f64)], label: &str| -> Vec<(usize, f64)> {
        shares
            .iter()
            .copied()
            .filter(|&(row, _)| metas[row].label == label)
            .collect()
    };
    let by_class = h
        .glcm3d
        .labels
        .iter()
        .map(|label| {
            compare_shares(
                ("3D-GLCM", &of_class(&h.glcm3d.correct_shares, label)),
                ("single taxel", &of_class(&h.taxel.correct_shares, label)),
                c.params,
            )
        })
        .collect::<crate::error::Result<_>>()?;
    Ok(E2 {
        speed,
        labels: h.glcm3d.labels.clone(),
        taxel: h.taxel.confusion.clone().into_rows(),
        glcm3d: h.glcm3d.confusion.clone().into_rows(),
        glcm3d_vs_taxel_by_class: by_class,
    })
}

#[cfg(test)]
mod tests {
    use super::super::testing::small_run;
    use super::*;

    #[test]
    fn square_matrices_whose_totals_are_the_evaluations() {
        let run = small_run();
        let c = run.context();
        let e2 = e2_confusion(&c).unwrap();
        let n = c.prepared.at(e2.speed).count();
        let repeats = c.params.cv().repeats;
        let taxels = c.prepared.grid.n_taxels();
        let total = |m: &Vec<Vec<usize>>| m.iter().flatten().sum::<usize>();
        assert!(e2.glcm3d.iter().all(|r| r.len() == e2.labels.len()));
        assert_eq!(total(&e2.glcm3d), n * repeats);
        assert_eq!(total(&e2.taxel), n * repeats * taxels);
        // one comparison per class, on that class's recordings
        assert_eq!(e2.glcm3d_vs_taxel_by_class.len(), e2.labels.len());
        for (k, paired) in e2.glcm3d_vs_taxel_by_class.iter().enumerate() {
            assert_eq!(
                paired.recordings,
                e2.glcm3d[k].iter().sum::<usize>() / repeats
            );
        }
    }
}
