//! Leveled maps (subdivision levels) in both file forms, version 2: random subdivision sequences
//! round-trip exactly (finest map slot for slot, dart levels, μ, flat flags, every αj^i at every
//! level, points bit for bit, every level isomorphic); truncations, corrupted levels, unknown
//! versions and sections give clear errors; `topomech check` names the dart and the level law.

use std::process::Command;

use proptest::prelude::*;
use topomech::generate::{grid_triangles, kuhn_cube};
use topomech::ops::same_raw;
use topomech::store::{self, Document, Finding, Format, StoreError};
use topomech::subdivide::{HistoryEntry, LevelError, LevelPartsError, LeveledMap, SubdivideError, TetMasses};
use topomech::{DartId, GMap};

const FORMATS: [Format; 2] = [Format::Text, Format::Binary];

fn grid(n: usize) -> LeveledMap<2> {
    let (points, tris) = grid_triangles(n);
    let (map, _) = GMap::<2>::from_triangles(points.len(), &tris).unwrap();
    LeveledMap::new(map, points)
}

fn cube(k: usize) -> LeveledMap<3> {
    let (points, tets) = kuhn_cube(k);
    let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    LeveledMap::new(map, points)
}

/// Applies random operations as tests/subdivide_tet.rs drives them: `op` 0 = edge split,
/// 1 = triangle 1→4, 2 = tetrahedron 1→8 (3D only); refusals for cells already refined are normal.
fn apply<const N: usize>(m: &mut LeveledMap<N>, steps: &[(usize, u8, bool)]) {
    for &(k, op, up) in steps {
        let darts: Vec<DartId> = m.map().darts().collect();
        let d = darts[k % darts.len()];
        let level = (m.max_level() + up as u8).max(1);
        let r = match (op, N) {
            (0, _) => m.split_edge(d, level).map(|_| ()),
            (1, _) | (_, 2) => m.subdivide_triangle(d, level).map(|_| ()),
            _ => subdivide_tet_dyn(m, d, level),
        };
        match r {
            Ok(()) | Err(SubdivideError::AlreadyAtLevel { .. } | SubdivideError::FaceRefinedTooFar { .. }) => {}
            Err(e) => panic!("unexpected error {e}"),
        }
    }
}

/// `subdivide_tet` exists on 3-G-maps only: go through the document to reach it generically.
fn subdivide_tet_dyn<const N: usize>(m: &mut LeveledMap<N>, d: DartId, level: u8) -> Result<(), SubdivideError> {
    let any: &mut dyn std::any::Any = m;
    match any.downcast_mut::<LeveledMap<3>>() {
        Some(m3) => m3.subdivide_tet(d, level).map(|_| ()),
        None => Ok(()),
    }
}

/// Every part of `back` equals `m`: finest map slot for slot, dart levels, μ, flat flags and
/// history (the documents), αj^i for every live dart, j and level, points bit for bit, and
/// every extracted level isomorphic with the same darts.
fn assert_same<const N: usize>(m: &LeveledMap<N>, back: &LeveledMap<N>) -> Result<(), TestCaseError> {
    prop_assert!(same_raw(back.map(), m.map()), "finest maps differ");
    prop_assert_eq!(back.max_level(), m.max_level());
    prop_assert_eq!(Document::from_leveled(back), Document::from_leveled(m));
    let bits = |p: &[[f64; 3]]| p.iter().flatten().map(|x| x.to_bits()).collect::<Vec<u64>>();
    prop_assert_eq!(bits(back.points()), bits(m.points()));
    for d in m.map().darts() {
        prop_assert_eq!(back.dart_level(d), m.dart_level(d));
        prop_assert_eq!(back.mu(d), m.mu(d));
        for i in 0..=m.max_level() {
            for j in 0..=N {
                prop_assert_eq!(back.alpha_at(i, j, d), m.alpha_at(i, j, d), "α{}^{}({})", j, i, d);
            }
        }
    }
    for i in 0..=m.max_level() {
        let (a, b) = (m.level(i).unwrap(), back.level(i).unwrap());
        prop_assert!(a.map.is_isomorphic(&b.map), "level {} not isomorphic", i);
        prop_assert_eq!(a.darts, b.darts);
    }
    Ok(())
}

fn round_trip<const N: usize>(m: &LeveledMap<N>) -> Result<(), TestCaseError> {
    for format in FORMATS {
        let bytes = store::encode(&Document::from_leveled(m), format).unwrap();
        let back: LeveledMap<N> = store::decode(&bytes).unwrap().into_leveled().unwrap();
        assert_same(m, &back)?;
        // A leveled map is a valid map too: load_map reads its finest level.
        let map: GMap<N> = store::decode(&bytes).unwrap().into_map().unwrap();
        prop_assert!(same_raw(&map, m.map()));
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn random_triangle_subdivisions_round_trip_exactly(
        steps in prop::collection::vec((any::<usize>(), 0u8..2, any::<bool>()), 1..10)
    ) {
        let mut m = grid(2);
        apply(&mut m, &steps);
        round_trip(&m)?;
    }

    #[test]
    fn random_tet_subdivisions_round_trip_exactly(
        steps in prop::collection::vec((any::<usize>(), 0u8..3, any::<bool>()), 1..6)
    ) {
        let mut m = cube(1);
        apply(&mut m, &steps);
        round_trip(&m)?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 6, ..ProptestConfig::default() })]

    #[test]
    fn random_ball_refinements_round_trip_exactly(
        c in prop::array::uniform3(0.0f64..2.0), radius in 0.05f64..0.8, levels in 1u8..3
    ) {
        let mut m = cube(2);
        let mut masses = TetMasses::from_density(&m, 1.0).unwrap();
        m.refine_around(c, radius, levels, &mut masses).unwrap();
        round_trip(&m)?;
    }
}

#[test]
fn the_sequences_exercise_histories_and_several_levels() {
    // The properties above must see real histories and more than one level, not only level 0.
    let mut m = cube(1);
    apply(&mut m, &[(3, 2, true), (40, 1, true), (7, 0, false), (90, 2, true)]);
    assert!(m.max_level() >= 2, "max level {}", m.max_level());
    let parts = m.to_parts();
    assert!(parts.darts.iter().any(|d| d.history.len() >= 2));
    assert!(parts.darts.iter().any(|d| d.flat));
    round_trip(&m).unwrap();
}

fn small() -> LeveledMap<2> {
    let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
    let mut m = LeveledMap::new(map, vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    let d = m.map().darts().next().unwrap();
    m.split_edge(d, 1).unwrap();
    m
}

#[test]
fn files_with_levels_are_version_2_and_files_without_stay_version_1() {
    let m = small();
    let text = String::from_utf8(store::encode(&Document::from_leveled(&m), Format::Text).unwrap()).unwrap();
    assert!(text.starts_with("topomech-gmap 2 2\n"), "{text}");
    assert!(text.contains("\nlevels 1 "), "{text}");
    let bare = String::from_utf8(store::encode(&Document::from_map(m.map()), Format::Text).unwrap()).unwrap();
    assert!(bare.starts_with("topomech-gmap 1 2\n"));
    assert!(!bare.contains("levels"));
    let bin = store::encode(&Document::from_leveled(&m), Format::Binary).unwrap();
    assert_eq!(u32::from_le_bytes(bin[8..12].try_into().unwrap()), 2);
    assert_eq!(u32::from_le_bytes(bin[16..20].try_into().unwrap()), 2, "flags: levels bit");
    let bare = store::encode(&Document::from_map(m.map()), Format::Binary).unwrap();
    assert_eq!(u32::from_le_bytes(bare[8..12].try_into().unwrap()), 1);
    // A bare map is not a leveled map.
    let e = store::decode(&bare).unwrap().into_leveled::<2>().unwrap_err();
    assert!(matches!(e, StoreError::NoLevels), "{e}");
}

#[test]
fn save_and_load_through_files() {
    let dir = std::env::temp_dir().join(format!("topomech-store-levels-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut m = cube(1);
    apply(&mut m, &[(5, 2, true), (60, 1, true)]);
    for (name, format) in [("m.tmap", Format::Text), ("m.tmapb", Format::Binary)] {
        let path = dir.join(name);
        store::save_leveled(&m, &path, format).unwrap();
        let back = store::load_leveled::<3>(&path).unwrap();
        assert_same(&m, &back).unwrap();
        let e = store::load_leveled::<2>(&path).unwrap_err();
        assert!(matches!(e, StoreError::WrongDimension { found: 3, expected: 2 }), "{e}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn every_truncation_is_an_error_never_a_panic() {
    let doc = Document::from_leveled(&small());
    for format in FORMATS {
        let bytes = store::encode(&doc, format).unwrap();
        for cut in 0..bytes.len() {
            let r = store::decode(&bytes[..cut]).and_then(|d| d.into_leveled::<2>());
            assert!(r.is_err(), "{format:?}: a file cut at byte {cut} of {} loaded", bytes.len());
        }
    }
}

#[test]
fn unknown_versions_sections_and_flags_are_refused_clearly() {
    let doc = Document::from_leveled(&small());
    let text = String::from_utf8(store::encode(&doc, Format::Text).unwrap()).unwrap();
    let e = store::decode(text.replacen("topomech-gmap 2 2", "topomech-gmap 4 2", 1).as_bytes()).unwrap_err();
    assert!(matches!(e, StoreError::UnsupportedVersion { found: 4, .. }), "{e}");
    assert!(e.to_string().contains("line 1") && e.to_string().contains("versions 1 to 3"), "{e}");
    // A version-2 levels section under a version-3 header: the origin count is missing.
    let e = store::decode(text.replacen("topomech-gmap 2 2", "topomech-gmap 3 2", 1).as_bytes()).unwrap_err();
    assert!(e.to_string().contains("levels"), "{e}");
    // A levels section in a version-1 file.
    let e = store::decode(text.replacen("topomech-gmap 2 2", "topomech-gmap 1 2", 1).as_bytes()).unwrap_err();
    assert!(matches!(e, StoreError::Inconsistent { .. }) && e.to_string().contains("version 2"), "{e}");
    // An unknown section.
    let e = store::decode(text.replacen("\nlevels ", "\nwidgets 3\nlevels ", 1).as_bytes()).unwrap_err();
    assert!(matches!(e, StoreError::Syntax { .. }) && e.to_string().contains("widgets"), "{e}");
    let e = store::decode(text.replacen("\nend\n", "\nwidgets 3\nend\n", 1).as_bytes()).unwrap_err();
    assert!(e.to_string().contains("widgets"), "{e}");

    let bin = store::encode(&doc, Format::Binary).unwrap();
    let edit = |offset: usize, value: u32| {
        let mut b = bin.clone();
        b[offset..offset + 4].copy_from_slice(&value.to_le_bytes());
        reseal(&mut b);
        store::decode(&b).unwrap_err()
    };
    let e = edit(8, 4);
    assert!(matches!(e, StoreError::UnsupportedVersion { found: 4, .. }) && e.to_string().contains("byte 8"), "{e}");
    // A version-2 levels section under a version-3 header: the origin count is missing.
    assert!(matches!(edit(8, 3), StoreError::Truncated { .. }), "{}", edit(8, 3));
    let e = edit(8, 1);
    assert!(matches!(e, StoreError::Inconsistent { .. }) && e.to_string().contains("version 2"), "{e}");
    let e = edit(16, 2 | 4);
    assert!(e.to_string().contains("unknown flags 0x6"), "{e}");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    /// A flipped byte never panics; when the file still decodes (a text digit changed, or a
    /// re-sealed binary edit), `check` and `load_leveled` agree on whether every law holds.
    #[test]
    fn byte_flips_never_panic_and_check_agrees_with_load(
        pos in any::<prop::sample::Index>(), bits in 1u8..=255, binary in any::<bool>(), sealed in any::<bool>()
    ) {
        let mut m = grid(1);
        apply(&mut m, &[(0, 1, true), (5, 0, true)]);
        let format = if binary { Format::Binary } else { Format::Text };
        let mut bytes = store::encode(&Document::from_leveled(&m), format).unwrap();
        let k = pos.index(bytes.len());
        bytes[k] ^= bits;
        if binary && sealed && k < bytes.len() - 8 {
            reseal(&mut bytes);
        }
        if let Ok(doc) = store::decode(&bytes) {
            if doc.map.dimension == 2 {
                let report = store::check_all_laws(&doc, 1000);
                let loaded = doc.into_leveled::<2>();
                prop_assert_eq!(report.valid, loaded.is_ok(), "{:?} / {:?}", report.findings, loaded.err());
            }
        }
    }
}

/// FNV-1a 64 from the format document, to re-seal an edited binary file.
fn reseal(bytes: &mut [u8]) {
    let n = bytes.len() - 8;
    let sum = bytes[..n].iter().fold(0xcbf29ce484222325u64, |h, &b| (h ^ b as u64).wrapping_mul(0x100000001b3));
    bytes[n..].copy_from_slice(&sum.to_le_bytes());
}

/// A refined cube whose document has μt > μf at one dart of a refined tet.
fn broken_mu() -> (Document, u32) {
    let mut m = cube(1);
    apply(&mut m, &[(5, 2, true)]);
    let mut doc = Document::from_leveled(&m);
    let levels = doc.levels.as_mut().unwrap();
    let d = m.map().darts().find(|&d| m.mu(d).tet == 1).unwrap();
    levels.darts[d.index()].mu.tet = levels.darts[d.index()].mu.face + 1;
    (doc, d.0)
}

#[test]
fn a_broken_mu_order_is_refused_by_load_and_listed_by_check() {
    let (doc, d) = broken_mu();
    let e = doc.clone().into_leveled::<3>().unwrap_err();
    assert!(matches!(e, StoreError::Levels(LevelPartsError::Law(_))), "{e}");
    let report = store::check_all_laws(&doc, 100);
    assert!(!report.valid);
    let order = |f: &Finding| matches!(f, Finding::Level(LevelPartsError::Law(LevelError::MuOrder { dart, .. })) if dart.0 == d);
    assert_eq!(report.findings.iter().filter(|f| order(f)).count(), 1, "{:?}", report.findings);
    // Its neighbours in the tet now differ from it: μt is not constant on the volume.
    assert!(report.findings.iter().any(|f| matches!(f,
        Finding::Level(LevelPartsError::Law(LevelError::MuNotConstant { dim: 3, dart, other, .. }))
            if dart.0 == d || other.0 == d)));
}

/// A refined 1×1 grid whose level-0 history is broken at one dart d: a dart of level 0 whose link
/// at level 0 (remembered in its history) went to another dart is made to remember itself
/// instead, so G_0 is no longer an involution at d and its partner. Returns the file and d.
fn broken_level_history() -> (Document, usize) {
    let mut m = grid(1);
    apply(&mut m, &[(0, 1, true)]);
    let mut doc = Document::from_leveled(&m);
    let levels = doc.levels.as_mut().unwrap();
    let (d, rec) = levels
        .darts
        .iter_mut()
        .enumerate()
        .find(|(d, r)| r.level == 0 && r.history.iter().any(|h| h.old as usize != *d))
        .unwrap();
    rec.history.iter_mut().find(|h| h.old as usize != d).unwrap().old = d as u32;
    (doc, d)
}

#[test]
fn a_broken_history_breaks_a_level_and_check_names_it() {
    let (doc, d) = broken_level_history();
    let report = store::check_all_laws(&doc, 100);
    assert!(!report.valid);
    let names_d = |ds: &[DartId]| ds.iter().any(|x| x.index() == d);
    assert!(
        report.findings.iter().any(|f| match f {
            Finding::LevelMap { level: 0, violation }
            | Finding::Level(LevelPartsError::Law(LevelError::InvalidLevel { level: 0, source: violation })) => {
                names_d(&violation_darts(violation))
            }
            Finding::Level(LevelPartsError::Law(LevelError::NotClosed { dart, .. })) => dart.index() == d,
            _ => false,
        }),
        "{:?}",
        report.findings
    );
    assert!(doc.into_leveled::<2>().is_err());
}

fn violation_darts(v: &topomech::gmap::InvariantViolation) -> Vec<DartId> {
    use topomech::gmap::InvariantViolation::*;
    match *v {
        DanglingLink { dart, .. } | CellIdNotLive { dart, .. } | QuasiManifold { dart, .. } => vec![dart],
        NotInvolution { dart, image, back, .. } => vec![dart, image, back],
        CellIdDiffers { dart, other, .. } => vec![dart, other],
        CellIdShared { first, second, .. } => vec![first, second],
        CellIdOrphan { .. } => vec![],
        TetLayout { dart, stored, built, .. } => vec![dart, stored, built],
    }
}

#[test]
fn malformed_records_are_refused_by_from_parts() {
    let m = small();
    let cap = m.map().capacity();
    let mut parts = m.to_parts();
    parts.darts.pop();
    let e = LeveledMap::from_parts(m.map().clone(), parts).unwrap_err();
    assert_eq!(e, LevelPartsError::WrongLength { found: cap - 1, capacity: cap });

    let d = m.map().darts().find(|&d| !m.to_parts().darts[d.index()].history.is_empty()).unwrap();
    let bad = |f: &dyn Fn(&mut HistoryEntry)| {
        let mut parts = m.to_parts();
        f(&mut parts.darts[d.index()].history[0]);
        LeveledMap::from_parts(m.map().clone(), parts).unwrap_err()
    };
    for (edit, reason) in [
        (&(|h: &mut HistoryEntry| h.j = 3) as &dyn Fn(&mut HistoryEntry), "involution above"),
        (&|h: &mut HistoryEntry| h.level = 2, "above the max level"),
        (&|h: &mut HistoryEntry| h.old = cap as u32, "outside the dart slots"),
    ] {
        let e = bad(edit);
        assert!(matches!(e, LevelPartsError::BadHistory { dart, .. } if dart == d), "{e}");
        assert!(e.to_string().contains(reason), "{e}");
    }
    let mut parts = m.to_parts();
    parts.darts[d.index()].level = 7;
    let e = LeveledMap::from_parts(m.map().clone(), parts).unwrap_err();
    assert_eq!(e, LevelPartsError::DartLevelAboveMax { dart: d, level: 7, max_level: 1 });
}

fn topomech() -> Command {
    Command::new(env!("CARGO_BIN_EXE_topomech"))
}

#[test]
fn check_command_reports_the_dart_and_the_level_law() {
    let dir = std::env::temp_dir().join(format!("topomech-store-levels-check-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut m = cube(1);
    apply(&mut m, &[(5, 2, true)]);
    let good = dir.join("good.tmapb");
    store::save_leveled(&m, &good, Format::Binary).unwrap();
    let out = topomech().args(["check", good.to_str().unwrap()]).output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{stdout}");
    assert!(stdout.contains("levels 0..=1: valid"), "{stdout}");

    let (doc, d) = broken_mu();
    let bad = dir.join("bad.tmap");
    store::save_document(&doc, &bad, Format::Text).unwrap();
    let out = topomech().args(["check", "--json", bad.to_str().unwrap()]).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["valid"], false);
    assert_eq!(json["max_level"], 1);
    let findings = json["findings"].as_array().unwrap();
    assert!(findings.iter().any(|f| f["law"] == "mu_order" && f["darts"] == serde_json::json!([d])), "{json}");
    let out = topomech().args(["check", bad.to_str().unwrap()]).output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let line = stdout.lines().find(|l| l.contains("[mu_order]")).unwrap_or_default();
    assert!(line.contains(&DartId(d).to_string()) && line.contains("μt ≤ μf ≤ μa"), "{stdout}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_documented_example_is_the_small_leveled_map() {
    // docs/FILE_FORMAT.md shows a triangle whose edge 0–1 was split at level 1; it must load and be
    // exactly that map, and encoding the map must give the documented text.
    let doc = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/FILE_FORMAT.md")).unwrap();
    let start = doc.find("<!-- levels-example -->").expect("example marker");
    let body = &doc[start..];
    let from = body.find("```text\n").unwrap() + "```text\n".len();
    let example = &body[from..from + body[from..].find("```").unwrap()];
    let back = store::decode(example.as_bytes()).unwrap().into_leveled::<2>().unwrap();
    assert_same(&small(), &back).unwrap();
    let written = store::encode(&Document::from_leveled(&small()), Format::Text).unwrap();
    assert_eq!(String::from_utf8(written).unwrap(), example);
}

#[test]
fn mechanics_and_levels_sections_coexist() {
    use topomech::mechanics::{Body, Material};
    let (points, tets) = kuhn_cube(1);
    let body = Body::from_tets(&points, &tets, Material::default()).unwrap().0;
    let mut m = LeveledMap::new(body.map().clone(), points);
    apply(&mut m, &[(3, 0, true)]);
    let mut doc = Document::from_body(&body);
    doc.map = Document::from_leveled(&m).map;
    doc.levels = Document::from_leveled(&m).levels;
    // Structure only: the attributes are those of the unrefined body, so no law is checked here.
    for format in FORMATS {
        let back = store::decode(&store::encode(&doc, format).unwrap()).unwrap();
        assert_eq!(back, doc, "{format:?}");
    }
}

/// `topomech check` on a leveled file whose level-0 link history was broken by hand
/// ([`broken_level_history`]): it exits 1 and names a level law at the broken dart, with the
/// leveled map's dart ids, in JSON and in the table.
#[test]
fn check_command_names_a_broken_level_with_the_leveled_darts() {
    let (doc, d) = broken_level_history();
    let path = std::env::temp_dir().join(format!("topomech-broken-level-{}.tmap", std::process::id()));
    store::save_document(&doc, &path, Format::Text).unwrap();
    let out = topomech().args(["check", "--json", path.to_str().unwrap()]).output().unwrap();
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stderr));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let findings = json["findings"].as_array().unwrap();
    let level_law = |f: &serde_json::Value| ["level_valid", "level_closed"].contains(&f["law"].as_str().unwrap_or(""));
    assert!(findings.iter().all(level_law), "only level laws are broken: {json}");
    let at_d = |f: &&serde_json::Value| f["darts"].as_array().unwrap().iter().any(|x| x.as_u64() == Some(d as u64));
    let named = findings.iter().find(at_d).unwrap_or_else(|| panic!("no finding names dart {d}: {json}"));
    let out = topomech().args(["check", path.to_str().unwrap()]).output().unwrap();
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(table.contains("INVALID") && table.contains(&format!("[{}]", named["law"].as_str().unwrap())), "{table}");
    std::fs::remove_file(&path).unwrap();
}
