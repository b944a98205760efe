//! The network run step by step: its state, a runner that gathers the scores as spikes
//! arrive, and a window that keeps the last steps' readouts.

use super::{xylo, Network, PerNeuron, Reset, Target};

/// The network's neuron state, advanced one step at a time; it owns no weights, so it can
/// live beside the network that drives it.
#[derive(Debug, Clone, PartialEq)]
pub struct State {
    /// The readout's decay `κ`.
    kappa: f64,
    /// Each hidden neuron's synaptic and membrane decays.
    alpha: Vec<f64>,
    beta: Vec<f64>,
    current: Vec<f64>,
    membrane: Vec<f64>,
    out: Vec<f64>,
    /// The hidden neurons that spiked in the last step, ascending, with their spike
    /// counts (kept for a recurrent network).
    fired: Vec<(u32, f64)>,
    /// A Xylo-profile network's integers and the chip's state, which then step in place
    /// of the float state.
    chip: Option<Box<(xylo::XyloNetwork, xylo::XyloState)>>,
    /// Scratch of a step: each hidden neuron's spike count, and the neurons that spiked.
    counts: Vec<f64>,
    active: Vec<u32>,
    /// What one input event adds ([`SpikeInput::scale`](super::SpikeInput::scale)).
    pub(super) scale: f64,
    /// Adaptive thresholds' `(ρ, b)` and each neuron's adaptation.
    adapt: Option<(f64, f64)>,
    level: Vec<f64>,
    /// Delays, the drive of the steps ahead in a ring of their reach, and the steps run.
    delays: Option<Box<super::delay::Delays>>,
    drive: Vec<f64>,
    t: usize,
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
        let (alpha, beta) = net.hidden_decays();
        let delays = super::delay::Delays::of(net);
        State {
            kappa: net.decays().2,
            alpha,
            beta,
            current: vec![0.0; net.hidden],
            membrane: vec![0.0; net.hidden],
            out: vec![0.0; net.classes],
            fired: Vec::new(),
            chip,
            counts: vec![0.0; net.hidden],
            active: Vec::with_capacity(net.hidden),
            scale: 1.0,
            adapt: net.adaptation.map(|a| a.per_step(net.dt_ms)),
            level: vec![0.0; net.adaptation.map_or(0, |_| net.hidden)],
            drive: vec![0.0; delays.as_ref().map_or(0, |d| d.reach * net.hidden)],
            delays: delays.map(Box::new),
            t: 0,
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
        float_step(self, net, spiked);
    }

    /// The readout's values after the last step.
    pub fn readout(&self) -> &[f64] {
        &self.out
    }
}

neurotex_core::widest_or_plain! {
    ["avx512f", "avx2"]
    /// [`State::step`] of a float network, compiled for the widest vectors the processor
    /// has (each operation element by element, so every width gives the same bits): the
    /// membranes and spike counts of every neuron first, then the readout and recurrent
    /// rows of those that spiked, in neuron order. The same operations in the same order
    /// as the training's forward pass, so its scores are those of training.
    fn float_step(state: &mut State, net: &Network, spiked: &[u32]) {
        let kappa = state.kappa;
        let h_n = net.hidden;
        // Neurons that share their decays step with two numbers (see `grad`'s loops).
        let own = net.own_decays();
        let (alpha, beta) = (&state.alpha[..h_n], &state.beta[..h_n]);
        let current = &mut state.current[..h_n];
        super::decay_currents(current, &net.b_in, alpha, own);
        match state.delays.as_deref() {
            None => super::add_inputs(current, &net.w_in, spiked, state.scale),
            Some(d) => {
                let (t, reach) = (state.t, d.reach);
                d.add_ring(&mut state.drive, t, spiked, state.scale);
                let row = (t % reach) * h_n;
                super::take_drive(current, &mut state.drive[row..row + h_n]);
                state.t += 1;
            }
        }
        for &(j, n) in &state.fired {
            let w = &net.w_rec[j as usize * h_n..(j as usize + 1) * h_n];
            for (c, w) in current.iter_mut().zip(w) {
                *c += n * w;
            }
        }
        state.fired.clear();
        for (o, b) in state.out.iter_mut().zip(&net.b_out) {
            *o = kappa * *o + b;
        }
        // One spike and a membrane of zero, or floor(p) spikes and the rest kept (a count
        // of 1 multiplies the weights exactly; `p (1 - 0)` and `p - 0` are `p`).
        let subtract = net.reset == Reset::Subtract;
        let (membrane, counts) = (&mut state.membrane[..h_n], &mut state.counts[..h_n]);
        match (own, state.adapt) {
            (true, Some(rho_b)) => fire_adaptive(membrane, counts, current, beta, &mut state.level, rho_b),
            (false, Some(rho_b)) => fire_adaptive(membrane, counts, current, beta[0], &mut state.level, rho_b),
            (true, None) => fire(membrane, counts, current, beta, subtract),
            (false, None) => fire(membrane, counts, current, beta[0], subtract),
        }
        let active = super::nonzero(counts, &mut state.active);
        if net.recurrent() {
            state.fired.extend(active.iter().map(|&h| (h, counts[h as usize])));
        }
        super::add_readout(&mut state.out, &net.w_out, counts, active);
    }
}

/// Each hidden neuron's membrane `P = β V + I`, its spike count and the membrane it keeps.
#[inline(always)]
fn fire(
    membrane: &mut [f64],
    counts: &mut [f64],
    current: &[f64],
    beta: impl PerNeuron,
    subtract: bool,
) {
    let n = membrane.len();
    let (counts, current, beta) = (&mut counts[..n], &current[..n], beta.first(n));
    for h in 0..n {
        let p = beta.at(h) * membrane[h] + current[h];
        let n = match (p >= 1.0, subtract) {
            (false, _) => 0.0,
            (true, true) => p.floor(),
            (true, false) => 1.0,
        };
        counts[h] = n;
        membrane[h] = if subtract { p - n } else { p * (1.0 - n) };
    }
}

/// [`fire`] with adaptive thresholds (reset to zero), as the training's forward pass.
#[inline(always)]
fn fire_adaptive(
    membrane: &mut [f64],
    counts: &mut [f64],
    current: &[f64],
    beta: impl PerNeuron,
    level: &mut [f64],
    (rho, b): (f64, f64),
) {
    let n = membrane.len();
    let (counts, current, beta, level) = (
        &mut counts[..n],
        &current[..n],
        beta.first(n),
        &mut level[..n],
    );
    for h in 0..n {
        let p = beta.at(h) * membrane[h] + current[h];
        let s = f64::from(u8::from(p - b * level[h] - 1.0 >= 0.0));
        counts[h] = s;
        membrane[h] = p * (1.0 - s);
        level[h] = rho * level[h] + (1.0 - rho) * s;
    }
}

/// The network's state, advanced one step at a time, with the scores of every step so far.
#[derive(Debug, Clone)]
pub struct Runner<'a> {
    pub(super) net: &'a Network,
    pub(super) state: State,
    /// The readout's sum (mean) or largest value (max) so far.
    pub(super) acc: Vec<f64>,
    pub(super) steps: usize,
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::snn::{Readout, SnnParams};

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
            alpha: Vec::new(),
            beta: Vec::new(),
            travel_mm_s: None,
            adaptation: None,
            delays: Vec::new(),
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
