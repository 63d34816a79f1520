//! Round 24, finding 225: cutting small pieces off a long ring. After an αi-unsew the kernel
//! decides a cell whose orbit is one path plus its αk image (the centre vertex of a 2D fan after
//! an α2-unsew, the axis edge of a needle of tets after an α3-unsew) by a lockstep walk of the
//! two paths, so each cut costs the piece, not the ring (the cost itself is checked by the unit
//! test `ring_split_costs_the_smaller_side`). These tests check the outcome of long cut
//! sequences through the public API: every cut after the first splits the ring's cell, the new
//! id goes to the small piece, the old id stays with the rest, and `new_side` (when given) is
//! the whole piece.

use topomech::{generate, CellId, DartId, GMap};

/// Checks the split of the ring's `dim`-cell `ring_id` made by the m-th cut: a piece of
/// `piece` darts got a fresh id, the rest (`rest` darts) kept `ring_id`.
fn check_split<const N: usize>(
    map: &GMap<N>,
    changes: &topomech::gmap::CellChanges,
    dim: usize,
    ring_id: CellId,
    (piece, rest): (usize, usize),
) {
    let splits: Vec<_> = changes.splits_with_index(dim).filter(|(_, (kept, ..))| *kept == ring_id).collect();
    assert_eq!(splits.len(), 1, "one split of the ring's cell: {:?}", changes.changes);
    let (k, (_, new, dart_kept, dart_new)) = splits[0];
    assert_ne!(new, ring_id);
    let mut new_cell = map.cell_darts(dim, dart_new);
    assert_eq!((new_cell.len(), map.cell_darts(dim, dart_kept).len()), (piece, rest));
    assert!(new_cell.iter().all(|&d| map.cell_id(dim, d) == new));
    let mut side = changes.new_side(k).to_vec();
    if !side.is_empty() {
        side.sort_unstable();
        new_cell.sort_unstable();
        assert_eq!(side, new_cell, "new_side is the whole new cell");
    }
}

#[test]
fn fan_cut_spoke_by_spoke_splits_two_darts_off_the_centre_each_time() {
    let n = 3_000u32;
    let (points, triangles) = generate::disk_fan(n);
    let (mut map, _) = GMap::<2>::from_triangles(points.len(), &triangles).unwrap();
    // The dart of triangle t at the centre on the spoke it shares with triangle t + 1.
    let spokes: Vec<DartId> = (0..n as usize)
        .map(|t| {
            (6 * t..6 * t + 6)
                .map(|d| DartId(d as u32))
                .find(|&d| map.cell_id(0, d) == CellId(0) && map.alpha::<2>(d).index() / 6 == (t + 1) % n as usize)
                .unwrap()
        })
        .collect();
    let opened = map.unsew::<2>(spokes[0]).unwrap();
    assert_eq!(opened.splits(0).filter(|s| s.0 == CellId(0)).count(), 0, "opening the disk splits no centre");
    for (m, &d) in spokes.iter().enumerate().take(n as usize - 1).skip(1) {
        let changes = map.unsew::<2>(d).unwrap();
        check_split(&map, &changes, 0, CellId(0), (2, 2 * (n as usize - m)));
    }
    assert_eq!(map.count_cells(), map.count_cells_by_traversal());
    assert!(map.validate().is_ok());
}

#[test]
fn needle_cut_face_by_face_splits_one_tet_off_the_axis_each_time() {
    let n = 2_000u32;
    let tets: Vec<[u32; 4]> = (0..n).map(|t| [0, 1, 2 + t, 2 + (t + 1) % n]).collect();
    let (mut map, _) = GMap::<3>::from_tets(n as usize + 2, &tets).unwrap();
    let on_axis = |map: &GMap<3>, d: DartId| map.cell_id(0, d).0 < 2 && map.cell_id(0, map.alpha::<0>(d)).0 < 2;
    // A dart of tet t on the axis and on the face it shares with tet t + 1.
    let faces: Vec<DartId> = (0..n as usize)
        .map(|t| {
            (24 * t..24 * t + 24)
                .map(|d| DartId(d as u32))
                .find(|&d| on_axis(&map, d) && map.alpha::<3>(d).index() / 24 == (t + 1) % n as usize)
                .unwrap()
        })
        .collect();
    let axis = map.cell_id(1, faces[0]);
    assert_eq!(map.cell_darts(1, faces[0]).len(), 4 * n as usize);
    map.unsew::<3>(faces[0]).unwrap();
    for (m, &d) in faces.iter().enumerate().take(n as usize - 1).skip(1) {
        let changes = map.unsew::<3>(d).unwrap();
        check_split(&map, &changes, 1, axis, (4, 4 * (n as usize - m)));
    }
    assert_eq!(map.count_cells(), map.count_cells_by_traversal());
    assert!(map.validate().is_ok());
}
