//! The methods and what the spike methods read: [`MethodChoice`] names a feature method,
//! `van-rossum` or `spikes`, and checks its pairing with a classifier; the `spikes` method
//! gives every recording's [`SpikeInput`] at the spiking network's step, or at 1 ms for
//! networks that rebin them to steps of travel ([`spike_inputs`]), `van-rossum` the
//! distances between the recordings ([`PopulationMatrices`]). [`crate::analysis::MethodSamples`] gathers them with the
//! feature tables.

use std::sync::Arc;

use crate::classify::{ClassifierChoice, DistanceMatrix, SpikeSamples, VanRossum, VanRossumParams};
use crate::encode::SpikeTrains;
use crate::error::{ParamError, Result};
use crate::pipeline::{Encoded, Encoding, Method};
use crate::snn::{SnnParams, SpikeInput, Travel};

/// The spike-timing method's name.
pub const VAN_ROSSUM: &str = "van-rossum";
/// The spike trains themselves, the spiking classifier's input.
pub const SPIKES: &str = "spikes";
/// The van Rossum time constant by default: the rate volume's 200 ms bin, the time
/// resolution the paper's rate code keeps (chosen a priori, not on any data).
pub const STANDARD_TAU_MS: f64 = 200.0;

/// A feature method, or a method whose samples are the spikes themselves.
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

    /// The method a classifier reads when none is named: the spike trains for the spiking
    /// network, `default` for the others.
    pub fn for_classifier(classifier: &ClassifierChoice, default: MethodChoice) -> MethodChoice {
        match classifier {
            ClassifierChoice::Snn(_) => MethodChoice::Spikes,
            _ => default,
        }
    }

    /// Checks that `classifier` reads this method's samples: feature rows for KNN, the
    /// forest and logistic regression; van Rossum distances for KNN; spike inputs for the
    /// spiking network.
    ///
    /// # Errors
    /// A pairing that does not run, naming the ones that do.
    pub fn check_pairing(self, classifier: &ClassifierChoice) -> Result<(), ParamError> {
        let fits = match self {
            MethodChoice::VanRossum => matches!(classifier, ClassifierChoice::Knn(_)),
            MethodChoice::Spikes => matches!(classifier, ClassifierChoice::Snn(_)),
            MethodChoice::Features(_) => !matches!(classifier, ClassifierChoice::Snn(_)),
        };
        match fits {
            true => Ok(()),
            false => Err(ParamError::new(
                "classifier",
                "van-rossum classifies with knn, spikes with snn (the spiking network), and the feature methods with knn, forest or linear",
                format!("{} with the {} method", classifier.name(), self.name()),
            )),
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
            let rule = "method must be taxel, all-taxels, all-taxels-mm, glcm2d, glcm3d, glcm3d-multi, spectrum, rates, van-rossum or spikes";
            ParamError::new("methods", rule, s)
        })
    }
}

/// The step, ms, the spike inputs of the recordings `view` are binned to for the networks
/// `snn`: their one `dt_ms` when no fit rebins them (every network counts time in ms, or
/// at the median speed and every recording slides at the same speed), 1 ms otherwise, to
/// be rebinned to each fit's steps of travel.
pub fn input_step_ms(view: &[Encoded], snn: &[SnnParams]) -> u32 {
    let dt = snn.first().map_or(SnnParams::default().dt_ms, |p| p.dt_ms);
    let speed = |e: &Encoded| e.meta.speed_mm_s.map(f64::abs);
    let one_speed = view
        .iter()
        .all(|e| speed(e) == view.first().and_then(speed));
    let in_ms = |p: &SnnParams| p.travel.is_off() || (p.travel == Travel::Median && one_speed);
    match snn.iter().all(|p| p.dt_ms == dt && in_ms(p)) {
        true => dt,
        false => 1,
    }
}

/// Every recording's spikes under `encoding` binned to `step_ms` steps ([`input_step_ms`]),
/// the spiking network's input, with their sliding speeds.
///
/// # Errors
/// `sa+fa` on recordings encoded with one population.
pub fn spike_inputs(view: &[Encoded], encoding: Encoding, step_ms: u32) -> Result<SpikeSamples> {
    let inputs = view
        .iter()
        .map(|e| {
            let pops: Vec<&SpikeTrains> = match encoding {
                Encoding::SaFa => e.populations().collect(),
                _ => vec![&e.spikes],
            };
            if encoding == Encoding::SaFa && pops.len() < 2 {
                let rule = "the sa+fa encoding needs both populations of every recording";
                return Err(ParamError::new("encodings", rule, "one population").into());
            }
            Ok(SpikeInput::from_trains(&pops, step_ms))
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(SpikeSamples {
        inputs,
        speeds: view.iter().map(|e| e.meta.speed_mm_s).collect(),
        step_ms,
    })
}

/// The recordings as `encoding` sees them: for `fa` alone, the fast-adapting population
/// as the first (and only) one.
pub fn population_view(encoded: &[Encoded], encoding: Encoding) -> Vec<Encoded> {
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

/// The van Rossum distances between every two recordings of each population, computed
/// once and shared by the encodings that use it: `sa` and `sa+fa` read the same SA matrix.
pub struct PopulationMatrices {
    metric: VanRossum,
    /// The first population's matrix (the SA neurons, or the FA neurons of `fa` alone).
    first: Option<Arc<DistanceMatrix>>,
    /// The FA population's matrix, as `sa+fa` adds it.
    fa: Option<Arc<DistanceMatrix>>,
}

impl PopulationMatrices {
    /// No matrix yet, for the kernel's time constant `tau_ms`.
    ///
    /// # Errors
    /// A time constant that is not positive and finite.
    pub fn new(tau_ms: f64) -> Result<Self> {
        Ok(PopulationMatrices {
            metric: VanRossumParams { tau_ms }.check()?,
            first: None,
            fa: None,
        })
    }

    /// The distances over `encoding`'s populations of `view` (the recordings as
    /// [`population_view`] gives them): with `sa+fa` the squared distances of the two
    /// populations add, as those of the taxels do.
    ///
    /// # Errors
    /// Recordings of different grids, or `sa+fa` without both populations.
    pub fn matrix(&mut self, view: &[Encoded], encoding: Encoding) -> Result<Arc<DistanceMatrix>> {
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
