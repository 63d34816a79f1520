//! Replays every input of the committed `cuts` fuzz corpus (`fuzz/corpus/cuts/`) on stable, as the
//! fuzz target runs it: `cut::ops::run_bytes`, every law checked after every step.

use std::path::Path;

use topomech::cut::ops::{decode, jittered_cube, Harness, Op};

#[test]
fn every_cuts_corpus_input_keeps_the_laws() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/cuts");
    let mut entries: Vec<_> = std::fs::read_dir(&dir).expect("corpus directory").map(|e| e.unwrap().path()).collect();
    entries.sort();
    assert!(
        entries.len() >= 133,
        "the committed corpus holds at least this many inputs (finding 326), found {}",
        entries.len()
    );
    let mut ops = 0;
    for path in entries {
        let bytes = std::fs::read(&path).unwrap();
        ops += decode(&bytes).ops.len();
        if let Err(message) = topomech::cut::ops::run_bytes(&bytes) {
            panic!("{}: {message}", path.display());
        }
    }
    assert!(ops >= 200, "the corpus exercises only {ops} ops");
}

/// The replayed checker can fail: a projection left stale after a dissociation (the update
/// skipped) is caught by `Harness::check`.
#[test]
fn the_replayed_checker_catches_a_skipped_update() {
    let (points, tets) = jittered_cube(1, 3);
    let mut h = Harness::new(points, tets).unwrap();
    let stale = h.projection.clone();
    h.apply(Op::Dissociate(0)).unwrap();
    h.check().unwrap();
    h.projection = stale;
    assert!(h.check().is_err(), "a stale projection passed the check");
}
