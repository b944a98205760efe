//! Learnable synaptic delays (Hammouamri, Khalfaoui-Hassani & Masquelier 2024): each input
//! synapse `i -> h` carries its spike `d_ih` steps late, `d_ih` a real number trained beside
//! the weights. A spike of input `i` at step `s` adds
//!
//! ```text
//! w_ih (1 - f) to I_h[s + k]    and    w_ih f to I_h[s + k + 1],    k = ⌊d_ih⌋, f = d_ih - k
//! ```
//!
//! (the delay's kernel interpolated linearly between the two steps it falls between, the
//! narrowest of the kernels Hammouamri et al. anneal towards), so that a hidden neuron can
//! line up spikes its inputs sent at different times: a texture's pattern reaching
//! neighbouring taxels one after the other, or one taxel's spikes a period apart. The
//! gradients (`gI[u]` the current's gradient at step `u`, zero past the recording's end):
//!
//! ```text
//! ∂L/∂w_ih += (1 - f) gI_h[s + k] + f gI_h[s + k + 1]
//! ∂L/∂d_ih += w_ih (gI_h[s + k + 1] - gI_h[s + k])
//! ```
//!
//! summed over the input's spikes (each times [`SpikeInput::scale`](super::SpikeInput::scale)).
//! The training pass keeps the drive of every step ahead in rows of its own; the runner,
//! which meets an endless stream, in a ring of [`Delays::reach`] rows.

use super::Network;

/// Longest delay a network may carry, in steps: its drive is kept this many steps ahead.
pub const MAX_DELAY_STEPS: f64 = 1000.0;

/// A network's delays made ready for a pass: each synapse's whole steps, its fraction, and
/// the parts of its weight it adds at those steps.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Delays {
    whole: Vec<u32>,
    /// `whole x hidden + h`: where synapse `(i, h)`'s first part lands, from its step's row.
    offset: Vec<u32>,
    frac: Vec<f64>,
    near: Vec<f64>,
    far: Vec<f64>,
    hidden: usize,
    /// Rows of drive a spike reaches: its own step and up to `⌊max d⌋ + 1` after it.
    pub(crate) reach: usize,
}

impl Delays {
    /// The delays of `net`, when it has them (checked: finite, 0 to [`MAX_DELAY_STEPS`]).
    pub(crate) fn of(net: &Network) -> Option<Delays> {
        if net.delays.is_empty() {
            return None;
        }
        let whole: Vec<u32> = net.delays.iter().map(|d| d.floor() as u32).collect();
        let frac: Vec<f64> = (net.delays.iter().zip(&whole))
            .map(|(d, &k)| d - f64::from(k))
            .collect();
        let near = (net.w_in.iter().zip(&frac))
            .map(|(w, f)| w * (1.0 - f))
            .collect();
        let far = (net.w_in.iter().zip(&frac)).map(|(w, f)| w * f).collect();
        let reach = whole.iter().copied().max().unwrap_or(0) as usize + 2;
        let h_n = net.hidden;
        let offset = (whole.iter().enumerate())
            .map(|(j, &k)| (k as usize * h_n + j % h_n) as u32)
            .collect();
        Some(Delays {
            hidden: net.hidden,
            whole,
            offset,
            frac,
            near,
            far,
            reach,
        })
    }

    /// Adds the drive of the inputs `spiked` at step `t` to `drive`, rows of `hidden`
    /// values for every step from 0, each part times `scale`.
    #[inline(always)]
    pub(crate) fn add(&self, drive: &mut [f64], t: usize, spiked: &[u32], scale: f64) {
        let h_n = self.hidden;
        let drive = &mut drive[t * h_n..];
        for &i in spiked {
            let at = i as usize * h_n..(i as usize + 1) * h_n;
            let (offset, near, far) = (
                &self.offset[at.clone()],
                &self.near[at.clone()],
                &self.far[at],
            );
            for h in 0..h_n {
                let r = offset[h] as usize;
                drive[r] += scale * near[h];
                drive[r + h_n] += scale * far[h];
            }
        }
    }

    /// [`Delays::add`] into a ring of [`Delays::reach`] rows, step `u` in row `u % reach`:
    /// each cell gains the same parts in the same order, so the runner's currents are the
    /// training pass's, bit for bit.
    #[inline(always)]
    pub(crate) fn add_ring(&self, ring: &mut [f64], t: usize, spiked: &[u32], scale: f64) {
        let (h_n, reach) = (self.hidden, self.reach);
        for &i in spiked {
            let at = i as usize * h_n..(i as usize + 1) * h_n;
            let (whole, near, far) = (
                &self.whole[at.clone()],
                &self.near[at.clone()],
                &self.far[at],
            );
            for h in 0..h_n {
                let u = t + whole[h] as usize;
                ring[(u % reach) * h_n + h] += scale * near[h];
                ring[((u + 1) % reach) * h_n + h] += scale * far[h];
            }
        }
    }

    /// The gradients of [`Delays::add`] for the inputs `spiked` at step `t`, from the
    /// current's gradients `g` of every step (rows of `hidden`, zero past the recording's
    /// end), added to `g_w` and `g_d` (input-major, as the weights).
    #[inline(always)]
    pub(crate) fn gradient(
        &self,
        w_in: &[f64],
        g: &[f64],
        (t, spiked, scale): (usize, &[u32], f64),
        g_w: &mut [f64],
        g_d: &mut [f64],
    ) {
        let h_n = self.hidden;
        let g = &g[t * h_n..];
        for &i in spiked {
            let at = i as usize * h_n..(i as usize + 1) * h_n;
            let (offset, frac, w) = (
                &self.offset[at.clone()],
                &self.frac[at.clone()],
                &w_in[at.clone()],
            );
            let (g_w, g_d) = (&mut g_w[at.clone()], &mut g_d[at]);
            for h in 0..h_n {
                let r = offset[h] as usize;
                let (g0, g1) = (g[r], g[r + h_n]);
                g_w[h] += scale * ((1.0 - frac[h]) * g0 + frac[h] * g1);
                g_d[h] += scale * w[h] * (g1 - g0);
            }
        }
    }
}
