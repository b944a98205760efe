#![no_main]
//! Fuzz target `layout`: see `neurotex_fuzz::harness`.

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    neurotex_fuzz::harness::run("layout", data);
});
