//! The stream classifier, one thread: a frame between bin boundaries, and a whole 200 ms
//! bin of frames (199 of them, then the one that classifies the window), 4x4 taxels and a
//! 100x100 skin, 3D-GLCM + KNN. The model's training rows are made up: the work per frame
//! and per bin does not depend on them.

mod support;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use neurotex::model::Model;
use neurotex::pipeline::PipelineParams;
use neurotex::signal::CausalConditioning;
use neurotex::stream::{StreamClassifier, StreamParams};
use support::made_up_model;

fn model(side: usize) -> Model {
    let mut params = PipelineParams::default();
    params.preprocess.causal = Some(CausalConditioning {
        offsets: vec![0.0; side * side],
        scale: 1.0,
    });
    made_up_model(side, &params)
}

/// 200 frames of a texture moving over the skin, values in [0, 1].
fn frames(side: usize) -> Vec<Vec<f64>> {
    (0..200)
        .map(|t| {
            (0..side * side)
                .map(|c| 0.5 + 0.5 * ((c % side) as f64 * 0.8 + 0.013 * t as f64).sin())
                .collect()
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("stream");
    for side in [4usize, 100] {
        let model = model(side);
        let frames = frames(side);
        let mut stream =
            StreamClassifier::new(model.clone(), StreamParams::for_model(&model)).unwrap();
        // A full window first, so that each bin classifies 4 s of spikes.
        for _ in 0..20 {
            for f in &frames {
                stream.push(None, f).unwrap();
            }
        }
        let id = format!("{side}x{side}");
        group.bench_function(BenchmarkId::new("bin_of_200_frames", &id), |b| {
            b.iter(|| {
                let mut events = 0;
                for f in &frames {
                    events += stream.push(None, f).unwrap().len();
                }
                assert_eq!(events, 1);
            })
        });
        group.bench_function(BenchmarkId::new("frame_between_bins", &id), |b| {
            // Every push is timed but those that end a bin, which run untimed. (Criterion
            // may call this closure more than once: the stream's own count says where in
            // the bin it stands.)
            b.iter_custom(|iters| {
                let mut total = std::time::Duration::ZERO;
                let mut timed = 0;
                while timed < iters {
                    let pushed = stream.frames() as usize + 1;
                    let frame = &frames[pushed % 200];
                    if pushed.is_multiple_of(200) {
                        assert_eq!(stream.push(None, frame).unwrap().len(), 1);
                        continue;
                    }
                    let start = std::time::Instant::now();
                    let n = stream.push(None, frame).unwrap().len();
                    total += start.elapsed();
                    assert_eq!(n, 0);
                    timed += 1;
                }
                total
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
