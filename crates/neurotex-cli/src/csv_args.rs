//! How to read CSV logs: the options `import csv` and `encode` share, parsed into the
//! library's [`CsvFormat`] so both read a log the same way.

use clap::Args;
use neurotex::csvlog::{ChannelSelect, Column, CsvFormat, Delimiter, DuplicateStamps};
use neurotex::recording::TimeUnit;

/// CSV reading options.
#[derive(Args, Debug, Clone)]
pub struct CsvArgs {
    /// The file has no header row: columns go by 0-based index, and --time-column and
    /// --channels take indices.
    #[arg(long = "no-header")]
    pub no_header: bool,
    /// The field delimiter: `,`, `;` or `tab` (default: detected from the first lines).
    #[arg(long)]
    pub delimiter: Option<Delimiter>,
    /// The time-stamp column, by name or 0-based index (irregular stamps are kept and
    /// resampled onto 1 ms later).
    #[arg(long = "time-column")]
    pub time_column: Option<Column>,
    /// Unit of the time column: `ms`, `s` or `us` (default: from a suffix of the column's
    /// name such as `_ms`, `_s`, `_us` or `(s)`, else `ms`; stamps implying a rate above
    /// 20 kHz or below 0.1 Hz are then refused, asking for this option).
    #[arg(long = "time-unit")]
    pub time_unit: Option<TimeUnit>,
    /// Channel columns: a comma-separated list of names, of 0-based indices and ranges such
    /// as `2,4-7` or `0-8`, or a regular expression such as `^channel\d+$` (default: every
    /// column but the time column).
    #[arg(long)]
    pub channels: Option<ChannelSelect>,
    /// Rows sharing one time stamp: `average` (one frame, their mean), `first`, `last`, or
    /// `error`. Exact duplicate rows are dropped under each; the counts are reported.
    #[arg(long = "duplicate-stamps")]
    pub duplicate_stamps: Option<DuplicateStamps>,
    /// The longest gap between two time stamps, in s, that resampling may fill by
    /// interpolation (default 1, as `stream`'s --max-gap-s): a longer pause in a log is an
    /// error naming where, not a straight line through it.
    #[arg(long = "max-gap-s")]
    pub max_gap_s: Option<f64>,
}

impl CsvArgs {
    /// `base` with every option given on the command line put in place of its setting.
    pub fn apply(&self, mut base: CsvFormat) -> CsvFormat {
        if self.no_header {
            base.header = false;
            base.detect_time = false;
        }
        if let Some(d) = self.delimiter {
            base.delimiter = Some(d);
        }
        if let Some(col) = &self.time_column {
            base.time_column = Some(col.clone());
            base.detect_time = false;
        }
        if let Some(unit) = self.time_unit {
            base.time_unit = unit;
            base.unit_given = true;
        }
        if let Some(channels) = &self.channels {
            base.channels = channels.clone();
        }
        if let Some(policy) = self.duplicate_stamps {
            base.duplicate_stamps = policy;
        }
        if let Some(gap) = self.max_gap_s {
            base.max_gap_s = gap;
        }
        base
    }
}
