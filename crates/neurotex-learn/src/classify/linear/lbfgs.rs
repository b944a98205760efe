//! L-BFGS on the objective: the two-loop search direction, the preconditioner's initial
//! Hessian for up to 256 features, and the backtracking line search.

use std::collections::VecDeque;

use super::objective::Problem;
use super::{add_scaled, dot8, sub_scaled, LinearParams};

/// The end of an L-BFGS run.
pub(super) struct Solution {
    pub(super) theta: Vec<f64>,
    pub(super) iterations: usize,
    pub(super) converged: bool,
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
        let mut scratch = SolveScratch::default();
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
pub(super) struct Preconditioner {
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
pub(super) const PRECONDITIONED_DIMS: usize = 256;

impl Preconditioner {
    /// The preconditioner of `problem`, or `None` beyond [`PRECONDITIONED_DIMS`] features.
    pub(super) fn new(problem: &Problem) -> Option<Self> {
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
/// (`d x d`) and its intercepts divided by `curvature`, in `scratch`'s space. Each class's
/// entry `j` is `Σ_i v_i inverse_ij` added from 0 in the order of `i`. The sums are kept
/// in registers, [`SOLVE_CLASSES`] classes by [`SOLVE_COLUMNS`] entries at a time, while
/// the rows of the inverse go by (a sum added into memory waits on a load and a store per
/// row); the last columns, fewer than [`SOLVE_COLUMNS`], are summed in memory.
#[inline(always)]
pub(super) fn solve(
    inverse: &[f64],
    d: usize,
    curvature: f64,
    v: &mut [f64],
    scratch: &mut SolveScratch,
) {
    let k = v.len() / (d + 1);
    let (w, b) = v.split_at_mut(k * d);
    let SolveScratch { out, by_row } = scratch;
    out.clear();
    out.resize(k * d, 0.0);
    let size = SOLVE_CLASSES * d;
    for (w, out) in w.chunks(size).zip(out.chunks_mut(size)) {
        solve_classes(inverse, d, w, out, by_row);
    }
    w.copy_from_slice(out);
    for bc in b.iter_mut() {
        *bc /= curvature;
    }
}

/// [`solve`]'s space, kept from one call to the next: the product, and a block of classes'
/// entries by row.
#[derive(Default)]
pub(super) struct SolveScratch {
    out: Vec<f64>,
    by_row: Vec<[f64; SOLVE_CLASSES]>,
}

/// Classes whose entries [`solve`] sums side by side.
const SOLVE_CLASSES: usize = 4;
/// Entries of each class [`solve`] sums side by side (two vectors of eight lanes).
const SOLVE_COLUMNS: usize = 16;

/// [`solve`] for the up to [`SOLVE_CLASSES`] classes of `w` (each `d` long) into `out`
/// (zeros, as long as `w`), `by_row` space for their entries. A block of fewer classes
/// sums zeros in the others' place.
#[inline(always)]
fn solve_classes(
    inverse: &[f64],
    d: usize,
    w: &[f64],
    out: &mut [f64],
    by_row: &mut Vec<[f64; SOLVE_CLASSES]>,
) {
    by_row.clear();
    by_row.resize(d, [0.0; SOLVE_CLASSES]);
    for (c, w) in w.chunks_exact(d).enumerate() {
        by_row.iter_mut().zip(w).for_each(|(g, &v)| g[c] = v);
    }
    let full = d / SOLVE_COLUMNS * SOLVE_COLUMNS;
    for j in (0..full).step_by(SOLVE_COLUMNS) {
        // Four named sums: kept in an array, one of them went through memory.
        let [mut s0, mut s1, mut s2, mut s3] = [[0.0; SOLVE_COLUMNS]; SOLVE_CLASSES];
        for (row, g) in inverse.chunks_exact(d).zip(by_row.iter()) {
            let tile: &[f64; SOLVE_COLUMNS] = row[j..j + SOLVE_COLUMNS].try_into().unwrap();
            add_times(&mut s0, g[0], tile);
            add_times(&mut s1, g[1], tile);
            add_times(&mut s2, g[2], tile);
            add_times(&mut s3, g[3], tile);
        }
        for (out, sum) in out.chunks_exact_mut(d).zip([s0, s1, s2, s3]) {
            out[j..j + SOLVE_COLUMNS].copy_from_slice(&sum);
        }
    }
    for (row, g) in inverse.chunks_exact(d).zip(by_row.iter()) {
        for (out, &g) in out.chunks_exact_mut(d).zip(g) {
            out[full..]
                .iter_mut()
                .zip(&row[full..])
                .for_each(|(o, &m)| *o += g * m);
        }
    }
}

/// `sum[t] += g * tile[t]`.
#[inline(always)]
fn add_times(sum: &mut [f64; SOLVE_COLUMNS], g: f64, tile: &[f64; SOLVE_COLUMNS]) {
    for t in 0..SOLVE_COLUMNS {
        sum[t] += g * tile[t];
    }
}

/// The inverse of the symmetric positive definite `m` (`d x d`, row-major, lower triangle
/// read) through its Cholesky factor. Written here: it is the only factorisation neurotex
/// needs, a few lines, where a linear-algebra crate (nalgebra, faer) would add a large
/// dependency to the build.
pub(super) fn inverse(mut m: Vec<f64>, d: usize) -> Vec<f64> {
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
    }
    // Lᵀ's rows (L's columns), read in order by the back substitutions.
    let mut upper = vec![0.0; d * d];
    for i in 0..d {
        for j in 0..=i {
            upper[j * d + i] = m[i * d + j];
        }
    }
    for columns in inv.chunks_mut(BACK * d) {
        back_substitute(&upper, d, columns);
    }
    inv
}

/// Columns solved side by side by [`back_substitute`].
const BACK: usize = 8;

neurotex_core::widest_or_plain! {
    ["avx512f", "avx2"]
    /// Solves `Lᵀ x = b` in place for each of up to [`BACK`] rows `b` of `columns` (each
    /// `d` long), `upper` holding `Lᵀ` row-major. Entry `i` of each is `(b_i - Σ_j
    /// Lᵀ_ij x_j) / Lᵀ_ii`, the sum over `j > i` added in ascending order from the value
    /// `f64`'s `Sum` starts from, as one column alone computes it; the columns are
    /// independent, so side by side they fill vector lanes where one column's sum waits on
    /// each addition, with the same bits.
    fn back_substitute(upper: &[f64], d: usize, columns: &mut [f64]) {
        let mut x = vec![0.0; d * BACK];
        for (l, column) in columns.chunks_exact(d).enumerate() {
            for (i, &v) in column.iter().enumerate() {
                x[i * BACK + l] = v;
            }
        }
        let start: f64 = std::iter::empty::<f64>().sum();
        for i in (0..d).rev() {
            let mut sum = [start; BACK];
            for (&u, xj) in upper[i * d + i + 1..(i + 1) * d]
                .iter()
                .zip(x[(i + 1) * BACK..].chunks_exact(BACK))
            {
                for l in 0..BACK {
                    sum[l] += u * xj[l];
                }
            }
            let diag = upper[i * d + i];
            for l in 0..BACK {
                x[i * BACK + l] = (x[i * BACK + l] - sum[l]) / diag;
            }
        }
        for (l, column) in columns.chunks_exact_mut(d).enumerate() {
            for (i, v) in column.iter_mut().enumerate() {
                *v = x[i * BACK + l];
            }
        }
    }
}

/// Minimises the problem's objective from zero by L-BFGS.
pub(super) fn lbfgs(problem: &Problem, params: LinearParams) -> Solution {
    lbfgs_from(problem, params, Preconditioner::new(problem))
}

/// [`lbfgs`] with the given preconditioner, or none.
pub(super) fn lbfgs_from(
    problem: &Problem,
    params: LinearParams,
    pre: Option<Preconditioner>,
) -> Solution {
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
