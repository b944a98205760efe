//! Multinomial logistic regression with an L2 penalty, scikit-learn's
//! `LogisticRegression(C, solver="lbfgs")` on z-scored features.
//!
//! Features are z-scored with the training set's mean and population standard deviation (a
//! feature constant in training is only centred, as in KNN). The weights `W` (one row per
//! class) and intercepts `b` minimise
//! `(1/n) Σ_i -log softmax(W z_i + b)[y_i] + ‖W‖² / (2 C n)`,
//! which is scikit-learn's objective (`C Σ_i loss_i + ‖W‖²/2`, intercepts unpenalised)
//! divided by `C n`. The problem is smooth and convex; it is solved by L-BFGS (forty
//! correction pairs and the initial Hessian of [`Preconditioner`] up to 256 features, ten
//! pairs and a scaled identity beyond; backtracking Armijo line search) from zero until
//! the largest absolute
//! gradient component is at most `tol`, or `max_iter` iterations. Starting from zero keeps
//! the intercepts summing to zero (every gradient does), which fixes the one direction the
//! penalty leaves free. Classes absent from the training set get probability 0 and take no
//! part in the fit (their intercept would run to minus infinity).
//!
//! Written here rather than taken from linfa-logistic (argmin's L-BFGS): that crate
//! penalises with its own `alpha` and does not scale features, so matching scikit-learn's
//! `C` would need a translation layer around it, and it brings argmin and a second ndarray
//! major version into the build for about a hundred lines of optimiser. Everything here is
//! sequential and deterministic.

use std::collections::VecDeque;

use serde::{Deserialize, Serialize};

use super::{check_training, first_max, Classifier, Predict};
use crate::error::{ClassifyError, ParamError};

/// Logistic regression parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinearParams {
    /// Inverse penalty strength, scikit-learn's `C` (1.0): smaller penalises more.
    pub c: f64,
    /// Most L-BFGS iterations (1000).
    pub max_iter: usize,
    /// Stop when no gradient component of the objective exceeds this (1e-8).
    pub tol: f64,
}

impl Default for LinearParams {
    fn default() -> Self {
        LinearParams {
            c: 1.0,
            max_iter: 1000,
            tol: 1e-8,
        }
    }
}

impl LinearParams {
    /// Checks the rules (`c` and `tol` positive and finite, at least one iteration) and
    /// returns the unfitted classifier.
    ///
    /// # Errors
    /// The rule broken.
    pub fn check(self) -> Result<Linear, ParamError> {
        if !(self.c > 0.0 && self.c.is_finite()) {
            return Err(ParamError::new(
                "c",
                "C must be positive and finite",
                self.c,
            ));
        }
        if self.max_iter == 0 {
            return Err(ParamError::new(
                "max_iter",
                "at least 1 iteration is needed",
                0,
            ));
        }
        if !(self.tol > 0.0 && self.tol.is_finite()) {
            return Err(ParamError::new(
                "tol",
                "the tolerance must be positive and finite",
                self.tol,
            ));
        }
        Ok(Linear { params: self })
    }
}

/// The unfitted classifier, with parameters that passed [`LinearParams::check`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Linear {
    params: LinearParams,
}

impl Linear {
    /// The parameters.
    pub fn params(&self) -> LinearParams {
        self.params
    }
}

/// A fitted logistic regression.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearModel {
    dims: usize,
    n_classes: usize,
    /// The classes seen in training, ascending; the rows of `weights`.
    classes: Vec<usize>,
    mean: Vec<f64>,
    inv_std: Vec<f64>,
    /// `classes.len() x dims`, row-major, on z-scored features.
    weights: Vec<f64>,
    intercepts: Vec<f64>,
    iterations: usize,
    converged: bool,
}

impl LinearModel {
    /// The classes seen in training, ascending: the rows of [`LinearModel::weights`].
    pub fn classes(&self) -> &[usize] {
        &self.classes
    }

    /// The weights on z-scored features, one row of [`Predict::dims`] per class of
    /// [`LinearModel::classes`] (scikit-learn's `coef_` fitted on standardised features).
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }

    /// The intercepts, one per class of [`LinearModel::classes`]; they sum to zero.
    pub fn intercepts(&self) -> &[f64] {
        &self.intercepts
    }

    /// L-BFGS iterations made.
    pub fn iterations(&self) -> usize {
        self.iterations
    }

    /// Whether the gradient fell to the tolerance within `max_iter` iterations (else the
    /// model holds the last iterate).
    pub fn converged(&self) -> bool {
        self.converged
    }

    /// Every class's probability for one row (0 for classes absent in training).
    fn shares(&self, row: &[f64]) -> Vec<f64> {
        let z: Vec<f64> = row
            .iter()
            .zip(self.mean.iter().zip(&self.inv_std))
            .map(|(&v, (&m, &s))| (v - m) * s)
            .collect();
        let logits: Vec<f64> = self
            .weights
            .chunks_exact(self.dims)
            .zip(&self.intercepts)
            .map(|(w, &b)| b + dot(w, &z))
            .collect();
        let mut shares = vec![0.0; self.n_classes];
        for (&c, p) in self.classes.iter().zip(softmax(&logits)) {
            shares[c] = p;
        }
        shares
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// `a · b` summed in eight running sums (the solver's long vectors: independent sums fill
/// the vector units where one running sum waits on each addition). The sums are lanes, so
/// AVX-512 gives the plain code's bits.
#[inline(always)]
fn dot8(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let whole = n - n % 8;
    let tail: f64 = a[whole..n]
        .iter()
        .zip(&b[whole..n])
        .map(|(x, y)| x * y)
        .sum();
    let mut sums = [0.0; 8];
    for (x, y) in a[..whole].chunks_exact(8).zip(b[..whole].chunks_exact(8)) {
        for i in 0..8 {
            sums[i] += x[i] * y[i];
        }
    }
    sums.iter().sum::<f64>() + tail
}

/// `q[i] += a * v[i]`, element by element.
#[inline(always)]
fn add_scaled(q: &mut [f64], a: f64, v: &[f64]) {
    let n = q.len().min(v.len());
    let (q, v) = (&mut q[..n], &v[..n]);
    for i in 0..n {
        q[i] += a * v[i];
    }
}

/// `q[i] -= a * v[i]`, element by element.
#[inline(always)]
fn sub_scaled(q: &mut [f64], a: f64, v: &[f64]) {
    let n = q.len().min(v.len());
    let (q, v) = (&mut q[..n], &v[..n]);
    for i in 0..n {
        q[i] -= a * v[i];
    }
}

/// Softmax of `logits`, shifted by their maximum.
fn softmax(logits: &[f64]) -> Vec<f64> {
    let top = logits.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let exp: Vec<f64> = logits.iter().map(|&l| (l - top).exp()).collect();
    let sum: f64 = exp.iter().sum();
    exp.iter().map(|e| e / sum).collect()
}

/// The fitting problem: z-scored rows, compact class indices, the penalty factor.
struct Problem {
    z: Vec<f64>,
    dims: usize,
    y: Vec<usize>,
    k: usize,
    /// `1 / (C n)`.
    penalty: f64,
}

impl Problem {
    /// The objective and its gradient at `theta` (`k x dims` weights, then `k` intercepts).
    ///
    /// Rows go a group of [`ROWS`] at a time: the group's logits are summed for four
    /// classes side by side and its gradient terms sixteen features of two classes side by
    /// side,
    /// but every sum is formed in the order of the textbook loop (one row, then each
    /// class's dot product over the features, then its gradient terms): each logit is
    /// `b + Σ_j w_j z_j` summed over `j` from -0 upward as `Iterator::sum` does, and each
    /// gradient entry adds the rows in their order. So the result is bit for bit that of
    /// the row-by-row loop (`tests::value_grad_is_the_row_by_row_loop`), in less time: the
    /// sums of a group are independent, so they fill the vector units instead of waiting on
    /// one addition after another.
    fn value_grad(&self, theta: &[f64]) -> (f64, Vec<f64>) {
        self.value_grad_with(Kernels::fastest(), theta)
    }

    /// [`Problem::value_grad`] with the given kernels.
    fn value_grad_with(&self, kernels: Kernels, theta: &[f64]) -> (f64, Vec<f64>) {
        let (d, k) = (self.dims, self.k);
        let (w, b) = theta.split_at(k * d);
        // The weights feature-major, classes padded to whole blocks with zeros (their logits
        // are computed and never read).
        let padded = k.div_ceil(LANES) * LANES;
        let mut by_feature = vec![0.0; d * padded];
        for (c, wc) in w.chunks_exact(d).enumerate() {
            for (j, &wj) in wc.iter().enumerate() {
                by_feature[j * padded + c] = wj;
            }
        }
        let mut grad = vec![0.0; theta.len()];
        let mut loss = 0.0;
        let mut logits = vec![0.0; ROWS * padded];
        let mut residuals = vec![0.0; ROWS * k];
        let (mut rows, mut labels) = (self.z.chunks(ROWS * d), self.y.chunks(ROWS));
        while let (Some(z), Some(y)) = (rows.next(), labels.next()) {
            (kernels.logits)(z, &by_feature, d, &mut logits);
            for (r, &yr) in y.iter().enumerate() {
                let l = &mut logits[r * padded..r * padded + k];
                l.iter_mut().zip(b).for_each(|(l, &bc)| *l += bc);
                let top = l.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                let sum: f64 = l.iter().map(|&l| (l - top).exp()).sum();
                let log_norm = top + sum.ln();
                loss += log_norm - l[yr];
                let res = &mut residuals[r * k..(r + 1) * k];
                for (c, (res, &lc)) in res.iter_mut().zip(&*l).enumerate() {
                    *res = (lc - log_norm).exp() - f64::from(u8::from(c == yr));
                }
            }
            let (gw, gb) = grad.split_at_mut(k * d);
            let residuals = &residuals[..y.len() * k];
            (kernels.gradient)(z, residuals, k, gw);
            for (c, g) in gb.iter_mut().enumerate() {
                residuals.iter().skip(c).step_by(k).for_each(|r| *g += r);
            }
        }
        let n = self.y.len() as f64;
        grad.iter_mut().for_each(|g| *g /= n);
        for (g, &wj) in grad.iter_mut().zip(w) {
            *g += self.penalty * wj;
        }
        (loss / n + 0.5 * self.penalty * dot(w, w), grad)
    }
}

/// Classes per block of the logits: one block's sums fill one AVX2 register.
const LANES: usize = 4;
/// Rows per group: a group runs `ROWS` independent chains of additions per block of
/// classes, enough to hide an addition's latency, and its gradient terms are added to each
/// gradient entry with one load and one store.
const ROWS: usize = 8;

/// The two loops of [`Problem::value_grad`] over a group of rows, for this processor.
#[derive(Clone, Copy)]
struct Kernels {
    /// Every row's dot product with every padded class's weights (feature-major) into
    /// `out`, `padded` per row.
    logits: fn(z: &[f64], by_feature: &[f64], d: usize, out: &mut [f64]),
    /// Adds the rows' gradient terms, `residual x row`, to each class's row of weights'
    /// gradient, row after row.
    gradient: fn(z: &[f64], residuals: &[f64], k: usize, gw: &mut [f64]),
}

impl Kernels {
    fn fastest() -> Self {
        #[cfg(target_arch = "x86_64")]
        {
            if neurotex_core::has_feature!("avx512f") && neurotex_core::has_feature!("avx2") {
                return Kernels {
                    // SAFETY (both): the CPU supports AVX-512F and AVX2, the features they
                    // enable.
                    logits: |z, w, d, out| unsafe { avx512::logits(z, w, d, out) },
                    gradient: |z, res, k, gw| unsafe { avx512::gradient(z, res, k, gw) },
                };
            }
            if neurotex_core::has_feature!("avx2") {
                return Kernels {
                    // SAFETY (both): the CPU supports AVX2, the only feature they enable.
                    logits: |z, w, d, out| unsafe { avx2::logits(z, w, d, out) },
                    gradient: |z, res, k, gw| unsafe { avx2::gradient(z, res, k, gw) },
                };
            }
        }
        Kernels {
            logits: logits_portable,
            gradient: gradient_portable,
        }
    }
}

/// [`Kernels::logits`] in plain Rust: the same sums in the same order, one at a time.
fn logits_portable(z: &[f64], by_feature: &[f64], d: usize, out: &mut [f64]) {
    let padded = by_feature.len() / d;
    for (row, out) in z.chunks_exact(d).zip(out.chunks_exact_mut(padded)) {
        for (c, o) in out.iter_mut().enumerate() {
            let column = by_feature.iter().skip(c).step_by(padded);
            *o = column.zip(row).map(|(w, x)| w * x).sum();
        }
    }
}

/// [`Kernels::gradient`] in plain Rust.
fn gradient_portable(z: &[f64], residuals: &[f64], k: usize, gw: &mut [f64]) {
    let d = gw.len() / k;
    for (row, res) in z.chunks_exact(d).zip(residuals.chunks_exact(k)) {
        for (g, &r) in gw.chunks_exact_mut(d).zip(res) {
            g.iter_mut().zip(row).for_each(|(gj, &zj)| *gj += r * zj);
        }
    }
}

/// The vector kernels of one width, as functions of the enclosing module: `blocks` (the
/// logits of a group of [`ROWS`] rows, `$lanes` classes a register, for padded classes a
/// multiple of `$lanes`), `gradient_two` (`4 x $lanes` features of two classes' gradients
/// held in registers while the group's rows are added in order; returns the first feature
/// left) and `gradient` (every pair of classes so, the rest of each class and the last of
/// an odd number of classes by the AVX2 `tail`). A multiply then an add (no FMA), so each
/// lane's rounding is the scalar loop's.
#[cfg(target_arch = "x86_64")]
macro_rules! wide_kernels {
    ($feature:literal, $lanes:expr, $zero:ident, $set1:ident, $load:ident, $store:ident,
     $add:ident, $mul:ident) => {
        /// The logits of a group of rows, a block of classes at a time.
        #[target_feature(enable = $feature)]
        unsafe fn blocks(z: &[f64], by_feature: &[f64], d: usize, out: &mut [f64]) {
            let padded = by_feature.len() / d;
            for block in (0..padded).step_by($lanes) {
                let mut acc = [$set1(-0.0); ROWS];
                for (j, w) in by_feature.chunks_exact(padded).enumerate() {
                    let w = $load(w[block..block + $lanes].as_ptr());
                    for (r, a) in acc.iter_mut().enumerate() {
                        let x = $set1(z[r * d + j]);
                        *a = $add(*a, $mul(w, x));
                    }
                }
                for (r, a) in acc.iter().enumerate() {
                    let o = &mut out[r * padded + block..r * padded + block + $lanes];
                    $store(o.as_mut_ptr(), *a);
                }
            }
        }

        /// [`super::Kernels::gradient`], two classes at a time.
        #[target_feature(enable = $feature)]
        pub(super) unsafe fn gradient(z: &[f64], residuals: &[f64], k: usize, gw: &mut [f64]) {
            let d = gw.len() / k;
            let rows = residuals.len() / k;
            let mut pairs = gw.chunks_exact_mut(2 * d);
            let mut c = 0;
            for pair in pairs.by_ref() {
                let (ga, gb) = pair.split_at_mut(d);
                let j = gradient_two(z, residuals, (k, c, rows), ga, gb);
                super::avx2::tail(z, residuals, k, c, rows, j, ga);
                super::avx2::tail(z, residuals, k, c + 1, rows, j, gb);
                c += 2;
            }
            let last = pairs.into_remainder();
            if !last.is_empty() {
                super::avx2::tail(z, residuals, k, c, rows, 0, last);
            }
        }

        /// Classes `c` and `c + 1`'s gradients `ga` and `gb`, `4 x $lanes` features at a
        /// time; the first feature left.
        #[target_feature(enable = $feature)]
        unsafe fn gradient_two(
            z: &[f64],
            residuals: &[f64],
            (k, c, rows): (usize, usize, usize),
            ga: &mut [f64],
            gb: &mut [f64],
        ) -> usize {
            let d = ga.len();
            let mut j = 0;
            while j + 4 * $lanes <= d {
                let mut a = [$zero(); 4];
                let mut b = [$zero(); 4];
                for q in 0..4 {
                    a[q] = $load(ga[j + q * $lanes..][..$lanes].as_ptr());
                    b[q] = $load(gb[j + q * $lanes..][..$lanes].as_ptr());
                }
                for r in 0..rows {
                    let res = &residuals[r * k + c..r * k + c + 2];
                    let (ra, rb) = ($set1(res[0]), $set1(res[1]));
                    let row = &z[r * d + j..r * d + j + 4 * $lanes];
                    for q in 0..4 {
                        let x = $load(row[q * $lanes..][..$lanes].as_ptr());
                        a[q] = $add(a[q], $mul(ra, x));
                        b[q] = $add(b[q], $mul(rb, x));
                    }
                }
                for q in 0..4 {
                    $store(ga[j + q * $lanes..][..$lanes].as_mut_ptr(), a[q]);
                    $store(gb[j + q * $lanes..][..$lanes].as_mut_ptr(), b[q]);
                }
                j += 4 * $lanes;
            }
            j
        }
    };
}

/// The AVX2 kernels: four f64 lanes.
#[cfg(target_arch = "x86_64")]
mod avx2 {
    use std::arch::x86_64::*;

    use super::{LANES, ROWS};

    wide_kernels!(
        "avx2",
        LANES,
        _mm256_setzero_pd,
        _mm256_set1_pd,
        _mm256_loadu_pd,
        _mm256_storeu_pd,
        _mm256_add_pd,
        _mm256_mul_pd
    );

    /// [`super::Kernels::logits`]: for each block of four classes, the group's rows' sums
    /// in eight registers, one multiply and add per row and feature.
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn logits(z: &[f64], by_feature: &[f64], d: usize, out: &mut [f64]) {
        if z.len() / d < ROWS {
            super::logits_portable(z, by_feature, d, out);
            return;
        }
        blocks(z, by_feature, d, out);
    }

    /// Features `j..` of class `c`'s gradient `g`: four, then one at a time.
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn tail(
        z: &[f64],
        residuals: &[f64],
        k: usize,
        c: usize,
        rows: usize,
        mut j: usize,
        g: &mut [f64],
    ) {
        let d = g.len();
        while j + LANES <= d {
            let mut acc = _mm256_loadu_pd(g[j..j + LANES].as_ptr());
            for r in 0..rows {
                let res = _mm256_set1_pd(residuals[r * k + c]);
                let x = _mm256_loadu_pd(z[r * d + j..r * d + j + LANES].as_ptr());
                acc = _mm256_add_pd(acc, _mm256_mul_pd(res, x));
            }
            _mm256_storeu_pd(g[j..j + LANES].as_mut_ptr(), acc);
            j += LANES;
        }
        for (jj, gj) in g.iter_mut().enumerate().skip(j) {
            for r in 0..rows {
                *gj += residuals[r * k + c] * z[r * d + jj];
            }
        }
    }
}

/// The AVX-512 kernels: eight f64 lanes; logits whose padded classes are not a multiple of
/// eight, and groups of fewer rows, go to the AVX2 kernel.
#[cfg(target_arch = "x86_64")]
mod avx512 {
    use std::arch::x86_64::*;

    use super::ROWS;

    /// Classes per block of the logits.
    const WIDE: usize = 8;

    wide_kernels!(
        "avx512f,avx2",
        WIDE,
        _mm512_setzero_pd,
        _mm512_set1_pd,
        _mm512_loadu_pd,
        _mm512_storeu_pd,
        _mm512_add_pd,
        _mm512_mul_pd
    );

    /// [`super::Kernels::logits`] eight classes a register.
    #[target_feature(enable = "avx512f,avx2")]
    pub(super) unsafe fn logits(z: &[f64], by_feature: &[f64], d: usize, out: &mut [f64]) {
        let padded = by_feature.len() / d;
        if z.len() / d < ROWS || !padded.is_multiple_of(WIDE) {
            super::avx2::logits(z, by_feature, d, out);
            return;
        }
        blocks(z, by_feature, d, out);
    }
}

/// The end of an L-BFGS run.
struct Solution {
    theta: Vec<f64>,
    iterations: usize,
    converged: bool,
}

/// L-BFGS's search direction `-H g` by the two-loop recursion over the stored pairs
/// `(s, y, 1/(s·y))`, the initial Hessian the preconditioner's (else the identity), scaled
/// by the newest pair. Every step is element by element or a sum in lanes
/// ([`dot8`]), so it is compiled for the widest vectors too with the same bits.
fn direction(
    grad: &[f64],
    pairs: &VecDeque<(Vec<f64>, Vec<f64>, f64)>,
    pre: Option<&Preconditioner>,
) -> Vec<f64> {
    let pre = pre.map(|p| (&p.inverse[..], p.dims, p.curvature));
    direction_wide(grad, pairs, pre)
}

neurotex_core::widest_or_plain! {
    ["avx512f", "avx2"]
    /// [`direction`], the preconditioner as its inverse, dimension and curvature.
    fn direction_wide(
        grad: &[f64],
        pairs: &VecDeque<(Vec<f64>, Vec<f64>, f64)>,
        pre: Option<(&[f64], usize, f64)>,
    ) -> Vec<f64> {
        let mut q = grad.to_vec();
        let mut alpha = Vec::with_capacity(pairs.len());
        for (s, y, rho) in pairs.iter().rev() {
            let a = rho * dot8(s, &q);
            sub_scaled(&mut q, a, y);
            alpha.push(a);
        }
        let mut scratch = Vec::new();
        if let Some((inverse, d, curvature)) = pre {
            solve(inverse, d, curvature, &mut q, &mut scratch);
        }
        if let Some((s, y, _)) = pairs.back() {
            let mut my = y.clone();
            if let Some((inverse, d, curvature)) = pre {
                solve(inverse, d, curvature, &mut my, &mut scratch);
            }
            let gamma = dot8(s, y) / dot8(y, &my);
            for qi in q.iter_mut() {
                *qi *= gamma;
            }
        }
        for ((s, y, rho), a) in pairs.iter().zip(alpha.iter().rev()) {
            let b = rho * dot8(y, &q);
            add_scaled(&mut q, a - b, s);
        }
        for qi in q.iter_mut() {
            *qi = -*qi;
        }
        q
    }
}

/// L-BFGS's initial inverse Hessian, the inverse of `a Σ + λ I` for each class's weights
/// and of `a` for its intercept (`Σ` the z-scored features' second moments, `λ` the
/// penalty): the objective's Hessian with the coupling between classes left out and every
/// row's softmax curvature taken as `a`.
///
/// Collinear features (every taxel's statistics side by side, 48 or 96 columns in E9) give
/// the plain problem directions of curvature thousands of times the penalty's, and L-BFGS
/// from a scaled identity crawled along them (500-800 iterations on E9's fits). This
/// matrix takes them out. It costs `dims²` numbers and `dims³` operations per fit, so
/// problems of more than [`PRECONDITIONED_DIMS`] features go without it (and with the ten
/// correction pairs of plain L-BFGS, whose memory grows with the features too). It changes the path, not the minimum: the fit stops at the same
/// gradient tolerance. `a = A_SHARE / k`: at uniform probabilities a row's curvature is
/// `1/k`, but at the minimum of a training set the classes separate well, most rows are
/// fitted with probabilities near 0 or 1 and their curvature is far smaller. `A_SHARE`
/// was measured, not derived: of `(1, 0.3, 0.1, 0.03, 0.01, 0.003) / k`, `0.01 / k` gave
/// the shortest total fit time of E9's logistic regressions on a simulated dataset.
struct Preconditioner {
    dims: usize,
    /// `a`.
    curvature: f64,
    /// `(a Σ + λ I)⁻¹`, `dims x dims` row-major.
    inverse: Vec<f64>,
}

/// The share of the uniform curvature `1/k` the preconditioner assumes for every row.
const A_SHARE: f64 = 0.01;

/// The most features a fit is preconditioned for: the inverse is then at most 512 KiB and
/// a few milliseconds to form.
const PRECONDITIONED_DIMS: usize = 256;

impl Preconditioner {
    /// The preconditioner of `problem`, or `None` beyond [`PRECONDITIONED_DIMS`] features.
    fn new(problem: &Problem) -> Option<Self> {
        let d = problem.dims;
        if d > PRECONDITIONED_DIMS {
            return None;
        }
        let n = problem.y.len() as f64;
        let curvature = A_SHARE / problem.k as f64;
        let mut m = vec![0.0; d * d];
        for row in problem.z.chunks_exact(d) {
            for (i, &zi) in row.iter().enumerate() {
                let mi = &mut m[i * d..i * d + i + 1];
                mi.iter_mut().zip(row).for_each(|(m, &zj)| *m += zi * zj);
            }
        }
        for i in 0..d {
            for j in 0..=i {
                m[i * d + j] *= curvature / n;
            }
            m[i * d + i] += problem.penalty;
        }
        Some(Preconditioner {
            dims: d,
            curvature,
            inverse: inverse(m, d),
        })
    }
}

/// `v` (`k` rows of weights, then `k` intercepts) times the preconditioner's inverse
/// (`d x d`) and its intercepts divided by `curvature`, `out` scratch space. Each class's
/// entry `j` is `Σ_i v_i inverse_ij` added from 0 in the order of `i`; the classes go side
/// by side, so each row of the inverse is read once per call.
#[inline(always)]
fn solve(inverse: &[f64], d: usize, curvature: f64, v: &mut [f64], out: &mut Vec<f64>) {
    let k = v.len() / (d + 1);
    let (w, b) = v.split_at_mut(k * d);
    out.clear();
    out.resize(k * d, 0.0);
    for i in 0..d {
        let row = &inverse[i * d..(i + 1) * d];
        for c in 0..k {
            let g = w[c * d + i];
            let o = &mut out[c * d..(c + 1) * d];
            for j in 0..d {
                o[j] += g * row[j];
            }
        }
    }
    w.copy_from_slice(out);
    for bc in b.iter_mut() {
        *bc /= curvature;
    }
}

/// The inverse of the symmetric positive definite `m` (`d x d`, row-major, lower triangle
/// read) through its Cholesky factor. Written here: it is the only factorisation neurotex
/// needs, a few lines, where a linear-algebra crate (nalgebra, faer) would add a large
/// dependency to the build.
fn inverse(mut m: Vec<f64>, d: usize) -> Vec<f64> {
    // m = L Lᵀ, L in the lower triangle.
    for j in 0..d {
        let diag = (m[j * d + j] - dot8(&m[j * d..j * d + j], &m[j * d..j * d + j])).sqrt();
        m[j * d + j] = diag;
        for i in j + 1..d {
            let sum = dot8(&m[i * d..i * d + j], &m[j * d..j * d + j]);
            m[i * d + j] = (m[i * d + j] - sum) / diag;
        }
    }
    // Each column of the identity through L, then Lᵀ; the solutions are the inverse's
    // columns, stored as rows (it is symmetric).
    let mut inv = vec![0.0; d * d];
    for (c, x) in inv.chunks_exact_mut(d).enumerate() {
        for i in c..d {
            let sum = dot8(&m[i * d + c..i * d + i], &x[c..i]);
            x[i] = (f64::from(u8::from(i == c)) - sum) / m[i * d + i];
        }
        for i in (0..d).rev() {
            let sum: f64 = (i + 1..d).map(|j| m[j * d + i] * x[j]).sum();
            x[i] = (x[i] - sum) / m[i * d + i];
        }
    }
    inv
}

/// Minimises the problem's objective from zero by L-BFGS.
fn lbfgs(problem: &Problem, params: LinearParams) -> Solution {
    lbfgs_from(problem, params, Preconditioner::new(problem))
}

/// [`lbfgs`] with the given preconditioner, or none.
fn lbfgs_from(problem: &Problem, params: LinearParams, pre: Option<Preconditioner>) -> Solution {
    let len = problem.k * (problem.dims + 1);
    let mut theta = vec![0.0; len];
    let (mut value, mut grad) = problem.value_grad(&theta);
    let mut pairs: VecDeque<(Vec<f64>, Vec<f64>, f64)> = VecDeque::new();
    let memory = if pre.is_some() { 40 } else { 10 };
    let largest = |g: &[f64]| g.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for iteration in 0..params.max_iter {
        if largest(&grad) <= params.tol {
            return Solution {
                theta,
                iterations: iteration,
                converged: true,
            };
        }
        let mut dir = direction(&grad, &pairs, pre.as_ref());
        let mut slope = dot8(&grad, &dir);
        if slope >= 0.0 {
            pairs.clear();
            dir = direction(&grad, &pairs, pre.as_ref());
            slope = dot8(&grad, &dir);
        }
        // The first step is scaled to unit length; later ones start at 1 (L-BFGS's
        // scaled direction). A rounding-level slack lets the last steps through once the
        // objective no longer changes in its last digits.
        let mut step = if pairs.is_empty() {
            1.0 / dot8(&dir, &dir).sqrt().max(1.0)
        } else {
            1.0
        };
        let slack = 8.0 * f64::EPSILON * value.abs();
        let accepted = loop {
            let trial: Vec<f64> = theta.iter().zip(&dir).map(|(t, d)| t + step * d).collect();
            let (v, g) = problem.value_grad(&trial);
            if v <= value + 1e-4 * step * slope + slack {
                break Some((trial, v, g));
            }
            step *= 0.5;
            if step < 1e-20 {
                break None;
            }
        };
        let Some((next, next_value, next_grad)) = accepted else {
            return Solution {
                theta,
                iterations: iteration,
                converged: false,
            };
        };
        let s: Vec<f64> = next.iter().zip(&theta).map(|(a, b)| a - b).collect();
        let y: Vec<f64> = next_grad.iter().zip(&grad).map(|(a, b)| a - b).collect();
        let sy = dot8(&s, &y);
        if sy > 1e-12 * dot8(&y, &y).sqrt() * dot8(&s, &s).sqrt() && sy > 0.0 {
            if pairs.len() == memory {
                pairs.pop_front();
            }
            pairs.push_back((s, y, 1.0 / sy));
        }
        (theta, value, grad) = (next, next_value, next_grad);
    }
    let converged = largest(&grad) <= params.tol;
    Solution {
        theta,
        iterations: params.max_iter,
        converged,
    }
}

/// Each feature's training mean and inverse population standard deviation (1 for a
/// constant feature).
fn scaling(x: &[f64], dims: usize) -> (Vec<f64>, Vec<f64>) {
    let n = (x.len() / dims) as f64;
    let mut mean = vec![0.0; dims];
    for row in x.chunks_exact(dims) {
        mean.iter_mut().zip(row).for_each(|(m, v)| *m += v);
    }
    mean.iter_mut().for_each(|m| *m /= n);
    let mut var = vec![0.0; dims];
    for row in x.chunks_exact(dims) {
        for ((s, &v), &m) in var.iter_mut().zip(row).zip(&mean) {
            *s += (v - m) * (v - m);
        }
    }
    let inv_std = var
        .iter()
        .map(|&s| {
            let sd = (s / n).sqrt();
            if sd > 0.0 {
                1.0 / sd
            } else {
                1.0
            }
        })
        .collect();
    (mean, inv_std)
}

/// The rows of `x` z-scored with each feature's mean and inverse standard deviation.
fn z_scored(x: &[f64], dims: usize, mean: &[f64], inv_std: &[f64]) -> Vec<f64> {
    x.chunks_exact(dims)
        .flat_map(|row| {
            row.iter()
                .zip(mean.iter().zip(inv_std))
                .map(|(&v, (&m, &s))| (v - m) * s)
        })
        .collect()
}

impl Classifier for Linear {
    type Model = LinearModel;

    /// Z-scores the features and solves for the weights.
    ///
    /// # Errors
    /// Empty or ragged input, non-finite features.
    fn fit(&self, x: &[f64], dims: usize, y: &[usize]) -> Result<LinearModel, ClassifyError> {
        check_training(x, dims, y)?;
        let n_classes = y.iter().max().map_or(0, |&m| m + 1);
        let mut classes = y.to_vec();
        classes.sort_unstable();
        classes.dedup();
        let (mean, inv_std) = scaling(x, dims);
        let z = z_scored(x, dims, &mean, &inv_std);
        let k = classes.len();
        let compact = y
            .iter()
            .map(|c| classes.binary_search(c).unwrap_or(0))
            .collect();
        let problem = Problem {
            z,
            dims,
            y: compact,
            k,
            penalty: 1.0 / (self.params.c * y.len() as f64),
        };
        let solution = if k > 1 {
            lbfgs(&problem, self.params)
        } else {
            Solution {
                theta: vec![0.0; dims + 1],
                iterations: 0,
                converged: true,
            }
        };
        let mut weights = solution.theta;
        let intercepts = weights.split_off(k * dims);
        Ok(LinearModel {
            dims,
            n_classes,
            classes,
            mean,
            inv_std,
            weights,
            intercepts,
            iterations: solution.iterations,
            converged: solution.converged,
        })
    }
}

impl Predict for LinearModel {
    fn dims(&self) -> usize {
        self.dims
    }

    fn n_classes(&self) -> usize {
        self.n_classes
    }

    fn predict_with_shares(&self, x: &[f64]) -> Vec<(usize, Vec<f64>)> {
        assert_eq!(
            x.len() % self.dims,
            0,
            "samples must have the training dimension"
        );
        x.chunks_exact(self.dims)
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
        let d = LinearParams::default();
        let name = |p: LinearParams| p.check().unwrap_err().name;
        assert_eq!(name(LinearParams { c: 0.0, ..d }), "c");
        assert_eq!(name(LinearParams { c: f64::NAN, ..d }), "c");
        assert_eq!(name(LinearParams { max_iter: 0, ..d }), "max_iter");
        assert_eq!(name(LinearParams { tol: -1.0, ..d }), "tol");
    }

    #[test]
    fn the_gradient_is_the_objectives() {
        let x = [0.3, -1.0, 2.0, 0.5, -0.7, 0.1, 1.5, 1.5, -2.0, 0.0];
        let problem = Problem {
            z: x.to_vec(),
            dims: 2,
            y: vec![0, 2, 1, 2, 0],
            k: 3,
            penalty: 0.3,
        };
        let theta: Vec<f64> = (0..9).map(|i| 0.1 * i as f64 - 0.35).collect();
        let (_, grad) = problem.value_grad(&theta);
        for j in 0..theta.len() {
            let h = 1e-6;
            let (mut up, mut down) = (theta.clone(), theta.clone());
            up[j] += h;
            down[j] -= h;
            let numeric = (problem.value_grad(&up).0 - problem.value_grad(&down).0) / (2.0 * h);
            assert!(
                (numeric - grad[j]).abs() < 1e-8,
                "{j}: {numeric} vs {}",
                grad[j]
            );
        }
    }

    /// The objective and gradient as first written: one row at a time, each class's dot
    /// product over the features, then its gradient terms (the reference the grouped
    /// kernel must equal bit for bit).
    fn value_grad_row_by_row(p: &Problem, theta: &[f64]) -> (f64, Vec<f64>) {
        let (d, k) = (p.dims, p.k);
        let (w, b) = theta.split_at(k * d);
        let mut grad = vec![0.0; theta.len()];
        let mut loss = 0.0;
        let mut logits = vec![0.0; k];
        for (row, &y) in p.z.chunks_exact(d).zip(&p.y) {
            for ((l, wc), &bc) in logits.iter_mut().zip(w.chunks_exact(d)).zip(b) {
                *l = bc + dot(wc, row);
            }
            let top = logits.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let sum: f64 = logits.iter().map(|&l| (l - top).exp()).sum();
            let log_norm = top + sum.ln();
            loss += log_norm - logits[y];
            let (gw, gb) = grad.split_at_mut(k * d);
            for (c, (g, &l)) in gw.chunks_exact_mut(d).zip(&logits).enumerate() {
                let r = (l - log_norm).exp() - f64::from(u8::from(c == y));
                for (gj, &zj) in g.iter_mut().zip(row) {
                    *gj += r * zj;
                }
                gb[c] += r;
            }
        }
        let n = p.y.len() as f64;
        grad.iter_mut().for_each(|g| *g /= n);
        for (g, &wj) in grad.iter_mut().zip(w) {
            *g += p.penalty * wj;
        }
        (loss / n + 0.5 * p.penalty * dot(w, w), grad)
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(200))]
        /// Rows not a multiple of the group, classes not a multiple of the block, zero and
        /// negative-zero weights: every bit of the value and gradient as the reference.
        #[test]
        fn value_grad_is_the_row_by_row_loop(
            n in 1usize..40,
            d in 1usize..72,
            k in 2usize..11,
            seed in proptest::prelude::any::<u64>(),
            zeros in proptest::prelude::any::<bool>(),
        ) {
            let mut state = seed | 1;
            let mut next = move || {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state >> 11) as f64 / (1u64 << 53) as f64 * 6.0 - 3.0
            };
            let z: Vec<f64> = (0..n * d).map(|_| next()).collect();
            let y: Vec<usize> = (0..n).map(|i| i % k).collect();
            let problem = Problem { z, dims: d, y, k, penalty: 0.01 + next().abs() };
            let theta: Vec<f64> = (0..k * (d + 1))
                .map(|i| match (zeros, i % 3) {
                    (true, 0) => -0.0,
                    (true, 1) => 0.0,
                    _ => next(),
                })
                .collect();
            let (expected_value, expected_grad) = value_grad_row_by_row(&problem, &theta);
            let bits = |g: &[f64]| g.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            let portable = Kernels { logits: logits_portable, gradient: gradient_portable };
            // The fastest kernels for this processor, then the portable ones.
            for (value, grad) in [
                problem.value_grad(&theta),
                problem.value_grad_with(portable, &theta),
            ] {
                proptest::prop_assert_eq!(value.to_bits(), expected_value.to_bits());
                proptest::prop_assert_eq!(bits(&grad), bits(&expected_grad));
            }
        }
    }

    #[test]
    fn the_preconditioner_solves_each_class_as_one_at_a_time() {
        let mut state = 7u64;
        let (d, k) = (37, 5);
        let inverse: Vec<f64> = (0..d * d).map(|_| uniform(&mut state) - 0.5).collect();
        let v: Vec<f64> = (0..k * (d + 1))
            .map(|_| uniform(&mut state) - 0.5)
            .collect();
        // Class by class: each entry summed from 0 over the inverse's rows in order.
        let mut expected = v.clone();
        for c in 0..k {
            let mut out = vec![0.0; d];
            for (i, row) in inverse.chunks_exact(d).enumerate() {
                out.iter_mut()
                    .zip(row)
                    .for_each(|(o, &m)| *o += v[c * d + i] * m);
            }
            expected[c * d..(c + 1) * d].copy_from_slice(&out);
        }
        expected[k * d..].iter_mut().for_each(|b| *b /= 0.3);
        let mut got = v.clone();
        solve(&inverse, d, 0.3, &mut got, &mut Vec::new());
        let bits = |g: &[f64]| g.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&got), bits(&expected));
    }

    #[test]
    fn one_class_and_absent_classes_are_handled() {
        let x = [0.0, 1.0, 2.0, 3.0];
        let model = fit_default(&x, 1, &[2, 2, 2, 2]);
        assert_eq!(
            model.predict_with_shares(&[5.0]),
            vec![(2, vec![0.0, 0.0, 1.0])]
        );
        let model = fit_default(&x, 1, &[0, 0, 2, 2]);
        assert!(model.converged());
        let shares = model.predict_with_shares(&[3.0]);
        assert_eq!(shares[0].0, 2);
        assert_eq!(shares[0].1[1], 0.0);
    }

    /// A logistic regression with the default parameters fitted on `x`.
    fn fit_default(x: &[f64], dims: usize, y: &[usize]) -> LinearModel {
        LinearParams::default()
            .check()
            .unwrap()
            .fit(x, dims, y)
            .unwrap()
    }

    /// A small deterministic generator for the tests' data (uniform in [-1, 1)).
    fn uniform(state: &mut u64) -> f64 {
        *state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }

    #[test]
    fn the_inverse_times_the_matrix_is_the_identity() {
        let d = 7;
        let mut state = 3;
        let a: Vec<f64> = (0..d * d).map(|_| uniform(&mut state)).collect();
        // a aᵀ + 0.1 I: symmetric positive definite.
        let mut m = vec![0.0; d * d];
        for i in 0..d {
            for j in 0..d {
                m[i * d + j] = dot(&a[i * d..(i + 1) * d], &a[j * d..(j + 1) * d]);
            }
            m[i * d + i] += 0.1;
        }
        let inv = inverse(m.clone(), d);
        for i in 0..d {
            for j in 0..d {
                let product: f64 = (0..d).map(|l| m[i * d + l] * inv[l * d + j]).sum();
                let identity = f64::from(u8::from(i == j));
                assert!((product - identity).abs() < 1e-10, "({i}, {j}): {product}");
            }
        }
    }

    /// Collinear columns (each of 8 underlying features seen 12 times with small
    /// differences, as every taxel's statistics side by side) over 8 classes: `dims`
    /// z-scored columns and their labels.
    fn collinear_problem() -> (Vec<f64>, usize, Vec<usize>) {
        let (n, base, copies, k) = (128, 8, 12, 8);
        let mut state = 11;
        let mut x = Vec::new();
        let mut y = Vec::new();
        for i in 0..n {
            let class = i % k;
            let latent: Vec<f64> = (0..base)
                .map(|b| uniform(&mut state) + if b == class { 1.5 } else { 0.0 })
                .collect();
            for c in 0..copies {
                for &l in &latent {
                    x.push(l * (1.0 + 0.1 * c as f64) + 0.01 * uniform(&mut state));
                }
            }
            y.push(class);
        }
        (x, base * copies, y)
    }

    /// To the default tolerance, L-BFGS from a scaled identity needed 138 iterations on
    /// [`collinear_problem`] with ten pairs (the solver before the preconditioner) and 104
    /// with forty; the preconditioned one needs 52.
    #[test]
    fn collinear_features_converge_in_few_iterations() {
        let (x, dims, y) = collinear_problem();
        let model = fit_default(&x, dims, &y);
        assert!(model.converged());
        assert!(model.iterations() < 80, "{} iterations", model.iterations());
    }

    /// The preconditioner changes the path, not the minimum: with and without it the
    /// weights agree to the tolerance's reach (gradient 1e-10 over the penalty's curvature).
    #[test]
    fn the_preconditioned_minimum_is_the_plain_one() {
        let (x, dims, y) = collinear_problem();
        let params = LinearParams {
            tol: 1e-10,
            ..LinearParams::default()
        };
        let (mean, inv_std) = scaling(&x, dims);
        let z = z_scored(&x, dims, &mean, &inv_std);
        let problem = Problem {
            penalty: 1.0 / (params.c * y.len() as f64),
            z,
            dims,
            y,
            k: 8,
        };
        let pre = Preconditioner::new(&problem);
        assert!(pre.is_some());
        let with = lbfgs_from(&problem, params, pre);
        let without = lbfgs_from(&problem, params, None);
        assert!(with.converged && without.converged);
        assert!(with.iterations < without.iterations);
        for (a, b) in with.theta.iter().zip(&without.theta) {
            assert!((a - b).abs() < 1e-6, "{a} vs {b}");
        }
    }

    /// Beyond [`PRECONDITIONED_DIMS`] features the fit goes without the preconditioner
    /// (its inverse would grow with the square of the features) and still converges.
    #[test]
    fn wide_problems_go_without_the_preconditioner() {
        let (n, dims) = (40, PRECONDITIONED_DIMS + 44);
        let mut state = 5;
        let y: Vec<usize> = (0..n).map(|i| i % 3).collect();
        let x: Vec<f64> = y
            .iter()
            .flat_map(|&c| {
                let mut row: Vec<f64> = (0..dims).map(|_| uniform(&mut state)).collect();
                row[c] += 2.0;
                row
            })
            .collect();
        let problem = Problem {
            z: x.clone(),
            dims,
            y: y.clone(),
            k: 3,
            penalty: 1.0 / n as f64,
        };
        assert!(Preconditioner::new(&problem).is_none());
        let model = fit_default(&x, dims, &y);
        assert!(model.converged());
        assert_eq!(model.predict(&x), y);
    }
}
