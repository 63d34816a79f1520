//! The checks the demo runs after every operation and at every frame: the map's laws
//! (`validate()`), the conservation laws recomputed from the orbits (`check_conservation`), and
//! two global balances against the initial body:
//!
//! ```text
//!   mass       Σ_v m_v + removed mass       = M0     (relative residual |Δ| / M0 ≤ TOLERANCE)
//!   stiffness  Σ_e k_e + removed stiffness  = K0     (relative residual |Δ| / K0 ≤ TOLERANCE)
//! ```
//!
//! A simulation step writes only positions and velocities, which none of these laws read (they
//! use rest positions), so the demo checks after every topological operation and at every frame,
//! not after every step.
//!
//! Cutting and tearing only dissociate (m = m1 + m2, k = k1 + k2), so both sums stay; a removal
//! takes exactly its tet's mass and stiffness contributions away, which [`Checker::removed`]
//! records.

use topomech::mechanics::{check_conservation, Body};
use topomech::GMap;

use super::DemoError;

/// Largest relative residual of a balance that still passes.
pub const TOLERANCE: f64 = 1e-9;

/// Relative residuals of the two balances at one check.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Residuals {
    /// (Σ_v m_v + removed − M0) / M0.
    pub mass: f64,
    /// (Σ_e k_e + removed − K0) / K0.
    pub stiffness: f64,
}

/// Runs the checks and counts those that passed. Four checks per call: validity, conservation,
/// mass balance, stiffness balance.
#[derive(Clone, Debug)]
pub struct Checker {
    /// Checks passed so far.
    pub passed: usize,
    /// Σ_v m_v of the initial body.
    pub initial_mass: f64,
    /// Σ_e k_e of the initial body.
    pub initial_stiffness: f64,
    /// Mass removed with tets so far.
    pub removed_mass: f64,
    /// Stiffness removed with tets so far.
    pub removed_stiffness: f64,
    /// The residuals of the last check.
    pub last: Residuals,
}

/// Σ_v m_v over the live vertices. O(darts).
pub fn total_mass(body: &Body) -> f64 {
    body.total_vertex_mass()
}

/// Σ_e k_e over the live edges. O(darts).
pub fn total_stiffness(body: &Body) -> f64 {
    let (map, mech): (&GMap<3>, _) = (body.map(), body.attrs());
    map.one_dart_per_cell(1).into_iter().map(|d| mech.edge_stiffness(map.cell_id(1, d))).sum()
}

impl Checker {
    /// A checker whose reference is `body` as it is now. O(darts).
    pub fn new(body: &Body) -> Self {
        Checker {
            passed: 0,
            initial_mass: total_mass(body),
            initial_stiffness: total_stiffness(body),
            removed_mass: 0.0,
            removed_stiffness: 0.0,
            last: Residuals::default(),
        }
    }

    /// Records mass and stiffness that left the body with a removed tet. O(1).
    pub fn removed(&mut self, mass: f64, stiffness: f64) {
        self.removed_mass += mass;
        self.removed_stiffness += stiffness;
    }

    /// Runs the four checks on `body`; `stage` and `step` name the moment in an error.
    /// O(darts · n²) for `validate()`, O(darts · log) for the rest.
    ///
    /// # Errors
    /// The first check that fails: [`DemoError::Invalid`], [`DemoError::Conservation`] or
    /// [`DemoError::Balance`].
    pub fn check(&mut self, body: &Body, stage: &'static str, step: u64) -> Result<Residuals, DemoError> {
        let map = body.map();
        map.validate().map_err(|violation| DemoError::Invalid { stage, step, violation })?;
        self.passed += 1;
        check_conservation(map, body.attrs()).map_err(|source| DemoError::Conservation { stage, step, source })?;
        self.passed += 1;
        let mass = (total_mass(body) + self.removed_mass - self.initial_mass) / self.initial_mass;
        let stiffness = if self.initial_stiffness > 0.0 {
            (total_stiffness(body) + self.removed_stiffness - self.initial_stiffness) / self.initial_stiffness
        } else {
            0.0
        };
        for (quantity, residual) in [("total mass", mass), ("total stiffness", stiffness)] {
            if residual.is_nan() || residual.abs() > TOLERANCE {
                return Err(DemoError::Balance { stage, step, quantity, residual });
            }
            self.passed += 1;
        }
        self.last = Residuals { mass, stiffness };
        Ok(self.last)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::demo::test_cube as cube;
    use topomech::cut;

    #[test]
    fn a_fresh_body_passes_the_four_checks() {
        let body = cube();
        let mut checker = Checker::new(&body);
        assert!((checker.initial_mass - 1.7 * 8.0).abs() < 1e-12, "ρ · volume");
        let r = checker.check(&body, "test", 0).unwrap();
        assert_eq!(checker.passed, 4);
        assert_eq!(r, Residuals { mass: 0.0, stiffness: 0.0 });
    }

    #[test]
    fn a_removal_is_balanced_by_what_it_reports() {
        let mut body = cube();
        let mut checker = Checker::new(&body);
        let r = cut::remove_volume(&mut body, topomech::CellId(5)).unwrap();
        assert!(matches!(checker.check(&body, "removal", 1), Err(DemoError::Balance { quantity: "total mass", .. })));
        checker.removed(r.removed_mass, r.removed_stiffness);
        let res = checker.check(&body, "removal", 1).unwrap();
        assert!(res.mass.abs() <= TOLERANCE && res.stiffness.abs() <= TOLERANCE, "{res:?}");
    }

    #[test]
    fn an_unbalanced_account_stops_with_the_stage_and_quantity() {
        let body = cube();
        let mut checker = Checker::new(&body);
        checker.removed(0.0, 1.0);
        let err = checker.check(&body, "tear", 7).unwrap_err();
        let msg = err.to_string();
        assert!(msg.contains("stage tear, step 7") && msg.contains("total stiffness"), "{msg}");
        assert_eq!(checker.passed, 3, "validity, conservation and mass passed before");
    }
}
