//! Where the recordings come from: the built-in simulator or a dataset folder, each
//! recording loaded when asked for.

use crate::calibrate::{calibrate_gain, GainCalibration};
use crate::error::{DataError, Result};
use crate::pipeline::Pipeline;
use crate::recording::{Baseline, Dataset, Recording};
use crate::sim::{design, simulate_trial, RigParams, Trial, ALL_TEXTURES};
use crate::values::Speed;

/// Where the recordings come from.
pub enum Source<'a> {
    /// The built-in simulator, trials generated in memory and never written.
    Simulated {
        /// Rig parameters.
        rig: Box<RigParams>,
        /// The trials.
        trials: Vec<Trial>,
        /// Simulation seed.
        seed: u64,
    },
    /// A dataset folder.
    Dataset(&'a Dataset),
}

impl Source<'_> {
    /// The paper's design on the built-in simulator: its 8 textures x 5, 10, 15 mm/s x
    /// `trials` trials, on the default rig, generated with `seed`.
    pub fn paper_design(trials: u32, seed: u64) -> Self {
        Source::Simulated {
            rig: Box::new(RigParams::default()),
            trials: design(&ALL_TEXTURES, &[5.0, 10.0, 15.0], trials),
            seed,
        }
    }

    /// One paragraph saying where the recordings come from, for the report.
    pub fn describe(&self) -> String {
        match self {
            Source::Dataset(ds) => {
                let layout = &ds.layout;
                let baseline = layout.baseline.unwrap_or_default();
                let (root, n) = (ds.root.display(), ds.entries.len());
                let grid = match (layout.rows, layout.cols) {
                    (Some(rows), Some(cols)) => {
                        let channels = layout.channels.as_ref().map(Vec::len);
                        let empty = match channels {
                            Some(c) if c < rows * cols => {
                                format!(" ({} cells without a channel)", rows * cols - c)
                            }
                            _ => String::new(),
                        };
                        let channels =
                            channels.map_or(String::new(), |c| format!("{c} channels on "));
                        format!(" {channels}a {rows}x{cols} grid{empty};")
                    }
                    _ => String::new(),
                };
                match &layout.events {
                    Some(e) => format!(
                        "Dataset folder `{root}`: {n} address-event recordings as listed in its manifest; layout.toml:{grid} times in {}; the events skip the encoder (ON events are the SA population's spikes, OFF events the FA population's), so the encoder's parameters below do not apply.",
                        e.time_unit
                    ),
                    None => format!(
                        "Dataset folder `{root}`: {n} recordings as listed in its manifest; layout.toml:{grid} baseline removed: {baseline}."
                    ),
                }
            }
            Source::Simulated { rig, trials, seed } => describe_simulated(rig, trials, *seed),
        }
    }

    /// `--gain auto` on this source's recordings, all of them (labels unused): every
    /// analysis cross-validates over them, so there is no training set apart from the rest.
    ///
    /// # Errors
    /// A recording that cannot be loaded or conditioned, or no taxel with any signal.
    pub fn calibrate_gain(&self, pipeline: &Pipeline, target_hz: f64) -> Result<GainCalibration> {
        let indices: Vec<usize> = (0..self.len()).collect();
        let load = |i: usize| self.load(i);
        calibrate_gain(pipeline, &load, &indices, self.baseline(), target_hz)
    }

    /// Number of recordings.
    pub(super) fn len(&self) -> usize {
        match self {
            Source::Simulated { trials, .. } => trials.len(),
            Source::Dataset(ds) => ds.entries.len(),
        }
    }

    /// Recording `i`'s speed and label, known before it is loaded.
    ///
    /// # Errors
    /// A dataset recording without a speed: the analyses compare speeds.
    pub(super) fn condition(&self, i: usize) -> Result<(Speed, String)> {
        match self {
            Source::Simulated { trials, .. } => Ok((
                Speed::of(trials[i].speed_mm_s),
                trials[i].texture.name().to_string(),
            )),
            Source::Dataset(ds) => {
                let meta = &ds.entries[i];
                let speed = meta.speed().ok_or_else(|| {
                    let message = format!(
                        "line {}: `{}` has no speed_mm_s; reproduce compares speeds, so every recording needs one (evaluate and features work without)",
                        i + 2,
                        meta.file
                    );
                    DataError::invalid(ds.root.join("manifest.csv"), message)
                })?;
                Ok((speed, meta.label.clone()))
            }
        }
    }

    pub(super) fn baseline(&self) -> Baseline {
        match self {
            Source::Dataset(ds) => ds.layout.baseline.unwrap_or_default(),
            Source::Simulated { .. } => Baseline::None,
        }
    }

    pub(super) fn load(&self, i: usize) -> Result<Recording> {
        match self {
            Source::Simulated { rig, trials, seed } => Ok(simulate_trial(rig, &trials[i], *seed)?),
            Source::Dataset(ds) => ds.load(i),
        }
    }
}

fn describe_simulated(rig: &RigParams, trials: &[Trial], seed: u64) -> String {
    let mut textures: Vec<&str> = Vec::new();
    for t in trials {
        if !textures.contains(&t.texture.name()) {
            textures.push(t.texture.name());
        }
    }
    let speeds = Speed::distinct(trials.iter().map(|t| Speed::of(t.speed_mm_s)));
    let speeds: Vec<String> = speeds.iter().map(|s| s.to_string()).collect();
    let per_condition = trials.len() / (textures.len() * speeds.len()).max(1);
    let rig_json = serde_json::to_string(rig).unwrap_or_default();
    format!(
        "Simulated in memory by neurotex's model of the rig (seed {seed}): {} textures ({}) x {} mm/s x {per_condition} trials; a {}x{} array of {} mm taxels on {} mm, {} N under force control, {} s hold, {} mm slide, 1 kHz. Rig parameters: `{rig_json}`.",
        textures.len(),
        textures.join(", "),
        speeds.join(", "),
        rig.rows,
        rig.cols,
        rig.taxel_mm,
        rig.active_mm,
        rig.force_n,
        rig.hold_s,
        rig.slide_mm,
    )
}
