//! Single-taxel statistics (paper section II-F, approach 1): mean spike rate, coefficient
//! of variation of the inter-spike intervals and Fano factor of windowed counts.

/// The three single-taxel features.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpikeStats {
    /// Mean spike rate: spikes / duration, in Hz.
    pub msr: f64,
    /// Population std / mean of the inter-spike intervals; 0 with fewer than 2 intervals.
    pub cv_isi: f64,
    /// Population variance / mean of spike counts in consecutive windows (a last partial
    /// window dropped); 0 when the mean count is 0 or no whole window fits.
    pub fano: f64,
}

impl SpikeStats {
    /// The features as `[msr, cv_isi, fano]`.
    pub fn to_array(self) -> [f64; 3] {
        [self.msr, self.cv_isi, self.fano]
    }
}

/// Statistics of one train of spike times (ms steps) over `n_steps` steps of 1 ms, with
/// Fano windows of `window_ms` steps.
///
/// # Panics
/// If `n_steps` or `window_ms` is 0 (a caller bug; the pipeline checks both).
pub fn spike_stats(train: &[u32], n_steps: usize, window_ms: usize) -> SpikeStats {
    assert!(n_steps > 0 && window_ms > 0);
    let msr = train.len() as f64 / (n_steps as f64 * 1e-3);
    let cv_isi = if train.len() >= 3 {
        let isi = train.windows(2).map(|w| f64::from(w[1] - w[0]));
        let n = (train.len() - 1) as f64;
        let mean = isi.clone().sum::<f64>() / n;
        let var = isi.map(|x| (x - mean) * (x - mean)).sum::<f64>() / n;
        var.sqrt() / mean
    } else {
        0.0
    };
    let windows = n_steps / window_ms;
    let fano = if windows == 0 {
        0.0
    } else {
        let mut counts = vec![0u32; windows];
        for &t in train {
            let w = t as usize / window_ms;
            if w < windows {
                counts[w] += 1;
            }
        }
        let n = windows as f64;
        let mean = counts.iter().map(|&c| f64::from(c)).sum::<f64>() / n;
        if mean > 0.0 {
            let var = counts
                .iter()
                .map(|&c| (f64::from(c) - mean).powi(2))
                .sum::<f64>()
                / n;
            var / mean
        } else {
            0.0
        }
    };
    SpikeStats { msr, cv_isi, fano }
}

/// The Fano window in 1 ms steps that covers `window_mm` of travel at `speed_mm_s`
/// (rounded to the nearest step, at least one).
pub fn distance_window_ms(window_mm: f64, speed_mm_s: f64) -> usize {
    ((window_mm / speed_mm_s.abs() * 1e3).round() as usize).max(1)
}

/// Statistics of one train in units of travelled distance, for a slide at `speed_mm_s`
/// (its sign, the direction, is ignored): the rate in spikes per mm instead of per s,
/// CV_ISI unchanged (a ratio of times, the same in distance), and the Fano factor of
/// counts in windows of `window_mm` of travel ([`distance_window_ms`]). A texture of
/// spatial period P read at any speed gives the same spikes per mm and the same counts
/// per window when the neurons follow the signal; they do not exactly (the neuron has
/// its own time constants), so the invariance is approximate.
///
/// # Panics
/// If `n_steps` is 0, or `speed_mm_s` or `window_mm` is not positive and finite (a caller
/// bug; the pipeline checks both).
pub fn distance_stats(
    train: &[u32],
    n_steps: usize,
    speed_mm_s: f64,
    window_mm: f64,
) -> SpikeStats {
    let speed = speed_mm_s.abs();
    assert!(speed.is_finite() && speed > 0.0 && window_mm.is_finite() && window_mm > 0.0);
    let per_time = spike_stats(train, n_steps, distance_window_ms(window_mm, speed));
    SpikeStats {
        msr: per_time.msr / speed,
        ..per_time
    }
}
