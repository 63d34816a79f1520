//! API probe round 20, conformance vectors (findings 173–174 of `docs/VERIFICATION.md`): every
//! test states a law of `topomech::conformance` or of `topomech conformance check` that the code
//! before the round broke (or, marked so, a guard that it keeps).
//!
//! - 173: an `incise` plane through a tet centroid was replayed with topomech's undocumented tie
//!   rule (on the plane = negative side), so a vector written by the documented rule ("strictly on
//!   opposite sides") FAILed the engine; the 1e-6 margin was checked only on generation.
//! - 174: a `refused` mismatch printed Rust Debug values (`Some(BoundaryFace)`), and the doc did
//!   not say which refusal wins when a face was dissociated and one of its tets later removed.

use std::path::{Path, PathBuf};
use std::process::Command;

use topomech::conformance::{
    generate, replay_in, ConformanceError, Expect, MeshSpec, Op, Ops, Recipe, Refusal, Step, Vector, PLANE_MARGIN,
};
use topomech::cut::Plane;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A fresh, empty directory for one test.
fn scratch(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("round20-conformance-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn recipe(name: &str, mesh: MeshSpec, ops: Vec<Op>) -> Recipe {
    Recipe {
        name: name.into(),
        description: "round 20 probe".into(),
        mesh,
        material: topomech::mechanics::Material::default().into(),
        ops: Ops::Listed(ops),
    }
}

/// `topomech conformance check FILE`: (status, stdout).
fn check_cli(file: &Path) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_topomech"))
        .args(["conformance", "check"])
        .arg(file)
        .current_dir(root())
        .output()
        .unwrap();
    (out.status.code().unwrap_or(-1), String::from_utf8_lossy(&out.stdout).into_owned())
}

/// Writes `v` as DIR/NAME.json (name = stem, so `check` can only fail on the content).
fn write(dir: &Path, v: &Vector) -> PathBuf {
    let path = dir.join(format!("{}.json", v.name));
    std::fs::write(&path, v.to_json()).unwrap();
    path
}

/// The k = 2 Kuhn cube with one `incise` step by z = `z` (normal `nz`), whose expectation is the
/// one the documented "strictly on opposite sides" rule gives for z = 0.5: nothing is cut (every
/// pair of glued tets has one centroid at z = 0.5 or both on one side), the state is the initial
/// one. Built in memory: `generate` refuses such a plane.
fn on_plane_vector(name: &str, z: f64, nz: f64) -> Vector {
    let mut v = generate(&recipe(name, MeshSpec::KuhnCube { k: 2 }, vec![])).unwrap();
    let expect: Expect = v.initial.clone();
    v.steps.push(Step { op: Op::Incise { point: [0.0, 0.0, z], normal: [0.0, 0.0, nz] }, expect });
    v
}

// ---------------------------------------------------------------------------------------------
// 173: an ambiguous incise is refused on replay, not held against the engine.

/// The reproducer of the finding: z = 0.5 passes through the centroids of bottom-layer tets (tet 1
/// is [0, 1, 10, 13], centroid z = 0.5). Replay refuses the step as an ambiguous vector naming the
/// step, the tet, the distance and the margin, before applying it — not a `Mismatch` of
/// `dissociated` (topomech's tie rule cuts 12 faces there, the documented rule none).
#[test]
fn an_incise_through_a_centroid_is_refused_on_replay_as_an_ambiguous_vector() {
    let diagonal = 12f64.sqrt(); // the k = 2 cube [0, 2]³
    for nz in [1.0, -1.0, 1e-300] {
        let v = on_plane_vector("onplane", 0.5, nz);
        let e = replay_in(&v, root()).expect_err("an on-plane incise must not replay");
        let ConformanceError::AmbiguousPlane { ref vector, step, tet, distance, margin } = e else {
            panic!("normal z {nz}: expected an ambiguous plane, got {e}");
        };
        assert_eq!((vector.as_str(), step, tet), ("onplane", Some(0), 1), "{e}");
        assert!(distance <= 1e-15, "{e}");
        assert!((margin - PLANE_MARGIN * diagonal).abs() <= 1e-18, "{e}");
        assert_eq!((e.step(), e.field()), (Some(0), None), "not a mismatch of a field: {e}");
        let text = e.to_string();
        for part in ["vector onplane, step 0", "ambiguous vector", "centroid of tet 1", "is 0e0 from", "margin 3.46"] {
            assert!(text.contains(part), "{text} should say {part:?}");
        }
        assert!(!text.contains("expected"), "{text}");
    }
    // The same with the expectation of topomech's own tie rule: refused just the same (the vector
    // is ambiguous whichever rule wrote it).
    let mut leq = on_plane_vector("onplane", 0.5, 1.0);
    leq.steps[0].expect.dissociated = vec![[1, 4]];
    assert!(matches!(replay_in(&leq, root()), Err(ConformanceError::AmbiguousPlane { step: Some(0), tet: 1, .. })));
}

/// `topomech conformance check` reports the ambiguous vector on a FAIL line that says so (not
/// "expected …, got …") with status 1, as for the other defects of a vector's content.
#[test]
fn check_reports_an_ambiguous_vector_as_such_with_status_1() {
    let d = scratch("ambiguous");
    let file = write(&d, &on_plane_vector("onplane", 0.5, 1.0));
    let (code, out) = check_cli(&file);
    assert_eq!(code, 1, "{out}");
    let first = out.lines().next().unwrap();
    assert!(first.starts_with("FAIL  "), "{out}");
    for part in ["step 0: ambiguous vector: the centroid of tet 1 is 0e0 from the incise plane", "margin"] {
        assert!(first.contains(part), "{first} should say {part:?}");
    }
    assert!(!first.contains("expected") && !first.contains("dissociated"), "{first}");
    assert!(out.contains("1 vector(s) checked, 1 failed"), "{out}");
    let _ = std::fs::remove_dir_all(&d);
}

/// Guard: a plane just outside the margin still generates and replays (k = 1: margin = 1e-6 · √3
/// ≈ 1.73e-6 < 2e-6), and replay applies exactly the margin generation applies: relative to the
/// bounding-box diagonal (k = 2: √12 · 1e-6 ≈ 3.46e-6, so 2e-6 is inside and 4e-6 outside).
#[test]
fn a_plane_just_outside_the_margin_still_replays_and_the_margin_is_relative() {
    let d = scratch("margin");
    for (k, offset, ok) in [(1, 2e-6, true), (1, -2e-6, true), (2, 4e-6, true), (2, 2e-6, false), (1, 1e-6, false)] {
        let plane = Op::Incise { point: [0.0, 0.0, 0.5 + offset], normal: [0.0, 0.0, 1.0] };
        let generated = generate(&recipe("near", MeshSpec::KuhnCube { k }, vec![plane.clone()]));
        // The same step built in memory (as another engine would write it), expectation from a
        // plane well away on the same side, so only the margin can refuse it.
        let away = Op::Incise { point: [0.0, 0.0, 0.5 + offset.signum() * 0.01], normal: [0.0, 0.0, 1.0] };
        let mut v = generate(&recipe("near", MeshSpec::KuhnCube { k }, vec![away])).unwrap();
        v.steps[0].op = plane;
        let replayed = replay_in(&v, root());
        if ok {
            let g = generated.unwrap_or_else(|e| panic!("k {k}, offset {offset:e}: {e}"));
            assert_eq!(g.steps, v.steps, "k {k}, offset {offset:e}");
            replayed.unwrap_or_else(|e| panic!("k {k}, offset {offset:e}: {e}"));
            let (code, out) = check_cli(&write(&d, &v));
            assert_eq!(code, 0, "{out}");
            assert!(out.starts_with("ok    near (1 steps)"), "{out}");
        } else {
            for e in [generated.unwrap_err(), replayed.unwrap_err()] {
                assert!(matches!(e, ConformanceError::AmbiguousPlane { step: Some(0), .. }), "k {k}: {e}");
            }
        }
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// Guard: only live tets count. On the k = 1 cube the centroids of tets 1 and 3 lie on z = 0.5;
/// once both are removed, an incision by z = 0.5 is unambiguous and generates and replays.
#[test]
fn a_removed_tet_on_the_plane_does_not_make_the_plane_ambiguous() {
    let plane = Op::Incise { point: [0.0, 0.0, 0.5], normal: [0.0, 0.0, 1.0] };
    let before = generate(&recipe("dead", MeshSpec::KuhnCube { k: 1 }, vec![plane.clone()])).unwrap_err();
    assert!(matches!(before, ConformanceError::AmbiguousPlane { tet: 1, .. }), "{before}");
    let ops = vec![Op::Remove { tet: 1 }, Op::Remove { tet: 3 }, plane];
    let v = generate(&recipe("dead", MeshSpec::KuhnCube { k: 1 }, ops)).unwrap();
    replay_in(&v, root()).unwrap();
}

/// The tie rule the doc now states is the one `Plane::positive` applies: a point on the plane is
/// on the negative side (dot = 0 is not > 0); docs/CONFORMANCE.md says so and no longer promises
/// "strictly on opposite sides" without the rule.
#[test]
fn the_tie_rule_is_documented_and_is_the_one_applied() {
    let plane = Plane { point: [0.0, 0.0, 0.5], normal: [0.0, 0.0, 1.0] };
    assert!(!plane.positive([1.0, 1.0, 0.5]));
    assert!(!Plane { normal: [0.0, 0.0, -1.0], ..plane }.positive([1.0, 1.0, 0.5]));
    let doc = std::fs::read_to_string(root().join("docs/CONFORMANCE.md")).unwrap();
    let row = doc.lines().find(|l| l.starts_with("| `incise` |")).expect("the incise row");
    for part in ["**Tie rule**", "exactly on the plane", "is on the negative side", "ambiguous vector"] {
        assert!(row.contains(part), "the incise row should say {part:?}: {row}");
    }
    assert!(!row.contains("strictly on opposite sides"), "{row}");
}

// ---------------------------------------------------------------------------------------------
// 174: refusals in the vector's vocabulary, and their precedence.

/// The chain of three tets (`chain_remove_middle`): dissociate the face of tets 0 and 1, remove
/// tet 1, dissociate the face again. Both refusals of `dissociate` apply to the last step.
fn both_refusals() -> Vector {
    let mesh = Vector::read(&root().join("conformance/chain_remove_middle.json")).unwrap().mesh;
    let again = Op::Dissociate { tets: [0, 1], face: [1, 2, 3] };
    generate(&recipe("chain", mesh, vec![again.clone(), Op::Remove { tet: 1 }, again])).unwrap()
}

/// A `refused` mismatch prints JSON values, `"boundary_face"` / `"removed_tet"` / `null`, like
/// every other field — not `Some(BoundaryFace)` — in the API and in `check`'s report.
#[test]
fn a_refused_mismatch_is_printed_in_the_vectors_vocabulary() {
    let v = both_refusals();
    let cases = [
        (2, Some(Refusal::BoundaryFace), r#"step 2: refused: expected "boundary_face", got "removed_tet""#),
        (2, None, r#"step 2: refused: expected null, got "removed_tet""#),
        (0, Some(Refusal::RemovedTet), r#"step 0: refused: expected "removed_tet", got null"#),
    ];
    let d = scratch("refused");
    for (k, want, says) in cases {
        let mut bad = v.clone();
        bad.steps[k].expect.refused = want;
        let e = replay_in(&bad, root()).expect_err("an altered refusal must not replay");
        assert_eq!((e.step(), e.field()), (Some(k), Some("refused")), "{e}");
        let text = e.to_string();
        assert!(text.ends_with(says), "{text} should end with {says:?}");
        assert!(!text.contains("Some(") && !text.contains("None"), "{text}");
        let (code, out) = check_cli(&write(&d, &bad));
        assert_eq!(code, 1, "{out}");
        assert!(out.lines().next().unwrap().ends_with(says), "{out}");
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// A face dissociated before and whose tet was then removed: `removed_tet` wins over
/// `boundary_face`, as docs/CONFORMANCE.md now states (its `dissociate` row and "Order of the
/// checks"); a malformed operation is an error of the vector before any refusal (a tear from a
/// removed tet with a zero direction is a bad operation, not `removed_tet`).
#[test]
fn the_refusal_precedence_is_the_documented_one() {
    let v = both_refusals();
    assert_eq!(v.steps[2].expect.refused, Some(Refusal::RemovedTet));
    assert_eq!(v.steps[2].expect.cells, v.steps[1].expect.cells);
    replay_in(&v, root()).unwrap();
    let d = scratch("precedence");
    let (code, out) = check_cli(&write(&d, &v));
    assert_eq!(code, 0, "{out}");
    let _ = std::fs::remove_dir_all(&d);

    let mut malformed = v.clone();
    malformed.steps[2].op = Op::Tear { tet: 1, vertex: 1, direction: [0.0; 3] };
    let e = replay_in(&malformed, root()).unwrap_err();
    assert!(matches!(e, ConformanceError::BadOp { step: Some(2), .. }), "{e}");

    let doc = std::fs::read_to_string(root().join("docs/CONFORMANCE.md")).unwrap();
    let row = doc.lines().find(|l| l.starts_with("| `dissociate` |")).expect("the dissociate row");
    assert!(row.contains("`removed_tet` wins"), "{row}");
    let order = doc.split("**Order of the checks.**").nth(1).expect("an 'Order of the checks' paragraph");
    let order = &order[..order.find("\n\n").unwrap()];
    let at = |s: &str| order.find(s).unwrap_or_else(|| panic!("{s:?} missing from: {order}"));
    assert!(at("malformed") < at("(2) `removed_tet`") && at("(2) `removed_tet`") < at("(3) `boundary_face`"));
}
