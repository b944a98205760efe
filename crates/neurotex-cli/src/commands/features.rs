//! `neurotex features`: one feature row per recording of a dataset, into a CSV file.

use std::io::Write;
use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use neurotex::analysis::FeatureTable;
use neurotex::pipeline::{Method, Pipeline};

use super::{calibrated_pipeline, feature_table};
use crate::open_args::OpenArgs;
use crate::output::{check_output, shown, write_file};
use crate::stage_args::StageArgs;

/// Options of `neurotex features`.
#[derive(Args)]
pub struct FeaturesArgs {
    /// The dataset folder (with `manifest.csv`, optional `layout.toml`).
    #[arg(long)]
    pub dataset: PathBuf,
    /// Feature set: `taxel` or `all-taxels` (MSR, CV_ISI, Fano of every taxel),
    /// `all-taxels-mm` (spikes per mm, CV_ISI, Fano over fixed travel), `glcm2d`, `glcm3d`
    /// or `glcm3d-multi` (Haralick features, at each of `--bin-widths` for the last).
    #[arg(long)]
    pub method: Method,
    /// The CSV file to write (`-`: standard output): every manifest column in the manifest's order (extra ones
    /// such as a session or subject included), then the features.
    #[arg(long)]
    pub out: PathBuf,
    #[command(flatten)]
    pub stages: StageArgs,
    #[command(flatten)]
    pub open: OpenArgs,
}

/// Runs `neurotex features`.
pub fn run(args: FeaturesArgs) -> Result<()> {
    let dataset = args.open.open(&args.dataset)?;
    check_output(&args.out, &dataset.files())?;
    // Features are computed for every recording; `--gain auto` calibrates on all of them.
    let all: Vec<usize> = (0..dataset.entries.len()).collect();
    let params = calibrated_pipeline(&args.stages, &dataset, &all)?.params;
    let pipeline = Pipeline::new(params)?;
    let (table, _) = feature_table(&dataset, &pipeline, None, args.method)?;
    let columns = &dataset.columns;
    write_file(&args.out, "the feature table", |w| {
        write_table(w, columns, &table)
    })?;
    eprintln!(
        "{} recordings x {} features -> {}",
        table.metas.len(),
        table.dims(),
        shown(&args.out)
    );
    Ok(())
}

/// Writes the table as CSV: the manifest's `columns` (empty where a recording gives no
/// value), then one column per feature.
fn write_table(w: &mut dyn Write, columns: &[String], table: &FeatureTable) -> std::io::Result<()> {
    let mut out = csv::Writer::from_writer(w);
    out.write_record(columns.iter().chain(&table.names))?;
    for (i, m) in table.metas.iter().enumerate() {
        let ids = columns.iter().map(|c| m.field(c).unwrap_or_default());
        let values = table.row(i).iter().map(f64::to_string);
        out.write_record(ids.chain(values))?;
    }
    out.flush()
}
