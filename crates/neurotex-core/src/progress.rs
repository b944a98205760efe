//! Progress of a long workflow (`reproduce`'s analyses, `compare`'s candidates), as events
//! a front end turns into a progress bar or log lines, and a stop a front end may ask of
//! them.

use std::sync::atomic::{AtomicBool, Ordering};

/// One event of a long workflow's progress.
#[derive(Debug, Clone, Copy)]
pub enum Progress<'a> {
    /// A stage begins with this many steps.
    Stage(&'a str, usize),
    /// One step of the current stage is done.
    Tick,
    /// One step of the current stage is done: the named analysis (id, what it asks) ended.
    Done(&'a str, &'a str),
    /// One step of the current stage is done: the named analysis (id, what it asks) was
    /// skipped, for the reason given.
    Skipped(&'a str, &'a str, &'a str),
    /// The design is too small for the folds or neighbours asked for, found before any
    /// recording is read: the analyses resting on the cross-validation within each speed
    /// will be skipped for this error.
    TooSmall(&'a crate::Error),
    /// What the recordings suggest changing (most taxels silent or at the encoder's
    /// ceiling), said at once rather than only in the report.
    Advice(&'a str),
    /// A line for the user as it stands (`note: ...`, or what a calibration chose).
    Say(&'a str),
}

/// A progress callback that ignores every event.
pub fn silent(_: Progress) {}

/// Whether a stop was asked of the running workflows ([`request_stop`]).
///
/// Process-wide on purpose, as the temporaries' registry is: the one asking is a signal
/// handler (a Ctrl-C in a Python session), which has no handle on the call that is
/// running nor on its threads. No result depends on it: a run either ends as it would have,
/// or does not end at all.
static STOP: AtomicBool = AtomicBool::new(false);

/// Asks every running workflow to stop at its next step ([`stop_point`]). Only an atomic
/// store, so a signal handler may call it.
pub fn request_stop() {
    STOP.store(true, Ordering::SeqCst);
}

/// Takes back a request to stop, and says whether there was one.
pub fn take_stop() -> bool {
    STOP.swap(false, Ordering::SeqCst)
}

/// The payload of the panic with which a step ends a run asked to stop: what the run kept,
/// in the words of [`crate::io::interrupted_note`], taken while the run's kept work is
/// still noted.
#[derive(Debug, Clone)]
pub struct Stopped(pub String);

/// Ends the run here when a stop was asked ([`request_stop`]), by a panic whose payload is
/// [`Stopped`]; the front end that asked catches it. The long loops call it at the start of
/// each step (a candidate on a part of a comparison, an outer split's inner ranking, a fold
/// of a cross-validation, a recording's encoding), so that steps not yet begun on other
/// threads end at once rather than each running before the panic reaches the caller.
/// Unwinding drops the run's temporary files, which remove themselves. The command line
/// never asks: a signal ends its process. (docs/decisions/0030: why a panic.)
pub fn stop_point() {
    if STOP.load(Ordering::Relaxed) {
        std::panic::panic_any(Stopped(crate::io::interrupted_note()));
    }
}
