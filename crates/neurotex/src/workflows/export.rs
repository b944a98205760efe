//! `export`: a spiking model's network as a NIR graph for other simulators and
//! neuromorphic hardware, the spike tensors its input node receives, and a dataset's spikes
//! as an address-event dataset.
use ndarray::Array2;
use ndarray_npy::write_npy;
use std::path::{Path, PathBuf};

use rayon::prelude::*;

use super::{OnProgress, OpenOptions};
use crate::error::DataError;
use crate::events::{write_events, Event, EventFile, EventsFormat};
use crate::nir::Convention;
use crate::pipeline::{Encoded, Encoding, Pipeline};
use crate::progress::Progress;
use crate::recording::{
    create_dataset_dir, write_layout, write_manifest, Dataset, LayoutFile, Meta,
};
use crate::snn::xylo::XyloNetwork;
use crate::snn::Target;
use crate::spiking_model::{network_input, SpikingModel};
use crate::Result;

/// Options of `neurotex export nir`.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct ExportNirOptions {
    /// The spiking model file (`train --classifier snn`).
    #[cfg_attr(feature = "cli", arg(long))]
    pub model: PathBuf,
    /// The NIR file to write.
    #[cfg_attr(feature = "cli", arg(long))]
    pub out: PathBuf,
    /// The importer the graph is written for, each loading it unchanged with the network's
    /// decisions and scores: `nir` (NIR's equations by forward Euler, seconds, `dt` in the
    /// metadata: Norse, neurotex, any NIR reader), `snntorch` (its importer steps at 0.1 ms:
    /// the constants are scaled to it), `norse` (the `nir` graph), `sinabs` or `rockpool`
    /// (time in steps, exact decays; for networks trained with `--snn-reset subtract`).
    #[cfg_attr(feature = "cli", arg(long = "for", alias = "convention", value_enum, default_value_t = NirConvention::Nir))]
    pub convention: NirConvention,
}

/// Options of `neurotex export xylo`.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct ExportXyloOptions {
    /// The spiking model file, trained with `--snn-target xylo`.
    #[cfg_attr(feature = "cli", arg(long))]
    pub model: PathBuf,
    /// The configuration file to write (JSON).
    #[cfg_attr(feature = "cli", arg(long))]
    pub out: PathBuf,
}

/// Options of `neurotex export inputs`.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct ExportInputsOptions {
    /// The spiking model whose pipeline and time step make the tensors.
    #[cfg_attr(feature = "cli", arg(long))]
    pub model: PathBuf,
    /// The dataset folder whose recordings are exported.
    #[cfg_attr(feature = "cli", arg(long))]
    pub dataset: PathBuf,
    /// The folder to write (new, empty, or an earlier export, which is replaced).
    #[cfg_attr(feature = "cli", arg(long))]
    pub out: PathBuf,
    /// Only the recordings at these speeds (mm/s, comma-separated); default all.
    #[cfg_attr(
        feature = "cli",
        arg(long, value_delimiter = ',', allow_hyphen_values = true)
    )]
    pub speeds: Option<Vec<crate::Speed>>,
    /// How the dataset folder is opened.
    #[cfg_attr(feature = "cli", command(flatten))]
    pub open: OpenOptions,
}

/// A spiking model's network in words: inputs, hidden neurons, readouts with their labels,
/// and the time step.
pub fn network_shape(model: &SpikingModel) -> String {
    let net = model.network();
    let recurrent = if net.recurrent() { " recurrent" } else { "" };
    format!(
        "{} inputs -> {}{recurrent} hidden neurons -> {} readout neurons ({}), dt {} ms",
        net.inputs,
        net.hidden,
        net.classes,
        model.labels().join(", "),
        net.dt_ms
    )
}

/// Which importer a NIR graph is written for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum NirConvention {
    /// NIR's equations by forward Euler in physical time (`dt` in the metadata, constants in
    /// seconds), the readout a CubaLIF that never fires: Norse, neurotex, any NIR reader.
    #[default]
    #[cfg_attr(feature = "cli", value(alias = "physical"))]
    Nir,
    /// snnTorch's importer, which steps every graph at dt = 0.1 ms: the same graph with its
    /// constants scaled so that its decays per step are the network's (Norse reads it too).
    Snntorch,
    /// Norse's `from_nir(graph, dt=graph.metadata["dt"])`: the `nir` graph.
    Norse,
    /// sinabs's `from_nir`: time in steps and exact decays, for a network trained with
    /// `--snn-reset subtract` (sinabs's neurons subtract the threshold on a spike).
    Sinabs,
    /// Rockpool's `from_nir`: time in steps and exact decays, for a network trained with
    /// `--snn-reset subtract` (Rockpool's neurons subtract the threshold on a spike).
    Rockpool,
}

impl NirConvention {
    /// The name typed after `--for`.
    pub fn name(self) -> &'static str {
        match self {
            NirConvention::Norse => "norse",
            other => Convention::from(other).name(),
        }
    }
}

impl From<NirConvention> for Convention {
    fn from(c: NirConvention) -> Self {
        match c {
            NirConvention::Nir | NirConvention::Norse => Convention::Physical,
            NirConvention::Snntorch => Convention::Snntorch,
            NirConvention::Sinabs => Convention::Sinabs,
            NirConvention::Rockpool => Convention::Rockpool,
        }
    }
}

/// Writes `model`'s network as a NIR graph to `out`, whole or not at all.
///
/// # Errors
/// The file cannot be written.
pub fn export_nir(model: &SpikingModel, out: &Path, convention: NirConvention) -> Result<()> {
    if convention == NirConvention::Norse && !model.network().reset.is_zero() {
        let why = "this network's neurons subtract the threshold (--snn-reset subtract), and Norse's reset to zero: export it --for sinabs or --for rockpool, or --for nir for neurotex";
        return Err(crate::error::OptionsError::Conflict(why.into()).into());
    }
    if model.network().target == Target::Xylo {
        let why = "this network was trained for Xylo (--snn-target xylo), and predicts in the chip's integers, which a NIR graph does not hold: export it with `export xylo`";
        return Err(crate::error::OptionsError::Conflict(why.into()).into());
    }
    let bytes = model.to_nir(convention.into())?;
    crate::io::write_atomic(out, |w| w.write_all(&bytes))
}

/// The format name of a Xylo configuration file.
pub const XYLO_FORMAT: &str = "neurotex-xylo";

/// Writes `model`'s network in the Xylo chip's integers to `out` (JSON), whole or not at
/// all: under `specification` the keyword arguments of Rockpool's
/// `XyloSim.from_specification` (and of `config_from_specification` for a board), beside
/// them the labels of the readouts in order, how scores are read and the readout's scale.
///
/// # Errors
/// A network not trained for Xylo (`--snn-target xylo`), or the file cannot be written.
pub fn export_xylo(model: &SpikingModel, out: &Path) -> Result<()> {
    let net = model.network();
    if net.target != Target::Xylo {
        // What the chip has no circuit for, named, so the retraining does not meet them as
        // refusals one at a time.
        let unsupported: Vec<&str> = [
            (
                net.adaptation.is_some(),
                "--snn-adapt-ms (adaptive thresholds)",
            ),
            (!net.delays.is_empty(), "--snn-delay-ms (synaptic delays)"),
        ]
        .into_iter()
        .filter_map(|(has, option)| has.then_some(option))
        .collect();
        let without = match unsupported.is_empty() {
            true => String::new(),
            false => format!(
                ", and without {}, which the chip does not have",
                unsupported.join(" or ")
            ),
        };
        let why = format!("this network was trained for neurotex's float network; a Xylo configuration needs a network trained within the chip's limits: train it with --classifier snn --snn-target xylo{without}");
        return Err(crate::error::OptionsError::Conflict(why).into());
    }
    let chip = XyloNetwork::quantise(net)?;
    let file = serde_json::json!({
        "format": XYLO_FORMAT,
        "version": 1,
        "labels": model.labels(),
        "readout": chip.readout.name(),
        "score_scale": chip.score_scale,
        "dt_ms": chip.dt_ms,
        "output_mode": "Vmem",
        "specification": chip.specification(),
    });
    let text = serde_json::to_string(&file).expect("JSON of numbers and strings");
    crate::io::write_atomic(out, |w| w.write_all(text.as_bytes()))
}

/// Loads the spiking model at `path` (a model file or a NIR graph written by neurotex):
/// only a spiking network has a NIR graph and input tensors.
///
/// # Errors
/// What [`SpikingModel::load`] refuses: a feature model is named as such, a damaged file as
/// damaged.
pub fn load_spiking(path: &Path) -> Result<SpikingModel> {
    SpikingModel::load(path)
}

/// Writes, into the folder `out` (new, or an earlier export), every recording of `dataset`
/// (those at `speeds` when given) as the `(steps, inputs)` float32 spike counts the
/// network's input node receives (`<n>.npy`, row-major), and `index.csv`
/// (`file,label,array`). Returns the recordings written.
///
/// # Errors
/// A speed the dataset has no recording at, a recording that cannot be read or encoded, or
/// `out` holds files neurotex did not write there (an earlier export is replaced).
pub fn export_inputs(
    model: &SpikingModel,
    dataset: &Dataset,
    speeds: Option<&[crate::Speed]>,
    out: &Path,
    on: OnProgress,
) -> Result<usize> {
    let all: Vec<usize> = match speeds {
        Some(speeds) => dataset.indices_at(speeds)?,
        None => (0..dataset.entries.len()).collect(),
    };
    on(Progress::Stage("encoding", all.len()));
    let encoded = model
        .pipeline()
        .encode_dataset(dataset, &all, &|| on(Progress::Tick))?;
    let net = model.network();
    crate::io::replace_dir(out, |dir| {
        let names: Vec<String> = (0..encoded.len()).map(|i| format!("{i:05}.npy")).collect();
        encoded
            .par_iter()
            .zip(&names)
            .map(|(e, name)| {
                let input = network_input(net, e)?;
                let path = dir.join(name);
                let array = Array2::from_shape_vec((input.steps(), input.inputs), input.dense())
                    .expect("one count per step and input");
                write_npy(&path, &array)
                    .map_err(|err| DataError::write(&path, std::io::Error::other(err)).into())
            })
            .collect::<Result<Vec<()>>>()?;
        let index = dir.join("index.csv");
        let mut csv = String::from("file,label,array\n");
        for (e, name) in encoded.iter().zip(&names) {
            csv.push_str(&format!(
                "{},{},{name}\n",
                quote(&e.meta.file),
                quote(&e.meta.label)
            ));
        }
        std::fs::write(&index, csv).map_err(|err| DataError::write(&index, err))?;
        Ok(encoded.len())
    })
}

/// A CSV field, quoted when it holds a comma, a quote or a line break.
fn quote(field: &str) -> String {
    match field.contains([',', '"', '\n', '\r']) {
        true => format!("\"{}\"", field.replace('"', "\"\"")),
        false => field.to_string(),
    }
}

/// The file kind `export events` writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum EventFormat {
    /// CSV `t,x,y,p`, `t` in ms.
    #[default]
    Csv,
    /// tonic's structured `.npy` (`x, y, t, p` as int64), `t` in microseconds.
    Npy,
}

impl From<EventFormat> for EventFile {
    fn from(f: EventFormat) -> Self {
        match f {
            EventFormat::Csv => EventFile::Csv,
            EventFormat::Npy => EventFile::Npy,
        }
    }
}

/// The events of one encoded recording: its first population's spikes as ON (`p` 1) and
/// its FA population's as OFF (`p` 0), or the FA spikes of an `fa` encoding as OFF; in
/// time order.
pub fn encoded_events(encoded: &Encoded, encoding: Encoding) -> Vec<Event> {
    let first = match encoding {
        Encoding::Fa => 0,
        Encoding::Sa | Encoding::SaFa => 1,
    };
    let mut events: Vec<Event> = std::iter::once((&encoded.spikes, first))
        .chain(encoded.fa.as_ref().map(|fa| (fa, 0)))
        .flat_map(|(trains, p)| {
            trains
                .events()
                .into_iter()
                .map(move |(t_ms, row, col)| Event {
                    t_ms,
                    y: row as u32,
                    x: col as u32,
                    p,
                })
        })
        .collect();
    events.sort_unstable_by_key(|e| (e.t_ms, std::cmp::Reverse(e.p), e.y, e.x));
    events
}

/// Writes `dataset`'s recordings, encoded by `pipeline`, as a new event dataset in `out`
/// (which must not exist or be empty): one event file per recording (`<n>_<name>.csv` or
/// `.npy`), `manifest.csv` with each recording's fields and its `duration_s` (the encoded
/// length; the slide's times are dropped, as the events hold only the selected phase), and
/// `layout.toml` with the grid and the `[events]` table. Reading it back gives the same
/// spike trains. Returns the recordings written.
///
/// # Errors
/// A recording that cannot be read or encoded, recordings on different grids, or `out`
/// cannot be created.
pub fn export_events(
    dataset: &Dataset,
    pipeline: &Pipeline,
    out: &Path,
    kind: EventFormat,
    on: OnProgress,
) -> Result<usize> {
    let all: Vec<usize> = (0..dataset.entries.len()).collect();
    let (encoded, grid) = super::encode_all(dataset, pipeline, &all, on)?;
    let kind = EventFile::from(kind);
    let encoding = pipeline.params().encoding;
    create_dataset_dir(out, |dir| {
        let names: Vec<String> = encoded
            .iter()
            .enumerate()
            .map(|(i, e)| {
                let stem = Path::new(&e.meta.file)
                    .file_stem()
                    .map_or(String::new(), |s| s.to_string_lossy().into_owned());
                format!("{i:05}_{stem}.{}", kind.extension())
            })
            .collect();
        encoded
            .par_iter()
            .zip(&names)
            .map(|(e, name)| {
                let path = dir.join(name);
                let events = encoded_events(e, encoding);
                std::fs::File::create(&path)
                    .and_then(|f| {
                        let mut w = std::io::BufWriter::new(f);
                        write_events(&mut w, &events, kind)?;
                        std::io::Write::flush(&mut w)
                    })
                    .map_err(|err| DataError::write(&path, err).into())
            })
            .collect::<Result<Vec<()>>>()?;
        let metas: Vec<Meta> = encoded
            .iter()
            .zip(&names)
            .map(|(e, name)| {
                let mut meta = Meta {
                    file: name.clone(),
                    slide_start_s: None,
                    slide_end_s: None,
                    ..e.meta.clone()
                };
                let duration = e.spikes.n_steps as f64 / 1000.0;
                meta.extra.insert("duration_s".into(), duration.to_string());
                meta
            })
            .collect();
        write_manifest(dir, &metas)?;
        let masked = grid.present().iter().any(|&p| !p);
        let layout = LayoutFile {
            rows: Some(grid.rows()),
            cols: Some(grid.cols()),
            mask: masked.then(|| {
                grid.present()
                    .chunks(grid.cols())
                    .map(|row| row.iter().map(|&p| if p { '1' } else { '0' }).collect())
                    .collect()
            }),
            events: Some(EventsFormat::new(kind.time_unit())),
            ..LayoutFile::default()
        };
        write_layout(dir, &layout)?;
        Ok(encoded.len())
    })
}
