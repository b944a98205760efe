//! Feature rows of many recordings: one row per recording, with the recording's [`Meta`].

use rayon::prelude::*;

use crate::error::Result;
use crate::pipeline::{Encoded, FeatureExtractor, Method};
use crate::recording::Meta;
use crate::values::{Grid, Speed};

/// Feature rows of many recordings, one per recording.
#[derive(Debug, Clone, PartialEq)]
pub struct FeatureTable {
    /// The method that made the features.
    pub method: Method,
    /// The taxel grid of every recording (the single-taxel columns follow its taxels).
    pub grid: Grid,
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
    /// A recording too short for one bin (named by its file).
    pub fn build(
        encoded: &[Encoded],
        extractor: &FeatureExtractor,
        method: Method,
    ) -> Result<Self> {
        let rows: Vec<Vec<f64>> = encoded
            .par_iter()
            .map(|e| {
                extractor
                    .row(e, method)
                    .map_err(|err| err.in_recording(&e.meta.file))
            })
            .collect::<Result<_>>()?;
        let metas = encoded.iter().map(|e| e.meta.clone()).collect();
        Ok(Self::from_rows(extractor, method, metas, &rows))
    }

    /// The table of `rows`, `method`'s features by `extractor` of the recordings `metas`.
    pub fn from_rows(
        extractor: &FeatureExtractor,
        method: Method,
        metas: Vec<Meta>,
        rows: &[Vec<f64>],
    ) -> Self {
        FeatureTable {
            method,
            grid: extractor.grid().clone(),
            names: extractor.names(method),
            metas,
            values: rows.concat(),
        }
    }

    /// Features per row.
    pub fn dims(&self) -> usize {
        self.names.len()
    }

    /// One row's values.
    pub fn row(&self, i: usize) -> &[f64] {
        &self.values[i * self.dims()..(i + 1) * self.dims()]
    }

    /// The indices of the rows recorded at one of `speeds`.
    pub fn rows_at(&self, speeds: &[Speed]) -> Vec<usize> {
        rows_at(&self.metas, speeds)
    }

    /// The table of rows `rows` alone, in that order.
    pub fn subset(&self, rows: &[usize]) -> FeatureTable {
        FeatureTable {
            method: self.method,
            grid: self.grid.clone(),
            names: self.names.clone(),
            metas: rows.iter().map(|&i| self.metas[i].clone()).collect(),
            values: rows.iter().flat_map(|&i| self.row(i)).copied().collect(),
        }
    }

    /// The values of rows `rows` and columns `columns`, row-major.
    pub(crate) fn select(&self, rows: &[usize], columns: &[usize]) -> Vec<f64> {
        rows.iter()
            .flat_map(|&i| columns.iter().map(move |&j| self.row(i)[j]))
            .collect()
    }
}

/// The indices of the recordings of `metas` made at one of `speeds`.
pub(crate) fn rows_at(metas: &[Meta], speeds: &[Speed]) -> Vec<usize> {
    (0..metas.len())
        .filter(|&i| metas[i].speed().is_some_and(|s| speeds.contains(&s)))
        .collect()
}
