//! One recording's signal statistics: its stamps (rate, jitter, gaps), and each channel's
//! range, resting offset, full-scale share, and whether it is dead, rising like a clock, or
//! a copy of another channel.

use std::collections::HashMap;

use serde::Serialize;

use crate::recording::Recording;

/// An interval this many times the median interval, or longer, is a gap in the stamps.
pub const GAP_FACTOR: f64 = 2.5;

/// Full-scale values of the usual converters: a channel held at one of them is clipped.
const FULL_SCALES: [f64; 5] = [255.0, 1023.0, 4095.0, 16383.0, 65535.0];

/// What a recording's time stamps say.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Stamps {
    /// One over the median interval, Hz.
    pub fs_hz: f64,
    /// The spread of the intervals (5th to 95th percentile) over the median interval.
    pub jitter: f64,
    /// Intervals of at least [`GAP_FACTOR`] median intervals.
    pub gaps: usize,
    /// The longest interval, s.
    pub longest_s: f64,
}

/// One channel of one recording.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Channel {
    /// Smallest sample.
    pub min: f64,
    /// Largest sample.
    pub max: f64,
    /// The smallest sample over the range (`min / (max - min)`), when the channel moves and
    /// rests above zero: how high above zero it rests, in ranges.
    pub resting_ratio: Option<f64>,
    /// Share of samples at a converter's full scale (255, 1023, 4095, 16383, 65535).
    pub full_scale_share: f64,
    /// Every sample the same.
    pub dead: bool,
    /// Never falls and rises at nearly every frame, as a clock or a counter does.
    pub rising: bool,
}

/// One recording's statistics.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SignalStats {
    /// Frames.
    pub frames: usize,
    /// Duration, s.
    pub duration_s: f64,
    /// The stamps, for a recording read with them (at least two frames).
    pub stamps: Option<Stamps>,
    /// Per channel, in the file's order.
    pub channels: Vec<Channel>,
    /// `(original, copy)`: a channel equal to an earlier one at every frame.
    pub copies: Vec<(usize, usize)>,
}

/// The value of channel `c` at each frame (`channel_map` gives the cell of each channel).
pub fn channel_series(rec: &Recording, c: usize) -> impl Iterator<Item = f64> + Clone + '_ {
    let cells = rec.layout.cells().max(1);
    let cell = rec.layout.channel_map[c];
    rec.samples.iter().skip(cell).step_by(cells).copied()
}

/// The statistics of `rec`, in one pass over its frames (each channel's extremes, steps
/// and sums of its values, channels side by side), then a look back only at the
/// channels that need one: those held at a converter's full scale, and those whose sums
/// match another's.
pub fn signal_stats(rec: &Recording) -> SignalStats {
    let n = rec.layout.channel_map.len();
    let cells = rec.layout.cells().max(1);
    let map = &rec.layout.channel_map;
    let mut pass = Pass::new(n);
    if map.iter().copied().eq(0..cells) {
        pass.scan(&rec.samples);
    } else {
        // Channels picked out of their frames a block at a time, so the pass reads them
        // side by side as it does a frame of only channels.
        let mut block = Vec::with_capacity(PICK_FRAMES * n);
        for frames in rec.samples.chunks(PICK_FRAMES * cells) {
            block.clear();
            for row in frames.chunks_exact(cells) {
                block.extend(map.iter().map(|&cell| row[cell]));
            }
            pass.scan(&block);
        }
    }
    let frames = rec.samples.len() / cells;
    let channels: Vec<Channel> = (0..n)
        .map(|c| pass.channel(c, frames, || channel_series(rec, c)))
        .collect();
    SignalStats {
        frames: rec.len(),
        duration_s: rec.duration_s(),
        stamps: rec.times_s.as_deref().and_then(stamps),
        copies: copies(rec, &channels, &pass.lanes),
        channels,
    }
}

/// Frames whose channels are picked out of their cells at a time, when the channels are
/// not the frame's cells in order.
const PICK_FRAMES: usize = 256;

/// Every channel's running statistics over the frames seen so far, one lane per channel.
struct Pass {
    lanes: Vec<Lane>,
}

/// One channel's running statistics.
#[derive(Debug, Clone, Copy)]
struct Lane {
    lo: f64,
    hi: f64,
    prev: f64,
    rises: u64,
    falls: u64,
    /// A Fletcher-style pair of sums of the values' bits: the sum, and the sum of the
    /// running sums (which weighs each value by its place).
    sums: [u64; 2],
}

impl Default for Lane {
    fn default() -> Self {
        Lane {
            lo: f64::INFINITY,
            hi: f64::NEG_INFINITY,
            // Comparisons with the first frame's NaN `prev` are false: no step before it.
            prev: f64::NAN,
            rises: 0,
            falls: 0,
            sums: [0; 2],
        }
    }
}

impl Lane {
    #[inline(always)]
    fn add(&mut self, v: f64) {
        self.lo = self.lo.min(v);
        self.hi = self.hi.max(v);
        self.rises += u64::from(v > self.prev);
        self.falls += u64::from(v < self.prev);
        self.prev = v;
        self.sums[0] = self.sums[0].wrapping_add(v.to_bits());
        self.sums[1] = self.sums[1].wrapping_add(self.sums[0]);
    }
}

/// Lanes a block of the pass keeps in registers.
const BLOCK: usize = 8;

impl Pass {
    fn new(n: usize) -> Self {
        Pass {
            lanes: vec![Lane::default(); n],
        }
    }

    /// Adds `frames`, each one value per lane.
    fn scan(&mut self, frames: &[f64]) {
        let n = self.lanes.len();
        let mut start = 0;
        while start + BLOCK <= n {
            let block: &mut [Lane; BLOCK] = (&mut self.lanes[start..start + BLOCK])
                .try_into()
                .expect("a whole block");
            scan_block(frames, n, start, block);
            start += BLOCK;
        }
        for (c, lane) in self.lanes.iter_mut().enumerate().skip(start) {
            frames.iter().skip(c).step_by(n).for_each(|&v| lane.add(v));
        }
    }

    /// Channel `c` over `frames` frames; `values` gives its samples again when it is held
    /// at a full scale.
    fn channel<I: Iterator<Item = f64>>(
        &self,
        c: usize,
        frames: usize,
        values: impl Fn() -> I,
    ) -> Channel {
        let Lane {
            lo,
            hi,
            rises,
            falls,
            ..
        } = self.lanes[c];
        let full_scale = if FULL_SCALES.contains(&hi) && hi > lo {
            values().filter(|&v| v == hi).count() as f64 / frames.max(1) as f64
        } else {
            0.0
        };
        // As `clock_like`: at least two steps, none falling, at least 99 % rising.
        let steps = frames.saturating_sub(1);
        Channel {
            min: lo,
            max: hi,
            resting_ratio: (hi > lo && lo > 0.0).then(|| lo / (hi - lo)),
            full_scale_share: full_scale,
            dead: frames > 0 && hi == lo,
            rising: steps >= 2 && falls == 0 && rises as f64 >= 0.99 * steps as f64,
        }
    }
}

neurotex_core::simd::widest_or_plain! {
    ["avx512f", "avx2"]
    /// [`BLOCK`] lanes from `start` of `frames` (`n` values a frame) through [`Lane::add`],
    /// side by side, their statistics held in registers over the frames. Each lane is
    /// computed on its own in frame order, so the width changes no result.
    fn scan_block(frames: &[f64], n: usize, start: usize, block: &mut [Lane; BLOCK]) {
        // Each statistic as an array over the lanes, so a step is a few vector operations.
        let mut lo = block.map(|l| l.lo);
        let mut hi = block.map(|l| l.hi);
        let mut prev = block.map(|l| l.prev);
        let mut rises = block.map(|l| l.rises);
        let mut falls = block.map(|l| l.falls);
        let mut sum = block.map(|l| l.sums[0]);
        let mut sum_of_sums = block.map(|l| l.sums[1]);
        for row in frames.chunks_exact(n) {
            let values: &[f64; BLOCK] = row[start..start + BLOCK]
                .try_into()
                .expect("a whole block");
            for l in 0..BLOCK {
                let v = values[l];
                lo[l] = lo[l].min(v);
                hi[l] = hi[l].max(v);
                rises[l] += u64::from(v > prev[l]);
                falls[l] += u64::from(v < prev[l]);
                prev[l] = v;
                sum[l] = sum[l].wrapping_add(v.to_bits());
                sum_of_sums[l] = sum_of_sums[l].wrapping_add(sum[l]);
            }
        }
        for (l, lane) in block.iter_mut().enumerate() {
            *lane = Lane {
                lo: lo[l],
                hi: hi[l],
                prev: prev[l],
                rises: rises[l],
                falls: falls[l],
                sums: [sum[l], sum_of_sums[l]],
            };
        }
    }
}

/// Pairs of channels equal at every frame (dead channels left out: every flat channel
/// equals every other flat one at the same level, which says nothing); only channels of
/// equal sums are compared.
fn copies(rec: &Recording, channels: &[Channel], lanes: &[Lane]) -> Vec<(usize, usize)> {
    let mut seen: HashMap<[u64; 2], Vec<usize>> = HashMap::new();
    let mut out = Vec::new();
    for (c, ch) in channels.iter().enumerate() {
        if ch.dead {
            continue;
        }
        let same = seen.entry(lanes[c].sums).or_default();
        let original = same
            .iter()
            .copied()
            .find(|&o| channel_series(rec, o).eq(channel_series(rec, c)));
        match original {
            Some(o) => out.push((o, c)),
            None => same.push(c),
        }
    }
    out
}

/// The stamps' rate, jitter and gaps; `None` with fewer than two stamps.
pub fn stamps(times_s: &[f64]) -> Option<Stamps> {
    let mut dts: Vec<f64> = times_s.windows(2).map(|w| w[1] - w[0]).collect();
    if dts.is_empty() {
        return None;
    }
    dts.sort_by(f64::total_cmp);
    let at = |q: f64| dts[((dts.len() - 1) as f64 * q).round() as usize];
    let median = at(0.5);
    if median <= 0.0 {
        return None;
    }
    Some(Stamps {
        fs_hz: 1.0 / median,
        jitter: (at(0.95) - at(0.05)) / median,
        gaps: dts.iter().filter(|&&d| d >= GAP_FACTOR * median).count(),
        longest_s: dts[dts.len() - 1],
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::recording::{Layout, Meta};

    fn recording(channels: &[Vec<f64>], times_s: Option<Vec<f64>>) -> Recording {
        let n = channels.len();
        let frames = channels[0].len();
        let samples = (0..frames)
            .flat_map(|t| channels.iter().map(move |c| c[t]))
            .collect();
        Recording {
            fs: 100.0,
            layout: Layout::grid(1, n),
            samples,
            times_s,
            phases: None,
            meta: Meta::default(),
        }
    }

    #[test]
    fn a_hand_made_log_gives_its_statistics() {
        let clock: Vec<f64> = (0..10).map(|t| 1000.0 + 10.0 * t as f64).collect();
        let wave = vec![5.0, 6.0, 7.0, 6.0, 5.0, 6.0, 7.0, 6.0, 5.0, 6.0];
        let clipped = vec![1.0, 255.0, 255.0, 2.0, 255.0, 3.0, 4.0, 5.0, 6.0, 7.0];
        let dead = vec![3.0; 10];
        let times: Vec<f64> = [0, 10, 20, 30, 40, 50, 80, 90, 100, 111]
            .iter()
            .map(|&ms| ms as f64 / 1000.0)
            .collect();
        let rec = recording(&[clock, wave.clone(), clipped, dead, wave], Some(times));
        let s = signal_stats(&rec);
        assert_eq!(s.frames, 10);
        let c = &s.channels;
        assert!(c[0].rising && !c[1].rising && !c[3].rising);
        // the wave rests at 5 over a range of 2
        assert_eq!(c[1].resting_ratio, Some(2.5));
        assert_eq!(c[2].full_scale_share, 0.3);
        assert!(c[3].dead && !c[1].dead);
        assert_eq!(s.copies, vec![(1, 4)]);
        let st = s.stamps.unwrap();
        // intervals: 10 x 7, 30, 11 -> median 10 ms, one gap of 30 ms
        assert!((st.fs_hz - 100.0).abs() < 1e-9);
        assert_eq!(st.gaps, 1);
        assert!((st.longest_s - 0.03).abs() < 1e-12);
    }

    /// Each channel's statistics as the definitions read, one channel at a time.
    fn reference(rec: &Recording) -> (Vec<Channel>, Vec<(usize, usize)>) {
        let n = rec.layout.channel_map.len();
        let channels: Vec<Channel> = (0..n)
            .map(|c| {
                let v: Vec<f64> = channel_series(rec, c).collect();
                let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
                let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                let rises = v.windows(2).filter(|w| w[1] > w[0]).count();
                let falls = v.windows(2).filter(|w| w[1] < w[0]).count();
                let steps = v.len().saturating_sub(1);
                let at_top = v.iter().filter(|&&x| x == hi).count() as f64;
                Channel {
                    min: lo,
                    max: hi,
                    resting_ratio: (hi > lo && lo > 0.0).then(|| lo / (hi - lo)),
                    full_scale_share: match FULL_SCALES.contains(&hi) && hi > lo {
                        true => at_top / v.len().max(1) as f64,
                        false => 0.0,
                    },
                    dead: !v.is_empty() && hi == lo,
                    rising: steps >= 2 && falls == 0 && rises as f64 >= 0.99 * steps as f64,
                }
            })
            .collect();
        let mut copies = Vec::new();
        for c in 0..n {
            let original = (0..c).find(|&o| {
                !channels[o].dead
                    && !copies.iter().any(|&(_, k)| k == o)
                    && channel_series(rec, o).eq(channel_series(rec, c))
            });
            if let (Some(o), false) = (original, channels[c].dead) {
                copies.push((o, c));
            }
        }
        (channels, copies)
    }

    /// The lane-wise pass gives every channel's statistics as [`reference`] does, on
    /// channels in the frame's order and picked out of a masked grid in another order,
    /// with clocks, copies, dead and clipped channels among noise.
    #[test]
    fn the_pass_gives_the_statistics_the_definitions_give() {
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = move |m: u64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state % m
        };
        for case in 0..40 {
            let n = 1 + next(20) as usize;
            let frames = [0, 1, 2, 3, 300, 700][case % 6];
            let mut columns: Vec<Vec<f64>> = Vec::new();
            for c in 0..n {
                let column: Vec<f64> = match (next(6), c) {
                    (0, _) => (0..frames).map(|t| 10.0 + t as f64).collect(),
                    (1, c) if c > 0 => columns[next(c as u64) as usize].clone(),
                    (2, _) => vec![next(9) as f64; frames],
                    (3, _) => (0..frames)
                        .map(|_| [255.0, 3.0, 1.5][next(3) as usize])
                        .collect(),
                    _ => (0..frames)
                        .map(|_| next(5000) as f64 / 7.0 - 100.0)
                        .collect(),
                };
                columns.push(column);
            }
            let mut rec = recording(&columns, None);
            if case % 2 == 1 {
                // the channels placed in reverse on a grid with a masked cell at its start
                let cells = n + 1;
                rec.layout = Layout::grid(1, cells);
                rec.layout.channel_map = (1..cells).rev().collect();
                rec.layout.present[0] = false;
                rec.samples = (0..frames)
                    .flat_map(|t| {
                        let frame = (0..n).rev().map(move |c| (c, t));
                        std::iter::once(0.0).chain(frame.map(|(c, t)| columns[c][t]))
                    })
                    .collect();
            }
            let s = signal_stats(&rec);
            let (channels, copies) = reference(&rec);
            assert_eq!(s.channels, channels, "case {case}");
            assert_eq!(s.copies, copies, "case {case}");
        }
    }

    #[test]
    fn flat_channels_are_not_copies_and_one_stamp_has_no_rate() {
        let rec = recording(&[vec![1.0; 4], vec![1.0; 4]], None);
        assert!(signal_stats(&rec).copies.is_empty());
        assert_eq!(stamps(&[0.0]), None);
    }
}
