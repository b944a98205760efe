//! The figures of `neurotex compare`: every candidate's accuracy with its 95 %
//! interval, ranked, and the accuracy per condition of the best candidate and the paper's
//! method. Both are drawn from a [`Comparison`] and judge nothing.

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use super::accuracy::{chart_width, group_labels, plot_height};
use super::plot::{
    accuracy_axis, accuracy_chart, fit, hline, interval, line_height, line_with_markers, markers,
    percent, text, text_width, vline, Chart, Drawn, Frame, Key, Placement, Swatch, Width, GLCM3D,
    GREY, LABEL, MARGIN, SERIES, SINGLE, TICK, X_AXIS_H, Y_AXIS_W,
};
use super::FigureError;
use crate::compare::{Comparison, Ranked};
use neurotex_core::words::signed_one_decimal as signed;

/// Every candidate but the paper's method.
const CANDIDATE: RGBColor = SINGLE;
/// The paper's method: 3D-GLCM's colour in every figure of the report.
const PAPER: RGBColor = GLCM3D;
/// The nested estimate: black, apart from every candidate.
const NESTED: RGBColor = BLACK;
/// The best baseline without spikes beside the candidates (bluish green, dashed).
const BASELINE: RGBColor = SERIES[2];
/// The majority-class line (reddish purple, apart from chance's grey).
const MAJORITY: RGBColor = SERIES[4];
/// Every other row's background, so that a name can be followed to its dot.
const STRIPE: RGBColor = RGBColor(244, 244, 244);
/// The nested interval's band across every row.
const BAND: RGBColor = RGBColor(222, 222, 222);
/// Below this p-value against the paper's method a row is starred.
const SIGNIFICANT: f64 = 0.05;

const ROW_H: i32 = 16;
/// The narrowest the ranking's plot gets, however long the names.
const MIN_PLOT_W: i32 = 150;
/// The widest it gets: the names stay near their dots.
const MAX_PLOT_W: i32 = 300;
const VALUE_HEAD: &str = "accuracy (%)";
const VERSUS_HEAD: &str = "vs paper (points, p)";

/// `encoding / method / classifier`.
fn name(r: &Ranked) -> String {
    format!("{} / {} / {}", r.encoding, r.method, r.classifier)
}

/// A p-value to three decimals, or `< 0.001`.
fn p_text(p: f64) -> String {
    if p < 0.001 {
        "p < 0.001".into()
    } else {
        format!("p = {p:.3}")
    }
}

/// One row of the ranking, in percent.
struct Row {
    label: String,
    accuracy: f64,
    ci: [f64; 2],
    colour: RGBColor,
    /// The accuracy as text, in its column.
    value: String,
    /// The difference from the paper's method and its p-value, in the last column.
    versus: String,
}

/// The nested estimate (when there is one), then every candidate best first.
fn rows(c: &Comparison) -> Vec<Row> {
    let nested = c.nested.iter().map(|n| Row {
        label: "nested selection".into(),
        accuracy: 100.0 * n.accuracy,
        ci: [100.0 * n.ci[0], 100.0 * n.ci[1]],
        colour: NESTED,
        value: format!("{:.1}", 100.0 * n.accuracy),
        versus: String::new(),
    });
    let candidates = c.results.iter().map(|r| {
        let versus = match (r.paper, r.difference_vs_paper, r.p_vs_paper) {
            (true, _, _) => "reference".into(),
            (false, Some(d), Some(p)) => {
                let star = if p < SIGNIFICANT { " *" } else { "" };
                format!("{}, {}{star}", signed(100.0 * d), p_text(p))
            }
            _ => String::new(),
        };
        Row {
            label: if r.paper {
                format!("{} (paper)", name(r))
            } else {
                name(r)
            },
            accuracy: 100.0 * r.accuracy,
            ci: [100.0 * r.ci[0], 100.0 * r.ci[1]],
            colour: if r.paper { PAPER } else { CANDIDATE },
            value: format!("{:.1}", 100.0 * r.accuracy),
            versus,
        }
    });
    nested.chain(candidates).collect()
}

/// The legend of the ranking.
fn keys(c: &Comparison) -> Vec<Key> {
    let mut keys = vec![Key::new(
        format!(
            "candidate: accuracy, 95 % bootstrap interval over {}",
            c.units
        ),
        Swatch::Points(CANDIDATE),
    )];
    if let Some(p) = c.results.iter().find(|r| r.paper) {
        let label = format!("paper's method ({})", name(p));
        keys.push(Key::new(label, Swatch::Points(PAPER)));
    }
    if let Some(n) = &c.nested {
        let label = format!(
            "nested selection, best chosen in each of {} training sets",
            n.outer_splits
        );
        keys.push(Key::new(label, Swatch::Points(NESTED)));
        keys.push(Key::new("its 95 % interval", Swatch::Band(BAND)));
    }
    keys.extend(reference_keys(c));
    keys
}

/// Chance and the majority-class share, one key when they coincide (balanced classes).
fn reference_keys(c: &Comparison) -> Vec<Key> {
    let chance = percent(100.0 * c.chance);
    if (c.chance - c.majority).abs() < 1e-9 {
        let label = format!(
            "chance, 1 / {} classes = majority class ({chance} %)",
            c.classes
        );
        return vec![Key::new(label, Swatch::Dashed(GREY))];
    }
    vec![
        Key::new(
            format!("chance, 1 / {} classes ({chance} %)", c.classes),
            Swatch::Dashed(GREY),
        ),
        Key::new(
            format!("majority class ({} %)", percent(100.0 * c.majority)),
            Swatch::Dashed(MAJORITY),
        ),
    ]
}

/// The lines of text under the legend.
fn notes(c: &Comparison) -> Vec<String> {
    let mut notes = Vec::new();
    if c.results.iter().any(|r| r.p_vs_paper.is_some()) {
        notes.push(format!(
            "vs paper: difference in accuracy, in points; p of the paired sign-flip test over {}; * p < {SIGNIFICANT}",
            c.units
        ));
    }
    if c.nested.is_some() {
        notes.push(
            "the top candidate's accuracy is biased upwards by the choice; nested selection is not"
                .into(),
        );
    }
    notes
}

/// Pixel positions of the ranking, from its texts' widths.
struct Layout {
    /// The plot's left edge; names end just left of it.
    left: i32,
    /// The plot's width.
    plot_w: i32,
    /// The right edge of the accuracy column.
    value_x: i32,
    /// The left edge of the vs-paper column.
    versus_x: i32,
    /// The room for the names.
    name_w: i32,
    width: i32,
}

/// The body's rows start under the subtitle and the columns' headings.
const ROWS_TOP: i32 = 34;

fn layout(rows: &[Row]) -> Layout {
    let width = Width::Page.px();
    let widest = |texts: &mut dyn Iterator<Item = &str>| {
        texts.map(|t| text_width(t, TICK)).max().unwrap_or(0)
    };
    let value_w = widest(&mut rows.iter().map(|r| r.value.as_str()).chain([VALUE_HEAD]));
    let versus_w = if rows.iter().all(|r| r.versus.is_empty()) {
        0
    } else {
        widest(&mut rows.iter().map(|r| r.versus.as_str()).chain([VERSUS_HEAD])) + 12
    };
    let columns_w = 16 + value_w + versus_w + MARGIN;
    let names = widest(&mut rows.iter().map(|r| r.label.as_str()));
    let name_w = names.min(width - MARGIN - 8 - MIN_PLOT_W - 16 - columns_w);
    let left = MARGIN + name_w + 8;
    let plot_w = (width - left - 16 - columns_w).clamp(MIN_PLOT_W, MAX_PLOT_W);
    let value_x = left + plot_w + 16 + value_w;
    Layout {
        left,
        plot_w,
        value_x,
        versus_x: value_x + 12,
        name_w,
        width,
    }
}

/// Every candidate ranked by accuracy with its 95 % interval, best at the top, under the
/// nested estimate when there is one; chance and the majority-class share as dashed lines;
/// `source` names the data.
///
/// # Errors
/// The drawing fails.
pub fn ranking(c: &Comparison, source: &str) -> Result<String, FigureError> {
    let rows = rows(c);
    let keys = keys(c);
    let notes = notes(c);
    let title = format!("{} candidates ranked by accuracy", c.results.len());
    let subtitle = format!(
        "{}; {} classes, {} recordings, intervals over {} {}",
        plain_protocol(&c.protocol),
        c.classes,
        c.n_recordings,
        c.n_units,
        c.units
    );
    let at = layout(&rows);
    let frame = Frame {
        width: Width::Page,
        title: &title,
        source,
        keys: &keys,
    };
    let plot_h = ROW_H * rows.len() as i32;
    let notes_y = ROWS_TOP + plot_h + X_AXIS_H + 4;
    let body_h = notes_y + line_height(TICK) * notes.len() as i32;
    frame.render(body_h, |_, body| {
        let style = text(TICK, HPos::Left, VPos::Top);
        let subtitle = fit(&subtitle, TICK, at.width - 2 * MARGIN);
        body.draw(&Text::new(subtitle, (MARGIN, 0), style))?;
        stripes(body, &rows, &at)?;
        let area = body
            .clone()
            .shrink((at.left, ROWS_TOP), (at.plot_w + 16, plot_h + X_AXIS_H));
        let mut chart = ChartBuilder::on(&area)
            .margin_right(16)
            .x_label_area_size(X_AXIS_H)
            .build_cartesian_2d(0.0..100.0, 0.0..rows.len() as f64)?;
        draw_rows(&mut chart, c, &rows)?;
        row_texts(body, &rows, &at)?;
        for (k, note) in notes.iter().enumerate() {
            let style = text(TICK, HPos::Left, VPos::Top);
            let y = notes_y + line_height(TICK) * k as i32;
            let note = fit(note, TICK, at.width - 2 * MARGIN);
            body.draw(&Text::new(note, (MARGIN, y), style))?;
        }
        Ok(())
    })
}

/// The pixel row of the centre of row `k` (0 at the top).
fn row_y(k: usize) -> i32 {
    ROWS_TOP + ROW_H * k as i32 + ROW_H / 2
}

/// A light background behind every other row, across names, plot and columns.
fn stripes(root: &super::plot::Canvas, rows: &[Row], at: &Layout) -> Drawn {
    for k in (1..rows.len()).step_by(2) {
        let y = ROWS_TOP + ROW_H * k as i32;
        let corners = [(MARGIN / 2, y), (at.width - MARGIN / 2, y + ROW_H)];
        root.draw(&Rectangle::new(corners, STRIPE.filled()))?;
    }
    Ok(())
}

/// The axis, the nested band, the reference lines and each row's interval and dot.
fn draw_rows(chart: &mut Chart, c: &Comparison, rows: &[Row]) -> Drawn {
    let n = rows.len() as f64;
    if let Some(nested) = &c.nested {
        let (lo, hi) = (100.0 * nested.ci[0], 100.0 * nested.ci[1]);
        chart.draw_series([Rectangle::new([(lo, 0.0), (hi, n)], BAND.mix(0.6).filled())])?;
    }
    accuracy_axis(chart)?;
    vline(chart, 100.0 * c.chance, GREY, 9)?;
    if (c.chance - c.majority).abs() >= 1e-9 {
        vline(chart, 100.0 * c.majority, MAJORITY, 5)?;
    }
    if c.nested.is_some() {
        // A rule under the nested row: it is not one of the candidates.
        let rule = PathElement::new(vec![(0.0, n - 1.0), (100.0, n - 1.0)], GREY);
        chart.draw_series([rule])?;
    }
    for (k, row) in rows.iter().enumerate() {
        let y = n - k as f64 - 0.5;
        interval(chart, row.ci, y, row.colour)?;
        chart.draw_series([Circle::new((row.accuracy, y), 3, row.colour.filled())])?;
    }
    Ok(())
}

/// Each row's name left of the plot and its accuracy and comparison right of it, under
/// the columns' headings.
fn row_texts(root: &super::plot::Canvas, rows: &[Row], at: &Layout) -> Drawn {
    let head_y = ROWS_TOP - 2;
    let right = text(TICK, HPos::Right, VPos::Bottom);
    root.draw(&Text::new(VALUE_HEAD, (at.value_x, head_y), right))?;
    if rows.iter().any(|r| !r.versus.is_empty()) {
        let left = text(TICK, HPos::Left, VPos::Bottom);
        root.draw(&Text::new(VERSUS_HEAD, (at.versus_x, head_y), left))?;
    }
    for (k, row) in rows.iter().enumerate() {
        let y = row_y(k);
        let name = text(TICK, HPos::Right, VPos::Center).color(&row.colour);
        let label = fit(&row.label, TICK, at.name_w);
        root.draw(&Text::new(label, (at.left - 8, y), name))?;
        let value = text(TICK, HPos::Right, VPos::Center);
        root.draw(&Text::new(row.value.as_str(), (at.value_x, y), value))?;
        if !row.versus.is_empty() {
            let versus = text(TICK, HPos::Left, VPos::Center);
            root.draw(&Text::new(row.versus.as_str(), (at.versus_x, y), versus))?;
        }
    }
    Ok(())
}

/// The caption of [`ranking`].
pub fn ranking_caption(c: &Comparison) -> String {
    let nested = match &c.nested {
        Some(n) => format!(
            " The top row (black, grey band across) is nested selection: the candidates ranked inside each of {} training sets and the chosen one scored on its test set ({} %, 95 % interval {}–{} %), the estimate to quote for choosing the best; the ranking's top accuracy is biased upwards by the choice.",
            n.outer_splits,
            percent_1(n.accuracy),
            percent_1(n.ci[0]),
            percent_1(n.ci[1])
        ),
        None => String::new(),
    };
    format!(
        "Every candidate (encoding / feature method / classifier) under {}, best at the top: the dot is the accuracy, the whisker its 95 % percentile-bootstrap interval over {} {}, stratified by condition. The paper's method (sa / glcm3d / knn) is in vermillion; the right-hand columns give the accuracy and its difference from the paper's method, in points, with the p-value of a paired sign-flip test over units (* p < 0.05, not corrected for the number of candidates). Grey dashed: chance, one over {} classes; purple dashed: the largest class's share (drawn only when it differs from chance).{nested}",
        c.protocol, c.n_units, c.units, c.classes
    )
}

fn percent_1(v: f64) -> String {
    format!("{:.1}", 100.0 * v)
}

/// A manifest column in plain words, its unit from the name's suffix apart:
/// `speed_mm_s` -> (`speed`, `speed (mm/s)`), `session` -> (`session`, `session`).
fn column_words(column: &str) -> (String, String) {
    const UNITS: [(&str, &str); 7] = [
        ("_mm_s", "mm/s"),
        ("_ms", "ms"),
        ("_hz", "Hz"),
        ("_mm", "mm"),
        ("_s", "s"),
        ("_n", "N"),
        ("_g", "g"),
    ];
    let lower = column.to_ascii_lowercase();
    let (stem, unit) = UNITS
        .iter()
        .find(|(suffix, _)| lower.ends_with(suffix) && lower.len() > suffix.len())
        .map_or((column, None), |(suffix, unit)| {
            (&column[..column.len() - suffix.len()], Some(*unit))
        });
    let name = stem.replace('_', " ");
    let with_unit = match unit {
        Some(unit) => format!("{name} ({unit})"),
        None => name.clone(),
    };
    (name, with_unit)
}

/// The protocol's text with its column names (between backticks) in plain words.
pub(crate) fn plain_protocol(protocol: &str) -> String {
    protocol
        .split('`')
        .enumerate()
        .map(|(k, part)| {
            if k % 2 == 1 {
                column_words(part).1
            } else {
                part.to_string()
            }
        })
        .collect()
}

/// The condition column named in the protocol's text (between backticks), in plain words
/// without and with its unit, and the x description: whether each condition was held out
/// in turn or cross-validated within.
fn condition_desc(protocol: &str) -> (String, String) {
    let column = protocol.split('`').nth(1).unwrap_or("condition");
    let (name, with_unit) = column_words(column);
    let desc = if protocol.contains("held out") {
        format!("held-out {with_unit}, trained on the others")
    } else {
        format!("{with_unit}, cross-validated within each")
    };
    (name, desc)
}

/// One line of the per-condition figure.
struct Series {
    key: Key,
    colour: RGBColor,
    dashed: bool,
    /// Accuracy (%) at each condition, in the figure's order.
    values: Vec<Option<f64>>,
}

fn series(c: &Comparison, baseline: Option<&Ranked>, conditions: &[String]) -> Vec<Series> {
    let at = |r: &Ranked| -> Vec<Option<f64>> {
        let value = |condition: &String| {
            let found = r.per_condition.iter().find(|p| p.condition == *condition);
            found.map(|p| 100.0 * p.accuracy)
        };
        conditions.iter().map(value).collect()
    };
    let best = &c.best;
    let mut out = Vec::new();
    if let Some(b) = baseline {
        out.push(Series {
            key: Key::new(
                format!("best baseline without spikes: {}", name(b)),
                Swatch::DashedPoints(BASELINE),
            ),
            colour: BASELINE,
            dashed: true,
            values: at(b),
        });
    }
    if let Some(paper) = c.results.iter().find(|r| r.paper && !best.paper) {
        out.push(Series {
            key: Key::new(
                format!("the paper's method: {}", name(paper)),
                Swatch::DashedPoints(PAPER),
            ),
            colour: PAPER,
            dashed: true,
            values: at(paper),
        });
    }
    let what = if best.paper {
        "best, the paper's method"
    } else {
        "best"
    };
    out.push(Series {
        key: Key::new(
            format!("{what}: {}", name(best)),
            Swatch::Points(if best.paper { PAPER } else { CANDIDATE }),
        ),
        colour: if best.paper { PAPER } else { CANDIDATE },
        dashed: false,
        values: at(best),
    });
    out
}

/// The accuracy at each condition of the protocol (speeds, say) of the best candidate and
/// the paper's method, to draw; `None` when the protocol has no conditions (pooled or one
/// split).
pub fn per_condition(c: &Comparison) -> Option<PerCondition<'_>> {
    (!c.best.per_condition.is_empty()).then_some(PerCondition(c, None))
}

/// The figure of [`per_condition`], to draw with the data's name.
#[derive(Debug, Clone, Copy)]
pub struct PerCondition<'a>(&'a Comparison, Option<&'a Ranked>);

impl<'a> PerCondition<'a> {
    /// The same figure with `baseline` (the best baseline without spikes, evaluated on the
    /// same splits) drawn beside the candidates.
    pub fn with_baseline(self, baseline: Option<&'a Ranked>) -> Self {
        PerCondition(self.0, baseline)
    }

    /// Draws the figure, `source` naming the data.
    ///
    /// # Errors
    /// The drawing fails.
    pub fn draw(&self, source: &str) -> Result<String, FigureError> {
        let c = self.0;
        let conditions: Vec<String> = c
            .best
            .per_condition
            .iter()
            .map(|p| p.condition.clone())
            .collect();
        let lines = series(c, self.1, &conditions);
        // A line joins the conditions only when they are numbers (speeds, forces):
        // sessions or sensors have no order for a line to follow.
        let ordered = conditions.iter().all(|c| c.trim().parse::<f64>().is_ok());
        // The best drawn last, on top, but named first.
        let mut keys: Vec<Key> = lines.iter().rev().map(|s| s.key.clone()).collect();
        keys.extend(reference_keys(c));
        let n = conditions.len();
        let width = Width::fitting(chart_width(n, 28));
        let slot = (width.px() - chart_width(n, 0)) / n as i32;
        let bottom = Placement::of(&conditions, slot).height() + line_height(LABEL) + 4;
        let (column, x_desc) = condition_desc(&c.protocol);
        let title = format!("accuracy per {column}");
        let frame = Frame {
            width,
            title: &title,
            source,
            keys: &keys,
        };
        frame.render(plot_height(width) + bottom, |root, area| {
            let mut chart = accuracy_chart(area, n, (Y_AXIS_W, bottom), &x_desc)?;
            hline(&mut chart, 100.0 * c.chance, GREY, 6)?;
            if (c.chance - c.majority).abs() >= 1e-9 {
                hline(&mut chart, 100.0 * c.majority, MAJORITY, 4)?;
            }
            for (k, s) in lines.iter().enumerate() {
                // Markers without a line sit side by side within their condition, so
                // that equal accuracies do not hide one another.
                let shift = match ordered {
                    true => 0.0,
                    false => 0.12 * (k as f64 - (lines.len() - 1) as f64 / 2.0),
                };
                let points: Vec<(f64, f64)> = (s.values.iter().enumerate())
                    .filter_map(|(i, v)| v.map(|v| (i as f64 + 0.5 + shift, v)))
                    .collect();
                match ordered {
                    true => line_with_markers(&mut chart, &points, s.colour, s.dashed)?,
                    false => markers(&mut chart, &points, s.colour)?,
                }
            }
            group_labels(root, &chart, &conditions, slot)
        })
    }
}

/// The caption of [`per_condition`], with `baseline` as given to
/// [`PerCondition::with_baseline`].
pub fn per_condition_caption(c: &Comparison, baseline: Option<&Ranked>) -> String {
    let paper = if c.best.paper {
        "The best candidate is the paper's method."
    } else {
        "The paper's method (sa / glcm3d / knn) is dashed vermillion, where it was among the candidates."
    };
    let baseline = baseline.map_or(String::new(), |b| {
        format!(
            " Dashed bluish green: the best baseline without spikes on the same splits ({}, from the conditioned signal, not a candidate).",
            name(b)
        )
    });
    format!(
        "Accuracy at each condition ({}) of the best candidate (solid); the ranking's accuracy is the mean over these. {paper}{baseline} Grey dashed: chance, one over {} classes; purple dashed: the largest class's share over all conditions (when it differs from chance). No intervals per condition are computed.",
        c.protocol, c.classes
    )
}

#[cfg(test)]
mod tests;
