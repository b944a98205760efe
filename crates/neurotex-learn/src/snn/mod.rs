//! A spiking classifier: a feed-forward network of current-based leaky integrate-and-fire
//! (LIF) neurons read out by non-spiking leaky integrators, trained with surrogate
//! gradients through time (Zenke & Ganguli 2018, SuperSpike; Neftci, Mostafa & Zenke 2019).
//! Its input is the encoder's spike trains, one input per taxel and population, binned to
//! the network's time step ([`SpikeInput`]); no feature is computed.
//!
//! **The network** (discrete time, step `dt`; `α = e^{-dt/τ_syn}`, `β = e^{-dt/τ_mem}`,
//! `κ = e^{-dt/τ_out}`, threshold 1, reset to 0):
//!
//! ```text
//! I[t] = α I[t-1] + W_in x[t] + b_in        synaptic current of each hidden neuron
//! P[t] = β V[t-1] + I[t]                     membrane before the spike
//! S[t] = H(P[t] - 1)                         spike
//! V[t] = P[t] (1 - S[t])                     reset to zero
//! O[t] = κ O[t-1] + W_out S[t] + b_out       leaky readout, one per class
//! ```
//!
//! With [`SnnParams::train_decays`] each hidden neuron has decays of its own, `α_h` and
//! `β_h` ([`Network::alpha`], [`Network::beta`]), trained beside the weights. With
//! [`SnnParams::delay_ms`] each input synapse carries its spikes a trained delay late
//! ([`Network::delays`], [`delay`]): `W_in x[t]` becomes each spike's weight split between
//! the two steps its delay falls between.
//!
//! With [`Reset::Subtract`] a neuron instead emits `S[t] = ⌊P[t]⌋` spikes when `P[t] ≥ 1`
//! (none below) and keeps the rest, `V[t] = P[t] - S[t]`: the multi-spike neuron with
//! subtractive reset of sinabs, Rockpool and SynSense's Xylo, so that a network trained
//! with it runs unchanged there. The readout and a recurrent layer receive the count.
//!
//! A class's score is the **mean of its readout over time** ([`Readout::Mean`]): a texture
//! slid over the skin is a stationary process, so evidence is gathered over the whole
//! window rather than at the one most confident step ([`Readout::Max`], Zenke & Vogels
//! 2021, is the option). The running mean is what a stream reads as its window grows.
//!
//! **Training** ([`train`]): softmax cross-entropy on the scores, gradients by
//! backpropagation through time written out in [`grad`] (`H'` replaced by the fast-sigmoid
//! surrogate `1 / (1 + slope |P - 1|)²` of SuperSpike), Adam on mini-batches, and early
//! stopping on a stratified validation split drawn from the training data. Reset is
//! detached from the graph by default, as Zenke & Vogels (2021) recommend.

pub mod delay;
pub mod grad;
pub mod train;
pub mod xylo;

mod input;
mod params;
mod run;
mod travel;

use serde::{Deserialize, Serialize};

use crate::error::{ModelError, ParamError};

pub use input::SpikeInput;
pub use params::{SnnParams, MAX_HIDDEN};
pub use run::{Runner, State, Windowed};
pub use train::{fit, fit_with};
pub use travel::{event_weight, step_ms, Travel};
pub use xylo::Target;

/// How a class's score is read from its readout trace.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Readout {
    /// The mean over the window's steps (the default).
    Mean,
    /// The largest value over the window's steps.
    Max,
}

impl Readout {
    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Readout::Mean => "mean",
            Readout::Max => "max",
        }
    }
}

impl std::str::FromStr for Readout {
    type Err = ParamError;
    fn from_str(s: &str) -> Result<Self, ParamError> {
        match s {
            "mean" => Ok(Readout::Mean),
            "max" => Ok(Readout::Max),
            _ => Err(ParamError::new(
                "snn-readout",
                "readout must be mean or max",
                s,
            )),
        }
    }
}

/// How a hidden neuron resets when its membrane reaches the threshold.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Reset {
    /// One spike at most per step, the membrane set to zero (the default).
    #[default]
    Zero,
    /// `n = ⌊P⌋` spikes in a step, `n` subtracted from the membrane (sinabs, Rockpool,
    /// Xylo).
    Subtract,
}

impl Reset {
    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Reset::Zero => "zero",
            Reset::Subtract => "subtract",
        }
    }

    /// Whether this is the default reset to zero (which model files leave out).
    pub fn is_zero(&self) -> bool {
        *self == Reset::Zero
    }
}

impl std::str::FromStr for Reset {
    type Err = ParamError;
    fn from_str(s: &str) -> Result<Self, ParamError> {
        match s {
            "zero" => Ok(Reset::Zero),
            "subtract" => Ok(Reset::Subtract),
            _ => Err(ParamError::new(
                "snn-reset",
                "reset must be zero or subtract",
                s,
            )),
        }
    }
}

/// The network's weights and constants: everything prediction needs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Network {
    /// Inputs (taxels x populations).
    pub inputs: usize,
    /// Hidden LIF neurons.
    pub hidden: usize,
    /// Classes (readout neurons).
    pub classes: usize,
    /// The time step, ms.
    pub dt_ms: u32,
    /// Synaptic, membrane and readout time constants, ms.
    pub tau_syn_ms: f64,
    /// Membrane time constant, ms.
    pub tau_mem_ms: f64,
    /// Readout time constant, ms.
    pub tau_out_ms: f64,
    /// How scores are read.
    pub readout: Readout,
    /// How a hidden neuron resets on a spike; absent (zero) in the files of networks that
    /// reset to zero.
    #[serde(default, skip_serializing_if = "Reset::is_zero")]
    pub reset: Reset,
    /// Input weights, input-major: `w_in[i * hidden + h]` from input `i` to neuron `h`.
    pub w_in: Vec<f64>,
    /// Hidden biases (a constant current each step).
    pub b_in: Vec<f64>,
    /// Readout weights, hidden-major: `w_out[h * classes + c]` from neuron `h` to class `c`.
    pub w_out: Vec<f64>,
    /// Readout biases.
    pub b_out: Vec<f64>,
    /// Recurrent weights, hidden-major: `w_rec[j * hidden + h]` from neuron `j`'s spike of
    /// one step to neuron `h`'s current at the next; empty for a feed-forward network.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub w_rec: Vec<f64>,
    /// Where the network runs; absent (float) in the files of float networks.
    #[serde(default, skip_serializing_if = "Target::is_float")]
    pub target: Target,
    /// Each hidden neuron's synaptic decay per step `α_h`, when the decays were trained
    /// ([`SnnParams::train_decays`]; the shared time constants then say where the neurons
    /// started from); empty: every neuron's is `α` of `tau_syn_ms`. Absent from the files
    /// of networks whose neurons share their decays.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub alpha: Vec<f64>,
    /// Each hidden neuron's membrane decay per step `β_h`, as [`Network::alpha`]; empty:
    /// every neuron's is `β` of `tau_mem_ms`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub beta: Vec<f64>,
    /// The speed, mm/s, at which the network's steps last `dt_ms`, when it counts time in
    /// travel ([`Travel`]): a recording slid at `v` mm/s is binned in steps of
    /// `dt_ms x travel_mm_s / |v|` ms. Absent: steps of `dt_ms` whatever the speed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub travel_mm_s: Option<f64>,
    /// Adaptive thresholds (ALIF): each hidden neuron's threshold rises with its recent
    /// spikes. Absent: a fixed threshold of 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub adaptation: Option<Adaptation>,
    /// Each input synapse's delay in steps, input-major as `w_in` (learnable delays,
    /// [`SnnParams::delay_ms`]; [`delay`] has the arithmetic). Absent from the files of
    /// networks whose inputs drive the hidden layer in the step they arrive.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub delays: Vec<f64>,
}

/// Adaptive thresholds (Bellec et al. 2020): a neuron's threshold is `1 + b a[t]`, its
/// adaptation `a[t+1] = ρ a[t] + (1 - ρ) S[t]` (a low-passed spike rate, 0 to 1), with
/// `ρ = e^{-dt/τ_a}`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Adaptation {
    /// The adaptation's time constant `τ_a`, ms.
    pub tau_ms: f64,
    /// How far the threshold rises at a full spike rate, `b`.
    pub strength: f64,
}

impl Adaptation {
    /// `(ρ, b)` for steps of `dt_ms`.
    pub fn per_step(&self, dt_ms: u32) -> (f64, f64) {
        ((-f64::from(dt_ms) / self.tau_ms).exp(), self.strength)
    }
}

/// The smallest and largest decay per step trained decays are kept within: time constants
/// from about a seventh of a step to a thousand steps.
pub const TRAINED_DECAYS: (f64, f64) = (0.001, 0.999);

impl Network {
    /// The decay factors `(α, β, κ)` of one step.
    pub fn decays(&self) -> (f64, f64, f64) {
        let dt = f64::from(self.dt_ms);
        (
            (-dt / self.tau_syn_ms).exp(),
            (-dt / self.tau_mem_ms).exp(),
            (-dt / self.tau_out_ms).exp(),
        )
    }

    /// How long, in ms, this network's step lasts for a recording slid at `speed_mm_s`
    /// ([`step_ms`]).
    ///
    /// # Errors
    /// A network counting time in travel, and no nonzero speed.
    pub fn step_ms(&self, speed_mm_s: Option<f64>) -> Result<f64, String> {
        step_ms(self.dt_ms, self.travel_mm_s, speed_mm_s)
    }

    /// The step's rules: 1 to 1000 ms, and a reference speed, when it counts in travel,
    /// positive and finite.
    fn check_steps(&self) -> Result<(), ModelError> {
        if !(1..=1000).contains(&self.dt_ms) {
            let why = format!(
                "the network's dt_ms is {}; the time step must be 1 to 1000 ms",
                self.dt_ms
            );
            return Err(ModelError::network("dt_ms", why));
        }
        match self.travel_mm_s.filter(|v| !(*v > 0.0 && v.is_finite())) {
            Some(v) => Err(ModelError::network("travel_mm_s", format!("the network's reference speed travel_mm_s is {v}; it must be positive and finite"))),
            None => Ok(()),
        }
    }

    /// Whether the hidden layer has recurrent connections.
    pub fn recurrent(&self) -> bool {
        !self.w_rec.is_empty()
    }

    /// Whether each hidden neuron has decays of its own ([`Network::alpha`],
    /// [`Network::beta`]).
    pub fn own_decays(&self) -> bool {
        !self.alpha.is_empty()
    }

    /// Each hidden neuron's synaptic and membrane decays per step, `(α_h, β_h)`: its own,
    /// or those of the shared time constants.
    pub fn hidden_decays(&self) -> (Vec<f64>, Vec<f64>) {
        if self.own_decays() {
            return (self.alpha.clone(), self.beta.clone());
        }
        let (alpha, beta, _) = self.decays();
        (vec![alpha; self.hidden], vec![beta; self.hidden])
    }

    /// Every trained parameter: `w_in`, `b_in`, `w_out`, `b_out`, `w_rec` (empty when
    /// feed-forward), `alpha` and `beta` (empty when the neurons share their decays) and
    /// `delays` (empty without delays).
    pub fn params_mut(&mut self) -> [&mut Vec<f64>; 8] {
        [
            &mut self.w_in,
            &mut self.b_in,
            &mut self.w_out,
            &mut self.b_out,
            &mut self.w_rec,
            &mut self.alpha,
            &mut self.beta,
            &mut self.delays,
        ]
    }

    /// Checks what training guarantees: the shapes, a time step of 1 to 1000 ms, time
    /// constants whose decays lie strictly between 0 and 1, and weights a float32 holds.
    ///
    /// # Errors
    /// [`ModelError::Network`]: the rule broken, as a sentence naming the field.
    pub fn check(&self) -> Result<(), ModelError> {
        let shapes = [
            (
                "w_in",
                self.w_in.len(),
                self.inputs.checked_mul(self.hidden),
            ),
            ("b_in", self.b_in.len(), Some(self.hidden)),
            (
                "w_out",
                self.w_out.len(),
                self.hidden.checked_mul(self.classes),
            ),
            ("b_out", self.b_out.len(), Some(self.classes)),
        ];
        for (name, got, want) in shapes {
            if Some(got) != want {
                let want = want.map_or("more than memory holds".into(), |w| w.to_string());
                return Err(ModelError::network(
                    name,
                    format!("the network's {name} holds {got} values, not {want}"),
                ));
            }
        }
        let square = self.hidden.saturating_mul(self.hidden);
        if self.recurrent() && self.w_rec.len() != square {
            let got = self.w_rec.len();
            return Err(ModelError::network(
                "w_rec",
                format!("the network's w_rec holds {got} values, not hidden x hidden = {square} (or none)"),
            ));
        }
        let layers = [
            ("inputs", self.inputs),
            ("hidden", self.hidden),
            ("classes", self.classes),
        ];
        if let Some((layer, _)) = layers.iter().find(|(_, n)| *n == 0) {
            let why = format!("the network has an empty layer: its {layer} is 0");
            return Err(ModelError::network(layer, why));
        }
        self.check_steps()?;
        self.check_taus()?;
        self.check_own_decays()?;
        self.check_adaptation()?;
        self.check_delays()?;
        if self.target == Target::Xylo {
            xylo::check(self)?;
        }
        for (name, w) in [
            ("w_in", &self.w_in),
            ("b_in", &self.b_in),
            ("w_out", &self.w_out),
            ("b_out", &self.b_out),
            ("w_rec", &self.w_rec),
        ] {
            // Training rounds every weight to float32 (what NIR and NumPy files hold); a
            // larger one is damage, and could overflow a readout's sum to infinity.
            if let Some(pos) = w
                .iter()
                .position(|v| !v.is_finite() || v.abs() > f64::from(f32::MAX))
            {
                return Err(ModelError::network(
                    name,
                    format!(
                        "the network's {name}[{pos}] is {:?}, not a finite float32 value",
                        w[pos]
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Checks that each time constant is positive and finite and gives a decay per step
    /// strictly between 0 and 1 (a decay of 0 or 1 has no continuous-time constant, so no
    /// NIR graph). The one exception is `tau_syn_ms` 0, a hidden layer without synaptic
    /// memory (`α = 0`: the current is the step's input), which is how a NIR graph's LIF
    /// hidden node (snnTorch's `Leaky`, Norse's `LIFBoxCell`) reads.
    fn check_taus(&self) -> Result<(), ModelError> {
        let (alpha, beta, kappa) = self.decays();
        for (name, tau, decay) in [
            ("tau_syn_ms", self.tau_syn_ms, alpha),
            ("tau_mem_ms", self.tau_mem_ms, beta),
            ("tau_out_ms", self.tau_out_ms, kappa),
        ] {
            let memoryless = name == "tau_syn_ms" && tau == 0.0;
            let decays = tau > 0.0 && tau.is_finite() && decay > 0.0 && decay < 1.0;
            if !(memoryless || decays) {
                return Err(ModelError::network(name, format!(
                    "the network's {name} is {tau:?}, which gives the decay {decay} per step of {} ms; a time constant must be positive and finite, its decay strictly between 0 and 1",
                    self.dt_ms
                )));
            }
        }
        Ok(())
    }

    /// Checks each neuron's own decays, when it has them: one per hidden neuron in both
    /// `alpha` and `beta`, each `β_h` strictly between 0 and 1 and each `α_h` at least 0
    /// (a synapse without memory, as a NIR graph's LIF node reads) and under 1.
    fn check_own_decays(&self) -> Result<(), ModelError> {
        if self.alpha.is_empty() && self.beta.is_empty() {
            return Ok(());
        }
        for (name, d) in [("alpha", &self.alpha), ("beta", &self.beta)] {
            if d.len() != self.hidden {
                return Err(ModelError::network(name, format!(
                    "the network's {name} holds {} decays, not one per hidden neuron ({}); both alpha and beta, or neither",
                    d.len(),
                    self.hidden
                )));
            }
            let low_ok = |v: f64| if name == "alpha" { v >= 0.0 } else { v > 0.0 };
            if let Some(pos) = d.iter().position(|&v| !(low_ok(v) && v < 1.0)) {
                return Err(ModelError::network(name, format!(
                    "the network's {name}[{pos}] is {:?}; a decay per step must lie between 0 and 1 (alpha may be 0)",
                    d[pos]
                )));
            }
        }
        Ok(())
    }

    /// Adaptive thresholds' rules: a positive finite time constant and strength, neurons
    /// that reset to zero, and a float network.
    fn check_adaptation(&self) -> Result<(), ModelError> {
        let Some(a) = self.adaptation else {
            return Ok(());
        };
        let why = if !(a.tau_ms > 0.0 && a.tau_ms.is_finite()) {
            format!(
                "the network's adaptation.tau_ms is {:?}; it must be positive and finite",
                a.tau_ms
            )
        } else if !(a.strength > 0.0 && a.strength.is_finite()) {
            format!(
                "the network's adaptation.strength is {:?}; it must be positive and finite",
                a.strength
            )
        } else if self.reset != Reset::Zero || self.target != Target::Float {
            "a network with adaptive thresholds resets to zero and runs in float (no `reset` or `target` key)".to_string()
        } else {
            return Ok(());
        };
        Err(ModelError::network("adaptation", why))
    }

    /// Delays' rules: one per input synapse, each finite and 0 to [`delay::MAX_DELAY_STEPS`]
    /// steps, in a float network.
    fn check_delays(&self) -> Result<(), ModelError> {
        if self.delays.is_empty() {
            return Ok(());
        }
        let (n, want) = (self.delays.len(), self.inputs.saturating_mul(self.hidden));
        let why = if n != want {
            format!("the network's delays holds {n} values, not inputs x hidden = {want} (or none)")
        } else if let Some(pos) =
            (self.delays.iter()).position(|d| !(*d >= 0.0 && *d <= delay::MAX_DELAY_STEPS))
        {
            format!(
                "the network's delays[{pos}] is {:?}; a delay must be 0 to {} steps",
                self.delays[pos],
                delay::MAX_DELAY_STEPS
            )
        } else if self.target != Target::Float {
            "a network with delays runs in float (no `target` key)".to_string()
        } else {
            return Ok(());
        };
        Err(ModelError::network("delays", why))
    }

    /// A running copy of the network, for spikes that arrive step by step.
    pub fn runner(&self) -> Runner<'_> {
        Runner {
            net: self,
            state: State::new(self),
            acc: vec![0.0; self.classes],
            steps: 0,
        }
    }

    /// The class scores of a whole window.
    ///
    /// # Panics
    /// If the input's width is not the network's (a caller bug).
    pub fn scores(&self, input: &SpikeInput) -> Vec<f64> {
        assert_eq!(input.inputs, self.inputs);
        let mut run = self.runner();
        run.state.scale = input.scale();
        for t in 0..input.steps() {
            run.step(input.at(t));
        }
        run.scores()
    }

    /// Reduces readout values over time to scores as [`Network::readout`] says: their mean
    /// or their largest value, class by class, in the order given (zeros for none).
    fn reduce<'r>(&self, readouts: impl Iterator<Item = &'r [f64]>) -> Vec<f64> {
        let mut acc = vec![0.0; self.classes];
        let mut n = 0usize;
        for out in readouts {
            self.readout.fold(n, &mut acc, out);
            n += 1;
        }
        self.readout.finish(n, acc)
    }
}

impl Readout {
    /// Folds the `n`-th step's (0-based) readout values `out` into `acc`.
    pub(crate) fn fold(self, n: usize, acc: &mut [f64], out: &[f64]) {
        for (a, &o) in acc.iter_mut().zip(out) {
            *a = match (self, n) {
                (Readout::Mean, _) => *a + o,
                (Readout::Max, 0) => o,
                (Readout::Max, _) => a.max(o),
            };
        }
    }

    /// The scores of `n` steps folded into `acc`.
    pub(crate) fn finish(self, n: usize, mut acc: Vec<f64>) -> Vec<f64> {
        if self == Readout::Mean {
            let n = n.max(1) as f64;
            acc.iter_mut().for_each(|a| *a /= n);
        }
        acc
    }
}

/// A value per hidden neuron: one for all (`f64`), or each its own (`&[f64]`).
pub(crate) trait PerNeuron: Copy {
    /// The first `n` neurons' (indexed below `n` without a bounds check in the loops).
    fn first(self, n: usize) -> Self;
    fn at(self, k: usize) -> f64;
}

impl PerNeuron for f64 {
    #[inline(always)]
    fn first(self, _: usize) -> Self {
        self
    }

    #[inline(always)]
    fn at(self, _: usize) -> f64 {
        self
    }
}

impl PerNeuron for &[f64] {
    #[inline(always)]
    fn first(self, n: usize) -> Self {
        &self[..n]
    }

    #[inline(always)]
    fn at(self, k: usize) -> f64 {
        self[k]
    }
}

/// `I = α I + b` for each hidden neuron, with the decays `alpha` (one per neuron): each
/// neuron's own when `own`, else the first for all, stepped as one number rather than a load
/// per neuron. The training pass and the runner both step so, with the same bits.
#[inline(always)]
pub(crate) fn decay_currents(current: &mut [f64], b: &[f64], alpha: &[f64], own: bool) {
    match own {
        true => decay_currents_by(current, b, alpha),
        false => decay_currents_by(current, b, alpha[0]),
    }
}

#[inline(always)]
fn decay_currents_by<D: PerNeuron>(current: &mut [f64], b: &[f64], alpha: D) {
    // Indexed over slices of one length, so that the loop vectorises.
    let n = current.len();
    let (b, alpha) = (&b[..n], alpha.first(n));
    for k in 0..n {
        current[k] = alpha.at(k) * current[k] + b[k];
    }
}

/// Adds the input weights of the inputs `spiked` to the currents, each times `scale` (what
/// one event adds; 1, a spike, but for steps of travel). The training pass and the runner
/// both add them so, with the same bits; a scale of 1 adds the weights themselves.
#[inline(always)]
pub(crate) fn add_inputs(current: &mut [f64], w_in: &[f64], spiked: &[u32], scale: f64) {
    let h_n = current.len();
    let rows = spiked
        .iter()
        .map(|&i| &w_in[i as usize * h_n..(i as usize + 1) * h_n]);
    // One test per step, not per event: the loops stay those of unweighed spikes.
    match scale == 1.0 {
        true => rows.for_each(|w| current.iter_mut().zip(w).for_each(|(c, w)| *c += w)),
        false => rows.for_each(|w| current.iter_mut().zip(w).for_each(|(c, w)| *c += scale * w)),
    }
}

/// Adds a step's delayed input drive to the currents and clears it for the steps to come
/// (the training pass and the runner, with the same bits).
#[inline(always)]
pub(crate) fn take_drive(current: &mut [f64], drive: &mut [f64]) {
    let n = current.len();
    let drive = &mut drive[..n];
    for k in 0..n {
        current[k] += drive[k];
        drive[k] = 0.0;
    }
}

/// The gradient of [`add_inputs`]: each input that spiked gains the currents' gradient
/// `g_i`, times `scale` (`1 x g` is `g`, bit for bit).
#[inline(always)]
pub(crate) fn add_inputs_gradient(g_w: &mut [f64], g_i: &[f64], spiked: &[u32], scale: f64) {
    let h_n = g_i.len();
    for &i in spiked {
        let gw = &mut g_w[i as usize * h_n..(i as usize + 1) * h_n];
        gw.iter_mut().zip(g_i).for_each(|(gw, g)| *gw += scale * g);
    }
}

/// Softmax of scores (shifted by their largest value, so nothing overflows).
pub fn softmax(scores: &[f64]) -> Vec<f64> {
    let top = scores.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let exp: Vec<f64> = scores.iter().map(|s| (s - top).exp()).collect();
    let sum: f64 = exp.iter().sum();
    exp.iter().map(|e| e / sum).collect()
}

/// Adds the readout rows of the hidden neurons in `fired` (rows of `w_out`, one per hidden
/// neuron, `out.len()` classes each), each times the neuron's spikes in `spikes`, to `out`,
/// in the order of `fired`. Up to eight classes are summed in registers, one class per
/// lane: summed in `out` itself, each spike's sums waited for the stores of the one before
/// (a fifth of the forward pass). Each class's sum runs in the same order either way.
#[inline(always)]
pub(crate) fn add_readout(out: &mut [f64], w_out: &[f64], spikes: &[f64], fired: &[u32]) {
    match out.len() {
        1 => add_readout_in::<1>(out, w_out, spikes, fired),
        2 => add_readout_in::<2>(out, w_out, spikes, fired),
        3 => add_readout_in::<3>(out, w_out, spikes, fired),
        4 => add_readout_in::<4>(out, w_out, spikes, fired),
        5 => add_readout_in::<5>(out, w_out, spikes, fired),
        6 => add_readout_in::<6>(out, w_out, spikes, fired),
        7 => add_readout_in::<7>(out, w_out, spikes, fired),
        8 => add_readout_in::<8>(out, w_out, spikes, fired),
        c_n => {
            for &h in fired {
                let (s, w) = (spikes[h as usize], &w_out[h as usize * c_n..][..c_n]);
                out.iter_mut().zip(w).for_each(|(o, w)| *o += s * w);
            }
        }
    }
}

/// [`add_readout`] for `N` classes, summed in a local array the compiler keeps in
/// registers.
#[inline(always)]
fn add_readout_in<const N: usize>(out: &mut [f64], w_out: &[f64], spikes: &[f64], fired: &[u32]) {
    let mut sum = [0.0; N];
    sum.copy_from_slice(&out[..N]);
    for &h in fired {
        let s = spikes[h as usize];
        let w = &w_out[h as usize * N..][..N];
        for k in 0..N {
            sum[k] += s * w[k];
        }
    }
    out[..N].copy_from_slice(&sum);
}

/// The positions of `s`'s values that are not zero, in order, put in `at`. Each block of
/// [`MASKED`] values becomes a mask of one bit per value (compares that vectorise), and the
/// positions are read off its set bits: a step's spikes are irregular, so a branch per value
/// would often be mispredicted, and writing a position for every value cost a
/// quarter of the forward pass.
#[inline(always)]
pub(super) fn nonzero<'a>(s: &[f64], at: &'a mut Vec<u32>) -> &'a [u32] {
    // Every slot up to the last position is written below before it is read.
    if at.len() < s.len() {
        at.resize(s.len(), 0);
    }
    let mut n = 0;
    let (blocks, rest) = s.as_chunks::<MASKED>();
    for (b, block) in blocks.iter().enumerate() {
        let mut bits = 0u64;
        for (k, &x) in block.iter().enumerate() {
            bits |= u64::from(x != 0.0) << k;
        }
        while bits != 0 {
            at[n] = (b * MASKED) as u32 + bits.trailing_zeros();
            n += 1;
            bits &= bits - 1;
        }
    }
    let first = blocks.len() * MASKED;
    for (j, &x) in rest.iter().enumerate() {
        at[n] = (first + j) as u32;
        n += usize::from(x != 0.0);
    }
    &at[..n]
}

/// Values per mask in [`nonzero`]: the bits of a `u64`.
const MASKED: usize = 64;
