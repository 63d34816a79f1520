//! The spring/mass coupling of the leveled map (`subdivide::LeveledMechanics`, issue 5): the laws
//! of the subdivided spring network after every operation of random sequences, the series rule as
//! physics (static response of split edges), mass conservation, and tampering detected.

use proptest::prelude::*;
use topomech::generate::kuhn_cube;
use topomech::mechanics::{Integrator, Material, SpringSystem, StepConfig, Stepper, Vec3};
use topomech::subdivide::fuzz::{decode, Op, MAX_DARTS, MAX_FUZZ_LEVEL};
use topomech::subdivide::{CouplingError, LeveledMap, LeveledMechanics, SpringLawError};
use topomech::{DartId, GMap};

const TET: [[f64; 3]; 4] = [[0.0, 0.0, 0.0], [1.0, 0.1, 0.0], [0.2, 1.0, 0.1], [0.1, 0.3, 1.0]];

fn leveled(points: Vec<[f64; 3]>, tets: &[[u32; 4]]) -> LeveledMap<3> {
    let (map, _) = GMap::<3>::from_tets(points.len(), tets).unwrap();
    LeveledMap::new(map, points)
}

fn material() -> Material {
    Material { density: 2.0, young: 500.0, damping: 0.01, viscosity: 0.5 }
}

/// A deterministic pseudo-random vector in [−1, 1]³.
fn jitter(seed: u64) -> Vec3 {
    let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15).wrapping_add(1);
    [0, 1, 2].map(|_| {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s % 2001) as f64 / 1000.0 - 1.0
    })
}

fn level_of(m: &LeveledMap<3>, up: bool) -> u8 {
    let top = m.max_level();
    if up && top < MAX_FUZZ_LEVEL {
        top + 1
    } else {
        top
    }
}

fn pick(m: &LeveledMap<3>, pick: u16) -> DartId {
    m.map().darts().nth(pick as usize % m.map().dart_count()).unwrap()
}

fn apply(mech: &mut LeveledMechanics, m: &mut LeveledMap<3>, op: Op) -> Result<(), CouplingError> {
    match op {
        Op::SplitEdge { pick: p, up } => mech.split_edge(m, pick(m, p), level_of(m, up)).map(drop),
        Op::Triangle { pick: p, up } => mech.subdivide_triangle(m, pick(m, p), level_of(m, up)).map(drop),
        Op::Tet { pick: p, up } => mech.subdivide_tet(m, pick(m, p), level_of(m, up)).map(drop),
        Op::Around { center, radius } => {
            let c = [f64::from(center[0]) / 255.0, f64::from(center[1]) / 255.0, 0.5];
            let levels = level_of(m, true);
            mech.refine_around(m, c, f64::from(radius) / 255.0, levels).map(drop)
        }
    }
}

/// Every vertex inserted since `from` (split log index) has the mean position and velocity of its
/// edge's ends (nothing moved in between).
fn check_interpolation(mech: &LeveledMechanics, m: &LeveledMap<3>, from: usize) -> Result<(), String> {
    for &[v, a, b] in &m.split_log()[from..] {
        let (v, a, b) = (v as usize, a as usize, b as usize);
        for (name, x) in [("position", &mech.position), ("velocity", &mech.velocity)] {
            let mean = [0, 1, 2].map(|k| 0.5 * (x[a][k] + x[b][k]));
            if (0..3).any(|k| (x[v][k] - mean[k]).abs() > 1e-12) {
                return Err(format!("vertex {v}: {name} {:?}, mean of its ends {mean:?}", x[v]));
            }
        }
    }
    Ok(())
}

/// Runs the decoded ops with the coupling, checking every law after every op (accepted or not).
fn run(bytes: &[u8]) -> Result<usize, String> {
    let (mesh, ops) = decode(bytes);
    let mut m = match mesh {
        topomech::subdivide::fuzz::Mesh::Tet => leveled(TET.to_vec(), &[[0, 1, 2, 3]]),
        _ => {
            let (p, t) = kuhn_cube(1);
            leveled(p, &t)
        }
    };
    let mut mech = LeveledMechanics::new(&m, material()).map_err(|e| e.to_string())?;
    for (v, x) in mech.velocity.iter_mut().enumerate() {
        *x = jitter(v as u64);
    }
    for (v, x) in mech.position.iter_mut().enumerate() {
        *x = [0, 1, 2].map(|k| x[k] + 0.1 * jitter(100 + v as u64)[k]);
    }
    let mut splits = 0;
    for (k, &op) in ops.iter().enumerate() {
        if m.map().dart_count() >= MAX_DARTS {
            break;
        }
        let (before, log) = (mech.clone(), m.split_log().len());
        match apply(&mut mech, &mut m, op) {
            Ok(()) => {}
            Err(CouplingError::Subdivide(_)) if !matches!(op, Op::Around { .. }) => {
                if mech != before {
                    return Err(format!("op {k} {op:?} refused but the coupling changed"));
                }
            }
            Err(CouplingError::Subdivide(_)) => {} // refine_around keeps the ops before the refusal
            Err(e) => return Err(format!("op {k} {op:?}: {e}")),
        }
        mech.check(&m).map_err(|e| format!("op {k} {op:?}: {e}"))?;
        check_interpolation(&mech, &m, log).map_err(|e| format!("op {k} {op:?}: {e}"))?;
        splits = m.split_log().len();
    }
    Ok(splits)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn spring_laws_hold_after_every_op_of_random_sequences(bytes in proptest::collection::vec(any::<u8>(), 1..31)) {
        let bytes: Vec<u8> = std::iter::once(1 + bytes[0] % 2).chain(bytes[1..].iter().copied()).collect();
        if let Err(e) = run(&bytes) {
            prop_assert!(false, "{}", e);
        }
    }
}

#[test]
fn fixed_sequences_split_edges_and_keep_the_laws() {
    // Tet mesh; a tet 1→8, an edge split one level up, a face split one up, a ball.
    let splits = run(&[2, 0x82, 0, 0, 0x80, 0, 7, 0x81, 1, 3, 3, 128, 128]).unwrap();
    assert!(splits >= 6);
    let splits = run(&[1, 0x83, 100, 100, 0x80, 3, 3, 0x82, 0, 40]).unwrap();
    assert!(splits > 0);
}

/// Splits every edge of the finest map `levels` times (edge splits only: the network is the coarse
/// one with every spring replaced by a chain of 2^levels springs).
fn split_all_edges(mech: &mut LeveledMechanics, m: &mut LeveledMap<3>, levels: u8) {
    for level in 1..=levels {
        loop {
            let d = m.map().darts().find(|&d| m.mu(d).edge < level);
            match d {
                Some(d) => drop(mech.split_edge(m, d, level).unwrap()),
                None => break,
            }
        }
        mech.check(m).unwrap();
    }
}

/// Net spring force on each slot (gravity zero, velocities zero).
fn spring_forces(sys: &SpringSystem, x: &[Vec3]) -> Vec<Vec3> {
    let (mut sf, mut out) = (vec![[0.0; 3]; sys.springs()], vec![[0.0; 3]; sys.slots()]);
    sys.forces(x, &vec![[0.0; 3]; sys.slots()], &mut sf, &mut out, false);
    out
}

/// A deformation of the tet's corners (stretch, shear, a non-affine push on one corner) that
/// lengthens every edge: a compressed chain of free midpoints buckles (it has no transverse
/// stiffness), so the series law is stated for chains in tension.
fn deformed(p: Vec3, v: usize) -> Vec3 {
    let mut q = [1.3 * p[0] + 0.1 * p[1], 1.2 * p[1], 1.25 * p[2] + 0.1 * p[0]];
    if v == 3 {
        q[0] += 0.15;
    }
    q
}

#[test]
fn the_test_deformation_stretches_every_edge() {
    let len = |p: Vec3, q: Vec3| (0..3).map(|k| (p[k] - q[k]).powi(2)).sum::<f64>().sqrt();
    for (a, &pa) in TET.iter().enumerate() {
        for (b, &pb) in TET.iter().enumerate().skip(a + 1) {
            assert!(len(deformed(pa, a), deformed(pb, b)) > 1.05 * len(pa, pb), "edge ({a}, {b})");
        }
    }
}

#[test]
fn split_edges_interpolated_after_deformation_are_in_equilibrium_with_the_coarse_reactions() {
    let mut m = leveled(TET.to_vec(), &[[0, 1, 2, 3]]);
    let mut mech = LeveledMechanics::new(&m, material()).unwrap();
    for (v, &p) in TET.iter().enumerate() {
        mech.position[v] = deformed(p, v);
    }
    let coarse = mech.spring_system(&m, [0.0; 3], &[true; 4]);
    let f_coarse = spring_forces(&coarse, &mech.position);
    split_all_edges(&mut mech, &mut m, 3);
    let fine = mech.spring_system(&m, [0.0; 3], &[true; 4]);
    assert_eq!(fine.springs(), 6 * 8);
    let f_fine = spring_forces(&fine, &mech.position);
    let scale = f_coarse.iter().flatten().fold(0.0f64, |a, &b| a.max(b.abs()));
    assert!(scale > 1.0, "the deformation loads the springs");
    for v in 0..fine.slots() {
        let expected = if v < 4 { f_coarse[v] } else { [0.0; 3] }; // midpoints: no net force
        for k in 0..3 {
            assert!((f_fine[v][k] - expected[k]).abs() < 1e-9 * scale, "vertex {v}: {:?} vs {expected:?}", f_fine[v]);
        }
    }
}

#[test]
fn a_relaxed_refined_chain_network_has_the_coarse_static_response() {
    // Series law as physics: with the corners held in a deformed position, the midpoints (moved off
    // their equilibrium) relax under damped implicit dynamics and the reactions at the corners are
    // the coarse network's: each chain stretches the same total amount as its coarse spring.
    let mut m = leveled(TET.to_vec(), &[[0, 1, 2, 3]]);
    let heavy = Material { viscosity: 200.0, ..material() };
    let mut mech = LeveledMechanics::new(&m, heavy).unwrap();
    split_all_edges(&mut mech, &mut m, 2);
    for (v, &p) in TET.iter().enumerate() {
        mech.position[v] = deformed(p, v);
    }
    for v in 4..mech.position.len() {
        let j = jitter(7 * v as u64);
        mech.position[v] = [0, 1, 2].map(|k| mech.position[v][k] + 0.05 * j[k]);
    }
    let coarse = LeveledMechanics::new(&leveled(TET.to_vec(), &[[0, 1, 2, 3]]), heavy).unwrap();
    let mut x_coarse = coarse.position.clone();
    (0..4).for_each(|v| x_coarse[v] = mech.position[v]);
    let f_coarse =
        spring_forces(&coarse.spring_system(&leveled(TET.to_vec(), &[[0, 1, 2, 3]]), [0.0; 3], &[]), &x_coarse);
    let sys = mech.spring_system(&m, [0.0; 3], &[true; 4]);
    let mut stepper =
        Stepper::new(StepConfig::new(Integrator::Implicit, 1e-2), &sys, &mech.position, &mech.velocity).unwrap();
    for _ in 0..3000 {
        stepper.step(&sys, &mut mech.position, &mut mech.velocity).unwrap();
    }
    let f_fine = spring_forces(&sys, &mech.position);
    let scale = f_coarse.iter().flatten().fold(0.0f64, |a, &b| a.max(b.abs()));
    for v in 0..sys.slots() {
        let expected = if v < 4 { f_coarse[v] } else { [0.0; 3] };
        for k in 0..3 {
            assert!((f_fine[v][k] - expected[k]).abs() < 1e-6 * scale, "vertex {v}: {:?} vs {expected:?}", f_fine[v]);
        }
    }
}

/// Affine motion x = A·X of every vertex.
fn affine(x: &[Vec3]) -> Vec<Vec3> {
    x.iter().map(|p| [1.1 * p[0] + 0.05 * p[2], 0.95 * p[1] + 0.1 * p[0], 1.02 * p[2]]).collect()
}

#[test]
fn refinement_never_softens_and_chains_alone_keep_the_coarse_energy() {
    let (points, tets) = kuhn_cube(1);
    let mut m = leveled(points.clone(), &tets);
    let mech0 = LeveledMechanics::new(&m, material()).unwrap();
    let e_coarse = mech0.spring_system(&m, [0.0; 3], &[]).elastic_energy(&affine(m.points()));
    // Edge splits only: the network is the coarse one in series, same energy under affine motion.
    let mut mech = mech0.clone();
    split_all_edges(&mut mech, &mut m, 2);
    let e_chains = mech.spring_system(&m, [0.0; 3], &[]).elastic_energy(&affine(m.points()));
    assert!((e_chains - e_coarse).abs() < 1e-12 * e_coarse, "{e_chains} vs {e_coarse}");
    // 1→8 adds inner springs: at least as stiff.
    let mut m2 = leveled(points, &tets);
    let mut mech2 = LeveledMechanics::new(&m2, material()).unwrap();
    mech2.refine_around(&mut m2, [0.5; 3], 10.0, 2).unwrap();
    mech2.check(&m2).unwrap();
    let e_fine = mech2.spring_system(&m2, [0.0; 3], &[]).elastic_energy(&affine(m2.points()));
    assert!(e_fine > e_coarse * (1.0 + 1e-6), "{e_fine} vs {e_coarse}");
}

#[test]
fn masses_are_conserved_exactly_and_every_vertex_has_mass() {
    let (points, tets) = kuhn_cube(2);
    let mut m = leveled(points, &tets);
    let mut mech = LeveledMechanics::new(&m, material()).unwrap();
    let r = mech.refine_around(&mut m, [0.7, 0.6, 0.5], 0.3, 2).unwrap();
    assert!(r.subdivided_per_level[1] > 0 && r.subdivided_per_level[2] > 0);
    mech.check(&m).unwrap();
    let total = 2.0 * 8.0; // ρ · volume of [0, 2]³
    let vm = mech.vertex_masses(&m);
    assert!((vm.iter().sum::<f64>() - total).abs() < 1e-12 * total);
    assert!(vm.iter().all(|&x| x > 0.0), "a vertex without mass would be pinned by the projection");
    let sys = mech.spring_system(&m, [0.0; 3], &[]);
    assert!((sys.mass.iter().sum::<f64>() - total).abs() < 1e-12 * total);
    assert_eq!(sys.springs(), m.map().count_cells().0[1]);
}

#[test]
fn a_refined_zone_simulates_from_the_projection_without_a_tet_list() {
    let (points, tets) = kuhn_cube(2);
    let mut m = leveled(points, &tets);
    let mut mech = LeveledMechanics::new(&m, Material::default()).unwrap();
    mech.refine_around(&mut m, [1.0, 1.0, 2.0], 0.4, 2).unwrap();
    let fixed: Vec<bool> = m.points().iter().map(|p| p[2] == 0.0).collect();
    let sys = mech.spring_system(&m, [0.0, 0.0, -9.81], &fixed);
    let mut stepper =
        Stepper::new(StepConfig::new(Integrator::Implicit, 1e-3), &sys, &mech.position, &mech.velocity).unwrap();
    for _ in 0..200 {
        stepper.step(&sys, &mut mech.position, &mut mech.velocity).unwrap();
    }
    let top = mech.position.iter().zip(m.points()).filter(|(_, p)| p[2] == 2.0);
    assert!(top.clone().count() > 9, "the refined top face has new vertices");
    assert!(top.clone().all(|(x, p)| x[2] < p[2]), "the top sags under gravity");
    assert!(mech.position.iter().zip(&fixed).filter(|(_, &f)| f).all(|(x, _)| x[2] == 0.0));
}

type Tamper = Box<dyn Fn(&mut LeveledMechanics)>;
type Expect = Box<dyn Fn(&SpringLawError) -> bool>;

#[test]
fn tampering_is_flagged_naming_the_edge_or_vertex() {
    let (points, tets) = kuhn_cube(1);
    let mut m = leveled(points, &tets);
    let mut mech = LeveledMechanics::new(&m, material()).unwrap();
    let d = m.map().darts().next().unwrap();
    mech.subdivide_tet(&mut m, d, 1).unwrap();
    mech.check(&m).unwrap();
    let (half, _) = mech.springs().find(|&((a, b), _)| a < 8 && b >= 8).unwrap();
    let (coarse, _) = mech.springs().find(|&((a, b), _)| b < 8 && mech.root(a, b).is_none()).unwrap();
    let (inner, _) = mech.springs().find(|&((a, _), _)| a >= 8).unwrap();
    let cases: Vec<(Tamper, Expect)> = vec![
        (
            Box::new(move |x| x.spring_mut(coarse.0, coarse.1).unwrap().stiffness *= 1.0 + 1e-9),
            Box::new(move |e| matches!(e, &SpringLawError::Stiffness { a, b, .. } if (a, b) == coarse)),
        ),
        (
            Box::new(move |x| x.spring_mut(inner.0, inner.1).unwrap().stiffness *= 0.5),
            Box::new(move |e| matches!(e, &SpringLawError::Stiffness { a, b, .. } if (a, b) == inner)),
        ),
        (
            Box::new(move |x| x.spring_mut(half.0, half.1).unwrap().stiffness *= 1.0 + 1e-9),
            Box::new(|e| matches!(e, SpringLawError::Series { .. })),
        ),
        (
            Box::new(move |x| x.spring_mut(half.0, half.1).unwrap().damping = 0.0),
            Box::new(|e| matches!(e, SpringLawError::Series { .. })),
        ),
        (
            Box::new(move |x| x.spring_mut(inner.0, inner.1).unwrap().damping *= 2.0),
            Box::new(move |e| matches!(e, &SpringLawError::Damping { a, b, .. } if (a, b) == inner)),
        ),
        (
            Box::new(move |x| x.spring_mut(inner.0, inner.1).unwrap().rest *= 1.001),
            Box::new(move |e| matches!(e, &SpringLawError::RestLength { a, b, .. } if (a, b) == inner)),
        ),
        (Box::new(|x| x.masses.mass[0] *= 1.01), Box::new(|e| matches!(e, SpringLawError::TotalMass { .. }))),
    ];
    for (k, (tamper, expect)) in cases.iter().enumerate() {
        let mut bad = mech.clone();
        tamper(&mut bad);
        let e = bad.check(&m).unwrap_err();
        assert!(expect(&e), "case {k}: {e}");
    }
    // A map without geometry cannot carry springs.
    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let e = LeveledMechanics::new(&LeveledMap::new(map, vec![]), material()).unwrap_err();
    assert_eq!(e, CouplingError::NoGeometry(0));
    // An operation done on the map alone is seen.
    let d = m.map().darts().find(|&d| m.mu(d).edge == 0).unwrap();
    m.split_edge(d, 1).unwrap();
    assert!(matches!(mech.check(&m), Err(SpringLawError::OutOfSync { applied: _, logged: _ })));
}

#[test]
fn the_refine_command_reports_the_spring_coupling_with_springs() {
    let liver = format!("{}/data/liver_547_v22.msh", env!("CARGO_MANIFEST_DIR"));
    let args = ["refine", &liver, "--around", "-2.2,3.2,0.6", "--radius", "0.5", "--levels", "1", "--json"];
    let run = |extra: &[&str]| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_topomech")).args(args).args(extra).output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        serde_json::from_slice::<serde_json::Value>(&out.stdout).unwrap()
    };
    let (plain, coupled) = (run(&[]), run(&["--springs"]));
    assert!(plain.get("springs_after").is_none(), "the keys exist only with --springs: {plain}");
    for key in ["volumes", "darts", "tets_per_level", "subdivided_per_level"] {
        assert_eq!(plain[key], coupled[key], "the coupling does not change the refinement ({key})");
    }
    let (before, after) = (coupled["springs_before"].as_u64().unwrap(), coupled["springs_after"].as_u64().unwrap());
    assert!(after > before, "{coupled}");
    assert_eq!(coupled["stiffness_series_ok"], true);
    assert_eq!(coupled["spring_laws_ok"], true);
    let (a, b) = (coupled["total_mass_before"].as_f64().unwrap(), coupled["total_mass_after"].as_f64().unwrap());
    assert!((a - b).abs() <= 1e-12 * a);
    // One spring per distinct edge of the input tets.
    let tets = topomech::load::load_builtin().unwrap().mesh.tets;
    let edges: std::collections::BTreeSet<(u32, u32)> = tets
        .iter()
        .flat_map(|t| [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)].map(|(i, j)| (t[i].min(t[j]), t[i].max(t[j]))))
        .collect();
    assert_eq!(before as usize, edges.len());
}

/// A cut that opens the ring of faces around an inner edge at two places splits the edge into
/// two edges between the same two vertices (its ends stay joined through their other tets):
/// springs keyed by vertex pairs would be ambiguous, so the coupling refuses the map up front,
/// naming the two vertices, instead of failing half-way through a later operation.
#[test]
fn a_cut_edge_whose_ends_did_not_split_is_refused_up_front() {
    use topomech::mechanics::Body;
    let (points, tets) = kuhn_cube(3);
    let (mut body, _) = Body::from_tets(&points, &tets, material()).unwrap();
    let inner = |v: topomech::CellId| body.attrs().rest_position[v].iter().all(|&c| c > 0.5 && c < 2.5);
    let map = body.map();
    let edge = map
        .one_dart_per_cell(1)
        .into_iter()
        .find(|&d| inner(map.vertex_id(d)) && inner(map.vertex_id(map.alpha::<0>(d))))
        .expect("an edge between two inner vertices");
    let (a, b) = (map.vertex_id(edge).0, map.vertex_id(map.alpha::<0>(edge)).0);
    // The faces around the edge, in ring order: α2 then α3 from the edge's dart.
    let mut ring = vec![edge];
    let mut x = map.alpha::<3>(map.alpha::<2>(edge));
    while x != edge && ring.len() < 64 {
        ring.push(x);
        x = map.alpha::<3>(map.alpha::<2>(x));
    }
    assert!(ring.len() >= 4, "an inner edge has a closed ring of at least 4 tets: {}", ring.len());
    for f in [ring[0], ring[ring.len() / 2]] {
        let face = body.map().alpha::<2>(f);
        topomech::cut::dissociate_face(&mut body, face).unwrap();
    }
    let map = body.map();
    assert_eq!((map.vertex_id(edge).0, map.vertex_id(map.alpha::<0>(edge)).0), (a, b), "the ends did not split");
    let rest = body.attrs().rest_position.as_slice().to_vec();
    let m = LeveledMap::new(map.clone(), rest);
    let err = LeveledMechanics::new(&m, material()).unwrap_err();
    assert_eq!(err, CouplingError::AmbiguousEdge(a.min(b), a.max(b)), "{err}");
    // The uncut cube is accepted.
    let fresh = LeveledMap::new(GMap::<3>::from_tets(points.len(), &tets).unwrap().0, points.clone());
    assert!(LeveledMechanics::new(&fresh, material()).is_ok());
}
