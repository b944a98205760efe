//! The reproduction report: `report.md` with every table beside the paper's values,
//! `results.json`, and the figures as SVG and PNG, all rendered from [`Results`].
//!
//! The report judges nothing: whether the paper's claims hold comes from
//! [`crate::experiments::claims`]; this module only writes tables, captions and figures.

pub mod comparison;
pub mod figures;
pub mod inspection;
mod markdown;
mod paper;
pub mod reproduce;
mod table;

use std::path::{Path, PathBuf};

use crate::error::{DataError, Result};
use crate::experiments::Results;
use crate::io::{claim_output_dir, replace_dir, OutputClaim};

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
    /// The dataset in a few words, drawn on every figure: [`simulated_source`] or
    /// [`folder_source`].
    pub source: String,
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

/// The figures' name for simulated data: `simulated rig, seed 0`, or `simulated rig, seeds
/// 0-4` over several datasets.
pub fn simulated_source(seeds: &[u64]) -> String {
    match seeds {
        [one] => format!("simulated rig, seed {one}"),
        [first, .., last] if last.checked_sub(*first) == Some(seeds.len() as u64 - 1) => {
            format!("simulated rig, seeds {first}\u{2013}{last}")
        }
        _ => {
            let list: Vec<String> = seeds.iter().map(u64::to_string).collect();
            format!("simulated rig, seeds {}", list.join(", "))
        }
    }
}

/// The figures' name for a dataset folder: the folder's own name (`FabricSlide`), the
/// path as given when it has none (`.`, `/`).
pub fn folder_source(root: &Path) -> String {
    root.file_name().map_or_else(
        || root.display().to_string(),
        |name| name.to_string_lossy().into_owned(),
    )
}

/// Writes `report.md`, `results.json` and `figures/*.svg` and `*.png` into `dir` whole or
/// not at all
/// ([`replace_dir`]): everything is rendered, then written into a temporary folder beside
/// `dir`, which takes `dir`'s place. An earlier report in `dir` is replaced as a whole (no
/// figure of an earlier run stays beside the new report); a folder holding anything else,
/// or an earlier report edited since, is refused ([`check_report_dir`]). On any failure the temporary folder is removed and `dir`
/// is left as it was.
///
/// # Errors
/// The folder cannot be created, a file cannot be written or a figure cannot be drawn.
pub fn write_report(dir: &Path, results: &Results, ctx: &ReportContext) -> Result<()> {
    let _claim = check_report_dir(dir)?;
    let mut files: Vec<(PathBuf, Vec<u8>)> = Vec::new();
    for (name, svg) in figures::all(results, ctx.paper(), &ctx.source) {
        let failed = |e: figures::FigureError| {
            DataError::invalid(dir.join("figures").join(name), e.to_string())
        };
        for (file, bytes) in figures::svg_and_png(name, svg.map_err(failed)?).map_err(failed)? {
            files.push((Path::new("figures").join(file), bytes));
        }
    }
    let json = serde_json::to_string_pretty(results)
        .map_err(|e| DataError::invalid(dir.join("results.json"), e.to_string()))?;
    files.push(("results.json".into(), json.into_bytes()));
    files.push(("report.md".into(), markdown(results, ctx).into_bytes()));
    replace_dir(dir, |tmp| write_files(tmp, &files))
}

/// Claims `dir` for this run and checks, before any work, that it is new, empty or an
/// earlier report left as it was written ([`claim_output_dir`]): a report replaces
/// nothing else, and two runs do not write one folder at once. Hold the claim until
/// [`write_report`] returns.
///
/// # Errors
/// Another running process claims `dir`, `dir` is not a folder, or it holds a file the
/// earlier report did not write, or one changed since (named).
pub fn check_report_dir(dir: &Path) -> Result<OutputClaim> {
    claim_output_dir(dir)
}

/// Writes `files` (paths relative to `dir`, and their bytes) and the `figures` folder.
fn write_files(dir: &Path, files: &[(PathBuf, Vec<u8>)]) -> Result<()> {
    let figures_dir = dir.join("figures");
    std::fs::create_dir(&figures_dir).map_err(|e| DataError::write(&figures_dir, e))?;
    for (name, text) in files {
        let path = dir.join(name);
        std::fs::write(&path, text).map_err(|e| DataError::write(&path, e))?;
    }
    Ok(())
}
