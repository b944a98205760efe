//! The paper's rig as a physical model, the built-in default dataset
//! (docs/decisions/0015-a-physical-simulator-never-tuned-to-the-paper.md).
//!
//! A 4x4 array of 2x2 mm piezoresistive taxels on a 13x13 mm pad, under a soft cover, is
//! pressed onto one of eight procedural textures with 1 N under force control, held 5 s,
//! slid 90 mm at the given speed and lifted, sampled at 1 kHz with every phase labelled.
//!
//! Mechanics: each taxel's share of the pad rests on a Winkler foundation (pad and texture
//! stiffness in series); the pad height is solved every millisecond so the contact force
//! equals the commanded force. The texture height under a taxel is the surface averaged
//! over the taxel and spread by the cover (a box of the taxel's length convolved with a
//! Gaussian, and three lateral lines). The piezoresistive response saturates
//! (`p / (p + p_sat)`), lags (first order), carries signal-dependent noise and a fixed
//! per-taxel gain mismatch, and is read by an ADC. Every parameter is physical and
//! documented in [`RigParams`]; none is tuned to reach the paper's accuracies.

pub mod texture;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use rand_xoshiro::Xoshiro256PlusPlus;
use serde::{Deserialize, Serialize};

use crate::error::ParamError;
use crate::recording::{Layout, Meta, Phase, Recording};
use texture::{hash3, Surface};
pub use texture::{Texture, ALL_TEXTURES};

/// Physical parameters of the sensor, the protocol and the trial-to-trial variation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RigParams {
    /// Taxel rows (along the sliding direction; row 0 leads).
    pub rows: usize,
    /// Taxel columns (across the sliding direction).
    pub cols: usize,
    /// Side of one square taxel, mm (paper: 2).
    pub taxel_mm: f64,
    /// Side of the square active area, mm (paper: 13).
    pub active_mm: f64,
    /// Pad stiffness per unit area, N/mm³: the soft finger cuff and VHB cover in series.
    pub pad_stiffness_n_per_mm3: f64,
    /// Standard deviation of the cover's pressure spreading, mm (about the 1 mm cover's thickness / 2).
    pub cover_spread_mm: f64,
    /// Pressure at which the piezoresistive response is half its maximum, N/mm².
    pub saturation_n_per_mm2: f64,
    /// Time constant of the fabric's response lag, ms.
    pub lag_ms: f64,
    /// Noise: standard deviation `noise * sqrt(y)` on a response `y` in [0, 1].
    pub noise: f64,
    /// ADC resolution in bits; samples are ADC counts.
    pub adc_bits: u32,
    /// Relative standard deviation of the fixed per-taxel gain mismatch.
    pub gain_mismatch: f64,
    /// Seed of the sensor's own gain mismatch (the same sensor for every trial and seed).
    pub sensor_seed: u64,
    /// Commanded normal force, N (paper: 1).
    pub force_n: f64,
    /// Time off the surface before contact, s.
    pub free_s: f64,
    /// Force ramp from touch to full force, s.
    pub contact_s: f64,
    /// Hold at full force, s (paper: 5).
    pub hold_s: f64,
    /// Sliding distance, mm (paper: 90).
    pub slide_mm: f64,
    /// Force ramp down to lift-off, s.
    pub retract_s: f64,
    /// Time off the surface after lift-off, s.
    pub after_s: f64,
    /// Range of the random translation of each trial's patch of texture, mm.
    pub patch_range_mm: f64,
    /// Largest lateral offset of the sliding path, mm.
    pub lateral_offset_mm: f64,
    /// Largest rotation of the sensor against the texture, degrees.
    pub rotation_deg: f64,
    /// Relative standard deviation of the force actually applied per trial.
    pub force_jitter: f64,
    /// Relative standard deviation of the speed actually reached per trial.
    pub speed_jitter: f64,
    /// Spacing of the precomputed height profiles along the path, mm.
    pub profile_step_mm: f64,
}

impl Default for RigParams {
    fn default() -> Self {
        RigParams {
            rows: 4,
            cols: 4,
            taxel_mm: 2.0,
            active_mm: 13.0,
            pad_stiffness_n_per_mm3: 0.01,
            cover_spread_mm: 0.5,
            saturation_n_per_mm2: 0.02,
            lag_ms: 8.0,
            noise: 0.004,
            adc_bits: 12,
            gain_mismatch: 0.1,
            sensor_seed: 0x5E45_0001,
            force_n: 1.0,
            free_s: 0.2,
            contact_s: 0.5,
            hold_s: 5.0,
            slide_mm: 90.0,
            retract_s: 0.3,
            after_s: 0.2,
            patch_range_mm: 1000.0,
            lateral_offset_mm: 1.0,
            rotation_deg: 3.0,
            force_jitter: 0.03,
            speed_jitter: 0.02,
            profile_step_mm: 0.2,
        }
    }
}

impl RigParams {
    /// Checks that every parameter is physical: positive sizes, times, stiffnesses.
    ///
    /// # Errors
    /// The rule broken.
    pub fn check(&self) -> Result<(), ParamError> {
        let positive = [
            ("taxel_mm", self.taxel_mm),
            ("active_mm", self.active_mm),
            ("pad_stiffness_n_per_mm3", self.pad_stiffness_n_per_mm3),
            ("saturation_n_per_mm2", self.saturation_n_per_mm2),
            ("lag_ms", self.lag_ms),
            ("force_n", self.force_n),
            ("hold_s", self.hold_s),
            ("slide_mm", self.slide_mm),
            ("profile_step_mm", self.profile_step_mm),
        ];
        for (name, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err(ParamError::new(name, "must be a positive number", v));
            }
        }
        let non_negative = [
            ("cover_spread_mm", self.cover_spread_mm),
            ("noise", self.noise),
            ("gain_mismatch", self.gain_mismatch),
            ("free_s", self.free_s),
            ("contact_s", self.contact_s),
            ("retract_s", self.retract_s),
            ("after_s", self.after_s),
            ("patch_range_mm", self.patch_range_mm),
            ("lateral_offset_mm", self.lateral_offset_mm),
            ("rotation_deg", self.rotation_deg),
            ("force_jitter", self.force_jitter),
            ("speed_jitter", self.speed_jitter),
        ];
        for (name, v) in non_negative {
            if !(v.is_finite() && v >= 0.0) {
                return Err(ParamError::new(name, "must be a non-negative number", v));
            }
        }
        if self.rows == 0 || self.cols == 0 {
            return Err(ParamError::new(
                "rows, cols",
                "the array needs at least one taxel",
                format!("{}x{}", self.rows, self.cols),
            ));
        }
        if self.taxel_mm * self.rows.max(self.cols) as f64 > self.active_mm {
            return Err(ParamError::new(
                "taxel_mm",
                "taxels must fit in the active area",
                self.taxel_mm,
            ));
        }
        if !(1..=24).contains(&self.adc_bits) {
            return Err(ParamError::new(
                "adc_bits",
                "ADC resolution must be 1 to 24 bits",
                self.adc_bits,
            ));
        }
        Ok(())
    }

    /// Centre-to-centre taxel spacing, mm.
    pub fn pitch_mm(&self) -> f64 {
        let n = self.rows.max(self.cols);
        if n < 2 {
            0.0
        } else {
            (self.active_mm - self.taxel_mm) / (n - 1) as f64
        }
    }
}

/// One simulated trial's conditions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Trial {
    /// The texture.
    pub texture: Texture,
    /// Nominal sliding speed, mm/s.
    pub speed_mm_s: f64,
    /// Trial number.
    pub trial: u32,
}

/// A trial's random draws, from a generator seeded by the dataset seed and the trial's
/// identity only (so results do not depend on thread count or order).
fn trial_rng(seed: u64, t: &Trial) -> ChaCha8Rng {
    let texture_index = ALL_TEXTURES
        .iter()
        .position(|&x| x == t.texture)
        .unwrap_or(0) as i64;
    let speed_key = (t.speed_mm_s * 1000.0).round() as i64;
    ChaCha8Rng::seed_from_u64(hash3(
        texture_index * 1_000_003 + speed_key,
        i64::from(t.trial),
        seed,
    ))
}

/// The sensor's fixed per-taxel gains.
fn taxel_gains(p: &RigParams) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(p.sensor_seed);
    (0..p.rows * p.cols)
        .map(|_| {
            let z: f64 = rng.sample(StandardNormal);
            (1.0 + p.gain_mismatch * z).max(0.2)
        })
        .collect()
}

/// Height profiles along the sliding path, smoothed by the taxel and the cover. The taxels
/// of one column lie on one line parallel to the sliding direction, so each column keeps
/// one profile and each row reads it at its own offset along the line.
struct Profiles {
    start_mm: f64,
    per_mm: f64,
    cols: usize,
    /// Profile sample `k` of column `c` at `k * cols + c`: heights from `start_mm` in steps
    /// of `1 / per_mm`, the columns of one sample side by side.
    heights: Vec<f64>,
    /// Per row, its offset along the sliding direction, mm.
    row_offset_mm: Vec<f64>,
}

impl Profiles {
    /// The height under every taxel (row-major) after sliding `s_mm`, interpolated
    /// linearly between profile samples.
    fn heights(&self, s_mm: f64, out: &mut [f64]) {
        let cols = self.cols;
        let last = (self.heights.len() / cols - 2) as f64;
        for (offset, out) in self.row_offset_mm.iter().zip(out.chunks_exact_mut(cols)) {
            // One position per row: the taxels of a row share it (every column's profile
            // has the same sampling), so it is computed once, not once per taxel.
            let x = ((s_mm + offset - self.start_mm) * self.per_mm).clamp(0.0, last);
            let k = x as usize;
            let w = x - k as f64;
            let (here, next) = self.heights[k * cols..(k + 2) * cols].split_at(cols);
            for ((o, &a), &b) in out.iter_mut().zip(here).zip(next) {
                *o = a + (b - a) * w;
            }
        }
    }
}

/// The along-track smoothing kernel over `-reach..=reach` profile steps: a box of
/// `half_box` steps either side (the taxel's length) convolved with a Gaussian of `sigma`
/// steps (the cover's spread), normalised to sum to 1.
fn along_track_kernel(half_box: isize, sigma: f64, reach: isize) -> Vec<f64> {
    let k: Vec<f64> = (-reach..=reach)
        .map(|i| {
            (-half_box..=half_box)
                .map(|b| {
                    let d = (i - b) as f64;
                    if sigma > 0.0 {
                        (-0.5 * d * d / (sigma * sigma)).exp()
                    } else if d == 0.0 {
                        1.0
                    } else {
                        0.0
                    }
                })
                .sum()
        })
        .collect();
    let total: f64 = k.iter().sum();
    k.into_iter().map(|v| v / total).collect()
}

fn build_profiles(p: &RigParams, texture: Texture, rng: &mut ChaCha8Rng) -> Profiles {
    let texture_seed: u64 = rng.gen();
    let origin = (
        rng.gen::<f64>() * p.patch_range_mm,
        rng.gen::<f64>() * p.patch_range_mm,
    );
    let lateral = (rng.gen::<f64>() * 2.0 - 1.0) * p.lateral_offset_mm;
    let theta = (rng.gen::<f64>() * 2.0 - 1.0) * p.rotation_deg.to_radians();
    let (u, n) = ((theta.cos(), theta.sin()), (-theta.sin(), theta.cos()));
    // Along-track smoothing: the taxel's length as a box, convolved with the cover's Gaussian.
    let step = p.profile_step_mm;
    let half_box = (p.taxel_mm / 2.0 / step).round() as isize;
    let sigma = p.cover_spread_mm / step;
    let reach = half_box + (3.0 * sigma).ceil() as isize;
    let kernel = along_track_kernel(half_box, sigma, reach);
    let pitch = p.pitch_mm();
    let row_offset_mm: Vec<f64> = (0..p.rows)
        .map(|r| ((p.rows - 1) as f64 / 2.0 - r as f64) * pitch)
        .collect();
    let lowest = row_offset_mm.iter().copied().fold(f64::INFINITY, f64::min);
    let highest = row_offset_mm
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max);
    // The line covers every row's path from 1 mm before the start to 1 mm past the end.
    let start_mm = lowest - 1.0;
    let samples = ((highest - lowest + p.slide_mm + 2.0) / step).ceil() as usize + 2;
    let raw_len = samples + 2 * reach as usize;
    // Lateral spreading: three lines across the taxel, weighted as a coarse Gaussian.
    let lines = [
        (-p.taxel_mm / 3.0, 0.25),
        (0.0, 0.5),
        (p.taxel_mm / 3.0, 0.25),
    ];
    let mut raw = vec![0.0; raw_len];
    // One surface per line, so each keeps what its neighbouring points share.
    let mut surfaces = lines.map(|_| Surface::new(texture, texture_seed));
    let columns: Vec<Vec<f64>> = (0..p.cols)
        .map(|c| {
            let across0 = (c as f64 - (p.cols - 1) as f64 / 2.0) * pitch + lateral;
            raw.fill(0.0);
            for (k, h) in raw.iter_mut().enumerate() {
                let along = start_mm + (k as f64 - reach as f64) * step;
                for (&(offset, weight), surface) in lines.iter().zip(&mut surfaces) {
                    let across = across0 + offset;
                    let x = origin.0 + along * u.0 + across * n.0;
                    let y = origin.1 + along * u.1 + across * n.1;
                    *h += weight * surface.height(x, y);
                }
            }
            (0..samples)
                .map(|k| kernel.iter().zip(&raw[k..]).map(|(w, h)| w * h).sum())
                .collect()
        })
        .collect();
    let heights = (0..samples)
        .flat_map(|k| columns.iter().map(move |column| column[k]))
        .collect();
    Profiles {
        start_mm,
        per_mm: 1.0 / step,
        cols: p.cols,
        heights,
        row_offset_mm,
    }
}

/// Pad height `z` such that `sum max(0, h_i - z) = depth_sum`, by the sorted-prefix solution
/// of the Winkler contact (exact; taxels below `z` carry no load).
fn solve_contact(h: &[f64], depth_sum: f64, sorted: &mut Vec<f64>) -> f64 {
    // Usually every taxel touches: then z is the plain mean solution, no sorting needed.
    // (Four running sums and a check without early exit: this runs every millisecond of
    // the slide, and a single chain of additions was most of its time.)
    let mut sums = [0.0; 4];
    let mut quads = h.chunks_exact(4);
    for quad in &mut quads {
        for (s, &hi) in sums.iter_mut().zip(quad) {
            *s += hi;
        }
    }
    let total = (sums[0] + sums[1]) + (sums[2] + sums[3]) + quads.remainder().iter().sum::<f64>();
    let all = (total - depth_sum) * (1.0 / h.len() as f64);
    if h.iter().fold(true, |touch, &hi| touch & (hi >= all)) {
        return all;
    }
    sorted.clear();
    sorted.extend_from_slice(h);
    sorted.sort_unstable_by(|a, b| b.total_cmp(a));
    let mut prefix = 0.0;
    for m in 1..=sorted.len() {
        prefix += sorted[m - 1];
        let z = (prefix - depth_sum) / m as f64;
        if m == sorted.len() || z >= sorted[m] {
            return z;
        }
    }
    f64::INFINITY
}

/// Simulates one trial of the protocol; samples are ADC counts, phases are labelled and
/// the manifest fields (including the sliding interval) are filled in.
///
/// # Errors
/// Unphysical parameters or a non-positive speed.
pub fn simulate_trial(p: &RigParams, trial: &Trial, seed: u64) -> Result<Recording, ParamError> {
    simulate(p, trial, seed, None)
}

/// [`simulate_trial`] that also returns the contact force (N) of every step, recomputed
/// from the solved pad height, and the force commanded.
///
/// # Errors
/// Unphysical parameters or a non-positive speed.
pub fn simulate_trial_traced(
    p: &RigParams,
    trial: &Trial,
    seed: u64,
) -> Result<(Recording, Vec<(f64, f64)>), ParamError> {
    let mut forces = Vec::new();
    let rec = simulate(p, trial, seed, Some(&mut forces))?;
    Ok((rec, forces))
}

/// The simulation; with `forces`, also the commanded and the contact force of every step.
fn simulate(
    p: &RigParams,
    trial: &Trial,
    seed: u64,
    mut forces: Option<&mut Vec<(f64, f64)>>,
) -> Result<Recording, ParamError> {
    p.check()?;
    check_speed(p, trial.speed_mm_s)?;
    let mut rng = trial_rng(seed, trial);
    let profiles = build_profiles(p, trial.texture, &mut rng);
    let force = p.force_n * (1.0 + p.force_jitter * rng.sample::<f64, _>(StandardNormal)).max(0.5);
    let speed =
        trial.speed_mm_s * (1.0 + p.speed_jitter * rng.sample::<f64, _>(StandardNormal)).max(0.5);
    let gains = taxel_gains(p);
    let cells = p.rows * p.cols;
    let schedule = Schedule::with_force(p, speed, force);
    let total = schedule.total();
    let sensor = Sensor::of(p, trial.texture);
    let (k, area) = (sensor.k, p.active_mm * p.active_mm / cells as f64);
    let mut samples = vec![0.0; total * cells];
    let mut phases = Vec::with_capacity(total);
    // The sensor noise has its own generator, seeded from the trial's: ChaCha8 and the
    // ziggurat took half of a trial's time for one normal draw per taxel and millisecond;
    // xoshiro256++ draws them three times faster with the same ziggurat.
    let mut noise_rng = Xoshiro256PlusPlus::seed_from_u64(rng.gen());
    if let Some(forces) = forces.as_deref_mut() {
        forces.reserve(total);
    }
    let (mut h, mut target, mut y, mut sorted) = (
        vec![0.0; cells],
        vec![0.0; cells],
        vec![0.0; cells],
        Vec::with_capacity(cells),
    );
    let mut z = f64::INFINITY;
    // The force and the distance slid of the step whose contact `h` and `z` hold.
    let mut solved: Option<(u64, u64)> = None;
    // Steps go in blocks: each step's targets first, then the block's noise in one tight
    // loop (the processor overlaps the draws), then the read-out of the whole block.
    let block = Sensor::BLOCK_STEPS * cells;
    let (mut targets, mut draws) = (vec![0.0; block], vec![0.0; block]);
    for (b, frames) in samples.chunks_mut(block).enumerate() {
        let steps = frames.len() / cells;
        for (i, row) in targets[..frames.len()].chunks_exact_mut(cells).enumerate() {
            let step = b * Sensor::BLOCK_STEPS + i;
            let (phase, f, s) = schedule.at(step);
            phases.push(phase);
            // Before contact, in the hold and after lift-off the pad neither moves nor
            // changes its force (5.4 s of the protocol's 24 at 5 mm/s): the previous
            // step's contact solution is still exact, so it is solved only when force or
            // position change.
            if solved != Some((f.to_bits(), s.to_bits())) {
                profiles.heights(s, &mut h);
                z = if f > 0.0 {
                    solve_contact(&h, f / (k * area), &mut sorted)
                } else {
                    f64::INFINITY
                };
                sensor.targets(&h, z, &gains, &mut target);
                solved = Some((f.to_bits(), s.to_bits()));
            }
            row.copy_from_slice(&target);
            if let Some(forces) = forces.as_deref_mut() {
                let contact = h
                    .iter()
                    .map(|&hi| k * area * (hi - z).max(0.0))
                    .sum::<f64>();
                forces.push((f, contact));
            }
        }
        let draws = &mut draws[..steps * cells];
        standard_normals(&mut noise_rng, draws);
        sensor.read(&targets[..frames.len()], &mut y, draws, frames);
    }
    let slide_start = schedule.slide_start() as f64 / 1000.0;
    let slide_s = (slide_start, slide_start + schedule.slide as f64 / 1000.0);
    Ok(trial_recording(p, trial, samples, phases, slide_s))
}

/// Fills `out` with standard normal draws. A function of its own, so that the draw is
/// compiled into this one tight loop (inlined, the processor overlaps the draws) whatever
/// the inliner decides for the large step loop around it.
#[inline(never)]
fn standard_normals(rng: &mut Xoshiro256PlusPlus, out: &mut [f64]) {
    // The generator's state in a local: through the reference it was stored back to
    // memory after every draw.
    let mut local = rng.clone();
    for draw in out {
        *draw = local.sample(StandardNormal);
    }
    *rng = local;
}

/// The piezoresistive read-out of a trial: response lag, noise and ADC.
struct Sensor {
    /// Contact stiffness per unit area, N/mm³ (pad and texture in series).
    k: f64,
    /// Pressure of half the maximum response, N/mm².
    saturation: f64,
    /// Weight of the new target in the first-order lag per step.
    alpha: f64,
    /// Noise: standard deviation `noise * sqrt(y)`.
    noise: f64,
    /// The ADC's largest count.
    full_scale: f64,
}

impl Sensor {
    /// The rig's sensor pressed on `texture`.
    fn of(p: &RigParams, texture: Texture) -> Self {
        let k_texture = texture.stiffness_n_per_mm3();
        Sensor {
            k: 1.0 / (1.0 / p.pad_stiffness_n_per_mm3 + 1.0 / k_texture),
            saturation: p.saturation_n_per_mm2,
            alpha: 1.0 - (-1.0 / p.lag_ms).exp(),
            noise: p.noise,
            full_scale: ((1u64 << p.adc_bits) - 1) as f64,
        }
    }

    /// Each taxel's saturated response to its pressure, at heights `h` under a pad at
    /// `z`, scaled by its gain: the target its output lags towards.
    fn targets(&self, h: &[f64], z: f64, gains: &[f64], target: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        {
            if neurotex_core::has_feature!("avx2") {
                // SAFETY: the CPU supports AVX2, the only feature the function enables.
                return unsafe { self.targets_avx2(h, z, gains, target) };
            }
        }
        self.targets_lanes(h, z, gains, target);
    }

    /// [`Sensor::targets_lanes`] compiled for AVX2, exact as [`Sensor::read_avx2`] is.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn targets_avx2(&self, h: &[f64], z: f64, gains: &[f64], target: &mut [f64]) {
        self.targets_lanes(h, z, gains, target);
    }

    #[inline(always)]
    fn targets_lanes(&self, h: &[f64], z: f64, gains: &[f64], target: &mut [f64]) {
        for ((t, &hi), &gain) in target.iter_mut().zip(h).zip(gains) {
            let pressure = self.k * (hi - z).max(0.0);
            *t = gain * pressure / (pressure + self.saturation);
        }
    }

    /// Steps read out together: the block's targets and noise draws stay in the cache.
    const BLOCK_STEPS: usize = 256;

    /// Consecutive steps of every taxel (`targets`, `draws` and `frames` hold one row of
    /// `y.len()` taxels per step): the lag of the response `y` towards the step's target,
    /// the noise (the step's draw of each taxel, scaled by `sqrt(y)`, so an unloaded taxel
    /// reads 0) and the ADC counts into `frames`.
    fn read(&self, targets: &[f64], y: &mut [f64], draws: &[f64], frames: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        {
            if neurotex_core::has_feature!("avx2") {
                // SAFETY: the CPU supports AVX2, the only feature the function enables.
                return unsafe { self.read_avx2(targets, y, draws, frames) };
            }
        }
        self.read_lanes(targets, y, draws, frames)
    }

    /// [`Sensor::read_lanes`] compiled for AVX2 (four taxels per instruction). FMA is not
    /// enabled and Rust never fuses a multiply and an add on its own; division, square
    /// root and conversions are exact in every width: the bits do not depend on it.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn read_avx2(&self, targets: &[f64], y: &mut [f64], draws: &[f64], frames: &mut [f64]) {
        self.read_lanes(targets, y, draws, frames)
    }

    #[inline(always)]
    fn read_lanes(&self, targets: &[f64], y: &mut [f64], draws: &[f64], frames: &mut [f64]) {
        let (alpha, noise, full_scale) = (self.alpha, self.noise, self.full_scale);
        let n = y.len();
        for ((target, draw), frame) in targets
            .chunks_exact(n)
            .zip(draws.chunks_exact(n))
            .zip(frames.chunks_exact_mut(n))
        {
            for (((&t, y), &d), sample) in target.iter().zip(y.iter_mut()).zip(draw).zip(frame) {
                *y += (t - *y) * alpha;
                // Rounds half up (a floor, not a conversion to integers: that has no
                // vector instruction for unsigned integers before AVX-512).
                let v = *y + noise * y.sqrt() * d;
                *sample = (v.clamp(0.0, 1.0) * full_scale + 0.5).floor();
            }
        }
    }
}

/// The protocol's phases in 1 ms steps: free, contact (force ramps up), hold, slide,
/// retract (force ramps down), free.
struct Schedule {
    free: usize,
    contact: usize,
    hold: usize,
    slide: usize,
    retract: usize,
    after: usize,
    force: f64,
    speed: f64,
    slide_mm: f64,
}

impl Schedule {
    fn with_force(p: &RigParams, speed: f64, force: f64) -> Self {
        let ms = |s: f64| (s * 1000.0).round() as usize;
        Schedule {
            free: ms(p.free_s),
            contact: ms(p.contact_s),
            hold: ms(p.hold_s),
            slide: ms(p.slide_mm / speed).max(1),
            retract: ms(p.retract_s),
            after: ms(p.after_s),
            force,
            speed,
            slide_mm: p.slide_mm,
        }
    }

    fn total(&self) -> usize {
        self.slide_start() + self.slide + self.retract + self.after
    }

    fn slide_start(&self) -> usize {
        self.free + self.contact + self.hold
    }

    /// The phase, the commanded force (N) and the distance slid (mm) at `step`.
    fn at(&self, step: usize) -> (Phase, f64, f64) {
        let force = self.force;
        let slide_start = self.slide_start();
        if step < self.free {
            (Phase::Free, 0.0, 0.0)
        } else if step < self.free + self.contact {
            let ramped = force * (step - self.free + 1) as f64 / self.contact as f64;
            (Phase::Contact, ramped, 0.0)
        } else if step < slide_start {
            (Phase::Hold, force, 0.0)
        } else if step < slide_start + self.slide {
            let k_slide = step - slide_start;
            (Phase::Slide, force, self.speed * k_slide as f64 / 1000.0)
        } else if step < self.total() - self.after {
            let k_up = step - (slide_start + self.slide);
            let ramp = 1.0 - (k_up + 1) as f64 / self.retract.max(1) as f64;
            (Phase::Retract, force * ramp, self.slide_mm)
        } else {
            (Phase::Free, 0.0, self.slide_mm)
        }
    }
}

/// The recording of a simulated trial from its samples and phases; `slide_s` is the
/// sliding phase's start and end in s.
fn trial_recording(
    p: &RigParams,
    trial: &Trial,
    samples: Vec<f64>,
    phases: Vec<Phase>,
    slide_s: (f64, f64),
) -> Recording {
    Recording {
        fs: 1000.0,
        layout: Layout::grid(p.rows, p.cols),
        samples,
        times_s: None,
        phases: Some(phases),
        meta: Meta {
            file: trial_file_name(trial),
            label: trial.texture.name().to_string(),
            speed_mm_s: Some(trial.speed_mm_s),
            force_n: Some(p.force_n),
            trial: Some(i64::from(trial.trial)),
            slide_start_s: Some(slide_s.0),
            slide_end_s: Some(slide_s.1),
            extra: Default::default(),
        },
    }
}

/// The file name a simulated trial is written under.
pub fn trial_file_name(t: &Trial) -> String {
    format!("{}_v{}_t{:02}.npy", t.texture.name(), t.speed_mm_s, t.trial)
}

/// Most trials per texture and speed a simulation accepts: 500 times the paper's 20, and
/// about 20 GB of recordings on its design; more is a typo (`design` would allocate the
/// trial list before anything ran).
pub const MAX_TRIALS: u32 = 10_000;

/// Longest nominal slide a simulation accepts, s: ten minutes, 33 times the paper's
/// slowest (90 mm at 5 mm/s, 18 s). Speed jitter may stretch a slide to twice this, which
/// keeps the recording under the readers' one-hour limit; a 4x4 grid's slide then holds at
/// most 1.2 million frames (150 MB of f64 per trial in memory).
pub const MAX_SLIDE_S: f64 = 600.0;

/// Checks a design before it is built: 1 to [`MAX_TRIALS`] trials, positive speeds whose
/// slide of `p.slide_mm` lasts at most [`MAX_SLIDE_S`], and no texture or speed given twice
/// (the two would write one file).
///
/// # Errors
/// The rule broken, naming `trials`, `speeds` or `textures`.
pub fn check_design(
    p: &RigParams,
    textures: &[Texture],
    speeds: &[f64],
    trials: u32,
) -> Result<(), ParamError> {
    if !(1..=MAX_TRIALS).contains(&trials) {
        return Err(ParamError::new(
            "trials",
            "trials must be between 1 and 10000",
            trials,
        ));
    }
    for (k, &speed) in speeds.iter().enumerate() {
        check_speed(p, speed)?;
        if speeds[..k].contains(&speed) {
            let rule = "each speed may be given once (one file per texture, speed and trial)";
            return Err(ParamError::new("speeds", rule, format!("{speed} twice")));
        }
    }
    for (k, texture) in textures.iter().enumerate() {
        if textures[..k].contains(texture) {
            let rule = "each texture may be given once (one file per texture, speed and trial)";
            let got = format!("{} twice", texture.name());
            return Err(ParamError::new("textures", rule, got));
        }
    }
    Ok(())
}

/// A speed is positive and slides `p.slide_mm` in at most [`MAX_SLIDE_S`].
fn check_speed(p: &RigParams, speed: f64) -> Result<(), ParamError> {
    if !(speed.is_finite() && speed > 0.0) {
        return Err(ParamError::new(
            "speeds",
            "sliding speeds must be positive mm/s",
            speed,
        ));
    }
    if p.slide_mm / speed > MAX_SLIDE_S {
        let rule = "a slide may last at most 600 s, so a speed must be at least slide_mm / 600 (0.15 mm/s for the rig's 90 mm)";
        return Err(ParamError::new("speeds", rule, format!("{speed} mm/s")));
    }
    Ok(())
}

/// The trials of a dataset: every texture x speed x trial, in that order (the paper's).
pub fn design(textures: &[Texture], speeds: &[f64], trials: u32) -> Vec<Trial> {
    let mut out = Vec::new();
    for &texture in textures {
        for &speed_mm_s in speeds {
            for trial in 0..trials {
                out.push(Trial {
                    texture,
                    speed_mm_s,
                    trial,
                });
            }
        }
    }
    out
}

/// Simulates `trials` in parallel and writes them as a dataset folder in the core format:
/// one `.npy` (f32 ADC counts, `(T, rows, cols)`, exact) per trial and `manifest.csv`
/// with `slide_start_s,slide_end_s`. Everything is written into a temporary folder beside
/// `dir`, renamed to `dir` only when complete; `on_done` is called once per trial.
///
/// # Errors
/// `dir` exists and is not empty, unphysical parameters, or a write failure.
pub fn write_dataset(
    dir: &std::path::Path,
    p: &RigParams,
    trials: &[Trial],
    seed: u64,
    on_done: &(dyn Fn() + Sync),
) -> crate::Result<()> {
    use crate::error::DataError;
    use rayon::prelude::*;
    p.check()?;
    let mut names = std::collections::BTreeSet::new();
    if let Some(t) = trials.iter().find(|t| !names.insert(trial_file_name(t))) {
        let rule = "each texture, speed and trial may be given once (one file each)";
        return Err(ParamError::new("trials", rule, trial_file_name(t)).into());
    }
    crate::recording::create_dataset_dir(dir, |tmp| {
        let metas: Vec<Meta> = trials
            .par_iter()
            .map(|t| -> crate::Result<Meta> {
                let rec = simulate_trial(p, t, seed)?;
                let array = ndarray::Array3::from_shape_vec(
                    (rec.len(), p.rows, p.cols),
                    rec.samples.iter().map(|&v| v as f32).collect(),
                )
                .map_err(|e| DataError::invalid(&rec.meta.file, e.to_string()))?;
                let path = tmp.join(&rec.meta.file);
                ndarray_npy::write_npy(&path, &array)
                    .map_err(|e| DataError::invalid(&path, e.to_string()))?;
                on_done();
                Ok(rec.meta)
            })
            .collect::<crate::Result<_>>()?;
        crate::recording::write_manifest(tmp, &metas)
    })
}
