//! Figure 5 of the seed paper (§2.1): a 2D subdivision and its 2-G-map.
//!
//! The paper gives α0, α1, α2 for darts 1..10 and three orbits; the rest of the figure is not in
//! the text, so this test completes it with the smallest subdivision consistent with all of it:
//!
//! ```text
//!          s7                 faces:  f1 = darts 1..8        (quad s1 s2 s3 s4)
//!        9/  \18                      f2 = 11,12,15,16,19..22 (quad s2 s5 s6 s3)
//!       10    17                      f3 = 9,10,13,14,17,18   (triangle s6 s5 s7)
//!      s6 13-14 s5            shared edges: a2 = {3,4 | 19,20} between f1 and f2,
//!      |12    11|                           {11,12 | 13,14}   between f2 and f3.
//!      |15    22|
//!      s3 16 19 21 s2         22 darts, V = 7 (s1..s7), E = 9, F = 3, χ = 1, 7 boundary edges.
//!      |4  f1   3|
//!      |8       2|
//!      s4 7 6 5 1 s1
//! ```
//!
//! Completion (darts 11..22): α0 pairs 11-12, 13-14, 15-16, 17-18, 19-20, 21-22; α1 pairs
//! 14-17, 20-21, 22-11, 12-15, 16-19; α2 pairs 11-14, 12-13 (and 3-20, 4-19 from the table).
//! Dart 21 stays 2-free, as the vertex orbit {2,3,20,21} requires.

use std::collections::BTreeSet;
use topomech::{AlphaMask, DartId, GMap};

/// Figure dart k is `DartId(k − 1)`.
fn dart(k: u32) -> DartId {
    DartId(k - 1)
}

fn figure(d: DartId) -> u32 {
    d.0 + 1
}

const ALPHA0: [(u32, u32); 11] =
    [(1, 2), (3, 4), (5, 6), (7, 8), (9, 10), (11, 12), (13, 14), (15, 16), (17, 18), (19, 20), (21, 22)];
const ALPHA1: [(u32, u32); 11] =
    [(1, 5), (2, 3), (4, 8), (6, 7), (9, 18), (10, 13), (14, 17), (20, 21), (22, 11), (12, 15), (16, 19)];
/// One dart of each 2-sewn edge: the 2-sew links the whole α0 orbit (3-20 brings 4-19).
const ALPHA2: [(u32, u32); 2] = [(3, 20), (11, 14)];

/// Builds the map with `create_dart` and `sew` only.
fn build() -> GMap<2> {
    let mut map = GMap::<2>::new();
    for k in 1..=22 {
        assert_eq!(map.create_dart().unwrap(), dart(k));
    }
    for (a, b) in ALPHA0 {
        map.sew::<0>(dart(a), dart(b)).unwrap();
    }
    for (a, b) in ALPHA1 {
        map.sew::<1>(dart(a), dart(b)).unwrap();
    }
    for (a, b) in ALPHA2 {
        map.sew::<2>(dart(a), dart(b)).unwrap();
    }
    map
}

fn orbit(map: &GMap<2>, k: u32, alphas: &[usize]) -> BTreeSet<u32> {
    map.orbit(dart(k), AlphaMask::of(alphas)).into_iter().map(figure).collect()
}

#[test]
fn the_table_of_the_paper_holds() {
    let map = build();
    // The table of §2.1, copied from the paper: darts 1..10, then α0, α1, α2.
    let table: [[u32; 10]; 3] =
        [[2, 1, 4, 3, 6, 5, 8, 7, 10, 9], [5, 3, 2, 8, 1, 7, 6, 4, 18, 13], [1, 2, 20, 19, 5, 6, 7, 8, 9, 10]];
    for (i, row) in table.iter().enumerate() {
        for (k, &image) in (1..=10).zip(row) {
            assert_eq!(figure(map.alpha_dyn(i, dart(k))), image, "alpha{i}({k})");
        }
    }
}

#[test]
fn the_orbits_of_the_paper_hold() {
    let map = build();
    assert_eq!(orbit(&map, 2, &[1, 2]), BTreeSet::from([2, 3, 20, 21]), "vertex of dart 2");
    assert_eq!(orbit(&map, 3, &[0, 2]), BTreeSet::from([3, 4, 19, 20]), "edge of dart 3");
    assert_eq!(orbit(&map, 9, &[0, 1]), BTreeSet::from([9, 10, 13, 14, 17, 18]), "face of dart 9");
    // The kernel's cell lists agree with the orbits.
    let cell = |i: usize, k: u32| map.cell_darts(i, dart(k)).into_iter().map(figure).collect::<BTreeSet<_>>();
    assert_eq!(cell(0, 2), orbit(&map, 2, &[1, 2]));
    assert_eq!(cell(1, 3), orbit(&map, 3, &[0, 2]));
    assert_eq!(cell(2, 9), orbit(&map, 9, &[0, 1]));
}

#[test]
fn darts_are_cell_tuples_as_in_the_paper() {
    // Dart 1 = (s1, a1, f1), 2 = (s2, a1, f1), 3 = (s2, a2, f1), 20 = (s2, a2, f2).
    let map = build();
    let ids = |k: u32| [0, 1, 2].map(|i| map.cell_id(i, dart(k)));
    let (d1, d2, d3, d20) = (ids(1), ids(2), ids(3), ids(20));
    assert!(d1[0] != d2[0] && d1[1] == d2[1] && d1[2] == d2[2]);
    assert!(d2[0] == d3[0] && d2[1] != d3[1] && d2[2] == d3[2]);
    assert!(d3[0] == d20[0] && d3[1] == d20[1] && d3[2] != d20[2]);
}

#[test]
fn the_completed_map_is_a_valid_disk() {
    let map = build();
    map.validate().unwrap();
    assert_eq!(map.dart_count(), 22);
    assert_eq!(map.count_cells().0, vec![7, 9, 3]);
    assert_eq!(map.count_cells_by_traversal(), map.count_cells());
    assert_eq!(map.euler_characteristic(), 1, "a disk");
    assert_eq!(map.boundary_cell_count(), 7);
    assert_eq!(map.components().len(), 1);
    assert!(map.is_orientable());
    // Every dart of a subdivision of the plane is 0- and 1-sewn.
    assert!(map.darts().all(|d| !map.is_free(0, d) && !map.is_free(1, d)));
}
