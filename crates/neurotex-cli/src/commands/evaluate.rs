//! `neurotex evaluate`: KNN on a dataset's features, by cross-validation or by training on
//! some speeds and testing on others; prints accuracy and confusion matrix.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use clap::Args;
use neurotex::analysis::{
    evaluate, Columns, FeatureTable, OutOfFold, Outcome, Split, TaxelAccuracy,
};
use neurotex::classify::{CvParams, Metrics};
use neurotex::pipeline::{Method, Pipeline};
use neurotex::recording::Dataset;
use neurotex::{Cell, Speed};

use super::feature_table;
use crate::output::write_file;
use crate::stage_args::StageArgs;

/// Options of `neurotex evaluate`.
#[derive(Args)]
pub struct EvaluateArgs {
    /// The dataset folder.
    #[arg(long)]
    pub dataset: PathBuf,
    /// Feature set: `taxel`, `glcm2d` or `glcm3d`.
    #[arg(long)]
    pub method: Method,
    /// With `--method taxel`: the taxel to use, as `ROW,COL`. Without it every taxel is
    /// evaluated and the mean over taxels is reported, with the best beside it.
    #[arg(long)]
    pub taxel: Option<Cell>,
    /// Neighbours in KNN.
    #[arg(long, default_value_t = 5)]
    pub k: usize,
    /// Cross-validation folds (stratified, shuffled).
    #[arg(long, default_value_t = 5)]
    pub folds: usize,
    /// Seed of the fold shuffle (repeat r uses seed + r).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Cross-validation repeats with different shuffles.
    #[arg(long, default_value_t = 1)]
    pub repeats: usize,
    /// Only recordings at these speeds (mm/s, comma-separated); default all.
    #[arg(
        long,
        value_delimiter = ',',
        allow_hyphen_values = true,
        conflicts_with = "train_speeds"
    )]
    pub speeds: Option<Vec<Speed>>,
    /// Train on these speeds instead of cross-validating (needs --test-speeds).
    #[arg(
        long = "train-speeds",
        value_delimiter = ',',
        allow_hyphen_values = true,
        requires = "test_speeds"
    )]
    pub train_speeds: Option<Vec<Speed>>,
    /// Test on these speeds (needs --train-speeds).
    #[arg(
        long = "test-speeds",
        value_delimiter = ',',
        allow_hyphen_values = true,
        requires = "train_speeds"
    )]
    pub test_speeds: Option<Vec<Speed>>,
    /// Cross-validation folds never split a group of this manifest column (`trial`,
    /// `force_n`, or any further column such as a session or subject); with fewer groups
    /// than folds, each group is held out in turn.
    #[arg(long = "group-by", conflicts_with = "train_speeds")]
    pub group_by: Option<String>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// Write each recording's out-of-fold prediction to this CSV file:
    /// `file,label,predicted,fold,repeat`, one row per recording and CV repeat (folds and
    /// repeats count from 0; `fold` is `test` with --train-speeds/--test-speeds). Needs one
    /// classifier: a GLCM method, or --method taxel with --taxel.
    #[arg(long)]
    pub predictions: Option<PathBuf>,
    #[command(flatten)]
    pub stages: StageArgs,
}

impl EvaluateArgs {
    /// Cross-validation, or training and testing on the given speeds.
    fn split(&self) -> Result<Split> {
        let cv = CvParams {
            folds: self.folds,
            seed: self.seed,
            repeats: self.repeats,
        }
        .check()?;
        Ok(match (&self.train_speeds, &self.test_speeds) {
            (Some(train), Some(test)) => Split::ByCondition {
                train: train.clone(),
                test: test.clone(),
            },
            _ => Split::CrossValidation {
                speeds: self.speeds.clone(),
                cv,
                group_by: self.group_by.clone(),
            },
        })
    }

    /// The speeds whose recordings the split uses; `None` for all.
    fn speeds_used(&self) -> Option<Vec<Speed>> {
        match (&self.train_speeds, &self.test_speeds) {
            (Some(train), Some(test)) => Some([&train[..], test].concat()),
            _ => self.speeds.clone(),
        }
    }

    /// The feature columns to classify with.
    fn columns(&self) -> Result<Columns> {
        Ok(match (self.method, self.taxel) {
            (Method::Taxel, Some(cell)) => Columns::Taxel(cell),
            (Method::Taxel, None) => Columns::EachTaxel,
            (_, Some(_)) => bail!("--taxel applies only to --method taxel"),
            (_, None) => Columns::All,
        })
    }
}

/// Runs `neurotex evaluate`.
pub fn run(args: EvaluateArgs) -> Result<()> {
    let pipeline = Pipeline::new(args.stages.pipeline()?)?;
    let knn = args.stages.knn(args.k)?;
    let split = args.split()?;
    let columns = args.columns()?;
    if args.predictions.is_some() && columns == Columns::EachTaxel {
        bail!("--predictions needs one classifier, not one per taxel: add --taxel ROW,COL");
    }
    let dataset = Dataset::open(&args.dataset)?;
    let speeds = args.speeds_used();
    let (table, grid) = feature_table(&dataset, &pipeline, speeds.as_deref(), args.method)?;
    if let Some(cell) = args.taxel {
        grid.locate(cell)?;
    }
    let outcome = evaluate(&table, columns, &split, &knn.check()?)?;
    if let Some(path) = &args.predictions {
        let predictions = outcome
            .predictions
            .as_deref()
            .context("one classifier's predictions for --predictions")?;
        write_file(path, "out-of-fold predictions", |w| {
            write_out_of_fold(w, &table, &outcome.labels, predictions)
        })?;
    }
    if args.json {
        let mut value = serde_json::to_value(&outcome)?;
        value["method"] = args.method.name().into();
        // Balanced accuracy, per-class recall and precision and both chance levels from the
        // confusion matrix; the interval resamples recordings, keeping each one's
        // predictions over repeats (and taxels) together.
        value["metrics"] = serde_json::to_value(Metrics::from_confusion(&outcome.confusion))?;
        let interval = outcome.accuracy_interval(args.seed)?;
        value["accuracy_interval"] = serde_json::to_value(interval)?;
        println!("{}", serde_json::to_string(&value)?);
    } else {
        print_outcome(&outcome, args.method, &split, grid.cols());
    }
    Ok(())
}

/// Prints the outcome as text: what was run, the accuracy (per taxel when every taxel was
/// evaluated) and the confusion matrix.
fn print_outcome(outcome: &Outcome, method: Method, split: &Split, cols: usize) {
    let how = match split {
        Split::CrossValidation {
            cv,
            group_by: Some(column),
            ..
        } => format!(
            "up to {}-fold CV keeping each `{column}` group in one fold, seed {}, {} repeat(s)",
            cv.folds, cv.seed, cv.repeats
        ),
        Split::CrossValidation { cv, .. } => format!(
            "{}-fold stratified CV, seed {}, {} repeat(s)",
            cv.folds, cv.seed, cv.repeats
        ),
        Split::ByCondition { train, test } => {
            let list = |s: &[Speed]| s.iter().map(|s| s.to_string()).collect::<Vec<_>>();
            format!(
                "train on [{}] mm/s, test on [{}] mm/s",
                list(train).join(", "),
                list(test).join(", ")
            )
        }
    };
    println!("method {}: {} samples, {how}", method.name(), outcome.n);
    if let (Some(per), Some(best)) = (&outcome.per_taxel, &outcome.best) {
        print_taxel_grid(per, cols);
        println!(
            "accuracy {:.1}% (mean over taxels); best taxel r{}c{} {:.1}% (chosen after the fact)",
            100.0 * outcome.accuracy,
            best.row,
            best.col,
            100.0 * best.accuracy
        );
    } else if outcome.accuracy_std > 0.0 {
        println!(
            "accuracy {:.1}% ± {:.1}%",
            100.0 * outcome.accuracy,
            100.0 * outcome.accuracy_std
        );
    } else {
        println!("accuracy {:.1}%", 100.0 * outcome.accuracy);
    }
    print_confusion(outcome);
}

/// Prints each taxel's accuracy in its place on the grid; `-` for cells without a taxel.
fn print_taxel_grid(per: &[TaxelAccuracy], cols: usize) {
    println!("accuracy per taxel (%):");
    let rows = per.iter().map(|t| t.row).max().unwrap_or(0) + 1;
    for r in 0..rows {
        let line: Vec<String> = (0..cols)
            .map(|c| {
                per.iter()
                    .find(|t| t.row == r && t.col == c)
                    .map_or("    -".to_string(), |t| {
                        format!("{:5.1}", 100.0 * t.accuracy)
                    })
            })
            .collect();
        println!("  {}", line.join(" "));
    }
}

/// Prints the confusion matrix, rows the true labels.
fn print_confusion(outcome: &Outcome) {
    let summed = if outcome.per_taxel.is_some() {
        ", summed over taxels"
    } else {
        ""
    };
    println!("confusion (rows = true, columns = predicted{summed}):");
    let width = outcome
        .labels
        .iter()
        .map(|l| l.len())
        .max()
        .unwrap_or(1)
        .max(5);
    print!("{:width$}", "");
    for l in &outcome.labels {
        print!(" {l:>width$}");
    }
    println!();
    for (l, row) in outcome.labels.iter().zip(outcome.confusion.rows()) {
        print!("{l:width$}");
        for v in row {
            print!(" {v:>width$}");
        }
        println!();
    }
}

/// Writes `file,label,predicted,fold,repeat`, one row per prediction.
fn write_out_of_fold(
    w: &mut dyn Write,
    table: &FeatureTable,
    labels: &[String],
    predictions: &[OutOfFold],
) -> std::io::Result<()> {
    let mut out = csv::Writer::from_writer(w);
    out.write_record(["file", "label", "predicted", "fold", "repeat"])?;
    for p in predictions {
        let meta = &table.metas[p.row];
        let fold = p.fold.map_or("test".to_string(), |f| f.to_string());
        out.write_record([
            meta.file.as_str(),
            meta.label.as_str(),
            labels[p.predicted].as_str(),
            fold.as_str(),
            p.repeat.to_string().as_str(),
        ])?;
    }
    out.flush()
}
