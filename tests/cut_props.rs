//! Random cut sequences (dissociate, refused dissociate, remove, refused remove, incise, tear) on
//! Kuhn cubes and liver_547: after every step validate(), the conservation laws, the totals
//! (old − removed), cell counts against a union-find oracle built from the tet list and the cut
//! faces only, and the incrementally updated projection against a fresh one.

mod cut_common;

use cut_common::{decode, run_bytes, run_ops, Harness, Op, MAX_OPS, OP_BYTES};
use proptest::prelude::*;
use topomech::mechanics::Vec3;

fn run(mut h: Harness, ops: &[Op]) -> Result<(), TestCaseError> {
    run_ops(&mut h, ops).map_err(TestCaseError::fail)
}

/// Byte strings of the fuzz target's encoding ([`decode`]): a header and 1–13 ops.
fn scenario_bytes() -> impl Strategy<Value = Vec<u8>> {
    (any::<[u8; 2]>(), prop::collection::vec(any::<[u8; OP_BYTES]>(), 1..14))
        .prop_map(|(h, ops)| h.into_iter().chain(ops.into_iter().flatten()).collect())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn cut_sequences_on_kuhn_cubes(bytes in scenario_bytes()) {
        run_bytes(&bytes).map_err(TestCaseError::fail)?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 3, ..ProptestConfig::default() })]

    #[test]
    fn cut_sequences_on_liver_547(bytes in scenario_bytes()) {
        // The built-in copy (byte-identical to ../shared/meshes/liver_547_v22.msh): never skipped
        // (finding 293: the shared file is absent from a checkout elsewhere).
        let path = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/data/liver_547_v22.msh"));
        let mesh = topomech::io::read_mesh(path).unwrap();
        let ops = decode(&bytes).ops;
        run(Harness::new(mesh.points, mesh.tets).unwrap(), &ops[..ops.len().min(4)])?;
    }
}

/// Every byte string decodes; the header and each op group land where the format says.
#[test]
fn decoder_reads_the_documented_format() {
    let s = decode(&[3, 7, 0, 5, 1, 0, 10, 2, 0, 0b11_000_111, 9]);
    assert_eq!((s.k, s.seed), (2, 7));
    assert_eq!(s.ops.len(), 2, "trailing partial group ignored");
    assert_eq!(s.ops[0], Op::Dissociate(5 + 256));
    assert_eq!(s.ops[1], Op::Incise(2, [1.0, -1.0, 1.0]));
    assert_eq!(decode(&[]).ops, vec![]);
    assert_eq!(decode(&vec![0u8; 4 * 100]).ops.len(), MAX_OPS);
}

/// The oracle is not vacuous: on two tets sharing a face it predicts the counts the kernel's own
/// doc example states before and after the dissociation, and it disagrees with an uncut map.
#[test]
fn oracle_agrees_with_hand_counts() {
    let points = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
    let mut h = Harness::new(points, vec![[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
    assert_eq!(h.oracle.counts(), ([5, 9, 7, 2], 6, 1));
    h.apply(Op::Dissociate(0)).unwrap();
    assert_eq!(h.oracle.counts(), ([8, 12, 8, 2], 8, 2));
    h.check().unwrap();
    h.apply(Op::Remove(1)).unwrap();
    assert_eq!(h.oracle.counts(), ([4, 6, 4, 1], 4, 1));
    h.check().unwrap();
    h.apply(Op::RemoveAgain(0)).unwrap();
    h.check().unwrap();
}

/// One edit of a spring system's incidence lists.
#[derive(Clone, Debug)]
enum Edit {
    Slot,
    Spring(usize, usize),
    Move(usize, usize, usize),
    Remove(usize),
}

fn edit_strategy() -> impl Strategy<Value = Edit> {
    prop_oneof![
        1 => Just(Edit::Slot),
        4 => (any::<usize>(), any::<usize>()).prop_map(|(a, b)| Edit::Spring(a, b)),
        3 => (any::<usize>(), any::<usize>(), any::<usize>()).prop_map(|(s, a, b)| Edit::Move(s, a, b)),
        2 => any::<usize>().prop_map(Edit::Remove),
    ]
}

/// Two distinct slots picked by (a, b) among n ≥ 2.
fn pick_ends(n: usize, a: usize, b: usize) -> [u32; 2] {
    let a = a % n;
    let b = (a + 1 + b % (n - 1)) % n;
    [a as u32, b as u32]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// The incidence lists edited in place (appending slots and springs, moving spring ends,
    /// swap-removing springs, with segment moves and compactions) always hold exactly the springs
    /// of `ends`, and give the same forces as a system built fresh from the same arrays (up to the
    /// summation order inside each vertex).
    #[test]
    fn incidence_lists_follow_edits(edits in prop::collection::vec(edit_strategy(), 1..120)) {
        use topomech::mechanics::SpringSystem;
        let n0 = 4;
        let mut sys = SpringSystem::new(
            vec![[0, 1], [1, 2], [2, 3]], vec![1.0; 3], vec![10.0, 20.0, 30.0], vec![0.1; 3],
            vec![1.0; n0], &[false; 4], vec![0.0; n0], [0.0, 0.0, -1.0],
        ).unwrap();
        for e in &edits {
            let n = sys.slots();
            match *e {
                Edit::Slot => { sys.push_slot(1.0 + n as f64, false, 0.01).unwrap(); }
                Edit::Spring(a, b) => { sys.push_spring(pick_ends(n, a, b), 0.5, 1.0 + a as f64 % 7.0, 0.2).unwrap(); }
                Edit::Move(s, a, b) if sys.springs() > 0 => {
                    let s = s % sys.springs();
                    sys.set_spring(s, pick_ends(n, a, b), 0.7, 3.0, 0.3).unwrap();
                }
                Edit::Remove(s) if sys.springs() > 0 => { sys.swap_remove_spring(s % sys.springs()).unwrap(); }
                _ => {}
            }
            prop_assert!(sys.check_incidence().is_ok(), "{:?}", sys.check_incidence());
        }
        let fixed: Vec<bool> = sys.inv_mass().iter().map(|&w| w == 0.0).collect();
        let fresh = SpringSystem::new(
            sys.ends().to_vec(), sys.rest().to_vec(), sys.stiffness().to_vec(), sys.damping().to_vec(),
            sys.mass().to_vec(), &fixed, sys.viscosity().to_vec(), sys.gravity(),
        ).unwrap();
        let n = sys.slots();
        let x: Vec<Vec3> = (0..n).map(|i| [i as f64 * 0.37, (i * i % 5) as f64 * 0.11, (i % 3) as f64]).collect();
        let v: Vec<Vec3> = (0..n).map(|i| [0.01 * i as f64, -0.02, 0.0]).collect();
        let (mut sf1, mut sf2) = (vec![[0.0; 3]; sys.springs()], vec![[0.0; 3]; sys.springs()]);
        let (mut f1, mut f2) = (vec![[0.0; 3]; n], vec![[0.0; 3]; n]);
        sys.forces(&x, &v, &mut sf1, &mut f1, false).unwrap();
        fresh.forces(&x, &v, &mut sf2, &mut f2, false).unwrap();
        for i in 0..n {
            for c in 0..3 {
                let (a, b) = (f1[i][c], f2[i][c]);
                prop_assert!((a - b).abs() <= 1e-9 * (1.0 + a.abs().max(b.abs())), "slot {} force {:?} vs fresh {:?}", i, f1[i], f2[i]);
            }
        }
        let deg = |s: &SpringSystem, i| { let mut l: Vec<_> = s.incident(i).map(|(k, w)| (k, w as i8)).collect(); l.sort_unstable(); l };
        for i in 0..n {
            prop_assert_eq!(deg(&sys, i), deg(&fresh, i));
        }
    }
}
