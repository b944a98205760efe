//! Training: initial weights scaled to the data, a stratified validation split for early
//! stopping, Adam on shuffled mini-batches. Every random choice comes from one seeded
//! ChaCha stream, and a batch's gradients are summed in recording order whatever thread
//! computed them, so a seed gives the same network on any number of threads.

use std::borrow::Cow;

use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use rayon::prelude::*;

use super::grad::{loss_and_gradient, Activation, Backprop, Gradient, Trajectory};
use super::{softmax, Network, SnnParams, SpikeInput};
use crate::error::ClassifyError;

/// How training went: the epochs run and the one whose network was kept.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrainingLog {
    /// Epochs run (early stopping may end before [`SnnParams::epochs`]).
    pub epochs: usize,
    /// The epoch (1-based) with the lowest validation loss, whose weights are kept.
    pub best_epoch: usize,
    /// That validation loss (mean cross-entropy per recording).
    pub validation_loss: f64,
}

/// Trains a network on `inputs` with class indices `y` (`classes` of them).
///
/// # Errors
/// No recording, inputs of different widths, no input spike at all, or a class with
/// too few recordings to put one aside for validation and keep one to train on.
pub fn fit(
    params: &SnnParams,
    inputs: &[&SpikeInput],
    y: &[usize],
    classes: usize,
) -> Result<(Network, TrainingLog), ClassifyError> {
    fit_with(params, inputs, y, classes, &|| ())
}

/// [`fit`], calling `each_epoch` after each epoch run ([`TrainingLog::epochs`] times:
/// fewer than `params.epochs` when early stopping ends training).
///
/// # Errors
/// As [`fit`].
pub fn fit_with(
    params: &SnnParams,
    inputs: &[&SpikeInput],
    y: &[usize],
    classes: usize,
    each_epoch: &(dyn Fn() + Sync),
) -> Result<(Network, TrainingLog), ClassifyError> {
    check_inputs(inputs, y)?;
    if params.target == super::Target::Xylo {
        let shape = super::xylo::check_shape(inputs[0].inputs, params.hidden, classes);
        shape.map_err(|e| ClassifyError::BadFeatures(e.to_string()))?;
    }
    let mut rng = ChaCha8Rng::seed_from_u64(params.seed);
    let (train, valid) = validation_split(y, classes, params.validation, &mut rng)?;
    let mut net = initial(params, inputs, &train, classes, &mut rng)?;
    let rule = Backprop {
        act: Activation::Spike {
            slope: params.slope,
        },
        detach_reset: params.detach_reset,
    };
    // With standardised inputs the optimiser moves their parameters, of which the network
    // is made after each step; without, the network's own.
    let scaled = params.standardize.then(|| Standardised::of(inputs, &train));
    let mut moved = scaled.as_ref().map(|z| (z, z.trained(&net)));
    let mut adam = Adam::new(&net, params);
    let mut best = (f64::INFINITY, net.clone(), 0);
    let mut order = train.clone();
    let mut epochs = 0;
    for epoch in 1..=params.epochs {
        neurotex_core::progress::stop_point();
        epochs = epoch;
        order.shuffle(&mut rng);
        for batch in order.chunks(params.batch) {
            let seen = seen_inputs(params, inputs, batch, &mut rng);
            let mut grad = batch_gradient(&net, &seen, y, batch, rule);
            match &mut moved {
                None => adam.step(&mut net, &grad),
                Some((z, trained)) => {
                    z.gradient(&mut grad);
                    adam.step(trained, &grad);
                    net = z.network(trained);
                }
            }
        }
        let loss = mean_loss(&net, inputs, y, &valid);
        each_epoch();
        if loss < best.0 {
            best = (loss, net.clone(), epoch);
        } else if epoch - best.2 >= params.patience {
            break;
        }
    }
    let (validation_loss, mut net, best_epoch) = best;
    // Weights a float32 file (NIR, NumPy) holds exactly: the model file and its export
    // predict alike.
    for w in net.params_mut() {
        w.iter_mut().for_each(|v| *v = f64::from(*v as f32));
    }
    let log = TrainingLog {
        epochs,
        best_epoch,
        validation_loss,
    };
    Ok((net, log))
}

fn check_inputs(inputs: &[&SpikeInput], y: &[usize]) -> Result<(), ClassifyError> {
    if inputs.is_empty() || inputs.len() != y.len() {
        return Err(ClassifyError::Empty { what: "train on" });
    }
    let width = inputs[0].inputs;
    if let Some(i) = inputs.iter().position(|x| x.inputs != width) {
        return Err(ClassifyError::BadFeatures(format!(
            "recording {i} has {} spike inputs, the first has {width}",
            inputs[i].inputs
        )));
    }
    if inputs.iter().all(|x| x.total() == 0) {
        return Err(ClassifyError::BadFeatures(
            "no training recording has a spike: the spiking classifier has nothing to learn from"
                .into(),
        ));
    }
    Ok(())
}

/// Each class's recordings shuffled, `share` of them (rounded, at least one) set aside for
/// validation; every class must keep at least one to train on.
fn validation_split(
    y: &[usize],
    classes: usize,
    share: f64,
    rng: &mut ChaCha8Rng,
) -> Result<(Vec<usize>, Vec<usize>), ClassifyError> {
    let (mut train, mut valid) = (Vec::new(), Vec::new());
    for c in 0..classes {
        let mut members: Vec<usize> = (0..y.len()).filter(|&i| y[i] == c).collect();
        if members.is_empty() {
            continue;
        }
        if members.len() < 2 {
            return Err(ClassifyError::ValidationTooSmall {
                class: c.to_string(),
                count: members.len(),
            });
        }
        members.shuffle(rng);
        let held = ((members.len() as f64 * share).round() as usize).clamp(1, members.len() - 1);
        valid.extend_from_slice(&members[..held]);
        train.extend_from_slice(&members[held..]);
    }
    train.sort_unstable();
    valid.sort_unstable();
    Ok((train, valid))
}

/// Initial weights. The input weights are drawn with mean 0 and the spread that gives the
/// hidden membranes a standard deviation of about one threshold under the training data's
/// mean input rate (fluctuation-driven initialisation, Rossbroich, Gygax & Zenke 2022,
/// with Campbell's theorem for Poisson inputs): `σ² n ν Σ_t k_t² = 1`, `k` the membrane's
/// response to one input spike. Readout weights are uniform in `±1/√hidden`; biases start
/// at zero. Recurrent weights start uniform in `±0.1/√hidden`: small against the
/// threshold, so that training starts from the feed-forward dynamics.
fn initial(
    params: &SnnParams,
    inputs: &[&SpikeInput],
    train: &[usize],
    classes: usize,
    rng: &mut ChaCha8Rng,
) -> Result<Network, ClassifyError> {
    let n = inputs[0].inputs;
    let (spikes, steps) = train.iter().fold((0usize, 0usize), |(s, t), &i| {
        (s + inputs[i].total(), t + inputs[i].steps())
    });
    let rate = spikes as f64 / (steps.max(1) * n) as f64;
    if rate <= 0.0 {
        return Err(ClassifyError::BadFeatures(
            "the training recordings of the spiking classifier have no spike".into(),
        ));
    }
    let (alpha, beta, _) = params.decays();
    let sigma = 1.0 / (n as f64 * rate * kernel_energy(alpha, beta)).sqrt();
    let normal = Normal::new(0.0, sigma).expect("a finite positive spread");
    let h = params.hidden;
    let bound = 1.0 / (h as f64).sqrt();
    Ok(Network {
        inputs: n,
        hidden: h,
        classes,
        dt_ms: params.dt_ms,
        tau_syn_ms: params.tau_syn_ms,
        tau_mem_ms: params.tau_mem_ms,
        tau_out_ms: params.tau_out_ms,
        readout: params.readout,
        reset: params.reset,
        target: params.target,
        w_in: (0..n * h).map(|_| normal.sample(rng)).collect(),
        b_in: vec![0.0; h],
        w_out: (0..h * classes)
            .map(|_| rng.gen_range(-bound..bound))
            .collect(),
        b_out: vec![0.0; classes],
        w_rec: match params.recurrent {
            true => (0..h * h)
                .map(|_| 0.1 * rng.gen_range(-bound..bound))
                .collect(),
            false => Vec::new(),
        },
        alpha: Vec::new(),
        beta: Vec::new(),
        travel_mm_s: None,
        adaptation: params.adaptation(),
        delays: Vec::new(),
    }
    .with_own_decays(params, rng)
    .with_delays(params, rng))
}

impl Network {
    /// With [`SnnParams::train_decays`], each hidden neuron's own decays, drawn from its time
    /// constants' gamma distributions of shape 3 about the shared ones (Perez-Nieves et al.
    /// 2021 start heterogeneous neurons so), kept within [`super::TRAINED_DECAYS`].
    fn with_own_decays(mut self, params: &SnnParams, rng: &mut ChaCha8Rng) -> Network {
        if !params.train_decays {
            return self;
        }
        let dt = f64::from(params.dt_ms);
        let (low, high) = super::TRAINED_DECAYS;
        let mut draw = |tau: f64| -> Vec<f64> {
            let gamma = rand_distr::Gamma::new(3.0, tau / 3.0).expect("a positive time constant");
            (0..self.hidden)
                .map(|_| (-dt / gamma.sample(rng)).exp().clamp(low, high))
                .collect()
        };
        self.alpha = draw(params.tau_syn_ms);
        self.beta = draw(params.tau_mem_ms);
        self
    }
}

impl Network {
    /// With [`SnnParams::delay_ms`], each input synapse's delay drawn uniformly from 0 to
    /// the longest, in steps (Hammouamri et al. 2024 start them spread so).
    fn with_delays(mut self, params: &SnnParams, rng: &mut ChaCha8Rng) -> Network {
        if let Some(longest) = params.delay_steps() {
            self.delays = (0..self.w_in.len())
                .map(|_| rng.gen_range(0.0..=longest))
                .collect();
        }
        self
    }
}

/// `Σ_t k_t²` of the membrane's response to one unit input,
/// `k_t = Σ_{s ≤ t} α^s β^{t-s}` (no threshold), summed until it no longer changes.
fn kernel_energy(alpha: f64, beta: f64) -> f64 {
    let (mut current, mut membrane, mut energy) = (1.0f64, 0.0f64, 0.0f64);
    for _ in 0..100_000 {
        membrane = beta * membrane + current;
        current *= alpha;
        energy += membrane * membrane;
        if membrane < 1e-9 * energy.sqrt() {
            break;
        }
    }
    energy
}

/// What the network is trained on for each recording of `batch`, in batch order: the
/// recording whole, or with [`SnnParams::window_ms`] a window of that length starting at
/// a step drawn uniformly among those that fit; with [`SnnParams::warp`] `W`, that
/// stretched or squeezed by a factor `f = e^u`, `u` uniform in `±ln W` (step `t` to step
/// `⌊t / f⌋`). The draws come in batch order from the one stream.
fn seen_inputs<'a>(
    params: &SnnParams,
    inputs: &[&'a SpikeInput],
    batch: &[usize],
    rng: &mut ChaCha8Rng,
) -> Vec<Cow<'a, SpikeInput>> {
    let cut = |x: &'a SpikeInput, rng: &mut ChaCha8Rng| match params.window_steps() {
        Some(len) if len > 0 && len < x.steps() => {
            Cow::Owned(x.window(rng.gen_range(0..=x.steps() - len), len))
        }
        _ => Cow::Borrowed(x),
    };
    let warp = |x: Cow<'a, SpikeInput>, rng: &mut ChaCha8Rng| match params.warp {
        Some(w) => {
            let u: f64 = rng.gen_range(-w.ln()..=w.ln());
            Cow::Owned(x.rebin(u.exp()))
        }
        None => x,
    };
    (batch.iter())
        .map(|&i| {
            let seen = cut(inputs[i], rng);
            warp(seen, rng)
        })
        .collect()
}

thread_local! {
    /// Each thread's trajectory, kept from one recording and batch to the next: a new one
    /// for each (megabytes on long slides) cost its pages anew, and the kernel's work on
    /// them was a fifth of training's CPU time (11 s of system time in 56 s).
    static TRAJECTORY: std::cell::RefCell<Trajectory> = std::cell::RefCell::new(Trajectory::default());
}

/// The batch's mean gradient over `seen` (the batch's inputs, in batch order): each
/// recording's on some thread, summed in batch order.
fn batch_gradient(
    net: &Network,
    seen: &[Cow<'_, SpikeInput>],
    y: &[usize],
    batch: &[usize],
    rule: Backprop,
) -> Gradient {
    let weight = 1.0 / batch.len() as f64;
    let parts: Vec<Gradient> = seen
        .par_iter()
        .zip(batch)
        .map(|(x, &i)| {
            let mut g = Gradient::zeros(net);
            // The pass runs no parallel work, so no other recording's pass can borrow the
            // thread's trajectory while this one holds it.
            TRAJECTORY
                .with_borrow_mut(|tr| loss_and_gradient(net, x, y[i], rule, weight, tr, &mut g));
            g
        })
        .collect();
    let mut sum = Gradient::zeros(net);
    for g in &parts {
        sum.add(g);
    }
    sum
}

/// The mean cross-entropy over `which` (in recording order, so the sum is the same on
/// any number of threads).
fn mean_loss(net: &Network, inputs: &[&SpikeInput], y: &[usize], which: &[usize]) -> f64 {
    let losses: Vec<f64> = which
        .par_iter()
        .map(|&i| {
            let p = softmax(&net.scores(inputs[i]));
            -p[y[i]].max(f64::MIN_POSITIVE).ln()
        })
        .collect();
    losses.iter().sum::<f64>() / which.len().max(1) as f64
}

/// Training on standardised inputs ([`SnnParams::standardize`]): each input's mean spike
/// count per step in each training recording, their mean `μ` and spread `σ` across the
/// recordings (at least a thousandth of a spike per step, so that an input that hardly
/// varies is not scaled without bound). The optimiser moves `V` and `c` of the current
/// `Σ_i z_i V_i + c`, `z_i = (x_i - μ_i) / σ_i`; the network runs on the same current
/// written in its own counts, `W_i = V_i / σ_i`, `b = c - Σ_i μ_i V_i / σ_i`.
struct Standardised {
    mean: Vec<f64>,
    spread: Vec<f64>,
}

impl Standardised {
    fn of(inputs: &[&SpikeInput], train: &[usize]) -> Self {
        let n = inputs[0].inputs;
        let rates: Vec<Vec<f64>> = (train.iter())
            .map(|&r| {
                let mut counts = vec![0.0; n];
                (0..inputs[r].steps())
                    .flat_map(|t| inputs[r].at(t))
                    .for_each(|&i| counts[i as usize] += inputs[r].scale());
                let steps = inputs[r].steps().max(1) as f64;
                counts.iter().map(|c| c / steps).collect()
            })
            .collect();
        let m = rates.len().max(1) as f64;
        let mean: Vec<f64> = (0..n)
            .map(|i| rates.iter().map(|r| r[i]).sum::<f64>() / m)
            .collect();
        let spread = (0..n)
            .map(|i| {
                let var = rates.iter().map(|r| (r[i] - mean[i]).powi(2)).sum::<f64>() / m;
                var.sqrt().max(1e-3)
            })
            .collect();
        Standardised { mean, spread }
    }

    /// The parameters the optimiser moves of the network `net` (the same current).
    fn trained(&self, net: &Network) -> Network {
        let (mut t, h_n) = (net.clone(), net.hidden);
        for (i, (mu, sd)) in self.mean.iter().zip(&self.spread).enumerate() {
            for h in 0..h_n {
                t.w_in[i * h_n + h] = net.w_in[i * h_n + h] * sd;
                t.b_in[h] += mu * net.w_in[i * h_n + h];
            }
        }
        t
    }

    /// The network of the moved parameters `t`.
    fn network(&self, t: &Network) -> Network {
        let (mut net, h_n) = (t.clone(), t.hidden);
        for (i, (mu, sd)) in self.mean.iter().zip(&self.spread).enumerate() {
            for h in 0..h_n {
                net.w_in[i * h_n + h] = t.w_in[i * h_n + h] / sd;
                net.b_in[h] -= mu * t.w_in[i * h_n + h] / sd;
            }
        }
        net
    }

    /// The loss's gradient in the moved parameters, from its gradient in the network's:
    /// `∂L/∂V_i = (∂L/∂W_i - μ_i ∂L/∂b) / σ_i`; `∂L/∂c = ∂L/∂b`.
    fn gradient(&self, g: &mut Gradient) {
        let h_n = g.b_in.len();
        for (i, (mu, sd)) in self.mean.iter().zip(&self.spread).enumerate() {
            for h in 0..h_n {
                g.w_in[i * h_n + h] = g.w_in[i * h_n + h] / sd - mu / sd * g.b_in[h];
            }
        }
    }
}

/// Adam (Kingma & Ba 2015) with its usual constants. Delays, in steps, move at the
/// learning rate times their longest: a step of Adam moves each parameter by about its
/// rate, so delays then cross the same share of their range as weights of order 1 do of
/// theirs (Hammouamri et al. 2024 also give the delays a rate of their own, far above the
/// weights').
struct Adam {
    rate: f64,
    /// The delays' rate and their longest, in steps.
    delays: (f64, f64),
    m: Gradient,
    v: Gradient,
    t: i32,
}

impl Adam {
    fn new(net: &Network, params: &SnnParams) -> Self {
        let longest = params.delay_steps().unwrap_or(0.0);
        Adam {
            rate: params.learning_rate,
            delays: (params.learning_rate * longest.max(1.0), longest),
            m: Gradient::zeros(net),
            v: Gradient::zeros(net),
            t: 0,
        }
    }

    fn step(&mut self, net: &mut Network, grad: &Gradient) {
        const B1: f64 = 0.9;
        const B2: f64 = 0.999;
        const EPS: f64 = 1e-8;
        self.t += 1;
        let c1 = 1.0 - B1.powi(self.t);
        let c2 = 1.0 - B2.powi(self.t);
        let (ms, vs) = (self.m.parts_mut(), self.v.parts_mut());
        let (delay_rate, longest) = self.delays;
        let rates = [self.rate; 7].into_iter().chain([delay_rate]);
        for ((((p, m), v), g), rate) in net
            .params_mut()
            .into_iter()
            .zip(ms)
            .zip(vs)
            .zip(grad.parts())
            .zip(rates)
        {
            for j in 0..p.len() {
                m[j] = B1 * m[j] + (1.0 - B1) * g[j];
                v[j] = B2 * v[j] + (1.0 - B2) * g[j] * g[j];
                p[j] -= rate * (m[j] / c1) / ((v[j] / c2).sqrt() + EPS);
            }
        }
        net.delays
            .iter_mut()
            .for_each(|d| *d = d.clamp(0.0, longest));
        // Each neuron's own decays stay decays (projected gradient descent).
        let (low, high) = super::TRAINED_DECAYS;
        for d in net.alpha.iter_mut().chain(net.beta.iter_mut()) {
            *d = d.clamp(low, high);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The kernel's energy against a direct sum of the closed form
    /// `k_t = (α^{t+1} - β^{t+1}) / (α - β)`.
    #[test]
    fn kernel_energy_matches_the_closed_form() {
        let (a, b) = (0.6f64, 0.8f64);
        let direct: f64 = (0..5000)
            .map(|t| ((a.powi(t + 1) - b.powi(t + 1)) / (a - b)).powi(2))
            .sum();
        assert!((kernel_energy(a, b) - direct).abs() < 1e-9 * direct);
    }

    /// Training on standardised inputs: the network of the moved parameters is the
    /// network they were made from, and their gradient, from the network's, is the central
    /// finite difference of the loss (a smooth spike, so that the loss has a gradient).
    #[test]
    fn standardised_parameters_give_the_network_and_the_gradient_of_the_loss() {
        use super::super::grad::{Activation, Backprop, Trajectory};
        use super::super::{Readout, Reset};
        let (inputs, _) = two_class_task(6, 30);
        let refs: Vec<&SpikeInput> = inputs.iter().collect();
        let z = Standardised::of(&refs, &[0, 1, 2, 3, 4]);
        assert!(z.spread.iter().all(|&sd| sd > 2e-3), "{:?}", z.spread);
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let mut w =
            |k: usize, s: f64| -> Vec<f64> { (0..k).map(|_| rng.gen_range(-s..s)).collect() };
        let (n, h, c) = (4, 5, 2);
        let net = Network {
            inputs: n,
            hidden: h,
            classes: c,
            dt_ms: 5,
            tau_syn_ms: 10.0,
            tau_mem_ms: 20.0,
            tau_out_ms: 15.0,
            readout: Readout::Mean,
            reset: Reset::Zero,
            w_in: w(n * h, 1.5),
            b_in: w(h, 0.2),
            w_out: w(h * c, 1.0),
            b_out: w(c, 0.3),
            w_rec: Vec::new(),
            target: Default::default(),
            alpha: Vec::new(),
            beta: Vec::new(),
            travel_mm_s: None,
            adaptation: None,
            delays: Vec::new(),
        };
        let moved = z.trained(&net);
        let back = z.network(&moved);
        for (a, b) in back
            .w_in
            .iter()
            .chain(&back.b_in)
            .zip(net.w_in.iter().chain(&net.b_in))
        {
            assert!((a - b).abs() <= 1e-12 * (1.0 + b.abs()), "{a} against {b}");
        }
        let rule = Backprop {
            act: Activation::Smooth { k: 4.0 },
            detach_reset: false,
        };
        let loss_of = |moved: &Network, grad: &mut Gradient| {
            let net = z.network(moved);
            loss_and_gradient(
                &net,
                &inputs[5],
                1,
                rule,
                1.0,
                &mut Trajectory::default(),
                grad,
            )
        };
        let mut grad = Gradient::zeros(&net);
        loss_of(&moved, &mut grad);
        z.gradient(&mut grad);
        let eps = 1e-6;
        for part in 0..2 {
            for j in 0..grad.parts()[part].len() {
                let bumped = |d: f64| {
                    let mut m = moved.clone();
                    m.params_mut()[part][j] += d;
                    loss_of(&m, &mut Gradient::zeros(&net))
                };
                let numeric = (bumped(eps) - bumped(-eps)) / (2.0 * eps);
                let analytic = grad.parts()[part][j];
                assert!(
                    (numeric - analytic).abs() < 1e-6 * (1.0 + numeric.abs()),
                    "part {part}, {j}: {numeric} against {analytic}"
                );
            }
        }
    }

    /// `n` recordings of `steps` steps, two classes told apart by which two of four inputs
    /// fire more.
    fn two_class_task(n: usize, steps: u32) -> (Vec<SpikeInput>, Vec<usize>) {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let mut data = Vec::new();
        let mut y = Vec::new();
        for k in 0..n {
            let class = k % 2;
            let mut events = Vec::new();
            for t in 0..steps {
                for i in 0..4u32 {
                    let rate = if (i < 2) == (class == 0) { 0.3 } else { 0.05 };
                    if rng.gen_bool(rate) {
                        events.push((t, i));
                    }
                }
            }
            data.push(SpikeInput::from_events(4, steps as usize, &events));
            y.push(class);
        }
        (data, y)
    }

    /// `net`, trained with `params`, tells at least 36 of the 40 recordings of
    /// [`two_class_task`] apart, and training on one thread gives it bit for bit.
    fn learned_alike_on_one_thread(
        params: &SnnParams,
        refs: &[&SpikeInput],
        y: &[usize],
        (net, log): (&Network, TrainingLog),
    ) {
        let correct = refs
            .iter()
            .zip(y)
            .filter(|(x, &c)| {
                let s = net.scores(x);
                (s[1] > s[0]) == (c == 1)
            })
            .count();
        assert!(correct >= 36, "{correct} of 40 right, log {log:?}");
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let (again, _) = one.install(|| fit(params, refs, y, 2)).unwrap();
        assert_eq!(&again, net);
    }

    /// Two classes told apart by which input fires: the network learns them, and the same
    /// seed gives the same network on one thread and on several.
    #[test]
    fn learns_a_separable_task_deterministically() {
        let (data, y) = two_class_task(40, 50);
        let refs: Vec<&SpikeInput> = data.iter().collect();
        let params = SnnParams {
            hidden: 16,
            epochs: 30,
            ..SnnParams::default()
        };
        let (net, log) = fit(&params, &refs, &y, 2).unwrap();
        learned_alike_on_one_thread(&params, &refs, &y, (&net, log));
        assert!(log.best_epoch >= 1 && log.epochs <= 30);
    }

    /// A progress callback hears one tick per epoch run, whether early stopping ends
    /// training before the parameters' epochs or not, and changes nothing of the network.
    #[test]
    fn each_epoch_ticks_once_early_stopping_or_not() {
        let (data, _) = two_class_task(40, 50);
        // Labels the inputs do not carry (the task's classes alternate): the validation
        // loss soon stops falling, so early stopping ends training.
        let y: Vec<usize> = (0..data.len()).map(|k| (k / 2) % 2).collect();
        let refs: Vec<&SpikeInput> = data.iter().collect();
        for patience in [1, 100] {
            let params = SnnParams {
                hidden: 16,
                epochs: 120,
                patience,
                ..SnnParams::default()
            };
            let ticks = std::sync::atomic::AtomicUsize::new(0);
            let tick = || {
                ticks.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            };
            let (net, log) = fit_with(&params, &refs, &y, 2, &tick).unwrap();
            assert_eq!(ticks.into_inner(), log.epochs, "patience {patience}");
            assert_eq!((net, log), fit(&params, &refs, &y, 2).unwrap());
            if patience == 1 {
                assert!(log.epochs < 120, "{log:?}");
            }
        }
    }

    /// Training on windows: a window no shorter than every recording trains on them whole
    /// (the same network bit for bit), short windows still learn the task, and a seed
    /// gives one network on any number of threads.
    #[test]
    fn windows_train_on_parts_of_each_recording() {
        let (data, y) = two_class_task(40, 50);
        let refs: Vec<&SpikeInput> = data.iter().collect();
        let whole = SnnParams {
            hidden: 16,
            epochs: 30,
            ..SnnParams::default()
        };
        let long = SnnParams {
            window_ms: Some(50 * whole.dt_ms as usize),
            ..whole
        };
        assert_eq!(
            fit(&whole, &refs, &y, 2).unwrap(),
            fit(&long, &refs, &y, 2).unwrap()
        );
        let short = SnnParams {
            window_ms: Some(10 * whole.dt_ms as usize),
            ..whole
        };
        let (net, log) = fit(&short, &refs, &y, 2).unwrap();
        assert_ne!(net, fit(&whole, &refs, &y, 2).unwrap().0);
        learned_alike_on_one_thread(&short, &refs, &y, (&net, log));
    }

    /// Time-warped training: each epoch's recordings are their steps stretched or squeezed
    /// within the bound (never by more, and by different factors), the task is still
    /// learnt, a seed gives one network on any number of threads, and bounds that are no
    /// warp or past the largest are refused.
    #[test]
    fn warped_recordings_keep_their_spikes_within_the_bound() {
        let (data, y) = two_class_task(40, 50);
        let refs: Vec<&SpikeInput> = data.iter().collect();
        let plain = SnnParams {
            hidden: 16,
            epochs: 30,
            ..SnnParams::default()
        };
        let warped = SnnParams {
            warp: Some(2.0),
            ..plain
        };
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let batch: Vec<usize> = (0..40).collect();
        let seen = seen_inputs(&warped, &refs, &batch, &mut rng);
        let mut lengths: Vec<usize> = seen.iter().map(|x| x.steps()).collect();
        for (x, &i) in seen.iter().zip(&batch) {
            assert_eq!(x.total(), refs[i].total());
            assert!((25..=100).contains(&x.steps()), "{} steps", x.steps());
        }
        lengths.sort_unstable();
        lengths.dedup();
        assert!(lengths.len() > 10, "{lengths:?}");
        let (net, log) = fit(&warped, &refs, &y, 2).unwrap();
        assert_ne!(net, fit(&plain, &refs, &y, 2).unwrap().0);
        learned_alike_on_one_thread(&warped, &refs, &y, (&net, log));
        for w in [1.0, 0.5, 10.5, f64::NAN] {
            let p = SnnParams {
                warp: Some(w),
                ..plain
            };
            let err = p.check().unwrap_err().to_string();
            assert!(err.contains("snn-warp"), "{err}");
        }
        let xylo = SnnParams {
            target: crate::snn::Target::Xylo,
            reset: crate::snn::Reset::Subtract,
            ..warped
        };
        let err = xylo.check().unwrap_err().to_string();
        assert!(err.contains("snn-warp"), "{err}");
    }

    #[test]
    fn a_window_shorter_than_a_step_is_refused() {
        let p = SnnParams {
            window_ms: Some(5),
            ..SnnParams::default()
        };
        let err = p.check().unwrap_err().to_string();
        assert!(err.contains("snn-window-ms"), "{err}");
    }

    #[test]
    fn a_class_of_one_cannot_be_split() {
        let x = SpikeInput::from_events(2, 3, &[(0, 0)]);
        let refs = vec![&x, &x, &x];
        let err = fit(&SnnParams::default(), &refs, &[0, 0, 1], 2).unwrap_err();
        assert!(
            matches!(&err, ClassifyError::ValidationTooSmall { class, count: 1 } if class == "1"),
            "{err}"
        );
    }
}
