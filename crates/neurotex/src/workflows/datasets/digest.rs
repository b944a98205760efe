//! Checksums of files and folders: a file's SHA-256, and a folder's tree digest.

use std::fs::File;
use std::io::Read;
use std::path::Path;

use sha2::{Digest, Sha256};

use super::recipe::hex;
use crate::error::DataError;
use crate::Result;

/// The SHA-256 of `path`'s content, in hex.
pub fn file_digest(path: &Path) -> Result<String> {
    let io = |reason| DataError::Io {
        path: path.to_path_buf(),
        reason,
    };
    let mut file = File::open(path).map_err(io)?;
    let mut hasher = Sha256::new();
    let mut buf = vec![0u8; 1 << 16];
    loop {
        let n = file.read(&mut buf).map_err(io)?;
        if n == 0 {
            break;
        }
        hasher.update(&buf[..n]);
    }
    Ok(hex(&hasher.finalize()))
}

/// The tree digest of folder `dir`: the SHA-256 of `sha256sum`'s lines (`HASH  PATH`) for
/// every regular file under it, paths relative to `dir` with `/`, sorted bytewise; the
/// same as `(cd DIR && find . -type f | sed 's|^\./||' | LC_ALL=C sort | xargs -d '\n'
/// sha256sum) | sha256sum`.
///
/// # Errors
/// A file cannot be read, or the folder holds a link (a tree is plain files and folders).
pub fn tree_digest(dir: &Path) -> Result<String> {
    let mut paths = Vec::new();
    walk(dir, "", &mut paths)?;
    if paths.is_empty() {
        let why = "no files: a tree digest is of a folder's files";
        return Err(DataError::invalid(dir, why).into());
    }
    paths.sort();
    let mut lines = String::new();
    for rel in &paths {
        lines.push_str(&format!("{}  {rel}\n", file_digest(&dir.join(rel))?));
    }
    Ok(hex(&Sha256::digest(lines.as_bytes())))
}

/// Collects the relative paths of the regular files under `dir/rel`.
fn walk(dir: &Path, rel: &str, out: &mut Vec<String>) -> Result<()> {
    let here = dir.join(rel);
    let io = |reason| DataError::Io {
        path: here.clone(),
        reason,
    };
    for item in std::fs::read_dir(&here).map_err(io)? {
        let item = item.map_err(io)?;
        let name = item.file_name().to_string_lossy().into_owned();
        let path = if rel.is_empty() {
            name
        } else {
            format!("{rel}/{name}")
        };
        let kind = item.file_type().map_err(io)?;
        if kind.is_dir() {
            walk(dir, &path, out)?;
        } else if kind.is_file() {
            out.push(path);
        } else {
            let why = "a link or special file: a dataset's tree holds plain files and folders";
            return Err(DataError::invalid(dir.join(&path), why).into());
        }
    }
    Ok(())
}

/// Copies the plain files and folders under `from` into `to`.
pub(super) fn copy_tree(from: &Path, to: &Path) -> Result<()> {
    let mut paths = Vec::new();
    walk(from, "", &mut paths)?;
    for rel in paths {
        let dest = to.join(&rel);
        if let Some(parent) = dest.parent() {
            std::fs::create_dir_all(parent).map_err(|e| DataError::write(parent, e))?;
        }
        std::fs::copy(from.join(&rel), &dest).map_err(|e| DataError::write(&dest, e))?;
    }
    Ok(())
}
