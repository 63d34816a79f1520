//! A map as plain data: the α links of its darts, renumbered 0..darts. The form stored in the
//! JSON test vectors, so that any other engine can rebuild the maps.

use crate::gmap::{DartId, GMap, SewError};

/// The darts of an n-G-map with their α links: `alpha[d][i]` = αi(d), darts numbered densely in
/// increasing order of the map's own ids. Cell ids are not stored (they are derived data).
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::darts::DartsJson;
/// use topomech::GMap;
/// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
/// let json = DartsJson::of(&map);
/// assert_eq!((json.dim, json.alpha.len()), (2, 6));
/// // Each αi is an involution on the renumbered darts.
/// assert!((0..6).all(|d| (0..3).all(|i| json.alpha[json.alpha[d][i] as usize][i] == d as u32)));
/// ```
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct DartsJson {
    /// The dimension n.
    pub dim: usize,
    /// One row of n + 1 links per dart.
    pub alpha: Vec<Vec<u32>>,
}

/// Why a [`DartsJson`] does not describe a valid n-G-map.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::darts::{DartsError, DartsJson};
/// let bad = DartsJson { dim: 2, alpha: vec![vec![0, 0, 5]] };
/// let e = bad.to_map::<2>().unwrap_err();
/// assert!(matches!(e, DartsError::BadRow { dart: 0, darts: 1, .. }));
/// ```
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum DartsError {
    /// The stored dimension is not the one asked for.
    #[error("the darts are those of a {found}-map, not of a {expected}-map")]
    Dimension {
        /// The dimension asked for.
        expected: usize,
        /// The stored one.
        found: usize,
    },
    /// A row does not have n + 1 entries, or names a dart out of range.
    #[error("dart {dart}: row {row:?} is not n + 1 links into 0..{darts}")]
    BadRow {
        /// The dart.
        dart: usize,
        /// Its row.
        row: Vec<u32>,
        /// Number of darts.
        darts: usize,
    },
    /// αi is not an involution at this dart.
    #[error("alpha{i} is not an involution at dart {dart}")]
    NotInvolution {
        /// The dart.
        dart: usize,
        /// The involution.
        i: usize,
    },
    /// The kernel refused a sew: the links break the quasi-manifold law (the kernel refuses only
    /// some such links; the others are [`DartsError::NotQuasiManifold`]).
    #[error("rebuilding alpha{i} at dart {dart}: {source}")]
    Sew {
        /// The dart.
        dart: usize,
        /// The involution.
        i: usize,
        /// The kernel's reason.
        source: SewError,
    },
    /// The links break the quasi-manifold law (some αi∘αj with j ≥ i + 2 is no involution) in a
    /// way the kernel's orbit sews do not refuse: sewing the stored pairs also linked darts that
    /// the data stores otherwise. `dart` and `i` name the first difference (smallest dart, then
    /// smallest i) between the rebuilt links and the stored ones.
    #[error(
        "the links break the quasi-manifold law: the rebuilt alpha{i} of dart {dart} is {rebuilt}, the stored one {stored}"
    )]
    NotQuasiManifold {
        /// The dart.
        dart: usize,
        /// The involution.
        i: usize,
        /// αi(dart) as stored.
        stored: u32,
        /// αi(dart) in the map the sews built.
        rebuilt: u32,
    },
    /// The kernel could not create the darts.
    #[error("cannot create dart {0}")]
    Create(usize),
}

impl DartsJson {
    /// The links of `map`, renumbered. O(darts · n).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::darts::DartsJson;
    /// use topomech::GMap;
    ///
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let json = DartsJson::of(&map);
    /// assert_eq!((json.dim, json.alpha.len()), (3, 24));
    /// assert!(json.alpha.iter().all(|row| row.len() == 4));
    /// ```
    pub fn of<const N: usize>(map: &GMap<N>) -> Self {
        let mut rank = vec![u32::MAX; map.capacity()];
        for (r, d) in map.darts().enumerate() {
            rank[d.index()] = r as u32;
        }
        let alpha = map.darts().map(|d| (0..=N).map(|i| rank[map.alpha_dyn(i, d).index()]).collect()).collect();
        DartsJson { dim: N, alpha }
    }

    /// Rebuilds the map through the public kernel API only: creates the darts, then sews α0,
    /// α1, …, αn in that order (when αi is sewn, the involutions αj with j ≤ i − 2 it must commute
    /// with are already in place and those with j ≥ i + 2 are still free, so for links that obey
    /// the quasi-manifold law every orbit sew links exactly the stored pairs). Links that break
    /// the law are refused: either a sew fails, or an orbit sew links darts the data stores
    /// otherwise, and the rebuilt links are compared with the stored ones at the end (the map is
    /// returned only if [`DartsJson::of`] of it is `self`). O(darts · n²).
    ///
    /// # Errors
    /// [`DartsError::Dimension`], [`DartsError::BadRow`], [`DartsError::NotInvolution`] for
    /// malformed rows; [`DartsError::Sew`] or [`DartsError::NotQuasiManifold`] for links that are
    /// no n-G-map.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::darts::{DartsError, DartsJson};
    /// use topomech::GMap;
    ///
    /// let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [1, 2, 3, 4]]).unwrap();
    /// let json = DartsJson::of(&map);
    /// let back: GMap<3> = json.to_map().unwrap();
    /// assert!(back.is_isomorphic(&map));
    /// assert!(matches!(json.to_map::<2>(), Err(DartsError::Dimension { expected: 2, found: 3 })));
    /// // Edges 0–1 and 2–3, α2 linking 0 and 2 only: α0α2(0) = 3 but α0α2(3) = 2.
    /// let bad = DartsJson { dim: 2, alpha: vec![vec![1, 0, 2], vec![0, 1, 1], vec![3, 2, 0], vec![2, 3, 3]] };
    /// assert!(matches!(
    ///     bad.to_map::<2>(),
    ///     Err(DartsError::NotQuasiManifold { dart: 1, i: 2, stored: 1, rebuilt: 3 })
    /// ));
    /// ```
    pub fn to_map<const N: usize>(&self) -> Result<GMap<N>, DartsError> {
        if self.dim != N {
            return Err(DartsError::Dimension { expected: N, found: self.dim });
        }
        self.check_rows()?;
        let mut map = GMap::<N>::new();
        for d in 0..self.alpha.len() {
            map.create_dart().map_err(|_| DartsError::Create(d))?;
        }
        for i in 0..=N {
            for (d, row) in self.alpha.iter().enumerate() {
                let e = row[i] as usize;
                if e == d || !map.is_free(i, DartId(d as u32)) {
                    continue;
                }
                map.sew_dyn(i, DartId(d as u32), DartId(e as u32)).map_err(|source| DartsError::Sew {
                    dart: d,
                    i,
                    source,
                })?;
            }
        }
        // The darts were created as 0..len: compare the rebuilt links with the stored ones.
        for (d, row) in self.alpha.iter().enumerate() {
            for (i, &stored) in row.iter().enumerate() {
                let rebuilt = map.alpha_dyn(i, DartId(d as u32)).0;
                if rebuilt != stored {
                    return Err(DartsError::NotQuasiManifold { dart: d, i, stored, rebuilt });
                }
            }
        }
        debug_assert!(DartsJson::of(&map) == *self);
        Ok(map)
    }

    fn check_rows(&self) -> Result<(), DartsError> {
        let darts = self.alpha.len();
        for (d, row) in self.alpha.iter().enumerate() {
            if row.len() != self.dim + 1 || row.iter().any(|&e| e as usize >= darts) {
                return Err(DartsError::BadRow { dart: d, row: row.clone(), darts });
            }
            if let Some(i) = (0..=self.dim).find(|&i| self.alpha[row[i] as usize][i] as usize != d) {
                return Err(DartsError::NotInvolution { dart: d, i });
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_of_a_tet_pair_is_isomorphic() {
        let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [1, 2, 3, 4]]).expect("valid tets");
        let json = DartsJson::of(&map);
        let back: GMap<3> = json.to_map().expect("valid darts");
        assert!(back.validate().is_ok());
        assert!(back.is_isomorphic(&map));
        assert_eq!(back.count_cells(), map.count_cells());
    }

    #[test]
    fn broken_rows_are_refused() {
        let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).expect("valid triangle");
        let mut json = DartsJson::of(&map);
        json.alpha[0][0] = 2;
        assert!(matches!(json.to_map::<2>(), Err(DartsError::NotInvolution { .. })));
        assert!(matches!(json.to_map::<3>(), Err(DartsError::Dimension { .. })));
        json.alpha[0].pop();
        assert!(matches!(json.to_map::<2>(), Err(DartsError::BadRow { .. })));
    }
}
