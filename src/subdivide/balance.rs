//! 2:1 balance across faces for region refinement (finding 264).
//!
//! # The law
//! A tet T can be split 1→8 only while each of its faces, seen from T, is unsplit or split once
//! ([`SubdivideError::FaceRefinedTooFar`] otherwise, for good). A face of T is split twice when a
//! neighbour across it, itself a child of a split of that face, is split again. So a refinement
//! keeps every tet splittable when it never splits a tet N while a face neighbour M still sees
//! the face they share as one child of a split face of M ("M is coarser across that face"): M
//! goes first. [`LeveledMap::check_faces_refinable`] checks the law on a whole map.
//!
//! # Levels
//! [`LeveledMap::refine_around`] works level by level, and the level order (operations at
//! levels ≥ the map's maximum) forbids going back: a coarse neighbour must be split at a level
//! before the one where its finer neighbour is. At level L of a call to `levels`
//! ([`LeveledMap::refine_mixed`]):
//! - the zone ([`LeveledMap::balanced_zone`]) is every tet with μt < min(L, `levels`) within
//!   min(`levels` − L, [`RING_CAP`]) face rings of a tet meeting the ball, and, transitively,
//!   the tets that must be split before one of them ([`LeveledMap::blockers`], read off the
//!   faces: after a level skip, μt no longer tells which neighbour is coarser);
//! - the zone tets without blockers and without an unsplit face made at level L (next to a
//!   level skip: such a face cannot be split at L) are split at L; the others wait a level;
//! - the call ends at the first level ≥ `levels` with an empty zone (a tet held back at the
//!   last requested level is split at the first later level where nothing blocks it, by a
//!   level skip: a chain of blockers can hold it back several levels, so its children can end
//!   several levels past `levels`, with the size of level `levels`; finding 275).
//!
//! The rings anticipate (the neighbours of the tets of the next level are split a level before,
//! so few tets wait); the blockers make it exact.

use super::{LeveledMap, SubdivideError, MAX_LEVEL};
use crate::gmap::{AlphaMask, DartId};
use rustc_hash::FxHashMap;
use std::collections::hash_map::Entry;

/// Per edge id, the darts around the edge whose tets see it as an inner side of a split face
/// ([`LeveledMap::sees_inside`]): the edge part of [`LeveledMap::blockers`], found once per edge
/// and level (the map does not change between a level's zone and its ready tets), so that the k
/// tets around an edge of valence k cost O(k) there, not O(k²) (finding 248).
type EdgeSeers = FxHashMap<u32, Vec<DartId>>;

/// The most face rings a level's zone is widened by (module docs). `levels − L` rings at level
/// L (enough by a monotonicity argument) made a deep call (60 levels around a point) refine the
/// whole liver uniformly for its first levels. With fewer, the blockers still make every split
/// safe, but a tet blocked by a neighbour the rings missed waits a level and is then split by a
/// level skip, so its children have the μt of the level and the size of the one before: with 2
/// rings the tet around a point 50 levels deep had edges of 2.2e-9 instead of about 1e-15 (the
/// misses repeat level after level); with 3, 3.4e-14, and the refinement reaches the precision
/// of f64 at level 57 (liver_547, round 29).
const RING_CAP: u8 = 3;

/// What one level of [`LeveledMap::refine_mixed`] does to the map: split one tet, or take the
/// whole map at once (the bulk path) where that applies.
pub(super) trait LevelSplit {
    /// The error of a split, which a map refusal converts into.
    type Error: From<SubdivideError>;
    /// Splits the tet of `d` 1→8 at `level`, with whatever it carries (masses, springs).
    fn split(&mut self, m: &mut LeveledMap<3>, d: DartId, level: u8) -> Result<(), Self::Error>;
    /// Splits every tet at `level` in one pass, if that path applies (`None`: nothing changed).
    fn bulk(&mut self, m: &mut LeveledMap<3>, level: u8) -> Result<Option<usize>, Self::Error>;
    /// The refusals the splits of the tets of `zone` at `level` would make, on the map as it is,
    /// before any of them is split (those of the map, [`LeveledMap::check_zone`], and those of
    /// what the splitter carries).
    fn check_zone(&mut self, m: &LeveledMap<3>, level: u8, zone: &[DartId]) -> Result<(), Self::Error>;
}

impl LeveledMap<3> {
    /// Checks that every tet of the finest map could still be split 1→8 as far as its faces go:
    /// each face, seen from the tet at its level μt, is a triangle either unsplit or split once
    /// by a 1→4 split with single inner sides (what [`Self::subdivide_tet`] needs of its faces).
    /// A face refined twice from one side (a neighbour refined two levels past a coarse tet, by
    /// single operations) is [`SubdivideError::FaceRefinedTooFar`], naming the first such tet.
    /// [`Self::refine_around`] keeps this on a map that has it (the 2:1 balance of its zones,
    /// finding 264). O(darts).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::subdivide::{LeveledMap, TetMasses};
    /// use topomech::GMap;
    /// let (points, tets) = kuhn_cube(2);
    /// let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    /// let mut m = LeveledMap::new(map, points);
    /// let mut masses = TetMasses::from_density(&m, 1.0).unwrap();
    /// m.refine_around([0.5; 3], 0.0, 2, &mut masses).unwrap();
    /// m.check_faces_refinable().unwrap(); // the neighbours were refined to level 1 first
    /// m.refine_around([1.5; 3], 1.0, 2, &mut masses).unwrap(); // refused before finding 264
    /// m.check_faces_refinable().unwrap();
    /// ```
    pub fn check_faces_refinable(&self) -> Result<(), SubdivideError> {
        for d in self.map.one_dart_per_cell(3) {
            let corners = self.tet_corners(d, self.mu[d.index()].tet)?;
            self.check_tet_faces_visiting(d, &corners, |_, _| {})?;
        }
        Ok(())
    }

    /// The tets a refinement to `levels` wants split at `level` (module docs): one dart of every
    /// tet with μt < `below` that is within min(`levels − level`, [`RING_CAP`]) face rings of a
    /// tet meeting the ball, or one of the [`Self::blockers`] of such a tet, and so on. In the
    /// order of [`crate::GMap::one_dart_per_cell`]. Every tet's corners are read (the ball test),
    /// so a tet without finite corner positions anywhere is refused here. O(darts + Σ_{ringed and
    /// closure tets} volume · (neighbours + edge rings)).
    pub(super) fn balanced_zone(
        &self,
        (level, levels, below): (u8, u8, u8),
        center: [f64; 3],
        radius: f64,
        seers: &mut EdgeSeers,
    ) -> Result<Vec<DartId>, SubdivideError> {
        let tets = self.map.one_dart_per_cell(3);
        let ring = self.rings(&tets, center, radius, levels.saturating_sub(level).min(RING_CAP))?;
        let mut in_zone = vec![false; ring.len()];
        let mut stack = Vec::new();
        for &d in &tets {
            let id = self.map.cell_id(3, d).index();
            if ring[id] != u8::MAX && self.mu[d.index()].tet < below {
                in_zone[id] = true;
                stack.push(d);
            }
        }
        while let Some(t) = stack.pop() {
            for n in self.blockers(t, seers)? {
                let id = self.map.cell_id(3, n).index();
                if !in_zone[id] {
                    in_zone[id] = true;
                    stack.push(n);
                }
            }
        }
        Ok(tets.into_iter().filter(|&d| in_zone[self.map.cell_id(3, d).index()]).collect())
    }

    /// The ring of every volume id (index: id) up to `depth`: 0 for the tets of `tets` meeting
    /// the ball, r for those r α3 steps from one, `u8::MAX` past `depth` or for ids no volume
    /// uses. O(|tets| · volume + Σ_{ringed tets} volume).
    fn rings(&self, tets: &[DartId], center: [f64; 3], radius: f64, depth: u8) -> Result<Vec<u8>, SubdivideError> {
        let mut ring = vec![u8::MAX; self.map.cell_id_bound(3)];
        let mut frontier = Vec::new();
        for &d in tets {
            if self.tet_in_ball(d, center, radius)? {
                ring[self.map.cell_id(3, d).index()] = 0;
                frontier.push(d);
            }
        }
        for r in 1..=depth.min(MAX_LEVEL) {
            let mut next = Vec::new();
            for &t in &frontier {
                for (_, n) in self.face_neighbours(t) {
                    let id = self.map.cell_id(3, n).index();
                    if ring[id] == u8::MAX {
                        ring[id] = r;
                        next.push(n);
                    }
                }
            }
            frontier = next;
        }
        Ok(ring)
    }

    /// Each sewn face dart x of the tet of `t` with the dart n = α3(x) of the tet across (a
    /// neighbour comes once per dart pair of the faces they share). O(volume).
    fn face_neighbours(&self, t: DartId) -> impl Iterator<Item = (DartId, DartId)> + '_ {
        let volume = self.map.orbit(t, AlphaMask::cell(3, 3));
        volume.into_iter().filter(|&x| !self.map.is_free(3, x)).map(|x| (x, self.map.alpha_dyn(3, x)))
    }

    /// One dart of each tet whose faces a split of the tet of `t` would refine twice: a face
    /// neighbour that sees the shared face as a child of its own ([`Self::sees_split`]) where
    /// the tet of `t` sees it whole (the split would refine it), and a tet around an edge the
    /// split would split (a side without a flat vertex of one of its unsplit faces) that sees
    /// that edge as an inner side of one of its split faces (a side of a child face, between two
    /// of its corners that are not corners of the tet). A face both tets see as a child (a face
    /// split 1→4 on its own) blocks neither: the split of either keeps its children (finding
    /// 272). Read off the faces, whatever the levels say. O(volume · (neighbours + edge rings)).
    fn blockers(&self, t: DartId, seers: &mut EdgeSeers) -> Result<Vec<DartId>, SubdivideError> {
        let mut out = Vec::new();
        for (x, n) in self.face_neighbours(t) {
            if self.sees_split(n)? && !self.sees_split(x)? {
                out.push(n);
            }
        }
        let (mut faces, mut edges) = (Vec::new(), Vec::new());
        self.zone_tet_splits(t, &mut faces, &mut edges);
        let own = self.map.cell_id(3, t);
        for (_, x) in edges {
            let around = match seers.entry(self.map.cell_id(1, x).0) {
                Entry::Occupied(known) => known.into_mut(),
                Entry::Vacant(slot) => slot.insert(self.edge_seers(x)?),
            };
            out.extend(around.iter().filter(|&&y| self.map.cell_id(3, y) != own));
        }
        Ok(out)
    }

    /// The darts y around the edge of `x` (its ⟨α2, α3⟩ orbit, in orbit order) whose tets see
    /// the edge as an inner side of a split face ([`Self::sees_inside`]). O(edge ring · volume).
    fn edge_seers(&self, x: DartId) -> Result<Vec<DartId>, SubdivideError> {
        let ends = [self.map.vertex_id(x).0, self.map.vertex_id(self.map.alpha_dyn(0, x)).0];
        let mut out = Vec::new();
        for y in self.map.orbit(x, AlphaMask::of(&[2, 3])) {
            if self.sees_inside(y, ends)? {
                out.push(y);
            }
        }
        Ok(out)
    }

    /// Whether the tet of `y` sees the edge of `y` (ends `ends`) as an inner side of a split face:
    /// the face of `y` is a child of a split one, both ends are corners of that child face (not
    /// flat vertices on its sides) and neither is a corner of the tet. O(volume).
    fn sees_inside(&self, y: DartId, ends: [u32; 2]) -> Result<bool, SubdivideError> {
        // Both ends must be corners of the child face (not flat vertices on its sides): a part
        // of an outer half-side, between a midpoint and a flat vertex, may be split.
        if self.flat[y.index()] || self.flat[self.map.alpha_dyn(0, y).index()] {
            return Ok(false);
        }
        let corners = self.tet_corners(y, self.mu[y.index()].tet)?;
        if ends.iter().any(|e| corners.contains(e)) {
            return Ok(false);
        }
        self.sees_split(y)
    }

    /// Whether the face of dart `n`, seen from its tet at the tet's level μt, is a child of a
    /// split face (fewer than 3 of the tet's corners on it: a corner child has 1, the centre
    /// child 0) rather than a whole face (its 3 corners, whatever flat vertices its sides
    /// carry). O(volume).
    pub(super) fn sees_split(&self, n: DartId) -> Result<bool, SubdivideError> {
        let corners = self.tet_corners(n, self.mu[n.index()].tet)?;
        let face: Vec<u32> =
            self.map.orbit(n, AlphaMask::of(&[0, 1])).iter().map(|&x| self.map.vertex_id(x).0).collect();
        Ok(corners.iter().filter(|c| face.contains(c)).count() < 3)
    }

    /// The tets of `zone` that may be split at `level` now: no [`Self::blockers`] and no
    /// unsplit face with μf ≥ `level`. A face refined twice is
    /// refused ([`SubdivideError::FaceRefinedTooFar`], from [`Self::check_tet_faces_visiting`]).
    /// O(Σ zone volumes · neighbours).
    fn ready_at(&self, zone: &[DartId], level: u8, seers: &mut EdgeSeers) -> Result<Vec<DartId>, SubdivideError> {
        let mut ready = Vec::new();
        for &d in zone {
            let corners = self.tet_corners(d, self.mu[d.index()].tet)?;
            let unsplit = self.check_tet_faces_visiting(d, &corners, |_, _| {})?;
            if unsplit.iter().any(|f| self.mu[f.index()].face >= level) {
                continue;
            }
            let blocked = !self.blockers(d, seers)?.is_empty();
            if !blocked {
                ready.push(d);
            }
        }
        Ok(ready)
    }

    /// The refusal for a level where no zone tet may be split, named by the zone tet of `d`: its
    /// first blocker as [`SubdivideError::FaceRefinedTooFar`] (that tet's face would be refined
    /// twice), else its unsplit face of μf ≥ `level` as [`SubdivideError::AlreadyAtLevel`].
    /// O(volume · (neighbours + edge rings)).
    fn stuck(&self, d: DartId, level: u8, seers: &mut EdgeSeers) -> Result<SubdivideError, SubdivideError> {
        if let Some(&b) = self.blockers(d, seers)?.first() {
            return Ok(SubdivideError::FaceRefinedTooFar { dart: b });
        }
        let corners = self.tet_corners(d, self.mu[d.index()].tet)?;
        let unsplit = self.check_tet_faces_visiting(d, &corners, |_, _| {})?;
        let f = unsplit.into_iter().find(|f| self.mu[f.index()].face >= level).unwrap_or(d);
        Ok(SubdivideError::AlreadyAtLevel { dart: f, dim: 2, cell_level: self.mu[f.index()].face, level })
    }

    /// The levels of a refinement (module docs, "Levels"), from level max(1, k), k the map's
    /// maximum level: at each level L the zone of [`Self::balanced_zone`] (tets with
    /// μt < min(L, `levels`)), of which the ready ones are checked ([`Self::check_zone_darts`],
    /// the splitter's `check_zone`) and split at L (tets below μt = L − 1 by a level skip);
    /// until the zone is empty at a level ≥ `levels`. Returns the tets split per level (index =
    /// level; longer than `levels` + 1 when a tet held back at the last level was split at the
    /// next). Each level is checked before its first split; a refusal keeps the levels before
    /// (a caller that wants all or nothing keeps a
    /// copy. O(levels · darts + Σ zone volumes · neighbours).
    ///
    /// Errors: [`SubdivideError::LevelTooHigh`] past [`MAX_LEVEL`], the dart limit per level
    /// ([`Self::check_zone_darts`]), the splitter's own, and a split's refusal; a level after
    /// the first where no zone tet is ready ([`Self::stuck`]: not met — a blocker is strictly
    /// larger than the tet it blocks, so the largest zone tet has none, and faces of the level
    /// only come with its own splits — but refused rather than split past a blocker; round 30
    /// met it through a wrong blocker, finding 272).
    pub(super) fn refine_mixed<S: LevelSplit>(
        &mut self,
        center: [f64; 3],
        radius: f64,
        levels: u8,
        s: &mut S,
    ) -> Result<Vec<usize>, S::Error> {
        let first = self.max_level.max(1);
        let mut per_level = vec![0; levels as usize + 1];
        for level in first..=MAX_LEVEL {
            let mut seers = EdgeSeers::default();
            let zone = self.balanced_zone((level, levels, level.min(levels)), center, radius, &mut seers)?;
            if zone.is_empty() && level >= levels {
                return Ok(per_level);
            }
            if per_level.len() <= level as usize {
                per_level.resize(level as usize + 1, 0);
            }
            if level <= levels {
                if let Some(count) = s.bulk(self, level)? {
                    per_level[level as usize] += count;
                    continue;
                }
            }
            let ready = self.ready_at(&zone, level, &mut seers)?;
            if let (true, Some(&d), true) = (ready.is_empty(), zone.first(), level > first) {
                return Err(self.stuck(d, level, &mut seers)?.into());
            }
            self.check_zone_darts(level, &ready)?;
            s.check_zone(self, level, &ready)?;
            let darts = self.map.dart_count();
            for &d in &ready {
                s.split(self, d, level)?;
            }
            self.check_caught_up(darts, ready.len())?;
            per_level[level as usize] += ready.len();
        }
        Err(SubdivideError::LevelTooHigh(MAX_LEVEL.saturating_add(1)).into())
    }
}
