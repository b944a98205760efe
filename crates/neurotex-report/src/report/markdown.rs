//! `report.md`, one function per section. Sections only render: the verdicts come from
//! [`claims`], the numbers from [`Results`], and the paper's values from
//! [`Paper`](super::paper::Paper).

use crate::experiments::{claims, Results};

use super::figures::{self, file};
use super::paper::PAPER;
use super::table::Table;
use super::ReportContext;

mod e0_e4;
mod e5_e6;
mod e7_e9;

use e0_e4::{e0, e1, e2, e3, e4, encoder_sensitivity};
use e5_e6::{e5, e5c, e6};
use e7_e9::{e7, e8, e9};

fn pct(a: f64) -> String {
    format!("{:.1}", 100.0 * a)
}

/// An accuracy in % with its interval in brackets, where it has one.
fn pct_in(v: f64, interval: Option<&crate::classify::Interval>) -> String {
    interval.map_or(pct(v), |i| format!("{} {}", pct(v), bracket(i)))
}

fn list<T: ToString>(items: impl IntoIterator<Item = T>) -> String {
    items
        .into_iter()
        .map(|i| i.to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

/// An embedded figure with its alt text and caption.
fn figure(name: &str, alt: &str, caption: &str) -> String {
    format!("![{alt}](figures/{name})\n\n**Figure.** {caption}\n\n")
}

/// The paper's value in a table cell, or `-` where it gives none.
/// An interval as `[lower, upper]` in percent.
fn bracket(i: &crate::classify::Interval) -> String {
    format!("[{}, {}]", pct(i.lower), pct(i.upper))
}

fn paper_cell(v: Option<f64>) -> String {
    v.map_or("-".into(), |v| v.to_string())
}

/// A section's heading: what the analysis asks, then the paper's number for it (`E6`).
fn heading(asks: &str, id: &str) -> String {
    format!("## {asks} ({id})\n\n")
}

/// The section of an analysis that did not run: its heading and why (`None` when it ran).
fn skipped_section(r: &Results, key: &str, asks: &str, id: &str) -> Option<String> {
    let why = r.skipped.get(key)?;
    let sharing = r.skipped.values().filter(|w| *w == why).count();
    let text = match sharing {
        1 => format!("Skipped: {why}"),
        n => format!(
            "Skipped, with {} other analyses, for the reason under Skipped below.",
            n - 1
        ),
    };
    Some(heading(asks, id) + &text + "\n\n")
}

/// The whole report for `r`; deterministic for a given `r` and `ctx`.
pub fn markdown(r: &Results, ctx: &ReportContext) -> String {
    let paper = ctx.paper();
    [
        header(r, ctx),
        data(r, ctx),
        summary(r),
        across_seeds(r),
        encoder_sensitivity(r),
        e1(r, paper),
        e2(r),
        e3(r),
        e4(r, paper),
        e5(r, paper),
        e5c(r),
        e6(r, paper),
        e7(r),
        e8(r),
        e9(r),
        e0(r),
        skipped(r),
        parameters(r, ctx),
        timing(r),
    ]
    .concat()
}

fn header(r: &Results, ctx: &ReportContext) -> String {
    let beyond: Vec<&str> = [
        (!r.e5c.is_empty()).then_some("E5c (a live stream's time to recognition)"),
        r.e9.is_some()
            .then_some("E9 (the best of `neurotex compare`'s candidates)"),
    ]
    .into_iter()
    .flatten()
    .collect();
    let beyond = match beyond.as_slice() {
        [] => String::new(),
        names => format!(", and beyond it {}", names.join(" and ")),
    };
    let (title, what) = if ctx.paper_comparable {
        (
            "neurotex reproduction of Gupta, Nakagawa, Lepora and Thakor",
            "every analysis of the paper (E0-E8) run on the data below",
        )
    } else {
        (
            "neurotex analyses of a tactile dataset",
            "the paper's analyses, each named by what it asks with the paper's number for it (E0-E8), run on the data below",
        )
    };
    format!(
        "# {title}\n\n\
         Gupta, Nakagawa, Lepora and Thakor, \"Spatio-temporal encoding improves neuromorphic tactile texture classification\": {what}{beyond}. **Our numbers are not the paper's**: we do not have its recordings, so the paper's values stand beside ours for comparison only; nothing was tuned to approach them.\n\n\
         Produced by `{}`; its analyses took {:.1} s, reading and encoding the recordings included (writing this report and its figures not).\n\n",
        ctx.command, ctx.total_seconds
    )
}

fn paper_design() -> String {
    let e1: Vec<String> = PAPER
        .e1
        .iter()
        .map(|(_, t, g)| format!("{t}/{g}"))
        .collect();
    format!(
        "{} textures at {} mm/s on its own rig; E1 {} % single taxel/3D-GLCM",
        PAPER.textures,
        list(PAPER.speeds()),
        e1.join(", ")
    )
}

fn data(r: &Results, ctx: &ReportContext) -> String {
    let mut out = format!("## Data\n\n{}\n\n", ctx.dataset);
    if !ctx.paper_comparable {
        out += &format!("These are not the paper's recordings or its design, so the paper's values ({}) are not set beside ours speed by speed; the summary below compares conclusions only.\n\n", paper_design());
    }
    out += &format!(
        "{} recordings, {} classes ({}), speeds {} mm/s.",
        r.recordings,
        r.labels.len(),
        super::table::escape_html(&r.labels.join(", ")),
        list(&r.speeds)
    );
    if r.resampled > 0 {
        out += &format!(
            " {} recordings were resampled to 1 kHz by linear interpolation.",
            r.resampled
        );
    }
    if r.flat > 0 {
        out += &format!(
            " {} recordings had no positive signal and gave no spikes.",
            r.flat
        );
    }
    out + "\n\n" + &taxel_diagnostics(r)
}

/// Which taxels are silent or at the encoder's ceiling in most recordings.
fn taxel_diagnostics(r: &Results) -> String {
    let d = &r.taxels;
    let named = |names: Vec<&str>| {
        if names.is_empty() {
            "none".to_string()
        } else {
            names.join(", ")
        }
    };
    let busiest = |share: fn(&crate::experiments::TaxelResponse) -> f64| {
        let top = d.taxels.iter().max_by(|a, b| share(a).total_cmp(&share(b)));
        match top {
            Some(t) if share(t) > 0.0 => {
                format!("{} in {} % of recordings", t.taxel, pct(share(t)))
            }
            _ => "no taxel in any recording".to_string(),
        }
    };
    let advice = match d.advice() {
        Some(advice) => format!("**Warning:** {advice}.\n\n"),
        None => String::new(),
    };
    format!(
        "Taxels silent (no spike) in most recordings: {}; most often silent: {}. Taxels at the encoder's ceiling (at least {:.0} % of the {:.0} Hz a neuron reaches at the largest normalised input) in most recordings: {}; most often: {}. A silent or saturated taxel scores about the majority share whatever the texture, so the single-taxel mean is also given over the responsive taxels.\n\n{advice}",
        named(d.silent()),
        busiest(|t| t.silent_share),
        100.0 * crate::experiments::SATURATION_SHARE,
        d.ceiling_hz,
        named(d.saturated()),
        busiest(|t| t.saturated_share),
    )
}

fn summary(r: &Results) -> String {
    let mut out = format!("## Summary: the paper's claims on these data\n\n\
        A claim *holds* only when a paired comparison on the same recordings (95 % bootstrap interval of the per-recording difference, resampling recordings) puts it on the paper's side at every speed; it is *not shown to hold* when an interval holds 0, and *contradicted* when one lies on the other side. Claims without such a comparison are judged on point estimates and say so. Intervals are in brackets.{}\n\n",
        encodings_note(r)
    );
    for c in claims(r) {
        let verdict = format!("{}:", c.verdict.describe());
        let detail = if c.detail.is_empty() {
            String::new()
        } else {
            format!(" ({})", c.detail)
        };
        out += &format!("- {verdict} **{}**{detail}\n", c.statement);
    }
    out + "\n"
}

/// The headline accuracies and claims over several simulated datasets; empty with one.
fn across_seeds(r: &Results) -> String {
    let Some(a) = &r.across_seeds else {
        return String::new();
    };
    let n = a.seeds.len();
    let mut out = format!(
        "## Across simulated datasets\n\n\
         The analyses ran on {n} independent simulated datasets of the same design (simulation seeds {}); the sections below show the first. Each headline accuracy is given here as its mean over the {n} datasets with a 95 % Student-t interval over them (the spread a new dataset of this design would see; narrower than the range when datasets agree), the first dataset's value and the range. Each claim is judged on every dataset separately.{}\n\n",
        list(&a.seeds),
        r.encoder_sensitivity.as_ref().map_or(String::new(), |s| format!(
            " On every dataset, E1, E4, E6 and E8 are means over {} encodings of its recordings, as in the sections below; E3 uses the encoding as run.",
            s.encodings
        ))
    );
    let mut t = Table::new([
        "analysis",
        "condition",
        "method",
        "first dataset (%)",
        "mean (%) [95 % interval]",
        "range (%)",
    ]);
    for row in &a.accuracies {
        let interval = row.interval.as_ref().map_or(String::new(), bracket);
        let (lo, hi) = row.range();
        t.row([
            row.analysis.clone(),
            row.condition.clone(),
            row.method.clone(),
            row.values.first().map_or("-".into(), |v| pct(*v)),
            format!("{} {interval}", pct(row.mean())),
            format!("{}-{}", pct(lo), pct(hi)),
        ]);
    }
    out += &t.render();
    out += "\n";
    out += &figure(
        file::SEEDS,
        "E1 and E6 accuracies on each simulated dataset, with their means and intervals",
        &figures::across_seeds_caption(a),
    );
    let mut t = Table::new(["claim", "holds on", "verdicts"]);
    for c in &a.claims {
        t.row([
            c.statement.clone(),
            format!("{} of {n}", c.holds_on()),
            verdict_counts(&c.verdicts),
        ]);
    }
    out + &t.render() + "\n"
}

/// `Holds (paired test) x3, Not shown to hold (paired test not significant everywhere) x2`, in
/// first-seen order.
fn verdict_counts(verdicts: &[crate::experiments::Verdict]) -> String {
    let mut seen: Vec<(crate::experiments::Verdict, usize)> = Vec::new();
    for v in verdicts {
        match seen.iter_mut().find(|(w, _)| w == v) {
            Some((_, count)) => *count += 1,
            None => seen.push((*v, 1)),
        }
    }
    let parts: Vec<String> = seen
        .iter()
        .map(|(v, count)| format!("{} x{count}", v.describe()))
        .collect();
    parts.join(", ")
}

/// What E1's, E4's, E6's and E8's numbers are over, when the run has several encodings.
fn encodings_note(r: &Results) -> String {
    r.encoder_sensitivity.as_ref().map_or(String::new(), |s| {
        format!(
            " E1, E4, E6 and E8 are means over {} encodings of every recording, and their intervals resample the encodings too (see The encoder's sensitivity); the other analyses use the encoding as run.",
            s.encodings
        )
    })
}

fn skipped(r: &Results) -> String {
    if r.skipped.is_empty() {
        return String::new();
    }
    // One line per reason: a design too small skips every analysis of one kind alike.
    let mut reasons: Vec<(Vec<&str>, &str)> = Vec::new();
    for (key, why) in &r.skipped {
        match reasons.iter_mut().find(|(_, w)| w == why) {
            Some((keys, _)) => keys.push(key),
            None => reasons.push((vec![key.as_str()], why.as_str())),
        }
    }
    let lines: String = reasons
        .iter()
        .map(|(keys, why)| format!("- {}: {why}\n", keys.join(", ")))
        .collect();
    format!("## Skipped\n\n{lines}\n")
}

fn parameters(r: &Results, ctx: &ReportContext) -> String {
    let lines: String = ctx.parameters.iter().map(|p| format!("- {p}\n")).collect();
    let provenance = r.provenance.as_ref().map_or(String::new(), |p| {
        let commit = p
            .git_commit
            .as_deref()
            .unwrap_or("not built from a checkout");
        format!(
            "\nneurotex {} (commit {commit}), started {}; data: {}.\n",
            p.neurotex_version, p.created_utc, p.data
        )
    });
    format!("## Parameters\n\n{lines}{provenance}\n")
}

fn timing(r: &Results) -> String {
    if r.timing_s.is_empty() {
        return String::new();
    }
    let mut lines: String = r
        .timing_s
        .iter()
        .map(|(k, v)| format!("- {k}: {v:.3}\n"))
        .collect();
    let spiking = r.e9.as_ref().and_then(|e9| e9.spiking.as_ref());
    for (protocol, c) in spiking.iter().flat_map(|s| {
        [
            ("within each speed", &s.per_speed),
            ("with each speed held out", &s.held_out),
        ]
    }) {
        for x in &c.results {
            let who = match (x.paper, x.classifier.as_str()) {
                (true, _) => "the paper's method",
                (false, "snn") => "the spiking network",
                (false, _) => "the network's inputs' rates (logistic regression)",
            };
            lines += &format!("- e9, {who} {protocol}: {:.3}\n", x.seconds);
        }
    }
    format!("## Timing (wall clock, s)\n\n{lines}")
}
