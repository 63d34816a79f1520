//! API probe round 16 (findings 105–107 of `docs/VERIFICATION.md`), on the scale handling that
//! round 15 added: every test states a law the code before the round broke.
//!
//! - 105: `tet_distance` called points outside a tet of edge 1e-55 to 1e-75 inside (its inside
//!   test multiplied two volumes, a sixth power of the lengths, which underflowed to 0), so
//!   `refine_around` refined tets outside its ball at that scale.
//! - 106: needle tets just past 2²⁵⁰ long called outside points inside: round 15 scaled their
//!   length to about 1, which pushed their width towards underflow.
//! - 107: `triangle_area` of a needle (legs 1e200 and 1e-200) was 0: both edges were scaled by the
//!   longer one's power of two, and the short one underflowed.

use topomech::subdivide::{tet_distance, LeveledMap, TetMasses};
use topomech::GMap;

const UNIT: [[f64; 3]; 4] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// Finding 105: the distance from a point one edge length outside a tiny tet is that length, at
/// every scale from 1e-40 to 1e-90 (through the plain range's lower end, 2⁻²⁵⁰ ≈ 5.5e-76).
#[test]
fn tet_distance_outside_a_tiny_tet_is_its_distance() {
    for s in [1e-40, 1e-55, 1e-60, 1e-70, 1e-75, 1e-80, 1e-90] {
        let t = UNIT.map(|c| c.map(|x| x * s));
        let d = tet_distance([2.0 * s, 0.0, 0.0], t);
        assert!((d / s - 1.0).abs() < 1e-12, "scale {s:e}: distance {d:e}");
        assert_eq!(tet_distance([0.1 * s; 3], t), 0.0, "scale {s:e}: a point inside");
    }
}

/// Finding 105 through `refine_around`: a ball of radius 0 inside the first of two tets refines
/// that tet only, at scale 1 and at scale 1e-60.
#[test]
fn refine_around_picks_the_same_zone_at_a_tiny_scale() {
    for s in [1.0, 1e-60] {
        let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [1, 2, 3, 4]]).unwrap();
        let pts = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]];
        let mut m = LeveledMap::new(map, pts.iter().map(|p| p.map(|x| x * s)).collect());
        let mut masses = TetMasses::from_density(&m, 1.0).unwrap();
        let r = m.refine_around([0.1 * s; 3], 0.0, 1, &mut masses).unwrap();
        assert_eq!(r.subdivided_per_level, vec![0, 1], "scale {s:e}");
    }
}

/// Finding 106: needle tets of length 1e76, 1e100 and 1e150 (width 1): points beside and past
/// their thin end are at their distance (the code before round 15 gave these), points inside
/// at 0.
#[test]
fn tet_distance_outside_a_needle_is_its_distance() {
    for length in [1e76, 1e100, 1e150] {
        let needle = [[0.0, 0.0, 0.0], [length, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        for (p, expected) in [([-5.0, 0.2, 0.2], 5.0), ([-1.0, 0.0, 0.0], 1.0), ([-0.001, 0.3, 0.3], 0.001)] {
            let d = tet_distance(p, needle);
            assert!((d - expected).abs() <= 1e-9 * expected, "length {length:e}, {p:?}: {d:e}");
        }
        assert!((tet_distance([length / 2.0, 0.0, -3.0], needle) - 3.0).abs() < 1e-9, "length {length:e}");
        assert_eq!(tet_distance([1.0, 0.1, 0.1], needle), 0.0, "length {length:e}: inside");
    }
}

/// Finding 107: a needle triangle's area is ½ · long leg · short leg at any pair of scales.
#[test]
fn triangle_area_of_a_needle_is_its_area() {
    use topomech::mesh::triangle_area;
    assert_eq!(triangle_area([0.0; 3], [1e200, 0.0, 0.0], [0.0, 1e-200, 0.0]), 0.5);
    for (long, short) in [(1e100, 1e-215), (1e80, 1e-200), (1e300, 1e-300), (1e-150, 1e-170)] {
        let area = triangle_area([0.0; 3], [long, 0.0, 0.0], [0.0, short, 0.0]);
        let expected = 0.5 * long * short;
        assert!((area / expected - 1.0).abs() < 1e-15, "{long:e} × {short:e}: {area:e}");
    }
}
