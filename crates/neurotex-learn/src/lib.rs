//! neurotex's learning layer: classifiers (KNN, random forest, logistic regression,
//! spike distances), cross-validation, metrics, and the statistics of intervals and paired
//! tests ([`classify`]); the spiking network ([`snn`]).
//! Depends on `neurotex-core`.
#![deny(missing_docs)]

pub mod classify;
pub mod snn;

// The layers below, under the names their modules had when they were one crate, so
// that `crate::recording` and the like read the same in every layer.
use neurotex_core::error;
use neurotex_core::spikes;

/// What the unit tests share.
#[cfg(test)]
mod testing {
    /// A xorshift64 stream from `state` (not 0): reproducible test data.
    pub(crate) fn xorshift(mut state: u64) -> impl FnMut() -> u64 {
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        }
    }
}
