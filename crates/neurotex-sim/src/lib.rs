//! neurotex's simulator: taxel-array recordings of textured surfaces slid at several
//! speeds, written as a dataset ([`sim`]). Depends on `neurotex-core` only.
#![deny(missing_docs)]

pub mod sim;

// The layers below, under the names their modules had when they were one crate, so
// that `crate::recording` and the like read the same in every layer.
use neurotex_core::{error, recording, Result};
