//! The stages joined: a recording becomes spike trains, spike trains become a feature row.
//! Every stage is planned once (filter, GLCM offsets) and applied to many recordings,
//! in parallel across recordings.

use crate::encode::SpikeTrains;
use crate::error::{DataError, Result};
use crate::recording::{one_grid, Meta};
use crate::values::Grid;

mod encode;
mod extract;
mod params;

pub use encode::{events_encoded, Pipeline};
pub use extract::{FeatureExtractor, Quantised};
pub use params::{Encoding, FeatureParams, HaralickSet, Method, PipelineParams};

/// The taxel grid every encoded recording shares (size and mask).
///
/// # Errors
/// Recordings on different grids, the first that differs named; no recording.
pub fn shared_grid(encoded: &[Encoded]) -> Result<Grid> {
    let grids = encoded
        .iter()
        .map(|e| {
            let s = &e.spikes;
            Ok((
                e.meta.file.as_str(),
                Grid::masked(s.rows, s.cols, s.present.clone())?,
            ))
        })
        .collect::<Result<Vec<_>>>()?;
    one_grid(grids)
}

/// One recording's spikes with what the conditioning noticed.
#[derive(Debug, Clone, PartialEq)]
pub struct Encoded {
    /// The recording's manifest fields.
    pub meta: Meta,
    /// The first population's spike trains over the selected phase: SA for the `sa` and
    /// `sa+fa` encodings, FA for `fa`.
    pub spikes: SpikeTrains,
    /// The FA population of an `sa+fa` encoding; `None` for a single population.
    pub fa: Option<SpikeTrains>,
    /// The input was resampled to 1 kHz.
    pub resampled: bool,
    /// The recording had no positive signal and was left at zero.
    pub flat: bool,
    /// Every channel of the recording held one value from start to end: no signal, and
    /// spikes that are the encoder's answer to a constant input.
    pub constant: bool,
    /// The spikes are a sensor's address events, not the encoder's.
    pub from_events: bool,
}

impl Encoded {
    /// What to say of a recording whose every channel held one value from start to end
    /// (and was not left at zero for want of positive signal, which is said of its own);
    /// `None` for any other.
    pub fn constant_warning(&self) -> Option<String> {
        (self.constant && !self.flat).then(|| {
            format!(
                "{}: every channel holds one value from start to end (no signal): its spikes, and the class it is given, are the encoder's answer to a constant input, whatever texture it was",
                self.meta.file
            )
        })
    }

    /// The populations in feature order: `spikes`, then `fa` when present.
    pub fn populations(&self) -> impl Iterator<Item = &SpikeTrains> {
        std::iter::once(&self.spikes).chain(self.fa.as_ref())
    }

    /// The same recording with every population transformed by `f` (truncation,
    /// permutation).
    pub fn map_spikes(&self, f: impl Fn(&SpikeTrains) -> SpikeTrains) -> Encoded {
        Encoded {
            spikes: f(&self.spikes),
            fa: self.fa.as_ref().map(&f),
            ..self.clone()
        }
    }
}

/// Why [`Method::AllTaxelsMm`] refuses a recording without a speed.
const NO_SPEED: &str =
    "the all-taxels-mm method needs the recording's sliding speed (manifest column speed_mm_s, nonzero)";

/// One population's [`Method::Spectrum`] column names on `grid`: `{cell}_f{lo}_{hi}` for
/// each taxel's band of frequencies `lo` to `hi - 1` cycles over the span.
pub fn spectrum_names(grid: &Grid, features: &FeatureParams) -> Vec<String> {
    let edges = features.spectrum().edges();
    grid.taxels()
        .flat_map(|cell| {
            let cell = grid.cell(cell);
            edges
                .windows(2)
                .map(move |w| format!("{cell}_f{}_{}", w[0], w[1]))
        })
        .collect()
}

/// The steps [`Method::Spectrum`] reads of a phase of `n_steps` at `speed_mm_s`: all of
/// them, or those of `travel_mm` of travel.
///
/// # Errors
/// Why the recording cannot give that span: no speed, or a slide shorter than the travel
/// or than one step per bin.
pub fn spectrum_span(
    n_steps: usize,
    speed_mm_s: Option<f64>,
    features: &FeatureParams,
) -> std::result::Result<usize, String> {
    let span = if features.travel_mm > 0.0 {
        let Some(speed) = speed_mm_s.filter(|s| s.is_finite() && *s != 0.0) else {
            return Err("the spectrum's --travel-mm needs the recording's sliding speed (manifest column speed_mm_s, nonzero); --travel-mm 0 uses the whole slide without it".into());
        };
        let steps = (features.travel_mm / speed.abs() * 1e3).round() as usize;
        // A slide's stamps span one sample less than its travel: up to 1 % short reads whole.
        if steps > n_steps + n_steps / 100 {
            return Err(format!(
                "its slide travels {:.2} mm ({n_steps} ms at {} mm/s), less than the spectrum's travel (--travel-mm {})",
                n_steps as f64 * 1e-3 * speed.abs(),
                speed.abs(),
                features.travel_mm
            ));
        }
        steps.min(n_steps)
    } else {
        n_steps
    };
    if span < features.spectrum_bins {
        return Err(format!(
            "the spectrum's span is {span} ms, fewer than its {} bins (--spectrum-bins)",
            features.spectrum_bins
        ));
    }
    Ok(span)
}

/// The error of trains shorter than one bin of `bin_ms`.
fn too_short(spikes: &SpikeTrains, bin_ms: usize) -> crate::Error {
    DataError::TooShort {
        n_ms: spikes.n_steps,
        bin_ms,
    }
    .into()
}

/// Row-major indices of the cells holding a taxel.
pub fn taxel_cells(present: &[bool]) -> impl Iterator<Item = usize> + '_ {
    present
        .iter()
        .enumerate()
        .filter(|(_, &p)| p)
        .map(|(i, _)| i)
}
