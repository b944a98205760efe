//! Outputs whole or not at all (SPEC 8, issue 14): a failed or interrupted run leaves no
//! output file or folder and no temporary one.

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

/// Runs `neurotex ARGS` under `ulimit -f BLOCKS` with SIGXFSZ ignored, so that writing
/// past the limit fails as on a full disk.
fn run_with_file_limit(dir: &Dir, blocks: u32, args: &[&str]) -> std::process::Output {
    let script = format!("trap '' XFSZ; ulimit -f {blocks}; exec \"$0\" \"$@\"");
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
    // a full disk (a file size limit), into a new folder and into an earlier report
    let run = run_with_file_limit(&dir, 4, &quick("report"));
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("File too large"), "{stderr}");
    assert_eq!(names(dir.path()), ["ds", "file"]);
    std::fs::create_dir(dir.join("report")).unwrap();
    std::fs::write(dir.join("report/notes.txt"), "mine").unwrap();
    let run = run_with_file_limit(&dir, 4, &quick("report"));
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("File too large"), "{stderr}");
    assert_eq!(names(dir.path()), ["ds", "file", "report"]);
    assert_eq!(names(&dir.join("report")), ["notes.txt"]);
    // with room, the report lands beside what was there
    dir.ok(&quick("report"));
    let written = names(&dir.join("report"));
    assert_eq!(
        written,
        ["figures", "notes.txt", "report.md", "results.json"]
    );
    assert!(!names(&dir.join("report/figures")).is_empty());
    assert_eq!(names(dir.path()), ["ds", "file", "report"]);
}

fn set_mode(path: &Path, mode: u32) {
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(mode)).unwrap();
}
