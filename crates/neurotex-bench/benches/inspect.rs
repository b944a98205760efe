//! `inspect`'s per-recording statistics (range, resting offset, full scale, dead, clock,
//! copies, stamps) on a FabricSlide-sized log (16 channels, 420 frames at 35.7 Hz) and on
//! a 10 s recording of 16 channels at 1 kHz. The whole command on FabricSlide is timed in
//! docs/performance.md.

use criterion::{criterion_group, criterion_main, Criterion};
use neurotex::inspect::signals::signal_stats;
use neurotex::recording::{Layout, Meta, Recording};

fn recording(frames: usize, fs: f64) -> Recording {
    let samples = (0..frames * 16)
        .map(|k| 100.0 + ((k * 7919) % 251) as f64 + (k % 16) as f64)
        .collect();
    Recording {
        fs,
        layout: Layout::grid(4, 4),
        samples,
        times_s: Some((0..frames).map(|t| t as f64 / fs).collect()),
        phases: None,
        meta: Meta::default(),
    }
}

fn bench(c: &mut Criterion) {
    let fabric = recording(420, 35.7);
    c.bench_function("inspect/signal_stats/16x420", |b| {
        b.iter(|| signal_stats(std::hint::black_box(&fabric)))
    });
    let long = recording(10_000, 1000.0);
    c.bench_function("inspect/signal_stats/16x10000", |b| {
        b.iter(|| signal_stats(std::hint::black_box(&long)))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
