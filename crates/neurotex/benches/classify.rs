//! KNN (k = 5) with 5-fold stratified cross-validation on 160 samples x 3 features
//! (8 classes x 20 trials, one speed of the paper's dataset).

use criterion::{criterion_group, criterion_main, Criterion};
use neurotex::classify::{cross_validate, CvParams, KnnParams};

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

criterion_group!(benches, bench);
criterion_main!(benches);
