use std::path::Path;

use super::*;
use crate::analysis::{Columns, FeatureTable};
use crate::classify::{ForestParams, KnnParams, LinearParams};
use crate::encode::SpikeTrains;
use crate::error::{ClassifyError, DataError, ParamError};
use crate::pipeline::Encoded;
use crate::recording::Meta;

/// `n` feature values in [0, 10), seeded.
fn values(seed: u64, n: usize) -> Vec<f64> {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    (0..n).map(|_| 10.0 * rng.gen::<f64>()).collect()
}

/// A `method` table of three classes x 6 recordings on a 2x2 grid whose class shifts
/// every feature, so that the classes are told apart.
fn table(method: Method) -> FeatureTable {
    let grid = Grid::full(2, 2).unwrap();
    let extractor = FeatureExtractor::new(&PipelineParams::default(), &grid).unwrap();
    let names = extractor.names(method);
    let labels = ["rough", "smooth", "ribbed"];
    let metas: Vec<Meta> = (0..18)
        .map(|i| Meta {
            file: format!("r{i}.npy"),
            label: labels[i % 3].to_string(),
            ..Meta::default()
        })
        .collect();
    let noise = values(7, metas.len() * names.len());
    let values = noise
        .chunks(names.len())
        .enumerate()
        .flat_map(|(i, row)| row.iter().map(move |v| v + 20.0 * (i % 3) as f64))
        .collect();
    FeatureTable {
        method,
        grid,
        names,
        metas,
        values,
    }
}

fn provenance() -> Provenance {
    Provenance {
        fingerprint: "sha256:00".into(),
        baseline: Baseline::Min,
        speeds: Some(vec![Speed::of(5.0)]),
        gain_calibration: None,
        median_duration_ms: None,
        layout: None,
    }
}

fn trained(method: Method, columns: Columns) -> Model {
    let knn = ClassifierChoice::Knn(KnnParams {
        k: 3,
        standardize: true,
    });
    trained_with(method, columns, knn)
}

fn trained_with(method: Method, columns: Columns, classifier: ClassifierChoice) -> Model {
    let params = PipelineParams::default();
    Model::train(&params, &table(method), columns, classifier, provenance()).unwrap()
}

#[test]
fn a_saved_model_loads_equal_and_predicts_the_same() {
    let dir = tempfile::tempdir().unwrap();
    for (method, columns) in [
        (Method::Glcm3d, Columns::All),
        (Method::Taxel, Columns::All),
        (Method::Taxel, Columns::Taxel(Cell { row: 1, col: 0 })),
    ] {
        let model = trained(method, columns);
        let dims = model.features().columns.len();
        let queries = values(99, 40 * dims);
        let before = model.predict_rows(&queries).unwrap();
        let path = dir.path().join("model.json");
        model.save(&path).unwrap();
        let loaded = Model::load(&path).unwrap();
        assert_eq!(loaded, model);
        assert_eq!(loaded.predict_rows(&queries).unwrap(), before);
        assert_eq!(loaded.baseline(), Baseline::Min, "the training layout's");
        for p in &before {
            assert!((p.shares.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            let top = model
                .labels()
                .iter()
                .position(|l| *l == p.predicted)
                .unwrap();
            assert!(p.shares.iter().all(|&s| s <= p.shares[top]));
        }
    }
}

#[test]
fn forest_and_linear_models_save_load_and_predict_the_same() {
    let dir = tempfile::tempdir().unwrap();
    let forest = ForestParams {
        trees: 25,
        seed: 3,
        ..ForestParams::default()
    };
    for choice in [
        ClassifierChoice::Forest(forest),
        ClassifierChoice::Linear(LinearParams::default()),
    ] {
        let model = trained_with(Method::Glcm3d, Columns::All, choice);
        let dims = model.features().columns.len();
        let queries = values(5, 30 * dims);
        let before = model.predict_rows(&queries).unwrap();
        let path = dir.path().join("model.json");
        model.save(&path).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains(&format!("\"kind\": \"{}\"", choice.name())));
        let loaded = Model::load(&path).unwrap();
        assert_eq!(loaded.classifier(), choice);
        assert_eq!(loaded.predict_rows(&queries).unwrap(), before);
        let rows: Vec<f64> = (0..18)
            .flat_map(|i| model.file.training.rows[i].clone())
            .collect();
        let right = model
            .predict_rows(&rows)
            .unwrap()
            .iter()
            .zip(&model.file.training.labels)
            .filter(|(p, l)| p.predicted == **l)
            .count();
        assert_eq!(right, 18, "{choice}: separable training rows");
        for p in &before {
            assert!((p.shares.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            let top = model
                .labels()
                .iter()
                .position(|l| *l == p.predicted)
                .unwrap();
            assert!(p.shares.iter().all(|&s| s <= p.shares[top]));
        }
    }
}

#[test]
fn the_file_describes_itself() {
    let model = trained(Method::Taxel, Columns::Taxel(Cell { row: 0, col: 1 }));
    let value = serde_json::to_value(&model.file).unwrap();
    assert_eq!(value["format"], "neurotex-model");
    assert_eq!(value["version"], 1);
    assert_eq!(value["neurotex_version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(value["pipeline"]["preprocess"]["cutoff_hz"], 50.0);
    assert_eq!(value["pipeline"]["encoder"]["gain"], 8.0);
    assert_eq!(
        value["pipeline"]["glcm"]["distances"],
        serde_json::json!([1, 2, 4, 8])
    );
    assert_eq!(
        value["features"]["columns"],
        serde_json::json!(["r0c1_msr", "r0c1_cv_isi", "r0c1_fano"])
    );
    assert_eq!(
        value["classifier"],
        serde_json::json!({"kind": "knn", "k": 3, "standardize": true})
    );
    assert_eq!(
        value["labels"],
        serde_json::json!(["rough", "smooth", "ribbed"])
    );
    assert_eq!(value["training"]["dataset"]["baseline"]["kind"], "min");
    assert_eq!(value["training"]["rows"].as_array().unwrap().len(), 18);
}

#[test]
fn the_training_rows_are_one_set_of_columns() {
    let params = PipelineParams::default();
    let err = Model::train(
        &params,
        &table(Method::Taxel),
        Columns::EachTaxel,
        ClassifierChoice::default(),
        provenance(),
    )
    .unwrap_err();
    assert!(matches!(
        err,
        crate::Error::Param(ParamError { name: "taxel", .. })
    ));
    let err = Model::train(
        &params,
        &table(Method::Glcm3d),
        Columns::All,
        ClassifierChoice::Knn(KnnParams {
            k: 19,
            standardize: true,
        }),
        provenance(),
    )
    .unwrap_err();
    assert!(matches!(
        err,
        crate::Error::Classify(ClassifyError::KTooLarge { k: 19, n_train: 18 })
    ));
}

/// Writes `text` to a file and loads it as a model.
fn load_text(text: &str) -> crate::Error {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.json");
    std::fs::write(&path, text).unwrap();
    Model::load(&path).unwrap_err()
}

#[test]
fn files_of_another_format_or_version_or_damaged_are_named_errors() {
    let model = trained(Method::Glcm3d, Columns::All);
    let text = serde_json::to_string_pretty(&model.file).unwrap();
    let err = load_text(&text.replacen("\"version\": 1", "\"version\": 99", 1));
    assert!(
        matches!(&err, crate::Error::Model(ModelError::UnsupportedVersion { found, .. }) if found == "99"),
        "{err}"
    );
    assert!(
        err.to_string().contains("version 99 is not supported"),
        "{err}"
    );
    let err = load_text(&text.replacen("neurotex-model", "other-model", 1));
    assert!(
        matches!(err, crate::Error::Model(ModelError::NotAModel { .. })),
        "{err}"
    );
    // An array's items do not stand for the header's fields.
    let err = load_text("[1, 2]");
    assert!(
        matches!(&err, crate::Error::Model(ModelError::NotAModel { found, .. }) if found.contains("not a JSON object")),
        "{err}"
    );
    for damaged in [&text[..text.len() / 2], "", "not json"] {
        let err = load_text(damaged);
        assert!(
            matches!(err, crate::Error::Model(ModelError::Damaged { .. })),
            "{err}"
        );
    }
    // Whole JSON whose content neurotex never writes: named as such, not as damaged.
    for edited in [
        &text.replacen("\"kind\": \"knn\"", "\"kind\": \"forest\"", 1),
        &text.replacen("\"levels\": 16", "\"levels\": 1", 1),
        &text.replacen("\"rows\": 2,", "\"rows\": 3,", 1),
        &text.replacen("\"asm\"", "\"energy\"", 1),
        &text.replacen("\"k\": 3", "\"k\": 0", 1),
        // absurd neuron constants: the Euler step would overflow to NaN, silently
        // silencing every neuron
        &text.replacen("\"a\": 0.02", "\"a\": 1e300", 1),
        &text.replacen("\"b\": 0.2", "\"b\": -1e300", 1),
        &text.replacen("\"d\": 8.0", "\"d\": 1e300", 1),
    ] {
        let err = load_text(edited);
        assert!(
            matches!(err, crate::Error::Model(ModelError::Invalid { .. })),
            "{err}"
        );
    }
    let missing = Model::load(Path::new("/nonexistent/model.json")).unwrap_err();
    assert!(matches!(missing, crate::Error::Data(DataError::Io { .. })));
}

#[test]
fn model_files_asking_for_absurd_work_or_values_are_damaged_not_aborts() {
    let model = trained(Method::Glcm3d, Columns::All);
    let value = serde_json::to_value(&model.file).unwrap();
    // a billion trees: refused by the forest's limit before anything is allocated
    let mut forest = value.clone();
    let trees = ForestParams {
        trees: 1_000_000_000,
        ..ForestParams::default()
    };
    forest["classifier"] = serde_json::to_value(ClassifierChoice::Forest(trees)).unwrap();
    let err = load_text(&forest.to_string());
    assert!(
        matches!(err, crate::Error::Model(ModelError::Invalid { .. })),
        "{err}"
    );
    assert!(err.to_string().contains("at most 10000"), "{err}");
    // a training value that would overflow the z-scoring
    let mut rows = value;
    rows["training"]["rows"][0][1] = serde_json::json!(1e300);
    let err = load_text(&rows.to_string());
    assert!(
        err.to_string().contains("training row 0, feature 1"),
        "{err}"
    );
}

#[test]
fn recordings_of_another_grid_are_named() {
    let model = trained(Method::Glcm3d, Columns::All);
    let encoded = |file: &str, rows: usize, cols: usize| Encoded {
        meta: Meta {
            file: file.into(),
            ..Meta::default()
        },
        spikes: SpikeTrains::from_raster(
            &vec![0; 400 * rows * cols],
            rows,
            cols,
            &vec![true; rows * cols],
        ),
        fa: None,
        resampled: false,
        flat: false,
        constant: false,
        from_events: false,
    };
    assert_eq!(model.predict(&[encoded("a.npy", 2, 2)]).unwrap().len(), 1);
    let err = model
        .predict(&[encoded("a.npy", 2, 2), encoded("b.npy", 3, 3)])
        .unwrap_err();
    assert!(
        matches!(&err, crate::Error::Model(ModelError::OtherGrid { file, .. }) if file == "b.npy"),
        "{err}"
    );
    assert!(err.to_string().contains("3x3, 9 taxels"), "{err}");
}

#[test]
fn scores_count_true_labels_against_predictions() {
    let model = trained(Method::Glcm3d, Columns::All);
    let p = |label: &str| Prediction {
        predicted: label.into(),
        shares: vec![],
    };
    let truth: Vec<String> = ["rough", "smooth", "ribbed"].map(String::from).to_vec();
    let score = model
        .score(&truth, &[p("rough"), p("rough"), p("ribbed")])
        .unwrap();
    assert_eq!(score.n, 3);
    assert!((score.accuracy - 2.0 / 3.0).abs() < 1e-15);
    // Wilson's interval for 2 of 3, (k + z²/2 ± z √(k (n - k) / n + z²/4)) / (n + z²) by
    // hand with z = 1.959964; chance one over the three classes scored.
    let i = &score.interval;
    assert!((i.lower - 0.207_660).abs() < 1e-6 && (i.upper - 0.938_508).abs() < 1e-6);
    assert!((score.chance - 1.0 / 3.0).abs() < 1e-15);
    assert_eq!(score.confusion.rows()[1], vec![1, 0, 0]);
    let err = model
        .score(&["felt".to_string()], &[p("rough")])
        .unwrap_err();
    assert!(matches!(
        err,
        crate::Error::Classify(ClassifyError::UnknownTestLabel { .. })
    ));
}
