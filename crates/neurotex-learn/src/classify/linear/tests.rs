use super::lbfgs::{inverse, lbfgs_from, solve, Preconditioner, PRECONDITIONED_DIMS};
use super::objective::{gradient_portable, logits_portable, Kernels};
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
        let mut bits = crate::testing::xorshift(seed | 1);
        let mut next = move || (bits() >> 11) as f64 / (1u64 << 53) as f64 * 6.0 - 3.0;
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
    solve(&inverse, d, 0.3, &mut got, &mut Default::default());
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

/// [`inverse`] as it was written first: each column of the identity through `L`, then
/// through `Lᵀ` read down `L`'s columns, one column at a time.
fn inverse_column_by_column(mut m: Vec<f64>, d: usize) -> Vec<f64> {
    for j in 0..d {
        let diag = (m[j * d + j] - dot8(&m[j * d..j * d + j], &m[j * d..j * d + j])).sqrt();
        m[j * d + j] = diag;
        for i in j + 1..d {
            let sum = dot8(&m[i * d..i * d + j], &m[j * d..j * d + j]);
            m[i * d + j] = (m[i * d + j] - sum) / diag;
        }
    }
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

/// Sizes below, at and around the columns solved side by side, and the largest
/// preconditioned: the inverse's bits are those of one column at a time.
#[test]
fn the_inverse_is_the_one_column_at_a_time() {
    let mut state = 11;
    for d in [1, 2, 7, 8, 9, 16, 17, 45, PRECONDITIONED_DIMS] {
        let a: Vec<f64> = (0..d * d).map(|_| uniform(&mut state)).collect();
        let mut m = vec![0.0; d * d];
        for i in 0..d {
            for j in 0..d {
                m[i * d + j] = dot(&a[i * d..(i + 1) * d], &a[j * d..(j + 1) * d]);
            }
            m[i * d + i] += 0.01;
        }
        let bits = |v: Vec<f64>| v.into_iter().map(f64::to_bits).collect::<Vec<_>>();
        assert_eq!(
            bits(inverse(m.clone(), d)),
            bits(inverse_column_by_column(m, d)),
            "{d} features"
        );
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
