//! `report.md`, one function per section. Sections only render: the verdicts come from
//! [`claims`], the numbers from [`Results`], and the paper's values from [`Paper`].

use super::figures::{self, file};
use super::paper::{Paper, PAPER};
use super::table::Table;
use super::ReportContext;
use crate::experiments::{claims, Results};
use crate::values::Speed;

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
        A claim *holds* only when a paired comparison on the same recordings (95 % bootstrap interval of the per-recording difference, resampling recordings) puts it on the paper's side at every speed; it is *not shown* when an interval holds 0, and *contradicted* when one lies on the other side. Claims without such a comparison are judged on point estimates and say so. Intervals are in brackets.{}\n\n",
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

/// `Holds (paired test) x3, Not shown (within noise) x2`, in first-seen order.
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

fn e1(r: &Results, paper: Option<&Paper>) -> String {
    let asks = "Accuracy per speed: single taxel against 3D-GLCM";
    if let Some(skipped) = skipped_section(r, "e1", asks, "E1") {
        return skipped;
    }
    let mut out = heading(asks, "E1") + &format!("\
        Single taxel: the paper used \"a representative taxel\" without saying which; we report the mean over all taxels as the headline, the mean over the responsive taxels (neither silent nor at the encoder's ceiling in most recordings; see Data) and the best taxel beside it (chosen after the fact, so optimistic). Chance is one over the classes recorded at that speed. Stratified cross-validation, mean over repeats (folds and repeats under Parameters); the 95 % intervals come from a percentile bootstrap over recordings (2000 resamples), each recording's predictions over repeats (and taxels) kept together; where every recording was right (or every one wrong) the bootstrap has no spread, and the Wilson score interval over the recordings is given instead.{}\n\n",
        encodings_note(r)
    );
    let mut header = vec![
        "speed (mm/s)",
        "classes (chance %)",
        "single taxel, mean (%) [95 % interval]",
        "responsive taxels, mean (%)",
        "best taxel (%)",
        "3D-GLCM (%) [95 % interval]",
    ];
    if paper.is_some() {
        header.extend(["paper: single (%)", "paper: 3D-GLCM (%)"]);
    }
    let mut t = Table::new(header);
    for (s, e) in r.e1.iter() {
        let mut row = vec![
            s.to_string(),
            format!("{} ({})", e.classes, pct(e.chance)),
            format!("{} {}", pct(e.taxel_mean), bracket(&e.taxel_mean_interval)),
            e.taxel_mean_responsive.map_or("-".into(), pct),
            format!("{} ({})", pct(e.taxel_best), e.taxel_best_cell),
            format!("{} {}", pct(e.glcm3d), bracket(&e.glcm3d_interval)),
        ];
        if let Some(p) = paper {
            let v = p.e1_at(s);
            row.extend([
                paper_cell(v.map(|v| v.taxel)),
                paper_cell(v.map(|v| v.glcm3d)),
            ]);
        }
        t.row(row);
    }
    out += &t.render();
    out += "\n";
    out += &figure(
        file::E1,
        "E1: bar chart of accuracy per speed, single taxel and 3D-GLCM",
        &figures::e1_caption(r, paper),
    );
    out
}

fn e2(r: &Results) -> String {
    let asks = "Which classes are confused";
    let Some(e2) = &r.e2 else {
        return skipped_section(r, "e2", asks, "E2").unwrap_or_default();
    };
    let mut out = heading(&format!("{asks}, at {} mm/s", e2.speed), "E2") + "\
        Rows are the true texture, columns the prediction; counts summed over CV repeats (and over taxels for the single taxel). The paper: the single taxel confuses scotch brite (SB) and styrofoam (STF) with the rug (TRug).\n\n";
    for (name, m) in [
        ("single taxel (all taxels)", &e2.taxel),
        ("3D-GLCM", &e2.glcm3d),
    ] {
        out += &format!("{name}, row percentages:\n\n");
        let mut t = Table::new(
            std::iter::once("true \\ predicted").chain(e2.labels.iter().map(String::as_str)),
        );
        for (label, row) in e2.labels.iter().zip(m) {
            let total = row.iter().sum::<usize>().max(1) as f64;
            let cells = row
                .iter()
                .map(|&v| format!("{:.0}", 100.0 * v as f64 / total));
            t.row(std::iter::once(label.clone()).chain(cells));
        }
        out += &t.render();
        out += "\n";
    }
    out + &figure(
        file::E2,
        "E2: confusion matrices of the single taxel and 3D-GLCM as heat maps",
        &figures::e2_caption(e2),
    )
}

fn e3(r: &Results) -> String {
    let asks = "Spatial perturbation: taxels moved";
    let Some(e3) = &r.e3 else {
        return skipped_section(r, "e3", asks, "E3").unwrap_or_default();
    };
    let mut out = heading(&format!("{asks}, at {} mm/s", e3.speed), "E3") + &format!("\
        For each recording, n taxels chosen at random swap places among themselves (every chosen taxel moves; each recording gets its own draw); 3D-GLCM accuracy, mean over {} draws, with a 95 % interval that holds both the recordings' and the draws' variability (a bootstrap that picks one draw, then the recordings), and the standard deviation over draws. Unperturbed 3D-GLCM {} %, single taxel {} %{}. The paper: accuracy falls towards or below the single taxel as n grows.\n\n",
        e3.repeats, pct(e3.glcm3d), pct(e3.taxel_mean),
        r.e1.get(e3.speed).map_or(String::new(), |e| format!(", chance {} %", pct(e.chance))));
    let mut t = Table::new([
        "taxels moved",
        "3D-GLCM (%) [95 % interval]",
        "std over draws (points)",
    ]);
    for (i, ((n, m), s)) in e3.n.iter().zip(&e3.mean).zip(&e3.std).enumerate() {
        t.row([n.to_string(), pct_in(*m, e3.interval.get(i)), pct(*s)]);
    }
    out += &t.render();
    out += "\n";
    out + &figure(
        file::E3,
        "E3: line chart of 3D-GLCM accuracy against the number of taxels moved",
        &figures::e3_caption(e3),
    )
}

fn e4(r: &Results, paper: Option<&Paper>) -> String {
    let asks = "Temporal information: 2D-GLCM without the time axis";
    if let Some(skipped) = skipped_section(r, "e4", asks, "E4") {
        return skipped;
    }
    let mut out = heading(asks, "E4");
    let mut header = vec![
        "speed (mm/s)",
        "chance (%)",
        "single taxel (%) [95 % interval]",
        "2D-GLCM (%) [95 % interval]",
        "3D-GLCM (%) [95 % interval]",
    ];
    if paper.is_some() {
        header.extend(["paper: single", "paper: 2D", "paper: 3D"]);
    }
    let mut t = Table::new(header);
    for (s, e) in r.e4.iter() {
        // The single taxel and 3D-GLCM are E1's, with E1's intervals.
        let e1 = r.e1.get(s);
        let with = pct_in;
        let mut row = vec![
            s.to_string(),
            e1.map_or("-".into(), |e| pct(e.chance)),
            with(e.taxel_mean, e1.map(|e| &e.taxel_mean_interval)),
            with(e.glcm2d, Some(&e.glcm2d_interval)),
            with(e.glcm3d, e1.map(|e| &e.glcm3d_interval)),
        ];
        if let Some(p) = paper {
            let e1 = p.e1_at(s);
            row.extend([
                paper_cell(e1.map(|v| v.taxel)),
                paper_cell(p.e4_2d_at(s)),
                paper_cell(e1.map(|v| v.glcm3d)),
            ]);
        }
        t.row(row);
    }
    out += &t.render();
    out += "\n";
    out + &figure(
        file::E4,
        "E4: bar chart of single taxel, 2D-GLCM and 3D-GLCM accuracy per speed",
        &figures::e4_caption(r, paper),
    )
}

/// The fractions of the slide E5 used at any speed, ascending.
fn e5_fractions(r: &Results) -> Vec<f64> {
    let mut all: Vec<f64> =
        r.e5.values()
            .flat_map(|e| e.fractions.iter().copied())
            .collect();
    all.sort_by(f64::total_cmp);
    all.dedup();
    all
}

fn e5(r: &Results, paper: Option<&Paper>) -> String {
    let stated: Vec<String> = PAPER
        .e5_first_match
        .iter()
        .map(|(s, p)| format!("{:.0} % of the slide at {s} mm/s", 100.0 * p))
        .collect();
    let asks = "Time to recognition";
    if let Some(skipped) = skipped_section(r, "e5", asks, "E5") {
        return skipped;
    }
    let mut out = heading(asks, "E5") + &format!("\
        3D-GLCM on the first part of the slide against the single taxel (mean over taxels) on all of it; accuracy (%) per share of the slide used with its 95 % interval (bootstrap over recordings), \"short\" where that part is shorter than one bin. The paper: 3D-GLCM matches at {}.\n\n", stated.join(" and "));
    let fractions = e5_fractions(r);
    let speeds: Vec<Speed> = r.e5.iter().map(|(s, _)| s).collect();
    let header = std::iter::once("accuracy (%) [95 % interval]".to_string())
        .chain(speeds.iter().map(|s| format!("{s} mm/s")));
    let mut t = Table::new(header);
    t.row(
        std::iter::once("chance".to_string()).chain(
            speeds
                .iter()
                .map(|&s| r.e1.get(s).map_or("-".into(), |e| pct(e.chance))),
        ),
    );
    t.row(
        std::iter::once("single taxel, whole slide".to_string()).chain(
            r.e5.values()
                .map(|e| pct_in(e.taxel_full, e.taxel_full_interval.as_ref())),
        ),
    );
    for &p in &fractions {
        let cells = r.e5.values().map(|e| {
            let at = e.fractions.iter().position(|&q| q == p);
            match at.map(|i| (e.glcm3d.get(i).copied().flatten(), i)) {
                Some((Some(a), i)) => pct_in(a, e.glcm3d_interval.get(i).and_then(Option::as_ref)),
                Some((None, _)) => "short".into(),
                None => "-".into(),
            }
        });
        t.row(std::iter::once(format!("3D-GLCM, first {:.0} %", 100.0 * p)).chain(cells));
    }
    let share = |p: Option<f64>| p.map_or("never".into(), |p| format!("{:.0} %", 100.0 * p));
    t.row(
        std::iter::once("3D-GLCM first matches at".to_string())
            .chain(r.e5.values().map(|e| share(e.first_match))),
    );
    if let Some(p) = paper {
        t.row(
            std::iter::once("paper: first match".to_string()).chain(speeds.iter().map(|&s| {
                p.e5_first_match_at(s)
                    .map_or("not stated".into(), |p| format!("{:.0} %", 100.0 * p))
            })),
        );
    }
    out += &t.render();
    out += "\n";
    out + &figure(
        file::E5,
        "E5: one line chart per speed of 3D-GLCM accuracy against the share of the slide used",
        &figures::e5_caption(r, paper),
    )
}

/// E5c: the causal pipeline over time, its time to decision and its cost.
fn e5c(r: &Results) -> String {
    let Some(first) = r.e5c.values().next() else {
        let asks = "Online time to recognition, causal";
        return skipped_section(r, "e5c", asks, "E5c, beyond the paper").unwrap_or_default();
    };
    let mut out = e5c_intro(first.decision.rule);
    out += &e5c_whole_slides(r);
    out += &e5c_shares(r);
    out += "\n";
    out + &figure(
        file::E5C_ACCURACY,
        "E5c: one line chart per speed of causal and offline 3D-GLCM accuracy against time into the slide",
        &figures::e5c_accuracy_caption(r),
    ) + &figure(
        file::E5C_DECISION,
        "E5c: one step chart per speed of the share of slides decided against time into the slide",
        &figures::e5c_decision_caption(r),
    )
}

/// E5c's heading and what it measures, with the decision rule's numbers.
fn e5c_intro(rule: crate::causal::DecisionRule) -> String {
    format!(
        "## Online time to recognition, causal (E5c, beyond the paper)\n\n\
         The paper's 3D-GLCM + KNN as a live classifier runs it (`neurotex stream`): causal conditioning (a forward-only low-pass; each taxel's resting value and one normalisation scale fixed per speed on **all of that speed's recordings, labels unused**, rather than inside each training fold: each recording is in some training fold, and fixing them per fold would encode every recording once per fold), trained on whole slides in the folds and repeats of E1, and classifying each test recording at every 200 ms bin boundary from the slide so far. \
         A decision is the first time one class holds at least {} of the vote in {} consecutive bins. \
         The cost of causal processing is the zero-phase 3D-GLCM (E1's folds, the encoding as run: the first column of The encoder's sensitivity, not E1's mean over encodings) minus the causal one on whole slides, per recording on the same folds (95 % bootstrap interval over recordings; a positive difference is accuracy lost).\n\n",
        rule.share, rule.bins
    )
}

/// E5c's table of whole slides and decisions, one row per speed.
fn e5c_whole_slides(r: &Results) -> String {
    let mut t = Table::new(vec![
        "speed (mm/s)",
        "recordings (chance %)",
        "scale (median slide max, fixed on)",
        "zero-phase 3D-GLCM, whole slide (%)",
        "causal 3D-GLCM, whole slide (%) [95 % interval]",
        "cost: zero-phase - causal (points) [95 % interval]",
        "median time to decision (s) [quartiles]",
        "median slide (s)",
        "never decided (%)",
        "decisions right (%)",
    ]);
    for (s, e) in r.e5c.iter() {
        t.row(e5c_whole_slide_row(s, e));
    }
    t.render()
}

/// One speed's row of [`e5c_whole_slides`].
fn e5c_whole_slide_row(s: Speed, e: &crate::experiments::E5CausalSpeed) -> Vec<String> {
    use crate::classify::PairedVerdict;
    let c = &e.offline_vs_causal;
    let verdict = match c.verdict {
        PairedVerdict::Supported => "causal lower",
        PairedVerdict::Contradicted => "causal higher",
        PairedVerdict::NotShown => "no difference shown",
    };
    let d = &e.decision;
    vec![
        s.to_string(),
        format!("{} ({})", e.n, pct(e.chance)),
        format!(
            "{:.4} ({} recordings)",
            e.calibration.conditioning.scale, e.calibration.recordings
        ),
        pct(e.offline),
        format!("{} {}", pct(e.whole), bracket(&e.whole_interval)),
        format!(
            "{:+.1} [{:+.1}, {:+.1}], {verdict}",
            100.0 * c.difference,
            100.0 * c.lower,
            100.0 * c.upper
        ),
        d.quartiles_s.map_or("-".into(), |q| {
            format!("{:.1} [{:.1}, {:.1}]", q[1], q[0], q[2])
        }),
        format!("{:.1}", e.median_slide_s),
        format!(
            "{:.1} ({} of {})",
            100.0 * d.never_share,
            d.episodes - d.decided,
            d.episodes
        ),
        d.accuracy.map_or("-".into(), pct),
    ]
}

/// E5c's causal against offline accuracy at E5's shares of the slide, with its
/// explanation; empty when no speed has shares.
fn e5c_shares(r: &Results) -> String {
    let mut fractions: Vec<f64> = r
        .e5c
        .values()
        .flat_map(|e| e.fractions.iter().map(|f| f.fraction))
        .collect();
    fractions.sort_by(f64::total_cmp);
    fractions.dedup();
    if fractions.is_empty() {
        return String::new();
    }
    let mut out = "\nCausal against offline at E5's shares of the slide, accuracy (%) as causal / offline, each with its 95 % interval (bootstrap over recordings): causal classifies each test recording at the last bin boundary within that share of its slide with the whole-slide classifier; the offline E5 trains and tests on that share of every slide, zero-phase (\"short\": some share is shorter than one bin).\n\n".to_string();
    let header = std::iter::once("share of the slide".to_string()).chain(
        r.e5c
            .iter()
            .map(|(s, _)| format!("{s} mm/s: causal / offline")),
    );
    let mut t = Table::new(header);
    let cell = |v: Option<f64>, i: Option<&crate::classify::Interval>| {
        v.map_or("short".into(), |v| pct_in(v, i))
    };
    for &p in &fractions {
        let cells = r
            .e5c
            .values()
            .map(|e| match e.fractions.iter().find(|f| f.fraction == p) {
                Some(f) => format!(
                    "{} / {}",
                    cell(f.causal, f.causal_interval.as_ref()),
                    cell(f.offline, f.offline_interval.as_ref())
                ),
                None => "-".into(),
            });
        t.row(std::iter::once(format!("first {:.0} %", 100.0 * p)).chain(cells));
    }
    out += &t.render();
    out
}

/// The training speeds of an E6 row: "all others" when that is what they are.
fn trained_on(all: &[Speed], test: Speed, train: &[Speed]) -> String {
    let others: Vec<Speed> = all.iter().copied().filter(|&s| s != test).collect();
    if others == train && train.len() > 2 {
        format!("the other {}", train.len())
    } else {
        list(train)
    }
}

fn e6(r: &Results, paper: Option<&Paper>) -> String {
    let mut out = heading(
        "Speed invariance: trained on the other speeds, tested on one",
        "E6",
    );
    if r.e6.is_empty() {
        let why = r
            .skipped
            .get("e6")
            .map_or("no second speed", String::as_str);
        return out + &format!("Skipped: {why}\n\n");
    }
    let mut header = vec![
        "test speed (mm/s)",
        "trained on (mm/s)",
        "chance (%)",
        "single taxel (%) [95 % interval]",
        "3D-GLCM (%) [95 % interval]",
    ];
    if paper.is_some() {
        header.extend(["paper: single", "paper: 3D"]);
    }
    let mut t = Table::new(header);
    for (s, e) in r.e6.iter() {
        let mut row = vec![
            s.to_string(),
            trained_on(&r.speeds, s, &e.train),
            pct(e.chance),
            format!("{} {}", pct(e.taxel_mean), bracket(&e.taxel_mean_interval)),
            format!("{} {}", pct(e.glcm3d), bracket(&e.glcm3d_interval)),
        ];
        if let Some(p) = paper {
            let v = p.e6_at(s);
            row.extend([
                paper_cell(v.map(|v| v.taxel)),
                paper_cell(v.map(|v| v.glcm3d)),
            ]);
        }
        t.row(row);
    }
    out += &t.render();
    out += "\n";
    out + &figure(
        file::E6,
        "E6: bar chart of accuracy per held-out speed, single taxel and 3D-GLCM",
        &figures::e6_caption(r, paper),
    )
}

fn e7(r: &Results) -> String {
    let Some(e7) = &r.e7 else {
        return String::new();
    };
    let asks = format!(
        "The encoder's gain: firing rates and intervals, at {} mm/s",
        e7.speed
    );
    let mut out = heading(&asks, "E7") + &format!("\
        Mean firing rate per taxel (Hz) for each gain and texture; the paper chose G = {} as the balance between sparse responses (low G) and saturated, less discriminative ones (high G).\n\n",
        super::paper::PAPER_GAIN);
    let mut t = Table::new(std::iter::once("G").chain(e7.sweep.labels.iter().map(String::as_str)));
    for (g, rates) in e7.sweep.gains.iter().zip(&e7.rate_hz) {
        t.row(std::iter::once(g.to_string()).chain(rates.iter().map(|r| format!("{r:.1}"))));
    }
    out += &t.render();
    out += "\n";
    out += &figure(
        file::E7_RATE,
        "E7: line chart of firing rate against gain, one line per texture",
        &figures::e7_rate_caption(e7),
    );
    out + &figure(
        file::E7_ISI,
        "E7: one panel per gain of the cumulative ISI distribution of each texture",
        &figures::e7_isi_caption(e7),
    )
}

fn e8(r: &Results) -> String {
    let asks = "Robustness to the number of neighbours k";
    if let Some(skipped) = skipped_section(r, "e8", asks, "E8") {
        return skipped;
    }
    let over = match r.e8.values().next().map_or(1, |e| e.encodings) {
        1 => "recordings".to_string(),
        n => format!("recordings and {n} encodings, as E1"),
    };
    let mut out = heading(asks, "E8") + &format!("Single taxel (mean over taxels) and 3D-GLCM accuracy (%) for each number of neighbours k, with 95 % intervals (bootstrap over {over}). The paper: the outperformance is robust to k.\n\n");
    let mut t = Table::new([
        "speed (mm/s)",
        "chance (%)",
        "k",
        "single taxel (%) [95 % interval]",
        "3D-GLCM (%) [95 % interval]",
    ]);
    for (s, e) in r.e8.iter() {
        let chance = r.e1.get(s).map_or("-".into(), |e| pct(e.chance));
        for (i, k) in e.k.iter().enumerate() {
            t.row([
                s.to_string(),
                chance.clone(),
                k.to_string(),
                pct_in(e.taxel_mean[i], e.taxel_mean_interval.get(i)),
                pct_in(e.glcm3d[i], e.glcm3d_interval.get(i)),
            ]);
        }
    }
    out += &t.render();
    out += "\n";
    out + &figure(
        file::E8,
        "E8: one line chart per speed of accuracy against k",
        &figures::e8_caption(r),
    )
}

fn e9(r: &Results) -> String {
    let asks = "The best of `neurotex compare`'s candidates";
    let Some(e9) = &r.e9 else {
        return skipped_section(r, "e9", asks, "E9, beyond the paper").unwrap_or_default();
    };
    let (within, held) = (&e9.per_speed, &e9.held_out);
    let mut out = format!(
        "## {asks} (E9, beyond the paper)\n\n\
         {} candidates (encodings, feature methods, classifiers: see `neurotex compare --help`) on the same folds: \
         accuracy (%) of the paper's method (SA, 3D-GLCM, KNN) and of the best candidate, cross-validated within each speed \
         and with each speed held out (trained on the others, E6's question). Intervals: 95 % bootstrap over {}. \
         E9 runs every candidate with its own number of cross-validation repeats (under Parameters; fewer than E1's by default) and on the encoding as run, \
         so its paper's-method accuracy may differ from E1's (a mean over more repeats and encodings) by a few points. \
         **Caveat**: {}.\n\n",
        within.results.len(),
        within.units,
        within.caveat
    );
    out += &e9_table(within, held);
    for (protocol, c) in [
        ("within each speed", within),
        ("with each speed held out", held),
    ] {
        if let Some(n) = &c.nested {
            let chosen: Vec<String> = n
                .chosen
                .iter()
                .map(|(c, k)| format!("{c} ({k} of {})", n.outer_splits))
                .collect();
            out += &format!(
                "\nNested selection {protocol} (the candidate chosen inside each training set; the number to quote): {} [{}, {}] % (chose {}).\n",
                pct(n.accuracy), pct(n.ci[0]), pct(n.ci[1]), chosen.join(", ")
            );
        }
    }
    out += &e9_baselines(e9.baselines.as_ref());
    out += &e9_spiking(e9.spiking.as_ref());
    out += "\n";
    out + &figure(
        file::E9_PER_SPEED,
        "E9: every candidate's accuracy within each speed, ranked, with nested selection",
        &figures::compare::ranking_caption(within),
    ) + &figure(
        file::E9_HELD_OUT,
        "E9: every candidate's accuracy with each speed held out, ranked, with nested selection",
        &figures::compare::ranking_caption(held),
    ) + &if figures::compare::per_condition(held).is_some() {
        figure(
            file::E9_SPEEDS,
            "E9: the best candidate, the paper's method and the best baseline without spikes at each held-out speed",
            &figures::compare::per_condition_caption(held, e9.held_out_baseline()),
        )
    } else {
        String::new()
    }
}

/// E9's baselines without spikes beside the spike candidates: the best of each protocol.
fn e9_baselines(baselines: Option<&crate::experiments::Baselines>) -> String {
    use crate::experiments::Baselines;
    let best = |c: &crate::compare::Comparison| {
        let b = &c.best;
        format!(
            "{} % [{}, {}] ({} / {} / {})",
            pct(b.accuracy),
            pct(b.ci[0]),
            pct(b.ci[1]),
            b.encoding,
            b.method,
            b.classifier
        )
    };
    match baselines {
        None => String::new(),
        Some(Baselines::Skipped(why)) => {
            format!("\nThe baselines without spikes were not run: {why}.\n")
        }
        Some(Baselines::Compared {
            per_speed,
            held_out,
        }) => format!(
            "\nBaselines without spikes on the same folds (`neurotex compare --encodings none`: the spectrum and the statistics of the conditioned signal the encoder receives, with each classifier; not among the candidates above): the best within each speed {}, with each speed held out {}. They say what the spikes cost or gain against the signal they are made from.\n",
            best(per_speed),
            best(held_out)
        ),
    }
}

/// The spiking network beside the paper's method on E9's folds (`reproduce --snn`).
fn e9_spiking(spiking: Option<&crate::experiments::Spiking>) -> String {
    use crate::experiments::Spiking;
    let Some(s) = spiking else {
        return String::new();
    };
    let (within, held) = (&s.per_speed, &s.held_out);
    let (Some((net_w, paper_w)), Some((net_h, paper_h))) =
        (Spiking::pair(within), Spiking::pair(held))
    else {
        return String::new();
    };
    let mut out = format!(
        "\n### The spiking network beside the paper's method\n\n\
         A spiking network (`--classifier snn`: one hidden layer of current-based leaky integrate-and-fire neurons and a leaky readout, \
         trained with surrogate gradients; see docs/spiking-classifier.md) reads the SA+FA spike trains themselves instead of features. \
         Its hyperparameters are its defaults, fixed before any data, so no selection flatters it; it ran on the same folds and the same encoding (as run) as the paper's method (SA, 3D-GLCM, KNN). \
         Accuracy (%), intervals 95 % bootstrap over {}; chance {} % within each speed and {} % with each speed held out.\n\n",
        within.units,
        pct(within.chance),
        pct(held.chance)
    );
    let mut t = Table::new(vec![
        "speed (mm/s)",
        "paper, within speed",
        "network, within speed",
        "paper, speed held out",
        "network, speed held out",
    ]);
    let columns = [paper_w, net_w, paper_h, net_h];
    for (i, c) in net_w.per_condition.iter().enumerate() {
        let at = |x: &&crate::compare::Ranked| {
            x.per_condition
                .get(i)
                .map_or("-".into(), |p| pct(p.accuracy))
        };
        t.row(std::iter::once(c.condition.clone()).chain(columns.iter().map(at)));
    }
    let mean = |x: &&crate::compare::Ranked| {
        format!("{} [{}, {}]", pct(x.accuracy), pct(x.ci[0]), pct(x.ci[1]))
    };
    t.row(std::iter::once("mean [95 % CI]".to_string()).chain(columns.iter().map(mean)));
    out += &t.render();
    out + &format!(
        "\nThe network against the paper's method (paired sign-flip test over {}): within each speed {}, with each speed held out {}. \
         Their training and testing times are under Timing.\n",
        within.units,
        super::comparison::versus_paper(net_w),
        super::comparison::versus_paper(net_h),
    )
}

/// E9's table: per speed, the paper's method and the best candidate within the speed and
/// with it held out; the means with their intervals last.
fn e9_table(within: &crate::compare::Comparison, held: &crate::compare::Comparison) -> String {
    use crate::compare::Ranked;
    let name = |x: &Ranked| format!("{} / {} / {}", x.encoding, x.method, x.classifier);
    let paper = |c: &crate::compare::Comparison| c.results.iter().find(|x| x.paper).cloned();
    let mut t = Table::new([
        "speed (mm/s)".to_string(),
        "paper, within speed".into(),
        format!("best within speed: {}", name(&within.best)),
        "paper, speed held out".into(),
        format!("best held out: {}", name(&held.best)),
    ]);
    let columns = [
        paper(within),
        Some(within.best.clone()),
        paper(held),
        Some(held.best.clone()),
    ];
    for (i, c) in within.best.per_condition.iter().enumerate() {
        let at = |x: &Option<Ranked>| {
            x.as_ref()
                .and_then(|x| x.per_condition.get(i))
                .map_or("-".into(), |p| pct(p.accuracy))
        };
        t.row(std::iter::once(c.condition.clone()).chain(columns.iter().map(at)));
    }
    let mean = |x: &Option<Ranked>| {
        x.as_ref().map_or("-".into(), |x| {
            format!("{} [{}, {}]", pct(x.accuracy), pct(x.ci[0]), pct(x.ci[1]))
        })
    };
    t.row(std::iter::once("mean [95 % CI]".to_string()).chain(columns.iter().map(mean)));
    t.render()
}

fn e0(r: &Results) -> String {
    let Some(e0) = &r.e0 else {
        return String::new();
    };
    heading("Spike trains and rate volumes of two classes", "E0")
        + &figure(
            file::E0,
            "E0: PSTH of one taxel beside the rate volume of the array, for two textures",
            &figures::e0_caption(e0),
        )
}

fn encoder_sensitivity(r: &Results) -> String {
    let Some(s) = &r.encoder_sensitivity else {
        return String::new();
    };
    let out = format!(
        "## The encoder's sensitivity\n\n\
         Spiking neurons turn a signal into threshold crossings: a neuron near its threshold fires a step earlier or later, or once more or less, when its input moves by far less than any sensor resolves, and those spikes move features and sometimes predictions. So E1, E4, E6 and E8 classify every recording under {n} encodings: as run, and {more} more with each input sample multiplied by 1 + u x {eps:e} (u uniform in [-1, 1), independent). Their accuracies are means over the encodings, their intervals resample encodings as well as recordings, and their claims are judged on those. One encoding's accuracy differs from another's by up to {spread} points here; the other analyses use the encoding as run, so a difference between them smaller than that is within the encoder's noise.\n\n",
        n = s.encodings,
        more = s.encodings - 1,
        eps = s.perturbation,
        spread = pct(s.largest_spread)
    );
    let mut t = Table::new(vec![
        "speed (mm/s)",
        "method",
        "as run (%) [95 % interval, recordings only]",
        "range over encodings (%)",
        "mean over encodings (%) [95 % interval, recordings and encodings]",
        "recordings whose spikes changed",
    ]);
    for (speed, e) in s.speeds.iter() {
        let methods = [
            ("3D-GLCM", &e.glcm3d),
            ("single taxel, mean", &e.taxel_mean),
            ("2D-GLCM", &e.glcm2d),
        ];
        for (name, a) in methods {
            let (lo, hi) = a.range();
            let i = &a.recordings_only;
            t.row(vec![
                speed.to_string(),
                name.to_string(),
                format!("{} {}", pct(i.estimate), bracket(i)),
                format!("{}-{}", pct(lo), pct(hi)),
                format!("{} {}", pct(a.mean()), bracket(&a.combined)),
                format!("{} of {}", e.recordings_changed, e.recordings),
            ]);
        }
    }
    out + &t.render() + "\n"
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
            let who = match x.paper {
                true => "the paper's method",
                false => "the spiking network",
            };
            lines += &format!("- e9, {who} {protocol}: {:.3}\n", x.seconds);
        }
    }
    format!("## Timing (wall clock, s)\n\n{lines}")
}
