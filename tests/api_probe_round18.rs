//! API probe round 18, geometry at extreme scales (findings 129–134 and the mesh check of 141 in
//! `docs/VERIFICATION.md`): every test states a law the code before the round broke.
//!
//! - 129/130: `triangle_area` was 0 for a needle of unit length and width 1e-200 (the squares of
//!   its exact cross product underflowed), and 0 for a thin triangle whose cross product
//!   overflowed (the fallback's norm was plain).
//! - 131/132: tets whose volume under- or overflows f64 though their extent does not (a needle
//!   1e-170 thin beside a unit edge; a sliver 1e200 wide and 1e-200 thick) were called flat, got
//!   mass 0 or a false volume overflow, or springs 1e-3 off.
//! - 133: `Body` measured rest lengths plainly (√Σd²): ∞ at 1e160, so `from_tets` returned a body
//!   that failed its own `check`.
//! - 134: `centroid` left the points' range (three points at 5e-324 averaged to 0).
//! - 141 (the mesh check): `TetMesh::check` called a regular tet of edge 1e-150 zero-volume.

use topomech::gmap::GMap;
use topomech::mechanics::{Body, Material, ModelError};
use topomech::mesh::{centroid, triangle_area, TetMesh};
use topomech::subdivide::{CouplingError, LeveledMap, LeveledMechanics, TetMasses};
use topomech::surface::boundary_surface_of_tets;

fn one_tet(p: [[f64; 3]; 4]) -> LeveledMap<3> {
    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    LeveledMap::new(map, p.to_vec())
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs()
}

/// Finding 129: ½|u × v| of a needle of unit length and width w is w/2 for every representable
/// w/2, at any scale of the needle.
#[test]
fn f129_needle_area_is_half_its_width() {
    for w in [1e-100, 1e-160, 1e-200, 1e-300] {
        let a = triangle_area([0.0; 3], [1.0, 0.0, 0.0], [1.0, w, 0.0]);
        assert!(close(a, w / 2.0, 1e-15), "width {w:e}: {a:e}");
    }
    // Rotated out of the axes, the cross product has three non-zero components.
    let a = triangle_area([0.0; 3], [1.0, 1.0, 0.0], [1.0, 1.0, 1e-200]);
    assert!(close(a, 2f64.sqrt() / 2.0 * 1e-200, 1e-15), "{a:e}");
}

/// Finding 130: a thin triangle whose cross product overflows f64 has its area (≈ 5e99 here).
#[test]
fn f130_thin_triangle_with_an_overflowing_cross_product() {
    let a = triangle_area([0.0; 3], [1e200, 0.0, 1e150], [1e200, 1e-100, 1e150]);
    let exact = 0.5 * (1e100f64 * 1e100 + 1e50 * 1e50).sqrt();
    assert!(close(a, exact, 1e-15), "{a:e}");
}

/// Findings 131/132: flatness, masses and stiffnesses of tets whose volume under- or overflows
/// f64 on its own (not their extent): not flat; ρ·V and E·V/L² as exact as for ordinary tets.
#[test]
fn f131_needle_tet_below_f64_volume_is_not_flat() {
    let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1e-170, 0.0], [0.0, 0.0, 1e-170]]; // V = 1e-340/6
    let e = Body::from_tets(&p, &[[0, 1, 2, 3]], Material::default()).map(|_| ()).unwrap_err();
    assert!(matches!(e, ModelError::VolumeUnderflow { tet: 0, .. }), "{e}");
    // Density 1e300, so that the mass is in range (since finding 268 the coupling, as a body,
    // refuses a mass whose quarter has no finite inverse: at density 1000 it is 1.7e-338).
    let dense = Material { density: 1e300, ..Material::default() };
    assert!(LeveledMechanics::new(&one_tet(p), Material::default()).is_err());
    let mech = LeveledMechanics::new(&one_tet(p), dense).unwrap();
    let k = mech.spring(0, 2).unwrap().stiffness; // E·V/L² = 1000 · (1e-340/6) / 1e-340
    assert!(close(k, 1000.0 / 6.0, 1e-12), "{k:e}");
    let mass = TetMasses::from_density(&one_tet(p), 1e300).unwrap().mass[0];
    assert!(close(mass, 1e-40 / 6.0, 1e-12), "{mass:e}");
    let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1e-160, 0.0], [0.0, 0.0, 1e-160]];
    let mech = LeveledMechanics::new(&one_tet(p), dense).unwrap();
    let k = mech.spring(0, 2).unwrap().stiffness;
    assert!(close(k, 1000.0 / 6.0, 1e-12), "{k:e}");
    let mass = TetMasses::from_density(&one_tet(p), 1e300).unwrap().mass[0];
    assert!(close(mass, 1e-20 / 6.0, 1e-12), "{mass:e}");
}

/// Finding 132: a sliver 1e200 wide and 1e-200 thick has the volume 1e200/6: not flat, not a
/// volume overflow, its mass and enclosed volume that value (its stiffness E·V/L² on the
/// 1e-200 edge, 1.7e601, is past f64 and refused as such).
#[test]
fn f132_huge_thin_sliver_has_its_volume() {
    let p = [[0.0, 0.0, 0.0], [1e200, 0.0, 0.0], [0.0, 1e200, 0.0], [0.0, 0.0, 1e-200]];
    let v = 1e200 / 6.0;
    let mass = TetMasses::from_density(&one_tet(p), 1.0).unwrap().mass[0];
    assert!(close(mass, v, 1e-12), "{mass:e}");
    let enclosed = boundary_surface_of_tets(&p, &[[0, 1, 2, 3]]).unwrap().enclosed_volume().unwrap();
    assert!(close(enclosed, v, 1e-12), "{enclosed:e}");
    let e = Body::from_tets(&p, &[[0, 1, 2, 3]], Material::default()).map(|_| ()).unwrap_err();
    assert!(matches!(e, ModelError::Overflow { quantity: "total stiffness", .. }), "{e}");
    let e = LeveledMechanics::new(&one_tet(p), Material::default()).map(|_| ()).unwrap_err();
    assert!(matches!(e, CouplingError::Overflow { quantity: "stiffness", .. }), "{e}");
    // With E = 1e-300 every spring is finite, and the body's mass is ρ·V.
    let soft = Material { young: 1e-300, ..Material::default() };
    let (body, _) = Body::from_tets(&p, &[[0, 1, 2, 3]], soft).unwrap();
    body.check().unwrap();
    let total = body.attrs().total_tet_mass(body.map()).unwrap();
    assert!(close(total, soft.density * v, 1e-12), "{total:e}");
    let sliver = one_tet(p);
    let mech = LeveledMechanics::new(&sliver, soft).unwrap();
    mech.check(&sliver).unwrap();
    let p = [[0.0, 0.0, 0.0], [1e200, 0.0, 0.0], [0.0, 1e200, 0.0], [0.0, 0.0, 1e-196]];
    let mass = TetMasses::from_density(&one_tet(p), 1e-100).unwrap().mass[0];
    assert!(close(mass, 1e104 / 6.0, 1e-12), "{mass:e}"); // ρ · 1e204/6
}

/// Finding 133: a body's rest lengths are the distances of their ends at any scale, so a body
/// `from_tets` accepts passes its own `check`, and agrees with the coupling.
#[test]
fn f133_body_rest_lengths_are_scale_safe() {
    let p = [[0.0, 0.0, 0.0], [1e160, 0.0, 0.0], [0.0, 1e-100, 0.0], [0.0, 0.0, 1e-100]];
    let (body, _) = Body::from_tets(&p, &[[0, 1, 2, 3]], Material::default()).unwrap();
    body.check().unwrap();
    let longest = body
        .map()
        .one_dart_per_cell(1)
        .into_iter()
        .map(|d| body.attrs().edge_rest_length(body.map().cell_id(1, d)))
        .fold(0.0, f64::max);
    assert!(close(longest, 1e160, 1e-15), "{longest:e}");
    let p = [[0.0, 0.0, 0.0], [1e-160, 1e-160, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let (body, _) = Body::from_tets(&p, &[[0, 1, 2, 3]], Material::default()).unwrap();
    body.check().unwrap();
    let short = body
        .map()
        .one_dart_per_cell(1)
        .into_iter()
        .map(|d| body.map().cell_id(1, d))
        .find(|&e| body.attrs().edge_rest_length(e) < 1e-100)
        .unwrap();
    let coupled = LeveledMechanics::new(&one_tet(p), Material::default()).unwrap().spring(0, 1).unwrap();
    assert!(close(body.attrs().edge_rest_length(short), 2f64.sqrt() * 1e-160, 1e-15));
    assert!(close(body.attrs().edge_stiffness(short), coupled.stiffness, 1e-12));
}

/// Finding 134: the centroid lies within the points' range per coordinate; that of identical
/// points is the point.
#[test]
fn f134_centroid_stays_within_the_points() {
    assert_eq!(centroid(&[[5e-324; 3]; 3]), [5e-324; 3]);
    assert_eq!(centroid(&[]), [0.0; 3]);
    let x = 2.2462425722150364e-29;
    assert_eq!(centroid(&[[x; 3]; 7]), [x; 3]);
    let c = centroid(&[[1.0, -3.0, 5e-324], [2.0, -1.0, 1e-323]]);
    assert!(c[0] == 1.5 && c[1] == -2.0 && (5e-324..=1e-323).contains(&c[2]), "{c:?}");
}

/// Finding 141, its mesh check: the zero-volume test is scale-invariant where 6V or l³ under- or
/// overflows f64; a flat tet at those scales still is one.
#[test]
fn f141_mesh_check_is_scale_invariant() {
    for s in [1e-150, 1e-300, 1e150, 1e300] {
        let points = vec![[0.0; 3], [s, 0.0, 0.0], [0.0, s, 0.0], [0.0, 0.0, s]];
        let mesh = TetMesh { points, tets: vec![[0, 1, 2, 3]], ..Default::default() };
        let r = mesh.check().unwrap();
        assert!(r.zero_volume_tets.is_empty() && r.inverted_tets.is_empty(), "{s:e}: {r:?}");
        // A volume past f64::MAX (1e450/6) is reported as unmeasurable (finding 51), not flat.
        assert_eq!(r.unmeasurable_tets.is_empty(), s < 1.0, "{s:e}: {r:?}");
        let flat = vec![[0.0; 3], [s, 0.0, 0.0], [0.0, s, 0.0], [s, s, 0.0]];
        let r = TetMesh { points: flat, tets: vec![[0, 1, 2, 3]], ..Default::default() }.check().unwrap();
        assert_eq!(r.zero_volume_tets, vec![0], "{s:e}");
        let inverted = vec![[0.0; 3], [0.0, s, 0.0], [s, 0.0, 0.0], [0.0, 0.0, s]];
        let r = TetMesh { points: inverted, tets: vec![[0, 1, 2, 3]], ..Default::default() }.check().unwrap();
        assert_eq!(r.inverted_tets.is_empty(), s > 1.0, "{s:e}: {r:?}");
    }
}

/// Finding 146, its render, surface and store part: a PNG or OBJ that cannot be written is named
/// once in the message (the cause already names the file), and a bad magic is escaped once.
#[test]
fn f146_write_errors_name_the_file_once() {
    let dir = std::path::Path::new("/nonexistent-topomech-dir");
    let png = dir.join("picture.png");
    let e = topomech::render::Image::new(2, 2, [0; 3]).unwrap().write_png(&png).unwrap_err().to_string();
    assert_eq!(e.matches("picture.png").count(), 1, "{e}");
    let (points, tets) = topomech::generate::kuhn_cube(1);
    let obj = dir.join("surface.obj");
    let e = boundary_surface_of_tets(&points, &tets).unwrap().write_obj(&obj).unwrap_err().to_string();
    assert_eq!(e.matches("surface.obj").count(), 1, "{e}");
    // A map file's bad magic is escaped once: a control byte shows as \x07, not \\x07. The
    // message quotes the first significant line (finding 210), without its line end.
    let e = topomech::store::decode(b"$MeshFormat\n2.2 0 8\n").unwrap_err().to_string();
    assert!(e.contains(r#""$MeshFormat""#) && !e.contains(r"\\"), "{e}");
    let e = topomech::store::decode(b"\x07bell\n").unwrap_err().to_string();
    assert!(e.contains(r#""\x07bell""#) && !e.contains(r"\\"), "{e}");
}

/// Finding 142, its mesh part: a tet listed twice (the same corners, in any order) is an error
/// naming both tets, not a valid closed two-tet map with double the mass.
#[test]
fn f142_duplicate_tets_are_refused() {
    let unit = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0; 3]];
    let mesh =
        TetMesh { points: unit.clone(), tets: vec![[0, 1, 2, 3], [1, 2, 3, 4], [3, 2, 0, 1]], ..Default::default() };
    let e = mesh.check().unwrap_err();
    assert!(matches!(e, topomech::mesh::MeshError::DuplicateTet { first: 0, second: 2, .. }), "{e}");
    let ok = TetMesh { points: unit, tets: vec![[0, 1, 2, 3], [1, 2, 3, 4]], ..Default::default() };
    ok.check().unwrap();
}

/// Finding 141, its ambiguity part: the mixed campaign subdivides a Kuhn cube at scales 1e±150
/// (its tets' volumes past or below f64) as it does at scale 1, instead of refusing it as
/// degenerate; a flat tet is still refused.
#[test]
fn f141_mixed_campaign_takes_tiny_and_huge_meshes() {
    use topomech::ambiguity::mixed::{run_ops, MixedError, Op};
    let (points, tets) = topomech::generate::kuhn_cube(1);
    let ops: Vec<Op> = (0..6).map(Op::Subdivide).collect();
    let plain = run_ops(&points, &tets, &ops).unwrap();
    for s in [1e-150, 1e150] {
        let scaled: Vec<[f64; 3]> = points.iter().map(|p| p.map(|c| c * s)).collect();
        let run = run_ops(&scaled, &tets, &ops).unwrap_or_else(|e| panic!("{s:e}: {e}"));
        assert_eq!(
            (run.subdivisions, run.refused, run.levels.len()),
            (plain.subdivisions, plain.refused, plain.levels.len())
        );
        assert!(run.gmap_valid && run.level_law, "{s:e}");
    }
    let flat = vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]];
    let e = run_ops(&flat, &[[0, 1, 2, 3]], &[Op::Subdivide(0)]).unwrap_err();
    assert!(matches!(e, MixedError::Degenerate { tet: 0, .. }), "{e}");
}
