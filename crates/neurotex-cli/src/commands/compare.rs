//! `neurotex compare`: every encoding x feature method x classifier on the same splits of a
//! dataset, ranked with 95 % intervals and a paired test against the paper's method
//! (SA encoding, 3D-GLCM, KNN); to find what suits a sensor best.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use clap::Args;
use neurotex::classify::{ClassifierChoice, CvParams, ForestParams};
use neurotex::compare::candidates::{
    candidates, CandidateSet, MethodChoice, STANDARD_CLASSIFIERS, STANDARD_ENCODINGS,
    STANDARD_METHODS, STANDARD_TAU_MS,
};
use neurotex::compare::{compare_with_progress, Candidate, CompareParams, Protocol};
use neurotex::pipeline::{Encoding, Pipeline};
use neurotex::progress::Progress;
use neurotex::recording::{Dataset, Selection};
use neurotex::report::comparison::{text_lines, write_comparison};
use neurotex::Speed;

use super::{calibrated_pipeline, encode_all};
use crate::open_args::OpenArgs;
use crate::output::{progress, show_progress};
use crate::stage_args::StageArgs;

/// Most candidates one run compares (encodings x methods x classifiers).
const MAX_CANDIDATES: usize = 200;

/// Options of `neurotex compare`.
#[derive(Args)]
pub struct CompareArgs {
    /// The dataset folder.
    #[arg(long)]
    pub dataset: PathBuf,
    /// Only recordings at these speeds (mm/s, comma-separated); default all.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub speeds: Option<Vec<Speed>>,
    /// Cross-validate within each value of this manifest column (each speed:
    /// `speed_mm_s`) and rank by the mean over values. Default: all recordings pooled.
    #[arg(long, conflicts_with_all = ["hold_out", "train_where"])]
    pub per: Option<String>,
    /// Hold out each value of this manifest column in turn (train on the others), and rank
    /// by the mean over held-out values: `speed_mm_s` asks which method generalises to an
    /// unseen speed.
    #[arg(long = "hold-out", conflicts_with = "train_where")]
    pub hold_out: Option<String>,
    /// Train on the recordings whose column holds one of the values (needs --test-where).
    #[arg(
        long = "train-where",
        value_name = "COL=V1,V2",
        requires = "test_where"
    )]
    pub train_where: Option<Selection>,
    /// Test on the recordings whose column holds one of the values.
    #[arg(
        long = "test-where",
        value_name = "COL=V1,V2",
        requires = "train_where"
    )]
    pub test_where: Option<Selection>,
    /// Folds never split a group of this manifest column; intervals and tests resample
    /// its groups.
    #[arg(long = "group-by")]
    pub group_by: Option<String>,
    /// Encodings to compare, comma-separated: `sa` (the paper's slowly adapting neurons),
    /// `fa` (fast adapting, driven by the rectified rate of change), `sa+fa` (both).
    /// Overrides --encoding.
    #[arg(long, value_delimiter = ',', default_value = STANDARD_ENCODINGS)]
    pub encodings: Vec<Encoding>,
    /// Feature methods to compare, comma-separated. `taxel` is the paper's single-taxel
    /// method (each taxel alone, mean over taxels; KNN only); `van-rossum` classifies by
    /// spike-train distances (KNN only).
    /// `all-taxels-mm` (statistics per mm travelled) needs the manifest's speeds.
    #[arg(long, value_delimiter = ',', default_value = STANDARD_METHODS)]
    pub methods: Vec<String>,
    /// Classifiers to compare, comma-separated: knn, forest, linear.
    #[arg(long, value_delimiter = ',', default_value = STANDARD_CLASSIFIERS)]
    pub classifiers: Vec<String>,
    /// Time constant of the van Rossum kernel in ms (method `van-rossum`). Default: the
    /// rate volume's 200 ms bin, the time resolution the paper's rate code keeps.
    #[arg(long = "tau-ms", default_value_t = STANDARD_TAU_MS)]
    pub tau_ms: f64,
    /// Neighbours in KNN.
    #[arg(long, default_value_t = neurotex::classify::KnnParams::default().k)]
    pub k: usize,
    /// Cross-validation folds.
    #[arg(long, default_value_t = neurotex::classify::CvParams::default().folds)]
    pub folds: usize,
    /// Cross-validation repeats (every candidate gets the same folds in each).
    #[arg(long, default_value_t = 2)]
    pub repeats: usize,
    /// Seed of the folds, the bootstrap and the sign-flip test.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Also estimate the accuracy of choosing the best candidate inside each training set
    /// (nested selection): the number to quote for "the best method".
    #[arg(long)]
    pub nested: bool,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// Also write compare.json, compare.md and the figures into this folder.
    #[arg(long)]
    pub out: Option<PathBuf>,
    #[command(flatten)]
    pub stages: StageArgs,
    #[command(flatten)]
    pub open: OpenArgs,
}

impl CompareArgs {
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
            bail!("no recordings to compare");
        }
        Ok(rows)
    }

    /// The candidates to compare, checked.
    fn set(&self) -> Result<CandidateSet> {
        let methods = self
            .methods
            .iter()
            .map(|m| m.parse::<MethodChoice>())
            .collect::<Result<Vec<_>, _>>()?;
        let classifiers = self
            .classifiers
            .iter()
            .map(|name| {
                Ok(match name.parse::<ClassifierChoice>()? {
                    ClassifierChoice::Knn(_) => ClassifierChoice::Knn(self.stages.knn(self.k)?),
                    ClassifierChoice::Forest(p) => ClassifierChoice::Forest(ForestParams {
                        seed: self.seed,
                        ..p
                    }),
                    linear => linear,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(CandidateSet {
            encodings: self.encodings.clone(),
            methods,
            classifiers,
            tau_ms: self.tau_ms,
        })
    }
}

/// Runs `neurotex compare`.
pub fn run(args: CompareArgs) -> Result<()> {
    let params = args.params()?;
    let dataset = args.open.open(&args.dataset)?;
    let _claim = match &args.out {
        Some(dir) => {
            Some(neurotex::io::claim_output_dir(dir).context("checking the output folder")?)
        }
        None => None,
    };
    let indices = args.indices(&dataset)?;
    let set = args.set()?;
    let n = set.len();
    if n == 0 || n > MAX_CANDIDATES {
        bail!("{n} candidates to compare; between 1 and {MAX_CANDIDATES} are allowed");
    }
    let candidates = make_candidates(&args, &dataset, &indices, &set)?;
    eprintln!(
        "comparing {} candidates on {} recordings: {}",
        candidates.len(),
        indices.len(),
        params.protocol
    );
    let bar = progress(0, "candidates");
    let on_progress = |p: Progress| show_progress(&bar, p);
    let comparison = compare_with_progress(&candidates, &params, &on_progress)?;
    bar.finish_and_clear();
    if !params.nested {
        eprintln!("note: --nested computes the nested estimate the caveat below speaks of");
    }
    if let Some(dir) = &args.out {
        write_comparison(dir, &comparison, &args.dataset).context("writing the comparison")?;
        eprintln!("wrote {}", dir.display());
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&comparison)?);
    } else {
        for line in text_lines(&comparison) {
            println!("{line}");
        }
    }
    Ok(())
}

/// Encodes the recordings once (both populations when an encoding needs the fast-adapting
/// one) and makes every candidate of `set` from them.
fn make_candidates(
    args: &CompareArgs,
    dataset: &Dataset,
    indices: &[usize],
    set: &CandidateSet,
) -> Result<Vec<Candidate>> {
    let start = Instant::now();
    let mut params = calibrated_pipeline(&args.stages, dataset, indices)?.params;
    params.encoding = if set.needs_fa() {
        Encoding::SaFa
    } else {
        Encoding::Sa
    };
    let pipeline = Pipeline::new(params.clone())?;
    let (encoded, grid) = encode_all(dataset, &pipeline, indices)?;
    let encode_s = start.elapsed().as_secs_f64();
    Ok(candidates(&encoded, &grid, &params, set, encode_s)?)
}
