//! `evaluate` on encoded recordings: the samples a method makes of them
//! ([`Spikes::samples`], which [`crate::analysis::evaluator`] classifies by
//! cross-validation or a train/test split), and the result ([`Evaluation`]) with the
//! accuracy's interval and chance levels, which taxels respond when taxels are scored one
//! by one, as JSON and as text, and each recording's out-of-fold prediction as CSV.

use crate::values::shown_label;
use crate::words::counted;
use std::fmt::Write as _;
use std::io::Write;

use serde::Serialize;
use serde_json::Value;

use crate::analysis::{Columns, MethodSamples, Outcome, Split, TaxelAccuracy};
use crate::classify::metrics::{chance_level, AgainstChance};
use crate::classify::{ClassifierChoice, Interval, Metrics};
use crate::diagnostics::{taxel_diagnostics, TaxelDiagnostics};
use crate::pipeline::{Encoded, Pipeline};
use crate::recording::{Meta, Selection};
use crate::samples::{input_step_ms, MethodChoice, PopulationMatrices};
use crate::snn::SnnParams;
use crate::values::{Grid, Speed};
use crate::Result;

/// A dataset's recordings as encoded: what every evaluation starts from.
#[derive(Debug, Clone, Copy)]
pub struct Spikes<'a> {
    /// The encoded recordings, in table order.
    pub encoded: &'a [Encoded],
    /// The grid they share.
    pub grid: &'a Grid,
    /// The pipeline that encoded them (its features are extracted with it).
    pub pipeline: &'a Pipeline,
}

/// The accuracy over the encodings of an evaluation's recordings.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EncoderDraws {
    /// Each encoding's accuracy, the one as run first.
    pub accuracies: Vec<f64>,
    /// The mean over the encodings (`estimate`) with its 95 % interval resampling
    /// encodings and recordings.
    pub combined: Interval,
    /// Each perturbed sample was the sample times `1 + u * perturbation`.
    pub perturbation: f64,
}

impl EncoderDraws {
    /// The text line: the mean, its interval and the range of the encodings' accuracies.
    pub fn text(&self) -> String {
        let fold = |f: fn(f64, f64) -> f64, start| self.accuracies.iter().copied().fold(start, f);
        let (lo, hi) = (
            fold(f64::min, f64::INFINITY),
            fold(f64::max, f64::NEG_INFINITY),
        );
        let each = match lo == hi {
            true => format!("every encoding {:.1}%", 100.0 * lo),
            false => format!(
                "each encoding from {:.1}% to {:.1}%",
                100.0 * lo,
                100.0 * hi
            ),
        };
        format!(
            "the accuracy above is the encoding as run's; over {} encodings (the one as run and {} with each input sample times 1 + u x {:e}, u uniform in [-1, 1)): mean {:.1}%, 95 % interval [{:.1}%, {:.1}%] ({}); {each}",
            self.accuracies.len(),
            self.accuracies.len() - 1,
            self.perturbation,
            100.0 * self.combined.estimate,
            100.0 * self.combined.lower,
            100.0 * self.combined.upper,
            self.combined.described(),
        )
    }
}

/// One evaluation's result, with everything its JSON and text need.
#[derive(Debug, Clone)]
pub struct Evaluation {
    /// Accuracy, confusion, per-taxel accuracies and out-of-fold predictions.
    pub outcome: Outcome,
    /// The feature method's name (`van-rossum` for spike timing).
    pub method: &'static str,
    /// The van Rossum kernel's time constant, for spike timing.
    pub tau_ms: Option<f64>,
    /// How the recordings were split.
    pub split: Split,
    /// Balanced accuracy, per-class recall and precision, both chance levels.
    pub metrics: Metrics,
    /// The accuracy's 95 % bootstrap interval over recordings.
    pub interval: Interval,
    /// Silent and saturated taxels, when every taxel was scored alone.
    pub taxels: Option<TaxelDiagnostics>,
    /// What to change when most taxels are silent or at the encoder's ceiling
    /// ([`TaxelDiagnostics::advice`]), whatever the method.
    pub advice: Option<String>,
    /// The classifier and its main parameters as run (`KNN (k = 5)`), when the caller
    /// names it: said in the text's first line and under `classifier` in JSON.
    pub classifier: Option<String>,
    /// The encoding and the encoder as run (`encoding sa; encoder: Izhikevich (2003)
    /// neurons, ..., overshoot kept ..., gain G = 8`): the text's second line.
    pub encoder: String,
    /// With `--encoder-draws` above 1: the accuracy over the recordings' encodings.
    pub draws: Option<EncoderDraws>,
    /// The grid's columns, to print per-taxel accuracies in place.
    pub cols: usize,
    /// Each table row's recording, for the out-of-fold predictions.
    pub metas: Vec<Meta>,
}

impl Spikes<'_> {
    /// What `method` makes of the encoded recordings for `classifier`: the feature table
    /// with the columns `columns`, the van Rossum distances (time constant `tau_ms`), or
    /// the spike inputs at the spiking network's step.
    ///
    /// # Errors
    /// A taxel outside the grid, a broken time constant, a feature method the recordings
    /// cannot support, or populations the encoding lacks.
    pub fn samples(
        &self,
        method: MethodChoice,
        columns: Columns,
        classifier: &ClassifierChoice,
        tau_ms: f64,
    ) -> Result<MethodSamples> {
        if let Columns::Taxel(cell) = columns {
            self.grid.locate(cell)?;
        }
        let encoding = self.pipeline.params().encoding;
        let extractor = self.pipeline.extractor(self.grid)?;
        // The recordings were encoded with the pipeline's encoding: as that encoding sees
        // them already.
        let view = self.encoded;
        let snn: Vec<SnnParams> = match classifier {
            ClassifierChoice::Snn(p) => vec![*p],
            _ => Vec::new(),
        };
        let step_ms = input_step_ms(view, &snn);
        MethodSamples::of(
            (view, encoding, &extractor),
            method,
            columns,
            step_ms,
            || PopulationMatrices::new(tau_ms)?.matrix(view, encoding),
        )
    }
}

impl Evaluation {
    /// The evaluation of `method` whose samples of the recordings `spikes`, in the columns
    /// `columns`, gave `outcome` under `split`; `seed` draws the interval's bootstrap.
    /// Which taxels stay silent or saturate is kept when every taxel was scored alone.
    ///
    /// # Errors
    /// An outcome without per-recording results.
    pub fn of(
        spikes: Spikes<'_>,
        (method, columns): (MethodChoice, Columns),
        outcome: Outcome,
        split: &Split,
        tau_ms: f64,
        seed: u64,
    ) -> Result<Self> {
        let Spikes {
            encoded,
            grid,
            pipeline,
        } = spikes;
        let diagnostics = taxel_diagnostics(encoded, grid, pipeline.params().encoder)?;
        let advice = diagnostics.advice_for(pipeline.params());
        let metas = encoded.iter().map(|e| e.meta.clone()).collect();
        let tau_ms = (method == MethodChoice::VanRossum).then_some(tau_ms);
        let evaluation = Self::new(outcome, method.name(), tau_ms, split, grid, metas, seed)?;
        Ok(Self {
            encoder: encoding_line(pipeline.params()),
            advice,
            taxels: (columns == Columns::EachTaxel).then_some(diagnostics),
            ..evaluation
        })
    }

    /// The evaluation of `outcome`, its metrics and interval computed.
    fn new(
        outcome: Outcome,
        method: &'static str,
        tau_ms: Option<f64>,
        split: &Split,
        grid: &Grid,
        metas: Vec<Meta>,
        seed: u64,
    ) -> Result<Self> {
        Ok(Self {
            metrics: Metrics::from_confusion(&outcome.confusion),
            interval: outcome.accuracy_interval(seed)?,
            outcome,
            method,
            tau_ms,
            split: split.clone(),
            taxels: None,
            advice: None,
            classifier: None,
            encoder: String::new(),
            draws: None,
            cols: grid.cols(),
            metas,
        })
    }

    /// The note for an accuracy whose interval is not above chance, taken as the larger of
    /// one over the classes and the most frequent class's share (what always answering it
    /// scores); `None` when the interval is wholly above. A workflow says it as a warning:
    /// the accuracy alone, a few points over chance, reads as a result it is not.
    pub fn chance_note(&self) -> Option<String> {
        let (level, chance) =
            chance_level(self.metrics.classes_present, self.metrics.chance_majority);
        let ci = [self.interval.lower, self.interval.upper];
        let interval = format!("[{:.1}, {:.1}] %", 100.0 * ci[0], 100.0 * ci[1]);
        let apart = !matches!(self.split, Split::CrossValidation { .. });
        let why = match apart {
            true => " (features that differ between the training and the test recordings)",
            false => "",
        };
        AgainstChance::of(ci, level).map(|at| match at {
            AgainstChance::Below => format!(
                "the accuracy's interval {interval} is under chance ({chance}): what the classifier learns on the training recordings does not carry over to the test recordings{why}"
            ),
            AgainstChance::Includes => format!(
                "the accuracy's interval {interval} includes chance ({chance}): this procedure is not shown to classify better than guessing"
            ),
        })
    }

    /// The result as one JSON object: the outcome's fields, `method`, `metrics`,
    /// `accuracy_interval`, `tau_ms` for spike timing, and `taxels` (every taxel's silent
    /// and saturated shares, those by name, the mean over responsive taxels beside the
    /// mean over all) when every taxel was scored alone.
    ///
    /// # Errors
    /// A value JSON cannot hold.
    pub fn json(&self) -> serde_json::Result<Value> {
        let mut value = serde_json::to_value(&self.outcome)?;
        value["method"] = self.method.into();
        if let Some(classifier) = &self.classifier {
            value["classifier"] = classifier.as_str().into();
        }
        if let Some(tau) = self.tau_ms {
            value["tau_ms"] = tau.into();
        }
        value["metrics"] = serde_json::to_value(&self.metrics)?;
        value["accuracy_interval"] = serde_json::to_value(&self.interval)?;
        if let Some(draws) = &self.draws {
            value["encoder_draws"] = serde_json::to_value(draws)?;
        }
        // How the accuracy was obtained, in words and, for cross-validation, as numbers.
        value["protocol"] = split_text(&self.split).into();
        if let Split::CrossValidation { cv, group_by, .. } = &self.split {
            value["cv"] = serde_json::json!({
                "folds": cv.folds,
                "seed": cv.seed,
                "repeats": cv.repeats,
                "group_by": group_by,
            });
        }
        if let Some(advice) = &self.advice {
            value["warning"] = advice.as_str().into();
        }
        if let Some(taxels) = &self.taxels {
            let per = self.outcome.per_taxel.as_deref().unwrap_or_default();
            let mut t = serde_json::to_value(taxels)?;
            t["silent"] = serde_json::to_value(taxels.silent())?;
            t["saturated"] = serde_json::to_value(taxels.saturated())?;
            t["mean_all"] = self.outcome.accuracy.into();
            t["mean_responsive"] = serde_json::to_value(taxels.responsive_mean(per))?;
            value["taxels"] = t;
        }
        Ok(value)
    }

    /// The result as text: what was run, the accuracy (per taxel when every taxel was
    /// evaluated), its interval and chance levels, the confusion matrix, and the silent
    /// and saturated taxels when taxels were scored one by one.
    pub fn text(&self) -> String {
        let mut out = String::new();
        let (outcome, metrics, interval) = (&self.outcome, &self.metrics, &self.interval);
        let how = split_text(&self.split);
        // Writing to a String cannot fail.
        let by = self.classifier.as_ref().map(|c| format!(", {c}"));
        let by = by.unwrap_or_default();
        let _ = writeln!(
            out,
            "method {}{by}: {how}; {} recordings scored",
            self.method, outcome.n
        );
        if !self.encoder.is_empty() {
            let _ = writeln!(out, "{}", self.encoder);
        }
        accuracy_text(&mut out, outcome, self.cols);
        // No accuracy without its uncertainty and the level a guess reaches.
        let _ = writeln!(
            out,
            "95 % interval [{:.1}%, {:.1}%] ({}); chance {:.1}% (one over {} classes), {:.1}% always answering the most frequent class",
            100.0 * interval.lower,
            100.0 * interval.upper,
            interval.described(),
            100.0 * metrics.chance_uniform,
            metrics.classes_present,
            100.0 * metrics.chance_majority
        );
        if let Some(draws) = &self.draws {
            let _ = writeln!(out, "{}", draws.text());
        }
        confusion_text(&mut out, outcome);
        if let Some(taxels) = &self.taxels {
            taxels_text(&mut out, taxels, outcome);
        }
        if let Some(advice) = &self.advice {
            let _ = writeln!(out, "warning: {advice}");
        }
        out
    }

    /// Writes `file,label,predicted,fold,repeat`, one row per out-of-fold prediction
    /// (`fold` is `test` with a train/test split; folds and repeats count from 0).
    ///
    /// # Errors
    /// One classifier's predictions are not kept (every taxel scored alone), or `w` fails.
    pub fn write_out_of_fold(&self, w: &mut dyn Write) -> std::io::Result<()> {
        let predictions =
            self.outcome.predictions.as_deref().ok_or_else(|| {
                std::io::Error::other("out-of-fold predictions need one classifier")
            })?;
        let labels = &self.outcome.labels;
        let mut out = csv::Writer::from_writer(w);
        out.write_record(["file", "label", "predicted", "fold", "repeat"])?;
        for p in predictions {
            let meta = &self.metas[p.row];
            let fold = p.fold.map_or("test".to_string(), |f| f.to_string());
            out.write_record([
                meta.file.as_str(),
                meta.label.as_str(),
                labels[p.predicted].as_str(),
                fold.as_str(),
                p.repeat.to_string().as_str(),
            ])?;
        }
        out.flush()
    }
}

/// The populations that encoded and their neurons: the encoding (with the FA population's
/// gain when it encodes), then the SA encoder's line as results list it.
fn encoding_line(params: &crate::pipeline::PipelineParams) -> String {
    let encoding = match params.encoding {
        crate::pipeline::Encoding::Sa => "encoding sa".to_string(),
        other => format!("encoding {other} (FA gain {})", params.fa.gain),
    };
    format!("{encoding}; {}", params.encoder_line())
}

/// How the recordings were split, as text.
fn split_text(split: &Split) -> String {
    match split {
        Split::CrossValidation {
            cv,
            group_by: Some(column),
            speeds,
        } => format!(
            "{}, up to {}-fold CV keeping each `{column}` group in one fold, seed {}, {}",
            recordings_at(speeds.as_deref()),
            cv.folds,
            cv.seed,
            counted(cv.repeats, "repeat")
        ),
        Split::CrossValidation { cv, speeds, .. } => format!(
            "{}, {}-fold stratified CV, seed {}, {}",
            recordings_at(speeds.as_deref()),
            cv.folds,
            cv.seed,
            counted(cv.repeats, "repeat")
        ),
        Split::Where { train, test } => {
            format!("train on {}, test on {}", selected(train), selected(test))
        }
        Split::Rows { train, test } => format!(
            "train on {} recordings, test on {}",
            train.len(),
            test.len()
        ),
    }
}

/// The recordings cross-validation runs over, as text.
fn recordings_at(speeds: Option<&[Speed]>) -> String {
    match speeds {
        None => "all recordings".into(),
        Some(speeds) => format!("recordings at {}", selected(&Selection::speeds(speeds))),
    }
}

/// A selection as text: `5, 10 mm/s` for speeds, `session in s1, s2` otherwise.
fn selected(selection: &Selection) -> String {
    let values = selection.values.join(", ");
    match selection.column.as_str() {
        "speed_mm_s" => format!("{values} mm/s"),
        column => format!("{column} in {values}"),
    }
}

/// The accuracy: per taxel with the mean and best when every taxel was evaluated, with
/// its spread over repeats when there is one.
fn accuracy_text(out: &mut String, outcome: &Outcome, cols: usize) {
    let _ = match (&outcome.per_taxel, &outcome.best) {
        (Some(per), Some(best)) => {
            taxel_grid_text(out, per, cols);
            writeln!(
                out,
                "accuracy {:.1}% (mean over taxels); best taxel r{}c{} {:.1}% (chosen after the fact)",
                100.0 * outcome.accuracy,
                best.row,
                best.col,
                100.0 * best.accuracy
            )
        }
        _ if outcome.accuracy_std > 0.0 => writeln!(
            out,
            "accuracy {:.1}% ± {:.1}%",
            100.0 * outcome.accuracy,
            100.0 * outcome.accuracy_std
        ),
        _ => writeln!(out, "accuracy {:.1}%", 100.0 * outcome.accuracy),
    };
}

/// Each taxel's accuracy in its place on the grid; `-` for cells without a taxel.
fn taxel_grid_text(out: &mut String, per: &[TaxelAccuracy], cols: usize) {
    out.push_str("accuracy per taxel (%):\n");
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
        let _ = writeln!(out, "  {}", line.join(" "));
    }
}

/// Widest confusion matrix printed whole, in characters per line; a wider one (many
/// classes) is summed up by its largest confusions instead.
const WIDEST_CONFUSION: usize = 120;

/// Largest confusions listed in place of a matrix too wide to print.
const CONFUSIONS_LISTED: usize = 10;

/// The confusion matrix, rows the true labels; with too many classes for a line, its
/// largest confusions and the classes recalled worst.
fn confusion_text(out: &mut String, outcome: &Outcome) {
    let summed = match outcome.per_taxel {
        Some(_) => ", summed over taxels",
        None => "",
    };
    let labels: Vec<String> = outcome.labels.iter().map(|l| shown_label(l)).collect();
    let width = labels
        .iter()
        .map(|l| l.chars().count())
        .max()
        .unwrap_or(1)
        .max(5);
    if (width + 1) * (labels.len() + 1) > WIDEST_CONFUSION {
        return confusions_listed(out, outcome, &labels, summed);
    }
    let _ = writeln!(out, "confusion (rows = true, columns = predicted{summed}):");
    let _ = write!(out, "{:width$}", "");
    for l in &labels {
        let _ = write!(out, " {l:>width$}");
    }
    out.push('\n');
    for (l, row) in labels.iter().zip(outcome.confusion.rows()) {
        let _ = write!(out, "{l:width$}");
        for v in row {
            let _ = write!(out, " {v:>width$}");
        }
        out.push('\n');
    }
}

/// A confusion matrix too wide for a line: its largest off-diagonal cells (largest first,
/// then in the matrix's order) and the classes recalled worst; `--json` has it whole.
fn confusions_listed(out: &mut String, outcome: &Outcome, labels: &[String], summed: &str) {
    let m = outcome.confusion.rows();
    let n = labels.len();
    let mut off: Vec<(usize, usize, usize)> = (0..n)
        .flat_map(|t| (0..n).map(move |p| (t, p)))
        .filter(|&(t, p)| t != p && m[t][p] > 0)
        .map(|(t, p)| (m[t][p], t, p))
        .collect();
    off.sort_by(|a, b| b.0.cmp(&a.0).then((a.1, a.2).cmp(&(b.1, b.2))));
    let _ = writeln!(
        out,
        "confusion over {n} classes{summed}: too wide to print (--json has it whole); the largest confusions, true -> predicted:"
    );
    if off.is_empty() {
        out.push_str("  none\n");
    }
    for &(count, t, p) in off.iter().take(CONFUSIONS_LISTED) {
        let _ = writeln!(out, "  {} -> {}: {count}", labels[t], labels[p]);
    }
    if off.len() > CONFUSIONS_LISTED {
        let _ = writeln!(out, "  ... {} more pairs", off.len() - CONFUSIONS_LISTED);
    }
    let recall: Vec<(f64, usize)> = (0..n)
        .filter_map(|t| {
            let total: usize = m[t].iter().sum();
            (total > 0).then(|| (m[t][t] as f64 / total as f64, t))
        })
        .collect();
    let perfect = recall.iter().filter(|r| r.0 == 1.0).count();
    let mut worst: Vec<&(f64, usize)> = recall.iter().filter(|r| r.0 < 1.0).collect();
    worst.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let shown: Vec<String> = (worst.iter().take(CONFUSIONS_LISTED))
        .map(|&&(r, t)| format!("{} {:.0}%", labels[t], 100.0 * r))
        .collect();
    let _ = writeln!(
        out,
        "recall: {perfect} of {} classes right on every recording; lowest: {}",
        recall.len(),
        if shown.is_empty() {
            "none".to_string()
        } else {
            shown.join(", ")
        }
    );
}

/// The silent and saturated taxels and the mean over the responsive ones.
fn taxels_text(out: &mut String, taxels: &TaxelDiagnostics, outcome: &Outcome) {
    let names = |list: Vec<&str>| match list.is_empty() {
        true => "none".to_string(),
        false => list.join(", "),
    };
    let _ = writeln!(
        out,
        "taxels silent (no spike) in most recordings: {}; at the encoder's ceiling ({:.0} Hz) in most recordings: {}",
        names(taxels.silent()),
        taxels.ceiling_hz,
        names(taxels.saturated())
    );
    let per = outcome.per_taxel.as_deref().unwrap_or_default();
    let all = 100.0 * outcome.accuracy;
    let _ = match taxels.responsive_mean(per) {
        Some(mean) => writeln!(
            out,
            "accuracy {:.1}% (mean over responsive taxels) beside {all:.1}% (mean over all taxels)",
            100.0 * mean
        ),
        None => writeln!(
            out,
            "no taxel responds in most recordings; mean over all taxels {all:.1}%"
        ),
    };
}
