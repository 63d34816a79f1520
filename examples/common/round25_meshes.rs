//! Meshes of round 25's probes, shared by `examples/probe_round25.rs` and the round's tests
//! (`#[path]` modules; each user takes what it needs).
#![allow(dead_code)]

use topomech::mechanics::Material;
use topomech::subdivide::{LeveledMap, LeveledMechanics};
use topomech::{AlphaMask, DartId, GMap};

/// Two tets across the face x + y + z = 1, that face split 1→4 through the coupling at every
/// level up to `levels` (each coarse tet then has hundreds of hanging vertices).
pub fn split_face(levels: u8) -> (LeveledMap<3>, LeveledMechanics) {
    let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [4, 1, 3, 2]]).unwrap();
    let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]];
    let mut m = LeveledMap::new(map, pts);
    let mut mech = LeveledMechanics::new(&m, Material::default()).unwrap();
    for level in 1..=levels {
        let mut faces: Vec<DartId> = Vec::new();
        let mut seen = std::collections::HashSet::new();
        for d in m.map().darts() {
            if m.map().is_free(3, d) {
                continue;
            }
            let orbit = m.map().orbit(d, AlphaMask::of(&[0, 1]));
            let key = *orbit.iter().min().unwrap();
            let on_plane = orbit.iter().all(|&x| {
                let p = m.position(x);
                (p[0] + p[1] + p[2] - 1.0).abs() < 1e-9
            });
            if seen.insert(key) && on_plane {
                faces.push(d);
            }
        }
        for f in faces {
            if m.map().contains(f) {
                let _ = mech.subdivide_triangle(&mut m, f, level);
            }
        }
    }
    (m, mech)
}

/// A double cone: a centre, two apexes and a ring of k points; the edges centre–apex have
/// valence k.
pub fn double_cone(k: usize) -> (Vec<[f64; 3]>, Vec<[u32; 4]>) {
    let mut pts = vec![[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
    for i in 0..k {
        let a = 2.0 * std::f64::consts::PI * i as f64 / k as f64;
        pts.push([a.cos(), a.sin(), 0.0]);
    }
    let r = |i: usize| (3 + i % k) as u32;
    let mut tets = Vec::new();
    for i in 0..k {
        tets.push([0, 1, r(i), r(i + 1)]);
        tets.push([0, 2, r(i + 1), r(i)]);
    }
    (pts, tets)
}
