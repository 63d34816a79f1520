//! Kani proof harnesses. Under `cargo test` each runs as a randomized test of a few thousand
//! seeded cases (see [`crate::kani_shim`]); under `cargo kani --tests` each is a bounded proof.
//! The inputs are small fixed-size byte arrays decoded by the shared `ops::decode`, so the
//! harnesses explore the same operation space as proptest and the fuzzer.

use crate::kani_shim::{any, assume, cases};
use crate::laws::{check_sew, check_unsew, check_validate_names_law};
use topomech::ops::{self, KernelOp, RawEdit};
use topomech::{DartId, GMap};

/// Darts a [`small_map`] holds at most: 4 created, then at most one per decoded operation (12
/// bytes: 12 creates at most). Every loop over its darts runs at most this often, so the proofs
/// over small maps unwind once more (`kani::unwind(17)`; finding 316, checked against the
/// attributes by `unwind_bounds_cover_the_small_maps`).
const SMALL_MAP_DARTS: usize = 16;

/// A small map: a few darts, a few decoded operations (no Grow, to keep proofs bounded), then
/// four direct i-sews of any two of its darts: a sew takes 6 of the 12 decoded bytes, so without
/// them two maps in three held no link at all and a sew that propagated one level only passed
/// every harness (finding 317).
fn small_map<const N: usize>() -> Option<GMap<N>> {
    let bytes: [u8; 12] = any();
    let mut map = GMap::<N>::new();
    for _ in 0..1 + any::<u8>() % 4 {
        map.create_dart().ok()?;
    }
    for op in ops::decode(&bytes) {
        if !matches!(op, KernelOp::Grow { .. }) {
            let _ = ops::apply(&mut map, &op);
        }
    }
    let sews: [u8; 12] = any();
    let cap = map.capacity().max(1) as u32;
    for s in sews.chunks(3) {
        let (i, a, b) = (usize::from(s[0]) % (N + 1), DartId(u32::from(s[1]) % cap), DartId(u32::from(s[2]) % cap));
        if map.contains(a) && map.contains(b) {
            let _ = map.sew_dyn(i, a, b);
        }
    }
    debug_assert!(map.capacity() <= SMALL_MAP_DARTS);
    Some(map)
}

/// decode is total and bounded, and encode inverts it.
#[cfg_attr(kani, kani::proof)]
#[cfg_attr(kani, kani::unwind(20))]
#[cfg_attr(not(kani), test)]
fn decode_is_total_and_encode_inverts_it() {
    cases(4000, || {
        let bytes: [u8; 16] = any();
        if let Err(e) = ops::check_decode(&bytes) {
            panic!("{bytes:?}: {e}");
        }
    });
}

/// Every short op sequence on a small 2-map of 1 to 4 darts keeps every law of
/// `check_after_op` (from an empty map, half the sequences ended with no dart and 4 % changed a
/// link: finding 318).
#[cfg_attr(kani, kani::proof)]
#[cfg_attr(kani, kani::unwind(17))]
#[cfg_attr(not(kani), test)]
fn short_sequences_keep_the_laws() {
    cases(3000, || {
        let bytes: [u8; 12] = any();
        let mut map = GMap::<2>::new();
        for _ in 0..1 + any::<u8>() % 4 {
            if map.create_dart().is_err() {
                return;
            }
        }
        let ops: Vec<KernelOp> =
            ops::decode(&bytes).into_iter().filter(|op| !matches!(op, KernelOp::Grow { .. })).collect();
        if let Err(e) = ops::run_ops(&mut map, &ops) {
            panic!("{bytes:?}: {e}");
        }
    });
}

/// Any i-sew of any two darts of a small 3-map is either refused without change (and then
/// is_sewable is false) or gives a valid map with exact cell ids, undone by an unsew.
#[cfg_attr(kani, kani::proof)]
#[cfg_attr(kani, kani::unwind(17))]
#[cfg_attr(not(kani), test)]
fn any_sew_is_refused_cleanly_or_exact() {
    cases(3000, || {
        let Some(map) = small_map::<3>() else { return };
        let cap = map.capacity() as u32;
        let (i, a, b) = (any::<u8>() % 5, any::<u32>(), any::<u32>());
        if !assume(cap > 0) {
            return;
        }
        if let Err(e) = check_sew(&map, usize::from(i), DartId(a % cap), DartId(b % cap)) {
            panic!("{e}");
        }
    });
}

/// Any unsew of a sewn dart of a small 2-map gives a valid map with exact cell ids. The link is
/// drawn among the map's links (a dart and an i drawn at random were linked in 7 % of the cases:
/// finding 319).
#[cfg_attr(kani, kani::proof)]
#[cfg_attr(kani, kani::unwind(17))]
#[cfg_attr(not(kani), test)]
fn any_unsew_is_exact() {
    cases(3000, || {
        let Some(map) = small_map::<2>() else { return };
        let links: Vec<(usize, DartId)> =
            map.darts().flat_map(|d| (0..3).map(move |i| (i, d))).filter(|&(i, d)| !map.is_free(i, d)).collect();
        if !assume(!links.is_empty()) {
            return;
        }
        let (i, d) = links[any::<u32>() as usize % links.len()];
        if let Err(e) = check_unsew(&map, i, d) {
            panic!("{e}");
        }
    });
}

/// After any raw corruption of a small valid 2-map, validate() fails iff a law is broken and
/// names a broken law with a true witness.
#[cfg_attr(kani, kani::proof)]
#[cfg_attr(kani, kani::unwind(17))]
#[cfg_attr(not(kani), test)]
fn validate_names_any_single_corruption() {
    cases(3000, || {
        let Some(mut map) = small_map::<2>() else { return };
        let cap = map.capacity() as u32;
        let (kind, i, a, b, id) =
            (any::<u8>() % 3, usize::from(any::<u8>() % 3), any::<u32>() % cap, any::<u32>() % cap, any::<u8>());
        let edit = match kind {
            0 => RawEdit::Link { i, a: DartId(a), b: DartId(b) },
            1 => RawEdit::Unlink { i, a: DartId(a) },
            _ => RawEdit::SetCell { dim: i, d: DartId(a), id: u32::from(id % 8) },
        };
        if !assume(ops::raw_edit_unchecked(&mut map, edit)) {
            return;
        }
        if let Err(e) = check_validate_names_law(&map) {
            panic!("{edit:?}: {e}");
        }
    });
}

/// The darts of face `f` of tet `t` (built layout: 24t + 6f + j) in the order φ(j) of the flag
/// bijection onto itself that commutes with α0 and α1 and sends flag 0 to flag `r`: the α0/α1
/// words from flag 0, applied to flag r instead. A gluing along it satisfies the quasi-manifold
/// laws with α0 and α1, so only the ids (or a partner left behind) can break a law.
fn face_flags_from(map: &GMap<3>, t: u32, f: u32, r: u32) -> [DartId; 6] {
    let first = 24 * t + 6 * f;
    let (mut from_zero, mut from_r) = (vec![DartId(first)], vec![DartId(first + r)]);
    let mut head = 0;
    while head < from_zero.len() {
        for i in 0..2 {
            let next = map.alpha_dyn(i, from_zero[head]);
            if !from_zero.contains(&next) {
                from_zero.push(next);
                from_r.push(map.alpha_dyn(i, from_r[head]));
            }
        }
        head += 1;
    }
    let mut out = [DartId(first); 6];
    for (x, y) in from_zero.iter().zip(&from_r) {
        out[(x.0 - first) as usize] = *y;
    }
    out
}

/// After any two raw edits that keep the tets-as-built flag — α3 links and unlinks, cell-id
/// overwrites, and whole-face gluings along a flag bijection that commutes with α0 and α1 — of
/// two built tets sharing a face, validate() (which then takes its tet path) fails iff a law is
/// broken and names the first broken law with a true witness.
#[cfg_attr(kani, kani::proof)]
#[cfg_attr(kani, kani::unwind(50))]
#[cfg_attr(not(kani), test)]
fn validate_tet_path_names_any_double_corruption() {
    let (built, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
    cases(3000, || {
        let mut map = built.clone();
        let cap = map.capacity() as u32;
        for _ in 0..2 {
            let (kind, a, b, dim, id) =
                (any::<u8>() % 5, any::<u32>() % cap, any::<u32>() % cap, any::<u8>() % 4, any::<u8>());
            let edits: Vec<RawEdit> = match kind {
                // A whole cell relabelled with another cell's id: two orbits, one id (the
                // tet path's CellIdUnique, never named by the single-dart edits: finding 323).
                4 => {
                    let (dim, b) = (usize::from(dim), DartId(b));
                    let id = map.cell_id(dim, b).0;
                    map.cell_darts(dim, DartId(a)).into_iter().map(|d| RawEdit::SetCell { dim, d, id }).collect()
                }
                0 => vec![RawEdit::Link { i: 3, a: DartId(a), b: DartId(b) }],
                1 => vec![RawEdit::Unlink { i: 3, a: DartId(a) }],
                2 => vec![RawEdit::SetCell { dim: usize::from(dim), d: DartId(a), id: u32::from(id % 12) }],
                _ => {
                    let (from, onto) = (
                        face_flags_from(&map, a / 24, a % 24 / 6, 0),
                        face_flags_from(&map, b / 24, b % 24 / 6, u32::from(id % 6)),
                    );
                    from.iter().zip(&onto).map(|(&a, &b)| RawEdit::Link { i: 3, a, b }).collect()
                }
            };
            for edit in edits {
                if !assume(ops::raw_edit_unchecked(&mut map, edit)) {
                    return;
                }
            }
        }
        assert!(map.tets_as_built(), "the edits keep the flag");
        if let Err(e) = check_validate_names_law(&map) {
            panic!("{e}");
        }
    });
}

/// The unwind bounds of the harnesses over small maps cover their largest map: 4 darts and 12
/// decoded creates make [`SMALL_MAP_DARTS`] darts, and every such harness (and the short
/// sequences, built the same way) unwinds at least once more than that (finding 316: they
/// unwound 16 times, one short, so real Kani would have stopped on an unwinding assertion).
#[cfg(not(kani))]
#[test]
fn unwind_bounds_cover_the_small_maps() {
    let mut map = GMap::<2>::new();
    for _ in 0..4 {
        map.create_dart().unwrap();
    }
    for op in ops::decode(&[0u8; 12]) {
        ops::apply(&mut map, &op).unwrap();
    }
    assert_eq!(map.capacity(), SMALL_MAP_DARTS);
    let source = include_str!("harnesses.rs");
    let mut checked = 0;
    // Each harness from its proof attribute to the end of its body (the markers are built with
    // `concat!` so that this test's own text does not contain them).
    let proof = concat!("#[cfg_attr(kani, ", "kani::proof)]");
    for chunk in source.split(proof).skip(1) {
        let chunk = &chunk[..chunk.find("\n}\n").unwrap()];
        let unwind = concat!("kani::", "unwind(");
        let Some(at) = chunk.find(unwind) else { continue };
        let rest = &chunk[at + unwind.len()..];
        let bound: usize = rest[..rest.find(')').unwrap()].parse().unwrap();
        let name = chunk.split("fn ").nth(1).unwrap().split('(').next().unwrap();
        if chunk.contains(concat!("small_map", "::<")) || name == "short_sequences_keep_the_laws" {
            assert!(bound > SMALL_MAP_DARTS, "{name}: unwind({bound}) for maps of {SMALL_MAP_DARTS} darts");
            checked += 1;
        }
    }
    assert_eq!(checked, 4);
}
