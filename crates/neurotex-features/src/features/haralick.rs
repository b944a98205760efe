//! Haralick features (Haralick, Shanmugam and Dinstein 1973; paper eqs. 5-8) of a
//! normalised co-occurrence matrix.

/// The paper's three features of a mean GLCM.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Haralick {
    /// `sum p(i,j) (i-j)^2`.
    pub contrast: f64,
    /// `sum p(i,j) (i-mu_x)(j-mu_y) / (sigma_x sigma_y)`; 1 when either sigma is below
    /// 1e-15 (the scikit-image convention), so never NaN.
    pub correlation: f64,
    /// Angular second moment `sum p(i,j)^2`.
    pub asm: f64,
}

impl Haralick {
    /// The features as `[contrast, correlation, asm]`.
    pub fn to_array(self) -> [f64; 3] {
        [self.contrast, self.correlation, self.asm]
    }
}

/// Features of the `levels x levels` count matrix `counts` (u32 or u64), normalised by its total.
/// An all-zero matrix (no pairs at all) gives contrast 0, correlation 1, ASM 0.
///
/// Every sum is taken over the integer counts exactly (the marginals' means and variances
/// as `N * sum(i^2 r_i) - (sum(i r_i))^2` over `N^2`, and so on); only the final ratios are
/// rounded, so the features are as exact as f64 allows and one pass suffices.
///
/// # Panics
/// If `counts` is not square in `levels` (a caller bug).
pub fn haralick<C: Copy + Into<u64>>(counts: &[C], levels: usize) -> Haralick {
    assert_eq!(counts.len(), levels * levels);
    let (mut total, mut contrast, mut square, mut cross) = (0u64, 0u128, 0u128, 0u128);
    let mut column = vec![0u64; levels];
    let (mut s_i, mut s_ii) = (0u128, 0u128);
    for (i, row) in counts.chunks_exact(levels).enumerate() {
        let mut row_total = 0u64;
        let mut row_cross = 0u128;
        for (j, (&c, col)) in row.iter().zip(column.iter_mut()).enumerate() {
            let c: u64 = c.into();
            let d = i.abs_diff(j) as u128;
            row_total += c;
            let c = u128::from(c);
            row_cross += c * j as u128;
            contrast += c * d * d;
            square += c * c;
            *col += c as u64;
        }
        let i = i as u128;
        total += row_total;
        cross += i * row_cross;
        s_i += i * u128::from(row_total);
        s_ii += i * i * u128::from(row_total);
    }
    if total == 0 {
        return Haralick {
            contrast: 0.0,
            correlation: 1.0,
            asm: 0.0,
        };
    }
    let (s_j, s_jj) = column
        .iter()
        .enumerate()
        .fold((0u128, 0u128), |(s, ss), (j, &c)| {
            let j = j as u128;
            (s + j * u128::from(c), ss + j * j * u128::from(c))
        });
    let n = total as f64;
    let big_n = u128::from(total);
    // N^2 times the covariance and the variances, exact while N < 2^55 (a total of counts
    // no volume that fits in memory reaches): with at most 256 levels every product below
    // stays under 2^128.
    let cov = signed_difference(big_n * cross, s_i * s_j);
    let var_x = signed_difference(big_n * s_ii, s_i * s_i);
    let var_y = signed_difference(big_n * s_jj, s_j * s_j);
    let (sd_x, sd_y) = (var_x.max(0.0).sqrt() / n, var_y.max(0.0).sqrt() / n);
    let correlation = if sd_x < 1e-15 || sd_y < 1e-15 {
        1.0
    } else {
        cov / (var_x.sqrt() * var_y.sqrt())
    };
    Haralick {
        contrast: contrast as f64 / n,
        correlation,
        asm: square as f64 / (n * n),
    }
}

/// `a - b` of two exact integers, as f64 (rounded once).
fn signed_difference(a: u128, b: u128) -> f64 {
    if a >= b {
        (a - b) as f64
    } else {
        -((b - a) as f64)
    }
}
