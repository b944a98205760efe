//! neurotex's bottom layer: the values every stage speaks in ([`values`]), the errors
//! ([`error`]), recordings, datasets and their readers ([`recording`], [`csvlog`]), the
//! import of raw logs into a dataset ([`import`]), outputs written whole or not at all
//! ([`io`]), the model file format's marks ([`model_format`]) and parser messages in a
//! user's words ([`words`]). Nothing here knows of spikes, features or classifiers.
#![deny(missing_docs)]

pub mod csvlog;
pub mod error;
pub mod events;
pub mod import;
pub mod io;
pub mod model_format;
mod npy;
pub mod progress;
pub mod recording;
#[doc(hidden)]
pub mod simd;
pub mod spikes;
pub mod values;
pub mod words;

pub use error::{Error, Result};
pub use values::{BySpeed, Cell, Grid, SampleRate, Speed, FS_RANGE, FS_RULE};
