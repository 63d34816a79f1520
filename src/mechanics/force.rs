//! Forces of the mass/spring model on plain arrays, and the orbit-walk reference.
//!
//! Forces on a vertex v (all laws in `docs/MECHANICS.md`):
//! - gravity m_v g;
//! - ambient viscosity −γ_v ẋ_v;
//! - each spring s = (a, b) with rest length L, stiffness k, damping c: with d = x_b − x_a,
//!   l = |d|, n = d / l, the force on a is F_s = [k (l − L) + c (ẋ_b − ẋ_a)·n] n and the force on
//!   b is −F_s (Hooke's law plus damping along the spring).
//!
//! [`SpringSystem`] evaluates them in two passes: one over the springs writing F_s into an array,
//! then one over the vertices gathering, through a list of incident springs per vertex, minus the
//! F_s of the springs that end at v (tails), then plus those that start at v (heads). No two
//! writes go to the same slot, so both passes split freely across threads and the result is
//! bitwise the same for any thread count: each vertex sums its own lists in their stored order.
//!
//! # Spring sums
//! On a fresh system whose springs are sorted by first end with a < b
//! ([`SpringSystem::sorted_by_first_end`], the layout of `FlatModel` and of a fresh `Projection`),
//! the tails of v are the springs before its heads in spring order, each list ascending. Adding
//! +F_s at a and −F_s at b into a per-slot sum while walking the springs in order then performs
//! exactly the gather's operations in the gather's order, so the RK4 stepper does that: one pass
//! over the springs, no per-spring force array written and read back, no incidence lists read
//! (about 100 fewer bytes per spring and stage on a mesh that does not fit in cache). On several
//! threads the slots are cut into ranges that each take the springs of their first ends; a range
//! first adds the forces of earlier ranges' springs that end in it, so every slot still sums in
//! spring order (the same bits for any split and thread count). The sum of the current first
//! end stays in a register over its run of springs (no −F_s reaches it meanwhile, as b > a) and
//! is stored when the run ends, which spares a store-to-load chain through memory per spring.
//!
//! # Incidence lists with slack
//! The lists live in one array `adj`; vertex v owns the segment `adj[start..start + cap]`, whose
//! first `heads` entries are the springs with a = v and the next `len − heads` those with b = v:
//!
//! ```text
//!   adj: … | s3 s9 │ s4 · · | s1 s2 s7 │ s8 | …      (│ = heads/tails border, · = slack)
//!          └── v ─────────┘ └── w ─────────┘
//! ```
//!
//! A fresh [`SpringSystem::new`] packs the segments tightly in slot order with heads before tails
//! (the classic CSR, so a fresh build sums in the same order as before). The mutators
//! ([`SpringSystem::push_slot`], [`SpringSystem::push_spring`], [`SpringSystem::set_spring`],
//! [`SpringSystem::swap_remove_spring`]) edit only the segments of the ends involved, O(degree):
//! a full segment moves to the end of `adj` with twice the capacity, and the array is compacted
//! once the abandoned space exceeds the live entries (amortised O(degree) per change).

use rayon::prelude::*;

use super::geom::{dot, Vec3};
use super::simd::{multiversion, Kernel};
use crate::wide::Wide;

/// Spring and vertex count above which the parallel passes are worth their overhead.
pub const PARALLEL_CHUNK: usize = 4096;

/// The mass/spring system as flat arrays: what the step loop reads.
///
/// Vertices are *slots* `0..slots()`: positions and velocities are passed in as slices of that
/// length. A slot with `inv_mass == 0` (fixed: pinned, dead or massless) has no acceleration: it
/// keeps its velocity, so it stays put at velocity 0 and moves at constant velocity otherwise (a
/// driven pin, in every scheme of [`crate::mechanics::Stepper`]; a force on it that is not
/// finite is a blow-up in the explicit schemes, docs/MECHANICS.md); its kinetic energy counts
/// nowhere ([`SpringSystem::kinetic_energy`], the runaway test). Equality compares
/// the arrays and, per slot, the incident lists in order (not where they sit in memory).
///
/// # Examples
///
/// ```
/// use topomech::mechanics::SpringSystem;
///
/// let mut sys = SpringSystem::default();
/// let (a, b) = (sys.push_slot(2.0, false, 0.0).unwrap(), sys.push_slot(1.0, true, 0.0).unwrap());
/// let s = sys.push_spring([a as u32, b as u32], 1.0, 50.0, 0.1).unwrap();
/// assert_eq!((sys.slots(), sys.springs()), (2, 1));
/// assert_eq!((sys.inv_mass()[a], sys.inv_mass()[b]), (0.5, 0.0)); // slot b is fixed
/// assert_eq!(sys.incident(a).map(|(spring, _)| spring).collect::<Vec<_>>(), vec![s]);
/// assert!(sys.check_incidence().is_ok());
/// ```
///
/// The arrays are read through accessors and written only through the checked mutators, so a
/// spring end past the slots (which made `Stepper::step` index out of bounds, finding 36) does
/// not compile:
///
/// ```compile_fail
/// use topomech::mechanics::SpringSystem;
///
/// let mut sys = SpringSystem::default();
/// sys.push_slot(1.0, false, 0.0).unwrap();
/// sys.push_slot(1.0, false, 0.0).unwrap();
/// sys.push_spring([0, 1], 1.0, 1.0, 0.0).unwrap();
/// sys.ends[0] = [0, 7]; // private field
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SpringSystem {
    // The arrays are crate-private and read through the accessors of the same names: every
    // way in ([`SpringSystem::new`] and the mutators) checks what it stores, so a system is
    // always what [`SpringSystem::check`] accepts and the step loop can trust it (finding 36).
    /// Spring end slots (a, b).
    pub(crate) ends: Vec<[u32; 2]>,
    /// Rest length L of each spring.
    pub(crate) rest: Vec<f64>,
    /// Stiffness k of each spring.
    pub(crate) stiffness: Vec<f64>,
    /// Damping c of each spring.
    pub(crate) damping: Vec<f64>,
    /// Mass of each slot.
    pub(crate) mass: Vec<f64>,
    /// 1/m for a free slot, 0 for a fixed one.
    pub(crate) inv_mass: Vec<f64>,
    /// Ambient viscosity γ of each slot.
    pub(crate) viscosity: Vec<f64>,
    /// Gravity acceleration g.
    pub(crate) gravity: Vec3,
    /// Incident springs per slot (module docs). Change `ends` only through the mutators, which
    /// keep it in step; [`SpringSystem::check_incidence`] verifies it.
    inc: Incidence,
}

impl SpringSystem {
    /// A system from its arrays; builds the incidence lists packed (module docs). O(slots + springs).
    ///
    /// `inv_mass` is derived: 0 on a fixed slot or one of mass 0, else 1/mass.
    ///
    /// # Errors
    /// What [`SpringSystem::check`] refuses, before anything is built: arrays that disagree in
    /// length ([`SystemError::Length`]), a spring whose ends are not two different slots
    /// ([`SystemError::BadEnds`]), a mass, viscosity, rest length, stiffness or damping that is
    /// negative or not finite ([`SystemError::BadValue`]), a non-finite gravity.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::{SpringSystem, SystemError};
    ///
    /// let sys = SpringSystem::new(
    ///     vec![[0, 1]], vec![1.0], vec![10.0], vec![0.0], // ends, rest length, stiffness, damping
    ///     vec![1.0, 2.0], &[false, true], vec![0.0; 2], [0.0; 3], // mass, fixed, viscosity, gravity
    /// )
    /// .unwrap();
    /// assert_eq!(sys.inv_mass(), vec![1.0, 0.0]); // slot 1 is fixed
    /// assert_eq!((sys.slots(), sys.springs()), (2, 1));
    /// assert_eq!(sys.incident(1).collect::<Vec<_>>(), vec![(0, -1.0)]); // end b of spring 0
    /// sys.check_incidence().unwrap();
    /// // A spring to a slot that does not exist is named, not a panic.
    /// let bad = SpringSystem::new(vec![[0, 5]], vec![1.0], vec![1.0], vec![0.0], vec![1.0; 2], &[false; 2], vec![0.0; 2], [0.0; 3]);
    /// assert_eq!(bad, Err(SystemError::BadEnds { spring: 0, ends: [0, 5], slots: 2 }));
    /// ```
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        ends: Vec<[u32; 2]>,
        rest: Vec<f64>,
        stiffness: Vec<f64>,
        damping: Vec<f64>,
        mass: Vec<f64>,
        fixed: &[bool],
        viscosity: Vec<f64>,
        gravity: Vec3,
    ) -> Result<Self, SystemError> {
        if fixed.len() != mass.len() {
            return Err(SystemError::Length { array: "fixed", len: fixed.len(), expected: mass.len(), of: "slots" });
        }
        let inv_mass = mass.iter().zip(fixed).map(|(&m, &f)| inverse_mass(m, f)).collect();
        let mut sys = SpringSystem {
            ends,
            rest,
            stiffness,
            damping,
            mass,
            inv_mass,
            viscosity,
            gravity,
            inc: Incidence::default(),
        };
        sys.check()?;
        sys.inc = Incidence::packed(sys.slots(), &sys.ends);
        Ok(sys)
    }

    /// [`SpringSystem::new`] for the crate's builders, whose arrays are right by construction
    /// (checked in debug builds). O(slots + springs).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn from_arrays(
        ends: Vec<[u32; 2]>,
        rest: Vec<f64>,
        stiffness: Vec<f64>,
        damping: Vec<f64>,
        mass: Vec<f64>,
        fixed: &[bool],
        viscosity: Vec<f64>,
        gravity: Vec3,
    ) -> Self {
        let inv_mass = mass.iter().zip(fixed).map(|(&m, &f)| inverse_mass(m, f)).collect();
        let inc = Incidence::packed(mass.len(), &ends);
        let sys = SpringSystem { ends, rest, stiffness, damping, mass, inv_mass, viscosity, gravity, inc };
        debug_assert_eq!(sys.check_shape(), Ok(()));
        sys
    }

    /// Whether the system can be stepped: every array has one entry per slot or per spring,
    /// every spring joins two different slots, every mass, inverse mass, viscosity, rest length,
    /// stiffness and damping is finite and ≥ 0, gravity is finite. O(slots + springs).
    ///
    /// Every way in ([`SpringSystem::new`], the mutators, [`SpringSystem::set_gravity`]) refuses
    /// what this check refuses and the arrays are private (finding 36), so a system made through
    /// the API always passes; the stepper runs it once anyway, as a guard against the crate's own
    /// unchecked builders.
    ///
    /// # Errors
    /// The first fault found, as a [`SystemError`] naming the array, spring or slot.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::{SpringSystem, SystemError};
    ///
    /// let mut sys = SpringSystem::default();
    /// sys.push_slot(1.0, false, 0.0).unwrap();
    /// assert_eq!(sys.check(), Ok(()));
    /// let refused = sys.set_slot(0, 1.0, false, f64::NAN); // the way in checks first
    /// assert!(matches!(refused, Err(SystemError::BadValue { quantity: "viscosity", index: 0, .. })));
    /// assert_eq!(sys.check(), Ok(())); // nothing was stored
    /// ```
    pub fn check(&self) -> Result<(), SystemError> {
        self.check_shape()?;
        let per_slot = [("mass", &self.mass), ("inverse mass", &self.inv_mass), ("viscosity", &self.viscosity)];
        let per_spring = [("rest length", &self.rest), ("stiffness", &self.stiffness), ("damping", &self.damping)];
        let all = per_slot.map(|(q, a)| (q, a, "slot")).into_iter().chain(per_spring.map(|(q, a)| (q, a, "spring")));
        for (quantity, values, of) in all {
            if let Some((index, &value)) = values.iter().enumerate().find(|(_, &x)| !is_amount(x)) {
                return Err(SystemError::BadValue { quantity, of, index, value });
            }
        }
        match self.gravity.iter().all(|g| g.is_finite()) {
            true => Ok(()),
            false => Err(SystemError::BadGravity(self.gravity)),
        }
    }

    /// The structural part of [`SpringSystem::check`]: array lengths and spring ends (what the
    /// force and energy passes index by). O(springs).
    fn check_shape(&self) -> Result<(), SystemError> {
        self.check_given(&[], &[])?;
        self.check_ends()
    }

    /// [`SystemError::BadEnds`] for the first spring whose ends are not two different slots.
    /// O(springs).
    fn check_ends(&self) -> Result<(), SystemError> {
        let n = self.slots();
        match self.ends.iter().position(|&e| !ends_ok(e, n)) {
            Some(spring) => Err(SystemError::BadEnds { spring, ends: self.ends[spring], slots: n }),
            None => Ok(()),
        }
    }

    /// One entry per slot in the system's per-slot arrays and in each of `per_slot`, one per
    /// spring in its per-spring arrays and in each of `per_spring` (name, length): what a pass
    /// that does not follow the spring ends needs. O(1).
    fn check_given(
        &self,
        per_slot: &[(&'static str, usize)],
        per_spring: &[(&'static str, usize)],
    ) -> Result<(), SystemError> {
        let (n, s) = (self.slots(), self.springs());
        let own_slot = [("inverse mass", self.inv_mass.len()), ("viscosity", self.viscosity.len())];
        let own_spring =
            [("rest length", self.rest.len()), ("stiffness", self.stiffness.len()), ("damping", self.damping.len())];
        let slot_arrays = own_slot.iter().chain(per_slot).map(|&(a, l)| (a, l, n, "slots"));
        let spring_arrays = own_spring.iter().chain(per_spring).map(|&(a, l)| (a, l, s, "springs"));
        for (array, len, expected, of) in slot_arrays.chain(spring_arrays) {
            if len != expected {
                return Err(SystemError::Length { array, len, expected, of });
            }
        }
        Ok(())
    }

    /// [`SpringSystem::check_given`] and the spring ends: what a pass over the springs needs.
    /// O(springs).
    fn check_state(
        &self,
        per_slot: &[(&'static str, usize)],
        per_spring: &[(&'static str, usize)],
    ) -> Result<(), SystemError> {
        self.check_given(per_slot, per_spring)?;
        self.check_ends()
    }

    /// Appends a slot with mass `mass` (fixed when `fixed` or `mass == 0`) and viscosity
    /// `viscosity`, with no spring; returns its index. O(1) amortised.
    ///
    /// # Errors
    /// [`SystemError::BadValue`] (with the index the slot would have had) for a mass or
    /// viscosity that is negative or not finite; nothing is appended.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::SpringSystem;
    ///
    /// let mut sys = SpringSystem::default();
    /// assert_eq!(sys.push_slot(2.0, false, 0.1), Ok(0));
    /// assert_eq!(sys.push_slot(3.0, true, 0.0), Ok(1)); // fixed: infinite inertia
    /// assert_eq!(sys.inv_mass(), vec![0.5, 0.0]);
    /// assert_eq!(sys.incident(1).count(), 0); // no spring yet
    /// assert!(sys.push_slot(f64::NAN, false, 0.0).is_err());
    /// assert_eq!(sys.slots(), 2);
    /// ```
    pub fn push_slot(&mut self, mass: f64, fixed: bool, viscosity: f64) -> Result<usize, SystemError> {
        check_slot_values(self.slots(), mass, viscosity)?;
        Ok(self.push_slot_raw(mass, fixed, viscosity))
    }

    /// [`SpringSystem::push_slot`] without the value check (the crate's builders). O(1) amortised.
    pub(crate) fn push_slot_raw(&mut self, mass: f64, fixed: bool, viscosity: f64) -> usize {
        self.mass.push(0.0);
        self.inv_mass.push(0.0);
        self.viscosity.push(0.0);
        self.inc.push_slot();
        let v = self.mass.len() - 1;
        self.set_slot_raw(v, mass, fixed, viscosity);
        v
    }

    /// Sets slot v's mass, fixedness and viscosity (`inv_mass` = 0 when fixed or `mass == 0`,
    /// else 1/mass). O(1).
    ///
    /// # Errors
    /// [`SystemError::NoSuchSlot`], [`SystemError::BadValue`]; nothing changes.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::{SpringSystem, SystemError};
    ///
    /// let mut sys = SpringSystem::default();
    /// let v = sys.push_slot(1.0, false, 0.0).unwrap();
    /// sys.set_slot(v, 4.0, false, 0.5).unwrap();
    /// assert_eq!((sys.mass()[v], sys.inv_mass()[v], sys.viscosity()[v]), (4.0, 0.25, 0.5));
    /// sys.set_slot(v, 4.0, true, 0.5).unwrap(); // pin it
    /// assert_eq!(sys.inv_mass()[v], 0.0);
    /// assert_eq!(sys.set_slot(7, 1.0, false, 0.0), Err(SystemError::NoSuchSlot { slot: 7, slots: 1 }));
    /// ```
    pub fn set_slot(&mut self, v: usize, mass: f64, fixed: bool, viscosity: f64) -> Result<(), SystemError> {
        self.check_slot(v)?;
        check_slot_values(v, mass, viscosity)?;
        self.set_slot_raw(v, mass, fixed, viscosity);
        Ok(())
    }

    /// [`SpringSystem::set_slot`] without the checks (v must be a slot). O(1).
    pub(crate) fn set_slot_raw(&mut self, v: usize, mass: f64, fixed: bool, viscosity: f64) {
        self.mass[v] = mass;
        self.viscosity[v] = viscosity;
        self.inv_mass[v] = inverse_mass(mass, fixed);
    }

    /// Appends spring `ends` = (a, b) with rest length, stiffness and damping; returns its index.
    /// O(degree of a and b) amortised.
    ///
    /// # Errors
    /// [`SystemError::BadEnds`] unless a and b are two different slots, [`SystemError::BadValue`]
    /// for a negative or non-finite rest length, stiffness or damping; nothing is appended.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::{SpringSystem, SystemError};
    ///
    /// let mut sys = SpringSystem::default();
    /// let (a, b) = (sys.push_slot(1.0, false, 0.0).unwrap(), sys.push_slot(0.0, false, 0.0).unwrap());
    /// assert_eq!(sys.inv_mass(), vec![1.0, 0.0]); // a massless slot does not move
    /// let s = sys.push_spring([a as u32, b as u32], 1.0, 3.0, 0.0).unwrap();
    /// assert_eq!((s, sys.springs()), (0, 1));
    /// assert_eq!(sys.incident(a).collect::<Vec<_>>(), vec![(s, 1.0)]);
    /// assert_eq!(sys.push_spring([1, 1], 1.0, 3.0, 0.0), Err(SystemError::BadEnds { spring: 1, ends: [1, 1], slots: 2 }));
    /// sys.check_incidence().unwrap();
    /// ```
    pub fn push_spring(
        &mut self,
        ends: [u32; 2],
        rest: f64,
        stiffness: f64,
        damping: f64,
    ) -> Result<usize, SystemError> {
        self.check_spring_values(self.springs(), ends, rest, stiffness, damping)?;
        Ok(self.push_spring_raw(ends, rest, stiffness, damping))
    }

    /// [`SpringSystem::push_spring`] without the checks (the ends must be two different slots).
    pub(crate) fn push_spring_raw(&mut self, ends: [u32; 2], rest: f64, stiffness: f64, damping: f64) -> usize {
        debug_assert!(ends_ok(ends, self.slots()), "bad spring ends {ends:?}");
        let s = self.ends.len();
        self.ends.push(ends);
        self.rest.push(rest);
        self.stiffness.push(stiffness);
        self.damping.push(damping);
        self.inc.insert(ends[0] as usize, true, s as u32);
        self.inc.insert(ends[1] as usize, false, s as u32);
        s
    }

    /// Rewrites spring s: its ends (moving it between incidence lists when they change), rest
    /// length, stiffness and damping. O(degree of the old and new ends) amortised.
    ///
    /// # Errors
    /// [`SystemError::NoSuchSpring`], and what [`SpringSystem::push_spring`] refuses; nothing
    /// changes.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::{SpringSystem, SystemError};
    ///
    /// let mut sys = SpringSystem::default();
    /// (0..3).for_each(|_| drop(sys.push_slot(1.0, false, 0.0)));
    /// sys.push_spring([0, 1], 1.0, 1.0, 0.0).unwrap();
    /// sys.set_spring(0, [0, 2], 2.0, 5.0, 0.1).unwrap(); // re-attach end b to slot 2
    /// assert_eq!((sys.incident(1).count(), sys.incident(2).count()), (0, 1));
    /// assert_eq!((sys.rest()[0], sys.stiffness()[0], sys.damping()[0]), (2.0, 5.0, 0.1));
    /// assert_eq!(sys.set_spring(3, [0, 1], 1.0, 1.0, 0.0), Err(SystemError::NoSuchSpring { spring: 3, springs: 1 }));
    /// sys.check_incidence().unwrap();
    /// ```
    pub fn set_spring(
        &mut self,
        s: usize,
        ends: [u32; 2],
        rest: f64,
        stiffness: f64,
        damping: f64,
    ) -> Result<(), SystemError> {
        self.check_spring(s)?;
        self.check_spring_values(s, ends, rest, stiffness, damping)?;
        self.set_spring_raw(s, ends, rest, stiffness, damping);
        Ok(())
    }

    /// [`SpringSystem::set_spring`] without the checks.
    pub(crate) fn set_spring_raw(&mut self, s: usize, ends: [u32; 2], rest: f64, stiffness: f64, damping: f64) {
        debug_assert!(ends_ok(ends, self.slots()), "bad spring ends {ends:?}");
        let old = self.ends[s];
        if old != ends {
            self.inc.remove(old[0] as usize, true, s as u32);
            self.inc.remove(old[1] as usize, false, s as u32);
            self.inc.insert(ends[0] as usize, true, s as u32);
            self.inc.insert(ends[1] as usize, false, s as u32);
            self.ends[s] = ends;
        }
        self.rest[s] = rest;
        self.stiffness[s] = stiffness;
        self.damping[s] = damping;
    }

    /// Removes spring s; the last spring takes its index (its incidence entries are renamed).
    /// Returns the former index of the moved spring, `None` if s was last. O(degree of the ends
    /// of both springs).
    ///
    /// # Errors
    /// [`SystemError::NoSuchSpring`]; nothing changes.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::SpringSystem;
    ///
    /// let mut sys = SpringSystem::default();
    /// (0..3).for_each(|_| drop(sys.push_slot(1.0, false, 0.0)));
    /// sys.push_spring([0, 1], 1.0, 1.0, 0.0).unwrap();
    /// sys.push_spring([1, 2], 1.0, 1.0, 0.0).unwrap();
    /// assert_eq!(sys.swap_remove_spring(0), Ok(Some(1))); // spring 1 moved into index 0
    /// assert_eq!((sys.springs(), sys.ends()[0]), (1, [1, 2]));
    /// assert_eq!(sys.incident(0).count(), 0);
    /// assert!(sys.swap_remove_spring(1).is_err()); // only spring 0 is left
    /// sys.check_incidence().unwrap();
    /// ```
    pub fn swap_remove_spring(&mut self, s: usize) -> Result<Option<usize>, SystemError> {
        self.check_spring(s)?;
        Ok(self.swap_remove_spring_raw(s))
    }

    /// [`SpringSystem::swap_remove_spring`] without the check (s must be a spring).
    pub(crate) fn swap_remove_spring_raw(&mut self, s: usize) -> Option<usize> {
        let [a, b] = self.ends[s];
        self.inc.remove(a as usize, true, s as u32);
        self.inc.remove(b as usize, false, s as u32);
        let last = self.ends.len() - 1;
        let moved = (last != s).then(|| {
            let [la, lb] = self.ends[last];
            self.inc.rename(la as usize, true, last as u32, s as u32);
            self.inc.rename(lb as usize, false, last as u32, s as u32);
            last
        });
        self.ends.swap_remove(s);
        self.rest.swap_remove(s);
        self.stiffness.swap_remove(s);
        self.damping.swap_remove(s);
        moved
    }

    /// [`SystemError::NoSuchSlot`] unless v is a slot. O(1).
    fn check_slot(&self, v: usize) -> Result<(), SystemError> {
        match v < self.slots() {
            true => Ok(()),
            false => Err(SystemError::NoSuchSlot { slot: v, slots: self.slots() }),
        }
    }

    /// [`SystemError::NoSuchSpring`] unless s is a spring. O(1).
    fn check_spring(&self, s: usize) -> Result<(), SystemError> {
        match s < self.springs() {
            true => Ok(()),
            false => Err(SystemError::NoSuchSpring { spring: s, springs: self.springs() }),
        }
    }

    /// The checks of a spring about to be written at index s. O(1).
    fn check_spring_values(&self, s: usize, ends: [u32; 2], rest: f64, k: f64, c: f64) -> Result<(), SystemError> {
        if !ends_ok(ends, self.slots()) {
            return Err(SystemError::BadEnds { spring: s, ends, slots: self.slots() });
        }
        for (quantity, value) in [("rest length", rest), ("stiffness", k), ("damping", c)] {
            if !is_amount(value) {
                return Err(SystemError::BadValue { quantity, of: "spring", index: s, value });
            }
        }
        Ok(())
    }

    /// Whether the incidence lists hold exactly the springs of `ends`: spring s once in the head
    /// list of `ends[s][0]` and once in the tail list of `ends[s][1]`, nothing else, segments
    /// inside `adj` and disjoint. O(slots + springs).
    ///
    /// # Errors
    /// [`IncidenceError`] naming the first slot found wrong.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::SpringSystem;
    ///
    /// let mut sys = SpringSystem::default();
    /// (0..3).for_each(|_| drop(sys.push_slot(1.0, false, 0.0)));
    /// sys.push_spring([0, 1], 1.0, 1.0, 0.0).unwrap();
    /// sys.push_spring([1, 2], 1.0, 1.0, 0.0).unwrap();
    /// sys.swap_remove_spring(0).unwrap();
    /// assert!(sys.check_incidence().is_ok());
    /// assert_eq!(sys.incident(0).count(), 0);
    /// ```
    pub fn check_incidence(&self) -> Result<(), IncidenceError> {
        self.inc.check(self.slots(), &self.ends)
    }

    /// Number of vertex slots. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material, Projection};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let p = Projection::build(&body, [0.0; 3]).unwrap();
    /// assert_eq!(p.system().slots(), 8); // one slot per vertex of the cube
    /// ```
    pub fn slots(&self) -> usize {
        self.mass.len()
    }

    /// Number of springs. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::SpringSystem;
    ///
    /// let mut sys = SpringSystem::default();
    /// (0..3).for_each(|_| drop(sys.push_slot(1.0, false, 0.0)));
    /// assert_eq!(sys.springs(), 0);
    /// sys.push_spring([0, 2], 1.0, 1.0, 0.0).unwrap();
    /// assert_eq!((sys.springs(), sys.slots()), (1, 3));
    /// ```
    pub fn springs(&self) -> usize {
        self.ends.len()
    }

    /// End slots (a, b) of each spring, two different slots below [`SpringSystem::slots`]. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::SpringSystem;
    ///
    /// let mut sys = SpringSystem::default();
    /// let (a, b) = (sys.push_slot(1.0, false, 0.0).unwrap(), sys.push_slot(1.0, false, 0.0).unwrap());
    /// sys.push_spring([b as u32, a as u32], 1.0, 10.0, 0.5).unwrap();
    /// assert_eq!(sys.ends(), &[[1, 0]]);
    /// assert_eq!((sys.rest(), sys.stiffness(), sys.damping()), (&[1.0][..], &[10.0][..], &[0.5][..]));
    /// ```
    pub fn ends(&self) -> &[[u32; 2]] {
        &self.ends
    }

    /// Rest length L of each spring (finite, ≥ 0). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{FlatModel, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let flat = FlatModel::from_tets(&points, &tets, Material::default(), [0.0; 3], &[]).unwrap();
    /// let diagonals = flat.system.rest().iter().filter(|&&l| (l - 3f64.sqrt()).abs() < 1e-12).count();
    /// assert_eq!(diagonals, 1); // the Kuhn cube's one main diagonal
    /// ```
    pub fn rest(&self) -> &[f64] {
        &self.rest
    }

    /// Stiffness k of each spring (finite, ≥ 0). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{FlatModel, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let flat = FlatModel::from_tets(&points, &tets, Material::default(), [0.0; 3], &[]).unwrap();
    /// assert!(flat.system.stiffness().iter().all(|&k| k > 0.0));
    /// ```
    pub fn stiffness(&self) -> &[f64] {
        &self.stiffness
    }

    /// Damping c of each spring (finite, ≥ 0). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{FlatModel, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let no_damping = Material { damping: 0.0, ..Material::default() };
    /// let flat = FlatModel::from_tets(&points, &tets, no_damping, [0.0; 3], &[]).unwrap();
    /// assert!(flat.system.damping().iter().all(|&c| c == 0.0));
    /// ```
    pub fn damping(&self) -> &[f64] {
        &self.damping
    }

    /// Mass of each slot (finite, ≥ 0). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::SpringSystem;
    ///
    /// let mut sys = SpringSystem::default();
    /// sys.push_slot(2.5, true, 0.0).unwrap();
    /// assert_eq!((sys.mass(), sys.inv_mass()), (&[2.5][..], &[0.0][..])); // fixed: it does not move
    /// ```
    pub fn mass(&self) -> &[f64] {
        &self.mass
    }

    /// 1/m of each free slot, 0 for a fixed or massless one. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::SpringSystem;
    ///
    /// let mut sys = SpringSystem::default();
    /// sys.push_slot(4.0, false, 0.0).unwrap();
    /// sys.push_slot(0.0, false, 0.0).unwrap(); // massless: cannot be accelerated
    /// assert_eq!(sys.inv_mass(), &[0.25, 0.0]);
    /// ```
    pub fn inv_mass(&self) -> &[f64] {
        &self.inv_mass
    }

    /// Ambient viscosity γ of each slot (finite, ≥ 0). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::SpringSystem;
    ///
    /// let mut sys = SpringSystem::default();
    /// sys.push_slot(1.0, false, 0.3).unwrap();
    /// assert_eq!(sys.viscosity(), &[0.3]);
    /// ```
    pub fn viscosity(&self) -> &[f64] {
        &self.viscosity
    }

    /// Gravity acceleration g (finite). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::SpringSystem;
    ///
    /// let sys = SpringSystem::new(vec![], vec![], vec![], vec![], vec![], &[], vec![], [0.0, 0.0, -9.81]).unwrap();
    /// assert_eq!(sys.gravity(), [0.0, 0.0, -9.81]);
    /// ```
    pub fn gravity(&self) -> Vec3 {
        self.gravity
    }

    /// Sets the gravity acceleration g. O(1).
    ///
    /// # Errors
    /// [`SystemError::BadGravity`] for a NaN or infinite component; the gravity is unchanged.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::{SpringSystem, SystemError};
    ///
    /// let mut sys = SpringSystem::default();
    /// sys.set_gravity([0.0, -9.81, 0.0]).unwrap();
    /// assert!(matches!(sys.set_gravity([0.0, 0.0, f64::INFINITY]), Err(SystemError::BadGravity(_))));
    /// assert_eq!(sys.gravity(), [0.0, -9.81, 0.0]); // unchanged
    /// ```
    pub fn set_gravity(&mut self, gravity: Vec3) -> Result<(), SystemError> {
        if gravity.iter().any(|g| !g.is_finite()) {
            return Err(SystemError::BadGravity(gravity));
        }
        self.gravity = gravity;
        Ok(())
    }

    /// Pass 1: F_s (force on end a) of every spring into `sf`. O(springs).
    ///
    /// # Errors
    /// [`SystemError::Length`] unless `x` and `v` hold one entry per slot and `sf` one per
    /// spring, and what the structural part of [`SpringSystem::check`] refuses; `sf` is then
    /// left as it was.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::SpringSystem;
    ///
    /// // Three slots on a line, springs of rest length 1: the first compressed, the second stretched.
    /// let mut sys = SpringSystem::default();
    /// (0..3).for_each(|_| drop(sys.push_slot(1.0, false, 0.0)));
    /// sys.push_spring([0, 1], 1.0, 2.0, 0.0).unwrap();
    /// sys.push_spring([1, 2], 1.0, 2.0, 0.0).unwrap();
    /// let (x, v) = ([[0.0; 3], [0.5, 0.0, 0.0], [2.5, 0.0, 0.0]], [[0.0; 3]; 3]);
    /// let mut sf = vec![[0.0; 3]; 2];
    /// sys.spring_forces(&x, &v, &mut sf, false).unwrap();
    /// assert_eq!(sf, vec![[-1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]); // F on end a: pushed away, pulled along
    /// assert_eq!(sys.vertex_force(1, &v, &sf), Ok([1.0 + 2.0, 0.0, 0.0])); // −F₀ + F₁ on the middle slot
    /// assert!(sys.spring_forces(&x[..2], &v, &mut sf, false).is_err()); // two positions for three slots
    /// ```
    pub fn spring_forces(&self, x: &[Vec3], v: &[Vec3], sf: &mut [Vec3], parallel: bool) -> Result<(), SystemError> {
        self.spring_forces_with(Kernel::detect(), x, v, sf, parallel)
    }

    /// [`SpringSystem::spring_forces`] run with `kernel`: the same bits for every kernel
    /// ([`Kernel`]). O(springs).
    ///
    /// # Errors
    /// As [`SpringSystem::spring_forces`].
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::{Kernel, SpringSystem};
    ///
    /// let mut sys = SpringSystem::default();
    /// (0..2).for_each(|_| drop(sys.push_slot(1.0, false, 0.0)));
    /// sys.push_spring([0, 1], 1.0, 2.0, 0.5).unwrap();
    /// let (x, v) = ([[0.0; 3], [0.3, 0.4, 1.2]], [[0.1, 0.0, 0.0], [0.0, -0.2, 0.0]]);
    /// let mut reference = vec![[0.0; 3]];
    /// sys.spring_forces_with(Kernel::portable(), &x, &v, &mut reference, false).unwrap();
    /// for kernel in Kernel::available() {
    ///     let mut sf = vec![[0.0; 3]];
    ///     sys.spring_forces_with(kernel, &x, &v, &mut sf, false).unwrap();
    ///     assert_eq!(sf, reference); // bit for bit
    /// }
    /// ```
    pub fn spring_forces_with(
        &self,
        kernel: Kernel,
        x: &[Vec3],
        v: &[Vec3],
        sf: &mut [Vec3],
        parallel: bool,
    ) -> Result<(), SystemError> {
        self.check_state(&[("positions", x.len()), ("velocities", v.len())], &[("spring forces", sf.len())])?;
        self.spring_forces_raw(kernel, x, v, sf, parallel);
        Ok(())
    }

    /// [`SpringSystem::spring_forces_with`] on arrays of the right lengths (the steppers check
    /// them once). O(springs).
    pub(crate) fn spring_forces_raw(&self, kernel: Kernel, x: &[Vec3], v: &[Vec3], sf: &mut [Vec3], parallel: bool) {
        self.by_spring_chunks(sf, parallel, |springs, out| spring_pass(kernel, springs, x, v, out));
    }

    /// Runs `pass` over the springs and their slots of `sf`: in chunks of [`PARALLEL_CHUNK`]
    /// across threads when asked and large, else once. Panics if `sf` is not one slot per spring.
    #[inline]
    fn by_spring_chunks(&self, sf: &mut [Vec3], parallel: bool, pass: impl Fn(Springs<'_>, &mut [Vec3]) + Sync) {
        let n = self.springs();
        assert!(sf.len() == n, "spring force buffer has {} entries for {n} springs", sf.len());
        if parallel && n > PARALLEL_CHUNK {
            sf.par_chunks_mut(PARALLEL_CHUNK).enumerate().for_each(|(c, chunk)| {
                let r = c * PARALLEL_CHUNK..c * PARALLEL_CHUNK + chunk.len();
                pass(self.spring_view(r), chunk);
            });
        } else {
            pass(self.spring_view(0..n), sf);
        }
    }

    /// The spring arrays over range `r`.
    #[inline]
    fn spring_view(&self, r: std::ops::Range<usize>) -> Springs<'_> {
        Springs {
            ends: &self.ends[r.clone()],
            rest: &self.rest[r.clone()],
            stiffness: &self.stiffness[r.clone()],
            damping: &self.damping[r],
        }
    }

    /// Σ over incident springs (−F_s where v = b, then +F_s where v = a: tails first, so that a
    /// fresh system sorted by first end sums in spring order, as [`SpringSystem::spring_sums4`]
    /// does). O(degree).
    #[inline(always)]
    fn gather(&self, i: usize, sf: &[Vec3]) -> Vec3 {
        let (heads, tails) = self.inc.lists(i);
        let mut f = [0.0; 3];
        for &s in tails {
            let g = sf[s as usize];
            f = [f[0] - g[0], f[1] - g[1], f[2] - g[2]];
        }
        for &s in heads {
            let g = sf[s as usize];
            f = [f[0] + g[0], f[1] + g[1], f[2] + g[2]];
        }
        f
    }

    /// [`SpringSystem::gather`] for an `sf` of exactly one entry per spring (checked by the
    /// callers): the spring ids are then < sf.len() (and no spring means empty lists), so
    /// clamping them to sf.len() − 1 is a no-op that spares a bounds check per entry.
    #[inline(always)]
    fn gather_full(&self, i: usize, sf: &[Vec3]) -> Vec3 {
        let (heads, tails) = self.inc.lists(i);
        let mut f = [0.0; 3];
        if let Some(last) = sf.len().checked_sub(1) {
            for &s in tails {
                let g = sf[(s as usize).min(last)];
                f = [f[0] - g[0], f[1] - g[1], f[2] - g[2]];
            }
            for &s in heads {
                let g = sf[(s as usize).min(last)];
                f = [f[0] + g[0], f[1] + g[1], f[2] + g[2]];
            }
        }
        f
    }

    /// Total force on slot i from gravity, viscosity and the springs (given F_s in `sf`). O(degree).
    ///
    /// # Errors
    /// [`SystemError::NoSuchSlot`], or [`SystemError::Length`] unless `v` holds one entry per
    /// slot and `sf` one per spring.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::SpringSystem;
    ///
    /// let mut sys = SpringSystem::default();
    /// sys.set_gravity([0.0, 0.0, -10.0]).unwrap();
    /// sys.push_slot(2.0, false, 0.5).unwrap(); // mass 2, viscosity 0.5, no spring
    /// let (v, sf) = ([[1.0, 0.0, 0.0]], []);
    /// assert_eq!(sys.vertex_force(0, &v, &sf), Ok([-0.5, 0.0, -20.0])); // m·g − γ·v
    /// assert!(sys.vertex_force(1, &v, &sf).is_err()); // there is one slot
    /// ```
    pub fn vertex_force(&self, i: usize, v: &[Vec3], sf: &[Vec3]) -> Result<Vec3, SystemError> {
        self.check_slot(i)?;
        self.check_given(&[("velocities", v.len())], &[("spring forces", sf.len())])?;
        Ok(self.vertex_force_raw(i, v, sf))
    }

    /// [`SpringSystem::vertex_force`] on a slot and arrays of the right lengths. O(degree).
    #[inline(always)]
    fn vertex_force_raw(&self, i: usize, v: &[Vec3], sf: &[Vec3]) -> Vec3 {
        let s = self.gather(i, sf);
        let (m, g, vi) = (self.mass[i], self.viscosity[i], v[i]);
        [
            s[0] + m * self.gravity[0] - g * vi[0],
            s[1] + m * self.gravity[1] - g * vi[1],
            s[2] + m * self.gravity[2] - g * vi[2],
        ]
    }

    /// Forces on every slot (pinned ones included) into `out`. O(slots + springs).
    ///
    /// # Errors
    /// As [`SpringSystem::spring_forces`], and [`SystemError::Length`] unless `out` holds one
    /// entry per slot; nothing is written then.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::SpringSystem;
    ///
    /// // One spring of rest length 1 and stiffness 10, stretched to length 2 along x.
    /// let mut sys = SpringSystem::default();
    /// let (a, b) = (sys.push_slot(1.0, false, 0.0).unwrap(), sys.push_slot(1.0, false, 0.0).unwrap());
    /// sys.push_spring([a as u32, b as u32], 1.0, 10.0, 0.0).unwrap();
    /// let (x, v) = ([[0.0; 3], [2.0, 0.0, 0.0]], [[0.0; 3]; 2]);
    /// let (mut sf, mut out) = (vec![[0.0; 3]; 1], vec![[0.0; 3]; 2]);
    /// sys.forces(&x, &v, &mut sf, &mut out, false).unwrap();
    /// assert_eq!(out, vec![[10.0, 0.0, 0.0], [-10.0, 0.0, 0.0]]); // equal and opposite
    /// assert_eq!(sys.elastic_energy(&x), Ok(5.0)); // ½ k (l − L)²
    /// assert!(sys.forces(&x, &v, &mut sf, &mut out[..1], false).is_err()); // one output for two slots
    /// sys.check_incidence().unwrap();
    /// ```
    pub fn forces(
        &self,
        x: &[Vec3],
        v: &[Vec3],
        sf: &mut [Vec3],
        out: &mut [Vec3],
        parallel: bool,
    ) -> Result<(), SystemError> {
        let per_slot = [("positions", x.len()), ("velocities", v.len()), ("forces", out.len())];
        self.check_state(&per_slot, &[("spring forces", sf.len())])?;
        self.forces_raw(x, v, sf, out, parallel);
        Ok(())
    }

    /// [`SpringSystem::forces`] on arrays of the right lengths. O(slots + springs).
    pub(crate) fn forces_raw(&self, x: &[Vec3], v: &[Vec3], sf: &mut [Vec3], out: &mut [Vec3], parallel: bool) {
        self.spring_forces_raw(Kernel::detect(), x, v, sf, parallel);
        self.per_slot(out, parallel, |i| self.vertex_force_raw(i, v, sf));
    }

    /// Accelerations f_i / m_i (zero on fixed slots) into `acc`. O(slots + springs).
    ///
    /// # Errors
    /// As [`SpringSystem::forces`], with `acc` for `out`.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::SpringSystem;
    ///
    /// // No springs: a free slot falls with g, a fixed one does not move.
    /// let mut sys = SpringSystem::default();
    /// sys.set_gravity([0.0, 0.0, -9.81]).unwrap();
    /// sys.push_slot(2.0, false, 0.0).unwrap();
    /// sys.push_slot(2.0, true, 0.0).unwrap();
    /// let (x, v, mut acc) = ([[0.0; 3]; 2], [[0.0; 3]; 2], [[1.0; 3]; 2]);
    /// sys.accelerations(&x, &v, &mut [], &mut acc, false).unwrap();
    /// assert_eq!(acc, [[0.0, 0.0, -9.81], [0.0; 3]]);
    /// ```
    pub fn accelerations(
        &self,
        x: &[Vec3],
        v: &[Vec3],
        sf: &mut [Vec3],
        acc: &mut [Vec3],
        parallel: bool,
    ) -> Result<(), SystemError> {
        self.accelerations_with(Kernel::detect(), x, v, sf, acc, parallel)
    }

    /// [`SpringSystem::accelerations`] run with `kernel`: the same bits for every kernel
    /// ([`Kernel`]). O(slots + springs).
    ///
    /// # Errors
    /// As [`SpringSystem::accelerations`].
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::{Kernel, SpringSystem};
    ///
    /// let mut sys = SpringSystem::default();
    /// sys.set_gravity([0.0, 0.0, -9.81]).unwrap();
    /// (0..3).for_each(|i| drop(sys.push_slot(1.0 + i as f64, i == 0, 0.1)));
    /// sys.push_spring([0, 1], 1.0, 30.0, 0.2).unwrap();
    /// sys.push_spring([1, 2], 1.0, 20.0, 0.2).unwrap();
    /// let x = [[0.0; 3], [0.0, 0.0, -1.1], [0.1, 0.0, -2.3]];
    /// let v = [[0.0; 3], [0.0, 0.3, 0.0], [0.2, 0.0, -0.1]];
    /// let (mut sf, mut reference) = (vec![[0.0; 3]; 2], vec![[0.0; 3]; 3]);
    /// sys.accelerations_with(Kernel::portable(), &x, &v, &mut sf, &mut reference, false).unwrap();
    /// for kernel in Kernel::available() {
    ///     let mut acc = vec![[0.0; 3]; 3];
    ///     sys.accelerations_with(kernel, &x, &v, &mut sf, &mut acc, false).unwrap();
    ///     assert_eq!(acc, reference); // bit for bit
    /// }
    /// ```
    pub fn accelerations_with(
        &self,
        kernel: Kernel,
        x: &[Vec3],
        v: &[Vec3],
        sf: &mut [Vec3],
        acc: &mut [Vec3],
        parallel: bool,
    ) -> Result<(), SystemError> {
        let per_slot = [("positions", x.len()), ("velocities", v.len()), ("accelerations", acc.len())];
        self.check_state(&per_slot, &[("spring forces", sf.len())])?;
        self.accelerations_raw(kernel, x, v, sf, acc, parallel);
        Ok(())
    }

    /// [`SpringSystem::accelerations_with`] on arrays of the right lengths. O(slots + springs).
    pub(crate) fn accelerations_raw(
        &self,
        kernel: Kernel,
        x: &[Vec3],
        v: &[Vec3],
        sf: &mut [Vec3],
        acc: &mut [Vec3],
        parallel: bool,
    ) {
        self.spring_forces_raw(kernel, x, v, sf, parallel);
        let sf: &[Vec3] = sf;
        if parallel && acc.len() > PARALLEL_CHUNK {
            acc.par_chunks_mut(PARALLEL_CHUNK).enumerate().for_each(|(c, chunk)| {
                acceleration_pass(kernel, self, c * PARALLEL_CHUNK, v, sf, chunk);
            });
        } else {
            acceleration_pass(kernel, self, 0, v, sf, acc);
        }
    }

    /// a_i = f_i / m_i (zero on a fixed slot) from the spring forces `sf` (one per spring), with
    /// `vi` the velocity of slot i; the same arithmetic as [`SpringSystem::vertex_force`] then the scaling.
    #[inline(always)]
    pub(crate) fn acceleration(&self, i: usize, vi: Vec3, sf: &[Vec3]) -> Vec3 {
        self.acceleration_of_sum(i, self.gather_full(i, sf), vi)
    }

    /// [`SpringSystem::acceleration`] of slot i given the sum `s` of its spring forces (as the
    /// gather or [`SpringSystem::spring_sums4`] computes it). O(1).
    #[inline(always)]
    pub(crate) fn acceleration_of_sum(&self, i: usize, s: Vec3, vi: Vec3) -> Vec3 {
        let (m, g, w) = (self.mass[i], self.viscosity[i], self.inv_mass[i]);
        let f = [
            s[0] + m * self.gravity[0] - g * vi[0],
            s[1] + m * self.gravity[1] - g * vi[1],
            s[2] + m * self.gravity[2] - g * vi[2],
        ];
        [f[0] * w, f[1] * w, f[2] * w]
    }

    /// `out[i] = value(i)` for every slot, split across threads when asked and large.
    #[inline]
    pub(crate) fn per_slot(&self, out: &mut [Vec3], parallel: bool, value: impl Fn(usize) -> Vec3 + Sync) {
        if parallel && out.len() > PARALLEL_CHUNK {
            out.par_chunks_mut(PARALLEL_CHUNK).enumerate().for_each(|(c, chunk)| {
                for (k, o) in chunk.iter_mut().enumerate() {
                    *o = value(c * PARALLEL_CHUNK + k);
                }
            });
        } else {
            for (i, o) in out.iter_mut().enumerate() {
                *o = value(i);
            }
        }
    }

    /// The springs incident to slot i as (spring, sign): +1 where i is end a; none if i is not
    /// a slot. O(degree).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::SpringSystem;
    ///
    /// let mut sys = SpringSystem::default();
    /// (0..3).for_each(|_| drop(sys.push_slot(1.0, false, 0.0)));
    /// sys.push_spring([0, 1], 1.0, 1.0, 0.0).unwrap();
    /// sys.push_spring([1, 2], 1.0, 1.0, 0.0).unwrap();
    /// let mut at_1: Vec<_> = sys.incident(1).collect();
    /// at_1.sort_by(|a, b| a.partial_cmp(b).unwrap());
    /// assert_eq!(at_1, vec![(0, -1.0), (1, 1.0)]); // end b of spring 0, end a of spring 1
    /// assert_eq!(sys.incident(9).count(), 0); // no slot 9
    /// ```
    pub fn incident(&self, i: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let (heads, tails) = if i < self.slots() { self.inc.lists(i) } else { (&[][..], &[][..]) };
        heads.iter().map(|&s| (s as usize, 1.0)).chain(tails.iter().map(|&s| (s as usize, -1.0)))
    }

    /// Kinetic energy ½ Σ m |v|² over free slots. O(slots).
    ///
    /// # Errors
    /// [`SystemError::Length`] unless `v` holds one entry per slot (and per mass and inverse
    /// mass).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::SpringSystem;
    ///
    /// let mut sys = SpringSystem::default();
    /// sys.push_slot(2.0, false, 0.0).unwrap();
    /// sys.push_slot(2.0, true, 0.0).unwrap(); // fixed slots do not count
    /// assert_eq!(sys.kinetic_energy(&[[3.0, 0.0, 4.0], [9.0; 3]]), Ok(25.0)); // ½ · 2 · 5²
    /// assert!(sys.kinetic_energy(&[[3.0, 0.0, 4.0]]).is_err()); // not a sum over a prefix
    /// ```
    pub fn kinetic_energy(&self, v: &[Vec3]) -> Result<f64, SystemError> {
        self.check_given(&[("velocities", v.len())], &[])?;
        Ok(self.kinetic_energy_raw(v))
    }

    /// [`SpringSystem::kinetic_energy`] of a `v` of the right length. O(slots).
    pub(crate) fn kinetic_energy_raw(&self, v: &[Vec3]) -> f64 {
        self.mass
            .iter()
            .zip(&self.inv_mass)
            .zip(v)
            .filter(|((_, &w), _)| w > 0.0)
            .map(|((&m, _), v)| 0.5 * m * dot(*v, *v))
            .fold(0.0, |sum, e| sum + e) // +0 when every vertex is pinned (`sum` starts at −0)
    }

    /// Elastic energy ½ Σ k (l − L)². O(springs).
    ///
    /// # Errors
    /// [`SystemError::Length`] unless `x` holds one entry per slot, and the structural faults
    /// of [`SpringSystem::check`].
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::SpringSystem;
    ///
    /// let mut sys = SpringSystem::default();
    /// (0..2).for_each(|_| drop(sys.push_slot(1.0, false, 0.0)));
    /// sys.push_spring([0, 1], 2.0, 8.0, 0.0).unwrap();
    /// assert_eq!(sys.elastic_energy(&[[0.0; 3], [0.0, 2.0, 0.0]]), Ok(0.0)); // at rest length
    /// assert_eq!(sys.elastic_energy(&[[0.0; 3], [0.0, 1.5, 0.0]]), Ok(1.0)); // ½ · 8 · 0.5²
    /// ```
    pub fn elastic_energy(&self, x: &[Vec3]) -> Result<f64, SystemError> {
        self.check_state(&[("positions", x.len())], &[])?;
        Ok(self.elastic_energy_raw(x))
    }

    /// [`SpringSystem::elastic_energy`] of an `x` of the right length. O(springs).
    pub(crate) fn elastic_energy_raw(&self, x: &[Vec3]) -> f64 {
        (0..self.springs())
            .map(|s| {
                let [a, b] = self.ends[s];
                // l as rest lengths are measured: a needle's l² would be subnormal or 0.
                let stretch = super::geom::rest_length(x[a as usize], x[b as usize]) - self.rest[s];
                0.5 * self.stiffness[s] * stretch * stretch
            })
            .fold(0.0, |sum, e| sum + e) // +0 with no spring (`sum` starts at −0)
    }

    /// Gravitational potential −Σ m g·x over free slots. O(slots).
    ///
    /// # Errors
    /// [`SystemError::Length`] unless `x` holds one entry per slot.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::SpringSystem;
    ///
    /// let mut sys = SpringSystem::default();
    /// sys.set_gravity([0.0, 0.0, -10.0]).unwrap();
    /// sys.push_slot(2.0, false, 0.0).unwrap();
    /// assert_eq!(sys.gravity_energy(&[[0.0, 0.0, 3.0]]), Ok(60.0)); // m g h
    /// assert_eq!(sys.kinetic_energy(&[[0.0, 4.0, 0.0]]), Ok(16.0)); // ½ m v²
    /// ```
    pub fn gravity_energy(&self, x: &[Vec3]) -> Result<f64, SystemError> {
        self.check_given(&[("positions", x.len())], &[])?;
        let g = self.gravity;
        let free = self.mass.iter().zip(&self.inv_mass).zip(x).filter(|((_, &w), _)| w > 0.0);
        Ok(free.map(|((&m, _), x)| -m * dot(g, *x)).fold(0.0, |sum, e| sum + e))
        // +0 with no free slot
    }

    /// A bound on the largest angular frequency, ω_max² ≤ max_v Σ_{s ∋ v} 2 k_s / m_v
    /// (Gershgorin on M⁻¹K), over free slots. Explicit schemes need dt ≲ 2/ω_max. ω_max² is formed
    /// per slot in wide floats when the plain one leaves the normal range (see `per_mass`), so
    /// ω_max² may pass `f64::MAX` (a stiff, light vertex: a needle edge of 1e-153 beside a unit
    /// one) and ω_max is ∞ only when ω_max itself is past it; ordinary systems keep the plain bits
    /// √(max_v (Σ 2k_s)·(1/m_v)). O(springs).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::SpringSystem;
    ///
    /// let mut sys = SpringSystem::default();
    /// sys.push_slot(2.0, true, 0.0).unwrap(); // fixed: does not count
    /// sys.push_slot(0.5, false, 0.0).unwrap();
    /// sys.push_spring([0, 1], 1.0, 4.0, 0.0).unwrap();
    /// assert_eq!(sys.omega_max(), 4.0); // √(2k / m)
    /// sys.set_slot(1, 1e-300, false, 0.0).unwrap();
    /// sys.set_spring(0, [0, 1], 1.0, 5e9, 0.0).unwrap();
    /// let w = sys.omega_max(); // ω² = 1e310 is past f64::MAX, ω is not
    /// assert!((w / 1e155 - 1.0).abs() < 1e-15, "{w:e}");
    /// ```
    pub fn omega_max(&self) -> f64 {
        let free = (0..self.slots()).filter(|&i| self.inv_mass[i] > 0.0);
        free.map(|i| self.per_mass(i, 0.0, &self.stiffness).sqrt().to_f64()).fold(0.0, f64::max)
    }

    /// (own + Σ_{s ∋ i} 2 x_s) · (1/m_i) for slot i (a rate per mass: Σ 2k/m or (γ + Σ 2c)/m),
    /// summed in incidence order. The plain `f64` value when it is normal (then the wide
    /// operations would give its bits: the terms are ≥ 0, so an overflow would have left ∞, and
    /// doubling and adding subnormals are exact), else the same operations in wide floats
    /// (`crate::wide`: an unbounded exponent), so a value past `f64::MAX` keeps its digits.
    /// O(degree of i).
    fn per_mass(&self, i: usize, own: f64, x: &[f64]) -> Wide {
        let sum: f64 = self.incident(i).map(|(s, _)| 2.0 * x[s]).sum();
        let plain = (own + sum) * self.inv_mass[i];
        if plain.is_normal() {
            return Wide::new(plain);
        }
        let two = Wide::new(2.0);
        let sum = self.incident(i).fold(Wide::new(0.0), |sum, (s, _)| sum.add(two.mul(Wide::new(x[s]))));
        Wide::new(own).add(sum).mul(Wide::new(self.inv_mass[i]))
    }

    /// Bounds on the modes of the system at rest, for the stable time step of an explicit scheme
    /// ([`crate::mechanics::Integrator::stable_dt`]): ω_max as [`SpringSystem::omega_max`]; the
    /// largest damping rate c_max = max_v (γ_v + Σ_{s ∋ v} 2 c_s) / m_v over free slots (every
    /// mode's rate c = ν + β ω² is at most this, by the same argument as ω_max: xᵀCx =
    /// Σ c_s ((x_a − x_b)·n)² ≤ Σ_v |x_v|² Σ_{s ∋ v} 2 c_s); the least spring ratio c_s / k_s
    /// (β_min, over springs with k_s > 0 and a free end) and the least γ_v / m_v (ν_min, over free
    /// slots), ∞ when there is none. ω_max and c_max are formed without intermediate overflow
    /// (the plain bits on ordinary systems): each is ∞ only when it is itself past `f64::MAX`,
    /// and then every stable limit is below the normal range of f64 (each is at most
    /// 2.6/ω_max and 2.6/c_max < 1.5e-308). O(springs + slots).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::SpringSystem;
    ///
    /// let mut sys = SpringSystem::default();
    /// sys.push_slot(2.0, true, 0.0).unwrap(); // fixed: does not count
    /// sys.push_slot(0.5, false, 1.5).unwrap(); // γ = 1.5, so γ/m = 3
    /// sys.push_spring([0, 1], 1.0, 4.0, 0.02).unwrap(); // c/k = 0.005
    /// let b = sys.mode_bounds();
    /// assert_eq!(b.omega_max, 4.0); // √(2k / m)
    /// assert_eq!(b.damping_max, (1.5 + 2.0 * 0.02) / 0.5);
    /// assert_eq!((b.beta_min, b.nu_min), (0.005, 3.0));
    /// ```
    pub fn mode_bounds(&self) -> ModeBounds {
        let (mut damping_max, mut nu_min): (f64, f64) = (0.0, f64::INFINITY);
        for i in 0..self.slots() {
            let w = self.inv_mass[i];
            if w > 0.0 {
                damping_max = damping_max.max(self.per_mass(i, self.viscosity[i], &self.damping).to_f64());
                nu_min = nu_min.min(self.viscosity[i] * w);
            }
        }
        let free = |s: usize| self.ends[s].iter().any(|&v| self.inv_mass[v as usize] > 0.0);
        let beta_min = (0..self.springs())
            .filter(|&s| self.stiffness[s] > 0.0 && free(s))
            .map(|s| self.damping[s] / self.stiffness[s])
            .fold(f64::INFINITY, f64::min);
        ModeBounds { omega_max: self.omega_max(), damping_max, beta_min, nu_min }
    }
}

/// Bounds on the modes of a [`SpringSystem`] at rest ([`SpringSystem::mode_bounds`]), from which
/// [`crate::mechanics::Integrator::stable_dt`] derives a stable time step. With the material law's
/// damping (c_s = β k_s, γ_v = ν m_v) the damping is proportional, M⁻¹(C + Γ) = β M⁻¹K + ν, so the
/// system splits into modes ẍ + c ẋ + ω² x = 0 with ω ≤ `omega_max` and c = ν + β ω² ≤
/// `damping_max`, c/ω² ≥ `beta_min` + `nu_min`/ω_max² (docs/MECHANICS.md, "Time step").
///
/// # Examples
///
/// ```
/// use topomech::mechanics::{Integrator, SpringSystem};
///
/// let mut sys = SpringSystem::default();
/// sys.push_slot(1.0, true, 0.0).unwrap();
/// sys.push_slot(1.0, false, 0.0).unwrap();
/// sys.push_spring([0, 1], 1.0, 50.0, 0.0).unwrap(); // undamped: ω_max = 10
/// let b = sys.mode_bounds();
/// assert_eq!((b.omega_max, b.damping_max), (10.0, 0.0));
/// assert_eq!(Integrator::Symplectic.stable_dt(&b), Some(0.2)); // 2/ω_max
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModeBounds {
    /// ω_max ≥ every angular frequency.
    pub omega_max: f64,
    /// c_max ≥ every modal damping rate (1/s).
    pub damping_max: f64,
    /// β_min: the least damping-to-stiffness ratio c_s / k_s of a spring (s); ∞ for none.
    pub beta_min: f64,
    /// ν_min: the least viscosity-to-mass ratio γ_v / m_v of a free slot (1/s); ∞ for none.
    pub nu_min: f64,
}

/// A fault of a [`SpringSystem`] or of the arrays given to it, naming the array, spring or slot.
///
/// # Examples
///
/// ```
/// use topomech::mechanics::{SpringSystem, SystemError};
///
/// let mut sys = SpringSystem::default();
/// sys.push_slot(1.0, false, 0.0).unwrap();
/// let e = sys.push_spring([0, 1], 1.0, 1.0, 0.0).unwrap_err();
/// assert_eq!(e, SystemError::BadEnds { spring: 0, ends: [0, 1], slots: 1 });
/// assert_eq!(e.to_string(), "spring 0 joins slots [0, 1] (must be two different slots of 1)");
/// ```
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SystemError {
    /// An array has the wrong number of entries.
    #[error("{array} has {len} entries for {expected} {of}")]
    Length {
        /// Which array (e.g. "positions", "rest length").
        array: &'static str,
        /// Its length.
        len: usize,
        /// The length it must have.
        expected: usize,
        /// What it must have one entry per ("slots" or "springs").
        of: &'static str,
    },
    /// A spring whose ends are not two different slots.
    #[error("spring {spring} joins slots {ends:?} (must be two different slots of {slots})")]
    BadEnds {
        /// The spring's index.
        spring: usize,
        /// Its ends.
        ends: [u32; 2],
        /// The number of slots.
        slots: usize,
    },
    /// A spring index past the last spring.
    #[error("no spring {spring} (the system has {springs})")]
    NoSuchSpring {
        /// The index given.
        spring: usize,
        /// The number of springs.
        springs: usize,
    },
    /// A slot index past the last slot.
    #[error("no slot {slot} (the system has {slots})")]
    NoSuchSlot {
        /// The index given.
        slot: usize,
        /// The number of slots.
        slots: usize,
    },
    /// A mass, viscosity, rest length, stiffness or damping that is negative or not finite.
    #[error("{quantity} of {of} {index} is {value} (must be finite and >= 0)")]
    BadValue {
        /// Which quantity.
        quantity: &'static str,
        /// "slot" or "spring".
        of: &'static str,
        /// The slot's or spring's index.
        index: usize,
        /// The value.
        value: f64,
    },
    /// A gravity with a non-finite component.
    #[error("gravity {0:?} is not finite")]
    BadGravity(Vec3),
    /// A positive mass so small that its inverse overflows f64 (below about 5.6e-309).
    #[error("mass of slot {slot} is {mass:e}: its inverse overflows f64 (give 0 for a massless slot)")]
    MassTooSmall {
        /// The slot's index.
        slot: usize,
        /// The mass given.
        mass: f64,
    },
    /// A body whose attribute arrays do not cover its map (a defence: possible only while the
    /// attributes could be replaced whole, before round 27): nothing can be projected.
    #[error("the body's attributes do not fit its map: {0}")]
    Attributes(crate::mechanics::ConservationError),
}

/// 1/m for a free slot of mass m > 0, else 0 (fixed or massless). O(1).
fn inverse_mass(m: f64, fixed: bool) -> f64 {
    if fixed || m <= 0.0 {
        0.0
    } else {
        1.0 / m
    }
}

/// A physical amount: finite and ≥ 0. O(1).
fn is_amount(x: f64) -> bool {
    x.is_finite() && x >= 0.0
}

/// Whether `ends` are two different slots of `slots`. O(1).
fn ends_ok(ends: [u32; 2], slots: usize) -> bool {
    ends[0] != ends[1] && (ends[0].max(ends[1]) as usize) < slots
}

/// The value checks of a slot at index v: amounts, and a mass that is 0 or has a finite
/// inverse (a subnormal mass such as 5e-324 would give 1/m = ∞, which [`SpringSystem::check`]
/// refuses; it is refused here, pinned or not, so that every system built passes `check`). O(1).
fn check_slot_values(v: usize, mass: f64, viscosity: f64) -> Result<(), SystemError> {
    for (quantity, value) in [("mass", mass), ("viscosity", viscosity)] {
        if !is_amount(value) {
            return Err(SystemError::BadValue { quantity, of: "slot", index: v, value });
        }
    }
    if mass > 0.0 && !(1.0 / mass).is_finite() {
        return Err(SystemError::MassTooSmall { slot: v, mass });
    }
    Ok(())
}

/// Springs per block of the vectorised spring pass.
const BLOCK: usize = 64;

/// The per-spring arrays of a range of springs.
#[derive(Clone, Copy)]
pub(crate) struct Springs<'a> {
    pub(crate) ends: &'a [[u32; 2]],
    pub(crate) rest: &'a [f64],
    pub(crate) stiffness: &'a [f64],
    pub(crate) damping: &'a [f64],
}

multiversion! {
    /// F_s of the springs of `springs` into `out` (same length).
    pub(crate) fn spring_pass(springs: Springs<'_>, x: &[Vec3], v: &[Vec3], out: &mut [Vec3]) = spring_pass_body;
}

/// Springs in blocks of [`BLOCK`]: a scalar gather of the end states into per-coordinate
/// arrays, a branch-free arithmetic loop the compiler vectorises (sqrt and division are the cost
/// of a spring), then the writes. Same arithmetic as [`spring_force`], bit for bit. The block
/// arrays are written before they are read, so they are zeroed once per call, not per block.
#[inline(always)]
fn spring_pass_body(springs: Springs<'_>, x: &[Vec3], v: &[Vec3], out: &mut [Vec3]) {
    let mut d = [[0.0f64; BLOCK]; 3];
    let mut dv = [[0.0f64; BLOCK]; 3];
    let mut s = [0.0f64; BLOCK];
    let n_all = out.len();
    let mut first = 0;
    while first < n_all {
        let n = BLOCK.min(n_all - first);
        let ends = &springs.ends[first..first + n];
        for (j, &[a, b]) in ends.iter().enumerate() {
            let (xa, xb, va, vb) = (x[a as usize], x[b as usize], v[a as usize], v[b as usize]);
            for c in 0..3 {
                d[c][j] = xb[c] - xa[c];
                dv[c][j] = vb[c] - va[c];
            }
        }
        let (rest, k, damp) =
            (&springs.rest[first..first + n], &springs.stiffness[first..first + n], &springs.damping[first..first + n]);
        let (dvx, dvy, dvz) = (&dv[0][..n], &dv[1][..n], &dv[2][..n]);
        let s = &mut s[..n];
        let mut rare = 0u64;
        {
            let (dx, dy, dz) = (&d[0][..n], &d[1][..n], &d[2][..n]);
            for j in 0..n {
                let (q, untrusted) = spring_scale(dx[j], dy[j], dz[j], dvx[j], dvy[j], dvz[j], rest[j], k[j], damp[j]);
                s[j] = q;
                rare |= untrusted;
            }
        }
        if rare != 0 {
            redo_rare(&mut d, &dv, rest, k, damp, s);
        }
        let (dx, dy, dz) = (&d[0][..n], &d[1][..n], &d[2][..n]);
        for (j, f) in out[first..first + n].iter_mut().enumerate() {
            *f = [s[j] * dx[j], s[j] * dy[j], s[j] * dz[j]];
        }
        first += n;
    }
}

/// The cold pass of a block of [`spring_pass`] with a rare lane: as [`redo_rare4`] on
/// per-coordinate arrays.
#[cold]
#[inline(never)]
fn redo_rare(d: &mut [[f64; BLOCK]; 3], dv: &[[f64; BLOCK]; 3], rest: &[f64], k: &[f64], damp: &[f64], s: &mut [f64]) {
    for j in 0..s.len() {
        let mut e = [d[0][j], d[1][j], d[2][j]];
        let w = [dv[0][j], dv[1][j], dv[2][j]];
        let (q, untrusted) = spring_scale(e[0], e[1], e[2], w[0], w[1], w[2], rest[j], k[j], damp[j]);
        if untrusted != 0 {
            s[j] = spring_scale_rare(&mut e, w, rest[j], k[j], damp[j], q);
            (d[0][j], d[1][j], d[2][j]) = (e[0], e[1], e[2]);
        }
    }
}

/// A padded state record: x, y, z and a zero.
pub(crate) type Rec4 = [f64; 4];

/// The state of one slot as the spring pass reads it: padded position and velocity in one
/// 64-byte record aligned to 64 bytes, so a spring end costs one bounds check and one cache line
/// (two separate arrays cost two of each).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(64))]
pub(crate) struct SlotState {
    /// Position (x, y, z, +0).
    pub(crate) x: Rec4,
    /// Velocity (x, y, z, +0).
    pub(crate) v: Rec4,
}

multiversion! {
    /// [`spring_pass`] on padded slot records.
    pub(crate) fn spring_pass4(springs: Springs<'_>, y: &[SlotState], out: &mut [Vec3]) = spring_pass4_body;
}

#[inline(always)]
fn spring_pass4_body(springs: Springs<'_>, y: &[SlotState], out: &mut [Vec3]) {
    assert!(out.len() == springs.ends.len(), "one force per spring");
    spring_blocks4(springs, y, &mut ForceArray(out));
}

/// What [`spring_blocks4`] does with each block's forces F_s = s·d (a trait, not a closure, so
/// that it is inlined into each instruction-set copy).
trait BlockSink {
    /// Block of springs `first..first + ends.len()`, their ends, padded d = x_b − x_a and scales s.
    fn emit(&mut self, first: usize, ends: &[[u32; 2]], d: &[Rec4], s: &[f64]);
}

/// Writes F_s into one entry per spring.
struct ForceArray<'a>(&'a mut [Vec3]);

impl BlockSink for ForceArray<'_> {
    #[inline(always)]
    fn emit(&mut self, first: usize, _: &[[u32; 2]], d: &[Rec4], s: &[f64]) {
        for (j, f) in self.0[first..first + s.len()].iter_mut().enumerate() {
            let e = d[j];
            *f = [s[j] * e[0], s[j] * e[1], s[j] * e[2]];
        }
    }
}

/// Adds +F_s at a and −F_s at b into per-slot sums, slot `first_slot + i` at `sums[i]`; an end
/// beyond the sums is skipped. The springs must be sorted by first end with a < b.
struct SlotSums<'a> {
    first_slot: usize,
    sums: &'a mut [Rec4],
}

impl BlockSink for SlotSums<'_> {
    /// The sum of the current first end a is kept in a register over its run of springs and
    /// stored when the run ends: the same additions in the same order as updating `sums[a]`
    /// per spring (no −F_s lands on a during its run, since every b > a), without the chain
    /// of store, reload and add through memory that costs several cycles per spring.
    #[inline(always)]
    fn emit(&mut self, _: usize, ends: &[[u32; 2]], d: &[Rec4], s: &[f64]) {
        let (first_slot, sums) = (self.first_slot, &mut *self.sums);
        let Some(&[a0, _]) = ends.first() else { return };
        let mut run = (a0 as usize).wrapping_sub(first_slot);
        let mut acc = sums[run];
        for (j, &[a, b]) in ends.iter().enumerate() {
            debug_assert!(a < b, "spring sums need a < b");
            let (e, q) = (d[j], s[j]);
            let f = [q * e[0], q * e[1], q * e[2], q * e[3]];
            let ia = (a as usize).wrapping_sub(first_slot);
            if ia != run {
                sums[run] = acc;
                (run, acc) = (ia, sums[ia]);
            }
            acc = [acc[0] + f[0], acc[1] + f[1], acc[2] + f[2], acc[3] + f[3]];
            if let Some(t) = sums.get_mut((b as usize).wrapping_sub(first_slot)) {
                *t = [t[0] - f[0], t[1] - f[1], t[2] - f[2], t[3] - f[3]];
            }
        }
        sums[run] = acc;
    }
}

/// Runs the springs of `springs` in blocks of [`BLOCK`]: a scalar gather of the end records, the
/// vectorised scale s of each spring, then `sink.emit(first, ends, d, s)` with the block's first index,
/// its ends, its end differences d = x_b − x_a (padded) and scales (F_s = s·d).
#[inline(always)]
fn spring_blocks4(springs: Springs<'_>, y: &[SlotState], sink: &mut impl BlockSink) {
    let mut d = [[0.0f64; 4]; BLOCK];
    let mut dv = [[0.0f64; 4]; BLOCK];
    let mut s = [0.0f64; BLOCK];
    let n_all = springs.ends.len();
    let mut first = 0;
    while first < n_all {
        let n = BLOCK.min(n_all - first);
        let ends = &springs.ends[first..first + n];
        let (dd, ddv) = (&mut d[..n], &mut dv[..n]);
        for j in 0..n {
            let [a, b] = ends[j];
            let (ya, yb) = (&y[a as usize], &y[b as usize]);
            let (xa, xb, va, vb) = (ya.x, yb.x, ya.v, yb.v);
            dd[j] = [xb[0] - xa[0], xb[1] - xa[1], xb[2] - xa[2], xb[3] - xa[3]];
            ddv[j] = [vb[0] - va[0], vb[1] - va[1], vb[2] - va[2], vb[3] - va[3]];
        }
        let (rest, k, damp) =
            (&springs.rest[first..first + n], &springs.stiffness[first..first + n], &springs.damping[first..first + n]);
        let s = &mut s[..n];
        let mut rare = 0u64;
        for j in 0..n {
            let (e, w) = (dd[j], ddv[j]);
            // The pads are +0, so l2 + (pad² + pad²) = l2 exactly; reading them keeps the
            // interleaved loads gap-free, which spares the vectoriser a scalar epilogue.
            let pads = e[3] * e[3] + w[3] * w[3];
            let (q, untrusted) = spring_scale_padded(e[0], e[1], e[2], w[0], w[1], w[2], pads, rest[j], k[j], damp[j]);
            s[j] = q;
            rare |= untrusted;
        }
        if rare != 0 {
            redo_rare4(dd, ddv, rest, k, damp, s);
        }
        sink.emit(first, ends, &d[..n], s);
        first += n;
    }
}

/// The cold pass of a block of [`spring_blocks4`] with a rare lane: redoes each spring whose
/// branch-free scale is untrusted ([`spring_scale_padded`], the same bits recomputed on one lane)
/// with [`spring_scale_rare`] (its s and d replaced).
#[cold]
#[inline(never)]
fn redo_rare4(d: &mut [Rec4], dv: &[Rec4], rest: &[f64], k: &[f64], damp: &[f64], s: &mut [f64]) {
    for j in 0..s.len() {
        let (e, w) = (&mut d[j], dv[j]);
        let pads = e[3] * e[3] + w[3] * w[3];
        let (q, untrusted) = spring_scale_padded(e[0], e[1], e[2], w[0], w[1], w[2], pads, rest[j], k[j], damp[j]);
        if untrusted != 0 {
            s[j] = spring_scale_rare(&mut e[..3], [w[0], w[1], w[2]], rest[j], k[j], damp[j], q);
        }
    }
}

multiversion! {
    /// Adds the forces of `springs` (all with first end in `first_slot..first_slot + sums.len()`)
    /// into `sums`, slot `first_slot + i` at `sums[i]`: +F_s at a, −F_s at b when b is in range
    /// (skipped otherwise), one spring after the other.
    pub(crate) fn scatter_pass4(springs: Springs<'_>, y: &[SlotState], first_slot: usize, sums: &mut [Rec4])
        = scatter_pass4_body;
}

#[inline(always)]
fn scatter_pass4_body(springs: Springs<'_>, y: &[SlotState], first_slot: usize, sums: &mut [Rec4]) {
    spring_blocks4(springs, y, &mut SlotSums { first_slot, sums });
}

/// F_s of spring s on padded records, scalar: the same bits as the blocked passes.
#[inline]
fn spring_force4(springs: &Springs<'_>, s: usize, y: &[SlotState]) -> Vec3 {
    let [a, b] = springs.ends[s];
    let (ya, yb) = (&y[a as usize], &y[b as usize]);
    let mut d: Rec4 = std::array::from_fn(|c| yb.x[c] - ya.x[c]);
    let w: Rec4 = std::array::from_fn(|c| yb.v[c] - ya.v[c]);
    let pads = d[3] * d[3] + w[3] * w[3];
    let (mut q, untrusted) = spring_scale_padded(
        d[0],
        d[1],
        d[2],
        w[0],
        w[1],
        w[2],
        pads,
        springs.rest[s],
        springs.stiffness[s],
        springs.damping[s],
    );
    if untrusted != 0 {
        q = spring_scale_rare(
            &mut d[..3],
            [w[0], w[1], w[2]],
            springs.rest[s],
            springs.stiffness[s],
            springs.damping[s],
            q,
        );
    }
    [q * d[0], q * d[1], q * d[2]]
}

/// Slot ranges per thread of the parallel spring sums: few, because each border costs the
/// forces of the springs crossing it a second time (scalar, with cache misses).
const RANGES_PER_THREAD: usize = 2;

/// How [`SpringSystem::spring_sums4`] splits the work on several threads (made by
/// [`SpringSystem::plan_sums`] from the spring ends, valid while they do not change): slot
/// ranges `[s0, s1, p0, p1]` (slots s0..s1 and the springs p0..p1 of their first ends) and per
/// range its cross springs, those whose second end lies in a later range (largest second end,
/// spring ids in spring order). No ranges: one serial pass.
#[derive(Clone, Debug, Default)]
pub(crate) struct SumPlan {
    bounds: Vec<[usize; 4]>,
    cross: Vec<(usize, Vec<u32>)>,
}

impl SpringSystem {
    /// Pass 1 on padded slot records (the RK4 stepper's layout).
    pub(crate) fn spring_forces4(&self, kernel: Kernel, y: &[SlotState], sf: &mut [Vec3], parallel: bool) {
        self.by_spring_chunks(sf, parallel, |springs, out| spring_pass4(kernel, springs, y, out));
    }

    /// Whether the springs are sorted by first end with a < b and the incidence lists are the
    /// packed ones of [`SpringSystem::new`] (no mutator that touches the lists has run since):
    /// then slot v's tails come before its heads in spring order, each list ascending, and
    /// summing F_s in spring order gives the gather's bits, which lets the RK4 stepper add the
    /// forces per slot in one pass over the springs (module docs, "Spring sums"). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::SpringSystem;
    ///
    /// let sorted = |ends: Vec<[u32; 2]>| {
    ///     let n = ends.len();
    ///     let sys = SpringSystem::new(ends, vec![1.0; n], vec![1.0; n], vec![0.0; n], vec![1.0; 3], &[false; 3], vec![0.0; 3], [0.0; 3]);
    ///     sys.unwrap().sorted_by_first_end()
    /// };
    /// assert!(sorted(vec![[0, 1], [0, 2], [1, 2]]));
    /// assert!(!sorted(vec![[1, 2], [0, 1]])); // not by first end
    /// assert!(!sorted(vec![[1, 0]])); // a > b
    /// let mut sys = SpringSystem::new(vec![[0, 1]], vec![1.0], vec![1.0], vec![0.0], vec![1.0; 3], &[false; 3], vec![0.0; 3], [0.0; 3]).unwrap();
    /// sys.push_spring([0, 2], 1.0, 1.0, 0.0).unwrap(); // a mutator: the lists are no longer the packed ones
    /// assert!(!sys.sorted_by_first_end());
    /// ```
    pub fn sorted_by_first_end(&self) -> bool {
        self.inc.sorted
    }

    /// Plans [`SpringSystem::spring_sums4`] on the current thread pool (one range when not
    /// `parallel` or small): two ranges of slots per thread, each at least one chunk (any split
    /// gives the same bits). O(springs / threads + log springs) per range.
    pub(crate) fn plan_sums(&self, parallel: bool, plan: &mut SumPlan) {
        let n = self.slots();
        let ranges = (RANGES_PER_THREAD * rayon::current_num_threads()).min(n / PARALLEL_CHUNK);
        plan.bounds.clear();
        if !parallel || ranges <= 1 {
            return;
        }
        let slot_at = |r: usize| r * n / ranges;
        let spring_at = |r: usize| self.ends.partition_point(|e| (e[0] as usize) < slot_at(r));
        plan.bounds.extend((0..ranges).map(|r| [slot_at(r), slot_at(r + 1), spring_at(r), spring_at(r + 1)]));
        plan.cross.resize_with(ranges, Default::default);
        plan.cross.par_iter_mut().zip(&plan.bounds).for_each(|((reach, list), &[_, s1, p0, p1])| {
            list.clear();
            *reach = 0;
            for (s, &[_, b]) in self.ends[p0..p1].iter().enumerate() {
                if b as usize >= s1 {
                    list.push((p0 + s) as u32);
                    *reach = (*reach).max(b as usize);
                }
            }
        });
    }

    /// The spring part of every slot's force, Σ −F_s (v = b) then +F_s (v = a) in spring order,
    /// added into `sums` (all zero on entry, one per slot) straight from the springs: no
    /// per-spring force array, no incidence lists. Bitwise equal to the gather for every kernel
    /// and thread count. With a `plan` of several ranges (made by [`SpringSystem::plan_sums`]
    /// for these ends), each range takes the springs of its first ends, but first adds the
    /// forces of the earlier ranges' springs that end in it (computed there from the records),
    /// which keeps the spring order per slot. Panics unless [`SpringSystem::sorted_by_first_end`].
    /// O(springs + slots).
    pub(crate) fn spring_sums4(&self, kernel: Kernel, y: &[SlotState], sums: &mut [Rec4], plan: &SumPlan) {
        assert!(self.sorted_by_first_end() && sums.len() == self.slots(), "spring sums need a sorted system");
        if plan.bounds.is_empty() {
            scatter_pass4(kernel, self.spring_view(0..self.springs()), y, 0, sums);
            return;
        }
        let mut parts = Vec::with_capacity(plan.bounds.len());
        let mut rest = sums;
        for &[s0, s1, _, _] in &plan.bounds {
            let (part, tail) = rest.split_at_mut(s1 - s0);
            parts.push(part);
            rest = tail;
        }
        let all = self.spring_view(0..self.springs());
        parts.into_par_iter().zip(&plan.bounds).enumerate().for_each(|(r, (part, &[s0, s1, p0, p1]))| {
            let reaching = plan.cross[..r].iter().filter(|(reach, _)| *reach >= s0);
            for &s in reaching.flat_map(|(_, list)| list) {
                let b = self.ends[s as usize][1] as usize;
                if (s0..s1).contains(&b) {
                    let f = spring_force4(&all, s as usize, y);
                    let t = &mut part[b - s0];
                    *t = [t[0] - f[0], t[1] - f[1], t[2] - f[2], t[3]];
                }
            }
            scatter_pass4(kernel, self.spring_view(p0..p1), y, s0, part);
        });
    }
}

multiversion! {
    /// Accelerations of slots `first..first + out.len()` into `out`.
    fn acceleration_pass(sys: &SpringSystem, first: usize, v: &[Vec3], sf: &[Vec3], out: &mut [Vec3])
        = acceleration_pass_body;
}

#[inline(always)]
fn acceleration_pass_body(sys: &SpringSystem, first: usize, v: &[Vec3], sf: &[Vec3], out: &mut [Vec3]) {
    for (k, o) in out.iter_mut().enumerate() {
        let i = first + k;
        *o = sys.acceleration(i, v[i], sf);
    }
}

/// F_s on end a of a spring (see the module docs). Zero for a zero-length spring. O(1).
///
/// # Examples
///
/// ```
/// use topomech::mechanics::force::spring_force;
///
/// let (a, b, still) = ([0.0; 3], [3.0, 0.0, 0.0], [0.0; 3]);
/// assert_eq!(spring_force(a, b, still, still, 1.0, 5.0, 0.0), [10.0, 0.0, 0.0]); // pulled towards b
/// assert_eq!(spring_force(a, b, still, still, 3.0, 5.0, 0.0), [0.0; 3]); // at rest length
/// let closing = [1.0, 0.0, 0.0]; // a moves towards b: damping resists
/// assert_eq!(spring_force(a, b, closing, still, 3.0, 5.0, 0.5), [-0.5, 0.0, 0.0]);
/// ```
#[inline(always)]
pub fn spring_force(xa: Vec3, xb: Vec3, va: Vec3, vb: Vec3, rest: f64, k: f64, c: f64) -> Vec3 {
    let mut d = [xb[0] - xa[0], xb[1] - xa[1], xb[2] - xa[2]];
    let dv = [vb[0] - va[0], vb[1] - va[1], vb[2] - va[2]];
    let s = spring_scale_full(&mut d, dv, rest, k, c);
    [s * d[0], s * d[1], s * d[2]]
}

/// The scalar s with F_s = s·d: s = [k (l − L) l + c (dv·d)] / l², one sqrt and one division;
/// zero when l = 0. This is [`spring_scale_padded`] with pads −0: x + (−0) = x for every x, so
/// the compiler drops the addition (the same machine code as a copy without it). Also returns
/// whether s is untrusted (1) and must be redone by [`spring_scale_rare`].
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn spring_scale(dx: f64, dy: f64, dz: f64, dvx: f64, dvy: f64, dvz: f64, rest: f64, k: f64, c: f64) -> (f64, u64) {
    spring_scale_padded(dx, dy, dz, dvx, dvy, dvz, -0.0, rest, k, c)
}

/// The squared spring lengths the branch-free scale takes as they are: 2⁻⁴⁹⁸ ≤ l² ≤ 2⁵⁰⁰. Inside,
/// the largest component of d is at most 2²⁵⁰ and, since l² ≤ 3 max dₖ², at least 2⁻²⁵⁰ (well,
/// past (2⁻⁴⁹⁸ / 3)^½ > 2⁻²⁵⁰), so d is a plain difference of [`crate::mesh::PLAIN_EXTENT`]
/// (the one [`super::geom::rest_length`] measures with √(Σ dₖ²)): l² neither under- nor
/// overflows, and l has the bits of the rest length of the same shape. Every spring of an
/// ordinary mesh; the rest (needles shorter than 2⁻²⁴⁹, lengths past 2²⁵⁰, l = 0, non-finite
/// states) go to [`spring_scale_rare`].
const PLAIN_L2: std::ops::RangeInclusive<f64> = 1.221974545399842e-150..=3.273390607896142e150; // 2⁻⁴⁹⁸ ..= 2⁵⁰⁰

/// 2²⁵⁰: the largest damping c the branch-free scale keeps (see [`spring_scale_padded`]).
const PLAIN_DAMPING: f64 = 1.8092513943330656e75; // 2²⁵⁰

/// 2⁵²⁵: the largest |n| + |k (l − L)| the branch-free scale keeps (see [`spring_scale_padded`]).
const PLAIN_TERMS_MAX: f64 = 1.0983676256208976e158; // 2⁵²⁵

/// The bits of 2⁻⁵²¹: the smallest nonzero |n| + |k (l − L)| the branch-free scale keeps (see
/// [`spring_scale_padded`]).
const PLAIN_TERMS_MIN_BITS: i64 = 2260807012939988992; // (2⁻⁵²¹).to_bits()

/// [`spring_scale`] with `pads` (±0) added to l²: the same bits. Branch-free, and with it a flag
/// (1 = untrusted) that the callers OR over a block and, when set, redo the flagged springs
/// with [`spring_scale_rare`], which evaluates the same formula with an unbounded exponent. With
/// n = k (l − L) l + c (dv·d) the numerator and t = |n| + |k (l − L)|, the flag is set exactly
/// when
///
/// 1. l² is outside [`PLAIN_L2`] (a subnormal l², finding 168; l² = 0, coincident ends: 0/0;
///    l² = ∞; so below l ∈ [2⁻²⁴⁹, 2²⁵⁰], l² and l without under- or overflow), or
/// 2. t is above 2⁵²⁵ or NaN (an overflow anywhere, which reaches n as ±∞ or NaN; below, |s| =
///    |n| / l² ≤ 2⁵²⁵⁺⁴⁹⁸ is finite), or
/// 3. 0 < t < 2⁻⁵²¹ (a numerator or an elastic force near or below the subnormals), or
/// 4. c > 2²⁵⁰ (damping so large that the products dvₖ dₖ rounded among the subnormals matter).
///
/// Unflagged, nothing overflowed, and underflow moved F = s·d by at most 2⁻¹⁰⁷⁵ (k (l − L), the
/// elastic force itself, rounded among the subnormals) plus (3c + 2)·2⁻¹⁰⁷⁵ / l (the products
/// dvₖ dₖ, c (dv·d) and k (l − L)·l rounded among the subnormals, divided by l on the way to F)
/// plus 2⁻¹⁰⁷⁵ l (s rounded among the subnormals): either |n| ≥ 2⁻⁵²² and then s is normal and
/// all this is below 2⁻⁵² |F| (|F| = |n| / l), or |k (l − L)| ≥ 2⁻⁵²² and |n| is a cancellation
/// of two terms of at least 2⁻⁷⁷¹ and it is below 2⁻⁵² of their size, the accuracy the plain
/// formula has anyway. Where nothing underflowed the plain result has exactly the bits of the
/// cold path. Left as 0: t = 0, that is k (l − L) = 0 and n = 0 (a spring at its rest length
/// with no relative velocity along it: the common case that needs no work), which is exact
/// unless c (dv·d) underflowed to 0 with dv ≠ 0, c ≠ 0: then the true force is below
/// 3c·2⁻¹⁰⁷⁵ / l ≤ 2⁻⁵⁷⁴ (every product dvₖ dₖ below 2⁻¹⁰⁷⁵, or c (dv·d) below it).
///
/// Cost: three `and`s, an addition, four compares next to the sqrt and the division.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn spring_scale_padded(
    dx: f64,
    dy: f64,
    dz: f64,
    dvx: f64,
    dvy: f64,
    dvz: f64,
    pads: f64,
    rest: f64,
    k: f64,
    c: f64,
) -> (f64, u64) {
    let l2 = (dx * dx + dy * dy + dz * dz) + pads;
    let l = l2.sqrt();
    let elastic = k * (l - rest);
    let num = elastic * l + c * (dvx * dx + dvy * dy + dvz * dz);
    let terms = num.abs() + elastic.abs();
    // 0 < terms < 2⁻⁵²¹ on the bits: terms ≥ +0 (or NaN), so bits − 1 as an unsigned number is
    // below bits(2⁻⁵²¹) − 1 exactly then; the unsigned order is the signed one shifted by 2⁶³.
    let tiny = ((terms.to_bits() as i64).wrapping_add(i64::MAX)) < (PLAIN_TERMS_MIN_BITS - 1).wrapping_add(i64::MIN);
    let outside = (l2 < *PLAIN_L2.start()) | (l2 > *PLAIN_L2.end());
    // !(t ≤ max), not t > max: a NaN t (an overflow met a 0 or an opposite ∞) is untrusted too,
    // in one compare.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    let untrusted = outside | !(terms <= PLAIN_TERMS_MAX) | tiny | (c > PLAIN_DAMPING);
    (num / l2, untrusted as u64)
}

/// The cold path of a spring whose branch-free scale `q` is untrusted (see
/// [`spring_scale_padded`]): returns s' and replaces `d` (its first three entries) by d' so that
/// F_s = s'·d' is [k (l − L) l + c (dv·d)] / l² · d evaluated with an unbounded exponent
/// (`crate::wide`: each operation rounded as in `f64`, in the plain operation order), that is,
/// k (l − L) n + c (dv·n) n, n = d / l, for any finite d ≠ 0 whose length l = |d| is a normal
/// `f64` (l ≥ 2⁻¹⁰²²), to within an ulp wherever the force is a normal `f64`; a component is ±∞
/// or 0 only when it is past `f64::MAX` or below half the smallest subnormal. l is measured as
/// [`super::geom::rest_length`] measures a rest length, so a spring in its rest shape feels
/// exactly k·0 (the plain √l² of the hot path inside [`crate::mesh::PLAIN_EXTENT`],
/// [`crate::mesh::distance`] outside). That l is an `f64`: a subnormal l (0 < l < 2⁻¹⁰²²) is
/// rounded to a multiple of 2⁻¹⁰⁷⁴, an error ε of up to about 2⁻¹⁰⁷⁵, and the elastic term
/// k (l − L) n is then off by about k·ε·|2 − L/l| — up to 2⁻¹⁰⁷⁴/l relative when L ≪ l (1.2 % at
/// l = 20·2⁻¹⁰⁷⁴), more where l − L cancels (findings 168 and 200); the damping term, formed from
/// d·d and not from l, keeps the ulp bound. Where no plain
/// intermediate over- or underflows, s' = q and d' = d, the hot path's bits; where s is a normal
/// `f64`, s' = s and d' = d (F_s = s·d rounded once per component); else s' = 1 and d' = F_s,
/// each component rounded from the wide product (twice only among the subnormals). Returns 0
/// when d is 0 (coincident ends: no force), and keeps `q` (and d) when a state or parameter is
/// not finite (NaN or ∞, as before). O(1).
#[cold]
#[inline(never)]
fn spring_scale_rare(d: &mut [f64], dv: [f64; 3], rest: f64, k: f64, c: f64, q: f64) -> f64 {
    let e = [d[0], d[1], d[2]];
    let largest = e.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if largest == 0.0 {
        return 0.0;
    }
    if !e.iter().chain(&dv).chain(&[rest, k, c]).all(|x| x.is_finite()) {
        return q;
    }
    let l = super::geom::rest_length([0.0; 3], e);
    let l = if l.is_finite() {
        Wide::new(l)
    } else {
        // |d| past f64::MAX (components near it): measured at half the scale, exactly doubled.
        Wide::new(crate::mesh::distance(e.map(|x| 0.5 * x), [0.0; 3])).mul(Wide::new(2.0))
    };
    let dw = e.map(Wide::new);
    let elastic = Wide::new(k).mul(l.sub(Wide::new(rest)));
    let damping = Wide::new(c).mul(crate::wide::dot(dv.map(Wide::new), dw));
    let s = elastic.mul(l).add(damping).div(crate::wide::dot(dw, dw));
    let plain = s.to_f64();
    if plain.is_normal() || s.is_zero() {
        return plain;
    }
    for (x, w) in d.iter_mut().zip(dw) {
        *x = s.mul(w).to_f64();
    }
    1.0
}

/// [`spring_scale`] with its cold path: s and d (replaced when rare) with F_s = s·d. O(1).
#[inline(always)]
fn spring_scale_full(d: &mut [f64; 3], dv: [f64; 3], rest: f64, k: f64, c: f64) -> f64 {
    let (q, untrusted) = spring_scale(d[0], d[1], d[2], dv[0], dv[1], dv[2], rest, k, c);
    if untrusted != 0 {
        spring_scale_rare(d, dv, rest, k, c, q)
    } else {
        q
    }
}

/// Why [`SpringSystem::check_incidence`] failed.
///
/// # Examples
///
/// ```
/// use topomech::mechanics::{IncidenceError, SpringSystem};
///
/// let mut sys = SpringSystem::default();
/// (0..3).for_each(|_| drop(sys.push_slot(1.0, false, 0.0)));
/// sys.push_spring([0, 1], 1.0, 1.0, 0.0).unwrap();
/// sys.set_spring(0, [0, 2], 1.0, 1.0, 0.0).unwrap(); // the mutators keep the lists in step
/// assert_eq!(sys.check_incidence(), Ok(()));
/// let e = IncidenceError::SlotCount { expected: 3, got: 2 }; // what a stale table would report
/// assert_eq!(e.to_string(), "incidence table has 2 slots, the system 3");
/// ```
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum IncidenceError {
    /// The per-slot table does not have one entry per slot.
    #[error("incidence table has {got} slots, the system {expected}")]
    SlotCount {
        /// Slots of the system.
        expected: usize,
        /// Entries of the table.
        got: usize,
    },
    /// Slot `slot`'s segment runs outside `adj`, overlaps another one, or its counts are
    /// inconsistent (heads ≤ len ≤ cap).
    #[error("slot {slot}: segment out of bounds, overlapping or inconsistent")]
    Segment {
        /// The slot.
        slot: usize,
    },
    /// Slot `slot`'s lists are not the springs whose ends name it.
    #[error("slot {slot}: incident springs differ from the spring ends")]
    Lists {
        /// The slot.
        slot: usize,
    },
}

/// Where slot v's lists sit in `adj` (module docs).
#[derive(Clone, Copy, Debug, Default)]
struct Segment {
    start: u32,
    heads: u32,
    len: u32,
    cap: u32,
}

/// Incidence lists with slack (module docs).
#[derive(Clone, Debug, Default)]
struct Incidence {
    seg: Vec<Segment>,
    adj: Vec<u32>,
    /// Entries of `adj` owned by no segment (abandoned by moves).
    garbage: usize,
    /// Packed from springs sorted by first end, each with a < b, and unchanged since
    /// ([`SpringSystem::sorted_by_first_end`]).
    sorted: bool,
}

impl PartialEq for Incidence {
    fn eq(&self, other: &Self) -> bool {
        self.seg.len() == other.seg.len() && (0..self.seg.len()).all(|v| self.lists(v) == other.lists(v))
    }
}

impl Incidence {
    /// Tight CSR: slot order, heads then tails, spring order within each. O(slots + springs).
    fn packed(n: usize, ends: &[[u32; 2]]) -> Self {
        let mut seg = vec![Segment::default(); n];
        for &[a, b] in ends {
            seg[a as usize].heads += 1;
            seg[a as usize].len += 1;
            seg[b as usize].len += 1;
        }
        let mut start = 0u32;
        for g in &mut seg {
            g.start = start;
            g.cap = g.len;
            start += g.len;
        }
        let mut adj = vec![0u32; 2 * ends.len()];
        let mut fill: Vec<[u32; 2]> = seg.iter().map(|g| [g.start, g.start + g.heads]).collect();
        for (s, &[a, b]) in ends.iter().enumerate() {
            for (v, side) in [(a as usize, 0), (b as usize, 1)] {
                adj[fill[v][side] as usize] = s as u32;
                fill[v][side] += 1;
            }
        }
        let sorted = ends.iter().all(|&[a, b]| a < b) && ends.windows(2).all(|w| w[0][0] <= w[1][0]);
        Incidence { seg, adj, garbage: 0, sorted }
    }

    /// (heads, tails) of slot v. O(1).
    #[inline(always)]
    fn lists(&self, v: usize) -> (&[u32], &[u32]) {
        let g = self.seg[v];
        let (o0, o1, o2) = (g.start as usize, (g.start + g.heads) as usize, (g.start + g.len) as usize);
        (&self.adj[o0..o1], &self.adj[o1..o2])
    }

    fn push_slot(&mut self) {
        self.seg.push(Segment { start: self.adj.len() as u32, ..Segment::default() });
    }

    /// Adds spring s to v's head list (`head`) or tail list. O(degree) amortised.
    fn insert(&mut self, v: usize, head: bool, s: u32) {
        self.sorted = false;
        if self.seg[v].len == self.seg[v].cap {
            self.grow(v);
        }
        let g = &mut self.seg[v];
        let (o1, o2) = ((g.start + g.heads) as usize, (g.start + g.len) as usize);
        if head {
            // The first tail moves to the end of the tails; s takes its place.
            self.adj[o2] = self.adj[o1];
            self.adj[o1] = s;
            g.heads += 1;
        } else {
            self.adj[o2] = s;
        }
        g.len += 1;
    }

    /// Removes spring s from v's head or tail list (panics if absent: a bug). O(degree).
    fn remove(&mut self, v: usize, head: bool, s: u32) {
        self.sorted = false;
        let p = self.position(v, head, s);
        let g = &mut self.seg[v];
        // s was found in the list, so that list is not empty: neither index underflows. (The
        // last head is computed only for a head: with no heads at slot 0 it would underflow.)
        let last = (g.start + g.len) as usize - 1;
        if head {
            let last_head = (g.start + g.heads) as usize - 1;
            self.adj[p] = self.adj[last_head];
            self.adj[last_head] = self.adj[last];
            g.heads -= 1;
        } else {
            self.adj[p] = self.adj[last];
        }
        g.len -= 1;
    }

    /// Renames spring `from` to `to` in v's head or tail list. O(degree).
    fn rename(&mut self, v: usize, head: bool, from: u32, to: u32) {
        self.sorted = false;
        let p = self.position(v, head, from);
        self.adj[p] = to;
    }

    fn position(&self, v: usize, head: bool, s: u32) -> usize {
        let g = self.seg[v];
        let range = if head { g.start..g.start + g.heads } else { g.start + g.heads..g.start + g.len };
        let found = range.clone().find(|&p| self.adj[p as usize] == s);
        found.unwrap_or_else(|| panic!("spring {s} missing from slot {v}'s incidence list {range:?}")) as usize
    }

    /// Moves v's full segment to the end of `adj` with twice the capacity (at least 4), then
    /// compacts if the abandoned space exceeds the live entries. O(degree) amortised.
    fn grow(&mut self, v: usize) {
        let g = self.seg[v];
        let new_start = self.adj.len();
        self.adj.extend_from_within(g.start as usize..(g.start + g.len) as usize);
        let cap = (2 * g.cap).max(4);
        self.adj.resize(new_start + cap as usize, 0);
        self.garbage += g.cap as usize;
        self.seg[v] = Segment { start: new_start as u32, cap, ..g };
        if self.garbage > self.adj.len() / 2 {
            self.compact();
        }
    }

    /// Repacks every segment in slot order keeping one spare entry of slack each. O(slots + springs).
    fn compact(&mut self) {
        let mut adj = Vec::with_capacity(self.adj.len() - self.garbage);
        for g in &mut self.seg {
            let (from, len) = (g.start as usize, g.len as usize);
            g.start = adj.len() as u32;
            adj.extend_from_slice(&self.adj[from..from + len]);
            g.cap = g.len + 1;
            adj.push(0);
        }
        self.adj = adj;
        self.garbage = 0;
    }

    fn check(&self, n: usize, ends: &[[u32; 2]]) -> Result<(), IncidenceError> {
        if self.seg.len() != n {
            return Err(IncidenceError::SlotCount { expected: n, got: self.seg.len() });
        }
        let mut by_start: Vec<usize> = (0..n).collect();
        by_start.sort_unstable_by_key(|&v| self.seg[v].start);
        let mut end = 0u64;
        for v in by_start {
            let g = self.seg[v];
            let ok = g.heads <= g.len && g.len <= g.cap && g.start as u64 + g.cap as u64 <= self.adj.len() as u64;
            if !ok || (g.cap > 0 && (g.start as u64) < end) {
                return Err(IncidenceError::Segment { slot: v });
            }
            end = end.max(g.start as u64 + g.cap as u64);
        }
        let mut expected: Vec<[Vec<u32>; 2]> = vec![[Vec::new(), Vec::new()]; n];
        for (s, &[a, b]) in ends.iter().enumerate() {
            for (v, side) in [(a as usize, 0), (b as usize, 1)] {
                if v >= n {
                    return Err(IncidenceError::Lists { slot: v });
                }
                expected[v][side].push(s as u32);
            }
        }
        for (v, [eh, et]) in expected.into_iter().enumerate() {
            let (h, t) = self.lists(v);
            let (mut h, mut t) = (h.to_vec(), t.to_vec());
            h.sort_unstable();
            t.sort_unstable();
            if h != eh || t != et {
                return Err(IncidenceError::Lists { slot: v });
            }
        }
        Ok(())
    }
}
