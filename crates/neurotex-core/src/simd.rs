//! Whole-array passes compiled several times: as plain code, and with wider vector
//! instructions (AVX2, AVX-512) for processors that have them, the widest chosen at run
//! time, so one binary runs on any x86-64 and still uses the wider vectors where they exist.
//!
//! Only passes whose result does not depend on the vector width go through here: copies,
//! conversions, comparisons, and arithmetic that is exact or correctly rounded one element
//! at a time (Rust never fuses a multiply and an add on its own, so an FMA unit that a
//! feature brings along changes nothing). Their bodies are plain `for` loops over slices:
//! iterator adaptors that take closures (`fold`, `for_each`) were seen compiled out of
//! line, without the feature.
//!
//! Every dispatch in neurotex, these passes and the hand-written kernels alike, asks
//! [`has_feature!`](crate::has_feature): the processor must have the feature and the run
//! must allow it. `NEUROTEX_SIMD=portable` allows none (every pass runs its plain code),
//! `NEUROTEX_SIMD=avx2` allows all but AVX-512; unset (or `native`), the processor decides.
//! It is read once, at the first dispatch, so a process never mixes paths; the tests run
//! under each setting the machine supports (`.ci/run`), and every path must give the
//! reference's bits.

use std::sync::OnceLock;

/// The widest instructions a run may use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cap {
    /// Whatever the processor has.
    Native,
    /// AVX2 and narrower (no AVX-512).
    Avx2,
    /// Plain code only.
    Portable,
}

/// The run's cap, from `NEUROTEX_SIMD` (read once; an unknown value is `Native`).
pub fn cap() -> Cap {
    // Set once from the environment and never changed: a process-wide value, but not
    // mutable state (the dispatch must not change in the middle of a run).
    static CAP: OnceLock<Cap> = OnceLock::new();
    *CAP.get_or_init(|| match std::env::var("NEUROTEX_SIMD").as_deref() {
        Ok("portable") => Cap::Portable,
        Ok("avx2") => Cap::Avx2,
        _ => Cap::Native,
    })
}

/// Whether the run's [`cap`] allows the target feature `feature` (`"avx2"`, `"avx512f"`,
/// `"popcnt"`, ...).
#[inline]
pub fn allows(feature: &str) -> bool {
    match cap() {
        Cap::Native => true,
        Cap::Avx2 => !feature.starts_with("avx512"),
        Cap::Portable => false,
    }
}

/// Whether the processor has the target feature and the run allows it ([`allows`]): the
/// one test every SIMD dispatch makes. x86-64 only.
#[doc(hidden)]
#[macro_export]
macro_rules! has_feature {
    ($feature:tt) => {
        $crate::simd::allows($feature) && std::arch::is_x86_feature_detected!($feature)
    };
}

pub use crate::has_feature;

/// Defines a function whose body is compiled once as plain code and once per listed target
/// feature, the first listed feature the processor has chosen at run time (list the widest
/// first). The body must give the same result either way (see the module documentation).
///
/// ```text
/// widest_or_plain! {
///     ["avx512f", "avx2"]
///     /// Doc comment.
///     fn name(a: &[f64], b: &mut [f64]) { for .. }
/// }
/// ```
#[doc(hidden)]
#[macro_export]
macro_rules! widest_or_plain {
    (
        [$($feature:tt),+ $(,)?]
        $(#[$meta:meta])*
        $vis:vis fn $name:ident($($arg:ident: $ty:ty),* $(,)?) $(-> $ret:ty)? $body:block
    ) => {
        $(#[$meta])*
        $vis fn $name($($arg: $ty),*) $(-> $ret)? {
            #[inline(always)]
            fn body($($arg: $ty),*) $(-> $ret)? $body
            $crate::widest_or_plain!(@try [$($feature),+] ($($arg: $ty),*) $(-> $ret)?);
            body($($arg),*)
        }
    };
    // One feature's copy of `body`, returned from the caller when the processor has it;
    // then the next feature's.
    (@try [$feature:tt $(, $rest:tt)*] ($($arg:ident: $ty:ty),*) $(-> $ret:ty)?) => {
        #[cfg(target_arch = "x86_64")]
        {
            #[target_feature(enable = $feature)]
            unsafe fn wide($($arg: $ty),*) $(-> $ret)? {
                body($($arg),*)
            }
            if $crate::has_feature!($feature) {
                // SAFETY: the CPU supports the feature, the only one `wide` enables.
                return unsafe { wide($($arg),*) };
            }
        }
        $crate::widest_or_plain!(@try [$($rest),*] ($($arg: $ty),*) $(-> $ret)?);
    };
    (@try [] ($($arg:ident: $ty:ty),*) $(-> $ret:ty)?) => {};
}

pub use crate::widest_or_plain;
