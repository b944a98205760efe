//! The headline accuracies over several simulated datasets: E1 per speed and E6 per
//! held-out speed, every dataset's value as a dot, the mean as a bar with its 95 % interval.

use plotters::prelude::*;

use super::plot::{
    accuracy_chart, category_labels, error_bar, labels_fit, labels_height, legend, legend_size,
    render, Chart, Drawn, Key, Swatch, GLCM3D, GREY, SINGLE,
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
        Circle::new((x + dx, 100.0 * v), 3, colour.mix(0.55).filled())
    });
    chart.draw_series(dots)?;
    let mean = 100.0 * row.mean();
    let bar = PathElement::new(
        vec![(x - 0.12, mean), (x + 0.12, mean)],
        colour.stroke_width(3),
    );
    chart.draw_series([bar])?;
    if let Some(i) = &row.interval {
        error_bar(chart, x, 100.0 * i.lower, 100.0 * i.upper, 0.05)?;
    }
    Ok(())
}

const PLOT_H: i32 = 300;
const LEFT: i32 = 64;
const TOP: i32 = 40;

/// The figure, or `None` without results over several datasets.
pub(crate) fn across_seeds(r: &Results) -> Option<Result<String, FigureError>> {
    let a = r.across_seeds.as_ref()?;
    let groups = groups(r, a);
    if groups.is_empty() {
        return None;
    }
    let labels: Vec<String> = groups.iter().map(|g| g.label.clone()).collect();
    let n = groups.len();
    let plot_w = (n as i32 * 70).max(360);
    let level = labels_fit(&labels, plot_w / n as i32);
    let bottom = labels_height(&labels, level) + 26;
    let mut keys: Vec<Key> = METHODS
        .iter()
        .map(|(m, c)| Key::new(format!("{m}: one dot per dataset"), Swatch::Points(*c)))
        .collect();
    keys.push(Key::new(
        "bar: mean over datasets, 95 % t interval",
        Swatch::BarError(GREY),
    ));
    let chances: Vec<f64> = groups.iter().filter_map(|g| g.chance).collect();
    if !chances.is_empty() {
        keys.push(Key::new(chance_key(&chances), Swatch::Dashed(GREY)));
    }
    let (legend_w, legend_h) = legend_size(&keys);
    let size = (
        (LEFT + plot_w + 28 + legend_w + 12) as u32,
        (TOP + PLOT_H.max(legend_h) + bottom + 8) as u32,
    );
    let title = format!("E1 and E6 over {} simulated datasets", a.seeds.len());
    Some(render(size, |root| {
        let (area, _) = root.split_horizontally(LEFT + plot_w + 12);
        let mut chart = accuracy_chart(&area, &title, n, (LEFT, bottom), "")?;
        draw_groups(&mut chart, &groups)?;
        let xs: Vec<i32> = (0..n)
            .map(|i| chart.backend_coord(&(i as f64 + 0.5, 0.0)).0)
            .collect();
        let axis_y = chart.backend_coord(&(0.0, 0.0)).1;
        category_labels(root, &labels, &xs, axis_y, level)?;
        legend(root, (LEFT + plot_w + 28, TOP + 4), &keys)
    }))
}

fn draw_groups(chart: &mut Chart, groups: &[Group]) -> Drawn {
    for (i, g) in groups.iter().enumerate() {
        if let Some(c) = g.chance {
            let (x0, x1) = (i as f64 + 0.02, i as f64 + 0.98);
            chart.draw_series(DashedLineSeries::new(
                [(x0, c), (x1, c)],
                9,
                6,
                GREY.stroke_width(2),
            ))?;
        }
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
