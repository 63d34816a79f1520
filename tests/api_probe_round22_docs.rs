//! Round 22, a claims audit of the user documentation (findings 193–197): what a user reading
//! FILE_FORMAT.md, SUBDIVISION.md and FORMATS.md is promised, checked against the behaviour.

use std::path::Path;

use topomech::generate::kuhn_cube;
use topomech::io::{read_mesh, ReadError};
use topomech::store::{self, StoreError};
use topomech::subdivide::{LeveledMap, SubdivideError, TetMasses};
use topomech::GMap;

/// A one-dart 1-G-map in the text form.
const MAP: &str = "topomech-gmap 1 1\ndarts 1 1\n0 0 0 | 0 0\nfree-darts 0\ncell-ids 0 1 0\ncell-ids 1 1 0\nend\n";

/// Finding 193: blank and `#` lines, and blanks, before the header are ignored as everywhere else
/// in the text form (the decoder used to look for the magic at byte 0 only).
#[test]
fn f193_comments_and_blanks_before_the_text_header_are_ignored() {
    let plain = store::decode(MAP.as_bytes()).unwrap();
    for prefix in ["# written by hand\n", "\n", "  \t", " \n# a\r\n\t\n  ", "#\n"] {
        let text = format!("{prefix}{MAP}");
        assert_eq!(store::decode(text.as_bytes()).unwrap(), plain, "prefix {prefix:?}");
    }
    // Line numbers in errors count the lines before the header.
    let broken = format!("# note\n\n{}", MAP.replace("darts 1 1", "darts x 1"));
    let e = store::decode(broken.as_bytes()).unwrap_err().to_string();
    assert!(e.contains("line 4"), "{e}");
}

/// Finding 193, the other side: what has no header as its first significant line is still no
/// map file, and the binary form is told by its magic at byte 0 only.
#[test]
fn f193_a_file_without_the_header_first_is_refused_by_its_magic() {
    for bad in [&b"# only a comment\n"[..], b"\n\n", b"", b"darts 1 1\ntopomech-gmap 1 1\n", b"#topomech-gmap 1 1\n"] {
        let e = store::decode(bad).unwrap_err();
        assert!(matches!(e, StoreError::BadMagic { .. }), "{bad:?}: {e}");
    }
    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let binary = store::encode(&store::Document::from_map(&map), store::Format::Binary).unwrap();
    let mut shifted = b"\n".to_vec();
    shifted.extend_from_slice(&binary);
    assert!(matches!(store::decode(&shifted), Err(StoreError::BadMagic { .. })));
}

/// Finding 195: a uniform level over the dart limit is refused with its exact estimate, 2³ × the
/// darts (the bulk path's), not the op-by-op path's bound of 384 darts per tet.
#[test]
fn f195_a_uniform_level_over_the_limit_names_its_exact_estimate() {
    let (p, t) = kuhn_cube(2);
    let (map, _) = GMap::<3>::from_tets(p.len(), &t).unwrap();
    let mut m = LeveledMap::new(map, p);
    let mut masses = TetMasses::from_density(&m, 1.0).unwrap();
    let darts = m.map().dart_count();
    m.set_max_darts(8 * darts); // exactly level 1: accepted
    m.refine_around([1.0; 3], 1e9, 1, &mut masses).unwrap();
    assert_eq!(m.map().dart_count(), 8 * darts);
    let darts = m.map().dart_count();
    m.set_max_darts(8 * darts - 1);
    let before = (m.clone(), masses.clone());
    match m.refine_around([1.0; 3], 1e9, 2, &mut masses).unwrap_err() {
        SubdivideError::DartLimit { level, tets, darts: d, estimate, limit } => {
            assert_eq!((level, tets, d, estimate, limit), (2, darts / 24, darts, 8 * darts, 8 * darts - 1));
        }
        other => panic!("{other}"),
    }
    assert!(topomech::ops::same_raw(m.map(), before.0.map()), "a refusal changes nothing");
    assert_eq!(masses, before.1);
}

/// Finding 197: an OBJ given where a volume is read names the formats the commands take, and
/// still points a library caller to the surface reader.
#[test]
fn f197_an_obj_volume_names_the_volume_formats() {
    let e = read_mesh(Path::new("/no/such/surface.obj")).unwrap_err();
    assert!(matches!(e, ReadError::UnknownFormat { .. }));
    let text = e.to_string();
    for part in ["surface", "MSH", "TetGen", "read_tri_mesh"] {
        assert!(text.contains(part), "{part} in {text}");
    }
}
