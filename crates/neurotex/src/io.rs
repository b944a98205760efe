//! Writing outputs whole or not at all (SPEC 8): every file neurotex writes goes through
//! [`write_atomic`] (or [`stage`] and [`Staged::commit`] when several files must appear
//! together), and every folder through a [`Temporary`] folder renamed into place.
//!
//! Each temporary file or folder is listed in a process-wide registry from before it is
//! created until it is renamed into place or removed, so that a signal handler in the
//! binary can remove whatever is still temporary ([`remove_temporaries`]) before it exits.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

use crate::error::{DataError, Result};

/// The temporaries that exist now (or are about to be created).
static TEMPORARIES: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// The registry, even after a panic on another thread poisoned it (its list stays valid:
/// every change to it is a single push or removal).
fn registry() -> MutexGuard<'static, Vec<PathBuf>> {
    TEMPORARIES.lock().unwrap_or_else(|e| e.into_inner())
}

/// Removes a file, or a folder with everything in it. Workers may still be writing into
/// a folder while it is removed, so a folder that is not empty yet is tried again.
fn remove(path: &Path) {
    for _ in 0..20 {
        let done = match std::fs::symlink_metadata(path) {
            Err(_) => true,
            Ok(m) if m.is_dir() => std::fs::remove_dir_all(path).is_ok(),
            Ok(_) => std::fs::remove_file(path).is_ok(),
        };
        if done {
            return;
        }
    }
}

/// A temporary file or folder, registered before it is created: removed when dropped,
/// unless it was renamed into place ([`Temporary::persist`]) or kept ([`Temporary::keep`]).
#[derive(Debug)]
pub struct Temporary {
    path: PathBuf,
    /// Renamed into place or kept: nothing to remove.
    done: bool,
}

impl Temporary {
    /// Registers `path` as temporary; the caller then creates it.
    pub fn new(path: PathBuf) -> Self {
        registry().push(path.clone());
        Temporary { path, done: false }
    }

    /// The hidden temporary name beside `path` (`.name.partial-PID`), registered.
    ///
    /// # Errors
    /// `path` has no file name.
    pub fn beside(path: &Path) -> Result<Self> {
        let name = path
            .file_name()
            .ok_or_else(|| DataError::invalid(path, "not a file or folder name"))?;
        let tmp = parent(path).join(format!(
            ".{}.partial-{}",
            name.to_string_lossy(),
            std::process::id()
        ));
        Ok(Temporary::new(tmp))
    }

    /// The temporary path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Renames the temporary to `dest`, which then no longer counts as temporary. The
    /// registry is held during the rename, so a signal handler sees either the temporary
    /// (and removes it) or the finished output (and leaves it).
    ///
    /// # Errors
    /// The rename fails (the temporary is then removed).
    pub fn persist(mut self, dest: &Path) -> std::io::Result<()> {
        let mut list = registry();
        let result = std::fs::rename(&self.path, dest);
        if result.is_ok() {
            forget(&mut list, &self.path);
            self.done = true;
        }
        drop(list);
        result
    }

    /// Keeps the temporary where it is: it is no longer removed.
    pub fn keep(mut self) {
        forget(&mut registry(), &self.path);
        self.done = true;
    }
}

fn forget(list: &mut Vec<PathBuf>, path: &Path) {
    if let Some(i) = list.iter().rposition(|p| p == path) {
        list.swap_remove(i);
    }
}

impl Drop for Temporary {
    fn drop(&mut self) {
        if self.done {
            return;
        }
        let mut list = registry();
        remove(&self.path);
        forget(&mut list, &self.path);
    }
}

/// Removes every temporary file and folder of the process, for a signal handler about to
/// exit. The returned guard keeps the registry locked: while it lives, no new temporary can
/// be registered and none can be renamed into place, so nothing half-written appears
/// between the clean-up and the exit. Hold it until the process exits.
pub fn remove_temporaries() -> MutexGuard<'static, Vec<PathBuf>> {
    let mut list = registry();
    for path in list.drain(..) {
        remove(&path);
    }
    list
}

/// The folder `path` is in (`.` for a bare name).
fn parent(path: &Path) -> &Path {
    path.parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

/// A file written and flushed to disk under a temporary name, not yet in place.
#[derive(Debug)]
pub struct Staged {
    tmp: Temporary,
    path: PathBuf,
}

impl Staged {
    /// Renames the file into place.
    ///
    /// # Errors
    /// The rename fails; the temporary is removed and `path` left as it was.
    pub fn commit(self) -> Result<()> {
        let path = self.path;
        self.tmp
            .persist(&path)
            .map_err(|e| DataError::io(&path, e).into())
    }
}

/// Writes `path`'s future content through `fill` into a hidden temporary file beside it,
/// flushed to disk; [`Staged::commit`] renames it into place. Dropped uncommitted (an
/// error elsewhere), the temporary file is removed.
///
/// # Errors
/// The folder does not exist, the file cannot be created or written, or `fill` fails;
/// the temporary file is then removed.
pub fn stage(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<Staged> {
    let dir = parent(path);
    if !dir.is_dir() {
        let message = format!("folder {} does not exist", dir.display());
        return Err(DataError::invalid(path, message).into());
    }
    let tmp = Temporary::beside(path)?;
    let written = (|| -> std::io::Result<()> {
        let file = std::fs::File::create(tmp.path())?;
        let mut w = std::io::BufWriter::new(file);
        fill(&mut w)?;
        w.flush()?;
        w.into_inner().map_err(|e| e.into_error())?.sync_all()
    })();
    match written {
        Ok(()) => Ok(Staged {
            tmp,
            path: path.to_path_buf(),
        }),
        Err(e) => Err(DataError::io(path, e).into()),
    }
}

/// Writes `path` through `fill` into a hidden temporary file beside it, flushed to disk and
/// renamed into place only when everything succeeded; on failure the temporary file is
/// removed and `path` is left as it was.
///
/// # Errors
/// The folder does not exist, the file cannot be created or written, or `fill` fails.
pub fn write_atomic(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    stage(path, fill)?.commit()
}

/// Creates folder `dir` whole or not at all: `fill` writes into a registered temporary
/// folder beside it, which is renamed to `dir` when `fill` succeeds and removed otherwise.
/// Missing parent folders are created, and removed again on failure. An existing empty
/// `dir` is replaced.
///
/// # Errors
/// `dir` exists and is not empty, or a folder cannot be created, or `fill` or the rename
/// fails.
pub fn create_dir_atomic<T>(dir: &Path, fill: impl FnOnce(&Path) -> Result<T>) -> Result<T> {
    let is_empty = |d: &Path| std::fs::read_dir(d).is_ok_and(|mut e| e.next().is_none());
    if dir.exists() && !is_empty(dir) {
        return Err(DataError::invalid(dir, "output folder exists and is not empty").into());
    }
    let created = create_parents(dir)?;
    let tmp = Temporary::beside(dir)?;
    std::fs::create_dir(tmp.path()).map_err(|e| DataError::io(tmp.path(), e))?;
    let value = fill(tmp.path())?;
    if dir.exists() {
        std::fs::remove_dir(dir).map_err(|e| DataError::io(dir, e))?;
    }
    tmp.persist(dir).map_err(|e| DataError::io(dir, e))?;
    if let Some(created) = created {
        created.keep();
    }
    Ok(value)
}

/// Creates the missing folders above `path`; the topmost one created is returned as a
/// [`Temporary`], so that it goes away again unless the caller keeps it.
///
/// # Errors
/// A folder cannot be created.
pub fn create_parents(path: &Path) -> Result<Option<Temporary>> {
    let dir = parent(path);
    if dir.is_dir() {
        return Ok(None);
    }
    if dir.exists() {
        return Err(DataError::invalid(dir, "is not a folder").into());
    }
    let mut top = dir;
    while let Some(up) = top
        .parent()
        .filter(|p| !p.as_os_str().is_empty() && !p.exists())
    {
        top = up;
    }
    let tmp = Temporary::new(top.to_path_buf());
    std::fs::create_dir_all(dir).map_err(|e| DataError::io(dir, e))?;
    Ok(Some(tmp))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    #[test]
    fn a_failed_fill_leaves_neither_file_nor_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.txt");
        std::fs::write(&path, "old").unwrap();
        let err = write_atomic(&path, |w| {
            w.write_all(b"half")?;
            Err(std::io::Error::other("disk full"))
        });
        assert!(err.is_err());
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "old");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        write_atomic(&path, |w| w.write_all(b"new")).unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "new");
        assert!(write_atomic(&dir.path().join("missing/x"), |_| Ok(())).is_err());
    }

    #[test]
    fn a_staged_file_dropped_uncommitted_is_removed() {
        let dir = tempfile::tempdir().unwrap();
        let staged = stage(&dir.path().join("a"), |w| w.write_all(b"a")).unwrap();
        assert_eq!(names(dir.path()).len(), 1);
        drop(staged);
        assert!(names(dir.path()).is_empty());
        let staged = stage(&dir.path().join("a"), |w| w.write_all(b"a")).unwrap();
        staged.commit().unwrap();
        assert_eq!(names(dir.path()), ["a"]);
    }

    #[test]
    fn a_failed_folder_leaves_nothing_not_even_its_parents() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("x/y/out");
        let failed: Result<()> = create_dir_atomic(&out, |tmp| {
            std::fs::write(tmp.join("f"), "f").unwrap();
            Err(DataError::invalid(tmp, "failed").into())
        });
        assert!(failed.is_err());
        assert!(names(dir.path()).is_empty());
        create_dir_atomic(&out, |tmp| {
            std::fs::write(tmp.join("f"), "f").unwrap();
            Ok(())
        })
        .unwrap();
        assert_eq!(names(&out), ["f"]);
        assert_eq!(names(&dir.path().join("x/y")), ["out"]);
    }
}
