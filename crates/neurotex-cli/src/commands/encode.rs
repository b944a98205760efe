//! `neurotex encode`: one recording into a spike raster (and address events).

use std::io::Write;
use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use clap::Args;
use neurotex::calibrate::calibrate_gain;
use neurotex::encode::SpikeTrains;
use neurotex::pipeline::Pipeline;
use neurotex::recording::{read_recording_as, LayoutFile};
use neurotex::{Grid, SampleRate};

use super::{report_conditions, say_calibration};
use crate::csv_args::CsvArgs;
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
    /// Sampling rate of the input in Hz (default: the layout's, else 1000; ignored when the
    /// CSV has a time column: its stamps give the rate).
    #[arg(long, allow_negative_numbers = true)]
    pub fs: Option<SampleRate>,
    /// A `layout.toml` giving grid, channel map, mask, rate, baseline or CSV columns for the
    /// input (default: the `layout.toml` beside the input, if any).
    #[arg(long)]
    pub layout: Option<PathBuf>,
    /// Grid `ROWSxCOLS` to place the channels on, row-major (replaces the layout's grid,
    /// channel map and mask).
    #[arg(long)]
    pub grid: Option<Grid>,
    #[command(flatten)]
    pub csv: CsvArgs,
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
    let mut inputs = vec![args.input.clone()];
    inputs.extend(layout_path(&args));
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
    let layout = input_layout(&args)?;
    let format = layout
        .csv_format()
        .with_context(|| format!("reading the layout for {}", args.input.display()))?;
    let format = args.csv.apply(format);
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

/// The layout file read for the input: `--layout FILE`, else `layout.toml` beside it.
fn layout_path(args: &EncodeArgs) -> Option<PathBuf> {
    let beside = args
        .input
        .parent()
        .map(|dir| dir.join("layout.toml"))
        .filter(|p| p.is_file());
    args.layout.clone().or(beside)
}

/// The input's layout: `--layout FILE`, else `layout.toml` beside the input, else the
/// defaults; then `--fs` and `--grid` in place of the layout's.
fn input_layout(args: &EncodeArgs) -> Result<LayoutFile> {
    let mut layout = match layout_path(args).as_ref() {
        Some(path) => {
            if args.layout.is_none() {
                eprintln!(
                    "note: reading the layout beside the recording, {}",
                    path.display()
                );
            }
            LayoutFile::read(path)?
        }
        None => LayoutFile::default(),
    };
    if let Some(fs) = args.fs {
        layout.fs = Some(fs.hz());
    }
    if let Some(grid) = &args.grid {
        layout.rows = Some(grid.rows());
        layout.cols = Some(grid.cols());
        layout.channel_map = None;
        layout.mask = None;
    }
    Ok(layout)
}

/// Writes `t_ms,row,col`, one spike a line.
fn write_events(w: &mut dyn Write, spikes: &SpikeTrains) -> std::io::Result<()> {
    writeln!(w, "t_ms,row,col")?;
    for (t, r, c) in spikes.events() {
        writeln!(w, "{t},{r},{c}")?;
    }
    Ok(())
}
