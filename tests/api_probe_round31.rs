//! Round 31's probes. Finding 274: the 2D 1→4 split of a valid triangle nearly collinear at the
//! scale of its coordinates gave children that the rounded midpoints made collinear or
//! inverted; it now refuses such a split with `FlatTriangleChild` before any change, on the
//! single operation and on the bulk path.

use topomech::subdivide::{LeveledMap, SubdivideError};
use topomech::GMap;

#[path = "rng_common/mod.rs"]
mod rng_common;

/// The exact orientation of (a, b, c) in the plane of the coordinates `axes` (the third one
/// constant), for coordinates 1 + k·2⁻⁵² (k < 2⁵²): integers k, i128.
fn exact_sign(p: [[f64; 3]; 3], axes: [usize; 2]) -> i32 {
    let k = |x: f64| ((x - 1.0) * 2f64.powi(52)) as i128;
    let d = |i: usize| axes.map(|c| k(p[i][c]) - k(p[0][c]));
    let (b, c) = (d(1), d(2));
    (b[0] * c[1] - b[1] * c[0]).signum() as i32
}

/// The midpoint labels: 3 + side k, side k = corners (k, k + 1 mod 3).
const SIDES: [(usize, usize); 3] = [(0, 1), (1, 2), (2, 0)];

/// A random valid triangle nearly collinear at its scale: corners 1 + k·ulp, the third within
/// a few steps of the line through the first two, in the plane of `axes` (third coordinate 1);
/// offsets multiples of `step` ulps.
fn thin_triangle(state: &mut u64, axes: [usize; 2], step: f64) -> [[f64; 3]; 3] {
    let ulp = step * 2f64.powi(-52);
    let mut r = || rng_common::next_unit(state);
    let big = |r: f64| (1.0 + (r * 2f64.powi(30)).floor()) * ulp;
    let flat = [[1.0, 1.0], [1.0 + big(r()), 1.0], [1.0 + big(r()) / 2.0, 1.0 + (1.0 + (r() * 6.0).floor()) * ulp]];
    let order = [[0, 1, 2], [1, 0, 2], [2, 0, 1], [0, 2, 1], [1, 2, 0], [2, 1, 0]][(r() * 6.0) as usize];
    order.map(|i| {
        let mut q = [1.0; 3];
        q[axes[0]] = flat[i][0];
        q[axes[1]] = flat[i][1];
        q
    })
}

/// Every face of `m` (one triangle `p` split 1→4) has the parent's orientation `parent` in the
/// plane of `axes`, in integers: each child vertex labelled by its position (a corner or a
/// rounded side midpoint), the sign each sorted label triple must have read off a reference
/// triangle whose midpoints f64 holds exactly.
fn check_children_oriented(m: &LeveledMap<2>, p: [[f64; 3]; 3], axes: [usize; 2], parent: i32) {
    let reference: Vec<[f64; 3]> = {
        let c = [[1.0; 3], [1.0 + 2f64.powi(-40), 1.0, 1.0], [1.0, 1.0 + 2f64.powi(-40), 1.0]];
        let mut all = c.to_vec();
        all.extend(SIDES.iter().map(|&(x, y)| topomech::mesh::midpoint(c[x], c[y])));
        all
    };
    assert!(m.check_all().is_ok());
    let points = m.points();
    let at = |l: usize| if l < 3 { p[l] } else { topomech::mesh::midpoint(p[SIDES[l - 3].0], p[SIDES[l - 3].1]) };
    let label_of = |v: u32| -> usize {
        let hits: Vec<usize> = (0..6).filter(|&l| at(l) == points[v as usize]).collect();
        assert_eq!(hits.len(), 1, "a corner or a distinct midpoint");
        hits[0]
    };
    let faces = m.map().one_dart_per_cell(2);
    assert_eq!(faces.len(), 4);
    for f in faces {
        let mut vs: Vec<u32> =
            m.map().orbit(f, topomech::AlphaMask::of(&[0, 1])).into_iter().map(|x| m.map().vertex_id(x).0).collect();
        vs.sort_unstable();
        vs.dedup();
        let mut labels: Vec<usize> = vs.into_iter().map(label_of).collect();
        labels.sort_unstable();
        assert_eq!(labels.len(), 3);
        let r = |l: usize| reference[l];
        let want = exact_sign([r(labels[0]), r(labels[1]), r(labels[2])], [0, 1])
            * exact_sign([r(0), r(1), r(2)], [0, 1])
            * parent;
        let got = exact_sign([at(labels[0]), at(labels[1]), at(labels[2])], axes);
        assert_ne!(got, 0, "child {labels:?} of {p:?} is collinear");
        assert_eq!(got, want, "child {labels:?} of {p:?} is inverted");
    }
}

/// Finding 274: each random thin triangle is either refused with `FlatTriangleChild` (the map
/// unchanged) or split into four children that all have the parent's orientation, checked in
/// integers (each child vertex labelled by its position, the reference signs read off a
/// triangle whose midpoints f64 holds exactly). Before, about half of such splits made a
/// collinear or inverted child.
#[test]
fn a_nearly_collinear_triangle_is_refused_or_split_into_children_oriented_as_it() {
    let (mut refused, mut split, mut state) = (0, 0, 0x9e37_79b9_u64);
    for round in 0..400 {
        let axes = [[0, 1], [1, 2], [2, 0], [1, 0]][round % 4];
        let p = thin_triangle(&mut state, axes, 1.0);
        let parent = exact_sign(p, axes);
        assert_ne!(parent, 0, "valid");
        let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
        let mut m = LeveledMap::new(map, p.to_vec());
        let d = m.map().darts().next().unwrap();
        let before = format!("{m:?}");
        match m.subdivide_triangle(d, 1) {
            Err(SubdivideError::FlatTriangleChild { level: 1, child, .. }) => {
                refused += 1;
                assert!(child.iter().all(|&l| l < 6));
                assert_eq!(format!("{m:?}"), before, "refused before any change");
            }
            Err(e) => panic!("unexpected {e}"),
            Ok(_) => {
                split += 1;
                check_children_oriented(&m, p, axes, parent);
            }
        }
    }
    assert!(refused > 0 && split > 0, "both kinds met: {refused} refused, {split} split");
}

/// The bulk path refuses the same triangles, before any change, and names the first parent;
/// an ordinary neighbour alone is split.
#[test]
fn the_bulk_path_refuses_a_thin_triangle_before_any_change() {
    let mut state = 0x51ed_2701_u64;
    let mut met = 0;
    for _ in 0..200 {
        let p = thin_triangle(&mut state, [0, 1], 1.0);
        let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
        let single = {
            let mut m = LeveledMap::new(map.clone(), p.to_vec());
            let d = m.map().darts().next().unwrap();
            m.subdivide_triangle(d, 1).map(drop)
        };
        let mut m = LeveledMap::new(map, p.to_vec());
        let before = format!("{m:?}");
        match (m.refine_uniform(1), single) {
            (Err(SubdivideError::FlatTriangleChild { .. }), Err(SubdivideError::FlatTriangleChild { .. })) => {
                met += 1;
                assert_eq!(format!("{m:?}"), before, "refused before any change");
            }
            (Ok(1), Ok(())) => assert!(m.check_all().is_ok()),
            (bulk, single) => panic!("the two paths disagree: bulk {bulk:?}, single {single:?}"),
        }
    }
    assert!(met > 0);
    // An ordinary grid is not affected.
    let (map, _) = GMap::<2>::from_triangles(4, &[[0, 1, 2], [1, 3, 2]]).unwrap();
    let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]];
    let mut m = LeveledMap::new(map, pts);
    assert_eq!(m.refine_uniform(1).unwrap(), 2);
}

/// A surface triangle in 3D is checked in its dominant projection: thin triangles on the plane
/// z = 1 + 2(x − 1) + 3(y − 1) (exact on these coordinates; normal ∝ (−2, −3, 1), so the
/// dominant projection is onto the zx plane) are refused or split into children oriented as
/// the parent there, in integers.
#[test]
fn a_tilted_thin_triangle_is_refused_or_split_into_children_oriented_as_it() {
    let mut state = 0x1234_5678_u64;
    let (mut refused, mut split) = (0, 0);
    for _ in 0..300 {
        let flat = thin_triangle(&mut state, [0, 1], 1.0);
        let p = flat.map(|q| [q[0], q[1], 1.0 + 2.0 * (q[0] - 1.0) + 3.0 * (q[1] - 1.0)]);
        assert!(p.iter().all(|q| q[2] - 1.0 == 2.0 * (q[0] - 1.0) + 3.0 * (q[1] - 1.0)), "exact plane");
        let parent = exact_sign(p, [2, 0]);
        let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
        let mut m = LeveledMap::new(map, p.to_vec());
        let d = m.map().darts().next().unwrap();
        let before = format!("{m:?}");
        match m.subdivide_triangle(d, 1) {
            Err(SubdivideError::FlatTriangleChild { .. }) => {
                refused += 1;
                assert_eq!(format!("{m:?}"), before, "refused before any change");
            }
            Err(e) => panic!("unexpected {e}"),
            Ok(_) => {
                split += 1;
                check_children_oriented(&m, p, [2, 0], parent);
            }
        }
    }
    assert!(refused > 0 && split > 0, "both kinds met: {refused} refused, {split} split");
}

/// The tets of a fan of `k` tets around the edge (0, 1), closed or open.
fn fan_tets(k: u32, closed: bool) -> Vec<[u32; 4]> {
    (0..k).map(|t| [0, 1, 2 + t, 2 + (t + 1) % (k + u32::from(!closed))]).collect()
}

/// Finding 276: when one unsew cuts a cell into three or more pieces, it reports one split per
/// extra piece, and a later split could carry an earlier one's `dart_kept` away to its own new
/// piece, so the report said that dart carried `kept` when, after the operation (when the
/// embedding rules read it), it carried another id. Now every split of every report holds in the
/// final map: `dart_kept` carries `kept`, `dart_new` carries `new`. Random unsews of every index
/// on open and closed fans of 3–6 tets, until 20 reports with a cell split more than once were
/// met.
#[test]
fn every_split_names_darts_of_its_cells_after_the_unsew() {
    let mut state = 0x0dd_ba11_u64;
    let (mut multi, mut checked) = (0, 0);
    'outer: for round in 0..4000 {
        let k = 3 + (round % 4) as u32;
        let (mut map, _) = GMap::<3>::from_tets(k as usize + 3, &fan_tets(k, round % 2 == 0)).unwrap();
        for _ in 0..40 {
            let darts: Vec<_> = map.darts().collect();
            let d = darts[(rng_common::next_unit(&mut state) * darts.len() as f64) as usize];
            let i = (rng_common::next_unit(&mut state) * 4.0) as usize;
            if map.is_free(i, d) {
                continue;
            }
            let changes = map.unsew_dyn(i, d).unwrap();
            for dim in 0..=3 {
                let splits: Vec<_> = changes.splits(dim).collect();
                for &(kept, new, dart_kept, dart_new) in &splits {
                    checked += 1;
                    assert_eq!(map.cell_id(dim, dart_kept), kept, "{dim}-cell split {splits:?}, α{i} at {d}");
                    assert_eq!(map.cell_id(dim, dart_new), new, "{dim}-cell split {splits:?}, α{i} at {d}");
                }
                let mut kept: Vec<_> = splits.iter().map(|s| s.0).collect();
                kept.sort_unstable();
                if kept.windows(2).any(|w| w[0] == w[1]) {
                    multi += 1;
                }
            }
            assert!(map.validate().is_ok());
            if multi >= 20 {
                break 'outer;
            }
        }
    }
    assert!(multi >= 20, "cells split more than once in one unsew: {multi} ({checked} splits checked)");
}

/// Finding 275 (documentation): `refine_around` said a tet held back at the last requested level
/// is split at the next one, one level past `levels` at most; a chain of blockers holds it back
/// longer. On this sequence of balls on `kuhn_cube(2)` (found by the round's probe) the last
/// call, to `levels` = 6 on a map at level 5, split tets at levels 6, 7 and 8. What the docs now
/// say is checked: every call in order succeeds or is refused as documented, and after each
/// `Ok` the map is valid and refinable, the masses sum as before, every tet meeting the ball has
/// μt ≥ `levels`, and the report has one entry per level up to `levels` or the map's new
/// maximum, whichever is higher.
#[test]
fn a_chain_of_blockers_can_hold_a_tet_back_several_levels() {
    use topomech::generate::kuhn_cube;
    use topomech::subdivide::{tet_distance, TetMasses};
    let (points, tets) = kuhn_cube(2);
    let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    let mut m = LeveledMap::new(map, points);
    let calls: [([f64; 3], f64, u8, bool); 9] = [
        ([0.28595923990953503, 1.210862592750567, 0.7100492034005381], 0.40789929242047346, 1, true),
        ([0.1398581048385884, -0.02058297284919347, 1.1524758493590503], 0.0, 1, false),
        ([-0.10239895864218729, 1.1101241158697766, 1.2553589464319794], 0.0, 3, false),
        ([1.2795847053076679, 0.6267789535726651, -0.18744607938182867], 0.04572390901437135, 1, true),
        ([0.13608148252724722, 0.782952527769216, 1.2367377627794993], 0.2724393127072467, 2, false),
        ([-0.0969346869940226, 1.2397593391296524, -0.24499219171265682], 0.03685115766002045, 5, true),
        ([0.28028862151270645, 0.5601575152693907, 0.2175882958228728], 0.0, 3, false),
        ([0.6966007376600734, 1.008956262901929, 0.7329352167803003], 0.09594354237839664, 4, true),
        ([0.03354171610406209, 0.6288037157671966, 0.4878832747805984], 0.43608095839057187, 6, false),
    ];
    let mut deepest_overshoot = 0;
    for (c, r, levels, per_op) in calls {
        let mut masses = TetMasses::from_density(&m, 1.0).unwrap();
        let before_max = m.max_level();
        let total = masses.total(&m);
        let result = if per_op {
            m.refine_around_per_op(c, r, levels, &mut masses)
        } else {
            m.refine_around(c, r, levels, &mut masses)
        };
        match result {
            Err(SubdivideError::LevelBelowMax { .. }) => assert!(levels < before_max),
            Err(e) => panic!("unexpected refusal {e}"),
            Ok(report) => {
                assert!(m.check_all().is_ok() && m.check_faces_refinable().is_ok() && masses.check(&m).is_ok());
                assert!((masses.total(&m) - total).abs() <= 1e-12 * total);
                let reached = report.subdivided_per_level.len() - 1;
                assert_eq!(reached, (levels as usize).max(m.max_level() as usize), "{report:?}");
                for d in m.map().one_dart_per_cell(3) {
                    let corners = m.tet_vertices(d).unwrap().map(|v| m.points()[v as usize]);
                    if tet_distance(c, corners) <= r {
                        assert!(m.mu(d).tet >= levels, "a tet at the ball stayed at {}", m.mu(d).tet);
                    }
                }
                deepest_overshoot = deepest_overshoot.max(reached - levels as usize);
            }
        }
    }
    // Two levels past: what SUBDIVISION.md reports for this sequence (update both together).
    assert!(deepest_overshoot >= 2, "tets held back past `levels`: {deepest_overshoot} levels");
}

/// What a 2D 1→4 split of the triangle `p` answers: accepted, refused for a child (its labels),
/// or refused for another reason.
fn split_outcome(p: [[f64; 3]; 3]) -> String {
    let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
    let mut m = LeveledMap::new(map, p.to_vec());
    let d = m.map().darts().next().unwrap();
    match m.subdivide_triangle(d, 1) {
        Ok(_) => "split".into(),
        Err(SubdivideError::FlatTriangleChild { child, .. }) => format!("refused for {child:?}"),
        Err(SubdivideError::BelowPrecision { .. }) => "below precision".into(),
        Err(e) => panic!("unexpected {e}"),
    }
}

/// Finding 277: the check took its projection from the float normal, which overflows (NaN) for
/// edges past about 1e154 and underflows (0) below about 1e-154; it then checked an arbitrary
/// plane (the first axis), accepting splits whose children were inverted in the dominant one,
/// so the answer depended on the scale. Scaling by a power of two is exact (corners, midpoints
/// and every orientation scale with it) as long as everything stays normal: the answer must be
/// the same at every scale. Thin and general triangles on a plane whose dominant projection is
/// not the first axis, at scales 2⁻⁹⁰⁰ to 2¹⁰⁰⁰.
#[test]
fn the_children_check_answers_the_same_at_every_scale() {
    let mut state = 0x7777_1234_u64;
    let mut refused = 0;
    for round in 0..400 {
        let flat = if round % 2 == 0 {
            thin_triangle(&mut state, [0, 1], 1.0)
        } else {
            let mut r = || 1.0 + rng_common::next_unit(&mut state);
            [[r(), r(), 1.0], [r(), r(), 1.0], [r(), r(), 1.0]]
        };
        // Normal ∝ (−2, −3, 1): the dominant projection is onto the zx plane (axis 1).
        let p = flat.map(|q| [q[0], q[1], 1.0 + 2.0 * (q[0] - 1.0) + 3.0 * (q[1] - 1.0)]);
        let at_one = split_outcome(p);
        refused += at_one.starts_with("refused") as usize;
        for s in [-900, -500, -100, 100, 500, 900, 1000] {
            let scaled = p.map(|q| q.map(|x| x * 2f64.powi(s)));
            assert_eq!(split_outcome(scaled), at_one, "{p:?} scaled by 2^{s}");
        }
    }
    assert!(refused > 0, "thin triangles refused at scale 1");
    // The probe's case: a triangle at 1e271 (its plain normal NaN), accepted there and refused
    // at 2⁻⁶⁰⁰ of that scale before; three of its children are inverted in the dominant plane.
    let p = [
        [1.0307711606538196e271, 1.2171719376801812e271, 1.181016250216777e271],
        [1.0415737989055892e271, 1.2332546634633508e271, 1.1627729967832536e271],
        [1.0315900280463959e271, 1.218391049106543e271, 1.1796333653119e271],
    ];
    for s in [0, -600, -1000] {
        assert_eq!(split_outcome(p.map(|q| q.map(|x| x * 2f64.powi(s)))), "refused for [3, 1, 4]", "at 2^{s}");
    }
}
