//! A minimal Wavefront OBJ reader for triangle surfaces.
//!
//! Reads `v x y z [w]` and `f a b c` records, where each corner is `i`, `i/t`, `i//n` or
//! `i/t/n`; `i` is 1-based, or negative to count back from the last vertex read so far.
//! Faces with other than three corners are an error. Every other record (`vn`, `vt`, `o`, `g`,
//! `s`, `usemtl`, `mtllib`, ...) and `#` comments are ignored.

use std::path::Path;

use super::build::{ElementUse, MeshBuilder};
use super::{shorten, Location, ReadError};

/// A face waiting for all vertices to be read: (line, face number, 1-based vertex numbers).
type PendingFace = (usize, u64, [u64; 3]);

fn garbage(path: &Path, line: usize, token: &[u8], expected: &str) -> ReadError {
    ReadError::Garbage {
        path: path.to_path_buf(),
        at: Location::Line(line),
        section: "OBJ",
        token: shorten(&String::from_utf8_lossy(token)),
        expected: expected.to_string(),
    }
}

fn number<T: std::str::FromStr>(
    path: &Path,
    line: usize,
    token: Option<&[u8]>,
    expected: &str,
) -> Result<T, ReadError> {
    let Some(raw) = token else {
        return Err(ReadError::Truncated {
            path: path.to_path_buf(),
            at: Location::Line(line),
            section: "OBJ",
            expected: expected.to_string(),
            found: "end of line".into(),
        });
    };
    std::str::from_utf8(raw).ok().and_then(|s| s.parse().ok()).ok_or_else(|| garbage(path, line, raw, expected))
}

/// Resolves one face corner (`i`, `i/t`, `i//n`, `i/t/n`) of face `face` to a 1-based vertex
/// number, `vertices` being the number of vertices read so far (an index past them is left to
/// the builder, once the whole file is read: faces may name vertices defined later).
///
/// # Errors
/// `Garbage`, naming the corner as written, for an index that is not an integer; `Malformed`,
/// naming the index as written, for 0 or a negative index that counts back past the first
/// vertex.
fn corner(path: &Path, line: usize, face: u64, raw: &[u8], vertices: u64) -> Result<u64, ReadError> {
    let index_part = raw.split(|&b| b == b'/').next().unwrap_or(&[]);
    // A bad index is named by the corner as written ("/3", not the empty part before the slash).
    let i: i64 = number(path, line, Some(index_part), "a vertex index")
        .map_err(|_| garbage(path, line, raw, "a vertex index"))?;
    let resolved = if i < 0 { i128::from(vertices) + 1 + i128::from(i) } else { i128::from(i) };
    match u64::try_from(resolved) {
        Ok(n) if n >= 1 => Ok(n),
        _ => {
            let why = if i == 0 {
                "OBJ vertex indices start at 1 (or count back from -1)".to_string()
            } else {
                format!("it counts back past the first vertex ({vertices} vertices read so far)")
            };
            Err(ReadError::Malformed {
                path: path.to_path_buf(),
                at: Location::Line(line),
                message: format!("face {face}: vertex index {i} refers to no vertex: {why}"),
            })
        }
    }
}

/// Parses an OBJ file into a builder whose node tags are the 1-based vertex numbers.
pub(crate) fn parse(data: &[u8], path: &Path) -> Result<MeshBuilder, ReadError> {
    let mut b = MeshBuilder::new();
    let mut faces: Vec<PendingFace> = Vec::new();
    for (i, raw_line) in data.split(|&b| b == b'\n').enumerate() {
        let line = i + 1;
        let content = raw_line.split(|&b| b == b'#').next().unwrap_or(&[]);
        let mut fields = content.split(|b| b.is_ascii_whitespace()).filter(|f| !f.is_empty());
        match fields.next() {
            Some(b"v") => {
                let x = number(path, line, fields.next(), "vertex x coordinate")?;
                let y = number(path, line, fields.next(), "vertex y coordinate")?;
                let z = number(path, line, fields.next(), "vertex z coordinate")?;
                let tag = b.point_count() as u64 + 1;
                b.add_node(path, Location::Line(line), tag, [x, y, z])?;
            }
            Some(b"f") => {
                let corners: Vec<&[u8]> = fields.collect();
                let [p, q, r] = corners[..] else {
                    return Err(ReadError::Malformed {
                        path: path.to_path_buf(),
                        at: Location::Line(line),
                        message: format!("face with {} corners: only triangles are supported", corners.len()),
                    });
                };
                let (n, face) = (b.point_count() as u64, faces.len() as u64 + 1);
                let tri =
                    [corner(path, line, face, p, n)?, corner(path, line, face, q, n)?, corner(path, line, face, r, n)?];
                faces.push((line, face, tri));
            }
            _ => {}
        }
    }
    for (line, face, tri) in faces {
        b.add_element(path, Location::Line(line), face, ElementUse::Triangle, &tri)?;
    }
    Ok(b)
}
