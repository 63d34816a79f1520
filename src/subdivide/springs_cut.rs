//! A cut followed by the spring coupling: [`LeveledMechanics::unsew_face`] (round 42; seed 000's
//! face dissociation, section 3.1, on a subdivided map).
//!
//! # Rules
//! The map's [`LeveledMap::unsew_face`] α3-unsews one face of the finest map. Only the face's own
//! cells can come apart: a vertex of the face whose darts no longer meet around it gets a fresh
//! vertex id (a *copy*, whose origin is the vertex it was split from), an edge of the face whose
//! darts no longer meet gets a fresh edge cell id for the part on one side. The coupling then:
//! - **copies a split vertex's state**: the copy takes the position and velocity of the vertex
//!   it was split from (the map gives it the same rest position). Vertex masses are derived from
//!   the volumes, which the cut leaves as they were, so m_v + m_v' is the mass v had and
//!   Σ_v m_v u_v is unchanged;
//! - **shares a split edge's spring between its two parts in parallel** (Kirchhoff: k = k₁ + k₂,
//!   c = c₁ + c₂, each part with the rest length L). Part i takes the fraction w_i / (w₁ + w₂),
//!   w_i = Σ over the volumes around part i of law 2's term E V_t / L² of the corner pair of t
//!   whose segment holds the part (its two ends are corners of t, or midpoints inserted on that
//!   segment); a volume where no corner pair holds it adds nothing. For an edge that is not a
//!   half this gives each part the stiffness law 5 gives it from its own tets; for a half it
//!   shares the series value 2ᵈ k by the same tets' terms. Equal shares when w₁ + w₂ = 0 (a
//!   spring of k = 0 on both sides);
//! - **renames the springs whose key changed**: an edge at a copy keeps its cell id and its
//!   spring, under its new end.
//!
//! A part of a half is a half; it replaces the half in the side of its split edge
//! ([`super::springs::SplitNode`]), where the two parts stand in parallel. Gluing the cut back
//! (every vertex identified with its origin), each split edge's springs give its root's
//! stiffness, damping and rest length again: law 4 of [`LeveledMechanics::check`], now over
//! series of parallel sides.

use std::collections::{BTreeMap, BTreeSet};

use super::springs::{EdgeKey, Member, Spring, PAIRS};
use super::{CouplingError, LeveledMap, LeveledMechanics};
use crate::gmap::{AlphaMask, DartId};
use crate::mechanics::model::tet_stiffnesses;

/// What the coupling reads off a face before the map cuts it.
struct FaceBefore {
    /// Per edge of the face: a dart of the face at it, the dart across (α3), the edge's key.
    edges: Vec<(DartId, DartId, EdgeKey)>,
    /// Every dart of the face on both sides, with its vertex id.
    vertices: Vec<(DartId, u32)>,
}

impl FaceBefore {
    /// The face of the live dart `d`. O(face).
    fn of(m: &LeveledMap<3>, d: DartId) -> Self {
        let map = m.map();
        let side = map.orbit(d, AlphaMask::of(&[0, 1]));
        let mut seen = BTreeSet::new();
        let edges = side
            .iter()
            .filter(|&&x| seen.insert(map.cell_id(1, x)))
            .map(|&x| (x, map.alpha::<3>(x), EdgeKey::of(map, x)))
            .collect();
        let vertices = side.iter().flat_map(|&x| [x, map.alpha::<3>(x)]).map(|x| (x, map.vertex_id(x).0)).collect();
        FaceBefore { edges, vertices }
    }
}

impl LeveledMechanics {
    /// [`LeveledMap::unsew_face`] with the springs and vertex states following the cut (module
    /// docs: a split vertex's copy takes its state, a split edge's spring is shared by its two
    /// parts in parallel by their tets' terms, k₁ + k₂ = k). Returns the map's result (the darts
    /// unlinked on the side of `d`). O(face + star of the face's vertices · log E + volumes
    /// around its edges).
    ///
    /// Errors: those of the coupling's sync check ([`CouplingError::OutOfSync`],
    /// [`CouplingError::StateCount`], [`CouplingError::Unfollowed`], [`CouplingError::OtherMap`],
    /// [`CouplingError::Material`]) and the map's refusals (the level order, no such dart, a face
    /// not sewn): map and coupling unchanged; [`CouplingError::NoSpring`] is a bug (or a
    /// tampered coupling).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::Material;
    /// use topomech::subdivide::{LeveledMap, LeveledMechanics};
    /// use topomech::GMap;
    /// // Two tets glued by the face (1, 2, 3): the cut splits every vertex and edge of it.
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]];
    /// let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [1, 2, 3, 4]]).unwrap();
    /// let mut m = LeveledMap::new(map, pts);
    /// let mut mech = LeveledMechanics::new(&m, Material::default()).unwrap();
    /// let k = mech.spring(1, 2).unwrap().stiffness;
    /// let glued = m.map().darts().find(|&d| !m.map().is_free(3, d)).unwrap();
    /// mech.unsew_face(&mut m, glued, 1).unwrap();
    /// mech.check(&m).unwrap();
    /// let parts: Vec<f64> = mech.springs().filter(|(e, _)| {
    ///     [e.a, e.b].map(|v| m.vertex_origin(v)) == [1, 2]
    /// }).map(|(_, s)| s.stiffness).collect();
    /// assert_eq!(parts.len(), 2);
    /// assert!((parts[0] + parts[1] - k).abs() <= 1e-12 * k); // k = k₁ + k₂
    /// ```
    pub fn unsew_face(&mut self, m: &mut LeveledMap<3>, d: DartId, level: u8) -> Result<usize, CouplingError> {
        self.in_sync(m)?;
        let before = m.map().contains(d).then(|| FaceBefore::of(m, d));
        let unlinked = m.unsew_face(d, level)?;
        if let Some(before) = before {
            self.follow_cut(m, &before)?;
        }
        self.followed = m.version();
        self.followed_stamp = m.stamp();
        self.expensive_check(m);
        Ok(unlinked)
    }

    /// Applies the module's rules to the face `before` that the map has just cut. O(face + star
    /// of its split vertices · log E + volumes around its edges).
    fn follow_cut(&mut self, m: &LeveledMap<3>, before: &FaceBefore) -> Result<(), CouplingError> {
        let map = m.map();
        // Copies: (dart at the copy, vertex id it had before).
        let copies: BTreeMap<u32, (DartId, u32)> = before
            .vertices
            .iter()
            .filter(|&&(x, old)| map.vertex_id(x).0 != old)
            .map(|&(x, old)| (map.vertex_id(x).0, (x, old)))
            .collect();
        let n = map.cell_id_bound(0);
        self.position.resize(n, [0.0; 3]);
        self.velocity.resize(n, [0.0; 3]);
        self.parents.resize(n.max(self.parents.len()), None);
        for (&copy, &(_, old)) in &copies {
            self.position[copy as usize] = self.position[old as usize];
            self.velocity[copy as usize] = self.velocity[old as usize];
        }
        for &(x, y, old) in &before.edges {
            let (kx, ky) = (EdgeKey::of(map, x), EdgeKey::of(map, y));
            let parts = if kx.id == ky.id { vec![(kx, x)] } else { vec![(kx, x), (ky, y)] };
            if parts.len() > 1 || kx != old {
                self.replace_spring(m, old, &parts)?;
            }
        }
        // Every other edge at a copy keeps its cell id and its spring under its new end.
        let old_of = |v: u32| copies.get(&v).map_or(v, |&(_, old)| old);
        for &(x, _) in copies.values() {
            for y in map.orbit(x, AlphaMask::cell(3, 0)) {
                let e = EdgeKey::of(map, y);
                if !self.springs.contains_key(&e) {
                    self.replace_spring(m, EdgeKey::new(e.id, old_of(e.a), old_of(e.b)), &[(e, y)])?;
                }
            }
        }
        Ok(())
    }

    /// Replaces the spring of the edge `old` by the springs of `parts` (key, a dart of it): the
    /// same spring for one part, the parallel shares of the module docs for two; the parts take
    /// its place among the halves and in the side of its split edge. O(parts · volumes around
    /// them + log E).
    fn replace_spring(
        &mut self,
        m: &LeveledMap<3>,
        old: EdgeKey,
        parts: &[(EdgeKey, DartId)],
    ) -> Result<(), CouplingError> {
        let s = self.springs.remove(&old).ok_or(CouplingError::NoSpring(old))?;
        let weights: Vec<f64> = parts.iter().map(|&(e, x)| self.part_weight(m, e, x)).collect();
        let total: f64 = weights.iter().sum();
        for (&(e, _), &w) in parts.iter().zip(&weights) {
            let spring = match parts.len() {
                1 => s,
                n => {
                    let f = if total > 0.0 && total.is_finite() { w / total } else { 1.0 / n as f64 };
                    Spring { rest: s.rest, stiffness: s.stiffness * f, damping: s.damping * f }
                }
            };
            self.springs.insert(e, spring);
        }
        if self.halves.remove(&old) {
            self.halves.extend(parts.iter().map(|&(e, _)| e));
        }
        if let Some(parent) = self.member_of.remove(&old) {
            let node = self.split_at.get_mut(&parent).ok_or(CouplingError::NoSpring(parent))?;
            for side in &mut node.sides {
                let Some(i) = side.iter().position(|x| x.key == old) else { continue };
                let outer = m.vertex_origin(if side[i].outer_at_a { old.a } else { old.b });
                let members = parts.iter().map(|&(e, _)| Member { key: e, outer_at_a: m.vertex_origin(e.a) == outer });
                side.splice(i..=i, members);
            }
            for &(e, _) in parts {
                self.member_of.insert(e, parent);
            }
        }
        Ok(())
    }

    /// w of the module docs for the edge `e` of dart `x`: Σ over the volumes around it of law 2's
    /// term of the corner pair whose segment holds it. O(volumes around it · (volume + depth)).
    fn part_weight(&self, m: &LeveledMap<3>, e: EdgeKey, x: DartId) -> f64 {
        let map = m.map();
        let mut volumes = BTreeSet::new();
        let mut w = 0.0;
        for y in map.orbit(x, AlphaMask::cell(3, 1)) {
            if !volumes.insert(map.cell_id(3, y)) {
                continue;
            }
            let Ok(corners) = m.tet_vertices(y) else { continue };
            let holds = |(i, j): (usize, usize)| [e.a, e.b].iter().all(|&v| self.lies_on(m, v, corners[i], corners[j]));
            if let Some(pair) = PAIRS.iter().position(|&p| holds(p)) {
                w += tet_stiffnesses(self.material.young, corners.map(|v| m.points()[v as usize]))[pair];
            }
        }
        w
    }

    /// Whether the vertex `v` lies on the segment between the vertices `a` and `b`: it is one of
    /// them, or a midpoint inserted between two vertices that do (vertices compared by origin).
    /// O(split depth).
    fn lies_on(&self, m: &LeveledMap<3>, v: u32, a: u32, b: u32) -> bool {
        let o = m.vertex_origin(v);
        if o == m.vertex_origin(a) || o == m.vertex_origin(b) {
            return true;
        }
        match self.parents.get(o as usize).copied().flatten() {
            Some((_, [p, q])) => self.lies_on(m, p, a, b) && self.lies_on(m, q, a, b),
            None => false,
        }
    }
}
