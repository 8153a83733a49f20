//! The convex second-order-cone program of one fixed-point iteration, solved with clarabel:
//!
//! `min 1/2 r^T W r + c^T r  s.t.  r_i ∈ K_mu_i`,
//!
//! with `P = triu(W)`, `A = -diag(mu_i, 1[, 1])` per contact and `b = 0`, so that the slack
//! `s = -A r = (mu_i r_N, r_T)` lies in `SOC(dim)` (`t` first). A frictionless contact uses
//! `A = -I`, a non-negative cone on `r_N` and a zero cone on `r_T`. The solver is built once and
//! only the linear term `c` changes between fixed-point iterations.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};
use nalgebra::DMatrix;

use crate::error::ContactError;

/// A clarabel solver for the friction SOCP with fixed `W`, `mu` and cone structure.
pub(crate) struct ConicProgram {
    solver: DefaultSolver<f64>,
}

impl ConicProgram {
    /// Build the solver for `W` (symmetric positive semi-definite, `m x m` with `m = dim * mu.len()`,
    /// dimensions checked by the caller), initial linear term `linear` and friction
    /// coefficients `mu`.
    pub(crate) fn new(
        w: &DMatrix<f64>,
        linear: &[f64],
        dim: usize,
        mu: &[f64],
        tolerance: f64,
        max_iterations: u32,
    ) -> Result<Self, ContactError> {
        let m = w.nrows();
        let p = upper_triangle(w);
        let (a, cones) = cone_constraints(dim, mu);
        let settings = DefaultSettingsBuilder::default()
            .verbose(false)
            .presolve_enable(false)
            .tol_gap_abs(tolerance)
            .tol_gap_rel(tolerance)
            .tol_feas(tolerance)
            .max_iter(max_iterations)
            .build()
            .map_err(|e| ContactError::InvalidProblem(format!("clarabel settings: {e}")))?;
        let solver = DefaultSolver::new(&p, linear, &a, &vec![0.0; m], &cones, settings)
            .map_err(|e| ContactError::InvalidProblem(format!("clarabel setup: {e}")))?;
        Ok(Self { solver })
    }

    /// Replace the linear term `c` (same length as before).
    pub(crate) fn set_linear_term(&mut self, linear: &[f64]) -> Result<(), ContactError> {
        self.solver
            .update_q(&linear.to_vec())
            .map_err(|e| ContactError::InvalidProblem(format!("clarabel update: {e}")))
    }

    /// Solve and return the (scaled) contact forces. `Solved` and `AlmostSolved` both give an
    /// iterate (the caller accepts a result only through the natural-map check); any other status
    /// is [`ContactError::ConicSolveFailed`] tagged with `fixed_point_iteration`.
    pub(crate) fn solve(&mut self, fixed_point_iteration: usize) -> Result<Vec<f64>, ContactError> {
        self.solver.solve();
        match self.solver.solution.status {
            SolverStatus::Solved | SolverStatus::AlmostSolved => Ok(self.solver.solution.x.clone()),
            other => Err(ContactError::ConicSolveFailed {
                status: format!("{other:?}"),
                fixed_point_iteration,
            }),
        }
    }
}

/// Dense upper triangle of `w` in CSC form (explicit zeros kept, rows sorted in each column).
fn upper_triangle(w: &DMatrix<f64>) -> CscMatrix<f64> {
    let n = w.ncols();
    let mut colptr = Vec::with_capacity(n + 1);
    let mut rowval = Vec::with_capacity(n * (n + 1) / 2);
    let mut nzval = Vec::with_capacity(n * (n + 1) / 2);
    colptr.push(0);
    for j in 0..n {
        for i in 0..=j {
            rowval.push(i);
            nzval.push(w[(i, j)]);
        }
        colptr.push(rowval.len());
    }
    CscMatrix::new(n, n, colptr, rowval, nzval)
}

/// Diagonal constraint matrix `A` and the cone list, contact by contact.
fn cone_constraints(dim: usize, mu: &[f64]) -> (CscMatrix<f64>, Vec<SupportedConeT<f64>>) {
    let m = dim * mu.len();
    let mut diagonal = Vec::with_capacity(m);
    let mut cones = Vec::with_capacity(2 * mu.len());
    for &mu_i in mu {
        if mu_i > 0.0 {
            diagonal.push(-mu_i);
            cones.push(SupportedConeT::SecondOrderConeT(dim));
        } else {
            diagonal.push(-1.0);
            cones.push(SupportedConeT::NonnegativeConeT(1));
            cones.push(SupportedConeT::ZeroConeT(dim - 1));
        }
        diagonal.extend(std::iter::repeat_n(-1.0, dim - 1));
    }
    let a = CscMatrix::new(m, m, (0..=m).collect(), (0..m).collect(), diagonal);
    (a, cones)
}
