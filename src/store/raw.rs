//! The raw arrays a file holds, and their conversion from and to the kernel's types.

use crate::embedding::CellArray;
use crate::mechanics::{Material, Mechanics, Vec3};
use crate::{DartId, GMap};

use super::StoreError;

/// The allocator of one cell dimension: ids `0..next` were handed out, those in `free` are dead
/// (the last one is reused first).
///
/// # Examples
///
/// ```
/// use topomech::store::RawMap;
/// use topomech::GMap;
///
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let raw = RawMap::from_map(&map);
/// assert_eq!(raw.ids.len(), 4); // one allocator per cell dimension 0..=3
/// let nexts: Vec<u32> = raw.ids.iter().map(|a| a.next).collect();
/// assert_eq!(nexts, vec![4, 6, 4, 1]); // a tet: 4 vertices, 6 edges, 4 faces, 1 volume
/// assert!(raw.ids.iter().all(|a| a.free.is_empty()));
/// ```
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct IdAllocRecord {
    /// One past the largest id ever handed out.
    pub next: u32,
    /// Dead ids, in reuse order.
    pub free: Vec<u32>,
}

/// Every slot of a map, live or dead: what a file stores.
///
/// Row d of `alpha` / `cell` is `[d·(n+1), (d+1)·(n+1))`. A dead slot (listed in `free_darts`)
/// has `alpha = d` and `cell = u32::MAX` in every column.
///
/// # Examples
///
/// ```
/// use topomech::store::RawMap;
/// use topomech::GMap;
///
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let raw = RawMap::from_map(&map);
/// let n1 = raw.dimension + 1;
/// assert_eq!((raw.alpha.len(), raw.cell.len()), (24 * n1, 24 * n1));
/// let d = 5;
/// assert_eq!(raw.alpha[raw.alpha[d * n1] as usize * n1], d as u32); // α0 is an involution
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RawMap {
    /// The dimension n.
    pub dimension: usize,
    /// Number of dart slots.
    pub capacity: u32,
    /// αi of every slot, row-major.
    pub alpha: Vec<u32>,
    /// The i-cell id of every slot, row-major.
    pub cell: Vec<u32>,
    /// Dead slots, in reuse order (the last one is reused first).
    pub free_darts: Vec<u32>,
    /// One allocator per cell dimension 0..=n.
    pub ids: Vec<IdAllocRecord>,
}

/// The unset cell id of a dead slot.
pub(crate) const UNSET: u32 = u32::MAX;

impl RawMap {
    /// Copies every slot of `map`. O(capacity · n).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::GMap;
    /// # use topomech::store::RawMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let raw = RawMap::from_map(&map);
    /// assert_eq!((raw.dimension, raw.capacity, raw.alpha.len()), (3, 24, 24 * 4));
    /// assert!(raw.free_darts.is_empty());
    /// ```
    pub fn from_map<const N: usize>(map: &GMap<N>) -> Self {
        let cap = map.capacity();
        let mut alpha = Vec::with_capacity(cap * (N + 1));
        let mut cell = Vec::with_capacity(cap * (N + 1));
        for d in 0..cap as u32 {
            let dart = DartId(d);
            let live = map.contains(dart);
            for i in 0..=N {
                alpha.push(if live { map.alpha_dyn(i, dart).0 } else { d });
                cell.push(if live { map.cell_id(i, dart).0 } else { UNSET });
            }
        }
        let ids = (0..=N)
            .map(|i| {
                let (next, free) = map.id_alloc_raw(i);
                IdAllocRecord { next, free: free.to_vec() }
            })
            .collect();
        RawMap { dimension: N, capacity: cap as u32, alpha, cell, free_darts: map.free_dart_slots_raw().to_vec(), ids }
    }

    /// Number of involutions, n + 1.
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::GMap;
    /// # use topomech::store::RawMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// assert_eq!(RawMap::from_map(&map).alphas(), 4);
    /// ```
    pub fn alphas(&self) -> usize {
        self.dimension + 1
    }

    /// Liveness of every slot (false for the slots of `free_darts`). O(capacity).
    ///
    /// # Panics
    /// If a free dart slot is not below `capacity` ([`RawMap::check`] refuses such a map; a
    /// decoded one never has it).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::GMap;
    /// # use topomech::store::RawMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let live = RawMap::from_map(&map).live();
    /// assert_eq!(live.len(), 24);
    /// assert!(live.iter().all(|&l| l));
    /// ```
    pub fn live(&self) -> Vec<bool> {
        let mut live = vec![true; self.capacity as usize];
        for &d in &self.free_darts {
            live[d as usize] = false;
        }
        live
    }

    /// αi of slot d. O(1). Panics if d or i is out of range (the decoder guarantees neither is).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::GMap;
    /// # use topomech::{store::RawMap, DartId};
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let raw = RawMap::from_map(&map);
    /// for d in 0..24 {
    ///     assert_eq!(raw.alpha(2, d), map.alpha_dyn(2, DartId(d)).0);
    /// }
    /// ```
    pub fn alpha(&self, i: usize, d: u32) -> u32 {
        self.alpha[d as usize * self.alphas() + i]
    }

    /// The i-cell id of slot d. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::GMap;
    /// # use topomech::{store::RawMap, DartId};
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let raw = RawMap::from_map(&map);
    /// for d in 0..24 {
    ///     assert_eq!(raw.cell(0, d) as usize, map.vertex_id(DartId(d)).index());
    /// }
    /// ```
    pub fn cell(&self, i: usize, d: u32) -> u32 {
        self.cell[d as usize * self.alphas() + i]
    }

    /// Checks the structure [`decode`](super::decode) guarantees of every map it returns, for a map
    /// built or changed in memory (the fields are public): a dimension in 1..=[`MAX_DIMENSION`],
    /// `alpha` and `cell` of `capacity · (n + 1)` entries, one allocator per dimension, every link
    /// a dart slot, free dart slots in range, listed once and blank, free cell ids below `next`
    /// and listed once, at most `capacity` live ids per dimension. The laws are not checked
    /// ([`Document::into_map`](super::Document::into_map) does). [`encode`](super::encode), the
    /// `into_*` conversions and [`check_all_laws`](super::check_all_laws) call it first.
    /// O(capacity · n + free ids).
    ///
    /// [`MAX_DIMENSION`]: super::MAX_DIMENSION
    ///
    /// # Errors
    /// [`StoreError::BadDimension`], [`StoreError::BadCount`] (a capacity of `u32::MAX`),
    /// [`StoreError::Inconsistent`] (array lengths, allocators, free lists),
    /// [`StoreError::DartOutOfRange`], each located at [`Where::Document`](super::Where::Document).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::GMap;
    /// # use topomech::store::{RawMap, StoreError};
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let mut raw = RawMap::from_map(&map);
    /// assert!(raw.check().is_ok());
    /// raw.alpha[5] = 24; // one past the last dart slot
    /// assert!(matches!(raw.check(), Err(StoreError::DartOutOfRange { dart: 24, capacity: 24, .. })));
    /// raw.alpha.pop();
    /// assert!(raw.check().unwrap_err().to_string().contains("the alpha array has 95 entries"));
    /// ```
    pub fn check(&self) -> Result<(), StoreError> {
        super::structure::check_shape(self)
    }

    /// Rebuilds the map exactly, with no law checked (the crate-private raw layer). O(capacity · n).
    /// The structure must be one [`RawMap::check`] accepts (a decoded map's always is), else this
    /// may panic on an index.
    ///
    /// # Errors
    /// [`StoreError::WrongDimension`] when the file's dimension is not `N`.
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::GMap;
    /// # use topomech::store::RawMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let raw = RawMap::from_map(&map);
    /// assert!(topomech::ops::same_raw(&raw.to_gmap_raw::<3>().unwrap(), &map));
    /// assert!(raw.to_gmap_raw::<2>().is_err());
    /// ```
    pub fn to_gmap_raw<const N: usize>(&self) -> Result<GMap<N>, StoreError> {
        if self.dimension != N {
            return Err(StoreError::WrongDimension { found: self.dimension, expected: N });
        }
        let mut map = GMap::<N>::new();
        map.alloc_darts_raw(self.capacity as usize);
        let live = self.live();
        // One-sided writes: a broken file stays broken (no partner row is touched).
        for d in (0..self.capacity).filter(|&d| live[d as usize]) {
            for i in 0..=N {
                map.set_alpha_raw(i, DartId(d), DartId(self.alpha(i, d)));
                map.set_cell_raw(i, DartId(d), self.cell(i, d));
            }
        }
        for &d in &self.free_darts {
            map.kill_dart_raw(DartId(d));
        }
        for (i, rec) in self.ids.iter().enumerate() {
            map.set_id_alloc_raw(i, rec.next, rec.free.clone());
        }
        Ok(map)
    }
}

/// The attributes of one vertex id.
///
/// # Examples
///
/// ```
/// use topomech::mechanics::{Body, Material};
/// use topomech::store::RawMechanics;
///
/// let (points, tets) = topomech::generate::kuhn_cube(1);
/// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let raw = RawMechanics::from_mechanics(body.attrs());
/// let v = raw.vertices[7];
/// assert_eq!((v.rest, v.position, v.velocity), (points[7], points[7], [0.0; 3])); // at rest
/// assert!(v.mass > 0.0 && !v.pinned);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct VertexRecord {
    /// Rest position.
    pub rest: Vec3,
    /// Current position.
    pub position: Vec3,
    /// Current velocity.
    pub velocity: Vec3,
    /// Last force accumulator.
    pub force: Vec3,
    /// Mass m_v.
    pub mass: f64,
    /// Ambient viscosity γ_v.
    pub viscosity: f64,
    /// Fixed vertex.
    pub pinned: bool,
}

impl VertexRecord {
    /// The record of the 14 numbers a store file holds per vertex, in file order: rest,
    /// position, velocity and force (x, y, z each), then mass and viscosity. O(1).
    pub(crate) fn from_attributes(xs: &[f64; 14], pinned: bool) -> VertexRecord {
        let v3 = |o: usize| [xs[o], xs[o + 1], xs[o + 2]];
        VertexRecord {
            rest: v3(0),
            position: v3(3),
            velocity: v3(6),
            force: v3(9),
            mass: xs[12],
            viscosity: xs[13],
            pinned,
        }
    }
}

/// Every mechanical attribute of a body, one record per cell id (live or dead).
///
/// # Examples
///
/// ```
/// use topomech::mechanics::{Body, Material};
/// use topomech::store::RawMechanics;
///
/// let (points, tets) = topomech::generate::kuhn_cube(1);
/// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let raw = RawMechanics::from_mechanics(body.attrs());
/// assert_eq!(raw.material[0], Material::default().density);
/// assert_eq!((raw.vertices.len(), raw.volumes.len()), (8, 6));
/// assert_eq!(raw.faces.iter().filter(|f| f.0).count(), 12); // boundary faces
/// ```
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RawMechanics {
    /// Density ρ, Young's modulus E, damping β, viscosity ν.
    pub material: [f64; 4],
    /// Per vertex id.
    pub vertices: Vec<VertexRecord>,
    /// Per edge id: rest length, stiffness, damping.
    pub edges: Vec<[f64; 3]>,
    /// Per face id: boundary flag and outward normal.
    pub faces: Vec<(bool, Vec3)>,
    /// Per volume id: rest volume, mass, Young's modulus.
    pub volumes: Vec<[f64; 3]>,
}

/// Copies `len` values of a cell array, the default past its end (arrays of one dimension are
/// grown together, so this only pads arrays a caller shortened by hand).
fn column<T: Copy + Default>(a: &CellArray<T>, len: usize) -> impl Iterator<Item = T> + '_ {
    (0..len).map(move |k| a.as_slice().get(k).copied().unwrap_or_default())
}

impl RawMechanics {
    /// Copies every attribute. O(cells).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::mechanics::{Body, Material};
    /// # use topomech::store::RawMechanics;
    /// let (points, tets) = topomech::generate::kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let raw = RawMechanics::from_mechanics(body.attrs());
    /// let vertex_mass: f64 = raw.vertices.iter().map(|v| v.mass).sum();
    /// let tet_mass: f64 = raw.volumes.iter().map(|t| t[1]).sum();
    /// assert!(tet_mass > 0.0 && (vertex_mass - tet_mass).abs() < 1e-12 * tet_mass);
    /// ```
    pub fn from_mechanics(m: &Mechanics) -> Self {
        let Material { density, young, damping, viscosity } = m.material;
        let nv = m.vertex_mass.len().max(m.position.len());
        let mut vertices: Vec<VertexRecord> = Vec::with_capacity(nv);
        let cols = (
            column(&m.rest_position, nv),
            column(&m.position, nv),
            column(&m.velocity, nv),
            column(&m.force, nv),
            column(&m.vertex_mass, nv),
            column(&m.vertex_viscosity, nv),
            column(&m.pinned, nv),
        );
        let (r, p, v, f, ma, vi, pi) = cols;
        for ((((((rest, position), velocity), force), mass), visc), pinned) in
            r.zip(p).zip(v).zip(f).zip(ma).zip(vi).zip(pi)
        {
            vertices.push(VertexRecord { rest, position, velocity, force, mass, viscosity: visc, pinned });
        }
        let ne = m.edge_stiffness.len();
        let edges = column(&m.edge_rest_length, ne)
            .zip(column(&m.edge_stiffness, ne))
            .zip(column(&m.edge_damping, ne))
            .map(|((l, k), c)| [l, k, c])
            .collect();
        let nf = m.face_normal.len();
        let faces = column(&m.face_boundary, nf).zip(column(&m.face_normal, nf)).collect();
        let nt = m.tet_mass.len();
        let volumes = column(&m.tet_rest_volume, nt)
            .zip(column(&m.tet_mass, nt))
            .zip(column(&m.tet_young, nt))
            .map(|((v, ma), e)| [v, ma, e])
            .collect();
        RawMechanics { material: [density, young, damping, viscosity], vertices, edges, faces, volumes }
    }

    /// Blanks the records of every id `map` lists as dead (its allocators' free lists): zero
    /// numbers, not pinned, not boundary; and drops the records past the ids it handed out
    /// (attributes longer than the map, which `Body::new` accepts). No cell reads those
    /// attributes, so a value left there (even a NaN) is not the body's state and is not
    /// written (findings 257 and round 28's); two bodies that differ only there give the same
    /// file. O(dead ids + dropped records).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::cut::remove_volume;
    /// use topomech::mechanics::{Body, Material};
    /// use topomech::store::{RawMap, RawMechanics};
    /// use topomech::CellId;
    ///
    /// let (points, tets) = topomech::generate::kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// remove_volume(&mut body, CellId(0)).unwrap();
    /// let mut raw = RawMechanics::from_mechanics(body.attrs());
    /// assert!(raw.volumes[0][1] > 0.0); // the removed tet's mass is still in its dead slot
    /// raw.blank_dead(&RawMap::from_map(body.map()));
    /// assert_eq!(raw.volumes[0], [0.0; 3]);
    /// ```
    pub fn blank_dead(&mut self, map: &RawMap) {
        let bound = |dim: usize| map.ids.get(dim).map_or(usize::MAX, |a| a.next as usize);
        self.vertices.truncate(bound(0));
        self.edges.truncate(bound(1));
        self.faces.truncate(bound(2));
        self.volumes.truncate(bound(3));
        let free = |dim: usize| map.ids.get(dim).into_iter().flat_map(|a| a.free.iter().map(|&id| id as usize));
        for id in free(0) {
            self.vertices.get_mut(id).into_iter().for_each(|r| *r = VertexRecord::default());
        }
        for id in free(1) {
            self.edges.get_mut(id).into_iter().for_each(|r| *r = [0.0; 3]);
        }
        for id in free(2) {
            self.faces.get_mut(id).into_iter().for_each(|r| *r = (false, [0.0; 3]));
        }
        for id in free(3) {
            self.volumes.get_mut(id).into_iter().for_each(|r| *r = [0.0; 3]);
        }
    }

    /// Rebuilds the attributes exactly (no law checked). O(cells).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::mechanics::{Body, Material};
    /// # use topomech::store::RawMechanics;
    /// let (points, tets) = topomech::generate::kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let raw = RawMechanics::from_mechanics(body.attrs());
    /// assert_eq!(RawMechanics::from_mechanics(&raw.to_mechanics()), raw);
    /// ```
    pub fn to_mechanics(&self) -> Mechanics {
        let [density, young, damping, viscosity] = self.material;
        let vs = &self.vertices;
        let col = |f: &dyn Fn(&VertexRecord) -> Vec3| CellArray::from_vec(vs.iter().map(f).collect());
        let scalar = |f: &dyn Fn(&VertexRecord) -> f64| CellArray::from_vec(vs.iter().map(f).collect());
        let edge = |k: usize| CellArray::from_vec(self.edges.iter().map(|e| e[k]).collect());
        let tet = |k: usize| CellArray::from_vec(self.volumes.iter().map(|t| t[k]).collect());
        Mechanics {
            material: Material { density, young, damping, viscosity },
            tet_rest_volume: tet(0),
            tet_mass: tet(1),
            tet_young: tet(2),
            edge_rest_length: edge(0),
            edge_stiffness: edge(1),
            edge_damping: edge(2),
            face_boundary: CellArray::from_vec(self.faces.iter().map(|f| f.0).collect()),
            face_normal: CellArray::from_vec(self.faces.iter().map(|f| f.1).collect()),
            vertex_mass: scalar(&|v| v.mass),
            vertex_viscosity: scalar(&|v| v.viscosity),
            rest_position: col(&|v| v.rest),
            position: col(&|v| v.position),
            velocity: col(&|v| v.velocity),
            force: col(&|v| v.force),
            pinned: CellArray::from_vec(vs.iter().map(|v| v.pinned).collect()),
            pins_epoch: 0,
            velocity_epoch: 0,
            position_epoch: 0,
            instance: crate::mechanics::model::Instance::fresh(),
        }
    }

    /// `Err(description)` naming the first NaN or infinite value. O(cells).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::mechanics::{Body, Material};
    /// # use topomech::store::RawMechanics;
    /// let (points, tets) = topomech::generate::kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let mut raw = RawMechanics::from_mechanics(body.attrs());
    /// assert!(raw.check_finite().is_ok());
    /// raw.vertices[2].mass = f64::INFINITY;
    /// assert!(raw.check_finite().unwrap_err().contains("record 2"));
    /// ```
    pub fn check_finite(&self) -> Result<(), String> {
        match self.first_non_finite() {
            Some((what, k)) => Err(format!("{what} of record {k} is not finite")),
            None => Ok(()),
        }
    }

    /// The attribute and record of the first NaN or infinite value. O(cells).
    pub(crate) fn first_non_finite(&self) -> Option<(&'static str, usize)> {
        if self.material.iter().any(|x| !x.is_finite()) {
            return Some(("material", 0));
        }
        for (k, v) in self.vertices.iter().enumerate() {
            let all =
                v.rest.iter().chain(&v.position).chain(&v.velocity).chain(&v.force).chain([&v.mass, &v.viscosity]);
            if all.into_iter().any(|x| !x.is_finite()) {
                return Some(("a vertex attribute", k));
            }
        }
        if let Some(k) = self.edges.iter().position(|e| e.iter().any(|x| !x.is_finite())) {
            return Some(("an edge attribute", k));
        }
        if let Some(k) = self.faces.iter().position(|f| f.1.iter().any(|x| !x.is_finite())) {
            return Some(("a face normal", k));
        }
        self.volumes.iter().position(|t| t.iter().any(|x| !x.is_finite())).map(|k| ("a volume attribute", k))
    }
}
