//! What every figure shares: the canvas at a paper's column or page width, text sizes in
//! points, colours, the title with the data's name, legends above the plot, category
//! labels, colour scales and the grid of small multiples.
//!
//! The SVG's pixels are CSS pixels, 96 to the inch, so a figure is as wide as the paper's
//! column (3.5 in, 336 px) or page (7 in, 672 px) it is drawn for, and its text sizes are
//! the points it prints at: 8 pt ticks and legends, 9 pt axis descriptions, 10 pt titles.
//! Text is measured with the font it is drawn in (Noto Sans, bundled: see
//! [`super::raster`]), so a legend or a label takes the room it needs and no more; a
//! viewer setting the SVG in another sans-serif may run a few per cent wider or narrower,
//! which the layouts' gaps absorb.

use std::sync::OnceLock;

use plotters::chart::{ChartContext, MeshStyle};
use plotters::coord::ranged1d::{Ranged, ValueFormatter};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use skrifa::instance::{LocationRef, Size};
use skrifa::{FontRef, MetadataProvider};

use super::FigureError;

/// The drawing surface of one figure.
pub(crate) type Canvas<'a> = DrawingArea<SVGBackend<'a>, Shift>;
/// What drawing on a [`Canvas`] returns.
pub(crate) type Drawn = Result<(), DrawingAreaErrorKind<std::io::Error>>;
/// A chart with numeric axes on a [`Canvas`].
pub(crate) type Chart<'a, 'b> =
    ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// The SVG's pixels to the inch: CSS pixels, so that a browser prints the SVG at its
/// paper width.
pub(crate) const DPI: f64 = 96.0;
/// The font every figure is set in, as TrueType data: text is measured here and drawn
/// with it in the PNGs ([`super::raster`]).
pub(crate) const FONT_DATA: &[u8] = ttf_noto_sans::REGULAR;

/// The paper width a figure is laid out for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Width {
    /// One column of a two-column paper, 3.5 in.
    Column,
    /// The whole text width, 7 in.
    Page,
}

impl Width {
    /// The width in pixels, at [`DPI`].
    pub(crate) const fn px(self) -> i32 {
        match self {
            Width::Column => 336,
            Width::Page => 672,
        }
    }

    /// A column when `needed` pixels fit one, else the page.
    pub(crate) fn fitting(needed: i32) -> Self {
        if needed <= Width::Column.px() {
            Width::Column
        } else {
            Width::Page
        }
    }
}

/// A size in points as plotters' font size (plotters writes its size / 1.24 as the SVG's
/// font-size, in pixels).
const fn pt(points: f64) -> f64 {
    points * DPI / 72.0 * 1.24
}

/// Font family of all text.
pub(crate) const FONT: &str = "sans-serif";
/// Tick labels, legends and the data's name: 8 pt.
pub(crate) const TICK: f64 = pt(8.0);
/// Axis descriptions and panel titles: 9 pt.
pub(crate) const LABEL: f64 = pt(9.0);
/// Titles: 10 pt.
pub(crate) const TITLE: f64 = pt(10.0);
/// Numbers inside the cells of a matrix: 7 pt, the smallest text of any figure.
pub(crate) const SMALL: f64 = pt(7.0);
/// Space around the figure's content.
pub(crate) const MARGIN: i32 = 6;

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
    size: (i32, i32),
    draw: impl FnOnce(&Canvas<'_>) -> Drawn,
) -> Result<String, FigureError> {
    let mut svg = String::new();
    {
        let size = (size.0.max(1) as u32, size.1.max(1) as u32);
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        root.fill(&WHITE)?;
        draw(&root)?;
        root.present()?;
    }
    Ok(svg)
}

/// The bundled font, parsed once.
fn font() -> &'static FontRef<'static> {
    static FONT_REF: OnceLock<FontRef<'static>> = OnceLock::new();
    FONT_REF.get_or_init(|| FontRef::new(FONT_DATA).expect("the bundled font parses"))
}

/// The width in pixels of `text` at plotters' `size`, from the font's advance widths.
pub(crate) fn text_width(text: &str, size: f64) -> i32 {
    let px = (size / 1.24) as f32;
    let font = font();
    let (charmap, metrics) = (
        font.charmap(),
        font.glyph_metrics(Size::new(px), LocationRef::default()),
    );
    let width: f32 = text
        .chars()
        .map(|c| {
            let glyph = charmap.map(c).unwrap_or_default();
            metrics.advance_width(glyph).unwrap_or(0.6 * px)
        })
        .sum();
    width.ceil() as i32
}

/// The pixels one line of text at `size` takes, with its leading.
pub(crate) fn line_height(size: f64) -> i32 {
    (size / 1.24 * 1.3).ceil() as i32
}

/// `text` cut to at most `max` pixels at `size`, an ellipsis marking the cut.
pub(crate) fn fit(text: &str, size: f64, max: i32) -> String {
    if text_width(text, size) <= max {
        return text.to_string();
    }
    let mut cut: String = text.to_string();
    while !cut.is_empty() && text_width(&format!("{cut}…"), size) > max {
        cut.pop();
    }
    format!("{}…", cut.trim_end())
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
        .x_label_offset(0)
        .set_all_tick_mark_size(3)
        .axis_style(BLACK);
    m
}

/// Room for tick labels and an axis description left of a chart.
pub(crate) const Y_AXIS_W: i32 = 44;
/// Room for tick labels and an axis description under a chart.
pub(crate) const X_AXIS_H: i32 = 34;

/// A horizontal dashed line at `y` across the chart.
pub(crate) fn hline(chart: &mut Chart, y: f64, colour: RGBColor, dash: i32) -> Drawn {
    let x = chart.x_range();
    chart.draw_series(DashedLineSeries::new(
        [(x.start, y), (x.end, y)],
        dash,
        dash * 2 / 3,
        colour.stroke_width(1),
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
        colour.stroke_width(1),
    ))?;
    Ok(())
}

/// A translucent band in `colour` between the lower and upper ends of `points`
/// (`(x, lo, hi)`, in ascending x): a series' interval along its line.
pub(crate) fn band(chart: &mut Chart, points: &[(f64, f64, f64)], colour: RGBColor) -> Drawn {
    if points.len() < 2 {
        return Ok(());
    }
    let outline: Vec<(f64, f64)> = points
        .iter()
        .map(|&(x, lo, _)| (x, lo))
        .chain(points.iter().rev().map(|&(x, _, hi)| (x, hi)))
        .collect();
    chart.draw_series(std::iter::once(Polygon::new(
        outline,
        colour.mix(0.2).filled(),
    )))?;
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
            vec![(x, y), (x, y + 3)],
            BLACK.stroke_width(1),
        ))?;
        let style = text(TICK, HPos::Center, VPos::Top);
        canvas.draw(&Text::new(number(v), (x, y + 5), style))?;
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
        chart.draw_series(DashedLineSeries::new(points.iter().copied(), 6, 3, stroke))?;
    } else {
        chart.draw_series(LineSeries::new(points.iter().copied(), stroke))?;
    }
    chart.draw_series(points.iter().map(|&p| Circle::new(p, 2, colour.filled())))?;
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

    /// The pixels the entry takes in a row: swatch, gap and text.
    fn width(&self) -> i32 {
        SWATCH_W + 4 + text_width(&self.label, TICK)
    }
}

const KEY_ROW: i32 = 15;
const SWATCH_W: i32 = 18;
/// Between two columns of a legend.
const KEY_GAP: i32 = 12;

/// How a legend of several entries is set within a width: the widths of its columns
/// (entries fill them row by row) and its rows.
struct LegendGrid {
    columns: Vec<i32>,
    rows: usize,
}

impl LegendGrid {
    /// As many columns as fit `max_w` pixels (each as wide as its widest entry), so that
    /// the legend takes few rows across the figure rather than a column beside it.
    fn of(keys: &[Key], max_w: i32) -> Self {
        let widths: Vec<i32> = keys.iter().map(Key::width).collect();
        for cols in (1..=keys.len().max(1)).rev() {
            let columns: Vec<i32> = (0..cols)
                .map(|c| {
                    widths
                        .iter()
                        .skip(c)
                        .step_by(cols)
                        .copied()
                        .max()
                        .unwrap_or(0)
                })
                .collect();
            let total = columns.iter().sum::<i32>() + KEY_GAP * (cols as i32 - 1);
            if total <= max_w || cols == 1 {
                let rows = keys.len().div_ceil(cols);
                return LegendGrid { columns, rows };
            }
        }
        unreachable!("one column always fits")
    }

    fn size(&self, max_w: i32) -> (i32, i32) {
        let w = self.columns.iter().sum::<i32>() + KEY_GAP * (self.columns.len() as i32 - 1);
        (w.min(max_w), KEY_ROW * self.rows as i32)
    }
}

/// The pixels a legend of `keys` set within `max_w` pixels takes, `(width, height)`;
/// nothing for no keys.
pub(crate) fn legend_size(keys: &[Key], max_w: i32) -> (i32, i32) {
    if keys.is_empty() {
        return (0, 0);
    }
    LegendGrid::of(keys, max_w).size(max_w)
}

/// Draws a legend with its top left corner at `(x, y)` within `max_w` pixels, in as many
/// columns as fit (a label too long for the width alone is cut with an ellipsis).
pub(crate) fn legend(canvas: &Canvas, (x, y): (i32, i32), keys: &[Key], max_w: i32) -> Drawn {
    if keys.is_empty() {
        return Ok(());
    }
    let grid = LegendGrid::of(keys, max_w);
    let cols = grid.columns.len();
    for (k, key) in keys.iter().enumerate() {
        let (row, col) = ((k / cols) as i32, k % cols);
        let x0 = x + grid.columns[..col].iter().sum::<i32>() + KEY_GAP * col as i32;
        let cy = y + KEY_ROW * row + KEY_ROW / 2;
        swatch(canvas, key.swatch, x0, cy)?;
        let label = fit(&key.label, TICK, max_w - SWATCH_W - 4);
        canvas.draw(&Text::new(
            label,
            (x0 + SWATCH_W + 4, cy),
            text(TICK, HPos::Left, VPos::Center),
        ))?;
    }
    Ok(())
}

/// Draws `swatch` from `x0`, centred on row `cy`.
fn swatch(canvas: &Canvas, swatch: Swatch, x0: i32, cy: i32) -> Drawn {
    let x1 = x0 + SWATCH_W;
    let bar = [(x0 + 3, cy - 4), (x1 - 3, cy + 5)];
    match swatch {
        Swatch::Bar(c) | Swatch::Band(c) => canvas.draw(&Rectangle::new(bar, c.filled())),
        Swatch::Hollow(c) => canvas.draw(&Rectangle::new(bar, c.stroke_width(1))),
        Swatch::BarError(c) => {
            canvas.draw(&Rectangle::new(bar, c.filled()))?;
            let mx = (x0 + x1) / 2;
            for points in [
                vec![(mx, cy - 7), (mx, cy + 2)],
                vec![(mx - 2, cy - 7), (mx + 2, cy - 7)],
                vec![(mx - 2, cy + 2), (mx + 2, cy + 2)],
            ] {
                canvas.draw(&PathElement::new(points, BLACK.stroke_width(1)))?;
            }
            Ok(())
        }
        Swatch::Line(c)
        | Swatch::DashedLine(c)
        | Swatch::Points(c)
        | Swatch::DashedPoints(c)
        | Swatch::Dashed(c) => {
            let width = if matches!(swatch, Swatch::Dashed(_)) {
                1
            } else {
                2
            };
            let style = c.stroke_width(width);
            if matches!(swatch, Swatch::Points(_) | Swatch::Line(_)) {
                canvas.draw(&PathElement::new(vec![(x0, cy), (x1, cy)], style))?;
            } else {
                for dash in [(x0, x0 + 5), (x0 + 7, x0 + 11), (x0 + 13, x1)] {
                    canvas.draw(&PathElement::new(vec![(dash.0, cy), (dash.1, cy)], style))?;
                }
            }
            if matches!(swatch, Swatch::Points(_) | Swatch::DashedPoints(_)) {
                canvas.draw(&Circle::new(((x0 + x1) / 2, cy), 2, c.filled()))?;
            }
            Ok(())
        }
        Swatch::Cross(c) => canvas.draw(&Cross::new(((x0 + x1) / 2, cy), 3, c.stroke_width(1))),
    }
}

/// The height of a figure's heading: the title, and the data's name on its right or, when
/// both do not fit one line, on a line of its own.
fn heading_height(title: &str, source: &str, width: i32) -> i32 {
    let one_line = heading_fits(title, source, width);
    MARGIN + line_height(TITLE) + if one_line { 0 } else { line_height(TICK) } + 4
}

fn heading_fits(title: &str, source: &str, width: i32) -> bool {
    source.is_empty()
        || text_width(title, TITLE) + 16 + text_width(source, TICK) <= width - 2 * MARGIN
}

/// Draws the title at the top left and the data's name, in grey, at the top right (or
/// under the title when they do not fit one line).
fn heading(canvas: &Canvas, title: &str, source: &str, width: i32) -> Drawn {
    canvas.draw(&Text::new(
        fit(title, TITLE, width - 2 * MARGIN),
        (MARGIN, MARGIN),
        text(TITLE, HPos::Left, VPos::Top),
    ))?;
    if source.is_empty() {
        return Ok(());
    }
    let grey = |h| text(TICK, h, VPos::Top).color(&GREY);
    let source_text = fit(source, TICK, width - 2 * MARGIN);
    if heading_fits(title, source, width) {
        // level with the title's baseline: the smaller text starts a little lower
        let y = MARGIN + line_height(TITLE) - line_height(TICK);
        canvas.draw(&Text::new(
            source_text,
            (width - MARGIN, y),
            grey(HPos::Right),
        ))
    } else {
        let y = MARGIN + line_height(TITLE);
        canvas.draw(&Text::new(source_text, (MARGIN, y), grey(HPos::Left)))
    }
}

/// A figure's frame: its width, the heading (title and the data's name) and the legend
/// under it, across the figure, above the body the figure draws.
pub(crate) struct Frame<'a> {
    /// The paper width.
    pub(crate) width: Width,
    /// The title.
    pub(crate) title: &'a str,
    /// The data, in a few words (`simulated rig, seed 0`, a dataset folder's name).
    pub(crate) source: &'a str,
    /// The legend; none when empty.
    pub(crate) keys: &'a [Key],
}

impl Frame<'_> {
    /// The width in pixels.
    pub(crate) fn px(&self) -> i32 {
        self.width.px()
    }

    /// The pixels above the body: the heading and the legend.
    pub(crate) fn top(&self) -> i32 {
        let legend_h = legend_size(self.keys, self.legend_w()).1;
        heading_height(self.title, self.source, self.px()) + legend_h + 4 * i32::from(legend_h > 0)
    }

    fn legend_w(&self) -> i32 {
        self.px() - 2 * MARGIN
    }

    /// Draws the frame and, through `body(root, area)`, the body of `body_h` pixels under
    /// it, full width; returns the SVG.
    pub(crate) fn render(
        &self,
        body_h: i32,
        body: impl FnOnce(&Canvas, &Canvas) -> Drawn,
    ) -> Result<String, FigureError> {
        let (width, top) = (self.px(), self.top());
        render((width, top + body_h + MARGIN), |root| {
            heading(root, self.title, self.source, width)?;
            let max_w = self.legend_w();
            let (legend_w, _) = legend_size(self.keys, max_w);
            let y = heading_height(self.title, self.source, width);
            legend(root, ((width - legend_w) / 2, y), self.keys, max_w)?;
            let area = root.clone().shrink((0, top), (width, body_h));
            body(root, &area)
        })
    }
}

/// How category labels are set under an axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Placement {
    /// One line, each label centred on its slot.
    Level,
    /// Two or three lines, the labels taking them in turn, so each has as many slots' room
    /// (cut with an ellipsis if even three are too few).
    Staggered(i32),
}

impl Placement {
    /// On as few lines (up to three) as let every label fit its room of slots of `slot`
    /// pixels.
    pub(crate) fn of(labels: &[String], slot: i32) -> Self {
        let widest = widest(labels);
        match (1..=3).find(|lines| widest + 4 <= lines * slot) {
            Some(1) => Placement::Level,
            Some(lines) => Placement::Staggered(lines),
            None => Placement::Staggered(3),
        }
    }

    /// Whether every label fits whole.
    pub(crate) fn fits(labels: &[String], slot: i32) -> bool {
        let widest = widest(labels);
        widest + 4 <= 3 * slot
    }

    fn lines(self) -> i32 {
        match self {
            Placement::Level => 1,
            Placement::Staggered(lines) => lines,
        }
    }

    /// The pixels the labels take under the axis.
    pub(crate) fn height(self) -> i32 {
        5 + self.lines() * line_height(TICK)
    }
}

/// The widest of `labels` at [`TICK`], in pixels.
fn widest(labels: &[String]) -> i32 {
    labels
        .iter()
        .map(|l| text_width(l, TICK))
        .max()
        .unwrap_or(0)
}

/// Draws category labels below a horizontal axis at pixel row `y`, centred on the pixel
/// columns `xs`, each with a slot of `slot` pixels; returns the placement used.
pub(crate) fn category_labels(
    canvas: &Canvas,
    labels: &[String],
    xs: &[i32],
    y: i32,
    slot: i32,
) -> Result<Placement, DrawingAreaErrorKind<std::io::Error>> {
    let placement = Placement::of(labels, slot);
    let lines = placement.lines();
    for (k, (label, &x)) in labels.iter().zip(xs).enumerate() {
        let line = k as i32 % lines;
        let style = text(TICK, HPos::Center, VPos::Top);
        let at = (x, y + 5 + line * line_height(TICK));
        canvas.draw(&Text::new(fit(label, TICK, lines * slot - 4), at, style))?;
    }
    Ok(placement)
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

const BAR_W: i32 = 10;

/// The width a colour bar with its tick labels and description takes.
pub(crate) fn colour_bar_width(max: f64) -> i32 {
    let widest = colour_ticks(max)
        .iter()
        .map(|&v| text_width(&number(v), TICK))
        .max()
        .unwrap_or(0);
    BAR_W + 3 + 3 + widest + 6 + line_height(LABEL)
}

/// Round tick values from 0 to `max`: five or so steps of 1, 2 or 5 times a power of ten.
fn colour_ticks(max: f64) -> Vec<f64> {
    let max = if max > 0.0 && max.is_finite() {
        max
    } else {
        1.0
    };
    let raw = max / 5.0;
    let power = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * power)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * power);
    (0..)
        .map(|k| k as f64 * step)
        .take_while(|v| *v <= max * (1.0 + 1e-9))
        .collect()
}

/// Draws a vertical colour bar of [`heat`] from 0 (bottom) to `max` (top), `height` pixels
/// tall from `(x, y)`, with tick marks and labels right of the bar and the description
/// `desc` reading upwards right of them.
pub(crate) fn colour_bar(
    canvas: &Canvas,
    (x, y): (i32, i32),
    height: i32,
    max: f64,
    desc: &str,
) -> Drawn {
    let max = if max > 0.0 && max.is_finite() {
        max
    } else {
        1.0
    };
    let steps = height.max(1);
    for k in 0..steps {
        let f = (f64::from(k) + 0.5) / f64::from(steps);
        let row = y + height - k - 1;
        // each pixel row overlaps the one below, so that no seam of the background shows
        // between rows in an antialiased rendering
        let bottom = (row + 2).min(y + height);
        canvas.draw(&Rectangle::new(
            [(x, row), (x + BAR_W, bottom)],
            heat(f).filled(),
        ))?;
    }
    canvas.draw(&Rectangle::new(
        [(x, y), (x + BAR_W, y + height)],
        BLACK.stroke_width(1),
    ))?;
    let mut widest = 0;
    for v in colour_ticks(max) {
        let row = y + height - (f64::from(height) * v / max).round() as i32;
        canvas.draw(&PathElement::new(
            vec![(x + BAR_W, row), (x + BAR_W + 3, row)],
            BLACK.stroke_width(1),
        ))?;
        let label = number(v);
        widest = widest.max(text_width(&label, TICK));
        let style = text(TICK, HPos::Left, VPos::Center);
        canvas.draw(&Text::new(label, (x + BAR_W + 6, row), style))?;
    }
    let desc_x = x + BAR_W + 6 + widest + 6;
    axis_desc(canvas, desc, (desc_x, 0), (y, y + height), true)
}

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
        assert_eq!(grid(30), (4, 8));
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
    fn text_is_measured_with_the_font() {
        // Noto Sans: "W" is wider than "i", and a width grows with the size
        assert!(text_width("WWWW", TICK) > 2 * text_width("iiii", TICK));
        assert!(text_width("accuracy", TITLE) > text_width("accuracy", TICK));
        // 8 pt is 10.67 px; "0" is 0.572 em in Noto Sans: 10 x 6.1 px
        assert_eq!(text_width("0000000000", TICK), 61);
    }

    #[test]
    fn long_text_is_cut_with_an_ellipsis() {
        let cut = fit("a rather long label for a legend", TICK, 60);
        assert!(cut.ends_with('…') && text_width(&cut, TICK) <= 60, "{cut}");
        assert_eq!(fit("short", TICK, 60), "short");
    }

    #[test]
    fn legends_take_as_many_columns_as_fit() {
        let keys: Vec<Key> = ["one", "two", "three", "four"]
            .iter()
            .map(|l| Key::new(*l, Swatch::Bar(SINGLE)))
            .collect();
        let (w, h) = legend_size(&keys, 600);
        assert_eq!(h, KEY_ROW, "one row across");
        assert!(w < 600);
        assert_eq!(legend_size(&keys, w - 1).1, 2 * KEY_ROW);
        assert_eq!(legend_size(&[], 600), (0, 0));
    }

    #[test]
    fn colour_ticks_are_round() {
        assert_eq!(
            colour_ticks(100.0),
            vec![0.0, 20.0, 40.0, 60.0, 80.0, 100.0]
        );
        assert_eq!(colour_ticks(63.0), vec![0.0, 20.0, 40.0, 60.0]);
        assert_eq!(
            colour_ticks(0.0),
            vec![0.0, 0.2, 0.4, 0.6000000000000001, 0.8, 1.0]
        );
    }
}
