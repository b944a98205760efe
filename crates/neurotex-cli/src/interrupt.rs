//! What SIGINT, SIGTERM and SIGHUP do: a run stops at once and removes its temporary files;
//! a stream that asked for it ends at its next frame with the episode's summary.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// The exit code after a signal (the shell's 128 + SIGINT).
const INTERRUPTED: i32 = 130;

/// How long a stream that handles the signal has to reach its next frame; an input that
/// stays silent longer ends the run as any other.
const GRACE: Duration = Duration::from_secs(2);

/// Set once a command takes the signal as the end of its input.
static GRACEFUL: AtomicBool = AtomicBool::new(false);

/// Set by the signal for such a command.
static STOP: AtomicBool = AtomicBool::new(false);

/// Installs the handler: with [`end_input_on_signal`] called, the signal asks the command to
/// stop ([`stop_requested`]) and the process exits after [`GRACE`] if it has not; otherwise
/// the run's temporary files and folders are removed (the library registers each one;
/// finished outputs are never among them) and the process exits with 130.
pub fn install() {
    ignore_file_size_signal();
    quiet_on_closed_pipe();
    let installed = ctrlc::set_handler(|| {
        if GRACEFUL.load(Ordering::SeqCst) && !STOP.swap(true, Ordering::SeqCst) {
            // The command ends by itself at its next frame; the process exits then.
            std::thread::sleep(GRACE);
            eprintln!(
                "interrupted: no frame arrived within {} s, so the episode ended without its summary",
                GRACE.as_secs()
            );
        }
        // Held until exit: no temporary is created or renamed into place after the clean-up.
        let _registry = neurotex::io::remove_temporaries();
        eprintln!("interrupted: {}", neurotex::io::interrupted_note());
        std::process::exit(INTERRUPTED);
    });
    if let Err(e) = installed {
        eprintln!("warning: an interrupted run may leave temporary files ({e})");
    }
}

/// Makes the signal the end of the input: the command checks [`stop_requested`] after each
/// frame and ends cleanly.
pub fn end_input_on_signal() {
    GRACEFUL.store(true, Ordering::SeqCst);
}

/// Whether a signal asked the command to stop.
pub fn stop_requested() -> bool {
    STOP.load(Ordering::Relaxed)
}

/// Makes a write beyond the file-size limit (`ulimit -f`) fail with `EFBIG`, which the run
/// reports as a write error (naming the output) and cleans up after, instead of the kernel's
/// SIGXFSZ killing the process with a half-written temporary left behind.
#[cfg(unix)]
fn ignore_file_size_signal() {
    // SAFETY: setting a standard signal's disposition to SIG_IGN installs no handler code;
    // it is done once, at start, before any other thread exists.
    unsafe {
        libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
    }
}

#[cfg(not(unix))]
fn ignore_file_size_signal() {}

/// Ends the process quietly when the reader of its standard output has gone
/// (`neurotex features --out - | head`), as other Unix tools do, instead of Rust's default
/// of ignoring SIGPIPE, which turns the next `println!` into a panic. Files are written to
/// temporaries and renamed before anything is printed, so a reader that stops early costs
/// no output file.
#[cfg(unix)]
fn quiet_on_closed_pipe() {
    // SAFETY: restoring a standard signal's default disposition installs no handler code;
    // it is done once, at start, before any other thread exists.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

#[cfg(not(unix))]
fn quiet_on_closed_pipe() {}
