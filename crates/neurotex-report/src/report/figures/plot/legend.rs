//! Legends: the keys of a figure's series (a line, a marker, a bar, a band), laid out in rows
//! above the plot.

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use super::{fit, text, text_width, Canvas, Drawn, TICK};

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

pub(super) const KEY_ROW: i32 = 15;

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
pub(super) fn swatch(canvas: &Canvas, swatch: Swatch, x0: i32, cy: i32) -> Drawn {
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
