//! neurotex's signal layer: a recording's taxel signals conditioned on a 1 ms grid
//! ([`signal`]: resampling, baseline, low-pass, gain) and encoded into spikes by
//! Izhikevich neurons ([`encode`]). Depends on `neurotex-core` only.
#![deny(missing_docs)]

pub mod encode;
pub mod signal;

// The layers below, under the names their modules had when they were one crate, so
// that `crate::recording` and the like read the same in every layer.
use neurotex_core::{error, recording, simd, Error};
