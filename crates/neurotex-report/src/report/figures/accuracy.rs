//! E1, E4 and E6: accuracy per speed as grouped bars, one group per speed, ours filled and
//! the paper's outlined beside them, a chance line across.

use plotters::prelude::*;

use super::plot::{
    accuracy_chart, category_labels, error_bar, hline, line_height, percent, Canvas, Chart, Drawn,
    Frame, Key, Placement, Swatch, Width, BEST, GLCM2D, GLCM3D, GREY, LABEL, MARGIN, SINGLE,
    Y_AXIS_W,
};
use super::{chance, chance_key, chance_per_speed, chance_values, FigureError};
use crate::experiments::Results;
use crate::report::paper::Paper;
use crate::values::Speed;

/// One series of bars: a value (%) per group, or none.
struct Bars {
    key: Key,
    colour: RGBColor,
    hollow: bool,
    values: Vec<Option<f64>>,
    /// 95 % intervals (%, lower and upper) per group, empty when the series has none.
    errors: Vec<(f64, f64)>,
}

impl Bars {
    fn ours(label: &str, colour: RGBColor, values: Vec<Option<f64>>) -> Self {
        Bars {
            key: Key::new(label, Swatch::Bar(colour)),
            colour,
            hollow: false,
            values,
            errors: Vec::new(),
        }
    }

    /// The series with error bars at `intervals`, one per group.
    fn with_intervals<'a>(
        mut self,
        intervals: impl IntoIterator<Item = &'a crate::classify::Interval>,
    ) -> Self {
        self.key.swatch = Swatch::BarError(self.colour);
        self.errors = intervals
            .into_iter()
            .map(|i| (100.0 * i.lower, 100.0 * i.upper))
            .collect();
        self
    }

    fn paper(label: &str, colour: RGBColor, values: Vec<Option<f64>>) -> Self {
        Bars {
            key: Key::new(label, Swatch::Hollow(colour)),
            colour,
            hollow: true,
            values,
            errors: Vec::new(),
        }
    }
}

/// A grouped bar chart of accuracies (%).
struct Grouped {
    title: String,
    x_desc: String,
    groups: Vec<String>,
    series: Vec<Bars>,
    chance: Option<f64>,
    /// Chance (%) at each group, drawn as a dashed segment across its slot instead of one
    /// line for all classes, when the groups hold different classes.
    chance_per_group: Option<Vec<f64>>,
}

/// The x description for speeds: signed speeds are directions, and say so.
fn speed_desc(speeds: &[Speed], what: &str) -> String {
    if speeds.iter().any(|s| s.mm_s() < 0.0) {
        format!("{what} (mm/s; the sign is the direction)")
    } else {
        format!("{what} (mm/s)")
    }
}

/// Draws each series' bars side by side within each group's unit of x, with error bars
/// where the series has intervals.
fn bars(chart: &mut Chart, series: &[&Bars]) -> Drawn {
    let width = 0.8 / series.len().max(1) as f64;
    for (k, s) in series.iter().enumerate() {
        for (i, v) in s.values.iter().enumerate() {
            let Some(v) = *v else { continue };
            let x0 = i as f64 + 0.1 + width * k as f64;
            let x1 = x0 + width * 0.88;
            if s.hollow {
                chart.draw_series([
                    Rectangle::new([(x0, 0.0), (x1, v)], WHITE.filled()),
                    Rectangle::new([(x0, 0.0), (x1, v)], s.colour.stroke_width(2)),
                ])?;
            } else {
                chart.draw_series([Rectangle::new([(x0, 0.0), (x1, v)], s.colour.filled())])?;
            }
            if let Some(&(lo, hi)) = s.errors.get(i).filter(|(lo, hi)| hi > lo) {
                let x = (x0 + x1) / 2.0;
                error_bar(chart, x, lo, hi, width * 0.25)?;
            }
        }
    }
    Ok(())
}

/// The height of a bar chart's plot, at a column's and at the page's width.
pub(crate) fn plot_height(width: Width) -> i32 {
    match width {
        Width::Column => 190,
        Width::Page => 230,
    }
}

/// The width a chart of `n` categories of `slot` pixels each needs: the categories, the y
/// axis and the margins.
pub(crate) fn chart_width(n: usize, slot: i32) -> i32 {
    Y_AXIS_W + slot * n as i32 + 2 * MARGIN + 2
}

fn draw(g: &Grouped, source: &str) -> Result<String, FigureError> {
    let series: Vec<&Bars> = g
        .series
        .iter()
        .filter(|s| s.values.iter().any(Option::is_some))
        .collect();
    let n = g.groups.len().max(1);
    // a bar at least 7 px wide, and a gap between groups
    let width = Width::fitting(chart_width(n, series.len() as i32 * 8 + 12));
    let slot = (width.px() - chart_width(n, 0)) / n as i32;
    let placement = Placement::of(&g.groups, slot);
    let bottom = placement.height() + line_height(LABEL) + 4;
    // "ours:" tells our bars from the paper's outlined ones, when there are any
    let compared = series.iter().any(|s| s.hollow);
    let mut keys: Vec<Key> = series
        .iter()
        .map(|s| {
            let mut key = s.key.clone();
            if !compared {
                key.label = key.label.trim_start_matches("ours: ").to_string();
            }
            key
        })
        .collect();
    if let Some(per) = &g.chance_per_group {
        keys.push(Key::new(chance_key(per), Swatch::Dashed(GREY)));
    } else if let Some(c) = g.chance {
        keys.push(Key::new(
            format!("chance, all classes ({} %)", percent(c)),
            Swatch::Dashed(GREY),
        ));
    }
    let frame = Frame {
        width,
        title: &g.title,
        source,
        keys: &keys,
    };
    frame.render(plot_height(width) + bottom, |root, area| {
        let mut chart = accuracy_chart(area, n, (Y_AXIS_W, bottom), &g.x_desc)?;
        bars(&mut chart, &series)?;
        match (&g.chance_per_group, g.chance) {
            (Some(per), _) => chance_segments(&mut chart, per.iter().copied().map(Some))?,
            (None, Some(c)) => hline(&mut chart, c, GREY, 6)?,
            (None, None) => {}
        }
        group_labels(root, &chart, &g.groups, slot)
    })
}

/// A dashed segment at chance across each group's slot (none where it is `None`).
pub(crate) fn chance_segments(
    chart: &mut Chart,
    per_group: impl Iterator<Item = Option<f64>>,
) -> Drawn {
    for (i, c) in per_group.enumerate() {
        let Some(c) = c else { continue };
        let (x0, x1) = (i as f64 + 0.02, i as f64 + 0.98);
        let segment = DashedLineSeries::new([(x0, c), (x1, c)], 6, 4, GREY.stroke_width(1));
        chart.draw_series(segment)?;
    }
    Ok(())
}

/// The groups' labels under the x axis of `chart`, one per unit of x.
pub(crate) fn group_labels(root: &Canvas, chart: &Chart, labels: &[String], slot: i32) -> Drawn {
    let xs: Vec<i32> = (0..labels.len())
        .map(|i| chart.backend_coord(&(i as f64 + 0.5, 0.0)).0)
        .collect();
    let axis_y = chart.backend_coord(&(0.0, 0.0)).1;
    category_labels(root, labels, &xs, axis_y, slot)?;
    Ok(())
}

fn pct(v: f64) -> Option<f64> {
    Some(100.0 * v)
}

/// E1: single taxel (mean over taxels and the best taxel) and 3D-GLCM with the table's 95 %
/// intervals, per speed.
pub(crate) fn e1(r: &Results, paper: Option<&Paper>, source: &str) -> Result<String, FigureError> {
    let speeds: Vec<Speed> = r.e1.iter().map(|(s, _)| s).collect();
    let at = |f: &dyn Fn(&crate::experiments::E1Speed) -> Option<f64>| -> Vec<Option<f64>> {
        r.e1.values().map(f).collect()
    };
    let paper_at = |f: &dyn Fn(crate::report::paper::PaperPair) -> f64| -> Vec<Option<f64>> {
        speeds
            .iter()
            .map(|&s| paper.and_then(|p| p.e1_at(s)).map(f))
            .collect()
    };
    let glcm3d = Bars::ours("ours: 3D-GLCM", GLCM3D, at(&|e| pct(e.glcm3d)))
        .with_intervals(r.e1.values().map(|e| &e.glcm3d_interval));
    let taxel = Bars::ours(
        "ours: single taxel (mean)",
        SINGLE,
        at(&|e| pct(e.taxel_mean)),
    )
    .with_intervals(r.e1.values().map(|e| &e.taxel_mean_interval));
    let series = vec![
        taxel,
        Bars::paper("paper: single taxel", SINGLE, paper_at(&|p| p.taxel)),
        Bars::ours(
            "ours: best taxel (post hoc)",
            BEST,
            at(&|e| pct(e.taxel_best)),
        ),
        glcm3d,
        Bars::paper("paper: 3D-GLCM", GLCM3D, paper_at(&|p| p.glcm3d)),
    ];
    draw(
        &Grouped {
            title: "E1: accuracy per speed".into(),
            x_desc: speed_desc(&speeds, "speed"),
            groups: speeds.iter().map(ToString::to_string).collect(),
            series,
            chance: chance(r),
            chance_per_group: Some(r.e1.values().map(|e| 100.0 * e.chance).collect()),
        },
        source,
    )
}

/// E4: single taxel, 2D-GLCM (time collapsed) and 3D-GLCM, per speed.
pub(crate) fn e4(r: &Results, paper: Option<&Paper>, source: &str) -> Result<String, FigureError> {
    let speeds: Vec<Speed> = r.e4.iter().map(|(s, _)| s).collect();
    let ours = |f: &dyn Fn(&crate::experiments::E4Speed) -> f64| -> Vec<Option<f64>> {
        r.e4.values().map(|e| pct(f(e))).collect()
    };
    let paper_e1 = |f: &dyn Fn(crate::report::paper::PaperPair) -> f64| -> Vec<Option<f64>> {
        speeds
            .iter()
            .map(|&s| paper.and_then(|p| p.e1_at(s)).map(f))
            .collect()
    };
    let paper_2d = speeds
        .iter()
        .map(|&s| paper.and_then(|p| p.e4_2d_at(s)))
        .collect();
    // E4's single taxel and 3D-GLCM are E1's, with E1's intervals.
    let e1 = |s: &Speed| r.e1.get(*s);
    let taxel = speeds.iter().filter_map(e1).map(|e| &e.taxel_mean_interval);
    let glcm3d = speeds.iter().filter_map(e1).map(|e| &e.glcm3d_interval);
    let series = vec![
        Bars::ours("ours: single taxel (mean)", SINGLE, ours(&|e| e.taxel_mean))
            .with_intervals(taxel),
        Bars::paper("paper: single taxel", SINGLE, paper_e1(&|p| p.taxel)),
        Bars::ours("ours: 2D-GLCM (no time axis)", GLCM2D, ours(&|e| e.glcm2d))
            .with_intervals(r.e4.values().map(|e| &e.glcm2d_interval)),
        Bars::paper("paper: 2D-GLCM", GLCM2D, paper_2d),
        Bars::ours("ours: 3D-GLCM", GLCM3D, ours(&|e| e.glcm3d)).with_intervals(glcm3d),
        Bars::paper("paper: 3D-GLCM", GLCM3D, paper_e1(&|p| p.glcm3d)),
    ];
    draw(
        &Grouped {
            title: "E4: temporal information removed".into(),
            x_desc: speed_desc(&speeds, "speed"),
            groups: speeds.iter().map(ToString::to_string).collect(),
            series,
            chance: chance(r),
            chance_per_group: chance_per_speed(r, &speeds),
        },
        source,
    )
}

/// E6: trained on the other speeds, tested on one: single taxel and 3D-GLCM.
pub(crate) fn e6(r: &Results, paper: Option<&Paper>, source: &str) -> Result<String, FigureError> {
    let speeds: Vec<Speed> = r.e6.iter().map(|(s, _)| s).collect();
    let paper_at = |f: &dyn Fn(crate::report::paper::PaperPair) -> f64| -> Vec<Option<f64>> {
        speeds
            .iter()
            .map(|&s| paper.and_then(|p| p.e6_at(s)).map(f))
            .collect()
    };
    let series = vec![
        Bars::ours(
            "ours: single taxel (mean)",
            SINGLE,
            r.e6.values().map(|e| pct(e.taxel_mean)).collect(),
        )
        .with_intervals(r.e6.values().map(|e| &e.taxel_mean_interval)),
        Bars::paper("paper: single taxel", SINGLE, paper_at(&|p| p.taxel)),
        Bars::ours(
            "ours: 3D-GLCM",
            GLCM3D,
            r.e6.values().map(|e| pct(e.glcm3d)).collect(),
        )
        .with_intervals(r.e6.values().map(|e| &e.glcm3d_interval)),
        Bars::paper("paper: 3D-GLCM", GLCM3D, paper_at(&|p| p.glcm3d)),
    ];
    draw(
        &Grouped {
            title: "E6: speed invariance".into(),
            x_desc: speed_desc(&speeds, "test speed, trained on the others"),
            groups: speeds.iter().map(ToString::to_string).collect(),
            series,
            chance: chance(r),
            chance_per_group: chance_per_speed(r, &speeds),
        },
        source,
    )
}

/// How chance is drawn: per speed from the classes recorded there when E1 knows every
/// speed of `speeds`, else one line for all classes of the dataset, with its caveat.
fn chance_note(r: &Results, speeds: &[Speed], speed: &str) -> String {
    if chance_per_speed(r, speeds).is_some() {
        format!(
            "The dashed grey segment over each {speed} is chance there, one over the classes recorded at that speed{}.",
            chance_values(r, speeds)
        )
    } else {
        format!(
            "The dashed grey line is chance with all {n} classes present (1/{n}); a speed recorded with fewer classes has a higher chance level.",
            n = r.labels.len()
        )
    }
}

fn paper_note(paper: Option<&Paper>) -> &'static str {
    if paper.is_some() {
        " Outlined bars are the paper's values at the speeds it reports."
    } else {
        ""
    }
}

/// E1's caption.
pub(crate) fn e1_caption(r: &Results, paper: Option<&Paper>) -> String {
    format!(
        "Accuracy per speed (cross-validated, mean over repeats{}): the single taxel as the mean over all taxels (dark blue) and the best taxel, chosen after the fact (light blue), against 3D-GLCM (vermillion); error bars are the table's 95 % intervals.{} The dashed grey segment over each speed is chance there, one over the classes recorded at that speed.",
        over_encodings(r),
        paper_note(paper),
    )
}

/// `" and over N encodings"` when E1's accuracies are means over several encodings.
fn over_encodings(r: &Results) -> String {
    match r.e1.values().next().map_or(1, |e| e.encodings) {
        1 => String::new(),
        n => format!(" and over {n} encodings"),
    }
}

/// E4's caption.
pub(crate) fn e4_caption(r: &Results, paper: Option<&Paper>) -> String {
    format!(
        "Accuracy per speed without the time axis{}: 2D-GLCM on the time-collapsed rate image (green) beside the single taxel (mean over taxels, blue) and 3D-GLCM (vermillion); error bars are the table's 95 % intervals.{} {}",
        over_encodings(r),
        paper_note(paper),
        chance_note(r, &r.e4.iter().map(|(s, _)| s).collect::<Vec<_>>(), "speed")
    )
}

/// E6's caption.
pub(crate) fn e6_caption(r: &Results, paper: Option<&Paper>) -> String {
    format!(
        "Speed invariance: trained on every other speed and tested on the one on the x axis; single taxel (mean over taxels, blue) against 3D-GLCM (vermillion); error bars are the table's 95 % intervals.{} {}",
        paper_note(paper),
        chance_note(r, &r.e6.iter().map(|(s, _)| s).collect::<Vec<_>>(), "test speed")
    )
}
