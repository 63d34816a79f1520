//! Round 30's probes: a face split 1→4 on its own blocked the balanced zones of `refine_around`
//! (finding 272), and a split mass check that passes at one level can refuse the next (273, a
//! documentation fix, pinned here).

use topomech::generate::kuhn_cube;
use topomech::mechanics::Material;
use topomech::subdivide::{LeveledMap, LeveledMechanics, SubdivideError, TetMasses};
use topomech::GMap;

fn cube(n: usize) -> LeveledMap<3> {
    let (p, t) = kuhn_cube(n);
    let (map, _) = GMap::<3>::from_tets(p.len(), &t).unwrap();
    LeveledMap::new(map, p)
}

/// Finding 272: after `subdivide_triangle` of an inner face (a map `check_faces_refinable`
/// accepts), every ball meeting that face was refused with `FaceRefinedTooFar`: both tets beside
/// the face see it split, and each was taken for a coarser neighbour of the other, so neither
/// was ever ready (72 of the 72 inner faces of `kuhn_cube(2)`). Now every face, inner or on the
/// boundary, split at level 1 or 2, is refined around, plainly and with the spring coupling,
/// and the map stays refinable with every tet at the ball at `levels`.
#[test]
fn a_face_split_on_its_own_does_not_block_a_ball() {
    let start = cube(2);
    let faces = start.map().one_dart_per_cell(2);
    let inner = faces.iter().filter(|&&d| !start.map().is_free(3, d)).count();
    assert_eq!((faces.len(), inner), (120, 72));
    for (k, &d) in faces.iter().enumerate() {
        let (level, levels) = (1 + (k % 2) as u8, 2 + (k % 3 == 0) as u8);
        let mut m = start.clone();
        let mut masses = TetMasses::from_density(&m, 1.0).unwrap();
        let total = masses.total(&m);
        let mut mech = LeveledMechanics::new(&m, Material::default()).unwrap();
        let mut coupled = m.clone();
        m.subdivide_triangle(d, level).unwrap();
        mech.subdivide_triangle(&mut coupled, d, level).unwrap();
        m.check_faces_refinable().unwrap();
        let centre = m.position(d);
        let r = m.refine_around(centre, 0.0, levels, &mut masses);
        assert!(r.is_ok(), "face {d} split at {level}, ball to {levels}: {r:?}");
        m.check_all().unwrap();
        m.check_faces_refinable().unwrap_or_else(|e| panic!("face {d}: {e}"));
        assert!((masses.total(&m) - total).abs() <= 1e-12 * total);
        for t in m.map().one_dart_per_cell(3) {
            let at_ball = m.tet_vertices(t).unwrap().iter().any(|&v| m.points()[v as usize] == centre);
            assert!(!at_ball || m.mu(t).tet >= levels, "face {d}: a tet at the centre stayed at {}", m.mu(t).tet);
        }
        let r = mech.refine_around(&mut coupled, centre, 0.0, levels);
        assert!(r.is_ok(), "coupled, face {d}: {r:?}");
        mech.check(&coupled).unwrap();
        assert_eq!(coupled.map().count_cells(), m.map().count_cells(), "face {d}: plain and coupled differ");
    }
}

/// Finding 273 (documentation): the split mass check of a level passes the parents, and may
/// refuse their children at the next level. A tet of mass 300 / f64::MAX can be split once
/// (64 / m is finite) but its children of mass m / 8 cannot; `refine_around` on the level-0
/// map keeps level 1 and refuses level 2 with `MassTooSmall`, with masses that still cover the
/// map and keep their sum (its docs said such an error came before any change).
#[test]
fn a_split_mass_refusal_at_a_later_level_keeps_the_earlier_levels() {
    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let mut m = LeveledMap::new(map, vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
    let mut masses = TetMasses::from_density(&m, 6.0 * 300.0 / f64::MAX).unwrap();
    let total = masses.total(&m);
    let e = m.refine_around([0.1; 3], 10.0, 2, &mut masses).unwrap_err();
    assert!(matches!(e, SubdivideError::MassTooSmall { .. }), "{e:?}");
    assert_eq!((m.max_level(), m.map().count_cells().0[3]), (1, 8));
    m.check_all().unwrap();
    masses.check(&m).unwrap();
    assert!((masses.total(&m) - total).abs() <= 1e-12 * total);
    // One level is accepted whole.
    let mut one = LeveledMap::new(GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap().0, m.points()[..4].to_vec());
    let mut masses = TetMasses::from_density(&one, 6.0 * 300.0 / f64::MAX).unwrap();
    one.refine_around([0.1; 3], 10.0, 1, &mut masses).unwrap();
    assert_eq!(one.map().count_cells().0[3], 8);
}

/// Mutation sample 47: a zero tet mass (finite and ≥ 0, documented as allowed) must pass the
/// mass checks, and a tet of mass 0 must split into eight children of mass 0 — the checks of
/// finding 268 refuse only positive masses too small for f64 (a `≥ 0` in either guard would
/// refuse 0, whose quarter or 64th has no finite inverse, and no test said so).
#[test]
fn a_zero_tet_mass_is_accepted_and_split() {
    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let mut m = LeveledMap::new(map, vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
    let mut masses = TetMasses { mass: vec![0.0] };
    assert_eq!(masses.check(&m), Ok(()));
    let d = m.map().darts().next().unwrap();
    m.subdivide_tet_with_mass(d, 1, &mut masses).unwrap();
    m.check_all().unwrap();
    masses.check(&m).unwrap();
    let children: Vec<f64> =
        m.map().one_dart_per_cell(3).iter().map(|&t| masses.mass[m.map().cell_id(3, t).index()]).collect();
    assert_eq!(children, vec![0.0; 8]);
    // And a ball around it, another level down.
    m.refine_around([0.1; 3], 0.0, 2, &mut masses).unwrap();
    assert_eq!(masses.total(&m), 0.0);
    masses.check(&m).unwrap();
}
