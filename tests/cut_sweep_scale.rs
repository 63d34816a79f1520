//! Scale invariance of the swept-polyline incision (`PolylineSweep::check`, `crosses`,
//! `sweep_faces`, `incise_sweep`): the degeneracy tests and the crossing test give the same
//! answers whatever the scale of the coordinates, from 1e-150 to 1e300 and up to `f64::MAX`,
//! while a genuinely parallel segment and a genuinely repeated point stay refused.

mod sweep_oracle;

use sweep_oracle::crossing_faces;
use topomech::cut::{incise_sweep, sweep_faces, CutError, PolylineSweep};
use topomech::generate::kuhn_cube;
use topomech::mechanics::{Body, Material, Vec3};

const SCALES: [f64; 12] = [1e-150, 1e-120, 1e-100, 1e-60, 1e-10, 1.0, 1e10, 1e60, 1e100, 1e154, 1e200, 1e300];

fn scaled(v: Vec3, s: f64) -> Vec3 {
    v.map(|c| c * s)
}

/// A slit in the plane x = `x` through the cube (y beyond both sides, z from 2 down to −2), scaled.
fn slit_at(x: f64, s: f64) -> PolylineSweep {
    PolylineSweep {
        points: vec![scaled([x, -2.0, 2.0], s), scaled([x, 2.0, 2.0], s)],
        sweep: scaled([0.0, 0.0, -4.0], s),
    }
}

/// The slit in the plane x = 0.45: no centroid of a Kuhn cube (quarter-integer coordinates) lies
/// on it, so rounding the scaled inputs cannot turn a tie either way.
fn slit(s: f64) -> PolylineSweep {
    slit_at(0.45, s)
}

fn is_bad_sweep(r: Result<(), CutError>, what: &str) -> bool {
    matches!(r, Err(CutError::BadSweep { reason }) if reason.contains(what))
}

#[test]
fn a_scaled_cube_and_slit_give_the_unscaled_crossings_at_every_scale() {
    for k in [1, 2] {
        let (points, tets) = kuhn_cube(k);
        let unit = crossing_faces(&points, &tets, &slit(1.0));
        assert!(unit > 0);
        for s in SCALES {
            let pts: Vec<Vec3> = points.iter().map(|&p| scaled(p, s)).collect();
            let surface = slit(s);
            assert!(surface.check().is_ok(), "scale {s:e}: {:?}", surface.check());
            assert_eq!(crossing_faces(&pts, &tets, &surface), unit, "k = {k}, scale {s:e}");
        }
    }
}

#[test]
fn power_of_two_scalings_keep_even_the_ties() {
    // x = 0.5 passes through centroids: exact ties, kept by exact (power-of-two) scalings.
    for k in [1, 2] {
        let (points, tets) = kuhn_cube(k);
        let unit = crossing_faces(&points, &tets, &slit_at(0.5, 1.0));
        assert!(unit > 0);
        for e in [-1000, -700, -500, -100, -1, 1, 100, 500, 900, 1000] {
            let s = 2f64.powi(e);
            let pts: Vec<Vec3> = points.iter().map(|&p| scaled(p, s)).collect();
            assert_eq!(crossing_faces(&pts, &tets, &slit_at(0.5, s)), unit, "k = {k}, scale 2^{e}");
        }
    }
}

#[test]
fn sweep_faces_counts_the_same_for_every_scale_a_body_can_be_built_at() {
    let (points, tets) = kuhn_cube(2);
    let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    let unit = sweep_faces(&body, &slit(1.0)).unwrap().len();
    assert!(unit > 0);
    // A body's volumes (cubes of coordinates) only exist within about 1e±100.
    for s in [1e-100, 1e-60, 1e-10, 1e10, 1e60, 1e100] {
        let pts: Vec<Vec3> = points.iter().map(|&p| scaled(p, s)).collect();
        let (mut body, _) = Body::from_tets(&pts, &tets, Material::default()).unwrap();
        assert_eq!(sweep_faces(&body, &slit(s)).unwrap().len(), unit, "scale {s:e}");
        assert_eq!(incise_sweep(&mut body, &slit(s)).unwrap().cut_faces(), unit, "scale {s:e}");
        body.map().validate().unwrap();
    }
}

#[test]
fn a_huge_or_long_thin_slit_through_a_unit_cube_cuts_it() {
    let (points, tets) = kuhn_cube(1);
    let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    let cube = |surface: &PolylineSweep| sweep_faces(&body, surface).map(|f| f.len());
    let unit =
        cube(&PolylineSweep { points: vec![[0.5, -10.0, 2.0], [0.5, 10.0, 2.0]], sweep: [0.0, 0.0, -10.0] }).unwrap();
    assert!(unit > 0);
    for s in [10.0, 1e100, 1e150, 1e154, 1e200, 1e300, 1e308, f64::MAX] {
        // The probe's slit: y from −s to s, swept down by s from z = 2.
        let surface = PolylineSweep { points: vec![[0.5, -s, 2.0], [0.5, s, 2.0]], sweep: [0.0, 0.0, -s] };
        assert_eq!(cube(&surface).unwrap(), unit, "scale {s:e}");
        // Long and thin: huge along y, only 4 deep.
        let thin = PolylineSweep { points: vec![[0.5, -s, 2.0], [0.5, s, 2.0]], sweep: [0.0, 0.0, -4.0] };
        assert_eq!(cube(&thin).unwrap(), unit, "long thin slit, scale {s:e}");
        // Huge but stopping above the cube: nothing cut.
        let above = PolylineSweep { points: vec![[0.5, -s, 3.0], [0.5, s, 3.0]], sweep: [0.0, 0.0, 1.0] };
        assert_eq!(cube(&above).unwrap(), 0, "slit above the cube, scale {s:e}");
    }
}

#[test]
fn degenerate_surfaces_stay_refused_at_every_scale() {
    for s in SCALES.into_iter().chain([f64::MIN_POSITIVE, 1e308, f64::MAX]) {
        let along = PolylineSweep {
            points: vec![scaled([0.0, 0.0, 0.0], s), scaled([0.0, 0.0, 1.0], s)],
            sweep: scaled([0.0, 0.0, -1.0], s),
        };
        assert!(is_bad_sweep(along.check(), "parallel"), "scale {s:e}: {:?}", along.check());
        let skew = PolylineSweep {
            points: vec![scaled([0.1, 0.2, 0.3], s), scaled([0.3, 0.6, 0.9], s)],
            sweep: scaled([-0.1, -0.2, -0.3], s),
        };
        assert!(is_bad_sweep(skew.check(), "parallel"), "scale {s:e}: {:?}", skew.check());
        let repeated = PolylineSweep {
            points: vec![scaled([0.5, 0.0, 0.25], s), scaled([0.5, 1.0, 0.25], s), scaled([0.5, 1.0, 0.25], s)],
            sweep: scaled([0.0, 0.0, -1.0], s),
        };
        assert!(is_bad_sweep(repeated.check(), "zero length"), "scale {s:e}: {:?}", repeated.check());
        let zero = PolylineSweep { points: vec![scaled([0.0; 3], s), scaled([0.0, 1.0, 0.0], s)], sweep: [0.0; 3] };
        assert!(is_bad_sweep(zero.check(), "zero"), "scale {s:e}");
    }
    // Non-finite coordinates stay refused.
    let inf = PolylineSweep { points: vec![[0.0; 3], [0.0, f64::INFINITY, 0.0]], sweep: [0.0, 0.0, 1.0] };
    assert!(is_bad_sweep(inf.check(), "not finite"));
    let nan_sweep = PolylineSweep { points: vec![[0.0; 3], [0.0, 1.0, 0.0]], sweep: [0.0, 0.0, f64::NAN] };
    assert!(is_bad_sweep(nan_sweep.check(), "not finite"));
}

#[test]
fn points_that_differ_at_all_make_a_segment_and_any_nonzero_sweep_counts() {
    // 2e-150 apart at scale 1e-150 (the squared length 4e-300 is fine, but the old product with the
    // sweep underflowed), and down to the smallest subnormal steps.
    for (gap, depth) in [(2e-150, 1e-150), (2e-200, 2e-200), (1e-300, 1e-300), (5e-324, 5e-324), (1e-320, 1.0)] {
        let surface = PolylineSweep { points: vec![[0.0; 3], [0.0, gap, 0.0]], sweep: [0.0, 0.0, depth] };
        assert!(surface.check().is_ok(), "gap {gap:e}, sweep {depth:e}: {:?}", surface.check());
    }
    // One ulp apart at a large coordinate.
    let x: f64 = 1e300;
    let next = f64::from_bits(x.to_bits() + 1);
    let surface = PolylineSweep { points: vec![[0.0, x, 0.0], [0.0, next, 0.0]], sweep: [0.0, 0.0, 1.0] };
    assert!(surface.check().is_ok(), "{:?}", surface.check());
    // A segment from −MAX to MAX (its difference overflows) is well formed.
    let wide = PolylineSweep { points: vec![[0.0, -f64::MAX, 0.0], [0.0, f64::MAX, 0.0]], sweep: [f64::MAX, 0.0, 0.0] };
    assert!(wide.check().is_ok(), "{:?}", wide.check());
}

#[test]
fn crossing_is_the_same_for_scaled_segments_and_surfaces() {
    let wall =
        PolylineSweep { points: vec![[1.0, -1.0, 0.0], [1.0, 1.0, 0.0], [3.0, 1.0, 0.0]], sweep: [0.0, 0.0, 2.0] };
    let cases: [(Vec3, Vec3, bool); 6] = [
        ([0.5, 0.0, 1.0], [1.5, 0.0, 1.0], true),
        ([2.0, 0.5, 1.0], [2.0, 1.5, 1.0], true),
        ([0.5, 2.0, 1.0], [0.8, 2.0, 1.0], false),
        ([0.5, 0.0, 2.5], [1.5, 0.0, 2.5], false),
        ([0.5, 0.0, 1.0], [0.9, 0.0, 1.0], false),
        ([4.0, 0.5, 1.0], [4.0, 1.5, 1.0], false),
    ];
    for s in SCALES.into_iter().chain([1e-300, 1e307]) {
        let w =
            PolylineSweep { points: wall.points.iter().map(|&p| scaled(p, s)).collect(), sweep: scaled(wall.sweep, s) };
        assert!(w.check().is_ok(), "scale {s:e}: {:?}", w.check());
        for (a, b, expected) in cases {
            assert_eq!(w.crosses(scaled(a, s), scaled(b, s)), expected, "scale {s:e}: {a:?}–{b:?}");
        }
    }
}
