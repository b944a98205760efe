//! Whole-array passes compiled twice: as plain code, and with AVX2 enabled for processors
//! that have it (chosen at run time), so one binary runs on any x86-64 and still uses the
//! wider vectors where they exist.
//!
//! Only passes whose result does not depend on the vector width go through here: copies,
//! conversions, comparisons, and arithmetic that is exact or correctly rounded one element
//! at a time (no FMA is enabled, and Rust never fuses a multiply and an add on its own).
//! Their bodies are plain `for` loops over slices: iterator adaptors that take closures
//! (`fold`, `for_each`) were seen compiled out of line, without the feature.

/// Defines a function whose body is compiled once as plain code and once with AVX2, the
/// AVX2 copy called where the processor has it. The body must give the same result either
/// way (see the module documentation).
macro_rules! avx2_or_plain {
    (
        $(#[$meta:meta])*
        $vis:vis fn $name:ident($($arg:ident: $ty:ty),* $(,)?) $(-> $ret:ty)? $body:block
    ) => {
        $(#[$meta])*
        $vis fn $name($($arg: $ty),*) $(-> $ret)? {
            #[inline(always)]
            fn body($($arg: $ty),*) $(-> $ret)? $body
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx2")]
                unsafe fn avx2($($arg: $ty),*) $(-> $ret)? {
                    body($($arg),*)
                }
                if std::arch::is_x86_feature_detected!("avx2") {
                    // SAFETY: the CPU supports AVX2, the only feature `avx2` enables.
                    return unsafe { avx2($($arg),*) };
                }
            }
            body($($arg),*)
        }
    };
}

pub(crate) use avx2_or_plain;
