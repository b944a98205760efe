//! Files written whole: staged beside their destination and renamed into place, the
//! destination checked first (a regular file, a link's target, a device or pipe written
//! through), an output that is an input refused.

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::error::{DataError, Result};

use super::{parent, remove, Temporary};

/// A file written and flushed to disk under a temporary name, not yet in place.
#[derive(Debug)]
pub struct Staged {
    /// `None` when the content was written through (a device or a pipe).
    tmp: Option<Temporary>,
    path: PathBuf,
}

impl Staged {
    /// Renames the file into place (nothing to do for a device or a pipe, written already).
    ///
    /// # Errors
    /// The rename fails; the temporary is removed and `path` left as it was.
    pub fn commit(self) -> Result<()> {
        let path = self.path;
        match self.tmp {
            Some(tmp) => tmp
                .persist(&path)
                .map_err(|e| DataError::write(&path, e).into()),
            None => Ok(()),
        }
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
    let target = match destination(path)? {
        Destination::Replace(target) => target,
        Destination::WriteThrough(target) => {
            write_through(&target, fill).map_err(|e| DataError::write(path, e))?;
            return Ok(Staged {
                tmp: None,
                path: target,
            });
        }
    };
    let dir = parent(&target);
    if !dir.is_dir() {
        let message = format!("folder {} does not exist", dir.display());
        return Err(DataError::invalid(path, message).into());
    }
    let tmp = Temporary::beside(&target)?;
    let written = (|| -> std::io::Result<()> {
        let file = std::fs::File::create_new(tmp.path())?;
        let mut w = std::io::BufWriter::new(file);
        fill(&mut w)?;
        w.flush()?;
        w.into_inner().map_err(|e| e.into_error())?.sync_all()
    })();
    match written {
        Ok(()) => Ok(Staged {
            tmp: Some(tmp),
            path: target,
        }),
        Err(e) => Err(DataError::write(path, e).into()),
    }
}

/// Writes `fill` straight into an existing character device or pipe, which has no content
/// to lose and cannot be renamed over.
fn write_through(
    target: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let file = std::fs::OpenOptions::new().write(true).open(target)?;
    let mut w = std::io::BufWriter::new(file);
    fill(&mut w)?;
    w.flush()
}

/// Where an output path's content goes (see the module's notes).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Destination {
    /// A new file, or a regular file with no other hard link, at this path (a symbolic
    /// link's target): written beside it under a temporary name and renamed over it.
    Replace(PathBuf),
    /// A character device or a pipe: written through, never renamed over.
    WriteThrough(PathBuf),
}

/// Where the content for output file `path` goes, following symbolic links.
///
/// # Errors
/// `path` is (or links to) a folder, a block device, a socket or a regular file with
/// other hard links; or a link whose target does not exist.
pub fn destination(path: &Path) -> Result<Destination> {
    let meta = match std::fs::symlink_metadata(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Ok(Destination::Replace(path.to_path_buf()))
        }
        Err(e) => return Err(DataError::write(path, e).into()),
        Ok(meta) => meta,
    };
    if meta.file_type().is_symlink() {
        let target = std::fs::canonicalize(path).map_err(|_| {
            let to = std::fs::read_link(path).unwrap_or_default();
            DataError::invalid(
                path,
                format!(
                    "is a symbolic link to {}, which does not exist; write to the target's \
                     path or remove the link",
                    to.display()
                ),
            )
        })?;
        return match destination(&target)? {
            // `canonicalize` leaves no link in `target`, so this does not recurse again.
            Destination::Replace(t) if t == target => Ok(Destination::Replace(target)),
            other => Ok(other),
        };
    }
    let refuse = |what: String| -> Result<Destination> {
        Err(DataError::invalid(
            path,
            format!("{what}; neurotex replaces only regular files"),
        )
        .into())
    };
    let kind = meta.file_type();
    if kind.is_file() {
        let links = hard_links(&meta);
        if links > 1 {
            let message = format!(
                "has {links} hard links, and writing a new file would split them (the other \
                 names would keep the old content); remove it first or choose another name"
            );
            return Err(DataError::invalid(path, message).into());
        }
        return Ok(Destination::Replace(path.to_path_buf()));
    }
    if kind.is_dir() {
        return refuse("is a folder, not a file".to_string());
    }
    if is_char_device_or_pipe(&kind) {
        return Ok(Destination::WriteThrough(path.to_path_buf()));
    }
    refuse("is a block device or socket, not a file".to_string())
}

#[cfg(unix)]
fn hard_links(meta: &std::fs::Metadata) -> u64 {
    use std::os::unix::fs::MetadataExt;
    meta.nlink()
}

#[cfg(not(unix))]
fn hard_links(_: &std::fs::Metadata) -> u64 {
    1
}

#[cfg(unix)]
fn is_char_device_or_pipe(kind: &std::fs::FileType) -> bool {
    use std::os::unix::fs::FileTypeExt;
    kind.is_char_device() || kind.is_fifo()
}

#[cfg(not(unix))]
fn is_char_device_or_pipe(_: &std::fs::FileType) -> bool {
    false
}

/// Checks, before any work, that output file `output` can be written ([`destination`])
/// and is none of `inputs` (compared as files, through links and hard links: the same
/// device and inode).
///
/// # Errors
/// As [`destination`]; or `output` is one of `inputs`.
pub fn check_output<P: AsRef<Path>>(output: &Path, inputs: &[P]) -> Result<()> {
    destination(output)?;
    if let Some(input) = inputs.iter().find(|i| same_file(output, i.as_ref())) {
        let message = if input.as_ref() == output {
            "is also an input of this command; write the output elsewhere".to_string()
        } else {
            format!(
                "is the same file as input {}; write the output elsewhere",
                input.as_ref().display()
            )
        };
        return Err(DataError::invalid(output, message).into());
    }
    Ok(())
}

/// Whether `a` and `b` both exist and are one file.
#[cfg(unix)]
pub fn same_file(a: &Path, b: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (std::fs::metadata(a), std::fs::metadata(b)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

/// Whether `a` and `b` both exist and are one file.
#[cfg(not(unix))]
pub fn same_file(a: &Path, b: &Path) -> bool {
    match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

/// Removes the temporaries `{prefix}PID` in `dir` that a process killed without a chance to
/// clean up (`kill -9`, a power cut) left behind: those whose process no longer runs.
/// Where that cannot be told (no `/proc`), nothing is removed.
pub(super) fn remove_stale(dir: &Path, prefix: &str) {
    if !Path::new("/proc/self").exists() {
        return;
    }
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(pid) = name
            .to_str()
            .and_then(|n| n.strip_prefix(prefix))
            .and_then(|pid| pid.parse::<u32>().ok())
        else {
            continue;
        };
        if pid != std::process::id() && !Path::new(&format!("/proc/{pid}")).exists() {
            remove(&entry.path());
        }
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
