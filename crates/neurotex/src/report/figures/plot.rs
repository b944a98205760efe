//! What every figure shares: the SVG canvas, text sizes, colours, legends, category labels,
//! colour scales and the grid of small multiples.
//!
//! Text is placed with plotters' built-in size estimate: the crate is built without its
//! `ttf` and `ab_glyph` features, so no font file is loaded, and the SVG backend writes
//! `<text>` elements that the viewer sets in its own sans-serif. The estimate is about right
//! for such fonts; the layouts below leave a few pixels of slack for its error.

use plotters::chart::{ChartContext, MeshStyle};
use plotters::coord::ranged1d::{Ranged, ValueFormatter};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::FigureError;

/// The drawing surface of one figure.
pub(crate) type Canvas<'a> = DrawingArea<SVGBackend<'a>, Shift>;
/// What drawing on a [`Canvas`] returns.
pub(crate) type Drawn = Result<(), DrawingAreaErrorKind<std::io::Error>>;
/// A chart with numeric axes on a [`Canvas`].
pub(crate) type Chart<'a, 'b> =
    ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Font family of all text.
pub(crate) const FONT: &str = "sans-serif";
/// Tick labels and legends (plotters' size; the SVG font size is this / 1.24, about 12 px).
pub(crate) const TICK: f64 = 15.0;
/// Axis descriptions.
pub(crate) const LABEL: f64 = 16.5;
/// Titles.
pub(crate) const TITLE: f64 = 18.5;

/// The single taxel, in every figure.
pub(crate) const SINGLE: RGBColor = RGBColor(0, 114, 178);
/// The best single taxel, chosen after the fact.
pub(crate) const BEST: RGBColor = RGBColor(86, 180, 233);
/// 2D-GLCM.
pub(crate) const GLCM2D: RGBColor = RGBColor(0, 158, 115);
/// 3D-GLCM.
pub(crate) const GLCM3D: RGBColor = RGBColor(213, 94, 0);
/// Reference lines (chance).
pub(crate) const GREY: RGBColor = RGBColor(105, 105, 105);
/// Grid lines and shaded bands.
pub(crate) const LIGHT: RGBColor = RGBColor(228, 228, 228);
/// Colours for one series per class (Okabe and Ito's colour-blind safe set, yellow last
/// since it is faint on white).
pub(crate) const SERIES: [RGBColor; 8] = [
    RGBColor(0, 114, 178),
    RGBColor(230, 159, 0),
    RGBColor(0, 158, 115),
    RGBColor(213, 94, 0),
    RGBColor(204, 121, 167),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
    RGBColor(240, 228, 66),
];

/// The colour of series `k`, and whether it is dashed: past eight series the colours come
/// round again, dashed so that no two series look alike.
pub(crate) fn series(k: usize) -> (RGBColor, bool) {
    (SERIES[k % SERIES.len()], k >= SERIES.len())
}

/// Draws a figure of `size` pixels on a white background and returns its SVG text.
pub(crate) fn render(
    size: (u32, u32),
    draw: impl FnOnce(&Canvas<'_>) -> Drawn,
) -> Result<String, FigureError> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        root.fill(&WHITE)?;
        draw(&root)?;
        root.present()?;
    }
    Ok(svg)
}

/// The width in pixels plotters reserves for `text` at `size`.
pub(crate) fn text_width(text: &str, size: f64) -> i32 {
    (FONT, size).into_font().box_size(text).map_or(
        (0.46 * size * text.chars().count() as f64) as i32,
        |(w, _)| w as i32,
    )
}

/// A text style of `size`, anchored at `h`, `v`.
pub(crate) fn text(size: f64, h: HPos, v: VPos) -> TextStyle<'static> {
    TextStyle::from((FONT, size).into_font()).pos(Pos::new(h, v))
}

/// A tick value without trailing zeros (`0`, `0.5`, `20`, never `-0`).
pub(crate) fn number(v: f64) -> String {
    let s = format!("{:.2}", v);
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
}

/// A percentage for a legend: whole numbers as such, others to one decimal (`20`, `14.3`).
pub(crate) fn percent(v: f64) -> String {
    if (v - v.round()).abs() < 1e-9 {
        format!("{v:.0}")
    } else {
        format!("{v:.1}")
    }
}

/// The mesh every numeric chart uses: grey grid lines at the labelled ticks only, tick
/// labels and axis descriptions in the figure's sizes.
pub(crate) fn mesh<'a, 'b, DB, X, Y, XT, YT>(
    chart: &'b mut ChartContext<'a, DB, Cartesian2d<X, Y>>,
) -> MeshStyle<'a, 'b, X, Y, DB>
where
    DB: DrawingBackend,
    X: Ranged<ValueType = XT> + ValueFormatter<XT>,
    Y: Ranged<ValueType = YT> + ValueFormatter<YT>,
    XT: std::fmt::Debug,
    YT: std::fmt::Debug,
{
    let mut m = chart.configure_mesh();
    m.label_style((FONT, TICK))
        .axis_desc_style((FONT, LABEL))
        .bold_line_style(LIGHT)
        .max_light_lines(0)
        .axis_style(BLACK);
    m
}

/// A horizontal dashed line at `y` across the chart.
pub(crate) fn hline(chart: &mut Chart, y: f64, colour: RGBColor, dash: i32) -> Drawn {
    let x = chart.x_range();
    chart.draw_series(DashedLineSeries::new(
        [(x.start, y), (x.end, y)],
        dash,
        dash * 2 / 3,
        colour.stroke_width(2),
    ))?;
    Ok(())
}

/// A vertical dashed line at `x` across the chart.
pub(crate) fn vline(chart: &mut Chart, x: f64, colour: RGBColor, dash: i32) -> Drawn {
    let y = chart.y_range();
    chart.draw_series(DashedLineSeries::new(
        [(x, y.start), (x, y.end)],
        dash,
        dash * 2 / 3,
        colour.stroke_width(2),
    ))?;
    Ok(())
}

/// An error bar from `lo` to `hi` at `x`, with caps `cap` wide (in x units).
pub(crate) fn error_bar(chart: &mut Chart, x: f64, lo: f64, hi: f64, cap: f64) -> Drawn {
    let style = BLACK.stroke_width(1);
    chart.draw_series([
        PathElement::new(vec![(x, lo), (x, hi)], style),
        PathElement::new(vec![(x - cap, lo), (x + cap, lo)], style),
        PathElement::new(vec![(x - cap, hi), (x + cap, hi)], style),
    ])?;
    Ok(())
}

/// Tick marks and labels at the data's own x values (as `k` in 1, 3, 5), in place of
/// plotters' evenly spaced ticks.
pub(crate) fn x_ticks_at(canvas: &Canvas, chart: &Chart, values: &[f64]) -> Drawn {
    let base = canvas.get_base_pixel();
    let y0 = chart.y_range().start;
    for &v in values {
        let (x, y) = chart.backend_coord(&(v, y0));
        let (x, y) = (x - base.0, y - base.1);
        canvas.draw(&PathElement::new(
            vec![(x, y), (x, y + 5)],
            BLACK.stroke_width(1),
        ))?;
        let style = text(TICK, HPos::Center, VPos::Top);
        canvas.draw(&Text::new(number(v), (x, y + 7), style))?;
    }
    Ok(())
}

/// A line through `points` with a marker at each, dashed when `dashed`.
pub(crate) fn line_with_markers(
    chart: &mut Chart,
    points: &[(f64, f64)],
    colour: RGBColor,
    dashed: bool,
) -> Drawn {
    let stroke = colour.stroke_width(2);
    if dashed {
        chart.draw_series(DashedLineSeries::new(points.iter().copied(), 7, 4, stroke))?;
    } else {
        chart.draw_series(LineSeries::new(points.iter().copied(), stroke))?;
    }
    chart.draw_series(points.iter().map(|&p| Circle::new(p, 3, colour.filled())))?;
    Ok(())
}

/// How a legend entry is drawn.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Swatch {
    /// A filled bar.
    Bar(RGBColor),
    /// An outlined, empty bar.
    Hollow(RGBColor),
    /// A bar with an error bar.
    BarError(RGBColor),
    /// A solid line.
    Line(RGBColor),
    /// A dashed line with no marker, for a series.
    DashedLine(RGBColor),
    /// A solid line with a marker.
    Points(RGBColor),
    /// A dashed line with a marker.
    DashedPoints(RGBColor),
    /// A dashed line.
    Dashed(RGBColor),
    /// A marker alone: a cross.
    Cross(RGBColor),
    /// A shaded band.
    Band(RGBColor),
}

/// One legend entry.
#[derive(Debug, Clone)]
pub(crate) struct Key {
    /// Its text.
    pub(crate) label: String,
    /// Its swatch.
    pub(crate) swatch: Swatch,
}

impl Key {
    /// An entry `label` drawn as `swatch`.
    pub(crate) fn new(label: impl Into<String>, swatch: Swatch) -> Self {
        Key {
            label: label.into(),
            swatch,
        }
    }
}

const KEY_ROW: i32 = 21;
const SWATCH_W: i32 = 28;

/// The pixels a legend of `keys` takes, `(width, height)`.
pub(crate) fn legend_size(keys: &[Key]) -> (i32, i32) {
    let text = keys
        .iter()
        .map(|k| text_width(&k.label, TICK))
        .max()
        .unwrap_or(0);
    (SWATCH_W + 8 + text + 4, KEY_ROW * keys.len() as i32)
}

/// Draws a legend with its top left corner at `(x, y)`, one entry a row.
pub(crate) fn legend(canvas: &Canvas, (x, y): (i32, i32), keys: &[Key]) -> Drawn {
    for (k, key) in keys.iter().enumerate() {
        let cy = y + KEY_ROW * k as i32 + KEY_ROW / 2;
        let (x0, x1) = (x, x + SWATCH_W);
        let bar = [(x0 + 4, cy - 6), (x1 - 4, cy + 7)];
        match key.swatch {
            Swatch::Bar(c) => canvas.draw(&Rectangle::new(bar, c.filled()))?,
            Swatch::Hollow(c) => canvas.draw(&Rectangle::new(bar, c.stroke_width(2)))?,
            Swatch::BarError(c) => {
                canvas.draw(&Rectangle::new(bar, c.filled()))?;
                let mx = (x0 + x1) / 2;
                for points in [
                    vec![(mx, cy - 9), (mx, cy + 3)],
                    vec![(mx - 3, cy - 9), (mx + 3, cy - 9)],
                    vec![(mx - 3, cy + 3), (mx + 3, cy + 3)],
                ] {
                    canvas.draw(&PathElement::new(points, BLACK.stroke_width(1)))?;
                }
            }
            Swatch::Line(c)
            | Swatch::DashedLine(c)
            | Swatch::Points(c)
            | Swatch::DashedPoints(c)
            | Swatch::Dashed(c) => {
                let style = c.stroke_width(2);
                if matches!(key.swatch, Swatch::Points(_) | Swatch::Line(_)) {
                    canvas.draw(&PathElement::new(vec![(x0, cy), (x1, cy)], style))?;
                } else {
                    for dash in [(x0, x0 + 8), (x0 + 11, x0 + 18), (x0 + 21, x1)] {
                        canvas.draw(&PathElement::new(vec![(dash.0, cy), (dash.1, cy)], style))?;
                    }
                }
                if matches!(key.swatch, Swatch::Points(_) | Swatch::DashedPoints(_)) {
                    canvas.draw(&Circle::new(((x0 + x1) / 2, cy), 3, c.filled()))?;
                }
            }
            Swatch::Cross(c) => {
                canvas.draw(&Cross::new(((x0 + x1) / 2, cy), 4, c.stroke_width(2)))?
            }
            Swatch::Band(c) => canvas.draw(&Rectangle::new(bar, c.filled()))?,
        }
        canvas.draw(&Text::new(
            key.label.as_str(),
            (x1 + 8, cy),
            text(TICK, HPos::Left, VPos::Center),
        ))?;
    }
    Ok(())
}

/// Whether every label fits level in a slot of `slot` pixels; if not, labels are turned to
/// read upwards.
pub(crate) fn labels_fit(labels: &[String], slot: i32) -> bool {
    labels.iter().all(|l| text_width(l, TICK) + 6 <= slot)
}

/// The pixels category labels take below an axis: one line when level, the longest label
/// when turned.
pub(crate) fn labels_height(labels: &[String], level: bool) -> i32 {
    if level {
        22
    } else {
        labels
            .iter()
            .map(|l| text_width(l, TICK))
            .max()
            .unwrap_or(0)
            + 10
    }
}

/// Draws category labels below a horizontal axis, centred on the pixel columns `xs`, their
/// top at pixel row `y`: level when `level`, else reading upwards and ending at `y`.
pub(crate) fn category_labels(
    canvas: &Canvas,
    labels: &[String],
    xs: &[i32],
    y: i32,
    level: bool,
) -> Drawn {
    for (label, &x) in labels.iter().zip(xs) {
        let style = if level {
            text(TICK, HPos::Center, VPos::Top)
        } else {
            text(TICK, HPos::Right, VPos::Center).transform(FontTransform::Rotate270)
        };
        canvas.draw(&Text::new(label.as_str(), (x, y + 5), style))?;
    }
    Ok(())
}

/// A sequential colour from near white (0) to dark blue (1), even in lightness so that the
/// colour bar reads as a scale.
pub(crate) fn heat(f: f64) -> RGBColor {
    const RAMP: [(f64, f64, f64); 5] = [
        (247.0, 251.0, 255.0),
        (198.0, 219.0, 239.0),
        (107.0, 174.0, 214.0),
        (33.0, 113.0, 181.0),
        (8.0, 48.0, 107.0),
    ];
    let f = if f.is_finite() {
        f.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let pos = f * (RAMP.len() - 1) as f64;
    let k = (pos.floor() as usize).min(RAMP.len() - 2);
    let t = pos - k as f64;
    let mix = |a: f64, b: f64| (a + (b - a) * t).round() as u8;
    let (a, b) = (RAMP[k], RAMP[k + 1]);
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// Whether text on a cell of colour [`heat`]`(f)` should be white to be read.
pub(crate) fn dark(f: f64) -> bool {
    f > 0.55
}

/// The width a colour bar with its labels takes.
pub(crate) const COLOUR_BAR_W: i32 = 72;

/// Draws a vertical colour bar of [`heat`] from 0 (bottom) to `max` (top) in the box at
/// `(x, y)` of `height` pixels, with ticks and the description `desc` on its right.
pub(crate) fn colour_bar(
    canvas: &Canvas,
    (x, y): (i32, i32),
    height: i32,
    max: f64,
    desc: &str,
) -> Drawn {
    let area = canvas
        .clone()
        .shrink((x, y - 8), (COLOUR_BAR_W, height + 16));
    let max = if max > 0.0 { max } else { 1.0 };
    let mut chart = ChartBuilder::on(&area)
        .margin_top(8)
        .margin_bottom(8)
        .right_y_label_area_size(COLOUR_BAR_W - 22)
        .build_cartesian_2d(0.0..1.0, 0.0..max)?;
    let steps = 64;
    chart.draw_series((0..steps).map(|k| {
        let (lo, hi) = (k as f64 / steps as f64, (k + 1) as f64 / steps as f64);
        Rectangle::new(
            [(0.0, lo * max), (1.0, hi * max)],
            heat((lo + hi) / 2.0).filled(),
        )
    }))?;
    chart.draw_series([Rectangle::new(
        [(0.0, 0.0), (1.0, max)],
        BLACK.stroke_width(1),
    )])?;
    mesh(&mut chart)
        .disable_mesh()
        .disable_x_axis()
        .y_labels(6)
        .y_label_formatter(&|v| number(*v))
        .y_desc(desc)
        .draw()?;
    Ok(())
}

/// Columns and rows of a grid of `n` small multiples: one row up to four panels, then close
/// to square, so twelve panels are 4 x 3 rather than one tall column.
pub(crate) fn grid(n: usize) -> (usize, usize) {
    let cols = if n <= 4 {
        n.max(1)
    } else {
        (n as f64).sqrt().ceil() as usize
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
    if upright {
        let style = text(LABEL, HPos::Center, VPos::Top).transform(FontTransform::Rotate270);
        canvas.draw(&Text::new(desc, (at.0, (span.0 + span.1) / 2), style))
    } else {
        let style = text(LABEL, HPos::Center, VPos::Top);
        canvas.draw(&Text::new(desc, ((span.0 + span.1) / 2, at.1), style))
    }
}

/// A grid of small multiples, one panel per item, sharing their axis descriptions and one
/// legend on the right.
pub(crate) struct Multiples<'a> {
    /// Panels.
    pub(crate) n: usize,
    /// Pixels of one panel, `(width, height)`, tick labels and panel title included.
    pub(crate) panel: (i32, i32),
    /// The figure's title.
    pub(crate) title: &'a str,
    /// The x description, once under the grid.
    pub(crate) x_desc: &'a str,
    /// The y description, once left of the grid.
    pub(crate) y_desc: &'a str,
    /// The legend.
    pub(crate) keys: &'a [Key],
}

/// Draws the grid of `m`, calling `panel(i, area)` to draw panel `i` in its area.
pub(crate) fn multiples(
    m: &Multiples,
    mut panel: impl FnMut(usize, &Canvas) -> Drawn,
) -> Result<String, FigureError> {
    let (cols, rows) = grid(m.n);
    let (pw, ph) = m.panel;
    let (legend_w, legend_h) = legend_size(m.keys);
    let (left, top, bottom) = (30, 44, 34);
    let grid_w = pw * cols as i32;
    let grid_h = ph * rows as i32;
    let width = left + grid_w + 16 + legend_w + 12;
    let height = top + grid_h.max(legend_h) + bottom;
    render((width as u32, height as u32), |root| {
        let style = text(TITLE, HPos::Center, VPos::Top);
        root.draw(&Text::new(m.title, (left + grid_w / 2, 8), style))?;
        for i in 0..m.n {
            let (r, c) = ((i / cols) as i32, (i % cols) as i32);
            let area = root.clone().shrink((left + c * pw, top + r * ph), (pw, ph));
            panel(i, &area)?;
        }
        axis_desc(
            root,
            m.x_desc,
            (0, top + grid_h + 6),
            (left, left + grid_w),
            false,
        )?;
        axis_desc(root, m.y_desc, (4, 0), (top, top + grid_h), true)?;
        legend(root, (left + grid_w + 16, top + 4), m.keys)
    })
}

/// A panel's chart: its title above, tick labels only (the grid carries the descriptions).
pub(crate) fn panel_chart<'a, 'b>(
    area: &'a Canvas<'b>,
    title: &str,
    x: std::ops::Range<f64>,
    y: std::ops::Range<f64>,
) -> Result<Chart<'a, 'b>, DrawingAreaErrorKind<std::io::Error>> {
    ChartBuilder::on(area)
        .caption(title, (FONT, LABEL))
        .margin(4)
        .margin_top(10)
        .margin_right(14)
        .x_label_area_size(24)
        .y_label_area_size(40)
        .build_cartesian_2d(x, y)
}

/// A chart of accuracy (0-100 %, a labelled grid line every 10) over `groups` categories
/// of one x unit each, on `area` with `title`, room for `(left, bottom)` pixels of labels, and
/// the x description `x_desc` (none when empty); the categories' own labels are drawn apart.
pub(crate) fn accuracy_chart<'a, 'b>(
    area: &'a Canvas<'b>,
    title: &str,
    groups: usize,
    (left, bottom): (i32, i32),
    x_desc: &str,
) -> Result<Chart<'a, 'b>, DrawingAreaErrorKind<std::io::Error>> {
    let mut chart = ChartBuilder::on(area)
        .caption(title, (FONT, TITLE))
        .margin_top(6)
        .margin_right(12)
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_drop_trailing_zeros_and_minus_zero() {
        assert_eq!(number(20.0), "20");
        assert_eq!(number(0.5), "0.5");
        assert_eq!(number(-0.0001), "0");
        assert_eq!(number(0.25), "0.25");
    }

    #[test]
    fn grids_wrap_into_rows() {
        assert_eq!(grid(3), (3, 1));
        assert_eq!(grid(12), (4, 3));
        assert_eq!(grid(16), (4, 4));
        assert_eq!(grid(5), (3, 2));
        assert_eq!(grid(0), (1, 1));
    }

    #[test]
    fn heat_runs_light_to_dark() {
        let lum = |c: RGBColor| u32::from(c.0) + u32::from(c.1) + u32::from(c.2);
        assert!(lum(heat(0.0)) > lum(heat(0.5)) && lum(heat(0.5)) > lum(heat(1.0)));
        assert_eq!(heat(f64::NAN), heat(0.0));
    }

    #[test]
    fn text_width_is_plotters_naive_estimate() {
        // without a font file plotters estimates 0.7 em a character at size / 1.24^2
        let w = text_width("abcdefghij", 15.0);
        assert_eq!(w, (15.0 / 1.24 / 1.24 * 0.7 * 10.0_f64).round() as i32);
    }
}
