//! `neurotex predict`: a saved model applied to new recordings, a dataset folder or plain
//! files, with its own pipeline; one CSV row per recording, and the accuracy when the
//! labels are known.

use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;
use neurotex::model::write_predictions;
use neurotex::pipeline::Encoded;
use neurotex::saved::SavedModel;
use neurotex::stream::write_episodes;
use neurotex::workflows::predict::PredictOptions;

use crate::output::{check_output, is_stdout, shown, write_file, Shown};

/// Options of `neurotex predict`.
#[derive(Args)]
pub struct PredictArgs {
    #[command(flatten)]
    pub options: PredictOptions,
    /// The CSV file to write (`-`: standard output): `file,label,predicted`, then `share_<class>` for each class
    /// of the model (KNN: its share of the votes among the k neighbours; forest: its mean
    /// leaf share over the trees; linear: its probability); `label` is empty when unknown.
    #[arg(long)]
    pub out: PathBuf,
    /// With --model FILE.nir from another tool (snnTorch, Norse, Rockpool: no neurotex
    /// metadata in the graph): a neurotex spiking model whose pipeline, grid and labels the
    /// graph's network runs with (the network must have its inputs and outputs).
    #[arg(long)]
    pub like: Option<PathBuf>,
    /// The tool that wrote the graph given as --model, for what its file does not say:
    /// `nir` (NIR's equations, `dt` in the metadata or else --like's time step),
    /// `snntorch` (snnTorch's `export_to_nir`: constants for its fixed 0.1 ms step, a
    /// `Leaky` readout's membrane read without reset) or `norse` (Norse's `to_nir`: time
    /// constants multiplied by `dt`); snnTorch and Norse write no time step, so the network
    /// steps at --like's `dt_ms`, which must be the `dt` the tool ran at.
    #[arg(long, value_name = "TOOL", default_value = "nir")]
    pub nir_from: neurotex::nir::NirFrom,
    /// Also print `{"accuracy", "interval" (95 %, Wilson), "chance", "n", "labels", "confusion"}`
    /// (rows = true label) and `trained_on` (how many of the recordings scored the model was
    /// trained on: its training dataset's at its training speeds, whose predictions test
    /// nothing) as JSON; needs --dataset whose every label is a model's class.
    #[arg(long)]
    pub json: bool,
}

/// Runs `neurotex predict`.
pub fn run(args: PredictArgs) -> Result<()> {
    let o = &args.options;
    if o.causal && args.json {
        bail!("--causal writes per-bin decisions; score whole recordings without it (the end lines' labels classify each episode's last window, the whole recording only when it is no longer than --window-s)");
    }
    if args.json && is_stdout(&args.out) {
        bail!("--out - and --json would both write standard output; write the predictions to a file with --json");
    }
    if args.json && o.dataset.is_none() {
        bail!("--json scores the predictions against known labels: it needs --dataset");
    }
    let dataset = o.dataset()?;
    check_output(&args.out, &o.inputs(dataset.as_ref()))?;
    let model = SavedModel::load_as(&o.model, args.like.as_deref(), args.nir_from)?;
    let progress = Shown::new("starting");
    let encoded = o.encode(&model, dataset.as_ref(), &progress.callback());
    progress.finish();
    let encoded = encoded?;
    if o.causal {
        return predict_causal(&args, &model, &encoded);
    }
    let predictions = model.predict(&encoded)?;
    // Scored before anything is written, so that a label the model cannot score leaves no
    // predictions file behind a failed run (with --json; else the accuracy is left out).
    let score = match &dataset {
        Some(d) if args.json => Some(o.score(&model, d, &encoded, &predictions)?),
        Some(d) => o.score(&model, d, &encoded, &predictions).ok(),
        None => None,
    };
    let known = dataset.is_some();
    write_file(&args.out, "predictions", |w| {
        write_predictions(w, model.labels(), &encoded, &predictions, known)
    })?;
    match score {
        Some(score) if args.json => println!("{}", serde_json::to_string(&score)?),
        Some(score) => eprintln!("{}", score.summary()),
        None => {}
    }
    let (with, n) = (model.described(&o.model), predictions.len());
    eprintln!(
        "{} predicted with {with}{} -> {}",
        neurotex::words::counted(n, "recording"),
        o.model.display(),
        shown(&args.out)
    );
    Ok(())
}

/// Writes every recording's per-bin decisions and end, as `neurotex stream` prints them.
fn predict_causal(args: &PredictArgs, model: &SavedModel, encoded: &[Encoded]) -> Result<()> {
    let episodes = args.options.episodes(model, encoded)?;
    write_file(&args.out, "causal decisions", |w| {
        write_episodes(w, model.labels(), encoded, &episodes)
    })?;
    let decided = episodes.iter().filter(|e| e.decided()).count();
    eprintln!(
        "{} recordings, {decided} decided before their end -> {}",
        episodes.len(),
        shown(&args.out)
    );
    Ok(())
}
