#![no_main]
//! Fuzz target `events_npy`: see `neurotex_fuzz::harness`.

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    neurotex_fuzz::harness::run("events_npy", data);
});
