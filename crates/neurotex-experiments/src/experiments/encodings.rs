//! The encoder's own sensitivity, made part of the headline accuracies. Spiking neurons
//! turn their input into threshold crossings: a neuron near its threshold fires one step
//! earlier or later, or once more or less, when the input moves by a rounding-level
//! amount, and those spikes move a recording's features and sometimes its prediction. So
//! the headline evaluations run on several encodings of every recording (as run, and with
//! independent perturbations far below any sensor's resolution), their accuracies are
//! averaged, and their intervals resample encodings as well as recordings.

use serde::{Deserialize, Serialize};

use super::{Context, Headline, Stop};
use crate::analysis::{seeded_bootstrap_over_encodings, Outcome};
use crate::classify::Interval;
use crate::error::ClassifyError;
use crate::values::BySpeed;

/// One method's accuracy at one speed over the encodings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OverEncodings {
    /// Each encoding's accuracy, the one as run first.
    pub per_encoding: Vec<f64>,
    /// The 95 % interval of the encoding as run, resampling recordings only.
    pub recordings_only: Interval,
    /// The mean over encodings (`estimate`) with its 95 % interval resampling recordings
    /// and encodings.
    pub combined: Interval,
}

impl OverEncodings {
    /// `outcomes[e]`, the method's evaluation on encoding `e` (as run first), summarised.
    ///
    /// # Errors
    /// No outcomes, or outcomes of different recordings.
    pub fn of(outcomes: &[&Outcome], seed: u64) -> crate::Result<Self> {
        let Some(first) = outcomes.first() else {
            let (first, second) = ("the run".to_string(), "its encodings".to_string());
            return Err(ClassifyError::Unpaired { first, second }.into());
        };
        let shares: Vec<Vec<f64>> = outcomes
            .iter()
            .map(|o| o.correct_shares.iter().map(|s| s.1).collect())
            .collect();
        Ok(OverEncodings {
            per_encoding: outcomes.iter().map(|o| o.accuracy).collect(),
            recordings_only: first.accuracy_interval(seed)?,
            combined: seeded_bootstrap_over_encodings(&shares, seed)?
                .or_wilson_at_the_bounds(first.correct_shares.len()),
        })
    }

    /// The mean accuracy over encodings (the one as run, to the bit, with one encoding).
    pub fn mean(&self) -> f64 {
        self.per_encoding.iter().sum::<f64>() / self.per_encoding.len().max(1) as f64
    }

    /// The lowest and highest accuracy of any encoding.
    pub fn range(&self) -> (f64, f64) {
        let lo = self
            .per_encoding
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        let hi = self
            .per_encoding
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max);
        (lo, hi)
    }
}

/// The headline accuracies at one speed over the encodings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EncodingsSpeed {
    /// 3D-GLCM.
    pub glcm3d: OverEncodings,
    /// Single taxel, mean over taxels.
    pub taxel_mean: OverEncodings,
    /// 2D-GLCM.
    pub glcm2d: OverEncodings,
    /// Recordings whose spike trains differ from the ones as run in some encoding.
    pub recordings_changed: usize,
    /// Recordings at this speed.
    pub recordings: usize,
}

/// The encoder's sensitivity at every speed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EncoderSensitivity {
    /// Encodings of each recording, the one as run included.
    pub encodings: usize,
    /// The largest relative change of an input sample in a perturbed encoding.
    pub perturbation: f64,
    /// Per speed.
    pub speeds: BySpeed<EncodingsSpeed>,
    /// The largest spread (highest minus lowest encoding) of any headline accuracy, in
    /// accuracy units (0..1).
    pub largest_spread: f64,
}

/// Each headline method's evaluations at one speed, one per encoding.
pub(crate) struct Methods<'a> {
    pub(crate) taxel: Vec<&'a Outcome>,
    pub(crate) glcm3d: Vec<&'a Outcome>,
    pub(crate) glcm2d: Vec<&'a Outcome>,
}

impl<'a> Methods<'a> {
    /// The evaluations of `encodings` (as [`super::Tables::encodings_at`] gives them).
    pub(crate) fn of(encodings: &[&'a Headline]) -> Self {
        Methods {
            taxel: encodings.iter().map(|h| &h.taxel).collect(),
            glcm3d: encodings.iter().map(|h| &h.glcm3d).collect(),
            glcm2d: encodings.iter().map(|h| &h.glcm2d).collect(),
        }
    }
}

/// The encoder's sensitivity, when the run has more than one encoding (`None` otherwise).
///
/// # Errors
/// Evaluations of different recordings.
pub fn encoder_sensitivity(c: &Context) -> Result<Option<EncoderSensitivity>, Stop> {
    let perturbed = &c.prepared.perturbed;
    if perturbed.is_empty() {
        return Ok(None);
    }
    let seed = c.params.seed;
    let mut speeds = BySpeed::new();
    let mut largest_spread: f64 = 0.0;
    for &speed in &c.prepared.speeds {
        let m = Methods::of(&c.tables.encodings_at(speed));
        let entry = EncodingsSpeed {
            glcm3d: OverEncodings::of(&m.glcm3d, seed)?,
            taxel_mean: OverEncodings::of(&m.taxel, seed)?,
            glcm2d: OverEncodings::of(&m.glcm2d, seed)?,
            recordings_changed: (0..c.prepared.encoded.len())
                .filter(|&i| c.prepared.encoded[i].meta.speed() == Some(speed))
                .filter(|&i| {
                    let spikes = &c.prepared.encoded[i].spikes;
                    perturbed.iter().any(|p| p[i].spikes != *spikes)
                })
                .count(),
            recordings: c.prepared.at(speed).count(),
        };
        for a in [&entry.glcm3d, &entry.taxel_mean, &entry.glcm2d] {
            let (lo, hi) = a.range();
            largest_spread = largest_spread.max(hi - lo);
        }
        speeds.insert(speed, entry);
    }
    Ok(Some(EncoderSensitivity {
        encodings: perturbed.len() + 1,
        perturbation: c.params.perturbation,
        speeds,
        largest_spread,
    }))
}

#[cfg(test)]
mod tests {
    use super::super::testing::small_run;
    use super::*;

    #[test]
    fn every_speed_summarised_over_every_encoding() {
        let run = small_run();
        let c = run.context();
        let s = encoder_sensitivity(&c)
            .unwrap()
            .expect("more than one encoding");
        assert_eq!(s.encodings, run.params.encoder_draws);
        assert_eq!(s.speeds.len(), 2);
        let mut largest: f64 = 0.0;
        for (speed, e) in s.speeds.iter() {
            assert_eq!(e.recordings, 24);
            assert!(e.recordings_changed <= e.recordings);
            let g = &e.glcm3d;
            assert_eq!(g.per_encoding.len(), s.encodings);
            assert_eq!(g.per_encoding[0], c.tables.at(speed).glcm3d.accuracy);
            let mean = g.per_encoding.iter().sum::<f64>() / s.encodings as f64;
            assert!((g.combined.estimate - mean).abs() < 1e-12);
            assert!(g.combined.lower <= g.combined.estimate);
            assert!(g.combined.estimate <= g.combined.upper);
            for a in [&e.glcm3d, &e.taxel_mean, &e.glcm2d] {
                largest = largest.max(a.range().1 - a.range().0);
            }
        }
        assert_eq!(s.largest_spread, largest);
    }
}
