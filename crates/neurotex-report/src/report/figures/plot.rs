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

mod colour_scale;
mod frame;
mod legend;
mod multiples;

pub(crate) use colour_scale::{colour_bar, colour_bar_width, dark, heat};
pub(crate) use frame::{category_labels, Frame, Placement};
pub(crate) use legend::{legend_size, Key, Swatch};
pub(crate) use multiples::{
    accuracy_chart, axis_desc, line_chart, multiples, multiples_in, panel_chart, Multiples,
};

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

/// A horizontal accuracy axis from 0 to 100 % with a tick every 10, and no y labels: the
/// axis of the rankings.
pub(crate) fn accuracy_axis(chart: &mut Chart) -> Drawn {
    mesh(chart)
        .disable_y_mesh()
        .y_labels(0)
        .x_labels(11)
        .x_label_formatter(&|v| number(*v))
        .x_desc("accuracy (%)")
        .draw()
}

/// An interval from `lo` to `hi` at height `y`, with short caps, in `colour`.
pub(crate) fn interval(chart: &mut Chart, [lo, hi]: [f64; 2], y: f64, colour: RGBColor) -> Drawn {
    let (style, cap) = (colour.stroke_width(1), 0.25);
    chart.draw_series([
        PathElement::new(vec![(lo, y), (hi, y)], style),
        PathElement::new(vec![(lo, y - cap), (lo, y + cap)], style),
        PathElement::new(vec![(hi, y - cap), (hi, y + cap)], style),
    ])?;
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

/// Markers at `points`, joined by no line: values at categories that have no order.
pub(crate) fn markers(chart: &mut Chart, points: &[(f64, f64)], colour: RGBColor) -> Drawn {
    chart.draw_series(points.iter().map(|&p| Circle::new(p, 3, colour.filled())))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::colour_scale::colour_ticks;
    use super::legend::KEY_ROW;
    use super::multiples::grid;
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
