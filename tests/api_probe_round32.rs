//! Round 32's probes. Finding 278: the implicit step "solved" a right-hand side whose every
//! nonzero entry was NaN (Δv = 0, `Ok`). Finding 279 (documented): a pinned slot whose force
//! overflows is a blow-up in the explicit schemes. Finding 280: the CLI named a failed implicit
//! solve by the library's 0-based step. Findings 281–283: the conforming closure refused faces
//! with tiny corner angles and depended on the vertex numbering; `measure_cut` dropped faces
//! whose centroid lies exactly on the zone's sphere.

use topomech::generate::kuhn_cube;
use topomech::mechanics::{Body, Integrator, Material, Simulation, SpringSystem, StepConfig, StepError, Stepper};

#[path = "cli_common/mod.rs"]
mod cli_common;

/// Three slots on a line, 0 and 2 fixed and pulled apart at ±1e10 through two springs of
/// damping 1e300 to slot 1: slot 1's damping forces overflow to +∞ and −∞, their sum is NaN.
fn nan_force_chain() -> (SpringSystem, Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let sys = SpringSystem::new(
        vec![[0, 1], [1, 2]],
        vec![1.0, 1.0],
        vec![1e300, 1e300],
        vec![1e300, 1e300],
        vec![1.0; 3],
        &[true, false, true],
        vec![0.0; 3],
        [0.0; 3],
    )
    .unwrap();
    let x = vec![[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
    let v = vec![[-1e10, 0.0, 0.0], [0.0; 3], [1e10, 0.0, 0.0]];
    (sys, x, v)
}

#[test]
fn an_implicit_step_with_a_nan_right_hand_side_fails_as_the_explicit_ones_blow_up() {
    let (sys, x0, v0) = nan_force_chain();
    for integrator in [Integrator::Euler, Integrator::Symplectic, Integrator::Rk4, Integrator::Implicit] {
        let (mut x, mut v) = (x0.clone(), v0.clone());
        let mut st = Stepper::new(StepConfig::new(integrator, 1e-3), &sys, &x, &v).unwrap();
        let r = st.step(&sys, &mut x, &mut v);
        match (integrator, r) {
            (Integrator::Implicit, Err(StepError::SolverFailed { step: 0, iterations: 0, .. })) => {}
            (Integrator::Implicit, other) => panic!("implicit: expected SolverFailed at step 0, got {other:?}"),
            // The first slot whose state is not finite: fixed slot 0, whose force overflowed
            // too (finding 279).
            (_, Err(StepError::BlowUp { step: 0, slot: 0, .. })) => {}
            (_, other) => panic!("{integrator:?}: expected a blow-up at step 0, got {other:?}"),
        }
    }
}

#[test]
fn an_implicit_free_fall_at_a_step_past_the_range_of_f64_is_refused() {
    // h² = ∞ and h f₀ = ∞: there is no finite right-hand side (before: `Ok`, nothing moved).
    let (points, tets) = kuhn_cube(1);
    let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    let mut sim = Simulation::new(&mut body, [0.0, 0.0, -9.81], StepConfig::new(Integrator::Implicit, 1e308)).unwrap();
    match sim.step(&mut body) {
        Err(e) => assert!(e.to_string().contains("conjugate gradient"), "{e}"),
        Ok(()) => panic!("a step of 1e308 s under gravity was reported as solved"),
    }
}

#[test]
fn an_overflowing_force_on_a_pinned_slot_is_a_blow_up_named_at_that_slot() {
    // Slots 0 and 1 fixed and moving apart through a spring of damping 1e300 (its force
    // overflows, on fixed slots only); slot 2 free, at rest, joined to slot 0 by a spring without
    // stiffness or damping. The documented behaviour (finding 279): the explicit schemes report
    // a blow-up at the first fixed slot whose force is not finite; the implicit one leaves fixed
    // slots out of its solve and moves them at their velocity.
    let sys = SpringSystem::new(
        vec![[0, 1], [0, 2]],
        vec![1.0, 1.0],
        vec![0.0, 0.0],
        vec![1e300, 0.0],
        vec![1.0; 3],
        &[true, true, false],
        vec![0.0; 3],
        [0.0; 3],
    )
    .unwrap();
    for integrator in [Integrator::Euler, Integrator::Symplectic, Integrator::Rk4, Integrator::Implicit] {
        let mut x = vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let v0 = vec![[-1e10, 0.0, 0.0], [1e10, 0.0, 0.0], [0.0; 3]];
        let mut v = v0.clone();
        let dt = 1e-3;
        let mut st = Stepper::new(StepConfig::new(integrator, dt), &sys, &x, &v).unwrap();
        match (integrator, st.step(&sys, &mut x, &mut v)) {
            (Integrator::Implicit, Ok(())) => {
                assert_eq!(&v[..2], &v0[..2]);
                assert_eq!((x[2], v[2]), ([0.0, 1.0, 0.0], [0.0; 3]), "the free slot feels nothing");
            }
            (Integrator::Implicit, Err(e)) => panic!("implicit: {e}"),
            (_, Err(StepError::BlowUp { step: 0, slot: 0, reason })) => {
                assert!(reason.contains("non-finite"), "{integrator:?}: {reason}")
            }
            (_, other) => panic!("{integrator:?}: expected a blow-up at fixed slot 0, got {other:?}"),
        }
    }
}

#[test]
fn a_failed_implicit_solve_is_named_by_the_step_the_user_counts() {
    let dir = cli_common::fresh_dir("round32", "implicit_step");
    let mesh = dir.join("cube.msh");
    let (points, tets) = kuhn_cube(2);
    cli_common::write_msh(&mesh, &points, &tets);
    let out = cli_common::run_in(
        &dir,
        &[
            "simulate",
            "cube.msh",
            "--steps",
            "3",
            "--integrator",
            "implicit",
            "--dt",
            "1e300",
            "--out",
            "frames",
            "--frames",
            "3",
        ],
    );
    assert!(!out.status.success());
    let err = cli_common::text(&out.stderr);
    // Frames 0..k written: the step that failed is k + 1 of the run.
    let written = (0..=3).filter(|k| dir.join("frames").join(format!("frame_{k:06}.vtu")).exists()).count() as u64;
    assert!(written >= 1, "the initial frame is written: {err}");
    let expected = format!("implicit step {written} of 3 (counted from 1");
    assert!(err.contains(&expected), "expected {expected:?} in {err:?}");
}

/// The closure's tets as sets of corner positions (bit patterns), sorted: comparable across
/// vertex numberings.
fn closure_geometry(cl: &topomech::subdivide::ConformingMesh) -> Vec<[[u64; 3]; 4]> {
    let mut out: Vec<[[u64; 3]; 4]> = cl
        .tets
        .iter()
        .map(|t| {
            let mut p = t.map(|v| cl.points[v as usize].map(f64::to_bits));
            p.sort_unstable();
            p
        })
        .collect();
    out.sort_unstable();
    out
}

/// refine_around(c, r, l) then the closure, on a mesh given as points and tets.
fn refined_closure(
    points: &[[f64; 3]],
    tets: &[[u32; 4]],
    c: [f64; 3],
    r: f64,
    l: u8,
) -> Result<topomech::subdivide::ConformingMesh, topomech::subdivide::SubdivideError> {
    let (map, _) = topomech::GMap::<3>::from_tets(points.len(), tets).unwrap();
    let mut m = topomech::subdivide::LeveledMap::new(map, points.to_vec());
    let mut masses = topomech::subdivide::TetMasses::from_density(&m, 1.0).unwrap();
    m.refine_around(c, r, l, &mut masses).unwrap();
    m.conforming_tets()
}

#[test]
fn the_closure_takes_faces_with_corner_angles_far_below_any_tolerance() {
    // Tet 0's face (0, 1, 2) has corner angles of about eps, eps and π − 2 eps.
    for eps in [1e-8, 1e-10, 1e-12, 1e-14] {
        let points = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, eps, 0.0], [0.5, 0.0, 1.0], [1.0, 1.0, 1.0]];
        let tets = [[0u32, 1, 2, 3], [1, 2, 3, 4]];
        let cl = refined_closure(&points, &tets, [1.0, 1.0, 1.0], 0.0, 1).unwrap_or_else(|e| panic!("eps {eps}: {e}"));
        // Every output tet positive, and the volumes sum to the input's.
        let vol = |p: [[f64; 3]; 4]| topomech::mesh::signed_volume(p[0], p[1], p[2], p[3]);
        let total: f64 = cl.tets.iter().map(|t| vol(t.map(|v| cl.points[v as usize]))).sum();
        let input: f64 = tets.iter().map(|t| vol(t.map(|v| points[v as usize]))).sum();
        assert!((total - input).abs() <= 1e-12 * input.abs(), "eps {eps}: {total} vs {input}");
        let (body, _) = topomech::mechanics::Body::from_tets(&cl.points, &cl.tets, Material::default())
            .unwrap_or_else(|e| panic!("eps {eps}: the closure is no valid tet mesh: {e}"));
        body.map().validate().unwrap();
    }
}

#[test]
fn the_closure_of_a_renumbered_mesh_is_the_same_set_of_tets() {
    for (k, c, r, l) in
        [(2usize, [1.0, 0.75, 0.5], 0.5, 1u8), (3, [2.0, 1.75, 2.75], 0.0, 2), (3, [1.25, 1.5, 1.0], 0.25, 2)]
    {
        let (points, tets) = kuhn_cube(k);
        let n = points.len() as u32;
        let reversed: Vec<[f64; 3]> = (0..n).map(|i| points[(n - 1 - i) as usize]).collect();
        let renumbered: Vec<[u32; 4]> = tets
            .iter()
            .map(|t| {
                let mut u = t.map(|v| n - 1 - v);
                u.swap(0, 1); // an odd permutation of the reversed order: keeps the orientation
                u.swap(2, 3);
                u
            })
            .collect();
        let a = refined_closure(&points, &tets, c, r, l).unwrap();
        let b = refined_closure(&reversed, &renumbered, c, r, l).unwrap();
        assert_eq!(closure_geometry(&a), closure_geometry(&b), "kuhn_cube({k}), ball {c:?} {r}, {l} levels");
    }
}

#[test]
fn a_face_whose_centroid_is_on_the_zone_sphere_is_measured() {
    use topomech::cut::{incise_plane, Plane};
    use topomech::subdivide::measure_cut;
    let (points, tets) = kuhn_cube(3);
    let (c, r) = ([3.0, 1.5, 1.0], 0.5);
    let cl = refined_closure(&points, &tets, c, r, 2).unwrap();
    let (mut body, _) = Body::from_tets(&cl.points, &cl.tets, Material::default()).unwrap();
    let plane = Plane { point: [3.0, 1.5, 1.125], normal: [1.0, -1.0, 0.0] };
    let inc = incise_plane(&mut body, &plane).unwrap();
    let e = measure_cut(&body, &inc, &plane, Some((c, r))).unwrap();
    // The oracle: in integers. Every position here is a multiple of 1/16 (corners and midpoints
    // of 1/4, the closure's Steiner points their centroids), so 16·(Σ x − 3c) is an integer
    // vector, compared with (16 · 3 r)².
    let map = body.map();
    let mut expected = 0;
    let mut on_sphere = 0;
    for dis in &inc.dissociations {
        let mut ids: Vec<_> =
            map.orbit(dis.dart, topomech::gmap::AlphaMask::of(&[0, 1])).into_iter().map(|x| map.vertex_id(x)).collect();
        ids.sort_unstable();
        ids.dedup();
        let p: Vec<[f64; 3]> = ids.iter().map(|&v| body.attrs().position()[v]).collect();
        let s: i64 = (0..3)
            .map(|k| {
                let x = 16.0 * (p.iter().map(|q| q[k]).sum::<f64>() - 3.0 * c[k]);
                assert_eq!(x, x.round());
                (x as i64) * (x as i64)
            })
            .sum();
        let rr = (48.0 * r) as i64;
        expected += usize::from(s <= rr * rr);
        on_sphere += usize::from(s == rr * rr);
    }
    assert!(on_sphere > 0, "the case has a face on the sphere");
    assert_eq!(e.measured, expected);
}

#[test]
fn a_body_read_with_a_rest_length_within_the_tolerance_stays_lawful_after_a_cut() {
    // Round 33's probe, finding 287: law 2 measured L_e on the rest positions while every rule
    // recomputes stiffness from the stored L_e; a length stored 9.1e-13 off (accepted) failed
    // law 2 after the next removal, and the body's own save was refused on load.
    use topomech::cut::remove_volume;
    use topomech::mechanics::check_conservation;
    use topomech::store::{self, Document, Format};
    use topomech::CellId;
    let (points, tets) = kuhn_cube(1);
    let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    for edge in 0..6 {
        for factor in [1.0 + 9.1e-13, 1.0 - 9.1e-13] {
            let mut doc = Document::from_body(&body);
            doc.mechanics.as_mut().unwrap().edges[edge][0] *= factor;
            let Ok(b) = doc.into_body() else { continue };
            for t in 0..6 {
                let mut cut = b.clone();
                remove_volume(&mut cut, CellId(t)).unwrap();
                check_conservation(cut.map(), cut.attrs())
                    .unwrap_or_else(|e| panic!("edge {edge} × {factor}, tet {t} removed: {e}"));
                let bytes = store::encode(&Document::from_body(&cut), Format::Binary).unwrap();
                let back = store::decode(&bytes).unwrap().into_body();
                assert!(back.is_ok(), "edge {edge}, tet {t}: its own save is refused: {back:?}");
            }
        }
    }
}
