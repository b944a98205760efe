//! E5: time to recognition, one panel per speed on one accuracy scale.

use plotters::prelude::*;

use super::plot::{
    band, hline, line_with_markers, mesh, multiples, number, panel_chart, vline, Canvas, Chart,
    Key, Multiples, Swatch, GLCM3D, GREY, SINGLE,
};
use super::{panel_chance_note, panel_chances, FigureError};
use crate::experiments::{E5CausalSpeed, Results};
use crate::report::paper::Paper;

/// E5: 3D-GLCM on the first part of the slide against the single taxel on all of it, one
/// panel per speed.
pub(crate) fn e5(r: &Results, paper: Option<&Paper>, source: &str) -> Result<String, FigureError> {
    let too_short = r.e5.values().any(|e| e.glcm3d.iter().any(Option::is_none));
    let paper_marks =
        r.e5.iter()
            .any(|(s, _)| paper.and_then(|p| p.e5_first_match_at(s)).is_some());
    let mut keys = vec![
        Key::new("3D-GLCM, first part of the slide", Swatch::Points(GLCM3D)),
        Key::new("single taxel (mean), whole slide", Swatch::Dashed(SINGLE)),
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
        keys.push(Key::new("shorter than a bin", Swatch::Cross(GREY)));
    }
    let layout = Multiples {
        n: speeds.len(),
        aspect: 0.75,
        source,
        title: "E5: time to recognition",
        x_desc: "share of the slide used (%)",
        y_desc: "accuracy (%)",
        keys: &keys,
    };
    multiples(&layout, |i, area| {
        let (speed, e) = speeds[i];
        let mut chart = panel_chart(area, &format!("{speed} mm/s"), 0.0..100.0, 0.0..100.0)?;
        mesh(&mut chart)
            .x_labels(5)
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
        let spans: Vec<(f64, f64, f64)> = e
            .fractions
            .iter()
            .zip(&e.glcm3d_interval)
            .filter_map(|(&p, i)| {
                i.as_ref()
                    .map(|i| (100.0 * p, 100.0 * i.lower, 100.0 * i.upper))
            })
            .collect();
        band(&mut chart, &spans, GLCM3D)?;
        line_with_markers(&mut chart, &points, GLCM3D, false)?;
        let short = e
            .fractions
            .iter()
            .zip(&e.glcm3d)
            .filter(|(_, a)| a.is_none());
        chart.draw_series(
            short.map(|(&p, _)| Cross::new((100.0 * p, 3.0), 3, GREY.stroke_width(1))),
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
        "Time to recognition, one panel per speed on one scale: 3D-GLCM accuracy using only the first part of each slide (vermillion, shaded: the table's 95 % intervals) against the single taxel's accuracy on the whole slide (mean over taxels, dashed blue); {}.{} 3D-GLCM first reaches the single taxel at {}.",
        panel_chance_note(r, &r.e5.iter().map(|(s, _)| s).collect::<Vec<_>>()),
        if paper.is_some() {
            " Black dashed: the share at which the paper's 3D-GLCM matched its single taxel, where the paper states it."
        } else {
            ""
        },
        first.join(", ")
    )
}

/// The time axis of an E5c panel: up to the longest slide, at least one bin.
fn time_range(e: &E5CausalSpeed) -> std::ops::Range<f64> {
    let end = e.times_s.last().copied().unwrap_or(0.2);
    0.0..end.max(0.2)
}

/// E5c: causal 3D-GLCM accuracy against time into the slide beside the offline E5, one
/// panel per speed.
pub(crate) fn e5c_accuracy(r: &Results, source: &str) -> Result<String, FigureError> {
    let speeds: Vec<_> = r.e5c.iter().collect();
    let mut keys = vec![
        Key::new("causal 3D-GLCM, the slide so far", Swatch::Line(GLCM3D)),
        Key::new("offline, first part (E5)", Swatch::Points(SINGLE)),
        Key::new("offline, whole slide (E1)", Swatch::Dashed(BLACK)),
    ];
    let chances = panel_chances(
        r,
        &speeds.iter().map(|(s, _)| *s).collect::<Vec<_>>(),
        &mut keys,
    );
    let layout = Multiples {
        n: speeds.len(),
        aspect: 0.75,
        source,
        title: "E5c: accuracy against time into the slide",
        x_desc: "time into the slide (s)",
        y_desc: "accuracy (%)",
        keys: &keys,
    };
    multiples(&layout, |i, area| {
        let (speed, e) = speeds[i];
        let mut chart = e5c_panel(area, speed, e)?;
        if let Some(c) = chances[i] {
            hline(&mut chart, c, GREY, 6)?;
        }
        hline(&mut chart, 100.0 * e.offline, BLACK, 6)?;
        let causal: Vec<(f64, f64)> = e
            .times_s
            .iter()
            .zip(&e.accuracy)
            .map(|(&t, &a)| (t, 100.0 * a))
            .collect();
        chart.draw_series(LineSeries::new(causal, GLCM3D.stroke_width(2)))?;
        let offline: Vec<(f64, f64)> = e
            .fractions
            .iter()
            .filter_map(|f| f.offline.map(|a| (f.time_s, 100.0 * a)))
            .collect();
        line_with_markers(&mut chart, &offline, SINGLE, false)?;
        Ok(())
    })
}

/// One E5c panel: the speed's time axis (s) against 0-100 %, its mesh drawn.
fn e5c_panel<'a, 'b>(
    area: &'a Canvas<'b>,
    speed: crate::values::Speed,
    e: &E5CausalSpeed,
) -> Result<Chart<'a, 'b>, DrawingAreaErrorKind<std::io::Error>> {
    let mut chart = panel_chart(area, &format!("{speed} mm/s"), time_range(e), 0.0..100.0)?;
    mesh(&mut chart)
        .x_labels(5)
        .y_labels(6)
        .x_label_formatter(&|v| number(*v))
        .y_label_formatter(&|v| number(*v))
        .draw()?;
    Ok(chart)
}

/// E5c accuracy figure's caption.
pub(crate) fn e5c_accuracy_caption(r: &Results) -> String {
    format!(
        "Online time to recognition, one panel per speed (each on its own time axis, up to the longest slide): the causal 3D-GLCM's accuracy at every 200 ms bin boundary from the slide so far, classified by a KNN trained on whole causal slides in the folds of E1 and pooled over its repeats (vermillion; a slide that has ended keeps its last classification); the offline E5 (blue points: trained and tested on the first part of every slide, zero-phase, plotted at that share of the median slide); the zero-phase 3D-GLCM on whole slides in E1's folds, the encoding as run (black dashed); {}.",
        panel_chance_note(r, &r.e5c.iter().map(|(s, _)| s).collect::<Vec<_>>())
    )
}

/// E5c: the share of slides decided by each time, one panel per speed.
pub(crate) fn e5c_decision(r: &Results, source: &str) -> Result<String, FigureError> {
    let speeds: Vec<_> = r.e5c.iter().collect();
    let keys = vec![
        Key::new("decided by then", Swatch::Line(GLCM3D)),
        Key::new("still sliding", Swatch::Dashed(GREY)),
        Key::new("median time to decision", Swatch::Dashed(BLACK)),
    ];
    let layout = Multiples {
        n: speeds.len(),
        aspect: 0.75,
        source,
        title: "E5c: time to decision",
        x_desc: "time into the slide (s)",
        y_desc: "share of slides (%)",
        keys: &keys,
    };
    multiples(&layout, |i, area| {
        let (speed, e) = speeds[i];
        let mut chart = e5c_panel(area, speed, e)?;
        // Steps: the share decided holds from one bin boundary to the next.
        let mut decided = vec![(0.0, 0.0)];
        for (&t, &d) in e.times_s.iter().zip(&e.decision.decided_by) {
            let last = decided.last().map_or(0.0, |p: &(f64, f64)| p.1);
            decided.push((t, last));
            decided.push((t, 100.0 * d));
        }
        chart.draw_series(LineSeries::new(decided, GLCM3D.stroke_width(2)))?;
        let sliding: Vec<(f64, f64)> = std::iter::once((0.0, 100.0))
            .chain(
                e.times_s
                    .iter()
                    .zip(&e.sliding)
                    .map(|(&t, &s)| (t, 100.0 * s)),
            )
            .collect();
        chart.draw_series(DashedLineSeries::new(sliding, 6, 4, GREY.stroke_width(2)))?;
        if let Some(q) = e.decision.quartiles_s {
            vline(&mut chart, q[1], BLACK, 6)?;
        }
        Ok(())
    })
}

/// E5c decision figure's caption.
pub(crate) fn e5c_decision_caption(r: &Results) -> String {
    let rule = r
        .e5c
        .values()
        .next()
        .map(|e| e.decision.rule)
        .unwrap_or_default();
    let never: Vec<String> = r
        .e5c
        .iter()
        .map(|(s, e)| format!("{s} mm/s {:.1} %", 100.0 * e.decision.never_share))
        .collect();
    format!(
        "Time to decision, one panel per speed: the share of test slides (over E1's repeats) decided by each time into the slide (vermillion steps), a decision being the first time one class holds at least {} of the vote in {} consecutive bins; grey dashed: the share of slides still sliding; black dashed: the median time to decision of the slides decided. Never decided before the slide ended: {}.",
        rule.share,
        rule.bins,
        never.join(", ")
    )
}
