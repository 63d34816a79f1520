//! Structural checks shared by both decoders: what must hold for the raw arrays to be turned into
//! a map without a panic or an unbounded allocation (the laws themselves are checked later).

use super::raw::{RawMap, UNSET};
use super::{StoreError, Where, MAX_DIMENSION};

/// Checks a map built or changed in memory (not read by a decoder) for everything the decoders
/// guarantee: the dimension, arrays of `capacity · (n + 1)` entries, one allocator per dimension,
/// every link a dart slot, then [`check`]. Errors are located at [`Where::Document`].
/// O(capacity · n + free ids).
pub(super) fn check_shape(raw: &RawMap) -> Result<(), StoreError> {
    let at = Where::Document;
    if raw.dimension == 0 || raw.dimension > MAX_DIMENSION {
        return Err(StoreError::BadDimension { at, found: raw.dimension as u64 });
    }
    if raw.capacity == UNSET {
        let (what, limit) = ("dart capacity", u64::from(UNSET) - 1);
        return Err(StoreError::BadCount { at, what, count: raw.capacity.into(), limit });
    }
    let n1 = raw.alphas();
    let slots = raw.capacity as usize * n1;
    for (what, len) in [("alpha", raw.alpha.len()), ("cell", raw.cell.len())] {
        if len != slots {
            let message =
                format!("the {what} array has {len} entries, not {} dart slots × {n1} = {slots}", raw.capacity);
            return Err(StoreError::Inconsistent { at, message });
        }
    }
    if raw.ids.len() != n1 {
        let message = format!(
            "{} cell-id allocators for dimension {} (one per dimension 0..={})",
            raw.ids.len(),
            raw.dimension,
            raw.dimension
        );
        return Err(StoreError::Inconsistent { at, message });
    }
    if let Some(&a) = raw.alpha.iter().find(|&&a| a >= raw.capacity) {
        return Err(StoreError::DartOutOfRange { at, dart: a.into(), capacity: raw.capacity.into() });
    }
    check(raw, at)
}

/// Checks the free dart list (in range, no repeats, dead rows canonical) and the id allocators
/// (free ids below `next`, no repeats, live ids ≤ dart slots). `at` locates the allocator lines.
/// O(capacity · n + free ids).
pub(super) fn check(raw: &RawMap, at: Where) -> Result<(), StoreError> {
    let n1 = raw.alphas();
    let mut dead = vec![false; raw.capacity as usize];
    for &d in &raw.free_darts {
        if d >= raw.capacity {
            return Err(StoreError::DartOutOfRange { at, dart: d.into(), capacity: raw.capacity.into() });
        }
        if std::mem::replace(&mut dead[d as usize], true) {
            return Err(StoreError::Inconsistent { at, message: format!("dart slot {d} is listed twice as free") });
        }
        let row = d as usize * n1..(d as usize + 1) * n1;
        if raw.alpha[row.clone()].iter().any(|&a| a != d) || raw.cell[row].iter().any(|&c| c != UNSET) {
            let message = format!("free dart slot {d} has links or cell ids (a dead slot must be blank)");
            return Err(StoreError::Inconsistent { at, message });
        }
    }
    for (i, rec) in raw.ids.iter().enumerate() {
        let mut seen = std::collections::HashSet::with_capacity(rec.free.len());
        for &id in &rec.free {
            if id >= rec.next || !seen.insert(id) {
                let message = format!("free {i}-cell id {id} is not below next = {} or is listed twice", rec.next);
                return Err(StoreError::Inconsistent { at, message });
            }
        }
        let live_ids = u64::from(rec.next) - rec.free.len() as u64;
        if live_ids > u64::from(raw.capacity) {
            let (what, limit) = ("live cell ids (next − free)", raw.capacity.into());
            return Err(StoreError::BadCount { at, what, count: live_ids, limit });
        }
    }
    Ok(())
}
