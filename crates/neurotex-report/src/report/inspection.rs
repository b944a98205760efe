//! `inspect`'s outputs: lines for a terminal, `inspect.md` with its figures, and
//! `inspect.json`, all rendered from an [`Inspection`].

use std::fmt::Write as _;
use std::path::Path;

use super::figures::inspect as figs;
use super::figures::{svg_and_png, FigureError};
use super::folder_source;
use crate::error::{DataError, Result};
use crate::inspect::{EncoderCheck, Finding, Inspection, Severity};
use crate::io::replace_dir;

/// `a, b and 3 more`.
fn short_list(names: &[String], max: usize) -> String {
    let shown = names
        .iter()
        .take(max)
        .cloned()
        .collect::<Vec<_>>()
        .join(", ");
    match names.len() > max {
        true => format!("{shown} and {} more", names.len() - max),
        false => shown,
    }
}

/// A finding on one line, then its suggestion.
fn finding_lines(f: &Finding) -> [String; 2] {
    [
        format!("{}: [{}] {}", f.severity, f.area, f.message),
        format!("    try: {}", f.suggestion),
    ]
}

/// The inspection in a few lines for a terminal: what was read, the design, then every
/// finding with its suggestion.
pub fn text_lines(i: &Inspection) -> Vec<String> {
    let d = &i.design;
    let s = &i.signals;
    let l = &i.layout;
    let mut out = vec![format!(
        "{} recordings ({}): {} read, {} unreadable; {} classes ({})",
        i.files,
        i.kind,
        s.recordings,
        s.unreadable.len(),
        d.classes.len(),
        short_list(&d.classes, 6)
    )];
    let speeds: Vec<String> = (d.speeds().iter())
        .filter_map(|c| c.speed_mm_s)
        .map(|v| v.to_string())
        .collect();
    if !speeds.is_empty() {
        out.push(format!("speeds (mm/s): {}", short_list(&speeds, 12)));
    }
    let [dmin, dmid, dmax] = s.duration_s;
    if let Some(e) = &i.events {
        out.extend(event_lines(e, l, [dmin, dmid, dmax]));
    }
    let rate = match s.fs_hz {
        Some([lo, mid, hi]) => format!("stamps at {mid:.2} Hz (from {lo:.2} to {hi:.2})"),
        None => format!("no stamps; {:.2} Hz nominal", l.fs_hz),
    };
    if i.events.is_none() {
        let [dmin, dmid, dmax] = [dmin, dmid, dmax].map(seconds);
        out.push(format!(
        "{} channels on a {}x{} grid; {rate}; recordings of {dmid} s (median; from {dmin} to {dmax}); baseline removed: {}",
        l.channels.len(), l.rows, l.cols, l.baseline
    ));
    }
    if let Some(e) = &i.encoder {
        let silent = e.taxels.iter().filter(|t| t.silent_share > 0.5).count();
        let mut rates: Vec<f64> = e.taxels.iter().map(|t| t.median_hz).collect();
        rates.sort_by(f64::total_cmp);
        let mid = rates.get(rates.len() / 2).copied().unwrap_or(0.0);
        out.push(format!(
            "encoder ({}) at gain {}: median taxel {mid:.1} Hz, {silent} of {} taxels silent in most recordings",
            neurons(e),
            e.gain,
            e.taxels.len()
        ));
    }
    match i.findings.is_empty() {
        true => out.push("no findings".to_string()),
        false => {
            for f in &i.findings {
                out.extend(finding_lines(f));
            }
        }
    }
    out
}

/// An event dataset's grid, lengths and events, for [`text_lines`].
fn event_lines(
    e: &crate::events::EventSummary,
    l: &crate::inspect::LayoutSummary,
    [dmin, dmid, dmax]: [f64; 3],
) -> Vec<String> {
    let [emin, emid, emax] = e.events;
    let silent = e.cells.iter().filter(|c| c.silent_share > 0.5).count();
    let mut rates: Vec<f64> = e
        .cells
        .iter()
        .map(|c| c.on_hz + c.off_hz.unwrap_or(0.0))
        .collect();
    rates.sort_by(f64::total_cmp);
    let mid = rates.get(rates.len() / 2).copied().unwrap_or(0.0);
    let polarity = match e.on_share {
        Some(share) => format!("{} ON", percent(share)),
        None => "ON only (no polarity column)".to_string(),
    };
    let [dmin, dmid, dmax] = [dmin, dmid, dmax].map(seconds);
    vec![
        format!(
            "address events on a {}x{} grid ({} cells), times in {}; recordings of {dmid} s (median; from {dmin} to {dmax})",
            l.rows,
            l.cols,
            e.cells.len(),
            e.time_unit
        ),
        format!(
            "{emid} events a recording (from {emin} to {emax}), {polarity}; median cell {mid:.1} events/s; {silent} of {} cells silent in most recordings; {} of the events merged into the spike of their millisecond",
            e.cells.len(),
            percent(e.merged_share)
        ),
    ]
}

/// A markdown table.
fn table(header: &[&str], rows: &[Vec<String>]) -> String {
    let mut out = format!("| {} |\n", header.join(" | "));
    let _ = writeln!(out, "|{}", "---|".repeat(header.len()));
    for r in rows {
        let _ = writeln!(out, "| {} |", r.join(" | "));
    }
    out
}

fn optional(v: Option<f64>, digits: usize) -> String {
    v.map_or("-".to_string(), |v| format!("{v:.digits$}"))
}

fn percent(share: f64) -> String {
    format!("{:.0} %", 100.0 * share)
}

/// `inspect.md`: the findings first, then the design, the layout, the signals, the encoder
/// and the figures (`figures` names the ones written).
pub fn markdown(i: &Inspection, source: &str, figures: &[(&str, String)]) -> String {
    let mut md = format!("# Inspection of {source}\n\n");
    md += &format!(
        "{} recordings ({}) found; {} read.\n\n",
        i.files, i.kind, i.signals.recordings
    );
    md += "## Findings\n\n";
    if i.findings.is_empty() {
        md += "No findings.\n\n";
    }
    for sev in [Severity::Severe, Severity::Warning, Severity::Note] {
        for f in i.findings.iter().filter(|f| f.severity == sev) {
            md += &format!(
                "- **{}** ({}, `{}`): {}. Try: {}.\n",
                f.severity, f.area, f.code, f.message, f.suggestion
            );
        }
    }
    md += "\n## Design\n\n";
    let d = &i.design;
    let mut header: Vec<String> = vec!["class".into(), "all".into()];
    header.extend(
        d.speeds()
            .iter()
            .filter_map(|c| c.speed_mm_s)
            .map(|s| format!("{s} mm/s")),
    );
    let rows: Vec<Vec<String>> = (0..d.classes.len())
        .map(|k| {
            let mut row = vec![d.classes[k].clone()];
            row.extend(d.conditions.iter().map(|c| c.counts[k].to_string()));
            row
        })
        .chain(std::iter::once({
            let mut row = vec!["chance (largest class)".to_string()];
            row.extend(d.conditions.iter().map(|c| format!("{:.3}", c.chance)));
            row
        }))
        .collect();
    let header: Vec<&str> = header.iter().map(String::as_str).collect();
    md += &table(&header, &rows);
    md += "\nGroups the manifest names: ";
    let groups: Vec<String> = d
        .groups
        .iter()
        .map(|g| format!("`{}` ({} values)", g.column, g.values))
        .collect();
    md += &match groups.is_empty() {
        true => "none.\n\n".to_string(),
        false => format!(
            "{}; `--group-by COLUMN` keeps each group in one fold.\n\n",
            groups.join(", ")
        ),
    };
    let support: Vec<Vec<String>> = (d.support.iter())
        .map(|s| {
            vec![
                s.analysis.clone(),
                if s.supported { "yes" } else { "**no**" }.into(),
                s.why.clone(),
            ]
        })
        .collect();
    md += &table(&["analysis", "supported", "why"], &support);
    md += &layout_section(i);
    match &i.events {
        Some(e) => md += &events_section(i, e),
        None => {
            md += &signals_section(i);
            md += &encoder_section(i);
        }
    }
    md += "\n## Figures\n\n";
    for (name, caption) in figures {
        md += &format!("![{name}](figures/{name}.png)\n\n{caption}\n\n");
    }
    md
}

fn layout_section(i: &Inspection) -> String {
    let l = &i.layout;
    let mut md = format!(
        "\n## Layout\n\n{} channels on a {}x{} grid ({}), {} without a channel, {} neighbouring pairs for the GLCM; baseline removed: {}; nominal rate {:.2} Hz.\n\n```\n",
        l.channels.len(), l.rows, l.cols,
        if l.mapped { "placed by a channel map" } else { "row by row in channel order" },
        neurotex_core::words::counted(l.empty_cells, "cell"), l.neighbour_pairs, l.baseline, l.fs_hz
    );
    let width = l.channels.iter().map(String::len).max().unwrap_or(1).max(1);
    for r in 0..l.rows {
        let cells: Vec<String> = (0..l.cols)
            .map(|c| {
                let name = l
                    .cells
                    .iter()
                    .position(|&x| x == [r, c])
                    .map_or(".", |k| l.channels[k].as_str());
                format!("{name:>width$}")
            })
            .collect();
        md += &cells.join(" ");
        md += "\n";
    }
    md + "```\n"
}

fn signals_section(i: &Inspection) -> String {
    let s = &i.signals;
    let mut md = "\n## Signals\n\n".to_string();
    if let Some([lo, mid, hi]) = s.fs_hz {
        md += &format!("Stamps: {mid:.2} Hz median rate (from {lo:.2} to {hi:.2} over recordings)");
        if let Some([j, jmax]) = s.jitter {
            md += &format!(
                "; intervals spread over {:.0} % of the median interval (largest {:.0} %)",
                100.0 * j,
                100.0 * jmax
            );
        }
        md += &format!(
            "; {} with gaps.\n",
            neurotex_core::words::counted(s.gappy.len(), "recording")
        );
    } else {
        md += "No time stamps: the nominal rate is used.\n";
    }
    let [lo, mid, hi] = s.duration_s.map(seconds);
    md += &format!("Durations: {mid} s median (from {lo} to {hi}).\n\n");
    let rows: Vec<Vec<String>> = (s.channels.iter())
        .map(|c| {
            vec![
                format!("`{}`", c.name),
                significant(c.range),
                optional(c.resting_ratio, 2),
                percent(c.dead_share),
                percent(c.rising_share),
                percent(c.clipped_share),
                c.copy_of
                    .as_ref()
                    .map_or("-".into(), |o| format!("`{o}` ({})", percent(c.copy_share))),
            ]
        })
        .collect();
    md += &table(
        &[
            "channel",
            "range (median, the log's units)",
            "resting offset / range",
            "dead",
            "rising",
            "clipped",
            "copy of",
        ],
        &rows,
    );
    md += "\nShares are of the recordings read. Range and offset are medians over them.\n";
    if !s.unreadable.is_empty() {
        md += "\nUnreadable files:\n\n";
        for u in s.unreadable.iter().take(20) {
            md += &format!("- `{}`: {}\n", u.file, u.reason);
        }
        if s.unreadable.len() > 20 {
            md += &format!(
                "- and {} more (inspect.json lists them all)\n",
                s.unreadable.len() - 20
            );
        }
    }
    md
}

/// The neurons `e` checked: `Izhikevich neurons of type RS`, or without a type when their
/// parameters are no preset's.
fn neurons(e: &EncoderCheck) -> String {
    match &e.neurons {
        Some(t) => format!("Izhikevich neurons of type {t}"),
        None => "Izhikevich neurons of no preset type".to_string(),
    }
}

fn encoder_section(i: &Inspection) -> String {
    let Some(e) = &i.encoder else {
        return "\n## Encoder\n\nNot checked.\n".to_string();
    };
    let mut md = format!(
        "\n## Encoder at gain {}\n\n{}. A neuron held at the largest input fires at {:.0} Hz (the ceiling). {} had no positive signal.",
        e.gain,
        neurons(e),
        e.ceiling_hz,
        neurotex_core::words::counted(e.flat, "recording")
    );
    match (&e.auto, &e.auto_error) {
        (Some(a), _) => {
            md += &format!(
                " `--gain auto` would choose {} (median {:.1} Hz, target {} Hz).\n\n",
                a.gain, a.median_hz, a.target_hz
            )
        }
        (None, Some(why)) => md += &format!(" `--gain auto` cannot choose: {why}.\n\n"),
        (None, None) => md += "\n\n",
    }
    let rows: Vec<Vec<String>> = (e.taxels.iter())
        .map(|t| {
            vec![
                format!("`{}`", t.name),
                format!("r{}c{}", t.cell[0], t.cell[1]),
                format!("{:.1}", t.median_hz),
                percent(t.silent_share),
                percent(t.saturated_share),
            ]
        })
        .collect();
    md + &table(
        &[
            "channel",
            "cell",
            "median rate (Hz)",
            "silent",
            "at the ceiling",
        ],
        &rows,
    )
}

/// The figures with their captions, as `(name, svg, caption)`.
/// An event dataset's lengths and events, in place of the signals and the encoder.
fn events_section(i: &Inspection, e: &crate::events::EventSummary) -> String {
    let s = &i.signals;
    let [dmin, dmid, dmax] = s.duration_s.map(seconds);
    let [emin, emid, emax] = e.events;
    let mut md = format!(
        "\n## Events\n\nAddress events, times in {}: they skip the encoder (ON events are the SA population's spikes, OFF events the FA population's). Durations: {dmid} s median (from {dmin} to {dmax}). Events a recording: {emid} median (from {emin} to {emax}); {}; {} of the events fell in a millisecond already holding an event of their cell and polarity (one spike for both).\n\n",
        e.time_unit,
        e.on_share.map_or("ON events only (no polarity column)".to_string(), |x| format!("{} of them ON", percent(x))),
        percent(e.merged_share)
    );
    for u in &s.unreadable {
        md += &format!("- cannot be read: `{}`: {}\n", u.file, u.reason);
    }
    let rows: Vec<Vec<String>> = e
        .cells
        .iter()
        .map(|c| {
            vec![
                format!("r{}c{}", c.cell[0], c.cell[1]),
                format!("{:.1}", c.on_hz),
                optional(c.off_hz, 1),
                percent(c.silent_share),
            ]
        })
        .collect();
    md += &table(
        &[
            "cell",
            "ON events/s (median)",
            "OFF events/s (median)",
            "silent in",
        ],
        &rows,
    );
    md + "\nRates are medians over the recordings read; a cell is silent in a recording without any event of either polarity.\n"
}

fn figures(
    i: &Inspection,
    source: &str,
) -> Vec<(
    &'static str,
    std::result::Result<String, FigureError>,
    String,
)> {
    let mut out = Vec::new();
    if let Some(svg) = figs::traces(i, source) {
        let files: Vec<String> = i.traces.iter().map(|t| format!("`{}`", t.file)).collect();
        let caption = format!("The first recording of each class (up to six classes, in name order: {}): left, its channels as logged; right, the encoder's input after conditioning (selected phase, 1 kHz, baseline removed, low-passed, divided by the recording's maximum). One colour per channel, in channel order.", files.join(", "));
        out.push(("traces", svg, caption));
    }
    let encoder = match i.encoder.is_some() {
        true => " Right: each taxel's median firing rate over the recordings at the gain checked.",
        false => "",
    };
    let caption = format!("Left: each taxel's resting offset in the raw samples, before any baseline is removed: its smallest value over its range (median over recordings); far above 1 the encoder sees mostly the offset unless a baseline is removed (baseline here: {}).{encoder} Grey cells have no channel.", i.layout.baseline);
    if i.events.is_none() {
        out.push(("taxels", figs::taxel_map(i, source), caption));
    }
    out.push(("design", figs::design(i, source), "Recordings of each class at each speed (or over all recordings when the manifest has no speeds).".to_string()));
    out
}

/// `inspect.md`, `inspect.json` and `figures/` (SVG and PNG) as one folder `dir`, written
/// whole and replacing an earlier inspection there; `inspected` names the data on the
/// figures.
///
/// # Errors
/// A figure cannot be drawn; the folder cannot be written or holds files that are not an
/// earlier output's.
pub fn write_inspection(dir: &Path, i: &Inspection, inspected: &Path) -> Result<()> {
    let source = folder_source(inspected);
    let json = serde_json::to_string_pretty(i)
        .map_err(|e| DataError::invalid(dir.join("inspect.json"), e.to_string()))?;
    let mut files = vec![("inspect.json".to_string(), (json + "\n").into_bytes())];
    let mut captions = Vec::new();
    for (name, svg, caption) in figures(i, &source) {
        let svg_name = format!("{name}.svg");
        let failed =
            |e: FigureError| DataError::invalid(dir.join("figures").join(&svg_name), e.to_string());
        let svg = svg.map_err(failed)?;
        for (file, bytes) in svg_and_png(&svg_name, svg).map_err(failed)? {
            files.push((format!("figures/{file}"), bytes));
        }
        captions.push((name, caption));
    }
    files.push((
        "inspect.md".to_string(),
        markdown(i, &source, &captions).into_bytes(),
    ));
    replace_dir(dir, |tmp| {
        std::fs::create_dir(tmp.join("figures"))
            .map_err(|e| DataError::write(dir.join("figures"), e))?;
        for (name, bytes) in &files {
            let path = tmp.join(name);
            std::fs::write(&path, bytes).map_err(|e| DataError::write(dir.join(name), e))?;
        }
        Ok(())
    })
}

/// A duration in seconds to three significant digits (`0.750`, `3.90`, `11.8`), whole
/// seconds from 100 s: one decimal made a 0.750 s recording `0.8` where `import` says 0.750.
fn seconds(s: f64) -> String {
    match s.abs() {
        a if a >= 100.0 => format!("{s:.0}"),
        a if a >= 10.0 => format!("{s:.1}"),
        a if a >= 1.0 => format!("{s:.2}"),
        _ => format!("{s:.3}"),
    }
}

/// A value in a sensor's own units to four significant digits, or its whole part where
/// that is longer (`209.0`, `0.01230`, `51234`): raw counts and volts alike.
fn significant(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let decimals = 3 - x.abs().log10().floor() as i32;
    format!("{x:.*}", decimals.max(0) as usize)
}

#[cfg(test)]
mod tests {
    use super::{seconds, significant};

    #[test]
    fn ranges_keep_four_significant_digits() {
        let shown: Vec<String> = [209.0, 0.0123, 51234.0, 0.0, 1.5].map(significant).into();
        assert_eq!(shown, ["209.0", "0.01230", "51234", "0", "1.500"]);
    }

    #[test]
    fn durations_keep_three_significant_digits() {
        let shown: Vec<String> = [0.75, 3.9, 11.84, 59.4, 123.4].map(seconds).into();
        assert_eq!(shown, ["0.750", "3.90", "11.8", "59.4", "123"]);
    }
}
