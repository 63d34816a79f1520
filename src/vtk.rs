//! ParaView output: VTK XML unstructured grids (`.vtu`, ASCII) and a `.pvd` time series.
//!
//! One `.vtu` frame holds the points, the tetrahedra (VTK cell type 10) and per-point vectors
//! (e.g. velocity, displacement); the `.pvd` file lists the frames with their times so ParaView
//! plays them as an animation. Cost: O(points + tets) per frame.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};

use crate::mechanics::{Body, Vec3};
use crate::{AlphaMask, CellId};

/// Errors of the VTK writers.
///
/// # Examples
///
/// ```
/// use topomech::vtk::{Frame, VtkError};
///
/// let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// let short = [[0.0; 3]; 2];
/// let frame = Frame { points: &points, tets: &[[0, 1, 2, 3]], vectors: vec![("force", &short[..])] };
/// let err = frame.to_vtu().unwrap_err();
/// assert!(matches!(&err, VtkError::BadArray { name, got: 2, expected: 4 } if name == "force"));
/// assert!(err.to_string().contains("force"));
/// ```
#[derive(Debug, thiserror::Error)]
pub enum VtkError {
    /// The file could not be written.
    #[error("cannot write {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The series directory could not be created.
    #[error("cannot create the directory {path}: {source}")]
    CreateDir {
        /// The directory.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A point array does not have one entry per point.
    #[error("point array {name} has {got} entries for {expected} points")]
    BadArray {
        /// The array's name.
        name: String,
        /// Its length.
        got: usize,
        /// The number of points.
        expected: usize,
    },
    /// A point array name holding a character XML cannot carry: a control character
    /// (`char::is_control`: C0 such as NUL or U+0001, DEL, C1) or a character outside the XML 1.0
    /// `Char` production (the noncharacters U+FFFE and U+FFFF). XML 1.0 forbids most C0 controls
    /// and U+FFFE/U+FFFF, so readers would reject the file, and tab, line feed and carriage return
    /// in an attribute come back as spaces.
    #[error("point array {array} has the name {name:?}, which holds a control character or a non-XML character")]
    BadArrayName {
        /// The array's index in [`Frame::vectors`].
        array: usize,
        /// The name given.
        name: String,
    },
    /// A tetrahedron names a point the frame does not have (readers would accept the file and
    /// index past their point array).
    #[error("tetrahedron {tet} names point {point}, but the frame has {points} points")]
    BadTet {
        /// The tet's index in the frame.
        tet: usize,
        /// The point index out of range.
        point: u32,
        /// The number of points.
        points: usize,
    },
    /// A series stem that is empty or holds a path separator, a control character or a character
    /// outside the XML 1.0 `Char` production such as U+FFFE (the frames would land outside the
    /// series directory, under a name no listing shows, or in a `.pvd` no XML reader accepts).
    #[error("series stem {stem:?} must be a non-empty file name without '/', '\\', control or non-XML characters")]
    BadStem {
        /// The stem given.
        stem: String,
    },
    /// A frame time that is NaN or infinite (ParaView orders frames by time).
    #[error("frame {frame} has time {time}, which is not finite")]
    BadTime {
        /// The frame's index in the series.
        frame: usize,
        /// The time given.
        time: f64,
    },
}

/// One frame: points, tets and named per-point vectors.
///
/// # Examples
///
/// ```
/// use topomech::generate::kuhn_cube;
/// use topomech::vtk::Frame;
///
/// let (points, tets) = kuhn_cube(1);
/// let zero = vec![[0.0; 3]; points.len()];
/// let frame = Frame { points: &points, tets: &tets, vectors: vec![("velocity", &zero[..])] };
/// assert_eq!(frame.vectors[0].1.len(), frame.points.len()); // one vector per point
/// let xml = frame.to_vtu().unwrap();
/// assert!(xml.contains("NumberOfPoints=\"8\" NumberOfCells=\"6\""));
/// ```
#[derive(Clone, Debug, Default)]
pub struct Frame<'a> {
    /// Point coordinates.
    pub points: &'a [Vec3],
    /// Tetrahedra as four point indices.
    pub tets: &'a [[u32; 4]],
    /// Per-point 3-vectors, by name.
    pub vectors: Vec<(&'a str, &'a [Vec3])>,
}

impl Frame<'_> {
    /// The frame as VTU XML text. O(points + tets).
    ///
    /// Array names are written as XML attribute values (`&`, `<`, `>`, `"` and `'` as entities),
    /// so a reader gets back the name as given; a name with a control character or a character
    /// outside the XML 1.0 `Char` production (U+FFFE, U+FFFF), which XML cannot carry, is
    /// refused. Everything is checked before any text is made: the names and lengths in
    /// O(arrays + name lengths), the tets in O(tets).
    ///
    /// # Errors
    /// For the first array in order: [`VtkError::BadArrayName`] when its name holds a control
    /// character (`char::is_control`) or a non-XML character (U+FFFE, U+FFFF),
    /// [`VtkError::BadArray`] when it has the wrong length;
    /// then [`VtkError::BadTet`] when a tetrahedron names a point past the end of `points`.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::vtk::{Frame, VtkError};
    ///
    /// let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let velocity = [[0.0, 0.0, -1.0]; 4];
    /// let frame = Frame { points: &points, tets: &[[0, 1, 2, 3]], vectors: vec![("velocity", &velocity[..])] };
    /// let xml = frame.to_vtu().unwrap();
    /// assert!(xml.contains("NumberOfPoints=\"4\" NumberOfCells=\"1\"") && xml.contains("Name=\"velocity\""));
    /// let bad = Frame { vectors: vec![("velocity", &velocity[..3])], ..frame.clone() };
    /// assert!(matches!(bad.to_vtu(), Err(VtkError::BadArray { got: 3, expected: 4, .. })));
    /// let bad = Frame { tets: &[[0, 1, 2, 3], [1, 2, 3, 4]], ..frame.clone() };
    /// assert!(matches!(bad.to_vtu(), Err(VtkError::BadTet { tet: 1, point: 4, points: 4 })));
    /// let named = Frame { vectors: vec![("v<&>w", &velocity[..])], ..frame.clone() };
    /// assert!(named.to_vtu().unwrap().contains("Name=\"v&lt;&amp;&gt;w\""));
    /// let control = Frame { vectors: vec![("v", &velocity[..]), ("a\u{1}b", &velocity[..])], ..frame };
    /// let err = control.to_vtu().unwrap_err();
    /// assert!(matches!(&err, VtkError::BadArrayName { array: 1, name } if name == "a\u{1}b"));
    /// assert!(err.to_string().contains("\"a\\u{1}b\"")); // the name, escaped
    /// let nonchar = Frame { vectors: vec![("a\u{FFFE}b", &velocity[..])], ..control };
    /// assert!(matches!(nonchar.to_vtu(), Err(VtkError::BadArrayName { array: 0, .. })));
    /// ```
    pub fn to_vtu(&self) -> Result<String, VtkError> {
        let n = self.points.len();
        for (array, (name, values)) in self.vectors.iter().enumerate() {
            if !name.chars().all(is_name_char) {
                return Err(VtkError::BadArrayName { array, name: name.to_string() });
            }
            if values.len() != n {
                return Err(VtkError::BadArray { name: name.to_string(), got: values.len(), expected: n });
            }
        }
        let outside = |t: &[u32; 4]| t.iter().copied().find(|&p| p as usize >= n);
        if let Some((tet, point)) = self.tets.iter().enumerate().find_map(|(k, t)| outside(t).map(|p| (k, p))) {
            return Err(VtkError::BadTet { tet, point, points: n });
        }
        let mut s = String::with_capacity(64 * (n + self.tets.len()) + 512);
        s.push_str("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n<UnstructuredGrid>\n");
        let _ = writeln!(s, "<Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{}\">", self.tets.len());
        s.push_str("<PointData>\n");
        for (name, values) in &self.vectors {
            vector_array(&mut s, name, values);
        }
        s.push_str("</PointData>\n<Points>\n");
        vector_array(&mut s, "Points", self.points);
        s.push_str("</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
        for t in self.tets {
            let _ = writeln!(s, "{} {} {} {}", t[0], t[1], t[2], t[3]);
        }
        s.push_str("</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
        for i in 0..self.tets.len() {
            let _ = writeln!(s, "{}", 4 * (i + 1));
        }
        s.push_str("</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
        for _ in self.tets {
            s.push_str("10\n");
        }
        s.push_str("</DataArray>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
        Ok(s)
    }

    /// Writes the frame to `path`, atomically: through a temporary file beside it and a rename
    /// ([`crate::store::write_atomically`]), so a failed write (a full disk) leaves an earlier
    /// file at `path` whole. A device or a pipe (`/dev/null`) is written in place. O(points + tets).
    ///
    /// # Errors
    /// The errors of [`Frame::to_vtu`], checked before the file is created (nothing is written
    /// then); [`VtkError::Io`] naming `path`.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::vtk::{Frame, VtkError};
    ///
    /// let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let frame = Frame { points: &points, tets: &[[0, 1, 2, 3]], vectors: vec![] };
    /// let path = std::env::temp_dir().join(format!("topomech-doc-{}.vtu", std::process::id()));
    /// frame.write(&path).unwrap();
    /// let text = std::fs::read_to_string(&path).unwrap();
    /// std::fs::remove_file(&path).unwrap();
    /// assert_eq!(text, frame.to_vtu().unwrap());
    /// let nul = Frame { vectors: vec![("f\0", &points[..])], ..frame };
    /// assert!(matches!(nul.write(&path), Err(VtkError::BadArrayName { array: 0, .. })));
    /// assert!(!path.exists()); // refused before the file was created
    /// ```
    pub fn write(&self, path: &Path) -> Result<(), VtkError> {
        write_file(path, &self.to_vtu()?)
    }
}

/// The XML 1.0 `Char` production: #x9 | #xA | #xD | \[#x20–#xD7FF\] | \[#xE000–#xFFFD\] |
/// \[#x10000–#x10FFFF\] (a Rust `char` is never a surrogate, U+D800–U+DFFF). O(1).
fn is_xml_char(c: char) -> bool {
    matches!(c, '\t' | '\n' | '\r' | '\u{20}'..='\u{D7FF}' | '\u{E000}'..='\u{FFFD}' | '\u{10000}'..='\u{10FFFF}')
}

/// A character a name or stem may hold: an XML `Char` that is not a control character (tab, line
/// feed and carriage return are XML characters, but an attribute value turns them into spaces,
/// so the name would not come back as given). O(1).
fn is_name_char(c: char) -> bool {
    is_xml_char(c) && !c.is_control()
}

fn vector_array(s: &mut String, name: &str, values: &[Vec3]) {
    let name = xml_attribute(name);
    let _ = writeln!(s, "<DataArray type=\"Float64\" Name=\"{name}\" NumberOfComponents=\"3\" format=\"ascii\">");
    for v in values {
        let _ = writeln!(s, "{:e} {:e} {:e}", v[0], v[1], v[2]);
    }
    s.push_str("</DataArray>\n");
}

/// `text` as an XML attribute value: the five markup characters as entities, every other
/// character as given. O(text).
fn xml_attribute(text: &str) -> std::borrow::Cow<'_, str> {
    if !text.contains(['&', '<', '>', '"', '\'']) {
        return text.into();
    }
    let mut out = String::with_capacity(text.len() + 16);
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    out.into()
}

/// Writes `text` to `path` through [`crate::store::write_atomically`] (a temporary file and a
/// rename: a failed write leaves the earlier file whole), or in place when `path` is a device or
/// a pipe (renaming over `/dev/null` would replace the device by a file). O(text).
fn write_file(path: &Path, text: &str) -> Result<(), VtkError> {
    let io = |source| VtkError::Io { path: path.to_path_buf(), source };
    if std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir()) {
        let mut f = std::fs::OpenOptions::new().write(true).truncate(true).open(path).map_err(io)?;
        return f.write_all(text.as_bytes()).map_err(io);
    }
    crate::store::write_atomically(path, text.as_bytes()).map_err(|e| match e {
        crate::store::StoreError::Io { source, .. } => io(source),
        other => io(std::io::Error::other(other.to_string())),
    })
}

/// A `.pvd` collection being written: frames are recorded as they are saved.
///
/// # Examples
///
/// ```
/// use topomech::vtk::{Frame, Series};
///
/// let dir = std::env::temp_dir().join(format!("topomech-doc-series-{}", std::process::id()));
/// let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// let frame = Frame { points: &points, tets: &[[0, 1, 2, 3]], vectors: vec![] };
/// let mut series = Series::new(&dir, "drop").unwrap();
/// for step in 0..3 {
///     assert!(series.push(step as f64 * 0.1, &frame).unwrap().exists());
/// }
/// assert_eq!(std::fs::read_to_string(series.pvd_path()).unwrap().matches("<DataSet").count(), 3);
/// std::fs::remove_dir_all(&dir).unwrap();
/// ```
#[derive(Clone, Debug)]
pub struct Series {
    dir: PathBuf,
    stem: String,
    frames: Vec<(f64, String)>,
}

impl Series {
    /// A series of files `DIR/STEM_NNNNNN.vtu` and `DIR/STEM.pvd`; creates DIR.
    ///
    /// # Errors
    /// [`VtkError::BadStem`] for an empty stem or one with a path separator, a control character
    /// or a non-XML character (U+FFFE, U+FFFF: the stem is written into the `.pvd`);
    /// [`VtkError::CreateDir`] if DIR cannot be created.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::vtk::{Series, VtkError};
    ///
    /// let file = std::env::temp_dir().join(format!("topomech-doc-file-{}", std::process::id()));
    /// std::fs::write(&file, "not a directory").unwrap();
    /// let err = Series::new(&file.join("frames"), "run"); // a directory under a file: refused
    /// std::fs::remove_file(&file).unwrap();
    /// assert!(matches!(err, Err(VtkError::CreateDir { .. })));
    /// let series = Series::new(&std::env::temp_dir(), "run").unwrap();
    /// assert!(series.pvd_path().ends_with("run.pvd"));
    /// for stem in ["", "../run", "a\\b", "run\n"] {
    ///     assert!(matches!(Series::new(&std::env::temp_dir(), stem), Err(VtkError::BadStem { .. })));
    /// }
    /// for stem in ["run\u{FFFE}", "run\u{FFFF}"] { // not XML characters
    ///     assert!(matches!(Series::new(&std::env::temp_dir(), stem), Err(VtkError::BadStem { .. })));
    /// }
    /// ```
    pub fn new(dir: &Path, stem: &str) -> Result<Self, VtkError> {
        if stem.is_empty() || stem.contains(['/', '\\']) || !stem.chars().all(is_name_char) {
            return Err(VtkError::BadStem { stem: stem.to_string() });
        }
        std::fs::create_dir_all(dir).map_err(|source| VtkError::CreateDir { path: dir.to_path_buf(), source })?;
        Ok(Series { dir: dir.to_path_buf(), stem: stem.to_string(), frames: Vec::new() })
    }

    /// Writes `frame` as the next file, at simulated time `time`, and rewrites the `.pvd`; both
    /// atomically (as [`Frame::write`]), so a failed write never leaves a truncated `.pvd` or
    /// frame behind. O(frame + frames so far).
    ///
    /// # Errors
    /// [`VtkError::BadTime`] for a time that is not finite (nothing is written), and the errors
    /// of [`Frame::write`] for the frame or the `.pvd`. On any error the series is as it was: a
    /// frame whose `.pvd` could not be rewritten is dropped and its file removed, so a retry
    /// takes the same number.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::vtk::{Frame, Series, VtkError};
    ///
    /// let dir = std::env::temp_dir().join(format!("topomech-doc-vtk-{}", std::process::id()));
    /// let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let frame = Frame { points: &points, tets: &[[0, 1, 2, 3]], vectors: vec![] };
    /// let mut series = Series::new(&dir, "run").unwrap();
    /// assert!(series.push(0.0, &frame).unwrap().ends_with("run_000000.vtu"));
    /// series.push(0.1, &frame).unwrap();
    /// assert!(matches!(series.push(f64::NAN, &frame), Err(VtkError::BadTime { frame: 2, .. })));
    /// let pvd = std::fs::read_to_string(series.pvd_path()).unwrap();
    /// std::fs::remove_dir_all(&dir).unwrap();
    /// assert_eq!(pvd.matches("<DataSet").count(), 2);
    /// ```
    pub fn push(&mut self, time: f64, frame: &Frame<'_>) -> Result<PathBuf, VtkError> {
        if !time.is_finite() {
            return Err(VtkError::BadTime { frame: self.frames.len(), time });
        }
        let name = format!("{}_{:06}.vtu", self.stem, self.frames.len());
        let path = self.dir.join(&name);
        frame.write(&path)?;
        self.frames.push((time, name));
        if let Err(e) = self.write_pvd() {
            // Refused as a whole (finding 204): the frame is not in the series, its file is
            // taken away again (best effort) and a retry writes the same name.
            self.frames.pop();
            let _ = std::fs::remove_file(&path);
            return Err(e);
        }
        Ok(path)
    }

    /// The `.pvd` path. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use std::path::Path;
    /// use topomech::vtk::Series;
    ///
    /// let dir = std::env::temp_dir();
    /// let series = Series::new(&dir, "liver").unwrap(); // creates nothing but the directory
    /// assert_eq!(series.pvd_path(), dir.join("liver.pvd"));
    /// assert!(series.pvd_path().extension() == Some(Path::new("pvd").as_os_str()));
    /// ```
    pub fn pvd_path(&self) -> PathBuf {
        self.dir.join(format!("{}.pvd", self.stem))
    }

    fn write_pvd(&self) -> Result<(), VtkError> {
        let mut s =
            String::from("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n");
        for (time, name) in &self.frames {
            let _ = writeln!(s, "<DataSet timestep=\"{time:e}\" part=\"0\" file=\"{}\"/>", xml_attribute(name));
        }
        s.push_str("</Collection>\n</VTKFile>\n");
        write_file(&self.pvd_path(), &s)
    }
}

/// The tets of a body as four vertex ids each (one per volume orbit), ordered so that their rest
/// signed volume is positive: by the exact orientation of the rest positions (a sliver is never
/// written inside out by rounding), as [`crate::subdivide::LeveledMap::finest_tets`]. O(darts).
///
/// # Examples
///
/// ```
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Material};
/// use topomech::mesh::signed_volume;
/// use topomech::vtk::body_tets;
///
/// let (points, tets) = kuhn_cube(1);
/// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let out = body_tets(&body);
/// assert_eq!(out.len(), 6);
/// let p = |v: u32| points[v as usize];
/// assert!(out.iter().all(|t| signed_volume(p(t[0]), p(t[1]), p(t[2]), p(t[3])) > 0.0));
/// ```
pub fn body_tets(body: &Body) -> Vec<[u32; 4]> {
    let map = body.map();
    let rest = &body.attrs().rest_position;
    let mut out = Vec::with_capacity(map.cell_id_bound(3));
    for d in map.one_dart_per_cell(3) {
        let mut ids: Vec<u32> = map.orbit(d, AlphaMask::cell(3, 3)).into_iter().map(|x| map.vertex_id(x).0).collect();
        ids.sort_unstable();
        ids.dedup();
        let Ok(mut t) = <[u32; 4]>::try_from(ids.as_slice()) else { continue };
        let p = t.map(|v| rest[CellId(v)]);
        if crate::exact::orient3d(p[0], p[1], p[2], p[3]) < 0 {
            t.swap(2, 3); // the exact orientation, as `finest_tets` (finding 222)
        }
        out.push(t);
    }
    out
}
