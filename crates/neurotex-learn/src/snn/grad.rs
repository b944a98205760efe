//! The loss of one recording and its gradient by backpropagation through time, written out
//! by hand: the networks are small (tens of inputs, about a hundred hidden neurons, a few
//! classes) and their inputs sparse, so a loop over steps that touches only the inputs
//! that spiked is faster than a dense tensor graph, and needs no autodiff framework in the
//! build (`docs/spiking-classifier.md` weighs the two).
//!
//! With `g` the loss's gradient and the forward pass of [`super`]:
//!
//! ```text
//! gO[t] = ∂L/∂O[t] + κ gO[t+1]                   readout, backwards
//! gS[t] = W_out gO[t] + W_rec gI[t+1]  (- P[t] gV[t] unless the reset is detached)
//! gP[t] = gV[t] (1 - S[t]) + gS[t] H'(P[t] - 1)  H' the surrogate
//! gI[t] = gP[t] + α gI[t+1]
//! gV[t-1] = β gP[t]
//! ∂L/∂W_in += gI[t] x[t]ᵀ, ∂L/∂b_in += gI[t], ∂L/∂W_out += S[t] gO[t]ᵀ, ∂L/∂b_out += gO[t]
//! ∂L/∂W_rec += S[t-1] gI[t]ᵀ                      (recurrent networks)
//! ∂L/∂α_h += gI[t]_h I[t-1]_h, ∂L/∂β_h += gP[t]_h V[t-1]_h   (each neuron's own decays)
//! ```
//!
//! `I[t-1]` and `V[t-1]` are not kept: they are made again from the kept membranes and
//! spikes, `V[t] = P[t] (1 - S[t])` (or `P[t] - S[t]`) and `I[t] = P[t] - β V[t-1]`.
//!
//! With synaptic delays the input's line `∂L/∂W_in += gI[t] x[t]ᵀ` reads each spike's
//! `gI` at the steps its delay reaches, and the delays gain theirs ([`super::delay`]).
//!
//! With the subtractive reset (`V[t] = P[t] - S[t]`, `S[t]` a count), the spike's
//! derivative is the same surrogate and the membrane line becomes
//!
//! ```text
//! gP[t] = gV[t] + gS[t] H'(P[t] - 1)                 reset detached
//! gP[t] = gV[t] (1 - H'(P[t] - 1)) + gS[t] H'(P[t] - 1)  reset in the graph
//! ```
//!
//! With adaptive thresholds (`S[t] = H(P[t] - 1 - b a[t])`, `a[t+1] = ρ a[t] + (1 - ρ) S[t]`,
//! reset to zero) the spike's gradient gains the adaptation's, which runs back in time:
//!
//! ```text
//! gS̃[t] = gS[t] + (1 - ρ) ga[t+1]
//! gP[t] = gV[t] (1 - S[t]) + gS̃[t] H'(P[t] - 1 - b a[t])
//! ga[t] = ρ ga[t+1] - b gS̃[t] H'(P[t] - 1 - b a[t])
//! ```

use super::{softmax, Network, PerNeuron, Readout, Reset, SpikeInput};

/// The spike nonlinearity of the forward pass and the derivative the backward pass uses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Activation {
    /// A spike when the membrane reaches the threshold; the fast-sigmoid surrogate
    /// `1 / (1 + slope |x|)²` stands in for its derivative (SuperSpike).
    Spike {
        /// The surrogate's slope.
        slope: f64,
    },
    /// A smooth logistic `1 / (1 + e^{-k x})` with its exact derivative: a network whose
    /// loss is differentiable, so the backward pass can be checked against finite
    /// differences.
    Smooth {
        /// The logistic's steepness.
        k: f64,
    },
}

impl Activation {
    fn value(self, x: f64) -> f64 {
        match self {
            Activation::Spike { .. } => f64::from(u8::from(x >= 0.0)),
            Activation::Smooth { k } => 1.0 / (1.0 + (-k * x).exp()),
        }
    }

    fn derivative(self, x: f64) -> f64 {
        match self {
            Activation::Spike { slope } => {
                let d = 1.0 + slope * x.abs();
                1.0 / (d * d)
            }
            Activation::Smooth { k } => {
                let s = self.value(x);
                k * s * (1.0 - s)
            }
        }
    }
}

/// How the backward pass treats the spike: the nonlinearity and whether the reset is kept
/// out of the gradient.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Backprop {
    /// The spike nonlinearity and its derivative.
    pub act: Activation,
    /// Keep the reset out of the gradient (Zenke & Vogels 2021).
    pub detach_reset: bool,
}

/// Gradients of the loss with respect to the network's parameters, laid out as they are.
#[derive(Debug, Clone, PartialEq)]
pub struct Gradient {
    /// ∂L/∂W_in, input-major.
    pub w_in: Vec<f64>,
    /// ∂L/∂b_in.
    pub b_in: Vec<f64>,
    /// ∂L/∂W_out, hidden-major.
    pub w_out: Vec<f64>,
    /// ∂L/∂b_out.
    pub b_out: Vec<f64>,
    /// ∂L/∂W_rec, hidden-major (empty for a feed-forward network).
    pub w_rec: Vec<f64>,
    /// ∂L/∂α_h (empty when the neurons share their decays).
    pub alpha: Vec<f64>,
    /// ∂L/∂β_h (empty when the neurons share their decays).
    pub beta: Vec<f64>,
    /// ∂L/∂d_ih, input-major (empty without delays).
    pub delays: Vec<f64>,
}

impl Gradient {
    /// Zeros shaped as `net`.
    pub fn zeros(net: &Network) -> Gradient {
        Gradient {
            w_in: vec![0.0; net.w_in.len()],
            b_in: vec![0.0; net.b_in.len()],
            w_out: vec![0.0; net.w_out.len()],
            b_out: vec![0.0; net.b_out.len()],
            w_rec: vec![0.0; net.w_rec.len()],
            alpha: vec![0.0; net.alpha.len()],
            beta: vec![0.0; net.beta.len()],
            delays: vec![0.0; net.delays.len()],
        }
    }

    /// Adds `other` to this gradient.
    pub fn add(&mut self, other: &Gradient) {
        for (a, b) in self.parts_mut().into_iter().zip(other.parts()) {
            for (x, y) in a.iter_mut().zip(b) {
                *x += y;
            }
        }
    }

    /// The parts in the order of [`Network::params_mut`] (w_in, b_in, w_out, b_out, w_rec,
    /// alpha, beta, delays).
    pub fn parts(&self) -> [&[f64]; 8] {
        [
            &self.w_in,
            &self.b_in,
            &self.w_out,
            &self.b_out,
            &self.w_rec,
            &self.alpha,
            &self.beta,
            &self.delays,
        ]
    }

    /// The parts, mutable, in the same order.
    pub fn parts_mut(&mut self) -> [&mut Vec<f64>; 8] {
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
}

/// What the forward pass keeps for the backward pass: each step's membrane before the
/// spike, the spike, and the readout.
#[derive(Debug, Default)]
pub struct Trajectory {
    pre: Vec<f64>,
    spikes: Vec<f64>,
    out: Vec<f64>,
    /// Each step's threshold rise `b a[t]` (adaptive thresholds only).
    shift: Vec<f64>,
    /// With delays: the input drive of every step ahead (zero between passes), and the
    /// backward pass's current gradients of every step.
    drive: Vec<f64>,
    g_drive: Vec<f64>,
}

neurotex_core::widest_or_plain! {
    ["avx512f", "avx2"]
    /// Runs `net` over `input`, keeping the trajectory, and returns the class scores
    /// (compiled for the widest vectors the processor has: each operation is element by
    /// element, so every width gives the same bits).
    pub fn forward(
        net: &Network,
        input: &SpikeInput,
        act: Activation,
        tr: &mut Trajectory,
    ) -> Vec<f64> {
        // One copy of the loop per nonlinearity and reset, so that each inlines and
        // vectorises. `spike` maps the membrane to the step's spikes, `reset` the membrane and
        // its spikes to what is kept.
        let zero = |p: f64, s: f64| p * (1.0 - s);
        let subtract = |p: f64, s: f64| p - s;
        match (act, net.reset) {
            (Activation::Spike { .. }, Reset::Zero) => forward_with(
                net,
                input,
                tr,
                |p| f64::from(u8::from(p - 1.0 >= 0.0)),
                zero,
            ),
            (Activation::Spike { .. }, Reset::Subtract) => forward_with(
                net,
                input,
                tr,
                |p| if p >= 1.0 { p.floor() } else { 0.0 },
                subtract,
            ),
            (Activation::Smooth { .. }, Reset::Zero) => {
                forward_with(net, input, tr, |p| act.value(p - 1.0), zero)
            }
            (Activation::Smooth { .. }, Reset::Subtract) => {
                forward_with(net, input, tr, |p| act.value(p - 1.0), subtract)
            }
        }
    }
}

#[inline(always)]
fn forward_with(
    net: &Network,
    input: &SpikeInput,
    tr: &mut Trajectory,
    spike: impl Fn(f64) -> f64,
    reset: impl Fn(f64, f64) -> f64,
) -> Vec<f64> {
    let kappa = net.decays().2;
    let ((alpha, beta), own) = (net.hidden_decays(), net.own_decays());
    let (h_n, c_n, steps) = (net.hidden, net.classes, input.steps());
    // Every value is written below, step by step: the buffers keep their last contents
    // rather than being cleared on every call.
    tr.pre.resize(steps * h_n, 0.0);
    tr.spikes.resize(steps * h_n, 0.0);
    tr.out.resize(steps * c_n, 0.0);
    let mut current = vec![0.0; h_n];
    let mut membrane = vec![0.0; h_n];
    let mut out = vec![0.0; c_n];
    let mut fired = Vec::with_capacity(h_n);
    let adapt = net.adaptation.map(|a| a.per_step(net.dt_ms));
    let mut level = vec![0.0; if adapt.is_some() { h_n } else { 0 }];
    tr.shift
        .resize(if adapt.is_some() { steps * h_n } else { 0 }, 0.0);
    let delays = super::delay::Delays::of(net);
    let mut drive = std::mem::take(&mut tr.drive);
    drive.resize(delays.as_ref().map_or(0, |d| (steps + d.reach) * h_n), 0.0);
    for t in 0..steps {
        super::decay_currents(&mut current, &net.b_in, &alpha, own);
        match &delays {
            None => super::add_inputs(&mut current, &net.w_in, input.at(t), input.scale()),
            Some(d) => {
                d.add(&mut drive, t, input.at(t), input.scale());
                super::take_drive(&mut current, &mut drive[t * h_n..(t + 1) * h_n]);
            }
        }
        if net.recurrent() && t > 0 {
            let before = &tr.spikes[(t - 1) * h_n..t * h_n];
            for &j in super::nonzero(before, &mut fired) {
                let (s, w) = (before[j as usize], &net.w_rec[j as usize * h_n..][..h_n]);
                for (c, w) in current.iter_mut().zip(w) {
                    *c += s * w;
                }
            }
        }
        for (o, b) in out.iter_mut().zip(&net.b_out) {
            *o = kappa * *o + b;
        }
        let pre = &mut tr.pre[t * h_n..(t + 1) * h_n];
        let spikes = &mut tr.spikes[t * h_n..(t + 1) * h_n];
        let laws = (&spike, &reset);
        match (own, adapt) {
            (true, None) => membranes(pre, spikes, &mut membrane, &current, beta.as_slice(), laws),
            (false, None) => membranes(pre, spikes, &mut membrane, &current, beta[0], laws),
            (_, Some(rho_b)) => {
                let shift = &mut tr.shift[t * h_n..(t + 1) * h_n];
                let (m, a, rest) = (&mut membrane, &mut level, (&current[..], rho_b));
                match own {
                    true => {
                        adaptive_membranes(pre, spikes, shift, m, a, beta.as_slice(), rest, laws)
                    }
                    false => adaptive_membranes(pre, spikes, shift, m, a, beta[0], rest, laws),
                }
            }
        }
        super::add_readout(
            &mut out,
            &net.w_out,
            spikes,
            super::nonzero(spikes, &mut fired),
        );
        tr.out[t * c_n..(t + 1) * c_n].copy_from_slice(&out);
    }
    // What reached past the last step is dropped: the drive is zero for the next pass.
    let tail = (steps * h_n).min(drive.len());
    drive[tail..].fill(0.0);
    tr.drive = drive;
    read_scores(net.readout, &tr.out, c_n, steps)
}

/// Each hidden neuron's membrane before the spike `P = β V + I`, its spikes, and the
/// membrane it keeps, `reset(P, S)`; the slices written are parameters of their own, not a
/// tuple (see [`step_back`]).
#[inline(always)]
fn membranes<D: PerNeuron>(
    pre: &mut [f64],
    spikes: &mut [f64],
    membrane: &mut [f64],
    current: &[f64],
    beta: D,
    (spike, reset): (&impl Fn(f64) -> f64, &impl Fn(f64, f64) -> f64),
) {
    let n = pre.len();
    let (spikes, membrane, current) = (&mut spikes[..n], &mut membrane[..n], &current[..n]);
    let beta = beta.first(n);
    for k in 0..n {
        let p = beta.at(k) * membrane[k] + current[k];
        let s = spike(p);
        (pre[k], spikes[k], membrane[k]) = (p, s, reset(p, s));
    }
}

/// [`membranes`] with adaptive thresholds: the spike of `P - b a`, the threshold's rise
/// `b a` kept in `shift`, and the adaptation `a` moved on by the step's spikes. The slices
/// written are parameters of their own, not a tuple (see [`step_back`]).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn adaptive_membranes<D: PerNeuron>(
    pre: &mut [f64],
    spikes: &mut [f64],
    shift: &mut [f64],
    membrane: &mut [f64],
    level: &mut [f64],
    beta: D,
    (current, (rho, b)): (&[f64], (f64, f64)),
    (spike, reset): (&impl Fn(f64) -> f64, &impl Fn(f64, f64) -> f64),
) {
    let n = pre.len();
    let (spikes, shift) = (&mut spikes[..n], &mut shift[..n]);
    let (current, beta) = (&current[..n], beta.first(n));
    let (membrane, level) = (&mut membrane[..n], &mut level[..n]);
    for k in 0..n {
        let p = beta.at(k) * membrane[k] + current[k];
        let th = b * level[k];
        let s = spike(p - th);
        (pre[k], spikes[k], shift[k], membrane[k]) = (p, s, th, reset(p, s));
        level[k] = rho * level[k] + (1.0 - rho) * s;
    }
}

/// The scores read from a readout trace (`steps x classes`).
fn read_scores(readout: Readout, trace: &[f64], classes: usize, steps: usize) -> Vec<f64> {
    let mut acc = vec![0.0; classes];
    for (t, out) in trace.chunks_exact(classes).take(steps).enumerate() {
        readout.fold(t, &mut acc, out);
    }
    readout.finish(steps, acc)
}

/// The cross-entropy loss of one recording of class `label` and its gradient, added to
/// `grad` (scaled by `weight`, the recording's share of its batch).
pub fn loss_and_gradient(
    net: &Network,
    input: &SpikeInput,
    label: usize,
    rule: Backprop,
    weight: f64,
    tr: &mut Trajectory,
    grad: &mut Gradient,
) -> f64 {
    let scores = forward(net, input, rule.act, tr);
    let p = softmax(&scores);
    let loss = -p[label].max(f64::MIN_POSITIVE).ln();
    let dscore: Vec<f64> = p
        .iter()
        .enumerate()
        .map(|(c, &pc)| weight * (pc - f64::from(u8::from(c == label))))
        .collect();
    backward(net, input, rule, &dscore, tr, grad);
    loss
}

neurotex_core::widest_or_plain! {
    ["avx512f", "avx2"]
    /// Backpropagation through time of the score gradient `dscore` (see the module's
    /// equations), compiled as [`forward`] is.
    fn backward(
        net: &Network,
        input: &SpikeInput,
        rule: Backprop,
        dscore: &[f64],
        tr: &mut Trajectory,
        grad: &mut Gradient,
    ) {
        let kept = std::mem::take(&mut tr.g_drive);
        let hidden = &mut HiddenBack::new(net, rule.detach_reset, input.steps(), kept);
        match rule.act {
            Activation::Spike { slope } => backward_with(net, input, hidden, dscore, tr, grad, |x| {
                let d = 1.0 + slope * x.abs();
                1.0 / (d * d)
            }),
            act @ Activation::Smooth { .. } => {
                backward_with(net, input, hidden, dscore, tr, grad, |x| act.derivative(x))
            }
        }
        tr.g_drive = std::mem::take(&mut hidden.g_drive);
    }
}

#[inline(always)]
fn backward_with(
    net: &Network,
    input: &SpikeInput,
    hidden: &mut HiddenBack,
    dscore: &[f64],
    tr: &Trajectory,
    grad: &mut Gradient,
    derivative: impl Fn(f64) -> f64,
) {
    let (h_n, c_n, steps) = (net.hidden, net.classes, input.steps());
    let kappa = net.decays().2;
    let mut g_s = vec![0.0; h_n];
    if net.readout == Readout::Mean {
        // Every class's readout gradient follows one decay: gO[t] = φ[t] dscore, with
        // φ[t] = 1/T + κ φ[t+1]. So gS[t] = φ[t] (W_out dscore), and the readout's
        // gradients are sums over steps of φ[t] (biases) and φ[t] S[t] (weights).
        let mean_share = 1.0 / steps.max(1) as f64;
        let direction: Vec<f64> = (net.w_out.chunks_exact(c_n))
            .map(|w| w.iter().zip(dscore).map(|(w, d)| w * d).sum())
            .collect();
        let (mut phi, mut phi_sum) = (0.0, 0.0);
        let mut weighted = vec![0.0; h_n];
        for t in (0..steps).rev() {
            phi = mean_share + kappa * phi;
            phi_sum += phi;
            let spikes = &tr.spikes[t * h_n..(t + 1) * h_n];
            mean_readout_step(phi, spikes, &direction, &mut weighted, &mut g_s);
            hidden.step(net, input, t, tr, &mut g_s, grad, &derivative);
        }
        for (c, &d) in dscore.iter().enumerate() {
            grad.b_out[c] += d * phi_sum;
        }
        add_outer(&mut grad.w_out, &weighted, dscore);
        return;
    }
    let argmax = argmax_steps(&tr.out, c_n, steps);
    let mut g_out = vec![0.0; c_n];
    // W_out class-major, for gS = W_out gO over contiguous hidden neurons.
    let mut w_out_t = vec![0.0; h_n * c_n];
    for h in 0..h_n {
        for c in 0..c_n {
            w_out_t[c * h_n + h] = net.w_out[h * c_n + c];
        }
    }
    for t in (0..steps).rev() {
        for c in 0..c_n {
            let direct = if argmax[c] == t { dscore[c] } else { 0.0 };
            g_out[c] = direct + kappa * g_out[c];
            grad.b_out[c] += g_out[c];
        }
        // gS = W_out gO, class by class over the hidden layer (so the loop vectorises).
        g_s.iter_mut().for_each(|g| *g = 0.0);
        for (c, &g) in g_out.iter().enumerate() {
            for (gs, w) in g_s.iter_mut().zip(&w_out_t[c * h_n..(c + 1) * h_n]) {
                *gs += w * g;
            }
        }
        add_outer(&mut grad.w_out, &tr.spikes[t * h_n..(t + 1) * h_n], &g_out);
        hidden.step(net, input, t, tr, &mut g_s, grad, &derivative);
    }
}

/// One step of the mean readout's backward pass: the spikes weighted by `φ[t]` added to
/// `weighted`, and the spike gradient `gS[t] = φ[t] (W_out dscore)` written into `g_s`.
/// The slices are parameters of their own and indexed over one length, so that the loop
/// vectorises: written in the caller over zipped iterators, it ran one neuron at a time
/// and took a third of the backward pass (see [`step_back`]).
#[inline(always)]
fn mean_readout_step(
    phi: f64,
    spikes: &[f64],
    direction: &[f64],
    weighted: &mut [f64],
    g_s: &mut [f64],
) {
    let n = g_s.len();
    let (spikes, direction, weighted) = (&spikes[..n], &direction[..n], &mut weighted[..n]);
    for k in 0..n {
        weighted[k] += phi * spikes[k];
        g_s[k] = phi * direction[k];
    }
}

/// The hidden layer's side of the backward pass, step by step from the last: the next
/// step's membrane and current gradients, and the decays.
struct HiddenBack {
    g_v: Vec<f64>,
    g_i: Vec<f64>,
    /// Each neuron's `α_h` and `β_h`.
    alpha: Vec<f64>,
    beta: Vec<f64>,
    /// 1 if the reset is in the graph, else 0.
    reset: f64,
    subtract: bool,
    /// The step's membrane gradient `gP[t]`, kept for the gradients of each neuron's own
    /// decays (empty when the neurons share their decays).
    g_p: Vec<f64>,
    /// Adaptive thresholds' `(ρ, b)` and the next step's adaptation gradient.
    adapt: Option<(f64, f64)>,
    g_a: Vec<f64>,
    /// The delays, and the current's gradient of every step so far (from the last back)
    /// with zeros past the recording's end (delays only).
    delays: Option<super::delay::Delays>,
    g_drive: Vec<f64>,
}

impl HiddenBack {
    /// The state before the last step of `steps`, in the buffer `g_drive` kept from an
    /// earlier pass.
    fn new(net: &Network, detach_reset: bool, steps: usize, mut g_drive: Vec<f64>) -> Self {
        let (alpha, beta) = net.hidden_decays();
        let delays = super::delay::Delays::of(net);
        // Rows before `steps` are written before they are read; those after must be zero.
        let h_n = net.hidden;
        g_drive.resize(delays.as_ref().map_or(0, |d| (steps + d.reach) * h_n), 0.0);
        let tail = (steps * h_n).min(g_drive.len());
        g_drive[tail..].fill(0.0);
        HiddenBack {
            delays,
            g_drive,
            g_v: vec![0.0; net.hidden],
            g_i: vec![0.0; net.hidden],
            alpha,
            beta,
            reset: f64::from(u8::from(!detach_reset)),
            subtract: net.reset == Reset::Subtract,
            g_p: vec![0.0; if net.own_decays() { net.hidden } else { 0 }],
            adapt: net.adaptation.map(|a| a.per_step(net.dt_ms)),
            g_a: vec![0.0; net.adaptation.map_or(0, |_| net.hidden)],
        }
    }

    /// Step `t` from its spike gradient `g_s` (to which the recurrent path is added): the
    /// membrane and current gradients, and the input-side parameters' gradients.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn step(
        &mut self,
        net: &Network,
        input: &SpikeInput,
        t: usize,
        tr: &Trajectory,
        g_s: &mut [f64],
        grad: &mut Gradient,
        derivative: &impl Fn(f64) -> f64,
    ) {
        let h_n = net.hidden;
        let pre = &tr.pre[t * h_n..(t + 1) * h_n];
        let spikes = &tr.spikes[t * h_n..(t + 1) * h_n];
        if net.recurrent() {
            // S[t] drives I[t+1]: g_i still holds step t+1's.
            add_recurrent_spike_gradient(net, &self.g_i, g_s);
        }
        match self.adapt {
            Some(rho_b) => {
                let shift = &tr.shift[t * h_n..(t + 1) * h_n];
                self.adaptive_step((g_s, pre, spikes, shift), rho_b, derivative);
            }
            None => step_back(
                (g_s, pre, spikes),
                &mut self.g_v,
                &mut self.g_i,
                &mut self.g_p,
                (&self.alpha, &self.beta, self.reset),
                self.subtract,
                derivative,
            ),
        }
        let g_i = &mut self.g_i;
        if !self.g_p.is_empty() {
            add_decay_gradients(
                (tr, t, h_n),
                self.subtract,
                &self.beta,
                (&self.g_p, g_i),
                &mut grad.alpha,
                &mut grad.beta,
            );
        }
        for (b, g) in grad.b_in.iter_mut().zip(g_i.iter()) {
            *b += g;
        }
        match &self.delays {
            None => super::add_inputs_gradient(&mut grad.w_in, g_i, input.at(t), input.scale()),
            Some(d) => {
                self.g_drive[t * h_n..(t + 1) * h_n].copy_from_slice(g_i);
                let at = (t, input.at(t), input.scale());
                d.gradient(
                    &net.w_in,
                    &self.g_drive,
                    at,
                    &mut grad.w_in,
                    &mut grad.delays,
                );
            }
        }
        if net.recurrent() && t > 0 {
            let before = &tr.spikes[(t - 1) * h_n..t * h_n];
            add_outer(&mut grad.w_rec, before, g_i);
        }
    }
}

impl HiddenBack {
    /// [`step_back_adaptive`] with the decays shared (two numbers) or each neuron's own.
    #[inline(always)]
    fn adaptive_step(
        &mut self,
        parts: (&[f64], &[f64], &[f64], &[f64]),
        rho_b: (f64, f64),
        derivative: &impl Fn(f64) -> f64,
    ) {
        let (g_v, g_i, g_a, g_p) = (&mut self.g_v, &mut self.g_i, &mut self.g_a, &mut self.g_p);
        match g_p.is_empty() {
            true => {
                let decays = (self.alpha[0], self.beta[0], self.reset);
                step_back_adaptive::<false, f64>(
                    parts, g_v, g_i, g_a, g_p, decays, rho_b, derivative,
                );
            }
            false => {
                let decays = (&self.alpha[..], &self.beta[..], self.reset);
                step_back_adaptive::<true, &[f64]>(
                    parts, g_v, g_i, g_a, g_p, decays, rho_b, derivative,
                );
            }
        }
    }
}

/// One step of the hidden layer backwards (see the module's equations): from the step's
/// spike gradient, membranes and spikes `(gS, P, S)`, turns the next step's membrane and
/// current gradients `g_v`, `g_i` into this step's, and writes `gP` into `g_p` unless it
/// is empty; the decays are `(α_h, β_h, 1 if the reset is in the graph else 0)`.
///
/// The gradients written are parameters of their own, not a tuple: a tuple of references is
/// passed through memory, without the promise that they alias nothing, and the loops then
/// ran one neuron at a time.
#[inline(always)]
fn step_back(
    parts: (&[f64], &[f64], &[f64]),
    g_v: &mut [f64],
    g_i: &mut [f64],
    g_p: &mut [f64],
    decays: (&[f64], &[f64], f64),
    subtract: bool,
    derivative: &impl Fn(f64) -> f64,
) {
    // Neurons that share their decays step with two numbers, not a load per neuron;
    // neurons with decays of their own also keep `gP` for their decays' gradients.
    let (alpha, beta, reset) = decays;
    match g_p.is_empty() {
        true => {
            let shared = (alpha[0], beta[0], reset);
            step_back_with::<false, f64>(parts, g_v, g_i, g_p, shared, subtract, derivative);
        }
        false => step_back_with::<true, &[f64]>(parts, g_v, g_i, g_p, decays, subtract, derivative),
    }
}

#[inline(always)]
fn step_back_with<const KEEP: bool, D: PerNeuron>(
    (g_s, pre, spikes): (&[f64], &[f64], &[f64]),
    g_v: &mut [f64],
    g_i: &mut [f64],
    g_p: &mut [f64],
    (alpha, beta, reset): (D, D, f64),
    subtract: bool,
    derivative: &impl Fn(f64) -> f64,
) {
    // Indexed over slices of one length, so that the loops vectorise (through five zipped
    // iterators they ran one neuron at a time).
    let n = g_s.len();
    let (pre, spikes, g_v, g_i) = (&pre[..n], &spikes[..n], &mut g_v[..n], &mut g_i[..n]);
    let g_p = if KEEP { &mut g_p[..n] } else { g_p };
    let (alpha, beta) = (alpha.first(n), beta.first(n));
    if subtract {
        // V = P - S: the reset passes gV to P whole, and (in the graph) as -gV to S.
        for k in 0..n {
            let p = g_v[k] + (g_s[k] - reset * g_v[k]) * derivative(pre[k] - 1.0);
            if KEEP {
                g_p[k] = p;
            }
            g_i[k] = p + alpha.at(k) * g_i[k];
            g_v[k] = beta.at(k) * p;
        }
    } else {
        for k in 0..n {
            let g_sh = g_s[k] - reset * pre[k] * g_v[k];
            let p = g_v[k] * (1.0 - spikes[k]) + g_sh * derivative(pre[k] - 1.0);
            if KEEP {
                g_p[k] = p;
            }
            g_i[k] = p + alpha.at(k) * g_i[k];
            g_v[k] = beta.at(k) * p;
        }
    }
}

/// [`step_back`] with adaptive thresholds (reset to zero): `g_a` holds the next step's
/// adaptation gradient `∂L/∂a[t+1]` and becomes this step's. The gradients written are
/// parameters of their own (see [`step_back`]).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn step_back_adaptive<const KEEP: bool, D: PerNeuron>(
    (g_s, pre, spikes, shift): (&[f64], &[f64], &[f64], &[f64]),
    g_v: &mut [f64],
    g_i: &mut [f64],
    g_a: &mut [f64],
    g_p: &mut [f64],
    (alpha, beta, reset): (D, D, f64),
    (rho, b): (f64, f64),
    derivative: &impl Fn(f64) -> f64,
) {
    let n = g_s.len();
    let (pre, spikes, shift, g_v, g_i, g_a) = (
        &pre[..n],
        &spikes[..n],
        &shift[..n],
        &mut g_v[..n],
        &mut g_i[..n],
        &mut g_a[..n],
    );
    let g_p = if KEEP { &mut g_p[..n] } else { g_p };
    let (alpha, beta) = (alpha.first(n), beta.first(n));
    for k in 0..n {
        let g_sh = g_s[k] + (1.0 - rho) * g_a[k] - reset * pre[k] * g_v[k];
        let d = g_sh * derivative(pre[k] - shift[k] - 1.0);
        let p = g_v[k] * (1.0 - spikes[k]) + d;
        g_a[k] = rho * g_a[k] - b * d;
        if KEEP {
            g_p[k] = p;
        }
        g_i[k] = p + alpha.at(k) * g_i[k];
        g_v[k] = beta.at(k) * p;
    }
}

/// Step `t`'s share of each neuron's own decays' gradients, `∂L/∂α_h += gI[t] I[t-1]` and
/// `∂L/∂β_h += gP[t] V[t-1]`, with `V` and `I` made again from the kept membranes and
/// spikes as the forward pass made them (nothing before step 0). The gradients written are
/// parameters of their own (see [`step_back`]).
#[inline(always)]
fn add_decay_gradients(
    (tr, t, h_n): (&Trajectory, usize, usize),
    subtract: bool,
    beta: &[f64],
    (g_p, g_i): (&[f64], &[f64]),
    g_alpha: &mut [f64],
    g_beta: &mut [f64],
) {
    if t == 0 {
        return;
    }
    // Indexed over slices of one length, so that the loop vectorises.
    let row = |u: usize| (&tr.pre[u * h_n..][..h_n], &tr.spikes[u * h_n..][..h_n]);
    let kept = |p: f64, s: f64| if subtract { p - s } else { p * (1.0 - s) };
    let ((p1, s1), (g_p, g_i, beta)) = (row(t - 1), (&g_p[..h_n], &g_i[..h_n], &beta[..h_n]));
    let (g_alpha, g_beta) = (&mut g_alpha[..h_n], &mut g_beta[..h_n]);
    let (p2, s2) = if t >= 2 { row(t - 2) } else { (p1, s1) };
    let first = t == 1;
    for h in 0..h_n {
        let before = if first { 0.0 } else { kept(p2[h], s2[h]) };
        g_alpha[h] += g_i[h] * (p1[h] - beta[h] * before);
        g_beta[h] += g_p[h] * kept(p1[h], s1[h]);
    }
}

/// `g_s += W_rec g_next`: the spike gradient through the recurrent weights (`g_next` the
/// next step's current gradient).
#[inline(always)]
fn add_recurrent_spike_gradient(net: &Network, g_next: &[f64], g_s: &mut [f64]) {
    let h_n = net.hidden;
    for (j, gs) in g_s.iter_mut().enumerate() {
        let w = &net.w_rec[j * h_n..(j + 1) * h_n];
        *gs += w.iter().zip(g_next).map(|(w, g)| w * g).sum::<f64>();
    }
}

/// `grad += s gᵀ` over the rows `j` where `s[j]` is not zero (source-major, `g.len()`
/// columns).
#[inline(always)]
fn add_outer(grad: &mut [f64], s: &[f64], g: &[f64]) {
    let n = g.len();
    for (j, &s) in s.iter().enumerate().filter(|(_, &s)| s != 0.0) {
        for (gw, g) in grad[j * n..(j + 1) * n].iter_mut().zip(g) {
            *gw += s * g;
        }
    }
}

/// For each class, the first step where its readout is largest.
fn argmax_steps(trace: &[f64], classes: usize, steps: usize) -> Vec<usize> {
    (0..classes)
        .map(|c| {
            let mut best = 0;
            for t in 1..steps {
                if trace[t * classes + c] > trace[best * classes + c] {
                    best = t;
                }
            }
            best
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn spiking_positions_and_readout_sums_are_those_of_the_plain_loops() {
        let mut next = crate::testing::xorshift(7);
        let mut value = |n: u64| (next() % n) as f64 - 1.0;
        let (mut at, nan) = (Vec::new(), f64::NAN);
        // Lengths around the 64 values of a mask; a NaN is not zero, -0.0 is.
        for len in [0, 1, 63, 64, 65, 127, 128, 130, 200] {
            let mut s: Vec<f64> = (0..len).map(|_| value(4).max(0.0) * value(3)).collect();
            s.iter_mut().step_by(37).for_each(|x| *x = nan);
            s.iter_mut().skip(5).step_by(41).for_each(|x| *x = -0.0);
            let plain: Vec<u32> = (0..len as u32).filter(|&j| s[j as usize] != 0.0).collect();
            assert_eq!(super::super::nonzero(&s, &mut at), plain, "length {len}");
        }
        for classes in 1..=10 {
            let hidden = 70;
            let w: Vec<f64> = (0..hidden * classes).map(|_| value(1000) / 7.0).collect();
            let spikes: Vec<f64> = (0..hidden).map(|_| value(3).max(0.0)).collect();
            let fired = super::super::nonzero(&spikes, &mut at).to_vec();
            let start: Vec<f64> = (0..classes).map(|_| value(100) / 3.0).collect();
            let (mut plain, mut out) = (start.clone(), start);
            for &h in &fired {
                let row = &w[h as usize * classes..][..classes];
                plain
                    .iter_mut()
                    .zip(row)
                    .for_each(|(o, w)| *o += spikes[h as usize] * w);
            }
            super::super::add_readout(&mut out, &w, &spikes, &fired);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&out), bits(&plain), "{classes} classes");
        }
    }

    /// A random network (recurrent when `recurrent`) and a random input.
    fn random_net_of(readout: Readout, seed: u64, recurrent: bool) -> (Network, SpikeInput) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let (inputs, hidden, classes, steps) = (5, 7, 3, 40);
        let mut w =
            |n: usize, s: f64| -> Vec<f64> { (0..n).map(|_| rng.gen_range(-s..s)).collect() };
        let net = Network {
            inputs,
            hidden,
            classes,
            dt_ms: 5,
            tau_syn_ms: 10.0,
            tau_mem_ms: 20.0,
            tau_out_ms: 15.0,
            readout,
            reset: Reset::Zero,
            w_in: w(inputs * hidden, 1.5),
            b_in: w(hidden, 0.2),
            w_out: w(hidden * classes, 1.0),
            b_out: w(classes, 0.3),
            w_rec: match recurrent {
                true => w(hidden * hidden, 0.8),
                false => Vec::new(),
            },
            target: Default::default(),
            alpha: Vec::new(),
            beta: Vec::new(),
            travel_mm_s: None,
            adaptation: None,
            delays: Vec::new(),
        };
        let mut events = Vec::new();
        for t in 0..steps as u32 {
            for i in 0..inputs as u32 {
                if rng.gen_bool(0.2) {
                    events.push((t, i));
                }
            }
        }
        (net, SpikeInput::from_events(inputs, steps, &events))
    }

    fn random_net(readout: Readout, seed: u64) -> (Network, SpikeInput) {
        random_net_of(readout, seed, false)
    }

    /// `net` with decays of each neuron's own, drawn from `seed`.
    fn with_own_decays(mut net: Network, seed: u64) -> Network {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        net.alpha = (0..net.hidden).map(|_| rng.gen_range(0.2..0.95)).collect();
        net.beta = (0..net.hidden).map(|_| rng.gen_range(0.2..0.95)).collect();
        net.check().unwrap();
        net
    }

    /// `net` with delays drawn from `seed`, up to `longest` steps.
    fn with_delays(mut net: Network, seed: u64, longest: f64) -> Network {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        net.delays = (0..net.w_in.len())
            .map(|_| rng.gen_range(0.0..longest))
            .collect();
        net.check().unwrap();
        net
    }

    /// Delays against their meaning: whole delays of `k` steps score as the network without
    /// delays on the input `k` steps later, and a spike split between two steps adds to
    /// the current what a hand calculation says. Equal up to the order of additions.
    #[test]
    fn delays_carry_spikes_later() {
        let act = Activation::Smooth { k: 4.0 };
        let (plain, input) = random_net(Readout::Mean, 3);
        let later = {
            let steps = input.steps() + 3;
            let events: Vec<(u32, u32)> = (0..input.steps())
                .flat_map(|t| input.at(t).iter().map(move |&i| (t as u32 + 3, i)))
                .collect();
            SpikeInput::from_events(input.inputs, steps, &events)
        };
        let mut delayed = plain.clone();
        delayed.delays = vec![3.0; plain.w_in.len()];
        let longer = {
            let events: Vec<(u32, u32)> = (0..input.steps())
                .flat_map(|t| input.at(t).iter().map(move |&i| (t as u32, i)))
                .collect();
            SpikeInput::from_events(input.inputs, input.steps() + 3, &events)
        };
        let a = forward(&plain, &later, act, &mut Trajectory::default());
        let b = forward(&delayed, &longer, act, &mut Trajectory::default());
        for (a, b) in a.iter().zip(&b) {
            assert!((a - b).abs() < 1e-12, "{a} against {b}");
        }
        // One input, one neuron: a spike at step 1 with delay 2.25 and weight 0.4 adds
        // 0.4 x 0.75 = 0.3 to step 3's current and 0.4 x 0.25 = 0.1 to step 4's.
        let mut one = plain.clone();
        (one.inputs, one.hidden, one.w_in, one.b_in) = (1, 1, vec![0.4], vec![0.0]);
        (one.w_out, one.delays) = (vec![1.0; one.classes], vec![2.25]);
        let d = super::super::delay::Delays::of(&one).unwrap();
        let mut drive = vec![0.0; 8];
        d.add(&mut drive, 1, &[0], 1.0);
        assert_eq!(
            drive,
            [0.0, 0.0, 0.0, 0.4 * 0.75, 0.4 * 0.25, 0.0, 0.0, 0.0]
        );
        let (k, alpha) = (d.reach, one.decays().0);
        assert_eq!(k, 4);
        let mut tr = Trajectory::default();
        forward(
            &one,
            &SpikeInput::from_events(1, 6, &[(1, 0)]),
            act,
            &mut tr,
        );
        // Membranes before the spike: the current alone until step 3 (nothing before).
        let (_, beta, _) = one.decays();
        let spike = |p: f64| act.value(p - 1.0);
        let mut expect = [0.0; 6];
        let (mut i, mut v) = (0.0, 0.0);
        for (t, e) in expect.iter_mut().enumerate() {
            i = alpha * i + [0.0, 0.0, 0.0, 0.3, 0.1, 0.0][t];
            let p = beta * v + i;
            *e = p;
            v = p * (1.0 - spike(p));
        }
        for (t, (got, want)) in tr.pre.iter().zip(expect).enumerate() {
            assert!((got - want).abs() < 1e-15, "step {t}: {got} against {want}");
        }
    }

    fn loss(net: &Network, input: &SpikeInput, act: Activation) -> f64 {
        let scores = forward(net, input, act, &mut Trajectory::default());
        -softmax(&scores)[1].ln()
    }

    /// The hand-written backward pass against central finite differences of the loss, on
    /// a network with a smooth spike function (whose loss has a true gradient), the reset
    /// kept in the graph, both readouts, feed-forward and recurrent, with shared decays and
    /// with each neuron's own, adaptive thresholds (seeds 8 and 9) and delays (seeds 10 and
    /// 11).
    #[test]
    fn gradient_matches_finite_differences() {
        for (readout, seed, recurrent, own) in [
            (Readout::Mean, 1, false, false),
            (Readout::Max, 2, false, false),
            (Readout::Mean, 5, true, false),
            (Readout::Max, 6, false, true),
            (Readout::Mean, 7, true, true),
            (Readout::Mean, 8, false, false),
            (Readout::Max, 9, true, true),
            (Readout::Mean, 10, false, false),
            (Readout::Max, 11, true, true),
        ] {
            let (net, input) = random_net_of(readout, seed, recurrent);
            let mut net = if own { with_own_decays(net, seed) } else { net };
            if seed == 8 || seed == 9 {
                net.adaptation = Some(super::super::Adaptation {
                    tau_ms: 30.0,
                    strength: 0.8,
                });
            }
            if seed >= 10 {
                net = with_delays(net, seed, 6.0);
            }
            let act = Activation::Smooth { k: 4.0 };
            let mut grad = Gradient::zeros(&net);
            let mut tr = Trajectory::default();
            let rule = Backprop {
                act,
                detach_reset: false,
            };
            loss_and_gradient(&net, &input, 1, rule, 1.0, &mut tr, &mut grad);
            let eps = 1e-6;
            let mut checked = 0;
            for part in 0..8 {
                for j in 0..grad.parts()[part].len() {
                    let bump = |d: f64| {
                        let mut n = net.clone();
                        n.params_mut()[part][j] += d;
                        loss(&n, &input, act)
                    };
                    let numeric = (bump(eps) - bump(-eps)) / (2.0 * eps);
                    let analytic = grad.parts()[part][j];
                    let tol = 1e-6 + 1e-4 * numeric.abs().max(analytic.abs());
                    assert!(
                        (numeric - analytic).abs() <= tol,
                        "{readout:?} seed {seed} part {part} [{j}]: numeric {numeric}, backward {analytic}"
                    );
                    checked += 1;
                }
            }
            let rec = if recurrent { 7 * 7 } else { 0 };
            let decays = if own { 2 * 7 } else { 0 };
            let delays = if seed >= 10 { 5 * 7 } else { 0 };
            assert_eq!(checked, 5 * 7 + 7 + 7 * 3 + 3 + rec + decays + delays);
            assert!(delays == 0 || grad.delays.iter().any(|g| g.abs() > 1e-4));
            assert!(
                grad.w_in.iter().any(|g| g.abs() > 1e-4),
                "a gradient that is all zero checks nothing"
            );
            assert!(!recurrent || grad.w_rec.iter().any(|g| g.abs() > 1e-4));
            for d in [&grad.alpha, &grad.beta] {
                assert!(!own || d.iter().any(|g| g.abs() > 1e-4));
            }
        }
    }

    /// An evidently correct forward pass of the smooth network, neuron by neuron, for
    /// either reset, returning the loss (class 1) and every step's spikes. With `frozen`
    /// (the spikes of an earlier run) the reset subtracts those instead of this run's:
    /// held fixed, they are what a detached reset keeps out of the gradient, so finite
    /// differences of this loss check the detached backward pass.
    fn reference_loss(
        net: &Network,
        input: &SpikeInput,
        k: f64,
        frozen: Option<&[f64]>,
    ) -> (f64, Vec<f64>) {
        let kappa = net.decays().2;
        let (alpha, beta) = net.hidden_decays();
        let (n, h_n, c_n) = (net.inputs, net.hidden, net.classes);
        let sigma = |x: f64| 1.0 / (1.0 + (-k * x).exp());
        let x = input.dense();
        let (mut current, mut v) = (vec![0.0; h_n], vec![0.0; h_n]);
        let (mut out, mut last) = (vec![0.0; c_n], vec![0.0; h_n]);
        let (mut spikes, mut trace) = (Vec::new(), Vec::new());
        for t in 0..input.steps() {
            let loops = if net.recurrent() { h_n } else { 0 };
            for (h, current) in current.iter_mut().enumerate() {
                let mut drive = net.b_in[h];
                for i in 0..n {
                    drive += f64::from(x[t * n + i]) * net.w_in[i * h_n + h];
                }
                for (j, &s) in last.iter().enumerate().take(loops) {
                    drive += s * net.w_rec[j * h_n + h];
                }
                *current = alpha[h] * *current + drive;
            }
            for h in 0..h_n {
                let p = beta[h] * v[h] + current[h];
                last[h] = sigma(p - 1.0);
                let r = frozen.map_or(last[h], |f| f[t * h_n + h]);
                v[h] = match net.reset {
                    Reset::Zero => p * (1.0 - r),
                    Reset::Subtract => p - r,
                };
            }
            for (c, out) in out.iter_mut().enumerate() {
                let drive: f64 = (0..h_n).map(|h| last[h] * net.w_out[h * c_n + c]).sum();
                *out = kappa * *out + net.b_out[c] + drive;
            }
            spikes.extend_from_slice(&last);
            trace.extend_from_slice(&out);
        }
        let scores = net.reduce(trace.chunks_exact(c_n));
        (-softmax(&scores)[1].ln(), spikes)
    }

    /// The backward pass against central finite differences of the reference's loss, for
    /// both resets, feed-forward and recurrent, the reset detached (the reference's
    /// spikes in the reset held) and in the graph, every other case with each neuron's
    /// own decays and the others with each input event weighed 0.75.
    #[test]
    fn gradient_matches_finite_differences_for_each_reset() {
        let k = 4.0;
        let act = Activation::Smooth { k };
        let mut seed = 10;
        for reset in [Reset::Subtract, Reset::Zero] {
            for recurrent in [false, true] {
                for detach_reset in [true, false] {
                    seed += 1;
                    let (mut net, input) = random_net_of(Readout::Mean, seed, recurrent);
                    if seed % 2 == 0 {
                        net = with_own_decays(net, seed);
                    }
                    // Every other case weighs each event 0.75, as steps of travel do.
                    let input = match seed % 2 {
                        1 => input.scaled(0.75),
                        _ => input,
                    };
                    net.reset = reset;
                    let (loss_at, spikes) = reference_loss(&net, &input, k, None);
                    let want = loss(&net, &input, act);
                    assert!((loss_at - want).abs() <= 1e-9, "{loss_at} vs {want}");
                    let mut grad = Gradient::zeros(&net);
                    let rule = Backprop { act, detach_reset };
                    let mut tr = Trajectory::default();
                    loss_and_gradient(&net, &input, 1, rule, 1.0, &mut tr, &mut grad);
                    let frozen = detach_reset.then_some(spikes.as_slice());
                    let eps = 1e-6;
                    for part in 0..7 {
                        for j in 0..grad.parts()[part].len() {
                            let bump = |d: f64| {
                                let mut n = net.clone();
                                n.params_mut()[part][j] += d;
                                reference_loss(&n, &input, k, frozen).0
                            };
                            let numeric = (bump(eps) - bump(-eps)) / (2.0 * eps);
                            let analytic = grad.parts()[part][j];
                            let tol = 1e-6 + 1e-4 * numeric.abs().max(analytic.abs());
                            assert!(
                                (numeric - analytic).abs() <= tol,
                                "{reset:?} recurrent {recurrent} detached {detach_reset} part {part} [{j}]: numeric {numeric}, backward {analytic}"
                            );
                        }
                    }
                    assert!(grad.w_in.iter().any(|g| g.abs() > 1e-4));
                    assert!(!recurrent || grad.w_rec.iter().any(|g| g.abs() > 1e-4));
                    assert_eq!(grad.beta.len(), if seed % 2 == 0 { 7 } else { 0 });
                    assert!(grad.beta.iter().all(|g| g.abs() > 0.0));
                }
            }
        }
    }

    /// The training forward pass with the spike nonlinearity gives the scores prediction's
    /// step-by-step runner gives, bit for bit, for either reset and with adaptive
    /// thresholds.
    #[test]
    fn training_forward_equals_the_runner() {
        for (readout, recurrent, reset, adapt, delays) in [
            (Readout::Mean, false, Reset::Zero, false, false),
            (Readout::Max, false, Reset::Zero, false, false),
            (Readout::Mean, true, Reset::Zero, false, false),
            (Readout::Mean, false, Reset::Subtract, false, false),
            (Readout::Max, true, Reset::Subtract, false, false),
            (Readout::Mean, false, Reset::Zero, true, false),
            (Readout::Max, true, Reset::Zero, true, false),
            (Readout::Mean, false, Reset::Zero, false, true),
            (Readout::Max, true, Reset::Zero, true, true),
            (Readout::Max, true, Reset::Subtract, false, true),
        ] {
            let (net, input) = random_net_of(readout, 3, recurrent);
            // Each neuron's own decays, where it runs as the shared ones do.
            let mut net = match reset == Reset::Subtract || (adapt && recurrent) {
                true => with_own_decays(net, 4),
                false => net,
            };
            net.reset = reset;
            if adapt {
                let fixed = net.scores(&input);
                net.adaptation = Some(super::super::Adaptation {
                    tau_ms: 25.0,
                    strength: 0.7,
                });
                net.check().unwrap();
                assert_ne!(net.scores(&input), fixed);
            }
            if delays {
                // Up to 9 steps: the runner's ring of 11 rows wraps round the 40 steps.
                let at_once = net.scores(&input);
                net = with_delays(net, 12, 9.0);
                assert_ne!(net.scores(&input), at_once);
            }
            let act = Activation::Spike { slope: 10.0 };
            let mut tr = Trajectory::default();
            let trained = forward(&net, &input, act, &mut tr);
            assert_eq!(trained, net.scores(&input));
            assert!(tr.spikes.contains(&1.0) && tr.spikes.contains(&0.0));
            let scaled = input.clone().scaled(1.3);
            let trained = forward(&net, &scaled, act, &mut Trajectory::default());
            assert_eq!(trained, net.scores(&scaled));
            assert_ne!(trained, net.scores(&input));
            let most = tr.spikes.iter().copied().fold(0.0, f64::max);
            assert_eq!(most >= 2.0, reset == Reset::Subtract, "{reset:?}: {most}");
        }
    }

    /// A network run step by step and read over its last `w` steps: over a window as long
    /// as the run, the whole run's scores; over a shorter one, the mean (or largest value)
    /// of the readout trace's last `w` rows, computed here by hand.
    #[test]
    fn windowed_scores_read_the_last_steps_of_the_readout() {
        for readout in [Readout::Mean, Readout::Max] {
            let (net, input) = random_net(readout, 4);
            let mut tr = Trajectory::default();
            forward(&net, &input, Activation::Spike { slope: 10.0 }, &mut tr);
            let steps = input.steps();
            for w in [1, 7, steps, steps + 5] {
                let mut run = crate::snn::Windowed::new(&net, w);
                for t in 0..steps {
                    run.step(&net, input.at(t));
                }
                let last = &tr.out[steps.saturating_sub(w) * 3..steps * 3];
                let rows = last.len() / 3;
                for (c, &got) in run.scores(&net).iter().enumerate() {
                    let values: Vec<f64> = (0..rows).map(|r| last[r * 3 + c]).collect();
                    let want = match readout {
                        Readout::Mean => values.iter().sum::<f64>() / rows as f64,
                        Readout::Max => values.iter().copied().fold(f64::MIN, f64::max),
                    };
                    assert!(
                        (got - want).abs() <= 1e-12,
                        "{readout:?} w {w} class {c}: {got} vs {want}"
                    );
                }
                if w >= steps {
                    assert_eq!(run.scores(&net), net.scores(&input));
                }
            }
        }
    }
}
