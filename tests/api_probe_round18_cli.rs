//! Round 18 (b), CLI findings 137–148: exit statuses when stdout fails, output errors of JSON
//! reports, FIFOs as inputs, atomic output files, negative numbers as flag values, message
//! polish and silent no-ops. Every test runs the `topomech` binary as a user would, on files it
//! writes under Cargo's temporary directory (or the fixtures of `data/`).

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

mod cli_common;

const BIN: &str = env!("CARGO_BIN_EXE_topomech");
const ROOT: &str = env!("CARGO_MANIFEST_DIR");
const BUILTIN: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/data/liver_547_v22.msh");

fn run(args: &[&str]) -> Output {
    Command::new(BIN).args(args).output().expect("the topomech binary runs")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// A fresh scratch directory of this test under Cargo's temporary directory.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("round18-cli").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A valid `.tmap`: one dart of a 1-G-map, fixed by α0 and α1.
const VALID_TMAP: &str =
    "topomech-gmap 1 1\ndarts 1 1\n0 0 0 | 0 0\nfree-darts 0\ncell-ids 0 1 0\ncell-ids 1 1 0\nend\n";

/// A `.tmap` of a 1-G-map with `n` darts whose α0 is no involution (d → d + 1 mod n): `n`
/// broken laws, a long report.
fn broken_tmap(n: usize) -> String {
    let mut s = format!("topomech-gmap 1 1\ndarts {n} {n}\n");
    for d in 0..n {
        s.push_str(&format!("{d} {} {d} | 0 0\n", (d + 1) % n));
    }
    s + "free-darts 0\ncell-ids 0 1 0\ncell-ids 1 1 0\nend\n"
}

/// Runs `args` with stdout the write end of a pipe whose reader has exited (every write gets
/// EPIPE): the exit code and stderr.
#[cfg(unix)]
fn into_a_closed_pipe(args: &[&str]) -> (Option<i32>, String) {
    let mut reader = Command::new("true").stdin(Stdio::piped()).spawn().unwrap();
    let write_end = reader.stdin.take().unwrap();
    reader.wait().unwrap();
    let out = Command::new(BIN).args(args).stdout(Stdio::from(write_end)).stderr(Stdio::piped()).output().unwrap();
    (out.status.code(), text(&out.stderr))
}

/// Runs `args` with stdout `/dev/full` (every write fails with "no space left"); `None` where
/// there is no `/dev/full`.
fn into_a_full_device(args: &[&str]) -> Option<(Option<i32>, String)> {
    let full = std::fs::OpenOptions::new().write(true).open("/dev/full").ok()?;
    let out = Command::new(BIN).args(args).stdout(Stdio::from(full)).stderr(Stdio::piped()).output().unwrap();
    Some((out.status.code(), text(&out.stderr)))
}

/// Runs `args`; if the process is still running after a minute (blocked on a FIFO, say) it is
/// killed and the test fails. The exit code and stdout + stderr.
fn run_guarded(args: &[&str], cwd: &Path) -> (Option<i32>, String) {
    let child = Command::new(BIN)
        .args(args)
        .current_dir(cwd)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let out = cli_common::wait_at_most_a_minute(child)
        .unwrap_or_else(|| panic!("{args:?} still ran after a minute: it blocks on its input"));
    (out.status.code(), text(&out.stdout) + &text(&out.stderr))
}

// ---------------------------------------------------------------------------------------------
// 137

/// Finding 137: `check` exits with the map's verdict whatever happens to stdout — a broken map
/// exits 1 into a closed pipe (it exited 0) and into a full device; a valid map whose report
/// cannot be written exits 3 (it exited 1, "laws are broken").
#[test]
fn f137_check_keeps_the_maps_verdict_when_stdout_fails() {
    let dir = scratch("f137");
    let (valid, broken) = (dir.join("valid.tmap"), dir.join("broken.tmap"));
    std::fs::write(&valid, VALID_TMAP).unwrap();
    std::fs::write(&broken, broken_tmap(2000)).unwrap();
    let (valid, broken) = (valid.to_str().unwrap(), broken.to_str().unwrap());
    assert_eq!(run(&["check", valid]).status.code(), Some(0));
    assert_eq!(run(&["check", broken]).status.code(), Some(1));
    #[cfg(unix)]
    for args in [vec!["check", broken], vec!["check", broken, "--json", "--limit", "100000"]] {
        let (code, err) = into_a_closed_pipe(&args);
        assert_eq!(code, Some(1), "{args:?}: a broken map is never 0: {err}");
    }
    #[cfg(unix)]
    {
        let (code, err) = into_a_closed_pipe(&["check", valid]);
        assert_eq!(code, Some(3), "a valid map whose report was lost: {err}");
    }
    if let Some((code, err)) = into_a_full_device(&["check", valid]) {
        assert_eq!(code, Some(3), "{err}");
        assert!(err.contains("No space left"), "{err}");
    }
    if let Some((code, err)) = into_a_full_device(&["check", broken]) {
        assert_eq!(code, Some(1), "{err}");
    }
}

// ---------------------------------------------------------------------------------------------
// 138

/// Finding 138: a JSON report that cannot be written is an output error ("cannot write the
/// output"), not "cannot encode the JSON report", whatever its size; and a large one into a
/// closed pipe ends as quietly as a small one (status 0, nothing on stderr; it was status 1).
#[test]
fn f138_a_failed_json_write_is_an_output_error() {
    let dir = scratch("f138");
    let broken = dir.join("broken.tmap");
    std::fs::write(&broken, broken_tmap(2000)).unwrap();
    let broken = broken.to_str().unwrap();
    let big = ["ambiguity", "kuhn:2", "--cuts", "1,2,3,4,5,6,7,8,9,10", "--sequences", "20", "--catalogue", "--json"];
    let out = run(&big);
    assert!(out.status.success() && out.stdout.len() > 4096, "a large report: {}", text(&out.stderr));
    for args in [&big[..], &["check", broken, "--json", "--limit", "100000"]] {
        if let Some((_, err)) = into_a_full_device(args) {
            assert!(err.contains("cannot write the output") && !err.contains("encode"), "{args:?}: {err}");
        }
    }
    #[cfg(unix)]
    {
        let (code, err) = into_a_closed_pipe(&big);
        assert_eq!((code, err.as_str()), (Some(0), ""), "a closed pipe is not reported");
    }
}

// ---------------------------------------------------------------------------------------------
// 139

/// `mkfifo PATH`; false where there is no `mkfifo`.
fn mkfifo(path: &Path) -> bool {
    Command::new("mkfifo").arg(path).status().is_ok_and(|s| s.success())
}

/// Finding 139: a named pipe (FIFO) given as an input — a mesh, a `.tmap`, a conformance
/// vector, a FIFO `*.json` in a vector directory, a FIFO where a file vector's mesh should be —
/// is refused before it is opened, with an error naming the path (every reader blocked for ever
/// in `open`). An anonymous pipe (`… | topomech info /dev/stdin`) is still read.
#[cfg(unix)]
#[test]
fn f139_fifo_inputs_are_refused_before_they_are_opened() {
    let dir = scratch("f139");
    let names = ["fifo.msh", "fifo.tmap", "fifo.json", "vectors/x.json", "root/data/liver_547_v22.msh"];
    std::fs::create_dir_all(dir.join("vectors")).unwrap();
    std::fs::create_dir_all(dir.join("root/data")).unwrap();
    for name in names {
        if !mkfifo(&dir.join(name)) {
            eprintln!("no mkfifo here: skipped");
            return;
        }
    }
    let liver_vector = format!("{ROOT}/conformance/liver_short_sequence.json");
    let cases: [(Vec<&str>, &str); 7] = [
        (vec!["info", "fifo.msh"], "fifo.msh"),
        (vec!["demo", "--mesh", "fifo.msh", "--out", "demo_out"], "fifo.msh"),
        (vec!["ambiguity", "fifo.msh", "--cuts", "1", "--sequences", "1"], "fifo.msh"),
        (vec!["check", "fifo.tmap"], "fifo.tmap"),
        (vec!["conformance", "check", "fifo.json"], "fifo.json"),
        (vec!["conformance", "check", "vectors"], "x.json"),
        (vec!["conformance", "check", &liver_vector, "--root", "root"], "liver_547_v22.msh"),
    ];
    for (args, named) in cases {
        let (code, out) = run_guarded(&args, &dir);
        assert!(matches!(code, Some(1 | 2)), "{args:?}: {code:?} {out}");
        assert!(out.contains("named pipe (FIFO)") && out.contains(named), "{args:?}: {out}");
    }
    let piped = Command::new("sh").arg("-c").arg(format!("cat '{BUILTIN}' | '{BIN}' info --json /dev/stdin")).output();
    let piped = piped.unwrap();
    assert!(piped.status.success(), "{}", text(&piped.stderr));
    assert!(text(&piped.stdout).contains("\"volumes\":1852"), "{}", text(&piped.stdout));
}

// ---------------------------------------------------------------------------------------------
// 140

/// Runs `args` under a file-size limit of one 512-byte block with SIGXFSZ ignored (a write past
/// it fails with "file too large", as on a full disk). None where `sh` cannot do that.
#[cfg(unix)]
fn with_small_file_limit(args: &[&str], cwd: &Path) -> Option<Output> {
    let quoted: Vec<String> = args.iter().map(|a| format!("'{a}'")).collect();
    let script = format!("trap '' XFSZ && ulimit -f 1 && exec '{BIN}' {}", quoted.join(" "));
    let out = Command::new("sh").arg("-c").arg(script).current_dir(cwd).output().ok()?;
    Some(out)
}

/// The contents of every file of `dir`, by name.
fn contents(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .map(|p| (p.file_name().unwrap().to_string_lossy().into_owned(), std::fs::read(&p).unwrap()))
        .collect();
    files.sort();
    files
}

/// Finding 140: a write that fails (here: past a file-size limit) leaves the earlier complete
/// file whole — the ambiguity vectors, the conformance set, a VTU file, a frame series — where
/// each was truncated at the limit; and a vector name taken by a directory is refused before
/// any vector of the run is written.
#[cfg(unix)]
#[test]
fn f140_failed_writes_leave_earlier_files_whole() {
    let dir = scratch("f140");
    let vectors = ["ambiguity", "kuhn:2", "--cuts", "3", "--sequences", "20", "--write-vectors", "vec"];
    let conformance = ["conformance", "generate", "conf", "--root", ROOT];
    let cut = ["cut", BUILTIN, "--plane", "0,0,0,1,0,0", "--out", "cut.vtu"];
    let frames = ["simulate", BUILTIN, "--steps", "2", "--frames", "2", "--out", "sim"];
    for args in [&vectors[..], &conformance, &cut, &frames] {
        let out = Command::new(BIN).args(args).current_dir(&dir).output().unwrap();
        assert!(out.status.success(), "{args:?}: {}", text(&out.stderr));
    }
    let outputs = ["vec", "conf", ".", "sim"].map(|d| dir.join(d));
    let before = outputs.clone().map(|d| contents(&d));
    assert!(before.iter().all(|files| files.iter().any(|(_, b)| b.len() > 1024)), "files past the limit");
    let catalogue = [&vectors[..], &["--catalogue"]].concat();
    for args in [&catalogue[..], &conformance, &cut, &frames] {
        let Some(out) = with_small_file_limit(args, &dir) else { return };
        assert_eq!(out.status.code(), Some(1), "{args:?}: {}", text(&out.stderr));
    }
    let after = outputs.map(|d| contents(&d));
    for (b, a) in before.iter().zip(&after) {
        let changed: Vec<&String> = b.iter().filter(|f| !a.contains(f)).map(|(n, _)| n).collect();
        assert!(changed.is_empty() && a.len() == b.len(), "changed by failed writes: {changed:?}");
    }
    // A name taken by a directory: refused before the first vector is written.
    std::fs::write(dir.join("vec/ambiguity_campaign_face_still_shared.json"), "sentinel").unwrap();
    std::fs::create_dir_all(dir.join("vec/ambiguity_2d_dual_simple_boundary.json")).unwrap();
    let out = Command::new(BIN).args(&catalogue).current_dir(&dir).output().unwrap();
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
    assert!(text(&out.stderr).contains("ambiguity_2d_dual_simple_boundary.json"), "{}", text(&out.stderr));
    assert_eq!(std::fs::read(dir.join("vec/ambiguity_campaign_face_still_shared.json")).unwrap(), b"sentinel");
}

// ---------------------------------------------------------------------------------------------
// 145

/// Finding 145: a negative number in exponent or leading-dot form (`-1e-4`, `-.5`) given as a
/// flag's value reaches that flag's own check; it was "unexpected argument '-1' found", naming
/// text the user did not type.
#[test]
fn f145_negative_numbers_in_any_form_reach_the_value_check() {
    let mesh = format!("{ROOT}/tests/fixtures/single_tet.msh");
    let cases: [(&[&str], &str); 5] = [
        (&["simulate", &mesh, "--steps", "2", "--dt", "-1e-4", "--json"], "-0.0001"),
        (&["simulate", &mesh, "--steps", "2", "--dt", "-.5", "--json"], "-0.5"),
        (&["tear", &mesh, "--threshold", "1", "--steps", "1", "--dt", "-1e-4"], "-0.0001"),
        (&["simulate", &mesh, "--steps", "2", "--young", "-1e3", "--json"], "-1000"),
        (&["bench", "step", &mesh, "--rounds", "-1e3"], "'-1e3'"),
    ];
    for (args, named) in cases {
        let out = run(args);
        let err = text(&out.stderr);
        assert!(!out.status.success(), "{args:?}");
        assert!(!err.contains("unexpected argument"), "{args:?}: {err}");
        assert!(err.contains(named), "{args:?}: {err}");
    }
    // The value check of the flag itself answered (status 1 from the run, not 2 from clap).
    assert_eq!(run(cases[0].0).status.code(), Some(1));
}

// ---------------------------------------------------------------------------------------------
// 146

/// Finding 146: a conformance file without `format` says "missing field `format`" (it said
/// `format is "null"`), an ambiguity vector is named as such, and a wrong format is quoted once
/// (it was `"\"topomech-conformance \""`).
#[test]
fn f146_conformance_format_messages_say_what_was_found() {
    let dir = scratch("f146");
    let ambiguity = std::fs::read_dir(format!("{ROOT}/tests/vectors/ambiguity")).unwrap().next().unwrap().unwrap();
    std::fs::copy(ambiguity.path(), dir.join("amb.json")).unwrap();
    std::fs::write(dir.join("array.json"), "[]").unwrap();
    std::fs::write(dir.join("nofmt.json"), "{\"version\": 1}").unwrap();
    std::fs::write(dir.join("space.json"), "{\"format\": \"topomech-conformance \", \"version\": 1}").unwrap();
    let cases = [
        ("array.json", "array.json: missing field `format`: the file holds a JSON array"),
        ("nofmt.json", "nofmt.json: missing field `format`, expected format \"topomech-conformance\""),
        ("amb.json", "this is an ambiguity vector"),
        ("space.json", "space.json: format is \"topomech-conformance \", expected format \"topomech-conformance\""),
    ];
    for (file, expected) in cases {
        let path = dir.join(file);
        let out = run(&["conformance", "check", path.to_str().unwrap()]);
        let got = text(&out.stdout);
        assert_eq!(out.status.code(), Some(2), "{file}: {got}");
        assert!(got.contains(expected) && !got.contains("null") && !got.contains("\\\""), "{file}: {got}");
    }
}

// ---------------------------------------------------------------------------------------------
// 148

/// Finding 148: what did nothing while reporting success is a usage error (status 2, naming the
/// flag): `remove` with neither `--tets` nor `--sphere`, `tear --per-step 0`, `bench step
/// --rounds 0` (it ran one round and printed "0 rounds"), `bench order --batch 0`, and
/// `ambiguity --sequences 0` (refused or run depending on the default `--cuts`).
#[test]
fn f148_silent_no_ops_are_usage_errors() {
    let mesh = format!("{ROOT}/tests/fixtures/single_tet.msh");
    let cases: [(&[&str], &str); 6] = [
        (&["remove", &mesh, "--json"], "--tets"),
        (&["tear", &mesh, "--threshold", "0", "--per-step", "0", "--steps", "1"], "--per-step"),
        (&["bench", "step", &mesh, "--rounds", "0", "--batch", "1"], "--rounds"),
        (&["bench", "order", &mesh, "--rounds", "1", "--batch", "0"], "--batch"),
        (&["ambiguity", "kuhn:1", "--sequences", "0", "--json"], "--sequences"),
        (&["ambiguity", "kuhn:2", "--sequences", "0", "--json"], "--sequences"),
    ];
    for (args, flag) in cases {
        let out = run(args);
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(flag), "{args:?}: {err}");
    }
    let out = run(&["remove", &mesh, "--tets", "0", "--json"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
}
