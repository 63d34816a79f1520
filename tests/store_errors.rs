//! Bad files give clear errors, never panics: truncations, byte flips, wrong magic or version,
//! out-of-range darts, NaN, huge counts; a hand-broken map is listed by `check` with the right dart
//! and law; a failed save leaves the old file intact.

use std::process::Command;

use proptest::prelude::*;
use topomech::gmap::{InvariantViolation, Law};
use topomech::mechanics::{Body, Material};
use topomech::store::{self, Document, Finding, Format, StoreError};
use topomech::{DartId, GMap};

fn small_body() -> Body {
    let (points, tets) = topomech::generate::kuhn_cube(1);
    Body::from_tets(&points, &tets, Material::default()).unwrap().0
}

fn two_tets() -> GMap<3> {
    GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap().0
}

/// FNV-1a 64, written again from the format document (not the library's code).
fn fnv(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf29ce484222325;
    for &b in bytes {
        h ^= b as u64;
        h = h.wrapping_mul(0x100000001b3);
    }
    h
}

/// Rewrites the trailing checksum after an edit, so the edit itself is what the loader sees.
fn reseal(bytes: &mut [u8]) {
    let n = bytes.len() - 8;
    let sum = fnv(&bytes[..n]);
    bytes[n..].copy_from_slice(&sum.to_le_bytes());
}

#[test]
fn every_truncation_errors_cleanly() {
    let doc = Document::from_body(&small_body());
    for format in [Format::Text, Format::Binary] {
        let bytes = store::encode(&doc, format).unwrap();
        for cut in 0..bytes.len() {
            let err = store::decode(&bytes[..cut]).expect_err("a strict prefix must not decode");
            assert!(!err.to_string().is_empty());
        }
        assert!(store::decode(&bytes).is_ok());
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]
    #[test]
    fn byte_flips_never_panic(pos in any::<prop::sample::Index>(), bits in 1u8..=255, binary in any::<bool>()) {
        let format = if binary { Format::Binary } else { Format::Text };
        let mut bytes = store::encode(&Document::from_map(&two_tets()), format).unwrap();
        let k = pos.index(bytes.len());
        bytes[k] ^= bits;
        match store::decode(&bytes) {
            // A text flip may still parse (a digit changed): then check must list or accept it.
            Ok(doc) => {
                prop_assert!(!binary, "a flipped binary file decoded: the checksum missed it");
                let report = store::check_all_laws(&doc, 50);
                prop_assert_eq!(report.valid, doc.clone().into_map::<3>().is_ok());
                prop_assert_eq!(report.valid, report.findings.is_empty());
            }
            Err(e) => prop_assert!(!e.to_string().is_empty()),
        }
    }
}

#[test]
fn header_errors_name_what_is_wrong() {
    let text = store::encode(&Document::from_map(&two_tets()), Format::Text).unwrap();
    let text = String::from_utf8(text).unwrap();
    let e = store::decode(b"solid cube\nfacet normal").unwrap_err();
    assert!(matches!(e, StoreError::BadMagic { .. }), "{e}");
    let next = store::VERSION + 1;
    let e = store::decode(text.replacen("topomech-gmap 1 3", &format!("topomech-gmap {next} 3"), 1).as_bytes())
        .unwrap_err();
    assert!(matches!(e, StoreError::UnsupportedVersion { found, .. } if found == u64::from(next)), "{e}");
    assert!(e.to_string().contains("line 1"), "{e}");
    let e = store::decode(text.replacen("topomech-gmap 1 3", "topomech-gmap 1 9", 1).as_bytes()).unwrap_err();
    assert!(matches!(e, StoreError::BadDimension { found: 9, .. }), "{e}");
    let e = store::decode(text.as_bytes()).unwrap().into_map::<2>().unwrap_err();
    assert!(matches!(e, StoreError::WrongDimension { found: 3, expected: 2 }), "{e}");

    let mut bin = store::encode(&Document::from_map(&two_tets()), Format::Binary).unwrap();
    bin[8] = 7;
    reseal(&mut bin);
    let e = store::decode(&bin).unwrap_err();
    assert!(matches!(e, StoreError::UnsupportedVersion { found: 7, .. }), "{e}");
    assert!(e.to_string().contains("byte 8"), "{e}");
}

#[test]
fn binary_corruption_is_a_checksum_error() {
    let mut bin = store::encode(&Document::from_map(&two_tets()), Format::Binary).unwrap();
    let k = bin.len() / 2;
    bin[k] ^= 0x10;
    assert!(matches!(store::decode(&bin).unwrap_err(), StoreError::Checksum { .. }));
}

#[test]
fn huge_counts_are_refused_before_allocating() {
    let mut bin = store::encode(&Document::from_map(&two_tets()), Format::Binary).unwrap();
    bin[28..32].copy_from_slice(&(u32::MAX - 2).to_le_bytes()); // dart capacity
    reseal(&mut bin);
    let e = store::decode(&bin).unwrap_err();
    assert!(matches!(e, StoreError::BadCount { what: "dart capacity", .. }), "{e}");
    let text = "topomech-gmap 1 3\ndarts 4000000000 0\nfree-darts 0\nend\n";
    assert!(matches!(store::decode(text.as_bytes()).unwrap_err(), StoreError::BadCount { .. }));
    let text =
        "topomech-gmap 1 1\ndarts 1 1\n0 0 0 | 0 0\nfree-darts 0\ncell-ids 0 4000000000 0\ncell-ids 1 1 0\nend\n";
    let e = store::decode(text.as_bytes()).unwrap_err();
    assert!(matches!(e, StoreError::BadCount { .. }), "{e}");
}

/// A count is bounded by the bytes left over the real size of one record, so a count one record
/// past what the file can hold is refused at once as a bad count, not read until the bytes run
/// out. Checked on the vertex records of a body (14 f64 and a flag byte each: 113 bytes).
#[test]
fn a_vertex_count_past_what_the_file_holds_is_a_bad_count() {
    const RECORD: usize = 14 * 8 + 1;
    let doc = Document::from_body(&small_body());
    let mech = doc.mechanics.as_ref().unwrap();
    let mut bin = store::encode(&doc, Format::Binary).unwrap();
    let material: Vec<u8> = mech.material.iter().flat_map(|x| x.to_le_bytes()).collect();
    let at = bin.windows(32).position(|w| w == material).expect("the material precedes the vertex count") + 32;
    assert_eq!(bin[at..at + 4], (mech.vertices.len() as u32).to_le_bytes(), "the vertex count follows the material");
    let left = bin.len() - (at + 4); // an upper bound: the checksum is not payload
    let count = left / RECORD + 1;
    bin[at..at + 4].copy_from_slice(&(count as u32).to_le_bytes());
    reseal(&mut bin);
    match store::decode(&bin).unwrap_err() {
        StoreError::BadCount { what: "vertex records", count: c, limit, .. } => {
            assert_eq!(c, count as u64);
            assert!(limit as usize * RECORD <= left, "limit {limit} allows more records than the {left} bytes left");
        }
        e => panic!("a vertex count past the end must be a bad count: {e}"),
    }
}

#[test]
fn out_of_range_dart_and_nan_are_located() {
    let text =
        "topomech-gmap 1 1\ndarts 2 2\n0 0 1 | 0 0\n1 1 7 | 1 0\nfree-darts 0\ncell-ids 0 2 0\ncell-ids 1 1 0\nend\n";
    let e = store::decode(text.as_bytes()).unwrap_err();
    assert!(matches!(e, StoreError::DartOutOfRange { dart: 7, capacity: 2, .. }), "{e}");
    assert!(e.to_string().contains("line 4"), "{e}");

    let body = small_body();
    let text = String::from_utf8(store::encode(&Document::from_body(&body), Format::Text).unwrap()).unwrap();
    let line = text.lines().position(|l| l.starts_with("e 3 ")).unwrap();
    let broken: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(k, l)| if k == line { "e 3 NaN 1.0 1.0".to_string() } else { l.to_string() })
        .collect();
    let e = store::decode((broken.join("\n") + "\n").as_bytes()).unwrap_err();
    assert!(matches!(e, StoreError::NonFinite { index: 3, .. }), "{e}");
    assert!(e.to_string().contains(&format!("line {}", line + 1)), "{e}");
}

/// The text of `two_tets` with α0 of dart `d` pointed at `to` instead.
fn swap_alpha0(d: u32, to: u32) -> String {
    let text = String::from_utf8(store::encode(&Document::from_map(&two_tets()), Format::Text).unwrap()).unwrap();
    text.lines()
        .map(|l| {
            let t: Vec<&str> = l.split_whitespace().collect();
            if t.first() == Some(&d.to_string().as_str()) && t.get(5) == Some(&"|") {
                let mut t: Vec<String> = t.iter().map(|s| s.to_string()).collect();
                t[1] = to.to_string();
                t.join(" ")
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
        + "\n"
}

#[test]
fn a_swapped_link_is_reported_with_its_dart_and_law() {
    let map = two_tets();
    let (d, to) = (5u32, 11u32);
    assert_ne!(map.alpha_dyn(0, DartId(d)), DartId(to));
    let doc = store::decode(swap_alpha0(d, to).as_bytes()).unwrap();
    // The normal load refuses the map ...
    let e = doc.clone().into_map::<3>().unwrap_err();
    assert!(matches!(e, StoreError::BrokenLaw(_)), "{e}");
    // ... check lists every law it breaks: the involution at d (α0(d) = to, α0(to) ≠ d) and at
    // d's old partner (α0(4) = d but α0(d) ≠ 4).
    let report = store::check_all_laws(&doc, 100);
    assert!(!report.valid);
    let involution_at = |x: u32| {
        report.findings.iter().find_map(|f| match f {
            Finding::Map(v @ InvariantViolation::NotInvolution { dart, i: 0, image, .. }) if dart.0 == x => {
                assert_eq!(v.law(), Law::Involution);
                Some(*image)
            }
            _ => None,
        })
    };
    assert_eq!(involution_at(d), Some(DartId(to)));
    assert_eq!(involution_at(map.alpha_dyn(0, DartId(d)).0), Some(DartId(d)));
    assert!(report.findings.len() > 1, "only the first violation was listed: {:?}", report.findings);
    // The quasi-manifold law composes four links; it is judged only where all four are
    // involutions, so a broken link is reported once, as such, and not again as a spurious
    // αiαj failure at every dart whose composition passes through it.
    let spurious: Vec<_> =
        report.findings.iter().filter(|f| matches!(f, Finding::Map(v) if v.law() == Law::QuasiManifold)).collect();
    assert!(spurious.is_empty(), "quasi-manifold failures reported through a broken link: {spurious:?}");
}

fn topomech() -> Command {
    Command::new(env!("CARGO_BIN_EXE_topomech"))
}

#[test]
fn check_command_exit_codes_and_json() {
    let dir = std::env::temp_dir().join(format!("topomech-store-check-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let good = dir.join("good.tmapb");
    store::save_body(&small_body(), &good, Format::Binary).unwrap();
    let out = topomech().args(["check", good.to_str().unwrap()]).output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stdout));

    let bad = dir.join("bad.tmap");
    std::fs::write(&bad, swap_alpha0(5, 11)).unwrap();
    let out = topomech().args(["check", "--json", bad.to_str().unwrap()]).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["valid"], false);
    let findings = json["findings"].as_array().unwrap();
    assert!(findings.iter().any(|f| f["law"] == "involution" && f["darts"][0] == 5 && f["darts"][1] == 11));

    let garbage = dir.join("garbage.tmap");
    std::fs::write(&garbage, "topomech-gmap 1 3\ndarts 3\n").unwrap();
    let out = topomech().args(["check", garbage.to_str().unwrap()]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("line 2"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn failed_saves_leave_the_old_file_intact() {
    let dir = std::env::temp_dir().join(format!("topomech-store-atomic-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("body.tmap");
    let body = small_body();
    store::save_body(&body, &path, Format::Text).unwrap();
    let old = std::fs::read(&path).unwrap();

    // An unrepresentable value: refused before anything is written.
    let mut nan = body.clone();
    nan.attrs_mut().position_mut().as_mut_slice()[0][0] = f64::NAN;
    assert!(matches!(store::save_body(&nan, &path, Format::Text), Err(StoreError::Unrepresentable { .. })));
    assert_eq!(std::fs::read(&path).unwrap(), old);

    // The rename fails (the target is a non-empty directory): the temporary file is cleaned up.
    let blocker = dir.join("blocker.tmap");
    std::fs::create_dir_all(blocker.join("inside")).unwrap();
    assert!(matches!(store::save_body(&body, &blocker, Format::Text), Err(StoreError::Io { .. })));
    assert!(blocker.join("inside").is_dir());

    // A directory that takes no new file (only effective when not running as root): an existing
    // writable file is written in place (finding 158), a new one is refused naming the directory.
    let ro = dir.join("ro");
    std::fs::create_dir_all(&ro).unwrap();
    let ro_path = ro.join("body.tmap");
    store::save_body(&body, &ro_path, Format::Text).unwrap();
    let ro_old = std::fs::read(&ro_path).unwrap();
    set_mode(&ro, 0o555);
    let probe_ok = std::fs::write(ro.join("probe"), b"x").is_ok();
    let mut moved = small_body();
    moved.attrs_mut().position_mut().as_mut_slice()[0][0] += 1.0;
    let result = store::save_body(&moved, &ro_path, Format::Text);
    if !probe_ok {
        assert!(result.is_ok(), "{result:?}");
        assert_ne!(std::fs::read(&ro_path).unwrap(), ro_old);
        let loaded = store::load_body(&ro_path).unwrap();
        assert_eq!(loaded.attrs().position().as_slice()[0], moved.attrs().position().as_slice()[0]);
        let fresh = store::save_body(&moved, &ro.join("new.tmap"), Format::Text);
        assert!(matches!(&fresh, Err(StoreError::Io { .. })), "{fresh:?}");
        assert!(fresh.unwrap_err().to_string().contains("cannot create a temporary file in"));
    }
    set_mode(&ro, 0o755);

    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".tmp-"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[cfg(unix)]
fn set_mode(p: &std::path::Path, mode: u32) {
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(p, std::fs::Permissions::from_mode(mode)).unwrap();
}

#[cfg(not(unix))]
fn set_mode(_: &std::path::Path, _: u32) {}

/// `check` lists every broken conservation law of a body, not only the first, each naming its
/// cell: two tampered edge stiffnesses give four findings (stiffness and damping of each), and
/// the listing stops at the limit with `truncated` set.
#[test]
fn every_broken_conservation_law_is_listed() {
    let body = small_body();
    let clean = store::check_all_laws(&Document::from_body(&body), 100);
    assert!(clean.valid && clean.findings.is_empty(), "{:?}", clean.findings);
    let mut doc = Document::from_body(&body);
    let edges = &mut doc.mechanics.as_mut().expect("a body").edges;
    edges[0][1] *= 2.0; // [rest length, stiffness, damping]
    edges[3][1] *= 3.0;
    let report = store::check_all_laws(&doc, 100);
    assert!(!report.valid);
    let edges: Vec<String> = report.findings.iter().map(|f| f.to_string()).collect();
    assert_eq!(edges.len(), 4, "{edges:?}");
    assert!(edges.iter().all(|f| f.starts_with("conservation: edge ")), "{edges:?}");
    assert_eq!(edges.iter().filter(|f| f.contains("stiffness")).count(), 2, "{edges:?}");
    assert!(
        edges[0].contains("edge 0 (e.g. dart 0)") && (edges[2].contains("edge 3 (") || edges[2].contains("edge 3:")),
        "{edges:?}"
    );
    let short = store::check_all_laws(&doc, 2);
    assert_eq!(short.findings.len(), 2);
    assert!(short.truncated && !short.valid);
}

/// A binary header whose declared payload fits but whose 8-byte checksum does not (found by the
/// `readers` fuzz target: the decoder used to slice past the end): every such length is a
/// `Truncated` error.
#[test]
fn a_checksum_cut_short_is_truncated_not_a_panic() {
    let full = store::encode(&Document::from_map(&two_tets()), Format::Binary).unwrap();
    let header = &full[..28]; // magic, version, dimension, flags, payload length
    for payload in 0u64..4 {
        for tail in 0..8 {
            let mut bytes = header[..20].to_vec();
            bytes.extend_from_slice(&payload.to_le_bytes());
            bytes.extend(std::iter::repeat_n(0u8, payload as usize + tail)); // payload + a short checksum
            let err = store::decode(&bytes).expect_err("the checksum is missing bytes");
            assert!(matches!(err, StoreError::Truncated { .. }), "payload {payload}, {tail} checksum bytes: {err}");
        }
    }
}

/// The text file of `two_tets()` with row `d`'s field `k` (0 = the dart, 1..=4 its α0..α3, then
/// "|", 6..=9 its cell ids) set to `value`, for each `(d, k, value)`.
fn edited_rows(edits: &[(u32, usize, u32)]) -> String {
    let text = String::from_utf8(store::encode(&Document::from_map(&two_tets()), Format::Text).unwrap()).unwrap();
    let mut done = 0;
    let rows: Vec<String> = text
        .lines()
        .map(|l| {
            let mut t: Vec<String> = l.split_whitespace().map(str::to_string).collect();
            if t.get(5).map(String::as_str) == Some("|") {
                let row = t[0].clone();
                for &(_, k, value) in edits.iter().filter(|e| row == e.0.to_string()) {
                    t[k] = value.to_string();
                    done += 1;
                }
                return t.join(" ");
            }
            l.to_string()
        })
        .collect();
    assert_eq!(done, edits.len(), "every edited row exists");
    rows.join("\n") + "\n"
}

/// `topomech check --json` on `text`: exit code and the (law, darts) of each finding.
fn check_findings(name: &str, text: &str) -> (Option<i32>, Vec<(String, Vec<u64>)>) {
    let path = std::env::temp_dir().join(format!("topomech-check-{name}-{}.tmap", std::process::id()));
    std::fs::write(&path, text).unwrap();
    let out = topomech().args(["check", "--json", path.to_str().unwrap()]).output().unwrap();
    std::fs::remove_file(&path).unwrap();
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{name}: {e}"));
    let findings = json["findings"].as_array().unwrap().iter();
    let listed = findings
        .map(|f| {
            (
                f["law"].as_str().unwrap().to_string(),
                f["darts"].as_array().unwrap().iter().map(|d| d.as_u64().unwrap()).collect(),
            )
        })
        .collect();
    (out.status.code(), listed)
}

#[test]
fn check_names_the_quasi_manifold_and_cell_id_laws_with_their_darts() {
    let map = two_tets();
    // Two α3 pairs whose first darts are α0-linked, re-paired crosswise: α3 stays an involution,
    // α0α3 does not (the quasi-manifold law of j = i + 3).
    let x = map.darts().find(|&d| !map.is_free(3, d)).unwrap();
    let (x2, y, y2) = (map.alpha::<0>(x), map.alpha::<3>(x), map.alpha::<3>(map.alpha::<0>(x)));
    let crossed = edited_rows(&[(x.0, 4, y2.0), (y2.0, 4, x.0), (x2.0, 4, y.0), (y.0, 4, x2.0)]);
    let (code, findings) = check_findings("crossed", &crossed);
    assert_eq!(code, Some(1));
    assert!(findings.iter().all(|(law, _)| law == "quasi_manifold" || law.starts_with("cell_id")), "{findings:?}");
    let qm: Vec<_> = findings.iter().filter(|(law, _)| law == "quasi_manifold").collect();
    assert!(qm.iter().any(|(_, darts)| darts[0] == u64::from(x.0)), "{findings:?}");
    // One dart given the vertex id of another vertex: its id differs from its orbit's
    // (cell_id_constant, naming it and a neighbour), and the id now names two vertices.
    let d = DartId(0);
    let other = map.darts().map(|e| map.vertex_id(e)).find(|&v| v != map.vertex_id(d)).unwrap();
    let (code, findings) = check_findings("vertex-id", &edited_rows(&[(d.0, 6, other.0)]));
    assert_eq!(code, Some(1));
    let constant: Vec<_> = findings.iter().filter(|(law, _)| law == "cell_id_constant").collect();
    assert!(!constant.is_empty() && constant.iter().all(|(_, darts)| darts.len() == 2), "{findings:?}");
    assert!(constant.iter().any(|(_, darts)| darts.contains(&0)), "{findings:?}");
    assert!(findings.iter().any(|(law, darts)| law == "cell_id_unique" && darts.contains(&0)), "{findings:?}");
    assert!(findings.iter().all(|(law, _)| law.starts_with("cell_id")), "{findings:?}");
}

/// The text twin of the test above: a record count is bounded by the significant lines *left
/// after* the header that states it, not by the lines of the whole file. A vertex count one past
/// the lines left (but well under the file's line total) is a bad count naming that limit.
#[test]
fn a_text_vertex_count_past_the_lines_left_is_a_bad_count() {
    let doc = Document::from_body(&small_body());
    let text = String::from_utf8(store::encode(&doc, Format::Text).unwrap()).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let at = lines.iter().position(|l| l.starts_with("mechanics ")).expect("a body has a mechanics line");
    let significant = |ls: &[&str]| ls.iter().filter(|l| !l.trim().is_empty() && !l.trim().starts_with('#')).count();
    let left = significant(&lines[at + 1..]);
    assert!(significant(&lines[..at]) > 1, "the map's lines precede the mechanics line");
    let head: Vec<&str> = lines[at].split(' ').collect();
    let count = left + 1;
    let changed = format!("mechanics {count} {} {} {}", head[2], head[3], head[4]);
    let broken: Vec<String> =
        lines.iter().enumerate().map(|(k, l)| if k == at { changed.clone() } else { l.to_string() }).collect();
    match store::decode((broken.join("\n") + "\n").as_bytes()).unwrap_err() {
        StoreError::BadCount { what: "mechanics records", count: c, limit, .. } => {
            assert_eq!(c, count as u64);
            assert_eq!(limit, left as u64, "the limit is the significant lines after the mechanics line");
        }
        e => panic!("a vertex count past the lines left must be a bad count: {e}"),
    }
}
