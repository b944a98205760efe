//! k-nearest neighbours, Euclidean distance, majority vote.
//!
//! Ties are broken deterministically: among neighbours at equal distance the earlier
//! training sample comes first; among classes with equal votes the one with the nearest
//! member wins. Features are z-scored with the training set's mean and population standard
//! deviation (a feature constant in training is only centred).

use serde::{Deserialize, Serialize};

use super::{Classifier, Predict, Sweep, SweepModel};
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

/// Training samples visited in the scattered order to set the bar the nearest are under:
/// at least this many, and at least `SEEDS_PER_NEIGHBOUR` per neighbour sought.
const SEEDS: usize = 16;
const SEEDS_PER_NEIGHBOUR: usize = 3;
/// The most neighbours [`KnnModel::nearest_by_selection`] seeks (its seeds are kept on the
/// stack); a larger `k` takes [`KnnModel::nearest_any`].
const SELECTION_K: usize = 16;
const SEEDS_MOST: usize = if SEEDS > SEEDS_PER_NEIGHBOUR * SELECTION_K {
    SEEDS
} else {
    SEEDS_PER_NEIGHBOUR * SELECTION_K
};
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
    fn classify(&self, x: &[f64], mut on_row: impl FnMut(usize, &[usize])) {
        let mut votes = vec![0usize; self.n_classes];
        self.neighbours(x, |best| {
            let predicted = majority(best, &self.labels, &mut votes);
            on_row(predicted, &votes);
        });
    }

    /// Calls `on_row` with each row's `k` nearest training samples, nearest first under
    /// the order (distance, training index).
    fn neighbours(&self, x: &[f64], on_row: impl FnMut(&[(f64, usize)])) {
        assert_eq!(
            x.len() % self.dims,
            0,
            "samples must have the training dimension"
        );
        #[cfg(target_arch = "x86_64")]
        {
            if neurotex_core::has_feature!("avx2") {
                // SAFETY: the CPU supports AVX2, the only feature the function enables.
                return unsafe { self.neighbours_avx2(x, on_row) };
            }
        }
        self.neighbours_of_rows(x, on_row);
    }

    /// [`KnnModel::neighbours_of_rows`] compiled for AVX2: the distances of four training
    /// samples per instruction. FMA is not enabled and Rust never fuses a multiply and an
    /// add on its own, and each distance is still summed over the features in order: the
    /// bits do not depend on it.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn neighbours_avx2(&self, x: &[f64], on_row: impl FnMut(&[(f64, usize)])) {
        self.neighbours_of_rows(x, on_row);
    }

    #[inline(always)]
    fn neighbours_of_rows(&self, x: &[f64], mut on_row: impl FnMut(&[(f64, usize)])) {
        let n = self.labels.len();
        let mut dist = vec![0.0f64; n];
        let mut scratch = Scratch {
            index: vec![0; n + 1],
            near: vec![0; n + 1],
        };
        let mut best: Vec<(f64, usize)> = Vec::with_capacity(self.k);
        for row in x.chunks_exact(self.dims) {
            dist.fill(0.0);
            for (j, column) in self.columns.chunks_exact(n).enumerate() {
                let q = (row[j] - self.mean[j]) * self.inv_std[j];
                for (d, &t) in dist.iter_mut().zip(column) {
                    *d += (t - q) * (t - q);
                }
            }
            best.clear();
            let finite = dist.iter().fold(true, |all, d| all & d.is_finite());
            if self.k <= SELECTION_K && finite {
                self.nearest_by_selection(&dist, &mut scratch, &mut best);
            } else {
                self.nearest_any(&mut dist, &mut best);
            }
            on_row(&best);
        }
    }

    /// The `k` smallest of `dist` (all finite, `k <= SELECTION_K`) under the order
    /// (distance, training index), nearest first, into `best`.
    ///
    /// The k-th smallest distance among a few samples visited in a fixed scattered order (a
    /// stride coprime to n, so that a training set sorted by class, as manifests often
    /// are, does not put the nearest last) is a bar the k nearest are all at or under. The
    /// samples at most that bar are gathered in index order without a branch, the k-th
    /// smallest distance among them is found by selection, and the nearest are those under
    /// it, then the earliest at it, sorted by distance (stably, so index order breaks ties).
    /// Distances are compared as their bits: a sum of squares from +0.0 is never -0.0, and
    /// the bits of finite non-negative doubles are in the order of their values.
    #[inline(always)]
    fn nearest_by_selection(
        &self,
        dist: &[f64],
        scratch: &mut Scratch,
        best: &mut Vec<(f64, usize)>,
    ) {
        let (n, k) = (dist.len(), self.k);
        let mut seeds = [0u64; SEEDS_MOST];
        let sampled = n.min(SEEDS.max(SEEDS_PER_NEIGHBOUR * k));
        let mut j = 0usize;
        for seed in &mut seeds[..sampled] {
            *seed = dist[j].to_bits();
            j += self.stride;
            if j >= n {
                j -= n;
            }
        }
        seeds[..sampled].sort_unstable();
        let bar = seeds[k - 1];
        let mut found = 0;
        for (i, &d) in dist.iter().enumerate() {
            scratch.index[found] = i;
            scratch.near[found] = d.to_bits();
            found += usize::from(d.to_bits() <= bar);
        }
        let kth = f64::from_bits(*scratch.near[..found].select_nth_unstable(k - 1).1);
        best.extend(
            scratch.index[..found]
                .iter()
                .map(|&i| (dist[i], i))
                .filter(|&(d, _)| d < kth),
        );
        let under = best.len();
        best.extend(
            scratch.index[..found]
                .iter()
                .map(|&i| (dist[i], i))
                .filter(|&(d, _)| d == kth)
                .take(k - under),
        );
        best[..under].sort_by(|a, b| a.0.total_cmp(&b.0));
    }

    /// The `k` smallest of `dist` under the order (distance, training index), nearest
    /// first, into `best`, for any `k` and distances (a query with a non-finite feature).
    ///
    /// A first few samples, visited in the scattered order of [`KnnModel::nearest_by_selection`],
    /// give the k-th distance to beat; the rest are then read in index order four at a
    /// time, and a block with no distance at most that is passed over whole, most of them
    /// once the k-th distance has settled. The seeds' distances are set to NaN, which no
    /// comparison passes, so they are not taken twice.
    #[inline(always)]
    fn nearest_any(&self, dist: &mut [f64], best: &mut Vec<(f64, usize)>) {
        let n = dist.len();
        let mut j = 0usize;
        for _ in 0..n.min(self.k.max(SEEDS)) {
            insert(best, self.k, (dist[j], j));
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
                        insert(best, self.k, (d, b * LANES + o));
                        bar = best[self.k - 1].0;
                    }
                }
            }
        }
    }
}

/// Room for the samples at most a row's bar in [`KnnModel::nearest_by_selection`] (one
/// slot spare, written and not counted).
struct Scratch {
    index: Vec<usize>,
    near: Vec<u64>,
}

/// KNN at several k from one neighbour search per sample: the `k` nearest under the order
/// (distance, training index) are the first `k` of the largest k's nearest, and the vote
/// and its tie-break read only those, so each k's prediction is exactly that of [`Knn`]
/// with that k (`tests::a_sweep_predicts_as_each_k_alone`). E8 cross-validates five k this
/// way for the price of about one.
#[derive(Debug, Clone, PartialEq)]
pub struct KnnSweep {
    /// The classifier with the largest k.
    widest: Knn,
    ks: Vec<usize>,
}

impl KnnSweep {
    /// `knn`'s standardisation at each of `ks` (in that order).
    ///
    /// # Errors
    /// No k, or a k of 0.
    pub fn new(knn: &Knn, ks: &[usize]) -> Result<Self, ParamError> {
        let Some(&largest) = ks.iter().max() else {
            return Err(ParamError::new("k", "a sweep needs at least one k", "none"));
        };
        if ks.contains(&0) {
            return Err(ParamError::new("k", "k must be at least 1", 0));
        }
        let widest = KnnParams {
            k: largest,
            ..knn.params()
        }
        .check()?;
        Ok(KnnSweep {
            widest,
            ks: ks.to_vec(),
        })
    }
}

/// A fitted [`KnnSweep`]: the model of the largest k and every k.
#[derive(Debug, Clone, PartialEq)]
pub struct KnnSweepModel {
    model: KnnModel,
    ks: Vec<usize>,
}

impl Sweep for KnnSweep {
    type Model = KnnSweepModel;

    /// Stores the z-scored training set.
    ///
    /// # Errors
    /// The largest k larger than the training set, empty or ragged input, non-finite
    /// features.
    fn fit_sweep(
        &self,
        x: &[f64],
        dims: usize,
        y: &[usize],
    ) -> Result<KnnSweepModel, ClassifyError> {
        Ok(KnnSweepModel {
            model: self.widest.fit(x, dims, y)?,
            ks: self.ks.clone(),
        })
    }
}

impl SweepModel for KnnSweepModel {
    fn predict_sweep(&self, x: &[f64]) -> Vec<Vec<usize>> {
        let rows = x.len() / self.model.dims.max(1);
        let mut out: Vec<Vec<usize>> = self.ks.iter().map(|_| Vec::with_capacity(rows)).collect();
        let mut votes = vec![0usize; self.model.n_classes];
        self.model.neighbours(x, |best| {
            for (&k, predicted) in self.ks.iter().zip(out.iter_mut()) {
                predicted.push(majority(&best[..k], &self.model.labels, &mut votes));
            }
        });
        out
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

#[cfg(test)]
mod tests {
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;
    use crate::classify::{
        cross_validate, cross_validate_grouped, cross_validate_sweep, train_test, train_test_sweep,
        CvParams,
    };

    /// `n` samples of `dims` small integer features (many equal distances, so the
    /// tie-breaks are exercised) in `classes` classes, and each sample's group of 4.
    fn data(
        seed: u64,
        n: usize,
        dims: usize,
        classes: usize,
    ) -> (Vec<f64>, Vec<usize>, Vec<usize>) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let x = (0..n * dims)
            .map(|_| f64::from(rng.gen_range(0..3u8)))
            .collect();
        let y = (0..n).map(|i| i % classes).collect();
        (x, y, (0..n).map(|i| i / 4).collect())
    }

    fn knn(k: usize, standardize: bool) -> Knn {
        KnnParams { k, standardize }.check().unwrap()
    }

    #[test]
    fn a_sweep_predicts_as_each_k_alone() {
        let ks = [7, 1, 3, 3, 9, 2];
        for (seed, dims, standardize) in [(1, 2, true), (2, 3, false), (3, 5, true)] {
            let (x, y, _) = data(seed, 60, dims, 4);
            let (train, test) = x.split_at(40 * dims);
            let sweep = KnnSweep::new(&knn(5, standardize), &ks).unwrap();
            let each = sweep
                .fit_sweep(train, dims, &y[..40])
                .unwrap()
                .predict_sweep(test);
            assert_eq!(each.len(), ks.len());
            for (&k, predicted) in ks.iter().zip(&each) {
                let alone = knn(k, standardize).fit(train, dims, &y[..40]).unwrap();
                assert_eq!(*predicted, alone.predict(test), "k={k}, seed {seed}");
            }
        }
    }

    #[test]
    fn a_swept_evaluation_is_each_ks_evaluation() {
        let (x, y, groups) = data(4, 48, 3, 3);
        let names: Vec<String> = ["a", "b", "c"].map(String::from).to_vec();
        let ks = [1, 4, 9];
        let sweep = KnnSweep::new(&knn(5, true), &ks).unwrap();
        let cv = CvParams {
            folds: 4,
            seed: 11,
            repeats: 3,
        }
        .check()
        .unwrap();
        let swept = cross_validate_sweep(&sweep, (&x, 3), &y, &names, cv, None).unwrap();
        let grouped = cross_validate_sweep(&sweep, (&x, 3), &y, &names, cv, Some(&groups));
        let (train, test) = ((&x[..90], &y[..30]), (&x[90..], &y[30..]));
        let split = train_test_sweep(&sweep, train, test, 3, &names).unwrap();
        for (i, &k) in ks.iter().enumerate() {
            let alone = knn(k, true);
            assert_eq!(
                swept[i],
                cross_validate(&alone, &x, 3, &y, &names, cv).unwrap()
            );
            let by_group = cross_validate_grouped(&alone, &x, 3, &y, &names, cv, &groups);
            assert_eq!(grouped.as_ref().unwrap()[i], by_group.unwrap());
            assert_eq!(
                split[i],
                train_test(&alone, train, test, 3, &names).unwrap()
            );
        }
        // A k above a fold's training set fails the sweep as it fails that k alone.
        let too_many = KnnSweep::new(&knn(5, true), &[1, 40]).unwrap();
        let err = cross_validate_sweep(&too_many, (&x, 3), &y, &names, cv, None).unwrap_err();
        assert!(
            matches!(err, ClassifyError::KTooLarge { k: 40, .. }),
            "{err}"
        );
        assert!(KnnSweep::new(&knn(5, true), &[]).is_err());
        assert!(KnnSweep::new(&knn(5, true), &[2, 0]).is_err());
    }
}
