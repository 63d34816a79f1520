//! Round 23, probe C, findings 212, 213 and 215: the cuts' geometric decisions are exact and do
//! not depend on numbering.
//!
//! - 212: `Plane::positive` / `tet_sides` / `incise_plane` decide the side of a tet's exact
//!   centroid exactly: an on-plane centroid is negative for every normal length, the face set
//!   is the same for n and c·n (exact multiples) and under renumbering of points and tets, and
//!   equals an exact integer oracle.
//! - 213: `PolylineSweep::crosses` / `sweep_faces`: a segment ending exactly on the swept
//!   surface (at a polyline point, at P + w, at a mid-edge point) crosses, for decimal data.
//! - 215: `tear_vertex` tears the same faces (as vertex-position triples) whatever the order of
//!   the tet list, on liver_547, a jittered cube and the exact Kuhn cube.

use std::collections::BTreeSet;
use std::path::Path;

use topomech::cut::{incise_plane, ops::jittered_cube, sweep_faces, tear_vertex, tet_sides, Plane, PolylineSweep};
use topomech::generate::kuhn_cube;
use topomech::mechanics::{check_conservation, Body, Material, Vec3};
use topomech::{CellId, DartId};

type Key = [[u64; 3]; 3];

/// The face of `d` as its three corner positions (bit patterns), sorted.
fn face_key(body: &Body, d: DartId) -> Key {
    let map = body.map();
    let mut ids: Vec<CellId> = map.cell_darts(2, d).into_iter().map(|x| map.vertex_id(x)).collect();
    ids.sort_unstable();
    ids.dedup();
    assert_eq!(ids.len(), 3, "a triangle");
    let mut k: Vec<[u64; 3]> = ids.iter().map(|&v| body.attrs().position()[v].map(f64::to_bits)).collect();
    k.sort_unstable();
    [k[0], k[1], k[2]]
}

fn body_of(points: &[Vec3], tets: &[[u32; 4]]) -> Body {
    Body::from_tets(points, tets, Material::default()).unwrap().0
}

/// The faces an incision cuts, as position triples.
fn plane_cut(points: &[Vec3], tets: &[[u32; 4]], plane: &Plane) -> BTreeSet<Key> {
    let mut body = body_of(points, tets);
    let cut = incise_plane(&mut body, plane).unwrap();
    check_conservation(body.map(), body.attrs()).unwrap();
    cut.dissociations.iter().map(|d| face_key(&body, d.dart)).collect()
}

/// A small deterministic generator (64-bit LCG, high bits).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        self.0 >> 33
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
    fn shuffle<T>(&mut self, v: &mut [T]) {
        for i in (1..v.len()).rev() {
            v.swap(i, self.below(i as u64 + 1) as usize);
        }
    }
}

/// The inner faces of the tet list (sorted vertex triples) with their two tets.
fn inner_faces(tets: &[[u32; 4]]) -> Vec<([u32; 3], usize, usize)> {
    let mut all: Vec<([u32; 3], usize)> = Vec::new();
    for (t, tet) in tets.iter().enumerate() {
        for skip in 0..4 {
            let mut f: Vec<u32> = (0..4).filter(|&i| i != skip).map(|i| tet[i]).collect();
            f.sort_unstable();
            all.push(([f[0], f[1], f[2]], t));
        }
    }
    all.sort_unstable();
    all.windows(2).filter(|w| w[0].0 == w[1].0).map(|w| (w[0].0, w[0].1, w[1].1)).collect()
}

/// Finding 212, the probe's reproduction: the centroid (1.25, 2.5, 3.75) of a tet of
/// `kuhn_cube(4)` is exactly on the plane for both normals (−0.2 = 2 · −0.1 exactly); it is not
/// positive for either, and both cut the same 56 faces.
#[test]
fn f212_on_plane_centroid_is_negative_for_every_normal_length() {
    let (points, tets) = kuhn_cube(4);
    let mut sets = Vec::new();
    for normal in [[-2.0, -1.0, -2.0], [-0.2, -0.1, -0.2], [-2e-300, -1e-300, -2e-300], [-0.002, -0.001, -0.002]] {
        let plane = Plane { point: [2.75, 0.5, 3.25], normal };
        assert!(!plane.positive([1.25, 2.5, 3.75]), "normal {normal:?}: on the plane is not positive");
        let set = plane_cut(&points, &tets, &plane);
        assert_eq!(set.len(), 56, "normal {normal:?}");
        sets.push(set);
    }
    assert!(sets.windows(2).all(|w| w[0] == w[1]));
}

/// Finding 212: on `kuhn_cube(4)` (integer corners), planes through vertices and through tet
/// centroids with normals of power-of-two components (so that c·n is exactly f64(c)·n) cut the
/// same faces for n and c·n, c ∈ {1, 0.1, 1/3, 0.7, 1e-3}, and exactly the faces an integer
/// oracle selects: the sign of Σ_corners (corner − p) · n, all terms exact small dyadics, with
/// a zero (exact centroid on the plane) on the negative side.
#[test]
fn f212_face_set_same_for_exact_multiples_of_the_normal_and_equal_to_the_oracle() {
    let (points, tets) = kuhn_cube(4);
    let faces = inner_faces(&tets);
    let comps = [0.0, 1.0, -1.0, 2.0, -2.0, 0.5, -4.0];
    let mut rng = Lcg(212);
    let mut planes = 0;
    let mut ties = 0;
    while planes < 40 {
        let n: Vec3 = [0, 1, 2].map(|_| comps[rng.below(comps.len() as u64) as usize]);
        if n == [0.0; 3] {
            continue;
        }
        let point = if rng.below(2) == 0 {
            points[rng.below(points.len() as u64) as usize]
        } else {
            let t = tets[rng.below(tets.len() as u64) as usize];
            let s = t.iter().fold([0.0; 3], |s, &v| [0, 1, 2].map(|k| s[k] + points[v as usize][k]));
            s.map(|c| c / 4.0) // exact: quarters of small integers
        };
        // The oracle: exact in f64 (small dyadic values, no rounding anywhere).
        let side = |t: usize| {
            let s: f64 =
                tets[t].iter().map(|&v| (0..3).map(|k| (points[v as usize][k] - point[k]) * n[k]).sum::<f64>()).sum();
            s > 0.0
        };
        let expected: BTreeSet<[u32; 3]> = faces.iter().filter(|(_, a, b)| side(*a) != side(*b)).map(|f| f.0).collect();
        ties += (0..tets.len())
            .filter(|&t| {
                tets[t]
                    .iter()
                    .map(|&v| (0..3).map(|k| (points[v as usize][k] - point[k]) * n[k]).sum::<f64>())
                    .sum::<f64>()
                    == 0.0
            })
            .count();
        let oracle: BTreeSet<Key> = expected
            .iter()
            .map(|f| {
                let mut k: Vec<[u64; 3]> = f.iter().map(|&v| points[v as usize].map(f64::to_bits)).collect();
                k.sort_unstable();
                [k[0], k[1], k[2]]
            })
            .collect();
        for c in [1.0, 0.1, 1.0 / 3.0, 0.7, 1e-3] {
            let plane = Plane { point, normal: n.map(|x| x * c) };
            assert_eq!(plane_cut(&points, &tets, &plane), oracle, "point {point:?} normal {n:?} × {c}");
        }
        planes += 1;
    }
    assert!(ties > 100, "the planes must hold many exact centroids ({ties})");
}

/// Finding 212: `kuhn_cube(4)` scaled by 0.1 (rounded, non-dyadic coordinates), planes through
/// vertices with integer normals: the face set does not depend on the numbering of the points
/// nor on the order of the tets (nor of each tet's corners), and `tet_sides` agrees tet by tet.
#[test]
fn f212_cut_independent_of_point_and_tet_numbering() {
    let (points, tets) = kuhn_cube(4);
    let points: Vec<Vec3> = points.iter().map(|p| p.map(|c| c * 0.1)).collect();
    let mut rng = Lcg(2120);
    let mut perm: Vec<u32> = (0..points.len() as u32).collect();
    rng.shuffle(&mut perm); // old id i becomes perm[i]
    let mut renumbered = vec![[0.0; 3]; points.len()];
    for (i, &j) in perm.iter().enumerate() {
        renumbered[j as usize] = points[i];
    }
    let mut order: Vec<usize> = (0..tets.len()).collect();
    rng.shuffle(&mut order);
    let retets: Vec<[u32; 4]> = order
        .iter()
        .map(|&t| {
            let mut c = tets[t].map(|v| perm[v as usize]);
            // Even permutations of the corners (orientation kept).
            if t % 2 == 0 {
                c.swap(0, 1);
                c.swap(2, 3);
            }
            if t % 3 == 0 {
                c[1..].rotate_left(1);
            }
            c
        })
        .collect();
    let normals = [[1.0, 2.0, 3.0], [-2.0, -1.0, -2.0], [3.0, -1.0, 1.0], [1.0, 1.0, 1.0], [5.0, 0.0, -3.0]];
    let mut differing_sides = 0;
    for (i, normal) in normals.iter().enumerate() {
        for j in 0..8 {
            let point = points[(i * 37 + j * 11) % points.len()];
            let plane = Plane { point, normal: *normal };
            let a = plane_cut(&points, &tets, &plane);
            let b = plane_cut(&renumbered, &retets, &plane);
            assert_eq!(a, b, "plane {plane:?}: the cut depends on numbering");
            // tet_sides tet by tet (keyed by corner positions).
            let side_map = |pts: &[Vec3], ts: &[[u32; 4]]| {
                let body = body_of(pts, ts);
                let sides = tet_sides(&body, &plane).unwrap();
                let mut m: Vec<([[u64; 3]; 4], bool)> = ts
                    .iter()
                    .enumerate()
                    .map(|(t, tet)| {
                        let mut k = tet.map(|v| pts[v as usize].map(f64::to_bits));
                        k.sort_unstable();
                        (k, t)
                    })
                    .map(|(k, t)| (k, sides[t].unwrap()))
                    .collect();
                m.sort_unstable();
                m
            };
            let (sa, sb) = (side_map(&points, &tets), side_map(&renumbered, &retets));
            differing_sides += sa.iter().zip(&sb).filter(|(x, y)| x != y).count();
        }
    }
    assert_eq!(differing_sides, 0);
}

/// Finding 213, the probe's reproduction: a segment ending exactly at the bent slit's point P₂
/// (decimal sweep) crosses, and `sweep_faces` on `kuhn_cube(3)` selects the face (18, 22, 38)
/// whose tets' centroids are (1.75, 0.5, 1.25) and that point.
#[test]
fn f213_segment_ending_on_the_sweep_counts_as_crossing() {
    let slit =
        PolylineSweep { points: vec![[2.5, 0.25, 2.75], [3.0, 3.0, 2.0], [2.25, 0.75, 1.5]], sweep: [0.3, 0.3, 0.3] };
    assert!(slit.crosses([1.75, 0.5, 1.25], [2.25, 0.75, 1.5]));
    assert!(slit.crosses([2.25, 0.75, 1.5], [1.75, 0.5, 1.25]));
    let (points, tets) = kuhn_cube(3);
    let body = body_of(&points, &tets);
    let selected: BTreeSet<Key> = sweep_faces(&body, &slit).unwrap().into_iter().map(|d| face_key(&body, d)).collect();
    let mut want: Vec<[u64; 3]> = [18, 22, 38].iter().map(|&v: &usize| points[v].map(f64::to_bits)).collect();
    want.sort_unstable();
    assert!(selected.contains(&[want[0], want[1], want[2]]), "face (18, 22, 38) left out");
}

/// `x + y` if it is exact in f64 (Fast2Sum error zero), per component.
fn exact_sum(x: Vec3, y: Vec3) -> Option<Vec3> {
    let mut out = [0.0; 3];
    for k in 0..3 {
        let (a, b) = if x[k].abs() >= y[k].abs() { (x[k], y[k]) } else { (y[k], x[k]) };
        let s = a + b;
        if b - (s - a) != 0.0 {
            return None;
        }
        out[k] = s;
    }
    Some(out)
}

/// Finding 213: random decimal quads (coordinates k/10, k/100, non-dyadic) and segments from a
/// random decimal point to a point exactly on the surface — a polyline point, P + w when that
/// sum is exact, the exact midpoint of an edge when it is exact — always cross, in both
/// directions; segments between two points exactly on the surface too.
#[test]
fn f213_exact_boundary_points_of_the_quad_are_crossed() {
    let mut rng = Lcg(213);
    let mut dec = |scale: f64| (rng.below(2001) as f64 - 1000.0) / scale;
    let mut checked = 0;
    for case in 0..400 {
        let scale = if case % 2 == 0 { 10.0 } else { 100.0 };
        let p0 = [dec(scale), dec(scale), dec(scale)];
        let p1 = [dec(scale), dec(scale), dec(scale)];
        let w = [dec(scale), dec(scale), dec(scale)];
        let a = [dec(scale), dec(scale), dec(scale)];
        let slit = PolylineSweep { points: vec![p0, p1], sweep: w };
        if slit.check().is_err() {
            continue;
        }
        let mut on: Vec<Vec3> = vec![p0, p1];
        on.extend(exact_sum(p0, w));
        on.extend(exact_sum(p1, w));
        if let Some(m) = exact_sum(p0, p1).map(|s| s.map(|c| c / 2.0)) {
            if exact_sum(m, m) == exact_sum(p0, p1) {
                on.push(m);
            }
        }
        for &b in &on {
            // Skip segments nearly parallel to the quad (the documented tolerance decides them).
            let (d, e) = ([0, 1, 2].map(|k| b[k] - a[k]), [0, 1, 2].map(|k| p1[k] - p0[k]));
            let det = d[0] * (e[1] * w[2] - e[2] * w[1]) - d[1] * (e[0] * w[2] - e[2] * w[0])
                + d[2] * (e[0] * w[1] - e[1] * w[0]);
            let size = [d, e, w].iter().map(|v| v.iter().map(|c| c * c).sum::<f64>().sqrt()).product::<f64>();
            if det.abs() <= 1e-6 * size {
                continue;
            }
            assert!(slit.crosses(a, b), "case {case}: {a:?} → {b:?} ends on the surface {slit:?}");
            assert!(slit.crosses(b, a), "case {case}: {b:?} → {a:?} starts on the surface {slit:?}");
            checked += 1;
        }
    }
    assert!(checked > 600, "{checked}");
}

/// The faces a tear dissociates, as position triples, with `tets` in the given order; the
/// vertex is named by its point (vertex ids are point indices).
fn tear_faces(points: &[Vec3], tets: &[[u32; 4]], v: usize, dir: Vec3) -> (BTreeSet<Key>, bool) {
    let mut body = body_of(points, tets);
    assert_eq!(body.attrs().position()[CellId(v as u32)], points[v]);
    let tear = tear_vertex(&mut body, CellId(v as u32), dir, None).unwrap();
    check_conservation(body.map(), body.attrs()).unwrap();
    body.map().validate().unwrap();
    (tear.dissociations.iter().map(|d| face_key(&body, d.dart)).collect(), tear.split)
}

fn tet_orders(tets: &[[u32; 4]], seed: u64) -> Vec<Vec<[u32; 4]>> {
    let reversed: Vec<[u32; 4]> = tets.iter().rev().copied().collect();
    let mut shuffled = tets.to_vec();
    Lcg(seed).shuffle(&mut shuffled);
    vec![reversed, shuffled]
}

fn check_tears(points: &[Vec3], tets: &[[u32; 4]], vertices: &[usize], seed: u64) -> usize {
    let dirs = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.3, -0.7, 0.2], [1.0, 1.0, 1.0], [0.0, 0.0, -1.0]];
    let orders = tet_orders(tets, seed);
    let mut torn = 0;
    for &v in vertices {
        for dir in dirs {
            let (base, split) = tear_faces(points, tets, v, dir);
            assert_eq!(tear_faces(points, tets, v, dir.map(|c| -c)), (base.clone(), split), "±direction");
            for (i, order) in orders.iter().enumerate() {
                let (other, other_split) = tear_faces(points, order, v, dir);
                assert_eq!(base, other, "vertex {v} direction {dir:?}: tet order {i} tears other faces");
                assert_eq!(split, other_split);
            }
            torn += usize::from(!base.is_empty());
        }
    }
    torn
}

/// Finding 215 on liver_547: for several vertices and directions the dissociated faces are the
/// same with the tet list in file order, reversed and shuffled.
#[test]
fn f215_tear_faces_independent_of_tet_order_liver() {
    let liver =
        topomech::io::read_mesh(Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/data/liver_547_v22.msh"))).unwrap();
    let vertices = [0, 37, 101, 250, 387, 400, 527];
    assert!(check_tears(&liver.points, &liver.tets, &vertices, 215) > 20);
}

/// Finding 215 on a jittered Kuhn cube k = 3 and on the exact one (where many face scores tie
/// exactly): interior and boundary vertices, several directions, three tet orders.
#[test]
fn f215_tear_faces_independent_of_tet_order_cubes() {
    let (points, tets) = jittered_cube(3, 7);
    assert!(check_tears(&points, &tets, &[5, 21, 22, 26, 37, 42, 63], 2150) > 20);
    let (points, tets) = kuhn_cube(3);
    assert!(check_tears(&points, &tets, &[5, 21, 22, 42, 0], 2151) > 15);
}
