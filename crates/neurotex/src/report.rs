//! The reproduction report: `report.md` with every table beside the paper's values,
//! `results.json`, and SVG figures, rendered from [`Results`].

use std::fmt::Write as _;
use std::path::Path;

use crate::error::{DataError, Result};
use crate::experiments::{claims, Results};
use crate::svg::{heat, Panel, Svg, PALETTE};

/// The paper's E1 accuracies (%), single taxel and 3D-GLCM, by speed (table II).
pub const PAPER_E1: [(f64, f64, f64); 3] =
    [(5.0, 75.0, 92.0), (10.0, 73.0, 88.0), (15.0, 72.0, 84.0)];
/// The paper's 2D-GLCM accuracies (%) by speed (table III).
pub const PAPER_E4_2D: [(f64, f64); 3] = [(5.0, 46.0), (10.0, 33.0), (15.0, 43.0)];
/// The paper's speed-invariance accuracies (%), single taxel and 3D-GLCM, by test speed (table IV).
pub const PAPER_E6: [(f64, f64, f64); 3] =
    [(5.0, 28.0, 54.0), (10.0, 30.0, 51.0), (15.0, 27.0, 40.0)];
/// The paper's time to recognition: fraction of the slide at which 3D-GLCM matches the
/// single taxel, by speed (section IV-D; 10 mm/s is not stated).
pub const PAPER_E5: [(f64, f64); 2] = [(5.0, 0.3), (15.0, 0.7)];

/// What the report says about where the data came from and how the run went.
#[derive(Debug, Clone)]
pub struct ReportContext {
    /// One paragraph on the dataset (simulated or a folder).
    pub dataset: String,
    /// The parameters, one `name: value` line each.
    pub parameters: Vec<String>,
    /// Total wall-clock seconds.
    pub total_seconds: f64,
    /// The command that produced the report.
    pub command: String,
    /// Whether the data come from the paper's design (the simulated rig), so the paper's
    /// values can stand beside ours speed by speed. For other data they are left out of the
    /// tables, since the paper's speeds are those of its own rig.
    pub paper_comparable: bool,
}

fn paper_lookup<T: Copy>(table: &[(f64, T)], speed: f64) -> Option<T> {
    table
        .iter()
        .find(|(s, _)| (s - speed).abs() < 1e-9)
        .map(|&(_, v)| v)
}

fn pct(a: f64) -> String {
    format!("{:.1}", 100.0 * a)
}

fn write_file(path: &Path, content: &str) -> Result<()> {
    let tmp = path.with_extension(format!(
        "{}.partial",
        path.extension().and_then(|e| e.to_str()).unwrap_or("")
    ));
    std::fs::write(&tmp, content).map_err(|e| DataError::io(&tmp, e))?;
    std::fs::rename(&tmp, path).map_err(|e| DataError::io(path, e))?;
    Ok(())
}

/// Writes `report.md`, `results.json` and `figures/*.svg` into `dir` (created if needed);
/// each file is written whole or not at all.
///
/// # Errors
/// The folder cannot be created or a file cannot be written.
pub fn write_report(dir: &Path, results: &Results, ctx: &ReportContext) -> Result<()> {
    let figures = dir.join("figures");
    std::fs::create_dir_all(&figures).map_err(|e| DataError::io(&figures, e))?;
    let json = serde_json::to_string_pretty(results)
        .map_err(|e| DataError::invalid(dir, e.to_string()))?;
    for (name, svg) in figures_of(results, ctx.paper_comparable) {
        write_file(&figures.join(name), &svg)?;
    }
    write_file(&dir.join("results.json"), &json)?;
    write_file(&dir.join("report.md"), &markdown(results, ctx))?;
    Ok(())
}

fn markdown(r: &Results, ctx: &ReportContext) -> String {
    let comparable = ctx.paper_comparable;
    let paper_e1 = |s: f64| {
        PAPER_E1
            .iter()
            .find(|p| comparable && (p.0 - s).abs() < 1e-9)
    };
    let paper_e6 = |s: f64| {
        PAPER_E6
            .iter()
            .find(|p| comparable && (p.0 - s).abs() < 1e-9)
    };
    let paper_of = |table: &[(f64, f64)], s: f64| {
        if comparable {
            paper_lookup(table, s)
        } else {
            None
        }
    };
    let mut md = String::new();
    let w = &mut md;
    let _ = writeln!(
        w,
        "# neurotex reproduction of Gupta, Nakagawa, Lepora and Thakor\n"
    );
    let _ = writeln!(w, "\"Spatio-temporal encoding improves neuromorphic tactile texture classification\": every analysis (E0-E8) run on the data below. **Our numbers are not the paper's**: we do not have its recordings, so the paper's values stand beside ours for comparison only; nothing was tuned to approach them.\n");
    let _ = writeln!(
        w,
        "Produced by `{}` in {:.1} s.\n",
        ctx.command, ctx.total_seconds
    );
    let _ = writeln!(w, "## Data\n\n{}\n", ctx.dataset);
    if !comparable {
        let _ = writeln!(w, "These are not the paper's recordings or its design, so the paper's values (8 textures at 5, 10, 15 mm/s on its own rig; E1 75/92, 73/88, 72/84 % single taxel/3D-GLCM) are not set beside ours speed by speed; the summary below compares conclusions only.\n");
    }
    let _ = writeln!(
        w,
        "{} recordings, labels {}, speeds {} mm/s.{}{}\n",
        r.recordings,
        r.labels.join(", "),
        r.speeds
            .iter()
            .map(|s| s.to_string())
            .collect::<Vec<_>>()
            .join(", "),
        if r.resampled > 0 {
            format!(
                " {} recordings were resampled to 1 kHz by linear interpolation.",
                r.resampled
            )
        } else {
            String::new()
        },
        if r.flat > 0 {
            format!(
                " {} recordings had no positive signal and gave no spikes.",
                r.flat
            )
        } else {
            String::new()
        }
    );
    let _ = writeln!(w, "## Summary: where we agree with the paper\n");
    for c in claims(r) {
        let (claim, holds, detail) = (c.statement, c.verdict.holds(), c.detail);
        let _ = writeln!(
            w,
            "- {} **{}**{}",
            if holds { "Agrees:" } else { "Does not agree:" },
            claim,
            if detail.is_empty() {
                String::new()
            } else {
                format!(" ({detail})")
            }
        );
    }
    let _ = writeln!(w);

    let _ = writeln!(w, "## E1: accuracy per speed, single taxel vs 3D-GLCM\n");
    let _ = writeln!(w, "Single taxel: the paper used \"a representative taxel\" without saying which; we report the mean over all taxels as the headline and the best taxel beside it (chosen after the fact, so optimistic). 5-fold stratified CV, mean over repeats.\n");
    let _ = writeln!(w, "| speed (mm/s) | single taxel, mean (%) | best taxel (%) | 3D-GLCM (%) | paper: single (%) | paper: 3D-GLCM (%) |");
    let _ = writeln!(w, "|---|---|---|---|---|---|");
    for s in &r.speeds {
        if let Some(e) = r.e1.get(*s) {
            let paper = paper_e1(s.mm_s());
            let _ = writeln!(
                w,
                "| {s} | {} | {} ({}) | {} ± {} | {} | {} |",
                pct(e.taxel_mean),
                pct(e.taxel_best),
                e.taxel_best_cell,
                pct(e.glcm3d),
                pct(e.glcm3d_std),
                paper.map_or("-".into(), |p| p.1.to_string()),
                paper.map_or("-".into(), |p| p.2.to_string())
            );
        }
    }
    let _ = writeln!(w, "\n![E1](figures/e1_accuracy.svg)\n");

    if let Some(e2) = &r.e2 {
        let _ = writeln!(w, "## E2: confusion matrices at {} mm/s\n", e2.speed);
        let _ = writeln!(w, "Rows are the true texture, columns the prediction; counts summed over CV repeats (and over taxels for the single taxel). The paper: the single taxel confuses scotch brite (SB) and styrofoam (STF) with the rug (TRug).\n");
        for (name, m) in [
            ("single taxel (all taxels)", &e2.taxel),
            ("3D-GLCM", &e2.glcm3d),
        ] {
            let _ = writeln!(w, "{name}, row percentages:\n");
            let _ = writeln!(w, "| true \\ predicted | {} |", e2.labels.join(" | "));
            let _ = writeln!(w, "|---|{}", "---|".repeat(e2.labels.len()));
            for (l, row) in e2.labels.iter().zip(m) {
                let total = row.iter().sum::<usize>().max(1) as f64;
                let cells: Vec<String> = row
                    .iter()
                    .map(|&v| format!("{:.0}", 100.0 * v as f64 / total))
                    .collect();
                let _ = writeln!(w, "| {l} | {} |", cells.join(" | "));
            }
            let _ = writeln!(w);
        }
        let _ = writeln!(w, "![E2](figures/e2_confusion.svg)\n");
    }

    if let Some(e3) = &r.e3 {
        let _ = writeln!(w, "## E3: spatial perturbation at {} mm/s\n", e3.speed);
        let _ = writeln!(w, "For each recording, n taxels chosen at random swap places among themselves (every chosen taxel moves; each recording gets its own draw); 3D-GLCM accuracy, mean ± std over {} draws. Unperturbed 3D-GLCM {} %, single taxel {} %. The paper: accuracy falls towards or below the single taxel as n grows.\n", e3.repeats, pct(e3.glcm3d), pct(e3.taxel_mean));
        let _ = writeln!(w, "| taxels moved | 3D-GLCM (%) |");
        let _ = writeln!(w, "|---|---|");
        for ((n, m), s) in e3.n.iter().zip(&e3.mean).zip(&e3.std) {
            let _ = writeln!(w, "| {n} | {} ± {} |", pct(*m), pct(*s));
        }
        let _ = writeln!(w, "\n![E3](figures/e3_perturbation.svg)\n");
    }

    let _ = writeln!(w, "## E4: temporal information removed (2D-GLCM)\n");
    let _ = writeln!(w, "| speed (mm/s) | single taxel (%) | 2D-GLCM (%) | 3D-GLCM (%) | paper: single | paper: 2D | paper: 3D |");
    let _ = writeln!(w, "|---|---|---|---|---|---|---|");
    for s in &r.speeds {
        if let Some(e) = r.e4.get(*s) {
            let p1 = paper_e1(s.mm_s());
            let _ = writeln!(
                w,
                "| {s} | {} | {} | {} | {} | {} | {} |",
                pct(e.taxel_mean),
                pct(e.glcm2d),
                pct(e.glcm3d),
                p1.map_or("-".into(), |p| p.1.to_string()),
                paper_of(&PAPER_E4_2D, s.mm_s()).map_or("-".into(), |v| v.to_string()),
                p1.map_or("-".into(), |p| p.2.to_string())
            );
        }
    }
    let _ = writeln!(w);

    let _ = writeln!(w, "## E5: time to recognition\n");
    let _ = writeln!(w, "3D-GLCM on the first part of the slide against the single taxel (mean over taxels) on all of it. The paper: 3D-GLCM matches at 30 % of the slide at 5 mm/s and 70 % at 15 mm/s.\n");
    for s in &r.speeds {
        if let Some(e) = r.e5.get(*s) {
            let cells: Vec<String> = e
                .fractions
                .iter()
                .zip(&e.glcm3d)
                .map(|(p, a)| format!("{:.0} %: {}", 100.0 * p, a.map_or("too short".into(), pct)))
                .collect();
            let _ = writeln!(
                w,
                "- {s} mm/s (single taxel, full slide: {} %): {}. First match: **{}** (paper: {}).",
                pct(e.taxel_full),
                cells.join(", "),
                e.first_match
                    .map_or("never".to_string(), |p| format!("{:.0} %", 100.0 * p)),
                paper_lookup(&PAPER_E5, s.mm_s())
                    .map_or("not stated".into(), |p| format!("{:.0} %", 100.0 * p))
            );
        }
    }
    let _ = writeln!(w, "\n![E5](figures/e5_time_to_recognition.svg)\n");

    let _ = writeln!(
        w,
        "## E6: speed invariance (train on the other speeds, test on one)\n"
    );
    if r.e6.is_empty() {
        let _ = writeln!(
            w,
            "Skipped: {}\n",
            r.skipped
                .get("e6")
                .map_or("no second speed", String::as_str)
        );
    } else {
        let _ = writeln!(w, "| test speed (mm/s) | trained on | single taxel (%) | 3D-GLCM (%) | paper: single | paper: 3D |");
        let _ = writeln!(w, "|---|---|---|---|---|---|");
        for s in &r.speeds {
            if let Some(e) = r.e6.get(*s) {
                let p = paper_e6(s.mm_s());
                let _ = writeln!(
                    w,
                    "| {s} | {} | {} | {} | {} | {} |",
                    e.train
                        .iter()
                        .map(|t| t.to_string())
                        .collect::<Vec<_>>()
                        .join(", "),
                    pct(e.taxel_mean),
                    pct(e.glcm3d),
                    p.map_or("-".into(), |p| p.1.to_string()),
                    p.map_or("-".into(), |p| p.2.to_string())
                );
            }
        }
        let _ = writeln!(w);
    }

    if let Some(e7) = &r.e7 {
        let _ = writeln!(w, "## E7: gain sweep at {} mm/s\n", e7.speed);
        let _ = writeln!(w, "Mean firing rate per taxel (Hz) for each gain and texture; the paper chose G = 8 as the balance between sparse responses (low G) and saturated, less discriminative ones (high G). ISI histograms per gain are in the figure.\n");
        let _ = writeln!(w, "| G | {} |", e7.sweep.labels.join(" | "));
        let _ = writeln!(w, "|---|{}", "---|".repeat(e7.sweep.labels.len()));
        for (g, rates) in e7.sweep.gains.iter().zip(&e7.rate_hz) {
            let _ = writeln!(
                w,
                "| {g} | {} |",
                rates
                    .iter()
                    .map(|r| format!("{r:.1}"))
                    .collect::<Vec<_>>()
                    .join(" | ")
            );
        }
        let _ = writeln!(w, "\n![E7](figures/e7_isi.svg)\n");
    }

    let _ = writeln!(w, "## E8: robustness to k\n");
    let _ = writeln!(w, "| speed (mm/s) | k | single taxel (%) | 3D-GLCM (%) |");
    let _ = writeln!(w, "|---|---|---|---|");
    for s in &r.speeds {
        if let Some(e) = r.e8.get(*s) {
            for ((k, t), g) in e.k.iter().zip(&e.taxel_mean).zip(&e.glcm3d) {
                let _ = writeln!(w, "| {s} | {k} | {} | {} |", pct(*t), pct(*g));
            }
        }
    }
    let _ = writeln!(w, "\nThe paper: the outperformance is robust to k.\n");

    if let Some(e0) = &r.e0 {
        let _ = writeln!(w, "## E0: PSTH and rate volume\n");
        let _ = writeln!(w, "Taxel r{}c{} at {} mm/s, first trial of {}: the PSTH ({} ms bins) beside the whole array's rate volume (rows: the 16 taxels, columns: 200 ms bins). The paper: the volumes differ more than the PSTHs.\n", e0.taxel[0], e0.taxel[1], e0.speed, e0.examples.iter().map(|e| e.label.as_str()).collect::<Vec<_>>().join(" and "), e0.psth_bin_ms);
        let _ = writeln!(w, "![E0](figures/e0_psth_volume.svg)\n");
    }

    if !r.skipped.is_empty() {
        let _ = writeln!(w, "## Skipped\n");
        for (k, v) in &r.skipped {
            let _ = writeln!(w, "- {k}: {v}");
        }
        let _ = writeln!(w);
    }
    let _ = writeln!(w, "## Parameters\n");
    for p in &ctx.parameters {
        let _ = writeln!(w, "- {p}");
    }
    let _ = writeln!(w, "\n## Timing (wall clock, s)\n");
    for (k, v) in &r.timing_s {
        let _ = writeln!(w, "- {k}: {v:.3}");
    }
    md
}

fn figures_of(r: &Results, comparable: bool) -> Vec<(&'static str, String)> {
    let mut out = vec![("e1_accuracy.svg", fig_e1(r, comparable))];
    if let Some(e) = &r.e2 {
        out.push(("e2_confusion.svg", fig_e2(e)));
    }
    if let Some(e) = &r.e3 {
        out.push(("e3_perturbation.svg", fig_e3(e)));
    }
    out.push(("e5_time_to_recognition.svg", fig_e5(r)));
    if let Some(e) = &r.e7 {
        out.push(("e7_isi.svg", fig_e7(e)));
    }
    if let Some(e) = &r.e0 {
        out.push(("e0_psth_volume.svg", fig_e0(e)));
    }
    out
}

fn legend(svg: &mut Svg, x: f64, y: f64, items: &[(&str, &str)]) {
    for (k, (name, colour)) in items.iter().enumerate() {
        let yy = y + 16.0 * k as f64;
        svg.rect(x, yy - 9.0, 12.0, 10.0, colour);
        svg.text(x + 16.0, yy, name, 11.0, "start", 0.0);
    }
}

fn fig_e1(r: &Results, comparable: bool) -> String {
    let mut svg = Svg::new(720.0, 360.0);
    let panel = Panel {
        x: 70.0,
        y: 40.0,
        w: 470.0,
        h: 260.0,
        y_min: 0.0,
        y_max: 100.0,
    };
    panel.axes(&mut svg, "E1: accuracy per speed", "accuracy (%)", 5, |v| {
        format!("{v:.0}")
    });
    let series = [
        "ours: single taxel (mean)",
        "ours: 3D-GLCM",
        "paper: single taxel",
        "paper: 3D-GLCM",
    ];
    let group = panel.w / r.speeds.len().max(1) as f64;
    for (k, s) in r.speeds.iter().enumerate() {
        let e = r.e1.get(*s);
        let paper = PAPER_E1
            .iter()
            .find(|p| comparable && (p.0 - s.mm_s()).abs() < 1e-9);
        let values = [
            e.map(|e| 100.0 * e.taxel_mean),
            e.map(|e| 100.0 * e.glcm3d),
            paper.map(|p| p.1),
            paper.map(|p| p.2),
        ];
        let bar = group / 5.5;
        for (j, v) in values.iter().enumerate() {
            if let Some(v) = v {
                let x = panel.x + group * k as f64 + bar * (0.75 + j as f64);
                svg.rect(
                    x,
                    panel.py(*v),
                    bar * 0.9,
                    panel.py(0.0) - panel.py(*v),
                    PALETTE[j],
                );
            }
        }
        svg.text(
            panel.x + group * (k as f64 + 0.5),
            panel.y + panel.h + 18.0,
            &format!("{s} mm/s"),
            12.0,
            "middle",
            0.0,
        );
    }
    legend(
        &mut svg,
        555.0,
        60.0,
        &series
            .iter()
            .zip(PALETTE)
            .map(|(a, b)| (*a, b))
            .collect::<Vec<_>>(),
    );
    svg.finish()
}

fn confusion_panel(
    svg: &mut Svg,
    x: f64,
    y: f64,
    size: f64,
    title: &str,
    labels: &[String],
    m: &[Vec<usize>],
) {
    let n = labels.len().max(1);
    let cell = size / n as f64;
    svg.text(x + size / 2.0, y - 28.0, title, 14.0, "middle", 0.0);
    for (i, row) in m.iter().enumerate() {
        let total = row.iter().sum::<usize>().max(1) as f64;
        for (j, &v) in row.iter().enumerate() {
            let f = v as f64 / total;
            svg.rect(
                x + j as f64 * cell,
                y + i as f64 * cell,
                cell,
                cell,
                &heat(f),
            );
            if v > 0 {
                let colour_text = format!("{:.0}", 100.0 * f);
                svg.text(
                    x + (j as f64 + 0.5) * cell,
                    y + (i as f64 + 0.62) * cell,
                    &colour_text,
                    10.0,
                    "middle",
                    0.0,
                );
            }
        }
        svg.text(
            x - 4.0,
            y + (i as f64 + 0.62) * cell,
            &labels[i],
            11.0,
            "end",
            0.0,
        );
    }
    for (j, l) in labels.iter().enumerate() {
        svg.text(x + (j as f64 + 0.5) * cell, y - 6.0, l, 10.0, "middle", 0.0);
    }
    svg.text(
        x + size / 2.0,
        y + size + 18.0,
        "predicted",
        12.0,
        "middle",
        0.0,
    );
}

fn fig_e2(e: &crate::experiments::E2) -> String {
    let mut svg = Svg::new(780.0, 400.0);
    confusion_panel(
        &mut svg,
        70.0,
        60.0,
        300.0,
        &format!("single taxel, {} mm/s (row %)", e.speed),
        &e.labels,
        &e.taxel,
    );
    confusion_panel(
        &mut svg,
        460.0,
        60.0,
        300.0,
        &format!("3D-GLCM, {} mm/s (row %)", e.speed),
        &e.labels,
        &e.glcm3d,
    );
    svg.text(20.0, 210.0, "true", 12.0, "middle", -90.0);
    svg.finish()
}

fn fig_e3(e: &crate::experiments::E3) -> String {
    let mut svg = Svg::new(720.0, 360.0);
    let panel = Panel {
        x: 70.0,
        y: 40.0,
        w: 600.0,
        h: 260.0,
        y_min: 0.0,
        y_max: 100.0,
    };
    panel.axes(
        &mut svg,
        &format!("E3: spatial perturbation, {} mm/s", e.speed),
        "3D-GLCM accuracy (%)",
        5,
        |v| format!("{v:.0}"),
    );
    let n = e.n.len() + 2;
    let slot = panel.w / n as f64;
    let bars: Vec<(String, f64, f64, &str)> =
        std::iter::once(("single".to_string(), e.taxel_mean, 0.0, "#555555"))
            .chain(std::iter::once((
                "none".to_string(),
                e.glcm3d,
                0.0,
                PALETTE[1],
            )))
            .chain(
                e.n.iter()
                    .zip(&e.mean)
                    .zip(&e.std)
                    .map(|((n, m), s)| (n.to_string(), *m, *s, PALETTE[0])),
            )
            .collect();
    for (k, (label, v, sd, colour)) in bars.iter().enumerate() {
        let x = panel.x + slot * k as f64 + slot * 0.15;
        svg.rect(
            x,
            panel.py(100.0 * v),
            slot * 0.7,
            panel.py(0.0) - panel.py(100.0 * v),
            colour,
        );
        if *sd > 0.0 {
            let cx = x + slot * 0.35;
            svg.line(
                cx,
                panel.py(100.0 * (v - sd)),
                cx,
                panel.py(100.0 * (v + sd)),
                "#000000",
                1.0,
                false,
            );
        }
        svg.text(
            x + slot * 0.35,
            panel.y + panel.h + 16.0,
            label,
            11.0,
            "middle",
            0.0,
        );
    }
    svg.text(
        panel.x + panel.w / 2.0,
        panel.y + panel.h + 34.0,
        "taxels moved (single = single taxel, none = unperturbed 3D-GLCM)",
        12.0,
        "middle",
        0.0,
    );
    svg.finish()
}

fn fig_e5(r: &Results) -> String {
    let speeds: Vec<(f64, &crate::experiments::E5Speed)> = r
        .speeds
        .iter()
        .filter_map(|s| r.e5.get(*s).map(|e| (s.mm_s(), e)))
        .collect();
    let h = 250.0;
    let mut svg = Svg::new(720.0, 40.0 + h * speeds.len().max(1) as f64);
    for (k, (s, e)) in speeds.iter().enumerate() {
        let panel = Panel {
            x: 70.0,
            y: 40.0 + h * k as f64,
            w: 600.0,
            h: h - 70.0,
            y_min: 0.0,
            y_max: 100.0,
        };
        panel.axes(
            &mut svg,
            &format!("E5: 3D-GLCM on part of the slide, {s} mm/s"),
            "accuracy (%)",
            4,
            |v| format!("{v:.0}"),
        );
        let slot = panel.w / (e.fractions.len() + 1) as f64;
        let x0 = panel.x + slot * 0.15;
        svg.rect(
            x0,
            panel.py(100.0 * e.taxel_full),
            slot * 0.7,
            panel.py(0.0) - panel.py(100.0 * e.taxel_full),
            "#555555",
        );
        svg.text(
            x0 + slot * 0.35,
            panel.y + panel.h + 16.0,
            "single",
            11.0,
            "middle",
            0.0,
        );
        for (j, (p, a)) in e.fractions.iter().zip(&e.glcm3d).enumerate() {
            let x = panel.x + slot * (j + 1) as f64 + slot * 0.15;
            if let Some(a) = a {
                svg.rect(
                    x,
                    panel.py(100.0 * a),
                    slot * 0.7,
                    panel.py(0.0) - panel.py(100.0 * a),
                    PALETTE[0],
                );
            }
            svg.text(
                x + slot * 0.35,
                panel.y + panel.h + 16.0,
                &format!("{:.0}%", 100.0 * p),
                11.0,
                "middle",
                0.0,
            );
        }
        let y = panel.py(100.0 * e.taxel_full);
        svg.line(panel.x, y, panel.x + panel.w, y, "#D55E00", 1.5, true);
    }
    svg.finish()
}

fn fig_e7(e: &crate::experiments::E7) -> String {
    let gains = &e.sweep.gains;
    let cols = 4usize;
    let rows = gains.len().div_ceil(cols).max(1);
    let (pw, ph) = (220.0, 170.0);
    let mut svg = Svg::new(60.0 + pw * cols as f64 + 120.0, 50.0 + ph * rows as f64);
    svg.text(
        30.0 + pw * cols as f64 / 2.0,
        22.0,
        &format!(
            "E7: ISI distribution per gain, {} mm/s (probability per {} ms bin)",
            e.speed, e.sweep.bin_ms
        ),
        14.0,
        "middle",
        0.0,
    );
    for (g, gain) in gains.iter().enumerate() {
        let (r, c) = (g / cols, g % cols);
        let dists: Vec<Vec<f64>> = e.sweep.counts[g]
            .iter()
            .map(|h| {
                let total = h.iter().sum::<u64>().max(1) as f64;
                h.iter().map(|&v| v as f64 / total).collect()
            })
            .collect();
        let y_max = dists
            .iter()
            .flatten()
            .copied()
            .fold(0.0, f64::max)
            .max(1e-9);
        let panel = Panel {
            x: 60.0 + pw * c as f64,
            y: 50.0 + ph * r as f64,
            w: pw - 40.0,
            h: ph - 50.0,
            y_min: 0.0,
            y_max,
        };
        panel.axes(&mut svg, &format!("G = {gain}"), "", 2, |v| {
            format!("{v:.2}")
        });
        for (li, d) in dists.iter().enumerate() {
            let n = d.len().max(2);
            let pts: Vec<(f64, f64)> = d
                .iter()
                .enumerate()
                .map(|(b, &v)| (panel.x + panel.w * b as f64 / (n - 1) as f64, panel.py(v)))
                .collect();
            svg.polyline(&pts, PALETTE[li % PALETTE.len()], 1.2);
        }
        svg.text(
            panel.x + panel.w / 2.0,
            panel.y + panel.h + 14.0,
            &format!(
                "ISI 0-{} ms",
                e.sweep.bin_ms as usize * (e.sweep.counts[g].first().map_or(1, |h| h.len()) - 1)
            ),
            10.0,
            "middle",
            0.0,
        );
    }
    let items: Vec<(&str, &str)> = e
        .sweep
        .labels
        .iter()
        .enumerate()
        .map(|(i, l)| (l.as_str(), PALETTE[i % PALETTE.len()]))
        .collect();
    legend(&mut svg, 60.0 + pw * cols as f64, 60.0, &items);
    svg.finish()
}

fn fig_e0(e: &crate::experiments::E0) -> String {
    let rows = e.examples.len().max(1);
    let (h, w) = (220.0, 920.0);
    let mut svg = Svg::new(w, 30.0 + h * rows as f64);
    let vmax = e
        .examples
        .iter()
        .flat_map(|x| x.volume.iter().flatten())
        .copied()
        .fold(0.0, f64::max)
        .max(1e-9);
    for (k, ex) in e.examples.iter().enumerate() {
        let y0 = 40.0 + h * k as f64;
        let pmax = ex.psth.iter().copied().max().unwrap_or(1).max(1) as f64;
        let panel = Panel {
            x: 60.0,
            y: y0,
            w: 330.0,
            h: h - 70.0,
            y_min: 0.0,
            y_max: pmax,
        };
        panel.axes(
            &mut svg,
            &format!("{}: PSTH of taxel r{}c{}", ex.label, e.taxel[0], e.taxel[1]),
            &format!("spikes / {} ms", e.psth_bin_ms),
            3,
            |v| format!("{v:.0}"),
        );
        let bw = panel.w / ex.psth.len().max(1) as f64;
        for (b, &v) in ex.psth.iter().enumerate() {
            svg.rect(
                panel.x + bw * b as f64,
                panel.py(f64::from(v)),
                bw,
                panel.py(0.0) - panel.py(f64::from(v)),
                PALETTE[0],
            );
        }
        svg.text(
            panel.x + panel.w / 2.0,
            panel.y + panel.h + 16.0,
            "time in slide",
            11.0,
            "middle",
            0.0,
        );
        let vx = 470.0;
        let cells = ex.volume.len().max(1);
        let bins = ex.volume.first().map_or(1, Vec::len).max(1);
        let (cw, chh) = ((w - vx - 30.0) / bins as f64, (h - 70.0) / cells as f64);
        svg.text(
            vx + (w - vx - 30.0) / 2.0,
            y0 - 10.0,
            &format!(
                "{}: rate volume (taxel x 200 ms bin), max {:.0} Hz",
                ex.label, vmax
            ),
            14.0,
            "middle",
            0.0,
        );
        for (c, row) in ex.volume.iter().enumerate() {
            for (b, &v) in row.iter().enumerate() {
                svg.rect(
                    vx + cw * b as f64,
                    y0 + chh * c as f64,
                    cw + 0.3,
                    chh + 0.3,
                    &heat(v / vmax),
                );
            }
        }
        svg.text(vx - 6.0, y0 + (h - 70.0) / 2.0, "taxel", 11.0, "end", 0.0);
    }
    svg.finish()
}
