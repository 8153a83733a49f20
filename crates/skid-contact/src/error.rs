//! Errors of the contact crate.

/// Everything that can go wrong in contact geometry or in the friction solve.
///
/// [`ContactError::ConicSolveFailed`] and [`ContactError::FixedPointNotConverged`] mean that a
/// well-posed problem was not solved to tolerance; a time integrator should answer them with a
/// time-step cutback (see [`ContactError::calls_for_cutback`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ContactError {
    /// The friction problem is malformed (sizes, non-finite data, negative friction coefficient,
    /// unsupported dimension, invalid settings).
    #[error("invalid friction problem: {0}")]
    InvalidProblem(String),
    /// The conic solver (clarabel) stopped with a status other than an accepted solution.
    #[error(
        "conic solver stopped with status {status} in fixed-point iteration {fixed_point_iteration}"
    )]
    ConicSolveFailed {
        /// Clarabel's termination status, as text.
        status: String,
        /// One-based index of the fixed-point iteration whose conic solve failed.
        fixed_point_iteration: usize,
    },
    /// The fixed point on the De Saxcé shift did not reach the natural-map tolerance.
    #[error(
        "Coulomb fixed point did not converge in {iterations} iterations (natural-map error {error:e})"
    )]
    FixedPointNotConverged {
        /// Number of fixed-point iterations performed.
        iterations: usize,
        /// Natural-map error of the last iterate.
        error: f64,
    },
    /// A rigid surface was constructed from invalid data.
    #[error("invalid rigid surface: {0}")]
    InvalidSurface(String),
}

impl ContactError {
    /// True for the errors that mean "did not converge" on valid input, which a time integrator
    /// should turn into a time-step cutback; false for invalid input.
    pub fn calls_for_cutback(&self) -> bool {
        matches!(
            self,
            ContactError::ConicSolveFailed { .. } | ContactError::FixedPointNotConverged { .. }
        )
    }
}
