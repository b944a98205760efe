//! A recipe's sources downloaded into the cache's `downloads/` folder, each by its URL's
//! file name: an interrupted download is kept as `NAME.partial` and resumed from where it
//! stopped (an HTTP range request; a server that ignores it starts the file again). The
//! files are checked afterwards, as a local copy is, by [`super::fetch`]; a file whose
//! checksum does not match is removed, so that the next run downloads it anew.

use std::fs::{File, OpenOptions};
use std::io::{Read, Write};
use std::path::Path;
use std::time::Duration;

use super::recipe::{Recipe, Source};
use crate::error::DataError;
use crate::progress::Progress;
use crate::workflows::OnProgress;
use crate::Result;

/// Bytes per progress step.
const STEP: u64 = 1 << 20;

/// The file name a source is saved as: the last part of its URL's path.
pub fn file_name(source: &Source) -> String {
    let path = source.url.split(['?', '#']).next().unwrap_or_default();
    path.rsplit('/').next().unwrap_or_default().to_string()
}

/// Downloads every source of `recipe` not yet complete in `dir`, resuming partial files.
///
/// # Errors
/// A source that cannot be reached or answers with an error status, or a file that cannot
/// be written: naming the URL.
pub fn download_all(recipe: &Recipe, dir: &Path, on: OnProgress) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| DataError::write(dir, e))?;
    let agent: ureq::Agent = ureq::Agent::config_builder()
        .timeout_connect(Some(Duration::from_secs(30)))
        .timeout_recv_response(Some(Duration::from_secs(60)))
        // A stalled transfer ends (and is resumed by the next run) rather than hanging.
        .timeout_recv_body(Some(Duration::from_secs(30 * 60)))
        .http_status_as_error(false)
        .user_agent(format!("neurotex/{}", env!("CARGO_PKG_VERSION")))
        .build()
        .into();
    for source in &recipe.sources {
        let name = file_name(source);
        if name.is_empty() || name == "." || name == ".." {
            let why = "the URL names no file to save";
            return Err(DataError::invalid(&source.url, why).into());
        }
        let done = dir.join(&name);
        let complete = source.size.is_some_and(|size| {
            std::fs::metadata(&done).is_ok_and(|m| m.is_file() && m.len() == size)
        });
        if complete {
            continue;
        }
        if source.sha256.is_none() {
            // Nothing checks its bytes before they are unpacked: never a part kept from
            // an earlier run, always the whole file anew.
            let partial = dir.join(format!("{name}.partial"));
            for stale in [&done, &partial] {
                plain_or_absent(stale)?;
                if stale.exists() {
                    std::fs::remove_file(stale).map_err(|e| DataError::write(stale, e))?;
                }
            }
        }
        one(&agent, source, &done, on)?;
    }
    Ok(())
}

/// Refuses `path` when it exists and is not a regular file (a link, a device): a download
/// never writes through or renames over one.
fn plain_or_absent(path: &Path) -> Result<()> {
    match std::fs::symlink_metadata(path) {
        Ok(m) if !m.file_type().is_file() => {
            let why = "exists and is not a regular file; a download writes only its own files";
            Err(DataError::invalid(path, why).into())
        }
        _ => Ok(()),
    }
}

/// Downloads `source` into `done` through `done.partial`, resuming it when present.
fn one(agent: &ureq::Agent, source: &Source, done: &Path, on: OnProgress) -> Result<()> {
    let partial = done.with_file_name(format!("{}.partial", file_name(source)));
    plain_or_absent(&partial)?;
    plain_or_absent(done)?;
    let have = std::fs::metadata(&partial).map_or(0, |m| m.len());
    let failed = |why: String| -> crate::Error { DataError::invalid(&source.url, why).into() };
    let mut request = agent.get(&source.url);
    if have > 0 {
        request = request.header("Range", format!("bytes={have}-"));
    }
    let mut response = request
        .call()
        .map_err(|e| failed(format!("cannot download ({e}): without a network, download it elsewhere and give its folder with --from")))?;
    let status = response.status().as_u16();
    // A part is resumed only where the server says it sends the rest from there.
    let from_here = format!("bytes {have}-");
    let resumes = (response.headers().get("content-range"))
        .and_then(|v| v.to_str().ok())
        .is_some_and(|v| v.starts_with(&from_here));
    let resumed = match status {
        206 if have > 0 && resumes => true,
        200 => false,
        // Not the rest from where the part stops (another range, or the part is already
        // whole or longer than the file): the part goes and the file starts again.
        206 | 416 if have > 0 => {
            std::fs::remove_file(&partial).map_err(|e| DataError::write(&partial, e))?;
            return one(agent, source, done, on);
        }
        _ => return Err(failed(format!("the server answered HTTP {status}"))),
    };
    let mut file = match resumed {
        true => OpenOptions::new().append(true).open(&partial),
        false => File::create(&partial),
    }
    .map_err(|e| DataError::write(&partial, e))?;
    let start = if resumed { have } else { 0 };
    let total = response
        .body()
        .content_length()
        .and_then(|n| n.checked_add(start))
        .or(source.size);
    let steps = total.map_or(0, |t| t.div_ceil(STEP)) as usize;
    let what = match resumed {
        true => "downloading, resumed, MiB",
        false => "downloading, MiB",
    };
    on(Progress::Stage(what, steps));
    let mut reader = response.body_mut().as_reader();
    let written =
        copy_body(&mut reader, &mut file, start, on).map_err(|(at, e, reading)| match reading {
            true => failed(format!(
                "the download stopped after {at} bytes ({e}); run again to resume it"
            )),
            false => DataError::write(&partial, e).into(),
        })?;
    file.sync_all().map_err(|e| DataError::write(&partial, e))?;
    if let Some(t) = total.filter(|&t| t != written) {
        let why =
            format!("the download stopped after {written} of {t} bytes; run again to resume it");
        return Err(failed(why));
    }
    if done.exists() {
        std::fs::remove_file(done).map_err(|e| DataError::write(done, e))?;
    }
    std::fs::rename(&partial, done).map_err(|e| DataError::write(done, e))?;
    Ok(())
}

/// Copies the body from `reader` to `file`, which holds `start` bytes already, ticking a
/// step per MiB; the bytes the file holds after. On failure, the bytes written, the error
/// and whether reading (not writing) failed.
fn copy_body(
    reader: &mut impl Read,
    file: &mut File,
    start: u64,
    on: OnProgress,
) -> std::result::Result<u64, (u64, std::io::Error, bool)> {
    let mut buf = vec![0u8; 1 << 16];
    let (mut written, mut ticked) = (start, start / STEP);
    loop {
        let n = reader.read(&mut buf).map_err(|e| (written, e, true))?;
        if n == 0 {
            return Ok(written);
        }
        file.write_all(&buf[..n]).map_err(|e| (written, e, false))?;
        written += n as u64;
        while ticked < written / STEP {
            ticked += 1;
            on(Progress::Tick);
        }
    }
}

/// Removes the downloaded files in `dir` whose checksum does not match their source's, so
/// that the next run downloads them anew; whether any was.
pub fn drop_damaged(recipe: &Recipe, dir: &Path) -> bool {
    let mut removed = false;
    for source in &recipe.sources {
        let file = dir.join(file_name(source));
        // Without a checksum (a repository's archive, checked only once unpacked) a
        // failed fetch cannot vouch for the file either.
        let damaged = match &source.sha256 {
            Some(want) => super::digest::file_digest(&file).is_ok_and(|got| &got != want),
            None => file.is_file(),
        };
        if damaged {
            removed |= std::fs::remove_file(&file).is_ok();
        }
    }
    removed
}
