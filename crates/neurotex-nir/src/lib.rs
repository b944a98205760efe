//! NIR, the Neuromorphic Intermediate Representation (Pedersen et al., Nature
//! Communications 2024; the `nir` Python package, 1.0): a spiking model's network as a
//! graph of continuous-time nodes in an HDF5 file, which snnTorch, Norse, Rockpool, Lava
//! and the toolchains of Loihi, SpiNNaker, Xylo and Speck read.
//!
//! **The graph** neurotex writes and reads: `input` (Input, one channel per taxel and
//! population) → `fc1` (Affine) → `lif1` (CubaLIF) → `fc2` (Affine) → `li` (LI) →
//! `output` (Output), with the time step in the graph's metadata (`dt`, seconds) and, under
//! `neurotex_model`, the model file without its weights (pipeline, grid, labels, training):
//! the Izhikevich encoder in front of the network has no NIR node, so its parameters travel
//! as metadata. Output `i` is the model's `i`-th label.
//!
//! **From discrete to continuous time.** NIR's nodes are ODEs
//! (`τ_syn dI/dt = -I + w_in a`, `τ_mem dv/dt = v_leak - v + r I`, spike and reset to
//! `v_reset` when `v > v_threshold`; `τ dv/dt = v_leak - v + r a` for LI). neurotex's
//! network ([`neurotex_learn::snn`]) is their forward-Euler step at `dt`, the current first and the
//! membrane with the new current, as snnTorch's `Synaptic` and Norse's `LIFBox` step:
//! `α = 1 - dt/τ_syn`, `β = 1 - dt/τ_mem`, `κ = 1 - dt/τ`, so the export writes
//! `τ_syn = dt/(1-α)`, `τ_mem = dt/(1-β)`, `τ = dt/(1-κ)` and the gains that make each
//! step add its input once: `w_in = τ_syn/dt`, `r = τ_mem/dt` (LIF), `r = τ/dt` (LI),
//! `v_leak = 0`, `v_threshold = 1`, `v_reset = 0`. Reading a graph inverts this; gains,
//! thresholds and leaks that differ per neuron are folded into the weights and biases
//! (dividing by the threshold, adding the leak to the readout's bias), while the decays must
//! be one per layer, as neurotex's network has.
//!
//! **Recurrent networks** (`--snn-recurrent`) add a `rec` node (Linear, `(hidden, hidden)`)
//! on the edges `lif1 → rec → lif1`, the form snnTorch's and Norse's importers read as a
//! recurrent layer. NIR's equations leave the loop's delay to the simulator; neurotex's
//! network, like theirs, feeds a step's spikes into the next step's current.
//!
//! **Graphs written by other tools** ([`read_as`], [`NirFrom`]). A LIF hidden node is a
//! layer without synaptic current (`α = 0`: the current is the step's input), as snnTorch's
//! `Leaky` and Norse's `LIFBoxCell` step. snnTorch's `export_to_nir` writes no `dt`, its
//! constants for a step of 1e-4 s whatever the network's, and a recurrent layer as a graph
//! nested in the graph (`Input → LIF → Output` with the loop `LIF → w_rec → LIF`), which is
//! read as the loop on a flat graph's hidden layer; its readout is a `Leaky`, a LIF node
//! whose membrane is read without reset. Norse's `to_nir` writes no `dt` and every time
//! constant multiplied by `dt`. Neither file says the step, which comes from the model
//! lending the pipeline; every formula above holds `dt/τ`, so each convention is NIR's read
//! at another time: 1e-4 s for snnTorch, `dt²` for Norse.
//!
//! Depends on `neurotex-core` and `neurotex-learn` (the network it writes and reads).
#![deny(missing_docs)]

use std::path::Path;

use hdf5_pure::File;

use crate::error::{DataError, ModelError, Result};
use crate::snn::{Network, Readout, Reset};

// The layers below, under the names their modules have there, so that `crate::snn` and
// the like read the same in every layer.
use neurotex_core::{error, io};
use neurotex_learn::snn;

mod graph;
mod network;
mod reader;
#[cfg(test)]
mod tests;
mod write;

use graph::path_of_nodes;
use network::{network_of, recurrent_of};
use reader::{read_string, time_of, Reader};

pub use write::{to_bytes, NEVER_FIRES, SNNTORCH_DT_S};

/// The nodes of the graph, in order along its one path.
pub const NODES: [(&str, &str); 6] = [
    ("input", "Input"),
    ("fc1", "Affine"),
    ("lif1", "CubaLIF"),
    ("fc2", "Affine"),
    ("li", "LI"),
    ("output", "Output"),
];

/// The importer a graph is written for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Convention {
    /// NIR's equations by forward Euler in physical time (`dt` in the metadata, constants
    /// in seconds), the readout a CubaLIF that never fires: Norse (`from_nir(g, dt=dt)`),
    /// neurotex, and any reader of NIR 1.0 (`v_reset` is left out, as it is 0).
    Physical,
    /// snnTorch's importer, which steps every graph at `dt = 1e-4` s whatever its metadata:
    /// the same graph with its constants scaled by `1e-4 / dt`, so that its decays are
    /// neurotex's. Norse and neurotex read it too.
    Snntorch,
    /// sinabs 3.1's importer: time in steps, exact decays, the synapse an LI node, neurons
    /// that subtract the threshold on a spike.
    Sinabs,
    /// Rockpool 3.1's importer: time in steps, exact decays, the input before the decay,
    /// neurons that subtract the threshold on a spike.
    Rockpool,
}

impl Convention {
    /// The name written in the graph's metadata (`neurotex_for`) and typed after `--for`.
    pub fn name(self) -> &'static str {
        match self {
            Convention::Physical => "nir",
            Convention::Snntorch => "snntorch",
            Convention::Sinabs => "sinabs",
            Convention::Rockpool => "rockpool",
        }
    }
}

/// Whether `convention`'s importer runs `net`'s neurons: sinabs's and Rockpool's subtract
/// the threshold on a spike (several spikes a step), snnTorch's and Norse's reset to zero.
/// NIR's own graph takes both (a subtracting network says so in its metadata, which only
/// neurotex reads). No importer runs adaptive thresholds (NIR has no node for them) or
/// per-synapse delays.
///
/// # Errors
/// A network whose reset the importer does not have, or with adaptive thresholds or
/// delays, naming the training option.
pub fn check_neurons(net: &Network, convention: Convention) -> Result<()> {
    let subtracts = !net.reset.is_zero();
    let tool = convention.name();
    let why = match convention {
        _ if net.adaptation.is_some() => "this network's neurons have adaptive thresholds (--snn-adapt-ms), for which NIR has no node: every tool would run the graph with fixed thresholds, and predict otherwise. Keep the model file for neurotex (predict, stream), or train without --snn-adapt-ms to export".to_string(),
        _ if !net.delays.is_empty() => "this network's input synapses each have a delay of their own (--snn-delay-ms), and NIR's Delay node delays a whole layer's values, one delay per value, not each synapse: every tool would run the graph without them, and predict otherwise. Keep the model file for neurotex (predict, stream), or train without --snn-delay-ms to export".to_string(),
        Convention::Sinabs | Convention::Rockpool if !subtracts => format!("{tool}'s neurons subtract the threshold on a spike (several spikes a step), and this network resets to zero: train it with --snn-reset subtract for {tool}, or export it --for nir"),
        Convention::Snntorch if subtracts => format!("this network's neurons subtract the threshold (--snn-reset subtract), and a graph for {tool} resets to zero: export it --for sinabs or --for rockpool, or --for nir for neurotex"),
        _ => return Ok(()),
    };
    Err(crate::error::OptionsError::Conflict(why).into())
}

/// The tool that wrote a graph: how to read what its file does not say (`--nir-from`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum NirFrom {
    /// NIR's equations in physical time, `dt` in the metadata (else the time step of the
    /// model lending the pipeline); a readout must never fire.
    #[default]
    Nir,
    /// snnTorch's `export_to_nir`: constants written for its fixed step of 1e-4 s
    /// (`τ = 1e-4/(1-β)`), no `dt`, the network stepping at the `--like` model's `dt_ms`;
    /// a LIF readout is its `Leaky` output layer, whose membrane is the score and is read
    /// without reset (snnTorch's `reset_mechanism="none"`).
    Snntorch,
    /// Norse's `to_nir(net, x, dt)`: every time constant written multiplied by `dt`
    /// (`τ dt`), no `dt` in the file, the network stepping at the `--like` model's `dt_ms`.
    Norse,
}

impl NirFrom {
    /// The name typed after `--nir-from`.
    pub fn name(self) -> &'static str {
        match self {
            NirFrom::Nir => "nir",
            NirFrom::Snntorch => "snntorch",
            NirFrom::Norse => "norse",
        }
    }
}

impl std::str::FromStr for NirFrom {
    type Err = crate::error::ParamError;
    fn from_str(s: &str) -> std::result::Result<Self, Self::Err> {
        match s {
            "nir" => Ok(NirFrom::Nir),
            "snntorch" => Ok(NirFrom::Snntorch),
            "norse" => Ok(NirFrom::Norse),
            _ => Err(crate::error::ParamError::new(
                "nir-from",
                "the tool that wrote the graph must be nir, snntorch or norse",
                s,
            )),
        }
    }
}

/// A network and what the graph's metadata says about it.
#[derive(Debug, Clone, PartialEq)]
pub struct NirNetwork {
    /// The network, in neurotex's discrete form.
    pub network: Network,
    /// The network's time step, s, from the metadata (`neurotex_dt` when the graph has it,
    /// else `dt`).
    pub dt_s: f64,
    /// The neurotex model file without its weights, when the graph was written by
    /// neurotex (`neurotex_model` in the metadata).
    pub neurotex_model: Option<String>,
}

/// Writes `net`'s graph to `path`, whole or not at all.
///
/// # Errors
/// The file cannot be written.
pub fn write(path: &Path, net: &Network, model_json: &str, convention: Convention) -> Result<()> {
    let bytes = to_bytes(net, model_json, convention)?;
    crate::io::write_atomic(path, |w| w.write_all(&bytes))
}

/// Reads a NIR graph of the shape neurotex runs (see the module) from `path`.
///
/// # Errors
/// An unreadable file, not HDF5, or a graph of another shape: an unknown or missing node,
/// edges that are not the one path (recurrent edges), inputs or outputs that do not match
/// the weights, per-neuron decays, a missing or non-whole-millisecond `dt`, or a
/// non-finite weight, each naming the node.
pub fn read(path: &Path) -> Result<NirNetwork> {
    read_as(path, NirFrom::Nir, None)
}

/// Reads a NIR graph written by `from` (see [`NirFrom`]); `step_s`, the time step of the
/// model lending the pipeline, is the network's step when the graph has none.
///
/// # Errors
/// As [`read`]; also a graph without a time step and no `step_s`, or a readout that fires
/// where `from` has none.
pub fn read_as(path: &Path, from: NirFrom, step_s: Option<f64>) -> Result<NirNetwork> {
    let bytes = std::fs::read(path).map_err(|e| DataError::io(path, e))?;
    let damaged = |reason: String| -> neurotex_core::Error {
        ModelError::Nir {
            path: path.to_path_buf(),
            reason,
        }
        .into()
    };
    // The parser is a young crate: whatever a damaged file makes it do, neurotex reports
    // an error rather than stopping.
    let parsed = std::panic::catch_unwind(|| from_bytes_as(bytes, from, step_s));
    match parsed {
        Ok(result) => result.map_err(damaged),
        Err(_) => Err(damaged("not a readable HDF5 file".into())),
    }
}

#[cfg(test)]
fn from_bytes(bytes: Vec<u8>) -> Result<NirNetwork, String> {
    from_bytes_as(bytes, NirFrom::Nir, None)
}

fn from_bytes_as(
    bytes: Vec<u8>,
    from: NirFrom,
    fallback_step_s: Option<f64>,
) -> Result<NirNetwork, String> {
    if !bytes.starts_with(b"\x89HDF\r\n\x1a\n") {
        return Err(
            "not an HDF5 file (a NIR graph is HDF5, which starts with its signature)".into(),
        );
    }
    let file = File::from_bytes(bytes).map_err(|e| format!("a damaged HDF5 file: {e}"))?;
    let reader = Reader { file };
    let node = reader.group(&["node"])?;
    let kind = read_string(&node, "type", "/node")?;
    if kind.first().map(String::as_str) != Some("NIRGraph") {
        return Err(format!("/node is a {kind:?}, not a NIRGraph"));
    }
    let meta = reader.group(&["node", "metadata"]).ok();
    let meta_str = |field: &str| {
        meta.as_ref()
            .and_then(|m| read_string(m, field, "/node/metadata").ok())
            .and_then(|v| v.into_iter().next())
    };
    if let Some(tool) = meta_str("neurotex_for").filter(|t| t == "sinabs" || t == "rockpool") {
        return Err(format!("the graph was written for {tool}'s importer (time in steps, the synapse split or the input before the decay), which neurotex does not read back: give the model file it was exported from, or a graph written with --for nir"));
    }
    let (names, rec) = path_of_nodes(&reader)?;
    let (scale_s, step_s) = time_of(meta.as_ref(), from, fallback_step_s)?;
    let dt_ms = step_s * 1000.0;
    if !((1.0..=1000.0).contains(&dt_ms) && (dt_ms - dt_ms.round()).abs() < 1e-6) {
        return Err(format!("the graph's dt is {step_s} s; neurotex's networks step a whole number of ms (1 to 1000) on the encoder's 1 ms spikes"));
    }
    let readout = meta_str("readout").map_or(Ok(Readout::Mean), |r| {
        r.parse()
            .map_err(|e: crate::error::ParamError| e.rule.to_string())
    })?;
    let reset = meta_str("reset").map_or(Ok(Reset::Zero), |r| {
        r.parse()
            .map_err(|e: crate::error::ParamError| e.rule.to_string())
    })?;
    let at = Layers {
        names: &names,
        scale_s,
        dt_ms: dt_ms.round() as u32,
        from,
    };
    let mut network = network_of(&reader, &at, readout)?;
    if let Some(rec) = rec {
        recurrent_of(&reader, &rec, &names[2], scale_s, &mut network)?;
    }
    network.reset = reset;
    network.travel_mm_s = reader::meta_number(meta.as_ref(), "neurotex_travel_mm_s")?;
    network.check().map_err(|e| e.to_string())?;
    Ok(NirNetwork {
        network,
        dt_s: step_s,
        neurotex_model: meta_str("neurotex_model"),
    })
}

/// The graph's layers: the nodes along its path and how to read their constants.
struct Layers<'a> {
    names: &'a [String],
    /// The time against which `dt/τ` is read, s.
    scale_s: f64,
    /// The network's step, ms.
    dt_ms: u32,
    from: NirFrom,
}
