//! Writing a network as a NIR graph for each importer ([`Convention`]): the graph as a tree
//! of nodes and fields ([`Graph`]), then its HDF5 bytes in the layout of the `nir` package.

use hdf5_pure::{FileBuilder, GroupBuilder};

use super::Convention;
use crate::error::{ModelError, Result};
use crate::snn::Network;

/// A neuron's threshold that a readout's membrane never reaches: a CubaLIF with it never
/// fires and is read by its membrane, the readout node every importer maps.
pub const NEVER_FIRES: f64 = 1e30;

/// snnTorch's fixed import step, s.
pub const SNNTORCH_DT_S: f64 = 1e-4;

/// A field's values.
#[derive(Debug, Clone)]
pub(super) enum Values {
    F64(Vec<f64>),
    F32(Vec<f32>),
    I64(Vec<i64>),
}

/// A node: its name, NIR type, fields with their shapes, and for a `NIRGraph` node its
/// own graph.
#[derive(Debug, Clone)]
pub(super) struct Node {
    pub name: String,
    pub kind: &'static str,
    pub fields: Vec<(&'static str, Values, Vec<u64>)>,
    pub graph: Option<Graph>,
}

/// Nodes and edges.
#[derive(Debug, Clone, Default)]
pub(super) struct Graph {
    pub nodes: Vec<Node>,
    pub edges: Vec<[String; 2]>,
}

impl Graph {
    fn node(&mut self, name: &str, kind: &'static str) -> &mut Node {
        self.nodes.push(Node {
            name: name.to_string(),
            kind,
            fields: Vec::new(),
            graph: None,
        });
        self.nodes.last_mut().expect("just pushed")
    }

    fn io(&mut self, name: &str, kind: &'static str, width: usize) {
        let shape = vec![width as i64];
        self.node(name, kind)
            .fields
            .push(("shape", Values::I64(shape), vec![1]));
    }

    /// An `Affine` (with `bias`) or `Linear` node of a `(out, in)` weight given
    /// source-major (`w[i * out + o]`, as neurotex keeps weights), each output's row and
    /// bias times its `scale[o]`.
    fn dense(
        &mut self,
        name: &str,
        w: &[f64],
        bias: Option<&[f64]>,
        (out, inp): (usize, usize),
        scale: &[f64],
    ) {
        let weight: Vec<f32> = (0..out)
            .flat_map(|o| (0..inp).map(move |i| (scale[o] * w[i * out + o]) as f32))
            .collect();
        let kind = if bias.is_some() { "Affine" } else { "Linear" };
        let node = self.node(name, kind);
        let shape = vec![out as u64, inp as u64];
        node.fields.push(("weight", Values::F32(weight), shape));
        if let Some(b) = bias {
            let b: Vec<f32> = (b.iter().zip(scale))
                .map(|(&v, s)| (s * v) as f32)
                .collect();
            node.fields.push(("bias", Values::F32(b), vec![out as u64]));
        }
    }

    /// A node of neurons whose fields each hold one value per neuron, in float64 (so that
    /// reading them back gives the decays to the last bit).
    fn neurons(&mut self, name: &str, kind: &'static str, fields: Vec<(&'static str, Vec<f64>)>) {
        let node = self.node(name, kind);
        for (field, v) in fields {
            let len = v.len() as u64;
            node.fields.push((field, Values::F64(v), vec![len]));
        }
    }

    fn chain(&mut self, names: &[&str]) {
        for w in names.windows(2) {
            self.edge(w[0], w[1]);
        }
    }

    fn edge(&mut self, from: &str, to: &str) {
        self.edges.push([from.to_string(), to.to_string()]);
    }
}

/// The graph of `net` for `convention`, and the metadata's `dt` in seconds.
pub(super) fn graph(net: &Network, convention: Convention) -> (Graph, f64) {
    let dt = f64::from(net.dt_ms) / 1000.0;
    match convention {
        Convention::Physical => (euler(net, dt), dt),
        Convention::Snntorch => (euler(net, SNNTORCH_DT_S), SNNTORCH_DT_S),
        Convention::Sinabs => (sinabs(net), 1.0),
        Convention::Rockpool => (rockpool(net), 1.0),
    }
}

/// `v` for each of `len` neurons.
fn all(len: usize, v: f64) -> Vec<f64> {
    vec![v; len]
}

/// `f` of each value.
fn each(values: &[f64], f: impl Fn(f64) -> f64) -> Vec<f64> {
    values.iter().map(|&v| f(v)).collect()
}

/// NIR's equations stepped by forward Euler at `d` seconds (see the module): CubaLIF
/// hidden neurons (each with its own time constants when it has its own decays), a CubaLIF
/// readout that never fires (its current is the step's input, `tau_syn = d`), and a
/// recurrent loop `lif1 → rec → rec_id → lif1` through an identity, which importers run
/// flat with the one-step delay neurotex has.
fn euler(net: &Network, d: f64) -> Graph {
    let ((alpha, beta), kappa) = (net.hidden_decays(), net.decays().2);
    let tau_syn = each(&alpha, |a| d / (1.0 - a));
    let tau_mem = each(&beta, |b| d / (1.0 - b));
    let tau_out = d / (1.0 - kappa);
    let (h, c, n) = (net.hidden, net.classes, net.inputs);
    let mut g = Graph::default();
    g.io("input", "Input", n);
    g.dense("fc1", &net.w_in, Some(&net.b_in), (h, n), &all(h, 1.0));
    let (r, w_in) = (each(&tau_mem, |t| t / d), each(&tau_syn, |t| t / d));
    let lif = vec![
        ("tau_syn", tau_syn),
        ("tau_mem", tau_mem),
        ("r", r),
        ("v_leak", all(h, 0.0)),
        ("v_threshold", all(h, 1.0)),
        ("w_in", w_in),
    ];
    g.neurons("lif1", "CubaLIF", lif);
    g.dense("fc2", &net.w_out, Some(&net.b_out), (c, h), &all(c, 1.0));
    let readout = vec![
        ("tau_syn", all(c, d)),
        ("tau_mem", all(c, tau_out)),
        ("r", all(c, tau_out / d)),
        ("v_leak", all(c, 0.0)),
        ("v_threshold", all(c, NEVER_FIRES)),
        ("w_in", all(c, 1.0)),
    ];
    g.neurons("li", "CubaLIF", readout);
    g.io("output", "Output", c);
    g.chain(&["input", "fc1", "lif1", "fc2", "li", "output"]);
    if net.recurrent() {
        g.dense("rec", &net.w_rec, None, (h, h), &all(h, 1.0));
        let identity: Vec<f64> = (0..h * h)
            .map(|k| f64::from(u8::from(k / h == k % h)))
            .collect();
        g.dense("rec_id", &identity, None, (h, h), &all(h, 1.0));
        g.chain(&["lif1", "rec", "rec_id", "lif1"]);
    }
    g
}

/// sinabs 3.1's `from_nir`: time in steps (`dt` 1), exact decays `e^{-1/τ}`, inputs added
/// unscaled, no CubaLIF: the synaptic current is an LI node of its own before an LIF
/// node, and a recurrent loop (an Affine with zero bias: sinabs maps no Linear) joins it.
fn sinabs(net: &Network) -> Graph {
    let ((alpha, beta), kappa) = (net.hidden_decays(), net.decays().2);
    let steps = |decay: f64| -1.0 / decay.ln();
    let (h, c, n) = (net.hidden, net.classes, net.inputs);
    let mut g = Graph::default();
    g.io("input", "Input", n);
    g.dense("fc1", &net.w_in, Some(&net.b_in), (h, n), &all(h, 1.0));
    let li = |tau: Vec<f64>| {
        let len = tau.len();
        vec![
            ("tau", tau),
            ("r", all(len, 1.0)),
            ("v_leak", all(len, 0.0)),
        ]
    };
    g.neurons("syn", "LI", li(each(&alpha, steps)));
    let lif = vec![
        ("tau", each(&beta, steps)),
        ("r", all(h, 1.0)),
        ("v_leak", all(h, 0.0)),
        ("v_threshold", all(h, 1.0)),
    ];
    g.neurons("lif1", "LIF", lif);
    g.dense("fc2", &net.w_out, Some(&net.b_out), (c, h), &all(c, 1.0));
    g.neurons("li", "LI", li(all(c, steps(kappa))));
    g.io("output", "Output", c);
    g.chain(&["input", "fc1", "syn", "lif1", "fc2", "li", "output"]);
    if net.recurrent() {
        g.dense("rec", &net.w_rec, Some(&vec![0.0; h]), (h, h), &all(h, 1.0));
        g.chain(&["lif1", "rec", "syn"]);
    }
    g
}

/// Rockpool 3.1's `from_nir`: each node's step is `min(tau_mem / (1 + r))` (the metadata
/// is not read), exact decays, the input added before the synaptic decay (so the weights
/// into a decaying state are divided by its decay, neuron by neuron), an LI's `tau` cast
/// to an integer (so the readout's decay goes into `r` with `tau` 1), and a recurrent layer
/// as a nested graph `input → lif → w_rec → lif → output`, as Rockpool writes one.
fn rockpool(net: &Network) -> Graph {
    let ((alpha, beta), kappa) = (net.hidden_decays(), net.decays().2);
    let steps = |decay: f64| -1.0 / decay.ln();
    let (h, c, n) = (net.hidden, net.classes, net.inputs);
    let tau_mem = each(&beta, steps);
    let lif = || {
        vec![
            ("tau_syn", each(&alpha, steps)),
            ("tau_mem", tau_mem.clone()),
            ("r", each(&tau_mem, |t| t - 1.0)),
            ("v_leak", all(h, 0.0)),
            ("v_threshold", all(h, 1.0)),
            ("w_in", all(h, 1.0)),
        ]
    };
    let into_synapse = each(&alpha, |a| 1.0 / a);
    let mut g = Graph::default();
    g.io("input", "Input", n);
    g.dense("fc1", &net.w_in, Some(&net.b_in), (h, n), &into_synapse);
    if net.recurrent() {
        let mut inner = Graph::default();
        inner.io("input", "Input", h);
        inner.neurons("lif", "CubaLIF", lif());
        inner.dense("w_rec", &net.w_rec, None, (h, h), &into_synapse);
        inner.io("output", "Output", h);
        inner.chain(&["input", "lif", "w_rec", "lif", "output"]);
        g.node("lif1", "NIRGraph").graph = Some(inner);
    } else {
        g.neurons("lif1", "CubaLIF", lif());
    }
    g.dense(
        "fc2",
        &net.w_out,
        Some(&net.b_out),
        (c, h),
        &all(c, 1.0 / kappa),
    );
    let li = vec![
        ("tau", all(c, 1.0)),
        ("r", all(c, steps(kappa) - 1.0)),
        ("v_leak", all(c, 0.0)),
    ];
    g.neurons("li", "LI", li);
    g.io("output", "Output", c);
    g.chain(&["input", "fc1", "lif1", "fc2", "li", "output"]);
    g
}

/// The graph's bytes (HDF5) for `net` written for `convention`, with `model_json` (the
/// model file without its network) in the metadata.
///
/// # Errors
/// The HDF5 writer fails (it should not for these shapes).
pub fn to_bytes(net: &Network, model_json: &str, convention: Convention) -> Result<Vec<u8>> {
    let (graph, dt) = graph(net, convention);
    let mut fb = FileBuilder::new();
    fb.create_dataset("version")
        .with_vlen_strings(&["1.0.0"])
        .with_shape(&[]);
    let mut node = fb.create_group("node");
    put_graph(&mut node, &graph);
    let mut meta = node.create_group("metadata");
    put_f64(&mut meta, "dt", dt);
    // The network's own step: a graph in steps or in snnTorch's time has another `dt`.
    put_f64(&mut meta, "neurotex_dt", f64::from(net.dt_ms) / 1000.0);
    put_str(&mut meta, "neurotex_for", convention.name());
    if let Some(v) = net.travel_mm_s {
        // Steps of travel: at speed v the step lasts `dt x neurotex_travel_mm_s / v`.
        put_f64(&mut meta, "neurotex_travel_mm_s", v);
    }
    put_str(&mut meta, "readout", net.readout.name());
    if !net.reset.is_zero() {
        // NIR 1.0's neurons reset to `v_reset`: the subtracting neuron is neurotex's word
        // to itself here (sinabs and Rockpool have it as their own neuron).
        put_str(&mut meta, "reset", net.reset.name());
    }
    put_str(&mut meta, "neurotex_model", model_json);
    node.add_group(meta.finish());
    fb.add_group(node.finish());
    fb.finish()
        .map_err(|e| ModelError::Inconsistent(format!("writing the NIR graph: {e}")).into())
}

/// `graph`'s type, edges and nodes into `g` (nested graphs recursively).
fn put_graph(g: &mut GroupBuilder, graph: &Graph) {
    put_str(g, "type", "NIRGraph");
    let edges: Vec<&str> = (graph.edges.iter())
        .flat_map(|e| [e[0].as_str(), e[1].as_str()])
        .collect();
    g.create_dataset("edges")
        .with_vlen_strings(&edges)
        .with_shape(&[graph.edges.len() as u64, 2]);
    let mut nodes = g.create_group("nodes");
    for node in &graph.nodes {
        let mut n = nodes.create_group(&node.name);
        match &node.graph {
            Some(inner) => put_graph(&mut n, inner),
            None => put_str(&mut n, "type", node.kind),
        }
        for (field, values, shape) in &node.fields {
            let d = n.create_dataset(field);
            match values {
                Values::F64(v) => d.with_f64_data(v),
                Values::F32(v) => d.with_f32_data(v),
                Values::I64(v) => d.with_i64_data(v),
            }
            .with_shape(shape);
        }
        nodes.add_group(n.finish());
    }
    g.add_group(nodes.finish());
}

pub(super) fn put_str(g: &mut GroupBuilder, name: &str, value: &str) {
    g.create_dataset(name)
        .with_vlen_strings(&[value])
        .with_shape(&[]);
}

fn put_f64(g: &mut GroupBuilder, name: &str, value: f64) {
    g.create_dataset(name)
        .with_f64_data(&[value])
        .with_shape(&[]);
}
