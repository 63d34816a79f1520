//! TetGen `.node` and `.ele` files.
//!
//! Both are line-based: `#` starts a comment, blank lines are ignored, and every other line is
//! one record. `.node`: header `<points> <dimension = 3> [<attributes> [<markers>]]`, then
//! `<number> <x> <y> <z> [attributes] [marker]`. `.ele`: header
//! `<tets> <nodes per tet = 4> [<attributes>]`, then `<number> <n1> <n2> <n3> <n4> [attributes]`.
//! Point numbers are used as tags, so 0- and 1-based files both work (the `.ele` must use the
//! same numbering as its `.node`). Attributes and markers are ignored.

use std::path::Path;

use super::build::{bounded_count, ElementUse, MeshBuilder};
use super::{shorten, Location, ReadError};

/// Smallest number of bytes one record takes (`1 0 0 0\n`).
const MIN_RECORD: usize = 8;

/// One non-blank, comment-stripped line.
struct Record<'a> {
    line: usize,
    fields: Vec<&'a [u8]>,
}

/// The records of a file, in order.
fn records(data: &[u8]) -> impl Iterator<Item = Record<'_>> {
    data.split(|&b| b == b'\n').enumerate().filter_map(|(i, line)| {
        let content = line.split(|&b| b == b'#').next().unwrap_or(&[]);
        let fields: Vec<&[u8]> = content.split(|b| b.is_ascii_whitespace()).filter(|f| !f.is_empty()).collect();
        (!fields.is_empty()).then_some(Record { line: i + 1, fields })
    })
}

/// Reading context for errors.
struct Ctx<'a> {
    path: &'a Path,
    section: &'static str,
}

impl Ctx<'_> {
    fn field<T: std::str::FromStr>(&self, rec: &Record<'_>, k: usize, expected: &str) -> Result<T, ReadError> {
        let Some(raw) = rec.fields.get(k) else {
            return Err(ReadError::Truncated {
                path: self.path.to_path_buf(),
                at: Location::Line(rec.line),
                section: self.section,
                expected: expected.to_string(),
                found: "end of line".into(),
            });
        };
        std::str::from_utf8(raw).ok().and_then(|s| s.parse().ok()).ok_or_else(|| ReadError::Garbage {
            path: self.path.to_path_buf(),
            at: Location::Line(rec.line),
            section: self.section,
            token: shorten(&String::from_utf8_lossy(raw)),
            expected: expected.to_string(),
        })
    }

    fn truncated_file(&self, line: usize, expected: String) -> ReadError {
        ReadError::Truncated {
            path: self.path.to_path_buf(),
            at: Location::Line(line),
            section: self.section,
            expected,
            found: "end of file".into(),
        }
    }

    fn no_extra(&self, extra: Option<Record<'_>>, declared: usize) -> Result<(), ReadError> {
        match extra {
            None => Ok(()),
            Some(rec) => Err(ReadError::Garbage {
                path: self.path.to_path_buf(),
                at: Location::Line(rec.line),
                section: self.section,
                token: shorten(&String::from_utf8_lossy(rec.fields.first().copied().unwrap_or(&[]))),
                expected: format!("end of file after the {declared} declared records"),
            }),
        }
    }
}

fn last_line(data: &[u8]) -> usize {
    data.iter().filter(|&&b| b == b'\n').count() + 1
}

/// Reads a `.node` file into `b`.
pub(crate) fn parse_node(data: &[u8], path: &Path, b: &mut MeshBuilder) -> Result<(), ReadError> {
    let ctx = Ctx { path, section: ".node" };
    let mut recs = records(data);
    let header_text = "the header `<points> <dimension> <attributes> <markers>`";
    let header = recs.next().ok_or_else(|| ctx.truncated_file(last_line(data), header_text.into()))?;
    let count: u64 = ctx.field(&header, 0, "the number of points")?;
    let dim: u64 = ctx.field(&header, 1, "the dimension")?;
    if dim != 3 {
        return Err(ReadError::Malformed {
            path: path.to_path_buf(),
            at: Location::Line(header.line),
            message: format!("dimension {dim}: only 3-D `.node` files are supported"),
        });
    }
    let remaining = data.len();
    let at = Location::Line(header.line);
    let n = bounded_count(path, at, "point", count, MIN_RECORD, remaining)?;
    b.reserve_points(n);
    for i in 0..n {
        let rec =
            recs.next().ok_or_else(|| ctx.truncated_file(last_line(data), format!("point record {} of {n}", i + 1)))?;
        let tag: u64 = ctx.field(&rec, 0, "a point number")?;
        let x = ctx.field(&rec, 1, "point x coordinate")?;
        let y = ctx.field(&rec, 2, "point y coordinate")?;
        let z = ctx.field(&rec, 3, "point z coordinate")?;
        b.add_node(path, Location::Line(rec.line), tag, [x, y, z])?;
    }
    ctx.no_extra(recs.next(), n)
}

/// Reads an `.ele` file into `b` (whose points come from the `.node` file).
pub(crate) fn parse_ele(data: &[u8], path: &Path, b: &mut MeshBuilder) -> Result<(), ReadError> {
    let ctx = Ctx { path, section: ".ele" };
    let mut recs = records(data);
    let header_text = "the header `<tetrahedra> <nodes per tetrahedron> <attributes>`";
    let header = recs.next().ok_or_else(|| ctx.truncated_file(last_line(data), header_text.into()))?;
    let count: u64 = ctx.field(&header, 0, "the number of tetrahedra")?;
    let per_tet: u64 = ctx.field(&header, 1, "the number of nodes per tetrahedron")?;
    let at = Location::Line(header.line);
    match per_tet {
        4 => {}
        10 => {
            return Err(ReadError::UnsupportedElementType {
                path: path.to_path_buf(),
                at,
                element_type: 11,
                name: "10-node second-order tetrahedron",
            })
        }
        _ => {
            return Err(ReadError::Malformed {
                path: path.to_path_buf(),
                at,
                message: format!("{per_tet} nodes per tetrahedron (expected 4)"),
            })
        }
    }
    let n = bounded_count(path, at, "tetrahedron", count, MIN_RECORD, data.len())?;
    let mut nodes = [0u64; 4];
    for i in 0..n {
        let rec = recs
            .next()
            .ok_or_else(|| ctx.truncated_file(last_line(data), format!("tetrahedron record {} of {n}", i + 1)))?;
        let tag: u64 = ctx.field(&rec, 0, "a tetrahedron number")?;
        for (k, node) in nodes.iter_mut().enumerate() {
            *node = ctx.field(&rec, k + 1, "a point number")?;
        }
        b.add_element(path, Location::Line(rec.line), tag, ElementUse::Tet, &nodes)?;
    }
    ctx.no_extra(recs.next(), n)
}
