//! Structural checks shared by both decoders: what must hold for the raw arrays to be turned into
//! a map without a panic or an unbounded allocation (the laws themselves are checked later).

use super::raw::{RawMap, UNSET};
use super::{StoreError, Where};

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
