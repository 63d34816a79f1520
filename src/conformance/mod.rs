//! Conformance vectors: an input mesh, a sequence of cutting operations and the expected state
//! after each, as JSON that another engine can replay (`docs/CONFORMANCE.md`, `conformance/`).
//!
//! ```text
//!   Recipe ──generate──▶ Vector { mesh, material, initial: Expect, steps: [Step { op, expect }] }
//!   Vector ──replay────▶ Ok(()) | ConformanceError naming the vector, the step, the field,
//!                        expected vs got
//! ```
//!
//! Everything in a vector is named the way any engine can name it: points and tets by their
//! 0-based index in the input mesh (these never change: the operations split vertices, edges and
//! faces but never tets), an inner face by the two input tets that share it (and, as a
//! cross-check, by its sorted triple of input point ids), a vertex to tear by an input tet and
//! one of its input points. The expected state holds only quantities that do not depend on how an
//! engine stores its mesh: cell counts, components, boundary faces, Euler characteristic, darts
//! (24 per tet), total mass, Σ spring stiffness, the masses of the components, and the inner
//! faces each step dissociated.
//!
//! Replaying a vector also checks, after every step, the map's laws (`validate()`), the
//! conservation laws ([`check_conservation`](crate::mechanics::check_conservation)) and the cell
//! counts of an independent union-find model of the cut tet list ([`Oracle`](crate::cut::ops::Oracle)).

mod runner;
mod schema;
pub mod standard;

pub use runner::{generate, generate_in, replay, replay_in, Ops, Recipe, PLANE_MARGIN};
pub use schema::{Expect, MaterialSpec, MeshSpec, Op, Refusal, Step, Vector};

use std::path::{Path, PathBuf};

/// The value of [`Vector::format`].
pub const FORMAT: &str = "topomech-conformance";
/// The schema version this code reads and writes.
pub const VERSION: u32 = 1;
/// Default relative tolerance of every floating-point comparison (stored in each vector).
pub const TOLERANCE: f64 = 1e-9;

/// The largest initial vertex count for which [`generate`] writes the per-cell fields
/// [`Expect::vertex_masses`] and [`Expect::edge_stiffnesses`] (larger vectors stay small files:
/// their totals only).
pub const DETAIL_MAX_VERTICES: usize = 200;
/// The largest [`Vector::tolerance`] a vector may ask for: 0 ≤ tolerance ≤ 10⁻³. A relative
/// tolerance of 1 or more accepts every value of the same sign (|a − b| ≤ max(|a|, |b|)), so a
/// loose bound would make the float fields vacuous; 10⁻³ still absorbs any rounding difference
/// between engines (the standard set uses [`TOLERANCE`]).
pub const MAX_TOLERANCE: f64 = 1e-3;
/// The longest [`Vector::name`] (in bytes; names are ASCII, see [`Vector::check_fields`]).
pub const MAX_NAME_LEN: usize = 128;

/// Why a vector could not be read, generated or replayed. Every variant that concerns a vector
/// names it; those that concern a step carry its index (`None` = the initial state).
///
/// # Examples
///
/// ```
/// use topomech::conformance::{generate, ConformanceError, MeshSpec, Op, Ops, Recipe, Vector};
///
/// let e = Vector::from_json("{", "x.json").unwrap_err();
/// assert!(matches!(e, ConformanceError::Json { ref origin, .. } if origin == "x.json"));
/// let recipe = Recipe {
///     name: "bad".into(), description: "a tet that is not there".into(), mesh: MeshSpec::KuhnCube { k: 1 },
///     material: topomech::mechanics::Material::default().into(), ops: Ops::Listed(vec![Op::Remove { tet: 6 }]),
/// };
/// let e = generate(&recipe).unwrap_err();
/// assert!(matches!(e, ConformanceError::BadOp { step: Some(0), .. }));
/// ```
#[derive(Debug, thiserror::Error)]
pub enum ConformanceError {
    /// A file could not be read or written.
    #[error("{}: {source}", .path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The text is not JSON, or not a vector of this schema.
    #[error("{origin}: not a conformance vector: {message}")]
    Json {
        /// The file (or `<memory>`).
        origin: String,
        /// What serde_json reported (with line and column).
        message: String,
    },
    /// `format` is not [`FORMAT`], or missing.
    #[error("{origin}: {found}, expected format {FORMAT:?}")]
    Format {
        /// The file (or `<memory>`).
        origin: String,
        /// What was found, in words: `format is "x"` (the value as JSON text: a string once
        /// quoted, a number as written), `missing field \`format\``, with what the file is when
        /// that is known (an ambiguity vector, a JSON array).
        found: String,
    },
    /// `version` is not [`VERSION`].
    #[error("{origin}: version {found} is not supported (this topomech reads version {VERSION})")]
    Version {
        /// The file (or `<memory>`).
        origin: String,
        /// The version found.
        found: String,
    },
    /// The mesh could not be loaded or built, or does not have the declared size.
    #[error("vector {vector}: mesh: {message}")]
    Mesh {
        /// The vector.
        vector: String,
        /// What is wrong.
        message: String,
    },
    /// A field of the vector is invalid (a tolerance outside 0 ..= [`MAX_TOLERANCE`], a
    /// non-finite material constant).
    #[error("vector {vector}: {message}")]
    Invalid {
        /// The vector.
        vector: String,
        /// What is wrong.
        message: String,
    },
    /// The vector's (or recipe's) name is empty, longer than [`MAX_NAME_LEN`] or holds a
    /// character outside `A–Z a–z 0–9 _ - .` (it is printed in reports and is a file stem, so a
    /// newline or a path separator could forge a report line or a path). Shown escaped.
    #[error("vector name {name:?} is not a plain name (1 to {MAX_NAME_LEN} of A-Z a-z 0-9 _ - .)")]
    BadName {
        /// The name as found.
        name: String,
    },
    /// A vector file's `name` differs from the file's stem (`docs/CONFORMANCE.md`: the name is
    /// the file stem), so a report line would name another vector than the file checked.
    #[error("{}: the vector is named {name:?} but the file stem is {stem:?}; they must be equal", .path.display())]
    NameMismatch {
        /// The file.
        path: PathBuf,
        /// The vector's `name`.
        name: String,
        /// The file's stem (lossy UTF-8).
        stem: String,
    },
    /// An expected float is ±∞ or NaN: |∞ − x| ≤ tolerance · ∞ holds for every x, so such an
    /// expectation would match anything; vectors store finite values only.
    #[error("vector {vector}, {}: expected {field}{} = {value:?} is not finite", at(.step), element(.index))]
    NotFinite {
        /// The vector.
        vector: String,
        /// The step index (`None` = initial state).
        step: Option<usize>,
        /// The field of [`Expect`].
        field: &'static str,
        /// The element, for the lists (`component_masses`, `vertex_masses`, `edge_stiffnesses`).
        index: Option<usize>,
        /// The value found.
        value: f64,
    },
    /// A vector's `file` mesh path resolves (through a symbolic link) to a place outside the
    /// repository root; nothing is read from it.
    #[error("vector {vector}: mesh path {path:?} resolves outside the repository root {}; not read", .root.display())]
    OutsideRoot {
        /// The vector.
        vector: String,
        /// The path as the vector gives it.
        path: String,
        /// The root it must stay inside.
        root: PathBuf,
    },
    /// An operation names something the mesh does not have (tet id out of range, two tets that
    /// share no face, a point that is not a corner of the tet, a non-finite plane).
    #[error("vector {vector}, {}: bad operation: {message}", at(.step))]
    BadOp {
        /// The vector.
        vector: String,
        /// The step index.
        step: Option<usize>,
        /// What is wrong.
        message: String,
    },
    /// An observed value differs from the expected one.
    #[error("vector {vector}, {}: {field}: expected {expected}, got {got}", at(.step))]
    Mismatch {
        /// The vector.
        vector: String,
        /// The step index (`None` = initial state).
        step: Option<usize>,
        /// The field of [`Expect`] that differs.
        field: &'static str,
        /// The stored value.
        expected: String,
        /// The replayed value.
        got: String,
    },
    /// A law broke after a step: `validate()`, conservation, or the union-find model.
    #[error("vector {vector}, {}: law broken: {message}", at(.step))]
    Law {
        /// The vector.
        vector: String,
        /// The step index.
        step: Option<usize>,
        /// Which law and how.
        message: String,
    },
    /// An `incise` step whose plane passes within [`PLANE_MARGIN`] · (bounding-box diagonal) of a
    /// live tet centroid: the side of that tet would be decided by rounding or by a tie rule
    /// (topomech's puts a centroid on the plane on the negative side), so the vector does not
    /// determine the outcome. A defect of the vector, not a failure of the engine replaying it:
    /// [`generate`] refuses to write such a step and [`replay_in`] refuses to replay one.
    #[error(
        "vector {vector}, {}: ambiguous vector: the centroid of tet {tet} is {distance:e} from the incise plane, \
         within the vectors' margin {margin:e} ({PLANE_MARGIN:e} × the bounding-box diagonal): its side is \
         left to rounding and tie rules, not fixed by the vector; not replayed",
        at(.step)
    )]
    AmbiguousPlane {
        /// The vector.
        vector: String,
        /// The step index.
        step: Option<usize>,
        /// The live input tet whose centroid is closest to the plane (the smallest id among equals).
        tet: u32,
        /// Its centroid's distance from the plane.
        distance: f64,
        /// The required margin: [`PLANE_MARGIN`] × the diagonal of the bounding box of the points
        /// the input tets use (removed ones included).
        margin: f64,
    },
}

/// "" or "\[i\]".
fn element(index: &Option<usize>) -> String {
    index.map(|i| format!("[{i}]")).unwrap_or_default()
}

/// "initial state" or "step k".
fn at(step: &Option<usize>) -> String {
    match step {
        None => "initial state".to_string(),
        Some(k) => format!("step {k}"),
    }
}

impl ConformanceError {
    /// The step the error concerns (`None`: the initial state or not step-specific). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::conformance::{generate, replay};
    /// # use topomech::conformance::{MeshSpec, Op, Ops, Recipe};
    /// # let recipe = Recipe {
    /// #     name: "one".into(),
    /// #     description: "remove a tet".into(),
    /// #     mesh: MeshSpec::KuhnCube { k: 1 },
    /// #     material: topomech::mechanics::Material::default().into(),
    /// #     ops: Ops::Listed(vec![Op::Remove { tet: 0 }]),
    /// # };
    /// let mut v = generate(&recipe).unwrap();
    /// v.steps[0].expect.cells[3] = 4; // a wrong expectation after step 0
    /// assert_eq!(replay(&v).unwrap_err().step(), Some(0));
    /// v.initial.darts += 1; // now the initial state is already wrong
    /// assert_eq!(replay(&v).unwrap_err().step(), None);
    /// ```
    pub fn step(&self) -> Option<usize> {
        match self {
            ConformanceError::BadOp { step, .. }
            | ConformanceError::Mismatch { step, .. }
            | ConformanceError::Law { step, .. }
            | ConformanceError::NotFinite { step, .. }
            | ConformanceError::AmbiguousPlane { step, .. } => *step,
            _ => None,
        }
    }

    /// The mismatching field, for a [`ConformanceError::Mismatch`], or the non-finite one, for a
    /// [`ConformanceError::NotFinite`]. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::conformance::{generate, replay};
    /// # use topomech::conformance::{MeshSpec, Op, Ops, Recipe};
    /// # let recipe = Recipe {
    /// #     name: "one".into(),
    /// #     description: "remove a tet".into(),
    /// #     mesh: MeshSpec::KuhnCube { k: 1 },
    /// #     material: topomech::mechanics::Material::default().into(),
    /// #     ops: Ops::Listed(vec![Op::Remove { tet: 0 }]),
    /// # };
    /// let mut v = generate(&recipe).unwrap();
    /// v.steps[0].expect.total_mass *= 2.0;
    /// assert_eq!(replay(&v).unwrap_err().field(), Some("total_mass"));
    /// ```
    pub fn field(&self) -> Option<&'static str> {
        match self {
            ConformanceError::Mismatch { field, .. } | ConformanceError::NotFinite { field, .. } => Some(field),
            _ => None,
        }
    }
}

impl Vector {
    /// Parses a vector; `origin` names the text in errors. The envelope (`format`, `version`) is
    /// checked before the rest, so a file of another format or version says so. A key given twice
    /// in one object, at any depth, is refused (JSON leaves its meaning open). O(text).
    ///
    /// # Errors
    /// [`ConformanceError::Json`], [`ConformanceError::Format`], [`ConformanceError::Version`].
    ///
    /// ```
    /// use topomech::conformance::{ConformanceError, Vector};
    /// let e = Vector::from_json(r#"{"format": "topomech-conformance", "version": 9}"#, "x.json").unwrap_err();
    /// assert!(matches!(e, ConformanceError::Version { .. }));
    /// ```
    pub fn from_json(text: &str, origin: &str) -> Result<Vector, ConformanceError> {
        let json = |e: serde_json::Error| ConformanceError::Json { origin: origin.to_string(), message: e.to_string() };
        let value: serde_json::Value = serde_json::from_str(text).map_err(json)?;
        if value.get("format").and_then(|f| f.as_str()) != Some(FORMAT) {
            return Err(ConformanceError::Format { origin: origin.to_string(), found: format_found(&value) });
        }
        let version = value.get("version").cloned().unwrap_or(serde_json::Value::Null);
        if version.as_u64() != Some(u64::from(VERSION)) {
            return Err(ConformanceError::Version { origin: origin.to_string(), found: version.to_string() });
        }
        // Decoded again from the text, not from `value` (whose maps keep the last of two equal
        // keys): a key given twice, at any depth, is refused.
        let v: Vector = serde_json::from_str(text).map_err(json)?;
        v.check_fields_from(origin)?;
        Ok(v)
    }

    /// The checks every vector passes before it is replayed, whether it was decoded
    /// ([`Vector::from_json`] runs them) or built in memory ([`replay_in`] runs them), in this
    /// order: `format` is [`FORMAT`], `version` is [`VERSION`], `name` is 1 to [`MAX_NAME_LEN`]
    /// characters of `A–Z a–z 0–9 _ - .` (it is printed in reports and is a file stem), the
    /// tolerance is in 0 ..= [`MAX_TOLERANCE`], the material constants are finite and ≥ 0, and
    /// every expected float (`total_mass`, `total_stiffness`, `component_masses`, `vertex_masses`,
    /// `edge_stiffnesses`, initial state and every step) is finite, and the two per-cell lists
    /// are ascending with no negative entry. O(size).
    ///
    /// # Errors
    /// The first that fails: [`ConformanceError::Format`], [`ConformanceError::Version`] (origin
    /// `<memory>`), [`ConformanceError::BadName`], [`ConformanceError::Invalid`],
    /// [`ConformanceError::NotFinite`] (step, field and element), [`ConformanceError::Invalid`]
    /// for a per-cell list out of order.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::conformance::{generate, ConformanceError, MAX_TOLERANCE};
    /// # use topomech::conformance::{MeshSpec, Op, Ops, Recipe};
    /// # let recipe = Recipe {
    /// #     name: "one".into(),
    /// #     description: "remove a tet".into(),
    /// #     mesh: MeshSpec::KuhnCube { k: 1 },
    /// #     material: topomech::mechanics::Material::default().into(),
    /// #     ops: Ops::Listed(vec![Op::Remove { tet: 0 }]),
    /// # };
    /// let v = generate(&recipe).unwrap();
    /// v.check_fields().unwrap();
    /// let mut loose = v.clone();
    /// loose.tolerance = 2.0 * MAX_TOLERANCE;
    /// assert!(matches!(loose.check_fields(), Err(ConformanceError::Invalid { .. })));
    /// let mut inf = v.clone();
    /// inf.steps[0].expect.total_mass = f64::INFINITY; // would match any mass
    /// let e = inf.check_fields().unwrap_err();
    /// assert_eq!((e.step(), e.field()), (Some(0), Some("total_mass")));
    /// let mut forged = v.clone();
    /// forged.name = "x\nok    everything_fine".into();
    /// assert!(matches!(forged.check_fields(), Err(ConformanceError::BadName { .. })));
    /// ```
    pub fn check_fields(&self) -> Result<(), ConformanceError> {
        self.check_fields_from("<memory>")
    }

    fn check_fields_from(&self, origin: &str) -> Result<(), ConformanceError> {
        if self.format != FORMAT {
            let found = format!("format is {}", serde_json::Value::from(self.format.as_str()));
            return Err(ConformanceError::Format { origin: origin.to_string(), found });
        }
        if self.version != VERSION {
            return Err(ConformanceError::Version { origin: origin.to_string(), found: self.version.to_string() });
        }
        check_name(&self.name)?;
        let invalid = |message: String| ConformanceError::Invalid { vector: self.name.clone(), message };
        if !(0.0..=MAX_TOLERANCE).contains(&self.tolerance) {
            return Err(invalid(format!(
                "tolerance {:e} is outside 0 ..= {MAX_TOLERANCE:e} (a looser relative tolerance makes the float fields \
                 vacuous)",
                self.tolerance
            )));
        }
        let m = self.material;
        for (name, value) in
            [("density", m.density), ("young", m.young), ("damping", m.damping), ("viscosity", m.viscosity)]
        {
            if !(value.is_finite() && value >= 0.0) {
                return Err(invalid(format!("material {name} = {value} must be finite and ≥ 0")));
            }
        }
        let expects = std::iter::once((None, &self.initial))
            .chain(self.steps.iter().enumerate().map(|(k, s)| (Some(k), &s.expect)));
        for (step, e) in expects {
            let scalars = [("total_mass", None, e.total_mass), ("total_stiffness", None, e.total_stiffness)];
            fn list<'a>(
                field: &'static str,
                x: Option<&'a [f64]>,
            ) -> impl Iterator<Item = (&'static str, Option<usize>, f64)> + 'a {
                x.unwrap_or_default().iter().enumerate().map(move |(i, &m)| (field, Some(i), m))
            }
            let lists = list("component_masses", Some(&e.component_masses))
                .chain(list("vertex_masses", e.vertex_masses.as_deref()))
                .chain(list("edge_stiffnesses", e.edge_stiffnesses.as_deref()));
            if let Some((field, index, value)) = scalars.into_iter().chain(lists).find(|(_, _, x)| !x.is_finite()) {
                return Err(ConformanceError::NotFinite { vector: self.name.clone(), step, field, index, value });
            }
            // The per-cell lists are sorted values of masses and stiffnesses: a list out of
            // order or with a negative entry is a defect of the vector, not a mismatch of the
            // engine (finding 313).
            for (field, list) in [("vertex_masses", &e.vertex_masses), ("edge_stiffnesses", &e.edge_stiffnesses)] {
                let list = list.as_deref().unwrap_or_default();
                if let Some(i) = (0..list.len()).find(|&i| list[i] < 0.0 || (i > 0 && list[i] < list[i - 1])) {
                    let at = step.map_or("the initial state".to_string(), |k| format!("step {k}"));
                    return Err(invalid(format!(
                        "{at}: {field}[{i}] = {:?} breaks the list's order (ascending, every entry ≥ 0)",
                        list[i]
                    )));
                }
            }
        }
        Ok(())
    }

    /// Reads and parses the vector file at `path`. O(file).
    ///
    /// # Errors
    /// [`ConformanceError::Io`], then as [`Vector::from_json`].
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::conformance::{generate, Vector};
    /// # use topomech::conformance::{MeshSpec, Op, Ops, Recipe};
    /// # let recipe = Recipe {
    /// #     name: "one".into(),
    /// #     description: "remove a tet".into(),
    /// #     mesh: MeshSpec::KuhnCube { k: 1 },
    /// #     material: topomech::mechanics::Material::default().into(),
    /// #     ops: Ops::Listed(vec![Op::Remove { tet: 0 }]),
    /// # };
    /// let v = generate(&recipe).unwrap();
    /// let path = std::env::temp_dir().join(format!("topomech_doc_read_{}.json", std::process::id()));
    /// std::fs::write(&path, v.to_json()).unwrap();
    /// assert_eq!(Vector::read(&path).unwrap(), v);
    /// std::fs::remove_file(&path).unwrap();
    /// assert!(Vector::read(&path).is_err()); // gone: an I/O error naming the path
    /// ```
    pub fn read(path: &Path) -> Result<Vector, ConformanceError> {
        let io = |source| ConformanceError::Io { path: path.into(), source };
        let bytes = crate::io::read_whole(path).map_err(io)?;
        let text = String::from_utf8(bytes)
            .map_err(|e| io(std::io::Error::new(std::io::ErrorKind::InvalidData, e.utf8_error())))?;
        Vector::from_json(&text, &path.display().to_string())
    }

    /// The vector as pretty-printed JSON (two-space indent, arrays of numbers on one line) with a
    /// final newline: the exact bytes of the committed files, so regeneration can be compared
    /// byte for byte. O(size).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::conformance::{generate, Vector};
    /// # use topomech::conformance::{MeshSpec, Op, Ops, Recipe};
    /// # let recipe = Recipe {
    /// #     name: "one".into(),
    /// #     description: "remove a tet".into(),
    /// #     mesh: MeshSpec::KuhnCube { k: 1 },
    /// #     material: topomech::mechanics::Material::default().into(),
    /// #     ops: Ops::Listed(vec![Op::Remove { tet: 0 }]),
    /// # };
    /// let v = generate(&recipe).unwrap();
    /// let text = v.to_json();
    /// assert!(text.ends_with("}\n"));
    /// assert_eq!(Vector::from_json(&text, "mem").unwrap(), v);
    /// ```
    pub fn to_json(&self) -> String {
        let pretty = serde_json::to_string_pretty(self).expect("a vector always serialises (plain data)");
        let mut s = flatten_scalar_arrays(&pretty);
        s.push('\n');
        s
    }
}

/// What a document whose `format` is not [`FORMAT`] holds there, in words for
/// [`ConformanceError::Format`]: `format is "x"` (its JSON text), or the field missing, with what
/// the document is when that is known: an ambiguity vector (`"type": "pair"` or `"indexed"`, as
/// `topomech ambiguity --write-vectors` writes) or not a JSON object at all. O(1).
fn format_found(value: &serde_json::Value) -> String {
    use serde_json::Value;
    let kind = match value {
        Value::Object(map) => map.get("type").and_then(|t| t.as_str()),
        Value::Array(_) => return "missing field `format`: the file holds a JSON array, not an object".into(),
        Value::String(_) => return "missing field `format`: the file holds a JSON string, not an object".into(),
        Value::Number(_) => return "missing field `format`: the file holds a JSON number, not an object".into(),
        Value::Bool(_) | Value::Null => {
            return format!("missing field `format`: the file holds {value}, not an object")
        }
    };
    match (value.get("format"), kind) {
        (Some(f), _) => {
            let text = f.to_string();
            let cut: String = text.chars().take(60).collect();
            format!("format is {cut}{}", if cut.len() < text.len() { "…" } else { "" })
        }
        (None, Some("pair" | "indexed")) => {
            "missing field `format`: this is an ambiguity vector (`topomech ambiguity --write-vectors`; \
             `cargo test --test ambiguity_vectors` replays those), not a conformance vector"
                .into()
        }
        (None, _) => "missing field `format`".into(),
    }
}

/// Refuses a vector or recipe name that is empty, longer than [`MAX_NAME_LEN`] or holds a
/// character outside `A–Z a–z 0–9 _ - .`. O(len).
pub(crate) fn check_name(name: &str) -> Result<(), ConformanceError> {
    let plain = |c: char| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.');
    if name.is_empty() || name.len() > MAX_NAME_LEN || !name.chars().all(plain) {
        return Err(ConformanceError::BadName { name: name.to_string() });
    }
    Ok(())
}

/// What `topomech conformance check` does with one file: reads the vector at `path`
/// ([`Vector::read`], which runs [`Vector::check_fields`]), replays it with mesh files relative
/// to `root` ([`replay_in`]), and then requires its `name` to be the file's stem, so the report
/// line of a file names that file's vector. A vector that fails to replay is reported by that
/// failure (it says what is wrong with the content). Cost: that of [`replay_in`].
///
/// # Errors
/// As [`Vector::read`] and [`replay_in`]; then [`ConformanceError::NameMismatch`].
///
/// # Examples
///
/// ```
/// use topomech::conformance::{check_file, generate, ConformanceError};
/// # use topomech::conformance::{MeshSpec, Op, Ops, Recipe};
/// # let recipe = Recipe {
/// #     name: "one".into(),
/// #     description: "remove a tet".into(),
/// #     mesh: MeshSpec::KuhnCube { k: 1 },
/// #     material: topomech::mechanics::Material::default().into(),
/// #     ops: Ops::Listed(vec![Op::Remove { tet: 0 }]),
/// # };
/// let v = generate(&recipe).unwrap();
/// let dir = std::env::temp_dir().join(format!("topomech_doc_check_file_{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// std::fs::write(dir.join("one.json"), v.to_json()).unwrap();
/// assert_eq!(check_file(&dir.join("one.json"), &dir).unwrap(), v);
/// std::fs::write(dir.join("other.json"), v.to_json()).unwrap();
/// let e = check_file(&dir.join("other.json"), &dir).unwrap_err();
/// assert!(matches!(e, ConformanceError::NameMismatch { ref stem, .. } if stem == "other"));
/// std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub fn check_file(path: &Path, root: &Path) -> Result<Vector, ConformanceError> {
    let v = Vector::read(path)?;
    replay_in(&v, root)?;
    let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    if stem != v.name {
        return Err(ConformanceError::NameMismatch { path: path.to_path_buf(), name: v.name, stem });
    }
    Ok(v)
}

/// The `*.json` files of `dir`, sorted by name. O(entries log entries).
///
/// # Errors
/// [`ConformanceError::Io`] when the directory cannot be listed.
///
/// # Examples
///
/// ```
/// use topomech::conformance::vector_files;
///
/// let dir = std::env::temp_dir().join(format!("topomech_doc_vectors_{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// for name in ["b.json", "notes.txt", "a.json"] {
///     std::fs::write(dir.join(name), "{}").unwrap();
/// }
/// assert_eq!(vector_files(&dir).unwrap(), vec![dir.join("a.json"), dir.join("b.json")]);
/// std::fs::remove_dir_all(&dir).unwrap();
/// assert!(vector_files(&dir).is_err());
/// ```
pub fn vector_files(dir: &Path) -> Result<Vec<PathBuf>, ConformanceError> {
    let io = |source| ConformanceError::Io { path: dir.into(), source };
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(io)? {
        let path = entry.map_err(io)?.path();
        if path.extension().is_some_and(|e| e == "json") {
            files.push(path);
        }
    }
    files.sort();
    Ok(files)
}

/// Rewrites every array of `pretty` that holds no array or object onto one line (`[1, 2, 3]`);
/// strings are copied untouched. O(len).
fn flatten_scalar_arrays(pretty: &str) -> String {
    let mut out = String::with_capacity(pretty.len());
    // For each open array: where it starts in `out`, and whether it holds only scalars so far.
    let mut open: Vec<(usize, bool)> = Vec::new();
    let mut strings = JsonStrings::default();
    for c in pretty.chars() {
        if strings.literal(c) {
            out.push(c);
            continue;
        }
        if let ('[' | '{', Some(top)) = (c, open.last_mut()) {
            top.1 = false;
        }
        if c == '[' {
            open.push((out.len(), true));
        }
        if c == ']' {
            if let Some((start, true)) = open.pop() {
                let body = squeeze(&out[start..]);
                out.truncate(start);
                out.push_str(&body);
            }
        }
        out.push(c);
    }
    out
}

/// Where a left-to-right scan of JSON text stands with respect to string literals.
#[derive(Default)]
struct JsonStrings {
    inside: bool,
    escaped: bool,
}

impl JsonStrings {
    /// Steps over `c`: true when `c` belongs to a string literal (its quotes included), whose
    /// characters are to be copied untouched. O(1).
    fn literal(&mut self, c: char) -> bool {
        if !self.inside {
            self.inside = c == '"';
            return self.inside;
        }
        (self.inside, self.escaped) = match (self.escaped, c) {
            (true, _) => (true, false),
            (false, '\\') => (true, true),
            (false, '"') => (false, false),
            _ => (true, false),
        };
        true
    }
}

/// `[\n  1,\n  2\n` → `[1, 2` (whitespace outside strings dropped, `,` followed by one space).
fn squeeze(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut strings = JsonStrings::default();
    for c in text.chars() {
        if strings.literal(c) {
            out.push(c);
            continue;
        }
        match c {
            ',' => out.push_str(", "),
            c if c.is_whitespace() => {}
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::flatten_scalar_arrays;
    use proptest::prelude::*;
    use serde_json::{json, Value};

    /// JSON values whose strings hold the characters the flattener must step over: quotes,
    /// backslashes, brackets, commas, spaces and newlines.
    fn values() -> impl Strategy<Value = Value> {
        let text = || proptest::string::string_regex("[a-c \\[\\]{},:\"\\\\\n]{0,8}").unwrap();
        let leaf = prop_oneof![
            any::<i32>().prop_map(Value::from),
            any::<bool>().prop_map(Value::from),
            text().prop_map(Value::from),
            Just(Value::Null),
        ];
        leaf.prop_recursive(4, 40, 5, move |inner| {
            prop_oneof![
                proptest::collection::vec(inner.clone(), 0..5).prop_map(Value::Array),
                proptest::collection::btree_map(text(), inner, 0..4)
                    .prop_map(|m| Value::Object(m.into_iter().collect())),
            ]
        })
    }

    /// An array with no array or object inside is on one line; other lines keep their indent.
    #[test]
    fn scalar_arrays_go_on_one_line_and_strings_are_untouched() {
        // `\" ]`: a quote that does not end its string, then a bracket that closes nothing.
        let tricky = "q\\\" ] [ \\\\\" {";
        let v = json!({"a [b]": ["x, \"y\" ]", "\\", 1], "nested": [[1, 2], {"k": [true, null]}], "e": [], "t": [tricky, [tricky]]});
        let flat = flatten_scalar_arrays(&serde_json::to_string_pretty(&v).unwrap());
        assert_eq!(serde_json::from_str::<Value>(&flat).unwrap(), v);
        assert!(flat.contains(r#""a [b]": ["x, \"y\" ]", "\\", 1]"#), "{flat}");
        assert!(flat.contains(r#"[1, 2]"#) && flat.contains(r#""k": [true, null]"#), "{flat}");
        assert!(flat.contains("\"e\": []"), "{flat}");
        assert!(flat.contains(&format!("[{}]", serde_json::to_string(tricky).unwrap())), "{flat}");
    }

    proptest! {
        /// The flattened text is the same JSON value: only whitespace outside strings changed.
        #[test]
        fn flattening_keeps_the_value(v in values()) {
            let pretty = serde_json::to_string_pretty(&v).unwrap();
            let flat = flatten_scalar_arrays(&pretty);
            prop_assert_eq!(serde_json::from_str::<Value>(&flat).unwrap(), v);
            let squeeze = |s: &str| s.chars().filter(|c| !c.is_whitespace()).collect::<String>();
            // Equal up to whitespace (whitespace inside strings included, so this also shows
            // that no string lost or gained a character).
            prop_assert_eq!(squeeze(&flat), squeeze(&pretty));
        }
    }
}
