//! The encoder's sensitivity in one evaluation: every recording encoded again with its
//! conditioned input perturbed at the level of rounding, the same classifier evaluated on
//! each encoding under the same split, and the accuracy given over the encodings with an
//! interval that resamples encodings as well as recordings (as `reproduce` gives its
//! headline accuracies).

use rayon::prelude::*;

use super::{EncoderDraws, Evaluation, Spikes};
use crate::analysis::{evaluator, Columns, Outcome, Split};
use crate::classify::ClassifierChoice;
use crate::error::OptionsError;
use crate::experiments::{perturbed_encodings, Draws, OverEncodings, MAX_ENCODER_DRAWS};
use crate::pipeline::{Encoded, Pipeline};
use crate::progress::Progress;
use crate::recording::Dataset;
use crate::samples::MethodChoice;
use crate::values::Grid;
use crate::Result;

use super::super::OnProgress;

/// The size of the perturbations: each conditioned sample times `1 + u * 1e-12`, `u`
/// uniform in [-1, 1), far below any sensor's resolution and above a double's rounding
/// (`reproduce`'s default).
pub const PERTURBATION: f64 = 1e-12;

/// Checks a count of encodings of `dataset`'s recordings before any is read: at least 1
/// (the one as run alone), at most [`MAX_ENCODER_DRAWS`], and 1 for address events.
///
/// # Errors
/// A count out of that range, or above 1 on address events (they skip the encoder).
pub fn check(encodings: usize, dataset: &Dataset) -> Result<()> {
    if !(1..=MAX_ENCODER_DRAWS).contains(&encodings) {
        let reason = format!(
            "1 (the input as run only) to {MAX_ENCODER_DRAWS} encodings of each recording, got {encodings}"
        );
        let option = "--encoder-draws";
        return Err(OptionsError::Invalid { option, reason }.into());
    }
    if encodings > 1 && dataset.is_events() {
        let why = format!(
            "{} holds address events, which skip the encoder: --encoder-draws perturbs the sampled signal the encoder receives",
            dataset.root.display()
        );
        return Err(OptionsError::Conflict(why).into());
    }
    Ok(())
}

/// What an evaluation ran, to run it again on other encodings of its recordings.
pub(super) struct Run<'a> {
    pub dataset: &'a Dataset,
    pub pipeline: &'a Pipeline,
    pub grid: &'a Grid,
    pub indices: &'a [usize],
    pub chosen: (MethodChoice, Columns),
    pub classifier: ClassifierChoice,
    pub split: &'a Split,
    pub tau_ms: f64,
}

/// `as_run`, the evaluation of `run` on its recordings as encoded, with its accuracy over
/// `encodings` encodings of them when that is above 1 ([`over_encodings`], perturbed from
/// streams of `seed`).
///
/// # Errors
/// As [`over_encodings`].
pub(super) fn with_draws(
    run: &Run<'_>,
    as_run: Evaluation,
    encodings: usize,
    seed: u64,
    on: OnProgress,
) -> Result<Evaluation> {
    if encodings == 1 {
        return Ok(as_run);
    }
    let draws = Draws {
        encodings,
        seed,
        size: PERTURBATION,
    };
    let over = over_encodings(run, &as_run, draws, on)?;
    Ok(Evaluation {
        draws: Some(over),
        ..as_run
    })
}

/// `run` evaluated on `draws.encodings - 1` perturbed encodings of its recordings beside
/// `as_run`, the evaluation of the encoding as run, and summarised over all of them. The
/// perturbations' streams are seeded by `draws.seed` and each recording's index in the
/// dataset, so an evaluation of the same recordings perturbs them alike.
///
/// # Errors
/// A recording that cannot be read, or an evaluation that fails.
pub(super) fn over_encodings(
    run: &Run<'_>,
    as_run: &Evaluation,
    draws: Draws,
    on: OnProgress,
) -> Result<EncoderDraws> {
    let per_draw = perturbed(run.dataset, run.pipeline, run.indices, draws, on)?;
    on(Progress::Stage(
        "evaluating the perturbed encodings",
        per_draw.len(),
    ));
    let mut outcomes: Vec<Outcome> = Vec::with_capacity(per_draw.len());
    for encoded in &per_draw {
        let spikes = Spikes {
            encoded,
            grid: run.grid,
            pipeline: run.pipeline,
        };
        let (method, columns) = run.chosen;
        let samples = spikes.samples(method, columns, &run.classifier, run.tau_ms)?;
        let all: Vec<usize> = (0..encoded.len()).collect();
        let silent = |_: Progress| {};
        outcomes.push(evaluator(run.classifier, samples)?(
            &all, run.split, &silent,
        )?);
        on(Progress::Tick);
    }
    let all: Vec<&Outcome> = std::iter::once(&as_run.outcome).chain(&outcomes).collect();
    let over = OverEncodings::of(&all, draws.seed)?;
    Ok(EncoderDraws {
        accuracies: over.per_encoding,
        combined: over.combined,
        perturbation: draws.size,
    })
}

/// The recordings `indices` of `dataset` encoded by `pipeline` `draws.encodings - 1` times
/// each, with its conditioned input perturbed (seeded by `draws.seed` and the recording's
/// index in the dataset): `[draw][recording]`, the recordings in `indices`' order.
///
/// # Errors
/// A recording that cannot be read or encoded.
pub(in crate::workflows) fn perturbed(
    dataset: &Dataset,
    pipeline: &Pipeline,
    indices: &[usize],
    draws: Draws,
    on: OnProgress,
) -> Result<Vec<Vec<Encoded>>> {
    on(Progress::Stage(
        "encoding the perturbed inputs",
        indices.len(),
    ));
    let baseline = dataset.layout.baseline.unwrap_or_default();
    let per_recording: Vec<Vec<Encoded>> = indices
        .par_iter()
        .map(|&i| {
            crate::progress::stop_point();
            let rec = dataset.load(i)?;
            let cond = pipeline.condition(&rec, baseline)?;
            let trains = perturbed_encodings(pipeline, &rec, &cond, draws, i)?;
            on(Progress::Tick);
            Ok(trains
                .into_iter()
                .map(|t| Encoded::of(&rec, &cond, t))
                .collect())
        })
        .collect::<Result<_>>()?;
    let mut per_draw: Vec<Vec<Encoded>> = (1..draws.encodings).map(|_| Vec::new()).collect();
    for encodings in per_recording {
        for (draw, encoded) in per_draw.iter_mut().zip(encodings) {
            draw.push(encoded);
        }
    }
    Ok(per_draw)
}
