//! The leaderboard's figure: per dataset and protocol, the nested estimate, the best spike
//! method, the spike counts with logistic regression, the best baseline without spikes and
//! the paper's method, each with its 95 % interval, chance, and the published results
//! beside them (hollow: not the same protocol).

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use super::plot::{
    accuracy_axis, fit, interval, text, text_width, Frame, Key, Swatch, Width, GLCM3D, GREY,
    MARGIN, SERIES, SINGLE, TICK, X_AXIS_H,
};
use super::FigureError;

/// What a row of the figure shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Nested selection: the number to quote.
    Nested,
    /// The best spike method of the ranking.
    Spikes,
    /// Spike counts with logistic regression.
    Rates,
    /// The best baseline without spikes.
    NoSpikes,
    /// The paper's method.
    Paper,
    /// A published result on the same protocol.
    Published,
    /// A published result on another protocol.
    PublishedOther,
}

impl Kind {
    fn colour(self) -> RGBColor {
        match self {
            Kind::Nested => BLACK,
            Kind::Spikes => SINGLE,
            Kind::Rates => SERIES[5],
            Kind::NoSpikes => SERIES[2],
            Kind::Paper => GLCM3D,
            Kind::Published | Kind::PublishedOther => SERIES[4],
        }
    }
}

/// One row: a label, an accuracy in 0..1 and its interval (none for a published number).
#[derive(Debug, Clone, PartialEq)]
pub struct Entry {
    /// The row's name.
    pub label: String,
    /// Accuracy, 0..1.
    pub accuracy: f64,
    /// 95 % interval, 0..1.
    pub ci: Option<[f64; 2]>,
    /// What it is.
    pub kind: Kind,
}

/// One dataset under one protocol.
#[derive(Debug, Clone, PartialEq)]
pub struct Group {
    /// `dataset: protocol`.
    pub title: String,
    /// Chance accuracy, 0..1.
    pub chance: f64,
    /// Its rows, top first.
    pub rows: Vec<Entry>,
}

const ROW_H: i32 = 15;
const TOP: i32 = 4;
const PLOT_W: i32 = 300;

/// The figure's rows: each group's title and its entries.
fn lines(groups: &[Group]) -> usize {
    groups.iter().map(|g| 1 + g.rows.len()).sum()
}

/// The legend: a key for each kind of row the figure draws (published numbers of either
/// protocol share one), so that no key names what is not there, and chance.
fn keys(groups: &[Group]) -> Vec<Key> {
    let drawn =
        |kinds: &[Kind]| (groups.iter().flat_map(|g| &g.rows)).any(|r| kinds.contains(&r.kind));
    [
        (
            &[Kind::Nested][..],
            "nested selection (the number to quote)",
        ),
        (&[Kind::Spikes], "best spike method"),
        (&[Kind::Rates], "spike counts, logistic regression"),
        (&[Kind::NoSpikes], "best without spikes"),
        (&[Kind::Paper], "paper's method (sa / glcm3d / knn)"),
        (
            &[Kind::Published, Kind::PublishedOther],
            "published (hollow: another protocol)",
        ),
    ]
    .into_iter()
    .filter(|(kinds, _)| drawn(kinds))
    .map(|(kinds, l)| Key::new(l, Swatch::Points(kinds[0].colour())))
    .chain([Key::new("chance", Swatch::Dashed(GREY))])
    .collect()
}

/// The figure: every group's rows under its title, on one accuracy axis; `source` names
/// the run.
///
/// # Errors
/// The drawing fails.
pub fn leaderboard(groups: &[Group], source: &str) -> Result<String, FigureError> {
    let keys = keys(groups);
    let frame = Frame {
        width: Width::Page,
        title: "the leaderboard: accuracy with 95 % intervals, per dataset and protocol",
        source,
        keys: &keys,
    };
    let width = Width::Page.px();
    let n = lines(groups);
    let labels = groups
        .iter()
        .flat_map(|g| g.rows.iter().map(|r| r.label.as_str()));
    let name_w = labels.map(|l| text_width(l, TICK)).max().unwrap_or(0);
    let name_w = name_w.min(width - 2 * MARGIN - PLOT_W - 60);
    let left = MARGIN + 12 + name_w + 8;
    let plot_h = ROW_H * n as i32;
    frame.render(TOP + plot_h + X_AXIS_H + 4, |_, body| {
        let area = body
            .clone()
            .shrink((left, TOP), (PLOT_W + 16, plot_h + X_AXIS_H));
        let mut chart = ChartBuilder::on(&area)
            .margin_right(16)
            .x_label_area_size(X_AXIS_H)
            .build_cartesian_2d(0.0..100.0, 0.0..n as f64)?;
        accuracy_axis(&mut chart)?;
        let mut k = 0usize;
        for g in groups {
            let y_of = |k: usize| n as f64 - k as f64 - 0.5;
            let row_px = |k: usize| TOP + ROW_H * k as i32 + ROW_H / 2;
            let title = text(TICK, HPos::Left, VPos::Center);
            let title_text = fit(&g.title, TICK, width - 2 * MARGIN);
            body.draw(&Text::new(title_text, (MARGIN, row_px(k)), title))?;
            let (top, bottom) = (y_of(k) - 0.5, y_of(k + g.rows.len()) + 0.5);
            let chance = 100.0 * g.chance;
            chart.draw_series(DashedLineSeries::new(
                [(chance, top), (chance, bottom)],
                4,
                3,
                GREY.stroke_width(1),
            ))?;
            for row in &g.rows {
                k += 1;
                let (y, colour) = (y_of(k), row.kind.colour());
                if let Some([lo, hi]) = row.ci {
                    interval(&mut chart, [100.0 * lo, 100.0 * hi], y, colour)?;
                }
                let at = (100.0 * row.accuracy, y);
                match row.kind {
                    Kind::PublishedOther => {
                        chart.draw_series([Circle::new(at, 3, colour.stroke_width(1))])?
                    }
                    _ => chart.draw_series([Circle::new(at, 3, colour.filled())])?,
                };
                let name = text(TICK, HPos::Right, VPos::Center).color(&colour);
                let label = fit(&row.label, TICK, name_w);
                body.draw(&Text::new(label, (left - 8, row_px(k)), name))?;
                let value = text(TICK, HPos::Left, VPos::Center);
                let shown = format!("{:.1}", 100.0 * row.accuracy);
                body.draw(&Text::new(shown, (left + PLOT_W + 24, row_px(k)), value))?;
            }
            k += 1;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn group(kinds: &[Kind]) -> Group {
        let rows = kinds.iter().enumerate().map(|(i, &kind)| Entry {
            label: format!("row {i}"),
            accuracy: 0.5 + 0.1 * i as f64,
            ci: (kind != Kind::Published).then_some([0.4, 0.6]),
            kind,
        });
        Group {
            title: "a dataset, one protocol".into(),
            chance: 0.25,
            rows: rows.collect(),
        }
    }

    #[test]
    fn the_keys_name_only_the_kinds_of_rows_drawn() {
        let without = leaderboard(&[group(&[Kind::Nested, Kind::Paper])], "test").unwrap();
        assert!(without.contains("nested selection") && without.contains("chance"));
        assert!(!without.contains("published"), "{without}");
        assert!(!without.contains("best spike method"));
        let with = leaderboard(&[group(&[Kind::Nested, Kind::PublishedOther])], "test").unwrap();
        assert!(with.contains("published (hollow: another protocol)"));
    }
}
