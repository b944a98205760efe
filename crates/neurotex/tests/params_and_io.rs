//! One test per parameter rule, and the data model's readers on good and bad files.

use ndarray::{Array2, Array3};
use ndarray_npy::write_npy;
use std::path::Path;

use neurotex::classify::{CvParams, KnnParams};
use neurotex::encode::{FiringType, IzhikevichParams, PRESETS};
use neurotex::error::{DatasetError, ParamError};
use neurotex::features::{GlcmParams, VolumeParams};
use neurotex::recording::{
    one_grid, read_manifest, read_recording, write_layout, write_manifest, Baseline, ChannelMap,
    Dataset, LayoutFile, Meta, Selection, TimeUnit,
};
use neurotex::signal::PreprocessParams;
use neurotex::{Cell, Error, Grid, Speed};

fn broken_rule<T, E: std::fmt::Display>(r: Result<T, E>) -> String {
    r.err()
        .map(|e| e.to_string())
        .expect("the rule must be enforced")
}

#[test]
fn cutoff_must_be_off_or_below_nyquist() {
    for bad in [-1.0, 500.0, 800.0, f64::NAN] {
        let msg = broken_rule(
            PreprocessParams {
                cutoff_hz: bad,
                ..Default::default()
            }
            .check(),
        );
        assert!(msg.contains("cutoff"), "{msg}");
    }
    assert!(PreprocessParams {
        cutoff_hz: 0.0,
        ..Default::default()
    }
    .check()
    .is_ok());
}

#[test]
fn gain_must_be_positive_and_finite() {
    for bad in [0.0, -8.0, f64::INFINITY, f64::NAN] {
        assert!(broken_rule(IzhikevichParams::default().with_gain(bad).check()).contains("gain"));
    }
}

#[test]
fn recovery_scale_must_be_positive() {
    let p = IzhikevichParams {
        a: 0.0,
        ..Default::default()
    };
    assert!(broken_rule(p.check()).contains("`a`"));
}

#[test]
fn reset_must_be_below_peak() {
    let p = IzhikevichParams {
        c: 30.0,
        ..Default::default()
    };
    assert!(broken_rule(p.check()).contains("`c`"));
}

#[test]
fn presets_exist_and_unknown_is_none() {
    for name in ["RS", "IB", "CH", "FS", "LTS", "TC", "RZ", "rs"] {
        assert!(IzhikevichParams::preset(name).is_some(), "{name}");
    }
    assert!(IzhikevichParams::preset("XX").is_none());
}

#[test]
fn firing_types_are_the_presets_in_order() {
    for (t, preset) in FiringType::ALL.iter().zip(PRESETS) {
        assert_eq!(t.name(), preset.0);
        assert_eq!(t.to_string().parse::<FiringType>(), Ok(*t));
        assert_eq!(Some(t.params()), IzhikevichParams::preset(preset.0));
    }
    assert_eq!("lts".parse::<FiringType>(), Ok(FiringType::Lts));
    assert_eq!(FiringType::default().params(), IzhikevichParams::default());
    assert!(matches!(
        "XX".parse::<FiringType>(),
        Err(ParamError { name: "preset", .. })
    ));
}

#[test]
fn bins_must_be_at_least_one_ms() {
    assert!(broken_rule(
        VolumeParams {
            bin_ms: 0,
            ..Default::default()
        }
        .check()
    )
    .contains("bin-ms"));
}

#[test]
fn levels_must_be_between_2_and_256() {
    for bad in [0, 1, 257] {
        assert!(broken_rule(
            VolumeParams {
                levels: bad,
                ..Default::default()
            }
            .check()
        )
        .contains("levels"));
    }
}

#[test]
fn fixed_range_must_be_ordered() {
    let p = VolumeParams {
        range: Some((5.0, 5.0)),
        ..Default::default()
    };
    assert!(broken_rule(p.check()).contains("range"));
}

#[test]
fn distances_must_be_given_and_positive() {
    assert!(broken_rule(
        GlcmParams {
            distances: vec![],
            symmetric: false
        }
        .check()
    )
    .contains("distances"));
    assert!(broken_rule(
        GlcmParams {
            distances: vec![1, 0],
            symmetric: false
        }
        .check()
    )
    .contains("distances"));
}

#[test]
fn k_must_be_positive() {
    assert!(broken_rule(
        KnnParams {
            k: 0,
            standardize: true
        }
        .check()
    )
    .contains("`k`"));
}

#[test]
fn folds_and_repeats_must_be_enough() {
    assert!(broken_rule(
        CvParams {
            folds: 1,
            ..Default::default()
        }
        .check()
    )
    .contains("folds"));
    assert!(broken_rule(
        CvParams {
            repeats: 0,
            ..Default::default()
        }
        .check()
    )
    .contains("repeats"));
}

#[test]
fn npy_f32_and_f64_in_both_shapes_are_read() {
    let dir = tempfile::tempdir().unwrap();
    let grid = Array3::<f32>::from_shape_fn((5, 2, 3), |(t, r, c)| (t * 6 + r * 3 + c) as f32);
    write_npy(dir.path().join("g.npy"), &grid).unwrap();
    let rec = read_recording(&dir.path().join("g.npy"), &LayoutFile::default()).unwrap();
    assert_eq!((rec.layout.rows, rec.layout.cols, rec.len()), (2, 3, 5));
    assert_eq!(rec.samples[7], 7.0);
    let chans = Array2::<f64>::from_shape_fn((4, 6), |(t, c)| (t * 10 + c) as f64);
    write_npy(dir.path().join("c.npy"), &chans).unwrap();
    // channels onto a 2x3 grid in reverse order
    let layout = LayoutFile {
        rows: Some(2),
        cols: Some(3),
        channel_map: Some(vec![[1, 2], [1, 1], [1, 0], [0, 2], [0, 1], [0, 0]]),
        ..Default::default()
    };
    let rec = read_recording(&dir.path().join("c.npy"), &layout).unwrap();
    assert_eq!(&rec.samples[6..12], &[15.0, 14.0, 13.0, 12.0, 11.0, 10.0]);
    assert!(rec.layout.present.iter().all(|&p| p), "every cell mapped");
    // Four channels on the 2x3 grid: the two cells no channel reaches are masked, not
    // zero-signal taxels.
    let four = Array2::<f64>::from_shape_fn((4, 4), |(t, c)| (t * 10 + c) as f64);
    write_npy(dir.path().join("four.npy"), &four).unwrap();
    let layout = LayoutFile {
        channel_map: Some(vec![[0, 0], [0, 1], [1, 0], [1, 2]]),
        ..layout
    };
    let rec = read_recording(&dir.path().join("four.npy"), &layout).unwrap();
    assert_eq!(
        rec.layout.present,
        vec![true, true, false, true, false, true]
    );
}

#[test]
fn a_non_finite_npy_sample_is_named_in_float32_and_float64() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("r.npy");
    let read = || read_recording(&path, &LayoutFile::default()).map_err(|e| e.to_string());
    // 37 frames of 3 channels: bad values in the vectorised body and in the tail.
    for (frame, channel) in [(0, 0), (20, 1), (36, 2)] {
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let mut x = Array2::<f64>::from_shape_fn((37, 3), |(t, c)| (t + c) as f64);
            x[[frame, channel]] = bad;
            write_npy(&path, &x).unwrap();
            let f64_error = read().unwrap_err();
            write_npy(&path, &x.mapv(|v| v as f32)).unwrap();
            let f32_error = read().unwrap_err();
            let expected = format!("sample {frame} of channel {channel} is {bad}");
            for error in [f64_error, f32_error] {
                assert!(error.contains(&expected), "{expected}: {error}");
            }
        }
    }
    // Values up to ±1e15 are read; larger ones (f32::MAX, a placeholder) are no
    // sensor's reading and refused.
    let x = Array2::<f32>::from_shape_fn((37, 3), |(t, _)| if t % 2 == 0 { 1e15 } else { -1e15 });
    write_npy(&path, &x).unwrap();
    assert_eq!(read().unwrap().samples[3], f64::from(-1e15f32));
    let x = Array2::<f32>::from_shape_fn((37, 3), |(t, _)| if t == 5 { f32::MAX } else { 0.0 });
    write_npy(&path, &x).unwrap();
    assert!(read()
        .unwrap_err()
        .to_string()
        .contains("sample 5 of channel 0"));
}

#[test]
fn csv_with_time_column_keeps_irregular_stamps() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("r.csv");
    std::fs::write(&p, "t_ms,a,b\n0,1,2\n1.5,3,4\n2.0,5,6\n").unwrap();
    let rec = read_recording(&p, &LayoutFile::default()).unwrap();
    assert_eq!(rec.times_s.as_deref(), Some(&[0.0, 0.0015, 0.002][..]));
    assert_eq!(rec.samples, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
}

#[test]
fn bad_recordings_are_named_errors() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&str, &str, &str); 4] = [
        ("nan.csv", "a,b\n1,2\nNaN,3\n", "line 3, column `a`"),
        (
            "time.csv",
            "t_ms,a\n0,1\n2,1\n1,1\n",
            "line 4: time stamps must not go back",
        ),
        ("text.csv", "a,b\n1,x\n", "got `x`"),
        ("r.txt", "a\n1\n", "expected a .npy or .csv"),
    ];
    for (name, content, expected) in cases {
        let p = dir.path().join(name);
        std::fs::write(&p, content).unwrap();
        let msg = read_recording(&p, &LayoutFile::default())
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains(name) && msg.contains(expected),
            "{name}: {msg}"
        );
    }
    let inf = Array2::<f64>::from_elem((3, 2), f64::INFINITY);
    write_npy(dir.path().join("inf.npy"), &inf).unwrap();
    let msg = read_recording(&dir.path().join("inf.npy"), &LayoutFile::default())
        .unwrap_err()
        .to_string();
    assert!(msg.contains("±1e15"), "{msg}");
    let layout = LayoutFile {
        rows: Some(4),
        cols: Some(4),
        ..Default::default()
    };
    write_npy(dir.path().join("wide.npy"), &Array2::<f64>::zeros((3, 5))).unwrap();
    let msg = read_recording(&dir.path().join("wide.npy"), &layout)
        .unwrap_err()
        .to_string();
    assert!(
        msg.contains("5 channels") && msg.contains("16 taxel cells"),
        "{msg}"
    );
}

#[test]
fn manifest_errors_name_line_and_field() {
    let dir = tempfile::tempdir().unwrap();
    write_npy(dir.path().join("a.npy"), &Array2::<f64>::zeros((300, 4))).unwrap();
    let cases = [
        ("file,speed_mm_s,trial\n", "missing column `label`"),
        (
            "file;label\na.npy;X\n",
            "its header `file;label` is separated by semicolons: a manifest is separated by commas",
        ),
        (
            "file,label,speed_mm_s,force_n,trial\na.npy,X,fast,1,0\n",
            "line 2, field `speed_mm_s`",
        ),
        (
            "file,label,speed_mm_s,force_n,trial\na.npy,X,5,1,zero\n",
            "line 2, field `trial`",
        ),
        (
            "file,label,speed_mm_s,force_n,trial\nb.npy,X,5,1,0\n",
            "line 2: file `b.npy` does not exist",
        ),
        (
            "file,label,speed_mm_s,force_n,trial\n",
            "lists no recordings",
        ),
        (
            "file,label\na.npy,X\n./a.npy,Y\n",
            "line 3: file `./a.npy` is listed again (first on line 2)",
        ),
        (
            "file,label\na.npy,X\nb.npy, X\n",
            "line 3: label ` X` and `X` (line 2) differ only by surrounding spaces",
        ),
    ];
    for (manifest, expected) in cases {
        std::fs::write(dir.path().join("manifest.csv"), manifest).unwrap();
        let msg = Dataset::open(dir.path()).unwrap_err().to_string();
        assert!(
            msg.contains("manifest.csv") && msg.contains(expected),
            "{msg}"
        );
    }
    std::fs::write(dir.path().join("manifest.csv"), "file,label,speed_mm_s,force_n,trial,slide_start_s,slide_end_s,site\na.npy,X,5,1,0,0.05,0.25,lab\n").unwrap();
    let ds = Dataset::open(dir.path()).unwrap();
    assert_eq!(ds.entries[0].slide_end_s, Some(0.25));
    // padding written the same way throughout is one spelling, trimmed
    std::fs::copy(dir.path().join("a.npy"), dir.path().join("a2.npy")).unwrap();
    std::fs::write(
        dir.path().join("manifest.csv"),
        "file, label\na.npy, X \n./a2.npy , X \n",
    )
    .unwrap();
    let padded = Dataset::open(dir.path()).unwrap();
    assert_eq!(padded.labels(), vec!["X".to_string()]);
    std::fs::write(dir.path().join("manifest.csv"), "file,label,speed_mm_s,force_n,trial,slide_start_s,slide_end_s,site\na.npy,X,5,1,0,0.05,0.25,lab\n").unwrap();
    assert_eq!(
        ds.entries[0].extra.get("site").map(String::as_str),
        Some("lab")
    );
    std::fs::write(
        dir.path().join("layout.toml"),
        "rows = 2\ncols = 2\nmask = [\"11\", \"1x\"]\n",
    )
    .unwrap();
    let msg = Dataset::open(dir.path()).unwrap_err().to_string();
    assert!(msg.contains("layout.toml") && msg.contains("mask"), "{msg}");
}

#[test]
fn baselines_time_units_and_channel_maps_parse_from_what_users_type() {
    assert_eq!("none".parse::<Baseline>(), Ok(Baseline::None));
    assert_eq!("min".parse::<Baseline>(), Ok(Baseline::Min));
    for bad in ["max", "mean", ""] {
        assert!(matches!(
            bad.parse::<Baseline>(),
            Err(ParamError {
                name: "baseline",
                ..
            })
        ));
    }
    assert_eq!("ms".parse::<TimeUnit>(), Ok(TimeUnit::Milliseconds));
    assert_eq!("s".parse::<TimeUnit>(), Ok(TimeUnit::Seconds));
    assert_eq!(TimeUnit::Seconds.to_string(), "s");
    assert!(matches!(
        "min".parse::<TimeUnit>(),
        Err(ParamError {
            name: "time-unit",
            ..
        })
    ));
    let map: ChannelMap = "1,1; 1,0;0,1".parse().unwrap();
    assert_eq!(map.cells()[1], Cell { row: 1, col: 0 });
    assert_eq!(map.to_pairs(), vec![[1, 1], [1, 0], [0, 1]]);
    assert_eq!(map.to_string(), "1,1;1,0;0,1");
    for bad in ["0,0;0", "0,0;0,x", "", "0,0,0"] {
        let e = bad.parse::<ChannelMap>().unwrap_err();
        assert_eq!(e.name, "channel-map", "{bad}");
    }
}

#[test]
fn layout_files_keep_the_time_unit_as_text() {
    let dir = tempfile::tempdir().unwrap();
    let layout = LayoutFile {
        time_column: Some("stamp".into()),
        time_unit: Some(TimeUnit::Seconds),
        ..Default::default()
    };
    write_layout(dir.path(), &layout).unwrap();
    let path = dir.path().join("layout.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("time_unit = \"s\""), "{text}");
    assert_eq!(LayoutFile::read(&path).unwrap(), layout);
    std::fs::write(&path, "time_unit = \"min\"\n").unwrap();
    let msg = LayoutFile::read(&path).unwrap_err().to_string();
    assert!(msg.contains("layout.toml") && msg.contains("`ms`"), "{msg}");
}

/// A dataset folder with one short recording per entry of `speeds` (as the manifest
/// writes them), labels alternating `A`, `B`.
fn dataset_at_speeds(dir: &Path, speeds: &[&str]) -> Dataset {
    let mut manifest = String::from("file,label,speed_mm_s,force_n,trial\n");
    for (i, speed) in speeds.iter().enumerate() {
        let file = format!("r{i}.npy");
        write_npy(dir.join(&file), &Array2::<f64>::zeros((10, 4))).unwrap();
        let label = ["A", "B"][i % 2];
        manifest.push_str(&format!("{file},{label},{speed},1,{i}\n"));
    }
    std::fs::write(dir.join("manifest.csv"), manifest).unwrap();
    Dataset::open(dir).unwrap()
}

#[test]
fn recordings_are_selected_by_speed_and_a_missing_speed_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let ds = dataset_at_speeds(dir.path(), &["10", "5", "-5", "5.0", "10", "2.5"]);
    let speeds: Vec<f64> = ds.speeds().iter().map(|s| s.mm_s()).collect();
    assert_eq!(speeds, [-5.0, 2.5, 5.0, 10.0]);
    assert_eq!(ds.indices_at(&[Speed::of(5.0)]).unwrap(), [1, 3]);
    assert_eq!(
        ds.indices_at(&[Speed::of(10.0), Speed::of(-5.0)]).unwrap(),
        [0, 2, 4]
    );
    assert!(ds.indices_at(&[]).unwrap().is_empty());
    let err = ds
        .indices_at(&[Speed::of(5.0), Speed::of(7.0)])
        .unwrap_err();
    assert!(matches!(
        &err,
        Error::Dataset(DatasetError::NoRecordingsAt { speed, available, .. })
            if *speed == Speed::of(7.0) && available.len() == 4
    ));
    let msg = err.to_string();
    assert!(
        msg.contains("no recordings at 7 mm/s") && msg.contains("(its speeds: -5, 2.5, 5, 10)"),
        "{msg}"
    );
    // a speed near but not at a recorded one is not that condition
    assert!(ds.indices_at(&[Speed::of(5.0 + 1e-12)]).is_err());
}

#[test]
fn recordings_of_one_dataset_share_one_grid() {
    let full: Grid = "2x2".parse().unwrap();
    let masked = Grid::masked(2, 2, vec![true, true, false, true]).unwrap();
    let wide: Grid = "1x4".parse().unwrap();
    assert_eq!(
        one_grid([("a", full.clone()), ("b", full.clone())]).unwrap(),
        full
    );
    for other in [masked, wide] {
        let err = one_grid([("a", full.clone()), ("b", full.clone()), ("c", other)]).unwrap_err();
        assert!(matches!(
            &err,
            Error::Dataset(DatasetError::MixedGrids { file, first }) if file == "c" && first == "a"
        ));
        assert!(
            err.to_string().contains("a dataset needs one layout"),
            "{err}"
        );
    }
    assert!(matches!(
        one_grid([]),
        Err(Error::Dataset(DatasetError::Empty))
    ));
}

#[test]
fn a_dataset_fingerprint_hashes_the_manifest_and_the_file_sizes() {
    let dir = tempfile::tempdir().unwrap();
    let manifest = "file,label,speed_mm_s,force_n,trial\na.npy,A,5,1,0\nb.npy,B,5,1,0\n";
    let write = |root: &Path, b_size: usize| {
        std::fs::create_dir_all(root).unwrap();
        std::fs::write(root.join("manifest.csv"), manifest).unwrap();
        std::fs::write(root.join("a.npy"), vec![0u8; 200]).unwrap();
        std::fs::write(root.join("b.npy"), vec![7u8; b_size]).unwrap();
        Dataset::open(root).unwrap().fingerprint().unwrap()
    };
    // From Python 3.11's hashlib, as Dataset::fingerprint documents it:
    //   m = b"file,label,speed_mm_s,force_n,trial\na.npy,A,5,1,0\nb.npy,B,5,1,0\n"
    //   h = hashlib.sha256(); h.update(len(m).to_bytes(8, "little")); h.update(m)
    //   for size in (200, 1000): h.update(size.to_bytes(8, "little"))
    //   h.hexdigest()
    let expected = "sha256:a4773520efb0eb82feab86a42a00ab037abd3d36ef6ad32d17c24f69d5280f7d";
    assert_eq!(write(&dir.path().join("one"), 1000), expected);
    assert_eq!(
        write(&dir.path().join("elsewhere"), 1000),
        expected,
        "the folder's name is not part of the data"
    );
    assert_ne!(write(&dir.path().join("bigger"), 1001), expected);
    let root = dir.path().join("one");
    std::fs::write(root.join("manifest.csv"), manifest.replace("B,5", "B,10")).unwrap();
    assert_ne!(
        Dataset::open(&root).unwrap().fingerprint().unwrap(),
        expected
    );
}

#[test]
fn speed_force_and_trial_are_optional_and_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    for file in ["a.npy", "b.npy"] {
        write_npy(dir.path().join(file), &Array2::<f64>::zeros((10, 4))).unwrap();
    }
    let manifest = dir.path().join("manifest.csv");
    std::fs::write(&manifest, "file,label\na.npy,A\nb.npy,B\n").unwrap();
    let ds = Dataset::open(dir.path()).unwrap();
    assert_eq!(ds.columns, ["file", "label"]);
    let m = &ds.entries[0];
    assert_eq!((m.speed_mm_s, m.force_n, m.trial), (None, None, None));
    assert_eq!(m.speed(), None);
    assert!(ds.speeds().is_empty());
    assert!(matches!(
        ds.indices_at(&[Speed::of(5.0)]),
        Err(Error::Dataset(DatasetError::NoRecordingsAt { .. }))
    ));
    // written back without condition columns, read back the same
    let out = tempfile::tempdir().unwrap();
    write_manifest(out.path(), &ds.entries).unwrap();
    let text = std::fs::read_to_string(out.path().join("manifest.csv")).unwrap();
    assert_eq!(text, "file,label\na.npy,A\nb.npy,B\n");

    // an empty field is "not given"; a column some recording gives is written for all
    let text = "file,label,speed_mm_s,force_n,trial,session\na.npy,A,5,,,s1\nb.npy,B,,2,3,\n";
    std::fs::write(&manifest, text).unwrap();
    let metas = read_manifest(&manifest).unwrap();
    assert_eq!(metas[0].speed_mm_s, Some(5.0));
    assert_eq!(
        (metas[1].speed_mm_s, metas[1].force_n, metas[1].trial),
        (None, Some(2.0), Some(3))
    );
    assert_eq!(metas[1].field("session"), None);
    write_manifest(out.path(), &metas).unwrap();
    let back = read_manifest(&out.path().join("manifest.csv")).unwrap();
    assert_eq!(back, metas);
}

/// Recordings `file{i}` with `trial` i and `session` `sessions[i]`.
fn session_metas(sessions: &[&str]) -> Vec<Meta> {
    sessions
        .iter()
        .enumerate()
        .map(|(i, session)| Meta {
            file: format!("file{i}"),
            label: "A".into(),
            trial: Some(i as i64),
            extra: [("session".to_string(), session.to_string())].into(),
            ..Meta::default()
        })
        .collect()
}

#[test]
fn selections_compare_numbers_as_numbers_and_name_what_is_missing() {
    let metas = session_metas(&["s1", "s2", "s1", "s10"]);
    let select = |text: &str| text.parse::<Selection>().unwrap().rows(&metas);
    assert_eq!(select("trial=1.0,3").unwrap(), [1, 3]);
    assert_eq!(select("session=s1").unwrap(), [0, 2]);
    assert_eq!(
        Selection::speeds(&[Speed::of(5.0)]).to_string(),
        "speed_mm_s=5"
    );
    match select("session=s3") {
        Err(Error::Dataset(DatasetError::NoRecordingsWhere {
            column,
            value,
            present,
        })) => {
            assert_eq!((column.as_str(), value.as_str()), ("session", "s3"));
            assert_eq!(present, ["s1", "s10", "s2"]);
        }
        other => panic!("{other:?}"),
    }
    match select("trial=9") {
        Err(Error::Dataset(DatasetError::NoRecordingsWhere { present, .. })) => {
            assert_eq!(present, ["0", "1", "2", "3"]);
        }
        other => panic!("{other:?}"),
    }
    match select("speed_mm_s=5") {
        Err(Error::Dataset(DatasetError::NoColumn { column, columns })) => {
            assert_eq!(column, "speed_mm_s");
            assert_eq!(columns, ["file", "label", "trial", "session"]);
        }
        other => panic!("{other:?}"),
    }
    for bad in [
        "label=A",
        "trial",
        "=1",
        "trial=",
        "trial=one",
        "session=a,,b",
    ] {
        assert!(bad.parse::<Selection>().is_err(), "{bad}");
    }
}

#[test]
fn a_recording_in_both_the_training_and_the_test_set_is_an_error() {
    use neurotex::analysis::{evaluate, Columns, FeatureTable, Split};
    use neurotex::pipeline::Method;
    let mut metas = session_metas(&["s1", "s2", "s1", "s2"]);
    // two classes in each session (one class would be refused as a trivial 100 %)
    for m in &mut metas[2..] {
        m.label = "B".into();
    }
    let table = FeatureTable {
        method: Method::Glcm3d,
        grid: "1x1".parse().unwrap(),
        names: vec!["x".into()],
        values: vec![0.0, 1.0, 2.0, 3.0],
        metas,
    };
    let knn = KnnParams {
        k: 1,
        ..Default::default()
    }
    .check()
    .unwrap();
    let split = |train: &str, test: &str| Split::Where {
        train: train.parse().unwrap(),
        test: test.parse().unwrap(),
    };
    let both = evaluate(&table, Columns::All, &split("trial=0,1", "trial=1,2"), &knn);
    match both {
        Err(Error::Dataset(DatasetError::InBothSets { file, .. })) => assert_eq!(file, "file1"),
        other => panic!("{other:?}"),
    }
    let apart = evaluate(
        &table,
        Columns::All,
        &split("session=s1", "session=s2"),
        &knn,
    );
    assert_eq!(apart.unwrap().n, 2);
}

#[test]
fn a_folder_of_raw_logs_opened_as_a_dataset_says_how_to_import_it() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["cotton_V10_1.csv", "cotton_V10_2.csv", "notes.txt"] {
        std::fs::write(dir.path().join(name), "t_ms,a\n0,1\n").unwrap();
    }
    let message = Dataset::open(dir.path()).unwrap_err().to_string();
    assert!(
        message.contains("no manifest.csv")
            && message.contains("holds 2 .csv/.npy file(s)")
            && message.contains("neurotex import csv"),
        "{message}"
    );
    // an empty folder gets the plain rule
    let empty = tempfile::tempdir().unwrap();
    let message = Dataset::open(empty.path()).unwrap_err().to_string();
    assert!(
        message.contains("is not a dataset folder (expected a folder with manifest.csv)"),
        "{message}"
    );
    // a path that is not there is said to be missing
    let message = Dataset::open(empty.path().join("nope"))
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("nope: does not exist (expected a dataset folder"),
        "{message}"
    );
}
