//! A recording's times relative to its start, its resampling onto the encoder's 1 ms grid,
//! and the resting values its baseline removes.

use std::mem::MaybeUninit;

use crate::error::{DataError, Result};
use crate::recording::{Baseline, Phase, Recording};
use crate::simd::widest_or_plain;

use super::CausalConditioning;

/// Each sample's time in s from the recording's first: its time stamps less the first, or
/// `i / fs` (the stream computes its frames' times the same way, so both resample alike).
pub fn relative_times(rec: &Recording) -> Vec<f64> {
    match &rec.times_s {
        Some(t) => t.iter().map(|&x| x - t[0]).collect(),
        None => (0..rec.len()).map(|i| i as f64 / rec.fs).collect(),
    }
}

/// A recording's [`relative_times`], without a list for one sampled uniformly: its time
/// `i / fs` is computed where it is read (the same number as the list's).
#[derive(Debug, Clone, Copy)]
pub(super) enum Times<'a> {
    /// Time stamps less the first.
    Stamps(&'a [f64]),
    /// `n` samples at `fs`.
    Uniform { fs: f64, n: usize },
}

impl<'a> Times<'a> {
    /// The times of `rec`, whose [`relative_times`] are `stamps` where it has time stamps.
    pub(super) fn of(rec: &Recording, stamps: Option<&'a [f64]>) -> Self {
        match stamps {
            Some(t) => Times::Stamps(t),
            None => Times::Uniform {
                fs: rec.fs,
                n: rec.len(),
            },
        }
    }

    pub(super) fn len(self) -> usize {
        match self {
            Times::Stamps(t) => t.len(),
            Times::Uniform { n, .. } => n,
        }
    }

    /// Sample `i`'s time.
    pub(super) fn at(self, i: usize) -> f64 {
        match self {
            Times::Stamps(t) => t[i],
            Times::Uniform { fs, .. } => i as f64 / fs,
        }
    }

    /// The number of samples before the first whose time is not `before` (times ascend, so
    /// `before` holds for a prefix): `slice::partition_point` over the times.
    pub(super) fn partition_point(self, before: impl Fn(f64) -> bool) -> usize {
        match self {
            Times::Stamps(t) => t.partition_point(|&x| before(x)),
            Times::Uniform { n, .. } => {
                let (mut lo, mut hi) = (0, n);
                while lo < hi {
                    let mid = lo + (hi - lo) / 2;
                    match before(self.at(mid)) {
                        true => lo = mid + 1,
                        false => hi = mid,
                    }
                }
                lo
            }
        }
    }

    /// The times of samples `range`, as a list.
    pub(super) fn span(self, range: std::ops::Range<usize>) -> Vec<f64> {
        range.map(|i| self.at(i)).collect()
    }
}

/// The causal resting values for `rec`'s grid, with the grid's size checked (a model
/// applied to another grid is refused before this; a hand-edited file could still differ).
pub(super) fn fixed_offsets(rec: &Recording, causal: &CausalConditioning) -> Result<Vec<f64>> {
    let cells = rec.layout.cells();
    if causal.offsets.len() != cells {
        return Err(DataError::invalid(
            &rec.meta.file,
            format!(
                "the causal resting values are for {} cells, the recording has {cells}",
                causal.offsets.len()
            ),
        )
        .into());
    }
    Ok(causal.offsets.clone())
}

/// The number of samples (`frames x cells`) that [`resample_linear`] makes of a `span_s`
/// second span at `fs`, computed without overflow; `None` when it is not finite or would
/// need more than `isize::MAX` bytes of f64 (no allocation could hold it).
pub fn resampled_len(span_s: f64, fs: f64, cells: usize) -> Option<usize> {
    let steps = (span_s * fs + 1e-9).floor() + 1.0;
    let limit = (isize::MAX as usize / std::mem::size_of::<f64>()) as f64;
    if !(steps.is_finite() && steps >= 1.0 && steps <= limit) {
        return None;
    }
    (steps as usize)
        .checked_mul(cells.max(1))
        .filter(|&n| n <= isize::MAX as usize / std::mem::size_of::<f64>())
}

/// Linear interpolation of `frames` (time-major, `cells` per frame, at `times` in s from the
/// recording's start) onto a grid of `fs` starting at `times[0]`, up to the last time stamp.
///
/// # Panics
/// If `times` does not have one entry per frame, or the result would not fit in memory
/// ([`resampled_len`] is `None`): caller bugs, as readers bound a recording's span.
pub fn resample_linear(frames: &[f64], cells: usize, times: &[f64], fs: f64) -> Vec<f64> {
    resample_less(frames, cells, times, fs, None)
}

/// [`resample_linear`], each value then less its cell's resting value in the same pass when
/// `rest` gives them (`(offsets, present)`: a cell not present is 0), as a pass of its own
/// after the resampling would make it.
///
/// # Panics
/// As [`resample_linear`].
pub(super) fn resample_less(
    frames: &[f64],
    cells: usize,
    times: &[f64],
    fs: f64,
    rest: Option<(&[f64], &[bool])>,
) -> Vec<f64> {
    assert_eq!(
        frames.len(),
        times.len() * cells,
        "one time stamp per frame"
    );
    if times.is_empty() || cells == 0 {
        return Vec::new();
    }
    let span = times[times.len() - 1] - times[0];
    let total = resampled_len(span, fs, cells).expect("a resampled length that fits in memory");
    let mut out = Vec::with_capacity(total);
    resample_into(
        frames,
        times,
        fs,
        rest,
        &mut out.spare_capacity_mut()[..total],
    );
    // SAFETY: the pass wrote every one of the `total` values.
    unsafe { out.set_len(total) };
    out
}

widest_or_plain! {
    ["avx512f", "avx2"]
    /// The steps of [`resample_less`] into `out` (`frames.len() / times.len()` cells a
    /// step): each value `a + (b - a) * w` of its bracketing frames, then less its resting
    /// value, lane by lane, so the width changes no bit.
    fn resample_into(
        frames: &[f64],
        times: &[f64],
        fs: f64,
        rest: Option<(&[f64], &[bool])>,
        out: &mut [MaybeUninit<f64>],
    ) {
        let cells = frames.len() / times.len();
        let t0 = times[0];
        let mut k = 0usize;
        for (s, step) in out.chunks_exact_mut(cells).enumerate() {
            if times.len() == 1 {
                for (x, &a) in step.iter_mut().zip(&frames[..cells]) {
                    x.write(a);
                }
            } else {
                let t = t0 + s as f64 / fs;
                while k + 1 < times.len() - 1 && times[k + 1] <= t {
                    k += 1;
                }
                let (ta, tb) = (times[k], times[k + 1]);
                let w = ((t - ta) / (tb - ta)).clamp(0.0, 1.0);
                let fa = &frames[k * cells..(k + 1) * cells];
                let fb = &frames[(k + 1) * cells..(k + 2) * cells];
                match rest {
                    Some((offsets, present)) => {
                        let cell = fa.iter().zip(fb).zip(offsets).zip(present);
                        for (x, (((&a, &b), &o), &p)) in step.iter_mut().zip(cell) {
                            let v = a + (b - a) * w;
                            x.write(if p { v - o } else { 0.0 });
                        }
                    }
                    None => {
                        for ((x, &a), &b) in step.iter_mut().zip(fa).zip(fb) {
                            x.write(a + (b - a) * w);
                        }
                    }
                }
                continue;
            }
            if let Some((offsets, present)) = rest {
                for ((x, &o), &p) in step.iter_mut().zip(offsets).zip(present) {
                    // SAFETY: written from the frame just above.
                    let v = unsafe { x.assume_init() };
                    x.write(if p { v - o } else { 0.0 });
                }
            }
        }
    }
}

/// The sample range `[lo, hi)` of the sliding phase: labelled phases first, then the
/// manifest's `slide_start_s`/`slide_end_s`, else the whole recording.
pub(super) fn slide_range(rec: &Recording, times: Times) -> Result<(usize, usize)> {
    let n = times.len();
    if let Some(phases) = &rec.phases {
        let lo = phases.iter().position(|&p| p == Phase::Slide);
        let hi = phases.iter().rposition(|&p| p == Phase::Slide);
        return match (lo, hi) {
            (Some(lo), Some(hi)) => Ok((lo, hi + 1)),
            _ => Err(DataError::invalid(&rec.meta.file, "no sample is labelled as sliding").into()),
        };
    }
    let start = rec.meta.slide_start_s.unwrap_or(0.0);
    let end = rec.meta.slide_end_s.unwrap_or(f64::INFINITY);
    let lo = times.partition_point(|t| t < start - 1e-9);
    let hi = times.partition_point(|t| t < end - 1e-9);
    if hi <= lo || lo >= n {
        return Err(DataError::invalid(
            &rec.meta.file,
            format!(
                "slide interval [{start}, {end}) s holds no samples of this {:.3} s recording",
                rec.duration_s()
            ),
        )
        .into());
    }
    Ok((lo, hi))
}

/// Each cell's resting value under `baseline` (zeros for [`Baseline::None`]), over the whole
/// recording (`times` in s from its first sample).
///
/// # Errors
/// A mean baseline whose interval holds no samples.
pub fn baseline_offsets(rec: &Recording, times: &[f64], baseline: Baseline) -> Result<Vec<f64>> {
    offsets_at(rec, Times::Stamps(times), baseline)
}

/// [`baseline_offsets`] with the recording's [`Times`].
pub(super) fn offsets_at(rec: &Recording, times: Times, baseline: Baseline) -> Result<Vec<f64>> {
    let cells = rec.layout.cells();
    match baseline {
        Baseline::None => Ok(vec![0.0; cells]),
        Baseline::Min => {
            let mut lo = vec![f64::INFINITY; cells];
            for frame in rec.samples.chunks_exact(cells) {
                for (l, &s) in lo.iter_mut().zip(frame) {
                    *l = l.min(s);
                }
            }
            Ok(lo)
        }
        Baseline::Mean { start_s, end_s } => {
            let a = times.partition_point(|t| t < start_s);
            let b = times.partition_point(|t| t < end_s);
            if b <= a {
                return Err(DataError::invalid(
                    &rec.meta.file,
                    format!("baseline interval [{start_s}, {end_s}) s holds no samples"),
                )
                .into());
            }
            let mut sum = vec![0.0; cells];
            for frame in rec.samples[a * cells..b * cells].chunks_exact(cells) {
                for (acc, &s) in sum.iter_mut().zip(frame) {
                    *acc += s;
                }
            }
            Ok(sum.into_iter().map(|s| s / (b - a) as f64).collect())
        }
    }
}
