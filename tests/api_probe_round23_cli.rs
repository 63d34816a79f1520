//! Round 23 probing of round 22's pinched-point and pin work through the other commands
//! (findings 206, 207) and of the `.tmap` text header (210).

use std::path::{Path, PathBuf};

use topomech::store::{self, Document, Format, StoreError};
use topomech::GMap;

mod cli_common;
use cli_common::{run_in, text, write_msh};

fn fresh_dir(name: &str) -> PathBuf {
    cli_common::fresh_dir("topomech-round23-cli", name)
}

/// A 2×2×2 Kuhn cube lifted to z ∈ [5, 7], and with `unused` a last point no tet uses.
fn high_cube(dir: &Path, name: &str, unused: bool) -> String {
    let (points, tets) = topomech::generate::kuhn_cube(2);
    let mut points: Vec<[f64; 3]> = points.iter().map(|p| [p[0], p[1], p[2] + 5.0]).collect();
    if unused {
        points.push([0.0, 0.0, 100.0]);
    }
    write_msh(&dir.join(name), &points, &tets);
    name.to_string()
}

/// The velocity rows of a VTU file written by `tear --out`.
fn vtu_velocities(path: &Path) -> Vec<[f64; 3]> {
    let vtu = std::fs::read_to_string(path).unwrap();
    let start = vtu.find("Name=\"velocity\"").expect("a velocity array");
    let body = &vtu[start..];
    let body = &body[body.find('>').unwrap() + 1..body.find("</DataArray>").unwrap()];
    body.lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect()
}

/// Finding 206: `tear` took its pin range from every vertex slot, and an unreferenced point's
/// slot rests at the origin: the default pin held nothing and `--pin-z` below the body passed.
#[test]
fn f206_tear_pins_the_body_not_an_unreferenced_point() {
    let dir = fresh_dir("tear");
    for unused in [false, true] {
        let mesh = high_cube(&dir, if unused { "unused.msh" } else { "plain.msh" }, unused);
        let args = ["tear", &mesh, "--threshold", "1e30", "--steps", "100", "--dt", "1e-3", "--out", "t.vtu"];
        let out = run_in(&dir, &args);
        assert!(out.status.success(), "{}", text(&out.stderr));
        let v = vtu_velocities(&dir.join("t.vtu"));
        // The default pins the lowest 10 % of the body: its bottom layer of 9 vertices (z = 5).
        let held = v.iter().filter(|v| **v == [0.0; 3]).count();
        assert_eq!(held, 9, "unused point: {unused}: {held} vertices at rest");
        let out = run_in(&dir, &["tear", &mesh, "--threshold", "1e30", "--steps", "10", "--pin-z", "1"]);
        assert_eq!(out.status.code(), Some(1), "unused point: {unused}");
        let err = text(&out.stderr);
        assert!(err.contains("from 5 to 7"), "{err}");
    }
}

/// Two tets that meet only at point 0 (a pinched point: two map vertices there).
fn bowtie(dir: &Path) -> String {
    cli_common::write_bowtie(&dir.join("bowtie.msh"), false);
    "bowtie.msh".to_string()
}

fn json_number(json: &str, key: &str) -> f64 {
    let at = json.find(&format!("\"{key}\":")).unwrap_or_else(|| panic!("no {key} in {json}"));
    let rest = &json[at + key.len() + 3..];
    let end = rest.find([',', '}', '\n']).unwrap();
    rest[..end].trim().parse().unwrap()
}

/// Finding 207: `refine` gave the leveled map positions for the file's points only, so a
/// pinched point's extra vertex had none and every such mesh was refused ("vertex 7 has no
/// position"), whatever the zone.
#[test]
fn f207_refine_takes_a_mesh_with_a_pinched_point() {
    let dir = fresh_dir("refine");
    let mesh = bowtie(&dir);
    let cases: [(&[&str], f64); 3] = [
        (&["--around", "5,5,5", "--radius", "0.1"], 2.0),
        (&["--around", "0,0,0", "--radius", "0.5", "--levels", "2"], 128.0),
        (&["--around", "0.2,0.2,0.2", "--radius", "0.1", "--springs", "--conforming"], 9.0),
    ];
    for (extra, volumes) in cases {
        let mut args = vec!["refine", &mesh, "--json"];
        args.extend_from_slice(extra);
        let out = run_in(&dir, &args);
        assert!(out.status.success(), "{extra:?}: {}", text(&out.stderr));
        let json = text(&out.stdout);
        assert_eq!(json_number(&json, "volumes"), volumes, "{extra:?}: {json}");
        let (before, after) = (json_number(&json, "total_mass_before"), json_number(&json, "total_mass_after"));
        assert!((before - after).abs() <= 1e-12 * before, "{extra:?}: {json}");
        assert!(json.contains("\"valid\":true") && json.contains("\"mu_order_ok\":true"), "{json}");
    }
}

/// The library side of 207: positions per point extended to every vertex id.
#[test]
fn f207_per_vertex_gives_every_extra_vertex_its_points_value() {
    let tets = [[0, 1, 2, 3], [0, 4, 5, 6], [0, 7, 8, 9]];
    let (map, report) = GMap::<3>::from_tets(10, &tets).unwrap();
    let values: Vec<u32> = (0..10).map(|p| 1000 + p).collect();
    let per_vertex = report.per_vertex(&values).unwrap();
    assert_eq!(per_vertex.len(), map.cell_id_bound(0));
    for d in map.darts() {
        let id = map.vertex_id(d).0 as usize;
        let point = report.extra_vertices.iter().find(|e| e.0 as usize == id).map_or(id as u32, |e| e.1);
        assert_eq!(per_vertex[id], 1000 + point);
        assert!(tets.iter().flatten().any(|&p| p == point), "vertex {id} stands for a used point");
    }
    assert_eq!(report.extra_vertices.len(), 2);
    assert_eq!(report.per_vertex(&values[..0]), None);
    assert_eq!(report.per_vertex(&values[..9]), None, "one value short: the extra ids do not follow");
}

/// Finding 210: a `.tmap` text file that starts with a UTF-8 byte-order mark was "not a topomech
/// map file"; and the refusal of a file with a comment first quoted the comment.
#[test]
fn f210_a_byte_order_mark_is_skipped_and_bad_magic_quotes_the_first_significant_line() {
    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let doc = Document::from_map(&map);
    let plain = store::encode(&doc, Format::Text).unwrap();
    for prefix in ["\u{feff}", "\u{feff}# written on Windows\r\n", "\u{feff}\n\n"] {
        let mut bytes = prefix.as_bytes().to_vec();
        bytes.extend_from_slice(&plain);
        assert_eq!(store::decode(&bytes).unwrap(), doc, "{prefix:?}");
    }
    // Only at the start: a mark after a comment is a character of a record line.
    assert!(store::decode(format!("# c\n\u{feff}{}", text(&plain)).as_bytes()).is_err());
    match store::decode(b"# a comment first\nhello world\n") {
        Err(e @ StoreError::BadMagic { .. }) => assert!(e.to_string().contains("\"hello world\""), "{e}"),
        other => panic!("{other:?}"),
    }
}
