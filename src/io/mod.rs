//! Mesh-file readers: Gmsh MSH 4.1 (ASCII and binary), MSH 2.2 ASCII, MSH v1, TetGen
//! `.node`/`.ele`, and a minimal OBJ reader for triangle surfaces.
//!
//! Every reader returns a [`TetMesh`] (or [`TriMesh`]) that has passed [`TetMesh::check`]
//! (resp. [`TriMesh::check`]) without error, or a [`ReadError`] that names the file, the line
//! (text files) or byte offset (binary files) and what is wrong. Readers never panic, whatever
//! the input, and never allocate from a count read in the file before checking it against the
//! bytes that are left. See `docs/FORMATS.md` for what each reader accepts.
//!
//! Only linear tetrahedra (Gmsh type 4) make the volume. Triangles (type 2) are kept in
//! [`TetMesh::boundary_triangles`] as a cross-check; points, lines and other surface elements
//! are skipped; other volume elements (hexahedra, prisms, pyramids, higher-order tets) are an
//! error, because dropping them would leave a hole. A surface read ([`read_tri_mesh`],
//! [`parse_msh_tri`]) keeps the triangles and skips every other element, volume elements
//! included. The node tags of a skipped element must be defined all the same.

use std::fmt;
use std::path::{Path, PathBuf};

use crate::mesh::{MeshError, TetMesh, TriMesh};

mod build;
pub mod fuzz;
mod msh1;
mod msh22;
mod msh41;
mod obj;
mod scan;
mod tetgen;

use build::{MeshBuilder, Target};

/// Where in a file a problem is.
///
/// # Examples
///
/// ```
/// use std::path::Path;
/// use topomech::io::{parse_msh, Location, ReadError};
///
/// let msh = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n1\n1 0 0 zz\n$EndNodes\n";
/// match parse_msh(msh.as_bytes(), Path::new("bad.msh")).unwrap_err() {
///     ReadError::Garbage { at, .. } => assert_eq!(at, Location::Line(6)),
///     other => panic!("unexpected {other}"),
/// }
/// assert_eq!(Location::Byte(12).to_string(), "byte 12");
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Location {
    /// 1-based line number (text files).
    Line(usize),
    /// 0-based byte offset (binary files).
    Byte(usize),
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::Line(n) => write!(f, "line {n}"),
            Location::Byte(n) => write!(f, "byte {n}"),
        }
    }
}

/// Why a mesh file could not be read. Every variant names the file; most name a [`Location`].
///
/// # Examples
///
/// ```
/// use std::path::Path;
/// use topomech::io::{parse_msh, ReadError};
///
/// let msh = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 zz\n3 0 1 0\n4 0 0 1\n\
///            $EndNodes\n$Elements\n1\n1 4 2 0 1 1 2 3 4\n$EndElements\n";
/// let err = parse_msh(msh.as_bytes(), Path::new("bad.msh")).unwrap_err();
/// assert!(matches!(err, ReadError::Garbage { .. }), "{err}");
/// assert!(err.to_string().starts_with("bad.msh: line 7: garbage token `zz`"), "{err}");
/// ```
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    /// The file could not be read from disk.
    #[error("{}: cannot read file: {source}", .path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The file is not in a format this module reads.
    #[error("{}: unknown mesh format: {reason}", .path.display())]
    UnknownFormat {
        /// The file.
        path: PathBuf,
        /// What was found instead.
        reason: String,
    },
    /// A known format in a version (or encoding) that is not supported.
    #[error("{}: {at}: unsupported version `{version}` (supported: {supported})", .path.display())]
    UnsupportedVersion {
        /// The file.
        path: PathBuf,
        /// Where the version is.
        at: Location,
        /// The version found.
        version: String,
        /// What is supported.
        supported: &'static str,
    },
    /// The file or section ends before the data it declares.
    #[error(
        "{}: {at}: truncated section `{section}`: expected {expected}, found {found}",
        .path.display()
    )]
    Truncated {
        /// The file.
        path: PathBuf,
        /// Where the data stops.
        at: Location,
        /// The section being read.
        section: &'static str,
        /// What was expected next.
        expected: String,
        /// What was found (end of file, or a section marker).
        found: String,
    },
    /// A token that is not what the format requires at this place.
    #[error(
        "{}: {at}: garbage token `{token}` in section `{section}`: expected {expected}",
        .path.display()
    )]
    Garbage {
        /// The file.
        path: PathBuf,
        /// Where the token is.
        at: Location,
        /// The section being read.
        section: &'static str,
        /// The token (shortened).
        token: String,
        /// What was expected.
        expected: String,
    },
    /// An element type number that no supported format defines.
    #[error("{}: {at}: unknown element type {element_type}", .path.display())]
    UnknownElementType {
        /// The file.
        path: PathBuf,
        /// Where the type is.
        at: Location,
        /// The type number.
        element_type: i64,
    },
    /// A known volume element type other than the linear tetrahedron.
    #[error(
        "{}: {at}: unsupported element type {element_type} ({name}): only linear \
         tetrahedra (type 4) can make the volume",
        .path.display()
    )]
    UnsupportedElementType {
        /// The file.
        path: PathBuf,
        /// Where the type is.
        at: Location,
        /// The type number (Gmsh numbering; TetGen's 10-node tets are reported as 11).
        element_type: i64,
        /// Its name.
        name: &'static str,
    },
    /// An element refers to a node tag that no node record defines.
    #[error(
        "{}: {at}: node tag not defined: element {element} refers to node {tag}, which the \
         node section does not define",
        .path.display()
    )]
    UndefinedNode {
        /// The file.
        path: PathBuf,
        /// Where the element is.
        at: Location,
        /// The element's tag (number) in the file.
        element: u64,
        /// The undefined node tag.
        tag: u64,
    },
    /// Two node records have the same tag.
    #[error("{}: {at}: duplicate node tag {tag}", .path.display())]
    DuplicateNode {
        /// The file.
        path: PathBuf,
        /// Where the second definition is.
        at: Location,
        /// The tag.
        tag: u64,
    },
    /// A node coordinate is NaN or infinite.
    #[error(
        "{}: {at}: non-finite coordinate (NaN or infinite) for node {tag}: {coords:?}",
        .path.display()
    )]
    NonFiniteCoordinate {
        /// The file.
        path: PathBuf,
        /// Where the node is.
        at: Location,
        /// The node's tag.
        tag: u64,
        /// Its coordinates.
        coords: [f64; 3],
    },
    /// A tetrahedron or triangle uses the same node twice.
    #[error("{}: {at}: repeated vertex: element {element} uses node {tag} twice", .path.display())]
    RepeatedVertex {
        /// The file.
        path: PathBuf,
        /// Where the element is.
        at: Location,
        /// The element's tag.
        element: u64,
        /// The repeated node tag.
        tag: u64,
    },
    /// A declared count cannot fit in what is left of the file.
    #[error(
        "{}: {at}: {what} count {count} is too large for the {remaining} bytes left in the \
         file (truncated file or corrupt count)",
        .path.display()
    )]
    CountTooLarge {
        /// The file.
        path: PathBuf,
        /// Where the count is.
        at: Location,
        /// What is counted.
        what: &'static str,
        /// The declared count.
        count: u64,
        /// Bytes left after the count.
        remaining: usize,
    },
    /// A declared count disagrees with the records that follow.
    #[error("{}: {at}: {what}: declared {declared}, found {found}", .path.display())]
    CountMismatch {
        /// The file.
        path: PathBuf,
        /// Where the mismatch is noticed.
        at: Location,
        /// What is counted.
        what: &'static str,
        /// The declared count.
        declared: u64,
        /// The actual count.
        found: u64,
    },
    /// A required section is absent.
    #[error("{}: missing section `{section}`", .path.display())]
    MissingSection {
        /// The file.
        path: PathBuf,
        /// The section.
        section: &'static str,
    },
    /// A structural problem not covered by the other variants.
    #[error("{}: {at}: {message}", .path.display())]
    Malformed {
        /// The file.
        path: PathBuf,
        /// Where.
        at: Location,
        /// What is wrong.
        message: String,
    },
    /// More nodes than `u32` indices can address.
    #[error("{}: {at}: too many nodes (at most u32::MAX - 1)", .path.display())]
    TooManyNodes {
        /// The file.
        path: PathBuf,
        /// Where the node that does not fit is.
        at: Location,
    },
    /// Two elements have the same nodes, in any order: a tetrahedron (triangle, in a surface
    /// read) listed twice. The mesh check's [`MeshError::DuplicateTet`] /
    /// [`MeshError::DuplicateTriangle`], named with the file's element numbers and node tags.
    #[error(
        "{}: duplicate element: elements {first} and {second} have the same nodes {nodes:?} \
         (a {kind} listed twice)",
        .path.display()
    )]
    DuplicateElement {
        /// The file.
        path: PathBuf,
        /// Tet or triangle.
        kind: crate::mesh::CellKind,
        /// The element number (tag) in the file of the earliest copy.
        first: u64,
        /// The element number of the element that repeats it.
        second: u64,
        /// The node tags, as `first` lists them.
        nodes: Vec<u64>,
    },
    /// The records parse but the mesh fails [`TetMesh::check`] / [`TriMesh::check`] (e.g. it
    /// has no tetrahedra).
    #[error("{}: invalid mesh: {source}", .path.display())]
    InvalidMesh {
        /// The file.
        path: PathBuf,
        /// The mesh error.
        #[source]
        source: MeshError,
    },
}

/// At most 40 characters of `s`, with control characters escaped, for messages.
pub(crate) fn shorten(s: &str) -> String {
    let mut out: String = s.chars().take(40).flat_map(char::escape_debug).collect();
    if s.chars().nth(40).is_some() {
        out.push('…');
    }
    out
}

fn read_file(path: &Path) -> Result<Vec<u8>, ReadError> {
    read_whole(path).map_err(|source| ReadError::Io { path: path.to_path_buf(), source })
}

/// The bytes of the file at `path`: a regular file, an anonymous pipe (`<(zcat mesh.msh.gz)`,
/// `zcat mesh.msh.gz | topomech info /dev/stdin`), or standard input named as `/dev/stdin`,
/// `/dev/fd/0` or `/proc/self/fd/0` when it is a named pipe (`topomech info /dev/stdin < FIFO`):
/// that one is read from the open descriptor, never reopened (opening a FIFO waits for a writer,
/// for ever once the writer has left). Refused with [`std::io::ErrorKind::InvalidInput`] before
/// the file is opened ([`refuse_special`]): a character or block device or a socket
/// (`/dev/zero` or `/dev/urandom` never end, and reading one would fill the memory before
/// failing) and any other named pipe. O(file).
pub(crate) fn read_whole(path: &Path) -> std::io::Result<Vec<u8>> {
    match refuse_special(path)? {
        Source::Path => std::fs::read(path),
        Source::Stdin => {
            let mut bytes = Vec::new();
            std::io::Read::read_to_end(&mut std::io::stdin().lock(), &mut bytes)?;
            Ok(bytes)
        }
    }
}

/// Where [`read_whole`] takes the bytes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Source {
    /// Open the path.
    Path,
    /// Read the process's standard input, which the path names.
    Stdin,
}

/// `Err(InvalidInput)` when `path` (followed through symbolic links) is a device, a socket or a
/// named pipe that [`read_whole`] would have to open: nothing it could read to an end without
/// waiting for someone. A named pipe already open as standard input (`/dev/stdin`, `/dev/fd/0`,
/// `/proc/self/fd/0`) is [`Source::Stdin`]: its writer was there when the shell opened it, and
/// it is read where it is. An anonymous pipe (`/dev/fd/N`, `/dev/stdin` fed by `|`) is a FIFO
/// too, but it has no name in the file system (its path does not canonicalize) and reopening it
/// does not wait: it is read by its path. Nothing is opened. O(path length) file-system queries.
fn refuse_special(path: &Path) -> std::io::Result<Source> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let kind = std::fs::metadata(path)?.file_type();
        let refuse = |why: &str| Err(std::io::Error::new(std::io::ErrorKind::InvalidInput, why.to_string()));
        if kind.is_char_device() || kind.is_block_device() || kind.is_socket() {
            return refuse("a device or socket, not a file (reading it might never end)");
        }
        if kind.is_fifo() && std::fs::canonicalize(path).is_ok() {
            if names_stdin(path) {
                return Ok(Source::Stdin);
            }
            return refuse(
                "a named pipe (FIFO), not a file (opening it waits for a writer that may never come; \
                 give it as standard input instead: `topomech … /dev/stdin < FIFO` or `cat FIFO | topomech … /dev/stdin`)",
            );
        }
    }
    #[cfg(not(unix))]
    let _ = path;
    Ok(Source::Path)
}

/// Whether `path` is written as a name of this process's standard input: `/dev/stdin`,
/// `/dev/fd/0` or `/proc/self/fd/0`. O(path length).
#[cfg(unix)]
fn names_stdin(path: &Path) -> bool {
    ["/dev/stdin", "/dev/fd/0", "/proc/self/fd/0"].iter().any(|name| path == Path::new(name))
}

fn extension(path: &Path) -> String {
    path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).unwrap_or_default()
}

/// The other file of a TetGen pair: `path` with extension `other` (`node` or `ele`), written in
/// the case of `path`'s extension — `m.NODE` → `m.ELE`, `m.Node` → `m.Ele`, `m.node` → `m.ele`.
/// When that file does not exist but the lowercase or the uppercase one does, that one. O(1)
/// file-system queries.
fn tetgen_sibling(path: &Path, other: &str) -> PathBuf {
    let given = path.extension().map(|e| e.to_string_lossy().into_owned()).unwrap_or_default();
    let upper = given.chars().all(|c| !c.is_ascii_lowercase());
    let capitalised = !upper && given.chars().next().is_some_and(|c| c.is_ascii_uppercase());
    let styled = if upper {
        other.to_ascii_uppercase()
    } else if capitalised {
        other[..1].to_ascii_uppercase() + &other[1..]
    } else {
        other.to_string()
    };
    let candidates = [styled, other.to_string(), other.to_ascii_uppercase()];
    let first = path.with_extension(&candidates[0]);
    if first.exists() {
        return first;
    }
    candidates[1..].iter().map(|e| path.with_extension(e)).find(|p| p.exists()).unwrap_or(first)
}

/// Reads a tetrahedral mesh, choosing the reader by extension and header: `.node` or `.ele`
/// (in any case) reads the TetGen pair — the given file, and the other one with the same stem
/// and its extension in the same case (`m.NODE` pairs with `m.ELE`); anything else must be a
/// Gmsh MSH file (v1, 2.x ASCII, or 4.1 ASCII/binary), recognised by its first line.
///
/// Cost: O(file size) plus O(T) hashing; the whole file is held in memory.
///
/// # Errors
/// Any [`ReadError`]; [`ReadError::UnknownFormat`] for an OBJ file or an unrecognised header.
///
/// # Examples
///
/// ```
/// use std::path::Path;
/// use topomech::io::{read_mesh, ReadError};
///
/// let err = read_mesh(Path::new("/no/such/mesh.msh")).unwrap_err();
/// assert!(matches!(err, ReadError::Io { .. }));
/// let err = read_mesh(Path::new("/no/such/surface.obj")).unwrap_err();
/// assert!(matches!(err, ReadError::UnknownFormat { .. })); // a surface format, refused by name
/// ```
pub fn read_mesh(path: &Path) -> Result<TetMesh, ReadError> {
    match extension(path).as_str() {
        "node" => read_tetgen(path, &tetgen_sibling(path, "ele")),
        "ele" => read_tetgen(&tetgen_sibling(path, "node"), path),
        "obj" => Err(ReadError::UnknownFormat {
            path: path.to_path_buf(),
            reason: "OBJ holds a surface, not a tetrahedral volume: give an MSH or TetGen .node/.ele mesh \
                     (a library caller reads surfaces with io::read_tri_mesh)"
                .into(),
        }),
        _ => parse_msh(&read_file(path)?, path),
    }
}

/// Reads a TetGen `.node` / `.ele` pair. O(file sizes).
///
/// # Errors
/// Any [`ReadError`], naming whichever of the two files is at fault.
///
/// # Examples
///
/// ```
/// use topomech::io::read_tetgen;
///
/// let stem = std::env::temp_dir().join(format!("topomech-doc-{}", std::process::id()));
/// let (node, ele) = (stem.with_extension("node"), stem.with_extension("ele"));
/// std::fs::write(&node, "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n").unwrap(); // 0-based numbers
/// std::fs::write(&ele, "1 4 0\n0 0 1 2 3\n").unwrap();
/// let mesh = read_tetgen(&node, &ele);
/// std::fs::remove_file(&node).unwrap();
/// std::fs::remove_file(&ele).unwrap();
/// assert_eq!(mesh.unwrap().tets, vec![[0, 1, 2, 3]]);
/// ```
pub fn read_tetgen(node_path: &Path, ele_path: &Path) -> Result<TetMesh, ReadError> {
    let node = read_file(node_path)?;
    let ele = read_file(ele_path)?;
    parse_tetgen(&node, node_path, &ele, ele_path)
}

/// Reads a triangle surface mesh: `.obj` with the OBJ reader, anything else as a Gmsh MSH file
/// whose triangle elements (type 2) make the surface. Volume elements of every type (linear or
/// higher-order tetrahedra, hexahedra, ...), like points, lines and other surface elements, are
/// skipped: only their node tags must be defined. O(file size).
///
/// # Errors
/// Any [`ReadError`]; [`ReadError::InvalidMesh`] when there is no triangle.
///
/// # Examples
///
/// ```
/// use topomech::io::read_tri_mesh;
///
/// let path = std::env::temp_dir().join(format!("topomech-doc-{}.obj", std::process::id()));
/// std::fs::write(&path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
/// let mesh = read_tri_mesh(&path).unwrap();
/// std::fs::remove_file(&path).unwrap();
/// assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
/// ```
pub fn read_tri_mesh(path: &Path) -> Result<TriMesh, ReadError> {
    let bytes = read_file(path)?;
    match extension(path).as_str() {
        "obj" => parse_obj(&bytes, path),
        _ => parse_msh_tri(&bytes, path),
    }
}

/// The MSH dialect of a file, from its first tokens.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum MshVersion {
    V1,
    V2,
    V41,
}

fn msh_version(bytes: &[u8], path: &Path) -> Result<MshVersion, ReadError> {
    let mut sc = scan::Scanner::new(bytes, path);
    let first = sc.next_raw();
    match first {
        Some(t) if t.is("$NOD") => Ok(MshVersion::V1),
        Some(t) if t.is("$MeshFormat") => match sc.next_raw() {
            Some(v) if v.is("4.1") => Ok(MshVersion::V41),
            Some(v) if [&b"2"[..], b"2.0", b"2.1", b"2.2"].contains(&v.raw) => Ok(MshVersion::V2),
            Some(v) => Err(ReadError::UnsupportedVersion {
                path: path.to_path_buf(),
                at: Location::Line(v.line),
                version: shorten(&v.text()),
                supported: "MSH 1, 2.0-2.2 ASCII, 4.1 ASCII and binary",
            }),
            None => Err(sc.truncated("the format version", "end of file".into())),
        },
        Some(t) => Err(ReadError::UnknownFormat {
            path: path.to_path_buf(),
            reason: format!("expected `$MeshFormat` or `$NOD` at the start, found `{}`", shorten(&t.text())),
        }),
        None => Err(ReadError::UnknownFormat { path: path.to_path_buf(), reason: "the file is empty".into() }),
    }
}

fn parse_msh_records(bytes: &[u8], path: &Path, target: Target) -> Result<MeshBuilder, ReadError> {
    match msh_version(bytes, path)? {
        MshVersion::V1 => msh1::parse(bytes, path, target),
        MshVersion::V2 => msh22::parse(bytes, path, target),
        MshVersion::V41 => msh41::parse(bytes, path, target),
    }
}

/// Parses the bytes of a Gmsh MSH file (any supported version, detected from the header) into
/// a tet mesh; `path` is only used in errors. O(bytes).
///
/// # Errors
/// Any [`ReadError`] except `Io`.
///
/// # Examples
///
/// ```
/// use std::path::Path;
/// use topomech::io::parse_msh;
///
/// let msh = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n\
///            $EndNodes\n$Elements\n2\n1 4 2 0 1 1 2 3 4\n2 2 2 0 1 1 2 3\n$EndElements\n";
/// let mesh = parse_msh(msh.as_bytes(), Path::new("one.msh")).unwrap();
/// assert_eq!(mesh.tets, vec![[0, 1, 2, 3]]); // node tags 1..4 become indices 0..3
/// assert_eq!(mesh.boundary_triangles, vec![[0, 1, 2]]);
/// assert!((mesh.total_volume().unwrap() - 1.0 / 6.0).abs() < 1e-15);
/// ```
pub fn parse_msh(bytes: &[u8], path: &Path) -> Result<TetMesh, ReadError> {
    parse_msh_records(bytes, path, Target::Volume)?.into_tet_mesh(path)
}

/// Parses the bytes of a Gmsh MSH file into a triangle mesh made of its triangle elements;
/// `path` is only used in errors. Every other element is skipped, volume elements of any type
/// included (a degenerate or second-order tetrahedron is no error here), once its node tags are
/// found defined. O(bytes).
///
/// # Errors
/// Any [`ReadError`] except `Io` and `UnsupportedElementType`; `InvalidMesh` when there is no
/// triangle; `UndefinedNode` for a node tag of any element that no node defines.
///
/// # Examples
///
/// ```
/// use std::path::Path;
/// use topomech::io::parse_msh_tri;
///
/// let msh = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n1 0 0 0\n2 2 0 0\n3 0 2 0\n\
///            $EndNodes\n$Elements\n1\n1 2 2 0 1 1 2 3\n$EndElements\n";
/// let mesh = parse_msh_tri(msh.as_bytes(), Path::new("tri.msh")).unwrap();
/// assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
/// assert_eq!(mesh.total_area(), Ok(2.0));
/// ```
pub fn parse_msh_tri(bytes: &[u8], path: &Path) -> Result<TriMesh, ReadError> {
    parse_msh_records(bytes, path, Target::Surface)?.into_tri_mesh(path)
}

/// Parses the bytes of a TetGen `.node` and `.ele` pair; the paths are only used in errors.
/// O(bytes).
///
/// # Errors
/// Any [`ReadError`] except `Io`.
///
/// # Examples
///
/// ```
/// use std::path::Path;
/// use topomech::io::parse_tetgen;
///
/// let node = "# a unit tet\n4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n";
/// let ele = "1 4 0\n1 1 2 3 4\n";
/// let mesh = parse_tetgen(node.as_bytes(), Path::new("t.node"), ele.as_bytes(), Path::new("t.ele")).unwrap();
/// assert_eq!((mesh.points.len(), mesh.tets.len()), (4, 1));
/// assert_eq!(mesh.points[3], [0.0, 0.0, 1.0]);
/// ```
pub fn parse_tetgen(node: &[u8], node_path: &Path, ele: &[u8], ele_path: &Path) -> Result<TetMesh, ReadError> {
    let mut b = MeshBuilder::new();
    tetgen::parse_node(node, node_path, &mut b)?;
    tetgen::parse_ele(ele, ele_path, &mut b)?;
    b.into_tet_mesh(ele_path)
}

/// Parses the bytes of an OBJ file (`v` and triangular `f` records); `path` is only used in
/// errors. O(bytes).
///
/// # Errors
/// Any [`ReadError`] except `Io`.
///
/// # Examples
///
/// ```
/// use std::path::Path;
/// use topomech::io::parse_obj;
///
/// let obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1/1 3/3 -1\n"; // -1: the last vertex so far
/// let mesh = parse_obj(obj.as_bytes(), Path::new("quad.obj")).unwrap();
/// assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 2, 3]]);
/// assert_eq!(mesh.total_area(), Ok(1.0));
/// assert!(parse_obj(b"v 0 0 0\nf 1 2 3\n", Path::new("x.obj")).is_err()); // vertices 2, 3 missing
/// ```
pub fn parse_obj(bytes: &[u8], path: &Path) -> Result<TriMesh, ReadError> {
    obj::parse(bytes, path)?.into_tri_mesh(path)
}
