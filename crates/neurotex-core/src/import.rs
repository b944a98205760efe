//! Importing recordings from other layouts into the dataset format: per-trial CSV logs from
//! a DAQ (metadata from file names) and the stacked arrays machine-learning datasets ship.
//!
//! The options a user types ([`NamePattern`], [`ChannelSelect`], [`Axes`]) parse from text
//! with `FromStr`.

use std::path::{Path, PathBuf};

pub use crate::csvlog::ChannelSelect;
use crate::csvlog::CsvLog;
use crate::error::{DataError, Result};
use crate::recording::Meta;

mod csv_logs;
mod dropped;
mod event_logs;
mod name_pattern;
mod stacked;
mod warnings;

pub use csv_logs::{
    csv_files, find_csv, import_csv, CsvImportParams, ImportSummary, Logs, MergedRows,
};
pub use event_logs::{event_files, import_events, EventImportParams, ImportedFile};
pub use name_pattern::NamePattern;
pub use stacked::{import_stacked, Axes, StackedParams};
pub use warnings::{clock_like, grid_advice, ImportWarning, OFFSET_RATIO};

/// A CSV log read, with the metadata its file name gives.
struct ParsedCsv {
    meta: Meta,
    log: CsvLog,
}

fn invalid(path: &Path, message: impl Into<String>) -> crate::Error {
    DataError::invalid(path, message).into()
}

/// The files a scan of a command's inputs found.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Found {
    /// The files to read, sorted.
    pub files: Vec<PathBuf>,
    /// Entries of the folders searched, named like the files wanted, that are not regular
    /// files (a pipe, a device, a link to one or to nothing), with the reason: reading a
    /// pipe blocks until something writes it, and a device may never end.
    pub left_out: Vec<(PathBuf, String)>,
}

/// The files among `inputs` with one of `extensions` (any case; folders are searched one
/// level deep, files given by name are taken whatever their extension), sorted.
///
/// # Errors
/// An input that does not exist or is not a regular file or folder, or a folder that
/// cannot be read.
fn files_with(inputs: &[PathBuf], extensions: &[&str]) -> Result<Found> {
    let wanted = |p: &Path| {
        p.extension()
            .is_some_and(|x| extensions.iter().any(|e| x.eq_ignore_ascii_case(e)))
    };
    let mut found = Found::default();
    for input in inputs {
        if input.is_dir() {
            let entries = std::fs::read_dir(input).map_err(|e| DataError::io(input, e))?;
            for e in entries {
                let path = e.map_err(|e| DataError::io(input, e))?.path();
                if !wanted(&path) {
                    continue;
                }
                match crate::io::check_input(&path) {
                    Ok(()) => found.files.push(path),
                    Err(why) => found.left_out.push((path, why.to_string())),
                }
            }
        } else if std::fs::symlink_metadata(input).is_ok() {
            crate::io::check_input(input)?;
            found.files.push(input.clone());
        } else {
            return Err(invalid(input, "does not exist"));
        }
    }
    found.files.sort();
    found.left_out.sort();
    Ok(found)
}
