//! k-nearest neighbours, Euclidean distance, majority vote.
//!
//! Ties are broken deterministically: among neighbours at equal distance the earlier
//! training sample comes first; among classes with equal votes the one with the nearest
//! member wins. Features are z-scored with the training set's mean and population standard
//! deviation (a feature constant in training is only centred).

use serde::{Deserialize, Serialize};

use super::{Classifier, Predict};
use crate::error::{ClassifyError, ParamError};

/// KNN parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
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
    /// Checks the rule (at least one neighbour) and returns the unfitted classifier.
    ///
    /// # Errors
    /// The rule broken.
    pub fn check(self) -> Result<Knn, ParamError> {
        if self.k == 0 {
            return Err(ParamError::new("k", "k must be at least 1", self.k));
        }
        Ok(Knn { params: self })
    }
}

/// The unfitted classifier, with parameters that passed [`KnnParams::check`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Knn {
    params: KnnParams,
}

/// A fitted KNN: the scaled training set and its labels.
#[derive(Debug, Clone, PartialEq)]
pub struct KnnModel {
    k: usize,
    dims: usize,
    mean: Vec<f64>,
    inv_std: Vec<f64>,
    /// The scaled training set stored feature-major (`dims x n`), so the distances of one
    /// query to every training sample are computed a feature at a time, vectorised.
    columns: Vec<f64>,
    labels: Vec<usize>,
    n_classes: usize,
    /// Step of the scattered visiting order, coprime to the training set's size.
    stride: usize,
}

/// Whether `a` comes before `b` in the order (distance, training index).
fn closer(a: (f64, usize), b: (f64, usize)) -> bool {
    a.0 < b.0 || (a.0 == b.0 && a.1 < b.1)
}

/// Training samples visited in the scattered order before the rest are read in blocks.
const SEEDS: usize = 16;
/// Distances compared at a time while the rest are read.
const LANES: usize = 4;

/// Puts `key` into `best` (at most `k` keys, nearest first) if it belongs among them.
#[inline(always)]
pub(super) fn insert(best: &mut Vec<(f64, usize)>, k: usize, key: (f64, usize)) {
    if best.len() == k && !closer(key, best[k - 1]) {
        return;
    }
    if best.len() < k {
        best.push(key);
    } else {
        best[k - 1] = key;
    }
    let mut pos = best.len() - 1;
    while pos > 0 && closer(best[pos], best[pos - 1]) {
        best.swap(pos, pos - 1);
        pos -= 1;
    }
}

/// The majority class among the neighbours `best` (nearest first), with each class's votes
/// in `votes`; among classes with equal votes, the one with the nearest member.
pub(super) fn majority(best: &[(f64, usize)], labels: &[usize], votes: &mut [usize]) -> usize {
    votes.fill(0);
    for &(_, i) in best {
        votes[labels[i]] += 1;
    }
    let top = votes.iter().copied().max().unwrap_or(0);
    best.iter()
        .map(|&(_, i)| labels[i])
        .find(|&c| votes[c] == top)
        .unwrap_or(0)
}

/// A step near `n / golden ratio` coprime to `n` (1 for tiny sets): `j -> j + step mod n`
/// visits every index once, well scattered (a Weyl sequence).
fn scatter_stride(n: usize) -> usize {
    fn gcd(a: usize, b: usize) -> usize {
        if b == 0 {
            a
        } else {
            gcd(b, a % b)
        }
    }
    let target = (n as f64 * 0.618_033_988_749_895) as usize;
    (target..n).find(|&s| s > 1 && gcd(s, n) == 1).unwrap_or(1) % n.max(1)
}

impl Knn {
    /// The parameters.
    pub fn params(&self) -> KnnParams {
        self.params
    }
}

impl Classifier for Knn {
    type Model = KnnModel;

    /// Stores the z-scored training set.
    ///
    /// # Errors
    /// `k` larger than the training set, empty or ragged input, non-finite features.
    fn fit(&self, x: &[f64], dims: usize, y: &[usize]) -> Result<KnnModel, ClassifyError> {
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
        let mut columns = vec![0.0; n * dims];
        for (i, row) in x.chunks_exact(dims).enumerate() {
            for (j, &v) in row.iter().enumerate() {
                columns[j * n + i] = (v - mean[j]) * inv_std[j];
            }
        }
        Ok(KnnModel {
            k: self.params.k,
            dims,
            mean,
            inv_std,
            columns,
            labels: y.to_vec(),
            stride: scatter_stride(n),
            n_classes: y.iter().max().map_or(0, |&m| m + 1),
        })
    }
}

impl KnnModel {
    /// The predicted class of each row of `x` (row-major, [`Predict::dims`] per row) with
    /// the votes of each class among its `k` neighbours, indexed by class.
    ///
    /// # Panics
    /// If `x` is not whole rows of the training dimension (a caller bug).
    pub fn predict_with_votes(&self, x: &[f64]) -> Vec<(usize, Vec<usize>)> {
        let mut out = Vec::with_capacity(x.len() / self.dims.max(1));
        self.classify(x, |predicted, votes| out.push((predicted, votes.to_vec())));
        out
    }

    /// Finds each row's `k` nearest training samples and calls `on_row` with the predicted
    /// class and the votes per class.
    fn classify(&self, x: &[f64], on_row: impl FnMut(usize, &[usize])) {
        assert_eq!(
            x.len() % self.dims,
            0,
            "samples must have the training dimension"
        );
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: the CPU supports AVX2, the only feature the function enables.
                return unsafe { self.classify_avx2(x, on_row) };
            }
        }
        self.classify_rows(x, on_row);
    }

    /// [`KnnModel::classify_rows`] compiled for AVX2: the distances of four training
    /// samples per instruction. FMA is not enabled and Rust never fuses a multiply and an
    /// add on its own, and each distance is still summed over the features in order: the
    /// bits do not depend on it.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn classify_avx2(&self, x: &[f64], on_row: impl FnMut(usize, &[usize])) {
        self.classify_rows(x, on_row);
    }

    #[inline(always)]
    fn classify_rows(&self, x: &[f64], mut on_row: impl FnMut(usize, &[usize])) {
        let n = self.labels.len();
        let mut dist = vec![0.0f64; n];
        let mut best: Vec<(f64, usize)> = Vec::with_capacity(self.k);
        let mut votes = vec![0usize; self.n_classes];
        for row in x.chunks_exact(self.dims) {
            dist.fill(0.0);
            for (j, column) in self.columns.chunks_exact(n).enumerate() {
                let q = (row[j] - self.mean[j]) * self.inv_std[j];
                for (d, &t) in dist.iter_mut().zip(column) {
                    *d += (t - q) * (t - q);
                }
            }
            // The k smallest under the total order (distance, training index): ties in
            // distance go to the earlier training sample. The result does not depend on
            // the order the samples are visited in; the order only decides how much work
            // it takes. A first few, visited in a fixed scattered order (a stride coprime
            // to n, so that a training set sorted by class, as manifests often are, does
            // not make each a new nearest), give the k-th distance to beat; the rest are
            // then read in index order four at a time, and a block with no distance at
            // most that is passed over whole (one vector comparison), most of them once
            // the k-th distance has settled. The seeds' distances are set to NaN, which
            // no comparison passes, so they are not taken twice.
            best.clear();
            let mut j = 0usize;
            for _ in 0..n.min(self.k.max(SEEDS)) {
                insert(&mut best, self.k, (dist[j], j));
                dist[j] = f64::NAN;
                j += self.stride;
                if j >= n {
                    j -= n;
                }
            }
            if best.len() == self.k {
                let mut bar = best[self.k - 1].0;
                for (b, block) in dist.chunks(LANES).enumerate() {
                    if !block.iter().fold(false, |any, &d| any | (d <= bar)) {
                        continue;
                    }
                    for (o, &d) in block.iter().enumerate() {
                        if d <= bar {
                            insert(&mut best, self.k, (d, b * LANES + o));
                            bar = best[self.k - 1].0;
                        }
                    }
                }
            }
            let predicted = majority(&best, &self.labels, &mut votes);
            on_row(predicted, &votes);
        }
    }
}

impl Predict for KnnModel {
    fn dims(&self) -> usize {
        self.dims
    }

    fn n_classes(&self) -> usize {
        self.n_classes
    }

    /// The votes of each class among the `k` neighbours, divided by `k`.
    fn predict_with_shares(&self, x: &[f64]) -> Vec<(usize, Vec<f64>)> {
        let k = self.k as f64;
        let mut out = Vec::with_capacity(x.len() / self.dims.max(1));
        self.classify(x, |predicted, votes| {
            out.push((predicted, votes.iter().map(|&v| v as f64 / k).collect()))
        });
        out
    }

    fn predict(&self, x: &[f64]) -> Vec<usize> {
        let mut out = Vec::with_capacity(x.len() / self.dims.max(1));
        self.classify(x, |predicted, _| out.push(predicted));
        out
    }
}
