//! Runtime choice of the instruction set the hot mechanics loops are compiled for.
//!
//! The crate is built for baseline x86-64 (SSE2). The spring pass, the per-vertex gather and the
//! RK4 vector loops are written once as `#[inline(always)]` bodies; the crate-internal
//! `multiversion!` macro makes one copy of such a body per instruction set, the wider ones inside
//! functions compiled with `#[target_feature(enable = "avx2")]` or `"avx512f"` when
//! the CPU has it, so that LLVM vectorises the same source at 4 or 8 lanes instead of 2.
//!
//! # Bitwise identical on every kernel
//! Only `+ − × ÷ √`, `max` and comparisons/selects are used, each correctly rounded by IEEE 754
//! whatever the vector width; Rust never contracts `a * b + c` into a fused multiply-add, and the
//! `fma` feature is not even enabled. The order of every sum is fixed by the source (vectorisation
//! is across springs or slots, never inside one sum). So every kernel returns the same bits, and
//! the results stay independent of the machine and of the thread count
//! (`tests/mechanics_kernels.rs` checks it on the built-in liver and random systems).
//!
//! This module holds the crate's only `unsafe` (the crate is `deny(unsafe_code)`): the calls into
//! the `#[target_feature]` copies, sound because a [`Kernel`] naming a wide set is only made after
//! run-time detection of that set.

use std::sync::OnceLock;

/// The instruction set a hot loop runs with; only a set the CPU has can be made (detection at
/// run time), so running with it is always sound.
///
/// # Examples
///
/// ```
/// use topomech::mechanics::Kernel;
///
/// let best = Kernel::detect();
/// assert!(Kernel::available().contains(&best) && Kernel::available().contains(&Kernel::portable()));
/// assert_eq!(Kernel::portable().name(), "portable");
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Kernel(pub(crate) Isa);

/// The private instruction sets (a public enum would let callers claim one the CPU lacks).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Isa {
    Portable,
    #[cfg(target_arch = "x86_64")]
    Avx2,
    #[cfg(target_arch = "x86_64")]
    Avx512,
}

impl Kernel {
    /// The baseline build (SSE2 on x86-64), available everywhere. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::Kernel;
    ///
    /// assert_eq!(Kernel::portable().name(), "portable");
    /// assert!(Kernel::available().contains(&Kernel::portable()));
    /// ```
    pub fn portable() -> Kernel {
        Kernel(Isa::Portable)
    }

    /// The widest kernel the CPU supports, detected once per process (later calls read a cache).
    /// The environment variable `TOPOMECH_KERNEL` (`portable`, `avx2`, `avx512`), read at that
    /// first call, caps it for benchmarks (any other value is ignored); a kernel the CPU lacks is
    /// never chosen. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::Kernel;
    ///
    /// let k = Kernel::detect();
    /// assert_eq!(k, Kernel::detect()); // cached
    /// assert!(["portable", "avx2", "avx512"].contains(&k.name()));
    /// ```
    pub fn detect() -> Kernel {
        static BEST: OnceLock<Kernel> = OnceLock::new();
        *BEST.get_or_init(|| {
            let cap = std::env::var("TOPOMECH_KERNEL").ok();
            let all = Kernel::available();
            let allowed = match cap.as_deref() {
                Some("portable") => 1,
                Some("avx2") => 2,
                _ => all.len(),
            };
            all[..allowed.min(all.len())].last().copied().unwrap_or(Kernel::portable())
        })
    }

    /// Every kernel this CPU can run, narrowest (portable) first. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::Kernel;
    ///
    /// let all = Kernel::available();
    /// assert_eq!(all[0], Kernel::portable());
    /// assert!(all.contains(&Kernel::detect()));
    /// ```
    pub fn available() -> Vec<Kernel> {
        let mut all = vec![Kernel(Isa::Portable)];
        #[cfg(target_arch = "x86_64")]
        {
            if std::is_x86_feature_detected!("avx2") {
                all.push(Kernel(Isa::Avx2));
                let avx512 = std::is_x86_feature_detected!("avx512f")
                    && std::is_x86_feature_detected!("avx512dq")
                    && std::is_x86_feature_detected!("avx512vl");
                if avx512 {
                    all.push(Kernel(Isa::Avx512));
                }
            }
        }
        all
    }

    /// `portable`, `avx2` or `avx512`. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::Kernel;
    ///
    /// let names: Vec<&str> = Kernel::available().iter().map(|k| k.name()).collect();
    /// assert_eq!(names[0], "portable");
    /// ```
    pub fn name(self) -> &'static str {
        match self.0 {
            Isa::Portable => "portable",
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => "avx2",
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => "avx512",
        }
    }
}

/// Defines `fn NAME(kernel: Kernel, ARGS) -> RET` running `BODY(ARGS)` compiled for `kernel`:
/// `BODY` (an `#[inline(always)]` function, as must be everything hot it calls) is inlined into
/// one copy per instruction set, the wider ones built with `#[target_feature]`.
macro_rules! multiversion {
    ($(#[$attr:meta])* $vis:vis fn $name:ident($($arg:ident: $ty:ty),* $(,)?) $(-> $ret:ty)? = $body:path;) => {
        $(#[$attr])*
        #[allow(clippy::too_many_arguments, unsafe_code)]
        #[inline]
        $vis fn $name(kernel: $crate::mechanics::simd::Kernel, $($arg: $ty),*) $(-> $ret)? {
            #[cfg(target_arch = "x86_64")]
            #[target_feature(enable = "avx2")]
            #[allow(clippy::too_many_arguments)]
            fn avx2($($arg: $ty),*) $(-> $ret)? {
                $body($($arg),*)
            }
            #[cfg(target_arch = "x86_64")]
            #[target_feature(enable = "avx512f,avx512dq,avx512vl,avx2")]
            #[allow(clippy::too_many_arguments)]
            fn avx512($($arg: $ty),*) $(-> $ret)? {
                $body($($arg),*)
            }
            match kernel.0 {
                $crate::mechanics::simd::Isa::Portable => $body($($arg),*),
                // SAFETY: a `Kernel` holding Avx2 is only made by `Kernel::available` after
                // `is_x86_feature_detected!("avx2")` confirmed the feature on this CPU.
                #[cfg(target_arch = "x86_64")]
                $crate::mechanics::simd::Isa::Avx2 => unsafe { avx2($($arg),*) },
                // SAFETY: as above, avx2, avx512f, avx512dq and avx512vl were all detected.
                #[cfg(target_arch = "x86_64")]
                $crate::mechanics::simd::Isa::Avx512 => unsafe { avx512($($arg),*) },
            }
        }
    };
}
pub(crate) use multiversion;
