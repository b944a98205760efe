//! The library's classifiers fitted on feature matrices, for the scikit-learn estimators.

use neurotex::classify::{
    cross_validate as lib_cross_validate, ChosenModel, Classifier, CvParams, Predict,
};
use numpy::{IntoPyArray, PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{guarded, raise, Kind};
use crate::params;

/// A fitted KNN, random forest or logistic regression.
#[pyclass(module = "neurotex._native", frozen)]
pub struct FittedClassifier {
    model: ChosenModel,
}

/// The rows of `x` in C order.
fn rows_of(x: &PyReadonlyArray2<'_, f64>) -> (Vec<f64>, usize, usize) {
    let a = x.as_array();
    let (n, d) = a.dim();
    let data = match a.as_slice() {
        Some(s) => s.to_vec(),
        None => a.iter().copied().collect(),
    };
    (data, n, d)
}

/// The rows of `x` in C order, with one label per row.
fn labelled_rows<T>(x: &PyReadonlyArray2<'_, f64>, y: &[T]) -> PyResult<(Vec<f64>, usize)> {
    let (data, n, d) = rows_of(x);
    if y.len() != n {
        return Err(raise(
            Kind::Data,
            format!("x has {n} samples but y has {} labels", y.len()),
        ));
    }
    Ok((data, d))
}

#[pymethods]
impl FittedClassifier {
    /// Fits classifier `kind` (knn, forest, linear) with `options` on `x` (n, d) and class
    /// indices `y`.
    #[staticmethod]
    fn fit(
        py: Python<'_>,
        kind: &str,
        options: &Bound<'_, PyDict>,
        x: PyReadonlyArray2<'_, f64>,
        y: Vec<usize>,
    ) -> PyResult<Self> {
        let chosen = params::chosen_classifier(kind, options)?;
        let (data, d) = labelled_rows(&x, &y)?;
        let model = py.detach(|| guarded(|| Ok(chosen.fit(&data, d, &y)?)))?;
        Ok(FittedClassifier { model })
    }

    /// L-BFGS iterations of a logistic regression; `None` for the other classifiers.
    #[getter]
    fn n_iter(&self) -> Option<usize> {
        match &self.model {
            ChosenModel::Linear(m) => Some(m.iterations()),
            _ => None,
        }
    }

    /// Predicted class indices and every class's share, `(n,)` and `(n, classes)`.
    fn predict<'py>(
        &self,
        py: Python<'py>,
        x: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<(Vec<usize>, Bound<'py, PyArray2<f64>>)> {
        let (data, n, d) = rows_of(&x);
        if d != self.model.dims() {
            return Err(raise(
                Kind::Data,
                format!(
                    "x has {d} features per sample, the classifier was fitted on {}",
                    self.model.dims()
                ),
            ));
        }
        if let Some(pos) = data.iter().position(|v| !v.is_finite()) {
            return Err(raise(
                Kind::Data,
                format!(
                    "x[{}, {}] is {}; features must be finite",
                    pos / d.max(1),
                    pos % d.max(1),
                    data[pos]
                ),
            ));
        }
        let classes = self.model.n_classes();
        let out = py.detach(|| guarded(|| Ok(self.model.predict_with_shares(&data))))?;
        let predicted = out.iter().map(|(c, _)| *c).collect();
        let shares: Vec<f64> = out.into_iter().flat_map(|(_, s)| s).collect();
        let shares = ndarray::Array2::from_shape_vec((n, classes), shares)
            .map_err(|e| raise(Kind::Internal, e.to_string()))?;
        Ok((predicted, shares.into_pyarray(py)))
    }
}

/// Stratified, shuffled k-fold cross-validation of classifier `kind` on `x` (n, d) with
/// labels `y`, as `neurotex evaluate` runs it (classes in order of first appearance, the
/// library's folds for `seed`): a dict with `accuracy`, `accuracy_std`, `per_repeat`,
/// `confusion` (rows = true class) and `labels`.
#[pyfunction]
#[pyo3(signature = (x, y, kind, options, folds=5, seed=0, repeats=1))]
#[allow(clippy::too_many_arguments)]
fn cross_validate<'py>(
    py: Python<'py>,
    x: PyReadonlyArray2<'py, f64>,
    y: Vec<String>,
    kind: &str,
    options: &Bound<'py, PyDict>,
    folds: usize,
    seed: u64,
    repeats: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let chosen = params::chosen_classifier(kind, options)?;
    let cv = CvParams {
        folds,
        seed,
        repeats,
    }
    .check()
    .map_err(crate::errors::param)?;
    let (data, d) = labelled_rows(&x, &y)?;
    let mut labels: Vec<String> = Vec::new();
    let indices: Vec<usize> = y
        .iter()
        .map(|l| match labels.iter().position(|k| k == l) {
            Some(i) => i,
            None => {
                labels.push(l.clone());
                labels.len() - 1
            }
        })
        .collect();
    let evaluation = py.detach(|| {
        guarded(|| {
            Ok(lib_cross_validate(
                &chosen, &data, d, &indices, &labels, cv,
            )?)
        })
    })?;
    let out = PyDict::new(py);
    out.set_item("accuracy", evaluation.accuracy)?;
    out.set_item("accuracy_std", evaluation.accuracy_std)?;
    out.set_item("per_repeat", evaluation.per_repeat.clone())?;
    out.set_item("confusion", evaluation.confusion.rows().to_vec())?;
    out.set_item("labels", labels)?;
    Ok(out)
}

/// Registers the classifier class and cross-validation.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<FittedClassifier>()?;
    m.add_function(wrap_pyfunction!(cross_validate, m)?)
}
