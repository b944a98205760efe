//! The spiking classifier ([`crate::snn`]) under the [`Classifier`] machinery (cross-validation,
//! train/test). Its input is spike trains, not a feature row, so, as with
//! [`crate::classify::SpikeDistanceKnn`], every recording's [`SpikeInput`] is built once
//! and shared, and the table the classifier is given holds, as its single "feature", each
//! sample's **index** into that list.

use std::sync::Arc;

use super::{Classifier, Predict};
use crate::error::ClassifyError;
use crate::snn::{fit, softmax, Network, SnnParams, SpikeInput};

/// An unfitted spiking classifier over a shared list of recordings' inputs.
#[derive(Debug, Clone)]
pub struct SnnClassifier {
    params: SnnParams,
    inputs: Arc<Vec<SpikeInput>>,
}

impl SnnClassifier {
    /// The classifier with checked `params` over `inputs` (a sample's "feature" is its
    /// index into this list).
    pub fn new(params: SnnParams, inputs: Arc<Vec<SpikeInput>>) -> Self {
        SnnClassifier { params, inputs }
    }

    /// The recordings' inputs.
    pub fn inputs(&self) -> &Arc<Vec<SpikeInput>> {
        &self.inputs
    }

    fn lookup(&self, x: &[f64]) -> Result<Vec<&SpikeInput>, ClassifyError> {
        x.iter()
            .map(|&v| {
                let i = v as usize;
                match v >= 0.0 && v.fract() == 0.0 && i < self.inputs.len() {
                    true => Ok(&self.inputs[i]),
                    false => Err(ClassifyError::BadFeatures(format!(
                        "{v} is not an index into the {} recordings' spike inputs",
                        self.inputs.len()
                    ))),
                }
            })
            .collect()
    }
}

impl Classifier for SnnClassifier {
    type Model = SnnModel;

    fn fit(&self, x: &[f64], dims: usize, y: &[usize]) -> Result<SnnModel, ClassifyError> {
        if dims != 1 {
            return Err(ClassifyError::BadFeatures(format!(
                "the spiking classifier reads one index per sample, got {dims} columns"
            )));
        }
        let inputs = self.lookup(x)?;
        let classes = y.iter().max().map_or(0, |m| m + 1);
        let (network, _) = fit(&self.params, &inputs, y, classes)?;
        Ok(SnnModel {
            network,
            inputs: Arc::clone(&self.inputs),
        })
    }
}

/// A trained network over the shared list of inputs.
#[derive(Debug, Clone)]
pub struct SnnModel {
    /// The network.
    pub network: Network,
    inputs: Arc<Vec<SpikeInput>>,
}

impl PartialEq for SnnModel {
    fn eq(&self, other: &Self) -> bool {
        self.network == other.network
    }
}

impl Predict for SnnModel {
    fn dims(&self) -> usize {
        1
    }

    fn n_classes(&self) -> usize {
        self.network.classes
    }

    fn predict(&self, x: &[f64]) -> Vec<usize> {
        self.predict_with_shares(x)
            .into_iter()
            .map(|p| p.0)
            .collect()
    }

    fn predict_with_shares(&self, x: &[f64]) -> Vec<(usize, Vec<f64>)> {
        use rayon::prelude::*;
        x.par_iter()
            .map(|&v| {
                let scores = self.network.scores(&self.inputs[v as usize]);
                let shares = softmax(&scores);
                (super::first_max(&shares), shares)
            })
            .collect()
    }
}
