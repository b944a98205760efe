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
        alpha: Vec::new(),
        beta: Vec::new(),
        travel_mm_s: None,
        adaptation: None,
        delays: Vec::new(),
    }
}

/// A graph like neurotex's with `edit` applied to its node table before writing:
/// `(name, type, fields)` and the edges; `dt` in the metadata or none.
fn graph(edit: impl Fn(&mut Vec<Node>, &mut Vec<[String; 2]>), dt: Option<f64>) -> Vec<u8> {
    let written = File::from_bytes(to_bytes(&net(), "{}", Convention::Physical).unwrap()).unwrap();
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

/// Multiplies every value of field `f` of `node` by `by`.
fn scale(nodes: &mut [Node], node: &str, f: &str, by: f64) {
    let v = field(nodes, node, f).iter().map(|x| x * by).collect();
    set(nodes, node, f, v);
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
        let x =
            crate::snn::SpikeInput::from_events(3, 20, &[(0, 1), (2, 0), (2, 2), (5, 1), (9, 0)]);
        n.scores(&x)
    };
    for (a, b) in scores(&net()).iter().zip(scores(&back.network)) {
        assert!((a - b).abs() < 1e-12, "{a} vs {b}");
    }
    // Written for snnTorch's importer (`dt` 0.1 ms, the constants scaled to it): read
    // back as the same network, its own step from `neurotex_dt`.
    let snntorch = from_bytes(to_bytes(&net(), "{}", Convention::Snntorch).unwrap()).unwrap();
    assert_eq!((snntorch.dt_s, snntorch.network.dt_ms), (0.01, 10));
    assert_eq!(back.network.travel_mm_s, None);
    // A network in steps of travel keeps its reference speed.
    let travel = Network {
        travel_mm_s: Some(12.5),
        ..net()
    };
    let back = from_bytes(to_bytes(&travel, "{}", Convention::Physical).unwrap()).unwrap();
    assert_eq!(back.network.travel_mm_s, Some(12.5));
    for (a, b) in scores(&net()).iter().zip(scores(&snntorch.network)) {
        assert!((a - b).abs() < 1e-9, "{a} vs {b}");
    }
    // A threshold of 2 with every input weight doubled, and an LI gain r halved with
    // the readout weights doubled: the same network.
    let doubled = graph(
        |nodes, _| {
            set(nodes, "lif1", "v_threshold", vec![2.0; 4]);
            for (node, f, by) in [
                ("fc1", "weight", 2.0),
                ("fc1", "bias", 2.0),
                ("li", "r", 0.5),
                ("fc2", "weight", 2.0),
                ("fc2", "bias", 2.0),
            ] {
                scale(nodes, node, f, by);
            }
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
                scale(nodes, node, f, dt);
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

/// A network whose neurons have decays of their own: written with each neuron's time
/// constants, read back with them, in NIR's own units and snnTorch's; and a graph written
/// elsewhere with time constants that differ between neurons reads as such a network.
#[test]
fn decays_of_each_neurons_own_round_trip() {
    let own = Network {
        alpha: vec![0.3, 0.5, 0.6, 0.9],
        beta: vec![0.7, 0.75, 0.95, 0.5],
        travel_mm_s: None,
        adaptation: None,
        delays: Vec::new(),
        ..net()
    };
    own.check().unwrap();
    let x = crate::snn::SpikeInput::from_events(3, 30, &[(0, 1), (2, 0), (2, 2), (5, 1), (9, 0)]);
    for convention in [Convention::Physical, Convention::Snntorch] {
        let back = from_bytes(to_bytes(&own, "{}", convention).unwrap())
            .unwrap()
            .network;
        for (a, b) in back
            .alpha
            .iter()
            .chain(&back.beta)
            .zip(own.alpha.iter().chain(&own.beta))
        {
            assert!((a - b).abs() < 1e-12, "{convention:?}: {a} vs {b}");
        }
        for (a, b) in own.scores(&x).iter().zip(back.scores(&x)) {
            assert!((a - b).abs() < 1e-9, "{convention:?}: {a} vs {b}");
        }
        assert_ne!(own.scores(&x), net().scores(&x));
    }
    // tau_mem 40, 40, 50, 40 ms at dt 10 ms: decays 0.75, 0.75, 0.8, 0.75.
    let edited = graph(
        |n, _| set(n, "lif1", "tau_mem", vec![0.04, 0.04, 0.05, 0.04]),
        Some(0.01),
    );
    let read = from_bytes(edited).unwrap().network;
    let beta: Vec<f64> = read.beta.iter().map(|b| (b * 1e9).round() / 1e9).collect();
    assert_eq!(beta, [0.75, 0.75, 0.8, 0.75]);
    assert_eq!(read.alpha.len(), 4);
    // The shared constants are those of the mean decays; an unedited graph has none of its
    // neurons' own.
    assert!((read.tau_mem_ms - (-10.0 / 0.7625f64.ln())).abs() < 1e-9);
    let plain = from_bytes(graph(|_, _| {}, Some(0.01))).unwrap().network;
    assert!(plain.alpha.is_empty() && plain.beta.is_empty());
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
            graph(|n, _| set(n, "li", "tau_mem", vec![0.04, 0.05]), Some(0.01)),
            "differs between neurons",
        ),
        (
            graph(
                |n, _| set(n, "lif1", "tau_mem", vec![0.04, 0.01, 0.05, 0.04]),
                Some(0.01),
            ),
            "node lif1: `tau_mem` 0.01 s gives the decay 0",
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
