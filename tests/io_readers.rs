//! Mesh-file readers: reference meshes, hand-written fixtures, malformed input, fuzzing.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use proptest::prelude::*;
use topomech::io::{self, ReadError};
use topomech::mesh::{signed_volume, TetMesh};

// ---------------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------------

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures").join(name)
}

fn fixture_text(name: &str) -> String {
    std::fs::read_to_string(fixture(name)).unwrap()
}

/// `../shared/meshes/`, or `None` (with a printed note) when it is absent.
fn shared_meshes() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/meshes");
    if dir.join("README.md").is_file() {
        Some(dir)
    } else {
        println!("note: {} is absent; reference-mesh test skipped", dir.display());
        None
    }
}

fn msh(text: &str) -> Result<TetMesh, ReadError> {
    io::parse_msh(text.as_bytes(), Path::new("test.msh"))
}

/// Reads `text` as MSH and returns the error message; fails if it parses.
fn msh_err(text: &str) -> String {
    match msh(text) {
        Ok(m) => panic!("expected an error, got a mesh with {} tets", m.tets.len()),
        Err(e) => e.to_string(),
    }
}

fn assert_contains(message: &str, parts: &[&str]) {
    for p in parts {
        assert!(message.contains(p), "message {message:?} does not contain {p:?}");
    }
}

/// The tets as sorted tag quadruples, each with the sign of its volume.
fn tets_by_tag(m: &TetMesh) -> BTreeMap<[u64; 4], bool> {
    m.tets
        .iter()
        .map(|t| {
            let mut key = t.map(|v| m.node_tags[v as usize]);
            key.sort_unstable();
            let c = t.map(|v| m.points[v as usize]);
            (key, signed_volume(c[0], c[1], c[2], c[3]) > 0.0)
        })
        .collect()
}

fn points_by_tag(m: &TetMesh) -> BTreeMap<u64, [f64; 3]> {
    m.node_tags.iter().copied().zip(m.points.iter().copied()).collect()
}

/// Same tets (up to point renumbering, by tag) with the same orientation and the same
/// coordinates for every tag.
fn assert_same_mesh(a: &TetMesh, b: &TetMesh) {
    assert_eq!(a.tets.len(), b.tets.len());
    assert_eq!(tets_by_tag(a), tets_by_tag(b));
    let (pa, pb) = (points_by_tag(a), points_by_tag(b));
    assert_eq!(pa.len(), pb.len());
    for (tag, p) in &pa {
        let q = pb[tag];
        for k in 0..3 {
            assert!((p[k] - q[k]).abs() <= 1e-12 * (1.0 + p[k].abs()), "tag {tag}");
        }
    }
}

// ---------------------------------------------------------------------------------------------
// MSH 4.1 ASCII -> binary converter (test helper, follows the MSH 4.1 binary layout)
// ---------------------------------------------------------------------------------------------

struct BinWriter {
    out: Vec<u8>,
    big_endian: bool,
    size_t: usize,
}

impl BinWriter {
    fn text(&mut self, s: &str) {
        self.out.extend_from_slice(s.as_bytes());
    }
    fn size_t(&mut self, tok: &str) {
        let v: u64 = tok.parse().unwrap();
        match (self.size_t, self.big_endian) {
            (4, false) => self.out.extend((v as u32).to_le_bytes()),
            (4, true) => self.out.extend((v as u32).to_be_bytes()),
            (_, false) => self.out.extend(v.to_le_bytes()),
            (_, true) => self.out.extend(v.to_be_bytes()),
        }
    }
    fn int(&mut self, tok: &str) {
        let v: i32 = tok.parse().unwrap();
        if self.big_endian {
            self.out.extend(v.to_be_bytes());
        } else {
            self.out.extend(v.to_le_bytes());
        }
    }
    fn float(&mut self, tok: &str) {
        let v: f64 = tok.parse().unwrap();
        if self.big_endian {
            self.out.extend(v.to_be_bytes());
        } else {
            self.out.extend(v.to_le_bytes());
        }
    }
}

fn nodes_per_gmsh_type(t: &str) -> usize {
    match t {
        "15" => 1,
        "1" => 2,
        "2" => 3,
        "4" => 4,
        other => panic!("converter: element type {other}"),
    }
}

/// Writes the start of a block section (`$Nodes` or `$Elements`): its name, then its block count
/// and three more counts as size_t. Returns the block count.
fn section_header<'a>(w: &mut BinWriter, name: &str, next: &mut impl FnMut() -> &'a str) -> u64 {
    w.text(&format!("{name}\n"));
    let blocks = next();
    w.size_t(blocks);
    for _ in 0..3 {
        w.size_t(next());
    }
    blocks.parse().unwrap()
}

/// Writes a block header: entity dimension and tag, a third int (the parametric flag of a node
/// block, the element type of an element block) and the entry count as size_t. Returns the third
/// int's text and the count.
fn block_header<'a>(w: &mut BinWriter, next: &mut impl FnMut() -> &'a str) -> (&'a str, usize) {
    w.int(next());
    w.int(next());
    let third = next();
    w.int(third);
    let n = next();
    w.size_t(n);
    (third, n.parse().unwrap())
}

/// Converts an ASCII MSH 4.1 file to binary: `$Entities`, `$Nodes` (non-parametric) and
/// `$Elements` are encoded, other sections are copied as text.
fn ascii41_to_binary(text: &str, big_endian: bool, size_t: usize) -> Vec<u8> {
    let mut w = BinWriter { out: Vec::new(), big_endian, size_t };
    let mut lines = text.lines();
    while let Some(start) = lines.next() {
        let name = start.trim();
        let end = format!("$End{}", &name[1..]);
        let body: Vec<&str> = lines.by_ref().take_while(|l| l.trim() != end).collect();
        let mut t = body.iter().flat_map(|l| l.split_whitespace());
        let mut next = || t.next().unwrap();
        match name {
            "$MeshFormat" => {
                w.text(&format!("$MeshFormat\n4.1 1 {size_t}\n"));
                w.int("1");
                w.text("\n$EndMeshFormat\n");
                continue;
            }
            "$Entities" => {
                w.text("$Entities\n");
                let counts: Vec<u64> = (0..4)
                    .map(|_| {
                        let c = next();
                        w.size_t(c);
                        c.parse().unwrap()
                    })
                    .collect();
                for (dim, &count) in counts.iter().enumerate() {
                    for _ in 0..count {
                        w.int(next());
                        for _ in 0..if dim == 0 { 3 } else { 6 } {
                            w.float(next());
                        }
                        let lists = if dim == 0 { 1 } else { 2 };
                        for _ in 0..lists {
                            let n = next();
                            w.size_t(n);
                            for _ in 0..n.parse::<u64>().unwrap() {
                                w.int(next());
                            }
                        }
                    }
                }
            }
            "$Nodes" => {
                for _ in 0..section_header(&mut w, name, &mut next) {
                    let (parametric, n) = block_header(&mut w, &mut next);
                    assert_eq!(parametric, "0");
                    for _ in 0..n {
                        w.size_t(next());
                    }
                    for _ in 0..3 * n {
                        w.float(next());
                    }
                }
            }
            "$Elements" => {
                for _ in 0..section_header(&mut w, name, &mut next) {
                    let (ty, n) = block_header(&mut w, &mut next);
                    for _ in 0..(1 + nodes_per_gmsh_type(ty)) * n {
                        w.size_t(next());
                    }
                }
            }
            _ => {
                w.text(&format!("{name}\n"));
                for l in &body {
                    w.text(&format!("{l}\n"));
                }
                w.text(&format!("{end}\n"));
                continue;
            }
        }
        w.text(&format!("\n{end}\n"));
    }
    w.out
}

// ---------------------------------------------------------------------------------------------
// Reference meshes from ../shared/meshes
// ---------------------------------------------------------------------------------------------

/// (file, nodes, tets, edges, boundary faces, volume) from `../shared/meshes/README.md`.
const REFERENCE: [(&str, usize, usize, usize, usize, f64); 8] = [
    ("liver_547.msh", 547, 1852, 2833, 870, 38.17),
    ("liver_547_v22.msh", 547, 1852, 2833, 870, 38.17),
    ("liver_547.node", 547, 1852, 2833, 870, 38.17),
    ("liver_1814.msh", 1814, 7453, 10409, 2286, 38.89),
    ("box_458.msh", 458, 1566, 2377, 708, 1.0),
    ("box_458_v22.msh", 458, 1566, 2377, 708, 1.0),
    ("sfepy_cube_medium_tetra.msh", 448, 1782, 2493, 528, 1.0),
    ("sofa_liver_v1.msh", 181, 596, 914, 276, 36.56),
];

#[test]
fn reference_meshes_match_readme_counts() {
    let Some(dir) = shared_meshes() else { return };
    for (file, nodes, tets, edges, faces, volume) in REFERENCE {
        let m = io::read_mesh(&dir.join(file)).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(m.points.len(), nodes, "{file} nodes");
        assert_eq!(m.tets.len(), tets, "{file} tets");
        assert_eq!(m.edge_count(), edges, "{file} edges");
        assert_eq!(m.boundary_face_count(), faces, "{file} boundary faces");
        assert_eq!(m.boundary_triangles_of_tets().len(), faces, "{file}");
        let v = m.total_volume().unwrap();
        assert!((v - volume).abs() < 1e-2, "{file} volume {v}");
        // README: no inverted tet; the file's triangles (if any) are exactly the boundary.
        let report = m.check().unwrap();
        assert!(report.is_clean(), "{file}: {report:?}");
        assert!(m.boundary_triangles.is_empty() || m.boundary_triangles.len() == faces, "{file}");
    }
}

#[test]
fn liver_547_same_mesh_in_three_formats() {
    let Some(dir) = shared_meshes() else { return };
    let v41 = io::read_mesh(&dir.join("liver_547.msh")).unwrap();
    let v22 = io::read_mesh(&dir.join("liver_547_v22.msh")).unwrap();
    let tetgen = io::read_mesh(&dir.join("liver_547.ele")).unwrap();
    assert_same_mesh(&v41, &v22);
    assert_same_mesh(&v41, &tetgen);
    assert_eq!(v41.boundary_triangles.len(), v22.boundary_triangles.len());
}

#[test]
fn box_458_same_mesh_in_two_formats() {
    let Some(dir) = shared_meshes() else { return };
    let v41 = io::read_mesh(&dir.join("box_458.msh")).unwrap();
    let v22 = io::read_mesh(&dir.join("box_458_v22.msh")).unwrap();
    assert_same_mesh(&v41, &v22);
}

/// Our MSH 4.1 reader agrees with the `mshio` crate on node and tet counts and on every tet's
/// node tags (ASCII and binary files).
#[test]
fn msh41_agrees_with_mshio() {
    let Some(dir) = shared_meshes() else { return };
    for file in ["liver_547.msh", "liver_1814.msh", "box_458.msh", "sfepy_cube_medium_tetra.msh"] {
        let bytes = std::fs::read(dir.join(file)).unwrap();
        let ours = io::parse_msh(&bytes, Path::new(file)).unwrap();
        let theirs = mshio::parse_msh_bytes(&bytes).unwrap();
        let mut tets: Vec<[u64; 4]> = Vec::new();
        let elements = theirs.data.elements.unwrap();
        for block in &elements.element_blocks {
            if block.element_type == mshio::ElementType::Tet4 {
                for e in &block.elements {
                    tets.push([e.nodes[0], e.nodes[1], e.nodes[2], e.nodes[3]]);
                }
            }
        }
        let our_tets: Vec<[u64; 4]> = ours.tets.iter().map(|t| t.map(|v| ours.node_tags[v as usize])).collect();
        assert_eq!(our_tets, tets, "{file}");
        let nodes = theirs.data.nodes.unwrap();
        assert_eq!(nodes.num_nodes as usize, ours.points.len(), "{file}");
    }
}

#[test]
fn liver_surface_as_tri_mesh() {
    let Some(dir) = shared_meshes() else { return };
    let path = dir.join("liver_547.msh");
    let surface = io::read_tri_mesh(&path).unwrap();
    let volume = io::read_mesh(&path).unwrap();
    assert_eq!(surface.triangles.len(), 870);
    let sorted = |t: &[u32; 3]| {
        let mut t = *t;
        t.sort_unstable();
        t
    };
    let a: BTreeSet<[u32; 3]> = surface.triangles.iter().map(sorted).collect();
    let b: BTreeSet<[u32; 3]> = volume.boundary_triangles_of_tets().iter().map(sorted).collect();
    assert_eq!(a, b);
}

// ---------------------------------------------------------------------------------------------
// Hand-written fixtures
// ---------------------------------------------------------------------------------------------

#[test]
fn single_tet_with_sparse_tags() {
    let m = io::read_mesh(&fixture("single_tet.msh")).unwrap();
    assert_eq!(m.node_tags, vec![10, 20, 30, 40]);
    assert_eq!(m.tets, vec![[0, 1, 2, 3]]);
    assert!((m.total_volume().unwrap() - 1.0 / 6.0).abs() < 1e-15);
    assert!(m.check().unwrap().is_clean());
}

#[test]
fn two_tets_sharing_a_face() {
    let m = io::read_mesh(&fixture("two_tets.msh")).unwrap();
    assert_eq!(m.points.len(), 5);
    assert_eq!(m.node_tags, vec![1, 2, 3, 5, 8]);
    assert_eq!(m.tets.len(), 2);
    assert_eq!(m.edge_count(), 9);
    assert_eq!(m.boundary_face_count(), 6);
    assert!((m.total_volume().unwrap() - 0.5).abs() < 1e-15);
    // The point and line elements are skipped; the six triangles are the boundary.
    assert_eq!(m.boundary_triangles.len(), 6);
    assert!(m.check().unwrap().is_clean());
    // As a surface: the six triangles.
    let s = io::read_tri_mesh(&fixture("two_tets.msh")).unwrap();
    assert_eq!(s.triangles.len(), 6);
}

fn check_cube5(m: &TetMesh, name: &str) {
    assert_eq!(m.points.len(), 8, "{name}");
    assert_eq!(m.tets.len(), 5, "{name}");
    assert_eq!(m.edge_count(), 18, "{name}");
    assert_eq!(m.boundary_face_count(), 12, "{name}");
    assert!((m.total_volume().unwrap() - 1.0).abs() < 1e-14, "{name}");
    let r = m.check().unwrap();
    assert!(r.zero_volume_tets.is_empty() && r.inverted_tets.is_empty(), "{name}");
}

#[test]
fn cube5_in_every_format() {
    let v41 = io::read_mesh(&fixture("cube5.msh")).unwrap();
    check_cube5(&v41, "cube5.msh");
    assert_eq!(v41.node_tags, vec![3, 7, 11, 100, 250, 1000, 1001, 5000]);
    for name in ["cube5_v22.msh", "cube5_v1.msh", "cube5_bin.msh"] {
        let m = io::read_mesh(&fixture(name)).unwrap_or_else(|e| panic!("{e}"));
        check_cube5(&m, name);
        assert_same_mesh(&v41, &m);
    }
    // TetGen, 0-based: same geometry, different numbering.
    let t = io::read_mesh(&fixture("cube5.node")).unwrap();
    check_cube5(&t, "cube5.node");
    assert_eq!(t.node_tags, (0..8).collect::<Vec<u64>>());
    let remap = |m: &TetMesh| {
        let mut v: Vec<[[u64; 3]; 4]> = m
            .tets
            .iter()
            .map(|t| {
                let mut c = t.map(|i| m.points[i as usize].map(|x| x as u64));
                c.sort_unstable();
                c
            })
            .collect();
        v.sort_unstable();
        v
    };
    assert_eq!(remap(&t), remap(&v41));
}

#[test]
fn binary_fixture_matches_converter_and_variants_parse() {
    let text = fixture_text("cube5.msh");
    let committed = std::fs::read(fixture("cube5_bin.msh")).unwrap();
    assert_eq!(ascii41_to_binary(&text, false, 8), committed);
    let reference = msh(&text).unwrap();
    for big_endian in [false, true] {
        for size_t in [4, 8] {
            let bytes = ascii41_to_binary(&text, big_endian, size_t);
            let m = io::parse_msh(&bytes, Path::new("cube5.bin")).unwrap();
            assert_eq!(m, reference, "big endian {big_endian}, size_t {size_t}");
        }
    }
    // A file with `$PhysicalNames`, `$Entities` and a trailing `$NodeData`.
    let text = fixture_text("two_tets.msh");
    let reference = msh(&text).unwrap();
    let m = io::parse_msh(&ascii41_to_binary(&text, false, 8), Path::new("b")).unwrap();
    assert_eq!(m, reference);
}

#[test]
#[ignore = "writes tests/fixtures/cube5_bin.msh; run by hand after changing cube5.msh"]
fn regenerate_binary_fixture() {
    let bytes = ascii41_to_binary(&fixture_text("cube5.msh"), false, 8);
    std::fs::write(fixture("cube5_bin.msh"), bytes).unwrap();
}

#[test]
fn liver_547_through_binary_converter() {
    let Some(dir) = shared_meshes() else { return };
    let text = std::fs::read_to_string(dir.join("liver_547.msh")).unwrap();
    let a = msh(&text).unwrap();
    let b = io::parse_msh(&ascii41_to_binary(&text, true, 8), Path::new("x")).unwrap();
    assert_eq!(a, b);
}

/// Index of the first occurrence of `pattern` in `bytes`.
fn find_bytes(bytes: &[u8], pattern: &[u8]) -> usize {
    bytes.windows(pattern.len()).position(|w| w == pattern).unwrap()
}

/// In a binary file the data starts after the line of the marker before it; blanks and a
/// carriage return (a file written on Windows) may end that line.
#[test]
fn binary_markers_may_end_in_blanks_and_crlf() {
    let reference = msh(TET41).unwrap();
    let plain = ascii41_to_binary(TET41, false, 8);
    let mut padded = plain.clone();
    for (from, to) in [
        (&b"4.1 1 8\n"[..], &b"4.1 1 8 \t\r\n"[..]),
        (b"$Nodes\n", b"$Nodes  \r\n"),
        (b"$Elements\n", b"$Elements\t\r\n"),
    ] {
        let at = find_bytes(&padded, from);
        padded.splice(at..at + from.len(), to.iter().copied());
    }
    assert_eq!(padded.len(), plain.len() + 3 + 3 + 2);
    let m = io::parse_msh(&padded, Path::new("crlf.msh")).unwrap();
    assert_eq!(m, reference);
    // Anything else after a marker is garbage, named with its line.
    let at = find_bytes(&plain, b"$Nodes\n") + "$Nodes".len();
    let mut bad = plain.clone();
    bad.splice(at..at, *b" x");
    let e = io::parse_msh(&bad, Path::new("x.msh")).unwrap_err().to_string();
    assert_contains(&e, &["x.msh", "garbage token `x`", "expected end of line"]);
}

/// The count of a binary element block is bounded by the bytes left over one element's
/// record, (nodes + 1) size_t values: a count that passes a weaker bound but not this one is
/// refused before reading, not found truncated afterwards.
#[test]
fn binary_element_count_is_bounded_by_the_record_size() {
    let mut bytes = ascii41_to_binary(TET41, false, 8);
    let section = find_bytes(&bytes, b"$Elements\n") + "$Elements\n".len();
    // size_t blocks, total, min tag, max tag; int dim, tag, type; size_t count.
    let (total, count) = (section + 8, section + 4 * 8 + 3 * 4);
    assert_eq!(bytes[count..count + 8], 1u64.to_le_bytes());
    // Left after the count: one tet record (5 × 8 bytes) and "\n$EndElements\n" (14): 54
    // bytes, enough for two records of 13 bytes but not for two of 40.
    for at in [total, count] {
        bytes[at..at + 8].copy_from_slice(&2u64.to_le_bytes());
    }
    let e = io::parse_msh(&bytes, Path::new("b.msh")).unwrap_err().to_string();
    assert_contains(&e, &["b.msh", "element count 2 is too large for the 54 bytes left"]);
}

#[test]
fn tri_meshes_obj_and_msh() {
    let obj = io::read_tri_mesh(&fixture("cube_surface.obj")).unwrap();
    let msh = io::read_tri_mesh(&fixture("cube_surface_v22.msh")).unwrap();
    for m in [&obj, &msh] {
        assert_eq!(m.points.len(), 8);
        assert_eq!(m.triangles.len(), 12);
        assert!((m.total_area().unwrap() - 6.0).abs() < 1e-14);
        assert!(m.check().unwrap().is_clean());
    }
    assert_eq!(obj.triangles, msh.triangles);
    // A surface file has no tetrahedra.
    let e = io::read_mesh(&fixture("cube_surface_v22.msh")).unwrap_err().to_string();
    assert_contains(&e, &["empty mesh", "cube_surface_v22.msh"]);
    // An OBJ file is refused by its extension, with the reason and the reader to use instead
    // (not as an MSH file with an unrecognised header).
    let e = io::read_mesh(&fixture("cube_surface.obj")).unwrap_err();
    assert!(matches!(e, ReadError::UnknownFormat { .. }), "{e}");
    assert_contains(&e.to_string(), &["cube_surface.obj", "OBJ holds a surface", "read_tri_mesh"]);
}

#[test]
fn missing_file_names_the_path() {
    let e = io::read_mesh(Path::new("/nonexistent/x.msh")).unwrap_err();
    assert!(matches!(e, ReadError::Io { .. }));
    assert_contains(&e.to_string(), &["/nonexistent/x.msh", "cannot read"]);
}

// ---------------------------------------------------------------------------------------------
// Malformed input
// ---------------------------------------------------------------------------------------------

/// Every text fixture, with the function that reads it from bytes.
/// A reader under test: parses bytes, discarding the mesh.
type ReadBytes = fn(&[u8]) -> Result<(), ReadError>;

fn text_fixtures() -> Vec<(&'static str, ReadBytes)> {
    fn tet(b: &[u8]) -> Result<(), ReadError> {
        io::parse_msh(b, Path::new("f.msh")).map(drop)
    }
    fn tri(b: &[u8]) -> Result<(), ReadError> {
        io::parse_msh_tri(b, Path::new("f.msh")).map(drop)
    }
    fn obj(b: &[u8]) -> Result<(), ReadError> {
        io::parse_obj(b, Path::new("f.obj")).map(drop)
    }
    fn node(b: &[u8]) -> Result<(), ReadError> {
        let ele = fixture_text("cube5.ele");
        io::parse_tetgen(b, Path::new("f.node"), ele.as_bytes(), Path::new("f.ele")).map(drop)
    }
    fn ele(b: &[u8]) -> Result<(), ReadError> {
        let node = fixture_text("cube5.node");
        io::parse_tetgen(node.as_bytes(), Path::new("f.node"), b, Path::new("f.ele")).map(drop)
    }
    vec![
        ("single_tet.msh", tet),
        ("two_tets.msh", tet),
        ("cube5.msh", tet),
        ("cube5_v22.msh", tet),
        ("cube5_v1.msh", tet),
        ("cube_surface_v22.msh", tri),
        ("cube_surface.obj", obj),
        ("cube5.node", node),
        ("cube5.ele", ele),
    ]
}

/// Cutting a fixture after any line gives an error that says what is missing.
#[test]
fn truncated_at_every_line() {
    for (name, read) in text_fixtures() {
        let text = fixture_text(name);
        let lines: Vec<&str> = text.trim_end().lines().collect();
        read(text.as_bytes()).unwrap_or_else(|e| panic!("{name}: {e}"));
        for k in 0..lines.len() {
            let prefix = lines[..k].join("\n");
            if name == "cube_surface.obj" {
                // OBJ has no counts: a prefix is a smaller (possibly empty) surface.
                if let Err(e) = read(prefix.as_bytes()) {
                    assert_contains(&e.to_string(), &["empty mesh"]);
                }
                continue;
            }
            let Err(e) = read(prefix.as_bytes()) else {
                // The only complete prefix is one that drops a trailing section we skip.
                assert_eq!(name, "two_tets.msh", "prefix of {k} lines parsed");
                assert!(lines[k..].iter().any(|l| l.starts_with("$NodeData")));
                continue;
            };
            let msg = e.to_string();
            let named =
                ["truncated", "missing section", "unknown mesh format", "empty mesh"].iter().any(|p| msg.contains(p));
            assert!(named, "{name}, {k} lines: {msg}");
        }
    }
}

/// Cutting the binary fixture at any byte gives an error.
#[test]
fn binary_truncated_at_every_byte() {
    let bytes = std::fs::read(fixture("cube5_bin.msh")).unwrap();
    let end = bytes.len() - b"$EndElements\n".len();
    for k in 0..end {
        let e = io::parse_msh(&bytes[..k], Path::new("b.msh"))
            .err()
            .unwrap_or_else(|| panic!("prefix of {k} bytes parsed"));
        let msg = e.to_string();
        let named = ["truncated", "missing section", "unknown mesh format", "garbage", "unsupported version"]
            .iter()
            .any(|p| msg.contains(p));
        assert!(named, "{k} bytes: {msg}");
    }
}

const TET41: &str = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n\
0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 4\n$EndElements\n";

const TET22: &str = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n\
3 0 1 0\n4 0 0 1\n$EndNodes\n$Elements\n1\n1 4 2 1 1 1 2 3 4\n$EndElements\n";

const TET1: &str = "$NOD\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$ENDNOD\n$ELM\n1\n\
1 4 1 1 4 1 2 3 4\n$ENDELM\n";

const NODE: &str = "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n";
const ELE: &str = "1 4 0\n1 1 2 3 4\n";

fn tetgen(node: &str, ele: &str) -> Result<TetMesh, ReadError> {
    io::parse_tetgen(node.as_bytes(), Path::new("t.node"), ele.as_bytes(), Path::new("t.ele"))
}

fn tetgen_err(node: &str, ele: &str) -> String {
    tetgen(node, ele).unwrap_err().to_string()
}

#[test]
fn small_inputs_parse() {
    for text in [TET41, TET22, TET1] {
        let m = msh(text).unwrap();
        assert_eq!((m.points.len(), m.tets.len()), (4, 1));
    }
    assert_eq!(tetgen(NODE, ELE).unwrap().tets, vec![[0, 1, 2, 3]]);
}

#[test]
fn garbage_tokens_are_named_with_their_line() {
    let e = msh_err(&TET41.replace("1 0 0\n0 1 0", "1 abc 0\n0 1 0"));
    assert_contains(&e, &["test.msh", "line 12", "garbage token `abc`", "$Nodes"]);
    let e = msh_err(&TET22.replace("3 0 1 0", "3 0 1 0x")); // "0x" is not a number
    assert_contains(&e, &["line 8", "garbage token `0x`"]);
    let e = msh_err(&TET1.replace("1 4 1 1 4", "1 four 1 1 4"));
    assert_contains(&e, &["line 10", "garbage token `four`", "element type"]);
    let e = tetgen_err(NODE, &ELE.replace("1 1 2", "1 1 #2"));
    assert_contains(&e, &["t.ele", "line 2", "truncated", "point number"]);
    let e = tetgen_err(&NODE.replace("2 1 0 0", "2 1 O 0"), ELE);
    assert_contains(&e, &["t.node", "line 3", "garbage token `O`"]);
    let e = msh_err(&format!("{TET41}stray\n"));
    assert_contains(&e, &["garbage token `stray`", "section start"]);
    let e = io::parse_obj(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n", Path::new("s.obj")).unwrap_err().to_string();
    assert_contains(&e, &["s.obj", "line 4", "garbage token `x`"]);
}

#[test]
fn undefined_node_tag() {
    let e = msh_err(&TET41.replace("1 1 2 3 4", "1 1 2 3 99"));
    assert_contains(&e, &["line 19", "node tag not defined", "99", "element 1"]);
    let e = msh_err(&TET22.replace("1 2 3 4\n$End", "1 2 3 0\n$End"));
    assert_contains(&e, &["node tag not defined", "node 0"]);
    let e = msh_err(&TET1.replace("1 2 3 4\n$END", "1 2 3 5\n$END"));
    assert_contains(&e, &["node tag not defined", "node 5"]);
    // A 0-based .ele against a 1-based .node.
    let e = tetgen_err(NODE, "1 4 0\n0 0 1 2 3\n");
    assert_contains(&e, &["t.ele", "line 2", "node tag not defined", "node 0"]);
    let e = io::parse_obj(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", Path::new("s.obj")).unwrap_err().to_string();
    assert_contains(&e, &["line 4", "node tag not defined", "node 4"]);
}

#[test]
fn repeated_vertex() {
    let e = msh_err(&TET41.replace("1 1 2 3 4", "1 1 2 3 3"));
    assert_contains(&e, &["line 19", "repeated vertex", "node 3"]);
    let e = msh_err(&TET22.replace("1 2 3 4\n$End", "1 2 1 4\n$End"));
    assert_contains(&e, &["repeated vertex", "node 1"]);
    let e = tetgen_err(NODE, "1 4 0\n1 1 2 4 4\n");
    assert_contains(&e, &["t.ele", "repeated vertex"]);
    let e = io::parse_obj(b"v 0 0 0\nv 1 0 0\nf 1 2 1\n", Path::new("s.obj")).unwrap_err().to_string();
    assert_contains(&e, &["repeated vertex"]);
}

#[test]
fn nan_and_infinite_coordinates() {
    let e = msh_err(&TET41.replace("0 1 0\n0 0 1", "0 nan 0\n0 0 1"));
    assert_contains(&e, &["line 13", "non-finite coordinate", "node 3", "NaN"]);
    let e = msh_err(&TET22.replace("4 0 0 1", "4 0 0 inf"));
    assert_contains(&e, &["non-finite coordinate", "node 4"]);
    let e = msh_err(&TET1.replace("2 1 0 0", "2 NaN 0 0"));
    assert_contains(&e, &["non-finite coordinate", "node 2"]);
    let e = tetgen_err(&NODE.replace("3 0 1 0", "3 0 1 -inf"), ELE);
    assert_contains(&e, &["t.node", "non-finite coordinate", "node 3"]);
}

#[test]
fn empty_mesh() {
    let no_tets = TET41.replace("3 1 4 1\n1 1 2 3 4", "2 1 2 1\n1 1 2 3");
    let e = msh_err(&no_tets);
    assert_contains(&e, &["test.msh", "empty mesh"]);
    let e =
        msh_err("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n0 0 0 0\n$EndNodes\n$Elements\n0 0 0 0\n$EndElements\n");
    assert_contains(&e, &["empty mesh"]);
    let e = msh_err("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n0\n$EndNodes\n$Elements\n0\n$EndElements\n");
    assert_contains(&e, &["empty mesh"]);
    let e = tetgen_err(NODE, "0 4 0\n");
    assert_contains(&e, &["empty mesh"]);
    let e = msh_err("");
    assert_contains(&e, &["unknown mesh format", "empty"]);
    let e = io::parse_obj(b"# nothing\n", Path::new("s.obj")).unwrap_err().to_string();
    assert_contains(&e, &["empty mesh"]);
}

#[test]
fn element_types() {
    let e = msh_err(&TET41.replace("3 1 4 1\n", "3 1 99 1\n"));
    assert_contains(&e, &["line 18", "unknown element type 99"]);
    let e = msh_err(&TET41.replace("3 1 4 1\n1 1 2 3 4", "3 1 11 1\n1 1 2 3 4 1 2 3 4 1 2"));
    assert_contains(&e, &["unsupported element type 11", "10-node"]);
    let e = msh_err(&TET22.replace("1 4 2 1 1", "1 11 2 1 1"));
    assert_contains(&e, &["unsupported element type 11"]);
    let e = msh_err(&TET22.replace("1 4 2 1 1", "1 0 2 1 1"));
    assert_contains(&e, &["unknown element type 0"]);
    let e = msh_err(&TET1.replace("1 4 1 1 4", "1 5 1 1 8"));
    assert_contains(&e, &["unsupported element type 5", "hexahedron"]);
    let e = msh_err(&TET1.replace("1 4 1 1 4", "1 4 1 1 5"));
    assert_contains(&e, &["declares 5 nodes"]);
    // Each ASCII dialect names the parts of its own element records.
    for (file, record, broken, expected) in [
        (TET1, "1 4 1 1 4 1 2 3 4", "x 4 1 1 4 1 2 3 4", "expected an element number"),
        (TET1, "1 4 1 1 4 1 2 3 4", "1 4 1 x 4 1 2 3 4", "expected the elementary region"),
        (TET1, "1 4 1 1 4 1 2 3 4", "1 4 1 1 4 1 2 x 4", "expected an element node number"),
        (TET22, "1 4 2 1 1 1 2 3 4", "x 4 2 1 1 1 2 3 4", "expected an element tag"),
        (TET22, "1 4 2 1 1 1 2 3 4", "1 4 2 1 x 1 2 3 4", "expected an element tag (physical, elementary"),
        (TET22, "1 4 2 1 1 1 2 3 4", "1 4 2 1 1 1 2 x 4", "expected an element node tag"),
    ] {
        assert!(file.contains(record));
        let e = msh_err(&file.replace(record, broken));
        assert_contains(&e, &["garbage token `x`", expected]);
    }
    let e = tetgen_err(NODE, "1 10 0\n1 1 2 3 4 1 2 3 4 1 2\n");
    assert_contains(&e, &["t.ele", "unsupported element type", "10-node"]);
}

#[test]
fn versions_and_headers() {
    let e = msh_err(&TET41.replace("4.1 0 8", "4.0 0 8"));
    assert_contains(&e, &["unsupported version `4.0`"]);
    let e = msh_err(&TET41.replace("4.1 0 8", "3.0 0 8"));
    assert_contains(&e, &["unsupported version `3.0`"]);
    let e = msh_err(&TET22.replace("2.2 0 8", "2.2 1 8"));
    assert_contains(&e, &["unsupported version", "binary"]);
    let e = msh_err("$MeshFormat\n4.1 1 3\n\u{1}\0\0\0\n$EndMeshFormat\n");
    assert_contains(&e, &["unsupported version", "data size 3"]);
    let e = msh_err("$MeshFormat\n4.1 1 8\n\u{2}\0\0\0\n$EndMeshFormat\n");
    assert_contains(&e, &["endianness"]);
    let e = msh_err("$MeshFormat\n4.1 2 8\n$EndMeshFormat\n");
    assert_contains(&e, &["garbage token `2`", "file type"]);
    let e = msh_err("solid cube\n");
    assert_contains(&e, &["unknown mesh format", "`solid`"]);
    let e = tetgen_err("4 2 0 0\n1 0 0\n", ELE);
    assert_contains(&e, &["t.node", "dimension 2"]);
}

#[test]
fn counts_are_checked_before_allocating() {
    let e = msh_err(&TET41.replace("1 4 1 4\n", "1 1000000000000 1 4\n"));
    assert_contains(&e, &["node count 1000000000000 is too large"]);
    let e = msh_err(&TET41.replace("3 1 0 4\n", "3 1 0 18446744073709551615\n"));
    assert_contains(&e, &["too large"]);
    let e = msh_err(&TET22.replace("$Nodes\n4\n", "$Nodes\n99999999999999\n"));
    assert_contains(&e, &["too large"]);
    let e = tetgen_err("18446744073709551615 3 0 0\n", ELE);
    assert_contains(&e, &["too large"]);
    // Counts that fit the file but disagree with the records.
    let e = msh_err(&TET41.replace("1 4 1 4\n", "1 5 1 4\n"));
    assert_contains(&e, &["number of nodes", "declared 5, found 4"]);
    let e = msh_err(&TET22.replace("$Nodes\n4\n", "$Nodes\n5\n"));
    assert_contains(&e, &["truncated section `$Nodes`", "found `$EndNodes`"]);
    let e = msh_err(&TET22.replace("$Nodes\n4\n", "$Nodes\n3\n"));
    assert_contains(&e, &["garbage token `4`", "expected `$EndNodes`"]);
    let e = tetgen_err(NODE, "2 4 0\n1 1 2 3 4\n");
    assert_contains(&e, &["t.ele", "truncated", "tetrahedron record 2 of 2"]);
    let e = tetgen_err(NODE, "1 4 0\n1 1 2 3 4\n2 1 2 3 4\n");
    assert_contains(&e, &["t.ele", "line 3", "end of file after the 1 declared records"]);
}

#[test]
fn duplicate_nodes_and_section_order() {
    let e = msh_err(&TET22.replace("2 1 0 0", "1 1 0 0"));
    assert_contains(&e, &["line 7", "duplicate node tag 1"]);
    let swapped = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Elements\n0\n$EndElements\n";
    assert_contains(&msh_err(swapped), &["`$Elements` before `$Nodes`"]);
    let no_elements = TET41.split("$Elements").next().unwrap();
    assert_contains(&msh_err(no_elements), &["missing section `$Elements`"]);
    let e = msh_err(&TET41.replace("$EndElements\n", ""));
    assert_contains(&e, &["truncated section `$Elements`", "expected `$EndElements`"]);
    let e =
        io::parse_obj(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 4 3\n", Path::new("q.obj")).unwrap_err().to_string();
    assert_contains(&e, &["line 5", "face with 4 corners", "only triangles"]);
}

/// Inputs that make `mshio` 0.4.2 panic (see docs/FORMATS.md) are plain errors here.
#[test]
fn inputs_that_panic_mshio() {
    let e = msh_err("$MeshFormat\n4.1 1 3\n\u{1}\0\0\0\n$EndMeshFormat\n");
    assert_contains(&e, &["unsupported version", "data size 3"]);
    let e = msh_err("$MeshFormat\n4.1 0 99999999999999999999999\n$EndMeshFormat\n");
    assert_contains(&e, &["garbage token", "data size"]);
    let e = msh_err("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n0 0 1 1\n$EndNodes\n");
    assert_contains(&e, &["missing section `$Elements`"]);
}

// ---------------------------------------------------------------------------------------------
// Fuzzing: no input makes a reader panic or breaks a law of `io::fuzz`
// ---------------------------------------------------------------------------------------------

/// Runs every reader on `bytes`: through the fuzz target's own decoder and laws
/// (`io::fuzz::run_bytes`, one selector byte per reader and one for all: an error names the
/// file, an accepted mesh is sound and builds a valid map, the store round-trips; finding 329 —
/// these proptests checked only that no reader panics), and each TetGen half against a valid
/// partner file.
fn run_all_readers(bytes: &[u8]) {
    for selector in [0u8, 1, 2, 3, 4, 255] {
        let mut input = vec![selector];
        input.extend_from_slice(bytes);
        if let Err(e) = io::fuzz::run_bytes(&input) {
            panic!("reader {selector}: {e}");
        }
    }
    let p = Path::new("fuzz");
    let _ = io::parse_tetgen(bytes, p, ELE.as_bytes(), p);
    let _ = io::parse_tetgen(NODE.as_bytes(), p, bytes, p);
}

/// Valid inputs for every reader, to be mutated.
fn seeds() -> Vec<Vec<u8>> {
    let mut v: Vec<Vec<u8>> = [
        "single_tet.msh",
        "two_tets.msh",
        "cube5.msh",
        "cube5_v22.msh",
        "cube5_v1.msh",
        "cube5_bin.msh",
        "cube5.node",
        "cube5.ele",
        "cube_surface.obj",
    ]
    .iter()
    .map(|n| std::fs::read(fixture(n)).unwrap())
    .collect();
    let two = fixture_text("two_tets.msh");
    v.push(ascii41_to_binary(&two, true, 4));
    v
}

/// Headers that lead the random tail into each MSH reader.
const HEADERS: [&[u8]; 5] = [
    b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n",
    b"$MeshFormat\n4.1 1 8\n\x01\0\0\0\n$EndMeshFormat\n$Nodes\n",
    b"$MeshFormat\n4.1 1 4\n\0\0\0\x01\n$EndMeshFormat\n$Elements\n",
    b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n",
    b"$NOD\n",
];

/// Tokens that stress number parsing and section structure.
const NASTY: [&str; 14] = [
    "-1",
    "0",
    "18446744073709551615",
    "99999999999999999999999",
    "nan",
    "-inf",
    "1e308",
    "$EndNodes",
    "$Elements",
    "$Nodes",
    "",
    "x",
    "4",
    "11",
];

#[derive(Debug, Clone)]
enum Mutation {
    Set(usize, u8),
    Insert(usize, u8),
    Delete(usize),
    Token(usize, usize),
    Truncate(usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<usize>(), any::<u8>()).prop_map(|(i, b)| Mutation::Set(i, b)),
        (any::<usize>(), any::<u8>()).prop_map(|(i, b)| Mutation::Insert(i, b)),
        any::<usize>().prop_map(Mutation::Delete),
        (any::<usize>(), 0..NASTY.len()).prop_map(|(i, t)| Mutation::Token(i, t)),
        any::<usize>().prop_map(Mutation::Truncate),
    ]
}

fn apply(bytes: &mut Vec<u8>, m: &Mutation) {
    if bytes.is_empty() {
        return;
    }
    let n = bytes.len();
    match *m {
        Mutation::Set(i, b) => bytes[i % n] = b,
        Mutation::Insert(i, b) => bytes.insert(i % (n + 1), b),
        Mutation::Delete(i) => {
            bytes.remove(i % n);
        }
        Mutation::Truncate(i) => bytes.truncate(i % n),
        Mutation::Token(i, t) => {
            // Replace the whitespace-separated token that contains byte i.
            let i = i % n;
            let is_ws = |b: u8| b.is_ascii_whitespace();
            let start = bytes[..i].iter().rposition(|&b| is_ws(b)).map_or(0, |p| p + 1);
            let end = bytes[i..].iter().position(|&b| is_ws(b)).map_or(n, |p| i + p);
            if start <= end {
                bytes.splice(start..end, NASTY[t].bytes());
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..512)) {
        run_all_readers(&bytes);
    }

    #[test]
    fn random_tail_after_header_never_panics(
        header in 0..HEADERS.len(),
        tail in proptest::collection::vec(any::<u8>(), 0..256),
    ) {
        let mut bytes = HEADERS[header].to_vec();
        bytes.extend(tail);
        run_all_readers(&bytes);
    }

    #[test]
    fn mutated_fixtures_never_panic(
        seed in 0..10usize,
        mutations in proptest::collection::vec(mutation(), 1..6),
    ) {
        let mut bytes = seeds()[seed].clone();
        for m in &mutations {
            apply(&mut bytes, m);
        }
        run_all_readers(&bytes);
    }
}

/// Finding 29 (docs/VERIFICATION.md): `TetMesh::total_volume`, `TetMesh::compact` and
/// `TriMesh::total_area` panicked on a corner past the points (the fields are public, so such a
/// mesh is easy to make), and `graph::incidences(map, k)` panicked for k ≥ n. The measures now
/// name the corner; there are no incidences with (n+1)-cells.
#[test]
fn mesh_measures_name_a_corner_past_the_points_and_no_cell_is_incident_past_n() {
    use topomech::mesh::{CellKind, MeshError, TriMesh};
    let unit = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let out =
        |kind, cell, corner, value| Some(MeshError::IndexOutOfRange { kind, cell, corner, value, point_count: 4 });
    let good = TetMesh { points: unit.clone(), tets: vec![[0, 1, 2, 3]], ..Default::default() };
    let bad = TetMesh { tets: vec![[0, 1, 2, 3], [0, 1, 7, 3]], ..good.clone() };
    assert_eq!(bad.total_volume().err(), out(CellKind::Tet, 1, 2, 7));
    assert_eq!(bad.compact().err(), out(CellKind::Tet, 1, 2, 7));
    let bad_triangle = TetMesh { boundary_triangles: vec![[0, 1, 2], [1, 2, 9]], ..good.clone() };
    assert_eq!(bad_triangle.compact().err(), out(CellKind::BoundaryTriangle, 1, 2, 9));
    assert!((good.total_volume().unwrap() - 1.0 / 6.0).abs() < 1e-15);
    assert_eq!(good.compact().unwrap().0, good);
    let tri = TriMesh { points: unit, triangles: vec![[0, 1, 2], [4, 1, 2]] };
    assert_eq!(tri.total_area().err(), out(CellKind::Triangle, 1, 0, 4));
    let tri = TriMesh { triangles: vec![[0, 1, 2]], ..tri };
    assert_eq!(tri.total_area(), Ok(0.5));

    let (map, _) = topomech::GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    for k in 0..3 {
        assert!(!topomech::graph::incidences(&map, k).is_empty(), "k = {k}");
    }
    for k in [3, 4, 99] {
        assert!(topomech::graph::incidences(&map, k).is_empty(), "k = {k}");
    }
}
