//! The objective L-BFGS minimises, its value and gradient over z-scored rows, and the
//! loops over a group of rows in plain Rust, AVX2 and AVX-512, chosen for the processor.

use super::dot;

/// The fitting problem: z-scored rows, compact class indices, the penalty factor.
pub(super) struct Problem {
    pub(super) z: Vec<f64>,
    pub(super) dims: usize,
    pub(super) y: Vec<usize>,
    pub(super) k: usize,
    /// `1 / (C n)`.
    pub(super) penalty: f64,
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
    pub(super) fn value_grad(&self, theta: &[f64]) -> (f64, Vec<f64>) {
        self.value_grad_with(Kernels::fastest(), theta)
    }

    /// [`Problem::value_grad`] with the given kernels.
    pub(super) fn value_grad_with(&self, kernels: Kernels, theta: &[f64]) -> (f64, Vec<f64>) {
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
pub(super) struct Kernels {
    /// Every row's dot product with every padded class's weights (feature-major) into
    /// `out`, `padded` per row.
    pub(super) logits: fn(z: &[f64], by_feature: &[f64], d: usize, out: &mut [f64]),
    /// Adds the rows' gradient terms, `residual x row`, to each class's row of weights'
    /// gradient, row after row.
    pub(super) gradient: fn(z: &[f64], residuals: &[f64], k: usize, gw: &mut [f64]),
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
pub(super) fn logits_portable(z: &[f64], by_feature: &[f64], d: usize, out: &mut [f64]) {
    let padded = by_feature.len() / d;
    for (row, out) in z.chunks_exact(d).zip(out.chunks_exact_mut(padded)) {
        for (c, o) in out.iter_mut().enumerate() {
            let column = by_feature.iter().skip(c).step_by(padded);
            *o = column.zip(row).map(|(w, x)| w * x).sum();
        }
    }
}

/// [`Kernels::gradient`] in plain Rust.
pub(super) fn gradient_portable(z: &[f64], residuals: &[f64], k: usize, gw: &mut [f64]) {
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
