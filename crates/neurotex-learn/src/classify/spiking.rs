//! The spiking classifier ([`crate::snn`]) as a [`Learner`] over the recordings' binned
//! spikes ([`SpikeSamples`]): cross-validation and train/test pick its training and test
//! recordings by index, and every recording's input is built once and shared by the folds.
//! A network counting time in travel ([`crate::snn::Travel`]) takes its reference speed
//! from each fit's training recordings, and rebins their inputs (and its test recordings')
//! to steps of that travel.

use std::borrow::Cow;

use rayon::prelude::*;

use super::samples::{Decide, Learner, Samples};
use crate::error::ClassifyError;
use crate::snn::{event_weight, fit_with, softmax, step_ms, Network, SnnParams, SpikeInput};

/// Every recording's spikes binned to `step_ms`, with its sliding speed.
#[derive(Debug, Clone, PartialEq)]
pub struct SpikeSamples {
    /// Each recording's input in steps of `step_ms`.
    pub inputs: Vec<SpikeInput>,
    /// Each recording's sliding speed, mm/s (signed), where known.
    pub speeds: Vec<Option<f64>>,
    /// The steps' length, ms: the networks' `dt_ms` when no fit rebins them (one step,
    /// time in ms or every recording at the same speed), 1 otherwise.
    pub step_ms: u32,
}

impl Samples for SpikeSamples {
    fn count(&self) -> usize {
        self.inputs.len()
    }
}

impl SpikeSamples {
    /// The inputs `rows` in steps of a network of step `dt_ms` counting time in travel at
    /// `reference` (or in ms): borrowed where the steps are already those.
    ///
    /// # Errors
    /// An index past the last recording, or a recording without the speed travel needs.
    fn pick(
        &self,
        rows: &[usize],
        dt_ms: u32,
        reference: Option<f64>,
    ) -> Result<Vec<Cow<'_, SpikeInput>>, ClassifyError> {
        rows.par_iter()
            .map(|&i| {
                let input = self.inputs.get(i).ok_or_else(|| {
                    let message = format!("recording {i} of {} spike inputs", self.inputs.len());
                    ClassifyError::BadFeatures(message)
                })?;
                let ms = step_ms(dt_ms, reference, self.speeds[i])
                    .map_err(ClassifyError::BadFeatures)?;
                let (per, weight) = (ms / f64::from(self.step_ms), event_weight(dt_ms, ms));
                Ok(match per == 1.0 && weight == input.scale() {
                    true => Cow::Borrowed(input),
                    false => Cow::Owned(input.rebin(per).scaled(weight)),
                })
            })
            .collect()
    }
}

/// An unfitted spiking classifier with checked parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SnnClassifier {
    params: SnnParams,
}

impl SnnClassifier {
    /// The classifier with `params`, checked.
    ///
    /// # Errors
    /// The rule `params` break.
    pub fn new(params: SnnParams) -> Result<Self, crate::error::ParamError> {
        Ok(SnnClassifier {
            params: params.check()?,
        })
    }

    /// The checked parameters.
    pub fn params(&self) -> &SnnParams {
        &self.params
    }
}

impl Learner<SpikeSamples> for SnnClassifier {
    type Fitted = SnnModel;

    fn learn(
        &self,
        samples: &SpikeSamples,
        rows: &[usize],
        y: &[usize],
    ) -> Result<SnnModel, ClassifyError> {
        self.learn_ticking(samples, rows, y, &|| ())
    }

    /// Ticks once per epoch run, at most the parameters' `epochs` (a fit on long slides
    /// takes minutes).
    fn learn_ticking(
        &self,
        samples: &SpikeSamples,
        rows: &[usize],
        y: &[usize],
        tick: &(dyn Fn() + Sync),
    ) -> Result<SnnModel, ClassifyError> {
        let speeds = rows
            .iter()
            .map(|&i| samples.speeds.get(i).copied().flatten());
        let reference = self
            .params
            .travel
            .reference(speeds)
            .map_err(|e| ClassifyError::BadFeatures(e.to_string()))?;
        let inputs = samples.pick(rows, self.params.dt_ms, reference)?;
        let refs: Vec<&SpikeInput> = inputs.iter().map(|c| c.as_ref()).collect();
        let classes = y.iter().max().map_or(0, |m| m + 1);
        let (mut network, _) = fit_with(&self.params, &refs, y, classes, tick)?;
        network.travel_mm_s = reference;
        Ok(SnnModel { network })
    }

    fn ticks(&self) -> usize {
        self.params.epochs
    }
}

/// A trained network.
#[derive(Debug, Clone, PartialEq)]
pub struct SnnModel {
    /// The network.
    pub network: Network,
}

impl SnnModel {
    /// The predicted class of each of `inputs` with every class's share (the softmax of
    /// the network's scores).
    pub fn predict_with_shares(&self, inputs: &[&SpikeInput]) -> Vec<(usize, Vec<f64>)> {
        inputs
            .par_iter()
            .map(|input| {
                let shares = softmax(&self.network.scores(input));
                (super::first_max(&shares), shares)
            })
            .collect()
    }
}

impl Decide<SpikeSamples> for SnnModel {
    fn decide(
        &self,
        samples: &SpikeSamples,
        rows: &[usize],
    ) -> Result<Vec<Vec<usize>>, ClassifyError> {
        let net = &self.network;
        let inputs = samples.pick(rows, net.dt_ms, net.travel_mm_s)?;
        let refs: Vec<&SpikeInput> = inputs.iter().map(|c| c.as_ref()).collect();
        let predicted = self.predict_with_shares(&refs).into_iter().map(|p| p.0);
        Ok(vec![predicted.collect()])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::snn::Travel;

    /// `n` recordings at `speed` of `ms` ms each in 1 ms steps, two classes told apart by
    /// which two of four inputs fire more, with the labels.
    fn at_one_ms(n: usize, ms: u32, speed: f64) -> (SpikeSamples, Vec<usize>) {
        let mut next = crate::testing::xorshift(11);
        let mut inputs = Vec::new();
        for k in 0..n {
            let mut events = Vec::new();
            for t in 0..ms {
                for i in 0..4u32 {
                    let odds = if (i < 2) == (k % 2 == 0) { 30 } else { 5 };
                    if next() % 1000 < odds {
                        events.push((t, i));
                    }
                }
            }
            inputs.push(SpikeInput::from_events(4, ms as usize, &events));
        }
        let speeds = vec![Some(speed); n];
        let y = (0..n).map(|k| k % 2).collect();
        let samples = SpikeSamples {
            inputs,
            speeds,
            step_ms: 1,
        };
        (samples, y)
    }

    /// A slide at twice the speed, its spikes at half the times, gives the network the
    /// same steps when it counts time in travel, each of its spikes weighing 2 (its steps
    /// are half as long: the same count is twice the rate), and other steps when it counts
    /// in ms.
    #[test]
    fn in_travel_a_faster_slide_of_the_same_pattern_gives_the_same_steps() {
        let slow = SpikeInput::from_events(1, 40, &[(0, 0), (15, 0), (30, 0)]);
        let fast = SpikeInput::from_events(1, 20, &[(0, 0), (7, 0), (15, 0)]);
        let samples = SpikeSamples {
            inputs: vec![slow, fast],
            speeds: vec![Some(10.0), Some(-20.0)],
            step_ms: 1,
        };
        let travel = samples.pick(&[0, 1], 10, Some(10.0)).unwrap();
        let by_hand = SpikeInput::from_events(1, 4, &[(0, 0), (1, 0), (3, 0)]);
        let twice = by_hand.clone().scaled(2.0);
        assert_eq!((&*travel[0], &*travel[1]), (&by_hand, &twice));
        let ms = samples.pick(&[0, 1], 10, None).unwrap();
        assert_ne!(ms[0], ms[1]);
        let no_speed = SpikeSamples {
            speeds: vec![Some(10.0), None],
            ..samples
        };
        assert!(no_speed.pick(&[1], 10, Some(10.0)).is_err());
    }

    /// At one speed, the median reference is that speed: the network trained in travel
    /// on 1 ms inputs is, bit for bit, the one trained in ms on inputs binned to its step.
    #[test]
    fn at_one_speed_travel_trains_the_network_time_in_ms_trains() {
        let (fine, y) = at_one_ms(12, 300, 7.5);
        let rows: Vec<usize> = (0..12).collect();
        let params = SnnParams {
            hidden: 6,
            epochs: 3,
            travel: Travel::Median,
            ..SnnParams::default()
        };
        let in_travel = SnnClassifier::new(params).unwrap();
        let travelled = in_travel.learn(&fine, &rows, &y).unwrap();
        assert_eq!(travelled.network.travel_mm_s, Some(7.5));
        let binned = SpikeSamples {
            inputs: fine.inputs.iter().map(|x| x.rebin(10.0)).collect(),
            step_ms: 10,
            ..fine.clone()
        };
        let off = SnnParams {
            travel: Travel::Off,
            ..params
        };
        let in_ms = SnnClassifier::new(off)
            .unwrap()
            .learn(&binned, &rows, &y)
            .unwrap();
        assert_eq!(in_ms.network.travel_mm_s, None);
        let weights = |m: &SnnModel| (m.network.w_in.clone(), m.network.w_out.clone());
        assert_eq!(weights(&travelled), weights(&in_ms));
        assert_eq!(
            travelled.decide(&fine, &rows).unwrap(),
            in_ms.decide(&binned, &rows).unwrap()
        );
    }
}
