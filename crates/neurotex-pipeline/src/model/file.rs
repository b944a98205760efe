//! A model made and kept: training it, its file written and read back, and the checks a
//! file passes on load (its header, its training rows, its classifier re-fitted).

use std::path::Path;

use super::{FeatureSpec, Header, Model, ModelFile, Provenance, TrainingSet, FORMAT, VERSION};
use crate::analysis::{column_groups, Columns, FeatureTable};
use crate::classify::{ChosenModel, Classifier, ClassifierChoice};
use crate::error::{DataError, ModelError, ParamError, Result};
use crate::pipeline::{Method, Pipeline, PipelineParams};
use crate::values::Grid;

impl Model {
    /// Trains `classifier` on `columns` of `table` (the features of the training recordings,
    /// conditioned and encoded with `params`).
    ///
    /// # Errors
    /// [`Columns::EachTaxel`] (a model classifies with one set of columns), a taxel outside
    /// the grid, broken parameters, or a training set the classifier cannot fit (`k`
    /// larger than the training set, non-finite features).
    pub fn train(
        params: &PipelineParams,
        table: &FeatureTable,
        columns: Columns,
        classifier: ClassifierChoice,
        provenance: Provenance,
    ) -> Result<Model> {
        let taxel = match columns {
            Columns::All => None,
            Columns::Taxel(cell) => Some(cell),
            Columns::EachTaxel => {
                return Err(ParamError::new(
                    "taxel",
                    "a model classifies with one set of columns: all of them, or one taxel's",
                    "every taxel in turn",
                )
                .into())
            }
        };
        let groups = column_groups(&table.grid, table.dims(), columns)?;
        let selected = &groups[0].1;
        let row_labels: Vec<String> = table.metas.iter().map(|m| m.label.clone()).collect();
        let mut labels: Vec<String> = Vec::new();
        for label in &row_labels {
            if !labels.contains(label) {
                labels.push(label.clone());
            }
        }
        let file = ModelFile {
            format: FORMAT.to_string(),
            version: VERSION,
            neurotex_version: env!("CARGO_PKG_VERSION").to_string(),
            pipeline: params.clone(),
            features: FeatureSpec {
                method: table.method,
                taxel,
                columns: selected.iter().map(|&j| table.names[j].clone()).collect(),
            },
            grid: table.grid.clone(),
            classifier,
            labels,
            training: TrainingSet {
                dataset: provenance,
                labels: row_labels,
                rows: (0..table.metas.len())
                    .map(|i| table.select(&[i], selected))
                    .collect(),
            },
        };
        Model::assemble(file)
    }

    /// Checks a model file's content and makes its pipeline, extractor and classifier.
    ///
    /// # Errors
    /// A broken parameter rule, parts that disagree, or a training set that cannot be fit.
    fn assemble(file: ModelFile) -> Result<Model> {
        let inconsistent = |what: String| -> crate::Error { ModelError::Inconsistent(what).into() };
        let grid = &file.grid;
        let grid = Grid::masked(grid.rows(), grid.cols(), grid.present().to_vec())?;
        // The model conditions new recordings as it did its training set, whatever the
        // baseline of their dataset's layout.
        let mut resolved = file.pipeline.clone();
        let baseline = resolved.preprocess.baseline;
        resolved.preprocess.baseline = Some(baseline.unwrap_or(file.training.dataset.baseline));
        let pipeline = Pipeline::new(resolved)?;
        let extractor = pipeline.extractor(&grid)?;
        let spec = &file.features;
        let columns = match (spec.method, spec.taxel) {
            (Method::Taxel, Some(cell)) => Columns::Taxel(cell),
            (_, None) => Columns::All,
            (method, Some(_)) => {
                return Err(inconsistent(format!(
                    "a taxel is given for method {}, which has no per-taxel columns",
                    method.name()
                )))
            }
        };
        let names = extractor.names(spec.method);
        let columns = column_groups(&grid, names.len(), columns)?.remove(0).1;
        let expected: Vec<&String> = columns.iter().map(|&j| &names[j]).collect();
        if spec.columns.iter().collect::<Vec<_>>() != expected {
            return Err(inconsistent(format!(
                "feature columns {:?} are not those of method {} on the {grid} grid",
                spec.columns,
                spec.method.name()
            )));
        }
        check_trained(&file.labels, &file.pipeline, &grid, &file.training.dataset)
            .map_err(inconsistent)?;
        let classifier = fit(&file, columns.len())?;
        Ok(Model {
            file,
            pipeline,
            extractor,
            columns,
            classifier,
        })
    }

    /// Writes the model to `path` as pretty-printed JSON, whole or not at all.
    ///
    /// # Errors
    /// The file cannot be written.
    pub fn save(&self, path: &Path) -> Result<()> {
        crate::io::write_atomic(path, |w| {
            serde_json::to_writer_pretty(&mut *w, &self.file).map_err(std::io::Error::other)?;
            writeln!(w)
        })
    }

    /// Reads a model file written by [`Model::save`].
    ///
    /// # Errors
    /// [`DataError::Io`] for an unreadable file; [`ModelError::NotAModel`] for JSON of
    /// another format, [`ModelError::UnsupportedVersion`] for another format version, and
    /// [`ModelError::Damaged`] for a truncated file or one that is not JSON, and
    /// [`ModelError::Invalid`] for content that breaks a rule.
    pub fn load(path: &Path) -> Result<Model> {
        let bytes = std::fs::read(path).map_err(|e| DataError::io(path, e))?;
        if bytes.starts_with(b"\x89HDF\r\n\x1a\n") {
            // HDF5: a NIR graph, which holds a spiking network.
            let path = path.to_path_buf();
            return Err(ModelError::SpikingModel { path }.into());
        }
        let not_an_object = || -> crate::Error {
            let found = "missing (the file is not a JSON object)".into();
            ModelError::NotAModel {
                path: path.to_path_buf(),
                found,
            }
            .into()
        };
        // An array would fill the header's fields in order: only an object has a format.
        if bytes.iter().find(|b| !b.is_ascii_whitespace()) == Some(&b'[') {
            return Err(not_an_object());
        }
        let header: Header = serde_json::from_slice(&bytes).map_err(|e| match e.classify() {
            serde_json::error::Category::Data => not_an_object(),
            _ => unreadable(path, &e),
        })?;
        let (format, version) = (header.format.as_ref(), header.version.as_ref());
        check_header(path, format, version, (FORMAT, VERSION))?;
        let file: ModelFile = serde_json::from_slice(&bytes).map_err(|e| unreadable(path, &e))?;
        Model::assemble(file).map_err(|e| invalid(path, e.to_string()))
    }
}

/// The error of a model file serde could not read: [`ModelError::Damaged`] when the JSON
/// itself is broken or cut short, [`ModelError::Invalid`] when it is whole but its content
/// breaks the format (a field of the wrong type, one missing, a value out of range).
pub(crate) fn unreadable(path: &Path, e: &serde_json::Error) -> crate::Error {
    let reason = crate::error::json_error(e);
    match e.classify() {
        serde_json::error::Category::Data => invalid(path, reason),
        _ => ModelError::Damaged {
            path: path.to_path_buf(),
            reason,
        }
        .into(),
    }
}

/// [`ModelError::Invalid`]: whole JSON whose content breaks the rule `reason`.
pub(crate) fn invalid(path: &Path, reason: String) -> crate::Error {
    let path = path.to_path_buf();
    ModelError::Invalid { path, reason }.into()
}

/// Fits the file's classifier on its training rows of `dims` features.
///
/// # Errors
/// Rows of another length, labels that are not classes of the model, or a training set
/// the classifier cannot fit.
fn fit(file: &ModelFile, dims: usize) -> Result<ChosenModel> {
    let training = &file.training;
    let inconsistent = |what: String| -> crate::Error { ModelError::Inconsistent(what).into() };
    if training.labels.len() != training.rows.len() {
        return Err(inconsistent(format!(
            "{} training labels for {} training rows",
            training.labels.len(),
            training.rows.len()
        )));
    }
    if let Some(i) = training.rows.iter().position(|r| r.len() != dims) {
        return Err(inconsistent(format!(
            "training row {i} has {} features, expected {dims}",
            training.rows[i].len()
        )));
    }
    // The features neurotex computes are rates, statistics and Haralick values, all far
    // below this; a larger value in a model file is damage, and would overflow the
    // z-scoring's squares to infinity and the distances to NaN.
    const MAX_FEATURE: f64 = 1e15;
    for (i, row) in training.rows.iter().enumerate() {
        if let Some(j) = row.iter().position(|v| v.is_nan() || v.abs() > MAX_FEATURE) {
            return Err(inconsistent(format!(
                "training row {i}, feature {j} is {}, beyond the ±1e15 any feature can reach",
                row[j]
            )));
        }
    }
    let y = training
        .labels
        .iter()
        .map(|l| {
            file.labels.iter().position(|c| c == l).ok_or_else(|| {
                inconsistent(format!("training label `{l}` is not one of the classes"))
            })
        })
        .collect::<Result<Vec<_>>>()?;
    // Training lists exactly the labels of its rows: a class without a row would leave the
    // classifier with fewer outputs than the file has labels.
    if let Some(label) = (0..file.labels.len()).find(|c| !y.contains(c)) {
        return Err(inconsistent(format!(
            "field `labels`: class `{}` has no training row",
            file.labels[label]
        )));
    }
    let classifier = file.classifier.check()?;
    Ok(classifier.fit(&training.rows.concat(), dims, &y)?)
}

/// Checks what training guarantees of any model's file beyond its pipeline's own rules:
/// at least two distinct labels, a causal conditioning with one resting value per cell of
/// `grid`, and a provenance training could have written (a stream's default window of at
/// least 1 ms, a finite gain calibration, a layout that passes its own checks).
///
/// # Errors
/// The rule broken, as a sentence naming the field.
pub(crate) fn check_trained(
    labels: &[String],
    pipeline: &PipelineParams,
    grid: &Grid,
    provenance: &Provenance,
) -> std::result::Result<(), String> {
    if labels.len() < 2 {
        return Err(format!(
            "field `labels` holds {} class(es); a model is trained on at least two",
            labels.len()
        ));
    }
    if let Some(i) = (1..labels.len()).find(|&i| labels[..i].contains(&labels[i])) {
        return Err(format!(
            "field `labels`: class `{}` is listed twice",
            labels[i]
        ));
    }
    if let Some(causal) = &pipeline.preprocess.causal {
        let cells = grid.rows() * grid.cols();
        if causal.offsets.len() != cells {
            return Err(format!(
                "field `pipeline.preprocess.causal.offsets` holds {} resting values for the {cells} cells of the {grid} grid",
                causal.offsets.len()
            ));
        }
    }
    if provenance.median_duration_ms == Some(0) {
        return Err("field `training.dataset.median_duration_ms` is 0; training recordings last at least one bin".into());
    }
    if let Some(g) = &provenance.gain_calibration {
        let numbers = [g.target_hz, g.gain, g.median_hz];
        if numbers.iter().any(|v| !(v.is_finite() && *v >= 0.0)) || g.gain == 0.0 {
            return Err(format!(
                "field `training.dataset.gain_calibration`: target {} Hz, gain {}, median {} Hz; each must be finite and not negative, the gain positive",
                g.target_hz, g.gain, g.median_hz
            ));
        }
    }
    if let Some(layout) = &provenance.layout {
        let at = Path::new("field `training.dataset.layout`");
        layout.check(at).map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// Checks a model file's `format` and `version` fields (`None` when missing) against the
/// `expected` format and version: the other kind of model file is named as such.
///
/// # Errors
/// [`ModelError::NotSpiking`] or [`ModelError::SpikingModel`] for the other kind,
/// [`ModelError::NotAModel`] for another format, [`ModelError::UnsupportedVersion`].
pub fn check_header(
    path: &Path,
    format: Option<&serde_json::Value>,
    version: Option<&serde_json::Value>,
    expected: (&str, u64),
) -> Result<()> {
    let path = path.to_path_buf();
    let text =
        |field: Option<&serde_json::Value>| field.map_or("missing".into(), |v| v.to_string());
    match format.and_then(|f| f.as_str()) {
        Some(f) if f == expected.0 => {}
        Some(FORMAT) => return Err(ModelError::NotSpiking { path }.into()),
        Some(crate::error::SNN_MODEL_FORMAT) => {
            return Err(ModelError::SpikingModel { path }.into())
        }
        _ => {
            let found = text(format);
            return Err(ModelError::NotAModel { path, found }.into());
        }
    }
    if version.and_then(|v| v.as_u64()) != Some(expected.1) {
        let found = text(version);
        return Err(ModelError::UnsupportedVersion { path, found }.into());
    }
    Ok(())
}
