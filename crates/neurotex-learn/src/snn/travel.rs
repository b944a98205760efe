//! Time in units of travel: a network whose every step covers the same sliding distance,
//! whatever the speed of the slide.
//!
//! A texture slid at twice the speed passes the taxels in half the time: its pattern of
//! spikes is the same pattern, squeezed. A network stepping in ms sees two patterns and
//! must learn both, and a speed it never trained on shows it a third. Stepping in travel
//! instead, a recording slid at `v` mm/s is binned in steps of `dt_ms x V / |v|` ms, where
//! `V` is the network's reference speed: each step covers the travel `dt_ms` covers at
//! `V`, and the time constants, given in ms, hold at `V` (they too are travel, scaled).
//! Each event then weighs `dt / step` ([`crate::snn::SpikeInput::scale`]), so a step's
//! input is a rate per `dt_ms` at every speed: time is warped, the rates' scale kept.
//! The encoder's dynamics still run in ms, so the patterns are alike, not the same; the
//! measurements are in `docs/spiking-classifier.md`.
//!
//! With [`Travel::Median`] the reference is the median speed of the training recordings,
//! so a network trained at one speed steps in `dt_ms` exactly as one counting time in ms
//! does, bit for bit; only training on several speeds, and testing on others, differ.
//! It is not the default: measured, it moves held-out speeds within their intervals.

use serde::{Deserialize, Serialize};

use crate::error::ParamError;

/// How the network counts time.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Travel {
    /// In steps of `dt_ms` whatever the speed (the default).
    Off,
    /// In travel at the training recordings' median speed when every one of them has a
    /// nonzero speed; in ms otherwise.
    Median,
    /// In travel at this speed, mm/s; every recording needs its speed.
    At(f64),
}

impl Travel {
    /// [`Travel::Off`], the reading of model files written before the option existed.
    pub fn off() -> Travel {
        Travel::Off
    }

    /// Whether time is counted in ms.
    pub fn is_off(&self) -> bool {
        *self == Travel::Off
    }

    /// The option's text: `off`, `median` or the speed.
    pub fn name(&self) -> String {
        match self {
            Travel::Off => "off".into(),
            Travel::Median => "median".into(),
            Travel::At(v) => v.to_string(),
        }
    }

    /// The reference speed for training on recordings slid at `speeds` (mm/s, signed;
    /// `None` where a recording has none): `None` counts time in ms.
    ///
    /// # Errors
    /// [`Travel::At`] with a recording without a nonzero speed.
    pub fn reference(
        &self,
        speeds: impl Iterator<Item = Option<f64>>,
    ) -> Result<Option<f64>, ParamError> {
        let mut known: Vec<f64> = Vec::new();
        let mut missing = 0usize;
        for s in speeds {
            match s.map(f64::abs).filter(|v| *v > 0.0 && v.is_finite()) {
                Some(v) => known.push(v),
                None => missing += 1,
            }
        }
        match *self {
            Travel::Off => Ok(None),
            Travel::Median if missing > 0 || known.is_empty() => Ok(None),
            Travel::Median => {
                known.sort_unstable_by(f64::total_cmp);
                let n = known.len();
                Ok(Some(match n % 2 {
                    1 => known[n / 2],
                    _ => (known[n / 2 - 1] + known[n / 2]) / 2.0,
                }))
            }
            Travel::At(_) if missing > 0 => Err(ParamError::new(
                "snn-travel",
                "a network counting time in travel needs every recording's sliding speed (manifest column speed_mm_s, nonzero); --snn-travel median falls back to ms without them",
                format!("{missing} recording(s) without one"),
            )),
            Travel::At(v) => Ok(Some(v)),
        }
    }

    /// Checks a given speed.
    ///
    /// # Errors
    /// A speed that is not positive and finite.
    pub fn check(self) -> Result<Travel, ParamError> {
        match self {
            Travel::At(v) if !(v > 0.0 && v.is_finite()) => Err(ParamError::new(
                "snn-travel",
                "the reference speed must be positive and finite (mm/s)",
                v,
            )),
            other => Ok(other),
        }
    }
}

impl std::str::FromStr for Travel {
    type Err = ParamError;
    fn from_str(s: &str) -> Result<Self, ParamError> {
        match s {
            "off" => Ok(Travel::Off),
            "median" => Ok(Travel::Median),
            _ => s.parse::<f64>().map(Travel::At).map_err(|_| {
                let rule = "--snn-travel is `median`, `off` or a speed in mm/s";
                ParamError::new("snn-travel", rule, s)
            }),
        }
    }
}

/// The shortest and longest step of travel, ms: the encoder's 1 ms resolution, and the
/// longest `--snn-dt-ms`.
pub const STEP_RANGE_MS: (f64, f64) = (1.0, 1000.0);

/// What one input event weighs in a network step of `dt_ms` that lasts `step_ms`:
/// `dt_ms / step_ms`, so that a step of travel's input stays a rate per `dt_ms` at every
/// speed (1 in steps of `dt_ms`). Every path that bins a recording for a network weighs its
/// events so.
pub fn event_weight(dt_ms: u32, step_ms: f64) -> f64 {
    f64::from(dt_ms) / step_ms
}

/// How long, in ms, a network step of `dt_ms` lasts for a recording slid at `speed_mm_s`,
/// the network counting time in travel at `reference` mm/s (`None`: in ms, `dt_ms`).
///
/// # Errors
/// A reference without the recording's nonzero speed, or a step outside [`STEP_RANGE_MS`]
/// (a reference speed far from the recording's: given in m/s, say).
pub fn step_ms(dt_ms: u32, reference: Option<f64>, speed_mm_s: Option<f64>) -> Result<f64, String> {
    let dt = f64::from(dt_ms);
    let Some(reference) = reference else {
        return Ok(dt);
    };
    let (short, long) = STEP_RANGE_MS;
    match speed_mm_s.map(f64::abs).filter(|v| *v > 0.0 && v.is_finite()) {
        Some(v) if (short..=long).contains(&(dt * (reference / v))) => Ok(dt * (reference / v)),
        Some(v) => Err(format!(
            "in steps of travel at {reference} mm/s, a slide at {v} mm/s takes steps of {} ms, outside {short} to {long} ms (the encoder's 1 ms to the longest step): give a reference speed nearer the recordings' speeds, in mm/s, or another --snn-dt-ms",
            dt * (reference / v)
        )),
        None => Err(format!(
            "the network counts time in travel (each step the distance {dt_ms} ms cover at {reference} mm/s), and a recording without a nonzero sliding speed (manifest column speed_mm_s; raw files have none: import them into a dataset with their speeds) gives it no steps: give every recording its speed, or train the network with --snn-travel off"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_median_reference_is_the_middle_speed_and_needs_every_speed() {
        let speeds = [Some(-10.0), Some(5.0), Some(15.0), Some(15.0)];
        let median = Travel::Median.reference(speeds.into_iter()).unwrap();
        assert_eq!(median, Some(12.5));
        let some_missing = [Some(5.0), None];
        assert_eq!(
            Travel::Median.reference(some_missing.into_iter()).unwrap(),
            None
        );
        assert_eq!(Travel::Off.reference(speeds.into_iter()).unwrap(), None);
        assert!(Travel::At(20.0)
            .reference(some_missing.into_iter())
            .is_err());
        assert_eq!(
            Travel::At(20.0).reference(speeds.into_iter()).unwrap(),
            Some(20.0)
        );
    }

    /// A slide at twice the reference speed takes steps half as long; at the reference
    /// itself, exactly `dt_ms`.
    #[test]
    fn a_step_covers_the_same_travel_at_every_speed() {
        assert_eq!(step_ms(10, Some(12.5), Some(-25.0)).unwrap(), 5.0);
        assert_eq!(step_ms(10, Some(0.1), Some(0.1)).unwrap(), 10.0);
        assert_eq!(step_ms(10, None, None).unwrap(), 10.0);
        assert!(step_ms(10, Some(10.0), Some(0.0)).is_err());
        // A reference given in m/s (0.016 for 16 mm/s) asks for steps of a hundredth of a ms.
        let err = step_ms(10, Some(0.016), Some(16.0)).unwrap_err();
        assert!(err.contains("0.01 ms, outside 1 to 1000 ms"), "{err}");
        assert!(step_ms(10, Some(1e9), Some(16.0)).is_err());
        assert_eq!(step_ms(1, Some(10.0), Some(10.0)).unwrap(), 1.0);
        for text in ["off", "median", "42.5"] {
            assert_eq!(text.parse::<Travel>().unwrap().name(), text);
        }
        assert!("fast".parse::<Travel>().is_err());
        assert!(Travel::At(-1.0).check().is_err());
    }
}
