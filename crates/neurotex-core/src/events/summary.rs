//! What a set of event recordings holds per cell: the rates of its ON and OFF events over
//! every recording, and the cells that stay silent.

use serde::Serialize;

use crate::values::TimeUnit;

use super::Events;

/// A cell's events over every recording.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CellEvents {
    /// Its cell, `[row, col]`.
    pub cell: [usize; 2],
    /// The median over recordings of its ON events per second (spikes: one per ms at most).
    pub on_hz: f64,
    /// The same of its OFF events; `None` without polarities.
    pub off_hz: Option<f64>,
    /// Share of recordings in which it has no event.
    pub silent_share: f64,
}

/// The events over every recording.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EventSummary {
    /// The time unit of the stamps.
    pub time_unit: String,
    /// Events per recording, `[min, median, max]`.
    pub events: [usize; 3],
    /// Share of the events that are ON; `None` without polarities.
    pub on_share: Option<f64>,
    /// Share of the events that fell in a millisecond already holding an event of their
    /// cell and polarity (one spike for both).
    pub merged_share: f64,
    /// Recordings without any event.
    pub empty: Vec<String>,
    /// Per cell with a taxel, row-major.
    pub cells: Vec<CellEvents>,
}

impl EventSummary {
    /// The summary of `recordings` (each file's name and events) on a grid whose cells with
    /// a taxel are `present`, stamped in `time_unit`.
    pub fn of(
        recordings: &[(&str, &Events)],
        present: &[bool],
        time_unit: Option<TimeUnit>,
    ) -> Self {
        let ok = recordings;
        let count = |lists: &[Vec<u32>]| lists.iter().map(Vec::len).sum::<usize>();
        let on: usize = ok.iter().map(|(_, e)| count(&e.on)).sum();
        let off: usize = ok
            .iter()
            .filter_map(|(_, e)| e.off.as_deref().map(count))
            .sum();
        let polarities = ok.iter().any(|(_, e)| e.off.is_some());
        let read: usize = ok.iter().map(|(_, e)| e.count).sum();
        let merged: usize = ok.iter().map(|(_, e)| e.merged).sum();
        let median = |mut v: Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v.get(v.len() / 2).copied().unwrap_or(0.0)
        };
        let per_s = |n: usize, e: &Events| match e.n_steps {
            0 => 0.0,
            steps => n as f64 * 1000.0 / steps as f64,
        };
        let cols = recordings.first().map_or(1, |(_, e)| e.cols.max(1));
        let cells = (0..present.len())
            .filter(|&c| present[c])
            .map(|c| {
                let on = ok.iter().map(|(_, e)| per_s(e.on[c].len(), e)).collect();
                let off = polarities.then(|| {
                    let off = ok
                        .iter()
                        .map(|(_, e)| per_s(e.off.as_ref().map_or(0, |o| o[c].len()), e));
                    median(off.collect())
                });
                let silent = ok
                    .iter()
                    .filter(|(_, e)| {
                        e.on[c].is_empty() && e.off.as_ref().is_none_or(|o| o[c].is_empty())
                    })
                    .count();
                CellEvents {
                    cell: [c / cols, c % cols],
                    on_hz: median(on),
                    off_hz: off,
                    silent_share: silent as f64 / ok.len().max(1) as f64,
                }
            })
            .collect();
        EventSummary {
            time_unit: time_unit.map_or(String::new(), |u| u.to_string()),
            events: {
                let mut counts: Vec<usize> = ok.iter().map(|(_, e)| e.count).collect();
                counts.sort_unstable();
                match counts.len() {
                    0 => [0; 3],
                    n => [counts[0], counts[n / 2], counts[n - 1]],
                }
            },
            on_share: polarities.then(|| on as f64 / (on + off).max(1) as f64),
            merged_share: merged as f64 / read.max(1) as f64,
            empty: ok
                .iter()
                .filter(|(_, e)| e.count == 0)
                .map(|(m, _)| m.to_string())
                .collect(),
            cells,
        }
    }
}
