//! Fast code against slow, evidently correct versions written from the definitions,
//! on random inputs (proptest).

use neurotex::classify::{Classifier, KnnParams, Predict};
use neurotex::encode::{encode, encode_banks, Encoder, IzhikevichParams, Overshoot, SpikeTrains};
use neurotex::features::glcm::GlcmKind;
use neurotex::features::{
    haralick, quantise, spike_stats, CountVolume, Counting, GlcmParams, GlcmPlan, RateVolume,
    DIRECTIONS_13,
};
use proptest::prelude::*;

use crate::support;
use support::{few_levels_volume, spike_train, uniform_volume, Volume, XorShift};

/// Loop-built GLCM: every voxel, every direction times every distance, bounds and mask checked.
#[allow(clippy::too_many_arguments)]
fn slow_glcm(
    q: &[u8],
    rows: usize,
    cols: usize,
    bins: usize,
    present: &[bool],
    levels: usize,
    distances: &[usize],
    dirs: &[(i32, i32, i32)],
    symmetric: bool,
) -> Vec<u32> {
    let mut m = vec![0u32; levels * levels];
    let at =
        |r: i64, c: i64, t: i64| q[((r * cols as i64 + c) * bins as i64 + t) as usize] as usize;
    for &d in distances {
        for &(dr, dc, dt) in dirs {
            let (dr, dc, dt) = (
                dr as i64 * d as i64,
                dc as i64 * d as i64,
                dt as i64 * d as i64,
            );
            for r in 0..rows as i64 {
                for c in 0..cols as i64 {
                    for t in 0..bins as i64 {
                        let (r2, c2, t2) = (r + dr, c + dc, t + dt);
                        if r2 < 0
                            || c2 < 0
                            || t2 < 0
                            || r2 >= rows as i64
                            || c2 >= cols as i64
                            || t2 >= bins as i64
                        {
                            continue;
                        }
                        if !present[(r * cols as i64 + c) as usize]
                            || !present[(r2 * cols as i64 + c2) as usize]
                        {
                            continue;
                        }
                        let (i, j) = (at(r, c, t), at(r2, c2, t2));
                        m[i * levels + j] += 1;
                        if symmetric {
                            m[j * levels + i] += 1;
                        }
                    }
                }
            }
        }
    }
    m
}

/// The encoder one neuron at a time, straight from the scheme.
fn slow_encoder(input: &[f64], n: usize, p: IzhikevichParams) -> Vec<Vec<u32>> {
    (0..n)
        .map(|k| {
            let (mut v, mut u) = (p.c, p.b * p.c);
            let mut spikes = Vec::new();
            for (t, frame) in input.chunks_exact(n).enumerate() {
                let i = p.gain * frame[k];
                if v >= 30.0 {
                    spikes.push(t as u32);
                    v = p.c;
                    u += p.d;
                }
                v += 0.5 * (0.04 * (v * v) + 5.0 * v + 140.0 - u + i);
                v += 0.5 * (0.04 * (v * v) + 5.0 * v + 140.0 - u + i);
                let seen = match p.overshoot {
                    Overshoot::Kept => v,
                    Overshoot::Capped => v.min(30.0),
                };
                u += p.a * (p.b * seen - u);
            }
            spikes
        })
        .collect()
}

/// Haralick's features in two floating-point passes over the normalised matrix, straight
/// from eqs. 5-8 (means and deviations of the marginals first, then the covariance).
fn slow_haralick(counts: &[u32], levels: usize) -> [f64; 3] {
    let total: f64 = counts.iter().map(|&c| c as f64).sum();
    if total == 0.0 {
        return [0.0, 1.0, 0.0];
    }
    let p = |i: usize, j: usize| counts[i * levels + j] as f64 / total;
    let (mut contrast, mut asm, mut mu_x, mut mu_y) = (0.0, 0.0, 0.0, 0.0);
    for i in 0..levels {
        for j in 0..levels {
            contrast += p(i, j) * (i as f64 - j as f64).powi(2);
            asm += p(i, j) * p(i, j);
            mu_x += i as f64 * p(i, j);
            mu_y += j as f64 * p(i, j);
        }
    }
    let (mut var_x, mut var_y, mut cov) = (0.0, 0.0, 0.0);
    for i in 0..levels {
        for j in 0..levels {
            var_x += p(i, j) * (i as f64 - mu_x).powi(2);
            var_y += p(i, j) * (j as f64 - mu_y).powi(2);
            cov += p(i, j) * (i as f64 - mu_x) * (j as f64 - mu_y);
        }
    }
    let (sd_x, sd_y) = (var_x.sqrt(), var_y.sqrt());
    let correlation = if sd_x < 1e-15 || sd_y < 1e-15 {
        1.0
    } else {
        cov / (sd_x * sd_y)
    };
    [contrast, correlation, asm]
}

/// KNN by sorting every distance (stable, so earlier training samples win distance ties).
fn slow_knn(
    train: &[f64],
    y: &[usize],
    test: &[f64],
    dims: usize,
    k: usize,
    standardize: bool,
) -> Vec<usize> {
    let n = y.len();
    let (mut mean, mut sd) = (vec![0.0; dims], vec![1.0; dims]);
    if standardize {
        for j in 0..dims {
            let col: Vec<f64> = (0..n).map(|i| train[i * dims + j]).collect();
            mean[j] = col.iter().sum::<f64>() / n as f64;
            let var = col.iter().map(|x| (x - mean[j]).powi(2)).sum::<f64>() / n as f64;
            sd[j] = if var.sqrt() > 0.0 { var.sqrt() } else { 1.0 };
        }
    }
    let scale = |row: &[f64]| -> Vec<f64> {
        row.iter()
            .enumerate()
            .map(|(j, &x)| (x - mean[j]) * (1.0 / sd[j]))
            .collect()
    };
    let classes = y.iter().max().unwrap() + 1;
    test.chunks_exact(dims)
        .map(|row| {
            let s = scale(row);
            let mut dist: Vec<(f64, usize)> = train
                .chunks_exact(dims)
                .enumerate()
                .map(|(i, t)| {
                    (
                        scale(t)
                            .iter()
                            .zip(&s)
                            .map(|(a, b)| (a - b) * (a - b))
                            .sum(),
                        i,
                    )
                })
                .collect();
            dist.sort_by(|a, b| a.0.partial_cmp(&b.0).unwrap());
            let near = &dist[..k];
            let mut votes = vec![0; classes];
            for &(_, i) in near {
                votes[y[i]] += 1;
            }
            let top = *votes.iter().max().unwrap();
            near.iter()
                .map(|&(_, i)| y[i])
                .find(|&c| votes[c] == top)
                .unwrap()
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn glcm_plan_matches_loop_built_glcm(
        Volume { rows, cols, bins, levels, present, q } in uniform_volume(),
        distances in proptest::sample::subsequence(vec![1usize, 2, 3, 4, 8], 1..5),
        symmetric in any::<bool>(),
        two_d in any::<bool>(),
    ) {
        let params = GlcmParams { distances: distances.clone(), symmetric };
        let (kind, dirs) = if two_d { (GlcmKind::TwoD, &DIRECTIONS_13[..4]) } else { (GlcmKind::ThreeD, &DIRECTIONS_13[..]) };
        let plan = GlcmPlan::new(rows, cols, &present, levels, &params, kind).unwrap();
        // masked cells carry arbitrary levels here: they must never be counted
        let mut fast = vec![0u32; levels * levels];
        plan.count(&q, bins, &mut fast);
        let slow = slow_glcm(&q, rows, cols, bins, &present, levels, &distances, dirs, symmetric);
        prop_assert_eq!(&fast, &slow);
        for counting in [Counting::Histogram, Counting::LevelMasks, Counting::OneHot] {
            plan.count_with(&q, bins, &mut fast, counting);
            prop_assert_eq!(&fast, &slow, "{:?}", counting);
        }
    }

    #[test]
    fn every_counting_method_matches_loop_built_glcm_on_few_level_volumes(
        Volume { rows, cols, bins, levels, present, q } in few_levels_volume(),
        distances in proptest::sample::subsequence(vec![1usize, 2, 3, 4, 8, 130], 1..5),
        symmetric in any::<bool>(),
    ) {
        let params = GlcmParams { distances: distances.clone(), symmetric };
        let plan = GlcmPlan::new(rows, cols, &present, levels, &params, GlcmKind::ThreeD).unwrap();
        let slow = slow_glcm(&q, rows, cols, bins, &present, levels, &distances, &DIRECTIONS_13, symmetric);
        let mut fast = vec![0u32; levels * levels];
        for counting in [Counting::Auto, Counting::Histogram, Counting::LevelMasks, Counting::OneHot] {
            plan.count_with(&q, bins, &mut fast, counting);
            prop_assert_eq!(&fast, &slow, "{:?}", counting);
        }
    }

    #[test]
    fn haralick_matches_two_pass_definitions(
        levels in 2usize..20,
        seed in any::<u64>(),
        zeros in 0.0f64..1.0,
        scale in prop_oneof![Just(3u64), Just(1000), Just(u32::MAX as u64)],
    ) {
        let mut rng = XorShift::new(seed);
        let counts: Vec<u32> = (0..levels * levels).map(|_| {
            let x = rng.next_u64();
            if (x % 1000) as f64 / 1000.0 < zeros { 0 } else { ((x >> 20) % scale) as u32 }
        }).collect();
        let fast = haralick(&counts, levels).to_array();
        let slow = slow_haralick(&counts, levels);
        for (f, s) in fast.iter().zip(&slow) {
            prop_assert!((f - s).abs() <= 1e-9 * s.abs().max(1e-3), "{:?} vs {:?}", fast, slow);
        }
    }

    #[test]
    fn encoder_matches_step_by_step_and_chunks_do_not_matter(
        // blocks of 32, 16 and 8 neurons and a rest (AVX-512), of 16 and a rest (AVX2)
        n in 1usize..80,
        steps in 1usize..600,
        seed in any::<u64>(),
        gain in 1.0f64..25.0,
        split in 0.0f64..1.0,
        capped in any::<bool>(),
    ) {
        let mut rng = XorShift::new(seed);
        let input: Vec<f64> = (0..n * steps).map(|_| rng.fraction(10_000)).collect();
        let overshoot = if capped { Overshoot::Capped } else { Overshoot::Kept };
        let p = IzhikevichParams::default().with_gain(gain).with_overshoot(overshoot);
        let mut whole = vec![0u8; input.len()];
        Encoder::new(p, n).unwrap().run(&input, &mut whole);
        let cut = ((steps as f64 * split) as usize) * n;
        let mut chunked = vec![0u8; input.len()];
        let mut enc = Encoder::new(p, n).unwrap();
        enc.run(&input[..cut], &mut chunked[..cut]);
        enc.run(&input[cut..], &mut chunked[cut..]);
        prop_assert_eq!(&whole, &chunked);
        let trains = SpikeTrains::from_raster(&whole, 1, n, &vec![true; n]);
        let slow = slow_encoder(&input, n, p);
        for (k, expected) in slow.iter().enumerate() {
            prop_assert_eq!(trains.train(k), expected.as_slice());
        }
    }

    #[test]
    fn banks_side_by_side_give_each_signals_own_trains(
        rows in 1usize..5,
        cols in 1usize..9,
        banks in 1usize..5,
        // past one 1024-step block, and a part block
        steps in 1usize..1500,
        seed in any::<u64>(),
    ) {
        let mut rng = XorShift::new(seed);
        let cells = rows * cols;
        let present: Vec<bool> = (0..cells).map(|c| c == 0 || rng.below(4) > 0).collect();
        let signals: Vec<Vec<f64>> = (0..banks)
            .map(|_| (0..cells * steps).map(|_| rng.fraction(10_000)).collect())
            .collect();
        let gains: Vec<f64> = (0..banks).map(|_| 1.0 + rng.fraction(10_000) * 30.0).collect();
        let p = IzhikevichParams::default();
        let views: Vec<&[f64]> = signals.iter().map(|s| s.as_slice()).collect();
        let together = encode_banks(&views, &gains, rows, cols, &present, p).unwrap();
        prop_assert_eq!(together.len(), banks);
        for ((signal, &gain), trains) in signals.iter().zip(&gains).zip(&together) {
            let alone = encode(signal, rows, cols, &present, p.with_gain(gain)).unwrap();
            prop_assert_eq!(trains, &alone);
        }
    }

    #[test]
    fn knn_matches_sorted_brute_force(
        // several blocks of distances past the seeds, and k past the selection search's 16
        n in 5usize..160,
        dims in 1usize..5,
        k in 1usize..20,
        classes in 2usize..5,
        seed in any::<u64>(),
        standardize in any::<bool>(),
    ) {
        let mut rng = XorShift::new(seed);
        // coarse values so distance and vote ties happen often
        let train: Vec<f64> = (0..n * dims).map(|_| rng.below(5) as f64).collect();
        let y: Vec<usize> = (0..n).map(|i| if i < classes { i } else { rng.below(classes as u64) as usize }).collect();
        let test: Vec<f64> = (0..10 * dims).map(|_| rng.below(5) as f64).collect();
        let knn = KnnParams { k: k.min(n), standardize }.check().unwrap();
        let model = knn.fit(&train, dims, &y).unwrap();
        prop_assert_eq!(model.predict(&test), slow_knn(&train, &y, &test, dims, k.min(n), standardize));
    }

    #[test]
    fn spike_stats_match_their_definitions(
        mut train in spike_train(3000, 0..80),
        n_steps in 1usize..3000,
        window in 1usize..500,
    ) {
        train.retain(|&t| (t as usize) < n_steps);
        let s = spike_stats(&train, n_steps, window);
        let msr = train.len() as f64 / (n_steps as f64 / 1000.0);
        prop_assert!((s.msr - msr).abs() <= 1e-9 * msr.max(1.0));
        let isi: Vec<f64> = train.windows(2).map(|w| (w[1] - w[0]) as f64).collect();
        let cv = if isi.len() < 2 { 0.0 } else {
            let m = isi.iter().sum::<f64>() / isi.len() as f64;
            (isi.iter().map(|x| (x - m).powi(2)).sum::<f64>() / isi.len() as f64).sqrt() / m
        };
        prop_assert!((s.cv_isi - cv).abs() <= 1e-9);
        let w = n_steps / window;
        let counts: Vec<f64> = (0..w).map(|k| train.iter().filter(|&&t| t as usize / window == k).count() as f64).collect();
        let fano = if w == 0 { 0.0 } else {
            let m = counts.iter().sum::<f64>() / w as f64;
            if m == 0.0 { 0.0 } else { counts.iter().map(|c| (c - m).powi(2)).sum::<f64>() / w as f64 / m }
        };
        prop_assert!((s.fano - fano).abs() <= 1e-9 * fano.max(1.0));
        prop_assert!(s.msr.is_finite() && s.cv_isi.is_finite() && s.fano.is_finite());
    }

    #[test]
    fn rate_volume_and_quantisation_match_definitions(
        lists in proptest::collection::vec(spike_train(2000, 0..60), 6),
        n_steps in 200usize..2000,
        bin in prop_oneof![1usize..4, 50usize..400, 2000usize..2100],
        levels in 2usize..32,
    ) {
        let lists: Vec<Vec<u32>> = lists.into_iter().map(|l| l.into_iter().filter(|&t| (t as usize) < n_steps).collect()).collect();
        let present = vec![true; 6];
        let trains = SpikeTrains::from_lists(&lists, 2, 3, &present, n_steps);
        let Some(vol) = RateVolume::from_spikes(&trains, bin) else {
            prop_assert!(n_steps < bin);
            return Ok(());
        };
        prop_assert_eq!(vol.bins, n_steps / bin);
        for (cell, l) in lists.iter().enumerate() {
            for b in 0..vol.bins {
                let count = l.iter().filter(|&&t| t as usize / bin == b).count() as f64;
                prop_assert!((vol.data[cell * vol.bins + b] - count * 1000.0 / bin as f64).abs() < 1e-9);
            }
        }
        let mut q = Vec::new();
        quantise(&vol, levels, None, &mut q);
        // The count volume holds the same rates; its levels are the formula's in fractions
        // of the counts. The f64 rates' levels agree except on a boundary, where rounding
        // may have put the rate just below it.
        let counted = CountVolume::from_spikes(&trains, bin).unwrap();
        prop_assert_eq!(&counted.rates(), &vol);
        let mut from_counts = Vec::new();
        counted.quantise(levels, None, &mut from_counts);
        let (min, max) = (counted.counts.iter().min().unwrap(), counted.counts.iter().max().unwrap());
        let (lo, hi) = (rate_frac(*min, bin), rate_frac(*max, bin));
        for ((&c, &exact), &float) in counted.counts.iter().zip(&from_counts).zip(&q) {
            let v = level_value(rate_frac(c, bin), lo, hi, levels);
            prop_assert_eq!(exact, level_by_definition(rate_frac(c, bin), lo, hi, levels));
            let on_boundary = v.is_some_and(|v| v.1 == 1 && v.0 >= 1 && v.0 < levels as i128);
            prop_assert!(float == exact || (on_boundary && float + 1 == exact), "count {c}: {float} vs {exact}");
        }
        let range = Some((5.0, 5.0 + 37.5 * levels as f64));
        counted.quantise(levels, range, &mut from_counts);
        let (lo, hi) = (Frac::new(5, 1), Frac::new(10 + 75 * levels as i128, 2));
        for (&c, &exact) in counted.counts.iter().zip(&from_counts) {
            prop_assert_eq!(exact, level_by_definition(rate_frac(c, bin), lo, hi, levels));
        }
    }

    /// Count volumes from spike trains, 3D (bins of `bin` ms) and 2D (one bin spanning the
    /// train), against the quantisation's formula in fractions, over counts on level
    /// boundaries (the span of the counts a multiple of L) and anywhere.
    #[test]
    fn count_volume_levels_are_the_formula_in_fractions(
        bin in prop_oneof![Just(201usize), Just(300), Just(7 * 31), 110usize..400],
        bins in 1usize..6,
        levels in 2usize..=32,
        min in 0u32..10,
        step in 1u32..=3,
        on_boundaries in any::<bool>(),
        picks in proptest::collection::vec(any::<u32>(), 30),
        masked in proptest::option::of(0usize..6),
        fixed in proptest::option::of((-80i32..400, 1i32..8000)),
    ) {
        let present: Vec<bool> = (0..6).map(|cell| Some(cell) != masked).collect();
        let span = if on_boundaries { step * levels as u32 } else { picks[0] % (bin as u32 - min) };
        let counts: Vec<u32> = picks.iter().take(6 * bins).map(|&p| min + p % (span + 1)).collect();
        // Trains with those counts per cell and bin, bins of `bin` ms.
        let lists: Vec<Vec<u32>> = counts
            .chunks_exact(bins)
            .map(|cell| {
                cell.iter()
                    .enumerate()
                    .flat_map(|(b, &c)| (0..c).map(move |j| (b * bin) as u32 + j))
                    .collect()
            })
            .collect();
        let trains = SpikeTrains::from_lists(&lists, 2, 3, &present, bins * bin);
        let three_d = CountVolume::from_spikes(&trains, bin).unwrap();
        prop_assert_eq!(&three_d.counts, &counts);
        let two_d = CountVolume::collapsed(&trains).unwrap();
        let range = fixed.map(|(lo8, width8)| (f64::from(lo8) / 8.0, f64::from(lo8 + width8) / 8.0));
        for volume in [&three_d, &two_d] {
            let mut q = Vec::new();
            volume.quantise(levels, range, &mut q);
            let held: Vec<u32> = volume.counts.chunks_exact(volume.bins).zip(&present).filter(|(_, &p)| p).flat_map(|(c, _)| c.iter().copied()).collect();
            let (lo, hi) = match fixed {
                Some((lo8, width8)) => (Frac::new(lo8.into(), 8), Frac::new((lo8 + width8).into(), 8)),
                None => (
                    rate_frac(*held.iter().min().unwrap(), volume.bin_ms),
                    rate_frac(*held.iter().max().unwrap(), volume.bin_ms),
                ),
            };
            for (cell, (levels_of_cell, counts_of_cell)) in q.chunks_exact(volume.bins).zip(volume.counts.chunks_exact(volume.bins)).enumerate() {
                for (&level, &c) in levels_of_cell.iter().zip(counts_of_cell) {
                    let expected = if present[cell] { level_by_definition(rate_frac(c, volume.bin_ms), lo, hi, levels) } else { 0 };
                    prop_assert_eq!(level, expected, "cell {} count {} ({} bins)", cell, c, volume.bins);
                }
            }
        }
    }

    /// Rates given as f64 (eighths of a Hz, exact in binary) quantise to the formula's
    /// levels in fractions, rates on boundaries included, over their own range and a fixed one.
    #[test]
    fn float_rate_levels_are_the_formula_in_fractions(
        levels in 2usize..=64,
        lo8 in -400i64..400,
        step8 in 1i64..40,
        picks in proptest::collection::vec((any::<u32>(), 0i64..3), 1..40),
        fixed in any::<bool>(),
    ) {
        // Eighths lo8 + k * step8 lie on boundary k of lo8..lo8 + L * step8.
        let top8 = lo8 + step8 * levels as i64;
        let mut eighths: Vec<i64> = picks
            .iter()
            .map(|&(p, jitter)| lo8 + step8 * i64::from(p % (levels as u32 + 1)) + if p % 4 == 0 { jitter - 1 } else { 0 })
            .collect();
        eighths.extend([lo8, top8]);
        let data: Vec<f64> = eighths.iter().map(|&e| e as f64 / 8.0).collect();
        let volume = RateVolume { rows: 1, cols: 1, bins: data.len(), present: vec![true], data };
        let (range, lo, hi) = if fixed {
            (Some((lo8 as f64 / 8.0, top8 as f64 / 8.0)), Frac::new(lo8.into(), 8), Frac::new(top8.into(), 8))
        } else {
            let (min, max) = (*eighths.iter().min().unwrap(), *eighths.iter().max().unwrap());
            (None, Frac::new(min.into(), 8), Frac::new(max.into(), 8))
        };
        let mut q = Vec::new();
        quantise(&volume, levels, range, &mut q);
        for (&e, &level) in eighths.iter().zip(&q) {
            prop_assert_eq!(level, level_by_definition(Frac::new(e.into(), 8), lo, hi, levels), "{}/8 Hz", e);
        }
    }
}

/// A fraction `num / den` with `den > 0`, kept in lowest terms: the slow exact arithmetic
/// of the quantisation's levels.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Frac(i128, i128);

impl Frac {
    fn new(num: i128, den: i128) -> Frac {
        let g = gcd(num.unsigned_abs(), den.unsigned_abs()).max(1) as i128;
        let sign = if den < 0 { -1 } else { 1 };
        Frac(sign * num / g, sign * den / g)
    }
    fn sub(self, o: Frac) -> Frac {
        Frac::new(self.0 * o.1 - o.0 * self.1, self.1 * o.1)
    }
    fn div(self, o: Frac) -> Frac {
        Frac::new(self.0 * o.1, self.1 * o.0)
    }
    fn times(self, n: i128) -> Frac {
        Frac::new(self.0 * n, self.1)
    }
}

fn gcd(a: u128, b: u128) -> u128 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// The rate of `count` spikes in `bin_ms`, in Hz.
fn rate_frac(count: u32, bin_ms: usize) -> Frac {
    Frac::new(i128::from(count) * 1000, bin_ms as i128)
}

/// `(x - lo) / (hi - lo) * L`, `None` for `hi <= lo`.
fn level_value(x: Frac, lo: Frac, hi: Frac, levels: usize) -> Option<Frac> {
    let span = hi.sub(lo);
    (span.0 > 0).then(|| x.sub(lo).div(span).times(levels as i128))
}

/// The quantisation's level, `min(L-1, floor((x - lo) / (hi - lo) * L))`, clamped at 0; 0
/// for a constant volume (`hi <= lo`)
/// (docs/decisions/0004-sixteen-gray-levels-over-the-volumes-own-range.md).
fn level_by_definition(x: Frac, lo: Frac, hi: Frac, levels: usize) -> u8 {
    level_value(x, lo, hi, levels).map_or(0, |v| {
        v.0.div_euclid(v.1).clamp(0, levels as i128 - 1) as u8
    })
}

/// Uniform random levels below `levels`.
fn random_levels(n: usize, levels: u8, seed: u64) -> Vec<u8> {
    let mut rng = XorShift::new(seed);
    (0..n).map(|_| rng.below(u64::from(levels)) as u8).collect()
}

#[test]
fn one_hot_counting_handles_more_runs_per_cell_than_a_byte_counts() {
    // 300 distances on a 2x2 grid: about 300 runs start at each cell, and as nearly all
    // voxels share level 0, most steps have more partners of that level than a byte
    // counts, so the runs must be summed in batches.
    let (rows, cols, bins, levels) = (2, 2, 400, 16);
    let distances: Vec<usize> = (1..=300).collect();
    let present = [true; 4];
    let mut q = random_levels(rows * cols * bins, levels as u8, 7);
    for (k, x) in q.iter_mut().enumerate() {
        if k % 50 != 0 {
            *x = 0;
        }
    }
    let params = GlcmParams {
        distances: distances.clone(),
        symmetric: false,
    };
    let plan = GlcmPlan::new(rows, cols, &present, levels, &params, GlcmKind::ThreeD).unwrap();
    let slow = slow_glcm(
        &q,
        rows,
        cols,
        bins,
        &present,
        levels,
        &distances,
        &DIRECTIONS_13,
        false,
    );
    let mut fast = vec![0u32; levels * levels];
    plan.count_with(&q, bins, &mut fast, Counting::OneHot);
    assert_eq!(fast, slow);
}

#[test]
fn one_hot_counting_of_a_long_volume_overflows_no_partial_count() {
    // 20000 bins of 16 cells: each count reaches far beyond the u16 partial counts, which
    // must be moved into the u32 counts in time.
    let (rows, cols, bins, levels) = (4, 4, 20_000, 16);
    let mut q = random_levels(rows * cols * bins, levels as u8, 11);
    // One level dominates, so that a single count grows fastest.
    for x in q.iter_mut().step_by(3) {
        *x = 5;
    }
    let present = [true; 16];
    let params = GlcmParams::default();
    let plan = GlcmPlan::new(rows, cols, &present, levels, &params, GlcmKind::ThreeD).unwrap();
    let slow = slow_glcm(
        &q,
        rows,
        cols,
        bins,
        &present,
        levels,
        &params.distances,
        &DIRECTIONS_13,
        false,
    );
    assert!(slow[5 * levels + 5] > 3 * u32::from(u16::MAX));
    for counting in [Counting::OneHot, Counting::Auto] {
        let mut fast = vec![0u32; levels * levels];
        plan.count_with(&q, bins, &mut fast, counting);
        assert_eq!(fast, slow, "{counting:?}");
    }
}
