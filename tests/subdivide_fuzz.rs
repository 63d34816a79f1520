//! Subdivision sequences from bytes (`topomech::subdivide::fuzz`), run by proptest on random
//! bytes and by replaying the committed cargo-fuzz corpus `fuzz/corpus/subdivide/` — the same
//! decoder as the fuzz target, every level law checked after every op.

use std::path::Path;

use proptest::prelude::*;
use topomech::subdivide::fuzz::{decode, run_bytes, Mesh, Op};

#[test]
fn every_subdivide_corpus_input_keeps_the_laws() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/subdivide");
    let mut entries: Vec<_> = std::fs::read_dir(&dir).expect("corpus directory").map(|e| e.unwrap().path()).collect();
    entries.sort();
    assert!(
        entries.len() >= 48,
        "the committed corpus holds at least this many inputs (finding 326), found {}",
        entries.len()
    );
    let (mut applied, mut refused, mut top) = (0, 0, 0);
    let mut meshes = [0; 3];
    for path in entries {
        let bytes = std::fs::read(&path).unwrap();
        meshes[decode(&bytes).0 as usize] += 1;
        match run_bytes(&bytes) {
            Ok(r) => {
                applied += r.applied;
                refused += r.refused;
                top = top.max(r.max_level);
            }
            Err(message) => panic!("{}: {message}", path.display()),
        }
    }
    // The corpus must exercise the operations, not only their refusals, in 2D and 3D.
    assert!(applied >= 100 && refused >= 10, "applied {applied}, refused {refused}");
    assert!(top >= 2, "the corpus never goes beyond level {top}");
    assert!(meshes.iter().all(|&n| n > 0), "meshes covered: {meshes:?}");
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
