//! Time integrators over a [`SpringSystem`] and state slices, with blow-up detection.
//!
//! State y = (x, ẋ), ÿ = a(x, ẋ) = M⁻¹ f(x, ẋ) (zero on fixed slots). With step h:
//! - [`Integrator::Euler`] (explicit, order 1): x₁ = x₀ + h ẋ₀, ẋ₁ = ẋ₀ + h a(y₀).
//! - [`Integrator::Symplectic`] (semi-implicit Euler, order 1, symplectic without damping):
//!   ẋ₁ = ẋ₀ + h a(y₀), x₁ = x₀ + h ẋ₁.
//! - [`Integrator::Rk4`] (classic Runge–Kutta, order 4, the seed's scheme).
//! - [`Integrator::Implicit`] (backward Euler linearised once per step, Baraff–Witkin): solve
//!   (M + h(Γ + C) + h² K) Δẋ = h (f₀ − h K ẋ₀) with matrix-free conjugate gradient, where
//!   K = −∂f/∂x and C = −∂f/∂ẋ (spring part) are applied spring by spring and never assembled;
//!   ẋ₁ = ẋ₀ + Δẋ, x₁ = x₀ + h ẋ₁. Each spring's K block is k n nᵀ + k max(0, 1 − L/l)(I − n nᵀ)
//!   (the transverse term clamped at zero under compression so that the system stays SPD).
//!   Unconditionally stable for this linearisation: it runs stiff tissue at large steps.
//!
//! After every step the state is scanned: a NaN or infinite coordinate, or a kinetic energy above
//! [`StepConfig::runaway_factor`] times the energy scale of the start (kinetic plus elastic energy
//! plus M |g| D, with D the diagonal of the bounding box; when that is 0 — at rest in the rest
//! shape without gravity — Σ ½ k L² over the springs, the material's own energy scale), is
//! returned as [`StepError::BlowUp`] naming the step and the slot. The kinetic energy is that of
//! the free slots, as everywhere in this crate: a fixed slot (inverse mass 0) has no
//! acceleration but keeps its velocity, so a fixed slot given a velocity moves at that constant
//! velocity in all four schemes (x₁ = x₀ + h ẋ₀: a kinematically driven pin, a grasped vertex),
//! and being prescribed it is neither part of the runaway test nor named by it (finding 169).
//! A non-finite coordinate of any slot is a blow-up. A start state whose energy
//! scale is not finite is refused. State written between steps is new energy put in by hand:
//! [`Stepper::reset_energy_scale`] takes it as the new start ([`crate::mechanics::Simulation`]
//! does so itself when positions or velocities were handed out for writing).

use std::str::FromStr;
use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

use super::force::{ModeBounds, Rec4, SlotState, SpringSystem, SumPlan, PARALLEL_CHUNK};
use super::geom::{dot, exponent, norm, pow2, sub, Vec3};
use super::simd::{multiversion, Kernel};
use crate::wide::Wide;

/// Radius of a left half-disc {|z| ≤ r, Re z ≤ 0} inside RK4's stability region
/// |1 + z + z²/2 + z³/6 + z⁴/24| ≤ 1 (the largest such radius is about 2.61).
const RK4_HALF_DISC: f64 = 2.6;

/// The time integration scheme.
///
/// # Examples
///
/// ```
/// use topomech::mechanics::Integrator;
///
/// assert_eq!("rk4".parse::<Integrator>(), Ok(Integrator::Rk4));
/// assert_eq!("Semi-Implicit".parse::<Integrator>(), Ok(Integrator::Symplectic)); // alias, any case
/// assert_eq!("backward-euler".parse::<Integrator>(), Ok(Integrator::Implicit));
/// assert_eq!(Integrator::Euler.name(), "euler");
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Integrator {
    /// Explicit (forward) Euler.
    Euler,
    /// Semi-implicit (symplectic) Euler.
    Symplectic,
    /// Classic fourth-order Runge–Kutta.
    Rk4,
    /// Linearised backward Euler with matrix-free conjugate gradient.
    Implicit,
}

impl Integrator {
    /// The CLI name: `euler`, `symplectic`, `rk4`, `implicit`.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::Integrator;
    ///
    /// for scheme in [Integrator::Euler, Integrator::Symplectic, Integrator::Rk4, Integrator::Implicit] {
    ///     assert_eq!(scheme.name().parse::<Integrator>(), Ok(scheme));
    /// }
    /// ```
    pub fn name(self) -> &'static str {
        match self {
            Integrator::Euler => "euler",
            Integrator::Symplectic => "symplectic",
            Integrator::Rk4 => "rk4",
            Integrator::Implicit => "implicit",
        }
    }

    /// The largest time step at which this scheme is stable on every mode the bounds allow (None
    /// for [`Integrator::Implicit`], stable at every step). A mode ẍ + c ẋ + ω² x = 0 (ω ≤ ω_max,
    /// c ≤ c_max; see [`ModeBounds`] and docs/MECHANICS.md, "Time step"):
    /// - symplectic Euler (v₁ = v₀ + h a(x₀, v₀), x₁ = x₀ + h v₁) has the step matrix
    ///   [[1 − h²ω², h(1 − hc)], [−hω², 1 − hc]], trace 2 − h²ω² − hc and determinant 1 − hc; its
    ///   eigenvalues stay in the unit disc iff h²ω² + 2hc ≤ 4, i.e. h ≤ 4 / (c + √(c² + 4ω²)).
    ///   That limit falls as ω or c grows, so the worst corner (ω_max, c_max) bounds every mode:
    ///   2/ω_max undamped, about 2/c_max when damping dominates. Exact for one mode;
    /// - forward Euler needs |1 + hλ| ≤ 1 at both roots λ of λ² + cλ + ω² = 0: h ≤ c/ω² for an
    ///   oscillating mode (c < 2ω) and h ≤ 2/c for an overdamped one; with c = ν + βω²,
    ///   c/ω² ≥ β_min + ν_min/ω_max², so h ≤ min(β_min + ν_min/ω_max², 2/c_max) (0 for an
    ///   undamped system: forward Euler amplifies every undamped oscillation);
    /// - RK4's stability region holds the left half-disc of radius 2.6 (it reaches 2.83 on the
    ///   imaginary axis and 2.79 on the real one), and every root has |λ| ≤ max(ω_max, c_max)
    ///   (|λ| = ω when it oscillates, ≤ c when overdamped): h ≤ 2.6 / max(ω_max, c_max), a
    ///   sufficient bound.
    ///
    /// ∞ when nothing bounds the step (no spring, no damping). Computed without intermediate
    /// overflow (ω_max² may pass `f64::MAX` while the limit is an ordinary number: a needle's
    /// 1e309 gives a step near 1e-306), with the plain formula's bits wherever it stays in range.
    /// So the limit is 0 only for forward Euler with β_min = ν_min = 0 (no damping the bound can
    /// count on: an undamped system) or when the limit itself is below the smallest subnormal,
    /// and it leaves the normal range of f64 only when it is below 2.2e-308 (as it is for
    /// ω_max or c_max = ∞, see [`SpringSystem::mode_bounds`]). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::force::ModeBounds;
    /// use topomech::mechanics::Integrator;
    ///
    /// let undamped = ModeBounds { omega_max: 100.0, damping_max: 0.0, beta_min: 0.0, nu_min: 0.0 };
    /// assert_eq!(Integrator::Symplectic.stable_dt(&undamped), Some(0.02)); // 2/ω_max
    /// assert_eq!(Integrator::Euler.stable_dt(&undamped), Some(0.0)); // unstable at every dt
    /// assert_eq!(Integrator::Implicit.stable_dt(&undamped), None);
    /// // Stiffness-proportional damping β = 0.01 s: c = βω² = 100 at ω_max, and the damping term
    /// // sets the limit, well below 2/ω_max.
    /// let damped = ModeBounds { omega_max: 100.0, damping_max: 100.0, beta_min: 0.01, nu_min: 0.0 };
    /// let h = Integrator::Symplectic.stable_dt(&damped).unwrap();
    /// assert!((h - 4.0 / (100.0 + 50_000f64.sqrt())).abs() < 1e-15 && h < 0.013);
    /// assert_eq!(Integrator::Euler.stable_dt(&damped), Some(0.01)); // β + 0/ω² and 2/c: 0.01, 0.02
    /// ```
    pub fn stable_dt(self, b: &ModeBounds) -> Option<f64> {
        let (w, c) = (b.omega_max, b.damping_max);
        match self {
            Integrator::Symplectic => Some(symplectic_limit(w, c)),
            Integrator::Euler => Some(euler_oscillating_limit(b).min(limit(2.0, c))),
            Integrator::Rk4 => Some(limit(RK4_HALF_DISC, w.max(c))),
            Integrator::Implicit => None,
        }
    }

    /// Half this scheme's stability limit, the working step that the demo and the benchmarks
    /// take: h = ½ [`Integrator::stable_dt`], the implicit scheme at symplectic Euler's (it is
    /// stable at every step, but a step that resolves the stiffest mode keeps it comparable with
    /// the explicit ones). ∞ when nothing bounds the step; 0 or subnormal when the system leaves
    /// no step f64 can take (forward Euler undamped, a needle near 1e-154): callers cap the
    /// first and refuse the second. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::force::ModeBounds;
    /// use topomech::mechanics::Integrator;
    ///
    /// let b = ModeBounds { omega_max: 100.0, damping_max: 0.0, beta_min: 0.0, nu_min: 0.0 };
    /// assert_eq!(Integrator::Symplectic.half_stable_dt(&b), 0.01);
    /// assert_eq!(Integrator::Implicit.half_stable_dt(&b), 0.01);
    /// assert_eq!(Integrator::Euler.half_stable_dt(&b), 0.0);
    /// let free = ModeBounds { omega_max: 0.0, ..b };
    /// assert_eq!(Integrator::Rk4.half_stable_dt(&free), f64::INFINITY);
    /// ```
    pub fn half_stable_dt(self, b: &ModeBounds) -> f64 {
        let scheme = match self {
            Integrator::Implicit => Integrator::Symplectic,
            explicit => explicit,
        };
        0.5 * scheme.stable_dt(b).unwrap_or(f64::INFINITY)
    }
}

/// num / den, ∞ for den = 0 (nothing bounds the step). O(1).
fn limit(num: f64, den: f64) -> f64 {
    if den > 0.0 {
        num / den
    } else {
        f64::INFINITY
    }
}

/// Symplectic Euler's limit 4 / (c + √(c² + 4ω²)): the plain formula (`hypot`, no intermediate
/// overflow) while its denominator is finite, else the same in wide floats (the limit is then
/// below 4/`f64::MAX` and comes out subnormal or 0). O(1).
fn symplectic_limit(w: f64, c: f64) -> f64 {
    let den = c + c.hypot(2.0 * w);
    if den.is_finite() {
        return limit(4.0, den);
    }
    let (two_w, c) = (Wide::new(2.0).mul(Wide::new(w)), Wide::new(c));
    Wide::new(4.0).div(c.add(c.mul(c).add(two_w.mul(two_w)).sqrt())).to_f64()
}

/// Forward Euler's limit on the oscillating modes, β_min + ν_min / ω_max² (∞ for ω_max = 0), in
/// wide floats: ω_max² may pass `f64::MAX` (the plain bits where nothing over- or underflows).
/// O(1).
fn euler_oscillating_limit(b: &ModeBounds) -> f64 {
    if b.omega_max <= 0.0 {
        return f64::INFINITY;
    }
    let w = Wide::new(b.omega_max);
    Wide::new(b.beta_min).add(Wide::new(b.nu_min).div(w.mul(w))).to_f64()
}

/// An integrator name that is not one of the four.
///
/// # Examples
///
/// ```
/// use topomech::mechanics::integrate::UnknownIntegrator;
/// use topomech::mechanics::Integrator;
///
/// let err = "leapfrog".parse::<Integrator>().unwrap_err();
/// assert_eq!(err, UnknownIntegrator("leapfrog".to_string()));
/// assert!(err.to_string().contains("\"leapfrog\"") && err.to_string().contains("rk4"));
/// ```
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown integrator {0:?} (expected euler, symplectic, rk4 or implicit)")]
pub struct UnknownIntegrator(pub String);

impl FromStr for Integrator {
    type Err = UnknownIntegrator;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.to_ascii_lowercase().as_str() {
            "euler" => Ok(Integrator::Euler),
            "symplectic" | "semi-implicit" => Ok(Integrator::Symplectic),
            "rk4" => Ok(Integrator::Rk4),
            "implicit" | "backward-euler" => Ok(Integrator::Implicit),
            _ => Err(UnknownIntegrator(s.to_string())),
        }
    }
}

/// What went wrong in a step.
///
/// # Examples
///
/// ```
/// use topomech::mechanics::{Integrator, SpringSystem, StepConfig, StepError, Stepper};
///
/// let mut sys = SpringSystem::default();
/// sys.push_slot(1.0, false, 0.0).unwrap();
/// let (x, v) = (vec![[0.0; 3]], vec![[0.0; 3]]);
/// let nan = Stepper::new(StepConfig::new(Integrator::Rk4, f64::NAN), &sys, &x, &v);
/// assert!(matches!(nan, Err(StepError::BadTimeStep(dt)) if dt.is_nan()));
/// let short = Stepper::new(StepConfig::new(Integrator::Rk4, 0.1), &sys, &x, &[]);
/// assert!(matches!(short, Err(StepError::SizeMismatch { expected: 1, got: 0 })));
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StepError {
    /// The state became non-finite or its energy ran away; the simulation must stop.
    #[error("simulation blew up at step {step}, vertex slot {slot}: {reason}")]
    BlowUp {
        /// Index of the step that produced the bad state (0-based).
        step: u64,
        /// The vertex slot at fault (for a map-driven simulation, the vertex id).
        slot: usize,
        /// What was found.
        reason: String,
    },
    /// The conjugate gradient of the implicit step did not reach its tolerance.
    #[error("implicit step {step}: conjugate gradient stopped after {iterations} iterations at relative residual {residual:e}")]
    SolverFailed {
        /// Index of the step whose solve failed (0-based, as [`StepError::BlowUp`]'s).
        step: u64,
        /// Iterations made.
        iterations: usize,
        /// Relative residual reached: max |zᵢ| / max(max |(P b)ᵢ|, max |Δvᵢ|) over the free slots'
        /// coordinates, z = P r the Jacobi-preconditioned residual (Δv's units, see
        /// [`StepConfig::cg_tolerance`]); ‖b‖ itself (∞ or NaN, with 0 iterations) when the
        /// right-hand side is not finite (the forces overflowed).
        residual: f64,
    },
    /// The time step is not a positive finite number.
    #[error("time step {0} must be positive and finite")]
    BadTimeStep(f64),
    /// A parameter of the stepping other than the time step is outside its range: `runaway_factor`
    /// must be a finite number > 0 and `cg_tolerance` one in (0, 1) (with NaN the runaway test or
    /// the solver's stopping test would never fire; a tolerance ≥ 1 accepts Δv = 0, no solve).
    #[error("step parameter {name} = {value} must be {allowed}")]
    BadParameter {
        /// `runaway_factor` or `cg_tolerance`.
        name: &'static str,
        /// The value given.
        value: f64,
        /// The range allowed, in words.
        allowed: &'static str,
    },
    /// The state slices do not match the system.
    #[error("state has {got} slots, the system {expected}")]
    SizeMismatch {
        /// Slots of the system.
        expected: usize,
        /// Length of the state given.
        got: usize,
    },
    /// [`Stepper::step`] was given a system of another shape than the one the stepper was made
    /// for (its buffers are sized by it): make a new stepper for the new system.
    #[error("this stepper was made for {slots} slots and {springs} springs, the system given has {got_slots} and {got_springs}")]
    OtherSystem {
        /// Slots of the system at [`Stepper::new`].
        slots: usize,
        /// Springs of the system at [`Stepper::new`].
        springs: usize,
        /// Slots of the system given.
        got_slots: usize,
        /// Springs of the system given.
        got_springs: usize,
    },
    /// [`Stepper::new`] was given a system or a start state it cannot step, named in the text:
    /// a mass, inverse mass, viscosity, rest length, stiffness or damping that is NaN, infinite
    /// or negative, a non-finite gravity, per-slot or per-spring arrays of the wrong length, a
    /// spring whose ends are equal or not slots, a non-finite start position or velocity.
    #[error("cannot step this input: {0}")]
    BadInput(String),
}

/// Parameters of the stepping.
///
/// # Examples
///
/// ```
/// use topomech::mechanics::{Integrator, SpringSystem, StepConfig, Stepper};
///
/// let config = StepConfig { cg_tolerance: 1e-6, cg_max_iterations: 50, ..StepConfig::new(Integrator::Implicit, 0.01) };
/// assert_eq!((config.integrator, config.dt, config.parallel), (Integrator::Implicit, 0.01, false));
/// let mut sys = SpringSystem::default();
/// sys.push_slot(1.0, false, 0.0).unwrap();
/// let stepper = Stepper::new(config, &sys, &[[0.0; 3]], &[[0.0; 3]]).unwrap();
/// assert_eq!(stepper.config().cg_max_iterations, 50);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepConfig {
    /// The scheme.
    pub integrator: Integrator,
    /// Time step h.
    pub dt: f64,
    /// Split passes across rayon's threads when the system is large (bitwise identical results).
    pub parallel: bool,
    /// Kinetic energy above this many times the starting energy scale counts as a blow-up.
    pub runaway_factor: f64,
    /// Relative residual at which conjugate gradient stops, in (0, 1): CG is Jacobi
    /// preconditioned (P = D⁻¹, D the diagonal of M + h(Γ + C) + h² K) and stops when every
    /// coordinate of every free slot of the preconditioned residual z = P r — the correction
    /// to Δv the diagonal alone would still make, in velocity units — is at most
    /// `cg_tolerance` · max(max |(P b)ᵢ|, max |Δvᵢ|). A solve that does not reach it within
    /// `cg_max_iterations` (or breaks down) is [`StepError::SolverFailed`].
    pub cg_tolerance: f64,
    /// Iteration cap of conjugate gradient.
    pub cg_max_iterations: usize,
}

impl StepConfig {
    /// Defaults for `integrator` at step `dt`: serial, runaway factor 1e3, CG to 1e-10 in ≤ 1000
    /// iterations.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::{Integrator, StepConfig};
    ///
    /// let config = StepConfig::new("rk4".parse::<Integrator>().unwrap(), 1e-3);
    /// assert_eq!(config.integrator, Integrator::Rk4);
    /// assert!(!config.parallel && config.dt == 1e-3);
    /// assert!("leapfrog".parse::<Integrator>().is_err());
    /// assert_eq!(Integrator::Symplectic.name(), "symplectic");
    /// ```
    pub fn new(integrator: Integrator, dt: f64) -> Self {
        StepConfig {
            integrator,
            dt,
            parallel: false,
            runaway_factor: 1e3,
            cg_tolerance: 1e-10,
            cg_max_iterations: 1000,
        }
    }
}

/// The integrator's scratch buffers and step counter; reused every step (no allocation).
///
/// A fixed slot with a velocity is a driven pin: it moves at that constant velocity, and its
/// kinetic energy is not part of the runaway test (module docs).
///
/// # Examples
///
/// ```
/// use topomech::mechanics::{Integrator, SpringSystem, StepConfig, Stepper};
///
/// let mut sys = SpringSystem::default();
/// sys.set_gravity([0.0, 0.0, -10.0]).unwrap();
/// sys.push_slot(1.0, false, 0.0).unwrap();
/// let (mut x, mut v) = (vec![[0.0; 3]], vec![[0.0; 3]]);
/// let mut stepper = Stepper::new(StepConfig::new(Integrator::Symplectic, 0.1), &sys, &x, &v).unwrap();
/// (0..10).for_each(|_| stepper.step(&sys, &mut x, &mut v).unwrap());
/// assert_eq!(stepper.steps_done(), 10);
/// assert!((v[0][2] + 10.0).abs() < 1e-12); // free fall for 1 s: v = g t
///
/// // A driven pin: fixed slot 1 moves at 1 km/s (½ m v² = 5e5, far above the limit 1e3 × 20);
/// // the runaway test counts the free slot only.
/// sys.push_slot(1.0, true, 0.0).unwrap();
/// let (mut x, mut v) = (vec![[0.0; 3], [1.0, 0.0, 0.0]], vec![[0.0; 3], [1000.0, 0.0, 0.0]]);
/// let mut stepper = Stepper::new(StepConfig::new(Integrator::Symplectic, 0.01), &sys, &x, &v).unwrap();
/// stepper.step(&sys, &mut x, &mut v).unwrap();
/// assert_eq!((x[1][0], v[1][0]), (11.0, 1000.0));
/// ```
#[derive(Clone, Debug)]
pub struct Stepper {
    config: StepConfig,
    step: u64,
    energy_scale: f64,
    sf: Vec<Vec3>,
    /// Stage state (xs, vs) of RK4, padded to 4 lanes, both in one 64-byte record per slot (one
    /// cache line per spring end).
    ys: Vec<SlotState>,
    acc: Vec<Vec3>,
    ax: Vec<Vec3>,
    av: Vec<Vec3>,
    /// Per-slot spring force sums of the RK4 stages on a sorted system (zero between stages).
    sums: Vec<Rec4>,
    /// How the spring sums split across threads (remade every RK4 step).
    plan: SumPlan,
    /// Whether RK4 may sum spring forces per slot straight from the springs.
    spring_sums: bool,
    /// (kinetic energy, non-finite probe) per chunk of slots, from the last RK4 stage.
    partials: Vec<Probe>,
    kernel: Kernel,
    cg: CgBuffers,
    /// Iterations of the last implicit solve.
    pub last_cg_iterations: usize,
}

#[derive(Clone, Debug, Default)]
struct CgBuffers {
    dir: Vec<Vec3>,
    /// Per spring (k, k_transverse, c) from `linearise`; during the solve 2^-α (h² (k − kt),
    /// h² kt, h c) (`scale_operator`).
    coef: Vec<[f64; 3]>,
    /// Per slot 2^-α (mᵢ + h νᵢ) during the solve (0 on fixed slots).
    diag: Vec<f64>,
    /// Jacobi preconditioner: per free slot and coordinate the inverse of the scaled operator's
    /// diagonal entry, 1 / (2^-α (mᵢ + h νᵢ + Σ_s (h² kt + (h² (k − kt) + h c) n_j²))); 0 on
    /// fixed slots (`jacobi`).
    pre: Vec<Vec3>,
    r: Vec<Vec3>,
    p: Vec<Vec3>,
    /// A p during an iteration, then the preconditioned residual z = P r.
    q: Vec<Vec3>,
    dv: Vec<Vec3>,
    /// Wide-float spring products and right-hand side of `wide_rhs` (kept to step without
    /// allocating).
    wide_y: Vec<[Wide; 3]>,
    wide_b: Vec<[Wide; 3]>,
}

impl CgBuffers {
    /// One CG update with step length `alpha` (when `advance`: Δv += α p, r −= α q; else the
    /// residual as it is), then the preconditioned residual z = P r into `q`. Returns (rᵀz,
    /// ‖z‖∞, ‖Δv‖∞). O(slots).
    fn step_residual(&mut self, alpha: f64, advance: bool) -> (f64, f64, f64) {
        let (mut rz, mut zm, mut dm) = (0.0, 0.0, 0.0);
        for i in 0..self.r.len() {
            if advance {
                self.dv[i] = madd(self.dv[i], alpha, self.p[i]);
                self.r[i] = madd(self.r[i], -alpha, self.q[i]);
            }
            let z = times(self.pre[i], self.r[i]);
            rz += dot(self.r[i], z);
            zm = max_abs(zm, z);
            dm = max_abs(dm, self.dv[i]);
            self.q[i] = z;
        }
        (rz, zm, dm)
    }
}

/// The binade of max |(P b)ᵢ| to a factor 2, from the exponents of P and b alone (no product
/// formed: either may be far outside 1); `None` when every P b coordinate is 0. O(slots).
fn preconditioned_binade(b: &[Vec3], pre: &[Vec3]) -> Option<i32> {
    b.iter()
        .zip(pre)
        .flat_map(|(r, p)| (0..3).map(move |j| (r[j], p[j])))
        .filter(|&(r, p)| r != 0.0 && p != 0.0)
        .map(|(r, p)| exponent(r.abs()) + exponent(p))
        .max()
}

impl Stepper {
    /// A stepper for `sys` starting from state (x, v): records the energy scale for the runaway
    /// test. O(slots + springs).
    ///
    /// # Errors
    /// [`StepError::BadTimeStep`], [`StepError::BadParameter`], [`StepError::SizeMismatch`],
    /// [`StepError::BadInput`] (a system or start state it cannot step, a start energy scale that
    /// is not finite).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::{Integrator, SpringSystem, StepConfig, StepError, Stepper};
    ///
    /// let mut sys = SpringSystem::default();
    /// sys.push_slot(1.0, false, 0.0).unwrap();
    /// let (x, v) = (vec![[0.0; 3]], vec![[0.0; 3]]);
    /// let stepper = Stepper::new(StepConfig::new(Integrator::Implicit, 0.01), &sys, &x, &v).unwrap();
    /// assert_eq!((stepper.steps_done(), stepper.config().dt), (0, 0.01));
    /// let bad = Stepper::new(StepConfig::new(Integrator::Implicit, 0.01), &sys, &[], &v);
    /// assert!(matches!(bad, Err(StepError::SizeMismatch { .. })));
    /// let nan = vec![[f64::NAN, 0.0, 0.0]]; // a start state the stepping cannot use
    /// let bad = Stepper::new(StepConfig::new(Integrator::Implicit, 0.01), &sys, &nan, &v).unwrap_err();
    /// assert!(bad.to_string().starts_with("cannot step this input: start position of slot 0"), "{bad}");
    /// ```
    pub fn new(config: StepConfig, sys: &SpringSystem, x: &[Vec3], v: &[Vec3]) -> Result<Self, StepError> {
        let mut stepper = Stepper::with_buffers(config, sys)?;
        stepper.reset_energy_scale(sys, x, v)?;
        Ok(stepper)
    }

    /// A stepper for `sys` whose runaway test has no energy scale yet: the caller must take one
    /// with [`Stepper::reset_energy_scale`] before the first step (the simulation does, at its
    /// next step). Checks the configuration and the system, not a state. O(slots + springs).
    pub(crate) fn with_buffers(config: StepConfig, sys: &SpringSystem) -> Result<Self, StepError> {
        if !(config.dt.is_finite() && config.dt > 0.0) {
            return Err(StepError::BadTimeStep(config.dt));
        }
        let (factor, tol) = (config.runaway_factor, config.cg_tolerance);
        if !(factor.is_finite() && factor > 0.0) {
            return Err(StepError::BadParameter {
                name: "runaway_factor",
                value: factor,
                allowed: "a finite number > 0",
            });
        }
        if !(tol > 0.0 && tol < 1.0) {
            return Err(StepError::BadParameter { name: "cg_tolerance", value: tol, allowed: "a number in (0, 1)" });
        }
        check_system(sys).map_err(StepError::BadInput)?;
        let (n, s) = (sys.slots(), sys.springs());
        let z = |len| vec![[0.0; 3]; len];
        Ok(Stepper {
            config,
            step: 0,
            energy_scale: f64::NAN,
            sf: z(s),
            ys: vec![SlotState::default(); n],
            acc: z(n),
            ax: z(n),
            av: z(n),
            sums: vec![[0.0; 4]; n],
            plan: SumPlan::default(),
            spring_sums: true,
            partials: Vec::new(),
            kernel: Kernel::detect(),
            cg: CgBuffers::default(),
            last_cg_iterations: 0,
        })
    }

    /// The configuration. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::{Integrator, SpringSystem, StepConfig, Stepper};
    ///
    /// let mut sys = SpringSystem::default();
    /// sys.push_slot(1.0, false, 0.0).unwrap();
    /// let config = StepConfig { parallel: true, ..StepConfig::new(Integrator::Symplectic, 0.002) };
    /// let stepper = Stepper::new(config, &sys, &[[0.0; 3]], &[[0.0; 3]]).unwrap();
    /// assert_eq!(stepper.config(), &config);
    /// ```
    pub fn config(&self) -> &StepConfig {
        &self.config
    }

    /// Steps made so far. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::{Integrator, SpringSystem, StepConfig, Stepper};
    ///
    /// let mut sys = SpringSystem::default();
    /// sys.push_slot(1.0, false, 0.0).unwrap();
    /// let (mut x, mut v) = (vec![[0.0; 3]], vec![[1.0, 0.0, 0.0]]);
    /// let mut stepper = Stepper::new(StepConfig::new(Integrator::Euler, 0.5), &sys, &x, &v).unwrap();
    /// for _ in 0..4 {
    ///     stepper.step(&sys, &mut x, &mut v).unwrap();
    /// }
    /// assert_eq!(stepper.steps_done(), 4);
    /// assert_eq!(x[0], [2.0, 0.0, 0.0]); // free flight: 4 steps × 0.5 s × 1 m/s
    /// ```
    pub fn steps_done(&self) -> u64 {
        self.step
    }

    /// Takes the state (x, v) as the new start of the runaway test: its energy scale replaces
    /// the one recorded by [`Stepper::new`]. Call it after writing positions or velocities by hand
    /// between steps — energy put in from outside is not a blow-up, and without it a body started
    /// at rest would have a stale scale. The step count is kept. A caller that writes the state
    /// before every step moves the threshold with it, so only the non-finite test is left to
    /// catch a slow runaway then. O(slots + springs).
    ///
    /// # Errors
    /// [`StepError::OtherSystem`], [`StepError::SizeMismatch`], [`StepError::BadInput`] (a
    /// non-finite coordinate, or an energy scale that is not finite); the scale is unchanged then.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::{Integrator, SpringSystem, StepConfig, StepError, Stepper};
    ///
    /// // Two free unit masses on a spring of rest length 1, at rest: nothing can move.
    /// let mut sys = SpringSystem::default();
    /// sys.push_slot(1.0, false, 0.0).unwrap();
    /// sys.push_slot(1.0, false, 0.0).unwrap();
    /// sys.push_spring([0, 1], 1.0, 10.0, 0.0).unwrap();
    /// let (mut x, mut v) = (vec![[0.0; 3], [1.0, 0.0, 0.0]], vec![[0.0; 3]; 2]);
    /// let mut stepper = Stepper::new(StepConfig::new(Integrator::Symplectic, 1e-2), &sys, &x, &v).unwrap();
    /// v[1] = [200.0, 0.0, 0.0]; // a kick by hand: 20 000 J against 10³ × (½ k L² = 5 J)
    /// assert!(matches!(stepper.step(&sys, &mut x, &mut v), Err(StepError::BlowUp { .. })));
    /// (x[1], v[1]) = ([1.0, 0.0, 0.0], [200.0, 0.0, 0.0]);
    /// stepper.reset_energy_scale(&sys, &x, &v).unwrap(); // the kick is the new start
    /// stepper.step(&sys, &mut x, &mut v).unwrap();
    /// v[0] = [f64::NAN; 3];
    /// assert!(matches!(stepper.reset_energy_scale(&sys, &x, &v), Err(StepError::BadInput(_))));
    /// ```
    pub fn reset_energy_scale(&mut self, sys: &SpringSystem, x: &[Vec3], v: &[Vec3]) -> Result<(), StepError> {
        self.check_shape(sys)?;
        self.energy_scale = start_energy_scale(sys, x, v)?;
        Ok(())
    }

    /// Fits the buffers to `sys`, the system this stepper steps after a topological change
    /// (slots and springs added, springs moved), keeping the configuration, the step count and
    /// the runaway test's energy scale. The whole system is checked as [`Stepper::new`] does
    /// under `expensive-checks` only: this runs after every cut, and a debug build's checks stay
    /// local (finding 227; the crate's projection maintains the system). O(growth) amortised.
    ///
    /// # Errors
    /// [`StepError::BadInput`]: a system the stepper cannot take (under `expensive-checks` only;
    /// the buffers are unchanged then).
    pub(crate) fn follow_system(&mut self, sys: &SpringSystem) -> Result<(), StepError> {
        #[cfg(feature = "expensive-checks")]
        check_system(sys).map_err(StepError::BadInput)?;
        let (n, s) = (sys.slots(), sys.springs());
        self.sf.resize(s, [0.0; 3]);
        self.ys.resize(n, SlotState::default());
        for buf in [&mut self.acc, &mut self.ax, &mut self.av] {
            buf.resize(n, [0.0; 3]);
        }
        self.sums.resize(n, [0.0; 4]);
        Ok(())
    }

    /// Drops the runaway test's energy scale: the next step must take one
    /// ([`Stepper::reset_energy_scale`]), as after [`Stepper::with_buffers`]. O(1).
    pub(crate) fn forget_energy_scale(&mut self) {
        self.energy_scale = f64::NAN;
    }

    /// Whether the runaway test has its energy scale (every public constructor takes it; only a
    /// crate-internal [`Stepper::with_buffers`] stepper, or one told to
    /// [`Stepper::forget_energy_scale`], waits for [`Stepper::reset_energy_scale`]). O(1).
    pub(crate) fn has_energy_scale(&self) -> bool {
        !self.energy_scale.is_nan()
    }

    /// [`StepError::OtherSystem`] unless `sys` has the slot and spring counts the buffers were
    /// made for. O(1).
    fn check_shape(&self, sys: &SpringSystem) -> Result<(), StepError> {
        if (sys.slots(), sys.springs()) == (self.ys.len(), self.sf.len()) {
            return Ok(());
        }
        Err(StepError::OtherSystem {
            slots: self.ys.len(),
            springs: self.sf.len(),
            got_slots: sys.slots(),
            got_springs: sys.springs(),
        })
    }

    /// The instruction set of the hot loops ([`Kernel::detect`] unless set). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::{Integrator, Kernel, SpringSystem, StepConfig, Stepper};
    ///
    /// let mut sys = SpringSystem::default();
    /// sys.push_slot(1.0, false, 0.0).unwrap();
    /// let stepper = Stepper::new(StepConfig::new(Integrator::Rk4, 0.1), &sys, &[[0.0; 3]], &[[0.0; 3]]).unwrap();
    /// assert_eq!(stepper.kernel(), Kernel::detect());
    /// ```
    pub fn kernel(&self) -> Kernel {
        self.kernel
    }

    /// Runs the hot loops with `kernel` from now on; every kernel gives the same bits. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::{Integrator, Kernel, SpringSystem, StepConfig, Stepper};
    ///
    /// let mut sys = SpringSystem::default();
    /// sys.set_gravity([0.0, 0.0, -9.81]).unwrap();
    /// sys.push_slot(1.0, false, 0.3).unwrap();
    /// let run = |kernel| {
    ///     let (mut x, mut v) = (vec![[0.0; 3]], vec![[1.0, 0.0, 0.0]]);
    ///     let mut stepper = Stepper::new(StepConfig::new(Integrator::Rk4, 0.01), &sys, &x, &v).unwrap();
    ///     stepper.set_kernel(kernel);
    ///     (0..10).for_each(|_| stepper.step(&sys, &mut x, &mut v).unwrap());
    ///     (x, v)
    /// };
    /// let portable = run(Kernel::portable());
    /// assert!(Kernel::available().into_iter().all(|k| run(k) == portable));
    /// ```
    pub fn set_kernel(&mut self, kernel: Kernel) {
        self.kernel = kernel;
    }

    /// Allows (`true`, the default) or forbids the one-pass spring sums of RK4 on a system sorted
    /// by first end (`mechanics::force` module docs, "Spring sums"); forbidden, RK4 writes one force
    /// per spring and gathers them per slot. Both give the same bits; the switch is for tests
    /// and same-process benchmarks. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{FlatModel, Integrator, Material, StepConfig, Stepper};
    ///
    /// let (points, tets) = kuhn_cube(2);
    /// let pinned: Vec<bool> = points.iter().map(|p| p[2] == 0.0).collect();
    /// let flat = FlatModel::from_tets(&points, &tets, Material::default(), [0.0, 0.0, -9.81], &pinned).unwrap();
    /// let run = |sums: bool| {
    ///     let (mut x, mut v) = (flat.position.clone(), flat.velocity.clone());
    ///     let mut stepper = Stepper::new(StepConfig::new(Integrator::Rk4, 1e-4), &flat.system, &x, &v).unwrap();
    ///     stepper.set_spring_sums(sums);
    ///     (0..5).for_each(|_| stepper.step(&flat.system, &mut x, &mut v).unwrap());
    ///     x
    /// };
    /// assert_eq!(run(true), run(false)); // bit for bit
    /// assert_ne!(run(true), flat.position); // and it moved
    /// ```
    pub fn set_spring_sums(&mut self, allowed: bool) {
        self.spring_sums = allowed;
    }

    /// Whether an RK4 step of `sys` takes the one-pass spring sums: they are allowed
    /// ([`Stepper::set_spring_sums`]) and `sys` is sorted by first end. Tests that compare the two
    /// paths read it to know they compared two paths. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{FlatModel, Integrator, Material, StepConfig, Stepper};
    ///
    /// let (points, tets) = kuhn_cube(2);
    /// let flat = FlatModel::from_tets(&points, &tets, Material::default(), [0.0; 3], &vec![false; points.len()]).unwrap();
    /// let (x, v) = (&flat.position, &flat.velocity);
    /// let mut stepper = Stepper::new(StepConfig::new(Integrator::Rk4, 1e-4), &flat.system, x, v).unwrap();
    /// assert!(stepper.takes_spring_sums(&flat.system)); // a fresh flat model is sorted
    /// stepper.set_spring_sums(false);
    /// assert!(!stepper.takes_spring_sums(&flat.system));
    /// ```
    pub fn takes_spring_sums(&self, sys: &SpringSystem) -> bool {
        self.spring_sums && sys.sorted_by_first_end()
    }

    /// Advances (x, v) by one step of the configured scheme, then checks for blow-up.
    /// O(slots + springs) (times the CG iterations for the implicit scheme).
    ///
    /// # Errors
    /// [`StepError::BlowUp`], [`StepError::SolverFailed`] (after either, the state holds the bad
    /// values, for inspection; do not continue), [`StepError::SizeMismatch`] and
    /// [`StepError::OtherSystem`] (a system of another shape than at [`Stepper::new`]; nothing
    /// moved).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::{Integrator, SpringSystem, StepConfig, Stepper};
    ///
    /// // A unit mass hanging from a fixed point on a spring, released at the spring's rest length.
    /// let mut sys = SpringSystem::default();
    /// sys.set_gravity([0.0, 0.0, -10.0]).unwrap();
    /// sys.push_slot(1.0, true, 0.0).unwrap();
    /// sys.push_slot(1.0, false, 0.0).unwrap();
    /// sys.push_spring([0, 1], 1.0, 100.0, 0.0).unwrap();
    /// let (mut x, mut v) = (vec![[0.0; 3], [0.0, 0.0, -1.0]], vec![[0.0; 3]; 2]);
    /// let mut stepper = Stepper::new(StepConfig::new(Integrator::Symplectic, 1e-3), &sys, &x, &v).unwrap();
    /// (0..100).for_each(|_| stepper.step(&sys, &mut x, &mut v).unwrap());
    /// assert_eq!(stepper.steps_done(), 100);
    /// assert!(x[0] == [0.0; 3] && x[1][2] < -1.0); // the anchor stays, the mass falls
    /// // Another system's shape is refused, not stepped with buffers of the wrong size.
    /// let mut bigger = sys.clone();
    /// bigger.push_slot(1.0, false, 0.0).unwrap();
    /// let (mut x3, mut v3) = (vec![[0.0; 3]; 3], vec![[0.0; 3]; 3]);
    /// let e = stepper.step(&bigger, &mut x3, &mut v3).unwrap_err();
    /// assert!(matches!(e, topomech::mechanics::StepError::OtherSystem { slots: 2, got_slots: 3, .. }));
    /// ```
    pub fn step(&mut self, sys: &SpringSystem, x: &mut [Vec3], v: &mut [Vec3]) -> Result<(), StepError> {
        self.check_shape(sys)?;
        check_len(sys, x)?;
        check_len(sys, v)?;
        if !self.has_energy_scale() {
            // Only a crate-internal `with_buffers` or forgetful stepper lacks it; never step without it.
            return Err(StepError::BadInput("the runaway test has no energy scale yet (reset_energy_scale)".into()));
        }
        match self.config.integrator {
            Integrator::Euler => self.euler(sys, x, v),
            Integrator::Symplectic => self.symplectic(sys, x, v),
            Integrator::Rk4 => self.rk4(sys, x, v),
            Integrator::Implicit => self.implicit(sys, x, v)?,
        }
        if self.config.integrator != Integrator::Rk4 {
            let par = self.config.parallel;
            chunked(par, x.len(), &mut self.partials, |first, n| {
                let r = first..first + n;
                probe_state(&sys.mass[r.clone()], &sys.inv_mass[r.clone()], &x[r.clone()], &v[r])
            });
        }
        self.check_state(sys, x, v)?;
        self.step += 1;
        Ok(())
    }

    fn euler(&mut self, sys: &SpringSystem, x: &mut [Vec3], v: &mut [Vec3]) {
        let (h, par) = (self.config.dt, self.config.parallel);
        sys.accelerations_raw(self.kernel, x, v, &mut self.sf, &mut self.acc, par);
        axpy(x, h, v);
        axpy(v, h, &self.acc);
    }

    fn symplectic(&mut self, sys: &SpringSystem, x: &mut [Vec3], v: &mut [Vec3]) {
        let (h, par) = (self.config.dt, self.config.parallel);
        sys.accelerations_raw(self.kernel, x, v, &mut self.sf, &mut self.acc, par);
        axpy(v, h, &self.acc);
        axpy(x, h, v);
    }

    /// Classic RK4, each stage's per-slot update fused with the gather of its accelerations
    /// (one pass over the slots per stage); the last stage also collects the blow-up probes.
    fn rk4(&mut self, sys: &SpringSystem, x: &mut [Vec3], v: &mut [Vec3]) {
        let (h, par, kernel) = (self.config.dt, self.config.parallel, self.kernel);
        let stages = [Stage::First(0.5 * h), Stage::Middle(0.5 * h), Stage::Middle(h), Stage::Last(h / 6.0)];
        // Stage 1 evaluates at y0: its padded copy.
        let copy = |(y, (xi, vi)): (&mut SlotState, (&Vec3, &Vec3))| *y = SlotState { x: pad(*xi), v: pad(*vi) };
        if par && x.len() > PARALLEL_CHUNK {
            self.ys.par_iter_mut().zip(x.par_iter().zip(v.par_iter())).for_each(copy);
        } else {
            self.ys.iter_mut().zip(x.iter().zip(v.iter())).for_each(copy);
        }
        // A system sorted by first end sums its spring forces per slot in one pass over the
        // springs (no force array, no incidence lists); any other uses the two-pass gather.
        let sorted = self.takes_spring_sums(sys);
        self.sums.resize(x.len(), [0.0; 4]);
        if sorted {
            sys.plan_sums(par, &mut self.plan);
        }
        for stage in stages {
            let forces = if sorted {
                sys.spring_sums4(kernel, &self.ys, &mut self.sums, &self.plan);
                None
            } else {
                sys.spring_forces4(kernel, &self.ys, &mut self.sf, par);
                Some(&self.sf[..])
            };
            let state = Rk4State {
                x: &mut *x,
                v: &mut *v,
                ys: &mut self.ys,
                ax: &mut self.ax,
                av: &mut self.av,
                sums: &mut self.sums,
            };
            state.run(par, &mut self.partials, |first, chunk| rk4_stage(kernel, sys, forces, stage, first, chunk));
        }
    }

    /// Reports a non-finite state or a runaway kinetic energy, from the probes of
    /// `self.partials` (filled by the step); scans the slots again only to name the culprit.
    fn check_state(&self, sys: &SpringSystem, x: &[Vec3], v: &[Vec3]) -> Result<(), StepError> {
        let step = self.step;
        let bad = |slot, reason: String| Err(StepError::BlowUp { step, slot, reason });
        let (kinetic, probe) = self.partials.iter().fold((0.0, 0.0), |(k, p), q| (k + q.kinetic, p + q.probe));
        if !probe.is_finite() {
            if let Some(i) = (0..x.len()).find(|&i| !(x[i].iter().chain(&v[i]).all(|c| c.is_finite()))) {
                return bad(i, format!("non-finite state x = {:?}, v = {:?}", x[i], v[i]));
            }
        }
        let limit = self.config.runaway_factor * self.energy_scale;
        if self.energy_scale > 0.0 && kinetic > limit {
            // The culprit is the free slot of largest ½ m |v|², as the probe counts free slots only
            // (the smallest such slot on a tie: `>`, not `>=`).
            let (mut worst, mut worst_slot) = (-1.0, 0);
            for (i, ((&m, &w), vi)) in sys.mass.iter().zip(&sys.inv_mass).zip(v).enumerate() {
                let e = 0.5 * m * dot(*vi, *vi);
                if w > 0.0 && e > worst {
                    (worst, worst_slot) = (e, i);
                }
            }
            return bad(worst_slot, format!("kinetic energy {kinetic:e} exceeds {limit:e} (runaway)"));
        }
        Ok(())
    }
}

/// Blow-up probes of a chunk of slots: its kinetic energy Σ ½ m |v|² over the **free** slots
/// (inverse mass > 0, as [`SpringSystem::kinetic_energy`] and the energy scale count it: a fixed
/// slot with a velocity is a driven pin, its motion prescribed, and cannot run away), and
/// Σ 0·c over every coordinate c of x and v of every slot, which is NaN exactly when some c is
/// NaN or infinite.
#[derive(Clone, Copy, Debug, Default)]
struct Probe {
    kinetic: f64,
    probe: f64,
}

impl Probe {
    #[inline(always)]
    fn add(&mut self, m: f64, inv_mass: f64, x: Vec3, v: Vec3) {
        // A select, not a branch: m of a free slot, +0 of a fixed one (adding 0.5 · 0 · |v|² = +0
        // leaves the sum's bits, so the sum is the free slots' one).
        let m = if inv_mass > 0.0 { m } else { 0.0 };
        self.kinetic += 0.5 * m * dot(v, v);
        self.probe += (x[0] * 0.0 + x[1] * 0.0 + x[2] * 0.0) + (v[0] * 0.0 + v[1] * 0.0 + v[2] * 0.0);
    }
}

/// Probes of slots with masses `m`, inverse masses `w`, positions `x`, velocities `v`.
fn probe_state(m: &[f64], w: &[f64], x: &[Vec3], v: &[Vec3]) -> Probe {
    let mut p = Probe::default();
    for (((&m, &w), &x), &v) in m.iter().zip(w).zip(x).zip(v) {
        p.add(m, w, x, v);
    }
    p
}

/// `partials[c] = probe(c·C, len)` for the chunks of C = [`PARALLEL_CHUNK`] slots of `0..n`,
/// across threads when asked: the same chunks, hence the same sums, for any thread count.
fn chunked(par: bool, n: usize, partials: &mut Vec<Probe>, probe: impl Fn(usize, usize) -> Probe + Sync) {
    let chunks = n.div_ceil(PARALLEL_CHUNK);
    let range = |c: usize| (c * PARALLEL_CHUNK, PARALLEL_CHUNK.min(n - c * PARALLEL_CHUNK));
    if par && chunks > 1 {
        (0..chunks).into_par_iter().map(|c| probe(range(c).0, range(c).1)).collect_into_vec(partials);
    } else {
        partials.clear();
        partials.extend((0..chunks).map(|c| probe(range(c).0, range(c).1)));
    }
}

/// Which RK4 stage a slot pass finishes (its step factor).
#[derive(Clone, Copy, Debug)]
enum Stage {
    /// a = a(y0); (ax, av) = k1 = (v, a); (xs, vs) = y0 + c·k1.
    First(f64),
    /// a = a(xs, vs); (ax, av) += 2 (vs, a); (xs, vs) = y0 + c·(vs, a).
    Middle(f64),
    /// a = a(xs, vs); y0 += c·((ax, av) + (vs, a)), and the probes.
    Last(f64),
}

/// The RK4 state over a range of slots (the stage state `ys` as (xs, vs) records).
struct Rk4State<'a> {
    x: &'a mut [Vec3],
    v: &'a mut [Vec3],
    ys: &'a mut [SlotState],
    ax: &'a mut [Vec3],
    av: &'a mut [Vec3],
    sums: &'a mut [Rec4],
}

impl Rk4State<'_> {
    /// `pass(first, chunk)` over the chunks of [`PARALLEL_CHUNK`] slots, across threads when asked;
    /// the probes go to `partials` in chunk order.
    fn run(self, par: bool, partials: &mut Vec<Probe>, pass: impl Fn(usize, Rk4State<'_>) -> Probe + Sync + Send) {
        let c = PARALLEL_CHUNK;
        let Rk4State { x, v, ys, ax, av, sums } = self;
        if par && x.len() > c {
            let chunks = (
                x.par_chunks_mut(c),
                v.par_chunks_mut(c),
                ys.par_chunks_mut(c),
                ax.par_chunks_mut(c),
                av.par_chunks_mut(c),
                sums.par_chunks_mut(c),
            );
            chunks
                .into_par_iter()
                .enumerate()
                .map(|(k, (x, v, ys, ax, av, sums))| pass(k * c, Rk4State { x, v, ys, ax, av, sums }))
                .collect_into_vec(partials);
        } else {
            partials.clear();
            let chunks = x.chunks_mut(c).zip(v.chunks_mut(c)).zip(ys.chunks_mut(c)).zip(ax.chunks_mut(c));
            for (k, (((x, v), ys), ax)) in chunks.enumerate() {
                let r = k * c..k * c + x.len();
                let (av, sums) = (&mut av[r.clone()], &mut sums[r]);
                partials.push(pass(k * c, Rk4State { x, v, ys, ax, av, sums }));
            }
        }
    }
}

multiversion! {
    /// One RK4 stage over the slots `first..` of `s` (see [`Stage`]); the spring force sum of a
    /// slot is the gather of the spring forces `sf` or, when `sf` is `None`, its entry of
    /// `s.sums` (read, then reset to zero for the next stage).
    fn rk4_stage(sys: &SpringSystem, sf: Option<&[Vec3]>, stage: Stage, first: usize, s: Rk4State<'_>) -> Probe
        = rk4_stage_body;
}

#[inline(always)]
fn rk4_stage_body(sys: &SpringSystem, sf: Option<&[Vec3]>, stage: Stage, first: usize, s: Rk4State<'_>) -> Probe {
    match sf {
        Some(sf) => stage_slots(sys, stage, first, s, |_, i, vi, _| sys.acceleration(i, vi, sf)),
        None => stage_slots(sys, stage, first, s, |k, i, vi, sums| {
            sys.acceleration_of_sum(i, unpad(std::mem::take(&mut sums[k])), vi)
        }),
    }
}

/// The stage's per-slot loop; `acceleration(k, first + k, v_k, sums)` gives slot k's acceleration.
#[inline(always)]
fn stage_slots(
    sys: &SpringSystem,
    stage: Stage,
    first: usize,
    s: Rk4State<'_>,
    mut acceleration: impl FnMut(usize, usize, Vec3, &mut [Rec4]) -> Vec3,
) -> Probe {
    let n = s.x.len();
    let (x, v, ys, ax, av) = (s.x, &mut s.v[..n], &mut s.ys[..n], &mut s.ax[..n], &mut s.av[..n]);
    let sums = &mut s.sums[..n];
    let mut probe = Probe::default();
    match stage {
        Stage::First(c) => {
            for k in 0..n {
                let (xi, vi) = (x[k], v[k]);
                let a = acceleration(k, first + k, vi, sums);
                ax[k] = vi;
                av[k] = a;
                ys[k] = SlotState { x: pad(madd(xi, c, vi)), v: pad(madd(vi, c, a)) };
            }
        }
        Stage::Middle(c) => {
            for k in 0..n {
                let vi = unpad(ys[k].v);
                let a = acceleration(k, first + k, vi, sums);
                ax[k] = madd(ax[k], 2.0, vi);
                av[k] = madd(av[k], 2.0, a);
                ys[k] = SlotState { x: pad(madd(x[k], c, vi)), v: pad(madd(v[k], c, a)) };
            }
        }
        Stage::Last(c) => {
            for k in 0..n {
                let vi = unpad(ys[k].v);
                let a = acceleration(k, first + k, vi, sums);
                // The probe takes the new state from registers: read back from `x` and `v`,
                // its loads straddled the two stores of each Vec3 just written, and the
                // store-to-load forwarding failed (a stall per slot).
                let (xk, vk) = (madd(x[k], c, add(ax[k], vi)), madd(v[k], c, add(av[k], a)));
                (x[k], v[k]) = (xk, vk);
                probe.add(sys.mass[first + k], sys.inv_mass[first + k], xk, vk);
            }
        }
    }
    probe
}

/// What makes `sys` unsteppable (see [`StepError::BadInput`]), if anything. O(slots + springs),
/// no allocation unless it fails.
fn check_system(sys: &SpringSystem) -> Result<(), String> {
    sys.check().map_err(|e| e.to_string())
}

/// What makes the start state unsteppable: a non-finite position or velocity. O(slots).
fn check_start(x: &[Vec3], v: &[Vec3]) -> Result<(), String> {
    for (name, values) in [("position", x), ("velocity", v)] {
        if let Some((i, p)) = values.iter().enumerate().find(|(_, p)| !p.iter().all(|c| c.is_finite())) {
            return Err(format!("start {name} of slot {i} is {p:?} (must be finite)"));
        }
    }
    Ok(())
}

/// The checked start state (lengths, finite values) and its energy scale, which must be finite.
/// O(slots + springs).
fn start_energy_scale(sys: &SpringSystem, x: &[Vec3], v: &[Vec3]) -> Result<f64, StepError> {
    check_len(sys, x)?;
    check_len(sys, v)?;
    check_start(x, v).map_err(StepError::BadInput)?;
    let scale = energy_scale(sys, x, v);
    if !scale.is_finite() {
        return Err(StepError::BadInput(format!(
            "the start energy scale (kinetic + elastic + M |g| D, or Σ ½ k L² when that is 0) is {scale:e}: \
             the runaway test needs a finite one"
        )));
    }
    Ok(scale)
}

fn check_len(sys: &SpringSystem, x: &[Vec3]) -> Result<(), StepError> {
    if x.len() == sys.slots() {
        Ok(())
    } else {
        Err(StepError::SizeMismatch { expected: sys.slots(), got: x.len() })
    }
}

/// Kinetic + elastic energy + M |g| D (D = bounding-box diagonal of the slots that have mass:
/// a massless slot has no potential energy, and a body's slot of a vertex id no tet uses rests
/// at the origin, which would stretch the box and loosen the runaway test by the body's distance
/// from it, finding 217); if that is 0, Σ ½ k L² (the elastic energy of every spring at twice its
/// rest length): a body at rest in its rest shape without gravity keeps a runaway test of the
/// material's scale. O(slots + springs).
fn energy_scale(sys: &SpringSystem, x: &[Vec3], v: &[Vec3]) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for (p, _) in x.iter().zip(&sys.mass).filter(|(_, &m)| m > 0.0) {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let diag = if lo[0] > hi[0] { 0.0 } else { norm(sub(hi, lo)) };
    let total_mass: f64 = sys.mass.iter().sum();
    let scale = sys.kinetic_energy_raw(v) + sys.elastic_energy_raw(x) + total_mass * norm(sys.gravity) * diag;
    if scale != 0.0 {
        return scale;
    }
    sys.stiffness.iter().zip(&sys.rest).map(|(&k, &l)| 0.5 * k * l * l).sum()
}

#[inline(always)]
fn madd(a: Vec3, s: f64, b: Vec3) -> Vec3 {
    [a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]]
}

#[inline(always)]
fn pad(a: Vec3) -> Rec4 {
    [a[0], a[1], a[2], 0.0]
}

#[inline(always)]
fn unpad(a: Rec4) -> Vec3 {
    [a[0], a[1], a[2]]
}

#[inline(always)]
fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// y += s·x.
fn axpy(y: &mut [Vec3], s: f64, x: &[Vec3]) {
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi = madd(*yi, s, *xi);
    }
}

// ---------------------------------------------------------------------------------------------
// Implicit (linearised backward) Euler with matrix-free CG.

impl Stepper {
    fn implicit(&mut self, sys: &SpringSystem, x: &mut [Vec3], v: &mut [Vec3]) -> Result<(), StepError> {
        let (h, par) = (self.config.dt, self.config.parallel);
        let n = x.len();
        let cg = &mut self.cg;
        for buf in [&mut cg.r, &mut cg.p, &mut cg.q, &mut cg.dv, &mut cg.pre] {
            buf.resize(n, [0.0; 3]);
        }
        cg.dir.resize(sys.springs(), [0.0; 3]);
        cg.coef.resize(sys.springs(), [0.0; 3]);
        cg.diag.resize(n, 0.0);
        linearise(sys, x, &mut cg.dir, &mut cg.coef);
        // b = h f0 + h² K-gather(v0)  (K v0 enters with a minus: −h² K v0, K = −∂f/∂x ⇒ + gather).
        sys.forces_raw(x, v, &mut self.sf, &mut self.acc, par);
        let products_lost = spring_products(sys, &cg.dir, &cg.coef, v, 0.0, 1.0, &mut self.sf);
        let sf: &[Vec3] = &self.sf;
        let f0: &[Vec3] = &self.acc;
        let hh = h * h;
        let terms_lost = AtomicBool::new(false);
        sys.per_slot(&mut cg.r, par, |i| {
            let g = gather(sys, i, sf);
            if sys.inv_mass[i] > 0.0 {
                [0, 1, 2].map(|j| {
                    let (hf, hhg) = (h * f0[i][j], hh * g[j]);
                    let b = hf + hhg;
                    // A term (h f₀, h² g, h² itself) or b below the normal range while its
                    // factors are not 0: underflowed, not exact.
                    let lost = (f0[i][j] != 0.0 && !hf.is_normal())
                        || (g[j] != 0.0 && !(hh.is_normal() && hhg.is_normal()))
                        || (b != 0.0 && !b.is_normal());
                    if lost {
                        terms_lost.store(true, Ordering::Relaxed);
                    }
                    b
                })
            } else {
                [0.0; 3]
            }
        });
        // A b that is not finite in f64 while the forces are: an intermediate overflowed (K ẋ₀
        // for a stiffness near f64::MAX, h² for a huge h, h f₀ for h > 1); or a b one of whose
        // terms underflowed (finding 209: h f₀, h², h² K ẋ₀ or a product of K ẋ₀ below the
        // normal range — b = 0 or a few bits where the forces and Δv are ordinary). Formed again
        // in wide floats and handed to CG already scaled, unless b itself is past f64::MAX
        // (refused, as a b that is not finite always was). Cold: the plain b stands wherever
        // it is finite and every term of it normal or exactly 0.
        let plain = cg.r.iter().flatten().all(|c| c.is_finite());
        let lost = products_lost || terms_lost.into_inner();
        let forces_finite = (0..n).all(|i| sys.inv_mass[i] == 0.0 || f0[i].iter().all(|c| c.is_finite()));
        let pre_scaled = match (plain && !lost) || !forces_finite {
            true => None,
            false => wide_rhs(sys, &cg.dir, &cg.coef, v, f0, h, &mut cg.wide_y, &mut cg.wide_b, &mut cg.r),
        };
        let iterations = self.conjugate_gradient(sys, h, pre_scaled)?;
        self.last_cg_iterations = iterations;
        let dv = &self.cg.dv;
        for i in 0..n {
            v[i] = add(v[i], dv[i]);
            x[i] = madd(x[i], h, v[i]);
        }
        Ok(())
    }

    /// Solves A Δv = r (r holds b on entry, or 2^-β b when `pre_scaled` is `Some(β)`, from
    /// `wide_rhs`) by Jacobi-preconditioned CG on the free slots; Δv in `cg.dv`.
    ///
    /// Preconditioner and stop test (finding 208): P = D⁻¹, D the diagonal of A (per free slot
    /// and coordinate mᵢ + h νᵢ + Σ_s h² kt_s + (h² (k_s − kt_s) + h c_s) n_j², `jacobi`), and
    /// CG stops when the preconditioned residual z = P r — the correction to Δv that the
    /// diagonal alone would make, in velocity units — is at most `cg_tolerance` times
    /// max(‖P b‖∞, ‖Δv‖∞) in every coordinate of every free slot. The error of Δv is
    /// (P A)⁻¹ z, so every slot's Δv is within tol·‖(P A)⁻¹‖∞ of that scale: exact after one
    /// iteration for unconnected slots (A diagonal), and near the tolerance as long as the
    /// springs are not much stiffer than the masses they join (h² k / m moderate). Before, the
    /// test was ‖r‖₂ ≤ tol ‖b‖₂ in force units, and a slot (or part) whose share of b was below
    /// tol of the largest — a light slot beside a heavy one — was left unsolved.
    ///
    /// Scale-safe: CG runs on 2^-β b and 2^-α A, with 2^β the binade of max |(P b)ᵢ| (to a
    /// factor 2, from the exponents of P and b: no product formed) and 2^α
    /// (`operator_exponent`) midway, in binades, between the smallest diagonal mass term
    /// mᵢ + h νᵢ of a free slot and the largest term of the operator (mᵢ + h νᵢ, h c_s, h² k_s
    /// over the free slots and their springs), so that z (Δv's units) starts near 1 and
    /// rᵀz, pᵀAp and the step lengths stay inside f64's range for a body of any size (finding
    /// 179: ‖b‖² under- or overflowed for edges beyond about 1e±33, and an underflowed ‖b‖ ended
    /// the solve with Δv = 0, every force dropped; round 23: with b rather than P b scaled to 1,
    /// z underflowed when the operator's terms spanned 2^1700). The
    /// factor 2^-α goes into the operator's coefficients — 2^-α (mᵢ + h νᵢ), 2^-α h² (k − kt),
    /// 2^-α h² kt and 2^-α h c, each formed in wide floats and rounded once — before any of them
    /// meets a vector, so no product of the unscaled operator is formed (finding 198: A p was
    /// formed first and scaled after, and mᵢ pᵢ overflowed for a free slot of mass ≈ 1e308;
    /// h² k, m + h ν overflowed for a stiffness or viscosity near `f64::MAX`). The preconditioner
    /// is built from these scaled coefficients, so it is 2^α D⁻¹. Powers of two scale exactly,
    /// so wherever the unscaled solve would neither over- nor underflow the iterates are its bits
    /// times powers of two, and Δv = 2^(β−α) y at the end is its Δv bit for bit; elsewhere the
    /// scaled solve keeps the operator's terms inside f64's range as long as they span less than
    /// about 2^1900 (a term below 2^-1074 of the largest is lost as an underflow, a Δv past
    /// `f64::MAX` is ±∞ and ends the step as a blow-up; a coordinate of 2^-β b below 2^-1074 —
    /// b's coordinates spanning more than that — is lost the same way). A breakdown (pᵀAp ≤ 0 or
    /// not finite, possible only past that span) is [`StepError::SolverFailed`]. Only an exactly
    /// zero b has nothing to solve (a b that underflowed was formed again in wide floats by
    /// `implicit`). O(iterations · (slots + springs)), plus O(slots + springs) for the scaling
    /// and the preconditioner.
    fn conjugate_gradient(&mut self, sys: &SpringSystem, h: f64, pre_scaled: Option<i32>) -> Result<usize, StepError> {
        let (par, tol) = (self.config.parallel, self.config.cg_tolerance);
        let cg = &mut self.cg;
        cg.dv.iter_mut().for_each(|d| *d = [0.0; 3]);
        // `f64::max` skips NaN: the NaN test comes before the zero test (finding 278: a b whose
        // every nonzero entry was NaN had b_max = 0 and was "solved" with Δv = 0).
        let b_max = cg.r.iter().flatten().fold(0.0f64, |m, c| m.max(c.abs()));
        if !b_max.is_finite() || cg.r.iter().flatten().any(|c| c.is_nan()) {
            // b overflowed or holds NaN: there is no finite right-hand side to solve for.
            let residual = dot_all(&cg.r, &cg.r).sqrt();
            return Err(StepError::SolverFailed { step: self.step, iterations: 0, residual });
        }
        if b_max == 0.0 {
            return Ok(0);
        }
        let op_exp = operator_exponent(sys, &cg.coef, h);
        scale_operator(sys, h, op_exp, &mut cg.coef, &mut cg.diag);
        jacobi(sys, &cg.dir, &cg.coef, &cg.diag, &mut cg.pre, par);
        // r = 2^-β b with 2^β the binade of max |(P b)ᵢ| (to a factor 2), so that the
        // preconditioned residual z — Δv's units — starts near 1: estimated from exponents, no
        // product of P and b formed (either may be far outside 1).
        let shift = preconditioned_binade(&cg.r, &cg.pre).unwrap_or(exponent(b_max));
        scale_all(&mut cg.r, -shift);
        let b_exp = pre_scaled.unwrap_or(0) + shift;
        // z₀ = P b, p₀ = z₀.
        let (mut rz, mut z_max, _) = cg.step_residual(0.0, false);
        cg.p.copy_from_slice(&cg.q);
        let z_b = z_max;
        let mut dv_max = 0.0;
        let solved = |cg: &mut CgBuffers, it: usize| {
            scale_all(&mut cg.dv, b_exp - op_exp);
            Ok(it)
        };
        for it in 0..self.config.cg_max_iterations {
            if z_max <= tol * max_of(z_b, dv_max) {
                return solved(cg, it);
            }
            apply_system(sys, &cg.dir, &cg.coef, &cg.diag, &cg.p, &mut self.sf, &mut cg.q, par);
            let pq = dot_all(&cg.p, &cg.q);
            if !(pq > 0.0 && pq.is_finite()) {
                // Breakdown: A is positive definite in exact arithmetic, so pᵀAp ≤ 0 (or not
                // finite) means its terms have left f64's range (beyond the documented span).
                let residual = z_max / max_of(z_b, dv_max);
                return Err(StepError::SolverFailed { step: self.step, iterations: it, residual });
            }
            let (rz_new, zm, dm) = cg.step_residual(rz / pq, true);
            let beta = rz_new / rz;
            (rz, z_max, dv_max) = (rz_new, zm, dm);
            for i in 0..cg.p.len() {
                cg.p[i] = madd(cg.q[i], beta, cg.p[i]);
            }
        }
        let residual = z_max / max_of(z_b, dv_max);
        if residual <= tol {
            return solved(cg, self.config.cg_max_iterations);
        }
        Err(StepError::SolverFailed { step: self.step, iterations: self.config.cg_max_iterations, residual })
    }
}

/// The Jacobi preconditioner of the scaled operator (after [`scale_operator`]): per free slot i
/// and coordinate j, 1 / Dᵢⱼ with Dᵢⱼ = `diag`ᵢ + Σ_{s ∋ i} (kt_s + (ka_s + c_s) n_sj²), the
/// diagonal entry of the operator [`apply_system`] applies (`coef` = (ka, kt, c) scaled); 0 on
/// fixed slots. A Dᵢⱼ that is not a normal number (the operator's terms spanning more than f64
/// holds, beyond the documented limit) gets 1, so that its coordinate is still searched and
/// tested. Each slot on its own, in the order of its incident springs: the same bits at any
/// thread count. O(slots + springs).
fn jacobi(sys: &SpringSystem, dir: &[Vec3], coef: &[[f64; 3]], diag: &[f64], pre: &mut [Vec3], par: bool) {
    sys.per_slot(pre, par, |i| {
        if sys.inv_mass[i] == 0.0 {
            return [0.0; 3];
        }
        let mut d = [diag[i]; 3];
        for (s, _) in sys.incident(i) {
            let ([ka, kt, c], n) = (coef[s], dir[s]);
            let axial = ka + c;
            for j in 0..3 {
                d[j] += kt + axial * n[j] * n[j];
            }
        }
        d.map(|e| if e.is_normal() { 1.0 / e } else { 1.0 })
    });
}

/// (aᵢ bᵢ)ᵢ.
#[inline(always)]
fn times(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] * b[0], a[1] * b[1], a[2] * b[2]]
}

/// max(m, |aⱼ|) over j, NaN once m or any aⱼ is NaN (so that a NaN never passes a stop test).
#[inline(always)]
fn max_abs(m: f64, a: Vec3) -> f64 {
    a.iter().fold(m, |m, c| if c.abs() > m || c.is_nan() { c.abs() } else { m })
}

/// max(a, b), NaN when either is.
#[inline(always)]
fn max_of(a: f64, b: f64) -> f64 {
    max_abs(a, [b, 0.0, 0.0])
}

/// Per spring: unit direction n and (k_axial, k_transverse, c) for the K and C blocks.
fn linearise(sys: &SpringSystem, x: &[Vec3], dir: &mut [Vec3], coef: &mut [[f64; 3]]) {
    for s in 0..sys.springs() {
        let [a, b] = sys.ends[s];
        let d = sub(x[b as usize], x[a as usize]);
        // Measured as rest lengths are (plain √(Σ dₖ²) at ordinary extents, scale-safe beyond),
        // so a needle's direction is a unit vector and a spring at rest has rest / l = 1.
        let l = super::geom::rest_length(x[a as usize], x[b as usize]);
        let (k, rest) = (sys.stiffness[s], sys.rest[s]);
        if l > 0.0 {
            dir[s] = [d[0] / l, d[1] / l, d[2] / l];
            coef[s] = [k, k * (1.0 - rest / l).max(0.0), sys.damping[s]];
        } else {
            dir[s] = [0.0; 3];
            coef[s] = [0.0, 0.0, 0.0];
        }
    }
}

/// out_s = wc·C_s w + wk·K_s w with w = u_b − u_a (C_s = c n nᵀ, K_s as in the module docs).
/// Returns whether a product of a spring with a free end underflowed: fell below the normal
/// range (to a subnormal or 0) while neither of its factors is 0, so that out_s is not the
/// product's rounding (finding 209: K ẋ₀ of a tiny stiffness). O(springs).
fn spring_products(
    sys: &SpringSystem,
    dir: &[Vec3],
    coef: &[[f64; 3]],
    u: &[Vec3],
    wc: f64,
    wk: f64,
    out: &mut [Vec3],
) -> bool {
    // p = a b, below the normal range while a, b ≠ 0.
    let lost = |p: f64, a: f64, b: f64| p.abs() < f64::MIN_POSITIVE && a != 0.0 && b != 0.0;
    let mut any = false;
    for s in 0..sys.springs() {
        let [a, b] = sys.ends[s];
        let w = sub(u[b as usize], u[a as usize]);
        let n = dir[s];
        let [k, kt, c] = coef[s];
        let along = dot(n, w);
        let (ka, ca, kw) = (wk * (k - kt), wc * c, wk * kt);
        let axial = ka * along + ca * along;
        out[s] = [kw * w[0] + axial * n[0], kw * w[1] + axial * n[1], kw * w[2] + axial * n[2]];
        if sys.inv_mass[a as usize] > 0.0 || sys.inv_mass[b as usize] > 0.0 {
            let mut l = lost(ka * along, ka, along) || lost(ca * along, ca, along);
            for j in 0..3 {
                l |= lost(n[j] * w[j], n[j], w[j]) || lost(kw * w[j], kw, w[j]) || lost(axial * n[j], axial, n[j]);
            }
            any |= l;
        }
    }
    any
}

/// Σ_{v = a} y_s − Σ_{v = b} y_s.
#[inline(always)]
fn gather(sys: &SpringSystem, i: usize, y: &[Vec3]) -> Vec3 {
    let mut f = [0.0; 3];
    for (s, sign) in sys.incident(i) {
        f = madd(f, sign, y[s]);
    }
    f
}

/// The exponent α of the implicit solve's operator scale 2^α: ⌊(e_lo + e_hi) / 2⌋, with e_lo
/// the binade of the smallest mᵢ + h νᵢ over the free slots and e_hi that of the largest term
/// of the operator over the free slots and the springs with a free end (mᵢ + h νᵢ, h c_s,
/// h² k_s), each estimated from its factors' exponents (within 2 of the true one, and no
/// product formed, so nothing over- or underflows). Scaled by 2^-α the terms lie within
/// 2^±((e_hi − e_lo) / 2 + 3) of 1. 0 with no free slot. Any α gives the same bits where
/// nothing over- or underflows; this one keeps the most room on both sides. O(slots + springs).
fn operator_exponent(sys: &SpringSystem, coef: &[[f64; 3]], h: f64) -> i32 {
    // exponent(a b) is exponent(a) + exponent(b) or one more, for a, b > 0.
    let eh = exponent(h);
    let free = |i: u32| sys.inv_mass[i as usize] > 0.0;
    let (mut lo, mut hi) = (i32::MAX, i32::MIN);
    for i in 0..sys.slots() {
        if sys.inv_mass[i] > 0.0 {
            let (m, nu) = (sys.mass[i], sys.viscosity[i]);
            // A free slot's mass is > 0 (inverse mass > 0).
            let mut e = exponent(m);
            if nu > 0.0 {
                e = e.max(eh + exponent(nu));
            }
            lo = lo.min(e);
            hi = hi.max(e);
        }
    }
    if lo == i32::MAX {
        return 0;
    }
    for (s, &[a, b]) in sys.ends.iter().enumerate() {
        if free(a) || free(b) {
            let [k, _, c] = coef[s];
            if k > 0.0 {
                hi = hi.max(2 * eh + exponent(k));
            }
            if c > 0.0 {
                hi = hi.max(eh + exponent(c));
            }
        }
    }
    (lo + hi).div_euclid(2)
}

/// The implicit right-hand side b = h f₀ + h² K ẋ₀ (0 on fixed slots) evaluated in wide floats
/// in the plain evaluation's order (K ẋ₀ spring by spring as `spring_products` forms it,
/// gathered, then h f₀ + (h h) g): when max |bᵢ| is at most `f64::MAX`, writes 2^-β b to `r`,
/// with 2^β the binade of max |bᵢ|, and returns β; else (b itself past `f64::MAX`, refused as
/// before) leaves `r` alone and returns `None`. For the rare b whose plain evaluation is not
/// finite while f₀ is — an intermediate (K ẋ₀, h², h f₀) overflowed — or one of whose terms
/// underflowed (h f₀, h², h² g or a product of K ẋ₀ below the normal range with factors ≠ 0:
/// b = 0 or a few bits where the exact b is ordinary, finding 209). The plain bits wherever the
/// plain evaluation is finite and normal. `y` and `b` are work buffers (spring products and b
/// in wide floats), kept by the caller so that a step allocates nothing once they have grown.
/// O(slots + springs).
#[allow(clippy::too_many_arguments)]
fn wide_rhs(
    sys: &SpringSystem,
    dir: &[Vec3],
    coef: &[[f64; 3]],
    v: &[Vec3],
    f0: &[Vec3],
    h: f64,
    y: &mut Vec<[Wide; 3]>,
    b: &mut Vec<[Wide; 3]>,
    r: &mut [Vec3],
) -> Option<i32> {
    let zero = Wide::new(0.0);
    y.clear();
    y.extend((0..sys.springs()).map(|s| {
        let [a, b] = sys.ends[s];
        let w = crate::wide::difference(v[b as usize], v[a as usize]);
        let n = dir[s].map(Wide::new);
        let [k, kt, _] = coef[s];
        let axial = Wide::new(k - kt).mul(crate::wide::dot(n, w));
        let kt = Wide::new(kt);
        [0, 1, 2].map(|j| kt.mul(w[j]).add(axial.mul(n[j])))
    }));
    let y: &[[Wide; 3]] = y;
    let (wh, wh2) = (Wide::new(h), Wide::new(h).mul(Wide::new(h)));
    b.clear();
    b.extend((0..sys.slots()).map(|i| {
        if sys.inv_mass[i] == 0.0 {
            return [zero; 3];
        }
        let mut g = [zero; 3];
        for (s, sign) in sys.incident(i) {
            g = [0, 1, 2].map(|j| g[j].add(if sign < 0.0 { y[s][j].neg() } else { y[s][j] }));
        }
        [0, 1, 2].map(|j| wh.mul(Wide::new(f0[i][j])).add(wh2.mul(g[j])))
    }));
    let b_max = b.iter().flatten().fold(zero, |m, c| if m.less_than(c.abs()) { c.abs() } else { m });
    if !b_max.to_f64().is_finite() {
        return None;
    }
    let beta = if b_max.is_zero() { 0 } else { wide_exponent(b_max) };
    let scale = wide_pow2(-beta);
    for (ri, bi) in r.iter_mut().zip(b.iter()) {
        *ri = bi.map(|c| c.mul(scale).to_f64());
    }
    Some(beta)
}

/// The exponent k with 2^k ≤ w < 2^(k+1) of a finite w > 0 of any size. O(|k| / 1000).
fn wide_exponent(w: Wide) -> i32 {
    let (mut x, mut shift) = (w, 0);
    loop {
        let t = x.to_f64();
        if t.is_infinite() {
            (x, shift) = (x.mul(wide_pow2(-1000)), shift + 1000);
        } else if t < f64::MIN_POSITIVE {
            (x, shift) = (x.mul(wide_pow2(1000)), shift - 1000);
        } else {
            return shift + exponent(t);
        }
    }
}

/// 2^e as a wide float, exactly, for any e. O(|e| / 1000).
fn wide_pow2(mut e: i32) -> Wide {
    let mut w = Wide::new(1.0);
    while e != 0 {
        let step = e.clamp(-1000, 1000);
        w = w.mul(Wide::new(pow2(step)));
        e -= step;
    }
    w
}

/// Scales the operator by 2^-α before CG: `diag`ᵢ = 2^-α (mᵢ + h νᵢ) on the free slots (0 on
/// fixed ones), and `coef` (k, kt, c) of each spring with a free end becomes 2^-α (h² (k − kt),
/// h² kt, h c) (0 for a spring between fixed slots, which no free slot gathers). Each is the
/// plain formula (h² rounded as h·h, m + h ν as in f64) evaluated with an unbounded exponent and
/// rounded once to f64: 2^-α times the plain value, bit for bit, wherever the plain value neither
/// over- nor underflows, and otherwise the scaled value the plain one would have with an
/// unbounded exponent. The plain value times 2^-α where it and the result are normal (exact
/// there, and so the same bits), wide floats elsewhere. O(slots + springs).
fn scale_operator(sys: &SpringSystem, h: f64, alpha: i32, coef: &mut [[f64; 3]], diag: &mut [f64]) {
    let scale = wide_pow2(-alpha);
    let (f1, f2) = (pow2(-alpha / 2), pow2(-alpha - (-alpha / 2)));
    let (wh, hh) = (Wide::new(h), h * h);
    let wh2 = wh.mul(wh);
    // 2^-α x for x = `plain` when the plain evaluation kept every bit (`exact`), else from `wide`.
    let scaled = |plain: f64, exact: bool, wide: &dyn Fn() -> Wide| {
        let y = plain * f1 * f2;
        match exact && plain.is_normal() && y.is_normal() {
            true => y,
            false => wide().mul(scale).to_f64(),
        }
    };
    // h² x and h x, scaled; exactly 0 for x = 0.
    let h2_times = |x: f64| match x == 0.0 {
        true => 0.0,
        false => scaled(hh * x, hh.is_normal(), &|| wh2.mul(Wide::new(x))),
    };
    let h_times = |x: f64| match x == 0.0 {
        true => 0.0,
        false => scaled(h * x, true, &|| wh.mul(Wide::new(x))),
    };
    let free = |i: u32| sys.inv_mass[i as usize] > 0.0;
    for (i, d) in diag.iter_mut().enumerate() {
        let (m, nu) = (sys.mass[i], sys.viscosity[i]);
        *d = match sys.inv_mass[i] > 0.0 {
            true => scaled(m + h * nu, nu == 0.0 || (h * nu).is_normal(), &|| Wide::new(m).add(wh.mul(Wide::new(nu)))),
            false => 0.0,
        };
    }
    for (s, &[a, b]) in sys.ends.iter().enumerate() {
        let [k, kt, c] = coef[s];
        coef[s] = match free(a) || free(b) {
            true => [h2_times(k - kt), h2_times(kt), h_times(c)],
            false => [0.0; 3],
        };
    }
}

/// q = S 2^-α (M + h(Γ + C) + h² K) p, S zeroing fixed slots, from the scaled coefficients of
/// [`scale_operator`] (`diag`, and `coef` = 2^-α (h² (k − kt), h² kt, h c) per spring): every
/// product is one of the scaled operator, in the order of the plain one's evaluation
/// (h² (k − kt) · (n·w) + h c · (n·w) along n, h² kt · w across), so each is 2^-α times the
/// plain product, bit for bit, where neither over- nor underflows.
#[allow(clippy::too_many_arguments)]
fn apply_system(
    sys: &SpringSystem,
    dir: &[Vec3],
    coef: &[[f64; 3]],
    diag: &[f64],
    p: &[Vec3],
    y: &mut [Vec3],
    q: &mut [Vec3],
    par: bool,
) {
    for s in 0..sys.springs() {
        let [a, b] = sys.ends[s];
        let w = sub(p[b as usize], p[a as usize]);
        let n = dir[s];
        let [ka, kt, c] = coef[s];
        let along = dot(n, w);
        let axial = ka * along + c * along;
        y[s] = [kt * w[0] + axial * n[0], kt * w[1] + axial * n[1], kt * w[2] + axial * n[2]];
    }
    let y: &[Vec3] = y;
    let value = |i: usize| {
        if sys.inv_mass[i] == 0.0 {
            return [0.0; 3];
        }
        let g = gather(sys, i, y);
        let d = diag[i];
        [d * p[i][0] - g[0], d * p[i][1] - g[1], d * p[i][2] - g[2]]
    };
    if par && q.len() > PARALLEL_CHUNK {
        q.par_iter_mut().enumerate().for_each(|(i, o)| *o = value(i));
    } else {
        q.iter_mut().enumerate().for_each(|(i, o)| *o = value(i));
    }
}

/// Every coordinate of `a` times 2^e: in two steps for e in [−2046, 2046] (exact; a product
/// leaving f64's range gives 0 or ±∞ as it would in one step), beyond in steps of at most
/// 2^±1022 (`crate::mesh::times_pow2`, exact wherever the result is normal). O(len).
fn scale_all(a: &mut [Vec3], e: i32) {
    if (-2046..=2046).contains(&e) {
        let (f1, f2) = (pow2(e / 2), pow2(e - e / 2));
        a.iter_mut().flatten().for_each(|c| *c = *c * f1 * f2);
    } else {
        a.iter_mut().flatten().for_each(|c| *c = crate::mesh::times_pow2(*c, e as i64));
    }
}

fn dot_all(a: &[Vec3], b: &[Vec3]) -> f64 {
    a.iter().zip(b).map(|(x, y)| dot(*x, *y)).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mechanics::SystemError;

    /// The energy scale is exactly kinetic + elastic + M |g| D, and Σ ½ k L² when that is 0.
    #[test]
    fn energy_scale_is_its_documented_sum() {
        let mut sys = SpringSystem::default();
        sys.set_gravity([0.0, 0.0, -10.0]).unwrap();
        sys.push_slot(1.0, false, 0.0).unwrap();
        sys.push_slot(3.0, false, 0.0).unwrap();
        sys.push_spring([0, 1], 5.0, 10.0, 0.0).unwrap(); // at its rest length below: no elastic energy
        let x = vec![[0.0; 3], [3.0, 4.0, 0.0]]; // D = 5
        let v = vec![[1.0, 0.0, 0.0], [0.0; 3]]; // kinetic ½
        assert_eq!(energy_scale(&sys, &x, &v), 0.5 + 4.0 * 10.0 * 5.0);
        sys.set_gravity([0.0; 3]).unwrap();
        assert_eq!(energy_scale(&sys, &x, &[[0.0; 3]; 2]), 0.5 * 10.0 * 25.0); // Σ ½ k L²
        let stretched = vec![[0.0; 3], [9.0, 12.0, 0.0]]; // l = 15: ½ k (l − L)² = 500
        assert_eq!(energy_scale(&sys, &stretched, &[[0.0; 3]; 2]), 500.0);
        // A massless slot far away (a vertex id no tet uses) does not stretch D (finding 217).
        sys.set_gravity([0.0, 0.0, -10.0]).unwrap();
        sys.push_slot(0.0, false, 0.0).unwrap();
        let far = vec![[0.0; 3], [3.0, 4.0, 0.0], [1e6, 0.0, 0.0]];
        assert_eq!(energy_scale(&sys, &far, &[[0.0; 3]; 3]), 4.0 * 10.0 * 5.0);
    }

    /// A chain of `n` unit masses on springs, the first pinned, hanging under gravity.
    fn chain(n: usize) -> (SpringSystem, Vec<Vec3>, Vec<Vec3>) {
        let mut sys = SpringSystem::default();
        sys.set_gravity([0.0, 0.0, -10.0]).unwrap();
        for i in 0..n {
            sys.push_slot(1.0, i == 0, 0.1).unwrap();
        }
        for i in 1..n {
            sys.push_spring([(i - 1) as u32, i as u32], 1.0, 100.0, 0.1).unwrap();
        }
        let x = (0..n).map(|i| [0.0, 0.0, -(i as f64)]).collect();
        (sys, x, vec![[0.0; 3]; n])
    }

    /// Finding 25: `Stepper::new` refuses a system with a NaN, negative or misplaced value, named.
    /// Since finding 36 such a system can only be made inside the crate (the arrays are private
    /// and every way in checks), so the refusals are tested here.
    #[test]
    fn stepper_new_refuses_a_broken_system() {
        type Tamper = fn(&mut SpringSystem);
        let cases: [(Tamper, &str); 11] = [
            (|s| s.mass[1] = f64::NAN, "mass of slot 1 is NaN"),
            (|s| s.mass[2] = -1.0, "mass of slot 2 is -1"),
            (|s| s.inv_mass[3] = f64::INFINITY, "inverse mass of slot 3 is inf"),
            (|s| s.viscosity[0] = -0.5, "viscosity of slot 0 is -0.5"),
            (|s| s.rest[0] = f64::NAN, "rest length of spring 0 is NaN"),
            (|s| s.stiffness[2] = f64::NAN, "stiffness of spring 2 is NaN"),
            (|s| s.damping[1] = -2.0, "damping of spring 1 is -2"),
            (|s| s.gravity[1] = f64::NAN, "gravity [0.0, NaN, -10.0] is not finite"),
            (|s| s.ends[1] = [1, 9], "spring 1 joins slots [1, 9]"),
            (|s| s.ends[2] = [3, 3], "spring 2 joins slots [3, 3]"),
            (|s| s.damping.truncate(2), "damping has 2 entries for 3 springs"),
        ];
        for (tamper, expected) in cases {
            let (mut sys, x, v) = chain(4);
            tamper(&mut sys);
            for integrator in [Integrator::Euler, Integrator::Rk4, Integrator::Implicit] {
                match Stepper::new(StepConfig::new(integrator, 1e-3), &sys, &x, &v) {
                    Err(StepError::BadInput(text)) => assert!(text.starts_with(expected), "{expected}: {text}"),
                    other => panic!("{expected}: {other:?}"),
                }
            }
        }
    }

    /// Finding 28: the public passes and `check` find a spring end past the slots, a short array
    /// and a NaN value instead of indexing them (a system broken inside the crate, as above).
    #[test]
    fn passes_and_check_refuse_a_system_broken_inside_the_crate() {
        let (sys, _, _) = chain(3);
        let (x, v) = (vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 3.0, 0.0]], vec![[1.0, 0.0, 0.0]; 3]);
        let (mut sf, mut out) = (vec![[0.0; 3]; 2], vec![[0.0; 3]; 3]);
        let mut broken = sys.clone();
        broken.ends[1] = [1, 8];
        let bad_ends = Err(SystemError::BadEnds { spring: 1, ends: [1, 8], slots: 3 });
        assert_eq!(broken.forces(&x, &v, &mut sf, &mut out, false), bad_ends);
        assert_eq!(broken.elastic_energy(&x), Err(SystemError::BadEnds { spring: 1, ends: [1, 8], slots: 3 }));
        broken.viscosity.pop();
        let short = Err(SystemError::Length { array: "viscosity", len: 2, expected: 3, of: "slots" });
        assert_eq!(broken.check(), short);
        let mut nan = sys.clone();
        nan.damping[1] = f64::NAN;
        assert!(matches!(nan.check(), Err(SystemError::BadValue { quantity: "damping", of: "spring", index: 1, .. })));
        assert_eq!(sys.check(), Ok(()));
    }
}
