//! The fast path of [`GMap::validate`] for a map whose tets are as built: while
//! [`Law::TetLayout`](super::Law::TetLayout) holds, the laws are restated on tets instead of darts.
//!
//! The layout law says that α0, α1, α2 inside every block of 24 darts are the builder's pattern
//! (`build::TET_LINKS`). Facts of that pattern (checked by the tests below):
//! * α0, α1 and α2 are involutions without fixed point and α0α2 is an involution: nothing of
//!   them is left to check;
//! * inside one tet, the orbit of ⟨αj : j < 3, j ≠ i⟩ of a dart is its *piece* of dimension i:
//!   its corner (6 darts), its edge (4 darts), its face (6 darts), the tet (24 darts). So the
//!   i-cell id is constant under those αj iff it is constant on every piece, an i-cell is a class
//!   of pieces joined by α3, and a volume is exactly one tet.
//!
//! The layout law itself is checked in the same pass, block by block. What is left reads each
//! dart's own block and the row of its α3 image: α3 is an involution, commutes with α0 and α1,
//! and carries the vertex, edge and face ids across; every piece's id is live. Uniqueness is
//! then counted on pieces: #volumes = #tets; a face is one piece or two glued by α3; vertices
//! and edges are the classes of a union-find over the 4 and 6 pieces of every tet, joined across
//! each glued face at three of its darts (the other three are their α0 or α1 images, which α3
//! commutes with and which stay in the same corner and edge).
//!
//! Cost: one sequential pass over the rows, reading one α3 image per dart, plus O(tets · α(tets))
//! union-find; the generic path reads the rows of all n + 1 neighbours of every dart and unions
//! darts, not pieces.

use super::orbit::{find_root, VisitBits};
use super::GMap;
use crate::build::{built_tet_link, built_tet_links, TET_DART_CORNER, TET_DART_EDGE, TET_LINKS};

/// The number of pieces of one tet per cell dimension: corners, edges, faces, the tet.
pub(super) const PIECES: [usize; 4] = [4, 6, 4, 1];

/// Per dart offset k in a tet and cell dimension: the index of k's piece in its tet.
const PIECE: [[u8; 4]; 24] = {
    let mut piece = [[0u8; 4]; 24];
    let mut k = 0;
    while k < 24 {
        piece[k] = [TET_DART_CORNER[k], TET_DART_EDGE[k], (k / 6) as u8, 0];
        k += 1;
    }
    piece
};

/// Per cell dimension and piece index: the offset of the piece's first dart.
const FIRST_OF_PIECE: [[u8; 6]; 4] = {
    let mut first = [[u8::MAX; 6]; 4];
    let mut k = 24;
    while k > 0 {
        k -= 1;
        let mut dim = 0;
        while dim < 4 {
            first[dim][PIECE[k][dim] as usize] = k as u8;
            dim += 1;
        }
    }
    first
};

/// Per dart offset k and cell dimension: the offset of the first dart of k's piece.
const FIRST: [[u8; 4]; 24] = {
    let mut first = [[0u8; 4]; 24];
    let mut k = 0;
    while k < 24 {
        let mut dim = 0;
        while dim < 4 {
            first[k][dim] = FIRST_OF_PIECE[dim][PIECE[k][dim] as usize];
            dim += 1;
        }
        k += 1;
    }
    first
};

/// The darts (offsets in a face's 6) whose α3 images join a glued face's corners and edges: the
/// flags (a, ab), (b, bc), (c, ca), one per corner and one per edge.
const FACE_JOINERS: [usize; 3] = [0, 2, 4];

/// The global index of dart x's piece of dimension dim (pieces of tet t numbered after those of
/// the tets before it).
#[inline(always)]
pub(super) fn piece_of(dim: usize, x: u32) -> u32 {
    (x / 24) * PIECES[dim] as u32 + u32::from(PIECE[(x % 24) as usize][dim])
}

/// Joins the trees of a and b in a union-find forest whose roots are the smallest elements of
/// their trees; whether they were apart. O(α(len)).
#[inline(always)]
pub(super) fn join(forest: &mut [u32], a: u32, b: u32) -> bool {
    let (ra, rb) = (find_root(forest, a), find_root(forest, b));
    if ra == rb {
        return false;
    }
    let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
    forest[hi as usize] = lo;
    true
}

/// What the tet sweep counts, per cell dimension: the distinct ids of the pieces, and what
/// gives the number of cells (faces counted directly, vertices and edges by union-find).
struct PieceCensus {
    /// The ids seen so far, one set per dimension.
    used: Vec<VisitBits>,
    /// The number of distinct ids seen, per dimension.
    distinct: [usize; 4],
    /// Face pieces that are free or glued to a face piece numbered no lower: one per face.
    glued_or_free_faces: usize,
    /// Union-find forest over the 4 corner pieces of every tet.
    vertex_forest: Vec<u32>,
    /// Union-find forest over the 6 edge pieces of every tet.
    edge_forest: Vec<u32>,
    /// Successful joins in the vertex and the edge forest.
    joins: [usize; 2],
}

impl<const N: usize> GMap<N> {
    /// The number of tets when n = 3, the dart slots are whole blocks of 24 and every slot is
    /// live (what the tet paths need before reading blocks); `None` otherwise. O(1).
    pub(super) fn live_tet_blocks(&self) -> Option<usize> {
        (N == 3 && self.capacity() % 24 == 0 && self.dart_count() == self.capacity()).then(|| self.capacity() / 24)
    }

    /// Whether every law holds, for a 3-map flagged [`GMap::tets_as_built`], the tet layout law
    /// included (checked here, block by block, in the same pass: any other map gets `false`).
    /// Where the layout law holds, same verdict as the generic fast path. `dead[dim]`: the freed
    /// ids (`None` if none); `live[dim]`: the number of live ids. O(darts + tets · α(tets)).
    pub(super) fn built_tet_laws_hold(&self, dead: &[Option<VisitBits>], live: &[usize]) -> bool {
        let Some(tets) = self.live_tet_blocks() else {
            return false;
        };
        let mut census = PieceCensus {
            used: self.ids.iter().map(|a| VisitBits::new(a.next as usize)).collect(),
            distinct: [0; 4],
            glued_or_free_faces: 0,
            vertex_forest: (0..(PIECES[0] * tets) as u32).collect(),
            edge_forest: (0..(PIECES[1] * tets) as u32).collect(),
            joins: [0; 2],
        };
        for t in 0..tets {
            if !self.tet_darts_hold(t) || !self.tet_piece_ids_live(t, dead, &mut census) {
                return false;
            }
            self.glue_tet_faces(t, &mut census);
        }
        let orbits =
            [PIECES[0] * tets - census.joins[0], PIECES[1] * tets - census.joins[1], census.glued_or_free_faces, tets];
        census
            .distinct
            .iter()
            .zip(live)
            .zip(orbits)
            .all(|((&distinct, &live), orbits)| distinct == live && distinct == orbits)
    }

    /// The per-dart laws left at the 24 darts of tet t: α0, α1, α2 are the layout's, α3 is an
    /// involution and commutes with α0 and α1, vertex, edge and face ids agree across α3, and
    /// every id is its piece's. O(1).
    ///
    /// The α3 images' rows (the only reads outside the tet's block, often cache misses) are
    /// gathered first in a loop of independent loads, so that their misses overlap.
    #[inline(always)]
    fn tet_darts_hold(&self, t: usize) -> bool {
        let (w, capacity, base) = (N + 1, self.capacity(), 24 * t);
        let alpha = &self.alpha[base * w..(base + 24) * w];
        let cells = &self.cell[base * w..(base + 24) * w];
        let (mut far_alpha3, mut far_cells) = ([0u32; 24], [[0u32; 3]; 24]);
        for k in 0..24 {
            let e = alpha[k * w + 3] as usize;
            if e >= capacity {
                return false;
            }
            far_alpha3[k] = self.alpha[e * w + 3];
            far_cells[k].copy_from_slice(&self.cell[e * w..e * w + 3]);
        }
        let mut bad = false;
        for k in 0..24 {
            let e = alpha[k * w + 3];
            bad |= far_alpha3[k] != (base + k) as u32;
            let [l0, l1, _] = TET_LINKS[k];
            bad |= alpha[k * w..k * w + 3] != built_tet_links((base + k) as u32);
            bad |= built_tet_link(0, e) != alpha[l0 as usize * w + 3];
            bad |= built_tet_link(1, e) != alpha[l1 as usize * w + 3];
            let own = &cells[k * w..k * w + w];
            for dim in 0..3 {
                bad |= far_cells[k][dim] != own[dim];
            }
            for dim in 0..4 {
                bad |= own[dim] != cells[FIRST[k][dim] as usize * w + dim];
            }
        }
        !bad
    }

    /// Whether the ids of tet t's pieces are live (below the allocator's bound and not freed);
    /// counts the new ones. O(1).
    fn tet_piece_ids_live(&self, t: usize, dead: &[Option<VisitBits>], census: &mut PieceCensus) -> bool {
        let (w, base) = (N + 1, 24 * t);
        let mut bad = false;
        for (dim, firsts) in FIRST_OF_PIECE.iter().enumerate() {
            for &k in &firsts[..PIECES[dim]] {
                let id = self.cell[(base + k as usize) * w + dim];
                if id >= self.ids[dim].next {
                    return false;
                }
                bad |= dead[dim].as_ref().is_some_and(|dead| dead.contains(id));
                census.distinct[dim] += usize::from(census.used[dim].insert(id));
            }
        }
        !bad
    }

    /// Counts tet t's faces that are free or glued to a face numbered no lower, and joins the
    /// corners and edges of each glued one with its partner's. O(α(tets)).
    fn glue_tet_faces(&self, t: usize, census: &mut PieceCensus) {
        let w = N + 1;
        for f in 0..4u32 {
            let face = 4 * t as u32 + f;
            let d = 6 * face;
            let e = self.alpha[d as usize * w + 3];
            if e / 6 < face {
                continue;
            }
            census.glued_or_free_faces += 1;
            if e == d {
                continue;
            }
            for j in FACE_JOINERS {
                let (d, e) = (d + j as u32, self.alpha[(d as usize + j) * w + 3]);
                census.joins[0] += usize::from(join(&mut census.vertex_forest, piece_of(0, d), piece_of(0, e)));
                census.joins[1] += usize::from(join(&mut census.edge_forest, piece_of(1, d), piece_of(1, e)));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::{kuhn_cube, SplitMix64};
    use crate::{CellId, DartId};

    /// The two fast paths' verdicts on a map flagged as built tets whose layout law holds.
    fn both_paths(map: &GMap<3>) -> (bool, bool) {
        assert!(map.tets_as_built() && map.check_tet_layout().is_ok());
        let (dead, live) = map.id_liveness();
        (map.built_tet_laws_hold(&dead, &live), map.all_laws_hold(&dead, &live))
    }

    /// A random edit that keeps the tets-as-built flag: an α3 link or unlink, or a new cell id
    /// in 0..=bound (one past the allocator: not live; some maps have freed ids below it) at one
    /// dart, at the darts of its piece (constant inside the tet, so only α3 sees it) or at its
    /// whole cell (constant everywhere, so only liveness or uniqueness can fail).
    fn random_edit(map: &mut GMap<3>, rng: &mut SplitMix64) {
        let cap = map.capacity();
        let (a, b) = (DartId(rng.below(cap) as u32), DartId(rng.below(cap) as u32));
        let dim = rng.below(4);
        let id = rng.below(map.cell_id_bound(dim) + 1) as u32;
        let darts = match rng.below(5) {
            0 => return map.link_raw(3, a, b),
            1 => return map.unlink_raw(3, a),
            2 => vec![a],
            3 => {
                let base = a.0 - a.0 % 24;
                (base..base + 24)
                    .filter(|&x| PIECE[(x % 24) as usize][dim] == PIECE[(a.0 % 24) as usize][dim])
                    .map(DartId)
                    .collect()
            }
            _ => map.cell_darts(dim, a),
        };
        for d in darts {
            map.set_cell_raw(dim, d, id);
        }
    }

    /// Kuhn cubes with some inner faces unsewn through the public API (free α3 darts inside),
    /// all still flagged as built tets.
    fn built_maps() -> Vec<GMap<3>> {
        let mut maps = Vec::new();
        for (k, unsewn, resewn) in [(1, 0, 0), (1, 3, 1), (2, 0, 0), (2, 10, 4)] {
            let (points, tets) = kuhn_cube(k);
            let (mut map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
            let inner: Vec<DartId> = map.darts().filter(|&d| !map.is_free(3, d)).step_by(7).take(unsewn).collect();
            let mut pairs = Vec::new();
            for d in inner {
                if !map.is_free(3, d) {
                    pairs.push((d, map.alpha::<3>(d)));
                    map.unsew::<3>(d).unwrap();
                }
            }
            // Sewing back merges cells that the unsew split, which frees ids below the bound.
            for (d, e) in pairs.into_iter().take(resewn) {
                map.sew::<3>(d, e).unwrap();
            }
            assert!(map.tets_as_built() && map.validate().is_ok());
            maps.push(map);
        }
        maps
    }

    #[test]
    fn the_tet_path_agrees_with_the_generic_path_on_random_corruptions() {
        // Corruptions that break only α1α3 (the other checks and the counts catch the rest) are
        // rare: about one seed in two meets one in this many cases; seed 547 does.
        let mut rng = SplitMix64(547);
        let mut verdicts = [0usize; 2];
        for map in built_maps() {
            assert_eq!(both_paths(&map), (true, true));
            for case in 0..20000 {
                let mut broken = map.clone();
                for _ in 0..1 + case % 3 {
                    random_edit(&mut broken, &mut rng);
                }
                let (tet, generic) = both_paths(&broken);
                assert_eq!(tet, generic, "case {case}: the tet path says {tet}, the generic path {generic}");
                verdicts[usize::from(tet)] += 1;
                assert_eq!(broken.validate().is_ok(), tet, "case {case}: validate() disagrees with both paths");
            }
        }
        assert!(verdicts[0] > 1000 && verdicts[1] > 100, "too few of one verdict: {verdicts:?}");
    }

    /// Folds face 0 of a lone tet onto itself: α3 = (0 1)(2 5)(3 4) on its flags, the reflection
    /// that swaps corners a and b and fixes c (it commutes with α0 and α1, so the map is lawful
    /// once a and b, and the edges bc and ca, carry one id each).
    /// `join` keeps its documented forest: every root is the smallest element of its tree, and
    /// it reports a join exactly when the two were apart (checked against a naive labelling).
    #[test]
    fn join_keeps_each_tree_rooted_at_its_smallest_element() {
        let n = 60u32;
        let mut rng = SplitMix64(31);
        let mut forest: Vec<u32> = (0..n).collect();
        let mut label: Vec<u32> = (0..n).collect(); // the smallest element of each one's set
        for _ in 0..200 {
            let (a, b) = ((rng.next_u64() % u64::from(n)) as u32, (rng.next_u64() % u64::from(n)) as u32);
            let (la, lb) = (label[a as usize], label[b as usize]);
            assert_eq!(join(&mut forest, a, b), la != lb, "join({a}, {b})");
            let merged = la.min(lb);
            label.iter_mut().filter(|l| **l == la || **l == lb).for_each(|l| *l = merged);
            for x in 0..n {
                assert_eq!(find_root(&mut forest, x), label[x as usize], "root of {x} after join({a}, {b})");
            }
        }
    }

    /// The tet paths read whole 24-dart blocks: `live_tet_blocks` gives their number only for a
    /// 3-map whose slots are whole blocks, all live, and `None` for a dead slot, a partial block
    /// or another dimension (each condition alone).
    #[test]
    fn live_tet_blocks_need_n_3_whole_blocks_and_every_slot_live() {
        let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
        assert_eq!(map.live_tet_blocks(), Some(2));
        let mut dead = map.clone();
        dead.kill_dart_raw(DartId(47)); // 48 slots, 47 live
        assert_eq!((dead.capacity(), dead.live_tet_blocks()), (48, None));
        let mut partial = map.clone();
        partial.create_dart().unwrap(); // 49 slots, all live
        assert_eq!((partial.dart_count(), partial.live_tet_blocks()), (49, None));
        let (flat, _) = GMap::<2>::from_triangles(6, &[[0, 1, 2], [3, 4, 5], [0, 1, 3], [2, 4, 5]]).unwrap();
        assert_eq!((flat.dart_count(), flat.live_tet_blocks()), (24, None)); // 24 live darts, n = 2
    }

    #[test]
    fn a_face_folded_onto_itself_is_lawful_on_both_paths() {
        let (mut map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
        for (x, y) in [(0, 1), (2, 5), (3, 4)] {
            map.link_raw(3, DartId(x), DartId(y));
        }
        assert_eq!(both_paths(&map), (false, false), "ids not merged yet");
        for (dim, keep, merge) in [(0, 0, 1), (1, 2, 5)] {
            let (kept, merged) = (map.cell_id(dim, DartId(keep)), map.cell_id(dim, DartId(merge)));
            for d in map.darts().filter(|&d| map.cell_id(dim, d) == merged).collect::<Vec<_>>() {
                map.set_cell_raw(dim, d, kept.0);
            }
            map.release_cell_id(dim, merged.0);
        }
        assert_eq!(both_paths(&map), (true, true));
        assert_eq!(map.validate(), Ok(()));
        assert_eq!(map.count_cells_by_traversal().0, vec![3, 5, 4, 1]);
    }

    /// Relabels the whole i-cell of d with the id of the i-cell of `other`.
    fn relabel_cell(map: &mut GMap<3>, dim: usize, d: DartId, other: DartId) {
        let id = map.cell_id(dim, other).0;
        for x in map.cell_darts(dim, d) {
            map.set_cell_raw(dim, x, id);
        }
    }

    #[test]
    fn a_shared_or_orphan_id_is_found_in_every_dimension() {
        let (points, tets) = kuhn_cube(2);
        let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
        for dim in 0..4 {
            let d = DartId(0);
            let other = map.darts().find(|&x| map.cell_id(dim, x) != map.cell_id(dim, d)).unwrap();
            let mut shared = map.clone();
            relabel_cell(&mut shared, dim, d, other);
            assert_eq!(both_paths(&shared), (false, false), "dimension {dim}: shared id");
            assert_eq!(shared.validate().map_err(|v| v.law()), Err(super::super::Law::CellIdUnique));
            let mut orphan = map.clone();
            let id = orphan.alloc_cell_id(dim);
            assert_eq!(both_paths(&orphan), (false, false), "dimension {dim}: orphan id {id}");
            assert!(matches!(
                orphan.validate(),
                Err(super::super::InvariantViolation::CellIdOrphan { dim: e, id: CellId(i) }) if e == dim && i == id
            ));
        }
    }

    /// The orbit of offset k under the pattern links `gens` (i < 3) inside one tet.
    fn pattern_orbit(k: usize, gens: &[usize]) -> Vec<usize> {
        let (mut orbit, mut head) = (vec![k], 0);
        while head < orbit.len() {
            let x = orbit[head];
            head += 1;
            for &i in gens {
                let y = TET_LINKS[x][i] as usize;
                if !orbit.contains(&y) {
                    orbit.push(y);
                }
            }
        }
        orbit.sort_unstable();
        orbit
    }

    #[test]
    fn the_pattern_links_are_fixed_point_free_involutions_and_alpha0_alpha2_commute() {
        for (k, links) in TET_LINKS.iter().enumerate() {
            for (i, &image) in links.iter().enumerate() {
                let image = image as usize;
                assert_ne!(image, k, "alpha{i} fixes {k}");
                assert_eq!(TET_LINKS[image][i] as usize, k, "alpha{i} is not an involution at {k}");
            }
            let a02 = TET_LINKS[TET_LINKS[k][2] as usize][0];
            let a20 = TET_LINKS[TET_LINKS[k][0] as usize][2];
            assert_eq!(a02, a20, "alpha0 alpha2 at {k}");
        }
    }

    #[test]
    fn pieces_are_the_orbits_inside_one_tet() {
        for dim in 0..4 {
            let gens: Vec<usize> = (0..3).filter(|&i| i != dim).collect();
            let mut seen = 0;
            for k in 0..24 {
                let orbit = pattern_orbit(k, &gens);
                let piece: Vec<usize> = (0..24).filter(|&j| PIECE[j][dim] == PIECE[k][dim]).collect();
                assert_eq!(orbit, piece, "dimension {dim}, dart {k}");
                assert_eq!(usize::from(FIRST[k][dim]), piece[0], "first dart of {k}'s {dim}-piece");
                seen |= 1u32 << PIECE[k][dim];
            }
            assert_eq!(seen, (1u32 << PIECES[dim]) - 1, "dimension {dim} has {} pieces", PIECES[dim]);
        }
    }

    #[test]
    fn face_joiners_meet_every_corner_and_edge_of_their_face() {
        for f in 0..4 {
            let corners: Vec<u8> = FACE_JOINERS.iter().map(|&j| PIECE[6 * f + j][0]).collect();
            let edges: Vec<u8> = FACE_JOINERS.iter().map(|&j| PIECE[6 * f + j][1]).collect();
            let all_corners: Vec<u8> = (0..6).map(|j| PIECE[6 * f + j][0]).collect();
            let all_edges: Vec<u8> = (0..6).map(|j| PIECE[6 * f + j][1]).collect();
            for (chosen, all) in [(corners, all_corners), (edges, all_edges)] {
                let (mut chosen, mut all) = (chosen, all);
                chosen.sort_unstable();
                all.sort_unstable();
                all.dedup();
                assert_eq!(chosen, all, "face {f}");
            }
        }
    }
}
