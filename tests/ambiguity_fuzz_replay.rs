//! Replays the corpus of the `ambiguity` fuzz target (`fuzz/corpus/ambiguity/`) through the same
//! checker, so the invariants run on every `cargo test` without cargo-fuzz. The files `mixed_*`
//! (byte 0 ≥ 128) drive the mixed cut/subdivide mode; the others the cut mode.

use std::path::Path;

use topomech::ambiguity::fuzz::check_bytes;

#[test]
fn the_fuzz_corpus_replays() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/ambiguity");
    let mut files: Vec<_> =
        std::fs::read_dir(&dir).expect("corpus directory").map(|e| e.expect("entry").path()).collect();
    files.sort();
    assert!(files.len() >= 11, "the committed corpus holds 11 files at least (finding 326), found {}", files.len());
    let mut ambiguous = 0;
    let mut cuts = 0;
    let mut subdivisions = 0;
    for f in &files {
        let bytes = std::fs::read(f).expect("readable corpus file");
        let report = check_bytes(&bytes).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        ambiguous += usize::from(report.ambiguous);
        cuts += report.cuts;
        subdivisions += report.subdivisions;
    }
    assert!(ambiguous > 0, "some corpus input ends with an ambiguous indexed model");
    assert!(cuts > 20, "the corpus exercises cuts ({cuts})");
    assert!(subdivisions >= 10, "the mixed-mode files exercise subdivisions ({subdivisions})");
}
