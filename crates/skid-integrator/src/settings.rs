//! The solver's settings: Newton's iteration limit and tolerances, the Coulomb solve, which
//! contact solve each Newton iteration takes, and the cutback of a failed increment.

use skid_contact::coulomb::CoulombSettings;

use crate::global_contact::QUASI_DEFINITE_FROM;
use crate::model::Model;

/// Newton settings.
#[derive(Clone, Debug, PartialEq)]
pub struct NewtonSettings {
    /// Iteration limit per increment.
    pub max_iterations: usize,
    /// Relative force residual tolerance.
    pub force_tolerance: f64,
    /// Contact kinematic tolerance, relative to the model size: a converged increment's gaps
    /// and slips differ from those for which the Coulomb law holds exactly by less than this
    /// times the model size. The default, 1e-8, is under 3 nm on the braking drum (model size
    /// about 0.28 m), nanometres against a pad compressed by millimetres. 1e-9 took 11 % more
    /// Newton iterations on `3d-refined` (3738 against 3374) and 14 % more time (145.7 s
    /// against 127.9 s), for the same stop time to 4e-8 and deceleration to 2e-8.
    pub contact_tolerance: f64,
}

impl Default for NewtonSettings {
    fn default() -> Self {
        Self {
            max_iterations: 25,
            force_tolerance: 1e-6,
            contact_tolerance: 1e-8,
        }
    }
}

/// How each Newton iteration obtains its contact forces.
///
/// Both give the same converged increments (the same forces to the Coulomb tolerance); they
/// differ in cost, which [`ContactSolve::preferred_for`] weighs for a model.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ContactSolve {
    /// Displacement step and forces together from one sparse system (see
    /// [`crate::global_contact`]); an increment it does not converge is solved again by
    /// [`ContactSolve::Reduced`] before any cutback.
    Global,
    /// The exact Coulomb problem in the forces alone, on the Delassus operator of the contact
    /// set (see [`crate::coupling`]): dense, cubic in the contact candidates.
    #[default]
    Reduced,
}

impl ContactSolve {
    /// The faster path for `model`: [`ContactSolve::Global`] for a model with a quasi-static
    /// solid (held only by its contacts, its tangent without them is singular, which the
    /// reduced path must regularise by a mass shift that slows Newton down) or whose global
    /// system has [`QUASI_DEFINITE_FROM`] unknowns or more (preconditioned GMRES there costs
    /// less than the dense Delassus operator: on `3d-refined`, 9,965 unknowns, 4 ms of
    /// spin-down took 16.2 s against 27.6 s); [`ContactSolve::Reduced`] otherwise.
    pub fn preferred_for<const D: usize>(model: &Model<D>) -> Self {
        let candidates: usize = model.contacts().iter().map(|p| p.nodes.len()).sum();
        Self::preferred(
            model.part().quasi_static,
            model.dofs().len() + D * candidates,
        )
    }

    /// [`ContactSolve::preferred_for`] a model with a quasi-static solid or not and `unknowns`
    /// unknowns of its global system (equations and contact rows), known before it is built.
    pub fn preferred(quasi_static: bool, unknowns: usize) -> Self {
        if quasi_static || unknowns >= QUASI_DEFINITE_FROM {
            Self::Global
        } else {
            Self::Reduced
        }
    }
}

/// Cutback settings.
#[derive(Clone, Debug, PartialEq)]
pub struct CutbackSettings {
    /// Factor applied to the increment size after a failure.
    pub factor: f64,
    /// Consecutive cutbacks allowed before the run stops.
    pub max_cutbacks: usize,
    /// Successful increments before the size grows again.
    pub growth_after: usize,
    /// Growth factor (the size never exceeds the nominal one).
    pub growth_factor: f64,
    /// Smallest increment, as a fraction of the nominal one: a failure that would need a
    /// smaller one stops the run (crawling on with vanishing increments only hides it).
    pub min_fraction: f64,
}

impl Default for CutbackSettings {
    fn default() -> Self {
        Self {
            factor: 0.25,
            max_cutbacks: 8,
            growth_after: 3,
            growth_factor: 2.0,
            min_fraction: 1e-4,
        }
    }
}

/// All solver settings.
#[derive(Clone, Debug, Default)]
pub struct Settings {
    /// Newton settings.
    pub newton: NewtonSettings,
    /// Exact-Coulomb solver settings.
    pub coulomb: CoulombSettings,
    /// How each Newton iteration obtains its contact forces.
    pub contact_solve: ContactSolve,
    /// Cutback settings.
    pub cutback: CutbackSettings,
}
