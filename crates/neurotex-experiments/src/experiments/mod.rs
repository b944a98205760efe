//! The paper's analyses E0-E8 (docs/analyses.md), one file and one function each, from
//! prepared recordings, their feature tables and validated parameters to a result struct.
//!
//! [`prepare`] makes one pass over the recordings (simulated or a dataset folder),
//! [`Tables::build`] extracts the feature tables and the headline evaluations once, and
//! [`run_all`] walks [`ANALYSES`], timing each and collecting skips. The paper's claims are
//! judged here ([`claims`]); the report only renders.

mod claims;
mod comparison;
mod diagnostics;
mod e0_psth;
mod e1_accuracy;
mod e2_confusion;
mod e3_perturbation;
mod e4_temporal;
mod e5_causal;
mod e5_time;
mod e6_speed_invariance;
mod e7_gain;
mod e8_neighbours;
mod e9_compare;
mod encodings;
mod keystream;
mod params;
mod perturb;
mod prepare;
mod provenance;
mod seeds;
mod skip;
mod source;
mod tables;
#[cfg(test)]
mod testing;

use std::collections::BTreeMap;
use std::time::Instant;

use serde::{Deserialize, Serialize};

pub use claims::{claims, Claim, Verdict};
pub use comparison::{compare, compare_encodings, compare_shares, Comparison};
pub use diagnostics::{taxel_diagnostics, TaxelDiagnostics, TaxelResponse, SATURATION_SHARE};
pub use e0_psth::{e0_psth, E0Example, E0};
pub use e1_accuracy::{e1_accuracy, E1Speed};
pub use e2_confusion::{e2_confusion, E2};
pub use e3_perturbation::{e3_perturbation, E3};
pub use e4_temporal::{e4_temporal, E4Speed};
pub use e5_causal::{e5_causal, E5CausalSpeed, E5cFraction, TimeToDecision};
pub use e5_time::{e5_time_to_recognition, E5Speed};
pub use e6_speed_invariance::{e6_speed_invariance, E6Speed};
pub use e7_gain::{e7_gain_sweep, E7};
pub use e8_neighbours::{e8_neighbours, E8Speed};
pub use e9_compare::{e9_compare, Baselines, Spiking, E9};
pub use encodings::{
    encoder_sensitivity, EncoderSensitivity, EncodingsSpeed, OverEncodings, SpikeAgreement,
};
pub use params::{
    Draws, ReproduceParams, ValidReproduceParams, DEFAULT_ENCODER_DRAWS, MAX_ENCODER_DRAWS,
    MAX_REPEATS,
};
pub use perturb::{perturbed_encodings, perturbed_input};
pub use prepare::{prepare, CausalPrepared, IsiSweep, Prepared, WITHIN_SPEED};
pub use provenance::{build, now_utc, slide_times, Provenance};
pub use seeds::{across_seeds, run_seeds, AcrossSeeds, ClaimAcrossSeeds, SeedAccuracy};
pub use skip::{Skip, Stop};
pub use source::Source;
pub use tables::{EncodingTables, Headline, Tables};

/// One encoding: what results files written before the encodings were counted were over.
fn one() -> usize {
    1
}

use crate::calibrate::GainCalibration;
use crate::error::Result;
use crate::values::{BySpeed, Speed};

pub use crate::progress::Progress;

/// What every analysis reads: the prepared recordings, their tables and the parameters.
#[derive(Clone, Copy)]
pub struct Context<'a> {
    /// The encoded recordings.
    pub prepared: &'a Prepared,
    /// Feature tables and headline evaluations.
    pub tables: &'a Tables,
    /// The run's parameters.
    pub params: &'a ValidReproduceParams,
}

/// All results, as written to `results.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Results {
    /// Speeds found, ascending.
    pub speeds: Vec<Speed>,
    /// Labels in order.
    pub labels: Vec<String>,
    /// Recordings used.
    pub recordings: usize,
    /// Recordings resampled to 1 kHz.
    pub resampled: usize,
    /// Recordings with no positive signal.
    pub flat: usize,
    /// Taxels silent or at the encoder's ceiling in most recordings.
    pub taxels: TaxelDiagnostics,
    /// E0.
    pub e0: Option<E0>,
    /// E1 by speed.
    pub e1: BySpeed<E1Speed>,
    /// E2.
    pub e2: Option<E2>,
    /// E3.
    pub e3: Option<E3>,
    /// E4 by speed.
    pub e4: BySpeed<E4Speed>,
    /// E5 by speed.
    pub e5: BySpeed<E5Speed>,
    /// E5c (beyond the paper) by speed: the causal pipeline's accuracy against time into
    /// the slide, its time to decision and its cost against E1's zero-phase 3D-GLCM.
    #[serde(default, skip_serializing_if = "BySpeed::is_empty")]
    pub e5c: BySpeed<E5CausalSpeed>,
    /// E6 by held-out speed.
    pub e6: BySpeed<E6Speed>,
    /// E7.
    pub e7: Option<E7>,
    /// E8 by speed.
    pub e8: BySpeed<E8Speed>,
    /// E9: the best of `neurotex compare`'s standard candidates beside the paper's method.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub e9: Option<E9>,
    /// The headline accuracies of every encoding, with and without the encoder's
    /// variability in their intervals; `None` with one encoding.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub encoder_sensitivity: Option<EncoderSensitivity>,
    /// How `--gain auto` chose the gain (on the first dataset's recordings, labels unused);
    /// `None` for a gain given as a number.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gain_calibration: Option<GainCalibration>,
    /// The headline accuracies and claims over several simulated datasets (`--seeds`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub across_seeds: Option<AcrossSeeds>,
    /// The code, parameters, data and date of the run (left out of golden comparisons,
    /// whose date and commit change).
    pub provenance: Option<Provenance>,
    /// The headline 3D-GLCM evaluations' out-of-fold predictions, one per recording and CV
    /// repeat at each speed (`reproduce --predictions`); not part of `results.json`.
    #[serde(skip)]
    pub predictions: Vec<HeadlinePrediction>,
    /// Analyses skipped, with the reason.
    pub skipped: BTreeMap<String, String>,
    /// Wall-clock seconds per analysis.
    pub timing_s: BTreeMap<String, f64>,
}

impl Results {
    fn empty(prepared: &Prepared) -> Self {
        let encoded = &prepared.encoded;
        Results {
            speeds: prepared.speeds.clone(),
            labels: prepared.labels.clone(),
            recordings: encoded.len(),
            resampled: encoded.iter().filter(|e| e.resampled).count(),
            flat: encoded.iter().filter(|e| e.flat).count(),
            taxels: prepared.taxels.clone(),
            e0: None,
            e1: BySpeed::new(),
            e2: None,
            e3: None,
            e4: BySpeed::new(),
            e5: BySpeed::new(),
            e5c: BySpeed::new(),
            e6: BySpeed::new(),
            e7: None,
            e8: BySpeed::new(),
            e9: None,
            encoder_sensitivity: None,
            across_seeds: None,
            gain_calibration: None,
            provenance: Some(prepared.provenance.clone()),
            predictions: Vec::new(),
            skipped: BTreeMap::new(),
            timing_s: BTreeMap::new(),
        }
    }

    fn skip(&mut self, skip: &Skip) {
        self.skipped.insert(skip.key(), skip.to_string());
    }
}

/// One out-of-fold prediction of a headline evaluation.
#[derive(Debug, Clone, PartialEq)]
pub struct HeadlinePrediction {
    /// The speed evaluated at.
    pub speed: Speed,
    /// The method (`3D-GLCM`).
    pub method: &'static str,
    /// The recording's file, as in the manifest.
    pub file: String,
    /// Its true label.
    pub label: String,
    /// The predicted label.
    pub predicted: String,
    /// The fold it was tested in.
    pub fold: Option<usize>,
    /// The CV repeat.
    pub repeat: usize,
}

/// The 3D-GLCM headline predictions at every speed, in speed order.
fn headline_predictions(tables: &Tables) -> Vec<HeadlinePrediction> {
    let mut out = Vec::new();
    for (speed, headline) in tables.headline.iter() {
        let outcome = &headline.glcm3d;
        for p in outcome.predictions.iter().flatten() {
            let meta = &tables.glcm3d.metas[p.row];
            out.push(HeadlinePrediction {
                speed,
                method: "3D-GLCM",
                file: meta.file.clone(),
                label: meta.label.clone(),
                predicted: outcome.labels[p.predicted].clone(),
                fold: p.fold,
                repeat: p.repeat,
            });
        }
    }
    out
}

/// One analysis: its id (the key of its timing and skip) and how its result is stored.
pub struct Analysis {
    /// `e0` .. `e8`.
    pub id: &'static str,
    /// What it asks, in a few words, for progress and logs.
    pub asks: &'static str,
    /// Whether it rests on the cross-validation within each speed (the headline
    /// evaluations); when that cannot run, the analysis is skipped with the reason.
    pub within_speed: bool,
    /// Runs the analysis and stores its result.
    pub run: fn(&Context, &mut Results) -> Result<(), Stop>,
}

/// The analyses in the order they run (E0 last: it shows examples, and the paper's own
/// order puts the accuracies first). E9 is not among them: it runs beside them
/// ([`run_all`]).
pub const ANALYSES: [Analysis; 11] = [
    Analysis {
        id: "e1",
        asks: "accuracy at each speed",
        within_speed: true,
        run: |c, r| {
            r.e1 = e1_accuracy(c)?;
            Ok(())
        },
    },
    Analysis {
        id: "e2",
        asks: "which classes are confused",
        within_speed: true,
        run: |c, r| {
            r.e2 = Some(e2_confusion(c)?);
            Ok(())
        },
    },
    Analysis {
        id: "e3",
        asks: "spatial perturbation: taxels moved",
        within_speed: true,
        run: |c, r| {
            if let Some(skip) = e3_perturbation::counts_beyond_the_grid(c) {
                r.skip(&skip);
            }
            r.e3 = Some(e3_perturbation(c)?);
            Ok(())
        },
    },
    Analysis {
        id: "e4",
        asks: "temporal information: 2D against 3D",
        within_speed: true,
        run: |c, r| {
            r.e4 = e4_temporal(c)?;
            Ok(())
        },
    },
    Analysis {
        id: "e5",
        asks: "time to recognition (offline)",
        within_speed: true,
        run: |c, r| {
            r.e5 = e5_time_to_recognition(c)?;
            Ok(())
        },
    },
    Analysis {
        id: "e5c",
        asks: "time to recognition (causal, online)",
        within_speed: true,
        run: |c, r| {
            let (e5c, skipped) = e5_causal(c, &r.e5)?;
            skipped.iter().for_each(|s| r.skip(s));
            r.e5c = e5c;
            Ok(())
        },
    },
    Analysis {
        id: "e6",
        asks: "speed invariance: a speed held out",
        within_speed: false,
        run: |c, r| {
            r.e6 = e6_speed_invariance(c)?;
            Ok(())
        },
    },
    Analysis {
        id: "e7",
        asks: "the encoder's gain and intervals between spikes",
        within_speed: false,
        run: |c, r| {
            if c.params.e7 {
                r.e7 = Some(e7_gain_sweep(c)?);
            }
            Ok(())
        },
    },
    Analysis {
        id: "e8",
        asks: "the number of neighbours",
        within_speed: true,
        run: |c, r| {
            let (e8, skipped) = e8_neighbours(c)?;
            skipped.iter().for_each(|s| r.skip(s));
            r.e8 = e8;
            Ok(())
        },
    },
    Analysis {
        id: "encoder sensitivity",
        asks: "the encoder's sensitivity to rounding",
        within_speed: true,
        run: |c, r| {
            r.encoder_sensitivity = encoder_sensitivity(c)?;
            Ok(())
        },
    },
    Analysis {
        id: "e0",
        asks: "example spike trains and volumes",
        within_speed: false,
        run: |c, r| {
            r.e0 = Some(e0_psth(c)?);
            Ok(())
        },
    },
];

/// Builds the feature tables and runs every analysis of [`ANALYSES`] on prepared
/// recordings, and E9 beside them; an analysis the data cannot support is skipped with its
/// reason.
///
/// E9 reads nothing but the prepared recordings and the parameters, and it is the longest
/// analysis by far, while the others leave a core idle at times (three speeds on two
/// cores, one resampling stream per interval): it runs beside them from the start. The
/// results are the same as one after another; E9's time in `timing_s` is its own wall
/// clock, shared with the others. When both fail, the error is the one that came first in
/// the order E1, ..., E8, E9, the encoder's sensitivity, E0.
///
/// # Errors
/// A classification that cannot run (a class smaller than the fold count, for example).
pub fn run_all(
    prepared: &Prepared,
    params: &ValidReproduceParams,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<Results> {
    let mut results = Results::empty(prepared);
    results.timing_s.insert("prepare".into(), prepared.seconds);
    if let Some(causal) = &prepared.causal {
        // Part of `prepare`: the causal conditioning fixed on every recording, loaded again.
        let key = "prepare: e5c calibration";
        results.timing_s.insert(key.into(), causal.seconds);
    }
    progress(Progress::Stage("analyses", ANALYSES.len() + 2));
    let e9 = || {
        let clock = Instant::now();
        let asks = "the standard candidates compared";
        let e9 = match (&prepared.within_speed, params.e9) {
            (_, false) => Ok(None),
            (Some(reason), true) => Err(Stop::Skipped(Skip::Design {
                analysis: "e9",
                reason: reason.clone(),
            })),
            (None, true) => e9_compare(prepared, params, progress)
                .map(Some)
                .map_err(|stop| match stop.design_skipped("e9") {
                    Stop::Failed(e) => Stop::Failed(e.in_analysis(format!("E9 ({asks})"))),
                    skipped => skipped,
                }),
        };
        match &e9 {
            Err(Stop::Skipped(skip)) => progress(Progress::Skipped("e9", asks, &skip.to_string())),
            _ => progress(Progress::Done("e9", asks)),
        }
        (e9, clock.elapsed().as_secs_f64())
    };
    let (ordered, (e9, e9_seconds)) =
        rayon::join(|| run_ordered(prepared, params, progress, &mut results), e9);
    let e9 = match e9 {
        Ok(e9) => {
            results.timing_s.insert("e9".into(), e9_seconds);
            e9
        }
        Err(Stop::Skipped(skip)) => {
            results.skip(&skip);
            None
        }
        Err(Stop::Failed(error)) => match ordered {
            Err((before_e9, first)) if before_e9 => return Err(first),
            _ => return Err(error),
        },
    };
    ordered.map_err(|(_, error)| error)?;
    results.e9 = e9;
    Ok(results)
}

/// The tables and [`ANALYSES`] in order, into `results`; on a failure, whether it came
/// before E9's place (after E8) and the error.
fn run_ordered(
    prepared: &Prepared,
    params: &ValidReproduceParams,
    progress: &(dyn Fn(Progress) + Sync),
    results: &mut Results,
) -> std::result::Result<(), (bool, crate::Error)> {
    let clock = Instant::now();
    let tables = Tables::build(prepared, params).map_err(|e| (true, e))?;
    results.predictions = headline_predictions(&tables);
    results
        .timing_s
        .insert("tables".into(), clock.elapsed().as_secs_f64());
    progress(Progress::Done(
        "tables",
        "feature tables and headline evaluations",
    ));
    let context = Context {
        prepared,
        tables: &tables,
        params,
    };
    let mut before_e9 = true;
    for analysis in &ANALYSES {
        let clock = Instant::now();
        let ran = match (&tables.within_speed, analysis.within_speed) {
            (Some(reason), true) => Err(Stop::Skipped(Skip::Design {
                analysis: analysis.id,
                reason: reason.clone(),
            })),
            _ => (analysis.run)(&context, results),
        };
        match ran.map_err(|stop| stop.design_skipped(analysis.id)) {
            Ok(()) => {
                progress(Progress::Done(analysis.id, analysis.asks));
                let seconds = clock.elapsed().as_secs_f64();
                results.timing_s.insert(analysis.id.into(), seconds);
            }
            // A skipped analysis has no time of its own to report.
            Err(Stop::Skipped(skip)) => {
                progress(Progress::Skipped(
                    analysis.id,
                    analysis.asks,
                    &skip.to_string(),
                ));
                results.skip(&skip);
            }
            Err(Stop::Failed(error)) => {
                let what = format!("{} ({})", analysis.id.to_uppercase(), analysis.asks);
                return Err((before_e9, error.in_analysis(what)));
            }
        }
        before_e9 &= analysis.id != "e8";
    }
    Ok(())
}
