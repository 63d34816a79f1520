//! The level laws of a document's levels part, every violation listed (what `topomech check`
//! prints for a leveled map): malformed records, μt ≤ μf ≤ μa at every dart, μ constant on the
//! cells of the finest map, every level G_0 … G_k closed, an involution at every dart and a
//! valid G-map, every dart's flat flag the one its level and link history determine, and the
//! laws of the vertices' past (origins of cut copies, the split log the history witnesses).

use crate::gmap::InvariantViolation;
use crate::subdivide::{record_errors, LevelError, LevelParts, LevelPartsError, LeveledMap};
use crate::DartId;

use super::check::{check_all_laws, Collector, Finding};
use super::raw::RawMap;
use super::Document;

/// Lists the level findings of `doc` into `out`; returns whether any law is broken. Levels are
/// extracted only when the finest map is valid (`map_valid`) and every record is well formed.
/// Maps of dimension above 3 are not checked (no leveled map of that dimension exists).
/// O(k · capacity · n²).
pub(super) fn check_levels(doc: &Document, map_valid: bool, out: &mut Collector) -> bool {
    let Some(parts) = &doc.levels else { return false };
    match doc.map.dimension {
        1 => check_dim::<1>(&doc.map, parts, map_valid, out),
        2 => check_dim::<2>(&doc.map, parts, map_valid, out),
        3 => check_dim::<3>(&doc.map, parts, map_valid, out),
        _ => false,
    }
}

fn check_dim<const N: usize>(raw: &RawMap, parts: &LevelParts, map_valid: bool, out: &mut Collector) -> bool {
    let Ok(map) = raw.to_gmap_raw::<N>() else { return false };
    let records = record_errors(&map, parts, usize::MAX);
    let mut broken = !records.is_empty();
    records.into_iter().for_each(|e| out.push(Finding::Level(e)));
    if parts.darts.len() != raw.capacity as usize {
        return true;
    }
    broken |= mu_laws(raw, parts, out);
    if map_valid && !broken {
        broken |= every_level(LeveledMap::from_parts_unchecked(map, parts.clone()), out);
    }
    broken
}

/// μt ≤ μf ≤ μa at every live dart; μa constant on edges, μf on faces, μt on volumes (each pair
/// of linked darts once; dangling links are skipped, the map laws report them).
fn mu_laws(raw: &RawMap, parts: &LevelParts, out: &mut Collector) -> bool {
    let live = raw.live();
    let mut broken = false;
    let mut law = |e: LevelError| {
        broken = true;
        out.push(Finding::Level(LevelPartsError::Law(e)));
    };
    for d in (0..raw.capacity).filter(|&d| live[d as usize]) {
        let mu = parts.darts[d as usize].mu;
        if !(mu.tet <= mu.face && mu.face <= mu.edge) {
            law(LevelError::MuOrder { dart: DartId(d), mu });
        }
        for j in 0..=raw.dimension {
            let e = raw.alpha(j, d);
            if e <= d || !live[e as usize] {
                continue;
            }
            let other = parts.darts[e as usize].mu;
            for (dim, a, b) in [(1, mu.edge, other.edge), (2, mu.face, other.face), (3, mu.tet, other.tet)] {
                if j != dim && a != b {
                    law(LevelError::MuNotConstant { dim, dart: DartId(d), a, other: DartId(e), b });
                }
            }
        }
    }
    broken
}

/// Checks that every αj^i is closed in B_i and an involution, then extracts G_0 … G_k and lists every law each breaks, with the leveled map's dart ids.
fn every_level<const N: usize>(m: LeveledMap<N>, out: &mut Collector) -> bool {
    // One-sided links first: the extracted maps link in pairs and would hide them.
    let links = m.level_link_errors(usize::MAX);
    if !links.is_empty() {
        links.into_iter().for_each(|e| out.push(Finding::Level(LevelPartsError::Law(e))));
        return true;
    }
    let mut broken = false;
    for level in 0..=m.max_level() {
        match m.level(level) {
            Err(e) => {
                broken = true;
                out.push(Finding::Level(LevelPartsError::Law(e)));
            }
            Ok(view) => {
                let report = check_all_laws(&Document::from_map::<N>(&view.map), usize::MAX);
                broken |= !report.valid;
                for f in report.findings {
                    if let Finding::Map(v) = f {
                        out.push(Finding::LevelMap { level, violation: translate(v, &view.darts) });
                    }
                }
            }
        }
    }
    // Every level is closed (checked above), so the flat law reads live darts only.
    let flats = m.flat_errors(usize::MAX);
    broken |= !flats.is_empty();
    flats.into_iter().for_each(|e| out.push(Finding::Level(LevelPartsError::Law(e))));
    // Top cells at their own level, then the vertices' past (origins, the split log).
    let past: Vec<LevelError> = m.own_level_errors(usize::MAX).into_iter().chain(m.past_errors(usize::MAX)).collect();
    broken |= !past.is_empty();
    past.into_iter().for_each(|e| out.push(Finding::Level(LevelPartsError::Law(e))));
    broken
}

/// The violation with every dart of the extracted level replaced by its leveled-map dart.
fn translate(v: InvariantViolation, darts: &[DartId]) -> InvariantViolation {
    use InvariantViolation::*;
    let t = |d: DartId| darts.get(d.index()).copied().unwrap_or(d);
    match v {
        DanglingLink { dart, i, target } => DanglingLink { dart: t(dart), i, target: t(target) },
        NotInvolution { dart, i, image, back } => NotInvolution { dart: t(dart), i, image: t(image), back: t(back) },
        QuasiManifold { dart, i, j, ij, ji } => QuasiManifold { dart: t(dart), i, j, ij: t(ij), ji: t(ji) },
        CellIdDiffers { dart, dim, j, id, other, other_id } => {
            CellIdDiffers { dart: t(dart), dim, j, id, other: t(other), other_id }
        }
        CellIdNotLive { dart, dim, id } => CellIdNotLive { dart: t(dart), dim, id },
        CellIdShared { dim, id, first, second } => CellIdShared { dim, id, first: t(first), second: t(second) },
        CellIdOrphan { dim, id } => CellIdOrphan { dim, id },
        TetLayout { dart, i, stored, built } => TetLayout { dart: t(dart), i, stored: t(stored), built: t(built) },
    }
}
