//! The readers under arbitrary bytes: one decoder shared by the `readers` cargo-fuzz target and
//! its corpus replay on stable (`tests/readers_fuzz_replay.rs`).
//!
//! The first byte picks a reader, the rest is the file: `0` MSH through [`load_tet_map_from_msh_bytes`]
//! (parse, check, build), `1` MSH as a triangle mesh, `2` TetGen (`.node`, a NUL byte, `.ele`),
//! `3` OBJ, `4` the `.tmap` / `.tmapb` store. Any other first byte runs every reader on the rest.
//!
//! Laws, each checked on every input ([`run_bytes`] returns the first one broken):
//!
//! | law | statement |
//! |---|---|
//! | no panic | every reader returns, `Ok` or `Err` (a panic aborts the fuzzer) |
//! | error names the file | the message of a rejected mesh file names the path it was given |
//! | accepted mesh is sound | indices in range, coordinates finite, at least one cell |
//! | accepted mesh builds a valid map | when the G-map builds, `validate()` holds and it has one volume (face) per tet (triangle) |
//! | store round trip | an accepted document encodes and decodes to itself in both forms, and a map it yields validates |
//!
//! Cost: O(input) for the parsers, O(T log T) for the builds (T cells).

use std::path::Path;

use crate::load::load_tet_map_from_msh_bytes;
use crate::mesh::{TetMesh, TriMesh};
use crate::store::{self, Format};
use crate::GMap;

/// One reader under test: books its verdict in the outcome, returns a broken law.
type Reader = fn(&[u8], &mut Outcome) -> Result<(), String>;

/// The name every rejected input must carry in its message.
pub const FUZZ_PATH: &str = "fuzz-input";

/// What [`run_bytes`] did with an input: how many readers accepted and rejected it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Outcome {
    /// Readers that returned `Ok`.
    pub accepted: usize,
    /// Readers that returned a (law-abiding) error.
    pub rejected: usize,
}

/// Runs the reader(s) the first byte picks on the rest and checks every law of the module docs.
/// O(input + T log T).
///
/// # Errors
/// The first law broken, as a message naming the reader and what was wrong.
///
/// # Examples
///
/// ```
/// use topomech::io::fuzz::run_bytes;
///
/// let msh = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n\
///            $EndNodes\n$Elements\n1\n1 4 2 0 1 1 2 3 4\n$EndElements\n";
/// let mut input = vec![0u8];
/// input.extend_from_slice(msh.as_bytes());
/// assert_eq!(run_bytes(&input).unwrap().accepted, 1);
/// assert_eq!(run_bytes(&[0, b'$', b'M']).unwrap().rejected, 1); // truncated: rejected, no panic
/// ```
pub fn run_bytes(data: &[u8]) -> Result<Outcome, String> {
    let Some((&pick, rest)) = data.split_first() else {
        return Ok(Outcome::default());
    };
    let mut out = Outcome::default();
    let readers: &[Reader] = &[msh_tets, msh_triangles, tetgen, obj, store_doc];
    match readers.get(pick as usize) {
        Some(reader) => reader(rest, &mut out)?,
        None => readers.iter().try_for_each(|reader| reader(rest, &mut out))?,
    }
    Ok(out)
}

/// The message of an error about a file must name the file. O(message).
///
/// # Errors
/// The law, when `message` does not contain `path`.
///
/// # Examples
///
/// ```
/// use topomech::io::fuzz::check_error_names_path;
///
/// assert!(check_error_names_path("a.msh: line 3: expected a node tag", "a.msh").is_ok());
/// assert!(check_error_names_path("expected a node tag", "a.msh").is_err());
/// ```
pub fn check_error_names_path(message: &str, path: &str) -> Result<(), String> {
    if message.contains(path) {
        Ok(())
    } else {
        Err(format!("error message does not name the file `{path}`: {message}"))
    }
}

/// An accepted tet mesh: indices in range, finite coordinates, at least one tet; and when its
/// G-map builds, the map validates with one volume per tet. O(T log T).
///
/// # Errors
/// The law broken, prefixed by `reader`.
///
/// # Examples
///
/// ```
/// use topomech::io::fuzz::check_tet_mesh;
/// use topomech::mesh::TetMesh;
///
/// let mut mesh = TetMesh {
///     points: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
///     tets: vec![[0, 1, 2, 3]],
///     ..TetMesh::default()
/// };
/// assert!(check_tet_mesh("doc", &mesh).is_ok());
/// mesh.tets[0][3] = 9; // out of range: a reader must never accept this
/// assert!(check_tet_mesh("doc", &mesh).is_err());
/// ```
pub fn check_tet_mesh(reader: &str, mesh: &TetMesh) -> Result<(), String> {
    check_cells(reader, &mesh.points, mesh.tets.iter().map(|t| &t[..]))?;
    if let Ok((map, _)) = GMap::<3>::from_tets(mesh.points.len(), &mesh.tets) {
        check_map(reader, &map, mesh.tets.len())?;
    }
    Ok(())
}

/// [`check_tet_mesh`] for triangle meshes and 2-G-maps. O(T log T).
///
/// # Errors
/// The law broken, prefixed by `reader`.
///
/// # Examples
///
/// ```
/// use topomech::io::fuzz::check_tri_mesh;
/// use topomech::mesh::TriMesh;
///
/// let mesh = TriMesh { points: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, f64::NAN, 0.0]], triangles: vec![[0, 1, 2]] };
/// assert!(check_tri_mesh("doc", &mesh).is_err()); // NaN: a reader must never accept this
/// ```
pub fn check_tri_mesh(reader: &str, mesh: &TriMesh) -> Result<(), String> {
    check_cells(reader, &mesh.points, mesh.triangles.iter().map(|t| &t[..]))?;
    if let Ok((map, _)) = GMap::<2>::from_triangles(mesh.points.len(), &mesh.triangles) {
        check_map(reader, &map, mesh.triangles.len())?;
    }
    Ok(())
}

fn check_cells<'a>(reader: &str, points: &[[f64; 3]], cells: impl Iterator<Item = &'a [u32]>) -> Result<(), String> {
    if let Some(p) = points.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
        return Err(format!("{reader}: accepted point {p} with a non-finite coordinate {:?}", points[p]));
    }
    let mut count = 0;
    for (c, cell) in cells.enumerate() {
        count += 1;
        if let Some(&i) = cell.iter().find(|&&i| i as usize >= points.len()) {
            return Err(format!("{reader}: accepted cell {c} naming point {i} of {}", points.len()));
        }
    }
    if count == 0 {
        return Err(format!("{reader}: accepted a mesh with no cell"));
    }
    Ok(())
}

fn check_map<const N: usize>(reader: &str, map: &GMap<N>, cells: usize) -> Result<(), String> {
    map.validate().map_err(|e| format!("{reader}: the built map breaks a law: {e}"))?;
    let top = map.count_cells().0[N];
    if top != cells {
        return Err(format!("{reader}: {cells} cells read but the map has {top} {N}-cells"));
    }
    Ok(())
}

/// Books a reader's result: an error must name the file, an accepted mesh passes `check`.
fn book<T, E: std::fmt::Display>(
    out: &mut Outcome,
    result: Result<T, E>,
    check: impl FnOnce(&T) -> Result<(), String>,
) -> Result<(), String> {
    match result {
        Ok(value) => {
            out.accepted += 1;
            check(&value)
        }
        Err(e) => {
            out.rejected += 1;
            check_error_names_path(&e.to_string(), FUZZ_PATH)
        }
    }
}

fn msh_tets(bytes: &[u8], out: &mut Outcome) -> Result<(), String> {
    let loaded = load_tet_map_from_msh_bytes(bytes, Path::new(FUZZ_PATH));
    book(out, loaded, |l| {
        check_tet_mesh("msh", &l.mesh)?;
        check_map("msh load", &l.map, l.mesh.tets.len())
    })
}

fn msh_triangles(bytes: &[u8], out: &mut Outcome) -> Result<(), String> {
    book(out, super::parse_msh_tri(bytes, Path::new(FUZZ_PATH)), |m| check_tri_mesh("msh triangles", m))
}

fn tetgen(bytes: &[u8], out: &mut Outcome) -> Result<(), String> {
    let cut = bytes.iter().position(|&b| b == 0).unwrap_or(bytes.len());
    let (node, ele) = (&bytes[..cut], bytes.get(cut + 1..).unwrap_or(&[]));
    let path = Path::new(FUZZ_PATH);
    book(out, super::parse_tetgen(node, path, ele, path), |m| check_tet_mesh("tetgen", m))
}

fn obj(bytes: &[u8], out: &mut Outcome) -> Result<(), String> {
    book(out, super::parse_obj(bytes, Path::new(FUZZ_PATH)), |m| check_tri_mesh("obj", m))
}

/// The store: decoded documents re-encode to themselves; maps they hold validate. Store errors
/// come from bytes, not from a named file, so only their being errors is checked.
fn store_doc(bytes: &[u8], out: &mut Outcome) -> Result<(), String> {
    let Ok(doc) = store::decode(bytes) else {
        out.rejected += 1;
        return Ok(());
    };
    out.accepted += 1;
    for format in [Format::Text, Format::Binary] {
        let encoded =
            store::encode(&doc, format).map_err(|e| format!("store: an accepted document fails to encode: {e}"))?;
        let again =
            store::decode(&encoded).map_err(|e| format!("store: its own {format:?} encoding is rejected: {e}"))?;
        if again != doc {
            return Err(format!("store: the {format:?} round trip changes the document"));
        }
    }
    let check =
        |r: Result<(), crate::InvariantViolation>| r.map_err(|e| format!("store: an accepted map breaks a law: {e}"));
    match doc.map.dimension {
        2 => doc.into_map::<2>().map_or(Ok(()), |m| check(m.validate())),
        3 => doc.into_map::<3>().map_or(Ok(()), |m| check(m.validate())),
        _ => Ok(()),
    }
}
