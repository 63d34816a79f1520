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
//! stale ([`Projection::is_current`] compares the body's version) and must be rebuilt. An
//! incremental update (next issue) only has to touch the slots and springs named by the
//! operation's `CellChanges`, through these maps.
//!
//! [`forces_by_coverage`] computes the same forces the paper's first way, by covering the
//! map's edges and vertices with a dart set: the reference the projection is tested against.

use crate::gmap::DartSet;
use crate::{AlphaMask, CellId, DartId};

use super::force::{spring_force, SpringSystem};
use super::geom::Vec3;
use super::model::{Body, Mechanics};

/// See the [module docs](self).
#[derive(Clone, Debug)]
pub struct Projection {
    /// The arrays the step loop reads.
    pub system: SpringSystem,
    spring_edge: Vec<CellId>,
    spring_dart: Vec<DartId>,
    edge_spring: Vec<u32>,
    vertex_dart: Vec<Option<DartId>>,
    version: u64,
}

impl Projection {
    /// Projects `body` with gravity `gravity`. O(darts + E log E).
    pub fn build(body: &Body, gravity: Vec3) -> Self {
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
        Projection { system, spring_edge, spring_dart, edge_spring, vertex_dart, version: body.version() }
    }

    /// Rebuilds from scratch after topological changes (keeps the gravity). O(darts + E log E).
    pub fn rebuild(&mut self, body: &Body) {
        *self = Projection::build(body, self.system.gravity);
    }

    /// Whether the body has not changed topologically since the projection was built. O(1).
    pub fn is_current(&self, body: &Body) -> bool {
        self.version == body.version()
    }

    /// The body version the projection was built from. O(1).
    pub fn version(&self) -> u64 {
        self.version
    }

    /// The edge of spring s. O(1).
    pub fn edge_of_spring(&self, s: usize) -> CellId {
        self.spring_edge[s]
    }

    /// A dart of spring s's edge; its vertex is end a. O(1).
    pub fn dart_of_spring(&self, s: usize) -> DartId {
        self.spring_dart[s]
    }

    /// The spring of edge `e`, if `e` is live. O(1).
    pub fn spring_of_edge(&self, e: CellId) -> Option<usize> {
        self.edge_spring.get(e.index()).filter(|&&s| s != u32::MAX).map(|&s| s as usize)
    }

    /// A dart of the vertex in slot `slot` (= vertex id), `None` for a dead id. O(1).
    pub fn dart_of_vertex(&self, slot: usize) -> Option<DartId> {
        self.vertex_dart.get(slot).copied().flatten()
    }
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
    SpringSystem::new(ends, rest, stiffness, damping, mass, &fixed, visc, gravity)
}

/// Forces on every vertex id computed by covering the map (seed §4.2), without the projection:
/// each edge orbit is covered once with a dart set, its spring taken between the vertices of b
/// and α0(b); then each vertex gets gravity and viscosity. Pinned vertices get their force too.
/// Dead ids get zero. O(darts).
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
