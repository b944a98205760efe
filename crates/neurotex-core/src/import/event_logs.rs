//! Importing raw address-event logs: each sorted by time stably and written as an event
//! recording, with the layout of its grid and polarity.

use std::path::{Path, PathBuf};

use crate::error::{DataError, Result};

use super::name_pattern::{meta_from_name, NamePattern};
use super::{files_with, Found};

/// What `import events` did with one file.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportedFile {
    /// The file written into the dataset.
    pub file: String,
    /// Events imported.
    pub events: usize,
    /// Events that came before an earlier line's time and were moved into time order.
    pub reordered: usize,
    /// Events that share a millisecond with another of their cell and polarity.
    pub merged: usize,
    /// The recording's span from its start (by the origin) to its last event, s.
    pub span_s: f64,
    /// Its first event's time from its start, s (0 with `--origin first`).
    pub first_s: f64,
    /// Whether the log has a polarity column.
    pub polarity: bool,
}

/// Options of [`import_events`].
#[derive(Debug, Clone)]
pub struct EventImportParams {
    /// Metadata from file names; without it the label is the file stem.
    pub pattern: Option<NamePattern>,
    /// How the logs are read.
    pub format: crate::events::EventsFormat,
    /// The sensor's grid (and, for a taxel column, each taxel's cell).
    pub grid: crate::events::EventGrid,
    /// The polarity column was named (or its values given): a log without it is an error,
    /// not ON events only.
    pub require_polarity: bool,
}

/// The `.csv` and `.npy` files among `inputs` (folders are searched one level deep),
/// sorted, and those a folder holds that are not regular files, left out.
///
/// # Errors
/// As [`find_csv`].
pub fn event_files(inputs: &[PathBuf]) -> Result<Found> {
    files_with(inputs, &["csv", "npy"])
}

/// Imports event logs into a new dataset folder `out`: each file's events sorted into time
/// order (a stable sort: events of one time keep their order) and checked as a dataset's
/// reader checks them, written as `<stem>.csv` with columns `t,x,y,p` (times and
/// polarities as the log wrote them, taxel indices turned into x and y); a manifest from
/// the file names; `layout.toml` with the grid and the `[events]` table. Files are read in
/// parallel; `on_done` is called once per file.
///
/// Sorting rather than refusing: a logger that writes events from several buffers
/// interleaves them a little, and the order carries no information a stable sort loses. A
/// dataset's reader, in contrast, refuses events out of order, so a dataset is always in
/// the order every command reads.
///
/// # Errors
/// A file that cannot be read or breaks a rule (named with its line), two files of one
/// stem, or `out` not empty.
pub fn import_events(
    files: &[std::path::PathBuf],
    p: &EventImportParams,
    out: &Path,
    on_done: &(dyn Fn() + Sync),
) -> Result<Vec<ImportedFile>> {
    use rayon::prelude::*;
    if files.is_empty() {
        return Err(DataError::invalid(out, "no .csv or .npy event files to import").into());
    }
    let mut stems = std::collections::BTreeMap::new();
    for f in files {
        let stem = f.file_stem().map(|s| s.to_string_lossy().into_owned());
        if let Some(first) = stems.insert(stem.clone(), f) {
            let why = format!(
                "`{}` and `{}` would both be {}.csv in the dataset; rename one",
                first.display(),
                f.display(),
                stem.unwrap_or_default()
            );
            return Err(DataError::invalid(f, why).into());
        }
    }
    crate::recording::create_dataset_dir(out, |dir| {
        // Each log is written as soon as it is read: an import holds one log per thread.
        let read: Vec<(crate::recording::Meta, ImportedFile)> = files
            .par_iter()
            .map(|f| {
                let meta = meta_from_name(f, p.pattern.as_ref())?;
                let (text, summary) = sorted_log(f, p)?;
                let path = dir.join(&summary.file);
                std::fs::write(&path, text).map_err(|e| DataError::write(&path, e))?;
                on_done();
                let meta = crate::recording::Meta {
                    file: summary.file.clone(),
                    ..meta
                };
                Ok((meta, summary))
            })
            .collect::<Result<_>>()?;
        // `read` is in the order of `files`.
        let with = read.iter().zip(files).find(|(r, _)| r.1.polarity);
        let without = read.iter().zip(files).find(|(r, _)| !r.1.polarity);
        if let (Some((_, with)), Some((_, without))) = (with, without) {
            let why = format!(
                "has no polarity column `{}`, which {} has: its OFF events would be read as ON",
                p.format.polarity,
                with.display()
            );
            return Err(DataError::invalid(without, why).into());
        }
        let (metas, summaries): (Vec<_>, Vec<_>) = read.into_iter().unzip();
        crate::recording::write_manifest(dir, &metas)?;
        crate::recording::write_layout(dir, &imported_layout(p))?;
        crate::recording::Dataset::open(dir)?;
        Ok(summaries)
    })
}

/// The layout an import writes: the grid, its mask, the columns it writes, and for logs
/// addressed by taxel index the channel map (a stream of the same sensor's taxel indices
/// reads it, `neurotex stream --taxel`).
fn imported_layout(p: &EventImportParams) -> crate::recording::LayoutFile {
    let g = &p.grid;
    let masked = g.present.iter().any(|&x| !x);
    crate::recording::LayoutFile {
        rows: Some(g.rows),
        cols: Some(g.cols),
        mask: masked.then(|| {
            g.present
                .chunks(g.cols)
                .map(|row| row.iter().map(|&x| if x { '1' } else { '0' }).collect())
                .collect()
        }),
        channel_map: p.format.taxel.as_ref().map(|_| {
            g.taxels
                .iter()
                .map(|&cell| [cell / g.cols, cell % g.cols])
                .collect()
        }),
        events: Some(crate::events::EventsFormat {
            values: p.format.values,
            origin: p.format.origin,
            ..crate::events::EventsFormat::new(p.format.time_unit)
        }),
        ..Default::default()
    }
}

/// Column names that say an event's polarity, refused when left unread.
pub(super) const POLARITY_NAMES: [&str; 9] = [
    "p",
    "pol",
    "polarity",
    "sign",
    "on",
    "onoff",
    "on_off",
    "parity",
    "ev_polarity",
];

/// An event as parsed: time, cell fields, polarity, and its line or record.
type RawEvent = (crate::events::Stamp, (i64, i64), Option<i64>, usize);

/// Checks that a log's polarity is read when it has one: the column named (or its values
/// given) is there, and no unread column is named like a polarity, which would leave
/// every OFF event ON, silently.
fn polarity_read(
    p: &EventImportParams,
    polarity: bool,
    unread: &[String],
) -> std::result::Result<(), String> {
    if p.require_polarity && !polarity {
        return Err(format!(
            "no polarity column `{}`, which --polarity or --polarity-values asks for",
            p.format.polarity
        ));
    }
    let polarity_like = |name: &str| POLARITY_NAMES.contains(&name.to_ascii_lowercase().as_str());
    match unread.iter().find(|n| !polarity && polarity_like(n)) {
        Some(name) => Err(format!(
            "column `{name}` is not read, and its name says polarity: name it with --polarity {name} (and --polarity-values ON,OFF unless they are 1,0), or the log's OFF events would be read as ON"
        )),
        None => Ok(()),
    }
}

/// Sorts `events` into time order, stably (events of one time keep the log's order); the
/// events that came before an earlier line's time.
fn sort_stably(events: &mut [RawEvent]) -> usize {
    let key = |t: &crate::events::Stamp| crate::events::as_f64(*t);
    let mut reordered = 0;
    let mut latest = f64::NEG_INFINITY;
    for (t, ..) in events.iter() {
        let v = key(t);
        if v < latest {
            reordered += 1;
        }
        latest = latest.max(v);
    }
    if reordered > 0 {
        events.sort_by(|a, b| match (a.0, b.0) {
            (crate::events::Stamp::Int(x), crate::events::Stamp::Int(y)) => x.cmp(&y),
            (x, y) => key(&x).total_cmp(&key(&y)),
        });
    }
    reordered
}

/// One log's events in time order as the CSV text an import writes, and what was done.
fn sorted_log(path: &Path, p: &EventImportParams) -> Result<(String, ImportedFile)> {
    let mut events: Vec<RawEvent> = Vec::new();
    let mut polarity = false;
    let mut unread = Vec::new();
    crate::events::parse(path, &p.format, &mut |event| {
        match event {
            crate::events::Parsed::Columns {
                polarity: has,
                unread: other,
            } => (polarity, unread) = (has, other),
            crate::events::Parsed::Event { t, cell, p, at } => events.push((t, cell, p, at)),
        }
        Ok(())
    })?;
    let bad = |why: String| -> crate::Error { DataError::invalid(path, why).into() };
    polarity_read(p, polarity, &unread).map_err(bad)?;
    if events.is_empty() {
        return Err(bad(
            "holds no events (a header only, or an empty array)".into()
        ));
    }
    let reordered = sort_stably(&mut events);
    let max_steps = (crate::recording::DEFAULT_MAX_DURATION_S * 1000.0) as u64;
    let mut gather = crate::events::Gather::new(&p.format, &p.grid, polarity, None, max_steps);
    let name = format!(
        "{}.csv",
        path.file_stem()
            .map_or(String::new(), |s| s.to_string_lossy().into_owned())
    );
    let mut text = String::from(if polarity { "t,x,y,p\n" } else { "t,x,y\n" });
    for &(t, cell, pol, at) in &events {
        let named = |m: String| -> crate::Error {
            DataError::invalid(path, format!("{}: {m}", crate::events::place(path, at))).into()
        };
        gather.push(t, cell, pol).map_err(named)?;
        let c = gather.cell(cell).map_err(named)?;
        use std::fmt::Write as _;
        let _ = write!(
            text,
            "{},{},{}",
            crate::events::show(t),
            c % p.grid.cols,
            c / p.grid.cols
        );
        let _ = match pol {
            Some(v) => writeln!(text, ",{v}"),
            None => writeln!(text),
        };
    }
    let done = gather.finish();
    Ok((
        text,
        ImportedFile {
            file: name,
            events: done.count,
            reordered,
            merged: done.merged,
            span_s: done.n_steps as f64 / 1000.0,
            first_s: done
                .on
                .iter()
                .chain(done.off.iter().flatten())
                .filter_map(|train| train.first())
                .min()
                .map_or(0.0, |&step| f64::from(step) / 1000.0),
            polarity,
        },
    ))
}
