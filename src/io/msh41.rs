//! Gmsh MSH 4.1, ASCII and binary.
//!
//! Reads `$MeshFormat`, `$Entities` (parsed only to step over it), `$Nodes` and `$Elements`;
//! every other section is skipped up to its `$End...` marker. Node tags may be sparse.
//! Binary files may be little- or big-endian, with a `size_t` of 4 or 8 bytes.

use std::path::Path;

use super::build::{bounded_count, MeshBuilder, Target};
use super::scan::Scanner;
use super::{Location, ReadError};

/// Smallest number of bytes one node takes in a text file (`1\n0 0 0\n`).
const MIN_TEXT_NODE: usize = 8;
/// Smallest number of bytes one element takes in a text file (`1 1\n`).
const MIN_TEXT_ELEMENT: usize = 4;

/// Binary encoding parameters from the header.
#[derive(Debug, Clone, Copy)]
struct Binary {
    big_endian: bool,
    size_t: usize,
}

/// A cursor that reads MSH 4.1 values as text tokens or as binary numbers.
struct Reader<'a> {
    sc: Scanner<'a>,
    bin: Option<Binary>,
}

impl<'a> Reader<'a> {
    fn path(&self) -> &'a Path {
        self.sc.path()
    }

    fn bytes<const N: usize>(&mut self, what: &str) -> Result<[u8; N], ReadError> {
        let raw = self.sc.take(N, what)?;
        let mut out = [0u8; N];
        out.copy_from_slice(raw);
        Ok(out)
    }

    fn size_t(&mut self, what: &str) -> Result<u64, ReadError> {
        match self.bin {
            None => self.sc.u64(what),
            Some(b) => match (b.size_t, b.big_endian) {
                (4, false) => Ok(u64::from(u32::from_le_bytes(self.bytes(what)?))),
                (4, true) => Ok(u64::from(u32::from_be_bytes(self.bytes(what)?))),
                (_, false) => Ok(u64::from_le_bytes(self.bytes(what)?)),
                (_, true) => Ok(u64::from_be_bytes(self.bytes(what)?)),
            },
        }
    }

    fn int(&mut self, what: &str) -> Result<i64, ReadError> {
        match self.bin {
            None => self.sc.i64(what),
            Some(b) if b.big_endian => Ok(i64::from(i32::from_be_bytes(self.bytes(what)?))),
            Some(_) => Ok(i64::from(i32::from_le_bytes(self.bytes(what)?))),
        }
    }

    fn float(&mut self, what: &str) -> Result<f64, ReadError> {
        match self.bin {
            None => self.sc.f64(what),
            Some(b) if b.big_endian => Ok(f64::from_be_bytes(self.bytes(what)?)),
            Some(_) => Ok(f64::from_le_bytes(self.bytes(what)?)),
        }
    }

    fn size_t_bytes(&self) -> usize {
        self.bin.map_or(1, |b| b.size_t)
    }

    /// Enters a section after its start marker: in binary files the data starts after the
    /// marker's line.
    fn enter(&mut self, section: &'static str) -> Result<(), ReadError> {
        self.sc.section = section;
        if self.bin.is_some() {
            self.sc.end_of_line()?;
        }
        Ok(())
    }

    fn malformed(&self, at: Location, message: String) -> ReadError {
        ReadError::Malformed { path: self.path().to_path_buf(), at, message }
    }
}

/// Parses an MSH 4.1 file into a builder for a read of `target`.
pub(crate) fn parse(data: &[u8], path: &Path, target: Target) -> Result<MeshBuilder, ReadError> {
    let mut r = Reader { sc: Scanner::new(data, path), bin: None };
    parse_header(&mut r)?;
    let mut b = MeshBuilder::for_target(target);
    let (mut seen_nodes, mut seen_elements) = (false, false);
    while let Some(t) = r.sc.next_raw() {
        let at = r.sc.location_of(&t);
        let name = t.raw;
        match name {
            b"$Nodes" => {
                r.enter("$Nodes")?;
                parse_nodes(&mut r, &mut b)?;
                r.sc.expect_marker("$EndNodes")?;
                seen_nodes = true;
            }
            b"$Elements" => {
                if !seen_nodes {
                    return Err(r.malformed(at, "`$Elements` before `$Nodes`".into()));
                }
                r.enter("$Elements")?;
                parse_elements(&mut r, &mut b)?;
                r.sc.expect_marker("$EndElements")?;
                seen_elements = true;
            }
            b"$Entities" => {
                r.enter("$Entities")?;
                parse_entities(&mut r)?;
                r.sc.expect_marker("$EndEntities")?;
            }
            _ if name.starts_with(b"$") && !name.starts_with(b"$End") => {
                r.sc.section = "unknown";
                let end = format!("$End{}", String::from_utf8_lossy(&name[1..]));
                r.sc.skip_section(&end)?;
            }
            _ => {
                r.sc.section = "top level";
                return Err(r.sc.garbage(&t, "a section start such as `$Nodes`"));
            }
        }
    }
    if !seen_nodes {
        return Err(missing(path, "$Nodes"));
    }
    if !seen_elements {
        return Err(missing(path, "$Elements"));
    }
    Ok(b)
}

fn missing(path: &Path, section: &'static str) -> ReadError {
    ReadError::MissingSection { path: path.to_path_buf(), section }
}

/// `$MeshFormat` `4.1 file-type data-size` [binary one] `$EndMeshFormat`.
fn parse_header(r: &mut Reader<'_>) -> Result<(), ReadError> {
    r.sc.section = "$MeshFormat";
    r.sc.expect_marker("$MeshFormat")?;
    let v = r.sc.token("the format version")?;
    if !v.is("4.1") {
        return Err(ReadError::UnsupportedVersion {
            path: r.path().to_path_buf(),
            at: r.sc.location_of(&v),
            version: super::shorten(&v.text()),
            supported: "4.1",
        });
    }
    let ft = r.sc.token("the file type (0 = ASCII, 1 = binary)")?;
    let binary = match ft.raw {
        b"0" => false,
        b"1" => true,
        _ => return Err(r.sc.garbage(&ft, "the file type (0 = ASCII, 1 = binary)")),
    };
    let ds = r.sc.token("the data size")?;
    if binary {
        let size_t = match ds.raw {
            b"4" => 4,
            b"8" => 8,
            _ => {
                return Err(ReadError::UnsupportedVersion {
                    path: r.path().to_path_buf(),
                    at: r.sc.location_of(&ds),
                    version: format!("4.1 binary with data size {}", super::shorten(&ds.text())),
                    supported: "data size 4 or 8",
                })
            }
        };
        r.sc.end_of_line()?;
        let at = r.sc.here();
        let one = r.sc.take(4, "the binary endianness marker (int 1)")?;
        let big_endian = match one {
            [1, 0, 0, 0] => false,
            [0, 0, 0, 1] => true,
            _ => return Err(r.malformed(at, "bad endianness marker: expected int 1".into())),
        };
        r.sc.binary = true;
        r.bin = Some(Binary { big_endian, size_t });
    } else if std::str::from_utf8(ds.raw).ok().and_then(|s| s.parse::<u32>().ok()).is_none() {
        return Err(r.sc.garbage(&ds, "the data size"));
    }
    r.sc.expect_marker("$EndMeshFormat")
}

/// Steps over `$Entities`: points, curves, surfaces and volumes with their physical tags and
/// bounding entities. Nothing is kept.
fn parse_entities(r: &mut Reader<'_>) -> Result<(), ReadError> {
    let mut counts = [0u64; 4];
    for (dim, c) in counts.iter_mut().enumerate() {
        *c = r.size_t(["number of points", "number of curves", "number of surfaces", "number of volumes"][dim])?;
    }
    for (dim, &count) in counts.iter().enumerate() {
        for _ in 0..count {
            r.int("entity tag")?;
            let coords = if dim == 0 { 3 } else { 6 };
            for _ in 0..coords {
                r.float("entity bounding-box coordinate")?;
            }
            let physicals = r.size_t("number of physical tags")?;
            for _ in 0..physicals {
                r.int("physical tag")?;
            }
            if dim > 0 {
                let bounding = r.size_t("number of bounding entities")?;
                for _ in 0..bounding {
                    r.int("bounding entity tag")?;
                }
            }
        }
    }
    Ok(())
}

/// `$Nodes`: header, then blocks of tags followed by coordinates.
fn parse_nodes(r: &mut Reader<'_>, b: &mut MeshBuilder) -> Result<(), ReadError> {
    let path = r.path();
    let blocks = r.size_t("number of node entity blocks")?;
    let at = r.sc.here();
    let declared = r.size_t("total number of nodes")?;
    let min_node = match r.bin {
        None => MIN_TEXT_NODE,
        Some(bin) => bin.size_t + 24,
    };
    let n = bounded_count(path, at, "node", declared, min_node, r.sc.remaining())?;
    b.reserve_points(n);
    r.size_t("minimum node tag")?;
    r.size_t("maximum node tag")?;
    let mut found = 0u64;
    // Each tag with its line (text) or byte offset (binary): a duplicate is reported there, not
    // at the coordinates.
    let mut tags: Vec<(u64, usize)> = Vec::new();
    let binary = r.bin.is_some();
    let located = |n: usize| if binary { Location::Byte(n) } else { Location::Line(n) };
    for _ in 0..blocks {
        let dim_at = r.sc.here();
        let dim = r.int("entity dimension")?;
        r.int("entity tag")?;
        let parametric = r.int("parametric flag (0 or 1)")?;
        let at = r.sc.here();
        let count = r.size_t("number of nodes in the block")?;
        let count = bounded_count(path, at, "node", count, min_node, r.sc.remaining())?;
        let extra = match (parametric, dim) {
            (0, 0..=3) => 0,
            (1, 0..=3) => dim as usize,
            (0 | 1, _) => return Err(r.malformed(dim_at, format!("entity dimension {dim}"))),
            _ => return Err(r.malformed(dim_at, format!("parametric flag {parametric}"))),
        };
        tags.clear();
        tags.reserve(count);
        for _ in 0..count {
            let (Location::Line(n) | Location::Byte(n)) = r.sc.here();
            tags.push((r.size_t("node tag")?, n));
        }
        for &(tag, tag_at) in &tags {
            let at = r.sc.here();
            let x = r.float("node x coordinate")?;
            let y = r.float("node y coordinate")?;
            let z = r.float("node z coordinate")?;
            for _ in 0..extra {
                r.float("node parametric coordinate")?;
            }
            b.add_node_split(path, located(tag_at), at, tag, [x, y, z])?;
        }
        found = found.saturating_add(count as u64);
    }
    if found != declared {
        let at = r.sc.here();
        return Err(ReadError::CountMismatch {
            path: path.to_path_buf(),
            at,
            what: "number of nodes in `$Nodes`",
            declared,
            found,
        });
    }
    Ok(())
}

/// `$Elements`: header, then blocks of one element type each.
fn parse_elements(r: &mut Reader<'_>, b: &mut MeshBuilder) -> Result<(), ReadError> {
    let path = r.path();
    let blocks = r.size_t("number of element entity blocks")?;
    let at = r.sc.here();
    let declared = r.size_t("total number of elements")?;
    let min_element = match r.bin {
        None => MIN_TEXT_ELEMENT,
        Some(bin) => 2 * bin.size_t,
    };
    bounded_count(path, at, "element", declared, min_element, r.sc.remaining())?;
    r.size_t("minimum element tag")?;
    r.size_t("maximum element tag")?;
    let mut found = 0u64;
    let mut nodes: Vec<u64> = Vec::new();
    for _ in 0..blocks {
        r.int("entity dimension")?;
        r.int("entity tag")?;
        let type_at = r.sc.here();
        let element_type = r.int("element type")?;
        let kind = b.element_kind(path, type_at, element_type)?;
        let at = r.sc.here();
        let count = r.size_t("number of elements in the block")?;
        let per_element = (kind.nodes + 1) * r.size_t_bytes().max(2);
        bounded_count(path, at, "element", count, per_element, r.sc.remaining())?;
        for _ in 0..count {
            let at = r.sc.here();
            let tag = r.size_t("element tag")?;
            nodes.clear();
            for _ in 0..kind.nodes {
                nodes.push(r.size_t("element node tag")?);
            }
            b.add_element(path, at, tag, kind.usage, &nodes)?;
        }
        found = found.saturating_add(count);
    }
    if found != declared {
        let at = r.sc.here();
        return Err(ReadError::CountMismatch {
            path: path.to_path_buf(),
            at,
            what: "number of elements in `$Elements`",
            declared,
            found,
        });
    }
    Ok(())
}
