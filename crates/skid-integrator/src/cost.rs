//! What a Newton loop spends: wall time per part and the linear systems factorized and
//! iterated on, summed over increments and steps for the run's statistics.

use std::time::Duration;

/// Wall time spent in the parts of the Newton loop.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Timings {
    /// Element loop, loads and contact kinematics.
    pub assembly: Duration,
    /// Numeric factorizations and triangular solves (including the Delassus operator).
    pub linear_solve: Duration,
    /// Of `linear_solve`: the numeric factorizations of every kind.
    #[serde(default)]
    pub factorization: Duration,
    /// Exact Coulomb solves of the reduced contact path (semismooth Newton, and the conic
    /// solves behind it).
    pub contact_solve: Duration,
    /// The observer: history and field output and restart files of converged increments.
    #[serde(default)]
    pub output: Duration,
}

/// Factorizations and iterative solves of the linear systems.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct SolveCounts {
    /// Cholesky factorizations of the effective tangent (contact-free steps, the reduced
    /// contact path).
    pub tangent_factorizations: usize,
    /// Sparse LU factorizations of the global contact system.
    pub lu_factorizations: usize,
    /// `L D L^T` factorizations of its quasi-definite approximation.
    pub preconditioner_factorizations: usize,
    /// GMRES iterations (each one solve with a factorization and one product with the matrix).
    pub krylov_iterations: usize,
}

impl SolveCounts {
    /// Factorizations of every kind.
    pub fn factorizations(&self) -> usize {
        self.tangent_factorizations + self.lu_factorizations + self.preconditioner_factorizations
    }

    /// Adds the work done between the snapshots `before` and `after` of a workspace's counts.
    pub fn add_between(&mut self, before: &Self, after: &Self) {
        self.tangent_factorizations += after.tangent_factorizations - before.tangent_factorizations;
        self.lu_factorizations += after.lu_factorizations - before.lu_factorizations;
        self.preconditioner_factorizations +=
            after.preconditioner_factorizations - before.preconditioner_factorizations;
        self.krylov_iterations += after.krylov_iterations - before.krylov_iterations;
    }
}
