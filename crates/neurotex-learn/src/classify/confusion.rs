//! The confusion matrix: counts of (true class, predicted class) pairs.

use serde::{Deserialize, Serialize};

/// `n_classes x n_classes` counts, row = true class, column = predicted class; serialised
/// as the nested rows.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(transparent)]
pub struct ConfusionMatrix(Vec<Vec<usize>>);

impl ConfusionMatrix {
    /// An all-zero matrix for `n_classes` classes.
    pub fn zeros(n_classes: usize) -> Self {
        ConfusionMatrix(vec![vec![0; n_classes]; n_classes])
    }

    /// Counts the pairs `(truth[i], predicted[i])` into a matrix for `n_classes` classes.
    ///
    /// # Panics
    /// If a class index is not below `n_classes` (a caller bug).
    pub fn from_predictions(truth: &[usize], predicted: &[usize], n_classes: usize) -> Self {
        let mut m = Self::zeros(n_classes);
        for (&t, &p) in truth.iter().zip(predicted) {
            m.0[t][p] += 1;
        }
        m
    }

    /// Adds `other`'s counts (for sums over repeats or taxels).
    ///
    /// # Panics
    /// If the two matrices are of different sizes (a caller bug).
    pub fn add(&mut self, other: &ConfusionMatrix) {
        assert_eq!(
            self.0.len(),
            other.0.len(),
            "confusion matrices of one size"
        );
        for (mine, theirs) in self.0.iter_mut().zip(&other.0) {
            for (a, &b) in mine.iter_mut().zip(theirs) {
                *a += b;
            }
        }
    }

    /// Number of classes.
    pub fn n_classes(&self) -> usize {
        self.0.len()
    }

    /// The rows (row = true class).
    pub fn rows(&self) -> &[Vec<usize>] {
        &self.0
    }

    /// Samples counted.
    pub fn total(&self) -> usize {
        self.0.iter().flatten().sum()
    }

    /// Share of samples on the diagonal (0 for an empty matrix).
    pub fn accuracy(&self) -> f64 {
        let correct: usize = (0..self.0.len()).map(|i| self.0[i][i]).sum();
        correct as f64 / self.total().max(1) as f64
    }

    /// The counts as nested rows.
    pub fn into_rows(self) -> Vec<Vec<usize>> {
        self.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_sums_and_accuracy_by_hand() {
        let mut m = ConfusionMatrix::from_predictions(&[0, 0, 1, 2, 2], &[0, 1, 1, 2, 0], 3);
        assert_eq!(m.rows(), &[vec![1, 1, 0], vec![0, 1, 0], vec![1, 0, 1]]);
        assert_eq!(m.total(), 5);
        assert!((m.accuracy() - 0.6).abs() < 1e-15);
        m.add(&ConfusionMatrix::from_predictions(&[1], &[1], 3));
        assert_eq!(m.rows()[1], vec![0, 2, 0]);
        assert_eq!(
            serde_json::to_string(&m).unwrap(),
            "[[1,1,0],[0,2,0],[1,0,1]]"
        );
        assert_eq!(ConfusionMatrix::zeros(0).accuracy(), 0.0);
    }
}
