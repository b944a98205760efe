//! The subcommands: each parses its options into library parameters, runs the library and
//! writes or prints the result.

use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use clap::Args;
use neurotex::analysis::{evaluate as run_evaluation, Columns, FeatureTable, Outcome, Split};
use neurotex::classify::CvParams;
use neurotex::pipeline::{Encoded, Method, Pipeline};
use neurotex::recording::{read_recording, same_speed, Dataset, LayoutFile};
use neurotex::Speed;

use crate::output::{progress, write_atomic};
use crate::stage_args::StageArgs;

/// Options of `neurotex encode`.
#[derive(Args)]
pub struct EncodeArgs {
    /// The recording: `.npy` (f32/f64, `(T, rows, cols)` or `(T, channels)`) or `.csv`
    /// (header row, optional `t_ms`/`t_s` time column, one column per channel).
    pub input: PathBuf,
    /// Where to write the spikes: u8 `.npy` of shape `(T, rows, cols)` at 1 kHz.
    #[arg(long)]
    pub out: PathBuf,
    /// Sampling rate of the input in Hz (default: the layout's, else 1000; ignored when the
    /// CSV has a time column).
    #[arg(long, allow_negative_numbers = true)]
    pub fs: Option<f64>,
    /// A `layout.toml` giving grid, channel map, mask or baseline for the input.
    #[arg(long)]
    pub layout: Option<PathBuf>,
    /// Also write the spikes as address events `t_ms,row,col` to this CSV file.
    #[arg(long)]
    pub events: Option<PathBuf>,
    #[command(flatten)]
    pub stages: StageArgs,
}

/// Options of `neurotex features`.
#[derive(Args)]
pub struct FeaturesArgs {
    /// The dataset folder (with `manifest.csv`, optional `layout.toml`).
    #[arg(long)]
    pub dataset: PathBuf,
    /// Feature set: `taxel` (MSR, CV_ISI, Fano of every taxel), `glcm2d` or `glcm3d`
    /// (contrast, correlation, ASM).
    #[arg(long)]
    pub method: Method,
    /// The CSV file to write: `file,label,speed_mm_s,trial` then the features.
    #[arg(long)]
    pub out: PathBuf,
    #[command(flatten)]
    pub stages: StageArgs,
}

/// Options of `neurotex evaluate`.
#[derive(Args)]
pub struct EvaluateArgs {
    /// The dataset folder.
    #[arg(long)]
    pub dataset: PathBuf,
    /// Feature set: `taxel`, `glcm2d` or `glcm3d`.
    #[arg(long)]
    pub method: Method,
    /// With `--method taxel`: the taxel to use, as `ROW,COL`. Without it every taxel is
    /// evaluated and the mean over taxels is reported, with the best beside it.
    #[arg(long)]
    pub taxel: Option<String>,
    /// Neighbours in KNN.
    #[arg(long, default_value_t = 5)]
    pub k: usize,
    /// Cross-validation folds (stratified, shuffled).
    #[arg(long, default_value_t = 5)]
    pub folds: usize,
    /// Seed of the fold shuffle (repeat r uses seed + r).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Cross-validation repeats with different shuffles.
    #[arg(long, default_value_t = 1)]
    pub repeats: usize,
    /// Only recordings at these speeds (mm/s, comma-separated); default all.
    #[arg(
        long,
        value_delimiter = ',',
        allow_hyphen_values = true,
        conflicts_with = "train_speeds"
    )]
    pub speeds: Option<Vec<f64>>,
    /// Train on these speeds instead of cross-validating (needs --test-speeds).
    #[arg(
        long = "train-speeds",
        value_delimiter = ',',
        allow_hyphen_values = true,
        requires = "test_speeds"
    )]
    pub train_speeds: Option<Vec<f64>>,
    /// Test on these speeds (needs --train-speeds).
    #[arg(
        long = "test-speeds",
        value_delimiter = ',',
        allow_hyphen_values = true,
        requires = "train_speeds"
    )]
    pub test_speeds: Option<Vec<f64>>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub stages: StageArgs,
}

/// Options of `neurotex simulate`.
#[derive(Args)]
pub struct SimulateArgs {
    /// The dataset folder to create (must not exist, or be empty).
    #[arg(long)]
    pub out: PathBuf,
    /// Seed of every random draw: the same seed gives the same bits.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Trials per texture and speed (paper: 20).
    #[arg(long, default_value_t = 20)]
    pub trials: u32,
    /// Sliding speeds in mm/s (paper: 5, 10, 15).
    #[arg(long, value_delimiter = ',', default_value = "5,10,15")]
    pub speeds: Vec<f64>,
    /// Textures, by the paper's names: FT1, FT2, FT3, RT, TRug, SB, CP, STF (default all).
    #[arg(long, value_delimiter = ',')]
    pub textures: Option<Vec<String>>,
}

/// Parses texture names, naming the unknown one.
pub fn parse_textures(names: Option<&[String]>) -> Result<Vec<neurotex::sim::Texture>> {
    use neurotex::sim::{Texture, ALL_TEXTURES};
    match names {
        None => Ok(ALL_TEXTURES.to_vec()),
        Some(names) => names
            .iter()
            .map(|n| {
                Texture::from_name(n.trim()).with_context(|| {
                    format!(
                        "unknown texture `{n}`: expected FT1, FT2, FT3, RT, TRug, SB, CP or STF"
                    )
                })
            })
            .collect(),
    }
}

pub fn simulate(args: SimulateArgs) -> Result<()> {
    use neurotex::sim::{design, write_dataset, RigParams};
    let textures = parse_textures(args.textures.as_deref())?;
    if args.trials == 0 {
        bail!("--trials must be at least 1");
    }
    if let Some(s) = args.speeds.iter().find(|s| !(s.is_finite() && **s > 0.0)) {
        bail!("--speeds must be positive mm/s, got {s}");
    }
    let trials = design(&textures, &args.speeds, args.trials);
    let bar = progress(trials.len(), "simulating");
    let result = write_dataset(
        &args.out,
        &RigParams::default(),
        &trials,
        args.seed,
        &|| bar.inc(1),
    );
    bar.finish_and_clear();
    result?;
    eprintln!("{} recordings -> {}", trials.len(), args.out.display());
    Ok(())
}

pub fn encode(args: EncodeArgs) -> Result<()> {
    let params = args.stages.pipeline()?;
    let mut layout = match &args.layout {
        Some(path) => LayoutFile::read(path)?,
        None => LayoutFile::default(),
    };
    if let Some(fs) = args.fs {
        if !(fs.is_finite() && fs > 0.0) {
            bail!("--fs must be a positive sampling rate in Hz, got {fs}");
        }
        layout.fs = Some(fs);
    }
    let rec = read_recording(&args.input, &layout)?;
    let pipeline = Pipeline::new(params)?;
    let encoded = pipeline.encode(&rec, layout.baseline.unwrap_or_default())?;
    report_conditions(std::slice::from_ref(&encoded));
    let spikes = &encoded.spikes;
    let raster = ndarray::Array3::from_shape_vec(
        (spikes.n_steps, spikes.rows, spikes.cols),
        spikes.to_raster(),
    )?;
    if let Some(events) = &args.events {
        write_atomic(events, |w| {
            writeln!(w, "t_ms,row,col")?;
            for (t, r, c) in spikes.events() {
                writeln!(w, "{t},{r},{c}")?;
            }
            Ok(())
        })?;
    }
    write_atomic(&args.out, |w| {
        ndarray_npy::WriteNpyExt::write_npy(&raster, w).context("writing .npy")?;
        Ok(())
    })?;
    eprintln!(
        "{} spikes from {} taxels over {} ms -> {}",
        spikes.total_spikes(),
        spikes.present.iter().filter(|&&p| p).count(),
        spikes.n_steps,
        args.out.display()
    );
    Ok(())
}

/// Opens the dataset and encodes the recordings at `indices` with a progress bar.
fn encode_selected(
    dataset: &Dataset,
    pipeline: &Pipeline,
    indices: &[usize],
) -> Result<Vec<Encoded>> {
    let bar = progress(indices.len(), "encoding");
    let encoded = pipeline.encode_dataset(dataset, indices, &|| bar.inc(1));
    bar.finish_and_clear();
    let encoded = encoded?;
    report_conditions(&encoded);
    Ok(encoded)
}

/// Says on standard error what conditioning did that the user should know.
fn report_conditions(encoded: &[Encoded]) {
    let resampled = encoded.iter().filter(|e| e.resampled).count();
    if resampled > 0 {
        eprintln!("note: {resampled} recording(s) resampled to the encoder's 1 kHz by linear interpolation");
    }
    for e in encoded.iter().filter(|e| e.flat) {
        eprintln!(
            "warning: {}: no positive signal in the selected phase; left at zero (no spikes)",
            e.meta.file
        );
    }
}

/// Encodes the recordings at `indices` and extracts `method`'s features; also returns the
/// grid (present cells, columns) of the first recording.
fn feature_table(
    dataset: &Dataset,
    pipeline: &Pipeline,
    indices: &[usize],
    method: Method,
) -> Result<(FeatureTable, Vec<bool>, usize)> {
    let encoded = encode_selected(dataset, pipeline, indices)?;
    let first = &encoded[0].spikes;
    if let Some(other) = encoded.iter().find(|e| e.spikes.present != first.present) {
        bail!(
            "{}: its taxel grid differs from that of {}; a dataset needs one layout",
            other.meta.file,
            encoded[0].meta.file
        );
    }
    let extractor = pipeline.extractor(&first.grid())?;
    let table = FeatureTable::build(&encoded, &extractor, method)?;
    Ok((table, first.present.clone(), first.cols))
}

pub fn features(args: FeaturesArgs) -> Result<()> {
    let pipeline = Pipeline::new(args.stages.pipeline()?)?;
    let dataset = Dataset::open(&args.dataset)?;
    let all: Vec<usize> = (0..dataset.entries.len()).collect();
    let (table, _, _) = feature_table(&dataset, &pipeline, &all, args.method)?;
    write_atomic(&args.out, |w| {
        let mut out = csv::Writer::from_writer(w);
        let mut header = vec![
            "file".to_string(),
            "label".into(),
            "speed_mm_s".into(),
            "trial".into(),
        ];
        header.extend(table.names.iter().cloned());
        out.write_record(&header)?;
        for (i, m) in table.metas.iter().enumerate() {
            let mut rec = vec![
                m.file.clone(),
                m.label.clone(),
                m.speed_mm_s.to_string(),
                m.trial.to_string(),
            ];
            rec.extend(table.row(i).iter().map(|v| v.to_string()));
            out.write_record(&rec)?;
        }
        out.flush()?;
        Ok(())
    })?;
    eprintln!(
        "{} recordings x {} features -> {}",
        table.metas.len(),
        table.dims(),
        args.out.display()
    );
    Ok(())
}

fn parse_taxel(text: &str) -> Result<(usize, usize)> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    match parts.as_slice() {
        [r, c] => match (r.parse(), c.parse()) {
            (Ok(r), Ok(c)) => Ok((r, c)),
            _ => bail!("--taxel must be ROW,COL with non-negative integers, got `{text}`"),
        },
        _ => bail!("--taxel must be ROW,COL, got `{text}`"),
    }
}

pub fn evaluate(args: EvaluateArgs) -> Result<()> {
    let pipeline = Pipeline::new(args.stages.pipeline()?)?;
    let knn = args.stages.knn(args.k)?;
    let cv = CvParams {
        folds: args.folds,
        seed: args.seed,
        repeats: args.repeats,
    }
    .check()?;
    let columns = match (args.method, &args.taxel) {
        (Method::Taxel, Some(t)) => {
            let (row, col) = parse_taxel(t)?;
            Columns::Taxel(neurotex::Cell { row, col })
        }
        (Method::Taxel, None) => Columns::EachTaxel,
        (_, Some(_)) => bail!("--taxel applies only to --method taxel"),
        (_, None) => Columns::All,
    };
    let dataset = Dataset::open(&args.dataset)?;
    let split = match (&args.train_speeds, &args.test_speeds) {
        (Some(train), Some(test)) => Split::ByCondition {
            train: train.iter().map(|&s| Speed::of(s)).collect(),
            test: test.iter().map(|&s| Speed::of(s)).collect(),
        },
        _ => Split::CrossValidation {
            speeds: args
                .speeds
                .as_ref()
                .map(|s| s.iter().map(|&s| Speed::of(s)).collect()),
            cv,
        },
    };
    let wanted: Vec<f64> = match &split {
        Split::CrossValidation {
            speeds: Some(s), ..
        } => s.iter().map(|s| s.mm_s()).collect(),
        Split::CrossValidation { speeds: None, .. } => dataset.speeds(),
        Split::ByCondition { train, test } => train.iter().chain(test).map(|s| s.mm_s()).collect(),
    };
    let available = dataset.speeds();
    for s in &wanted {
        if !available.iter().any(|&a| same_speed(a, *s)) {
            bail!(
                "no recordings at {s} mm/s in {} (its speeds: {})",
                dataset.root.display(),
                available
                    .iter()
                    .map(|s| s.to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
    }
    let indices: Vec<usize> = (0..dataset.entries.len())
        .filter(|&i| {
            wanted
                .iter()
                .any(|&s| same_speed(s, dataset.entries[i].speed_mm_s))
        })
        .collect();
    let (table, present, cols) = feature_table(&dataset, &pipeline, &indices, args.method)?;
    if let Columns::Taxel(cell) = columns {
        let rows = present.len() / cols;
        if cell.row >= rows || cell.col >= cols {
            bail!(
                "--taxel {},{} is outside the {rows}x{cols} grid",
                cell.row,
                cell.col
            );
        }
    }
    let outcome = run_evaluation(&table, columns, &split, &knn.check()?)?;
    if args.json {
        let mut value = serde_json::to_value(&outcome)?;
        value["method"] = args.method.name().into();
        println!("{}", serde_json::to_string(&value)?);
    } else {
        print_outcome(&outcome, args.method, &split, cols);
    }
    Ok(())
}

fn print_outcome(outcome: &Outcome, method: Method, split: &Split, cols: usize) {
    let how = match split {
        Split::CrossValidation { cv, .. } => format!(
            "{}-fold stratified CV, seed {}, {} repeat(s)",
            cv.folds, cv.seed, cv.repeats
        ),
        Split::ByCondition { train, test } => {
            let list = |s: &[Speed]| {
                s.iter()
                    .map(|s| s.to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            format!(
                "train on [{}] mm/s, test on [{}] mm/s",
                list(train),
                list(test)
            )
        }
    };
    println!("method {}: {} samples, {how}", method.name(), outcome.n);
    if let (Some(per), Some(best)) = (&outcome.per_taxel, &outcome.best) {
        println!("accuracy per taxel (%):");
        let rows = per.iter().map(|t| t.row).max().unwrap_or(0) + 1;
        for r in 0..rows {
            let line: Vec<String> = (0..cols)
                .map(|c| {
                    per.iter()
                        .find(|t| t.row == r && t.col == c)
                        .map_or("    -".to_string(), |t| {
                            format!("{:5.1}", 100.0 * t.accuracy)
                        })
                })
                .collect();
            println!("  {}", line.join(" "));
        }
        println!(
            "accuracy {:.1}% (mean over taxels); best taxel r{}c{} {:.1}% (chosen after the fact)",
            100.0 * outcome.accuracy,
            best.row,
            best.col,
            100.0 * best.accuracy
        );
    } else if outcome.accuracy_std > 0.0 {
        println!(
            "accuracy {:.1}% ± {:.1}%",
            100.0 * outcome.accuracy,
            100.0 * outcome.accuracy_std
        );
    } else {
        println!("accuracy {:.1}%", 100.0 * outcome.accuracy);
    }
    let summed = if outcome.per_taxel.is_some() {
        ", summed over taxels"
    } else {
        ""
    };
    println!("confusion (rows = true, columns = predicted{summed}):");
    let width = outcome
        .labels
        .iter()
        .map(|l| l.len())
        .max()
        .unwrap_or(1)
        .max(5);
    print!("{:width$}", "");
    for l in &outcome.labels {
        print!(" {l:>width$}");
    }
    println!();
    for (l, row) in outcome.labels.iter().zip(outcome.confusion.rows()) {
        print!("{l:width$}");
        for v in row {
            print!(" {v:>width$}");
        }
        println!();
    }
}

/// Options of `neurotex reproduce`.
#[derive(Args)]
pub struct ReproduceArgs {
    /// A dataset folder to run on; without it the built-in simulator generates the paper's
    /// design (8 textures x 5, 10, 15 mm/s x 20 trials) in memory.
    #[arg(long)]
    pub dataset: Option<PathBuf>,
    /// Folder for report.md, results.json and figures/.
    #[arg(long, default_value = "report")]
    pub out: PathBuf,
    /// Seed of the simulation, the CV shuffles and the perturbations.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// A small run (10 trials per condition when simulating, fewer repeats, gains, fractions).
    #[arg(long)]
    pub quick: bool,
    /// Simulated trials per texture and speed (default 20, or 10 with --quick).
    #[arg(long)]
    pub trials: Option<u32>,
    /// Neighbours in KNN.
    #[arg(long, default_value_t = 5)]
    pub k: usize,
    #[command(flatten)]
    pub stages: StageArgs,
}

pub fn reproduce(args: ReproduceArgs) -> Result<()> {
    use neurotex::experiments::{prepare, run_all, Progress, ReproduceParams, Source};
    use neurotex::report::{write_report, ReportContext};
    use neurotex::sim::{design, RigParams, ALL_TEXTURES};
    let started = std::time::Instant::now();
    let mut params = if args.quick {
        ReproduceParams::quick()
    } else {
        ReproduceParams::default()
    };
    params.pipeline = args.stages.pipeline()?;
    params.knn = args.stages.knn(args.k)?;
    params.seed = args.seed;
    params.cv.seed = args.seed;
    let dataset = match &args.dataset {
        Some(dir) => Some(Dataset::open(dir)?),
        None => None,
    };
    let trials_per = args.trials.unwrap_or(if args.quick { 10 } else { 20 });
    if trials_per == 0 {
        bail!("--trials must be at least 1");
    }
    let (source, description) = match &dataset {
        Some(ds) => (
            Source::Dataset(ds),
            format!(
                "Dataset folder `{}`: {} recordings as listed in its manifest{}.",
                ds.root.display(),
                ds.entries.len(),
                match ds.layout.baseline {
                    Some(b) => format!(", baseline removal {b:?} (layout.toml)"),
                    None => String::new(),
                }
            ),
        ),
        None => {
            let rig = RigParams::default();
            let trials = design(&ALL_TEXTURES, &[5.0, 10.0, 15.0], trials_per);
            let text = format!(
                "Simulated in memory by neurotex's model of the rig (seed {}): 8 textures (FT1, FT2, FT3, RT, TRug, SB, CP, STF) x 5, 10, 15 mm/s x {trials_per} trials; a 4x4 array of {} mm taxels on {} mm, {} N under force control, {} s hold, {} mm slide, 1 kHz. Rig parameters: `{}`.",
                args.seed,
                rig.taxel_mm,
                rig.active_mm,
                rig.force_n,
                rig.hold_s,
                rig.slide_mm,
                serde_json::to_string(&rig)?
            );
            (
                Source::Simulated {
                    rig: Box::new(rig),
                    trials,
                    seed: args.seed,
                },
                text,
            )
        }
    };
    let bar = std::sync::Mutex::new(progress(0, "starting"));
    let on_progress = |p: Progress| {
        let bar = bar.lock().expect("progress bar");
        match p {
            Progress::Stage(name, n) => {
                bar.set_length(n as u64);
                bar.set_position(0);
                bar.set_message(name.to_string());
            }
            Progress::Tick => bar.inc(1),
        }
    };
    let params = params.check()?;
    let prepared = prepare(&source, &params, &on_progress)?;
    let results = run_all(&prepared, &params, &on_progress)?;
    bar.lock().expect("progress bar").finish_and_clear();
    let p = &params.pipeline;
    let parameters = vec![
        format!("encoder: Izhikevich {:?}, gain G = {}", p.encoder, p.encoder.gain),
        format!("low-pass: {} Hz (0 = off), zero-phase 2nd-order Butterworth; sliding phase only: {}", p.preprocess.cutoff_hz, p.preprocess.slide_only),
        format!("rate volume: {} ms bins; {} gray levels; GLCM distances {:?}, 13 directions, symmetric {}", p.volume.bin_ms, p.volume.levels, p.glcm.distances, p.glcm.symmetric),
        format!("KNN: k = {}, Euclidean, features z-scored on training folds: {}", params.knn.k, params.knn.standardize),
        format!("CV: {}-fold stratified, shuffled with seed {}, {} repeats", params.cv.folds, params.cv.seed, params.cv.repeats),
        format!("E3: {} draws per n, n in {:?}; E5 fractions {:?}; E7 gains {:?}; E8 k in {:?}", params.e3_repeats, params.e3_counts, params.e5_fractions, params.e7_gains, params.e8_ks),
    ];
    let command = std::env::args()
        .map(|a| if a.contains(' ') { format!("'{a}'") } else { a })
        .collect::<Vec<_>>()
        .join(" ");
    let ctx = ReportContext {
        dataset: description,
        parameters,
        total_seconds: started.elapsed().as_secs_f64(),
        command: command.replacen(&std::env::args().next().unwrap_or_default(), "neurotex", 1),
        paper_comparable: dataset.is_none(),
    };
    write_report(&args.out, &results, &ctx)?;
    for claim in neurotex::experiments::claims(&results) {
        eprintln!(
            "{} {}",
            if claim.verdict.holds() {
                "agrees:        "
            } else {
                "does not agree:"
            },
            claim.statement
        );
    }
    eprintln!(
        "report in {}/report.md ({:.1} s)",
        args.out.display(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

/// `neurotex import`: bring recordings from other layouts into the dataset format.
#[derive(clap::Subcommand)]
pub enum ImportCommand {
    /// Per-trial CSV logs (a header row, a time column, one column per channel), with
    /// metadata taken from the file names.
    Csv(ImportCsvArgs),
    /// A stacked array `(N, ...)` with one label (and optionally one speed) per sample.
    Stacked(ImportStackedArgs),
}

/// Options of `neurotex import csv`.
#[derive(Args)]
pub struct ImportCsvArgs {
    /// CSV files, or folders whose .csv files are all imported.
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    /// The dataset folder to create (must not exist, or be empty).
    #[arg(long)]
    pub out: PathBuf,
    /// Fields from file names, e.g. `{label}_F{force}_V{speed}mmps_{trial}.csv`; `label`,
    /// `speed` (mm/s), `force` and `trial` fill the manifest, other fields become columns.
    /// Without it the label is the file name.
    #[arg(long = "name-pattern")]
    pub name_pattern: Option<String>,
    /// The time-stamp column (irregular stamps are kept and resampled onto 1 ms later).
    #[arg(long = "time-column")]
    pub time_column: Option<String>,
    /// Unit of the time column.
    #[arg(long = "time-unit", default_value = "ms", value_parser = ["ms", "s"])]
    pub time_unit: String,
    /// Channel columns: a comma-separated list, or a regular expression such as `^channel\d+$`
    /// (default: every column but the time column).
    #[arg(long)]
    pub channels: Option<String>,
    /// Grid `ROWSxCOLS` to place the channels on, row-major (default one row).
    #[arg(long)]
    pub grid: Option<String>,
    /// Each channel's cell as `row,col;row,col;...` (needs --grid).
    #[arg(long = "channel-map")]
    pub channel_map: Option<String>,
    /// Nominal sampling rate in Hz (needed without a time column; else the median interval).
    #[arg(long, allow_negative_numbers = true)]
    pub fs: Option<f64>,
    /// Baseline removal to record in layout.toml: `none` or `min` (capacitive sensors rest
    /// at a large offset).
    #[arg(long)]
    pub baseline: Option<String>,
    /// Leave out files with errors (each is reported) instead of stopping at the first.
    #[arg(long = "skip-bad")]
    pub skip_bad: bool,
}

/// Options of `neurotex import stacked`.
#[derive(Args)]
pub struct ImportStackedArgs {
    /// The stacked samples, `.npy` of floats or integers.
    #[arg(long)]
    pub data: PathBuf,
    /// One label per sample, `.npy` of integers or strings.
    #[arg(long)]
    pub labels: PathBuf,
    /// The data's axes in order, from n (sample), t (time), row, col, channel:
    /// e.g. `n,row,col,t` for shape (N, rows, cols, T) or `n,t,channel`.
    #[arg(long)]
    pub axes: String,
    /// Sampling rate in Hz.
    #[arg(long, allow_negative_numbers = true)]
    pub fs: f64,
    /// One speed (mm/s) per sample, `.npy`.
    #[arg(long)]
    pub speeds: Option<PathBuf>,
    /// With a channel axis: the grid `ROWSxCOLS` to place channels on, row-major.
    #[arg(long)]
    pub grid: Option<String>,
    /// The dataset folder to create.
    #[arg(long)]
    pub out: PathBuf,
}

fn parse_grid(text: &str) -> Result<(usize, usize)> {
    let parts: Vec<&str> = text.split(['x', 'X']).collect();
    match parts.as_slice() {
        [r, c] => match (r.trim().parse::<usize>(), c.trim().parse::<usize>()) {
            (Ok(r), Ok(c)) if r > 0 && c > 0 => Ok((r, c)),
            _ => bail!("--grid must be ROWSxCOLS with positive integers, got `{text}`"),
        },
        _ => bail!("--grid must be ROWSxCOLS, e.g. 4x4, got `{text}`"),
    }
}

pub fn import(cmd: ImportCommand) -> Result<()> {
    use neurotex::import::{
        csv_files, import_csv, import_stacked, ChannelSelect, CsvImportParams, NamePattern,
        StackedParams,
    };
    match cmd {
        ImportCommand::Csv(a) => {
            let channel_map = match &a.channel_map {
                None => None,
                Some(text) => Some(
                    text.split(';')
                        .map(|pair| {
                            let rc: Vec<&str> = pair.split(',').collect();
                            match rc.as_slice() {
                                [r, c] => match (r.trim().parse(), c.trim().parse()) {
                                    (Ok(r), Ok(c)) => Ok([r, c]),
                                    _ => bail!("--channel-map entries are row,col; got `{pair}`"),
                                },
                                _ => bail!("--channel-map entries are row,col separated by `;`, got `{pair}`"),
                            }
                        })
                        .collect::<Result<Vec<_>>>()?,
                ),
            };
            if channel_map.is_some() && a.grid.is_none() {
                bail!("--channel-map needs --grid");
            }
            if let Some(fs) = a.fs {
                if !(fs.is_finite() && fs > 0.0) {
                    bail!("--fs must be a positive sampling rate in Hz, got {fs}");
                }
            }
            let params = CsvImportParams {
                pattern: a
                    .name_pattern
                    .as_deref()
                    .map(NamePattern::parse)
                    .transpose()?,
                time_column: a.time_column.clone(),
                time_unit_s: if a.time_unit == "s" { 1.0 } else { 1e-3 },
                channels: match &a.channels {
                    Some(text) => ChannelSelect::parse(text)?,
                    None => ChannelSelect::All,
                },
                grid: a.grid.as_deref().map(parse_grid).transpose()?,
                channel_map,
                fs: a.fs,
                baseline: match a.baseline.as_deref() {
                    None | Some("none") => None,
                    Some("min") => Some(neurotex::recording::Baseline::Min),
                    Some(other) => bail!("unknown --baseline `{other}`: expected none or min"),
                },
                skip_bad: a.skip_bad,
            };
            let files = csv_files(&a.inputs)?;
            let bar = progress(files.len(), "importing");
            let summary = import_csv(&files, &params, &a.out, &|| bar.inc(1));
            bar.finish_and_clear();
            let summary = summary?;
            for (_, why) in &summary.skipped {
                eprintln!("warning: left out {why}");
            }
            eprintln!(
                "{} recordings ({} left out) -> {}; {} channels on a {}x{} grid at {:.2} Hz nominal",
                summary.written,
                summary.skipped.len(),
                a.out.display(),
                summary.layout.channels.as_ref().map_or(0, Vec::len),
                summary.layout.rows.unwrap_or(1),
                summary.layout.cols.unwrap_or(1),
                summary.layout.fs.unwrap_or(0.0)
            );
        }
        ImportCommand::Stacked(a) => {
            let params = StackedParams {
                axes: a.axes.clone(),
                fs: a.fs,
                grid: a.grid.as_deref().map(parse_grid).transpose()?,
            };
            let n = import_stacked(&a.data, &a.labels, a.speeds.as_deref(), &params, &a.out)?;
            eprintln!("{n} recordings -> {}", a.out.display());
        }
    }
    Ok(())
}
