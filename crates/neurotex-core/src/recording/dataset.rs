//! A dataset folder opened: its manifest's recordings and layout, each recording loaded on
//! demand, and the one grid a set of datasets shares.

use std::path::{Path, PathBuf};

use crate::error::{DataError, DatasetError, Result};
use crate::values::{Grid, Speed};

use super::layout_file::{LayoutFile, DEFAULT_MAX_DURATION_S};
use super::manifest::{no_manifest, read_manifest_columns};
use super::read::read_recording;
use super::{Meta, Recording, EVENTS_NOT_SAMPLES};

/// A dataset folder: its manifest, layout and where the recordings are.
#[derive(Debug, Clone)]
pub struct Dataset {
    /// The folder.
    pub root: PathBuf,
    /// One entry per recording, in manifest order.
    pub entries: Vec<Meta>,
    /// The manifest's column names, in its order.
    pub columns: Vec<String>,
    /// The parsed `layout.toml` (all defaults when absent).
    pub layout: LayoutFile,
}

impl Dataset {
    /// Opens a dataset folder, reading and checking `manifest.csv` and `layout.toml`; every
    /// recording must lie inside the folder (see [`Dataset::open_with`]).
    ///
    /// # Errors
    /// Missing or malformed manifest or layout; a manifest line naming a missing file or
    /// one outside the folder.
    pub fn open(root: impl AsRef<Path>) -> Result<Self> {
        Self::open_with(root, false)
    }

    /// [`Dataset::open`], with `allow_outside_paths` choosing whether manifest `file`
    /// entries may leave the dataset folder (`../x.npy`, absolute paths, symbolic links to
    /// elsewhere). Refused by default: a dataset folder copied or shared should hold its
    /// recordings, and a manifest from elsewhere should not make neurotex read any file.
    ///
    /// # Errors
    /// As [`Dataset::open`].
    pub fn open_with(root: impl AsRef<Path>, allow_outside_paths: bool) -> Result<Self> {
        let root = root.as_ref().to_path_buf();
        if !root.is_dir() {
            let why = match root.exists() {
                true => "is not a dataset folder (expected a folder with manifest.csv)",
                false => "does not exist (expected a dataset folder with manifest.csv)",
            };
            return Err(DataError::invalid(&root, why).into());
        }
        let layout_path = root.join("layout.toml");
        let layout = if layout_path.exists() {
            LayoutFile::read(&layout_path)?
        } else {
            LayoutFile::default()
        };
        let manifest_path = root.join("manifest.csv");
        if !manifest_path.exists() {
            return Err(no_manifest(&root).into());
        }
        let (columns, entries) = read_manifest_columns(&manifest_path)?;
        for (i, m) in entries.iter().enumerate() {
            let file = root.join(&m.file);
            if let Some(meta) = std::fs::metadata(&file).ok().filter(|m| !m.is_file()) {
                let kind = crate::io::kind_name(meta.file_type());
                let why = format!(
                    "line {}: file `{}` is {kind}, not a regular file: a dataset's recordings are regular files",
                    i + 2,
                    m.file
                );
                return Err(DataError::invalid(&manifest_path, why).into());
            }
            if !file.is_file() {
                return Err(DataError::invalid(
                    &manifest_path,
                    format!(
                        "line {}: file `{}` does not exist in {}",
                        i + 2,
                        m.file,
                        root.display()
                    ),
                )
                .into());
            }
            if !allow_outside_paths {
                check_inside(&root, &m.file).map_err(|why| {
                    DataError::invalid(
                        &manifest_path,
                        format!("line {}: file `{}` {why}", i + 2, m.file),
                    )
                })?;
            }
        }
        Ok(Dataset {
            root,
            entries,
            columns,
            layout,
        })
    }

    /// Every file the dataset reads: `manifest.csv`, `layout.toml` when there is one, and
    /// each recording the manifest lists (so a command can refuse to write over its input).
    pub fn files(&self) -> Vec<PathBuf> {
        let mut files = vec![
            self.root.join("manifest.csv"),
            self.root.join("layout.toml"),
        ];
        files.extend(self.entries.iter().map(|m| self.root.join(&m.file)));
        files
    }

    /// The sampling rate of the dataset's recordings (default 1000 Hz, the paper's).
    pub fn fs(&self) -> f64 {
        self.layout.fs.unwrap_or(1000.0)
    }

    /// Loads recording `index` from disk.
    ///
    /// # Errors
    /// Unreadable file, wrong shape, non-finite samples, non-increasing time stamps.
    ///
    /// # Panics
    /// If `index` is out of range (a caller bug).
    pub fn load(&self, index: usize) -> Result<Recording> {
        let meta = &self.entries[index];
        if self.is_events() {
            return Err(DataError::invalid(self.root.join(&meta.file), EVENTS_NOT_SAMPLES).into());
        }
        let path = self.root.join(&meta.file);
        let mut rec = read_recording(&path, &self.layout)?;
        rec.meta = meta.clone();
        Ok(rec)
    }

    /// Whether the recordings are address events (`layout.toml` has an `[events]` table).
    pub fn is_events(&self) -> bool {
        self.layout.events.is_some()
    }

    /// Loads event recording `index` as spike trains ([`crate::events`]); the manifest's
    /// optional `duration_s` column gives its length.
    ///
    /// # Errors
    /// Not an event dataset, an unreadable file, a bad `duration_s`, or an event that breaks
    /// a rule.
    ///
    /// # Panics
    /// If `index` is out of range (a caller bug).
    pub fn load_events(&self, index: usize) -> Result<crate::events::Events> {
        let meta = &self.entries[index];
        let path = self.root.join(&meta.file);
        let (Some(format), Some(rows), Some(cols)) =
            (&self.layout.events, self.layout.rows, self.layout.cols)
        else {
            let why = "is a sampled recording: its dataset's layout.toml has no [events] table";
            return Err(DataError::invalid(&path, why).into());
        };
        let manifest = || self.root.join("manifest.csv");
        let duration = match meta.field("duration_s").filter(|d| !d.is_empty()) {
            None => None,
            Some(text) => match text.parse::<f64>() {
                Ok(s) if s.is_finite() && s >= 0.0 => Some((s * 1000.0).round() as u64),
                _ => {
                    let why = format!(
                        "line {}: duration_s `{text}` is not a non-negative number of seconds",
                        index + 2
                    );
                    return Err(DataError::invalid(manifest(), why).into());
                }
            },
        };
        let grid = self.layout.event_grid(rows, cols);
        let max_s = self.layout.max_duration_s.unwrap_or(DEFAULT_MAX_DURATION_S);
        // Spike times are u32 milliseconds: at most 49 days, far past any limit one sets.
        let max_steps = ((max_s * 1000.0) as u64).min(u64::from(u32::MAX));
        let limit = crate::events::StepLimit::new(max_steps, rows * cols);
        if let Some(d) = duration.filter(|&d| d > limit.steps) {
            let why = format!(
                "line {}: duration_s {} s is longer than {}",
                index + 2,
                d as f64 / 1000.0,
                limit.describe()
            );
            return Err(DataError::invalid(manifest(), why).into());
        }
        crate::events::read_events(&path, format, &grid, duration, max_steps)
    }

    /// A fingerprint of the dataset as its manifest lists it, `sha256:` and 64 hex digits:
    /// SHA-256 over the manifest's length in bytes (8 bytes, little-endian), the bytes of
    /// `manifest.csv`, then each listed file's size in bytes (8 bytes, little-endian) in
    /// manifest order. File sizes, not contents, keep it cheap on large datasets; so a
    /// recording rewritten with different samples of the same size keeps the fingerprint.
    /// In Python: `h = hashlib.sha256(); h.update(len(m).to_bytes(8, "little")); h.update(m)`,
    /// then `h.update(os.path.getsize(f).to_bytes(8, "little"))` for each file.
    ///
    /// # Errors
    /// The manifest or a listed file can no longer be read.
    pub fn fingerprint(&self) -> Result<String> {
        use sha2::{Digest, Sha256};
        let manifest_path = self.root.join("manifest.csv");
        let manifest =
            std::fs::read(&manifest_path).map_err(|e| DataError::io(&manifest_path, e))?;
        let mut hasher = Sha256::new();
        hasher.update((manifest.len() as u64).to_le_bytes());
        hasher.update(&manifest);
        for meta in &self.entries {
            let path = self.root.join(&meta.file);
            let size = std::fs::metadata(&path)
                .map_err(|e| DataError::io(&path, e))?
                .len();
            hasher.update(size.to_le_bytes());
        }
        let hex: String = hasher
            .finalize()
            .iter()
            .map(|byte| format!("{byte:02x}"))
            .collect();
        Ok(format!("sha256:{hex}"))
    }

    /// The distinct labels in order of first appearance.
    pub fn labels(&self) -> Vec<String> {
        let mut out: Vec<String> = Vec::new();
        for m in &self.entries {
            if !out.contains(&m.label) {
                out.push(m.label.clone());
            }
        }
        out
    }

    /// The distinct speeds, ascending; empty when the manifest gives none.
    pub fn speeds(&self) -> Vec<Speed> {
        Speed::distinct(self.entries.iter().filter_map(Meta::speed))
    }

    /// The indices of the recordings at any of `speeds`, in manifest order.
    ///
    /// # Errors
    /// [`DatasetError::NoRecordingsAt`] for the first of `speeds` at which the dataset
    /// holds no recording, naming the speeds it has.
    pub fn indices_at(&self, speeds: &[Speed]) -> Result<Vec<usize>> {
        let available = self.speeds();
        if let Some(&speed) = speeds.iter().find(|s| !available.contains(s)) {
            return Err(DatasetError::NoRecordingsAt {
                speed,
                root: self.root.clone(),
                available,
            }
            .into());
        }
        Ok((0..self.entries.len())
            .filter(|&i| self.entries[i].speed().is_some_and(|s| speeds.contains(&s)))
            .collect())
    }
}

/// Whether manifest entry `file` stays inside dataset folder `root`: a relative path
/// without `..` that, once symbolic links are resolved, still lies under the folder.
/// Returns why not.
fn check_inside(root: &Path, file: &str) -> std::result::Result<(), String> {
    use std::path::Component;
    let outside = "lies outside the dataset folder; manifest paths must stay inside it (--allow-outside-paths lets them out)";
    let relative = Path::new(file)
        .components()
        .all(|c| matches!(c, Component::Normal(_) | Component::CurDir));
    if !relative {
        return Err(format!("{outside} (no absolute paths or `..`)"));
    }
    let canonical = |p: &Path| {
        p.canonicalize()
            .map_err(|e| format!("cannot be resolved: {e}"))
    };
    if !canonical(&root.join(file))?.starts_with(canonical(root)?) {
        return Err(format!("{outside} (a symbolic link leads out)"));
    }
    Ok(())
}

/// The one grid that recordings share, from `(file, grid)` pairs in dataset order.
///
/// # Errors
/// [`DatasetError::MixedGrids`] naming the first recording whose grid (size or mask)
/// differs from the first one's; [`DatasetError::Empty`] when there is no pair.
pub fn one_grid<'a>(grids: impl IntoIterator<Item = (&'a str, Grid)>) -> Result<Grid> {
    let mut grids = grids.into_iter();
    let (first, first_grid) = grids.next().ok_or(DatasetError::Empty)?;
    match grids.find(|(_, grid)| *grid != first_grid) {
        Some((file, _)) => Err(DatasetError::MixedGrids {
            file: file.to_string(),
            first: first.to_string(),
        }
        .into()),
        None => Ok(first_grid),
    }
}
