//! E9 (beyond the paper): the best of the standard candidates of `neurotex compare`
//! (encodings, feature methods, classifiers) beside the paper's method (SA, 3D-GLCM, KNN),
//! cross-validated within each speed and with each speed held out (E6's question).
//!
//! The best candidate is chosen on the same recordings it is scored on, so its accuracy
//! flatters it; both comparisons also run nested selection (the candidates ranked inside
//! each training set), whose accuracy is the honest one for "the best method".
//!
//! With [`ValidReproduceParams::e9_snn`], the spiking network (`snn` on the SA+FA spikes)
//! runs beside the paper's method and beside its own inputs' spike rates with logistic
//! regression (`sa+fa / rates / linear`: what the network gains over it, it draws from the
//! spikes' timing and its own nonlinearity) on the same folds. Its hyperparameters are its
//! defaults, not searched on these recordings, so it needs no nested selection (all were
//! fixed before any data but standardised inputs, chosen over raw counts on the simulator
//! and FabricSlide; docs/spiking-classifier.md).

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

/// The spiking network (`sa+fa / spikes / snn`), the paper's method (`sa / glcm3d / knn`)
/// and the network's inputs' spike rates with logistic regression (`sa+fa / rates /
/// linear`) on E9's folds; each comparison's non-paper results carry the paired test
/// against the paper's method.
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

    /// The network's inputs' spike rates with logistic regression in `c`, when it ran.
    pub fn rates(c: &Comparison) -> Option<&crate::compare::Ranked> {
        c.results
            .iter()
            .find(|r| r.method == Method::Rates.name() && r.classifier == "linear")
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
    let compare = |list: &[crate::compare::Candidate], p: &CompareParams, what: &str| {
        let meter = Meter::begin(progress, what);
        compare_with_progress(list, p, &|e| meter.on(e))
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
        inner_folds: None,
    };
    let column = "speed_mm_s".to_string();
    let per = || Protocol::Per(column.clone());
    let held = || Protocol::HoldOut(column.clone());
    let (per_plain, held_plain) = (with(per(), false), with(held(), false));
    // The comparisons read the same candidates and write nothing the others read: they
    // run side by side, so that one's last and longest candidates overlap the next one's
    // work. Each is what it is alone, and a failure is the first in the order below.
    let ((baselines, spiking), (per_speed, held_out)) = rayon::join(
        || {
            rayon::join(
                || {
                    baselines(
                        prepared,
                        &set,
                        &pipeline,
                        [&per_plain, &held_plain],
                        &compare,
                    )
                },
                || match params.e9_snn {
                    true => {
                        spiking(prepared, params, [&per_plain, &held_plain], &compare).map(Some)
                    }
                    false => Ok(None),
                },
            )
        },
        || {
            let nested = [&with(per(), true), &per_plain, &with(held(), true)];
            nested_comparisons(&list, nested, &compare)
        },
    );
    let (baselines, spiking) = (baselines?, spiking?);
    Ok(E9 {
        per_speed: per_speed?,
        held_out: held_out?,
        baselines: Some(baselines),
        spiking,
    })
}

/// The candidates compared with nested selection within each speed (`per`; without it,
/// `per_plain`, when a pilot is too small for folds inside each speed's training folds)
/// and with each speed held out (`held`, which trains on the other speeds), side by side.
fn nested_comparisons(
    list: &[crate::compare::Candidate],
    [per, per_plain, held]: [&CompareParams; 3],
    compare: &CompareFn,
) -> (crate::Result<Comparison>, crate::Result<Comparison>) {
    rayon::join(
        || {
            compare(list, per, "candidates within each speed")
                .or_else(|_| compare(list, per_plain, "candidates within each speed, not nested"))
        },
        || compare(list, held, "candidates, each speed held out"),
    )
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
    let (per_speed, held_out) = rayon::join(
        || compare(&list, per, "signal baselines within each speed"),
        || compare(&list, held, "signal baselines, each speed held out"),
    );
    Ok(Baselines::Compared {
        per_speed: Box::new(per_speed?),
        held_out: Box::new(held_out?),
    })
}

/// The spiking network with its default hyperparameters, the paper's method and the
/// network's inputs' spike rates with logistic regression, compared under `per` and `held`.
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
    let rates = set(
        Encoding::SaFa,
        MethodChoice::Features(Method::Rates),
        ClassifierChoice::Linear(Default::default()),
    );
    let mut list = Vec::new();
    for set in [&paper, &rates, &network] {
        list.extend(candidates(
            &prepared.encoded,
            &prepared.grid,
            &pipeline,
            set,
            0.0,
        )?);
    }
    let (per_speed, held_out) = rayon::join(
        || compare(&list, per, "the spiking network within each speed"),
        || compare(&list, held, "the spiking network, each speed held out"),
    );
    Ok(Spiking {
        per_speed: per_speed?,
        held_out: held_out?,
    })
}

/// One of E9's comparisons, said as it runs: the candidates, the protocol, what to call it.
type CompareFn<'a> = dyn Fn(&[crate::compare::Candidate], &CompareParams, &str) -> crate::Result<Comparison>
    + Sync
    + 'a;

/// The longest E9 stays silent while its comparisons make steps: it runs beside the other
/// analyses, which hold the progress bar, so it speaks in lines.
const SAY_EVERY_S: f64 = 15.0;

/// How long a comparison's stage runs before its steps are said: a quick one stays quiet.
const SAY_AFTER_S: f64 = 1.0;

/// One of E9's comparisons, said as lines as it runs: its start, then its stage and the
/// steps done (`compare`'s steps: each candidate scored on each part of the protocol, then
/// each candidate cross-validated inside each of nested selection's outer splits) at each
/// tenth of a stage once it has run [`SAY_AFTER_S`], and at least every [`SAY_EVERY_S`]
/// while steps are done. The comparisons run side by side, each with its own meter.
struct Meter<'a> {
    progress: &'a (dyn Fn(Progress) + Sync),
    what: String,
    state: std::sync::Mutex<MeterState>,
}

struct MeterState {
    stage: String,
    done: usize,
    total: usize,
    /// When the stage began.
    began: std::time::Instant,
    /// When a line was last said.
    said: std::time::Instant,
}

impl<'a> Meter<'a> {
    /// Says that the comparison `what` begins.
    fn begin(progress: &'a (dyn Fn(Progress) + Sync), what: &str) -> Self {
        progress(Progress::Say(&format!("E9: {what}")));
        let now = std::time::Instant::now();
        let state = MeterState {
            stage: String::new(),
            done: 0,
            total: 0,
            began: now,
            said: now,
        };
        Meter {
            progress,
            what: what.to_string(),
            state: std::sync::Mutex::new(state),
        }
    }

    fn on(&self, event: Progress) {
        let mut s = self.state.lock().unwrap_or_else(|e| e.into_inner());
        match event {
            Progress::Stage(stage, total) => {
                let now = std::time::Instant::now();
                (s.stage, s.total, s.done, s.began) = (stage.to_string(), total, 0, now);
                return;
            }
            Progress::Tick | Progress::Done(..) | Progress::Skipped(..) => s.done += 1,
            other => return (self.progress)(other),
        }
        let (ran, quiet) = (
            s.began.elapsed().as_secs_f64(),
            s.said.elapsed().as_secs_f64(),
        );
        if say_step(s.done, s.total, ran, quiet) {
            s.said = std::time::Instant::now();
            let line = format!(
                "E9: {}: {} {}/{} ({ran:.1} s)",
                self.what, s.stage, s.done, s.total
            );
            (self.progress)(Progress::Say(&line));
        }
    }
}

/// Whether step `done` of `total` is said, the stage having run `ran` s and the last line
/// said `quiet` s ago: at each tenth of the way (every step of a stage of fewer than ten)
/// once the stage has run [`SAY_AFTER_S`], or when nothing was said for [`SAY_EVERY_S`].
fn say_step(done: usize, total: usize, ran: f64, quiet: f64) -> bool {
    let tenth = |d: usize| d * 10 / total.max(1);
    let new_tenth = done > 0 && (total < 10 || tenth(done) != tenth(done - 1));
    (ran >= SAY_AFTER_S && new_tenth) || quiet >= SAY_EVERY_S
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_are_said_at_each_tenth_once_the_stage_has_run_a_second() {
        let said = |ran| (1..=100).filter(|&d| say_step(d, 100, ran, 0.0)).count();
        assert_eq!(said(0.5), 0, "a quick stage stays quiet");
        assert_eq!(said(2.0), 10);
        let every: Vec<usize> = (1..=4).filter(|&d| say_step(d, 4, 2.0, 0.0)).collect();
        assert_eq!(every, [1, 2, 3, 4], "a short stage says every step");
        assert!(say_step(7, 100, 0.5, SAY_EVERY_S), "never silent for long");
    }

    #[test]
    fn e9_gives_the_same_results_on_one_thread_as_side_by_side() {
        let run = crate::experiments::testing::small_run();
        let e9 = |threads| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build();
            let pool = pool.expect("a thread pool");
            let mut e9 = pool
                .install(|| e9_compare(&run.prepared, &run.params, &|_| {}))
                .map_err(|e| format!("{e:?}"))
                .expect("E9 runs on the small design");
            for c in comparisons(&mut e9) {
                c.best.seconds = 0.0;
                c.results.iter_mut().for_each(|r| r.seconds = 0.0);
            }
            e9
        };
        assert_eq!(e9(1), e9(3));
    }

    /// Every comparison of `e9`.
    fn comparisons(e9: &mut E9) -> Vec<&mut Comparison> {
        let mut all = vec![&mut e9.per_speed, &mut e9.held_out];
        if let Some(Baselines::Compared {
            per_speed,
            held_out,
        }) = &mut e9.baselines
        {
            all.extend([&mut **per_speed, &mut **held_out]);
        }
        if let Some(s) = &mut e9.spiking {
            all.extend([&mut s.per_speed, &mut s.held_out]);
        }
        all
    }
}
