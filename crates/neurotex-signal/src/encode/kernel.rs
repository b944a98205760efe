//! The neuron bank's inner loop: blocks of neurons stepped with their state in registers,
//! compiled for AVX-512, AVX2 or portably, with bit-identical results.

use super::{Bank, IzhikevichParams, Overshoot, V_PEAK};

/// Runs the bank with AVX-512 or AVX2 where the processor has them.
pub(super) fn run_fastest(p: &IzhikevichParams, bank: Bank<'_>) {
    match p.overshoot {
        Overshoot::Kept => run_fastest_with::<false>(p, bank),
        Overshoot::Capped => run_fastest_with::<true>(p, bank),
    }
}

/// [`run_fastest`] with the recovery reading the membrane capped at the peak (`CAP`) or
/// as it is; each variant compiled on its own, so the choice costs the loop nothing.
fn run_fastest_with<const CAP: bool>(p: &IzhikevichParams, bank: Bank<'_>) {
    #[cfg(target_arch = "x86_64")]
    {
        if neurotex_core::has_feature!("avx512f") {
            // SAFETY: the CPU supports AVX-512F, the only feature the function enables.
            unsafe { run_avx512::<CAP>(p, bank) };
            return;
        }
        if neurotex_core::has_feature!("avx2") {
            // SAFETY: the CPU supports AVX2, the only feature the function enables.
            unsafe { run_avx2::<CAP>(p, bank) };
            return;
        }
    }
    run_portable::<CAP>(p, bank);
}

/// Neurons per block whose state stays in registers across time steps. One step is a
/// chain of about 20 dependent operations, so a block is bound by their latency, and the
/// more independent chains (lanes) in flight the better, as long as the registers hold
/// them: 16 neurons with AVX2 (four registers of four f64 each for `v`, four for `u`,
/// out of 16), 32 with AVX-512 (four of eight each, out of 32), where a block of 32 runs in
/// little more time than one of 16. A bank of 16 taxels gains from the wider block only
/// when two populations run as one bank ([`encode_banks`]).
pub(super) const BLOCK: usize = 16;

/// Blocks of [`BLOCK`], then the rest, compiled with AVX2 (4 f64 lanes). FMA is not
/// enabled, and Rust never fuses a multiply and an add on its own, so results are
/// bit-identical to the portable path.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn run_avx2<const CAP: bool>(p: &IzhikevichParams, mut bank: Bank<'_>) {
    let done = run_blocks::<BLOCK, CAP>(p, &mut bank, 0);
    run_rest::<CAP>(p, &mut bank, done);
}

/// Blocks of 32, 16 and 8 neurons (four, two and one register of eight f64 lanes per
/// state variable, see [`BLOCK`]), then the rest, with AVX-512F; bit-identical to the
/// portable path as [`run_avx2`] is.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn run_avx512<const CAP: bool>(p: &IzhikevichParams, mut bank: Bank<'_>) {
    let done = avx512::run_blocks::<4, CAP>(p, &mut bank, 0);
    let done = avx512::run_blocks::<2, CAP>(p, &mut bank, done);
    let done = avx512::run_blocks::<1, CAP>(p, &mut bank, done);
    run_rest::<CAP>(p, &mut bank, done);
}

/// The AVX-512 blocks, written with intrinsics: the compiler's own vectorisation of
/// [`step`] kept part of a 32-neuron block's state in memory between steps, which
/// lengthened every step's chain of dependent operations.
#[cfg(target_arch = "x86_64")]
mod avx512 {
    use std::arch::x86_64::*;

    use super::{Bank, IzhikevichParams, V_PEAK};

    /// f64 lanes per register.
    const LANES: usize = 8;

    /// Runs the whole blocks of `R` registers (`8 R` neurons) from neuron `first` on and
    /// returns the first neuron not run: [`super::step`]'s operations in its order, on
    /// eight neurons per instruction.
    #[target_feature(enable = "avx512f")]
    pub(super) unsafe fn run_blocks<const R: usize, const CAP: bool>(
        p: &IzhikevichParams,
        bank: &mut Bank<'_>,
        first: usize,
    ) -> usize {
        let n = bank.v.len();
        let width = R * LANES;
        let end = first + (n - first) / width * width;
        let [a, b, c, d] = [p.a, p.b, p.c, p.d].map(|k| _mm512_set1_pd(k));
        let [peak, half, quad, five, rest] =
            [V_PEAK, 0.5, 0.04, 5.0, 140.0].map(|k| _mm512_set1_pd(k));
        // `v += 0.5 * (0.04 * (v * v) + 5.0 * v + 140.0 - u + i)`, left to right.
        let half_step = |v: __m512d, u: __m512d, i: __m512d| {
            let square = _mm512_mul_pd(quad, _mm512_mul_pd(v, v));
            let sum = _mm512_add_pd(square, _mm512_mul_pd(five, v));
            let sum = _mm512_add_pd(_mm512_sub_pd(_mm512_add_pd(sum, rest), u), i);
            _mm512_add_pd(v, _mm512_mul_pd(half, sum))
        };
        for start in (first..end).step_by(width) {
            let load = |from: &[f64], r: usize| {
                _mm512_loadu_pd(from[start + r * LANES..][..LANES].as_ptr())
            };
            let mut v: [__m512d; R] = std::array::from_fn(|r| load(bank.v, r));
            let mut u: [__m512d; R] = std::array::from_fn(|r| load(bank.u, r));
            let g: [__m512d; R] = std::array::from_fn(|r| load(bank.gains, r));
            let frames = bank.input.chunks_exact(n);
            for (frame, out) in frames.zip(bank.raster.chunks_exact_mut(n)) {
                for r in 0..R {
                    let at = start + r * LANES;
                    let fired = _mm512_cmp_pd_mask::<_CMP_GE_OQ>(v[r], peak);
                    let spikes = _mm512_cvtepi64_epi8(_mm512_maskz_set1_epi64(fired, 1));
                    _mm_storel_epi64(out[at..at + LANES].as_mut_ptr().cast(), spikes);
                    let vv = _mm512_mask_blend_pd(fired, v[r], c);
                    let uu = _mm512_mask_add_pd(u[r], fired, u[r], d);
                    let i = _mm512_mul_pd(g[r], _mm512_loadu_pd(frame[at..at + LANES].as_ptr()));
                    let vv = half_step(half_step(vv, uu, i), uu, i);
                    let seen = if CAP { _mm512_min_pd(vv, peak) } else { vv };
                    let recovery = _mm512_sub_pd(_mm512_mul_pd(b, seen), uu);
                    u[r] = _mm512_add_pd(uu, _mm512_mul_pd(a, recovery));
                    v[r] = vv;
                }
            }
            for r in 0..R {
                let at = start + r * LANES;
                _mm512_storeu_pd(bank.v[at..at + LANES].as_mut_ptr(), v[r]);
                _mm512_storeu_pd(bank.u[at..at + LANES].as_mut_ptr(), u[r]);
            }
        }
        end
    }
}

/// Blocks of [`BLOCK`], then the rest, for any processor.
fn run_portable<const CAP: bool>(p: &IzhikevichParams, mut bank: Bank<'_>) {
    let done = run_blocks::<BLOCK, CAP>(p, &mut bank, 0);
    run_rest::<CAP>(p, &mut bank, done);
}

/// Runs the whole blocks of `B` neurons from neuron `first` on (time inner, a block's state
/// in registers) and returns the first neuron not run.
#[inline(always)]
fn run_blocks<const B: usize, const CAP: bool>(
    p: &IzhikevichParams,
    bank: &mut Bank<'_>,
    first: usize,
) -> usize {
    let n = bank.v.len();
    let end = first + (n - first) / B * B;
    for start in (first..end).step_by(B) {
        let block = start..start + B;
        let mut vb = [0.0; B];
        let mut ub = [0.0; B];
        let mut gb = [0.0; B];
        vb.copy_from_slice(&bank.v[block.clone()]);
        ub.copy_from_slice(&bank.u[block.clone()]);
        gb.copy_from_slice(&bank.gains[block.clone()]);
        let frames = bank.input.chunks_exact(n);
        for (frame, out) in frames.zip(bank.raster.chunks_exact_mut(n)) {
            let x: &[f64; B] = frame[block.clone()].try_into().expect("a block");
            let o: &mut [u8; B] = (&mut out[block.clone()]).try_into().expect("a block");
            step::<CAP>(p, &gb, &mut vb, &mut ub, x, o);
        }
        bank.v[block.clone()].copy_from_slice(&vb);
        bank.u[block].copy_from_slice(&ub);
    }
    end
}

/// Runs the neurons from `first` on, frame by frame.
#[inline(always)]
fn run_rest<const CAP: bool>(p: &IzhikevichParams, bank: &mut Bank<'_>, first: usize) {
    let n = bank.v.len();
    if first == n {
        return;
    }
    let frames = bank.input.chunks_exact(n);
    for (frame, out) in frames.zip(bank.raster.chunks_exact_mut(n)) {
        step::<CAP>(
            p,
            &bank.gains[first..],
            &mut bank.v[first..],
            &mut bank.u[first..],
            &frame[first..],
            &mut out[first..],
        );
    }
}

/// One 1 ms step of the reference scheme for a group of neurons, each with its gain, the
/// recovery reading the membrane capped at the peak under `CAP`. Branch-free per neuron
/// so it vectorises; the order of every floating-point operation is that of the
/// reference.
#[inline(always)]
pub(super) fn step<const CAP: bool>(
    p: &IzhikevichParams,
    gains: &[f64],
    v: &mut [f64],
    u: &mut [f64],
    x: &[f64],
    out: &mut [u8],
) {
    let IzhikevichParams { a, b, c, d, .. } = *p;
    let lanes = v.iter_mut().zip(u.iter_mut()).zip(gains.iter().zip(x));
    for (((vi, ui), (&gain, &x)), o) in lanes.zip(out.iter_mut()) {
        let fired = *vi >= V_PEAK;
        *o = fired as u8;
        let mut vv = if fired { c } else { *vi };
        let uu = if fired { *ui + d } else { *ui };
        let i = gain * x;
        vv += 0.5 * (0.04 * (vv * vv) + 5.0 * vv + 140.0 - uu + i);
        vv += 0.5 * (0.04 * (vv * vv) + 5.0 * vv + 140.0 - uu + i);
        let seen = if CAP { vv.min(V_PEAK) } else { vv };
        *ui = uu + a * (b * seen - uu);
        *vi = vv;
    }
}
