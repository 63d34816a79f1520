//! The flat-array baseline: the same mass/spring system built straight from the tet list, with no
//! map at all (the "classic adjacency graph" of seed §5.1).
//!
//! Vertices are the input points; springs are the distinct tet edges (sorted pairs); the laws are
//! applied by looping over the tets: m_v = Σ m_t/4, k_e = Σ E V_t / L_e², c_e = β k_e,
//! γ_v = ν m_v. It is the oracle of the map-driven model in tests and its baseline in benchmarks.
//! On a mesh with a pinched point the map has several vertices there and this baseline one, so
//! the two differ exactly there.

use super::force::SpringSystem;
use super::geom::{rest_length, tet_volume, Vec3};
use super::model::{check_material, stiffness_contribution, Material, ModelError, ModelTotals};
use crate::build::BuildError;

/// A flat mass/spring model: its [`SpringSystem`] and its own state arrays.
///
/// # Examples
///
/// ```
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{FlatModel, Material};
///
/// let (points, tets) = kuhn_cube(1);
/// let pinned = [true, false, false, false, false, false, false, false];
/// let flat = FlatModel::from_tets(&points, &tets, Material::default(), [0.0; 3], &pinned).unwrap();
/// assert_eq!(flat.rest_position, flat.position); // starts at rest
/// assert!(flat.velocity.iter().all(|v| *v == [0.0; 3]));
/// assert_eq!(flat.system.inv_mass()[0], 0.0); // the pinned point does not move
/// assert!(flat.system.inv_mass()[1] > 0.0);
/// ```
#[derive(Clone, Debug)]
pub struct FlatModel {
    /// The arrays the step loop reads.
    pub system: SpringSystem,
    /// Rest positions (the input points).
    pub rest_position: Vec<Vec3>,
    /// Positions.
    pub position: Vec<Vec3>,
    /// Velocities.
    pub velocity: Vec<Vec3>,
}

impl FlatModel {
    /// Builds the model of `tets` over `points`, at rest, with `pinned[i]` fixing point i (an
    /// empty slice pins nothing). O(T log T).
    ///
    /// # Errors
    /// What [`crate::mechanics::Body::from_tets`] refuses, so that the oracle and the body are
    /// built from the same inputs: [`ModelError::BadMaterial`], [`ModelError::Build`] for a bad
    /// index or repeated point, [`ModelError::DegenerateTet`] for a zero-volume tet,
    /// [`ModelError::VolumeUnderflow`] for a tet whose volume is not 0 but below the normal f64
    /// range, [`ModelError::MassTooSmall`] for a mass with no finite inverse,
    /// [`ModelError::NonFinitePoint`], [`ModelError::Overflow`] when a volume or a total (mass,
    /// stiffness, damping) overflows f64; and [`ModelError::BadGravity`] for a non-finite gravity,
    /// [`ModelError::PinCount`] for a pin list that is neither empty nor one flag per point.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{FlatModel, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let flat = FlatModel::from_tets(&points, &tets, Material::default(), [0.0; 3], &[]).unwrap();
    /// assert_eq!((flat.system.slots(), flat.system.springs()), (8, 19)); // one spring per edge
    /// assert!((flat.system.mass().iter().sum::<f64>() - 1.0).abs() < 1e-12); // density 1, unit cube
    /// assert_eq!(flat.position, points);
    /// let negative = Material { young: -1.0, ..Material::default() };
    /// assert!(FlatModel::from_tets(&points, &tets, negative, [0.0; 3], &[]).is_err()); // as Body::from_tets
    /// assert!(FlatModel::from_tets(&points, &tets, Material::default(), [0.0; 3], &[true; 2]).is_err()); // 2 pins, 8 points
    /// ```
    pub fn from_tets(
        points: &[Vec3],
        tets: &[[u32; 4]],
        material: Material,
        gravity: Vec3,
        pinned: &[bool],
    ) -> Result<Self, ModelError> {
        check_material(&material)?;
        if gravity.iter().any(|g| !g.is_finite()) {
            return Err(ModelError::BadGravity(gravity));
        }
        if !(pinned.is_empty() || pinned.len() == points.len()) {
            return Err(ModelError::PinCount { len: pinned.len(), points: points.len() });
        }
        check(points, tets)?;
        let n = points.len();
        let mut mass = vec![0.0; n];
        let mut contributions: Vec<(u64, f64)> = Vec::with_capacity(6 * tets.len());
        let mut totals = ModelTotals::default();
        for (t, tet) in tets.iter().enumerate() {
            let c = tet.map(|v| points[v as usize]);
            let volume = tet_volume(c[0], c[1], c[2], c[3]);
            totals.add(t, c, volume, &material)?;
            for &v in tet {
                mass[v as usize] += material.density * volume / 4.0;
            }
            for (i, j) in [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)] {
                let (a, b) = (tet[i].min(tet[j]), tet[i].max(tet[j]));
                let l = rest_length(points[a as usize], points[b as usize]);
                contributions.push(((a as u64) << 32 | b as u64, stiffness_contribution(material.young, volume, l)));
            }
        }
        contributions.sort_by_key(|&(key, _)| key);
        let mut ends: Vec<[u32; 2]> = Vec::new();
        let mut stiffness: Vec<f64> = Vec::new();
        for (key, k) in contributions {
            let e = [(key >> 32) as u32, key as u32];
            if ends.last() == Some(&e) {
                *stiffness.last_mut().expect("pushed with ends") += k;
            } else {
                ends.push(e);
                stiffness.push(k);
            }
        }
        let rest = ends.iter().map(|&[a, b]| rest_length(points[a as usize], points[b as usize])).collect();
        let damping = stiffness.iter().map(|k| material.damping * k).collect();
        let viscosity = mass.iter().map(|m| material.viscosity * m).collect();
        let fixed: Vec<bool> = (0..n).map(|i| pinned.get(i).copied().unwrap_or(false)).collect();
        let system = SpringSystem::from_arrays(ends, rest, stiffness, damping, mass, &fixed, viscosity, gravity);
        Ok(FlatModel { system, rest_position: points.to_vec(), position: points.to_vec(), velocity: vec![[0.0; 3]; n] })
    }
}

fn check(points: &[Vec3], tets: &[[u32; 4]]) -> Result<(), ModelError> {
    if let Some((point, &coords)) = points.iter().enumerate().find(|(_, p)| p.iter().any(|c| !c.is_finite())) {
        return Err(ModelError::NonFinitePoint { point, coords });
    }
    for (element, tet) in tets.iter().enumerate() {
        for (corner, &index) in tet.iter().enumerate() {
            if index as usize >= points.len() {
                return Err(BuildError::IndexOutOfRange { element, corner, index, points: points.len() }.into());
            }
            if tet[..corner].contains(&index) {
                return Err(BuildError::RepeatedVertex { element, point: index }.into());
            }
        }
    }
    // A tet listed twice, refused as `Body::from_tets` refuses it (its copies would double the mass).
    if let Some((first, second)) = crate::mesh::duplicate_cells(tets) {
        return Err(BuildError::DuplicateElement { what: "tet", first, second, points: tets[first].to_vec() }.into());
    }
    Ok(())
}
