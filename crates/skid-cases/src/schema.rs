//! The case-file schema (JSON).
//!
//! A case describes the braking-drum scene by its physical parameters; the builder
//! ([`crate::drum`]) turns it into a finite-element model. Every object rejects unknown fields,
//! and every value is checked by [`crate::validate`] before anything is built. Units are SI.
//!
//! Geometry convention: the drum axis is z through the origin, the pad sits on top with its
//! front face in the plane `y = R + standoff` and its back face `thickness` above, spanning
//! `x in [-length/2, length/2]` (and `z in [-width/2, width/2]` in 3D). The drum spins about +z.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use skid_fem::element::Formulation;
use skid_fem::hourglass::Hourglass;
use skid_integrator::settings::ContactSolve;

/// Index of the drum among the rigid bodies of a drum case's model.
pub const DRUM: usize = 0;
/// Index of the back plate among the rigid bodies of a drum case's model.
pub const BACK_PLATE: usize = 1;
/// Names of the drum case's rigid bodies, by index (as case files name them in a step's
/// `hold`).
pub const BODY_NAMES: [&str; 2] = ["drum", "back_plate"];

/// A complete case.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Case {
    /// Case name (output directory and report label).
    pub name: String,
    /// Free text.
    #[serde(default)]
    pub description: String,
    /// Spatial dimension: 2 (plane strain) or 3.
    pub dimension: usize,
    /// The rigid drum.
    pub drum: DrumSpec,
    /// The deformable pad.
    pub pad: PadSpec,
    /// The rigid back plate and its load.
    pub back_plate: BackPlateSpec,
    /// Friction between the pad's front face and the drum.
    pub contact: ContactSpec,
    /// Analysis steps, in order.
    pub steps: Vec<StepSpec>,
    /// Solver settings (all optional).
    #[serde(default)]
    pub solver: SolverSpec,
    /// Field output (optional; none by default).
    #[serde(default)]
    pub output: OutputSpec,
    /// What a run of the case is expected to show (optional; read by `skid report`'s hard-case
    /// checks, ignored by the solver).
    #[serde(default)]
    pub expect: ExpectSpec,
}

/// The rigid drum: its inertia sits at the reference node on the axis.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct DrumSpec {
    /// Radius, m.
    pub radius: f64,
    /// Axial width, m (3D surface extent; informative in 2D).
    pub width: f64,
    /// Mass, kg (its reference node cannot translate).
    pub mass: f64,
    /// Rotary inertia about the axis, kg m^2.
    pub rotary_inertia: f64,
    /// Initial angular velocity about +z, rad/s.
    pub omega0: f64,
    /// How the drum surface is represented.
    pub surface: DrumSurfaceSpec,
}

/// Drum surface idealization. Whatever the idealization, the drum's inertia sits at its
/// reference node and its surface carries no mass and no degrees of freedom.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum DrumSurfaceSpec {
    /// Analytical circle (2D) or cylinder (3D).
    Analytic,
    /// `count` flat facets around the circumference, the elements of the rigid drum:
    /// two-node rigid lines in 2D (R2D2); in 3D four-node rigid quads (R3D4), or membranes
    /// (M3D4R) or shells (S4R) made rigid, with zero density and a zero-thickness contact
    /// surface. Being rigid and massless, the three 3D element types share one contact geometry:
    /// the polygon prism inscribed in the drum circle.
    Facets {
        /// Element type of the facets.
        element: FacetElement,
        /// Number of facets around the circumference.
        count: usize,
    },
    /// A solid annular drum of four-node tetrahedra (C3D4) made rigid, zero density; contact
    /// on its exterior faces (3D only).
    Tetrahedra {
        /// Cells around the circumference.
        sectors: usize,
        /// Cells through the wall.
        rings: usize,
        /// Cells across the width.
        layers: usize,
        /// Inner radius of the annulus, m.
        inner_radius: f64,
    },
}

/// Element types of a faceted drum.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum FacetElement {
    /// Two-node rigid line (2D).
    R2d2,
    /// Four-node rigid quad (3D).
    R3d4,
    /// Four-node membrane made rigid (3D).
    M3d4r,
    /// Four-node shell made rigid (3D).
    S4r,
}

/// The pad block and its mesh.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PadSpec {
    /// Circumferential length (along x), m.
    pub length: f64,
    /// Axial width (along z), m; the plane-strain thickness in 2D.
    pub width: f64,
    /// Radial thickness (along y), m.
    pub thickness: f64,
    /// Elements along x, y (radial) and z (ignored in 2D).
    pub elements: ElementCounts,
    /// Initial distance of the front face above the drum's top, m.
    #[serde(default)]
    pub standoff: f64,
    /// Mass density, kg/m^3.
    pub density: f64,
    /// Hyperelastic material.
    pub material: MaterialSpec,
    /// Factor on the hourglass stabilisation stiffness (of the one-point element, with the
    /// `stiffness` control).
    #[serde(default = "one")]
    pub hourglass_scale: f64,
    /// Hourglass control of the one-point element: `stiffness` (the default) or `enhanced`;
    /// `enhanced` only with `formulation = "reduced"`.
    #[serde(default, skip_serializing_if = "HourglassControl::is_default")]
    pub hourglass: HourglassControl,
    /// The pad's element formulation: `reduced` (one-point with hourglass control: CPE4R /
    /// C3D8R, the default), `full` (CPE4 / C3D8), `hybrid` (CPE4H / C3D8H) or `incompatible`
    /// (CPE4I / C3D8I).
    #[serde(default)]
    pub formulation: PadFormulation,
    /// The pad has no inertia: in the spin-down it is in equilibrium with the mean contact
    /// force of each increment (`density` then only regularises the static Newton steps). The
    /// back plate tied to it must then be massless too.
    #[serde(default)]
    pub quasi_static: bool,
    /// The lumped mass of the pad's contact nodes moved to the other nodes of their elements
    /// (see the model file's `part.section.massless_contact_nodes`).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub massless_contact_nodes: bool,
    /// Stiffness-proportional (Rayleigh) damping factor `beta` of the pad, s (see the model
    /// file's `part.section.stiffness_damping`); 0, the default: none.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub stiffness_damping: f64,
}

/// Whether a factor is 0 (left out when written).
fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

/// The element formulation of a pad, in either dimension.
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum PadFormulation {
    /// One-point integration with hourglass control (CPE4R / C3D8R).
    #[default]
    Reduced,
    /// Full integration, displacement formulation (CPE4 / C3D8).
    Full,
    /// Full integration, constant-pressure hybrid (CPE4H / C3D8H).
    Hybrid,
    /// Full integration with incompatible modes (CPE4I / C3D8I).
    Incompatible,
}

impl PadFormulation {
    /// Every formulation.
    pub const ALL: [Self; 4] = [Self::Reduced, Self::Full, Self::Hybrid, Self::Incompatible];

    /// Its name in case files (`pad.formulation`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Reduced => "reduced",
            Self::Full => "full",
            Self::Hybrid => "hybrid",
            Self::Incompatible => "incompatible",
        }
    }

    /// The formulation of a name of [`Self::name`].
    ///
    /// # Errors
    /// A message listing the names.
    pub fn parse(name: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|f| f.name() == name)
            .ok_or_else(|| {
                let names: Vec<_> = Self::ALL.iter().map(|f| f.name()).collect();
                format!("expected one of {}, got {name:?}", names.join(", "))
            })
    }

    /// The element kernels' formulation.
    pub fn formulation(self) -> Formulation {
        match self {
            Self::Reduced => Formulation::Reduced,
            Self::Full => Formulation::Full,
            Self::Hybrid => Formulation::Hybrid,
            Self::Incompatible => Formulation::Incompatible,
        }
    }
}

/// The hourglass control of the one-point elements (CPE4R / C3D8R).
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum HourglassControl {
    /// A stiffness on each hourglass mode from the material's initial shear modulus
    /// (Flanagan-Belytschko), times the hourglass scale.
    #[default]
    Stiffness,
    /// Abaqus' enhanced hourglass control: the hourglass modes have the small-strain stiffness
    /// of the incompatible-mode element (CPE4I / C3D8I) of the same geometry, so that in the
    /// linear limit the one-point element is that element; it takes no hourglass scale.
    Enhanced,
}

impl HourglassControl {
    /// Whether it is the default, [`Self::Stiffness`] (left out when written).
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }

    /// Its name in model and case files.
    pub fn name(self) -> &'static str {
        match self {
            Self::Stiffness => "stiffness",
            Self::Enhanced => "enhanced",
        }
    }

    /// The element kernels' control; `scale` is the stiffness control's factor.
    pub fn hourglass(self, scale: f64) -> Hourglass {
        match self {
            Self::Stiffness => Hourglass::Stiffness { scale },
            Self::Enhanced => Hourglass::Enhanced,
        }
    }

    /// Checks the hourglass scale `scale` that goes with the control: the enhanced control
    /// takes none, so its scale must be the default 1.
    ///
    /// # Errors
    /// A message for the scale's field.
    pub fn check_scale(self, scale: f64) -> Result<(), String> {
        if self == Self::Enhanced && scale != 1.0 {
            Err(format!(
                "the enhanced hourglass control takes no scale: expected 1, got {scale}"
            ))
        } else {
            Ok(())
        }
    }
}

/// The serde default of factors and thicknesses: 1.
pub(crate) fn one() -> f64 {
    1.0
}

/// Element counts of the structured pad mesh.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ElementCounts {
    /// Along the circumference (x).
    pub circumferential: usize,
    /// Through the thickness (y).
    pub radial: usize,
    /// Across the width (z, 3D only).
    #[serde(default = "one_usize")]
    pub axial: usize,
}

fn one_usize() -> usize {
    1
}

/// Material laws.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum MaterialSpec {
    /// Polynomial hyperelasticity of order 1:
    /// `U = C10 (I1bar - 3) + C01 (I2bar - 3) + (J - 1)^2 / D1`.
    PolynomialN1 {
        /// C10, Pa.
        c10: f64,
        /// C01, Pa.
        c01: f64,
        /// D1, 1/Pa.
        d1: f64,
    },
}

/// The rigid plate tied to the pad's back face; it may only translate radially (along y).
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct BackPlateSpec {
    /// Pressure on the back face, Pa (pushes the pad onto the drum).
    pub pressure: f64,
    /// Mass of the plate itself, kg (the tied pad nodes add theirs).
    #[serde(default)]
    pub mass: f64,
}

/// Coulomb friction between the pad and the drum.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// Coulomb friction coefficient (dimensionless, >= 0).
    pub mu: f64,
    /// How contact candidates are chosen.
    #[serde(default)]
    pub formulation: ContactFormulation,
}

/// How contact candidates are chosen.
#[derive(Clone, Debug, Default, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum ContactFormulation {
    /// A contact pair: the pad's front face (slave) against the drum surface (master).
    #[default]
    Pair,
    /// General contact: every node on any exterior face of the pad is tested against every
    /// rigid surface, and kept as a candidate if its initial distance is below
    /// `search_distance`.
    General {
        /// Search distance, m.
        search_distance: f64,
    },
}

/// One analysis step.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum StepSpec {
    /// Static equilibrium with loads ramped to full value.
    Static {
        /// Step name.
        name: String,
        /// Number of increments.
        increments: usize,
        /// Rigid bodies held fixed ("drum", "back_plate").
        #[serde(default)]
        hold: Vec<String>,
        /// Time scale of the Newton regularisation `M/h_s^2`, s.
        #[serde(default = "default_regularization_time")]
        regularization_time: f64,
    },
    /// HHT-alpha dynamics.
    Dynamic {
        /// Step name.
        name: String,
        /// Duration, s.
        duration: f64,
        /// Time increment, s.
        dt: f64,
        /// HHT alpha in [-1/3, 0].
        #[serde(default = "default_alpha")]
        alpha: f64,
        /// Rigid bodies held fixed.
        #[serde(default)]
        hold: Vec<String>,
        /// Increments chosen by the local error, `dt` being the first (absent: `dt`
        /// throughout).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        adaptive: Option<AdaptiveSpec>,
    },
}

/// Error-controlled increments of a dynamic step (see `skid_integrator::stepper::Adaptive`):
/// an increment whose estimated local error exceeds `tolerance` is taken again shorter, the
/// next size follows from the error, and an increment ends where the drum would stop.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct AdaptiveSpec {
    /// Local error tolerance, relative to the model size (translations) or 1 rad (rotations).
    pub tolerance: f64,
    /// Smallest increment, s.
    pub min_dt: f64,
    /// Largest increment, s.
    pub max_dt: f64,
}

/// Default time scale of the static regularisation, s.
pub(crate) fn default_regularization_time() -> f64 {
    1e-2
}

/// Default HHT alpha.
pub(crate) fn default_alpha() -> f64 {
    -0.3
}

/// Solver settings; every field is optional.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct SolverSpec {
    /// Newton iteration limit per increment.
    pub max_newton_iterations: usize,
    /// Relative force residual tolerance.
    pub force_tolerance: f64,
    /// Contact kinematic tolerance relative to the model size: a converged increment's gaps
    /// and slips are within this times the model size of those for which the Coulomb law
    /// holds exactly.
    pub contact_tolerance: f64,
    /// Natural-map tolerance of the Coulomb solve.
    pub coulomb_tolerance: f64,
    /// Fixed-point iteration limit of the Coulomb solve.
    pub max_fixed_point_iterations: usize,
    /// Which algorithm leads the Coulomb solve.
    pub coulomb_method: CoulombMethodSpec,
    /// How each Newton iteration obtains its contact forces.
    pub contact_solve: ContactSolveSpec,
    /// Increment size factor after a failure.
    pub cutback_factor: f64,
    /// Consecutive cutbacks before the run stops.
    pub max_cutbacks: usize,
}

impl SolverSpec {
    /// The contact solve these settings ask for, where `auto` takes `preferred` (the model's,
    /// [`ContactSolve::preferred_for`]); the conic Coulomb method works on the reduced operator
    /// only.
    pub fn contact_solve_with(&self, preferred: ContactSolve) -> ContactSolve {
        match (self.contact_solve, self.coulomb_method) {
            (_, CoulombMethodSpec::Conic) | (ContactSolveSpec::Reduced, _) => ContactSolve::Reduced,
            (ContactSolveSpec::Auto, _) => preferred,
            (ContactSolveSpec::Global, _) => ContactSolve::Global,
        }
    }
}

impl Default for SolverSpec {
    fn default() -> Self {
        let newton = skid_integrator::settings::NewtonSettings::default();
        let coulomb = skid_contact::coulomb::CoulombSettings::default();
        let cutback = skid_integrator::settings::CutbackSettings::default();
        Self {
            max_newton_iterations: newton.max_iterations,
            force_tolerance: newton.force_tolerance,
            contact_tolerance: newton.contact_tolerance,
            coulomb_tolerance: coulomb.tolerance,
            max_fixed_point_iterations: coulomb.max_fixed_point_iterations,
            coulomb_method: CoulombMethodSpec::default(),
            contact_solve: ContactSolveSpec::default(),
            cutback_factor: cutback.factor,
            max_cutbacks: cutback.max_cutbacks,
        }
    }
}

/// Which algorithm leads the exact Coulomb solve of every Newton iteration (see
/// `skid_contact::coulomb::CoulombMethod`).
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum CoulombMethodSpec {
    /// Semismooth Newton from the last forces, the conic (clarabel) fixed point where it fails.
    #[default]
    NewtonFirst,
    /// The conic (clarabel) fixed point every time: slower, an independent check.
    Conic,
}

impl From<CoulombMethodSpec> for skid_contact::coulomb::CoulombMethod {
    fn from(spec: CoulombMethodSpec) -> Self {
        match spec {
            CoulombMethodSpec::NewtonFirst => Self::NewtonFirst,
            CoulombMethodSpec::Conic => Self::Conic,
        }
    }
}

/// How each Newton iteration obtains its contact forces (see
/// `skid_integrator::settings::ContactSolve`).
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum ContactSolveSpec {
    /// `global` for a quasi-static pad or a global system of 2,000 unknowns or more (equations
    /// and contact rows), `reduced` otherwise. A quasi-static pad is held only by its contacts:
    /// without them its stiffness is singular (the pad and plate translate freely), and the
    /// reduced path, which needs its inverse, regularises it by a mass shift that slows Newton
    /// down; the global system holds the contacts and needs none. On large systems the
    /// reduced path's dense Delassus operator costs more than the global path's
    /// preconditioned iterations (40 x 8 x 8 pad: 16 s against 28 s for 4 ms of spin-down).
    #[default]
    Auto,
    /// Step and forces together on one sparse system (semismooth Newton on the Alart–Curnier
    /// function); an increment it does not converge is solved again by `reduced`.
    Global,
    /// The exact Coulomb problem on the dense Delassus operator of the contact set, by
    /// `coulomb_method` (which `conic` requires).
    Reduced,
}

/// Output settings; every field is optional.
#[derive(Clone, Debug, Default, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct OutputSpec {
    /// Physical time between ParaView field frames in dynamic steps, s (written to
    /// `<out>/fields/`); frames are also written for the initial state, at the end of every
    /// static step and at the end of the run. Absent or null: no field output.
    pub field_interval: Option<f64>,
}

/// Expectations on a run, for the checks of `skid report --hard`; every field is optional.
/// The checks themselves are derived from the case (see `skid_report::hard`); this only
/// adjusts them where a case's physics departs from the assumptions of the defaults.
#[derive(Clone, Debug, Default, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct ExpectSpec {
    /// Relative tolerance of the stop time against the estimate `I omega0 / (mu p A R)`;
    /// absent or null: the report's default.
    pub t_stop_estimate_tolerance: Option<f64>,
    /// Why the case departs from the defaults (shown in the report).
    pub note: String,
    /// The run is expected to stop early with this kind of failure: the case lies beyond what
    /// the model can represent, and shows that skid stops with a clear message and keeps its
    /// results. Absent or null: the run is expected to complete.
    pub failure: Option<ExpectedFailure>,
}

/// A kind of failure a case may be built to show (see `expect.failure`).
#[derive(Clone, Copy, Debug, Deserialize, Serialize, JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum ExpectedFailure {
    /// An element turned inside out or folded.
    InvertedElement,
    /// Newton-Raphson did not converge, even after the cutbacks.
    NewtonNotConverged,
    /// The frictional contact problem was not solved.
    ContactSolve,
}

impl ExpectedFailure {
    /// The name the run's summary gives this failure (`summary.json`'s `failure`, from
    /// [`skid_integrator::IncrementFailure::kind`]).
    pub fn kind(self) -> &'static str {
        match self {
            Self::InvertedElement => "inverted element",
            Self::NewtonNotConverged => "newton not converged",
            Self::ContactSolve => "contact solve",
        }
    }

    /// Whether a run whose summary says `failure` (its kind, `None` if it completed) stopped
    /// as expected.
    pub fn matches(self, failure: Option<&str>) -> bool {
        failure == Some(self.kind())
    }
}

#[cfg(test)]
mod tests {
    use skid_integrator::IncrementFailure;

    use super::ExpectedFailure;

    #[test]
    fn expected_failures_name_the_kinds_the_integrator_reports() {
        let pairs = [
            (
                ExpectedFailure::InvertedElement,
                IncrementFailure::InvertedElement {
                    element: 0,
                    det_f: -1e-3,
                    corner: Some(3),
                },
            ),
            (
                ExpectedFailure::NewtonNotConverged,
                IncrementFailure::NewtonNotConverged {
                    iterations: 25,
                    force_residual: 1e-3,
                    contact_residual: 0.0,
                    worst: None,
                },
            ),
            (
                ExpectedFailure::ContactSolve,
                IncrementFailure::Contact(
                    skid_contact::error::ContactError::FixedPointNotConverged {
                        iterations: 50,
                        error: 1e-3,
                    },
                ),
            ),
        ];
        for (expected, failure) in pairs {
            assert_eq!(expected.kind(), failure.kind());
            assert!(expected.matches(Some(failure.kind())));
            assert!(!expected.matches(None));
        }
        assert!(!ExpectedFailure::InvertedElement.matches(Some("newton not converged")));
    }
}
