//! Embeddings, conservation laws and the embedding-aware unsew/sew of a mechanical body.

use topomech::embedding::CellRules;
use topomech::generate::{kuhn_cube, SplitMix64};
use topomech::mechanics::{
    check_conservation, forces_by_coverage, Body, BodyError, ConservationError, FlatModel, Integrator, Material,
    Projection, SimError, Simulation, StepConfig, Vec3,
};
use topomech::{CellId, DartId};

const G: Vec3 = [0.0, 0.0, -9.81];

fn material() -> Material {
    Material { density: 2.5, young: 700.0, damping: 0.01, viscosity: 0.7 }
}

fn rel_close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * a.abs().max(b.abs())
}

/// Slightly irregular Kuhn cube (points jittered) so that tets have different volumes.
fn jittered_cube(k: usize, seed: u64) -> (Vec<Vec3>, Vec<[u32; 4]>) {
    let (mut points, tets) = kuhn_cube(k);
    let mut rng = SplitMix64(seed);
    for p in &mut points {
        for c in p.iter_mut() {
            *c += (rng.below(1000) as f64 / 1000.0 - 0.5) * 0.2;
        }
    }
    (points, tets)
}

/// The darts (one per face) of the interior faces lying in the plane x = `x` of a Kuhn cube.
fn faces_in_plane(body: &Body, rest: &[Vec3], x: f64) -> Vec<DartId> {
    let map = body.map();
    let mut seen = std::collections::HashSet::new();
    let mut out = Vec::new();
    for d in map.darts() {
        if map.is_free(3, d) || !seen.insert(map.cell_id(2, d)) {
            continue;
        }
        let face = map.orbit(d, topomech::AlphaMask::of(&[0, 1]));
        if face.iter().all(|&e| rest[map.vertex_id(e).index()][0] == x) {
            out.push(d);
        }
    }
    out
}

#[test]
fn laws_hold_on_a_fresh_body_and_match_the_flat_baseline() {
    let (points, tets) = jittered_cube(3, 7);
    let (body, report) = Body::from_tets(&points, &tets, material()).unwrap();
    assert!(report.pinched_vertices.is_empty());
    check_conservation(body.map(), body.attrs()).unwrap();
    let mech = body.attrs();
    // Σ m_v = ρ Σ V_t, computed from the input directly.
    let volume: f64 = tets
        .iter()
        .map(|t| {
            let c = t.map(|v| points[v as usize]);
            topomech::mesh::signed_volume(c[0], c[1], c[2], c[3]).abs()
        })
        .sum();
    assert!(rel_close(mech.total_vertex_mass(body.map()).unwrap(), 2.5 * volume, 1e-12));
    assert!(rel_close(mech.total_tet_mass(body.map()).unwrap(), 2.5 * volume, 1e-12));
    // Every vertex mass and spring stiffness equals the flat baseline's (built with no map).
    let flat = FlatModel::from_tets(&points, &tets, material(), G, &[]).unwrap();
    for (v, &m) in flat.system.mass().iter().enumerate() {
        assert!(rel_close(mech.vertex_mass(CellId(v as u32)), m, 1e-12), "vertex {v}");
    }
    let projection = Projection::build(&body, G).unwrap();
    assert_eq!(projection.system().ends(), flat.system.ends());
    for s in 0..flat.system.springs() {
        assert!(rel_close(projection.system().stiffness()[s], flat.system.stiffness()[s], 1e-12), "spring {s}");
        assert!(rel_close(projection.system().rest()[s], flat.system.rest()[s], 1e-12), "spring {s}");
    }
}

#[test]
fn an_interior_edge_gets_the_sum_of_its_tets_contributions() {
    // The Kuhn cube's main diagonal (0,0,0)–(1,1,1) of a unit cube is shared by its 6 tets.
    let (points, tets) = kuhn_cube(1);
    let (body, _) = Body::from_tets(&points, &tets, material()).unwrap();
    let p = Projection::build(&body, G).unwrap();
    let s = (0..p.system().springs()).find(|&s| p.system().ends()[s] == [0, 7]).expect("diagonal spring");
    let l = 3f64.sqrt();
    let expected = 6.0 * 700.0 * (1.0 / 6.0) / (l * l);
    assert!(rel_close(p.system().stiffness()[s], expected, 1e-12), "{} vs {expected}", p.system().stiffness()[s]);
    // Corner vertex 0 belongs to all 6 tets: m = 6 · ρ (1/6) / 4.
    assert!(rel_close(body.attrs().vertex_mass(CellId(0)), 2.5 / 4.0, 1e-12));
}

#[test]
fn unsew3_along_a_plane_splits_masses_and_stiffnesses_conservatively() {
    let (points, tets) = kuhn_cube(2);
    let (mut body, _) = Body::from_tets(&points, &tets, material()).unwrap();
    let before = body.clone();
    let total = body.total_vertex_mass();
    let faces = faces_in_plane(&body, &points, 1.0);
    assert_eq!(faces.len(), 8, "the plane x = 1 of a 2-cube holds 8 triangles");
    let mut vertex_splits = Vec::new();
    let mut edge_splits = Vec::new();
    let mut partners = Vec::new();
    for &d in &faces {
        partners.push((d, body.map().alpha::<3>(d)));
        let changes = body.unsew3(d).unwrap();
        vertex_splits.extend(changes.splits(0));
        edge_splits.extend(changes.splits(1));
        check_conservation(body.map(), body.attrs()).unwrap();
    }
    // The 9 vertices and 16 edges of the plane each split exactly once.
    assert_eq!(vertex_splits.len(), 9);
    assert_eq!(edge_splits.len(), 16);
    let (m0, m) = (before.attrs(), body.attrs());
    for &(kept, new, dk, dn) in &vertex_splits {
        let sum = m.vertex_mass(kept) + m.vertex_mass(new);
        assert!(rel_close(sum, m0.vertex_mass(kept), 1e-12), "m = m1 + m2 at {kept:?}");
        assert!(m.vertex_mass(kept) > 0.0 && m.vertex_mass(new) > 0.0);
        assert_eq!(m.position()[new], m.position()[kept]);
        assert_ne!(body.map().vertex_id(dk), body.map().vertex_id(dn));
    }
    for &(kept, new, _, _) in &edge_splits {
        let sum = m.edge_stiffness(kept) + m.edge_stiffness(new);
        assert!(rel_close(sum, m0.edge_stiffness(kept), 1e-12), "k = k1 + k2 at {kept:?}");
        assert!(rel_close(m.edge_damping(kept) + m.edge_damping(new), m0.edge_damping(kept), 1e-12));
    }
    assert!(rel_close(m.total_vertex_mass(body.map()).unwrap(), total, 1e-12));
    // The body is now two halves: it must equal the flat model of the two halves, built apart.
    let (half_points, half_tets) = split_at_plane(&points, &tets, 1.0);
    let flat = FlatModel::from_tets(&half_points, &half_tets, material(), G, &[]).unwrap();
    let projection = Projection::build(&body, G).unwrap();
    assert_eq!(projection.system().springs(), flat.system.springs());
    let mut ours: Vec<f64> = projection.system().stiffness().to_vec();
    let mut theirs = flat.system.stiffness().to_vec();
    ours.sort_by(f64::total_cmp);
    theirs.sort_by(f64::total_cmp);
    for (a, b) in ours.iter().zip(&theirs) {
        assert!(rel_close(*a, *b, 1e-12));
    }
    // Every new boundary face has a unit normal pointing out of its own half.
    for &(d, e) in &partners {
        for x in [d, e] {
            let f = body.map().cell_id(2, x);
            assert!(m.face_is_boundary(f));
            let n = m.face_normal(f);
            let tet = body.map().cell_darts(3, x);
            let cx: f64 = tet.iter().map(|&y| m.position()[body.map().vertex_id(y)][0]).sum::<f64>() / tet.len() as f64;
            let side = if cx < 1.0 { 1.0 } else { -1.0 };
            assert!((n[0].abs() - 1.0).abs() < 1e-12 && n[0] * side > 0.0, "normal {n:?}");
        }
    }
    // Sewing back restores every mass and stiffness.
    for &(d, e) in &partners {
        body.sew3(d, e).unwrap();
        check_conservation(body.map(), body.attrs()).unwrap();
    }
    assert!(body.map().is_isomorphic(before.map()));
    // Ids may have moved (a merge keeps one side's id), so compare through rest positions.
    let flat = FlatModel::from_tets(&points, &tets, material(), G, &[]).unwrap();
    let point_of = |v: u32| points.iter().position(|p| *p == body.attrs().rest_position()[CellId(v)]).unwrap() as u32;
    let p1 = Projection::build(&body, G).unwrap();
    let mut springs: Vec<([u32; 2], f64)> = (0..p1.system().springs())
        .map(|s| {
            let [a, b] = p1.system().ends()[s].map(point_of);
            ([a.min(b), a.max(b)], p1.system().stiffness()[s])
        })
        .collect();
    springs.sort_by_key(|&(e, _)| e);
    assert_eq!(springs.len(), flat.system.springs());
    for (s, (ends, k)) in springs.iter().enumerate() {
        assert_eq!(*ends, flat.system.ends()[s]);
        assert!(rel_close(*k, flat.system.stiffness()[s], 1e-12));
    }
    for d in body.map().one_dart_per_cell(0) {
        let v = body.map().vertex_id(d);
        assert!(rel_close(body.attrs().vertex_mass(v), flat.system.mass()[point_of(v.0) as usize], 1e-12));
    }
}

/// Duplicates the points with x == plane used by tets on the x > plane side.
fn split_at_plane(points: &[Vec3], tets: &[[u32; 4]], plane: f64) -> (Vec<Vec3>, Vec<[u32; 4]>) {
    let mut points = points.to_vec();
    let n = points.len();
    let mut copy = vec![u32::MAX; n];
    let mut out = Vec::new();
    for tet in tets {
        let right = tet.iter().any(|&v| points[v as usize][0] > plane);
        let mut t = *tet;
        if right {
            for v in &mut t {
                if points[*v as usize][0] == plane {
                    if copy[*v as usize] == u32::MAX {
                        copy[*v as usize] = points.len() as u32;
                        points.push(points[*v as usize]);
                    }
                    *v = copy[*v as usize];
                }
            }
        }
        out.push(t);
    }
    (points, out)
}

#[test]
fn check_conservation_names_the_vertex_when_the_map_changes_behind_its_back() {
    let (points, tets) = kuhn_cube(2);
    let (mut body, _) = Body::from_tets(&points, &tets, material()).unwrap();
    let faces = faces_in_plane(&body, &points, 1.0);
    // All but one face unsewn through the embedding layer: the laws hold.
    for &d in &faces[1..] {
        body.unsew3(d).unwrap();
    }
    check_conservation(body.map(), body.attrs()).unwrap();
    // The last face unsewn on the bare map, behind the rules' back.
    let (mut map, mut mech) = body.into_parts();
    let changes = map.unsew_dyn(3, faces[0]).unwrap();
    let split: Vec<CellId> = changes.splits(0).flat_map(|(kept, new, _, _)| [kept, new]).collect();
    assert!(!split.is_empty(), "the last face of the plane splits vertices");
    // Arrays too short for the new ids: reported as such, not a panic.
    assert!(matches!(check_conservation(&map, &mech), Err(ConservationError::MissingAttributes { dim: 0, .. })));
    // Arrays grown but values stale: the mass law fails at one of the split vertices.
    mech.grow_to(&map);
    match check_conservation(&map, &mech) {
        Err(ConservationError::VertexMass { vertex, stored, expected, .. }) => {
            assert!(split.contains(&vertex), "{vertex:?} not among {split:?}");
            assert!(!rel_close(stored, expected, 1e-12));
        }
        other => panic!("stale masses passed the check: {other:?}"),
    }
}

#[test]
fn projection_forces_equal_the_orbit_walk_to_1e_12() {
    let (points, tets) = jittered_cube(3, 11);
    let (mut body, _) = Body::from_tets(&points, &tets, material()).unwrap();
    let mut rng = SplitMix64(99);
    let mut r = || rng.below(2001) as f64 / 1000.0 - 1.0;
    {
        let mut m = body.attrs_mut();
        for v in 0..m.position().len() {
            let id = CellId(v as u32);
            for c in 0..3 {
                m.position_mut()[id][c] += 0.1 * r();
                m.velocity_mut()[id][c] = r();
            }
        }
    }
    body.attrs_mut().pin_where(|id, _| id.0 % 7 == 0);
    for round in 0..2 {
        if round == 1 {
            // After a topological change the rebuilt projection still agrees.
            let d = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
            body.unsew3(d).unwrap();
        }
        let p = Projection::build(&body, G).unwrap();
        let n = p.system().slots();
        let m = body.attrs();
        let mut sf = vec![[0.0; 3]; p.system().springs()];
        let mut f = vec![[0.0; 3]; n];
        p.system()
            .forces(&m.position().as_slice()[..n], &m.velocity().as_slice()[..n], &mut sf, &mut f, false)
            .unwrap();
        let reference = forces_by_coverage(&body, G);
        let scale = reference.iter().flat_map(|v| v.iter()).fold(0.0f64, |a, &b| a.max(b.abs()));
        assert!(scale > 1.0);
        for v in 0..n {
            for c in 0..3 {
                assert!(
                    (f[v][c] - reference[v][c]).abs() <= 1e-12 * scale,
                    "vertex {v}: {:?} vs {:?}",
                    f[v],
                    reference[v]
                );
            }
        }
        // Every spring knows its edge and dart.
        for s in 0..p.system().springs() {
            let d = p.dart_of_spring(s);
            assert_eq!(body.map().cell_id(1, d), p.edge_of_spring(s));
            assert_eq!(p.spring_of_edge(p.edge_of_spring(s)), Some(s));
            let ends = [body.map().vertex_id(d).0, body.map().vertex_id(body.map().alpha::<0>(d)).0];
            assert!(ends.contains(&p.system().ends()[s][0]) && ends.contains(&p.system().ends()[s][1]));
        }
    }
}

#[test]
fn a_stale_projection_refuses_to_step() {
    let (points, tets) = kuhn_cube(2);
    let (mut body, _) = Body::from_tets(&points, &tets, material()).unwrap();
    let mut sim = Simulation::new(&mut body, G, StepConfig::new(Integrator::Rk4, 1e-4)).unwrap();
    sim.step(&mut body).unwrap();
    let d = faces_in_plane(&body, &points, 1.0)[0];
    body.unsew3(d).unwrap();
    assert!(matches!(sim.step(&mut body), Err(SimError::StaleProjection { built: 0, now: 1 })));
    sim.rebuild(&mut body).unwrap();
    sim.step(&mut body).unwrap();
}

/// A simulation runs only the body it was built for. Before, stepping a larger body with the
/// simulation of a smaller one returned Ok and moved the first vertices by the other body's
/// springs, the reverse panicked on a slice bound, and `update` took the touched cells of
/// another body; a clone (same version) was taken for the original.
#[test]
fn a_simulation_refuses_a_body_it_was_not_built_for() {
    let body = |k: usize| Body::from_tets(&kuhn_cube(k).0, &kuhn_cube(k).1, material()).unwrap().0;
    let config = StepConfig::new(Integrator::Rk4, 1e-4);
    let (mut small, mut big) = (body(1), body(2));
    let mut copy = small.clone();
    let mut sim = Simulation::new(&mut small, G, config).unwrap();
    for other in [&mut big, &mut copy] {
        let before = other.attrs().position().as_slice().to_vec();
        match sim.step(other) {
            Err(e @ SimError::OtherBody { built_for, given }) => {
                assert_eq!((built_for, given), (small.identity(), other.identity()));
                assert!(e.to_string().contains("rebuild it for this body"), "{e}");
            }
            r => panic!("expected OtherBody, got {r:?}"),
        }
        assert_eq!(other.attrs().position().as_slice(), &before[..], "nothing moved");
    }
    let mut sim_big = Simulation::new(&mut big, G, config).unwrap();
    assert!(matches!(sim_big.step(&mut small), Err(SimError::OtherBody { .. })), "the reverse panicked");
    let d = copy.map().darts().find(|&d| !copy.map().is_free(3, d)).unwrap();
    let touched = topomech::cut::dissociate_face(&mut copy, d).unwrap().touched;
    assert!(matches!(sim.update(&mut copy, &touched), Err(SimError::OtherBody { .. })));
    sim.step(&mut small).unwrap(); // its own body still runs
    sim_big.rebuild(&mut small).unwrap(); // and a rebuild adopts a body
    sim_big.step(&mut small).unwrap();
}

#[test]
fn unsew3_of_a_boundary_dart_is_refused_and_changes_nothing() {
    let (points, tets) = kuhn_cube(1);
    let (mut body, _) = Body::from_tets(&points, &tets, material()).unwrap();
    let d = body.map().darts().find(|&d| body.map().is_free(3, d)).unwrap();
    let version = body.version();
    assert!(body.unsew3(d).is_err());
    assert_eq!(body.version(), version);
    check_conservation(body.map(), body.attrs()).unwrap();
}

/// The merge rule of vertex state (the inverse of a split): when a sew joins two vertices, the
/// kept one takes the mass-weighted mean of both positions and velocities and is pinned if
/// either side was. Checked on the plane x = 1 of a 2-cube after its two halves were moved,
/// given different velocities and one side pinned.
#[test]
fn sew3_merges_vertices_by_mass_weighted_state_and_keeps_pins() {
    let (points, tets) = kuhn_cube(2);
    let (mut body, _) = Body::from_tets(&points, &tets, material()).unwrap();
    let mut partners = Vec::new();
    let mut split = Vec::new();
    for d in faces_in_plane(&body, &points, 1.0) {
        partners.push((d, body.map().alpha::<3>(d)));
        split.extend(body.unsew3(d).unwrap().splits(0).map(|(kept, new, _, _)| (kept, new)));
    }
    assert_eq!(split.len(), 9);
    for (i, &(kept, new)) in split.iter().enumerate() {
        let mut m = body.attrs_mut();
        let p = m.position()[kept];
        m.position_mut()[new] = [p[0] + 0.25, p[1] + 0.1 * i as f64, p[2] - 0.05];
        m.velocity_mut()[kept] = [1.0, 0.0, 0.5 * i as f64];
        m.velocity_mut()[new] = [-3.0, 2.0, 0.0];
        m.pinned_mut()[new] = i % 2 == 0;
    }
    let before = body.attrs().clone();
    let mut merged = Vec::new();
    for &(d, e) in &partners {
        merged.extend(body.sew3(d, e).unwrap().merges(0));
        check_conservation(body.map(), body.attrs()).unwrap();
    }
    assert_eq!(merged.len(), 9, "every split vertex joins again once");
    let m = body.attrs();
    for &(kept, absorbed) in &merged {
        let (mk, ma) = (before.vertex_mass(kept), before.vertex_mass(absorbed));
        assert!(mk > 0.0 && ma > 0.0);
        // Both free (or both pinned): the mass-weighted means; one side pinned: that side's
        // state (a pin holds its vertex; round 27).
        let mix = |a: Vec3, b: Vec3| -> Vec3 {
            match (before.pinned()[kept], before.pinned()[absorbed]) {
                (true, false) => a,
                (false, true) => b,
                _ => std::array::from_fn(|k| (mk * a[k] + ma * b[k]) / (mk + ma)),
            }
        };
        let want_x = mix(before.position()[kept], before.position()[absorbed]);
        let want_v = mix(before.velocity()[kept], before.velocity()[absorbed]);
        assert_ne!(before.position()[absorbed], before.position()[kept], "the two sides were apart");
        for k in 0..3 {
            assert!(
                (m.position()[kept][k] - want_x[k]).abs() < 1e-12,
                "position of {kept:?}: {:?} vs {want_x:?}",
                m.position()[kept]
            );
            assert!(
                (m.velocity()[kept][k] - want_v[k]).abs() < 1e-12,
                "velocity of {kept:?}: {:?} vs {want_v:?}",
                m.velocity()[kept]
            );
        }
        assert_eq!(m.pinned()[kept], before.pinned()[kept] || before.pinned()[absorbed], "pin of {kept:?}");
    }
    assert!(merged.iter().any(|&(k, _)| m.pinned()[k]) && merged.iter().any(|&(k, _)| !m.pinned()[k]));
}

/// A sew may only merge vertices that coincide at rest. Before, `sew3` of two boundary faces on
/// opposite sides of a cube succeeded and left the rest lengths of the merged edges wrong (law 3
/// broken, found by `check_conservation` only afterwards), and a face could be sewn onto itself
/// by a reflection. Now both are refused before the map changes, naming the two vertices, and
/// the body is untouched; sewing a dissociated face back still works.
#[test]
fn a_sew_that_merges_vertices_apart_at_rest_is_refused_and_changes_nothing() {
    let (points, tets) = kuhn_cube(2);
    let (mut body, _) = Body::from_tets(&points, &tets, material()).unwrap();
    let map = body.map();
    let free: Vec<DartId> = map.darts().filter(|&d| map.is_free(3, d)).collect();
    let rest = |d: DartId| body.attrs().rest_position()[body.map().vertex_id(d)];
    let a = free[0];
    // Faces on the opposite side: no vertex of theirs is at a's rest position.
    let far: Vec<DartId> =
        free.iter().copied().filter(|&b| (0..3).all(|k| (rest(a)[k] - rest(b)[k]).abs() > 1.5)).collect();
    let mut tried = 0;
    for b in far {
        if !body.map().is_sewable_dyn(3, a, b) {
            continue;
        }
        tried += 1;
        let (version, darts, attrs) = (body.version(), body.map().dart_count(), format!("{:?}", body.attrs()));
        match body.sew3(a, b) {
            Err(e @ BodyError::Refused { source: ConservationError::SewApart { distance, .. }, .. }) => {
                assert!(distance > 1.5, "{e}");
                assert!(e.to_string().contains("only faces that coincide at rest can be sewn"), "{e}");
            }
            other => panic!("sew3({a:?}, {b:?}): expected SewApart, got {other:?}"),
        }
        assert_eq!((body.version(), body.map().dart_count()), (version, darts));
        assert!(body.map().is_free(3, a) && body.map().is_free(3, b));
        assert_eq!(format!("{:?}", body.attrs()), attrs, "the attributes are untouched");
        body.map().validate().unwrap();
        check_conservation(body.map(), body.attrs()).unwrap();
    }
    assert!(tried > 0, "some far face is sewable to a's topologically");
    // Folded onto itself by a reflection (a with α1(a)): two corners of the triangle would merge.
    let fold = body.map().alpha::<1>(a);
    assert!(body.map().is_sewable_dyn(3, a, fold));
    assert!(matches!(body.sew3(a, fold), Err(BodyError::Refused { source: ConservationError::SewApart { .. }, .. })));
    // A dissociated face sews back, after its two sides have moved apart (current positions).
    let d = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
    let e = body.map().alpha::<3>(d);
    let splits: Vec<CellId> = body.unsew3(d).unwrap().splits(0).map(|(_, new, _, _)| new).collect();
    for v in splits {
        body.attrs_mut().position_mut()[v][2] += 0.5;
    }
    body.sew3(d, e).unwrap();
    check_conservation(body.map(), body.attrs()).unwrap();
}

/// A model whose volume or totals overflow f64 is refused at build, naming the tet and the
/// quantity, by the map-driven body and the flat model alike; the same mesh at a sane scale
/// builds, with the same totals in both.
#[test]
fn a_model_whose_totals_overflow_is_refused_naming_the_tet_and_quantity() {
    use topomech::mechanics::ModelError;
    let (points, tets) = kuhn_cube(2);
    let scaled = |s: f64| points.iter().map(|p| p.map(|c| c * s)).collect::<Vec<Vec3>>();
    let with = |density: f64, young: f64, damping: f64| Material { density, young, damping, viscosity: 0.0 };
    let cases: [(Vec<Vec3>, Material, &str); 4] = [
        (scaled(1e110), with(1.0, 1.0, 0.0), "volume"),
        (scaled(1e100), with(1e10, 1.0, 0.0), "total mass"),
        (scaled(1.0), with(1.0, 1e308, 0.0), "total stiffness"),
        (scaled(1.0), with(1.0, 1e300, 1e10), "total damping"),
    ];
    for (points, material, what) in cases {
        let body = Body::from_tets(&points, &tets, material).map(|_| ());
        let flat = FlatModel::from_tets(&points, &tets, material, G, &[]).map(|_| ());
        for got in [body, flat] {
            match got {
                Err(ModelError::Overflow { tet, quantity, value }) => {
                    assert_eq!(quantity, what);
                    assert!(tet < tets.len() && !value.is_finite(), "{what}: tet {tet}, value {value}");
                }
                other => panic!("{what}: expected an overflow, got {other:?}"),
            }
        }
    }
    let (body, _) = Body::from_tets(&scaled(1e50), &tets, with(1.0, 1.0, 1.0)).unwrap();
    check_conservation(body.map(), body.attrs()).unwrap();
    let flat = FlatModel::from_tets(&scaled(1e50), &tets, with(1.0, 1.0, 1.0), G, &[]).unwrap();
    let total: f64 = flat.system.mass().iter().sum();
    assert!(rel_close(total, body.total_vertex_mass(), 1e-12) && total.is_finite());
}

/// Finding 24 (docs/VERIFICATION.md): `Body::new` wrapped any map with any attributes, and every
/// operation then ran on a body that broke the conservation laws from the start. Parts from
/// outside are now checked; refused parts come back unchanged.
#[test]
fn a_body_from_parts_that_disagree_is_refused_and_the_parts_come_back() {
    let build = |k: usize| {
        let (points, tets) = kuhn_cube(k);
        Body::from_tets(&points, &tets, material()).unwrap().0
    };
    // Each way round: a larger map with smaller attributes, and the reverse.
    for (map_from, attrs_from) in [(2, 1), (1, 2)] {
        let (map, _) = build(map_from).into_parts();
        let (_, mech) = build(attrs_from).into_parts();
        let (darts, rest) = (map.dart_count(), mech.rest_position().as_slice().to_vec());
        let refused = Body::new(map, mech).unwrap_err();
        assert!(refused.to_string().starts_with("the attributes do not agree with the map"), "{refused}");
        assert_eq!(refused.map.dart_count(), darts);
        assert_eq!(&refused.attrs.rest_position().as_slice()[..rest.len()], &rest[..]);
    }
    // A lawful body after cuts goes apart and back together.
    let mut body = build(2);
    let d = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
    body.unsew3(d).unwrap();
    let (map, mech) = body.into_parts();
    let again = Body::new(map, mech).unwrap();
    assert!(again.check().is_ok() && again.map().is_free(3, d));
    // The same cube with its points numbered the other way round: as many darts and cells, each
    // set of attributes lawful on its own map, but vertex i is another corner in each, so the
    // edge laws of one do not hold on the edges of the other (the first one checked, the
    // stiffness from its tets, fails).
    let (map, _) = again.into_parts();
    let (points, tets) = kuhn_cube(2);
    let last = points.len() as u32 - 1;
    let reversed_points: Vec<_> = points.iter().rev().copied().collect();
    let reversed_tets: Vec<[u32; 4]> = tets.iter().map(|t| t.map(|v| last - v)).collect();
    let (reversed, _) = Body::from_tets(&reversed_points, &reversed_tets, material()).unwrap();
    assert!(reversed.check().is_ok());
    let (_, mech) = reversed.into_parts();
    let refused = Body::new(map, mech).unwrap_err();
    assert!(matches!(refused.error, ConservationError::EdgeStiffness { .. }), "{refused}");
}

/// Finding 26 (docs/VERIFICATION.md): `Projection::update` trusted its touched list. A vertex id
/// past the map panicked; a missed, repeated or hand-made list left a projection that said it
/// was current but was not a fresh build. Only lists that take the projection to the body's
/// version are applied incrementally now; anything else rebuilds.
#[test]
fn a_projection_update_takes_only_lists_that_bring_it_up_to_date() {
    use topomech::cut::dissociate_face;
    use topomech::mechanics::TouchedCells;
    let fresh = |b: &Body| Projection::build(b, G).unwrap();
    let inner = |b: &Body, k: usize| b.map().darts().filter(|&d| !b.map().is_free(3, d)).nth(k).unwrap();
    let (points, tets) = kuhn_cube(2);
    let base = Body::from_tets(&points, &tets, material()).unwrap().0;

    // Hand-made lists: an id past the map, a dart past the map. Rebuilt, no panic.
    let hand = TouchedCells::by_hand(vec![(CellId(9999), None)], vec![(CellId(5000), Some(DartId(88888)))]);
    let mut p = fresh(&base);
    assert!(!p.update(&base, &hand));
    assert!(p.is_current(&base) && p.equivalent(&fresh(&base)).is_ok());

    // Two cuts; a projection from before them.
    let mut body = base.clone();
    let before = fresh(&body);
    let d = inner(&body, 0);
    let first = dissociate_face(&mut body, d).unwrap();
    let d = inner(&body, 200);
    let second = dissociate_face(&mut body, d).unwrap();
    assert!(before.equivalent(&fresh(&body)).is_err(), "the cuts must need an update");
    for (name, list) in [("empty", TouchedCells::default()), ("first cut only", first.touched.clone())] {
        let mut p = before.clone();
        assert!(!p.update(&body, &list), "{name}");
        assert!(p.is_current(&body) && p.equivalent(&fresh(&body)).is_ok(), "{name}: not a fresh build");
    }
    // Both lists in order: incremental. Out of order: rebuilt.
    let mut both = first.touched.clone();
    both.extend(&second.touched);
    let mut reversed = second.touched.clone();
    reversed.extend(&first.touched);
    assert_eq!(both.versions(&body), Some((0, 2)));
    assert_eq!(reversed.versions(&body), None);
    let mut p = before.clone();
    assert!(!p.update(&body, &reversed));
    assert!(p.equivalent(&fresh(&body)).is_ok());
    let mut p = before.clone();
    assert!(p.update(&body, &both), "the operations' lists in order are incremental");
    assert!(p.equivalent(&fresh(&body)).is_ok());
    // Sewing both back, each change recorded: incremental too.
    let mut back = TouchedCells::default();
    for dis in [&second, &first] {
        let changes = body.sew3(dis.dart, dis.opposite).unwrap();
        back.record_change(&body, &changes);
    }
    assert_eq!(back.versions(&body), Some((2, 4)));
    assert!(p.update(&body, &back), "recorded changes in order are incremental");
    assert!(p.equivalent(&fresh(&body)).is_ok());
    assert!(!p.update(&body, &back), "the same list again is refused and rebuilt");
    assert!(p.equivalent(&fresh(&body)).is_ok());
    let d = inner(&body, 0);
    let again = dissociate_face(&mut body, d).unwrap();
    let by_hand = TouchedCells::by_hand(again.touched.vertices().to_vec(), again.touched.edges().to_vec());
    assert!(!p.update(&body, &by_hand), "a copy by hand has no version stamp");
    assert!(p.equivalent(&fresh(&body)).is_ok());
}

/// The laws are checked where the docs say: with `expensive-checks` a sew or unsew whose rules
/// leave the attributes broken returns `EmbedError::Check` (a rule that breaks its law on every
/// split, below), and `Embedded::check` reports it. (`Body::check` on a moved rest position is
/// a unit test in `src/mechanics/model.rs`: rest positions are read-only from outside.)
/// Found missing by the twenty-fourth mutation sample (docs/VERIFICATION.md).
#[test]
fn check_reports_a_broken_law_and_the_layer_checks_after_each_operation() {
    /// Counts splits and calls its own law broken once any happened.
    struct SplitsBreak(usize);
    #[derive(Debug, thiserror::Error)]
    #[error("{0} splits")]
    struct Broken(usize);
    impl CellRules<3> for SplitsBreak {
        type Error = Broken;
        fn grow_to(&mut self, _: &topomech::GMap<3>) {}
        fn on_split(&mut self, _: &topomech::GMap<3>, _: &topomech::embedding::Split<'_>) {
            self.0 += 1;
        }
        fn on_merge(&mut self, _: &topomech::GMap<3>, _: usize, _: CellId, _: CellId) {}
        fn check(&self, _: &topomech::GMap<3>) -> Result<(), Broken> {
            if self.0 == 0 {
                Ok(())
            } else {
                Err(Broken(self.0))
            }
        }
    }
    let (map, _) = topomech::GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
    let d = map.darts().find(|&d| !map.is_free(3, d)).unwrap();
    let mut e = topomech::embedding::Embedded::new(map, SplitsBreak(0)).unwrap();
    let result = e.unsew(3, d);
    assert!(e.map().is_free(3, d), "the unsew itself is done");
    if cfg!(feature = "expensive-checks") {
        assert!(matches!(result, Err(topomech::embedding::EmbedError::Check { op: "unsew", .. })), "{result:?}");
    } else {
        assert!(result.is_ok());
    }
    assert!(e.check().is_err());
}

/// Removing a tet counts as a topological change even when no face had to be dissociated first
/// (a lone tet): the version moves on and a projection built before is stale. Found missing by
/// the twenty-fourth mutation sample (the version bump of the crate-private bypass).
#[test]
fn removing_a_lone_tet_moves_the_version_on() {
    let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let (mut body, _) = Body::from_tets(&points, &[[0, 1, 2, 3]], material()).unwrap();
    let projection = Projection::build(&body, G).unwrap();
    let removal = topomech::cut::remove_volume(&mut body, CellId(0)).unwrap();
    assert!(removal.dissociations.is_empty());
    assert_eq!(body.version(), 1);
    assert!(!projection.is_current(&body));
    assert_eq!(removal.touched.versions(&body), Some((0, 1)));
}

/// Finding 32 (docs/VERIFICATION.md): the `Mechanics` functions that take the map beside the
/// attributes (`total_vertex_mass`, `total_tet_mass`, `vertex_mass_from_map`,
/// `edge_stiffness_from_map`, `update_normals`) panicked on an index when given another body's
/// map or a dart that is not live. They now return `ConservationError::MissingAttributes` or
/// `NoSuchDart`, as `check_conservation` does for such a pair, and change nothing.
/// (`update_normals` takes no map any more: it is `Body::update_normals`, round 25.)
#[test]
fn attributes_given_another_bodys_map_or_a_dead_dart_are_refused() {
    use topomech::mechanics::ConservationError;
    let body = |k| {
        let (points, tets) = kuhn_cube(k);
        Body::from_tets(&points, &tets, Material::default()).unwrap().0
    };
    let (small, big) = (body(1), body(2));
    let missing = Err(ConservationError::MissingAttributes { dim: 0, len: 8, bound: 27 });
    let m = small.attrs();
    assert_eq!(m.total_vertex_mass(big.map()), missing);
    assert_eq!(m.total_tet_mass(big.map()), missing);
    let far = big.map().darts().last().unwrap();
    assert_eq!(m.vertex_mass_from_map(big.map(), far), missing);
    assert_eq!(m.edge_stiffness_from_map(big.map(), far), missing);
    let dead = DartId(small.map().capacity() as u32 + 5);
    assert_eq!(m.vertex_mass_from_map(small.map(), dead), Err(ConservationError::NoSuchDart(dead)));
    assert_eq!(m.edge_stiffness_from_map(small.map(), dead), Err(ConservationError::NoSuchDart(dead)));
    // The body's own pair: the laws as before.
    assert!((m.total_vertex_mass(small.map()).unwrap() - 1.0).abs() < 1e-12);
    assert_eq!(m.total_tet_mass(small.map()).unwrap(), small.total_tet_mass());
    let d = small.map().darts().next().unwrap();
    assert_eq!(m.vertex_mass_from_map(small.map(), d), Ok(m.vertex_mass(small.map().vertex_id(d))));
    assert!(
        (m.edge_stiffness_from_map(small.map(), d).unwrap() / m.edge_stiffness(small.map().cell_id(1, d)) - 1.0).abs()
            < 1e-12
    );
}

/// Finding 40 (docs/VERIFICATION.md): the flat oracle and the projections took what the body
/// refuses. `FlatModel::from_tets` built a model with negative spring stiffnesses from
/// `young = -1` and massless slots (silently fixed) from `density = 0`, took a pin list of any
/// length (a short one left the rest free) and a NaN gravity; `Projection::build` and
/// `LeveledMechanics::spring_system` stored a NaN gravity in a system that `SpringSystem::check`
/// then refused. Each is now refused at the door with the error naming the value.
#[test]
fn the_flat_oracle_and_the_projections_refuse_what_the_body_refuses() {
    use topomech::mechanics::{ModelError, SystemError};
    use topomech::subdivide::{CouplingError, LeveledMap, LeveledMechanics};
    let (points, tets) = kuhn_cube(1);
    let flat = |m: Material, g: [f64; 3], pins: &[bool]| FlatModel::from_tets(&points, &tets, m, g, pins);
    for (name, bad) in [
        ("young", Material { young: -1.0, ..material() }),
        ("density", Material { density: 0.0, ..material() }),
        ("density", Material { density: f64::NAN, ..material() }),
        ("viscosity", Material { viscosity: f64::INFINITY, ..material() }),
    ] {
        assert!(
            matches!(Body::from_tets(&points, &tets, bad), Err(ModelError::BadMaterial { name: n, .. }) if n == name)
        );
        let e = flat(bad, [0.0; 3], &[]).unwrap_err();
        assert!(matches!(e, ModelError::BadMaterial { name: n, .. } if n == name), "{name}: {e}");
    }
    assert!(matches!(flat(material(), [0.0, f64::NAN, 0.0], &[]), Err(ModelError::BadGravity(_))));
    assert_eq!(flat(material(), [0.0; 3], &[true; 2]).unwrap_err(), ModelError::PinCount { len: 2, points: 8 });
    assert_eq!(flat(material(), [0.0; 3], &[true; 9]).unwrap_err(), ModelError::PinCount { len: 9, points: 8 });
    let pinned = flat(material(), [0.0; 3], &[true; 8]).unwrap();
    assert!(pinned.system.inv_mass().iter().all(|&w| w == 0.0) && pinned.system.check().is_ok());

    let (body, _) = Body::from_tets(&points, &tets, material()).unwrap();
    let e = Projection::build(&body, [f64::INFINITY, 0.0, 0.0]).unwrap_err();
    assert!(matches!(e, SystemError::BadGravity(g) if g[0] == f64::INFINITY));
    assert!(Projection::build(&body, G).unwrap().system().check().is_ok());

    let (map, _) = topomech::GMap::<3>::from_tets(points.len(), &tets).unwrap();
    let leveled = LeveledMap::new(map, points.clone());
    let coupling = LeveledMechanics::new(&leveled, material()).unwrap();
    let e = coupling.spring_system(&leveled, [0.0, 0.0, f64::NAN], &[]).unwrap_err();
    assert!(matches!(e, CouplingError::System(SystemError::BadGravity(_))), "{e}");
    assert!(coupling.spring_system(&leveled, G, &[]).unwrap().check().is_ok());
}
