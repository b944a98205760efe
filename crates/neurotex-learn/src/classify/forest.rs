//! Random forest (Breiman 2001): CART trees grown on bootstrap samples, each split chosen
//! by Gini impurity among a random subset of features (⌊√d⌋ by default), the class
//! shares the mean of the trees' leaf class distributions (scikit-learn's
//! `predict_proba`), the prediction the class with the largest mean share.
//!
//! Written here rather than taken from a crate: smartcore's and linfa-ensemble's forests
//! fit their trees one after another (no rayon), linfa-ensemble samples features once per
//! tree rather than per split and defaults to a thread-local generator, and neither
//! promises a result independent of how the work is scheduled. Here tree `t` draws
//! everything it needs (its bootstrap sample, the features tried at each node) from its own
//! ChaCha8 stream, `seed` with stream number `t`, and the trees are fitted in parallel and
//! averaged in tree order, so a forest is the same bit for bit on any number of threads.
//!
//! Splits are searched by sorting: every feature is rank-transformed once per fit (equal
//! values share a rank), and a node sorts its samples by rank for each feature it tries, as
//! 64-bit keys (rank, sample): a stable counting sort over the node's samples, which are
//! kept in ascending order, each small node's keys placed by counting the keys below each,
//! or a comparison sort where a node has far fewer samples than the feature has ranks. A
//! split's quality is the Gini proxy `Σ_c L_c² / |L| + Σ_c R_c² / |R|` (class counts
//! weighted by bootstrap multiplicity), compared exactly as a fraction of integers, so equal splits are equal and the choice
//! among them is fixed: the lowest feature index, then the lowest threshold. A threshold
//! lies midway between two neighbouring distinct values; a sample goes left when its value
//! is at most the threshold. A node is split while it is impure, above the depth limit and
//! large enough for two leaves of `min_samples_leaf` samples (counted without
//! multiplicity), even by a split that does not lower the impurity (as scikit-learn does).
//! Features constant within a node do not count towards the ones tried; when the drawn
//! features are all constant, further ones are drawn.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::{check_training, first_max, Classifier, Predict};
use crate::error::{ClassifyError, ParamError};

/// Random forest parameters.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ForestParams {
    /// Trees in the forest (200).
    pub trees: usize,
    /// Deepest level of a tree (the root is depth 0); `None` grows trees until their leaves
    /// are pure or too small to split.
    pub max_depth: Option<usize>,
    /// Fewest training samples in a leaf (1).
    pub min_samples_leaf: usize,
    /// Features tried at each split; `None` for ⌊√d⌋ (at least 1); more than `d` tries all.
    pub max_features: Option<usize>,
    /// Grow each tree on a bootstrap sample (`true`) or on the whole training set.
    pub bootstrap: bool,
    /// Seed of the trees' random streams.
    pub seed: u64,
}

impl Default for ForestParams {
    fn default() -> Self {
        ForestParams {
            trees: 200,
            max_depth: None,
            min_samples_leaf: 1,
            max_features: None,
            bootstrap: true,
            seed: 0,
        }
    }
}

impl ForestParams {
    /// Checks the rules (at least one tree, depth, leaf size and features tried at least 1)
    /// and returns the unfitted classifier.
    ///
    /// # Errors
    /// The rule broken.
    pub fn check(self) -> Result<Forest, ParamError> {
        if self.trees == 0 {
            return Err(ParamError::new("trees", "trees must be at least 1", 0));
        }
        if self.trees > MAX_TREES {
            return Err(ParamError::new(
                "trees",
                "trees must be at most 10000",
                self.trees,
            ));
        }
        if self.max_depth == Some(0) {
            return Err(ParamError::new(
                "max_depth",
                "max depth must be at least 1",
                0,
            ));
        }
        if self.min_samples_leaf == 0 {
            return Err(ParamError::new(
                "min_samples_leaf",
                "a leaf must hold at least 1 sample",
                0,
            ));
        }
        if self.max_features == Some(0) {
            return Err(ParamError::new(
                "max_features",
                "at least 1 feature must be tried per split",
                0,
            ));
        }
        Ok(Forest { params: self })
    }
}

/// The most trees a forest may have: far beyond where more trees stop helping (hundreds),
/// and small enough that a model file or option asking for more (a typo, a corrupted file)
/// is an error rather than an attempt to allocate that many.
pub const MAX_TREES: usize = 10_000;

/// The unfitted forest, with parameters that passed [`ForestParams::check`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Forest {
    params: ForestParams,
}

impl Forest {
    /// The parameters.
    pub fn params(&self) -> ForestParams {
        self.params
    }
}

/// One node of a tree.
#[derive(Debug, Clone, PartialEq)]
enum Node {
    /// Samples with `feature <= threshold` go to `left`, the others to `right`.
    Split {
        feature: usize,
        threshold: f64,
        left: usize,
        right: usize,
    },
    /// A leaf; its class distribution starts at this offset of the tree's `shares`.
    Leaf(usize),
}

/// One fitted tree: nodes (the root first) and its leaves' class distributions.
#[derive(Debug, Clone, PartialEq)]
struct Tree {
    nodes: Vec<Node>,
    shares: Vec<f64>,
}

/// A fitted forest.
#[derive(Debug, Clone, PartialEq)]
pub struct ForestModel {
    dims: usize,
    n_classes: usize,
    trees: Vec<Tree>,
}

/// The training set as every tree reads it.
struct Prepared<'a> {
    x: &'a [f64],
    dims: usize,
    y: &'a [usize],
    n_classes: usize,
    /// Dense rank of each sample's value among all training values of a feature,
    /// feature-major (`dims x n`).
    ranks: Vec<u32>,
    /// Each feature's number of distinct values (its largest rank + 1).
    distinct: Vec<u32>,
}

impl<'a> Prepared<'a> {
    fn new(x: &'a [f64], dims: usize, y: &'a [usize]) -> Self {
        let n = y.len();
        let mut ranks = vec![0u32; n * dims];
        let mut distinct = vec![0u32; dims];
        // Each feature's values beside their samples, sorted in one piece of memory (the
        // ranks do not depend on the order of equal values).
        let mut column: Vec<(f64, u32)> = Vec::with_capacity(n);
        for (f, feature_ranks) in ranks.chunks_exact_mut(n).enumerate() {
            column.clear();
            column.extend((0..n).map(|s| (x[s * dims + f], s as u32)));
            column.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
            let mut rank = 0u32;
            for (i, &(value, s)) in column.iter().enumerate() {
                if i > 0 && value != column[i - 1].0 {
                    rank += 1;
                }
                feature_ranks[s as usize] = rank;
            }
            distinct[f] = rank + 1;
        }
        Prepared {
            x,
            dims,
            y,
            n_classes: y.iter().max().map_or(0, |&m| m + 1),
            ranks,
            distinct,
        }
    }
}

/// The parameters a tree is grown with, resolved for the training set.
#[derive(Debug, Clone, Copy)]
struct Growth {
    max_depth: usize,
    min_leaf: usize,
    max_features: usize,
    bootstrap: bool,
}

/// The best split found so far in a node: its Gini proxy as the fraction `num / den`.
#[derive(Debug, Clone, Copy)]
struct Candidate {
    num: u128,
    den: u128,
    feature: usize,
    /// Samples going left.
    n_left: usize,
    /// The feature's largest rank among them: a sample goes left when its rank is at most
    /// this.
    rank: u32,
}

impl Candidate {
    /// Whether this split is better than `other`: a larger proxy, or an equal one on a
    /// lower feature.
    fn beats(&self, other: &Option<Candidate>) -> bool {
        match other {
            None => true,
            Some(o) => {
                let (a, b) = (self.num * o.den, o.num * self.den);
                a > b || (a == b && self.feature < o.feature)
            }
        }
    }
}

/// Grows one tree: the state of its random stream, its in-bag samples and scratch space.
struct Grower<'a> {
    data: &'a Prepared<'a>,
    growth: Growth,
    rng: ChaCha8Rng,
    buffers: Buffers,
}

/// A grower's samples and scratch space, handed from one tree to the next within each
/// piece of work rayon splits the trees into, so that a forest allocates them a few times
/// rather than once per tree; what they hold is never read before it is written.
#[derive(Default)]
struct Buffers {
    /// Bootstrap multiplicity of each training sample.
    weight: Vec<u64>,
    /// The in-bag samples; each node owns a contiguous range.
    samples: Vec<u32>,
    keys: Vec<u64>,
    /// The counting sort's first slot of each rank.
    rank_starts: Vec<u32>,
    /// The samples going right while a node is partitioned.
    right: Vec<u32>,
    features: Vec<usize>,
    counts: Vec<u64>,
    left: Vec<u64>,
}

impl<'a> Grower<'a> {
    /// The grower of tree `tree`, its buffers `buffers` (any contents).
    fn new(
        data: &'a Prepared<'a>,
        growth: Growth,
        seed: u64,
        tree: usize,
        mut buffers: Buffers,
    ) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(tree as u64);
        let n = data.y.len();
        let weight = &mut buffers.weight;
        weight.clear();
        weight.resize(n, u64::from(!growth.bootstrap));
        if growth.bootstrap {
            for _ in 0..n {
                weight[rng.gen_range(0..n as u64) as usize] += 1;
            }
        }
        buffers.samples.clear();
        let in_bag = (0..n as u32).filter(|&s| buffers.weight[s as usize] > 0);
        buffers.samples.extend(in_bag);
        buffers.counts.resize(data.n_classes, 0);
        buffers.left.resize(data.n_classes, 0);
        Grower {
            data,
            growth,
            rng,
            buffers,
        }
    }

    /// Grows the tree depth first from the root; returns it and the buffers for the next.
    fn grow(mut self) -> (Tree, Buffers) {
        // A binary tree has fewer nodes than twice its leaves, which are at most its
        // samples: room for every node and share at once, never much more than is used.
        let leaves = self.buffers.samples.len();
        let mut nodes = Vec::with_capacity(2 * leaves);
        nodes.push(Node::Leaf(0));
        let mut tree = Tree {
            nodes,
            shares: Vec::with_capacity(leaves * self.data.n_classes),
        };
        let mut stack = vec![(0usize, 0usize, self.buffers.samples.len(), 0usize)];
        while let Some((node, start, end, depth)) = stack.pop() {
            self.count(start, end);
            let split = if self.splittable(end - start, depth) {
                self.best_split(start, end)
            } else {
                None
            };
            match split {
                Some(best) => {
                    let threshold = self.partition(start, end, &best);
                    let (left, right) = (tree.nodes.len(), tree.nodes.len() + 1);
                    tree.nodes.extend([Node::Leaf(0), Node::Leaf(0)]);
                    tree.nodes[node] = Node::Split {
                        feature: best.feature,
                        threshold,
                        left,
                        right,
                    };
                    let middle = start + best.n_left;
                    stack.push((right, middle, end, depth + 1));
                    stack.push((left, start, middle, depth + 1));
                }
                None => {
                    tree.nodes[node] = Node::Leaf(tree.shares.len());
                    let total: u64 = self.buffers.counts.iter().sum();
                    let shares = self.buffers.counts.iter().map(|&c| c as f64 / total as f64);
                    tree.shares.extend(shares);
                }
            }
        }
        (tree, self.buffers)
    }

    /// Fills `counts` with the node's class counts (weighted by multiplicity).
    fn count(&mut self, start: usize, end: usize) {
        self.buffers.counts.fill(0);
        for &s in &self.buffers.samples[start..end] {
            self.buffers.counts[self.data.y[s as usize]] += self.buffers.weight[s as usize];
        }
    }

    /// Whether a node of `n` samples at `depth` (with `counts` filled) may be split.
    fn splittable(&self, n: usize, depth: usize) -> bool {
        let classes = self.buffers.counts.iter().filter(|&&c| c > 0).count();
        classes > 1 && depth < self.growth.max_depth && n >= 2 * self.growth.min_leaf
    }

    /// Sorts the node's samples by their rank on `feature` into `keys`, as 64-bit keys
    /// (rank, sample). A node's samples are kept in ascending order (the root's are, and
    /// [`Grower::partition`] keeps the order), so a stable counting sort by rank gives the
    /// keys in order; nodes of at most [`SMALL`] samples are placed by [`place_small`],
    /// and nodes with far more ranks than samples, where clearing a count per rank would
    /// cost more than the sort, are sorted by comparison. The keys are distinct, so every
    /// way gives one order.
    fn sort_keys(&mut self, start: usize, end: usize, feature: usize) {
        let n = self.data.y.len();
        let ranks = &self.data.ranks[feature * n..(feature + 1) * n];
        let samples = &self.buffers.samples[start..end];
        let key = |s: u32| (u64::from(ranks[s as usize]) << 32) | u64::from(s);
        self.buffers.keys.clear();
        let distinct = self.data.distinct[feature] as usize;
        if samples.len() <= SMALL && distinct <= 1 << (31 - SMALL.trailing_zeros()) {
            let mut packed = [i32::MAX; SMALL];
            let mut keys = [0u64; SMALL];
            for (i, &s) in samples.iter().enumerate() {
                packed[i] = ((ranks[s as usize] << SMALL.trailing_zeros()) | i as u32) as i32;
                keys[i] = key(s);
            }
            self.buffers.keys.resize(samples.len(), 0);
            place_small(&packed, &keys, &mut self.buffers.keys);
            return;
        }
        if samples.len() * 12 < distinct {
            self.buffers.keys.extend(samples.iter().map(|&s| key(s)));
            self.buffers.keys.sort_unstable();
            return;
        }
        let starts = &mut self.buffers.rank_starts;
        starts.clear();
        starts.resize(distinct, 0);
        for &s in samples {
            starts[ranks[s as usize] as usize] += 1;
        }
        // Each rank's first slot: the counts before it, summed in a register (a sum
        // carried through memory waits on a store and a load per rank).
        let mut slot = 0u32;
        for start in starts.iter_mut() {
            (*start, slot) = (slot, slot + *start);
        }
        self.buffers.keys.resize(samples.len(), 0);
        for &s in samples {
            let slot = &mut starts[ranks[s as usize] as usize];
            self.buffers.keys[*slot as usize] = key(s);
            *slot += 1;
        }
    }

    /// The best split of the node among randomly drawn features, or `None` when every
    /// feature is constant in it or no split leaves `min_samples_leaf` on both sides.
    fn best_split(&mut self, start: usize, end: usize) -> Option<Candidate> {
        let dims = self.data.dims;
        self.buffers.features.clear();
        self.buffers.features.extend(0..dims);
        let mut best = None;
        let mut tried = 0;
        for i in 0..dims {
            if tried == self.growth.max_features {
                break;
            }
            let j = self.rng.gen_range(i as u64..dims as u64) as usize;
            self.buffers.features.swap(i, j);
            let feature = self.buffers.features[i];
            self.sort_keys(start, end, feature);
            let (first, last) = (
                self.buffers.keys[0] >> 32,
                self.buffers.keys[self.buffers.keys.len() - 1] >> 32,
            );
            if first == last {
                continue;
            }
            tried += 1;
            self.scan(feature, &mut best);
        }
        best
    }

    /// Walks the sorted `keys` of `feature`, moving samples left one at a time, and puts
    /// the feature's best split position in `best` where it beats it.
    ///
    /// The feature's own best is the first position of its largest proxy (a later equal
    /// one does not beat a split on the same feature), which beats `best` exactly when
    /// some position would have beaten it one at a time. Its proxies are compared in
    /// 64-bit integers when the node's weight keeps every product below 2^64 (a proxy's
    /// numerator is below `total³` and its denominator below `total²`), else in 128 bits:
    /// exact either way, so the choice is the same.
    fn scan(&mut self, feature: usize, best: &mut Option<Candidate>) {
        let total: u64 = self.buffers.counts.iter().sum();
        let found = if total < 1 << 12 {
            self.scan_in::<u64>(feature, total)
        } else {
            self.scan_in::<u128>(feature, total)
        };
        if let Some(candidate) = found {
            if candidate.beats(best) {
                *best = Some(candidate);
            }
        }
    }

    /// [`Grower::scan`]'s walk, the proxies compared in `T`; the feature's best position.
    /// Only the best proxy and its position are kept while walking (the proxy in `T` is
    /// the exact value the candidate holds in 128 bits).
    #[inline(always)]
    fn scan_in<T>(&mut self, feature: usize, total: u64) -> Option<Candidate>
    where
        T: Copy
            + Ord
            + From<u64>
            + Into<u128>
            + std::ops::Mul<Output = T>
            + std::ops::Add<Output = T>,
    {
        let min_leaf = self.growth.min_leaf;
        let m = self.buffers.keys.len();
        let (keys, y, weight) = (
            &self.buffers.keys[..],
            self.data.y,
            &self.buffers.weight[..],
        );
        let (counts, left) = (&self.buffers.counts[..], &mut self.buffers.left[..]);
        left.fill(0);
        let mut sq_left = 0u64;
        let mut sq_right: u64 = counts.iter().map(|&c| c * c).sum();
        let mut w_left = 0u64;
        // The best proxy so far, `num / den` at position `at` (none while `at == m`).
        let (mut top_num, mut top_den, mut at) = (T::from(0), T::from(1), m);
        for p in 0..m - min_leaf {
            let s = (keys[p] & 0xffff_ffff) as usize;
            let (c, w) = (y[s], weight[s]);
            let right_c = counts[c] - left[c];
            sq_left += (2 * left[c] + w) * w;
            sq_right -= (2 * right_c - w) * w;
            left[c] += w;
            w_left += w;
            if p + 1 < min_leaf || keys[p] >> 32 == keys[p + 1] >> 32 {
                continue;
            }
            let w_right = total - w_left;
            let num = T::from(sq_left) * T::from(w_right) + T::from(sq_right) * T::from(w_left);
            let den = T::from(w_left) * T::from(w_right);
            if at == m || num * top_den > top_num * den {
                (top_num, top_den, at) = (num, den, p);
            }
        }
        if at == m {
            return None;
        }
        Some(Candidate {
            num: top_num.into(),
            den: top_den.into(),
            feature,
            n_left: at + 1,
            rank: (keys[at] >> 32) as u32,
        })
    }

    /// Moves the node's samples that go left (rank on `best`'s feature at most its rank)
    /// before the others, each side keeping its ascending order, and returns the threshold:
    /// midway between the largest left and the smallest right value, or the left value
    /// where the midpoint rounds to the right one.
    fn partition(&mut self, start: usize, end: usize, best: &Candidate) -> f64 {
        let n = self.data.y.len();
        let ranks = &self.data.ranks[best.feature * n..(best.feature + 1) * n];
        let node = &mut self.buffers.samples[start..end];
        self.buffers.right.clear();
        let mut left = 0;
        let mut above: Option<u32> = None;
        for i in 0..node.len() {
            let s = node[i];
            let r = ranks[s as usize];
            if r <= best.rank {
                node[left] = s;
                left += 1;
            } else {
                self.buffers.right.push(s);
                if above.is_none_or(|a| r < ranks[a as usize]) {
                    above = Some(s);
                }
            }
        }
        node[left..].copy_from_slice(&self.buffers.right);
        debug_assert_eq!(
            left, best.n_left,
            "a split's left side is its ranks up to its own"
        );
        // Equal values share a rank: any left sample of the split's rank holds the largest
        // left value.
        let below = node[..left]
            .iter()
            .copied()
            .find(|&s| ranks[s as usize] == best.rank)
            .expect("the split's rank is on its left side");
        let above = above.expect("a split has a right side");
        let value = |s: u32| self.data.x[s as usize * self.data.dims + best.feature];
        let (below, above) = (value(below), value(above));
        let middle = below / 2.0 + above / 2.0;
        if middle >= above || !middle.is_finite() {
            below
        } else {
            middle
        }
    }
}

/// The most samples a node may have for [`place_small`] (a power of two).
const SMALL: usize = 32;

neurotex_core::widest_or_plain! {
    ["avx2"]
    /// Writes `keys[..out.len()]` into `out` in ascending order, where `packed[i]` orders
    /// `keys[i]` as the keys do and is distinct for each key (`(rank << 5) | i`, at most
    /// `i32::MAX`, where the node's samples, and so their keys of equal rank, ascend with
    /// `i`), and unused entries of `packed` are `i32::MAX`. Each key goes to the place
    /// given by the number of `packed` values below its own, counted over the keys rounded
    /// up to eight: a fixed count of comparisons that vectorise (signed, one instruction
    /// each), where a comparison sort of a small node mispredicts about one branch in two.
    fn place_small(packed: &[i32; SMALL], keys: &[u64; SMALL], out: &mut [u64]) {
        let lanes = out.len().next_multiple_of(8).min(SMALL);
        let packed = &packed[..lanes];
        for (&own, &key) in packed.iter().zip(keys).take(out.len()) {
            let below: i32 = packed.iter().map(|&p| i32::from(p < own)).sum();
            out[below as usize] = key;
        }
    }
}

impl Tree {
    /// The class distribution of the leaf `row` falls in.
    fn leaf(&self, row: &[f64], n_classes: usize) -> &[f64] {
        let mut node = 0;
        loop {
            match self.nodes[node] {
                Node::Split {
                    feature,
                    threshold,
                    left,
                    right,
                } => {
                    node = if row[feature] <= threshold {
                        left
                    } else {
                        right
                    }
                }
                Node::Leaf(offset) => return &self.shares[offset..offset + n_classes],
            }
        }
    }
}

impl Classifier for Forest {
    type Model = ForestModel;

    /// Grows the trees in parallel, each from its own random stream.
    ///
    /// # Errors
    /// Empty or ragged input, non-finite features.
    fn fit(&self, x: &[f64], dims: usize, y: &[usize]) -> Result<ForestModel, ClassifyError> {
        check_training(x, dims, y)?;
        let p = self.params;
        let growth = Growth {
            max_depth: p.max_depth.unwrap_or(usize::MAX),
            min_leaf: p.min_samples_leaf,
            max_features: p
                .max_features
                .unwrap_or(((dims as f64).sqrt().floor() as usize).max(1))
                .min(dims),
            bootstrap: p.bootstrap,
        };
        let data = Prepared::new(x, dims, y);
        let trees = (0..p.trees)
            .into_par_iter()
            .map_init(Buffers::default, |buffers, t| {
                let grower = Grower::new(&data, growth, p.seed, t, std::mem::take(buffers));
                let tree;
                (tree, *buffers) = grower.grow();
                tree
            })
            .collect();
        Ok(ForestModel {
            dims,
            n_classes: data.n_classes,
            trees,
        })
    }
}

impl ForestModel {
    /// The trees.
    pub fn n_trees(&self) -> usize {
        self.trees.len()
    }

    /// Every class's mean leaf share over the trees, for one row.
    fn shares(&self, row: &[f64]) -> Vec<f64> {
        let mut sum = vec![0.0; self.n_classes];
        for tree in &self.trees {
            for (s, &v) in sum.iter_mut().zip(tree.leaf(row, self.n_classes)) {
                *s += v;
            }
        }
        let n = self.trees.len() as f64;
        sum.iter_mut().for_each(|s| *s /= n);
        sum
    }
}

impl Predict for ForestModel {
    fn dims(&self) -> usize {
        self.dims
    }

    fn n_classes(&self) -> usize {
        self.n_classes
    }

    /// Rows are predicted in parallel; each row's shares are summed in tree order.
    fn predict_with_shares(&self, x: &[f64]) -> Vec<(usize, Vec<f64>)> {
        assert_eq!(
            x.len() % self.dims,
            0,
            "samples must have the training dimension"
        );
        x.par_chunks_exact(self.dims)
            .map(|row| {
                let shares = self.shares(row);
                (first_max(&shares), shares)
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_rule_is_checked() {
        let d = ForestParams::default();
        let name = |p: ForestParams| p.check().unwrap_err().name;
        assert_eq!(name(ForestParams { trees: 0, ..d }), "trees");
        assert_eq!(
            name(ForestParams {
                max_depth: Some(0),
                ..d
            }),
            "max_depth"
        );
        assert_eq!(
            name(ForestParams {
                min_samples_leaf: 0,
                ..d
            }),
            "min_samples_leaf"
        );
        assert_eq!(
            name(ForestParams {
                max_features: Some(0),
                ..d
            }),
            "max_features"
        );
    }

    /// FNV-1a over every node (feature, threshold's bits, children) and every leaf share's
    /// bits of every tree.
    fn digest(model: &ForestModel) -> u64 {
        let mut h = 0xcbf2_9ce4_8422_2325u64;
        let mut eat = |v: u64| {
            for b in v.to_le_bytes() {
                h = (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
            }
        };
        for tree in &model.trees {
            for node in &tree.nodes {
                match *node {
                    Node::Split {
                        feature,
                        threshold,
                        left,
                        right,
                    } => {
                        [
                            feature as u64,
                            threshold.to_bits(),
                            left as u64,
                            right as u64,
                        ]
                        .into_iter()
                        .for_each(&mut eat);
                    }
                    Node::Leaf(offset) => eat(u64::MAX - offset as u64),
                }
            }
            tree.shares.iter().for_each(|s| eat(s.to_bits()));
        }
        h
    }

    /// Forests on data with many ties and without, small and larger, with and without
    /// bootstrap, depth and leaf limits: the digests of the trees grown before the split
    /// search stopped sorting each node's samples (sort_unstable of (rank, sample) keys),
    /// so that any change to the trees is seen.
    #[test]
    fn forests_are_the_ones_grown_before() {
        let mut next = crate::testing::xorshift(0x9e37_79b9_7f4a_7c15);
        let mut digests = Vec::new();
        for (n, dims, classes, levels) in [(40, 3, 3, 5u64), (200, 12, 8, 1000), (480, 96, 8, 40)] {
            let x: Vec<f64> = (0..n * dims)
                .map(|_| (next() % levels) as f64 * 0.37 - 2.0)
                .collect();
            let y: Vec<usize> = (0..n)
                .map(|i| (i + (next() % 2) as usize) % classes)
                .collect();
            for (bootstrap, max_depth, min_samples_leaf) in
                [(true, None, 1), (false, Some(4), 1), (true, None, 3)]
            {
                let params = ForestParams {
                    trees: 12,
                    bootstrap,
                    max_depth,
                    min_samples_leaf,
                    seed: 7,
                    ..ForestParams::default()
                };
                digests.push(digest(&params.check().unwrap().fit(&x, dims, &y).unwrap()));
            }
        }
        assert_eq!(digests, EXPECTED);
    }

    /// Taken with the sorting split search (commit cebc8de).
    const EXPECTED: [u64; 9] = [
        0xd9bf95ed6f2181a9,
        0x75d139cf1b81539e,
        0x35f13b98acf758e3,
        0xbbdbe603709b9d2b,
        0x688db7f982fa4af1,
        0xfe3595d94cc1d3b5,
        0x147c710072d89bc1,
        0xae7a98d51b3beada,
        0xfadec57147b6908a,
    ];

    /// Every count of up to 32 keys, ranks with many ties and without: placed as sorting
    /// them puts them.
    #[test]
    fn small_nodes_are_placed_as_sorted() {
        let mut next = crate::testing::xorshift(0x2545_f491_4f6c_dd1d);
        for m in 1..=SMALL {
            for levels in [2u64, 7, 1 << 20] {
                let mut samples: Vec<u32> = (0..m).map(|_| (next() % 4096) as u32).collect();
                samples.sort_unstable();
                samples.dedup();
                let mut packed = [i32::MAX; SMALL];
                let mut keys = [0u64; SMALL];
                for (i, &s) in samples.iter().enumerate() {
                    let rank = (next() % levels) as u32;
                    packed[i] = ((rank << 5) | i as u32) as i32;
                    keys[i] = (u64::from(rank) << 32) | u64::from(s);
                }
                let mut placed = vec![0u64; samples.len()];
                place_small(&packed, &keys, &mut placed);
                let mut sorted = keys[..samples.len()].to_vec();
                sorted.sort_unstable();
                assert_eq!(placed, sorted, "{m} keys of {levels} ranks");
            }
        }
    }

    #[test]
    fn a_stump_splits_between_the_classes() {
        let x = [0.0, 1.0, 2.0, 10.0, 11.0];
        let y = [0, 0, 0, 1, 1];
        let params = ForestParams {
            trees: 1,
            bootstrap: false,
            ..ForestParams::default()
        };
        let model = params.check().unwrap().fit(&x, 1, &y).unwrap();
        let tree = &model.trees[0];
        assert_eq!(tree.nodes.len(), 3);
        assert!(
            matches!(tree.nodes[0], Node::Split { feature: 0, threshold, .. } if threshold == 6.0)
        );
        assert_eq!(model.predict(&[5.9, 6.0, 6.1]), vec![0, 0, 1]);
    }
}
