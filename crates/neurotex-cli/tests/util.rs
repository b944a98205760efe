//! What every CLI test needs (after ripgrep's `tests/util.rs`): a temporary folder to run
//! the real `neurotex` binary in, its exit status and output, and small datasets written
//! there.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus};

use ndarray::Array3;
use ndarray_npy::write_npy;
use serde_json::Value;

/// A temporary folder, removed when dropped, in which `neurotex` runs.
pub struct Dir {
    tmp: tempfile::TempDir,
}

/// One run of the binary.
pub struct Run {
    /// How it exited.
    pub status: ExitStatus,
    /// Standard output.
    pub stdout: String,
    /// Standard error.
    pub stderr: String,
}

impl Dir {
    /// A new, empty temporary folder.
    pub fn new() -> Dir {
        Dir {
            tmp: tempfile::tempdir().expect("a temporary folder"),
        }
    }

    /// The folder.
    pub fn path(&self) -> &Path {
        self.tmp.path()
    }

    /// `name` inside the folder.
    pub fn join(&self, name: &str) -> PathBuf {
        self.path().join(name)
    }

    /// Runs `neurotex args...` in the folder.
    pub fn run(&self, args: &[&str]) -> Run {
        let out = Command::new(env!("CARGO_BIN_EXE_neurotex"))
            .args(args)
            .current_dir(self.path())
            .output()
            .expect("the binary runs");
        Run {
            status: out.status,
            stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
            stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
        }
    }

    /// Runs a command that must succeed; returns its standard output.
    pub fn ok(&self, args: &[&str]) -> String {
        let run = self.run(args);
        assert!(
            run.status.success(),
            "neurotex {args:?} failed: {}",
            run.stderr
        );
        run.stdout
    }

    /// Trains a tiny spiking network (8 hidden neurons, 2 epochs) on `dataset` into `out`,
    /// with `extra` flags; the command must succeed.
    pub fn train_tiny_snn(&self, dataset: &Path, out: &Path, extra: &[&str]) {
        let mut args = vec!["train", "--dataset", s(dataset), "--classifier", "snn"];
        args.extend(["--snn-hidden", "8", "--snn-epochs", "2", "--out", s(out)]);
        args.extend_from_slice(extra);
        self.ok(&args);
    }

    /// Runs `neurotex train --dataset DATASET --classifier snn --out OUT EXTRA...`, which
    /// must fail; returns what it says on standard error.
    pub fn train_snn_fails(&self, dataset: &Path, out: &Path, extra: &[&str]) -> String {
        let args = [
            "train",
            "--dataset",
            s(dataset),
            "--classifier",
            "snn",
            "--out",
            s(out),
        ];
        self.fails(&[&args[..], extra].concat())
    }

    /// Runs `neurotex predict --model MODEL --dataset DATASET --out OUT --json`, which must
    /// succeed; returns the JSON it prints.
    pub fn predict_json(&self, model: &Path, dataset: &Path, out: &Path) -> Value {
        let args = [
            "predict",
            "--model",
            s(model),
            "--dataset",
            s(dataset),
            "--out",
            s(out),
        ];
        let text = self.ok(&[&args[..], &["--json"]].concat());
        serde_json::from_str(&text).expect("predict --json prints JSON")
    }

    /// Runs `neurotex export FORMAT --model MODEL --out OUT`, which must be refused and
    /// leave no file at `OUT`; returns what it says on standard error.
    pub fn export_refused(&self, format: &str, model: &Path, out: &Path) -> String {
        let err = self.fails(&["export", format, "--model", s(model), "--out", s(out)]);
        assert!(!out.exists(), "a refused export wrote {}", out.display());
        err
    }

    /// Runs `neurotex evaluate --dataset DATASET --method METHOD EXTRA... --json`, which
    /// must succeed; returns the JSON it prints.
    pub fn evaluate_json(&self, dataset: &Path, method: &str, extra: &[&str]) -> Value {
        let mut args = vec!["evaluate", "--dataset", s(dataset), "--method", method];
        args.extend_from_slice(extra);
        args.push("--json");
        serde_json::from_str(&self.ok(&args)).expect("evaluate --json prints JSON")
    }

    /// Runs a command that must fail with an error, not a panic: exit code 1 (the run
    /// failed) or 2 (the command line is wrong), a message after `error:`. Returns standard
    /// error.
    pub fn fails(&self, args: &[&str]) -> String {
        let run = self.run(args);
        let err = run.stderr;
        assert!(!run.status.success(), "neurotex {args:?} should fail");
        assert!(
            matches!(run.status.code(), Some(1 | 2)),
            "neurotex {args:?} exited with {:?}: {err}",
            run.status.code()
        );
        assert!(
            !err.contains("panicked"),
            "neurotex {args:?} panicked: {err}"
        );
        assert!(err.starts_with("error:") || err.contains("error:"), "{err}");
        err
    }

    /// Runs every case, each expected to fail with its message and to leave `out` (an
    /// output file or folder) unwritten.
    pub fn fails_each(&self, cases: &[(Vec<&str>, &str)], out: &Path) {
        for (args, expected) in cases {
            let err = self.fails(args);
            assert!(
                err.contains(expected),
                "{args:?}: expected `{expected}` in {err}"
            );
            assert!(!out.exists(), "{args:?} left output behind at {out:?}");
        }
    }

    /// Writes a dataset folder `name` of `labels` classes x `trials` at each speed, 1.4 s
    /// recordings of [`recording`] gratings whose period grows with the class and
    /// shrinks with the speed, with the sliding phase from 0.1 s to 1.3 s.
    pub fn dataset(&self, name: &str, labels: &[&str], speeds: &[f64], trials: usize) -> PathBuf {
        let dir = self.join(name);
        std::fs::create_dir_all(&dir).unwrap();
        let mut manifest =
            String::from("file,label,speed_mm_s,force_n,trial,slide_start_s,slide_end_s\n");
        for (k, label) in labels.iter().enumerate() {
            for &speed in speeds {
                for trial in 0..trials {
                    let file = format!("{label}_{speed}_{trial}.npy");
                    let period = (60.0 + 70.0 * k as f64) * 5.0 / speed;
                    let seed = (k * 1000 + trial) as u64 + speed as u64;
                    let rec = recording(1400, period, 0.2 + 0.1 * k as f64, seed);
                    write_npy(dir.join(&file), &rec).unwrap();
                    manifest.push_str(&format!("{file},{label},{speed},1,{trial},0.1,1.3\n"));
                }
            }
        }
        std::fs::write(dir.join("manifest.csv"), manifest).unwrap();
        dir
    }

    /// Whether any temporary `.partial` file or folder is left in the folder.
    pub fn partial_left(&self) -> bool {
        std::fs::read_dir(self.path())
            .unwrap()
            .any(|e| e.unwrap().file_name().to_string_lossy().contains("partial"))
    }
}

/// A texture-like 4x4 recording: a grating of `period_ms` sweeping across the rows, with
/// noise from a small generator seeded by `seed`.
pub fn recording(steps: usize, period_ms: f64, amp: f64, seed: u64) -> Array3<f32> {
    let mut random = xorshift(seed);
    Array3::from_shape_fn((steps, 4, 4), |(t, r, c)| {
        let noise = (random() % 1000) as f64 / 1000.0 - 0.5;
        let phase = (t as f64 - 40.0 * r as f64 - 7.0 * c as f64) / period_ms;
        (0.5 + amp * (std::f64::consts::TAU * phase).sin() + 0.2 * noise) as f32
    })
}

/// A small xorshift generator seeded by `seed` (any value, 0 included): each call returns
/// the next 64 random bits.
pub fn xorshift(seed: u64) -> impl FnMut() -> u64 {
    let mut state = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407)
        | 1;
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    }
}

/// Adds a CSV recording of label A at 5 mm/s to a dataset's manifest.
pub fn add_csv(dataset: &Path, name: &str, content: &str) {
    std::fs::write(dataset.join(name), content).unwrap();
    let mut m = std::fs::read_to_string(dataset.join("manifest.csv")).unwrap();
    m.push_str(&format!("{name},A,5,1,9,,\n"));
    std::fs::write(dataset.join("manifest.csv"), &m).unwrap();
}

/// A path as the `&str` argument the binary takes.
pub fn s(p: &Path) -> &str {
    p.to_str().expect("a UTF-8 path")
}

/// The FabricSlide fabric logs in `../shared` beside the repository. Tests that need them
/// are `#[ignore]`d and run by `.ci/run` with `--ignored`, so when the data is absent this
/// fails, saying so, rather than letting such a test pass without running.
pub fn fabricslide() -> PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/fabricslide/fabric");
    assert!(
        dir.is_dir(),
        "FabricSlide data not found at {}: this test needs ../shared beside the repository",
        dir.display()
    );
    dir
}

/// Labels each recording of a [`Dir::dataset`] folder by its trial number alone.
pub fn relabel(data: &Path, label_of: impl Fn(usize) -> &'static str) {
    let manifest = std::fs::read_to_string(data.join("manifest.csv")).unwrap();
    let mut lines = manifest.lines();
    let mut relabelled = format!("{}\n", lines.next().unwrap());
    for line in lines {
        let mut fields: Vec<&str> = line.split(',').collect();
        fields[1] = label_of(fields[4].parse().unwrap());
        relabelled.push_str(&format!("{}\n", fields.join(",")));
    }
    std::fs::write(data.join("manifest.csv"), relabelled).unwrap();
}

/// The numbers of a JSON array.
pub fn floats(v: &Value) -> Vec<f64> {
    let values = v.as_array().expect("a JSON array");
    values
        .iter()
        .map(|x| x.as_f64().expect("a number"))
        .collect()
}
