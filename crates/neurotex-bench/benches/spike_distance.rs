//! Van Rossum distance matrix of 100 recordings x 16 taxels x 18 000 ms with ~20 Hz trains
//! (about 360 spikes per taxel), tau = 10 ms and 200 ms; and one exact taxel pair.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use neurotex::classify::{van_rossum_squared, VanRossumParams};
use neurotex::encode::SpikeTrains;

fn recordings(n: usize, steps: u32) -> Vec<SpikeTrains> {
    let mut state = 0x2545f4914f6cdd1du64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    (0..n)
        .map(|_| {
            let lists: Vec<Vec<u32>> = (0..16)
                .map(|_| (0..steps).filter(|_| next() % 50 == 0).collect())
                .collect();
            SpikeTrains::from_lists(&lists, 4, 4, &[true; 16], steps as usize)
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let recs = recordings(100, 18_000);
    let mut group = c.benchmark_group("spike_distance");
    group.sample_size(10);
    for tau in [10.0, 200.0] {
        let metric = VanRossumParams { tau_ms: tau }.check().unwrap();
        group.bench_with_input(
            BenchmarkId::new("van_rossum_matrix/100x16x18000ms", tau),
            &recs,
            |b, recs| b.iter(|| metric.matrix(recs).unwrap().values()[1]),
        );
    }
    let (a, b) = (recs[0].train(0).to_vec(), recs[1].train(0).to_vec());
    group.bench_function("van_rossum_pair/18000ms_20Hz", |bench| {
        bench.iter(|| van_rossum_squared(&a, &b, 10.0))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
