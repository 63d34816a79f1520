//! Conforming closure of an adaptively refined tet map (`LeveledMap::conforming_tets`, issue 5)
//! and refine-then-cut. Laws checked on the closure of random refinements of `kuhn_cube(1..=3)`
//! and of the built-in liver:
//! - it builds as a G-map and as a mechanical body without error, with no pinched vertex, no
//!   split edge and no unreferenced point;
//! - every tet has a positive volume; Σ volumes = the input volume (1e-12 relative);
//! - conformity ([`check_conforming`]): no face is shared by 3 tets; the two tets of a shared
//!   face see it with opposite orientations; the faces of a single tet are exactly the
//!   triangulated boundary of the input: their count is Σ (k − 2) over the boundary polygons of
//!   the finest map (k vertices each), their area and the volume they enclose equal the input's.
//!   A hanging vertex leaves unmatched faces inside, which breaks the count and the area (tested
//!   on the non-conforming output `finest_tets`);
//! - the body's total mass is ρ·V; `validate()` and `check_conservation` hold, also after a cut.
//!
//! Refine-then-cut: on the liver, the cut faces in the zone are closer to the plane after the
//! refinement than before (max and mean distance).

use std::collections::HashMap;
use std::process::Command;

use proptest::prelude::*;
use topomech::cut::{incise_plane, CutError, Plane};
use topomech::generate::kuhn_cube;
use topomech::load;
use topomech::mechanics::{check_conservation, Body, Material};
use topomech::mesh::signed_volume;
use topomech::subdivide::{cut_error, measure_cut, triangulate_polygon, ConformingMesh, LeveledMap, TetMasses};
use topomech::GMap;

const RHO: f64 = 2.5;

type P = [f64; 3];

fn sub(a: P, b: P) -> P {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: P, b: P) -> P {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn norm(a: P) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// Area of a planar polygon from its vector area (independent of any triangulation).
fn polygon_area(cycle: &[u32], points: &[P]) -> f64 {
    let mut n = [0.0; 3];
    for k in 0..cycle.len() {
        let c = cross(points[cycle[k] as usize], points[cycle[(k + 1) % cycle.len()] as usize]);
        n = [n[0] + c[0], n[1] + c[1], n[2] + c[2]];
    }
    0.5 * norm(n)
}

fn tet_volume(t: &[u32; 4], points: &[P]) -> f64 {
    let p = t.map(|v| points[v as usize]);
    signed_volume(p[0], p[1], p[2], p[3])
}

/// What the closure of a refined map must reproduce: the input volume and the boundary of the
/// finest map (its polygons, each with k vertices).
struct Expected {
    volume: f64,
    boundary: Vec<Vec<u32>>,
    points: Vec<P>,
}

impl Expected {
    fn of(m: &LeveledMap<3>, volume: f64) -> Self {
        Expected { volume, boundary: m.boundary_polygons().unwrap(), points: m.points().to_vec() }
    }
    fn triangles(&self) -> usize {
        self.boundary.iter().map(|c| c.len() - 2).sum()
    }
    fn area(&self) -> f64 {
        self.boundary.iter().map(|c| polygon_area(c, &self.points)).sum()
    }
}

/// Every conformity law of the module docs; the first one broken, as a message.
fn check_conforming(points: &[P], tets: &[[u32; 4]], exp: &Expected) -> Result<(), String> {
    let scale = exp.volume.abs().max(f64::MIN_POSITIVE);
    let mut total = 0.0;
    // Outward faces of every tet, keyed by their sorted vertices: (count, one oriented copy).
    let mut faces: HashMap<[u32; 3], (usize, [u32; 3], bool)> = HashMap::new();
    for (i, t) in tets.iter().enumerate() {
        let v = tet_volume(t, points);
        if v <= 0.0 {
            return Err(format!("tet {i} {t:?} has volume {v}"));
        }
        total += v;
        let [a, b, c, d] = *t;
        for f in [[b, c, d], [a, d, c], [a, b, d], [a, c, b]] {
            let mut key = f;
            key.sort_unstable();
            let e = faces.entry(key).or_insert((0, f, true));
            e.0 += 1;
            if e.0 == 2 {
                // Opposite orientation: f is an odd permutation of the first copy.
                let first = e.1;
                let k = first.iter().position(|&x| x == f[0]).unwrap();
                e.2 = first[(k + 1) % 3] == f[2];
            }
        }
    }
    if (total - exp.volume).abs() > 1e-12 * scale {
        return Err(format!("Σ tet volume {total} ≠ input volume {}", exp.volume));
    }
    let (mut once, mut area, mut enclosed) = (0usize, 0.0, 0.0);
    for (key, &(count, f, opposite)) in &faces {
        match count {
            1 => {
                once += 1;
                let p = f.map(|v| points[v as usize]);
                area += 0.5 * norm(cross(sub(p[1], p[0]), sub(p[2], p[0])));
                enclosed += signed_volume([0.0; 3], p[0], p[1], p[2]);
            }
            2 if !opposite => return Err(format!("face {key:?} has the same orientation in its two tets")),
            2 => {}
            n => return Err(format!("face {key:?} is shared by {n} tets")),
        }
    }
    if once != exp.triangles() {
        return Err(format!("{once} faces of a single tet, expected {} boundary triangles", exp.triangles()));
    }
    let area0 = exp.area();
    if (area - area0).abs() > 1e-12 * area0 {
        return Err(format!("boundary area {area} ≠ input boundary area {area0}"));
    }
    if (enclosed - exp.volume).abs() > 1e-12 * scale.max(1.0) {
        return Err(format!("the boundary encloses {enclosed}, not {}", exp.volume));
    }
    Ok(())
}

/// Builds the closure as a G-map and a body, checks every law, returns the body.
fn check_closure(c: &ConformingMesh, exp: &Expected) -> Body {
    check_conforming(&c.points, &c.tets, exp).unwrap();
    let (map, report) = GMap::<3>::from_tets(c.points.len(), &c.tets).unwrap();
    map.validate().unwrap();
    assert!(report.pinched_vertices.is_empty() && report.split_edges.is_empty(), "{report:?}");
    assert!(report.unreferenced_points.is_empty(), "{:?}", report.unreferenced_points);
    let material = Material { density: RHO, ..Material::default() };
    let (body, _) = Body::from_tets(&c.points, &c.tets, material).unwrap();
    body.map().validate().unwrap();
    check_conservation(body.map(), body.attrs()).unwrap();
    let mass = body.total_tet_mass();
    assert!((mass - RHO * exp.volume).abs() <= 1e-12 * RHO * exp.volume, "mass {mass} ≠ ρV");
    let vmass = body.total_vertex_mass();
    assert!((vmass - mass).abs() <= 1e-12 * mass, "Σ vertex mass {vmass} ≠ {mass}");
    body
}

fn leveled(points: Vec<P>, tets: &[[u32; 4]]) -> (LeveledMap<3>, f64) {
    let volume: f64 = tets.iter().map(|t| tet_volume(t, &points).abs()).sum();
    let (map, _) = GMap::<3>::from_tets(points.len(), tets).unwrap();
    (LeveledMap::new(map, points), volume)
}

fn refine_and_close(m: &mut LeveledMap<3>, volume: f64, c: P, r: f64, levels: u8) -> (ConformingMesh, Expected) {
    let mut masses = TetMasses::from_density(m, RHO).unwrap();
    m.refine_around(c, r, levels, &mut masses).unwrap();
    let closure = m.conforming_tets().unwrap();
    (closure, Expected::of(m, volume))
}

#[test]
fn an_unrefined_mesh_is_output_as_it_is() {
    let (points, tets) = kuhn_cube(2);
    let (m, volume) = leveled(points, &tets);
    let c = m.conforming_tets().unwrap();
    assert_eq!((c.kept, c.closed, c.tets.len()), (tets.len(), 0, tets.len()));
    assert_eq!(c.points.len(), 27, "no Steiner point");
    check_closure(&c, &Expected::of(&m, volume));
}

#[test]
fn one_refined_corner_tet_closes_its_neighbours_with_cones() {
    let (points, tets) = kuhn_cube(1);
    let (mut m, volume) = leveled(points, &tets);
    // The ball touches only the tets at the corner (0,0,0); every Kuhn tet contains the diagonal
    // 000–111, so all six are refined at level 1: nothing to close.
    let (c, exp) = refine_and_close(&mut m, volume, [0.0; 3], 0.05, 1);
    assert_eq!((c.kept, c.closed), (48, 0));
    check_closure(&c, &exp);
    // A cube of 8 cells refined at one corner cell: the other cells' tets next to it are closed.
    let (points, tets) = kuhn_cube(2);
    let (mut m, volume) = leveled(points, &tets);
    let (c, exp) = refine_and_close(&mut m, volume, [0.5, 0.5, 0.5], 0.1, 1);
    assert!(c.closed > 0 && c.kept > 0, "{} kept, {} closed", c.kept, c.closed);
    assert_eq!(c.points.len(), m.points().len() + c.closed, "one Steiner point per closed tet");
    check_closure(&c, &exp);
}

#[test]
fn the_checker_rejects_hanging_vertices() {
    let (points, tets) = kuhn_cube(2);
    let (mut m, volume) = leveled(points, &tets);
    let (c, exp) = refine_and_close(&mut m, volume, [0.5, 0.5, 0.5], 0.1, 2);
    check_conforming(&c.points, &c.tets, &exp).unwrap();
    // The finest tets with their own corners: the coarse neighbours keep hanging vertices.
    let raw: Vec<[u32; 4]> = m.finest_tets().unwrap().into_iter().map(|(t, _, _)| t).collect();
    let err = check_conforming(m.points(), &raw, &exp).unwrap_err();
    assert!(err.contains("faces of a single tet"), "{err}");
    // Dropping one cone tet leaves a hole: the volume law catches it.
    let mut holed = c.tets.clone();
    holed.pop();
    assert!(check_conforming(&c.points, &holed, &exp).unwrap_err().contains("volume"));
}

#[test]
fn triangulate_polygon_handles_collinear_vertices_and_refuses_degenerate_ones() {
    // A triangle with two inserted vertices on one side and one on another.
    let p = [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 2.0, 0.0]];
    let cycle = [0, 3, 4, 1, 5, 2];
    let tris = triangulate_polygon(&cycle, &p).unwrap();
    assert_eq!(tris.len(), cycle.len() - 2);
    let area: f64 = tris
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| p[v as usize]);
            let n = cross(sub(b, a), sub(c, a));
            assert!(n[2] > 0.0, "triangle {t:?} is degenerate or flipped");
            0.5 * n[2]
        })
        .sum();
    assert!((area - 8.0).abs() < 1e-12);
    // Zero area, too few vertices and unknown points are refused.
    assert!(triangulate_polygon(&[0, 3, 4, 1], &p).is_none());
    assert!(triangulate_polygon(&[0, 3], &p).is_none());
    assert!(triangulate_polygon(&[0, 1, 99], &p).is_none());
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 16, ..ProptestConfig::default() })]
    #[test]
    fn random_refinements_close_into_a_conforming_mesh(
        k in 1usize..=3,
        c in prop::array::uniform3(-0.5f64..3.5),
        radius in 0.0f64..0.8,
        levels in 1u8..=2,
    ) {
        let (points, tets) = kuhn_cube(k);
        let (mut m, volume) = leveled(points, &tets);
        let (closure, exp) = refine_and_close(&mut m, volume, c, radius, levels);
        check_closure(&closure, &exp);
    }
}

fn liver() -> (LeveledMap<3>, f64, Vec<P>, Vec<[u32; 4]>) {
    let loaded = load::load_builtin().unwrap();
    let (points, tets) = (loaded.mesh.points.clone(), loaded.mesh.tets.clone());
    let volume: f64 = tets.iter().map(|t| tet_volume(t, &points).abs()).sum();
    (LeveledMap::new(loaded.map, loaded.mesh.points), volume, points, tets)
}

const ZONE: (P, f64) = ([-2.2, 3.2, 0.6], 0.5);

#[test]
fn the_refined_liver_closes_and_cuts_closer_to_the_plane() {
    let (mut m, volume, points, tets) = liver();
    let (closure, exp) = refine_and_close(&mut m, volume, ZONE.0, ZONE.1, 2);
    assert!(closure.closed > 0);
    let after = check_closure(&closure, &exp);
    let material = Material { density: RHO, ..Material::default() };
    let (mut before, _) = Body::from_tets(&points, &tets, material).unwrap();
    // One oblique plane here (the command test cuts along (0, 0, 1)): cutting under
    // `expensive-checks` checks every conservation law after each dissociated face.
    for normal in [[1.0, 0.3, 0.2]] {
        let plane = Plane { point: ZONE.0, normal };
        let (mut b, mut a) = (before.clone(), after.clone());
        let eb = cut_error(&mut b, &plane, Some(ZONE)).unwrap();
        let incision = incise_plane(&mut a, &plane).unwrap();
        let ea = measure_cut(&a, &incision, &plane, Some(ZONE)).unwrap();
        assert!(eb.measured > 0 && ea.measured > eb.measured, "{eb:?} {ea:?}");
        assert!(ea.max < eb.max && ea.mean < eb.mean, "normal {normal:?}: before {eb:?}, after {ea:?}");
        for body in [&b, &a] {
            body.map().validate().unwrap();
            check_conservation(body.map(), body.attrs()).unwrap();
            let mass = body.total_tet_mass();
            assert!((mass - RHO * volume).abs() <= 1e-12 * RHO * volume);
        }
        // Without a zone every cut face is measured, and the zone's faces are among them.
        let all = measure_cut(&a, &incision, &plane, None).unwrap();
        assert_eq!((all.measured, all.faces), (ea.faces, ea.faces));
        assert!(all.max >= ea.max);
    }
    // A bad plane is refused and leaves the body unchanged.
    let darts = before.map().dart_count();
    assert!(cut_error(&mut before, &Plane { point: ZONE.0, normal: [0.0; 3] }, None).is_err());
    assert_eq!(before.map().dart_count(), darts);
    // So is a bad zone (a NaN radius would have measured every face as inside it), before the
    // incision: nothing is dissociated.
    let plane = Plane { point: ZONE.0, normal: [1.0, 0.3, 0.2] };
    let boundary_before = before.map().boundary_darts().count();
    for zone in [(ZONE.0, f64::NAN), (ZONE.0, -1.0), ([f64::INFINITY, 0.0, 0.0], 1.0), (ZONE.0, f64::INFINITY)] {
        let e = cut_error(&mut before, &plane, Some(zone)).unwrap_err();
        assert!(matches!(e, CutError::BadZone { .. }), "{zone:?}: {e}");
        assert_eq!(before.map().dart_count(), darts);
        assert_eq!(before.map().boundary_darts().count(), boundary_before);
    }
    after.map().validate().unwrap();
}

const BIN: &str = env!("CARGO_BIN_EXE_topomech");

fn liver_path() -> String {
    format!("{}/data/liver_547_v22.msh", env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn the_refine_command_reports_the_conforming_closure_and_the_cut_error() {
    let out = Command::new(BIN)
        .args(["refine", &liver_path(), "--around", "-2.2,3.2,0.6", "--radius", "0.5", "--levels", "1"])
        .args(["--cut", "-2.2,3.2,0.6,0,0,1", "--json"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let num = |k: &str| v.get(k).and_then(|x| x.as_f64()).unwrap_or_else(|| panic!("missing {k} in {v}"));
    assert!(num("conforming_tets") > num("volumes"), "the closure splits the coarse neighbours");
    assert!(num("cut_faces_after") > num("cut_faces_before"));
    assert!(num("cut_error_max_after") < num("cut_error_max_before"));
    assert!(num("cut_error_mean_after") < num("cut_error_mean_before"));
    // A single tet whose centroid-side rule cuts no face unrefined: no error to measure before,
    // so those keys are absent and the text says "none" (before, 0/0 printed NaN and JSON null).
    let tet = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/single_tet.msh");
    let args = ["refine", tet, "--around", "0,0,0", "--radius", "10", "--levels", "2", "--cut", "0.1,0.1,0.1,1,0,0"];
    let out = Command::new(BIN).args(args).arg("--json").output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["cut_zone_faces_before"], 0, "{v}");
    assert!(v.get("cut_error_max_before").is_none() && v.get("cut_error_mean_before").is_none(), "{v}");
    assert!(v["cut_error_max_after"].as_f64().is_some_and(|x| x > 0.0), "{v}");
    let text = String::from_utf8_lossy(&Command::new(BIN).args(args).output().unwrap().stdout).into_owned();
    let line = text.lines().find(|l| l.contains("cut error in the zone")).expect("the cut error line");
    assert!(line.contains("max none -> 0.") && !line.contains("NaN"), "{line}");
    // Without the options the new keys are absent and the documented ones unchanged.
    let out = Command::new(BIN)
        .args(["refine", &liver_path(), "--around", "-2.2,3.2,0.6", "--radius", "0.5", "--conforming", "--json"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v.get("conforming_tets").is_some() && v.get("cut_faces_before").is_none(), "{v}");
    assert!(v.get("tets_per_level").is_some() && v.get("total_mass_after").is_some());
    for (plane, needle) in [("1,2,3,0,0,0", "normal"), ("1,2,3,0,1", "PX,PY,PZ,NX,NY,NZ"), ("1,2,3,0,inf,1", "finite")]
    {
        let out = Command::new(BIN)
            .args(["refine", &liver_path(), "--around", "0,0,0", "--radius", "1", "--cut", plane])
            .output()
            .unwrap();
        assert!(!out.status.success());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(needle) && !err.contains("panicked"), "{plane}: {err}");
    }
}

/// `NumberOfCells` of a VTU file written by topomech.
fn vtu_cells(path: &std::path::Path) -> u64 {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let at = text.find("NumberOfCells=\"").expect("a piece header") + "NumberOfCells=\"".len();
    text[at..].split('"').next().unwrap().parse().unwrap()
}

#[test]
fn the_refine_command_writes_the_refined_and_conforming_meshes_and_a_table_of_the_same_figures() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("topomech-refine-out");
    let _ = std::fs::remove_dir_all(&dir);
    let common =
        ["refine", &liver_path(), "--around", "-2.2,3.2,0.6", "--radius", "0.5", "--levels", "2", "--conforming"];
    let json = Command::new(BIN).args(common).arg("--json").output().unwrap();
    assert!(json.status.success(), "{}", String::from_utf8_lossy(&json.stderr));
    let v: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    let levels: Vec<u64> = v["tets_per_level"].as_array().unwrap().iter().map(|x| x.as_u64().unwrap()).collect();
    assert_eq!(levels.len(), 3, "{v}");
    let table = Command::new(BIN).args(common).arg("--out").arg(&dir).output().unwrap();
    assert!(table.status.success(), "{}", String::from_utf8_lossy(&table.stderr));
    let text = String::from_utf8_lossy(&table.stdout);
    // The table states the JSON's figures (the refinement is deterministic).
    let row = |label: &str| {
        let line =
            text.lines().find(|l| l.trim_start().starts_with(label)).unwrap_or_else(|| panic!("{label}: {text}"));
        line.trim_start()[label.len()..].trim().to_string()
    };
    assert_eq!(row("tets per level"), format!("{levels:?}"));
    assert_eq!(row("darts"), v["darts"].to_string());
    assert_eq!(row("valid / μ order / levels"), "true / true / true");
    assert_eq!(row("conforming tets"), v["conforming_tets"].to_string());
    // refined.vtu holds the finest level's tets, conforming.vtu the closure's.
    assert_eq!(vtu_cells(&dir.join("refined.vtu")), *levels.last().unwrap());
    assert_eq!(vtu_cells(&dir.join("conforming.vtu")), v["conforming_tets"].as_u64().unwrap());
    let _ = std::fs::remove_dir_all(&dir);
}
