//! The stream classifier against its offline twin: a recording fed frame by frame (at
//! 1 kHz, at another fixed rate, or with irregular time stamps) gives exactly the
//! decisions `causal::episode_decisions` computes from the whole recording; bad frames are
//! skipped without changing them; memory stays within the window; onset episodes.

use crate::support;

use neurotex::analysis::{Columns, FeatureTable};
use neurotex::causal::{
    calibrate_conditioning, episode_decisions, spiking_episode_decisions, DecisionRule, Episode,
    EpisodeEnd,
};
use neurotex::classify::{ClassifierChoice, ForestParams, KnnParams};
use neurotex::model::{Model, Provenance};
use neurotex::pipeline::{Encoded, Encoding, Method, Pipeline, PipelineParams};
use neurotex::recording::{Baseline, Phase, Recording, TimeUnit};
use neurotex::sim::{design, simulate_trial, RigParams, Texture};
use neurotex::snn::SnnParams;
use neurotex::spiking_model::SpikingModel;
use neurotex::stream::{BadFrame, EpisodeRule, Event, StreamClassifier, StreamError, StreamParams};
use support::XorShift;

/// Short simulated slides (2 s) of three textures at 20 mm/s.
fn recordings() -> Vec<Recording> {
    let rig = RigParams {
        hold_s: 0.3,
        slide_mm: 40.0,
        ..RigParams::default()
    };
    let trials = design(&[Texture::Ft1, Texture::Sb, Texture::Stf], &[20.0], 5);
    trials
        .iter()
        .map(|t| simulate_trial(&rig, t, 11).unwrap())
        .collect()
}

/// The causal pipeline with `encoding` calibrated on `train` (conditioning fixed on them,
/// labels unused), their spikes, and what a model keeps of them.
fn causal_training(
    train: &[Recording],
    encoding: Encoding,
) -> (PipelineParams, Vec<Encoded>, Provenance) {
    let mut params = PipelineParams {
        encoding,
        ..PipelineParams::default()
    };
    let load = |i: usize| Ok(train[i].clone());
    let indices: Vec<usize> = (0..train.len()).collect();
    let calibration = calibrate_conditioning(&params, &load, &indices, Baseline::Min).unwrap();
    params.preprocess.causal = Some(calibration.conditioning);
    let pipeline = Pipeline::new(params.clone()).unwrap();
    let encoded: Vec<_> = train
        .iter()
        .map(|r| pipeline.encode(r, Baseline::Min).unwrap())
        .collect();
    let provenance = Provenance {
        fingerprint: "test".into(),
        baseline: Baseline::Min,
        speeds: None,
        gain_calibration: None,
        median_duration_ms: Some(calibration.median_duration_ms),
        layout: None,
    };
    (params, encoded, provenance)
}

/// A causal model trained on `train` (conditioning fixed on them, labels unused).
fn causal_model(
    train: &[Recording],
    encoding: Encoding,
    method: Method,
    classifier: ClassifierChoice,
) -> Model {
    let (params, encoded, provenance) = causal_training(train, encoding);
    let pipeline = Pipeline::new(params.clone()).unwrap();
    let extractor = pipeline.extractor(&train[0].layout_grid()).unwrap();
    let table = FeatureTable::build(&encoded, &extractor, method).unwrap();
    Model::train(&params, &table, Columns::All, classifier, provenance).unwrap()
}

/// The paper's method (SA, 3D-GLCM, KNN) as a causal model trained on `train`.
fn paper_model(train: &[Recording]) -> Model {
    let knn = ClassifierChoice::Knn(KnnParams::default());
    causal_model(train, Encoding::Sa, Method::Glcm3d, knn)
}

trait LayoutGrid {
    fn layout_grid(&self) -> neurotex::Grid;
}

impl LayoutGrid for Recording {
    fn layout_grid(&self) -> neurotex::Grid {
        let l = &self.layout;
        neurotex::Grid::masked(l.rows, l.cols, l.present.clone()).unwrap()
    }
}

/// The sliding phase of a simulated recording as a recording of its own (what a sensor
/// streams during the slide).
fn slide_only(rec: &Recording) -> Recording {
    let phases = rec.phases.as_ref().unwrap();
    let lo = phases.iter().position(|&p| p == Phase::Slide).unwrap();
    let hi = phases.iter().rposition(|&p| p == Phase::Slide).unwrap() + 1;
    let cells = rec.layout.cells();
    let mut meta = rec.meta.clone();
    (meta.slide_start_s, meta.slide_end_s) = (None, None);
    Recording {
        samples: rec.samples[lo * cells..hi * cells].to_vec(),
        phases: None,
        meta,
        ..rec.clone()
    }
}

/// Every event a stream reports for `frames` (`(stamp, values)`), then its end.
fn stream_events(stream: &mut StreamClassifier, frames: &[(Option<f64>, Vec<f64>)]) -> Vec<Event> {
    let mut events = Vec::new();
    for (t, values) in frames {
        match stream.push(*t, values) {
            Ok(e) => events.extend_from_slice(e),
            Err(StreamError::Bad(_)) => {}
            Err(e) => panic!("{e}"),
        }
    }
    events.extend_from_slice(stream.finish().unwrap());
    events
}

/// The offline twin's decisions as the stream's events.
fn offline_events(episode: Episode) -> Vec<Event> {
    let mut events: Vec<Event> = episode.bins.into_iter().map(Event::Bin).collect();
    events.push(Event::End(episode.summary));
    events
}

/// A recording's frames: one value per taxel, with its stamp when it has stamps.
fn frames_of(rec: &Recording) -> Vec<(Option<f64>, Vec<f64>)> {
    let cells = rec.layout.cells();
    rec.samples
        .chunks_exact(cells)
        .enumerate()
        .map(|(i, frame)| {
            let values = (0..cells)
                .filter(|&c| rec.layout.present[c])
                .map(|c| frame[c])
                .collect();
            (rec.times_s.as_ref().map(|t| t[i]), values)
        })
        .collect()
}

/// `rec` taken at irregular instants about `mean_ms` apart (stamped), as a slow sensor
/// logs it: each kept frame is a sample of the 1 kHz recording.
fn irregular(rec: &Recording, mean_ms: u64, seed: u64) -> Recording {
    let cells = rec.layout.cells();
    let mut rng = XorShift::new(seed);
    let (mut keep, mut i) = (Vec::new(), 0usize);
    while i < rec.len() {
        keep.push(i);
        i += 1 + (rng.below(2 * mean_ms) as usize);
    }
    Recording {
        samples: keep
            .iter()
            .flat_map(|&i| rec.samples[i * cells..(i + 1) * cells].to_vec())
            .collect(),
        // Stamps in s from an arbitrary origin, as a host clock gives them.
        times_s: Some(keep.iter().map(|&i| 1234.5 + i as f64 / 1000.0).collect()),
        fs: 1000.0 / mean_ms as f64,
        ..rec.clone()
    }
}

fn params(model: &Model) -> StreamParams {
    StreamParams::for_model(model)
}

#[test]
fn a_stream_at_1_khz_decides_as_the_offline_twin() {
    let recs = recordings();
    let model = paper_model(&recs);
    let p = params(&model);
    for rec in recs.iter().step_by(4) {
        let offline = model.encode(rec).unwrap();
        let expected = episode_decisions(&model, &offline, p.window_ms, p.rule).unwrap();
        assert!(expected.bins.len() >= 5, "a slide of several bins");
        let mut stream = StreamClassifier::new(model.clone(), p.clone()).unwrap();
        let got = stream_events(&mut stream, &frames_of(&slide_only(rec)));
        assert_eq!(got, offline_events(expected), "{}", rec.meta.file);
    }
}

#[test]
fn a_sliding_3d_glcm_window_decides_as_the_offline_twin() {
    // The stream keeps a 3D-GLCM model's co-occurrence counts bin by bin as the window
    // slides; offline, each window's volume is counted afresh.
    let recs = recordings();
    let model = causal_model(
        &recs,
        Encoding::SaFa,
        Method::Glcm3d,
        ClassifierChoice::Knn(KnnParams::default()),
    );
    let mut p = params(&model);
    p.window_ms = 600;
    for rec in recs.iter().step_by(3) {
        let offline = model.encode(rec).unwrap();
        let expected = episode_decisions(&model, &offline, p.window_ms, p.rule).unwrap();
        assert!(
            expected.bins.len() >= 6,
            "a window that slides several bins"
        );
        let mut stream = StreamClassifier::new(model.clone(), p.clone()).unwrap();
        let got = stream_events(&mut stream, &frames_of(&slide_only(rec)));
        assert_eq!(got, offline_events(expected), "{}", rec.meta.file);
    }
}

#[test]
fn irregular_stamps_and_other_rates_resample_as_offline() {
    let recs = recordings();
    let model = causal_model(
        &recs,
        Encoding::SaFa,
        Method::AllTaxels,
        ClassifierChoice::Forest(ForestParams {
            trees: 20,
            ..ForestParams::default()
        }),
    );
    let mut p = params(&model);
    // A window shorter than the slide, so that it slides.
    p.window_ms = 1000;
    for (k, rec) in recs.iter().step_by(5).enumerate() {
        // Stamped frames about 28 ms apart (FabricSlide's 35.7 Hz), irregular.
        let slow = irregular(&slide_only(rec), 28, k as u64 + 1);
        let expected =
            episode_decisions(&model, &model.encode(&slow).unwrap(), p.window_ms, p.rule).unwrap();
        let mut stream = StreamClassifier::new(model.clone(), p.clone()).unwrap();
        let got = stream_events(&mut stream, &frames_of(&slow));
        assert_eq!(got, offline_events(expected), "stamped, {}", rec.meta.file);

        // The same frames without stamps at a fixed 250 Hz.
        let mut fixed = slow.clone();
        fixed.times_s = None;
        fixed.fs = 250.0;
        let expected =
            episode_decisions(&model, &model.encode(&fixed).unwrap(), p.window_ms, p.rule).unwrap();
        let mut stream = StreamClassifier::new(
            model.clone(),
            StreamParams {
                fs: 250.0,
                ..p.clone()
            },
        )
        .unwrap();
        let got = stream_events(&mut stream, &frames_of(&fixed));
        assert_eq!(got, offline_events(expected), "250 Hz, {}", rec.meta.file);
    }
}

#[test]
fn bad_frames_are_counted_skipped_and_change_nothing() {
    let recs = recordings();
    let model = paper_model(&recs);
    let p = params(&model);
    let slow = irregular(&slide_only(&recs[2]), 10, 7);
    let clean = frames_of(&slow);
    let mut stream = StreamClassifier::new(model.clone(), p.clone()).unwrap();
    let expected = stream_events(&mut stream, &clean);

    let mut hostile = Vec::new();
    let mut kinds = Vec::new();
    for (i, (t, values)) in clean.iter().enumerate() {
        hostile.push((*t, values.clone()));
        if i % 50 == 7 {
            let mut nan = values.clone();
            nan[3] = f64::NAN;
            hostile.push((t.map(|t| t + 1e-4), nan));
            hostile.push((*t, values.clone())); // a repeated stamp
            hostile.push((t.map(|t| t + 1e-4), values[..5].to_vec())); // too few values
            hostile.push((Some(f64::INFINITY), values.clone()));
        }
    }
    let mut stream = StreamClassifier::new(model, p).unwrap();
    let mut got = Vec::new();
    for (t, values) in &hostile {
        match stream.push(*t, values) {
            Ok(e) => got.extend_from_slice(e),
            Err(StreamError::Bad(bad)) => kinds.push(bad),
            Err(e) => panic!("{e}"),
        }
    }
    got.extend_from_slice(stream.finish().unwrap());
    assert_eq!(got, expected);
    let bad = hostile.len() - clean.len();
    assert_eq!(stream.bad_frames() as usize, bad);
    assert_eq!(kinds.len(), bad);
    assert!(kinds
        .iter()
        .any(|k| matches!(k, BadFrame::NotFinite { index: 4, .. })));
    assert!(kinds.iter().any(|k| matches!(k, BadFrame::Stamp { .. })));
    assert!(kinds.iter().any(|k| matches!(
        k,
        BadFrame::FieldCount {
            expected: 16,
            got: 5
        }
    )));
}

#[test]
fn a_long_stream_keeps_only_its_window() {
    let recs = recordings();
    let model = causal_model(
        &recs,
        Encoding::Sa,
        Method::AllTaxels,
        ClassifierChoice::Knn(KnnParams::default()),
    );
    let mut p = params(&model);
    p.window_ms = 600;
    let frames = frames_of(&slide_only(&recs[0]));
    let mut stream = StreamClassifier::new(model, p).unwrap();
    let mut most = 0;
    // The slide over and over: 20 times its length in one episode.
    for _ in 0..20 {
        for (_, values) in &frames {
            stream.push(None, values).unwrap();
            most = most.max(stream.retained_spikes());
        }
    }
    // At most the window plus one bin of spikes is held: 16 neurons below 1 kHz.
    assert!(most > 0);
    assert!(most <= 16 * 800, "{most} spike times held");
}

#[test]
fn onset_episodes_start_at_contact_and_end_at_rest() {
    let recs = recordings();
    let model = paper_model(&recs);
    let c = model.causal().unwrap().clone();
    let rest: Vec<f64> = (0..16).map(|cell| c.offsets[cell]).collect();
    let slide = frames_of(&slide_only(&recs[1]));
    let mut p = params(&model);
    p.episodes = EpisodeRule::Onset {
        level: 0.1,
        rest_ms: 300,
    };
    let mut stream = StreamClassifier::new(model.clone(), p.clone()).unwrap();
    let mut frames: Vec<(Option<f64>, Vec<f64>)> = Vec::new();
    for _ in 0..2 {
        frames.extend(std::iter::repeat_n((None, rest.clone()), 1000));
        frames.extend(slide.iter().cloned());
    }
    frames.extend(std::iter::repeat_n((None, rest.clone()), 1000));
    let events = stream_events(&mut stream, &frames);
    let ends: Vec<_> = events
        .iter()
        .filter_map(|e| match e {
            Event::End(s) => Some(s),
            _ => None,
        })
        .collect();
    assert_eq!(ends.len(), 2, "two contacts, two episodes");
    for end in &ends {
        assert_eq!(end.ended_by, EpisodeEnd::Rest);
        // The episode holds the slide from its onset and the rest that ended it.
        let slide_s = slide.len() as f64 / 1000.0;
        assert!(
            end.duration_s > 0.3 && end.duration_s <= slide_s + 0.31,
            "{}",
            end.duration_s
        );
    }
    assert_eq!(ends[0], ends[1], "the same contact twice, the same episode");
    assert!(!stream.in_episode());
}

#[test]
fn an_offline_model_cannot_stream() {
    let recs = recordings();
    let params = PipelineParams::default();
    let pipeline = Pipeline::new(params.clone()).unwrap();
    let encoded: Vec<_> = recs
        .iter()
        .map(|r| pipeline.encode(r, Baseline::None).unwrap())
        .collect();
    let extractor = pipeline.extractor(&recs[0].layout_grid()).unwrap();
    let table = FeatureTable::build(&encoded, &extractor, Method::Glcm3d).unwrap();
    let provenance = Provenance {
        fingerprint: "test".into(),
        baseline: Baseline::None,
        speeds: None,
        gain_calibration: None,
        median_duration_ms: None,
        layout: None,
    };
    let model = Model::train(
        &params,
        &table,
        Columns::All,
        ClassifierChoice::default(),
        provenance,
    )
    .unwrap();
    let err = StreamClassifier::new(model.clone(), StreamParams::for_model(&model)).unwrap_err();
    assert!(err.to_string().contains("--causal"), "{err}");
    let mut p = StreamParams::for_model(&model);
    p.rule = DecisionRule {
        share: 0.0,
        bins: 3,
    };
    assert!(StreamClassifier::new(model, p).is_err());
}

/// The stream's bad frames as well as its events.
fn stream_with_bad(
    stream: &mut StreamClassifier,
    frames: &[(Option<f64>, Vec<f64>)],
) -> (Vec<Event>, Vec<BadFrame>) {
    let (mut events, mut bad) = (Vec::new(), Vec::new());
    for (t, values) in frames {
        match stream.push(*t, values) {
            Ok(e) => events.extend_from_slice(e),
            Err(StreamError::Bad(b)) => bad.push(b),
            Err(e) => panic!("{e}"),
        }
    }
    events.extend_from_slice(stream.finish().unwrap());
    (events, bad)
}

#[test]
fn a_stamp_far_in_the_future_costs_its_own_frame_only() {
    let recs = recordings();
    let model = paper_model(&recs);
    let p = params(&model);
    let clean = frames_of(&irregular(&slide_only(&recs[2]), 10, 7));
    let expected = stream_events(
        &mut StreamClassifier::new(model.clone(), p.clone()).unwrap(),
        &clean,
    );
    // A bit flip in the exponent of one stamp: some 10^6 s ahead.
    let mut hostile = clean.clone();
    let (t, values) = clean[40].clone();
    hostile.insert(41, (t.map(|t| t * 1024.0), values));
    let mut stream = StreamClassifier::new(model, p).unwrap();
    let (got, bad) = stream_with_bad(&mut stream, &hostile);
    assert_eq!(got, expected);
    assert_eq!(stream.bad_frames(), 1);
    assert!(matches!(bad[..], [BadFrame::Jump { .. }]), "{bad:?}");
}

#[test]
fn a_clock_that_jumps_and_stays_starts_a_new_episode() {
    let recs = recordings();
    let model = paper_model(&recs);
    let p = params(&model);
    let frames = frames_of(&irregular(&slide_only(&recs[4]), 10, 3));
    // Back (a sensor whose clock restarts) and forward (a pause longer than the largest gap).
    for shift in [-1000.0, 100.0] {
        let moved: Vec<_> = frames
            .iter()
            .map(|(t, v)| (t.map(|t| t + shift), v.clone()))
            .collect();
        let mut both = frames.clone();
        both.extend(moved.iter().cloned());
        let mut stream = StreamClassifier::new(model.clone(), p.clone()).unwrap();
        let (got, bad) = stream_with_bad(&mut stream, &both);
        // The first frame on the new clock is skipped: it alone cannot tell a wrong stamp
        // from a jump; the second, following it, starts the new episode.
        assert_eq!(bad.len(), 1, "shift {shift}: {bad:?}");
        let mut first = stream_events(
            &mut StreamClassifier::new(model.clone(), p.clone()).unwrap(),
            &frames,
        );
        let Some(Event::End(end)) = first.last_mut() else {
            panic!("an end")
        };
        end.ended_by = EpisodeEnd::Gap;
        let second = stream_events(
            &mut StreamClassifier::new(model.clone(), p.clone()).unwrap(),
            &moved[1..],
        );
        assert_eq!(got, [first, second].concat(), "shift {shift}");
    }
}

#[test]
fn stamps_beyond_the_exact_range_are_bad_frames() {
    let recs = recordings();
    let model = paper_model(&recs);
    let mut stream = StreamClassifier::new(model.clone(), params(&model)).unwrap();
    let values = frames_of(&recs[0])[0].1.clone();
    // 2^53 + 1 and 2^53 + 2 ms: as f64 they are one number, and a step of 2 ms.
    for ms in [9_007_199_254_740_993.0_f64, 9_007_199_254_740_994.0] {
        match stream.push(Some(ms / 1000.0), &values) {
            Err(StreamError::Bad(BadFrame::StampRange { .. })) => {}
            other => panic!("{other:?}"),
        }
    }
    // An ordinary host clock in s stays in range.
    assert!(stream.push(Some(1.7e9), &values).is_ok());
    assert!(stream.push(Some(1.7e9 + 0.001), &values).is_ok());
    assert_eq!(stream.bad_frames(), 2);
}

#[test]
fn the_largest_gap_and_so_the_work_per_frame_are_bounded() {
    let recs = recordings();
    let model = paper_model(&recs);
    let mut p = params(&model);
    p.max_gap_s = 3600.0;
    let err = StreamClassifier::new(model.clone(), p.clone()).unwrap_err();
    assert!(
        matches!(err, neurotex::Error::Param(ref e) if e.name == "max-gap"),
        "{err}"
    );
    p.max_gap_s = neurotex::stream::MAX_GAP_S;
    let mut stream = StreamClassifier::new(model.clone(), p).unwrap();
    let values = frames_of(&recs[0])[0].1.clone();
    stream.push(Some(0.0), &values).unwrap();
    // A frame at the largest gap completes at most that gap's bins.
    let events = stream
        .push(Some(neurotex::stream::MAX_GAP_S), &values)
        .unwrap();
    assert_eq!(
        events.len(),
        (neurotex::stream::MAX_GAP_S * 1000.0) as usize / 200
    );
}

#[test]
fn frames_stamped_on_the_1_ms_grid_give_the_spikes_of_unstamped_frames_at_1_khz() {
    let recs = recordings();
    let model = paper_model(&recs);
    let p = params(&model);
    for rec in recs.iter().step_by(4) {
        let frames = frames_of(&slide_only(rec));
        let mut plain = StreamClassifier::new(model.clone(), p.clone()).unwrap();
        let expected = stream_events(&mut plain, &frames);
        // Stamped in ms, from an epoch (a host clock) and from 0.
        for origin in [1_700_000_000_000.0, 0.0] {
            let mut stamped = StreamClassifier::new(model.clone(), p.clone()).unwrap();
            let mut events = Vec::new();
            for (i, (_, values)) in frames.iter().enumerate() {
                let t = origin + i as f64;
                let e = stamped
                    .push_in(Some(t), TimeUnit::Milliseconds, values)
                    .unwrap();
                events.extend_from_slice(e);
            }
            events.extend_from_slice(stamped.finish().unwrap());
            assert_eq!(
                events, expected,
                "stamped from {origin} ms, {}",
                rec.meta.file
            );
        }
    }
}

/// A spiking network trained (briefly: the weights need not classify well) on the spike
/// trains of `train`, causally conditioned, with time steps of `dt_ms`.
fn causal_network(train: &[Recording], dt_ms: u32) -> SpikingModel {
    let (params, encoded, provenance) = causal_training(train, Encoding::SaFa);
    let snn = SnnParams {
        hidden: 24,
        dt_ms,
        epochs: 4,
        ..SnnParams::default()
    };
    let grid = train[0].layout_grid();
    SpikingModel::train(&params, &encoded, &grid, (snn, &|| ()), provenance)
        .unwrap()
        .0
}

#[test]
fn a_spiking_network_streams_as_its_offline_twin_and_as_predict() {
    // The network runs step by step on the stream's spikes; offline it runs over the whole
    // causal encoding. Windows shorter and longer than the slide; a time step that divides
    // the 200 ms bins and one (30 ms) that does not, so that bins and the end fall inside a
    // time step; frames at 1 kHz and irregular stamped frames.
    let recs = recordings();
    for dt in [10, 30] {
        let model = causal_network(&recs, dt);
        let mut p = StreamParams::for_model(&model);
        for window_ms in [600, 3_600_000] {
            p.window_ms = window_ms;
            for (k, rec) in recs.iter().step_by(4).enumerate() {
                for (what, frames) in [
                    ("1 kHz", slide_only(rec)),
                    ("stamped", irregular(&slide_only(rec), 9, k as u64 + 1)),
                ] {
                    let offline = model.pipeline().encode(&frames, model.baseline()).unwrap();
                    let expected =
                        spiking_episode_decisions(&model, &offline, p.window_ms, p.rule).unwrap();
                    assert!(expected.bins.len() >= 5, "a slide of several bins");
                    let mut stream = StreamClassifier::new(model.clone(), p.clone()).unwrap();
                    let got = stream_events(&mut stream, &frames_of(&frames));
                    let file = &rec.meta.file;
                    assert_eq!(
                        got,
                        offline_events(expected.clone()),
                        "dt {dt}, {what}, {file}"
                    );
                    assert_eq!(stream.retained_spikes(), 0);
                    if window_ms > 10_000 {
                        // The whole slide in the window: the end's shares are predict's.
                        let whole = model.predict(std::slice::from_ref(&offline)).unwrap();
                        assert_eq!(expected.summary.shares.as_ref(), Some(&whole[0].shares));
                    }
                    // The running scores move as the slide goes on.
                    let first = &expected.bins[0].shares;
                    assert!(expected.bins.iter().any(|b| b.shares != *first), "{file}");
                }
            }
        }
    }
}
