//! Every reader over the fuzz seed corpus and deterministic mutations of it (bit flips,
//! truncations, huge numbers in headers and text, extreme binary words in records): an
//! error is fine, a panic is not. The readers: recordings (NPY, CSV), manifests, layouts,
//! datasets, both importers, event files (CSV, `.npy`), a live stream's event lines and
//! records, spiking model files and NIR graphs. The readers'
//! bodies are the fuzz targets' own (`fuzz/src/harness.rs`), so this stable test and
//! `cargo +nightly fuzz` exercise the same paths; see `fuzz/README.md` for the long run.

#[path = "../../../fuzz/src/harness.rs"]
#[allow(dead_code)]
mod harness;

use std::panic::{catch_unwind, AssertUnwindSafe};

/// Numbers put in place of each run of digits: past u64, past u32, zero, negative,
/// and the largest finite f64.
const HUGE: [&str; 6] = [
    "99999999999999999999",
    "18446744073709551615",
    "4294967296",
    "0",
    "-1",
    "1e308",
];

/// What a mutation did, for the failure message.
struct Mutant {
    what: String,
    bytes: Vec<u8>,
    /// Whether it sets a huge size (an NPY shape, a layout's rows, columns or channel map),
    /// which the readers must refuse before allocating.
    huge: bool,
}

/// The runs of ASCII digits in `bytes`, as (start, end), at most 24.
fn digit_runs(bytes: &[u8]) -> Vec<(usize, usize)> {
    let mut runs = Vec::new();
    let mut i = 0;
    while i < bytes.len() && runs.len() < 24 {
        if bytes[i].is_ascii_digit() {
            let start = i;
            while i < bytes.len() && bytes[i].is_ascii_digit() {
                i += 1;
            }
            runs.push((start, i));
        } else {
            i += 1;
        }
    }
    runs
}

/// Whether position `at` sets a size the readers' resource limits bound: inside an NPY
/// header (its shape), or on a `rows`, `cols` or `channel_map` line of a layout.
fn sets_unbounded_size(bytes: &[u8], at: usize) -> bool {
    let before = &bytes[..at];
    let in_npy_header = before
        .windows(6)
        .rposition(|w| w == b"\x93NUMPY")
        .is_some_and(|start| !bytes[start..at].contains(&b'\n'));
    let line_start = before
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |i| i + 1);
    let line = &bytes[line_start..at];
    let layout_size = [&b"rows"[..], b"cols", b"channel_map"]
        .iter()
        .any(|key| line.starts_with(key));
    in_npy_header || layout_size
}

/// Binary words put at aligned places of binary inputs (a stream's 16-byte event records,
/// an `.npy` event array's records, an HDF5 graph): the extremes of i64 and -1.
const WORDS: [i64; 3] = [i64::MAX, i64::MIN, -1];

/// The targets whose inputs are binary records, given [`WORDS`] too.
const BINARY: [&str; 3] = ["stream_events", "events_npy", "nir"];

/// The mutations of one seed of `target`.
fn mutants(target: &str, seed: &[u8]) -> Vec<Mutant> {
    let mut out = Vec::new();
    let n = seed.len();
    for i in (0..n).step_by((n / 48).max(1)) {
        let mut bytes = seed.to_vec();
        bytes[i] ^= 1 << (i % 8);
        out.push(Mutant {
            what: format!("bit {} of byte {i} flipped", i % 8),
            bytes,
            huge: false,
        });
    }
    for len in [0, 1, n / 4, n / 2, 3 * n / 4, n.saturating_sub(1)] {
        let bytes = seed[..len.min(n)].to_vec();
        out.push(Mutant {
            what: format!("cut to {len} bytes"),
            bytes,
            huge: false,
        });
    }
    if BINARY.contains(&target) {
        // After the flags byte, every 8 bytes: a stream record's stamp, then its address,
        // polarity and kind.
        for at in (1..n.saturating_sub(8)).step_by(8).take(24) {
            for word in WORDS {
                let mut bytes = seed.to_vec();
                bytes[at..at + 8].copy_from_slice(&word.to_le_bytes());
                out.push(Mutant {
                    what: format!("bytes {at}..{} set to {word} (i64, little-endian)", at + 8),
                    bytes,
                    huge: false,
                });
            }
        }
    }
    for (start, end) in digit_runs(seed) {
        for huge in HUGE {
            let bytes = [&seed[..start], huge.as_bytes(), &seed[end..]].concat();
            let big = huge.len() > 2 && !huge.contains('e');
            out.push(Mutant {
                what: format!("bytes {start}..{end} set to {huge}"),
                bytes,
                huge: big && sets_unbounded_size(seed, start),
            });
        }
    }
    out
}

/// Runs every seed and mutant with `huge` as given; returns how many ran and the panics.
fn run_all(huge: bool) -> (usize, Vec<String>) {
    let mut ran = 0;
    let mut panics = Vec::new();
    for (target, seed) in harness::seeds() {
        let seed_itself = Mutant {
            what: "the seed".into(),
            bytes: seed.clone(),
            huge: false,
        };
        for m in std::iter::once(seed_itself).chain(mutants(target, &seed)) {
            if m.huge != huge {
                continue;
            }
            ran += 1;
            if catch_unwind(AssertUnwindSafe(|| harness::run(target, &m.bytes))).is_err() {
                panics.push(format!("{target}: {}", m.what));
            }
        }
    }
    (ran, panics)
}

#[test]
fn readers_answer_mutated_files_with_errors_not_panics() {
    let (ran, panics) = run_all(false);
    assert!(ran > 1000, "only {ran} cases");
    eprintln!("{ran} cases, none panicked");
    assert!(
        panics.is_empty(),
        "{} of {ran} cases panicked: {panics:#?}",
        panics.len()
    );
}

/// Huge sizes in NPY headers and layouts: refused before anything is allocated (an
/// allocation of what such a header claims would abort, which no `catch_unwind` survives).
#[test]
fn huge_sizes_in_headers_are_refused_before_allocating() {
    let (ran, panics) = run_all(true);
    assert!(
        panics.is_empty(),
        "{} of {ran} cases panicked: {panics:#?}",
        panics.len()
    );
}

#[test]
fn every_seed_is_accepted_all_the_way() {
    let seeds = harness::seeds();
    for target in harness::TARGETS {
        assert!(
            seeds.iter().any(|(t, _)| *t == target),
            "no seed for {target}"
        );
    }
    for (i, (target, bytes)) in seeds.iter().enumerate() {
        assert!(
            harness::run(target, bytes),
            "seed {i} of {target} is refused"
        );
    }
}

/// The stream's fuzz regressions: a first stamp (or tick) far past time 0 once made one
/// event complete every 1 ms step up to it, minutes of work for 65 bytes. A first event
/// more than the largest gap after time 0 now starts the episode, so each runs at once.
#[test]
fn a_far_first_stamp_costs_a_stream_no_silent_steps() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fuzz/regressions/stream_events");
    for name in ["far-first-stamp.bin", "far-tick-in-seconds.bin"] {
        let bytes = std::fs::read(dir.join(name)).unwrap();
        let start = std::time::Instant::now();
        let ran = catch_unwind(AssertUnwindSafe(|| harness::stream_events(&bytes)));
        assert!(ran.is_ok(), "{name} panicked");
        let took = start.elapsed().as_secs_f64();
        assert!(took < 10.0, "{name} took {took:.1} s");
    }
}
