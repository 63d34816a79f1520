//! Every single raw corruption of every small valid map: `validate()` must fail exactly when a
//! law is broken and name a broken law with a true witness.

use crate::laws::{all_maps, check_validate_names_law};
use topomech::gmap::Law;
use topomech::ops::{self, RawEdit};
use topomech::{DartId, GMap};

/// Every raw edit on a map with `cap` slots: each link and unlink, and each cell id overwrite
/// with an id in 0..=bound (one past the allocator, so never allocated).
fn all_edits<const N: usize>(map: &GMap<N>) -> Vec<RawEdit> {
    let cap = map.capacity() as u32;
    let mut edits = Vec::new();
    for i in 0..=N {
        for a in 0..cap {
            edits.push(RawEdit::Unlink { i, a: DartId(a) });
            for b in 0..cap {
                edits.push(RawEdit::Link { i, a: DartId(a), b: DartId(b) });
            }
        }
    }
    for dim in 0..=N {
        for d in 0..cap {
            for id in 0..=map.cell_id_bound(dim) as u32 {
                edits.push(RawEdit::SetCell { dim, d: DartId(d), id });
            }
        }
    }
    edits
}

/// Checks every edit of every map on ≤ k darts, with and without one dead dart slot; returns
/// how often each law was named.
fn corruptions<const N: usize>(k: usize) -> Vec<(Law, usize)> {
    let mut named: Vec<(Law, usize)> = Vec::new();
    for darts in 1..=k {
        for table in all_maps::<N>(darts) {
            for with_dead in [false, true] {
                let mut map = ops::from_alpha_table::<N>(&table).unwrap();
                if with_dead {
                    let d = map.create_dart().unwrap();
                    map.delete_dart(d).unwrap();
                }
                for edit in all_edits(&map) {
                    let mut broken = map.clone();
                    if !ops::raw_edit_unchecked(&mut broken, edit) {
                        continue;
                    }
                    check_validate_names_law(&broken).unwrap_or_else(|e| panic!("{table:?} + {edit:?}: {e}"));
                    if let Err(v) = broken.validate() {
                        match named.iter_mut().find(|(l, _)| *l == v.law()) {
                            Some((_, c)) => *c += 1,
                            None => named.push((v.law(), 1)),
                        }
                    }
                }
            }
        }
    }
    named
}

#[test]
fn validate_names_the_broken_law_n1() {
    let named = corruptions::<1>(3);
    for law in [Law::Involution, Law::CellIdConstant, Law::CellIdUnique] {
        assert!(named.iter().any(|(l, c)| *l == law && *c > 0), "{law:?} never produced: {named:?}");
    }
}

#[test]
fn validate_names_the_broken_law_n2() {
    let named = corruptions::<2>(3);
    for law in [Law::Involution, Law::QuasiManifold, Law::CellIdConstant, Law::CellIdUnique] {
        assert!(named.iter().any(|(l, c)| *l == law && *c > 0), "{law:?} never produced: {named:?}");
    }
}

#[test]
fn validate_names_the_broken_law_n3() {
    let named = corruptions::<3>(3);
    for law in [Law::Involution, Law::QuasiManifold, Law::CellIdConstant] {
        assert!(named.iter().any(|(l, c)| *l == law && *c > 0), "{law:?} never produced: {named:?}");
    }
}

/// Every single α3 link or unlink and every cell-id overwrite of small complexes of built tets:
/// these edits keep [`GMap::tets_as_built`], so `validate()` takes its tet path (laws restated on
/// tets), which must fail exactly when a law is broken and name the first broken law.
#[test]
fn validate_names_the_broken_law_on_built_tets() {
    let complexes: [&[[u32; 4]]; 3] =
        [&[[0, 1, 2, 3]], &[[0, 1, 2, 3], [0, 1, 2, 4]], &[[0, 1, 2, 3], [0, 1, 2, 4], [0, 1, 3, 4]]];
    let mut named: Vec<(Law, usize)> = Vec::new();
    for tets in complexes {
        let (map, _) = GMap::<3>::from_tets(5, tets).unwrap();
        let edits = all_edits(&map)
            .into_iter()
            .filter(|e| !matches!(e, RawEdit::Link { i, .. } | RawEdit::Unlink { i, .. } if *i < 3));
        for edit in edits {
            let mut broken = map.clone();
            if !ops::raw_edit_unchecked(&mut broken, edit) {
                continue;
            }
            assert!(broken.tets_as_built(), "{edit:?} cleared the flag");
            check_validate_names_law(&broken).unwrap_or_else(|e| panic!("{tets:?} + {edit:?}: {e}"));
            if let Err(v) = broken.validate() {
                match named.iter_mut().find(|(l, _)| *l == v.law()) {
                    Some((_, c)) => *c += 1,
                    None => named.push((v.law(), 1)),
                }
            }
        }
    }
    for law in [Law::Involution, Law::QuasiManifold, Law::CellIdConstant] {
        assert!(named.iter().any(|(l, c)| *l == law && *c > 0), "{law:?} never produced: {named:?}");
    }
}

/// Every α3 rewiring (unlink a and b, then link them, or leave them free when a = b) of small
/// complexes of built tets keeps α3 an involution and the tets-as-built flag, so the cell and
/// component counts take their tet path (a union-find over tet corners, edges, faces and tets):
/// they must equal the orbit walks of `one_dart_per_cell_by_traversal` and `components`, which
/// read no id and share no code with it.
#[test]
fn cell_counts_on_built_tets_equal_orbit_walks_after_every_alpha3_rewiring() {
    let complexes: [&[[u32; 4]]; 3] =
        [&[[0, 1, 2, 3]], &[[0, 1, 2, 3], [0, 1, 2, 4]], &[[0, 1, 2, 3], [0, 1, 2, 4], [0, 1, 3, 4]]];
    let mut distinct = std::collections::HashSet::new();
    for tets in complexes {
        let (map, _) = GMap::<3>::from_tets(5, tets).unwrap();
        let cap = map.capacity() as u32;
        for a in 0..cap {
            for b in a..cap {
                let mut rewired = map.clone();
                for edit in [
                    RawEdit::Unlink { i: 3, a: DartId(a) },
                    RawEdit::Unlink { i: 3, a: DartId(b) },
                    RawEdit::Link { i: 3, a: DartId(a), b: DartId(b) },
                ] {
                    assert!(ops::raw_edit_unchecked(&mut rewired, edit), "{edit:?} refused");
                }
                assert!(rewired.tets_as_built(), "an α3 edit cleared the flag");
                let walked: Vec<usize> = (0..=3).map(|dim| rewired.one_dart_per_cell_by_traversal(dim).len()).collect();
                let (cells, components) = rewired.count_all_cells_by_traversal();
                assert_eq!(cells.0, walked, "{tets:?}: α3 rewired at {a}, {b}");
                assert_eq!(components, rewired.components().len(), "{tets:?}: α3 rewired at {a}, {b}");
                assert_eq!(rewired.count_cells_by_traversal(), cells);
                distinct.insert((cells.0, components));
            }
        }
    }
    assert!(distinct.len() > 20, "too few distinct outcomes: {}", distinct.len());
}
