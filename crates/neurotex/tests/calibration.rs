//! `--gain auto`: the chosen gain checked against a plain recomputation of its rule (the
//! median firing rate over every driven taxel x recording pair, by sorting) at the chosen
//! gain and at the next smaller 3-digit gain; with causal conditioning, on the causally
//! conditioned signal.

use neurotex::calibrate::{calibrate_gain, calibrate_pipeline, GainChoice};
use neurotex::encode::encode;
use neurotex::error::Result;
use neurotex::pipeline::{Pipeline, PipelineParams};
use neurotex::recording::{Baseline, Recording};
use neurotex::sim::{design, simulate_trial, RigParams, Texture};

fn recordings() -> Vec<Recording> {
    let rig = RigParams {
        hold_s: 0.5,
        slide_mm: 15.0,
        ..RigParams::default()
    };
    design(&[Texture::Ft1, Texture::Sb, Texture::Cp], &[10.0, 20.0], 2)
        .iter()
        .map(|t| simulate_trial(&rig, t, 3).unwrap())
        .collect()
}

/// The median rate over pairs whose conditioned input is not zero throughout, computed
/// directly: condition, encode at `gain`, count, sort.
fn median_rate(pipeline: &Pipeline, recs: &[Recording], gain: f64) -> f64 {
    let mut rates = Vec::new();
    for rec in recs {
        let cond = pipeline.condition(rec, Baseline::None).unwrap();
        let l = &rec.layout;
        let params = pipeline.params().encoder.with_gain(gain);
        let spikes = encode(&cond.samples, l.rows, l.cols, &l.present, params).unwrap();
        let seconds = cond.n_steps() as f64 / 1000.0;
        for c in 0..l.cells() {
            let driven = (0..cond.n_steps()).any(|t| cond.samples[t * l.cells() + c] != 0.0);
            if l.present[c] && driven {
                rates.push(spikes.train(c).len() as f64 / seconds);
            }
        }
    }
    rates.sort_by(f64::total_cmp);
    let n = rates.len();
    if n % 2 == 1 {
        rates[n / 2]
    } else {
        (rates[n / 2 - 1] + rates[n / 2]) / 2.0
    }
}

#[test]
fn chosen_gain_is_the_smallest_3_digit_gain_reaching_the_target() {
    let recs = recordings();
    let pipeline = Pipeline::new(PipelineParams::default()).unwrap();
    let load = |i: usize| -> Result<Recording> { Ok(recs[i].clone()) };
    let indices: Vec<usize> = (0..recs.len()).collect();
    for target in [5.0, 20.0, 60.0] {
        let c = calibrate_gain(&pipeline, &load, &indices, Baseline::None, target).unwrap();
        assert!(!c.clamped, "{target} Hz: {c:?}");
        assert_eq!(c.recordings, recs.len());
        let at = median_rate(&pipeline, &recs, c.gain);
        assert!(
            (at - c.median_hz).abs() < 1e-9,
            "{target}: {at} vs {}",
            c.median_hz
        );
        assert!(at >= target, "{target} Hz: median {at} at G = {}", c.gain);
        // One unit lower in the third significant digit falls short of the target. The
        // lower gain is formed as digits / scale, the double the calibration evaluates:
        // `gain - unit` can land one rounding step away, and spike counts change with that.
        let scale = 10f64.powi(2 - c.gain.log10().floor() as i32);
        let lower = ((c.gain * scale).round() - 1.0) / scale;
        let below = median_rate(&pipeline, &recs, lower);
        assert!(
            below < target,
            "{target} Hz: G = {lower}, one unit below {}, still gives {below}",
            c.gain
        );
    }
}

#[test]
fn training_recordings_only_and_flat_data_refused() {
    let recs = recordings();
    let pipeline = Pipeline::new(PipelineParams::default()).unwrap();
    // A loader that fails for any recording outside the training indices proves the
    // calibration reads nothing else.
    let train = [0usize, 2, 4];
    let load = |i: usize| -> Result<Recording> {
        assert!(
            train.contains(&i),
            "read recording {i} outside the training set"
        );
        Ok(recs[i].clone())
    };
    let c = calibrate_gain(&pipeline, &load, &train, Baseline::None, 20.0).unwrap();
    assert_eq!(c.recordings, 3);
    let mut flat = recs[0].clone();
    flat.samples.iter_mut().for_each(|x| *x = 0.0);
    let load_flat = |_: usize| -> Result<Recording> { Ok(flat.clone()) };
    let err = calibrate_gain(&pipeline, &load_flat, &[0], Baseline::None, 20.0).unwrap_err();
    assert!(err.to_string().contains("signal"), "{err}");
}

#[test]
fn causal_conditioning_is_fixed_first_and_the_gain_calibrated_on_it() {
    let recs = recordings();
    let train = [0usize, 1, 3, 5];
    let load = |i: usize| -> Result<Recording> {
        assert!(
            train.contains(&i),
            "read recording {i} outside the training set"
        );
        Ok(recs[i].clone())
    };
    let gain = GainChoice::Auto { target_hz: 20.0 };
    let params = PipelineParams::default();
    let c = calibrate_pipeline(params, true, gain, &load, &train, Baseline::None).unwrap();
    let causal = c.causal.as_ref().expect("causal conditioning fixed");
    assert_eq!(
        c.params.preprocess.causal.as_ref(),
        Some(&causal.conditioning)
    );
    let g = c.gain.as_ref().expect("gain calibrated");
    assert_eq!(c.params.encoder.gain, g.gain);
    // The gain's rule holds on the causally conditioned training recordings.
    let pipeline = Pipeline::new(c.params.clone()).unwrap();
    let used: Vec<Recording> = train.iter().map(|&i| recs[i].clone()).collect();
    let at = median_rate(&pipeline, &used, g.gain);
    assert!((at - g.median_hz).abs() < 1e-9, "{at} vs {}", g.median_hz);
    let scale = 10f64.powi(2 - g.gain.log10().floor() as i32);
    let lower = ((g.gain * scale).round() - 1.0) / scale;
    assert!(
        median_rate(&pipeline, &used, lower) < 20.0,
        "G = {lower} reaches 20 Hz too"
    );
    // Without either, the parameters come back as they went in.
    let fixed = GainChoice::Fixed(8.0);
    let plain = PipelineParams::default();
    let none = calibrate_pipeline(plain.clone(), false, fixed, &load, &train, Baseline::None);
    let none = none.unwrap();
    assert_eq!((none.params, none.gain, none.causal), (plain, None, None));
}
