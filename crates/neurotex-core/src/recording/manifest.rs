//! The manifest (`manifest.csv`): reading its columns into recordings' metadata, and writing
//! a dataset folder's manifest and layout.

use std::path::{Path, PathBuf};

use crate::csvlog::csv_error;
use crate::error::{DataError, Result};

use super::layout_file::LayoutFile;
use super::{Meta, CONDITION_COLUMNS, MANIFEST_COLUMNS};

/// Reads and checks a manifest.
///
/// # Errors
/// Missing file, missing column, unparsable or non-finite field; each names the line.
pub fn read_manifest(path: &Path) -> Result<Vec<Meta>> {
    read_manifest_columns(path).map(|(_, metas)| metas)
}

/// Reads and checks a manifest: its column names in order, and its recordings.
/// The error for a folder without `manifest.csv`: when it holds recordings (raw logs,
/// say), it says how to make a dataset folder of them.
pub(super) fn no_manifest(root: &Path) -> DataError {
    let recordings = std::fs::read_dir(root)
        .map(|entries| {
            entries
                .filter_map(|e| e.ok())
                .filter(|e| {
                    let name = e.file_name().to_string_lossy().to_lowercase();
                    name.ends_with(".csv") || name.ends_with(".npy")
                })
                .count()
        })
        .unwrap_or(0);
    let why = match recordings {
        0 => "is not a dataset folder (expected a folder with manifest.csv)".to_string(),
        n => format!(
            "is not a dataset folder (no manifest.csv) but holds {n} .csv/.npy file(s): \
             import them into a dataset folder first (`neurotex import csv` for per-trial \
             logs, `neurotex import stacked` for arrays; in Python, `neurotex.save_dataset`)"
        ),
    };
    DataError::invalid(root, why)
}

pub(super) fn read_manifest_columns(path: &Path) -> Result<(Vec<String>, Vec<Meta>)> {
    // Fields are trimmed (`a.npy, smooth` is common); the labels as written are kept to
    // refuse two that differ only by surrounding spaces, which trimming would make one class.
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::Headers)
        .from_reader(crate::io::open_text(path)?);
    let headers = reader.headers().map_err(|e| csv_error(path, e))?.clone();
    let columns = ManifestColumns::find(path, &headers)?;
    let mut out = Vec::new();
    let mut raw_labels = Vec::new();
    for (i, record) in reader.records().enumerate() {
        let mut record = record.map_err(|e| csv_error(path, e))?;
        let raw_label = record.get(columns.required[1]).unwrap_or("").to_string();
        record.trim();
        out.push(columns.row(path, i + 2, &headers, &record)?);
        raw_labels.push((raw_label, format!("line {}", i + 2)));
    }
    if let Some(message) = labels_merged_by_trimming(&raw_labels) {
        return Err(DataError::invalid(path, message).into());
    }
    if out.is_empty() {
        return Err(DataError::invalid(path, "the manifest lists no recordings").into());
    }
    // A recording listed twice would count twice, and could sit in a training and a test
    // fold at once. Names are compared by their path components (`./a.npy` is `a.npy`).
    let mut seen: std::collections::HashMap<PathBuf, usize> = std::collections::HashMap::new();
    for (i, meta) in out.iter().enumerate() {
        let key: PathBuf = Path::new(&meta.file)
            .components()
            .filter(|c| c != &std::path::Component::CurDir)
            .collect();
        if let Some(first) = seen.insert(key, i) {
            let message = format!(
                "line {}: file `{}` is listed again (first on line {}); each recording may be \
                 listed once",
                i + 2,
                meta.file,
                first + 2
            );
            return Err(DataError::invalid(path, message).into());
        }
    }
    Ok((headers.iter().map(String::from).collect(), out))
}

/// The first labels among `labels` that differ only in case (`Rough`, `rough`), sorted;
/// `None` when no two do. neurotex keeps them apart, as classes of their own, where they
/// most likely name one texture written two ways.
pub fn labels_differing_in_case<S: AsRef<str>>(labels: &[S]) -> Option<Vec<String>> {
    let mut sorted: Vec<&str> = labels.iter().map(AsRef::as_ref).collect();
    sorted.sort_unstable();
    sorted.dedup();
    let mut by_lower: Vec<(String, Vec<String>)> = Vec::new();
    for label in sorted {
        let lower = label.to_lowercase();
        match by_lower.iter_mut().find(|(l, _)| *l == lower) {
            Some((_, same)) => same.push(label.to_string()),
            None => by_lower.push((lower, vec![label.to_string()])),
        }
    }
    by_lower
        .into_iter()
        .map(|(_, same)| same)
        .find(|same| same.len() > 1)
}

/// Two labels that differ only by surrounding whitespace, which reading a manifest trims,
/// so that they would silently become one class: a message naming both, or `None`.
/// `labels` are the labels as written, each with where it was written.
pub(crate) fn labels_merged_by_trimming(labels: &[(String, String)]) -> Option<String> {
    let mut first: std::collections::HashMap<&str, &(String, String)> = Default::default();
    labels.iter().find_map(|entry| {
        let (raw, at) = entry;
        let (first_raw, first_at) = *first.entry(raw.trim()).or_insert(entry);
        (first_raw != raw).then(|| {
            format!(
                "{at}: label `{raw}` and `{first_raw}` ({first_at}) differ only by surrounding \
                 spaces, which neurotex trims, so they would be one class; write them \
                 identically, or as distinct names"
            )
        })
    })
}

/// Where a manifest's columns are: the required ones in [`MANIFEST_COLUMNS`] order, the
/// optional conditions in [`CONDITION_COLUMNS`] order, and the optional sliding interval.
struct ManifestColumns {
    required: [usize; 2],
    conditions: [Option<usize>; 3],
    start: Option<usize>,
    end: Option<usize>,
}

impl ManifestColumns {
    fn find(path: &Path, headers: &csv::StringRecord) -> Result<Self> {
        let names: Vec<&str> = headers.iter().collect();
        let why = "a manifest's fields are found by column name";
        if let Some(message) = crate::csvlog::repeated_name(&names, 0..names.len(), why) {
            return Err(DataError::invalid(path, message).into());
        }
        let col = |name: &str| headers.iter().position(|h| h == name);
        let mut required = [0usize; 2];
        for (slot, name) in required.iter_mut().zip(MANIFEST_COLUMNS) {
            *slot = col(name).ok_or_else(|| {
                let needed = MANIFEST_COLUMNS.join(",");
                let mut message = format!("missing column `{name}` (a manifest needs {needed})");
                // One column whose name holds the others: another delimiter than commas.
                if let [only] = names[..] {
                    if let Some(d) = [';', '\t'].into_iter().find(|&d| only.contains(d)) {
                        let shown = if d == ';' { "semicolons" } else { "tabs" };
                        message += &format!(
                            "; its header `{}` is separated by {shown}: a manifest is separated by commas",
                            crate::values::shown_label(only)
                        );
                    }
                }
                DataError::invalid(path, message)
            })?;
        }
        Ok(ManifestColumns {
            required,
            conditions: CONDITION_COLUMNS.map(col),
            start: col("slide_start_s"),
            end: col("slide_end_s"),
        })
    }

    /// Whether column `j` is one neurotex reads into a field of its own.
    fn known(&self, j: usize) -> bool {
        self.required.contains(&j)
            || self.conditions.contains(&Some(j))
            || Some(j) == self.start
            || Some(j) == self.end
    }

    /// The recording that manifest line `line` describes.
    fn row(
        &self,
        path: &Path,
        line: usize,
        headers: &csv::StringRecord,
        record: &csv::StringRecord,
    ) -> Result<Meta> {
        let field = |j: usize| record.get(j).unwrap_or("");
        let bad = |message: String| -> crate::Error {
            DataError::invalid(path, format!("line {line}{message}")).into()
        };
        // An absent column and an empty field both mean "not given".
        let given = |j: Option<usize>| j.map(field).filter(|s| !s.is_empty());
        let number = |j: Option<usize>, name: &str| -> Result<Option<f64>> {
            let Some(s) = given(j) else { return Ok(None) };
            let value = s.parse::<f64>().ok().filter(|v| v.is_finite());
            value.map(Some).ok_or_else(|| {
                bad(format!(
                    ", field `{name}`: expected a finite number, got `{s}`"
                ))
            })
        };
        let non_empty = |j: usize, name: &str| -> Result<String> {
            match field(j) {
                "" => Err(bad(format!(", field `{name}` is empty"))),
                text => Ok(text.to_string()),
            }
        };
        let idx = &self.required;
        let (file, label) = (non_empty(idx[0], "file")?, non_empty(idx[1], "label")?);
        let [speed, force, trial] = self.conditions;
        let trial = match given(trial) {
            None => None,
            Some(text) => Some(text.parse::<i64>().map_err(|_| {
                bad(format!(
                    ", field `trial`: expected an integer, got `{text}`"
                ))
            })?),
        };
        let slide_start_s = number(self.start, "slide_start_s")?;
        let slide_end_s = number(self.end, "slide_end_s")?;
        if let (Some(a), Some(b)) = (slide_start_s, slide_end_s) {
            if !(a >= 0.0 && b > a) {
                return Err(bad(format!(": slide interval must satisfy 0 <= slide_start_s < slide_end_s, got [{a}, {b}]")));
            }
        }
        let extra = headers
            .iter()
            .enumerate()
            .filter(|(j, _)| !self.known(*j))
            .map(|(j, h)| (h.to_string(), field(j).to_string()))
            .collect();
        Ok(Meta {
            file,
            label,
            speed_mm_s: number(speed, "speed_mm_s")?,
            force_n: number(force, "force_n")?,
            trial,
            slide_start_s,
            slide_end_s,
            extra,
        })
    }
}

/// Writes `manifest.csv` for `metas` into `dir`: `file,label`, each condition column
/// ([`CONDITION_COLUMNS`]) that some recording gives (empty where another does not), the
/// sliding interval when any recording has one, then every extra field any recording
/// carries. [`read_manifest`] reads the same recordings back.
///
/// # Errors
/// The file cannot be written.
pub fn write_manifest(dir: &Path, metas: &[Meta]) -> Result<()> {
    let path = dir.join("manifest.csv");
    let given = |column: &str| metas.iter().any(|m| m.field(column).is_some());
    let mut header: Vec<&str> = MANIFEST_COLUMNS.to_vec();
    header.extend(CONDITION_COLUMNS.into_iter().filter(|c| given(c)));
    if given("slide_start_s") || given("slide_end_s") {
        header.extend(["slide_start_s", "slide_end_s"]);
    }
    let mut extra: Vec<&str> = metas
        .iter()
        .flat_map(|m| m.extra.keys().map(String::as_str))
        .collect();
    extra.sort();
    extra.dedup();
    header.extend(extra);
    let mut w = csv::Writer::from_path(&path).map_err(|e| csv_error(&path, e))?;
    w.write_record(&header).map_err(|e| csv_error(&path, e))?;
    for m in metas {
        let row = header.iter().map(|c| m.field(c).unwrap_or_default());
        w.write_record(row).map_err(|e| csv_error(&path, e))?;
    }
    w.flush().map_err(|e| DataError::write(&path, e))?;
    Ok(())
}

/// Creates dataset folder `dir` whole or not at all, with [`crate::io::create_dir_atomic`]:
/// `fill` writes into a temporary folder beside it, which is renamed to `dir` only when
/// `fill` succeeds (and removed otherwise, or on SIGINT/SIGTERM in the binary).
///
/// # Errors
/// `dir` exists and is not empty, or `fill` or the rename fails.
pub fn create_dataset_dir<T>(dir: &Path, fill: impl FnOnce(&Path) -> Result<T>) -> Result<T> {
    crate::io::create_dir_atomic(dir, fill)
}

/// Writes `layout.toml` into `dir`.
///
/// # Errors
/// The file cannot be written.
pub fn write_layout(dir: &Path, layout: &LayoutFile) -> Result<()> {
    let path = dir.join("layout.toml");
    let text = toml::to_string(layout).map_err(|e| DataError::invalid(&path, e.to_string()))?;
    std::fs::write(&path, text).map_err(|e| DataError::write(&path, e))?;
    Ok(())
}
