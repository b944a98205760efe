//! Progress of a long workflow (`reproduce`'s analyses, `compare`'s candidates), as events
//! a front end turns into a progress bar or log lines.

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
