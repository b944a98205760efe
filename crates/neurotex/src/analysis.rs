//! Feature tables over many recordings and their evaluation: cross-validation on a set of
//! conditions, or training on some conditions and testing on others; per taxel for the
//! single-taxel method.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::classify::{cross_validate, train_test, CvParams, KnnParams};
use crate::error::{ClassifyError, Result};
use crate::pipeline::{taxel_cells, Encoded, FeatureExtractor, Method};
use crate::recording::{same_speed, Meta};

/// Feature rows of many recordings, one per recording.
#[derive(Debug, Clone, PartialEq)]
pub struct FeatureTable {
    /// The method that made the features.
    pub method: Method,
    /// Column names.
    pub names: Vec<String>,
    /// Each row's recording.
    pub metas: Vec<Meta>,
    /// Row-major values, `metas.len() * names.len()`.
    pub values: Vec<f64>,
}

impl FeatureTable {
    /// Extracts `method`'s features from every encoded recording, in parallel.
    ///
    /// # Errors
    /// A recording too short for one bin.
    pub fn build(
        encoded: &[Encoded],
        extractor: &FeatureExtractor,
        method: Method,
    ) -> Result<Self> {
        let rows: Vec<Vec<f64>> = encoded
            .par_iter()
            .map(|e| {
                extractor.row(&e.spikes, method).map_err(|err| match err {
                    crate::Error::Data(crate::error::DataError::Invalid { message, .. }) => {
                        crate::error::DataError::invalid(&e.meta.file, message).into()
                    }
                    other => other,
                })
            })
            .collect::<Result<_>>()?;
        Ok(FeatureTable {
            method,
            names: extractor.names(method),
            metas: encoded.iter().map(|e| e.meta.clone()).collect(),
            values: rows.concat(),
        })
    }

    /// Features per row.
    pub fn dims(&self) -> usize {
        self.names.len()
    }

    /// One row's values.
    pub fn row(&self, i: usize) -> &[f64] {
        &self.values[i * self.dims()..(i + 1) * self.dims()]
    }
}

/// How to split recordings for evaluation.
#[derive(Debug, Clone, PartialEq)]
pub enum Split {
    /// Stratified k-fold cross-validation over the recordings at these speeds (all when `None`).
    CrossValidation {
        /// Speeds to include.
        speeds: Option<Vec<f64>>,
        /// Folds, seed, repeats.
        cv: CvParams,
    },
    /// Train on recordings at `train` speeds, test on those at `test` speeds.
    ByCondition {
        /// Training speeds.
        train: Vec<f64>,
        /// Test speeds.
        test: Vec<f64>,
    },
}

/// One taxel's accuracy.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TaxelAccuracy {
    /// Grid row.
    pub row: usize,
    /// Grid column.
    pub col: usize,
    /// Accuracy, 0..1.
    pub accuracy: f64,
}

/// The result of an evaluation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Outcome {
    /// Accuracy 0..1 (for all taxels: the mean over taxels).
    pub accuracy: f64,
    /// Standard deviation over CV repeats (over taxels: mean of the per-taxel values).
    pub accuracy_std: f64,
    /// Class names in confusion-matrix order.
    pub labels: Vec<String>,
    /// Row = true label; summed over repeats, and over taxels when every taxel was evaluated.
    pub confusion: Vec<Vec<usize>>,
    /// Test samples per evaluation.
    pub n: usize,
    /// Every taxel's accuracy, when every taxel was evaluated.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub per_taxel: Option<Vec<TaxelAccuracy>>,
    /// The best taxel, chosen after the fact, when every taxel was evaluated.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub best: Option<TaxelAccuracy>,
}

/// One column group's evaluation: `(cell, accuracy, accuracy_std, confusion, n)`.
type GroupResult = (Option<usize>, f64, f64, Vec<Vec<usize>>, usize);

/// Which feature columns to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Columns {
    /// All of them (GLCM methods).
    All,
    /// The three of one taxel, by row and column.
    Taxel(usize, usize),
    /// Each taxel in turn, reporting the mean and the best.
    EachTaxel,
}

/// Evaluates a feature table with KNN.
///
/// # Errors
/// No recordings at the asked speeds, a class smaller than the fold count, `k` larger than
/// the training set, a test label unseen in training, or a taxel outside the grid.
pub fn evaluate(
    table: &FeatureTable,
    present: &[bool],
    cols: usize,
    columns: Columns,
    split: &Split,
    knn: KnnParams,
) -> Result<Outcome> {
    let in_speeds = |speeds: &[f64], m: &Meta| speeds.iter().any(|&s| same_speed(s, m.speed_mm_s));
    let taxels: Vec<usize> = taxel_cells(present).collect();
    let groups: Vec<(Option<usize>, Vec<usize>)> = match columns {
        Columns::All => vec![(None, (0..table.dims()).collect())],
        Columns::Taxel(r, c) => {
            let cell = r * cols + c;
            let k = taxels
                .iter()
                .position(|&t| t == cell && c < cols)
                .ok_or_else(|| {
                    crate::error::ParamError::new(
                        "taxel",
                        "taxel must be a present cell of the grid",
                        format!("{r},{c}"),
                    )
                })?;
            vec![(Some(cell), (3 * k..3 * k + 3).collect())]
        }
        Columns::EachTaxel => taxels
            .iter()
            .enumerate()
            .map(|(k, &cell)| (Some(cell), (3 * k..3 * k + 3).collect()))
            .collect(),
    };
    let select = |rows: &[usize], cols_idx: &[usize]| -> Vec<f64> {
        rows.iter()
            .flat_map(|&i| cols_idx.iter().map(move |&j| table.row(i)[j]))
            .collect()
    };
    let (train_rows, test_rows): (Vec<usize>, Vec<usize>) = match split {
        Split::CrossValidation { speeds, .. } => {
            let rows: Vec<usize> = (0..table.metas.len())
                .filter(|&i| {
                    speeds
                        .as_ref()
                        .is_none_or(|s| in_speeds(s, &table.metas[i]))
                })
                .collect();
            (rows, Vec::new())
        }
        Split::ByCondition { train, test } => (
            (0..table.metas.len())
                .filter(|&i| in_speeds(train, &table.metas[i]))
                .collect(),
            (0..table.metas.len())
                .filter(|&i| in_speeds(test, &table.metas[i]))
                .collect(),
        ),
    };
    if train_rows.is_empty() {
        return Err(ClassifyError::Empty {
            what: "evaluate: no recordings at the selected speeds",
        }
        .into());
    }
    let mut labels: Vec<String> = Vec::new();
    for &i in train_rows.iter().chain(&test_rows) {
        if !labels.contains(&table.metas[i].label) {
            labels.push(table.metas[i].label.clone());
        }
    }
    let class = |i: usize| {
        labels
            .iter()
            .position(|l| *l == table.metas[i].label)
            .unwrap_or(0)
    };
    let y_train: Vec<usize> = train_rows.iter().map(|&i| class(i)).collect();
    let y_test: Vec<usize> = test_rows.iter().map(|&i| class(i)).collect();
    let results: Vec<GroupResult> = groups
        .par_iter()
        .map(|(cell, cols_idx)| -> Result<_> {
            let dims = cols_idx.len();
            let x_train = select(&train_rows, cols_idx);
            Ok(match split {
                Split::CrossValidation { cv, .. } => {
                    let r = cross_validate(&x_train, dims, &y_train, &labels, knn, *cv)?;
                    (*cell, r.accuracy, r.accuracy_std, r.confusion, r.n)
                }
                Split::ByCondition { .. } => {
                    let x_test = select(&test_rows, cols_idx);
                    let r = train_test(&x_train, &y_train, &x_test, &y_test, dims, &labels, knn)?;
                    (*cell, r.accuracy, 0.0, r.confusion, r.n)
                }
            })
        })
        .collect::<Result<_>>()?;
    let n_groups = results.len() as f64;
    let mut confusion = vec![vec![0usize; labels.len()]; labels.len()];
    for (_, _, _, m, _) in &results {
        for (acc, row) in confusion.iter_mut().zip(m) {
            for (a, &v) in acc.iter_mut().zip(row) {
                *a += v;
            }
        }
    }
    let accuracy = results.iter().map(|r| r.1).sum::<f64>() / n_groups;
    let accuracy_std = results.iter().map(|r| r.2).sum::<f64>() / n_groups;
    let (per_taxel, best) = if columns == Columns::EachTaxel {
        let per: Vec<TaxelAccuracy> = results
            .iter()
            .map(|r| {
                let cell = r.0.unwrap_or(0);
                TaxelAccuracy {
                    row: cell / cols,
                    col: cell % cols,
                    accuracy: r.1,
                }
            })
            .collect();
        let best = per
            .iter()
            .copied()
            .fold(None, |b: Option<TaxelAccuracy>, t| match b {
                Some(b) if b.accuracy >= t.accuracy => Some(b),
                _ => Some(t),
            });
        (Some(per), best)
    } else {
        (None, None)
    };
    Ok(Outcome {
        accuracy,
        accuracy_std,
        labels,
        confusion,
        n: results[0].4,
        per_taxel,
        best,
    })
}
