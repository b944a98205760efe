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

use serde::{Deserialize, Serialize};

use super::{check_training, first_max, Classifier, Predict};
use crate::error::{ClassifyError, ParamError};

mod lbfgs;
mod objective;
#[cfg(test)]
mod tests;

use lbfgs::{lbfgs, Solution};
use objective::Problem;

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
