//! The van Rossum distance and the precomputed-distance KNN against slow, evidently correct
//! references (double sums, numerical integration, brute-force neighbours), hand cases and
//! Elephant's values.

use neurotex::classify::{
    cross_validate, cross_validate_on, van_rossum, van_rossum_squared, CvParams, Decide,
    DistanceMatrix, KnnParams, Learner, SpikeDistanceKnn, VanRossumParams,
};
use neurotex::encode::SpikeTrains;
use neurotex::error::ClassifyError;
use proptest::prelude::*;

/// `D² = ½ [Σ_ij e^{-|t_i-t_j|/τ} + Σ_ij e^{-|s_i-s_j|/τ} - 2 Σ_ij e^{-|t_i-s_j|/τ}]`,
/// every pair summed directly; also returns the scale of the sums for a tolerance.
fn double_sum(a: &[u32], b: &[u32], tau: f64) -> (f64, f64) {
    let k = |x: &[u32], y: &[u32]| -> f64 {
        let mut s = 0.0;
        for &p in x {
            for &q in y {
                s += (-(f64::from(p) - f64::from(q)).abs() / tau).exp();
            }
        }
        s
    };
    let (aa, bb, ab) = (k(a, a), k(b, b), k(a, b));
    (0.5 * (aa + bb - 2.0 * ab), aa + bb)
}

/// `(1/τ) ∫ (f - g)² dt` by the midpoint rule on a grid of `dt` ms, the filtered traces
/// evaluated from their definition at every grid point.
fn integrated(a: &[u32], b: &[u32], tau: f64, dt: f64) -> f64 {
    let end = f64::from(*a.iter().chain(b).max().unwrap_or(&0)) + 40.0 * tau;
    let trace = |x: &[u32], t: f64| -> f64 {
        x.iter()
            .map(|&s| f64::from(s))
            .filter(|&s| s <= t)
            .map(|s| (-(t - s) / tau).exp())
            .sum()
    };
    let steps = (end / dt).ceil() as usize;
    (0..steps)
        .map(|i| {
            let t = (i as f64 + 0.5) * dt;
            let d = trace(a, t) - trace(b, t);
            d * d * dt
        })
        .sum::<f64>()
        / tau
}

fn sorted_train(max_spikes: usize, max_time: u32) -> impl Strategy<Value = Vec<u32>> {
    proptest::collection::btree_set(0..max_time, 0..max_spikes)
        .prop_map(|s| s.into_iter().collect())
}

proptest! {
    #[test]
    fn the_linear_recursion_equals_the_double_sum(
        a in sorted_train(60, 3_000),
        b in sorted_train(60, 3_000),
        tau in 0.2f64..400.0,
    ) {
        let fast = van_rossum_squared(&a, &b, tau);
        let (slow, scale) = double_sum(&a, &b, tau);
        prop_assert!(fast >= 0.0);
        prop_assert!((fast - slow).abs() <= 1e-10 * (1.0 + scale), "{fast} vs {slow}");
    }

    #[test]
    fn the_distance_is_symmetric_and_zero_only_on_itself(
        a in sorted_train(40, 2_000),
        b in sorted_train(40, 2_000),
        tau in 0.5f64..300.0,
    ) {
        let ab = van_rossum(&a, &b, tau);
        prop_assert!((ab - van_rossum(&b, &a, tau)).abs() <= 1e-12 * (1.0 + ab));
        prop_assert_eq!(van_rossum(&a, &a, tau), 0.0);
        if a != b {
            prop_assert!(ab > 0.0);
        }
    }
}

#[test]
fn the_recursion_equals_the_integral_of_the_filtered_traces() {
    let cases: [(&[u32], &[u32], f64); 4] = [
        (&[3, 10, 11, 40], &[5, 12, 60], 5.0),
        (&[0, 1, 2, 3], &[], 2.0),
        (&[7, 30, 31, 32, 90], &[7, 29, 33, 91], 20.0),
        (&[100], &[0, 150], 50.0),
    ];
    for (a, b, tau) in cases {
        let fast = van_rossum_squared(a, b, tau);
        let slow = integrated(a, b, tau, 0.01);
        assert!(
            (fast - slow).abs() < 1e-4 * (1.0 + slow),
            "{a:?} {b:?} {tau}: {fast} vs {slow}"
        );
    }
}

#[test]
fn hand_cases() {
    // identical trains, and both empty
    assert_eq!(van_rossum(&[1, 5, 9], &[1, 5, 9], 10.0), 0.0);
    assert_eq!(van_rossum(&[], &[], 10.0), 0.0);
    // one spike against none: (1/τ) ∫ e^{-2t/τ} dt = ½
    for tau in [0.5, 10.0, 1e4] {
        assert!((van_rossum(&[42], &[], tau) - 0.5f64.sqrt()).abs() < 1e-15);
        assert!((van_rossum(&[], &[0], tau) - 0.5f64.sqrt()).abs() < 1e-15);
    }
    // two single spikes dt apart: D² = 1 - e^{-dt/τ}
    for (dt, tau) in [(1u32, 10.0), (10, 10.0), (300, 10.0), (5, 200.0)] {
        let want = (1.0 - (-f64::from(dt) / tau).exp()).sqrt();
        let got = van_rossum(&[1000], &[1000 + dt], tau);
        assert!((got - want).abs() < 1e-14, "{dt} {tau}: {got} vs {want}");
    }
    // n spikes against none, far apart: n/2
    let far: Vec<u32> = (0..50).map(|i| i * 10_000).collect();
    assert!((van_rossum_squared(&far, &[], 1.0) - 25.0).abs() < 1e-12);
}

#[test]
fn long_dense_trains_stay_exact() {
    // 18 000 ms at about 50 Hz against a copy shifted by 1 ms: the sums are large and
    // nearly cancel, the recursion has nothing to cancel
    let a: Vec<u32> = (0..900).map(|i| i * 20 + (i * 7) % 11).collect();
    let b: Vec<u32> = a.iter().map(|t| t + 1).collect();
    for tau in [1.0, 50.0, 1_000.0] {
        let fast = van_rossum_squared(&a, &b, tau);
        let (slow, scale) = double_sum(&a, &b, tau);
        assert!(
            (fast - slow).abs() <= 1e-9 * scale,
            "{tau}: {fast} vs {slow}"
        );
    }
}

#[test]
fn agrees_with_elephant() {
    // values from tests/reference/make_van_rossum_reference.py (Elephant 1.2.1,
    // van_rossum_distance, divided by √2 to the van Rossum 2001 normalisation)
    let text = include_str!("data/van_rossum_reference.json");
    let json: serde_json::Value = serde_json::from_str(text).unwrap();
    let cases = json["cases"].as_array().unwrap();
    assert_eq!(cases.len(), 16);
    for case in cases {
        let tau = case["tau_ms"].as_f64().unwrap();
        let trains: Vec<Vec<u32>> = serde_json::from_value(case["trains"].clone()).unwrap();
        let want: Vec<Vec<f64>> = serde_json::from_value(case["distance"].clone()).unwrap();
        for (i, a) in trains.iter().enumerate() {
            for (j, b) in trains.iter().enumerate() {
                let got = van_rossum(a, b, tau);
                // Elephant sums in seconds-scaled exponents and subtracts large sums
                let tol = 1e-7 * (1.0 + want[i][j]);
                assert!((got - want[i][j]).abs() < tol, "{tau} ({i},{j}): {got}");
            }
        }
    }
}

/// A xorshift generator for the recordings below.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
}

/// Recordings of `classes` classes on a 2x2 grid with one cell masked: class `c` fires
/// about every `25 + 10 c` ms, each spike jittered.
fn recordings(
    per_class: usize,
    classes: usize,
    steps: u32,
    seed: u64,
) -> (Vec<SpikeTrains>, Vec<usize>) {
    let mut rng = Rng(seed | 1);
    let present = [true, true, false, true];
    let mut out = Vec::new();
    let mut y = Vec::new();
    for i in 0..per_class * classes {
        let class = i % classes;
        let period = 25 + 10 * class as u32;
        let lists: Vec<Vec<u32>> = (0..4)
            .map(|cell| {
                let mut t = (cell as u32 * 7 + rng.next() as u32 % 5) % period;
                let mut list = Vec::new();
                while t < steps {
                    list.push(t);
                    t += period - 3 + (rng.next() % 7) as u32;
                }
                list
            })
            .collect();
        out.push(SpikeTrains::from_lists(
            &lists,
            2,
            2,
            &present,
            steps as usize,
        ));
        y.push(class);
    }
    (out, y)
}

/// Brute force: all distances recomputed pair by pair, neighbours by a full sort on
/// (distance, training position), votes counted, ties to the class of the nearest member.
fn brute_force_predict(
    recs: &[SpikeTrains],
    train: &[usize],
    labels: &[usize],
    query: usize,
    k: usize,
    tau: f64,
) -> usize {
    let dist = |a: &SpikeTrains, b: &SpikeTrains| -> f64 {
        let cells = (0..a.cells()).filter(|&c| a.present[c]);
        cells
            .map(|c| van_rossum_squared(a.train(c), b.train(c), tau))
            .sum::<f64>()
            .sqrt()
    };
    let mut order: Vec<(f64, usize)> = train
        .iter()
        .enumerate()
        .map(|(pos, &t)| (dist(&recs[query], &recs[t]), pos))
        .collect();
    order.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let nearest = &order[..k];
    let count = |c: usize| nearest.iter().filter(|&&(_, p)| labels[p] == c).count();
    let top = nearest
        .iter()
        .map(|&(_, p)| count(labels[p]))
        .max()
        .unwrap();
    nearest
        .iter()
        .map(|&(_, p)| labels[p])
        .find(|&c| count(c) == top)
        .unwrap()
}

#[test]
fn knn_on_the_matrix_predicts_as_brute_force() {
    let (recs, y) = recordings(6, 3, 1_500, 11);
    for (tau, k) in [(2.0, 1), (10.0, 3), (100.0, 5)] {
        let metric = VanRossumParams { tau_ms: tau }.check().unwrap();
        let matrix = metric.matrix(&recs).unwrap();
        let knn = SpikeDistanceKnn::new(k).unwrap();
        // train on every third recording's complement, test on the rest
        let train: Vec<usize> = (0..recs.len()).filter(|i| i % 3 != 1).collect();
        let test: Vec<usize> = (0..recs.len()).filter(|i| i % 3 == 1).collect();
        let labels: Vec<usize> = train.iter().map(|&i| y[i]).collect();
        let model = knn.learn(&matrix, &train, &labels).unwrap();
        let got = model.decide(&matrix, &test).unwrap().remove(0);
        let want: Vec<usize> = test
            .iter()
            .map(|&q| brute_force_predict(&recs, &train, &labels, q, k, tau))
            .collect();
        assert_eq!(got, want, "tau {tau}, k {k}");
        // the same through distances to the training recordings, as for new recordings
        let train_recs: Vec<SpikeTrains> = train.iter().map(|&i| recs[i].clone()).collect();
        let test_recs: Vec<SpikeTrains> = test.iter().map(|&i| recs[i].clone()).collect();
        let cross = metric.cross_distances(&test_recs, &train_recs).unwrap();
        assert_eq!(model.predict_from_distances(&cross), want);
    }
}

/// Points on a small integer lattice (many equal distances) and their Euclidean matrix.
fn lattice(n: usize, seed: u64) -> (Vec<f64>, Vec<usize>, DistanceMatrix) {
    let mut rng = Rng(seed | 1);
    let points: Vec<f64> = (0..2 * n).map(|_| (rng.next() % 4) as f64).collect();
    let y: Vec<usize> = (0..n).map(|_| (rng.next() % 3) as usize).collect();
    let mut values = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            let (dx, dy) = (
                points[2 * i] - points[2 * j],
                points[2 * i + 1] - points[2 * j + 1],
            );
            values[i * n + j] = (dx * dx + dy * dy).sqrt();
        }
    }
    (points, y, DistanceMatrix::from_values(n, values).unwrap())
}

#[test]
fn cross_validation_over_the_matrix_equals_knn_on_the_points_ties_included() {
    // a matrix of Euclidean distances must classify exactly like the feature KNN on the
    // points themselves, whose tie rules it copies; the lattice makes ties common
    let plain = KnnParams {
        k: 5,
        standardize: false,
    }
    .check()
    .unwrap();
    let names: Vec<String> = (0..3).map(|c| c.to_string()).collect();
    let mut compared = 0;
    for seed in 1..6 {
        let (points, y, matrix) = lattice(40, seed);
        let knn = SpikeDistanceKnn::new(5).unwrap();
        let cv = CvParams {
            folds: 4,
            seed,
            repeats: 2,
        }
        .check()
        .unwrap();
        let all: Vec<usize> = (0..y.len()).collect();
        let (Ok(mut on_matrix), Ok(on_points)) = (
            cross_validate_on(&knn, &matrix, (&all, &y), &names, cv, None),
            cross_validate(&plain, &points, 2, &y, &names, cv),
        ) else {
            continue; // a class too small for 4 folds under this seed
        };
        let on_matrix = on_matrix.remove(0);
        assert_eq!(on_matrix.predictions, on_points.predictions, "seed {seed}");
        compared += 1;
    }
    assert!(compared >= 3, "only {compared} seeds compared");
}

#[test]
fn cross_validation_separates_classes_that_differ_in_timing() {
    let (recs, y) = recordings(10, 3, 2_000, 5);
    let metric = VanRossumParams { tau_ms: 10.0 }.check().unwrap();
    let matrix = metric.matrix(&recs).unwrap();
    let knn = SpikeDistanceKnn::new(3).unwrap();
    let names: Vec<String> = (0..3).map(|c| format!("T{c}")).collect();
    let cv = CvParams::default().check().unwrap();
    let all: Vec<usize> = (0..y.len()).collect();
    let eval = cross_validate_on(&knn, &matrix, (&all, &y), &names, cv, None)
        .unwrap()
        .remove(0);
    assert_eq!(eval.n, 30);
    assert!(eval.accuracy > 0.9, "{}", eval.accuracy);
}

#[test]
fn the_multi_taxel_distance_adds_squared_taxel_distances_over_present_cells() {
    let (recs, _) = recordings(2, 2, 800, 9);
    let metric = VanRossumParams { tau_ms: 15.0 }.check().unwrap();
    let (a, b) = (&recs[0], &recs[3]);
    let want = [0, 1, 3]
        .iter()
        .map(|&c| van_rossum_squared(a.train(c), b.train(c), 15.0))
        .sum::<f64>()
        .sqrt();
    assert!((metric.distance(a, b).unwrap() - want).abs() < 1e-12);
    let m = metric.matrix(&recs).unwrap();
    assert!((m.get(0, 3) - want).abs() < 1e-9 * want);
    assert_eq!(m.get(3, 0), m.get(0, 3));
}

#[test]
fn bad_input_is_an_error_naming_the_rule() {
    for tau in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let err = VanRossumParams { tau_ms: tau }.check().unwrap_err();
        assert_eq!(err.name, "tau");
    }
    let (recs, y) = recordings(2, 2, 500, 3);
    let metric = VanRossumParams { tau_ms: 5.0 }.check().unwrap();
    let other = SpikeTrains::from_lists(&[vec![1], vec![2]], 1, 2, &[true, true], 500);
    let mixed = [recs[0].clone(), other];
    assert!(matches!(
        metric.matrix(&mixed),
        Err(ClassifyError::BadFeatures(_))
    ));
    assert!(matches!(
        metric.cross_distances(&mixed[1..], &recs),
        Err(ClassifyError::BadFeatures(_))
    ));
    let matrix = metric.matrix(&recs).unwrap();
    assert_eq!(SpikeDistanceKnn::new(0).unwrap_err().name, "k");
    let knn = SpikeDistanceKnn::new(3).unwrap();
    assert!(matches!(
        knn.learn(&matrix, &[0, 1, 2], &y),
        Err(ClassifyError::BadFeatures(_))
    ));
    assert!(matches!(
        knn.learn(&matrix, &[0, 1, 2, 4], &y),
        Err(ClassifyError::BadFeatures(_))
    ));
    assert!(matches!(
        knn.learn(&matrix, &[0, 1], &y[..2]),
        Err(ClassifyError::KTooLarge { .. })
    ));
    let model = knn.learn(&matrix, &[0, 1, 2], &y[..3]).unwrap();
    assert!(matches!(
        model.decide(&matrix, &[4]),
        Err(ClassifyError::BadFeatures(_))
    ));
    assert!(DistanceMatrix::from_values(2, vec![0.0, 1.0, 2.0, 0.0]).is_err());
}
