//! Cases worked out by hand (the arithmetic is in the comments).

use neurotex::encode::{encode, IzhikevichParams, SpikeTrains};
use neurotex::features::glcm::GlcmKind;
use neurotex::features::{
    haralick, quantise, spike_stats, Counting, GlcmParams, GlcmPlan, RateVolume,
};

/// The paper's 3D plan (13 directions x 1, 2, 4, 8) on a full 4x4 grid, 16 levels.
fn paper_plan_4x4() -> GlcmPlan {
    GlcmPlan::new(
        4,
        4,
        &[true; 16],
        16,
        &GlcmParams::default(),
        GlcmKind::ThreeD,
    )
    .unwrap()
}

fn counts_of(plan: &GlcmPlan, q: &[u8], bins: usize) -> Vec<u32> {
    let l = plan.levels();
    let mut c = vec![0u32; l * l];
    plan.count(q, bins, &mut c);
    c
}

#[test]
fn constant_volume_is_one_gray_level() {
    let trains = SpikeTrains::from_lists(
        &vec![vec![0, 200, 400, 600, 800]; 16],
        4,
        4,
        &[true; 16],
        1000,
    );
    let vol = RateVolume::from_spikes(&trains, 200).unwrap();
    let mut q = Vec::new();
    quantise(&vol, 16, None, &mut q);
    assert!(
        q.iter().all(|&l| l == 0),
        "a constant volume is all level 0"
    );
    let plan = paper_plan_4x4();
    let c = counts_of(&plan, &q, vol.bins);
    let h = haralick(&c, 16);
    assert_eq!((h.contrast, h.correlation, h.asm), (0.0, 1.0, 1.0));
}

#[test]
fn a_volume_without_bins_has_no_pairs() {
    let plan = paper_plan_4x4();
    for counting in [
        Counting::Auto,
        Counting::Histogram,
        Counting::LevelMasks,
        Counting::OneHot,
    ] {
        let mut c = vec![1u32; 256];
        plan.count_with(&[], 0, &mut c, counting);
        assert!(c.iter().all(|&n| n == 0), "{counting:?}");
    }
}

#[test]
fn two_level_checkerboard_2d_glcm() {
    // V[r, c] = (r + c) % 2 on 4x4, D = 1, the paper's four in-plane directions:
    // (0, 1): 12 pairs, all unlike: 6 x (0,1), 6 x (1,0).
    // (-1, 1): first cells r = 1..3, c = 0..2, alike; even cells 1 + 2 + 1 = 4 -> (0,0),
    //          odd 5 -> (1,1).
    // (-1, 0): 12 pairs, unlike: 6 + 6.
    // (-1, -1): first cells r = 1..3, c = 1..3, alike; even 2 + 1 + 2 = 5, odd 4.
    // Total (0,0) 9, (0,1) 12, (1,0) 12, (1,1) 9 of 42.
    let q: Vec<u8> = (0..16).map(|i| ((i / 4 + i % 4) % 2) as u8).collect();
    let params = GlcmParams {
        distances: vec![1],
        symmetric: false,
    };
    let plan = GlcmPlan::new(4, 4, &[true; 16], 2, &params, GlcmKind::TwoD).unwrap();
    let c = counts_of(&plan, &q, 1);
    assert_eq!(c, vec![9, 12, 12, 9]);
    // contrast = 24/42; ASM = (81 + 144 + 144 + 81) / 42^2 = 450/1764;
    // marginals 1/2, 1/2 both ways, mu = 1/2, var = 1/4,
    // cov = 9/42 - 1/4 = -1/28, correlation = (-1/28) / (1/4) = -1/7.
    let h = haralick(&c, 2);
    assert!((h.contrast - 24.0 / 42.0).abs() < 1e-12);
    assert!((h.asm - 450.0 / 1764.0).abs() < 1e-12);
    assert!((h.correlation - (-1.0 / 7.0)).abs() < 1e-12);
}

#[test]
fn four_by_four_pairs_at_d4_and_d8_are_temporal_only() {
    // On a 4x4 grid no spatial step of 4 or 8 stays inside, so only direction 6,
    // (0, 0, -D), has pairs: 16 cells x (T - D) times. With V[r, c, t] = t (T = L = 10):
    // D = 4 gives (t, t - 4) for t = 4..9, 16 each; D = 8 gives (8, 0), (9, 1), 16 each.
    let q: Vec<u8> = (0..16).flat_map(|_| 0..10u8).collect();
    let params = GlcmParams {
        distances: vec![4, 8],
        symmetric: false,
    };
    let plan = GlcmPlan::new(4, 4, &[true; 16], 10, &params, GlcmKind::ThreeD).unwrap();
    let c = counts_of(&plan, &q, 10);
    let mut expected = vec![0u32; 100];
    for t in 4..10 {
        expected[t * 10 + t - 4] += 16;
    }
    for t in 8..10 {
        expected[t * 10 + t - 8] += 16;
    }
    assert_eq!(c, expected);
}

#[test]
fn paper_offsets_on_4x4x90_count_23160_pairs() {
    // Pairs per direction, 4x4 grid, T = 90 (see the table of offsets):
    // D = 1: 1080 + 810 + 1080 + 810 + 1068 + 1424 + 3 x 1068 + 4 x 801 = 12680
    // D = 2:  720 + 360 +  720 + 360 +  704 + 1408 + 3 x  704 + 4 x 352 =  7792
    // D = 4: 16 x 86 = 1376;  D = 8: 16 x 82 = 1312.  Total 23160.
    let plan = paper_plan_4x4();
    let q = vec![3u8; 16 * 90];
    let c = counts_of(&plan, &q, 90);
    assert_eq!(c.iter().sum::<u32>(), 23160);
    assert_eq!(c[3 * 16 + 3], 23160);
}

#[test]
fn masked_cell_is_never_paired() {
    // 1x3 grid, middle cell masked: (0, D) at D = 1 has no pair, at D = 2 one per time step.
    let present = [true, false, true];
    let q = vec![0u8, 0, 1, 1, 1, 1];
    let params = GlcmParams {
        distances: vec![1, 2],
        symmetric: false,
    };
    let plan = GlcmPlan::new(1, 3, &present, 2, &params, GlcmKind::TwoD).unwrap();
    assert_eq!(counts_of(&plan, &q, 2), vec![0, 2, 0, 0]);
}

#[test]
fn spike_statistics_by_hand() {
    // Spikes at 0, 10, 30 ms over 1 s: MSR 3 Hz; ISIs 10, 20: mean 15, population sd 5,
    // CV 1/3; 200 ms counts 3, 0, 0, 0, 0: mean 0.6, variance (5.76 + 4 x 0.36) / 5 = 1.44,
    // Fano 2.4.
    let s = spike_stats(&[0, 10, 30], 1000, 200);
    assert!((s.msr - 3.0).abs() < 1e-12);
    assert!((s.cv_isi - 1.0 / 3.0).abs() < 1e-12);
    assert!((s.fano - 2.4).abs() < 1e-12);
    // Fewer than two intervals: CV 0; no spikes: Fano 0.
    assert_eq!(spike_stats(&[5, 50], 1000, 200).cv_isi, 0.0);
    assert_eq!(spike_stats(&[], 1000, 200).fano, 0.0);
    // A last partial window is dropped: 450 ms -> two windows, spike at 420 ignored.
    let s = spike_stats(&[10, 250, 420], 450, 200);
    assert!((s.fano - 0.0).abs() < 1e-12);
}

#[test]
fn rs_neuron_f_i_curve_is_sane() {
    // Regular spiking: silent at rest, rate rising with current, adapting (later ISIs longer).
    let rate = |i: f64| {
        let t = encode(
            &vec![i; 2000],
            1,
            1,
            &[true],
            IzhikevichParams::default().with_gain(1.0),
        )
        .unwrap();
        t.train(0).len() as f64 / 2.0
    };
    assert_eq!(rate(0.0), 0.0);
    assert_eq!(rate(3.0), 0.0, "below rheobase");
    let rates: Vec<f64> = [5.0, 8.0, 12.0, 20.0, 40.0]
        .iter()
        .map(|&i| rate(i))
        .collect();
    assert!(rates.windows(2).all(|w| w[1] > w[0]), "{rates:?}");
    assert!(
        rates[1] > 2.0 && rates[1] < 30.0,
        "RS at I = 8 fires a few to tens of Hz, got {}",
        rates[1]
    );
    let t = encode(
        &vec![10.0; 1000],
        1,
        1,
        &[true],
        IzhikevichParams::default().with_gain(1.0),
    )
    .unwrap();
    let isi: Vec<u32> = t.train(0).windows(2).map(|w| w[1] - w[0]).collect();
    assert!(
        isi[0] < *isi.last().unwrap(),
        "spike-frequency adaptation: {isi:?}"
    );
}

#[test]
fn a_volume_spanning_all_doubles_keeps_its_levels() {
    // lo = -MAX, hi = MAX, 16 levels: the level of x is floor(8 (1 + x / MAX)), capped at 15.
    // 1e308 / MAX = 0.55627 (MAX = 1.7977e308): x = 1e308 -> floor(12.45) = 12,
    // x = -1e308 -> floor(3.55) = 3, x = 0 -> 8 exactly (a boundary), x = MAX -> 15.
    // `hi - lo` overflows to infinity, so the f64 formula alone would give every cell 0.
    let data = vec![-f64::MAX, -1e308, 0.0, 1e308, f64::MAX];
    let vol = RateVolume {
        rows: 1,
        cols: 1,
        bins: data.len(),
        present: vec![true],
        data,
    };
    let mut q = Vec::new();
    quantise(&vol, 16, None, &mut q);
    assert_eq!(q, vec![0, 3, 8, 12, 15]);
}
