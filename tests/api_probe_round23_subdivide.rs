//! Round 23 (probe C) fixes in the refinement path, checked against exact oracles written here:
//! - 211: the octahedron's diagonal is one choice for all 24 corner orders and both paths, and it
//!   is never longer than the shortest by more than the documented tolerance (a chain of three
//!   near-equal diagonals made the pairwise 1e-12 tie test depend on which diagonal came first).
//! - 214: `tet_distance` is exactly 0 for a point on the tet (corner, edge, face), in every corner
//!   order, so `refine_around(v, 0.0, 1)` subdivides exactly the star of v (liver_547 lost 6 of
//!   the 32 tets at vertex 527).
//! - 216: the conforming closure and `finest_tets` at scales 1e-300 … 1e300: the closure succeeds
//!   wherever the split does, and every output tet has a positive exact orientation.

use std::path::Path;
use topomech::subdivide::{tet_distance, triangulate_polygon, LeveledMap, TetMasses};
use topomech::GMap;

mod rng_common;

type P = [f64; 3];

/// All 24 orders of four corners.
fn permutations() -> Vec<[usize; 4]> {
    let mut out = Vec::new();
    for a in 0..4 {
        for b in 0..4 {
            for c in 0..4 {
                for d in 0..4 {
                    let p = [a, b, c, d];
                    if (0..4).all(|x| p.contains(&x)) {
                        out.push(p);
                    }
                }
            }
        }
    }
    out
}

/// A small deterministic generator (xorshift64*), uniform in [0, 1).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        rng_common::next_unit(&mut self.0)
    }
    fn unit(&mut self) -> P {
        loop {
            let v = [2.0 * self.next() - 1.0, 2.0 * self.next() - 1.0, 2.0 * self.next() - 1.0];
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            if n > 0.3 && n < 1.0 {
                return v.map(|x| x / n);
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Exact oracles: error-free transformations (two_sum, fma two_product) over f64.

fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

fn two_product(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

/// Adds `x` to the nonoverlapping expansion `e` (increasing magnitude), exactly.
fn grow(e: &mut Vec<f64>, x: f64) {
    let mut q = x;
    let mut out = Vec::with_capacity(e.len() + 1);
    for &c in e.iter() {
        let (s, err) = two_sum(q, c);
        if err != 0.0 {
            out.push(err);
        }
        q = s;
    }
    if q != 0.0 {
        out.push(q);
    }
    *e = out;
}

/// Sign of the exact sum of `terms` (each an f64, summed exactly).
fn exact_sum_sign(terms: &[f64]) -> i32 {
    let mut e = Vec::new();
    for &t in terms {
        grow(&mut e, t);
    }
    match e.last() {
        None => 0,
        Some(&x) if x > 0.0 => 1,
        Some(_) => -1,
    }
}

/// The exact sign of det[b − a, c − a, d − a], for finite coordinates whose nonzero magnitudes
/// lie within 2^±150 of each other after one exact power-of-two rescale (asserted), so that no
/// error term of the products underflows.
fn exact_orientation(t: [P; 4]) -> i32 {
    let largest = t.iter().flatten().fold(0.0_f64, |m, x| m.max(x.abs()));
    assert!(largest.is_finite());
    if largest == 0.0 {
        return 0;
    }
    let e = largest.log2().floor() as i32;
    let scale = |x: f64| {
        // x · 2^-e in two exact steps (each result normal: asserted below).
        let y = x * 2f64.powi(-e / 2) * 2f64.powi(-(e - e / 2));
        assert!(y == 0.0 || (y.abs() > 2f64.powi(-150) && y.abs() < 4.0), "oracle range: {x:e}");
        y
    };
    let t = t.map(|p| p.map(scale));
    // Differences as exact two-term expansions.
    let diff = |p: P, q: P| [0, 1, 2].map(|k| two_sum(p[k], -q[k]));
    let (u, v, w) = (diff(t[1], t[0]), diff(t[2], t[0]), diff(t[3], t[0]));
    let mut terms = Vec::new();
    // det = Σ over permutations σ of sgn(σ) u_σ0 v_σ1 w_σ2.
    for (s, (i, j, k)) in
        [(1.0, (0, 1, 2)), (1.0, (1, 2, 0)), (1.0, (2, 0, 1)), (-1.0, (0, 2, 1)), (-1.0, (1, 0, 2)), (-1.0, (2, 1, 0))]
    {
        for &x in &[u[i].0, u[i].1] {
            for &y in &[v[j].0, v[j].1] {
                for &z in &[w[k].0, w[k].1] {
                    let (p, pe) = two_product(s * x, y);
                    for q in [p, pe] {
                        let (r, re) = two_product(q, z);
                        terms.push(r);
                        terms.push(re);
                    }
                }
            }
        }
    }
    exact_sum_sign(&terms)
}

/// |p − q|² to about 1e-30 relative (double-double).
fn accurate_len2(p: P, q: P) -> f64 {
    let mut e = Vec::new();
    for k in 0..3 {
        let (hi, lo) = two_sum(p[k], -q[k]);
        let (a, ae) = two_product(hi, hi);
        let (b, be) = two_product(2.0 * hi, lo);
        let (c, ce) = two_product(lo, lo);
        for x in [a, ae, b, be, c, ce] {
            grow(&mut e, x);
        }
    }
    e.iter().sum()
}

// ---------------------------------------------------------------------------------------------
// 211: the diagonal.

/// The diagonal chosen for the tet with these corners (in this order), by `subdivide_tet` (bulk
/// = false) or `refine_uniform`, as its two endpoint positions in increasing order.
fn chosen_diagonal(corners: [P; 4], bulk: bool) -> (P, P) {
    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let mut m = LeveledMap::new(map, corners.to_vec());
    if bulk {
        let mut masses = TetMasses::from_density(&m, 1.0).unwrap();
        m.refine_uniform(1, &mut masses).unwrap();
    } else {
        let d = m.map().darts().next().unwrap();
        m.subdivide_tet(d, 1).unwrap();
    }
    // The diagonal: the two midpoints (ids ≥ 4) shared by the four tets made of midpoints only.
    let inner: Vec<[u32; 4]> =
        m.finest_tets().unwrap().iter().map(|&(t, _, _)| t).filter(|t| t.iter().all(|&v| v >= 4)).collect();
    assert_eq!(inner.len(), 4);
    let ids: Vec<u32> = (4..10).filter(|v| inner.iter().all(|t| t.contains(v))).collect();
    assert_eq!(ids.len(), 2, "{inner:?}");
    let (p, q) = (m.points()[ids[0] as usize], m.points()[ids[1] as usize]);
    if p.partial_cmp(&q) == Some(std::cmp::Ordering::Less) {
        (p, q)
    } else {
        (q, p)
    }
}

/// The three diagonals of the octahedron of `corners`, from the midpoints as the library
/// computes them (½(a + b) per coordinate).
fn diagonals(c: [P; 4]) -> [(P, P); 3] {
    let mid = |a: P, b: P| [0, 1, 2].map(|k| 0.5 * (a[k] + b[k]));
    [(mid(c[0], c[1]), mid(c[2], c[3])), (mid(c[0], c[2]), mid(c[1], c[3])), (mid(c[0], c[3]), mid(c[1], c[2]))]
}

/// The law for one tet: one diagonal for all 24 corner orders and both paths, no longer than the
/// exact shortest by more than 1e-12 relative (plus 1e-14 for the rounding of the squared
/// lengths the library compares).
fn check_diagonal_law(corners: [P; 4], what: &str) {
    let mut first = None;
    for order in permutations() {
        let c = order.map(|i| corners[i]);
        for bulk in [false, true] {
            let d = chosen_diagonal(c, bulk);
            match first {
                None => first = Some(d),
                Some(f) => assert_eq!(d, f, "{what}: order {order:?} (bulk {bulk}) chose another diagonal"),
            }
        }
    }
    let (p, q) = first.unwrap();
    let chosen = accurate_len2(p, q);
    let shortest = diagonals(corners).iter().map(|&(a, b)| accurate_len2(a, b)).fold(f64::INFINITY, f64::min);
    assert!(
        chosen <= shortest * (1.0 + 1e-12 + 1e-14),
        "{what}: chosen diagonal {chosen:.17} is {:e} relatively longer than the shortest {shortest:.17}",
        chosen / shortest - 1.0
    );
}

/// The disphenoid of the report (half-axes 1 + 7e-13, 1 + 3.5e-13, 1) and its axis permutations,
/// reflections and a few other chains of near-ties.
#[test]
fn f211_diagonal_is_order_independent_for_near_tie_disphenoids() {
    for t in [5.5e-13, 7e-13, 9.5e-13] {
        let half = [1.0 + t, 1.0 + t / 2.0, 1.0];
        for axes in [[0, 1, 2], [1, 2, 0], [2, 0, 1], [0, 2, 1]] {
            let (a, b, c) = (half[axes[0]], half[axes[1]], half[axes[2]]);
            for sign in [1.0, -1.0] {
                let corners = [[a, b, c], [a, -b, -c], [-a, b, -c], [-a, -b, c]].map(|p| p.map(|x| sign * x));
                check_diagonal_law(corners, &format!("disphenoid t = {t:e}, axes {axes:?}, sign {sign}"));
            }
        }
    }
}

/// Random tets whose three diagonals form a chain of near-ties (A–B and B–C within 1e-12, A–C
/// not): corners solved from three random diagonal vectors D1..D3 and a centre o
/// (a = o + (D1 + D2 + D3)/2, …), at several magnitudes.
#[test]
fn f211_diagonal_is_order_independent_for_random_near_tie_tets() {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    for case in 0..24 {
        let (u, v, w) = (rng.unit(), rng.unit(), rng.unit());
        let independent = {
            let x = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
            (x[0] * w[0] + x[1] * w[1] + x[2] * w[2]).abs() > 0.2
        };
        if !independent {
            continue;
        }
        let step1 = (0.55 + 0.4 * rng.next()) * 0.5e-12; // squared: 1.1e-12 to 1.9e-12 for two steps
        let step2 = (0.55 + 0.4 * rng.next()) * 0.5e-12;
        let mut lens = [1.0 + step1 + step2, 1.0 + step1, 1.0];
        let mut dirs = [u, v, w];
        if case % 4 == 3 {
            lens.rotate_left(case % 3); // any assignment
        } else {
            // The hard case: the position tie-break against the lengths. A diagonal's smaller
            // endpoint has x = o_x − |D_x|/2, so the largest |D_x| gets the longest diagonal.
            dirs.sort_by(|a, b| b[0].abs().total_cmp(&a[0].abs()));
        }
        let scale = [1.0, 3.7e-5, 2.9e6][case % 3];
        let d = dirs.iter().zip(lens).map(|(x, l)| x.map(|c| c * l * scale)).collect::<Vec<_>>();
        let o = [rng.next(), rng.next(), rng.next()].map(|x| x * scale);
        let corner = |s: [f64; 3]| [0, 1, 2].map(|k| o[k] + 0.5 * (s[0] * d[0][k] + s[1] * d[1][k] + s[2] * d[2][k]));
        let corners =
            [corner([1.0, 1.0, 1.0]), corner([1.0, -1.0, -1.0]), corner([-1.0, 1.0, -1.0]), corner([-1.0, -1.0, 1.0])];
        check_diagonal_law(corners, &format!("random case {case}"));
    }
}

// ---------------------------------------------------------------------------------------------
// 214: distance 0 on the tet; radius-0 balls.

fn liver() -> topomech::mesh::TetMesh {
    topomech::io::read_mesh(Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/data/liver_547_v22.msh"))).unwrap()
}

/// Whether ½(a + b) is the exact midpoint (the sum of each coordinate exact).
fn exact_mid(a: P, b: P) -> Option<P> {
    let mut m = [0.0; 3];
    for k in 0..3 {
        let (s, e) = two_sum(a[k], b[k]);
        if e != 0.0 || !s.is_finite() {
            return None;
        }
        m[k] = 0.5 * s;
    }
    Some(m)
}

/// Points on the liver's tets built exactly — corners, exact edge midpoints, exact midpoints of
/// an edge midpoint and the third corner of a face (on the face) — are at distance exactly 0 in
/// every corner order.
#[test]
fn f214_tet_distance_is_zero_on_the_tet_in_every_corner_order() {
    let mesh = liver();
    let perms = permutations();
    let (mut corners_checked, mut edge_points, mut face_points) = (0, 0, 0);
    for tet in &mesh.tets {
        let c = tet.map(|v| mesh.points[v as usize]);
        let mut on = c.to_vec();
        corners_checked += 4;
        for (i, j, k) in [(0, 1, 2), (1, 2, 3), (2, 3, 0), (3, 0, 1), (0, 2, 1), (1, 3, 0)] {
            if let Some(m) = exact_mid(c[i], c[j]) {
                on.push(m);
                edge_points += 1;
                if let Some(f) = exact_mid(m, c[k]) {
                    on.push(f);
                    face_points += 1;
                }
            }
        }
        for p in on {
            for order in &perms {
                let t = order.map(|i| c[i]);
                assert_eq!(tet_distance(p, t), 0.0, "point {p:?} on tet {tet:?}, corner order {order:?}");
            }
        }
    }
    assert!(corners_checked > 7000 && edge_points > 500 && face_points > 50, "{edge_points} {face_points}");
}

/// The same law at scales where the coordinates round (non-dyadic scales) and at extreme ones:
/// random integer tets times s, their corners and exact edge points.
#[test]
fn f214_tet_distance_is_zero_on_the_tet_at_any_scale() {
    let mut rng = Rng(12345);
    let perms = permutations();
    let mut checked = 0;
    for s in [0.1, 1.0 / 3.0, 0.7, 1e-3, 1e-150, 3e200, 7e-300] {
        for _ in 0..40 {
            let c: [P; 4] = [0; 4].map(|_| [0; 3].map(|_| (rng.next() * 16.0).floor() * s));
            if exact_orientation(c) == 0 {
                continue;
            }
            let mut on = c.to_vec();
            for (i, j) in [(0, 1), (1, 2), (2, 3), (3, 0), (0, 2), (1, 3)] {
                on.extend(exact_mid(c[i], c[j]));
            }
            for p in on {
                for order in &perms {
                    assert_eq!(tet_distance(p, order.map(|i| c[i])), 0.0, "scale {s:e}: {p:?} on {c:?}, {order:?}");
                    checked += 1;
                }
            }
        }
    }
    assert!(checked > 10_000);
}

/// The radius-0 ball at a vertex meets exactly the tets that contain it: `tet_in_ball` for every
/// (vertex, tet) pair of liver_547, and `refine_around(v, 0.0, 1)` subdivides exactly the star of
/// v for a sample of vertices (527 and 387 of the report among them), with the vertex ids as in
/// the file and reversed (so each tet's corners come in another order).
#[test]
fn f214_radius_zero_ball_at_a_vertex_refines_exactly_its_star() {
    let mesh = liver();
    let n = mesh.points.len() as u32;
    for reversed in [false, true] {
        let renumber = |v: u32| if reversed { n - 1 - v } else { v };
        let mut points = vec![[0.0; 3]; n as usize];
        for (v, p) in mesh.points.iter().enumerate() {
            points[renumber(v as u32) as usize] = *p;
        }
        let tets: Vec<[u32; 4]> = mesh.tets.iter().map(|t| t.map(renumber)).collect();
        let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
        let base = LeveledMap::new(map, points.clone());
        // Every pair: the predicate.
        let cells: Vec<(topomech::DartId, [u32; 4])> =
            base.map().one_dart_per_cell(3).into_iter().map(|d| (d, base.tet_vertices(d).unwrap())).collect();
        for v in 0..n {
            for &(d, t) in &cells {
                let meets = base.tet_in_ball(d, points[v as usize], 0.0).unwrap();
                assert_eq!(meets, t.contains(&v), "vertex {v} and tet {t:?} (reversed ids: {reversed})");
            }
        }
        // A sample: the refinement.
        let sample: Vec<u32> = [527u32, 387].iter().map(|&v| renumber(v)).chain((0..n).step_by(37)).collect::<Vec<_>>();
        for v in sample {
            let mut m = base.clone();
            let mut masses = TetMasses::from_density(&m, 1.0).unwrap();
            let r = m.refine_around(points[v as usize], 0.0, 1, &mut masses).unwrap();
            let star = tets.iter().filter(|t| t.contains(&v)).count();
            assert_eq!(r.subdivided_per_level, vec![0, star], "vertex {v} (reversed ids: {reversed})");
            for (t, level, _) in m.finest_tets().unwrap() {
                assert!(level == 1 || !t.contains(&v), "tet {t:?} at vertex {v} left at level 0");
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// 216: the closure and the finest tets at any scale.

/// The two-tet example scaled by 10^k: one tet split; the closure succeeds and every tet of
/// `conforming_tets` and `finest_tets` has a positive exact orientation; the rustdoc polygon of
/// `triangulate_polygon` scaled the same way triangulates into two triangles.
#[test]
fn f216_closure_and_finest_tets_are_positive_at_every_scale() {
    let unit: [P; 5] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]];
    for k in (-300..=300).step_by(3) {
        let s = format!("1e{k}").parse::<f64>().unwrap();
        let pts: Vec<P> = unit.iter().map(|p| p.map(|x| x * s)).collect();
        let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [1, 2, 3, 4]]).unwrap();
        let mut m = LeveledMap::new(map, pts);
        let d = m.map().darts().next().unwrap();
        m.subdivide_tet(d, 1).unwrap();
        let closure = m.conforming_tets().unwrap_or_else(|e| panic!("scale 1e{k}: {e}"));
        assert_eq!((closure.kept, closure.closed), (8, 1), "scale 1e{k}");
        for t in &closure.tets {
            let p = t.map(|v| closure.points[v as usize]);
            assert_eq!(exact_orientation(p), 1, "scale 1e{k}: conforming tet {t:?}");
        }
        let finest = m.finest_tets().unwrap();
        assert_eq!(finest.len(), 9);
        for (t, _, _) in finest {
            let p = t.map(|v| m.points()[v as usize]);
            assert_eq!(exact_orientation(p), 1, "scale 1e{k}: finest tet {t:?}");
        }
        let poly: Vec<P> = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0], [1.0, 0.0, 0.0]]
            .iter()
            .map(|p| p.map(|x| x * s))
            .collect();
        let tris = triangulate_polygon(&[0, 3, 1, 2], &poly).unwrap_or_else(|| panic!("scale 1e{k}: no triangulation"));
        assert_eq!(tris.len(), 2, "scale 1e{k}");
    }
}
