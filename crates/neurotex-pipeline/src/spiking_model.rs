//! Saved spiking classifiers: a network trained on a dataset's spike trains
//! ([`crate::snn`]), with the pipeline that makes those spikes, in one versioned JSON file
//! of its own format (`neurotex-snn-model`). Unlike a feature model ([`crate::model`]),
//! which keeps its training rows and re-fits on load, it keeps the trained weights:
//! training a network takes seconds to minutes, and its weights are what a neuromorphic
//! chip or another simulator runs. The weights are float32 values, so a float32 export
//! holds them exactly.

use std::path::{Path, PathBuf};

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::{ClassifyError, DataError, ModelError, Result};
use crate::model::{Prediction, Provenance, Score};
use crate::nir::{Convention, NirFrom};
use crate::pipeline::{taxel_cells, Encoded, Pipeline, PipelineParams};
use crate::recording::{Baseline, FileReading, LayoutFrom};
use crate::snn::{
    event_weight, softmax, step_ms, train::TrainingLog, Network, SnnParams, SpikeInput, Travel,
};
use crate::values::Grid;

/// The `format` field of a spiking model file.
pub const FORMAT: &str = crate::error::SNN_MODEL_FORMAT;
/// The version of the spiking model format this neurotex writes and reads.
pub const VERSION: u64 = 1;

/// How the network was trained.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SpikingTraining {
    /// The training dataset.
    pub dataset: Provenance,
    /// Training recordings (validation split included).
    pub recordings: usize,
    /// Epochs run.
    pub epochs: usize,
    /// The epoch whose weights were kept (lowest validation loss).
    pub best_epoch: usize,
    /// Its validation loss.
    pub validation_loss: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct SpikingFile {
    format: String,
    version: u64,
    neurotex_version: String,
    pipeline: PipelineParams,
    grid: Grid,
    /// The training parameters.
    classifier: SnnParams,
    labels: Vec<String>,
    training: SpikingTraining,
    network: Network,
}

/// A trained spiking classifier and the pipeline that feeds it.
#[derive(Debug, Clone)]
pub struct SpikingModel {
    file: SpikingFile,
    pipeline: Pipeline,
}

impl PartialEq for SpikingModel {
    fn eq(&self, other: &Self) -> bool {
        self.file == other.file
    }
}

/// Whether the file starts with HDF5's signature (a NIR graph).
pub fn is_hdf5(path: &Path) -> bool {
    use std::io::Read;
    let mut head = [0u8; 8];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .is_ok_and(|()| head == *b"\x89HDF\r\n\x1a\n")
}

/// Whether the file is a NIR graph: HDF5's signature, or a `.nir` name.
fn is_graph(path: &Path) -> bool {
    is_hdf5(path)
        || path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("nir"))
}

/// A recording's spikes as the network's input: its populations in the pipeline's order
/// (SA then FA for `sa+fa`), each taxel one input, binned to steps of `step_ms` (whole or
/// fractional: a network counting time in travel, [`Network::step_ms`]).
pub fn spike_input(encoded: &Encoded, step_ms: f64) -> SpikeInput {
    let populations: Vec<_> = encoded.populations().collect();
    match step_ms.fract() == 0.0 && step_ms >= 1.0 {
        true => SpikeInput::from_trains(&populations, step_ms as u32),
        false => SpikeInput::from_trains(&populations, 1).rebin(step_ms),
    }
}

/// The input of a recording to `net`, in its steps for the recording's speed.
///
/// # Errors
/// A network counting time in travel, and a recording without a sliding speed.
pub fn network_input(net: &Network, encoded: &Encoded) -> Result<SpikeInput> {
    let step = net
        .step_ms(encoded.meta.speed_mm_s)
        .map_err(|why| ClassifyError::BadFeatures(format!("{}: {why}", encoded.meta.file)))?;
    Ok(in_steps_of(encoded, net.dt_ms, step))
}

/// A recording's input in steps of `step_ms` for a network of step `dt_ms`, each event
/// weighed as [`event_weight`] says.
fn in_steps_of(encoded: &Encoded, dt_ms: u32, step_ms: f64) -> SpikeInput {
    spike_input(encoded, step_ms).scaled(event_weight(dt_ms, step_ms))
}

/// The class a network's scores choose (the first of the highest) and every class's
/// share: the softmax of the scores.
pub fn decide(scores: &[f64]) -> (usize, Vec<f64>) {
    let shares = softmax(scores);
    let best = (0..shares.len()).fold(0, |b, c| if shares[c] > shares[b] { c } else { b });
    (best, shares)
}

/// Two values as JSON, as a model file writes them.
fn shown(a: &impl Serialize, b: &impl Serialize) -> [String; 2] {
    [serde_json::to_string(a), serde_json::to_string(b)].map(Result::unwrap_or_default)
}

/// A field checked by [`trained_as_said`]: its name, whether the network's value `a` and
/// the training parameters' `b` are equal, and both as the file writes them.
fn same<T: PartialEq + Serialize>(
    name: &'static str,
    a: &T,
    b: &T,
) -> (&'static str, bool, [String; 2]) {
    (name, a == b, shown(a, b))
}

/// Checks that a model file's network is the one its training parameters make: the same
/// hidden layer, step, readout, reset, recurrence, time constants (to a float's rounding in
/// JSON), whether each neuron has decays of its own, its adaptive thresholds, whether its
/// synapses have delays and whether it counts time in travel.
/// A NIR graph's network is not checked so: one run with `--like` comes from another tool,
/// whatever the spiking model lending its pipeline was trained with.
fn trained_as_said(net: &Network, snn: &SnnParams) -> std::result::Result<(), String> {
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * a.abs().max(b.abs());
    // Each field: whether the two agree, and each one's value as the file writes it.
    let travel = match snn.travel {
        Travel::Off => net.travel_mm_s.is_none(),
        Travel::Median => true,
        Travel::At(v) => net.travel_mm_s == Some(v),
    };
    let fields = [
        same("hidden", &net.hidden, &snn.hidden),
        same("dt_ms", &net.dt_ms, &snn.dt_ms),
        same("readout", &net.readout, &snn.readout),
        same("reset", &net.reset, &snn.reset),
        same("target", &net.target, &snn.target),
        same("w_rec", &net.recurrent(), &snn.recurrent),
        same("adaptation", &net.adaptation, &snn.adaptation()),
        (
            "alpha",
            net.own_decays() == snn.train_decays,
            [String::new(), String::new()],
        ),
        (
            "delays",
            net.delays.is_empty() == snn.delay_ms.is_none(),
            [String::new(), String::new()],
        ),
        ("travel_mm_s", travel, shown(&net.travel_mm_s, &snn.travel)),
        (
            "tau_syn_ms",
            close(net.tau_syn_ms, snn.tau_syn_ms),
            shown(&net.tau_syn_ms, &snn.tau_syn_ms),
        ),
        (
            "tau_mem_ms",
            close(net.tau_mem_ms, snn.tau_mem_ms),
            shown(&net.tau_mem_ms, &snn.tau_mem_ms),
        ),
        (
            "tau_out_ms",
            close(net.tau_out_ms, snn.tau_out_ms),
            shown(&net.tau_out_ms, &snn.tau_out_ms),
        ),
    ];
    match fields.iter().find(|(_, same, _)| !same) {
        None => Ok(()),
        Some(("alpha", ..)) => Err(format!(
            "the training parameters (`classifier.train_decays` {}) {} each neuron's own decays, and the network {} them (`network.alpha`, `network.beta`)",
            snn.train_decays,
            if snn.train_decays { "train" } else { "do not train" },
            if net.own_decays() { "has" } else { "lacks" }
        )),
        Some((name, _, [network, classifier])) => Err(format!(
            "field `network.{name}` ({network}) differs from the training parameters (`classifier`: {classifier}) that made the network: one of the two was changed after training"
        )),
    }
}

impl SpikingModel {
    /// Trains a network with `snn` on the recordings `encoded` (conditioned and encoded
    /// with `params`, all on `grid`), calling `each_epoch` after each epoch run.
    ///
    /// # Errors
    /// Fewer than two classes, a class too small for the validation split, recordings
    /// without spikes, or a broken parameter.
    pub fn train(
        params: &PipelineParams,
        encoded: &[Encoded],
        grid: &Grid,
        (snn, each_epoch): (SnnParams, &(dyn Fn() + Sync)),
        dataset: Provenance,
    ) -> Result<(SpikingModel, TrainingLog)> {
        let snn = snn.check()?;
        let mut labels: Vec<String> = Vec::new();
        for e in encoded {
            if !labels.contains(&e.meta.label) {
                labels.push(e.meta.label.clone());
            }
        }
        if labels.len() < 2 {
            let label = labels.first().cloned().unwrap_or_default();
            return Err(ClassifyError::OneClass {
                label,
                what: "train",
            }
            .into());
        }
        let y: Vec<usize> = encoded
            .iter()
            .map(|e| labels.iter().position(|l| *l == e.meta.label).unwrap_or(0))
            .collect();
        let reference = snn
            .travel
            .reference(encoded.iter().map(|e| e.meta.speed_mm_s))?;
        let inputs: Vec<SpikeInput> = encoded
            .par_iter()
            .map(|e| {
                let step = step_ms(snn.dt_ms, reference, e.meta.speed_mm_s);
                let why = |why| ClassifyError::BadFeatures(format!("{}: {why}", e.meta.file));
                step.map(|s| in_steps_of(e, snn.dt_ms, s)).map_err(why)
            })
            .collect::<std::result::Result<_, ClassifyError>>()?;
        let refs: Vec<&SpikeInput> = inputs.iter().collect();
        let (mut network, log) = crate::snn::fit_with(&snn, &refs, &y, labels.len(), each_epoch)
            .map_err(|e| match e {
                ClassifyError::ValidationTooSmall { class, count } => {
                    ClassifyError::ValidationTooSmall {
                        class: class.parse::<usize>().map_or(class, |c| labels[c].clone()),
                        count,
                    }
                }
                other => other,
            })?;
        network.travel_mm_s = reference;
        let file = SpikingFile {
            format: FORMAT.into(),
            version: VERSION,
            neurotex_version: env!("CARGO_PKG_VERSION").into(),
            pipeline: params.clone(),
            grid: grid.clone(),
            classifier: snn,
            labels,
            training: SpikingTraining {
                dataset,
                recordings: encoded.len(),
                epochs: log.epochs,
                best_epoch: log.best_epoch,
                validation_loss: log.validation_loss,
            },
            network,
        };
        Ok((SpikingModel::assemble(file)?, log))
    }

    /// Checks a file's content: the network's weights, that its shape fits the pipeline
    /// (one input per taxel and population, one readout per label), the training
    /// parameters' rules and what training guarantees of labels and provenance.
    fn assemble(file: SpikingFile) -> Result<SpikingModel> {
        let inconsistent = |what: String| -> crate::Error { ModelError::Inconsistent(what).into() };
        file.network.check()?;
        file.classifier
            .check()
            .map_err(|e| inconsistent(format!("field `classifier`: {e}")))?;
        let t = &file.training;
        if !(1 <= t.best_epoch && t.best_epoch <= t.epochs && t.epochs <= file.classifier.epochs)
            || t.recordings < file.labels.len()
        {
            return Err(inconsistent(format!(
                "field `training`: best epoch {} of {} run (at most {}), on {} recordings of {} classes; training keeps an epoch it ran, on at least one recording per class",
                t.best_epoch, t.epochs, file.classifier.epochs, t.recordings, file.labels.len()
            )));
        }
        let grid = Grid::masked(
            file.grid.rows(),
            file.grid.cols(),
            file.grid.present().to_vec(),
        )?;
        let taxels = taxel_cells(grid.present()).count();
        let populations = file.pipeline.encoding.prefixes().len();
        let net = &file.network;
        if net.inputs != taxels * populations {
            return Err(inconsistent(format!(
                "the network has {} inputs, but the pipeline gives {taxels} taxels x {populations} population(s) = {}",
                net.inputs,
                taxels * populations
            )));
        }
        if net.classes != file.labels.len() {
            return Err(inconsistent(format!(
                "the network has {} outputs for {} labels",
                net.classes,
                file.labels.len()
            )));
        }
        crate::model::check_trained(&file.labels, &file.pipeline, &grid, &t.dataset)
            .map_err(inconsistent)?;
        let mut resolved = file.pipeline.clone();
        let baseline = resolved.preprocess.baseline;
        resolved.preprocess.baseline = Some(baseline.unwrap_or(file.training.dataset.baseline));
        let pipeline = Pipeline::new(resolved)?;
        Ok(SpikingModel { file, pipeline })
    }

    /// Writes the model to `path` as pretty-printed JSON, whole or not at all.
    ///
    /// # Errors
    /// The file cannot be written.
    pub fn save(&self, path: &Path) -> Result<()> {
        crate::io::write_atomic(path, |w| {
            serde_json::to_writer_pretty(&mut *w, &self.file).map_err(std::io::Error::other)?;
            writeln!(w)
        })
    }

    /// The network as a NIR graph (HDF5 bytes), the model file without its weights in the
    /// graph's metadata ([`crate::nir`]).
    ///
    /// # Errors
    /// The graph cannot be written.
    pub fn to_nir(&self, convention: Convention) -> Result<Vec<u8>> {
        crate::nir::check_neurons(&self.file.network, convention)?;
        let mut value = serde_json::to_value(&self.file)
            .map_err(|e| ModelError::Inconsistent(e.to_string()))?;
        if let Some(map) = value.as_object_mut() {
            map.remove("network");
        }
        crate::nir::to_bytes(&self.file.network, &value.to_string(), convention)
    }

    /// A model from a NIR graph at `path`: its network, and the pipeline, grid and labels
    /// from the graph's `neurotex_model` metadata, or else from `like` (a spiking model
    /// whose pipeline feeds the network: a graph trained elsewhere on neurotex's inputs).
    ///
    /// # Errors
    /// A graph of another shape (see [`crate::nir::read`]), a graph without neurotex's
    /// metadata and no `like`, or a network that does not fit the pipeline, naming the file.
    pub fn from_nir(path: &Path, like: Option<&SpikingModel>) -> Result<SpikingModel> {
        SpikingModel::from_nir_as(path, like, NirFrom::Nir)
    }

    /// As [`SpikingModel::from_nir`], for a graph written by `from` (snnTorch's and Norse's
    /// exporters leave out the time step, which is then `like`'s, and write their
    /// constants in conventions of their own: [`NirFrom`]).
    ///
    /// # Errors
    /// As [`SpikingModel::from_nir`], and what [`crate::nir::read_as`] refuses.
    pub fn from_nir_as(
        path: &Path,
        like: Option<&SpikingModel>,
        from: NirFrom,
    ) -> Result<SpikingModel> {
        let step_s = like.map(|l| f64::from(l.file.network.dt_ms) / 1000.0);
        let graph = crate::nir::read_as(path, from, step_s)?;
        let damaged = |reason: String| -> crate::Error {
            ModelError::Nir {
                path: path.to_path_buf(),
                reason,
            }
            .into()
        };
        let mut file = match (like, &graph.neurotex_model) {
            (Some(_), Some(_)) => {
                return Err(damaged("the graph carries its own neurotex pipeline (it was written by neurotex export nir); a pipeline to run with (--like) applies only to a graph without one: run it without --like".into()))
            }
            (Some(like), None) => like.file.clone(),
            (None, Some(json)) => {
                let mut value: serde_json::Value = serde_json::from_str(json).map_err(|e| damaged(format!("its neurotex_model metadata: {e}")))?;
                value["network"] = serde_json::to_value(&graph.network).map_err(|e| damaged(crate::error::json_error(&e)))?;
                serde_json::from_value::<SpikingFile>(value).map_err(|e| damaged(format!("its neurotex_model metadata: {e}")))?
            }
            (None, None) => {
                return Err(damaged("a NIR graph not written by neurotex does not say which pipeline makes its input spikes: give a neurotex spiking model trained with that pipeline (--like MODEL.json)".into()))
            }
        };
        file.network = graph.network;
        SpikingModel::assemble(file).map_err(|e| damaged(e.to_string()))
    }

    /// Whether the file at `path` claims to be a spiking model (its `format`, HDF5's
    /// signature or a `.nir` name: a NIR graph), read without checking the rest.
    pub fn is_spiking(path: &Path) -> bool {
        if is_graph(path) {
            return true;
        }
        #[derive(Deserialize)]
        struct Header {
            format: Option<serde_json::Value>,
        }
        let Ok(bytes) = std::fs::read(path) else {
            return false;
        };
        serde_json::from_slice::<Header>(&bytes)
            .ok()
            .and_then(|h| h.format)
            .is_some_and(|f| f == FORMAT)
    }

    /// Reads a spiking model file written by [`SpikingModel::save`].
    ///
    /// # Errors
    /// An unreadable file, another format or version, or damaged content (a non-finite
    /// weight, a network that does not fit the pipeline), naming the file and the rule.
    pub fn load(path: &Path) -> Result<SpikingModel> {
        if is_graph(path) {
            return SpikingModel::from_nir(path, None);
        }
        use crate::model::{invalid, unreadable};
        let bytes = std::fs::read(path).map_err(|e| DataError::io(path, e))?;
        let value: serde_json::Value =
            serde_json::from_slice(&bytes).map_err(|e| unreadable(path, &e))?;
        let (format, version) = (value.get("format"), value.get("version"));
        crate::model::check_header(path, format, version, (FORMAT, VERSION))?;
        // Read from the bytes rather than the value, so that an error says where it is.
        let file: SpikingFile = serde_json::from_slice(&bytes).map_err(|e| unreadable(path, &e))?;
        // The training parameters first: a value out of range there is named as such, not as
        // a network that differs from them.
        let rules =
            |e: crate::error::ParamError| format!("the training parameters (`classifier`): {e}");
        file.classifier
            .check()
            .map_err(|e| invalid(path, rules(e)))?;
        trained_as_said(&file.network, &file.classifier).map_err(|why| invalid(path, why))?;
        SpikingModel::assemble(file).map_err(|e| invalid(path, e.to_string()))
    }

    /// Reads and encodes `files` as the training recordings were (see
    /// [`crate::model::Model::encode_files`]).
    ///
    /// # Errors
    /// A file that cannot be read or encoded, named.
    pub fn encode_files(
        &self,
        files: &[PathBuf],
        reading: &FileReading,
    ) -> Result<(Vec<Encoded>, Vec<LayoutFrom>)> {
        let remembered = self.file.training.dataset.layout.as_ref();
        crate::model::encode_files(&self.pipeline, self.baseline(), remembered, files, reading)
    }

    /// Predicts each encoded recording's class, in parallel.
    ///
    /// # Errors
    /// A recording on another grid than the model's, or sampled for a network trained on
    /// events.
    pub fn predict(&self, encoded: &[Encoded]) -> Result<Vec<Prediction>> {
        for e in encoded {
            self.check_grid(e)?;
            crate::model::check_source(&self.file.training.dataset, e)?;
        }
        let net = &self.file.network;
        encoded
            .par_iter()
            .map(|e| {
                let (best, shares) = decide(&net.scores(&network_input(net, e)?));
                Ok(Prediction {
                    predicted: self.file.labels[best].clone(),
                    shares,
                })
            })
            .collect()
    }

    /// Checks that a recording is on the model's grid.
    ///
    /// # Errors
    /// [`ModelError::OtherGrid`], naming the recording.
    pub fn check_grid(&self, encoded: &Encoded) -> Result<()> {
        if encoded.spikes.grid() == self.file.grid {
            return Ok(());
        }
        Err(ModelError::OtherGrid {
            file: encoded.meta.file.clone(),
            found: encoded.spikes.grid(),
            expected: self.file.grid.clone(),
        }
        .into())
    }

    /// Scores predictions against true labels (see [`crate::model::Model::score`]).
    ///
    /// # Errors
    /// No predictions, or a label the model does not know.
    pub fn score(&self, truth: &[String], predictions: &[Prediction]) -> Result<Score> {
        crate::model::score(&self.file.labels, truth, predictions)
    }

    /// The class labels, in the order of the network's outputs.
    pub fn labels(&self) -> &[String] {
        &self.file.labels
    }

    /// The network.
    pub fn network(&self) -> &Network {
        &self.file.network
    }

    /// The training parameters.
    pub fn params(&self) -> SnnParams {
        self.file.classifier
    }

    /// How training went.
    pub fn training(&self) -> &SpikingTraining {
        &self.file.training
    }

    /// The taxel grid recordings must have.
    pub fn grid(&self) -> &Grid {
        &self.file.grid
    }

    /// The pipeline as trained.
    pub fn pipeline_params(&self) -> &PipelineParams {
        &self.file.pipeline
    }

    /// The planned pipeline, the baseline resolved.
    pub fn pipeline(&self) -> &Pipeline {
        &self.pipeline
    }

    /// The baseline applied to every recording.
    pub fn baseline(&self) -> Baseline {
        self.file
            .pipeline
            .preprocess
            .baseline
            .unwrap_or(self.file.training.dataset.baseline)
    }
}
