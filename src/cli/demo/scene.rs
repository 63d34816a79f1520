//! The surgical scene: a body pinned at one end of its longest axis, sagging under gravity, then
//! cut, torn and trimmed, with every operation checked ([`Checker`]) and every stage recorded.
//!
//! ```text
//!   pinned end                          free end
//!   |##|------------------ | ------------------\
//!   |##|                   | incision           \   ← removal ball at the free tip
//!   |##|                   |(upper part only)   /
//!   |##|-----------------------------------------/        gravity ↓ (−up)
//! ```
//!
//! The incision is the face separation of `cut::incise_plane` (a face is cut when the centroids
//! of its two tets lie on opposite sides of the plane) restricted to the faces whose centroid lies
//! in the upper part of the body near the plane, so the body stays in one piece, as a scalpel
//! stroke does; a whole-plane cut would drop the free half.

use std::time::Instant;

use indicatif::ProgressBar;
use topomech::cut::{self, CutError, Plane};
use topomech::mechanics::{
    Body, Integrator, Material, PinSpec, Simulation, SpringSystem, StepConfig, TouchedCells, Vec3,
};
use topomech::mesh::centroid_of;
use topomech::{AlphaMask, CellId, DartId};

use super::checks::Checker;
use super::output::Output;
use super::DemoError;
use crate::cli::simulate::StepTimes;

/// Fraction of the longest extent pinned at its low end.
pub const PIN_FRACTION: f64 = 0.12;
/// Position of the incision plane along the longest axis, as a fraction of the extent from the
/// pinned end.
pub const INCISION_AT: f64 = 0.55;
/// Depth of the incision as a fraction of the body's height near the plane.
pub const INCISION_DEPTH: f64 = 0.6;
/// The tear threshold as a fraction of the largest vertex stress when the tear stage starts.
pub const TEAR_FRACTION: f64 = 0.8;
/// Vertices torn per step at most, and in the whole tear stage at most.
pub const TEAR_PER_STEP: usize = 2;
/// See [`TEAR_PER_STEP`].
pub const TEAR_MAX: usize = 16;
/// Radius of the removal ball as a fraction of the longest extent.
pub const REMOVAL_RADIUS: f64 = 0.12;
/// Young's modulus per unit weight and length, E = this · ρ · |g| · extent: with it the body sags
/// by about a fifth of its length whatever its units (E = 1000 for the built-in liver).
pub const YOUNG_PER_WEIGHT: f64 = 16.0;
/// Gravity acceleration.
pub const GRAVITY: f64 = 9.81;
/// Ambient viscosity ν (1/s): damps the sag to rest within about two seconds of simulated time.
pub const VISCOSITY: f64 = 5.0;
/// Largest time step; smaller when the mesh's stiffness or damping needs it ([`time_step`]).
pub const MAX_DT: f64 = 1e-3;

/// The fixed parameters of a scene, derived from the rest shape.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneConfig {
    /// Sag steps (the other stages scale with it).
    pub steps: u64,
    /// Time step.
    pub dt: f64,
    /// The axis of the longest extent (0 = x, 1 = y, 2 = z).
    pub long_axis: usize,
    /// The axis opposite to gravity.
    pub up_axis: usize,
    /// Gravity vector.
    pub gravity: Vec3,
    /// The material.
    pub material: Material,
    /// Rest bounding box of the points the tets use.
    pub lo: Vec3,
    /// See `lo`.
    pub hi: Vec3,
    /// Vertices with rest coordinate ≤ this along `long_axis` are pinned.
    pub pin_limit: f64,
    /// How many vertices are pinned.
    pub pinned: usize,
}

impl SceneConfig {
    /// The longest extent of the rest shape. O(1).
    pub fn extent(&self) -> f64 {
        self.hi[self.long_axis] - self.lo[self.long_axis]
    }
}

/// What one stage did, besides the state it leaves.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StageRun {
    /// Stage name.
    pub name: &'static str,
    /// Time steps made.
    pub steps: u64,
    /// Wall time of each step (or each refinement operation) in µs, a bounded sample.
    pub step_us: StepTimes,
    /// Operations made: faces cut, vertices torn, tets removed, tets refined.
    pub operations: usize,
    /// Faces dissociated by the stage.
    pub cut_faces: usize,
    /// Wall time of the topological operation(s) in µs.
    pub operation_us: f64,
}

/// A body, its simulation and its checker. See the [module docs](self).
pub struct Scene {
    /// The body.
    pub body: Body,
    /// Its simulation (projection and stepper).
    pub sim: Simulation,
    /// The checks run so far.
    pub checker: Checker,
    /// The parameters.
    pub config: SceneConfig,
    /// Simulated time so far.
    pub time: f64,
    /// The tets beside the incision (volume ids, both sides).
    pub incision_tets: Vec<CellId>,
    /// The incision plane.
    pub plane: Option<Plane>,
}

/// The bounding box of the points the tets use (a point no tet uses is not part of the body: it
/// must not stretch the box that places the pins, the incision and the removal). O(T).
fn bounds(points: &[Vec3], tets: &[[u32; 4]]) -> (Vec3, Vec3) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in tets.iter().flatten().filter_map(|&v| points.get(v as usize)) {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

/// The demo's time step for a spring system stepped by symplectic Euler:
/// [`Integrator::half_stable_dt`], half the stability limit (h²ω_max² + 2h c_max ≤ 4, damping
/// included), at most [`MAX_DT`]: dt = min(MAX_DT, 2 / (c_max + √(c_max² + 4 ω_max²))), which is 1/ω_max undamped.
/// ω_max² may pass `f64::MAX` (a needle edge of 1e-153): the limit is formed without it.
/// O(springs + slots).
///
/// # Errors
/// [`DemoError::TimeStep`] (naming `stage`) when dt is below the normal range of f64: a system
/// that stiff or that damped (a needle edge below about 1e-154 of the body) has no step that
/// f64 can take.
pub fn time_step(sys: &SpringSystem, stage: &'static str) -> Result<f64, DemoError> {
    let b = sys.mode_bounds();
    let dt = MAX_DT.min(Integrator::Symplectic.half_stable_dt(&b));
    if !dt.is_normal() {
        return Err(DemoError::TimeStep { stage, dt, omega_max: b.omega_max, damping_max: b.damping_max });
    }
    Ok(dt)
}

impl Scene {
    /// Builds the body of `points`/`tets`, pins its low end along the longest axis (the box of the
    /// points the tets use) and prepares a symplectic Euler simulation with dt = [`time_step`]
    /// (half the stability limit with the damping). O(T log T).
    ///
    /// # Errors
    /// [`DemoError::Model`] (a degenerate tet, a bad point), [`DemoError::TimeStep`] (a step
    /// below the normal range of f64), [`DemoError::Sim`].
    pub fn new(points: &[Vec3], tets: &[[u32; 4]], steps: u64) -> Result<Self, DemoError> {
        let (lo, hi) = bounds(points, tets);
        let ext = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
        let long_axis = (0..3).fold(0, |a, k| if ext[k] > ext[a] { k } else { a });
        let up_axis = if long_axis == 2 { 0 } else { 2 };
        let mut gravity = [0.0; 3];
        gravity[up_axis] = -GRAVITY;
        let density = Material::default().density;
        let young = YOUNG_PER_WEIGHT * density * GRAVITY * ext[long_axis];
        let material = Material { density, young, viscosity: VISCOSITY, ..Material::default() };
        let (mut body, _) = Body::from_tets(points, tets, material).map_err(DemoError::Model)?;
        let pin_limit = lo[long_axis] + PIN_FRACTION * ext[long_axis];
        let pins = PinSpec { ids: Vec::new(), below: Some((long_axis, pin_limit)), inside: None };
        body.attrs_mut().pin_where(|id, p| pins.pins(id, p));
        let live = topomech::mechanics::Mechanics::live_vertices(body.map());
        let pinned = body.attrs().pinned().as_slice().iter().zip(&live).filter(|(&p, &l)| p && l).count();
        let probe = Simulation::new(&mut body, gravity, StepConfig::new(Integrator::Symplectic, MAX_DT))
            .map_err(|source| DemoError::Sim { stage: "setup", source })?;
        let dt = time_step(probe.projection.system(), "setup")?;
        let sim = Simulation::new(&mut body, gravity, StepConfig::new(Integrator::Symplectic, dt))
            .map_err(|source| DemoError::Sim { stage: "setup", source })?;
        let config = SceneConfig { steps, dt, long_axis, up_axis, gravity, material, lo, hi, pin_limit, pinned };
        let checker = Checker::new(&body);
        Ok(Scene { body, sim, checker, config, time: 0.0, incision_tets: Vec::new(), plane: None })
    }

    /// Runs `steps` steps, checking and writing a frame every `steps / 10` steps and at the end;
    /// with `tear = Some(threshold)` a [`cut::tear_step`] follows each step (until [`TEAR_MAX`]
    /// vertices are torn) and every tear is checked. O(steps · (springs + slots)) + checks.
    ///
    /// # Errors
    /// [`DemoError::Sim`] on blow-up, [`DemoError::Cut`], or a failed check.
    pub fn simulate(
        &mut self,
        run: &mut StageRun,
        steps: u64,
        tear: Option<f64>,
        out: &mut Output,
        bar: &ProgressBar,
    ) -> Result<(), DemoError> {
        let stage = run.name;
        let every = (steps / 10).max(1);
        for step in 1..=steps {
            let t = Instant::now();
            self.sim.step(&mut self.body).map_err(|source| DemoError::Sim { stage, source })?;
            run.step_us.push(t.elapsed().as_secs_f64() * 1e6);
            self.time += self.config.dt;
            run.steps += 1;
            if let Some(threshold) = tear.filter(|_| run.operations < TEAR_MAX) {
                let t = Instant::now();
                let room = TEAR_PER_STEP.min(TEAR_MAX - run.operations);
                let torn = cut::tear_step(&mut self.body, &mut self.sim, threshold, room)
                    .map_err(|source| DemoError::Cut { stage, source })?;
                run.operation_us += t.elapsed().as_secs_f64() * 1e6;
                // A vertex with no inner face around it has an empty fan: nothing was torn.
                let real = torn.tears.iter().filter(|t| !t.dissociations.is_empty()).count();
                if real > 0 {
                    run.operations += real;
                    run.cut_faces += torn.tears.iter().map(|t| t.dissociations.len()).sum::<usize>();
                    self.checker.check(&self.body, stage, run.steps)?;
                }
            }
            if step % every == 0 || step == steps {
                self.checker.check(&self.body, stage, run.steps)?;
                out.frame(self)?;
            }
            bar.inc(1);
        }
        Ok(())
    }

    /// The incision (see the [module docs](self)): the plane normal to the longest axis at
    /// [`INCISION_AT`] of the extent, cutting the faces whose centroid lies in the top
    /// [`INCISION_DEPTH`] of the body's height near the plane. Checks the result. O(darts) plus
    /// one dissociation per cut face.
    ///
    /// # Errors
    /// [`DemoError::Cut`], [`DemoError::Sim`], a failed check.
    pub fn incise(&mut self, run: &mut StageRun) -> Result<(), DemoError> {
        let stage = run.name;
        let (a, up) = (self.config.long_axis, self.config.up_axis);
        let mut point = [0.0; 3];
        point[a] = self.config.lo[a] + INCISION_AT * self.config.extent();
        let mut normal = [0.0; 3];
        normal[a] = 1.0;
        let plane = Plane { point, normal };
        let t = Instant::now();
        let faces = self.incision_faces(&plane, a, up).map_err(|source| DemoError::Cut { stage, source })?;
        let mut touched = TouchedCells::default();
        for d in faces {
            let map = self.body.map();
            let pair = [map.cell_id(3, d), map.cell_id(3, map.alpha::<3>(d))];
            let dis = cut::dissociate_face(&mut self.body, d).map_err(|source| DemoError::Cut { stage, source })?;
            touched.extend(&dis.touched);
            self.incision_tets.extend(pair);
            run.cut_faces += 1;
        }
        self.incision_tets.sort_unstable();
        self.incision_tets.dedup();
        self.sim.update(&mut self.body, &touched).map_err(|source| DemoError::Sim { stage, source })?;
        run.operation_us += t.elapsed().as_secs_f64() * 1e6;
        run.operations = run.cut_faces;
        self.plane = Some(plane);
        self.checker.check(&self.body, stage, run.steps)?;
        Ok(())
    }

    /// The inner faces across `plane` (tet centroids on opposite sides, as `incise_plane`) whose
    /// centroid is above the cut depth. O(darts).
    fn incision_faces(&self, plane: &Plane, a: usize, up: usize) -> Result<Vec<DartId>, CutError> {
        let (map, x) = (self.body.map(), self.body.attrs().position());
        let near = 0.1 * self.config.extent();
        let (mut top, mut bottom) = (f64::NEG_INFINITY, f64::INFINITY);
        for d in map.one_dart_per_cell(0) {
            let p = x[map.vertex_id(d)];
            if (p[a] - plane.point[a]).abs() <= near {
                top = top.max(p[up]);
                bottom = bottom.min(p[up]);
            }
        }
        let depth = top - INCISION_DEPTH * (top - bottom);
        let side = cut::tet_sides(&self.body, plane)?;
        Ok(map
            .one_dart_per_cell(2)
            .into_iter()
            .filter(|&d| {
                let other = map.alpha::<3>(d);
                other != d
                    && side[map.cell_id(3, d).index()] != side[map.cell_id(3, other).index()]
                    && self.face_centroid(d)[up] >= depth
            })
            .collect())
    }

    /// Mean current position of the vertices of the face of `d`. O(face).
    pub fn face_centroid(&self, d: DartId) -> Vec3 {
        let map = self.body.map();
        let mut ids: Vec<CellId> = map.orbit(d, AlphaMask::of(&[0, 1])).into_iter().map(|x| map.vertex_id(x)).collect();
        ids.sort_unstable();
        ids.dedup();
        centroid_of(ids.iter().map(|&v| self.body.attrs().position()[v]))
    }

    /// The tear threshold: [`TEAR_FRACTION`] of the largest vertex stress now. O(springs + slots).
    ///
    /// # Errors
    /// [`DemoError::Sim`] if the simulation does not follow the body (a bug of the demo).
    pub fn tear_threshold(&self) -> Result<f64, DemoError> {
        let stress =
            cut::principal_stress(&self.body, &self.sim).map_err(|source| DemoError::Sim { stage: "tear", source })?;
        Ok(TEAR_FRACTION * stress.iter().map(|s| s.magnitude).fold(0.0, topomech::mesh::nan_max))
    }

    /// Removes the tets whose centroid (current positions) lies within [`REMOVAL_RADIUS`] of the
    /// extent from the free tip (the live vertex farthest along the longest axis), records the
    /// mass and stiffness that left, lets the simulation follow and checks. O(darts) per removal.
    ///
    /// # Errors
    /// [`DemoError::Cut`], [`DemoError::Sim`], a failed check.
    pub fn remove_ball(&mut self, run: &mut StageRun) -> Result<(), DemoError> {
        let stage = run.name;
        let t = Instant::now();
        let mut victims = self.tets_in_ball(self.free_tip(), REMOVAL_RADIUS * self.config.extent());
        // Never the whole body (a mesh of a few tets, or points far from its tets): the stages
        // after this one need tissue, so the victim farthest from the tip stays.
        if victims.len() == self.body.map().count_cells().0[3] {
            if let Some(k) = (0..victims.len()).max_by(|&a, &b| victims[a].1.total_cmp(&victims[b].1)) {
                victims.remove(k);
            }
        }
        let mut touched = TouchedCells::default();
        for (id, _) in victims {
            let r = cut::remove_volume(&mut self.body, id).map_err(|source| DemoError::Cut { stage, source })?;
            self.checker.removed(r.removed_mass, r.removed_stiffness);
            run.cut_faces += r.dissociations.len();
            run.operations += 1;
            touched.extend(&r.touched);
        }
        self.incision_tets.retain(|&t| topomech::cut::volume_dart(&self.body, t).is_some());
        self.sim.update(&mut self.body, &touched).map_err(|source| DemoError::Sim { stage, source })?;
        run.operation_us += t.elapsed().as_secs_f64() * 1e6;
        self.checker.check(&self.body, stage, run.steps)?;
        Ok(())
    }

    /// Current position of the live vertex farthest along the longest axis. O(darts).
    fn free_tip(&self) -> Vec3 {
        let (map, x) = (self.body.map(), self.body.attrs().position());
        let a = self.config.long_axis;
        map.one_dart_per_cell(0).into_iter().map(|d| x[map.vertex_id(d)]).fold(self.config.lo, |best, p| {
            if p[a] > best[a] {
                p
            } else {
                best
            }
        })
    }

    /// Volume ids whose centroid (current positions) is within `r` of `c`, with the distance, by
    /// id. O(darts).
    fn tets_in_ball(&self, c: Vec3, r: f64) -> Vec<(CellId, f64)> {
        let (map, x) = (self.body.map(), self.body.attrs().position());
        let mut out = Vec::new();
        for d in map.one_dart_per_cell(3) {
            let mut ids: Vec<CellId> = map.cell_darts(3, d).into_iter().map(|y| map.vertex_id(y)).collect();
            ids.sort_unstable();
            ids.dedup();
            let g = centroid_of(ids.iter().map(|&v| x[v]));
            let dist = topomech::mesh::distance(g, c);
            if dist <= r {
                out.push((map.cell_id(3, d), dist));
            }
        }
        out.sort_unstable_by_key(|&(id, _)| id);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tets in a ball are those whose corner mean lies within its radius, with that distance
    /// (against a brute-force pass over the input tets; at rest, positions are the input points).
    #[test]
    fn tets_in_ball_are_the_tets_whose_centroid_is_inside() {
        let (points, tets) = topomech::generate::kuhn_cube(3);
        let scene = Scene::new(&points, &tets, 1).unwrap();
        // Radii off the lattice of centroid distances (multiples of 1/12 per coordinate), so that
        // no distance is within rounding of a radius.
        for (c, r) in [([0.5; 3], 0.3137), ([0.0; 3], 0.5071), ([1.0, 0.2, 0.7], 0.4523), ([9.0; 3], 1.0)] {
            let mut expected: Vec<f64> = tets
                .iter()
                .map(|t| topomech::mesh::distance(topomech::mesh::centroid(&t.map(|v| points[v as usize])), c))
                .filter(|&d| d <= r)
                .collect();
            let mut got: Vec<f64> = scene.tets_in_ball(c, r).into_iter().map(|(_, d)| d).collect();
            expected.sort_by(f64::total_cmp);
            got.sort_by(f64::total_cmp);
            assert_eq!(got.len(), expected.len(), "ball {c:?}, {r}");
            assert!(got.iter().zip(&expected).all(|(a, b)| (a - b).abs() < 1e-12), "ball {c:?}, {r}: {got:?}");
        }
    }

    /// A face's centroid is the mean of its three corners.
    #[test]
    fn face_centroid_is_the_mean_of_the_corners() {
        let (points, tets) = topomech::generate::kuhn_cube(1);
        let scene = Scene::new(&points, &tets, 1).unwrap();
        let map = scene.body.map();
        for d in map.one_dart_per_cell(2) {
            let mut ids: Vec<CellId> =
                map.orbit(d, AlphaMask::of(&[0, 1])).into_iter().map(|x| map.vertex_id(x)).collect();
            ids.sort_unstable();
            ids.dedup();
            assert_eq!(ids.len(), 3);
            let x = scene.body.attrs().position();
            let mean = [0, 1, 2].map(|k| ids.iter().map(|&v| x[v][k]).sum::<f64>() / 3.0);
            let got = scene.face_centroid(d);
            assert!((0..3).all(|k| (got[k] - mean[k]).abs() < 1e-15), "{got:?} vs {mean:?}");
        }
    }
}
