//! The model file format's marks: the `format` field a feature model and a spiking model
//! carry, and the version of the format this neurotex writes and reads.

/// The `format` field of every model file.
pub const MODEL_FORMAT: &str = "neurotex-model";

/// The `format` field of a spiking model file (`train --classifier snn`).
pub const SNN_MODEL_FORMAT: &str = "neurotex-snn-model";

/// The version of the model file format this neurotex writes and reads.
pub const MODEL_VERSION: u64 = 1;
