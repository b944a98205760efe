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
/// and a hash of its values), then a look back only at the channels that need one: those
/// held at a converter's full scale, and those whose hashes match another's.
pub fn signal_stats(rec: &Recording) -> SignalStats {
    let n = rec.layout.channel_map.len();
    let cells = rec.layout.cells().max(1);
    let map = &rec.layout.channel_map;
    let mut pass = vec![Pass::default(); n];
    for row in rec.samples.chunks_exact(cells) {
        for (p, &cell) in pass.iter_mut().zip(map) {
            p.add(row[cell]);
        }
    }
    let channels: Vec<Channel> = (pass.iter().enumerate())
        .map(|(c, p)| p.channel(|| channel_series(rec, c)))
        .collect();
    SignalStats {
        frames: rec.len(),
        duration_s: rec.duration_s(),
        stamps: rec.times_s.as_deref().and_then(stamps),
        copies: copies(rec, &channels, &pass),
        channels,
    }
}

/// One channel's running statistics over the frames seen so far.
#[derive(Debug, Clone, Copy)]
struct Pass {
    lo: f64,
    hi: f64,
    frames: usize,
    prev: f64,
    rises: usize,
    falls: usize,
    /// FNV-1a over the values' bits.
    hash: u64,
}

impl Default for Pass {
    fn default() -> Self {
        Pass {
            lo: f64::INFINITY,
            hi: f64::NEG_INFINITY,
            frames: 0,
            prev: f64::NAN,
            rises: 0,
            falls: 0,
            hash: 0xcbf2_9ce4_8422_2325,
        }
    }
}

impl Pass {
    fn add(&mut self, v: f64) {
        self.lo = self.lo.min(v);
        self.hi = self.hi.max(v);
        self.frames += 1;
        // Comparisons with the first frame's NaN `prev` are false: no step before it.
        self.rises += usize::from(v > self.prev);
        self.falls += usize::from(v < self.prev);
        self.prev = v;
        self.hash = (self.hash ^ v.to_bits()).wrapping_mul(0x0100_0000_01b3);
    }

    /// The channel; `values` gives its samples again when it is held at a full scale.
    fn channel<I: Iterator<Item = f64>>(&self, values: impl Fn() -> I) -> Channel {
        let (lo, hi, frames) = (self.lo, self.hi, self.frames);
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
            rising: steps >= 2 && self.falls == 0 && self.rises as f64 >= 0.99 * steps as f64,
        }
    }
}

/// Pairs of channels equal at every frame (dead channels left out: every flat channel
/// equals every other flat one at the same level, which says nothing); only channels of
/// equal hashes are compared.
fn copies(rec: &Recording, channels: &[Channel], pass: &[Pass]) -> Vec<(usize, usize)> {
    let mut seen: HashMap<u64, Vec<usize>> = HashMap::new();
    let mut out = Vec::new();
    for (c, ch) in channels.iter().enumerate() {
        if ch.dead {
            continue;
        }
        let same = seen.entry(pass[c].hash).or_default();
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

    #[test]
    fn flat_channels_are_not_copies_and_one_stamp_has_no_rate() {
        let rec = recording(&[vec![1.0; 4], vec![1.0; 4]], None);
        assert!(signal_stats(&rec).copies.is_empty());
        assert_eq!(stamps(&[0.0]), None);
    }
}
