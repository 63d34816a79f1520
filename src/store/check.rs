//! `check_all_laws`: every broken law of a raw document, not only the first.

use crate::gmap::InvariantViolation;
use crate::mechanics::ConservationError;
use crate::subdivide::LevelPartsError;
use crate::{CellId, DartId, GMap};

use super::raw::RawMap;
use super::Document;

/// One broken law found by [`check_all_laws`].
///
/// # Examples
///
/// ```
/// use topomech::store::{check_all_laws, Document, Finding};
/// use topomech::GMap;
///
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let mut doc = Document::from_map(&map);
/// doc.map.alpha[0] = doc.map.alpha[1]; // α0(0) := α1(0): α0 is no longer an involution
/// let report = check_all_laws(&doc, 10);
/// assert!(matches!(report.findings[0], Finding::Map(_)));
/// assert!(!report.findings[0].to_string().is_empty());
/// ```
#[derive(Debug, Clone, PartialEq)]
pub enum Finding {
    /// A law of n-G-maps (involution, quasi-manifold, cell ids), with the darts involved.
    Map(InvariantViolation),
    /// A conservation law of the mechanical attributes (checked only when the map is valid).
    Conservation(ConservationError),
    /// A malformed level record or a μ law (order, constancy) or an unclosed level, with darts.
    Level(LevelPartsError),
    /// A G-map law broken by the map extracted at `level`, with the leveled map's dart ids
    /// (checked only when the finest map is valid and every level record well formed).
    LevelMap {
        /// The level i of G_i.
        level: u8,
        /// The law broken.
        violation: InvariantViolation,
    },
    /// A document built or changed in memory that no decoder would return: the structural error
    /// of [`RawMap::check`](super::RawMap::check), mechanical attributes on a map whose dimension
    /// is not 3, or a NaN or infinite attribute (the message of the
    /// [`StoreError`](super::StoreError)). Nothing else is checked then.
    Structure(String),
    /// A body whose material [`Body::from_tets`](crate::mechanics::Body::from_tets) refuses, a
    /// volume whose Young's modulus is not the material's, or a face whose boundary flag disagrees
    /// with the map (the message of the
    /// [`StoreError`](super::StoreError) that [`Document::into_body`] returns).
    BodyState(String),
}

impl std::fmt::Display for Finding {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Finding::Map(v) => write!(f, "{v}"),
            Finding::Conservation(c) => write!(f, "conservation: {c}"),
            Finding::Level(e) => write!(f, "levels: {e}"),
            Finding::LevelMap { level, violation } => write!(f, "level {level}: {violation}"),
            Finding::Structure(message) => write!(f, "structure: {message}"),
            Finding::BodyState(message) => write!(f, "body: {message}"),
        }
    }
}

/// What [`check_all_laws`] found.
///
/// # Examples
///
/// ```
/// use topomech::store::{check_all_laws, Document};
/// use topomech::GMap;
///
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let mut doc = Document::from_map(&map);
/// let clean = check_all_laws(&doc, 10);
/// assert!(clean.valid && clean.findings.is_empty() && !clean.truncated);
/// doc.map.alpha[0] = doc.map.alpha[1];
/// let first = check_all_laws(&doc, 1);
/// assert!(!first.valid && first.findings.len() == 1 && first.truncated);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct CheckReport {
    /// Verdict: no law is broken. For n ≤ 3 this is the kernel's own `validate()` (and
    /// `check_conservation` for a body), so the listing can never contradict it.
    pub valid: bool,
    /// The broken laws found, in the order of the kernel's table, at most the limit asked for.
    pub findings: Vec<Finding>,
    /// Whether more were found than the limit.
    pub truncated: bool,
}

/// Lists up to `limit` broken laws of `doc`: involution (dangling links, αi(αi(d)) ≠ d),
/// quasi-manifold (αiαj ≠ αjαi for j ≥ i + 2), cell ids constant and live on each cell, cell ids
/// unique (one id per orbit, no orphan live id), then, for a body whose map is valid, its material
/// and face boundary flags and conservation,
/// then, for a document with levels: malformed records, μt ≤ μf ≤ μa and μ constant on cells at
/// every dart, and (when the map is valid and the records well formed) every law of every
/// extracted level G_0 … G_k and the flat flag of every dart (the one its level and link history
/// determine, [`crate::subdivide::LevelError::FlatFlag`]), with the leveled map's dart ids.
/// The verdict comes from the kernel's `validate()` when n ≤ 3; the listing is a separate pass
/// on the raw arrays that never stops at the first violation. A document no decoder would return
/// (built or changed in memory: [`RawMap::check`](super::RawMap::check) refuses its structure, or
/// an attribute is NaN or infinite) gets one [`Finding::Structure`] and nothing else is checked.
/// Cost O(capacity · n² + cell ids) time and memory, O(k · capacity · n²) with k levels.
///
/// # Examples
///
/// ```
/// # use topomech::store::{check_all_laws, Document};
/// # use topomech::GMap;
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let mut doc = Document::from_map(&map);
/// assert!(check_all_laws(&doc, 10).valid);
/// doc.map.alpha[0] = doc.map.alpha[1]; // α0(0) := α1(0): α0 is no longer an involution
/// let report = check_all_laws(&doc, 10);
/// assert!(!report.valid && !report.findings.is_empty());
/// ```
pub fn check_all_laws(doc: &Document, limit: usize) -> CheckReport {
    let mut out = Collector { findings: Vec::new(), limit, truncated: false };
    let raw = &doc.map;
    let non_finite = doc.mechanics.as_ref().and_then(|m| m.first_non_finite());
    let structure = raw.check().err().map(|e| e.to_string()).or_else(|| {
        let dimension = doc.mechanics.as_ref().and_then(|_| super::mechanics_dimension(raw).err());
        dimension.or_else(|| {
            let at = super::Where::Document;
            non_finite.map(|(field, index)| super::StoreError::NonFinite { at, field, index }.to_string())
        })
    });
    if let Some(message) = structure {
        out.push(Finding::Structure(message));
        return CheckReport { valid: false, findings: out.findings, truncated: out.truncated };
    }
    let live = raw.live();
    involution_and_quasi_manifold(raw, &live, &mut out);
    cell_ids_constant(raw, &live, &mut out);
    cell_ids_unique(raw, &live, &mut out);
    let verdict = kernel_verdict(raw);
    let map_valid = verdict.as_ref().map_or(out.findings.is_empty(), |v| v.is_ok());
    if let Some(Err(first)) = &verdict {
        // Never report "invalid" with an empty listing: the kernel's first violation is a finding.
        if out.findings.is_empty() {
            out.push(Finding::Map(first.clone()));
        }
    }
    let mut valid = map_valid;
    if map_valid {
        if let (Some(mech), 3) = (&doc.mechanics, raw.dimension) {
            if let Ok(map) = raw.to_gmap_raw::<3>() {
                // The material and the flags first: a bad material breaks every mass law after it.
                let mechanics = mech.to_mechanics();
                if let Err(e) = super::check_body_state(&map, &mechanics) {
                    valid = false;
                    out.push(Finding::BodyState(e.to_string()));
                }
                // Every conservation violation, not only the first (one more than the room left, so
                // the collector sees the listing is truncated).
                let room = limit.saturating_sub(out.findings.len()).saturating_add(1);
                for e in crate::mechanics::conservation_violations(&map, &mechanics, room) {
                    valid = false;
                    out.push(Finding::Conservation(e));
                }
            }
        }
    }
    if super::check_levels::check_levels(doc, map_valid, &mut out) {
        valid = false;
    }
    CheckReport { valid, findings: out.findings, truncated: out.truncated }
}

pub(super) struct Collector {
    findings: Vec<Finding>,
    limit: usize,
    truncated: bool,
}

impl Collector {
    pub(super) fn push(&mut self, f: Finding) {
        if self.findings.len() < self.limit {
            self.findings.push(f);
        } else {
            self.truncated = true;
        }
    }

    fn map(&mut self, v: InvariantViolation) {
        self.push(Finding::Map(v));
    }
}

/// The kernel's verdict for n ≤ 3 (`None` for higher dimensions).
fn kernel_verdict(raw: &RawMap) -> Option<Result<(), InvariantViolation>> {
    fn verdict<const N: usize>(raw: &RawMap) -> Option<Result<(), InvariantViolation>> {
        raw.to_gmap_raw::<N>().ok().map(|m: GMap<N>| m.validate())
    }
    match raw.dimension {
        1 => verdict::<1>(raw),
        2 => verdict::<2>(raw),
        3 => verdict::<3>(raw),
        _ => None,
    }
}

/// αi(d) if it is a live dart.
fn link(raw: &RawMap, live: &[bool], i: usize, d: u32) -> Option<u32> {
    let a = raw.alpha(i, d);
    live[a as usize].then_some(a)
}

fn involution_and_quasi_manifold(raw: &RawMap, live: &[bool], out: &mut Collector) {
    let n = raw.dimension;
    let mut link_ok = vec![true; live.len() * (n + 1)];
    for d in (0..raw.capacity).filter(|&d| live[d as usize]) {
        for i in 0..=n {
            let dart = DartId(d);
            match link(raw, live, i, d) {
                None => out.map(InvariantViolation::DanglingLink { dart, i, target: DartId(raw.alpha(i, d)) }),
                Some(a) if raw.alpha(i, a) != d => {
                    let back = DartId(raw.alpha(i, a));
                    out.map(InvariantViolation::NotInvolution { dart, i, image: DartId(a), back });
                }
                Some(_) => continue,
            }
            link_ok[d as usize * (n + 1) + i] = false;
        }
    }
    let ok = |i: usize, d: u32| link_ok[d as usize * (n + 1) + i];
    for d in (0..raw.capacity).filter(|&d| live[d as usize]) {
        for i in 0..=n {
            for j in i + 2..=n {
                if !(ok(i, d) && ok(j, d) && ok(i, raw.alpha(j, d)) && ok(j, raw.alpha(i, d))) {
                    continue;
                }
                let (ij, ji) = (raw.alpha(i, raw.alpha(j, d)), raw.alpha(j, raw.alpha(i, d)));
                if ij != ji {
                    out.map(InvariantViolation::QuasiManifold {
                        dart: DartId(d),
                        i,
                        j,
                        ij: DartId(ij),
                        ji: DartId(ji),
                    });
                }
            }
        }
    }
}

fn is_live_id(raw: &RawMap, dim: usize, id: u32, dead_ids: &[Vec<bool>]) -> bool {
    id < raw.ids[dim].next && !dead_ids[dim][id as usize]
}

fn dead_id_table(raw: &RawMap) -> Vec<Vec<bool>> {
    raw.ids
        .iter()
        .map(|rec| {
            let mut dead = vec![false; rec.next as usize];
            rec.free.iter().for_each(|&id| dead[id as usize] = true);
            dead
        })
        .collect()
}

fn cell_ids_constant(raw: &RawMap, live: &[bool], out: &mut Collector) {
    let n = raw.dimension;
    let dead_ids = dead_id_table(raw);
    for d in (0..raw.capacity).filter(|&d| live[d as usize]) {
        for dim in 0..=n {
            let id = raw.cell(dim, d);
            if !is_live_id(raw, dim, id, &dead_ids) {
                out.map(InvariantViolation::CellIdNotLive { dart: DartId(d), dim, id: CellId(id) });
            }
            for j in (0..=n).filter(|&j| j != dim) {
                // Each unordered pair once; a dangling link was reported already.
                let Some(a) = link(raw, live, j, d).filter(|&a| a > d) else { continue };
                let other_id = raw.cell(dim, a);
                if other_id != id {
                    let (dart, other) = (DartId(d), DartId(a));
                    out.map(InvariantViolation::CellIdDiffers {
                        dart,
                        dim,
                        j,
                        id: CellId(id),
                        other,
                        other_id: CellId(other_id),
                    });
                }
            }
        }
    }
}

/// Per dimension: flood-fills the orbits ⟨αj : j ≠ dim⟩ over live links (dangling ones are
/// skipped: they were reported), records the first orbit of each id, and reports a
/// second orbit carrying it and live ids no dart carries.
fn cell_ids_unique(raw: &RawMap, live: &[bool], out: &mut Collector) {
    let n = raw.dimension;
    let dead_ids = dead_id_table(raw);
    let cap = raw.capacity as usize;
    for (dim, dead) in dead_ids.iter().enumerate() {
        let mut owner: Vec<u32> = vec![u32::MAX; raw.ids[dim].next as usize];
        let mut carried = vec![false; raw.ids[dim].next as usize];
        let mut seen = vec![false; cap];
        let mut stack = Vec::new();
        for start in (0..raw.capacity).filter(|&d| live[d as usize]) {
            if seen[start as usize] {
                continue;
            }
            seen[start as usize] = true;
            stack.push(start);
            // Ids met in this orbit, each reported at most once per orbit.
            let mut orbit_ids: Vec<u32> = Vec::new();
            while let Some(d) = stack.pop() {
                let id = raw.cell(dim, d);
                if id < raw.ids[dim].next && !orbit_ids.contains(&id) {
                    orbit_ids.push(id);
                }
                for j in (0..=n).filter(|&j| j != dim) {
                    if let Some(a) = link(raw, live, j, d) {
                        if !std::mem::replace(&mut seen[a as usize], true) {
                            stack.push(a);
                        }
                    }
                }
            }
            for id in orbit_ids {
                carried[id as usize] = true;
                match owner[id as usize] {
                    u32::MAX => owner[id as usize] = start,
                    first => out.map(InvariantViolation::CellIdShared {
                        dim,
                        id: CellId(id),
                        first: DartId(first),
                        second: DartId(start),
                    }),
                }
            }
        }
        for id in 0..raw.ids[dim].next {
            if !carried[id as usize] && !dead[id as usize] {
                out.map(InvariantViolation::CellIdOrphan { dim, id: CellId(id) });
            }
        }
    }
}
