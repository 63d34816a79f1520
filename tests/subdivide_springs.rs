//! The spring/mass coupling of the leveled map (`subdivide::LeveledMechanics`, issue 5): the laws
//! of the subdivided spring network after every operation of random sequences, the series rule as
//! physics (static response of split edges), mass conservation, and tampering detected.

use proptest::prelude::*;
use topomech::generate::kuhn_cube;
use topomech::mechanics::{Integrator, Material, SpringSystem, StepConfig, Stepper, Vec3};
use topomech::subdivide::fuzz::{Op, MAX_DARTS};
use topomech::subdivide::{CouplingError, EdgeKey, LeveledMap, LeveledMechanics, SpringLawError, SubdivideError};
use topomech::{DartId, GMap};

mod subdivide_common;
use subdivide_common::{apply_coupled, jitter, material, moving_coupling, tet_mesh, TET};

fn apply(mech: &mut LeveledMechanics, m: &mut LeveledMap<3>, op: Op) -> Result<(), CouplingError> {
    apply_coupled(mech, m, op).expect("decoded without cut mode: no reload")
}

/// The decoder's mesh and ops of `bytes` outside cut mode (bit 7 of byte 0 cleared): the cut
/// mode with the coupling is `tests/subdivide_springs_cut.rs`.
fn decode(bytes: &[u8]) -> (topomech::subdivide::fuzz::Mesh, Vec<Op>) {
    let mut bytes = bytes.to_vec();
    if let Some(b) = bytes.first_mut() {
        *b &= 0x7f;
    }
    topomech::subdivide::fuzz::decode(&bytes)
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
        topomech::subdivide::fuzz::Mesh::Tet => tet_mesh(TET.to_vec(), &[[0, 1, 2, 3]]),
        _ => {
            let (p, t) = kuhn_cube(1);
            tet_mesh(p, &t)
        }
    };
    let mut mech = moving_coupling(&m)?;
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
    sys.forces(x, &vec![[0.0; 3]; sys.slots()], &mut sf, &mut out, false).unwrap();
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
    let mut m = tet_mesh(TET.to_vec(), &[[0, 1, 2, 3]]);
    let mut mech = LeveledMechanics::new(&m, material()).unwrap();
    for (v, &p) in TET.iter().enumerate() {
        mech.position[v] = deformed(p, v);
    }
    let coarse = mech.spring_system(&m, [0.0; 3], &[true; 4]).unwrap();
    let f_coarse = spring_forces(&coarse, &mech.position);
    split_all_edges(&mut mech, &mut m, 3);
    let fine = mech.spring_system(&m, [0.0; 3], &[true; 4]).unwrap();
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
    let mut m = tet_mesh(TET.to_vec(), &[[0, 1, 2, 3]]);
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
    let coarse_map = tet_mesh(TET.to_vec(), &[[0, 1, 2, 3]]);
    let coarse = LeveledMechanics::new(&coarse_map, heavy).unwrap();
    let mut x_coarse = coarse.position.clone();
    (0..4).for_each(|v| x_coarse[v] = mech.position[v]);
    let f_coarse = spring_forces(&coarse.spring_system(&coarse_map, [0.0; 3], &[]).unwrap(), &x_coarse);
    let sys = mech.spring_system(&m, [0.0; 3], &[true; 4]).unwrap();
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
    let mut m = tet_mesh(points.clone(), &tets);
    let mech0 = LeveledMechanics::new(&m, material()).unwrap();
    let e_coarse = mech0.spring_system(&m, [0.0; 3], &[]).unwrap().elastic_energy(&affine(m.points())).unwrap();
    // Edge splits only: the network is the coarse one in series, same energy under affine motion.
    let mut mech = mech0.clone();
    split_all_edges(&mut mech, &mut m, 2);
    let e_chains = mech.spring_system(&m, [0.0; 3], &[]).unwrap().elastic_energy(&affine(m.points())).unwrap();
    assert!((e_chains - e_coarse).abs() < 1e-12 * e_coarse, "{e_chains} vs {e_coarse}");
    // 1→8 adds inner springs: at least as stiff.
    let mut m2 = tet_mesh(points, &tets);
    let mut mech2 = LeveledMechanics::new(&m2, material()).unwrap();
    mech2.refine_around(&mut m2, [0.5; 3], 10.0, 2).unwrap();
    mech2.check(&m2).unwrap();
    let e_fine = mech2.spring_system(&m2, [0.0; 3], &[]).unwrap().elastic_energy(&affine(m2.points())).unwrap();
    assert!(e_fine > e_coarse * (1.0 + 1e-6), "{e_fine} vs {e_coarse}");
}

#[test]
fn masses_are_conserved_exactly_and_every_vertex_has_mass() {
    let (points, tets) = kuhn_cube(2);
    let mut m = tet_mesh(points, &tets);
    let mut mech = LeveledMechanics::new(&m, material()).unwrap();
    let r = mech.refine_around(&mut m, [0.7, 0.6, 0.5], 0.3, 2).unwrap();
    assert!(r.subdivided_per_level[1] > 0 && r.subdivided_per_level[2] > 0);
    mech.check(&m).unwrap();
    let total = 2.0 * 8.0; // ρ · volume of [0, 2]³
    let vm = mech.vertex_masses(&m).unwrap();
    assert!((vm.iter().sum::<f64>() - total).abs() < 1e-12 * total);
    assert!(vm.iter().all(|&x| x > 0.0), "a vertex without mass would be pinned by the projection");
    let sys = mech.spring_system(&m, [0.0; 3], &[]).unwrap();
    assert!((sys.mass().iter().sum::<f64>() - total).abs() < 1e-12 * total);
    assert_eq!(sys.springs(), m.map().count_cells().0[1]);
}

#[test]
fn a_refined_zone_simulates_from_the_projection_without_a_tet_list() {
    let (points, tets) = kuhn_cube(2);
    let mut m = tet_mesh(points, &tets);
    let mut mech = LeveledMechanics::new(&m, Material::default()).unwrap();
    mech.refine_around(&mut m, [1.0, 1.0, 2.0], 0.4, 2).unwrap();
    let fixed: Vec<bool> = m.points().iter().map(|p| p[2] == 0.0).collect();
    let sys = mech.spring_system(&m, [0.0, 0.0, -9.81], &fixed).unwrap();
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
    let mut m = tet_mesh(points, &tets);
    let mut mech = LeveledMechanics::new(&m, material()).unwrap();
    let d = m.map().darts().next().unwrap();
    mech.subdivide_tet(&mut m, d, 1).unwrap();
    mech.check(&m).unwrap();
    let (half, _) = mech.springs().find(|(e, _)| e.a < 8 && e.b >= 8).unwrap();
    let (coarse, _) = mech.springs().find(|(e, _)| e.b < 8 && mech.root(*e).is_none()).unwrap();
    let (inner, _) = mech.springs().find(|(e, _)| e.a >= 8).unwrap();
    let named = |e: &SpringLawError| match *e {
        SpringLawError::Stiffness { a, b, edge, .. }
        | SpringLawError::Damping { a, b, edge, .. }
        | SpringLawError::RestLength { a, b, edge, .. } => Some(EdgeKey::new(edge, a, b)),
        _ => None,
    };
    let cases: Vec<(Tamper, Expect)> = vec![
        (
            Box::new(move |x| x.spring_mut(coarse).unwrap().stiffness *= 1.0 + 1e-9),
            Box::new(move |e| matches!(e, SpringLawError::Stiffness { .. }) && named(e) == Some(coarse)),
        ),
        (
            Box::new(move |x| x.spring_mut(inner).unwrap().stiffness *= 0.5),
            Box::new(move |e| matches!(e, SpringLawError::Stiffness { .. }) && named(e) == Some(inner)),
        ),
        (
            Box::new(move |x| x.spring_mut(half).unwrap().stiffness *= 1.0 + 1e-9),
            Box::new(|e| matches!(e, SpringLawError::Series { .. })),
        ),
        (
            Box::new(move |x| x.spring_mut(half).unwrap().damping = 0.0),
            Box::new(|e| matches!(e, SpringLawError::Series { .. })),
        ),
        (
            Box::new(move |x| x.spring_mut(inner).unwrap().damping *= 2.0),
            Box::new(move |e| matches!(e, SpringLawError::Damping { .. }) && named(e) == Some(inner)),
        ),
        (
            Box::new(move |x| x.spring_mut(inner).unwrap().rest *= 1.001),
            Box::new(move |e| matches!(e, SpringLawError::RestLength { .. }) && named(e) == Some(inner)),
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

/// The inner edges of a Kuhn cube of side 3 (both ends strictly inside), one dart each.
fn inner_edges(body: &topomech::mechanics::Body) -> Vec<DartId> {
    let map = body.map();
    let inner = |v: topomech::CellId| body.attrs().rest_position()[v].iter().all(|&c| c > 0.5 && c < 2.5);
    map.one_dart_per_cell(1)
        .into_iter()
        .filter(|&d| inner(map.vertex_id(d)) && inner(map.vertex_id(map.alpha::<0>(d))))
        .collect()
}

/// Dissociates the faces at positions i and j (mod its length, made distinct) of the ring of faces
/// around the edge of `edge` (walked by α2 then α3). Opening a closed ring at two places splits the
/// edge into two edge cells, and its ends stay joined through their other tets. Faces already cut
/// are skipped. Returns the ring length.
fn cut_ring(body: &mut topomech::mechanics::Body, edge: DartId, i: usize, j: usize) -> usize {
    let map = body.map();
    let mut ring = vec![edge];
    let mut x = map.alpha::<3>(map.alpha::<2>(edge));
    while x != edge && ring.len() < 64 {
        ring.push(x);
        x = map.alpha::<3>(map.alpha::<2>(x));
    }
    let n = ring.len();
    let (i, j) = (i % n, if j % n == i % n { (i + 1) % n } else { j % n });
    for f in [ring[i], ring[j]] {
        let face = body.map().alpha::<2>(f);
        if !body.map().is_free(3, face) {
            topomech::cut::dissociate_face(body, face).unwrap();
        }
    }
    n
}

/// The vertex pairs joined by more than one edge cell of `map`, counted from its orbits.
fn doubled_pairs(map: &GMap<3>) -> std::collections::BTreeMap<(u32, u32), usize> {
    let mut count = std::collections::BTreeMap::new();
    for d in map.one_dart_per_cell(1) {
        let (a, b) = (map.vertex_id(d).0, map.vertex_id(map.alpha::<0>(d)).0);
        *count.entry((a.min(b), a.max(b))).or_insert(0) += 1;
    }
    count.retain(|_, n| *n > 1);
    count
}

/// A leveled map of the body's map at its rest positions.
fn leveled_body(body: &topomech::mechanics::Body) -> LeveledMap<3> {
    LeveledMap::new(body.map().clone(), body.attrs().rest_position().as_slice().to_vec())
}

/// Law 2 per edge cell: two edge cells between the same vertices get a spring each, from the tets
/// on their own side of the cut; together they are exactly as stiff as the uncut edge, and each is
/// carried (split, refined) on its own.
#[test]
fn a_cut_edge_whose_ends_stay_joined_carries_two_springs_through_refinement() {
    use topomech::mechanics::Body;
    let (points, tets) = kuhn_cube(3);
    let (mut body, _) = Body::from_tets(&points, &tets, material()).unwrap();
    let edge = inner_edges(&body)[0];
    let (a, b) = (body.map().vertex_id(edge).0, body.map().vertex_id(body.map().alpha::<0>(edge)).0);
    let uncut = LeveledMechanics::new(&leveled_body(&body), material()).unwrap().spring(a, b).unwrap();
    let ring = cut_ring(&mut body, edge, 0, 3);
    assert!(ring >= 4, "an inner edge has a closed ring of at least 4 tets: {ring}");
    let map = body.map();
    assert_eq!((map.vertex_id(edge).0, map.vertex_id(map.alpha::<0>(edge)).0), (a, b), "the ends did not split");
    assert_eq!(doubled_pairs(map).get(&(a.min(b), a.max(b))), Some(&2), "two edge cells join a and b");

    let mut m = leveled_body(&body);
    let mut mech = LeveledMechanics::new(&m, material()).unwrap();
    mech.check(&m).unwrap();
    let two = mech.springs_between(a, b);
    assert_eq!(two.len(), 2, "one spring per edge cell");
    assert_ne!(two[0].0.id, two[1].0.id);
    assert!(mech.spring(a, b).is_none() && mech.edge(a, b).is_none(), "the pair alone is ambiguous");
    let (s0, s1) = (two[0].1, two[1].1);
    assert_eq!(s0.rest, s1.rest);
    assert!(s0.stiffness > 0.0 && s1.stiffness > 0.0, "both sides hold tets");
    let k = s0.stiffness + s1.stiffness;
    assert!((k - uncut.stiffness).abs() < 1e-12 * uncut.stiffness, "{k} vs {}", uncut.stiffness);
    let c = s0.damping + s1.damping;
    assert!((c - uncut.damping).abs() < 1e-12 * uncut.damping);

    // Split one of the two: the other is untouched, the split one becomes two halves in series.
    let d = m.map().darts().find(|&d| m.map().cell_id(1, d).0 == two[0].0.id).unwrap();
    mech.split_edge(&mut m, d, 1).unwrap();
    mech.check(&m).unwrap();
    assert_eq!(mech.spring_at(two[1].0), Some(s1), "the other edge cell keeps its spring");
    assert_eq!(mech.root(two[0].0), Some(s0));
    assert!(mech.root(two[1].0).is_none());
    let chain = mech.chain(two[0].0);
    assert_eq!(chain.len(), 2);
    assert!(chain.iter().all(|&h| mech.spring_at(h).unwrap().stiffness == 2.0 * s0.stiffness));

    // Refine the zone around the edge: both are carried, as disjoint chains from a to b.
    let mid = [0, 1, 2].map(|i| 0.5 * (m.points()[a as usize][i] + m.points()[b as usize][i]));
    mech.refine_around(&mut m, mid, 0.3, 2).unwrap();
    mech.check(&m).unwrap();
    let (c0, c1) = (mech.chain(two[0].0), mech.chain(two[1].0));
    assert!(c0.len() >= 2 && c1.len() >= 2, "both edge cells were split: {c0:?} {c1:?}");
    for (chain, root) in [(&c0, s0), (&c1, s1)] {
        let (first, last) = (chain[0], chain[chain.len() - 1]);
        assert!(first.ends().0 == a.min(b) || first.ends().1 == a.min(b), "starts at the smaller end");
        assert!(last.ends().0 == a.max(b) || last.ends().1 == a.max(b), "ends at the larger end");
        let compliance: f64 = chain.iter().map(|&h| 1.0 / mech.spring_at(h).unwrap().stiffness).sum();
        assert!((compliance * root.stiffness - 1.0).abs() < 1e-12);
    }
    assert!(c0.iter().all(|h| !c1.contains(h)), "two chains, no link shared");
    let sys = mech.spring_system(&m, [0.0; 3], &[]).unwrap();
    assert_eq!(sys.springs(), m.map().count_cells().0[1], "one spring per edge cell");
    let mut ends: Vec<[u32; 2]> = sys.ends().to_vec();
    ends.sort_unstable();
    let repeated = ends.windows(2).filter(|w| w[0] == w[1]).count();
    let doubled: usize = doubled_pairs(m.map()).values().map(|n| n - 1).sum();
    assert_eq!(repeated, doubled, "the spring system repeats exactly the doubled vertex pairs");
    let total = body.total_tet_mass(); // ρ · 27, cut or not
    let vm: f64 = mech.vertex_masses(&m).unwrap().iter().sum();
    assert!((vm - total).abs() < 1e-12 * total, "{vm} vs {total}");
}

/// Random cuts (rings opened at two places, so doubled edges, and random other faces) then random
/// refinements: every law holds after every op, and the springs between each vertex pair are as
/// many as the edge cells joining it.
fn run_cut(rings: &[(u8, u8, u8)], faces: &[u16], ops: &[u8]) -> Result<usize, String> {
    use topomech::mechanics::Body;
    let (points, tets) = kuhn_cube(3);
    let (mut body, _) = Body::from_tets(&points, &tets, material()).unwrap();
    for &(e, i, j) in rings {
        let edges = inner_edges(&body);
        cut_ring(&mut body, edges[e as usize % edges.len()], i as usize, j as usize);
    }
    for &f in faces {
        let inner: Vec<DartId> = body.map().darts().filter(|&d| !body.map().is_free(3, d)).collect();
        if let Some(&d) = inner.get(f as usize % inner.len().max(1)) {
            topomech::cut::dissociate_face(&mut body, d).map_err(|e| e.to_string())?;
        }
    }
    let mut m = leveled_body(&body);
    let mut mech = LeveledMechanics::new(&m, material()).map_err(|e| e.to_string())?;
    let doubled = doubled_pairs(m.map()).len();
    let (_, ops) = decode(ops);
    for (k, &op) in ops.iter().enumerate() {
        if m.map().dart_count() >= MAX_DARTS {
            break;
        }
        match apply(&mut mech, &mut m, op) {
            Ok(()) | Err(CouplingError::Subdivide(_)) => {}
            Err(e) => return Err(format!("op {k} {op:?}: {e}")),
        }
        mech.check(&m).map_err(|e| format!("op {k} {op:?}: {e}"))?;
    }
    mech.check(&m).map_err(|e| e.to_string())?;
    for (&(a, b), &n) in &doubled_pairs(m.map()) {
        let found = mech.springs_between(a, b).len();
        if found != n {
            return Err(format!("vertices ({a}, {b}): {n} edge cells, {found} springs"));
        }
    }
    let sys = mech.spring_system(&m, [0.0; 3], &[]).unwrap();
    if sys.springs() != m.map().count_cells().0[1] {
        return Err(format!("{} springs for {} edge cells", sys.springs(), m.map().count_cells().0[1]));
    }
    Ok(doubled)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]

    #[test]
    fn spring_laws_hold_after_random_refinements_of_randomly_cut_cubes(
        rings in proptest::collection::vec(any::<(u8, u8, u8)>(), 1..3),
        faces in proptest::collection::vec(any::<u16>(), 0..3),
        ops in proptest::collection::vec(any::<u8>(), 1..16),
    ) {
        if let Err(e) = run_cut(&rings, &faces, &ops) {
            prop_assert!(false, "{}", e);
        }
    }
}

#[test]
fn a_ring_opened_twice_gives_doubled_edges_that_survive_refinement() {
    // One ring cut, no other face: at least the cut edge is doubled; then a tet 1→8 and a ball.
    let doubled = run_cut(&[(0, 0, 3)], &[], &[1, 0x82, 0, 0, 3, 128, 128]).unwrap();
    assert!(doubled >= 1, "{doubled}");
}

/// The springs of `mech` as (end positions sorted, as bits; rest, stiffness, damping), sorted.
fn springs_by_position(mech: &LeveledMechanics, m: &LeveledMap<3>) -> Vec<([[u64; 3]; 2], [f64; 3])> {
    let bits = |v: u32| m.points()[v as usize].map(f64::to_bits);
    let mut out: Vec<_> = mech
        .springs()
        .map(|(e, s)| {
            let (mut x, mut y) = (bits(e.a), bits(e.b));
            if y < x {
                std::mem::swap(&mut x, &mut y);
            }
            ([x, y], [s.rest, s.stiffness, s.damping])
        })
        .collect();
    out.sort_by_key(|a| a.0);
    out
}

#[test]
fn a_ball_holding_everything_takes_the_bulk_path_with_the_per_tet_springs() {
    // Kuhn cube k = 2 on [0, 2]³, jittered inner vertex: a ball of radius 1.5 at the centre meets
    // every tet (each is within 0.82 of it) but misses the corners, so it runs tet by tet (1.7 at
    // level 2: the corner children are within 0.9); a ball of radius 10 holds every vertex, so
    // the map's bulk path runs.
    let (mut points, tets) = kuhn_cube(2);
    for (i, p) in points.iter_mut().enumerate() {
        if p.iter().all(|&c| c > 0.5 && c < 1.5) {
            let j = jitter(i as u64);
            *p = [0, 1, 2].map(|k| p[k] + 0.1 * j[k]);
        }
    }
    let base = tet_mesh(points, &tets);
    let (mut bulk, mut perop) = (base.clone(), base.clone());
    let mut mb = LeveledMechanics::new(&bulk, material()).unwrap();
    let mut mp = mb.clone();
    let rb = mb.refine_around(&mut bulk, [1.0; 3], 10.0, 2).unwrap();
    let rp = mp.refine_around(&mut perop, [1.0; 3], 1.5, 1).unwrap();
    let rp2 = mp.refine_around(&mut perop, [1.0; 3], 1.7, 2).unwrap();
    assert_eq!(rb.subdivided_per_level, vec![0, tets.len(), 8 * tets.len()]);
    assert_eq!(rp.subdivided_per_level, vec![0, tets.len()]);
    assert_eq!(rp2.subdivided_per_level[2], 8 * tets.len());
    mb.check(&bulk).unwrap();
    mp.check(&perop).unwrap();
    assert_eq!(bulk.map().count_cells(), perop.map().count_cells());
    let (sb, sp) = (springs_by_position(&mb, &bulk), springs_by_position(&mp, &perop));
    assert_eq!(sb.len(), sp.len());
    assert_eq!(sb.len(), bulk.map().count_cells().0[1], "one spring per edge cell");
    for ((kb, vb), (kp, vp)) in sb.iter().zip(&sp) {
        assert_eq!(kb, kp, "same edges by end positions");
        for (x, y) in vb.iter().zip(vp) {
            assert!((x - y).abs() <= 1e-12 * y.abs().max(1e-300), "spring {kb:?}: {vb:?} vs {vp:?}");
        }
    }
    let (tb, tp) = (mb.masses.total(&bulk), mp.masses.total(&perop));
    assert!((tb - tp).abs() <= 1e-12 * tp, "Σ tet mass {tb} vs {tp}");
}

/// Finding 23 (docs/VERIFICATION.md): the coupling refuses what a `Body` refuses (a bad material,
/// a zero-volume or non-finite tet) and a map it was not built for, before the map changes; the
/// leveled map refuses a partial geometry and a dart past its end instead of panicking or
/// making up positions.
#[test]
fn the_coupling_and_the_leveled_map_refuse_bad_input_before_changing_anything() {
    let single = || GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap().0;
    let m = LeveledMap::new(single(), TET.to_vec());
    // Materials: each bad constant is named, as by Body::from_tets.
    for (name, bad) in [
        ("density", Material { density: 0.0, ..material() }),
        ("young", Material { young: f64::NAN, ..material() }),
        ("young", Material { young: -1.0, ..material() }),
        ("damping", Material { damping: f64::INFINITY, ..material() }),
        ("viscosity", Material { viscosity: -3.0, ..material() }),
    ] {
        let e = LeveledMechanics::new(&m, bad).unwrap_err();
        assert!(
            matches!(e, CouplingError::Material(topomech::mechanics::ModelError::BadMaterial { name: n, .. }) if n == name)
                || (name == "density" && matches!(e, CouplingError::Subdivide(SubdivideError::BadDensity(_)))),
            "{name}: {e}"
        );
        let given = topomech::subdivide::TetMasses { mass: vec![1.0] };
        assert!(LeveledMechanics::with_masses(&m, bad, given).is_err(), "with_masses, {name}");
    }
    // Geometry: a flat tet, coincident corners, a NaN corner.
    let mut flat = TET.to_vec();
    flat[3] = [0.5, 0.5, 0.0];
    flat[0] = [0.0, 0.0, 0.0];
    flat[1] = [1.0, 0.0, 0.0];
    flat[2] = [0.0, 1.0, 0.0];
    let mut same = TET.to_vec();
    same[1] = same[0];
    for pts in [flat, same] {
        let e = LeveledMechanics::new(&LeveledMap::new(single(), pts), material()).unwrap_err();
        assert!(matches!(e, CouplingError::DegenerateTet { volume: 0, .. }), "{e}");
    }
    let mut nan = TET.to_vec();
    nan[2][1] = f64::NAN;
    let e = LeveledMechanics::new(&LeveledMap::new(single(), nan), material()).unwrap_err();
    assert!(matches!(e, CouplingError::Subdivide(SubdivideError::NonFinitePosition { vertex: 2, .. })), "{e}");

    // Another map's coupling: refused with the map unchanged (it was subdivided, then the
    // coupling failed with NoSpring and the pair was out of step).
    let mech = LeveledMechanics::new(&m, material()).unwrap();
    let (points, tets) = kuhn_cube(2);
    let mut big = LeveledMap::new(GMap::<3>::from_tets(points.len(), &tets).unwrap().0, points);
    let d = big.map().darts().nth(100).unwrap();
    let (darts, log) = (big.map().dart_count(), big.split_log().len());
    let mut other = mech.clone();
    let e = other.subdivide_tet(&mut big, d, 1).unwrap_err();
    assert_eq!(e, CouplingError::StateCount { states: 4, vertices: 27 });
    assert!(other.split_edge(&mut big, d, 1).is_err() && other.subdivide_triangle(&mut big, d, 1).is_err());
    assert!(other.refine_around(&mut big, [1.0; 3], 10.0, 1).is_err());
    assert_eq!((big.map().dart_count(), big.split_log().len()), (darts, log));
    assert_eq!(other, mech);
    // Resized state vectors are seen too.
    let mut own = LeveledMap::new(single(), TET.to_vec());
    let mut shrunk = mech.clone();
    shrunk.velocity.pop();
    assert!(matches!(
        shrunk.subdivide_tet(&mut own, DartId(0), 1),
        Err(CouplingError::StateCount { states: 3, vertices: 4 })
    ));
    assert_eq!(own.map().dart_count(), 24);

    // The leveled map alone: a dart past the end, points that stop before a vertex.
    let mut masses = topomech::subdivide::TetMasses::from_density(&m, 1.0).unwrap();
    let mut alone = LeveledMap::new(single(), TET.to_vec());
    let e = alone.subdivide_tet_with_mass(DartId(9999), 1, &mut masses).unwrap_err();
    assert_eq!(e, SubdivideError::NoSuchDart(DartId(9999)));
    let mut partial = LeveledMap::new(single(), TET[..3].to_vec());
    let refusals = [
        partial.clone().subdivide_tet(DartId(0), 1).map(|_| ()),
        partial.clone().subdivide_tet_with_mass(DartId(0), 1, &mut masses).map(|_| ()),
        partial.clone().split_edge(DartId(0), 1).map(|_| ()),
        partial.clone().subdivide_triangle(DartId(0), 1).map(|_| ()),
        partial.clone().refine_uniform(1, &mut masses).map(|_| ()),
        partial.refine_around([0.1; 3], 10.0, 1, &mut masses).map(|_| ()),
    ];
    for (k, r) in refusals.into_iter().enumerate() {
        assert_eq!(r, Err(SubdivideError::NoPosition { vertex: 3, points: 3 }), "operation {k}");
    }
    assert_eq!((partial.map().dart_count(), partial.points().len()), (24, 3));
    assert_eq!(masses.mass.len(), 1);
    // A map without any geometry still refines (its new vertices get the origin).
    let mut bare = LeveledMap::new(single(), vec![]);
    assert!(bare.subdivide_tet(DartId(0), 1).is_ok() && bare.points().is_empty());
}

/// Finding 31 (docs/VERIFICATION.md): `LeveledMechanics::spring_system` and `vertex_masses`
/// did not check that the map given is the one the coupling follows. A coupling of one tet
/// given a six-tet cube returned a system with the cube's masses and the tet's springs; a
/// coupling of the cube given one tet had springs whose ends reach past the tet's vertex ids
/// and panicked building the incidence lists. Both are refused as every coupling operation
/// refuses another map (`CouplingError::StateCount`).
#[test]
fn the_coupling_projects_only_the_map_it_follows() {
    let (points, tets) = kuhn_cube(1);
    let cube = tet_mesh(points, &tets);
    let one = tet_mesh(TET.to_vec(), &[[0, 1, 2, 3]]);
    let (small, big) = (
        LeveledMechanics::new(&one, Material::default()).unwrap(),
        LeveledMechanics::new(&cube, Material::default()).unwrap(),
    );
    let count = |states, vertices| Err(CouplingError::StateCount { states, vertices });
    assert_eq!(small.spring_system(&cube, [0.0; 3], &[]).map(|s| s.slots()), count(4, 8));
    assert_eq!(big.spring_system(&one, [0.0; 3], &[]).map(|s| s.slots()), count(8, 4));
    assert_eq!(small.vertex_masses(&cube).map(|v| v.len()), count(4, 8));
    assert_eq!(big.vertex_masses(&one).map(|v| v.len()), count(8, 4));
    let sys = big.spring_system(&cube, [0.0; 3], &[]).unwrap();
    assert_eq!((sys.slots(), sys.springs()), (8, 19));
    let total: f64 = big.vertex_masses(&cube).unwrap().iter().sum();
    assert!((total - 1.0).abs() < 1e-12, "{total}");
}
