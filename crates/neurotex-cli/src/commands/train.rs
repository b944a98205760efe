//! `neurotex train`: a classifier (KNN, random forest or logistic regression) trained on a dataset's features, saved as a model file that
//! `neurotex predict` applies to new recordings.

use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;
use neurotex::analysis::Columns;
use neurotex::model::{Model, Provenance};
use neurotex::pipeline::{Method, Pipeline};
use neurotex::{Cell, Speed};

use super::{calibrated_pipeline, feature_table};
use crate::classifier_args::ClassifierArgs;
use crate::open_args::OpenArgs;
use crate::output::check_output;
use crate::stage_args::StageArgs;

/// Options of `neurotex train`.
#[derive(Args)]
pub struct TrainArgs {
    /// The training dataset folder (with `manifest.csv`, optional `layout.toml`).
    #[arg(long)]
    pub dataset: PathBuf,
    /// Train only on recordings at these speeds (mm/s, comma-separated); default all.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub speeds: Option<Vec<Speed>>,
    /// Feature set: `taxel`, `glcm2d`, `glcm3d` (the paper's spatio-temporal approach),
    /// `all-taxels`, `all-taxels-mm` or `glcm3d-multi`.
    #[arg(long, default_value = "glcm3d")]
    pub method: Method,
    /// With `--method taxel`: classify with this one taxel's statistics, as `ROW,COL`.
    /// Without it, every taxel's three statistics together form one feature row.
    #[arg(long)]
    pub taxel: Option<Cell>,
    /// Neighbours in KNN; at most the number of training recordings.
    #[arg(short = 'k', long = "k", default_value_t = neurotex::classify::KnnParams::default().k)]
    pub k: usize,
    /// The model file to write (JSON: pipeline, features, grid, classifier, training rows,
    /// the dataset's fingerprint).
    #[arg(long)]
    pub out: PathBuf,
    #[command(flatten)]
    pub stages: StageArgs,
    #[command(flatten)]
    pub classifier: ClassifierArgs,
    #[command(flatten)]
    pub open: OpenArgs,
}

/// Runs `neurotex train`.
pub fn run(args: TrainArgs) -> Result<()> {
    let dataset = args.open.open(&args.dataset)?;
    check_output(&args.out, &dataset.files())?;
    let indices = match &args.speeds {
        Some(speeds) => dataset.indices_at(speeds)?,
        None => (0..dataset.entries.len()).collect(),
    };
    let calibrated = calibrated_pipeline(&args.stages, &dataset, &indices)?;
    let params = calibrated.params;
    let pipeline = Pipeline::new(params.clone())?;
    let classifier = args.classifier.choice(args.stages.knn(args.k)?)?;
    let columns = match (args.method, args.taxel) {
        (Method::Taxel, Some(cell)) => Columns::Taxel(cell),
        (_, Some(_)) => bail!("--taxel applies only to --method taxel"),
        (_, None) => Columns::All,
    };
    let (table, grid) = feature_table(&dataset, &pipeline, args.speeds.as_deref(), args.method)?;
    if let Some(cell) = args.taxel {
        grid.locate(cell)?;
    }
    let provenance = Provenance {
        gain_calibration: calibrated.gain,
        median_duration_ms: calibrated.causal.map(|c| c.median_duration_ms),
        ..Provenance::of(&dataset, args.speeds.clone())?
    };
    let model = Model::train(&params, &table, columns, classifier, provenance)?;
    model.save(&args.out)?;
    eprintln!(
        "{classifier} on {} recordings of {} classes, {} {} features on the {} grid -> {}",
        model.n_training(),
        model.labels().len(),
        model.features().columns.len(),
        args.method.name(),
        grid,
        args.out.display()
    );
    Ok(())
}
