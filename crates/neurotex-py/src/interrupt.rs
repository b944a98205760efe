//! A Ctrl-C during a long call (`compare`, `benchmark`, `evaluate`, `train`, `reproduce`,
//! ...) stops the run at its next step and raises `KeyboardInterrupt`, as a Ctrl-C does in
//! Python code: the run does not go on to its end first.
//!
//! Python's own SIGINT handler only sets a flag that the main thread reads between
//! bytecodes, and the main thread is inside the native call, with the GIL released, until
//! the run returns. So while a workflow runs from the main thread and SIGINT is Python's
//! default (`signal.default_int_handler`), SIGINT is taken here instead: the handler asks
//! the library to stop (`neurotex::progress::request_stop`, an atomic store, safe in a
//! signal handler), and the run unwinds at its next step (`stop_point`: each recording's
//! encoding, each step of a comparison, each fold, each epoch of the network, and each
//! event it reports to [`crate::model::Said`]) with a `Stopped` panic, which the call turns
//! into the exception. Unwinding drops the run's temporary files and folders, which remove
//! themselves; a benchmark's finished pieces stay, and the exception names where. Python's
//! handler is put back before the call returns, whatever happened. A call from another
//! thread, or with a handler of the user's own, is left as it was: the Ctrl-C then takes
//! effect when the call returns. Why a panic, and why process-wide:
//! docs/decisions/0030-a-stop-asked-of-a-run-ends-it-at-its-next-step.md.

use std::sync::atomic::{AtomicBool, Ordering};

use neurotex::progress::{request_stop, take_stop, Stopped};
use pyo3::exceptions::PyKeyboardInterrupt;
use pyo3::prelude::*;

/// Whether a run is watched now (a call made while another is watched is not).
static WATCHING: AtomicBool = AtomicBool::new(false);

/// The exception a stopped run's call raises.
pub(crate) fn stopped_error(stopped: &Stopped) -> PyErr {
    let kept = stopped
        .0
        .replace("the same command, run again,", "the same call, made again,");
    PyKeyboardInterrupt::new_err(format!("neurotex: the run stopped; {kept}"))
}

/// Keeps the report of a [`Stopped`] panic off standard error: the exception says it.
/// Other panics are reported as before. Called once, when the module is loaded.
pub(crate) fn quiet_panic_hook() {
    let previous = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        if !info.payload().is::<Stopped>() {
            previous(info);
        }
    }));
}

/// Runs `run` with the GIL released, as `py.detach` does, stopping it at its next step
/// when Ctrl-C is pressed (see the module's documentation).
///
/// # Errors
/// `run`'s, or `KeyboardInterrupt` after a Ctrl-C.
pub(crate) fn watched<T, F>(py: Python<'_>, run: F) -> PyResult<T>
where
    F: FnOnce() -> PyResult<T> + Send,
    T: Send,
{
    let handler = watch(py)?;
    let result = py.detach(run);
    let stopped = handler.is_some() && take_stop();
    drop(handler);
    match result {
        Err(e) if e.is_instance_of::<PyKeyboardInterrupt>(py) => Err(e),
        // A Ctrl-C after the run's last step: the call still ends as one.
        _ if stopped => Err(PyKeyboardInterrupt::new_err(
            "neurotex: the run had ended; its result is dropped",
        )),
        result => result,
    }
}

/// Takes SIGINT for the run when the call comes from the main thread and SIGINT is
/// Python's default; `None` otherwise.
fn watch(py: Python<'_>) -> PyResult<Option<handler::Installed>> {
    let threading = py.import("threading")?;
    let main = threading
        .call_method0("current_thread")?
        .is(&threading.call_method0("main_thread")?);
    let signal = py.import("signal")?;
    let sigint = signal.getattr("SIGINT")?;
    let default = signal
        .call_method1("getsignal", (sigint,))?
        .is(&signal.getattr("default_int_handler")?);
    if !(main && default) || WATCHING.swap(true, Ordering::SeqCst) {
        return Ok(None);
    }
    take_stop();
    let installed = handler::install();
    if installed.is_none() {
        WATCHING.store(false, Ordering::SeqCst);
    }
    Ok(installed)
}

#[cfg(unix)]
mod handler {
    use std::sync::atomic::Ordering;

    /// SIGINT taken from Python: Python's handler, put back when dropped.
    pub(super) struct Installed(libc::sigaction);

    extern "C" fn on_signal(_: libc::c_int) {
        super::request_stop();
    }

    /// Installs [`on_signal`] for SIGINT; `None` when the system refuses.
    pub(super) fn install() -> Option<Installed> {
        // SAFETY: zeroed `sigaction`s are valid values; `on_signal` only stores to an
        // atomic (`request_stop`), which is async-signal-safe; the previous action is
        // kept to be restored.
        unsafe {
            let mut ours: libc::sigaction = std::mem::zeroed();
            ours.sa_sigaction = on_signal as extern "C" fn(libc::c_int) as libc::sighandler_t;
            libc::sigemptyset(&mut ours.sa_mask);
            ours.sa_flags = libc::SA_RESTART;
            let mut previous: libc::sigaction = std::mem::zeroed();
            match libc::sigaction(libc::SIGINT, &ours, &mut previous) {
                0 => Some(Installed(previous)),
                _ => None,
            }
        }
    }

    impl Drop for Installed {
        fn drop(&mut self) {
            // SAFETY: `self.0` is the action `sigaction` returned, so restoring it is valid.
            unsafe { libc::sigaction(libc::SIGINT, &self.0, std::ptr::null_mut()) };
            super::WATCHING.store(false, Ordering::SeqCst);
        }
    }
}

#[cfg(not(unix))]
mod handler {
    /// No handler is taken off Python here: the Ctrl-C takes effect when the call returns.
    pub(super) struct Installed;

    pub(super) fn install() -> Option<Installed> {
        None
    }
}
