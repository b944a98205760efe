//! E2: the two confusion matrices side by side on one colour scale of row percentages.

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use super::plot::{
    axis_desc, category_labels, colour_bar, dark, heat, labels_fit, labels_height, render, text,
    text_width, Canvas, Drawn, COLOUR_BAR_W, LABEL, TICK, TITLE,
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
    cell: i32,
    size: i32,
    annotate: bool,
}

impl Layout {
    /// Cells shrink with the class count down to 20 px; below 26 px the numbers no longer
    /// fit and only the colour remains.
    fn for_classes(n: usize) -> Self {
        let n = n.max(1) as i32;
        let cell = (340 / n).clamp(20, 64);
        Layout {
            cell,
            size: cell * n,
            annotate: cell >= 26,
        }
    }
}

fn matrix(canvas: &Canvas, (x, y): (i32, i32), l: &Layout, title: &str, m: &[Vec<f64>]) -> Drawn {
    canvas.draw(&Text::new(
        title,
        (x + l.size / 2, y - 10),
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
                let style = text(TICK - 1.0, HPos::Center, VPos::Center).color(&colour);
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
pub(crate) fn e2(e: &E2) -> Result<String, FigureError> {
    let n = e.labels.len().max(1) as i32;
    let layout = Layout::for_classes(e.labels.len());
    let cell = layout.cell;
    let level = labels_fit(&e.labels, cell);
    let row_w = e
        .labels
        .iter()
        .map(|l| text_width(l, TICK))
        .max()
        .unwrap_or(0)
        + 10;
    let (left, top, gap) = (28 + row_w, 64, 36);
    let below = labels_height(&e.labels, level) + 30;
    let width = left + 2 * layout.size + gap + 20 + COLOUR_BAR_W + 8;
    let height = top + layout.size + below + 8;
    let panels = [
        ("single taxel (all taxels)", row_percent(&e.taxel)),
        ("3D-GLCM", row_percent(&e.glcm3d)),
    ];
    render((width as u32, height as u32), |root| {
        let title = format!("E2: confusion at {} mm/s (row %)", e.speed);
        root.draw(&Text::new(
            title,
            (width / 2, 8),
            text(TITLE, HPos::Center, VPos::Top),
        ))?;
        for (k, (name, m)) in panels.iter().enumerate() {
            let x = left + k as i32 * (layout.size + gap);
            matrix(root, (x, top), &layout, name, m)?;
            let xs: Vec<i32> = (0..n).map(|j| x + cell * j + cell / 2).collect();
            category_labels(root, &e.labels, &xs, top + layout.size, level)?;
            axis_desc(
                root,
                "predicted",
                (0, height - 26),
                (x, x + layout.size),
                false,
            )?;
        }
        for (i, label) in e.labels.iter().enumerate() {
            let y = top + cell * i as i32 + cell / 2;
            let style = text(TICK, HPos::Right, VPos::Center);
            root.draw(&Text::new(label.as_str(), (left - 6, y), style))?;
        }
        axis_desc(root, "true", (4, 0), (top, top + layout.size), true)?;
        let bar_x = left + 2 * layout.size + gap + 8;
        colour_bar(
            root,
            (bar_x, top),
            layout.size,
            100.0,
            "share of the true class (%)",
        )
    })
}

/// E2's caption.
pub(crate) fn e2_caption(e: &E2) -> String {
    let numbers = if Layout::for_classes(e.labels.len()).annotate {
        " (empty cells are 0; a 0 is a share under 0.5 %)"
    } else {
        ""
    };
    format!(
        "Confusion matrices at {} mm/s for the {} classes recorded at that speed: rows are the true class, columns the prediction, each cell the share (%) of the row's predictions{numbers}, pooled over CV repeats and, for the single taxel, over all taxels. One colour scale for both.",
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
