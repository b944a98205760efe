//! The network's training parameters and their rules, the Xylo profile's among them.

use serde::{Deserialize, Serialize};

use super::{xylo, Adaptation, Readout, Reset, Target, Travel};
use crate::error::ParamError;

/// The spiking classifier's parameters (defaults chosen a priori but standardised inputs,
/// chosen by measurement; `docs/spiking-classifier.md` gives the reasons).
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
    /// Train on windows of this many ms, each recording's window drawn anew at each epoch
    /// from anywhere in it (a recording no longer than the window is taken whole); `None`
    /// trains on whole recordings. Validation and prediction read whole recordings. Left
    /// out of model files when absent.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub window_ms: Option<usize>,
    /// Train the input weights on standardised inputs (true): each input's spike count per
    /// step, less its mean over the training recordings, over its spread across them, as
    /// logistic regression z-scores the rates; the network keeps the weights and biases
    /// this folds into. A model file without the key was trained before the option existed,
    /// on the counts as they are.
    #[serde(default)]
    pub standardize: bool,
    /// Train each hidden neuron's synaptic and membrane decays beside the weights
    /// (false: every neuron keeps those of `tau_syn_ms` and `tau_mem_ms`): the neurons start
    /// alike and each finds the time scales its inputs' timing is read at (learnable time
    /// constants, Perez-Nieves et al. 2021). Left out of model files when false.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub train_decays: bool,
    /// How the network counts time: in ms (off), or in travel at the training recordings'
    /// median speed or a given one (each step the distance `dt_ms` covers at that speed;
    /// [`Travel`]). Left out of model files when off.
    #[serde(default = "Travel::off", skip_serializing_if = "Travel::is_off")]
    pub travel: Travel,
    /// Train on time-warped recordings: at each epoch each training recording (or its
    /// window) is stretched or squeezed by a factor drawn log-uniformly between `1/W` and
    /// `W` (step `t` to step `⌊t / f⌋`), as if slid up to `W` times slower or faster with
    /// the same spikes per mm travelled; `None` trains on the recordings as they are.
    /// Validation and prediction read them as they are. Left out of model files when
    /// absent.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub warp: Option<f64>,
    /// Adaptive thresholds (ALIF, Bellec et al. 2020), their time constant in ms: each
    /// hidden neuron's threshold rises with its spikes of the last `adapt_ms` or so and falls
    /// back as it stays silent ([`Adaptation`]); `None`: a fixed threshold. Left out of
    /// model files when absent.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub adapt_ms: Option<f64>,
    /// How far an adaptive threshold rises above 1 at a spike every step (1). Left out of
    /// model files when 1.
    #[serde(skip_serializing_if = "is_one")]
    pub adapt_strength: f64,
    /// Learnable synaptic delays (Hammouamri, Khalfaoui-Hassani & Masquelier 2024), the
    /// longest in ms: each input synapse carries its spikes up to this late, its delay
    /// trained beside its weight ([`super::delay`]); `None`: every input drives the hidden
    /// layer in the step it arrives. Left out of model files when absent.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub delay_ms: Option<f64>,
}

fn is_one(v: &f64) -> bool {
    *v == 1.0
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
            window_ms: None,
            standardize: true,
            train_decays: false,
            travel: Travel::Off,
            warp: None,
            adapt_ms: None,
            adapt_strength: 1.0,
            delay_ms: None,
        }
    }
}

/// Largest hidden layer accepted: beyond it a model file and a training run grow past
/// what these small tactile datasets can fit.
pub const MAX_HIDDEN: usize = 4096;

/// Largest time warp's bound: a recording stretched `W` times is `W` times as long to
/// train on.
pub const MAX_WARP: f64 = 10.0;

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
        if let Some(window) = self.window_ms {
            if window < self.dt_ms as usize {
                let rule = "a training window must hold at least one of the network's time steps";
                let got = format!("{window} ms, under one step of {} ms", self.dt_ms);
                return Err(ParamError::new("snn-window-ms", rule, got));
            }
        }
        if let Some(w) = self.warp {
            if !(w > 1.0 && w <= MAX_WARP) {
                let rule = "a time warp's bound W must be above 1 (no warp: leave it out) and at most 10 (a recording stretched W times is W times as long to train on)";
                return Err(ParamError::new("snn-warp", rule, w));
            }
        }
        self.travel.check()?;
        self.check_adaptation()?;
        self.check_delays()?;
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
            ("snn-train-decays", self.train_decays, "the Xylo profile's neurons share the chip's bitshift decays", "--snn-train-decays".to_string()),
            ("snn-travel", !self.travel.is_off(), "the Xylo profile's inputs are whole events per step, which steps of travel weigh by their length", format!("--snn-travel {}", self.travel.name())),
            ("snn-adapt-ms", self.adapt_ms.is_some(), "the Xylo profile's neurons have fixed thresholds", format!("--snn-adapt-ms {}", self.adapt_ms.unwrap_or_default())),
            ("snn-delay-ms", self.delay_ms.is_some(), "the Xylo profile's synapses carry a spike in the step it arrives (leave out --snn-delay-ms, or train for --snn-target float)", format!("--snn-delay-ms {}", self.delay_ms.unwrap_or_default())),
            ("snn-warp", self.warp.is_some(), "the Xylo profile's inputs carry at most 15 events a step, which squeezed time can exceed (leave out --snn-warp, or train for --snn-target float)", format!("--snn-warp {}", self.warp.unwrap_or_default())),
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

    /// Adaptive thresholds' rules: a positive finite time constant, a positive finite
    /// strength, given only with a time constant, and neurons that reset to zero.
    fn check_adaptation(&self) -> Result<(), ParamError> {
        let Some(tau) = self.adapt_ms else {
            if self.adapt_strength != 1.0 {
                let rule = "an adaptive threshold's strength applies with its time constant (--snn-adapt-ms); without it the thresholds are fixed";
                return Err(ParamError::new(
                    "snn-adapt-strength",
                    rule,
                    self.adapt_strength,
                ));
            }
            return Ok(());
        };
        if !(tau > 0.0 && tau.is_finite()) {
            let rule = "an adaptive threshold's time constant must be positive and finite";
            return Err(ParamError::new("snn-adapt-ms", rule, tau));
        }
        let b = self.adapt_strength;
        if !(b > 0.0 && b.is_finite()) {
            let rule = "an adaptive threshold's strength must be positive and finite";
            return Err(ParamError::new("snn-adapt-strength", rule, b));
        }
        if self.reset != Reset::Zero && self.target == Target::Float {
            let rule = "adaptive thresholds are trained with neurons that reset to zero (--snn-reset zero)";
            return Err(ParamError::new(
                "snn-adapt-ms",
                rule,
                "--snn-reset subtract",
            ));
        }
        Ok(())
    }

    /// Delays' rules: the longest 1 to [`super::delay::MAX_DELAY_STEPS`] time steps (a
    /// delay under one step would only share each spike with the next step).
    fn check_delays(&self) -> Result<(), ParamError> {
        let Some(ms) = self.delay_ms else {
            return Ok(());
        };
        let steps = ms / f64::from(self.dt_ms);
        if !((1.0..=super::delay::MAX_DELAY_STEPS).contains(&steps)) {
            let rule = "the longest synaptic delay must be 1 to 1000 time steps (--snn-dt-ms to 1000 times it): under one step a delay only shares each spike with the next step, and each hidden neuron keeps the input drive of that many steps ahead";
            let got = format!("{ms} ms, {steps} steps of {} ms", self.dt_ms);
            return Err(ParamError::new("snn-delay-ms", rule, got));
        }
        Ok(())
    }

    /// The longest delay in time steps, when the network has delays.
    pub fn delay_steps(&self) -> Option<f64> {
        self.delay_ms.map(|ms| ms / f64::from(self.dt_ms))
    }

    /// The adaptive thresholds a network trained with these parameters has.
    pub fn adaptation(&self) -> Option<Adaptation> {
        self.adapt_ms.map(|tau_ms| Adaptation {
            tau_ms,
            strength: self.adapt_strength,
        })
    }

    /// The steps of a training window, when training on windows.
    pub fn window_steps(&self) -> Option<usize> {
        self.window_ms.map(|w| w / self.dt_ms as usize)
    }

    /// What to say of training windows under five membrane time constants: each window
    /// starts from rest, so the neurons' start-up fills much of it.
    pub fn short_window(&self) -> Option<String> {
        let window = self.window_ms? as f64;
        let floor = 5.0 * self.tau_mem_ms;
        (window < floor).then(|| format!(
            "note: training windows of {window} ms are under five membrane time constants ({floor} ms): each window starts from rest, so much of it is the neurons' start-up rather than the texture; windows of a second or more keep the start-up a small part"
        ))
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

#[cfg(test)]
mod tests {
    use super::SnnParams;

    /// New networks train on standardised inputs; a model file without the key was
    /// trained before the option existed, on the counts as they are, and reads so.
    #[test]
    fn standardised_inputs_are_the_default_but_not_of_files_without_the_key() {
        assert!(SnnParams::default().standardize);
        let old: SnnParams = serde_json::from_str(r#"{"hidden": 64}"#).unwrap();
        assert!(!old.standardize);
        assert_eq!(old.hidden, 64);
        let text = serde_json::to_string(&SnnParams::default()).unwrap();
        assert!(text.contains(r#""standardize":true"#), "{text}");
        assert!(!text.contains("travel") && old.travel.is_off(), "{text}");
        let median = SnnParams {
            travel: super::Travel::Median,
            ..SnnParams::default()
        };
        let text = serde_json::to_string(&median).unwrap();
        assert!(text.contains(r#""travel":"median""#), "{text}");
    }
}
