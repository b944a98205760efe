//! The layout file (`layout.toml`): a dataset's grid, channel map, sampling, time unit and
//! limits, and the layout a recording of a given shape gets from it.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::csvlog::{CsvFormat, CsvOverrides, Delimiter, DuplicateStamps, LogColumns};
use crate::error::{DataError, ParamError, Result};
use crate::values::{SampleRate, TimeUnit, FS_RULE};

use super::{Baseline, Layout, Shape};

/// `layout.toml`: how to read a dataset's recordings.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LayoutFile {
    /// Sampling rate in Hz (default 1000).
    pub fs: Option<f64>,
    /// Grid rows.
    pub rows: Option<usize>,
    /// Grid columns.
    pub cols: Option<usize>,
    /// For each file channel, `[row, col]`.
    pub channel_map: Option<Vec<[usize; 2]>>,
    /// One string per row, `1` for a taxel and `0` for a masked cell, e.g. `["1111", "1001"]`.
    pub mask: Option<Vec<String>>,
    /// Baseline removal.
    pub baseline: Option<Baseline>,
    /// CSV recordings: the time column's name.
    pub time_column: Option<String>,
    /// CSV recordings: the time column's unit, `ms` or `s`.
    pub time_unit: Option<TimeUnit>,
    /// CSV recordings: the channel columns, in channel order (default: every other column).
    /// Without a header row, the time column and the channels are 0-based indices (`"0"`).
    pub channels: Option<Vec<String>>,
    /// CSV recordings: the longest gap between time stamps resampling may fill, in s
    /// (default [`crate::csvlog::DEFAULT_MAX_GAP_S`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_gap_s: Option<f64>,
    /// Longest recording accepted, in s (default [`DEFAULT_MAX_DURATION_S`]); resampling
    /// allocates one frame per millisecond of it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_duration_s: Option<f64>,
    /// CSV recordings: whether the first row names the columns (default `true`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub header: Option<bool>,
    /// CSV recordings: the field delimiter, `,` `;` or `tab` (default: detected).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub delimiter: Option<Delimiter>,
    /// CSV recordings: rows sharing a time stamp (default `average`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub duplicate_stamps: Option<DuplicateStamps>,
    /// How the raw logs an imported dataset came from were read (`import csv` writes it):
    /// a CSV file outside the dataset whose columns are not the dataset's is read this
    /// way, so a raw log of the same logger needs no options.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source: Option<LogColumns>,
    /// The recordings are address events, not samples: how to read them
    /// ([`crate::events`]). Needs `rows` and `cols`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub events: Option<crate::events::EventsFormat>,
}

/// The longest recording accepted unless `layout.toml` sets `max_duration_s`: one hour.
/// Resampling to the encoder's 1 kHz allocates one frame per millisecond of a recording's
/// time span, so the span, not the file's size, sets the memory: an hour of a 4x4 grid is
/// 3.6 million frames, 460 MB of f64 samples, about what a laptop can spare per worker.
/// The paper's slides last seconds; a span of days is a wrong time unit or sampling rate.
pub const DEFAULT_MAX_DURATION_S: f64 = 3600.0;

impl LayoutFile {
    /// Which of the grid's `cells` hold a taxel, row-major: the mask's `1`s, or all.
    fn present(&self, cells: usize) -> Vec<bool> {
        match &self.mask {
            Some(m) => m
                .iter()
                .flat_map(|row| row.chars().map(|ch| ch == '1'))
                .collect(),
            None => vec![true; cells],
        }
    }

    /// How events address the cells of a `rows x cols` grid: the mask's cells, and each
    /// taxel index's cell (the channel map's, or row-major order without one).
    pub fn event_grid(&self, rows: usize, cols: usize) -> crate::events::EventGrid {
        let present = self.present(rows * cols);
        let taxels = match &self.channel_map {
            Some(map) => map.iter().map(|&[r, c]| r * cols + c).collect(),
            None => (0..rows * cols).collect(),
        };
        crate::events::EventGrid {
            rows,
            cols,
            present,
            taxels,
        }
    }

    /// Reads and checks `layout.toml`.
    ///
    /// # Errors
    /// The file is unreadable, not TOML of this form, or inconsistent.
    pub fn read(path: &Path) -> Result<Self> {
        let text = crate::io::read_text(path)?;
        let file: LayoutFile = toml::from_str(&text).map_err(|e| {
            let why = crate::words::toml_error(&text, &e);
            DataError::invalid(path, format!("not a valid layout file: {why}"))
        })?;
        file.check(path)?;
        Ok(file)
    }

    /// How this layout's CSV recordings are laid out: `time_column` and `channels` are
    /// names with a header row and 0-based indices without one; with a header and no
    /// `time_column`, a column named `t_ms` or `time_ms` (ms), or `t_s` or `time_s` (s), is
    /// the time column.
    ///
    /// # Errors
    /// Without a header row, a time column or channel that is not an index.
    pub fn csv_format(&self) -> Result<CsvFormat, ParamError> {
        self.own_columns().csv_format(self.max_gap_s)
    }

    /// The formats a CSV file read with this layout may be in, by preference: the layout's
    /// own (its dataset's files), then its `[source]` (the raw logs they were imported
    /// from), each with `overrides` applied; only the overridden own format when the
    /// overrides say where the columns are.
    ///
    /// # Errors
    /// As [`LayoutFile::csv_format`].
    pub fn csv_formats(&self, overrides: &CsvOverrides) -> Result<Vec<CsvFormat>, ParamError> {
        let mut formats = vec![overrides.apply(self.csv_format()?)];
        if let Some(source) = self.source.as_ref().filter(|_| !overrides.place_columns()) {
            formats.push(overrides.apply(source.csv_format(self.max_gap_s)?));
        }
        Ok(formats)
    }

    /// The layout's own CSV fields.
    fn own_columns(&self) -> LogColumns {
        LogColumns {
            header: self.header,
            delimiter: self.delimiter,
            time_column: self.time_column.clone(),
            time_unit: self.time_unit,
            channels: self.channels.clone(),
            duplicate_stamps: self.duplicate_stamps,
        }
    }

    /// Checks every field against the rules the importers apply to the same values, so a
    /// layout written by hand is refused where an import's options would have been (a
    /// layout kept in a model file is checked when the model is read), naming `path` in the
    /// error.
    ///
    /// # Errors
    /// The first rule broken.
    pub fn check(&self, path: &Path) -> Result<()> {
        let bad = |m: String| -> Result<()> { Err(DataError::invalid(path, m).into()) };
        if let Err(e) = self.csv_formats(&CsvOverrides::default()) {
            return bad(e.to_string());
        }
        if let Some(fs) = self.fs.filter(|&fs| SampleRate::new(fs).is_err()) {
            return bad(format!("field `fs`: {FS_RULE}, got {fs}"));
        }
        let positive = [
            ("max_gap_s", self.max_gap_s, "s"),
            ("max_duration_s", self.max_duration_s, "s"),
        ];
        for (field, value, unit) in positive {
            if let Some(v) = value.filter(|v| !(v.is_finite() && *v > 0.0)) {
                return bad(format!(
                    "field `{field}` must be a positive number of {unit}, got {v}"
                ));
            }
        }
        if self.rows.is_some() != self.cols.is_some() {
            return bad("fields `rows` and `cols` must be given together".into());
        }
        if let (Some(r), Some(c)) = (self.rows, self.cols) {
            self.check_grid(r, c).or_else(bad)?;
        } else if self.channel_map.is_some() || self.mask.is_some() {
            return bad("fields `channel_map` and `mask` need `rows` and `cols`".into());
        }
        if let Some(channels) = &self.channels {
            // A column named twice would be read twice, as two taxels of one signal.
            let mut seen = std::collections::HashMap::new();
            for (j, name) in channels.iter().enumerate() {
                if let Some(i) = seen.insert(name.as_str(), j) {
                    return bad(format!(
                        "field `channels` names `{}` twice (entries {} and {}): each channel is a column of its own",
                        crate::csvlog::excerpt(name),
                        i + 1,
                        j + 1
                    ));
                }
            }
        }
        if let Some(events) = &self.events {
            if self.rows.is_none() {
                return bad("an [events] table needs the grid: give `rows` and `cols`".into());
            }
            let [on, off] = events.values;
            if on == off {
                return bad(format!("[events] `values`: the ON and OFF polarity values must be two different integers, got [{on}, {off}]"));
            }
        }
        if let Some(Baseline::Mean { start_s, end_s }) = self.baseline {
            if !(start_s.is_finite() && end_s.is_finite() && start_s >= 0.0 && end_s > start_s) {
                return bad(format!(
                    "field `baseline`: mean interval must satisfy 0 <= start_s < end_s, got [{start_s}, {end_s}]"
                ));
            }
        }
        Ok(())
    }

    /// The grid's fields on a `r x c` grid: its size, the mask (its shape, at least one
    /// taxel), and the channel map (one cell per channel, each on the grid, none twice,
    /// none masked, as many as `channels`); `Err` says which rule is broken.
    fn check_grid(&self, r: usize, c: usize) -> std::result::Result<(), String> {
        if r == 0 || c == 0 {
            return Err(format!("grid must be at least 1x1, got {r}x{c}"));
        }
        crate::values::check_grid_cells(r, c)
            .map_err(|e| format!("fields `rows` and `cols`: {e}"))?;
        if let Some(mask) = &self.mask {
            if mask.len() != r || mask.iter().any(|row| row.chars().count() != c) {
                return Err(format!(
                    "field `mask` must have {r} strings of {c} characters"
                ));
            }
            if mask
                .iter()
                .any(|row| row.chars().any(|ch| ch != '0' && ch != '1'))
            {
                return Err("field `mask` may hold only `0` and `1`".into());
            }
            if mask.iter().all(|row| !row.contains('1')) {
                return Err("field `mask` must leave at least one taxel (a `1`)".into());
            }
        }
        let present = self.present(r * c);
        let channels = self.channels.as_ref().map(Vec::len);
        let Some(map) = &self.channel_map else {
            let taxels = present.iter().filter(|&&p| p).count();
            return match channels.filter(|&n| n != taxels) {
                Some(n) => Err(format!("field `channels` names {n} channels, but the {r}x{c} grid has {taxels} taxel cells and no `channel_map` places them")),
                None => Ok(()),
            };
        };
        if let Some(n) = channels.filter(|&n| n != map.len()) {
            return Err(format!("field `channel_map` has {} cells for the {n} channels of `channels`: the map needs one cell per channel", map.len()));
        }
        let mut seen = vec![false; r * c];
        for (ch, &[mr, mc]) in map.iter().enumerate() {
            if mr >= r || mc >= c {
                return Err(format!(
                    "field `channel_map`: channel {ch} maps to [{mr}, {mc}], outside the {r}x{c} grid"
                ));
            }
            if std::mem::replace(&mut seen[mr * c + mc], true) {
                return Err(format!(
                    "field `channel_map`: cell [{mr}, {mc}] is given twice"
                ));
            }
            if !present[mr * c + mc] {
                return Err(format!("field `channel_map`: channel {ch} maps to [{mr}, {mc}], a cell the mask marks empty"));
            }
        }
        Ok(())
    }

    /// The layout for a recording with `channels` channels (or a `rows x cols` array).
    pub(super) fn layout_for(&self, path: &Path, shape: Shape) -> Result<Layout> {
        let (rows, cols) = match (self.rows, self.cols, shape) {
            (Some(r), Some(c), _) => (r, c),
            (_, _, Shape::Grid(r, c)) => (r, c),
            (_, _, Shape::Channels(n)) => (1, n),
        };
        let present = self.present(rows * cols);
        let n_channels = match shape {
            Shape::Grid(r, c) => {
                if (r, c) != (rows, cols) {
                    return Err(DataError::invalid(
                        path,
                        format!("recording is a {r}x{c} grid but layout.toml says {rows}x{cols}"),
                    )
                    .into());
                }
                r * c
            }
            Shape::Channels(n) => n,
        };
        let channel_map: Vec<usize> = match (&self.channel_map, shape) {
            (Some(map), _) => map.iter().map(|&[r, c]| r * cols + c).collect(),
            (None, Shape::Grid(..)) => (0..rows * cols).collect(),
            (None, Shape::Channels(n)) => {
                let taxels: Vec<usize> = (0..rows * cols).filter(|&i| present[i]).collect();
                if taxels.len() != n {
                    return Err(DataError::invalid(
                        path,
                        format!(
                            "recording has {n} channels but the {rows}x{cols} layout has {} taxel cells",
                            taxels.len()
                        ),
                    )
                    .into());
                }
                taxels
            }
        };
        if channel_map.len() != n_channels {
            return Err(DataError::invalid(
                path,
                format!(
                    "recording has {n_channels} channels but layout.toml maps {}",
                    channel_map.len()
                ),
            )
            .into());
        }
        if let Some(&cell) = channel_map.iter().find(|&&cell| !present[cell]) {
            return Err(DataError::invalid(
                path,
                format!(
                    "layout maps a channel to cell [{}, {}], which the mask marks empty",
                    cell / cols,
                    cell % cols
                ),
            )
            .into());
        }
        // A cell no channel reaches carries no signal: masked, never scored as a taxel.
        let mut present = present;
        if self.channel_map.is_some() {
            let mut mapped = vec![false; rows * cols];
            channel_map.iter().for_each(|&cell| mapped[cell] = true);
            present.iter_mut().zip(mapped).for_each(|(p, m)| *p &= m);
        }
        Ok(Layout {
            rows,
            cols,
            channel_map,
            present,
        })
    }
}
