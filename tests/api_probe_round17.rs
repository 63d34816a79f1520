//! API probe round 17 (findings 119–121, 126 and 127 of `docs/VERIFICATION.md`); findings
//! 108–118 (render and surface) are in `api_probe_round17_render.rs`, 122–125 (spring coupling,
//! masses, refinement zones) in `api_probe_round17_subdivide.rs`. Every test states a law the code before
//! the round broke.
//!
//! - 119: `SplitMix64::below(0)` divided by zero (a panic, also in release builds).
//! - 120: `Body::unsew(0, d)` returned `Ok` and left an edge whose two ends are one vertex with
//!   its old rest length (the laws broken; under `expensive-checks` the error came after the
//!   change).
//! - 121: `simulate --steps N` and `bench step --rounds N` reserved 8·N bytes before the first
//!   step (a capacity-overflow panic for N = 2⁶⁴ − 1, an abort for 10¹²).
//! - 126: `triangle_area` of a needle whose long edge has a short component was 0 (each edge was
//!   scaled by its largest component, and the short one underflowed).
//! - 127: a leveled map with μ above its max level loaded (from parts and from a file), and
//!   `refine_around` then refined nothing and returned `Ok`.
//!
//! Also a survivor of the 35th mutation sample (`segment_distance`).

use std::io::Write;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use topomech::embedding::EmbedError;
use topomech::generate::{kuhn_cube, SplitMix64};
use topomech::mechanics::{Body, Material};

/// Finding 119: `below` is total: `below(0)` is 0 and `below(1)` is 0, with no panic.
#[test]
fn f119_below_zero_is_zero() {
    let mut rng = SplitMix64(1);
    for _ in 0..100 {
        assert_eq!(rng.below(0), 0);
        assert_eq!(rng.below(1), 0);
        assert!(rng.below(3) < 3);
    }
}

/// Finding 120: a 0-unsew of any sewn dart of a body is refused before anything changes (map,
/// attributes, version), naming the dart and its edge; so is a 1-unsew (finding 150).
#[test]
fn f120_body_refuses_a_zero_unsew_unchanged() {
    let (points, tets) = kuhn_cube(1);
    let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    let darts: Vec<_> = body.map().darts().collect();
    for &d in &darts {
        let (version, alpha0) = (body.version(), body.map().alpha::<0>(d));
        let err = body.unsew(0, d).unwrap_err();
        match &err {
            EmbedError::Refused { op, dart, source } => {
                assert_eq!((*op, *dart), ("unsew", d));
                let edge = body.map().cell_id(1, d);
                assert_eq!(format!("{source:?}"), format!("UnsewEdge {{ dart: {d:?}, edge: {edge:?} }}"));
            }
            other => panic!("dart {d}: {other}"),
        }
        assert_eq!((body.version(), body.map().alpha::<0>(d)), (version, alpha0), "dart {d} changed");
    }
    body.check().unwrap();
    // Since finding 150 a 1-unsew (it opens a tet) is refused unchanged too; 3-unsews cut.
    let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    let d = darts[0];
    let err = body.unsew(1, d).unwrap_err();
    assert!(matches!(err, EmbedError::Refused { op: "unsew", dart, .. } if dart == d), "{err}");
    assert_eq!(body.version(), 0);
    body.check().unwrap();
    body.map().validate().unwrap();
}

/// A one-tet MSH 2.2 file in a fresh directory.
fn one_tet_file(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("topomech_f121_{name}_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("one.msh");
    let mut f = std::fs::File::create(&path).unwrap();
    f.write_all(
        b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n\
          $Elements\n1\n1 4 2 0 1 1 2 3 4\n$EndElements\n",
    )
    .unwrap();
    path
}

/// Runs the CLI with `args` for up to `wait`: `None` if it is still running then (killed),
/// else its exit code and stderr.
fn run_for(args: &[&str], wait: Duration) -> Option<(Option<i32>, String)> {
    let mut child = Command::new(env!("CARGO_BIN_EXE_topomech"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while start.elapsed() < wait {
        if let Some(status) = child.try_wait().unwrap() {
            let mut err = String::new();
            std::io::Read::read_to_string(child.stderr.as_mut().unwrap(), &mut err).unwrap();
            return Some((status.code(), err));
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    None
}

/// Finding 121: a huge step or round count is a long run, not a panic or an abort before the
/// first step: the process is still stepping after 3 s (the old code died within milliseconds
/// of loading the mesh, exit 101 or SIGABRT).
#[test]
fn f121_huge_step_counts_run_instead_of_reserving() {
    let mesh = one_tet_file("steps");
    let mesh = mesh.to_str().unwrap();
    let max = u64::MAX.to_string();
    for args in [
        vec!["simulate", mesh, "--steps", &max, "--json"],
        vec!["simulate", mesh, "--steps", "1000000000000", "--json"],
        vec!["bench", "step", mesh, "--rounds", &max],
    ] {
        if let Some((code, err)) = run_for(&args, Duration::from_secs(3)) {
            panic!("{args:?} ended within 3 s with {code:?}: {err}");
        }
    }
}

/// Finding 126 (a regression of 102 and 107): a needle whose long edge has a short component
/// (2⁻⁶⁶⁵ of its largest) keeps its area; the plain ½|u × v| is exact for these corners.
#[test]
fn f126_triangle_area_of_a_needle_with_a_short_component() {
    use topomech::mesh::triangle_area;
    assert_eq!(triangle_area([0.0; 3], [1e200, 0.0, 0.0], [1e200, 1e-120, 0.0]), 0.5 * 1e200 * 1e-120);
    assert_eq!(triangle_area([0.0; 3], [1e200, 0.0, 0.0], [1e200, 1e-125, 0.0]), 0.5 * 1e200 * 1e-125);
    assert_eq!(triangle_area([0.0; 3], [1e100, 0.0, 0.0], [1e100, 1e-230, 0.0]), 0.5 * 1e100 * 1e-230);
    let a = triangle_area([1e300, 0.0, 0.0], [-1e300, 0.0, 0.0], [0.0, 1e-300, 0.0]);
    assert!((a - 1.0).abs() < 1e-15, "{a}");
    // A difference past f64::MAX beside a short leg: quartered, the area finite (1e308).
    let a = triangle_area([-1e308, 0.0, 0.0], [-1e308, 1.0, 0.0], [1e308, 0.0, 0.0]);
    assert!((a / 1e308 - 1.0).abs() < 1e-15, "{a}");
}

/// A survivor of the 35th mutation sample (`segment_distance`'s projected point with a wrong y):
/// the distance from (1, 1, −1) to the unit corner tet is the distance to the middle of its
/// edge (1, 0, 0)–(0, 1, 0), √1.5, from both orientations of the tet.
#[test]
fn tet_distance_to_an_edge_interior() {
    use topomech::subdivide::tet_distance;
    let t = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let flipped = [t[0], t[2], t[1], t[3]];
    for tet in [t, flipped] {
        let d = tet_distance([1.0, 1.0, -1.0], tet);
        assert!((d - 1.5f64.sqrt()).abs() < 1e-15, "{d}");
        let d = tet_distance([-1.0, 1.0, 1.0], tet); // nearest: the middle of (0, 1, 0)–(0, 0, 1)
        assert!((d - 1.5f64.sqrt()).abs() < 1e-15, "{d}");
    }
}

/// Finding 127: a leveled map whose μ is above its max level is refused by `from_parts`, by
/// `load_leveled` (both forms) and listed by `check_all_laws`: no operation makes one, and
/// `refine_around` skipped every such cell (`Ok` with nothing refined).
#[test]
fn f127_mu_above_the_max_level_is_refused() {
    use topomech::store::{load_leveled, save_leveled, Format};
    use topomech::subdivide::{LevelPartsError, LeveledMap};
    let (map, _) = topomech::GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let m = LeveledMap::new(map, pts);
    let dir = std::env::temp_dir().join(format!("topomech_f127_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for mu in [(1, 0, 0), (200, 200, 200)] {
        let mut parts = m.to_parts();
        for r in &mut parts.darts {
            (r.mu.edge, r.mu.face, r.mu.tet) = mu;
        }
        let err: LevelPartsError = LeveledMap::from_parts(m.map().clone(), parts).unwrap_err();
        // `LevelPartsError::MuAboveMax`, named by its message (so that this test also builds
        // against the code before the round).
        assert!(err.to_string().contains("is above the max level 0"), "μ {mu:?}: {err}");
        // Through a file: the same μ written into every level line ("l d level μa μf μt …").
        let path = dir.join("m.tmap");
        save_leveled(&m, &path, Format::Text).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let tampered: Vec<String> = text
            .lines()
            .map(|line| {
                let mut t: Vec<String> = line.split_whitespace().map(String::from).collect();
                if t.first().map(String::as_str) == Some("l") {
                    (t[3], t[4], t[5]) = (mu.0.to_string(), mu.1.to_string(), mu.2.to_string());
                    return t.join(" ");
                }
                line.to_string()
            })
            .collect();
        std::fs::write(&path, tampered.join("\n") + "\n").unwrap();
        let e = load_leveled::<3>(&path).unwrap_err().to_string();
        assert!(e.contains("above the max level"), "μ {mu:?}: {e}");
    }
}

/// Round 17's message polish: an OBJ corner with no index before its slash is named as written
/// ("/3"), not by the empty index part.
#[test]
fn obj_bad_corner_is_named_as_written() {
    let err = topomech::io::parse_obj(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 /3\n", std::path::Path::new("s.obj"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("`/3`") && err.contains("line 4"), "{err}");
}
