//! E3: 3D-GLCM accuracy as more taxels are moved, against the single taxel and chance.

use plotters::prelude::*;

use super::plot::{
    error_bar, hline, legend, legend_size, line_with_markers, mesh, number, percent, render, Key,
    Swatch, FONT, GLCM3D, GREY, SINGLE, TITLE,
};
use super::FigureError;
use crate::experiments::{E2, E3};

/// Chance (%) at E3's speed: from the classes E2 found there when E2 ran at the same
/// speed, else with every class of the dataset.
fn chance_at(e: &E3, e2: Option<&E2>, all: Option<f64>) -> Option<f64> {
    match e2 {
        Some(e2) if e2.speed == e.speed && !e2.labels.is_empty() => {
            Some(100.0 / e2.labels.len() as f64)
        }
        _ => all,
    }
}

/// E3: mean ± std of 3D-GLCM over random draws for each number of taxels moved, with the
/// unperturbed 3D-GLCM at 0 and the single taxel and chance as lines.
pub(crate) fn e3(e: &E3, e2: Option<&E2>, all_chance: Option<f64>) -> Result<String, FigureError> {
    let chance = chance_at(e, e2, all_chance);
    let mut keys = vec![
        Key::new(
            format!("3D-GLCM, mean ± std over {} draws", e.repeats),
            Swatch::Points(GLCM3D),
        ),
        Key::new(
            "single taxel, mean over taxels (unperturbed)",
            Swatch::Dashed(SINGLE),
        ),
    ];
    if let Some(c) = chance {
        keys.push(Key::new(
            format!("chance ({} %)", percent(c)),
            Swatch::Dashed(GREY),
        ));
    }
    let (legend_w, legend_h) = legend_size(&keys);
    let (plot_w, left) = (520, 64);
    let width = left + plot_w + 24 + legend_w + 12;
    let height = 40 + 300.max(legend_h) + 60;
    let max_n = e.n.iter().copied().max().unwrap_or(1) as f64;
    render((width as u32, height as u32), |root| {
        let (area, _) = root.split_horizontally(left + plot_w + 12);
        let mut chart = ChartBuilder::on(&area)
            .caption(
                format!("E3: spatial perturbation at {} mm/s", e.speed),
                (FONT, TITLE),
            )
            .margin_top(6)
            .margin_right(12)
            .x_label_area_size(56)
            .y_label_area_size(left)
            .build_cartesian_2d(-0.5..max_n + 0.5, 0.0..100.0)?;
        mesh(&mut chart)
            .x_labels((plot_w / 30) as usize)
            .y_labels(11)
            .x_label_formatter(&|v| number(*v))
            .y_label_formatter(&|v| number(*v))
            .x_desc("taxels moved (0 = unperturbed)")
            .y_desc("accuracy (%)")
            .draw()?;
        hline(&mut chart, 100.0 * e.taxel_mean, SINGLE, 9)?;
        if let Some(c) = chance {
            hline(&mut chart, c, GREY, 9)?;
        }
        for ((&n, &m), &s) in e.n.iter().zip(&e.mean).zip(&e.std) {
            let (m, s) = (100.0 * m, 100.0 * s);
            if s > 0.0 {
                error_bar(
                    &mut chart,
                    n as f64,
                    (m - s).max(0.0),
                    (m + s).min(100.0),
                    0.2,
                )?;
            }
        }
        let points: Vec<(f64, f64)> = std::iter::once((0.0, 100.0 * e.glcm3d))
            .chain(
                e.n.iter()
                    .zip(&e.mean)
                    .map(|(&n, &m)| (n as f64, 100.0 * m)),
            )
            .collect();
        line_with_markers(&mut chart, &points, GLCM3D, false)?;
        legend(root, (left + plot_w + 24, 44), &keys)
    })
}

/// E3's caption.
pub(crate) fn e3_caption(e: &E3) -> String {
    format!(
        "3D-GLCM accuracy at {} mm/s when n taxels swap places at random (each recording its own draw), mean ± 1 std over {} draws; n = 0 is the unperturbed 3D-GLCM ({:.1} %). Dashed lines: the single taxel's mean over taxels ({:.1} %) and chance.",
        e.speed,
        e.repeats,
        100.0 * e.glcm3d,
        100.0 * e.taxel_mean
    )
}
