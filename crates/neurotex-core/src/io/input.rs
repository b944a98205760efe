//! Reading inputs: only regular files, and text a line at a time up to a limit.

use std::path::Path;

use crate::error::{DataError, Result};

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
