//! What an import notices but does not refuse: a grid left for the user to give, a clock-like
//! channel, samples that rest far from zero.

/// A choice of the import that is probably a mistake, found on the logs it read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ImportWarning {
    /// Labels that differ only in case: two classes where there is most likely one.
    #[error("labels {} differ only in case: they are {} classes, each with part of what is most likely one texture's recordings; write one texture's label the same way in every file name", quoted(labels), labels.len())]
    LabelsDifferInCase {
        /// The labels, sorted.
        labels: Vec<String>,
    },
    /// Logs in which every channel holds one value from start to end.
    #[error("{} no signal, every channel one value from start to end ({}): each would be classified by the encoder's answer to a constant input; leave it out, or record it again", match files.len() { 1 => "1 log holds".to_string(), n => format!("{n} logs hold") }, quoted(files))]
    NoSignal {
        /// The logs, in import order.
        files: Vec<String>,
    },
    /// Fewer channels than grid cells and no channel map: the channels fill the grid row by
    /// row, so cells that are neighbours on the grid need not be on the sensor.
    #[error("{channels} channels on a {rows}x{cols} grid fill it row by row and leave {} empty, so taxels that are neighbours on the grid (what the GLCM compares) need not be neighbours on the sensor; {}", crate::words::counted(rows * cols - channels, "cell"), grid_advice(*channels))]
    GridNotFilled {
        /// Channels imported.
        channels: usize,
        /// Grid rows.
        rows: usize,
        /// Grid columns.
        cols: usize,
    },
    /// A channel rises at every row of most logs, as a clock or a sample counter does: a
    /// time column read as a taxel.
    #[error("channel `{channel}` rises at every row in {files} of {total} logs, as a clock or a sample counter does: a time column read as a taxel; --time-column {channel} reads it as time (and --channels can leave it out)")]
    RisingChannel {
        /// The channel.
        channel: String,
        /// Logs in which it rises at every row.
        files: usize,
        /// Logs imported.
        total: usize,
    },
    /// Most recordings rest far above their range and no baseline is removed: the
    /// encoder, normalising by each recording's maximum, sees mostly the offset.
    #[error("in {files} of {total} recordings the channels rest at about {ratio:.0} times their range above zero (median channel) and no baseline is removed, so the encoder sees mostly the resting offset; --baseline min removes each channel's minimum")]
    RestingOffset {
        /// The median over those recordings of the median channel's minimum over its range.
        ratio: f64,
        /// Recordings resting that high.
        files: usize,
        /// Recordings imported.
        total: usize,
    },
}

/// `` `a` and `b` ``, or the first three of more and how many more.
fn quoted(names: &[String]) -> String {
    let shown: Vec<String> = names.iter().take(3).map(|n| format!("`{n}`")).collect();
    match names.len() {
        n if n > 3 => format!("{} and {} more", shown.join(", "), n - 3),
        _ => shown.join(" and "),
    }
}

/// What places `channels` channels on the grid the sensor has.
pub fn grid_advice(channels: usize) -> String {
    let side = (channels as f64).sqrt().round() as usize;
    if side * side == channels {
        format!("--grid {side}x{side} (or a channel map) places them as a square sensor has them")
    } else {
        "a grid of the sensor's shape (--grid) or a channel map places them".to_string()
    }
}

/// A resting value this many times the signal's range, or more, is an offset the encoder
/// should not see: normalised by the recording's maximum, the input then spans half its
/// scale or less (FabricSlide's capacitive channels rest at 2 to 12 times their range).
pub const OFFSET_RATIO: f64 = 1.0;

/// Whether `values` never fall and rise at (nearly) every step, as a clock or a sample
/// counter does: at least two steps, none falling, and at least 99 % rising (a rare equal
/// pair is a repeated reading).
pub fn clock_like(values: impl Iterator<Item = f64>) -> bool {
    let (mut rises, mut falls, mut steps, mut prev) = (0usize, 0usize, 0usize, None);
    for v in values {
        if let Some(p) = prev {
            steps += 1;
            rises += usize::from(v > p);
            falls += usize::from(v < p);
        }
        prev = Some(v);
    }
    steps >= 2 && falls == 0 && rises as f64 >= 0.99 * steps as f64
}

/// The median over a log's channels (`frames x channels`, time-major) of each channel's
/// minimum over its range; channels that never move are left out, `None` without any.
pub(super) fn resting_ratio(samples: &[f64], channels: usize) -> Option<f64> {
    let mut ratios: Vec<f64> = (0..channels)
        .filter_map(|c| {
            let column = samples.iter().skip(c).step_by(channels.max(1));
            let (lo, hi) = column.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            });
            (hi > lo && lo > 0.0).then(|| lo / (hi - lo))
        })
        .collect();
    if ratios.is_empty() {
        return None;
    }
    ratios.sort_by(f64::total_cmp);
    Some(ratios[ratios.len() / 2])
}
