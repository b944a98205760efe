//! Latency and capacity of the stream classifier, on one thread.
//!
//! ```sh
//! cargo run --release -p neurotex-bench --example stream_latency            # both parts
//! cargo run --release -p neurotex-bench --example stream_latency -- latency
//! cargo run --release -p neurotex-bench --example stream_latency -- capacity
//! cargo run --release -p neurotex-bench --example stream_latency -- capacity 316   # one grid
//! cargo run --release -p neurotex-bench --example stream_latency -- memory         # 10 minutes
//! ```
//!
//! Latency: a causal 3D-GLCM + KNN model and a causal spiking network (16 SA inputs, 128
//! hidden neurons, 10 ms steps) trained on simulated slides (4x4 taxels); the slide
//! of one recording streamed 20 times over as one 1 kHz episode (no time stamps, so no
//! resampling; `--window-s` default: the training slides' median length). Each frame is
//! timed from the call that takes it to the JSON lines of what it completed written into
//! a buffer, as `neurotex stream` prints them; frames that end a bin are reported apart.
//!
//! Capacity: large skins (100x100, 200x200, 316x316 taxels) with a 3D-GLCM + KNN model
//! whose training rows are made up (the work per frame and per bin does not depend on
//! them), fed 4 s of a moving sinusoidal texture at 1 kHz; the real-time factor is stream
//! time over processing time, so a factor above 1 means the skin is processed in real time.
//!
//! Memory (Linux): a 100x100 skin streamed for 10 minutes as one episode with a 10 s
//! window; the process's resident memory (`VmRSS`, and its peak `VmHWM`) after each minute.

use std::time::Instant;

use neurotex::analysis::{Columns, FeatureTable};
use neurotex::causal::calibrate_conditioning;
use neurotex::classify::{ClassifierChoice, KnnParams};
use neurotex::model::{Model, Provenance};
use neurotex::pipeline::{Method, Pipeline, PipelineParams};
use neurotex::recording::{Baseline, Meta, Phase, Recording};
use neurotex::saved::SavedModel;
use neurotex::signal::CausalConditioning;
use neurotex::sim::{design, simulate_trial, RigParams, Texture};
use neurotex::snn::SnnParams;
use neurotex::spiking_model::SpikingModel;
use neurotex::stream::{bin_json, end_json, Event, StreamClassifier, StreamParams};
use neurotex::Grid;

fn main() {
    let part = std::env::args().nth(1).unwrap_or_default();
    if part.is_empty() || part == "latency" {
        latency();
    }
    if part.is_empty() || part == "capacity" {
        capacity();
    }
    if part == "memory" {
        memory();
    }
}

/// The `p`-th percentile of sorted nanoseconds, in µs.
fn percentile(sorted: &[u64], p: f64) -> f64 {
    let i = ((sorted.len() - 1) as f64 * p).round() as usize;
    sorted[i] as f64 / 1000.0
}

fn latency() {
    let rig = RigParams {
        hold_s: 0.3,
        slide_mm: 40.0,
        ..RigParams::default()
    };
    let trials = design(
        &[Texture::Ft1, Texture::Sb, Texture::Stf, Texture::Cp],
        &[10.0],
        5,
    );
    let recs: Vec<Recording> = trials
        .iter()
        .map(|t| simulate_trial(&rig, t, 3).unwrap())
        .collect();
    let mut params = PipelineParams::default();
    let load = |i: usize| Ok(recs[i].clone());
    let all: Vec<usize> = (0..recs.len()).collect();
    let calibration = calibrate_conditioning(&params, &load, &all, Baseline::None).unwrap();
    params.preprocess.causal = Some(calibration.conditioning);
    let pipeline = Pipeline::new(params.clone()).unwrap();
    let encoded: Vec<_> = recs
        .iter()
        .map(|r| pipeline.encode(r, Baseline::None).unwrap())
        .collect();
    let grid = Grid::masked(4, 4, vec![true; 16]).unwrap();
    let extractor = pipeline.extractor(&grid).unwrap();
    let table = FeatureTable::build(&encoded, &extractor, Method::Glcm3d).unwrap();
    let provenance = Provenance {
        fingerprint: "example".into(),
        baseline: Baseline::None,
        speeds: None,
        gain_calibration: None,
        median_duration_ms: Some(calibration.median_duration_ms),
        layout: None,
    };
    let knn = ClassifierChoice::Knn(KnnParams::default());
    let model = Model::train(&params, &table, Columns::All, knn, provenance.clone()).unwrap();
    let snn = SnnParams::default();
    let (network, _) =
        SpikingModel::train(&params, &encoded, &grid, (snn, &|| ()), provenance).unwrap();

    let rec = &recs[0];
    let phases = rec.phases.as_ref().unwrap();
    let lo = phases.iter().position(|&p| p == Phase::Slide).unwrap();
    let hi = phases.iter().rposition(|&p| p == Phase::Slide).unwrap() + 1;
    let frames: Vec<&[f64]> = rec.samples[lo * 16..hi * 16].chunks_exact(16).collect();
    time_stream("glcm3d + KNN", model.into(), &frames);
    time_stream("spiking network 16x128, dt 10 ms", network.into(), &frames);
}

/// Streams `frames` 20 times over through `model` and prints the latency percentiles.
fn time_stream(name: &str, model: SavedModel, frames: &[&[f64]]) {
    let labels = model.labels().to_vec();
    let params = StreamParams::for_model(&model);
    let window_ms = params.window_ms;
    let mut stream = StreamClassifier::new(model, params).unwrap();
    let mut out: Vec<u8> = Vec::with_capacity(1 << 20);
    let (mut between, mut at_bin) = (Vec::new(), Vec::new());
    let mut most_spikes = 0;
    for _ in 0..20 {
        for frame in frames {
            let start = Instant::now();
            let events = stream.push(None, frame).unwrap();
            for event in events {
                let line = match event {
                    Event::Bin(b) => bin_json(&labels, b, None),
                    Event::End(e) => end_json(&labels, e, None),
                };
                serde_json_line(&mut out, &line);
            }
            let ns = start.elapsed().as_nanos() as u64;
            match events.is_empty() {
                true => between.push(ns),
                false => at_bin.push(ns),
            }
            most_spikes = most_spikes.max(stream.retained_spikes());
            if out.len() > 1 << 19 {
                out.clear();
            }
        }
    }
    between.sort_unstable();
    at_bin.sort_unstable();
    println!(
        "latency, 4x4 taxels, {name}, window {window_ms} ms, {} frames ({} s of stream):",
        between.len() + at_bin.len(),
        (between.len() + at_bin.len()) / 1000
    );
    for (what, v) in [
        ("between bins", &between),
        ("at a bin boundary (classify + JSON)", &at_bin),
    ] {
        println!(
            "  {what}: n {}, p50 {:.2} us, p99 {:.2} us, max {:.1} us",
            v.len(),
            percentile(v, 0.5),
            percentile(v, 0.99),
            *v.last().unwrap() as f64 / 1000.0
        );
    }
    println!("  spike times held at most: {most_spikes} (u32 each)");
}

fn serde_json_line(out: &mut Vec<u8>, line: &serde_json::Value) {
    serde_json::to_writer(&mut *out, line).unwrap();
    out.push(b'\n');
}

/// A 3D-GLCM + KNN causal model on a `side x side` grid with made-up training rows.
fn large_model(side: usize) -> Model {
    let cells = side * side;
    let mut params = PipelineParams::default();
    params.preprocess.causal = Some(CausalConditioning {
        offsets: vec![0.0; cells],
        scale: 1.0,
    });
    let grid = Grid::masked(side, side, vec![true; cells]).unwrap();
    let metas: Vec<Meta> = (0..10)
        .map(|i| Meta {
            file: format!("made-up-{i}"),
            label: ["A", "B"][i % 2].into(),
            ..Meta::default()
        })
        .collect();
    let values: Vec<f64> = (0..30).map(|i| ((i * 37) % 11) as f64 / 11.0).collect();
    let table = FeatureTable {
        method: Method::Glcm3d,
        grid,
        names: vec!["contrast".into(), "correlation".into(), "asm".into()],
        metas,
        values,
    };
    let provenance = Provenance {
        fingerprint: "made up".into(),
        baseline: Baseline::None,
        speeds: None,
        gain_calibration: None,
        median_duration_ms: None,
        layout: None,
    };
    let knn = ClassifierChoice::Knn(KnnParams::default());
    Model::train(&params, &table, Columns::All, knn, provenance).unwrap()
}

fn capacity() {
    println!("capacity, one thread, 3D-GLCM + KNN, frames at 1 kHz without stamps:");
    // `capacity SIDE` measures one grid only.
    let sides = match std::env::args().nth(2) {
        Some(side) => vec![side.parse::<usize>().expect("a grid side")],
        None => vec![100, 200, 316],
    };
    for side in sides {
        for window_s in [2.0, 10.0] {
            let model = large_model(side);
            let mut params = StreamParams::for_model(&model);
            params.window_ms = (window_s * 1000.0) as usize;
            let mut stream = StreamClassifier::new(model, params).unwrap();
            let cells = side * side;
            // A texture of 1 mm period moving at 10 mm/s over 1 mm taxels, 100 frames
            // (0.1 s) of it cycled: values in [0, 1].
            let pattern: Vec<Vec<f64>> = (0..100)
                .map(|t| {
                    (0..cells)
                        .map(|c| {
                            let x = (c % side) as f64 + 0.01 * t as f64;
                            0.5 + 0.5
                                * (std::f64::consts::TAU * x / 1.3).sin()
                                * (0.3 + 0.7 * ((c / side) as f64 * 0.7).cos().abs())
                        })
                        .collect()
                })
                .collect();
            let seconds = 4usize;
            // The first window fills before it is timed.
            let warm = (window_s * 1000.0) as usize;
            for i in 0..warm {
                stream.push(None, &pattern[i % 100]).unwrap();
            }
            let start = Instant::now();
            let mut bins = 0;
            for i in 0..seconds * 1000 {
                bins += stream.push(None, &pattern[i % 100]).unwrap().len();
            }
            let wall = start.elapsed().as_secs_f64();
            let factor = seconds as f64 / wall;
            println!(
                "  {side}x{side} ({cells} taxels), window {window_s} s: {seconds} s of stream in {wall:.2} s ({bins} bins), real-time factor {factor:.2}, {:.0} taxels in real time; {} spike times held",
                cells as f64 * factor,
                stream.retained_spikes()
            );
        }
    }
}

/// A `/proc/self/status` field in MiB (Linux).
fn status_mib(field: &str) -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find(|l| l.starts_with(field))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|kb| kb.parse::<f64>().ok())
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

fn memory() {
    let side = 100;
    let cells = side * side;
    let model = large_model(side);
    let mut params = StreamParams::for_model(&model);
    params.window_ms = 10_000;
    let mut stream = StreamClassifier::new(model, params).unwrap();
    // 97 frames (a prime) cycle, so the pattern does not repeat bin for bin.
    let pattern: Vec<Vec<f64>> = (0..97)
        .map(|t| {
            (0..cells)
                .map(|c| {
                    let x = (c % side) as f64 + 0.01 * t as f64;
                    0.5 + 0.5 * (std::f64::consts::TAU * x / 1.3).sin()
                })
                .collect()
        })
        .collect();
    println!(
        "memory, {side}x{side} taxels, window 10 s, one episode of 10 minutes at 1 kHz; before: RSS {:.1} MiB",
        status_mib("VmRSS:")
    );
    for minute in 1..=10 {
        for i in 0..60_000 {
            stream.push(None, &pattern[i % pattern.len()]).unwrap();
        }
        println!(
            "  after {minute:2} min: RSS {:.1} MiB, peak {:.1} MiB, {} spike times held",
            status_mib("VmRSS:"),
            status_mib("VmHWM:"),
            stream.retained_spikes()
        );
    }
}
