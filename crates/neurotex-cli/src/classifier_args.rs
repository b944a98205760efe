//! The classifier options of `evaluate` and `train`: which classifier, and the knobs of the
//! forest and the logistic regression (KNN's `--k` stays with each command).

use anyhow::{bail, Result};
use clap::Args;
use neurotex::classify::{ClassifierChoice, ForestParams, KnnParams, LinearParams};

/// Options choosing the classifier.
#[derive(Args, Debug, Clone)]
pub struct ClassifierArgs {
    /// Classifier: `knn` (the paper's), `forest` (random forest of CART trees, √d features
    /// tried per split) or `linear` (multinomial logistic regression, L2 penalty). The
    /// regression always z-scores features with training statistics and the forest needs no
    /// scaling: --no-standardize applies to KNN only.
    #[arg(long, default_value = "knn")]
    pub classifier: ClassifierChoice,
    /// With `--classifier forest`: trees in the forest [default: 200].
    #[arg(long)]
    pub trees: Option<usize>,
    /// With `--classifier forest`: seed of the trees' random streams [default: 0].
    #[arg(long = "forest-seed")]
    pub forest_seed: Option<u64>,
    /// With `--classifier linear`: inverse penalty strength, scikit-learn's C [default: 1].
    #[arg(long = "c")]
    pub c: Option<f64>,
}

impl ClassifierArgs {
    /// The chosen classifier with its options applied, checked; `knn` is used as it is for
    /// `--classifier knn`.
    pub fn choice(&self, knn: KnnParams) -> Result<ClassifierChoice> {
        let choice = match self.classifier {
            ClassifierChoice::Knn(_) => ClassifierChoice::Knn(knn),
            ClassifierChoice::Forest(defaults) => ClassifierChoice::Forest(ForestParams {
                trees: self.trees.unwrap_or(defaults.trees),
                seed: self.forest_seed.unwrap_or(defaults.seed),
                ..defaults
            }),
            ClassifierChoice::Linear(defaults) => ClassifierChoice::Linear(LinearParams {
                c: self.c.unwrap_or(defaults.c),
                ..defaults
            }),
        };
        let forest = matches!(choice, ClassifierChoice::Forest(_));
        if !forest && (self.trees.is_some() || self.forest_seed.is_some()) {
            bail!("--trees and --forest-seed apply only to --classifier forest");
        }
        if !matches!(choice, ClassifierChoice::Linear(_)) && self.c.is_some() {
            bail!("--c applies only to --classifier linear");
        }
        choice.check()?;
        Ok(choice)
    }
}
