//! The full set of 13 Haralick features (Haralick, Shanmugam and Dinstein 1973, table 1,
//! features 1-13) of a co-occurrence matrix, with the definitions of mahotas 1.4
//! (`mahotas.features.texture.haralick_features`, `use_x_minus_y_variance=True`): base-2
//! logarithms, the corrected sum variance (about the sum average, not Haralick's typo),
//! the difference variance as the variance of `|i - j|`, and IMC2 with `exp`.
//!
//! `p` is the matrix normalised by its total; `p_x(j) = sum_i p(i, j)` (column sums, as
//! mahotas) and `p_y(i) = sum_j p(i, j)`; `p_{x+y}(k)` and `p_{x-y}(k)` sum `p` over
//! `i + j = k` and `|i - j| = k`; `H(q) = -sum q log2 q` over nonzero `q`.

/// The feature names in the order of [`haralick_full`]'s values (mahotas's order).
pub const FULL_NAMES: [&str; 13] = [
    "asm",
    "contrast",
    "correlation",
    "variance",
    "idm",
    "sum_average",
    "sum_variance",
    "sum_entropy",
    "entropy",
    "difference_variance",
    "difference_entropy",
    "imc1",
    "imc2",
];

/// `-sum q log2 q` over the nonzero entries.
fn entropy(q: &[f64]) -> f64 {
    -q.iter()
        .filter(|&&x| x > 0.0)
        .map(|&x| x * x.log2())
        .sum::<f64>()
}

/// The marginals and sum/difference distributions of a normalised `levels x levels` matrix.
struct Marginals {
    p_x: Vec<f64>,
    p_y: Vec<f64>,
    sum: Vec<f64>,
    diff: Vec<f64>,
}

impl Marginals {
    fn of(p: &[f64], levels: usize) -> Self {
        let mut m = Marginals {
            p_x: vec![0.0; levels],
            p_y: vec![0.0; levels],
            sum: vec![0.0; 2 * levels],
            diff: vec![0.0; levels],
        };
        for (i, row) in p.chunks_exact(levels).enumerate() {
            for (j, &v) in row.iter().enumerate() {
                m.p_x[j] += v;
                m.p_y[i] += v;
                m.sum[i + j] += v;
                m.diff[i.abs_diff(j)] += v;
            }
        }
        m
    }
}

/// Mean and variance of the index under the distribution `q`.
fn moments(q: &[f64]) -> (f64, f64) {
    let mean: f64 = q.iter().enumerate().map(|(k, &v)| k as f64 * v).sum();
    let square: f64 = q.iter().enumerate().map(|(k, &v)| (k * k) as f64 * v).sum();
    (mean, square - mean * mean)
}

/// The 13 features of the `levels x levels` matrix `counts` (any nonnegative weights,
/// normalised here by their total), in the order of [`FULL_NAMES`]. An all-zero matrix
/// gives zeros with correlation 1 (mahotas refuses it). Correlation is 1 when either
/// marginal's standard deviation is below 1e-15 (mahotas: exactly 0), as in
/// [`crate::features::haralick`].
///
/// # Panics
/// If `counts` is not square in `levels` (a caller bug).
pub fn haralick_full(counts: &[f64], levels: usize) -> [f64; 13] {
    assert_eq!(counts.len(), levels * levels);
    let total: f64 = counts.iter().sum();
    if total <= 0.0 {
        let mut out = [0.0; 13];
        out[2] = 1.0;
        return out;
    }
    let p: Vec<f64> = counts.iter().map(|&c| c / total).collect();
    let m = Marginals::of(&p, levels);
    let (u_x, v_x) = moments(&m.p_x);
    let (u_y, v_y) = moments(&m.p_y);
    let (mut asm, mut ij, mut idm, mut hxy1) = (0.0, 0.0, 0.0, 0.0);
    let mut hxy2 = 0.0;
    for (i, row) in p.chunks_exact(levels).enumerate() {
        for (j, &v) in row.iter().enumerate() {
            asm += v * v;
            ij += (i * j) as f64 * v;
            let d = i.abs_diff(j) as f64;
            idm += v / (1.0 + d * d);
            let cross = m.p_x[i] * m.p_y[j];
            if cross > 0.0 {
                hxy1 -= v * cross.log2();
                hxy2 -= cross * cross.log2();
            }
        }
    }
    let (s_x, s_y) = (v_x.max(0.0).sqrt(), v_y.max(0.0).sqrt());
    let correlation = if s_x < 1e-15 || s_y < 1e-15 {
        1.0
    } else {
        (ij - u_x * u_y) / (s_x * s_y)
    };
    let (sum_average, sum_variance) = moments(&m.sum);
    let (_, difference_variance) = moments(&m.diff);
    let contrast: f64 = m
        .diff
        .iter()
        .enumerate()
        .map(|(k, &v)| (k * k) as f64 * v)
        .sum();
    let hxy = entropy(&p);
    let (hx, hy) = (entropy(&m.p_x), entropy(&m.p_y));
    let imc1 = (hxy - hxy1) / if hx.max(hy) == 0.0 { 1.0 } else { hx.max(hy) };
    let imc2 = (1.0 - (-2.0 * (hxy2 - hxy)).exp()).max(0.0).sqrt();
    [
        asm,
        contrast,
        correlation,
        v_x,
        idm,
        sum_average,
        sum_variance,
        entropy(&m.sum),
        hxy,
        difference_variance,
        entropy(&m.diff),
        imc1,
        imc2,
    ]
}
