//! neurotex's analyses: every experiment of the paper and the extensions (E0-E9), run on
//! a dataset into one [`experiments::Results`]. Depends on every layer below.
#![deny(missing_docs)]

pub mod experiments;

// The layers below, under the names their modules had when they were one crate, so
// that `crate::recording` and the like read the same in every layer.
use neurotex_core::{error, progress, recording, values, Error, Result};
use neurotex_features::features;
use neurotex_learn::{classify, snn};
#[cfg(test)]
use neurotex_pipeline::model;
use neurotex_pipeline::{analysis, calibrate, causal, compare, diagnostics, inspect, pipeline};
use neurotex_signal::{encode, signal};
use neurotex_sim::sim;
