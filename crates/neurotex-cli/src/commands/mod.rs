//! The subcommands, one module each: every one parses its options into the library's
//! workflow options ([`neurotex::workflows`]) and the stage options, runs the workflow with
//! a progress bar, and writes or prints the result.

pub mod compare;
pub mod datasets;
pub mod encode;
pub mod evaluate;
pub mod export;
pub mod features;
pub mod import;
pub mod inspect;
pub mod predict;
pub mod reproduce;
pub mod simulate;
pub mod stream;
pub mod train;
