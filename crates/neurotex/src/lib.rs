//! neurotex: neuromorphic tactile texture classification.
//!
//! Taxel-array recordings become spikes of Izhikevich neurons, spikes become single-taxel
//! statistics or 2D/3D gray-level co-occurrence features, and a KNN classifier scores them,
//! as in Gupta, Nakagawa, Lepora and Thakor, "Spatio-temporal encoding improves
//! neuromorphic tactile texture classification". Data flows down the modules:
//! [`recording`] → [`signal`] → [`encode`] → [`features`] → [`classify`], joined by
//! [`pipeline`] and [`analysis`] (with [`diagnostics`] of the taxels); [`model`] saves a trained classifier and applies it to
//! new recordings.
//!
//! The library never prints and never exits: it returns [`Error`]s naming the file, line
//! or parameter at fault.
#![deny(missing_docs)]

pub mod analysis;
pub mod calibrate;
pub mod causal;
pub mod classify;
pub mod compare;
pub mod csvlog;
pub mod diagnostics;
pub mod encode;
pub mod error;
pub mod experiments;
pub mod features;
pub mod import;
pub mod io;
pub mod model;
mod npy;
pub mod pipeline;
pub mod recording;
pub mod report;
pub mod signal;
pub mod sim;
mod simd;
pub mod stream;
pub mod values;

pub use error::{Error, Result};
pub use values::{BySpeed, Cell, Grid, SampleRate, Speed};
