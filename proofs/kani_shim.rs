//! The two Kani primitives the harnesses use, so the same harness code runs as a seeded
//! randomized test under `cargo test` and as a proof under `cargo kani --tests`:
//!
//! * `any::<T>()` — under Kani a symbolic value; in tests a pseudo-random one from a SplitMix64
//!   seeded per case by [`cases`];
//! * `assume(cond) -> bool` — under Kani restricts the inputs (and returns true); in tests
//!   returns `cond`, so a harness writes `if !assume(c) { return; }` to skip the case.
//!
//! [`cases`] runs the body once under Kani (the proof covers every value) and `count` times
//! with unrelated seeds in tests.

#[cfg(kani)]
mod imp {
    /// A symbolic value.
    pub fn any<T: kani::Arbitrary>() -> T {
        kani::any()
    }

    /// Restricts the inputs.
    pub fn assume(cond: bool) -> bool {
        kani::assume(cond);
        true
    }

    /// Runs the body once: the proof covers every input.
    pub fn cases(_count: u64, mut body: impl FnMut()) {
        body()
    }
}

#[cfg(not(kani))]
mod imp {
    use std::cell::Cell;
    use topomech::generate::SplitMix64;

    thread_local! {
        static STATE: Cell<u64> = const { Cell::new(0) };
    }

    /// Values `any()` can produce in tests.
    pub trait Arbitrary {
        /// A pseudo-random value.
        fn arbitrary(rng: &mut SplitMix64) -> Self;
    }

    macro_rules! arbitrary_int {
        ($($t:ty),*) => {$(
            impl Arbitrary for $t {
                fn arbitrary(rng: &mut SplitMix64) -> Self {
                    rng.next_u64() as $t
                }
            }
        )*};
    }
    arbitrary_int!(u8, u16, u32, u64, usize);

    impl Arbitrary for bool {
        fn arbitrary(rng: &mut SplitMix64) -> Self {
            rng.next_u64() & 1 == 1
        }
    }

    impl<T: Arbitrary, const K: usize> Arbitrary for [T; K] {
        fn arbitrary(rng: &mut SplitMix64) -> Self {
            std::array::from_fn(|_| T::arbitrary(rng))
        }
    }

    /// A pseudo-random value from the current case's generator.
    pub fn any<T: Arbitrary>() -> T {
        STATE.with(|s| {
            let mut rng = SplitMix64(s.get());
            let value = T::arbitrary(&mut rng);
            s.set(rng.0);
            value
        })
    }

    /// In tests: whether the case satisfies the assumption (skip it if not).
    pub fn assume(cond: bool) -> bool {
        cond
    }

    /// Runs the body `count` times, case c seeded with a SplitMix64 output of c (so failures are
    /// reproducible). Not c·γ itself: SplitMix64 steps its state by γ, so case c + 1 then drew
    /// case c's values shifted by one (finding 320); mixed seeds start unrelated streams.
    pub fn cases(count: u64, mut body: impl FnMut()) {
        for case in 0..count {
            STATE.with(|s| s.set(SplitMix64(case).next_u64()));
            body();
        }
    }
}

pub use imp::{any, assume, cases};
