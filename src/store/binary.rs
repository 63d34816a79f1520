//! The binary form `.tmapb` (layout in `docs/FILE_FORMAT.md`): little-endian, FNV-1a 64 checksum.

use super::raw::{IdAllocRecord, RawMap, RawMechanics, VertexRecord, UNSET};
use super::{
    structure, Document, StoreError, Where, BINARY_MAGIC, LEVELS_VERSION, MAX_DIMENSION, MIN_VERSION, ORIGINS_VERSION,
    VERSION,
};
use crate::subdivide::{DartLevels, HistoryEntry, LevelParts, Mu};

/// Bytes before the payload: magic, version, dimension, flags, payload length.
const HEADER: usize = 8 + 4 + 4 + 4 + 8;
/// Flag bit: a mechanics section follows the map.
const FLAG_MECHANICS: u32 = 1;
/// Flag bit: a levels section follows (version 2 and later).
const FLAG_LEVELS: u32 = 2;

/// FNV-1a, 64 bits, over `bytes`. O(len).
pub(super) fn fnv1a64(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3))
}

/// Writes the document. O(size).
pub(super) fn encode(doc: &Document) -> Vec<u8> {
    let m = &doc.map;
    let mut p = Vec::new();
    let put = |p: &mut Vec<u8>, x: u32| p.extend_from_slice(&x.to_le_bytes());
    put(&mut p, m.capacity);
    put(&mut p, m.free_darts.len() as u32);
    m.free_darts.iter().for_each(|&d| put(&mut p, d));
    m.alpha.iter().for_each(|&a| put(&mut p, a));
    m.cell.iter().for_each(|&c| put(&mut p, c));
    for rec in &m.ids {
        put(&mut p, rec.next);
        put(&mut p, rec.free.len() as u32);
        rec.free.iter().for_each(|&id| put(&mut p, id));
    }
    if let Some(mech) = &doc.mechanics {
        encode_mechanics(&mut p, mech);
    }
    if let Some(levels) = &doc.levels {
        encode_levels(&mut p, levels, &m.live(), doc.version());
    }
    let mut out = Vec::with_capacity(HEADER + p.len() + 8);
    out.extend_from_slice(&BINARY_MAGIC);
    out.extend_from_slice(&doc.version().to_le_bytes());
    out.extend_from_slice(&(m.dimension as u32).to_le_bytes());
    let flags =
        if doc.mechanics.is_some() { FLAG_MECHANICS } else { 0 } | if doc.levels.is_some() { FLAG_LEVELS } else { 0 };
    out.extend_from_slice(&flags.to_le_bytes());
    out.extend_from_slice(&(p.len() as u64).to_le_bytes());
    out.extend_from_slice(&p);
    let sum = fnv1a64(&out);
    out.extend_from_slice(&sum.to_le_bytes());
    out
}

fn encode_mechanics(p: &mut Vec<u8>, m: &RawMechanics) {
    let f = |p: &mut Vec<u8>, x: f64| p.extend_from_slice(&x.to_bits().to_le_bytes());
    let n = |p: &mut Vec<u8>, k: usize| p.extend_from_slice(&(k as u32).to_le_bytes());
    m.material.iter().for_each(|&x| f(p, x));
    n(p, m.vertices.len());
    for v in &m.vertices {
        v.rest.iter().chain(&v.position).chain(&v.velocity).chain(&v.force).for_each(|&x| f(p, x));
        f(p, v.mass);
        f(p, v.viscosity);
        p.push(u8::from(v.pinned));
    }
    n(p, m.edges.len());
    m.edges.iter().flatten().for_each(|&x| f(p, x));
    n(p, m.faces.len());
    for (b, normal) in &m.faces {
        p.push(u8::from(*b));
        normal.iter().for_each(|&x| f(p, x));
    }
    n(p, m.volumes.len());
    m.volumes.iter().flatten().for_each(|&x| f(p, x));
}

/// u8 max level; per live dart (increasing id): u8 level, μa, μf, μt, flat, u32 h, h × (u8 level,
/// u8 j, u32 old); u32 np, np × 3 f64; from version 3 on, u32 no, no × (u32 copy, u32 origin).
fn encode_levels(p: &mut Vec<u8>, l: &LevelParts, live: &[bool], version: u32) {
    p.push(l.max_level);
    for rec in l.darts.iter().enumerate().filter(|&(d, _)| live[d]).map(|(_, r)| r) {
        p.extend_from_slice(&[rec.level, rec.mu.edge, rec.mu.face, rec.mu.tet, u8::from(rec.flat)]);
        p.extend_from_slice(&(rec.history.len() as u32).to_le_bytes());
        for h in &rec.history {
            p.extend_from_slice(&[h.level, h.j]);
            p.extend_from_slice(&h.old.to_le_bytes());
        }
    }
    p.extend_from_slice(&(l.points.len() as u32).to_le_bytes());
    l.points.iter().flatten().for_each(|x| p.extend_from_slice(&x.to_bits().to_le_bytes()));
    if version >= ORIGINS_VERSION {
        p.extend_from_slice(&(l.origins.len() as u32).to_le_bytes());
        l.origins.iter().flatten().for_each(|x| p.extend_from_slice(&x.to_le_bytes()));
    }
}

/// A bounds-checked little-endian reader that knows its absolute offset.
struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize, expected: &str) -> Result<&'a [u8], StoreError> {
        match self.bytes.get(self.pos..self.pos.saturating_add(n)) {
            Some(s) if self.pos.checked_add(n).is_some() => {
                self.pos += n;
                Ok(s)
            }
            _ => Err(StoreError::Truncated { at: Where::Byte(self.pos), expected: expected.into() }),
        }
    }

    fn u32(&mut self, what: &str) -> Result<u32, StoreError> {
        let s = self.take(4, what)?;
        Ok(u32::from_le_bytes([s[0], s[1], s[2], s[3]]))
    }

    fn u8(&mut self, what: &str) -> Result<u8, StoreError> {
        Ok(self.take(1, what)?[0])
    }

    fn u64(&mut self, what: &str) -> Result<u64, StoreError> {
        let s = self.take(8, what)?;
        let mut b = [0u8; 8];
        b.copy_from_slice(s);
        Ok(u64::from_le_bytes(b))
    }

    fn f64(&mut self, field: &'static str, index: usize) -> Result<f64, StoreError> {
        let at = Where::Byte(self.pos);
        let x = f64::from_bits(self.u64(field)?);
        if x.is_finite() {
            Ok(x)
        } else {
            Err(StoreError::NonFinite { at, field, index })
        }
    }

    fn flag(&mut self, what: &str) -> Result<bool, StoreError> {
        let at = Where::Byte(self.pos);
        match self.take(1, what)?[0] {
            0 => Ok(false),
            1 => Ok(true),
            b => Err(StoreError::Inconsistent { at, message: format!("{what}: flag byte {b} is not 0 or 1") }),
        }
    }

    /// A count of records of `size` bytes each, checked against the bytes left.
    fn count(&mut self, what: &'static str, size: usize) -> Result<usize, StoreError> {
        let at = Where::Byte(self.pos);
        let count = u64::from(self.u32(what)?);
        let limit = ((self.bytes.len() - self.pos) / size.max(1)) as u64;
        if count > limit {
            return Err(StoreError::BadCount { at, what, count, limit });
        }
        Ok(count as usize)
    }

    /// `count` u32 values (the caller has bounded `count` by the bytes left).
    fn u32s(&mut self, count: usize, what: &str) -> Result<Vec<u32>, StoreError> {
        let s = self.take(count.saturating_mul(4), what)?;
        Ok(s.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect())
    }
}

/// Parses the binary form: header, checksum, then the payload with its structure checked.
pub(super) fn decode(bytes: &[u8]) -> Result<Document, StoreError> {
    let mut r = Reader { bytes, pos: BINARY_MAGIC.len() };
    let version_at = Where::Byte(r.pos);
    let version = r.u32("the format version")?;
    if !(MIN_VERSION..=VERSION).contains(&version) {
        return Err(StoreError::UnsupportedVersion { at: version_at, found: version.into() });
    }
    let dim_at = Where::Byte(r.pos);
    let dim = r.u32("the dimension")? as usize;
    if dim == 0 || dim > MAX_DIMENSION {
        return Err(StoreError::BadDimension { at: dim_at, found: dim as u64 });
    }
    let flags_at = Where::Byte(r.pos);
    let flags = r.u32("the flags")?;
    if flags & !(FLAG_MECHANICS | FLAG_LEVELS) != 0 {
        return Err(StoreError::Inconsistent { at: flags_at, message: format!("unknown flags {flags:#x}") });
    }
    if flags & FLAG_MECHANICS != 0 && dim != 3 {
        let message = format!("the mechanics flag needs a 3-G-map, the header says n = {dim}");
        return Err(StoreError::Inconsistent { at: flags_at, message });
    }
    if flags & FLAG_LEVELS != 0 && version < LEVELS_VERSION {
        let message = format!("the levels flag needs format version {LEVELS_VERSION}, the header says {version}");
        return Err(StoreError::Inconsistent { at: flags_at, message });
    }
    let len_at = r.pos;
    let len = r.u64("the payload length")?;
    // The payload and the 8-byte checksum must both fit after the header.
    let available = bytes.len().saturating_sub(HEADER) as u64;
    if len.checked_add(8).is_none_or(|needed| needed > available) {
        return Err(StoreError::Truncated {
            at: Where::Byte(bytes.len()),
            expected: format!("a payload of {len} bytes (header at byte {len_at}) and an 8-byte checksum"),
        });
    }
    let end = HEADER + len as usize;
    if bytes.len() > end + 8 {
        return Err(StoreError::TrailingData { at: Where::Byte(end + 8) });
    }
    let stored = u64::from_le_bytes(bytes[end..end + 8].try_into().unwrap_or([0; 8]));
    let computed = fnv1a64(&bytes[..end]);
    if stored != computed {
        return Err(StoreError::Checksum { stored, computed });
    }
    let mut r = Reader { bytes: &bytes[..end], pos: HEADER };
    let map = decode_map(&mut r, dim)?;
    let mechanics = if flags & FLAG_MECHANICS != 0 { Some(decode_mechanics(&mut r)?) } else { None };
    let levels = if flags & FLAG_LEVELS != 0 { Some(decode_levels(&mut r, &map, version)?) } else { None };
    if r.pos != end {
        return Err(StoreError::TrailingData { at: Where::Byte(r.pos) });
    }
    Ok(Document { map, mechanics, levels })
}

fn decode_map(r: &mut Reader<'_>, dim: usize) -> Result<RawMap, StoreError> {
    let n1 = dim + 1;
    let cap_at = Where::Byte(r.pos);
    let capacity = r.u32("the dart capacity")?;
    // Each slot needs 2·(n+1) u32 of links and ids: bounded by the bytes left.
    let limit = ((r.bytes.len() - r.pos) / (8 * n1)) as u64;
    if capacity == UNSET || u64::from(capacity) > limit {
        return Err(StoreError::BadCount { at: cap_at, what: "dart capacity", count: capacity.into(), limit });
    }
    let n_free = r.count("free dart slots", 4)?;
    let free_darts = r.u32s(n_free, "the free dart slots")?;
    let slots = capacity as usize * n1;
    let alpha_at = r.pos;
    let alpha = r.u32s(slots, "the alpha links")?;
    let cell = r.u32s(slots, "the cell ids")?;
    if let Some(k) = alpha.iter().position(|&a| a >= capacity) {
        let at = Where::Byte(alpha_at + 4 * k);
        return Err(StoreError::DartOutOfRange { at, dart: alpha[k].into(), capacity: capacity.into() });
    }
    let ids_at = Where::Byte(r.pos);
    let mut ids = Vec::with_capacity(n1);
    for _ in 0..n1 {
        let next = r.u32("a cell-id allocator")?;
        let k = r.count("free cell ids", 4)?;
        ids.push(IdAllocRecord { next, free: r.u32s(k, "the free cell ids")? });
    }
    let raw = RawMap { dimension: dim, capacity, alpha, cell, free_darts, ids };
    structure::check(&raw, ids_at)?;
    Ok(raw)
}

fn decode_mechanics(r: &mut Reader<'_>) -> Result<RawMechanics, StoreError> {
    let mut material = [0.0; 4];
    for x in &mut material {
        *x = r.f64("material", 0)?;
    }
    let mut m = RawMechanics { material, ..RawMechanics::default() };
    let nv = r.count("vertex records", 14 * 8 + 1)?;
    for k in 0..nv {
        let mut xs = [0.0; 14];
        for x in &mut xs {
            *x = r.f64("vertex attribute", k)?;
        }
        let pinned = r.flag("pinned")?;
        m.vertices.push(VertexRecord::from_attributes(&xs, pinned));
    }
    let ne = r.count("edge records", 24)?;
    for k in 0..ne {
        m.edges.push([r.f64("edge attribute", k)?, r.f64("edge attribute", k)?, r.f64("edge attribute", k)?]);
    }
    let nf = r.count("face records", 25)?;
    for k in 0..nf {
        let b = r.flag("boundary")?;
        m.faces.push((b, [r.f64("face normal", k)?, r.f64("face normal", k)?, r.f64("face normal", k)?]));
    }
    let nt = r.count("volume records", 24)?;
    for k in 0..nt {
        m.volumes.push([r.f64("volume attribute", k)?, r.f64("volume attribute", k)?, r.f64("volume attribute", k)?]);
    }
    Ok(m)
}

/// The levels section (structure only: flags 0|1, j ≤ n, old < capacity, finite points; the
/// origin pairs of version 3 are judged by the level laws).
fn decode_levels(r: &mut Reader<'_>, map: &RawMap, version: u32) -> Result<LevelParts, StoreError> {
    let max_level = r.u8("the max level")?;
    let alive = map.live();
    let mut darts = vec![DartLevels::default(); map.capacity as usize];
    for d in (0..map.capacity as usize).filter(|&d| alive[d]) {
        let b = r.take(4, "a dart level record")?;
        let (level, mu) = (b[0], Mu { edge: b[1], face: b[2], tet: b[3] });
        let flat = r.flag("flat")?;
        let h = r.count("history entries", 6)?;
        let mut history = Vec::with_capacity(h);
        for _ in 0..h {
            let at = Where::Byte(r.pos);
            let (hl, j) = (r.u8("a history level")?, r.u8("a history involution")?);
            let old = r.u32("a history link")?;
            if usize::from(j) > map.dimension {
                let message = format!("history of dart {d}: α{j} is above the dimension {}", map.dimension);
                return Err(StoreError::Inconsistent { at, message });
            }
            if old >= map.capacity {
                return Err(StoreError::DartOutOfRange { at, dart: old.into(), capacity: map.capacity.into() });
            }
            history.push(HistoryEntry { level: hl, j, old });
        }
        darts[d] = DartLevels { level, mu, flat, history };
    }
    let np = r.count("points", 24)?;
    let mut points = Vec::with_capacity(np);
    for k in 0..np {
        points.push([r.f64("point", k)?, r.f64("point", k)?, r.f64("point", k)?]);
    }
    let mut origins = Vec::new();
    if version >= ORIGINS_VERSION {
        let no = r.count("origin pairs", 8)?;
        origins.reserve_exact(no);
        for _ in 0..no {
            origins.push([r.u32("a copied vertex")?, r.u32("an origin")?]);
        }
    }
    Ok(LevelParts { max_level, darts, points, origins })
}
