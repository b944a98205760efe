//! `compare`: every encoding x feature method x classifier on the same splits of a dataset,
//! ranked with 95 % intervals and a paired test against the paper's method (SA encoding,
//! 3D-GLCM, KNN); to find what suits a sensor best.

use std::path::PathBuf;
use std::time::Instant;

use super::evaluate::draws::PERTURBATION;
use super::{
    calibrated_pipeline, encode_all, say_conditions, KnnOptions, OnProgress, OpenOptions,
    SnnOptions,
};
use crate::calibrate::CalibratedParams;
use crate::classify::metrics::{chance_level, AgainstChance};
use crate::classify::{ClassifierChoice, CvParams, ForestParams};
use crate::compare::candidates::{candidates, CandidateSet, MethodChoice};
use crate::compare::signal::{
    baseline_candidates, signal_rows, SignalRows, NO_ENCODING, SIGNAL_METHODS,
};
use crate::compare::{
    compare_over_encodings, Candidate, CompareParams, Comparison, Keep, Perturbed, Protocol,
};
use crate::error::{OptionsError, ParamError};
use crate::experiments::Draws;
use crate::options::StageOptions;
use crate::pipeline::{shared_grid, Encoding, Method, Pipeline, PipelineParams};
use crate::progress::Progress;
use crate::recording::{Dataset, Recording, Selection};
use crate::signal::Conditioned;
use crate::snn::SnnParams;
use crate::values::Grid;
use crate::{Result, Speed};

/// Most candidates one run compares (encodings x methods x classifiers).
const MAX_CANDIDATES: usize = 200;

/// Options of `neurotex compare`.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct CompareOptions {
    /// The dataset folder.
    #[cfg_attr(feature = "cli", arg(long))]
    pub dataset: PathBuf,
    /// Only recordings at these speeds (mm/s, comma-separated); default all.
    #[cfg_attr(
        feature = "cli",
        arg(long, value_delimiter = ',', allow_hyphen_values = true)
    )]
    pub speeds: Option<Vec<Speed>>,
    /// Cross-validate within each value of this manifest column (each speed:
    /// `speed_mm_s`) and rank by the mean over values. Default: all recordings pooled.
    #[cfg_attr(feature = "cli", arg(long, conflicts_with_all = ["hold_out", "train_where"]))]
    pub per: Option<String>,
    /// Hold out each value of this manifest column in turn (train on the others), and rank
    /// by the mean over held-out values: `speed_mm_s` asks which method generalises to an
    /// unseen speed.
    #[cfg_attr(
        feature = "cli",
        arg(long = "hold-out", conflicts_with = "train_where")
    )]
    pub hold_out: Option<String>,
    /// Train on the recordings whose column holds one of the values (needs --test-where).
    #[cfg_attr(
        feature = "cli",
        arg(
            long = "train-where",
            value_name = "COL=V1,V2",
            requires = "test_where"
        )
    )]
    pub train_where: Option<Selection>,
    /// Test on the recordings whose column holds one of the values.
    #[cfg_attr(
        feature = "cli",
        arg(
            long = "test-where",
            value_name = "COL=V1,V2",
            requires = "train_where"
        )
    )]
    pub test_where: Option<Selection>,
    /// Folds never split a group of this manifest column; intervals and tests resample
    /// its groups.
    #[cfg_attr(feature = "cli", arg(long = "group-by"))]
    pub group_by: Option<String>,
    /// Encodings to compare, comma-separated: `sa` (the paper's slowly adapting neurons),
    /// `fa` (fast adapting, driven by the rectified rate of change), `sa+fa` (both), and
    /// `none`: the baselines without spikes, from the signal the encoder would receive
    /// (`spectrum`, its speed-normalised spectrum, and `signal-stats`, moments and
    /// quantiles per taxel, each with every classifier; --methods does not apply to
    /// them). Overrides --encoding.
    #[cfg_attr(feature = "cli", arg(long, value_delimiter = ',', default_value = crate::compare::candidates::STANDARD_ENCODINGS))]
    pub encodings: Vec<String>,
    /// Feature methods to compare, comma-separated. `taxel` is the paper's single-taxel
    /// method (each taxel alone, mean over taxels; KNN only); `van-rossum` classifies by
    /// spike-train distances (KNN only).
    /// `all-taxels-mm` (statistics per mm travelled) needs the manifest's speeds.
    /// `spectrum`: each taxel's spike counts along the slide, their Fourier magnitudes in
    /// logarithmic bands of spatial frequency. `rates`: every taxel's mean spike rate in
    /// spikes/s, the counts without their timing (with `linear`, the spiking network's
    /// baseline: what the network gains over it, it draws from the spikes' timing and its
    /// own nonlinearity). `spikes`: the spike trains themselves, classified by the spiking
    /// network (`snn`, its options --snn-*).
    #[cfg_attr(feature = "cli", arg(long, value_delimiter = ',', default_value = crate::compare::candidates::STANDARD_METHODS))]
    pub methods: Vec<String>,
    /// Classifiers to compare, comma-separated: knn, forest, linear, snn (the spiking
    /// network; it reads spike trains, so it runs with the `spikes` method only).
    #[cfg_attr(feature = "cli", arg(long, value_delimiter = ',', default_value = crate::compare::candidates::STANDARD_CLASSIFIERS))]
    pub classifiers: Vec<String>,
    /// Time constant of the van Rossum kernel in ms (method `van-rossum`). Default: the
    /// rate volume's 200 ms bin, the time resolution the paper's rate code keeps.
    #[cfg_attr(feature = "cli", arg(long = "tau-ms", default_value_t = crate::compare::candidates::STANDARD_TAU_MS))]
    pub tau_ms: f64,
    /// KNN's neighbours and z-scoring.
    #[cfg_attr(feature = "cli", command(flatten))]
    pub knn: KnnOptions,
    /// The spiking network's options (method `spikes`); its seed is --seed unless
    /// --snn-seed is given.
    #[cfg_attr(feature = "cli", command(flatten))]
    pub snn: SnnOptions,
    /// Cross-validation folds.
    #[cfg_attr(feature = "cli", arg(long, default_value_t = crate::classify::CvParams::default().folds))]
    pub folds: usize,
    /// Cross-validation repeats (every candidate gets the same folds in each); the
    /// default is `evaluate`'s, so a candidate scores here as `evaluate` scores it.
    #[cfg_attr(feature = "cli", arg(long, default_value_t = crate::classify::CvParams::default().repeats))]
    pub repeats: usize,
    /// Seed of the folds, the bootstrap and the sign-flip test.
    #[cfg_attr(feature = "cli", arg(long, default_value_t = 0))]
    pub seed: u64,
    /// Also estimate the accuracy of choosing the best candidate inside each training set
    /// (nested selection, on the first repeat's folds): the number to quote for "the best
    /// method".
    #[cfg_attr(feature = "cli", arg(long))]
    pub nested: bool,
    /// With --nested: rank the candidates inside each outer training set by a
    /// cross-validation of this many folds of its own (fewer where a class there has fewer
    /// recordings; under --hold-out, only where a training set holds one value of the
    /// column). Default: each of the other outer folds held out in turn (--folds minus 1
    /// inner folds; each inner fit serves two outer training sets, so it is made once), or
    /// with fewer than 4 folds, --folds folds of its own. Fewer folds rank on smaller
    /// training sets: quicker, but the choice can be worse, and the nested estimate with it
    /// (docs/methods-and-compare.md).
    #[cfg_attr(feature = "cli", arg(long = "inner-folds", requires = "nested"))]
    pub inner_folds: Option<usize>,
    /// Encodings of every recording: the input as run, then N - 1 more with each of its
    /// conditioned samples times 1 + u x 1e-12 (u uniform in [-1, 1), a stream per seed,
    /// encoding and recording), every candidate that reads spikes scored on each under the
    /// same splits. Each such candidate then also gets its accuracy over the encodings,
    /// with an interval that draws an encoding as well as the recordings: spiking neurons
    /// turn rounding-level input changes into moved spikes, which can move an accuracy, and
    /// a ranking's order, by several points. The ranking, its paired tests and nested
    /// selection stay those of the encoding as run. Costs N times the encoding and the
    /// scoring of the spike candidates; 1 (the default) encodes the input as run only.
    #[cfg_attr(feature = "cli", arg(long = "encoder-draws", default_value_t = 1))]
    pub encoder_draws: usize,
    /// How the dataset folder is opened.
    #[cfg_attr(feature = "cli", command(flatten))]
    pub open: OpenOptions,
}

impl CompareOptions {
    fn protocol(&self) -> Protocol {
        match (
            &self.per,
            &self.hold_out,
            &self.train_where,
            &self.test_where,
        ) {
            (Some(column), ..) => Protocol::Per(column.clone()),
            (_, Some(column), ..) => Protocol::HoldOut(column.clone()),
            (_, _, Some(train), Some(test)) => Protocol::Where {
                train: train.clone(),
                test: test.clone(),
            },
            _ => Protocol::Pooled,
        }
    }

    fn params(&self) -> Result<CompareParams> {
        let cv = CvParams {
            folds: self.folds,
            seed: self.seed,
            repeats: self.repeats,
        }
        .check()?;
        Ok(CompareParams {
            protocol: self.protocol(),
            cv,
            group_by: self.group_by.clone(),
            resamples: 2000,
            nested: self.nested,
            inner_folds: self.inner_folds,
        })
    }

    /// The recordings compared: those at `--speeds`, or both sides of a train/test split.
    fn indices(&self, dataset: &Dataset) -> Result<Vec<usize>> {
        let entries = &dataset.entries;
        let mut rows = match &self.speeds {
            Some(speeds) => dataset.indices_at(speeds)?,
            None => (0..entries.len()).collect(),
        };
        if let (Some(train), Some(test)) = (&self.train_where, &self.test_where) {
            let (train, test) = (train.rows(entries)?, test.rows(entries)?);
            rows.retain(|i| train.contains(i) || test.contains(i));
        }
        if rows.is_empty() {
            return Err(OptionsError::Conflict("no recordings to compare".into()).into());
        }
        Ok(rows)
    }

    /// The candidates to compare, checked: between 1 and [`MAX_CANDIDATES`].
    fn set(&self) -> Result<CandidateSet> {
        let methods = self
            .methods
            .iter()
            .map(|m| m.parse::<MethodChoice>())
            .collect::<Result<Vec<_>, _>>()?;
        let snn = ClassifierChoice::Snn(self.snn.params(SnnParams {
            seed: self.seed,
            ..SnnParams::default()
        })?);
        let mut classifiers = self
            .classifiers
            .iter()
            .map(|name| {
                Ok(match name.parse::<ClassifierChoice>()? {
                    ClassifierChoice::Knn(_) => ClassifierChoice::Knn(self.knn.params()?),
                    ClassifierChoice::Forest(p) => ClassifierChoice::Forest(ForestParams {
                        seed: self.seed,
                        ..p
                    }),
                    ClassifierChoice::Snn(_) => snn,
                    linear => linear,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let has_snn = classifiers.contains(&snn);
        match (methods.contains(&MethodChoice::Spikes), has_snn) {
            (true, false) => classifiers.push(snn),
            (false, true) => {
                let rule = "the snn classifier reads spike trains: add spikes to --methods";
                return Err(ParamError::new("classifiers", rule, "snn").into());
            }
            // The network's options with no network to run: refused, as `evaluate` does.
            (false, false) if !self.snn.knobs.is_empty() => {
                let (spec, _) = self.snn.knobs[0];
                let applies_to = "the spiking network (`spikes` in --methods, which adds `snn` to --classifiers)";
                return Err(OptionsError::NotApplicable {
                    option: spec.flag,
                    applies_to,
                }
                .into());
            }
            _ => {}
        }
        let baselines = self.encodings.iter().any(|e| e.trim() == NO_ENCODING);
        let encodings = self
            .encodings
            .iter()
            .filter(|e| e.trim() != NO_ENCODING)
            .map(|e| e.parse::<Encoding>())
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| {
                let rule = "encodings must be sa, fa, sa+fa or none (the baselines without spikes)";
                ParamError::new("encodings", rule, e.got)
            })?;
        let set = CandidateSet {
            encodings,
            methods,
            classifiers,
            tau_ms: self.tau_ms,
            baselines,
        };
        let n = set.len();
        if n == 0 || n > MAX_CANDIDATES {
            return Err(OptionsError::Conflict(format!(
                "{n} candidates to compare; between 1 and {MAX_CANDIDATES} are allowed"
            ))
            .into());
        }
        Ok(set)
    }

    /// Compares the candidates on `dataset` with the stage options `stages`.
    ///
    /// # Errors
    /// Options out of range or that do not go together, recordings that cannot be read,
    /// or a design too small for the protocol.
    pub fn run(
        &self,
        dataset: &Dataset,
        stages: &StageOptions,
        on: OnProgress,
    ) -> Result<Comparison> {
        self.run_keeping(dataset, stages, on, None)
    }

    /// [`CompareOptions::run`], taking the finished pieces `keep` holds (from the same
    /// comparison stopped part way) and keeping the others there.
    ///
    /// # Errors
    /// As [`CompareOptions::run`], or a piece that cannot be kept.
    pub fn run_keeping(
        &self,
        dataset: &Dataset,
        stages: &StageOptions,
        on: OnProgress,
        keep: Option<&dyn Keep>,
    ) -> Result<Comparison> {
        let params = self.params()?;
        super::evaluate::draws::check(self.encoder_draws, dataset)?;
        let indices = self.indices(dataset)?;
        let metas: Vec<_> = indices
            .iter()
            .map(|&i| dataset.entries[i].clone())
            .collect();
        crate::compare::check_design(&metas, &params)?;
        let set = self.set()?;
        let train = match (&self.train_where, &self.test_where) {
            (Some(train), Some(_)) => Some(train),
            _ => None,
        };
        let calibration = super::calibration_rows(train, dataset, &indices, stages, on)?;
        let (candidates, calibrated) =
            make_candidates(stages, dataset, &indices, &calibration, &set, on)?;
        on(Progress::Say(&format!(
            "comparing {} candidates on {} recordings: {}",
            candidates.len(),
            indices.len(),
            params.protocol
        )));
        let snn = set
            .classifiers
            .iter()
            .find(|c| matches!(c, ClassifierChoice::Snn(_)));
        let snn = snn.filter(|_| set.methods.contains(&MethodChoice::Spikes));
        let snn = snn.map(|snn| self.snn.described(snn));
        if let Some(snn) = &snn {
            on(Progress::Say(&format!("snn: {snn}")));
        }
        let capped = stages.overshoot == crate::encode::Overshoot::Capped;
        if capped {
            on(Progress::Say("encoder: the overshoot capped at the 30 mV peak (--overshoot capped), not Izhikevich's reference scheme"));
        }
        let speeds = Speed::distinct(indices.iter().filter_map(|&i| dataset.entries[i].speed()));
        if matches!(params.protocol, Protocol::Pooled) && speeds.len() > 1 {
            on(Progress::Say(&format!(
                "note: recordings at {} speeds are cross-validated together, so each texture's features vary with speed as well; --per speed_mm_s compares within each speed (as the paper does), --hold-out speed_mm_s on speeds not trained on",
                speeds.len()
            )));
        }
        let draws = (self.encoder_draws, self.seed);
        let further = perturbed_candidates(&calibrated.params, dataset, &indices, &set, draws, on)?;
        let perturbed = Perturbed {
            candidates: &further,
            size: PERTURBATION,
        };
        let mut comparison = compare_over_encodings(&candidates, perturbed, &params, on, keep)?;
        // The network's settings go with the ranking (compare.md and compare.json), as the
        // folds and seed do.
        if let Some(snn) = &snn {
            comparison.design = format!("{}; snn: {snn}", comparison.design);
        }
        if capped {
            comparison.design = format!("{}; encoder overshoot capped", comparison.design);
        }
        comparison.provenance = provenance(dataset, &indices, &set, &calibrated, train.is_some())?;
        if let Some(note) = under_chance_note(&comparison, &params.protocol) {
            on(Progress::Advice(&note));
            comparison.notes.push(note);
        }
        if !params.nested {
            on(Progress::Say(
                "note: the nested estimate the caveat below speaks of was not computed (add --nested)",
            ));
        }
        Ok(comparison)
    }
}

/// The note for candidates whose whole interval lies under chance, one over the classes:
/// `None` when there are none. Recordings cannot teach a classifier to be wrong, so such
/// scores come from the design, and a ranking or a paired test among them says nothing of
/// the recordings. (Under the largest class's share alone, a classifier may still carry
/// what the recordings hold: it need not answer by the classes' shares.)
fn under_chance_note(c: &Comparison, protocol: &Protocol) -> Option<String> {
    let (level, words) = chance_level(c.classes, 0.0);
    let below = Some(AgainstChance::Below);
    let under = c
        .results
        .iter()
        .filter(|r| AgainstChance::of(r.ci, level) == below);
    let under = under.count();
    if under == 0 {
        return None;
    }
    let held_out = match protocol {
        Protocol::HoldOut(_) => {
            "; with a condition held out, so do features that change with the condition"
        }
        _ => "",
    };
    Some(format!(
        "{under} of {} candidates score under chance ({words}) over their whole 95 % interval: such scores come from the design, not from the recordings (labels the recordings do not carry score under chance in cross-validation, each test fold holding more of the classes its training folds hold less of{held_out}), so their ranks and their differences from the paper's method say nothing of the recordings",
        c.results.len()
    ))
}

/// Where a comparison of `set` on the recordings `indices` of `dataset` comes from:
/// neurotex's build, the time, the data and the stages as `calibrated` ran them, the
/// settings of the encodings, methods and classifiers compared only
/// ([`Comparison::provenance`]);
/// `split` whether the gain was calibrated on a training side alone.
///
/// # Errors
/// The manifest or a listed file can no longer be read for the fingerprint.
fn provenance(
    dataset: &Dataset,
    indices: &[usize],
    set: &CandidateSet,
    calibrated: &CalibratedParams,
    split: bool,
) -> Result<Vec<String>> {
    let metas: Vec<_> = indices
        .iter()
        .map(|&i| dataset.entries[i].clone())
        .collect();
    let mut lines = vec![
        crate::experiments::build(),
        format!("created: {}", crate::experiments::now_utc()),
        super::data_line(dataset)?,
    ];
    let p = &calibrated.params;
    lines.extend(p.conditioning_lines(
        dataset.layout.baseline,
        crate::experiments::slide_times(&metas),
    ));
    let classifiers: Vec<String> = set.classifiers.iter().map(|c| c.to_string()).collect();
    let classifiers = format!("classifiers: {}", classifiers.join("; "));
    if set.encodings.is_empty() {
        lines.push("encodings: none (the signal baselines, without spikes)".into());
        lines.push(classifiers);
        return Ok(lines);
    }
    lines.push(p.encoder_line());
    if let Some(c) = &calibrated.gain {
        lines.push(super::calibration_provenance(c, split));
    }
    let names: Vec<String> = set.encodings.iter().map(|e| e.to_string()).collect();
    let fa = match set.needs_fa() {
        true => format!("; FA gain {}", p.fa.gain),
        false => String::new(),
    };
    let baselines = match set.baselines {
        true => ", and none (the signal baselines)",
        false => "",
    };
    lines.push(format!("encodings: {}{fa}{baselines}", names.join(", ")));
    lines.push(p.volume_line());
    let methods: Vec<Method> = set
        .methods
        .iter()
        .filter_map(|m| match m {
            MethodChoice::Features(m) => Some(*m),
            _ => None,
        })
        .collect();
    lines.extend(p.feature_lines(&methods));
    lines.push(classifiers);
    Ok(lines)
}

/// The candidates of `set` that read spikes, made from each further encoding of the
/// recordings `indices` (`encodings` of them, the one as run the caller's; the others'
/// conditioned input perturbed by [`PERTURBATION`] from streams of `seed`): none with one
/// encoding or no spike encodings.
///
/// # Errors
/// A recording that cannot be read or encoded, or a feature table that cannot be made.
fn perturbed_candidates(
    params: &PipelineParams,
    dataset: &Dataset,
    indices: &[usize],
    set: &CandidateSet,
    (encodings, seed): (usize, u64),
    on: OnProgress,
) -> Result<Vec<Vec<Candidate>>> {
    if encodings < 2 || set.encodings.is_empty() {
        return Ok(Vec::new());
    }
    let draws = Draws {
        encodings,
        seed,
        size: PERTURBATION,
    };
    let start = Instant::now();
    let pipeline = Pipeline::new(params.clone())?;
    let per_draw = super::evaluate::draws::perturbed(dataset, &pipeline, indices, draws, on)?;
    let encode_s = start.elapsed().as_secs_f64() / per_draw.len() as f64;
    let set = CandidateSet {
        baselines: false,
        ..set.clone()
    };
    per_draw
        .iter()
        .map(|encoded| candidates(encoded, &shared_grid(encoded)?, params, &set, encode_s))
        .collect()
}

/// Encodes the recordings `indices` once (both populations when an encoding needs the
/// fast-adapting one), with the pipeline calibrated on the recordings `calibration`, and
/// makes every candidate of `set` from them; returns them and the calibrated pipeline.
fn make_candidates(
    stages: &StageOptions,
    dataset: &Dataset,
    indices: &[usize],
    calibration: &[usize],
    set: &CandidateSet,
    on: OnProgress,
) -> Result<(Vec<Candidate>, CalibratedParams)> {
    let start = Instant::now();
    let mut calibrated = calibrated_pipeline(stages, dataset, calibration, on)?;
    calibrated.params.encoding = if set.needs_fa() {
        Encoding::SaFa
    } else {
        Encoding::Sa
    };
    let made = candidates_with(&calibrated.params, dataset, indices, set, on, start)?;
    Ok((made, calibrated))
}

/// The candidates of `set` on the recordings `indices` with the pipeline `params`, whose
/// making began at `start`.
fn candidates_with(
    params: &PipelineParams,
    dataset: &Dataset,
    indices: &[usize],
    set: &CandidateSet,
    on: OnProgress,
    start: Instant,
) -> Result<Vec<Candidate>> {
    let pipeline = Pipeline::new(params.clone())?;
    let tick = || on(Progress::Tick);
    let features = &params.features;
    if set.encodings.is_empty() {
        // The baselines alone: conditioning without encoding.
        on(Progress::Stage("conditioning", indices.len()));
        let rows = signal_rows(dataset, &pipeline, indices, &tick)?;
        let first = dataset.load(indices[0])?.layout;
        let grid = Grid::masked(first.rows, first.cols, first.present)?;
        let share = start.elapsed().as_secs_f64() / SIGNAL_METHODS.len() as f64;
        return baseline_candidates(&rows, &grid, features, &set.classifiers, share);
    }
    let (encoded, rows) = if set.baselines {
        // One pass: the baselines' rows from the signal each recording is encoded from.
        on(Progress::Stage("encoding", indices.len()));
        let also = |rec: &Recording, cond: &Conditioned| SignalRows::of(rec, cond, features);
        let pairs = pipeline.encode_dataset_with(dataset, indices, &tick, &also)?;
        let (encoded, rows): (Vec<_>, Vec<_>) = pairs.into_iter().unzip();
        say_conditions(&encoded, on);
        (encoded, rows)
    } else {
        (encode_all(dataset, &pipeline, indices, on)?.0, Vec::new())
    };
    let grid = shared_grid(&encoded)?;
    let encode_s = start.elapsed().as_secs_f64();
    let mut out = candidates(&encoded, &grid, params, set, encode_s)?;
    if set.baselines {
        let share = encode_s / (set.encodings.len() + 1) as f64;
        out.extend(baseline_candidates(
            &rows,
            &grid,
            features,
            &set.classifiers,
            share,
        )?);
    }
    Ok(out)
}
