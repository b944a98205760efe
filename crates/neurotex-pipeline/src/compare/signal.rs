//! Baselines without spikes: candidates computed from the same conditioned signal the
//! encoder receives (resampled to 1 kHz, baseline removed, low-pass filtered, divided by
//! the recording's maximum, over the selected phase), so that a comparison shows what
//! the spikes cost or gain against the signal itself, on the same folds.
//!
//! - `spectrum`: each taxel's signal averaged in the spectrum's equal bins of travel, the
//!   magnitudes of its Fourier transform in logarithmic bands of spatial frequency
//!   ([`crate::features::Spectrum::signal`]), the same transform and bands the spike
//!   method `spectrum` applies to spike counts. After the speed-normalised spectrum of
//!   Wang, Albini, Maiolino, Mastrogiovanni and Cannata (Front. Neurorobot. 16:808222,
//!   2022), who resample each taxel's signal to samples per millimetre over a fixed
//!   travel, take its FFT and reduce it by PCA for a nearest-class rule. Here the bands
//!   reduce the spectrum instead of PCA (fixed a priori, nothing fitted to a fold), and
//!   the classifiers are the comparison's.
//! - `signal-stats`: each taxel's moments, quantiles and turns per second
//!   ([`crate::features::signal_stats`]), a common hand-made baseline.

use std::sync::Arc;

use rayon::prelude::*;

use super::Candidate;
use crate::analysis::{evaluator, Columns, FeatureTable, MethodSamples};
use crate::classify::ClassifierChoice;
use crate::error::{DataError, Result};
use crate::features::{signal_stats, Spectrum, SIGNAL_STAT_NAMES};
use crate::pipeline::{
    spectrum_names, spectrum_span, taxel_cells, FeatureParams, Method, Pipeline,
};
use crate::recording::{Dataset, Meta, Recording};
use crate::signal::Conditioned;
use crate::values::Grid;

/// The encoding name of the baselines.
pub const NO_ENCODING: &str = "none";

/// The baseline methods, in the order they are listed.
pub const SIGNAL_METHODS: [&str; 2] = ["spectrum", "signal-stats"];

/// One recording's rows of both baselines.
#[derive(Debug, Clone, PartialEq)]
pub struct SignalRows {
    /// The recording's manifest fields.
    pub meta: Meta,
    /// Which cells of its grid hold a taxel.
    pub present: Vec<bool>,
    /// The `spectrum` row.
    pub spectrum: Vec<f64>,
    /// The `signal-stats` row.
    pub stats: Vec<f64>,
}

impl SignalRows {
    /// The rows of `rec`, conditioned into `cond`, with the spectrum of `features`.
    ///
    /// # Errors
    /// A slide that cannot give the spectrum's span (named, with the option).
    pub fn of(rec: &Recording, cond: &Conditioned, features: &FeatureParams) -> Result<Self> {
        let n = cond.n_steps();
        let span = spectrum_span(n, rec.meta.speed_mm_s, features)
            .map_err(|why| DataError::invalid(&rec.meta.file, format!("none / spectrum: {why}")))?;
        let spectrum = Spectrum::new(features.spectrum());
        let mut row = SignalRows {
            meta: rec.meta.clone(),
            present: rec.layout.present.clone(),
            spectrum: Vec::new(),
            stats: Vec::new(),
        };
        let mut x = Vec::with_capacity(n);
        for cell in taxel_cells(&rec.layout.present) {
            x.clear();
            x.extend((0..n).map(|t| cond.samples[t * cond.cells + cell]));
            spectrum.signal(&x[..span], &mut row.spectrum);
            row.stats.extend(signal_stats(&x));
        }
        Ok(row)
    }
}

/// The baseline rows of the dataset's recordings `indices`, conditioned by `pipeline`
/// (its encoder unused); `on_done` is called once per recording. For a comparison
/// without spike encodings; with them, [`Pipeline::encode_dataset_with`] makes the rows
/// in the encoding's pass.
///
/// # Errors
/// A recording that cannot be read or conditioned, or as [`SignalRows::of`].
pub fn signal_rows(
    dataset: &Dataset,
    pipeline: &Pipeline,
    indices: &[usize],
    on_done: &(dyn Fn() + Sync),
) -> Result<Vec<SignalRows>> {
    let baseline = dataset.layout.baseline.unwrap_or_default();
    indices
        .par_iter()
        .map(|&i| {
            let rec = dataset.load(i)?;
            let cond = pipeline.condition(&rec, baseline)?;
            let rows = SignalRows::of(&rec, &cond, &pipeline.params().features);
            on_done();
            rows
        })
        .collect()
}

/// The baseline candidates, both methods with each of `classifiers`, from the recordings'
/// `rows` on `grid`; `prepare_s` is each method's share of the time the rows took.
///
/// # Errors
/// A recording on another grid (named), or a classifier's broken parameter.
pub fn baseline_candidates(
    rows: &[SignalRows],
    grid: &Grid,
    features: &FeatureParams,
    classifiers: &[ClassifierChoice],
    prepare_s: f64,
) -> Result<Vec<Candidate>> {
    if let Some(r) = rows.iter().find(|r| r.present != grid.present()) {
        let why = "its taxel grid differs from the other recordings'";
        return Err(DataError::invalid(&r.meta.file, why).into());
    }
    let metas: Vec<Meta> = rows.iter().map(|r| r.meta.clone()).collect();
    let spectrum_names = spectrum_names(grid, features);
    let cells: Vec<String> = grid.taxels().map(|c| grid.cell(c).to_string()).collect();
    let stats_names = cells
        .iter()
        .flat_map(|c| SIGNAL_STAT_NAMES.map(|s| format!("{c}_{s}")))
        .collect();
    let table = |names: Vec<String>, pick: fn(&SignalRows) -> &Vec<f64>| FeatureTable {
        // The nearest spike method's; a comparison reads only the names and values.
        method: Method::Spectrum,
        grid: grid.clone(),
        names,
        metas: metas.clone(),
        values: rows.iter().flat_map(|r| pick(r).iter().copied()).collect(),
    };
    let tables = [
        Arc::new(table(spectrum_names, |r| &r.spectrum)),
        Arc::new(table(stats_names, |r| &r.stats)),
    ];
    let metas = Arc::new(metas);
    let mut out = Vec::new();
    for (method, table) in SIGNAL_METHODS.iter().zip(tables) {
        // The spiking network reads spikes: it has no baseline without them.
        let features = classifiers
            .iter()
            .filter(|c| !matches!(c, ClassifierChoice::Snn(_)));
        for &classifier in features {
            out.push(Candidate {
                encoding: NO_ENCODING.to_string(),
                method: method.to_string(),
                classifier: classifier.name().to_string(),
                metas: Arc::clone(&metas),
                evaluate: evaluator(
                    classifier,
                    MethodSamples::Table(Arc::clone(&table), Columns::All),
                )?,
                prepare_s,
            });
        }
    }
    Ok(out)
}
