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
    assert!(files.len() >= 15, "the committed corpus holds 15 files at least (finding 326), found {}", files.len());
    let mut ambiguous = 0;
    // Cut-mode inputs with at least one cut that split no vertex or edge: those that reach
    // invariant 4 (same vertex–edge graph as the uncut map, yet not isomorphic to it).
    let mut skeleton_kept = 0;
    let mut cuts = 0;
    let mut subdivisions = 0;
    for f in &files {
        let bytes = std::fs::read(f).expect("readable corpus file");
        let report = check_bytes(&bytes).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        ambiguous += usize::from(report.ambiguous);
        cuts += report.cuts;
        subdivisions += report.subdivisions;
        skeleton_kept +=
            usize::from(bytes.first().is_some_and(|&b| b < 128) && report.cuts > 0 && report.skeleton_unchanged);
    }
    assert!(ambiguous > 0, "some corpus input ends with an ambiguous indexed model");
    assert!(cuts > 20, "the corpus exercises cuts ({cuts})");
    assert!(subdivisions >= 10, "the mixed-mode files exercise subdivisions ({subdivisions})");
    assert!(skeleton_kept >= 3, "only {skeleton_kept} cut-mode inputs reach invariant 4 (`cube2_*skeleton_kept`)");
}
