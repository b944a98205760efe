//! The simulated rig's physics and determinism.

use neurotex::recording::Phase;
use neurotex::sim::{
    design, simulate_trial, simulate_trial_traced, RigParams, Texture, Trial, ALL_TEXTURES,
};

fn trial(texture: Texture, speed: f64, n: u32) -> Trial {
    Trial {
        texture,
        speed_mm_s: speed,
        trial: n,
    }
}

/// A shorter protocol so debug-profile tests stay quick: 1 s hold, 30 mm slide.
fn short_rig() -> RigParams {
    RigParams {
        hold_s: 1.0,
        slide_mm: 30.0,
        ..RigParams::default()
    }
}

#[test]
fn force_is_held_at_the_commanded_value_during_hold_and_slide() {
    let p = short_rig();
    for texture in ALL_TEXTURES {
        let (rec, forces) = simulate_trial_traced(&p, &trial(texture, 10.0, 3), 1).unwrap();
        let phases = rec.phases.as_ref().unwrap();
        for (&(commanded, actual), phase) in forces.iter().zip(phases) {
            if matches!(phase, Phase::Hold | Phase::Slide) {
                // the trial's force jitter is 3 % (one sigma); the contact solution is exact
                assert!(
                    (commanded - 1.0).abs() < 0.15,
                    "{texture:?}: commanded {commanded}"
                );
                assert!(
                    (actual - commanded).abs() < 1e-9 * commanded.max(1.0),
                    "{texture:?}: {actual} vs {commanded}"
                );
            }
        }
    }
}

/// The read-out noise as documented on `RigParams::noise`: during the hold the pad is still
/// and every taxel's response has settled, so each taxel's counts are its level plus
/// independent Gaussian noise of standard deviation `noise * sqrt(y)` (in full-scale units)
/// and the ADC's rounding (variance 1/12 count²). Checked on the moments of 4.5 s of hold at
/// 1 kHz for every taxel (sampling error of the standard deviation about 1 %), the
/// independence of successive steps and of neighbouring taxels, with the ADC's rounding
/// taken out by dithering theory only (no simulator code reused).
#[test]
fn hold_noise_is_independent_gaussian_with_the_documented_spread() {
    let p = RigParams {
        force_jitter: 0.0,
        ..RigParams::default()
    };
    let full_scale = ((1u64 << p.adc_bits) - 1) as f64;
    for (n, texture) in [Texture::Rt, Texture::Sb, Texture::Cp]
        .into_iter()
        .enumerate()
    {
        let rec = simulate_trial(&p, &trial(texture, 10.0, n as u32), 5).unwrap();
        let phases = rec.phases.as_ref().unwrap();
        let cells = rec.layout.cells();
        let hold: Vec<usize> = (0..phases.len())
            .filter(|&i| phases[i] == Phase::Hold)
            .collect();
        // The first 0.5 s of the hold lets the 8 ms lag settle (60 time constants).
        let steady = &hold[500..];
        let m = steady.len() as f64;
        let mut centred: Vec<Vec<f64>> = Vec::new();
        for c in 0..cells {
            let x: Vec<f64> = steady.iter().map(|&i| rec.samples[i * cells + c]).collect();
            let mean = x.iter().sum::<f64>() / m;
            let dev: Vec<f64> = x.iter().map(|v| v - mean).collect();
            let var = dev.iter().map(|d| d * d).sum::<f64>() / (m - 1.0);
            let y = mean / full_scale;
            if y < 0.05 {
                continue; // too little load for a noise well above the ADC's step
            }
            let expected = (p.noise * y.sqrt() * full_scale).powi(2) + 1.0 / 12.0;
            let ratio = (var / expected).sqrt();
            assert!(
                (ratio - 1.0).abs() < 0.06,
                "{texture:?} taxel {c}: sd {:.3} counts, expected {:.3}",
                var.sqrt(),
                expected.sqrt()
            );
            // Gaussian shape: skewness 0 and kurtosis 3, each within about five of its
            // sampling errors (sqrt(6/m) and sqrt(24/m)).
            let sd = var.sqrt();
            let skew = dev.iter().map(|d| (d / sd).powi(3)).sum::<f64>() / m;
            let kurt = dev.iter().map(|d| (d / sd).powi(4)).sum::<f64>() / m;
            assert!(
                skew.abs() < 5.0 * (6.0 / m).sqrt(),
                "{texture:?} {c}: skew {skew}"
            );
            assert!(
                (kurt - 3.0).abs() < 5.0 * (24.0 / m).sqrt(),
                "{texture:?} {c}: kurtosis {kurt}"
            );
            // Successive steps independent: the lag-1 autocorrelation within noise
            // (sampling error 1/sqrt(m)).
            let lag1 = dev.windows(2).map(|w| w[0] * w[1]).sum::<f64>() / (m - 1.0) / var;
            assert!(lag1.abs() < 5.0 / m.sqrt(), "{texture:?} {c}: lag-1 {lag1}");
            centred.push(dev.iter().map(|d| d / sd).collect());
        }
        assert!(
            centred.len() >= cells / 2,
            "{texture:?}: most taxels loaded"
        );
        // Different taxels draw different noise.
        for pair in centred.windows(2) {
            let r = pair[0]
                .iter()
                .zip(&pair[1])
                .map(|(a, b)| a * b)
                .sum::<f64>()
                / m;
            assert!(
                r.abs() < 5.0 / m.sqrt(),
                "{texture:?}: taxels correlate {r}"
            );
        }
    }
}

#[test]
fn no_signal_before_contact_or_after_lift_off() {
    let p = short_rig();
    let rec = simulate_trial(&p, &trial(Texture::Rt, 15.0, 0), 0).unwrap();
    let phases = rec.phases.as_ref().unwrap();
    let cells = rec.layout.cells();
    let first_contact = phases.iter().position(|&ph| ph == Phase::Contact).unwrap();
    assert!(first_contact > 0);
    assert!(
        rec.samples[..first_contact * cells]
            .iter()
            .all(|&v| v == 0.0),
        "signal before contact"
    );
    // the response lag (8 ms) has died out 100 ms after lift-off
    let tail = &rec.samples[rec.samples.len() - 100 * cells..];
    assert!(tail.iter().all(|&v| v == 0.0), "signal after lift-off");
    let slide: Vec<f64> = rec
        .samples
        .chunks(cells)
        .zip(phases)
        .filter(|(_, &ph)| ph == Phase::Slide)
        .flat_map(|(f, _)| f.to_vec())
        .collect();
    assert!(
        slide.iter().filter(|&&v| v > 0.0).count() > slide.len() / 2,
        "the taxels are loaded while sliding"
    );
}

#[test]
fn phases_follow_the_protocol_and_the_manifest_interval() {
    let p = short_rig();
    let rec = simulate_trial(&p, &trial(Texture::Cp, 10.0, 0), 0).unwrap();
    let phases = rec.phases.as_ref().unwrap();
    let order: Vec<Phase> = phases.iter().fold(Vec::new(), |mut acc, &ph| {
        if acc.last() != Some(&ph) {
            acc.push(ph);
        }
        acc
    });
    assert_eq!(
        order,
        vec![
            Phase::Free,
            Phase::Contact,
            Phase::Hold,
            Phase::Slide,
            Phase::Retract,
            Phase::Free
        ]
    );
    let slide_steps = phases.iter().filter(|&&ph| ph == Phase::Slide).count() as f64;
    // 30 mm at 10 mm/s with 2 % speed jitter
    assert!((slide_steps - 3000.0).abs() < 300.0, "{slide_steps}");
    let start = phases.iter().position(|&ph| ph == Phase::Slide).unwrap() as f64 / 1000.0;
    assert!((rec.meta.slide_start_s.unwrap() - start).abs() < 1e-9);
    assert!((rec.meta.slide_end_s.unwrap() - start - slide_steps / 1000.0).abs() < 1e-9);
}

#[test]
fn a_surface_feature_reaches_the_next_row_after_pitch_over_speed() {
    // Styrofoam's beads are random, so the cross-correlation of two rows has one peak: row
    // r + 1 trails row r by pitch / speed = 3.667 mm / 5 mm/s = 733 ms. Rotation, speed
    // jitter and noise are turned off to isolate the kinematics; lags near 0 (the common
    // mode of force control, which moves every taxel at once) are not searched.
    let p = RigParams {
        noise: 0.0,
        rotation_deg: 0.0,
        speed_jitter: 0.0,
        ..short_rig()
    };
    let speed = 5.0;
    let rec = simulate_trial(&p, &trial(Texture::Stf, speed, 2), 5).unwrap();
    let phases = rec.phases.as_ref().unwrap();
    let cells = rec.layout.cells();
    let series = |cell: usize| -> Vec<f64> {
        rec.samples
            .chunks(cells)
            .zip(phases)
            .filter(|(_, &ph)| ph == Phase::Slide)
            .map(|(f, _)| f[cell])
            .collect()
    };
    let expected = (p.pitch_mm() / speed * 1000.0).round() as i64;
    let mut lags = Vec::new();
    for col in 0..4 {
        let (lead, trail) = (series(col), series(4 + col));
        let mean = |x: &[f64]| x.iter().sum::<f64>() / x.len() as f64;
        let (ml, mt) = (mean(&lead), mean(&trail));
        let best = (300..1500i64)
            .max_by(|&a, &b| {
                let corr = |lag: i64| -> f64 {
                    let n = lead.len() as i64 - lag;
                    (0..n)
                        .map(|t| (lead[t as usize] - ml) * (trail[(t + lag) as usize] - mt))
                        .sum::<f64>()
                        / n as f64
                };
                corr(a).total_cmp(&corr(b))
            })
            .unwrap();
        lags.push(best);
    }
    // within 30 ms, 0.15 mm of travel: finer than the 0.2 mm spacing of the height profiles
    for lag in &lags {
        assert!(
            (lag - expected).abs() <= 30,
            "lags {lags:?}, expected {expected} ms"
        );
    }
}

#[test]
fn same_seed_same_bits_and_trials_differ() {
    let p = short_rig();
    let t = trial(Texture::Sb, 15.0, 4);
    let a = simulate_trial(&p, &t, 9).unwrap();
    let b = simulate_trial(&p, &t, 9).unwrap();
    assert_eq!(a.samples, b.samples);
    let other_trial = simulate_trial(&p, &trial(Texture::Sb, 15.0, 5), 9).unwrap();
    let other_seed = simulate_trial(&p, &t, 10).unwrap();
    assert_ne!(a.samples, other_trial.samples);
    assert_ne!(a.samples, other_seed.samples);
}

#[test]
fn dataset_bits_do_not_depend_on_thread_count() {
    let p = RigParams {
        hold_s: 0.5,
        slide_mm: 10.0,
        ..RigParams::default()
    };
    let trials = design(&[Texture::Ft2, Texture::Stf], &[10.0, 15.0], 2);
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let out = dir.path().join(name);
        pool.install(|| neurotex::sim::write_dataset(&out, &p, &trials, 3, &|| {}))
            .unwrap();
        out
    };
    let (one, two) = (write("one", 1), write("two", 2));
    for entry in std::fs::read_dir(&one).unwrap() {
        let name = entry.unwrap().file_name();
        assert_eq!(
            std::fs::read(one.join(&name)).unwrap(),
            std::fs::read(two.join(&name)).unwrap(),
            "{name:?}"
        );
    }
    assert_eq!(std::fs::read_dir(&one).unwrap().count(), 9);
}

#[test]
fn every_texture_has_relief_and_the_rig_rejects_unphysical_parameters() {
    for texture in ALL_TEXTURES {
        let heights: Vec<f64> = (0..400)
            .map(|i| texture.height(i as f64 * 0.25, (i % 17) as f64 * 0.7, 1))
            .collect();
        let (lo, hi) = heights
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &x| {
                (l.min(x), h.max(x))
            });
        assert!(heights.iter().all(|h| h.is_finite()));
        assert!(hi - lo > 0.1, "{texture:?} relief {lo}..{hi} mm");
        assert_eq!(Texture::from_name(texture.name()), Some(texture));
    }
    assert!(RigParams {
        force_n: 0.0,
        ..RigParams::default()
    }
    .check()
    .is_err());
    assert!(RigParams {
        taxel_mm: 5.0,
        ..RigParams::default()
    }
    .check()
    .is_err());
    assert!(simulate_trial(&RigParams::default(), &trial(Texture::Cp, 0.0, 0), 0).is_err());
}

/// FNV-1a over the bits of every sample, phase and traced force: a change of any bit of the
/// simulator's output changes the digest.
fn digest(rec: &neurotex::recording::Recording, forces: &[(f64, f64)]) -> u64 {
    let mut h: u64 = 0xCBF2_9CE4_8422_2325;
    let mut eat = |word: u64| {
        for byte in word.to_le_bytes() {
            h = (h ^ u64::from(byte)).wrapping_mul(0x0000_0100_0000_01B3);
        }
    };
    rec.samples.iter().for_each(|v| eat(v.to_bits()));
    let phases = rec.phases.as_ref().unwrap();
    phases.iter().for_each(|&ph| eat(ph as u64));
    for &(commanded, actual) in forces {
        eat(commanded.to_bits());
        eat(actual.to_bits());
    }
    h
}

/// The full paper protocol for every texture at 5, 10 and 15 mm/s, bit for bit as stored:
/// digests of the simulator's output, so a rewrite that moves any sample, phase or force by
/// one bit fails here. A change to the output must update them on purpose and say why.
/// Last taken when the sensor noise moved to its own xoshiro256++ generator with one draw
/// per taxel and step, and the contact solve's sum was split four ways (for speed; the
/// physics and the noise's distribution are unchanged, the draws are new).
#[test]
fn full_protocol_bits_match_the_stored_digests() {
    const STORED: [(&str, [u64; 3]); 8] = [
        (
            "FT1",
            [0x2a8ef0246eb8417a, 0xedaa507fc227313b, 0xddde4747b4b4c1f7],
        ),
        (
            "FT2",
            [0x32d8ffd9ce450625, 0x6dfe79825a4fe5b3, 0x6c350c1bd6dd442],
        ),
        (
            "FT3",
            [0x8019e2a7d18726e4, 0x4bb8310348a02bb4, 0xf43023f9247544df],
        ),
        (
            "RT",
            [0x2880dee5ecdf48c, 0xce062c23183dbbb4, 0x27dc06df39931c7e],
        ),
        (
            "TRug",
            [0xac1aedf4ea32f599, 0xbd6396713a3847ca, 0xe7ba627c5baf862d],
        ),
        (
            "SB",
            [0x37ab6dc41c821d9b, 0x2c381e53bb4c6a81, 0xe16ca1e0821ac0a4],
        ),
        (
            "CP",
            [0xd1abd84d0b8a2fd, 0x518cdbfae57388b, 0xd77b70ac17933949],
        ),
        (
            "STF",
            [0x4f08387ae0ff32cf, 0x84232147e1f4b737, 0x84ef03b71efac6f6],
        ),
    ];
    let p = RigParams::default();
    let mut got = Vec::new();
    for (name, _) in STORED {
        let texture = Texture::from_name(name).unwrap();
        let row: Vec<u64> = [5.0, 10.0, 15.0]
            .iter()
            .enumerate()
            .map(|(k, &speed)| {
                let (rec, forces) =
                    simulate_trial_traced(&p, &trial(texture, speed, 3 + k as u32), 11).unwrap();
                assert_eq!(
                    simulate_trial(&p, &trial(texture, speed, 3 + k as u32), 11)
                        .unwrap()
                        .samples,
                    rec.samples
                );
                digest(&rec, &forces)
            })
            .collect();
        got.push((name, row));
    }
    let printed: Vec<String> = got
        .iter()
        .map(|(name, row)| {
            format!(
                "(\"{name}\", [{:#x}, {:#x}, {:#x}]),",
                row[0], row[1], row[2]
            )
        })
        .collect();
    for ((name, stored), (_, row)) in STORED.iter().zip(&got) {
        assert_eq!(
            &stored[..],
            &row[..],
            "{name} moved; now:\n{}",
            printed.join("\n")
        );
    }
}
