//! `neurotex stream`: a causal model classifies a live taxel stream frame by frame and
//! prints one JSON line per bin boundary and one per episode's end.

use std::io::Write;

use anyhow::Result;
use neurotex::saved::SavedModel;
use neurotex::stream::events::{feed_events, EventEncoding, EventReader, EventSource};
use neurotex::stream::frames::{event_json, feed, FrameReader, Replay, Sink};
use neurotex::stream::{Event, StreamClassifier};
use neurotex::workflows::stream::StreamOptions;

/// Runs `neurotex stream`.
pub fn run(args: StreamOptions) -> Result<()> {
    let model = SavedModel::load(&args.model, args.like.as_deref())?;
    if let Some((encoding, source)) = args.event_source(&model)? {
        return run_events(&args, model, encoding, source);
    }
    if let Some(why) = neurotex::stream::events::trained_on_events(&model) {
        anyhow::bail!("{}: {why}", args.model.display());
    }
    if let Err(why) = model.streams() {
        let from = match &args.like {
            Some(like) => format!(
                "{} (its pipeline from {})",
                args.model.display(),
                like.display()
            ),
            None => args.model.display().to_string(),
        };
        anyhow::bail!("{from}: {why}");
    }
    let params = args.params(&model)?;
    let format = args.frame_format(&model)?;
    let mut stream = StreamClassifier::new(model, params)?;
    let input = neurotex::stream::input::open(&args.input, &|said| eprintln!("{said}"))?;
    let mut frames = FrameReader::new(input, &args.input, format, stream.channels());
    let mut out = Output {
        out: std::io::stdout().lock(),
        episodes: 0,
    };
    let replay = args
        .realtime
        .then(|| Replay::new(stream.params().max_gap_s));
    crate::interrupt::end_input_on_signal();
    let stop = crate::interrupt::stop_requested;
    feed(&mut frames, &mut stream, replay, &mut out, &stop)?;
    let events = finish(&mut stream, stop())?;
    out.events(&stream, &events)?;
    eprintln!(
        "{} frames, {} bad frame(s) skipped, {} episode(s)",
        stream.frames(),
        stream.bad_frames(),
        out.episodes
    );
    Ok(())
}

/// Runs `neurotex stream` on address events.
fn run_events(
    args: &StreamOptions,
    model: SavedModel,
    encoding: EventEncoding,
    source: EventSource,
) -> Result<()> {
    let params = args.params(&model)?;
    let format = source.format.clone();
    let mut stream = StreamClassifier::for_events(model, params, source)?;
    let input = neurotex::stream::input::open(&args.input, &|said| eprintln!("{said}"))?;
    let mut events = EventReader::new(input, &args.input, encoding, &format);
    let mut out = Output {
        out: std::io::stdout().lock(),
        episodes: 0,
    };
    let replay = args
        .realtime
        .then(|| Replay::new(stream.params().max_gap_s));
    crate::interrupt::end_input_on_signal();
    let stop = crate::interrupt::stop_requested;
    feed_events(&mut events, &mut stream, replay, &mut out, &stop)?;
    let ended = finish(&mut stream, stop())?;
    out.events(&stream, &ended)?;
    eprintln!(
        "{} events ({} in a millisecond their cell already spiked in), {} bad event(s) skipped, {} episode(s)",
        stream.frames(),
        stream.merged_events(),
        stream.bad_frames(),
        out.episodes
    );
    Ok(())
}

/// Ends the stream: stopped by a signal, or at the end of its input.
fn finish(stream: &mut StreamClassifier, stopped: bool) -> Result<Vec<Event>> {
    let events = match stopped {
        true => {
            eprintln!("interrupted: the stream stopped at its next frame");
            stream.stop()
        }
        false => stream.finish(),
    };
    Ok(events.map_err(anyhow::Error::new)?.to_vec())
}

/// The JSON lines on standard output, one per bin boundary and one per episode's end,
/// each flushed at once; bad frames said on standard error.
struct Output<W: Write> {
    out: W,
    /// Episodes ended so far.
    episodes: usize,
}

impl<W: Write> Sink for Output<W> {
    fn events(&mut self, stream: &StreamClassifier, events: &[Event]) -> neurotex::Result<()> {
        let write = |e| neurotex::error::DataError::write("standard output", e);
        for event in events {
            self.episodes += usize::from(matches!(event, Event::End(_)));
            writeln!(self.out, "{}", event_json(stream, event)).map_err(write)?;
        }
        self.out.flush().map_err(write)?;
        Ok(())
    }

    fn bad_frame(&mut self, place: &str, why: &str) {
        eprintln!("warning: {place}: bad frame skipped: {why}");
    }
}
