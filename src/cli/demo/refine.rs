//! Refinement of the incision zone (seed 004) with its mechanics: the final body's map and rest
//! positions wrapped as level 0 of a [`LeveledMap`], its masses, springs and vertex state wrapped as
//! a [`LeveledMechanics`], and each tet beside the incision subdivided 1→8 at level 1 through the
//! coupling.
//!
//! Masses follow the subdivision (each child tet takes its parent's mass in proportion to its
//! volume) and the stage checks that Σ tet mass is unchanged. Springs follow too, one per edge
//! cell, so the pairs of vertices that the tear left joined by two edge cells carry two springs:
//! the stage checks that the level-0 coupling is the body's spring network spring for spring (rest
//! length, stiffness, damping per edge cell), then after the refinement every spring law of
//! [`LeveledMechanics::check`] (one spring per edge cell, rest lengths, the series rule along
//! every split spring, law 2 for the rest, vertex masses) and that the projected spring system has
//! one spring per edge cell; and the level laws ([`LeveledMap::check_all`]: finest map valid,
//! μt ≤ μf ≤ μa, every level extracted and valid). Then the simulation goes on on the refined
//! network ([`simulate_refined`]): the finest level projected as a flat spring system (slots =
//! vertex ids, one spring per edge cell, vertex masses from the child tets), stepped with the
//! scene's integrator and pins at its own stable time step (its springs are stiffer); checked:
//! Σ slot mass = Σ tet mass, no blow-up, pinned vertices unmoved.

use std::time::Instant;

use indicatif::ProgressBar;
use topomech::mechanics::{Body, Integrator, StepConfig, StepError, Stepper, Vec3};
use topomech::mesh::centroid_of;
use topomech::subdivide::{EdgeKey, LeveledMap, LeveledMechanics, TetMasses};
use topomech::surface::Surface;
use topomech::{AlphaMask, CellId, DartId, GMap};

use super::scene::{SceneConfig, StageRun};
use super::DemoError;
use crate::cli::simulate::StepTimes;

/// The level the incision zone is refined to.
pub const LEVEL: u8 = 1;

/// Checks run by [`refine`] when it succeeds: level laws, mass balance, level-0 springs = the
/// body's, spring laws, one projected spring per edge cell.
pub const CHECKS: usize = 5;

/// What [`refine`] made.
#[derive(Clone, Debug)]
pub struct Refined {
    /// The leveled map (its points are the rest positions).
    pub lm: LeveledMap<3>,
    /// Masses, springs and vertex state of its finest level (positions: the body's current ones,
    /// new vertices interpolated).
    pub mech: LeveledMechanics,
    /// Checks passed.
    pub checks: usize,
    /// Springs before the refinement (the body's, one per edge cell).
    pub springs_before: usize,
    /// Edge cells of level 0 sharing both end vertices with another edge cell (the cut edges whose
    /// ends stayed joined): each has its own spring.
    pub doubled_edges: usize,
    /// How many of those were split by the refinement (each carried as its own chain of halves).
    pub doubled_split: usize,
}

/// Wraps `body` (map, rest and current positions, velocities, tet masses, springs) as level 0 and
/// subdivides the live tets among `tets` at [`LEVEL`] through the spring coupling, then checks the
/// laws listed in the [module docs](self). O(tets · darts) to find the tets plus the subdivisions
/// and O(capacity · n² + darts · volume) for the checks.
///
/// # Errors
/// [`DemoError::Coupling`] when the body cannot be coupled or a subdivision fails (naming the
/// tet), [`DemoError::SpringMismatch`] when a level-0 spring is not the body's,
/// [`DemoError::SpringLaws`] when a spring law fails, [`DemoError::Levels`] when a level law
/// fails, [`DemoError::Balance`] when Σ tet mass changed by more than the tolerance.
pub fn refine(body: &Body, tets: &[CellId], run: &mut StageRun, bar: &ProgressBar) -> Result<Refined, DemoError> {
    let mut lm = LeveledMap::new(body.map().clone(), body.attrs().rest_position().as_slice().to_vec());
    // The leveled map starts as a copy of the body's map: same cell ids, so the same masses and
    // the same springs per edge cell.
    let masses =
        TetMasses { mass: (0..body.map().cell_id_bound(3)).map(|t| body.attrs().tet_mass(CellId(t as u32))).collect() };
    let coupling = |tet: Option<CellId>| move |source| DemoError::Coupling { tet, source };
    let mut mech = LeveledMechanics::with_masses(&lm, *body.attrs().material(), masses).map_err(coupling(None))?;
    same_springs(body, &mech)?;
    mech.position.iter_mut().zip(body.attrs().position().as_slice()).for_each(|(x, p)| *x = *p);
    mech.velocity.iter_mut().zip(body.attrs().velocity().as_slice()).for_each(|(x, v)| *x = *v);
    let (before, springs_before) = (mech.masses.total(&lm), mech.springs().count());
    let doubled = doubled_edges(&mech);
    let t0 = Instant::now();
    for &t in tets {
        let found = lm.map().darts().find(|&d| lm.map().cell_id(3, d) == t && lm.mu(d).tet < LEVEL);
        if let Some(d) = found {
            let t1 = Instant::now();
            mech.subdivide_tet(&mut lm, d, LEVEL).map_err(coupling(Some(t)))?;
            run.step_us.push(t1.elapsed().as_secs_f64() * 1e6);
            run.operations += 1;
        }
        bar.inc(1);
    }
    run.operation_us = t0.elapsed().as_secs_f64() * 1e6;
    lm.check_all().map_err(DemoError::Levels)?;
    let residual = (mech.masses.total(&lm) - before) / before;
    if residual.abs() > super::checks::TOLERANCE {
        return Err(DemoError::Balance { stage: "refinement", step: 0, quantity: "mass", residual });
    }
    mech.check(&lm).map_err(DemoError::SpringLaws)?;
    let projected =
        mech.spring_system(&lm, [0.0; 3], &[]).map_err(|source| DemoError::Coupling { tet: None, source })?.springs();
    let edges = lm.map().count_cells().0[1];
    if projected != edges {
        return Err(DemoError::SpringCount { springs: projected, edges });
    }
    let doubled_split = doubled.iter().filter(|&&e| mech.root(e).is_some()).count();
    Ok(Refined { lm, mech, checks: CHECKS, springs_before, doubled_edges: doubled.len(), doubled_split })
}

/// Checks run by [`simulate_refined`] when it succeeds: mass balance of the projected system,
/// the steps without blow-up, pinned vertices unmoved.
pub const SIM_CHECKS: usize = 3;

/// What [`simulate_refined`] measured.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct RefinedSim {
    /// Steps made on the refined network.
    pub steps: u64,
    /// Its time step: [`super::scene::time_step`] of the refined network (at most the body's when
    /// the refinement made it stiffer).
    pub dt: f64,
    /// Slots (vertex ids of the finest level) and springs (edge cells) of the projected system.
    pub slots: usize,
    /// See `slots`.
    pub springs: usize,
    /// Pinned slots (the body's pins, and new vertices whose rest position is in the pinned zone).
    pub pinned: usize,
    /// Median wall time of a step in µs.
    pub step_us_median: f64,
    /// Largest distance of a vertex from its rest position at the end.
    pub max_displacement: f64,
    /// Kinetic energy at the end.
    pub kinetic_energy: f64,
    /// Checks passed ([`SIM_CHECKS`]).
    pub checks: usize,
}

/// Runs `steps` steps of the scene's integrator (symplectic Euler, gravity `config.gravity`) on the
/// finest level of `refined`, in place on its positions and velocities, at the refined network's
/// own time step ([`super::scene::time_step`]: its springs are stiffer than the body's, so the
/// body's `config.dt` may be past its stability limit).
/// Pins: a vertex id the body has keeps the body's pin; a new vertex is pinned when its rest
/// coordinate along the long axis is ≤ `config.pin_limit` (the scene's rule). O(steps · (slots +
/// springs)) plus O(darts + E) to project.
///
/// # Errors
/// [`DemoError::Balance`] when Σ slot mass differs from Σ tet mass, [`DemoError::TimeStep`] when
/// the refined network's step is below the normal range of f64, [`DemoError::RefinedStep`] on
/// a blow-up (naming the step), [`DemoError::RefinedPin`] when a pinned vertex moved.
pub fn simulate_refined(
    refined: &mut Refined,
    body: &Body,
    config: &SceneConfig,
    steps: u64,
) -> Result<RefinedSim, DemoError> {
    let (lm, mech) = (&refined.lm, &mut refined.mech);
    let pins = body.attrs().pinned().as_slice();
    let rest = lm.points();
    let fixed: Vec<bool> = (0..mech.position.len())
        .map(|v| {
            pins.get(v).copied().unwrap_or_else(|| rest.get(v).is_some_and(|p| p[config.long_axis] <= config.pin_limit))
        })
        .collect();
    let sys =
        mech.spring_system(lm, config.gravity, &fixed).map_err(|source| DemoError::Coupling { tet: None, source })?;
    let (slot_mass, tet_mass) = (sys.mass().iter().sum::<f64>(), mech.masses.total(lm));
    let residual = (slot_mass - tet_mass) / tet_mass;
    if residual.is_nan() || residual.abs() > super::checks::TOLERANCE {
        return Err(DemoError::Balance { stage: "refinement", step: 0, quantity: "slot mass", residual });
    }
    // A pinned vertex does not move: a new one may have inherited a velocity from a free end.
    for (v, _) in fixed.iter().enumerate().filter(|(_, &f)| f) {
        mech.velocity[v] = [0.0; 3];
    }
    let held: Vec<(usize, Vec3)> = (0..sys.slots()).filter(|&v| fixed[v]).map(|v| (v, mech.position[v])).collect();
    let step_error = |step| move |source| DemoError::RefinedStep { step, source };
    // The refined network is stiffer than the body (children are half the size, springs follow
    // law 2 and the series rule): its own stable step, by the scene's rule, not the body's.
    let dt = super::scene::time_step(&sys, "refinement")?;
    let config_step = StepConfig::new(Integrator::Symplectic, dt);
    let mut stepper = Stepper::new(config_step, &sys, &mech.position, &mech.velocity).map_err(step_error(0))?;
    let mut times = StepTimes::new(steps);
    for step in 1..=steps {
        let t = Instant::now();
        stepper.step(&sys, &mut mech.position, &mut mech.velocity).map_err(step_error(step))?;
        times.push(t.elapsed().as_secs_f64() * 1e6);
    }
    if let Some(&(vertex, at)) = held.iter().find(|&&(v, p)| mech.position[v] != p) {
        return Err(DemoError::RefinedPin { vertex, at, now: mech.position[vertex] });
    }
    let kinetic_energy = sys
        .kinetic_energy(&mech.velocity)
        .map_err(|e| DemoError::RefinedStep { step: steps, source: StepError::BadInput(e.to_string()) })?;
    let max_displacement = (0..sys.slots().min(rest.len()))
        .filter(|&v| sys.mass()[v] > 0.0)
        .map(|v| dist(mech.position[v], rest[v]))
        .fold(0.0, topomech::mesh::nan_max);
    Ok(RefinedSim {
        steps,
        dt,
        slots: sys.slots(),
        springs: sys.springs(),
        pinned: fixed.iter().filter(|&&f| f).count(),
        step_us_median: times.median(),
        max_displacement,
        kinetic_energy,
        checks: SIM_CHECKS,
    })
}

fn dist(a: Vec3, b: Vec3) -> f64 {
    let d = sub(a, b);
    dot(d, d).sqrt()
}

/// Errors unless every spring of the level-0 coupling has the rest length, stiffness and damping of
/// the body's spring on the same edge cell (relative [`super::checks::TOLERANCE`]), and the body
/// has no other edge. O(E log E).
fn same_springs(body: &Body, mech: &LeveledMechanics) -> Result<(), DemoError> {
    let attrs = body.attrs();
    let close = |x: f64, y: f64| (x - y).abs() <= super::checks::TOLERANCE * x.abs().max(y.abs());
    for (e, s) in mech.springs() {
        let id = CellId(e.id);
        let pairs = [
            ("rest length", s.rest, attrs.edge_rest_length(id)),
            ("stiffness", s.stiffness, attrs.edge_stiffness(id)),
            ("damping", s.damping, attrs.edge_damping(id)),
        ];
        if let Some(&(quantity, coupled, body)) = pairs.iter().find(|(_, x, y)| !close(*x, *y)) {
            return Err(DemoError::SpringMismatch { edge: e.id, ends: e.ends(), quantity, coupled, body });
        }
    }
    let edges = body.map().count_cells().0[1];
    let springs = mech.springs().count();
    if springs != edges {
        return Err(DemoError::SpringCount { springs, edges });
    }
    Ok(())
}

/// The edges whose spring shares both ends with another spring (springs come in vertex-pair order,
/// so such springs are neighbours). O(E).
fn doubled_edges(mech: &LeveledMechanics) -> Vec<EdgeKey> {
    let keys: Vec<EdgeKey> = mech.springs().map(|(e, _)| e).collect();
    let shared = |k: usize, l: usize| keys.get(l).is_some_and(|x: &EdgeKey| x.ends() == keys[k].ends());
    (0..keys.len()).filter(|&k| shared(k, k + 1) || (k > 0 && shared(k, k - 1))).map(|k| keys[k]).collect()
}

/// The boundary of the finest level as triangles: every α3-free face, its vertex cycle walked by
/// α0 then α1 and fanned from its first vertex (zero-area triangles at flat vertices dropped),
/// oriented away from its volume's centroid, at `positions` (by vertex id); with, per triangle, μt
/// of the volume behind it (its resolution level, for colouring). O(darts).
pub fn refined_surface(lm: &LeveledMap<3>, positions: &[Vec3]) -> (Surface, Vec<u8>) {
    let map = lm.map();
    let mut index = vec![u32::MAX; map.cell_id_bound(0)];
    let mut s = Surface::default();
    let mut levels = Vec::new();
    for d in map.one_dart_per_cell(2) {
        if !map.is_free(3, d) {
            continue;
        }
        let cycle = face_cycle(map, d);
        let inside = volume_centroid(map, positions, d);
        let ids: Vec<u32> = cycle.iter().map(|&v| vertex_index(&mut s, &mut index, positions, v)).collect();
        for k in 1..ids.len().saturating_sub(1) {
            let tri = [ids[0], ids[k], ids[k + 1]];
            let p = tri.map(|i| s.positions[i as usize]);
            let n = cross(sub(p[1], p[0]), sub(p[2], p[0]));
            let area2 = dot(n, n);
            if area2 <= f64::EPSILON * dot(sub(p[1], p[0]), sub(p[1], p[0])).powi(2) {
                continue;
            }
            let outward = dot(n, sub(p[0], inside)) >= 0.0;
            s.triangles.push(if outward { tri } else { [tri[0], tri[2], tri[1]] });
            s.face_volumes.push(map.cell_id(3, d).0);
            levels.push(lm.mu(d).tet);
        }
    }
    (s, levels)
}

/// The vertex ids around the face of `d`, in order. Bounded by the face's dart count.
fn face_cycle(map: &GMap<3>, d: DartId) -> Vec<CellId> {
    let mut out = vec![map.vertex_id(d)];
    let mut x = map.alpha::<1>(map.alpha::<0>(d));
    for _ in 0..map.dart_count() {
        if x == d {
            break;
        }
        out.push(map.vertex_id(x));
        x = map.alpha::<1>(map.alpha::<0>(x));
    }
    out
}

fn volume_centroid(map: &GMap<3>, positions: &[Vec3], d: DartId) -> Vec3 {
    let mut ids: Vec<CellId> = map.orbit(d, AlphaMask::cell(3, 3)).into_iter().map(|x| map.vertex_id(x)).collect();
    ids.sort_unstable();
    ids.dedup();
    centroid_of(ids.iter().map(|v| positions.get(v.index()).copied().unwrap_or([0.0; 3])))
}

fn vertex_index(s: &mut Surface, index: &mut [u32], positions: &[Vec3], v: CellId) -> u32 {
    if index[v.index()] == u32::MAX {
        index[v.index()] = s.positions.len() as u32;
        s.positions.push(positions.get(v.index()).copied().unwrap_or([0.0; 3]));
        s.vertex_ids.push(v.0);
    }
    index[v.index()]
}

fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::demo::test_cube as cube;
    use topomech::{cut, generate};

    #[test]
    fn refining_some_tets_keeps_the_enclosed_volume_and_marks_their_level() {
        let body = cube();
        let before = topomech::surface::boundary_surface(&body);
        let tets: Vec<CellId> = (0..12).map(CellId).collect();
        let mut run = StageRun::default();
        let mass = body.total_tet_mass();
        let r = refine(&body, &tets, &mut run, &ProgressBar::hidden()).unwrap();
        assert_eq!((run.operations, r.checks), (12, CHECKS));
        assert!((r.mech.masses.total(&r.lm) - mass).abs() < 1e-12 * mass, "the children share the parents' masses");
        assert_eq!(r.lm.map().count_cells().0[3], 48 + 7 * 12, "1→8 per refined tet");
        assert_eq!(r.springs_before, body.map().count_cells().0[1]);
        assert_eq!(r.mech.springs().count(), r.lm.map().count_cells().0[1], "one spring per edge cell");
        assert_eq!(r.doubled_edges, 0, "an uncut cube has no doubled edge");
        let (after, levels) = refined_surface(&r.lm, &r.mech.position);
        assert_eq!(levels.len(), after.triangles.len());
        assert!((after.enclosed_volume().unwrap() - before.enclosed_volume().unwrap()).abs() < 1e-12, "same solid");
        assert!((after.enclosed_volume().unwrap() - 8.0).abs() < 1e-12);
        assert!(levels.contains(&0) && levels.contains(&LEVEL), "both levels show on the boundary");
        assert!(after.triangles.len() > before.triangles.len());
    }

    #[test]
    fn an_unrefined_map_gives_back_the_body_surface() {
        let body = cube();
        let r = refine(&body, &[], &mut StageRun::default(), &ProgressBar::hidden()).unwrap();
        let (s, levels) = refined_surface(&r.lm, &r.mech.position);
        assert_eq!(s.triangles.len(), 12 * 4, "12k² boundary faces for k = 2");
        assert!(levels.iter().all(|&l| l == 0));
        assert!((s.enclosed_volume().unwrap() - 8.0).abs() < 1e-12);
    }

    /// A cube whose ring of tets around an inner edge is opened at two faces: the edge becomes two
    /// edge cells between the same vertices. Refining the tets around it carries both springs.
    #[test]
    fn a_doubled_edge_of_a_cut_body_is_refined_with_both_springs() {
        let (points, tets) = generate::kuhn_cube(3);
        let mut body = Body::from_tets(&points, &tets, cut::ops::material()).unwrap().0;
        let map = body.map();
        let inner = |v: CellId| body.attrs().rest_position()[v].iter().all(|&c| c > 0.5 && c < 2.5);
        let edge = map
            .one_dart_per_cell(1)
            .into_iter()
            .find(|&d| inner(map.vertex_id(d)) && inner(map.vertex_id(map.alpha::<0>(d))))
            .unwrap();
        let ring: Vec<DartId> =
            std::iter::successors(Some(edge), |&x| Some(map.alpha::<3>(map.alpha::<2>(x))).filter(|&y| y != edge))
                .collect();
        let around: Vec<CellId> = ring.iter().map(|&x| map.cell_id(3, x)).collect();
        for f in [ring[0], ring[2]] {
            let face = body.map().alpha::<2>(f);
            cut::dissociate_face(&mut body, face).unwrap();
        }
        let before = body.map().count_cells().0[1];
        let r = refine(&body, &around, &mut StageRun::default(), &ProgressBar::hidden()).unwrap();
        assert_eq!(r.springs_before, before);
        assert_eq!((r.doubled_edges, r.doubled_split), (2, 2), "two edge cells, both split");
        assert_eq!(r.mech.roots().count(), r.lm.edge_split_log().len(), "level 1 splits level-0 edges only");
        assert!(r.mech.springs().count() > before);
        r.mech.check(&r.lm).unwrap();
    }
}
