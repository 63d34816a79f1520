//! Gmsh MSH 2.x ASCII (2.0, 2.1, 2.2): `$MeshFormat`, `$Nodes`, `$Elements`; other sections
//! are skipped up to their `$End...` marker. Binary 2.x is rejected as unsupported.

use std::path::Path;

use super::build::{bounded_count, MeshBuilder, Target};
use super::scan::Scanner;
use super::{shorten, ReadError};

/// Smallest number of bytes one node record takes (`1 0 0 0\n`).
const MIN_NODE: usize = 8;
/// Smallest number of bytes one element record takes (`1 15 0 1\n`).
const MIN_ELEMENT: usize = 8;

/// The section names of one Gmsh ASCII dialect, for [`parse_sections`].
pub(crate) struct Dialect {
    /// Start and end markers of the node section.
    pub nodes: [&'static str; 2],
    /// Start and end markers of the element section.
    pub elements: [&'static str; 2],
    /// Whether other `$Name` ... `$EndName` sections are skipped (2.x) or are garbage (v1).
    pub skips_unknown: bool,
    /// What the error names as expected at top level.
    pub expected: &'static str,
    /// How an element record is laid out.
    pub records: ElementRecords,
}

/// The layout of one dialect's element records, `tag type <fields> node...`, for
/// [`element_records`].
pub(crate) struct ElementRecords {
    /// Fewest bytes one record takes (the declared count is bounded by the bytes left).
    pub min_bytes: usize,
    /// What the dialect calls an element's id (the messages name it).
    pub tag: &'static str,
    /// What the dialect calls a node id in an element record.
    pub node: &'static str,
    /// Reads the fields between the type and the nodes; returns the node count the record
    /// declares, when it declares one (checked against the type's).
    pub fields: fn(&mut Scanner<'_>) -> Result<Option<u64>, ReadError>,
}

/// The 2.x markers; other `$Name` sections are skipped.
const MSH22: Dialect = Dialect {
    nodes: ["$Nodes", "$EndNodes"],
    elements: ["$Elements", "$EndElements"],
    skips_unknown: true,
    expected: "a section start such as `$Nodes`",
    records: ElementRecords {
        min_bytes: MIN_ELEMENT,
        tag: "an element tag",
        node: "an element node tag",
        fields: tag_list,
    },
};

/// The 2.x fields between an element's type and its nodes: a count, then that many tags
/// (physical, elementary, partition...). No node count is declared.
fn tag_list(sc: &mut Scanner<'_>) -> Result<Option<u64>, ReadError> {
    let tag_count = sc.u64("the number of element tags")?;
    for _ in 0..tag_count {
        sc.i64("an element tag (physical, elementary, partition)")?;
    }
    Ok(None)
}

/// Parses an MSH 2.x ASCII file into a builder for a read of `target`.
pub(crate) fn parse(data: &[u8], path: &Path, target: Target) -> Result<MeshBuilder, ReadError> {
    let mut sc = Scanner::new(data, path);
    parse_header(&mut sc)?;
    parse_sections(&mut sc, &MSH22, target)
}

/// The top-level loop of the Gmsh ASCII dialects: one node section (`tag x y z` records), then
/// one element section laid out as `dialect.records`, both required, nodes first. O(bytes).
pub(crate) fn parse_sections(
    sc: &mut Scanner<'_>,
    dialect: &Dialect,
    target: Target,
) -> Result<MeshBuilder, ReadError> {
    let path = sc.path();
    let mut b = MeshBuilder::for_target(target);
    let (mut seen_nodes, mut seen_elements) = (false, false);
    let ([nodes, end_nodes], [elems, end_elems]) = (dialect.nodes, dialect.elements);
    while let Some(t) = sc.next_raw() {
        match t.raw {
            name if name == nodes.as_bytes() => {
                sc.section = nodes;
                node_records(sc, &mut b)?;
                sc.expect_marker(end_nodes)?;
                seen_nodes = true;
            }
            name if name == elems.as_bytes() => {
                sc.section = elems;
                if !seen_nodes {
                    let message = format!("`{elems}` before `{nodes}`");
                    return Err(ReadError::Malformed { path: path.to_path_buf(), at: sc.location_of(&t), message });
                }
                element_records(sc, &mut b, &dialect.records)?;
                sc.expect_marker(end_elems)?;
                seen_elements = true;
            }
            name if dialect.skips_unknown && name.starts_with(b"$") && !name.starts_with(b"$End") => {
                sc.section = "unknown";
                let end = format!("$End{}", String::from_utf8_lossy(&name[1..]));
                sc.skip_section(&end)?;
            }
            _ => {
                sc.section = "top level";
                return Err(sc.garbage(&t, dialect.expected));
            }
        }
    }
    for (seen, section) in [(seen_nodes, nodes), (seen_elements, elems)] {
        if !seen {
            return Err(ReadError::MissingSection { path: path.to_path_buf(), section });
        }
    }
    Ok(b)
}

/// `$MeshFormat` `2.x 0 data-size` `$EndMeshFormat`.
fn parse_header(sc: &mut Scanner<'_>) -> Result<(), ReadError> {
    sc.section = "$MeshFormat";
    sc.expect_marker("$MeshFormat")?;
    let v = sc.token("the format version")?;
    let ft = sc.token("the file type (0 = ASCII)")?;
    match ft.raw {
        b"0" => {}
        b"1" => {
            return Err(ReadError::UnsupportedVersion {
                path: sc.path().to_path_buf(),
                at: sc.location_of(&ft),
                version: format!("{} binary", shorten(&v.text())),
                supported: "MSH 2.x ASCII only",
            })
        }
        _ => return Err(sc.garbage(&ft, "the file type (0 = ASCII)")),
    }
    sc.u64("the data size")?;
    sc.expect_marker("$EndMeshFormat")
}

/// The body of a `$Nodes` (2.x) or `$NOD` (v1) section: a count, then `tag x y z` records.
pub(crate) fn node_records(sc: &mut Scanner<'_>, b: &mut MeshBuilder) -> Result<(), ReadError> {
    let path = sc.path();
    let at = sc.here();
    let count = sc.u64("the number of nodes")?;
    let n = bounded_count(path, at, "node", count, MIN_NODE, sc.remaining())?;
    b.reserve_points(n);
    for _ in 0..n {
        let at = sc.here();
        let tag = sc.u64("a node tag")?;
        let x = sc.f64("node x coordinate")?;
        let y = sc.f64("node y coordinate")?;
        let z = sc.f64("node z coordinate")?;
        b.add_node(path, at, tag, [x, y, z])?;
    }
    Ok(())
}

/// The body of an element section (`$Elements`, `$ELM`): a count, then `tag type <fields>
/// node...` records, the fields and the words of the messages as `layout` says. O(bytes).
fn element_records(sc: &mut Scanner<'_>, b: &mut MeshBuilder, layout: &ElementRecords) -> Result<(), ReadError> {
    let path = sc.path();
    let at = sc.here();
    let count = sc.u64("the number of elements")?;
    let n = bounded_count(path, at, "element", count, layout.min_bytes, sc.remaining())?;
    let mut nodes: Vec<u64> = Vec::new();
    for _ in 0..n {
        let at = sc.here();
        let tag = sc.u64(layout.tag)?;
        let type_at = sc.here();
        let element_type = sc.i64("an element type")?;
        let declared = (layout.fields)(sc)?;
        let kind = b.element_kind(path, type_at, element_type)?;
        if let Some(declared) = declared.filter(|&d| d != kind.nodes as u64) {
            let message = format!(
                "element {tag} of type {element_type} declares {declared} nodes, but that type has {}",
                kind.nodes
            );
            return Err(ReadError::Malformed { path: path.to_path_buf(), at, message });
        }
        nodes.clear();
        for _ in 0..kind.nodes {
            nodes.push(sc.u64(layout.node)?);
        }
        b.add_element(path, at, tag, kind.usage, &nodes)?;
    }
    Ok(())
}
