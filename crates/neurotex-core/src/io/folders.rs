//! Folders written whole: filled under a temporary name and renamed into place, and an output
//! folder claimed only when neurotex wrote it (its record of the files it holds).

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::error::{DataError, Result};

use super::files::remove_stale;
use super::{parent, Temporary};

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
pub(super) fn write_record(tmp: &Path, dir: &Path) -> Result<()> {
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
