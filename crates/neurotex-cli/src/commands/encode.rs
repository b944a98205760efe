//! `neurotex encode`: one recording into a spike raster (and address events).

use std::io::Write;
use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;
use neurotex::calibrate::calibrate_gain;
use neurotex::encode::SpikeTrains;
use neurotex::pipeline::Pipeline;
use neurotex::recording::{read_recording_as, LayoutFrom};

use super::{report_conditions, say_calibration};
use crate::csv_args::ReadArgs;
use crate::output::{check_output, stage_file};
use crate::stage_args::StageArgs;

/// Options of `neurotex encode`.
#[derive(Args)]
pub struct EncodeArgs {
    /// The recording: `.npy` (f32/f64, `(T, rows, cols)` or `(T, channels)`) or `.csv`
    /// (by default a header row, an optional `t_ms`/`t_s` time column, one column per
    /// channel; the CSV options below read raw logs). Its layout is `--layout FILE` when
    /// given, else the `layout.toml` beside the recording when there is one (a dataset
    /// folder's), else the defaults; options given here override the layout's settings.
    pub input: PathBuf,
    /// Where to write the spikes: u8 `.npy` of shape `(T, rows, cols)` at 1 kHz.
    #[arg(long)]
    pub out: PathBuf,
    #[command(flatten)]
    pub read: ReadArgs,
    /// Also write the spikes as address events `t_ms,row,col` to this CSV file.
    #[arg(long)]
    pub events: Option<PathBuf>,
    #[command(flatten)]
    pub stages: StageArgs,
}

/// Runs `neurotex encode`.
pub fn run(args: EncodeArgs) -> Result<()> {
    if args.stages.options.causal {
        bail!("--causal fixes resting values and a scale on training recordings: use it with train, evaluate, features or compare (then predict or stream with the model)");
    }
    let pipeline = Pipeline::new(args.stages.pipeline()?)?;
    let reading = args.read.reading()?;
    let (layout, from) = reading.layout_for(&args.input, None)?;
    let mut inputs = vec![args.input.clone()];
    inputs.extend(args.read.layout.clone());
    if let LayoutFrom::Beside(path) = &from {
        inputs.push(path.clone());
    }
    check_output(&args.out, &inputs)?;
    if let Some(events) = &args.events {
        if events == &args.out || neurotex::io::same_file(events, &args.out) {
            bail!(
                "--events and --out name the same file, {}",
                args.out.display()
            );
        }
        check_output(events, &inputs)?;
    }
    args.read.say_layouts(std::slice::from_ref(&from));
    let format = reading.csv_format(&args.input, &layout)?;
    let recording = read_recording_as(&args.input, &layout, &format)?;
    let baseline = layout.baseline.unwrap_or_default();
    // `--gain auto` on the one recording being encoded.
    let pipeline = match args.stages.gain_target() {
        Some(target) => {
            let load = |_: usize| Ok(recording.clone());
            let c = calibrate_gain(&pipeline, &load, &[0], baseline, target)?;
            say_calibration(&c);
            let mut params = pipeline.params().clone();
            params.encoder.gain = c.gain;
            Pipeline::new(params)?
        }
        None => pipeline,
    };
    let encoded = pipeline.encode(&recording, baseline)?;
    report_conditions(std::slice::from_ref(&encoded));
    let spikes = &encoded.spikes;
    let raster = ndarray::Array3::from_shape_vec(
        (spikes.n_steps, spikes.rows, spikes.cols),
        spikes.to_raster(),
    )?;
    // Both files are written before either is put in place: a failure leaves neither.
    let events = match &args.events {
        Some(path) => Some(stage_file(path, "address events", |w| {
            write_events(w, spikes)
        })?),
        None => None,
    };
    let raster = stage_file(&args.out, "spike raster", |w| {
        ndarray_npy::WriteNpyExt::write_npy(&raster, w).map_err(std::io::Error::other)
    })?;
    raster.commit()?;
    if let Some(events) = events {
        events.commit()?;
    }
    eprintln!(
        "{} spikes from {} taxels over {} ms -> {}",
        spikes.total_spikes(),
        spikes.present.iter().filter(|&&p| p).count(),
        spikes.n_steps,
        args.out.display()
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
