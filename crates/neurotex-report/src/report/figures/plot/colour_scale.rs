//! Colour scales: a share's colour on the heat scale, and the bar that explains it.

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use super::multiples::axis_desc;
use super::{line_height, number, text, text_width, Canvas, Drawn, LABEL, TICK};

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
pub(super) fn colour_ticks(max: f64) -> Vec<f64> {
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
