//! Normalising samples: by their global maximum or by a fixed scale.

use crate::simd::widest_or_plain;

/// Divides every sample by the largest sample of all taxels (paper section II-E), so
/// relative activation between taxels survives. Returns `true`, and sets everything to 0,
/// when that maximum is <= 0 (a recording with no positive signal is never divided).
pub fn normalise_global_max(samples: &mut [f64]) -> bool {
    normalise_by_max(samples, largest(samples))
}

/// [`normalise_global_max`] with the samples' maximum `max` already found.
pub(super) fn normalise_by_max(samples: &mut [f64], max: f64) -> bool {
    if max > 0.0 {
        // A true division, not a multiplication by `1 / max`: that rounds twice and can
        // differ in the last bit, which the encoder's threshold can turn into a spike more
        // or less; dividing gives numpy's `x / x.max()` bit for bit.
        divide_all(samples, max);
        false
    } else {
        samples.iter_mut().for_each(|s| *s = 0.0);
        true
    }
}

widest_or_plain! {
    ["avx2"]
    /// The largest of `samples` (finite numbers; -inf for none): eight running maxima,
    /// which vectorise where one fold through `f64::max` is a chain of dependent
    /// comparisons. The largest of a set does not depend on the order it is sought in (a
    /// maximum of 0 may come out as -0, which compares equal).
    pub(super) fn largest(samples: &[f64]) -> f64 {
        let mut lanes = [f64::NEG_INFINITY; 8];
        let chunks = samples.chunks_exact(8);
        for &x in chunks.remainder() {
            lanes[0] = if x > lanes[0] { x } else { lanes[0] };
        }
        for chunk in chunks {
            for (m, &x) in lanes.iter_mut().zip(chunk) {
                *m = if x > *m { x } else { *m };
            }
        }
        let mut top = f64::NEG_INFINITY;
        for m in lanes {
            top = top.max(m);
        }
        top
    }
}

widest_or_plain! {
    ["avx2"]
    /// Divides every sample by `by` (correctly rounded in any vector width, so the same
    /// bits as one division at a time).
    pub(super) fn divide_all(samples: &mut [f64], by: f64) {
        for s in samples {
            *s /= by;
        }
    }
}

/// Divides every sample by the fixed causal `scale` (a true division, as
/// [`normalise_global_max`], so the stream's per-sample division gives the same bits).
/// Returns whether no sample is positive (the recording gives the neurons no drive).
pub fn normalise_fixed(samples: &mut [f64], scale: f64) -> bool {
    let mut any_positive = false;
    for s in samples.iter_mut() {
        *s /= scale;
        any_positive |= *s > 0.0;
    }
    !any_positive
}
