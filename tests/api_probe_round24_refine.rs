//! Round 24: the spring coupling's vertex masses at the instant of a refinement (finding 218).
//!
//! The children of a 1→8 partition their parent with masses ∝ rest volume, and inserted vertices
//! take the interpolated position and velocity, so lumping each volume's mass onto its vertices
//! must keep Σ_v m_v x_v and Σ_v m_v v_v: refining must not kick the body. The old lumping
//! (m_t / n_t on every vertex of a coarse volume, hanging vertices included) moved both.

use topomech::generate::kuhn_cube;
use topomech::mechanics::{Material, Vec3};
use topomech::subdivide::{LeveledMap, LeveledMechanics, SpringLawError};
use topomech::GMap;

mod rng_common;
use rng_common::next_unit;

/// (Σ m_v, Σ m_v x_v, Σ m_v v_v) with the coupling's own vertex masses.
fn moments(mech: &LeveledMechanics, m: &LeveledMap<3>) -> (f64, Vec3, Vec3) {
    let mass = mech.vertex_masses(m).unwrap();
    let (mut total, mut first, mut momentum) = (0.0, [0.0; 3], [0.0; 3]);
    for (v, &mv) in mass.iter().enumerate() {
        total += mv;
        for k in 0..3 {
            first[k] += mv * mech.position[v][k];
            momentum[k] += mv * mech.velocity[v][k];
        }
    }
    (total, first, momentum)
}

fn assert_close(before: Vec3, after: Vec3, scale: f64, what: &str) {
    for k in 0..3 {
        assert!((after[k] - before[k]).abs() <= 1e-13 * scale, "{what}: {before:?} -> {after:?}");
    }
}

/// Tet A = [0,1,2,3], tet B = [1,2,3,4] across the face 1-2-3; a ball inside A refines A 1→8,
/// which splits the shared face, so B keeps 4 corners and gains 3 hanging vertices.
fn two_tets() -> (LeveledMap<3>, LeveledMechanics) {
    let points = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]];
    let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [1, 2, 3, 4]]).unwrap();
    let m = LeveledMap::new(map, points.clone());
    let mut mech = LeveledMechanics::new(&m, Material::default()).unwrap();
    for (v, p) in points.iter().enumerate() {
        mech.velocity[v] = [p[2], 0.5 - p[0], 0.0]; // a linear field: midpoints interpolate it exactly
    }
    (m, mech)
}

#[test]
fn f218_refine_around_keeps_the_centre_of_mass_and_the_momentum() {
    let (mut m, mut mech) = two_tets();
    let (m0, x0, p0) = moments(&mech, &m);
    let r = mech.refine_around(&mut m, [0.1, 0.1, 0.1], 0.01, 1).unwrap();
    assert_eq!(r.subdivided_per_level, vec![0, 1]);
    mech.check(&m).unwrap();
    let (m1, x1, p1) = moments(&mech, &m);
    assert!((m1 - m0).abs() <= 1e-15 * m0);
    assert_close(x0, x1, m0, "Σ m x");
    assert_close(p0, p1, m0, "Σ m v");
}

#[test]
fn f218_a_bare_edge_split_keeps_the_first_moment_and_gives_the_midpoint_mass() {
    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let points = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let mut m = LeveledMap::new(map, points);
    let mut mech = LeveledMechanics::new(&m, Material::default()).unwrap();
    let (m0, x0, _) = moments(&mech, &m);
    // split one edge, then a half of it again: a hanging vertex whose parent is hanging too
    let d = m.map().darts().next().unwrap();
    let mid = mech.split_edge(&mut m, d, 1).unwrap();
    mech.split_edge(&mut m, mid, 2).unwrap();
    mech.check(&m).unwrap();
    let mass = mech.vertex_masses(&m).unwrap();
    assert_eq!(mass.len(), 6);
    assert!(mass.iter().all(|&x| x > 0.0), "every vertex has mass: {mass:?}");
    let (m1, x1, _) = moments(&mech, &m);
    assert!((m1 - m0).abs() <= 1e-15 * m0);
    assert_close(x0, x1, m0, "Σ m x");
}

/// Random balls on a jittered cube, deformed and moving with a linear velocity field: every
/// adaptive refinement keeps the total mass, the first moment and the momentum.
#[test]
fn f218_random_adaptive_refinements_keep_both_moments() {
    let mut state = 0x218u64;
    let mut unit = move || next_unit(&mut state);
    let (mut points, tets) = kuhn_cube(3);
    for p in &mut points {
        for x in p.iter_mut() {
            *x += 0.08 * (unit() - 0.5);
        }
    }
    let mut refined = 0;
    for case in 0..12 {
        let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
        let mut m = LeveledMap::new(map, points.clone());
        let mut mech = LeveledMechanics::new(&m, Material::default()).unwrap();
        for (v, p) in points.iter().enumerate() {
            mech.position[v] = [p[0] + 0.1 * p[1], p[1] - 0.05 * p[2], p[2] + 0.02 * p[0]]; // sheared
            let x = mech.position[v];
            mech.velocity[v] = [0.3 + 0.5 * x[1], -0.1 + 0.4 * x[0] - 0.2 * x[2], 0.7 * x[1]];
        }
        let (m0, x0, p0) = moments(&mech, &m);
        let centre = [unit() * 3.0, unit() * 3.0, unit() * 3.0];
        let r = mech.refine_around(&mut m, centre, 0.3 + 0.4 * unit(), 1 + (case % 2) as u8).unwrap();
        refined += r.subdivided_per_level.iter().sum::<usize>();
        mech.check(&m).unwrap();
        let (m1, x1, p1) = moments(&mech, &m);
        assert!((m1 - m0).abs() <= 1e-13 * m0, "case {case}: mass {m0} -> {m1}");
        assert_close(x0, x1, 4.0 * m0, &format!("case {case}: Σ m x"));
        assert_close(p0, p1, 4.0 * m0, &format!("case {case}: Σ m v"));
    }
    assert!(refined > 12, "the balls refined something ({refined} tets)");
}

/// Law 6's first-moment part, as an error, names the axis and both centres.
#[test]
fn f218_the_centre_of_mass_error_names_the_axis() {
    let e = SpringLawError::CentreOfMass { axis: 2, lumped: 0.25, tets: 0.2 };
    assert_eq!(e.to_string(), "centre of mass, axis 2: 2.5e-1 lumped on the vertices, 2e-1 from the tets");
}

/// Finding 228: a 162 000-tet cube, fresh from the builder, passes its own conservation check
/// (the totals Σ m_v and Σ m_t of 10⁵ terms each, summed plainly, differed by 2e-12 relative),
/// and its saved file loads back.
#[test]
fn f228_a_large_cube_passes_its_conservation_check_and_reloads() {
    use topomech::mechanics::{check_conservation, Body};
    use topomech::store::{decode, encode, Document, Format};
    let (points, tets) = kuhn_cube(30);
    let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    assert_eq!(check_conservation(body.map(), body.attrs()), Ok(()));
    let bytes = encode(&Document::from_body(&body), Format::Binary).unwrap();
    let back = decode(&bytes).unwrap().into_body().unwrap();
    assert_eq!(back.map().dart_count(), body.map().dart_count());
}
