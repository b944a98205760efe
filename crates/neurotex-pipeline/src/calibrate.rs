//! `--gain auto`: the encoder's gain G chosen per dataset, from training recordings only,
//! so that the median taxel fires at a target rate during the slide.
//!
//! The paper chose G = 8 by eye from ISI histograms over G = 5..20 (its E7), balancing two
//! failures: too high a gain drives every taxel towards the neuron's ceiling, where the
//! texture's modulation is lost; too low a gain leaves taxels silent. G = 8 suits the
//! paper's sensor and normalisation; another sensor's signals (a few taxels carrying most
//! of the signal, a long slow slide, a noisy baseline) give other rates at the same G: at
//! G = 8, 58 % of FabricSlide's taxel x recording pairs never spike. This module makes the
//! paper's criterion explicit and automatic: the G (to 3 significant digits) at which the
//! median, over every (taxel, recording) pair that receives any signal, of the firing rate
//! over the encoded phase reaches `target_hz`, while one unit less in the third digit does
//! not.
//!
//! Pairs whose conditioned input is zero throughout (an unconnected taxel, a cell the
//! baseline removal flattened) are left out: no gain makes them fire. The rate of one pair
//! grows with G up to one-spike wobbles (the neuron adapts), so the median does too and a
//! bisection on log G finds the crossing, refined on the 3-digit grid. Labels are never
//! read.
//!
//! The default target, 20 Hz, is a choice, not a fit to accuracy: it leaves the median taxel
//! about four spikes per 200 ms rate-volume bin, far below the regular-spiking neuron's
//! ceiling of several hundred Hz, so both the texture's slow modulations and the sparse
//! taxels stay visible.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::causal::{calibrate_conditioning, ConditioningCalibration};
use crate::encode::encode;
use crate::error::{ParamError, Result};
pub use crate::model::GainCalibration;
use crate::pipeline::{Pipeline, PipelineParams};
use crate::recording::{Baseline, Recording};
use crate::signal::Conditioned;

/// The default target rate of `--gain auto`, Hz.
pub const DEFAULT_TARGET_HZ: f64 = 20.0;

/// At most this many training recordings (evenly spread over them) are used: the median
/// of thousands of pairs is settled long before, and they are held in memory together.
pub const MAX_CALIBRATION_RECORDINGS: usize = 32;

/// The range of gains searched (the encoder's own limits are (0, 10000]).
const GAIN_RANGE: (f64, f64) = (0.01, 1e4);

/// How the encoder's gain is set.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GainChoice {
    /// This gain.
    Fixed(f64),
    /// Calibrated on training recordings to this median firing rate, Hz.
    Auto {
        /// The target median rate.
        target_hz: f64,
    },
}

impl Default for GainChoice {
    /// The encoder's default gain, the paper's.
    fn default() -> Self {
        GainChoice::Fixed(crate::encode::IzhikevichParams::default().gain)
    }
}

impl GainChoice {
    /// The target rate of `auto`, or `None` for a gain given as a number.
    pub fn target_hz(self) -> Option<f64> {
        match self {
            GainChoice::Auto { target_hz } => Some(target_hz),
            GainChoice::Fixed(_) => None,
        }
    }
}

impl std::fmt::Display for GainChoice {
    /// As it is typed: `8`, `auto:20`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            GainChoice::Fixed(g) => write!(f, "{g}"),
            GainChoice::Auto { target_hz } => write!(f, "auto:{target_hz}"),
        }
    }
}

impl std::str::FromStr for GainChoice {
    type Err = String;

    /// `auto` (the default target), `auto:HZ`, or a number.
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        let auto = |target_hz: f64| {
            if target_hz.is_finite() && target_hz > 0.0 && target_hz <= 1000.0 {
                Ok(GainChoice::Auto { target_hz })
            } else {
                Err(format!(
                    "auto:HZ needs a target rate in (0, 1000] Hz, got {target_hz}"
                ))
            }
        };
        match s.trim() {
            "auto" => auto(DEFAULT_TARGET_HZ),
            t => match t.strip_prefix("auto:") {
                Some(hz) => auto(
                    hz.parse()
                        .map_err(|_| format!("auto:HZ: `{hz}` is not a number"))?,
                ),
                None => t
                    .parse()
                    .map(GainChoice::Fixed)
                    .map_err(|_| format!("expected a number, `auto` or `auto:HZ`, got `{t}`")),
            },
        }
    }
}

/// One training recording, conditioned, with the cells that receive any signal.
struct Sample {
    cond: Conditioned,
    rows: usize,
    cols: usize,
    present: Vec<bool>,
    /// Present cells whose input is not zero throughout.
    driven: Vec<usize>,
}

/// A pipeline's parameters calibrated on training recordings, with what was calibrated.
#[derive(Debug, Clone, PartialEq)]
pub struct CalibratedParams {
    /// The parameters, with the causal conditioning and the gain filled in.
    pub params: PipelineParams,
    /// What [`GainChoice::Auto`] chose.
    pub gain: Option<GainCalibration>,
    /// What the causal conditioning fixed.
    pub causal: Option<ConditioningCalibration>,
}

/// `params` calibrated on the recordings `indices` (read by `load`; labels never read):
/// with `causal`, each taxel's resting value and one scale fixed on them
/// ([`calibrate_conditioning`]); with [`GainChoice::Auto`], the gain calibrated on them
/// too, on the causally conditioned signal when both are asked for. The command line and
/// the Python package both calibrate here, so the same recordings give the same pipeline.
///
/// # Errors
/// No recording, one that cannot be read or conditioned, or no signal to calibrate on.
pub fn calibrate_pipeline(
    mut params: PipelineParams,
    causal: bool,
    gain: GainChoice,
    load: &(dyn Fn(usize) -> Result<Recording> + Sync),
    indices: &[usize],
    baseline: Baseline,
) -> Result<CalibratedParams> {
    let causal = match causal {
        true => {
            let c = calibrate_conditioning(&params, load, indices, baseline)?;
            params.preprocess.causal = Some(c.conditioning.clone());
            Some(c)
        }
        false => None,
    };
    let gain = match gain {
        GainChoice::Auto { target_hz } => {
            let pipeline = Pipeline::new(params.clone())?;
            let c = calibrate_gain(&pipeline, load, indices, baseline, target_hz)?;
            params.encoder.gain = c.gain;
            Some(c)
        }
        GainChoice::Fixed(_) => None,
    };
    Ok(CalibratedParams {
        params,
        gain,
        causal,
    })
}

/// Chooses the gain on the recordings `indices` (loaded by `load`, conditioned by
/// `pipeline`, whose own gain is ignored); see the module documentation.
///
/// # Errors
/// No recording, a recording that cannot be loaded or conditioned, or no taxel with any
/// signal in any of them.
pub fn calibrate_gain(
    pipeline: &Pipeline,
    load: &(dyn Fn(usize) -> Result<Recording> + Sync),
    indices: &[usize],
    baseline: Baseline,
    target_hz: f64,
) -> Result<GainCalibration> {
    let used = spread(indices, MAX_CALIBRATION_RECORDINGS);
    let samples: Vec<Sample> = used
        .par_iter()
        .map(|&i| sample(pipeline, &load(i)?, baseline))
        .collect::<Result<_>>()?;
    let pairs: usize = samples.iter().map(|s| s.driven.len()).sum();
    if pairs == 0 {
        let rule = "--gain auto needs a taxel with some signal in the training recordings";
        return Err(ParamError::new("gain", rule, "every taxel is flat").into());
    }
    // Each gain's median is computed once: the search ends on a gain it has tried.
    let tried: std::cell::RefCell<Vec<(f64, f64)>> = std::cell::RefCell::new(Vec::new());
    let median = |gain: f64| -> Result<f64> {
        let known = tried.borrow().iter().find(|t| t.0 == gain).map(|t| t.1);
        if let Some(m) = known {
            return Ok(m);
        }
        let m = median_rate(pipeline, &samples, gain)?;
        tried.borrow_mut().push((gain, m));
        Ok(m)
    };
    let (lo, hi) = GAIN_RANGE;
    let (gain, clamped) = if median(hi)? < target_hz {
        (hi, true)
    } else if median(lo)? >= target_hz {
        (lo, true)
    } else {
        (bisect(&median, target_hz)?, false)
    };
    Ok(GainCalibration {
        target_hz,
        gain,
        median_hz: median(gain)?,
        recordings: samples.len(),
        pairs,
        clamped,
    })
}

/// A gain of 3 significant digits whose median reaches `target` while the next smaller one
/// does not; `median` is below the target at the range's low end and reaches it at the
/// high end.
fn bisect(median: &dyn Fn(f64) -> Result<f64>, target: f64) -> Result<f64> {
    let (mut lo, mut hi) = (GAIN_RANGE.0.ln(), GAIN_RANGE.1.ln());
    // The bracket narrows to a relative width of 1e-4, below the 3-digit rounding.
    while hi - lo > 1e-4 {
        let mid = 0.5 * (lo + hi);
        if median(mid.exp())? >= target {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    // A neuron's spike count over a finite slide can wobble by one spike as the gain grows
    // (adaptation), so the median is monotone only up to such wobbles: step up until the
    // rounded gain reaches the target, then down while a smaller 3-digit gain does too.
    // (A few steps at most: the bracket is far narrower than one step.)
    let mut gain = round_up_3(hi.exp());
    for _ in 0..20 {
        if median(gain)? >= target {
            break;
        }
        gain = step_up_3(gain);
    }
    for _ in 0..10 {
        let lower = step_down_3(gain);
        if lower < GAIN_RANGE.0 || median(lower)? < target {
            break;
        }
        gain = lower;
    }
    Ok(gain.min(GAIN_RANGE.1))
}

/// `x` rounded up to 3 significant digits.
fn round_up_3(x: f64) -> f64 {
    let scale = 10f64.powi(2 - x.log10().floor() as i32);
    (x * scale).ceil() / scale
}

/// The next larger 3-significant-digit number above `x` (itself 3-digit).
fn step_up_3(x: f64) -> f64 {
    let scale = 10f64.powi(2 - x.log10().floor() as i32);
    ((x * scale).round() + 1.0) / scale
}

/// The next smaller 3-significant-digit number below `x` (itself 3-digit).
fn step_down_3(x: f64) -> f64 {
    let scale = 10f64.powi(2 - x.log10().floor() as i32);
    let digits = (x * scale).round();
    if digits <= 100.0 {
        (999.0 / scale) / 10.0
    } else {
        (digits - 1.0) / scale
    }
}

/// Up to `max` of `indices`, evenly spread and in order.
fn spread(indices: &[usize], max: usize) -> Vec<usize> {
    if indices.len() <= max {
        return indices.to_vec();
    }
    (0..max).map(|k| indices[k * indices.len() / max]).collect()
}

fn sample(pipeline: &Pipeline, rec: &Recording, baseline: Baseline) -> Result<Sample> {
    let cond = pipeline.condition(rec, baseline)?;
    let layout = &rec.layout;
    let cells = layout.cells();
    let driven = (0..cells)
        .filter(|&c| layout.present[c])
        .filter(|&c| {
            cond.samples
                .iter()
                .skip(c)
                .step_by(cells)
                .any(|&x| x != 0.0)
        })
        .collect();
    Ok(Sample {
        rows: layout.rows,
        cols: layout.cols,
        present: layout.present.clone(),
        driven,
        cond,
    })
}

/// The median firing rate (Hz) over every driven (taxel, recording) pair at `gain`.
fn median_rate(pipeline: &Pipeline, samples: &[Sample], gain: f64) -> Result<f64> {
    let params = pipeline.params().encoder.with_gain(gain);
    let per: Vec<Vec<f64>> = samples
        .par_iter()
        .map(|s| {
            let spikes = encode(&s.cond.samples, s.rows, s.cols, &s.present, params)?;
            let seconds = s.cond.n_steps() as f64 / 1000.0;
            Ok(s.driven
                .iter()
                .map(|&c| spikes.train(c).len() as f64 / seconds)
                .collect())
        })
        .collect::<std::result::Result<_, ParamError>>()?;
    let mut rates: Vec<f64> = per.into_iter().flatten().collect();
    rates.sort_by(f64::total_cmp);
    let n = rates.len();
    Ok(if n % 2 == 1 {
        rates[n / 2]
    } else {
        0.5 * (rates[n / 2 - 1] + rates[n / 2])
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_auto_targets_and_numbers() {
        assert_eq!("8".parse(), Ok(GainChoice::Fixed(8.0)));
        assert_eq!(
            "auto".parse(),
            Ok(GainChoice::Auto {
                target_hz: DEFAULT_TARGET_HZ
            })
        );
        assert_eq!("auto:35".parse(), Ok(GainChoice::Auto { target_hz: 35.0 }));
        for bad in ["auto:0", "auto:-3", "auto:x", "eight", "auto:1e9"] {
            assert!(bad.parse::<GainChoice>().is_err(), "{bad}");
        }
    }

    #[test]
    fn three_digit_rounding() {
        assert_eq!(round_up_3(8.0012), 8.01);
        assert_eq!(round_up_3(123.01), 124.0);
        assert_eq!(step_down_3(8.01), 8.0);
        assert_eq!(step_down_3(1.0), 0.999);
        assert_eq!(step_up_3(9.99), 10.0);
        assert_eq!(step_up_3(13.6), 13.7);
        assert_eq!(spread(&[0, 1, 2, 3], 2), vec![0, 2]);
    }
}
