//! Replays every input of the committed `cuts` fuzz corpus (`fuzz/corpus/cuts/`) on stable, as the
//! fuzz target runs it: `cut::ops::run_bytes`, every law checked after every step.

use std::path::Path;

use topomech::cut::ops::{decode, jittered_cube, run_bytes, run_ops, Harness, Op};

/// Replays each input step by step as `run_bytes` does (same decoder, cube and laws after every
/// step) and counts, per kind, the operations that changed the body (its version moved) and the
/// refusals the harness checked (a decoded op that found nothing to act on counts for neither):
/// the corpus must reach every kind, not only decode many ops.
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
    // [dissociate, remove, incise, tear] that changed the body; refused boundary faces and
    // removed tets (checked to change nothing by the harness).
    let (mut effective, mut refusals) = ([0usize; 4], 0usize);
    for path in entries {
        let bytes = std::fs::read(&path).unwrap();
        let s = decode(&bytes);
        let (points, tets) = jittered_cube(s.k, s.seed);
        let mut h = Harness::new(points, tets).unwrap();
        run_ops(&mut h, &[]).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        for (i, &op) in s.ops.iter().enumerate() {
            let version = h.body.version();
            run_ops(&mut h, &[op]).unwrap_or_else(|e| panic!("{}: step {i} {op:?}: {e}", path.display()));
            let changed = h.body.version() != version;
            match op {
                Op::Dissociate(_) => effective[0] += changed as usize,
                Op::Remove(_) => effective[1] += changed as usize,
                Op::Incise(..) => effective[2] += changed as usize,
                Op::Tear(..) => effective[3] += changed as usize,
                Op::DissociateBoundary(_) | Op::RemoveAgain(_) => {
                    assert!(!changed, "{}: step {i} {op:?} changed the body", path.display());
                    refusals += 1;
                }
            }
        }
        // The whole target on the same bytes agrees with the step-by-step replay.
        assert_eq!(run_bytes(&bytes), Ok(()), "{}", path.display());
    }
    assert!(
        effective.iter().all(|&n| n >= 20) && refusals >= 20,
        "the corpus changes the body by too few ops of some kind: [dissociate, remove, incise, tear] = \
         {effective:?}, refusals {refusals}"
    );
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
