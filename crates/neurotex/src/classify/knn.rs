//! k-nearest neighbours, Euclidean distance, majority vote.
//!
//! Ties are broken deterministically: among neighbours at equal distance the earlier
//! training sample comes first; among classes with equal votes the one with the nearest
//! member wins. Features are z-scored with the training set's mean and population standard
//! deviation (a feature constant in training is only centred).

use crate::error::{ClassifyError, ParamError};

/// KNN parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KnnParams {
    /// Neighbours (the paper's 5).
    pub k: usize,
    /// Z-score features with training statistics (on by default; the paper does not say,
    /// and without it the spike rate in Hz swamps the other features).
    pub standardize: bool,
}

impl Default for KnnParams {
    fn default() -> Self {
        KnnParams {
            k: 5,
            standardize: true,
        }
    }
}

impl KnnParams {
    /// Checks the rule: at least one neighbour.
    ///
    /// # Errors
    /// The rule broken.
    pub fn check(&self) -> Result<(), ParamError> {
        if self.k == 0 {
            return Err(ParamError::new("k", "k must be at least 1", self.k));
        }
        Ok(())
    }
}

/// The unfitted classifier.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Knn {
    /// Its parameters.
    pub params: KnnParams,
}

/// A fitted KNN: the scaled training set and its labels.
#[derive(Debug, Clone, PartialEq)]
pub struct KnnModel {
    k: usize,
    dims: usize,
    mean: Vec<f64>,
    inv_std: Vec<f64>,
    train: Vec<f64>,
    labels: Vec<usize>,
    n_classes: usize,
}

impl Knn {
    /// A classifier with `params`.
    pub fn new(params: KnnParams) -> Self {
        Knn { params }
    }

    /// Fits on `x` (row-major, `dims` features per sample) with class indices `y`.
    ///
    /// # Errors
    /// `k` larger than the training set, empty or ragged input, non-finite features.
    pub fn fit(&self, x: &[f64], dims: usize, y: &[usize]) -> Result<KnnModel, ClassifyError> {
        self.params
            .check()
            .map_err(|e| ClassifyError::BadFeatures(e.to_string()))?;
        let n = y.len();
        if n == 0 || dims == 0 {
            return Err(ClassifyError::Empty { what: "train on" });
        }
        if x.len() != n * dims {
            return Err(ClassifyError::BadFeatures(format!(
                "{} feature values for {n} samples of {dims} features",
                x.len()
            )));
        }
        if let Some(pos) = x.iter().position(|v| !v.is_finite()) {
            return Err(ClassifyError::BadFeatures(format!(
                "feature {} of training sample {} is not finite",
                pos % dims,
                pos / dims
            )));
        }
        if self.params.k > n {
            return Err(ClassifyError::KTooLarge {
                k: self.params.k,
                n_train: n,
            });
        }
        let (mean, inv_std) = if self.params.standardize {
            let mut mean = vec![0.0; dims];
            for row in x.chunks_exact(dims) {
                for (m, &v) in mean.iter_mut().zip(row) {
                    *m += v;
                }
            }
            mean.iter_mut().for_each(|m| *m /= n as f64);
            let mut var = vec![0.0; dims];
            for row in x.chunks_exact(dims) {
                for ((s, &v), &m) in var.iter_mut().zip(row).zip(&mean) {
                    *s += (v - m) * (v - m);
                }
            }
            let inv_std = var
                .iter()
                .map(|&s| {
                    let sd = (s / n as f64).sqrt();
                    if sd > 0.0 {
                        1.0 / sd
                    } else {
                        1.0
                    }
                })
                .collect();
            (mean, inv_std)
        } else {
            (vec![0.0; dims], vec![1.0; dims])
        };
        let mut train = x.to_vec();
        for row in train.chunks_exact_mut(dims) {
            for ((v, &m), &s) in row.iter_mut().zip(&mean).zip(&inv_std) {
                *v = (*v - m) * s;
            }
        }
        Ok(KnnModel {
            k: self.params.k,
            dims,
            mean,
            inv_std,
            train,
            labels: y.to_vec(),
            n_classes: y.iter().max().map_or(0, |&m| m + 1),
        })
    }
}

impl KnnModel {
    /// Predicts the class of each row of `x`.
    ///
    /// # Panics
    /// If `x` is not whole rows of the training dimension (a caller bug).
    pub fn predict(&self, x: &[f64]) -> Vec<usize> {
        assert_eq!(
            x.len() % self.dims,
            0,
            "samples must have the training dimension"
        );
        let mut scaled = vec![0.0; self.dims];
        let mut best: Vec<(f64, usize)> = Vec::with_capacity(self.k + 1);
        let mut votes = vec![0usize; self.n_classes];
        x.chunks_exact(self.dims)
            .map(|row| {
                for ((s, &v), (&m, &is)) in scaled
                    .iter_mut()
                    .zip(row)
                    .zip(self.mean.iter().zip(&self.inv_std))
                {
                    *s = (v - m) * is;
                }
                best.clear();
                for (i, t) in self.train.chunks_exact(self.dims).enumerate() {
                    let d: f64 = t.iter().zip(&scaled).map(|(a, b)| (a - b) * (a - b)).sum();
                    if best.len() == self.k && d >= best[self.k - 1].0 {
                        continue;
                    }
                    // Insert after every neighbour at distance <= d: earlier samples win ties.
                    let pos = best.partition_point(|&(bd, _)| bd <= d);
                    best.insert(pos, (d, i));
                    best.truncate(self.k);
                }
                votes.fill(0);
                for &(_, i) in &best {
                    votes[self.labels[i]] += 1;
                }
                let top = *votes.iter().max().unwrap_or(&0);
                // Nearest-first order: the first neighbour of a top-voted class wins.
                best.iter()
                    .map(|&(_, i)| self.labels[i])
                    .find(|&c| votes[c] == top)
                    .unwrap_or(0)
            })
            .collect()
    }
}
