//! Features from spike trains: single-taxel spike statistics, the rate volume and its
//! quantisation, gray-level co-occurrence matrices and Haralick features.

mod exact;
pub mod glcm;
pub mod haralick;
pub mod haralick_full;
pub mod signal_stats;
pub mod spectrum;
pub mod spike_stats;
pub mod volume;

pub use glcm::{Counting, GlcmParams, GlcmPlan, DIRECTIONS_13};
pub use haralick::{haralick, Haralick};
pub use haralick_full::{haralick_full, FULL_NAMES};
pub use signal_stats::{signal_stats, SIGNAL_STAT_NAMES};
pub use spectrum::{Spectrum, SpectrumParams};
pub use spike_stats::{distance_stats, spike_stats, SpikeStats};
pub use volume::{quantise, CountVolume, RateVolume, VolumeParams};
