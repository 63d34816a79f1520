//! Kani proof harnesses. Under `cargo test` each runs as a randomized test of a few thousand
//! seeded cases (see [`crate::kani_shim`]); under `cargo kani --tests` each is a bounded proof.
//! The inputs are small fixed-size byte arrays decoded by the shared `ops::decode`, so the
//! harnesses explore the same operation space as proptest and the fuzzer.

use crate::kani_shim::{any, assume, cases};
use crate::laws::{check_sew, check_unsew, check_validate_names_law};
use topomech::ops::{self, KernelOp, RawEdit};
use topomech::{DartId, GMap};

/// A small map: a few darts and a few decoded operations (no Grow, to keep proofs bounded).
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
    Some(map)
}

/// decode is total and bounded, and encode inverts it.
#[cfg_attr(kani, kani::proof)]
#[cfg_attr(kani, kani::unwind(20))]
#[cfg_attr(not(kani), test)]
fn decode_is_total_and_encode_inverts_it() {
    cases(4000, || {
        let bytes: [u8; 16] = any();
        let decoded = ops::decode(&bytes);
        assert!(decoded.len() <= bytes.len());
        assert_eq!(ops::decode(&ops::encode(&decoded)), decoded);
    });
}

/// Every short op sequence on a small 2-map keeps every law of `check_after_op`.
#[cfg_attr(kani, kani::proof)]
#[cfg_attr(kani, kani::unwind(16))]
#[cfg_attr(not(kani), test)]
fn short_sequences_keep_the_laws() {
    cases(3000, || {
        let bytes: [u8; 12] = any();
        let mut map = GMap::<2>::new();
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
#[cfg_attr(kani, kani::unwind(16))]
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

/// Any unsew of a sewn dart of a small 2-map gives a valid map with exact cell ids.
#[cfg_attr(kani, kani::proof)]
#[cfg_attr(kani, kani::unwind(16))]
#[cfg_attr(not(kani), test)]
fn any_unsew_is_exact() {
    cases(3000, || {
        let Some(map) = small_map::<2>() else { return };
        let (i, d) = (usize::from(any::<u8>() % 3), any::<u32>());
        let d = DartId(d % map.capacity().max(1) as u32);
        if !assume(map.contains(d) && !map.is_free(i, d)) {
            return;
        }
        if let Err(e) = check_unsew(&map, i, d) {
            panic!("{e}");
        }
    });
}

/// After any raw corruption of a small valid 2-map, validate() fails iff a law is broken and
/// names a broken law with a true witness.
#[cfg_attr(kani, kani::proof)]
#[cfg_attr(kani, kani::unwind(16))]
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
                (any::<u8>() % 4, any::<u32>() % cap, any::<u32>() % cap, any::<u8>() % 4, any::<u8>());
            let edits: Vec<RawEdit> = match kind {
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
