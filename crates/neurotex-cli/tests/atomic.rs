//! Outputs whole or not at all
//! (docs/decisions/0012-outputs-whole-and-never-over-what-is-not-theirs.md): a failed or
//! interrupted run leaves no output file or folder and no temporary one.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use ndarray_npy::write_npy;

use crate::util::{recording, s, Dir};

/// The names in `dir`, sorted.
fn names(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn a_failed_encode_writes_no_events_file() {
    let dir = Dir::new();
    let input = dir.join("in.npy");
    write_npy(&input, &recording(300, 80.0, 0.3, 1)).unwrap();
    let events = dir.join("events.csv");
    // the raster's folder is missing: the events, written first, must not stay
    dir.fails(&[
        "encode",
        s(&input),
        "--out",
        "missing/spikes.npy",
        "--events",
        s(&events),
    ]);
    assert_eq!(names(dir.path()), ["in.npy"]);
    // and the other way round
    dir.fails(&[
        "encode",
        s(&input),
        "--out",
        "spikes.npy",
        "--events",
        "missing/events.csv",
    ]);
    assert_eq!(names(dir.path()), ["in.npy"]);
}

/// Starts `neurotex simulate --out ds`, sends `signal` once its temporary folder exists,
/// and checks that it exits with 130 leaving nothing behind.
fn interrupt_simulate(signal: &str) {
    let dir = Dir::new();
    let mut child = Command::new(env!("CARGO_BIN_EXE_neurotex"))
        .args(["simulate", "--out", "out/ds", "--trials", "40"])
        .current_dir(dir.path())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let started = Instant::now();
    let out = dir.join("out");
    while !(out.is_dir() && names(&out).iter().any(|n| n.starts_with(".ds.partial-"))) {
        assert!(child.try_wait().unwrap().is_none(), "simulate ended first");
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "no temporary folder"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    let pid = child.id().to_string();
    let kill = Command::new("kill").args([signal, &pid]).status().unwrap();
    assert!(kill.success());
    let output = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(130), "{signal}: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    // the temporary folder is gone, and so is `out`, which the run created
    assert!(names(dir.path()).is_empty(), "{:?}", names(dir.path()));
}

#[test]
fn sigint_and_sigterm_during_simulate_leave_nothing_behind() {
    interrupt_simulate("-INT");
    interrupt_simulate("-TERM");
}

/// Runs `neurotex ARGS` under `ulimit -f BLOCKS`, so that writing past the limit fails as
/// on a full disk. The shell leaves SIGXFSZ at its default (killing the process): the
/// binary must ignore it itself to turn the limit into an error it reports.
fn run_with_file_limit(dir: &Dir, blocks: u32, args: &[&str]) -> std::process::Output {
    let script = format!("trap - XFSZ; ulimit -f {blocks}; exec \"$0\" \"$@\"");
    Command::new("sh")
        .arg("-c")
        .arg(script)
        .arg(env!("CARGO_BIN_EXE_neurotex"))
        .args(args)
        .current_dir(dir.path())
        .output()
        .unwrap()
}

#[test]
fn reproduce_that_cannot_write_leaves_no_partial_output() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[5.0], 5);
    let ds = s(&ds).to_string();
    let quick = |out: &'static str| {
        [
            "reproduce",
            "--dataset",
            ds.as_str(),
            "--out",
            out,
            "--quick",
        ]
    };
    // the output's folder is a file
    std::fs::write(dir.join("file"), "x").unwrap();
    dir.fails(&quick("file/report"));
    assert_eq!(names(dir.path()), ["ds", "file"]);
    // a read-only folder (root may write anyway: then there is nothing to check)
    let ro = dir.join("ro");
    std::fs::create_dir(&ro).unwrap();
    set_mode(&ro, 0o555);
    if std::fs::write(ro.join("probe"), "").is_err() {
        dir.fails(&quick("ro/report"));
        assert!(names(&ro).is_empty());
    }
    set_mode(&ro, 0o755);
    let _ = std::fs::remove_file(ro.join("probe"));
    std::fs::remove_dir(&ro).unwrap();
    // a full disk (a file size limit) into a new folder: an error naming the report's
    // file, not the hidden temporary, and nothing left
    let run = run_with_file_limit(&dir, 4, &quick("report"));
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("cannot write report/"), "{stderr}");
    assert!(stderr.contains("File too large"), "{stderr}");
    assert!(!stderr.contains("partial"), "{stderr}");
    assert_eq!(names(dir.path()), ["ds", "file"]);
    // a folder holding something a report does not write is refused before any work
    std::fs::create_dir(dir.join("report")).unwrap();
    std::fs::write(dir.join("report/notes.txt"), "mine").unwrap();
    let err = dir.fails(&quick("report"));
    assert!(err.contains("holds notes.txt"), "{err}");
    assert_eq!(names(&dir.join("report")), ["notes.txt"]);
    std::fs::remove_file(dir.join("report/notes.txt")).unwrap();
    // an earlier report is replaced whole, and a run that cannot write leaves it as it was
    dir.ok(&quick("report"));
    let earlier = names(&dir.join("report/figures"));
    let record = std::fs::read(dir.join("report/.neurotex-output")).unwrap();
    let run = run_with_file_limit(&dir, 4, &quick("report"));
    assert_eq!(run.status.code(), Some(1));
    assert_eq!(names(&dir.join("report/figures")), earlier);
    assert_eq!(
        std::fs::read(dir.join("report/.neurotex-output")).unwrap(),
        record
    );
    assert_eq!(names(dir.path()), ["ds", "file", "report"]);
    dir.ok(&quick("report"));
    // a file of the user's among the figures, or a report edited since, is not replaced
    for (path, why) in [
        ("report/figures/my_plot.svg", "did not write"),
        ("report/report.md", "changed since"),
    ] {
        std::fs::write(dir.join(path), "mine").unwrap();
        let err = dir.fails(&quick("report"));
        assert!(err.contains(why), "{err}");
        assert_eq!(std::fs::read_to_string(dir.join(path)).unwrap(), "mine");
        std::fs::remove_file(dir.join(path)).unwrap();
    }
    // a file of the earlier report removed since is no obstacle
    dir.ok(&quick("report"));
    assert_eq!(
        names(&dir.join("report")),
        [".neurotex-output", "figures", "report.md", "results.json"]
    );
    assert_eq!(names(dir.path()), ["ds", "file", "report"]);
}

fn set_mode(path: &Path, mode: u32) {
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(mode)).unwrap();
}

/// The file type of `path` itself (a link is not followed).
fn kind(path: &Path) -> std::fs::FileType {
    std::fs::symlink_metadata(path).unwrap().file_type()
}

#[test]
fn outputs_never_replace_a_device_a_link_or_an_input() {
    use std::os::unix::fs::FileTypeExt;
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[5.0], 5);
    let features = |out: &str| -> Vec<String> {
        [
            "features",
            "--dataset",
            s(&ds),
            "--method",
            "glcm3d",
            "--out",
            out,
        ]
        .map(String::from)
        .to_vec()
    };
    let run_ok = |args: Vec<String>| dir.ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let run_fails =
        |args: Vec<String>| dir.fails(&args.iter().map(String::as_str).collect::<Vec<_>>());
    // a device is written through, not renamed over (as root, a rename would succeed and
    // turn /dev/null into a file for every process)
    run_ok(features("/dev/null"));
    assert!(kind(Path::new("/dev/null")).is_char_device());
    // a symbolic link keeps linking: its target gets the new content
    std::fs::write(dir.join("target.csv"), "old").unwrap();
    std::os::unix::fs::symlink("target.csv", dir.join("link.csv")).unwrap();
    run_ok(features("link.csv"));
    assert!(kind(&dir.join("link.csv")).is_symlink());
    let written = std::fs::read_to_string(dir.join("target.csv")).unwrap();
    assert!(written.starts_with("file,label"), "{written}");
    // a dangling link, a file with another hard link and a folder are refused, untouched
    std::os::unix::fs::symlink("missing.csv", dir.join("dangling.csv")).unwrap();
    let err = run_fails(features("dangling.csv"));
    assert!(err.contains("missing.csv, which does not exist"), "{err}");
    assert!(!dir.join("missing.csv").exists());
    std::fs::hard_link(dir.join("target.csv"), dir.join("second.csv")).unwrap();
    let err = run_fails(features("second.csv"));
    assert!(err.contains("2 hard links"), "{err}");
    assert!(kind(&dir.join("second.csv")).is_file());
    std::fs::create_dir(dir.join("folder")).unwrap();
    let err = run_fails(features("folder"));
    assert!(err.contains("is a folder"), "{err}");
    // an output that is one of the inputs, by its name or through a link
    let manifest = std::fs::read(ds.join("manifest.csv")).unwrap();
    let err = run_fails(features(s(&ds.join("manifest.csv"))));
    assert!(err.contains("is also an input"), "{err}");
    std::os::unix::fs::symlink(ds.join("manifest.csv"), dir.join("m.csv")).unwrap();
    let err = run_fails(features("m.csv"));
    assert!(err.contains("same file as input"), "{err}");
    assert_eq!(std::fs::read(ds.join("manifest.csv")).unwrap(), manifest);
    let recording = ds.join("A_5_0.npy");
    let before = std::fs::read(&recording).unwrap();
    let err = dir.fails(&["encode", s(&recording), "--out", s(&recording)]);
    assert!(err.contains("is also an input"), "{err}");
    let err = dir.fails(&[
        "encode",
        s(&recording),
        "--out",
        "x.npy",
        "--events",
        "x.npy",
    ]);
    assert!(err.contains("name the same file"), "{err}");
    assert_eq!(std::fs::read(&recording).unwrap(), before);
    dir.ok(&["train", "--dataset", s(&ds), "--out", "model.json"]);
    let model = std::fs::read(dir.join("model.json")).unwrap();
    let err = dir.fails(&[
        "predict",
        "--model",
        "model.json",
        "--dataset",
        s(&ds),
        "--out",
        "model.json",
    ]);
    assert!(err.contains("is also an input"), "{err}");
    let err = dir.fails(&["train", "--dataset", s(&ds), "--out", s(&recording)]);
    assert!(err.contains("is also an input"), "{err}");
    assert_eq!(std::fs::read(dir.join("model.json")).unwrap(), model);
    assert_eq!(std::fs::read(&recording).unwrap(), before);
    assert!(!dir.partial_left());
}

#[test]
fn a_full_disk_is_an_error_even_where_sigxfsz_would_kill() {
    let dir = Dir::new();
    let ds = dir.dataset("ds", &["A", "B"], &[5.0], 3);
    let run = run_with_file_limit(
        &dir,
        1,
        &[
            "features",
            "--dataset",
            s(&ds),
            "--method",
            "all-taxels",
            "--out",
            "f.csv",
        ],
    );
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("cannot write f.csv: File too large"),
        "{stderr}"
    );
    assert_eq!(stderr.matches("File too large").count(), 1, "{stderr}");
    assert_eq!(names(dir.path()), ["ds"]);
}

#[test]
fn temporaries_of_a_killed_run_are_removed_by_the_next() {
    let dir = Dir::new();
    // what `kill -9` during `simulate --out out/ds` leaves: a temporary folder whose
    // process is gone (no process has a PID this large)
    let stale = dir.join("out/.ds.partial-4194999");
    std::fs::create_dir_all(stale.join("inner")).unwrap();
    std::fs::write(stale.join("inner/x.npy"), "x").unwrap();
    // and one of a process that still runs (this test's): left alone
    let live = dir.join(&format!("out/.ds.partial-{}", std::process::id()));
    std::fs::create_dir(&live).unwrap();
    dir.ok(&["simulate", "--out", "out/ds", "--trials", "1"]);
    let left = names(&dir.join("out"));
    assert_eq!(
        left,
        [
            format!(".ds.partial-{}", std::process::id()),
            "ds".to_string()
        ]
    );
}

#[test]
fn an_earlier_output_set_aside_by_a_killed_run_is_removed_by_the_next() {
    let dir = Dir::new();
    dir.dataset("data", &["A", "B"], &[5.0], 5);
    let inspect = |out: &str| dir.ok(&["inspect", "data", "--no-encoder", "--out", out]);
    inspect("fresh");
    // What `kill -9` between replace's two renames leaves: the earlier output moved aside
    // as `.rep.old-PID` and the new one still `.rep.partial-PID`, of a process that is gone
    // (no process has a PID this large), and no `rep`.
    let old = dir.join(".rep.old-4194999");
    std::fs::create_dir(&old).unwrap();
    std::fs::write(old.join("inspect.md"), "the earlier report").unwrap();
    let partial = dir.join(".rep.partial-4194999");
    std::fs::create_dir(&partial).unwrap();
    std::fs::write(partial.join("inspect.md"), "the new report").unwrap();
    inspect("rep");
    assert_eq!(names(dir.path()), ["data", "fresh", "rep"]);
    assert_eq!(names(&dir.join("rep")), names(&dir.join("fresh")));
    let report = std::fs::read_to_string(dir.join("rep/inspect.md")).unwrap();
    assert_eq!(
        report,
        std::fs::read_to_string(dir.join("fresh/inspect.md")).unwrap()
    );
    // and when the earlier output is still in place beside such a leftover
    std::fs::create_dir(&old).unwrap();
    inspect("rep");
    assert_eq!(names(dir.path()), ["data", "fresh", "rep"]);
}
