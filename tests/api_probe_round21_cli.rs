//! Round 21, acceptance audit, findings 181–186: the CLI's blow-up message names a file node tag
//! and a 1-based step (181), a pin region that pins nothing is refused (182), `refine` reports one
//! count per requested level (183), the VTU of `remove`/`cut`/`tear` holds only live vertices (184),
//! `cut --sweep` alone gets a true usage message (185), and the cut reports give the mass of each
//! component (186).

mod cli_common;

use std::path::Path;

use cli_common::{fresh_dir, run_in, text};
use serde_json::Value;

const MESH: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/data/liver_547_v22.msh");

fn json(out: &std::process::Output) -> Value {
    assert!(out.status.success(), "failed: {}", text(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{e}: {}", text(&out.stdout)))
}

fn mesh() -> topomech::mesh::TetMesh {
    topomech::io::read_mesh(Path::new(MESH)).unwrap()
}

/// The smallest and largest coordinate `axis` of the mesh's points.
fn range(axis: usize) -> (f64, f64) {
    mesh().points.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(p[axis]), hi.max(p[axis])))
}

/// `(step, steps, tag)` of a blow-up message "… in step S of N … file node tag T …".
fn blow_up(stderr: &str) -> (u64, u64, u64) {
    let after = |key: &str| -> &str { stderr.split(key).nth(1).unwrap_or_else(|| panic!("no {key:?} in {stderr:?}")) };
    let word = |s: &str, k: usize| -> u64 {
        let w = s.split_whitespace().nth(k).unwrap();
        w.trim_matches(|c: char| !c.is_ascii_digit()).parse().unwrap_or_else(|_| panic!("{w:?} in {stderr:?}"))
    };
    let step = after("in step ");
    (word(step, 0), word(step, 2), word(after("file node tag "), 0))
}

/// Finding 181: explicit Euler at dt = 0.01 blows up on the liver. The error names the same vertex, as a
/// node tag of the file, and the same step whatever the point order (the slot changed with each
/// order: 365, 2, 83); the step counts from 1 as the progress bar does, so exactly S − 1 steps run
/// cleanly and the S-th fails.
#[test]
fn a_blow_up_names_the_file_node_tag_and_a_one_based_step() {
    let dir = fresh_dir("round21_cli", "blow_up");
    let base = ["simulate", MESH, "--steps", "100", "--integrator", "euler", "--dt", "0.01"];
    let mut seen = Vec::new();
    for order in [&[][..], &["--rcm-order"][..], &["--spatial-order"][..], &["--spatial-order", "--rcm-order"][..]] {
        let out = run_in(&dir, &[&base[..], order].concat());
        assert_eq!(out.status.code(), Some(1), "{order:?} did not fail: {}", text(&out.stdout));
        let stderr = text(&out.stderr);
        assert!(!stderr.contains("vertex slot"), "{order:?}: {stderr}");
        seen.push(blow_up(&stderr));
    }
    assert!(seen.windows(2).all(|w| w[0] == w[1]), "the orders disagree: {seen:?}");
    let (step, steps, tag) = seen[0];
    assert_eq!(steps, 100);
    assert!(mesh().node_tags.contains(&tag), "tag {tag} is not a node tag of the file");
    assert!(step >= 2, "blew up in step {step}");
    let clean = (step - 1).to_string();
    let out = run_in(&dir, &["simulate", MESH, "--steps", &clean, "--integrator", "euler", "--dt", "0.01", "--json"]);
    assert_eq!(json(&out)["steps"].as_u64(), Some(step - 1));
    let fail = step.to_string();
    let out = run_in(&dir, &["simulate", MESH, "--steps", &fail, "--integrator", "euler", "--dt", "0.01"]);
    assert_eq!(blow_up(&text(&out.stderr)), (step, step, tag));
}

/// Finding 181 for `tear`: its blow-up names a file node tag and the step of `--steps` it happened in.
#[test]
fn a_tear_blow_up_names_the_file_node_tag() {
    let dir = fresh_dir("round21_cli", "tear_blow_up");
    let out = run_in(&dir, &["tear", MESH, "--threshold", "1e300", "--steps", "200", "--dt", "0.05"]);
    assert_eq!(out.status.code(), Some(1), "did not fail: {}", text(&out.stdout));
    let stderr = text(&out.stderr);
    assert!(!stderr.contains("vertex slot"), "{stderr}");
    let (step, steps, tag) = blow_up(&stderr);
    assert!(step >= 1 && step <= steps && steps == 200, "{stderr}");
    assert!(mesh().node_tags.contains(&tag), "tag {tag} is not a node tag of the file");
}

/// Finding 182: a `--pin-below` bound under the whole body and a `--pin-z` under it pin no vertex: refused
/// (exit 1, the flag, the value and the body's range on that axis named, no frame written), while
/// the lowest coordinate itself pins a vertex and runs.
#[test]
fn a_pin_region_that_pins_nothing_is_refused() {
    let dir = fresh_dir("round21_cli", "pin_nothing");
    let (x_lo, x_hi) = range(0);
    let out = run_in(&dir, &["simulate", MESH, "--steps", "3", "--pin-below", "x=-100", "--out", "frames"]);
    assert_eq!(out.status.code(), Some(1), "accepted: {}", text(&out.stdout));
    let stderr = text(&out.stderr);
    for part in ["--pin-below", "-100", &format!("{x_lo}"), &format!("{x_hi}")] {
        assert!(stderr.contains(part), "{part:?} not in {stderr:?}");
    }
    assert!(!dir.join("frames").exists(), "frames written for a refused run");
    let at_lo = format!("x={x_lo}");
    let out = run_in(&dir, &["simulate", MESH, "--steps", "3", "--pin-below", &at_lo]);
    assert!(out.status.success(), "{at_lo}: {}", text(&out.stderr));
    assert!(text(&out.stdout).contains(", 1 fixed)") || !text(&out.stdout).contains(" 0 fixed)"));

    let (z_lo, z_hi) = range(2);
    let out = run_in(&dir, &["tear", MESH, "--threshold", "2", "--steps", "3", "--pin-z", "-100", "--out", "t.vtu"]);
    assert_eq!(out.status.code(), Some(1), "accepted: {}", text(&out.stdout));
    let stderr = text(&out.stderr);
    for part in ["--pin-z", "-100", &format!("{z_lo}"), &format!("{z_hi}")] {
        assert!(stderr.contains(part), "{part:?} not in {stderr:?}");
    }
    assert!(!dir.join("t.vtu").exists());
    let at_lo = z_lo.to_string();
    let out = run_in(&dir, &["tear", MESH, "--threshold", "2", "--steps", "3", "--pin-z", &at_lo, "--json"]);
    json(&out);
}

/// Finding 183: `tets_per_level` has one entry per level 0..=L, as `subdivided_per_level` does, and each
/// level has 7 more tets per tet subdivided at it (1 → 8); an empty zone repeats the input's count
/// at every level and says so on stderr, a zone with tets does not warn.
#[test]
fn refine_reports_every_requested_level() {
    let dir = fresh_dir("round21_cli", "refine_levels");
    let tets = mesh().tets.len();
    for (around, radius, levels, empty) in
        [("100,100,100", "0", "3", true), ("-2.2,3.2,0.6", "0.3", "2", false), ("100,100,100", "1", "1", true)]
    {
        let args = ["refine", MESH, "--around", around, "--radius", radius, "--levels", levels, "--json"];
        let out = run_in(&dir, &args);
        let v = json(&out);
        let per: Vec<u64> = v["tets_per_level"].as_array().unwrap().iter().map(|x| x.as_u64().unwrap()).collect();
        let sub: Vec<u64> = v["subdivided_per_level"].as_array().unwrap().iter().map(|x| x.as_u64().unwrap()).collect();
        let l: usize = levels.parse().unwrap();
        assert_eq!((per.len(), sub.len()), (l + 1, l + 1), "{args:?}: {v}");
        assert_eq!(per[0], tets as u64);
        for i in 1..=l {
            assert_eq!(per[i], per[i - 1] + 7 * sub[i], "level {i} of {args:?}: {v}");
        }
        assert_eq!(*per.last().unwrap(), v["volumes"].as_u64().unwrap());
        let warned = text(&out.stderr).contains("warning");
        assert_eq!(warned, empty, "{args:?}: stderr {:?}", text(&out.stderr));
        assert_eq!(sub.iter().all(|&n| n == 0), empty);
    }
}

/// The points, the cells and the `velocity` array of an ASCII VTU written by topomech.
fn read_vtu(path: &Path) -> (Vec<[f64; 3]>, Vec<[usize; 4]>, usize) {
    let xml = std::fs::read_to_string(path).unwrap();
    let array = |name: &str| -> Vec<&str> {
        let start = xml.find(&format!("Name=\"{name}\"")).unwrap_or_else(|| panic!("no {name}"));
        let body = &xml[start..];
        let body = &body[body.find('>').unwrap() + 1..body.find("</DataArray>").unwrap()];
        body.split_whitespace().collect()
    };
    let num = |s: &&str| s.parse::<f64>().unwrap();
    let points: Vec<[f64; 3]> = array("Points").chunks(3).map(|c| [num(&c[0]), num(&c[1]), num(&c[2])]).collect();
    let cells = array("connectivity").chunks(4).map(|c| std::array::from_fn(|k| c[k].parse().unwrap())).collect();
    let declared: usize = xml.split("NumberOfPoints=\"").nth(1).unwrap().split('"').next().unwrap().parse().unwrap();
    assert_eq!(declared, points.len());
    (points, cells, array("velocity").len() / 3)
}

/// Finding 184: the VTU of `remove`, `cut` and `tear` has exactly `after.vertices` points, every one used
/// by a cell, `after.volumes` cells and one velocity per point. A removal does not move the body,
/// so its points are points of the file and its cells the file's tets that were kept.
#[test]
fn cut_outputs_write_only_live_vertices() {
    let dir = fresh_dir("round21_cli", "live_vtu");
    let runs: [&[&str]; 3] = [
        &["remove", MESH, "--sphere", "-2.2,3.2,0.6,1"],
        &["cut", MESH, "--plane", "0,0,0,1,0.3,0.2"],
        &["tear", MESH, "--threshold", "1", "--steps", "200"],
    ];
    let m = mesh();
    for args in runs {
        let out = run_in(&dir, &[args, &["--out", "o.vtu", "--json"]].concat());
        let v = json(&out);
        let (points, cells, velocities) = read_vtu(&dir.join("o.vtu"));
        let after = &v["after"];
        assert_eq!(points.len() as u64, after["vertices"].as_u64().unwrap(), "{args:?}");
        assert_eq!(cells.len() as u64, after["volumes"].as_u64().unwrap(), "{args:?}");
        assert_eq!(velocities, points.len(), "{args:?}");
        let mut used = vec![false; points.len()];
        cells.iter().flatten().for_each(|&p| used[p] = true);
        assert!(used.iter().all(|&u| u), "{args:?}: an unreferenced point");
        if args[0] == "remove" {
            let file: std::collections::HashSet<[u64; 3]> = m.points.iter().map(|p| p.map(f64::to_bits)).collect();
            assert!(points.iter().all(|p| file.contains(&p.map(f64::to_bits))), "a point not in the file");
            let mut tets: std::collections::HashSet<Vec<[u64; 3]>> = m
                .tets
                .iter()
                .map(|t| {
                    let mut c: Vec<[u64; 3]> = t.iter().map(|&p| m.points[p as usize].map(f64::to_bits)).collect();
                    c.sort_unstable();
                    c
                })
                .collect();
            for c in &cells {
                let mut key: Vec<[u64; 3]> = c.iter().map(|&p| points[p].map(f64::to_bits)).collect();
                key.sort_unstable();
                assert!(tets.remove(&key), "cell {c:?} is not a tet of the file (or is written twice)");
            }
        }
    }
}

/// Finding 185: `--sweep` without `--polyline` is a usage error that asks for `--polyline` and does not
/// also demand `--plane` (the two exclude each other); no surface at all asks for one of the two;
/// both together are refused.
#[test]
fn cut_usage_errors_name_the_right_arguments() {
    let dir = fresh_dir("round21_cli", "cut_usage");
    let out = run_in(&dir, &["cut", MESH, "--sweep", "0,0,5"]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = text(&out.stderr);
    assert!(stderr.contains("--polyline"), "{stderr}");
    assert!(!stderr.contains("--plane <PLANE>\n"), "--plane demanded as well: {stderr}");
    let usage = stderr.lines().find(|l| l.starts_with("Usage:")).unwrap_or("");
    assert!(!(usage.contains("--plane") && usage.contains("--polyline") && !usage.contains('|')), "{stderr}");
    let out = run_in(&dir, &["cut", MESH]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = text(&out.stderr);
    assert!(stderr.contains("--plane") && stderr.contains("--polyline") && stderr.contains('|'), "{stderr}");
    let both = ["cut", MESH, "--plane", "0,0,0,1,0,0", "--polyline", "0,0,0;1,0,0", "--sweep", "0,0,1"];
    let out = run_in(&dir, &both);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    // A --sweep beside --plane used to be dropped without a word (clap waived its requirement of
    // --polyline, which the group excludes): now refused.
    let out = run_in(&dir, &["cut", MESH, "--plane", "0,0,0,1,0,0", "--sweep", "0,0,5"]);
    assert_eq!(out.status.code(), Some(2), "--plane with --sweep accepted: {}", text(&out.stdout));
    assert!(text(&out.stderr).contains("--sweep"), "{}", text(&out.stderr));
    let out = run_in(&dir, &["cut", MESH, "--polyline", "-3,0,1;3,0,1", "--sweep", "0,0,-2", "--json"]);
    json(&out);
}

/// Finding 186: `before` and `after` give each component's mass, ascending, one per component, summing to
/// `total_mass` (1e-12 relative), and equal to what the library's `cut::components` finds on the
/// same cut; a removal's parts sum to the mass before less the mass removed.
#[test]
fn cut_reports_give_the_mass_of_each_component() {
    let dir = fresh_dir("round21_cli", "component_masses");
    let runs: [&[&str]; 3] = [
        &["cut", MESH, "--plane", "0,0,0,1,0.3,0.2", "--json"],
        &["remove", MESH, "--sphere", "-2.2,3.2,0.6,1", "--json"],
        &["tear", MESH, "--threshold", "1", "--steps", "200", "--json"],
    ];
    for args in runs {
        let v = json(&run_in(&dir, args));
        for side in ["before", "after"] {
            let s = &v[side];
            let masses: Vec<f64> = s["component_masses"]
                .as_array()
                .unwrap_or_else(|| panic!("{args:?} {side}: no component_masses in {s}"))
                .iter()
                .map(|m| m.as_f64().unwrap())
                .collect();
            assert_eq!(masses.len() as u64, s["components"].as_u64().unwrap(), "{args:?} {side}");
            assert!(masses.windows(2).all(|w| w[0] <= w[1]) && masses.iter().all(|&m| m > 0.0), "{masses:?}");
            let total = s["total_mass"].as_f64().unwrap();
            let sum: f64 = masses.iter().sum();
            assert!((sum - total).abs() <= 1e-12 * total, "{args:?} {side}: Σ {sum} vs total {total}");
        }
        if args[0] == "remove" {
            let (b, a) = (&v["before"], &v["after"]);
            let sum: f64 = a["component_masses"].as_array().unwrap().iter().map(|m| m.as_f64().unwrap()).sum();
            let expected = b["total_mass"].as_f64().unwrap() - a["removed_mass"].as_f64().unwrap();
            assert!((sum - expected).abs() <= 1e-12 * expected, "Σ {sum} vs {expected}");
        }
    }
    // The same plane cut through the library.
    use topomech::cut::{components, incise_plane, Plane};
    use topomech::mechanics::{Body, Material};
    let m = mesh();
    let (mut body, _) = Body::from_tets(&m.points, &m.tets, Material::default()).unwrap();
    incise_plane(&mut body, &Plane { point: [0.0; 3], normal: [1.0, 0.3, 0.2] }).unwrap();
    let mut lib: Vec<f64> = components(&body).iter().map(|c| c.mass).collect();
    lib.sort_by(f64::total_cmp);
    let v = json(&run_in(&dir, runs[0]));
    let cli: Vec<f64> =
        v["after"]["component_masses"].as_array().unwrap().iter().map(|m| m.as_f64().unwrap()).collect();
    assert_eq!(cli, lib);
    assert!(lib.len() >= 2, "the plane should split the liver");
}
