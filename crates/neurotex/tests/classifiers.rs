//! The random forest and the logistic regression: against scikit-learn (values in
//! `tests/reference/classifiers.json`, made by `tests/reference/make_classifier_reference.py`
//! with scikit-learn 1.9.1), a single tree against a slow reference, determinism across
//! thread counts, and KNN's shares against its votes.

use neurotex::classify::{
    Classifier, ClassifierChoice, ForestParams, KnnParams, LinearParams, Predict,
};
use proptest::prelude::*;
use serde_json::Value;

fn reference() -> Value {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/reference/classifiers.json"
    ))
    .expect("classifiers.json is in the repository");
    serde_json::from_str(&text).expect("valid JSON")
}

/// A JSON matrix, row-major, with its row length.
fn rows(v: &Value) -> (Vec<f64>, usize) {
    let rows = v.as_array().unwrap();
    let dims = rows[0].as_array().unwrap().len();
    let flat = rows
        .iter()
        .flat_map(|r| r.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()))
        .collect();
    (flat, dims)
}

fn labels(v: &Value) -> Vec<usize> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_u64().unwrap() as usize)
        .collect()
}

fn close(a: f64, b: f64, tol: f64, what: &str) {
    assert!((a - b).abs() <= tol, "{what}: {a} vs scikit-learn {b}");
}

#[test]
fn multinomial_logistic_regression_matches_scikit_learn() {
    let case = &reference()["logistic_multinomial"];
    let (x, dims) = rows(&case["train_x"]);
    let y = labels(&case["train_y"]);
    let params = LinearParams {
        c: case["c"].as_f64().unwrap(),
        ..LinearParams::default()
    };
    let model = params.check().unwrap().fit(&x, dims, &y).unwrap();
    assert!(model.converged(), "{} iterations", model.iterations());
    let (coef, _) = rows(&case["coef"]);
    assert_eq!(model.weights().len(), coef.len());
    for (i, (&w, &c)) in model.weights().iter().zip(&coef).enumerate() {
        close(w, c, 1e-6, &format!("weight {i}"));
    }
    // The constant fifth column is only centred: it carries no weight.
    assert!(model.weights().chunks(dims).all(|w| w[4] == 0.0));
    let sk: Vec<f64> = labels_f64(&case["intercept"]);
    let sk_mean = sk.iter().sum::<f64>() / sk.len() as f64;
    for (&b, &s) in model.intercepts().iter().zip(&sk) {
        close(b, s - sk_mean, 1e-6, "intercept");
    }
    let (test, _) = rows(&case["test_x"]);
    let (proba, classes) = rows(&case["proba"]);
    let ours = model.predict_with_shares(&test);
    for (row, (predicted, shares)) in ours.iter().enumerate() {
        let expected = &proba[row * classes..(row + 1) * classes];
        for (&p, &e) in shares.iter().zip(expected) {
            close(p, e, 1e-6, &format!("probability of row {row}"));
        }
        assert!(expected.iter().all(|&e| e <= expected[*predicted]));
    }
}

fn labels_f64(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

#[test]
fn two_classes_are_scikit_learns_binary_regression_at_twice_the_c() {
    let case = &reference()["logistic_binary"];
    let (x, dims) = rows(&case["train_x"]);
    let y = labels(&case["train_y"]);
    assert_eq!(case["c"], 2.0);
    let model = LinearParams::default()
        .check()
        .unwrap()
        .fit(&x, dims, &y)
        .unwrap();
    let (coef, _) = rows(&case["coef"]);
    let w = model.weights();
    for j in 0..dims {
        close(w[dims + j] - w[j], coef[j], 1e-6, &format!("weight {j}"));
    }
    let (test, _) = rows(&case["test_x"]);
    let (proba, _) = rows(&case["proba"]);
    for (row, (_, shares)) in model.predict_with_shares(&test).iter().enumerate() {
        close(shares[1], proba[2 * row + 1], 1e-6, "probability");
    }
}

#[test]
fn the_forest_is_within_a_few_points_of_scikit_learns() {
    // A sanity check, not equality: the two forests draw different bootstrap samples and
    // features, so the mean accuracy over five seeds is compared on 400 test rows.
    let case = &reference()["forest"];
    let (x, dims) = rows(&case["train_x"]);
    let y = labels(&case["train_y"]);
    let (test, _) = rows(&case["test_x"]);
    let truth = labels(&case["test_y"]);
    let sk = labels_f64(&case["accuracies"]);
    let sk_mean = sk.iter().sum::<f64>() / sk.len() as f64;
    let mut ours = 0.0;
    for seed in 0..5 {
        let params = ForestParams {
            seed,
            ..ForestParams::default()
        };
        let model = params.check().unwrap().fit(&x, dims, &y).unwrap();
        let predicted = model.predict(&test);
        let right = predicted.iter().zip(&truth).filter(|(p, t)| p == t).count();
        ours += right as f64 / truth.len() as f64 / 5.0;
    }
    assert!(
        (ours - sk_mean).abs() < 0.04,
        "neurotex {ours:.4} vs scikit-learn {sk_mean:.4}"
    );
}

/// Well separated classes: `per_class` rows of `dims` features around centres 10 apart.
fn separable(per_class: usize, dims: usize, classes: usize, seed: u64) -> (Vec<f64>, Vec<usize>) {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let y: Vec<usize> = (0..per_class * classes).map(|i| i % classes).collect();
    let x = y
        .iter()
        .flat_map(|&c| {
            let noise: Vec<f64> = (0..dims).map(|_| rng.gen::<f64>()).collect();
            noise
                .into_iter()
                .enumerate()
                .map(move |(j, v)| v + 10.0 * ((c + j) % classes) as f64)
        })
        .collect();
    (x, y)
}

#[test]
fn every_classifier_separates_separable_classes() {
    let (x, y) = separable(20, 6, 5, 1);
    let (test, truth) = separable(10, 6, 5, 2);
    for name in ClassifierChoice::NAMES {
        let choice: ClassifierChoice = name.parse().unwrap();
        let model = choice.check().unwrap().fit(&x, 6, &y).unwrap();
        assert_eq!(model.predict(&test), truth, "{name}");
        for (predicted, shares) in model.predict_with_shares(&test) {
            assert_eq!(shares.len(), 5);
            assert!((shares.iter().sum::<f64>() - 1.0).abs() < 1e-12, "{name}");
            assert!(shares.iter().all(|&s| s <= shares[predicted]), "{name}");
        }
    }
}

#[test]
fn the_forest_is_the_same_on_one_thread_and_on_two() {
    let (x, y) = separable(30, 12, 4, 3);
    // Overlap the classes so that trees grow deep and differ.
    let x: Vec<f64> = x.iter().map(|v| v * 0.05).collect();
    let forest = ForestParams {
        trees: 40,
        seed: 11,
        ..ForestParams::default()
    }
    .check()
    .unwrap();
    let fit_on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| forest.fit(&x, 12, &y).unwrap())
    };
    let (one, two) = (fit_on(1), fit_on(2));
    assert_eq!(one, two);
    let (queries, _) = separable(10, 12, 4, 4);
    let queries: Vec<f64> = queries.iter().map(|v| v * 0.05).collect();
    assert_eq!(
        one.predict_with_shares(&queries),
        two.predict_with_shares(&queries)
    );
    let other = ForestParams {
        trees: 40,
        seed: 12,
        ..ForestParams::default()
    };
    let other = other.check().unwrap().fit(&x, 12, &y).unwrap();
    assert_ne!(one, other, "the seed matters");
}

#[test]
fn knn_shares_are_its_votes_over_k() {
    let (x, y) = separable(8, 3, 3, 5);
    let (queries, _) = separable(4, 3, 3, 6);
    let queries: Vec<f64> = queries.iter().map(|v| v * 0.7).collect();
    let model = KnnParams {
        k: 5,
        standardize: true,
    }
    .check()
    .unwrap()
    .fit(&x, 3, &y)
    .unwrap();
    let votes = model.predict_with_votes(&queries);
    let shares = model.predict_with_shares(&queries);
    for ((class, v), (predicted, s)) in votes.iter().zip(&shares) {
        assert_eq!(class, predicted);
        let expected: Vec<f64> = v.iter().map(|&n| n as f64 / 5.0).collect();
        assert_eq!(s, &expected);
    }
}

/// The slow, evidently correct tree: at every node each feature and each threshold between
/// neighbouring distinct values is tried, the children's class counts found by scanning
/// the node, and the split of least weighted Gini impurity kept (compared exactly as
/// fractions; the first feature, then the first threshold, on ties).
#[derive(Debug)]
enum Slow {
    Split(usize, f64, Box<Slow>, Box<Slow>),
    Leaf(Vec<f64>),
}

struct SlowData<'a> {
    x: &'a [f64],
    dims: usize,
    y: &'a [usize],
    classes: usize,
    min_leaf: usize,
    max_depth: usize,
}

impl SlowData<'_> {
    fn counts(&self, samples: &[usize]) -> Vec<i128> {
        let mut counts = vec![0i128; self.classes];
        for &s in samples {
            counts[self.y[s]] += 1;
        }
        counts
    }

    /// Weighted Gini impurity `Σ_side n_side (1 - Σ_c p_c²)` as `(numerator, denominator)`.
    fn impurity(&self, left: &[usize], right: &[usize]) -> (i128, i128) {
        let (nl, nr) = (left.len() as i128, right.len() as i128);
        let sq = |c: Vec<i128>| c.iter().map(|v| v * v).sum::<i128>();
        let (sl, sr) = (sq(self.counts(left)), sq(self.counts(right)));
        ((nl + nr) * nl * nr - sl * nr - sr * nl, nl * nr)
    }

    fn grow(&self, samples: Vec<usize>, depth: usize) -> Slow {
        let counts = self.counts(&samples);
        let pure = counts.iter().filter(|&&c| c > 0).count() <= 1;
        let mut best: Option<((i128, i128), usize, f64)> = None;
        if !pure && depth < self.max_depth {
            for f in 0..self.dims {
                let value = |s: usize| self.x[s * self.dims + f];
                let mut distinct: Vec<f64> = samples.iter().map(|&s| value(s)).collect();
                distinct.sort_by(f64::total_cmp);
                distinct.dedup();
                for pair in distinct.windows(2) {
                    let (left, right): (Vec<usize>, Vec<usize>) =
                        samples.iter().partition(|&&s| value(s) <= pair[0]);
                    if left.len() < self.min_leaf || right.len() < self.min_leaf {
                        continue;
                    }
                    let g = self.impurity(&left, &right);
                    let better = best.is_none_or(|(b, _, _)| g.0 * b.1 < b.0 * g.1);
                    if better {
                        let mid = pair[0] / 2.0 + pair[1] / 2.0;
                        let threshold = if mid >= pair[1] { pair[0] } else { mid };
                        best = Some((g, f, threshold));
                    }
                }
            }
        }
        match best {
            None => {
                let n = samples.len() as f64;
                Slow::Leaf(counts.iter().map(|&c| c as f64 / n).collect())
            }
            Some((_, f, t)) => {
                let (left, right) = samples
                    .iter()
                    .partition(|&&s| self.x[s * self.dims + f] <= t);
                Slow::Split(
                    f,
                    t,
                    Box::new(self.grow(left, depth + 1)),
                    Box::new(self.grow(right, depth + 1)),
                )
            }
        }
    }
}

impl Slow {
    fn shares(&self, row: &[f64]) -> &[f64] {
        match self {
            Slow::Leaf(shares) => shares,
            Slow::Split(f, t, left, right) => {
                if row[*f] <= *t {
                    left.shares(row)
                } else {
                    right.shares(row)
                }
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// One tree on the whole training set with every feature tried is the slow tree,
    /// exactly: features on a coarse grid make ties and duplicates common.
    #[test]
    fn one_full_tree_is_the_slow_reference(
        n in 2usize..40,
        dims in 1usize..5,
        classes in 2usize..4,
        seed in any::<u64>(),
        min_leaf in 1usize..4,
        max_depth in prop::option::of(1usize..6),
    ) {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let x: Vec<f64> = (0..n * dims).map(|_| f64::from(rng.gen_range(0..6u8)) * 0.5).collect();
        let y: Vec<usize> = (0..n).map(|_| rng.gen_range(0..classes)).collect();
        let params = ForestParams {
            trees: 1,
            bootstrap: false,
            max_features: Some(dims),
            min_samples_leaf: min_leaf,
            max_depth,
            seed,
        };
        let model = params.check().unwrap().fit(&x, dims, &y).unwrap();
        let n_classes = y.iter().max().unwrap() + 1;
        let slow = SlowData {
            x: &x,
            dims,
            y: &y,
            classes: n_classes,
            min_leaf,
            max_depth: max_depth.unwrap_or(usize::MAX),
        }
        .grow((0..n).collect(), 0);
        let queries: Vec<f64> = (0..30 * dims).map(|_| rng.gen_range(-0.5..3.0)).collect();
        for rows in [&x, &queries] {
            for (row, (_, shares)) in rows.chunks(dims).zip(model.predict_with_shares(rows)) {
                prop_assert_eq!(&shares[..], slow.shares(row));
            }
        }
    }
}
