//! Property tests (proptest) of the kernel: random operation sequences from `topomech::ops`
//! on seeded maps for n = 1, 2, 3, with every law of `ops::check_after_op` checked after every
//! step, and isomorphism round trips through copies with permuted dart ids.
//!
//! The byte strings proptest generates are decoded by the same `ops::decode` the fuzz target
//! uses, so a failure here shrinks to bytes that can be dropped into `fuzz/corpus/kernel_ops/`.

use proptest::prelude::*;
use topomech::ops::{self, KernelOp, Seed};
use topomech::{DartId, GMap};

fn seed_kind() -> impl Strategy<Value = Seed> {
    prop_oneof![Just(Seed::Structured), Just(Seed::Soup), Just(Seed::Wild)]
}

/// A start map (one `Grow`) followed by up to 120 decoded operations.
fn op_sequence() -> impl Strategy<Value = Vec<KernelOp>> {
    (seed_kind(), any::<u16>(), prop::collection::vec(any::<u8>(), 0..400)).prop_map(|(kind, seed, bytes)| {
        let mut ops = vec![KernelOp::Grow { kind, seed: u32::from(seed) }];
        ops.extend(ops::decode(&bytes).into_iter().take(120));
        ops
    })
}

/// Runs the operations without checks (the maps used by the isomorphism properties).
fn build<const N: usize>(ops: &[KernelOp]) -> GMap<N> {
    let mut map = GMap::<N>::new();
    for op in ops {
        let _ = ops::apply(&mut map, op);
    }
    map
}

/// Copy with permuted ids is isomorphic (both ways, and by the explicit map from a dart of each
/// component); breaking one αi link of the copy makes it non-isomorphic.
fn check_permuted_copy<const N: usize>(map: &GMap<N>, perm_seed: u64) -> Result<(), TestCaseError> {
    let perm = ops::random_permutation(map.dart_count(), perm_seed);
    let copy = ops::permuted_copy(map, &perm).map_err(|e| TestCaseError::fail(e.to_string()))?;
    prop_assert!(map.is_isomorphic(&copy) && copy.is_isomorphic(map), "permuted copy not isomorphic");
    let ranks: Vec<DartId> = map.darts().collect();
    if let Some(&d) = ranks.first() {
        let image = DartId(perm[0]);
        let pairs = map.isomorphism_from(d, &copy, image);
        prop_assert!(pairs.is_some(), "no isomorphism sends the first dart to its image");
        for (x, y) in pairs.unwrap() {
            let rank = ranks.binary_search(&x).unwrap();
            prop_assert_eq!(y, DartId(perm[rank]), "isomorphism disagrees with the permutation");
        }
    }
    let mut broken = copy.clone();
    let sewn = broken.darts().find_map(|d| (0..=N).find(|&i| !broken.is_free(i, d)).map(|i| (i, d)));
    if let Some((i, d)) = sewn {
        broken.unsew_dyn(i, d).unwrap();
        prop_assert!(!map.is_isomorphic(&broken), "a copy with alpha{} cut at {:?} is still isomorphic", i, d);
    }
    broken.create_dart().unwrap();
    prop_assert!(!map.is_isomorphic(&broken), "a copy with an extra dart is still isomorphic");
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn laws_hold_after_every_op_n1(ops in op_sequence()) {
        ops::run_ops(&mut GMap::<1>::new(), &ops).map_err(TestCaseError::fail)?;
    }

    #[test]
    fn laws_hold_after_every_op_n2(ops in op_sequence()) {
        ops::run_ops(&mut GMap::<2>::new(), &ops).map_err(TestCaseError::fail)?;
    }

    #[test]
    fn laws_hold_after_every_op_n3(ops in op_sequence()) {
        ops::run_ops(&mut GMap::<3>::new(), &ops).map_err(TestCaseError::fail)?;
    }

    #[test]
    fn permuted_copies_are_isomorphic_n1(ops in op_sequence(), perm_seed in any::<u64>()) {
        check_permuted_copy(&build::<1>(&ops), perm_seed)?;
    }

    #[test]
    fn permuted_copies_are_isomorphic_n2(ops in op_sequence(), perm_seed in any::<u64>()) {
        check_permuted_copy(&build::<2>(&ops), perm_seed)?;
    }

    #[test]
    fn permuted_copies_are_isomorphic_n3(ops in op_sequence(), perm_seed in any::<u64>()) {
        check_permuted_copy(&build::<3>(&ops), perm_seed)?;
    }

    #[test]
    fn encode_inverts_decode(bytes in prop::collection::vec(any::<u8>(), 0..300)) {
        if let Err(e) = ops::check_decode(&bytes) {
            return Err(TestCaseError::fail(e));
        }
    }
}

/// `is_isomorphic` must not be fooled by equal counts: a closed 2-gon (one component) and two
/// loops (each an edge whose α1 joins its own two ends) both have 4 darts, 2 vertices, 2 edges.
#[test]
fn same_counts_different_structure_is_not_isomorphic() {
    let two_gon: ops::AlphaTable = vec![vec![1, 3], vec![0, 2], vec![3, 1], vec![2, 0]];
    let two_loops: ops::AlphaTable = vec![vec![1, 1], vec![0, 0], vec![3, 3], vec![2, 2]];
    let a = ops::from_alpha_table::<1>(&two_gon).unwrap();
    let b = ops::from_alpha_table::<1>(&two_loops).unwrap();
    assert_eq!((a.dart_count(), a.count_cells()), (b.dart_count(), b.count_cells()));
    assert_eq!((a.components().len(), b.components().len()), (1, 2));
    assert!(!a.is_isomorphic(&b) && !b.is_isomorphic(&a));
    assert!(a.is_isomorphic(&ops::permuted_copy(&a, &[2, 0, 3, 1]).unwrap()));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// `DartSet` behaves as a set: after any sequence of inserts and removes (darts up to 1 000,
    /// so several 64-bit words), membership, the return values and the length agree with a
    /// `BTreeSet` model.
    #[test]
    fn dart_set_agrees_with_a_model_set(ops in prop::collection::vec((any::<bool>(), 0u32..1000), 0..300)) {
        let (mut set, mut model) = (topomech::gmap::DartSet::with_capacity(64), std::collections::BTreeSet::new());
        for (insert, d) in ops {
            if insert {
                prop_assert_eq!(set.insert(DartId(d)), model.insert(d), "insert {}", d);
            } else {
                prop_assert_eq!(set.remove(DartId(d)), model.remove(&d), "remove {}", d);
            }
            prop_assert_eq!(set.len(), model.len());
            prop_assert_eq!(set.is_empty(), model.is_empty());
        }
        for d in 0..1000 {
            prop_assert_eq!(set.contains(DartId(d)), model.contains(&d), "contains {}", d);
        }
    }

    /// Reusable marks behave as sets too, and `count` and `unmark` agree with a model.
    #[test]
    fn marks_agree_with_a_model_set(ops in prop::collection::vec((any::<bool>(), 0u32..200), 0..200)) {
        let mut map = GMap::<2>::new();
        for _ in 0..200 {
            map.create_dart().unwrap();
        }
        let mut mark = map.reserve_mark();
        let mut model = std::collections::BTreeSet::new();
        for (set, d) in ops {
            if set {
                prop_assert_eq!(mark.mark(DartId(d)), model.insert(d));
            } else {
                prop_assert_eq!(mark.unmark(DartId(d)), model.remove(&d));
            }
            prop_assert_eq!(mark.count(), model.len());
        }
        for d in 0..200 {
            prop_assert_eq!(mark.is_marked(DartId(d)), model.contains(&d));
        }
        for d in std::mem::take(&mut model) {
            mark.unmark(DartId(d));
        }
        map.free_mark(mark);
    }

    /// `mark_orbit` marks exactly the darts of the orbit ⟨mask⟩(d) (as `orbit` lists them) and
    /// nothing else, on top of what was marked before; `unmark_orbit` takes exactly those off.
    #[test]
    fn marking_an_orbit_marks_exactly_its_darts(ops in op_sequence(), pick in any::<u32>(), bits in 0u8..16, other in any::<u32>()) {
        let mut map = build::<3>(&ops);
        let darts: Vec<DartId> = map.darts().collect();
        prop_assume!(!darts.is_empty());
        let (d, before) = (darts[pick as usize % darts.len()], darts[other as usize % darts.len()]);
        let mask = topomech::AlphaMask(bits);
        let orbit: std::collections::BTreeSet<DartId> = map.orbit(d, mask).into_iter().collect();
        let mut mark = map.reserve_mark();
        mark.mark(before);
        map.mark_orbit(&mut mark, d, mask);
        for &x in &darts {
            prop_assert_eq!(mark.is_marked(x), orbit.contains(&x) || x == before, "dart {:?}", x);
        }
        prop_assert_eq!(mark.count(), orbit.len() + usize::from(!orbit.contains(&before)));
        map.unmark_orbit(&mut mark, d, mask);
        for &x in &darts {
            prop_assert_eq!(mark.is_marked(x), x == before && !orbit.contains(&x), "dart {:?} after unmark", x);
        }
        mark.unmark(before);
        map.free_mark(mark);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// `try_alpha(i, d)` succeeds exactly when i ≤ n and d is live, and then equals `alpha_dyn`;
    /// otherwise it names the dart. Checked for every slot (dead ones included) and one past.
    #[test]
    fn try_alpha_succeeds_exactly_on_live_darts_and_valid_indices(ops in op_sequence()) {
        let map = build::<3>(&ops);
        for slot in 0..map.capacity() as u32 + 2 {
            let d = DartId(slot);
            for i in 0..=4 {
                match map.try_alpha(i, d) {
                    Ok(x) => {
                        prop_assert!(i <= 3 && map.contains(d), "try_alpha({i}, {d:?}) accepted");
                        prop_assert_eq!(x, map.alpha_dyn(i, d));
                    }
                    Err(e) => {
                        prop_assert!(i > 3 || !map.contains(d), "try_alpha({i}, {d:?}) refused: {e}");
                        let expected = if i > 3 {
                            topomech::gmap::DartError::BadIndex { i, n: 3 }
                        } else {
                            topomech::gmap::DartError::NoSuchDart(d)
                        };
                        prop_assert_eq!(e, expected);
                    }
                }
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// `sewn_pairs(i)` lists every i-sewn link once as (d, αi(d)) with d < αi(d): as many pairs
    /// as half the i-sewn darts, and every listed pair is a link.
    #[test]
    fn sewn_pairs_list_each_link_once_in_order(ops in op_sequence()) {
        let map = build::<3>(&ops);
        for i in 0..=3 {
            let pairs: Vec<(DartId, DartId)> = map.sewn_pairs(i).collect();
            let sewn = map.darts().filter(|&d| !map.is_free(i, d)).count();
            prop_assert_eq!(pairs.len() * 2, sewn, "α{}", i);
            for (d, e) in pairs {
                prop_assert!(d < e && map.alpha_dyn(i, d) == e, "α{}: ({:?}, {:?})", i, d, e);
            }
        }
    }
}
