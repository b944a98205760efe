//! The extensions beyond the paper: FA-I encoding, per-population features, all-taxels,
//! travelled-distance statistics, multi-scale 3D-GLCM and the full Haralick set.

use neurotex::encode::{encode, encode_fa, FaParams, IzhikevichParams, SpikeTrains, V_PEAK};
use neurotex::features::{distance_stats, haralick_full, spike_stats};
use neurotex::pipeline::{
    Encoded, Encoding, FeatureExtractor, FeatureParams, HaralickSet, Method, PipelineParams,
};
use neurotex::recording::Meta;
use neurotex::values::Grid;

/// Izhikevich's own scheme for one neuron
/// (docs/decisions/0001-izhikevich-rs-neurons-dt-1ms.md), step by step, with a per-step
/// input current.
fn slow_izhikevich(p: IzhikevichParams, current: &[f64]) -> Vec<u32> {
    let (mut v, mut u) = (p.c, p.b * p.c);
    let mut spikes = Vec::new();
    for (t, &i) in current.iter().enumerate() {
        if v >= V_PEAK {
            spikes.push(t as u32);
            v = p.c;
            u += p.d;
        }
        for _ in 0..2 {
            v += 0.5 * (0.04 * (v * v) + 5.0 * v + 140.0 - u + i);
        }
        u += p.a * (p.b * v - u);
    }
    spikes
}

#[test]
fn a_ramp_drives_fa_neurons_with_a_constant_current() {
    // x(t) = t / 1024 (exact in binary): |dx/dt| = 1/1024 per ms from the second step on,
    // so with G_fa = 8192 the neuron sees I = 8 (the first step has no previous sample).
    let samples: Vec<f64> = (0..3000).map(|t| f64::from(t) / 1024.0).collect();
    let neuron = IzhikevichParams::default();
    let fa = FaParams { gain: 8192.0 };
    let trains = encode_fa(&samples, 1, 1, &[true], neuron, fa).unwrap();
    let mut current = vec![8.0; 3000];
    current[0] = 0.0;
    let expected = slow_izhikevich(neuron, &current);
    assert_eq!(trains.train(0), &expected[..]);
    // RS at I = 8 fires tonically: dozens of spikes in 3 s.
    assert!(expected.len() > 20, "{}", expected.len());
}

#[test]
fn a_constant_signal_gives_no_fa_spikes_but_sa_spikes() {
    let samples = vec![0.8; 2000 * 4];
    let neuron = IzhikevichParams::default();
    let fa = encode_fa(&samples, 2, 2, &[true; 4], neuron, FaParams::default()).unwrap();
    assert_eq!(fa.total_spikes(), 0);
    let sa = encode(&samples, 2, 2, &[true; 4], neuron).unwrap();
    assert!(sa.total_spikes() > 0);
}

#[test]
fn fa_gain_rule_is_checked() {
    let bad = FaParams { gain: -1.0 };
    let err = encode_fa(&[0.0; 4], 1, 1, &[true], IzhikevichParams::default(), bad);
    assert_eq!(err.unwrap_err().name, "fa-gain");
}

/// Spike trains on a 2x2 grid from a seeded pattern, 1000 ms long.
fn trains(seed: u32) -> SpikeTrains {
    let lists: Vec<Vec<u32>> = (0..4)
        .map(|c| {
            (0..1000)
                .filter(|t| (t * (c + 3) + seed * 7).is_multiple_of(37 + 5 * c))
                .collect()
        })
        .collect();
    SpikeTrains::from_lists(&lists, 2, 2, &[true; 4], 1000)
}

fn encoded(speed: Option<f64>, fa: bool) -> Encoded {
    Encoded {
        meta: Meta {
            file: "x.npy".into(),
            speed_mm_s: speed,
            ..Meta::default()
        },
        spikes: trains(1),
        fa: fa.then(|| trains(2)),
        resampled: false,
        flat: false,
        constant: false,
        from_events: false,
    }
}

fn extractor(params: PipelineParams) -> FeatureExtractor {
    FeatureExtractor::new(&params, &Grid::full(2, 2).unwrap()).unwrap()
}

#[test]
fn sa_fa_rows_are_each_populations_row_with_prefixed_names() {
    let both = extractor(PipelineParams {
        encoding: Encoding::SaFa,
        ..PipelineParams::default()
    });
    let one = extractor(PipelineParams::default());
    for method in Method::ALL {
        let names = both.names(method);
        let row = both.row(&encoded(Some(10.0), true), method).unwrap();
        let single = one.names(method);
        assert_eq!(names.len(), 2 * single.len(), "{}", method.name());
        assert_eq!(row.len(), names.len());
        assert_eq!(names[0], format!("sa_{}", single[0]));
        assert_eq!(names[single.len()], format!("fa_{}", single[0]));
        let sa = one.row(&encoded(Some(10.0), false), method).unwrap();
        let fa_only = Encoded {
            spikes: trains(2),
            ..encoded(Some(10.0), false)
        };
        let fa = one.row(&fa_only, method).unwrap();
        assert_eq!(row, [sa, fa].concat(), "{}", method.name());
    }
    assert_eq!(
        one.names(Method::AllTaxels)[..3],
        ["r0c0_msr", "r0c0_cv_isi", "r0c0_fano"]
    );
    assert_eq!(one.names(Method::AllTaxels), one.names(Method::Taxel));
    let missing = both.row(&encoded(Some(10.0), false), Method::Glcm3d);
    assert!(missing.unwrap_err().to_string().contains("two populations"));
}

#[test]
fn multi_scale_is_the_concatenation_of_single_scale_runs() {
    for haralick in [HaralickSet::Paper, HaralickSet::Full] {
        let features = FeatureParams {
            haralick,
            bin_widths_ms: vec![50, 100, 250],
            ..FeatureParams::default()
        };
        let multi = extractor(PipelineParams {
            features: features.clone(),
            ..PipelineParams::default()
        });
        let e = encoded(None, false);
        let mut expected = Vec::new();
        for width in [50, 100, 250] {
            let mut params = PipelineParams {
                features: features.clone(),
                ..PipelineParams::default()
            };
            params.volume.bin_ms = width;
            expected.extend(extractor(params).row(&e, Method::Glcm3d).unwrap());
        }
        assert_eq!(multi.row(&e, Method::Glcm3dMulti).unwrap(), expected);
        assert_eq!(multi.names(Method::Glcm3dMulti).len(), expected.len());
    }
}

#[test]
fn distance_statistics_are_time_statistics_rescaled_by_speed() {
    // 400 ms at 20 mm/s is 8 mm: 4 spikes are 0.5 per mm (10 Hz / 20 mm/s). Windows of
    // 2 mm are 100 ms: counts 2, 1, 0, 1, mean 1, variance 0.5, Fano 0.5.
    let train = [10, 60, 110, 300];
    let per_mm = distance_stats(&train, 400, -20.0, 2.0);
    assert_eq!(per_mm.msr, 0.5);
    assert_eq!(per_mm.fano, 0.5);
    assert_eq!(per_mm.cv_isi, spike_stats(&train, 400, 100).cv_isi);
    // Through the extractor: at 10 mm/s a 2 mm window is the default 200 ms bin.
    let e = extractor(PipelineParams::default());
    let time = e
        .row(&encoded(Some(10.0), false), Method::AllTaxels)
        .unwrap();
    let distance = e
        .row(&encoded(Some(10.0), false), Method::AllTaxelsMm)
        .unwrap();
    for (k, (t, d)) in time.iter().zip(&distance).enumerate() {
        let expected = if k % 3 == 0 { t / 10.0 } else { *t };
        assert_eq!(*d, expected, "column {k}");
    }
    let err = e
        .row(&encoded(None, false), Method::AllTaxelsMm)
        .unwrap_err();
    assert!(err.to_string().contains("speed"), "{err}");
}

#[test]
fn the_spectrum_reads_the_whole_slide_or_a_travel_and_names_what_it_lacks() {
    use neurotex::features::{Spectrum, SpectrumParams};
    let whole = extractor(PipelineParams::default());
    let e = encoded(None, false);
    let row = whole.row(&e, Method::Spectrum).unwrap();
    let names = whole.names(Method::Spectrum);
    assert_eq!(row.len(), names.len());
    assert_eq!(names.len(), 4 * 14);
    assert_eq!(names[0], "r0c0_f1_2");
    // The whole slide: each taxel's train over its 1000 ms, by the spectrum itself.
    let spectrum = Spectrum::new(SpectrumParams {
        bins: 128,
        bands: 16,
    });
    let mut expected = Vec::new();
    for cell in 0..4 {
        spectrum.train(e.spikes.train(cell), 1000, &mut expected);
    }
    assert_eq!(row, expected);
    // 300 mm of travel at 500 mm/s: the first 600 ms of each train.
    let mut params = PipelineParams::default();
    params.features.travel_mm = 300.0;
    let travel = extractor(params);
    let row = travel
        .row(&encoded(Some(-500.0), false), Method::Spectrum)
        .unwrap();
    let mut expected = Vec::new();
    for cell in 0..4 {
        spectrum.train(e.spikes.train(cell), 600, &mut expected);
    }
    assert_eq!(row, expected);
    // A slide up to 1 % short of the travel (its stamps span one sample less) reads whole:
    // 300 mm at 297 mm/s is 1010 ms of a 1000 ms slide.
    let short = travel
        .row(&encoded(Some(297.0), false), Method::Spectrum)
        .unwrap();
    assert_eq!(short, whole.row(&e, Method::Spectrum).unwrap());
    // No speed, or a slide shorter than the travel: errors naming the file and option.
    let err = travel.row(&e, Method::Spectrum).unwrap_err().to_string();
    assert!(err.contains("x.npy") && err.contains("speed"), "{err}");
    let err = travel
        .row(&encoded(Some(100.0), false), Method::Spectrum)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("x.npy") && err.contains("100.00 mm") && err.contains("--travel-mm 300"),
        "{err}"
    );
}

#[test]
fn full_haralick_matches_mahotas() {
    let text = include_str!("data/haralick_full.json");
    let reference: serde_json::Value = serde_json::from_str(text).unwrap();
    for case in reference["cases"].as_array().unwrap() {
        let levels = case["levels"].as_u64().unwrap() as usize;
        let counts: Vec<f64> = case["counts"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c.as_f64().unwrap())
            .collect();
        let got = haralick_full(&counts, levels);
        for (k, want) in case["features"].as_array().unwrap().iter().enumerate() {
            let want = want.as_f64().unwrap();
            assert!(
                (got[k] - want).abs() <= 1e-10 * want.abs().max(1.0),
                "levels {levels} feature {k}: {} vs mahotas {want}",
                got[k]
            );
        }
    }
}

#[test]
fn full_haralick_of_an_empty_matrix_is_defined() {
    let out = haralick_full(&[0.0; 16], 4);
    assert!(out.iter().all(|v| v.is_finite()));
    assert_eq!(out[2], 1.0);
}

#[test]
fn model_files_without_the_new_fields_load_as_sa() {
    let mut value = serde_json::to_value(PipelineParams::default()).unwrap();
    let object = value.as_object_mut().unwrap();
    for key in ["encoding", "fa", "features"] {
        assert!(object.remove(key).is_some(), "{key}");
    }
    let params: PipelineParams = serde_json::from_value(value).unwrap();
    assert_eq!(params, PipelineParams::default());
    assert_eq!(params.encoding, Encoding::Sa);
}

#[test]
fn names_parse_back() {
    for method in Method::ALL {
        assert_eq!(method.name().parse::<Method>().unwrap(), method);
    }
    for encoding in [Encoding::Sa, Encoding::Fa, Encoding::SaFa] {
        assert_eq!(encoding.name().parse::<Encoding>().unwrap(), encoding);
        let json = serde_json::to_string(&encoding).unwrap();
        assert_eq!(json, format!("\"{}\"", encoding.name()));
    }
    let json = serde_json::to_string(&Method::AllTaxelsMm).unwrap();
    assert_eq!(json, "\"all-taxels-mm\"");
    assert!("bogus".parse::<Method>().is_err());
    assert_eq!("full".parse::<HaralickSet>().unwrap(), HaralickSet::Full);
}
