//! Exhaustive small-scope checks of face dissociation (and volume removal) on small tet complexes:
//! two tets sharing a face, a closed fan of three tets around an edge, and the Kuhn cube k = 1
//! (six tets). Every order of dissociating every subset of the inner faces is applied (a depth-
//! first walk over all sequences without repetition, sharing prefixes); after each step
//! `cut::ops::Harness::check` verifies validate(), the conservation laws, totals, cell, boundary
//! and component counts against the union-find oracle, and incremental ≡ fresh projection. The
//! maps reached by different orders of the same subset must be isomorphic (dissociation commutes).
//! On the two smaller complexes, removals of live tets are interleaved as well.

use std::collections::BTreeMap;
use std::time::Instant;

use topomech::cut::ops::{Harness, Op};
use topomech::generate::kuhn_cube;
use topomech::mechanics::Vec3;
use topomech::GMap;

/// What the walk visited.
#[derive(Default)]
struct Tally {
    /// States checked (one per step of one sequence).
    states: usize,
    /// One map per set of dissociated faces (and removed tets), the first reached.
    seen: BTreeMap<(Vec<[u32; 3]>, Vec<bool>), GMap<3>>,
}

/// Applies every possible next op to a copy of `h` and recurses; depth ≤ inner faces + tets, so
/// the recursion is bounded by the (tiny) complex, never by a mesh size.
fn walk(h: &Harness, removals: bool, tally: &mut Tally) {
    let glued = h.oracle.glued().len();
    let live = h.oracle.alive.iter().filter(|&&a| a).count();
    let mut next: Vec<Op> = (0..glued).map(Op::Dissociate).collect();
    if removals && live > 1 {
        next.extend((0..live).map(Op::Remove));
    }
    for op in next {
        let mut child = h.clone();
        child.apply(op).unwrap_or_else(|e| panic!("{op:?}: {e}"));
        child.check().unwrap_or_else(|e| panic!("after {op:?}: {e}"));
        tally.states += 1;
        let mut cut: Vec<[u32; 3]> = child.oracle.cut.iter().copied().collect();
        cut.sort_unstable();
        let key = (cut, child.oracle.alive.clone());
        match tally.seen.get(&key) {
            Some(first) => assert!(first.is_isomorphic(child.body.map()), "two orders of {key:?} give different maps"),
            None => {
                tally.seen.insert(key, child.body.map().clone());
            }
        }
        walk(&child, removals, tally);
    }
}

fn exhaust(name: &str, points: Vec<Vec3>, tets: Vec<[u32; 4]>, removals: bool) -> Tally {
    let start = Instant::now();
    let h = Harness::new(points, tets).unwrap();
    h.check().unwrap();
    let mut tally = Tally::default();
    walk(&h, removals, &mut tally);
    eprintln!(
        "{name}: {} states, {} distinct cut sets, every order checked in {:?}",
        tally.states,
        tally.seen.len(),
        start.elapsed()
    );
    tally
}

/// Number of sequences without repetition of length 1..=n over n items: Σ n!/(n−j)!.
fn sequences(n: usize) -> usize {
    (1..=n).map(|j| ((n - j + 1)..=n).product::<usize>()).sum()
}

#[test]
fn two_tets_sharing_a_face() {
    let points = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.3, 0.3, -1.0]];
    let tally = exhaust("two tets", points.clone(), vec![[0, 1, 2, 3], [0, 1, 2, 4]], false);
    assert_eq!(tally.states, 1);
    let with_removals = exhaust("two tets + removals", points, vec![[0, 1, 2, 3], [0, 1, 2, 4]], true);
    // dissociate then remove either (2), or remove either directly (2).
    assert_eq!(with_removals.states, 1 + 2 + 2);
}

/// Three tets around the edge (0, 1), closing the fan: three inner faces, all containing the edge.
fn fan() -> (Vec<Vec3>, Vec<[u32; 4]>) {
    let points = vec![[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.5], [-0.5, 0.87, 0.5], [-0.5, -0.87, 0.5]];
    (points, vec![[0, 1, 2, 3], [0, 1, 3, 4], [0, 1, 4, 2]])
}

#[test]
fn closed_fan_of_three_tets() {
    let (points, tets) = fan();
    let tally = exhaust("fan of 3", points.clone(), tets.clone(), false);
    assert_eq!(tally.states, sequences(3));
    assert_eq!(tally.seen.len(), 7, "every non-empty subset of 3 faces");
    let with_removals = exhaust("fan of 3 + removals", points, tets, true);
    assert!(with_removals.states > tally.states);
}

#[test]
fn kuhn_cube_k1_every_order_of_every_subset() {
    let (points, tets) = kuhn_cube(1);
    let tally = exhaust("Kuhn k=1", points, tets, false);
    assert_eq!(tally.states, sequences(6), "6 inner faces: every sequence without repetition");
    assert_eq!(tally.seen.len(), (1 << 6) - 1, "every non-empty subset reached");
}
