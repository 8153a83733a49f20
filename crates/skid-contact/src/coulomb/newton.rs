//! Semismooth Newton on the Alart–Curnier function of the exact Coulomb law in Delassus form.
//!
//! With `u = W r + q` and a force-per-length weight `rho_i` per contact (the inverse mean
//! compliance), the law holds exactly where `Phi(r) = 0`, contact by contact, with `Phi` the
//! local function of [`super::alart_curnier`]. `Phi` is piecewise smooth, so Newton with the
//! generalized Jacobian `dPhi/dr|_u + dPhi/du W` converges quadratically near a solution; the
//! step is damped by a backtracking (Armijo) line search on `||Phi||^2`.
//!
//! Open contacts take the step `dr = -r` outright, so only the closed ones enter the dense
//! linear solve.

use faer::Mat;
use faer::linalg::solvers::Solve;
use nalgebra::{DMatrix, DVector};

use super::alart_curnier::{LocalBranch, LocalLaw};
use super::polish::Candidate;
use super::{FrictionProblem, inverse_mean_compliance, natural_map};

/// Newton steps per call: from a good start a handful reach round-off; more mean the active
/// set keeps changing, and the caller falls back to the interior-point solve.
const MAX_STEPS: usize = 12;
/// Armijo parameter of the line search on `||Phi||^2`.
const ARMIJO: f64 = 1e-4;
/// Halvings of the step before the line search gives up.
const MAX_HALVINGS: usize = 30;

/// The Alart–Curnier function `Phi` at `(r, u)` and the local law of every contact.
fn evaluate(
    problem: &FrictionProblem,
    rho: &[f64],
    r: &DVector<f64>,
    u: &DVector<f64>,
) -> (DVector<f64>, Vec<LocalLaw>) {
    let dim = problem.dim;
    let mut phi = DVector::zeros(r.len());
    let laws = problem
        .mu
        .iter()
        .enumerate()
        .map(|(i, &mu)| {
            let range = dim * i..dim * (i + 1);
            let law = LocalLaw::evaluate(
                dim,
                mu,
                rho[i],
                &r.as_slice()[range.clone()],
                &u.as_slice()[range],
            );
            phi.rows_mut(dim * i, dim).copy_from_slice(&law.phi[..dim]);
            law
        })
        .collect();
    (phi, laws)
}

/// The generalized Jacobian `dPhi/dr = dPhi/dr|_u + dPhi/du W` of the closed contacts,
/// transposed (`m` rows, one column per closed-contact row of `Phi`, in contact order), with
/// the indices of those rows. `W` is symmetric, so its rows are read as (contiguous) columns.
fn closed_jacobian_transposed(
    problem: &FrictionProblem,
    w: &DMatrix<f64>,
    laws: &[LocalLaw],
) -> (DMatrix<f64>, Vec<usize>) {
    let dim = problem.dim;
    let closed = |law: &LocalLaw| law.branch != LocalBranch::Open;
    let rows: Vec<usize> = laws
        .iter()
        .enumerate()
        .filter(|(_, law)| closed(law))
        .flat_map(|(i, _)| dim * i..dim * (i + 1))
        .collect();
    let mut transposed = DMatrix::zeros(w.nrows(), rows.len());
    let mut a = 0;
    for (i, law) in laws.iter().enumerate().filter(|(_, law)| closed(law)) {
        let k = dim * i;
        // column a + t of the transpose is row k + t of the Jacobian
        for t in 0..dim {
            let mut target = transposed.column_mut(a + t);
            for s in 0..dim {
                if law.d_u[t][s] != 0.0 {
                    target.axpy(law.d_u[t][s], &w.column(k + s), 1.0);
                }
                target[k + s] += law.d_r[t][s];
            }
        }
        a += dim;
    }
    (transposed, rows)
}

/// Newton step `dr` with `J dr = -Phi`: `dr = -r` on open contacts, the dense solve on the closed
/// ones. `None` if the closed block is singular.
fn newton_step(
    problem: &FrictionProblem,
    w: &DMatrix<f64>,
    r: &DVector<f64>,
    phi: &DVector<f64>,
    laws: &[LocalLaw],
) -> Option<DVector<f64>> {
    let dim = problem.dim;
    let mut step = DVector::zeros(r.len());
    for (i, law) in laws.iter().enumerate() {
        if law.branch == LocalBranch::Open {
            step.rows_mut(dim * i, dim)
                .copy_from(&(-r.rows(dim * i, dim)));
        }
    }
    let (transposed, rows) = closed_jacobian_transposed(problem, w, laws);
    if rows.is_empty() {
        return Some(step);
    }
    let coupling = transposed.tr_mul(&step);
    let n = rows.len();
    // the closed block of J^T; J dr = rhs is solved as a transposed system
    let block = Mat::<f64>::from_fn(n, n, |a, b| transposed[(rows[a], b)]);
    let mut rhs = Mat::<f64>::from_fn(n, 1, |a, _| -phi[rows[a]] - coupling[a]);
    block
        .partial_piv_lu()
        .solve_transpose_in_place(rhs.as_mut());
    for (a, &row) in rows.iter().enumerate() {
        step[row] = rhs[(a, 0)];
    }
    step.iter().all(|v| v.is_finite()).then_some(step)
}

/// Semismooth Newton from the forces `start`, stopping once the natural-map error is at most
/// `tolerance`. Returns the iterate with the smallest natural-map error seen (`start` itself if
/// no step improved on it).
pub(crate) fn newton(
    problem: &FrictionProblem,
    w: &DMatrix<f64>,
    start: Candidate,
    tolerance: f64,
) -> (Candidate, usize) {
    let rho: Vec<f64> = (0..problem.mu.len())
        .map(|i| inverse_mean_compliance(problem, i))
        .collect();
    let (mut r, mut u) = (start.r.clone(), start.u.clone());
    let mut best = start;
    let (mut phi, mut branches) = evaluate(problem, &rho, &r, &u);
    let mut merit = phi.norm_squared();
    let mut steps = 0;
    while best.error > tolerance && steps < MAX_STEPS {
        let Some(dr) = newton_step(problem, w, &r, &phi, &branches) else {
            break;
        };
        steps += 1;
        let du = w * &dr;
        let mut length = 1.0;
        let accepted = loop {
            let trial_r = &r + &dr * length;
            let trial_u = &u + &du * length;
            let (trial_phi, trial_branches) = evaluate(problem, &rho, &trial_r, &trial_u);
            let trial_merit = trial_phi.norm_squared();
            if trial_merit <= (1.0 - 2.0 * ARMIJO * length) * merit {
                break Some((trial_r, trial_u, trial_phi, trial_branches, trial_merit));
            }
            length *= 0.5;
            if length < 0.5f64.powi(MAX_HALVINGS as i32) {
                break None;
            }
        };
        let Some((next_r, next_u, next_phi, next_branches, next_merit)) = accepted else {
            break;
        };
        (r, u, phi, branches, merit) = (next_r, next_u, next_phi, next_branches, next_merit);
        let error = natural_map(problem, &r, &u);
        if error < best.error {
            best = Candidate {
                r: r.clone(),
                u: u.clone(),
                error,
            };
        }
    }
    (best, steps)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Away from the branch switches the generalized Jacobian is the derivative of `Phi`:
    /// central differences on a problem with one contact on each branch (open, stick, slide,
    /// frictionless), built by choosing `r` and `u` and setting `q = u - W r`.
    fn jacobian_matches_finite_differences(dim: usize) {
        let n = 4;
        let m = dim * n;
        let b = DMatrix::from_fn(m, m, |i, j| ((i * 7 + j * 3) as f64 * 0.37).sin());
        let w = &b * b.transpose() / m as f64 + DMatrix::identity(m, m) * 0.5;
        let mu = [0.3, 0.3, 0.3, 0.0];
        let (r_blocks, u_blocks) = (
            [
                [0.1, 0.05, 0.02],
                [1.0, 0.1, 0.05],
                [1.0, 0.2, -0.3],
                [1.0, 0.1, 0.2],
            ],
            [
                [1.0, 0.3, 0.1],
                [0.0, 0.01, 0.0],
                [0.01, 1.5, 0.8],
                [0.05, 0.3, 0.1],
            ],
        );
        let r = DVector::from_fn(m, |k, _| r_blocks[k / dim][k % dim]);
        let u = DVector::from_fn(m, |k, _| u_blocks[k / dim][k % dim]);
        let q = &u - &w * &r;
        let problem = FrictionProblem {
            dim,
            w: &w,
            q: &q,
            mu: &mu,
        };
        let rho: Vec<f64> = (0..n)
            .map(|i| inverse_mean_compliance(&problem, i))
            .collect();
        let (_, branches) = evaluate(&problem, &rho, &r, &u);
        let kinds: Vec<LocalBranch> = branches.iter().map(|law| law.branch).collect();
        use LocalBranch::{Frictionless, Open, Slide, Stick};
        assert_eq!(kinds, [Open, Stick, Slide, Frictionless], "{dim}D");
        let (transposed, rows) = closed_jacobian_transposed(&problem, &w, &branches);
        let h = 1e-7;
        for j in 0..m {
            let phi_at = |sign: f64| {
                let mut r_shifted = r.clone();
                r_shifted[j] += sign * h;
                let u_shifted = &w * &r_shifted + &q;
                evaluate(&problem, &rho, &r_shifted, &u_shifted).0
            };
            let derivative = (phi_at(1.0) - phi_at(-1.0)) / (2.0 * h);
            for (a, &row) in rows.iter().enumerate() {
                assert!(
                    (derivative[row] - transposed[(j, a)]).abs() < 1e-6,
                    "{dim}D: dPhi_{row}/dr_{j} = {} by differences, {} analytic",
                    derivative[row],
                    transposed[(j, a)]
                );
            }
        }
    }

    #[test]
    fn jacobian_matches_finite_differences_2d() {
        jacobian_matches_finite_differences(2);
    }

    #[test]
    fn jacobian_matches_finite_differences_3d() {
        jacobian_matches_finite_differences(3);
    }
}
