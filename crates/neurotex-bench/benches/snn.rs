//! The spiking classifier: one step of a running network (16 inputs, 128 hidden LIF
//! neurons, 8 classes; the stream's cost per 1 ms step) and at twice and four times the
//! inputs x hidden, to show the step grows linearly; and one training epoch (forward and
//! backward through time, Adam) over 55 recordings of 32 inputs x 1200 steps at 10 ms
//! (12 s slides, about one FabricSlide velocity's training folds; 45 trained, 10 held out
//! for validation) with one epoch, so every iteration is one whole epoch, with the neurons'
//! shared decays, with each neuron's own trained, with adaptive thresholds and with
//! learnable synaptic delays.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use neurotex::snn::{fit, Network, Readout, Reset, SnnParams, SpikeInput};

fn xorshift(mut state: u64) -> impl FnMut() -> f64 {
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state % 1_000_000) as f64 / 1_000_000.0
    }
}

fn network(inputs: usize, hidden: usize, classes: usize) -> Network {
    let mut next = xorshift(0x2545_f491_4f6c_dd1d);
    let mut w = |n: usize, s: f64| -> Vec<f64> { (0..n).map(|_| (next() - 0.5) * s).collect() };
    Network {
        inputs,
        hidden,
        classes,
        dt_ms: 1,
        tau_syn_ms: 5.0,
        tau_mem_ms: 10.0,
        tau_out_ms: 10.0,
        readout: Readout::Mean,
        reset: Reset::Zero,
        w_in: w(inputs * hidden, 1.0),
        b_in: w(hidden, 0.2),
        w_out: w(hidden * classes, 1.0),
        b_out: w(classes, 0.1),
        w_rec: Vec::new(),
        target: Default::default(),
        alpha: Vec::new(),
        beta: Vec::new(),
        travel_mm_s: None,
        adaptation: None,
        delays: Vec::new(),
    }
}

/// `n` recordings of `inputs` x `steps`, class `i % classes`: each class drives its own
/// quarter of the inputs harder.
fn recordings(
    n: usize,
    inputs: usize,
    steps: usize,
    classes: usize,
) -> (Vec<SpikeInput>, Vec<usize>) {
    let mut next = xorshift(0x9e37_79b9_7f4a_7c15);
    let y: Vec<usize> = (0..n).map(|i| i % classes).collect();
    let x = y
        .iter()
        .map(|&c| {
            let mut events = Vec::new();
            for t in 0..steps as u32 {
                for i in 0..inputs as u32 {
                    let rate = if (i as usize * classes / inputs) == c {
                        0.08
                    } else {
                        0.02
                    };
                    if next() < rate {
                        events.push((t, i));
                    }
                }
            }
            SpikeInput::from_events(inputs, steps, &events)
        })
        .collect();
    (x, y)
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("snn/step");
    for (inputs, hidden) in [(16, 128), (32, 128), (16, 512)] {
        let net = network(inputs, hidden, 8);
        // Two of the inputs spike in the step (16 taxels at about 100 Hz each, 1 ms steps).
        let spiked = [3u32, 11];
        let mut run = net.runner();
        group.bench_function(
            BenchmarkId::from_parameter(format!("{inputs}x{hidden}")),
            |b| {
                b.iter(|| {
                    run.step(&spiked);
                    run.steps()
                })
            },
        );
    }
    group.finish();
    let (x, y) = recordings(55, 32, 1200, 5);
    let refs: Vec<&SpikeInput> = x.iter().collect();
    let params = SnnParams {
        epochs: 1,
        patience: 2,
        ..SnnParams::default()
    };
    c.bench_function("snn/train_epoch/55x32x1200", |b| {
        b.iter(|| fit(&params, &refs, &y, 5).unwrap().1.epochs)
    });
    // The same epoch with each hidden neuron's decays trained beside the weights.
    let decays = SnnParams {
        train_decays: true,
        ..params
    };
    c.bench_function("snn/train_epoch/55x32x1200/decays", |b| {
        b.iter(|| fit(&decays, &refs, &y, 5).unwrap().1.epochs)
    });
    // The same epoch with adaptive thresholds (`--snn-adapt-ms 200`).
    let adaptive = SnnParams {
        adapt_ms: Some(200.0),
        ..params
    };
    c.bench_function("snn/train_epoch/55x32x1200/adapt", |b| {
        b.iter(|| fit(&adaptive, &refs, &y, 5).unwrap().1.epochs)
    });
    // The same epoch with learnable synaptic delays of up to 250 ms (`--snn-delay-ms 250`,
    // 25 steps).
    let delayed = SnnParams {
        delay_ms: Some(250.0),
        ..params
    };
    c.bench_function("snn/train_epoch/55x32x1200/delays", |b| {
        b.iter(|| fit(&delayed, &refs, &y, 5).unwrap().1.epochs)
    });
    // What a fit in steps of travel (`--snn-travel`) adds before it trains: the same
    // recordings' 12 s in 1 ms steps (20-80 Hz an input), rebinned to steps of 15 ms (10 ms
    // at a reference speed 1.5 times theirs).
    let (fine, _) = recordings(55, 32, 12_000, 5);
    c.bench_function("snn/rebin/55x32x12000", |b| {
        b.iter(|| fine.iter().map(|x| x.rebin(15.0).steps()).sum::<usize>())
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = bench
}
criterion_main!(benches);
