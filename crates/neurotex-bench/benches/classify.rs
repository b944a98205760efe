//! KNN (k = 5) with 5-fold stratified cross-validation on 160 samples x 3 features
//! (8 classes x 20 trials, one speed of the paper's dataset); fitting a random forest
//! (200 trees, √d features per split) and a logistic regression (C = 1) on 1000 samples x
//! 100 features of 8 classes, and on 102 samples (E9's nested inner training sets) of 96,
//! 6 and 448 features (`all-taxels`, `glcm3d` and `spectrum` of `sa+fa`); the resampling
//! statistics every accuracy carries: a 2000-resample bootstrap interval over 160
//! recordings (one speed) and a 2000-resample sign-flip test over 480 paired differences.

use criterion::{criterion_group, criterion_main, Criterion};
use neurotex::classify::metrics::sign_flip_p;
use neurotex::classify::{
    bootstrap_mean_share, cross_validate, BootstrapParams, Classifier, CvParams, ForestParams,
    KnnParams, LinearParams,
};

fn bench(c: &mut Criterion) {
    let mut state = 0x2545f4914f6cdd1du64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state % 10_000) as f64 / 10_000.0
    };
    let y: Vec<usize> = (0..160).map(|i| i / 20).collect();
    let x: Vec<f64> = y
        .iter()
        .flat_map(|&k| {
            [
                k as f64 * 3.0 + next() * 10.0,
                next() + 0.1 * k as f64,
                next() * 0.01,
            ]
        })
        .collect::<Vec<f64>>();
    let names: Vec<String> = (0..8).map(|k| format!("T{k}")).collect();
    let knn = KnnParams::default().check().unwrap();
    let cv = CvParams::default().check().unwrap();
    c.bench_function("classify/knn_cv5/160x3", |b| {
        b.iter(|| {
            cross_validate(&knn, &x, 3, &y, &names, cv)
                .unwrap()
                .accuracy
        })
    });
}

/// `n` samples x `dims` features of `classes` classes: every feature uniform noise plus a
/// class offset on the first quarter of the features, so the classes overlap.
fn overlapping(n: usize, dims: usize, classes: usize) -> (Vec<f64>, Vec<usize>) {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state % 1_000_000) as f64 / 1_000_000.0
    };
    let y: Vec<usize> = (0..n).map(|i| i % classes).collect();
    let x = y
        .iter()
        .flat_map(|&c| {
            (0..dims)
                .map(|j| {
                    let offset = if j < dims / 4 {
                        ((c + j) % classes) as f64 * 0.3
                    } else {
                        0.0
                    };
                    offset + next()
                })
                .collect::<Vec<_>>()
        })
        .collect();
    (x, y)
}

fn bench_fit(c: &mut Criterion) {
    let (n, dims) = (1000, 100);
    let (x, y) = overlapping(n, dims, 8);
    let forest = ForestParams::default().check().unwrap();
    let mut group = c.benchmark_group("classify");
    group.sample_size(10);
    group.bench_function(format!("forest_fit/200trees/{n}x{dims}"), |b| {
        b.iter(|| forest.fit(&x, dims, &y).unwrap())
    });
    let linear = LinearParams::default().check().unwrap();
    group.bench_function(format!("linear_fit/{n}x{dims}"), |b| {
        b.iter(|| linear.fit(&x, dims, &y).unwrap())
    });
    // E9's size: a training set of nested selection's inner folds within one speed (4/5 of
    // 4/5 of 160 recordings), the `all-taxels` rows of `sa+fa`.
    let (n, dims) = (102, 96);
    let (x, y) = overlapping(n, dims, 8);
    group.bench_function(format!("forest_fit/200trees/{n}x{dims}"), |b| {
        b.iter(|| forest.fit(&x, dims, &y).unwrap())
    });
    group.bench_function(format!("linear_fit/{n}x{dims}"), |b| {
        b.iter(|| linear.fit(&x, dims, &y).unwrap())
    });
    // The same training set's rows of E9's narrowest and widest forest candidates:
    // `glcm3d` of `sa+fa` (one split feature tried per node), `spectrum` of `sa` (the widest
    // the regression preconditions) and of `sa+fa` (21 features tried per node).
    for dims in [6, 224, 448] {
        let (x, y) = overlapping(n, dims, 8);
        group.bench_function(format!("forest_fit/200trees/{n}x{dims}"), |b| {
            b.iter(|| forest.fit(&x, dims, &y).unwrap())
        });
        group.bench_function(format!("linear_fit/{n}x{dims}"), |b| {
            b.iter(|| linear.fit(&x, dims, &y).unwrap())
        });
    }
    group.finish();
}

fn bench_resampling(c: &mut Criterion) {
    // Shares of 10 CV repeats right per recording, and paired differences of two methods.
    let shares: Vec<f64> = (0..160).map(|i| ((i * 7) % 11) as f64 / 10.0).collect();
    let differences: Vec<f64> = (0..480)
        .map(|i| ((i * 13) % 21) as f64 / 10.0 - 1.0)
        .collect();
    let params = BootstrapParams::default().check().unwrap();
    c.bench_function("classify/bootstrap_interval/160", |b| {
        b.iter(|| bootstrap_mean_share(&shares, &params).unwrap().lower)
    });
    c.bench_function("classify/sign_flip/480", |b| {
        b.iter(|| sign_flip_p(&differences, 2000, 0).unwrap())
    });
}

criterion_group!(benches, bench, bench_fit, bench_resampling);
criterion_main!(benches);
