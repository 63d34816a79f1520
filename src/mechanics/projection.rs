//! The indexed projection of a [`Body`] (seed 000 §5.2): flat arrays for the step loop, built from
//! the map after topological changes, each entry knowing its cell and a dart.
//!
//! ```text
//!   map (topology, cell ids)  ──build/rebuild──▶  SpringSystem: ends[s] = (v_a, v_b), L, k, c
//!   Mechanics (embeddings)                        mass/inv_mass/viscosity per vertex slot
//!        ▲  positions, velocities: the SAME arrays (slot = vertex id), no copy, no write-back
//!        └───────────────────────── step loop reads/writes them directly
//! ```
//!
//! Vertex slots *are* vertex ids: the integrator advances the body's `position` and `velocity`
//! embeddings in place, so they are never stale. Dead or free vertex ids are fixed slots
//! (`inv_mass = 0`, no spring). Springs are one per live edge, sorted by their end ids for memory
//! locality; `spring_edge[s]` / `spring_dart[s]` give the edge and a dart of spring s, and
//! [`Projection::spring_of_edge`] the way back. Spring parameters and per-vertex masses are
//! copied in; they change only through topological operations, after which the projection is
//! stale ([`Projection::is_current`] compares the body's version, and its identity: a
//! projection of another body, or of a clone, is never current) and must be rebuilt or updated
//! (below).
//!
//! # Incremental update
//! [`Projection::update`] applies a topological operation's [`TouchedCells`] (the vertex and edge
//! ids it split, merged, renamed the ends of, or deleted, each with a dart of the cell now):
//! per-vertex values of those slots are re-read, springs of split edges are appended, springs of
//! deleted edges are swap-removed, springs whose end vertex got a new id get their ends fixed.
//! The incidence lists inside [`SpringSystem`] follow through its mutators (`push_slot`,
//! `push_spring`, `set_spring`, `swap_remove_spring`), each O(degree of the ends involved), so the
//! whole update costs O(touched cells · degree) (amortised; plus the slots for new ids), with no
//! pass over the mesh.
//! Spring order differs from a fresh build (appended, not sorted), so the two are compared with
//! [`Projection::equivalent`], cell by cell.
//!
//! The lists are stamped with the versions of the body they cover (the operations of
//! `crate::cut` do it, [`TouchedCells::extend`] joins consecutive ones,
//! [`TouchedCells::record_change`] stamps one sew or unsew of [`Body`]), and an update applies
//! them only when they take the projection from its version to the body's; a missed, repeated,
//! reordered or hand-made list makes it rebuild instead, so a projection that says it is
//! current always is.
//!
//! [`forces_by_coverage`] computes the same forces the paper's first way, by covering the
//! map's edges and vertices with a dart set: the reference the projection is tested against.

use crate::gmap::{CellChanges, DartSet};
use crate::{AlphaMask, CellId, DartId, GMap};

use super::force::{spring_force, IncidenceError, SpringSystem, SystemError};
use super::geom::Vec3;
use super::model::{Body, Mechanics};

/// See the [module docs](self).
///
/// # Examples
///
/// ```
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Material, Projection};
///
/// let (points, tets) = kuhn_cube(1);
/// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let p = Projection::build(&body, [0.0, 0.0, -9.81]).unwrap();
/// let cells = body.map().count_cells();
/// assert_eq!((p.system().slots(), p.system().springs()), (cells.0[0], cells.0[1])); // vertices, edges
/// assert_eq!(p.system().gravity(), [0.0, 0.0, -9.81]);
/// assert_eq!(p.version(), body.version());
/// ```
#[derive(Clone, Debug)]
pub struct Projection {
    /// The arrays the step loop reads: private, so that they cannot fall out of step with the
    /// spring ↔ edge and slot ↔ vertex tables beside them (finding 34); read with
    /// [`Projection::system`].
    pub(crate) system: SpringSystem,
    spring_edge: Vec<CellId>,
    spring_dart: Vec<DartId>,
    edge_spring: Vec<u32>,
    vertex_dart: Vec<Option<DartId>>,
    version: u64,
    /// The body's pin epoch (`Mechanics::pins_epoch`) its fixed slots were read at.
    pins_epoch: u64,
    /// The [`Body::identity`] of the body it was built from.
    body: u64,
    /// The instance of that body's attributes (`Mechanics::instance`): a body cannot have its
    /// attributes replaced since round 27 ([`crate::mechanics::AttrsMut`]); kept as a defence.
    attrs: u64,
    /// The lists of [`Resolved::of`], kept between updates.
    scratch: Resolved,
}

impl Projection {
    /// Projects `body` with gravity `gravity`. O(darts + E log E).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material, Projection};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let p = Projection::build(&body, [0.0, 0.0, -9.81]).unwrap();
    /// assert_eq!((p.system().slots(), p.system().springs()), (8, 19));
    /// for s in 0..p.system().springs() {
    ///     assert_eq!(p.spring_of_edge(p.edge_of_spring(s)), Some(s));
    /// }
    /// assert!(p.is_current(&body));
    /// ```
    pub fn build(body: &Body, gravity: Vec3) -> Result<Self, SystemError> {
        if gravity.iter().any(|g| !g.is_finite()) {
            return Err(SystemError::BadGravity(gravity));
        }
        body.attrs().check_covers(body.map()).map_err(SystemError::Attributes)?;
        Ok(Projection::build_raw(body, gravity))
    }

    /// [`Projection::build`] with a gravity known to be finite. O(darts + E log E).
    pub(crate) fn build_raw(body: &Body, gravity: Vec3) -> Self {
        let map = body.map();
        let mech = body.attrs();
        let n = map.cell_id_bound(0);
        let mut vertex_dart = vec![None; n];
        for d in map.one_dart_per_cell(0) {
            vertex_dart[map.vertex_id(d).index()] = Some(d);
        }
        let mut springs: Vec<([u32; 2], DartId)> = map
            .one_dart_per_cell(1)
            .into_iter()
            .map(|d| {
                let (a, b) = (map.vertex_id(d).0, map.vertex_id(map.alpha::<0>(d)).0);
                ([a.min(b), a.max(b)], d)
            })
            .collect();
        springs.sort_unstable_by_key(|&(ends, d)| (ends, d));
        let spring_dart: Vec<DartId> = springs.iter().map(|&(_, d)| d).collect();
        let spring_edge: Vec<CellId> = spring_dart.iter().map(|&d| map.cell_id(1, d)).collect();
        let mut edge_spring = vec![u32::MAX; map.cell_id_bound(1)];
        for (s, e) in spring_edge.iter().enumerate() {
            edge_spring[e.index()] = s as u32;
        }
        let system = system_of(mech, &springs, &spring_edge, &vertex_dart, gravity);
        Projection {
            system,
            spring_edge,
            spring_dart,
            edge_spring,
            vertex_dart,
            version: body.version(),
            pins_epoch: mech.pins_epoch,
            body: body.identity(),
            attrs: mech.instance.id,
            scratch: Resolved::default(),
        }
    }

    /// The arrays the step loop reads (springs as index pairs and parameters, per-slot masses),
    /// read-only: they change only with the body, through [`Projection::update`] and
    /// [`Projection::rebuild`]. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material, Projection};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let p = Projection::build(&body, [0.0, 0.0, -9.81]).unwrap();
    /// let (x, v) = (body.attrs().position().as_slice(), body.attrs().velocity().as_slice());
    /// let (mut sf, mut f) = (vec![[0.0; 3]; p.system().springs()], vec![[0.0; 3]; p.system().slots()]);
    /// p.system().forces(x, v, &mut sf, &mut f, false).unwrap();
    /// let weight: f64 = f.iter().map(|f| f[2]).sum(); // springs at rest: only gravity
    /// assert!((weight + 9.81 * body.total_vertex_mass()).abs() < 1e-12);
    /// ```
    ///
    /// Changing them from outside would leave the tables beside them wrong, so it does not
    /// compile:
    ///
    /// ```compile_fail
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material, Projection};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let mut p = Projection::build(&body, [0.0; 3]).unwrap();
    /// p.system.swap_remove_spring(0).unwrap(); // private field
    /// ```
    pub fn system(&self) -> &SpringSystem {
        &self.system
    }

    /// Rebuilds from scratch after topological changes (keeps the gravity). O(darts + E log E).
    ///
    /// # Panics
    /// If the body's attributes do not cover its map, which no body built and changed through
    /// the public API has (attributes can no longer be replaced whole since round 27;
    /// [`Projection::build`] returns the error instead).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::cut::remove_volume;
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material, Projection};
    /// use topomech::CellId;
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let mut p = Projection::build(&body, [0.0; 3]).unwrap();
    /// remove_volume(&mut body, CellId(0)).unwrap();
    /// assert!(!p.is_current(&body));
    /// p.rebuild(&body);
    /// assert_eq!((p.version(), p.system().springs()), (body.version(), body.map().count_cells().0[1]));
    /// ```
    pub fn rebuild(&mut self, body: &Body) {
        *self = Projection::build_raw(body, self.system.gravity);
    }

    /// Whether the body has not changed since the projection was built: no topological change,
    /// and its pins not handed out for writing ([`crate::mechanics::Mechanics::pinned_mut`],
    /// [`crate::mechanics::Mechanics::pin_where`]: the fixed slots may differ). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::cut::dissociate_face;
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material, Projection};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let mut p = Projection::build(&body, [0.0; 3]).unwrap();
    /// let d = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
    /// let cut = dissociate_face(&mut body, d).unwrap();
    /// assert!(!p.is_current(&body) && !cut.touched.is_empty());
    /// p.update(&body, &cut.touched);
    /// assert!(p.is_current(&body));
    /// ```
    pub fn is_current(&self, body: &Body) -> bool {
        self.is_for(body) && self.version == body.version() && self.pins_current(body)
    }

    /// Whether the fixed slots were read at the body's current pin epoch. O(1).
    pub(crate) fn pins_current(&self, body: &Body) -> bool {
        self.pins_epoch == body.attrs().pins_epoch
    }

    /// The slots' inverse masses and the pin epoch as they are, for
    /// [`Projection::restore_pins`] when what follows [`Projection::follow_pins`] is refused
    /// (finding 203). O(slots).
    pub(crate) fn pin_snapshot(&self) -> (Vec<f64>, u64) {
        (self.system.inv_mass.clone(), self.pins_epoch)
    }

    /// Puts back what [`Projection::pin_snapshot`] took: [`Projection::follow_pins`] changes
    /// only the inverse masses (the masses and viscosities it writes are the ones there, the
    /// projection being current) and the epoch. O(slots).
    pub(crate) fn restore_pins(&mut self, (inv_mass, epoch): (Vec<f64>, u64)) {
        self.system.inv_mass = inv_mass;
        self.pins_epoch = epoch;
    }

    /// Re-reads every live vertex's pin into its slot (fixed or not; mass and viscosity as
    /// they are), after the pins were handed out for writing. O(slots).
    pub(crate) fn follow_pins(&mut self, body: &Body) {
        let mech = body.attrs();
        for (v, d) in self.vertex_dart.iter().enumerate() {
            if d.is_some() {
                let id = CellId(v as u32);
                self.system.set_slot_raw(v, mech.vertex_mass(id), mech.pinned[id], mech.vertex_viscosity(id));
            }
        }
        self.pins_epoch = mech.pins_epoch;
    }

    /// Whether the projection was built from `body` (and not from another body, or a clone of
    /// it: [`Body::identity`]), with the attributes it has now (each `Mechanics` value has its
    /// own instance stamp; round 26: attributes replaced as a whole made it say it was current
    /// with another body's masses — since round 27 a body's attributes cannot be replaced).
    /// O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material, Projection};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let p = Projection::build(&body, [0.0; 3]).unwrap();
    /// assert!(p.is_for(&body) && p.is_current(&body));
    /// let copy = body.clone();
    /// assert!(!p.is_for(&copy) && !p.is_current(&copy)); // same version, another body
    /// ```
    pub fn is_for(&self, body: &Body) -> bool {
        self.body == body.identity() && self.attrs == body.attrs().instance.id
    }

    /// The [`Body::identity`] of the body the projection was built from. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material, Projection};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// assert_eq!(Projection::build(&body, [0.0; 3]).unwrap().body_identity(), body.identity());
    /// ```
    pub fn body_identity(&self) -> u64 {
        self.body
    }

    /// A copy of this projection for `copy`, a clone of `original` taken while this projection
    /// was current for it (same map, attributes and version): the copy's arrays are the same,
    /// only the body it answers for changes. `None` unless the projection is current for
    /// `original` and `copy` is a clone of `original` with no operation on either since
    /// ([`Body::clone`] records its source's identity and version), the same pins, and the
    /// attributes cloned with it. O(slots + springs)
    /// (the copy).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material, Projection};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let p = Projection::build(&body, [0.0; 3]).unwrap();
    /// let copy = body.clone();
    /// let q = p.for_clone(&body, &copy).unwrap();
    /// assert!(q.is_current(&copy) && !q.is_for(&body));
    /// assert!(p.for_clone(&copy, &body).is_none()); // p is not current for `copy`
    /// ```
    pub fn for_clone(&self, original: &Body, copy: &Body) -> Option<Projection> {
        let same_pins = copy.attrs().pins_epoch == original.attrs().pins_epoch;
        // The copy's attributes must be the clone of the ones this projection read, not put in
        // its place since (round 26).
        let same_attrs = copy.attrs().instance.from == self.attrs;
        if !self.is_current(original) || !copy.is_unchanged_clone_of(original) || !same_pins || !same_attrs {
            return None;
        }
        let mut out = self.clone();
        out.body = copy.identity();
        out.attrs = copy.attrs().instance.id;
        Some(out)
    }

    /// The body version the projection was built from. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material, Projection};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let d = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
    /// body.unsew3(d).unwrap();
    /// let p = Projection::build(&body, [0.0; 3]).unwrap();
    /// assert_eq!((p.version(), body.version()), (1, 1));
    /// ```
    pub fn version(&self) -> u64 {
        self.version
    }

    /// Applies the topological changes listed in `touched` (see the module docs, "Incremental
    /// update"): afterwards the projection is [`Projection::equivalent`] to a fresh
    /// [`Projection::build`] of `body` and [`Projection::is_current`] holds.
    /// Cost: O(touched cells · degree + new ids) amortised (see [`SpringSystem`]'s incidence
    /// lists); nothing proportional to the mesh, except that the pins are re-read for every slot
    /// (O(slots)) when they were handed out for writing since the projection last read them.
    /// Returns `true` for this incremental update (empty lists at the body's version take only
    /// the pins).
    ///
    /// `touched` must bring this projection to the body's version: the lists an operation of
    /// `crate::cut` returned, or several of them merged in order with [`TouchedCells::extend`]
    /// ([`TouchedCells::versions`] = (this projection's version, the body's version)). Anything
    /// else — a projection of another body ([`Projection::is_for`] false), a missed or repeated
    /// operation, lists filled by hand or by [`TouchedCells::record`] — cannot be trusted, and
    /// the projection is rebuilt from `body` instead (O(darts + E log E)); the result is `false`.
    /// Either way the projection ends current and equal to a fresh build.
    ///
    /// # Panics
    /// As [`Projection::rebuild`], when it rebuilds.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::cut::{incise_plane, Plane};
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material, Projection};
    ///
    /// let (points, tets) = kuhn_cube(2);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let mut p = Projection::build(&body, [0.0, 0.0, -9.81]).unwrap();
    /// let cut = incise_plane(&mut body, &Plane { point: [1.0; 3], normal: [1.0, 0.0, 0.0] }).unwrap();
    /// assert!(p.update(&body, &cut.touched)); // incremental
    /// assert!(p.is_current(&body));
    /// assert!(p.equivalent(&Projection::build(&body, [0.0, 0.0, -9.81]).unwrap()).is_ok());
    /// assert_eq!(p.system().slots(), body.map().cell_id_bound(0)); // new vertex ids got slots
    /// ```
    pub fn update(&mut self, body: &Body, touched: &TouchedCells) -> bool {
        let brings_up_to_date = match touched.span {
            Span::Versions { body: id, from, to } => {
                id == body.identity() && from == self.version && to == body.version()
            }
            Span::Nothing => touched.is_empty() && self.version == body.version(),
            Span::Unknown => false,
        };
        if !self.is_for(body) || !brings_up_to_date {
            // Built from another body, or records that do not take this projection to the body's
            // version (missed, repeated, hand-made): they cannot be trusted.
            self.rebuild(body);
            return false;
        }
        let map = body.map();
        let mech = body.attrs();
        let n = map.cell_id_bound(0);
        while self.system.slots() < n {
            self.system.push_slot_raw(0.0, true, 0.0);
            self.vertex_dart.push(None);
        }
        if self.edge_spring.len() < map.cell_id_bound(1) {
            self.edge_spring.resize(map.cell_id_bound(1), u32::MAX);
        }
        let mut resolved = std::mem::take(&mut self.scratch);
        for &(v, d) in resolved.of(map, 0, &touched.vertices) {
            self.vertex_dart[v.index()] = d;
            let (m, g) = if d.is_some() { (mech.vertex_mass(v), mech.vertex_viscosity(v)) } else { (0.0, 0.0) };
            let fixed = d.is_none() || mech.pinned[v];
            self.system.set_slot_raw(v.index(), m, fixed, g);
        }
        for &(e, d) in resolved.of(map, 1, &touched.edges) {
            match d {
                Some(d) => self.set_spring(map, mech, e, d),
                None => self.remove_spring(e),
            }
        }
        self.scratch = resolved;
        self.version = body.version();
        if !self.pins_current(body) {
            self.follow_pins(body); // the pins were handed out for writing: O(slots), only then
        }
        true
    }

    /// Writes (or appends) the spring of live edge `e`, a dart of which is `d`. O(degree of its
    /// old and new ends).
    fn set_spring(&mut self, map: &GMap<3>, mech: &Mechanics, e: CellId, d: DartId) {
        let (a, b) = (map.vertex_id(d).0, map.vertex_id(map.alpha::<0>(d)).0);
        let ends = [a.min(b), a.max(b)];
        let (rest, k, c) = (mech.edge_rest_length(e), mech.edge_stiffness(e), mech.edge_damping(e));
        match self.spring_of_edge(e) {
            Some(s) => {
                self.system.set_spring_raw(s, ends, rest, k, c);
                self.spring_dart[s] = d;
            }
            None => {
                let s = self.system.push_spring_raw(ends, rest, k, c);
                self.spring_edge.push(e);
                self.spring_dart.push(d);
                self.edge_spring[e.index()] = s as u32;
            }
        }
    }

    /// Swap-removes the spring of the dead edge `e`, if any. O(degree of the two springs' ends).
    fn remove_spring(&mut self, e: CellId) {
        let Some(s) = self.spring_of_edge(e) else { return };
        self.system.swap_remove_spring_raw(s);
        self.spring_dart.swap_remove(s);
        self.spring_edge.swap_remove(s);
        self.edge_spring[e.index()] = u32::MAX;
        if let Some(&moved) = self.spring_edge.get(s) {
            self.edge_spring[moved.index()] = s as u32;
        }
    }

    /// Whether `self` and `other` project the same body: same slots with the same mass, inverse
    /// mass, viscosity and liveness, and for every edge id the same spring (ends, rest length,
    /// stiffness, damping), whatever the spring order; and each side's incidence lists hold
    /// exactly its springs ([`SpringSystem::check_incidence`]). Values are compared bit for bit
    /// (both read the same stored attributes). O(slots + springs).
    ///
    /// # Errors
    /// The first [`ProjectionMismatch`] found.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material, Projection};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let a = Projection::build(&body, [0.0; 3]).unwrap();
    /// assert!(a.equivalent(&Projection::build(&body, [0.0; 3]).unwrap()).is_ok());
    /// assert!(a.equivalent(&Projection::build(&body, [0.0, 0.0, -1.0]).unwrap()).is_err()); // other gravity
    /// ```
    pub fn equivalent(&self, other: &Projection) -> Result<(), ProjectionMismatch> {
        let (a, b) = (&self.system, &other.system);
        a.check_incidence().map_err(ProjectionMismatch::Incidence)?;
        b.check_incidence().map_err(ProjectionMismatch::Incidence)?;
        if a.slots() != b.slots() || a.springs() != b.springs() || a.gravity != b.gravity {
            return Err(ProjectionMismatch::Sizes {
                slots: (a.slots(), b.slots()),
                springs: (a.springs(), b.springs()),
            });
        }
        for v in 0..a.slots() {
            let same = a.mass[v] == b.mass[v]
                && a.inv_mass[v] == b.inv_mass[v]
                && a.viscosity[v] == b.viscosity[v]
                && self.vertex_dart[v].is_some() == other.vertex_dart[v].is_some();
            if !same {
                return Err(ProjectionMismatch::Vertex { slot: v });
            }
        }
        for (s, &e) in self.spring_edge.iter().enumerate() {
            let Some(t) = other.spring_of_edge(e) else { return Err(ProjectionMismatch::Spring { edge: e }) };
            let same = a.ends[s] == b.ends[t]
                && a.rest[s] == b.rest[t]
                && a.stiffness[s] == b.stiffness[t]
                && a.damping[s] == b.damping[t];
            if !same {
                return Err(ProjectionMismatch::Spring { edge: e });
            }
        }
        Ok(())
    }

    /// The edge of spring s. O(1).
    ///
    /// # Panics
    /// If `s` is not below `self.system().springs()`.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material, Projection};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let p = Projection::build(&body, [0.0; 3]).unwrap();
    /// let mut edges: Vec<_> = (0..p.system().springs()).map(|s| p.edge_of_spring(s)).collect();
    /// edges.sort_unstable();
    /// edges.dedup();
    /// assert_eq!(edges.len(), 19); // one spring per edge, every edge once
    /// ```
    pub fn edge_of_spring(&self, s: usize) -> CellId {
        self.spring_edge[s]
    }

    /// A dart of spring s's edge; its vertex is one of the spring's two ends (either one: ends are
    /// stored as `[lo, hi]`). O(1).
    ///
    /// # Panics
    /// If `s` is not below `self.system().springs()`.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material, Projection};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let p = Projection::build(&body, [0.0; 3]).unwrap();
    /// let map = body.map();
    /// for s in 0..p.system().springs() {
    ///     let d = p.dart_of_spring(s);
    ///     assert_eq!(map.cell_id(1, d), p.edge_of_spring(s));
    ///     let [a, b] = p.system().ends()[s];
    ///     assert!(a < b && [a, b].contains(&map.vertex_id(d).0));
    ///     assert_eq!(map.vertex_id(map.alpha::<0>(d)).0, a + b - map.vertex_id(d).0); // α0: the other end
    /// }
    /// ```
    pub fn dart_of_spring(&self, s: usize) -> DartId {
        self.spring_dart[s]
    }

    /// The spring of edge `e`, if `e` is live. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::cut::remove_volume;
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material, Projection};
    /// use topomech::CellId;
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// remove_volume(&mut body, CellId(0)).unwrap(); // edge (1,0,0)–(1,1,0) was only in tet 0
    /// let (p, map) = (Projection::build(&body, [0.0; 3]).unwrap(), body.map());
    /// let live: Vec<CellId> = map.one_dart_per_cell(1).iter().map(|&d| map.cell_id(1, d)).collect();
    /// assert!(live.iter().all(|&e| p.spring_of_edge(e).is_some()) && p.system().springs() == live.len());
    /// let dead: Vec<CellId> = (0..map.cell_id_bound(1) as u32).map(CellId).filter(|e| !live.contains(e)).collect();
    /// assert!(!dead.is_empty() && dead.iter().all(|&e| p.spring_of_edge(e).is_none()));
    /// ```
    pub fn spring_of_edge(&self, e: CellId) -> Option<usize> {
        self.edge_spring.get(e.index()).filter(|&&s| s != u32::MAX).map(|&s| s as usize)
    }

    /// A dart of the vertex in slot `slot` (= vertex id), `None` for a dead id. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material, Projection};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let p = Projection::build(&body, [0.0; 3]).unwrap();
    /// for slot in 0..p.system().slots() {
    ///     assert_eq!(body.map().vertex_id(p.dart_of_vertex(slot).unwrap()).index(), slot); // slot = vertex id
    /// }
    /// assert_eq!(p.dart_of_vertex(99), None);
    /// ```
    pub fn dart_of_vertex(&self, slot: usize) -> Option<DartId> {
        self.vertex_dart.get(slot).copied().flatten()
    }
}

/// How two projections of the same body differ ([`Projection::equivalent`]).
///
/// # Examples
///
/// ```
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Material, Projection, ProjectionMismatch};
///
/// let (points, tets) = kuhn_cube(1);
/// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let a = Projection::build(&body, [0.0; 3]).unwrap();
/// let b = Projection::build(&body, [0.0, 0.0, -1.0]).unwrap();
/// assert!(matches!(a.equivalent(&b), Err(ProjectionMismatch::Sizes { slots: (8, 8), .. })));
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ProjectionMismatch {
    /// Different numbers of slots or springs, or different gravity.
    #[error("sizes differ: slots {slots:?}, springs {springs:?} (or gravity)")]
    Sizes {
        /// (self, other) slot counts.
        slots: (usize, usize),
        /// (self, other) spring counts.
        springs: (usize, usize),
    },
    /// Slot `slot` has a different mass, inverse mass, viscosity or liveness.
    #[error("vertex slot {slot} differs")]
    Vertex {
        /// The slot (= vertex id).
        slot: usize,
    },
    /// One side's incidence lists disagree with its spring ends.
    #[error("incidence lists: {0}")]
    Incidence(IncidenceError),
    /// The spring of edge `edge` is missing on one side or has different values.
    #[error("spring of edge {edge} differs or is missing")]
    Spring {
        /// The edge id.
        edge: CellId,
    },
}

/// The vertex and edge ids a topological operation touched, each with a dart of the cell at the
/// time it was recorded (`None`: the cell was deleted or absorbed). Records accumulate over a
/// batch of operations; [`Projection::update`] keeps, per id, the latest record whose dart still
/// carries that id (no valid dart: the cell is gone).
///
/// # Examples
///
/// ```
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Material, TouchedCells};
///
/// let (points, tets) = kuhn_cube(1);
/// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let d = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
/// let changes = body.unsew3(d).unwrap();
/// let mut touched = TouchedCells::default();
/// touched.record(body.map(), &changes);
/// assert!(touched.vertices().iter().all(|&(v, dart)| dart.map_or(true, |d| body.map().vertex_id(d) == v)));
/// ```
///
/// The lists of an operation cannot be changed behind its stamp (an emptied list would be taken
/// as complete by [`Projection::update`], finding 66), so this does not compile:
///
/// ```compile_fail
/// use topomech::cut::dissociate_face;
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Material};
///
/// let (points, tets) = kuhn_cube(1);
/// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let d = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
/// let mut cut = dissociate_face(&mut body, d).unwrap();
/// cut.touched.edges.clear(); // private field
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TouchedCells {
    /// Vertex ids and a dart of each (crate-private, read with [`TouchedCells::vertices`]: lists
    /// changed after an operation stamped them would be taken as complete, finding 66).
    pub(crate) vertices: Vec<(CellId, Option<DartId>)>,
    /// Edge ids and a dart of each (read with [`TouchedCells::edges`]).
    pub(crate) edges: Vec<(CellId, Option<DartId>)>,
    /// Which changes of which body the lists hold (stamped by the operations).
    span: Span,
}

/// Which topological changes a [`TouchedCells`] holds, so that [`Projection::update`] applies
/// it only to a projection it brings up to date.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
enum Span {
    /// Nothing recorded.
    #[default]
    Nothing,
    /// Every change of body `body` ([`crate::embedding::Embedded::identity`]) from version
    /// `from` to version `to`, as the operations of `crate::cut` report them.
    Versions { body: u64, from: u64, to: u64 },
    /// Records of unknown coverage: filled by hand or by [`TouchedCells::record`], or merged
    /// from operations that do not follow each other.
    Unknown,
}

impl Span {
    /// The span of lists `a` followed by lists `b` (each with whether its lists are empty):
    /// an empty unstamped side adds nothing; two stamped spans of one body join when `b` starts
    /// where `a` ends; anything else is unknown. O(1).
    fn joined((a, a_empty): (Span, bool), (b, b_empty): (Span, bool)) -> Span {
        match (a, b) {
            (Span::Nothing, span) if a_empty => span,
            (span, Span::Nothing) if b_empty => span,
            (Span::Versions { body, from, to }, Span::Versions { body: id, from: f, to: t })
                if body == id && to == f =>
            {
                Span::Versions { body, from, to: t }
            }
            _ => Span::Unknown,
        }
    }
}

impl TouchedCells {
    /// Stamps the lists as every change of `body` since its version `from` (the operation that
    /// filled them started there and `body` is now where it ended). O(1).
    pub(crate) fn cover(&mut self, body: &Body, from: u64) {
        self.span = Span::Versions { body: body.identity(), from, to: body.version() };
    }

    /// The versions of `body` the lists bring a projection from and to, when an operation of
    /// `crate::cut` (or an in-order [`Self::extend`] of theirs) filled them; `None` for lists of
    /// unknown coverage (filled by hand or by [`Self::record`]) or of another body. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::cut::dissociate_face;
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material, TouchedCells};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let d = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
    /// let cut = dissociate_face(&mut body, d).unwrap();
    /// assert_eq!(cut.touched.versions(&body), Some((0, 1)));
    /// assert_eq!(TouchedCells::default().versions(&body), None);
    /// ```
    pub fn versions(&self, body: &Body) -> Option<(u64, u64)> {
        match self.span {
            Span::Versions { body: id, from, to } if id == body.identity() => Some((from, to)),
            _ => None,
        }
    }

    /// Records what `changes` (already applied to `map`) did to vertices and edges: both sides of
    /// every split, the survivor and the absorbed id of every merge, and every edge around a
    /// vertex that got a new id (its spring's ends changed). O(changes + stars of renamed
    /// vertices).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material, TouchedCells};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let d = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
    /// let changes = body.unsew3(d).unwrap();
    /// let mut touched = TouchedCells::default();
    /// assert!(touched.is_empty());
    /// touched.record(body.map(), &changes);
    /// assert!(!touched.is_empty() && !touched.vertices().is_empty());
    /// ```
    pub fn record(&mut self, map: &GMap<3>, changes: &CellChanges) {
        // A map has no version: what these records cover is unknown until an operation stamps them.
        self.span = Span::Unknown;
        self.record_with(map, changes, |t, d, side| match side {
            Some(side) => t.edges_around(map, side.iter().copied()),
            None => t.edges_around(map, map.cell_darts(0, d)),
        });
    }

    /// [`Self::record`] with `star(self, d, side)` recording the edges around the renamed vertex
    /// of d, whose darts are `side` when the kernel reported them (a split's new side).
    fn record_with(
        &mut self,
        map: &GMap<3>,
        changes: &CellChanges,
        mut star: impl FnMut(&mut Self, DartId, Option<&[DartId]>),
    ) {
        if self.vertices.capacity() == 0 && self.edges.capacity() == 0 && !changes.changes.is_empty() {
            (self.vertices, self.edges) = crate::spare::take(&SPARE_TOUCHED);
        }
        for (k, (kept, new, dk, dn)) in changes.splits_with_index(0) {
            push_pair(&mut self.vertices, [(kept, Some(dk)), (new, Some(dn))]);
            let side = changes.new_side(k);
            star(self, dn, (!side.is_empty()).then_some(side));
        }
        for (kept, new, dk, dn) in changes.splits(1) {
            push_pair(&mut self.edges, [(kept, Some(dk)), (new, Some(dn))]);
        }
        let darts = || changes.pairs.iter().flat_map(|&(a, b)| [a, b]);
        for (kept, absorbed) in changes.merges(0) {
            self.vertices.push((absorbed, None));
            if let Some(d) = darts().find(|&d| map.vertex_id(d) == kept) {
                self.vertices.push((kept, Some(d)));
                star(self, d, None);
            }
        }
        for (kept, absorbed) in changes.merges(1) {
            self.edges.push((absorbed, None));
            if let Some(d) = darts().find(|&d| map.cell_id(1, d) == kept) {
                self.edges.push((kept, Some(d)));
            }
        }
    }

    /// Every edge of the star of a vertex whose orbit is `darts`, once each, with the last of
    /// `darts` that lies on it (the record [`Projection::update`] would have picked among one
    /// record per dart, which is what was pushed before: ~150 records for ~20 edges). Past
    /// [`TouchedCells::STAR_EDGES`] distinct edges the rest are pushed per dart (duplicates are
    /// harmless). O(vertex orbit · star edges), no allocation beyond the records.
    fn edges_around(&mut self, map: &GMap<3>, darts: impl IntoIterator<Item = DartId>) {
        self.edges.reserve(Self::STAR_RESERVE);
        let start = self.edges.len();
        let mut ids = [u32::MAX; Self::STAR_EDGES];
        let mut len = 0;
        for x in darts {
            let e = map.cell_id(1, x);
            match ids[..len].iter().position(|&id| id == e.0) {
                Some(k) => self.edges[start + k].1 = Some(x),
                None if len < Self::STAR_EDGES => {
                    ids[len] = e.0;
                    len += 1;
                    self.edges.push((e, Some(x)));
                }
                None => self.edges.push((e, Some(x))),
            }
        }
    }

    /// Distinct edges of a star deduplicated by [`TouchedCells::record`].
    const STAR_EDGES: usize = 64;

    /// Edge records reserved per star (a typical star in a tet mesh has about 20 edges; a
    /// larger one only grows the list).
    const STAR_RESERVE: usize = 24;

    /// Appends the records of `other` (a later operation of the same batch). When both lists
    /// were stamped by operations on one body and `other` starts where `self` ends, the result
    /// covers both ([`Self::versions`]); otherwise its coverage is unknown and
    /// [`Projection::update`] rebuilds from it. O(|other|).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::cut::dissociate_face;
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material, TouchedCells};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let mut batch = TouchedCells::default();
    /// for _ in 0..2 {
    ///     let d = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
    ///     let cut = dissociate_face(&mut body, d).unwrap();
    ///     let n = batch.vertices().len() + cut.touched.vertices().len();
    ///     batch.extend(&cut.touched);
    ///     assert_eq!(batch.vertices().len(), n);
    /// }
    /// ```
    pub fn extend(&mut self, other: &TouchedCells) {
        self.span = Span::joined((self.span, self.is_empty()), (other.span, other.is_empty()));
        self.vertices.extend_from_slice(&other.vertices);
        self.edges.extend_from_slice(&other.edges);
    }

    /// [`Self::record`] of the `changes` that the last sew or unsew of `body` returned
    /// ([`crate::mechanics::Body::sew3`], [`crate::mechanics::Body::unsew3`], …), called right
    /// after it: the records are stamped as that one change (versions `body.version() − 1` to
    /// `body.version()`), so that [`Projection::update`] can take them incrementally, alone or
    /// after the lists of the operations before it. The body stamps each report it returns
    /// (its identity, its version after the operation, a fingerprint of the lists): any other
    /// report — empty or default, an earlier operation's, another body's, the kernel's
    /// ([`GMap::sew_dyn`]) or one edited since — is recorded with unknown coverage
    /// ([`Self::versions`] `None`), and [`Projection::update`] rebuilds from it. O(changes +
    /// stars of renamed vertices).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::cut::dissociate_face;
    /// use topomech::generate::kuhn_cube;
    /// use topomech::gmap::CellChanges;
    /// use topomech::mechanics::{Body, Material, Projection, TouchedCells};
    ///
    /// let (points, tets) = kuhn_cube(2);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let mut p = Projection::build(&body, [0.0; 3]).unwrap();
    /// let d = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
    /// let cut = dissociate_face(&mut body, d).unwrap();
    /// let mut touched = TouchedCells::default();
    /// touched.extend(&cut.touched);
    /// let changes = body.sew3(cut.dart, cut.opposite).unwrap(); // sew it back
    /// touched.record_change(&body, &changes);
    /// assert_eq!(touched.versions(&body), Some((0, 2)));
    /// assert!(p.update(&body, &touched)); // incremental, both changes at once
    /// assert!(p.equivalent(&Projection::build(&body, [0.0; 3]).unwrap()).is_ok());
    /// let mut wrong = TouchedCells::default();
    /// wrong.record_change(&body, &CellChanges::default()); // not what the body returned
    /// assert_eq!(wrong.versions(&body), None); // unknown coverage: an update would rebuild
    /// ```
    pub fn record_change(&mut self, body: &Body, changes: &CellChanges) {
        let before = (self.span, self.is_empty());
        self.record(body.map(), changes);
        let step = if body.returned_last(changes) {
            Span::Versions { body: body.identity(), from: body.version().saturating_sub(1), to: body.version() }
        } else {
            Span::Unknown
        };
        self.span = Span::joined(before, (step, false));
    }

    /// Lists given by hand (vertex and edge ids, each with a dart or `None` for a dead id): their
    /// coverage is unknown, so [`Projection::update`] rebuilds instead of trusting them. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material, Projection, TouchedCells};
    /// use topomech::CellId;
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let mut p = Projection::build(&body, [0.0; 3]).unwrap();
    /// let hand = TouchedCells::by_hand(vec![(CellId(0), None)], Vec::new());
    /// assert_eq!((hand.vertices().len(), hand.versions(&body)), (1, None));
    /// assert!(!p.update(&body, &hand)); // not trusted: rebuilt
    /// ```
    pub fn by_hand(vertices: Vec<(CellId, Option<DartId>)>, edges: Vec<(CellId, Option<DartId>)>) -> Self {
        TouchedCells { vertices, edges, span: Span::Unknown }
    }

    /// The vertex ids touched, each with a dart of its vertex (`None`: the id died). O(1).
    pub fn vertices(&self) -> &[(CellId, Option<DartId>)] {
        &self.vertices
    }

    /// The edge ids touched, each with a dart of its edge (`None`: the id died). O(1).
    pub fn edges(&self) -> &[(CellId, Option<DartId>)] {
        &self.edges
    }

    /// Whether nothing was recorded. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::cut::dissociate_face;
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material, TouchedCells};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// assert!(TouchedCells::default().is_empty());
    /// let d = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
    /// assert!(!dissociate_face(&mut body, d).unwrap().touched.is_empty());
    /// ```
    pub fn is_empty(&self) -> bool {
        self.vertices.is_empty() && self.edges.is_empty()
    }
}

thread_local! {
    /// The lists of the [`TouchedCells`] last dropped on this thread, for the next record
    /// (the crate-private `spare` module).
    static SPARE_TOUCHED: std::cell::Cell<Option<(TouchedList, TouchedList)>> = const { std::cell::Cell::new(None) };
}

type TouchedList = Vec<(CellId, Option<DartId>)>;

/// Gives the lists back to this thread's spare slot (the crate-private `spare` module). O(1).
impl Drop for TouchedCells {
    fn drop(&mut self) {
        crate::spare::give_back(&SPARE_TOUCHED, (std::mem::take(&mut self.vertices), std::mem::take(&mut self.edges)));
    }
}

/// Appends two records, making room for a triangle's worth (3 pairs) at the first push: one
/// allocation for a face's splits rather than a growth at the third pair.
fn push_pair(list: &mut Vec<(CellId, Option<DartId>)>, pair: [(CellId, Option<DartId>); 2]) {
    if list.capacity() == 0 {
        list.reserve(6);
    }
    list.extend(pair);
}

/// [`Resolved::of`] into fresh lists (for the unit tests).
#[cfg(test)]
fn resolve(map: &GMap<3>, dim: usize, records: &[(CellId, Option<DartId>)]) -> Vec<(CellId, Option<DartId>)> {
    Resolved::default().of(map, dim, records).to_vec()
}

/// The lists of [`Resolved::of`]: the records' order and the answer, kept by
/// [`Projection::update`] from one update to the next (no allocation in the steady state).
#[derive(Clone, Debug, Default)]
struct Resolved {
    order: Vec<(u32, u32)>,
    out: Vec<(CellId, Option<DartId>)>,
}

impl Resolved {
    /// Per id, the latest record whose dart still carries the id in dimension `dim`, or `None`.
    /// Sorted by id. O(r log r) for r records: the records sorted by (id, latest first), then
    /// one pass (no hash map), reading the map only until each id has a valid dart.
    fn of(&mut self, map: &GMap<3>, dim: usize, records: &[(CellId, Option<DartId>)]) -> &[(CellId, Option<DartId>)] {
        let Resolved { order, out } = self;
        order.clear();
        out.clear();
        order.extend(records.iter().enumerate().map(|(k, r)| (r.0 .0, (records.len() - 1 - k) as u32)));
        order.sort_unstable();
        for &(id, rev) in order.iter() {
            // Only until an id has its dart: the map is read for no record older than that one.
            let valid = || {
                let d = records[records.len() - 1 - rev as usize].1;
                d.filter(|&d| map.contains(d) && map.cell_id(dim, d).0 == id)
            };
            match out.last_mut() {
                Some(last) if last.0 .0 == id => {
                    if last.1.is_none() {
                        last.1 = valid();
                    }
                }
                _ => out.push((CellId(id), valid())),
            }
        }
        out
    }
}

/// [`Resolved::of`] as it was written first (a hash map filled from the latest record back): the
/// reference of the unit test.
#[cfg(test)]
fn resolve_by_hash(map: &GMap<3>, dim: usize, records: &[(CellId, Option<DartId>)]) -> Vec<(CellId, Option<DartId>)> {
    let mut out: rustc_hash::FxHashMap<CellId, Option<DartId>> = Default::default();
    for &(id, d) in records.iter().rev() {
        let slot = out.entry(id).or_insert(None);
        if slot.is_none() {
            *slot = d.filter(|&d| map.contains(d) && map.cell_id(dim, d) == id);
        }
    }
    let mut v: Vec<_> = out.into_iter().collect();
    v.sort_unstable_by_key(|&(id, _)| id);
    v
}

fn system_of(
    mech: &Mechanics,
    springs: &[([u32; 2], DartId)],
    edges: &[CellId],
    vertex_dart: &[Option<DartId>],
    gravity: Vec3,
) -> SpringSystem {
    let ends = springs.iter().map(|&(e, _)| e).collect();
    let rest = edges.iter().map(|&e| mech.edge_rest_length(e)).collect();
    let stiffness = edges.iter().map(|&e| mech.edge_stiffness(e)).collect();
    let damping = edges.iter().map(|&e| mech.edge_damping(e)).collect();
    let n = vertex_dart.len();
    let live = |v: usize| vertex_dart[v].is_some();
    let mass = (0..n).map(|v| if live(v) { mech.vertex_mass(CellId(v as u32)) } else { 0.0 }).collect();
    let visc = (0..n).map(|v| if live(v) { mech.vertex_viscosity(CellId(v as u32)) } else { 0.0 }).collect();
    let fixed: Vec<bool> = (0..n).map(|v| !live(v) || mech.pinned[CellId(v as u32)]).collect();
    SpringSystem::from_arrays(ends, rest, stiffness, damping, mass, &fixed, visc, gravity)
}

/// Forces on every vertex id computed by covering the map (seed §4.2), without the projection:
/// each edge orbit is covered once with a dart set, its spring taken between the vertices of b
/// and α0(b); then each vertex gets gravity and viscosity. Pinned vertices get their force too.
/// Dead ids get zero. The reference formula, evaluated as given: a non-finite `gravity` gives
/// non-finite forces on every live vertex (the step's entries refuse it, [`Projection::build`]).
/// O(darts).
///
/// # Examples
///
/// ```
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{forces_by_coverage, Body, Material};
///
/// // At rest the springs pull nothing: the forces add up to the weight.
/// let (points, tets) = kuhn_cube(1);
/// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let f = forces_by_coverage(&body, [0.0, 0.0, -9.81]);
/// let total_z: f64 = f.iter().map(|f| f[2]).sum();
/// assert!((total_z + 9.81 * body.total_vertex_mass()).abs() < 1e-12);
/// assert!(f.iter().all(|f| f[0] == 0.0 && f[1] == 0.0));
/// ```
pub fn forces_by_coverage(body: &Body, gravity: Vec3) -> Vec<Vec3> {
    let map = body.map();
    let mech = body.attrs();
    let mut f = vec![[0.0; 3]; map.cell_id_bound(0)];
    let mut seen = DartSet::with_capacity(map.capacity());
    for b in map.darts() {
        if seen.contains(b) {
            continue;
        }
        for x in map.orbit(b, AlphaMask::cell(3, 1)) {
            seen.insert(x);
        }
        let (va, vb, e) = (map.vertex_id(b), map.vertex_id(map.alpha::<0>(b)), map.cell_id(1, b));
        let (l, k, c) = (mech.edge_rest_length(e), mech.edge_stiffness(e), mech.edge_damping(e));
        let fs = spring_force(mech.position[va], mech.position[vb], mech.velocity[va], mech.velocity[vb], l, k, c);
        for i in 0..3 {
            f[va.index()][i] += fs[i];
            f[vb.index()][i] -= fs[i];
        }
    }
    seen.clear();
    for d in map.darts() {
        if seen.contains(d) {
            continue;
        }
        for x in map.orbit(d, AlphaMask::cell(3, 0)) {
            seen.insert(x);
        }
        let v = map.vertex_id(d);
        let (m, g) = (mech.vertex_mass(v), mech.vertex_viscosity(v));
        for i in 0..3 {
            f[v.index()][i] += m * gravity[i] - g * mech.velocity[v][i];
        }
    }
    f
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cut::ops::{jittered_cube, material};
    use crate::generate::SplitMix64;
    use crate::mechanics::Body;

    /// [`TouchedCells::record`] as it was first written: one edge record per dart of each
    /// renamed vertex's orbit, in the order of the new side the kernel reported (else of the
    /// orbit walk) — the same walk over the changes, another star.
    fn record_per_dart(t: &mut TouchedCells, map: &GMap<3>, changes: &CellChanges) {
        t.record_with(map, changes, |t, d, side| {
            let darts = side.map_or_else(|| map.cell_darts(0, d), <[DartId]>::to_vec);
            for x in darts {
                t.edges.push((map.cell_id(1, x), Some(x)));
            }
        });
    }

    /// Batches of random α3-unsews and sews back on a jittered Kuhn cube: the deduplicated star
    /// records resolve exactly as one record per dart (same ids, same darts), the sort-based
    /// `resolve` equals the hash-map one on both record lists, and the incrementally updated
    /// projection equals a fresh one. Vertex splits and merges must have happened.
    #[test]
    fn deduplicated_records_resolve_as_per_dart_records() {
        let (points, tets) = jittered_cube(3, 7);
        let (mut body, _) = Body::from_tets(&points, &tets, material()).unwrap();
        let mut projection = Projection::build_raw(&body, [0.0, 0.0, -1.0]);
        let mut rng = SplitMix64(19);
        let mut cut: Vec<(DartId, DartId)> = Vec::new();
        let (mut vertex_splits, mut vertex_merges) = (0, 0);
        for _batch in 0..40 {
            let (mut fast, mut reference) = (TouchedCells::default(), TouchedCells::default());
            for _ in 0..1 + rng.below(12) {
                let changes = if !cut.is_empty() && rng.below(4) == 0 {
                    let (a, b) = cut.swap_remove(rng.below(cut.len()));
                    body.sew3(a, b).unwrap()
                } else {
                    let d = DartId(rng.below(body.map().capacity()) as u32);
                    if !body.map().contains(d) || body.map().is_free(3, d) {
                        continue;
                    }
                    let e = body.map().alpha::<3>(d);
                    let changes = body.unsew3(d).unwrap();
                    cut.push((d, e));
                    changes
                };
                vertex_splits += changes.splits(0).count();
                vertex_merges += changes.merges(0).count();
                fast.record_change(&body, &changes);
                record_per_dart(&mut reference, body.map(), &changes);
            }
            let map = body.map();
            assert!(fast.edges.len() <= reference.edges.len());
            for dim in [0, 1] {
                let pick = |t: &TouchedCells| if dim == 0 { t.vertices.clone() } else { t.edges.clone() };
                let (f, r) = (pick(&fast), pick(&reference));
                assert_eq!(resolve(map, dim, &f), resolve(map, dim, &r), "dimension {dim}");
                assert_eq!(resolve(map, dim, &f), resolve_by_hash(map, dim, &f));
                assert_eq!(resolve(map, dim, &r), resolve_by_hash(map, dim, &r));
            }
            assert!(projection.update(&body, &fast), "the recorded changes are taken incrementally");
            projection.equivalent(&Projection::build_raw(&body, [0.0, 0.0, -1.0])).unwrap();
        }
        assert!(vertex_splits > 10 && vertex_merges > 10, "splits {vertex_splits}, merges {vertex_merges}");
    }
}
