//! Gmsh MSH version 1 (the format SOFA ships its meshes in): `$NOD` ... `$ENDNOD` and
//! `$ELM` ... `$ENDELM`. Element records are
//! `number type physical-region elementary-region number-of-nodes node-tag...`.

use std::path::Path;

use super::build::{MeshBuilder, Target};
use super::msh22::{parse_sections, Dialect, ElementRecords};
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
    records: ElementRecords {
        min_bytes: MIN_ELEMENT,
        tag: "an element number",
        node: "an element node number",
        fields: regions_and_node_count,
    },
};

/// Parses an MSH v1 file into a builder for a read of `target`.
pub(crate) fn parse(data: &[u8], path: &Path, target: Target) -> Result<MeshBuilder, ReadError> {
    parse_sections(&mut Scanner::new(data, path), &MSH1, target)
}

/// The v1 fields between an element's type and its nodes: the physical and elementary regions
/// and the declared number of nodes.
fn regions_and_node_count(sc: &mut Scanner<'_>) -> Result<Option<u64>, ReadError> {
    sc.i64("the physical region")?;
    sc.i64("the elementary region")?;
    sc.u64("the number of nodes").map(Some)
}
