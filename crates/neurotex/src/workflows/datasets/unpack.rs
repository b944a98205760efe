//! Archives unpacked into a folder, entry by entry: an entry whose path leaves the folder
//! (`../x`, `/etc/x`: "zip slip") or that is a link is refused, naming the archive and the
//! entry, before anything of it is written, and unpacking stops at the first byte past the
//! archive's budget (a few kilobytes that inflate to terabytes, a "zip bomb"). Written by
//! hand over the `zip` and `tar` crates only for these checks; neither crate refuses links
//! or bounds what it writes on its own.

use std::fs::File;
use std::io::Read;
use std::path::{Component, Path};

use crate::error::DataError;
use crate::Result;

/// An archive's error naming the archive `path` and what is wrong.
fn bad(path: &Path, why: String) -> crate::Error {
    DataError::invalid(path, why).into()
}

/// The most bytes an archive of `archive_bytes` may unpack to when its recipe states no
/// `unpacked-at-most`: a hundred times its size (sensor logs compress to a fifth or a
/// tenth), and never less than 1 GiB.
pub fn default_budget(archive_bytes: u64) -> u64 {
    archive_bytes.saturating_mul(100).max(1 << 30)
}

/// The bytes an archive may still unpack to.
struct Budget<'a> {
    archive: &'a Path,
    limit: u64,
    left: u64,
}

impl Budget<'_> {
    /// Copies `entry` (named `name`) into a new file `out`, at most the bytes left.
    fn copy(&mut self, entry: &mut impl Read, out: &Path, name: &str) -> Result<()> {
        let mut w = File::create_new(out).map_err(|e| DataError::write(out, e))?;
        let written = std::io::copy(&mut entry.take(self.left + 1), &mut w)
            .map_err(|e| bad(self.archive, format!("entry {name}: {e}")))?;
        if written > self.left {
            let why = format!(
                "unpacks to more than {} bytes (at entry {name}); a recipe that expects more \
                 says so with unpacked-at-most",
                self.limit
            );
            return Err(bad(self.archive, why));
        }
        self.left -= written;
        Ok(())
    }
}

/// Unpacks the zip archive `path` into `dest`, writing at most `limit` bytes.
///
/// # Errors
/// The archive cannot be read, an entry leaves the folder or is a link, or the files
/// would pass `limit`.
pub fn unzip(path: &Path, dest: &Path, limit: u64) -> Result<()> {
    let mut budget = Budget {
        archive: path,
        limit,
        left: limit,
    };
    let file = File::open(path).map_err(|reason| DataError::Io {
        path: path.to_path_buf(),
        reason,
    })?;
    let mut archive =
        zip::ZipArchive::new(file).map_err(|e| bad(path, format!("not a zip archive: {e}")))?;
    for i in 0..archive.len() {
        let mut entry = archive
            .by_index(i)
            .map_err(|e| bad(path, format!("entry {i}: {e}")))?;
        let name = entry
            .name()
            .map_err(|e| bad(path, format!("entry {i}'s name: {e}")))?
            .into_owned();
        let raw = Path::new(&name);
        let inside = stays_inside(raw) && !name.starts_with(['/', '\\']);
        let Some(rel) = entry.enclosed_name().filter(|p| inside && stays_inside(p)) else {
            return Err(bad(
                path,
                format!("entry {name} would be written outside its folder"),
            ));
        };
        if entry.is_symlink() {
            return Err(bad(path, format!("entry {name} is a link")));
        }
        let out = dest.join(rel);
        if entry.is_dir() {
            std::fs::create_dir_all(&out).map_err(|e| DataError::write(&out, e))?;
            continue;
        }
        if let Some(parent) = out.parent() {
            std::fs::create_dir_all(parent).map_err(|e| DataError::write(parent, e))?;
        }
        budget.copy(&mut entry, &out, &name)?;
    }
    Ok(())
}

/// Unpacks the gzip-compressed tar archive `path` into `dest`, writing at most `limit`
/// bytes.
///
/// # Errors
/// The archive cannot be read, an entry leaves the folder or is a link or a device, or
/// the files would pass `limit`.
pub fn untar_gz(path: &Path, dest: &Path, limit: u64) -> Result<()> {
    let mut budget = Budget {
        archive: path,
        limit,
        left: limit,
    };
    let file = File::open(path).map_err(|reason| DataError::Io {
        path: path.to_path_buf(),
        reason,
    })?;
    let mut archive = tar::Archive::new(flate2::read::GzDecoder::new(file));
    let entries = archive
        .entries()
        .map_err(|e| bad(path, format!("not a tar.gz archive: {e}")))?;
    for entry in entries {
        let mut entry = entry.map_err(|e| bad(path, format!("not a tar.gz archive: {e}")))?;
        let rel = entry
            .path()
            .map_err(|e| bad(path, format!("an entry's name: {e}")))?
            .into_owned();
        let name = rel.display().to_string();
        if !stays_inside(&rel) {
            return Err(bad(
                path,
                format!("entry {name} would be written outside its folder"),
            ));
        }
        let out = dest.join(&rel);
        let kind = entry.header().entry_type();
        if kind.is_dir() {
            std::fs::create_dir_all(&out).map_err(|e| DataError::write(&out, e))?;
        } else if kind.is_file() {
            if let Some(parent) = out.parent() {
                std::fs::create_dir_all(parent).map_err(|e| DataError::write(parent, e))?;
            }
            budget.copy(&mut entry, &out, &name)?;
        } else if !matches!(
            kind,
            tar::EntryType::XGlobalHeader | tar::EntryType::XHeader
        ) {
            return Err(bad(
                path,
                format!("entry {name} is a link or a special file"),
            ));
        }
    }
    Ok(())
}

/// Whether `path` is relative and stays inside its folder (no `..`, no root).
fn stays_inside(path: &Path) -> bool {
    path.components()
        .all(|c| matches!(c, Component::Normal(_) | Component::CurDir))
}
