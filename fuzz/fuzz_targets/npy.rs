#![no_main]
//! Fuzz target `npy`: see `neurotex_fuzz::harness`.

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    neurotex_fuzz::harness::run("npy", data);
});
