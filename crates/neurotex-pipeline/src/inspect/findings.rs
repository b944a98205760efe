//! The rules that turn an inspection's numbers into findings, each with its severity and
//! the option that addresses it.

use serde::Serialize;

use super::design::{Design, Support};
use super::{InspectParams, Inspection, SignalSummary};
use crate::diagnostics::{TaxelDiagnostics, TaxelResponse};
use crate::import::{grid_advice, ImportWarning, OFFSET_RATIO};
use crate::recording::LayoutFile;
use neurotex_core::words::counted;

/// How much a finding matters.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Severity {
    /// Worth knowing; nothing is wrong.
    Note,
    /// Probably not what was meant, or weakens an analysis.
    Warning,
    /// An analysis will fail or mislead unless it is addressed.
    Severe,
}

impl Finding {
    /// The finding and what to try, on one line.
    pub fn line(&self) -> String {
        format!("{}; try: {}", self.message, self.suggestion)
    }
}

impl std::fmt::Display for Severity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Severity::Note => "note",
            Severity::Warning => "warning",
            Severity::Severe => "severe",
        })
    }
}

/// One finding.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Finding {
    /// How much it matters.
    pub severity: Severity,
    /// `design`, `layout`, `signals` or `encoder`.
    pub area: &'static str,
    /// A short name for the rule, stable for scripts and tests (`grid-not-filled`).
    pub code: &'static str,
    /// What was found, in numbers.
    pub message: String,
    /// What to do about it: the option first.
    pub suggestion: String,
}

pub(super) fn finding(
    severity: Severity,
    area: &'static str,
    code: &'static str,
    message: String,
    suggestion: impl Into<String>,
) -> Finding {
    Finding {
        severity,
        area,
        code,
        message,
        suggestion: suggestion.into(),
    }
}

/// `1 recording lasts` or `n recordings last`.
fn lasting(n: usize) -> String {
    match n {
        1 => "1 recording lasts".to_string(),
        n => format!("{n} recordings last"),
    }
}

/// At most the first three names, and how many more.
fn names(list: &[String]) -> String {
    let shown: Vec<String> = list.iter().take(3).map(|n| format!("`{n}`")).collect();
    match list.len() {
        n if n > 3 => format!("{} and {} more", shown.join(", "), n - 3),
        _ => shown.join(", "),
    }
}

/// Every finding of `i`, the most severe first.
pub(super) fn findings(i: &Inspection, file: &LayoutFile, p: &InspectParams) -> Vec<Finding> {
    let mut out = Vec::new();
    design(i, &mut out);
    layout(i, &mut out);
    signals(i, file, p, &mut out);
    encoder(i, p, &mut out);
    out.sort_by_key(|f| std::cmp::Reverse(f.severity));
    out
}

fn design(i: &Inspection, out: &mut Vec<Finding>) {
    use Severity::*;
    let d = &i.design;
    if d.classes.len() < 2 {
        out.push(finding(
            Severe,
            "design",
            "one-class",
            format!(
                "{} class(es) among the recordings: a classifier needs at least 2",
                d.classes.len()
            ),
            "--name-pattern with a {label} field, or a manifest with each recording's class",
        ));
        return;
    }
    out.extend(labels_differing_in_case(&d.classes));
    let [pooled, within, held_out, knn] = &d.support[..] else {
        return;
    };
    // Counts are of the recordings read: an unreadable file is one fewer.
    let read = match i.signals.unreadable.len() {
        0 => String::new(),
        n => format!(
            " (counted over the recordings read: {n} file(s) could not be read, see `unreadable`)"
        ),
    };
    if !pooled.supported {
        out.push(finding(
            Severe,
            "design",
            "folds",
            format!("{}: {}{read}", pooled.analysis, pooled.why),
            fewer_folds(pooled.limit),
        ));
    }
    by_speed(d, within, held_out, &read, out);
    if !knn.supported && pooled.supported {
        out.push(finding(
            Warning,
            "design",
            "neighbours",
            format!("{}: {}", knn.analysis, knn.why),
            match knn.limit {
                0 => {
                    "more recordings per class (or fewer folds, leaving more in each training fold)"
                        .to_string()
                }
                n => format!("--k {n} or fewer, or more recordings per class"),
            },
        ));
    }
    unbalanced(i, out);
}

/// A severe finding when two of the `classes` (distinct labels) differ only in case
/// (`Rough`, `rough`): neurotex keeps them apart, as two classes, where they most likely
/// name one texture written two ways, which splits its recordings and scores each half
/// against the other.
pub(super) fn labels_differing_in_case(classes: &[String]) -> Option<Finding> {
    let same = crate::recording::labels_differing_in_case(classes)?;
    let shown: Vec<String> = same.iter().map(|c| format!("`{c}`")).collect();
    Some(finding(
        Severity::Severe,
        "labels",
        "labels-differing-in-case",
        format!(
            "labels {} differ only in case: they are {} classes, each with part of what is most likely one texture's recordings",
            shown.join(" and "),
            same.len()
        ),
        "write one texture's label the same way in every manifest row (or file name); labels of truly different textures should differ in more than case",
    ))
}

/// The analyses by speed: none without speeds, folds within each, one held out.
fn by_speed(d: &Design, within: &Support, held_out: &Support, read: &str, out: &mut Vec<Finding>) {
    use Severity::*;
    if d.speeds().is_empty() {
        out.push(finding(
            Warning,
            "design",
            "no-speeds",
            "the recordings have no speed_mm_s: reproduce's analyses by speed cannot run".into(),
            "--name-pattern with a {speed} field (mm/s), or a speed_mm_s column in the manifest",
        ));
    } else {
        if !within.supported {
            out.push(finding(
                Severe,
                "design",
                "folds-within-speed",
                format!("{}: {}{read}", within.analysis, within.why),
                fewer_folds(within.limit),
            ));
        }
        if !held_out.supported {
            out.push(finding(
                Note,
                "design",
                "one-speed",
                format!("{}: {}", held_out.analysis, held_out.why),
                "recordings at a second speed",
            ));
        }
    }
}

/// Classes of very different sizes at some condition.
fn unbalanced(i: &Inspection, out: &mut Vec<Finding>) {
    let d = &i.design;
    // Unbalanced enough to matter: a largest class at least 1.5 times the smallest, and
    // its share at least 1.2 times one over the classes.
    let matters = |c: &&super::Condition| {
        let present = c.counts.iter().filter(|&&n| n > 0).count().max(1);
        c.imbalance() >= 1.5 && c.chance >= 1.2 / present as f64
    };
    let worst = (d.conditions.iter())
        .filter(matters)
        .max_by(|a, b| a.chance.total_cmp(&b.chance));
    if let Some(c) = worst {
        let at = c.speed_mm_s.map_or("over all recordings".to_string(), |s| {
            format!("at {s} mm/s")
        });
        let present = c.counts.iter().filter(|&&n| n > 0).count().max(1);
        out.push(finding(Severity::Warning, "design", "unbalanced", format!("the classes are unbalanced {at}: from {} to {} recordings a class, so chance there is the largest class's share, {:.2}, not 1/{present} = {:.2}", c.counts.iter().filter(|&&n| n > 0).min().unwrap_or(&0), c.counts.iter().max().unwrap_or(&0), c.chance, 1.0 / present as f64), "read each accuracy against the largest class's share (evaluate gives it beside one over the classes)"));
    }
}

fn fewer_folds(smallest: usize) -> String {
    match smallest {
        0 | 1 => "more recordings: each class needs at least 2 for any cross-validation".into(),
        n => format!("--folds {n} (each class has at least {n} recordings), or more recordings"),
    }
}

fn layout(i: &Inspection, out: &mut Vec<Finding>) {
    use Severity::*;
    let l = &i.layout;
    let n = l.channels.len();
    if l.rows == 1 && n >= 4 {
        out.push(finding(Warning, "layout", "one-row", format!("the {n} channels form one row (1x{n}), so the GLCM's neighbours run along a line and the 2D- and 3D-GLCM see no second dimension of the sensor (ignore this if the taxels do lie on a line)"), grid_advice(n)));
    } else if !l.mapped && l.empty_cells > 0 {
        let w = ImportWarning::GridNotFilled {
            channels: n,
            rows: l.rows,
            cols: l.cols,
        };
        let fix = format!("{}; if the sensor is the full grid with taxels left out, give every channel and --drop-channels the missing ones, which keeps the others in their cells", grid_advice(n));
        out.push(finding(
            Warning,
            "layout",
            "grid-not-filled",
            w.to_string(),
            fix,
        ));
    }
}

fn signals(i: &Inspection, file: &LayoutFile, p: &InspectParams, out: &mut Vec<Finding>) {
    use Severity::*;
    let s = &i.signals;
    let logs = i.kind == "raw logs";
    if !s.unreadable.is_empty() {
        let first = &s.unreadable[0];
        let fix = match logs {
            true => "fix the files, or leave them out (import csv --skip-bad)",
            false => "fix the files, or remove their rows from manifest.csv",
        };
        out.push(finding(
            Severe,
            "signals",
            "unreadable",
            format!(
                "{} of {} cannot be read; the first: {}",
                s.unreadable.len(),
                counted(i.files, "file"),
                first.reason
            ),
            fix,
        ));
    }
    if !s.too_short.is_empty() {
        out.push(finding(
            Severe,
            "signals",
            "too-short",
            format!(
                "{} less than one {} ms bin of the rate volume: {}",
                lasting(s.too_short.len()),
                p.pipeline.volume.bin_ms,
                names(&s.too_short)
            ),
            "leave them out, or --bin-ms smaller than the shortest recording",
        ));
    }
    out.extend(dead_recordings(s, logs));
    channels(i, file, p, out);
    if !s.gappy.is_empty() {
        let worst = s
            .gappy
            .iter()
            .max_by(|a, b| a.longest_s.total_cmp(&b.longest_s))
            .expect("not empty");
        out.push(finding(Warning, "signals", "gaps", format!("{} recording(s) have gaps of {} or more median intervals in their stamps; the longest, {:.3} s, in `{}`; resampling draws a straight line through each", s.gappy.len(), super::signals::GAP_FACTOR, worst.longest_s, worst.file), "--max-gap-s, the longest pause a reader may fill (longer ones are refused)"));
    }
    if let (false, Some([_, mid, _])) = (s.off_rate.is_empty(), s.fs_hz) {
        out.push(finding(
            Warning,
            "signals",
            "rate-differs",
            format!(
                "{} sampled more than 5 % off the median rate of {mid:.2} Hz: {}",
                match s.off_rate.len() {
                    1 => "1 recording is".to_string(),
                    n => format!("{n} recordings are"),
                },
                names(&s.off_rate)
            ),
            "check the logger's settings; each file's stamps are used to resample it to 1 kHz",
        ));
    }
    if let Some([mid, _]) = s.jitter.filter(|j| j[0] > 0.5) {
        out.push(finding(Note, "signals", "jitter", format!("the intervals between stamps spread over {:.0} % of the median interval (5th to 95th percentile, median recording)", 100.0 * mid), "nothing to do: irregular stamps are resampled onto 1 ms"));
    }
    if s.merged_rows[0] > 0 {
        out.push(finding(Note, "signals", "repeated-stamps", format!("{} row(s) in {} file(s) share a time stamp with another row and were merged or dropped", s.merged_rows[0], s.merged_rows[1]), "--duplicate-stamps average|first|last|error chooses what repeated stamps become"));
    }
}

/// The recordings in which every channel holds one value from start to end.
fn dead_recordings(s: &SignalSummary, logs: bool) -> Option<Finding> {
    if s.dead.is_empty() {
        return None;
    }
    let fix = match logs {
        true => "fix or record them again, or leave them out of the import",
        false => "fix or record them again, or remove their rows from manifest.csv",
    };
    Some(finding(
        Severity::Severe,
        "signals",
        "dead-recordings",
        format!(
            "{} no signal, every channel one value from start to end: {}; each is classified by the encoder's answer to a constant input, whatever texture it was",
            match s.dead.len() {
                1 => "1 recording holds".to_string(),
                n => format!("{n} recordings hold"),
            },
            names(&s.dead)
        ),
        fix,
    ))
}

/// What the channels say: a clock, dead, copied or clipped channels, a resting offset.
fn channels(i: &Inspection, file: &LayoutFile, p: &InspectParams, out: &mut Vec<Finding>) {
    use Severity::*;
    let s = &i.signals;
    let logs = i.kind == "raw logs";
    if !s.short.is_empty() {
        out.push(finding(
            Warning,
            "signals",
            "short-recordings",
            format!(
                "{} less than a quarter of the median recording ({:.2} s): {}",
                lasting(s.short.len()),
                s.duration_s[1],
                names(&s.short)
            ),
            "check them (an aborted trial?); leave them out of the manifest or the logs if so",
        ));
    }
    let most = |share: f64| share > 0.5;
    let chans = &s.channels;
    let list = |f: &dyn Fn(&super::ChannelSummary) -> bool| -> Vec<String> {
        chans
            .iter()
            .filter(|c| f(c))
            .map(|c| c.name.clone())
            .collect()
    };
    let rising = list(&|c| most(c.rising_share));
    if let Some(clock) = rising.first() {
        let how = match (file.time_column.is_some(), logs) {
            (true, _) => format!("--channels without `{clock}` (a counter beside the time column)"),
            (false, true) => {
                format!("--time-column {clock} if it holds the stamps, else --channels without it")
            }
            (false, false) => {
                format!("re-import with --time-column {clock}, or --channels without it")
            }
        };
        out.push(finding(Severe, "signals", "time-as-channel", format!("channel(s) {} rise at every frame in most recordings, as a clock or counter does: a time column read as a taxel", names(&rising)), how));
    }
    let dead = list(&|c| most(c.dead_share));
    if !dead.is_empty() {
        let listed = dead.join(",");
        let how = match logs {
            true => format!("--drop-channels {listed} (the other taxels keep their cells; these cells are masked)"),
            false => format!("re-import with --drop-channels {listed} (the other taxels keep their cells; these cells are masked)"),
        };
        out.push(finding(Warning, "signals", "dead-channel", format!("channel(s) {} hold one value throughout most recordings: unconnected or stuck, they carry nothing of the texture (silent taxels, or steady firing when no baseline is removed)", names(&dead)), how));
    }
    for c in chans.iter().filter(|c| most(c.copy_share)) {
        let of = c.copy_of.as_deref().unwrap_or("another channel");
        out.push(finding(Warning, "signals", "copied-channel", format!("channel `{}` equals `{of}` at every frame in {:.0} % of the recordings: one signal counted as two taxels", c.name, 100.0 * c.copy_share), format!("--channels without `{}`", c.name)));
    }
    let clipped = list(&|c| most(c.clipped_share));
    if !clipped.is_empty() {
        out.push(finding(Warning, "signals", "clipped", format!("channel(s) {} sit at a converter's full scale (255, 1023, 4095, 16383 or 65535) in at least 1 % of the samples of most recordings: clipped, the pressure beyond is lost", names(&clipped)), "a lower sensor gain or wider range; or --channels without them if they are not taxels"));
    }
    let ratios: Vec<f64> = chans.iter().filter_map(|c| c.resting_ratio).collect();
    let resting = super::median(ratios);
    let baseline = p
        .pipeline
        .preprocess
        .baseline
        .or(file.baseline)
        .unwrap_or_default();
    let spreads: Vec<f64> = chans.iter().filter_map(|c| c.resting_spread).collect();
    let spread = super::median(spreads);
    if spread >= OFFSET_RATIO {
        out.push(finding(Warning, "signals", "drifting-rest", format!("each channel's resting level (its least sample) moves between recordings by {spread:.1} times its range (median channel; 10th to 90th percentile of the recordings): offline, each recording's own minimum (--baseline min) absorbs it, but causal conditioning (--causal, `neurotex stream`) subtracts one resting value fixed at training, so recordings resting above it fire throughout and those below stay silent, whatever the gain"), format!("--causal --drift-window-s 30 (each taxel's resting value tracked as its least input over the last 30 s, longer than a contact){}", match baseline {
            crate::recording::Baseline::None => "; and --baseline min offline",
            _ => "",
        })));
    }
    if baseline == crate::recording::Baseline::None && resting >= OFFSET_RATIO {
        out.push(finding(Severe, "signals", "resting-offset", format!("the channels rest at about {resting:.1} times their range above zero (median channel) and no baseline is removed, so the encoder, dividing by each recording's maximum, sees mostly the resting offset"), "--baseline min (each channel's minimum removed)"));
    }
}

fn encoder(i: &Inspection, p: &InspectParams, out: &mut Vec<Finding>) {
    use Severity::*;
    let Some(e) = &i.encoder else { return };
    let diagnostics = TaxelDiagnostics {
        ceiling_hz: e.ceiling_hz,
        taxels: (e.taxels.iter())
            .map(|t| TaxelResponse {
                taxel: t.name.clone(),
                silent_share: t.silent_share,
                saturated_share: t.saturated_share,
            })
            .collect(),
    };
    // At the ceiling, --gain auto is a remedy only where it would lower the gain.
    let auto = match &e.auto {
        Some(a) if diagnostics.mostly_at_ceiling() && a.gain >= e.gain => format!(
            "--baseline min (the resting offset removed); --gain auto would choose {} here (a median of {:.1} Hz), no lower than {}, so the gain is not what holds them at the ceiling",
            a.gain, a.median_hz, e.gain
        ),
        Some(a) => format!(
            "--gain auto (it would choose {} here, a median of {:.1} Hz)",
            a.gain, a.median_hz
        ),
        None => "--gain auto".to_string(),
    };
    if let Some(advice) = diagnostics.advice() {
        out.push(finding(
            Severe,
            "encoder",
            "taxels-unresponsive",
            format!("at gain {}: {advice}", e.gain),
            auto.clone(),
        ));
    } else {
        // A dead channel is silent at any gain: the dead-channel finding says what to do.
        let dead =
            |name: &str| (i.signals.channels.iter()).any(|c| c.name == name && c.dead_share > 0.5);
        let silent: Vec<String> = (diagnostics.silent().iter())
            .filter(|s| !dead(s))
            .map(|s| s.to_string())
            .collect();
        if !silent.is_empty() {
            out.push(finding(
                Warning,
                "encoder",
                "silent-taxels",
                format!(
                    "at gain {}, {} of {} taxels never fire in most recordings: {}",
                    e.gain,
                    silent.len(),
                    e.taxels.len(),
                    names(&silent)
                ),
                auto.clone(),
            ));
        }
    }
    if e.flat > 0 {
        out.push(finding(Warning, "encoder", "flat-recordings", format!("{} recording(s) have no positive signal in the selected phase and encode to no spikes", e.flat), "--baseline none if the baseline removes the whole signal; check slide_start_s and slide_end_s"));
    }
    match (&e.auto, &e.auto_error) {
        (Some(a), _) if p.gain_target.is_some() => out.push(finding(Note, "encoder", "gain-auto", format!("--gain auto chose a gain of {} (median {:.1} Hz over {} taxel x recording pairs with signal; target {} Hz), the gain checked here", a.gain, a.median_hz, a.pairs, a.target_hz), "nothing: evaluate, train, compare and reproduce choose it the same way with --gain auto")),
        (Some(a), _) => out.push(finding(Note, "encoder", "gain-auto", format!("--gain auto would choose a gain of {} (median {:.1} Hz over {} taxel x recording pairs with signal; target {} Hz); checked here: {}", a.gain, a.median_hz, a.pairs, a.target_hz, e.gain), "--gain auto on evaluate, train, compare and reproduce")),
        (None, Some(why)) => out.push(finding(Note, "encoder", "gain-auto", format!("--gain auto cannot choose a gain here: {why}"), "nothing, or more recordings with signal")),
        (None, None) => {}
    }
}
