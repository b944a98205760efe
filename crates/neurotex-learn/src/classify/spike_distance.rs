//! A spike-timing method: van Rossum distances between recordings' spike trains, and
//! k-nearest neighbours over a precomputed distance matrix (Rongala et al. 2017, the
//! paper's reference 8).
//!
//! **The distance** (van Rossum 2001, Neural Computation 13:751). Each train is filtered
//! with the causal exponential kernel, `f(t) = Σ_i exp(-(t - t_i)/τ) H(t - t_i)`, and
//! `D² = (1/τ) ∫ (f - g)² dt`. With this normalisation one spike against none gives
//! `D = √½`, and
//! `D² = ½ [Σ_ij e^{-|t_i-t_j|/τ} + Σ_ij e^{-|s_i-s_j|/τ} - 2 Σ_ij e^{-|t_i-s_j|/τ}]`.
//! [`van_rossum_squared`] computes it exactly in `O(n + m)` with the Markov property of the
//! exponential kernel (Houghton & Kreuz 2012; Rusu & Florian 2014): between two events of
//! the merged trains the difference `f - g` only decays, so the integral is a sum of
//! closed-form, non-negative pieces carried by one running value. Nothing grows
//! exponentially and nothing cancels, so long trains (18 000 ms, hundreds of spikes) are as
//! accurate as short ones.
//!
//! **Recordings** are compared taxel by taxel as independent labelled lines: the squared
//! distances of the taxels add, `D² = Σ_taxel D²_taxel` (the multi-unit van Rossum distance
//! of Houghton & Sen 2008 with `c = 0`).
//!
//! **Classification.** A spike-timing method does not reduce a recording to a feature row:
//! it classifies by distances between recordings' trains. To run it through the same
//! [`Classifier`] machinery as feature methods (cross-validation, train/test), the
//! distance matrix of all recordings is computed once ([`VanRossum::matrix`]) and shared
//! by a [`SpikeDistanceKnn`]; the table that classifier is given holds, as its single
//! "feature", each sample's **row index into the matrix** ([`SpikeDistanceKnn::samples`]).
//! Neighbours and votes follow the tie rules of [`super::knn`]: among equal distances the
//! earlier training sample comes first; among classes with equal votes the one with the
//! nearest member wins.
//!
//! **Limits.** The matrix holds `n²` values: 1 000 recordings take 8 MB, 10 000 take 800 MB.
//! The fast matrix path keeps, per worker thread, one recording's filtered traces on the
//! 1 ms grid (`taxels x steps` values, 2.3 MB for 16 taxels x 18 000 ms); beyond
//! [`MAX_TRACE_VALUES`] it falls back to the exact pairwise merge.

use rayon::prelude::*;

use super::knn::{insert, majority};
use super::samples::{Decide, Learner, Samples};
use crate::error::{ClassifyError, ParamError};
use crate::spikes::SpikeTrains;

/// Largest `taxels x steps` trace table the fast matrix path builds per worker (32 MB of
/// `f64`); longer recordings use the exact pairwise merge, slower but without the table.
pub const MAX_TRACE_VALUES: usize = 1 << 22;

/// Squared van Rossum distance between two sorted spike trains (times in ms), exponential
/// kernel with time constant `tau_ms`, normalised so that one spike against none gives ½.
///
/// # Panics
/// If `tau_ms` is not positive and finite (a caller bug; [`VanRossumParams::check`]
/// validates user input).
pub fn van_rossum_squared(a: &[u32], b: &[u32], tau_ms: f64) -> f64 {
    assert!(
        tau_ms > 0.0 && tau_ms.is_finite(),
        "tau must be positive and finite"
    );
    // `diff` = f - g just after the last event at `last`; each gap between events adds
    // (1/τ) ∫_0^Δ diff² e^{-2u/τ} du = diff²/2 (1 - e^{-2Δ/τ}).
    let (mut i, mut j) = (0, 0);
    let (mut diff, mut last, mut sum) = (0.0f64, 0u32, 0.0f64);
    while i < a.len() || j < b.len() {
        let take_a = j == b.len() || (i < a.len() && a[i] <= b[j]);
        let t = if take_a { a[i] } else { b[j] };
        if t != last {
            let decay = (-f64::from(t - last) / tau_ms).exp();
            sum += 0.5 * diff * diff * (1.0 - decay * decay);
            diff *= decay;
            last = t;
        }
        if take_a {
            diff += 1.0;
            i += 1;
        } else {
            diff -= 1.0;
            j += 1;
        }
    }
    // after the last event the difference decays for ever
    sum + 0.5 * diff * diff
}

/// Van Rossum distance between two sorted spike trains (the square root of
/// [`van_rossum_squared`]).
///
/// # Panics
/// If `tau_ms` is not positive and finite.
pub fn van_rossum(a: &[u32], b: &[u32], tau_ms: f64) -> f64 {
    van_rossum_squared(a, b, tau_ms).sqrt()
}

/// Van Rossum parameters.
///
/// There is no `Default`: the time constant sets which timing differences count (about
/// `τ` and shorter), and neither the paper nor Rongala et al. fix one for this rig.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct VanRossumParams {
    /// Time constant of the exponential kernel, ms.
    pub tau_ms: f64,
}

impl VanRossumParams {
    /// Checks the rule (a positive, finite time constant) and returns the metric.
    ///
    /// # Errors
    /// The rule broken.
    pub fn check(self) -> Result<VanRossum, ParamError> {
        if !(self.tau_ms > 0.0 && self.tau_ms.is_finite()) {
            return Err(ParamError::new(
                "tau",
                "tau must be a positive, finite number of ms",
                self.tau_ms,
            ));
        }
        Ok(VanRossum {
            tau_ms: self.tau_ms,
        })
    }
}

/// The van Rossum metric with parameters that passed [`VanRossumParams::check`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VanRossum {
    tau_ms: f64,
}

/// A symmetric `n x n` matrix of distances between recordings, row-major.
#[derive(Debug, Clone, PartialEq)]
pub struct DistanceMatrix {
    n: usize,
    values: Vec<f64>,
}

impl DistanceMatrix {
    /// A matrix from its row-major values.
    ///
    /// # Errors
    /// Not `n x n` values, a negative or non-finite value, a non-zero diagonal or an
    /// asymmetric pair.
    pub fn from_values(n: usize, values: Vec<f64>) -> Result<Self, ClassifyError> {
        let bad = |what: String| Err(ClassifyError::BadFeatures(what));
        if values.len() != n * n {
            return bad(format!("{} distances for {n} x {n}", values.len()));
        }
        for i in 0..n {
            for j in 0..n {
                let v = values[i * n + j];
                if !(v.is_finite() && v >= 0.0) || (i == j && v != 0.0) {
                    return bad(format!("distance ({i}, {j}) = {v} is not a distance"));
                }
                if v != values[j * n + i] {
                    return bad(format!("distances ({i}, {j}) and ({j}, {i}) differ"));
                }
            }
        }
        Ok(DistanceMatrix { n, values })
    }

    /// Recordings (rows).
    pub fn n(&self) -> usize {
        self.n
    }

    /// The distance between recordings `i` and `j`.
    ///
    /// # Panics
    /// If `i` or `j` is not below [`DistanceMatrix::n`].
    pub fn get(&self, i: usize, j: usize) -> f64 {
        assert!(i < self.n && j < self.n, "index outside the matrix");
        self.values[i * self.n + j]
    }

    /// Row `i`: the distances of recording `i` to every recording.
    ///
    /// # Panics
    /// If `i` is not below [`DistanceMatrix::n`].
    pub fn row(&self, i: usize) -> &[f64] {
        &self.values[i * self.n..(i + 1) * self.n]
    }

    /// All values, row-major.
    pub fn values(&self) -> &[f64] {
        &self.values
    }
}

/// The cells holding a taxel, after checking that every recording is on the grid of the
/// first (same rows, columns and taxel mask).
fn common_taxels<'a>(
    recordings: impl IntoIterator<Item = (&'a str, usize, &'a SpikeTrains)>,
) -> Result<Vec<usize>, ClassifyError> {
    let mut first: Option<(&str, usize, &SpikeTrains)> = None;
    for (set, i, tr) in recordings {
        let Some((set0, i0, tr0)) = first else {
            first = Some((set, i, tr));
            continue;
        };
        if (tr.rows, tr.cols, &tr.present) != (tr0.rows, tr0.cols, &tr0.present) {
            let taxels = |t: &SpikeTrains| t.present.iter().filter(|&&p| p).count();
            return Err(ClassifyError::BadFeatures(format!(
                "{set} recording {i} is on a {}x{} grid with {} taxels, {set0} recording {i0} \
                 on a {}x{} grid with {}; spike distances need one grid",
                tr.rows,
                tr.cols,
                taxels(tr),
                tr0.rows,
                tr0.cols,
                taxels(tr0)
            )));
        }
    }
    Ok(first.map_or_else(Vec::new, |(_, _, tr)| {
        (0..tr.cells()).filter(|&c| tr.present[c]).collect()
    }))
}

/// One recording's filtered traces on the 1 ms grid, per taxel: `G(x) = Σ_i e^{-|x-t_i|/τ}`
/// for `x` in `0..steps`, so that the cross sum `Σ_ij e^{-|t_i-s_j|/τ}` of a taxel is
/// `Σ_j G(s_j)`, one lookup per spike of the other recording.
struct Traces {
    steps: usize,
    values: Vec<f64>,
}

impl Traces {
    fn new(steps: usize, taxels: usize) -> Self {
        Traces {
            steps,
            values: vec![0.0; steps * taxels],
        }
    }

    /// Fills the traces of `tr` from `decay[d] = e^{-d/τ}` (flushed to 0 where it would be
    /// subnormal): between two spikes every step is one independent multiplication of the
    /// level at the last spike (causal part) or of the sum over the next and later spikes
    /// (the strictly later part), so the loops vectorise.
    fn fill(&mut self, tr: &SpikeTrains, taxels: &[usize], decay: &[f64]) {
        for (trace, &cell) in self.values.chunks_exact_mut(self.steps).zip(taxels) {
            let spikes = tr.train(cell);
            let first = spikes.first().map_or(self.steps, |&t| t as usize);
            trace[..first].fill(0.0);
            let mut level = 0.0;
            for (k, &t) in spikes.iter().enumerate() {
                let t = t as usize;
                level = 1.0 + level * decay[t - spikes[k.saturating_sub(1)] as usize];
                let end = spikes.get(k + 1).map_or(self.steps, |&u| u as usize);
                for (g, &q) in trace[t..end].iter_mut().zip(decay) {
                    *g = level * q;
                }
            }
            // the part of later spikes: at x in [t_{k-1}, t_k), R_k e^{-(t_k - x)/τ}
            let mut later = 0.0;
            for (k, &t) in spikes.iter().enumerate().rev() {
                let t = t as usize;
                let next = spikes.get(k + 1).map_or(t, |&u| u as usize);
                later = 1.0 + later * decay[next - t];
                let start = if k == 0 { 0 } else { spikes[k - 1] as usize };
                for (g, &q) in trace[start..t].iter_mut().rev().zip(&decay[1..]) {
                    *g += later * q;
                }
            }
        }
    }

    /// `Σ_taxel Σ_j G(s_j)` over the spikes `s_j` of `other`; of the recording itself, its
    /// self sum `Σ_taxel Σ_ij e^{-|t_i-t_j|/τ}`.
    fn cross_sum(&self, other: &SpikeTrains, taxels: &[usize]) -> f64 {
        let mut total = 0.0;
        for (trace, &cell) in self.values.chunks_exact(self.steps).zip(taxels) {
            // four partial sums break the chain of dependent additions
            let mut acc = [0.0f64; 4];
            let spikes = other.train(cell);
            let mut quads = spikes.chunks_exact(4);
            for q in &mut quads {
                for (a, &s) in acc.iter_mut().zip(q) {
                    *a += trace[s as usize];
                }
            }
            for &s in quads.remainder() {
                acc[0] += trace[s as usize];
            }
            total += (acc[0] + acc[1]) + (acc[2] + acc[3]);
        }
        total
    }
}

/// `D = √(½ (S_a + S_b - 2 C))`, clamped at 0 against rounding.
fn from_sums(self_a: f64, self_b: f64, cross: f64) -> f64 {
    (0.5 * (self_a + self_b - 2.0 * cross)).max(0.0).sqrt()
}

impl VanRossum {
    /// The kernel's time constant, ms.
    pub fn tau_ms(&self) -> f64 {
        self.tau_ms
    }

    /// Distance between two recordings: the square root of the taxels' summed squared
    /// distances (computed exactly, pair by pair).
    ///
    /// # Errors
    /// Recordings on different grids.
    pub fn distance(&self, a: &SpikeTrains, b: &SpikeTrains) -> Result<f64, ClassifyError> {
        let taxels = common_taxels([("first", 0, a), ("second", 0, b)])?;
        Ok(self.squared_exact(a, b, &taxels).sqrt())
    }

    fn squared_exact(&self, a: &SpikeTrains, b: &SpikeTrains, taxels: &[usize]) -> f64 {
        taxels
            .iter()
            .map(|&c| van_rossum_squared(a.train(c), b.train(c), self.tau_ms))
            .sum()
    }

    /// `e^{-d/τ}` for `d` in `0..=steps`, flushed to 0 below 1e-300 (subnormal arithmetic
    /// is slow and the value no longer counts).
    fn decay_table(&self, steps: usize) -> Vec<f64> {
        (0..=steps)
            .map(|d| (-(d as f64) / self.tau_ms).exp())
            .map(|q| if q < 1e-300 { 0.0 } else { q })
            .collect()
    }

    /// Whether the trace table of recordings `steps` long fits [`MAX_TRACE_VALUES`].
    fn traces_fit(steps: usize, taxels: usize) -> bool {
        steps.saturating_mul(taxels) <= MAX_TRACE_VALUES
    }

    /// The distance matrix of `recordings` (all on one grid), rows computed in parallel,
    /// each pair once. Recordings may differ in length: the kernel integrates to infinity.
    ///
    /// # Errors
    /// Recordings on different grids.
    pub fn matrix(&self, recordings: &[SpikeTrains]) -> Result<DistanceMatrix, ClassifyError> {
        let taxels = common_taxels(recordings.iter().enumerate().map(|(i, r)| ("", i, r)))?;
        let n = recordings.len();
        let steps = recordings.iter().map(|r| r.n_steps).max().unwrap_or(0);
        let mut values = vec![0.0; n * n];
        if Self::traces_fit(steps, taxels.len()) {
            self.fill_upper_with_traces(recordings, &taxels, steps, &mut values);
        } else {
            let rows: Vec<Vec<f64>> = (0..n)
                .into_par_iter()
                .map(|i| {
                    let a = &recordings[i];
                    let row = recordings[i + 1..].iter();
                    row.map(|b| self.squared_exact(a, b, &taxels).sqrt())
                        .collect()
                })
                .collect();
            for (i, row) in rows.into_iter().enumerate() {
                values[i * n + i + 1..(i + 1) * n].copy_from_slice(&row);
            }
        }
        for i in 0..n {
            for j in 0..i {
                values[i * n + j] = values[j * n + i];
            }
        }
        Ok(DistanceMatrix { n, values })
    }

    /// The upper triangle of the matrix through trace tables: each row builds its
    /// recording's traces once and looks up the later recordings' spikes in them.
    fn fill_upper_with_traces(
        &self,
        recordings: &[SpikeTrains],
        taxels: &[usize],
        steps: usize,
        values: &mut [f64],
    ) {
        let n = recordings.len();
        let decay = self.decay_table(steps);
        let rows: Vec<(f64, Vec<f64>)> = (0..n)
            .into_par_iter()
            .map_init(
                || Traces::new(steps, taxels.len()),
                |traces, i| {
                    traces.fill(&recordings[i], taxels, &decay);
                    let own = traces.cross_sum(&recordings[i], taxels);
                    let cross = recordings[i + 1..]
                        .iter()
                        .map(|b| traces.cross_sum(b, taxels))
                        .collect();
                    (own, cross)
                },
            )
            .collect();
        let own: Vec<f64> = rows.iter().map(|(s, _)| *s).collect();
        for (i, (_, cross)) in rows.into_iter().enumerate() {
            for (k, c) in cross.into_iter().enumerate() {
                let j = i + 1 + k;
                values[i * n + j] = from_sums(own[i], own[j], c);
            }
        }
    }

    /// Distances from each of `queries` to each of `references` (all on one grid),
    /// row-major `queries.len() x references.len()`: what a fitted
    /// [`SpikeDistanceKnnModel`] needs to classify new recordings.
    ///
    /// # Errors
    /// Recordings on different grids.
    pub fn cross_distances(
        &self,
        queries: &[SpikeTrains],
        references: &[SpikeTrains],
    ) -> Result<Vec<f64>, ClassifyError> {
        let all = references
            .iter()
            .enumerate()
            .map(|(i, t)| ("reference", i, t))
            .chain(queries.iter().enumerate().map(|(i, t)| ("query", i, t)));
        let taxels = common_taxels(all)?;
        let steps = queries.iter().chain(references).map(|r| r.n_steps).max();
        let steps = steps.unwrap_or(0);
        if !Self::traces_fit(steps, taxels.len()) {
            let rows: Vec<Vec<f64>> = queries
                .par_iter()
                .map(|q| {
                    let row = references.iter();
                    row.map(|r| self.squared_exact(q, r, &taxels).sqrt())
                        .collect()
                })
                .collect();
            return Ok(rows.concat());
        }
        let decay = self.decay_table(steps);
        let own = |set: &[SpikeTrains]| -> Vec<f64> {
            set.par_iter()
                .map_init(
                    || Traces::new(steps, taxels.len()),
                    |traces, r| {
                        traces.fill(r, &taxels, &decay);
                        traces.cross_sum(r, &taxels)
                    },
                )
                .collect()
        };
        let own_ref = own(references);
        let rows: Vec<Vec<f64>> = queries
            .par_iter()
            .map_init(
                || Traces::new(steps, taxels.len()),
                |traces, q| {
                    traces.fill(q, &taxels, &decay);
                    let own_q = traces.cross_sum(q, &taxels);
                    let refs = references.iter().zip(&own_ref);
                    refs.map(|(r, &own_r)| from_sums(own_q, own_r, traces.cross_sum(r, &taxels)))
                        .collect()
                },
            )
            .collect();
        Ok(rows.concat())
    }
}

impl Samples for DistanceMatrix {
    fn count(&self) -> usize {
        self.n()
    }
}

/// K-nearest neighbours over a precomputed [`DistanceMatrix`] of recordings: a
/// [`Learner`] whose samples are the matrix's recordings. Fitting stores the training
/// recordings' indices and labels; prediction looks up each query's distances to them in
/// the matrix.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpikeDistanceKnn {
    k: usize,
}

impl SpikeDistanceKnn {
    /// A classifier with `k` neighbours.
    ///
    /// # Errors
    /// `k` of 0.
    pub fn new(k: usize) -> Result<Self, ParamError> {
        if k == 0 {
            return Err(ParamError::new("k", "k must be at least 1", k));
        }
        Ok(SpikeDistanceKnn { k })
    }

    /// Neighbours.
    pub fn k(&self) -> usize {
        self.k
    }
}

/// Checks that `rows` are recordings of `matrix`.
///
/// # Errors
/// The first index past the matrix's last recording.
fn check_rows(matrix: &DistanceMatrix, rows: &[usize], role: &str) -> Result<(), ClassifyError> {
    let n = matrix.n();
    match rows.iter().position(|&i| i >= n) {
        None => Ok(()),
        Some(pos) => Err(ClassifyError::BadFeatures(format!(
            "{role} sample {pos} is {}, not a row index of the {n} x {n} distance matrix",
            rows[pos]
        ))),
    }
}

impl Learner<DistanceMatrix> for SpikeDistanceKnn {
    type Fitted = SpikeDistanceKnnModel;

    /// Stores the training recordings' row indices and labels.
    ///
    /// # Errors
    /// No training recording, labels of another length than `rows`, an index past the
    /// matrix, `k` larger than the training set.
    fn learn(
        &self,
        matrix: &DistanceMatrix,
        rows: &[usize],
        y: &[usize],
    ) -> Result<SpikeDistanceKnnModel, ClassifyError> {
        if y.is_empty() {
            return Err(ClassifyError::Empty { what: "train on" });
        }
        if rows.len() != y.len() {
            return Err(ClassifyError::BadFeatures(format!(
                "{} training recordings for {} labels",
                rows.len(),
                y.len()
            )));
        }
        if self.k > y.len() {
            return Err(ClassifyError::KTooLarge {
                k: self.k,
                n_train: y.len(),
            });
        }
        check_rows(matrix, rows, "training")?;
        Ok(SpikeDistanceKnnModel {
            k: self.k,
            train: rows.to_vec(),
            labels: y.to_vec(),
            n_classes: y.iter().max().map_or(0, |&m| m + 1),
        })
    }
}

/// A fitted [`SpikeDistanceKnn`]: the training recordings' row indices and labels.
#[derive(Debug, Clone, PartialEq)]
pub struct SpikeDistanceKnnModel {
    k: usize,
    train: Vec<usize>,
    labels: Vec<usize>,
    n_classes: usize,
}

impl SpikeDistanceKnnModel {
    /// The training recordings' row indices into the matrix, in training order.
    pub fn training_indices(&self) -> &[usize] {
        &self.train
    }

    /// The training labels, in training order.
    pub fn labels(&self) -> &[usize] {
        &self.labels
    }

    /// The classes the votes cover: the largest training class index, plus one.
    pub fn n_classes(&self) -> usize {
        self.n_classes
    }

    /// Predicts recordings given by their distances to the training recordings: row-major,
    /// one row per query of [`SpikeDistanceKnnModel::training_indices`]`.len()` distances
    /// in training order (from [`VanRossum::cross_distances`] against the training
    /// recordings).
    ///
    /// # Panics
    /// If `distances` is not whole rows of the training set's size (a caller bug).
    pub fn predict_from_distances(&self, distances: &[f64]) -> Vec<usize> {
        let n = self.train.len();
        assert_eq!(
            distances.len() % n,
            0,
            "rows must hold one distance per training recording"
        );
        let mut votes = vec![0usize; self.n_classes];
        let mut best = Vec::with_capacity(self.k);
        distances
            .chunks_exact(n)
            .map(|row| vote(self.k, row, &self.labels, &mut best, &mut votes))
            .collect()
    }

    /// The predicted class of each of the recordings `rows` of `matrix`, with every
    /// class's votes among the `k` nearest training recordings divided by `k`.
    ///
    /// # Errors
    /// An index past the matrix's last recording, or a matrix smaller than the one the
    /// model was fitted on.
    pub fn predict_with_shares(
        &self,
        matrix: &DistanceMatrix,
        rows: &[usize],
    ) -> Result<Vec<(usize, Vec<f64>)>, ClassifyError> {
        check_rows(matrix, rows, "query")?;
        check_rows(matrix, &self.train, "training")?;
        let k = self.k as f64;
        let mut votes = vec![0usize; self.n_classes];
        let mut best = Vec::with_capacity(self.k);
        let mut row = vec![0.0; self.train.len()];
        let mut out = Vec::with_capacity(rows.len());
        for &q in rows {
            let all = matrix.row(q);
            for (d, &t) in row.iter_mut().zip(&self.train) {
                *d = all[t];
            }
            let predicted = vote(self.k, &row, &self.labels, &mut best, &mut votes);
            out.push((predicted, votes.iter().map(|&v| v as f64 / k).collect()));
        }
        Ok(out)
    }
}

/// The majority class among the `k` training samples nearest under the order (distance,
/// training position); among classes with equal votes, the one with the nearest member.
fn vote(
    k: usize,
    distances: &[f64],
    labels: &[usize],
    best: &mut Vec<(f64, usize)>,
    votes: &mut [usize],
) -> usize {
    best.clear();
    for key in distances.iter().copied().zip(0..) {
        insert(best, k, key);
    }
    majority(best, labels, votes)
}

impl Decide<DistanceMatrix> for SpikeDistanceKnnModel {
    fn decide(
        &self,
        matrix: &DistanceMatrix,
        rows: &[usize],
    ) -> Result<Vec<Vec<usize>>, ClassifyError> {
        let shares = self.predict_with_shares(matrix, rows)?;
        Ok(vec![shares.into_iter().map(|p| p.0).collect()])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn random_recordings(n: usize, steps: u32, seed: u64) -> Vec<SpikeTrains> {
        let mut next = crate::testing::xorshift(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1);
        let present = [true, false, true, true];
        (0..n)
            .map(|_| {
                let lists: Vec<Vec<u32>> = (0..4)
                    .map(|_| (0..steps).filter(|_| next().is_multiple_of(40)).collect())
                    .collect();
                SpikeTrains::from_lists(&lists, 2, 2, &present, steps as usize)
            })
            .collect()
    }

    #[test]
    fn the_trace_table_path_matches_the_exact_pairwise_merge() {
        let recs = random_recordings(7, 3_000, 3);
        for tau in [1.0, 10.0, 200.0] {
            let metric = VanRossumParams { tau_ms: tau }.check().unwrap();
            let m = metric.matrix(&recs).unwrap();
            let taxels = [0, 2, 3];
            for i in 0..7 {
                assert_eq!(m.get(i, i), 0.0);
                for j in 0..7 {
                    let exact = metric.squared_exact(&recs[i], &recs[j], &taxels).sqrt();
                    let tol = 1e-9 * (1.0 + exact);
                    assert!((m.get(i, j) - exact).abs() < tol, "{tau} {i} {j}");
                }
            }
            let cross = metric.cross_distances(&recs[..3], &recs).unwrap();
            for (q, row) in cross.chunks_exact(7).enumerate() {
                for (r, &d) in row.iter().enumerate() {
                    assert!((d - m.get(q, r)).abs() < 1e-9 * (1.0 + d));
                }
            }
        }
    }
}
