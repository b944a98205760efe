//! Writing outputs whole or not at all (why:
//! docs/decisions/0012-outputs-whole-and-never-over-what-is-not-theirs.md): every file
//! neurotex writes goes through [`write_atomic`] (or [`stage`] and [`Staged::commit`] when
//! several files must appear together), and every folder through a [`Temporary`] folder
//! renamed into place.
//!
//! Each temporary file or folder is listed in a process-wide registry from before it is
//! created until it is renamed into place or removed, so that a signal handler in the
//! binary can remove whatever is still temporary ([`remove_temporaries`]) before it exits.
//!
//! neurotex often runs as root (in containers), where a rename replaces anything: a device
//! node, a link, another program's file. So a rename only ever replaces a regular file
//! with no other hard link ([`destination`]): a symbolic link is followed and its target
//! replaced (the link stays), a character device or a pipe (`/dev/null`, `/dev/stdout`, a
//! FIFO) is written through, and anything else (a folder, a block device, a socket, a file
//! with several hard links, a dangling link) is refused before any work is done. An output
//! that is one of a command's inputs is refused too ([`check_output`]).
//!
//! Inputs are read the other way round: only regular files ([`open_input`]), so a pipe or
//! a device named as a log never blocks or never ends a run, and text a line at a time up
//! to [`MAX_LINE_BYTES`] ([`LineBounded`]).

use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

use crate::error::{DataError, Result};

mod files;
mod folders;
mod input;

use files::remove_stale;
pub use files::{check_output, destination, same_file, stage, write_atomic, Destination, Staged};
pub use folders::{
    check_output_dir, claim_folder, claim_output_dir, create_dir_atomic, create_parents,
    replace_dir, OutputClaim, OUTPUT_RECORD,
};
pub use input::{
    check_input, kind_name, not_regular, open_input, open_text, read_error, read_text, LineBounded,
    LineTooLong, MAX_LINE_BYTES,
};

/// The temporaries that exist now (or are about to be created).
///
/// Process-wide on purpose, the one piece of mutable state the library's outputs keep: a
/// signal handler has no handle on the call that is writing (it may be any thread, deep in
/// any workflow), and whatever it removes on SIGINT must be known to it. Only paths of
/// temporaries live here; no result depends on it.
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
        let prefix = format!(".{}.partial-", name.to_string_lossy());
        remove_stale(parent(path), &prefix);
        let tmp = parent(path).join(format!("{prefix}{}", std::process::id()));
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

/// Folders of finished work that running the same command again takes up (a benchmark's
/// kept pieces): an interrupted run names them, so that its user knows the work is kept.
static RESUMABLE: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn resumable() -> MutexGuard<'static, Vec<PathBuf>> {
    RESUMABLE.lock().unwrap_or_else(|e| e.into_inner())
}

/// Notes `dir` as finished work a rerun takes up, until [`forget_resumable`].
pub fn note_resumable(dir: &Path) {
    resumable().push(dir.to_path_buf());
}

/// `dir` no longer holds work to resume (its run finished).
pub fn forget_resumable(dir: &Path) {
    forget(&mut resumable(), dir);
}

/// What an interrupted run leaves, for the signal handler's last words: its temporary
/// files removed, and the folders of finished work that the same command takes up again.
pub fn interrupted_note() -> String {
    let mut note = "temporary files removed".to_string();
    for dir in resumable().iter() {
        note.push_str(&format!(
            "; finished work kept in {}: the same command, run again, takes it up",
            dir.display()
        ));
    }
    note
}

/// The folder `path` is in (`.` for a bare name).
fn parent(path: &Path) -> &Path {
    path.parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
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
    fn an_output_folder_that_is_a_file_is_refused_as_a_file_and_kept() {
        let root = tempfile::tempdir().unwrap();
        let file = root.path().join("trial_1.csv");
        std::fs::write(&file, "t_ms,a\n0,1\n").unwrap();
        let message = create_dir_atomic(&file, |_| Ok(()))
            .unwrap_err()
            .to_string();
        assert!(message.contains("is not a folder"), "{message}");
        assert!(!message.contains("not empty"), "{message}");
        assert_eq!(std::fs::read_to_string(&file).unwrap(), "t_ms,a\n0,1\n");
        assert_eq!(names(root.path()), ["trial_1.csv"]);
    }

    #[test]
    fn a_folder_claimed_by_a_running_process_is_refused_and_a_dead_claim_taken_over() {
        let root = tempfile::tempdir().unwrap();
        let dir = root.path().join("report");
        let lock = root.path().join(".report.lock");
        // process 1 runs on every Linux machine
        std::fs::write(&lock, "1").unwrap();
        let message = replace_dir(&dir, |_| Ok(())).unwrap_err().to_string();
        assert!(
            message.contains("another neurotex run (process 1) is writing this folder")
                && message.contains(".report.lock"),
            "{message}"
        );
        assert!(!dir.exists());
        // no process has this id (above Linux's largest, 2^22)
        std::fs::write(&lock, "4294967295").unwrap();
        let claim = claim_output_dir(&dir).unwrap();
        assert_eq!(
            std::fs::read_to_string(&lock).unwrap(),
            std::process::id().to_string()
        );
        // the claiming process itself writes the folder
        replace_dir(&dir, |tmp| {
            std::fs::write(tmp.join("a"), "1").map_err(|e| DataError::write(tmp, e).into())
        })
        .unwrap();
        assert!(lock.exists());
        drop(claim);
        assert_eq!(names(root.path()), vec!["report"]);
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

    #[cfg(unix)]
    #[test]
    fn only_a_regular_file_with_one_link_is_renamed_over() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("f.csv");
        assert_eq!(
            destination(&file).unwrap(),
            Destination::Replace(file.clone())
        );
        std::fs::write(&file, "old").unwrap();
        assert_eq!(
            destination(&file).unwrap(),
            Destination::Replace(file.clone())
        );
        // a link is followed: its target is replaced, the link stays a link
        let link = dir.path().join("link.csv");
        std::os::unix::fs::symlink(&file, &link).unwrap();
        let target = std::fs::canonicalize(&file).unwrap();
        assert_eq!(destination(&link).unwrap(), Destination::Replace(target));
        write_atomic(&link, |w| w.write_all(b"new")).unwrap();
        assert!(std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(std::fs::read_to_string(&file).unwrap(), "new");
        // a device is written through
        let null = Path::new("/dev/null");
        assert_eq!(
            destination(null).unwrap(),
            Destination::WriteThrough(null.into())
        );
        write_atomic(null, |w| w.write_all(b"gone")).unwrap();
        // refused: a second hard link, a folder, a dangling link
        let second = dir.path().join("second.csv");
        std::fs::hard_link(&file, &second).unwrap();
        assert!(destination(&second).is_err());
        assert!(destination(&file).is_err());
        assert!(destination(dir.path()).is_err());
        let dangling = dir.path().join("dangling.csv");
        std::os::unix::fs::symlink(dir.path().join("missing"), &dangling).unwrap();
        assert!(destination(&dangling).is_err());
        assert!(write_atomic(&second, |w| w.write_all(b"x")).is_err());
        assert_eq!(std::fs::read_to_string(&second).unwrap(), "new");
    }

    #[test]
    fn an_output_that_is_an_input_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("in.npy");
        std::fs::write(&input, "x").unwrap();
        let other = dir.path().join("out.npy");
        assert!(check_output(&other, &[&input]).is_ok());
        assert!(check_output(&input, &[&input]).is_err());
        let roundabout = dir.path().join(".").join("in.npy");
        assert!(check_output(&roundabout, &[&input]).is_err());
    }

    #[test]
    fn a_folder_is_replaced_whole_and_only_when_it_holds_an_unchanged_earlier_output() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        let write = |files: &'static [&'static str]| {
            replace_dir(&out, |tmp| {
                std::fs::create_dir(tmp.join("sub")).unwrap();
                for name in files {
                    std::fs::write(tmp.join(name), "1").unwrap();
                }
                Ok(())
            })
        };
        write(&["a.txt", "sub/b.svg"]).unwrap();
        let record = std::fs::read_to_string(out.join(OUTPUT_RECORD)).unwrap();
        assert!(
            record.contains("  a.txt\n") && record.contains("  sub/b.svg\n"),
            "{record}"
        );
        // what the earlier output had and the new one has not goes
        write(&["a.txt"]).unwrap();
        assert_eq!(names(&out), [OUTPUT_RECORD, "a.txt", "sub"]);
        assert!(names(&out.join("sub")).is_empty());
        assert_eq!(names(dir.path()), ["out"]);
        // a failure leaves the earlier output as it was, and names no temporary
        let failed: Result<()> = replace_dir(&out, |tmp| {
            Err(DataError::write(tmp.join("a.txt"), std::io::Error::other("disk full")).into())
        });
        let message = failed.unwrap_err().to_string();
        assert!(
            message.contains(&format!("{}", out.join("a.txt").display())),
            "{message}"
        );
        assert!(!message.contains("partial"), "{message}");
        assert_eq!(names(dir.path()), ["out"]);
        // a file of the user's, even under a name neurotex writes, or an edited file of the
        // earlier output: refused, untouched
        for (path, why) in [("sub/b.svg", "did not write"), ("a.txt", "changed since")] {
            std::fs::write(out.join(path), "mine").unwrap();
            let refused = replace_dir(&out, |_| Ok(())).unwrap_err().to_string();
            assert!(refused.contains(path) && refused.contains(why), "{refused}");
            assert_eq!(std::fs::read_to_string(out.join(path)).unwrap(), "mine");
            std::fs::remove_file(out.join(path)).unwrap();
        }
        // a folder without a record, holding anything: refused
        let other = dir.path().join("other");
        std::fs::create_dir(&other).unwrap();
        std::fs::write(other.join("report.md"), "my notes").unwrap();
        assert!(check_output_dir(&other).is_err());
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
