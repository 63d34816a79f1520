//! Round 22 probing of the CLI's pins and blow-up names (findings 201–202): a file's
//! unreferenced points are no vertices of the body, and a pinched point (tets that meet only
//! there) is several vertices of it.

use std::path::{Path, PathBuf};

use topomech::GMap;

mod cli_common;
use cli_common::{run_in, text, write_msh};

fn fresh_dir(name: &str) -> PathBuf {
    cli_common::fresh_dir("topomech-round22-cli", name)
}

/// A 2×2×2 Kuhn cube, and with `unused` an extra point at (1, 1, −10) that no tet uses.
fn cube(dir: &Path, name: &str, unused: bool) -> String {
    let (mut points, tets) = topomech::generate::kuhn_cube(2);
    if unused {
        points.push([1.0, 1.0, -10.0]);
    }
    write_msh(&dir.join(name), &points, &tets);
    name.to_string()
}

/// Two tets that meet only at point 0 (file node tag 1), in either order of the tets.
fn bowtie(dir: &Path, name: &str, swapped: bool) -> String {
    cli_common::write_bowtie(&dir.join(name), swapped);
    name.to_string()
}

fn simulate(dir: &Path, mesh: &str, extra: &[&str]) -> std::process::Output {
    let mut args = vec!["simulate", mesh, "--steps", "200", "--dt", "1e-3", "--integrator", "symplectic", "--json"];
    args.extend_from_slice(extra);
    run_in(dir, &args)
}

/// Finding 201: `--pin-below` is checked against the body's vertices, not the file's points: a
/// region that only an unreferenced point meets pins nothing and is refused, with the body's
/// range in the message; `--pin` of an unreferenced point is refused too.
#[test]
fn f201_pins_that_only_an_unreferenced_point_meets_are_refused() {
    let dir = fresh_dir("unreferenced");
    let (plain, unref) = (cube(&dir, "cube.msh", false), cube(&dir, "cube_unref.msh", true));
    assert_eq!(simulate(&dir, &plain, &["--pin-below", "z=-5"]).status.code(), Some(1));
    let out = simulate(&dir, &unref, &["--pin-below", "z=-5"]);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "accepted: {}", text(&out.stdout));
    assert!(err.contains("runs from 0 to 2") && err.contains("give a value ≥ 0"), "{err}");
    let out = simulate(&dir, &unref, &["--pin", "27"]);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "accepted: {}", text(&out.stdout));
    assert!(err.contains("--pin") && err.contains("point 27") && err.contains("no tet"), "{err}");
    // The vertices still pin as before.
    assert!(simulate(&dir, &unref, &["--pin-below", "z=0"]).status.success());
    assert!(simulate(&dir, &unref, &["--pin", "0,26"]).status.success());
}

/// The report lists which point each extra vertex of a pinched point stands for.
#[test]
fn f202_the_build_report_names_the_point_of_each_extra_vertex() {
    let (map, report) = GMap::<3>::from_tets(7, &[[0, 1, 2, 3], [0, 5, 4, 6]]).unwrap();
    assert_eq!(report.extra_vertices, vec![(7, 0)]);
    assert_eq!(map.cell_id_bound(0), 8);
    // Two pinched points in a chain of three tets meeting at single points.
    let tets = [[0, 1, 2, 3], [3, 4, 5, 6], [6, 7, 8, 0]];
    let (map, report) = GMap::<3>::from_tets(9, &tets).unwrap();
    let mut points: Vec<u32> = report.extra_vertices.iter().map(|&(_, p)| p).collect();
    points.sort_unstable();
    assert_eq!(points, vec![0, 3, 6]);
    for (k, &(id, p)) in report.extra_vertices.iter().enumerate() {
        assert_eq!(id, 9 + k as u32, "ids past the points, in order");
        let darts = (0..map.capacity() as u32).map(topomech::DartId).filter(|&d| map.vertex_id(d).0 == id);
        let tet_of = |d: topomech::DartId| map.cell_id(3, d).index();
        assert!(
            darts.clone().count() > 0 && darts.into_iter().all(|d| tets[tet_of(d)].contains(&p)),
            "vertex {id} at point {p}"
        );
    }
    let (_, report) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    assert!(report.extra_vertices.is_empty());
}

/// Finding 202: a blow-up at the extra vertex of a pinched point names the file's node tag, in
/// both orders of the tets (it named "vertex slot 7, not a point of the file" in one).
#[test]
fn f202_a_blow_up_at_a_pinched_copy_names_the_file_node_tag() {
    let dir = fresh_dir("blowup");
    for swapped in [false, true] {
        let mesh = bowtie(&dir, &format!("bowtie_{swapped}.msh"), swapped);
        let out = run_in(
            &dir,
            &[
                "simulate",
                &mesh,
                "--pin",
                "1,2,3,4,5,6",
                "--steps",
                "3000",
                "--dt",
                "0.05",
                "--damping",
                "0",
                "--viscosity",
                "0",
                "--integrator",
                "euler",
            ],
        );
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert!(err.contains("blew up in step") && err.contains("file node tag 1"), "swapped {swapped}: {err}");
        assert!(!err.contains("not a point of the file"), "swapped {swapped}: {err}");
    }
}

/// The point positions of a VTU frame written by `simulate`.
fn vtu_points(path: &Path) -> Vec<[f64; 3]> {
    let vtu = std::fs::read_to_string(path).unwrap();
    let body = &vtu[vtu.find("<Points>").unwrap()..];
    let values = &body[body.find('>').unwrap() + 1..];
    let values = &values[values.find('>').unwrap() + 1..];
    let xs: Vec<f64> = values[..values.find('<').unwrap()].split_whitespace().map(|v| v.parse().unwrap()).collect();
    xs.chunks(3).map(|c| [c[0], c[1], c[2]]).collect()
}

/// Finding 202: `--pin P` of a pinched point holds every vertex at P (it held one: the other
/// tet fell away from the pinned point).
#[test]
fn f202_pinning_a_pinched_point_holds_every_vertex_there() {
    let dir = fresh_dir("pinned");
    for swapped in [false, true] {
        let mesh = bowtie(&dir, &format!("bowtie_{swapped}.msh"), swapped);
        let out_dir = format!("frames_{swapped}");
        let out = run_in(
            &dir,
            &[
                "simulate",
                &mesh,
                "--pin",
                "0",
                "--steps",
                "100",
                "--dt",
                "1e-3",
                "--integrator",
                "symplectic",
                "--frames",
                "1",
                "--out",
                &out_dir,
            ],
        );
        assert!(out.status.success(), "{}", text(&out.stderr));
        let points = vtu_points(&dir.join(&out_dir).join("frame_000001.vtu"));
        assert_eq!(points.len(), 8, "7 file points and the pinched point's second vertex");
        let at_origin = points.iter().filter(|p| **p == [0.0; 3]).count();
        assert_eq!(at_origin, 2, "both vertices at point 0 stay pinned: {points:?}");
        assert!(
            points[1] != [1.0, 0.0, 0.0] && points[4] != [-0.3, 0.0, 0.0],
            "both tets swing under gravity: {points:?}"
        );
    }
}
