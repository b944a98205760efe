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

use serde::{Deserialize, Serialize};

use crate::error::ParamError;
use crate::recording::Meta;

mod contact;
pub mod texture;
mod trial;

pub use texture::{Texture, ALL_TEXTURES};
pub use trial::{simulate_trial, simulate_trial_traced};

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
