//! The report's sections on time and speed: E5's recognition from a part of the slide and
//! E5c's causal decisions, E6's invariance to the sliding speed.

use crate::experiments::Results;
use crate::values::Speed;

use super::super::figures::{self, file};
use super::super::paper::{Paper, PAPER};
use super::super::table::Table;
use super::{bracket, figure, heading, list, paper_cell, pct, pct_in, skipped_section};
use neurotex_core::words::signed_one_decimal as signed;

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

pub(super) fn e5(r: &Results, paper: Option<&Paper>) -> String {
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
pub(super) fn e5c(r: &Results) -> String {
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
            "{} [{}, {}], {verdict}",
            signed(100.0 * c.difference),
            signed(100.0 * c.lower),
            signed(100.0 * c.upper)
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

pub(super) fn e6(r: &Results, paper: Option<&Paper>) -> String {
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
