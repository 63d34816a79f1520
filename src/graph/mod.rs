//! Adjacency graphs of an n-G-map, as `petgraph` graphs (seed 000, §1: "adjacency graphs are
//! ambiguous").
//!
//! Three graphs are exported, all undirected, with one node per live cell labelled by its
//! dimension ([`CellNode`]) and one edge per *related pair* of cells weighted by its multiplicity:
//!
//! | [`GraphKind`] | nodes | an edge {a, b} with weight m when |
//! |---|---|---|
//! | `VertexEdge` (1-skeleton) | 0-cells | m 1-cells have endpoints a and b (a = b: m loops, each with two distinct end incidences at a; a folded edge is no loop, see below) |
//! | `Dual` | n-cells | m (n−1)-cells lie between n-cells a and b (a = b: m (n−1)-cells each with two distinct incidences at a, i.e. a glued to itself across two different faces; a folded (n−1)-cell is no loop, see below) |
//! | `Incidence` | every cell | a is a k-cell, b a (k+1)-cell, and a occurs m times in ∂b |
//!
//! # Incidences and their multiplicity
//! In an n-G-map the incidences between a k-cell and a (k+1)-cell are the orbits
//! ⟨αj : j ∉ {k, k+1}⟩ — the flags restricted to that pair of dimensions. A (k+1)-cell whose
//! boundary passes twice through one k-cell (a face glued to itself along an edge, an edge that is
//! a loop) has two such orbits in that k-cell: multiplicity 2. The graphs record multiplicity as
//! the edge weight (so they stay simple graphs, which `petgraph`'s VF2 requires); the comparison
//! chooses whether weights count ([`Multiplicity`]). An indexed mesh stores only the simple
//! relation, so `Multiplicity::Ignore` is "the adjacency graph" of the seed; `Match` is the finer
//! "incidence graph with multiplicities", which is still ambiguous (torus and Klein bottle share
//! it: see `docs/ambiguity.md`).
//!
//! # Cells with a single end incidence
//! The 1-skeleton and the dual graph join the two *end incidences* of an edge (its two vertex
//! incidences, orbits ⟨α2, …, αn⟩) or of an (n−1)-cell (its two n-cell incidences, orbits
//! ⟨α0, …, αn−2⟩). A cell with a single end incidence adds nothing to these two graphs. That is
//! the case of
//! - a dangling half-edge (an α0-free dart) and a boundary (n−1)-cell (αn-free);
//! - a *folded* cell, sewn but onto itself: an edge with α0(d) in the ⟨α2, …, αn⟩ orbit of d (the
//!   edge is identified with its own reverse; the quotient of a segment by its reflection is a
//!   half-edge with one vertex end and the fold as its other end), and an (n−1)-cell glued to
//!   itself by its own reflection, αn(d) in its ⟨α0, …, αn−2⟩ orbit (for n = 3: α3(d) in the
//!   ⟨α0, α1⟩ orbit of d; the quotient has one n-cell side).
//!
//! A *loop* is different: an edge whose two ends are two distinct incidences at the same vertex
//! (a = b in the table) counts one unit of weight on {a, a}, and likewise an (n−1)-cell whose two
//! sides are two distinct incidences with the same n-cell. All these cells still appear in the
//! incidence graph, with their true multiplicity (a folded edge has multiplicity 1 at its vertex,
//! a loop 2).
//!
//! Cost: every export is O(darts · n) plus the graph size.

use std::collections::BTreeMap;
use std::fmt;

use petgraph::graph::{Graph, NodeIndex};
use petgraph::Undirected;

use crate::gmap::{AlphaMask, DartSet, GMap};

/// A node of a cell graph: a cell of dimension `dim` with the map's cell id `id`.
///
/// # Examples
///
/// ```
/// use topomech::graph::incidence_graph;
/// use topomech::GMap;
///
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let g = incidence_graph(&map);
/// let volumes: Vec<_> = g.node_weights().filter(|n| n.dim == 3).collect();
/// assert_eq!(volumes.len(), 1);
/// assert_eq!(volumes[0].id, map.cell_id(3, map.darts().next().unwrap()).0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
pub struct CellNode {
    /// Dimension of the cell (0 = vertex).
    pub dim: u8,
    /// The map's id of the cell (meaningful only with that map).
    pub id: u32,
}

/// An undirected cell graph whose edge weights are multiplicities (≥ 1).
///
/// # Examples
///
/// ```
/// use topomech::graph::{dual_graph, CellGraph};
/// use topomech::GMap;
///
/// let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
/// let g: CellGraph = dual_graph(&map);
/// assert_eq!((g.node_count(), g.edge_count()), (2, 1)); // two tets through one face
/// assert!(g.node_weights().all(|n| n.dim == 3));
/// assert!(g.edge_weights().all(|&m| m == 1)); // multiplicities
/// ```
pub type CellGraph = Graph<CellNode, u32, Undirected>;

/// Which adjacency graph to export (see the [module docs](self)).
///
/// # Examples
///
/// ```
/// use topomech::graph::GraphKind;
///
/// assert_eq!(GraphKind::ALL.map(|k| k.name()), ["vertex_edge", "dual", "incidence"]);
/// assert_eq!(GraphKind::Dual.to_string(), "dual");
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GraphKind {
    /// Vertices joined by edges (the 1-skeleton).
    VertexEdge,
    /// n-cells joined through (n−1)-cells.
    Dual,
    /// All cells, a k-cell joined to the (k+1)-cells whose boundary contains it.
    Incidence,
}

impl GraphKind {
    /// Every kind, in a fixed order.
    pub const ALL: [GraphKind; 3] = [GraphKind::VertexEdge, GraphKind::Dual, GraphKind::Incidence];

    /// The snake-case name used in JSON and on the command line.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::graph::GraphKind;
    ///
    /// assert_eq!(GraphKind::ALL.map(|k| k.name()), ["vertex_edge", "dual", "incidence"]);
    /// assert_eq!(GraphKind::Dual.to_string(), GraphKind::Dual.name());
    /// ```
    pub const fn name(self) -> &'static str {
        match self {
            GraphKind::VertexEdge => "vertex_edge",
            GraphKind::Dual => "dual",
            GraphKind::Incidence => "incidence",
        }
    }
}

impl fmt::Display for GraphKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Whether graph comparison matches edge weights (multiplicities) or only the simple relation.
///
/// # Examples
///
/// ```
/// use topomech::graph::{graphs_isomorphic, GraphJson, GraphKind, Multiplicity};
///
/// let graph = |m| GraphJson { kind: GraphKind::Dual, nodes: vec![3, 3], edges: vec![[0, 1, m]] }.to_graph().unwrap();
/// let (once, twice) = (graph(1), graph(2)); // glued along one face, or along two
/// assert!(graphs_isomorphic(&once, &twice, Multiplicity::Ignore));
/// assert!(!graphs_isomorphic(&once, &twice, Multiplicity::Match));
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Multiplicity {
    /// Only which cells are related (what an indexed mesh stores).
    Ignore,
    /// Also how many times.
    Match,
}

/// The incidences between k-cells and (k+1)-cells of `map`: ((k-cell id, (k+1)-cell id) →
/// multiplicity), i.e. the number of orbits ⟨αj : j ∉ {k, k+1}⟩ carrying both ids. O(darts · n).
/// Empty for k ≥ n: there is no (k+1)-cell to be incident to.
///
/// # Examples
///
/// ```
/// use topomech::graph::incidences;
/// use topomech::GMap;
///
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let vertex_edge = incidences(&map, 0);
/// assert_eq!(vertex_edge.len(), 12); // 6 edges × 2 ends
/// assert!(vertex_edge.values().all(|&m| m == 1));
/// assert_eq!(incidences(&map, 2).len(), 4); // 4 faces on the one volume
/// assert!(incidences(&map, 3).is_empty()); // no 4-cells
/// ```
pub fn incidences<const N: usize>(map: &GMap<N>, k: usize) -> BTreeMap<(u32, u32), u32> {
    if k >= N {
        return BTreeMap::new();
    }
    let mask = AlphaMask(AlphaMask::all(N).0 & !(1 << k) & !(1 << (k + 1)));
    let mut seen = DartSet::with_capacity(map.capacity());
    let mut out = BTreeMap::new();
    for d in map.darts() {
        if !seen.insert(d) {
            continue;
        }
        for x in map.orbit(d, mask) {
            seen.insert(x);
        }
        *out.entry((map.cell_id(k, d).0, map.cell_id(k + 1, d).0)).or_insert(0) += 1;
    }
    out
}

/// Builds graphs with one node per live cell of the chosen dimensions, found by id.
struct Builder {
    graph: CellGraph,
    index: BTreeMap<(u8, u32), NodeIndex>,
    weights: BTreeMap<(NodeIndex, NodeIndex), u32>,
}

impl Builder {
    fn new<const N: usize>(map: &GMap<N>, dims: &[usize]) -> Self {
        let mut b = Builder { graph: CellGraph::default(), index: BTreeMap::new(), weights: BTreeMap::new() };
        for &dim in dims {
            let mut ids: Vec<u32> = map.one_dart_per_cell(dim).into_iter().map(|d| map.cell_id(dim, d).0).collect();
            ids.sort_unstable();
            for id in ids {
                let node = b.graph.add_node(CellNode { dim: dim as u8, id });
                b.index.insert((dim as u8, id), node);
            }
        }
        b
    }

    fn node(&self, dim: usize, id: u32) -> NodeIndex {
        self.index[&(dim as u8, id)]
    }

    /// Adds `m` to the weight of the edge {a, b}.
    fn add(&mut self, a: NodeIndex, b: NodeIndex, m: u32) {
        let key = if a <= b { (a, b) } else { (b, a) };
        *self.weights.entry(key).or_insert(0) += m;
    }

    fn finish(mut self) -> CellGraph {
        for ((a, b), w) in std::mem::take(&mut self.weights) {
            self.graph.add_edge(a, b, w);
        }
        self.graph
    }
}

/// Joins, for each c-cell, the cells of dimension `end_dim` it has incidences with, pairwise: a
/// c-cell with exactly two end incidences (counting multiplicity) adds one to that edge. A cell
/// with one end incidence (free, or folded onto itself: see the module docs) adds nothing.
fn join_through(b: &mut Builder, inc: &BTreeMap<(u32, u32), u32>, end_dim: usize, ends_are_low: bool) {
    let mut ends: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
    for (&(low, high), &m) in inc {
        let (through, end) = if ends_are_low { (high, low) } else { (low, high) };
        let list = ends.entry(through).or_default();
        list.extend(std::iter::repeat_n(end, m as usize));
    }
    for list in ends.values() {
        if let [u, v] = list[..] {
            let (nu, nv) = (b.node(end_dim, u), b.node(end_dim, v));
            b.add(nu, nv, 1);
        }
    }
}

/// The 1-skeleton: vertices, and one unit of weight per edge joining its two endpoints (two
/// distinct end incidences; a dangling or folded edge has one and adds nothing: see the
/// [module docs](self)). O(darts · n). Panics for N = 0 (not a valid map dimension anyway).
///
/// # Examples
///
/// ```
/// use topomech::graph::vertex_edge_graph;
/// use topomech::GMap;
///
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let g = vertex_edge_graph(&map);
/// assert_eq!((g.node_count(), g.edge_count()), (4, 6)); // the complete graph K4
/// ```
pub fn vertex_edge_graph<const N: usize>(map: &GMap<N>) -> CellGraph {
    let mut b = Builder::new(map, &[0]);
    let inc = incidences(map, 0);
    join_through(&mut b, &inc, 0, true);
    b.finish()
}

/// The dual graph: n-cells, and one unit of weight per (n−1)-cell lying between two of them (two
/// distinct n-cell incidences; a boundary or folded (n−1)-cell has one and adds nothing: see the
/// [module docs](self)). O(darts · n).
///
/// # Examples
///
/// ```
/// use topomech::graph::dual_graph;
/// use topomech::{generate, GMap};
///
/// let (points, tets) = generate::kuhn_cube(1);
/// let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
/// let g = dual_graph(&map);
/// assert_eq!(g.node_count(), 6); // the tets
/// assert_eq!(g.edge_count(), 18 - 12); // one per inner face
/// ```
pub fn dual_graph<const N: usize>(map: &GMap<N>) -> CellGraph {
    let mut b = Builder::new(map, &[N]);
    let inc = incidences(map, N - 1);
    join_through(&mut b, &inc, N, false);
    b.finish()
}

/// The incidence graph (Hasse diagram with multiplicities) of all cells. O(darts · n²).
///
/// # Examples
///
/// ```
/// use topomech::graph::incidence_graph;
/// use topomech::GMap;
///
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let g = incidence_graph(&map);
/// assert_eq!(g.node_count(), 4 + 6 + 4 + 1);
/// assert_eq!(g.edge_count(), 12 + 12 + 4); // vertex–edge, edge–face, face–volume
/// ```
pub fn incidence_graph<const N: usize>(map: &GMap<N>) -> CellGraph {
    let dims: Vec<usize> = (0..=N).collect();
    let mut b = Builder::new(map, &dims);
    for k in 0..N {
        for ((low, high), m) in incidences(map, k) {
            let (a, c) = (b.node(k, low), b.node(k + 1, high));
            b.add(a, c, m);
        }
    }
    b.finish()
}

/// The graph of the given kind. O(darts · n²).
///
/// # Examples
///
/// ```
/// use topomech::graph::{graph_of, GraphKind};
/// use topomech::{generate, GMap};
///
/// let (points, triangles) = generate::grid_triangles(2);
/// let (map, _) = GMap::<2>::from_triangles(points.len(), &triangles).unwrap();
/// let sizes: Vec<_> = GraphKind::ALL.iter().map(|&k| graph_of(&map, k).node_count()).collect();
/// assert_eq!(sizes, vec![9, 8, 9 + 16 + 8]); // vertices, triangles, all cells
/// ```
pub fn graph_of<const N: usize>(map: &GMap<N>, kind: GraphKind) -> CellGraph {
    match kind {
        GraphKind::VertexEdge => vertex_edge_graph(map),
        GraphKind::Dual => dual_graph(map),
        GraphKind::Incidence => incidence_graph(map),
    }
}

/// Whether there is a bijection of nodes preserving dimensions and edges (and, with
/// [`Multiplicity::Match`], edge weights): `petgraph`'s VF2 with a cheap invariant check first.
/// Exponential in the worst case; fast on the small and sparse graphs of this study.
///
/// # Examples
///
/// ```
/// use topomech::graph::{graph_of, graphs_isomorphic, GraphKind, Multiplicity};
/// use topomech::GMap;
///
/// let (a, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
/// let (b, _) = GMap::<3>::from_tets(5, &[[4, 3, 2, 0], [4, 3, 2, 1]]).unwrap();
/// let (c, _) = GMap::<3>::from_tets(6, &[[0, 1, 2, 3], [0, 1, 4, 5]]).unwrap();
/// let g = |m: &GMap<3>| graph_of(m, GraphKind::Incidence);
/// assert!(graphs_isomorphic(&g(&a), &g(&b), Multiplicity::Match));
/// assert!(!graphs_isomorphic(&g(&a), &g(&c), Multiplicity::Ignore)); // glued along an edge only
/// ```
pub fn graphs_isomorphic(a: &CellGraph, b: &CellGraph, multiplicity: Multiplicity) -> bool {
    if GraphInvariant::of(a, multiplicity) != GraphInvariant::of(b, multiplicity) {
        return false;
    }
    let node_match = |x: &CellNode, y: &CellNode| x.dim == y.dim;
    match multiplicity {
        Multiplicity::Ignore => petgraph::algo::is_isomorphic_matching(a, b, node_match, |_: &u32, _: &u32| true),
        Multiplicity::Match => petgraph::algo::is_isomorphic_matching(a, b, node_match, |x: &u32, y: &u32| x == y),
    }
}

/// A cheap isomorphism invariant of a cell graph: the sorted multiset of (dimension, loop weight,
/// sorted neighbour (dimension, weight) list) over nodes. Equal for isomorphic graphs; used to
/// bucket graphs before VF2. O(nodes + edges · log).
///
/// # Examples
///
/// ```
/// use topomech::graph::{dual_graph, GraphInvariant, Multiplicity};
/// use topomech::GMap;
///
/// let (a, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
/// let (b, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [1, 2, 3, 4]]).unwrap();
/// let (c, _) = GMap::<3>::from_tets(8, &[[0, 1, 2, 3], [4, 5, 6, 7]]).unwrap();
/// let inv = |m: &GMap<3>| GraphInvariant::of(&dual_graph(m), Multiplicity::Ignore);
/// assert_eq!(inv(&a), inv(&b)); // both: two volumes, one shared face
/// assert_ne!(inv(&a), inv(&c)); // two separate tets
/// ```
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct GraphInvariant(Vec<InvariantRow>);

/// One node of a [`GraphInvariant`]: (dimension, loop weight, sorted (neighbour dimension, weight)).
///
/// # Examples
///
/// ```
/// use topomech::graph::{incidence_graph, InvariantRow};
/// use topomech::GMap;
///
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let g = incidence_graph(&map);
/// // the row of a vertex of a lone tet: dimension 0, no loop, three edges of weight 1
/// let row: InvariantRow = (0, 0, vec![(1, 1); 3]);
/// let v = g.node_indices().find(|&n| g[n].dim == 0).unwrap();
/// assert_eq!(g.neighbors(v).count(), row.2.len());
/// ```
pub type InvariantRow = (u8, u32, Vec<(u8, u32)>);

impl GraphInvariant {
    /// The invariant of `g`; weights are replaced by 1 under [`Multiplicity::Ignore`].
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::graph::{vertex_edge_graph, GraphInvariant, Multiplicity};
    /// use topomech::GMap;
    ///
    /// let (a, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
    /// let (b, _) = GMap::<3>::from_tets(5, &[[4, 3, 2, 1], [4, 3, 2, 0]]).unwrap();
    /// let (c, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let inv = |m: &GMap<3>| GraphInvariant::of(&vertex_edge_graph(m), Multiplicity::Match);
    /// assert_eq!(inv(&a), inv(&b)); // isomorphic graphs share it
    /// assert_ne!(inv(&a), inv(&c));
    /// ```
    pub fn of(g: &CellGraph, multiplicity: Multiplicity) -> Self {
        let w = |x: u32| if multiplicity == Multiplicity::Match { x } else { 1 };
        let mut rows: Vec<InvariantRow> = g.node_indices().map(|n| (g[n].dim, 0, Vec::new())).collect();
        for e in g.edge_indices() {
            let (a, b) = g.edge_endpoints(e).expect("edge index from this graph");
            let weight = w(g[e]);
            if a == b {
                rows[a.index()].1 += weight;
                continue;
            }
            rows[a.index()].2.push((g[b].dim, weight));
            rows[b.index()].2.push((g[a].dim, weight));
        }
        for row in &mut rows {
            row.2.sort_unstable();
        }
        rows.sort_unstable();
        GraphInvariant(rows)
    }
}

/// A cell graph in a canonical-looking, id-free JSON form for snapshots and test vectors: nodes
/// renumbered by (dimension, id), edges as `[a, b, weight]` with a ≤ b, sorted.
///
/// # Examples
///
/// ```
/// use topomech::graph::{dual_graph, GraphJson, GraphKind};
/// use topomech::GMap;
///
/// let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
/// let json = GraphJson::of(&dual_graph(&map), GraphKind::Dual);
/// assert_eq!(json.kind, GraphKind::Dual);
/// assert_eq!(json.nodes, vec![3, 3]);
/// assert_eq!(json.edges, vec![[0, 1, 1]]); // ranks, not map ids
/// ```
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GraphJson {
    /// Which graph.
    pub kind: GraphKind,
    /// The dimension of each node.
    pub nodes: Vec<u8>,
    /// The edges `[a, b, multiplicity]`.
    pub edges: Vec<[u32; 3]>,
}

impl GraphJson {
    /// The JSON form of `g`. O(nodes + edges · log).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::graph::{vertex_edge_graph, GraphJson, GraphKind};
    /// use topomech::GMap;
    ///
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let json = GraphJson::of(&vertex_edge_graph(&map), GraphKind::VertexEdge);
    /// assert_eq!(json.nodes, vec![0, 0, 0, 0]); // four vertices (dimension 0)
    /// assert_eq!(json.edges.len(), 6);
    /// assert!(json.edges.windows(2).all(|w| w[0] < w[1]) && json.edges.iter().all(|e| e[0] <= e[1]));
    /// ```
    pub fn of(g: &CellGraph, kind: GraphKind) -> Self {
        let mut order: Vec<NodeIndex> = g.node_indices().collect();
        order.sort_by_key(|&n| g[n]);
        let mut rank = vec![0u32; g.node_count()];
        for (r, &n) in order.iter().enumerate() {
            rank[n.index()] = r as u32;
        }
        let mut edges: Vec<[u32; 3]> = g
            .edge_indices()
            .map(|e| {
                let (a, b) = g.edge_endpoints(e).expect("edge index from this graph");
                let (ra, rb) = (rank[a.index()], rank[b.index()]);
                [ra.min(rb), ra.max(rb), g[e]]
            })
            .collect();
        edges.sort_unstable();
        GraphJson { kind, nodes: order.iter().map(|&n| g[n].dim).collect(), edges }
    }

    /// Rebuilds a graph (node ids = ranks), checking that it is one that [`GraphJson::of`] can
    /// give: a simple graph (no two edges on one pair of nodes: the multiplicity is the weight),
    /// weights ≥ 1, node dimensions ≤ [`AlphaMask::MAX_INDEX`], and the shape of its kind (a
    /// 1-skeleton's nodes are vertices, a dual graph's nodes share one dimension, an incidence
    /// edge joins a k-cell and a (k+1)-cell). The errors ([`GraphJsonError`]) name the first
    /// node or edge at fault. O(nodes + edges · log edges).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::graph::{graphs_isomorphic, incidence_graph, GraphJson, GraphKind, Multiplicity};
    /// use topomech::GMap;
    ///
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let g = incidence_graph(&map);
    /// let json = GraphJson::of(&g, GraphKind::Incidence);
    /// assert_eq!(json.nodes.len(), 15);
    /// let back = json.to_graph().unwrap();
    /// assert!(graphs_isomorphic(&g, &back, Multiplicity::Match));
    /// ```
    pub fn to_graph(&self) -> Result<CellGraph, GraphJsonError> {
        let mut g = CellGraph::default();
        let nodes: Vec<NodeIndex> =
            self.nodes.iter().enumerate().map(|(i, &dim)| g.add_node(CellNode { dim, id: i as u32 })).collect();
        self.check_nodes()?;
        let mut seen = BTreeMap::new();
        for (k, &[a, b, w]) in self.edges.iter().enumerate() {
            let (Some(&na), Some(&nb)) = (nodes.get(a as usize), nodes.get(b as usize)) else {
                return Err(GraphJsonError::BadEndpoint { edge: k, nodes: nodes.len() });
            };
            if w == 0 {
                return Err(GraphJsonError::ZeroWeight { edge: k });
            }
            if let Some(&earlier) = seen.get(&(a.min(b), a.max(b))) {
                return Err(GraphJsonError::ParallelEdge { edge: k, earlier });
            }
            seen.insert((a.min(b), a.max(b)), k);
            let (da, db) = (self.nodes[a as usize], self.nodes[b as usize]);
            if self.kind == GraphKind::Incidence && da.abs_diff(db) != 1 {
                return Err(GraphJsonError::WrongShape {
                    what: format!("incidence edge {k} joins dimensions {da} and {db}"),
                });
            }
            g.add_edge(na, nb, w);
        }
        Ok(g)
    }

    /// The node part of [`GraphJson::to_graph`]'s checks. O(nodes).
    fn check_nodes(&self) -> Result<(), GraphJsonError> {
        if let Some(node) = self.nodes.iter().position(|&d| d as usize > AlphaMask::MAX_INDEX) {
            return Err(GraphJsonError::BadDimension { node, dim: self.nodes[node] });
        }
        let odd = match self.kind {
            GraphKind::VertexEdge => self.nodes.iter().position(|&d| d != 0),
            GraphKind::Dual => self.nodes.iter().position(|&d| d != self.nodes[0]),
            GraphKind::Incidence => None,
        };
        match odd {
            Some(node) => Err(GraphJsonError::WrongShape {
                what: format!("node {node} of dimension {} in a {:?} graph", self.nodes[node], self.kind),
            }),
            None => Ok(()),
        }
    }
}

/// Why a [`GraphJson`] does not describe a graph.
///
/// # Examples
///
/// ```
/// use topomech::graph::{GraphJson, GraphJsonError, GraphKind};
///
/// let json = GraphJson { kind: GraphKind::VertexEdge, nodes: vec![0, 0], edges: vec![[0, 1, 1], [1, 2, 1]] };
/// let err = json.to_graph().unwrap_err();
/// assert!(matches!(err, GraphJsonError::BadEndpoint { edge: 1, nodes: 2 }));
/// ```
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum GraphJsonError {
    /// An edge names a node that does not exist.
    #[error("edge {edge} has an endpoint out of range (the graph has {nodes} nodes)")]
    BadEndpoint {
        /// Index of the edge in the list.
        edge: usize,
        /// Number of nodes.
        nodes: usize,
    },
    /// An edge of multiplicity 0 (a multiplicity counts incidences: at least 1).
    #[error("edge {edge} has weight 0 (a multiplicity is at least 1)")]
    ZeroWeight {
        /// Index of the edge in the list.
        edge: usize,
    },
    /// Two edges on the same pair of nodes (the graphs are simple: the multiplicity is the
    /// weight of the one edge).
    #[error("edge {edge} joins the same pair of nodes as edge {earlier} (one edge per pair; the weight is the multiplicity)")]
    ParallelEdge {
        /// Index of the second edge in the list.
        edge: usize,
        /// Index of the first.
        earlier: usize,
    },
    /// A node dimension past the largest a map can have.
    #[error("node {node} has dimension {dim}, past the largest a map can have (7)")]
    BadDimension {
        /// Index of the node.
        node: usize,
        /// Its dimension.
        dim: u8,
    },
    /// A node or edge that does not fit the graph's kind.
    #[error("not a graph of its kind: {what}")]
    WrongShape {
        /// What does not fit.
        what: String,
    },
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two_triangles() -> GMap<2> {
        GMap::<2>::from_triangles(4, &[[0, 1, 2], [0, 2, 3]]).expect("valid triangles").0
    }

    /// `name` is the snake-case name used in JSON and by `Display`.
    #[test]
    fn each_kind_is_named_as_in_json() {
        for k in GraphKind::ALL {
            assert_eq!(serde_json::to_string(&k).expect("serialises"), format!("\"{}\"", k.name()));
            assert_eq!(k.to_string(), k.name());
        }
    }

    #[test]
    fn square_of_two_triangles_has_the_expected_graphs() {
        let map = two_triangles();
        let ve = vertex_edge_graph(&map);
        assert_eq!((ve.node_count(), ve.edge_count()), (4, 5));
        let dual = dual_graph(&map);
        assert_eq!((dual.node_count(), dual.edge_count()), (2, 1));
        let inc = incidence_graph(&map);
        assert_eq!(inc.node_count(), 4 + 5 + 2);
        assert_eq!(inc.edge_count(), 2 * 5 + 3 * 2);
        assert!(inc.edge_indices().all(|e| inc[e] == 1));
    }

    #[test]
    fn graph_json_round_trips_and_detects_bad_endpoints() {
        let g = incidence_graph(&two_triangles());
        let json = GraphJson::of(&g, GraphKind::Incidence);
        let back = json.to_graph().expect("valid json");
        assert!(graphs_isomorphic(&g, &back, Multiplicity::Match));
        let mut bad = json.clone();
        bad.edges.push([0, 999, 1]);
        assert!(matches!(bad.to_graph(), Err(GraphJsonError::BadEndpoint { .. })));
    }

    #[test]
    fn isomorphism_respects_dimension_labels() {
        let mut a = CellGraph::default();
        let x = a.add_node(CellNode { dim: 0, id: 0 });
        let y = a.add_node(CellNode { dim: 1, id: 0 });
        a.add_edge(x, y, 1);
        let mut b = CellGraph::default();
        let x = b.add_node(CellNode { dim: 0, id: 0 });
        let y = b.add_node(CellNode { dim: 0, id: 1 });
        b.add_edge(x, y, 1);
        assert!(!graphs_isomorphic(&a, &b, Multiplicity::Ignore));
        assert!(graphs_isomorphic(&a, &a.clone(), Multiplicity::Match));
    }
}
