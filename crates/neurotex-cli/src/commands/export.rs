//! `neurotex export`: a spiking model's network as a NIR graph, and the spike tensors its
//! input node receives, for other simulators and neuromorphic hardware.

use std::path::PathBuf;

use anyhow::Result;
use clap::{Args, Subcommand};
use neurotex::pipeline::Pipeline;
use neurotex::workflows::calibrated_pipeline;
use neurotex::workflows::export::{
    export_events, export_inputs, export_nir, export_xylo, load_spiking, network_shape,
    EventFormat, ExportInputsOptions, ExportNirOptions, ExportXyloOptions, NirConvention,
};
use neurotex::workflows::OpenOptions;

use crate::output::{check_binary, check_folder, check_output, save_to, shown, Shown};
use crate::stage_args::StageArgs;

/// `neurotex export`: what other tools read.
#[derive(Subcommand)]
pub enum ExportCommand {
    /// A spiking model's network (`train --classifier snn`) as a NIR graph (HDF5, NIR 1.0:
    /// Input → Affine → CubaLIF → Affine → CubaLIF readout that never fires → Output, for
    /// `--for nir`), the time step as `dt` (seconds) and the model's pipeline, grid and
    /// labels in the graph's metadata. `--for` writes it for snnTorch, Norse, sinabs or
    /// Rockpool, each loading it unchanged; `neurotex predict --model FILE.nir` runs the
    /// `nir`, `norse` and `snntorch` graphs again.
    Nir(ExportNirOptions),
    /// A spiking model trained for SynSense's Xylo Audio 2 (`train --classifier snn
    /// --snn-target xylo`) in the chip's integers (JSON): under `specification` the keyword
    /// arguments of Rockpool's `XyloSim.from_specification` (its bit-accurate simulator)
    /// and `config_from_specification` (a board's configuration), beside them the readouts'
    /// labels, `readout` and `score_scale`. XyloSim run with `output_mode="Vmem"` on
    /// `export inputs` gives neurotex's scores: the readout's membrane, its mean over the
    /// window divided by `score_scale`.
    Xylo(ExportXyloOptions),
    /// The spike tensors a spiking model's input node receives: one `(steps, inputs)`
    /// float32 NPY per recording of a dataset (spike counts per step, each weighing v / V in
    /// steps of travel; SA then FA taxels, row-major) and `index.csv` (`file,label,array`),
    /// so that the same network can be run or trained elsewhere on exactly neurotex's spikes.
    Inputs(ExportInputsOptions),
    /// A dataset's recordings encoded into spikes, written as a new address-event dataset:
    /// one event file per recording (`t,x,y,p` CSV in ms, or tonic's structured `.npy` in
    /// microseconds), ON (`p` 1) for the SA population and OFF (`p` 0) for the FA one,
    /// `manifest.csv` with each recording's `duration_s`, and `layout.toml` with the grid
    /// and its `[events]` table. Every command reads it back as the same spikes, so the
    /// spikes can go to event-based tools (tonic) and back.
    Events(ExportEventsArgs),
}

/// Options of `neurotex export events`.
#[derive(Args)]
pub struct ExportEventsArgs {
    /// The dataset folder whose recordings are encoded.
    #[arg(long)]
    pub dataset: PathBuf,
    /// The event dataset folder to create (new or empty).
    #[arg(long)]
    pub out: PathBuf,
    /// The event files' kind.
    #[arg(long, value_enum, default_value_t = EventFormat::Csv)]
    pub format: EventFormat,
    /// How the dataset folder is opened.
    #[command(flatten)]
    pub open: OpenOptions,
    #[command(flatten)]
    pub stages: StageArgs,
}

/// Runs `neurotex export nir`, `inputs` or `events`.
pub fn run(command: ExportCommand) -> Result<()> {
    match command {
        ExportCommand::Nir(args) => {
            check_output(&args.out, std::slice::from_ref(&args.model))?;
            check_binary(&args.out, "--out", "a NIR graph (HDF5)")?;
            let model = load_spiking(&args.model)?;
            save_to(&args.out, "the NIR graph", |p| {
                export_nir(&model, p, args.convention)
            })?;
            let net = model.network();
            if !net.reset.is_zero() && args.convention == NirConvention::Nir {
                eprintln!("note: the network's neurons subtract the threshold on a spike and NIR's neurons reset to zero, so the graph says `reset = subtract` in its metadata, which neurotex reads and other tools ignore (--for sinabs or --for rockpool write it for theirs)");
            }
            eprintln!(
                "NIR graph for {}: {} -> {}",
                args.convention.name(),
                network_shape(&model),
                shown(&args.out)
            );
        }
        ExportCommand::Xylo(args) => {
            check_output(&args.out, std::slice::from_ref(&args.model))?;
            let model = load_spiking(&args.model)?;
            save_to(&args.out, "the Xylo configuration", |p| {
                export_xylo(&model, p)
            })?;
            eprintln!(
                "Xylo Audio 2 configuration: {}, 8-bit weights -> {}",
                network_shape(&model),
                shown(&args.out)
            );
        }
        ExportCommand::Inputs(args) => {
            check_folder(&args.out, "--out")?;
            let _claim = neurotex::io::claim_output_dir(&args.out)?;
            let model = load_spiking(&args.model)?;
            let dataset = args.open.open(&args.dataset)?;
            let shown = Shown::new("starting");
            let (speeds, on) = (args.speeds.as_deref(), shown.callback());
            let n = export_inputs(&model, &dataset, speeds, &args.out, &on);
            shown.finish();
            let n = n?;
            eprintln!(
                "{n} recordings' input tensors ({} inputs, {} ms steps) -> {}",
                model.network().inputs,
                model.network().dt_ms,
                args.out.display()
            );
        }
        ExportCommand::Events(args) => {
            check_folder(&args.out, "--out")?;
            let _claim = neurotex::io::claim_output_dir(&args.out)?;
            let dataset = args.open.open(&args.dataset)?;
            let shown = Shown::new("starting");
            let on = shown.callback();
            let all: Vec<usize> = (0..dataset.entries.len()).collect();
            let written = calibrated_pipeline(&args.stages.options, &dataset, &all, &on)
                .and_then(|c| Ok(Pipeline::new(c.params)?))
                .and_then(|p| {
                    let n = export_events(&dataset, &p, &args.out, args.format, &on)?;
                    Ok((n, p.params().encoding))
                });
            shown.finish();
            let (n, encoding) = written?;
            eprintln!(
                "{n} recordings' {} spikes as address events -> {}",
                encoding.name(),
                args.out.display()
            );
        }
    }
    Ok(())
}
