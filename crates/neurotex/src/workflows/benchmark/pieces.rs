//! A comparison's finished pieces kept in a folder, so that a benchmark stopped part way
//! through a protocol takes them up when it is run again with the same settings.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use sha2::{Digest, Sha256};

use crate::compare::Keep;
use crate::error::DataError;
use crate::io::write_atomic;
use crate::Result;

/// The pieces of one comparison: a file each, named by the SHA-256 of its key and holding
/// the key on its first line and the piece after it; a folder made under another key is
/// emptied first, so pieces of other settings are never taken.
pub(super) struct Pieces {
    dir: PathBuf,
    taken: AtomicUsize,
    /// Pieces of other settings removed when the folder was opened.
    pub(super) removed: usize,
    /// The settings that differed from those of the removed pieces, as `name: then → now`.
    pub(super) differed: Vec<String>,
    /// Pieces of these settings the folder held when it was opened.
    pub(super) held: usize,
    /// Whether the folder holds a piece (an interrupted run names it only then).
    holds: AtomicBool,
}

impl Pieces {
    /// The pieces folder `dir` of the comparison under `key` (its JSON text).
    ///
    /// # Errors
    /// The folder cannot be emptied or made.
    pub(super) fn open(dir: PathBuf, key: &str) -> Result<Pieces> {
        let key_file = dir.join("key.json");
        let (mut removed, mut differed) = (0, Vec::new());
        let before = key_of(&dir);
        if before.as_deref() != Some(key) {
            if dir.exists() {
                removed = pieces_only(&dir)?;
                differed = differences(before.as_deref().unwrap_or_default(), key);
                std::fs::remove_dir_all(&dir).map_err(|e| DataError::write(&dir, e))?;
            }
            std::fs::create_dir_all(&dir).map_err(|e| DataError::write(&dir, e))?;
            write_atomic(&key_file, |w| w.write_all(key.as_bytes()))?;
        }
        let held = pieces_only(&dir)?;
        let pieces = Pieces {
            dir,
            taken: AtomicUsize::new(0),
            removed,
            differed,
            held,
            holds: AtomicBool::new(false),
        };
        if pieces.held > 0 {
            pieces.noted();
        }
        Ok(pieces)
    }

    /// The pieces folder `dir` of the comparison under `key`, made before (by a
    /// benchmark's shares on a cluster, where another task may be writing into it).
    ///
    /// # Errors
    /// No such folder, or one made under another key.
    pub(super) fn existing(dir: PathBuf, key: &str) -> Result<Pieces> {
        if key_of(&dir).as_deref() != Some(key) {
            let why = "is not the pieces folder of these settings: make the shares first";
            return Err(DataError::invalid(&dir, why.to_string()).into());
        }
        Ok(Pieces {
            dir,
            taken: AtomicUsize::new(0),
            removed: 0,
            differed: Vec::new(),
            held: 0,
            holds: AtomicBool::new(false),
        })
    }

    /// The folder noted as finished work an interrupted run names, once it holds a piece.
    fn noted(&self) {
        if !self.holds.swap(true, Ordering::SeqCst) {
            crate::io::note_resumable(&self.dir);
        }
    }

    /// How many pieces were taken from the folder.
    pub(super) fn taken(&self) -> usize {
        self.taken.load(Ordering::Relaxed)
    }

    /// The folder, once its comparison is written whole and its pieces are no longer
    /// needed, removed; a folder that stays is taken by nothing but the same comparison.
    pub(super) fn finish(self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }

    fn file(&self, key: &str) -> PathBuf {
        let digest: String = Sha256::digest(key.as_bytes())
            .iter()
            .take(12)
            .map(|b| format!("{b:02x}"))
            .collect();
        self.dir.join(format!("{digest}.piece"))
    }
}

/// The settings of two keys' JSON texts that differ, as `name: then → now` (values as
/// JSON); empty when the earlier key cannot be read.
fn differences(before: &str, now: &str) -> Vec<String> {
    let parse = |t: &str| serde_json::from_str::<serde_json::Map<String, serde_json::Value>>(t);
    let (Ok(before), Ok(now)) = (parse(before), parse(now)) else {
        return Vec::new();
    };
    let absent = serde_json::Value::Null;
    (now.iter())
        .filter_map(|(name, value)| {
            let then = before.get(name).unwrap_or(&absent);
            (then != value).then(|| format!("{name}: {then} → {value}"))
        })
        .collect()
}

/// The key the pieces folder `dir` was made under (its key file's text), if it has one.
fn key_of(dir: &Path) -> Option<String> {
    std::fs::read_to_string(dir.join("key.json")).ok()
}

/// How many pieces the folder `dir` holds, when it holds nothing else than pieces, their
/// key and a write's hidden temporary (left by a process killed outright).
///
/// # Errors
/// Anything else in it: a folder of the user's is never removed.
fn pieces_only(dir: &Path) -> Result<usize> {
    let items = std::fs::read_dir(dir).map_err(|reason| DataError::Io {
        path: dir.to_path_buf(),
        reason,
    })?;
    let mut pieces = 0;
    for item in items.flatten() {
        let name = item.file_name().to_string_lossy().into_owned();
        let file = item.file_type().is_ok_and(|t| t.is_file());
        match name.ends_with(".piece") {
            true if file => pieces += 1,
            _ if file && (name == "key.json" || name.starts_with('.')) => {}
            _ => {
                let why = format!("holds {name}, which is not a benchmark's finished piece: move it, or give another --out");
                return Err(DataError::invalid(dir, why).into());
            }
        }
    }
    Ok(pieces)
}

impl Drop for Pieces {
    /// The folder is no longer the work of a running comparison (an interrupted run names
    /// only those).
    fn drop(&mut self) {
        if self.holds.load(Ordering::SeqCst) {
            crate::io::forget_resumable(&self.dir);
        }
    }
}

impl Keep for Pieces {
    fn get(&self, key: &str) -> Option<String> {
        let text = std::fs::read_to_string(self.file(key)).ok()?;
        let (found, piece) = text.split_once('\n')?;
        (found == key).then(|| {
            self.taken.fetch_add(1, Ordering::Relaxed);
            piece.to_string()
        })
    }

    fn put(&self, key: &str, json: &str) -> Result<()> {
        write_atomic(&self.file(key), |w| write!(w, "{key}\n{json}"))?;
        self.noted();
        Ok(())
    }
}
