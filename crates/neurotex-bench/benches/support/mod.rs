//! What the stream benchmarks share: a 3D-GLCM + KNN model of made-up training rows (the
//! work per frame, event and bin does not depend on them).

use neurotex::analysis::{Columns, FeatureTable};
use neurotex::classify::{ClassifierChoice, KnnParams};
use neurotex::model::{Model, Provenance};
use neurotex::pipeline::{Encoding, Method, PipelineParams};
use neurotex::recording::{Baseline, Meta};
use neurotex::Grid;

/// A model of `params` on a `side x side` grid, trained on ten made-up rows of the three
/// Haralick features per population, with a 4 s window.
pub fn made_up_model(side: usize, params: &PipelineParams) -> Model {
    let cells = side * side;
    let features = ["contrast", "correlation", "asm"];
    let names: Vec<String> = match params.encoding {
        Encoding::SaFa => ["sa", "fa"]
            .iter()
            .flat_map(|p| features.map(|f| format!("{p}_{f}")))
            .collect(),
        _ => features.map(String::from).to_vec(),
    };
    let table = FeatureTable {
        method: Method::Glcm3d,
        grid: Grid::masked(side, side, vec![true; cells]).unwrap(),
        values: (0..10 * names.len())
            .map(|i| ((i * 37) % 11) as f64 / 11.0)
            .collect(),
        names,
        metas: (0..10)
            .map(|i| Meta {
                label: ["A", "B"][i % 2].into(),
                ..Meta::default()
            })
            .collect(),
    };
    let provenance = Provenance {
        fingerprint: "made up".into(),
        baseline: Baseline::None,
        speeds: None,
        gain_calibration: None,
        median_duration_ms: Some(4000),
        layout: None,
    };
    let knn = ClassifierChoice::Knn(KnnParams::default());
    Model::train(params, &table, Columns::All, knn, provenance).unwrap()
}
