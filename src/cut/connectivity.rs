//! Connectivity after cutting (seed, conclusion): the connected components of the map, each a
//! body part that can be simulated on its own, with its mass.

use crate::mechanics::Body;
use crate::DartId;

/// One connected component (orbit of all involutions).
///
/// # Examples
///
/// ```
/// use topomech::cut::components;
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Material};
///
/// let (points, tets) = kuhn_cube(1);
/// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let parts = components(&body);
/// assert_eq!(parts.len(), 1);
/// assert_eq!((parts[0].volumes, parts[0].vertices), (6, 8));
/// assert!(parts[0].mass > 0.0);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Component {
    /// Its smallest dart.
    pub dart: DartId,
    /// Number of volumes (tets) in it.
    pub volumes: usize,
    /// Number of vertices in it.
    pub vertices: usize,
    /// Σ m_v over its vertices (= Σ m_t over its tets, by the conservation laws).
    pub mass: f64,
}

/// The components of `body`, ordered by smallest dart. O(darts).
///
/// # Examples
///
/// ```
/// use topomech::cut::{components, remove_volume};
/// use topomech::mechanics::{Body, Material};
/// use topomech::CellId;
///
/// // Three tets in a row: removing the middle one leaves two parts.
/// let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0], [2.0, 2.0, 0.0]];
/// let (mut body, _) = Body::from_tets(&p, &[[0, 1, 2, 3], [1, 2, 3, 4], [2, 3, 4, 5]], Material::default()).unwrap();
/// assert_eq!(components(&body).len(), 1);
/// remove_volume(&mut body, CellId(1)).unwrap();
/// let parts = components(&body);
/// assert_eq!(parts.iter().map(|c| c.volumes).collect::<Vec<_>>(), vec![1, 1]);
/// ```
pub fn components(body: &Body) -> Vec<Component> {
    let (map, mech) = (body.map(), body.attrs());
    let (label, count) = map.component_labels();
    let mut out: Vec<Component> =
        (0..count).map(|_| Component { dart: DartId(u32::MAX), volumes: 0, vertices: 0, mass: 0.0 }).collect();
    for d in map.darts() {
        let c = &mut out[label[d.index()] as usize];
        if c.dart.0 == u32::MAX {
            c.dart = d;
        }
    }
    for d in map.one_dart_per_cell(0) {
        let c = &mut out[label[d.index()] as usize];
        c.vertices += 1;
        c.mass += mech.vertex_mass(map.vertex_id(d));
    }
    for d in map.one_dart_per_cell(3) {
        out[label[d.index()] as usize].volumes += 1;
    }
    out
}
