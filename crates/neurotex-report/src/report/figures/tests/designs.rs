//! The two designs the figures are drawn on: the golden test's small one and a
//! FabricSlide-shaped wide one, with the hand-made intervals and comparisons they hold.

use super::*;

/// The golden test's small design, as stored (accuracies rounded to 1e-6).
pub(crate) fn small() -> Results {
    let text = include_str!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../neurotex/tests/data/golden_small_design.json"
    ));
    serde_json::from_str(text).expect("golden results parse")
}

/// A deterministic value in 0..1 for index `i` (no randomness needed, just variety).
fn wobble(i: usize) -> f64 {
    ((i * 37 + 11) % 100) as f64 / 100.0
}

/// A FabricSlide-shaped result: 12 signed speeds, 7 classes with long names, 16 gains.
pub(crate) fn wide() -> Results {
    let speeds: Vec<Speed> = [-150, -120, -100, -50, -20, -10, 10, 20, 50, 100, 120, 150]
        .iter()
        .map(|&s| Speed::of(f64::from(s)))
        .collect();
    let labels: Vec<String> = [
        "BeigeCotton",
        "BrownCotton",
        "Canvas",
        "DenimFlex",
        "Denim",
        "Linen",
        "WovenFabric",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let by = |f: &dyn Fn(usize) -> f64| -> Vec<f64> { (0..speeds.len()).map(f).collect() };
    let acc = by(&|i| 0.3 + 0.5 * wobble(i));
    let e1: BySpeed<E1Speed> = speeds
        .iter()
        .enumerate()
        .map(|(i, &s)| {
            (
                s,
                E1Speed {
                    taxel_mean: acc[i] * 0.6,
                    taxel_best: acc[i] * 0.9,
                    taxel_best_cell: "r1c0".into(),
                    glcm3d: acc[i],
                    glcm3d_std: 0.03,
                    encodings: 8,
                    n: 69,
                    // FabricSlide records 5 of its 7 fabrics at the positive speeds
                    classes: if s.mm_s() > 0.0 { 5 } else { 7 },
                    chance: if s.mm_s() > 0.0 { 0.2 } else { 1.0 / 7.0 },
                    majority: if s.mm_s() > 0.0 { 0.22 } else { 0.16 },
                    taxel_mean_responsive: Some(acc[i] * 0.8),
                    glcm3d_interval: interval(acc[i]),
                    taxel_mean_interval: interval(acc[i] * 0.6),
                    glcm3d_vs_taxel: comparison(acc[i] * 0.4),
                },
            )
        })
        .collect();
    let e4 = speeds
        .iter()
        .enumerate()
        .map(|(i, &s)| {
            (
                s,
                E4Speed {
                    taxel_mean: acc[i] * 0.6,
                    glcm2d: acc[i] * 0.7,
                    glcm3d: acc[i],
                    glcm2d_interval: interval(acc[i] * 0.7),
                    taxel_vs_glcm2d: comparison(-acc[i] * 0.1),
                    glcm3d_vs_glcm2d: comparison(acc[i] * 0.3),
                },
            )
        })
        .collect();
    let fractions: Vec<f64> = (1..=10).map(|k| k as f64 / 10.0).collect();
    let e5 = speeds
        .iter()
        .enumerate()
        .map(|(i, &s)| {
            let glcm3d: Vec<Option<f64>> = fractions
                .iter()
                .map(|&p| (p > 0.1 || i > 3).then_some(acc[i] * (0.4 + 0.6 * p)))
                .collect();
            (
                s,
                E5Speed {
                    fractions: fractions.clone(),
                    glcm3d_interval: glcm3d.iter().map(|a| a.map(interval)).collect(),
                    glcm3d,
                    taxel_full: acc[i] * 0.6,
                    taxel_full_interval: Some(interval(acc[i] * 0.6)),
                    first_match: Some(0.3),
                    longest_vs_shortest: None,
                },
            )
        })
        .collect();
    let e5c = speeds
        .iter()
        .enumerate()
        .map(|(i, &s)| {
            let bins = 5 + 3 * i;
            let times_s: Vec<f64> = (1..=bins).map(|b| 0.2 * b as f64).collect();
            let rise = |b: usize| (b as f64 / bins as f64).min(1.0);
            (
                s,
                crate::experiments::E5CausalSpeed {
                    calibration: crate::causal::ConditioningCalibration {
                        conditioning: crate::signal::CausalConditioning {
                            offsets: vec![0.0; 16],
                            scale: 1234.5,
                        },
                        recordings: 69,
                        median_duration_ms: 200 * bins,
                        rest_spread: 0.0,
                    },
                    n: 69,
                    chance: if s.mm_s() > 0.0 { 0.2 } else { 1.0 / 7.0 },
                    median_slide_s: 0.2 * bins as f64,
                    accuracy: (1..=bins).map(|b| acc[i] * (0.3 + 0.6 * rise(b))).collect(),
                    sliding: (1..=bins).map(|b| 1.0 - 0.5 * rise(b).powi(8)).collect(),
                    fractions: e5_fraction_rows(&fractions, 0.2 * bins as f64, acc[i]),
                    whole: acc[i] * 0.9,
                    whole_interval: interval(acc[i] * 0.9),
                    offline: acc[i],
                    offline_vs_causal: comparison(acc[i] * 0.1),
                    decision: crate::experiments::TimeToDecision {
                        rule: crate::causal::DecisionRule::default(),
                        episodes: 69,
                        decided: 50,
                        never_share: 19.0 / 69.0,
                        accuracy: Some(0.8),
                        quartiles_s: Some([0.6, 0.2 * (bins / 2).max(3) as f64, 0.2 * bins as f64]),
                        decided_by: (1..=bins).map(|b| 50.0 / 69.0 * rise(b)).collect(),
                    },
                    times_s,
                },
            )
        })
        .collect();
    let e6 = speeds
        .iter()
        .enumerate()
        .map(|(i, &s)| {
            let train = speeds.iter().copied().filter(|&t| t != s).collect();
            (
                s,
                E6Speed {
                    train,
                    chance: if s.mm_s() > 0.0 { 0.2 } else { 1.0 / 7.0 },
                    taxel_mean: 0.3,
                    encodings: 1,
                    glcm3d: acc[i] * 0.8,
                    taxel_mean_interval: interval(0.3),
                    glcm3d_interval: interval(acc[i] * 0.8),
                    glcm3d_vs_taxel: comparison(acc[i] * 0.8 - 0.3),
                },
            )
        })
        .collect();
    let ks = vec![1, 3, 5, 7, 9];
    let e8 = speeds
        .iter()
        .enumerate()
        .map(|(i, &s)| {
            let shift = |d: f64| -> Vec<f64> {
                ks.iter()
                    .map(|&k| (acc[i] * d - 0.01 * k as f64).max(0.0))
                    .collect()
            };
            (
                s,
                E8Speed {
                    k: ks.clone(),
                    encodings: 1,
                    taxel_mean_interval: shift(0.6).into_iter().map(interval).collect(),
                    glcm3d_interval: shift(1.0).into_iter().map(interval).collect(),
                    taxel_mean: shift(0.6),
                    glcm3d: shift(1.0),
                    glcm3d_vs_taxel: Vec::new(),
                },
            )
        })
        .collect();
    let n = labels.len();
    let confusion = |strength: usize| -> Vec<Vec<usize>> {
        (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| if i == j { strength } else { (i + 2 * j) % 5 })
                    .collect()
            })
            .collect()
    };
    let gains: Vec<f64> = (5..=20).map(f64::from).collect();
    let bins = 61;
    let counts = gains
        .iter()
        .enumerate()
        .map(|(g, _)| {
            (0..n)
                .map(|l| {
                    if l == 3 && g < 8 {
                        return vec![0; bins];
                    }
                    (0..bins)
                        .map(|b| {
                            if b == bins - 1 {
                                400
                            } else {
                                ((b * (l + 1) + g) % 13) as u64
                            }
                        })
                        .collect()
                })
                .collect()
        })
        .collect();
    let rate_hz: Vec<Vec<f64>> = gains
        .iter()
        .map(|g| {
            (0..n)
                .map(|l| (g - 5.0) * 0.4 * (l as f64 + 1.0) / n as f64)
                .collect()
        })
        .collect();
    let cells = 16;
    let example = |label: &str, phase: usize| E0Example {
        label: label.into(),
        file: format!("{label}.csv"),
        psth: (0..28).map(|b| ((b + phase) % 4) as u32 / 3).collect(),
        volume: (0..cells)
            .map(|c| {
                (0..27)
                    .map(|b| 5.0 * ((b + c + phase) % 3) as f64)
                    .collect()
            })
            .collect(),
    };
    Results {
        speeds: speeds.clone(),
        labels: labels.clone(),
        recordings: 962,
        resampled: 962,
        flat: 0,
        taxels: TaxelDiagnostics {
            ceiling_hz: 63.0,
            taxels: (0..16)
                .map(|i| TaxelResponse {
                    taxel: format!("r{}c{}", i / 4, i % 4),
                    silent_share: if i == 0 { 0.98 } else { 0.3 },
                    saturated_share: 0.0,
                })
                .collect(),
        },
        e0: Some(E0 {
            speed: Speed::of(10.0),
            taxel: [1, 1],
            psth_bin_ms: 200,
            examples: vec![example("BeigeCotton", 0), example("BrownCotton", 1)],
        }),
        e1,
        e2: Some(E2 {
            speed: Speed::of(10.0),
            labels: labels.clone(),
            taxel: confusion(30),
            glcm3d: confusion(60),
            glcm3d_vs_taxel_by_class: Vec::new(),
        }),
        e3: Some(E3 {
            speed: Speed::of(10.0),
            repeats: 10,
            n: (2..=16).collect(),
            mean: (2..=16).map(|k| 0.7 - 0.01 * k as f64).collect(),
            std: (2..=16).map(|k| 0.02 + 0.002 * k as f64).collect(),
            interval: (2..=16).map(|k| interval(0.7 - 0.01 * k as f64)).collect(),
            glcm3d: 0.71,
            taxel_mean: 0.36,
            unperturbed_vs_moved: Vec::new(),
        }),
        e4,
        e5,
        e5c,
        e6,
        e7: Some(E7 {
            speed: Speed::of(10.0),
            sweep: IsiSweep {
                gains: gains.clone(),
                labels: labels.clone(),
                bin_ms: 5,
                counts,
                spikes: vec![vec![0; n]; gains.len()],
                taxel_seconds: vec![vec![1.0; n]; gains.len()],
            },
            rate_hz,
            median_isi_ms: vec![vec![None; n]; gains.len()],
        }),
        e8,
        e9: None,
        encoder_sensitivity: None,
        across_seeds: None,
        predictions: Vec::new(),
        gain_calibration: None,
        provenance: None,
        skipped: BTreeMap::new(),
        timing_s: BTreeMap::new(),
    }
}

/// E5c's rows at E5's shares of a slide of `slide_s`.
fn e5_fraction_rows(
    fractions: &[f64],
    slide_s: f64,
    a: f64,
) -> Vec<crate::experiments::E5cFraction> {
    fractions
        .iter()
        .map(|&p| crate::experiments::E5cFraction {
            fraction: p,
            time_s: p * slide_s,
            causal: Some(a * (0.3 + 0.6 * p)),
            causal_interval: Some(interval(a * (0.3 + 0.6 * p))),
            offline: Some(a * (0.4 + 0.6 * p)),
            offline_interval: Some(interval(a * (0.4 + 0.6 * p))),
        })
        .collect()
}

/// A hand-made 95 % interval of ±5 points around `a`.
fn interval(a: f64) -> crate::classify::Interval {
    crate::classify::Interval {
        estimate: a,
        lower: (a - 0.05).max(0.0),
        upper: (a + 0.05).min(1.0),
        level: 0.95,
        method: crate::classify::IntervalMethod::PercentileBootstrap {
            n: 69,
            resamples: 2000,
            seed: 0,
        },
    }
}

/// A hand-made comparison with difference `d` and an interval of ±8 points.
fn comparison(d: f64) -> crate::experiments::Comparison {
    let (lower, upper) = (d - 0.08, d + 0.08);
    let verdict = if lower > 0.0 {
        crate::classify::PairedVerdict::Supported
    } else if upper < 0.0 {
        crate::classify::PairedVerdict::Contradicted
    } else {
        crate::classify::PairedVerdict::NotShown
    };
    crate::experiments::Comparison {
        first: "a".into(),
        second: "b".into(),
        difference: d,
        lower,
        upper,
        verdict,
        recordings: 69,
    }
}
