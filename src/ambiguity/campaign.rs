//! Random cut campaigns on a real mesh: the g-map and the naive indexed model cut side by side,
//! then audited; and the delta-debugging shrinker that turns a finding into a small test vector.
//!
//! A *cut* dissociates the face between two tets (`unsew::<3>` on the g-map,
//! [`IndexedModel::cut`] on the indexed model). A sequence of k cuts picks k distinct interior
//! faces of the input uniformly at random (SplitMix64, so a seed reproduces it).
//!
//! Besides the audit, every sequence is checked for the *skeleton pair*: when no cut split a
//! vertex or an edge of the g-map (no `CellChange::Split` of dimension 0 or 1), the cut map and the
//! uncut one have the very same vertex–edge graph (same cell ids, same incidences: the identity
//! is an isomorphism) while the maps are not isomorphic (they differ in their number of faces).

use crate::ambiguity::construct::{glued_faces, shared_face_dart, ConstructError, CutComplex};
use crate::ambiguity::indexed::{Audit, AuditError, CutOutcome, IndexedError, IndexedModel};
use crate::generate::SplitMix64;
use crate::gmap::GMap;
use crate::BuildError;

/// Why a campaign could not run.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::campaign::{run_cuts, CampaignError};
/// let tets = [[0, 1, 2, 3], [1, 2, 3, 4]];
/// // Tets 0 and 0 share no face.
/// assert!(matches!(run_cuts(5, &tets, &[[0, 0]]), Err(CampaignError::Construct(_))));
/// // A point id past the point count does not build.
/// assert!(matches!(run_cuts(4, &tets, &[]), Err(CampaignError::Build(_))));
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CampaignError {
    /// The mesh does not build.
    #[error(transparent)]
    Build(#[from] BuildError),
    /// A cut failed on the g-map side.
    #[error(transparent)]
    Construct(#[from] ConstructError),
    /// The indexed model refuses the mesh ([`IndexedError::CoincidentTets`]: a duplicated tet),
    /// or a cut failed on the indexed side.
    #[error(transparent)]
    Indexed(#[from] IndexedError),
    /// The mesh has fewer interior faces than cuts asked for.
    #[error("{asked} cuts asked for but the mesh has only {faces} interior faces")]
    TooFewFaces {
        /// Cuts per sequence.
        asked: usize,
        /// Interior faces.
        faces: usize,
    },
}

impl From<AuditError> for CampaignError {
    /// [`AuditError::Build`] as [`CampaignError::Build`], [`AuditError::Cut`] as
    /// [`CampaignError::Indexed`] (its [`IndexedError::NoSuchTet`]).
    fn from(e: AuditError) -> Self {
        match e {
            AuditError::Build(b) => CampaignError::Build(b),
            AuditError::Cut { source, .. } => CampaignError::Indexed(source),
        }
    }
}

/// A symptom found after a cut sequence.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::campaign::{run_cuts, Symptom};
/// assert_eq!(Symptom::ALL.len(), 5);
/// let run = run_cuts(5, &[[0, 1, 2, 3], [1, 2, 3, 4]], &[]).unwrap();
/// // Nothing cut: the vertex–edge graph is that of the uncut map.
/// assert_eq!(run.symptoms(), vec![Symptom::SkeletonUnchanged]);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Symptom {
    /// The indexed model re-glued a cut face (no point of it could be duplicated).
    FaceStillShared,
    /// Tets around one point of the indexed model form several fans.
    PinchedPoint,
    /// Tets around one point pair of the indexed model form several fans.
    NonManifoldEdge,
    /// The map the tet list means glues faces differently from the g-map.
    GluingDiffers,
    /// The cut and uncut g-maps share their vertex–edge graph.
    SkeletonUnchanged,
}

impl Symptom {
    /// Every symptom, in a fixed order.
    pub const ALL: [Symptom; 5] = [
        Symptom::FaceStillShared,
        Symptom::PinchedPoint,
        Symptom::NonManifoldEdge,
        Symptom::GluingDiffers,
        Symptom::SkeletonUnchanged,
    ];
}

/// The outcome of one cut sequence.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::campaign::run_cuts;
/// let run = run_cuts(5, &[[0, 1, 2, 3], [1, 2, 3, 4]], &[[0, 1]]).unwrap();
/// assert_eq!(run.cuts, vec![[0, 1]]);
/// assert!(run.audit.gmap_valid && !run.skeleton_unchanged);
/// assert!(run.symptoms().is_empty());
/// ```
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct Run {
    /// The cuts `[t1, t2]`.
    pub cuts: Vec<[u32; 2]>,
    /// The comparison of both models.
    pub audit: Audit,
    /// Whether no cut split a g-map vertex or edge (see the [module docs](self)).
    pub skeleton_unchanged: bool,
}

impl Run {
    /// The symptoms of this run, in [`Symptom::ALL`] order.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::{campaign::run_cuts, campaign::Symptom, construct::glued_faces};
    /// use topomech::{generate, GMap};
    ///
    /// let run = run_cuts(5, &[[0, 1, 2, 3], [1, 2, 3, 4]], &[[0, 1]]).unwrap();
    /// assert!(run.symptoms().is_empty()); // the three points of the face are duplicated: all fine
    /// let (points, tets) = generate::kuhn_cube(2);
    /// let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    /// let runs = glued_faces(&map).into_iter().map(|f| run_cuts(points.len(), &tets, &[f]).unwrap());
    /// let lost: Vec<_> = runs.filter(|r| r.symptoms().contains(&Symptom::FaceStillShared)).collect();
    /// assert!(!lost.is_empty() && lost.iter().all(|r| r.symptoms().contains(&Symptom::GluingDiffers)));
    /// ```
    pub fn symptoms(&self) -> Vec<Symptom> {
        let a = &self.audit;
        let flags = [
            a.faces_still_shared > 0,
            a.pinched_points > 0,
            a.non_manifold_edges > 0,
            a.gluing_differs,
            self.skeleton_unchanged,
        ];
        Symptom::ALL.iter().zip(flags).filter(|(_, f)| *f).map(|(s, _)| *s).collect()
    }
}

/// Runs `cuts` on both models built from `complex` (its own `cuts` are ignored). O(tets + cuts ·
/// (orbit + fans) + darts · n).
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::campaign::{run_cuts, CampaignError};
///
/// let tets = [[0, 1, 2, 3], [1, 2, 3, 4]];
/// let run = run_cuts(5, &tets, &[[0, 1]]).unwrap();
/// assert_eq!(run.audit.gmap_vertices, 8);
/// assert!(!run.audit.ambiguous() && !run.skeleton_unchanged); // the cut split vertices
/// assert!(matches!(run_cuts(5, &tets, &[[0, 1], [0, 1]]), Err(CampaignError::Construct(_))));
/// ```
pub fn run_cuts(points: usize, tets: &[[u32; 4]], cuts: &[[u32; 2]]) -> Result<Run, CampaignError> {
    let (mut gmap, _) = GMap::<3>::from_tets(points, tets)?;
    let mut model = IndexedModel::new(points, tets)?;
    let mut outcomes: Vec<CutOutcome> = Vec::with_capacity(cuts.len());
    let mut skeleton_unchanged = true;
    for &[t1, t2] in cuts {
        let d = shared_face_dart(&gmap, t1, t2).ok_or(ConstructError::NoSharedFace(t1, t2))?;
        let changes = gmap.unsew::<3>(d).map_err(ConstructError::from)?;
        skeleton_unchanged &= changes.splits(0).count() == 0 && changes.splits(1).count() == 0;
        outcomes.push(model.cut(t1, t2)?);
    }
    let audit = model.audit(&gmap, cuts, &outcomes)?;
    Ok(Run { cuts: cuts.to_vec(), audit, skeleton_unchanged })
}

/// `k` distinct faces of `faces`, uniformly (a partial Fisher–Yates shuffle). O(faces).
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::campaign::random_cuts;
/// use topomech::generate::SplitMix64;
///
/// let faces: Vec<[u32; 2]> = (0..10).map(|t| [t, t + 1]).collect();
/// let mut picked = random_cuts(&faces, 4, &mut SplitMix64(1));
/// assert!(picked.iter().all(|f| faces.contains(f)));
/// picked.sort_unstable();
/// picked.dedup();
/// assert_eq!(picked.len(), 4);
/// assert_eq!(random_cuts(&faces, 99, &mut SplitMix64(1)).len(), 10);
/// ```
pub fn random_cuts(faces: &[[u32; 2]], k: usize, rng: &mut SplitMix64) -> Vec<[u32; 2]> {
    let mut pool = faces.to_vec();
    let k = k.min(pool.len());
    for i in 0..k {
        let j = i + rng.below(pool.len() - i);
        pool.swap(i, j);
    }
    pool.truncate(k);
    pool
}

/// Counts over the sequences of one length k.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::campaign::campaign_k;
/// use topomech::generate::{self, SplitMix64};
/// let (points, tets) = generate::kuhn_cube(1);
/// let (s, _) = campaign_k(points.len(), &tets, 1, 4, &mut SplitMix64(7)).unwrap();
/// assert_eq!((s.k, s.sequences, s.gmap_invalid), (1, 4, 0));
/// assert_eq!(s.symptoms.len(), 5);
/// assert!(s.symptoms.iter().all(|&(_, n)| n <= s.sequences) && s.wrong <= s.sequences);
/// ```
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
pub struct KStats {
    /// Cuts per sequence.
    pub k: usize,
    /// Sequences run.
    pub sequences: usize,
    /// Sequences after which the indexed model is ambiguous ([`Audit::ambiguous`]).
    pub ambiguous: usize,
    /// Sequences after which the indexed model means a different object ([`Audit::wrong`]).
    pub wrong: usize,
    /// Sequences with each symptom, in [`Symptom::ALL`] order.
    pub symptoms: Vec<(Symptom, usize)>,
    /// Total cuts that duplicated no point.
    pub cuts_without_duplication: usize,
    /// Sequences where the g-map failed validation (expected 0).
    pub gmap_invalid: usize,
}

/// Runs `sequences` random sequences of `k` cuts on the mesh. The first run with each symptom is
/// returned too. O(sequences · (tets + k · fans + darts)).
///
/// Errors: [`CampaignError::Build`] for a mesh that does not build, [`CampaignError::Indexed`]
/// ([`IndexedError::CoincidentTets`]) for a duplicated tet, [`CampaignError::TooFewFaces`]; any
/// other error is a bug.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::campaign::{campaign_k, CampaignError};
/// use topomech::generate::{self, SplitMix64};
///
/// let (points, tets) = generate::kuhn_cube(1);
/// let (stats, firsts) = campaign_k(points.len(), &tets, 2, 5, &mut SplitMix64(1)).unwrap();
/// assert_eq!((stats.sequences, stats.gmap_invalid), (5, 0));
/// assert!(firsts.len() <= 5 && stats.wrong <= 5);
/// let too_many = campaign_k(points.len(), &tets, 7, 1, &mut SplitMix64(1));
/// assert_eq!(too_many.unwrap_err(), CampaignError::TooFewFaces { asked: 7, faces: 6 });
/// ```
pub fn campaign_k(
    points: usize,
    tets: &[[u32; 4]],
    k: usize,
    sequences: usize,
    rng: &mut SplitMix64,
) -> Result<(KStats, Vec<Run>), CampaignError> {
    // A mesh the indexed model refuses (a duplicated tet) is refused before any sequence, by the
    // indexed model's own error (the g-map builder refuses it too, as `DuplicateElement`).
    IndexedModel::new(points, tets)?;
    let (fresh, _) = GMap::<3>::from_tets(points, tets)?;
    let faces = glued_faces(&fresh);
    if faces.len() < k {
        return Err(CampaignError::TooFewFaces { asked: k, faces: faces.len() });
    }
    let mut stats = KStats { k, symptoms: Symptom::ALL.iter().map(|&s| (s, 0)).collect(), ..KStats::default() };
    let mut firsts: Vec<Run> = Vec::new();
    for _ in 0..sequences {
        let cuts = random_cuts(&faces, k, rng);
        let run = run_cuts(points, tets, &cuts)?;
        stats.sequences += 1;
        stats.ambiguous += usize::from(run.audit.ambiguous());
        stats.wrong += usize::from(run.audit.wrong());
        stats.gmap_invalid += usize::from(!run.audit.gmap_valid);
        stats.cuts_without_duplication += run.audit.cuts_without_duplication;
        let symptoms = run.symptoms();
        for (s, count) in &mut stats.symptoms {
            *count += usize::from(symptoms.contains(s));
        }
        if symptoms.iter().any(|s| !firsts.iter().any(|r| r.symptoms().contains(s))) {
            firsts.push(run);
        }
    }
    Ok((stats, firsts))
}

/// Delta debugging (ddmin): a 1-minimal sublist of `items` on which `test` still holds, assuming
/// it holds on `items`. At most `budget` calls of `test`.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::campaign::ddmin;
///
/// let items: Vec<u32> = (0..20).collect();
/// assert_eq!(ddmin(&items, 1000, &mut |s| s.contains(&13)), vec![13]);
/// assert_eq!(ddmin(&items, 1000, &mut |s| s.contains(&2) && s.contains(&17)), vec![2, 17]);
/// assert_eq!(ddmin(&items, 0, &mut |_| true), items); // no budget: unchanged
/// ```
pub fn ddmin<T: Clone>(items: &[T], budget: usize, test: &mut dyn FnMut(&[T]) -> bool) -> Vec<T> {
    let mut current = items.to_vec();
    let mut n = 2usize;
    let mut calls = 0;
    while current.len() >= 2 && calls < budget {
        let chunk = current.len().div_ceil(n);
        let mut reduced = false;
        for start in (0..current.len()).step_by(chunk) {
            let end = (start + chunk).min(current.len());
            let complement: Vec<T> = current[..start].iter().chain(&current[end..]).cloned().collect();
            calls += 1;
            if test(&complement) {
                current = complement;
                n = (n - 1).max(2);
                reduced = true;
                break;
            }
            if calls >= budget {
                break;
            }
        }
        if !reduced {
            if n >= current.len() {
                break;
            }
            n = (2 * n).min(current.len());
        }
    }
    current
}

/// The complex restricted to the tets `keep` (indices into `c.tets`), points renumbered densely in
/// order of first use, cuts renumbered; `None` if a cut names a dropped tet, and likewise (never
/// a panic) if an index is out of range: a tet of `keep` past `c.tets`, a point of a kept tet
/// past `c.points`, or a cut naming a tet past `c.tets`. O(tets + cuts).
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::{campaign::sub_complex, construct::CutComplex};
///
/// let c = CutComplex { points: 5, tets: vec![[0, 1, 2, 3], [1, 2, 3, 4]], cuts: vec![[0, 1]] };
/// let second = CutComplex { cuts: vec![], ..c.clone() };
/// assert_eq!(sub_complex(&c, &[1]), None); // the cut names the dropped tet 0
/// let alone = sub_complex(&second, &[1]).unwrap();
/// assert_eq!((alone.points, alone.tets), (4, vec![[0, 1, 2, 3]]));
/// assert_eq!(sub_complex(&second, &[5]), None); // no tet 5
/// ```
pub fn sub_complex(c: &CutComplex, keep: &[usize]) -> Option<CutComplex> {
    let mut tet_map = vec![u32::MAX; c.tets.len()];
    let mut point_map = vec![u32::MAX; c.points];
    let mut points = 0u32;
    let mut tets = Vec::with_capacity(keep.len());
    for (new, &t) in keep.iter().enumerate() {
        *tet_map.get_mut(t)? = new as u32;
        let mut tet = *c.tets.get(t)?;
        for p in &mut tet {
            let slot = point_map.get_mut(*p as usize)?;
            if *slot == u32::MAX {
                *slot = points;
                points += 1;
            }
            *p = *slot;
        }
        tets.push(tet);
    }
    let cuts = c
        .cuts
        .iter()
        .map(|&[a, b]| {
            let (ma, mb) = (*tet_map.get(a as usize)?, *tet_map.get(b as usize)?);
            (ma != u32::MAX && mb != u32::MAX).then_some([ma, mb])
        })
        .collect::<Option<Vec<_>>>()?;
    Some(CutComplex { points: points as usize, tets, cuts })
}

/// Whether `symptom` shows after running the complex's cuts on both models (false when the
/// complex does not build or a cut is impossible).
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::campaign::{shows, Symptom};
/// use topomech::ambiguity::construct::CutComplex;
///
/// let pair = CutComplex { points: 5, tets: vec![[0, 1, 2, 3], [1, 2, 3, 4]], cuts: vec![[0, 1]] };
/// assert!(Symptom::ALL.iter().all(|&s| !shows(&pair, s)));
/// let uncut = CutComplex { cuts: vec![], ..pair.clone() };
/// assert!(shows(&uncut, Symptom::SkeletonUnchanged)); // no cut, nothing split
/// let twice = CutComplex { cuts: vec![[0, 1], [0, 1]], ..pair };
/// assert!(!shows(&twice, Symptom::SkeletonUnchanged)); // the second cut is impossible
/// ```
pub fn shows(c: &CutComplex, symptom: Symptom) -> bool {
    run_cuts(c.points, &c.tets, &c.cuts).is_ok_and(|run| run.symptoms().contains(&symptom))
}

/// Shrinks a complex showing `symptom` to a 1-minimal one: first the cut list, then the tets
/// (starting from the tets sharing a point with a cut face), each by [`ddmin`] within `budget`
/// tests. Returns the input unchanged if it does not show the symptom.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::campaign::{shows, shrink, Symptom};
/// use topomech::ambiguity::construct::{glued_faces, CutComplex};
/// use topomech::{generate, GMap};
///
/// let (points, tets) = generate::kuhn_cube(2);
/// let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
/// let one_cut = |f: [u32; 2]| CutComplex { points: points.len(), tets: tets.clone(), cuts: vec![f] };
/// let big = glued_faces(&map).into_iter().map(one_cut).find(|c| shows(c, Symptom::FaceStillShared)).unwrap();
/// let small = shrink(&big, Symptom::FaceStillShared, 500);
/// assert!(shows(&small, Symptom::FaceStillShared));
/// assert!(small.tets.len() < big.tets.len() && small.cuts.len() == 1);
/// ```
pub fn shrink(c: &CutComplex, symptom: Symptom, budget: usize) -> CutComplex {
    if !shows(c, symptom) {
        return c.clone();
    }
    let cuts = ddmin(&c.cuts, budget, &mut |cuts| shows(&CutComplex { cuts: cuts.to_vec(), ..c.clone() }, symptom));
    let c = CutComplex { cuts, ..c.clone() };
    let near: Vec<u32> = c.cuts.iter().flat_map(|&[a, b]| [c.tets[a as usize], c.tets[b as usize]]).flatten().collect();
    let mut keep: Vec<usize> = (0..c.tets.len()).filter(|&t| c.tets[t].iter().any(|p| near.contains(p))).collect();
    if !sub_complex(&c, &keep).is_some_and(|s| shows(&s, symptom)) {
        keep = (0..c.tets.len()).collect();
    }
    let keep = ddmin(&keep, budget, &mut |keep| sub_complex(&c, keep).is_some_and(|s| shows(&s, symptom)));
    sub_complex(&c, &keep).unwrap_or(c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ddmin_finds_the_single_culprit_and_pairs() {
        let items: Vec<u32> = (0..40).collect();
        assert_eq!(ddmin(&items, 1000, &mut |s| s.contains(&17)), vec![17]);
        assert_eq!(ddmin(&items, 1000, &mut |s| s.contains(&3) && s.contains(&31)), vec![3, 31]);
    }

    #[test]
    fn a_kuhn_cube_campaign_finds_lost_cuts_and_shrinks_them() {
        let (points, tets) = crate::generate::kuhn_cube(2);
        let mut rng = SplitMix64(7);
        let (stats, firsts) = campaign_k(points.len(), &tets, 3, 20, &mut rng).expect("runs");
        assert_eq!(stats.sequences, 20);
        assert_eq!(stats.gmap_invalid, 0);
        let total: usize = stats.symptoms.iter().map(|s| s.1).sum();
        assert!(total > 0 && stats.ambiguous > 0, "{stats:?}");
        let run = &firsts[0];
        let symptom = run.symptoms()[0];
        let big = CutComplex { points: points.len(), tets: tets.clone(), cuts: run.cuts.clone() };
        let small = shrink(&big, symptom, 2000);
        assert!(shows(&small, symptom));
        assert!(small.tets.len() < tets.len() && small.cuts.len() <= run.cuts.len());
    }
}
