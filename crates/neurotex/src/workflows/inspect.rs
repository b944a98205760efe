//! `inspect`: a quick, read-only check of a dataset folder or of raw logs before any
//! analysis, with findings and the options that address them.

use std::path::PathBuf;

use super::{LogOptions, OnProgress, OpenOptions};
use crate::inspect::{inspect, InspectParams, Inspection, Opened};
use crate::options::StageOptions;
use crate::progress::Progress;
use crate::Result;

/// Options of `inspect`.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct InspectOptions {
    /// A dataset folder (with `manifest.csv`), or raw CSV logs: files, or folders whose
    /// .csv files are all read, with the options `import csv` would be given.
    #[cfg_attr(feature = "cli", arg(required = true))]
    pub inputs: Vec<PathBuf>,
    /// Skip the encoder's check (the firing rates at the gain, and the gain `--gain auto`
    /// would choose): only the design, layout and signals.
    #[cfg_attr(feature = "cli", arg(long = "no-encoder"))]
    pub no_encoder: bool,
    /// Cross-validation folds the design is judged for.
    #[cfg_attr(feature = "cli", arg(long, default_value_t = crate::classify::CvParams::default().folds))]
    pub folds: usize,
    /// KNN's neighbours the design is judged for.
    #[cfg_attr(feature = "cli", arg(long, default_value_t = crate::classify::KnnParams::default().k))]
    pub k: usize,
    /// How raw logs are read.
    #[cfg_attr(feature = "cli", command(flatten))]
    pub logs: LogOptions,
    /// How the dataset folder is opened.
    #[cfg_attr(feature = "cli", command(flatten))]
    pub open: OpenOptions,
}

impl InspectOptions {
    /// Inspects the inputs with the stage options `stages`; `traces` keeps a few raw
    /// traces per class for the figures.
    ///
    /// # Errors
    /// Inputs that are neither a dataset folder nor CSV logs, or a parameter out of range.
    pub fn run(&self, stages: &StageOptions, traces: bool, on: OnProgress) -> Result<Inspection> {
        if stages.causal {
            let rule = "inspect checks the offline conditioning and the encoder; what causal conditioning meets is its own finding (`drifting-rest`), so --causal and --drift-window-s are for evaluate, train and the others";
            return Err(crate::error::ParamError::new("causal", rule, "--causal").into());
        }
        if self.folds < 2 {
            let rule = "the design is judged for at least 2 folds";
            return Err(crate::error::ParamError::new("folds", rule, self.folds).into());
        }
        if self.k < 1 {
            let rule = "the design is judged for at least 1 neighbour";
            return Err(crate::error::ParamError::new("k", rule, self.k).into());
        }
        let checked = stages.check()?;
        let params = InspectParams {
            pipeline: checked.to_calibrate().clone(),
            encoder: !self.no_encoder,
            folds: self.folds,
            k: self.k,
            gain_target: checked.gain.target_hz(),
            traces,
        };
        let opened = Opened::open(
            &self.inputs,
            self.logs.params(),
            self.logs.any(),
            self.open.allow_outside_paths,
        )?;
        if let Opened::Logs(_) = opened {
            // Raw logs' folders may hold what is not a regular file, which is left out.
            for (_, why) in crate::import::find_csv(&self.inputs)?.left_out {
                on(Progress::Advice(&format!("left out {why}")));
            }
        }
        on(Progress::Stage("inspecting", opened.len()));
        inspect(opened.source(), &params, &|| on(Progress::Tick))
    }
}
