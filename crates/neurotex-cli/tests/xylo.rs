//! The Xylo profile (`--snn-target xylo`): a network trained within Xylo Audio 2's limits,
//! predicting in the chip's integers, and its configuration (`export xylo`). Bit-equality
//! with the chip's simulator is checked in the learn crate against traces recorded from
//! XyloSim, and on whole networks by `tools/nir_interop/xylo.sh`.

use std::path::Path;

use serde_json::Value;

use crate::util::{s, Dir};

fn json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// A Xylo-profile model says so in its file, with time constants whose decays are the
/// chip's bitshifts; it predicts with the chip's integers (its shares differ from those of
/// the same weights run in float); its configuration holds 8-bit weights in XyloSim's
/// shapes; and each export refuses the other kind of network.
#[test]
fn a_xylo_network_predicts_in_integers_and_exports_the_chips_configuration() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B", "C"], &[10.0], 4);
    let model = dir.join("xylo.json");
    dir.ok(&[
        "train",
        "--dataset",
        s(&ds),
        "--classifier",
        "snn",
        "--snn-target",
        "xylo",
        "--snn-hidden",
        "12",
        "--snn-epochs",
        "3",
        "--out",
        s(&model),
    ]);
    let file = json(&model);
    assert_eq!(file["network"]["target"], "xylo");
    assert_eq!(file["network"]["reset"], "subtract");
    let tau_syn = file["classifier"]["tau_syn_ms"].as_f64().unwrap();
    let tau_mem = file["classifier"]["tau_mem_ms"].as_f64().unwrap();
    // 20 ms and 40 ms at 10 ms steps: decays 0.61 and 0.78 become 1/2 and 3/4.
    assert!(
        (1.0 - (-10.0 / tau_syn).exp() - 0.5).abs() < 1e-12,
        "{tau_syn}"
    );
    assert!(
        (1.0 - (-10.0 / tau_mem).exp() - 0.25).abs() < 1e-12,
        "{tau_mem}"
    );

    let predict = |model: &Path, out: &Path| {
        dir.ok(&[
            "predict",
            "--model",
            s(model),
            "--dataset",
            s(&ds),
            "--out",
            s(out),
        ]);
        std::fs::read_to_string(out).unwrap()
    };
    let chip = predict(&model, &dir.join("chip.csv"));
    let mut float = file.clone();
    for part in ["network", "classifier"] {
        float[part].as_object_mut().unwrap().remove("target");
    }
    let float_model = dir.join("float.json");
    std::fs::write(&float_model, float.to_string()).unwrap();
    let floats = predict(&float_model, &dir.join("float.csv"));
    assert_eq!(chip.lines().count(), 13);
    assert_ne!(chip, floats, "the integers change the shares");

    let config = dir.join("xylo.config.json");
    dir.ok(&["export", "xylo", "--model", s(&model), "--out", s(&config)]);
    let c = json(&config);
    assert_eq!(c["format"], "neurotex-xylo");
    assert_eq!(c["labels"], serde_json::json!(["A", "B", "C"]));
    let spec = &c["specification"];
    let w_in = spec["weights_in"].as_array().unwrap();
    assert_eq!(w_in.len(), 16, "one row per input");
    assert_eq!(
        w_in[0].as_array().unwrap().len(),
        12,
        "one column per hidden neuron"
    );
    let weights = w_in
        .iter()
        .flat_map(|r| r.as_array().unwrap())
        .flat_map(|w| w.as_array().unwrap());
    assert!(weights
        .clone()
        .all(|w| (-128..=127).contains(&w.as_i64().unwrap())));
    assert!(
        weights.map(|w| w.as_i64().unwrap().abs()).max() == Some(127),
        "the largest weight uses 8 bits"
    );
    assert_eq!(spec["weights_out"].as_array().unwrap().len(), 12);
    assert_eq!(spec["dash_syn"][0], 1);
    assert_eq!(spec["dash_mem"][0], 2);
    assert_eq!(spec["dt"], 0.01);

    let err = dir.fails(&[
        "export",
        "nir",
        "--model",
        s(&model),
        "--out",
        s(&dir.join("x.nir")),
    ]);
    assert!(err.contains("export xylo"), "{err}");
    let err = dir.fails(&[
        "export",
        "xylo",
        "--model",
        s(&float_model),
        "--out",
        s(&dir.join("f.json")),
    ]);
    assert!(err.contains("--snn-target xylo"), "{err}");
}

/// What the chip cannot hold is refused before training, naming the option: a reset to
/// zero, more than 1 000 hidden neurons, steps over 15 ms, a recurrent layer, and more
/// than 16 inputs (SA and FA of 16 taxels).
#[test]
fn what_the_chip_cannot_hold_is_refused_by_name() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[10.0], 3);
    let out = dir.join("never.json");
    let base = [
        "train",
        "--dataset",
        s(&ds),
        "--classifier",
        "snn",
        "--snn-target",
        "xylo",
        "--out",
        s(&out),
    ];
    let case = |extra: &'static [&'static str], said| {
        let args: Vec<&str> = base.iter().copied().chain(extra.iter().copied()).collect();
        (args, said)
    };
    let cases = [
        case(&["--snn-reset", "zero"], "snn-reset"),
        case(&["--snn-hidden", "1001"], "snn-hidden"),
        case(&["--snn-dt-ms", "20"], "snn-dt-ms"),
        case(&["--snn-recurrent"], "snn-recurrent"),
        case(&["--encoding", "sa+fa"], "at most 16 inputs"),
    ];
    dir.fails_each(&cases, &out);
}
