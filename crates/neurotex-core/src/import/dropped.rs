//! `--drop-channels`: channels placed on the grid and then left out, their cells masked,
//! so that a dead taxel of a full grid needs no hand-written channel map.

use std::path::{Path, PathBuf};

use super::csv_logs::{parse_csv, CsvImportParams};
use crate::csvlog::{header_names, ChannelSelect, CsvLog};
use crate::error::{ParamError, Result};
use crate::recording::ChannelMap;
use crate::values::{Cell, Grid};

impl CsvImportParams {
    /// These options with `drop_channels` resolved on the first of `files` that reads:
    /// every channel is placed on the grid (row-major or by the channel map), the dropped
    /// ones are left out of the channel list and of the map, so their cells are masked.
    /// Without `drop_channels`, a copy of these options. Also returns the names of the
    /// channels dropped.
    ///
    /// # Errors
    /// No file reads; a dropped channel that is not a channel; every channel dropped; a
    /// grid without a cell for every channel.
    pub fn without_dropped(&self, files: &[PathBuf]) -> Result<(CsvImportParams, Vec<String>)> {
        let Some(select) = &self.drop_channels else {
            return Ok((self.clone(), Vec::new()));
        };
        let all = CsvImportParams {
            drop_channels: None,
            ..self.clone()
        };
        let mut first_error = None;
        for f in files {
            match parse_csv(f, &all) {
                Ok(parsed) => return all.dropping(f, select, &parsed.log),
                Err(e) => {
                    first_error.get_or_insert(e);
                }
            }
        }
        Err(first_error.unwrap_or_else(|| {
            crate::error::DataError::invalid(Path::new("."), "no .csv files to read").into()
        }))
    }

    /// These options (no drop) reading `log`'s channels but those `select` names.
    fn dropping(
        &self,
        file: &Path,
        select: &ChannelSelect,
        log: &CsvLog,
    ) -> Result<(CsvImportParams, Vec<String>)> {
        let names = &log.channel_names;
        let columns = log
            .columns
            .channels
            .clone()
            .unwrap_or_else(|| names.clone());
        let dropped = dropped_flags(file, select, &self.format, log, &columns)?;
        let n = names.len();
        if dropped.iter().all(|&d| d) {
            let rule = "leave at least one channel";
            let got = format!("all {n} channels");
            return Err(ParamError::new("drop-channels", rule, got).into());
        }
        let grid = match &self.grid {
            Some(g) => g.clone(),
            None => Grid::full(1, n)?,
        };
        let cells: Vec<Cell> = match &self.channel_map {
            Some(map) if map.cells().len() != n => {
                let rule = "the map needs one cell per channel, dropped ones included";
                let got = format!("{} cells for {n} channels", map.cells().len());
                return Err(ParamError::new("channel-map", rule, got).into());
            }
            Some(map) => map.cells().to_vec(),
            None if grid.cells() < n => {
                let rule = "the grid must have a cell for every channel, dropped ones included (their cells are masked)";
                let got = format!("{grid} for {n} channels");
                return Err(ParamError::new("grid", rule, got).into());
            }
            None => (0..n)
                .map(|k| Cell {
                    row: k / grid.cols(),
                    col: k % grid.cols(),
                })
                .collect(),
        };
        let keep = |k: &usize| !dropped[*k];
        let kept_columns: Vec<String> = (0..n).filter(keep).map(|k| columns[k].clone()).collect();
        let channels = match self.format.header {
            true => ChannelSelect::Names(kept_columns),
            false => {
                ChannelSelect::Indices(kept_columns.iter().filter_map(|c| c.parse().ok()).collect())
            }
        };
        let gone = (0..n).filter(|&k| dropped[k]).map(|k| names[k].clone());
        let gone: Vec<String> = gone.collect();
        let mut out = self.clone();
        out.format.channels = channels;
        out.grid = Some(grid);
        out.channel_map = Some(ChannelMap::new(
            (0..n).filter(keep).map(|k| cells[k]).collect(),
        ));
        Ok((out, gone))
    }
}

/// Which of `log`'s channels `select` names: by name, by 0-based column index (as
/// `--channels` counts them), or by a regular expression over the names.
fn dropped_flags(
    file: &Path,
    select: &ChannelSelect,
    format: &crate::csvlog::CsvFormat,
    log: &CsvLog,
    columns: &[String],
) -> Result<Vec<bool>> {
    let names = &log.channel_names;
    let mut dropped = vec![false; names.len()];
    let not_a_channel = |what: String| -> crate::Error {
        let rule = "name channels of the log (not its time column)";
        let got = format!(
            "{what}; the channels are {}",
            crate::csvlog::excerpt(&names.join(", "))
        );
        ParamError::new("drop-channels", rule, got).into()
    };
    match select {
        ChannelSelect::All => return Ok(vec![true; names.len()]),
        ChannelSelect::Names(list) => {
            for name in list {
                let k = names.iter().position(|c| c == name);
                dropped[k.ok_or_else(|| {
                    not_a_channel(format!("`{}`", crate::csvlog::excerpt(name)))
                })?] = true;
            }
        }
        ChannelSelect::Indices(list) => {
            let header = header_names(file, format);
            for &i in list {
                let column = match (&header, format.header) {
                    (Some(h), true) => h.get(i).cloned(),
                    (_, true) => None,
                    (_, false) => Some(i.to_string()),
                };
                let k = column.and_then(|c| columns.iter().position(|x| *x == c));
                dropped[k.ok_or_else(|| not_a_channel(format!("column {i}")))?] = true;
            }
        }
        ChannelSelect::Regex(re) => {
            for (k, name) in names.iter().enumerate() {
                dropped[k] |= re.is_match(name);
            }
            if !dropped.contains(&true) {
                return Err(not_a_channel(format!("no channel matches `{re}`")));
            }
        }
    }
    Ok(dropped)
}
