//! Golden report: `report.md` rendered from the analyses on the small simulated design of
//! `golden.rs`, with a fixed context and no timings, so the text is the same on every run.
//! A change that moves it must regenerate it on purpose (`NEUROTEX_BLESS=1 cargo test -p
//! neurotex --test golden_report`) and say why in its commit.

use neurotex::classify::CvParams;
use neurotex::experiments::{prepare, run_all, ReproduceParams, Source};
use neurotex::report::{markdown, ReportContext};
use neurotex::sim::{design, RigParams, Texture};

#[test]
fn small_simulated_design_renders_the_stored_report() {
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
    };
    let source = Source::Simulated {
        rig: Box::new(rig),
        trials,
        seed: 7,
    };
    let prepared = prepare(&source, &params, &|_| {}).unwrap();
    let mut results = run_all(&prepared, &params, &|_| {}).unwrap();
    // wall-clock times differ from run to run; the context's total is fixed below
    results.timing_s.clear();
    let ctx = ReportContext {
        dataset:
            "The golden test's small simulated design: 4 textures x 10, 20 mm/s x 6 trials, seed 7."
                .into(),
        parameters: vec!["CV: 3-fold, 2 repeats".into()],
        total_seconds: 1.0,
        command: "cargo test --test golden_report".into(),
        paper_comparable: true,
    };
    let text = markdown(&results, &ctx);
    assert_eq!(text, markdown(&results, &ctx), "rendering twice differs");
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/golden_report.md");
    if std::env::var_os("NEUROTEX_BLESS").is_some() {
        std::fs::write(path, &text).unwrap();
    }
    let stored = std::fs::read_to_string(path).expect("golden file (NEUROTEX_BLESS=1 writes it)");
    assert_eq!(
        text, stored,
        "report.md moved: if on purpose, regenerate with NEUROTEX_BLESS=1 and say why"
    );
}
