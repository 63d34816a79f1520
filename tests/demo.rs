//! `topomech demo`, run as a user would, with few steps: the JSON summary obeys the laws of each
//! stage (mass kept or accounted for, boundary faces from the faces cut, 1→8 refinement), and the
//! files it names exist and are what they claim to be (ParaView series, OBJ, PNG).

use std::path::{Path, PathBuf};

use serde_json::Value;

mod cli_common;
use cli_common::{run_in, text};

/// A fresh scratch directory of this suite.
fn fresh_dir(name: &str) -> PathBuf {
    cli_common::fresh_dir("topomech-demo", name)
}

const STAGES: [&str; 6] = ["rest", "sag", "incision", "tear", "removal", "refinement"];

/// Runs `demo --json --steps STEPS --out out` in a fresh directory; returns it and the summary.
fn demo_json(name: &str, steps: u64) -> (PathBuf, Value) {
    let dir = fresh_dir(name);
    let steps = steps.to_string();
    let out = run_in(&dir, &["demo", "--json", "--steps", &steps, "--out", "out"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    assert_eq!(stdout.lines().count(), 1, "one JSON line: {stdout}");
    (dir, serde_json::from_str(&stdout).expect("valid JSON"))
}

fn num(v: &Value, key: &str) -> f64 {
    v[key].as_f64().unwrap_or_else(|| panic!("{key} is a number in {v}"))
}

fn int(v: &Value, key: &str) -> i64 {
    v[key].as_i64().unwrap_or_else(|| panic!("{key} is an integer in {v}"))
}

fn stage<'a>(summary: &'a Value, name: &str) -> &'a Value {
    summary["stages"].as_array().unwrap().iter().find(|s| s["stage"] == name).unwrap()
}

#[test]
fn every_check_passes_and_mass_is_kept_or_accounted_for() {
    let (_, s) = demo_json("laws", 40);
    assert_eq!(s["all_checks_passed"], true);
    let names: Vec<&str> = s["stages"].as_array().unwrap().iter().map(|r| r["stage"].as_str().unwrap()).collect();
    assert_eq!(names, STAGES);
    let m0 = num(&s, "initial_mass");
    assert!(m0 > 0.0);
    let mut checks = 0;
    for name in &STAGES[..5] {
        let r = stage(&s, name);
        let (mass, removed) = (num(r, "total_mass"), num(r, "removed_mass"));
        assert!((mass + removed - m0).abs() <= 1e-9 * m0, "{name}: {mass} + {removed} vs {m0}");
        if *name != "removal" {
            assert_eq!(removed, 0.0, "{name}: only the removal takes mass away");
            assert!((mass - m0).abs() <= 1e-9 * m0, "{name}: mass {mass} vs {m0}");
        }
        assert!(num(r, "mass_residual").abs() <= 1e-9 && num(r, "stiffness_residual").abs() <= 1e-9, "{name}: {r}");
        assert!(int(r, "components") >= 1, "{name}");
        assert!(int(r, "checks_passed") > checks, "{name}: checks run at every stage");
        checks = int(r, "checks_passed");
    }
    let removal = stage(&s, "removal");
    assert!(num(removal, "removed_mass") > 0.0);
    // The tear threshold is TEAR_FRACTION (0.8) of the largest vertex stress when the incision
    // stage ends, the state its row measures (closes a survivor of the thirty-second mutation sample).
    let (threshold, stress) = (num(&s["scene"], "tear_threshold"), num(stage(&s, "incision"), "max_stress"));
    assert!(stress > 0.0 && (threshold - 0.8 * stress).abs() <= 1e-12 * stress, "{threshold} vs 0.8 × {stress}");
    assert!((num(&s, "final_mass") + num(&s, "removed_mass") - m0).abs() <= 1e-9 * m0);
    assert_eq!(int(&s, "checks_passed"), int(stage(&s, "refinement"), "checks_passed"));
    assert_eq!(s["mesh"]["vertices"], 547, "the built-in liver");
    assert_eq!(s["refinement_mechanics"], true, "the simulation goes on on the refined network");
    let refined = stage(&s, "refinement");
    // The refined network is projected (one slot per vertex id, one spring per edge cell) and
    // stepped N/4 times with the scene's pins.
    let sim = &s["refined_simulation"];
    assert_eq!(int(sim, "steps"), 40 / 4);
    assert_eq!(int(sim, "springs"), int(refined, "edges"), "one spring per edge cell of the finest level");
    assert!(int(sim, "slots") >= int(refined, "vertices"), "a slot per vertex id (dead ids massless)");
    assert!(int(sim, "pinned") >= int(&s["scene"], "pinned"), "the body's pins are kept");
    assert!(num(sim, "kinetic_energy").is_finite() && num(sim, "kinetic_energy") >= 0.0, "{sim}");
    assert!(num(sim, "max_displacement") > 0.0 && num(sim, "max_displacement").is_finite(), "{sim}");
    assert_eq!(int(sim, "checks"), 3);
    assert!(num(refined, "mass_residual").abs() <= 1e-9, "the children share their parents' masses");
    assert!((num(refined, "total_mass") - num(&s, "final_mass")).abs() <= 1e-9 * m0);
    // Springs follow the refinement, one per edge cell before and after; a 1→8 only adds stiffness.
    let springs = &s["refinement_springs"];
    assert_eq!(int(springs, "before"), int(stage(&s, "removal"), "edges"), "one spring per edge of the final body");
    assert_eq!(int(springs, "after"), int(refined, "edges"), "one spring per edge cell of the finest level");
    assert!(int(springs, "doubled_split") <= int(springs, "doubled_edges"));
    assert_ne!(int(springs, "doubled_edges"), 1, "an edge is doubled with at least one other");
    assert!(num(refined, "stiffness_sum") > num(stage(&s, "removal"), "stiffness_sum") * (1.0 - 1e-9));
}

#[test]
fn stage_counts_follow_from_the_operations() {
    let (_, s) = demo_json("counts", 40);
    let get = |name: &str, key: &str| int(stage(&s, name), key);
    let rest = stage(&s, "rest");
    assert_eq!((int(rest, "volumes"), int(rest, "boundary_faces")), (1852, 870));
    assert_eq!(get("sag", "faces"), get("rest", "faces"), "sagging changes no cell");
    // Each dissociated face becomes two boundary faces.
    for (before, after) in [("sag", "incision"), ("incision", "tear")] {
        let cut = get(after, "cut_faces");
        assert!(cut > 0, "{after} cuts something");
        assert_eq!(get(after, "boundary_faces"), get(before, "boundary_faces") + 2 * cut, "{after}");
        assert_eq!(get(after, "faces"), get(before, "faces") + cut, "{after}");
        assert_eq!(get(after, "volumes"), get("rest", "volumes"), "{after} removes nothing");
    }
    // A removal dissociates the tet's inner faces, then its four faces leave with it.
    let removed = get("removal", "operations");
    assert!(removed > 0);
    assert_eq!(get("removal", "volumes"), get("tear", "volumes") - removed);
    let cut = get("removal", "cut_faces");
    assert_eq!(get("removal", "boundary_faces"), get("tear", "boundary_faces") + 2 * cut - 4 * removed);
    // Tetrahedron 1→8: seven more volumes per refined tet.
    let refined = get("refinement", "operations");
    assert!(refined > 0, "the incision zone is refined");
    assert_eq!(get("refinement", "volumes"), get("removal", "volumes") + 7 * refined);
    assert_eq!(get("refinement", "components"), get("removal", "components"), "refinement keeps the parts");
    scene_and_refinement_row_are_as_documented(&s);
}

/// DEMO.md, "JSON": the scene's keys (the material in full, β included: finding 194) and the
/// refinement row's masses (numbers; only the stiffness residual, stress and displacement null).
fn scene_and_refinement_row_are_as_documented(s: &Value) {
    let scene: Vec<&str> = s["scene"].as_object().unwrap().keys().map(String::as_str).collect();
    let documented = [
        "sag_steps",
        "dt",
        "integrator",
        "gravity",
        "young",
        "density",
        "viscosity",
        "damping",
        "pinned",
        "tear_threshold",
    ];
    assert_eq!(scene.len(), documented.len(), "scene keys {scene:?}");
    assert!(documented.iter().all(|k| scene.contains(k)), "scene keys {scene:?}");
    assert!(num(&s["scene"], "damping") > 0.0, "the demo's springs are damped");
    let row = stage(s, "refinement");
    for key in ["total_mass", "removed_mass", "mass_residual"] {
        assert!(row[key].is_number(), "refinement {key} = {}", row[key]);
    }
    for key in ["stiffness_residual", "max_stress", "max_displacement"] {
        assert!(row[key].is_null(), "refinement {key} = {}", row[key]);
    }
}

/// The `file="…"` attributes of a `.pvd` file.
fn pvd_files(pvd: &str) -> Vec<String> {
    pvd.split("file=\"").skip(1).map(|rest| rest.split('"').next().unwrap().to_string()).collect()
}

/// (width, height) from the IHDR chunk of a PNG file, after checking the signature.
fn png_size(bytes: &[u8]) -> (u32, u32) {
    assert!(bytes.len() > 33, "a PNG has at least a signature and an IHDR");
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "PNG signature");
    assert_eq!(&bytes[12..16], b"IHDR", "IHDR comes first");
    let be = |k: usize| u32::from_be_bytes(bytes[k..k + 4].try_into().unwrap());
    (be(16), be(20))
}

#[test]
fn the_files_it_names_exist_and_are_what_they_claim() {
    let (dir, s) = demo_json("files", 30);
    let files = &s["files"];
    let at = |p: &Value| dir.join(p.as_str().unwrap());
    let pvd = std::fs::read_to_string(at(&files["pvd"])).expect("the .pvd exists");
    let listed = pvd_files(&pvd);
    let vtu: Vec<&Value> = files["vtu"].as_array().unwrap().iter().collect();
    assert_eq!(listed.len(), vtu.len(), "the .pvd lists every frame");
    assert!(vtu.len() >= 5, "a frame per stage at least");
    for (name, path) in listed.iter().zip(&vtu) {
        assert!(path.as_str().unwrap().ends_with(name.as_str()), "{name} vs {path}");
        let frame = std::fs::read_to_string(dir.join("out").join(name)).expect("each listed .vtu exists");
        assert!(frame.contains("<UnstructuredGrid>") && frame.contains("Name=\"stress\""), "{name}");
    }
    let objs = files["obj"].as_array().unwrap();
    let obj = std::fs::read_to_string(at(&objs[0])).expect("the surface OBJ exists");
    let faces = obj.lines().filter(|l| l.starts_with("f ")).count() as i64;
    assert_eq!(faces, int(stage(&s, "removal"), "boundary_faces"), "one triangle per boundary face of the final body");
    let pngs = files["png"].as_array().unwrap();
    assert_eq!(pngs.len(), 5, "after sag, incision, tear, removal, refinement");
    let sizes: Vec<(u32, u32)> = pngs.iter().map(|p| png_size(&std::fs::read(at(p)).expect("PNG exists"))).collect();
    assert!(sizes[0].0 > 0 && sizes[0].1 > 0);
    assert!(sizes.iter().all(|&wh| wh == sizes[0]), "one fixed frame: {sizes:?}");
}

#[test]
fn the_text_report_ends_with_a_table_of_every_stage() {
    let dir = fresh_dir("text");
    let out = run_in(&dir, &["demo", "--steps", "20", "--out", "pictures"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let report = text(&out.stdout);
    let table = report.split("\nsummary\n").nth(1).expect("a summary section");
    for name in STAGES {
        assert!(table.lines().any(|l| l.trim_start().starts_with(name)), "{name} row: {table}");
    }
    assert!(report.contains("checks passed"), "{report}");
    assert!(report.contains("springs carried, one per edge cell"), "{report}");
    assert!(report.contains("on the refined network") && report.contains("pins held"), "{report}");
    assert!(dir.join("pictures/scene.pvd").is_file(), "--out is used");
    assert!(!dir.join("out").exists(), "and the default is not");
}

/// An output directory where a file stands: refused before any stage, with a message that says
/// a directory could not be created (it said "cannot write out: File exists").
#[test]
fn an_output_path_that_is_a_file_is_named_as_a_directory_that_cannot_be_created() {
    let dir = fresh_dir("out-is-a-file");
    std::fs::write(dir.join("taken"), "a file").unwrap();
    let out = run_in(&dir, &["demo", "--json", "--steps", "4", "--out", "taken"]);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("cannot create the directory taken"), "{err}");
    assert!(text(&out.stdout).is_empty(), "no summary: {}", text(&out.stdout));
}

fn expect_mesh_error(dir: &Path, mesh: &Path) -> String {
    let out = run_in(dir, &["demo", "--steps", "5", "--mesh", mesh.to_str().unwrap(), "--out", "out"]);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(err.starts_with("topomech: error: "), "{err}");
    assert!(err.contains(mesh.to_str().unwrap()), "names the file: {err}");
    assert!(text(&out.stdout).is_empty(), "nothing on stdout");
    err
}

#[test]
fn a_missing_or_garbage_mesh_is_named() {
    let dir = fresh_dir("bad-mesh");
    expect_mesh_error(&dir, &dir.join("no-such.msh"));
    let garbage = dir.join("garbage.msh");
    std::fs::write(&garbage, b"not a mesh at all\n\x00\xff").unwrap();
    expect_mesh_error(&dir, &garbage);
}

fn demo_on(mesh: &Path, name: &str) -> Value {
    let dir = fresh_dir(name);
    let out = run_in(&dir, &["demo", "--json", "--steps", "20", "--mesh", mesh.to_str().unwrap()]);
    assert!(out.status.success(), "{}: {}", mesh.display(), text(&out.stderr));
    let s: Value = serde_json::from_str(&text(&out.stdout)).unwrap();
    assert_eq!(s["mesh_name"], mesh.to_str().unwrap());
    assert_eq!(s["all_checks_passed"], true);
    assert!(dir.join("out/scene.pvd").is_file(), "the default output directory is out/");
    s
}

#[test]
fn other_mesh_files_run_the_same_scene() {
    let tiny = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/cube5.msh");
    let s = demo_on(&tiny, "tiny-mesh");
    assert_eq!(int(stage(&s, "rest"), "volumes"), 5);
    let shared = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/meshes/box_458.msh");
    if !shared.is_file() {
        println!("note: {} is absent; skipping it", shared.display());
        return;
    }
    let s = demo_on(&shared, "box-mesh");
    assert_eq!(int(stage(&s, "rest"), "volumes"), 1566);
    assert!(int(stage(&s, "incision"), "cut_faces") > 0);
}

/// A mesh whose removal ball at the free tip holds every tet (one tet, and two unused points that
/// stretch the scene's box): the removal keeps the tet farthest from the tip, so the refinement
/// and its checks still have a body to work on (before, it emptied the body and the refinement
/// failed on a NaN mass residual).
#[test]
fn the_removal_never_takes_the_whole_body() {
    let dir = fresh_dir("one-tet-mesh");
    let mesh = dir.join("one_tet_two_free_points.msh");
    let text_mesh = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n6\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n\
                     5 9 9 9\n6 8 8 8\n$EndNodes\n$Elements\n1\n1 4 2 0 0 1 2 3 4\n$EndElements\n";
    std::fs::write(&mesh, text_mesh).unwrap();
    let s = demo_on(&mesh, "one-tet");
    assert_eq!(int(stage(&s, "removal"), "operations"), 0, "the only tet stays");
    assert_eq!(int(stage(&s, "removal"), "volumes"), 1);
    assert_eq!(int(stage(&s, "refinement"), "components"), 1);
}
