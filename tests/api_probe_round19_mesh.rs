//! API probe round 19, meshes (findings 161–164 in `docs/VERIFICATION.md`): every test states a
//! law the code before the round broke.
//!
//! - 161: a tet listed twice was refused by the mesh check of the readers only; `GMap::from_tets`
//!   sewed its copies into a closed two-tet component, so `Body::from_tets` doubled its mass and
//!   a conformance vector with an inline mesh ran on it. Likewise a triangle listed twice made a
//!   closed two-triangle "pillow" in `GMap::from_triangles` and passed `TriMesh::check`.
//! - 162: the mesh check's zero-volume class changed when a tet at the threshold was scaled by an
//!   exact power of two (its plain and wide branches rounded differently).
//! - 163: the readers named a duplicate tet by 0-based tet and point indices, not by the file's
//!   element numbers and node tags as their other errors do.
//! - 164: `topomech info /dev/stdin < FIFO` was refused as a named pipe, though standard input is
//!   already open.

mod cli_common;

use cli_common::{fresh_dir, run_in, text, BIN};
use std::path::Path;
use std::process::{Command, Stdio};
use topomech::conformance::{replay, Vector};
use topomech::generate::{kuhn_cube, SplitMix64};
use topomech::io::{parse_msh, parse_obj, parse_tetgen, ReadError};
use topomech::mechanics::{Body, FlatModel, Material, ModelError};
use topomech::mesh::{MeshError, TetMesh, TriMesh};
use topomech::{BuildError, GMap};

const UNIT: [[f64; 3]; 5] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]];

fn duplicate(what: &'static str, first: usize, second: usize, points: &[u32]) -> BuildError {
    BuildError::DuplicateElement { what, first, second, points: points.to_vec() }
}

/// Finding 161: `GMap::from_tets` refuses a tet listed twice (any corner order), naming both
/// tets and the corners, the pair `TetMesh::check` names; three copies too, and before a face of
/// three other tets; so `Body::from_tets` refuses it instead of doubling its mass.
#[test]
fn f161_a_tet_listed_twice_is_refused_by_the_builders() {
    let twice = [[0, 1, 2, 3], [1, 0, 2, 3]];
    assert_eq!(GMap::<3>::from_tets(5, &twice).unwrap_err(), duplicate("tet", 0, 1, &[0, 1, 2, 3]));
    let thrice = [[0, 1, 2, 3], [1, 2, 3, 4], [3, 2, 1, 0], [2, 0, 3, 1]];
    assert_eq!(GMap::<3>::from_tets(5, &thrice).unwrap_err(), duplicate("tet", 0, 2, &[0, 1, 2, 3]));
    // A face of three distinct tets elsewhere: the duplicate is named first.
    let both = [[5, 6, 7, 8], [5, 6, 7, 9], [5, 6, 7, 10], [0, 1, 2, 3], [3, 1, 2, 0]];
    assert_eq!(GMap::<3>::from_tets(11, &both).unwrap_err(), duplicate("tet", 3, 4, &[0, 1, 2, 3]));
    // Without the duplicate, the fan is still what is refused.
    let fan = GMap::<3>::from_tets(11, &both[..4]).unwrap_err();
    assert!(matches!(fan, BuildError::NonManifold { what: "face", .. }), "{fan}");

    let err = Body::from_tets(&UNIT, &twice, Material::default()).unwrap_err();
    assert_eq!(err, ModelError::Build(duplicate("tet", 0, 1, &[0, 1, 2, 3])));
    assert_eq!(
        err.to_string(),
        "duplicate tet: elements 0 and 1 have the same points [0, 1, 2, 3] (a tet listed twice)"
    );
    let (body, _) = Body::from_tets(&UNIT, &[[0, 1, 2, 3], [1, 2, 3, 4]], Material::default()).unwrap();
    assert!(body.check().is_ok());
    // The flat baseline refuses what the body refuses (it doubled the mass too).
    let flat = FlatModel::from_tets(&UNIT, &twice, Material::default(), [0.0; 3], &[]).unwrap_err();
    assert_eq!(flat, ModelError::Build(duplicate("tet", 0, 1, &[0, 1, 2, 3])));
    assert!(FlatModel::from_tets(&UNIT, &[[0, 1, 2, 3], [1, 2, 3, 4]], Material::default(), [0.0; 3], &[]).is_ok());

    // Kuhn cubes with a tet repeated (corners shuffled) at a random place, in a random order:
    // the builder names the pair the mesh check names.
    let mut rng = SplitMix64(19_161);
    for k in 1..=4 {
        let (points, tets) = kuhn_cube(k);
        for _ in 0..20 {
            let mut tets = tets.clone();
            for i in (1..tets.len()).rev() {
                tets.swap(i, rng.below(i + 1));
            }
            let mut copy = tets[rng.below(tets.len())];
            copy.swap(0, 1 + rng.below(3));
            tets.insert(rng.below(tets.len() + 1), copy);
            let mesh = TetMesh { points: points.clone(), tets: tets.clone(), ..Default::default() };
            let Err(MeshError::DuplicateTet { first, second, corners }) = mesh.check() else { panic!("k = {k}") };
            let err = GMap::<3>::from_tets(points.len(), &tets).unwrap_err();
            assert_eq!(err, duplicate("tet", first, second, &corners), "k = {k}");
        }
    }
}

/// Finding 161, its 2-D part: a triangle listed twice is refused by `GMap::from_triangles` and
/// by `TriMesh::check` (so by the surface readers), not built into a closed two-triangle pillow.
#[test]
fn f161_a_triangle_listed_twice_is_refused() {
    let pillow = GMap::<2>::from_triangles(3, &[[0, 1, 2], [2, 1, 0]]);
    assert_eq!(pillow.unwrap_err(), duplicate("triangle", 0, 1, &[0, 1, 2]));
    let twice = [[0, 1, 2], [0, 2, 3], [2, 1, 0]];
    assert_eq!(GMap::<2>::from_triangles(4, &twice).unwrap_err(), duplicate("triangle", 0, 2, &[0, 1, 2]));
    // The copy of a triangle whose edge is already shared by two others.
    let crowded = [[0, 1, 2], [0, 1, 3], [1, 0, 2]];
    assert_eq!(GMap::<2>::from_triangles(4, &crowded).unwrap_err(), duplicate("triangle", 0, 2, &[0, 1, 2]));
    GMap::<2>::from_triangles(4, &twice[..2]).unwrap();

    let points = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]];
    let mesh = TriMesh { points, triangles: twice.to_vec() };
    let err = mesh.check().unwrap_err();
    assert_eq!(err, MeshError::DuplicateTriangle { first: 0, second: 2, corners: [0, 1, 2] });
    assert!(err.to_string().contains("0-based"), "{err}");
}

/// Finding 161, its conformance part: a vector whose inline mesh lists a tet twice is refused as
/// a bad mesh, before any expectation is compared.
#[test]
fn f161_an_inline_conformance_mesh_with_a_tet_listed_twice_is_refused() {
    let json = r#"{"format": "topomech-conformance", "version": 1, "name": "dup_inline",
        "description": "a tet listed twice", "tolerance": 1e-9,
        "mesh": {"kind": "inline", "points": [[0,0,0],[1,0,0],[0,1,0],[0,0,1],[1,1,1]],
                 "tets": [[0,1,2,3],[1,0,2,3]]},
        "material": {"density": 1.0, "young": 1000.0, "damping": 0.001, "viscosity": 1.0},
        "initial": {"dissociated": [], "darts": 48, "cells": [5, 9, 7, 2], "boundary_faces": 6,
                    "components": 1, "euler": 1, "total_mass": 0.3333333333333333,
                    "total_stiffness": 1750.0, "component_masses": [0.3333333333333333]},
        "steps": []}"#;
    let vector = Vector::from_json(json, "dup_inline.json").unwrap();
    let err = replay(&vector).unwrap_err().to_string();
    assert!(err.contains("duplicate tet: elements 0 and 1"), "{err}");
}

/// The tet of finding 162: ordinary corners within a few ulps of |6V| = 1e-12·l³ (exactly, just
/// inside: det²/(1e-24·l⁶) − 1 ≈ −2.6e-17), each coordinate times `scale`.
fn threshold_tet(scale: f64) -> TetMesh {
    let corners = [
        [0.0, 0.0, 0.0],
        [1.3314417065150366, 0.0, 0.0],
        [0.0, 1.0553485057719083, 0.0],
        [1.3791194158485247, 1.0648731846680457, 3.764597570845266e-12],
    ];
    let points = corners.iter().map(|p| p.map(|x| x * scale)).collect();
    TetMesh { points, tets: vec![[0, 1, 2, 3]], ..Default::default() }
}

/// Finding 162: the zero-volume class of a tet at the threshold is the same at scale 1 (plain
/// branch) and scaled by 2⁻¹⁰⁰, 2⁻⁴⁰⁰, 2³⁰⁰ (exact; the last two in wide floats), and it is the
/// exact class (zero-volume). The CLI says so for every scale.
#[test]
fn f162_the_zero_volume_class_does_not_change_under_exact_power_of_two_scaling() {
    for k in [0, -100, -400, 300, 200, -200] {
        let report = threshold_tet(2f64.powi(k)).check().unwrap();
        assert_eq!(report.zero_volume_tets, vec![0], "scale 2^{k}");
    }
    let dir = fresh_dir("round19_mesh", "f162");
    for (name, k) in [("edge1", 0), ("edge_small", -400), ("edge_big", 300)] {
        let mesh = threshold_tet(2f64.powi(k));
        let node: String =
            mesh.points.iter().enumerate().map(|(i, p)| format!("{i} {:?} {:?} {:?}\n", p[0], p[1], p[2])).collect();
        std::fs::write(dir.join(format!("{name}.node")), format!("4 3 0 0\n{node}")).unwrap();
        std::fs::write(dir.join(format!("{name}.ele")), "1 4 0\n0 0 1 2 3\n").unwrap();
        let out = run_in(&dir, &["info", &format!("{name}.node")]);
        assert!(out.status.success(), "{}", text(&out.stderr));
        assert!(text(&out.stderr).contains("1 zero-volume tets (first: 0)"), "{name}: {}", text(&out.stderr));
    }
}

/// Finding 163: the readers name a duplicate tet (or triangle) by the file's element numbers and
/// node tags, as their other errors do; the library's check says its ids are 0-based.
#[test]
fn f163_readers_name_a_duplicate_by_element_numbers_and_node_tags() {
    let node = "5 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 1 1 1\n";
    let ele = "3 4 0\n1 1 2 3 4\n2 2 3 4 5\n3 4 3 2 1\n"; // elements 1 and 3 coincide
    let err = parse_tetgen(node.as_bytes(), Path::new("dup1.node"), ele.as_bytes(), Path::new("dup1.ele")).unwrap_err();
    assert!(
        matches!(&err, ReadError::DuplicateElement { first: 1, second: 3, nodes, .. } if nodes == &[1, 2, 3, 4]),
        "{err}"
    );
    assert_eq!(
        err.to_string(),
        "dup1.ele: duplicate element: elements 1 and 3 have the same nodes [1, 2, 3, 4] (a tet listed twice)"
    );
    // Gmsh: node tags 101.., element numbers with gaps and other elements between the tets.
    let msh = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n5\n101 0 0 0\n102 1 0 0\n103 0 1 0\n104 0 0 1\n\
               105 1 1 1\n$EndNodes\n$Elements\n5\n7 15 2 0 1 101\n10 4 2 0 1 101 102 103 104\n\
               11 4 2 0 1 102 103 104 105\n12 2 2 0 1 101 102 103\n40 4 2 0 1 105 104 103 102\n$EndElements\n";
    let err = parse_msh(msh.as_bytes(), Path::new("dup.msh")).unwrap_err();
    assert!(err.to_string().contains("elements 11 and 40 have the same nodes [102, 103, 104, 105]"), "{err}");
    // OBJ faces are numbered from 1 in the file.
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\nf 3 2 1\n";
    let err = parse_obj(obj.as_bytes(), Path::new("dup.obj")).unwrap_err();
    assert!(
        err.to_string().contains("elements 1 and 3 have the same nodes [1, 2, 3] (a triangle listed twice)"),
        "{err}"
    );

    let mesh = TetMesh { points: UNIT.to_vec(), tets: vec![[0, 1, 2, 3], [3, 2, 1, 0]], ..Default::default() };
    let err = mesh.check().unwrap_err().to_string();
    assert!(err.contains("tets 0 and 1") && err.contains("0-based"), "{err}");

    let dir = fresh_dir("round19_mesh", "f163");
    std::fs::write(dir.join("dup1.node"), node).unwrap();
    std::fs::write(dir.join("dup1.ele"), ele).unwrap();
    let out = run_in(&dir, &["info", "dup1.node"]);
    assert!(!out.status.success());
    assert!(text(&out.stderr).contains("elements 1 and 3 have the same nodes [1, 2, 3, 4]"), "{}", text(&out.stderr));
}

/// Runs `script` with `sh`; None if it is still running after a minute (then it is killed).
fn sh_guarded(script: &str, dir: &Path) -> Option<std::process::Output> {
    let child = Command::new("sh")
        .arg("-c")
        .arg(script)
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    cli_common::wait_at_most_a_minute(child)
}

/// Finding 164: a named pipe redirected to standard input is read through `/dev/stdin`,
/// `/dev/fd/0` and `/proc/self/fd/0` — also once its writer has written everything and left,
/// when reopening it would wait for ever; a FIFO named directly is still refused, and the
/// advice of the refusal works.
#[cfg(target_os = "linux")]
#[test]
fn f164_a_fifo_on_standard_input_is_read() {
    let dir = fresh_dir("round19_mesh", "f164");
    cli_common::write_msh(&dir.join("cube.msh"), &kuhn_cube(1).0, &kuhn_cube(1).1);
    if !Command::new("mkfifo").arg(dir.join("ff")).status().is_ok_and(|s| s.success()) {
        eprintln!("no mkfifo here: skipped");
        return;
    }
    for name in ["/dev/stdin", "/dev/fd/0", "/proc/self/fd/0"] {
        // The writer finishes (the file is far below a pipe's buffer) before topomech starts.
        let script = format!("cat cube.msh > ff & sleep 0.3; '{BIN}' info --json {name} < ff");
        let out = sh_guarded(&script, &dir).unwrap_or_else(|| panic!("{name}: still waiting after a minute"));
        assert!(out.status.success(), "{name}: {}", text(&out.stderr));
        assert!(text(&out.stdout).contains("\"volumes\":6"), "{name}: {}", text(&out.stdout));
    }
    let script = format!("'{BIN}' info ff");
    let out = sh_guarded(&script, &dir).expect("a FIFO named directly is refused, not opened");
    let err = text(&out.stderr);
    assert!(!out.status.success() && err.contains("named pipe (FIFO)"), "{err}");
    assert!(err.contains("/dev/stdin < FIFO"), "{err}");
}
