//! `inspect` on an address-event dataset: the design, the grid, each recording's length and
//! events, each cell's event rates by polarity, and the findings on them. There is no
//! signal to check and no encoder to run: the events are the spikes.

use rayon::prelude::*;

use super::findings::{finding, Finding, Severity};
use super::{design, InspectParams, Inspection, LayoutSummary, SignalSummary, Unreadable};
use crate::events::{EventSummary, Events};
use crate::recording::{Dataset, Meta};

/// Inspects an event dataset (see the module's description).
///
/// # Errors
/// None yet: an unreadable recording is a finding.
pub(super) fn inspect_events(
    ds: &Dataset,
    params: &InspectParams,
    on_done: &(dyn Fn() + Sync),
) -> crate::error::Result<Inspection> {
    let read: Vec<Result<(Meta, Events), Unreadable>> = (0..ds.entries.len())
        .into_par_iter()
        .map(|i| {
            let loaded = ds.load_events(i);
            on_done();
            match loaded {
                Ok(e) => Ok((ds.entries[i].clone(), e)),
                Err(e) => Err(Unreadable {
                    file: ds.entries[i].file.clone(),
                    reason: e.to_string(),
                }),
            }
        })
        .collect();
    let (mut ok, mut unreadable) = (Vec::new(), Vec::new());
    for r in read {
        match r {
            Ok(x) => ok.push(x),
            Err(u) => unreadable.push(u),
        }
    }
    let metas: Vec<Meta> = ok.iter().map(|(m, _)| m.clone()).collect();
    let (rows, cols) = (
        ds.layout.rows.unwrap_or_default(),
        ds.layout.cols.unwrap_or_default(),
    );
    let present: Vec<bool> = match ok.first() {
        Some((_, e)) => e.present.clone(),
        None => vec![true; rows * cols],
    };
    let bin_ms = params.pipeline.volume.bin_ms;
    let mut inspection = Inspection {
        kind: "address-event dataset".into(),
        files: ds.entries.len(),
        design: design::design(&metas, params.folds, params.k),
        layout: grid_summary(ds, rows, cols, &present),
        signals: lengths(&ok, unreadable, bin_ms),
        encoder: None,
        events: Some(EventSummary::of(
            &ok.iter()
                .map(|(m, e)| (m.file.as_str(), e))
                .collect::<Vec<_>>(),
            &present,
            ds.layout.events.as_ref().map(|f| f.time_unit),
        )),
        findings: Vec::new(),
        traces: Vec::new(),
    };
    let mut findings = super::findings::findings(&inspection, &ds.layout, params);
    findings.extend(event_findings(&inspection));
    let onsets: Vec<(f64, f64)> = ok
        .iter()
        .filter_map(|(_, e)| first_step(e).map(|f| (f as f64 / 1000.0, e.n_steps as f64 / 1000.0)))
        .collect();
    if let Some(late) = LateOnsets::of(&onsets) {
        findings.push(finding(
            Severity::Severe,
            "events",
            "late-first-events",
            late.message(),
            "set `origin = \"first\"` in layout.toml's [events] table (each recording then starts at its first event), or import the logs again with `neurotex import events --origin first`",
        ));
    }
    findings.sort_by_key(|f| std::cmp::Reverse(f.severity));
    inspection.findings = findings;
    Ok(inspection)
}

/// The grid as the layout gives it: one "channel" per cell with a taxel.
fn grid_summary(ds: &Dataset, rows: usize, cols: usize, present: &[bool]) -> LayoutSummary {
    let cells: Vec<[usize; 2]> = (0..rows * cols)
        .filter(|&c| present.get(c).copied().unwrap_or(true))
        .map(|c| [c / cols, c % cols])
        .collect();
    let taxel = |r: usize, c: usize| present.get(r * cols + c).copied().unwrap_or(false);
    let neighbour_pairs = cells
        .iter()
        .map(|&[r, c]| {
            usize::from(c + 1 < cols && taxel(r, c + 1))
                + usize::from(r + 1 < rows && taxel(r + 1, c))
        })
        .sum();
    LayoutSummary {
        rows,
        cols,
        channels: cells.iter().map(|[r, c]| format!("r{r}c{c}")).collect(),
        empty_cells: rows * cols - cells.len(),
        cells,
        mapped: ds.layout.channel_map.is_some(),
        neighbour_pairs,
        baseline: "none (address events skip the encoder)".into(),
        fs_hz: 1000.0,
    }
}

/// `[min, median, max]` of `values` (zeros when empty).
fn spread<T: Copy + PartialOrd + Default>(mut values: Vec<T>) -> [T; 3] {
    values.sort_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal));
    match values.len() {
        0 => [T::default(); 3],
        n => [values[0], values[n / 2], values[n - 1]],
    }
}

/// The recordings' lengths, as the signal summary gives them for samples.
fn lengths(ok: &[(Meta, Events)], unreadable: Vec<Unreadable>, bin_ms: usize) -> SignalSummary {
    let seconds: Vec<f64> = ok.iter().map(|(_, e)| e.n_steps as f64 / 1000.0).collect();
    let duration_s = spread(seconds.clone());
    let name = |keep: &dyn Fn(f64) -> bool| -> Vec<String> {
        ok.iter()
            .zip(&seconds)
            .filter(|(_, &s)| keep(s))
            .map(|((m, _), _)| m.file.clone())
            .collect()
    };
    SignalSummary {
        recordings: ok.len(),
        unreadable,
        fs_hz: None,
        off_rate: Vec::new(),
        jitter: None,
        gappy: Vec::new(),
        merged_rows: [0, 0],
        duration_s,
        too_short: name(&|s| s * 1000.0 < bin_ms as f64),
        short: name(&|s| s < duration_s[1] / 4.0),
        dead: Vec::new(),
        channels: Vec::new(),
    }
}

/// A recording's first event's 1 ms step; `None` without events.
fn first_step(e: &Events) -> Option<u32> {
    let first = |lists: &[Vec<u32>]| lists.iter().filter_map(|l| l.first().copied()).min();
    let off = e.off.as_deref().and_then(first);
    match (first(&e.on), off) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

/// Leading silence, s, that is one rate-volume bin or less: never a finding.
const ONSET_FLOOR_S: f64 = 0.2;
/// A median first event later than this share of the median recording's events' span
/// (first to last event) is a late start.
const LATE_SHARE: f64 = 0.25;
/// First events spread over more than this share of the median span differ widely.
const SPREAD_SHARE: f64 = 0.5;

/// Recordings whose first events come late, or at times that differ widely between them:
/// stamps from a sensor's clock read with the origin at time 0, which puts seconds of
/// silence in front of every recording (the rate volume, the GLCM and the time windows
/// read it as texture; the paper's method loses half its accuracy on such logs).
#[derive(Debug, Clone, PartialEq)]
pub struct LateOnsets {
    /// The first event's time, `[min, median, max]`, s from the recording's start.
    pub first_s: [f64; 3],
    /// The median span from the first to the last event, s.
    pub active_s: f64,
    /// Recordings with events.
    pub recordings: usize,
}

impl LateOnsets {
    /// The rule on `(first event, end)` pairs in s, one per recording with events:
    /// `Some` when the median first event is later than a quarter of the median span of
    /// the events, or the first events spread over more than half of it (each also at
    /// least one 200 ms bin).
    pub fn of(onsets: &[(f64, f64)]) -> Option<LateOnsets> {
        if onsets.is_empty() {
            return None;
        }
        let firsts = spread(onsets.iter().map(|&(f, _)| f).collect());
        let active = spread(onsets.iter().map(|&(f, end)| (end - f).max(0.0)).collect())[1];
        let late = firsts[1] >= ONSET_FLOOR_S.max(LATE_SHARE * active);
        let differ = firsts[2] - firsts[0] >= ONSET_FLOOR_S.max(SPREAD_SHARE * active);
        (late || differ).then_some(LateOnsets {
            first_s: firsts,
            active_s: active,
            recordings: onsets.len(),
        })
    }

    /// What was found, in numbers.
    pub fn message(&self) -> String {
        let [lo, median, hi] = self.first_s;
        format!(
            "the first event comes {median:.3} s after the recording's start (median of {}; from {lo:.3} to {hi:.3} s) while the events span {:.3} s: stamps from a sensor's clock read from time 0 put that silence in front of every recording, where the rate volume, the GLCM and the time windows read it as texture",
            self.recordings, self.active_s
        )
    }
}

/// Findings on the events themselves.
fn event_findings(i: &Inspection) -> Vec<Finding> {
    let Some(e) = &i.events else {
        return Vec::new();
    };
    let mut out = Vec::new();
    let silent: Vec<String> = e
        .cells
        .iter()
        .filter(|c| c.silent_share > 0.5)
        .map(|c| format!("r{}c{}", c.cell[0], c.cell[1]))
        .collect();
    if !silent.is_empty() {
        out.push(finding(
            Severity::Warning,
            "events",
            "silent-cells",
            format!(
                "{} of {} cells have no event in most recordings ({}): the GLCM reads them as texture",
                silent.len(),
                e.cells.len(),
                silent.iter().take(6).cloned().collect::<Vec<_>>().join(", ")
            ),
            "check the grid (--grid, x and y or the channel map) against the sensor; a mask in layout.toml leaves out cells without a taxel",
        ));
    }
    if !e.empty.is_empty() {
        out.push(finding(
            Severity::Warning,
            "events",
            "empty-recordings",
            format!(
                "{} recording(s) hold no event: {}",
                e.empty.len(),
                e.empty
                    .iter()
                    .take(3)
                    .cloned()
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            "remove their rows from manifest.csv, or check the logger",
        ));
    }
    if e.merged_share > 0.2 {
        out.push(finding(
            Severity::Note,
            "events",
            "merged-events",
            format!(
                "{:.0} % of the events share a millisecond with another of their cell and polarity, so each such group is one spike: rates above 1 kHz per cell are capped",
                100.0 * e.merged_share
            ),
            "nothing, if the events' timing matters more than their count; a coarser grid (more events per cell) makes it worse",
        ));
    }
    out
}
