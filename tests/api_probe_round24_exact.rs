//! Round 24: round 23's exact decisions and the decisions beside them (findings 219–223).

use std::collections::BTreeSet;

use topomech::cut::ops::{Harness, Op};
use topomech::cut::tear_vertex;
use topomech::generate::kuhn_cube;
use topomech::gmap::AlphaMask;
use topomech::mechanics::{Body, Material};
use topomech::subdivide::{tet_distance, CouplingError, LeveledMap, LeveledMechanics};
use topomech::vtk::body_tets;
use topomech::{CellId, GMap};

mod rng_common;
use rng_common::next_unit;

fn pow2(k: i32) -> f64 {
    2f64.powi(k)
}

/// A tet whose orientation determinant is +2^-77 exactly, while a product of its cross product
/// underflows (5·2^-1076 rounds to 2^-1074) and is then multiplied by 2^1000: the float filter
/// alone says −2^-77.
fn mixed_scale_tet() -> [[f64; 3]; 4] {
    [[0.0; 3], [pow2(1000), -pow2(460), 0.0], [0.0, 5.0 * pow2(-538), pow2(-537)], [1.0, pow2(-537), pow2(-538)]]
}

/// The 24 orders of four corners.
fn orders() -> Vec<[usize; 4]> {
    let mut out = Vec::new();
    for a in 0..4 {
        for b in (0..4).filter(|&b| b != a) {
            for c in (0..4).filter(|&c| c != a && c != b) {
                out.push([a, b, c, 6 - a - b - c]);
            }
        }
    }
    out
}

#[test]
fn f219_a_corner_of_a_mixed_scale_tet_is_at_distance_zero_in_every_order() {
    let t = mixed_scale_tet();
    for order in orders() {
        let tt = order.map(|i| t[i]);
        for (i, &corner) in t.iter().enumerate() {
            assert_eq!(tet_distance(corner, tt), 0.0, "order {order:?}, corner {i}");
        }
    }
}

#[test]
fn f219_finest_tets_orient_a_mixed_scale_tet_positively() {
    // det[b − a, c − a, d − a] = +2^-77 for the tet as given; swapping two corners negates it,
    // so `finest_tets` must hand it back in an even permutation of [0, 1, 2, 3].
    let t = mixed_scale_tet();
    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let m = LeveledMap::new(map, t.to_vec());
    let tets = m.finest_tets().unwrap();
    assert_eq!(tets.len(), 1);
    let c = tets[0].0;
    let inversions = (0..4).flat_map(|i| (i + 1..4).map(move |j| (i, j))).filter(|&(i, j)| c[i] > c[j]).count();
    assert_eq!(inversions % 2, 0, "finest_tets returned {c:?}: the exact orientation is −1");
}

/// The faces a tear dissociates, as sorted triples of corner positions (bit patterns).
fn torn_faces(points: &[[f64; 3]], tets: &[[u32; 4]], v: u32, dir: [f64; 3]) -> Vec<[[u64; 3]; 3]> {
    let (mut body, _) = Body::from_tets(points, tets, Material::default()).unwrap();
    let tear = tear_vertex(&mut body, CellId(v), dir, None).unwrap();
    let (map, pos) = (body.map(), body.attrs().position());
    let mut out: Vec<[[u64; 3]; 3]> = tear
        .dissociations
        .iter()
        .map(|d| {
            let ids: BTreeSet<CellId> =
                map.orbit(d.dart, AlphaMask::of(&[0, 1])).into_iter().map(|x| map.vertex_id(x)).collect();
            let mut f: Vec<[u64; 3]> = ids.iter().map(|&i| pos[i].map(f64::to_bits)).collect();
            f.sort_unstable();
            [f[0], f[1], f[2]]
        })
        .collect();
    out.sort_unstable();
    out
}

/// A Kuhn cube rotated by (3/5, 4/5) on a decimal lattice: parallel faces whose exact scores tie
/// or nearly tie, so a normal rounded from the smallest-id corner picked by numbering.
#[test]
fn f220_the_faces_a_tear_dissociates_do_not_depend_on_the_numbering() {
    let (p0, t0) = kuhn_cube(3);
    let points: Vec<[f64; 3]> = p0
        .iter()
        .map(|p| [0.3 + 0.1 * (0.6 * p[0] - 0.8 * p[1]), 0.3 + 0.1 * (0.8 * p[0] + 0.6 * p[1]), 0.3 + 0.1 * p[2]])
        .collect();
    let dirs = [
        [0.6, 0.8, 0.0],
        [-0.8, 0.6, 0.0],
        [0.6, 0.8, 1.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [1.0, 1.0, 1.0],
        [0.0, 1.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, -1.0, 0.0],
        [0.3, 0.7, 0.2],
    ];
    let interior: Vec<u32> =
        (0..points.len() as u32).filter(|&i| p0[i as usize].iter().all(|&c| c > 0.5 && c < 2.5)).collect();
    let mut state = 12345u64;
    let (mut changed, mut tears) = (Vec::new(), 0);
    for trial in 0..6 {
        let mut perm: Vec<u32> = (0..points.len() as u32).collect();
        for i in (1..perm.len()).rev() {
            perm.swap(i, (next_unit(&mut state) * (i + 1) as f64) as usize);
        }
        let mut q = vec![[0.0; 3]; points.len()];
        for (old, &new) in perm.iter().enumerate() {
            q[new as usize] = points[old];
        }
        let t: Vec<[u32; 4]> = t0.iter().map(|t| t.map(|v| perm[v as usize])).collect();
        for &v in &interior {
            for dir in dirs {
                tears += 1;
                if torn_faces(&points, &t0, v, dir) != torn_faces(&q, &t, perm[v as usize], dir) {
                    changed.push((trial, v, dir));
                }
            }
        }
    }
    assert!(
        changed.is_empty(),
        "{} of {tears} tears changed with the numbering: {:?}",
        changed.len(),
        &changed[..changed.len().min(4)]
    );
}

/// Tet B's exact centroid is within rounding of the plane the harness builds for tet A
/// (x = 0.0137, normal +x): by the exact rule B is not strictly positive, and the harness's own
/// oracle must agree with the library's incision.
#[test]
fn f221_the_harness_oracle_decides_plane_sides_exactly() {
    let xs = [0.8439929428854351, 0.8178152702031081, 0.8714786339977247, -2.478486847086268];
    let points = vec![
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 1.0],
        [xs[0], 20.0, 0.0],
        [xs[1], 21.0, 0.0],
        [xs[2], 20.0, 1.0],
        [xs[3], 20.3, 0.3],
        [10.0, 20.4, 0.4],
    ];
    let tets = vec![[0, 1, 2, 3], [4, 5, 6, 7], [5, 6, 7, 8]];
    let mut h = Harness::new(points.clone(), tets.clone())
        .or_else(|_| Harness::new(points, vec![[0, 1, 3, 2], [4, 5, 7, 6], [5, 6, 8, 7]]))
        .unwrap();
    let r = h.apply(Op::Incise(0, [1.0, 0.0, 0.0]));
    assert!(r.is_ok(), "the harness failed a correct incision: {r:?}");
}

/// Whether the permutation `p` of 0..4 is even.
fn even(p: [u32; 4]) -> bool {
    (0..4).flat_map(|i| (i + 1..4).map(move |j| (i, j))).filter(|&(i, j)| p[i] > p[j]).count() % 2 == 0
}

/// The parity of the exactly positive order of the tet of `points`, through `finest_tets` (exact
/// since finding 216, checked against a rational oracle in round 24): `None` when it is flat
/// (the two input orders then come back as given, of different parity).
fn positive_parity(points: &[[f64; 3]]) -> Option<bool> {
    let parity = |tet: [u32; 4]| {
        let (map, _) = GMap::<3>::from_tets(4, &[tet]).unwrap();
        even(LeveledMap::new(map, points.to_vec()).finest_tets().unwrap()[0].0)
    };
    let (a, b) = (parity([0, 1, 2, 3]), parity([0, 1, 3, 2]));
    (a == b).then_some(a)
}

/// Slivers whose fourth corner is rounded onto the plane of the other three (exact orientation
/// tiny, of either sign): `body_tets` must write every one the body accepts in the exactly
/// positive order, as `finest_tets` does.
#[test]
fn f222_body_tets_never_writes_an_accepted_sliver_inside_out() {
    let mut state = 0x222u64;
    let mut unit = move || next_unit(&mut state);
    let (mut compared, mut inverted) = (0, 0);
    for _ in 0..20_000 {
        let (a, b, c) = ([unit(), unit(), unit()], [unit(), unit(), unit()], [unit(), unit(), unit()]);
        let (s, t) = (unit(), unit());
        let d = [0, 1, 2].map(|k| a[k] + s * (b[k] - a[k]) + t * (c[k] - a[k]));
        let points = vec![a, b, c, d];
        let Ok((body, _)) = Body::from_tets(&points, &[[0, 1, 2, 3]], Material::default()) else { continue };
        let Some(positive) = positive_parity(&points) else { continue };
        compared += 1;
        if body_tets(&body).iter().any(|&tet| even(tet) != positive) {
            inverted += 1;
        }
    }
    assert!(compared > 10_000, "compared {compared} slivers");
    assert_eq!(inverted, 0, "{inverted} of {compared} slivers written inside out");
}

/// A spring of −f64::MAX (written through `spring_mut`) would split into halves of −∞: refused
/// as +f64::MAX is, before the map changes.
#[test]
fn f223_a_split_refuses_a_spring_past_half_the_range_whatever_its_sign() {
    for field in 0..2 {
        let (points, tets) = kuhn_cube(2);
        let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
        let mut m = LeveledMap::new(map, points);
        let mut mech = LeveledMechanics::new(&m, Material::default()).unwrap();
        let e = mech.springs().next().unwrap().0;
        let spring = mech.spring_mut(e).unwrap();
        if field == 0 {
            spring.stiffness = -f64::MAX;
        } else {
            spring.damping = -f64::MAX;
        }
        let before = (format!("{m:?}"), format!("{mech:?}"));
        let d = m.map().darts().find(|&x| topomech::subdivide::EdgeKey::of(m.map(), x) == e).unwrap();
        let r = mech.split_edge(&mut m, d, 1);
        assert!(matches!(r, Err(CouplingError::SplitOverflow { .. })), "field {field}: {r:?}");
        assert_eq!(before, (format!("{m:?}"), format!("{mech:?}")), "field {field}: the refusal changed the state");
    }
}
