//! Exact arithmetic for gray levels on their boundaries: the sign of a sum of integers
//! times powers of two, wide enough for any f64 (each one is such a product).

use std::cmp::Ordering;

/// 2^-1074 is the smallest f64 step: the sum's lowest bit.
const OFFSET: i32 = 1074;
/// Limbs of the sum: terms below 2^127 at exponents up to 971 (f64's largest) stay below
/// 2^(127 + 971 + 1074), a few terms below 2^2175, with the sign: 35 limbs hold 2240 bits.
const LIMBS: usize = 35;

/// An exact sum of terms `n * 2^e`, two's complement in units of 2^-1074.
#[derive(Debug, Clone)]
struct ExactSum {
    limbs: [u64; LIMBS],
}

impl ExactSum {
    /// Zero.
    fn new() -> Self {
        ExactSum { limbs: [0; LIMBS] }
    }

    /// Adds `n * 2^e`.
    ///
    /// # Panics
    /// `e` outside f64's exponents `-1074..=971` (a caller bug: exponents come from
    /// [`f64_parts`] or are 0).
    fn add(&mut self, n: i128, e: i32) {
        assert!((-OFFSET..=971).contains(&e), "exponent {e} outside f64's");
        let shift = (e + OFFSET) as usize;
        let (limb, bit) = (shift / 64, shift % 64);
        let magnitude = n.unsigned_abs();
        let (low, high) = (magnitude as u64, (magnitude >> 64) as u64);
        let words = if bit == 0 {
            [low, high, 0]
        } else {
            [
                low << bit,
                (low >> (64 - bit)) | (high << bit),
                high >> (64 - bit),
            ]
        };
        let mut carry = false;
        for (k, limb) in self.limbs[limb..].iter_mut().enumerate() {
            let word = words.get(k).copied().unwrap_or(0);
            if k >= words.len() && !carry {
                break;
            }
            if n >= 0 {
                let (sum, c1) = limb.overflowing_add(word);
                let (sum, c2) = sum.overflowing_add(u64::from(carry));
                *limb = sum;
                carry = c1 || c2;
            } else {
                let (diff, b1) = limb.overflowing_sub(word);
                let (diff, b2) = diff.overflowing_sub(u64::from(carry));
                *limb = diff;
                carry = b1 || b2;
            }
        }
    }

    /// The sum's sign.
    fn sign(&self) -> Ordering {
        if self.limbs[LIMBS - 1] >> 63 == 1 {
            Ordering::Less
        } else if self.limbs.iter().all(|&l| l == 0) {
            Ordering::Equal
        } else {
            Ordering::Greater
        }
    }
}

/// The sign of `sum n * 2^e` over `terms` (each `|n| < 2^127`, `e` in `-1074..=971`): in
/// one i128 when the terms lie within about 2^124 of each other's scale (rates of one
/// volume do), else through [`ExactSum`].
pub(crate) fn sign_of_sum(terms: &[(i128, i32)]) -> Ordering {
    let Some(low) = terms.iter().filter(|t| t.0 != 0).map(|t| t.1).min() else {
        return Ordering::Equal;
    };
    let bits = |n: i128| 128 - n.unsigned_abs().leading_zeros() as i32;
    // Each shifted term below 2^124, so a sum of up to eight cannot overflow.
    if terms.len() <= 8
        && terms
            .iter()
            .all(|&(n, e)| n == 0 || bits(n) + (e - low) <= 124)
    {
        let sum: i128 = terms
            .iter()
            .map(|&(n, e)| if n == 0 { 0 } else { n << (e - low) })
            .sum();
        return sum.cmp(&0);
    }
    let mut sum = ExactSum::new();
    for &(n, e) in terms {
        sum.add(n, e);
    }
    sum.sign()
}

/// A finite `x` as `m * 2^e` with `|m| < 2^53` and `e` in `-1074..=971`.
pub(crate) fn f64_parts(x: f64) -> (i64, i32) {
    let bits = x.to_bits();
    let exponent = ((bits >> 52) & 0x7ff) as i32;
    let fraction = (bits & ((1u64 << 52) - 1)) as i64;
    let (m, e) = if exponent == 0 {
        (fraction, -OFFSET)
    } else {
        (fraction | (1i64 << 52), exponent - 1075)
    };
    (if bits >> 63 == 1 { -m } else { m }, e)
}

#[cfg(test)]
mod tests {
    use super::{f64_parts, sign_of_sum, ExactSum};
    use std::cmp::Ordering;

    /// The sign of `x - y` both ways: in one i128 where it fits, and through the limbs.
    fn difference_sign(x: f64, y: f64) -> Ordering {
        let ((mx, ex), (my, ey)) = (f64_parts(x), f64_parts(y));
        let mut sum = ExactSum::new();
        sum.add(i128::from(mx), ex);
        sum.add(-i128::from(my), ey);
        let fast = sign_of_sum(&[(i128::from(mx), ex), (-i128::from(my), ey)]);
        assert_eq!(fast, sum.sign(), "{x:e} - {y:e}");
        fast
    }

    /// A xorshift64 stream from `seed`: bit patterns of every kind for the doubles.
    fn xorshift(mut state: u64) -> impl FnMut() -> u64 {
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        }
    }

    #[test]
    fn the_sign_of_a_difference_of_two_doubles_is_their_order() {
        let mut next = xorshift(0x9E37_79B9_7F4A_7C15);
        let edges = [
            0.0,
            -0.0,
            f64::MIN_POSITIVE,
            f64::MIN_POSITIVE / 3.0,
            5e-324,
            -5e-324,
            1.0,
            0.1,
            f64::MAX,
            -f64::MAX,
            f64::EPSILON,
        ];
        let random: Vec<f64> = (0..3000)
            .map(|_| f64::from_bits(next()))
            .filter(|x| x.is_finite())
            .collect();
        let nearby: Vec<f64> = random
            .iter()
            .map(|x| f64::from_bits(x.to_bits() + 1))
            .filter(|x| x.is_finite())
            .collect();
        let values: Vec<f64> = edges.into_iter().chain(random).chain(nearby).collect();
        for (k, &x) in values.iter().enumerate() {
            for &y in values.iter().skip(k % 97).step_by(97) {
                assert_eq!(
                    Some(difference_sign(x, y)),
                    x.partial_cmp(&y),
                    "{x:e} vs {y:e}"
                );
            }
        }
    }

    #[test]
    fn sums_in_one_i128_agree_with_the_limbs() {
        let mut next = xorshift(0x2545_F491_4F6C_DD1D);
        for _ in 0..20_000 {
            let terms: Vec<(i128, i32)> = (0..3)
                .map(|_| {
                    let bits = next() % 126;
                    let n = (i128::from(next()) << 64 | i128::from(next())) >> (127 - bits);
                    // Exponents close together (the i128 path) or far apart (the limbs).
                    let spread = [4, 70, 1900][(next() % 3) as usize];
                    let e = (next() % spread) as i32 - (spread / 2) as i32;
                    (n, e)
                })
                .collect();
            // A cancelling pair now and then, for sums of exactly 0.
            let terms = if next().is_multiple_of(4) {
                vec![terms[0], (-terms[0].0, terms[0].1), terms[2]]
            } else {
                terms
            };
            let mut sum = ExactSum::new();
            for &(n, e) in &terms {
                sum.add(n, e);
            }
            assert_eq!(sign_of_sum(&terms), sum.sign(), "{terms:?}");
        }
    }

    #[test]
    fn sums_far_apart_in_scale_keep_their_smallest_term() {
        let big = (1i128 << 125) - 1;
        let mut sum = ExactSum::new();
        sum.add(big, 971);
        sum.add(-big, 971);
        assert_eq!(sum.sign(), Ordering::Equal);
        sum.add(1, -1074);
        assert_eq!(sum.sign(), Ordering::Greater);
        sum.add(-big, 971);
        sum.add(-1, -1074);
        sum.add(big, 971);
        assert_eq!(sum.sign(), Ordering::Equal);
        sum.add(-3, -1074);
        assert_eq!(sum.sign(), Ordering::Less);
        // Small terms against i128 arithmetic.
        for (a, b, c) in [(5, -3, -2), (1 << 100, -(1 << 99), -(1 << 99)), (-7, 3, 3)] {
            let mut sum = ExactSum::new();
            sum.add(a, 2);
            sum.add(b, 2);
            sum.add(c, 2);
            assert_eq!(sum.sign(), (a + b + c).cmp(&0), "{a} + {b} + {c}");
        }
    }
}
