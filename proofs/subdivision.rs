//! Exhaustive small-scope checks of adaptive subdivision (issue 5): from one triangle, two
//! triangles sharing an edge, one tetrahedron and two tetrahedra sharing a face, **every**
//! sequence of up to `DEPTH` operations — edge split, triangle 1→4 and (3D) tetrahedron 1→8, on
//! one dart of every cell, at the current maximum level or one above, up to level 2 — is applied,
//! and after each step the shared laws of `topomech::subdivide::fuzz` hold: an accepted operation
//! leaves every level valid, μt ≤ μf ≤ μa, level k isomorphic to the finest map and the Euler
//! characteristic of every level unchanged; a refused one is a documented refusal and changes
//! nothing. Plus the closed-form counts of full refinement to level 2.

use topomech::subdivide::fuzz::{check_accepted, check_refused};
use topomech::subdivide::{LeveledMap, SubdivideError};
use topomech::{DartId, GMap};

/// Highest level reached by the enumeration.
const TOP: u8 = 2;

#[derive(Clone, Copy, Debug)]
enum Kind {
    Edge,
    Triangle,
    Tet,
}

#[derive(Default, Debug)]
struct Tally {
    sequences: usize,
    accepted: usize,
    refused: usize,
}

/// Every (kind, dart, level) choice from the state `m`: one dart per cell of the kind's dimension.
fn choices<const N: usize>(m: &LeveledMap<N>, kinds: &[Kind]) -> Vec<(Kind, DartId, u8)> {
    let mut out = Vec::new();
    let levels: Vec<u8> = [m.max_level(), m.max_level() + 1].into_iter().filter(|&l| l <= TOP).collect();
    for &kind in kinds {
        let dim = match kind {
            Kind::Edge => 1,
            Kind::Triangle => 2,
            Kind::Tet => 3,
        };
        for d in m.map().one_dart_per_cell(dim) {
            for &level in &levels {
                out.push((kind, d, level));
            }
        }
    }
    out
}

type Apply<const N: usize> = fn(&mut LeveledMap<N>, Kind, DartId, u8) -> Result<(), SubdivideError>;

fn apply_2d(m: &mut LeveledMap<2>, kind: Kind, d: DartId, level: u8) -> Result<(), SubdivideError> {
    match kind {
        Kind::Edge => m.split_edge(d, level).map(drop),
        _ => m.subdivide_triangle(d, level).map(drop),
    }
}

fn apply_3d(m: &mut LeveledMap<3>, kind: Kind, d: DartId, level: u8) -> Result<(), SubdivideError> {
    match kind {
        Kind::Edge => m.split_edge(d, level).map(drop),
        Kind::Triangle => m.subdivide_triangle(d, level).map(drop),
        Kind::Tet => m.subdivide_tet(d, level).map(drop),
    }
}

/// Depth-first over every sequence of `depth` more operations from `m`.
fn walk<const N: usize>(m: &LeveledMap<N>, depth: usize, kinds: &[Kind], apply: Apply<N>, chi: i64, t: &mut Tally) {
    t.sequences += 1;
    if depth == 0 {
        return;
    }
    for (kind, d, level) in choices(m, kinds) {
        let mut next = m.clone();
        match apply(&mut next, kind, d, level) {
            Ok(()) => {
                t.accepted += 1;
                if let Err(e) = check_accepted(&next, chi) {
                    panic!("{kind:?} on {d} at level {level}: {e}");
                }
                walk(&next, depth - 1, kinds, apply, chi, t);
            }
            Err(e) => {
                t.refused += 1;
                if let Err(msg) = check_refused(m, &next, &e) {
                    panic!("{kind:?} on {d} at level {level} refused ({e}): {msg}");
                }
            }
        }
    }
}

fn exhaust_2d(tris: &[[u32; 3]], points: Vec<[f64; 3]>, depth: usize) -> Tally {
    let (map, _) = GMap::<2>::from_triangles(points.len(), tris).unwrap();
    let m = LeveledMap::new(map, points);
    let chi = m.map().euler_characteristic();
    let mut t = Tally::default();
    walk(&m, depth, &[Kind::Edge, Kind::Triangle], apply_2d, chi, &mut t);
    t
}

fn exhaust_3d(tets: &[[u32; 4]], points: Vec<[f64; 3]>, depth: usize) -> Tally {
    let (map, _) = GMap::<3>::from_tets(points.len(), tets).unwrap();
    let m = LeveledMap::new(map, points);
    let chi = m.map().euler_characteristic();
    let mut t = Tally::default();
    walk(&m, depth, &[Kind::Edge, Kind::Triangle, Kind::Tet], apply_3d, chi, &mut t);
    t
}

const P4: [[f64; 3]; 5] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.4, 0.4, -1.0]];

#[test]
fn every_sequence_of_four_operations_on_one_triangle() {
    let t = exhaust_2d(&[[0, 1, 2]], P4[..3].to_vec(), 4);
    eprintln!("one triangle, depth 4: {t:?}");
    // Both levels, refusals and acceptances are all reached.
    assert!(t.accepted > 100 && t.refused > 10, "{t:?}");
}

#[test]
fn every_sequence_of_three_operations_on_two_triangles() {
    let t = exhaust_2d(&[[0, 1, 2], [1, 3, 2]], vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]], 3);
    eprintln!("two triangles, depth 3: {t:?}");
    assert!(t.accepted > 1000 && t.refused > 100, "{t:?}");
}

#[test]
fn every_sequence_of_three_operations_on_one_tet() {
    let t = exhaust_3d(&[[0, 1, 2, 3]], P4[..4].to_vec(), 3);
    eprintln!("one tet, depth 3: {t:?}");
    assert!(t.accepted > 100 && t.refused > 10, "{t:?}");
}

#[test]
fn every_sequence_of_two_operations_on_two_tets() {
    let t = exhaust_3d(&[[0, 1, 2, 3], [0, 2, 1, 4]], P4.to_vec(), 2);
    eprintln!("two tets, depth 2: {t:?}");
    assert!(t.accepted > 200, "{t:?}");
}

/// Full refinement to level 2 of one triangle and one tet: the counts per level in closed form
/// (triangle: 4^i faces; tet with n = 2^i: T = n³, V = (n+1)(n+2)(n+3)/6).
#[test]
fn full_refinement_to_level_two_has_the_closed_form_counts() {
    let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
    let mut m = LeveledMap::new(map, P4[..3].to_vec());
    for level in 1..=TOP {
        for d in m.map().one_dart_per_cell(2) {
            m.subdivide_triangle(d, level).unwrap();
        }
    }
    let faces: Vec<usize> = (0..=TOP).map(|i| m.level(i).unwrap().map.count_cells().0[2]).collect();
    assert_eq!(faces, vec![1, 4, 16]);
    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let mut m = LeveledMap::new(map, P4[..4].to_vec());
    for level in 1..=TOP {
        for d in m.map().one_dart_per_cell(3) {
            m.subdivide_tet(d, level).unwrap();
        }
    }
    for i in 0..=TOP {
        let n = 1usize << i;
        let c = m.level(i).unwrap().map.count_cells().0;
        assert_eq!((c[0], c[3]), ((n + 1) * (n + 2) * (n + 3) / 6, n * n * n), "level {i}");
    }
}
