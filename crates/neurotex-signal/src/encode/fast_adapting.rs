//! The fast-adapting (FA) population: neurons driven by the rectified rate of change of
//! each taxel's signal, beside the slowly adapting (SA) ones.

use neurotex_core::spikes::SpikeTrains;
use serde::{Deserialize, Serialize};

use crate::error::ParamError;

use super::drives::{encode_drives, Drive};
use super::IzhikevichParams;

/// Fast-adapting (FA-I) encoding parameters.
///
/// The model: an FA-I afferent responds to the rate of change of skin indentation, at
/// contact onset and offset and to vibration, not to sustained pressure (Johnson 2001,
/// Curr. Opin. Neurobiol.; Kim, Sripati and Bensmaia 2010, J. Neurophysiol., whose RA
/// model is driven by the derivative of indentation; Saal and Bensmaia 2014, Trends
/// Neurosci.). Here each taxel's FA neuron is the Izhikevich neuron of the SA channel
/// (same firing type) driven by `I_fa(t) = G_fa * |x(t) - x(t - 1 ms)|`: the full-wave
/// rectified rate of change of the conditioned, normalised signal in units per ms. The
/// signal is already low-passed by the conditioning (50 Hz by default), which is the
/// only smoothing. The first step has no previous sample and gets no drive, so a signal
/// that is constant over the selected phase gives no FA spikes at all.
///
/// The default `G_fa = 8000` follows a stated rule, not classification accuracy: FA
/// neurons should fire at a rate comparable to the SA neurons at the paper's `G = 8` on a
/// typical slide. On the simulated paper rig (`neurotex simulate`, seed 0) at 10 mm/s the
/// median SA taxel fires at 12 Hz; the median FA taxel fires at 1.1, 5.1 and 10.0 Hz with
/// `G_fa` = 3000, 5000 and 8000, so 8000. (Equal mean current, `8 * mean x / mean |dx/dt|`
/// = 1800, left most FA neurons silent: the derivative drive is sparse and peaked, and
/// the neuron's threshold is not linear.)
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FaParams {
    /// Gain `G_fa` from rate of change (normalised units per ms) to input current.
    pub gain: f64,
}

impl Default for FaParams {
    /// `G_fa = 8000` (see the type's rule).
    fn default() -> Self {
        FaParams { gain: 8000.0 }
    }
}

impl FaParams {
    /// Checks the rule: a gain in (0, 10000].
    ///
    /// # Errors
    /// The rule broken.
    pub fn check(&self) -> Result<(), ParamError> {
        if !(self.gain.is_finite() && self.gain > 0.0 && self.gain <= 1e4) {
            return Err(ParamError::new(
                "fa-gain",
                "FA gain must be a number in (0, 10000]",
                self.gain,
            ));
        }
        Ok(())
    }
}

/// The rectified rate of change `|x(t) - x(t - 1)|` per 1 ms step of a time-major signal
/// of `cells` values per frame; the first frame is 0.
///
/// # Panics
/// If `samples` is not whole frames (a caller bug).
pub fn rectified_rate(samples: &[f64], cells: usize) -> Vec<f64> {
    assert!(
        cells > 0 && samples.len().is_multiple_of(cells),
        "whole frames"
    );
    let mut out = vec![0.0; samples.len()];
    for ((now, before), o) in samples[cells..]
        .chunks_exact(cells)
        .zip(samples.chunks_exact(cells))
        .zip(out[cells..].chunks_exact_mut(cells))
    {
        for ((&x, &x0), o) in now.iter().zip(before).zip(o) {
            *o = (x - x0).abs();
        }
    }
    out
}

/// Encodes a conditioned `n_steps x cells` signal into FA-I spike trains: `neuron`'s
/// firing type driven by `G_fa |dx/dt|` (see [`FaParams`]); `neuron.gain` is not used.
///
/// # Errors
/// A broken parameter rule.
pub fn encode_fa(
    samples: &[f64],
    rows: usize,
    cols: usize,
    present: &[bool],
    neuron: IzhikevichParams,
    fa: FaParams,
) -> Result<SpikeTrains, ParamError> {
    fa.check()?;
    let mut drive = [Drive::RectifiedRate(samples)];
    let neuron = neuron.with_gain(fa.gain);
    let mut trains = encode_drives(&mut drive, &[fa.gain], rows, cols, present, neuron)?;
    Ok(trains.pop().expect("one bank"))
}

/// The SA trains of a conditioned signal ([`encode`] with `neuron`) and its FA-I trains
/// ([`encode_fa`]), encoded side by side as two banks ([`encode_drives`]).
///
/// # Errors
/// A broken parameter rule.
pub fn encode_sa_fa(
    samples: &[f64],
    rows: usize,
    cols: usize,
    present: &[bool],
    neuron: IzhikevichParams,
    fa: FaParams,
) -> Result<(SpikeTrains, SpikeTrains), ParamError> {
    neuron.check()?;
    fa.check()?;
    let mut drives = [Drive::Signal(samples), Drive::RectifiedRate(samples)];
    let gains = [neuron.gain, fa.gain];
    let [sa, fa]: [SpikeTrains; 2] =
        encode_drives(&mut drives, &gains, rows, cols, present, neuron)?
            .try_into()
            .expect("two banks");
    Ok((sa, fa))
}
