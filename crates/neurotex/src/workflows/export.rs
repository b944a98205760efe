//! `export`: a spiking model's network as a NIR graph for other simulators and
//! neuromorphic hardware, and the spike tensors its input node receives.
use ndarray::Array2;
use ndarray_npy::write_npy;
use std::path::Path;

use rayon::prelude::*;

use super::OnProgress;
use crate::error::DataError;
use crate::nir::Convention;
use crate::progress::Progress;
use crate::recording::Dataset;
use crate::spiking_model::{spike_input, SpikingModel};
use crate::Result;

/// Which importer the exported time constants are meant for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum NirConvention {
    /// Physical time: `dt` in the metadata, time constants in seconds (Norse, Rockpool,
    /// NIR's equations).
    #[default]
    Physical,
    /// snnTorch's importer, which steps every graph at dt = 0.1 ms: the time constants are
    /// scaled so that its decays per step are the network's.
    Snntorch,
}

impl From<NirConvention> for Convention {
    fn from(c: NirConvention) -> Self {
        match c {
            NirConvention::Physical => Convention::Physical,
            NirConvention::Snntorch => Convention::Snntorch,
        }
    }
}

/// Writes `model`'s network as a NIR graph to `out`, whole or not at all.
///
/// # Errors
/// The file cannot be written.
pub fn export_nir(model: &SpikingModel, out: &Path, convention: NirConvention) -> Result<()> {
    let bytes = model.to_nir(convention.into())?;
    crate::io::write_atomic(out, |w| w.write_all(&bytes))
}

/// Loads the spiking model at `path` (a model file or a NIR graph written by neurotex):
/// only a spiking network has a NIR graph and input tensors.
///
/// # Errors
/// What [`SpikingModel::load`] refuses: a feature model is named as such, a damaged file as
/// damaged.
pub fn load_spiking(path: &Path) -> Result<SpikingModel> {
    SpikingModel::load(path)
}

/// Writes, into the folder `out` (new, or an earlier export), every recording of `dataset` as the `(steps,
/// inputs)` float32 spike counts the network's input node receives (`<n>.npy`, row-major),
/// and `index.csv` (`file,label,array`). Returns the recordings written.
///
/// # Errors
/// A recording that cannot be read or encoded, or `out` holds files neurotex did not write
/// there (an earlier export is replaced).
pub fn export_inputs(
    model: &SpikingModel,
    dataset: &Dataset,
    out: &Path,
    on: OnProgress,
) -> Result<usize> {
    let all: Vec<usize> = (0..dataset.entries.len()).collect();
    on(Progress::Stage("encoding", all.len()));
    let encoded = model
        .pipeline()
        .encode_dataset(dataset, &all, &|| on(Progress::Tick))?;
    let dt = model.network().dt_ms;
    crate::io::replace_dir(out, |dir| {
        let names: Vec<String> = (0..encoded.len()).map(|i| format!("{i:05}.npy")).collect();
        encoded
            .par_iter()
            .zip(&names)
            .map(|(e, name)| {
                let input = spike_input(e, dt);
                let path = dir.join(name);
                let array = Array2::from_shape_vec((input.steps(), input.inputs), input.dense())
                    .expect("one count per step and input");
                write_npy(&path, &array)
                    .map_err(|err| DataError::write(&path, std::io::Error::other(err)).into())
            })
            .collect::<Result<Vec<()>>>()?;
        let index = dir.join("index.csv");
        let mut csv = String::from("file,label,array\n");
        for (e, name) in encoded.iter().zip(&names) {
            csv.push_str(&format!(
                "{},{},{name}\n",
                quote(&e.meta.file),
                quote(&e.meta.label)
            ));
        }
        std::fs::write(&index, csv).map_err(|err| DataError::write(&index, err))?;
        Ok(encoded.len())
    })
}

/// A CSV field, quoted when it holds a comma, a quote or a line break.
fn quote(field: &str) -> String {
    match field.contains([',', '"', '\n', '\r']) {
        true => format!("\"{}\"", field.replace('"', "\"\"")),
        false => field.to_string(),
    }
}
