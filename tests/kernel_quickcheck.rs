//! Quickcheck properties of the kernel, driven by the same generator as proptest and the fuzz
//! target: an `Arbitrary` op sequence is a start map (`Grow`) plus bytes decoded by
//! `ops::decode`; shrinking shrinks the bytes. Every law of `ops::check_after_op` is checked
//! after every step, for n = 1, 2, 3; copies with permuted dart ids must be isomorphic.

use quickcheck::{Arbitrary, Gen, QuickCheck, TestResult};
use topomech::ops::{self, KernelOp, Seed};
use topomech::GMap;

/// A seeded start map and a byte string of operations.
#[derive(Clone, Debug)]
struct OpSeq {
    kind: u8,
    seed: u16,
    bytes: Vec<u8>,
}

impl OpSeq {
    fn ops(&self) -> Vec<KernelOp> {
        let kind = [Seed::Structured, Seed::Soup, Seed::Wild][usize::from(self.kind % 3)];
        let mut ops = vec![KernelOp::Grow { kind, seed: u32::from(self.seed) }];
        ops.extend(ops::decode(&self.bytes).into_iter().take(100));
        ops
    }
}

impl Arbitrary for OpSeq {
    fn arbitrary(g: &mut Gen) -> Self {
        let len = usize::arbitrary(g) % 300;
        OpSeq { kind: u8::arbitrary(g), seed: u16::arbitrary(g), bytes: (0..len).map(|_| u8::arbitrary(g)).collect() }
    }

    fn shrink(&self) -> Box<dyn Iterator<Item = Self>> {
        let (kind, seed) = (self.kind, self.seed);
        Box::new(self.bytes.shrink().map(move |bytes| OpSeq { kind, seed, bytes }))
    }
}

fn laws<const N: usize>(seq: OpSeq) -> TestResult {
    match ops::run_ops(&mut GMap::<N>::new(), &seq.ops()) {
        Ok(()) => TestResult::passed(),
        Err(message) => TestResult::error(message),
    }
}

fn permuted_copy_is_isomorphic<const N: usize>(seq: OpSeq, perm_seed: u64) -> TestResult {
    let mut map = GMap::<N>::new();
    for op in seq.ops() {
        let _ = ops::apply(&mut map, &op);
    }
    let perm = ops::random_permutation(map.dart_count(), perm_seed);
    match ops::permuted_copy(&map, &perm) {
        Ok(copy) => TestResult::from_bool(copy.is_isomorphic(&map) && map.is_isomorphic(&copy)),
        Err(e) => TestResult::error(e.to_string()),
    }
}

fn quickcheck() -> QuickCheck {
    QuickCheck::new().tests(40).max_tests(200)
}

#[test]
fn laws_hold_after_every_op_n1() {
    quickcheck().quickcheck(laws::<1> as fn(OpSeq) -> TestResult);
}

#[test]
fn laws_hold_after_every_op_n2() {
    quickcheck().quickcheck(laws::<2> as fn(OpSeq) -> TestResult);
}

#[test]
fn laws_hold_after_every_op_n3() {
    quickcheck().quickcheck(laws::<3> as fn(OpSeq) -> TestResult);
}

#[test]
fn permuted_copies_are_isomorphic() {
    quickcheck().quickcheck(permuted_copy_is_isomorphic::<1> as fn(OpSeq, u64) -> TestResult);
    quickcheck().quickcheck(permuted_copy_is_isomorphic::<2> as fn(OpSeq, u64) -> TestResult);
    quickcheck().quickcheck(permuted_copy_is_isomorphic::<3> as fn(OpSeq, u64) -> TestResult);
}

/// The property can fail: an op sequence whose check is fed a wrong "before" map is caught.
#[test]
fn the_checker_rejects_a_wrong_report() {
    let mut map = GMap::<2>::new();
    let grow = KernelOp::Grow { kind: Seed::Wild, seed: 0 };
    let before = map.clone();
    let result = ops::apply(&mut map, &grow);
    ops::check_after_op(&before, &map, &grow, &result).unwrap();
    // Claiming that a create happened when a whole sphere was added must be refused.
    let lie = Ok(ops::Applied::Created(topomech::DartId(0)));
    assert!(ops::check_after_op(&before, &map, &KernelOp::CreateDart, &lie).is_err());
}
