//! E2: the two confusion matrices side by side on one colour scale of row percentages.

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use super::plot::{
    axis_desc, category_labels, colour_bar, colour_bar_width, dark, fit, heat, line_height, text,
    text_width, Canvas, Drawn, Frame, Placement, Width, LABEL, MARGIN, SMALL, TICK,
};
use super::FigureError;
use crate::experiments::E2;

/// Row percentages of a count matrix (an empty row stays 0).
fn row_percent(m: &[Vec<usize>]) -> Vec<Vec<f64>> {
    m.iter()
        .map(|row| {
            let total = row.iter().sum::<usize>();
            row.iter()
                .map(|&v| {
                    if total == 0 {
                        0.0
                    } else {
                        100.0 * v as f64 / total as f64
                    }
                })
                .collect()
        })
        .collect()
}

/// Pixel geometry shared by both matrices.
struct Layout {
    width: Width,
    cell: i32,
    size: i32,
    /// Whether each cell shows its percentage.
    annotate: bool,
    /// The columns' labels: the classes' names, or their numbers when the names do not
    /// fit three cells (the rows then name each number).
    numbered: bool,
    /// Every how many rows a row is labelled: 1 unless the cells are lower than a line.
    every: usize,
    /// The rows' labels' width.
    row_w: i32,
    left: i32,
}

const GAP: i32 = 16;

impl Layout {
    /// Cells as large as the figure's width allows (up to 36 px), at a column's width
    /// when they keep 22 px there, else at the page's; below 20 px the numbers no longer
    /// fit and only the colour remains.
    fn for_classes(labels: &[String]) -> Self {
        let n = labels.len().max(1) as i32;
        let bar_w = colour_bar_width(100.0);
        let layout = |width: Width, numbered: bool| {
            let row_labels: Vec<String> = row_labels(labels, numbered);
            let row_w = row_labels
                .iter()
                .map(|l| text_width(l, TICK))
                .max()
                .unwrap_or(0)
                + 6;
            let left = MARGIN + line_height(LABEL) + 2 + row_w;
            let room = width.px() - left - GAP - 10 - bar_w - MARGIN;
            let cell = (room / (2 * n)).clamp(4, 36);
            let every = (line_height(TICK) as f64 / f64::from(cell)).ceil().max(1.0) as usize;
            Layout {
                width,
                cell,
                size: cell * n,
                annotate: cell >= 20,
                numbered,
                every,
                row_w,
                left,
            }
        };
        let fits = |l: &Layout| l.numbered || Placement::fits(labels, l.cell);
        let column = layout(Width::Column, false);
        if column.cell >= 22 && fits(&column) {
            return column;
        }
        let page = layout(Width::Page, false);
        if fits(&page) {
            page
        } else {
            layout(Width::Page, true)
        }
    }
}

/// The rows' labels: the names, or `number name` when the columns are numbered.
fn row_labels(labels: &[String], numbered: bool) -> Vec<String> {
    labels
        .iter()
        .enumerate()
        .map(|(i, l)| {
            if numbered {
                format!("{} {l}", i + 1)
            } else {
                l.clone()
            }
        })
        .collect()
}

fn matrix(canvas: &Canvas, (x, y): (i32, i32), l: &Layout, title: &str, m: &[Vec<f64>]) -> Drawn {
    canvas.draw(&Text::new(
        fit(title, LABEL, l.size + GAP),
        (x + l.size / 2, y - 4),
        text(LABEL, HPos::Center, VPos::Bottom),
    ))?;
    for (i, row) in m.iter().enumerate() {
        for (j, &v) in row.iter().enumerate() {
            let (x0, y0) = (x + l.cell * j as i32, y + l.cell * i as i32);
            let f = v / 100.0;
            canvas.draw(&Rectangle::new(
                [(x0, y0), (x0 + l.cell, y0 + l.cell)],
                heat(f).filled(),
            ))?;
            if l.annotate && v > 0.0 {
                let colour = if dark(f) { WHITE } else { BLACK };
                let style = text(SMALL, HPos::Center, VPos::Center).color(&colour);
                let label = format!("{:.0}", v);
                canvas.draw(&Text::new(label, (x0 + l.cell / 2, y0 + l.cell / 2), style))?;
            }
        }
    }
    let frame = [(x, y), (x + l.size, y + l.size)];
    canvas.draw(&Rectangle::new(frame, BLACK.stroke_width(1)))?;
    Ok(())
}

/// E2: row-normalised confusion matrices of the single taxel (summed over taxels) and of
/// 3D-GLCM, rows true and columns predicted, with one colour bar.
pub(crate) fn e2(e: &E2, source: &str) -> Result<String, FigureError> {
    let n = e.labels.len().max(1) as i32;
    let layout = Layout::for_classes(&e.labels);
    let cell = layout.cell;
    let columns: Vec<String> = if layout.numbered {
        (1..=e.labels.len()).map(|k| k.to_string()).collect()
    } else {
        e.labels.clone()
    };
    let placement = Placement::of(&columns, cell);
    let top = line_height(LABEL) + 8;
    let body_h = top + layout.size + placement.height() + line_height(LABEL) + 6;
    let panels = [
        ("single taxel (all taxels)", row_percent(&e.taxel)),
        ("3D-GLCM", row_percent(&e.glcm3d)),
    ];
    let title = format!("E2: confusion at {} mm/s (row %)", e.speed);
    let frame = Frame {
        width: layout.width,
        title: &title,
        source,
        keys: &[],
    };
    frame.render(body_h, |_, body| {
        let left = layout.left;
        for (k, (name, m)) in panels.iter().enumerate() {
            let x = left + k as i32 * (layout.size + GAP);
            matrix(body, (x, top), &layout, name, m)?;
            let desc_y = top + layout.size + placement.height() + 2;
            axis_desc(body, "predicted", (0, desc_y), (x, x + layout.size), false)?;
        }
        // both matrices' columns in one run, so that staggered labels take their lines in
        // turn across the gap too
        let xs: Vec<i32> = (0..2)
            .flat_map(|k| {
                let x = left + k * (layout.size + GAP);
                (0..n).map(move |j| x + cell * j + cell / 2)
            })
            .collect();
        let both: Vec<String> = columns.iter().chain(&columns).cloned().collect();
        category_labels(body, &both, &xs, top + layout.size - 4, cell)?;
        let rows = row_labels(&e.labels, layout.numbered);
        for (i, label) in rows.iter().enumerate().step_by(layout.every) {
            let y = top + cell * i as i32 + cell / 2;
            let style = text(TICK, HPos::Right, VPos::Center);
            let label = fit(label, TICK, layout.row_w - 6);
            body.draw(&Text::new(label, (left - 5, y), style))?;
        }
        axis_desc(body, "true", (MARGIN, 0), (top, top + layout.size), true)?;
        let bar_x = left + 2 * layout.size + GAP + 10;
        colour_bar(
            body,
            (bar_x, top),
            layout.size,
            100.0,
            "share of the true class (%)",
        )
    })
}

/// E2's caption.
pub(crate) fn e2_caption(e: &E2) -> String {
    let layout = Layout::for_classes(&e.labels);
    let numbers = if layout.annotate {
        " (empty cells are 0; a 0 is a share under 0.5 %)"
    } else {
        ""
    };
    let numbered = if layout.numbered {
        " The columns are numbered in the rows' order."
    } else {
        ""
    };
    format!(
        "Confusion matrices at {} mm/s for the {} classes recorded at that speed: rows are the true class, columns the prediction, each cell the share (%) of the row's predictions{numbers}, pooled over CV repeats and, for the single taxel, over all taxels. One colour scale for both.{numbered}",
        e.speed,
        e.labels.len()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_become_percentages_and_empty_rows_stay_zero() {
        let m = row_percent(&[vec![1, 3], vec![0, 0]]);
        assert_eq!(m, vec![vec![25.0, 75.0], vec![0.0, 0.0]]);
    }
}
