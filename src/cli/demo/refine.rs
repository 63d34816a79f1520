//! Refinement of the incision zone (seed 004): the final body's map and current positions wrapped
//! as level 0 of a [`LeveledMap`], and each tet beside the incision subdivided 1→8 at level 1.
//!
//! Masses follow the subdivision: each child tet takes its parent's mass in proportion to its
//! volume ([`LeveledMap::subdivide_tet_with_mass`]), and the stage checks that Σ tet mass is
//! unchanged. Springs do not follow yet (no stiffness for the new edges), so there is no stiffness
//! balance here; the level laws are checked instead ([`LeveledMap::check_all`]: finest map valid,
//! μt ≤ μf ≤ μa, every level extracted and valid).

use std::time::Instant;

use indicatif::ProgressBar;
use topomech::mechanics::{Body, Vec3};
use topomech::subdivide::{LeveledMap, TetMasses};
use topomech::surface::Surface;
use topomech::{AlphaMask, CellId, DartId, GMap};

use super::scene::{centroid, StageRun};
use super::DemoError;

/// The level the incision zone is refined to.
pub const LEVEL: u8 = 1;

/// Wraps `body` (map, current positions, tet masses) as level 0 and subdivides the live tets
/// among `tets` at [`LEVEL`], sharing their masses, then checks every level law and the mass
/// balance. Returns the leveled map, the tet masses and the checks passed.
/// O(tets · darts) to find the tets plus the subdivisions and O(capacity · n²) for the check.
///
/// # Errors
/// [`DemoError::Subdivide`] naming the tet, [`DemoError::Levels`] when a level law fails,
/// [`DemoError::Balance`] when Σ tet mass changed by more than the tolerance.
pub fn refine(
    body: &Body,
    tets: &[CellId],
    run: &mut StageRun,
    bar: &ProgressBar,
) -> Result<(LeveledMap<3>, TetMasses, usize), DemoError> {
    let points = body.attrs().position.as_slice().to_vec();
    let mut lm = LeveledMap::new(body.map().clone(), points);
    // The leveled map starts as a copy of the body's map: same volume ids, so the same masses.
    let mut masses =
        TetMasses { mass: (0..body.map().cell_id_bound(3)).map(|t| body.attrs().tet_mass(CellId(t as u32))).collect() };
    let before = masses.total(&lm);
    let t0 = Instant::now();
    for &t in tets {
        let found = lm.map().darts().find(|&d| lm.map().cell_id(3, d) == t && lm.mu(d).tet < LEVEL);
        if let Some(d) = found {
            let t1 = Instant::now();
            lm.subdivide_tet_with_mass(d, LEVEL, &mut masses)
                .map_err(|source| DemoError::Subdivide { tet: t, source })?;
            run.step_us.push(t1.elapsed().as_secs_f64() * 1e6);
            run.operations += 1;
        }
        bar.inc(1);
    }
    run.operation_us = t0.elapsed().as_secs_f64() * 1e6;
    lm.check_all().map_err(DemoError::Levels)?;
    let residual = (masses.total(&lm) - before) / before;
    if residual.abs() > super::checks::TOLERANCE {
        return Err(DemoError::Balance { stage: "refinement", step: 0, quantity: "mass", residual });
    }
    Ok((lm, masses, 3))
}

/// The boundary of the finest level as triangles: every α3-free face, its vertex cycle walked by
/// α0 then α1 and fanned from its first vertex (zero-area triangles at flat vertices dropped),
/// oriented away from its volume's centroid; with, per triangle, μt of the volume behind it (its
/// resolution level, for colouring). O(darts).
pub fn refined_surface(lm: &LeveledMap<3>) -> (Surface, Vec<u8>) {
    let map = lm.map();
    let mut index = vec![u32::MAX; map.cell_id_bound(0)];
    let mut s = Surface::default();
    let mut levels = Vec::new();
    for d in map.one_dart_per_cell(2) {
        if !map.is_free(3, d) {
            continue;
        }
        let cycle = face_cycle(map, d);
        let inside = volume_centroid(lm, d);
        let ids: Vec<u32> = cycle.iter().map(|&v| vertex_index(&mut s, &mut index, lm, v)).collect();
        for k in 1..ids.len().saturating_sub(1) {
            let tri = [ids[0], ids[k], ids[k + 1]];
            let p = tri.map(|i| s.positions[i as usize]);
            let n = cross(sub(p[1], p[0]), sub(p[2], p[0]));
            let area2 = dot(n, n);
            if area2 <= f64::EPSILON * dot(sub(p[1], p[0]), sub(p[1], p[0])).powi(2) {
                continue;
            }
            let outward = dot(n, sub(p[0], inside)) >= 0.0;
            s.triangles.push(if outward { tri } else { [tri[0], tri[2], tri[1]] });
            s.face_volumes.push(map.cell_id(3, d).0);
            levels.push(lm.mu(d).tet);
        }
    }
    (s, levels)
}

/// The vertex ids around the face of `d`, in order. Bounded by the face's dart count.
fn face_cycle(map: &GMap<3>, d: DartId) -> Vec<CellId> {
    let mut out = vec![map.vertex_id(d)];
    let mut x = map.alpha::<1>(map.alpha::<0>(d));
    for _ in 0..map.dart_count() {
        if x == d {
            break;
        }
        out.push(map.vertex_id(x));
        x = map.alpha::<1>(map.alpha::<0>(x));
    }
    out
}

fn volume_centroid(lm: &LeveledMap<3>, d: DartId) -> Vec3 {
    let map = lm.map();
    let mut ids: Vec<CellId> = map.orbit(d, AlphaMask::cell(3, 3)).into_iter().map(|x| map.vertex_id(x)).collect();
    ids.sort_unstable();
    ids.dedup();
    centroid(ids.iter().map(|v| lm.points().get(v.index()).copied().unwrap_or([0.0; 3])))
}

fn vertex_index(s: &mut Surface, index: &mut [u32], lm: &LeveledMap<3>, v: CellId) -> u32 {
    if index[v.index()] == u32::MAX {
        index[v.index()] = s.positions.len() as u32;
        s.positions.push(lm.points().get(v.index()).copied().unwrap_or([0.0; 3]));
        s.vertex_ids.push(v.0);
    }
    index[v.index()]
}

fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

#[cfg(test)]
mod tests {
    use super::*;
    use topomech::{cut, generate};

    fn cube() -> Body {
        let (points, tets) = generate::kuhn_cube(2);
        Body::from_tets(&points, &tets, cut::ops::material()).unwrap().0
    }

    #[test]
    fn refining_some_tets_keeps_the_enclosed_volume_and_marks_their_level() {
        let body = cube();
        let before = topomech::surface::boundary_surface(&body);
        let tets: Vec<CellId> = (0..12).map(CellId).collect();
        let mut run = StageRun::default();
        let mass = body.attrs().total_tet_mass(body.map());
        let (lm, masses, checks) = refine(&body, &tets, &mut run, &ProgressBar::hidden()).unwrap();
        assert_eq!((run.operations, checks), (12, 3));
        assert!((masses.total(&lm) - mass).abs() < 1e-12 * mass, "the children share the parents' masses");
        assert_eq!(lm.map().count_cells().0[3], 48 + 7 * 12, "1→8 per refined tet");
        let (after, levels) = refined_surface(&lm);
        assert_eq!(levels.len(), after.triangles.len());
        assert!((after.enclosed_volume() - before.enclosed_volume()).abs() < 1e-12, "same solid");
        assert!((after.enclosed_volume() - 8.0).abs() < 1e-12);
        assert!(levels.contains(&0) && levels.contains(&LEVEL), "both levels show on the boundary");
        assert!(after.triangles.len() > before.triangles.len());
    }

    #[test]
    fn an_unrefined_map_gives_back_the_body_surface() {
        let body = cube();
        let (lm, _, _) = refine(&body, &[], &mut StageRun::default(), &ProgressBar::hidden()).unwrap();
        let (s, levels) = refined_surface(&lm);
        assert_eq!(s.triangles.len(), 12 * 4, "12k² boundary faces for k = 2");
        assert!(levels.iter().all(|&l| l == 0));
        assert!((s.enclosed_volume() - 8.0).abs() < 1e-12);
    }
}
