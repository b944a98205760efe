//! The rate volume (paper section II-F): mean spike rate of every taxel in consecutive
//! 200 ms bins, and its quantisation to gray levels.

use crate::encode::SpikeTrains;
use crate::error::ParamError;

/// Binning and quantisation parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct VolumeParams {
    /// Bin width in ms (the paper's 200).
    pub bin_ms: usize,
    /// Gray levels L (16, the default of the `cooc3d` tool whose other defaults the paper matches).
    pub levels: usize,
    /// A fixed quantisation range `(lo, hi)` in Hz; `None` uses each volume's own min and max.
    pub range: Option<(f64, f64)>,
}

impl Default for VolumeParams {
    fn default() -> Self {
        VolumeParams {
            bin_ms: 200,
            levels: 16,
            range: None,
        }
    }
}

impl VolumeParams {
    /// Checks the rules: bins of at least 1 ms, 2 to 256 gray levels, `lo < hi` finite.
    ///
    /// # Errors
    /// The rule broken.
    pub fn check(&self) -> Result<(), ParamError> {
        if self.bin_ms == 0 {
            return Err(ParamError::new(
                "bin-ms",
                "bin width must be at least 1 ms",
                self.bin_ms,
            ));
        }
        if !(2..=256).contains(&self.levels) {
            return Err(ParamError::new(
                "levels",
                "gray levels must be between 2 and 256",
                self.levels,
            ));
        }
        if let Some((lo, hi)) = self.range {
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return Err(ParamError::new(
                    "range",
                    "quantisation range must satisfy lo < hi",
                    format!("{lo}..{hi}"),
                ));
            }
        }
        Ok(())
    }
}

/// Rates in Hz, `rows x cols x bins`, stored cell-major (each cell's bins contiguous).
#[derive(Debug, Clone, PartialEq)]
pub struct RateVolume {
    /// Grid rows.
    pub rows: usize,
    /// Grid columns.
    pub cols: usize,
    /// Time bins.
    pub bins: usize,
    /// Which cells hold a taxel.
    pub present: Vec<bool>,
    /// `rows * cols * bins` rates, index `cell * bins + bin`.
    pub data: Vec<f64>,
}

impl RateVolume {
    /// Bins the trains into `bin_ms` bins; a last bin shorter than `bin_ms` is dropped.
    /// Returns `None` when not one whole bin fits.
    pub fn from_spikes(spikes: &SpikeTrains, bin_ms: usize) -> Option<Self> {
        let bins = spikes.n_steps / bin_ms.max(1);
        if bins == 0 {
            return None;
        }
        Some(Self::binned(spikes, bin_ms, bins))
    }

    /// One bin spanning the whole train (the time-collapsed image of the 2D-GLCM).
    /// Returns `None` for an empty train.
    pub fn collapsed(spikes: &SpikeTrains) -> Option<Self> {
        (spikes.n_steps > 0).then(|| Self::binned(spikes, spikes.n_steps, 1))
    }

    fn binned(spikes: &SpikeTrains, bin_ms: usize, bins: usize) -> Self {
        let cells = spikes.cells();
        let mut data = vec![0.0; cells * bins];
        let scale = 1000.0 / bin_ms as f64;
        for cell in 0..cells {
            let row = &mut data[cell * bins..(cell + 1) * bins];
            // Trains are sorted: walk the bin edges instead of dividing each spike time.
            let (mut b, mut edge) = (0usize, bin_ms as u64);
            for &t in spikes.train(cell) {
                while u64::from(t) >= edge {
                    b += 1;
                    edge += bin_ms as u64;
                }
                if b >= bins {
                    break;
                }
                row[b] += 1.0;
            }
            row.iter_mut().for_each(|x| *x *= scale);
        }
        RateVolume {
            rows: spikes.rows,
            cols: spikes.cols,
            bins,
            present: spikes.present.clone(),
            data,
        }
    }
}

/// Quantises the volume to `levels` gray levels (SPEC 3.9):
/// `min(L-1, floor((x - lo) / (hi - lo) * L))`, with `lo`, `hi` the present cells' own min
/// and max unless `range` fixes them (values outside it are clamped). A constant volume is
/// all level 0. Masked cells get level 0 and are never paired by the GLCM.
pub fn quantise(volume: &RateVolume, levels: usize, range: Option<(f64, f64)>, out: &mut Vec<u8>) {
    let bins = volume.bins;
    let (lo, hi) = range.unwrap_or_else(|| {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for (row, _) in volume
            .data
            .chunks_exact(bins)
            .zip(&volume.present)
            .filter(|(_, &p)| p)
        {
            for &x in row {
                lo = lo.min(x);
                hi = hi.max(x);
            }
        }
        (lo, hi)
    });
    out.clear();
    out.resize(volume.data.len(), 0);
    if hi.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater) {
        return;
    }
    // Exactly the formula's order of operations, so levels at bin edges agree with it.
    let (span, l) = (hi - lo, levels as f64);
    let top = (levels - 1) as f64;
    for ((q, x), p) in out
        .chunks_exact_mut(bins)
        .zip(volume.data.chunks_exact(bins))
        .zip(&volume.present)
    {
        if *p {
            for (q, &x) in q.iter_mut().zip(x) {
                // Clamped into [0, L-1] first, where truncation equals floor; written without
                // branches or a call to floor so the loop vectorises.
                let v = ((x - lo) / span * l).max(0.0).min(top);
                *q = v as i32 as u8;
            }
        }
    }
}
