//! The `topomech` binary, run as a user would: the demo, `info --json` on the reference meshes,
//! and bad input (which must give a non-zero status and a one-line error, never a panic).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_topomech");
const SHARED_MESHES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/meshes");
const BUILTIN: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/data/liver_547_v22.msh");

/// The keys of `info --json`, in order.
const KEYS: [&str; 10] = [
    "darts",
    "vertices",
    "edges",
    "faces",
    "volumes",
    "boundary_faces",
    "components",
    "euler_characteristic",
    "valid",
    "build_ms",
];

/// (file, nodes, tets, edges, boundary faces), copied from the table of
/// `../shared/meshes/README.md` (counts made by meshio and an independent reader).
const REFERENCE: [(&str, u64, u64, u64, u64); 8] = [
    ("liver_547.msh", 547, 1852, 2833, 870),
    ("liver_547_v22.msh", 547, 1852, 2833, 870),
    ("liver_547.node", 547, 1852, 2833, 870),
    ("liver_1814.msh", 1814, 7453, 10409, 2286),
    ("box_458.msh", 458, 1566, 2377, 708),
    ("box_458_v22.msh", 458, 1566, 2377, 708),
    ("sfepy_cube_medium_tetra.msh", 448, 1782, 2493, 528),
    ("sofa_liver_v1.msh", 181, 596, 914, 276),
];

fn run(args: &[&str]) -> Output {
    Command::new(BIN).args(args).output().expect("the topomech binary runs")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A scratch file under Cargo's per-test temporary directory.
fn scratch(name: &str, contents: &[u8]) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("topomech-cli");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, contents).unwrap();
    path
}

/// The value of `label` in a `  label   value` table row of `text`.
fn table_value<'a>(text: &'a str, label: &str) -> Option<&'a str> {
    text.lines().find_map(|l| {
        let rest = l.trim_start().strip_prefix(label)?;
        rest.starts_with("  ").then(|| rest.trim())
    })
}

fn info_json(path: &Path) -> serde_json::Map<String, serde_json::Value> {
    let out = run(&["info", "--json", path.to_str().unwrap()]);
    assert!(out.status.success(), "{}: {}", path.display(), stderr(&out));
    let text = stdout(&out);
    assert_eq!(text.lines().count(), 1, "one JSON line: {text}");
    let value: serde_json::Value = serde_json::from_str(&text).expect("valid JSON");
    value.as_object().expect("a JSON object").clone()
}

fn check_json(path: &Path, (nodes, tets, edges, boundary): (u64, u64, u64, u64)) {
    let obj = info_json(path);
    let keys: Vec<&str> = obj.keys().map(String::as_str).collect();
    let mut expected_keys = KEYS.to_vec();
    expected_keys.sort_unstable();
    let mut sorted_keys = keys.clone();
    sorted_keys.sort_unstable();
    assert_eq!(sorted_keys, expected_keys, "{}", path.display());
    let int = |k: &str| obj[k].as_u64().unwrap_or_else(|| panic!("{k} is a non-negative integer"));
    let name = path.display();
    assert_eq!(int("vertices"), nodes, "{name}");
    assert_eq!(int("volumes"), tets, "{name}");
    assert_eq!(int("edges"), edges, "{name}");
    assert_eq!(int("boundary_faces"), boundary, "{name}");
    assert_eq!(int("faces"), (4 * tets + boundary) / 2, "{name}: each face has two tet sides unless on the boundary");
    assert_eq!(int("darts"), 24 * tets, "{name}");
    assert_eq!(int("components"), 1, "{name}");
    assert_eq!(obj["euler_characteristic"].as_i64(), Some(1), "{name}: a ball");
    assert_eq!(obj["valid"], serde_json::Value::Bool(true), "{name}");
    let ms = obj["build_ms"].as_f64().expect("build_ms is a number");
    assert!(ms >= 0.0 && ms.is_finite(), "{name}: build_ms = {ms}");
}

/// Runs the binary in a fresh scratch directory (the demo writes `out/` into its working
/// directory); returns the output and the directory.
fn run_in_scratch(name: &str, args: &[&str]) -> (Output, PathBuf) {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("topomech-cli-runs").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let out = Command::new(BIN).current_dir(&dir).args(args).output().expect("the topomech binary runs");
    (out, dir)
}

#[test]
fn no_arguments_runs_the_demo_on_the_builtin_liver() {
    let (out, dir) = run_in_scratch("no-arguments", &[]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert_eq!(table_value(&text, "vertices"), Some("547"), "{text}");
    assert_eq!(table_value(&text, "volumes"), Some("1852"), "{text}");
    assert_eq!(table_value(&text, "edges"), Some("2833"), "{text}");
    assert_eq!(table_value(&text, "boundary faces"), Some("870"), "{text}");
    assert_eq!(table_value(&text, "faces"), Some("4139"), "{text}");
    assert_eq!(table_value(&text, "darts"), Some("44448"), "{text}");
    assert_eq!(table_value(&text, "components"), Some("1"), "{text}");
    assert_eq!(table_value(&text, "Euler characteristic"), Some("1"), "{text}");
    assert_eq!(table_value(&text, "valid"), Some("yes"), "{text}");
    assert_eq!(table_value(&text, "orientable"), Some("yes"), "{text}");
    assert!(table_value(&text, "build time").is_some_and(|v| v.ends_with(" ms")), "{text}");
    for stage in ["[1/5] sag", "[2/5] incision", "[3/5] tear", "[4/5] removal", "[5/5] refinement"] {
        assert!(text.contains(stage), "{stage}: {text}");
    }
    assert!(text.lines().any(|l| l.trim_start().starts_with("all ") && l.contains(" checks passed")), "{text}");
    assert!(dir.join("out/scene.pvd").is_file(), "writes out/ by default");
    assert!(stderr(&out).is_empty(), "the built-in mesh has no warning: {}", stderr(&out));
}

#[test]
fn demo_subcommand_and_json_agree_with_the_table() {
    let (out, _) = run_in_scratch("demo-json", &["demo", "--json", "--steps", "10"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let value: serde_json::Value = serde_json::from_str(&stdout(&out)).expect("valid JSON");
    // The mesh part is what `info --json` prints (the whole of the old `demo --json`).
    let mesh = &value["mesh"];
    let info = info_json(Path::new(BUILTIN));
    for key in KEYS.iter().filter(|&&k| k != "build_ms") {
        assert_eq!(mesh[key], info[*key], "{key}");
    }
    assert_eq!(mesh["vertices"], 547);
    assert_eq!(mesh["boundary_faces"], 870);
    let (table, _) = run_in_scratch("demo-text", &["demo", "--steps", "10"]);
    assert_eq!(table_value(&stdout(&table), "edges"), Some(mesh["edges"].to_string().as_str()));
}

#[test]
fn info_json_on_the_builtin_copy_in_data() {
    check_json(Path::new(BUILTIN), (547, 1852, 2833, 870));
}

#[test]
fn info_json_on_the_shared_reference_meshes() {
    let dir = Path::new(SHARED_MESHES);
    if !dir.is_dir() {
        println!("note: {} is absent; skipping the reference meshes", dir.display());
        return;
    }
    for (file, nodes, tets, edges, boundary) in REFERENCE {
        check_json(&dir.join(file), (nodes, tets, edges, boundary));
    }
}

#[test]
fn info_prints_a_table_naming_the_file() {
    let out = run(&["info", BUILTIN]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert_eq!(text.lines().next(), Some(BUILTIN));
    assert_eq!(table_value(&text, "volumes"), Some("1852"), "{text}");
    assert_eq!(table_value(&text, "valid"), Some("yes"), "{text}");
}

/// Runs `info` on `path` and checks the failure contract; returns stderr.
fn expect_failure(path: &Path) -> String {
    for json in [false, true] {
        let mut args = vec!["info", path.to_str().unwrap()];
        if json {
            args.push("--json");
        }
        let out = run(&args);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{}: {err}", path.display());
        assert!(!err.contains("panicked"), "{err}");
        assert!(!err.contains("RUST_BACKTRACE"), "{err}");
        assert!(stdout(&out).is_empty(), "nothing on stdout: {}", stdout(&out));
        assert_eq!(err.lines().count(), 1, "one line: {err}");
        assert!(err.starts_with("topomech: error: "), "{err}");
        assert!(err.contains(path.to_str().unwrap()), "names the file: {err}");
    }
    stderr(&run(&["info", path.to_str().unwrap()]))
}

const HEADER: &str = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";

/// An MSH 2.2 file with the given node lines and tet lines (`a b c d` node tags).
fn msh22(nodes: &[&str], tets: &[&str]) -> String {
    let mut s = format!("{HEADER}$Nodes\n{}\n", nodes.len());
    for (k, n) in nodes.iter().enumerate() {
        s += &format!("{} {n}\n", k + 1);
    }
    s += &format!("$EndNodes\n$Elements\n{}\n", tets.len());
    for (k, t) in tets.iter().enumerate() {
        s += &format!("{} 4 2 1 1 {t}\n", k + 1);
    }
    s + "$EndElements\n"
}

const SIX_NODES: [&str; 6] = ["0 0 0", "1 0 0", "0 1 0", "0 0 1", "0 0 -1", "1 1 1"];

#[test]
fn a_missing_file_is_named() {
    let path = Path::new(env!("CARGO_TARGET_TMPDIR")).join("no-such-dir/missing.msh");
    let err = expect_failure(&path);
    assert!(err.contains("cannot read"), "{err}");
}

/// A device that never ends is refused before anything is read, by every command that reads a
/// file (before, `info /dev/zero` read until the memory ran out; under a 4 GB limit it failed
/// with "out of memory", without one it took the machine's memory). Pipes are still read.
#[cfg(unix)]
#[test]
fn a_device_is_refused_before_it_is_read() {
    for args in [vec!["info", "/dev/zero"], vec!["check", "/dev/zero"], vec!["conformance", "check", "/dev/zero"]] {
        let out = run(&args);
        let err = stderr(&out) + &stdout(&out); // conformance check reports on stdout
        assert!(matches!(out.status.code(), Some(1 | 2)), "{args:?}: {err}");
        assert!(err.contains("/dev/zero: ") && err.contains("a device or socket, not a file"), "{args:?}: {err}");
        assert_eq!(err.matches("/dev/zero").count(), 1, "the file is named once: {err}");
    }
    let piped = std::process::Command::new("sh")
        .arg("-c")
        .arg(format!("\"{BIN}\" info --json /dev/stdin < \"{BUILTIN}\""))
        .output()
        .unwrap();
    assert!(piped.status.success(), "{}", stderr(&piped));
    assert!(stdout(&piped).contains("\"volumes\":1852"), "{}", stdout(&piped));
}

#[test]
fn a_garbage_file_is_an_unknown_format() {
    let path = scratch("garbage.msh", b"hello, this is not a mesh\n\x00\xff\xfe");
    let err = expect_failure(&path);
    assert!(err.contains("unknown mesh format"), "{err}");
}

#[test]
fn truncated_files_name_the_line() {
    let full = std::fs::read(BUILTIN).unwrap();
    for (k, cut) in [full.len() / 3, full.len() / 2, full.len() - 200, full.len() - 10].into_iter().enumerate() {
        let path = scratch(&format!("truncated_{k}.msh"), &full[..cut]);
        let err = expect_failure(&path);
        assert!(err.contains("line "), "cut at byte {cut}: {err}");
    }
}

#[test]
fn a_face_shared_by_three_tets_is_not_a_quasi_manifold() {
    let text = msh22(&SIX_NODES, &["1 2 3 4", "1 3 2 5", "1 2 3 6"]);
    let path = scratch("three_tets_one_face.msh", text.as_bytes());
    let err = expect_failure(&path);
    assert!(err.contains("not a quasi-manifold"), "{err}");
    assert!(err.contains("file node tags [1, 2, 3]"), "{err}");
}

#[test]
fn a_nan_coordinate_names_the_node_and_line() {
    let mut nodes = SIX_NODES;
    nodes[3] = "0 nan 1";
    let text = msh22(&nodes[..5], &["1 2 3 4", "1 3 2 5"]);
    let path = scratch("nan.msh", text.as_bytes());
    let err = expect_failure(&path);
    assert!(err.contains("non-finite coordinate"), "{err}");
    // Node 4 is on line 9: 3 header lines, `$Nodes`, the count, then nodes 1..4.
    assert!(err.contains("line 9"), "{err}");
}

/// A mesh that loads (a flat tet is a valid map) but on which no mass/spring model can stand:
/// every command that builds one fails with one line naming the file, the law and the file's
/// node tags of the flat tet (2nd in the file, with a Z-order that would renumber it).
#[test]
fn a_flat_tet_is_refused_by_the_model_naming_the_file_and_its_nodes() {
    let nodes = ["0 0 0", "1 0 0", "0 1 0", "0 0 1", "2 0 0", "3 0 0", "4 0 0", "2 1 0"];
    let text = msh22(&nodes, &["1 2 3 4", "5 6 7 8"]);
    let path = scratch("flat_tet.msh", text.as_bytes());
    let p = path.to_str().unwrap();
    let commands: [&[&str]; 6] = [
        &["simulate", p, "--steps", "2"],
        &["simulate", p, "--steps", "2", "--spatial-order"],
        &["cut", p, "--plane", "0,0,0.5,0,0,1"],
        &["tear", p, "--threshold", "2"],
        &["bench", "step", p],
        &["demo", "--mesh", p, "--steps", "2"],
    ];
    for args in commands {
        let out = run(args);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        let last = err.lines().last().unwrap_or_default();
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert!(
            last.starts_with(&format!("topomech: error: {p}: cannot build the mass/spring model")),
            "{args:?}: {err}"
        );
        assert!(last.contains("zero volume") && last.contains("file node tags [5, 6, 7, 8]"), "{args:?}: {err}");
    }
    assert_eq!(run(&["info", p]).status.code(), Some(0), "info reports the map, which is valid");
}

/// A cube of six tets squashed flat: the cut campaign runs (it needs no geometry), the mixed
/// campaign refuses it naming the file and the nodes. (Before, it panicked on a lookup, or paired
/// children with the wrong volumes and reported made-up findings.)
#[test]
fn the_mixed_campaign_refuses_a_mesh_without_volume_naming_the_file_and_nodes() {
    let nodes = ["0 0 0", "1 0 0", "0 1 0", "1 1 0", "0 0 0", "1 0 0", "0 1 0", "1 1 0"];
    let tets = ["1 2 4 8", "1 2 6 8", "1 3 4 8", "1 3 7 8", "1 5 6 8", "1 5 7 8"];
    let path = scratch("flat_cube.msh", msh22(&nodes, &tets).as_bytes());
    let p = path.to_str().unwrap();
    let cuts = ["ambiguity", p, "--cuts", "3", "--sequences", "4"];
    assert_eq!(run(&cuts).status.code(), Some(0), "{}", stderr(&run(&cuts)));
    for probability in ["0.5", "1"] {
        let out = run(&[&cuts[..], &["--subdivide", probability]].concat());
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert!(!err.contains("panicked"), "{err}");
        let last = err.lines().last().unwrap_or_default();
        assert!(last.starts_with(&format!("topomech: error: {p}: the mixed campaign cannot run")), "{err}");
        assert!(last.contains("tet 0 has zero volume") && last.contains("file node tags [1, 2, 4, 8]"), "{err}");
    }
}

#[test]
fn warnings_go_to_stderr_and_the_load_succeeds() {
    // Tet 2 is inverted (node 5 is below the base, like node 4 above it) and node 6 is unused.
    let text = msh22(&SIX_NODES, &["1 2 3 4", "1 2 3 5"]);
    let path = scratch("inverted.msh", text.as_bytes());
    let out = run(&["info", "--json", path.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(err.contains("1 inverted tets") && err.contains("first: 1"), "{err}");
    assert!(err.contains("1 unreferenced points") && err.contains("first: 5"), "{err}");
    let value: serde_json::Value = serde_json::from_str(&stdout(&out)).expect("stdout stays pure JSON");
    assert_eq!(value["volumes"], 2);
    assert_eq!(value["boundary_faces"], 6);
    assert_eq!(value["valid"], true);
}

#[test]
fn a_bad_command_line_is_a_usage_error_not_a_panic() {
    let out = run(&["info"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("Usage"), "{}", stderr(&out));
    assert!(!stderr(&out).contains("panicked"));
}

/// Numbers that parse but make no sense are refused with a message, not run silently: a NaN
/// tear threshold (no vertex compares above NaN, so nothing would ever tear), a negative
/// removal radius (an empty ball), negative time steps and material constants.
#[test]
fn non_finite_and_out_of_range_numbers_are_refused_with_a_message() {
    let liver = concat!(env!("CARGO_MANIFEST_DIR"), "/data/liver_547_v22.msh");
    for (args, needle) in [
        (vec!["tear", liver, "--threshold", "NaN", "--steps", "1"], "threshold NaN"),
        (vec!["tear", liver, "--threshold", "inf", "--steps", "1"], "threshold inf"),
        (vec!["remove", liver, "--sphere", "0,0,0,-1"], "radius"),
        // A negative number reaches the command's own check (not clap's "unexpected argument").
        (vec!["tear", liver, "--threshold", "-1", "--steps", "1"], "threshold -1"),
        // Finding 269: refused up front, also when no step would reach `tear_step`.
        (vec!["tear", liver, "--threshold", "nan", "--steps", "0"], "threshold NaN"),
        (vec!["tear", liver, "--threshold", "-5", "--steps", "0"], "threshold -5"),
        (vec!["tear", liver, "--threshold", "inf", "--steps", "0"], "threshold inf"),
        (vec!["simulate", liver, "--steps", "1", "--dt", "-1"], "time step -1"),
        (vec!["simulate", liver, "--steps", "1", "--young", "-5"], "young = -5"),
        (vec!["refine", liver, "--around", "0,0,0", "--radius", "-1"], "radius must be"),
        (vec!["cut", liver, "--plane", "0,0,0,1,0,0", "--density", "-2"], "density = -2"),
    ] {
        let out = run(&args);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(needle), "{args:?}: {}", stderr(&out));
        assert!(!stderr(&out).contains("panicked"));
    }
    // Non-finite numbers in vector and plane arguments are usage errors (exit 2) naming the
    // value, not a run that blows up at step 0 or pins nothing.
    for (args, needle) in [
        (vec!["simulate", liver, "--steps", "1", "--gravity", "nan,0,0"], "not finite"),
        (vec!["simulate", liver, "--steps", "1", "--pin-below", "z=nan"], "not finite"),
        (vec!["tear", liver, "--threshold", "1", "--steps", "1", "--pin-z", "nan"], "not finite"),
        // Finding 310: exited 1 from the simulation ("gravity … must be finite").
        (vec!["tear", liver, "--threshold", "1", "--steps", "1", "--gravity-z", "nan"], "not finite"),
        (vec!["tear", liver, "--threshold", "1", "--steps", "1", "--gravity-z", "-inf"], "not finite"),
        (vec!["remove", liver, "--sphere", "nan,0,0,1"], "not finite"),
        (vec!["cut", liver, "--plane", "0,0,0,inf,0,0"], "not finite"),
        (vec!["simulate", liver, "--steps", "-3"], "invalid value '-3' for '--steps"),
    ] {
        let out = run(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(needle), "{args:?}: {}", stderr(&out));
        assert!(!stderr(&out).contains("panicked"));
    }
}

#[test]
fn remove_names_an_id_past_the_mesh_and_removes_a_repeated_id_once() {
    let liver = "data/liver_547_v22.msh";
    // An id past the last tet is refused before anything is removed, naming the id and the range
    // (not "already removed", which is what the second removal of the list would have said).
    let out = run(&["remove", liver, "--tets", "3,1852"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("tet 1852 does not exist: the mesh has 1852 tets (ids 0 to 1851)"),
        "{}",
        stderr(&out)
    );
    // A repeated id is removed once: two tets go, not an error on the third mention.
    let out = run(&["remove", liver, "--tets", "3,7,3,3", "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_str(&stdout(&out)).expect("one JSON object");
    assert_eq!(v["before"]["volumes"], 1852);
    assert_eq!(v["after"]["volumes"], 1850);
    assert_eq!(v["after"]["conservation_ok"], true);
    let removed = v["after"]["removed_mass"].as_f64().unwrap();
    let (before, after) = (v["before"]["total_mass"].as_f64().unwrap(), v["after"]["total_mass"].as_f64().unwrap());
    assert!(removed > 0.0 && ((before - removed) - after).abs() <= 1e-12 * before, "{before} - {removed} != {after}");
}

/// `simulate --json` on liver_547 (20 steps of 1e-4 s): the printed line and its object.
fn simulate_json(extra: &[&str]) -> (String, serde_json::Map<String, serde_json::Value>) {
    let mut args = vec!["simulate", "data/liver_547_v22.msh", "--steps", "20", "--dt", "1e-4", "--json"];
    args.extend_from_slice(extra);
    let out = run(&args);
    assert!(out.status.success(), "{args:?}: {}", stderr(&out));
    let v: serde_json::Value = serde_json::from_str(&stdout(&out)).expect("one JSON object");
    (stdout(&out), v.as_object().expect("an object").clone())
}

#[test]
fn simulate_writes_a_series_and_a_summary_that_follow_from_the_scene() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("topomech-cli-simulate");
    let _ = std::fs::remove_dir_all(&dir);
    let out_dir = dir.to_str().unwrap();
    let (text, s) = simulate_json(&["--pin-below", "z=-1", "--frames", "5", "--out", out_dir]);
    // Exactly the keys, in its order (as printed: the parsed map sorts them).
    let keys = ["steps", "dt", "integrator", "step_us_median", "total_mass", "kinetic_energy", "max_displacement"];
    assert_eq!(s.len(), keys.len(), "{text}");
    let at: Vec<usize> = keys.iter().map(|k| text.find(&format!("\"{k}\":")).expect(k)).collect();
    assert!(at.windows(2).all(|w| w[0] < w[1]), "keys out of order: {text}");
    assert_eq!((s["steps"].as_u64(), s["dt"].as_f64(), s["integrator"].as_str()), (Some(20), Some(1e-4), Some("rk4")));
    // The total mass is the body's: ρ × volume as the library builds it from the same file.
    let mesh = topomech::io::read_mesh(Path::new("data/liver_547_v22.msh")).unwrap();
    let (body, _) =
        topomech::mechanics::Body::from_tets(&mesh.points, &mesh.tets, topomech::mechanics::Material::default())
            .unwrap();
    let mass = body.total_vertex_mass();
    assert!((s["total_mass"].as_f64().unwrap() - mass).abs() <= 1e-12 * mass, "{s:?} vs {mass}");
    // Gravity moved the free vertices from rest.
    let (ke, disp) = (s["kinetic_energy"].as_f64().unwrap(), s["max_displacement"].as_f64().unwrap());
    assert!(ke > 0.0 && ke.is_finite() && disp > 0.0 && disp.is_finite(), "{s:?}");
    // 20 steps, a frame every 20 / 5 = 4 steps from step 0: six frames, each named by the series.
    let pvd = std::fs::read_to_string(dir.join("frame.pvd")).expect("the series file");
    let files: Vec<&str> = pvd.split("file=\"").skip(1).map(|r| r.split('"').next().unwrap()).collect();
    assert_eq!(files, (0..6).map(|k| format!("frame_{k:06}.vtu")).collect::<Vec<_>>());
    for f in &files {
        let vtu = std::fs::read_to_string(dir.join(f)).expect("a frame the series names");
        assert!(vtu.contains("NumberOfPoints=\"547\"") && vtu.contains("NumberOfCells=\"1852\""), "{f}");
    }
    // Two worker threads step the same bits; only the timing may differ.
    let (_, two) = simulate_json(&["--pin-below", "z=-1", "--threads", "2"]);
    for k in ["total_mass", "kinetic_energy", "max_displacement"] {
        assert_eq!(two[k], s[k], "{k} on 2 threads");
    }
    // Every vertex pinned: nothing moves.
    let (_, fixed) = simulate_json(&["--pin-below", "z=1e9"]);
    assert_eq!((fixed["kinetic_energy"].as_f64(), fixed["max_displacement"].as_f64()), (Some(0.0), Some(0.0)));
    // … and says so without a sign (an empty f64 `sum` is −0: it printed "kinetic_energy":-0.0).
    assert_eq!(fixed["kinetic_energy"].to_string(), "0.0");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn simulate_refuses_a_pinned_id_past_the_last_point() {
    let out = run(&["simulate", "data/liver_547_v22.msh", "--steps", "1", "--pin", "3,547"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("--pin: vertex 547 does not exist: the mesh has 547 points (ids 0 to 546)"),
        "{}",
        stderr(&out)
    );
    let ok = run(&["simulate", "data/liver_547_v22.msh", "--steps", "1", "--pin", "3,546"]);
    assert!(ok.status.success(), "{}", stderr(&ok));
}

#[test]
fn simulate_refuses_a_thread_count_of_zero_or_past_the_limit() {
    for (threads, message) in [
        ("0", "the thread count must be from 1 to 256, got 0"),
        ("257", "the thread count must be from 1 to 256, got 257"),
        ("100000", "the thread count must be from 1 to 256, got 100000"),
        ("-2", "expected a whole number of threads, got \"-2\""),
        ("two", "expected a whole number of threads, got \"two\""),
    ] {
        let out = run(&["simulate", "data/liver_547_v22.msh", "--steps", "1", "--threads", threads]);
        assert_eq!(out.status.code(), Some(2), "--threads {threads}: {}", stderr(&out));
        assert!(stderr(&out).contains(message), "--threads {threads}: {}", stderr(&out));
    }
    let ok = run(&["simulate", "data/liver_547_v22.msh", "--steps", "1", "--threads", "256", "--json"]);
    assert!(ok.status.success(), "{}", stderr(&ok));
}

#[test]
fn bench_step_reports_both_models_on_the_same_system() {
    let out = run(&["bench", "step", "data/liver_547_v22.msh", "--rounds", "3", "--batch", "2", "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_str(&stdout(&out)).expect("one JSON object");
    let o = v.as_object().unwrap();
    for k in ["map_step_us", "flat_step_us", "ratio", "springs", "vertices"] {
        assert!(o.contains_key(k), "{k} missing: {v}");
    }
    assert_eq!((v["springs"].as_u64(), v["vertices"].as_u64()), (Some(2833), Some(547)));
    let (map, flat, ratio) =
        (v["map_step_us"].as_f64().unwrap(), v["flat_step_us"].as_f64().unwrap(), v["ratio"].as_f64().unwrap());
    assert!(map > 0.0 && flat > 0.0 && ratio > 0.0, "{v}");
    // `bench order`: the flat model under two point orders and on 2 threads, one small round.
    let out = run(&["bench", "order", "data/liver_547_v22.msh", "--rounds", "1", "--batch", "1", "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_str(&stdout(&out)).expect("one JSON object");
    for k in ["zorder_step_us", "rcm_step_us", "rcm_2_threads_step_us", "rcm_over_zorder", "speedup_2_threads"] {
        assert!(v[k].as_f64().is_some_and(|x| x > 0.0 && x.is_finite()), "{k}: {v}");
    }
    assert_eq!((v["springs"].as_u64(), v["vertices"].as_u64()), (Some(2833), Some(547)));
    let per_spring = v["rcm_step_us"].as_f64().unwrap() * 1e3 / 2833.0;
    assert!((v["rcm_ns_per_spring"].as_f64().unwrap() - per_spring).abs() <= 1e-9 * per_spring, "{v}");
    assert!(["portable", "avx2", "avx512"].contains(&v["kernel"].as_str().unwrap()), "{v}");
}

#[test]
fn remove_by_ball_takes_the_tets_whose_centroid_is_inside_and_writes_what_is_left() {
    let liver = "data/liver_547_v22.msh";
    let mesh = topomech::io::read_mesh(Path::new(liver)).unwrap();
    let n = mesh.points.len() as f64;
    let c: Vec<f64> = (0..3).map(|k| mesh.points.iter().map(|p| p[k]).sum::<f64>() / n).collect();
    let r = 0.2
        * (0..3).map(|k| mesh.points.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max) - c[k]).fold(0.0, f64::max);
    // The expected tets, from the file alone: centroid within r of c; their mass is ρ·|V| (ρ = 2).
    let inside: Vec<&[u32; 4]> = mesh
        .tets
        .iter()
        .filter(|t| {
            (0..3)
                .map(|k| (t.iter().map(|&v| mesh.points[v as usize][k]).sum::<f64>() / 4.0 - c[k]).powi(2))
                .sum::<f64>()
                <= r * r
        })
        .collect();
    assert!(inside.len() > 10 && inside.len() < mesh.tets.len() / 2, "{} tets in the ball", inside.len());
    let p = |v: u32| mesh.points[v as usize];
    let mass: f64 =
        inside.iter().map(|t| 2.0 * topomech::mesh::signed_volume(p(t[0]), p(t[1]), p(t[2]), p(t[3])).abs()).sum();
    let vtu = Path::new(env!("CARGO_TARGET_TMPDIR")).join("topomech-cli-remove-ball.vtu");
    let _ = std::fs::remove_file(&vtu);
    let ball = format!("{},{},{},{r}", c[0], c[1], c[2]);
    let args = ["remove", liver, "--sphere", &ball, "--density", "2", "--out", vtu.to_str().unwrap(), "--json"];
    let out = run(&args);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_str(&stdout(&out)).expect("one JSON object");
    let (before, after) = (&v["before"], &v["after"]);
    assert_eq!(after["volumes"].as_u64(), Some(1852 - inside.len() as u64));
    assert!((after["removed_mass"].as_f64().unwrap() - mass).abs() <= 1e-9 * mass, "{v}");
    let left = before["total_mass"].as_f64().unwrap() - mass;
    assert!((after["total_mass"].as_f64().unwrap() - left).abs() <= 1e-9 * left, "{v}");
    assert_eq!((after["valid"].as_bool(), after["conservation_ok"].as_bool()), (Some(true), Some(true)));
    assert!(v["timings_us"].get("write").is_some(), "{v}");
    let written = std::fs::read_to_string(&vtu).expect("the VTU file");
    assert!(written.contains(&format!("NumberOfCells=\"{}\"", 1852 - inside.len())), "cells of the written body");
    // Without --json: the same figures as a table.
    let text = run(&["remove", liver, "--sphere", &ball]);
    assert!(text.status.success(), "{}", stderr(&text));
    let table = stdout(&text);
    assert!(
        table.contains("cells V/E/F/T  547/2833/4139/1852 -> ")
            && table.contains(&format!("/{}\n", 1852 - inside.len())),
        "{table}"
    );
    assert!(table.contains("valid true  conservation true"), "{table}");
    let _ = std::fs::remove_file(&vtu);
}

#[test]
fn ambiguity_writes_replayable_vectors_and_prints_its_table() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("topomech-cli-vectors");
    let _ = std::fs::remove_dir_all(&dir);
    let args = ["ambiguity", "kuhn:2", "--cuts", "4", "--sequences", "30", "--write-vectors", dir.to_str().unwrap()];
    let out = run(&args);
    assert!(out.status.success(), "{}", stderr(&out));
    let table = stdout(&out);
    assert!(table.starts_with("kuhn:2 (48 tets), seed 1\n") && table.contains("sequences_tried 30"), "{table}");
    // Every file written is a vector that replays: the g-map and the indexed model rerun from
    // its cuts and disagree as it records.
    let mut files: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).collect();
    files.sort();
    assert!(!files.is_empty(), "the campaign's findings were written");
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        let v: topomech::ambiguity::vector::Vector =
            serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        assert_eq!(f.file_name().unwrap().to_str().unwrap(), format!("{}.json", v.name()));
        v.check().unwrap_or_else(|e| panic!("{}: {e}", f.display()));
    }
    let bad = run(&["ambiguity", "kuhn:17"]);
    assert_eq!(bad.status.code(), Some(1));
    assert!(stderr(&bad).contains("kuhn:K needs K in 1..=16"), "{}", stderr(&bad));
    // A vector directory under a file: the error names it (before: "cannot write the output:
    // Not a directory").
    let under_file = files[0].join("sub");
    let bad = run(&[&args[..7], &[under_file.to_str().unwrap()]].concat());
    assert_eq!(bad.status.code(), Some(1));
    assert!(stderr(&bad).contains(&format!("cannot create the vector directory {}", under_file.display())));
    // A sequence of no cut changes nothing, so it cannot be a pair: refused (before, every
    // empty sequence counted as a "skeleton_unchanged" pair).
    let bad = run(&["ambiguity", "kuhn:1", "--cuts", "1,0", "--sequences", "2"]);
    assert_eq!(bad.status.code(), Some(2), "{}", stderr(&bad));
    assert!(stderr(&bad).contains("a sequence needs at least 1 cut"), "{}", stderr(&bad));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn tear_splits_stressed_vertices_and_keeps_mass_stiffness_and_the_map_laws() {
    let liver = "data/liver_547_v22.msh";
    let tear = |threshold: &str| {
        let out = run(&["tear", liver, "--threshold", threshold, "--steps", "3", "--json"]);
        assert!(out.status.success(), "{}", stderr(&out));
        serde_json::from_str::<serde_json::Value>(&stdout(&out)).expect("one JSON object")
    };
    // Every stressed vertex is over a zero threshold: faces are dissociated, the body keeps all
    // its tets, its mass and its summed stiffness (Kirchhoff), and every dissociated inner face
    // leaves two boundary faces.
    let v = tear("0");
    let (b, a) = (&v["before"], &v["after"]);
    let faces = v["cut_faces"].as_u64().unwrap();
    assert!(faces > 0, "{v}");
    assert!(a["vertices"].as_u64() > b["vertices"].as_u64(), "{v}");
    assert_eq!(a["volumes"], b["volumes"]);
    assert_eq!(a["boundary_faces"].as_u64(), Some(b["boundary_faces"].as_u64().unwrap() + 2 * faces));
    for k in ["total_mass", "stiffness_sum"] {
        let (x, y) = (b[k].as_f64().unwrap(), a[k].as_f64().unwrap());
        assert!((x - y).abs() <= 1e-12 * x, "{k}: {x} -> {y}");
    }
    assert_eq!((a["valid"].as_bool(), a["conservation_ok"].as_bool()), (Some(true), Some(true)));
    assert!(v["timings_us"].get("tear").is_some() && v["timings_us"].get("steps").is_some(), "{v}");
    // No vertex is that stressed: nothing is torn and the body is as it was.
    let v = tear("1e30");
    assert_eq!(v["cut_faces"], 0);
    assert_eq!(v["after"], v["before"]);
}

#[test]
fn ambiguity_subdivide_reports_the_mixed_campaign_and_rejects_a_bad_probability() {
    let o = run(&["ambiguity", "kuhn:1", "--cuts", "2", "--sequences", "3", "--subdivide", "0.5", "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("one JSON object");
    let m = &v["subdivide"];
    assert_eq!(m["probability"], 0.5);
    assert_eq!(m["sequences_tried"], 3);
    let k = &m["per_k"][0];
    assert_eq!(k["k"], 2);
    assert_eq!(k["level_law_broken"], 0);
    assert_eq!(k["gmap_invalid"], 0);
    assert_eq!(k["first_moment_moved"], 0);
    let ops = k["cuts"].as_u64().unwrap() + k["subdivisions"].as_u64().unwrap() + k["refused"].as_u64().unwrap();
    assert_eq!(ops, 6, "3 sequences of 2 ops on a cube with glued faces left");
    let bad = run(&["ambiguity", "kuhn:1", "--subdivide", "1.5"]);
    assert!(!bad.status.success());
    assert!(stderr(&bad).contains("not a probability"), "{}", stderr(&bad));
}
