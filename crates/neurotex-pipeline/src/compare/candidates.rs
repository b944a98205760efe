//! The candidates of a comparison made from encoded recordings: for each encoding, each
//! feature method's table is built once and shared by every classifier; the spike-timing
//! method's distance matrix is computed once per population and shared by the encodings.

use std::sync::Arc;
use std::time::Instant;

use super::Candidate;
use crate::analysis::{evaluator, Columns, MethodSamples};
use crate::classify::{ClassifierChoice, ForestParams, KnnParams};
use crate::error::Result;
use crate::pipeline::{Encoded, Encoding, FeatureExtractor, Method, PipelineParams};
use crate::samples::{population_view, PopulationMatrices};
pub use crate::samples::{MethodChoice, SPIKES, STANDARD_TAU_MS, VAN_ROSSUM};
use crate::snn::SnnParams;
use crate::values::Grid;

/// What to compare: every encoding x method x classifier, except that the paper's
/// single-taxel method (each taxel alone, mean over taxels) and the spike-timing method
/// are KNN methods and run with KNN only.
#[derive(Debug, Clone, PartialEq)]
pub struct CandidateSet {
    /// Encodings.
    pub encodings: Vec<Encoding>,
    /// Methods.
    pub methods: Vec<MethodChoice>,
    /// Classifiers.
    pub classifiers: Vec<ClassifierChoice>,
    /// Time constant of the van Rossum kernel, ms.
    pub tau_ms: f64,
    /// Also the baselines without spikes (encoding `none`; [`super::signal`]), each with
    /// every classifier.
    pub baselines: bool,
}

/// The encodings `neurotex compare` and E9 compare by default.
pub const STANDARD_ENCODINGS: &str = "sa,sa+fa";
/// The methods compared by default (`all-taxels-mm` needs every recording's speed, so it is
/// asked for by name).
pub const STANDARD_METHODS: &str =
    "taxel,all-taxels,glcm2d,glcm3d,glcm3d-multi,spectrum,van-rossum";
/// The classifiers compared by default.
pub const STANDARD_CLASSIFIERS: &str = "knn,forest,linear";

impl CandidateSet {
    /// The standard set ([`STANDARD_ENCODINGS`] x [`STANDARD_METHODS`] x
    /// [`STANDARD_CLASSIFIERS`]) with KNN's parameters `knn` and the forest seeded by `seed`.
    pub fn standard(knn: KnnParams, seed: u64) -> CandidateSet {
        let parse = |list: &str| -> Vec<String> { list.split(',').map(String::from).collect() };
        let encodings = parse(STANDARD_ENCODINGS)
            .iter()
            .filter_map(|e| e.parse().ok())
            .collect();
        let methods = parse(STANDARD_METHODS)
            .iter()
            .filter_map(|m| m.parse().ok())
            .collect();
        let classifiers = parse(STANDARD_CLASSIFIERS)
            .iter()
            .filter_map(|c| c.parse::<ClassifierChoice>().ok())
            .map(|c| match c {
                ClassifierChoice::Knn(_) => ClassifierChoice::Knn(knn),
                ClassifierChoice::Forest(p) => ClassifierChoice::Forest(ForestParams { seed, ..p }),
                other => other,
            })
            .collect();
        CandidateSet {
            encodings,
            methods,
            classifiers,
            tau_ms: STANDARD_TAU_MS,
            baselines: false,
        }
    }

    /// The (method, classifier) pairs of one encoding.
    fn pairs(&self) -> Vec<(MethodChoice, ClassifierChoice)> {
        let knn = self
            .classifiers
            .iter()
            .find(|c| matches!(c, ClassifierChoice::Knn(_)))
            .copied()
            .unwrap_or(ClassifierChoice::Knn(KnnParams::default()));
        let snn = self
            .classifiers
            .iter()
            .find(|c| matches!(c, ClassifierChoice::Snn(_)))
            .copied()
            .unwrap_or(ClassifierChoice::Snn(SnnParams::default()));
        let mut out = Vec::new();
        for &method in &self.methods {
            let knn_only = matches!(
                method,
                MethodChoice::VanRossum | MethodChoice::Features(Method::Taxel)
            );
            if knn_only {
                out.push((method, knn));
            } else if method == MethodChoice::Spikes {
                out.push((method, snn));
            } else {
                let features = self
                    .classifiers
                    .iter()
                    .filter(|c| !matches!(c, ClassifierChoice::Snn(_)));
                out.extend(features.map(|&c| (method, c)));
            }
        }
        out
    }

    /// How many candidates the set makes.
    pub fn len(&self) -> usize {
        let baselines = match self.baselines {
            true => {
                let features = self
                    .classifiers
                    .iter()
                    .filter(|c| !matches!(c, ClassifierChoice::Snn(_)));
                super::signal::SIGNAL_METHODS.len() * features.count()
            }
            false => 0,
        };
        self.encodings.len() * self.pairs().len() + baselines
    }

    /// Whether the set makes no candidate.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Whether some encoding needs the fast-adapting population.
    pub fn needs_fa(&self) -> bool {
        self.encodings.iter().any(|e| *e != Encoding::Sa)
    }
}

/// The candidates of `set` from recordings encoded with both populations where the set
/// needs them (`encoded[i].fa` present for `fa` and `sa+fa`), all on `grid`.
/// `encode_s` (the encoding's wall time) is shared evenly among each encoding's methods in
/// [`Candidate::prepare_s`].
///
/// # Errors
/// A broken parameter, recordings without the population an encoding needs, or a feature
/// method the recordings cannot support (a speed missing for `all-taxels-mm`).
pub fn candidates(
    encoded: &[Encoded],
    grid: &Grid,
    params: &PipelineParams,
    set: &CandidateSet,
    encode_s: f64,
) -> Result<Vec<Candidate>> {
    let pairs = set.pairs();
    let mut out = Vec::new();
    let mut van_rossum = PopulationMatrices::new(set.tau_ms)?;
    for &encoding in &set.encodings {
        let view = population_view(encoded, encoding);
        let params = PipelineParams {
            encoding,
            ..params.clone()
        };
        let extractor = FeatureExtractor::new(&params, grid)?;
        let mut methods: Vec<MethodChoice> = pairs.iter().map(|p| p.0).collect();
        methods.dedup();
        let share = encode_s / (set.encodings.len() * methods.len()).max(1) as f64;
        for method in methods {
            let start = Instant::now();
            let made = (&view[..], encoding, &extractor);
            let samples = method_samples(made, method, &pairs, &mut van_rossum)?;
            let prepare_s = share + start.elapsed().as_secs_f64();
            let metas = Arc::new(samples.metas().to_vec());
            for &(_, classifier) in pairs.iter().filter(|p| p.0 == method) {
                out.push(Candidate {
                    encoding: encoding.name().to_string(),
                    method: method.name().to_string(),
                    classifier: classifier.name().to_string(),
                    metas: Arc::clone(&metas),
                    evaluate: evaluator(classifier, samples.clone())?,
                    prepare_s,
                });
            }
        }
    }
    Ok(out)
}

/// The samples `method` makes of the recordings `view` (one encoding's view): its feature
/// table (every taxel alone for the single-taxel method), the van Rossum matrix, or the
/// spike inputs at the spiking network's step (that of the `spikes` method's pair in
/// `pairs`).
///
/// # Errors
/// A feature method the recordings cannot support, or populations an encoding lacks.
fn method_samples(
    (view, encoding, extractor): (&[Encoded], Encoding, &FeatureExtractor),
    method: MethodChoice,
    pairs: &[(MethodChoice, ClassifierChoice)],
    van_rossum: &mut PopulationMatrices,
) -> Result<MethodSamples> {
    let columns = match method {
        MethodChoice::Features(Method::Taxel) => Columns::EachTaxel,
        _ => Columns::All,
    };
    let snn: Vec<SnnParams> = pairs
        .iter()
        .filter_map(|p| match p {
            (MethodChoice::Spikes, ClassifierChoice::Snn(s)) => Some(*s),
            _ => None,
        })
        .collect();
    let step_ms = crate::samples::input_step_ms(view, &snn);
    let made = (view, encoding, extractor);
    MethodSamples::of(made, method, columns, step_ms, || {
        van_rossum.matrix(view, encoding)
    })
}
