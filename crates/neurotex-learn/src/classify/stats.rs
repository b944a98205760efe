//! The distributions behind [`super::metrics`]' intervals and tests, written out so that
//! their accuracy is known and checked (against scipy in `tests/stats_reference.rs`):
//! the normal quantile used by Wilson's interval, Student's t quantile, the lower tail of a
//! fair-coin binomial in log space, and the percentile of sorted values.

use std::f64::consts::{FRAC_PI_2, LN_2, PI};

pub use crate::error::StatsError;

/// The 0.975 quantile of the standard normal distribution (two-sided 95 %), correctly
/// rounded; scipy's `norm.ppf(0.975)` gives the same double.
pub const Z_95: f64 = 1.959_963_984_540_054;

/// The `p` quantile of Student's t distribution with `dof` degrees of freedom.
///
/// Computed, not tabulated: for integer degrees of freedom the two-sided mass
/// `A(t | dof) = P(|T| <= t)` is a finite trigonometric series in `θ = atan(t / √dof)`
/// (Abramowitz and Stegun 1964, 26.7.3 and 26.7.4), increasing in θ, so bisection on θ finds
/// the quantile to the last bit of θ without special functions. Against scipy's `t.ppf`
/// (`tests/stats_reference.rs`) the relative error is at most 4e-14 at p = 0.975 for 1 to
/// 999 degrees of freedom, and 3e-13 at p = 0.999; further into the tails it grows like
/// `1e-16 / min(p, 1 - p)`, as the mass `2p - 1` is computed near 1. Cost grows linearly
/// with `dof` (about 60 sums of `dof / 2` terms).
///
/// # Errors
/// `p` not strictly between 0 and 1, or `dof == 0`.
pub fn student_t_quantile(p: f64, dof: usize) -> Result<f64, StatsError> {
    if !(p > 0.0 && p < 1.0) {
        return Err(StatsError::Probability { got: p });
    }
    if dof == 0 {
        return Err(StatsError::ZeroDegreesOfFreedom);
    }
    if p == 0.5 {
        return Ok(0.0);
    }
    let mass = if p > 0.5 {
        2.0 * p - 1.0
    } else {
        1.0 - 2.0 * p
    };
    let (mut lo, mut hi) = (0.0_f64, FRAC_PI_2);
    loop {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if t_two_sided_mass(mid, dof) < mass {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let t = (dof as f64).sqrt() * (0.5 * (lo + hi)).tan();
    Ok(if p > 0.5 { t } else { -t })
}

/// `P(|T| <= √dof · tan θ)` for Student's t (Abramowitz and Stegun 26.7.3, 26.7.4). Every
/// term is positive, so the sum loses nothing to cancellation.
fn t_two_sided_mass(theta: f64, dof: usize) -> f64 {
    let (sin, cos) = theta.sin_cos();
    let cos2 = cos * cos;
    if dof.is_multiple_of(2) {
        // 1 + 1/2 cos²θ + (1·3)/(2·4) cos⁴θ + ... up to cos^(dof-2)θ
        let (mut term, mut sum) = (1.0, 1.0);
        for j in 1..dof / 2 {
            term *= cos2 * (2 * j - 1) as f64 / (2 * j) as f64;
            sum += term;
        }
        sin * sum
    } else {
        // θ + sinθ cosθ (1 + 2/3 cos²θ + (2·4)/(3·5) cos⁴θ + ... up to cos^(dof-3)θ)
        let (mut term, mut sum) = (1.0, 1.0);
        for j in 1..dof.saturating_sub(1) / 2 {
            term *= cos2 * (2 * j) as f64 / (2 * j + 1) as f64;
            sum += term;
        }
        let series = if dof == 1 { 0.0 } else { sin * cos * sum };
        2.0 / PI * (theta + series)
    }
}

/// `P(X <= k)` for `X ~ Binomial(n, 1/2)`, to a relative error within
/// `1e-15 · (2 + |ln P|)` (checked against exact rational sums up to n = 5000): a result
/// taken through its logarithm cannot do better than the rounding of that logarithm.
///
/// The naive sum of `C(n, i) / 2^n` overflows past `n ≈ 1000`, and its logarithm,
/// `ln C(n, k) - n ln 2`, cancels two numbers of size `n`, losing `n · 1e-16` of relative
/// accuracy. Instead the largest term `P(X = k)` (for `k <= n/2`) is computed in log space
/// by Loader's saddle-point form (Loader 2000, "Fast and accurate computation of binomial
/// probabilities"), whose parts are the Stirling-series remainders and the binomial
/// deviance, each small; the smaller terms follow from it by the ratio
/// `P(X = i - 1) / P(X = i) = i / (n - i + 1)`.
pub fn binomial_half_cdf(k: usize, n: usize) -> f64 {
    if k >= n {
        return 1.0;
    }
    // For k above the middle the complement is the short, accurate sum.
    if 2 * k > n {
        return 1.0 - binomial_half_cdf(n - k - 1, n);
    }
    if k == 0 {
        // 2^-n exactly (powers of two are exact doubles down to 2^-1074).
        return if n > 1100 {
            0.0
        } else {
            0.5_f64.powi(n as i32)
        };
    }
    binomial_half_ln_cdf(k, n).exp()
}

/// `ln P(X <= k)` for `X ~ Binomial(n, 1/2)` and `k <= n / 2` (see [`binomial_half_cdf`]).
fn binomial_half_ln_cdf(k: usize, n: usize) -> f64 {
    debug_assert!(2 * k <= n, "the lower half of the distribution");
    // Terms fall off at least geometrically below the mode, so the sum stops once a term
    // can no longer change it.
    let (mut term, mut sum) = (1.0_f64, 1.0_f64);
    for i in (1..=k).rev() {
        term *= i as f64 / (n - i + 1) as f64;
        if term < sum * 1e-18 {
            break;
        }
        sum += term;
    }
    binomial_half_ln_pmf(k, n) + sum.ln()
}

/// `ln P(X = k)` for `X ~ Binomial(n, 1/2)` (Loader 2000, equation for `dbinom_raw`).
fn binomial_half_ln_pmf(k: usize, n: usize) -> f64 {
    if k == 0 || k == n {
        return -(n as f64) * LN_2;
    }
    let (nf, kf, rest) = (n as f64, k as f64, (n - k) as f64);
    let mean = 0.5 * nf;
    stirling_error(n)
        - stirling_error(k)
        - stirling_error(n - k)
        - deviance(kf, mean)
        - deviance(rest, mean)
        - 0.5 * (2.0 * PI * kf * rest / nf).ln()
}

/// `ln n! - ln(√(2πn) (n/e)^n)`, the error of Stirling's formula: beyond 15 the asymptotic
/// series (five terms, truncation below 1e-16 there), up to 15 from a table. The table
/// avoids computing `ln n!` and `(n + 1/2) ln n` near 25 to get their difference near 0.01,
/// which would cost 1e-14 of relative accuracy in every binomial term.
fn stirling_error(n: usize) -> f64 {
    // lgamma(n + 1) - (n + 1/2) ln n + n - ln(2π) / 2 at 40 digits (mpmath 1.4.1), rounded to
    // double; the same values as Loader's (2000) table at the integers.
    const SMALL: [f64; 16] = [
        0.0,
        0.08106146679532726,
        0.0413406959554093,
        0.02767792568499834,
        0.020790672103765093,
        0.016644691189821193,
        0.013876128823070748,
        0.01189670994589177,
        0.010411265261972096,
        0.009255462182712733,
        0.00833056343336287,
        0.007573675487951841,
        0.00694284010720953,
        0.006408994188004207,
        0.0059513701127588475,
        0.005554733551962801,
    ];
    if let Some(&value) = SMALL.get(n) {
        return value;
    }
    let inv = 1.0 / n as f64;
    let inv2 = inv * inv;
    inv * (1.0 / 12.0
        - inv2 * (1.0 / 360.0 - inv2 * (1.0 / 1260.0 - inv2 * (1.0 / 1680.0 - inv2 / 1188.0))))
}

/// The binomial deviance `x ln(x / mean) + mean - x` (Loader 2000). The direct form cancels
/// (for x = 1000 around a mean of 1250 it is 250 - 223.1, losing two digits), so wherever
/// `v = (x - mean) / (x + mean)` is below 1/2 in size it is summed as
/// `(x - mean) v + 2x (v³/3 + v⁵/5 + ...)`, the series of `2x artanh v`, whose tail is at
/// most a sixth of the first term and whose terms shrink at least fourfold.
fn deviance(x: f64, mean: f64) -> f64 {
    if (x - mean).abs() >= 0.5 * (x + mean) {
        return x * (x / mean).ln() + mean - x;
    }
    let v = (x - mean) / (x + mean);
    let v2 = v * v;
    let mut sum = (x - mean) * v;
    let mut power = 2.0 * x * v;
    for j in 1.. {
        power *= v2;
        let next = sum + power / (2 * j + 1) as f64;
        if next == sum {
            break;
        }
        sum = next;
    }
    sum
}

/// The `q` quantile (0..=1) of ascending `sorted` values, interpolating linearly between
/// order statistics (Hyndman and Fan 1996 definition 7, numpy's default).
///
/// # Panics
/// If `sorted` is empty or `q` is outside [0, 1] (a caller bug).
pub fn percentile(sorted: &[f64], q: f64) -> f64 {
    assert!(!sorted.is_empty(), "a percentile of no values");
    assert!((0.0..=1.0).contains(&q), "quantile {q} outside [0, 1]");
    let position = q * (sorted.len() - 1) as f64;
    let below = position.floor() as usize;
    let fraction = position - below as f64;
    match sorted.get(below + 1) {
        Some(&next) if fraction > 0.0 => sorted[below] + fraction * (next - sorted[below]),
        _ => sorted[below],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn t_quantile_closed_forms_for_one_and_two_degrees() {
        // dof 1 is Cauchy: t = tan(π (p - 1/2)); dof 2: t = (2p - 1) √(2 / (4p(1 - p))).
        for p in [0.6, 0.9, 0.975, 0.995, 0.025] {
            let cauchy = (PI * (p - 0.5)).tan();
            let two = (2.0 * p - 1.0) * (2.0 / (4.0 * p * (1.0 - p))).sqrt();
            let got1 = student_t_quantile(p, 1).unwrap();
            let got2 = student_t_quantile(p, 2).unwrap();
            assert!((got1 - cauchy).abs() <= 1e-13 * cauchy.abs(), "{p}: {got1}");
            assert!((got2 - two).abs() <= 1e-13 * two.abs(), "{p}: {got2}");
        }
    }

    #[test]
    fn t_quantile_tends_to_the_normal_one() {
        let t = student_t_quantile(0.975, 100_000).unwrap();
        assert!(t > Z_95 && t - Z_95 < 1e-4, "{t}");
    }

    #[test]
    fn t_quantile_rejects_bad_arguments() {
        for p in [0.0, 1.0, -0.1, f64::NAN] {
            assert!(matches!(
                student_t_quantile(p, 3),
                Err(StatsError::Probability { .. })
            ));
        }
        assert_eq!(
            student_t_quantile(0.9, 0),
            Err(StatsError::ZeroDegreesOfFreedom)
        );
        assert_eq!(student_t_quantile(0.5, 7), Ok(0.0));
    }

    #[test]
    fn binomial_half_cdf_small_cases_by_hand() {
        // n = 4: 1, 4, 6, 4, 1 over 16.
        let expect = [1.0 / 16.0, 5.0 / 16.0, 11.0 / 16.0, 15.0 / 16.0, 1.0];
        for (k, e) in expect.iter().enumerate() {
            let got = binomial_half_cdf(k, 4);
            assert!((got - e).abs() <= 1e-15, "k = {k}: {got}");
        }
        assert_eq!(binomial_half_cdf(0, 0), 1.0);
        assert_eq!(binomial_half_cdf(0, 1), 0.5);
    }

    #[test]
    fn percentile_interpolates_like_numpy() {
        let v = [1.0, 2.0, 4.0, 8.0];
        assert_eq!(percentile(&v, 0.0), 1.0);
        assert_eq!(percentile(&v, 1.0), 8.0);
        assert_eq!(percentile(&v, 0.5), 3.0);
        assert!((percentile(&v, 0.25) - 1.75).abs() < 1e-15);
        assert_eq!(percentile(&[5.0], 0.975), 5.0);
    }
}
