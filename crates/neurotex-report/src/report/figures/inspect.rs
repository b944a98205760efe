//! `inspect`'s figures: a few recordings per class, raw and as the encoder sees them; the
//! taxel map of resting offsets and firing rates; the recordings per class and speed.

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use super::plot::{
    colour_bar, colour_bar_width, dark, fit, heat, line_height, mesh, multiples_in, number,
    panel_chart, text, text_width, Canvas, Drawn, Frame, Multiples, Width, LABEL, LIGHT, MARGIN,
    SERIES, SMALL, TICK,
};
use super::FigureError;
use crate::inspect::{Inspection, Series, Trace};

/// The range of every value of `series`, padded a little; `(0, 1)` when empty or flat.
fn range(series: &[Vec<f64>]) -> (f64, f64) {
    let values = series.iter().flatten().copied();
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    match hi > lo {
        true => (lo - 0.05 * (hi - lo), hi + 0.05 * (hi - lo)),
        false if lo.is_finite() => (lo - 1.0, lo + 1.0),
        false => (0.0, 1.0),
    }
}

fn trace_panel(area: &Canvas, title: &str, (t, series): &Series) -> Drawn {
    let t_end = t.last().copied().filter(|&e| e > 0.0).unwrap_or(1.0);
    let (lo, hi) = range(series);
    let mut chart = panel_chart(area, title, 0.0..t_end, lo..hi)?;
    mesh(&mut chart)
        .x_labels(5)
        .y_labels(4)
        .x_label_formatter(&|v| number(*v))
        .y_label_formatter(&|v| number(*v))
        .draw()?;
    for (k, s) in series.iter().enumerate() {
        let colour = SERIES[k % SERIES.len()];
        let points = t.iter().copied().zip(s.iter().copied());
        chart.draw_series(LineSeries::new(points, colour.stroke_width(1)))?;
    }
    Ok(())
}

/// The first recording of each class: its raw channels (left) and the conditioned input of
/// the encoder (right), one line per channel; `None` without traces.
pub fn traces(i: &Inspection, source: &str) -> Option<Result<String, FigureError>> {
    if i.traces.is_empty() {
        return None;
    }
    let panels: Vec<(String, &Series)> = i
        .traces
        .iter()
        .flat_map(|tr: &Trace| {
            let raw = (format!("{}: raw", tr.label), &tr.raw);
            let cond = tr
                .conditioned
                .as_ref()
                .map(|c| (format!("{}: as encoded", tr.label), c));
            std::iter::once(raw).chain(cond)
        })
        .collect();
    let m = Multiples {
        n: panels.len(),
        aspect: 0.55,
        title: "Recordings, raw and as the encoder sees them",
        source,
        x_desc: "time (s; as encoded: in the selected phase)",
        y_desc: "raw, or encoder input (0-1)",
        keys: &[],
    };
    // raw beside as-encoded: two classes a row, or one when a class could not be conditioned
    let paired = panels.len() == 2 * i.traces.len();
    let cols = if paired && panels.len() > 2 { 4 } else { 2 };
    Some(multiples_in(&m, cols, |k, area| {
        trace_panel(area, &panels[k].0, panels[k].1)
    }))
}

/// The least height of a map's colour bar, pixels.
const BAR_MIN: i32 = 90;

/// A map of values on a grid, one colour scale from 0 to its largest value.
struct Map<'a> {
    title: &'a str,
    /// The colour bar's description.
    unit: &'a str,
    rows: Vec<String>,
    cols: Vec<String>,
    /// `None`: no value (an empty cell).
    values: Vec<Vec<Option<f64>>>,
}

impl Map<'_> {
    fn max(&self) -> f64 {
        let values = self.values.iter().flatten().flatten().copied();
        values.fold(0.0, f64::max)
    }

    fn row_w(&self) -> i32 {
        self.rows
            .iter()
            .map(|r| text_width(r, TICK))
            .max()
            .unwrap_or(0)
            + 6
    }

    /// The pixels the map takes, with its labels and colour bar, at cells of `cell`.
    fn width(&self, cell: i32) -> i32 {
        self.row_w() + cell * self.cols.len() as i32 + 10 + colour_bar_width(self.max()) + 8
    }

    /// The grid's height, at least [`BAR_MIN`] so that a one-row grid's colour bar can
    /// hold its ticks.
    fn grid_h(&self, cell: i32) -> i32 {
        (cell * self.rows.len() as i32).max(BAR_MIN)
    }

    fn height(&self, cell: i32) -> i32 {
        line_height(LABEL) + line_height(TICK) + 6 + self.grid_h(cell) + 4
    }

    fn draw(&self, canvas: &Canvas, (x, y): (i32, i32), cell: i32) -> Drawn {
        let max = self.max();
        let scale = if max > 0.0 { max } else { 1.0 };
        let left = x + self.row_w();
        let top = y + line_height(LABEL) + line_height(TICK) + 6;
        let w = cell * self.cols.len() as i32;
        // left-aligned over the map, so a title wider than a narrow grid stays on the page
        let style = text(LABEL, HPos::Left, VPos::Top);
        canvas.draw(&Text::new(
            fit(self.title, LABEL, self.width(cell)),
            (x, y),
            style,
        ))?;
        for (j, c) in self.cols.iter().enumerate() {
            let at = (left + cell * j as i32 + cell / 2, top - 3);
            canvas.draw(&Text::new(
                fit(c, TICK, cell * 2),
                at,
                text(TICK, HPos::Center, VPos::Bottom),
            ))?;
        }
        for (i, (r, row)) in self.rows.iter().zip(&self.values).enumerate() {
            let y0 = top + cell * i as i32;
            canvas.draw(&Text::new(
                r.clone(),
                (left - 4, y0 + cell / 2),
                text(TICK, HPos::Right, VPos::Center),
            ))?;
            for (j, v) in row.iter().enumerate() {
                let x0 = left + cell * j as i32;
                let corners = [(x0, y0), (x0 + cell, y0 + cell)];
                let Some(v) = v else {
                    canvas.draw(&Rectangle::new(corners, LIGHT.filled()))?;
                    continue;
                };
                let f = v / scale;
                canvas.draw(&Rectangle::new(corners, heat(f).filled()))?;
                let colour = if dark(f) { WHITE } else { BLACK };
                let label = fit(&number(round3(*v)), SMALL, cell - 2);
                let style = text(SMALL, HPos::Center, VPos::Center).color(&colour);
                canvas.draw(&Text::new(label, (x0 + cell / 2, y0 + cell / 2), style))?;
            }
        }
        let h = cell * self.rows.len() as i32;
        canvas.draw(&Rectangle::new(
            [(left, top), (left + w, top + h)],
            BLACK.stroke_width(1),
        ))?;
        colour_bar(
            canvas,
            (left + w + 10, top),
            self.grid_h(cell),
            max,
            self.unit,
        )
    }
}

/// Three significant digits.
fn round3(v: f64) -> f64 {
    if v == 0.0 || !v.is_finite() {
        return v;
    }
    let scale = 10f64.powi(2 - v.abs().log10().floor() as i32);
    (v * scale).round() / scale
}

/// Draws `maps` side by side (wrapping onto further rows) under one frame.
fn maps(title: &str, source: &str, maps: &[Map], cell: i32) -> Result<String, FigureError> {
    // a column's width when the maps and their titles fit one, else the page's
    let widest = (maps.iter())
        .map(|m| m.width(cell).max(super::plot::text_width(m.title, LABEL)))
        .max()
        .unwrap_or(0);
    let frame = Frame {
        width: Width::fitting(widest + 2 * MARGIN + super::plot::text_width(source, TICK)),
        title,
        source,
        keys: &[],
    };
    let room = frame.px() - 2 * MARGIN;
    let mut rows: Vec<Vec<&Map>> = vec![Vec::new()];
    let mut used = 0;
    for m in maps {
        let w = m.width(cell) + 16;
        if used + w > room && !rows.last().expect("a row").is_empty() {
            rows.push(Vec::new());
            used = 0;
        }
        used += w;
        rows.last_mut().expect("a row").push(m);
    }
    let heights: Vec<i32> = (rows.iter())
        .map(|r| r.iter().map(|m| m.height(cell)).max().unwrap_or(0) + 8)
        .collect();
    frame.render(heights.iter().sum(), |_, body| {
        let mut y = 0;
        for (row, h) in rows.iter().zip(&heights) {
            let mut x = MARGIN;
            for m in row {
                m.draw(body, (x, y), cell)?;
                x += m.width(cell) + 16;
            }
            y += h;
        }
        Ok(())
    })
}

/// The taxel map: each taxel's resting offset (in ranges above zero) and, when the encoder
/// was checked, its median firing rate; empty cells grey.
pub fn taxel_map(i: &Inspection, source: &str) -> Result<String, FigureError> {
    let l = &i.layout;
    let on_grid = |value: &dyn Fn(usize) -> Option<f64>| -> Vec<Vec<Option<f64>>> {
        (0..l.rows)
            .map(|r| {
                (0..l.cols)
                    .map(|c| l.cells.iter().position(|&x| x == [r, c]).and_then(value))
                    .collect()
            })
            .collect()
    };
    let rows: Vec<String> = (0..l.rows).map(|r| format!("row {r}")).collect();
    let cols: Vec<String> = (0..l.cols).map(|c| c.to_string()).collect();
    let chans = &i.signals.channels;
    let mut out = vec![Map {
        title: "resting offset, in ranges above zero",
        unit: "ranges",
        rows: rows.clone(),
        cols: cols.clone(),
        values: on_grid(&|k| Some(chans.get(k)?.resting_ratio.unwrap_or(0.0))),
    }];
    if let Some(e) = &i.encoder {
        out.push(Map {
            title: "median firing rate at the gain",
            unit: "Hz",
            rows,
            cols,
            values: on_grid(&|k| Some(e.taxels.get(k)?.median_hz)),
        });
    }
    let cell = (220 / l.cols.max(1) as i32).clamp(14, 40);
    let title = format!("Taxels on the {}x{} grid", l.rows, l.cols);
    maps(&title, source, &out, cell)
}

/// Recordings per class (rows) at each speed (columns), or over all recordings when the
/// manifest has no speeds.
pub fn design(i: &Inspection, source: &str) -> Result<String, FigureError> {
    let d = &i.design;
    let conditions = match d.speeds().is_empty() {
        true => &d.conditions[..1],
        false => d.speeds(),
    };
    let cols: Vec<String> = (conditions.iter())
        .map(|c| c.speed_mm_s.map_or("all".to_string(), number))
        .collect();
    let values = (0..d.classes.len())
        .map(|k| {
            conditions
                .iter()
                .map(|c| Some(c.counts[k] as f64))
                .collect()
        })
        .collect();
    let map = Map {
        title: match d.speeds().is_empty() {
            true => "recordings per class",
            false => "recordings per speed (mm/s)",
        },
        unit: "recordings",
        rows: d.classes.clone(),
        cols,
        values,
    };
    let cell = (560 / conditions.len().max(1) as i32).clamp(18, 36);
    maps("The design", source, &[map], cell)
}
