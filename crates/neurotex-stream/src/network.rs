//! A spiking network fed by a stream's spikes as the encoder makes them, 1 ms at a time:
//! the spikes of `dt` ms gather into one time step of the network, which then runs that
//! step. The network's scores are read over a window of its last steps
//! ([`crate::snn::Windowed`]), as [`crate::causal::spiking_episode_decisions`] reads them
//! offline.

use crate::snn::{Network, Windowed};

/// The network's state in a stream's episode and the spikes of its current time step.
#[derive(Debug, Clone)]
pub(crate) struct NetworkFeed {
    run: Windowed,
    /// The network's time step, ms.
    dt: usize,
    /// The network input of each cell of the first population (`u32::MAX` where the cell
    /// holds no taxel); population `p`'s is `p * taxels` further on.
    cell_input: Vec<u32>,
    taxels: u32,
    /// The inputs that spiked in the current time step so far.
    pending: Vec<u32>,
    /// 1 ms steps gathered into the current time step.
    gathered: usize,
}

impl NetworkFeed {
    /// The network at rest, for cells where `present` holds a taxel, its scores read over
    /// `window` of its time steps.
    pub(crate) fn new(net: &Network, present: &[bool], window: usize) -> Self {
        let mut taxels = 0u32;
        let cell_input = present
            .iter()
            .map(|&p| match p {
                true => {
                    taxels += 1;
                    taxels - 1
                }
                false => u32::MAX,
            })
            .collect();
        NetworkFeed {
            run: Windowed::new(net, window),
            dt: net.dt_ms as usize,
            cell_input,
            taxels,
            pending: Vec::new(),
            gathered: 0,
        }
    }

    /// Takes the spikes of `population` in the cells from `start` on (`raster[i]` spikes in
    /// cell `start + i`) in the current 1 ms step.
    pub(crate) fn add(&mut self, population: usize, start: usize, raster: &[u8]) {
        let offset = population as u32 * self.taxels;
        for (i, &n) in raster.iter().enumerate().filter(|(_, &n)| n > 0) {
            let input = self.cell_input[start + i];
            if input != u32::MAX {
                let input = offset + input;
                self.pending.extend(std::iter::repeat_n(input, n as usize));
            }
        }
    }

    /// Ends the current 1 ms step; after `dt` of them, the network runs its time step.
    pub(crate) fn end_ms(&mut self, net: &Network) {
        self.gathered += 1;
        if self.gathered == self.dt {
            self.run_step(net);
        }
    }

    /// Runs a time step begun and not completed (the episode's end), as a whole recording's
    /// last partial step is run offline.
    pub(crate) fn flush(&mut self, net: &Network) {
        if self.gathered > 0 {
            self.run_step(net);
        }
    }

    /// The class scores over the window.
    pub(crate) fn scores(&self, net: &Network) -> Vec<f64> {
        self.run.scores(net)
    }

    /// The network's step with the gathered spikes, in ascending input order as offline.
    fn run_step(&mut self, net: &Network) {
        self.pending.sort_unstable();
        self.run.step(net, &self.pending);
        self.pending.clear();
        self.gathered = 0;
    }
}
