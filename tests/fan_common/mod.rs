//! A mesh with one vertex of high valence, shared by the fan-walk probes (rounds 35 and 37).

use topomech::GMap;

/// Vertex 0 at the centre of a ring of `k` points on the unit circle, with an apex above
/// (point 1) and one below (point 2): 2k tets around vertex 0, whose fan walks meet k faces.
pub fn double_cone(k: usize) -> GMap<3> {
    let mut points = vec![[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
    for i in 0..k {
        let a = i as f64 * std::f64::consts::TAU / k as f64;
        points.push([a.cos(), a.sin(), 0.0]);
    }
    let mut tets = Vec::new();
    for i in 0..k {
        let (a, b) = (3 + i as u32, 3 + ((i + 1) % k) as u32);
        tets.push([0, a, b, 1]);
        tets.push([0, b, a, 2]);
    }
    GMap::<3>::from_tets(points.len(), &tets).unwrap().0
}
