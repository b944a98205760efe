//! `neurotex features`: one feature row per recording of a dataset, into a CSV file.

use std::io::Write;
use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use neurotex::analysis::FeatureTable;
use neurotex::workflows::features::FeaturesOptions;

use crate::output::{check_output, shown, write_file, Shown};
use crate::stage_args::StageArgs;

/// Options of `neurotex features`.
#[derive(Args)]
pub struct FeaturesArgs {
    #[command(flatten)]
    pub options: FeaturesOptions,
    /// The CSV file to write (`-`: standard output): every manifest column in the
    /// manifest's order (extra ones such as a session or subject included), then the
    /// features.
    #[arg(long)]
    pub out: PathBuf,
    #[command(flatten)]
    pub stages: StageArgs,
}

/// Runs `neurotex features`.
pub fn run(args: FeaturesArgs) -> Result<()> {
    let o = &args.options;
    let dataset = o.open.open(&o.dataset)?;
    check_output(&args.out, &dataset.files())?;
    let progress = Shown::new("starting");
    let table = o.run(&dataset, &args.stages.options, &progress.callback())?;
    progress.finish();
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
