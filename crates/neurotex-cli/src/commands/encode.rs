//! `neurotex encode`: one recording into a spike raster (and address events).

use std::io::Write;
use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use neurotex::calibrate::calibrate_gain;
use neurotex::encode::SpikeTrains;
use neurotex::pipeline::Pipeline;
use neurotex::recording::{read_recording, LayoutFile};
use neurotex::SampleRate;

use super::{report_conditions, say_calibration};
use crate::output::stage_file;
use crate::stage_args::StageArgs;

/// Options of `neurotex encode`.
#[derive(Args)]
pub struct EncodeArgs {
    /// The recording: `.npy` (f32/f64, `(T, rows, cols)` or `(T, channels)`) or `.csv`
    /// (header row, optional `t_ms`/`t_s` time column, one column per channel).
    pub input: PathBuf,
    /// Where to write the spikes: u8 `.npy` of shape `(T, rows, cols)` at 1 kHz.
    #[arg(long)]
    pub out: PathBuf,
    /// Sampling rate of the input in Hz (default: the layout's, else 1000; ignored when the
    /// CSV has a time column).
    #[arg(long, allow_negative_numbers = true)]
    pub fs: Option<SampleRate>,
    /// A `layout.toml` giving grid, channel map, mask or baseline for the input.
    #[arg(long)]
    pub layout: Option<PathBuf>,
    /// Also write the spikes as address events `t_ms,row,col` to this CSV file.
    #[arg(long)]
    pub events: Option<PathBuf>,
    #[command(flatten)]
    pub stages: StageArgs,
}

/// Runs `neurotex encode`.
pub fn run(args: EncodeArgs) -> Result<()> {
    let pipeline = Pipeline::new(args.stages.pipeline()?)?;
    let mut layout = match &args.layout {
        Some(path) => LayoutFile::read(path)?,
        None => LayoutFile::default(),
    };
    if let Some(fs) = args.fs {
        layout.fs = Some(fs.hz());
    }
    let recording = read_recording(&args.input, &layout)?;
    let baseline = layout.baseline.unwrap_or_default();
    // `--gain auto` on the one recording being encoded.
    let pipeline = match args.stages.gain_target() {
        Some(target) => {
            let load = |_: usize| Ok(recording.clone());
            let c = calibrate_gain(&pipeline, &load, &[0], baseline, target)?;
            say_calibration(&c);
            {
                let mut params = pipeline.params().clone();
                params.encoder.gain = c.gain;
                Pipeline::new(params)?
            }
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
