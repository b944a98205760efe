//! The simulated rig: one trial of the full protocol (5 s hold, 90 mm slide) per speed.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use neurotex::sim::{simulate_trial, RigParams, Texture, Trial};

fn bench(c: &mut Criterion) {
    let p = RigParams::default();
    let mut group = c.benchmark_group("sim");
    group.sample_size(20);
    for (texture, speed) in [(Texture::Sb, 5.0), (Texture::Ft1, 15.0)] {
        let t = Trial {
            texture,
            speed_mm_s: speed,
            trial: 0,
        };
        group.bench_function(
            BenchmarkId::new("trial", format!("{}_{speed}mm_s", texture.name())),
            |b| b.iter(|| simulate_trial(&p, &t, 0).unwrap().samples.len()),
        );
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
