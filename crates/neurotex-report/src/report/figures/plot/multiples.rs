//! Small multiples: a grid of panels sharing axes, and the line and accuracy charts drawn in
//! a panel.

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use super::super::FigureError;
use super::frame::Frame;
use super::legend::Key;
use super::{
    fit, line_height, mesh, number, text, Canvas, Chart, Drawn, Width, LABEL, MARGIN, X_AXIS_H,
    Y_AXIS_W,
};

/// Columns and rows of a grid of `n` small multiples: one row up to four panels, then close
/// to square, at most four columns so that a panel keeps a quarter of the page.
pub(crate) fn grid(n: usize) -> (usize, usize) {
    let cols = if n <= 4 {
        n.max(1)
    } else {
        ((n as f64).sqrt().ceil() as usize).min(4)
    };
    (cols, n.div_ceil(cols).max(1))
}

/// Draws `desc` centred under the pixel span `x0..x1` at row `y` (level) or, with
/// `upright`, reading upwards centred on the pixel span `y0..y1` at column `x`.
pub(crate) fn axis_desc(
    canvas: &Canvas,
    desc: &str,
    at: (i32, i32),
    span: (i32, i32),
    upright: bool,
) -> Drawn {
    let room = (span.1 - span.0).max(0);
    let desc = fit(desc, LABEL, room);
    if upright {
        let style = text(LABEL, HPos::Center, VPos::Top).transform(FontTransform::Rotate270);
        canvas.draw(&Text::new(desc, (at.0, (span.0 + span.1) / 2), style))
    } else {
        let style = text(LABEL, HPos::Center, VPos::Top);
        canvas.draw(&Text::new(desc, ((span.0 + span.1) / 2, at.1), style))
    }
}

/// A grid of small multiples across the page, one panel per item, sharing their axis
/// descriptions and one legend above them.
pub(crate) struct Multiples<'a> {
    /// Panels.
    pub(crate) n: usize,
    /// A panel's plot height over its width.
    pub(crate) aspect: f64,
    /// The figure's title.
    pub(crate) title: &'a str,
    /// The data, in a few words.
    pub(crate) source: &'a str,
    /// The x description, once under the grid.
    pub(crate) x_desc: &'a str,
    /// The y description, once left of the grid.
    pub(crate) y_desc: &'a str,
    /// The legend.
    pub(crate) keys: &'a [Key],
}

/// A panel's room for its title above the plot.
const PANEL_TITLE_H: i32 = 17;

/// A panel's room for tick labels left of and under the plot.
const PANEL_Y_TICKS: i32 = 26;

const PANEL_X_TICKS: i32 = 16;

/// Draws the grid of `m`, calling `panel(i, area)` to draw panel `i` in its area.
pub(crate) fn multiples(
    m: &Multiples,
    panel: impl FnMut(usize, &Canvas) -> Drawn,
) -> Result<String, FigureError> {
    multiples_in(m, grid(m.n).0, panel)
}

/// [`multiples`] in `cols` columns (panels that belong together side by side).
pub(crate) fn multiples_in(
    m: &Multiples,
    cols: usize,
    mut panel: impl FnMut(usize, &Canvas) -> Drawn,
) -> Result<String, FigureError> {
    let cols = cols.clamp(1, m.n.max(1));
    let rows = m.n.div_ceil(cols).max(1);
    let frame = Frame {
        width: Width::Page,
        title: m.title,
        source: m.source,
        keys: m.keys,
    };
    let left = MARGIN + line_height(LABEL) + 2;
    let pw = (frame.px() - left - MARGIN) / cols as i32;
    let plot_w = pw - PANEL_Y_TICKS - 10;
    let ph = (f64::from(plot_w) * m.aspect).round() as i32 + PANEL_TITLE_H + PANEL_X_TICKS + 6;
    let grid_h = ph * rows as i32;
    let body_h = grid_h + line_height(LABEL) + 4;
    frame.render(body_h, |_, body| {
        for i in 0..m.n {
            let (r, c) = ((i / cols) as i32, (i % cols) as i32);
            let area = body.clone().shrink((left + c * pw, r * ph), (pw, ph));
            panel(i, &area)?;
        }
        let grid_w = pw * cols as i32;
        let x_span = (left + PANEL_Y_TICKS, left + grid_w - 10);
        axis_desc(body, m.x_desc, (0, grid_h + 2), x_span, false)?;
        let y_span = (PANEL_TITLE_H, grid_h - PANEL_X_TICKS);
        axis_desc(body, m.y_desc, (MARGIN, 0), y_span, true)
    })
}

/// A panel's chart: its title above, tick labels only (the grid carries the descriptions).
pub(crate) fn panel_chart<'a, 'b>(
    area: &'a Canvas<'b>,
    title: &str,
    x: std::ops::Range<f64>,
    y: std::ops::Range<f64>,
) -> Result<Chart<'a, 'b>, DrawingAreaErrorKind<std::io::Error>> {
    let (w, _) = area.dim_in_pixel();
    let style = text(LABEL, HPos::Center, VPos::Top);
    let centre = PANEL_Y_TICKS + (w as i32 - PANEL_Y_TICKS - 10) / 2;
    area.draw(&Text::new(
        fit(title, LABEL, w as i32 - 4),
        (centre, 2),
        style,
    ))?;
    ChartBuilder::on(area)
        .margin_top(PANEL_TITLE_H)
        .margin_right(10)
        .margin_bottom(6)
        .x_label_area_size(PANEL_X_TICKS)
        .y_label_area_size(PANEL_Y_TICKS)
        .build_cartesian_2d(x, y)
}

/// A chart with numeric axes filling `area`, room for tick labels and descriptions left
/// and under it.
pub(crate) fn line_chart<'a, 'b>(
    area: &'a Canvas<'b>,
    x: std::ops::Range<f64>,
    y: std::ops::Range<f64>,
) -> Result<Chart<'a, 'b>, DrawingAreaErrorKind<std::io::Error>> {
    ChartBuilder::on(area)
        .margin_top(6)
        .margin_right(MARGIN + 4)
        .x_label_area_size(X_AXIS_H)
        .y_label_area_size(Y_AXIS_W)
        .build_cartesian_2d(x, y)
}

/// A chart of accuracy (0-100 %, a labelled grid line every 10) over `groups` categories
/// of one x unit each, on `area`, with room for `(left, bottom)` pixels of labels, and
/// the x description `x_desc` (none when empty) under the categories' own labels, which
/// are drawn apart.
pub(crate) fn accuracy_chart<'a, 'b>(
    area: &'a Canvas<'b>,
    groups: usize,
    (left, bottom): (i32, i32),
    x_desc: &str,
) -> Result<Chart<'a, 'b>, DrawingAreaErrorKind<std::io::Error>> {
    let mut chart = ChartBuilder::on(area)
        .margin_top(6)
        .margin_right(MARGIN + 2)
        .x_label_area_size(bottom)
        .y_label_area_size(left)
        .build_cartesian_2d(0.0..groups as f64, 0.0..100.0)?;
    let mut m = mesh(&mut chart);
    m.disable_x_mesh()
        .x_labels(0)
        .y_labels(11)
        .y_label_formatter(&|v| number(*v))
        .y_desc("accuracy (%)");
    if !x_desc.is_empty() {
        m.x_desc(x_desc);
    }
    m.draw()?;
    Ok(chart)
}
