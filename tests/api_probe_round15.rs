//! API probe round 15 (findings 90– of `docs/VERIFICATION.md`): every test states a law that the
//! code before the round broke.
//!
//! - 90: a conformance vector with a key given twice was read with the last value (JSON leaves
//!   a repeated key's meaning open; a reference format must not pick one silently).
//! - 91: the human-readable `cut` and `refine` tables printed large masses with every digit
//!   (10³⁰¹ as 302 characters).
//! - 94: midpoints of finite corners were ½(a + b), ∞ where a + b overflows; the mass-coupled
//!   subdivision then refused after splitting the tet; the octahedron's diagonal was chosen on
//!   squared lengths that were all ∞.
//! - 95: child volumes that overflow made NaN masses in the bulk refinement (`Ok`), and the
//!   per-op path fell back to m/8 by accident: the two paths disagreed.
//! - 96: `topomech refine --help` and `bench order --help` showed rustdoc links.

use std::path::Path;
use std::process::Command;

use topomech::conformance::{ConformanceError, Vector};
use topomech::subdivide::{LeveledMap, TetMasses};
use topomech::{DartId, GMap};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn committed_text(name: &str) -> String {
    std::fs::read_to_string(root().join("conformance").join(format!("{name}.json"))).unwrap()
}

/// `text` with `"key": …` repeated right after its first occurrence, with `value`.
fn with_duplicate(text: &str, key: &str, value: &str) -> String {
    let needle = format!("\"{key}\":");
    let at = text.find(&needle).unwrap_or_else(|| panic!("no {key} in the vector"));
    format!("{}\"{key}\": {value}, {}", &text[..at], &text[at..])
}

/// Finding 90: a key given twice in any object of a vector (the top level, the expected
/// state, an operation) is refused with a JSON error naming the key; the vector as committed
/// still reads.
#[test]
fn a_conformance_key_given_twice_is_refused_at_any_depth() {
    let text = committed_text("single_tet_remove");
    assert!(Vector::from_json(&text, "single_tet_remove.json").is_ok());
    for (key, value) in
        [("tolerance", "1e-3"), ("total_mass", "5.0"), ("tet", "0"), ("format", "\"topomech-conformance\"")]
    {
        let twice = with_duplicate(&text, key, value);
        match Vector::from_json(&twice, "twice.json") {
            Err(ConformanceError::Json { origin, message }) => {
                assert_eq!(origin, "twice.json");
                assert!(message.contains("duplicate field") && message.contains(key), "{key}: {message}");
            }
            other => panic!("{key} given twice was not refused: {other:?}"),
        }
    }
}

fn topomech(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_topomech")).args(args).current_dir(root()).output().unwrap();
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).unwrap()
}

/// The value printed after `label` on the line that starts with it (after spaces).
fn line_after<'a>(table: &'a str, label: &str) -> &'a str {
    let line =
        table.lines().find(|l| l.trim_start().starts_with(label)).unwrap_or_else(|| panic!("no {label}: {table}"));
    line.trim_start()[label.len()..].trim()
}

/// Finding 91: the text tables print a mass of 10³⁰¹ in exponent form, short, and as the exact
/// value the JSON report gives.
#[test]
fn table_masses_are_short_and_exact_at_any_magnitude() {
    let mesh = "data/liver_547_v22.msh";
    let args = ["cut", mesh, "--plane", "0,0,0,0,0,1", "--density", "1e300"];
    let table = topomech(&args);
    let json: serde_json::Value = serde_json::from_str(&topomech(&[&args[..], &["--json"]].concat())).unwrap();
    let mass = line_after(&table, "total mass");
    assert!(mass.len() < 80, "a long mass line: {mass}");
    let before: f64 = mass.split(" -> ").next().unwrap().parse().unwrap();
    assert_eq!(before, json["before"]["total_mass"].as_f64().unwrap());
    assert!(before > 1e300);

    let refine =
        topomech(&["refine", mesh, "--around", "0,0,0", "--radius", "0.05", "--levels", "1", "--density", "1e300"]);
    let line = line_after(&refine, "total mass");
    assert!(line.len() < 100, "a long mass line: {line}");
    let after: f64 = line.split(" -> ").nth(1).unwrap().split(' ').next().unwrap().parse().unwrap();
    assert!(after > 1e300 && after.is_finite());
}

/// One tet with corners `corners`.
fn one_tet(corners: [[f64; 3]; 4]) -> LeveledMap<3> {
    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    LeveledMap::new(map, corners.to_vec())
}

/// Finding 94: a tet whose corners are finite but whose coordinate sums overflow refines to
/// finite midpoints, with its mass shared (not refused after the split).
#[test]
fn midpoints_of_finite_corners_are_finite_and_the_mass_is_shared() {
    let (o, s) = (0.7e308, 1.0e308);
    let corners = [[o; 3], [o + s, o, o], [o, o + s, o], [o, o, o + s]];
    let mut m = one_tet(corners);
    let mut masses = TetMasses { mass: vec![1.0] };
    let children = m.subdivide_tet_with_mass(DartId(0), 1, &mut masses).unwrap();
    m.check_all().unwrap();
    assert!(m.points().iter().flatten().all(|c| c.is_finite()), "{:?}", m.points());
    let shares: Vec<f64> = children.iter().map(|&c| masses.mass[m.map().cell_id(3, c).index()]).collect();
    assert!(shares.iter().all(|&x| (x - 0.125).abs() < 1e-12), "{shares:?}");
}

/// The finest tets' edges as sorted pairs of corner positions, each position divided by `scale`.
fn edges_at(m: &LeveledMap<3>, scale: f64) -> Vec<[[u64; 3]; 2]> {
    let key = |v: u32| m.points()[v as usize].map(|c| (c / scale).to_bits());
    let mut out: Vec<[[u64; 3]; 2]> = m
        .finest_tets()
        .unwrap()
        .iter()
        .flat_map(|(t, _, _)| [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)].map(|(i, j)| (t[i], t[j])))
        .map(|(a, b)| {
            let e = [key(a), key(b)];
            if e[0] <= e[1] {
                e
            } else {
                [e[1], e[0]]
            }
        })
        .collect();
    out.sort_unstable();
    out.dedup();
    out
}

/// Finding 94: the octahedron is split along its shortest diagonal at any scale: the same
/// tets at 2⁷⁰⁰ and 2⁻⁷⁰⁰ times the corners (exact scalings) as at scale 1, op by op and in bulk.
#[test]
fn the_shortest_diagonal_is_chosen_at_any_scale() {
    // Diagonal lengths² 3/4, 2/4, 6/4: one shortest, not the first.
    let unit = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let refine = |scale: f64, bulk: bool| {
        let mut m = one_tet(unit.map(|p| p.map(|c| c * scale)));
        if bulk {
            let mut masses = TetMasses { mass: vec![1.0] };
            m.refine_uniform(1, &mut masses).unwrap();
        } else {
            m.subdivide_tet(DartId(0), 1).unwrap();
        }
        m.check_all().unwrap();
        edges_at(&m, scale)
    };
    let reference = refine(1.0, false);
    assert_eq!(reference.len(), 25); // 6 · 2 halves + 12 face edges + 1 diagonal
    for scale in [2f64.powi(700), 2f64.powi(-700)] {
        for bulk in [false, true] {
            assert_eq!(refine(scale, bulk), reference, "scale {scale:e}, bulk {bulk}");
        }
    }
}

/// Finding 95: masses given by hand on a tet whose volume overflows (edge 1e110) are shared
/// into finite children that sum to the parent, the same by the bulk and the per-op paths.
#[test]
fn overflowing_child_volumes_still_share_the_mass_the_same_on_both_paths() {
    let s = 1e110;
    let corners = [[0.0; 3], [s, 0.0, 0.0], [0.0, s, 0.0], [0.0, 0.0, s]];
    let (mut bulk, mut per_op) = (one_tet(corners), one_tet(corners));
    let (mut mb, mut mp) = (TetMasses { mass: vec![1.0] }, TetMasses { mass: vec![1.0] });
    let r = bulk.refine_uniform(1, &mut mb).unwrap();
    assert_eq!((r.total_mass_before, r.total_mass_after), (1.0, 1.0));
    per_op.subdivide_tet_with_mass(DartId(0), 1, &mut mp).unwrap();
    let children = |m: &LeveledMap<3>, masses: &TetMasses| -> Vec<u64> {
        let mut v: Vec<u64> =
            m.finest_tets().unwrap().iter().map(|&(_, _, id)| masses.mass[id.index()].to_bits()).collect();
        v.sort_unstable();
        v
    };
    let (cb, cp) = (children(&bulk, &mb), children(&per_op, &mp));
    assert_eq!(cb.len(), 8);
    assert!(cb.iter().all(|&b| f64::from_bits(b).is_finite() && f64::from_bits(b) > 0.1), "{cb:?}");
    assert_eq!(cb, cp);
    assert!((cb.iter().map(|&b| f64::from_bits(b)).sum::<f64>() - 1.0).abs() < 1e-12);
}

/// Finding 96: no command's help shows a rustdoc link (`[`Type`]`).
#[test]
fn no_help_text_shows_a_rustdoc_link() {
    let help = |args: &[&str]| topomech(args);
    let top = help(&["--help"]);
    let mut commands: Vec<Vec<&str>> = top
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|&c| c != "help")
        .map(|c| vec![c])
        .collect();
    assert!(commands.len() >= 10, "{top}");
    commands.extend([
        vec!["bench", "step"],
        vec!["bench", "order"],
        vec!["conformance", "generate"],
        vec!["conformance", "check"],
    ]);
    for c in commands {
        let text = help(&[&c[..], &["--help"]].concat());
        assert!(!text.contains("[`"), "{c:?} --help: {text}");
    }
}
