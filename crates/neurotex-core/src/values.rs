//! Typed values that travel between stages and across the command line: a taxel [`Grid`]
//! with its mask, a grid [`Cell`], a sliding [`Speed`] with a total order, a
//! [`SampleRate`], a time column's [`TimeUnit`], plus [`BySpeed`], results keyed by speed
//! in numeric order. Each parses from the text a user types (`FromStr`), failing with a
//! [`ParamError`] that names the rule.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// The largest magnitude a sample may have. No sensor reads anywhere near it in any unit
/// (a 32-bit converter counts to 4e9; 1 N is 1e9 nN), while a value beyond it is a
/// corrupted word or a placeholder (1e308, `f32::MAX`): taken, it would become the
/// recording's maximum and silence every other sample, or drive a stream's neurons to
/// infinite state they never leave. Readers refuse such a sample as they refuse NaN;
/// streams count its frame as bad.
pub const MAX_SAMPLE_MAGNITUDE: f64 = 1e15;

/// Whether `v` is a sample neurotex takes: a number within [`MAX_SAMPLE_MAGNITUDE`] of 0
/// (never NaN or infinite).
#[inline(always)]
pub fn sample_in_range(v: f64) -> bool {
    v.abs() <= MAX_SAMPLE_MAGNITUDE
}

/// What a reader says of a sample it refuses: "a number within ±1e15".
pub const SAMPLE_RULE: &str =
    "every sample must be a number within ±1e15 (beyond, it is no sensor's reading)";

/// A label (or any name from a user's data) as a terminal line shows it: control
/// characters (a newline, a tab, the bell, an escape sequence's start) written as escapes,
/// so that a label cannot break a table's layout or reach the terminal as a command.
pub fn shown_label(label: &str) -> String {
    match label.chars().any(char::is_control) {
        false => label.to_string(),
        true => label
            .chars()
            .map(|c| match c.is_control() {
                true => c.escape_default().to_string(),
                false => c.to_string(),
            })
            .collect(),
    }
}

/// Largest number of grid cells accepted from a user (a 1024 x 1024 skin); more is a typo
/// or a hostile file, and would allocate per-cell state for nothing.
pub const MAX_CELLS: usize = 1 << 20;

/// Samples per second of `max_duration_s` that one recording may hold once placed on its
/// grid and resampled to 1 kHz: the paper's 16 taxels. With the default hour that is 57.6
/// million values, 460 MB as f64; a larger grid may span proportionally less. Sampled
/// recordings and event recordings alike keep it.
pub const VALUES_PER_LIMIT_S: f64 = 16_000.0;

/// A `rows x cols` taxel grid and which of its cells hold a taxel.
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Grid {
    rows: usize,
    cols: usize,
    present: Vec<bool>,
}

impl Grid {
    /// A full grid (every cell holds a taxel).
    ///
    /// # Errors
    /// An empty grid or one of more than [`MAX_CELLS`] cells.
    pub fn full(rows: usize, cols: usize) -> Result<Self, ParamError> {
        Self::masked(rows, cols, vec![true; check_grid_cells(rows, cols)?])
    }

    /// A grid with a mask: `present[row * cols + col]` tells whether that cell holds a taxel.
    ///
    /// # Errors
    /// An empty grid, more than [`MAX_CELLS`] cells, a mask of the wrong length, or a mask
    /// without any taxel.
    pub fn masked(rows: usize, cols: usize, present: Vec<bool>) -> Result<Self, ParamError> {
        let cells = check_grid_cells(rows, cols)?;
        if present.len() != cells {
            return Err(ParamError::new(
                "mask",
                "the mask must have one entry per grid cell",
                format!("{} entries for {rows}x{cols}", present.len()),
            ));
        }
        if !present.contains(&true) {
            return Err(ParamError::new(
                "mask",
                "the mask must leave at least one taxel",
                format!("{rows}x{cols} all masked"),
            ));
        }
        Ok(Grid {
            rows,
            cols,
            present,
        })
    }

    /// A grid from parts whose consistency the caller guarantees (`present.len() == rows *
    /// cols`), for types that hold a grid's parts already checked.
    pub fn from_parts(rows: usize, cols: usize, present: &[bool]) -> Self {
        debug_assert_eq!(present.len(), rows * cols);
        Grid {
            rows,
            cols,
            present: present.to_vec(),
        }
    }

    /// Rows.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Columns.
    pub fn cols(&self) -> usize {
        self.cols
    }

    /// Cells, `rows * cols`, masked ones included.
    pub fn cells(&self) -> usize {
        self.present.len()
    }

    /// Per cell (row-major), whether it holds a taxel.
    pub fn present(&self) -> &[bool] {
        &self.present
    }

    /// The row-major indices of the cells that hold a taxel, in order.
    pub fn taxels(&self) -> impl Iterator<Item = usize> + '_ {
        self.present
            .iter()
            .enumerate()
            .filter(|(_, &p)| p)
            .map(|(i, _)| i)
    }

    /// Number of cells that hold a taxel.
    pub fn n_taxels(&self) -> usize {
        self.present.iter().filter(|&&p| p).count()
    }

    /// The cell at row-major index `index`.
    pub fn cell(&self, index: usize) -> Cell {
        Cell {
            row: index / self.cols,
            col: index % self.cols,
        }
    }

    /// The row-major index of `cell` when it lies in the grid and holds a taxel.
    pub fn taxel_index(&self, cell: Cell) -> Option<usize> {
        let index = cell.row * self.cols + cell.col;
        (cell.row < self.rows && cell.col < self.cols && self.present[index]).then_some(index)
    }

    /// The row-major index of the taxel a user named at `cell`.
    ///
    /// # Errors
    /// A [`ParamError`] for `taxel` when `cell` lies outside the grid or on a masked cell,
    /// naming the cell and the grid.
    pub fn locate(&self, cell: Cell) -> Result<usize, ParamError> {
        self.taxel_index(cell).ok_or_else(|| {
            let (row, col) = (cell.row, cell.col);
            let got = if row < self.rows && col < self.cols {
                format!("{row},{col}, a masked cell of the {self} grid")
            } else {
                format!("{row},{col}, outside the {self} grid")
            };
            ParamError::new(
                "taxel",
                "a taxel must be a grid cell that holds a taxel",
                got,
            )
        })
    }
}

/// The number of cells of a `rows x cols` grid, multiplied without overflow.
///
/// # Errors
/// An empty grid, or one of more than [`MAX_CELLS`] cells (an overflowing product included).
pub fn check_grid_cells(rows: usize, cols: usize) -> Result<usize, ParamError> {
    match rows.checked_mul(cols) {
        Some(cells) if cells > 0 && cells <= MAX_CELLS => Ok(cells),
        _ => Err(ParamError::new(
            "grid",
            "a grid needs at least one row and column and at most 1048576 cells",
            format!("{rows}x{cols}"),
        )),
    }
}

impl fmt::Display for Grid {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}x{}", self.rows, self.cols)
    }
}

impl FromStr for Grid {
    type Err = ParamError;

    /// Parses `ROWSxCOLS` (for example `4x4`) into a full grid.
    fn from_str(text: &str) -> Result<Self, ParamError> {
        let bad = || ParamError::new("grid", "a grid is ROWSxCOLS, for example 4x4", text);
        let (rows, cols) = text.trim().split_once(['x', 'X']).ok_or_else(bad)?;
        let rows = rows.trim().parse().map_err(|_| bad())?;
        let cols = cols.trim().parse().map_err(|_| bad())?;
        Grid::full(rows, cols)
    }
}

/// One grid cell, by row and column from 0.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct Cell {
    /// Row from 0.
    pub row: usize,
    /// Column from 0.
    pub col: usize,
}

impl fmt::Display for Cell {
    /// `r{row}c{col}`, the name feature columns and reports use.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "r{}c{}", self.row, self.col)
    }
}

impl FromStr for Cell {
    type Err = ParamError;

    /// Parses `ROW,COL` (for example `1,2`).
    fn from_str(text: &str) -> Result<Self, ParamError> {
        let bad = || {
            ParamError::new(
                "taxel",
                "a taxel is ROW,COL with non-negative integers",
                text,
            )
        };
        let (row, col) = text.split_once(',').ok_or_else(bad)?;
        Ok(Cell {
            row: row.trim().parse().map_err(|_| bad())?,
            col: col.trim().parse().map_err(|_| bad())?,
        })
    }
}

/// A sliding speed in mm/s; the sign is the direction where a rig records it.
///
/// Speeds are conditions, so they need equality and order: two speeds are the same
/// condition when they are equal as numbers (`-0` is `0`), and they order numerically.
/// "Slowest" is by magnitude ([`Speed::slowest`]). Written as the shortest decimal that
/// reads back to the same number (`5`, `2.5`, `-150`), as manifests and `results.json` do.
#[derive(Debug, Clone, Copy)]
pub struct Speed(f64);

impl Speed {
    /// A speed of `mm_s` mm/s.
    ///
    /// # Errors
    /// A value that is not finite.
    pub fn new(mm_s: f64) -> Result<Self, ParamError> {
        if mm_s.is_finite() {
            Ok(Speed(mm_s + 0.0))
        } else {
            Err(ParamError::new(
                "speed",
                "a speed must be a finite number of mm/s",
                mm_s,
            ))
        }
    }

    /// The speed of a value already known to be finite (manifest fields are checked on
    /// reading); a non-finite value becomes 0 rather than breaking the order.
    pub fn of(mm_s: f64) -> Self {
        Speed::new(mm_s).unwrap_or(Speed(0.0))
    }

    /// mm/s.
    pub fn mm_s(self) -> f64 {
        self.0
    }

    /// The slowest of `speeds` by magnitude (a positive speed before its negative twin),
    /// `None` when there is none.
    pub fn slowest(speeds: impl IntoIterator<Item = Speed>) -> Option<Speed> {
        speeds.into_iter().min_by(|a, b| {
            a.0.abs()
                .total_cmp(&b.0.abs())
                .then((a.0 < 0.0).cmp(&(b.0 < 0.0)))
        })
    }

    /// The distinct speeds of `speeds`, ascending.
    pub fn distinct(speeds: impl IntoIterator<Item = Speed>) -> Vec<Speed> {
        let mut out: Vec<Speed> = speeds.into_iter().collect();
        out.sort();
        out.dedup();
        out
    }
}

impl PartialEq for Speed {
    fn eq(&self, other: &Self) -> bool {
        self.0 == other.0
    }
}

impl Eq for Speed {}

impl PartialOrd for Speed {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Speed {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

impl std::hash::Hash for Speed {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        self.0.to_bits().hash(state);
    }
}

impl fmt::Display for Speed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.0)
    }
}

/// `text` as a number, or a [`ParamError`] for parameter `name` with `rule`.
fn number(text: &str, name: &'static str, rule: &'static str) -> Result<f64, ParamError> {
    text.trim()
        .parse()
        .map_err(|_| ParamError::new(name, rule, text))
}

impl FromStr for Speed {
    type Err = ParamError;

    /// Parses a number of mm/s (`5`, `-150`, `2.5`).
    fn from_str(text: &str) -> Result<Self, ParamError> {
        let rule = "a speed is a number of mm/s, for example 5";
        Speed::new(number(text, "speed", rule)?)
    }
}

impl Serialize for Speed {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_f64(self.0)
    }
}

impl<'de> Deserialize<'de> for Speed {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let value = f64::deserialize(deserializer)?;
        Speed::new(value).map_err(serde::de::Error::custom)
    }
}

/// The sampling rates a recording may be read at, in Hz: outside them a rate is a typo or
/// a unit slip (ms for s), whose recordings would otherwise be refused later as too long
/// or too short for some stage, with the rate not named.
pub const FS_RANGE: (f64, f64) = (1.0, 1e6);

/// The rule of [`FS_RANGE`], as said to the user.
pub const FS_RULE: &str = "a sampling rate must be a number of Hz from 1 to 1e6 (1 MHz)";

/// A sampling rate in Hz: a number within [`FS_RANGE`].
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd)]
pub struct SampleRate(f64);

impl SampleRate {
    /// A rate of `hz` Hz.
    ///
    /// # Errors
    /// A rate outside [`FS_RANGE`] (or not a number).
    pub fn new(hz: f64) -> Result<Self, ParamError> {
        if (FS_RANGE.0..=FS_RANGE.1).contains(&hz) {
            Ok(SampleRate(hz))
        } else {
            Err(ParamError::new("fs", FS_RULE, hz))
        }
    }

    /// Hz.
    pub fn hz(self) -> f64 {
        self.0
    }
}

impl fmt::Display for SampleRate {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.0)
    }
}

impl FromStr for SampleRate {
    type Err = ParamError;

    /// Parses a number of Hz (`1000`, `34.5`).
    fn from_str(text: &str) -> Result<Self, ParamError> {
        let rule = "a sampling rate is a number of Hz, for example 1000";
        SampleRate::new(number(text, "fs", rule)?)
    }
}

/// Results keyed by speed, in ascending numeric order; serialised as a map whose keys are
/// the speeds written as [`Speed`]'s `Display` (`"5"`, `"-150"`).
#[derive(Debug, Clone, PartialEq)]
pub struct BySpeed<T>(Vec<(Speed, T)>);

impl<T> Default for BySpeed<T> {
    fn default() -> Self {
        BySpeed(Vec::new())
    }
}

impl<T> BySpeed<T> {
    /// An empty map.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets the value at `speed`, keeping the order.
    pub fn insert(&mut self, speed: Speed, value: T) {
        match self.0.binary_search_by(|(s, _)| s.cmp(&speed)) {
            Ok(i) => self.0[i].1 = value,
            Err(i) => self.0.insert(i, (speed, value)),
        }
    }

    /// The value at `speed`.
    pub fn get(&self, speed: Speed) -> Option<&T> {
        self.0
            .binary_search_by(|(s, _)| s.cmp(&speed))
            .ok()
            .map(|i| &self.0[i].1)
    }

    /// `(speed, value)` pairs in ascending speed.
    pub fn iter(&self) -> impl Iterator<Item = (Speed, &T)> {
        self.0.iter().map(|(s, v)| (*s, v))
    }

    /// The values in ascending speed.
    pub fn values(&self) -> impl Iterator<Item = &T> {
        self.0.iter().map(|(_, v)| v)
    }

    /// The values in ascending speed, to change in place.
    pub fn values_mut(&mut self) -> impl Iterator<Item = &mut T> {
        self.0.iter_mut().map(|(_, v)| v)
    }

    /// Number of speeds.
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// Whether there is no speed.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

impl<T> FromIterator<(Speed, T)> for BySpeed<T> {
    fn from_iter<I: IntoIterator<Item = (Speed, T)>>(iter: I) -> Self {
        let mut map = BySpeed::new();
        for (s, v) in iter {
            map.insert(s, v);
        }
        map
    }
}

impl<T: Serialize> Serialize for BySpeed<T> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_map(self.0.iter().map(|(s, v)| (s.to_string(), v)))
    }
}

impl<'de, T: Deserialize<'de>> Deserialize<'de> for BySpeed<T> {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let map = std::collections::BTreeMap::<String, T>::deserialize(deserializer)?;
        map.into_iter()
            .map(|(k, v)| {
                k.parse::<Speed>()
                    .map(|s| (s, v))
                    .map_err(serde::de::Error::custom)
            })
            .collect()
    }
}

/// The unit of a CSV recording's time column; written `ms`, `s` or `us` (in
/// `layout.toml` too).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum TimeUnit {
    /// Milliseconds, `ms`.
    #[default]
    #[serde(rename = "ms")]
    Milliseconds,
    /// Seconds, `s`.
    #[serde(rename = "s")]
    Seconds,
    /// Microseconds, `us`.
    #[serde(rename = "us")]
    Microseconds,
}

impl TimeUnit {
    /// Seconds per unit.
    pub fn seconds(self) -> f64 {
        match self {
            TimeUnit::Milliseconds => 1e-3,
            TimeUnit::Seconds => 1.0,
            TimeUnit::Microseconds => 1e-6,
        }
    }

    /// Units per second (1, 1000 or 1e6), an exact integer.
    pub fn per_second(self) -> f64 {
        match self {
            TimeUnit::Milliseconds => 1e3,
            TimeUnit::Seconds => 1.0,
            TimeUnit::Microseconds => 1e6,
        }
    }

    /// A time in this unit in seconds, by one correctly rounded division by
    /// [`Self::per_second`]: the nearest double to the exact value, so an integer stamp in
    /// ms or us lands on the same double as the encoder's 1 kHz grid point `k / 1000` at
    /// that time (a product with `1e-3`, itself rounded, can miss it by a unit in the last
    /// place and give an interpolation weight of 1e-13 instead of 0).
    pub fn to_seconds(self, t: f64) -> f64 {
        t / self.per_second()
    }

    /// Milliseconds per unit.
    pub fn milliseconds(self) -> f64 {
        match self {
            TimeUnit::Milliseconds => 1.0,
            TimeUnit::Seconds => 1e3,
            TimeUnit::Microseconds => 1e-3,
        }
    }
}

impl fmt::Display for TimeUnit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            TimeUnit::Milliseconds => "ms",
            TimeUnit::Seconds => "s",
            TimeUnit::Microseconds => "us",
        })
    }
}

impl FromStr for TimeUnit {
    type Err = ParamError;

    /// Parses `ms`, `s` or `us` (`µs` too).
    fn from_str(text: &str) -> Result<Self, ParamError> {
        match text.trim() {
            "ms" => Ok(TimeUnit::Milliseconds),
            "s" => Ok(TimeUnit::Seconds),
            "us" | "µs" => Ok(TimeUnit::Microseconds),
            _ => Err(ParamError::new(
                "time-unit",
                "a time unit is `ms`, `s` or `us`",
                text,
            )),
        }
    }
}

/// A parameter outside its allowed range; the message names the rule.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("invalid parameter `{name}`: {rule}, got {got}")]
pub struct ParamError {
    /// The parameter's name as the command line spells it.
    pub name: &'static str,
    /// The rule it must satisfy.
    pub rule: &'static str,
    /// The value that came.
    pub got: String,
}

impl ParamError {
    /// Builds the error for parameter `name` that broke `rule` with value `got`.
    pub fn new(name: &'static str, rule: &'static str, got: impl ToString) -> Self {
        Self {
            name,
            rule,
            got: got.to_string(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn speeds_order_numerically_and_slowest_is_by_magnitude() {
        let speeds: Vec<Speed> = ["-10", "-100", "5", "-5", "120", "0.5"]
            .iter()
            .map(|s| s.parse().unwrap())
            .collect();
        let sorted: Vec<String> = Speed::distinct(speeds.clone())
            .iter()
            .map(|s| s.to_string())
            .collect();
        assert_eq!(sorted, ["-100", "-10", "-5", "0.5", "5", "120"]);
        assert_eq!(Speed::slowest(speeds).unwrap().mm_s(), 0.5);
        let twins = [Speed::of(-3.0), Speed::of(3.0)];
        assert_eq!(Speed::slowest(twins).unwrap().mm_s(), 3.0);
        assert_eq!(Speed::of(-0.0), Speed::of(0.0));
        assert!("inf".parse::<Speed>().is_err());
    }

    #[test]
    fn by_speed_keys_serialise_as_today_and_read_back() {
        let map: BySpeed<u32> = [
            (Speed::of(15.0), 3),
            (Speed::of(5.0), 1),
            (Speed::of(-2.5), 0),
        ]
        .into_iter()
        .collect();
        let text = serde_json::to_string(&map).unwrap();
        assert_eq!(text, r#"{"-2.5":0,"5":1,"15":3}"#);
        let back: BySpeed<u32> = serde_json::from_str(&text).unwrap();
        assert_eq!(back, map);
        assert_eq!(back.get(Speed::of(5.0)), Some(&1));
    }

    #[test]
    fn grids_and_cells_parse_and_reject_what_cannot_be() {
        let g: Grid = "4x4".parse().unwrap();
        assert_eq!((g.rows(), g.cols(), g.n_taxels()), (4, 4, 16));
        assert!("0x4".parse::<Grid>().is_err());
        assert!("4by4".parse::<Grid>().is_err());
        assert!("100000x100000".parse::<Grid>().is_err());
        assert!(format!("{}x{}", usize::MAX, 2).parse::<Grid>().is_err());
        let masked = Grid::masked(2, 2, vec![true, false, true, true]).unwrap();
        assert_eq!(masked.taxels().collect::<Vec<_>>(), [0, 2, 3]);
        assert_eq!(masked.taxel_index(Cell { row: 0, col: 1 }), None);
        assert_eq!(masked.taxel_index(Cell { row: 1, col: 0 }), Some(2));
        assert_eq!(masked.taxel_index(Cell { row: 2, col: 0 }), None);
        assert!(Grid::masked(1, 2, vec![false, false]).is_err());
        let c: Cell = " 1, 2".parse().unwrap();
        assert_eq!(c.to_string(), "r1c2");
        assert!("1;2".parse::<Cell>().is_err());
        assert!("1,x".parse::<Cell>().is_err());
        assert!("-1,2".parse::<Cell>().is_err());
    }

    #[test]
    fn parse_errors_name_the_parameter() {
        let name = |e: ParamError| e.name;
        assert_eq!("4by4".parse::<Grid>().map_err(name), Err("grid"));
        assert_eq!("a".parse::<Cell>().map_err(name), Err("taxel"));
        assert_eq!("fast".parse::<Speed>().map_err(name), Err("speed"));
        assert_eq!("-5".parse::<SampleRate>().map_err(name), Err("fs"));
    }

    #[test]
    fn a_taxel_is_located_only_on_a_cell_that_holds_one() {
        let grid = Grid::masked(2, 2, vec![true, false, true, true]).unwrap();
        assert_eq!(grid.locate(Cell { row: 1, col: 1 }), Ok(3));
        let outside = grid.locate(Cell { row: 2, col: 0 }).unwrap_err();
        assert_eq!(outside.name, "taxel");
        assert!(
            outside.to_string().contains("2,0, outside the 2x2 grid"),
            "{outside}"
        );
        let masked = grid.locate(Cell { row: 0, col: 1 }).unwrap_err();
        assert!(
            masked.to_string().contains("a masked cell of the 2x2 grid"),
            "{masked}"
        );
    }

    #[test]
    fn sample_rates_are_positive_and_finite() {
        assert_eq!("500".parse::<SampleRate>().unwrap().hz(), 500.0);
        for bad in ["0", "-5", "inf", "NaN", "fast", ""] {
            assert!(bad.parse::<SampleRate>().is_err(), "{bad}");
        }
        assert_eq!(SampleRate::new(34.5).unwrap().to_string(), "34.5");
    }
}
