//! Which taxels carry information: a taxel that never fires, or fires at the encoder's
//! ceiling, in most recordings scores its class-majority share whatever the texture, and
//! would drag a mean over taxels toward chance for reasons of the sensor, not the method.
//! `reproduce` reports these for every run and `evaluate --method taxel` beside its mean.

use serde::{Deserialize, Serialize};

use crate::analysis::TaxelAccuracy;
use crate::encode::{encode, IzhikevichParams};
use crate::error::Result;
use crate::pipeline::Encoded;
use crate::values::{Cell, Grid};

/// A taxel-recording pair fires at the ceiling when its rate reaches this share of the
/// rate of a neuron driven by the largest input the normalisation allows.
pub const SATURATION_SHARE: f64 = 0.9;

/// Whether a taxel firing at `rate_hz` is at the ceiling `ceiling_hz` ([`SATURATION_SHARE`]
/// of it). A taxel that never fires is silent, never at the ceiling, even where the gain
/// is too low for the largest input to fire at all (a ceiling of 0 Hz).
pub fn at_ceiling(rate_hz: f64, ceiling_hz: f64) -> bool {
    rate_hz > 0.0 && rate_hz >= SATURATION_SHARE * ceiling_hz
}

/// One taxel's responses over the recordings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TaxelResponse {
    /// The taxel, `r{row}c{col}`.
    pub taxel: String,
    /// Share of recordings in which it never fired.
    pub silent_share: f64,
    /// Share of recordings in which it fired at the ceiling.
    pub saturated_share: f64,
}

impl TaxelResponse {
    /// Silent in most recordings.
    pub fn silent(&self) -> bool {
        self.silent_share > 0.5
    }

    /// At the ceiling in most recordings.
    pub fn saturated(&self) -> bool {
        self.saturated_share > 0.5
    }

    /// Neither silent nor saturated in most recordings.
    pub fn responsive(&self) -> bool {
        !self.silent() && !self.saturated()
    }
}

/// Every taxel's responses, and the ceiling they are judged against.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TaxelDiagnostics {
    /// The rate of a neuron driven by the normalised input 1 (the recording's maximum) for
    /// a whole second, at the pipeline's gain, Hz.
    pub ceiling_hz: f64,
    /// Per taxel, in grid order.
    pub taxels: Vec<TaxelResponse>,
}

impl TaxelDiagnostics {
    /// The taxels silent in most recordings.
    pub fn silent(&self) -> Vec<&str> {
        let silent = self.taxels.iter().filter(|t| t.silent());
        silent.map(|t| t.taxel.as_str()).collect()
    }

    /// The taxels at the ceiling in most recordings.
    pub fn saturated(&self) -> Vec<&str> {
        let saturated = self.taxels.iter().filter(|t| t.saturated());
        saturated.map(|t| t.taxel.as_str()).collect()
    }

    /// Whether most taxels are at the ceiling in most recordings (what [`advice`] speaks
    /// of first).
    ///
    /// [`advice`]: TaxelDiagnostics::advice
    pub fn mostly_at_ceiling(&self) -> bool {
        2 * self.saturated().len() > self.taxels.len()
    }

    /// What to change when most taxels do not respond: silent ones want a higher gain,
    /// ones at the ceiling most often a signal riding on a resting offset (normalised by
    /// its maximum, it stays near 1 throughout) or a lower gain. `None` when most respond.
    pub fn advice(&self) -> Option<String> {
        let n = self.taxels.len();
        let (silent, saturated) = (self.silent().len(), self.saturated().len());
        if self.mostly_at_ceiling() {
            Some(format!(
                "{saturated} of {n} taxels fire at the encoder's ceiling in most recordings, so they carry little of the texture: a signal riding on a large resting offset stays near its maximum throughout; remove the offset (--baseline min, or baseline in layout.toml), or lower the gain"
            ))
        } else if 2 * silent > n {
            Some(format!(
                "{silent} of {n} taxels never fire in most recordings, so they carry nothing of the texture: --gain auto chooses a gain from the data (a median rate over the training recordings)"
            ))
        } else {
            None
        }
    }

    /// [`TaxelDiagnostics::advice`] for a pipeline with `params`: under causal
    /// conditioning with resting values fixed at training, a resting level that differs
    /// between recordings leaves taxels silent or at the ceiling whatever the gain, so that
    /// is said first.
    pub fn advice_for(&self, params: &crate::pipeline::PipelineParams) -> Option<String> {
        let advice = self.advice()?;
        let p = &params.preprocess;
        Some(match p.causal.is_some() && p.drift_window_ms.is_none() {
            true => format!("{advice}. Under --causal each taxel's resting value is fixed at training: if the sensor's resting level differs between recordings (`neurotex inspect` says so: drifting-rest), --drift-window-s tracks it, which no gain replaces"),
            false => advice,
        })
    }

    /// Whether taxel `name` (`r{row}c{col}`) responds; unknown names do not.
    pub fn responsive(&self, name: &str) -> bool {
        self.taxels
            .iter()
            .any(|t| t.taxel == name && t.responsive())
    }

    /// The mean of the accuracies `per` over the responsive taxels; `None` when none
    /// responds.
    pub fn responsive_mean(&self, per: &[TaxelAccuracy]) -> Option<f64> {
        let responsive: Vec<f64> = per
            .iter()
            .filter(|t| {
                self.responsive(
                    &Cell {
                        row: t.row,
                        col: t.col,
                    }
                    .to_string(),
                )
            })
            .map(|t| t.accuracy)
            .collect();
        let n = responsive.len() as f64;
        (n > 0.0).then(|| responsive.iter().sum::<f64>() / n)
    }
}

/// The diagnostics of `encoded` (recordings on `grid`, encoded by neurons of `encoder`).
///
/// # Errors
/// Encoder parameters that break a rule (checked already when they come from a pipeline).
pub fn taxel_diagnostics(
    encoded: &[Encoded],
    grid: &Grid,
    encoder: IzhikevichParams,
) -> Result<TaxelDiagnostics> {
    // A sensor's address events are not the encoder's: their ceiling is the spike trains'
    // own, one spike per millisecond.
    let ceiling_hz = match encoded.iter().any(|e| e.from_events) {
        true => 1000.0,
        false => ceiling_rate(encoder)?,
    };
    let n = encoded.len().max(1) as f64;
    let taxels = grid
        .taxels()
        .map(|cell| {
            let (mut silent, mut saturated) = (0usize, 0usize);
            for e in encoded {
                let spikes = e.spikes.train(cell).len();
                let rate = spikes as f64 * 1000.0 / e.spikes.n_steps.max(1) as f64;
                silent += usize::from(spikes == 0);
                saturated += usize::from(at_ceiling(rate, ceiling_hz));
            }
            TaxelResponse {
                taxel: grid.cell(cell).to_string(),
                silent_share: silent as f64 / n,
                saturated_share: saturated as f64 / n,
            }
        })
        .collect();
    Ok(TaxelDiagnostics { ceiling_hz, taxels })
}

/// Spikes per second of one neuron held at input 1 for two seconds, counted over the second
/// (after the onset transient).
pub fn ceiling_rate(encoder: IzhikevichParams) -> Result<f64> {
    let input = vec![1.0; 2000];
    let trains = encode(&input, 1, 1, &[true], encoder)?;
    Ok(trains.train(0).iter().filter(|&&t| t >= 1000).count() as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_silent_taxel_is_never_at_the_ceiling() {
        // A gain too low for the largest input to fire: the ceiling is 0 Hz, and a taxel
        // that never fires is silent, not at it.
        assert!(!at_ceiling(0.0, 0.0));
        assert!(!at_ceiling(0.0, 16.0));
        assert!(at_ceiling(15.0, 16.0) && !at_ceiling(14.0, 16.0));
        assert!(at_ceiling(0.5, 0.0));
    }

    fn response(taxel: &str, silent_share: f64, saturated_share: f64) -> TaxelResponse {
        TaxelResponse {
            taxel: taxel.into(),
            silent_share,
            saturated_share,
        }
    }

    #[test]
    fn most_recordings_decide_and_the_responsive_mean_leaves_the_others_out() {
        let d = TaxelDiagnostics {
            ceiling_hz: 50.0,
            taxels: vec![
                response("r0c0", 0.75, 0.0),
                response("r0c1", 0.0, 0.5),
                response("r1c0", 0.0, 0.6),
            ],
        };
        assert_eq!(d.silent(), ["r0c0"]);
        assert_eq!(d.saturated(), ["r1c0"]);
        assert!(!d.responsive("r0c0") && d.responsive("r0c1") && !d.responsive("r9c9"));
        let acc = |row, col, accuracy| TaxelAccuracy { row, col, accuracy };
        let per = [acc(0, 0, 0.2), acc(0, 1, 0.9), acc(1, 0, 0.4)];
        assert_eq!(d.responsive_mean(&per), Some(0.9));
        assert_eq!(d.responsive_mean(&per[..1]), None);
    }

    #[test]
    fn most_taxels_silent_or_at_the_ceiling_say_what_to_change() {
        let taxel = |name: &str, silent_share: f64, saturated_share: f64| TaxelResponse {
            taxel: name.into(),
            silent_share,
            saturated_share,
        };
        let of = |taxels: Vec<TaxelResponse>| TaxelDiagnostics {
            ceiling_hz: 16.0,
            taxels,
        };
        let saturated = of(vec![
            taxel("r0c0", 0.0, 1.0),
            taxel("r0c1", 0.0, 0.9),
            taxel("r1c0", 0.0, 0.6),
            taxel("r1c1", 0.0, 0.0),
        ]);
        let advice = saturated.advice().expect("3 of 4 at the ceiling");
        assert!(
            advice.starts_with("3 of 4 taxels fire at the encoder's ceiling"),
            "{advice}"
        );
        assert!(advice.contains("--baseline min"), "{advice}");
        let silent = of(vec![
            taxel("r0c0", 1.0, 0.0),
            taxel("r0c1", 0.8, 0.0),
            taxel("r1c0", 0.0, 0.0),
        ]);
        let advice = silent.advice().expect("2 of 3 silent");
        assert!(advice.starts_with("2 of 3 taxels never fire") && advice.contains("--gain auto"));
        // half silent is not most
        let half = of(vec![taxel("r0c0", 1.0, 0.0), taxel("r0c1", 0.0, 0.0)]);
        assert_eq!(half.advice(), None);
    }
}
