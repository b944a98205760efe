//! E9 on a small simulated design: its paper's-method column is E1's and E6's 3D-GLCM on the
//! same folds (a second path to the same numbers), every standard candidate is ranked, and
//! the report shows the section and its figures. With `e9_snn`, the spiking network runs
//! beside the paper's method on the same folds, whose column is E1's again.

use crate::support;

use neurotex::classify::CvParams;
use neurotex::experiments::{prepare, run_all, ReproduceParams};
use neurotex::report::{markdown, ReportContext};

#[test]
fn e9_ranks_every_standard_candidate_and_agrees_with_e1_and_e6() {
    let params = ReproduceParams {
        cv: CvParams {
            folds: 3,
            seed: 0,
            repeats: 2,
        },
        e9_repeats: 2,
        e9_snn: true,
        e3_counts: vec![4],
        e5_fractions: vec![1.0],
        e7_gains: vec![8.0],
        e8_ks: vec![5],
        encoder_draws: 1,
        ..ReproduceParams::default()
    }
    .check()
    .unwrap();
    let prepared = prepare(&support::small_design(7), &params, &|_| {}).unwrap();
    assert!(
        prepared.encoded.iter().all(|e| e.fa.is_some()),
        "E9 needs FA"
    );
    let r = run_all(&prepared, &params, &|_| {}).unwrap();
    let e9 = r.e9.as_ref().expect("E9 ran");
    for c in [&e9.per_speed, &e9.held_out] {
        // 2 encodings x (taxel and van-rossum with KNN + 5 feature methods x 3 classifiers).
        assert_eq!(c.results.len(), 34);
        assert_eq!(c.n_recordings, prepared.encoded.len());
        let accuracies: Vec<f64> = c.results.iter().map(|x| x.accuracy).collect();
        assert!(accuracies.windows(2).all(|w| w[0] >= w[1]));
        assert_eq!(c.best, c.results[0]);
    }
    let paper = |c: &neurotex::compare::Comparison| c.results.iter().find(|x| x.paper).cloned();
    let (within, held) = (paper(&e9.per_speed).unwrap(), paper(&e9.held_out).unwrap());
    for (i, (speed, e1)) in r.e1.iter().enumerate() {
        let at = &within.per_condition[i];
        assert_eq!(at.condition, speed.to_string());
        assert_eq!(at.accuracy, e1.glcm3d, "within {speed} mm/s");
    }
    for (i, (speed, e6)) in r.e6.iter().enumerate() {
        let at = &held.per_condition[i];
        assert_eq!(at.condition, speed.to_string());
        assert_eq!(at.accuracy, e6.glcm3d, "held out {speed} mm/s");
    }
    assert!(e9.held_out.nested.is_some() && e9.per_speed.nested.is_some());
    assert!(matches!(
        e9.baselines,
        Some(neurotex::experiments::Baselines::Compared { .. })
    ));

    let spiking = e9.spiking.as_ref().expect("the network ran");
    for (c, paper_column) in [(&spiking.per_speed, &within), (&spiking.held_out, &held)] {
        assert_eq!(c.results.len(), 3);
        let rates = neurotex::experiments::Spiking::rates(c).expect("the rates baseline ran");
        assert_eq!(
            (rates.encoding.as_str(), rates.classifier.as_str()),
            ("sa+fa", "linear")
        );
        let (network, paper) = neurotex::experiments::Spiking::pair(c).unwrap();
        assert_eq!(paper.per_condition, paper_column.per_condition);
        assert_eq!(
            (network.encoding.as_str(), network.method.as_str()),
            ("sa+fa", "spikes")
        );
        let gap = network.difference_vs_paper.unwrap();
        assert!((gap - (network.accuracy - paper.accuracy)).abs() < 1e-12);
        assert!((0.0..=1.0).contains(&network.p_vs_paper.unwrap()));
        // and against its inputs' rates, paired on the same folds
        let adds = network.difference_vs_rates.unwrap();
        assert_eq!(adds, network.accuracy - rates.accuracy);
        assert!((0.0..=1.0).contains(&network.p_vs_rates.unwrap()));
        assert_eq!((rates.p_vs_rates, paper.p_vs_rates), (None, None));
        assert!(network.ci[0] <= network.accuracy && network.accuracy <= network.ci[1]);
        assert!(c.chance > 0.0 && c.chance < 1.0);
    }

    let context = ReportContext {
        dataset: "a small simulated design".into(),
        source: "a small simulated design".into(),
        parameters: Vec::new(),
        total_seconds: 1.0,
        command: "cargo test --test library e9".into(),
        paper_comparable: false,
    };
    let text = markdown(&r, &context);
    assert!(text.contains("(E9, beyond the paper)\n"), "{text}");
    assert!(
        text.contains("### The spiking network beside the paper's method"),
        "{text}"
    );
    let (network, _) = neurotex::experiments::Spiking::pair(&spiking.per_speed).unwrap();
    let mean = format!(
        "{:.1} [{:.1}, {:.1}]",
        100.0 * network.accuracy,
        100.0 * network.ci[0],
        100.0 * network.ci[1]
    );
    assert!(text.contains(&mean), "{mean} not in the report");
    // What the timing adds: the network minus its inputs' rates, within each speed.
    let rates = neurotex::experiments::Spiking::rates(&spiking.per_speed).unwrap();
    let adds = format!(
        "The network is {:+.1} points (p ",
        100.0 * (network.accuracy - rates.accuracy)
    );
    assert!(text.contains(&adds), "{adds} not in the report");
    for figure in ["e9_per_speed.svg", "e9_held_out.svg", "e9_speeds.svg"] {
        assert!(text.contains(figure), "{figure}");
    }
}
