//! E7: the gain sweep. Firing rate and ISI distribution per texture at each gain, at the
//! slowest speed (paper section III-B, the choice of G = 8).

use serde::{Deserialize, Serialize};

use super::{Context, IsiSweep, Stop};
use crate::values::Speed;

/// E7: the gain sweep's ISI statistics at the slowest speed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct E7 {
    /// Speed, mm/s.
    pub speed: Speed,
    /// The histograms.
    pub sweep: IsiSweep,
    /// `gains x labels` mean firing rate per taxel, Hz.
    pub rate_hz: Vec<Vec<f64>>,
    /// `gains x labels` median ISI, ms (from the histogram, bin centre).
    pub median_isi_ms: Vec<Vec<Option<f64>>>,
}

/// E7 from the sweep accumulated while preparing.
///
/// # Errors
/// None of its own.
pub fn e7_gain_sweep(c: &Context) -> Result<E7, Stop> {
    let sweep = c.prepared.isi.clone();
    let rate_hz = sweep
        .spikes
        .iter()
        .zip(&sweep.taxel_seconds)
        .map(|(s, t)| {
            s.iter()
                .zip(t)
                .map(|(&s, &t)| if t > 0.0 { s as f64 / t } else { 0.0 })
                .collect()
        })
        .collect();
    let median_isi_ms = sweep
        .counts
        .iter()
        .map(|per_label| {
            per_label
                .iter()
                .map(|h| median_bin(h).map(|b| (b as f64 + 0.5) * f64::from(sweep.bin_ms)))
                .collect()
        })
        .collect();
    Ok(E7 {
        speed: c.prepared.slowest,
        sweep,
        rate_hz,
        median_isi_ms,
    })
}

/// The bin holding the median of a histogram's counts; `None` when it is empty.
fn median_bin(histogram: &[u64]) -> Option<usize> {
    let total: u64 = histogram.iter().sum();
    let mut acc = 0;
    histogram.iter().position(|&c| {
        acc += c;
        total > 0 && acc * 2 >= total
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_bin_by_hand() {
        assert_eq!(median_bin(&[0, 0, 0]), None);
        assert_eq!(median_bin(&[1, 1, 1]), Some(1));
        assert_eq!(median_bin(&[3, 0, 1, 2]), Some(0));
        assert_eq!(median_bin(&[2, 0, 1, 3]), Some(2));
    }
}
