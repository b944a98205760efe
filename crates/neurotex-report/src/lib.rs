//! neurotex's report: the analyses' results as a markdown report with tables and figures
//! (SVG and PNG), and the comparison of methods as markdown ([`report`]).
#![deny(missing_docs)]

pub mod report;

// The layers below, under the names their modules had when they were one crate, so
// that `crate::recording` and the like read the same in every layer.
use neurotex_core::{error, events, io, values};
use neurotex_experiments::experiments;
use neurotex_learn::classify;
use neurotex_pipeline::{causal, compare, inspect};
#[cfg(test)]
use neurotex_signal::signal;
