//! The headline accuracies over several simulated datasets: E1 per speed and E6 per
//! held-out speed, every dataset's value as a dot, the mean as a bar with its 95 % interval.

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use super::accuracy::{chance_segments, chart_width, group_labels, plot_height};
use super::plot::{
    accuracy_chart, error_bar, fit, line_height, text, Canvas, Chart, Drawn, Frame, Key, Placement,
    Swatch, Width, GLCM3D, GREY, LABEL, SINGLE, TICK, Y_AXIS_W,
};
use super::{chance_key, FigureError};
use crate::experiments::{AcrossSeeds, Results, SeedAccuracy};

/// The two methods drawn, with their colours, in the order they stand in a group.
const METHODS: [(&str, RGBColor); 2] = [("single taxel (mean)", SINGLE), ("3D-GLCM", GLCM3D)];

/// One group of the figure: an analysis at a condition, with each method's row.
struct Group<'a> {
    label: String,
    rows: [Option<&'a SeedAccuracy>; 2],
    /// Chance (%) at the condition's speed.
    chance: Option<f64>,
}

/// E1's and E6's groups, in the table's order; chance from E1 at the same speed.
fn groups<'a>(r: &Results, a: &'a AcrossSeeds) -> Vec<Group<'a>> {
    let mut out: Vec<Group> = Vec::new();
    for row in a
        .accuracies
        .iter()
        .filter(|x| x.analysis == "E1" || x.analysis == "E6")
    {
        let label = format!("{}: {}", row.analysis, row.condition);
        let Some(slot) = METHODS.iter().position(|(m, _)| *m == row.method) else {
            continue;
        };
        if out.last().is_none_or(|g| g.label != label) {
            let speed =
                r.e1.iter()
                    .find(|(s, _)| row.condition.starts_with(&format!("{s} mm/s")));
            out.push(Group {
                label,
                rows: [None, None],
                chance: speed.map(|(_, e)| 100.0 * e.chance),
            });
        }
        if let Some(g) = out.last_mut() {
            g.rows[slot] = Some(row);
        }
    }
    out
}

/// Dots for each dataset, the mean as a short bar and its interval, for one method's row at
/// the group centred on `x`.
fn draw_row(chart: &mut Chart, row: &SeedAccuracy, x: f64, colour: RGBColor) -> Drawn {
    let n = row.values.len();
    let dots = row.values.iter().enumerate().map(|(j, v)| {
        let dx = (j as f64 - (n as f64 - 1.0) / 2.0) * 0.16 / n.max(1) as f64;
        Circle::new((x + dx, 100.0 * v), 2, colour.mix(0.55).filled())
    });
    chart.draw_series(dots)?;
    let mean = 100.0 * row.mean();
    let bar = PathElement::new(
        vec![(x - 0.12, mean), (x + 0.12, mean)],
        colour.stroke_width(2),
    );
    chart.draw_series([bar])?;
    if let Some(i) = &row.interval {
        error_bar(chart, x, 100.0 * i.lower, 100.0 * i.upper, 0.05)?;
    }
    Ok(())
}

/// The speed of a group (`E6: 5 mm/s held out` -> `5`), its label under the axis; the
/// brackets under the labels name the analysis.
fn speed_label(group: &str) -> String {
    let condition = group.split_once(": ").map_or(group, |(_, c)| c);
    condition
        .split(" mm/s")
        .next()
        .unwrap_or(condition)
        .to_string()
}

/// The figure, or `None` without results over several datasets.
pub(crate) fn across_seeds(r: &Results, source: &str) -> Option<Result<String, FigureError>> {
    let a = r.across_seeds.as_ref()?;
    let groups = groups(r, a);
    if groups.is_empty() {
        return None;
    }
    let labels: Vec<String> = groups.iter().map(|g| speed_label(&g.label)).collect();
    let n = groups.len();
    let width = Width::fitting(chart_width(n, 34));
    let slot = (width.px() - chart_width(n, 0)) / n as i32;
    let placement = Placement::of(&labels, slot);
    // the groups' speeds, then which analysis they belong to, then the axis description
    let bottom = placement.height() + 2 * line_height(LABEL) + 8;
    let mut keys: Vec<Key> = METHODS
        .iter()
        .map(|(m, c)| Key::new(*m, Swatch::Points(*c)))
        .collect();
    keys.push(Key::new("mean, 95 % t interval", Swatch::BarError(GREY)));
    let chances: Vec<f64> = groups.iter().filter_map(|g| g.chance).collect();
    if !chances.is_empty() {
        keys.push(Key::new(chance_key(&chances), Swatch::Dashed(GREY)));
    }
    let title = format!("E1 and E6 over {} simulated datasets", a.seeds.len());
    let frame = Frame {
        width,
        title: &title,
        source,
        keys: &keys,
    };
    Some(frame.render(plot_height(width) + bottom, |root, area| {
        let mut chart = accuracy_chart(area, n, (Y_AXIS_W, bottom), "speed (mm/s)")?;
        draw_groups(&mut chart, &groups)?;
        group_labels(root, &chart, &labels, slot)?;
        let y = chart.backend_coord(&(0.0, 0.0)).1 + placement.height() + 2;
        sections(root, &chart, &groups, y)
    }))
}

/// Under each run of groups of one analysis, a bracket and the analysis: what the speeds
/// under the axis mean there.
fn sections(root: &Canvas, chart: &Chart, groups: &[Group], y: i32) -> Drawn {
    let mut start = 0;
    for end in 1..=groups.len() {
        let analysis = |i: usize| groups[i].label.split(':').next().unwrap_or("");
        if end < groups.len() && analysis(end) == analysis(start) {
            continue;
        }
        let x0 = chart.backend_coord(&(start as f64 + 0.1, 0.0)).0;
        let x1 = chart.backend_coord(&(end as f64 - 0.1, 0.0)).0;
        root.draw(&PathElement::new(
            vec![(x0, y), (x0, y + 3), (x1, y + 3), (x1, y)],
            GREY.stroke_width(1),
        ))?;
        let name = match analysis(start) {
            "E1" => "E1: at each speed",
            "E6" => "E6: speed held out",
            other => other,
        };
        let label = fit(name, TICK, x1 - x0);
        let style = text(TICK, HPos::Center, VPos::Top);
        root.draw(&Text::new(label, ((x0 + x1) / 2, y + 5), style))?;
        start = end;
    }
    Ok(())
}

fn draw_groups(chart: &mut Chart, groups: &[Group]) -> Drawn {
    chance_segments(chart, groups.iter().map(|g| g.chance))?;
    for (i, g) in groups.iter().enumerate() {
        for (k, (row, (_, colour))) in g.rows.iter().zip(METHODS).enumerate() {
            if let Some(row) = row {
                draw_row(chart, row, i as f64 + 0.3 + 0.4 * k as f64, colour)?;
            }
        }
    }
    Ok(())
}

/// The caption.
pub(crate) fn across_seeds_caption(a: &AcrossSeeds) -> String {
    format!(
        "E1 (cross-validation at each speed) and E6 (trained on the other speeds, tested on the held-out one) on each of {} independent simulated datasets (seeds {}). Dots: one dataset each (spread sideways to stay apart); bar: the mean over datasets with its 95 % Student-t interval; grey dashed: chance at that speed, one over the classes recorded there.",
        a.seeds.len(),
        a.seeds.iter().map(u64::to_string).collect::<Vec<_>>().join(", ")
    )
}

#[cfg(test)]
mod tests {
    #[test]
    fn groups_are_labelled_by_their_speed() {
        assert_eq!(super::speed_label("E6: -10 mm/s held out"), "-10");
        assert_eq!(super::speed_label("E1: 5 mm/s"), "5");
    }
}
