//! The report's figures, one function per figure, each drawn with plotters' SVG backend and
//! laid out for any number of speeds, classes, taxels and gains, at a paper's column or
//! page width, with the data's name under its title; each is written as PNG too
//! ([`png`]). Each figure's caption is written beside its drawing so that the two change
//! together.

mod accuracy;
pub mod compare;
mod confusion;
mod gain;
pub mod inspect;
pub mod leaderboard;
mod neighbours;
mod perturbation;
mod plot;
mod psth;
mod raster;
mod recognition;
mod seeds;

use crate::experiments::Results;
use crate::values::Speed;
use plot::{percent, Key, Swatch, GREY};

use super::paper::Paper;

pub(crate) use accuracy::{e1_caption, e4_caption, e6_caption};
pub(crate) use confusion::e2_caption;
pub(crate) use gain::{e7_isi_caption, e7_rate_caption};
pub(crate) use neighbours::e8_caption;
pub(crate) use perturbation::e3_caption;
pub(crate) use psth::e0_caption;
pub(crate) use recognition::{e5_caption, e5c_accuracy_caption, e5c_decision_caption};
pub(crate) use seeds::across_seeds_caption;

pub use raster::png;

/// A figure could not be drawn.
#[derive(Debug, thiserror::Error)]
#[error("drawing a figure failed: {0}")]
pub struct FigureError(String);

impl<E: std::error::Error + Send + Sync> From<plotters::drawing::DrawingAreaErrorKind<E>>
    for FigureError
{
    fn from(e: plotters::drawing::DrawingAreaErrorKind<E>) -> Self {
        FigureError(e.to_string())
    }
}

/// File names of the figures, as `report.md` links them.
pub(crate) mod file {
    /// E0.
    pub(crate) const E0: &str = "e0_psth_volume.svg";
    /// E1.
    pub(crate) const E1: &str = "e1_accuracy.svg";
    /// E2.
    pub(crate) const E2: &str = "e2_confusion.svg";
    /// E3.
    pub(crate) const E3: &str = "e3_perturbation.svg";
    /// E4.
    pub(crate) const E4: &str = "e4_temporal.svg";
    /// E5.
    pub(crate) const E5: &str = "e5_time_to_recognition.svg";
    /// E5c, accuracy against time into the slide.
    pub(crate) const E5C_ACCURACY: &str = "e5c_accuracy_over_time.svg";
    /// E5c, time to decision.
    pub(crate) const E5C_DECISION: &str = "e5c_time_to_decision.svg";
    /// E6.
    pub(crate) const E6: &str = "e6_speed_invariance.svg";
    /// E7, firing rates.
    pub(crate) const E7_RATE: &str = "e7_rate.svg";
    /// E7, ISI distributions.
    pub(crate) const E7_ISI: &str = "e7_isi.svg";
    /// E8.
    pub(crate) const E8: &str = "e8_k.svg";
    /// E1 and E6 over several simulated datasets.
    pub(crate) const SEEDS: &str = "across_seeds.svg";
    /// E9: candidates ranked within each speed.
    pub(crate) const E9_PER_SPEED: &str = "e9_per_speed.svg";
    /// E9: candidates ranked with each speed held out.
    pub(crate) const E9_HELD_OUT: &str = "e9_held_out.svg";
    /// E9: the best candidate and the paper's method at each held-out speed.
    pub(crate) const E9_SPEEDS: &str = "e9_speeds.svg";
}

/// Chance level (%) with every class of the dataset present.
fn chance(r: &Results) -> Option<f64> {
    (!r.labels.is_empty()).then(|| 100.0 / r.labels.len() as f64)
}

/// Chance (%) at each of `speeds`, one over the classes E1 (or else E6, with each speed
/// held out) found recorded there; `None` unless one of them ran at every speed.
pub(crate) fn chance_per_speed(r: &Results, speeds: &[Speed]) -> Option<Vec<f64>> {
    speeds
        .iter()
        .map(|&s| {
            let e6 = || r.e6.get(s).map(|e| e.chance).filter(|&c| c > 0.0);
            r.e1.get(s).map(|e| e.chance).or_else(e6).map(|c| 100.0 * c)
        })
        .collect()
}

/// The legend key of chance lines drawn per speed: with its value when it is the same at
/// every speed (the caption says it is one over the classes recorded at the speed).
pub(crate) fn chance_key(per_speed: &[f64]) -> String {
    match per_speed {
        [first, rest @ ..] if rest.iter().all(|c| (c - first).abs() < 1e-9) => {
            format!("chance ({} %)", percent(*first))
        }
        _ => "chance at each speed".to_string(),
    }
}

/// Chance (%) in each panel of `speeds`: per speed when E1 knows every one (its key added
/// to `keys`), else the all-class level in each (with that key).
pub(crate) fn panel_chances(
    r: &Results,
    speeds: &[Speed],
    keys: &mut Vec<Key>,
) -> Vec<Option<f64>> {
    if let Some(per) = chance_per_speed(r, speeds) {
        keys.push(Key::new(chance_key(&per), Swatch::Dashed(GREY)));
        return per.into_iter().map(Some).collect();
    }
    let all = chance(r);
    if let Some(c) = all {
        keys.push(Key::new(
            format!("chance, all classes ({} %)", percent(c)),
            Swatch::Dashed(GREY),
        ));
    }
    vec![all; speeds.len()]
}

/// The chance levels per speed grouped by value, for a caption (` (14.3 % at -150, -10
/// mm/s; 20 % at 10 mm/s)`); empty when E1 does not know every speed or the level is the
/// same at all of them (the key gives it then).
pub(crate) fn chance_values(r: &Results, speeds: &[Speed]) -> String {
    let Some(per) = chance_per_speed(r, speeds) else {
        return String::new();
    };
    let mut groups: Vec<(String, Vec<String>)> = Vec::new();
    for (speed, c) in speeds.iter().zip(&per) {
        let value = percent(*c);
        match groups.iter_mut().find(|(v, _)| *v == value) {
            Some((_, at)) => at.push(speed.to_string()),
            None => groups.push((value, vec![speed.to_string()])),
        }
    }
    if groups.len() < 2 {
        return String::new();
    }
    let parts: Vec<String> = groups
        .iter()
        .map(|(v, at)| format!("{v} % at {} mm/s", at.join(", ")))
        .collect();
    format!(" ({})", parts.join("; "))
}

/// What the grey dashed line of a panel-per-speed figure is.
pub(crate) fn panel_chance_note(r: &Results, speeds: &[Speed]) -> String {
    if chance_per_speed(r, speeds).is_some() {
        format!(
            "grey dashed: chance at that speed, one over the classes recorded there{}",
            chance_values(r, speeds)
        )
    } else {
        format!("grey dashed: chance with all {} classes", r.labels.len())
    }
}

/// Every figure these results have, as `(file name, SVG)`, in the report's order;
/// `source` names the data on each.
pub(crate) fn all(
    r: &Results,
    paper: Option<&Paper>,
    source: &str,
) -> Vec<(&'static str, Result<String, FigureError>)> {
    let mut out = Vec::new();
    if let Some(svg) = seeds::across_seeds(r, source) {
        out.push((file::SEEDS, svg));
    }
    // Over several simulated datasets, every other figure shows the first.
    let first = r
        .across_seeds
        .as_ref()
        .and_then(|a| a.seeds.first())
        .map(|&seed| super::simulated_source(&[seed]));
    let source = first.as_deref().unwrap_or(source);
    if !r.e1.is_empty() {
        out.push((file::E1, accuracy::e1(r, paper, source)));
    }
    if let Some(e2) = &r.e2 {
        out.push((file::E2, confusion::e2(e2, source)));
    }
    if let Some(e3) = &r.e3 {
        let svg = perturbation::e3(e3, r.e2.as_ref(), chance(r), source);
        out.push((file::E3, svg));
    }
    if !r.e4.is_empty() {
        out.push((file::E4, accuracy::e4(r, paper, source)));
    }
    if !r.e5.is_empty() {
        out.push((file::E5, recognition::e5(r, paper, source)));
    }
    if !r.e5c.is_empty() {
        out.push((file::E5C_ACCURACY, recognition::e5c_accuracy(r, source)));
        out.push((file::E5C_DECISION, recognition::e5c_decision(r, source)));
    }
    if !r.e6.is_empty() {
        out.push((file::E6, accuracy::e6(r, paper, source)));
    }
    if let Some(e7) = &r.e7 {
        out.push((file::E7_RATE, gain::e7_rate(e7, source)));
        out.push((file::E7_ISI, gain::e7_isi(e7, source)));
    }
    if !r.e8.is_empty() {
        out.push((file::E8, neighbours::e8(r, source)));
    }
    if let Some(e9) = &r.e9 {
        out.push((file::E9_PER_SPEED, compare::ranking(&e9.per_speed, source)));
        out.push((file::E9_HELD_OUT, compare::ranking(&e9.held_out, source)));
        if let Some(figure) = compare::per_condition(&e9.held_out) {
            let figure = figure.with_baseline(e9.held_out_baseline());
            out.push((file::E9_SPEEDS, figure.draw(source)));
        }
    }
    if let Some(e0) = &r.e0 {
        out.push((file::E0, psth::e0(e0, source)));
    }
    out
}

/// A figure's files: its SVG under `svg_name` and the PNG rendered from it beside it
/// (`e1_accuracy.svg`, `e1_accuracy.png`).
///
/// # Errors
/// The PNG cannot be rendered ([`png`]).
pub fn svg_and_png(svg_name: &str, svg: String) -> Result<[(String, Vec<u8>); 2], FigureError> {
    let png = png(&svg)?;
    let stem = svg_name.strip_suffix(".svg").unwrap_or(svg_name);
    Ok([
        (svg_name.to_string(), svg.into_bytes()),
        (format!("{stem}.png"), png),
    ])
}

#[cfg(test)]
pub(crate) mod tests;
