//! Subdivision sequences from bytes (`topomech::subdivide::fuzz`), run by proptest on random
//! bytes and by replaying the committed cargo-fuzz corpus `fuzz/corpus/subdivide/` — the same
//! decoder as the fuzz target, every level law checked after every op.

use std::path::Path;

use proptest::prelude::*;
use topomech::subdivide::fuzz::{decode, is_cut_mode, run_bytes, Mesh, Op};

#[test]
fn every_subdivide_corpus_input_keeps_the_laws() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/subdivide");
    let mut entries: Vec<_> = std::fs::read_dir(&dir).expect("corpus directory").map(|e| e.unwrap().path()).collect();
    entries.sort();
    assert!(
        entries.len() >= 64,
        "the committed corpus holds at least this many inputs (finding 326; 16 in cut mode), found {}",
        entries.len()
    );
    let (mut applied, mut refused, mut top, mut cuts, mut reloads) = (0, 0, 0, 0, 0);
    let mut meshes = [0; 3];
    let mut cut_meshes = [0; 3];
    for path in entries {
        let bytes = std::fs::read(&path).unwrap();
        let mesh = decode(&bytes).0 as usize;
        meshes[mesh] += 1;
        if is_cut_mode(&bytes) {
            cut_meshes[mesh] += 1;
        }
        match run_bytes(&bytes) {
            Ok(r) => {
                applied += r.applied;
                refused += r.refused;
                top = top.max(r.max_level);
                cuts += r.cuts;
                reloads += r.reloads;
            }
            Err(message) => panic!("{}: {message}", path.display()),
        }
    }
    // The corpus must exercise the operations, not only their refusals, in 2D and 3D.
    assert!(applied >= 100 && refused >= 10, "applied {applied}, refused {refused}");
    assert!(top >= 2, "the corpus never goes beyond level {top}");
    assert!(meshes.iter().all(|&n| n > 0), "meshes covered: {meshes:?}");
    // Cut mode: cuts and reloads on every mesh, so that the later ops run on reloaded copies.
    assert!(cut_meshes.iter().all(|&n| n > 0), "meshes covered in cut mode: {cut_meshes:?}");
    assert!(cuts >= 20 && reloads >= 20, "cuts {cuts}, reloads {reloads}");
}

#[test]
fn decoding_is_total_and_follows_the_documented_layout() {
    assert_eq!(decode(&[]), (Mesh::Grid, vec![]));
    assert_eq!(decode(&[1]).0, Mesh::Cube);
    assert_eq!(decode(&[2, 0x80, 0, 5]), (Mesh::Tet, vec![Op::SplitEdge { pick: 5, up: true }]));
    assert_eq!(decode(&[2, 2, 1, 0, 9]).1, vec![Op::Tet { pick: 256, up: false }], "a trailing partial op is dropped");
}

#[test]
fn a_ball_on_a_uniform_triangle_grid_takes_the_bulk_path_and_a_mixed_one_falls_back() {
    // Grid (8 triangles), then a ball op: the bulk path refines all 8 triangles 1→4.
    let r = run_bytes(&[0, 0x83, 0, 0]).unwrap();
    assert_eq!((r.applied, r.refused, r.max_level, r.darts), (1, 0, 1, 8 * 4 * 6));
    // A triangle split first makes the levels mixed: the ball op is refused by the bulk path
    // (checked unchanged) and becomes one more triangle split (3 + 3 new triangles, not 32 + …).
    let r = run_bytes(&[0, 0x81, 0, 0, 0x03, 0, 1]).unwrap();
    assert_eq!((r.applied, r.refused), (2, 0));
    assert!(r.darts < 8 * 4 * 6, "fell back to a single split: {} darts", r.darts);
    // Twice in a row: levels 1 then 2, every triangle each time.
    let r = run_bytes(&[0, 0x83, 0, 0, 0x83, 0, 0]).unwrap();
    assert_eq!((r.applied, r.max_level, r.darts), (2, 2, 8 * 16 * 6));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, ..ProptestConfig::default() })]
    #[test]
    fn random_subdivision_sequences_keep_every_law(bytes in prop::collection::vec(any::<u8>(), 0..31)) {
        if let Err(message) = run_bytes(&bytes) {
            prop_assert!(false, "{}", message);
        }
    }
}

/// Cut mode (bit 7 of byte 0): the cube, a cut one level up, a binary reload, a 1→8 one level
/// up (applied to the copy too), a text reload, a cut at the maximum level.
#[test]
fn cut_mode_cuts_reloads_and_refines_the_copy_alike() {
    let bytes = [0x81, 0x84, 0, 3, 0x85, 0, 0, 0x82, 0, 9, 0x05, 0, 0, 0x04, 0, 11];
    let (_, ops) = decode(&bytes);
    assert_eq!(ops[0], Op::Cut { pick: 3, up: true });
    assert_eq!((ops[1], ops[3]), (Op::Reload { binary: true }, Op::Reload { binary: false }));
    let r = run_bytes(&bytes).unwrap();
    assert_eq!((r.cuts, r.reloads), (2, 2), "{r:?}");
    assert_eq!((r.applied, r.refused, r.max_level), (3, 0, 2), "{r:?}");
    // The grid: a cut is a reload in 2D.
    let r = run_bytes(&[0x80, 0x81, 0, 0, 0x04, 0, 0, 0x81, 0, 1]).unwrap();
    assert_eq!((r.cuts, r.reloads, r.applied), (0, 1, 2), "{r:?}");
    // The single tet has no sewn face: the cut is refused, the map unchanged.
    let r = run_bytes(&[0x82, 0x84, 0, 0]).unwrap();
    assert_eq!((r.cuts, r.refused, r.max_level), (0, 1, 0), "{r:?}");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]
    #[test]
    fn random_cut_and_subdivide_sequences_keep_every_law(
        mesh in 0u8..3,
        ops in prop::collection::vec(any::<u8>(), 0..40),
    ) {
        let bytes: Vec<u8> = std::iter::once(0x80 | mesh).chain(ops).collect();
        if let Err(message) = run_bytes(&bytes) {
            prop_assert!(false, "{}", message);
        }
    }
}
