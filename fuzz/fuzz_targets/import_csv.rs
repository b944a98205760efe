#![no_main]
//! Fuzz target `import_csv`: see `neurotex_fuzz::harness`.

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    neurotex_fuzz::harness::run("import_csv", data);
});
