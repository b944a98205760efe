//! Address events through a stream: an event sensor's events (a time, a cell, a polarity)
//! are spikes already, so they skip the resampler, the filter and the neurons and go
//! straight into the window the model classifies, ON events as the SA population and OFF
//! events as the FA one, in the 1 ms steps of the offline reader
//! ([`neurotex_core::events`]): an event recording streamed as one episode gives the lines
//! `predict` would give its bins, and the same lines as the sampled recording whose spikes
//! the events are.
//!
//! Events come as text lines (`t,x,y,p` or `t,taxel,p`, with or without a header naming the
//! columns) or as 16-byte binary records ([`RECORD_BYTES`]). Besides events, a stream may
//! send a tick (a time alone: time has reached it, with no event) and `reset` (the episode
//! ends). A sensor that falls silent should tick: a stamp further than `max_gap_s` after
//! the previous one is refused as a wild stamp unless the next one follows it, as for
//! frames ([`StreamClassifier::push`]), so the first event after a long silence costs its
//! own spike and starts a new episode.

use neurotex_core::events::{EventGrid, EventsFormat, Origin, Stamp};

use crate::error::Result;
use crate::frames::{Replay, Sink};
use crate::pipeline::Encoding;
use crate::recording::TimeUnit;
use crate::saved::{SavedModel, Trained};
use crate::signal::{CausalConditioning, ENCODER_FS};
use crate::StreamParams;

use super::{BadFrame, EpisodeEnd, EpisodeRule, Event, StreamClassifier, StreamError};

mod reader;

pub(crate) use reader::marker_item;
pub use reader::{EventEncoding, EventReader, Item};

/// The bytes of one binary event record, little-endian: `t` i64 (in the stream's unit,
/// microseconds unless said), `x` u16 (or the taxel index), `y` u16, `p` i8 (the polarity),
/// `kind` u8 (0 an event, 1 a tick, 2 the episode's end), two bytes unused. NumPy's
/// `[("t", "<i8"), ("x", "<u2"), ("y", "<u2"), ("p", "i1"), ("kind", "u1"), ("pad", "<u2")]`.
pub const RECORD_BYTES: usize = 16;

/// How a stream's events address the model's grid and count time.
#[derive(Debug, Clone)]
pub struct EventSource {
    /// The stamps' unit, the polarity values, a taxel column or `x` and `y`, the origin.
    pub format: EventsFormat,
    /// The model's grid, its mask and the taxel indices' cells.
    pub grid: EventGrid,
}

impl EventSource {
    /// The events of `model`'s sensor: read as its training dataset's event files were when
    /// it was trained on events, else as `x` and `y` on its grid with polarities 1 (ON) and
    /// 0 (OFF). `unit` and `origin` override the dataset's. `taxel`: the events name a
    /// taxel index (`t,taxel,p`), each taxel's cell from the channel map of the model's
    /// dataset (`import events --channel-map` keeps it), else row-major.
    ///
    /// # Errors
    /// No unit: the model was not trained on events and none was given.
    pub fn for_model(
        model: &SavedModel,
        unit: Option<TimeUnit>,
        origin: Option<Origin>,
        taxel: bool,
    ) -> std::result::Result<Self, String> {
        let grid = model.grid();
        let layout = model.provenance().layout.as_ref();
        let trained = layout.and_then(|l| l.events.clone());
        let mut format = match (trained, unit) {
            (Some(f), _) => f,
            (None, Some(unit)) => EventsFormat::new(unit),
            (None, None) => return Err("the model was not trained on events, so the stream's time unit is not known: say it with --time-unit (us, ms or s)".into()),
        };
        if let Some(unit) = unit {
            format.time_unit = unit;
        }
        if taxel && format.taxel.is_none() {
            format.taxel = Some("taxel".into());
        }
        format.origin = origin.unwrap_or(match layout.is_some_and(|l| l.events.is_some()) {
            true => format.origin,
            false => Origin::First,
        });
        let (rows, cols) = (grid.rows(), grid.cols());
        let taxels = match layout {
            Some(l) if format.taxel.is_some() => l.event_grid(rows, cols).taxels,
            _ => (0..rows * cols).collect(),
        };
        let grid = EventGrid {
            rows,
            cols,
            present: grid.present().to_vec(),
            taxels,
        };
        Ok(EventSource { format, grid })
    }
}

/// Why `model` cannot stream frames: it was trained on address events.
pub fn trained_on_events(model: &SavedModel) -> Option<String> {
    let layout = model.provenance().layout.as_ref()?;
    layout.events.as_ref().map(|_| {
        "the model was trained on address events, which skip the encoder: stream its sensor's events (--format events or events-bin), not sampled frames".to_string()
    })
}

/// An event stream's state beside the episode's.
#[derive(Debug, Clone)]
pub(crate) struct EventState {
    source: EventSource,
    /// The population ON events feed, and OFF events (`None`: the model reads none).
    on: Option<usize>,
    off: Option<usize>,
    /// Per population, the current step's spikes by cell.
    rasters: Vec<Vec<u8>>,
    /// Whether the current step holds a spike.
    pending: bool,
    /// The episode's time 0.
    origin: Stamp,
    /// Episodes started.
    episodes: u64,
    /// The step of the episode's last event.
    last_event: Option<u64>,
    /// Events that fell in a step already holding a spike of their cell and population.
    merged: u64,
}

impl StreamClassifier {
    /// A stream classifier for address events from `source` with any feature model or
    /// spiking network (events need no conditioning, so a model trained without `--causal`
    /// streams them too; a spectrum model still cannot).
    ///
    /// # Errors
    /// As [`StreamClassifier::new`], but for `--causal`.
    pub fn for_events(
        model: impl Into<SavedModel>,
        params: StreamParams,
        source: EventSource,
    ) -> Result<Self> {
        let model = model.into();
        if let SavedModel::Features(m) = &model {
            if m.features().method == crate::pipeline::Method::Spectrum {
                let why = crate::causal::NO_RUNNING_SPECTRUM.into();
                return Err(crate::error::OptionsError::Conflict(why).into());
            }
        }
        let cells = model.grid().rows() * model.grid().cols();
        let conditioning = CausalConditioning {
            offsets: vec![0.0; cells],
            scale: 1.0,
        };
        let (on, off) = match model.params().encoding {
            Encoding::Sa => (Some(0), None),
            Encoding::Fa => (None, Some(0)),
            Encoding::SaFa => (Some(0), Some(1)),
        };
        let populations = usize::from(on.is_some()) + usize::from(off.is_some());
        let mut stream = Self::with_conditioning(model, params, conditioning)?;
        stream.event_input = Some(EventState {
            source,
            on,
            off,
            rasters: vec![vec![0; cells]; populations],
            pending: false,
            origin: Stamp::Int(0),
            episodes: 0,
            last_event: None,
            merged: 0,
        });
        Ok(stream)
    }

    /// Events that added no spike: their cell already had one from its polarity in that
    /// millisecond (a train holds at most one spike per 1 ms step, as offline).
    pub fn merged_events(&self) -> u64 {
        self.event_input.as_ref().map_or(0, |e| e.merged)
    }

    /// Takes one event at `stamp` (in the source's unit) of the cell `address` gives (`x`
    /// and `y`, or the taxel index and an unused value) and its polarity, or a tick when
    /// `address` is `None`: time has reached `stamp`. Returns what it completed: a
    /// classification at each bin boundary passed, an episode's end.
    ///
    /// An episode's steps count from its origin: the stream's first episode from time 0
    /// with the `zero` origin, every other from its first event. A tick starts a `whole`
    /// episode but not an `onset` one; an `onset` episode ends once `rest_ms` pass without
    /// an event (its level does not apply to events).
    ///
    /// # Errors
    /// [`StreamError::Bad`] for a bad event (a cell off the grid or masked, an unknown
    /// polarity, a stamp not finite, before the previous or a gap too far ahead): counted and
    /// skipped. [`StreamError::Classify`] when the model cannot classify a window.
    ///
    /// # Panics
    /// If the classifier was not made for events ([`StreamClassifier::for_events`]).
    pub fn push_event(
        &mut self,
        stamp: Stamp,
        address: Option<(i64, i64, Option<i64>)>,
    ) -> std::result::Result<&[Event], StreamError> {
        self.events.clear();
        let (target, jumped) = match self.accept_event(stamp, address) {
            Ok(taken) => taken,
            Err(bad) => {
                self.bad_frames += 1;
                return Err(bad.into());
            }
        };
        // Ticks are not events: the count is of events taken.
        self.frames += u64::from(address.is_some());
        if jumped && self.episode.is_some() {
            self.end_episode(EpisodeEnd::Gap)?;
        }
        let rest = match self.params.episodes {
            EpisodeRule::Onset { rest_ms, .. } => Some(rest_ms as u64),
            EpisodeRule::Whole => None,
        };
        let mut step = None;
        if self.episode.is_some() {
            let state = self.event_input.as_ref().expect("an event stream");
            let s = stamp
                .step_from(state.origin, state.source.format.time_unit)
                .unwrap_or(u64::MAX);
            if let (Some(rest), Some(last)) = (rest, state.last_event) {
                if s > last + rest {
                    self.advance(last + rest + 1)?;
                    self.end_episode(EpisodeEnd::Rest)?;
                }
            }
            if s >= super::MAX_EPISODE_STEPS as u64 && self.episode.is_some() {
                self.end_episode(EpisodeEnd::Gap)?;
            }
            step = self.episode.is_some().then_some(s);
        }
        let step = match step {
            Some(s) => s,
            None if rest.is_some() && target.is_none() => return Ok(&self.events),
            None => self.start_event_episode(stamp),
        };
        self.advance(step)?;
        let state = self.event_input.as_mut().expect("an event stream");
        if let Some((cell, population)) = target {
            state.last_event = Some(step);
            if let Some(p) = population {
                let spike = &mut state.rasters[p][cell];
                state.merged += u64::from(*spike != 0);
                *spike = 1;
                state.pending = true;
            }
        }
        Ok(&self.events)
    }

    /// Checks an event: its cell and population (`None` for a polarity the model does not
    /// read) unless it is a tick, then its stamp against the previous one.
    #[allow(clippy::type_complexity)]
    fn accept_event(
        &mut self,
        stamp: Stamp,
        address: Option<(i64, i64, Option<i64>)>,
    ) -> std::result::Result<(Option<(usize, Option<usize>)>, bool), BadFrame> {
        let state = self.event_input.as_ref().expect("an event stream");
        let format = &state.source.format;
        let t = format.time_unit.to_seconds(stamp.as_f64());
        if !t.is_finite() {
            return Err(BadFrame::StampNotFinite { t: stamp.as_f64() });
        }
        if t.abs() > super::MAX_STAMP_S {
            return Err(BadFrame::StampRange { t });
        }
        let target = match address {
            None => None,
            Some((a, b, p)) => {
                let taxel = format.taxel.is_some();
                let cell = state.source.grid.cell(taxel, (a, b));
                let on = format.is_on(p);
                let (cell, on) = (
                    cell.map_err(BadFrame::Address)?,
                    on.map_err(BadFrame::Address)?,
                );
                Some((cell, if on { state.on } else { state.off }))
            }
        };
        Ok((target, self.follow(t)?))
    }

    /// Starts an episode at `stamp`: its first step.
    fn start_event_episode(&mut self, stamp: Stamp) -> u64 {
        self.episode = Some(self.new_episode(0.0));
        let state = self.event_input.as_mut().expect("an event stream");
        let zero = state.episodes == 0 && state.source.format.origin == Origin::Zero;
        state.origin = if zero { Stamp::Int(0) } else { stamp };
        state.episodes += 1;
        state.last_event = None;
        let unit = state.source.format.time_unit;
        // Time 0 is the stream's first stamp: a first event more than the largest gap
        // after it is a jump, as between frames, and the episode counts from the event
        // (which also bounds the silent steps one event completes).
        let max_gap_steps = (self.params.max_gap_s * ENCODER_FS) as u64;
        match stamp.step_from(state.origin, unit) {
            Ok(s) if s <= max_gap_steps => s,
            // Before time 0 or too far past it: the episode counts from this stamp.
            _ => {
                state.origin = stamp;
                0
            }
        }
    }

    /// Completes the episode's steps before `step`.
    fn advance(&mut self, step: u64) -> std::result::Result<(), StreamError> {
        while self
            .episode
            .as_ref()
            .is_some_and(|e| (e.steps as u64) < step)
        {
            self.complete_step()?;
        }
        Ok(())
    }

    /// Completes the episode's current step with the events it holds.
    fn complete_step(&mut self) -> std::result::Result<(), StreamError> {
        let episode = self.episode.as_mut().expect("an episode is under way");
        let state = self.event_input.as_mut().expect("an event stream");
        episode.kept.begin_step();
        for (population, raster) in state.rasters.iter_mut().enumerate() {
            episode.kept.add(population, 0, raster, &self.present);
            if state.pending {
                raster.fill(0);
            }
        }
        state.pending = false;
        self.end_step()
    }

    /// The episode's last step when it holds events (the steps before it are complete).
    pub(crate) fn flush_events(&mut self) -> std::result::Result<(), StreamError> {
        let pending = self.event_input.as_ref().is_some_and(|s| s.pending);
        match pending {
            true => self.complete_step(),
            false => Ok(()),
        }
    }
}

/// Where events come from: bytes an [`EventReader`] decodes, or an LSL inlet's samples
/// ([`crate::lsl::LslEvents`]).
pub trait EventInput {
    /// The next item; `None` at the end of the input or once `stop()` says so.
    ///
    /// # Errors
    /// The input cannot be read, or no longer fits the model.
    fn next_item(&mut self, stop: &dyn Fn() -> bool) -> Result<Option<Item>>;
    /// Where the last item was (`line 12`, `record 7`, `sample 9`).
    fn place(&self) -> String;
    /// The stamps' unit.
    fn unit(&self) -> TimeUnit;
    /// Why the input ended, when a person should hear it (a live stream that went away).
    fn ended(&self) -> Option<String> {
        None
    }
}

/// Feeds every item of `events` to `stream` until the input ends or `stop()` says so, as
/// [`crate::frames::feed`] feeds frames: bad events are counted, reported and skipped, and
/// the stream is not finished.
///
/// # Errors
/// As [`EventInput::next_item`]; the model could not classify a window; `sink` failed.
pub fn feed_events(
    events: &mut dyn EventInput,
    stream: &mut StreamClassifier,
    mut replay: Option<Replay>,
    sink: &mut dyn Sink,
    stop: &dyn Fn() -> bool,
) -> Result<()> {
    let unit = events.unit();
    loop {
        let done = match events.next_item(stop)? {
            None => return Ok(()),
            Some(Item::Reset) => stream.reset(),
            Some(Item::Bad { place, why }) => {
                stream.skip_bad_frame();
                sink.bad_frame(&place, &why);
                continue;
            }
            Some(Item::Event { stamp, address }) => {
                if let Some(r) = replay.as_mut() {
                    r.wait(unit.to_seconds(stamp.as_f64()));
                }
                stream.push_event(stamp, address)
            }
        };
        let done = done.map(<[_]>::to_vec);
        crate::frames::pass_on(done, stream, sink, &|| events.place())?;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn items(text: &str, format: &EventsFormat) -> Vec<Item> {
        let mut reader = EventReader::new(text.as_bytes(), "test", EventEncoding::Text, format);
        let mut out = Vec::new();
        while let Some(item) = reader.next(&|| false).unwrap() {
            out.push(item);
        }
        out
    }

    fn event(t: i64, x: i64, y: i64, p: Option<i64>) -> Item {
        Item::Event {
            stamp: Stamp::Int(t),
            address: Some((x, y, p)),
        }
    }

    #[test]
    fn lines_with_and_without_a_header_ticks_and_resets() {
        let format = EventsFormat::new(TimeUnit::Microseconds);
        let tick = |t| Item::Event {
            stamp: Stamp::Int(t),
            address: None,
        };
        // A header in another order, a tick written two ways, a comment, a reset.
        let text = "p;y;t;x\n1;2;10;3\n# note\n;;20;\nreset\n0; 1; 30; 0\n";
        let got = items(text, &format);
        let want = [
            event(10, 3, 2, Some(1)),
            tick(20),
            Item::Reset,
            event(30, 0, 1, Some(0)),
        ];
        assert_eq!(got, want);
        // No header: t, x, y and an optional polarity; a time alone is a tick; decimals.
        // Every line has the first one's fields.
        let got = items("5 1 2\n6\n7.5 0 0\n8 0 0 1\n", &format);
        assert_eq!(got[0], event(5, 1, 2, None));
        assert_eq!(got[1], tick(6));
        assert_eq!(
            got[2],
            Item::Event {
                stamp: Stamp::Float(7.5),
                address: Some((0, 0, None))
            }
        );
        assert!(
            matches!(&got[3], Item::Bad { why, .. } if why == "4 fields; the stream's lines have 3")
        );
        // Taxel-indexed: t, taxel, p.
        let mut taxels = format.clone();
        taxels.taxel = Some("taxel".into());
        assert_eq!(
            items("t,taxel,p\n9,4,0\n", &taxels),
            [event(9, 4, 0, Some(0))]
        );
    }

    #[test]
    fn undecodable_lines_and_records_are_bad_and_named() {
        let format = EventsFormat::new(TimeUnit::Microseconds);
        let got = items("t,x,y,p\nsoon,1,1,1\n5,1,,1\n6,1.5,1,1\n", &format);
        let whys: Vec<String> = got
            .iter()
            .map(|i| match i {
                Item::Bad { place, why } => format!("{place}: {why}"),
                other => panic!("{other:?}"),
            })
            .collect();
        assert!(whys[0].starts_with("line 2: time `soon`"), "{whys:?}");
        assert!(whys[1].contains("half a cell"), "{whys:?}");
        assert!(whys[2].contains("`1.5` is not a whole number"), "{whys:?}");
        let mut reader = EventReader::new(&b"t,x\n"[..], "test", EventEncoding::Text, &format);
        let err = reader.next(&|| false).unwrap_err().to_string();
        assert!(err.contains("no column `y`"), "{err}");
        // A record cut short, and one of an unknown kind.
        let mut bytes = vec![0u8; RECORD_BYTES];
        bytes[13] = 9;
        bytes.extend_from_slice(&[1, 2, 3]);
        let mut reader = EventReader::new(&bytes[..], "test", EventEncoding::Binary, &format);
        let first = reader.next(&|| false).unwrap().unwrap();
        assert!(matches!(first, Item::Bad { ref why, .. } if why.contains("kind 9")));
        let second = reader.next(&|| false).unwrap().unwrap();
        assert!(
            matches!(second, Item::Bad { ref place, ref why } if place == "record 2" && why.contains("3 of its 16"))
        );
        assert_eq!(reader.next(&|| false).unwrap(), None);
    }

    #[test]
    fn marker_strings_are_events_ticks_and_resets() {
        assert_eq!(marker_item(1.5, "reset", false), Ok(Item::Reset));
        let tick = marker_item(1.5, "", false).unwrap();
        assert_eq!(
            tick,
            Item::Event {
                stamp: Stamp::Float(1.5),
                address: None
            }
        );
        let e = marker_item(2.0, "3, 1, 0", false).unwrap();
        assert_eq!(
            e,
            Item::Event {
                stamp: Stamp::Float(2.0),
                address: Some((3, 1, Some(0)))
            }
        );
        let t = marker_item(2.0, "7", true).unwrap();
        assert_eq!(
            t,
            Item::Event {
                stamp: Stamp::Float(2.0),
                address: Some((7, 0, None))
            }
        );
    }
}
