//! Property tests of the ambiguity comparison. The strategy generates the very byte strings the
//! cargo-fuzz target `fuzz/fuzz_targets/ambiguity.rs` and the corpus replay
//! (`tests/ambiguity_fuzz_replay.rs`) feed to `topomech::ambiguity::fuzz::check_bytes`: one
//! decoder, three engines. A failing case is shrunk by proptest to a byte string that can be
//! dropped into `fuzz/corpus/ambiguity/` as is.

use proptest::prelude::*;
use topomech::ambiguity::fuzz::{check_bytes, decode_ops, MIXED};

/// Cut-mode inputs: byte 0 below [`MIXED`], then face indices.
fn cut_bytes() -> impl Strategy<Value = Vec<u8>> {
    (0u8..MIXED, prop::collection::vec(any::<u8>(), 0..24)).prop_map(|(b0, rest)| [vec![b0], rest].concat())
}

/// Mixed-mode inputs: byte 0 at or above [`MIXED`], then ops, about one in three a subdivision.
fn mixed_bytes() -> impl Strategy<Value = Vec<u8>> {
    let op = prop_oneof![2 => 0u8..192, 1 => 192u8..=255];
    (MIXED..=255u8, prop::collection::vec(op, 0..14)).prop_map(|(b0, rest)| [vec![b0], rest].concat())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn cut_mode_invariants_hold(bytes in cut_bytes()) {
        let report = check_bytes(&bytes).map_err(|e| TestCaseError::fail(format!("{bytes:?}: {e}")))?;
        prop_assert!(report.cuts <= bytes.len().saturating_sub(1));
        prop_assert_eq!(report.subdivisions, 0);
    }

    #[test]
    fn mixed_mode_invariants_hold(bytes in mixed_bytes()) {
        let report = check_bytes(&bytes).map_err(|e| TestCaseError::fail(format!("{bytes:?}: {e}")))?;
        let ops = decode_ops(&bytes[1..]);
        prop_assert!(report.cuts + report.subdivisions <= ops.len());
        // A subdivision next to an unrefined neighbour leaves hanging midpoints: every mesh here
        // has a neighbour for every tet, so the indexed model is ambiguous after one.
        if report.subdivisions == 1 && report.cuts == 0 {
            prop_assert!(report.ambiguous, "{:?}", bytes);
        }
    }
}
