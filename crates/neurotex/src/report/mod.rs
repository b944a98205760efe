//! The reproduction report: `report.md` with every table beside the paper's values,
//! `results.json`, and SVG figures, all rendered from [`Results`].
//!
//! The report judges nothing: whether the paper's claims hold comes from
//! [`crate::experiments::claims`]; this module only writes tables, captions and figures.

mod figures;
mod markdown;
mod paper;
mod table;

use std::path::Path;

use crate::error::{DataError, Result};
use crate::experiments::Results;
use crate::io::write_atomic;

pub use markdown::markdown;
pub use paper::{
    Paper, PaperPair, PAPER, PAPER_E1, PAPER_E4_2D, PAPER_E5, PAPER_E6, PAPER_GAIN, PAPER_TEXTURES,
};
pub use table::Table;

/// What the report says about where the data came from and how the run went.
#[derive(Debug, Clone)]
pub struct ReportContext {
    /// One paragraph on the dataset (simulated or a folder).
    pub dataset: String,
    /// The parameters, one `name: value` line each.
    pub parameters: Vec<String>,
    /// Total wall-clock seconds.
    pub total_seconds: f64,
    /// The command that produced the report.
    pub command: String,
    /// Whether the data come from the paper's design (the simulated rig), so the paper's
    /// values can stand beside ours speed by speed. For other data they are left out of the
    /// tables, since the paper's speeds are those of its own rig.
    pub paper_comparable: bool,
}

impl ReportContext {
    /// The paper's values when they can stand beside ours, else `None`.
    pub fn paper(&self) -> Option<&'static Paper> {
        self.paper_comparable.then_some(&PAPER)
    }
}

/// Writes `report.md`, `results.json` and `figures/*.svg` into `dir` (created if needed);
/// each file is written whole or not at all, `report.md` last.
///
/// # Errors
/// The folder cannot be created, a file cannot be written or a figure cannot be drawn.
pub fn write_report(dir: &Path, results: &Results, ctx: &ReportContext) -> Result<()> {
    let figures_dir = dir.join("figures");
    std::fs::create_dir_all(&figures_dir).map_err(|e| DataError::io(&figures_dir, e))?;
    for (name, svg) in figures::all(results, ctx.paper()) {
        let path = figures_dir.join(name);
        let svg = svg.map_err(|e| DataError::invalid(&path, e.to_string()))?;
        write_atomic(&path, |w| w.write_all(svg.as_bytes()))?;
    }
    let json = serde_json::to_string_pretty(results)
        .map_err(|e| DataError::invalid(dir.join("results.json"), e.to_string()))?;
    write_atomic(&dir.join("results.json"), |w| w.write_all(json.as_bytes()))?;
    let text = markdown(results, ctx);
    write_atomic(&dir.join("report.md"), |w| w.write_all(text.as_bytes()))?;
    Ok(())
}
