//! The intervals the report prints, recomputed independently from the analyses'
//! per-recording results: E1's accuracy intervals over recordings and encodings
//! (`classify::bootstrap_over_encodings`) and its paired comparison of 3D-GLCM with the
//! single taxel (`experiments::compare_encodings`).
//!
//! The statistics layer itself is checked against scipy, statsmodels and numpy in
//! `stats_reference.rs`; this file checks the path from predictions to the numbers in
//! report.md. A seeded bootstrap has no outside value to compare with (scipy's bootstrap
//! draws other resamples), so the reference here redraws the same resamples (the same
//! ChaCha8 generator and seed, one uniform index in 0..encodings and then one in 0..n per
//! recording, as `bootstrap_over_encodings` documents) and does everything else its own
//! slow, evident way:
//! - each recording's share of right predictions from the out-of-fold predictions and the
//!   table's labels (3D-GLCM);
//! - the resampled means by plain loops, sorted, and read at the 2.5th and 97.5th percentiles
//!   by numpy's default linear interpolation, written out here;
//! - the paired interval by resampling the per-recording differences themselves, not the
//!   library's shifted `(d + 1) / 2`;
//! - the printed text by formatting those values as report.md does (one decimal, percent).
//!
//! Tolerance: 1e-12 absolute on shares and interval ends, which differ from the library's
//! only in the order of floating-point operations; a wrong seed, a resample drawn
//! differently, a shifted percentile, a share counted over the wrong predictions or a
//! mis-mapped paired interval moves them by 1e-3 or more.

use crate::support;

use std::collections::BTreeMap;

use neurotex::classify::{BootstrapParams, CvParams};
use neurotex::experiments::{prepare, run_all, ReproduceParams, Tables};
use neurotex::report::{markdown, ReportContext};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const TOLERANCE: f64 = 1e-12;

/// The `q` quantile of ascending `sorted` by linear interpolation between order statistics
/// (numpy's `np.quantile` default, Hyndman and Fan definition 7).
fn quantile(sorted: &[f64], q: f64) -> f64 {
    let h = (sorted.len() - 1) as f64 * q;
    let below = h.floor() as usize;
    if below + 1 < sorted.len() {
        sorted[below] + (h - below as f64) * (sorted[below + 1] - sorted[below])
    } else {
        sorted[below]
    }
}

/// The 95 % percentile-bootstrap interval of the mean of `values[e]` over recordings and
/// encodings `e`, drawn with the library's generator and seed but computed step by step:
/// each resample picks an encoding (when there are several), then the recordings.
fn reference_bootstrap(values: &[Vec<f64>], seed: u64, resamples: usize) -> (f64, f64) {
    let n = values[0].len();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut means = Vec::with_capacity(resamples);
    for _ in 0..resamples {
        let e = if values.len() > 1 {
            rng.gen_range(0..values.len() as u64) as usize
        } else {
            0
        };
        let mut sum = 0.0;
        for _ in 0..n {
            sum += values[e][rng.gen_range(0..n as u64) as usize];
        }
        means.push(sum / n as f64);
    }
    means.sort_by(|a, b| a.partial_cmp(b).expect("no NaN"));
    (quantile(&means, 0.025), quantile(&means, 0.975))
}

fn close(what: &str, ours: f64, reference: f64) {
    assert!(
        (ours - reference).abs() <= TOLERANCE,
        "{what}: neurotex {ours}, reference {reference}"
    );
}

/// A small simulated run: its headline tables, its report, and the bootstrap seed.
fn small_run() -> (Tables, neurotex::experiments::Results, String, u64) {
    let params = ReproduceParams {
        cv: CvParams {
            folds: 3,
            seed: 0,
            repeats: 3,
        },
        e3_counts: vec![4],
        e3_repeats: 1,
        e5_fractions: vec![1.0],
        e7_gains: vec![8.0],
        e8_ks: vec![5],
        encoder_draws: 3,
        seed: 11,
        ..ReproduceParams::default()
    }
    .check()
    .unwrap();
    let source = support::small_design(3);
    let prepared = prepare(&source, &params, &|_| {}).unwrap();
    let tables = Tables::build(&prepared, &params).unwrap();
    let results = run_all(&prepared, &params, &|_| {}).unwrap();
    let context = ReportContext {
        dataset: "a small simulated design".into(),
        source: "a small simulated design".into(),
        parameters: Vec::new(),
        total_seconds: 1.0,
        command: "cargo test --test library report_intervals".into(),
        paper_comparable: false,
    };
    let report = markdown(&results, &context);
    (tables, results, report, params.seed)
}

#[test]
fn the_printed_accuracy_intervals_and_paired_differences_match_a_step_by_step_bootstrap() {
    let (tables, results, report, seed) = small_run();
    let resamples = BootstrapParams::default().resamples;
    let pct = |v: f64| format!("{:.1}", 100.0 * v);

    for speed in results.speeds.clone() {
        let e1 = results.e1.get(speed).expect("E1 at every speed");
        let encodings = tables.encodings_at(speed);
        assert_eq!(encodings.len(), 3);
        // each recording's share of right 3D-GLCM predictions under each encoding, from the
        // predictions
        let mut glcm3d: Vec<Vec<f64>> = Vec::new();
        for h in &encodings {
            let mut right: BTreeMap<usize, (usize, usize)> = BTreeMap::new();
            for p in h
                .glcm3d
                .predictions
                .as_ref()
                .expect("3D-GLCM keeps its predictions")
            {
                let truth = &tables.glcm3d.metas[p.row].label;
                let entry = right.entry(p.row).or_default();
                entry.0 += usize::from(h.glcm3d.labels[p.predicted] == *truth);
                entry.1 += 1;
            }
            assert_eq!(right.len(), h.glcm3d.correct_shares.len());
            for ((row, share), (&ref_row, &(k, n))) in h.glcm3d.correct_shares.iter().zip(&right) {
                assert_eq!(*row, ref_row);
                close("3D-GLCM share", *share, k as f64 / n as f64);
            }
            glcm3d.push(right.values().map(|&(k, n)| k as f64 / n as f64).collect());
        }
        let taxel: Vec<Vec<f64>> = encodings
            .iter()
            .map(|h| h.taxel.correct_shares.iter().map(|s| s.1).collect())
            .collect();
        let mean = |v: &[Vec<f64>]| {
            let all: Vec<f64> = v.iter().flatten().copied().collect();
            all.iter().sum::<f64>() / all.len() as f64
        };
        close("3D-GLCM accuracy", e1.glcm3d, mean(&glcm3d));
        close("single taxel accuracy", e1.taxel_mean, mean(&taxel));

        let (lo, hi) = reference_bootstrap(&glcm3d, seed, resamples);
        close("3D-GLCM interval, lower", e1.glcm3d_interval.lower, lo);
        close("3D-GLCM interval, upper", e1.glcm3d_interval.upper, hi);
        let printed = format!("{} [{}, {}]", pct(e1.glcm3d), pct(lo), pct(hi));
        assert!(
            report.contains(&printed),
            "{speed} mm/s: {printed} not in the report"
        );

        let (lo, hi) = reference_bootstrap(&taxel, seed, resamples);
        close("taxel interval, lower", e1.taxel_mean_interval.lower, lo);
        close("taxel interval, upper", e1.taxel_mean_interval.upper, hi);
        let printed = format!("{} [{}, {}]", pct(e1.taxel_mean), pct(lo), pct(hi));
        assert!(
            report.contains(&printed),
            "{speed} mm/s: {printed} not in the report"
        );

        let differences: Vec<Vec<f64>> = glcm3d
            .iter()
            .zip(&taxel)
            .map(|(g, t)| g.iter().zip(t).map(|(g, t)| g - t).collect())
            .collect();
        let (lo, hi) = reference_bootstrap(&differences, seed, resamples);
        let paired = &e1.glcm3d_vs_taxel;
        close("paired difference", paired.difference, mean(&differences));
        close("paired interval, lower", paired.lower, lo);
        close("paired interval, upper", paired.upper, hi);
        let printed = format!(
            "{:+.1} points [{:+.1}, {:+.1}]",
            100.0 * mean(&differences),
            100.0 * lo,
            100.0 * hi
        );
        assert!(
            report.contains(&printed),
            "{speed} mm/s: {printed} not in the report"
        );
    }
}
