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

pub mod grad;
pub mod train;
pub mod xylo;

use serde::{Deserialize, Serialize};

use crate::error::ParamError;
use crate::spikes::SpikeTrains;

pub use train::fit;
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

/// The spiking classifier's parameters (defaults chosen a priori;
/// `docs/spiking-classifier.md` gives the reasons).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SnnParams {
    /// Hidden LIF neurons (128).
    pub hidden: usize,
    /// The network's time step in ms (10): the encoder's 1 ms spikes are counted in bins
    /// of this width.
    pub dt_ms: u32,
    /// Synaptic time constant, ms (20).
    pub tau_syn_ms: f64,
    /// Membrane time constant, ms (40).
    pub tau_mem_ms: f64,
    /// Readout time constant, ms (40).
    pub tau_out_ms: f64,
    /// How scores are read from the readout.
    pub readout: Readout,
    /// Most passes over the training data (60).
    pub epochs: usize,
    /// Recordings per gradient step (8).
    pub batch: usize,
    /// Adam's step size (0.005).
    pub learning_rate: f64,
    /// Share of each class's training recordings held out for early stopping (0.2).
    pub validation: f64,
    /// Epochs without a better validation loss before training stops (15).
    pub patience: usize,
    /// Slope of the fast-sigmoid surrogate (10).
    pub slope: f64,
    /// Keep the reset out of the gradient (true).
    pub detach_reset: bool,
    /// Seed of the initial weights, the validation split and the batch order.
    pub seed: u64,
    /// Recurrent connections within the hidden layer (false: feed-forward): each
    /// neuron's spikes of one step drive every hidden neuron's current at the next.
    pub recurrent: bool,
    /// How a hidden neuron resets on a spike (zero); left out of model files when zero,
    /// so that they read as before the option existed.
    #[serde(skip_serializing_if = "Reset::is_zero")]
    pub reset: Reset,
    /// Where the network runs (float); with [`Target::Xylo`] it is trained within the
    /// chip's limits and predicts as the chip computes ([`xylo`]). Left out of model files
    /// when float.
    #[serde(skip_serializing_if = "Target::is_float")]
    pub target: Target,
}

impl Default for SnnParams {
    fn default() -> Self {
        SnnParams {
            hidden: 128,
            dt_ms: 10,
            tau_syn_ms: 20.0,
            tau_mem_ms: 40.0,
            tau_out_ms: 40.0,
            readout: Readout::Mean,
            epochs: 60,
            batch: 8,
            learning_rate: 0.005,
            validation: 0.2,
            patience: 15,
            slope: 10.0,
            detach_reset: true,
            seed: 0,
            recurrent: false,
            reset: Reset::Zero,
            target: Target::Float,
        }
    }
}

/// Largest hidden layer accepted: beyond it a model file and a training run grow past
/// what these small tactile datasets can fit.
pub const MAX_HIDDEN: usize = 4096;

impl SnnParams {
    /// Checks the rules and returns the parameters.
    ///
    /// # Errors
    /// The first rule broken, named by its command-line option.
    pub fn check(self) -> Result<SnnParams, ParamError> {
        let positive = |v: f64| v > 0.0 && v.is_finite();
        if self.hidden == 0 || self.hidden > MAX_HIDDEN {
            let rule = "the hidden layer must hold 1 to 4096 neurons";
            return Err(ParamError::new("snn-hidden", rule, self.hidden));
        }
        if self.dt_ms == 0 || self.dt_ms > 1000 {
            let rule = "the time step must be 1 to 1000 ms";
            return Err(ParamError::new("snn-dt-ms", rule, self.dt_ms));
        }
        for (name, v) in [
            ("snn-tau-syn-ms", self.tau_syn_ms),
            ("snn-tau-mem-ms", self.tau_mem_ms),
            ("snn-tau-out-ms", self.tau_out_ms),
        ] {
            if !positive(v) {
                return Err(ParamError::new(
                    name,
                    "a time constant must be positive and finite",
                    v,
                ));
            }
        }
        if self.epochs == 0 || self.batch == 0 || self.patience == 0 {
            let rule = "epochs, batch and patience must be at least 1";
            let got = format!("{} / {} / {}", self.epochs, self.batch, self.patience);
            return Err(ParamError::new("snn-epochs", rule, got));
        }
        if !positive(self.learning_rate) || !positive(self.slope) {
            let rule = "the learning rate and the surrogate's slope must be positive and finite";
            let got = format!("{} / {}", self.learning_rate, self.slope);
            return Err(ParamError::new("snn-learning-rate", rule, got));
        }
        if !(self.validation > 0.0 && self.validation < 1.0) {
            let rule = "the validation share must lie strictly between 0 and 1";
            return Err(ParamError::new("snn-validation", rule, self.validation));
        }
        match self.target {
            Target::Float => Ok(self),
            Target::Xylo => self.on_xylo(),
        }
    }

    /// The parameters under the Xylo profile: its limits checked, each time constant moved
    /// to the nearest whose decay per step the chip has (`1 - 2^-d`).
    fn on_xylo(mut self) -> Result<SnnParams, ParamError> {
        let rules = [
            ("snn-hidden", self.hidden > xylo::MAX_HIDDEN, "the Xylo profile holds at most 1000 hidden neurons", self.hidden.to_string()),
            ("snn-dt-ms", self.dt_ms > xylo::MAX_DT_MS, "the Xylo profile steps at most 15 ms (an input carries at most 15 events a step)", self.dt_ms.to_string()),
            ("snn-reset", self.reset != Reset::Subtract, "the Xylo profile's neurons subtract the threshold on a spike: --snn-reset subtract", self.reset.name().to_string()),
            ("snn-recurrent", self.recurrent, "the Xylo profile runs feed-forward networks", "--snn-recurrent".to_string()),
        ];
        if let Some((name, _, rule, got)) = rules.into_iter().find(|r| r.1) {
            return Err(ParamError::new(name, rule, got));
        }
        for tau in [
            &mut self.tau_syn_ms,
            &mut self.tau_mem_ms,
            &mut self.tau_out_ms,
        ] {
            *tau = xylo::tau_of(xylo::dash_of(*tau, self.dt_ms), self.dt_ms);
        }
        Ok(self)
    }

    /// The decay factors `(α, β, κ)` of one step.
    pub fn decays(&self) -> (f64, f64, f64) {
        let dt = f64::from(self.dt_ms);
        (
            (-dt / self.tau_syn_ms).exp(),
            (-dt / self.tau_mem_ms).exp(),
            (-dt / self.tau_out_ms).exp(),
        )
    }
}

/// A recording's spikes as the network's input: for each step of `dt` ms, the inputs that
/// spiked in it (an input spiking twice in one step is listed twice). Input `p * taxels +
/// k` is population `p`'s (SA, then FA) `k`-th taxel in row-major grid order.
#[derive(Debug, Clone, PartialEq)]
pub struct SpikeInput {
    /// Inputs (taxels x populations).
    pub inputs: usize,
    /// `offsets[t]..offsets[t + 1]` indexes step `t`'s events in `events`.
    offsets: Vec<u32>,
    events: Vec<u32>,
}

impl SpikeInput {
    /// Bins `populations` (one or two grids of the same taxels) to steps of `dt_ms`; the
    /// last step may be partial. The window's steps are `ceil(n_steps / dt_ms)` of the
    /// first population.
    ///
    /// # Panics
    /// If there is no population or `dt_ms` is 0 (caller bugs).
    pub fn from_trains(populations: &[&SpikeTrains], dt_ms: u32) -> SpikeInput {
        assert!(!populations.is_empty() && dt_ms > 0);
        let dt = dt_ms as usize;
        let steps = populations[0].n_steps.div_ceil(dt);
        let mut lists: Vec<(u32, u32)> = Vec::new();
        let mut input = 0u32;
        for pop in populations {
            for cell in (0..pop.cells()).filter(|&c| pop.present[c]) {
                for &t in pop.train(cell) {
                    lists.push(((t as usize / dt).min(steps.saturating_sub(1)) as u32, input));
                }
                input += 1;
            }
        }
        lists.sort_unstable();
        SpikeInput::from_events(input as usize, steps, &lists)
    }

    /// Builds the input from `(step, input)` events sorted by step.
    ///
    /// # Panics
    /// If an event's step or input is out of range or the events are unsorted (caller bugs).
    pub fn from_events(inputs: usize, steps: usize, events: &[(u32, u32)]) -> SpikeInput {
        assert!(events.windows(2).all(|w| w[0].0 <= w[1].0));
        let mut offsets = vec![0u32; steps + 1];
        for &(t, i) in events {
            assert!((t as usize) < steps && (i as usize) < inputs);
            offsets[t as usize + 1] += 1;
        }
        for t in 0..steps {
            offsets[t + 1] += offsets[t];
        }
        SpikeInput {
            inputs,
            offsets,
            events: events.iter().map(|e| e.1).collect(),
        }
    }

    /// Steps in the window.
    pub fn steps(&self) -> usize {
        self.offsets.len() - 1
    }

    /// The inputs that spiked in step `t`.
    pub fn at(&self, t: usize) -> &[u32] {
        &self.events[self.offsets[t] as usize..self.offsets[t + 1] as usize]
    }

    /// Spikes in the window.
    pub fn total(&self) -> usize {
        self.events.len()
    }

    /// The window as a dense `steps x inputs` table of spike counts, row-major (what a
    /// network's input node receives, step by step).
    pub fn dense(&self) -> Vec<f32> {
        let mut out = vec![0f32; self.steps() * self.inputs];
        for t in 0..self.steps() {
            for &i in self.at(t) {
                out[t * self.inputs + i as usize] += 1.0;
            }
        }
        out
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
}

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

    /// Whether the hidden layer has recurrent connections.
    pub fn recurrent(&self) -> bool {
        !self.w_rec.is_empty()
    }

    /// Every weight and bias: `w_in`, `b_in`, `w_out`, `b_out`, `w_rec` (empty when
    /// feed-forward).
    pub fn params_mut(&mut self) -> [&mut Vec<f64>; 5] {
        [
            &mut self.w_in,
            &mut self.b_in,
            &mut self.w_out,
            &mut self.b_out,
            &mut self.w_rec,
        ]
    }

    /// Checks what training guarantees: the shapes, a time step of 1 to 1000 ms, time
    /// constants whose decays lie strictly between 0 and 1, and weights a float32 holds.
    ///
    /// # Errors
    /// The rule broken, as a sentence naming the field.
    pub fn check(&self) -> Result<(), String> {
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
                return Err(format!(
                    "the network's {name} holds {got} values, not {want}"
                ));
            }
        }
        let square = self.hidden.saturating_mul(self.hidden);
        if self.recurrent() && self.w_rec.len() != square {
            let got = self.w_rec.len();
            return Err(format!(
                "the network's w_rec holds {got} values, not hidden x hidden = {square} (or none)"
            ));
        }
        if self.inputs == 0 || self.hidden == 0 || self.classes == 0 {
            return Err("the network has an empty layer".into());
        }
        if !(1..=1000).contains(&self.dt_ms) {
            return Err(format!(
                "the network's dt_ms is {}; the time step must be 1 to 1000 ms",
                self.dt_ms
            ));
        }
        self.check_taus()?;
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
                return Err(format!(
                    "the network's {name}[{pos}] is {:?}, not a finite float32 value",
                    w[pos]
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
    fn check_taus(&self) -> Result<(), String> {
        let (alpha, beta, kappa) = self.decays();
        for (name, tau, decay) in [
            ("tau_syn_ms", self.tau_syn_ms, alpha),
            ("tau_mem_ms", self.tau_mem_ms, beta),
            ("tau_out_ms", self.tau_out_ms, kappa),
        ] {
            let memoryless = name == "tau_syn_ms" && tau == 0.0;
            let decays = tau > 0.0 && tau.is_finite() && decay > 0.0 && decay < 1.0;
            if !(memoryless || decays) {
                return Err(format!(
                    "the network's {name} is {tau:?}, which gives the decay {decay} per step of {} ms; a time constant must be positive and finite, its decay strictly between 0 and 1",
                    self.dt_ms
                ));
            }
        }
        Ok(())
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

/// The network's neuron state, advanced one step at a time; it owns no weights, so it can
/// live beside the network that drives it.
#[derive(Debug, Clone, PartialEq)]
pub struct State {
    decays: (f64, f64, f64),
    current: Vec<f64>,
    membrane: Vec<f64>,
    out: Vec<f64>,
    /// The hidden neurons that spiked in the last step, ascending, with their spike
    /// counts (kept for a recurrent network).
    fired: Vec<(u32, f64)>,
    /// A Xylo-profile network's integers and the chip's state, which then step in place
    /// of the float state.
    chip: Option<Box<(xylo::XyloNetwork, xylo::XyloState)>>,
}

impl State {
    /// The network at rest.
    ///
    /// # Panics
    /// If `net` is a Xylo-profile network that breaks the profile's rules (a network is
    /// checked when trained or read, so a caller bug).
    pub fn new(net: &Network) -> Self {
        let chip = (net.target == Target::Xylo).then(|| {
            let chip = xylo::XyloNetwork::quantise(net).expect("a checked Xylo-profile network");
            let state = xylo::XyloState::new(&chip);
            Box::new((chip, state))
        });
        State {
            decays: net.decays(),
            current: vec![0.0; net.hidden],
            membrane: vec![0.0; net.hidden],
            out: vec![0.0; net.classes],
            fired: Vec::new(),
            chip,
        }
    }

    /// Advances one step of `net` (the network this state was made for) with the inputs
    /// that spiked in it, listed in ascending order for results that do not depend on how
    /// the spikes arrived.
    ///
    /// # Panics
    /// If an input index is out of range (a caller bug).
    pub fn step(&mut self, net: &Network, spiked: &[u32]) {
        if let Some(chip) = self.chip.as_deref_mut() {
            let (xnet, state) = (&chip.0, &mut chip.1);
            state.step(xnet, spiked);
            self.out = state.readout(xnet);
            return;
        }
        let (alpha, beta, kappa) = self.decays;
        let h_n = net.hidden;
        for (c, b) in self.current.iter_mut().zip(&net.b_in) {
            *c = alpha * *c + b;
        }
        for &i in spiked {
            let w = &net.w_in[i as usize * h_n..(i as usize + 1) * h_n];
            for (c, w) in self.current.iter_mut().zip(w) {
                *c += w;
            }
        }
        for &(j, n) in &self.fired {
            let w = &net.w_rec[j as usize * h_n..(j as usize + 1) * h_n];
            for (c, w) in self.current.iter_mut().zip(w) {
                *c += n * w;
            }
        }
        self.fired.clear();
        let recurrent = net.recurrent();
        for (o, b) in self.out.iter_mut().zip(&net.b_out) {
            *o = kappa * *o + b;
        }
        let subtract = net.reset == Reset::Subtract;
        for h in 0..h_n {
            let p = beta * self.membrane[h] + self.current[h];
            if p >= 1.0 {
                // One spike and a membrane of zero, or floor(p) spikes and the rest kept
                // (a count of 1 multiplies the weights exactly).
                let n = if subtract { p.floor() } else { 1.0 };
                self.membrane[h] = if subtract { p - n } else { 0.0 };
                if recurrent {
                    self.fired.push((h as u32, n));
                }
                let w = &net.w_out[h * net.classes..(h + 1) * net.classes];
                for (o, w) in self.out.iter_mut().zip(w) {
                    *o += n * w;
                }
            } else {
                self.membrane[h] = p;
            }
        }
    }

    /// The readout's values after the last step.
    pub fn readout(&self) -> &[f64] {
        &self.out
    }
}

/// The network's state, advanced one step at a time, with the scores of every step so far.
#[derive(Debug, Clone)]
pub struct Runner<'a> {
    net: &'a Network,
    state: State,
    /// The readout's sum (mean) or largest value (max) so far.
    acc: Vec<f64>,
    steps: usize,
}

impl Runner<'_> {
    /// Advances one step with the inputs that spiked in it (see [`State::step`]).
    ///
    /// # Panics
    /// If an input index is out of range (a caller bug).
    pub fn step(&mut self, spiked: &[u32]) {
        self.state.step(self.net, spiked);
        let readout = self.net.readout;
        readout.fold(self.steps, &mut self.acc, self.state.readout());
        self.steps += 1;
    }

    /// Steps run so far.
    pub fn steps(&self) -> usize {
        self.steps
    }

    /// The class scores so far (zeros before the first step).
    pub fn scores(&self) -> Vec<f64> {
        self.net.readout.finish(self.steps, self.acc.clone())
    }
}

/// A network run on spikes as they come, its scores read over its last `window` steps:
/// the readout's mean or largest value over those steps (over every step while fewer have
/// run), while the neurons carry their state from the first step. For a run no longer than
/// the window, the scores are [`Network::scores`]'s, bit for bit.
#[derive(Debug, Clone)]
pub struct Windowed {
    state: State,
    window: usize,
    /// The readout values of the last `window` steps, oldest first.
    readouts: std::collections::VecDeque<Vec<f64>>,
    steps: usize,
}

impl Windowed {
    /// `net` at rest, its scores read over `window` steps (at least one).
    pub fn new(net: &Network, window: usize) -> Self {
        Windowed {
            state: State::new(net),
            window: window.max(1),
            readouts: std::collections::VecDeque::with_capacity(window.clamp(1, 1 << 16)),
            steps: 0,
        }
    }

    /// Advances one step of `net` (see [`State::step`]).
    pub fn step(&mut self, net: &Network, spiked: &[u32]) {
        self.state.step(net, spiked);
        let mut oldest = match self.readouts.len() == self.window {
            true => self.readouts.pop_front().unwrap_or_default(),
            false => Vec::with_capacity(net.classes),
        };
        oldest.clear();
        oldest.extend_from_slice(self.state.readout());
        self.readouts.push_back(oldest);
        self.steps += 1;
    }

    /// Steps run so far.
    pub fn steps(&self) -> usize {
        self.steps
    }

    /// The class scores over the window (zeros before the first step).
    pub fn scores(&self, net: &Network) -> Vec<f64> {
        net.reduce(self.readouts.iter().map(Vec::as_slice))
    }
}

/// Softmax of scores (shifted by their largest value, so nothing overflows).
pub fn softmax(scores: &[f64]) -> Vec<f64> {
    let top = scores.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let exp: Vec<f64> = scores.iter().map(|s| (s - top).exp()).collect();
    let sum: f64 = exp.iter().sum();
    exp.iter().map(|e| e / sum).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One input, one hidden neuron, one class: an input weight of 2.7 drives the membrane
    /// to 2.7 in the first step.
    fn one_neuron(reset: Reset, w_rec: Vec<f64>) -> Network {
        Network {
            inputs: 1,
            hidden: 1,
            classes: 1,
            dt_ms: 10,
            tau_syn_ms: 20.0,
            tau_mem_ms: 40.0,
            tau_out_ms: 40.0,
            readout: Readout::Mean,
            reset,
            w_in: vec![2.7],
            b_in: vec![0.0],
            w_out: vec![0.25],
            b_out: vec![0.0],
            w_rec,
            target: Target::Float,
        }
    }

    /// A strong input makes a subtracting neuron spike twice in one step and keep 0.7; the
    /// readout and the recurrent current receive both spikes. Reset to zero, the same
    /// neuron spikes once and keeps nothing.
    #[test]
    fn subtract_emits_several_spikes_in_a_step_and_keeps_the_rest() {
        for (reset, spikes, kept) in [(Reset::Subtract, 2.0, 2.7 - 2.0), (Reset::Zero, 1.0, 0.0)] {
            let net = one_neuron(reset, vec![0.5]);
            let mut state = State::new(&net);
            state.step(&net, &[0]);
            assert_eq!(state.membrane, [kept], "{reset:?}");
            assert_eq!(state.readout(), [spikes * 0.25], "{reset:?}");
            assert_eq!(state.fired, [(0, spikes)], "{reset:?}");
            let (alpha, _, _) = net.decays();
            state.step(&net, &[]);
            assert_eq!(state.current, [alpha * 2.7 + spikes * 0.5], "{reset:?}");
        }
    }

    /// Below the threshold nothing fires and the membrane is kept, whatever the reset.
    #[test]
    fn subtract_below_threshold_keeps_the_membrane() {
        let mut net = one_neuron(Reset::Subtract, Vec::new());
        net.w_in = vec![0.6];
        let mut state = State::new(&net);
        state.step(&net, &[0]);
        assert_eq!(state.membrane, [0.6]);
        assert_eq!(state.readout(), [0.0]);
    }

    /// The reset's names and its file form: `subtract` is written, `zero` left out of a
    /// network's file, and a file without it reads as zero.
    #[test]
    fn reset_parses_and_zero_is_left_out_of_files() {
        assert_eq!("subtract".parse::<Reset>().unwrap(), Reset::Subtract);
        assert_eq!("zero".parse::<Reset>().unwrap(), Reset::Zero);
        assert_eq!("Zero".parse::<Reset>().unwrap_err().name, "snn-reset");
        let zero = serde_json::to_value(one_neuron(Reset::Zero, Vec::new())).unwrap();
        assert!(zero.get("reset").is_none());
        let back: Network = serde_json::from_value(zero).unwrap();
        assert_eq!(back.reset, Reset::Zero);
        let sub = serde_json::to_value(one_neuron(Reset::Subtract, Vec::new())).unwrap();
        assert_eq!(sub["reset"], "subtract");
        let params = serde_json::to_value(SnnParams::default()).unwrap();
        assert!(params.get("reset").is_none());
    }
}
