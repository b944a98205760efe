//! Which taxels carry information: a taxel that never fires, or fires at the encoder's
//! ceiling, in most recordings scores its class-majority share whatever the texture, and
//! would drag a mean over taxels toward chance for reasons of the sensor, not the method.

use serde::{Deserialize, Serialize};

use super::ValidReproduceParams;
use crate::encode::encode;
use crate::error::Result;
use crate::pipeline::Encoded;
use crate::values::Grid;

/// A taxel-recording pair fires at the ceiling when its rate reaches this share of the
/// rate of a neuron driven by the largest input the normalisation allows.
pub const SATURATION_SHARE: f64 = 0.9;

/// One taxel's responses over the recordings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TaxelResponse {
    /// The taxel, `r{row}c{col}`.
    pub taxel: String,
    /// Share of recordings in which it never fired.
    pub silent_share: f64,
    /// Share of recordings in which it fired at the ceiling.
    pub saturated_share: f64,
}

impl TaxelResponse {
    /// Silent in most recordings.
    pub fn silent(&self) -> bool {
        self.silent_share > 0.5
    }

    /// At the ceiling in most recordings.
    pub fn saturated(&self) -> bool {
        self.saturated_share > 0.5
    }

    /// Neither silent nor saturated in most recordings.
    pub fn responsive(&self) -> bool {
        !self.silent() && !self.saturated()
    }
}

/// Every taxel's responses, and the ceiling they are judged against.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TaxelDiagnostics {
    /// The rate of a neuron driven by the normalised input 1 (the recording's maximum) for
    /// a whole second, at the pipeline's gain, Hz.
    pub ceiling_hz: f64,
    /// Per taxel, in grid order.
    pub taxels: Vec<TaxelResponse>,
}

impl TaxelDiagnostics {
    /// The taxels silent in most recordings.
    pub fn silent(&self) -> Vec<&str> {
        let silent = self.taxels.iter().filter(|t| t.silent());
        silent.map(|t| t.taxel.as_str()).collect()
    }

    /// The taxels at the ceiling in most recordings.
    pub fn saturated(&self) -> Vec<&str> {
        let saturated = self.taxels.iter().filter(|t| t.saturated());
        saturated.map(|t| t.taxel.as_str()).collect()
    }

    /// Whether taxel `name` (`r{row}c{col}`) responds; unknown names do not.
    pub fn responsive(&self, name: &str) -> bool {
        self.taxels
            .iter()
            .any(|t| t.taxel == name && t.responsive())
    }
}

/// The diagnostics of `encoded` (recordings on `grid`).
///
/// # Errors
/// None in practice: the encoder's parameters were checked with the run's.
pub fn taxel_diagnostics(
    encoded: &[Encoded],
    grid: &Grid,
    params: &ValidReproduceParams,
) -> Result<TaxelDiagnostics> {
    let ceiling_hz = ceiling_rate(params)?;
    let n = encoded.len().max(1) as f64;
    let taxels = grid
        .taxels()
        .map(|cell| {
            let (mut silent, mut saturated) = (0usize, 0usize);
            for e in encoded {
                let spikes = e.spikes.train(cell).len();
                let rate = spikes as f64 * 1000.0 / e.spikes.n_steps.max(1) as f64;
                silent += usize::from(spikes == 0);
                saturated += usize::from(rate >= SATURATION_SHARE * ceiling_hz);
            }
            TaxelResponse {
                taxel: grid.cell(cell).to_string(),
                silent_share: silent as f64 / n,
                saturated_share: saturated as f64 / n,
            }
        })
        .collect();
    Ok(TaxelDiagnostics { ceiling_hz, taxels })
}

/// Spikes per second of one neuron held at input 1 for two seconds, counted over the second
/// (after the onset transient).
fn ceiling_rate(params: &ValidReproduceParams) -> Result<f64> {
    let input = vec![1.0; 2000];
    let trains = encode(&input, 1, 1, &[true], params.pipeline.encoder)?;
    Ok(trains.train(0).iter().filter(|&&t| t >= 1000).count() as f64)
}

#[cfg(test)]
mod tests {
    use super::super::testing::small_run;
    use super::*;

    #[test]
    fn shares_by_hand_and_the_ceiling_is_a_regular_spiking_rate() {
        let run = small_run();
        let d = &run.prepared.taxels;
        assert_eq!(d.taxels.len(), 16);
        // RS neurons at I = 8 fire regularly, tens of Hz (Izhikevich 2003, figure 2)
        assert!((10.0..200.0).contains(&d.ceiling_hz), "{}", d.ceiling_hz);
        let first = &run.prepared.encoded;
        let silent_r0c0 = first
            .iter()
            .filter(|e| e.spikes.train(0).is_empty())
            .count();
        let share = silent_r0c0 as f64 / first.len() as f64;
        assert_eq!(d.taxels[0].silent_share, share);
        let fake = TaxelDiagnostics {
            ceiling_hz: 50.0,
            taxels: vec![
                TaxelResponse {
                    taxel: "r0c0".into(),
                    silent_share: 0.75,
                    saturated_share: 0.0,
                },
                TaxelResponse {
                    taxel: "r0c1".into(),
                    silent_share: 0.0,
                    saturated_share: 0.5,
                },
            ],
        };
        assert_eq!(fake.silent(), ["r0c0"]);
        assert!(fake.saturated().is_empty());
        assert!(!fake.responsive("r0c0") && fake.responsive("r0c1"));
    }
}
