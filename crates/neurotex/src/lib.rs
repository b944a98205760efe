//! neurotex: neuromorphic tactile texture classification.
//!
//! Taxel-array recordings become spikes of Izhikevich neurons, spikes become single-taxel
//! statistics or 2D/3D gray-level co-occurrence features, and a KNN classifier scores them,
//! as in Gupta, Nakagawa, Lepora and Thakor, "Spatio-temporal encoding improves
//! neuromorphic tactile texture classification".
//!
//! This crate gathers the layers, each a crate that depends only on those below it:
//!
//! | layer | crate | modules |
//! |---|---|---|
//! | values, errors, recordings, event files, readers, import, outputs, progress, words | `neurotex-core` | [`values`], [`error`], [`recording`], [`events`], [`csvlog`], [`import`], [`io`], [`progress`], [`words`] |
//! | conditioning and spike encoding | `neurotex-signal` | [`signal`], [`encode`] |
//! | spike statistics and GLCM features | `neurotex-features` | [`features`] |
//! | classifiers, the spiking network, cross-validation, statistics | `neurotex-learn` | [`classify`], [`snn`] |
//! | simulated recordings | `neurotex-sim` | [`sim`] |
//! | stage options, pipeline, feature tables and their evaluation, inspection, models, NIR, compare | `neurotex-pipeline` | [`pipeline`], [`options`], [`analysis`], [`diagnostics`], [`inspect`], [`calibrate`], [`causal`], [`model`], [`spiking_model`], [`nir`], [`saved`], [`compare`] |
//! | live streams: frames, events, the Lab Streaming Layer | `neurotex-stream` | [`stream`] |
//! | the paper's analyses | `neurotex-experiments` | [`experiments`] |
//! | report and figures | `neurotex-report` | [`report`] |
//! | the commands' options and workflows, shared by the command line and Python | `neurotex` | [`workflows`] |
//!
//! The library never prints and never exits: it returns [`Error`]s naming the file, line
//! or parameter at fault. `ARCHITECTURE.md` follows one recording through the layers.
#![deny(missing_docs)]

pub use neurotex_core::{csvlog, error, events, import, io, progress, recording, values, words};
pub use neurotex_core::{BySpeed, Cell, Error, Grid, Result, SampleRate, Speed};
pub use neurotex_experiments::experiments;
pub use neurotex_features::features;
pub use neurotex_learn::classify;
pub use neurotex_learn::snn;
pub use neurotex_pipeline::{
    analysis, calibrate, causal, compare, diagnostics, inspect, model, nir, options, pipeline,
    samples, saved, spiking_model,
};
pub use neurotex_report::report;
pub use neurotex_signal::{encode, signal};
pub use neurotex_sim::sim;
pub use neurotex_stream as stream;

pub mod workflows;

pub use workflows::datasets;
