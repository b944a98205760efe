//! Simulating one trial: its random streams, the protocol's schedule of phases, the taxels'
//! piezoresistive response read by the ADC, and the recording it makes.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use rand_xoshiro::Xoshiro256PlusPlus;

use crate::error::ParamError;
use crate::recording::{Layout, Meta, Phase, Recording};

use super::contact::{build_profiles, solve_contact};
use super::texture::{hash3, Texture, ALL_TEXTURES};
use super::{check_speed, trial_file_name, RigParams, Trial};

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
