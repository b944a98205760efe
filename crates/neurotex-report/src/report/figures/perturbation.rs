//! E3: 3D-GLCM accuracy as more taxels are moved, against the single taxel and chance.

use super::accuracy::plot_height;
use super::plot::{
    error_bar, hline, line_chart, line_with_markers, mesh, number, percent, Frame, Key, Swatch,
    Width, GLCM3D, GREY, SINGLE, X_AXIS_H,
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
pub(crate) fn e3(
    e: &E3,
    e2: Option<&E2>,
    all_chance: Option<f64>,
    source: &str,
) -> Result<String, FigureError> {
    let chance = chance_at(e, e2, all_chance);
    let mut keys = vec![
        Key::new(
            format!("3D-GLCM, mean of {} draws, {}", e.repeats, spread_name(e)),
            Swatch::Points(GLCM3D),
        ),
        Key::new("single taxel (mean, unperturbed)", Swatch::Dashed(SINGLE)),
    ];
    if let Some(c) = chance {
        keys.push(Key::new(
            format!("chance ({} %)", percent(c)),
            Swatch::Dashed(GREY),
        ));
    }
    let max_n = e.n.iter().copied().max().unwrap_or(1) as f64;
    let title = format!("E3: spatial perturbation at {} mm/s", e.speed);
    let frame = Frame {
        width: Width::Column,
        title: &title,
        source,
        keys: &keys,
    };
    frame.render(plot_height(Width::Column) + X_AXIS_H, |_, area| {
        let mut chart = line_chart(area, -0.5..max_n + 0.5, 0.0..100.0)?;
        mesh(&mut chart)
            .x_labels(9)
            .y_labels(11)
            .x_label_formatter(&|v| number(*v))
            .y_label_formatter(&|v| number(*v))
            .x_desc("taxels moved (0 = unperturbed)")
            .y_desc("accuracy (%)")
            .draw()?;
        hline(&mut chart, 100.0 * e.taxel_mean, SINGLE, 6)?;
        if let Some(c) = chance {
            hline(&mut chart, c, GREY, 6)?;
        }
        for (i, ((&n, &m), &s)) in e.n.iter().zip(&e.mean).zip(&e.std).enumerate() {
            let (lo, hi) = match e.interval.get(i) {
                Some(ci) => (100.0 * ci.lower, 100.0 * ci.upper),
                None => (100.0 * (m - s), 100.0 * (m + s)),
            };
            if hi > lo {
                error_bar(&mut chart, n as f64, lo.max(0.0), hi.min(100.0), 0.2)?;
            }
        }
        let points: Vec<(f64, f64)> = std::iter::once((0.0, 100.0 * e.glcm3d))
            .chain(
                e.n.iter()
                    .zip(&e.mean)
                    .map(|(&n, &m)| (n as f64, 100.0 * m)),
            )
            .collect();
        line_with_markers(&mut chart, &points, GLCM3D, false)
    })
}

/// What E3's error bars show: the 95 % interval, or ± 1 std for results without one.
fn spread_name(e: &E3) -> &'static str {
    if e.interval.len() == e.n.len() {
        "95 % interval"
    } else {
        "± 1 std"
    }
}

/// E3's caption.
pub(crate) fn e3_caption(e: &E3) -> String {
    let bars = if e.interval.len() == e.n.len() {
        "error bars: the table's 95 % intervals over recordings and draws"
    } else {
        "error bars: ± 1 std over draws"
    };
    format!(
        "3D-GLCM accuracy at {} mm/s when n taxels swap places at random (each recording its own draw), mean over {} draws ({bars}); n = 0 is the unperturbed 3D-GLCM ({:.1} %). Dashed lines: the single taxel's mean over taxels ({:.1} %) and chance.",
        e.speed,
        e.repeats,
        100.0 * e.glcm3d,
        100.0 * e.taxel_mean
    )
}
