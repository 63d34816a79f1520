//! Mutation sample 51: laws of `check_refused` (through `refusal_holds`) that the subdivision
//! corpora do not pin down, checked on refusals built by hand against small maps whose levels
//! are known.

use topomech::subdivide::fuzz::check_refused;
use topomech::subdivide::{LeveledMap, SubdivideError};
use topomech::GMap;

fn one_tet() -> LeveledMap<3> {
    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    LeveledMap::new(map, vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
}

/// `OpenEdge(d)` is a false refusal when d is free for no αj, j < n (a closed map), and a true
/// one for a dart of an edge left open (α1-free in 2D, α2-free in 3D).
#[test]
fn an_open_edge_refusal_must_name_an_open_dart() {
    // 2D: one closed triangle, then the same triangle with one α1 link undone.
    let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
    let closed = LeveledMap::new(map.clone(), vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    for d in closed.map().darts() {
        let msg = check_refused(&closed, &closed, &SubdivideError::OpenEdge(d));
        assert!(msg.is_err(), "a closed triangle refused as open at {d:?} passed the check");
    }
    let mut open = map;
    let d = open.darts().next().unwrap();
    open.unsew::<1>(d).unwrap();
    // Undoing an α1 link splits a corner into two vertices: the new one needs a position.
    let mut o = LeveledMap::new(open, vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0]]);
    let before = o.clone();
    let e = o.refine_uniform(1).unwrap_err();
    assert!(matches!(e, SubdivideError::OpenEdge(_)), "{e}");
    assert_eq!(check_refused(&before, &o, &e), Ok(()));

    // 3D: a closed tet (α3-free only, which is not an open edge) and one with an α2 link undone.
    let t = one_tet();
    for d in t.map().darts() {
        assert!(check_refused(&t, &t, &SubdivideError::OpenEdge(d)).is_err(), "dart {d:?}");
    }
    let (mut map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let d = map.darts().next().unwrap();
    map.unsew::<2>(d).unwrap();
    let open3 = LeveledMap::new(map, vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
    assert_eq!(check_refused(&open3, &open3, &SubdivideError::OpenEdge(d)), Ok(()));
}

/// `AlreadyAtLevel { dim, cell_level, level }` holds exactly when the cell's own level (μa, μf,
/// μt by dim) is `cell_level` and `cell_level ≥ level`: true statements pass, with equality and
/// with a strictly higher cell level, for every dimension; a cell level below the level asked for,
/// or a cell level the dart does not have, is a false refusal.
#[test]
fn an_already_at_level_refusal_must_be_true_of_the_cell() {
    let mut m = one_tet();
    let d = m.map().darts().next().unwrap();
    // A genuine refusal of the operation itself (μt = 0 ≥ 0).
    let before = m.clone();
    let e = m.subdivide_tet(d, 0).unwrap_err();
    assert!(matches!(e, SubdivideError::AlreadyAtLevel { dim: 3, cell_level: 0, level: 0, .. }), "{e}");
    assert_eq!(check_refused(&before, &m, &e), Ok(()));

    // After one 1→8 split every dart has μa = μf = μt = 1.
    m.subdivide_tet(d, 1).unwrap();
    let x = m.map().darts().next().unwrap();
    let mu = m.mu(x);
    assert_eq!((mu.edge, mu.face, mu.tet), (1, 1, 1));
    let refusal = |dim, cell_level, level| SubdivideError::AlreadyAtLevel { dart: x, dim, cell_level, level };
    for dim in 1..=3 {
        // True: the cell is at level 1, asked for 1 or for 0.
        assert_eq!(check_refused(&m, &m, &refusal(dim, 1, 1)), Ok(()), "dim {dim}, 1 ≥ 1");
        assert_eq!(check_refused(&m, &m, &refusal(dim, 1, 0)), Ok(()), "dim {dim}, 1 ≥ 0");
        // False: the cell level is not the dart's, or below the level asked for.
        assert!(check_refused(&m, &m, &refusal(dim, 0, 0)).is_err(), "dim {dim}: level 0 claimed");
        assert!(check_refused(&m, &m, &refusal(dim, 1, 2)).is_err(), "dim {dim}: 1 < 2 refused");
    }
    // No cell level for dimension 0 or 4.
    assert!(check_refused(&m, &m, &refusal(0, 1, 1)).is_err());
    assert!(check_refused(&m, &m, &refusal(4, 1, 1)).is_err());
}
