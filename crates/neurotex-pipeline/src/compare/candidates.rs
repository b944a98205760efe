//! The candidates of a comparison made from encoded recordings: for each encoding, each
//! feature method's table is built once and shared by every classifier; the spike-timing
//! method's distance matrix is computed once per population and shared by the encodings.

use std::sync::Arc;
use std::time::Instant;

use super::evaluator::{evaluator, Shared};
use super::Candidate;
use crate::analysis::{Columns, FeatureTable};
use crate::classify::{
    ClassifierChoice, DistanceMatrix, ForestParams, KnnParams, VanRossum, VanRossumParams,
};
use crate::encode::SpikeTrains;
use crate::error::{ParamError, Result};
use crate::pipeline::{Encoded, Encoding, FeatureExtractor, Method, PipelineParams};
use crate::snn::{SnnParams, SpikeInput};
use crate::values::Grid;

/// The spike-timing method's name.
pub const VAN_ROSSUM: &str = "van-rossum";
/// The spike trains themselves, the spiking classifier's input.
pub const SPIKES: &str = "spikes";

/// A feature method, or the spike-timing method.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MethodChoice {
    /// Feature rows of a [`Method`].
    Features(Method),
    /// KNN over van Rossum distances between the recordings' spike trains.
    VanRossum,
    /// The spike trains as they are, for the spiking classifier (`snn`).
    Spikes,
}

impl MethodChoice {
    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            MethodChoice::Features(m) => m.name(),
            MethodChoice::VanRossum => VAN_ROSSUM,
            MethodChoice::Spikes => SPIKES,
        }
    }
}

impl std::str::FromStr for MethodChoice {
    type Err = ParamError;
    fn from_str(s: &str) -> Result<Self, ParamError> {
        if s == VAN_ROSSUM {
            return Ok(MethodChoice::VanRossum);
        }
        if s == SPIKES {
            return Ok(MethodChoice::Spikes);
        }
        s.parse().map(MethodChoice::Features).map_err(|_| {
            let rule = "method must be taxel, all-taxels, all-taxels-mm, glcm2d, glcm3d, glcm3d-multi, spectrum, van-rossum or spikes";
            ParamError::new("methods", rule, s)
        })
    }
}

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
/// The van Rossum time constant by default: the rate volume's 200 ms bin, the time
/// resolution the paper's rate code keeps (chosen a priori, not on any data).
pub const STANDARD_TAU_MS: f64 = 200.0;

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
            let table = Arc::new(match method {
                MethodChoice::Features(m) => FeatureTable::build(&view, &extractor, m)?,
                MethodChoice::VanRossum | MethodChoice::Spikes => index_table(&view, grid),
            });
            let shared = match method {
                MethodChoice::VanRossum => Shared::Distances(van_rossum.matrix(&view, encoding)?),
                MethodChoice::Spikes => Shared::Spikes(spike_inputs(&view, encoding, &pairs)?),
                MethodChoice::Features(_) => Shared::None,
            };
            let prepare_s = share + start.elapsed().as_secs_f64();
            for &(_, classifier) in pairs.iter().filter(|p| p.0 == method) {
                out.push(Candidate {
                    encoding: encoding.name().to_string(),
                    method: method.name().to_string(),
                    classifier: classifier.name().to_string(),
                    table: Arc::clone(&table),
                    columns: match method {
                        MethodChoice::Features(Method::Taxel) => Columns::EachTaxel,
                        _ => Columns::All,
                    },
                    evaluate: evaluator(classifier, shared.clone())?,
                    prepare_s,
                });
            }
        }
    }
    Ok(out)
}

/// Every recording's spikes under `encoding` binned to the spiking network's time step
/// (that of the `spikes` method's pair in `pairs`).
fn spike_inputs(
    view: &[Encoded],
    encoding: Encoding,
    pairs: &[(MethodChoice, ClassifierChoice)],
) -> Result<Arc<Vec<SpikeInput>>> {
    let dt_ms = pairs
        .iter()
        .find_map(|p| match p {
            (MethodChoice::Spikes, ClassifierChoice::Snn(s)) => Some(s.dt_ms),
            _ => None,
        })
        .unwrap_or(SnnParams::default().dt_ms);
    let inputs = view
        .iter()
        .map(|e| {
            let pops: Vec<&SpikeTrains> = match encoding {
                Encoding::SaFa => e.populations().collect(),
                _ => vec![&e.spikes],
            };
            if encoding == Encoding::SaFa && pops.len() < 2 {
                let rule = "the sa+fa encoding needs both populations of every recording";
                return Err(ParamError::new("encodings", rule, "one population"));
            }
            Ok(SpikeInput::from_trains(&pops, dt_ms))
        })
        .collect::<Result<Vec<_>, ParamError>>()?;
    Ok(Arc::new(inputs))
}

/// The recordings as `encoding` sees them: for `fa` alone, the fast-adapting population
/// as the first (and only) one.
fn population_view(encoded: &[Encoded], encoding: Encoding) -> Vec<Encoded> {
    encoded
        .iter()
        .map(|e| match (encoding, &e.fa) {
            (Encoding::Fa, Some(fa)) => Encoded {
                spikes: fa.clone(),
                fa: None,
                ..e.clone()
            },
            _ => e.clone(),
        })
        .collect()
}

/// The table of the spike-timing method: each recording's row index into the distance
/// matrix, the "feature" [`SpikeDistanceKnn`] looks up.
fn index_table(encoded: &[Encoded], grid: &Grid) -> FeatureTable {
    FeatureTable {
        // Not a feature method: the field is not read for a table of row indices.
        method: Method::Glcm3d,
        grid: grid.clone(),
        names: vec!["row".into()],
        metas: encoded.iter().map(|e| e.meta.clone()).collect(),
        values: (0..encoded.len()).map(|i| i as f64).collect(),
    }
}

/// The van Rossum distances between every two recordings of each population, computed
/// once and shared by the encodings that use it: `sa` and `sa+fa` read the same SA matrix.
struct PopulationMatrices {
    metric: VanRossum,
    /// The first population's matrix (the SA neurons, or the FA neurons of `fa` alone).
    first: Option<Arc<DistanceMatrix>>,
    /// The FA population's matrix, as `sa+fa` adds it.
    fa: Option<Arc<DistanceMatrix>>,
}

impl PopulationMatrices {
    fn new(tau_ms: f64) -> Result<Self> {
        Ok(PopulationMatrices {
            metric: VanRossumParams { tau_ms }.check()?,
            first: None,
            fa: None,
        })
    }

    /// The distances over `encoding`'s populations of `view` (the recordings as
    /// [`population_view`] gives them): with `sa+fa` the squared distances of the two
    /// populations add, as those of the taxels do.
    fn matrix(&mut self, view: &[Encoded], encoding: Encoding) -> Result<Arc<DistanceMatrix>> {
        let trains = |pick: fn(&Encoded) -> Option<&SpikeTrains>| -> Vec<SpikeTrains> {
            view.iter().filter_map(|e| pick(e).cloned()).collect()
        };
        if encoding == Encoding::Fa {
            // The view's first population is then the FA one: a matrix of its own.
            return Ok(Arc::new(self.metric.matrix(&trains(|e| Some(&e.spikes)))?));
        }
        let sa = match &self.first {
            Some(m) => Arc::clone(m),
            None => {
                let m = Arc::new(self.metric.matrix(&trains(|e| Some(&e.spikes)))?);
                self.first.insert(m).clone()
            }
        };
        if encoding != Encoding::SaFa {
            return Ok(sa);
        }
        let fa = match &self.fa {
            Some(m) => Arc::clone(m),
            None => {
                let fa = trains(|e| e.fa.as_ref());
                if fa.len() != view.len() {
                    let rule = "the sa+fa encoding needs both populations of every recording";
                    return Err(ParamError::new("encodings", rule, "one population").into());
                }
                self.fa.insert(Arc::new(self.metric.matrix(&fa)?)).clone()
            }
        };
        let values = sa
            .values()
            .iter()
            .zip(fa.values())
            .map(|(a, b)| (a * a + b * b).sqrt())
            .collect();
        Ok(Arc::new(DistanceMatrix::from_values(sa.n(), values)?))
    }
}
