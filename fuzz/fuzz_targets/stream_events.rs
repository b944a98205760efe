#![no_main]
//! Fuzz target `stream_events`: see `neurotex_fuzz::harness`.

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    neurotex_fuzz::harness::run("stream_events", data);
});
