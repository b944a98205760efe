//! `compare`'s outputs: the ranking as Markdown and as text lines, and the folder of
//! `compare.json`, `compare.md` and the figures. The binary prints and writes these; the
//! wording lives here once.

use std::path::Path;

use crate::compare::signal::NO_ENCODING;
use crate::compare::{Comparison, Nested, Ranked};
use crate::error::{DataError, Result};
use crate::io::replace_dir;

use super::figures::{compare as figures, svg_and_png, FigureError};
use super::folder_source;
use neurotex_core::words::signed_one_decimal as signed;

/// `87.5% [85.1, 89.8]`.
pub fn with_interval(accuracy: f64, ci: [f64; 2]) -> String {
    format!(
        "{:.1}% [{:.1}, {:.1}]",
        100.0 * accuracy,
        100.0 * ci[0],
        100.0 * ci[1]
    )
}

/// The ranking as a Markdown document.
pub fn markdown(c: &Comparison) -> String {
    let design = match c.design.is_empty() {
        true => String::new(),
        false => format!("{}.\n", capitalised(&c.design)),
    };
    // The units the intervals resample, where they are not the recordings themselves.
    let units = match (c.units.as_str(), c.n_units == c.n_recordings) {
        ("recordings", true) => String::new(),
        _ => format!(" ({} units: {})", c.n_units, c.units),
    };
    // The number to quote first, above the ranking it is not biased by.
    let nested = match &c.nested {
        Some(n) => format!(
            "**Nested selection: {}**{}\n\n",
            with_interval(n.accuracy, n.ci),
            nested_details(n)
        ),
        None => String::new(),
    };
    let encodings = encodings(c);
    let (heading, rule) = match encodings {
        Some(n) => (format!(" over {n} encodings: mean [95% CI] |"), "---|"),
        None => (String::new(), ""),
    };
    let mut out = format!(
        "# Comparison\n\n{} recordings{units}, {} classes; {}.\n{design}\
         Chance {:.1}%, majority class {:.1}%.\n\n{nested}\
         | rank | encoding | method | classifier | accuracy [95% CI] | vs paper (p) |{heading} seconds |\n\
         |---:|---|---|---|---|---|{rule}---:|\n",
        c.n_recordings,
        c.classes,
        c.protocol,
        100.0 * c.chance,
        100.0 * c.majority
    );
    for (i, r) in c.results.iter().enumerate() {
        let over = match encodings {
            Some(_) => format!(" {} |", over_encodings(r)),
            None => String::new(),
        };
        out.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} |{over} {:.2} |\n",
            i + 1,
            r.encoding,
            r.method,
            r.classifier,
            with_interval(r.accuracy, r.ci),
            versus_paper(r),
            r.seconds
        ));
    }
    if let Some(line) = encodings_note(c) {
        out.push_str(&format!("\n{}.\n", capitalised(&line)));
    }
    for line in versus_rates(c) {
        out.push_str(&format!("\n{}.\n", capitalised(&line)));
    }
    if let Some(line) = to_use(c) {
        out.push_str(&format!("\n{}\n", capitalised(&line)));
    }
    for note in &c.notes {
        out.push_str(&format!("\nNote: {note}.\n"));
    }
    if c.results.iter().any(|r| r.encoding == NO_ENCODING) {
        out.push_str(BASELINES_NOTE);
    }
    if !c.results.iter().any(|r| r.paper) {
        out.push_str(&format!("\n{NO_PAPER}\n"));
    }
    out.push_str(&format!("\nCaveat: {}.\n", c.caveat));
    if !c.provenance.is_empty() {
        out.push_str("\n## Provenance\n\n");
        for line in &c.provenance {
            out.push_str(&format!("- {line}\n"));
        }
    }
    out
}

/// The number of encodings the candidates that read spikes were scored on, when above one.
fn encodings(c: &Comparison) -> Option<usize> {
    let over = c.results.iter().find_map(|r| r.over_encodings.as_ref())?;
    (over.accuracies.len() > 1).then_some(over.accuracies.len())
}

/// `86.1% [80.0, 91.9], each from 84.4 to 88.1%`, or why a candidate has none.
fn over_encodings(r: &Ranked) -> String {
    let Some(over) = &r.over_encodings else {
        return "- (no spikes: the encoder is not run)".into();
    };
    let (lo, hi) = over.range();
    let spread = match hi > lo {
        true => format!("each from {:.1} to {:.1}%", 100.0 * lo, 100.0 * hi),
        false => format!("each {:.1}%", 100.0 * lo),
    };
    format!("{}, {spread}", with_interval(over.mean, over.ci))
}

/// What the accuracies over encodings are, when the comparison has them.
fn encodings_note(c: &Comparison) -> Option<String> {
    let n = encodings(c)?;
    let size = c
        .results
        .iter()
        .find_map(|r| r.over_encodings.as_ref())?
        .perturbation;
    Some(format!(
        "over {n} encodings (the input as run, whose accuracy the ranking shows, and {} with each conditioned sample times 1 + u x {size:e}): the mean accuracy, with a 95 % interval that draws an encoding as well as the {} (where one encoding's accuracy may land), and the lowest and highest encoding's",
        n - 1,
        c.units
    ))
}

/// The heading of the candidates' column.
const CANDIDATE: &str = "encoding / method / classifier";

/// Why the ranking has no difference from the paper's method.
const NO_PAPER: &str = "The paper's method (sa / glcm3d / knn) is not among the candidates, so no difference from it is given (-).";

/// What the encoding `none` means, under a ranking that holds it.
const BASELINES_NOTE: &str = "\nEncoding `none`: baselines without spikes, computed from the conditioned signal the encoder receives (resampled to 1 kHz, baseline removed, low-pass filtered, divided by the recording's maximum): `spectrum` is the same transform and bands as the spike method's applied to each taxel's signal, `signal-stats` each taxel's moments, quantiles and turns per second. They tell what the spikes cost or gain against the signal.\n";

/// The ranking as lines of text for a terminal.
pub fn text_lines(c: &Comparison) -> Vec<String> {
    let mut lines = vec![format!(
        "{} recordings, {} classes ({}); chance {:.1}%, majority {:.1}%",
        c.n_recordings,
        c.classes,
        c.protocol,
        100.0 * c.chance,
        100.0 * c.majority
    )];
    if !c.design.is_empty() {
        lines.push(c.design.clone());
    }
    let width = c
        .results
        .iter()
        .map(|r| r.encoding.len() + r.method.len() + r.classifier.len() + 6)
        .chain([CANDIDATE.len()])
        .max()
        .unwrap_or(0);
    lines.push(format!(
        "{:>3}  {:<width$}  {:<24} {:<28} {:>9}",
        "", CANDIDATE, "accuracy [95% CI]", "vs paper (paired test)", "time"
    ));
    for (i, r) in c.results.iter().enumerate() {
        let name = format!("{} / {} / {}", r.encoding, r.method, r.classifier);
        lines.push(format!(
            "{:>3}. {name:<width$}  {:<24} {:<28} {:>7.2} s",
            i + 1,
            with_interval(r.accuracy, r.ci),
            versus_paper(r),
            r.seconds
        ));
    }
    if let Some(note) = encodings_note(c) {
        lines.push(format!("{note}:"));
        for (i, r) in c.results.iter().enumerate() {
            let name = format!("{} / {} / {}", r.encoding, r.method, r.classifier);
            lines.push(format!(
                "{:>3}. {name:<width$}  {}",
                i + 1,
                over_encodings(r)
            ));
        }
    }
    lines.extend(versus_rates(c));
    if let Some(n) = &c.nested {
        lines.push(format!("nested selection: {}", nested_text(n)));
        lines.extend(to_use(c));
    }
    if !c.results.iter().any(|r| r.paper) {
        lines.push(NO_PAPER.to_string());
    }
    lines.push(format!("caveat: {}", c.caveat));
    lines
}

/// With nested selection, what to train: the ranking's top candidate (the choice the
/// nested estimate scores), with the command that trains it, and what to expect of it.
fn to_use(c: &Comparison) -> Option<String> {
    let (n, top) = (c.nested.as_ref()?, c.results.first()?);
    let how = match (top.encoding.as_str(), top.method.as_str()) {
        (NO_ENCODING, _) => "a baseline without spikes, which `neurotex train` does not make".into(),
        (_, "van-rossum") => "a spike-distance method, which `neurotex evaluate` scores but `neurotex train` does not make".into(),
        (encoding, method) => {
            let taxel = match method {
                "taxel" => " --taxel ROW,COL",
                _ => "",
            };
            format!(
                "`neurotex train --dataset DIR --encoding {encoding} --method {method}{taxel} --classifier {}` with this comparison's stage and classifier options, on the recordings of the conditions it will meet",
                top.classifier
            )
        }
    };
    Some(format!(
        "to use the choice: rank 1, {} / {} / {} ({how}); expect about the nested estimate, {}, not rank 1's own {}.",
        top.encoding,
        top.method,
        top.classifier,
        with_interval(n.accuracy, n.ci),
        with_interval(top.accuracy, top.ci)
    ))
}

/// `+12.3 points (p 0.0004)`, `paper's method`, or `-`.
pub(super) fn versus_paper(r: &Ranked) -> String {
    match (r.paper, r.difference_vs_paper, r.p_vs_paper) {
        (true, ..) => "paper's method".into(),
        (false, Some(d), Some(p)) => versus_text(d, p),
        _ => "-".into(),
    }
}

/// For each spiking network ranked beside its inputs' spike rates with logistic regression,
/// the paired test between the two: what the spikes' timing adds to their counts.
fn versus_rates(c: &Comparison) -> Vec<String> {
    let rates = |r: &Ranked| format!("{} / rates / linear", r.encoding);
    c.results
        .iter()
        .filter_map(|r| {
            let (d, p) = (r.difference_vs_rates?, r.p_vs_rates?);
            Some(format!(
                "the spiking network ({} / {} / {}) against its inputs' spike rates with logistic regression ({}), paired sign-flip test over {}: {}",
                r.encoding,
                r.method,
                r.classifier,
                rates(r),
                c.units,
                rates_verdict(d, p)
            ))
        })
        .collect()
}

/// What a paired test between the network and its inputs' rates says: `+10.4 points (p
/// 0.014): ahead of its inputs' rates beyond the folds' noise`.
fn rates_verdict(difference: f64, p: f64) -> String {
    let verdict = match (p < 0.05, difference > 0.0) {
        (true, true) => "ahead of its inputs' rates beyond the folds' noise",
        (true, false) => "behind its inputs' rates beyond the folds' noise",
        (false, _) => "not shown to differ from its inputs' rates",
    };
    format!("{}: {verdict}", versus_text(difference, p))
}

/// `+12.3 points (p 0.0004)`.
pub(super) fn versus_text(difference: f64, p: f64) -> String {
    format!("{} points (p {})", signed(100.0 * difference), p_text(p))
}

/// `text` with its first letter a capital.
fn capitalised(text: &str) -> String {
    let mut chars = text.chars();
    match chars.next() {
        Some(first) => first.to_uppercase().chain(chars).collect(),
        None => String::new(),
    }
}

fn p_text(p: f64) -> String {
    if p < 0.001 {
        "< 0.001".into()
    } else {
        format!("{p:.3}")
    }
}

fn nested_text(n: &Nested) -> String {
    format!("{}{}", with_interval(n.accuracy, n.ci), nested_details(n))
}

/// What follows the nested estimate: over how many outer splits, how they ranked, and
/// what they picked.
fn nested_details(n: &Nested) -> String {
    let chosen: Vec<String> = n
        .chosen
        .iter()
        .map(|(name, times)| format!("{name} ({times} of {})", n.outer_splits))
        .collect();
    let inner = match n.inner.is_empty() {
        true => String::new(),
        false => format!("; ranked by {}", n.inner),
    };
    format!(
        " over {} outer splits{inner}; picked inside the training sets (how stable the choice is): {}",
        n.outer_splits,
        chosen.join(", ")
    )
}

/// compare.json, compare.md and the figures (SVG and PNG), written as one folder `dir`
/// that replaces an earlier comparison there as a whole ([`replace_dir`]); the figures name
/// the dataset folder `dataset`.
///
/// # Errors
/// A figure cannot be drawn; the folder cannot be written or holds files that are not an
/// earlier comparison's.
pub fn write_comparison(dir: &Path, c: &Comparison, dataset: &Path) -> Result<()> {
    let source = folder_source(dataset);
    let json = serde_json::to_string_pretty(c)
        .map_err(|e| DataError::invalid(dir.join("compare.json"), e.to_string()))?;
    let mut files = vec![
        ("compare.json".to_string(), (json + "\n").into_bytes()),
        ("compare.md".to_string(), markdown(c).into_bytes()),
    ];
    let mut svgs = vec![("ranking.svg", figures::ranking(c, &source))];
    if let Some(figure) = figures::per_condition(c) {
        svgs.push(("per_condition.svg", figure.draw(&source)));
    }
    for (name, svg) in svgs {
        let failed = |e: FigureError| DataError::invalid(dir.join(name), e.to_string());
        files.extend(svg_and_png(name, svg.map_err(failed)?).map_err(failed)?);
    }
    replace_dir(dir, |tmp| {
        for (name, bytes) in &files {
            let path = tmp.join(name);
            std::fs::write(&path, bytes).map_err(|e| DataError::write(&path, e))?;
        }
        Ok(())
    })
}
