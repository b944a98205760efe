//! E8: accuracy against the number of neighbours k, one panel per speed on one scale.

use super::plot::{
    band, hline, line_with_markers, mesh, multiples, number, panel_chart, x_ticks_at, Key,
    Multiples, Swatch, GLCM3D, GREY, SINGLE,
};
use super::{panel_chance_note, panel_chances, FigureError};
use crate::experiments::Results;
use crate::values::Speed;

/// E8: single taxel and 3D-GLCM against k, one panel per speed.
pub(crate) fn e8(r: &Results, source: &str) -> Result<String, FigureError> {
    let mut keys = vec![
        Key::new("single taxel (mean)", Swatch::Points(SINGLE)),
        Key::new("3D-GLCM", Swatch::Points(GLCM3D)),
    ];
    let speeds: Vec<_> = r.e8.iter().collect();
    let chances = panel_chances(
        r,
        &speeds.iter().map(|(s, _)| *s).collect::<Vec<_>>(),
        &mut keys,
    );
    let ks = || {
        speeds
            .iter()
            .flat_map(|(_, e)| e.k.iter().map(|&k| k as f64))
    };
    let lo = ks().fold(f64::INFINITY, f64::min);
    let hi = ks().fold(f64::NEG_INFINITY, f64::max);
    let (lo, hi) = if lo.is_finite() { (lo, hi) } else { (1.0, 1.0) };
    let layout = Multiples {
        n: speeds.len(),
        aspect: 0.75,
        source,
        title: "E8: robustness to the number of neighbours k",
        x_desc: "neighbours k",
        y_desc: "accuracy (%)",
        keys: &keys,
    };
    multiples(&layout, |i, area| {
        let (speed, e) = speeds[i];
        let x = lo - 1.0..hi + 1.0;
        let mut chart = panel_chart(area, &format!("{speed} mm/s"), x, 0.0..100.0)?;
        mesh(&mut chart)
            .disable_x_mesh()
            .x_labels(0)
            .y_labels(6)
            .y_label_formatter(&|v| number(*v))
            .draw()?;
        let ks: Vec<f64> = e.k.iter().map(|&k| k as f64).collect();
        x_ticks_at(area, &chart, &ks)?;
        if let Some(c) = chances[i] {
            hline(&mut chart, c, GREY, 6)?;
        }
        let at = |values: &[f64]| -> Vec<(f64, f64)> {
            e.k.iter()
                .zip(values)
                .map(|(&k, &a)| (k as f64, 100.0 * a))
                .collect()
        };
        let span = |intervals: &[crate::classify::Interval]| -> Vec<(f64, f64, f64)> {
            e.k.iter()
                .zip(intervals)
                .map(|(&k, i)| (k as f64, 100.0 * i.lower, 100.0 * i.upper))
                .collect()
        };
        band(&mut chart, &span(&e.taxel_mean_interval), SINGLE)?;
        band(&mut chart, &span(&e.glcm3d_interval), GLCM3D)?;
        line_with_markers(&mut chart, &at(&e.taxel_mean), SINGLE, false)?;
        line_with_markers(&mut chart, &at(&e.glcm3d), GLCM3D, false)
    })
}

/// E8's caption.
pub(crate) fn e8_caption(r: &Results) -> String {
    let speeds: Vec<Speed> = r.e8.iter().map(|(s, _)| s).collect();
    format!(
        "Accuracy against the number of neighbours k of the KNN classifier, one panel per speed on one scale: single taxel (mean over taxels, blue) and 3D-GLCM (vermillion), shaded: the table's 95 % intervals; {}.",
        panel_chance_note(r, &speeds)
    )
}
