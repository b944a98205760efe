//! The spiking classifier ([`crate::snn`]) as a [`Learner`] over the recordings' binned
//! spikes (`[SpikeInput]`): cross-validation and train/test pick its training and test
//! recordings by index, and every recording's input is built once and shared by the folds.

use rayon::prelude::*;

use super::samples::{Decide, Learner, Samples};
use crate::error::ClassifyError;
use crate::snn::{fit_with, softmax, Network, SnnParams, SpikeInput};

impl Samples for [SpikeInput] {
    fn count(&self) -> usize {
        self.len()
    }
}

/// An unfitted spiking classifier with checked parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SnnClassifier {
    params: SnnParams,
}

impl SnnClassifier {
    /// The classifier with `params`, checked.
    ///
    /// # Errors
    /// The rule `params` break.
    pub fn new(params: SnnParams) -> Result<Self, crate::error::ParamError> {
        Ok(SnnClassifier {
            params: params.check()?,
        })
    }

    /// The checked parameters.
    pub fn params(&self) -> &SnnParams {
        &self.params
    }
}

/// The inputs `rows` of `samples`.
///
/// # Errors
/// An index past the last recording.
fn pick<'a>(
    samples: &'a [SpikeInput],
    rows: &[usize],
) -> Result<Vec<&'a SpikeInput>, ClassifyError> {
    rows.iter()
        .map(|&i| {
            samples.get(i).ok_or_else(|| {
                let message = format!("recording {i} of {} spike inputs", samples.len());
                ClassifyError::BadFeatures(message)
            })
        })
        .collect()
}

impl Learner<[SpikeInput]> for SnnClassifier {
    type Fitted = SnnModel;

    fn learn(
        &self,
        samples: &[SpikeInput],
        rows: &[usize],
        y: &[usize],
    ) -> Result<SnnModel, ClassifyError> {
        self.learn_ticking(samples, rows, y, &|| ())
    }

    /// Ticks once per epoch run, at most the parameters' `epochs` (a fit on long slides
    /// takes minutes).
    fn learn_ticking(
        &self,
        samples: &[SpikeInput],
        rows: &[usize],
        y: &[usize],
        tick: &(dyn Fn() + Sync),
    ) -> Result<SnnModel, ClassifyError> {
        let inputs = pick(samples, rows)?;
        let classes = y.iter().max().map_or(0, |m| m + 1);
        let (network, _) = fit_with(&self.params, &inputs, y, classes, tick)?;
        Ok(SnnModel { network })
    }

    fn ticks(&self) -> usize {
        self.params.epochs
    }
}

/// A trained network.
#[derive(Debug, Clone, PartialEq)]
pub struct SnnModel {
    /// The network.
    pub network: Network,
}

impl SnnModel {
    /// The predicted class of each of `inputs` with every class's share (the softmax of
    /// the network's scores).
    pub fn predict_with_shares(&self, inputs: &[&SpikeInput]) -> Vec<(usize, Vec<f64>)> {
        inputs
            .par_iter()
            .map(|input| {
                let shares = softmax(&self.network.scores(input));
                (super::first_max(&shares), shares)
            })
            .collect()
    }
}

impl Decide<[SpikeInput]> for SnnModel {
    fn decide(
        &self,
        samples: &[SpikeInput],
        rows: &[usize],
    ) -> Result<Vec<Vec<usize>>, ClassifyError> {
        let inputs = pick(samples, rows)?;
        let predicted = self.predict_with_shares(&inputs).into_iter().map(|p| p.0);
        Ok(vec![predicted.collect()])
    }
}
