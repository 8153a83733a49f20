//! Sparse-Newton HHT-alpha integration of a deformable solid in frictional contact with rigid
//! bodies.
//!
//! The pieces, in the order a time increment uses them:
//! - [`model`]: the assembled scene (mesh, material, rigid bodies, ties, loads, contact pairs);
//! - [`loads`]: pressures, concentrated loads and gravity, and their amplitudes;
//! - [`dof`]: which global equation each node component and rigid-body motion maps to;
//! - [`orientation`]: the orientations of rigid bodies free to turn, and their gyroscopic
//!   moments;
//! - [`sparse`]: the fixed sparsity pattern and the Cholesky factorization whose symbolic
//!   analysis is computed once per run and reused for every Newton iteration;
//! - [`assembly`]: internal forces, tangent, lumped masses and follower pressure on that pattern;
//! - [`mixed`]: the element pressures of the mixed (u-p) tangent between Newton iterates;
//! - [`hht`]: the HHT-alpha / Newmark relations between displacement, velocity and acceleration;
//! - [`contact_rows`]: the contact rows H (gap and slip linearised in the global unknowns);
//! - [`coupling`]: the reduction of one Newton step to the exact-Coulomb problem in the contact
//!   forces (the dense reference path);
//! - [`global_contact`]: one Newton step of unknowns and contact forces together, on a sparse
//!   unsymmetric system, solved by GMRES ([`krylov`]) preconditioned with the factors of a
//!   symmetric quasi-definite approximation ([`quasi_definite`]) in a nested-dissection
//!   order ([`ordering`]);
//! - [`settings`]: Newton's, the Coulomb solve's, the contact path's and the cutback's settings;
//! - [`cost`]: the wall time and linear solves a Newton loop spends;
//! - [`increment`]: Newton-Raphson for one increment (static or dynamic);
//! - [`stepper`]: steps, automatic cutback, and reporting of converged increments.
//!
//! Everything is generic over the spatial dimension `D` (2 = plane strain, 3 = solid): one code
//! path serves both.

pub mod assembly;
pub mod contact_rows;
pub mod cost;
pub mod coupling;
pub mod dof;
pub mod error;
pub mod global_contact;
pub mod hht;
pub mod increment;
pub mod krylov;
pub mod loads;
pub mod mixed;
pub mod model;
pub mod motion;
pub mod ordering;
pub mod orientation;
pub mod quasi_definite;
pub mod settings;
pub mod solid_mass;
pub mod sparse;
pub mod state;
pub mod stepper;
#[cfg(test)]
mod test_support;

pub use error::{IncrementFailure, LinearFailure, ModelError, RunError, WorstResidual};
pub use loads::{
    Amplitude, ConcentratedLoad, GravityLoad, LoadInstant, LoadTarget, Loads, PressureLoad,
    StepVariation, Variation,
};
pub use model::{ContactPair, Model, Section, SolidPart, Tie};
pub use motion::{BodyMotion, MotionTarget, PrescribedMotion};
pub use settings::Settings;
pub use state::State;
pub use stepper::{
    Adaptive, Checkpoint, IncrementReport, Observer, RejectionReport, RunStatistics,
    StaticIncrements, Step, StepKind, StepStatistics, resume, run,
};
