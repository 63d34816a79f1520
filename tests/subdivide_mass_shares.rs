//! Children of a 1→8 split take the parent's mass in proportion to their rest volumes, also when
//! those volumes differ: a split edge whose midpoint vertex is not at the edge's midpoint (a
//! leveled map put back together from parts whose points moved, e.g. saved after deformation).
//! With midpoints at the midpoints all eight children have volume V/8 and an equal share would
//! pass unnoticed (a mutation survivor of the thirty-eighth sample: `volumes_of_children`
//! replaced by eight equal volumes).

use topomech::subdivide::{LeveledMap, TetMasses};
use topomech::GMap;

#[test]
fn children_share_the_mass_by_volume_when_a_midpoint_is_off_centre() {
    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let mut m = LeveledMap::new(map, pts);
    let d = m.map().darts().next().unwrap();
    let mid = m.split_edge(d, 1).unwrap();
    let mut parts = m.to_parts();
    let v = m.map().cell_id(0, mid).index();
    let (a, b) = (parts.points[m.map().cell_id(0, d).index()], parts.points[v]);
    // Slide the midpoint along its edge, a third of the way back towards d's end.
    parts.points[v] = std::array::from_fn(|k| b[k] + (a[k] - b[k]) / 3.0);
    let mut m = LeveledMap::from_parts(m.map().clone(), parts).unwrap();
    let mut masses = TetMasses::from_density(&m, 6.0).unwrap();
    let parent = masses.mass[m.map().cell_id(3, d).index()];
    let children = m.subdivide_tet_with_mass(d, 1, &mut masses).unwrap();
    let volumes: Vec<f64> = children.iter().map(|&c| m.tet_volume(c).unwrap().abs()).collect();
    let shares: Vec<f64> = children.iter().map(|&c| masses.mass[m.map().cell_id(3, c).index()]).collect();
    let total_volume: f64 = volumes.iter().sum();
    let (vmin, vmax) = volumes.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &x| (lo.min(x), hi.max(x)));
    assert!(vmax > 1.2 * vmin, "the moved midpoint makes the children's volumes differ: {volumes:?}");
    for (share, volume) in shares.iter().zip(&volumes) {
        let expected = parent * volume / total_volume;
        assert!((share - expected).abs() <= 1e-12 * parent, "share {share} for volume {volume}, expected {expected}");
    }
    assert!((shares.iter().sum::<f64>() - parent).abs() <= 1e-12 * parent);
}
