//! `neurotex encode`: one recording into a spike raster (and address events).

use std::io::Write;
use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;
use neurotex::encode::SpikeTrains;
use neurotex::workflows::encode::EncodeOptions;

use crate::output::{check_binary, check_output, is_stdout, shown, stage_file, write_file, Shown};
use crate::stage_args::StageArgs;

/// Options of `neurotex encode`.
#[derive(Args)]
pub struct EncodeArgs {
    #[command(flatten)]
    pub options: EncodeOptions,
    /// Where to write the spikes: u8 `.npy` of shape `(T, rows, cols)` at 1 kHz.
    #[arg(long)]
    pub out: PathBuf,
    /// Also write the spikes as address events `t_ms,row,col` to this CSV file.
    #[arg(long)]
    pub events: Option<PathBuf>,
    #[command(flatten)]
    pub stages: StageArgs,
}

/// Runs `neurotex encode`.
pub fn run(args: EncodeArgs) -> Result<()> {
    let o = &args.options;
    let stages = &args.stages.options;
    EncodeOptions::check(stages)?;
    let bar = Shown::new("encoding");
    let on = bar.callback();
    let input = o.read(&on)?;
    check_output(&args.out, &input.files)?;
    check_binary(&args.out, "--out", "a spike raster (.npy)")?;
    if let Some(events) = &args.events {
        if events == &args.out || neurotex::io::same_file(events, &args.out) {
            bail!(
                "--events and --out name the same file, {}",
                shown(&args.out)
            );
        }
        check_output(events, &input.files)?;
    }
    let encoded = o.encode(&input, stages, &on)?;
    bar.finish();
    let spikes = &encoded.spikes;
    let raster = ndarray::Array3::from_shape_vec(
        (spikes.n_steps, spikes.rows, spikes.cols),
        spikes.to_raster(),
    )?;
    let write_raster = |w: &mut dyn Write| {
        ndarray_npy::WriteNpyExt::write_npy(&raster, w).map_err(std::io::Error::other)
    };
    // Both files are written before either is put in place: a failure leaves neither.
    // Standard output is written last of all but the renames.
    let mut staged = Vec::new();
    let events = args.events.as_deref();
    if let Some(path) = events.filter(|p| !is_stdout(p)) {
        staged.push(stage_file(path, "address events", |w| {
            write_events(w, spikes)
        })?);
    }
    if !is_stdout(&args.out) {
        staged.push(stage_file(&args.out, "spike raster", write_raster)?);
    }
    if let Some(path) = events.filter(|p| is_stdout(p)) {
        write_file(path, "address events", |w| write_events(w, spikes))?;
    }
    if is_stdout(&args.out) {
        write_file(&args.out, "spike raster", write_raster)?;
    }
    for file in staged {
        file.commit()?;
    }
    eprintln!(
        "{} spikes from {} taxels over {} ms -> {}",
        spikes.total_spikes(),
        spikes.present.iter().filter(|&&p| p).count(),
        spikes.n_steps,
        shown(&args.out)
    );
    Ok(())
}

/// Writes `t_ms,row,col`, one spike a line.
fn write_events(w: &mut dyn Write, spikes: &SpikeTrains) -> std::io::Result<()> {
    writeln!(w, "t_ms,row,col")?;
    for (t, r, c) in spikes.events() {
        writeln!(w, "{t},{r},{c}")?;
    }
    Ok(())
}
