//! How a candidate's classifier is evaluated on a table: feature rows, van Rossum distances
//! or spike inputs, shared across folds. Both the spiking candidates and the baselines
//! without spikes are evaluated through it.

use std::sync::Arc;

use crate::analysis::evaluate;
use crate::classify::{ClassifierChoice, DistanceMatrix, SnnClassifier, SpikeDistanceKnn};
use crate::error::{ParamError, Result};
use crate::snn::SpikeInput;

/// What a method's classifier shares across folds besides its table.
#[derive(Clone)]
pub(crate) enum Shared {
    /// Nothing: feature rows.
    None,
    /// Van Rossum distances between every two recordings.
    Distances(Arc<DistanceMatrix>),
    /// Every recording's spikes as the spiking network's input.
    Spikes(Arc<Vec<SpikeInput>>),
}

/// The classifier as a [`super::Candidate::evaluate`]; with a distance matrix, KNN over it; with
/// spike inputs, the spiking network.
pub(crate) fn evaluator(
    classifier: ClassifierChoice,
    shared: Shared,
) -> Result<Arc<super::EvaluateFn>> {
    Ok(match (shared, classifier) {
        (Shared::Distances(matrix), ClassifierChoice::Knn(p)) => {
            let knn = SpikeDistanceKnn::new(matrix, p.k)?;
            Arc::new(move |t, c, s| evaluate(t, c, s, &knn))
        }
        (Shared::Distances(_), other) => {
            let rule = "the van-rossum method classifies with KNN only";
            return Err(ParamError::new("classifiers", rule, other.name()).into());
        }
        (Shared::Spikes(inputs), ClassifierChoice::Snn(p)) => {
            let snn = SnnClassifier::new(p.check()?, inputs);
            Arc::new(move |t, c, s| evaluate(t, c, s, &snn))
        }
        (Shared::Spikes(_), other) => {
            let rule = "the spikes method classifies with the spiking network (snn) only";
            return Err(ParamError::new("classifiers", rule, other.name()).into());
        }
        (Shared::None, classifier) => {
            let chosen = classifier.check()?;
            Arc::new(move |t, c, s| evaluate(t, c, s, &chosen))
        }
    })
}
