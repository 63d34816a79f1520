//! Save and load a complete map with its embeddings: a readable text form (`.tmap`) and a compact
//! binary form (`.tmapb`), both versioned and documented in `docs/FILE_FORMAT.md`.
//!
//! A file holds a [`Document`]: the raw arrays of a map ([`RawMap`]: every dart slot's αi links and
//! cell ids, the free dart slots, the cell-id allocators) and, for a mechanical body, its
//! attributes ([`RawMechanics`]). Round trips are exact: the loaded map equals the saved one slot
//! for slot (same dart ids, links, cell ids, allocators, reuse order) and every float is the same
//! bit pattern.
//!
//! Loading never repairs. [`decode`] checks the *structure* (magic, version, counts bounded by the
//! data actually present, dart ids in range, finite floats, checksum of the binary form) and gives
//! a raw document; [`load_map`] / [`load_body`] then require every law (`GMap::validate`, and
//! `check_conservation` for a body) and return the first broken one as an error. [`check_all_laws`]
//! lists each broken law of a raw document (what `topomech check` prints).
//!
//! ```
//! use topomech::store::{self, Document, Format};
//! use topomech::GMap;
//!
//! let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
//! let doc = Document::from_map(&map);
//! for format in [Format::Text, Format::Binary] {
//!     let bytes = store::encode(&doc, format).unwrap();
//!     let back: GMap<3> = store::decode(&bytes).unwrap().into_map().unwrap();
//!     assert!(back.is_isomorphic(&map));
//!     assert!(topomech::ops::same_raw(&back, &map));
//! }
//! ```
//!
//! A leveled map ([`crate::subdivide::LeveledMap`]) adds an optional *levels* part
//! ([`LevelParts`]: max level, per-dart level, μ, flat flag and link history, vertex positions,
//! and the origins of the vertices a cut made inside it); a file holding it is version 2, or 3
//! when it has origins ([`save_leveled`] / [`load_leveled`]). Files without it are still written
//! and read as version 1, byte for byte as before.
//!
//! Writes are atomic: [`save_document`] (through [`write_atomically`]) writes a temporary file in
//! the target's directory, flushes and fsyncs it, then renames it into place, so a crash or an
//! error leaves either the old file or the new one, never half of one. A symbolic link is
//! followed (the file it points to is replaced, the link kept) and the old file's permissions
//! are kept. The one exception: an existing writable file in a directory that takes no new file
//! is written in place, where a failed write can leave it partial.

mod binary;
mod check;
mod check_levels;
mod raw;
mod structure;
mod text;
mod write;

use std::fmt;
use std::path::{Path, PathBuf};

pub use crate::subdivide::{DartLevels, HistoryEntry, LevelParts};
pub use check::{check_all_laws, CheckReport, Finding};
pub use raw::{IdAllocRecord, RawMap, RawMechanics, VertexRecord};
pub use write::write_atomically;

use crate::mechanics::{Body, ConservationError};
use crate::subdivide::{LevelPartsError, LeveledMap};
use crate::{GMap, InvariantViolation};

/// The newest version of both forms: this library reads versions [`MIN_VERSION`]`..=VERSION`.
/// It writes the lowest version that holds a document ([`Document::version`]).
pub const VERSION: u32 = 3;
/// The oldest version this library reads (and writes for documents without levels).
pub const MIN_VERSION: u32 = 1;
/// The first version that may hold a levels part.
pub const LEVELS_VERSION: u32 = 2;
/// The first version that holds the origins of a leveled map's cut copies
/// ([`LevelParts::origins`]); written only for a levels part that has some.
pub const ORIGINS_VERSION: u32 = 3;
/// First token of the text form.
pub const TEXT_MAGIC: &str = "topomech-gmap";
/// First 8 bytes of the binary form (the CR LF catches text-mode transfers).
pub const BINARY_MAGIC: [u8; 8] = *b"TMAPB\0\r\n";
/// Largest dimension a file may declare (the kernel supports 1..=7).
pub const MAX_DIMENSION: usize = 7;

/// Which of the two forms.
///
/// # Examples
///
/// ```
/// use topomech::store::{self, Document, Format};
/// use topomech::GMap;
///
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let doc = Document::from_map(&map);
/// let (text, bin) = (store::encode(&doc, Format::Text).unwrap(), store::encode(&doc, Format::Binary).unwrap());
/// assert!(std::str::from_utf8(&text).is_ok() && bin.starts_with(&store::BINARY_MAGIC));
/// assert_eq!(store::decode(&text).unwrap(), store::decode(&bin).unwrap()); // same document
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// `.tmap`: one line per dart, floats in Rust's shortest round-trip notation.
    Text,
    /// `.tmapb`: little-endian arrays with an FNV-1a 64 checksum.
    Binary,
}

impl Format {
    /// `Binary` for a path ending in `.tmapb`, `Text` otherwise. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use std::path::Path;
    /// use topomech::store::Format;
    /// assert_eq!(Format::from_path(Path::new("out/liver.tmapb")), Format::Binary);
    /// assert_eq!(Format::from_path(Path::new("liver.tmap")), Format::Text);
    /// assert_eq!(Format::from_path(Path::new("liver")), Format::Text);
    /// ```
    pub fn from_path(path: &Path) -> Format {
        match path.extension().and_then(|e| e.to_str()) {
            Some("tmapb") => Format::Binary,
            _ => Format::Text,
        }
    }
}

/// Where in a file a problem is: a line of the text form or a byte offset of the binary form.
///
/// # Examples
///
/// ```
/// use topomech::store::{self, Document, Format, StoreError, Where};
/// use topomech::GMap;
///
/// assert_eq!((Where::Line(3).to_string(), Where::Byte(0).to_string()), ("line 3".into(), "byte 0".into()));
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let mut text = store::encode(&Document::from_map(&map), Format::Text).unwrap();
/// text.extend_from_slice(b"junk\n");
/// let e = store::decode(&text).unwrap_err();
/// assert!(matches!(e, StoreError::TrailingData { at: Where::Line(_) } | StoreError::Syntax { at: Where::Line(_), .. }));
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Where {
    /// 1-based line of the text form.
    Line(usize),
    /// 0-based byte offset in the binary form.
    Byte(usize),
    /// A [`Document`] built or changed in memory, not read from a file (its fields are public):
    /// [`encode`], the `into_*` conversions and [`check_all_laws`] check its structure and laws
    /// as the decoders do, with two differences of scope (finding 288): only [`encode`] refuses
    /// what the file forms cannot write (a non-finite level point: `into_leveled` and
    /// `check_all_laws` accept it, as `LeveledMap::from_parts` does), and `into_map` builds the
    /// map alone, ignoring any mechanics or levels the document carries (`check_all_laws` and
    /// `encode` refuse mechanics on a map that is not a 3-G-map).
    Document,
}

impl fmt::Display for Where {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Where::Line(l) => write!(f, "line {l}"),
            Where::Byte(b) => write!(f, "byte {b}"),
            Where::Document => write!(f, "in the document"),
        }
    }
}

/// Why a file could not be written, read, or accepted.
///
/// # Examples
///
/// ```
/// use std::path::Path;
/// use topomech::store::{self, Document, StoreError};
/// use topomech::GMap;
///
/// assert!(matches!(store::decode(b"hello"), Err(StoreError::BadMagic { .. })));
/// assert!(matches!(store::load_body(Path::new("/nonexistent-dir/x.tmap")), Err(StoreError::Io { .. })));
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// assert!(matches!(Document::from_map(&map).into_body(), Err(StoreError::NoMechanics)));
/// ```
#[derive(Debug, thiserror::Error)]
pub enum StoreError {
    /// The operating system refused (open, write, fsync, rename), or [`write_atomically`]
    /// refused before writing (a target that cannot be opened for writing; a directory that
    /// takes no temporary file, named in `source`).
    #[error("{}: {source}", .path.display())]
    Io {
        /// The file asked for (a temporary file beside it is never named).
        path: PathBuf,
        /// The system error.
        source: std::io::Error,
    },
    /// The file starts with neither magic (the text one on its first significant line).
    #[error("not a topomech map file: it starts with \"{found}\", not {TEXT_MAGIC:?} or the binary magic")]
    BadMagic {
        /// The first bytes of the first significant line (the first bytes of the file if it has
        /// none), escaped.
        found: String,
    },
    /// The file was written by another version of the format.
    #[error("{at}: format version {found} is not supported (this topomech reads versions {MIN_VERSION} to {VERSION})")]
    UnsupportedVersion {
        /// Where the version is.
        at: Where,
        /// The version in the file.
        found: u64,
    },
    /// The declared dimension is 0 or above [`MAX_DIMENSION`].
    #[error("{at}: dimension {found} is not in 1..={MAX_DIMENSION}")]
    BadDimension {
        /// Where the dimension is.
        at: Where,
        /// The dimension in the file.
        found: u64,
    },
    /// The file holds an n-G-map of another dimension than the one asked for.
    #[error("the file holds a {found}-G-map, not a {expected}-G-map")]
    WrongDimension {
        /// Dimension in the file.
        found: usize,
        /// Dimension asked for.
        expected: usize,
    },
    /// The file ends before the data it announces.
    #[error("{at}: the file is truncated: expected {expected}")]
    Truncated {
        /// Where the data should have been.
        at: Where,
        /// What was expected.
        expected: String,
    },
    /// The binary form's checksum does not match its content.
    #[error("checksum mismatch: the file says {stored:#018x} but its content hashes to {computed:#018x} (corrupted)")]
    Checksum {
        /// Checksum stored in the file.
        stored: u64,
        /// Checksum of the bytes read.
        computed: u64,
    },
    /// Bytes or lines after the end of the document.
    #[error("{at}: unexpected data after the end of the document")]
    TrailingData {
        /// Where the extra data starts.
        at: Where,
    },
    /// A line of the text form does not follow the grammar.
    #[error("{at}: {message}")]
    Syntax {
        /// The line.
        at: Where,
        /// What is wrong.
        message: String,
    },
    /// A dart id is not below the dart capacity.
    #[error("{at}: dart {dart} is out of range (the map has {capacity} dart slots)")]
    DartOutOfRange {
        /// Where the id is.
        at: Where,
        /// The id.
        dart: u64,
        /// The capacity declared.
        capacity: u64,
    },
    /// A count is larger than the data that can follow it, or inconsistent with another count.
    #[error("{at}: {what} = {count} is impossible here (at most {limit})")]
    BadCount {
        /// Where the count is.
        at: Where,
        /// Which count.
        what: &'static str,
        /// The count.
        count: u64,
        /// The largest possible value.
        limit: u64,
    },
    /// A dead dart slot, a free list or a record id is inconsistent (e.g. listed twice).
    #[error("{at}: {message}")]
    Inconsistent {
        /// Where.
        at: Where,
        /// What.
        message: String,
    },
    /// A float is NaN or infinite.
    #[error("{at}: {field} of record {index} is not finite")]
    NonFinite {
        /// Where the value is.
        at: Where,
        /// Which attribute.
        field: &'static str,
        /// Which cell id (or 0 for the material).
        index: usize,
    },
    /// The map breaks an n-G-map law (use [`decode`] + [`check_all_laws`] to list them all).
    #[error("the map breaks an n-G-map law: {0}")]
    BrokenLaw(#[from] InvariantViolation),
    /// The mechanical attributes break a conservation law.
    #[error("the attributes break a conservation law: {0}")]
    Conservation(#[from] ConservationError),
    /// A body was asked for but the file holds no mechanical attributes.
    #[error("the file holds a bare map, not a mechanical body")]
    NoMechanics,
    /// A leveled map was asked for but the file holds no levels part.
    #[error("the file holds no levels part (it was not saved from a leveled map)")]
    NoLevels,
    /// The levels part is malformed or breaks a level law.
    #[error("the levels part is not acceptable: {0}")]
    Levels(#[from] LevelPartsError),
    /// Saving: the body holds values the format cannot represent exactly (non-finite floats).
    #[error("cannot save: {what}")]
    Unrepresentable {
        /// What.
        what: String,
    },
}

/// A decoded file: the raw map and, for a body, its attributes. Not checked against the laws.
///
/// # Examples
///
/// ```
/// use topomech::mechanics::{Body, Material};
/// use topomech::store::{self, Document, Format};
///
/// let (points, tets) = topomech::generate::kuhn_cube(1);
/// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let doc = Document::from_body(&body);
/// assert_eq!((doc.map.dimension, doc.map.capacity), (3, 6 * 24));
/// assert!(doc.mechanics.is_some() && doc.levels.is_none());
/// assert_eq!(store::decode(&store::encode(&doc, Format::Binary).unwrap()).unwrap(), doc);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Document {
    /// Every dart slot, link, cell id and allocator.
    pub map: RawMap,
    /// The mechanical attributes of a body (3-G-maps only).
    pub mechanics: Option<RawMechanics>,
    /// The levels of a leveled map (version 2; 3 with origins): one record per dart slot (dead
    /// slots are not stored and come back as defaults), the max level, the vertex positions and
    /// the origins of a cut's copies.
    pub levels: Option<LevelParts>,
}

impl Document {
    /// The document of a bare map. O(capacity · n).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::store::Document;
    /// # use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let doc = Document::from_map(&map);
    /// assert_eq!((doc.map.dimension, doc.map.capacity, doc.version()), (3, 24, 1));
    /// assert!(doc.mechanics.is_none() && doc.levels.is_none());
    /// ```
    pub fn from_map<const N: usize>(map: &GMap<N>) -> Self {
        Document { map: RawMap::from_map(map), mechanics: None, levels: None }
    }

    /// The document of a leveled map: its finest map and its levels part. Dead dart slots get
    /// default records (they are not stored). O(capacity · n + history entries + points).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::store::Document;
    /// # use topomech::{subdivide::LeveledMap, GMap};
    /// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
    /// let mut m = LeveledMap::new(map, vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    /// let d = m.map().darts().next().unwrap();
    /// m.subdivide_triangle(d, 1).unwrap();
    /// let doc = Document::from_leveled(&m);
    /// assert_eq!(doc.levels.as_ref().unwrap().max_level, 1);
    /// let back = doc.into_leveled::<2>().unwrap();
    /// assert_eq!((back.darts_at_level(0), back.darts_at_level(1)), (6, 24));
    /// ```
    pub fn from_leveled<const N: usize>(m: &LeveledMap<N>) -> Self {
        let mut parts = m.to_parts();
        for (k, rec) in parts.darts.iter_mut().enumerate() {
            if !m.map().contains(crate::DartId(k as u32)) {
                *rec = DartLevels::default();
            }
        }
        Document { map: RawMap::from_map(m.map()), mechanics: None, levels: Some(parts) }
    }

    /// The version a document is written with, the lowest that holds it: [`ORIGINS_VERSION`]
    /// with a levels part that has origins, [`LEVELS_VERSION`] with another levels part,
    /// [`MIN_VERSION`] without. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::store::{self, Document};
    /// # use topomech::{subdivide::LeveledMap, GMap};
    /// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
    /// let mut m = LeveledMap::new(map, vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    /// let d = m.map().darts().next().unwrap();
    /// m.subdivide_triangle(d, 1).unwrap();
    /// assert_eq!(Document::from_map(m.map()).version(), store::MIN_VERSION);
    /// assert_eq!(Document::from_leveled(&m).version(), store::LEVELS_VERSION);
    /// ```
    pub fn version(&self) -> u32 {
        match &self.levels {
            Some(l) if !l.origins.is_empty() => ORIGINS_VERSION,
            Some(_) => LEVELS_VERSION,
            None => MIN_VERSION,
        }
    }

    /// The document of a body (map + mechanics), as it is, unchecked, with the records of dead
    /// cell ids blank ([`RawMechanics::blank_dead`]: no cell reads them): a body whose state
    /// [`Document::into_body`] refuses (before round 27, a face flag rewritten by a
    /// [`crate::embedding::CellRules`] method called by hand on the body's attributes) gives a
    /// document it refuses;
    /// [`save_body`] checks before writing. O(capacity + cells).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::store::Document;
    /// # use topomech::mechanics::{Body, Material};
    /// let (points, tets) = topomech::generate::kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let doc = Document::from_body(&body);
    /// assert!(doc.mechanics.is_some());
    /// let back = doc.clone().into_body().unwrap();
    /// assert_eq!(Document::from_body(&back), doc);
    /// ```
    pub fn from_body(body: &Body) -> Self {
        let (map, mut mechanics) = (RawMap::from_map(body.map()), RawMechanics::from_mechanics(body.attrs()));
        mechanics.blank_dead(&map);
        Document { map, mechanics: Some(mechanics), levels: None }
    }

    /// The map, required to satisfy every law. O(darts · n²).
    ///
    /// # Errors
    /// The structural errors of [`RawMap::check`] (a map built or changed in memory that no
    /// decoder would return), [`StoreError::WrongDimension`], [`StoreError::BrokenLaw`] (the first
    /// law broken).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::store::{self, Document};
    /// # use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let back: GMap<3> = Document::from_map(&map).into_map().unwrap();
    /// assert!(topomech::ops::same_raw(&back, &map));
    /// let e = Document::from_map(&map).into_map::<2>().unwrap_err();
    /// assert!(matches!(e, store::StoreError::WrongDimension { found: 3, expected: 2 }));
    /// ```
    pub fn into_map<const N: usize>(self) -> Result<GMap<N>, StoreError> {
        self.map.check()?;
        let map = self.map.to_gmap_raw::<N>()?;
        map.validate()?;
        Ok(map)
    }

    /// The leveled map, required to satisfy every law of the map and of levels
    /// ([`LeveledMap::from_parts`]). O(k · darts · n²).
    ///
    /// # Errors
    /// [`StoreError::NoLevels`], the structural errors of [`RawMap::check`],
    /// [`StoreError::WrongDimension`], [`StoreError::BrokenLaw`], [`StoreError::Levels`] (a
    /// malformed record or the first level law broken).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::store::{self, Document};
    /// # use topomech::{subdivide::LeveledMap, GMap};
    /// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
    /// let mut m = LeveledMap::new(map, vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    /// let d = m.map().darts().next().unwrap();
    /// m.subdivide_triangle(d, 1).unwrap();
    /// let back = Document::from_leveled(&m).into_leveled::<2>().unwrap();
    /// assert_eq!(back.to_parts(), m.to_parts());
    /// let e = Document::from_map(m.map()).into_leveled::<2>().unwrap_err();
    /// assert!(matches!(e, store::StoreError::NoLevels));
    /// ```
    pub fn into_leveled<const N: usize>(self) -> Result<LeveledMap<N>, StoreError> {
        let parts = self.levels.ok_or(StoreError::NoLevels)?;
        self.map.check()?;
        let map = self.map.to_gmap_raw::<N>()?;
        map.validate()?;
        Ok(LeveledMap::from_parts(map, parts)?)
    }

    /// The body, required to satisfy every law of the map and of conservation. O(darts).
    ///
    /// # Errors
    /// [`StoreError::NoMechanics`], the structural errors of [`RawMap::check`],
    /// [`StoreError::NonFinite`] (at [`Where::Document`]) for a NaN or infinite attribute (which
    /// no decoder returns), [`StoreError::WrongDimension`], [`StoreError::BrokenLaw`],
    /// [`StoreError::Conservation`]; [`StoreError::Inconsistent`] (at [`Where::Document`]) for a
    /// material [`Body::from_tets`] refuses, a volume whose Young's modulus is not the material's
    /// E, a face whose boundary flag disagrees with the map, or a face normal that is neither zero
    /// nor (on a boundary face) of length 1.
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::store::{self, Document};
    /// # use topomech::mechanics::{Body, Material};
    /// let (points, tets) = topomech::generate::kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let back = Document::from_body(&body).into_body().unwrap();
    /// assert!(back.map().is_isomorphic(body.map()));
    /// let e = Document::from_map(body.map()).into_body().unwrap_err();
    /// assert!(matches!(e, store::StoreError::NoMechanics));
    /// ```
    pub fn into_body(self) -> Result<Body, StoreError> {
        let raw_mech = self.mechanics.ok_or(StoreError::NoMechanics)?;
        self.map.check()?;
        if let Some((field, index)) = raw_mech.first_non_finite() {
            return Err(StoreError::NonFinite { at: Where::Document, field, index });
        }
        let map = self.map.to_gmap_raw::<3>()?;
        map.validate()?;
        let mech = raw_mech.to_mechanics();
        check_body_state(&map, &mech)?;
        crate::mechanics::check_conservation(&map, &mech)?;
        Ok(Body::from_checked_parts(map, mech))
    }
}

/// How far from 1 the length of a stored boundary face normal may be (a normalized vector is
/// within a few ulps of it).
const NORMAL_TOLERANCE: f64 = 1e-9;

/// What a body keeps besides the conservation laws and must still agree with: its material is
/// one [`Body::from_tets`] accepts, the body is homogeneous (every live volume's Young's modulus
/// E_t is the material's E, bit for bit: `from_tets` sets E_t = E and every split copies it, and
/// the conservation laws check the springs against E_t, so this ties E to the springs as the
/// mass law ties ρ to the tet masses), each face's boundary flag says whether the face is α3-free
/// in the map (the flag is derived from the map; a flipped one would make the surface and the
/// boundary forces wrong), and each face normal is zero or, on a boundary face, of length 1.
/// (Normals are computed from the positions at the last topological change, so their directions
/// are kept as stored.) O(darts).
pub(super) fn check_body_state(map: &GMap<3>, mech: &crate::mechanics::Mechanics) -> Result<(), StoreError> {
    mech.check_covers(map)?;
    let inconsistent = |message: String| StoreError::Inconsistent { at: Where::Document, message };
    crate::mechanics::model::check_material(mech.material()).map_err(|e| inconsistent(format!("material: {e}")))?;
    let young = mech.material().young;
    for d in map.one_dart_per_cell(3) {
        let t = map.cell_id(3, d);
        let e_t = mech.tet_young(t);
        if e_t.to_bits() != young.to_bits() {
            return Err(inconsistent(format!(
                "volume {} has Young's modulus {e_t:?} but the material's E is {young:?} (a body is \
                 homogeneous: every tet's springs are computed from E_t = E)",
                t.0
            )));
        }
    }
    // The face law of the body (flag = α3-free, inner normals zero), named as the reader names it.
    let face_message = |e: ConservationError| match e {
        ConservationError::FaceFlag { face, flagged_boundary, .. } => {
            let (flag, truth) = if flagged_boundary { ("boundary", "inner") } else { ("inner", "boundary") };
            format!("face {} is flagged {flag} but is a {truth} face of the map", face.0)
        }
        ConservationError::InnerFaceNormal { face, normal, .. } => {
            let len = normal.iter().map(|c| c * c).sum::<f64>().sqrt();
            format!("face {} has the normal {normal:?} of length {len}, not zero (an inner face)", face.0)
        }
        other => other.to_string(),
    };
    mech.check_faces(map).map_err(|e| inconsistent(face_message(e)))?;
    for d in map.one_dart_per_cell(2).into_iter().filter(|&d| map.is_free(3, d)) {
        let f = map.cell_id(2, d);
        let n = mech.face_normal(f);
        let len = n.iter().map(|c| c * c).sum::<f64>().sqrt();
        if !(n == [0.0; 3] || (len - 1.0).abs() <= NORMAL_TOLERANCE) {
            let rule = "of length 1 (or zero for a degenerate face)";
            return Err(inconsistent(format!("face {} has the normal {n:?} of length {len}, not {rule}", f.0)));
        }
    }
    Ok(())
}

/// Encodes a document in one form. O(size).
///
/// # Errors
/// The structural errors of [`RawMap::check`] for a map no decoder would accept (it could not
/// be read back; nothing is written); [`StoreError::Unrepresentable`] when an attribute is NaN or
/// infinite, mechanics are given for a map whose dimension is not 3, or the levels part does not
/// fit the map (it could not be read back either).
///
/// # Examples
///
/// ```
/// # use topomech::store::{self, Document, Format};
/// # use topomech::GMap;
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let doc = Document::from_map(&map);
/// let text = store::encode(&doc, Format::Text).unwrap();
/// assert!(text.starts_with(store::TEXT_MAGIC.as_bytes()));
/// let bin = store::encode(&doc, Format::Binary).unwrap();
/// assert!(bin.starts_with(&store::BINARY_MAGIC));
/// assert_eq!(store::decode(&bin).unwrap(), store::decode(&text).unwrap());
/// ```
pub fn encode(doc: &Document, format: Format) -> Result<Vec<u8>, StoreError> {
    doc.map.check()?;
    if let Some(m) = &doc.mechanics {
        mechanics_dimension(&doc.map).map_err(|what| StoreError::Unrepresentable { what })?;
        m.check_finite().map_err(|what| StoreError::Unrepresentable { what })?;
    }
    if let Some(l) = &doc.levels {
        check_levels_representable(&doc.map, l).map_err(|what| StoreError::Unrepresentable { what })?;
    }
    Ok(match format {
        Format::Text => text::encode(doc).into_bytes(),
        Format::Binary => binary::encode(doc),
    })
}

/// `Err(description)` when a map of this dimension cannot carry mechanics (only a 3-G-map can:
/// the decoders refuse a mechanics section or flag for any other n). O(1).
pub(super) fn mechanics_dimension(map: &RawMap) -> Result<(), String> {
    if map.dimension == 3 {
        Ok(())
    } else {
        Err(format!("mechanical attributes need a 3-G-map, the map has dimension {}", map.dimension))
    }
}

/// `Err(description)` when the levels part cannot be written: not one record per dart slot, a
/// history entry of a live dart naming an involution above the dimension or a dart past the
/// capacity (the decoders refuse both), or a non-finite point. O(capacity + entries + points).
fn check_levels_representable(map: &RawMap, l: &LevelParts) -> Result<(), String> {
    if l.darts.len() != map.capacity as usize {
        return Err(format!("{} dart level records for {} dart slots", l.darts.len(), map.capacity));
    }
    let live = map.live();
    for (d, rec) in l.darts.iter().enumerate().filter(|&(d, _)| live[d]) {
        if let Some(e) = rec.history.iter().find(|e| usize::from(e.j) > map.dimension || e.old >= map.capacity) {
            return Err(format!(
                "history entry {e:?} of dart {d} names α{} or dart {} (the map has dimension {} and {} dart slots)",
                e.j, e.old, map.dimension, map.capacity
            ));
        }
    }
    if let Some(k) = l.points.iter().position(|p| p.iter().any(|x| !x.is_finite())) {
        return Err(format!("point {k} is not finite"));
    }
    Ok(())
}

/// Decodes either form (told apart by the magic) into a raw document, checking its structure but
/// not the laws. The binary magic must open the data; the text header is its first significant
/// line (blank and `#` comment lines before it, and blanks around it, are ignored as anywhere
/// else in the text form). O(size).
///
/// # Errors
/// Every structural [`StoreError`] variant, with the line or byte offset; never panics and never
/// allocates more than the data present justifies.
///
/// # Examples
///
/// ```
/// # use topomech::store::{self, Document, Format};
/// # use topomech::GMap;
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let doc = Document::from_map(&map);
/// let mut bytes = store::encode(&doc, Format::Binary).unwrap();
/// assert_eq!(store::decode(&bytes).unwrap(), doc);
/// let last = bytes.len() - 1;
/// bytes[last] ^= 1; // one flipped bit: the checksum no longer matches
/// assert!(store::decode(&bytes).is_err());
/// assert!(matches!(store::decode(b"hello"), Err(store::StoreError::BadMagic { .. })));
/// ```
pub fn decode(bytes: &[u8]) -> Result<Document, StoreError> {
    // A UTF-8 byte-order mark (which some editors write) is no part of the text (finding 210).
    let text = bytes.strip_prefix(UTF8_BOM).unwrap_or(bytes);
    if bytes.starts_with(&BINARY_MAGIC) {
        binary::decode(bytes)
    } else if text::header_comes_first(text) {
        text::decode(text)
    } else {
        let line = text::first_significant_line(text).unwrap_or(text);
        Err(StoreError::BadMagic { found: line[..line.len().min(16)].escape_ascii().to_string() })
    }
}

/// The UTF-8 encoding of U+FEFF, the byte-order mark.
const UTF8_BOM: &[u8] = b"\xEF\xBB\xBF";

/// Reads and decodes a file (raw: laws unchecked). O(size).
///
/// # Errors
/// [`StoreError::Io`] and the errors of [`decode`].
///
/// # Examples
///
/// ```
/// # use topomech::store::{self, Document, Format};
/// # use topomech::GMap;
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let path = std::env::temp_dir().join(format!("topomech-doc-{}-read.tmap", std::process::id()));
/// let doc = Document::from_map(&map);
/// store::save_document(&doc, &path, Format::Text).unwrap();
/// assert_eq!(store::read_document(&path).unwrap(), doc);
/// std::fs::remove_file(&path).unwrap();
/// assert!(matches!(store::read_document(&path), Err(store::StoreError::Io { .. })));
/// ```
pub fn read_document(path: &Path) -> Result<Document, StoreError> {
    let bytes = crate::io::read_whole(path).map_err(|source| StoreError::Io { path: path.to_path_buf(), source })?;
    decode(&bytes)
}

/// Loads a map that satisfies every law. O(size + darts · n²).
///
/// # Errors
/// As [`read_document`] and [`Document::into_map`].
///
/// # Examples
///
/// ```
/// # use topomech::store::{self, Format};
/// # use topomech::GMap;
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let path = std::env::temp_dir().join(format!("topomech-doc-{}-load.tmapb", std::process::id()));
/// store::save_map(&map, &path, Format::Binary).unwrap();
/// let back: GMap<3> = store::load_map(&path).unwrap();
/// assert!(topomech::ops::same_raw(&back, &map));
/// assert!(store::load_map::<2>(&path).is_err()); // a 3-G-map is stored
/// # std::fs::remove_file(&path).unwrap();
/// ```
pub fn load_map<const N: usize>(path: &Path) -> Result<GMap<N>, StoreError> {
    read_document(path)?.into_map()
}

/// Loads a body whose map and attributes satisfy every law. O(size + darts).
///
/// # Errors
/// As [`read_document`] and [`Document::into_body`].
///
/// # Examples
///
/// ```
/// # use topomech::store::{self, Document, Format};
/// # use topomech::mechanics::{Body, Material};
/// let (points, tets) = topomech::generate::kuhn_cube(1);
/// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let path = std::env::temp_dir().join(format!("topomech-doc-{}-load-body.tmapb", std::process::id()));
/// store::save_body(&body, &path, Format::Binary).unwrap();
/// let back = store::load_body(&path).unwrap();
/// assert_eq!(Document::from_body(&back), Document::from_body(&body));
/// # std::fs::remove_file(&path).unwrap();
/// ```
pub fn load_body(path: &Path) -> Result<Body, StoreError> {
    read_document(path)?.into_body()
}

/// Loads a leveled map whose map and levels satisfy every law. O(size + k · darts · n²).
///
/// # Errors
/// As [`read_document`] and [`Document::into_leveled`].
///
/// # Examples
///
/// ```
/// # use topomech::store::{self, Format};
/// # use topomech::{subdivide::LeveledMap, GMap};
/// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
/// let mut m = LeveledMap::new(map, vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
/// let d = m.map().darts().next().unwrap();
/// m.subdivide_triangle(d, 1).unwrap();
/// let path = std::env::temp_dir().join(format!("topomech-doc-{}-load-lev.tmap", std::process::id()));
/// store::save_leveled(&m, &path, Format::Text).unwrap();
/// let back = store::load_leveled::<2>(&path).unwrap();
/// assert_eq!(back.to_parts(), m.to_parts());
/// # std::fs::remove_file(&path).unwrap();
/// ```
pub fn load_leveled<const N: usize>(path: &Path) -> Result<LeveledMap<N>, StoreError> {
    read_document(path)?.into_leveled()
}

/// Saves a leveled map (version 2, or 3 when a cut made copies) in `format`, atomically. O(capacity · n + entries).
///
/// # Errors
/// As [`save_document`].
///
/// # Examples
///
/// ```
/// # use topomech::store::{self, Format};
/// # use topomech::{subdivide::LeveledMap, GMap};
/// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
/// let mut m = LeveledMap::new(map, vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
/// let d = m.map().darts().next().unwrap();
/// m.subdivide_triangle(d, 1).unwrap();
/// let path = std::env::temp_dir().join(format!("topomech-doc-{}-save-lev.tmapb", std::process::id()));
/// store::save_leveled(&m, &path, Format::Binary).unwrap();
/// let doc = store::read_document(&path).unwrap();
/// assert_eq!(doc.version(), 2);
/// assert_eq!(doc.levels.unwrap().max_level, m.max_level());
/// # std::fs::remove_file(&path).unwrap();
/// ```
pub fn save_leveled<const N: usize>(m: &LeveledMap<N>, path: &Path, format: Format) -> Result<(), StoreError> {
    save_document(&Document::from_leveled(m), path, format)
}

/// Saves a map in `format`, atomically. O(capacity · n).
///
/// # Errors
/// As [`save_document`].
///
/// # Examples
///
/// ```
/// # use topomech::store::{self, Format};
/// # use topomech::GMap;
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let path = std::env::temp_dir().join(format!("topomech-doc-{}-save.tmap", std::process::id()));
/// store::save_map(&map, &path, Format::Text).unwrap();
/// let text = std::fs::read_to_string(&path).unwrap();
/// assert!(text.starts_with(store::TEXT_MAGIC));
/// assert!(store::load_map::<3>(&path).unwrap().is_isomorphic(&map));
/// # std::fs::remove_file(&path).unwrap();
/// ```
pub fn save_map<const N: usize>(map: &GMap<N>, path: &Path, format: Format) -> Result<(), StoreError> {
    save_document(&Document::from_map(map), path, format)
}

/// Saves a body in `format`, atomically, after the body-state checks of
/// [`Document::into_body`] (material, E_t of every volume, each face's boundary flag against
/// the map, face normals zero or of length 1), so that no file is written that [`load_body`]
/// would refuse for them (the conservation laws, which the body's operations keep, are checked
/// by [`crate::embedding::Embedded::check`]). O(capacity + darts).
///
/// # Errors
/// [`StoreError::Inconsistent`] (at [`Where::Document`]) naming the volume or face whose state
/// the reader would refuse, or [`StoreError::Conservation`] for attributes that do not cover
/// the map (nothing is written); then as [`save_document`].
///
/// # Examples
///
/// ```
/// # use topomech::store::{self, Document, Format};
/// # use topomech::mechanics::{Body, Material};
/// let (points, tets) = topomech::generate::kuhn_cube(1);
/// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let path = std::env::temp_dir().join(format!("topomech-doc-{}-save-body.tmap", std::process::id()));
/// store::save_body(&body, &path, Format::Text).unwrap();
/// let doc = store::read_document(&path).unwrap();
/// assert_eq!(doc, Document::from_body(&body));
/// # std::fs::remove_file(&path).unwrap();
/// ```
pub fn save_body(body: &Body, path: &Path, format: Format) -> Result<(), StoreError> {
    check_body_state(body.map(), body.attrs())?;
    save_document(&Document::from_body(body), path, format)
}

/// Encodes `doc` and writes it with [`write_atomically`]: a temporary file in the target's
/// directory, written, flushed and fsynced, renamed onto `path` (onto the file a symbolic link
/// names, with the old file's permissions), then the directory fsynced (best effort). On any
/// error the temporary file is removed and an existing `path` is left untouched — except an
/// existing writable file in a directory that takes no new file, written in place (see
/// [`write_atomically`]). O(size).
///
/// # Errors
/// The errors of [`encode`] (nothing is written); [`StoreError::Io`] naming `path` as
/// [`write_atomically`].
///
/// # Examples
///
/// ```
/// # use topomech::store::{self, Document, Format};
/// # use topomech::mechanics::{Body, Material};
/// let (points, tets) = topomech::generate::kuhn_cube(1);
/// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let path = std::env::temp_dir().join(format!("topomech-doc-{}-save-doc.tmapb", std::process::id()));
/// let mut doc = Document::from_body(&body);
/// assert!(store::save_document(&doc, &path, Format::Binary).is_ok());
/// doc.mechanics.as_mut().unwrap().material[0] = f64::NAN;
/// let e = store::save_document(&doc, &path, Format::Binary).unwrap_err();
/// assert!(matches!(e, store::StoreError::Unrepresentable { .. }));
/// assert!(store::read_document(&path).is_ok()); // the first file is untouched
/// # std::fs::remove_file(&path).unwrap();
/// ```
pub fn save_document(doc: &Document, path: &Path, format: Format) -> Result<(), StoreError> {
    let bytes = encode(doc, format)?;
    write_atomically(path, &bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `save_body` refuses a boundary normal the reader would refuse (not of length 1), naming
    /// the face, and writes nothing. The library computes unit normals at every scale (finding
    /// 254), so the state is made by hand here.
    #[test]
    fn save_body_refuses_a_boundary_normal_not_of_length_one() {
        let (points, tets) = crate::generate::kuhn_cube(1);
        let (mut body, _) = Body::from_tets(&points, &tets, crate::mechanics::Material::default()).unwrap();
        let d = body.map().darts().find(|&d| body.map().is_free(3, d)).unwrap();
        let f = body.map().cell_id(2, d);
        body.attrs_raw_mut().face_normal[f] = [1.0 + 1e-6, 0.0, 0.0];
        let path = std::env::temp_dir().join(format!("topomech-store-unit-{}.tmap", std::process::id()));
        let _ = std::fs::remove_file(&path);
        let e = save_body(&body, &path, Format::Text).unwrap_err();
        let named = format!("face {} has the normal", f.0);
        assert!(matches!(&e, StoreError::Inconsistent { message, .. } if message.contains(&named)), "{e:?}");
        assert!(!path.exists(), "nothing written");
    }
}
