//! Mutation sample 52: the first-moment verdict of the mixed mode (`MixedRun::first_moment_kept`)
//! is a relative test. Σ_v m_v x_v = ∫ x dV holds in exact arithmetic for any placement of the
//! input, so moving the input by a similarity (a power-of-two scale and a translation) must not
//! change the verdict; its tolerance has to grow with Σ_t V_t max|x| as the rounding of both sums
//! does.

use topomech::ambiguity::mixed::{run_ops, Op};
use topomech::generate;

/// A sequence that subdivides (hanging midpoints, several levels) and cuts (copies of vertices,
/// some of them midpoints) on a Kuhn cube.
fn ops() -> Vec<Op> {
    vec![Op::Subdivide(0), Op::Cut(5), Op::Subdivide(17), Op::Cut(40), Op::Cut(11), Op::Subdivide(30), Op::Cut(2)]
}

/// x ↦ s·x + t on every point (s a power of two: the scaling itself is exact).
fn placed(points: &[[f64; 3]], s: f64, t: [f64; 3]) -> Vec<[f64; 3]> {
    points.iter().map(|p| [s * p[0] + t[0], s * p[1] + t[1], s * p[2] + t[2]]).collect()
}

/// The first moment is kept wherever the input lies: near the origin at unit size, scaled up,
/// and scaled up far from the origin (where each sum's rounding is far above 1e-9 of
/// Σ_t (V_t + max|x|), but far below 1e-9 of Σ_t V_t max|x|).
#[test]
fn the_first_moment_verdict_does_not_depend_on_where_the_input_lies() {
    let (points, tets) = generate::kuhn_cube(2);
    let placements: [(f64, [f64; 3]); 4] = [
        (1.0, [0.0; 3]),
        (4096.0, [0.0; 3]),
        (4096.0, [2f64.powi(40), -(2f64.powi(40)), 3.0 * 2f64.powi(39)]),
        (1.0, [1e9, 2e9, -3e9]),
    ];
    for (s, t) in placements {
        let p = placed(&points, s, t);
        let run = run_ops(&p, &tets, &ops()).expect("a Kuhn cube runs");
        assert!(run.subdivisions > 0 && run.cuts > 0, "the sequence did nothing at s = {s}, t = {t:?}: {run:?}");
        assert!(run.gmap_valid && run.level_law, "s = {s}, t = {t:?}");
        assert!(run.first_moment_kept, "the first moment moved at s = {s}, t = {t:?}");
    }
}
