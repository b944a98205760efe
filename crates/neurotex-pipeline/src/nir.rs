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
//! network ([`crate::snn`]) is their forward-Euler step at `dt`, the current first and the
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

use std::path::Path;

use hdf5_pure::{DType, File};

use crate::error::{DataError, ModelError, Result};
use crate::snn::{Network, Readout, Reset};

mod write;

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
/// neurotex reads).
///
/// # Errors
/// A network whose reset the importer does not have, naming the training option.
pub fn check_reset(net: &Network, convention: Convention) -> Result<()> {
    let subtracts = !net.reset.is_zero();
    let tool = convention.name();
    let why = match convention {
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
    let damaged = |reason: String| -> crate::Error {
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

/// The graph's arrays, read as f64.
struct Reader {
    file: File,
}

impl Reader {
    fn group(&self, path: &[&str]) -> Result<hdf5_pure::Group, String> {
        let mut g = self.file.root();
        let mut at = String::new();
        for name in path {
            at.push('/');
            at.push_str(name);
            g = g
                .group(name)
                .map_err(|_| format!("the graph has no group {at}"))?;
        }
        Ok(g)
    }

    /// The group of node `name`; `outer/inner` names a node of the subgraph `outer`.
    fn node(&self, name: &str) -> Result<hdf5_pure::Group, String> {
        let mut path = vec!["node"];
        for part in name.split('/') {
            path.extend(["nodes", part]);
        }
        self.group(&path)
    }
}

fn read_string(g: &hdf5_pure::Group, name: &str, at: &str) -> Result<Vec<String>, String> {
    let ds = g
        .dataset(name)
        .map_err(|_| format!("{at} has no `{name}`"))?;
    ds.read_string()
        .map_err(|e| format!("{at}/{name} is not a string: {e}"))
}

fn read_array(g: &hdf5_pure::Group, name: &str, at: &str) -> Result<(Vec<f64>, Vec<u64>), String> {
    let ds = g
        .dataset(name)
        .map_err(|_| format!("node {at} has no `{name}`"))?;
    let shape = ds.shape().map_err(|e| format!("node {at}: {name}: {e}"))?;
    let numeric = matches!(
        ds.dtype(),
        Ok(DType::F32 | DType::F64 | DType::I32 | DType::I64)
    );
    if !numeric {
        return Err(format!("node {at}: `{name}` is not a numeric array"));
    }
    let values = ds
        .read_f64()
        .map_err(|e| format!("node {at}: {name}: {e}"))?;
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(format!(
            "node {at}: `{name}`[{i}] is not finite ({})",
            values[i]
        ));
    }
    Ok((values, shape))
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
    network.check()?;
    Ok(NirNetwork {
        network,
        dt_s: step_s,
        neurotex_model: meta_str("neurotex_model"),
    })
}

/// A number in the graph's metadata, if it has the field.
fn meta_number(meta: Option<&hdf5_pure::Group>, field: &str) -> Result<Option<f64>, String> {
    let Some(d) = meta.and_then(|m| m.dataset(field).ok()) else {
        return Ok(None);
    };
    let v = d.read_f64().map_err(|_| {
        format!("the graph's metadata `{field}` is not a number (a time step in seconds)")
    })?;
    match v.first() {
        Some(&x) if x > 0.0 && x.is_finite() => Ok(Some(x)),
        Some(x) => Err(format!(
            "the graph's metadata `{field}` is {x}; a time step must be positive"
        )),
        None => Err(format!("the graph's metadata `{field}` is empty")),
    }
}

/// The time against which the graph's constants are read (every formula has `dt/τ`) and
/// the network's step, both in seconds. NIR's graphs say `dt`; neurotex's graphs for
/// snnTorch keep the network's own step as `neurotex_dt` beside snnTorch's `dt`; snnTorch
/// writes its constants for 1e-4 s and Norse its time constants multiplied by the step,
/// and neither says the step, which then is the `--like` model's.
fn time_of(
    meta: Option<&hdf5_pure::Group>,
    from: NirFrom,
    fallback_step_s: Option<f64>,
) -> Result<(f64, f64), String> {
    let dt = meta_number(meta, "dt")?;
    let own_step = meta_number(meta, "neurotex_dt")?;
    let no_step = |tool: &str| {
        format!("the graph's metadata has no `dt` (its time step in seconds), as {tool} writes none: give the neurotex spiking model whose pipeline makes its input spikes (--like MODEL.json), whose dt_ms is the step")
    };
    match from {
        NirFrom::Nir => {
            let dt = dt.or(fallback_step_s).ok_or_else(|| {
                "the graph's metadata has no `dt` (its time step in seconds)".to_string()
            })?;
            Ok((dt, own_step.unwrap_or(dt)))
        }
        NirFrom::Snntorch => {
            let step = own_step
                .or(fallback_step_s)
                .ok_or_else(|| no_step("snnTorch"))?;
            Ok((SNNTORCH_DT_S, step))
        }
        NirFrom::Norse => {
            let step = dt.or(fallback_step_s).ok_or_else(|| no_step("Norse"))?;
            Ok((step * step, step))
        }
    }
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

/// The nodes along the graph's one path from its Input to its Output, checked to be the
/// six neurotex runs, in order, and the Linear (or Affine) node of a recurrent loop on the
/// CubaLIF node (`lif → rec → lif`), if there is one.
fn path_of_nodes(reader: &Reader) -> Result<(Vec<String>, Option<Vec<String>>), String> {
    let (mut kinds, owned) = nodes_and_edges(reader)?;
    for (name, kind) in &kinds {
        if !NODES.iter().any(|(_, k)| *k == kind) && kind != "Linear" && kind != "LIF" {
            return Err(format!("node {name} is a {kind}; neurotex runs Input → Affine/Linear → CubaLIF or LIF → Affine/Linear → LI (or a LIF or CubaLIF that never fires) → Output, with at most one recurrent loop of Linear/Affine nodes on the hidden layer"));
        }
    }
    let mut edges: Vec<(&str, &str)> = owned
        .iter()
        .map(|(a, b)| (a.as_str(), b.as_str()))
        .collect();
    let rec = take_loop(&mut kinds, &mut edges)?;
    let start = kinds
        .iter()
        .filter(|(_, k)| k == "Input")
        .map(|(n, _)| n.clone())
        .collect::<Vec<_>>();
    let [start] = start.as_slice() else {
        return Err(format!(
            "the graph has {} Input nodes; neurotex runs one",
            start.len()
        ));
    };
    let mut path = vec![start.clone()];
    while path.len() < kinds.len() {
        let at = path.last().cloned().unwrap_or_default();
        let next: Vec<&str> = edges.iter().filter(|e| e.0 == at).map(|e| e.1).collect();
        let [next] = next.as_slice() else {
            return Err(format!(
                "node {at} has {} outgoing edges; neurotex runs one feed-forward path",
                next.len()
            ));
        };
        if path.iter().any(|p| p == next) {
            return Err(format!("the edge {at} → {next} makes a loop (a recurrent edge); neurotex runs feed-forward networks"));
        }
        path.push(next.to_string());
    }
    if edges.len() != kinds.len() - 1 {
        return Err(format!(
            "the graph has {} edges for {} nodes; neurotex runs one path without recurrent edges",
            edges.len(),
            kinds.len()
        ));
    }
    let order: Vec<&str> = path
        .iter()
        .map(|n| {
            kinds
                .iter()
                .find(|(m, _)| m == n)
                .map_or("", |(_, k)| k.as_str())
        })
        .collect();
    let want = ["Input", "Affine", "CubaLIF", "Affine", "LI", "Output"];
    for (i, (got, want)) in order.iter().zip(want).enumerate() {
        let fits = *got == want
            || (want == "Affine" && *got == "Linear")
            || (want == "CubaLIF" && *got == "LIF")
            || (want == "LI" && (*got == "CubaLIF" || *got == "LIF"));
        if !fits {
            return Err(format!("node {} is a {got} where neurotex runs a {want} (Input → Affine → CubaLIF or LIF → Affine → LI → Output)", path[i]));
        }
    }
    if order.len() != want.len() {
        return Err(format!("the graph has {} nodes; neurotex runs the six of Input → Affine → CubaLIF → Affine → LI → Output", order.len()));
    }
    Ok((path, rec))
}

/// Reads the recurrent loop's weights (the Linear or Affine nodes `rec`, in order from the
/// CubaLIF node `lif` back to it: their product is the loop's weight) into `net`, with the
/// CubaLIF's gain per neuron as for its feed-forward input; a bias on the loop is a
/// constant current, added to the hidden biases.
fn recurrent_of(
    reader: &Reader,
    rec: &[String],
    lif: &str,
    dt_s: f64,
    net: &mut Network,
) -> Result<(), String> {
    let h = net.hidden;
    // The loop as one (out, in) matrix and bias: each node's applied to the last's output.
    let mut w: Vec<f64> = (0..h * h)
        .map(|k| f64::from(u8::from(k / h == k % h)))
        .collect();
    let mut bias = vec![0.0; h];
    for node in rec {
        let (wn, bn, out, inp) = read_affine(reader, node)?;
        if (out, inp) != (h, h) {
            return Err(format!(
                "node {node}: the recurrent weight is ({out}, {inp}), not ({h}, {h}) for the {h} neurons of {lif}"
            ));
        }
        let row = |o: usize| &wn[o * h..(o + 1) * h];
        w = (0..h * h)
            .map(|k| {
                (row(k / h).iter().enumerate())
                    .map(|(j, x)| x * w[j * h + k % h])
                    .sum()
            })
            .collect();
        bias = (0..h)
            .map(|o| bn[o] + row(o).iter().zip(&bias).map(|(x, b)| x * b).sum::<f64>())
            .collect();
    }
    let (_, _, gain) = lif_of(reader, lif, dt_s, h)?;
    net.w_rec = (0..h * h)
        .map(|k| gain[k % h] * w[(k % h) * h + k / h])
        .collect();
    for (b, (g, extra)) in net.b_in.iter_mut().zip(gain.iter().zip(&bias)) {
        *b += g * extra;
    }
    Ok(())
}

/// A graph's nodes `(name, type)` and edges, with a nested graph's nodes in place of its
/// node (named `outer/inner`): snnTorch writes a recurrent layer (`RLeaky`, `RSynaptic`)
/// as a graph `Input → LIF → Output` with a loop `LIF → w_rec → LIF`, which then reads as
/// the loop on a flat graph's hidden layer.
type NodesAndEdges = (Vec<(String, String)>, Vec<(String, String)>);

fn nodes_and_edges(reader: &Reader) -> Result<NodesAndEdges, String> {
    let (kinds, mut edges) = graph_level(reader, &["node"], "")?;
    let mut flat = Vec::new();
    for (name, kind) in kinds {
        if kind != "NIRGraph" {
            flat.push((name, kind));
            continue;
        }
        let (inner, inner_edges) =
            graph_level(reader, &["node", "nodes", &name], &format!("{name}/"))?;
        if let Some((n, _)) = inner.iter().find(|(_, k)| k == "NIRGraph") {
            return Err(format!("node {n} is a graph inside the graph {name}; neurotex reads one level of nesting (snnTorch's recurrent layer)"));
        }
        let is = |n: &str, want: &str| inner.iter().any(|(m, k)| m == n && k == want);
        let entries: Vec<&String> = (inner_edges.iter().filter(|(a, _)| is(a, "Input")))
            .map(|(_, b)| b)
            .collect();
        let exits: Vec<&String> = (inner_edges.iter().filter(|(_, b)| is(b, "Output")))
            .map(|(a, _)| a)
            .collect();
        let mut rewired = Vec::new();
        for (a, b) in edges {
            if b == name {
                rewired.extend(entries.iter().map(|e| (a.clone(), (*e).clone())));
            } else if a == name {
                rewired.extend(exits.iter().map(|x| ((*x).clone(), b.clone())));
            } else {
                rewired.push((a, b));
            }
        }
        rewired.extend(
            (inner_edges.iter())
                .filter(|(a, b)| !is(a, "Input") && !is(b, "Output"))
                .cloned(),
        );
        edges = rewired;
        flat.extend(
            (inner.iter())
                .filter(|(_, k)| k != "Input" && k != "Output")
                .cloned(),
        );
    }
    Ok((flat, edges))
}

/// The nodes and edges of the graph at `path`, their names prefixed with `prefix`.
fn graph_level(reader: &Reader, path: &[&str], prefix: &str) -> Result<NodesAndEdges, String> {
    let at = format!("/{}", path.join("/"));
    let group = reader.group(path)?;
    let nodes = group
        .group("nodes")
        .map_err(|_| format!("{at} has no nodes"))?;
    let names = nodes.groups().map_err(|e| format!("{at}/nodes: {e}"))?;
    let mut kinds = Vec::new();
    for name in &names {
        let full = format!("{prefix}{name}");
        let g = nodes.group(name).map_err(|e| format!("node {full}: {e}"))?;
        let kind = read_string(&g, "type", &format!("node {full}"))?.concat();
        kinds.push((full, kind));
    }
    let flat = read_string(&group, "edges", &at)?;
    if flat.len() % 2 != 0 {
        return Err(format!("the edges of {at} are not pairs"));
    }
    let edges = (flat.chunks(2))
        .map(|e| (format!("{prefix}{}", e[0]), format!("{prefix}{}", e[1])))
        .collect();
    Ok((kinds, edges))
}

/// Takes the one recurrent loop on a CubaLIF node (through one Linear/Affine node, or two
/// in a row as snnTorch's importer needs, each with no other edge) out of the node list
/// and edges, and returns the loop's nodes in order from the CubaLIF.
fn take_loop(
    kinds: &mut Vec<(String, String)>,
    edges: &mut Vec<(&str, &str)>,
) -> Result<Option<Vec<String>>, String> {
    let kind_of = |n: &str| kinds.iter().find(|(m, _)| m == n).map(|(_, k)| k.clone());
    let dense = |n: &str| {
        matches!(kind_of(n).as_deref(), Some("Linear" | "Affine"))
            && edges.iter().filter(|e| e.0 == n || e.1 == n).count() == 2
    };
    let next = |n: &str| edges.iter().find(|e| e.0 == n).map(|e| e.1);
    let mut loops: Vec<(String, Vec<String>)> = Vec::new();
    for &(lif, a) in edges.iter() {
        if !matches!(kind_of(lif).as_deref(), Some("CubaLIF" | "LIF")) || !dense(a) {
            continue;
        }
        let mut path = vec![a.to_string()];
        let mut at = next(a);
        if let Some(b) = at.filter(|&b| b != lif && dense(b)) {
            path.push(b.to_string());
            at = next(b);
        }
        if at == Some(lif) {
            loops.push((lif.to_string(), path));
        }
    }
    Ok(match loops.as_slice() {
        [] => None,
        [(lif, path)] => {
            let on_loop = |n: &str| n == lif || path.iter().any(|p| p == n);
            edges.retain(|e| !(on_loop(e.0) && on_loop(e.1)));
            kinds.retain(|(n, _)| !path.contains(n));
            Some(path.clone())
        }
        _ => return Err(
            "the graph has more than one recurrent loop; neurotex runs one, on its CubaLIF layer"
                .into(),
        ),
    })
}

/// One value per neuron of a layer of `len` (a single value applies to all).
fn per_neuron(g: &hdf5_pure::Group, field: &str, at: &str, len: usize) -> Result<Vec<f64>, String> {
    let (values, _) = read_array(g, field, at)?;
    match values.len() {
        1 => Ok(vec![values[0]; len]),
        n if n == len => Ok(values),
        n => Err(format!(
            "node {at}: `{field}` has {n} values for {len} neurons"
        )),
    }
}

/// An Affine's (or Linear's) weight, `(out, in)` row-major, and bias.
fn read_affine(reader: &Reader, name: &str) -> Result<(Vec<f64>, Vec<f64>, usize, usize), String> {
    let g = reader.node(name)?;
    let (weight, shape) = read_array(&g, "weight", name)?;
    let [out, inp] = shape.as_slice() else {
        return Err(format!(
            "node {name}: the weight has shape {shape:?}, not (out, in)"
        ));
    };
    let (out, inp) = (*out as usize, *inp as usize);
    let bias = match g.dataset("bias") {
        Ok(_) => read_array(&g, "bias", name)?.0,
        Err(_) => vec![0.0; out],
    };
    if bias.len() != out {
        return Err(format!(
            "node {name}: {} biases for {out} outputs",
            bias.len()
        ));
    }
    Ok((weight, bias, out, inp))
}

/// The one decay `1 - dt/τ` of a layer's neurons.
fn one_decay(taus: &[f64], dt_s: f64, at: &str, field: &str) -> Result<f64, String> {
    let decays: Vec<f64> = taus.iter().map(|t| 1.0 - dt_s / t).collect();
    let first = decays[0];
    if !(first > 0.0 && first < 1.0) {
        return Err(format!("node {at}: `{field}` {} s gives the decay {first} per step of {dt_s} s; it must lie between 0 and 1 (tau above dt)", taus[0]));
    }
    if decays
        .iter()
        .any(|d| (d - first).abs() > 1e-9 * first.max(1e-12) + 1e-12)
    {
        return Err(format!(
            "node {at}: `{field}` differs between neurons; neurotex's network has one per layer"
        ));
    }
    Ok(first)
}

/// The CubaLIF node's decays and, per neuron, the gain each step gives its input on the
/// membrane scaled to a threshold of 1: `(dt/τ_mem) r (dt/τ_syn) w_in / v_threshold`.
fn lif_of(reader: &Reader, at: &str, dt_s: f64, h: usize) -> Result<(f64, f64, Vec<f64>), String> {
    let lif = reader.node(at)?;
    let field = |f: &str| per_neuron(&lif, f, at, h);
    let kind = read_string(&lif, "type", &format!("node {at}"))?.concat();
    // A LIF node has no synapse: its current is the step's input (α = 0, gain 1), as
    // snnTorch's `Leaky` and Norse's `LIFBoxCell` step.
    let (alpha, synapse_gain, tau_mem, tau_field) = if kind == "LIF" {
        (0.0, vec![1.0; h], field("tau")?, "tau")
    } else {
        let (tau_syn, w_in) = (field("tau_syn")?, field("w_in")?);
        let alpha = one_decay(&tau_syn, dt_s, at, "tau_syn")?;
        let gain = (0..h).map(|j| (dt_s / tau_syn[j]) * w_in[j]).collect();
        (alpha, gain, field("tau_mem")?, "tau_mem")
    };
    let r = field("r")?;
    // `v_reset` may be left out (nir 1.0.4 has no such field; later versions default to 0).
    let v_reset = match lif.dataset("v_reset") {
        Ok(_) => field("v_reset")?,
        Err(_) => vec![0.0; h],
    };
    let (v_leak, v_threshold) = (field("v_leak")?, field("v_threshold")?);
    let beta = one_decay(&tau_mem, dt_s, at, tau_field)?;
    if v_leak.iter().chain(&v_reset).any(|v| *v != 0.0) {
        return Err(format!(
            "node {at}: v_leak and v_reset must be 0 (neurotex's neurons rest and reset at 0)"
        ));
    }
    if v_threshold.iter().any(|v| *v <= 0.0) {
        return Err(format!("node {at}: v_threshold must be positive"));
    }
    let gain: Vec<f64> = (0..h)
        .map(|j| (dt_s / tau_mem[j]) * r[j] * synapse_gain[j] / v_threshold[j])
        .collect();
    Ok((alpha, beta, gain))
}

/// The readout node's decay, and per class the gain each step gives its input and the
/// constant its leak adds: an LI node (`τ dv/dt = v_leak - v + r a`), or a CubaLIF that
/// never fires whose current is the step's input (`tau_syn = dt`; a threshold of at least
/// 1e20), the readout snnTorch and Norse map, or a LIF node that never fires (with
/// [`NirFrom::Snntorch`], snnTorch's `Leaky` output layer: its membrane, read without
/// reset).
fn readout_of(
    reader: &Reader,
    at: &str,
    dt_s: f64,
    c: usize,
    from: NirFrom,
) -> Result<(f64, Vec<f64>, Vec<f64>), String> {
    let g = reader.node(at)?;
    let field = |f: &str| per_neuron(&g, f, at, c);
    let kind = read_string(&g, "type", &format!("node {at}"))?.concat();
    let (tau, r, leak, input_gain) = if kind == "CubaLIF" {
        let tau_syn = field("tau_syn")?;
        if let Some(t) = tau_syn.iter().find(|t| ((*t - dt_s) / dt_s).abs() > 1e-6) {
            return Err(format!("node {at}: a CubaLIF readout needs tau_syn = dt ({dt_s} s), so that its current is the step's input; got {t} s"));
        }
        if let Some(v) = field("v_threshold")?.iter().find(|v| **v < 1e20) {
            return Err(format!(
                "node {at}: a CubaLIF readout must never fire (v_threshold at least 1e20); got {v}"
            ));
        }
        let w_in = field("w_in")?;
        let gain = (0..c).map(|k| (dt_s / tau_syn[k]) * w_in[k]).collect();
        (field("tau_mem")?, field("r")?, field("v_leak")?, gain)
    } else {
        let fires = (kind == "LIF" && from != NirFrom::Snntorch)
            .then(|| field("v_threshold"))
            .transpose()?
            .and_then(|v| v.into_iter().find(|v| *v < 1e20));
        if let Some(v) = fires {
            return Err(format!("node {at}: a LIF readout that fires (v_threshold {v}); neurotex scores a readout's membrane, which a spike would reset, so a LIF readout must never fire (v_threshold at least 1e20); snnTorch's Leaky output layer reads with --nir-from snntorch, as a membrane without reset"));
        }
        (field("tau")?, field("r")?, field("v_leak")?, vec![1.0; c])
    };
    let field_name = if kind == "CubaLIF" { "tau_mem" } else { "tau" };
    let kappa = one_decay(&tau, dt_s, at, field_name)?;
    let gain = (0..c)
        .map(|k| (dt_s / tau[k]) * r[k] * input_gain[k])
        .collect();
    let leak = (0..c).map(|k| (dt_s / tau[k]) * leak[k]).collect();
    Ok((kappa, gain, leak))
}

fn network_of(reader: &Reader, at: &Layers<'_>, readout: Readout) -> Result<Network, String> {
    let (names, dt_s, dt_ms) = (at.names, at.scale_s, at.dt_ms);
    let (w1, b1, h, n) = read_affine(reader, &names[1])?;
    let (w2, b2, c, h2) = read_affine(reader, &names[3])?;
    let io_width = |name: &str| -> Result<usize, String> {
        let g = reader.node(name)?;
        let (shape, _) = read_array(&g, "shape", name)?;
        Ok(shape.iter().product::<f64>() as usize)
    };
    if io_width(&names[0])? != n {
        return Err(format!(
            "node {}: its shape is not the {n} inputs of {}",
            names[0], names[1]
        ));
    }
    if h2 != h {
        return Err(format!(
            "node {}: {h2} inputs, but {} has {h} neurons",
            names[3], names[2]
        ));
    }
    if io_width(&names[5])? != c {
        return Err(format!(
            "node {}: its shape is not the {c} outputs of {}",
            names[5], names[3]
        ));
    }
    let (alpha, beta, gain) = lif_of(reader, &names[2], dt_s, h)?;
    let (kappa, out_gain, out_leak) = readout_of(reader, &names[4], dt_s, c, at.from)?;
    let tau_ms = |decay: f64| -f64::from(dt_ms) / decay.ln();
    Ok(Network {
        inputs: n,
        hidden: h,
        classes: c,
        dt_ms,
        tau_syn_ms: tau_ms(alpha),
        tau_mem_ms: tau_ms(beta),
        tau_out_ms: tau_ms(kappa),
        readout,
        w_in: (0..n * h)
            .map(|k| gain[k % h] * w1[(k % h) * n + k / h])
            .collect(),
        b_in: (0..h).map(|j| gain[j] * b1[j]).collect(),
        w_out: (0..h * c)
            .map(|k| out_gain[k % c] * w2[(k % c) * h + k / c])
            .collect(),
        b_out: (0..c).map(|k| out_gain[k] * b2[k] + out_leak[k]).collect(),
        w_rec: Vec::new(),
        reset: Reset::Zero,
        target: Default::default(),
    })
}

#[cfg(test)]
mod tests {
    use super::write::put_str;
    use super::*;
    use hdf5_pure::FileBuilder;

    /// A node as the tests edit it: name, type, and each field's values and shape.
    type Node = (String, String, Vec<(String, Vec<f64>, Vec<u64>)>);

    fn net() -> Network {
        let (n, h, c) = (3, 4, 2);
        let w = |len: usize, k: f64| {
            (0..len)
                .map(|i| ((i as f64 * 0.37 + k).sin() as f32).into())
                .collect()
        };
        Network {
            inputs: n,
            hidden: h,
            classes: c,
            dt_ms: 10,
            tau_syn_ms: 20.0,
            tau_mem_ms: 40.0,
            tau_out_ms: 30.0,
            readout: Readout::Max,
            w_in: w(n * h, 0.1),
            b_in: w(h, 0.2),
            w_out: w(h * c, 0.3),
            b_out: w(c, 0.4),
            w_rec: Vec::new(),
            reset: Reset::Zero,
            target: Default::default(),
        }
    }

    /// A graph like neurotex's with `edit` applied to its node table before writing:
    /// `(name, type, fields)` and the edges; `dt` in the metadata or none.
    fn graph(edit: impl Fn(&mut Vec<Node>, &mut Vec<[String; 2]>), dt: Option<f64>) -> Vec<u8> {
        let written =
            File::from_bytes(to_bytes(&net(), "{}", Convention::Physical).unwrap()).unwrap();
        let nodes_group = written
            .root()
            .group("node")
            .unwrap()
            .group("nodes")
            .unwrap();
        let mut nodes = Vec::new();
        for (name, _) in NODES {
            let g = nodes_group.group(name).unwrap();
            let kind = g.dataset("type").unwrap().read_string().unwrap().concat();
            let fields = g
                .datasets()
                .unwrap()
                .into_iter()
                .filter(|f| f != "type")
                .map(|f| {
                    let d = g.dataset(&f).unwrap();
                    (f, d.read_f64().unwrap(), d.shape().unwrap())
                })
                .collect();
            nodes.push((name.to_string(), kind, fields));
        }
        let mut edges: Vec<[String; 2]> = NODES
            .windows(2)
            .map(|w| [w[0].0.to_string(), w[1].0.to_string()])
            .collect();
        edit(&mut nodes, &mut edges);
        let mut fb = FileBuilder::new();
        let mut node = fb.create_group("node");
        put_str(&mut node, "type", "NIRGraph");
        let flat: Vec<&str> = edges
            .iter()
            .flat_map(|e| [e[0].as_str(), e[1].as_str()])
            .collect();
        node.create_dataset("edges")
            .with_vlen_strings(&flat)
            .with_shape(&[edges.len() as u64, 2]);
        let mut meta = node.create_group("metadata");
        if let Some(dt) = dt {
            meta.create_dataset("dt")
                .with_f64_data(&[dt])
                .with_shape(&[]);
        }
        put_str(&mut meta, "readout", "max");
        node.add_group(meta.finish());
        let mut group = node.create_group("nodes");
        for (name, kind, fields) in &nodes {
            let mut g = group.create_group(name);
            put_str(&mut g, "type", kind);
            for (f, v, shape) in fields {
                g.create_dataset(f).with_f64_data(v).with_shape(shape);
            }
            group.add_group(g.finish());
        }
        node.add_group(group.finish());
        fb.add_group(node.finish());
        fb.finish().unwrap()
    }

    fn field(nodes: &mut [Node], node: &str, f: &str) -> Vec<f64> {
        let n = nodes.iter_mut().find(|n| n.0 == node).unwrap();
        n.2.iter().find(|x| x.0 == f).unwrap().1.clone()
    }

    /// Sets field `f` of `node` to `v` (added, shaped as `v`, when the node has none).
    fn set(nodes: &mut [Node], node: &str, f: &str, v: Vec<f64>) {
        let n = nodes.iter_mut().find(|n| n.0 == node).unwrap();
        match n.2.iter_mut().find(|x| x.0 == f) {
            Some(field) => field.1 = v,
            None => n.2.push((f.to_string(), v.clone(), vec![v.len() as u64])),
        }
    }

    #[test]
    fn a_graph_round_trips_and_one_written_in_other_units_reads_the_same() {
        let bytes = to_bytes(&net(), "{}", Convention::Physical).unwrap();
        let back = from_bytes(bytes).unwrap();
        assert_eq!(back.dt_s, 0.01);
        let scores = |n: &Network| {
            let x = crate::snn::SpikeInput::from_events(
                3,
                20,
                &[(0, 1), (2, 0), (2, 2), (5, 1), (9, 0)],
            );
            n.scores(&x)
        };
        for (a, b) in scores(&net()).iter().zip(scores(&back.network)) {
            assert!((a - b).abs() < 1e-12, "{a} vs {b}");
        }
        // Written for snnTorch's importer (`dt` 0.1 ms, the constants scaled to it): read
        // back as the same network, its own step from `neurotex_dt`.
        let snntorch = from_bytes(to_bytes(&net(), "{}", Convention::Snntorch).unwrap()).unwrap();
        assert_eq!((snntorch.dt_s, snntorch.network.dt_ms), (0.01, 10));
        for (a, b) in scores(&net()).iter().zip(scores(&snntorch.network)) {
            assert!((a - b).abs() < 1e-9, "{a} vs {b}");
        }
        // A threshold of 2 with every input weight doubled, and an LI gain r halved with
        // the readout weights doubled: the same network.
        let doubled = graph(
            |nodes, _| {
                set(nodes, "lif1", "v_threshold", vec![2.0; 4]);
                let w = field(nodes, "fc1", "weight")
                    .iter()
                    .map(|w| 2.0 * w)
                    .collect();
                set(nodes, "fc1", "weight", w);
                let b = field(nodes, "fc1", "bias")
                    .iter()
                    .map(|w| 2.0 * w)
                    .collect();
                set(nodes, "fc1", "bias", b);
                let r = field(nodes, "li", "r").iter().map(|r| r / 2.0).collect();
                set(nodes, "li", "r", r);
                let w = field(nodes, "fc2", "weight")
                    .iter()
                    .map(|w| 2.0 * w)
                    .collect();
                set(nodes, "fc2", "weight", w);
                let b = field(nodes, "fc2", "bias")
                    .iter()
                    .map(|w| 2.0 * w)
                    .collect();
                set(nodes, "fc2", "bias", b);
            },
            Some(0.01),
        );
        let same = from_bytes(doubled).unwrap().network;
        for (a, b) in scores(&net()).iter().zip(scores(&same)) {
            assert!((a - b).abs() < 1e-9, "{a} vs {b}");
        }
    }

    /// A recurrent network's graph carries its loop (`lif1 → rec → lif1`) and reads back
    /// as the same network; the loop's weights matter to its scores.
    #[test]
    fn a_recurrent_network_round_trips_through_its_loop() {
        let mut rec = net();
        rec.w_rec = (0..16)
            .map(|i| f64::from(((i as f32) * 0.91).cos() * 0.6))
            .collect();
        let bytes = to_bytes(&rec, "{}", Convention::Physical).unwrap();
        let back = from_bytes(bytes).unwrap().network;
        assert!(back.recurrent());
        let x = crate::snn::SpikeInput::from_events(3, 30, &[(0, 1), (1, 0), (2, 2), (3, 1)]);
        let (a, b) = (rec.scores(&x), back.scores(&x));
        for (a, b) in a.iter().zip(&b) {
            assert!((a - b).abs() < 1e-12, "{a} vs {b}");
        }
        assert_ne!(a, net().scores(&x), "the loop changes the scores");
        for (w, v) in rec.w_rec.iter().zip(&back.w_rec) {
            assert!((w - v).abs() < 1e-12);
        }
        // Two loops on the hidden layer are refused.
        let two = graph(
            |n, e| {
                for name in ["r1", "r2"] {
                    let weight = ("weight".to_string(), vec![0.1; 16], vec![4, 4]);
                    n.push((name.into(), "Linear".into(), vec![weight]));
                    e.push(["lif1".into(), name.into()]);
                    e.push([name.into(), "lif1".into()]);
                }
            },
            Some(0.01),
        );
        let err = from_bytes(two).unwrap_err();
        assert!(err.contains("more than one recurrent loop"), "{err}");
    }

    /// The graph neurotex wrote before its readout became a CubaLIF (an LI readout, a
    /// `v_reset` of zeros, a two-node loop) still reads as the same network.
    #[test]
    fn an_li_readout_and_an_explicit_v_reset_read_as_before() {
        let older = graph(
            |nodes, _| {
                let tau = field(nodes, "li", "tau_mem");
                let r = field(nodes, "li", "r");
                let li = nodes.iter_mut().find(|n| n.0 == "li").unwrap();
                li.1 = "LI".into();
                li.2 = vec![
                    ("tau".into(), tau, vec![2]),
                    ("r".into(), r, vec![2]),
                    ("v_leak".into(), vec![0.0; 2], vec![2]),
                ];
                set(nodes, "lif1", "v_reset", vec![0.0; 4]);
            },
            Some(0.01),
        );
        let back = from_bytes(older).unwrap().network;
        let x = crate::snn::SpikeInput::from_events(3, 20, &[(0, 1), (2, 0), (5, 2), (9, 0)]);
        for (a, b) in net().scores(&x).iter().zip(back.scores(&x)) {
            assert!((a - b).abs() < 1e-9, "{a} vs {b}");
        }
    }

    /// What the written graphs hold: no `v_reset` (nir 1.0.4 has no such field), a readout
    /// that never fires, and the conventions in steps refused on reading back.
    #[test]
    fn the_graphs_load_in_older_readers_and_say_what_they_were_written_for() {
        let bytes = to_bytes(&net(), "{}", Convention::Physical).unwrap();
        let file = File::from_bytes(bytes).unwrap();
        let nodes = file.root().group("node").unwrap().group("nodes").unwrap();
        let lif = nodes.group("lif1").unwrap();
        assert!(lif.dataset("v_reset").is_err());
        let li = nodes.group("li").unwrap();
        let kind = li.dataset("type").unwrap().read_string().unwrap().concat();
        let threshold = li.dataset("v_threshold").unwrap().read_f64().unwrap();
        assert_eq!((kind.as_str(), threshold[0]), ("CubaLIF", NEVER_FIRES));
        for convention in [Convention::Sinabs, Convention::Rockpool] {
            let err = from_bytes(to_bytes(&net(), "{}", convention).unwrap()).unwrap_err();
            assert!(
                err.contains(convention.name()) && err.contains("--for nir"),
                "{err}"
            );
        }
        let firing = graph(|n, _| set(n, "li", "v_threshold", vec![1.0; 2]), Some(0.01));
        let err = from_bytes(firing).unwrap_err();
        assert!(err.contains("must never fire"), "{err}");
    }

    /// Scores of two networks on one input, to within `tol`.
    fn same_scores(a: &Network, b: &Network, tol: f64) {
        let x = crate::snn::SpikeInput::from_events(3, 30, &[(0, 1), (1, 0), (2, 2), (3, 1)]);
        for (a, b) in a.scores(&x).iter().zip(b.scores(&x)) {
            assert!((a - b).abs() < tol, "{a} vs {b}");
        }
    }

    /// A LIF hidden node (snnTorch's `Leaky`, Norse's `LIFBoxCell`) has no synapse: it
    /// reads as a network whose current is the step's input (`tau_syn_ms` 0).
    #[test]
    fn a_lif_hidden_node_reads_without_synaptic_memory() {
        let lif = graph(
            |nodes, _| {
                let (tau, r) = (field(nodes, "lif1", "tau_mem"), field(nodes, "lif1", "r"));
                let node = nodes.iter_mut().find(|n| n.0 == "lif1").unwrap();
                node.1 = "LIF".into();
                node.2
                    .retain(|f| !matches!(f.0.as_str(), "tau_syn" | "tau_mem" | "w_in" | "r"));
                node.2.push(("tau".into(), tau, vec![4]));
                node.2.push(("r".into(), r, vec![4]));
            },
            Some(0.01),
        );
        let back = from_bytes(lif).unwrap().network;
        assert_eq!(back.tau_syn_ms, 0.0);
        let mut want = net();
        want.tau_syn_ms = 0.0;
        same_scores(&want, &back, 1e-9);
        let x = crate::snn::SpikeInput::from_events(3, 30, &[(0, 1), (1, 0), (2, 2), (3, 1)]);
        assert_ne!(back.scores(&x), net().scores(&x), "the synapse matters");
    }

    /// Norse writes every time constant multiplied by `dt` and no `dt`: read with the step
    /// given, it is the network; read as NIR's seconds, it is refused.
    #[test]
    fn norse_time_constants_read_with_the_step_given() {
        let dt = 0.01;
        let norse = graph(
            |nodes, _| {
                for (node, f) in [
                    ("lif1", "tau_syn"),
                    ("lif1", "tau_mem"),
                    ("li", "tau_syn"),
                    ("li", "tau_mem"),
                ] {
                    let v = field(nodes, node, f).iter().map(|t| t * dt).collect();
                    set(nodes, node, f, v);
                }
            },
            None,
        );
        let back = from_bytes_as(norse.clone(), NirFrom::Norse, Some(dt)).unwrap();
        assert_eq!((back.dt_s, back.network.dt_ms), (dt, 10));
        same_scores(&net(), &back.network, 1e-9);
        let err = from_bytes_as(norse.clone(), NirFrom::Nir, Some(dt)).unwrap_err();
        assert!(err.contains("node lif1: `tau_syn`"), "{err}");
        let err = from_bytes_as(norse, NirFrom::Norse, None).unwrap_err();
        assert!(
            err.contains("Norse writes none") && err.contains("--like"),
            "{err}"
        );
    }

    /// The time step: the graph's `dt`, else the one given; none, or one not positive, is
    /// refused by name.
    #[test]
    fn a_graph_without_a_positive_time_step_is_refused() {
        let back = from_bytes_as(graph(|_, _| {}, None), NirFrom::Nir, Some(0.01)).unwrap();
        same_scores(&net(), &back.network, 1e-9);
        let err = from_bytes(graph(|_, _| {}, Some(-0.01))).unwrap_err();
        assert!(
            err.contains("`dt` is -0.01; a time step must be positive"),
            "{err}"
        );
        let err = from_bytes_as(graph(|_, _| {}, None), NirFrom::Snntorch, None).unwrap_err();
        assert!(err.contains("snnTorch writes none"), "{err}");
        assert!("keras".parse::<NirFrom>().is_err());
        assert_eq!("norse".parse::<NirFrom>().unwrap().name(), "norse");
    }

    #[test]
    fn graphs_of_another_shape_name_the_node_and_the_rule() {
        let cases: Vec<(Vec<u8>, &str)> = vec![
            (graph(|_, _| {}, None), "no `dt`"),
            (graph(|_, _| {}, Some(0.0001)), "whole number of ms"),
            (
                graph(|n, _| n[2].1 = "IF".into(), Some(0.01)),
                "node lif1 is a IF",
            ),
            (
                graph(|_, e| e.push(["lif1".into(), "fc1".into()]), Some(0.01)),
                "node lif1 has 2 outgoing edges",
            ),
            (
                graph(|_, e| e[4] = ["li".into(), "fc2".into()], Some(0.01)),
                "recurrent edge",
            ),
            (
                graph(|n, _| set(n, "input", "shape", vec![5.0]), Some(0.01)),
                "node input",
            ),
            (
                graph(
                    |n, _| set(n, "fc2", "bias", vec![f64::NAN, 0.0]),
                    Some(0.01),
                ),
                "node fc2: `bias`[0] is not finite",
            ),
            (
                graph(
                    |n, _| set(n, "lif1", "tau_mem", vec![0.04, 0.04, 0.05, 0.04]),
                    Some(0.01),
                ),
                "differs between neurons",
            ),
            (
                graph(|n, _| set(n, "lif1", "v_reset", vec![0.5; 4]), Some(0.01)),
                "v_reset must be 0",
            ),
        ];
        for (bytes, want) in cases {
            let err = from_bytes(bytes).unwrap_err();
            assert!(err.contains(want), "{err:?} should say {want:?}");
        }
        assert!(from_bytes(b"not hdf5 at all".to_vec())
            .unwrap_err()
            .contains("not an HDF5 file"));
    }
}
