//! Volume removal (seed §3.2): isolate the tet by dissociating its faces, then delete its darts.

use crate::embedding::CellRules;
use crate::mechanics::model::stiffness_contribution;
use crate::mechanics::{Body, TouchedCells};
use crate::{CellId, DartId, GMap};

use super::{dissociate_face, CutError, Dissociation};

/// What one volume removal did.
///
/// # Examples
///
/// ```
/// use topomech::cut::remove_volume;
/// use topomech::mechanics::{Body, Material};
/// use topomech::CellId;
///
/// let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0], [2.0, 2.0, 0.0]];
/// let (mut body, _) = Body::from_tets(&p, &[[0, 1, 2, 3], [1, 2, 3, 4], [2, 3, 4, 5]], Material::default()).unwrap();
/// let removal = remove_volume(&mut body, CellId(1)).unwrap();
/// assert_eq!(removal.volume, CellId(1));
/// assert_eq!(removal.dissociations.len(), 2); // the middle tet had two inner faces
/// assert!(removal.removed_mass > 0.0 && removal.removed_stiffness > 0.0);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Removal {
    /// The removed volume id (now free).
    pub volume: CellId,
    /// Its mass m_t: the body's total mass dropped by exactly this.
    pub removed_mass: f64,
    /// Σ over its six edges of its stiffness contribution E_t·V_t/L_e²: the body's total spring
    /// stiffness dropped by this.
    pub removed_stiffness: f64,
    /// The dissociations of its inner faces (its neighbours' faces became boundary faces).
    pub dissociations: Vec<Dissociation>,
    /// Vertex and edge ids whose projected values changed or that disappeared.
    pub touched: TouchedCells,
}

/// A dart of volume `t`, or `None` if no live dart carries that id. Tries dart 24·t first (the
/// builder's numbering), then scans. O(1) when the numbering still holds, else O(darts).
///
/// # Examples
///
/// ```
/// use topomech::cut::volume_dart;
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Material};
/// use topomech::CellId;
///
/// let (points, tets) = kuhn_cube(1);
/// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let d = volume_dart(&body, CellId(4)).unwrap();
/// assert_eq!(body.map().cell_id(3, d), CellId(4));
/// assert_eq!(volume_dart(&body, CellId(6)), None); // only 6 tets
/// ```
pub fn volume_dart(body: &Body, t: CellId) -> Option<DartId> {
    let map = body.map();
    let guess = DartId(t.0.wrapping_mul(24));
    if map.contains(guess) && map.cell_id(3, guess) == t {
        return Some(guess);
    }
    map.darts().find(|&d| map.cell_id(3, d) == t)
}

/// Removes the tetrahedron `t`: dissociates each of its faces that is α3-sewn (mass and stiffness
/// of its vertices and edges are shared out by the split rules, seed §3.2), so the tet becomes a
/// component of its own whose vertices carry exactly m_t/4 each and whose edges carry exactly its
/// stiffness contributions; then unlinks its 24 darts inside the kernel and deletes them. What
/// remains sums to the old totals minus [`Removal::removed_mass`] and
/// [`Removal::removed_stiffness`].
///
/// Cost: O(darts) to find the tet when the builder's numbering no longer holds (O(1) otherwise),
/// plus four dissociations and O(24²) for the inner unlinking.
///
/// # Errors
/// [`CutError::NoSuchVolume`] (never existed or already removed), [`CutError::NotATet`] — body
/// unchanged; [`CutError::Body`], [`CutError::Kernel`], [`CutError::Dart`] are bugs, and so is
/// the attributes' check failing after the deletion (`expensive-checks` only).
///
/// # Examples
///
/// ```
/// use topomech::cut::{remove_volume, CutError};
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{check_conservation, Body, Material};
/// use topomech::CellId;
///
/// let (points, tets) = kuhn_cube(1);
/// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let removal = remove_volume(&mut body, CellId(0)).unwrap();
/// assert!((removal.removed_mass - 1.0 / 6.0).abs() < 1e-12); // one sixth of the unit cube
/// assert_eq!(body.map().count_cells().0[3], 5);
/// check_conservation(body.map(), body.attrs()).unwrap();
/// assert!(matches!(remove_volume(&mut body, CellId(0)), Err(CutError::NoSuchVolume(_))));
/// ```
pub fn remove_volume(body: &mut Body, t: CellId) -> Result<Removal, CutError> {
    let d = volume_dart(body, t).ok_or(CutError::NoSuchVolume(t))?;
    // A defence: attributes that do not cover the map (replaced whole before round 27).
    let refused = |source| crate::embedding::EmbedError::Refused { op: "remove_volume", dart: d, source };
    body.attrs().check_covers(body.map()).map_err(refused)?;
    let darts = body.map().cell_darts(3, d);
    if darts.len() != 24 {
        return Err(CutError::NotATet { volume: t, dart: d, darts: darts.len() });
    }
    let (removed_mass, removed_stiffness) = mass_and_stiffness(body, t, &darts);
    let from = body.version();
    let mut touched = TouchedCells::default();
    let mut dissociations = Vec::new();
    for x in one_dart_per_face(body.map(), &darts) {
        if !body.map().is_free(3, x) {
            let dis = dissociate_face(body, x)?;
            touched.extend(&dis.touched);
            dissociations.push(dis);
        }
    }
    let map = body.map();
    for &x in &darts {
        touched.vertices.push((map.vertex_id(x), None));
        touched.edges.push((map.cell_id(1, x), None));
    }
    delete_isolated(body, &darts)?;
    // The deletion bypasses the rules, so the embedding layer's check after each operation does
    // not run for it: under `expensive-checks`, the attributes' laws on what is left (finding 327).
    #[cfg(feature = "expensive-checks")]
    {
        use crate::embedding::CellRules;
        let check = |source| crate::embedding::EmbedError::Check { op: "remove_volume", dart: d, source };
        body.attrs().check(body.map()).map_err(check)?;
    }
    touched.cover(body, from);
    Ok(Removal { volume: t, removed_mass, removed_stiffness, dissociations, touched })
}

/// m_t and Σ_e E_t·V_t/L_e² of the tet `t` made of `darts`.
fn mass_and_stiffness(body: &Body, t: CellId, darts: &[DartId]) -> (f64, f64) {
    let (map, mech) = (body.map(), body.attrs());
    let mut edges: Vec<CellId> = darts.iter().map(|&x| map.cell_id(1, x)).collect();
    edges.sort_unstable();
    edges.dedup();
    let (young, volume) = (mech.tet_young(t), mech.tet_rest_volume(t));
    let stiffness = edges.iter().map(|&e| stiffness_contribution(young, volume, mech.edge_rest_length(e))).sum();
    (mech.tet_mass(t), stiffness)
}

/// One dart of each distinct face among `darts`.
fn one_dart_per_face(map: &GMap<3>, darts: &[DartId]) -> Vec<DartId> {
    let mut faces: Vec<(CellId, DartId)> = darts.iter().map(|&x| (map.cell_id(2, x), x)).collect();
    faces.sort_unstable_by_key(|&(f, _)| f);
    faces.dedup_by_key(|&mut (f, _)| f);
    faces.into_iter().map(|(_, x)| x).collect()
}

/// Unlinks every α0/α1/α2 link among the darts of an isolated volume with the kernel's unsew
/// (each step keeps the map valid), deletes the darts and grows the attribute arrays to the ids
/// the kernel may have handed out meanwhile. The attributes of the deleted cells stay as dead
/// slots, which nothing reads.
fn delete_isolated(body: &mut Body, darts: &[DartId]) -> Result<(), CutError> {
    let (map, mech) = body.parts_mut_bypassing_rules();
    for &x in darts {
        for i in 0..3 {
            if !map.is_free(i, x) {
                map.unsew_dyn(i, x)?;
            }
        }
    }
    for &x in darts {
        map.delete_dart(x)?;
    }
    mech.grow_to(map);
    Ok(())
}
