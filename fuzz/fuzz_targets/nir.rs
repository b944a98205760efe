#![no_main]
//! Fuzz target `nir`: see `neurotex_fuzz::harness`.
//!
//! `nir::read` runs the HDF5 parser (a young crate) under `catch_unwind` and answers its
//! panics with an error naming the file. libFuzzer's panic hook would abort before that
//! unwind, so this target puts back the default hook: a panic the reader catches is no
//! finding, while one that escapes it still ends in libfuzzer-sys's abort.

static DEFAULT_HOOK: std::sync::Once = std::sync::Once::new();

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    DEFAULT_HOOK.call_once(|| {
        let _ = std::panic::take_hook();
    });
    neurotex_fuzz::harness::run("nir", data);
});
