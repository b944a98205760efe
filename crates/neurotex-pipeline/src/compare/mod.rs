//! Which encoding, feature method and classifier suit a dataset best: every
//! candidate is evaluated on the same splits of the same recordings, ranked with a 95 %
//! interval, and compared with the paper's method (3D-GLCM + KNN) by a paired test.
//!
//! The splits depend only on the recordings' labels (and groups) and the seed, never on
//! the features, so every candidate is tested on exactly the same folds and a per-recording
//! difference between two candidates is a paired one. Intervals are percentile bootstraps
//! over units (recordings, or groups of `--group-by`) stratified by condition, so that the
//! interval is of the mean over conditions the accuracy is; the comparison with the paper's
//! method is the paired sign-flip test of the per-unit differences
//! ([`sign_flip_p`]).
//!
//! Picking the best of many candidates on the same data is itself a choice fitted to that
//! data: the winner's accuracy is biased upwards (the "winner's curse"; Cawley and Talbot
//! 2010, JMLR 11). [`CompareParams::nested`] adds the honest estimate of the whole
//! procedure: for each outer split the candidates are ranked inside its training recordings
//! only (by cross-validation, or under a hold-out protocol by holding out each of their
//! conditions in turn, the outer protocol's question), and the chosen one is scored on its
//! test recordings.

pub mod candidates;
mod nested;
mod parts;
pub mod signal;
mod units;

use std::sync::Arc;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::analysis::{Outcome, Split};
use crate::classify::metrics::{chance_level, AgainstChance};
use crate::classify::ValidCv;
use crate::error::{ClassifyError, Result};
use crate::progress::Progress;
use crate::recording::{Meta, Selection};
use nested::{check_nested, fewer_folds, nested};
use parts::{parts, score_all};
use units::Units;

pub use crate::analysis::EvaluateFn;

/// The version of what nested selection computes, raised whenever its rules change, so that
/// results kept under an older one are computed anew (2: under a hold-out protocol the inner
/// ranking holds out each condition of the outer training set; 3: under cross-validation
/// it holds out each other outer fold).
pub const NESTED_VERSION: u32 = 3;

/// One encoding x feature method x classifier, with its features computed.
#[derive(Clone)]
pub struct Candidate {
    /// The encoding's name (`sa`, `fa`, `sa+fa`).
    pub encoding: String,
    /// The feature method's name.
    pub method: String,
    /// The classifier's name.
    pub classifier: String,
    /// Every compared recording, in the same order for every candidate.
    pub metas: Arc<Vec<Meta>>,
    /// The classifier applied to the method's samples of some recordings under a split.
    pub evaluate: Arc<EvaluateFn>,
    /// Seconds spent making the samples (encoding shared among the methods of one
    /// encoding is split evenly among them).
    pub prepare_s: f64,
}

impl Candidate {
    /// `encoding / method / classifier`.
    pub fn name(&self) -> String {
        format!("{} / {} / {}", self.encoding, self.method, self.classifier)
    }

    /// Evaluates the candidate on all its recordings under `split`.
    ///
    /// # Errors
    /// As the candidate's classifier.
    pub fn evaluate_all(&self, split: &Split) -> Result<Outcome> {
        let all: Vec<usize> = (0..self.metas.len()).collect();
        (self.evaluate)(&all, split, &crate::progress::silent)
    }

    /// Whether this is the paper's method: the SA encoding, 3D-GLCM and KNN.
    pub fn is_paper(&self) -> bool {
        (
            self.encoding.as_str(),
            self.method.as_str(),
            self.classifier.as_str(),
        ) == ("sa", "glcm3d", "knn")
    }

    /// Whether `other` is this spiking network's own inputs reduced to their counts: the
    /// same encoding's spike rates with logistic regression (`rates / linear`), against
    /// which a paired test says what the spikes' timing adds.
    pub fn counts_of(&self, other: &Candidate) -> bool {
        (self.method.as_str(), self.classifier.as_str()) == ("spikes", "snn")
            && (other.method.as_str(), other.classifier.as_str()) == ("rates", "linear")
            && other.encoding == self.encoding
    }
}

/// How recordings are split.
#[derive(Debug, Clone, PartialEq)]
pub enum Protocol {
    /// Cross-validation over all recordings pooled.
    Pooled,
    /// Cross-validation within each value of a manifest column (each speed, say); the
    /// accuracy is the mean over values.
    Per(String),
    /// Each value of a manifest column held out in turn: trained on the other values,
    /// tested on it; the accuracy is the mean over held-out values.
    HoldOut(String),
    /// Trained on one selection, tested on another.
    Where {
        /// The training recordings.
        train: Selection,
        /// The test recordings.
        test: Selection,
    },
}

impl std::fmt::Display for Protocol {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Protocol::Pooled => write!(f, "cross-validation over all recordings pooled"),
            Protocol::Per(c) => write!(f, "cross-validation within each `{c}`, mean over them"),
            Protocol::HoldOut(c) => write!(f, "each `{c}` held out in turn, mean over them"),
            Protocol::Where { train, test } => write!(
                f,
                "train on `{}` in [{}], test on `{}` in [{}]",
                train.column,
                train.values.join(", "),
                test.column,
                test.values.join(", ")
            ),
        }
    }
}

/// How to compare.
#[derive(Debug, Clone, PartialEq)]
pub struct CompareParams {
    /// The splits.
    pub protocol: Protocol,
    /// Folds, seed and repeats of every cross-validation.
    pub cv: ValidCv,
    /// A manifest column whose groups no fold splits, and the unit of intervals and tests.
    pub group_by: Option<String>,
    /// Resamples of the bootstrap and the sign-flip test.
    pub resamples: usize,
    /// Also estimate the accuracy of choosing the best candidate inside each training set.
    pub nested: bool,
    /// Folds of nested selection's inner cross-validation on folds of its own (at least 2;
    /// fewer where a class of an outer training set has fewer recordings). `None`: the inner
    /// ranking holds out each other outer fold of its condition in turn (`cv.folds - 1`
    /// inner folds, each fit shared by the two outer splits that hold it); with fewer than
    /// 4 folds, or where a class would be missing from an inner fit, it cross-validates on
    /// `cv.folds` folds of its own.
    pub inner_folds: Option<usize>,
}

/// A candidate's accuracy at one condition.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ConditionAccuracy {
    /// The condition's value (a speed, a session).
    pub condition: String,
    /// Accuracy, 0..1.
    pub accuracy: f64,
}

/// One candidate's result.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Ranked {
    /// Encoding name.
    pub encoding: String,
    /// Feature method name.
    pub method: String,
    /// Classifier name.
    pub classifier: String,
    /// Accuracy, 0..1: the mean over conditions of the protocol.
    pub accuracy: f64,
    /// 95 % percentile-bootstrap interval of the accuracy over units (the Wilson score
    /// interval over the units where every one was right, or every one wrong).
    pub ci: [f64; 2],
    /// Two-sided p-value of the paired sign-flip test against the paper's method (`None`
    /// for the paper's method itself, or when it is not among the candidates).
    pub p_vs_paper: Option<f64>,
    /// Accuracy minus the paper's method's (both means over conditions).
    pub difference_vs_paper: Option<f64>,
    /// For the spiking network (`spikes / snn`), its accuracy minus that of its own inputs'
    /// spike rates with logistic regression (`rates / linear`, the same encoding), when that
    /// is a candidate: what the spikes' timing, with the network's nonlinearity, adds to
    /// their counts.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub difference_vs_rates: Option<f64>,
    /// The two-sided p-value of the paired sign-flip test of that difference.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub p_vs_rates: Option<f64>,
    /// Accuracy per condition (empty for pooled cross-validation).
    pub per_condition: Vec<ConditionAccuracy>,
    /// Seconds to make the features and evaluate (wall clock, summed over the parts of the
    /// protocol; candidates and their parts are evaluated side by side, so each one's time
    /// includes its share of the others' load).
    pub seconds: f64,
    /// Whether this is the paper's method.
    pub paper: bool,
    /// The accuracy over several encodings of the recordings (the one as run and copies of
    /// its input perturbed at the level of rounding), when the comparison made them and
    /// the candidate passes through the encoder.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub over_encodings: Option<AcrossEncodings>,
}

/// A candidate's accuracy over several encodings of the same recordings: the one as run,
/// whose accuracy the ranking shows, and copies of the encoder's input perturbed at the
/// level of rounding. Spiking neurons turn such changes into moved spikes, which can move
/// an accuracy by points; the interval holds that as well as the recordings drawn.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AcrossEncodings {
    /// The accuracy under each encoding, the one as run first.
    pub accuracies: Vec<f64>,
    /// Their mean.
    pub mean: f64,
    /// The 95 % percentile-bootstrap interval where one encoding's accuracy may land: each
    /// resample draws one encoding and resamples the units (within each condition) as the
    /// ranking's interval does.
    pub ci: [f64; 2],
    /// The relative size of the perturbations (each conditioned sample times `1 + u x
    /// perturbation`, `u` uniform in [-1, 1)).
    pub perturbation: f64,
}

impl AcrossEncodings {
    /// The lowest and highest accuracy of any encoding.
    pub fn range(&self) -> (f64, f64) {
        let values = self.accuracies.iter().copied();
        values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), a| {
            (lo.min(a), hi.max(a))
        })
    }
}

/// Choosing the best candidate inside each training set, scored on the test set.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Nested {
    /// Accuracy of the selection procedure, 0..1 (mean over conditions).
    pub accuracy: f64,
    /// Its 95 % interval.
    pub ci: [f64; 2],
    /// How often each candidate was chosen, most often first: `(name, times)`.
    pub chosen: Vec<(String, usize)>,
    /// Outer splits.
    pub outer_splits: usize,
    /// How each outer training set ranked the candidates (empty in results written before
    /// it was recorded).
    #[serde(default)]
    pub inner: String,
}

/// The comparison of every candidate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Comparison {
    /// The protocol, as text.
    pub protocol: String,
    /// The design behind it, as text: folds, repeats and seed of the cross-validations,
    /// the resamples of intervals and tests, nested selection's inner folds (empty in
    /// results written before it was recorded).
    #[serde(default)]
    pub design: String,
    /// What intervals and tests resample: `recordings` or `groups of COLUMN`.
    pub units: String,
    /// Units compared.
    pub n_units: usize,
    /// Recordings compared.
    pub n_recordings: usize,
    /// Classes.
    pub classes: usize,
    /// Chance accuracy, 1 / classes.
    pub chance: f64,
    /// Share of the largest class among the evaluated recordings.
    pub majority: f64,
    /// Every candidate, best first.
    pub results: Vec<Ranked>,
    /// The best candidate (the first of `results`).
    pub best: Ranked,
    /// The selection procedure's own estimate, when asked for.
    pub nested: Option<Nested>,
    /// What the ranking does not say.
    pub caveat: String,
    /// Options the design could not honour as given (fewer folds than asked), and results
    /// not above chance, each as said on standard error when the comparison ran; empty
    /// when nothing was said.
    #[serde(default)]
    pub notes: Vec<String>,
    /// Where the ranking comes from, one `name: value` line each: neurotex's build, the
    /// command, the data and the stages' settings as they ran (the gain `--gain auto`
    /// chose among them). Empty where the caller recorded none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub provenance: Vec<String>,
}

/// The caveat every comparison without nested selection carries.
pub const CAVEAT: &str = "the best of several candidates chosen on the same recordings \
    scores higher than it will on new recordings of the same kind; the nested estimate \
    (the best chosen inside each training set and scored on its test set, computed when \
    nested selection is asked for) is what choosing the best this way and training it on \
    all recordings can be expected to score: the number to quote. Each p value tests one \
    candidate against the paper's method alone, uncorrected for the many candidates tested";

/// The caveat of a comparison with nested selection.
pub const CAVEAT_NESTED: &str = "the best of several candidates chosen on the same \
    recordings scores higher than it will on new recordings of the same kind; the nested \
    estimate (the best chosen inside each training set and scored on its test set) is what \
    choosing the best this way and training it on all recordings can be expected to score: \
    the number to quote. Each p value tests one candidate against the paper's method alone, \
    uncorrected for the many candidates tested";

/// One candidate's scores under the protocol.
struct Scored {
    accuracy: f64,
    per_condition: Vec<ConditionAccuracy>,
    /// Per evaluated table row, its share of right predictions.
    shares: Vec<(usize, f64)>,
    seconds: f64,
}

/// Evaluates every candidate under `params` and ranks them.
///
/// # Errors
/// No candidates, tables of different recordings, or an evaluation that fails (a class
/// smaller than the folds, a protocol column the manifest lacks).
pub fn compare(candidates: &[Candidate], params: &CompareParams) -> Result<Comparison> {
    compare_with_progress(candidates, params, &crate::progress::silent)
}

/// [`compare`], saying its progress: a step per candidate and part of the protocol scored
/// (each condition's cross-validation, each held-out value, or the one split of a pooled
/// or train/test protocol), then with nested selection a step per candidate
/// cross-validated inside each outer split.
///
/// # Errors
/// As [`compare`].
pub fn compare_with_progress(
    candidates: &[Candidate],
    params: &CompareParams,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<Comparison> {
    compare_keeping(candidates, params, progress, None)
}

/// Where the finished pieces of one comparison are kept, so that the same comparison run
/// again after it stopped part way takes them instead of computing them anew: a
/// candidate's score on one part of the protocol, and its accuracy inside one outer split
/// of nested selection. Every evaluation is deterministic, so a kept piece is what it
/// would be computed to (its seconds aside). A keeper is for one comparison: the same
/// candidates, recordings and parameters; keys are unique within it.
pub trait Keep: Sync {
    /// The piece kept under `key` (JSON), if there is one.
    fn get(&self, key: &str) -> Option<String>;
    /// Keeps the piece `json` under `key`.
    ///
    /// # Errors
    /// It cannot be kept (a full disk): the comparison stops rather than losing work
    /// silently.
    fn put(&self, key: &str, json: &str) -> Result<()>;
}

/// A kept piece under `key` read back, or `make`'s piece, kept under `key`.
fn kept_or<T: Serialize + serde::de::DeserializeOwned>(
    keep: Option<&dyn Keep>,
    key: &str,
    make: impl FnOnce() -> Result<T>,
) -> Result<T> {
    let Some(keep) = keep else {
        return make();
    };
    if let Some(piece) = keep.get(key).and_then(|j| serde_json::from_str(&j).ok()) {
        return Ok(piece);
    }
    let piece = make()?;
    let json = serde_json::to_string(&piece).map_err(|e| {
        ClassifyError::BadFeatures(format!("a comparison's piece {key} as JSON: {e}"))
    })?;
    keep.put(key, &json)?;
    Ok(piece)
}

/// [`compare_with_progress`], taking the pieces `keep` holds and keeping the others there.
///
/// # Errors
/// As [`compare`], or a piece that cannot be kept.
pub fn compare_keeping(
    candidates: &[Candidate],
    params: &CompareParams,
    progress: &(dyn Fn(Progress) + Sync),
    keep: Option<&dyn Keep>,
) -> Result<Comparison> {
    let none = Perturbed {
        candidates: &[],
        size: 0.0,
    };
    compare_over_encodings(candidates, none, params, progress, keep)
}

/// The candidates of further encodings of the same recordings: `candidates[e]` those of
/// encoding `e + 1`, made alike from the encoder's input perturbed by `size`.
#[derive(Clone, Copy)]
pub struct Perturbed<'a> {
    /// Per further encoding, its candidates (those that pass through the encoder).
    pub candidates: &'a [Vec<Candidate>],
    /// The perturbations' relative size.
    pub size: f64,
}

/// [`compare_keeping`], each candidate that `perturbed` holds under every further encoding
/// (by name) also scored there, under the same parts of the protocol, and given its
/// accuracy over the encodings ([`Ranked::over_encodings`]). The ranking, its tests and
/// nested selection are those of the encoding as run.
///
/// # Errors
/// As [`compare_keeping`].
pub fn compare_over_encodings(
    candidates: &[Candidate],
    perturbed: Perturbed<'_>,
    params: &CompareParams,
    progress: &(dyn Fn(Progress) + Sync),
    keep: Option<&dyn Keep>,
) -> Result<Comparison> {
    let metas = shared_recordings(candidates)?;
    // Candidates are scored side by side, each part of the protocol (a condition, a
    // held-out value) on its own (each evaluation is deterministic, so the order of work
    // changes nothing but its clock): one candidate's folds are too few and too unequal
    // to keep every core busy, and a candidate's parts are its longest pieces of work.
    // Nested selection's outer splits, checked before any candidate is scored.
    let outer = match params.nested {
        true => Some(check_nested(metas, params)?),
        false => None,
    };
    let notes = fewer_folds(metas, params, outer.as_deref());
    for note in &notes {
        progress(Progress::Advice(note));
    }
    let parts = parts(metas, params)?;
    progress(Progress::Stage(
        "candidates",
        candidates.len() * parts.len(),
    ));
    let scored = score_all(candidates, &parts, params, progress, keep)?;
    let units = Units::new(metas, &scored[0].shares, params)?;
    let over = over_encodings(
        candidates,
        &scored,
        perturbed,
        (&parts, &units),
        params,
        (progress, keep),
    )?;
    let results = ranking(candidates, &scored, over, &units, params)?;
    let nested = match outer {
        Some(splits) => Some(nested(
            candidates,
            &splits,
            params,
            &units,
            (progress, keep),
        )?),
        None => None,
    };
    let (classes, majority) = class_shares(metas, &scored[0].shares);
    let chance = 1.0 / classes.max(1) as f64;
    let mut notes = notes;
    notes.extend(
        nested
            .as_ref()
            .and_then(|n| nested_note(n, (classes, majority), params, progress)),
    );
    Ok(Comparison {
        protocol: params.protocol.to_string(),
        design: design(params),
        units: units_of(params),
        n_units: units.n_units(),
        n_recordings: scored[0].shares.len(),
        classes,
        chance,
        majority,
        best: results[0].clone(),
        results,
        caveat: match nested {
            Some(_) => CAVEAT_NESTED.into(),
            None => CAVEAT.into(),
        },
        nested,
        notes,
        provenance: Vec::new(),
    })
}

/// The candidates ranked by their scores `scored`, best first, each with its accuracy over
/// the encodings (`over`), its interval and its paired tests.
///
/// # Errors
/// Two candidates a paired test needs were not scored on the same rows.
fn ranking(
    candidates: &[Candidate],
    scored: &[Scored],
    over: Vec<Option<AcrossEncodings>>,
    units: &Units,
    params: &CompareParams,
) -> Result<Vec<Ranked>> {
    let paper = candidates.iter().position(Candidate::is_paper);
    let counts = |c: &Candidate| candidates.iter().position(|o| c.counts_of(o));
    // Each candidate's interval and paired tests resample from their own seeded stream,
    // thousands of draws per unit: ranked side by side too.
    let mut results: Vec<Ranked> = (candidates.par_iter().zip(scored).zip(over))
        .map(|((c, s), over_encodings)| {
            let against = (paper.map(|p| &scored[p]), counts(c).map(|r| &scored[r]));
            Ok(Ranked {
                over_encodings,
                ..units.rank(c, s, against, params)?
            })
        })
        .collect::<Result<_>>()?;
    results.sort_by(|a, b| b.accuracy.total_cmp(&a.accuracy));
    Ok(results)
}

/// Each candidate's accuracy over the encoding as run (`scored`) and the further encodings
/// of `perturbed`, scored under `parts`; `None` for a candidate some further encoding
/// lacks (a baseline without spikes). The further encodings' pieces are kept under keys
/// of their own.
///
/// # Errors
/// An evaluation that fails, or a piece that cannot be kept.
fn over_encodings(
    candidates: &[Candidate],
    scored: &[Scored],
    perturbed: Perturbed<'_>,
    (parts, units): (&[parts::Part], &Units),
    params: &CompareParams,
    (progress, keep): nested::Around<'_>,
) -> Result<Vec<Option<AcrossEncodings>>> {
    if perturbed.candidates.is_empty() {
        return Ok(vec![None; candidates.len()]);
    }
    let n: usize = perturbed.candidates.iter().map(Vec::len).sum();
    progress(Progress::Stage(
        "candidates on the perturbed encodings",
        n * parts.len(),
    ));
    let further: Vec<Vec<Scored>> = (perturbed.candidates.iter().enumerate())
        .map(|(e, list)| {
            let keep = keep.map(|k| Prefixed {
                keep: k,
                prefix: format!("encoding {}: ", e + 2),
            });
            let keep = keep.as_ref().map(|k| k as &dyn Keep);
            score_all(list, parts, params, progress, keep)
        })
        .collect::<Result<_>>()?;
    Ok(candidates
        .iter()
        .zip(scored)
        .map(|(c, as_run)| {
            let name = c.name();
            let mut all = vec![as_run];
            for (list, s) in perturbed.candidates.iter().zip(&further) {
                all.push(&s[list.iter().position(|o| o.name() == name)?]);
            }
            let accuracies: Vec<f64> = all.iter().map(|s| s.accuracy).collect();
            let shares: Vec<&[(usize, f64)]> = all.iter().map(|s| s.shares.as_slice()).collect();
            Some(AcrossEncodings {
                mean: mean(accuracies.iter().copied()),
                ci: units.interval_over_encodings(&shares),
                accuracies,
                perturbation: perturbed.size,
            })
        })
        .collect())
}

/// A keeper whose keys are another's with a prefix: the further encodings' pieces beside
/// those of the encoding as run.
struct Prefixed<'a> {
    keep: &'a dyn Keep,
    prefix: String,
}

impl Keep for Prefixed<'_> {
    fn get(&self, key: &str) -> Option<String> {
        self.keep.get(&format!("{}{key}", self.prefix))
    }

    fn put(&self, key: &str, json: &str) -> Result<()> {
        self.keep.put(&format!("{}{key}", self.prefix), json)
    }
}

/// What intervals and tests resample: `recordings`, or `groups of COLUMN`.
fn units_of(params: &CompareParams) -> String {
    match &params.group_by {
        Some(column) => format!("groups of {column}"),
        None => "recordings".into(),
    }
}

/// `5-fold stratified cross-validation, 3 repeats, seed 0; 2000 resamples for intervals
/// and tests`, with nested selection's inner folds when it runs.
fn design(params: &CompareParams) -> String {
    let cv = &params.cv;
    let folds = match &params.group_by {
        Some(column) => format!(
            "{}-fold cross-validation keeping each `{column}` whole",
            cv.folds
        ),
        None => format!("{}-fold stratified cross-validation", cv.folds),
    };
    let repeats = match cv.repeats {
        1 => "1 repeat".to_string(),
        n => format!("{n} repeats"),
    };
    let splits = match params.protocol {
        Protocol::Pooled | Protocol::Per(_) => format!("{folds}, {repeats}, seed {}", cv.seed),
        Protocol::HoldOut(_) => format!("one split per held-out value, seed {}", cv.seed),
        Protocol::Where { .. } => format!("one train/test split, seed {}", cv.seed),
    };
    let nested = match params.nested {
        false => String::new(),
        true => format!("; nested selection {}", nested_design(params)),
    };
    format!(
        "{splits}; {} resamples for intervals and tests{nested}",
        params.resamples
    )
}

/// How nested selection ranks inside each outer training set, as the design line says it
/// (the nested line says what each training set did).
fn nested_design(params: &CompareParams) -> String {
    let cv = &params.cv;
    let first = match (cv.repeats, &params.protocol) {
        (2.., Protocol::Pooled | Protocol::Per(_)) => " of the first repeat",
        _ => "",
    };
    match (params.inner_folds, &params.protocol) {
        (_, Protocol::HoldOut(_)) => "ranks inside each training set, each of its other values held out in turn (cross-validating where it holds one)".into(),
        (None, Protocol::Pooled | Protocol::Per(_)) if cv.folds >= nested::OUTER_FOLDS_TO_RANK_ON => {
            format!("ranks inside each training set{first}, each of the other outer folds held out in turn")
        }
        (folds, _) => format!(
            "ranks inside each training set{first} (up to {} inner folds)",
            folds.unwrap_or(cv.folds)
        ),
    }
}

/// The recordings every candidate is made of, the same for all.
///
/// # Errors
/// No candidate, or one made of other recordings than the first.
fn shared_recordings(candidates: &[Candidate]) -> Result<&[Meta]> {
    let first = candidates.first().ok_or(ClassifyError::Empty {
        what: "compare: no candidates",
    })?;
    if let Some(c) = candidates.iter().find(|c| c.metas != first.metas) {
        let message = format!("{} has other recordings than {}", c.name(), first.name());
        return Err(ClassifyError::BadFeatures(message).into());
    }
    Ok(&first.metas)
}

/// The note for a nested estimate whose interval is not above chance, said to `progress`
/// as advice too.
fn nested_note(
    n: &Nested,
    (classes, majority): (usize, f64),
    params: &CompareParams,
    progress: &(dyn Fn(Progress) + Sync),
) -> Option<String> {
    let held_out = matches!(params.protocol, Protocol::HoldOut(_));
    let interval = format!("[{:.1}, {:.1}] %", 100.0 * n.ci[0], 100.0 * n.ci[1]);
    let (chance, words) = chance_level(classes, majority);
    let chance_text = format!("chance ({words})");
    let why = match held_out {
        true => " (features that change with the held-out condition)",
        false => "",
    };
    let note = AgainstChance::of(n.ci, chance).map(|at| match at {
        AgainstChance::Below => format!(
            "the nested estimate's interval {interval} is under {chance_text}: what the selection learns on the training sets does not carry over to the test sets{why}"
        ),
        AgainstChance::Includes => format!(
            "the nested estimate's interval {interval} includes {chance_text}: the chosen procedure is not shown to classify better than guessing"
        ),
    })?;
    progress(Progress::Advice(&note));
    Some(note)
}

/// Checks before the recordings `metas` are encoded what `params` asks of them: the
/// protocol's column (per or held out) has a value in some, and nested selection can run.
///
/// # Errors
/// A column without values (named with those that have some), or nested selection's.
pub fn check_design(metas: &[Meta], params: &CompareParams) -> Result<()> {
    if let Protocol::Per(column) | Protocol::HoldOut(column) = &params.protocol {
        parts::conditions(metas, column)?;
    }
    match params.nested {
        true => check_nested(metas, params).map(drop),
        false => Ok(()),
    }
}

/// The number of classes among the evaluated rows and the largest class's share.
fn class_shares(metas: &[Meta], shares: &[(usize, f64)]) -> (usize, f64) {
    let mut counts: Vec<(String, usize)> = Vec::new();
    for &(row, _) in shares {
        let label = &metas[row].label;
        match counts.iter_mut().find(|(l, _)| l == label) {
            Some((_, n)) => *n += 1,
            None => counts.push((label.clone(), 1)),
        }
    }
    let largest = counts.iter().map(|(_, n)| *n).max().unwrap_or(0);
    (counts.len(), largest as f64 / shares.len().max(1) as f64)
}

fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (total, n) = values.fold((0.0, 0usize), |(t, n), v| (t + v, n + 1));
    total / n.max(1) as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::{Columns, FeatureTable};
    use crate::classify::{CvParams, KnnParams};
    use crate::pipeline::Method;
    use crate::values::Grid;

    /// 3 classes x `speeds` x 12 trials; `separable` features put each class far apart,
    /// otherwise the features are noise that knows nothing of the class.
    fn table_at(speeds: &[f64], separable: bool) -> FeatureTable {
        let mut metas = Vec::new();
        let mut values = Vec::new();
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut noise = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed % 1000) as f64 / 1000.0
        };
        for class in 0..3 {
            for &speed in speeds {
                for trial in 0..12 {
                    metas.push(Meta {
                        file: format!("c{class}_{speed}_{trial}.npy"),
                        label: format!("c{class}"),
                        speed_mm_s: Some(speed),
                        force_n: None,
                        trial: Some(trial),
                        slide_start_s: None,
                        slide_end_s: None,
                        extra: Default::default(),
                    });
                    let centre = if separable { 10.0 * class as f64 } else { 0.0 };
                    values.extend([centre + noise(), centre + noise(), centre + noise()]);
                }
            }
        }
        FeatureTable {
            method: Method::Glcm3d,
            grid: Grid::full(2, 2).unwrap(),
            names: vec!["a".into(), "b".into(), "c".into()],
            metas,
            values,
        }
    }

    /// A KNN candidate on 2 speeds (see [`table_at`]).
    fn candidate(method: &str, separable: bool) -> Candidate {
        candidate_at(&[5.0, 10.0], method, separable)
    }

    /// [`candidate`] at `speeds`.
    fn candidate_at(speeds: &[f64], method: &str, separable: bool) -> Candidate {
        let knn = KnnParams::default().check().unwrap();
        let table = table_at(speeds, separable);
        Candidate {
            encoding: "sa".into(),
            method: method.into(),
            classifier: "knn".into(),
            metas: Arc::new(table.metas.clone()),
            evaluate: crate::analysis::on_table(Arc::new(table), Columns::All, knn),
            prepare_s: 0.0,
        }
    }

    fn params(protocol: Protocol, nested: bool) -> CompareParams {
        CompareParams {
            protocol,
            cv: CvParams {
                folds: 4,
                seed: 3,
                repeats: 2,
            }
            .check()
            .unwrap(),
            group_by: None,
            resamples: 500,
            nested,
            inner_folds: Some(4),
        }
    }

    #[test]
    fn each_candidate_gets_its_accuracy_over_the_encodings_it_was_scored_on() {
        let baseline = Candidate {
            encoding: "none".into(),
            ..candidate("spectrum", true)
        };
        let as_run = [
            candidate("glcm3d", false),
            candidate("good", true),
            baseline,
        ];
        // A further encoding in which the paper's method sees the classes; the baseline
        // passes through no encoder and has no further encoding.
        let further = vec![vec![candidate("glcm3d", true), candidate("good", true)]];
        let perturbed = Perturbed {
            candidates: &further,
            size: 1e-12,
        };
        let p = params(Protocol::Per("speed_mm_s".into()), false);
        let silent = &crate::progress::silent;
        let drawn = compare_over_encodings(&as_run, perturbed, &p, silent, None).unwrap();
        let plain = compare(&as_run, &p).unwrap();
        // The ranking is that of the encoding as run (the clocks aside).
        let without = |c: &Comparison| -> Vec<Ranked> {
            let strip = |r: &Ranked| Ranked {
                over_encodings: None,
                seconds: 0.0,
                ..r.clone()
            };
            c.results.iter().map(strip).collect()
        };
        assert_eq!(without(&drawn), without(&plain));
        assert!(plain.results.iter().all(|r| r.over_encodings.is_none()));
        let find = |method: &str| drawn.results.iter().find(|r| r.method == method).unwrap();
        let paper = find("glcm3d");
        let over = paper.over_encodings.as_ref().unwrap();
        assert_eq!(over.accuracies, vec![paper.accuracy, 1.0]);
        assert!(paper.accuracy < 0.7, "{}", paper.accuracy);
        assert_eq!(over.mean, (paper.accuracy + 1.0) / 2.0);
        assert_eq!(over.perturbation, 1e-12);
        // Half the resamples draw the perfect encoding, the rest the one as run.
        assert_eq!(over.ci[1], 1.0);
        assert!(
            over.ci[0] < paper.accuracy && over.ci[0] <= paper.ci[1],
            "{over:?}"
        );
        // Right everywhere under both: the interval of one encoding.
        let good = find("good");
        let over = good.over_encodings.as_ref().unwrap();
        assert_eq!((over.accuracies.clone(), over.mean), (vec![1.0, 1.0], 1.0));
        assert_eq!(over.ci, good.ci);
        assert!(find("spectrum").over_encodings.is_none());
        // Its JSON holds the key only where there are encodings to summarise.
        let json = serde_json::to_value(&drawn).unwrap();
        let keyed = |r: &serde_json::Value| r.get("over_encodings").is_some();
        let rows = json["results"].as_array().unwrap();
        assert_eq!(rows.iter().filter(|r| keyed(r)).count(), 2);
        let json = serde_json::to_value(&plain).unwrap();
        assert!(!json["results"].as_array().unwrap().iter().any(keyed));
    }

    #[test]
    fn a_separable_candidate_beats_the_paper_method_on_noise_significantly() {
        // The paper's method sees noise here; "good" sees the classes.
        let candidates = [candidate("glcm3d", false), candidate("good", true)];
        for protocol in [
            Protocol::Pooled,
            Protocol::Per("speed_mm_s".into()),
            Protocol::HoldOut("speed_mm_s".into()),
        ] {
            let c = compare(&candidates, &params(protocol.clone(), true)).unwrap();
            assert_eq!(c.best.method, "good", "{protocol}");
            assert_eq!(c.best.accuracy, 1.0);
            assert_eq!((c.classes, c.n_recordings, c.n_units), (3, 72, 72));
            assert!((c.chance - 1.0 / 3.0).abs() < 1e-15);
            let (best, paper) = (&c.results[0], &c.results[1]);
            assert!(paper.paper && paper.p_vs_paper.is_none());
            assert!(best.p_vs_paper.unwrap() < 0.01, "{protocol}: {best:?}");
            let gap = best.difference_vs_paper.unwrap();
            assert!((gap - (best.accuracy - paper.accuracy)).abs() < 1e-12);
            // noise classifies near chance, its interval holding chance and its estimate
            assert!(paper.ci[0] <= paper.accuracy && paper.accuracy <= paper.ci[1]);
            assert!(paper.ci[0] < 0.5 && paper.accuracy < 0.6, "{paper:?}");
            let nested = c.nested.as_ref().unwrap();
            assert_eq!(nested.chosen[0].0, "sa / good / knn");
            assert_eq!(nested.accuracy, 1.0);
            let conditions = if protocol == Protocol::Pooled { 0 } else { 2 };
            assert_eq!(best.per_condition.len(), conditions);
        }
    }

    #[test]
    fn per_condition_accuracies_average_to_the_accuracy_and_splits_are_shared() {
        let candidates = [candidate("glcm3d", true), candidate("glcm3d-again", true)];
        let c = compare(
            &candidates,
            &params(Protocol::Per("speed_mm_s".into()), false),
        )
        .unwrap();
        let r = &c.results[1];
        let mean = (r.per_condition[0].accuracy + r.per_condition[1].accuracy) / 2.0;
        assert_eq!(r.accuracy, mean);
        assert_eq!(r.per_condition[0].condition, "5");
        // the same features on the same splits: no difference at all, p = 1
        let other = c.results.iter().find(|r| !r.paper).unwrap();
        assert_eq!(other.difference_vs_paper, Some(0.0));
        assert_eq!(other.p_vs_paper, Some(1.0));
        assert!(c.nested.is_none());
    }

    /// A candidate named `encoding / method / classifier`, separable or noise.
    fn named(encoding: &str, method: &str, classifier: &str, separable: bool) -> Candidate {
        Candidate {
            encoding: encoding.into(),
            classifier: classifier.into(),
            ..candidate(method, separable)
        }
    }

    /// The spiking network is tested against its own encoding's rates with logistic
    /// regression, and nothing else is.
    #[test]
    fn the_network_is_paired_with_its_inputs_rates() {
        let candidates = [
            named("sa", "glcm3d", "knn", false),
            named("sa+fa", "spikes", "snn", true),
            named("sa+fa", "rates", "linear", false),
            named("sa", "rates", "linear", true),
            named("sa", "spikes", "snn", true),
        ];
        let c = compare(&candidates, &params(Protocol::Pooled, false)).unwrap();
        let find = |e: &str, m: &str| {
            let r = c.results.iter().find(|r| r.encoding == e && r.method == m);
            r.unwrap()
        };
        let (net, rates) = (find("sa+fa", "spikes"), find("sa+fa", "rates"));
        let gap = net.difference_vs_rates.unwrap();
        assert_eq!(gap, net.accuracy - rates.accuracy);
        assert!(gap > 0.4 && net.p_vs_rates.unwrap() < 0.01, "{net:?}");
        // the same features on the same splits: no difference, p = 1
        let same = find("sa", "spikes");
        assert_eq!(
            (same.difference_vs_rates, same.p_vs_rates),
            (Some(0.0), Some(1.0))
        );
        for r in [rates, find("sa", "rates"), find("sa", "glcm3d")] {
            assert_eq!((r.difference_vs_rates, r.p_vs_rates), (None, None), "{r:?}");
        }
        assert_eq!(
            c.design,
            "4-fold stratified cross-validation, 2 repeats, seed 3; 500 resamples for intervals and tests"
        );
        let json = serde_json::to_value(&c.results).unwrap();
        let with_test = json
            .as_array()
            .unwrap()
            .iter()
            .filter(|r| r.get("p_vs_rates").is_some());
        assert_eq!(with_test.count(), 2);
    }

    #[test]
    fn a_protocol_column_without_two_values_is_an_error() {
        let candidates = [candidate("glcm3d", true)];
        let err = compare(&candidates, &params(Protocol::Per("session".into()), false));
        assert!(err.unwrap_err().to_string().contains("session"));
        assert!(compare(&[], &params(Protocol::Pooled, false)).is_err());
    }

    /// Pieces kept in memory, for a test to read.
    #[derive(Default)]
    struct Spy(std::sync::Mutex<std::collections::HashMap<String, String>>);

    impl Keep for Spy {
        fn get(&self, key: &str) -> Option<String> {
            self.0.lock().unwrap().get(key).cloned()
        }
        fn put(&self, key: &str, json: &str) -> Result<()> {
            self.0.lock().unwrap().insert(key.into(), json.into());
            Ok(())
        }
    }

    /// A nested estimate of candidates that see only noise is not above chance, and the
    /// comparison says so (the separable candidates of the other tests get no such note).
    #[test]
    fn a_nested_estimate_at_chance_is_said_to_be() {
        let noise = [candidate("glcm3d", false), candidate("noise", false)];
        let c = compare(&noise, &params(Protocol::Per("speed_mm_s".into()), true)).unwrap();
        let n = c.nested.as_ref().unwrap();
        assert!(AgainstChance::of(n.ci, c.chance).is_some(), "{:?}", n.ci);
        let said = c
            .notes
            .iter()
            .filter(|s| s.contains("chance (33.3 %, one over 3 classes)"));
        assert_eq!(said.count(), 1, "{:?}", c.notes);
    }

    /// Under a hold-out protocol the inner ranking holds out each speed of the outer
    /// training set: a candidate's inner accuracy is the mean of its accuracies with each
    /// of them held out. With two speeds one is left to train on, and the comparison says
    /// that its inner ranking cross-validates within it.
    #[test]
    fn hold_out_nested_selection_holds_out_inside_too() {
        let speeds = [5.0, 10.0, 15.0];
        let three = [
            candidate_at(&speeds, "glcm3d", true),
            candidate_at(&speeds, "noise", false),
        ];
        let p = params(Protocol::HoldOut("speed_mm_s".into()), true);
        let spy = Spy::default();
        let c = compare_keeping(&three, &p, &crate::progress::silent, Some(&spy)).unwrap();
        assert!(c.notes.is_empty(), "{:?}", c.notes);
        let metas = &three[0].metas;
        let values = parts::conditions(metas, "speed_mm_s").unwrap();
        assert_eq!(values.len(), 3);
        for (s, held) in values.iter().enumerate() {
            let train: Vec<usize> = (0..metas.len())
                .filter(|&i| metas[i].field("speed_mm_s").as_ref() != Some(held))
                .collect();
            let others: Vec<String> = values.iter().filter(|v| *v != held).cloned().collect();
            for cand in &three {
                let each = others.iter().map(|v| {
                    let split = parts::hold_out("speed_mm_s", &others, v);
                    (cand.evaluate)(&train, &split, &crate::progress::silent)
                        .unwrap()
                        .accuracy
                });
                let expected = each.sum::<f64>() / others.len() as f64;
                let key = format!("inner accuracy of {} in outer split {s}", cand.name());
                let kept: f64 = serde_json::from_str(&spy.get(&key).unwrap()).unwrap();
                assert_eq!(kept, expected, "{key}");
            }
        }
        // The separable candidate carries to the speed held out; the noise does not.
        let nested = c.nested.unwrap();
        assert_eq!(nested.chosen[0].0, three[0].name());
        assert_eq!(
            nested.inner,
            "each other value of speed_mm_s held out in turn, inside each outer training set"
        );
        let two = [candidate("glcm3d", true), candidate("noise", false)];
        let c = compare(&two, &p).unwrap();
        assert_eq!(
            c.nested.as_ref().unwrap().inner,
            "4-fold cross-validation inside each outer training set (each holds one value of speed_mm_s)"
        );
        assert!(
            c.notes
                .iter()
                .any(|n| n.contains("2 of 2 outer training sets hold one value")),
            "{:?}",
            c.notes
        );
    }

    /// Under a hold-out protocol, outer split `a` holding out `b` trains on what outer split
    /// `b` holding out `a` trains on: with four speeds, each candidate's 12 inner splits are
    /// 6 fits, each made once on all recordings and read off per split. Every inner accuracy
    /// is, bit for bit, the one the split's own evaluation gives; a method scoring each taxel
    /// alone has no per-recording 1 or 0 to read and is evaluated split by split.
    #[test]
    fn held_out_inner_splits_share_their_fits_and_keep_their_accuracies() {
        use std::sync::atomic::{AtomicUsize, Ordering};
        let speeds = [5.0, 10.0, 15.0, 20.0];
        let mut taxels = table_at(&speeds, false);
        taxels.grid = Grid::full(1, 3).unwrap();
        let knn = KnnParams::default().check().unwrap();
        let each_taxel = Candidate {
            method: "taxel".into(),
            evaluate: crate::analysis::on_table(Arc::new(taxels), Columns::EachTaxel, knn),
            ..candidate_at(&speeds, "taxel", false)
        };
        let (shared, own) = (Arc::new(AtomicUsize::new(0)), Arc::new(AtomicUsize::new(0)));
        let counted = |c: Candidate| {
            let (evaluate, n) = (Arc::clone(&c.evaluate), c.metas.len());
            let (shared, own) = (Arc::clone(&shared), Arc::clone(&own));
            let evaluate: Arc<EvaluateFn> = Arc::new(move |within, split, on| {
                match (within.len() == n, split) {
                    (true, Split::Rows { .. }) => shared.fetch_add(1, Ordering::Relaxed),
                    (false, Split::Where { .. }) => own.fetch_add(1, Ordering::Relaxed),
                    _ => 0,
                };
                evaluate(within, split, on)
            });
            Candidate { evaluate, ..c }
        };
        let list = [
            counted(candidate_at(&speeds, "glcm3d", true)),
            counted(candidate_at(&speeds, "noise", false)),
        ];
        let p = params(Protocol::HoldOut("speed_mm_s".into()), true);
        let spy = Spy::default();
        // One thread, so that no two outer splits meet a fit at once (each would make it).
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let silent = &crate::progress::silent;
        pool.install(|| compare_keeping(&list, &p, silent, Some(&spy)).unwrap());
        // 6 shared fits per candidate and no inner split on its own; each of the 4 outer
        // splits then trains its chosen candidate on all its rows (also on all recordings).
        assert_eq!(shared.load(Ordering::Relaxed), 2 * 6 + 4);
        assert_eq!(own.load(Ordering::Relaxed), 0);
        let taxel_list = [counted(each_taxel)];
        let taxel_spy = Spy::default();
        pool.install(|| compare_keeping(&taxel_list, &p, silent, Some(&taxel_spy)).unwrap());
        // One shared fit tried (it scores each taxel alone), then every inner split alone.
        assert_eq!(shared.load(Ordering::Relaxed), 2 * 6 + 4 + 1 + 4);
        assert_eq!(own.load(Ordering::Relaxed), 4 * 3);
        let metas = &list[0].metas;
        let values = parts::conditions(metas, "speed_mm_s").unwrap();
        for (s, held) in values.iter().enumerate() {
            let train: Vec<usize> = (0..metas.len())
                .filter(|&i| metas[i].field("speed_mm_s").as_ref() != Some(held))
                .collect();
            let others: Vec<String> = values.iter().filter(|v| *v != held).cloned().collect();
            let kept = list.iter().map(|c| (c, &spy));
            for (cand, spy) in kept.chain(taxel_list.iter().map(|c| (c, &taxel_spy))) {
                let each = others.iter().map(|v| {
                    let split = parts::hold_out("speed_mm_s", &others, v);
                    (cand.evaluate)(&train, &split, silent).unwrap().accuracy
                });
                let expected = each.sum::<f64>() / others.len() as f64;
                let key = format!("inner accuracy of {} in outer split {s}", cand.name());
                let kept: f64 = serde_json::from_str(&spy.get(&key).unwrap()).unwrap();
                assert_eq!(kept.to_bits(), expected.to_bits(), "{key}");
            }
        }
    }

    /// Under cross-validation the inner ranking holds out each other outer fold of the
    /// condition in turn: outer split `a` holding out fold `b` trains on what outer split `b`
    /// holding out `a` trains on, so with 4 folds at each of 2 speeds each candidate's 24
    /// inner splits are 12 fits, each made once and read by both. Every inner accuracy is
    /// the mean of the split's own evaluations; where a fit would miss a class of the outer
    /// training set, or inner folds are asked for, the outer folds do not serve.
    #[test]
    fn cross_validated_inner_splits_hold_out_the_other_outer_folds_and_share_their_fits() {
        use std::sync::atomic::{AtomicUsize, Ordering};
        let speeds = [5.0, 10.0];
        let fits = Arc::new(AtomicUsize::new(0));
        let counted = |c: Candidate| {
            let (evaluate, n, fits) = (Arc::clone(&c.evaluate), c.metas.len(), Arc::clone(&fits));
            let evaluate: Arc<EvaluateFn> = Arc::new(move |within, split, on| {
                if within.len() == n && matches!(split, Split::Rows { .. }) {
                    fits.fetch_add(1, Ordering::Relaxed);
                }
                evaluate(within, split, on)
            });
            Candidate { evaluate, ..c }
        };
        let list = [
            counted(candidate_at(&speeds, "glcm3d", true)),
            counted(candidate_at(&speeds, "noise", false)),
        ];
        let p = CompareParams {
            inner_folds: None,
            ..params(Protocol::Per("speed_mm_s".into()), true)
        };
        let (spy, silent) = (Spy::default(), &crate::progress::silent);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let c = pool.install(|| compare_keeping(&list, &p, silent, Some(&spy)).unwrap());
        // 2 speeds x 6 pairs of folds per candidate, then each of the 8 outer splits trains
        // its chosen candidate on all its rows.
        assert_eq!(fits.load(Ordering::Relaxed), 2 * 2 * 6 + 8);
        let nested = c.nested.unwrap();
        assert!(
            nested.inner.starts_with("each of the other outer folds"),
            "{}",
            nested.inner
        );
        let metas = &list[0].metas;
        let splits = nested::outer_splits(metas, &p).unwrap();
        assert_eq!(splits.len(), 8);
        for (s, split) in splits.iter().enumerate() {
            assert_eq!(split.others.len(), 3);
            assert!(nested::on_outer_folds(metas, &p, split));
            let at = |rows: &[usize]| -> Vec<usize> {
                let position = |r: &usize| split.train.iter().position(|t| t == r).unwrap();
                rows.iter().map(position).collect()
            };
            for cand in &list {
                let each = split.others.iter().map(|held| {
                    let fit: Vec<usize> = (split.train.iter().copied())
                        .filter(|r| !held.contains(r))
                        .collect();
                    let own = Split::Rows {
                        train: at(&fit),
                        test: at(held),
                    };
                    (cand.evaluate)(&split.train, &own, silent)
                        .unwrap()
                        .accuracy
                });
                let expected = each.sum::<f64>() / 3.0;
                let key = format!("inner accuracy of {} in outer split {s}", cand.name());
                let kept: f64 = serde_json::from_str(&spy.get(&key).unwrap()).unwrap();
                assert_eq!(kept.to_bits(), expected.to_bits(), "{key}");
            }
        }
        // Inner folds asked for, three outer folds, or a class all in the two folds a fit
        // leaves out: the split cross-validates on folds of its own.
        let asked = CompareParams {
            inner_folds: Some(3),
            ..p.clone()
        };
        assert!(!nested::on_outer_folds(metas, &asked, &splits[0]));
        let mut splits = splits.into_iter();
        let (mut split, mut three) = (splits.next().unwrap(), splits.next().unwrap());
        three.others.truncate(2);
        assert!(!nested::on_outer_folds(metas, &p, &three));
        let class_of = |r: &usize| metas[*r].label.clone();
        let c0: Vec<usize> = (split.train.iter())
            .filter(|r| class_of(r) == "c0")
            .copied()
            .collect();
        split.others[0].retain(|r| class_of(r) != "c0");
        split.others[0].extend(&c0);
        split.others[0].sort_unstable();
        assert!(!nested::on_outer_folds(metas, &p, &split));
    }
}
