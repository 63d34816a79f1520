//! Replays every input of the committed fuzz corpus (`fuzz/corpus/kernel_ops/`) on stable, as
//! the fuzz target runs it: `ops::run_bytes` with every law checked after every step.

use std::path::Path;

#[test]
fn every_corpus_input_keeps_the_laws() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/kernel_ops");
    let mut entries: Vec<_> = std::fs::read_dir(&dir).expect("corpus directory").map(|e| e.unwrap().path()).collect();
    entries.sort();
    assert!(
        entries.len() >= 51,
        "the committed corpus holds at least this many inputs (finding 326), found {}",
        entries.len()
    );
    for path in entries {
        let bytes = std::fs::read(&path).unwrap();
        if let Err(message) = topomech::ops::run_bytes(&bytes) {
            panic!("{}: {message}", path.display());
        }
    }
}

/// The replay can fail: an input whose laws are checked against a wrong claim is caught (the
/// checker is the same one the corpus goes through).
#[test]
fn the_replayed_checker_catches_a_false_claim() {
    let mut map = topomech::GMap::<3>::new();
    let op = topomech::ops::KernelOp::CreateDart;
    let before = map.clone();
    let _ = topomech::ops::apply(&mut map, &op);
    let lie: Result<topomech::ops::Applied, topomech::ops::OpError> = Ok(topomech::ops::Applied::Nothing);
    assert!(topomech::ops::check_after_op(&before, &map, &op, &lie).is_err());
}
