//! Errors of model construction and of the time integration.
//!
//! A failure to converge is not a programming error: [`IncrementFailure`] describes why one
//! increment failed, and the stepper answers it with a cutback. Only when the cutbacks are
//! exhausted does the run end with a [`RunError`], which says where and why.

use thiserror::Error;

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
        "Newton did not converge in {iterations} iterations (force residual {force_residual:.3e}, contact residual {contact_residual:.3e})"
    )]
    NewtonNotConverged {
        /// Iterations performed.
        iterations: usize,
        /// Last scaled force residual.
        force_residual: f64,
        /// Last scaled contact (kinematic) residual.
        contact_residual: f64,
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
    /// The effective tangent could not be factorized (not positive definite).
    #[error("linear solve failed: {0}")]
    LinearSolve(String),
    /// The frictional contact problem was not solved.
    #[error("contact solve failed: {0}")]
    Contact(String),
    /// A contact node left the region where its surface projection is defined.
    #[error("node {node} has no projection on contact surface of pair {pair}")]
    NoProjection {
        /// Contact pair index.
        pair: usize,
        /// Node index.
        node: usize,
    },
}

impl IncrementFailure {
    /// A short name of the kind of failure, for counting cutbacks by cause.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::NewtonNotConverged { .. } => "newton not converged",
            Self::NonFinite { .. } => "non-finite values",
            Self::InvertedElement { .. } => "inverted element",
            Self::Element { .. } => "element evaluation",
            Self::Load(_) => "load evaluation",
            Self::LinearSolve(_) => "tangent not positive definite",
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
