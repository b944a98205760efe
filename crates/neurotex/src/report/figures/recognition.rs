//! E5: time to recognition, one panel per speed on one accuracy scale.

use plotters::prelude::*;

use super::plot::{
    hline, line_with_markers, mesh, multiples, number, panel_chart, vline, Key, Multiples, Swatch,
    GLCM3D, GREY, SINGLE,
};
use super::{panel_chance_note, panel_chances, FigureError};
use crate::experiments::Results;
use crate::report::paper::Paper;

/// E5: 3D-GLCM on the first part of the slide against the single taxel on all of it, one
/// panel per speed.
pub(crate) fn e5(r: &Results, paper: Option<&Paper>) -> Result<String, FigureError> {
    let too_short = r.e5.values().any(|e| e.glcm3d.iter().any(Option::is_none));
    let paper_marks =
        r.e5.iter()
            .any(|(s, _)| paper.and_then(|p| p.e5_first_match_at(s)).is_some());
    let mut keys = vec![
        Key::new(
            "3D-GLCM on the first part of the slide",
            Swatch::Points(GLCM3D),
        ),
        Key::new("single taxel on the whole slide", Swatch::Dashed(SINGLE)),
    ];
    let speeds: Vec<_> = r.e5.iter().collect();
    let chances = panel_chances(
        r,
        &speeds.iter().map(|(s, _)| *s).collect::<Vec<_>>(),
        &mut keys,
    );
    if paper_marks {
        keys.push(Key::new(
            "paper: 3D-GLCM matches here",
            Swatch::Dashed(BLACK),
        ));
    }
    if too_short {
        keys.push(Key::new(
            "shorter than one bin: no accuracy",
            Swatch::Cross(GREY),
        ));
    }
    let layout = Multiples {
        n: speeds.len(),
        panel: (250, 200),
        title: "E5: time to recognition",
        x_desc: "share of the slide used (%)",
        y_desc: "accuracy (%)",
        keys: &keys,
    };
    multiples(&layout, |i, area| {
        let (speed, e) = speeds[i];
        let mut chart = panel_chart(area, &format!("{speed} mm/s"), 0.0..100.0, 0.0..100.0)?;
        mesh(&mut chart)
            .x_labels(6)
            .y_labels(6)
            .x_label_formatter(&|v| number(*v))
            .y_label_formatter(&|v| number(*v))
            .draw()?;
        if let Some(c) = chances[i] {
            hline(&mut chart, c, GREY, 6)?;
        }
        hline(&mut chart, 100.0 * e.taxel_full, SINGLE, 6)?;
        if let Some(p) = paper.and_then(|p| p.e5_first_match_at(speed)) {
            vline(&mut chart, 100.0 * p, BLACK, 6)?;
        }
        let points: Vec<(f64, f64)> = e
            .fractions
            .iter()
            .zip(&e.glcm3d)
            .filter_map(|(&p, a)| a.map(|a| (100.0 * p, 100.0 * a)))
            .collect();
        line_with_markers(&mut chart, &points, GLCM3D, false)?;
        let short = e
            .fractions
            .iter()
            .zip(&e.glcm3d)
            .filter(|(_, a)| a.is_none());
        chart.draw_series(
            short.map(|(&p, _)| Cross::new((100.0 * p, 3.0), 4, GREY.stroke_width(2))),
        )?;
        Ok(())
    })
}

/// E5's caption.
pub(crate) fn e5_caption(r: &Results, paper: Option<&Paper>) -> String {
    let first: Vec<String> =
        r.e5.iter()
            .map(|(s, e)| {
                format!(
                    "{s} mm/s: {}",
                    e.first_match
                        .map_or("never".into(), |p| format!("{:.0} %", 100.0 * p))
                )
            })
            .collect();
    format!(
        "Time to recognition, one panel per speed on one scale: 3D-GLCM accuracy using only the first part of each slide (vermillion) against the single taxel's accuracy on the whole slide (mean over taxels, dashed blue); {}.{} 3D-GLCM first reaches the single taxel at {}.",
        panel_chance_note(r, &r.e5.iter().map(|(s, _)| s).collect::<Vec<_>>()),
        if paper.is_some() {
            " Black dashed: the share at which the paper's 3D-GLCM matched its single taxel, where the paper states it."
        } else {
            ""
        },
        first.join(", ")
    )
}
