//! The figures of `neurotex compare` (issue 11): every candidate's accuracy with its 95 %
//! interval, ranked, and the accuracy per condition of the best candidate and the paper's
//! method. Both are drawn from a [`Comparison`] and judge nothing.

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use super::plot::{
    accuracy_chart, category_labels, hline, labels_fit, labels_height, legend, legend_size,
    line_with_markers, mesh, number, percent, render, text, text_width, vline, Chart, Drawn, Key,
    Swatch, GLCM3D, GREY, SERIES, SINGLE, TICK, TITLE,
};
use super::FigureError;
use crate::compare::{Comparison, Ranked};

/// Every candidate but the paper's method.
const CANDIDATE: RGBColor = SINGLE;
/// The paper's method: 3D-GLCM's colour in every figure of the report.
const PAPER: RGBColor = GLCM3D;
/// The nested estimate: black, apart from every candidate.
const NESTED: RGBColor = BLACK;
/// The majority-class line (reddish purple, apart from chance's grey).
const MAJORITY: RGBColor = SERIES[4];
/// Every other row's background, so that a name can be followed to its dot.
const STRIPE: RGBColor = RGBColor(244, 244, 244);
/// The nested interval's band across every row.
const BAND: RGBColor = RGBColor(222, 222, 222);
/// Below this p-value against the paper's method a row is starred.
const SIGNIFICANT: f64 = 0.05;

const ROW_H: i32 = 22;
const PLOT_W: i32 = 440;
/// Tick labels and the axis description under the rows.
const AXIS_H: i32 = 48;
/// Title, subtitle and the columns' headings above the rows.
const TOP: i32 = 82;
const MARGIN: i32 = 12;
const NOTE_H: i32 = 18;
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
                format!("{:+.1}, {}{star}", 100.0 * d, p_text(p))
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
            "candidate: accuracy and 95 % bootstrap interval over {}",
            c.units
        ),
        Swatch::Points(CANDIDATE),
    )];
    if let Some(p) = c.results.iter().find(|r| r.paper) {
        let label = format!("the paper's method ({})", name(p));
        keys.push(Key::new(label, Swatch::Points(PAPER)));
    }
    if let Some(n) = &c.nested {
        let label = format!(
            "nested selection: the best chosen inside each training set, {} outer splits",
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
    /// The right edge of the accuracy column.
    value_x: i32,
    /// The left edge of the vs-paper column.
    versus_x: i32,
    /// The top of the legend.
    legend_y: i32,
    width: i32,
    height: i32,
}

fn layout(rows: &[Row], keys: &[Key], notes: &[String], titles: &[&str]) -> Layout {
    let widest = |texts: &mut dyn Iterator<Item = &str>, size: f64| {
        texts.map(|t| text_width(t, size)).max().unwrap_or(0)
    };
    let left = MARGIN + widest(&mut rows.iter().map(|r| r.label.as_str()), TICK) + 12;
    let value_w = widest(
        &mut rows.iter().map(|r| r.value.as_str()).chain([VALUE_HEAD]),
        TICK,
    );
    let value_x = left + PLOT_W + 20 + value_w;
    let versus_x = value_x + 18;
    let versus_w = if rows.iter().all(|r| r.versus.is_empty()) {
        0
    } else {
        widest(
            &mut rows.iter().map(|r| r.versus.as_str()).chain([VERSUS_HEAD]),
            TICK,
        )
    };
    let (legend_w, legend_h) = legend_size(keys);
    let notes_w = widest(&mut notes.iter().map(String::as_str), TICK);
    let titles_w = widest(&mut titles.iter().copied(), TITLE);
    let legend_y = TOP + ROW_H * rows.len() as i32 + AXIS_H + 10;
    let width = (versus_x + versus_w)
        .max(left + legend_w.max(notes_w))
        .max(MARGIN + titles_w)
        + MARGIN;
    let height = legend_y + legend_h + NOTE_H * notes.len() as i32 + MARGIN;
    Layout {
        left,
        value_x,
        versus_x,
        legend_y,
        width,
        height,
    }
}

/// Every candidate ranked by accuracy with its 95 % interval, best at the top, under the
/// nested estimate when there is one; chance and the majority-class share as dashed lines.
///
/// # Errors
/// The drawing fails.
pub fn ranking(c: &Comparison) -> Result<String, FigureError> {
    let rows = rows(c);
    let keys = keys(c);
    let notes = notes(c);
    let title = format!("{} candidates ranked by accuracy", c.results.len());
    let subtitle = format!(
        "{}; {} classes, {} recordings, intervals over {} {}",
        c.protocol, c.classes, c.n_recordings, c.n_units, c.units
    );
    let at = layout(&rows, &keys, &notes, &[&title, &subtitle]);
    render((at.width as u32, at.height as u32), |root| {
        root.draw(&Text::new(
            title.as_str(),
            (MARGIN, 8),
            text(TITLE, HPos::Left, VPos::Top),
        ))?;
        root.draw(&Text::new(
            subtitle.as_str(),
            (MARGIN, 34),
            text(TICK, HPos::Left, VPos::Top),
        ))?;
        stripes(root, &rows, &at)?;
        let plot_h = ROW_H * rows.len() as i32;
        let area = root
            .clone()
            .shrink((at.left, TOP), (PLOT_W + 16, plot_h + AXIS_H));
        let mut chart = ChartBuilder::on(&area)
            .margin_right(16)
            .x_label_area_size(AXIS_H)
            .build_cartesian_2d(0.0..100.0, 0.0..rows.len() as f64)?;
        draw_rows(&mut chart, c, &rows)?;
        row_texts(root, &rows, &at)?;
        legend(root, (at.left, at.legend_y), &keys)?;
        let notes_y = at.legend_y + legend_size(&keys).1 + 4;
        for (k, note) in notes.iter().enumerate() {
            let style = text(TICK, HPos::Left, VPos::Top);
            let y = notes_y + NOTE_H * k as i32;
            root.draw(&Text::new(note.as_str(), (at.left, y), style))?;
        }
        Ok(())
    })
}

/// The pixel row of the centre of row `k` (0 at the top).
fn row_y(k: usize) -> i32 {
    TOP + ROW_H * k as i32 + ROW_H / 2
}

/// A light background behind every other row, across names, plot and columns.
fn stripes(root: &super::plot::Canvas, rows: &[Row], at: &Layout) -> Drawn {
    for k in (1..rows.len()).step_by(2) {
        let y = TOP + ROW_H * k as i32;
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
    mesh(chart)
        .disable_y_mesh()
        .y_labels(0)
        .x_labels(11)
        .x_label_formatter(&|v| number(*v))
        .x_desc("accuracy (%)")
        .draw()?;
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
        let cap = 0.22;
        let style = row.colour.stroke_width(2);
        chart.draw_series([
            PathElement::new(vec![(row.ci[0], y), (row.ci[1], y)], style),
            PathElement::new(vec![(row.ci[0], y - cap), (row.ci[0], y + cap)], style),
            PathElement::new(vec![(row.ci[1], y - cap), (row.ci[1], y + cap)], style),
        ])?;
        chart.draw_series([Circle::new((row.accuracy, y), 4, row.colour.filled())])?;
    }
    Ok(())
}

/// Each row's name left of the plot and its accuracy and comparison right of it, under
/// the columns' headings.
fn row_texts(root: &super::plot::Canvas, rows: &[Row], at: &Layout) -> Drawn {
    let head_y = TOP - 6;
    let right = text(TICK, HPos::Right, VPos::Bottom);
    root.draw(&Text::new(VALUE_HEAD, (at.value_x, head_y), right))?;
    if rows.iter().any(|r| !r.versus.is_empty()) {
        let left = text(TICK, HPos::Left, VPos::Bottom);
        root.draw(&Text::new(VERSUS_HEAD, (at.versus_x, head_y), left))?;
    }
    for (k, row) in rows.iter().enumerate() {
        let y = row_y(k);
        let name = text(TICK, HPos::Right, VPos::Center).color(&row.colour);
        root.draw(&Text::new(row.label.as_str(), (at.left - 8, y), name))?;
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

/// The condition column named in the protocol's text (between backticks), and the x
/// description: whether each condition was held out in turn or cross-validated within.
fn condition_desc(protocol: &str) -> (&str, String) {
    let column = protocol.split('`').nth(1).unwrap_or("condition");
    let desc = if protocol.contains("held out") {
        format!("held-out {column}, trained on the others")
    } else {
        format!("{column}, cross-validated within each")
    };
    (column, desc)
}

/// One line of the per-condition figure.
struct Series {
    key: Key,
    colour: RGBColor,
    dashed: bool,
    /// Accuracy (%) at each condition, in the figure's order.
    values: Vec<Option<f64>>,
}

fn series(c: &Comparison, conditions: &[String]) -> Vec<Series> {
    let at = |r: &Ranked| -> Vec<Option<f64>> {
        let value = |condition: &String| {
            let found = r.per_condition.iter().find(|p| p.condition == *condition);
            found.map(|p| 100.0 * p.accuracy)
        };
        conditions.iter().map(value).collect()
    };
    let best = &c.best;
    let mut out = Vec::new();
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
/// the paper's method; `None` when the protocol has no conditions (pooled or one split).
///
/// # Errors
/// The drawing fails.
pub fn per_condition(c: &Comparison) -> Option<Result<String, FigureError>> {
    if c.best.per_condition.is_empty() {
        return None;
    }
    let conditions: Vec<String> = c
        .best
        .per_condition
        .iter()
        .map(|p| p.condition.clone())
        .collect();
    let lines = series(c, &conditions);
    // The best drawn last, on top, but named first.
    let mut keys: Vec<Key> = lines.iter().rev().map(|s| s.key.clone()).collect();
    keys.extend(reference_keys(c));
    let n = conditions.len();
    let plot_w = (56 * n as i32).max(360);
    let level = labels_fit(&conditions, plot_w / n as i32);
    let (left, top, plot_h) = (64, 40, 300);
    let bottom = labels_height(&conditions, level) + 26;
    let (legend_w, legend_h) = legend_size(&keys);
    let width = left + plot_w + 28 + legend_w + MARGIN;
    let height = top + plot_h.max(legend_h) + bottom + 8;
    Some(render((width as u32, height as u32), |root| {
        let (area, _) = root.split_horizontally(left + plot_w + 12);
        let (column, x_desc) = condition_desc(&c.protocol);
        let title = format!("accuracy per {column}");
        let mut chart = accuracy_chart(&area, &title, n, (left, bottom), &x_desc)?;
        hline(&mut chart, 100.0 * c.chance, GREY, 9)?;
        if (c.chance - c.majority).abs() >= 1e-9 {
            hline(&mut chart, 100.0 * c.majority, MAJORITY, 5)?;
        }
        for s in &lines {
            let points: Vec<(f64, f64)> = (s.values.iter().enumerate())
                .filter_map(|(i, v)| v.map(|v| (i as f64 + 0.5, v)))
                .collect();
            line_with_markers(&mut chart, &points, s.colour, s.dashed)?;
        }
        let xs: Vec<i32> = (0..n)
            .map(|i| chart.backend_coord(&(i as f64 + 0.5, 0.0)).0)
            .collect();
        let axis_y = chart.backend_coord(&(0.0, 0.0)).1;
        category_labels(root, &conditions, &xs, axis_y, level)?;
        legend(root, (left + plot_w + 28, top + 4), &keys)
    }))
}

/// The caption of [`per_condition`].
pub fn per_condition_caption(c: &Comparison) -> String {
    let paper = if c.best.paper {
        "The best candidate is the paper's method."
    } else {
        "The paper's method (sa / glcm3d / knn) is dashed vermillion, where it was among the candidates."
    };
    format!(
        "Accuracy at each condition ({}) of the best candidate (solid); the ranking's accuracy is the mean over these. {paper} Grey dashed: chance, one over {} classes; purple dashed: the largest class's share over all conditions (when it differs from chance). No intervals per condition are computed.",
        c.protocol, c.classes
    )
}

#[cfg(test)]
mod tests;
