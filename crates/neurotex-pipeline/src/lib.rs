//! neurotex's pipeline layer: one recording's path from samples to features
//! ([`pipeline`]), feature tables over a dataset ([`analysis`], [`diagnostics`]), saved
//! models ([`model`]), the gain calibration ([`calibrate`]), decisions from a window's
//! beginning ([`causal`]), and the ranking of methods
//! ([`compare`]). Depends on every layer below.
#![deny(missing_docs)]

pub mod analysis;
pub mod calibrate;
pub mod causal;
pub mod compare;
pub mod diagnostics;
pub mod inspect;
pub mod model;
pub mod options;
pub mod pipeline;
pub mod samples;
pub mod saved;
pub mod spiking_model;
mod table;

// The layers below, under the names their modules had when they were one crate, so
// that `crate::recording` and the like read the same in every layer.
use neurotex_core::{error, events, import, io, progress, recording, values, Error};
use neurotex_features::features;
use neurotex_learn::{classify, snn};
/// NIR graphs of the spiking network (the `neurotex-nir` crate).
pub use neurotex_nir as nir;
use neurotex_signal::{encode, signal};
