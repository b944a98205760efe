//! neurotex against values from established tools, stored in `tests/data/reference.json`
//! by `tests/reference/make_reference.py` (tool versions are recorded in the file's
//! `provenance`): scikit-image and pyradiomics for GLCM and Haralick features, scipy for
//! the Butterworth filter, scikit-learn for KNN, and a Python transcription of
//! Izhikevich's 2003 MATLAB listing for the encoder.

use neurotex::classify::cv::predict_out_of_fold;
use neurotex::classify::KnnParams;
use neurotex::encode::{Encoder, IzhikevichParams};
use neurotex::features::glcm::GlcmKind;
use neurotex::features::{haralick, GlcmParams, GlcmPlan};
use neurotex::signal::Butterworth2;
use serde_json::Value;

fn reference() -> Value {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/reference.json"
    ))
    .expect("reference.json is in the repository");
    serde_json::from_str(&text).expect("valid JSON")
}

fn f64s(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

fn ints(v: &Value) -> Vec<i64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_i64().unwrap())
        .collect()
}

/// Flattens a nested JSON array of integers in C order.
fn flat_ints(v: &Value) -> Vec<i64> {
    match v {
        Value::Array(items) => items.iter().flat_map(flat_ints).collect(),
        other => vec![other.as_i64().unwrap()],
    }
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + b.abs())
}

#[test]
fn glcm2d_matches_scikit_image_per_angle() {
    let r = reference();
    // skimage's angle θ pairs (r, c) with (r + round(sin θ), c + round(cos θ)), rows growing
    // downwards: angles 0, pi/4, pi/2, 3pi/4 are offsets (0, 1), (1, 1), (1, 0), (1, -1).
    // The paper's in-plane directions (table I, IDs 1-4) are (0, D), (-D, D), (-D, 0),
    // (-D, -D): the first equal, the other three the same pairs reversed (transposed).
    let skimage_dirs = [(0, 1, 0), (1, 1, 0), (1, 0, 0), (1, -1, 0)];
    for case in r["skimage_glcm2d"].as_array().unwrap() {
        let levels = case["levels"].as_u64().unwrap() as usize;
        let image = case["image"].as_array().unwrap();
        let (rows, cols) = (image.len(), image[0].as_array().unwrap().len());
        let q: Vec<u8> = flat_ints(&case["image"]).iter().map(|&v| v as u8).collect();
        let mut paper_sum = vec![0i64; levels * levels];
        for (a, &dir) in skimage_dirs.iter().enumerate() {
            let plan =
                GlcmPlan::from_offsets(rows, cols, &vec![true; rows * cols], levels, &[dir], false)
                    .unwrap();
            let mut counts = vec![0u32; levels * levels];
            plan.count(&q, 1, &mut counts);
            let expected = flat_ints(&case["counts"][a]);
            assert_eq!(
                counts.iter().map(|&c| c as i64).collect::<Vec<_>>(),
                expected,
                "angle {a}, {rows}x{cols}"
            );
            for i in 0..levels {
                for j in 0..levels {
                    let (ii, jj) = if a == 0 { (i, j) } else { (j, i) };
                    paper_sum[i * levels + j] += expected[ii * levels + jj];
                }
            }
            let h = haralick(&counts, levels);
            let props = &case["props"];
            assert!(close(
                h.contrast,
                props["contrast"][a].as_f64().unwrap(),
                1e-12
            ));
            assert!(close(
                h.correlation,
                props["correlation"][a].as_f64().unwrap(),
                1e-12
            ));
            assert!(close(h.asm, props["ASM"][a].as_f64().unwrap(), 1e-12));
        }
        // The planned 2D-GLCM at D = 1 sums the paper's four directions.
        let params = GlcmParams {
            distances: vec![1],
            symmetric: false,
        };
        let plan = GlcmPlan::new(
            rows,
            cols,
            &vec![true; rows * cols],
            levels,
            &params,
            GlcmKind::TwoD,
        )
        .unwrap();
        let mut counts = vec![0u32; levels * levels];
        plan.count(&q, 1, &mut counts);
        assert_eq!(
            counts.iter().map(|&c| c as i64).collect::<Vec<_>>(),
            paper_sum
        );
    }
}

#[test]
fn glcm3d_matches_pyradiomics_per_angle_and_features() {
    let r = reference();
    for case in r["pyradiomics_glcm3d"].as_array().unwrap() {
        let levels = case["levels"].as_u64().unwrap() as usize;
        let vol = case["volume"].as_array().unwrap();
        let rows = vol.len();
        let cols = vol[0].as_array().unwrap().len();
        let q: Vec<u8> = flat_ints(&case["binned"])
            .iter()
            .map(|&v| (v - 1) as u8)
            .collect();
        let bins = q.len() / (rows * cols);
        let mut sums = [0.0f64; 3];
        let angles = case["angles"].as_array().unwrap();
        assert_eq!(angles.len(), 13);
        for (k, angle) in angles.iter().enumerate() {
            let a = ints(angle);
            // pyradiomics counts (i at voxel, j at voxel + angle) in array index order
            // (axis0, axis1, axis2), here (row, col, time): its angle a is our offset +a.
            let offset = (a[0] as isize, a[1] as isize, a[2] as isize);
            let plan = GlcmPlan::from_offsets(
                rows,
                cols,
                &vec![true; rows * cols],
                levels,
                &[offset],
                false,
            )
            .unwrap();
            let mut counts = vec![0u32; levels * levels];
            plan.count(&q, bins, &mut counts);
            let expected = flat_ints(&case["counts"][k]);
            assert_eq!(
                counts.iter().map(|&c| c as i64).collect::<Vec<_>>(),
                expected,
                "angle {a:?}"
            );
            let h = haralick(&counts, levels);
            sums[0] += h.contrast;
            sums[1] += h.correlation;
            sums[2] += h.asm;
        }
        let f = &case["features_mean_over_angles"];
        let n = angles.len() as f64;
        assert!(close(sums[0] / n, f["Contrast"].as_f64().unwrap(), 1e-9));
        assert!(close(sums[1] / n, f["Correlation"].as_f64().unwrap(), 1e-9));
        assert!(close(sums[2] / n, f["JointEnergy"].as_f64().unwrap(), 1e-9));
    }
}

#[test]
fn butterworth_and_filtfilt_match_scipy() {
    let r = &reference()["scipy_filter"];
    for cutoff in [50, 120] {
        let f = Butterworth2::lowpass(1000.0, cutoff as f64).unwrap();
        for (mine, theirs) in f.b.iter().zip(f64s(&r[format!("b_{cutoff}")])) {
            assert!(close(*mine, theirs, 1e-12), "b {mine} vs {theirs}");
        }
        for (mine, theirs) in f.a.iter().zip(f64s(&r[format!("a_{cutoff}")])) {
            assert!(close(*mine, theirs, 1e-12), "a {mine} vs {theirs}");
        }
        let mut x = f64s(&r["x"]);
        f.filtfilt(&mut x, &mut Vec::new());
        for (i, (mine, theirs)) in x
            .iter()
            .zip(f64s(&r[format!("filtfilt_{cutoff}")]))
            .enumerate()
        {
            assert!(close(*mine, theirs, 1e-9), "sample {i}: {mine} vs {theirs}");
        }
    }
    let f = Butterworth2::lowpass(1000.0, 50.0).unwrap();
    let mut short = f64s(&r["short"]);
    f.filtfilt(&mut short, &mut Vec::new());
    for (mine, theirs) in short.iter().zip(f64s(&r["filtfilt_short"])) {
        assert!(close(*mine, theirs, 1e-9), "{mine} vs {theirs}");
    }
}

#[test]
fn knn_matches_scikit_learn_on_fixed_folds() {
    let r = &reference()["sklearn_knn"];
    let x: Vec<f64> = r["x"].as_array().unwrap().iter().flat_map(f64s).collect();
    let y: Vec<usize> = ints(&r["y"]).iter().map(|&v| v as usize).collect();
    let folds: Vec<usize> = ints(&r["folds"]).iter().map(|&v| v as usize).collect();
    let mut compared = 0;
    for case in r["cases"].as_array().unwrap() {
        let k = case["k"].as_u64().unwrap() as usize;
        let knn = KnnParams {
            k,
            standardize: true,
        }
        .check()
        .unwrap();
        let ours = predict_out_of_fold(&knn, &x, 3, &y, &folds, 5).unwrap();
        let theirs = ints(&case["predicted"]);
        let tied: Vec<bool> = case["vote_tie"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| b.as_bool().unwrap())
            .collect();
        // scikit-learn breaks vote ties by the lowest class index, neurotex by the nearest
        // neighbour: compare wherever the vote is not tied.
        for i in (0..y.len()).filter(|&i| !tied[i]) {
            assert_eq!(ours[i] as i64, theirs[i], "k = {k}, sample {i}");
            compared += 1;
        }
    }
    assert!(
        compared >= 200,
        "only {compared} of 240 predictions were untied"
    );
}

#[test]
fn encoder_spike_times_match_the_reference_scheme() {
    let r = reference();
    for case in r["izhikevich"].as_array().unwrap() {
        let current = f64s(&case["current"]);
        let expected: Vec<i64> = ints(&case["spikes"]);
        // gain 1 so the input is the current itself
        let params = IzhikevichParams::default().with_gain(1.0);
        let mut enc = Encoder::new(params, 1).unwrap();
        let mut raster = vec![0u8; current.len()];
        enc.run(&current, &mut raster);
        let spikes: Vec<i64> = raster
            .iter()
            .enumerate()
            .filter(|(_, &s)| s == 1)
            .map(|(t, _)| t as i64)
            .collect();
        assert_eq!(spikes, expected, "{}", case["name"]);
    }
}

#[test]
fn causal_filter_matches_scipy_lfilter_from_its_steady_state() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/causal_filter_reference.json"
    ))
    .expect("causal_filter_reference.json is in the repository");
    let r: Value = serde_json::from_str(&text).expect("valid JSON");
    for cutoff in [50, 120] {
        let f = Butterworth2::lowpass(1000.0, cutoff as f64).unwrap();
        let expected = f64s(&r[format!("lfilter_{cutoff}")]);
        let mut batch = f64s(&r["x"]);
        f.lfilter(&mut batch);
        // Sample by sample, as the stream runs it.
        let x = f64s(&r["x"]);
        let mut z = f.steady_state(x[0]);
        let online: Vec<f64> = x.iter().map(|&v| f.step(v, &mut z)).collect();
        for (i, ((b, o), e)) in batch.iter().zip(&online).zip(&expected).enumerate() {
            assert!(
                close(*b, *e, 1e-12),
                "{cutoff} Hz, sample {i}: {b} vs scipy {e}"
            );
            assert_eq!(b.to_bits(), o.to_bits(), "batch and online differ at {i}");
        }
    }
}
