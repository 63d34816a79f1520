//! API probe round 13, conformance vectors (findings 74–78 of `docs/VERIFICATION.md`): every test
//! states a law of `topomech::conformance` or of `topomech conformance check` that the code before
//! the round broke.
//!
//! - 74: an expected float of ±∞ matched anything, and a tolerance ≥ 1 every value of its sign.
//! - 75: `generate` refused nonzero normals whose unscaled length under- or overflowed, and an
//!   unused inline point widened the plane margin.
//! - 76: in-memory replay did not check `format` and `version`.
//! - 77: the `check` report printed names and paths raw (a newline forged an "ok" line), never
//!   compared `name` with the file stem, and a closed stdout ended the run with status 0.
//! - 78: a symbolic link let a vector read (and echo) a file outside the repository.

use std::mem::discriminant;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use topomech::conformance::{
    check_file, generate, generate_in, replay_in, vector_files, ConformanceError, MeshSpec, Op, Ops, Recipe, Vector,
    MAX_NAME_LEN, MAX_TOLERANCE, TOLERANCE,
};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn committed(name: &str) -> Vector {
    Vector::read(&root().join("conformance").join(format!("{name}.json"))).unwrap()
}

fn all_committed() -> Vec<Vector> {
    let files = vector_files(&root().join("conformance")).unwrap();
    assert!(!files.is_empty());
    files.iter().map(|f| Vector::read(f).unwrap()).collect()
}

/// A fresh, empty directory for one test.
fn scratch(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("round13-conformance-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn two_tets() -> MeshSpec {
    let points = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
    MeshSpec::Inline { points, tets: vec![[0, 1, 2, 3], [0, 1, 2, 4]] }
}

fn recipe(name: &str, mesh: MeshSpec, ops: Vec<Op>) -> Recipe {
    Recipe {
        name: name.into(),
        description: "round 13 probe".into(),
        mesh,
        material: topomech::mechanics::Material::default().into(),
        ops: Ops::Listed(ops),
    }
}

fn topomech(args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_topomech")).args(args).current_dir(root()).output().unwrap();
    (out.status.code().unwrap_or(-1), String::from_utf8_lossy(&out.stdout).into_owned())
}

// ---------------------------------------------------------------------------------------------
// 74: float comparisons cannot be made vacuous.

/// Every expected float, initial state and every step, set to ±∞ or NaN, is refused before the
/// replay with an error naming that step and field (∞ matched any value before: |∞ − x| ≤ tol·∞).
#[test]
fn an_expected_float_that_is_not_finite_is_refused_naming_its_step_and_field() {
    let v = committed("kuhn2_incise_planes");
    let slots = std::iter::once(None).chain((0..v.steps.len()).map(Some));
    for step in slots {
        for bad in [f64::INFINITY, f64::NEG_INFINITY, f64::NAN] {
            for field in ["total_mass", "total_stiffness", "component_masses"] {
                let mut w = v.clone();
                let e = match step {
                    None => &mut w.initial,
                    Some(k) => &mut w.steps[k].expect,
                };
                match field {
                    "total_mass" => e.total_mass = bad,
                    "total_stiffness" => e.total_stiffness = bad,
                    _ => *e.component_masses.last_mut().unwrap() = bad,
                }
                let err = replay_in(&w, root()).expect_err("a non-finite expectation must not replay");
                assert!(matches!(err, ConformanceError::NotFinite { .. }), "{step:?} {field} {bad}: {err}");
                assert_eq!((err.step(), err.field()), (step, Some(field)), "{err}");
                assert!(err.to_string().contains(field) && err.to_string().contains("not finite"), "{err}");
                if field == "component_masses" {
                    // The message names the element: the last component mass.
                    let last = e_len(&v, step) - 1;
                    assert!(err.to_string().contains(&format!("component_masses[{last}]")), "{err}");
                }
            }
        }
    }
    // The probe's vector: +∞ mass, −∞ stiffness, [∞] component masses on an in-memory vector.
    let mut v = generate(&recipe("inf", two_tets(), vec![])).unwrap();
    v.initial.total_mass = f64::INFINITY;
    v.initial.total_stiffness = f64::NEG_INFINITY;
    v.initial.component_masses = vec![f64::INFINITY];
    assert!(replay_in(&v, root()).is_err());
}

/// The number of component masses expected at `step` (`None`: the initial state).
fn e_len(v: &topomech::conformance::Vector, step: Option<usize>) -> usize {
    match step {
        None => v.initial.component_masses.len(),
        Some(k) => v.steps[k].expect.component_masses.len(),
    }
}

/// The tolerance lies in 0 ..= MAX_TOLERANCE: inside, a vector replays; outside (a tolerance of 1
/// accepted any value of the right sign) it is refused, in memory and from a file.
#[test]
fn the_tolerance_is_bounded_so_every_float_field_still_checks_something() {
    let v = committed("kuhn2_incise_planes");
    for tol in [0.0, TOLERANCE, MAX_TOLERANCE] {
        let mut w = v.clone();
        w.tolerance = tol;
        replay_in(&w, root()).unwrap_or_else(|e| panic!("tolerance {tol}: {e}"));
    }
    for tol in [MAX_TOLERANCE * (1.0 + 1e-12), 0.5, 1.0, 1e300, f64::INFINITY, f64::NAN, -1e-300, -1.0] {
        let mut w = v.clone();
        w.tolerance = tol;
        let e = replay_in(&w, root()).expect_err("a tolerance out of range must be refused");
        assert!(matches!(e, ConformanceError::Invalid { .. }) && e.to_string().contains("tolerance"), "{tol}: {e}");
        if tol.is_finite() {
            // (JSON has no ∞ or NaN: those are written as null and refused as not a number.)
            let e = Vector::from_json(&w.to_json(), "w.json").unwrap_err();
            assert!(matches!(e, ConformanceError::Invalid { .. }), "{tol}: {e}");
        }
    }
    // At the largest tolerance a float off by more than it still mismatches.
    let mut w = v.clone();
    w.tolerance = MAX_TOLERANCE;
    w.steps[0].expect.total_mass *= 1.0 + 2.0 * MAX_TOLERANCE;
    assert_eq!(replay_in(&w, root()).unwrap_err().field(), Some("total_mass"));
    // Every committed vector is inside the range.
    for v in all_committed() {
        assert!((0.0..=MAX_TOLERANCE).contains(&v.tolerance), "{}", v.name);
        v.check_fields().unwrap();
    }
}

/// The probe's file: tolerance 1, the mass ×1000, the stiffness ×10⁻⁶, a component mass of 10⁹.
/// `topomech conformance check` passed it (status 0).
#[test]
fn cli_check_fails_a_file_whose_tolerance_would_accept_anything() {
    let d = scratch("tolerance");
    let mut v = committed("single_tet_remove");
    v.tolerance = 1.0;
    v.initial.total_mass *= 1000.0;
    v.initial.total_stiffness *= 1e-6;
    v.steps[0].expect.component_masses = vec![1e9; v.steps[0].expect.component_masses.len()];
    let file = d.join(format!("{}.json", v.name));
    std::fs::write(&file, v.to_json()).unwrap();
    let (code, out) = topomech(&["conformance", "check", file.to_str().unwrap()]);
    assert_ne!(code, 0, "{out}");
    assert!(out.contains("FAIL") && out.contains("tolerance") && !out.contains("ok "), "{out}");
    let _ = std::fs::remove_dir_all(&d);
}

// ---------------------------------------------------------------------------------------------
// 75: generate's plane margin.

/// Scaling an incision normal by any positive factor changes nothing `generate` records: it
/// accepts every nonzero finite normal, as `incise_plane` and `replay` do (an unscaled √(n·n)
/// underflowed to 0 for [0, 0, 5e-324] and overflowed for [0, MAX, MAX]).
#[test]
fn generate_accepts_a_normal_of_any_nonzero_finite_length() {
    let cases: [(MeshSpec, [f64; 3], [f64; 3]); 3] = [
        (two_tets(), [0.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        (MeshSpec::KuhnCube { k: 2 }, [1.0, 1.0, 1.3], [0.0, 1.0, 1.0]),
        (MeshSpec::KuhnCube { k: 2 }, [1.0, 1.0, 1.2], [0.3, -0.2, 1.0]),
    ];
    for (mesh, point, unit) in cases {
        let expect = |normal: [f64; 3]| {
            let r = recipe("scaled", mesh.clone(), vec![Op::Incise { point, normal }]);
            let v = generate(&r).unwrap_or_else(|e| panic!("normal {normal:?}: {e}"));
            replay_in(&v, root()).unwrap();
            v.steps[0].expect.clone()
        };
        let reference = expect(unit);
        let largest = unit.iter().fold(0.0_f64, |m, c| m.max(c.abs()));
        // Scales that take the largest component to the smallest subnormal and to f64::MAX.
        for scale in [5e-324 / largest, 1e-300, 1e-160, 1e160, 1e300, f64::MAX / largest] {
            let normal = unit.map(|c| c * scale);
            if normal.iter().zip(unit).any(|(s, u)| (*s == 0.0) != (u == 0.0)) {
                continue; // a component underflowed: another direction
            }
            assert_eq!(expect(normal), reference, "normal {normal:?}");
        }
    }
    // A zero or non-finite normal is still refused.
    for normal in [[0.0; 3], [f64::NAN, 0.0, 1.0], [f64::INFINITY, 0.0, 0.0]] {
        let r = recipe("bad", two_tets(), vec![Op::Incise { point: [0.0; 3], normal }]);
        assert!(matches!(generate(&r), Err(ConformanceError::BadOp { step: Some(0), .. })), "{normal:?}");
    }
}

/// The margin is relative to the points the tets use: adding a point no tet references (here at
/// 10¹²) does not change what `generate` accepts or records.
#[test]
fn an_unused_inline_point_does_not_widen_the_plane_margin() {
    let MeshSpec::Inline { points, tets } = two_tets() else { unreachable!() };
    let ops = vec![Op::Incise { point: [0.0; 3], normal: [0.0, 0.0, 1.0] }];
    let plain = generate(&recipe("plain", two_tets(), ops.clone())).unwrap();
    for far in [[1e12; 3], [-1e12, 0.0, 0.0], [0.0, 0.0, 1e300]] {
        let mut with = points.clone();
        with.push(far);
        let padded = generate(&recipe("plain", MeshSpec::Inline { points: with, tets: tets.clone() }, ops.clone()))
            .unwrap_or_else(|e| panic!("unused point {far:?}: {e}"));
        assert_eq!((&padded.initial, &padded.steps), (&plain.initial, &plain.steps), "{far:?}");
    }
    // A plane through a centroid is still ambiguous, unused points or not.
    let mut with = points.clone();
    with.push([1e12; 3]);
    let through = vec![Op::Incise { point: [0.25, 0.25, 0.25], normal: [0.0, 0.0, 1.0] }];
    for mesh in [two_tets(), MeshSpec::Inline { points: with, tets }] {
        let e = generate(&recipe("through", mesh, through.clone())).unwrap_err();
        assert!(matches!(e, ConformanceError::AmbiguousPlane { .. }), "{e}");
    }
}

// ---------------------------------------------------------------------------------------------
// 76: in-memory replay checks what decoding checks.

/// A named change to a vector.
type Mutation = (&'static str, fn(&mut Vector));

/// For every header or field a file is refused for, the same vector in memory is refused by
/// `replay_in` with the same kind of error (format "nope" and version 99 replayed Ok).
#[test]
fn in_memory_replay_refuses_what_decoding_refuses() {
    let v = committed("two_tets_dissociate");
    let mutations: [Mutation; 7] = [
        ("format", |w| w.format = "nope".into()),
        ("empty format", |w| w.format.clear()),
        ("version 99", |w| w.version = 99),
        ("version 0", |w| w.version = 0),
        ("name", |w| w.name = "two tets".into()),
        ("tolerance", |w| w.tolerance = 1.0),
        ("material", |w| w.material.density = -1.0),
    ];
    for (what, mutate) in mutations {
        let mut w = v.clone();
        mutate(&mut w);
        let decoded = Vector::from_json(&w.to_json(), "w.json").expect_err(what);
        let replayed = replay_in(&w, root()).expect_err(what);
        assert_eq!(discriminant(&decoded), discriminant(&replayed), "{what}: {decoded} / {replayed}");
        assert!(w.check_fields().is_err(), "{what}");
    }
}

// ---------------------------------------------------------------------------------------------
// 77: the integrity of the `check` report.

/// A name is 1 to MAX_NAME_LEN characters of `A–Z a–z 0–9 _ - .`: any other is refused (when
/// decoded, replayed or generated), and the error shows it escaped, on one line.
#[test]
fn a_name_outside_the_plain_charset_is_refused_and_shown_escaped() {
    let v = committed("two_tets_dissociate");
    let long = "n".repeat(MAX_NAME_LEN + 1);
    for name in ["x\nok    everything_fine", "x\r", "x\u{1b}[2K", "a/b", "a b", "", "é", &long] {
        let mut w = v.clone();
        w.name = name.to_string();
        for e in [Vector::from_json(&w.to_json(), "w.json").unwrap_err(), replay_in(&w, root()).unwrap_err()] {
            assert!(matches!(e, ConformanceError::BadName { .. }), "{name:?}: {e}");
            assert!(!e.to_string().chars().any(char::is_control), "{name:?}: {e}");
        }
        let e = generate(&recipe(name, two_tets(), vec![])).unwrap_err();
        assert!(matches!(e, ConformanceError::BadName { .. }), "{name:?}: {e}");
    }
    for v in all_committed() {
        assert!(v.name.chars().all(|c| c.is_ascii_alphanumeric() || "_-.".contains(c)), "{}", v.name);
    }
    let mut w = v.clone();
    w.name = "n".repeat(MAX_NAME_LEN);
    w.check_fields().unwrap();
}

/// Every line of the report is a verdict ("ok    ", "FAIL  ") or the summary, one per vector:
/// neither a vector's name nor a file's name can add a line (a newline in either forged an
/// "ok    everything_fine" line before).
#[test]
fn cli_report_lines_cannot_be_forged() {
    let d = scratch("forge");
    let mut v = committed("two_tets_dissociate");
    v.steps[0].expect.cells[0] += 1; // fails
    v.name = "x\nok    everything_fine (1 steps)".into();
    std::fs::write(d.join("x.json"), v.to_json()).unwrap();
    std::fs::write(d.join("z\nok    forged_file (1 steps).json"), "{ not json").unwrap();
    let (code, out) = topomech(&["conformance", "check", d.to_str().unwrap()]);
    assert_ne!(code, 0, "{out}");
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines.len(), 3, "two verdicts and the summary: {out}");
    assert!(lines[..2].iter().all(|l| l.starts_with("FAIL  ")), "{out}");
    assert!(!lines.iter().any(|l| l.starts_with("ok")), "{out}");
    let _ = std::fs::remove_dir_all(&d);
}

/// A vector file's name is its stem: a vector that replays under another file name fails, and the
/// error names both.
#[test]
fn a_vector_whose_name_is_not_its_file_stem_fails_the_check() {
    let d = scratch("stem");
    let v = committed("single_tet_remove");
    let right = d.join(format!("{}.json", v.name));
    let wrong = d.join("everything_fine.json");
    std::fs::write(&right, v.to_json()).unwrap();
    std::fs::write(&wrong, v.to_json()).unwrap();
    assert_eq!(check_file(&right, root()).unwrap(), v);
    let e = check_file(&wrong, root()).unwrap_err();
    assert!(matches!(e, ConformanceError::NameMismatch { .. }), "{e}");
    assert!(e.to_string().contains(&v.name) && e.to_string().contains("everything_fine"), "{e}");
    let (code, out) = topomech(&["conformance", "check", d.to_str().unwrap()]);
    assert_eq!(code, 1, "{out}");
    assert!(out.contains("FAIL") && out.contains("everything_fine.json") && !out.contains("ok    everything"), "{out}");
    let _ = std::fs::remove_dir_all(&d);
}

/// `topomech conformance check DIR` with its stdout the write end of a pipe nobody reads: the
/// status is never 0 and every vector is still checked (the status is the failing vector's).
#[cfg(unix)]
fn check_into_a_closed_pipe(dir: &Path) -> (i32, String) {
    // `true` holds the only read end; once it has exited, every write gets EPIPE.
    let mut reader = Command::new("true").stdin(Stdio::piped()).spawn().unwrap();
    let write_end = reader.stdin.take().unwrap();
    reader.wait().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_topomech"))
        .args(["conformance", "check", dir.to_str().unwrap()])
        .current_dir(root())
        .stdout(Stdio::from(write_end))
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    (out.status.code().unwrap_or(-1), String::from_utf8_lossy(&out.stderr).into_owned())
}

#[cfg(unix)]
#[test]
fn a_closed_stdout_is_never_a_success_and_later_vectors_are_still_checked() {
    let d = scratch("pipe");
    let good = committed("single_tet_remove");
    std::fs::write(d.join(format!("{}.json", good.name)), good.to_json()).unwrap();
    let (code, err) = check_into_a_closed_pipe(&d);
    assert_ne!(code, 0, "all vectors passed but the report was lost: {err}");
    assert!(err.contains("report"), "{err}");
    // A failing vector after the first write: its status, not the write error's.
    let mut bad = committed("two_tets_dissociate");
    bad.steps[0].expect.cells[0] += 1;
    std::fs::write(d.join(format!("{}.json", bad.name)), bad.to_json()).unwrap();
    let (code, err) = check_into_a_closed_pipe(&d);
    assert_eq!(code, 1, "the later vector fails: {err}");
    let _ = std::fs::remove_dir_all(&d);
}

// ---------------------------------------------------------------------------------------------
// 78: nothing outside the repository is read.

/// A mesh path that resolves through a symbolic link to a place outside the root is refused
/// before anything is read (the error does not echo the file); links that stay inside are followed.
#[cfg(unix)]
#[test]
fn a_mesh_path_through_a_symlink_out_of_the_root_is_not_read() {
    use std::os::unix::fs::symlink;
    let base = scratch("symlink");
    let (repo, outside) = (base.join("repo"), base.join("outside"));
    std::fs::create_dir_all(repo.join("real")).unwrap();
    std::fs::create_dir_all(&outside).unwrap();
    let liver = std::fs::read(root().join("data/liver_547_v22.msh")).unwrap();
    std::fs::write(outside.join("liver_547_v22.msh"), &liver).unwrap();
    std::fs::write(outside.join("secret.msh"), "TOPSECRET-7f3a line one\nline two\n").unwrap();
    std::fs::write(repo.join("real/liver_547_v22.msh"), &liver).unwrap();
    symlink(&outside, repo.join("data")).unwrap();
    symlink(repo.join("real"), repo.join("alias")).unwrap();
    symlink(outside.join("secret.msh"), repo.join("real/secret_link.msh")).unwrap();

    let v = committed("liver_short_sequence");
    let MeshSpec::File { points, tets, .. } = v.mesh.clone() else { panic!("a file vector") };
    let with = |path: &str| {
        let mut w = v.clone();
        w.mesh = MeshSpec::File { path: path.into(), points, tets };
        w
    };
    for path in ["data/liver_547_v22.msh", "data/secret.msh", "real/secret_link.msh", "data/missing.msh"] {
        let e = replay_in(&with(path), &repo).expect_err(path);
        assert!(matches!(e, ConformanceError::OutsideRoot { .. }), "{path}: {e}");
        assert!(!e.to_string().contains("TOPSECRET"), "{path}: {e}");
        let r = recipe("outside", with(path).mesh, vec![]);
        assert!(matches!(generate_in(&r, &repo), Err(ConformanceError::OutsideRoot { .. })), "{path}");
    }
    // Inside the root: a plain path, a path through a link to a directory of the root, and a root
    // given through a link.
    replay_in(&with("real/liver_547_v22.msh"), &repo).unwrap();
    replay_in(&with("alias/liver_547_v22.msh"), &repo).unwrap();
    symlink(&repo, base.join("repo_link")).unwrap();
    replay_in(&with("alias/liver_547_v22.msh"), &base.join("repo_link")).unwrap();
    let e = replay_in(&with("real/missing.msh"), &repo).unwrap_err();
    assert!(matches!(e, ConformanceError::Mesh { .. }) && e.to_string().contains("missing.msh"), "{e}");
    let _ = std::fs::remove_dir_all(&base);
}
