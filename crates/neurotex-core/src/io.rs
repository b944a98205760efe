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

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

use crate::error::{DataError, Result};

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

/// The folder `path` is in (`.` for a bare name).
fn parent(path: &Path) -> &Path {
    path.parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

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
fn remove_stale(dir: &Path, prefix: &str) {
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
    if dir.exists() && !dir.is_dir() {
        let why = "exists and is not a folder: the output here is a folder; name a new one";
        return Err(DataError::invalid(dir, why).into());
    }
    if dir.exists() && !is_empty(dir) {
        return Err(DataError::invalid(dir, "output folder exists and is not empty").into());
    }
    let created = create_parents(dir)?;
    let _claim = claim_folder(dir)?;
    let tmp = Temporary::beside(dir)?;
    std::fs::create_dir(tmp.path()).map_err(|e| DataError::write(dir, e))?;
    let value = fill(tmp.path()).map_err(|e| named_in(e, tmp.path(), dir))?;
    if dir.exists() {
        std::fs::remove_dir(dir).map_err(|e| DataError::write(dir, e))?;
    }
    tmp.persist(dir).map_err(|e| DataError::write(dir, e))?;
    if let Some(created) = created {
        created.keep();
    }
    Ok(value)
}

/// `error` with a path inside the temporary folder `tmp` named as it will be inside `dir`:
/// the user never sees the hidden temporary's name.
fn named_in(error: crate::Error, tmp: &Path, dir: &Path) -> crate::Error {
    let rename = |path: PathBuf| match path.strip_prefix(tmp) {
        Ok(rest) => dir.join(rest),
        Err(_) => path,
    };
    match error {
        crate::Error::Data(DataError::Write { path, reason }) => DataError::Write {
            path: rename(path),
            reason,
        }
        .into(),
        crate::Error::Data(DataError::Io { path, reason }) => DataError::Io {
            path: rename(path),
            reason,
        }
        .into(),
        crate::Error::Data(DataError::Invalid { path, message }) => DataError::Invalid {
            path: rename(path),
            message,
        }
        .into(),
        other => other,
    }
}

/// The file in an output folder that lists what neurotex wrote there: one line per file,
/// its SHA-256 in hex, two spaces and its path relative to the folder (`sha256sum`'s form,
/// so `sha256sum -c .neurotex-output` checks it by hand).
pub const OUTPUT_RECORD: &str = ".neurotex-output";

/// Checks, before any work, that output folder `dir` can be written by [`replace_dir`]:
/// it is new, empty, or an earlier output that nobody changed since: every file in it is
/// listed in its [`OUTPUT_RECORD`] with the content neurotex wrote.
///
/// # Errors
/// `dir` is not a folder; or it holds a file neurotex did not write there, or one changed
/// since (named).
pub fn check_output_dir(dir: &Path) -> Result<()> {
    let meta = match std::fs::symlink_metadata(dir) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(DataError::write(dir, e).into()),
        Ok(meta) => meta,
    };
    if !meta.is_dir() {
        let what = if meta.file_type().is_symlink() {
            "is a symbolic link, not a folder; give the folder's own path"
        } else {
            "exists and is not a folder"
        };
        return Err(DataError::invalid(dir, what).into());
    }
    let mut files = Vec::new();
    list_files(dir, Path::new(""), &mut files)?;
    if files.is_empty() {
        return Ok(());
    }
    let record = std::fs::read_to_string(dir.join(OUTPUT_RECORD)).unwrap_or_default();
    let written: std::collections::HashMap<&str, &str> = record
        .lines()
        .filter_map(|line| line.split_once("  "))
        .map(|(hash, path)| (path, hash))
        .collect();
    for (path, hash) in &files {
        let refuse = |why: &str| -> Result<()> {
            let message = format!(
                "holds {}, {why}; neurotex replaces a folder only when it holds nothing but \
                 its own earlier output, unchanged: choose a new or empty folder, or move \
                 the file away",
                path.display()
            );
            Err(DataError::invalid(dir, message).into())
        };
        if path == Path::new(OUTPUT_RECORD) {
            continue;
        }
        match path.to_str().and_then(|p| written.get(p)) {
            None => return refuse("which neurotex did not write there"),
            Some(&h) if h != hash => return refuse("which changed since neurotex wrote it"),
            Some(_) => {}
        }
    }
    Ok(())
}

/// One run's claim on an output folder, so that two runs writing the same folder at once
/// do not both report it as theirs: the file `.NAME.lock` beside the folder holds the
/// claiming process's id. It is created only where none exists, and removed when the claim
/// is dropped (or by the signal handler, as a [`Temporary`]). A claim whose process no
/// longer runs (`kill -9`, a power cut; told from `/proc`) is taken over. Claims are per
/// process: a second claim by the same process is granted and holds nothing.
#[derive(Debug)]
#[must_use = "the folder is claimed only while the claim lives"]
pub struct OutputClaim {
    _lock: Option<Temporary>,
}

/// Claims output folder `dir` for this run ([`OutputClaim`]) and checks it as
/// [`check_output_dir`] does. Hold the claim until the folder is written. A folder whose
/// parent does not exist yet is not claimed (nothing can collide in it before it is
/// created).
///
/// # Errors
/// Another running process claims `dir` (its id and the lock file named), the lock file
/// cannot be created, or as [`check_output_dir`].
pub fn claim_output_dir(dir: &Path) -> Result<OutputClaim> {
    let claim = claim_folder(dir)?;
    check_output_dir(dir)?;
    Ok(claim)
}

/// Claims output folder `dir` for this run ([`OutputClaim`]) without checking what it
/// holds: for a folder that must be new or empty ([`create_dir_atomic`] says so), claimed
/// at a command's start so that a second run says so before it does any work. A folder
/// whose parent does not exist yet is not claimed.
///
/// # Errors
/// Another running process claims `dir` (its id and the lock file named), or the lock file
/// cannot be created.
pub fn claim_folder(dir: &Path) -> Result<OutputClaim> {
    let unclaimed = OutputClaim { _lock: None };
    let (Some(name), true) = (dir.file_name(), parent(dir).is_dir()) else {
        return Ok(unclaimed);
    };
    let lock = parent(dir).join(format!(".{}.lock", name.to_string_lossy()));
    let me = std::process::id();
    let runs =
        |pid: u32| !Path::new("/proc/self").exists() || Path::new(&format!("/proc/{pid}")).exists();
    for _ in 0..2 {
        let created = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&lock);
        match created {
            Ok(mut file) => {
                let lock = Temporary::new(lock);
                file.write_all(me.to_string().as_bytes())
                    .map_err(|e| DataError::write(lock.path(), e))?;
                return Ok(OutputClaim { _lock: Some(lock) });
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                let holder = std::fs::read_to_string(&lock)
                    .ok()
                    .and_then(|text| text.trim().parse::<u32>().ok());
                match holder {
                    Some(pid) if pid == me => return Ok(unclaimed),
                    Some(pid) if !runs(pid) => {
                        let _ = std::fs::remove_file(&lock);
                    }
                    _ => {
                        let who = holder.map_or("another run".to_string(), |pid| {
                            format!("another neurotex run (process {pid})")
                        });
                        let message = format!(
                            "{who} is writing this folder; wait for it to finish, or choose \
                             another folder (if no run is active, remove {})",
                            lock.display()
                        );
                        return Err(DataError::invalid(dir, message).into());
                    }
                }
            }
            Err(e) => return Err(DataError::write(&lock, e).into()),
        }
    }
    Err(DataError::invalid(
        dir,
        format!(
            "cannot claim the folder: {} keeps reappearing",
            lock.display()
        ),
    )
    .into())
}

/// Every file under `dir/rel` (depth first, links not followed) with its SHA-256 in hex,
/// as paths relative to `dir`.
fn list_files(dir: &Path, rel: &Path, out: &mut Vec<(PathBuf, String)>) -> Result<()> {
    let here = dir.join(rel);
    let entries = std::fs::read_dir(&here).map_err(|e| DataError::io(&here, e))?;
    for entry in entries {
        let entry = entry.map_err(|e| DataError::io(&here, e))?;
        let path = rel.join(entry.file_name());
        let kind = entry
            .file_type()
            .map_err(|e| DataError::io(entry.path(), e))?;
        if kind.is_dir() {
            list_files(dir, &path, out)?;
        } else if kind.is_file() {
            out.push((path, sha256_file(&entry.path())?));
        } else {
            // a link or a device was never written by neurotex: listed with no hash
            out.push((path, String::new()));
        }
    }
    Ok(())
}

/// The SHA-256 of a file's content, in hex.
fn sha256_file(path: &Path) -> Result<String> {
    use sha2::{Digest, Sha256};
    let mut file = std::fs::File::open(path).map_err(|e| DataError::io(path, e))?;
    let mut hasher = Sha256::new();
    std::io::copy(&mut file, &mut hasher).map_err(|e| DataError::io(path, e))?;
    Ok(hasher
        .finalize()
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect())
}

/// Writes [`OUTPUT_RECORD`] into the finished temporary folder `tmp`.
fn write_record(tmp: &Path, dir: &Path) -> Result<()> {
    let mut files = Vec::new();
    list_files(tmp, Path::new(""), &mut files)?;
    files.sort();
    let text: String = files
        .iter()
        .map(|(path, hash)| format!("{hash}  {}\n", path.display()))
        .collect();
    let path = tmp.join(OUTPUT_RECORD);
    std::fs::write(&path, text).map_err(|e| DataError::write(dir.join(OUTPUT_RECORD), e).into())
}

/// Writes output folder `dir` whole: `fill` writes into a temporary folder beside it, an
/// [`OUTPUT_RECORD`] of what it wrote is added, and the folder takes `dir`'s place. An
/// earlier output there (checked by [`check_output_dir`]: nothing added or changed since)
/// is moved aside first and removed afterwards, so `dir` never mixes two runs' files;
/// between the two renames `dir` is briefly absent. The folder is claimed for the run
/// ([`claim_output_dir`]) unless the caller already holds the claim: a second run writing
/// it at once is refused.
///
/// # Errors
/// As [`claim_output_dir`]; or a folder cannot be created, or `fill` or a rename fails
/// (the earlier output is then put back).
pub fn replace_dir<T>(dir: &Path, fill: impl FnOnce(&Path) -> Result<T>) -> Result<T> {
    let _claim = claim_output_dir(dir)?;
    let name = dir.file_name().unwrap_or_default().to_string_lossy();
    let prefix = format!(".{name}.old-");
    // A run killed between the two renames below left its earlier output aside, and `dir`
    // absent: removed whichever way this run writes `dir`.
    remove_stale(parent(dir), &prefix);
    let is_empty = |d: &Path| std::fs::read_dir(d).is_ok_and(|mut e| e.next().is_none());
    if !dir.exists() || is_empty(dir) {
        return create_dir_atomic(dir, |tmp| {
            let value = fill(tmp)?;
            write_record(tmp, dir)?;
            Ok(value)
        });
    }
    let tmp = Temporary::beside(dir)?;
    std::fs::create_dir(tmp.path()).map_err(|e| DataError::write(dir, e))?;
    let value = fill(tmp.path()).map_err(|e| named_in(e, tmp.path(), dir))?;
    write_record(tmp.path(), dir)?;
    let old = Temporary::new(parent(dir).join(format!("{prefix}{}", std::process::id())));
    std::fs::rename(dir, old.path()).map_err(|e| DataError::write(dir, e))?;
    if let Err(e) = tmp.persist(dir) {
        // Put the earlier output back; `old` is then gone and its removal does nothing.
        let _ = std::fs::rename(old.path(), dir);
        return Err(DataError::write(dir, e).into());
    }
    drop(old);
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
    std::fs::create_dir_all(dir).map_err(|e| DataError::write(dir, e))?;
    Ok(Some(tmp))
}

/// The longest line a text input (a CSV log, an event log, a manifest) may have, in bytes,
/// and the largest `layout.toml`: 64 MiB. A line is held whole while it is parsed, so a
/// file without line breaks (binary data named `.csv`, a link to `/dev/zero`) would
/// otherwise be read into memory until the machine has none; a log of the grid limit's
/// 1 048 576 channels writes lines of about 10 to 20 MB.
pub const MAX_LINE_BYTES: usize = 64 << 20;

/// Opens input `path` for reading, following links: only a regular file. A pipe (FIFO)
/// would block until something writes it, and a device such as `/dev/zero` never ends,
/// so neither is read as a log, recording, manifest or layout.
///
/// # Errors
/// `path` cannot be opened, or is not a regular file.
pub fn open_input(path: &Path) -> Result<std::fs::File> {
    // Checked before opening: opening a FIFO blocks until a writer comes.
    check_input(path)?;
    let file = std::fs::File::open(path).map_err(|e| DataError::io(path, e))?;
    // And on the file opened, in case the name was replaced in between.
    let meta = file.metadata().map_err(|e| DataError::io(path, e))?;
    match meta.is_file() {
        true => Ok(file),
        false => Err(not_regular(path, meta.file_type())),
    }
}

/// Checks that input `path` is a regular file (links followed), before a reader that
/// opens it by name is handed it.
///
/// # Errors
/// `path` does not exist, or is not a regular file.
pub fn check_input(path: &Path) -> Result<()> {
    let meta = std::fs::metadata(path).map_err(|e| DataError::io(path, e))?;
    match meta.is_file() {
        true => Ok(()),
        false => Err(not_regular(path, meta.file_type())),
    }
}

/// Why a file is not read: it is not a regular file.
pub fn not_regular(path: &Path, kind: std::fs::FileType) -> crate::Error {
    let message = format!(
        "is {}, not a regular file: neurotex reads logs, recordings, manifests and layouts \
         only from regular files (a pipe would block until written, a device may never end)",
        kind_name(kind)
    );
    DataError::invalid(path, message).into()
}

/// What a file that is not a regular file is, as messages say it.
pub fn kind_name(kind: std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_fifo() {
            return "a pipe (FIFO)";
        }
        if kind.is_char_device() {
            return "a character device";
        }
        if kind.is_block_device() {
            return "a block device";
        }
        if kind.is_socket() {
            return "a socket";
        }
    }
    match kind.is_dir() {
        true => "a folder",
        false => "not a file",
    }
}

/// Reads text input `path` whole: a regular file of at most [`MAX_LINE_BYTES`] bytes.
///
/// # Errors
/// As [`open_input`]; or the file is larger, or is not UTF-8 text.
pub fn read_text(path: &Path) -> Result<String> {
    use std::io::Read;
    let file = open_input(path)?;
    let mut bytes = Vec::new();
    file.take(MAX_LINE_BYTES as u64 + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| DataError::io(path, e))?;
    if bytes.len() > MAX_LINE_BYTES {
        let message = format!("is longer than {MAX_LINE_BYTES} bytes, the limit on this file");
        return Err(DataError::invalid(path, message).into());
    }
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        DataError::invalid(path, format!("is not UTF-8 text (its byte {at} is not)")).into()
    })
}

/// A reader of a text input that fails once a line grows past [`MAX_LINE_BYTES`] bytes,
/// with a [`LineTooLong`] inside the error (see [`read_error`]).
#[derive(Debug)]
pub struct LineBounded<R> {
    inner: R,
    /// The line being read, 1-based.
    line: u64,
    /// Bytes of it read so far.
    run: usize,
}

/// Opens text input `path` ([`open_input`]) behind a [`LineBounded`] reader.
///
/// # Errors
/// As [`open_input`].
pub fn open_text(path: &Path) -> Result<LineBounded<std::fs::File>> {
    Ok(LineBounded::new(open_input(path)?))
}

impl<R> LineBounded<R> {
    /// `inner`, read from its first line.
    pub fn new(inner: R) -> Self {
        LineBounded {
            inner,
            line: 1,
            run: 0,
        }
    }
}

impl<R: std::io::Read> std::io::Read for LineBounded<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        let mut pieces = buf[..n].split(|&b| b == b'\n').peekable();
        while let Some(piece) = pieces.next() {
            self.run += piece.len();
            if self.run > MAX_LINE_BYTES {
                let line = LineTooLong { line: self.line };
                return Err(std::io::Error::new(std::io::ErrorKind::InvalidData, line));
            }
            if pieces.peek().is_some() {
                self.line += 1;
                self.run = 0;
            }
        }
        Ok(n)
    }
}

/// A line of a text input longer than [`MAX_LINE_BYTES`] bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("line {line} is longer than {MAX_LINE_BYTES} bytes, the limit on one line of a text input (a file without line breaks, or not text, is the usual cause)")]
pub struct LineTooLong {
    /// The line, 1-based.
    pub line: u64,
}

/// The error for reading input `path` failing with `e`: a [`LineTooLong`] names the line
/// (as invalid content), anything else is an I/O error.
pub fn read_error(path: &Path, e: std::io::Error) -> crate::Error {
    match e
        .get_ref()
        .and_then(|inner| inner.downcast_ref::<LineTooLong>())
    {
        Some(long) => DataError::invalid(path, long.to_string()).into(),
        None => DataError::io(path, e).into(),
    }
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
