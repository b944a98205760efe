//! `encode`: one recording into spikes, read with its layout and the reading options.

use std::path::PathBuf;

use super::{calibration_line, say_conditions, OnProgress, ReadOptions};
use crate::calibrate::calibrate_gain;
use crate::error::OptionsError;
use crate::options::StageOptions;
use crate::pipeline::{Encoded, Pipeline};
use crate::progress::Progress;
use crate::recording::{read_recording_as, Baseline, LayoutFrom, Recording};
use crate::Result;

/// Options of `encode`.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct EncodeOptions {
    /// The recording: `.npy` (f32/f64, `(T, rows, cols)` or `(T, channels)`) or `.csv`
    /// (by default a header row, an optional `t_ms`/`t_s` time column, one column per
    /// channel; the CSV options below read raw logs). Its layout is `--layout FILE` when
    /// given, else the `layout.toml` beside the recording when there is one (a dataset
    /// folder's), else the defaults; options given here override the layout's settings.
    pub input: PathBuf,
    /// How the files are read.
    #[cfg_attr(feature = "cli", command(flatten))]
    pub read: ReadOptions,
}

/// A recording read for encoding, with its baseline and the files it was read from.
#[derive(Debug)]
pub struct Input {
    /// The recording.
    pub recording: Recording,
    /// The baseline its layout removes.
    pub baseline: Baseline,
    /// The files read: the recording and its layout file, if any.
    pub files: Vec<PathBuf>,
}

impl EncodeOptions {
    /// The pipeline the stage options name for one recording, checked before anything is
    /// read.
    ///
    /// # Errors
    /// `--causal` (it needs training recordings), or a parameter out of range.
    pub fn check(stages: &StageOptions) -> Result<Pipeline> {
        if stages.causal {
            return Err(OptionsError::Conflict("--causal fixes resting values and a scale on training recordings: use it with train, evaluate, features or compare (then predict or stream with the model)".into()).into());
        }
        Ok(Pipeline::new(stages.check()?.to_calibrate().clone())?)
    }

    /// Reads the recording with its layout, saying where the layout came from.
    ///
    /// # Errors
    /// The recording or its layout cannot be read.
    pub fn read(&self, on: OnProgress) -> Result<Input> {
        let reading = self.read.reading()?;
        let (layout, from) = reading.layout_for(&self.input, None)?;
        let mut files = vec![self.input.clone()];
        files.extend(self.read.layout.clone());
        if let LayoutFrom::Beside(path) = &from {
            files.push(path.clone());
        }
        for note in ReadOptions::layout_notes(std::slice::from_ref(&from)) {
            on(Progress::Say(&note));
        }
        let format = reading.csv_format(&self.input, &layout)?;
        Ok(Input {
            recording: read_recording_as(&self.input, &layout, &format)?,
            baseline: layout.baseline.unwrap_or_default(),
            files,
        })
    }

    /// Encodes `input` with the stage options `stages`; `--gain auto` calibrates on this
    /// one recording.
    ///
    /// # Errors
    /// `--causal` (it needs training recordings), a parameter out of range, or a
    /// recording the pipeline cannot encode.
    pub fn encode(&self, input: &Input, stages: &StageOptions, on: OnProgress) -> Result<Encoded> {
        let pipeline = Self::check(stages)?;
        let pipeline = match stages.gain.target_hz() {
            Some(target) => {
                let load = |_: usize| Ok(input.recording.clone());
                let c = calibrate_gain(&pipeline, &load, &[0], input.baseline, target)?;
                on(Progress::Say(&calibration_line(&c)));
                let mut params = pipeline.params().clone();
                params.encoder.gain = c.gain;
                Pipeline::new(params)?
            }
            None => pipeline,
        };
        let encoded = pipeline.encode(&input.recording, input.baseline)?;
        say_conditions(std::slice::from_ref(&encoded), on);
        Ok(encoded)
    }
}
