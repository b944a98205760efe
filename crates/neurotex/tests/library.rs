//! The library's integration tests, one binary with a module per topic (as the CLI's
//! `tests/cli.rs`), so that the crates are linked into one test program, not sixteen.
//! `cargo test -p neurotex --test library golden` runs one module's tests.

mod calibration;
mod classifiers;
mod datasets;
mod docs_numbers;
mod e9;
mod extensions;
mod golden;
mod hand_cases;
mod hostile_input;
mod import;
mod params_and_io;
mod reference_values;
mod report_intervals;
mod sim;
mod slow_references;
mod spike_distance;
mod stats_reference;
mod stream;
mod support;
