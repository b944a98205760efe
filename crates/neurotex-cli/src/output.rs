//! Writing files whole or not at all, and progress bars.

use std::io::Write;
use std::path::Path;

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressState, ProgressStyle};
use neurotex::experiments::WITHIN_SPEED;
use neurotex::progress::Progress;

/// The command line that is running, as `neurotex ...` with quoted arguments.
pub fn command_line() -> String {
    let quoted = |a: String| if a.contains(' ') { format!("'{a}'") } else { a };
    let command = std::env::args().map(quoted).collect::<Vec<_>>().join(" ");
    command.replacen(&std::env::args().next().unwrap_or_default(), "neurotex", 1)
}

/// Whether `path` is `-`: standard output, so that a table or predictions go down a pipe.
pub fn is_stdout(path: &Path) -> bool {
    path.as_os_str() == "-"
}

/// `path` as the messages name it: `standard output` for `-`.
pub fn shown(path: &Path) -> String {
    match is_stdout(path) {
        true => "standard output".to_string(),
        false => path.display().to_string(),
    }
}

/// Refuses `-` for an output folder (`option` names it): standard output takes one file.
pub fn check_folder(path: &Path, option: &str) -> Result<()> {
    if is_stdout(path) {
        anyhow::bail!(
            "{option} -: standard output takes one file, and {option} names a folder here; name the folder"
        );
    }
    Ok(())
}

/// Refuses `-` for `option`'s binary output (`what`) when standard output is a terminal,
/// where its bytes would only garble the screen.
pub fn check_binary(path: &Path, option: &str, what: &str) -> Result<()> {
    use std::io::IsTerminal;
    if is_stdout(path) && std::io::stdout().is_terminal() {
        anyhow::bail!(
            "{option} -: {what} is binary and standard output is a terminal; redirect it (`> FILE`) or name a file"
        );
    }
    Ok(())
}

/// Writes an output the library writes to a path (a model file, a NIR graph) to `path`, or
/// for `-` to standard output: into a temporary folder first, then copied, so standard
/// output gets the whole file or nothing.
pub fn save_to(
    path: &Path,
    what: &str,
    save: impl FnOnce(&Path) -> neurotex::Result<()>,
) -> Result<()> {
    if !is_stdout(path) {
        return Ok(save(path)?);
    }
    let name = format!(".neurotex-stdout.partial-{}", std::process::id());
    let tmp = neurotex::io::Temporary::new(std::env::temp_dir().join(name));
    std::fs::create_dir(tmp.path())
        .with_context(|| format!("creating {}", tmp.path().display()))?;
    let file = tmp.path().join("output");
    save(&file)?;
    let mut out = std::io::stdout().lock();
    std::fs::File::open(&file)
        .and_then(|mut f| std::io::copy(&mut f, &mut out))
        .and_then(|_| out.flush())
        .with_context(|| format!("writing {what} to standard output"))
}

/// Writes `what` to `path` through `fill` with the library's [`neurotex::io::write_atomic`]
/// (a temporary file beside it, renamed into place only when everything succeeded), or
/// to standard output for `-`.
pub fn write_file(
    path: &Path,
    what: &str,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    if is_stdout(path) {
        let mut out = std::io::BufWriter::new(std::io::stdout().lock());
        return fill(&mut out)
            .and_then(|()| out.flush())
            .with_context(|| format!("writing {what} to standard output"));
    }
    neurotex::io::write_atomic(path, fill).with_context(|| format!("writing {what}"))
}

/// Writes `what` for `path` through `fill` into a temporary file ([`neurotex::io::stage`]),
/// to be put in place by [`neurotex::io::Staged::commit`] once every output is written.
pub fn stage_file(
    path: &Path,
    what: &str,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<neurotex::io::Staged> {
    neurotex::io::stage(path, fill).with_context(|| format!("writing {what}"))
}

/// Checks, before any work, that output file `path` (not `-`, standard output) can be written and is none of `inputs`
/// ([`neurotex::io::check_output`]): neurotex never renames over a device, a link or a
/// file with other hard links, nor writes over what it reads.
pub fn check_output<P: AsRef<Path>>(path: &Path, inputs: &[P]) -> Result<()> {
    if is_stdout(path) {
        return Ok(());
    }
    neurotex::io::check_output(path, inputs).context("checking the output")
}

/// The time a stage has left: its elapsed time times the steps left over the steps done,
/// the average over the whole stage, said only once a fiftieth of it (and two steps) is
/// done. The first steps carry the stage's start-up (threads, first files) and a recent
/// rate extrapolates it: a tenth of a second's first step would promise minutes.
fn time_left(state: &ProgressState, w: &mut dyn std::fmt::Write) {
    let (pos, len) = (state.pos(), state.len().unwrap_or(0));
    let text = if pos >= 2 && pos * 50 >= len && pos < len {
        let left = state.elapsed().as_secs_f64() * (len - pos) as f64 / pos as f64;
        match left {
            s if s < 60.0 => format!("{s:.0} s left"),
            s => format!("{:.0} min left", s / 60.0),
        }
    } else if pos >= len && len > 0 {
        "done".to_string()
    } else {
        "estimating".to_string()
    };
    let _ = w.write_str(&text);
}

/// A progress bar on standard error, drawn only on a terminal.
pub fn progress(len: usize, what: &str) -> ProgressBar {
    let bar = ProgressBar::new(len as u64);
    bar.set_style(
        ProgressStyle::with_template("{msg:>12} [{bar:40}] {pos}/{len} ({left})")
            .expect("valid template")
            .with_key("left", time_left)
            .progress_chars("=> "),
    );
    bar.set_message(what.to_string());
    bar
}

/// Moves `bar` one step; where no bar is drawn (standard error is not a terminal), says
/// the step count on a line of its own at each tenth of the way once the stage has run a
/// second (`[   2.1 s] encoding 97/966`), so a log shows a long stage moving and a quick
/// one stays quiet.
pub fn tick(bar: &ProgressBar) {
    bar.inc(1);
    let (pos, len) = (bar.position(), bar.length().unwrap_or(0));
    let t = bar.elapsed().as_secs_f64();
    if bar.is_hidden() && t >= 1.0 && len >= 20 && (pos * 10 / len) != ((pos - 1) * 10 / len) {
        eprintln!("[{t:7.1} s] {} {pos}/{len}", bar.message());
    }
}

/// Moves the progress bar on one event of a long workflow; where no bar is drawn (standard
/// error is not a terminal: a log file, a pipe), says each stage on a line of its own with
/// the time since the start, so a long run is never silent.
pub fn show_progress(bar: &ProgressBar, event: Progress) {
    match event {
        Progress::Stage(name, n) => {
            if bar.is_hidden() {
                eprintln!("[{:7.1} s] {name} ({n} steps)", bar.elapsed().as_secs_f64());
            }
            bar.set_length(n as u64);
            bar.set_position(0);
            bar.set_message(name.to_string());
        }
        Progress::Tick => tick(bar),
        Progress::Done(id, asks) => {
            bar.inc(1);
            if bar.is_hidden() {
                let t = bar.elapsed().as_secs_f64();
                eprintln!("[{t:7.1} s]   done: {id}, {asks}");
            }
        }
        Progress::Skipped(id, asks, _) => {
            bar.inc(1);
            if bar.is_hidden() {
                let t = bar.elapsed().as_secs_f64();
                eprintln!("[{t:7.1} s]   skipped: {id}, {asks} (the report says why)");
            }
        }
        Progress::Advice(text) => bar.suspend(|| eprintln!("warning: {text}")),
        Progress::Say(text) => bar.suspend(|| eprintln!("{text}")),
        Progress::TooSmall(error) => bar.suspend(|| {
            eprintln!("warning: {WITHIN_SPEED}, which cannot run: {error}; they are skipped");
            if let Some(hint) = crate::design_hint(error) {
                eprintln!("hint: {hint}");
            }
        }),
    }
}

/// A workflow's progress bar: its stages and steps drawn on a terminal (a line per stage
/// elsewhere), what it says on standard error.
pub struct Shown {
    bar: ProgressBar,
}

impl Shown {
    /// A bar showing `what` until the workflow's first stage names itself.
    pub fn new(what: &str) -> Self {
        Self {
            bar: progress(0, what),
        }
    }

    /// The callback the workflow reports on.
    pub fn callback(&self) -> impl Fn(Progress) + Sync + '_ {
        |event| show_progress(&self.bar, event)
    }

    /// Clears the bar once the workflow ended.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}
