//! Golden results: the analyses on a small simulated design with a fixed seed. A change
//! that moves them must regenerate them on purpose (`NEUROTEX_BLESS=1 cargo test --test
//! golden`) and say why in its commit.

use neurotex::classify::CvParams;
use neurotex::experiments::{prepare, run_all, ReproduceParams, Source};
use neurotex::sim::{design, RigParams, Texture};

#[test]
fn small_simulated_design_matches_the_stored_results() {
    let rig = RigParams {
        hold_s: 0.5,
        slide_mm: 20.0,
        ..RigParams::default()
    };
    let trials = design(
        &[Texture::Ft1, Texture::Sb, Texture::Stf, Texture::Cp],
        &[10.0, 20.0],
        6,
    );
    let params = ReproduceParams {
        cv: CvParams {
            folds: 3,
            seed: 0,
            repeats: 2,
        },
        e3_repeats: 2,
        e3_counts: vec![4, 16],
        e5_fractions: vec![0.5, 1.0],
        e7_gains: vec![5.0, 8.0],
        e8_ks: vec![1, 5],
        ..ReproduceParams::default()
    }
    .check()
    .unwrap();
    let source = Source::Simulated {
        rig: Box::new(rig),
        trials,
        seed: 7,
    };
    let prepared = prepare(&source, &params, &|_| {}).unwrap();
    let mut results = run_all(&prepared, &params, &|_| {}).unwrap();
    results.timing_s.clear();
    let value = serde_json::to_value(&results).unwrap();
    // accuracies and rates rounded so the file reads well; the bits are checked by the
    // determinism tests
    let text = serde_json::to_string_pretty(&round(value)).unwrap() + "\n";
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/golden_small_design.json"
    );
    if std::env::var_os("NEUROTEX_BLESS").is_some() {
        std::fs::write(path, &text).unwrap();
    }
    let stored = std::fs::read_to_string(path).expect("golden file (NEUROTEX_BLESS=1 writes it)");
    assert_eq!(
        text, stored,
        "results moved: if on purpose, regenerate with NEUROTEX_BLESS=1 and say why"
    );
}

fn round(v: serde_json::Value) -> serde_json::Value {
    use serde_json::Value;
    match v {
        Value::Number(n) if n.is_f64() => {
            let x = n.as_f64().unwrap();
            serde_json::json!((x * 1e6).round() / 1e6)
        }
        Value::Array(a) => Value::Array(a.into_iter().map(round).collect()),
        Value::Object(o) => Value::Object(o.into_iter().map(|(k, v)| (k, round(v))).collect()),
        other => other,
    }
}
