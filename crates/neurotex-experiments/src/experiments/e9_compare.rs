//! E9 (beyond the paper): the best of the standard candidates of `neurotex compare`
//! (encodings, feature methods, classifiers) beside the paper's method (SA, 3D-GLCM, KNN),
//! cross-validated within each speed and with each speed held out (E6's question).
//!
//! The best candidate is chosen on the same recordings it is scored on, so its accuracy
//! flatters it; both comparisons also run nested selection (the candidates ranked inside
//! each training set), whose accuracy is the honest one for "the best method".
//!
//! With [`ValidReproduceParams::e9_snn`], the spiking network (`snn` on the SA+FA spikes)
//! runs beside the paper's method on the same folds. Its hyperparameters are its defaults,
//! fixed before any data, so it needs no nested selection: its accuracy is honest as it
//! stands.

use serde::{Deserialize, Serialize};

use super::{Prepared, Skip, Stop, ValidReproduceParams};
use crate::classify::ClassifierChoice;
use crate::classify::CvParams;
use crate::compare::candidates::{candidates, CandidateSet, MethodChoice};
use crate::compare::signal::baseline_candidates;
use crate::compare::{compare_with_progress, CompareParams, Comparison, Protocol};
use crate::pipeline::{Encoding, Method};
use crate::progress::Progress;
use crate::snn::SnnParams;

/// E9's two comparisons.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct E9 {
    /// Cross-validation within each speed, ranked by the mean over speeds, with nested
    /// selection.
    pub per_speed: Comparison,
    /// Each speed held out in turn (trained on the others), with nested selection.
    pub held_out: Comparison,
    /// The baselines without spikes on the same folds (`compare --encodings none`),
    /// within each speed and with each speed held out; not among the candidates.
    #[serde(default)]
    pub baselines: Option<Baselines>,
    /// The spiking network beside the paper's method, when asked for.
    #[serde(default)]
    pub spiking: Option<Spiking>,
}

/// The spiking network (`sa+fa / spikes / snn`) and the paper's method (`sa / glcm3d /
/// knn`) on E9's folds; each comparison's non-paper result carries the paired test.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Spiking {
    /// Cross-validation within each speed.
    pub per_speed: Comparison,
    /// Each speed held out.
    pub held_out: Comparison,
}

impl Spiking {
    /// The network's and the paper's method's results in `c`, when both ran.
    pub fn pair(c: &Comparison) -> Option<(&crate::compare::Ranked, &crate::compare::Ranked)> {
        let network = c.results.iter().find(|r| r.classifier == "snn")?;
        let paper = c.results.iter().find(|r| r.paper)?;
        Some((network, paper))
    }
}

impl E9 {
    /// The best baseline without spikes with each speed held out, when they ran.
    pub fn held_out_baseline(&self) -> Option<&crate::compare::Ranked> {
        match &self.baselines {
            Some(Baselines::Compared { held_out, .. }) => Some(&held_out.best),
            _ => None,
        }
    }
}

/// E9's baselines without spikes, or why they were not run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Baselines {
    /// Within each speed and with each speed held out.
    Compared {
        /// Cross-validation within each speed.
        per_speed: Box<Comparison>,
        /// Each speed held out.
        held_out: Box<Comparison>,
    },
    /// A recording's signal could not give a baseline's row.
    Skipped(String),
}

/// Runs E9 on the prepared recordings (both populations encoded).
///
/// # Errors
/// Skipped with one speed; fails when a candidate cannot be evaluated.
pub fn e9_compare(
    prepared: &Prepared,
    params: &ValidReproduceParams,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<E9, Stop> {
    let said = Said::new(progress);
    let compare = |list: &[crate::compare::Candidate], p: &CompareParams, what: &str| {
        said.begin(what);
        compare_with_progress(list, p, &|e| said.on(e))
    };
    if prepared.speeds.len() < 2 {
        return Err(Stop::Skipped(Skip::OneSpeedE9));
    }
    if prepared.encoded.iter().any(|e| e.fa.is_none()) {
        return Err(Stop::Skipped(Skip::NoOffEvents));
    }
    let set = CandidateSet::standard(params.knn, params.seed);
    let pipeline = params.pipeline().params().clone();
    let list = candidates(&prepared.encoded, &prepared.grid, &pipeline, &set, 0.0)?;
    let cv = CvParams {
        repeats: params.e9_repeats,
        ..params.cv
    }
    .check()
    .map_err(crate::Error::from)?;
    let with = |protocol, nested| CompareParams {
        protocol,
        cv,
        group_by: params.group_by.clone(),
        resamples: 2000,
        nested,
    };
    let column = "speed_mm_s".to_string();
    let per = || Protocol::Per(column.clone());
    let held = || Protocol::HoldOut(column.clone());
    let baselines = baselines(
        prepared,
        &set,
        &pipeline,
        [&with(per(), false), &with(held(), false)],
        &compare,
    )?;
    let spiking = match params.e9_snn {
        true => Some(spiking(
            prepared,
            params,
            [&with(per(), false), &with(held(), false)],
            &compare,
        )?),
        false => None,
    };
    Ok(E9 {
        // A pilot too small for folds inside each speed's training folds is ranked
        // without the nested estimate (the held-out comparison trains on other speeds).
        per_speed: compare(&list, &with(per(), true), "candidates within each speed").or_else(
            |_| {
                compare(
                    &list,
                    &with(per(), false),
                    "candidates within each speed, not nested",
                )
            },
        )?,
        held_out: compare(
            &list,
            &with(held(), true),
            "candidates, each speed held out",
        )?,
        baselines: Some(baselines),
        spiking,
    })
}

/// The signal baselines (no spikes) compared under `per` and `held`, or why they were not
/// run.
fn baselines(
    prepared: &Prepared,
    set: &CandidateSet,
    pipeline: &crate::pipeline::PipelineParams,
    [per, held]: [&CompareParams; 2],
    compare: &CompareFn,
) -> Result<Baselines, Stop> {
    let rows = match prepared
        .signal
        .iter()
        .cloned()
        .collect::<Result<Vec<_>, _>>()
    {
        Ok(rows) => rows,
        Err(why) => return Ok(Baselines::Skipped(why)),
    };
    let list = baseline_candidates(
        &rows,
        &prepared.grid,
        &pipeline.features,
        &set.classifiers,
        0.0,
    )?;
    Ok(Baselines::Compared {
        per_speed: Box::new(compare(&list, per, "signal baselines within each speed")?),
        held_out: Box::new(compare(
            &list,
            held,
            "signal baselines, each speed held out",
        )?),
    })
}

/// The spiking network with its default hyperparameters and the paper's method, compared
/// under `per` and `held`.
fn spiking(
    prepared: &Prepared,
    params: &ValidReproduceParams,
    [per, held]: [&CompareParams; 2],
    compare: &CompareFn,
) -> Result<Spiking, Stop> {
    let pipeline = params.pipeline().params().clone();
    let set = |encoding, method, classifier| CandidateSet {
        encodings: vec![encoding],
        methods: vec![method],
        classifiers: vec![classifier],
        ..CandidateSet::standard(params.knn, params.seed)
    };
    let paper = set(
        Encoding::Sa,
        MethodChoice::Features(Method::Glcm3d),
        ClassifierChoice::Knn(params.knn),
    );
    let network = set(
        Encoding::SaFa,
        MethodChoice::Spikes,
        ClassifierChoice::Snn(SnnParams::default()),
    );
    let mut list = candidates(&prepared.encoded, &prepared.grid, &pipeline, &paper, 0.0)?;
    list.extend(candidates(
        &prepared.encoded,
        &prepared.grid,
        &pipeline,
        &network,
        0.0,
    )?);
    Ok(Spiking {
        per_speed: compare(&list, per, "the spiking network within each speed")?,
        held_out: compare(&list, held, "the spiking network, each speed held out")?,
    })
}

/// One of E9's comparisons, said as it runs: the candidates, the protocol, what to call it.
type CompareFn<'a> =
    dyn Fn(&[crate::compare::Candidate], &CompareParams, &str) -> crate::Result<Comparison> + 'a;

/// How often E9 says how far its comparisons are: it runs beside the other analyses,
/// which hold the progress bar, so it speaks in lines.
const SAY_EVERY_S: f64 = 15.0;

/// E9's progress as lines: each comparison's start, then its stage and steps done at most
/// every [`SAY_EVERY_S`] seconds (`compare`'s steps: candidates scored, then each
/// candidate cross-validated inside each of nested selection's splits).
struct Said<'a> {
    progress: &'a (dyn Fn(Progress) + Sync),
    state: std::sync::Mutex<SaidState>,
}

struct SaidState {
    what: String,
    stage: String,
    done: usize,
    total: usize,
    last: std::time::Instant,
}

impl<'a> Said<'a> {
    fn new(progress: &'a (dyn Fn(Progress) + Sync)) -> Self {
        let state = SaidState {
            what: String::new(),
            stage: String::new(),
            done: 0,
            total: 0,
            last: std::time::Instant::now(),
        };
        Said {
            progress,
            state: std::sync::Mutex::new(state),
        }
    }

    fn begin(&self, what: &str) {
        let mut s = self.state.lock().unwrap_or_else(|e| e.into_inner());
        s.what = what.to_string();
        s.last = std::time::Instant::now();
        (self.progress)(Progress::Say(&format!("E9: {what}")));
    }

    fn on(&self, event: Progress) {
        let mut s = self.state.lock().unwrap_or_else(|e| e.into_inner());
        match event {
            Progress::Stage(stage, total) => {
                (s.stage, s.total, s.done) = (stage.to_string(), total, 0);
            }
            Progress::Tick | Progress::Done(..) | Progress::Skipped(..) => s.done += 1,
            other => return (self.progress)(other),
        }
        let due = s.last.elapsed().as_secs_f64() >= SAY_EVERY_S;
        if due || (s.done == s.total && s.total > 0 && s.stage == "nested selection") {
            s.last = std::time::Instant::now();
            let line = format!("E9: {}: {} {}/{}", s.what, s.stage, s.done, s.total);
            (self.progress)(Progress::Say(&line));
        }
    }
}
