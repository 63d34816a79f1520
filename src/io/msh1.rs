//! Gmsh MSH version 1 (the format SOFA ships its meshes in): `$NOD` ... `$ENDNOD` and
//! `$ELM` ... `$ENDELM`. Element records are
//! `number type physical-region elementary-region number-of-nodes node-tag...`.

use std::path::Path;

use super::build::{bounded_count, gmsh_element_kind, MeshBuilder};
use super::msh22::{parse_sections, Dialect};
use super::scan::Scanner;
use super::ReadError;

/// Smallest number of bytes one element record takes (`1 15 0 0 1 1\n`).
const MIN_ELEMENT: usize = 12;

/// The v1 markers; any other section is garbage.
const MSH1: Dialect = Dialect {
    nodes: ["$NOD", "$ENDNOD"],
    elements: ["$ELM", "$ENDELM"],
    skips_unknown: false,
    expected: "`$NOD` or `$ELM`",
};

/// Parses an MSH v1 file into a builder.
pub(crate) fn parse(data: &[u8], path: &Path) -> Result<MeshBuilder, ReadError> {
    parse_sections(&mut Scanner::new(data, path), &MSH1, element_records)
}

/// The body of `$ELM`: a count, then element records.
fn element_records(sc: &mut Scanner<'_>, b: &mut MeshBuilder) -> Result<(), ReadError> {
    let path = sc.path();
    let at = sc.here();
    let count = sc.u64("the number of elements")?;
    let n = bounded_count(path, at, "element", count, MIN_ELEMENT, sc.remaining())?;
    let mut nodes: Vec<u64> = Vec::new();
    for _ in 0..n {
        let at = sc.here();
        let tag = sc.u64("an element number")?;
        let type_at = sc.here();
        let element_type = sc.i64("an element type")?;
        sc.i64("the physical region")?;
        sc.i64("the elementary region")?;
        let declared = sc.u64("the number of nodes")?;
        let kind = gmsh_element_kind(path, type_at, element_type)?;
        if declared != kind.nodes as u64 {
            return Err(ReadError::Malformed {
                path: path.to_path_buf(),
                at,
                message: format!(
                    "element {tag} of type {element_type} declares {declared} nodes, \
                     but that type has {}",
                    kind.nodes
                ),
            });
        }
        nodes.clear();
        for _ in 0..kind.nodes {
            nodes.push(sc.u64("an element node number")?);
        }
        b.add_element(path, at, tag, kind.usage, &nodes)?;
    }
    Ok(())
}
