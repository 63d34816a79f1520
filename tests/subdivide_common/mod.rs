//! Shared by the subdivision suites: leveled maps of the generated meshes, and the laws every
//! leveled map obeys after any operation.
#![allow(dead_code)]

use topomech::generate::{grid_triangles, kuhn_cube};
use topomech::mechanics::Material;
use topomech::subdivide::fuzz::{Op, MAX_FUZZ_LEVEL};
use topomech::subdivide::{CouplingError, LeveledMap, LeveledMechanics};
use topomech::{DartId, GMap};

/// The tet of the spring-coupling suites' one-tet mesh.
pub const TET: [[f64; 3]; 4] = [[0.0, 0.0, 0.0], [1.0, 0.1, 0.0], [0.2, 1.0, 0.1], [0.1, 0.3, 1.0]];

/// The material of the spring-coupling suites (β > 0, so damping follows every rule too).
pub fn material() -> Material {
    Material { density: 2.0, young: 500.0, damping: 0.01, viscosity: 0.5 }
}

/// The level of a decoded op: the map's maximum, or one above it (`up`) below the fuzz cap.
pub fn level_of(m: &LeveledMap<3>, up: bool) -> u8 {
    let top = m.max_level();
    if up && top < MAX_FUZZ_LEVEL {
        top + 1
    } else {
        top
    }
}

/// The coupling of the level-0 map `m` with [`material`], set moving: jittered velocities, and
/// positions moved off the rest positions by a tenth of a jitter (so that interpolation and the
/// momentum correction are seen at work).
pub fn moving_coupling(m: &LeveledMap<3>) -> Result<LeveledMechanics, String> {
    let mut mech = LeveledMechanics::new(m, material()).map_err(|e| e.to_string())?;
    for (v, x) in mech.velocity.iter_mut().enumerate() {
        *x = jitter(v as u64);
    }
    for (v, x) in mech.position.iter_mut().enumerate() {
        *x = [0, 1, 2].map(|k| x[k] + 0.1 * jitter(100 + v as u64)[k]);
    }
    Ok(mech)
}

/// The pick-th live dart (modulo their number).
pub fn pick(m: &LeveledMap<3>, pick: u16) -> DartId {
    m.map().darts().nth(pick as usize % m.map().dart_count()).unwrap()
}

/// The leveled map (all at level 0) of a tet mesh with one position per point. O(tets).
pub fn tet_mesh(points: Vec<[f64; 3]>, tets: &[[u32; 4]]) -> LeveledMap<3> {
    let (map, _) = GMap::<3>::from_tets(points.len(), tets).unwrap();
    LeveledMap::new(map, points)
}

/// The leveled map (all at level 0) of a triangle mesh with one position per point. O(triangles).
pub fn triangle_mesh(points: Vec<[f64; 3]>, triangles: &[[u32; 3]]) -> LeveledMap<2> {
    let (map, _) = GMap::<2>::from_triangles(points.len(), triangles).unwrap();
    LeveledMap::new(map, points)
}

/// The Kuhn cube of k³ unit cells (6k³ tets).
pub fn cube(k: usize) -> LeveledMap<3> {
    let (points, tets) = kuhn_cube(k);
    tet_mesh(points, &tets)
}

/// The n × n grid of unit squares, each cut into 2 triangles.
pub fn grid(n: usize) -> LeveledMap<2> {
    let (points, triangles) = grid_triangles(n);
    triangle_mesh(points, &triangles)
}

/// The laws of a leveled map after any operation: every law of `check_all` (the finest map
/// valid, μt ≤ μf ≤ μa, every level a valid G-map); level k is the finest map itself (up to
/// isomorphism); the darts of level i are at level ≤ i, and B_{i−1} ⊂ B_i; every level has the
/// Euler characteristic of level 0 (subdivision never changes the topology). O(k · darts).
pub fn check_levels<const N: usize>(m: &LeveledMap<N>) {
    m.check_all().unwrap();
    let top = m.level(m.max_level()).unwrap();
    assert!(top.map.is_isomorphic(m.map()), "level k must be the finest map");
    let chi0 = m.level(0).unwrap().map.euler_characteristic();
    for i in 0..=m.max_level() {
        let view = m.level(i).unwrap();
        assert_eq!(view.map.euler_characteristic(), chi0, "level {i}");
        assert!(view.darts.iter().all(|&d| m.dart_level(d) <= i), "a dart of B_{i} is finer than level {i}");
        if i > 0 {
            let below = m.level(i - 1).unwrap();
            assert!(below.darts.iter().all(|d| view.darts.binary_search(d).is_ok()), "B_{} ⊄ B_{i}", i - 1);
        }
    }
}

/// The cell counts per dimension of every level, coarsest first.
pub fn level_counts<const N: usize>(m: &LeveledMap<N>) -> Vec<Vec<usize>> {
    (0..=m.max_level()).map(|i| m.level(i).unwrap().map.count_cells().0).collect()
}

/// A deterministic pseudo-random vector in [−1, 1]³ (xorshift of `seed`, steps of 0.001).
pub fn jitter(seed: u64) -> [f64; 3] {
    let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15).wrapping_add(1);
    [0, 1, 2].map(|_| {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s % 2001) as f64 / 1000.0 - 1.0
    })
}

/// One text line per dart slot of `map` (`k dead`, or `k a[α0..αn] c[cell ids]`), for
/// fingerprints that must notice any change of the numbering. O(capacity · n).
pub fn dart_rows<const N: usize>(map: &GMap<N>) -> String {
    let mut out = String::new();
    for k in 0..map.capacity() as u32 {
        let d = topomech::DartId(k);
        if !map.contains(d) {
            out.push_str(&format!("{k} dead\n"));
            continue;
        }
        let alpha: Vec<u32> = (0..=N).map(|i| map.alpha_dyn(i, d).0).collect();
        let cell: Vec<u32> = (0..=N).map(|i| map.cell_id(i, d).0).collect();
        out.push_str(&format!("{k} a{alpha:?} c{cell:?}\n"));
    }
    out
}

/// The split log read through [origins](LeveledMap::vertex_origin), ends increasing, sorted: what
/// two maps with the same split history agree on, however their logs were written (a loaded
/// map's log is rebuilt from its link history, finding 336). O(log length · log).
pub fn canon_log<const N: usize>(x: &LeveledMap<N>) -> Vec<[u32; 3]> {
    let mut log: Vec<[u32; 3]> = x
        .split_log()
        .iter()
        .map(|e| {
            let [v, a, b] = e.map(|u| x.vertex_origin(u));
            [v, a.min(b), a.max(b)]
        })
        .collect();
    log.sort_unstable();
    log
}

/// The pick-th α3-sewn dart (any dart when none is sewn: the map refuses it).
pub fn sewn(m: &LeveledMap<3>, pick: u16) -> DartId {
    let sewn: Vec<DartId> = m.map().darts().filter(|&d| !m.map().is_free(3, d)).collect();
    match sewn.len() {
        0 => m.map().darts().next().unwrap(),
        n => sewn[pick as usize % n],
    }
}

/// Applies one decoded op through the spring coupling (a cut by `LeveledMechanics::unsew_face`);
/// `None` for a reload (no file holds a coupling).
pub fn apply_coupled(mech: &mut LeveledMechanics, m: &mut LeveledMap<3>, op: Op) -> Option<Result<(), CouplingError>> {
    Some(match op {
        Op::SplitEdge { pick: p, up } => mech.split_edge(m, pick(m, p), level_of(m, up)).map(drop),
        Op::Triangle { pick: p, up } => mech.subdivide_triangle(m, pick(m, p), level_of(m, up)).map(drop),
        Op::Tet { pick: p, up } => mech.subdivide_tet(m, pick(m, p), level_of(m, up)).map(drop),
        Op::Around { center, radius } => {
            let c = [f64::from(center[0]) / 255.0, f64::from(center[1]) / 255.0, 0.5];
            let levels = level_of(m, true);
            mech.refine_around(m, c, f64::from(radius) / 255.0, levels).map(drop)
        }
        Op::Cut { pick: p, up } => mech.unsew_face(m, sewn(m, p), level_of(m, up)).map(drop),
        Op::Reload { .. } => return None,
    })
}
