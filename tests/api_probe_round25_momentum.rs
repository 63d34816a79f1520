//! Round 25, finding F2: a refinement in a running simulation must keep the total momentum
//! Σ_v m_v v_v of the spring coupling (`LeveledMechanics`).
//!
//! Vertex masses are lumped from the volumes on demand; an operation moves mass between
//! vertices (a new hanging vertex draws its share from the corners, a second split in the same
//! volume changes every hanging share), which creates the momentum E = Σ_v Δm_v v_v once the
//! velocities are no longer affine in the rest positions. Every coupled operation removes it by
//! the least mass-weighted velocity change: v_v −= E / M_A on the vertices A whose mass changed.

use proptest::prelude::*;
use topomech::mechanics::{Integrator, Material, StepConfig, Stepper, Vec3};
use topomech::subdivide::{LeveledMap, LeveledMechanics};
use topomech::{DartId, GMap};

mod subdivide_common;
use subdivide_common::{cube as kuhn, jitter, tet_mesh};

const TET: [[f64; 3]; 4] = [[0.0, 0.0, 0.0], [1.0, 0.1, 0.0], [0.2, 1.0, 0.1], [0.1, 0.3, 1.0]];

fn material() -> Material {
    Material { density: 2.0, young: 500.0, damping: 0.01, viscosity: 0.0 }
}

fn edge_dart(m: &LeveledMap<3>, a: u32, b: u32) -> DartId {
    let map = m.map();
    map.darts().find(|&d| map.vertex_id(d).0 == a && map.vertex_id(map.alpha_dyn(0, d)).0 == b).unwrap()
}

/// (Σ m_v v_v, Σ m_v |v_v|) with the coupling's own vertex masses.
fn momentum(m: &LeveledMap<3>, mech: &LeveledMechanics) -> (Vec3, f64) {
    let mass = mech.vertex_masses(m).unwrap();
    let (mut p, mut scale) = ([0.0; 3], 0.0);
    for (v, &mv) in mass.iter().enumerate() {
        let u = mech.velocity[v];
        for k in 0..3 {
            p[k] += mv * u[k];
        }
        scale += mv * (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
    }
    (p, scale)
}

/// Up to `steps` symplectic steps of the coupling's spring system (no gravity, no pins); stops at
/// the first step the stepper refuses (a runaway of the random states).
fn run_steps(m: &LeveledMap<3>, mech: &mut LeveledMechanics, steps: usize, dt: f64) {
    let sys = mech.spring_system(m, [0.0; 3], &[]).unwrap();
    let config = StepConfig::new(Integrator::Symplectic, dt);
    let mut stepper = Stepper::new(config, &sys, &mech.position, &mech.velocity).unwrap();
    for _ in 0..steps {
        let (x, v) = (&mut mech.position, &mut mech.velocity);
        if stepper.step(&sys, x, v).is_err() {
            break;
        }
    }
}

fn assert_momentum_kept(before: (Vec3, f64), after: (Vec3, f64), what: &str) {
    let scale = before.1.max(after.1);
    for k in 0..3 {
        let (p0, p1) = (before.0[k], after.0[k]);
        assert!((p1 - p0).abs() <= 1e-12 * scale, "{what}: axis {k}: Σ m v {p0} -> {p1} (Σ m |v| {scale})");
    }
}

/// Reproducer 1: the midpoint moved (position and velocity) away from its parents' interpolation;
/// a second split in the same tet changes every share and, before the fix, Σ m v.
#[test]
fn f2_refinement_after_motion_keeps_momentum() {
    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let mut m = LeveledMap::new(map, pts);
    let mut mech = LeveledMechanics::new(&m, Material { density: 6.0, ..Material::default() }).unwrap();
    let mid = {
        let e = edge_dart(&m, 0, 1);
        mech.split_edge(&mut m, e, 1)
    }
    .unwrap();
    let h = m.map().vertex_id(mid).index();
    mech.velocity[h] = [1.0, 0.0, 0.0];
    mech.position[h][1] += 0.1;
    let before = momentum(&m, &mech);
    let e = edge_dart(&m, 0, 2);
    mech.split_edge(&mut m, e, 1).unwrap();
    mech.check(&m).unwrap();
    let after = momentum(&m, &mech);
    eprintln!("Σ m v {:?} -> {:?}", before.0, after.0);
    assert!((after.0[0] - before.0[0]).abs() < 1e-12, "Σ m v_x {} -> {}", before.0[0], after.0[0]);
    assert_momentum_kept(before, after, "second split_edge");
}

/// Reproducer 2: the same inside a real loop (200 symplectic steps after a kick on a corner).
#[test]
fn f2_refinement_in_a_running_simulation_keeps_momentum() {
    let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [1, 2, 3, 4]]).unwrap();
    let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]];
    let mut m = LeveledMap::new(map, pts);
    let mat = Material { density: 1000.0, viscosity: 0.0, ..Material::default() };
    let mut mech = LeveledMechanics::new(&m, mat).unwrap();
    let e = edge_dart(&m, 0, 1);
    mech.split_edge(&mut m, e, 1).unwrap();
    mech.velocity[0] = [0.3, -0.2, 0.1];
    run_steps(&m, &mut mech, 200, 1e-5);
    let before = momentum(&m, &mech);
    let e = edge_dart(&m, 0, 2);
    mech.split_edge(&mut m, e, 1).unwrap();
    mech.check(&m).unwrap();
    let after = momentum(&m, &mech);
    let scale = 0.3 * mech.vertex_masses(&m).unwrap().iter().sum::<f64>();
    eprintln!("Σ m v {:?} -> {:?}", before.0, after.0);
    for k in 0..3 {
        assert!((after.0[k] - before.0[k]).abs() <= 1e-12 * scale, "axis {k}: {:?} -> {:?}", before.0, after.0);
    }
}

/// The same running state, each kind of operation in turn (a face split, a 1→8 of the tet with
/// the hanging vertices, a ball over everything by the bulk path).
#[test]
fn f2_every_coupled_operation_keeps_momentum_in_a_running_simulation() {
    let mut m = tet_mesh(vec![TET[0], TET[1], TET[2], TET[3], [1.0, 1.0, 1.0]], &[[0, 1, 2, 3], [1, 2, 3, 4]]);
    let mut mech = LeveledMechanics::new(&m, material()).unwrap();
    mech.velocity[4] = [0.5, 0.25, -1.0];
    let e = edge_dart(&m, 1, 2);
    mech.split_edge(&mut m, e, 1).unwrap();
    type Op = fn(&mut LeveledMechanics, &mut LeveledMap<3>);
    let ops: [(&str, Op); 4] = [
        ("subdivide_triangle", |mech, m| {
            mech.subdivide_triangle(m, edge_dart(m, 1, 3), 1).unwrap();
        }),
        ("subdivide_tet", |mech, m| {
            mech.subdivide_tet(m, edge_dart(m, 0, 3), 1).unwrap();
        }),
        ("refine_around (to level 2)", |mech, m| drop(mech.refine_around(m, [0.9, 0.9, 0.9], 0.2, 2).unwrap())),
        ("refine_around (whole body)", |mech, m| drop(mech.refine_around(m, [0.5; 3], 10.0, 2).unwrap())),
    ];
    for (what, op) in ops {
        run_steps(&m, &mut mech, 50, 1e-4);
        mech.velocity[0][1] += 0.75; // a kick
        let before = momentum(&m, &mech);
        op(&mut mech, &mut m);
        mech.check(&m).unwrap();
        assert_momentum_kept(before, momentum(&m, &mech), what);
    }
}

#[derive(Clone, Copy, Debug)]
enum Op {
    SplitEdge(u16, bool),
    Triangle(u16, bool),
    Tet(u16, bool),
    Around([u8; 3], u8),
}

fn op_strategy() -> impl Strategy<Value = Op> {
    prop_oneof![
        (any::<u16>(), any::<bool>()).prop_map(|(p, up)| Op::SplitEdge(p, up)),
        (any::<u16>(), any::<bool>()).prop_map(|(p, up)| Op::Triangle(p, up)),
        (any::<u16>(), any::<bool>()).prop_map(|(p, up)| Op::Tet(p, up)),
        (any::<[u8; 3]>(), any::<u8>()).prop_map(|(c, r)| Op::Around(c, r)),
    ]
}

fn level_of(m: &LeveledMap<3>, up: bool) -> u8 {
    if up && m.max_level() < 3 {
        m.max_level() + 1
    } else {
        m.max_level().max(1)
    }
}

fn pick(m: &LeveledMap<3>, p: u16) -> DartId {
    m.map().darts().nth(p as usize % m.map().dart_count()).unwrap()
}

/// Applies `op`; whether the map accepts it does not matter here (refusals change nothing, or
/// for `refine_around` keep the levels before the refusal, coupled).
fn apply(mech: &mut LeveledMechanics, m: &mut LeveledMap<3>, op: Op) {
    let _ = match op {
        Op::SplitEdge(p, up) => mech.split_edge(m, pick(m, p), level_of(m, up)).map(drop),
        Op::Triangle(p, up) => mech.subdivide_triangle(m, pick(m, p), level_of(m, up)).map(drop),
        Op::Tet(p, up) => mech.subdivide_tet(m, pick(m, p), level_of(m, up)).map(drop),
        Op::Around(c, r) => {
            let center = c.map(|x| f64::from(x) / 255.0);
            let levels = (m.max_level() + 1).min(3);
            mech.refine_around(m, center, f64::from(r) / 512.0, levels).map(drop)
        }
    };
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// Random operations interleaved with a few symplectic steps and random kicks: Σ m v is the
    /// same before and after every operation, and every law of the coupling holds.
    #[test]
    fn f2_momentum_is_kept_by_every_operation_of_random_sequences(
        cube in any::<bool>(),
        ops in proptest::collection::vec((op_strategy(), any::<u64>(), 0usize..4), 1..10),
    ) {
        let mut m = if cube { kuhn(1) } else { tet_mesh(TET.to_vec(), &[[0, 1, 2, 3]]) };
        let mut mech = LeveledMechanics::new(&m, material()).unwrap();
        for (v, u) in mech.velocity.iter_mut().enumerate() {
            *u = jitter(v as u64);
        }
        for (k, &(op, kick, steps)) in ops.iter().enumerate() {
            if m.map().dart_count() > 3_000 {
                break;
            }
            run_steps(&m, &mut mech, steps, 1e-4);
            let v = kick as usize % mech.velocity.len();
            mech.velocity[v] = jitter(kick);
            let before = momentum(&m, &mech);
            apply(&mut mech, &mut m, op);
            prop_assert!(mech.check(&m).is_ok(), "op {} {:?}: {:?}", k, op, mech.check(&m));
            let after = momentum(&m, &mech);
            let scale = before.1.max(after.1);
            for axis in 0..3 {
                let (p0, p1) = (before.0[axis], after.0[axis]);
                prop_assert!((p1 - p0).abs() <= 1e-12 * scale, "op {} {:?}: axis {}: {} -> {}", k, op, axis, p0, p1);
            }
        }
    }
}

/// The operations of the next two tests, on the Kuhn cube k = 2.
fn some_ops(step: usize) -> Op {
    [
        Op::SplitEdge(17, true),
        Op::Triangle(401, false),
        Op::Tet(999, false),
        Op::SplitEdge(5, false),
        Op::Around([40, 60, 200], 60),
        Op::Tet(77, true),
        Op::Triangle(3, true),
        Op::Around([255, 255, 255], 255),
    ][step % 8]
}

/// A rigid translation (every velocity c) in a deformed state stays exactly c: E is exactly 0
/// and the correction is skipped.
#[test]
fn f2_a_rigid_translation_is_kept_exactly() {
    let mut m = kuhn(2);
    let mut mech = LeveledMechanics::new(&m, material()).unwrap();
    let c = [0.3, -1.7, 2.9];
    for (v, x) in mech.position.iter_mut().enumerate() {
        *x = [0, 1, 2].map(|k| x[k] + 0.05 * jitter(v as u64 + 7)[k]);
    }
    mech.velocity.iter_mut().for_each(|u| *u = c);
    for step in 0..8 {
        let op = some_ops(step);
        apply(&mut mech, &mut m, op);
        mech.check(&m).unwrap();
        assert!(mech.velocity.iter().all(|&u| u == c), "{op:?}: a velocity is no longer {c:?}");
    }
}

/// An affine velocity field v = B·P + c at rest, inserted vertices interpolated (finding 218):
/// the operations leave the velocities as the interpolation makes them (the correction is zero
/// up to rounding).
#[test]
fn f2_an_affine_field_at_rest_is_left_as_interpolated() {
    let mut m = kuhn(2);
    let mut mech = LeveledMechanics::new(&m, material()).unwrap();
    let b = [[0.3, -1.1, 0.7], [2.0, 0.1, -0.4], [-0.6, 0.9, 1.3]];
    let c = [0.25, -0.5, 1.5];
    for (v, p) in m.points().iter().enumerate() {
        mech.velocity[v] = [0, 1, 2].map(|i| b[i][0] * p[0] + b[i][1] * p[1] + b[i][2] * p[2] + c[i]);
    }
    for step in 0..8 {
        let op = some_ops(step);
        let (before, from) = (mech.velocity.clone(), m.split_log().len());
        apply(&mut mech, &mut m, op);
        mech.check(&m).unwrap();
        let mut want = before;
        want.resize(mech.velocity.len(), [0.0; 3]);
        for &[v, a, b] in &m.split_log()[from..] {
            want[v as usize] = [0, 1, 2].map(|k| 0.5 * (want[a as usize][k] + want[b as usize][k]));
        }
        let scale = want.iter().flatten().fold(0.0f64, |x, &y| x.max(y.abs()));
        for (v, (u, w)) in mech.velocity.iter().zip(&want).enumerate() {
            for k in 0..3 {
                assert!((u[k] - w[k]).abs() <= 1e-15 * scale, "{op:?}: vertex {v}: {u:?}, interpolated {w:?}");
            }
        }
    }
}

/// At rest (zero velocities) nothing changes: the velocities stay exactly zero.
#[test]
fn f2_at_rest_the_velocities_stay_zero() {
    let mut m = kuhn(1);
    let mut mech = LeveledMechanics::new(&m, material()).unwrap();
    for step in 0..8 {
        apply(&mut mech, &mut m, some_ops(step));
        assert!(mech.velocity.iter().all(|&u| u == [0.0; 3]));
    }
}
