//! The run's taxel diagnostics: [`crate::diagnostics`] at the run's encoder.

pub use crate::diagnostics::{TaxelDiagnostics, TaxelResponse, SATURATION_SHARE};

use super::ValidReproduceParams;
use crate::error::Result;
use crate::pipeline::Encoded;
use crate::values::Grid;

/// The diagnostics of `encoded` (recordings on `grid`) at the run's encoder.
///
/// # Errors
/// None in practice: the encoder's parameters were checked with the run's.
pub fn taxel_diagnostics(
    encoded: &[Encoded],
    grid: &Grid,
    params: &ValidReproduceParams,
) -> Result<TaxelDiagnostics> {
    crate::diagnostics::taxel_diagnostics(encoded, grid, params.pipeline.encoder)
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
