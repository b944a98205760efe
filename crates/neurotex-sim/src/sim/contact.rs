//! The mechanics of contact: the texture's height under each taxel, spread by the cover, and
//! the pad height at which the contact force equals the commanded force.

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use super::texture::{Surface, Texture};
use super::RigParams;

/// Height profiles along the sliding path, smoothed by the taxel and the cover. The taxels
/// of one column lie on one line parallel to the sliding direction, so each column keeps
/// one profile and each row reads it at its own offset along the line.
pub(super) struct Profiles {
    start_mm: f64,
    per_mm: f64,
    cols: usize,
    /// Profile sample `k` of column `c` at `k * cols + c`: heights from `start_mm` in steps
    /// of `1 / per_mm`, the columns of one sample side by side.
    heights: Vec<f64>,
    /// Per row, its offset along the sliding direction, mm.
    row_offset_mm: Vec<f64>,
}

impl Profiles {
    /// The height under every taxel (row-major) after sliding `s_mm`, interpolated
    /// linearly between profile samples.
    pub(super) fn heights(&self, s_mm: f64, out: &mut [f64]) {
        let cols = self.cols;
        let last = (self.heights.len() / cols - 2) as f64;
        for (offset, out) in self.row_offset_mm.iter().zip(out.chunks_exact_mut(cols)) {
            // One position per row: the taxels of a row share it (every column's profile
            // has the same sampling), so it is computed once, not once per taxel.
            let x = ((s_mm + offset - self.start_mm) * self.per_mm).clamp(0.0, last);
            let k = x as usize;
            let w = x - k as f64;
            let (here, next) = self.heights[k * cols..(k + 2) * cols].split_at(cols);
            for ((o, &a), &b) in out.iter_mut().zip(here).zip(next) {
                *o = a + (b - a) * w;
            }
        }
    }
}

/// The along-track smoothing kernel over `-reach..=reach` profile steps: a box of
/// `half_box` steps either side (the taxel's length) convolved with a Gaussian of `sigma`
/// steps (the cover's spread), normalised to sum to 1.
fn along_track_kernel(half_box: isize, sigma: f64, reach: isize) -> Vec<f64> {
    let k: Vec<f64> = (-reach..=reach)
        .map(|i| {
            (-half_box..=half_box)
                .map(|b| {
                    let d = (i - b) as f64;
                    if sigma > 0.0 {
                        (-0.5 * d * d / (sigma * sigma)).exp()
                    } else if d == 0.0 {
                        1.0
                    } else {
                        0.0
                    }
                })
                .sum()
        })
        .collect();
    let total: f64 = k.iter().sum();
    k.into_iter().map(|v| v / total).collect()
}

pub(super) fn build_profiles(p: &RigParams, texture: Texture, rng: &mut ChaCha8Rng) -> Profiles {
    let texture_seed: u64 = rng.gen();
    let origin = (
        rng.gen::<f64>() * p.patch_range_mm,
        rng.gen::<f64>() * p.patch_range_mm,
    );
    let lateral = (rng.gen::<f64>() * 2.0 - 1.0) * p.lateral_offset_mm;
    let theta = (rng.gen::<f64>() * 2.0 - 1.0) * p.rotation_deg.to_radians();
    let (u, n) = ((theta.cos(), theta.sin()), (-theta.sin(), theta.cos()));
    // Along-track smoothing: the taxel's length as a box, convolved with the cover's Gaussian.
    let step = p.profile_step_mm;
    let half_box = (p.taxel_mm / 2.0 / step).round() as isize;
    let sigma = p.cover_spread_mm / step;
    let reach = half_box + (3.0 * sigma).ceil() as isize;
    let kernel = along_track_kernel(half_box, sigma, reach);
    let pitch = p.pitch_mm();
    let row_offset_mm: Vec<f64> = (0..p.rows)
        .map(|r| ((p.rows - 1) as f64 / 2.0 - r as f64) * pitch)
        .collect();
    let lowest = row_offset_mm.iter().copied().fold(f64::INFINITY, f64::min);
    let highest = row_offset_mm
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max);
    // The line covers every row's path from 1 mm before the start to 1 mm past the end.
    let start_mm = lowest - 1.0;
    let samples = ((highest - lowest + p.slide_mm + 2.0) / step).ceil() as usize + 2;
    let raw_len = samples + 2 * reach as usize;
    // Lateral spreading: three lines across the taxel, weighted as a coarse Gaussian.
    let lines = [
        (-p.taxel_mm / 3.0, 0.25),
        (0.0, 0.5),
        (p.taxel_mm / 3.0, 0.25),
    ];
    let mut raw = vec![0.0; raw_len];
    // One surface per line, so each keeps what its neighbouring points share.
    let mut surfaces = lines.map(|_| Surface::new(texture, texture_seed));
    let columns: Vec<Vec<f64>> = (0..p.cols)
        .map(|c| {
            let across0 = (c as f64 - (p.cols - 1) as f64 / 2.0) * pitch + lateral;
            raw.fill(0.0);
            for (k, h) in raw.iter_mut().enumerate() {
                let along = start_mm + (k as f64 - reach as f64) * step;
                for (&(offset, weight), surface) in lines.iter().zip(&mut surfaces) {
                    let across = across0 + offset;
                    let x = origin.0 + along * u.0 + across * n.0;
                    let y = origin.1 + along * u.1 + across * n.1;
                    *h += weight * surface.height(x, y);
                }
            }
            (0..samples)
                .map(|k| kernel.iter().zip(&raw[k..]).map(|(w, h)| w * h).sum())
                .collect()
        })
        .collect();
    let heights = (0..samples)
        .flat_map(|k| columns.iter().map(move |column| column[k]))
        .collect();
    Profiles {
        start_mm,
        per_mm: 1.0 / step,
        cols: p.cols,
        heights,
        row_offset_mm,
    }
}

/// Pad height `z` such that `sum max(0, h_i - z) = depth_sum`, by the sorted-prefix solution
/// of the Winkler contact (exact; taxels below `z` carry no load).
pub(super) fn solve_contact(h: &[f64], depth_sum: f64, sorted: &mut Vec<f64>) -> f64 {
    // Usually every taxel touches: then z is the plain mean solution, no sorting needed.
    // (Four running sums and a check without early exit: this runs every millisecond of
    // the slide, and a single chain of additions was most of its time.)
    let mut sums = [0.0; 4];
    let mut quads = h.chunks_exact(4);
    for quad in &mut quads {
        for (s, &hi) in sums.iter_mut().zip(quad) {
            *s += hi;
        }
    }
    let total = (sums[0] + sums[1]) + (sums[2] + sums[3]) + quads.remainder().iter().sum::<f64>();
    let all = (total - depth_sum) * (1.0 / h.len() as f64);
    if h.iter().fold(true, |touch, &hi| touch & (hi >= all)) {
        return all;
    }
    sorted.clear();
    sorted.extend_from_slice(h);
    sorted.sort_unstable_by(|a, b| b.total_cmp(a));
    let mut prefix = 0.0;
    for m in 1..=sorted.len() {
        prefix += sorted[m - 1];
        let z = (prefix - depth_sum) / m as f64;
        if m == sorted.len() || z >= sorted[m] {
            return z;
        }
    }
    f64::INFINITY
}
