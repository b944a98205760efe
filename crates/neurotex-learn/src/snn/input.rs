//! The network's input: spike trains binned to its time step, one input per taxel and
//! population.

use crate::spikes::SpikeTrains;

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
    /// What one event adds to a step's input (1: a spike; `dt / step` for steps of
    /// travel, so that a step's input is a rate at every speed).
    scale: f64,
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
            scale: 1.0,
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

    /// Steps `start..start + len` as an input of their own: a training window cut from a
    /// long slide.
    ///
    /// # Panics
    /// If the steps run past the window (a caller bug).
    pub fn window(&self, start: usize, len: usize) -> SpikeInput {
        let offsets = &self.offsets[start..=start + len];
        let (first, last) = (offsets[0], offsets[len]);
        SpikeInput {
            inputs: self.inputs,
            offsets: offsets.iter().map(|&o| o - first).collect(),
            events: self.events[first as usize..last as usize].to_vec(),
            scale: self.scale,
        }
    }

    /// The same spikes in steps `per` times as long: step `t` goes to step `⌊t / per⌋`,
    /// and the steps are `⌈steps / per⌉` (the last may be partial). Binned at 1 ms first,
    /// this is [`SpikeInput::from_trains`] at any step, whole or fractional.
    ///
    /// # Panics
    /// If `per` is not positive and finite (a caller bug).
    pub fn rebin(&self, per: f64) -> SpikeInput {
        assert!(per > 0.0 && per.is_finite());
        let steps = ((self.steps() as f64 / per).ceil() as usize).max(1);
        let mut offsets = vec![0u32; steps + 1];
        for t in 0..self.steps() {
            let to = ((t as f64 / per) as usize).min(steps - 1);
            offsets[to + 1] = self.offsets[t + 1];
        }
        let mut events = self.events.clone();
        for t in 0..steps {
            offsets[t + 1] = offsets[t + 1].max(offsets[t]);
            events[offsets[t] as usize..offsets[t + 1] as usize].sort_unstable();
        }
        SpikeInput {
            inputs: self.inputs,
            offsets,
            events,
            scale: self.scale,
        }
    }

    /// The same input with each event adding `scale` to its step's input.
    pub fn scaled(self, scale: f64) -> SpikeInput {
        SpikeInput { scale, ..self }
    }

    /// What one event adds to its step's input: 1 but for steps of travel.
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// Spikes in the window.
    pub fn total(&self) -> usize {
        self.events.len()
    }

    /// The window as a dense `steps x inputs` table of spike counts (times the scale),
    /// row-major (what a network's input node receives, step by step).
    pub fn dense(&self) -> Vec<f32> {
        let mut out = vec![0f32; self.steps() * self.inputs];
        for t in 0..self.steps() {
            for &i in self.at(t) {
                out[t * self.inputs + i as usize] += self.scale as f32;
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A window holds the steps it was cut from, and its dense table is those rows.
    #[test]
    fn a_window_is_its_steps() {
        let events = [(0, 1), (1, 0), (1, 2), (3, 1), (3, 1), (4, 2), (6, 0)];
        let x = SpikeInput::from_events(3, 7, &events);
        let w = x.window(1, 4);
        assert_eq!((w.inputs, w.steps(), w.total()), (3, 4, 5));
        for t in 0..4 {
            assert_eq!(w.at(t), x.at(1 + t));
        }
        assert_eq!(w.dense(), x.dense()[3..15].to_vec());
        assert_eq!(x.window(0, 7), x);
    }

    /// Rebinning 1 ms steps gives the counts binned by hand: with steps 2.5 ms long, ms
    /// 0-2 fall in step 0, 3-4 in step 1, 5-7 in step 2 and 8 in step 3; each step's
    /// inputs in order, as [`SpikeInput::from_trains`] lists them.
    #[test]
    fn rebinning_counts_each_spike_in_the_longer_step_it_falls_in() {
        let events = [(0, 1), (2, 0), (3, 2), (5, 1), (5, 1), (7, 0), (8, 2)];
        let x = SpikeInput::from_events(3, 9, &events);
        let by_hand = [(0, 0), (0, 1), (1, 2), (2, 0), (2, 1), (2, 1), (3, 2)];
        assert_eq!(x.rebin(2.5), SpikeInput::from_events(3, 4, &by_hand));
        assert_eq!(x.rebin(1.0), x);
        let whole = [(0, 0), (0, 0), (0, 1), (0, 1), (0, 1), (0, 2), (0, 2)];
        assert_eq!(x.rebin(100.0), SpikeInput::from_events(3, 1, &whole));
    }
}
