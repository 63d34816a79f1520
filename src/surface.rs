//! The boundary surface of a body or of a tetrahedral mesh, as an indexed triangle mesh.
//!
//! In a 3-G-map the boundary is made of the α3-free darts (seed 000, §2: "αn-free darts form the
//! boundary"); each boundary face orbit ⟨α0, α1⟩ is one triangle. [`boundary_surface`] reads it
//! from a [`Body`] at its current positions; [`boundary_surface_of_tets`] finds it in a plain
//! tetrahedron list (the faces used by exactly one tet), for meshes without a map, such as the
//! geometry of a subdivided level.
//!
//! A [`Surface`] is what the software renderer ([`crate::render`]) draws and what
//! [`Surface::to_obj`] writes as a Wavefront OBJ file.
//!
//! ```
//! use topomech::{generate, surface};
//!
//! let (points, tets) = generate::kuhn_cube(2);
//! let s = surface::boundary_surface_of_tets(&points, &tets).unwrap();
//! assert_eq!(s.triangles.len(), 2 * 6 * 2 * 2); // two triangles per unit square of each side
//! assert!((s.enclosed_volume().unwrap() - 8.0).abs() < 1e-12);
//! ```

use crate::mesh::triangle_area;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use rustc_hash::FxHashMap;

use crate::mechanics::{Body, Vec3};
use crate::DartId;

/// Errors of the surface extraction, of the measures and of the OBJ writer.
///
/// # Examples
///
/// ```
/// use std::path::Path;
/// use topomech::surface::{boundary_surface_of_tets, SurfaceError};
///
/// let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// let bad = boundary_surface_of_tets(&points, &[[0, 1, 2, 7]]);
/// assert!(matches!(bad, Err(SurfaceError::PointOutOfRange { tet: 0, point: 7, points: 4 })));
/// let mut s = boundary_surface_of_tets(&points, &[[0, 1, 2, 3]]).unwrap();
/// assert!(matches!(s.write_obj(Path::new("/nonexistent-dir/x.obj")), Err(SurfaceError::Write { .. })));
/// s.triangles.push([0, 1, 9]);
/// let err = s.area().unwrap_err();
/// assert!(matches!(err, SurfaceError::VertexOutOfRange { triangle: 4, corner: 2, index: 9, vertices: 4 }));
/// assert_eq!(err.to_string(), "triangle 4 corner 2 refers to vertex 9, but the surface has only 4 vertices");
/// ```
#[derive(Debug, thiserror::Error)]
pub enum SurfaceError {
    /// A tetrahedron refers to a point index outside the point array.
    #[error("tet {tet} refers to point {point}, but there are only {points} points")]
    PointOutOfRange {
        /// The tet's index.
        tet: usize,
        /// The bad point index.
        point: u32,
        /// The number of points.
        points: usize,
    },
    /// A tetrahedron names one point twice (its faces would be degenerate triangles).
    #[error("tet {tet} uses point {point} twice")]
    RepeatedPoint {
        /// The tet's index.
        tet: usize,
        /// The repeated point index.
        point: u32,
    },
    /// A triangle refers to a vertex index outside `positions` (the fields of [`Surface`] are
    /// public, so such a surface is one assignment away).
    #[error(
        "triangle {triangle} corner {corner} refers to vertex {index}, but the surface has only {vertices} vertices"
    )]
    VertexOutOfRange {
        /// The triangle's index in `triangles`.
        triangle: usize,
        /// The corner within the triangle (0, 1 or 2).
        corner: usize,
        /// The bad vertex index.
        index: u32,
        /// The number of vertices (`positions.len()`).
        vertices: usize,
    },
    /// A triangle names one vertex at two of its corners (the fields of [`Surface`] are
    /// public): a degenerate triangle, which the OBJ reader refuses (`RepeatedVertex`), so
    /// [`Surface::to_obj`] does not write it.
    #[error("triangle {triangle} uses vertex {vertex} at two corners")]
    RepeatedCorner {
        /// The triangle's index in `triangles`.
        triangle: usize,
        /// The repeated vertex index.
        vertex: u32,
    },
    /// A vertex position is NaN or infinite (the fields of [`Surface`] are public): no measure
    /// or OBJ file of it would be meaningful, and the OBJ reader refuses such a file.
    #[error("surface vertex {vertex} (vertex id {id}) has a non-finite position {position:?}")]
    NonFinitePosition {
        /// The vertex's index in `positions`.
        vertex: usize,
        /// Its id (`Surface::vertex_ids`), or `u32::MAX` if the surface has none for it.
        id: u32,
        /// The position.
        position: Vec3,
    },
    /// The OBJ file could not be written (the cause names the file).
    #[error("cannot write the surface OBJ file {source}")]
    Write {
        /// The file asked for.
        path: PathBuf,
        /// The cause.
        source: crate::store::StoreError,
    },
}

/// An indexed triangle mesh: the boundary of a solid.
///
/// Invariants (kept by the constructors of this module for finite input; the fields are public,
/// so [`Surface::check`] checks the first three, and the measures and OBJ writers call it): every
/// index of `triangles` is `< positions.len()`; no triangle names a vertex twice; every position
/// is finite; every surface vertex
/// is used by some triangle (the vertex array is compacted); `vertex_ids.len() ==
/// positions.len()` and `face_volumes.len() == triangles.len()`;
/// each triangle is oriented outward, i.e. its normal (b − a) × (c − a) points away from the
/// fourth vertex of the tetrahedron behind it (measured at rest for a body).
///
/// # Examples
///
/// ```
/// use topomech::generate::kuhn_cube;
/// use topomech::surface::boundary_surface_of_tets;
///
/// let (points, tets) = kuhn_cube(1);
/// let s = boundary_surface_of_tets(&points, &tets).unwrap();
/// assert_eq!((s.positions.len(), s.vertex_ids.len(), s.face_volumes.len()), (8, 8, 12));
/// assert!(s.triangles.iter().flatten().all(|&i| (i as usize) < s.positions.len()));
/// assert!(s.face_volumes.iter().all(|&t| (t as usize) < tets.len()));
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Surface {
    /// Position of each surface vertex.
    pub positions: Vec<Vec3>,
    /// Triangles as three indices into `positions`, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
    /// For surface vertex i, the vertex cell id in the body (or the point index in the point
    /// array for [`boundary_surface_of_tets`]).
    pub vertex_ids: Vec<u32>,
    /// For triangle t, the volume cell id of the tetrahedron behind it (or the tet index).
    pub face_volumes: Vec<u32>,
}

/// The boundary surface of `body`: one triangle per α3-free face orbit, at the body's current
/// vertex positions, in face id order.
///
/// Each triangle is oriented away from the fourth vertex of its tetrahedron, measured on the rest
/// positions (so the orientation is that of the material and does not flip when a tet is
/// inverted by a large deformation); a tet that is flat at rest is oriented on the current
/// positions instead. After a face dissociation both sides of the cut are boundary faces, so the
/// surface grows by two triangles per dissociated face.
///
/// Cost: O(darts) (one pass to pick a dart per face, O(1) per boundary face after that).
///
/// ```
/// use topomech::{generate, mechanics::Body, surface};
///
/// let (points, tets) = generate::kuhn_cube(1);
/// let (body, _) = Body::from_tets(&points, &tets, Default::default()).unwrap();
/// let s = surface::boundary_surface(&body);
/// assert_eq!((s.positions.len(), s.triangles.len()), (8, 12));
/// ```
pub fn boundary_surface(body: &Body) -> Surface {
    let map = body.map();
    let attrs = body.attrs();
    let mut builder = Builder::new(map.cell_id_bound(0));
    for d in map.one_dart_per_cell(2) {
        if !map.is_free(3, d) {
            continue;
        }
        let at = |x: DartId| map.vertex_id(x);
        let a = at(d);
        let b = at(map.alpha::<0>(d));
        let c = at(map.alpha::<0>(map.alpha::<1>(map.alpha::<0>(d))));
        // α2 stays in the tet (onto the other face through edge ab); α1 then α0 reach its apex.
        let apex = at(map.alpha::<0>(map.alpha::<1>(map.alpha::<2>(d))));
        let corners = [a, b, c, apex];
        let rest = corners.map(|v| attrs.rest_position[v]);
        let now = corners.map(|v| attrs.position[v]);
        let side = if apex_side(rest) != 0.0 { apex_side(rest) } else { apex_side(now) };
        let flip = side > 0.0;
        let tri = if flip { [a, c, b] } else { [a, b, c] };
        builder.push(tri.map(|v| (v.0, attrs.position[v])), map.cell_id(3, d).0);
    }
    builder.finish()
}

/// The boundary surface of a tetrahedral mesh: the faces used by exactly one tet, in tet order
/// then local face order, each oriented away from the tet's fourth point. `vertex_ids` are point
/// indices and `face_volumes` tet indices. A face shared by three or more tets (not a manifold)
/// is not a boundary face.
///
/// Cost: O(T) expected (one hash of each of the 4T sorted face triples).
///
/// # Errors
/// [`SurfaceError::PointOutOfRange`] naming the first tet with a bad index, then
/// [`SurfaceError::RepeatedPoint`] naming the first tet that uses a point twice.
///
/// ```
/// use topomech::surface::boundary_surface_of_tets;
///
/// let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// let s = boundary_surface_of_tets(&points, &[[0, 1, 2, 3]]).unwrap();
/// assert_eq!(s.triangles.len(), 4);
/// assert!((s.enclosed_volume().unwrap() - 1.0 / 6.0).abs() < 1e-15);
/// assert!(boundary_surface_of_tets(&points, &[[0, 1, 2, 9]]).is_err());
/// assert!(boundary_surface_of_tets(&points, &[[0, 1, 2, 3], [0, 2, 2, 3]]).is_err());
/// ```
pub fn boundary_surface_of_tets(points: &[Vec3], tets: &[[u32; 4]]) -> Result<Surface, SurfaceError> {
    if let Some((tet, &point)) =
        tets.iter().enumerate().find_map(|(t, tet)| tet.iter().find(|&&p| p as usize >= points.len()).map(|p| (t, p)))
    {
        return Err(SurfaceError::PointOutOfRange { tet, point, points: points.len() });
    }
    let repeated = |t: &[u32; 4]| (1..4).find_map(|j| t[..j].contains(&t[j]).then_some(t[j]));
    if let Some((tet, point)) = tets.iter().enumerate().find_map(|(k, t)| repeated(t).map(|p| (k, p))) {
        return Err(SurfaceError::RepeatedPoint { tet, point });
    }
    let face = |tet: &[u32; 4], f: usize| -> [u32; 3] {
        let mut k = 0;
        let mut out = [0; 3];
        for (j, &p) in tet.iter().enumerate() {
            if j != f {
                out[k] = p;
                k += 1;
            }
        }
        out
    };
    let key = |mut tri: [u32; 3]| {
        tri.sort_unstable();
        tri
    };
    let mut uses: FxHashMap<[u32; 3], u32> = FxHashMap::default();
    for tet in tets {
        for f in 0..4 {
            *uses.entry(key(face(tet, f))).or_insert(0) += 1;
        }
    }
    let mut builder = Builder::new(points.len());
    for (t, tet) in tets.iter().enumerate() {
        for f in 0..4 {
            let [a, b, c] = face(tet, f);
            if uses[&key([a, b, c])] != 1 {
                continue;
            }
            let p = |v: u32| points[v as usize];
            let tri = if apex_side([p(a), p(b), p(c), p(tet[f])]) > 0.0 { [a, c, b] } else { [a, b, c] };
            builder.push(tri.map(|v| (v, p(v))), t as u32);
        }
    }
    Ok(builder.finish())
}

/// Sign of the apex `q[3]` relative to the plane of the triangle `q[0..3]` oriented by its normal:
/// positive when the apex is in front, i.e. the triangle faces inward. The triple product is a
/// cube of the lengths, so it is taken in wide floats (`crate::wide`: the plain product where
/// nothing over- or underflows): the same sign at edge lengths 1e-200 and 1e200 as at 1, and for
/// a sliver 1e200 wide and 1e-200 thick. O(1).
fn apex_side(q: [Vec3; 4]) -> f64 {
    crate::wide::six_volume(q[0], q[1], q[2], q[3]).signum()
}

/// Collects triangles over vertex ids and compacts the vertices on the fly.
struct Builder {
    index_of: Vec<u32>,
    surface: Surface,
}

impl Builder {
    fn new(id_bound: usize) -> Self {
        Builder { index_of: vec![u32::MAX; id_bound], surface: Surface::default() }
    }

    fn push(&mut self, corners: [(u32, Vec3); 3], volume: u32) {
        let tri = corners.map(|(id, p)| self.vertex(id, p));
        self.surface.triangles.push(tri);
        self.surface.face_volumes.push(volume);
    }

    fn vertex(&mut self, id: u32, p: Vec3) -> u32 {
        let slot = &mut self.index_of[id as usize];
        if *slot == u32::MAX {
            *slot = self.surface.positions.len() as u32;
            self.surface.positions.push(p);
            self.surface.vertex_ids.push(id);
        }
        *slot
    }

    fn finish(self) -> Surface {
        self.surface
    }
}

impl Surface {
    /// Checks that every triangle corner is an index into `positions`, that no triangle names a
    /// vertex at two corners, and that every position is finite, the invariants the measures ([`Surface::area`], [`Surface::enclosed_volume`]) and
    /// the OBJ writers ([`Surface::to_obj`], [`Surface::write_obj`]) rely on; they call it first.
    /// O(triangles + vertices).
    ///
    /// # Errors
    /// [`SurfaceError::VertexOutOfRange`] naming the first triangle, corner and index past the
    /// vertices, or [`SurfaceError::RepeatedCorner`] naming the first triangle with a repeated
    /// corner (whichever triangle comes first; range first within a triangle); then
    /// [`SurfaceError::NonFinitePosition`] naming the first vertex with a NaN or infinite
    /// coordinate.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::surface::{boundary_surface_of_tets, SurfaceError};
    ///
    /// let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mut s = boundary_surface_of_tets(&points, &[[0, 1, 2, 3]]).unwrap();
    /// assert!(s.check().is_ok());
    /// s.triangles[1][0] = 4; // one past the last vertex
    /// assert!(matches!(
    ///     s.check(),
    ///     Err(SurfaceError::VertexOutOfRange { triangle: 1, corner: 0, index: 4, vertices: 4 })
    /// ));
    /// s.triangles[1][0] = s.triangles[1][1]; // a degenerate triangle
    /// let Err(SurfaceError::RepeatedCorner { triangle: 1, vertex }) = s.check() else { panic!() };
    /// assert_eq!(vertex, s.triangles[1][1]);
    /// s.triangles[1][0] = 0;
    /// s.positions[2][1] = f64::NAN; // surface vertex 2 is point s.vertex_ids[2] of the mesh
    /// let Err(SurfaceError::NonFinitePosition { vertex: 2, id, .. }) = s.check() else { panic!() };
    /// assert_eq!(id, s.vertex_ids[2]);
    /// ```
    pub fn check(&self) -> Result<(), SurfaceError> {
        let vertices = self.positions.len();
        for (triangle, tri) in self.triangles.iter().enumerate() {
            if let Some((corner, &index)) = tri.iter().enumerate().find(|(_, &i)| i as usize >= vertices) {
                return Err(SurfaceError::VertexOutOfRange { triangle, corner, index, vertices });
            }
            let [a, b, c] = *tri;
            if a == b || a == c || b == c {
                let vertex = if a == b || a == c { a } else { b };
                return Err(SurfaceError::RepeatedCorner { triangle, vertex });
            }
        }
        if let Some((vertex, &position)) =
            self.positions.iter().enumerate().find(|(_, p)| p.iter().any(|c| !c.is_finite()))
        {
            let id = self.vertex_ids.get(vertex).copied().unwrap_or(u32::MAX);
            return Err(SurfaceError::NonFinitePosition { vertex, id, position });
        }
        Ok(())
    }

    /// The axis-aligned bounding box `(min, max)` of the vertices, or `None` for an empty
    /// surface. Non-finite coordinates are skipped. O(vertices).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::surface::boundary_surface_of_tets;
    ///
    /// let points = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 3.0, 0.0], [0.0, 0.0, 1.0]];
    /// let s = boundary_surface_of_tets(&points, &[[0, 1, 2, 3]]).unwrap();
    /// assert_eq!(s.bounds(), Some(([0.0; 3], [2.0, 3.0, 1.0])));
    /// ```
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let mut it = self.positions.iter().filter(|p| p.iter().all(|c| c.is_finite()));
        let first = *it.next()?;
        Some(it.fold((first, first), |(lo, hi), p| {
            (std::array::from_fn(|k| lo[k].min(p[k])), std::array::from_fn(|k| hi[k].max(p[k])))
        }))
    }

    /// The signed volume enclosed by the triangles, Σ (a − o)·((b − o) × (c − o)) / 6 with `o`
    /// the first vertex (divergence theorem). For a closed, outward-oriented surface it is the
    /// volume of the solid, whatever `o` (for an open one it depends on `o`). Measured from a
    /// vertex, it does not depend on where the surface is: a unit cube at 1e9 encloses 1. The
    /// products are taken in wide floats (an f64 mantissa with an unbounded exponent: the plain
    /// bits where nothing over- or underflows), so the result is ∞ or 0 only when the volume
    /// itself is past f64::MAX or below the smallest f64 (a sliver 1e200 wide and 1e-200 thick
    /// encloses its 1.67e199). +0.0 for no triangles. O(vertices + triangles), including the check.
    ///
    /// # Errors
    /// As [`Surface::check`]: [`SurfaceError::VertexOutOfRange`] naming the first triangle corner
    /// past the vertices, [`SurfaceError::RepeatedCorner`] naming a degenerate triangle,
    /// [`SurfaceError::NonFinitePosition`] naming a non-finite vertex.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::surface::boundary_surface_of_tets;
    ///
    /// let (points, tets) = kuhn_cube(2); // side 2
    /// let mut s = boundary_surface_of_tets(&points, &tets).unwrap();
    /// assert!((s.enclosed_volume().unwrap() - 8.0).abs() < 1e-12);
    /// s.triangles.push([0, 1, 999]);
    /// assert!(s.enclosed_volume().is_err()); // vertex 999 of 26
    /// ```
    pub fn enclosed_volume(&self) -> Result<f64, SurfaceError> {
        self.check()?;
        use crate::wide::{cross, difference, dot, Wide};
        // Measured from the first vertex, in wide floats (the plain bits where nothing over- or
        // underflows).
        let o = self.positions.first().copied().unwrap_or_default();
        let p = |i: u32| difference(self.positions[i as usize], o);
        let triple = |&[a, b, c]: &[u32; 3]| dot(p(a), cross(p(b), p(c)));
        // A fold from +0.0: no triangles measure +0.0.
        let sum = self.triangles.iter().map(triple).fold(Wide::new(0.0), Wide::add);
        Ok(sum.div(Wide::new(6.0)).to_f64())
    }

    /// Total area of the triangles, each by the scale-safe [`crate::mesh::triangle_area`] (a
    /// cube of side 1e-90 measures 6e-180, one of side 1e80 6e160), +0.0 for none.
    /// O(vertices + triangles), including the check.
    ///
    /// # Errors
    /// As [`Surface::check`]: [`SurfaceError::VertexOutOfRange`] naming the first triangle corner
    /// past the vertices, [`SurfaceError::RepeatedCorner`] naming a degenerate triangle,
    /// [`SurfaceError::NonFinitePosition`] naming a non-finite vertex.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::surface::boundary_surface_of_tets;
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let mut s = boundary_surface_of_tets(&points, &tets).unwrap();
    /// assert_eq!(s.triangles.len(), 12);
    /// assert!((s.area().unwrap() - 6.0).abs() < 1e-12);
    /// s.triangles.push([0, 1, 8]);
    /// assert!(s.area().is_err()); // vertex 8 of 8
    /// ```
    pub fn area(&self) -> Result<f64, SurfaceError> {
        self.check()?;
        let p = |i: u32| self.positions[i as usize];
        let area = |&[a, b, c]: &[u32; 3]| triangle_area(p(a), p(b), p(c));
        // A fold from +0.0, not `sum` (which starts at −0.0): no triangles measure +0.0.
        Ok(self.triangles.iter().map(area).fold(0.0, |sum, a| sum + a))
    }

    /// The surface as Wavefront OBJ text: a comment header, one `v x y z` line per vertex
    /// (shortest round-trip decimal form), one `f i j k` line per triangle (1-based indices, in
    /// the triangle's outward orientation). O(vertices + triangles), including the check.
    ///
    /// [`crate::io::parse_obj`] reads it back bit for bit (same positions, same triangles) when
    /// the surface is one the mesh reader accepts: non-empty, and without two triangles on the
    /// same three vertices. Two surfaces that pass the check are written but not read back:
    /// - a body with a dissociated face whose corners did not split (an inner face cut alone:
    ///   its vertices and edges stay whole) has both sides of the cut on its boundary, two
    ///   coincident triangles of opposite orientation (a slit), which `parse_obj` refuses as a
    ///   duplicate (`ReadError::DuplicateElement`);
    /// - an empty surface (no tets, or every volume removed) writes a header-only file, which
    ///   `parse_obj` refuses as an empty mesh.
    ///
    /// Both are legitimate boundaries of cut bodies (the demo writes them), so they are written.
    ///
    /// # Errors
    /// As [`Surface::check`]: [`SurfaceError::VertexOutOfRange`] naming the first triangle corner
    /// past the vertices (a face with no vertex is not written), [`SurfaceError::RepeatedCorner`]
    /// naming a degenerate triangle and [`SurfaceError::NonFinitePosition`] naming a NaN or
    /// infinite vertex (both of which the OBJ reader would refuse).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::surface::{boundary_surface_of_tets, SurfaceError};
    ///
    /// let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mut s = boundary_surface_of_tets(&points, &[[0, 1, 2, 3]]).unwrap();
    /// let obj = s.to_obj().unwrap();
    /// assert_eq!(obj.lines().filter(|l| l.starts_with("v ")).count(), 4);
    /// assert_eq!(obj.lines().filter(|l| l.starts_with("f ")).count(), 4);
    /// s.positions.pop(); // vertex 3 is gone, the triangles still use it
    /// assert!(matches!(s.to_obj(), Err(SurfaceError::VertexOutOfRange { index: 3, vertices: 3, .. })));
    /// ```
    pub fn to_obj(&self) -> Result<String, SurfaceError> {
        self.check()?;
        let mut s = String::with_capacity(40 * self.positions.len() + 24 * self.triangles.len() + 128);
        let _ = writeln!(
            s,
            "# topomech boundary surface: {} vertices, {} triangles, outward counter-clockwise",
            self.positions.len(),
            self.triangles.len()
        );
        for p in &self.positions {
            let _ = writeln!(s, "v {} {} {}", p[0], p[1], p[2]);
        }
        for t in &self.triangles {
            let _ = writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
        }
        Ok(s)
    }

    /// Writes [`Surface::to_obj`] to `path` atomically (a temporary file in the same directory,
    /// then a rename: see [`crate::store::write_atomically`]). O(vertices + triangles).
    ///
    /// # Errors
    /// [`SurfaceError::VertexOutOfRange`], [`SurfaceError::RepeatedCorner`] and
    /// [`SurfaceError::NonFinitePosition`] as [`Surface::to_obj`], checked before anything is written (no file is created or replaced);
    /// [`SurfaceError::Write`] naming `path`.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::surface::boundary_surface_of_tets;
    ///
    /// let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mut s = boundary_surface_of_tets(&points, &[[0, 1, 2, 3]]).unwrap();
    /// let path = std::env::temp_dir().join(format!("topomech_doc_{}.obj", std::process::id()));
    /// s.write_obj(&path).unwrap();
    /// assert_eq!(std::fs::read_to_string(&path).unwrap(), s.to_obj().unwrap());
    /// std::fs::remove_file(&path).unwrap();
    /// assert!(s.write_obj(std::path::Path::new("/nonexistent-dir/x.obj")).is_err());
    /// s.triangles.push([0, 1, 999]);
    /// assert!(s.write_obj(&path).is_err() && !path.exists()); // refused before writing
    /// ```
    pub fn write_obj(&self, path: &Path) -> Result<(), SurfaceError> {
        let text = self.to_obj()?;
        crate::store::write_atomically(path, text.as_bytes())
            .map_err(|source| SurfaceError::Write { path: path.to_path_buf(), source })
    }
}
