//! The Izhikevich encoder (Izhikevich 2003, "Simple model of spiking neurons"; paper
//! section II-E): each taxel drives one neuron with input current `I = G * x`.
//!
//! The scheme is that of Izhikevich's reference code, in f64, one step per millisecond:
//! at the start of a step a neuron with `v >= 30` records a spike and resets
//! (`v = c`, `u = u + d`); then `v` advances in two 0.5 ms Euler half-steps and `u` by 1 ms
//! with the new `v` ([`Overshoot`] says which `v` at a spike's step). State persists
//! between calls, so a recording fed in chunks gives exactly the spikes of one call.

use serde::{Deserialize, Serialize};

use crate::error::ParamError;

mod drives;
mod fast_adapting;
mod kernel;

pub use drives::{encode, encode_banks, encode_drives, BankRows, Drive, MadeDrive};
pub use fast_adapting::{encode_fa, encode_sa_fa, rectified_rate, FaParams};
use kernel::run_fastest;

/// The spike threshold (mV) of the 2003 model.
pub const V_PEAK: f64 = 30.0;

/// Which membrane value the recovery variable `u` reads at the step a neuron crosses the
/// peak (docs/decisions/0031-overshoot-kept-by-default-capped-on-request.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Overshoot {
    /// `u += a (b v - u)` with `v` as the two half-steps left it, far above the peak at a
    /// spike: Izhikevich's reference code (2003), and the paper's encoder. The recovery
    /// after a spike then depends on how far `v` overshot, which makes spike timing
    /// sensitive to rounding-level changes of the input.
    #[default]
    Kept,
    /// `u += a (b min(v, 30) - u)`: the recovery reads the membrane capped at the peak,
    /// as in the continuous model, where a spike resets `v` on reaching 30 mV.
    Capped,
}

impl std::fmt::Display for Overshoot {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Overshoot::Kept => "kept",
            Overshoot::Capped => "capped",
        })
    }
}

impl std::str::FromStr for Overshoot {
    type Err = ParamError;

    /// `kept` or `capped`, in any case.
    fn from_str(text: &str) -> Result<Self, ParamError> {
        match text.trim().to_ascii_lowercase().as_str() {
            "kept" => Ok(Overshoot::Kept),
            "capped" => Ok(Overshoot::Capped),
            _ => Err(ParamError::new(
                "overshoot",
                "the overshoot is `kept` (Izhikevich's reference code) or `capped` (at the peak)",
                text,
            )),
        }
    }
}

/// Neuron parameters and input gain.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct IzhikevichParams {
    /// Recovery time scale `a`.
    pub a: f64,
    /// Recovery sensitivity `b`.
    pub b: f64,
    /// Reset potential `c` (mV).
    pub c: f64,
    /// Recovery jump after a spike `d`.
    pub d: f64,
    /// Gain `G` from normalised signal to input current (the paper's 8).
    pub gain: f64,
    /// The membrane value the recovery reads at a spike's step (absent from model files
    /// written before the choice existed: `kept`, the scheme they were made with).
    #[serde(default)]
    pub overshoot: Overshoot,
}

impl Default for IzhikevichParams {
    /// Regular spiking (slowly adapting type I) with the paper's gain G = 8.
    fn default() -> Self {
        Self::preset("RS").expect("RS is a preset")
    }
}

/// The firing types of Izhikevich (2003), figure 2, as `(name, a, b, c, d)`.
pub const PRESETS: [(&str, f64, f64, f64, f64); 7] = [
    ("RS", 0.02, 0.2, -65.0, 8.0),
    ("IB", 0.02, 0.2, -55.0, 4.0),
    ("CH", 0.02, 0.2, -50.0, 2.0),
    ("FS", 0.1, 0.2, -65.0, 2.0),
    ("LTS", 0.02, 0.25, -65.0, 2.0),
    ("TC", 0.02, 0.25, -65.0, 0.05),
    ("RZ", 0.1, 0.26, -65.0, 2.0),
];

/// A firing type of Izhikevich (2003), figure 2, in the order of [`PRESETS`]; parses from
/// its name in any case (`RS`, `fs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum FiringType {
    /// Regular spiking, the paper's slowly adapting type I.
    #[default]
    Rs,
    /// Intrinsically bursting.
    Ib,
    /// Chattering.
    Ch,
    /// Fast spiking.
    Fs,
    /// Low-threshold spiking.
    Lts,
    /// Thalamo-cortical.
    Tc,
    /// Resonator.
    Rz,
}

impl FiringType {
    /// Every firing type, in the order of [`PRESETS`].
    pub const ALL: [FiringType; 7] = [
        FiringType::Rs,
        FiringType::Ib,
        FiringType::Ch,
        FiringType::Fs,
        FiringType::Lts,
        FiringType::Tc,
        FiringType::Rz,
    ];

    /// The name in [`PRESETS`] (`RS`).
    pub fn name(self) -> &'static str {
        PRESETS[self as usize].0
    }

    /// The firing type whose `a`, `b`, `c` and `d` are exactly those of `params`, if any.
    pub fn of(params: &IzhikevichParams) -> Option<FiringType> {
        let abcd = (params.a, params.b, params.c, params.d);
        FiringType::ALL.into_iter().find(|t| {
            let (_, a, b, c, d) = PRESETS[*t as usize];
            (a, b, c, d) == abcd
        })
    }

    /// The neuron parameters of this type with gain 8.
    pub fn params(self) -> IzhikevichParams {
        let (_, a, b, c, d) = PRESETS[self as usize];
        IzhikevichParams {
            a,
            b,
            c,
            d,
            gain: 8.0,
            overshoot: Overshoot::Kept,
        }
    }
}

impl std::fmt::Display for FiringType {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for FiringType {
    type Err = ParamError;

    /// Parses a name of [`PRESETS`], in any case.
    fn from_str(text: &str) -> Result<Self, ParamError> {
        FiringType::ALL
            .into_iter()
            .find(|t| t.name().eq_ignore_ascii_case(text.trim()))
            .ok_or_else(|| {
                ParamError::new(
                    "preset",
                    "a firing type is one of RS, IB, CH, FS, LTS, TC, RZ",
                    text,
                )
            })
    }
}

impl IzhikevichParams {
    /// A named firing type from [`PRESETS`] with gain 8, or `None` for an unknown name.
    pub fn preset(name: &str) -> Option<Self> {
        name.parse().ok().map(FiringType::params)
    }

    /// Sets the gain.
    pub fn with_gain(mut self, gain: f64) -> Self {
        self.gain = gain;
        self
    }

    /// Sets the membrane value the recovery reads at a spike's step.
    pub fn with_overshoot(mut self, overshoot: Overshoot) -> Self {
        self.overshoot = overshoot;
        self
    }

    /// Checks the rules: `a` in (0, 1], `b` in [-1, 1], `c` in [-100, 30) mV, `d` in
    /// [-100, 100], gain in (0, 10000]. Izhikevich's firing types (2003, 2004) lie well
    /// inside (a 0.02-0.1, b -0.1-0.26, c -65 to -50, d -2 to 8); far outside, the 1 ms
    /// Euler step overflows to NaN, which never crosses the peak: the neuron would fall
    /// silent without an error.
    ///
    /// # Errors
    /// The rule broken.
    pub fn check(&self) -> Result<(), ParamError> {
        if !(self.gain.is_finite() && self.gain > 0.0 && self.gain <= 1e4) {
            return Err(ParamError::new(
                "gain",
                "gain must be a number in (0, 10000], or `auto` to choose one from the recordings",
                self.gain,
            ));
        }
        if !(self.a > 0.0 && self.a <= 1.0) {
            return Err(ParamError::new(
                "a",
                "recovery scale a must be in (0, 1]",
                self.a,
            ));
        }
        if !(-1.0..=1.0).contains(&self.b) {
            return Err(ParamError::new(
                "b",
                "recovery sensitivity b must be in [-1, 1]",
                self.b,
            ));
        }
        if !(self.c >= -100.0 && self.c < V_PEAK) {
            return Err(ParamError::new(
                "c",
                "reset potential c must be in [-100, 30) mV, below the 30 mV peak",
                self.c,
            ));
        }
        if !(-100.0..=100.0).contains(&self.d) {
            return Err(ParamError::new(
                "d",
                "recovery jump d must be in [-100, 100]",
                self.d,
            ));
        }
        Ok(())
    }
}

/// A bank of Izhikevich neurons whose state carries over between calls.
#[derive(Debug, Clone)]
pub struct Encoder {
    params: IzhikevichParams,
    /// Each neuron's input gain: the parameters' gain unless built by
    /// [`Encoder::with_gains`].
    gains: Vec<f64>,
    v: Vec<f64>,
    u: Vec<f64>,
    steps: u64,
}

impl Encoder {
    /// `n` neurons at rest (`v = c`, `u = b c`).
    ///
    /// # Errors
    /// A broken parameter rule.
    pub fn new(params: IzhikevichParams, n: usize) -> Result<Self, ParamError> {
        Encoder::with_gains(params, vec![params.gain; n])
    }

    /// One neuron at rest per gain, with that input gain and `params`' other parameters.
    ///
    /// # Errors
    /// A broken parameter rule, for `params` or with one of the gains.
    fn with_gains(params: IzhikevichParams, gains: Vec<f64>) -> Result<Self, ParamError> {
        params.check()?;
        for &g in &gains {
            params.with_gain(g).check()?;
        }
        let n = gains.len();
        Ok(Encoder {
            params,
            gains,
            v: vec![params.c; n],
            u: vec![params.b * params.c; n],
            steps: 0,
        })
    }

    /// Number of neurons.
    pub fn neurons(&self) -> usize {
        self.v.len()
    }

    /// Steps run so far (the time of the next step in ms).
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// Runs one step per frame of `input` (time-major, one value per neuron, normalised
    /// signal) and writes 1 into `raster` where a neuron spiked at that step, else 0.
    ///
    /// # Panics
    /// If `input` is not whole frames or `raster` is not its size (a caller bug).
    pub fn run(&mut self, input: &[f64], raster: &mut [u8]) {
        let n = self.v.len();
        assert!(
            n > 0 && input.len().is_multiple_of(n),
            "input must be whole frames"
        );
        assert_eq!(input.len(), raster.len(), "raster must match input");
        let bank = Bank {
            gains: &self.gains,
            v: &mut self.v,
            u: &mut self.u,
            input,
            raster,
        };
        run_fastest(&self.params, bank);
        self.steps += (input.len() / n) as u64;
    }

    /// Runs one step of the neurons `first..first + input.len()` only (one value each) and
    /// writes their spikes into `raster`: for callers that take a frame through all their
    /// stages a cache-sized part at a time. [`Encoder::steps`] counts [`Encoder::run`]'s
    /// frames only.
    ///
    /// # Panics
    /// If the part does not lie inside the bank or `raster` is not `input`'s size (a
    /// caller bug).
    pub fn run_part(&mut self, first: usize, input: &[f64], raster: &mut [u8]) {
        let cells = first..first + input.len();
        assert_eq!(input.len(), raster.len(), "raster must match input");
        let bank = Bank {
            gains: &self.gains[cells.clone()],
            v: &mut self.v[cells.clone()],
            u: &mut self.u[cells],
            input,
            raster,
        };
        run_fastest(&self.params, bank);
    }
}

pub use neurotex_core::spikes::SpikeTrains;

/// The part of a bank one kernel call runs: each neuron's gain and state, and the
/// time-major input and raster (one value per neuron per frame).
struct Bank<'a> {
    gains: &'a [f64],
    v: &'a mut [f64],
    u: &'a mut [f64],
    input: &'a [f64],
    raster: &'a mut [u8],
}

#[cfg(test)]
mod tests {
    use super::drives::block_steps;
    use super::*;

    /// A drive made as the banks ask for it: `signal` times `factor`.
    struct Scaled<'a> {
        signal: &'a [f64],
        cells: usize,
        factor: f64,
    }

    impl MadeDrive for Scaled<'_> {
        fn values(&self) -> usize {
            self.signal.len()
        }

        fn fill(&mut self, first: usize, mut rows: BankRows<'_>) {
            let signal = &self.signal[first * self.cells..][..rows.steps() * self.cells];
            for (row, x) in rows.rows().zip(signal.chunks_exact(self.cells)) {
                for (out, &x) in row.iter_mut().zip(x) {
                    *out = x * self.factor;
                }
            }
        }
    }

    /// Each preset's a, b, c and d name its firing type, whatever the gain; any other
    /// neuron has no name.
    #[test]
    fn a_neuron_is_named_by_its_firing_type_only_when_it_is_one() {
        for t in FiringType::ALL {
            assert_eq!(FiringType::of(&t.params().with_gain(3.0)), Some(t));
        }
        let rs = FiringType::Rs.params();
        assert_eq!(FiringType::of(&IzhikevichParams { d: 7.0, ..rs }), None);
        assert_eq!(FiringType::of(&IzhikevichParams { a: 0.021, ..rs }), None);
    }

    /// Many drives of every kind side by side on a grid whose banks straddle the vector
    /// registers (9 cells), over several blocks of steps and a part block: each bank's
    /// trains are those of its values encoded alone, whole.
    #[test]
    fn drives_side_by_side_give_each_drives_own_trains() {
        let (rows, cols, steps, banks) = (3, 3, 2_500, 13);
        let cells = rows * cols;
        let present: Vec<bool> = (0..cells).map(|c| c != 4).collect();
        let mut state = 0x2545_F491_4F6C_DD1Du64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let signals: Vec<Vec<f64>> = (0..banks)
            .map(|_| (0..cells * steps).map(|_| next()).collect())
            .collect();
        let gains: Vec<f64> = (0..banks).map(|b| 12.0 + 2.0 * b as f64).collect();
        let factors: Vec<f64> = (0..banks).map(|b| 1.0 + b as f64 / 7.0).collect();
        let mut made: Vec<Scaled> = (0..banks)
            .map(|b| Scaled {
                signal: &signals[b],
                cells,
                factor: factors[b],
            })
            .collect();
        let mut drives: Vec<Drive> = made
            .iter_mut()
            .enumerate()
            .map(|(b, made)| match b % 3 {
                0 => Drive::Signal(&signals[b]),
                1 => Drive::RectifiedRate(&signals[b]),
                _ => Drive::Made(made),
            })
            .collect();
        assert!(block_steps(cells * banks) < steps / 4, "several blocks");
        let p = IzhikevichParams::default();
        let together = encode_drives(&mut drives, &gains, rows, cols, &present, p).unwrap();
        assert_eq!(together.len(), banks);
        for (b, trains) in together.iter().enumerate() {
            let values: Vec<f64> = match b % 3 {
                0 => signals[b].clone(),
                1 => rectified_rate(&signals[b], cells),
                _ => signals[b].iter().map(|x| x * factors[b]).collect(),
            };
            let alone = encode(&values, rows, cols, &present, p.with_gain(gains[b])).unwrap();
            assert!(alone.total_spikes() > 100, "bank {b} nearly silent");
            assert_eq!(trains, &alone, "bank {b}");
        }
    }

    /// A slowly wandering drive and the same drive times `1 + u 1e-12` (`u` in [-1, 1)),
    /// each sample perturbed on its own: with the overshoot kept (Izhikevich's reference
    /// code) most spikes leave their step after the first departure; capped at the peak
    /// the trains stay the same.
    #[test]
    fn capping_the_overshoot_keeps_spikes_under_rounding_level_changes() {
        let (cells, steps) = (16, 18_000);
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        };
        let mut walk = vec![0.5; cells];
        let mut drive = Vec::with_capacity(cells * steps);
        for _ in 0..steps {
            for w in walk.iter_mut() {
                *w = (*w + 0.01 * next()).clamp(0.0, 1.0);
            }
            drive.extend_from_slice(&walk);
        }
        let perturbed: Vec<f64> = drive.iter().map(|x| x * (1.0 + next() * 1e-12)).collect();
        assert_ne!(drive, perturbed);
        let present = vec![true; cells];
        let same_step = |overshoot| {
            let p = IzhikevichParams::default().with_overshoot(overshoot);
            let a = encode(&drive, 4, 4, &present, p).unwrap();
            let b = encode(&perturbed, 4, 4, &present, p).unwrap();
            assert!(a.total_spikes() > 1000, "the drive makes spikes");
            let kept: usize = (0..cells)
                .map(|c| a.train(c).iter().filter(|t| b.train(c).contains(t)).count())
                .sum();
            kept as f64 / a.total_spikes() as f64
        };
        let kept = same_step(Overshoot::Kept);
        assert!(
            kept < 0.5,
            "kept overshoot: {kept} of the spikes at their step"
        );
        assert_eq!(same_step(Overshoot::Capped), 1.0);
    }
}
