//! neurotex's feature layer: spike trains become single-taxel statistics, rate images
//! and volumes, and their 2D/3D gray-level co-occurrence (GLCM) texture features
//! ([`features`]). Depends on `neurotex-core` and `neurotex-signal`.
#![deny(missing_docs)]

pub mod features;

// The layers below, under the names their modules had when they were one crate, so
// that `crate::recording` and the like read the same in every layer.
use neurotex_core::error;
use neurotex_core::spikes;
