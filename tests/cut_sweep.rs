//! Incision along a swept polyline (issue 4): the cut is exactly the set of inner faces whose
//! tets' centroid segment crosses the surface (checked against an oracle built from the tet list
//! alone), a sweep spanning a whole plane cuts what `incise_plane` cuts, a slit keeps the body in
//! one piece, an L-shaped wall cuts a block off, bad surfaces are refused without change, and the
//! map and the conservation laws hold after every cut.

mod sweep_oracle;

use std::process::Command;

use proptest::prelude::*;
use sweep_oracle::crossing_faces;
use topomech::cut::{components, incise_plane, incise_sweep, sweep_faces, tet_sides, CutError, Plane, PolylineSweep};
use topomech::generate::kuhn_cube;
use topomech::mechanics::{check_conservation, Body, Material, Vec3};

fn cube(k: usize) -> (Vec<Vec3>, Vec<[u32; 4]>, Body) {
    let (points, tets) = kuhn_cube(k);
    let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    (points, tets, body)
}

/// Cuts `body` along `surface` and checks the laws: valid map, conservation, unchanged mass,
/// two new boundary faces per cut face, and the oracle's count. Returns the cut face count.
fn cut_and_check(points: &[Vec3], tets: &[[u32; 4]], body: &mut Body, surface: &PolylineSweep) -> usize {
    let (mass, boundary) = (body.total_vertex_mass(), body.map().boundary_cell_count());
    let cut = incise_sweep(body, surface).unwrap();
    let map = body.map();
    map.validate().unwrap();
    check_conservation(map, body.attrs()).unwrap();
    let after = body.total_vertex_mass();
    assert!((after - mass).abs() <= 1e-12 * mass, "mass {mass} -> {after}");
    assert_eq!(map.boundary_cell_count(), boundary + 2 * cut.cut_faces());
    assert_eq!(cut.cut_faces(), crossing_faces(points, tets, surface), "cut faces vs the tet-list oracle");
    cut.cut_faces()
}

/// Two orthonormal vectors spanning the plane normal to n.
fn plane_basis(n: Vec3) -> (Vec3, Vec3) {
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    let n = [n[0] / len, n[1] / len, n[2] / len];
    let a = if n[0].abs() < 0.9 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
    let u = [n[1] * a[2] - n[2] * a[1], n[2] * a[0] - n[0] * a[2], n[0] * a[1] - n[1] * a[0]];
    let ul = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
    let u = [u[0] / ul, u[1] / ul, u[2] / ul];
    let v = [n[1] * u[2] - n[2] * u[1], n[2] * u[0] - n[0] * u[2], n[0] * u[1] - n[1] * u[0]];
    (u, v)
}

/// A square patch of the plane, half-width r, as a one-segment sweep.
fn plane_patch(plane: &Plane, r: f64) -> PolylineSweep {
    let (u, v) = plane_basis(plane.normal);
    let p = plane.point;
    let at = |s: f64, t: f64| [0, 1, 2].map(|k| p[k] + s * u[k] + t * v[k]);
    PolylineSweep { points: vec![at(-r, -r), at(r, -r)], sweep: [0, 1, 2].map(|k| 2.0 * r * v[k]) }
}

#[test]
fn a_sweep_spanning_the_body_cuts_exactly_what_the_plane_cuts() {
    let (_, _, body) = cube(3);
    for plane in [
        Plane { point: [1.45, 0.0, 0.0], normal: [1.0, 0.0, 0.0] }, // off the Kuhn centroids (ties differ: module docs)
        Plane { point: [1.2, 1.7, 1.4], normal: [0.3, -0.8, 0.5] },
        Plane { point: [0.9, 2.1, 1.0], normal: [1.0, 1.0, 1.0] },
    ] {
        let side = tet_sides(&body, &plane).unwrap();
        let map = body.map();
        let by_plane: Vec<_> = map
            .one_dart_per_cell(2)
            .into_iter()
            .filter(|&d| {
                let o = map.alpha::<3>(d);
                o != d && side[map.cell_id(3, d).index()] != side[map.cell_id(3, o).index()]
            })
            .collect();
        assert!(!by_plane.is_empty());
        assert_eq!(sweep_faces(&body, &plane_patch(&plane, 20.0)).unwrap(), by_plane, "{plane:?}");
        // And the incisions agree: same number of faces, same components.
        let (mut a, mut b) = (body.clone(), body.clone());
        let (ca, cb) =
            (incise_plane(&mut a, &plane).unwrap(), incise_sweep(&mut b, &plane_patch(&plane, 20.0)).unwrap());
        assert_eq!(ca.cut_faces(), cb.cut_faces());
        assert_eq!(components(&a).len(), components(&b).len());
    }
}

#[test]
fn a_slit_cuts_part_of_the_plane_and_keeps_one_piece() {
    let (points, tets, mut body) = cube(4);
    let full = PolylineSweep { points: vec![[2.0, -1.0, -1.0], [2.0, 5.0, -1.0]], sweep: [0.0, 0.0, 6.0] };
    let slit = PolylineSweep { points: vec![[2.0, -1.0, -1.0], [2.0, 2.0, -1.0]], sweep: [0.0, 0.0, 6.0] };
    let whole = sweep_faces(&body, &full).unwrap();
    let part = sweep_faces(&body, &slit).unwrap();
    assert!(!part.is_empty() && part.len() < whole.len());
    assert!(part.iter().all(|d| whole.contains(d)), "the slit's faces lie in the full plane's");
    let cut = cut_and_check(&points, &tets, &mut body, &slit);
    assert_eq!(cut, part.len());
    assert_eq!(components(&body).len(), 1, "tissue stays connected around the end of the slit");
}

#[test]
fn an_l_shaped_wall_cuts_a_block_off() {
    let (points, tets, mut body) = cube(4);
    let total = body.total_vertex_mass();
    // x = 2 for y ≤ 2, then y = 2 for x ≥ 2, through the whole height: frees the block x > 2, y < 2.
    let wall =
        PolylineSweep { points: vec![[2.0, -1.0, -1.0], [2.0, 2.0, -1.0], [5.0, 2.0, -1.0]], sweep: [0.0, 0.0, 6.0] };
    cut_and_check(&points, &tets, &mut body, &wall);
    let mut parts = components(&body);
    parts.sort_by_key(|p| p.volumes);
    assert_eq!(parts.iter().map(|p| p.volumes).collect::<Vec<_>>(), vec![2 * 2 * 4 * 6, 64 * 6 - 96]);
    let rel = (parts[0].mass / total - 0.25).abs();
    assert!(rel < 1e-12, "the block holds a quarter of the volume, so a quarter of the mass: {rel}");
}

#[test]
fn bad_sweeps_are_refused_and_change_nothing() {
    let (_, _, mut body) = cube(2);
    let counts = body.map().count_cells().0;
    let bad = [
        PolylineSweep { points: vec![], sweep: [0.0, 0.0, 1.0] },
        PolylineSweep { points: vec![[0.5; 3]], sweep: [0.0, 0.0, 1.0] },
        PolylineSweep { points: vec![[0.5; 3], [0.5; 3]], sweep: [0.0, 0.0, 1.0] },
        PolylineSweep { points: vec![[0.5; 3], [1.5, 0.5, 0.5]], sweep: [0.0; 3] },
        PolylineSweep { points: vec![[0.5; 3], [1.5, 0.5, 0.5]], sweep: [2.0, 0.0, 0.0] },
        PolylineSweep { points: vec![[0.5; 3], [f64::INFINITY, 0.5, 0.5]], sweep: [0.0, 0.0, 1.0] },
        PolylineSweep { points: vec![[0.5; 3], [1.5, 0.5, 0.5]], sweep: [0.0, f64::NAN, 1.0] },
    ];
    for s in bad {
        let err = incise_sweep(&mut body, &s).unwrap_err();
        assert!(matches!(err, CutError::BadSweep { .. }), "{s:?}: {err}");
        assert!(!err.to_string().is_empty());
    }
    assert_eq!(body.map().count_cells().0, counts);
    body.map().validate().unwrap();
}

#[test]
fn a_sweep_that_misses_the_body_cuts_nothing() {
    let (points, tets, mut body) = cube(2);
    let away = PolylineSweep { points: vec![[10.0, 0.0, 0.0], [10.0, 2.0, 0.0]], sweep: [0.0, 0.0, 2.0] };
    assert_eq!(cut_and_check(&points, &tets, &mut body, &away), 0);
}

#[test]
fn the_cli_cuts_along_a_polyline_and_refuses_a_bad_one() {
    let bin = env!("CARGO_BIN_EXE_topomech");
    let mesh = concat!(env!("CARGO_MANIFEST_DIR"), "/data/liver_547_v22.msh");
    let out = Command::new(bin)
        .args(["cut", mesh, "--polyline", "-2.2,2,3;-2.2,4,3;-1.5,5,3", "--sweep", "0,0,-3", "--json"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let r: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let faces = r["cut_faces"].as_u64().unwrap();
    assert!(faces > 0);
    let (before, after) = (&r["before"], &r["after"]);
    assert_eq!(after["valid"], true);
    assert_eq!(after["conservation_ok"], true);
    assert_eq!(after["boundary_faces"].as_u64().unwrap(), before["boundary_faces"].as_u64().unwrap() + 2 * faces);
    let (m0, m1) = (before["total_mass"].as_f64().unwrap(), after["total_mass"].as_f64().unwrap());
    assert!((m0 - m1).abs() <= 1e-12 * m0);

    for (line, sweep, says) in [
        ("-2.2,2,3", "0,0,-3", "at least 2 points"),
        ("-2.2,2,3;-2.2,2,3", "0,0,-3", "zero length"),
        ("-2.2,2,3;-2.2,4,3", "0,0,0", "sweep vector"),
        ("-2.2,2,x", "0,0,-3", "bad number"),
    ] {
        let out = Command::new(bin).args(["cut", mesh, "--polyline", line, "--sweep", sweep]).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.contains(says) && !err.contains("panicked"), "{line} {sweep}: {err}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, ..ProptestConfig::default() })]

    /// Random bent sweeps through a 3×3×3 Kuhn cube: the laws of `cut_and_check` after the cut,
    /// and every component's mass sums to the total.
    #[test]
    fn random_sweeps_cut_exactly_the_crossed_faces(
        pts in prop::collection::vec(prop::array::uniform3(-0.5f64..3.5), 2..5),
        sweep in prop::array::uniform3(-4.0f64..4.0),
    ) {
        let surface = PolylineSweep { points: pts, sweep };
        prop_assume!(surface.check().is_ok());
        let (points, tets, mut body) = cube(3);
        let total = body.total_vertex_mass();
        cut_and_check(&points, &tets, &mut body, &surface);
        let sum: f64 = components(&body).iter().map(|p| p.mass).sum();
        prop_assert!((sum - total).abs() <= 1e-12 * total);
    }
}
