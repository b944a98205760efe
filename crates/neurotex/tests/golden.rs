//! Golden outputs of the analyses on a small simulated design with a fixed seed: the
//! results (`golden_small_design.json`) and the report rendered from them
//! (`golden_report.md`, with a fixed context and no timings). A change that moves either
//! must regenerate it on purpose (`NEUROTEX_BLESS=1 cargo test -p neurotex --test library golden`)
//! and say why in its commit.

use crate::support;

use std::sync::OnceLock;

use neurotex::classify::CvParams;
use neurotex::experiments::{prepare, run_all, ReproduceParams, Results};
use neurotex::report::{markdown, ReportContext};

/// The analyses on 4 textures x 10, 20 mm/s x 6 trials of 20 mm slides, seed 7, without
/// timings and provenance (wall-clock times, dates and commits differ from run to run);
/// computed once per test binary.
fn small_design_results() -> &'static Results {
    static RESULTS: OnceLock<Results> = OnceLock::new();
    RESULTS.get_or_init(|| {
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
            encoder_draws: 3,
            // E9's results carry wall-clock times; it has tests of its own.
            e9: false,
            ..ReproduceParams::default()
        }
        .check()
        .unwrap();
        let source = support::small_design(7);
        let prepared = prepare(&source, &params, &|_| {}).unwrap();
        let mut results = run_all(&prepared, &params, &|_| {}).unwrap();
        results.timing_s.clear();
        results.provenance = None;
        results
    })
}

/// Compares `text` with the stored file `name` under `tests/data`, writing it first when
/// `NEUROTEX_BLESS` is set.
fn matches_stored(name: &str, text: &str) {
    let path = format!("{}/tests/data/{name}", env!("CARGO_MANIFEST_DIR"));
    if std::env::var_os("NEUROTEX_BLESS").is_some() {
        std::fs::write(&path, text).unwrap();
    }
    let stored = std::fs::read_to_string(&path).expect("golden file (NEUROTEX_BLESS=1 writes it)");
    assert_eq!(
        text, stored,
        "{name} moved: if on purpose, regenerate with NEUROTEX_BLESS=1 and say why"
    );
}

#[test]
fn small_simulated_design_matches_the_stored_results() {
    let value = serde_json::to_value(small_design_results()).unwrap();
    // accuracies and rates rounded so the file reads well; the bits are checked by the
    // determinism tests
    let text = serde_json::to_string_pretty(&round(value)).unwrap() + "\n";
    matches_stored("golden_small_design.json", &text);
}

#[test]
fn small_simulated_design_renders_the_stored_report() {
    let results = small_design_results();
    let ctx = ReportContext {
        dataset:
            "The golden test's small simulated design: 4 textures x 10, 20 mm/s x 6 trials, seed 7."
                .into(),
        source: "small simulated design, seed 7".into(),
        parameters: vec!["CV: 3-fold, 2 repeats".into()],
        total_seconds: 1.0,
        command: "cargo test --test library golden".into(),
        paper_comparable: true,
    };
    let text = markdown(results, &ctx);
    assert_eq!(text, markdown(results, &ctx), "rendering twice differs");
    matches_stored("golden_report.md", &text);
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
