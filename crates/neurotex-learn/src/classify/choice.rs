//! One type over every classifier, so that evaluation, model files and the command line
//! are written once: [`ClassifierChoice`] (parameters, tagged by `kind` in JSON:
//! `{"kind":"knn","k":5,"standardize":true}`), checked into a [`ChosenClassifier`] whose
//! fit gives a [`ChosenModel`].

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use super::{
    Classifier, Forest, ForestModel, ForestParams, Knn, KnnModel, KnnParams, Linear, LinearModel,
    LinearParams, Predict,
};
use crate::error::{ClassifyError, ParamError};
use crate::snn::SnnParams;

/// Why the spiking classifier cannot fit feature rows.
pub const SNN_READS_SPIKES: &str =
    "the snn classifier reads spike trains, not features: it runs with the spikes method";

/// A classifier and its parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum ClassifierChoice {
    /// k-nearest neighbours (the paper's classifier).
    Knn(KnnParams),
    /// A random forest of CART trees.
    Forest(ForestParams),
    /// Multinomial logistic regression with an L2 penalty.
    Linear(LinearParams),
    /// The spiking network ([`crate::snn`]): it reads spike trains, not feature rows, so
    /// it pairs with the `spikes` method only and is fitted by the pipeline, not by
    /// [`ClassifierChoice::check`].
    Snn(SnnParams),
}

impl Default for ClassifierChoice {
    fn default() -> Self {
        ClassifierChoice::Knn(KnnParams::default())
    }
}

impl ClassifierChoice {
    /// The feature classifiers' names, in order ([`FromStr`] also takes `snn`, the spiking
    /// network, which reads spike trains rather than feature rows).
    pub const NAMES: [&'static str; 3] = ["knn", "forest", "linear"];

    /// The classifier's name: `knn`, `forest` or `linear` (its `kind` in JSON).
    pub fn name(&self) -> &'static str {
        match self {
            ClassifierChoice::Knn(_) => "knn",
            ClassifierChoice::Forest(_) => "forest",
            ClassifierChoice::Linear(_) => "linear",
            ClassifierChoice::Snn(_) => "snn",
        }
    }

    /// Checks the chosen classifier's parameters.
    ///
    /// # Errors
    /// The rule broken.
    pub fn check(self) -> Result<ChosenClassifier, ParamError> {
        Ok(match self {
            ClassifierChoice::Knn(p) => ChosenClassifier::Knn(p.check()?),
            ClassifierChoice::Forest(p) => ChosenClassifier::Forest(p.check()?),
            ClassifierChoice::Linear(p) => ChosenClassifier::Linear(p.check()?),
            ClassifierChoice::Snn(_) => {
                return Err(ParamError::new("classifier", SNN_READS_SPIKES, "snn"))
            }
        })
    }
}

impl FromStr for ClassifierChoice {
    type Err = ParamError;

    /// `knn`, `forest` or `linear`, with default parameters.
    fn from_str(s: &str) -> Result<Self, ParamError> {
        match s {
            "knn" => Ok(ClassifierChoice::Knn(KnnParams::default())),
            "forest" => Ok(ClassifierChoice::Forest(ForestParams::default())),
            "linear" => Ok(ClassifierChoice::Linear(LinearParams::default())),
            "snn" => Ok(ClassifierChoice::Snn(SnnParams::default())),
            _ => Err(ParamError::new(
                "classifier",
                "classifier must be knn, forest, linear or snn",
                s,
            )),
        }
    }
}

impl fmt::Display for ClassifierChoice {
    /// The classifier with its main parameters, e.g. `random forest (200 trees, seed 0)`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ClassifierChoice::Knn(p) => match p.standardize {
                true => write!(f, "KNN (k = {})", p.k),
                false => write!(f, "KNN (k = {}, features not standardised)", p.k),
            },
            ClassifierChoice::Forest(p) => {
                let trees = if p.trees == 1 { "tree" } else { "trees" };
                write!(f, "random forest ({} {trees}, seed {}", p.trees, p.seed)?;
                let d = ForestParams::default();
                if let Some(depth) = p.max_depth {
                    write!(f, ", depth at most {depth}")?;
                }
                if p.min_samples_leaf != d.min_samples_leaf {
                    write!(f, ", at least {} per leaf", p.min_samples_leaf)?;
                }
                if let Some(tried) = p.max_features {
                    write!(f, ", {tried} features tried per split")?;
                }
                if !p.bootstrap {
                    write!(f, ", no bootstrap")?;
                }
                write!(f, ")")
            }
            ClassifierChoice::Linear(p) => {
                write!(f, "logistic regression (C = {}", p.c)?;
                let d = LinearParams::default();
                if p.max_iter != d.max_iter || p.tol != d.tol {
                    write!(
                        f,
                        ", at most {} iterations, tolerance {:e}",
                        p.max_iter, p.tol
                    )?;
                }
                write!(f, ")")
            }
            ClassifierChoice::Snn(p) => describe_snn(p, f),
        }
    }
}

/// The spiking network with its training options, e.g. `spiking network (128 LIF neurons, 10
/// ms steps, mean readout, seed 0)`.
fn describe_snn(p: &crate::snn::SnnParams, f: &mut fmt::Formatter<'_>) -> fmt::Result {
    write!(
        f,
        "spiking network ({} {}LIF neurons, {} ms steps{}, {} readout, seed {}",
        p.hidden,
        if p.recurrent { "recurrent " } else { "" },
        p.dt_ms,
        match p.travel {
            crate::snn::Travel::Off => String::new(),
            crate::snn::Travel::Median => {
                " of travel at the training speeds' median".into()
            }
            crate::snn::Travel::At(v) => format!(" of travel at {v} mm/s"),
        },
        p.readout.name(),
        p.seed
    )?;
    if let Some(window) = p.window_ms {
        write!(f, ", trained on {window} ms windows")?;
    }
    if let Some(w) = p.warp {
        write!(f, ", time warped up to {w}x in training")?;
    }
    if !p.standardize {
        write!(f, ", inputs not standardised")?;
    }
    if p.train_decays {
        write!(f, ", each neuron's decays trained")?;
    }
    if let Some(a) = p.adaptation() {
        let (tau, b) = (a.tau_ms, a.strength);
        write!(f, ", adaptive thresholds (tau {tau} ms, strength {b})")?;
    }
    if let Some(d) = p.delay_ms {
        write!(f, ", synaptic delays trained up to {d} ms")?;
    }
    if p.target == crate::snn::Target::Xylo {
        write!(
            f,
            "; Xylo profile: 8-bit weights, subtractive reset, tau_syn {:.2} ms, tau_mem {:.2} ms, tau_out {:.2} ms",
            p.tau_syn_ms, p.tau_mem_ms, p.tau_out_ms
        )?;
    }
    write!(f, ")")
}

/// A classifier whose parameters passed [`ClassifierChoice::check`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ChosenClassifier {
    /// k-nearest neighbours.
    Knn(Knn),
    /// A random forest.
    Forest(Forest),
    /// Logistic regression.
    Linear(Linear),
}

/// A fitted [`ChosenClassifier`].
#[derive(Debug, Clone, PartialEq)]
pub enum ChosenModel {
    /// A fitted KNN.
    Knn(KnnModel),
    /// A fitted random forest.
    Forest(ForestModel),
    /// A fitted logistic regression.
    Linear(LinearModel),
}

impl Classifier for ChosenClassifier {
    type Model = ChosenModel;

    fn fit(&self, x: &[f64], dims: usize, y: &[usize]) -> Result<ChosenModel, ClassifyError> {
        Ok(match self {
            ChosenClassifier::Knn(c) => ChosenModel::Knn(c.fit(x, dims, y)?),
            ChosenClassifier::Forest(c) => ChosenModel::Forest(c.fit(x, dims, y)?),
            ChosenClassifier::Linear(c) => ChosenModel::Linear(c.fit(x, dims, y)?),
        })
    }
}

impl ChosenModel {
    /// The model as the trait object every variant implements.
    fn inner(&self) -> &dyn Predict {
        match self {
            ChosenModel::Knn(m) => m,
            ChosenModel::Forest(m) => m,
            ChosenModel::Linear(m) => m,
        }
    }
}

impl Predict for ChosenModel {
    fn dims(&self) -> usize {
        self.inner().dims()
    }

    fn n_classes(&self) -> usize {
        self.inner().n_classes()
    }

    fn predict(&self, x: &[f64]) -> Vec<usize> {
        self.inner().predict(x)
    }

    fn predict_with_shares(&self, x: &[f64]) -> Vec<(usize, Vec<f64>)> {
        self.inner().predict_with_shares(x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse_and_old_knn_json_reads() {
        for name in ClassifierChoice::NAMES.into_iter().chain(["snn"]) {
            let choice: ClassifierChoice = name.parse().unwrap();
            assert_eq!(choice.name(), name);
            let json = serde_json::to_value(choice).unwrap();
            assert_eq!(json["kind"], name);
            let back: ClassifierChoice = serde_json::from_value(json).unwrap();
            assert_eq!(back, choice);
        }
        let err = "svm".parse::<ClassifierChoice>().unwrap_err();
        assert_eq!(err.name, "classifier");
        let old: ClassifierChoice =
            serde_json::from_str(r#"{"kind":"knn","k":3,"standardize":false}"#).unwrap();
        assert_eq!(
            old,
            ClassifierChoice::Knn(KnnParams {
                k: 3,
                standardize: false
            })
        );
        let mixed = r#"{"kind":"forest","k":3,"standardize":true}"#;
        assert!(serde_json::from_str::<ClassifierChoice>(mixed).is_err());
    }
}
