//! Round 19's fixes of file writing, `.tmap` reading and list-valued options (findings 156–160 of
//! docs/VERIFICATION.md), through the store's public functions and the binary:
//! - 156: the atomic writer follows a symbolic link (the link stays, its target is written) and
//!   keeps the old file's mode and owner; a target that does not open for writing is refused
//!   before anything is written;
//! - 157: a target name of 250–255 bytes gets a temporary (the temporary's name is short);
//! - 158: a writable file in a directory that takes no new file is written in place, and a new
//!   file there is refused naming the directory;
//! - 159: `.tmap` tokens are separated by ASCII spaces and tabs only, lines end with LF or CRLF;
//! - 160: negative values of `--cuts`, `--pin` and `--tets` reach their own value checks.
//!
//! The tests run as root here: a read-only file or directory does not stop root, so the refusals
//! are exercised with the immutable flag (`chattr +i`, which stops root too); where the system
//! does not allow it (not root, a file system without the flag) those parts are skipped.

mod cli_common;

use std::os::unix::fs::{MetadataExt, PermissionsExt};
use std::path::{Path, PathBuf};
use std::process::Command;

use cli_common::{fresh_dir, run_in, text, write_msh};
use topomech::store::{self, Document, Format, StoreError, Where};
use topomech::GMap;

const GROUP: &str = "api_probe_round19_io";

/// A one-unit Kuhn cube (8 points, 6 tets) as `cube.msh` in `dir`.
fn cube(dir: &Path) -> PathBuf {
    let (points, tets) = topomech::generate::kuhn_cube(1);
    let path = dir.join("cube.msh");
    write_msh(&path, &points, &tets);
    path
}

/// `topomech cut cube.msh … --out OUT` in `dir`: (exit code, stderr).
fn cut_to(dir: &Path, out: &str) -> (Option<i32>, String) {
    cube(dir);
    let o = run_in(dir, &["cut", "cube.msh", "--plane", "0.5,0.5,0.5,1,0,0", "--out", out]);
    (o.status.code(), text(&o.stderr))
}

fn mode(path: &Path) -> u32 {
    std::fs::metadata(path).unwrap().permissions().mode() & 0o7777
}

fn set_mode(path: &Path, mode: u32) {
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(mode)).unwrap();
}

/// Names in `dir` starting with a dot (the writer's temporaries).
fn hidden(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.'))
        .collect()
}

/// The immutable flag on a file or directory until dropped: no one, root included, may then
/// write the file or create a file in the directory. `None` where the system refuses the flag.
struct Immutable(PathBuf);

impl Immutable {
    fn set(path: &Path) -> Option<Immutable> {
        let ok = Command::new("chattr").arg("+i").arg(path).output().is_ok_and(|o| o.status.success());
        let flag = ok.then(|| Immutable(path.to_path_buf()));
        // Effective only if even this process can no longer create a file in it / write it.
        let probe = if path.is_dir() {
            std::fs::write(path.join("probe"), b"x").is_ok()
        } else {
            std::fs::OpenOptions::new().append(true).open(path).is_ok()
        };
        if flag.is_none() || probe {
            eprintln!("skipped: the immutable flag is not available or not effective on {}", path.display());
            return None;
        }
        flag
    }
}

impl Drop for Immutable {
    fn drop(&mut self) {
        let _ = Command::new("chattr").arg("-i").arg(&self.0).output();
    }
}

#[test]
fn f156_a_symlinked_target_is_written_through_the_link() {
    let dir = fresh_dir(GROUP, "f156_link");
    std::fs::write(dir.join("real.bin"), b"old").unwrap();
    std::os::unix::fs::symlink("real.bin", dir.join("link.bin")).unwrap();
    std::os::unix::fs::symlink("link.bin", dir.join("chain.bin")).unwrap();
    store::write_atomically(&dir.join("chain.bin"), b"new").unwrap();
    for link in ["link.bin", "chain.bin"] {
        assert!(std::fs::symlink_metadata(dir.join(link)).unwrap().file_type().is_symlink(), "{link} replaced");
    }
    assert_eq!(std::fs::read(dir.join("real.bin")).unwrap(), b"new");

    // A link into another directory: the temporary goes beside the target, which is written.
    std::fs::create_dir(dir.join("sub")).unwrap();
    std::fs::write(dir.join("sub/far.bin"), b"old").unwrap();
    std::os::unix::fs::symlink("sub/far.bin", dir.join("far.bin")).unwrap();
    store::write_atomically(&dir.join("far.bin"), b"far").unwrap();
    assert_eq!(std::fs::read(dir.join("sub/far.bin")).unwrap(), b"far");
    assert!(std::fs::symlink_metadata(dir.join("far.bin")).unwrap().file_type().is_symlink());

    // A dangling link: its target is created, as `File::create` would.
    std::os::unix::fs::symlink("made.bin", dir.join("dangling.bin")).unwrap();
    store::write_atomically(&dir.join("dangling.bin"), b"made").unwrap();
    assert_eq!(std::fs::read(dir.join("made.bin")).unwrap(), b"made");
    assert!(std::fs::symlink_metadata(dir.join("dangling.bin")).unwrap().file_type().is_symlink());

    // A loop is refused, naming the path asked for.
    std::os::unix::fs::symlink("loop_b", dir.join("loop_a")).unwrap();
    std::os::unix::fs::symlink("loop_a", dir.join("loop_b")).unwrap();
    let e = store::write_atomically(&dir.join("loop_a"), b"x").unwrap_err();
    assert!(matches!(&e, StoreError::Io { path, .. } if path.ends_with("loop_a")), "{e}");

    // Through the binary (VTU output): the link stays, its target gets the frame.
    std::fs::write(dir.join("real.vtu"), b"old").unwrap();
    std::os::unix::fs::symlink("real.vtu", dir.join("link.vtu")).unwrap();
    let (code, err) = cut_to(&dir, "link.vtu");
    assert_eq!(code, Some(0), "{err}");
    assert!(std::fs::symlink_metadata(dir.join("link.vtu")).unwrap().file_type().is_symlink());
    assert!(std::fs::read_to_string(dir.join("real.vtu")).unwrap().contains("<VTKFile"));
    assert!(hidden(&dir).is_empty() && hidden(&dir.join("sub")).is_empty(), "temporaries left");
}

#[test]
fn f156_the_old_files_mode_and_owner_are_kept() {
    let dir = fresh_dir(GROUP, "f156_mode");
    for m in [0o600, 0o640, 0o444, 0o755] {
        let path = dir.join(format!("m{m:o}.bin"));
        std::fs::write(&path, b"old").unwrap();
        set_mode(&path, m);
        // Root may write a 0444 file (as it may open it for writing); a user could not.
        store::write_atomically(&path, b"new").unwrap();
        assert_eq!((mode(&path), std::fs::read(&path).unwrap()), (m, b"new".to_vec()), "{}", path.display());
    }
    // A .tmap save keeps it too.
    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let tmap = dir.join("private.tmap");
    store::save_map(&map, &tmap, Format::Text).unwrap();
    set_mode(&tmap, 0o600);
    store::save_map(&map, &tmap, Format::Binary).unwrap();
    assert_eq!(mode(&tmap), 0o600);

    // The owner and group, where this process may give a file away (root).
    let given = dir.join("given.bin");
    std::fs::write(&given, b"old").unwrap();
    if std::os::unix::fs::chown(&given, Some(65534), Some(65534)).is_ok() {
        store::write_atomically(&given, b"new").unwrap();
        let m = std::fs::metadata(&given).unwrap();
        assert_eq!((m.uid(), m.gid()), (65534, 65534));
    }

    // Through the binary: a private VTU stays private.
    std::fs::write(dir.join("priv.vtu"), b"old").unwrap();
    set_mode(&dir.join("priv.vtu"), 0o600);
    let (code, err) = cut_to(&dir, "priv.vtu");
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(mode(&dir.join("priv.vtu")), 0o600);
    assert!(std::fs::read_to_string(dir.join("priv.vtu")).unwrap().contains("<VTKFile"));
    assert!(hidden(&dir).is_empty(), "temporaries left: {:?}", hidden(&dir));
}

#[test]
fn f156_a_target_that_does_not_open_for_writing_is_refused_before_writing() {
    let dir = fresh_dir(GROUP, "f156_refused");
    let path = dir.join("locked.vtu");
    std::fs::write(&path, b"old").unwrap();
    let Some(_flag) = Immutable::set(&path) else { return };
    let e = store::write_atomically(&path, b"new").unwrap_err();
    let message = e.to_string();
    assert!(matches!(&e, StoreError::Io { path: p, .. } if *p == path), "{message}");
    assert!(message.contains("cannot be opened for writing") && message.contains("nothing was written"), "{message}");
    let (code, err) = cut_to(&dir, "locked.vtu");
    assert_eq!(code, Some(1));
    assert!(err.contains("locked.vtu") && err.contains("cannot be opened for writing"), "{err}");
    assert_eq!(std::fs::read(&path).unwrap(), b"old");
    assert!(hidden(&dir).is_empty(), "temporaries left: {:?}", hidden(&dir));
}

#[test]
fn f157_target_names_up_to_the_system_limit_are_written() {
    let dir = fresh_dir(GROUP, "f157_long");
    let max = "m".repeat(251) + ".bin"; // 255 bytes, NAME_MAX
    store::write_atomically(&dir.join(&max), b"first").unwrap();
    store::write_atomically(&dir.join(&max), b"second").unwrap();
    assert_eq!(std::fs::read(dir.join(&max)).unwrap(), b"second");

    let long = "a".repeat(246) + ".vtu"; // 250 bytes
    let (code, err) = cut_to(&dir, &long);
    assert_eq!(code, Some(0), "{err}");
    assert!(std::fs::read_to_string(dir.join(&long)).unwrap().contains("<VTKFile"));
    assert!(hidden(&dir).is_empty(), "temporaries left: {:?}", hidden(&dir));
}

#[test]
fn f158_a_writable_file_in_a_directory_that_takes_no_new_file_is_written_in_place() {
    let dir = fresh_dir(GROUP, "f158_dir");
    let shut = dir.join("shut");
    std::fs::create_dir(&shut).unwrap();
    std::fs::write(shut.join("out.bin"), b"old").unwrap();
    std::fs::write(shut.join("out.vtu"), b"old").unwrap();
    let Some(_flag) = Immutable::set(&shut) else { return };

    store::write_atomically(&shut.join("out.bin"), b"new").unwrap();
    assert_eq!(std::fs::read(shut.join("out.bin")).unwrap(), b"new");
    let (code, err) = cut_to(&dir, "shut/out.vtu");
    assert_eq!(code, Some(0), "{err}");
    assert!(std::fs::read_to_string(shut.join("out.vtu")).unwrap().contains("<VTKFile"));

    // A new file there: refused, naming the directory, not the file.
    let e = store::write_atomically(&shut.join("new.bin"), b"x").unwrap_err().to_string();
    assert!(e.contains(&format!("cannot create a temporary file in {}", shut.display())), "{e}");
    let (code, err) = cut_to(&dir, "shut/new.vtu");
    assert_eq!(code, Some(1));
    assert!(err.contains("cannot create a temporary file in shut"), "{err}");
    assert!(!shut.join("new.bin").exists() && !shut.join("new.vtu").exists());
}

/// The text form of a one-tet 3-G-map; its line 2 is `darts 24 24`.
fn one_tet_text() -> (Document, String) {
    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let doc = Document::from_map(&map);
    let text = String::from_utf8(store::encode(&doc, Format::Text).unwrap()).unwrap();
    assert_eq!(text.lines().nth(1), Some("darts 24 24"));
    (doc, text)
}

#[test]
fn f159_tmap_tokens_are_separated_by_ascii_spaces_and_tabs_only() {
    let (doc, file) = one_tet_text();
    // Accepted: tabs, runs of separators, leading and trailing ones, CRLF line ends.
    for (what, t) in [
        ("tabs", file.replacen("darts 24 24", "darts\t24 \t 24", 1)),
        ("leading and trailing", file.replacen("darts 24 24", " \tdarts 24 24\t ", 1)),
        ("CRLF", file.replace('\n', "\r\n")),
        ("a comment with any character", file.replacen("darts", "# no\u{a0}break\u{b}\ndarts", 1)),
    ] {
        assert_eq!(store::decode(t.as_bytes()).unwrap(), doc, "{what}");
    }
    // Refused on line 2: other Unicode whitespace, control characters, a lone CR.
    for sep in ["\u{a0}", "\u{2003}", "\u{b}", "\u{c}", "\r", "\u{85}", "\u{3000}", "\u{1}"] {
        let t = file.replacen("darts 24 24", &format!("darts{sep}24 24"), 1);
        let e = store::decode(t.as_bytes()).unwrap_err();
        assert!(matches!(&e, StoreError::Syntax { at: Where::Line(2), .. }), "{sep:?}: {e}");
        assert!(e.to_string().contains(&format!("U+{:04X}", u32::from(sep.chars().next().unwrap()))), "{e}");
    }
    // A CR before a CR LF is not a line end; nor is a line of no-break spaces blank.
    let t = file.replacen("darts 24 24\n", "darts 24 24\r\r\n", 1);
    assert!(matches!(store::decode(t.as_bytes()), Err(StoreError::Syntax { at: Where::Line(2), .. })));
    let t = file.replacen("darts", "\u{a0}\ndarts", 1);
    assert!(matches!(store::decode(t.as_bytes()), Err(StoreError::Syntax { at: Where::Line(2), .. })));

    // Through the binary: `check` names the line.
    let dir = fresh_dir(GROUP, "f159_check");
    std::fs::write(dir.join("nbsp.tmap"), file.replacen("darts 24 24", "darts\u{a0}24\u{2003}24", 1)).unwrap();
    std::fs::write(dir.join("crlf.tmap"), file.replace('\n', "\r\n")).unwrap();
    let o = run_in(&dir, &["check", "nbsp.tmap"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stdout));
    assert!(text(&o.stderr).contains("line 2") && text(&o.stderr).contains("U+00A0"), "{}", text(&o.stderr));
    let o = run_in(&dir, &["check", "crlf.tmap"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
}

#[test]
fn f160_negative_values_of_comma_lists_reach_their_checks() {
    let dir = fresh_dir(GROUP, "f160_lists");
    cube(&dir);
    for (args, want) in [
        (&["ambiguity", "kuhn:1", "--cuts", "-1"][..], "\"-1\" is not a count"),
        (&["ambiguity", "kuhn:1", "--cuts", "-1e2"][..], "\"-1e2\" is not a count"),
        (&["ambiguity", "kuhn:1", "--cuts", "2,-1"][..], "\"-1\" is not a count"),
        (&["simulate", "cube.msh", "--pin", "-1"][..], "invalid value '-1' for '--pin"),
        (&["simulate", "cube.msh", "--pin", "-1,2"][..], "invalid value '-1' for '--pin"),
        (&["remove", "cube.msh", "--tets", "-1"][..], "invalid value '-1' for '--tets"),
    ] {
        let o = run_in(&dir, args);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(want) && !err.contains("unexpected argument"), "{args:?}: {err}");
    }
    // A flag after a list is still a flag, not a value.
    for args in [
        &["ambiguity", "kuhn:1", "--cuts", "5", "--json", "--sequences", "1"][..],
        &["simulate", "cube.msh", "--pin", "0,1", "--json", "--steps", "1"][..],
        &["remove", "cube.msh", "--tets", "0", "--json"][..],
    ] {
        let o = run_in(&dir, args);
        assert_eq!(o.status.code(), Some(0), "{args:?}: {}", text(&o.stderr));
        assert!(text(&o.stdout).trim_start().starts_with('{'), "{args:?}: {}", text(&o.stdout));
    }
}
