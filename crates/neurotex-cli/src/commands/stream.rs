//! `neurotex stream`: a model classifies a live taxel or event stream frame by frame and
//! prints one JSON line per bin boundary and one per episode's end.

use anyhow::Result;
use neurotex::workflows::stream::{run_stream, StreamOptions, StreamTalk};

/// Runs `neurotex stream`.
pub fn run(args: StreamOptions) -> Result<()> {
    let mut out = std::io::stdout().lock();
    let talk = StreamTalk {
        out: &mut out,
        say: &|said| eprintln!("{said}"),
        stop: &crate::interrupt::stop_requested,
        opened: &crate::interrupt::end_input_on_signal,
    };
    Ok(run_stream(&args, talk)?)
}
