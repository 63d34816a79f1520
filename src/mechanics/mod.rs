//! A mass/spring model embedded in a 3-G-map (seed 000 §3–§5).
//!
//! - [`model`]: the mechanical embeddings keyed by cell id, their laws, and the split/merge rules
//!   that keep them lawful under [`Body::unsew3`] / [`Body::sew3`];
//! - [`conservation`]: [`check_conservation`], the laws recomputed from the map's orbits;
//! - [`force`]: forces on flat arrays ([`SpringSystem`]) and their two-pass, thread-deterministic
//!   evaluation;
//! - [`integrate`]: explicit/symplectic Euler, RK4, implicit Euler with matrix-free CG, blow-up
//!   detection;
//! - [`projection`]: the indexed projection of a body (seed §5.2) and the orbit-walk reference;
//! - [`flat`]: the same model built from the tet list without a map (oracle and baseline).
//! - [`simd`]: [`Kernel`], the run-time choice of instruction set (SSE2, AVX2, AVX-512) for the
//!   hot loops, all giving the same bits.
//!
//! [`Simulation`] ties a body, its projection and a stepper together. `docs/MECHANICS.md` states
//! every law with its formula and where the code checks it.

pub mod conservation;
pub mod flat;
pub mod force;
pub(crate) mod geom;
pub mod integrate;
pub mod model;
pub mod projection;
pub mod simd;

pub use conservation::{check_conservation, conservation_violations, ConservationError};
pub use flat::FlatModel;
pub use force::{IncidenceError, ModeBounds, SpringSystem, SystemError};
pub use geom::Vec3;
pub use integrate::{Integrator, StepConfig, StepError, Stepper};
pub use model::{AttrsMut, Body, BodyError, Material, Mechanics, ModelError};
pub use projection::{forces_by_coverage, Projection, ProjectionMismatch, TouchedCells};
pub use simd::Kernel;

use crate::CellId;
use std::borrow::Cow;

/// Errors of a map-driven simulation.
///
/// # Examples
///
/// ```
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Integrator, Material, SimError, Simulation, StepConfig, StepError};
///
/// let (points, tets) = kuhn_cube(1);
/// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let err = Simulation::new(&mut body, [0.0; 3], StepConfig::new(Integrator::Euler, 0.0)).unwrap_err();
/// assert!(matches!(err, SimError::Step(StepError::BadTimeStep(dt)) if dt == 0.0));
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    /// A step failed; for a body, the slot is the vertex id.
    #[error(transparent)]
    Step(#[from] StepError),
    /// A gravity vector with a NaN or infinite component.
    #[error("gravity {0:?} must be finite")]
    BadGravity(Vec3),
    /// The body cannot be projected ([`SystemError::Attributes`]).
    #[error(transparent)]
    Projection(SystemError),
    /// The simulation was built for another body ([`crate::mechanics::Body::identity`]): its
    /// arrays describe that body's vertices and springs. Rebuild it for this one.
    #[error("the simulation was built for body {built_for}, not for body {given}: rebuild it for this body")]
    OtherBody {
        /// The identity of the body it was built for.
        built_for: u64,
        /// The identity of the body given.
        given: u64,
    },
    /// The simulation's projection does not describe this body: the public `projection` was
    /// rebuilt for another body (or, before round 27, the attributes were replaced whole).
    /// Rebuild the simulation ([`Simulation::rebuild`]).
    #[error("the simulation's projection no longer describes body {body} (its attributes were replaced, or the projection was rebuilt for another body): rebuild the simulation")]
    ProjectionNotForBody {
        /// The identity of the body given.
        body: u64,
    },
    /// The body changed topologically since the projection was built.
    #[error("the projection was built at body version {built} but the body is at version {now}: rebuild it")]
    StaleProjection {
        /// Version of the projection.
        built: u64,
        /// Version of the body.
        now: u64,
    },
}

/// Which vertices to fix, by rest position or id. The fields are public, so a spec can hold what
/// pins nothing by mistake (an axis past 2, a NaN bound, an empty box): [`PinSpec::check`]
/// refuses those, and [`PinSpec::pins`] never panics on them.
///
/// # Examples
///
/// ```
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::PinSpec;
/// use topomech::CellId;
///
/// let (points, _) = kuhn_cube(1);
/// let box_pins = PinSpec { inside: Some(([0.0; 3], [1.0, 1.0, 0.0])), ..Default::default() };
/// let fixed: Vec<u32> = (0..8).filter(|&v| box_pins.pins(CellId(v), points[v as usize])).collect();
/// assert_eq!(fixed, vec![0, 1, 2, 3]); // the bottom face, bounds included
/// assert!(PinSpec::default().ids.is_empty() && !PinSpec::default().pins(CellId(0), [0.0; 3]));
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PinSpec {
    /// Vertex ids (points of the input mesh for a fresh body).
    pub ids: Vec<u32>,
    /// Fix vertices whose rest coordinate `axis` (0 = x, 1 = y, 2 = z) is ≤ the value.
    pub below: Option<(usize, f64)>,
    /// Fix vertices inside the axis-aligned box (min, max), bounds included.
    pub inside: Option<(Vec3, Vec3)>,
}

/// Why a [`PinSpec`] would silently pin nothing by its `below` or `inside` part
/// ([`PinSpec::check`]).
///
/// # Examples
///
/// ```
/// use topomech::mechanics::{PinSpec, PinSpecError};
///
/// let spec = PinSpec { below: Some((3, 0.0)), ..Default::default() };
/// assert_eq!(spec.check(), Err(PinSpecError::BadAxis { axis: 3 }));
/// assert_eq!(spec.check().unwrap_err().to_string(), "pin axis 3 is not 0 (x), 1 (y) or 2 (z)");
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PinSpecError {
    /// `below` names an axis past 2.
    #[error("pin axis {axis} is not 0 (x), 1 (y) or 2 (z)")]
    BadAxis {
        /// The axis given.
        axis: usize,
    },
    /// `below` has a NaN bound: no coordinate compares ≤ it.
    #[error("pin bound on axis {axis} is NaN: no vertex would compare below it")]
    NanBound {
        /// The axis given.
        axis: usize,
    },
    /// `inside` has a NaN coordinate in a corner: no coordinate compares inside it.
    #[error("pin box ({min:?}, {max:?}) has a NaN corner coordinate on axis {axis}: no vertex would be inside it")]
    NanCorner {
        /// The first axis with a NaN.
        axis: usize,
        /// The box's min corner.
        min: Vec3,
        /// The box's max corner.
        max: Vec3,
    },
    /// `inside` is empty: its min is above its max on an axis.
    #[error("pin box is empty on axis {axis}: min {min} > max {max}")]
    EmptyBox {
        /// The first such axis.
        axis: usize,
        /// The min corner's coordinate on it.
        min: f64,
        /// The max corner's coordinate on it.
        max: f64,
    },
}

impl PinSpec {
    /// Whether vertex `id` at rest position `p` is fixed. Never panics: a `below` axis past 2
    /// pins nothing, and so do a NaN bound or a box with a NaN corner or min > max on some axis
    /// ([`PinSpec::check`] refuses all of them). O(ids).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::PinSpec;
    /// use topomech::CellId;
    ///
    /// let pins = PinSpec { ids: vec![7], below: Some((2, 0.0)), ..Default::default() };
    /// assert!(pins.pins(CellId(3), [1.0, 1.0, 0.0])); // on the floor
    /// assert!(pins.pins(CellId(7), [1.0, 1.0, 5.0])); // named
    /// assert!(!pins.pins(CellId(3), [1.0, 1.0, 0.5]));
    /// let past = PinSpec { below: Some((3, 0.0)), ..Default::default() };
    /// assert!(!past.pins(CellId(3), [-1.0; 3])); // axis 3: nothing by `below`
    /// ```
    pub fn pins(&self, id: CellId, p: Vec3) -> bool {
        let below = self.below.is_some_and(|(axis, value)| p.get(axis).is_some_and(|&c| c <= value));
        let inside = self.inside.is_some_and(|(lo, hi)| (0..3).all(|k| lo[k] <= p[k] && p[k] <= hi[k]));
        below || inside || self.ids.contains(&id.0)
    }

    /// Refuses a spec whose `below` or `inside` part would silently pin nothing: an axis past 2,
    /// a NaN bound, a box with a NaN corner coordinate or with min > max on some axis (the first
    /// such axis is named). Infinite bounds are taken (−∞ pins nothing by that part, +∞
    /// everything); ids are not checked. O(1).
    ///
    /// # Errors
    /// [`PinSpecError`] naming the axis and values at fault.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::{PinSpec, PinSpecError};
    ///
    /// let nan = PinSpec { below: Some((2, f64::NAN)), ..Default::default() };
    /// assert_eq!(nan.check(), Err(PinSpecError::NanBound { axis: 2 }));
    /// let inverted = PinSpec { inside: Some(([0.0; 3], [1.0, -1.0, 1.0])), ..Default::default() };
    /// assert_eq!(inverted.check(), Err(PinSpecError::EmptyBox { axis: 1, min: 0.0, max: -1.0 }));
    /// assert!(PinSpec { below: Some((0, 0.5)), ..Default::default() }.check().is_ok());
    /// ```
    pub fn check(&self) -> Result<(), PinSpecError> {
        if let Some((axis, value)) = self.below {
            if axis > 2 {
                return Err(PinSpecError::BadAxis { axis });
            }
            if value.is_nan() {
                return Err(PinSpecError::NanBound { axis });
            }
        }
        let Some((min, max)) = self.inside else { return Ok(()) };
        if let Some(axis) = (0..3).find(|&k| min[k].is_nan() || max[k].is_nan()) {
            return Err(PinSpecError::NanCorner { axis, min, max });
        }
        match (0..3).find(|&k| min[k] > max[k]) {
            Some(axis) => Err(PinSpecError::EmptyBox { axis, min: min[axis], max: max[axis] }),
            None => Ok(()),
        }
    }
}

/// A map-driven simulation: the projection of a body and a stepper that advances the body's own
/// position and velocity embeddings.
///
/// # Examples
///
/// ```
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Integrator, Material, Simulation, StepConfig};
///
/// let (points, tets) = kuhn_cube(1);
/// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let mut sim = Simulation::new(&mut body, [0.0, 0.0, -9.81], StepConfig::new(Integrator::Symplectic, 1e-3)).unwrap();
/// (0..10).for_each(|_| sim.step(&mut body).unwrap());
/// assert_eq!(sim.stepper.steps_done(), 10);
/// assert!(sim.projection.is_current(&body));
/// assert!(body.attrs().position().as_slice().iter().all(|p| p[2] < 1.0 + 1e-12)); // falling
/// ```
#[derive(Clone, Debug)]
pub struct Simulation {
    /// The indexed projection the step loop runs on.
    pub projection: Projection,
    /// The integrator and its buffers.
    pub stepper: Stepper,
    /// The body's velocity epoch (`Mechanics::velocity_epoch`) at which the pinned velocities
    /// were last zeroed and the runaway test's energy scale last taken.
    velocity_epoch: u64,
    /// The body's position epoch (`Mechanics::position_epoch`) at which the energy scale was
    /// last taken.
    position_epoch: u64,
    /// The identity of the body the simulation was made for ([`Simulation::new`],
    /// [`Simulation::rebuild`]): the public `projection` rebuilt for another body does not move
    /// the simulation over to it (round 26: the stepper kept its step count and the other body's
    /// pinned velocity moved its pinned vertex).
    body: u64,
}

/// Puts slot `v` at the origin at rest when it is a dead vertex id (no dart: no cell reads it)
/// holding a non-finite position or velocity, so that a value left in a slot no vertex uses
/// neither blocks the step's checks nor spreads (finding 257). O(1).
fn blank_dead(projection: &Projection, v: usize, position: &mut Vec3, velocity: &mut Vec3) {
    if dead_and_not_finite(projection, v, *position, *velocity) {
        (*position, *velocity) = ([0.0; 3], [0.0; 3]);
    }
}

/// Whether slot `v` is a dead vertex id holding a non-finite position or velocity. O(1).
fn dead_and_not_finite(projection: &Projection, v: usize, position: Vec3, velocity: Vec3) -> bool {
    !position.iter().chain(&velocity).all(|c| c.is_finite()) && projection.dart_of_vertex(v).is_none()
}

/// The positions and velocities of the projection's slots as the stepper will start from them:
/// the body's own, borrowed, unless a dead slot holds a non-finite value; then a copy with the
/// dead slots blanked as [`blank_dead`] blanks them in the body once the start is accepted (a
/// refused start leaves the body unchanged). O(slots).
fn start_state<'a>(projection: &Projection, mech: &'a Mechanics) -> (Cow<'a, [Vec3]>, Cow<'a, [Vec3]>) {
    let slots = projection.system.slots();
    let (x, v) = (&mech.position.as_slice()[..slots], &mech.velocity.as_slice()[..slots]);
    if !(0..slots).any(|k| dead_and_not_finite(projection, k, x[k], v[k])) {
        return (Cow::Borrowed(x), Cow::Borrowed(v));
    }
    let (mut x, mut v) = (x.to_vec(), v.to_vec());
    for (k, (p, w)) in x.iter_mut().zip(&mut v).enumerate() {
        blank_dead(projection, k, p, w);
    }
    (Cow::Owned(x), Cow::Owned(v))
}

impl Simulation {
    /// Projects `body` (gravity `gravity`) and prepares `config`'s integrator. Pinned vertices get
    /// zero velocity. O(darts + E log E).
    ///
    /// # Errors
    /// [`SimError::BadGravity`]; the errors of [`Stepper::new`] ([`StepError::BadTimeStep`], a
    /// bad parameter or input). On an error the body is unchanged.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Integrator, Material, Simulation, StepConfig};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// body.attrs_mut().velocity_mut().as_mut_slice()[0] = [1.0, 0.0, 0.0];
    /// body.attrs_mut().pinned_mut().as_mut_slice()[0] = true;
    /// let sim = Simulation::new(&mut body, [0.0; 3], StepConfig::new(Integrator::Rk4, 1e-3)).unwrap();
    /// assert_eq!(body.attrs().velocity().as_slice()[0], [0.0; 3]); // a pinned vertex starts still
    /// assert_eq!(sim.projection.system().springs(), 19); // one spring per edge
    /// assert!(Simulation::new(&mut body, [0.0; 3], StepConfig::new(Integrator::Rk4, -1.0)).is_err());
    /// ```
    pub fn new(body: &mut Body, gravity: Vec3, config: StepConfig) -> Result<Self, SimError> {
        if gravity.iter().any(|g| !g.is_finite()) {
            return Err(SimError::BadGravity(gravity));
        }
        body.attrs().check_covers(body.map()).map_err(|e| SimError::Projection(SystemError::Attributes(e)))?;
        let projection = Projection::build_raw(body, gravity);
        // Checked before any change (the energy scale counts free slots only, so the pinned
        // velocities zeroed below do not enter it; dead slots are checked as they will be).
        let (x, v) = start_state(&projection, body.attrs());
        let stepper = Stepper::new(config, &projection.system, &x, &v)?;
        let mut sim = Simulation { projection, stepper, velocity_epoch: 0, position_epoch: 0, body: body.identity() };
        sim.hold_fixed(body);
        sim.record_epochs(body);
        Ok(sim)
    }

    /// Zeroes the velocity of every fixed slot — pinned vertices (the law "a pinned vertex does
    /// not move") and dead vertex ids — as [`Simulation::update`] does, and puts a dead id with a
    /// non-finite position at the origin ([`blank_dead`]). O(vertex ids).
    fn hold_fixed(&self, body: &mut Body) {
        self.hold_fixed_among(body, (0..self.projection.system.slots()).map(|v| CellId(v as u32)));
    }

    /// [`Simulation::hold_fixed`] for the vertex ids `ids` only. O(|ids|).
    fn hold_fixed_among(&self, body: &mut Body, ids: impl Iterator<Item = CellId>) {
        let mech = body.attrs_raw_mut();
        let (position, velocity) = (mech.position.as_mut_slice(), mech.velocity.as_mut_slice());
        for v in ids.map(CellId::index) {
            if self.projection.system.inv_mass[v] == 0.0 {
                velocity[v] = [0.0; 3];
            }
            blank_dead(&self.projection, v, &mut position[v], &mut velocity[v]);
        }
    }

    /// Records the body's velocity and position epochs: what was written so far is taken up.
    fn record_epochs(&mut self, body: &Body) {
        self.velocity_epoch = body.attrs().velocity_epoch;
        self.position_epoch = body.attrs().position_epoch;
    }

    /// [`Simulation::check_current`], after taking up what was written into the body's pins or
    /// velocities since the last step: pins handed out for writing are re-read into the
    /// projection's fixed slots, and the fixed slots' velocities are zeroed again. O(1) when
    /// nothing was handed out, else O(vertex ids).
    ///
    /// # Errors
    /// As [`Simulation::check_current`] (another body: nothing is taken up), and the energy
    /// scale's refusal of the start state (a NaN or overflowing position or velocity): the
    /// projection's pins are put back, so the simulation is as it was.
    fn follow_writes(&mut self, body: &mut Body) -> Result<(), SimError> {
        self.check_current(body)?;
        let pins_changed = !self.projection.pins_current(body);
        let before = pins_changed.then(|| self.projection.pin_snapshot());
        if pins_changed {
            self.projection.follow_pins(body);
        }
        let mech = body.attrs();
        let written = mech.velocity_epoch != self.velocity_epoch || mech.position_epoch != self.position_epoch;
        if pins_changed || written || !self.stepper.has_energy_scale() {
            // Energy put in by hand is a new start, not a blow-up (and a body started at rest
            // would otherwise keep a stale scale). Taken before the pinned velocities are
            // zeroed (it counts free slots only), so that on an error the body is unchanged and
            // the epochs stay unrecorded: the next call checks again. The pins just followed
            // are put back then too, so a refused call leaves the simulation as it was
            // (finding 203).
            let (x, v) = start_state(&self.projection, mech);
            if let Err(e) = self.stepper.reset_energy_scale(&self.projection.system, &x, &v) {
                if let Some(before) = before {
                    self.projection.restore_pins(before);
                }
                return Err(e.into());
            }
            self.hold_fixed(body);
            self.record_epochs(body);
        }
        Ok(())
    }

    /// [`SimError::OtherBody`] unless the simulation was built for `body` and its projection
    /// still is (the `projection` field is public). O(1).
    pub(crate) fn check_body(&self, body: &Body) -> Result<(), SimError> {
        let given = body.identity();
        match (self.body == given, self.projection.is_for(body)) {
            (true, true) => Ok(()),
            (false, _) => Err(SimError::OtherBody { built_for: self.body, given }),
            (true, false) => Err(SimError::ProjectionNotForBody { body: given }),
        }
    }

    /// [`Simulation::check_body`], then [`SimError::StaleProjection`] unless the projection
    /// follows the body's topology (its slots, masses and springs are the body's now). Pins and
    /// velocities written since are not a staleness: the mutating entries take them up
    /// ([`Simulation::step`], [`Simulation::write_forces`], [`Simulation::update`]) and the
    /// read-outs read the body's own pins. O(1).
    pub(crate) fn check_current(&self, body: &Body) -> Result<(), SimError> {
        self.check_body(body)?;
        match self.projection.version() == body.version() {
            true => Ok(()),
            false => Err(SimError::StaleProjection { built: self.projection.version(), now: body.version() }),
        }
    }

    /// One step on the body's positions and velocities. O(springs + vertex ids).
    ///
    /// Pins and velocities written since the last step are taken up first: a vertex pinned
    /// (or unpinned) through [`Mechanics::pinned_mut`] or [`Mechanics::pin_where`] is fixed (or
    /// free) from this step on, and a pinned vertex given a velocity through
    /// [`Mechanics::velocity_mut`] has it zeroed: pinned vertices do not move.
    ///
    /// # Errors
    /// [`SimError::OtherBody`] if the simulation was built for another body (nothing moves);
    /// [`SimError::StaleProjection`] if the body changed topologically (call
    /// [`Simulation::rebuild`]); [`SimError::Step`] on blow-up (the slot is the vertex id; the
    /// body then holds the step's bad values, for inspection, as [`Stepper::step`] says: a new
    /// simulation on it starts from them — put back a saved state or positions first).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Integrator, Material, Simulation, StepConfig};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// body.attrs_mut().pin_where(|_, rest| rest[2] == 0.0); // hold the bottom face
    /// let config = StepConfig::new(Integrator::Symplectic, 1e-3);
    /// let mut sim = Simulation::new(&mut body, [0.0, 0.0, -9.81], config).unwrap();
    /// for _ in 0..50 {
    ///     sim.step(&mut body).unwrap();
    /// }
    /// let m = body.attrs();
    /// let z = |v: usize| m.position().as_slice()[v][2];
    /// assert!(z(7) < 1.0 && z(0) == 0.0); // the top corner sags, the pinned one stays
    /// assert!(sim.kinetic_energy(&body).unwrap() > 0.0 && sim.max_displacement(&body).unwrap() > 0.0);
    /// ```
    pub fn step(&mut self, body: &mut Body) -> Result<(), SimError> {
        self.follow_writes(body)?;
        let slots = self.projection.system.slots();
        let mech = body.attrs_raw_mut();
        let x = &mut mech.position.as_mut_slice()[..slots];
        let v = &mut mech.velocity.as_mut_slice()[..slots];
        self.stepper.step(&self.projection.system, x, v)?;
        Ok(())
    }

    /// Rebuilds the projection from the body after topological changes and fits the stepper's
    /// buffers to it, keeping the configuration, the step count and the runaway test's energy
    /// scale as [`Simulation::update`] does (pins, positions or velocities written since the
    /// last step make the next step take the scale again). Fixed slots get zero velocity.
    /// A simulation built for another body adopts `body` instead: it becomes
    /// [`Simulation::new`] of `body` with this gravity and configuration (the step count
    /// starts again, the scale is `body`'s). O(darts + E log E).
    ///
    /// # Errors
    /// For another body, as [`Simulation::new`]; for its own body, in checked builds (debug,
    /// `expensive-checks`) [`StepError::BadInput`] for a projection the stepper cannot take (a
    /// bug). Nothing changes on an error.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::cut::dissociate_face;
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Integrator, Material, SimError, Simulation, StepConfig};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let mut sim = Simulation::new(&mut body, [0.0; 3], StepConfig::new(Integrator::Euler, 1e-3)).unwrap();
    /// let d = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
    /// dissociate_face(&mut body, d).unwrap();
    /// assert!(matches!(sim.step(&mut body), Err(SimError::StaleProjection { .. })));
    /// sim.rebuild(&mut body).unwrap();
    /// sim.step(&mut body).unwrap();
    /// ```
    pub fn rebuild(&mut self, body: &mut Body) -> Result<(), SimError> {
        if self.check_body(body).is_err() {
            let config = *self.stepper.config();
            *self = Simulation::new(body, self.projection.system.gravity, config)?;
            return Ok(());
        }
        let pins_written = !self.projection.pins_current(body);
        let projection = Projection::build_raw(body, self.projection.system.gravity);
        self.stepper.follow_system(&projection.system)?;
        self.projection = projection;
        self.hold_fixed(body);
        if pins_written {
            self.stepper.forget_energy_scale();
        }
        Ok(())
    }

    /// Follows topological changes incrementally ([`Projection::update`] with `touched`) and fits
    /// the stepper's buffers to the new system in place. The step count goes on, and the runaway
    /// test keeps its energy scale: a cut, a tear or a removal puts no energy in (a split vertex's
    /// two sides share its velocity and its mass, m = m₁ + m₂, so the kinetic energy is
    /// unchanged; a removal only takes energy out), so a blow-up that runs on while the body is
    /// cut is still caught and named by its step since the start (finding 177). Pins handed out
    /// for writing since the last step are new energy put in by hand, as in
    /// [`Simulation::step`]: the scale is taken again at the next step then. Fixed slots (pinned,
    /// dead) get zero velocity, among the touched vertices and the new ids. It reads the
    /// topology, masses and pins, never the positions or velocities, so no state can make it
    /// fail halfway. O(touched cells · degree + new ids) amortised; O(slots) more when the pins
    /// were handed out for writing, O(darts + E log E) when `touched` cannot be trusted and the
    /// projection is rebuilt ([`Projection::update`]).
    ///
    /// # Errors
    /// [`SimError::OtherBody`] if the simulation was built for another body (nothing changes);
    /// otherwise only a system the stepper cannot take ([`StepError::BadInput`]: a bug).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::cut::dissociate_face;
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Integrator, Material, Projection, Simulation, StepConfig};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let mut sim = Simulation::new(&mut body, [0.0; 3], StepConfig::new(Integrator::Euler, 1e-3)).unwrap();
    /// let d = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
    /// let cut = dissociate_face(&mut body, d).unwrap();
    /// sim.update(&mut body, &cut.touched).unwrap(); // incremental: only the touched cells
    /// assert!(sim.projection.is_current(&body));
    /// assert!(sim.projection.equivalent(&Projection::build(&body, [0.0; 3]).unwrap()).is_ok()); // = a fresh build
    /// sim.step(&mut body).unwrap();
    /// ```
    pub fn update(&mut self, body: &mut Body, touched: &TouchedCells) -> Result<(), SimError> {
        self.check_body(body)?;
        let (slots_before, pins_written) = (self.projection.system.slots(), !self.projection.pins_current(body));
        let incremental = self.projection.update(body, touched);
        self.stepper.follow_system(&self.projection.system)?;
        if !incremental || pins_written {
            self.hold_fixed(body);
            if pins_written {
                self.stepper.forget_energy_scale();
            }
            return Ok(());
        }
        let new_ids = (slots_before..self.projection.system.slots()).map(|v| CellId(v as u32));
        let touched_ids = touched.vertices.iter().map(|&(v, _)| v);
        self.hold_fixed_among(body, touched_ids.chain(new_ids));
        Ok(())
    }

    /// Kinetic energy of the body's free vertices. O(vertex ids).
    ///
    /// # Errors
    /// [`SimError::OtherBody`] for a body the simulation was not built for, and
    /// [`SimError::StaleProjection`] after a topological change (its masses are not the body's
    /// any more): the energy would be a sum over another set of vertices.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Integrator, Material, Simulation, StepConfig};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// body.attrs_mut().velocity_mut().as_mut_slice().fill([0.0, 3.0, 0.0]);
    /// let sim = Simulation::new(&mut body, [0.0; 3], StepConfig::new(Integrator::Euler, 1e-3)).unwrap();
    /// assert!((sim.kinetic_energy(&body).unwrap() - 0.5 * 1.0 * 9.0).abs() < 1e-12); // ½ M v², M = 1
    /// assert!((sim.kinetic_energy(&body).unwrap() - body.kinetic_energy()).abs() < 1e-12);
    /// let (other, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// assert!(sim.kinetic_energy(&other).is_err()); // not the body it was built for
    /// ```
    pub fn kinetic_energy(&self, body: &Body) -> Result<f64, SimError> {
        self.check_current(body)?;
        let (sys, mech) = (&self.projection.system, body.attrs());
        let (pinned, v) = (mech.pinned.as_slice(), mech.velocity.as_slice());
        // Free = live (mass > 0) and not pinned, by the body's pins now (a pin written since the
        // last step counts already). `fold` from +0: no free vertex gives +0, not −0.
        Ok((0..sys.slots())
            .filter(|&i| sys.mass[i] > 0.0 && !pinned[i])
            .map(|i| 0.5 * sys.mass[i] * geom::dot(v[i], v[i]))
            .fold(0.0, |sum, e| sum + e))
    }

    /// Largest distance of a live vertex from its rest position; NaN if a live vertex's position
    /// is NaN (as [`Simulation::kinetic_energy`] is NaN for a NaN velocity: a lost state is never
    /// reported as "no movement"). O(vertex ids).
    ///
    /// # Errors
    /// As [`Simulation::kinetic_energy`]: another body, or a stale projection.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Integrator, Material, Simulation, StepConfig};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let sim = Simulation::new(&mut body, [0.0; 3], StepConfig::new(Integrator::Euler, 1e-3)).unwrap();
    /// assert_eq!(sim.max_displacement(&body), Ok(0.0));
    /// body.attrs_mut().position_mut().as_mut_slice()[5] = [1.0, 0.0, 1.25]; // vertex 5 rests at (1, 0, 1)
    /// assert_eq!(sim.max_displacement(&body), Ok(0.25));
    /// ```
    pub fn max_displacement(&self, body: &Body) -> Result<f64, SimError> {
        self.check_current(body)?;
        let m = body.attrs();
        Ok((0..self.projection.system.slots())
            .filter(|&v| self.projection.dart_of_vertex(v).is_some())
            .map(|v| geom::norm(geom::sub(m.position.as_slice()[v], m.rest_position.as_slice()[v])))
            .fold(0.0, crate::mesh::nan_max))
    }

    /// Evaluates the forces on every vertex at the body's current positions and velocities
    /// (springs with damping, gravity, ambient viscosity; pinned vertices get theirs too: the
    /// reaction their pin holds) and writes them into the body's force accumulator
    /// ([`Mechanics::force`]); dead vertex ids get zero. The step loop keeps its sums in its own
    /// buffers and does not write the accumulator (a pass fewer per step): call this when the
    /// forces are wanted. Pins and velocities written since the last step are taken up first, as
    /// in [`Simulation::step`]. O(springs + vertex ids).
    ///
    /// # Errors
    /// As [`Simulation::step`]: another body, or a stale projection (nothing is written).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Integrator, Material, Simulation, StepConfig};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let mut sim = Simulation::new(&mut body, [0.0, 0.0, -9.81], StepConfig::new(Integrator::Symplectic, 1e-3)).unwrap();
    /// sim.write_forces(&mut body).unwrap();
    /// let weight: f64 = body.attrs().force().as_slice().iter().map(|f| f[2]).sum(); // at rest: gravity alone
    /// assert!((weight + 9.81 * body.total_vertex_mass()).abs() < 1e-12);
    /// ```
    pub fn write_forces(&mut self, body: &mut Body) -> Result<(), SimError> {
        self.follow_writes(body)?;
        let sys = &self.projection.system;
        let slots = sys.slots();
        let (mut sf, mut out) = (vec![[0.0; 3]; sys.springs()], vec![[0.0; 3]; slots]);
        let mech = body.attrs_raw_mut();
        let (x, v) = (&mech.position.as_slice()[..slots], &mech.velocity.as_slice()[..slots]);
        sys.forces_raw(x, v, &mut sf, &mut out, self.stepper.config().parallel);
        let force = mech.force.as_mut_slice();
        force.fill([0.0; 3]);
        for (v, f) in out.into_iter().enumerate() {
            if self.projection.dart_of_vertex(v).is_some() {
                force[v] = f;
            }
        }
        Ok(())
    }
}
