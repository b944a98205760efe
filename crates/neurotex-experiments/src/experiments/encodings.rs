//! The encoder's own sensitivity, made part of the headline accuracies. Spiking neurons
//! turn their input into threshold crossings: a neuron near its threshold fires one step
//! earlier or later, or once more or less, when the input moves by a rounding-level
//! amount, and those spikes move a recording's features and sometimes its prediction. So
//! the headline evaluations run on several encodings of every recording (as run, and with
//! independent perturbations far below any sensor's resolution), their accuracies are
//! averaged, and their intervals resample encodings as well as recordings.

use serde::{Deserialize, Serialize};

use super::{Context, Headline, Stop};
use crate::analysis::{seeded_bootstrap_over_encodings, Outcome};
use crate::classify::Interval;
use crate::error::ClassifyError;
use crate::values::BySpeed;
use neurotex_core::spikes::SpikeTrains;

/// One method's accuracy at one speed over the encodings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OverEncodings {
    /// Each encoding's accuracy, the one as run first.
    pub per_encoding: Vec<f64>,
    /// The 95 % interval of the encoding as run, resampling recordings only.
    pub recordings_only: Interval,
    /// The mean over encodings (`estimate`) with its 95 % interval resampling recordings
    /// and encodings.
    pub combined: Interval,
}

impl OverEncodings {
    /// `outcomes[e]`, the method's evaluation on encoding `e` (as run first), summarised.
    ///
    /// # Errors
    /// No outcomes, or outcomes of different recordings.
    pub fn of(outcomes: &[&Outcome], seed: u64) -> crate::Result<Self> {
        let Some(first) = outcomes.first() else {
            let (first, second) = ("the run".to_string(), "its encodings".to_string());
            return Err(ClassifyError::Unpaired { first, second }.into());
        };
        let shares: Vec<Vec<f64>> = outcomes
            .iter()
            .map(|o| o.correct_shares.iter().map(|s| s.1).collect())
            .collect();
        Ok(OverEncodings {
            per_encoding: outcomes.iter().map(|o| o.accuracy).collect(),
            recordings_only: first.accuracy_interval(seed)?,
            combined: seeded_bootstrap_over_encodings(&shares, seed)?
                .or_wilson_at_the_bounds(first.correct_shares.len()),
        })
    }

    /// The mean accuracy over encodings (the one as run, to the bit, with one encoding).
    pub fn mean(&self) -> f64 {
        self.per_encoding.iter().sum::<f64>() / self.per_encoding.len().max(1) as f64
    }

    /// The lowest and highest accuracy of any encoding.
    pub fn range(&self) -> (f64, f64) {
        let lo = self
            .per_encoding
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        let hi = self
            .per_encoding
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max);
        (lo, hi)
    }
}

/// The headline accuracies at one speed over the encodings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EncodingsSpeed {
    /// 3D-GLCM.
    pub glcm3d: OverEncodings,
    /// Single taxel, mean over taxels.
    pub taxel_mean: OverEncodings,
    /// 2D-GLCM.
    pub glcm2d: OverEncodings,
    /// Recordings whose spike trains differ from the ones as run in some encoding.
    pub recordings_changed: usize,
    /// Recordings at this speed.
    pub recordings: usize,
    /// How far the perturbed encodings' spikes stay those of the encoding as run
    /// (absent from results written before it was measured).
    #[serde(default)]
    pub timing: Option<SpikeAgreement>,
}

/// How far a perturbed encoding's spikes are the ones as run, pooled over a speed's
/// recordings, their taxels and the perturbed encodings: each taxel's train as run
/// against the same taxel's train in each perturbed encoding.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SpikeAgreement {
    /// Spikes as run (summed over the perturbed encodings: each is compared once per
    /// encoding).
    pub spikes: usize,
    /// Of those, the ones the perturbed train also has at the same 1 ms step.
    pub same_step: usize,
    /// Of those, the ones with a perturbed spike within [`SpikeAgreement::NEAR_MS`] ms.
    pub near: usize,
    /// The perturbed encodings' spikes, against [`SpikeAgreement::spikes`].
    pub perturbed_spikes: usize,
    /// The median time (s from the start) at which a train first departs from the one as
    /// run (the first spike of either that the other lacks at that place in its order),
    /// over the taxel trains that depart; `None` when none does.
    pub median_first_departure_s: Option<f64>,
}

impl SpikeAgreement {
    /// The window of [`SpikeAgreement::near`], ms either side.
    pub const NEAR_MS: u32 = 10;

    /// Compares each recording's trains as run (`run[i]`) with the same recording's
    /// trains in each perturbed encoding (`perturbed[e][i]`), over the recordings
    /// `recordings`; trains of 1 ms steps.
    pub fn of(run: &[&SpikeTrains], perturbed: &[Vec<&SpikeTrains>], recordings: &[usize]) -> Self {
        let mut a = SpikeAgreement {
            spikes: 0,
            same_step: 0,
            near: 0,
            perturbed_spikes: 0,
            median_first_departure_s: None,
        };
        let mut departures = Vec::new();
        for &i in recordings {
            for draw in perturbed {
                for cell in 0..run[i].cells() {
                    let (x, y) = (run[i].train(cell), draw[i].train(cell));
                    let (same, near) = kept(x, y, Self::NEAR_MS);
                    a.spikes += x.len();
                    a.perturbed_spikes += y.len();
                    a.same_step += same;
                    a.near += near;
                    let first = x.iter().zip(y).position(|(s, t)| s != t);
                    let step = match first {
                        Some(k) => Some(x[k].min(y[k])),
                        None if x.len() != y.len() => x.get(y.len()).or(y.get(x.len())).copied(),
                        None => None,
                    };
                    departures.extend(step);
                }
            }
        }
        if !departures.is_empty() {
            let mid = departures.len() / 2;
            let (_, &mut m, _) = departures.select_nth_unstable(mid);
            a.median_first_departure_s = Some(f64::from(m) / 1000.0);
        }
        a
    }
}

/// Of the spike steps `x` (ascending), how many `y` (ascending) also holds, and how many
/// have a step of `y` within `w` steps either side.
fn kept(x: &[u32], y: &[u32], w: u32) -> (usize, usize) {
    let (mut same, mut near, mut j) = (0, 0, 0);
    for &t in x {
        while j < y.len() && y[j].saturating_add(w) < t {
            j += 1;
        }
        // `y[j]` is the first step at or after `t - w`.
        if let Some(&s) = y.get(j) {
            if s <= t.saturating_add(w) {
                near += 1;
                same += usize::from(y[j..].iter().take_while(|&&s| s <= t).any(|&s| s == t));
            }
        }
    }
    (same, near)
}

/// The encoder's sensitivity at every speed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EncoderSensitivity {
    /// Encodings of each recording, the one as run included.
    pub encodings: usize,
    /// The largest relative change of an input sample in a perturbed encoding.
    pub perturbation: f64,
    /// Per speed.
    pub speeds: BySpeed<EncodingsSpeed>,
    /// The largest spread (highest minus lowest encoding) of any headline accuracy, in
    /// accuracy units (0..1).
    pub largest_spread: f64,
}

/// Each headline method's evaluations at one speed, one per encoding.
pub(crate) struct Methods<'a> {
    pub(crate) taxel: Vec<&'a Outcome>,
    pub(crate) glcm3d: Vec<&'a Outcome>,
    pub(crate) glcm2d: Vec<&'a Outcome>,
}

impl<'a> Methods<'a> {
    /// The evaluations of `encodings` (as [`super::Tables::encodings_at`] gives them).
    pub(crate) fn of(encodings: &[&'a Headline]) -> Self {
        Methods {
            taxel: encodings.iter().map(|h| &h.taxel).collect(),
            glcm3d: encodings.iter().map(|h| &h.glcm3d).collect(),
            glcm2d: encodings.iter().map(|h| &h.glcm2d).collect(),
        }
    }
}

/// The encoder's sensitivity, when the run has more than one encoding (`None` otherwise).
///
/// # Errors
/// Evaluations of different recordings.
pub fn encoder_sensitivity(c: &Context) -> Result<Option<EncoderSensitivity>, Stop> {
    let perturbed = &c.prepared.perturbed;
    if perturbed.is_empty() {
        return Ok(None);
    }
    let seed = c.params.seed;
    let encoded = &c.prepared.encoded;
    let run: Vec<&SpikeTrains> = encoded.iter().map(|e| &e.spikes).collect();
    let draws: Vec<Vec<&SpikeTrains>> = (perturbed.iter())
        .map(|p| p.iter().map(|e| &e.spikes).collect())
        .collect();
    let mut speeds = BySpeed::new();
    let mut largest_spread: f64 = 0.0;
    for &speed in &c.prepared.speeds {
        let m = Methods::of(&c.tables.encodings_at(speed));
        let at: Vec<usize> = (0..encoded.len())
            .filter(|&i| encoded[i].meta.speed() == Some(speed))
            .collect();
        let entry = EncodingsSpeed {
            glcm3d: OverEncodings::of(&m.glcm3d, seed)?,
            taxel_mean: OverEncodings::of(&m.taxel, seed)?,
            glcm2d: OverEncodings::of(&m.glcm2d, seed)?,
            recordings_changed: (at.iter())
                .filter(|&&i| draws.iter().any(|d| d[i] != run[i]))
                .count(),
            recordings: at.len(),
            timing: Some(SpikeAgreement::of(&run, &draws, &at)),
        };
        for a in [&entry.glcm3d, &entry.taxel_mean, &entry.glcm2d] {
            let (lo, hi) = a.range();
            largest_spread = largest_spread.max(hi - lo);
        }
        speeds.insert(speed, entry);
    }
    Ok(Some(EncoderSensitivity {
        encodings: perturbed.len() + 1,
        perturbation: c.params.perturbation,
        speeds,
        largest_spread,
    }))
}

#[cfg(test)]
mod tests {
    use super::super::testing::small_run;
    use super::*;

    #[test]
    fn every_speed_summarised_over_every_encoding() {
        let run = small_run();
        let c = run.context();
        let s = encoder_sensitivity(&c)
            .unwrap()
            .expect("more than one encoding");
        assert_eq!(s.encodings, run.params.encoder_draws);
        assert_eq!(s.speeds.len(), 2);
        let mut largest: f64 = 0.0;
        for (speed, e) in s.speeds.iter() {
            assert_eq!(e.recordings, 24);
            assert!(e.recordings_changed <= e.recordings);
            let t = e.timing.as_ref().expect("measured");
            assert!(t.spikes > 0 && t.same_step <= t.near && t.near <= t.spikes);
            assert_eq!(
                t.median_first_departure_s.is_some(),
                e.recordings_changed > 0
            );
            let g = &e.glcm3d;
            assert_eq!(g.per_encoding.len(), s.encodings);
            assert_eq!(g.per_encoding[0], c.tables.at(speed).glcm3d.accuracy);
            let mean = g.per_encoding.iter().sum::<f64>() / s.encodings as f64;
            assert!((g.combined.estimate - mean).abs() < 1e-12);
            assert!(g.combined.lower <= g.combined.estimate);
            assert!(g.combined.estimate <= g.combined.upper);
            for a in [&e.glcm3d, &e.taxel_mean, &e.glcm2d] {
                largest = largest.max(a.range().1 - a.range().0);
            }
        }
        assert_eq!(s.largest_spread, largest);
    }

    #[test]
    fn spikes_are_kept_at_the_same_step_or_near_by_hand() {
        // 10 stays; 20 moves by 3; 40 moves by 11 (past 10 ms); 90 vanishes; 75 is new.
        let x = [10, 20, 40, 90];
        let y = [10, 23, 51, 75];
        assert_eq!(kept(&x, &y, 10), (1, 2));
        assert_eq!(kept(&x, &y, 11), (1, 3));
        assert_eq!(kept(&x, &y, 0), (1, 1));
        assert_eq!(kept(&[], &y, 10), (0, 0));
        assert_eq!(kept(&x, &[], 10), (0, 0));
        // Two perturbed spikes in one window count the spike as run once.
        assert_eq!(kept(&[5], &[0, 5, 9], 10), (1, 1));
    }

    #[test]
    fn agreement_pools_taxels_encodings_and_recordings() {
        let present = [true, true];
        let trains =
            |a: Vec<u32>, b: Vec<u32>| SpikeTrains::from_lists(&[a, b], 1, 2, &present, 5000);
        // Recording 0 as run; recording 1 is not among those compared.
        let run = [
            trains(vec![100, 200, 300], vec![1500]),
            trains(vec![7], vec![]),
        ];
        let same = trains(vec![100, 200, 300], vec![1500]);
        // Taxel 0 departs at 200 (205 instead), taxel 1 gains a spike at 2500.
        let moved = trains(vec![100, 205, 300], vec![1500, 2500]);
        let other = trains(vec![9], vec![]);
        let run: Vec<&SpikeTrains> = run.iter().collect();
        let perturbed = vec![vec![&same, &other], vec![&moved, &other]];
        let a = SpikeAgreement::of(&run, &perturbed, &[0]);
        assert_eq!(a.spikes, 8);
        assert_eq!(a.perturbed_spikes, 9);
        assert_eq!(a.same_step, 7);
        assert_eq!(a.near, 8);
        // Departures at 200 ms and 2500 ms: the upper of the two middle values.
        assert_eq!(a.median_first_departure_s, Some(2.5));
        let none = SpikeAgreement::of(&run, &[vec![&same, &other]], &[0]);
        assert_eq!((none.same_step, none.median_first_departure_s), (4, None));
    }
}
