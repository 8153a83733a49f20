//! Errors of model construction and of the time integration.
//!
//! A failure to converge is not a programming error: [`IncrementFailure`] describes why one
//! increment failed, and the stepper answers it with a cutback. Only when the cutbacks are
//! exhausted does the run end with a [`RunError`], which says where and why.

use thiserror::Error;

use crate::dof::EquationOwner;

/// An inconsistent model (caught before any numerics run).
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ModelError {
    /// A finite-element entity is invalid (mesh, material, element geometry, rigid body).
    #[error(transparent)]
    Fem(#[from] skid_fem::error::FemError),
    /// A contact surface could not be built.
    #[error(transparent)]
    Contact(#[from] skid_contact::error::ContactError),
    /// A reference to a node, body or set that does not exist, or an unsupported combination.
    #[error("{0}")]
    Invalid(String),
}

/// Why one increment failed; answered by a cutback.
#[derive(Debug, Error, Clone)]
#[non_exhaustive]
pub enum IncrementFailure {
    /// Newton-Raphson did not converge within the iteration limit.
    #[error(
        "Newton did not converge in {iterations} iterations (force residual {force_residual:.3e}, contact residual {contact_residual:.3e}{})",
        worst.map(|w| format!("; worst {w}")).unwrap_or_default()
    )]
    NewtonNotConverged {
        /// Iterations performed.
        iterations: usize,
        /// Last scaled force residual.
        force_residual: f64,
        /// Last scaled contact (kinematic) residual.
        contact_residual: f64,
        /// Where the residual furthest above its tolerance is largest (`None` if no residual
        /// was measured).
        worst: Option<WorstResidual>,
    },
    /// A residual, increment or contact force became NaN or infinite.
    #[error("non-finite values in Newton iteration {iteration}")]
    NonFinite {
        /// Iteration at which it was detected.
        iteration: usize,
    },
    /// An element turned inside out (J <= 0), at its centre or at a corner.
    #[error("element {element} inverted (J = {det_f:.3e} {})", skid_fem::error::inversion_point(*.corner))]
    InvertedElement {
        /// Element index in the mesh.
        element: usize,
        /// Volume ratio found.
        det_f: f64,
        /// The corner where it was found, `None` for the centre.
        corner: Option<usize>,
    },
    /// An element could not be evaluated for another reason.
    #[error("element {element}: {message}")]
    Element {
        /// Element index in the mesh.
        element: usize,
        /// What went wrong.
        message: String,
    },
    /// A load could not be evaluated on the current geometry.
    #[error("load: {0}")]
    Load(String),
    /// A linear system could not be solved.
    #[error("linear solve of the {system} failed: {failure}")]
    LinearSolve {
        /// Which system: the effective tangent, the global contact system, ...
        system: &'static str,
        /// What went wrong.
        failure: LinearFailure,
    },
    /// The frictional contact problem was not solved (see
    /// [`skid_contact::error::ContactError::calls_for_cutback`]).
    #[error("contact solve failed: {0}")]
    Contact(skid_contact::error::ContactError),
    /// A contact node left the region where its surface projection is defined.
    #[error("node {node} has no projection on contact surface of pair {pair}")]
    NoProjection {
        /// Contact pair index.
        pair: usize,
        /// Node index.
        node: usize,
    },
}

/// Where a Newton iteration's residual is largest: the equation of the largest force residual,
/// or the candidate of the largest contact residual, whichever is further above its tolerance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum WorstResidual {
    /// The force (or moment) residual of one equation.
    Equation(EquationOwner),
    /// The contact residual (gap, slip or Coulomb law) of one candidate.
    Contact {
        /// Contact pair index.
        pair: usize,
        /// The candidate's slave node.
        node: usize,
    },
}

impl std::fmt::Display for WorstResidual {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let axis = |component: usize| ["x", "y", "z"].get(component).copied().unwrap_or("?");
        match *self {
            Self::Equation(EquationOwner::Node { node, component }) => {
                write!(f, "force at node {node} ({})", axis(component))
            }
            Self::Equation(EquationOwner::BodyTranslation { body, component }) => {
                write!(f, "force on rigid body {body} ({})", axis(component))
            }
            Self::Equation(EquationOwner::BodyRotation { body, component }) => {
                write!(f, "moment on rigid body {body} (rotation {component})")
            }
            Self::Contact { pair, node } => write!(f, "contact of node {node} in pair {pair}"),
        }
    }
}

/// Why a linear system could not be solved.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum LinearFailure {
    /// The matrix has NaN or infinite entries.
    #[error("non-finite matrix entries")]
    NonFinite,
    /// The Cholesky factorization broke down: the matrix is not positive definite.
    #[error("the matrix is not positive definite")]
    NotPositiveDefinite,
    /// The solution came out non-finite: the matrix is singular.
    #[error("the matrix is singular (non-finite solution)")]
    Singular,
    /// The system is built inconsistently (a programming error, not a numerical one).
    #[error("inconsistent system: {0}")]
    Structure(String),
    /// The sparse solver could not run (its message: out of memory, ...).
    #[error("sparse solver: {0}")]
    Solver(String),
}

impl IncrementFailure {
    /// A failure of the linear solve of `system`.
    pub fn linear(system: &'static str, failure: LinearFailure) -> Self {
        Self::LinearSolve { system, failure }
    }

    /// Whether a shorter increment may succeed: false for a contact problem that is invalid
    /// rather than unsolved, and for an inconsistently built linear system.
    pub fn calls_for_cutback(&self) -> bool {
        match self {
            Self::Contact(e) => e.calls_for_cutback(),
            Self::LinearSolve {
                failure: LinearFailure::Structure(_),
                ..
            } => false,
            _ => true,
        }
    }

    /// A short name of the kind of failure, for counting cutbacks by cause.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::NewtonNotConverged { .. } => "newton not converged",
            Self::NonFinite { .. } => "non-finite values",
            Self::InvertedElement { .. } => "inverted element",
            Self::Element { .. } => "element evaluation",
            Self::Load(_) => "load evaluation",
            Self::LinearSolve { failure, .. } => match failure {
                LinearFailure::NonFinite => "non-finite matrix",
                LinearFailure::NotPositiveDefinite => "tangent not positive definite",
                LinearFailure::Singular => "singular system",
                LinearFailure::Structure(_) | LinearFailure::Solver(_) => "linear solver",
            },
            Self::Contact(_) => "contact solve",
            Self::NoProjection { .. } => "no contact projection",
        }
    }
}

/// A run that could not be completed.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum RunError {
    /// An increment failed even at the smallest allowed size.
    #[error(
        "step '{step}' failed at increment {increment} (time {time:.6e} s, size {size:.3e}) after {cutbacks} consecutive cutbacks: {cause}"
    )]
    StepFailed {
        /// Step name.
        step: String,
        /// Index of the increment being attempted (1-based within the step).
        increment: usize,
        /// Time at the start of the failed increment.
        time: f64,
        /// Size of the last attempted increment (time, or load factor for static steps).
        size: f64,
        /// Consecutive cutbacks of this increment before giving up (earlier increments' cutbacks
        /// may already have left `size` below the nominal one).
        cutbacks: usize,
        /// The last failure.
        cause: IncrementFailure,
    },
    /// The observer (output writer) failed.
    #[error("writing results failed: {0}")]
    Output(#[from] std::io::Error),
    /// The steps or settings are inconsistent.
    #[error("{0}")]
    Invalid(String),
}

impl RunError {
    /// A short name of why the run stopped: the kind of the increment failure that exhausted
    /// the cutbacks (see [`IncrementFailure::kind`]), `"output"` or `"invalid"`.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::StepFailed { cause, .. } => cause.kind(),
            Self::Output(_) => "output",
            Self::Invalid(_) => "invalid",
        }
    }
}

#[cfg(test)]
mod tests {
    use skid_contact::error::ContactError;

    use super::*;

    #[test]
    fn only_failures_a_shorter_increment_may_cure_call_for_a_cutback() {
        let unsolved = IncrementFailure::Contact(ContactError::FixedPointNotConverged {
            iterations: 50,
            error: 1e-3,
        });
        let invalid = IncrementFailure::Contact(ContactError::InvalidProblem("mu < 0".into()));
        let indefinite = IncrementFailure::linear("tangent", LinearFailure::NotPositiveDefinite);
        let broken = IncrementFailure::linear("tangent", LinearFailure::Structure("x".into()));
        assert!(unsolved.calls_for_cutback() && indefinite.calls_for_cutback());
        assert!(!invalid.calls_for_cutback() && !broken.calls_for_cutback());
        assert_eq!(indefinite.kind(), "tangent not positive definite");
        assert_eq!(
            indefinite.to_string(),
            "linear solve of the tangent failed: the matrix is not positive definite"
        );
    }
}
