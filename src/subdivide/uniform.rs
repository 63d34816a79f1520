//! Bulk uniform refinement: every cell of the finest level refined at once from fixed local
//! templates (issue 5, performance). Tetrahedra 1→8 in 3-G-maps, triangles 1→4 in 2-G-maps.
//!
//! # Template
//! A parent simplex has its corners labelled 0..=n from a root dart, and each of its darts is a
//! flag written as an ordered n-tuple of distinct corners (vertex, other end of the edge, third
//! corner of the face): 24 darts for a tet, 6 for a triangle. Edge midpoints get labels
//! n + 1 + (index of the corner pair), and the children are label sets (for tets the octahedron is
//! split around its shortest diagonal, [`super::tet`]'s rule, so there are three templates).
//! Each parent dart p owns a fixed number of child darts (8 for a tet, 4 for a triangle),
//! slot k of p, and slot 0 is p itself, which stays at its corner (only its α0 changes). For
//! p = (a, b, c) with missing corner d and midpoints m_xy:
//!
//! ```text
//!   tet   k = 0 (a, m_ab, m_ac)   k = 1 (m_ab, a, m_ac)   k = 2 (m_ab, m_ac, a)   in the corner child of a
//!         k = 3 (m_ab, m_ac, m_bc) in the child holding the face centre
//!         k = 4, 5 (m_ab, m_ac, m_ad) on both sides of the cut at corner a; k = 6, 7 the diagonal faces
//!   tri   k = 0 (a, m_ab)   k = 1 (m_ab, a)   k = 2 (m_ab, m_ac) in the corner child of a;   k = 3 (m_ab, m_ac) centre
//! ```
//! Slots 0..=3 (tets) and 0..=1 (triangles) lie on the parent's facets, and are defined from the
//! facet's corners only; so αn of child k of p is child k of αn(p), for any diagonal choice on
//! either side. Every other link is a template entry inside the parent.
//!
//! # Cell ids
//! Old ids stay where they were (corner vertices; the half of each parent edge at its end of
//! smaller vertex id; the centre child of each parent face; the corner child of label 0); new ids
//! are numbered from each allocator's `next`: per parent edge (first met) its midpoint and other
//! half, per parent face (3D) three cut edges and three corner faces (ordered by corner vertex
//! id, so both sides agree), per parent the inner cells.
//!
//! # Cost
//! O(darts), no hashing and no orbit walk: a check pass over the darts and a labelling pass over
//! the parents (both refuse before any change), then the write pass (old rows rewritten in place,
//! new rows appended in id order).

use super::tet::{child_tets, choose_diagonal};
use super::{LeveledMap, LinkChange, Mu, Refinement, SubdivideError, TetMasses};
use crate::gmap::DartId;

/// αn target of a slot on the parent's facet: child k of αn(parent dart).
const BORDER: u8 = u8::MAX;

/// Capacity of a parent's flat table of local cell ids (a tet has 10 + 25 + 24 + 8 = 67).
const FLAT: usize = 80;

/// How one local cell of a refined parent gets its global id.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Rule {
    /// A corner: its vertex id.
    Corner(u8),
    /// The midpoint of the parent edge with this pair index.
    Mid(u8),
    /// The half at corner x of the parent edge (x, y).
    Half { x: u8, y: u8 },
    /// The cut edge at corner x of the parent face missing corner w (3D).
    FaceInner { w: u8, x: u8 },
    /// The child face at corner x of the parent face missing corner w (3D).
    FaceCorner { w: u8, x: u8 },
    /// The centre child of the parent face missing corner w (3D): keeps the face's id.
    FaceCenter { w: u8 },
    /// The child of label set 0: keeps the parent's n-cell id.
    Old,
    /// The q-th cell of this dimension inside the parent: a fresh id.
    Inner(u8),
}

/// A refinement template for one dimension (and, for tets, one diagonal).
#[derive(Clone, Debug)]
struct Template {
    n: usize,
    /// Child darts per parent dart.
    per: usize,
    /// Parent darts as label tuples (first n entries used); index 0 is (0, 1, …).
    parents: Vec<[u8; 3]>,
    /// `act[p][j]`: the parent index of αj(p), j < n.
    act: Vec<[u8; 3]>,
    /// Spanning tree from parent 0: (target, source, j) with target = αj(source).
    tree: Vec<(u8, u8, u8)>,
    /// Per slot (p · per + k): the slot of αj, j ≤ n, or [`BORDER`] for αn on a facet.
    link: Vec<[u8; 4]>,
    /// Per slot: its local cell index in each dimension.
    cell: Vec<[u8; 4]>,
    /// Per dimension, per local cell: how its global id is found.
    rules: Vec<Vec<Rule>>,
    /// Per dimension: the number of [`Rule::Inner`] cells.
    inner: [u32; 4],
    /// Per corner pair index: a parent dart (x, y, …) on that edge.
    pair_parent: Vec<u8>,
    /// Per corner: a parent dart at it.
    corner_parent: [u8; 4],
    /// Per missing corner w (3D): a parent dart of the face without w.
    face_parent: [u8; 4],
    /// The children as label sets (n + 1 labels each).
    children: Vec<[u8; 4]>,
    /// The corner pairs (midpoint of pair i: label n + 1 + i).
    pairs: Vec<(u8, u8)>,
    /// Per child: its local n-cell index.
    child_cell: Vec<u8>,
    /// Per slot and dimension: the index of its cell in the flat id table of a parent (local
    /// index + offset of the dimension), filled by [`Template::flatten`].
    flat_cell: Vec<[u8; 4]>,
    /// Per slot (p · per + k): where each αj, j ≤ n, is found in a parent's dart table of
    /// 2 · P · per entries: the slot's own index below P · per (a template link), or P · per + the
    /// slot's index for αn on a facet (the table's second half holds child k of αn(parent dart)).
    /// Filled by [`Template::flatten`].
    gather: Vec<[u16; 4]>,
    /// The slots k < `border` of every parent dart lie on its facet ([`BORDER`] αn); the others
    /// have every link inside the parent.
    border: usize,
    /// Offset of each dimension in the flat id table.
    offset: [usize; 5],
}

/// The corner pairs of an n-simplex in order; the midpoint of pair i has label n + 1 + i.
fn pairs(n: usize) -> Vec<(u8, u8)> {
    let mut out = Vec::new();
    for x in 0..=n as u8 {
        for y in x + 1..=n as u8 {
            out.push((x, y));
        }
    }
    out
}

/// The ordered n-tuples of distinct labels of `set` (n + 1 labels), in lexicographic order of
/// positions in `set`.
fn tuples(n: usize, set: &[u8]) -> Vec<[u8; 3]> {
    let mut out = Vec::new();
    for a in 0..set.len() {
        for b in (0..set.len()).filter(|&b| b != a) {
            if n == 2 {
                out.push([set[a], set[b], 0]);
                continue;
            }
            for c in (0..set.len()).filter(|&c| c != a && c != b) {
                out.push([set[a], set[b], set[c]]);
            }
        }
    }
    out
}

/// αj of the flag `t` of the simplex with label set `set`: j < n − 1 swaps entries j and j + 1,
/// j = n − 1 replaces the last entry by the label of `set` not in the tuple.
fn flag_alpha(n: usize, set: &[u8], t: [u8; 3], j: usize) -> [u8; 3] {
    let mut out = t;
    if j + 1 < n {
        out.swap(j, j + 1);
    } else {
        let missing = set.iter().copied().find(|l| !t[..n].contains(l)).expect("n + 1 labels");
        out[n - 1] = missing;
    }
    out
}

/// The label of the midpoint of corners x and y: n + 1 + the index of the pair in `pr`.
fn midpoint_label(n: usize, pr: &[(u8, u8)], x: u8, y: u8) -> u8 {
    let i = pr.iter().position(|&p| p == (x.min(y), x.max(y))).expect("a corner pair");
    n as u8 + 1 + i as u8
}

/// The index in `parents` of the parent flag whose first n labels are those of `t`.
fn parent_index(n: usize, parents: &[[u8; 3]], t: [u8; 3]) -> u8 {
    parents.iter().position(|&p| p[..n] == t[..n]).expect("a parent flag") as u8
}

/// `act[p][j]`: the parent index of αj(p) for j < n.
fn parent_action(n: usize, corners: &[u8], parents: &[[u8; 3]]) -> Vec<[u8; 3]> {
    let act_of = |p: [u8; 3]| {
        let mut a = [0u8; 3];
        for (j, slot) in a.iter_mut().enumerate().take(n) {
            *slot = parent_index(n, parents, flag_alpha(n, corners, p, j));
        }
        a
    };
    parents.iter().map(|&p| act_of(p)).collect()
}

/// The child flags of the fixed slots of parent dart p = (a, b, c) (the table of the module
/// docs): the slots on the parent's facets, plus the centre slot of a triangle.
fn fixed_slots(n: usize, children: &[[u8; 4]], pr: &[(u8, u8)], p: [u8; 3]) -> Vec<(u8, [u8; 3])> {
    let mid = |x: u8, y: u8| midpoint_label(n, pr, x, y);
    let (a, b) = (p[0], p[1]);
    let other = |used: &[u8]| (0..=n as u8).find(|x| !used.contains(x)).expect("n + 1 corners");
    if n == 2 {
        let c = other(&[a, b]);
        return vec![
            (a, [a, mid(a, b), 0]),
            (a, [mid(a, b), a, 0]),
            (a, [mid(a, b), mid(a, c), 0]),
            (3, [mid(a, b), mid(a, c), 0]),
        ];
    }
    let (c, d) = (p[2], other(&p));
    let holder = |face: &[u8], not: Option<u8>| -> u8 {
        let found = (0..children.len() as u8)
            .find(|&k| Some(k) != not && face.iter().all(|l| children[k as usize][..=n].contains(l)));
        found.expect("a child holds the face")
    };
    let centre = [mid(a, b), mid(a, c), mid(b, c)];
    let cut = [mid(a, b), mid(a, c), mid(a, d)];
    // The corner child of a is child a.
    vec![
        (a, [a, mid(a, b), mid(a, c)]),
        (a, [mid(a, b), a, mid(a, c)]),
        (a, [mid(a, b), mid(a, c), a]),
        (holder(&centre, None), centre),
        (a, cut),
        (holder(&cut, Some(a)), cut),
    ]
}

/// Child darts per parent dart of an n-simplex split 1 → 2ⁿ (n ∈ {2, 3}): each of the 2ⁿ children
/// is an n-simplex with as many darts as its parent, (n + 1)!.
fn children_per_dart(n: usize) -> usize {
    if n == 3 {
        8
    } else {
        4
    }
}

/// The child flag of every slot (p · per + k): the fixed slots of each parent dart, then the
/// other child flags in order, one per remaining slot (a bijection).
fn slot_flags(n: usize, children: &[[u8; 4]], parents: &[[u8; 3]], pr: &[(u8, u8)]) -> Vec<(u8, [u8; 3])> {
    let per = children_per_dart(n);
    let mut flags: Vec<(u8, [u8; 3])> = Vec::new();
    for (c, set) in children.iter().enumerate() {
        flags.extend(tuples(n, &set[..=n]).into_iter().map(|t| (c as u8, t)));
    }
    let mut slot_flag: Vec<Option<(u8, [u8; 3])>> = vec![None; parents.len() * per];
    for (pi, &p) in parents.iter().enumerate() {
        for (k, f) in fixed_slots(n, children, pr, p).into_iter().enumerate() {
            slot_flag[pi * per + k] = Some(f);
        }
    }
    let mut rest = flags.iter().copied().filter(|f| !slot_flag.contains(&Some(*f))).collect::<Vec<_>>().into_iter();
    for s in slot_flag.iter_mut().filter(|s| s.is_none()) {
        *s = rest.next();
    }
    let slot_flag: Vec<(u8, [u8; 3])> = slot_flag.into_iter().map(|f| f.expect("a bijection")).collect();
    assert_eq!(slot_flag.len(), flags.len(), "template bug: slot count");
    slot_flag
}

/// Per slot: the slot of its αj for j < n (inside its child), and of its αn (the same flag in the
/// other child holding its facet) or [`BORDER`] when no other child holds it.
fn child_links(n: usize, children: &[[u8; 4]], slot_flag: &[(u8, [u8; 3])]) -> Vec<[u8; 4]> {
    let slot_of = |f: (u8, [u8; 3])| slot_flag.iter().position(|&g| g == f).expect("template bug: a flag") as u8;
    let link_of = |(c, t): (u8, [u8; 3])| {
        let set = &children[c as usize][..=n];
        let mut l = [BORDER; 4];
        for (j, slot) in l.iter_mut().enumerate().take(n) {
            *slot = slot_of((c, flag_alpha(n, set, t, j)));
        }
        let other =
            children.iter().enumerate().position(|(o, s)| o as u8 != c && t[..n].iter().all(|x| s[..=n].contains(x)));
        l[n] = other.map_or(BORDER, |o| slot_of((o as u8, t)));
        l
    };
    slot_flag.iter().map(|&f| link_of(f)).collect()
}

impl Template {
    /// The template of an n-simplex (n ∈ {2, 3}) whose children are `children`.
    fn new(n: usize, children: Vec<[u8; 4]>) -> Self {
        let corners: Vec<u8> = (0..=n as u8).collect();
        let pr = pairs(n);
        let parents = tuples(n, &corners);
        let act = parent_action(n, &corners, &parents);
        let tree = Self::spanning_tree(n, &act);
        let slot_flag = slot_flags(n, &children, &parents, &pr);
        let link = child_links(n, &children, &slot_flag);
        let pair_parent = pr
            .iter()
            .map(|&(x, y)| {
                let z = corners.iter().copied().find(|&z| z != x && z != y).expect("n ≥ 2");
                parent_index(n, &parents, [x, y, z])
            })
            .collect();
        let mut template = Template {
            n,
            per: children_per_dart(n),
            act,
            tree,
            link,
            cell: vec![[0; 4]; slot_flag.len()],
            rules: vec![Vec::new(); n + 1],
            inner: [0; 4],
            pair_parent,
            child_cell: Vec::new(),
            pairs: pr.clone(),
            flat_cell: Vec::new(),
            gather: Vec::new(),
            border: 0,
            offset: [0; 5],
            corner_parent: [0; 4],
            face_parent: [0; 4],
            children,
            parents,
        };
        template.fill_corner_and_face_parents();
        template.fill_cells(&slot_flag, &pr);
        template.flatten();
        template
    }

    /// The flat id table layout: dimension i's cells at `offset[i]..offset[i + 1]`.
    fn flatten(&mut self) {
        for i in 0..=self.n {
            self.offset[i + 1] = self.offset[i] + self.rules[i].len();
        }
        for i in self.n + 1..4 {
            self.offset[i + 1] = self.offset[i];
        }
        assert!(self.offset[self.n + 1] <= FLAT, "template bug: {} local cells", self.offset[self.n + 1]);
        self.flat_cell = self
            .cell
            .iter()
            .map(|c| [0, 1, 2, 3].map(|i| (self.offset[i.min(self.n)] + c[i] as usize) as u8))
            .collect();
        let (n, per, total) = (self.n, self.per, self.link.len());
        self.border = (0..per).take_while(|&k| self.link[k][n] == BORDER).count();
        self.gather = self
            .link
            .iter()
            .enumerate()
            .map(|(s, l)| {
                let on_facet = s % per < self.border;
                assert_eq!(l[n] == BORDER, on_facet, "template bug: facet slots are not the first of each flag");
                [0, 1, 2, 3].map(|j| if j == n && on_facet { (total + s) as u16 } else { l[j.min(n)] as u16 })
            })
            .collect();
    }

    /// BFS tree over the parent flags from flag 0.
    fn spanning_tree(n: usize, act: &[[u8; 3]]) -> Vec<(u8, u8, u8)> {
        let mut seen = vec![false; act.len()];
        seen[0] = true;
        let (mut order, mut tree) = (vec![0u8], Vec::new());
        let mut head = 0;
        while head < order.len() {
            let s = order[head];
            head += 1;
            for (j, &t) in act[s as usize].iter().enumerate().take(n) {
                if !seen[t as usize] {
                    seen[t as usize] = true;
                    order.push(t);
                    tree.push((t, s, j as u8));
                }
            }
        }
        tree
    }

    fn fill_corner_and_face_parents(&mut self) {
        let n = self.n;
        for x in 0..=n {
            self.corner_parent[x] = self.parents.iter().position(|p| p[0] as usize == x).expect("corner") as u8;
            if n == 3 {
                let found = self.parents.iter().position(|p| !p[..3].contains(&(x as u8)));
                self.face_parent[x] = found.expect("face") as u8;
            }
        }
    }

    /// Local cells (label sets, or the child for dimension n) and their rules.
    fn fill_cells(&mut self, slot_flag: &[(u8, [u8; 3])], pr: &[(u8, u8)]) {
        let n = self.n;
        for dim in 0..=n {
            let mut keys: Vec<[u8; 3]> = Vec::new();
            for (s, &(c, t)) in slot_flag.iter().enumerate() {
                let key = if dim == n {
                    [c, 0, 0]
                } else {
                    let mut k = [u8::MAX; 3];
                    k[..=dim].copy_from_slice(&t[..=dim]);
                    k.sort_unstable();
                    k
                };
                let local = match keys.iter().position(|&k| k == key) {
                    Some(i) => i,
                    None => {
                        if dim == n {
                            self.child_cell.resize(self.children.len(), 0);
                            self.child_cell[c as usize] = keys.len() as u8;
                        }
                        keys.push(key);
                        let rule = self.rule(dim, key, pr);
                        self.rules[dim].push(rule);
                        keys.len() - 1
                    }
                };
                self.cell[s][dim] = local as u8;
            }
        }
    }

    /// The rule of the local cell with key `key` (sorted labels, or [child, …] for dimension n).
    fn rule(&mut self, dim: usize, key: [u8; 3], pr: &[(u8, u8)]) -> Rule {
        let n = self.n;
        let nc = n as u8 + 1;
        let pair = |l: u8| pr[(l - nc) as usize];
        let mut fresh = || {
            self.inner[dim] += 1;
            Rule::Inner((self.inner[dim] - 1) as u8)
        };
        if dim == n {
            return if key[0] == 0 { Rule::Old } else { fresh() };
        }
        let labels = &key[..=dim];
        let corner: Vec<u8> = labels.iter().copied().filter(|&l| l < nc).collect();
        let mids: Vec<(u8, u8)> = labels.iter().copied().filter(|&l| l >= nc).map(pair).collect();
        let mut span: Vec<u8> = corner.iter().copied().chain(mids.iter().flat_map(|&(x, y)| [x, y])).collect();
        span.sort_unstable();
        span.dedup();
        let missing = (0..nc).find(|x| !span.contains(x)).unwrap_or(u8::MAX);
        match (dim, corner.len()) {
            (0, 1) => Rule::Corner(corner[0]),
            (0, _) => Rule::Mid(labels[0] - nc),
            (1, 1) => {
                let (x, y) = mids[0];
                Rule::Half { x: corner[0], y: if x == corner[0] { y } else { x } }
            }
            (1, _) if n == 3 && span.len() == 3 => {
                let shared = if mids[0].0 == mids[1].0 || mids[0].0 == mids[1].1 { mids[0].0 } else { mids[0].1 };
                Rule::FaceInner { w: missing, x: shared }
            }
            (2, 1) => Rule::FaceCorner { w: missing, x: corner[0] },
            (2, 0) if span.len() == 3 => Rule::FaceCenter { w: missing },
            _ => fresh(),
        }
    }
}

/// The templates of tets (one per diagonal label 4, 5, 6) or of triangles.
fn templates(n: usize) -> Vec<Template> {
    if n == 3 {
        (4..7u8).map(|diag| Template::new(3, child_tets(diag).into_iter().collect())).collect()
    } else {
        vec![Template::new(2, vec![[0, 3, 4, 0], [1, 3, 5, 0], [2, 4, 5, 0], [3, 4, 5, 0]])]
    }
}

/// What the check-and-label pass found: every parent's darts, its template, the parent edges
/// and faces (3D) with their first-met rank.
struct Labelled {
    /// Parent darts, `parents × P` (P = 24 or 6), in template order.
    darts: Vec<u32>,
    /// Template index per parent (the diagonal in 3D).
    template: Vec<u8>,
    /// Slot of every old dart in `darts` (parent index · P + flag index), `u32::MAX` if none.
    slot_of: Vec<u32>,
    /// Per slot: the slot of αn of its dart (its own slot where αn is free), set when the
    /// later of the two parents is labelled, so that the write pass reads it in slot order.
    across: Vec<u32>,
    /// Rank of each edge id (first met), `u32::MAX` if none.
    edge_rank: Vec<u32>,
    /// The parent edges by rank, as (vertex id, vertex id).
    edges: Vec<(u32, u32)>,
    /// The edge cell id of each parent edge, by rank.
    edge_ids: Vec<u32>,
    /// A dart of each parent edge, by rank (for the precision check of its midpoint).
    edge_darts: Vec<u32>,
    /// Rank of each face id (3D).
    face_rank: Vec<u32>,
    faces: u32,
}

impl<const N: usize> LeveledMap<N> {
    /// The common resolution level m of every dart, checking the uniform preconditions: μ = (m, m,
    /// m) in 3D ((m, m, 0) in 2D), m < level, no inserted (flat) vertex, α0…α(n−1) closed.
    fn uniform_level(&self, level: u8) -> Result<u8, SubdivideError> {
        self.check_op_level(level)?;
        let Some(first) = self.map.darts().next() else { return Ok(0) };
        let m = self.mu[first.index()].face;
        let expected = Mu { edge: m, face: m, tet: if N == 3 { m } else { 0 } };
        for d in self.map.darts() {
            let mu = self.mu[d.index()];
            if mu != expected || self.flat[d.index()] {
                return Err(SubdivideError::NotUniform { dart: d, mu, expected: m });
            }
            if (0..N).any(|j| self.map.is_free(j, d)) {
                return Err(SubdivideError::OpenEdge(d));
            }
        }
        if m >= level {
            return Err(SubdivideError::AlreadyAtLevel { dart: first, dim: N, cell_level: m, level });
        }
        // Every n-simplex becomes 2^n, each with as many darts as its parent.
        let darts = self.map.dart_count();
        let per_cell = if N == 3 { 24 } else { 6 };
        self.check_dart_limit(level, darts / per_cell, darts.saturating_mul(1 << N))?;
        Ok(m)
    }

    /// Labels every n-cell as a parent simplex (refusing cells that are not simplices with n + 1
    /// distinct corners) and ranks the parent edges and faces. No change to the map.
    fn label_parents(&self, tpl: &[Template]) -> Result<Labelled, SubdivideError> {
        let t0 = &tpl[0];
        let p = t0.parents.len();
        let cap = self.map.capacity();
        // Every buffer gets its final size (or an upper bound) at once: no growth by doubling.
        let edge_bound = self.map.cell_id_bound(1);
        let mut out = Labelled {
            darts: Vec::with_capacity(self.map.dart_count()),
            template: Vec::with_capacity(self.map.dart_count() / p),
            slot_of: vec![u32::MAX; cap],
            across: Vec::with_capacity(self.map.dart_count()),
            edge_rank: vec![u32::MAX; edge_bound],
            edges: Vec::with_capacity(edge_bound),
            edge_ids: Vec::with_capacity(edge_bound),
            edge_darts: Vec::with_capacity(edge_bound),
            face_rank: vec![u32::MAX; if N == 3 { self.map.cell_id_bound(2) } else { 0 }],
            faces: 0,
        };
        let mut lab = vec![0u32; p];
        for d in self.map.darts() {
            if out.slot_of[d.index()] != u32::MAX {
                continue;
            }
            let first_slot = out.darts.len() as u32;
            lab[0] = d.0;
            for &(t, s, j) in &t0.tree {
                lab[t as usize] = self.map.alpha_dyn(j as usize, DartId(lab[s as usize])).0;
            }
            let not_simplex = |corners| SubdivideError::NotATetrahedron { dart: d, corners };
            for (f, &x) in lab.iter().enumerate() {
                if out.slot_of[x as usize] != u32::MAX {
                    return Err(not_simplex(0));
                }
                out.slot_of[x as usize] = first_slot + f as u32;
            }
            for (f, &x) in lab.iter().enumerate() {
                for j in 0..N {
                    if self.map.alpha_dyn(j, DartId(x)).0 != lab[t0.act[f][j] as usize] {
                        return Err(not_simplex(0));
                    }
                }
            }
            let mut vids = [0u32; 4];
            for (c, v) in vids.iter_mut().enumerate().take(N + 1) {
                *v = self.map.vertex_id(DartId(lab[t0.corner_parent[c] as usize])).0;
            }
            let distinct = (0..=N).all(|a| (a + 1..=N).all(|b| vids[a] != vids[b]));
            if !distinct {
                let mut v = vids[..=N].to_vec();
                v.sort_unstable();
                v.dedup();
                return Err(not_simplex(v.len()));
            }
            for (f, &x) in lab.iter().enumerate() {
                let s = first_slot + f as u32;
                let y = self.map.alpha_dyn(N, DartId(x)).0;
                let t = out.slot_of[y as usize];
                out.across.push(if y == x { s } else { t });
                if y != x && t != u32::MAX {
                    out.across[t as usize] = s;
                }
            }
            out.template.push(if N == 3 { self.diagonal_template(&vids, &lab, t0) } else { 0 });
            self.rank_cells(&lab, t0, &vids, &mut out);
            out.darts.extend_from_slice(&lab);
        }
        Ok(out)
    }

    /// Ranks the parent's edges and faces at first meeting.
    fn rank_cells(&self, lab: &[u32], t0: &Template, vids: &[u32], out: &mut Labelled) {
        for (k, &(x, y)) in t0.pairs.iter().enumerate() {
            let dart = lab[t0.pair_parent[k] as usize];
            let e = self.map.cell_id(1, DartId(dart)).index();
            if out.edge_rank[e] == u32::MAX {
                out.edge_rank[e] = out.edges.len() as u32;
                out.edges.push((vids[x as usize], vids[y as usize]));
                out.edge_ids.push(e as u32);
                out.edge_darts.push(dart);
            }
        }
        if N == 3 {
            for w in 0..4 {
                let f = self.map.cell_id(2, DartId(lab[t0.face_parent[w] as usize])).index();
                if out.face_rank[f] == u32::MAX {
                    out.face_rank[f] = out.faces;
                    out.faces += 1;
                }
            }
        }
    }

    /// The template index (diagonal label − 4) of a parent tet, by [`choose_diagonal`].
    fn diagonal_template(&self, vids: &[u32], lab: &[u32], t0: &Template) -> u8 {
        let corner = [0, 1, 2, 3].map(|c| self.vertex_pos(vids[c]));
        let pr = [(0u8, 1u8), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];
        let mut pos = [[0.0; 3]; 6];
        let mut mid_vid = [0u32; 6];
        for (k, &(x, y)) in pr.iter().enumerate() {
            let (a, b) = (corner[x as usize], corner[y as usize]);
            pos[k] = crate::mesh::midpoint(a, b);
            // Ids only break ties between coincident midpoints; any per-edge number will do.
            mid_vid[k] = self.map.cell_id(1, DartId(lab[t0.pair_parent[k] as usize])).0;
        }
        choose_diagonal(&pos, &mid_vid) - 4
    }

    /// [`SubdivideError::BelowPrecision`] for the first parent edge (in rank order) whose
    /// midpoint f64 cannot hold strictly between its ends (`check_midpoint`); then
    /// [`SubdivideError::FlatChild`] (3D) or [`SubdivideError::FlatTriangleChild`] (2D) for the
    /// first parent with a flat or inverted child (`check_children`, `check_triangle_children`).
    /// O(edges + parents).
    fn check_uniform_midpoints(&self, level: u8, tpl: &[Template], lab: &Labelled) -> Result<(), SubdivideError> {
        for &x in &lab.edge_darts {
            self.check_midpoint(DartId(x), level)?;
        }
        if N == 3 {
            // And the children of every parent ([`SubdivideError::FlatChild`]), in parent order;
            // its darts are labelled in the order of the first template, as its corners.
            let t0 = &tpl[0];
            for darts in lab.darts.chunks_exact(t0.parents.len()) {
                let corners = t0.corner_parent.map(|p| self.map.vertex_id(DartId(darts[p as usize])).0);
                self.check_children(DartId(darts[0]), level, &corners)?;
            }
        } else {
            // 2D: the children of every triangle ([`SubdivideError::FlatTriangleChild`]); a
            // uniform map has no inserted vertex, so every midpoint is the rounded one.
            let t0 = &tpl[0];
            for darts in lab.darts.chunks_exact(t0.parents.len()) {
                let corners: [u32; 3] =
                    std::array::from_fn(|c| self.map.vertex_id(DartId(darts[t0.corner_parent[c] as usize])).0);
                self.check_triangle_children(DartId(darts[0]), level, corners, [None; 3])?;
            }
        }
        Ok(())
    }

    fn vertex_pos(&self, v: u32) -> [f64; 3] {
        self.points.get(v as usize).copied().unwrap_or([0.0; 3])
    }

    /// The write pass: grows the map and every record once (exact sizes, no doubling), writes
    /// the children of every parent. Returns the new n-cell ids per parent (child c at
    /// `parent * children + c`) when `children` is set, else an empty vector.
    fn write_uniform(&mut self, level: u8, tpl: &[Template], lab: &Labelled, children: bool) -> Vec<u32> {
        let t0 = &tpl[0];
        let (p, per, border) = (t0.parents.len(), t0.per, t0.border);
        let parents = lab.template.len();
        let fresh = p * (per - 1);
        let base = self.map.capacity();
        let cap = base + parents * fresh;
        self.map.reserve_darts_raw(parents * fresh);
        let mu = Mu { edge: level, face: level, tet: if N == 3 { level } else { 0 } };
        grow_exact(&mut self.dart_level, cap, level);
        grow_exact(&mut self.mu, cap, mu);
        grow_exact(&mut self.flat, cap, false);
        // Only the old darts get a change; the new ones have an empty history (no head).
        self.history.cover(base);
        self.history.reserve(lab.darts.len());
        let next: Vec<u32> = (0..=N).map(|i| self.map.id_alloc_raw(i).0).collect();
        let (ne, nf) = (lab.edges.len() as u32, lab.faces);
        // Ids shared between parents (per parent edge / face), then the per-parent ones.
        let shared = [ne, ne + if N == 3 { 3 * nf } else { 0 }, if N == 3 { 3 * nf } else { 0 }, 0];
        let inner_base: Vec<u32> = (0..=N).map(|i| next[i] + shared[i]).collect();
        let mut ids = [0u32; FLAT];
        // The parent's dart table (`Template::gather`): slot s's dart at s, child k of αn(parent
        // dart f) at P · per + f · per + k.
        let mut table = [0u32; 2 * 192];
        let mut old_alpha0 = [0u32; 24];
        let (mut new_alpha, mut new_cell) = (vec![0u32; fresh * (N + 1)], vec![0u32; fresh * (N + 1)]);
        let mut child_ids = Vec::with_capacity(if children { parents * t0.children.len() } else { 0 });
        let half = p * per;
        for parent in 0..parents {
            let tp = &tpl[lab.template[parent] as usize];
            let darts = &lab.darts[parent * p..(parent + 1) * p];
            self.local_ids(tp, darts, parent as u32, &next, &inner_base, lab, &mut ids);
            if children {
                child_ids.extend(tp.child_cell.iter().map(|&local| ids[tp.offset[N] + local as usize]));
            }
            let first = base + parent * fresh;
            let (alpha, cell) = self.map.rows_mut_raw();
            for (f, &old) in darts.iter().enumerate() {
                let row = old as usize * (N + 1);
                let across = alpha[row + N];
                old_alpha0[f] = alpha[row];
                let own = f * per;
                table[own] = old;
                for k in 1..per {
                    table[own + k] = (first + f * (per - 1) + k - 1) as u32;
                }
                // Child k of the dart across the facet: the same slot of αn(old), or the own
                // child on the boundary.
                if across == old {
                    table.copy_within(own..own + border, half + own);
                } else {
                    let q_first = base + lab.across[parent * p + f] as usize * (per - 1);
                    table[half + own] = across;
                    for k in 1..border {
                        table[half + own + k] = (q_first + k - 1) as u32;
                    }
                }
            }
            // Old darts (slot 0) are rewritten in place; the new ones go to a buffer appended
            // below in id order (slot f · per + k at buffer row f · (per − 1) + k − 1).
            let rows = new_alpha.chunks_exact_mut(N + 1).zip(new_cell.chunks_exact_mut(N + 1));
            let mut rows = rows.take(fresh);
            for (f, &old) in darts.iter().enumerate() {
                let own = f * per;
                let row = old as usize * (N + 1);
                let (g, fc) = (&tp.gather[own], &tp.flat_cell[own]);
                for i in 0..=N {
                    alpha[row + i] = table[g[i] as usize];
                    cell[row + i] = ids[fc[i] as usize];
                }
                for (s, (alpha_row, cell_row)) in (own + 1..own + per).zip(rows.by_ref()) {
                    let (g, fc) = (&tp.gather[s], &tp.flat_cell[s]);
                    for i in 0..=N {
                        alpha_row[i] = table[g[i] as usize];
                        cell_row[i] = ids[fc[i] as usize];
                    }
                }
            }
            for (&old, &alpha0) in darts.iter().zip(&old_alpha0) {
                self.history.push(old as usize, LinkChange { level, j: 0, old: alpha0 });
                self.mu[old as usize] = mu;
            }
            let at = self.map.push_rows_raw(&new_alpha, &new_cell);
            debug_assert_eq!(at as usize, first);
        }
        for i in 0..=N {
            let free = self.map.id_alloc_raw(i).1.to_vec();
            let added = shared[i] + parents as u32 * t0.inner[i];
            self.map.set_id_alloc_raw(i, next[i] + added, free);
        }
        self.write_midpoints(&next, lab);
        self.max_level = level;
        self.bump_version();
        child_ids
    }

    /// The global id of every local cell of one parent, by the template's rules, into the flat
    /// table `ids` (dimension i at `tp.offset[i]..`).
    #[allow(clippy::too_many_arguments)]
    fn local_ids(
        &self,
        tp: &Template,
        darts: &[u32],
        parent: u32,
        next: &[u32],
        inner_base: &[u32],
        lab: &Labelled,
        ids: &mut [u32; FLAT],
    ) {
        let map = &self.map;
        let mut vid = [0u32; 4];
        for x in 0..=N {
            vid[x] = map.vertex_id(DartId(darts[tp.corner_parent[x] as usize])).0;
        }
        let mut edge = [0u32; 6];
        let mut edge_rank = [0u32; 6];
        for k in 0..tp.pair_parent.len() {
            edge[k] = map.cell_id(1, DartId(darts[tp.pair_parent[k] as usize])).0;
            edge_rank[k] = lab.edge_rank[edge[k] as usize];
        }
        let (mut face, mut face_rank) = ([0u32; 4], [0u32; 4]);
        if N == 3 {
            for w in 0..4 {
                face[w] = map.cell_id(2, DartId(darts[tp.face_parent[w] as usize])).0;
                face_rank[w] = lab.face_rank[face[w] as usize];
            }
        }
        let old = map.cell_id(N, DartId(darts[0])).0;
        let pr_index = |x: u8, y: u8| -> usize {
            let (a, b) = (x.min(y) as usize, x.max(y) as usize);
            // Pair index in lexicographic order of (a, b) over 0..=N.
            (0..a).map(|i| N - i).sum::<usize>() + (b - a - 1)
        };
        let rank_in_face = |w: u8, x: u8| -> u32 {
            (0..4u8).filter(|&c| c != w && c != x && vid[c as usize] < vid[x as usize]).count() as u32
        };
        let ne = lab.edges.len() as u32;
        for (dim, rules) in tp.rules.iter().enumerate() {
            for (local, rule) in rules.iter().enumerate() {
                ids[tp.offset[dim] + local] = match *rule {
                    Rule::Corner(x) => vid[x as usize],
                    Rule::Mid(k) => next[0] + edge_rank[k as usize],
                    Rule::Half { x, y } => {
                        let k = pr_index(x, y);
                        if vid[x as usize] < vid[y as usize] {
                            edge[k]
                        } else {
                            next[1] + edge_rank[k]
                        }
                    }
                    Rule::FaceInner { w, x } => next[1] + ne + 3 * face_rank[w as usize] + rank_in_face(w, x),
                    Rule::FaceCorner { w, x } => next[2] + 3 * face_rank[w as usize] + rank_in_face(w, x),
                    Rule::FaceCenter { w } => face[w as usize],
                    Rule::Old => old,
                    Rule::Inner(q) => inner_base[dim] + parent * tp.inner[dim] + q as u32,
                };
            }
        }
    }

    /// Positions of the new vertices (edge midpoints), the split log and the edge split log (the
    /// half at the smaller end vertex keeps the parent edge's id, `local_ids`' `Half` rule).
    fn write_midpoints(&mut self, next: &[u32], lab: &Labelled) {
        let first = next[0];
        let end = first as usize + lab.edges.len();
        if !self.points.is_empty() && self.points.len() < end {
            grow_exact(&mut self.points, end, [0.0; 3]);
        }
        self.splits.reserve_exact(lab.edges.len());
        self.edge_splits.reserve_exact(lab.edges.len());
        for (r, &(a, b)) in lab.edges.iter().enumerate() {
            let v = first + r as u32;
            self.splits.push([v, a, b]);
            let (edge, fresh) = (lab.edge_ids[r], next[1] + r as u32);
            let halves = if a < b { [edge, fresh] } else { [fresh, edge] };
            self.edge_splits.push(super::EdgeSplit { vertex: v, ends: [a, b], edge, halves });
            if !self.points.is_empty() {
                let (pa, pb) = (self.vertex_pos(a), self.vertex_pos(b));
                self.points[v as usize] = crate::mesh::midpoint(pa, pb);
            }
        }
    }
}

impl LeveledMap<3> {
    /// Refines every tetrahedron of the finest level 1→8 at level `level` in one bulk pass (module
    /// docs of `uniform`), with the same result, up to dart and cell numbering, as
    /// [`Self::subdivide_tet`] on every tet in any order: same levels G_0..G_level, dart levels, μ,
    /// link history, midpoints and diagonal choice. The tet masses are shared among the children
    /// by [`Self::subdivide_tet_with_mass`]'s rule. Returns the count (at index `level`) and the
    /// mass totals. O(darts), no hashing.
    ///
    /// Preconditions, refused with the map and the masses unchanged: the level-order errors;
    /// [`SubdivideError::NotUniform`] (a dart off the common level m, or an inserted vertex);
    /// [`SubdivideError::AlreadyAtLevel`] (m ≥ `level`); [`SubdivideError::OpenEdge`] (an α0-,
    /// α1- or α2-free dart); [`SubdivideError::NotATetrahedron`] (a volume that is not a tet of
    /// 24 darts with four distinct corner vertices); those of [`TetMasses::check`] (a live
    /// volume without a finite mass ≥ 0 in `masses`); [`SubdivideError::NoPosition`] and
    /// [`SubdivideError::NonFinitePosition`] (the smallest live vertex without a position, or
    /// with a NaN or infinite one: the masses follow the children's volumes);
    /// [`SubdivideError::NonFinitePosition`] (an end of an edge to
    /// split at a NaN or infinite position), [`SubdivideError::BelowPrecision`] (an edge whose midpoint f64 cannot hold strictly
    /// between its ends).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::subdivide::{LeveledMap, TetMasses};
    /// use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mut m = LeveledMap::new(map, pts);
    /// let mut masses = TetMasses::from_density(&m, 6.0).unwrap();
    /// let r = m.refine_uniform(1, &mut masses).unwrap();
    /// assert_eq!((r.subdivided_per_level, m.map().count_cells().0), (vec![0, 1], vec![10, 25, 24, 8]));
    /// assert!((r.total_mass_after - 1.0).abs() < 1e-12);
    /// assert!(m.refine_uniform(1, &mut masses).is_err()); // already at level 1
    /// assert!(m.check_all().is_ok());
    /// ```
    pub fn refine_uniform(&mut self, level: u8, masses: &mut TetMasses) -> Result<Refinement, SubdivideError> {
        self.uniform_level(level)?;
        masses.check(self)?;
        // The children's masses come from their volumes: like `subdivide_tet_with_mass`, refuse
        // a live vertex without a position or with a NaN or infinite one (finding 70).
        self.check_positions_given()?;
        self.check_positions_finite()?;
        let tpl = templates(3);
        let lab = self.label_parents(&tpl)?;
        self.check_uniform_midpoints(level, &tpl, &lab)?;
        let parents = lab.template.len();
        let parent_mass: Vec<f64> = (0..parents)
            .map(|t| masses.check_split_mass(self.map.cell_id(3, DartId(lab.darts[t * 24]))))
            .collect::<Result<_, _>>()?;
        let child = self.write_uniform(level, &tpl, &lab, true);
        masses.mass.resize(self.map.cell_id_bound(3).max(masses.mass.len()), 0.0);
        let (mut before, mut after) = (0.0, 0.0);
        for (t, &m) in parent_mass.iter().enumerate() {
            let tp = &tpl[lab.template[t] as usize];
            let volumes = self.child_volumes(tp, &lab.darts[t * 24..(t + 1) * 24]);
            let total: f64 = volumes.iter().sum();
            let mut given = 0.0;
            for (c, &v) in volumes.iter().enumerate() {
                let share = if c + 1 == volumes.len() {
                    (m - given).max(0.0) // the rest, ≥ 0 (as in `subdivide_tet_with_mass`)
                } else if total > 0.0 {
                    super::region::share(m, v, total)
                } else {
                    m / volumes.len() as f64
                };
                given += share;
                masses.mass[child[t * 8 + c] as usize] = share;
                after += share;
            }
            before += m;
        }
        self.after_uniform();
        let mut per_level = vec![0; level as usize + 1];
        per_level[level as usize] = parents;
        Ok(Refinement { subdivided_per_level: per_level, total_mass_before: before, total_mass_after: after })
    }

    /// |volume| of each child of a refined parent, from the corner positions and the midpoints,
    /// up to one common factor (`geom::volume_ratios`: 1 for ordinary corners).
    fn child_volumes(&self, tp: &Template, darts: &[u32]) -> [f64; 8] {
        let mut pos = [[0.0; 3]; 10];
        for x in 0..4 {
            pos[x] = self.vertex_pos(self.map.vertex_id(DartId(darts[tp.corner_parent[x] as usize])).0);
        }
        for (k, &(x, y)) in tp.pairs.iter().enumerate() {
            pos[4 + k] = crate::mesh::midpoint(pos[x as usize], pos[y as usize]);
        }
        // Only the ratios are used: one common scale keeps them finite for any finite corners.
        crate::mechanics::geom::volume_ratios(std::array::from_fn(|c| tp.children[c].map(|l| pos[l as usize])))
    }
}

impl LeveledMap<2> {
    /// Refines every triangle of the finest level 1→4 at level `level` in one bulk pass (module
    /// docs of `uniform`), with the same result, up to dart and cell numbering, as
    /// [`Self::subdivide_triangle`] on every face: same levels G_0..G_level, dart levels, μ, link
    /// history and midpoints. Returns the number of triangles refined. O(darts), no hashing.
    ///
    /// Preconditions, refused with the map unchanged: the level-order errors;
    /// [`SubdivideError::NotUniform`]; [`SubdivideError::AlreadyAtLevel`];
    /// [`SubdivideError::OpenEdge`] (an α0- or α1-free dart); [`SubdivideError::NotATetrahedron`]
    /// (here: a face that is not a triangle of 6 darts with three distinct corner vertices);
    /// [`SubdivideError::NonFinitePosition`] (an end of an edge to
    /// split at a NaN or infinite position), [`SubdivideError::BelowPrecision`] (an edge whose midpoint f64 cannot hold strictly
    /// between its ends; with points only), [`SubdivideError::FlatTriangleChild`] (a triangle
    /// so nearly collinear that a child would be collinear or inverted; with points only).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::subdivide::LeveledMap;
    /// use topomech::GMap;
    /// let (map, _) = GMap::<2>::from_triangles(4, &[[0, 1, 2], [1, 3, 2]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]];
    /// let mut m = LeveledMap::new(map, pts);
    /// assert_eq!(m.refine_uniform(1).unwrap(), 2);
    /// assert_eq!(m.map().count_cells().0, vec![9, 16, 8]);
    /// assert_eq!(m.level(0).unwrap().map.count_cells().0, vec![4, 5, 2]);
    /// assert!(m.check_all().is_ok());
    /// ```
    pub fn refine_uniform(&mut self, level: u8) -> Result<usize, SubdivideError> {
        self.uniform_level(level)?;
        let tpl = templates(2);
        let lab = self.label_parents(&tpl)?;
        self.check_uniform_midpoints(level, &tpl, &lab)?;
        self.write_uniform(level, &tpl, &lab, false);
        self.after_uniform();
        Ok(lab.template.len())
    }
}

impl<const N: usize> LeveledMap<N> {
    /// The checks after a bulk refinement: the whole map in debug builds, and every law of the
    /// leveled map (`check_all`: levels, μ order, flat vertices) under `expensive-checks`
    /// (finding 327). A failure is a bug of this module.
    fn after_uniform(&self) {
        self.expensive_check_all("uniform refinement");
        #[cfg(all(debug_assertions, not(feature = "expensive-checks")))]
        if let Err(e) = self.map.validate() {
            panic!("topomech bug: uniform refinement broke the map: {e}");
        }
    }
}

/// Grows `v` to `len` entries of `value` with one allocation of exactly that size (`resize`
/// alone may double the capacity: a copy and fresh pages for room that is never used).
fn grow_exact<T: Clone>(v: &mut Vec<T>, len: usize, value: T) {
    if len > v.len() {
        v.reserve_exact(len - v.len());
        v.resize(len, value);
    }
}
