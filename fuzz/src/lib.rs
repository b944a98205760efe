//! Fuzz harness for neurotex's readers: see `fuzz/README.md`.

#[path = "harness.rs"]
pub mod harness;
