//! The Xylo profile: the spiking network as SynSense's Xylo Audio 2 chip (SYNS61201) runs
//! it, in integers, step for step as its bit-accurate simulator `XyloSim` (the `xylosim`
//! package, through Rockpool's `XyloSim.from_specification`).
//!
//! **The chip's neuron**, measured on `xylosim` 0.1.3 (`tools/nir_interop/xylo.sh` runs the
//! comparison): states are 16-bit signed integers that saturate, and a decay by the
//! bitshift `dash` d is `D(v) = v - max(v >> d, 1)` for `v > 0` and `v - (v >> d)` (an
//! arithmetic shift, so at least 1) for `v < 0`, `1 - 2^-d` per step. Each step, with input
//! counts `x` (at most 15 per channel), weights `W << shift` and spike counts `n`:
//!
//! ```text
//! I[t] = D_syn(I[t-1] ⊕ Σ_i x_i[t] W_in[i])      ⊕ a saturating add, input by input
//! V[t] = D_mem(V[t-1]) ⊕ I[t] ⊕ bias
//! n[t] = min(⌊V[t] / θ⌋, 31) when V[t] ≥ θ, else 0;  V[t] -= n[t] θ
//! J[t] = D_syn_out(J[t-1] ⊕ Σ_h n_h[t-1] W_out[h])  the readout, one step behind
//! O[t] = D_mem_out(O[t-1]) ⊕ J[t] ⊕ bias_out     (one spike at most, at θ_out)
//! ```
//!
//! **From neurotex's network.** A network trained with the profile ([`Target::Xylo`]) has
//! the chip's shape (at most 16 inputs, 1 000 hidden neurons and 8 classes, a step of at
//! most 15 ms so that a channel never carries more than 15 events in one, subtractive
//! reset, feed-forward) and decays that are bitshifts (its time constants moved to the
//! nearest the chip has). [`XyloNetwork::quantise`] maps it:
//! - the chip adds a step's input before the synaptic decay, so `W_in = w_in / α`;
//! - a spike's whole effect on the readout passes through its synapse, `Σ_k α_o^{k+1} =
//!   α_o / (1 - α_o)`, so `W_out = w_out (1 - α_o) / α_o`;
//! - neurotex's hidden bias is a current, the chip's a membrane input: `b / (1 - α)` gives
//!   the same drive once the current has settled (a few steps);
//! - each hidden neuron gets its own threshold θ, the largest that keeps its input weights
//!   in 8 bits (with one shift for the layer) and at most [`THRESHOLD_CAP`], so states of
//!   several thresholds fit in 16 bits; the readout one scale for all classes (their scores
//!   are compared), its threshold the largest state, so it does not fire.
//!
//! A class's score is the mean (or the largest value) of its readout membrane over the
//! window, divided by the readout's scale: the float network's score, to quantisation.

use serde::{Deserialize, Serialize};

use super::{Network, Readout, Reset, SpikeInput};
use crate::error::ModelError;

/// Where the network runs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Target {
    /// neurotex's float network (the default).
    #[default]
    Float,
    /// Xylo Audio 2, in integers, as its bit-accurate simulator runs it.
    Xylo,
}

impl Target {
    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Target::Float => "float",
            Target::Xylo => "xylo",
        }
    }

    /// Whether this is the default float network (which model files leave out).
    pub fn is_float(&self) -> bool {
        *self == Target::Float
    }
}

impl std::str::FromStr for Target {
    type Err = crate::error::ParamError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "float" => Ok(Target::Float),
            "xylo" => Ok(Target::Xylo),
            _ => Err(crate::error::ParamError::new(
                "snn-target",
                "the target must be float or xylo",
                s,
            )),
        }
    }
}

/// Input channels of the chip.
pub const MAX_INPUTS: usize = 16;
/// Hidden neurons of the chip.
pub const MAX_HIDDEN: usize = 1000;
/// Readout neurons of the chip.
pub const MAX_CLASSES: usize = 8;
/// Events one input channel carries in one step.
pub const MAX_INPUT_EVENTS: u32 = 15;
/// The longest step: the encoder spikes at most once a millisecond per input, so a step
/// of at most 15 ms never carries more than 15 events.
pub const MAX_DT_MS: u32 = 15;
/// Spikes a hidden neuron emits in one step.
pub const MAX_SPIKES: i32 = 31;
/// The largest dash (bitshift decay) neurotex uses: `1 - 2^-15` is as slow as a 16-bit
/// state can decay.
pub const MAX_DASH: u8 = 15;
/// The largest hidden threshold the quantiser gives: states of several thresholds (the
/// membrane before a spike, a current) then fit in 16 bits.
pub const THRESHOLD_CAP: i32 = 2048;

const STATE_MAX: i32 = i16::MAX as i32;
const STATE_MIN: i32 = i16::MIN as i32;

/// The decay per step of a dash: `1 - 2^-dash`.
pub fn decay_of(dash: u8) -> f64 {
    1.0 - (-f64::from(dash)).exp2()
}

/// The time constant (ms) whose decay per step of `dt_ms` is `1 - 2^-dash`.
pub fn tau_of(dash: u8, dt_ms: u32) -> f64 {
    -f64::from(dt_ms) / decay_of(dash).ln()
}

/// The dash (1 to [`MAX_DASH`]) whose time constant is nearest `tau_ms` (by ratio).
pub fn dash_of(tau_ms: f64, dt_ms: u32) -> u8 {
    (1..=MAX_DASH)
        .min_by(|&a, &b| {
            let off = |d: u8| (tau_of(d, dt_ms) / tau_ms).ln().abs();
            off(a).total_cmp(&off(b))
        })
        .unwrap_or(1)
}

/// The dash of `tau_ms` when its decay is a bitshift, to rounding.
fn exact_dash(tau_ms: f64, dt_ms: u32) -> Option<u8> {
    let d = dash_of(tau_ms, dt_ms);
    ((tau_of(d, dt_ms) / tau_ms - 1.0).abs() < 1e-9).then_some(d)
}

/// Checks that a network's shape fits the chip: inputs, hidden neurons, classes.
///
/// # Errors
/// [`ModelError::Network`]: the first limit exceeded, as a sentence naming it.
pub fn check_shape(inputs: usize, hidden: usize, classes: usize) -> Result<(), ModelError> {
    let limits = [
        (
            "inputs",
            "inputs",
            inputs,
            MAX_INPUTS,
            "use --encoding sa or fa on a grid of at most 16 taxels (compare: --encodings sa,fa), or leave taxels out (import csv --drop-channels)",
        ),
        (
            "hidden",
            "hidden neurons",
            hidden,
            MAX_HIDDEN,
            "use --snn-hidden 1000 or fewer",
        ),
        (
            "classes",
            "classes",
            classes,
            MAX_CLASSES,
            "train on at most 8 classes",
        ),
    ];
    for (parameter, what, got, most, how) in limits {
        if got > most {
            return Err(ModelError::network(
                parameter,
                format!(
                "the Xylo profile holds at most {most} {what}, and this network has {got}: {how}"
            ),
            ));
        }
    }
    Ok(())
}

/// Checks every rule of the profile on a trained network.
///
/// # Errors
/// [`ModelError::Network`]: the first rule broken, as a sentence naming it.
pub fn check(net: &Network) -> Result<(), ModelError> {
    check_shape(net.inputs, net.hidden, net.classes)?;
    if net.dt_ms > MAX_DT_MS {
        return Err(ModelError::network("dt_ms", format!("the Xylo profile steps at most {MAX_DT_MS} ms (so that an input never carries more than {MAX_INPUT_EVENTS} events in a step), and this network steps {} ms", net.dt_ms)));
    }
    if net.reset != Reset::Subtract {
        return Err(ModelError::network("reset", "the Xylo profile's neurons subtract the threshold on a spike, and this network resets to zero"));
    }
    if net.recurrent() {
        return Err(ModelError::network(
            "w_rec",
            "the Xylo profile runs feed-forward networks; this one is recurrent",
        ));
    }
    if net.own_decays() {
        return Err(ModelError::network(
            "alpha",
            "the Xylo profile's neurons share the chip's bitshift decays; this network's neurons have decays of their own",
        ));
    }
    for (name, tau) in [
        ("tau_syn_ms", net.tau_syn_ms),
        ("tau_mem_ms", net.tau_mem_ms),
        ("tau_out_ms", net.tau_out_ms),
    ] {
        if exact_dash(tau, net.dt_ms).is_none() {
            return Err(ModelError::network(name, format!("the network's {name} is {tau}, whose decay per step of {} ms is not one the chip has (1 - 2^-d)", net.dt_ms)));
        }
    }
    Ok(())
}

/// A network in the chip's integers: what `XyloSim.from_specification` takes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct XyloNetwork {
    /// Input channels.
    pub inputs: usize,
    /// Hidden neurons.
    pub hidden: usize,
    /// Readout neurons, one per class.
    pub classes: usize,
    /// The step, ms.
    pub dt_ms: u32,
    /// Input weights, input-major: `weights_in[i * hidden + h]`.
    pub weights_in: Vec<i8>,
    /// Readout weights, hidden-major: `weights_out[h * classes + c]`.
    pub weights_out: Vec<i8>,
    /// Left shift of the input weights.
    pub weight_shift_in: u8,
    /// Left shift of the readout weights.
    pub weight_shift_out: u8,
    /// Dashes of the hidden synapse and membrane, and of the readout's.
    pub dash_syn: u8,
    /// Dash of the hidden membrane.
    pub dash_mem: u8,
    /// Dash of the readout synapse.
    pub dash_syn_out: u8,
    /// Dash of the readout membrane.
    pub dash_mem_out: u8,
    /// Hidden thresholds, one per neuron.
    pub threshold: Vec<i32>,
    /// Hidden biases (added to the membrane each step).
    pub bias: Vec<i32>,
    /// The readout's threshold (the largest state: it does not fire).
    pub threshold_out: i32,
    /// Readout biases.
    pub bias_out: Vec<i32>,
    /// Readout units per unit of the float network's readout.
    pub score_scale: f64,
    /// How scores are read from the readout.
    pub readout: Readout,
}

fn quantise_to(v: f64, scale: f64, low: i32, high: i32) -> i32 {
    // The value is finite (the network is checked) and clamped before the cast.
    (v * scale).round().clamp(f64::from(low), f64::from(high)) as i32
}

/// The largest shift (0 to 7) at which the median neuron's threshold stays within the cap.
fn layer_shift(peaks: &[f64]) -> u8 {
    let mut sorted: Vec<f64> = peaks.iter().copied().filter(|p| *p > 0.0).collect();
    sorted.sort_by(f64::total_cmp);
    let Some(&median) = sorted.get(sorted.len() / 2) else {
        return 0;
    };
    (0..=7u8)
        .rev()
        .find(|&s| 127.0 * f64::from(1u32 << s) / median <= f64::from(THRESHOLD_CAP))
        .unwrap_or(0)
}

impl XyloNetwork {
    /// The chip's integers for `net` (see the module).
    ///
    /// # Errors
    /// [`ModelError::Network`]: a network that breaks a rule of the profile ([`check`]).
    pub fn quantise(net: &Network) -> Result<XyloNetwork, ModelError> {
        check(net)?;
        let (h_n, c_n) = (net.hidden, net.classes);
        let dash = |tau| exact_dash(tau, net.dt_ms).unwrap_or(1);
        let (ds, dm, dmo) = (
            dash(net.tau_syn_ms),
            dash(net.tau_mem_ms),
            dash(net.tau_out_ms),
        );
        let dso = 1u8;
        let (alpha, alpha_out) = (decay_of(ds), decay_of(dso));
        let w_in = |i: usize, h: usize| net.w_in[i * h_n + h] / alpha;
        let peaks: Vec<f64> = (0..h_n)
            .map(|h| {
                (0..net.inputs)
                    .map(|i| w_in(i, h).abs())
                    .fold(0.0, f64::max)
            })
            .collect();
        let shift_in = layer_shift(&peaks);
        let unit_in = f64::from(1u32 << shift_in);
        let threshold: Vec<i32> = peaks
            .iter()
            .map(|&p| match p > 0.0 {
                true => quantise_to(127.0 * unit_in / p, 1.0, 1, THRESHOLD_CAP),
                false => THRESHOLD_CAP,
            })
            .collect();
        let weights_in = (0..net.inputs * h_n)
            .map(|k| {
                let (i, h) = (k / h_n, k % h_n);
                quantise_to(w_in(i, h), f64::from(threshold[h]) / unit_in, -128, 127) as i8
            })
            .collect();
        let bias = (0..h_n)
            .map(|h| {
                let b = net.b_in[h] / (1.0 - alpha);
                quantise_to(b, f64::from(threshold[h]), STATE_MIN, STATE_MAX)
            })
            .collect();
        let gain_out = (1.0 - alpha_out) / alpha_out;
        let peak_out = net
            .w_out
            .iter()
            .fold(0.0f64, |m, w| m.max((w * gain_out).abs()));
        let score_scale = if peak_out > 0.0 {
            127.0 / peak_out
        } else {
            1.0
        };
        let weights_out = (0..h_n * c_n)
            .map(|k| quantise_to(net.w_out[k] * gain_out, score_scale, -128, 127) as i8)
            .collect();
        let bias_out = (net.b_out.iter())
            .map(|&b| quantise_to(b, score_scale, STATE_MIN, STATE_MAX))
            .collect();
        Ok(XyloNetwork {
            inputs: net.inputs,
            hidden: h_n,
            classes: c_n,
            dt_ms: net.dt_ms,
            weights_in,
            weights_out,
            weight_shift_in: shift_in,
            weight_shift_out: 0,
            dash_syn: ds,
            dash_mem: dm,
            dash_syn_out: dso,
            dash_mem_out: dmo,
            threshold,
            bias,
            threshold_out: STATE_MAX,
            bias_out,
            score_scale,
            readout: net.readout,
        })
    }

    /// The class scores of a whole window.
    ///
    /// # Panics
    /// If the input's width is not the network's (a caller bug).
    pub fn scores(&self, input: &SpikeInput) -> Vec<f64> {
        assert_eq!(input.inputs, self.inputs);
        let mut state = XyloState::new(self);
        let mut acc = vec![0.0; self.classes];
        for t in 0..input.steps() {
            state.step(self, input.at(t));
            self.readout.fold(t, &mut acc, &state.readout(self));
        }
        self.readout.finish(input.steps(), acc)
    }

    /// The keyword arguments of Rockpool's `XyloSim.from_specification` (and of
    /// `config_from_specification` for a board), as JSON: `weights_in` is
    /// `(inputs, hidden, 2)` with the second synapse unused, `dt` in seconds.
    pub fn specification(&self) -> serde_json::Value {
        let (h_n, c_n) = (self.hidden, self.classes);
        let w_in: Vec<Vec<[i8; 2]>> = (0..self.inputs)
            .map(|i| {
                (0..h_n)
                    .map(|h| [self.weights_in[i * h_n + h], 0])
                    .collect()
            })
            .collect();
        let w_out: Vec<&[i8]> = self.weights_out.chunks(c_n.max(1)).collect();
        serde_json::json!({
            "weights_in": w_in,
            "weights_out": w_out,
            "dash_syn": vec![self.dash_syn; h_n],
            "dash_syn_2": vec![1; h_n],
            "dash_mem": vec![self.dash_mem; h_n],
            "dash_syn_out": vec![self.dash_syn_out; c_n],
            "dash_mem_out": vec![self.dash_mem_out; c_n],
            "threshold": self.threshold,
            "threshold_out": vec![self.threshold_out; c_n],
            "bias": self.bias,
            "bias_out": self.bias_out,
            "weight_shift_in": self.weight_shift_in,
            "weight_shift_rec": 0,
            "weight_shift_out": self.weight_shift_out,
            "dt": f64::from(self.dt_ms) / 1000.0,
        })
    }
}

/// The chip's decay by a bitshift (see the module).
fn decay(v: i32, dash: u8) -> i32 {
    match v.cmp(&0) {
        std::cmp::Ordering::Greater => v - (v >> dash).max(1),
        std::cmp::Ordering::Less => v - (v >> dash),
        std::cmp::Ordering::Equal => 0,
    }
}

fn add(a: i32, b: i32) -> i32 {
    (a + b).clamp(STATE_MIN, STATE_MAX)
}

/// The chip's state, advanced one step at a time.
#[derive(Debug, Clone, PartialEq)]
pub struct XyloState {
    isyn: Vec<i32>,
    vmem: Vec<i32>,
    /// The hidden neurons that spiked in the last step, ascending, with their counts.
    fired: Vec<(u32, i32)>,
    isyn_out: Vec<i32>,
    vmem_out: Vec<i32>,
}

impl XyloState {
    /// The chip at rest.
    pub fn new(net: &XyloNetwork) -> Self {
        XyloState {
            isyn: vec![0; net.hidden],
            vmem: vec![0; net.hidden],
            fired: Vec::new(),
            isyn_out: vec![0; net.classes],
            vmem_out: vec![0; net.classes],
        }
    }

    /// Advances one step with the inputs that spiked in it, in ascending order (an input
    /// listed twice carried two events; more than 15 count as 15).
    pub fn step(&mut self, net: &XyloNetwork, spiked: &[u32]) {
        let (h_n, c_n) = (net.hidden, net.classes);
        // The readout, one step behind: last step's hidden spikes.
        for (c, j) in self.isyn_out.iter_mut().enumerate() {
            for &(h, n) in &self.fired {
                let w = i32::from(net.weights_out[h as usize * c_n + c]) << net.weight_shift_out;
                *j = add(*j, n * w);
            }
            *j = decay(*j, net.dash_syn_out);
        }
        for (c, o) in self.vmem_out.iter_mut().enumerate() {
            *o = add(
                add(decay(*o, net.dash_mem_out), self.isyn_out[c]),
                net.bias_out[c],
            );
            if *o >= net.threshold_out {
                *o -= net.threshold_out;
            }
        }
        let mut k = 0;
        while k < spiked.len() {
            let i = spiked[k] as usize;
            let run = spiked[k..].iter().take_while(|&&s| s as usize == i).count();
            let n = run.min(MAX_INPUT_EVENTS as usize) as i32;
            let w = &net.weights_in[i * h_n..(i + 1) * h_n];
            for (c, &w) in self.isyn.iter_mut().zip(w) {
                *c = add(*c, n * (i32::from(w) << net.weight_shift_in));
            }
            k += run;
        }
        self.fired.clear();
        for h in 0..h_n {
            self.isyn[h] = decay(self.isyn[h], net.dash_syn);
            let v = add(
                add(decay(self.vmem[h], net.dash_mem), self.isyn[h]),
                net.bias[h],
            );
            let theta = net.threshold[h];
            let n = if v >= theta {
                (v / theta).min(MAX_SPIKES)
            } else {
                0
            };
            self.vmem[h] = v - n * theta;
            if n > 0 {
                self.fired.push((h as u32, n));
            }
        }
    }

    /// The readout membranes after the last step, in the float network's units.
    pub fn readout(&self, net: &XyloNetwork) -> Vec<f64> {
        let scale = net.score_scale;
        self.vmem_out
            .iter()
            .map(|&o| f64::from(o) / scale)
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Traces recorded from `xylosim` 0.1.3 (`XyloSim.from_specification(...,
    /// output_mode="Vmem")`, `record=True`, by `tools/nir_interop/xylo_probe.py`, cases
    /// `decay_d*`): one synaptic current after one input event of weight `w` with dash `d`.
    #[test]
    fn decay_follows_the_chip_to_the_last_unit() {
        let mut checked = 0;
        for line in recorded() {
            let Some(name) = line["case"]
                .as_str()
                .and_then(|c| c.strip_prefix("decay_d"))
            else {
                continue;
            };
            let (d, w) = name.split_once("_w").unwrap();
            let (d, w): (u8, i32) = (d.parse().unwrap(), w.parse().unwrap());
            let want: Vec<i64> = serde_json::from_value(line["Isyn"][0].clone()).unwrap();
            let mut v = decay(w, d);
            let mut got = vec![i64::from(v)];
            while got.len() < want.len() {
                v = decay(v, d);
                got.push(i64::from(v));
            }
            assert_eq!(got, want, "dash {d}, weight {w}");
            checked += 1;
        }
        assert_eq!(checked, 6);
    }

    /// The probe's recorded cases, one JSON object each.
    fn recorded() -> Vec<serde_json::Value> {
        include_str!("testdata/xylosim_traces.jsonl")
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect()
    }

    /// A network of `inputs x hidden x classes` with the defaults of the probe
    /// (`tools/nir_interop/xylo_probe.py`): dashes 1, thresholds 30 000 and 32 767.
    fn probe_net(w_in: &[i8], w_out: &[i8], inputs: usize, classes: usize) -> XyloNetwork {
        let hidden = w_in.len() / inputs;
        XyloNetwork {
            inputs,
            hidden,
            classes,
            dt_ms: 1,
            weights_in: w_in.to_vec(),
            weights_out: w_out.to_vec(),
            weight_shift_in: 0,
            weight_shift_out: 0,
            dash_syn: 1,
            dash_mem: 1,
            dash_syn_out: 1,
            dash_mem_out: 1,
            threshold: vec![30_000; hidden],
            bias: vec![0; hidden],
            threshold_out: STATE_MAX,
            bias_out: vec![0; classes],
            score_scale: 1.0,
            readout: Readout::Mean,
        }
    }

    /// Runs `net` on input counts `x[t][i]` and returns the traces the probe records,
    /// neuron by neuron: `Vmem`, `Isyn`, `Spikes`, `Vmem_out`, `Isyn_out`.
    fn traces(net: &XyloNetwork, x: &[&[u32]]) -> serde_json::Value {
        let mut state = XyloState::new(net);
        let (mut v, mut i, mut s) = (
            vec![vec![]; net.hidden],
            vec![vec![]; net.hidden],
            vec![vec![]; net.hidden],
        );
        let (mut vo, mut io) = (vec![vec![]; net.classes], vec![vec![]; net.classes]);
        for counts in x {
            let spiked: Vec<u32> = (0..counts.len() as u32)
                .flat_map(|i| std::iter::repeat_n(i, counts[i as usize] as usize))
                .collect();
            state.step(net, &spiked);
            let fired = |h: usize| {
                state
                    .fired
                    .iter()
                    .find(|f| f.0 as usize == h)
                    .map_or(0, |f| f.1)
            };
            for (h, ((v, i), s)) in v.iter_mut().zip(&mut i).zip(&mut s).enumerate() {
                v.push(state.vmem[h]);
                i.push(state.isyn[h]);
                s.push(fired(h));
            }
            for (c, (vo, io)) in vo.iter_mut().zip(&mut io).enumerate() {
                vo.push(state.vmem_out[c]);
                io.push(state.isyn_out[c]);
            }
        }
        serde_json::json!({"Vmem": v, "Isyn": i, "Spikes": s, "Vmem_out": vo, "Isyn_out": io})
    }

    /// Every case the probe recorded from `xylosim` 0.1.3 (`testdata/xylosim_traces.jsonl`,
    /// written by `tools/nir_interop/xylo_probe.py`), state by state: a neuron several
    /// thresholds high spikes several times and keeps the rest, at most 31 times; the
    /// readout receives the spikes one step later and fires once at its threshold; biases
    /// enter the membrane; inputs beyond 15 events count as 15; sums saturate input by
    /// input at 16 bits.
    #[test]
    fn the_network_steps_as_the_simulator_recorded() {
        let recorded = recorded();
        let small_x: [&[u32]; 8] = [
            &[1, 0],
            &[0, 3],
            &[0, 0],
            &[2, 0],
            &[0, 0],
            &[0, 0],
            &[0, 0],
            &[0, 0],
        ];
        let mut small = probe_net(&[10, 0, 100, 0, -20, 0], &[50, 0, 0, 0, 0, 7], 2, 2);
        (small.dash_mem, small.dash_mem_out) = (2, 2);
        (small.threshold, small.threshold_out) = (vec![30, 30, 60], 100);
        let mut bias = probe_net(&[0], &[1], 1, 1);
        (bias.bias, bias.dash_mem) = (vec![8], 2);
        let mut cap = probe_net(&[127], &[1], 1, 1);
        (cap.threshold, cap.weight_shift_in) = (vec![10], 3);
        let mut clip = probe_net(&[3], &[1], 1, 1);
        clip.threshold = vec![1000];
        let mut order = probe_net(&[127, 127, -127], &[1], 3, 1);
        (order.weight_shift_in, order.dash_syn) = (4, 15);
        let mut negative = probe_net(&[-128], &[1], 1, 1);
        (negative.threshold, negative.weight_shift_in) = (vec![10], 7);
        let mut fires = probe_net(&[100], &[10], 1, 1);
        (fires.threshold, fires.threshold_out) = (vec![20], 5);
        let cases: [(&str, XyloNetwork, Vec<&[u32]>); 7] = [
            ("small", small, small_x.to_vec()),
            ("bias", bias, vec![&[0]; 4]),
            ("cap", cap, vec![&[15], &[0], &[0]]),
            ("clip", clip, vec![&[20], &[0]]),
            ("order", order, vec![&[15, 15, 15], &[0, 0, 0]]),
            ("negative_saturation", negative, vec![&[15]; 3]),
            ("readout_fires", fires, vec![&[1], &[0], &[0], &[0], &[0]]),
        ];
        for (name, net, x) in cases {
            let want = recorded.iter().find(|r| r["case"] == name).unwrap();
            let got = traces(&net, &x);
            for key in ["Vmem", "Isyn", "Spikes", "Vmem_out", "Isyn_out"] {
                assert_eq!(got[key], want[key], "{name}: {key}");
            }
        }
    }
}
