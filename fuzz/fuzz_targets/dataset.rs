#![no_main]
//! Fuzz target `dataset`: see `neurotex_fuzz::harness`.

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    neurotex_fuzz::harness::run("dataset", data);
});
