//! `neurotex predict`: a saved model applied to new recordings, a dataset folder or plain
//! files, with its own pipeline; one CSV row per recording, and the accuracy when the
//! labels are known.

use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;
use neurotex::causal::episode_decisions;
use neurotex::model::Model;
use neurotex::pipeline::Encoded;
use neurotex::recording::Dataset;
use neurotex::stream::write_episodes;
use rayon::prelude::*;

use super::report_conditions;
use super::stream::DecisionArgs;
use crate::csv_args::ReadArgs;
use crate::open_args::OpenArgs;
use crate::output::{check_output, is_stdout, progress, shown, tick, write_file};

/// Options of `neurotex predict`.
#[derive(Args)]
pub struct PredictArgs {
    /// The model file written by `neurotex train`. Its pipeline (filter, neurons, bins,
    /// GLCM offsets, baseline) is applied to the recordings, not this command's defaults.
    #[arg(long)]
    pub model: PathBuf,
    /// A dataset folder to predict; its manifest's labels are written beside the
    /// predictions and scored with --json.
    #[arg(
        long,
        required_unless_present = "files",
        conflicts_with_all = ["files", "layout", "fs", "grid", "no_header", "delimiter", "time_column", "time_unit", "channels", "duplicate_stamps", "max_gap_s"]
    )]
    pub dataset: Option<PathBuf>,
    /// Recordings to predict instead of a dataset (`.npy` or `.csv`); their labels are
    /// unknown. They must have the model's taxel grid. A file with no layout given or
    /// beside it is read as the model's training recordings were: raw logs of the logger
    /// the training dataset was imported from need no options.
    pub files: Vec<PathBuf>,
    /// With FILES: how to read them (the options of `encode`).
    #[command(flatten)]
    pub read: ReadArgs,
    /// The CSV file to write (`-`: standard output): `file,label,predicted`, then `share_<class>` for each class
    /// of the model (KNN: its share of the votes among the k neighbours; forest: its mean
    /// leaf share over the trees; linear: its probability); `label` is empty when unknown.
    #[arg(long)]
    pub out: PathBuf,
    /// Also print `{"accuracy", "n", "labels", "confusion"}` (rows = true label) as JSON;
    /// needs --dataset, and every label there must be a class of the model.
    #[arg(long)]
    pub json: bool,
    /// Decide as `neurotex stream` would, bin by bin (needs a model trained with
    /// --causal): --out gets JSON lines, one per bin boundary of each recording's selected
    /// phase and one for its end, each with the recording's `file`; the same lines
    /// `neurotex stream --episode whole` prints for that recording's frames.
    #[arg(long)]
    pub causal: bool,
    #[command(flatten)]
    pub decision: DecisionArgs,
    #[command(flatten)]
    pub open: OpenArgs,
}

/// Runs `neurotex predict`.
pub fn run(args: PredictArgs) -> Result<()> {
    if args.causal && args.json {
        bail!("--causal writes per-bin decisions; score whole recordings without it (a causal model's whole-recording predictions are its episodes' end labels)");
    }
    if args.json && is_stdout(&args.out) {
        bail!("--out - and --json would both write standard output; write the predictions to a file with --json");
    }
    if args.json && args.dataset.is_none() {
        bail!("--json scores the predictions against known labels: it needs --dataset");
    }
    let dataset = args
        .dataset
        .as_ref()
        .map(|d| args.open.open(d))
        .transpose()?;
    let mut inputs = vec![args.model.clone()];
    match &dataset {
        Some(dataset) => inputs.extend(dataset.files()),
        None => inputs.extend(args.files.iter().chain(&args.read.layout).cloned()),
    }
    check_output(&args.out, &inputs)?;
    let model = Model::load(&args.model)?;
    let (encoded, known) = match &dataset {
        Some(dataset) => (encode_dataset(&model, dataset)?, true),
        None => {
            let (encoded, from) = model.encode_files(&args.files, &args.read.reading()?)?;
            args.read.say_layouts(&from);
            (encoded, false)
        }
    };
    report_conditions(&encoded);
    if args.causal {
        return predict_causal(&args, &model, &encoded);
    }
    let predictions = model.predict(&encoded)?;
    let truth: Vec<String> = encoded.iter().map(|e| e.meta.label.clone()).collect();
    // Scored before anything is written, so that a label the model cannot score leaves no
    // predictions file behind a failed run.
    let score = match args.json {
        true => Some(model.score(&truth, &predictions)?),
        false => None,
    };
    write_file(&args.out, "predictions", |w| {
        model.write_predictions(w, &encoded, &predictions, known)
    })?;
    if let Some(score) = score {
        println!("{}", serde_json::to_string(&score)?);
    }
    eprintln!(
        "{} recordings predicted with {} -> {}",
        predictions.len(),
        args.model.display(),
        shown(&args.out)
    );
    Ok(())
}

/// Writes every recording's per-bin decisions and end, as `neurotex stream` prints them.
fn predict_causal(args: &PredictArgs, model: &Model, encoded: &[Encoded]) -> Result<()> {
    if model.causal().is_none() {
        bail!("{}: --causal needs a model trained with --causal (this one conditions each recording with the zero-phase filter and its own maximum, which need the whole recording)", args.model.display());
    }
    let window_ms = args.decision.window_ms(model)?;
    let rule = args.decision.rule()?;
    let episodes = encoded
        .par_iter()
        .map(|e| episode_decisions(model, e, window_ms, rule))
        .collect::<neurotex::Result<Vec<_>>>()?;
    let labels = model.labels();
    write_file(&args.out, "causal decisions", |w| {
        write_episodes(w, labels, encoded, &episodes)
    })?;
    let decided = episodes
        .iter()
        .filter(|e| e.summary.decision.is_some())
        .count();
    eprintln!(
        "{} recordings, {decided} decided before their end -> {}",
        episodes.len(),
        shown(&args.out)
    );
    Ok(())
}

/// Encodes every recording of `dataset` with the model's pipeline.
fn encode_dataset(model: &Model, dataset: &Dataset) -> Result<Vec<Encoded>> {
    let layout_baseline = dataset.layout.baseline.unwrap_or_default();
    if layout_baseline != model.baseline() {
        eprintln!(
            "note: the model removes baseline `{}` as in training; {} says `{layout_baseline}`",
            model.baseline(),
            dataset.root.join("layout.toml").display()
        );
    }
    let all: Vec<usize> = (0..dataset.entries.len()).collect();
    let bar = progress(all.len(), "encoding");
    let encoded = model
        .pipeline()
        .encode_dataset(dataset, &all, &|| tick(&bar));
    bar.finish_and_clear();
    Ok(encoded?)
}
