//! The tet-list oracle of the sweep tests (`cut_sweep`, `cut_sweep_scale`): what a cut along a
//! surface must dissociate, computed without the map.

use std::collections::HashMap;

use topomech::cut::PolylineSweep;
use topomech::mechanics::Vec3;

/// From the tet list only: the number of inner faces (vertex triples shared by two tets) whose
/// tets' centroids are joined by a segment crossing `surface`. O(tets).
pub fn crossing_faces(points: &[Vec3], tets: &[[u32; 4]], surface: &PolylineSweep) -> usize {
    let centroid = |t: &[u32; 4]| {
        let mut c = [0.0; 3];
        for &v in t {
            (0..3).for_each(|k| c[k] += points[v as usize][k] / 4.0);
        }
        c
    };
    let mut owners: HashMap<[u32; 3], Vec<usize>> = HashMap::new();
    for (i, t) in tets.iter().enumerate() {
        for skip in 0..4 {
            let mut f: Vec<u32> = (0..4).filter(|&j| j != skip).map(|j| t[j]).collect();
            f.sort_unstable();
            owners.entry([f[0], f[1], f[2]]).or_default().push(i);
        }
    }
    owners.values().filter(|o| o.len() == 2 && surface.crosses(centroid(&tets[o[0]]), centroid(&tets[o[1]]))).count()
}
