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

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::{factor, solve};
use faer::{Conj, MatMut, MatRef, Par};
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

/// The Alart–Curnier function `Phi` at `(r, u)` and the local law of every contact, written
/// into `phi` (length `m`) and `laws` (refilled).
fn evaluate(
    problem: &FrictionProblem,
    rho: &[f64],
    r: &DVector<f64>,
    u: &DVector<f64>,
    phi: &mut DVector<f64>,
    laws: &mut Vec<LocalLaw>,
) {
    let dim = problem.dim;
    laws.clear();
    for (i, &mu) in problem.mu.iter().enumerate() {
        let range = dim * i..dim * (i + 1);
        let law = LocalLaw::evaluate(
            dim,
            mu,
            rho[i],
            &r.as_slice()[range.clone()],
            &u.as_slice()[range.clone()],
        );
        phi.as_mut_slice()[range].copy_from_slice(&law.phi[..dim]);
        laws.push(law);
    }
}

/// The generalized Jacobian `dPhi/dr = dPhi/dr|_u + dPhi/du W` of the closed contacts,
/// transposed (`m` rows, one column per closed-contact row of `Phi`, in contact order), written
/// into `transposed`, with the indices of those rows in `rows`. `W` is symmetric, so its rows
/// are read as (contiguous) columns.
fn closed_jacobian_transposed(
    problem: &FrictionProblem,
    w: &DMatrix<f64>,
    laws: &[LocalLaw],
    transposed: &mut DMatrix<f64>,
    rows: &mut Vec<usize>,
) {
    let dim = problem.dim;
    let closed = |law: &LocalLaw| law.branch != LocalBranch::Open;
    rows.clear();
    rows.extend(
        laws.iter()
            .enumerate()
            .filter(|(_, law)| closed(law))
            .flat_map(|(i, _)| dim * i..dim * (i + 1)),
    );
    transposed.resize_mut(w.nrows(), rows.len(), 0.0);
    transposed.fill(0.0);
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
}

/// The buffers of one [`newton`] call, which its steps and line-search trials reuse.
struct Buffers {
    /// The transposed Jacobian of the closed contacts (see [`closed_jacobian_transposed`]).
    transposed: DMatrix<f64>,
    /// The closed rows of `Phi`.
    rows: Vec<usize>,
    /// The closed block of `J^T` (column-major), overwritten by its LU factors.
    block: Vec<f64>,
    /// The right-hand side, overwritten by the solution.
    rhs: Vec<f64>,
    /// The row permutation of the LU factorization and its inverse.
    permutation: (Vec<usize>, Vec<usize>),
    /// faer's workspace for the factorization and the solve of size up to `m`.
    scratch: MemBuffer,
}

impl Buffers {
    /// Buffers for problems of `m` unknowns.
    fn new(m: usize) -> Self {
        let par = Par::Seq;
        Self {
            transposed: DMatrix::zeros(m, m),
            rows: Vec::with_capacity(m),
            block: Vec::with_capacity(m * m),
            rhs: Vec::with_capacity(m),
            permutation: (vec![0; m], vec![0; m]),
            scratch: MemBuffer::new(StackReq::any_of(&[
                factor::lu_in_place_scratch::<usize, f64>(m, m, par, Default::default()),
                solve::solve_transpose_in_place_scratch::<usize, f64>(m, 1, par),
            ])),
        }
    }
}

/// Newton step `dr` with `J dr = -Phi`, written into `step`: `dr = -r` on open contacts, the
/// dense solve (LU with partial pivoting) on the closed ones. False if the closed block is
/// singular.
fn newton_step(
    problem: &FrictionProblem,
    w: &DMatrix<f64>,
    r: &DVector<f64>,
    phi: &DVector<f64>,
    laws: &[LocalLaw],
    step: &mut DVector<f64>,
    buffers: &mut Buffers,
) -> bool {
    let dim = problem.dim;
    step.fill(0.0);
    for (i, law) in laws.iter().enumerate() {
        if law.branch == LocalBranch::Open {
            for k in dim * i..dim * (i + 1) {
                step[k] = -r[k];
            }
        }
    }
    let Buffers {
        transposed,
        rows,
        block,
        rhs,
        permutation: (forward, inverse),
        scratch,
    } = buffers;
    closed_jacobian_transposed(problem, w, laws, transposed, rows);
    if rows.is_empty() {
        return true;
    }
    let coupling = transposed.tr_mul(step);
    let n = rows.len();
    // the closed block of J^T; J dr = rhs is solved as a transposed system
    block.clear();
    for column in transposed.as_slice().chunks_exact(transposed.nrows()) {
        block.extend(rows.iter().map(|&row| column[row]));
    }
    rhs.clear();
    rhs.extend(
        rows.iter()
            .zip(coupling.as_slice())
            .map(|(&row, c)| -phi[row] - c),
    );
    let par = Par::Seq;
    let stack = MemStack::new(scratch);
    let lu = MatMut::from_column_major_slice_mut(block.as_mut_slice(), n, n);
    let (_, permutation) = factor::lu_in_place(
        lu,
        &mut forward[..n],
        &mut inverse[..n],
        par,
        stack,
        Default::default(),
    );
    // the factors share the block: L strictly below the diagonal (unit diagonal), U on and
    // above it, and each triangular solve reads only its own triangle
    let lu = MatRef::from_column_major_slice(block.as_slice(), n, n);
    solve::solve_transpose_in_place_with_conj(
        lu,
        lu,
        permutation,
        Conj::No,
        MatMut::from_column_major_slice_mut(rhs.as_mut_slice(), n, 1),
        par,
        stack,
    );
    for (&row, &value) in rows.iter().zip(rhs.iter()) {
        step[row] = value;
    }
    step.iter().all(|v| v.is_finite())
}

/// `out = a + length b`, elementwise.
fn along(out: &mut DVector<f64>, a: &DVector<f64>, b: &DVector<f64>, length: f64) {
    let (a, b) = (a.as_slice(), b.as_slice());
    for ((o, a), b) in out.as_mut_slice().iter_mut().zip(a).zip(b) {
        *o = a + b * length;
    }
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
    let m = start.r.len();
    let mut buffers = Buffers::new(m);
    let (mut r, mut u) = (start.r.clone(), start.u.clone());
    let mut best = start;
    let (mut phi, mut laws) = (DVector::zeros(m), Vec::with_capacity(problem.mu.len()));
    evaluate(problem, &rho, &r, &u, &mut phi, &mut laws);
    let mut merit = phi.norm_squared();
    let (mut dr, mut du) = (DVector::zeros(m), DVector::zeros(m));
    let (mut trial_r, mut trial_u, mut trial_phi) =
        (DVector::zeros(m), DVector::zeros(m), DVector::zeros(m));
    let mut trial_laws = Vec::with_capacity(problem.mu.len());
    let mut steps = 0;
    while best.error > tolerance && steps < MAX_STEPS {
        if !newton_step(problem, w, &r, &phi, &laws, &mut dr, &mut buffers) {
            break;
        }
        steps += 1;
        du.gemv(1.0, w, &dr, 0.0);
        let mut length = 1.0;
        let accepted = loop {
            along(&mut trial_r, &r, &dr, length);
            along(&mut trial_u, &u, &du, length);
            evaluate(
                problem,
                &rho,
                &trial_r,
                &trial_u,
                &mut trial_phi,
                &mut trial_laws,
            );
            let trial_merit = trial_phi.norm_squared();
            if trial_merit <= (1.0 - 2.0 * ARMIJO * length) * merit {
                break Some(trial_merit);
            }
            length *= 0.5;
            if length < 0.5f64.powi(MAX_HALVINGS as i32) {
                break None;
            }
        };
        let Some(next_merit) = accepted else {
            break;
        };
        std::mem::swap(&mut r, &mut trial_r);
        std::mem::swap(&mut u, &mut trial_u);
        std::mem::swap(&mut phi, &mut trial_phi);
        std::mem::swap(&mut laws, &mut trial_laws);
        merit = next_merit;
        let error = natural_map(problem, &r, &u);
        if error < best.error {
            best.r.copy_from(&r);
            best.u.copy_from(&u);
            best.error = error;
        }
    }
    (best, steps)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Four contacts, one on each branch (open, stick, slide, frictionless), built by choosing
    /// `r` and `u` and setting `q = u - W r`, with `W = B B^T / m + I / 2` and `B_ij = b(i, j)`.
    struct OneContactPerBranch {
        w: DMatrix<f64>,
        q: DVector<f64>,
        r: DVector<f64>,
        u: DVector<f64>,
        mu: [f64; 4],
    }

    fn one_contact_per_branch(dim: usize, b: impl Fn(usize, usize) -> f64) -> OneContactPerBranch {
        let m = dim * 4;
        let b = DMatrix::from_fn(m, m, b);
        let w = &b * b.transpose() / m as f64 + DMatrix::identity(m, m) * 0.5;
        let blocks = [
            ([0.1, 0.05, 0.02], [1.0, 0.3, 0.1]),
            ([1.0, 0.1, 0.05], [0.0, 0.01, 0.0]),
            ([1.0, 0.2, -0.3], [0.01, 1.5, 0.8]),
            ([1.0, 0.1, 0.2], [0.05, 0.3, 0.1]),
        ];
        let r = DVector::from_fn(m, |k, _| blocks[k / dim].0[k % dim]);
        let u = DVector::from_fn(m, |k, _| blocks[k / dim].1[k % dim]);
        let q = &u - &w * &r;
        OneContactPerBranch {
            w,
            q,
            r,
            u,
            mu: [0.3, 0.3, 0.3, 0.0],
        }
    }

    /// Away from the branch switches the generalized Jacobian is the derivative of `Phi`:
    /// central differences on [`one_contact_per_branch`].
    fn jacobian_matches_finite_differences(dim: usize) {
        let n = 4;
        let m = dim * n;
        let OneContactPerBranch { w, q, r, u, mu } =
            one_contact_per_branch(dim, |i, j| ((i * 7 + j * 3) as f64 * 0.37).sin());
        let problem = FrictionProblem {
            dim,
            w: &w,
            q: &q,
            mu: &mu,
        };
        let rho: Vec<f64> = (0..n)
            .map(|i| inverse_mean_compliance(&problem, i))
            .collect();
        let (mut phi, mut branches) = (DVector::zeros(m), Vec::new());
        evaluate(&problem, &rho, &r, &u, &mut phi, &mut branches);
        let kinds: Vec<LocalBranch> = branches.iter().map(|law| law.branch).collect();
        use LocalBranch::{Frictionless, Open, Slide, Stick};
        assert_eq!(kinds, [Open, Stick, Slide, Frictionless], "{dim}D");
        let (mut transposed, mut rows) = (DMatrix::zeros(0, 0), Vec::new());
        closed_jacobian_transposed(&problem, &w, &branches, &mut transposed, &mut rows);
        let h = 1e-7;
        for j in 0..m {
            let phi_at = |sign: f64| {
                let mut r_shifted = r.clone();
                r_shifted[j] += sign * h;
                let u_shifted = &w * &r_shifted + &q;
                let (mut phi, mut laws) = (DVector::zeros(m), Vec::new());
                evaluate(&problem, &rho, &r_shifted, &u_shifted, &mut phi, &mut laws);
                phi
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

    /// The Newton step solves `J dr = -Phi`: `dr = -r` on the open contact and the closed rows
    /// of `J dr` equal `-Phi` there (one contact on each branch, buffers reused from a larger
    /// problem's size).
    fn newton_step_solves_the_linearisation(dim: usize) {
        let n = 4;
        let m = dim * n;
        let OneContactPerBranch { w, q, r, u, mu } =
            one_contact_per_branch(dim, |i, j| ((i * 5 + j * 2) as f64 * 0.41).cos());
        let problem = FrictionProblem {
            dim,
            w: &w,
            q: &q,
            mu: &mu,
        };
        let rho: Vec<f64> = (0..n)
            .map(|i| inverse_mean_compliance(&problem, i))
            .collect();
        let (mut phi, mut laws) = (DVector::zeros(m), Vec::new());
        evaluate(&problem, &rho, &r, &u, &mut phi, &mut laws);
        let mut buffers = Buffers::new(m + 3);
        let mut step = DVector::zeros(m);
        assert!(newton_step(
            &problem,
            &w,
            &r,
            &phi,
            &laws,
            &mut step,
            &mut buffers
        ));
        let (mut transposed, mut rows) = (DMatrix::zeros(0, 0), Vec::new());
        closed_jacobian_transposed(&problem, &w, &laws, &mut transposed, &mut rows);
        assert_eq!(rows.len(), m - dim, "{dim}D: one open contact");
        for k in 0..dim {
            assert_eq!(step[k], -r[k]);
        }
        let product = transposed.tr_mul(&step);
        for (a, &row) in rows.iter().enumerate() {
            assert!(
                (product[a] + phi[row]).abs() < 1e-12 * phi.amax(),
                "{dim}D: row {row}: {} vs {}",
                product[a],
                -phi[row]
            );
        }
    }

    #[test]
    fn newton_step_solves_the_linearisation_2d() {
        newton_step_solves_the_linearisation(2);
    }

    #[test]
    fn newton_step_solves_the_linearisation_3d() {
        newton_step_solves_the_linearisation(3);
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
