//! The text form `.tmap` (grammar in `docs/FILE_FORMAT.md`).

use std::fmt::Write as _;

use super::raw::{IdAllocRecord, RawMap, RawMechanics, VertexRecord, UNSET};
use super::{
    structure, Document, StoreError, Where, LEVELS_VERSION, MAX_DIMENSION, MIN_VERSION, ORIGINS_VERSION, TEXT_MAGIC,
    VERSION,
};
use crate::subdivide::{DartLevels, HistoryEntry, LevelParts, Mu};

/// Writes the document. Floats use Rust's shortest round-trip notation (`{:?}`). O(size).
pub(super) fn encode(doc: &Document) -> String {
    let m = &doc.map;
    let n1 = m.alphas();
    let mut s = String::new();
    let live = m.live();
    // `write!` into a String cannot fail.
    let _ = writeln!(s, "{TEXT_MAGIC} {} {}", doc.version(), m.dimension);
    let _ = writeln!(s, "darts {} {}", m.capacity, m.capacity as usize - m.free_darts.len());
    for d in (0..m.capacity).filter(|&d| live[d as usize]) {
        let row = d as usize * n1..(d as usize + 1) * n1;
        let _ = write!(s, "{d}");
        m.alpha[row.clone()].iter().for_each(|a| {
            let _ = write!(s, " {a}");
        });
        s.push_str(" |");
        m.cell[row].iter().for_each(|c| {
            let _ = write!(s, " {c}");
        });
        s.push('\n');
    }
    let _ = writeln!(s, "free-darts {}{}", m.free_darts.len(), list(&m.free_darts));
    for (i, rec) in m.ids.iter().enumerate() {
        let _ = writeln!(s, "cell-ids {i} {} {}{}", rec.next, rec.free.len(), list(&rec.free));
    }
    if let Some(mech) = &doc.mechanics {
        encode_mechanics(&mut s, mech);
    }
    if let Some(levels) = &doc.levels {
        encode_levels(&mut s, levels, &live, doc.version());
    }
    s.push_str("end\n");
    s
}

fn list(ids: &[u32]) -> String {
    ids.iter().fold(String::new(), |mut acc, id| {
        let _ = write!(acc, " {id}");
        acc
    })
}

fn floats(s: &mut String, xs: &[f64]) {
    for x in xs {
        let _ = write!(s, " {x:?}");
    }
}

fn encode_mechanics(s: &mut String, m: &RawMechanics) {
    let (nv, ne, nf, nt) = (m.vertices.len(), m.edges.len(), m.faces.len(), m.volumes.len());
    let _ = writeln!(s, "mechanics {nv} {ne} {nf} {nt}");
    s.push_str("material");
    floats(s, &m.material);
    s.push('\n');
    for (k, v) in m.vertices.iter().enumerate() {
        let _ = write!(s, "v {k}");
        for xs in [&v.rest, &v.position, &v.velocity, &v.force] {
            floats(s, xs);
        }
        floats(s, &[v.mass, v.viscosity]);
        let _ = writeln!(s, " {}", u8::from(v.pinned));
    }
    for (k, e) in m.edges.iter().enumerate() {
        let _ = write!(s, "e {k}");
        floats(s, e);
        s.push('\n');
    }
    for (k, (boundary, normal)) in m.faces.iter().enumerate() {
        let _ = write!(s, "f {k} {}", u8::from(*boundary));
        floats(s, normal);
        s.push('\n');
    }
    for (k, t) in m.volumes.iter().enumerate() {
        let _ = write!(s, "t {k}");
        floats(s, t);
        s.push('\n');
    }
}

/// `levels K LIVE NP` (version 3: `levels K LIVE NP NO`), one `l` line per live dart
/// (increasing id), one `p` line per point, (version 3) one `o COPY ORIGIN` line per origin pair.
fn encode_levels(s: &mut String, l: &LevelParts, live: &[bool], version: u32) {
    let live_count = live.iter().filter(|&&x| x).count();
    let _ = write!(s, "levels {} {live_count} {}", l.max_level, l.points.len());
    if version >= ORIGINS_VERSION {
        let _ = write!(s, " {}", l.origins.len());
    }
    s.push('\n');
    for (d, rec) in l.darts.iter().enumerate().filter(|&(d, _)| live[d]) {
        let Mu { edge, face, tet } = rec.mu;
        let _ = write!(s, "l {d} {} {edge} {face} {tet} {} {}", rec.level, u8::from(rec.flat), rec.history.len());
        for h in &rec.history {
            let _ = write!(s, " {} {} {}", h.level, h.j, h.old);
        }
        s.push('\n');
    }
    for (k, p) in l.points.iter().enumerate() {
        let _ = write!(s, "p {k}");
        floats(s, p);
        s.push('\n');
    }
    if version >= ORIGINS_VERSION {
        l.origins.iter().for_each(|[copy, origin]| {
            let _ = writeln!(s, "o {copy} {origin}");
        });
    }
}

/// The significant lines of a text file (blank lines and `#` comments skipped), with numbers,
/// read lazily: nothing is allocated per line (an index of every line would cost a dozen times
/// the size of a file of short lines).
#[derive(Clone, Copy)]
struct Lines<'a> {
    text: &'a str,
    /// Byte offset of the next unread raw line.
    offset: usize,
    /// 1-based number of that line.
    line: usize,
    /// `(offset, line, taken)` before the last [`Lines::next`], for [`Lines::back`].
    before: (usize, usize, usize),
    /// Significant lines taken so far.
    taken: usize,
    /// Significant lines in the whole text.
    total: usize,
    /// Characters of all significant lines, trimmed.
    chars: usize,
    /// Line number just past the last line (for "truncated" errors).
    end_line: usize,
}

impl<'a> Lines<'a> {
    fn new(text: &'a str) -> Self {
        let mut lines =
            Lines { text, offset: 0, line: 1, before: (0, 1, 0), taken: 0, total: 0, chars: 0, end_line: 1 };
        let mut all = lines;
        while let Some((_, t)) = all.next_line() {
            lines.total += 1;
            lines.chars += t.len();
        }
        lines.end_line = text.lines().count() + 1;
        lines
    }

    /// The next significant line (not blank, not a `#` comment), without its line end (LF or
    /// CRLF) and its leading and trailing spaces and tabs, with its number; `None` at the end.
    fn next_line(&mut self) -> Option<(usize, &'a str)> {
        while self.offset < self.text.len() {
            let rest = &self.text[self.offset..];
            let (raw, step) = match rest.find('\n') {
                // LF or CRLF ends a line; any other CR stays, for `check_characters` to refuse.
                Some(i) => (rest[..i].strip_suffix('\r').unwrap_or(&rest[..i]), i + 1),
                None => (rest, rest.len()),
            };
            let no = self.line;
            self.offset += step;
            self.line += 1;
            let t = raw.trim_matches(SEPARATORS);
            if !t.is_empty() && !t.starts_with('#') {
                return Some((no, t));
            }
        }
        None
    }

    /// Significant lines not yet taken. O(1).
    fn remaining(&self) -> usize {
        self.total - self.taken
    }

    /// The next significant line without taking it.
    fn peek(&self) -> Option<(usize, &'a str)> {
        let mut ahead = *self;
        ahead.next_line()
    }

    /// Puts back the line the last [`Lines::next`] took.
    fn back(&mut self) {
        (self.offset, self.line, self.taken) = self.before;
    }

    /// The next line split into tokens, whose first token must be `keyword` (unless empty).
    fn next(&mut self, keyword: &str, expected: &str) -> Result<(usize, Vec<&'a str>), StoreError> {
        self.before = (self.offset, self.line, self.taken);
        let Some((no, line)) = self.next_line() else {
            return Err(StoreError::Truncated { at: Where::Line(self.end_line), expected: expected.into() });
        };
        self.taken += 1;
        check_characters(no, line)?;
        let tokens: Vec<&str> = tokens(line).collect();
        if !keyword.is_empty() && tokens.first() != Some(&keyword) {
            return Err(syntax(no, format!("expected {expected}, found {:?}", first_chars(line))));
        }
        Ok((no, tokens))
    }
}

/// What separates tokens: ASCII spaces and tabs, nothing else (docs/FILE_FORMAT.md).
const SEPARATORS: [char; 2] = [' ', '\t'];

/// The tokens of a line: the non-empty runs between [`SEPARATORS`]. O(len).
fn tokens(line: &str) -> impl Iterator<Item = &str> {
    line.split(SEPARATORS).filter(|t| !t.is_empty())
}

/// Refuses a significant line holding whitespace other than the [`SEPARATORS`] (a no-break or
/// em space, a vertical tab, a form feed) or a control character (a CR not ending the line):
/// a `Syntax` error naming the line and the character. O(len).
fn check_characters(no: usize, line: &str) -> Result<(), StoreError> {
    match line.chars().find(|&c| !SEPARATORS.contains(&c) && (c.is_whitespace() || c.is_control())) {
        Some(c) => Err(syntax(
            no,
            format!(
                "character U+{:04X} is not allowed: tokens are separated by ASCII spaces or tabs, lines end with LF or CRLF",
                u32::from(c)
            ),
        )),
        None => Ok(()),
    }
}

fn first_chars(line: &str) -> String {
    line.chars().take(40).collect()
}

fn syntax(line: usize, message: String) -> StoreError {
    StoreError::Syntax { at: Where::Line(line), message }
}

/// An unsigned decimal integer in its one written form: ASCII digits only, no sign, no leading
/// zero (`0`, `7`, `12`; not `+1`, `01`), below 2^64. `None` otherwise. O(len).
fn unsigned(tok: &str) -> Option<u64> {
    let digits = !tok.is_empty() && tok.bytes().all(|b| b.is_ascii_digit());
    let canonical = tok == "0" || !tok.starts_with('0');
    if digits && canonical {
        tok.parse::<u64>().ok()
    } else {
        None
    }
}

fn int(tok: &str, line: usize, what: &str) -> Result<u64, StoreError> {
    unsigned(tok).ok_or_else(|| {
        let why = if tok.bytes().all(|b| b.is_ascii_digit()) && !tok.is_empty() && tok.len() < 20 {
            "has a leading zero"
        } else {
            "is not an unsigned decimal integer (digits only, no sign, no leading zero, below 2^64)"
        };
        syntax(line, format!("{what}: {tok:?} {why}"))
    })
}

fn int32(tok: &str, line: usize, what: &str) -> Result<u32, StoreError> {
    let v = int(tok, line, what)?;
    u32::try_from(v).map_err(|_| syntax(line, format!("{what}: {v} does not fit in 32 bits")))
}

fn float(tok: &str, line: usize, field: &'static str, index: usize) -> Result<f64, StoreError> {
    let x = tok.parse::<f64>().map_err(|_| syntax(line, format!("{field}: {tok:?} is not a number")))?;
    if x.is_finite() {
        Ok(x)
    } else {
        Err(StoreError::NonFinite { at: Where::Line(line), field, index })
    }
}

fn arity(tokens: &[&str], n: usize, line: usize, what: &str) -> Result<(), StoreError> {
    if tokens.len() == n {
        Ok(())
    } else {
        Err(syntax(line, format!("{what}: expected {n} fields, found {}", tokens.len())))
    }
}

/// Parses the text form into a raw document with its structure checked.
/// The first significant line of `bytes` as [`Lines`] reads lines (blank and `#` comment lines
/// skipped, spaces and tabs trimmed, LF or CRLF ends), if there is one. Needs no valid UTF-8.
/// O(bytes up to that line).
pub(super) fn first_significant_line(bytes: &[u8]) -> Option<&[u8]> {
    let blank = |b: &u8| SEPARATORS.contains(&char::from(*b));
    bytes
        .split(|&b| b == b'\n')
        .map(|line| {
            let line = line.strip_suffix(b"\r").unwrap_or(line);
            let start = line.iter().position(|b| !blank(b)).unwrap_or(line.len());
            &line[start..]
        })
        .find(|t| !t.iter().all(blank) && !t.starts_with(b"#"))
}

/// Whether the first significant line of `bytes` ([`first_significant_line`]) starts with
/// [`TEXT_MAGIC`], so that [`decode`] is the decoder to try. O(bytes up to that line).
pub(super) fn header_comes_first(bytes: &[u8]) -> bool {
    first_significant_line(bytes).is_some_and(|t| t.starts_with(TEXT_MAGIC.as_bytes()))
}

pub(super) fn decode(bytes: &[u8]) -> Result<Document, StoreError> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        let line = bytes[..e.valid_up_to()].iter().filter(|&&b| b == b'\n').count() + 1;
        syntax(line, "the text is not valid UTF-8".into())
    })?;
    let mut lines = Lines::new(text);
    let (version, map) = decode_map(&mut lines)?;
    let (no, head) = lines.next("", "\"mechanics\", \"levels\" or \"end\"")?;
    let mechanics = match head.first() {
        Some(&"mechanics") if map.dimension != 3 => {
            let message = format!("a mechanics section needs a 3-G-map, the header says n = {}", map.dimension);
            return Err(StoreError::Inconsistent { at: Where::Line(no), message });
        }
        Some(&"mechanics") => Some(decode_mechanics(&mut lines, no, &head)?),
        _ => {
            lines.back();
            None
        }
    };
    let (no, head) = lines.next("", "\"levels\" or \"end\"")?;
    let levels = match head.first() {
        Some(&"levels") if version < LEVELS_VERSION => {
            let message = format!("a levels section needs format version {LEVELS_VERSION}, the header says {version}");
            return Err(StoreError::Inconsistent { at: Where::Line(no), message });
        }
        Some(&"levels") => Some(decode_levels(&mut lines, no, &head, &map, version)?),
        _ => {
            lines.back();
            None
        }
    };
    let (no, end) = lines.next("end", "\"end\" (the sections are mechanics, then levels)")?;
    arity(&end, 1, no, "end")?;
    if let Some((extra, _)) = lines.peek() {
        return Err(StoreError::TrailingData { at: Where::Line(extra) });
    }
    if !text.ends_with('\n') {
        return Err(StoreError::Truncated { at: Where::Line(no), expected: "a newline after \"end\"".into() });
    }
    Ok(Document { map, mechanics, levels })
}

fn decode_header(lines: &mut Lines<'_>) -> Result<(u32, usize), StoreError> {
    let (no, h) = lines.next(TEXT_MAGIC, "the header")?;
    if h.len() < 2 {
        return Err(StoreError::Truncated { at: Where::Line(no), expected: "the format version".into() });
    }
    let version = int(h[1], no, "version")?;
    if !(u64::from(MIN_VERSION)..=u64::from(VERSION)).contains(&version) {
        return Err(StoreError::UnsupportedVersion { at: Where::Line(no), found: version });
    }
    arity(&h, 3, no, "header")?;
    let dim = int(h[2], no, "dimension")?;
    if dim == 0 || dim > MAX_DIMENSION as u64 {
        return Err(StoreError::BadDimension { at: Where::Line(no), found: dim });
    }
    Ok((version as u32, dim as usize))
}

fn decode_map(lines: &mut Lines<'_>) -> Result<(u32, RawMap), StoreError> {
    let (version, dim) = decode_header(lines)?;
    let n1 = dim + 1;
    let (capacity, live_count, dead) = decode_dart_counts(lines)?;
    // The arrays hold every slot, live or dead: they are allocated only when the free-darts line
    // after the dart lines lists as many slots as the counts leave dead, so that their size is
    // bounded by what the file holds (a lying count with no such line allocates nothing; the
    // dart lines are then read only for their errors, which come first as always).
    let listed = free_darts_line_ahead(lines, live_count, dead);
    let cap = if listed { capacity as usize } else { 0 };
    let mut alpha: Vec<u32> = (0..cap as u32).flat_map(|d| std::iter::repeat_n(d, n1)).collect();
    let mut cell = vec![UNSET; cap * n1];
    let mut prev: Option<u32> = None;
    for _ in 0..live_count {
        let line = decode_dart_line(lines, n1, capacity, prev)?;
        prev = Some(line.dart);
        if listed {
            let row = line.dart as usize * n1..(line.dart as usize + 1) * n1;
            alpha[row.clone()].copy_from_slice(&line.alpha[..n1]);
            cell[row].copy_from_slice(&line.cell[..n1]);
        }
    }
    let (no, f) = lines.next("free-darts", "\"free-darts COUNT IDS…\"")?;
    let free_darts = id_list(&f, 1, no, "free-darts")?;
    if free_darts.len() as u64 != dead {
        let what = "free dart slots (capacity − live)";
        return Err(StoreError::BadCount { at: Where::Line(no), what, count: free_darts.len() as u64, limit: dead });
    }
    // The look-ahead saw this very line: keyword, count = dead, and that many ids.
    debug_assert!(listed, "the free-darts line was accepted but not seen ahead");
    let ids = (0..n1).map(|i| decode_cell_ids(lines, i)).collect::<Result<Vec<_>, _>>()?;
    let raw = RawMap { dimension: dim, capacity, alpha, cell, free_darts, ids };
    structure::check(&raw, Where::Line(no))?;
    Ok((version, raw))
}

/// The `darts CAPACITY LIVE` line: (capacity, live darts, dead slots), each bounded by what the
/// rest of the file can hold.
fn decode_dart_counts(lines: &mut Lines<'_>) -> Result<(u32, u64, u64), StoreError> {
    let (no, h) = lines.next("darts", "\"darts CAPACITY LIVE\"")?;
    arity(&h, 3, no, "darts")?;
    let capacity = int32(h[1], no, "capacity")?;
    let live_count = int(h[2], no, "live darts")?;
    if live_count > u64::from(capacity) || live_count > lines.remaining() as u64 {
        let limit = u64::from(capacity).min(lines.remaining() as u64);
        return Err(StoreError::BadCount { at: Where::Line(no), what: "live darts", count: live_count, limit });
    }
    let dead = u64::from(capacity) - live_count;
    // Every dead slot is a token of the free-darts line: bounded by the file size.
    let limit = (lines.chars / 2) as u64;
    if capacity == UNSET || dead > limit {
        return Err(StoreError::BadCount { at: Where::Line(no), what: "dead dart slots", count: dead, limit });
    }
    Ok((capacity, live_count, dead))
}

/// Whether the line after the next `live_count` lines is a free-darts line listing `dead` ids
/// (a look-ahead: `lines` is not advanced).
fn free_darts_line_ahead(lines: &Lines<'_>, live_count: u64, dead: u64) -> bool {
    let mut ahead = *lines;
    (0..live_count).all(|_| ahead.next_line().is_some())
        && ahead.next_line().is_some_and(|(_, line)| {
            let mut tokens = tokens(line);
            tokens.next() == Some("free-darts")
                && tokens.next().is_some_and(|count| unsigned(count) == Some(dead))
                && tokens.count() as u64 == dead
        })
}

/// One dart line as read: `DART A0 … An | C0 … Cn` (first n + 1 entries of each row used).
struct DartLine {
    dart: u32,
    alpha: [u32; MAX_DIMENSION + 1],
    cell: [u32; MAX_DIMENSION + 1],
}

/// The next dart line, its dart after `prev` and every id below `capacity`.
fn decode_dart_line(
    lines: &mut Lines<'_>,
    n1: usize,
    capacity: u32,
    prev: Option<u32>,
) -> Result<DartLine, StoreError> {
    let (no, t) = lines.next("", "a dart line")?;
    arity(&t, 2 * n1 + 2, no, "dart line")?;
    let d = int(t[0], no, "dart id")?;
    if d >= u64::from(capacity) {
        return Err(StoreError::DartOutOfRange { at: Where::Line(no), dart: d, capacity: capacity.into() });
    }
    let dart = d as u32;
    if prev.is_some_and(|p| dart <= p) {
        return Err(StoreError::Inconsistent {
            at: Where::Line(no),
            message: format!("dart {dart} is not after dart {} (ids must increase)", prev.unwrap_or(0)),
        });
    }
    if t[n1 + 1] != "|" {
        return Err(syntax(no, format!("expected \"|\" between links and cell ids, found {:?}", t[n1 + 1])));
    }
    let mut line = DartLine { dart, alpha: [0; MAX_DIMENSION + 1], cell: [0; MAX_DIMENSION + 1] };
    for i in 0..n1 {
        let a = int(t[1 + i], no, "alpha link")?;
        if a >= u64::from(capacity) {
            return Err(StoreError::DartOutOfRange { at: Where::Line(no), dart: a, capacity: capacity.into() });
        }
        line.alpha[i] = a as u32;
        line.cell[i] = int32(t[n1 + 2 + i], no, "cell id")?;
    }
    Ok(line)
}

/// The `cell-ids DIM NEXT COUNT IDS…` line of dimension i.
fn decode_cell_ids(lines: &mut Lines<'_>, i: usize) -> Result<IdAllocRecord, StoreError> {
    let (no, c) = lines.next("cell-ids", "\"cell-ids DIM NEXT COUNT IDS…\"")?;
    if c.len() < 3 || int(c[1], no, "cell dimension")? != i as u64 {
        return Err(syntax(no, format!("expected \"cell-ids {i} NEXT COUNT IDS…\"")));
    }
    let next = int32(c[2], no, "next cell id")?;
    let free = id_list(&c, 3, no, "cell-ids")?;
    Ok(IdAllocRecord { next, free })
}

/// `COUNT IDS…` starting at token `start`.
fn id_list(t: &[&str], start: usize, no: usize, what: &str) -> Result<Vec<u32>, StoreError> {
    let Some(count) = t.get(start) else {
        return Err(syntax(no, format!("{what}: missing count")));
    };
    let count = int(count, no, what)?;
    if count != (t.len() - start - 1) as u64 {
        return Err(syntax(no, format!("{what}: count {count} but {} ids follow", t.len() - start - 1)));
    }
    t[start + 1..].iter().map(|tok| int32(tok, no, what)).collect()
}

fn decode_mechanics(lines: &mut Lines<'_>, no: usize, head: &[&str]) -> Result<RawMechanics, StoreError> {
    arity(head, 5, no, "mechanics")?;
    let mut counts = [0usize; 4];
    for (k, c) in counts.iter_mut().enumerate() {
        let v = int(head[1 + k], no, "record count")?;
        if v > lines.remaining() as u64 {
            let limit = lines.remaining() as u64;
            return Err(StoreError::BadCount { at: Where::Line(no), what: "mechanics records", count: v, limit });
        }
        *c = v as usize;
    }
    let (no, mat) = lines.next("material", "\"material ρ E β ν\"")?;
    arity(&mat, 5, no, "material")?;
    let mut material = [0.0; 4];
    for (k, x) in material.iter_mut().enumerate() {
        *x = float(mat[1 + k], no, "material", 0)?;
    }
    let mut m = RawMechanics { material, ..RawMechanics::default() };
    for k in 0..counts[0] {
        let (no, t) = record(lines, "v", k, 16)?;
        let mut xs = [0.0; 14];
        for (x, tok) in xs.iter_mut().zip(&t[2..16]) {
            *x = float(tok, no, "vertex attribute", k)?;
        }
        let pinned = flag(t[16], no)?;
        m.vertices.push(VertexRecord::from_attributes(&xs, pinned));
    }
    for k in 0..counts[1] {
        let (no, t) = record(lines, "e", k, 4)?;
        let xs = floats_of(&t[2..], no, "edge attribute", k)?;
        m.edges.push([xs[0], xs[1], xs[2]]);
    }
    for k in 0..counts[2] {
        let (no, t) = record(lines, "f", k, 5)?;
        let boundary = flag(t[2], no)?;
        let xs = floats_of(&t[3..], no, "face normal", k)?;
        m.faces.push((boundary, [xs[0], xs[1], xs[2]]));
    }
    for k in 0..counts[3] {
        let (no, t) = record(lines, "t", k, 4)?;
        let xs = floats_of(&t[2..], no, "volume attribute", k)?;
        m.volumes.push([xs[0], xs[1], xs[2]]);
    }
    Ok(m)
}

/// A record line `KIND k x…` with `fields` values after the kind.
fn record<'a>(lines: &mut Lines<'a>, kind: &str, k: usize, fields: usize) -> Result<(usize, Vec<&'a str>), StoreError> {
    let (no, t) = lines.next(kind, &format!("record \"{kind} {k} …\""))?;
    arity(&t, fields + 1, no, kind)?;
    if int(t[1], no, "record id")? != k as u64 {
        return Err(StoreError::Inconsistent { at: Where::Line(no), message: format!("expected record {kind} {k}") });
    }
    Ok((no, t))
}

fn floats_of(t: &[&str], no: usize, field: &'static str, k: usize) -> Result<Vec<f64>, StoreError> {
    t.iter().map(|tok| float(tok, no, field, k)).collect()
}

fn flag(tok: &str, no: usize) -> Result<bool, StoreError> {
    match tok {
        "0" => Ok(false),
        "1" => Ok(true),
        _ => Err(syntax(no, format!("expected a flag 0 or 1, found {tok:?}"))),
    }
}

fn int8(tok: &str, line: usize, what: &str) -> Result<u8, StoreError> {
    let v = int(tok, line, what)?;
    u8::try_from(v).map_err(|_| syntax(line, format!("{what}: {v} does not fit in 8 bits")))
}

/// `levels K LIVE NP` (version 3: `levels K LIVE NP NO`, already read as `head`), then the `l`,
/// `p` and (version 3) `o` lines. Structure only: one `l` line per live dart in increasing id
/// order, j ≤ n, old < capacity, finite points (the origin pairs are judged by the level laws).
fn decode_levels(
    lines: &mut Lines<'_>,
    no: usize,
    head: &[&str],
    map: &RawMap,
    version: u32,
) -> Result<LevelParts, StoreError> {
    let with_origins = version >= ORIGINS_VERSION;
    arity(head, if with_origins { 5 } else { 4 }, no, "levels")?;
    let max_level = int8(head[1], no, "max level")?;
    let live: Vec<u32> = {
        let alive = map.live();
        (0..map.capacity).filter(|&d| alive[d as usize]).collect()
    };
    let live_count = int(head[2], no, "level records")?;
    if live_count != live.len() as u64 {
        let (what, limit) = ("level records (one per live dart)", live.len() as u64);
        return Err(StoreError::BadCount { at: Where::Line(no), what, count: live_count, limit });
    }
    let np = int(head[3], no, "points")?;
    if np > lines.remaining() as u64 {
        let limit = lines.remaining() as u64;
        return Err(StoreError::BadCount { at: Where::Line(no), what: "points", count: np, limit });
    }
    let mut darts = vec![DartLevels::default(); map.capacity as usize];
    for &d in &live {
        let (no, t) = lines.next("l", &format!("the level line \"l {d} …\""))?;
        darts[d as usize] = level_line(&t, no, d, map)?;
    }
    let mut points = Vec::with_capacity(np as usize);
    for k in 0..np as usize {
        let (no, t) = record(lines, "p", k, 4)?;
        let xs = floats_of(&t[2..], no, "point", k)?;
        points.push([xs[0], xs[1], xs[2]]);
    }
    let mut origins = Vec::new();
    if with_origins {
        let count = int(head[4], no, "origin pairs")?;
        if count > lines.remaining() as u64 {
            let limit = lines.remaining() as u64;
            return Err(StoreError::BadCount { at: Where::Line(no), what: "origin pairs", count, limit });
        }
        for k in 0..count {
            let (no, t) = lines.next("o", &format!("origin pair {k} \"o COPY ORIGIN\""))?;
            arity(&t, 3, no, "o")?;
            origins.push([int32(t[1], no, "copied vertex")?, int32(t[2], no, "origin")?]);
        }
    }
    Ok(LevelParts { max_level, darts, points, origins })
}

/// `l D LEVEL MUA MUF MUT FLAT H (LEVEL J OLD){H}` for live dart `d`.
fn level_line(t: &[&str], no: usize, d: u32, map: &RawMap) -> Result<DartLevels, StoreError> {
    if t.len() < 8 {
        return Err(syntax(no, format!("level line: expected at least 8 fields, found {}", t.len())));
    }
    if int(t[1], no, "dart id")? != u64::from(d) {
        let message = format!("expected the level line of dart {d} (one per live dart, ids increasing)");
        return Err(StoreError::Inconsistent { at: Where::Line(no), message });
    }
    let h = int(t[7], no, "history length")?;
    if h.checked_mul(3).and_then(|x| x.checked_add(8)) != Some(t.len() as u64) {
        return Err(syntax(no, format!("level line: history length {h} but {} fields follow", t.len() - 8)));
    }
    let mu = Mu { edge: int8(t[3], no, "μa")?, face: int8(t[4], no, "μf")?, tet: int8(t[5], no, "μt")? };
    let mut rec = DartLevels { level: int8(t[2], no, "dart level")?, mu, flat: flag(t[6], no)?, history: Vec::new() };
    for e in t[8..].chunks_exact(3) {
        let entry = HistoryEntry {
            level: int8(e[0], no, "history level")?,
            j: int8(e[1], no, "history j")?,
            old: int32(e[2], no, "history old")?,
        };
        if usize::from(entry.j) > map.dimension {
            return Err(syntax(no, format!("history: α{} is above the dimension {}", entry.j, map.dimension)));
        }
        if entry.old >= map.capacity {
            let (dart, capacity) = (entry.old.into(), map.capacity.into());
            return Err(StoreError::DartOutOfRange { at: Where::Line(no), dart, capacity });
        }
        rec.history.push(entry);
    }
    Ok(rec)
}
