#![no_main]
//! Fuzz target `snn_model`: see `neurotex_fuzz::harness`.

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    neurotex_fuzz::harness::run("snn_model", data);
});
