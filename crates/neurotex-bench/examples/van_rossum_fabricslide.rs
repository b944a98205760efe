//! Van Rossum KNN on an imported dataset: encodes every recording with the default
//! pipeline, times the full distance matrix, and cross-validates (k = 5, 5 folds) the
//! recordings of one speed through the matrix for tau = 10, 50 and 200 ms.
//!
//! ```text
//! cargo run --release -p neurotex-bench --example van_rossum_fabricslide -- /tmp/fsc 10
//! ```

use std::time::Instant;

use neurotex::classify::{cross_validate_on, CvParams, SpikeDistanceKnn, VanRossumParams};
use neurotex::pipeline::{Pipeline, PipelineParams};
use neurotex::recording::Dataset;
use neurotex::values::Speed;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let root = args
        .next()
        .ok_or("usage: van_rossum_fabricslide DATASET SPEED_MM_S")?;
    let speed: f64 = args.next().unwrap_or_else(|| "10".into()).parse()?;
    let dataset = Dataset::open(&root)?;
    let pipeline = Pipeline::new(PipelineParams::default())?;
    let all: Vec<usize> = (0..dataset.entries.len()).collect();
    let started = Instant::now();
    let encoded = pipeline.encode_dataset(&dataset, &all, &|| {})?;
    let spikes: Vec<_> = encoded.iter().map(|e| e.spikes.clone()).collect();
    let steps: Vec<usize> = spikes.iter().map(|s| s.n_steps).collect();
    let total: usize = spikes.iter().map(|s| s.total_spikes()).sum();
    println!(
        "encoded {} recordings in {:.1} s: {}..{} ms long, {:.1} spikes per taxel-second",
        spikes.len(),
        started.elapsed().as_secs_f64(),
        steps.iter().min().unwrap_or(&0),
        steps.iter().max().unwrap_or(&0),
        total as f64 * 1000.0 / (steps.iter().sum::<usize>() as f64 * 16.0)
    );
    let at_speed = dataset.indices_at(&[Speed::new(speed)?])?;
    let labels = dataset.labels();
    let y: Vec<usize> = at_speed
        .iter()
        .map(|&i| {
            labels
                .iter()
                .position(|l| *l == dataset.entries[i].label)
                .unwrap()
        })
        .collect();
    let cv = CvParams::default().check()?;
    for tau in [10.0, 50.0, 200.0] {
        let metric = VanRossumParams { tau_ms: tau }.check()?;
        let started = Instant::now();
        let full = metric.matrix(&spikes)?;
        let full_s = started.elapsed().as_secs_f64();
        let subset: Vec<_> = at_speed.iter().map(|&i| spikes[i].clone()).collect();
        let (matrix, knn) = (metric.matrix(&subset)?, SpikeDistanceKnn::new(5)?);
        let all: Vec<usize> = (0..y.len()).collect();
        let eval = cross_validate_on(&knn, &matrix, (&all, &y), &labels, cv, None)?.remove(0);
        println!(
            "tau {tau:>5} ms: full {n}x{n} matrix {full_s:.2} s; {speed} mm/s: {} recordings, \
             {} classes, 5-fold accuracy {:.3}",
            y.len(),
            labels.len(),
            eval.accuracy,
            n = full.n()
        );
    }
    Ok(())
}
