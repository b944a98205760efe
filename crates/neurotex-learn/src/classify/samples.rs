//! Learning over typed samples, in the way linfa's `Fit<Records, Targets>` is: a
//! [`Learner`] fits on some samples of a source `S`, chosen by index, and its fitted
//! [`Decide`] classifies others of the same source. The source's type pairs classifiers
//! with what they read:
//! - [`Rows`], feature rows, for KNN, the forest and logistic regression (every
//!   [`Sweep`], and so every [`Classifier`](super::Classifier));
//! - `[SpikeInput]`, the recordings' binned spikes, for the spiking network
//!   ([`super::spiking`]);
//! - [`DistanceMatrix`](super::DistanceMatrix), van Rossum distances between recordings,
//!   for their KNN ([`super::spike_distance`]).
//!
//! A pairing the types do not allow does not compile. Cross-validation and train/test
//! ([`super::cv`]) are written once over any source: folds pick sample indices, so no
//! sample is copied to make a fold except where a classifier itself wants its rows side by
//! side (feature rows are gathered into one block, in index order, before fitting).

use super::{Sweep, SweepModel};
use crate::error::ClassifyError;

/// A source of samples, addressed by index `0..count()`.
pub trait Samples: Sync {
    /// The samples the source holds.
    fn count(&self) -> usize;

    /// Checks that the samples `rows` can be tested, as a train/test split does before
    /// predicting them (feature rows must be finite).
    ///
    /// # Errors
    /// The first sample that cannot be tested.
    fn check_test(&self, _rows: &[usize]) -> Result<(), ClassifyError> {
        Ok(())
    }
}

/// An unfitted classifier over samples of `S` with validated parameters.
pub trait Learner<S: ?Sized>: Sync {
    /// The fitted classifier.
    type Fitted: Decide<S>;

    /// Fits on the samples `rows` of `samples` with class indices `y` (one per row).
    ///
    /// # Errors
    /// Training data this classifier cannot use (empty, non-finite, too small).
    fn learn(
        &self,
        samples: &S,
        rows: &[usize],
        y: &[usize],
    ) -> Result<Self::Fitted, ClassifyError>;

    /// [`Learner::learn`], calling `tick` at most [`Learner::ticks`] times on the way (once
    /// when it is done, unless the learner says more of its progress).
    ///
    /// # Errors
    /// As [`Learner::learn`].
    fn learn_ticking(
        &self,
        samples: &S,
        rows: &[usize],
        y: &[usize],
        tick: &(dyn Fn() + Sync),
    ) -> Result<Self::Fitted, ClassifyError> {
        let fitted = self.learn(samples, rows, y)?;
        tick();
        Ok(fitted)
    }

    /// How many times [`Learner::learn_ticking`] ticks per fit.
    fn ticks(&self) -> usize {
        1
    }
}

/// A fitted [`Learner`]: each of its settings' decisions on samples of `S` (one setting,
/// except for a sweep such as KNN's over k).
pub trait Decide<S: ?Sized> {
    /// Each setting's predicted class of the samples `rows` of `samples`, setting by
    /// setting.
    ///
    /// # Errors
    /// Samples the fitted classifier cannot read (non-finite features).
    fn decide(&self, samples: &S, rows: &[usize]) -> Result<Vec<Vec<usize>>, ClassifyError>;
}

/// Feature rows: `dims` values per sample, row-major.
#[derive(Debug, Clone, Copy)]
pub struct Rows<'a> {
    pub(crate) values: &'a [f64],
    pub(crate) dims: usize,
}

impl<'a> Rows<'a> {
    /// The rows of `values`, `dims` per sample.
    ///
    /// # Errors
    /// Values that are not whole rows.
    pub fn new(values: &'a [f64], dims: usize) -> Result<Self, ClassifyError> {
        let whole = match dims {
            0 => values.is_empty(),
            _ => values.len().is_multiple_of(dims),
        };
        if !whole {
            return Err(ClassifyError::BadFeatures(format!(
                "{} feature values are not whole rows of {dims} features",
                values.len()
            )));
        }
        Ok(Rows { values, dims })
    }

    /// Features per sample.
    pub fn dims(&self) -> usize {
        self.dims
    }

    /// The values of the samples `rows`, side by side in their order.
    ///
    /// # Errors
    /// An index past the last sample.
    pub fn gather(&self, rows: &[usize]) -> Result<Vec<f64>, ClassifyError> {
        if self.dims == 0 {
            return Ok(Vec::new());
        }
        let n = self.count();
        let mut out = Vec::with_capacity(rows.len() * self.dims);
        for &i in rows {
            if i >= n {
                let message = format!("sample {i} of {n} feature rows");
                return Err(ClassifyError::BadFeatures(message));
            }
            out.extend_from_slice(&self.values[i * self.dims..(i + 1) * self.dims]);
        }
        Ok(out)
    }
}

impl Samples for Rows<'_> {
    fn count(&self) -> usize {
        self.values.len().checked_div(self.dims).unwrap_or(0)
    }

    fn check_test(&self, rows: &[usize]) -> Result<(), ClassifyError> {
        let finite = |&i: &usize| {
            let row = self.values.get(i * self.dims..(i + 1) * self.dims);
            row.is_some_and(|r| r.iter().all(|v| v.is_finite()))
        };
        match rows.iter().all(finite) {
            true => Ok(()),
            false => {
                let message = "test features are ragged or not finite";
                Err(ClassifyError::BadFeatures(message.into()))
            }
        }
    }
}

impl<'a, C: Sweep> Learner<Rows<'a>> for C {
    type Fitted = C::Model;

    fn learn(
        &self,
        samples: &Rows<'a>,
        rows: &[usize],
        y: &[usize],
    ) -> Result<C::Model, ClassifyError> {
        self.fit_sweep(&samples.gather(rows)?, samples.dims, y)
    }
}

impl<'a, M: SweepModel> Decide<Rows<'a>> for M {
    fn decide(&self, samples: &Rows<'a>, rows: &[usize]) -> Result<Vec<Vec<usize>>, ClassifyError> {
        Ok(self.predict_sweep(&samples.gather(rows)?))
    }
}
