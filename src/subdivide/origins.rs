//! What a leveled map knows of its vertices' past: the split log read back from the level
//! history, and the origins of the vertices a cut made (finding 336: a store round trip lost
//! both, and the lumped masses of a loaded map treated every midpoint as a corner).
//!
//! Laws (checked by [`LeveledMap::check_all`] and the store's check):
//! - **Split log = history.** An edge split at level L between the ends a and b at a new vertex
//!   m leaves, at every dart x of a on that edge, the history entry (L, α0, y) with y a dart of b,
//!   and α0^L(x) a dart of m. Conversely every α0 entry of the history is such a split. So the
//!   log, read as origin(m) → {origin(a), origin(b)}, is exactly what the history witnesses, each
//!   vertex inserted once, and a loaded map rebuilds it from its history
//!   ([`LeveledMap::rebuild_split_log`]).
//! - **Origins are roots.** A copy's origin is no copy itself; a copy lies where its origin lies
//!   (same point, when points are given); the darts of one n-cell (a volume in 3D) meet each
//!   origin at one vertex only (a cut separates copies between n-cells, never inside one).

use std::collections::BTreeMap;

use super::{LevelError, LeveledMap};
use crate::gmap::{AlphaMask, DartId};

/// One split as the history witnesses it: the level, the inserted vertex and the ends of the split
/// edge (ends increasing), all as [origins](LeveledMap::vertex_origin).
type Witness = (u8, u32, [u32; 2]);

/// A vertex whose witnesses disagree: the vertex, the ends of its first witness, another's.
type Clash = (u32, [u32; 2], [u32; 2]);

impl<const N: usize> LeveledMap<N> {
    /// Every split the link history witnesses (module docs), one per inserted vertex (the first
    /// witness met in dart order); a vertex whose witnesses disagree on its ends is returned in
    /// the second list with the two pairs. O(darts + history entries).
    fn witnessed_splits(&self) -> (BTreeMap<u32, Witness>, Vec<Clash>) {
        let (mut seen, mut clashes) = (BTreeMap::new(), Vec::new());
        let origin = |d: DartId| self.vertex_origin(self.map.vertex_id(d).0);
        for x in self.map.darts() {
            for c in self.history.of(x.index()).filter(|c| c.j == 0) {
                let (a, b) = (origin(x), origin(DartId(c.old)));
                let mid = origin(self.alpha_at(c.level, 0, x));
                let ends = [a.min(b), a.max(b)];
                match seen.get(&mid) {
                    None => {
                        seen.insert(mid, (c.level, mid, ends));
                    }
                    Some(&(_, _, first)) if first != ends => clashes.push((mid, first, ends)),
                    Some(_) => {}
                }
            }
        }
        (seen, clashes)
    }

    /// The split log as the link history records it: one entry [m, a, b] per inserted vertex,
    /// every id an [origin](Self::vertex_origin), ends increasing, entries in increasing (level,
    /// m) order, so that the ends of a split come before it. What [`Self::from_parts`] restores
    /// ([`Self::split_log`] is not saved). O(darts + history entries).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::subdivide::LeveledMap;
    /// # use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let mut m = LeveledMap::new(map, vec![]);
    /// let d = m.map().darts().next().unwrap();
    /// m.subdivide_tet(d, 1).unwrap(); // six midpoints, ids 4..10
    /// let mut log = m.split_log().to_vec();
    /// log.iter_mut().for_each(|e| e[1..].sort());
    /// log.sort_by_key(|e| e[0]);
    /// assert_eq!(m.rebuild_split_log(), log);
    /// ```
    pub fn rebuild_split_log(&self) -> Vec<[u32; 3]> {
        let mut log: Vec<Witness> = self.witnessed_splits().0.into_values().collect();
        log.sort_unstable();
        log.into_iter().map(|(_, m, [a, b])| [m, a, b]).collect()
    }

    /// The split-log law (module docs), up to `limit` violations: witnesses agree on each
    /// inserted vertex's ends, and the log (read by origins) has one entry per witnessed vertex
    /// with the witnessed ends. O(darts + history entries + log · log).
    pub(crate) fn split_log_errors(&self, limit: usize) -> Vec<LevelError> {
        let (witnessed, clashes) = self.witnessed_splits();
        let mut out: Vec<LevelError> = clashes
            .into_iter()
            .map(|(vertex, logged, witnessed)| LevelError::SplitLog {
                vertex,
                logged: Some(logged),
                witnessed: Some(witnessed),
            })
            .collect();
        let mut logged: BTreeMap<u32, [u32; 2]> = BTreeMap::new();
        for &[m, a, b] in &self.splits {
            let (m, a, b) = (self.vertex_origin(m), self.vertex_origin(a), self.vertex_origin(b));
            if logged.insert(m, [a.min(b), a.max(b)]).is_some() {
                out.push(LevelError::SplitLog { vertex: m, logged: Some([a.min(b), a.max(b)]), witnessed: None });
            }
        }
        let vertices = logged.keys().chain(witnessed.keys()).copied().collect::<std::collections::BTreeSet<_>>();
        for v in vertices {
            let (l, w) = (logged.get(&v).copied(), witnessed.get(&v).map(|&(_, _, ends)| ends));
            if l != w {
                out.push(LevelError::SplitLog { vertex: v, logged: l, witnessed: w });
            }
        }
        out.truncate(limit);
        out
    }

    /// The origin laws (module docs), up to `limit` violations: every origin a root, a copy's
    /// point its origin's, and no n-cell meeting one origin at two vertices. O(darts · log).
    pub(crate) fn origin_errors(&self, limit: usize) -> Vec<LevelError> {
        let mut out = Vec::new();
        for (copy, &origin) in self.origins.iter().enumerate() {
            let copy = copy as u32;
            if origin == copy {
                continue;
            }
            if self.vertex_origin(origin) != origin {
                out.push(LevelError::OriginNotRoot {
                    vertex: copy,
                    origin,
                    origin_of_origin: self.vertex_origin(origin),
                });
            }
            let (p, q) = (self.points.get(copy as usize), self.points.get(origin as usize));
            if let (Some(p), Some(q)) = (p, q) {
                if p.map(f64::to_bits) != q.map(f64::to_bits) {
                    out.push(LevelError::OriginElsewhere { vertex: copy, origin });
                }
            }
        }
        if !self.origins.is_empty() {
            out.extend(self.origins_shared_in_cells(limit));
        }
        out.truncate(limit);
        out
    }

    /// n-cells whose vertices include two copies of one origin, up to `limit`. O(darts · log).
    fn origins_shared_in_cells(&self, limit: usize) -> Vec<LevelError> {
        let mut out = Vec::new();
        let all_but_n = AlphaMask::of(&(0..N).collect::<Vec<_>>());
        for d in self.map.one_dart_per_cell(N) {
            let mut seen: BTreeMap<u32, u32> = BTreeMap::new();
            for x in self.map.orbit(d, all_but_n) {
                let v = self.map.vertex_id(x).0;
                let o = self.vertex_origin(v);
                match seen.insert(o, v) {
                    Some(w) if w != v => {
                        out.push(LevelError::OriginTwiceInCell { dart: d, origin: o, vertices: [w.min(v), w.max(v)] });
                        break;
                    }
                    _ => {}
                }
            }
            if out.len() >= limit {
                break;
            }
        }
        out
    }

    /// The origins as (copy, origin) pairs with copy ≠ origin, copies increasing: what
    /// [`Self::to_parts`] saves. O(vertices).
    pub(crate) fn origin_pairs(&self) -> Vec<[u32; 2]> {
        (0..self.origins.len() as u32)
            .filter(|&v| self.origins[v as usize] != v)
            .map(|v| [v, self.origins[v as usize]])
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gmap::GMap;

    /// A tet with one edge split, then a triangle on it split 1→4: three inserted vertices.
    fn refined() -> LeveledMap<3> {
        let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
        let mut m = LeveledMap::new(map, vec![]);
        let d = m.map().darts().next().unwrap();
        m.split_edge(d, 1).unwrap();
        m.subdivide_triangle(d, 2).unwrap();
        m
    }

    /// The law holds on what the operations make, and every way of breaking the log is named:
    /// an entry dropped, an entry with other ends, an entry repeated.
    #[test]
    fn the_split_log_law_names_each_way_the_log_can_lie() {
        let m = refined();
        assert_eq!(m.splits.len(), 3);
        assert!(m.split_log_errors(10).is_empty());
        let [v, a, b] = m.splits[0];
        let mut dropped = m.clone();
        dropped.splits.remove(0);
        let want = [a.min(b), a.max(b)];
        assert_eq!(
            dropped.split_log_errors(10),
            [LevelError::SplitLog { vertex: v, logged: None, witnessed: Some(want) }]
        );
        let mut other_ends = m.clone();
        let c = (0..4).find(|&c| c != a && c != b && c != v).unwrap();
        other_ends.splits[0] = [v, a, c];
        assert_eq!(
            other_ends.split_log_errors(10),
            [LevelError::SplitLog { vertex: v, logged: Some([a.min(c), a.max(c)]), witnessed: Some(want) }]
        );
        let mut repeated = m.clone();
        repeated.splits.push([v, a, b]);
        assert_eq!(repeated.split_log_errors(10).len(), 1);
        assert!(matches!(repeated.check_all(), Err(LevelError::SplitLog { .. })));
    }

    /// The rebuilt log, read by origins, is the log the operations wrote, in an order that puts
    /// the ends of every split before it.
    #[test]
    fn the_rebuilt_log_is_the_written_one_with_parents_first() {
        let m = refined();
        let rebuilt = m.rebuild_split_log();
        let mut written: Vec<[u32; 3]> = m.splits.iter().map(|&[v, a, b]| [v, a.min(b), a.max(b)]).collect();
        written.sort_unstable();
        let mut sorted = rebuilt.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, written);
        for (i, &[_, a, b]) in rebuilt.iter().enumerate() {
            assert!(rebuilt[i..].iter().all(|&[v, ..]| v != a && v != b), "entry {i}: an end is inserted later");
        }
    }

    /// Origin laws on a cut map: the cut's records hold them; a copy moved, a chained origin and
    /// two copies of one origin in one volume are each named.
    #[test]
    fn the_origin_laws_name_each_broken_record() {
        let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]];
        let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [1, 2, 3, 4]]).unwrap();
        let mut m = LeveledMap::new(map, pts);
        let glued = m.map().darts().find(|&d| !m.map().is_free(3, d)).unwrap();
        m.unsew_face(glued, 1).unwrap();
        assert!(m.origin_errors(10).is_empty());
        let pairs = m.origin_pairs();
        assert_eq!(pairs.len(), 3);
        let [c0, o0] = pairs[0];
        let mut moved = m.clone();
        moved.points[c0 as usize][0] += 1.0;
        assert_eq!(moved.origin_errors(10), [LevelError::OriginElsewhere { vertex: c0, origin: o0 }]);
        let mut chained = m.clone();
        let [c1, _] = pairs[1];
        chained.origins[c1 as usize] = c0;
        chained.points[c1 as usize] = chained.points[c0 as usize];
        assert!(chained.origin_errors(10).contains(&LevelError::OriginNotRoot {
            vertex: c1,
            origin: c0,
            origin_of_origin: o0
        }));
        // c0 and c1 are copies in one volume (the cut side of the face): naming o0 as c1's origin
        // too puts o0 twice in that volume.
        let mut twice = m.clone();
        twice.origins[c1 as usize] = o0;
        twice.points[c1 as usize] = twice.points[o0 as usize];
        assert!(twice
            .origin_errors(10)
            .iter()
            .any(|e| matches!(e, LevelError::OriginTwiceInCell { origin, .. } if *origin == o0)));
    }
}
