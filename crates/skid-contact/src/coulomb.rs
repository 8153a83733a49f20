//! The exact Coulomb friction problem in Delassus form, solved as a sequence of second-order-cone
//! programs.
//!
//! Per contact `i` with `dim` components (`[N, T]` in 2D, `[N, T1, T2]` in 3D), the local
//! displacement-level "velocities" are `u = W r + q` (`u_N` is the gap at the end of the step,
//! `u_T` the slip increment over the step, both lengths) and `r` are the contact forces
//! (`r_N >= 0` compressive). The exact Coulomb law in De Saxcé's bipotential form is
//!
//! `K*_mu ∋ û ⊥ r ∈ K_mu`,  `û_i = u_i + mu_i ||u_T,i|| e_N`,  `K_mu = {||r_T|| <= mu r_N}`,
//!
//! i.e. open (`u_N >= 0`, `r = 0`), stick (`u = 0`, `||r_T|| <= mu r_N`) or slide (`u_N = 0`,
//! `r_T = -mu r_N u_T / ||u_T||`). It is solved by the fixed point of Acary, Cadoux, Lemaréchal
//! and Malick (ZAMM 2011) on the shift `s_i`: solve the convex SOCP
//! `min 1/2 r^T W r + (q + Σ s_i e_N,i)^T r  s.t. r_i ∈ K_mu_i`, whose optimality conditions are
//! `K*_mu ∋ W r + q + s ⊥ r ∈ K_mu`, then set `s_i <- mu_i ||u_T,i(r)||`. At a fixed point a sliding
//! contact has `u_N = 0`; the plain relaxation `s = 0` instead gives the spurious dilation
//! `u_N = mu ||u_T||`.
//!
//! Before any conic solve, a semismooth Newton method on the Alart–Curnier function (see
//! `newton`) is tried from the warm-start forces: from the forces of the previous Newton
//! iteration or time increment it typically converges in a few steps to round-off, at the cost
//! of a dense solve on the closed contacts. The conic fixed point is the fallback, and Newton
//! also refines each of its iterates.

pub mod alart_curnier;
mod cone;
mod conic_program;
mod newton;
mod polish;
#[cfg(test)]
mod tests;
mod validation;

use std::borrow::Cow;

use nalgebra::{DMatrix, DVector};

use crate::error::ContactError;
use cone::{project_onto_friction_cone, tangential_norm};
use conic_program::ConicProgram;
use newton::newton;
use polish::{Candidate, polish};
use validation::{
    check_forces, check_problem, check_settings, check_shape, check_shift, exactly_symmetric,
};

/// Tolerances and iteration limits of [`solve_coulomb`].
#[derive(Clone, Debug)]
pub struct CoulombSettings {
    /// Bound on the relative natural-map error (see [`natural_map_error`]) of the returned
    /// solution. Default `1e-8`. The error is relative to the norm of all contact forces, so a
    /// looser bound lets a single stiff contact penetrate visibly (`1e-6` left 3 µm on the
    /// refined 3D pad's preload); the semismooth Newton refinement converges quadratically past
    /// the interior-point accuracy floor (around `1e-7` on larger 3D problems), so `1e-8` costs
    /// at most a step more.
    pub tolerance: f64,
    /// Maximum number of fixed-point iterations (one conic solve each). Default 50.
    pub max_fixed_point_iterations: usize,
    /// Clarabel's absolute/relative duality-gap and feasibility tolerances on the scaled problem.
    /// Default `1e-10`.
    pub conic_tolerance: f64,
    /// Clarabel's interior-point iteration limit. Default 100.
    pub conic_max_iterations: u32,
    /// Which algorithm leads. Default [`CoulombMethod::NewtonFirst`].
    pub method: CoulombMethod,
}

/// How [`solve_coulomb`] reaches the exact Coulomb law.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CoulombMethod {
    /// Semismooth Newton from the warm start; the conic fixed point only where it fails.
    #[default]
    NewtonFirst,
    /// The conic (clarabel) fixed point from the start: clarabel decides the active set every
    /// time, each iterate refined as described in [`solve_coulomb`]. Slower; an independent
    /// check of the Newton path.
    Conic,
}

impl Default for CoulombSettings {
    fn default() -> Self {
        Self {
            tolerance: 1e-8,
            max_fixed_point_iterations: 50,
            conic_tolerance: 1e-10,
            conic_max_iterations: 100,
            method: CoulombMethod::NewtonFirst,
        }
    }
}

/// A discrete Coulomb friction problem `K*_mu ∋ û ⊥ r ∈ K_mu`, `u = W r + q`.
#[derive(Clone, Copy, Debug)]
pub struct FrictionProblem<'a> {
    /// Components per contact: 2 (`[N, T]`) or 3 (`[N, T1, T2]`).
    pub dim: usize,
    /// Delassus operator `W` (`m x m`, `m = dim * n_contacts`): symmetric positive semi-definite
    /// with a positive diagonal. Round-off asymmetry up to `1e-6 max |W|` is accepted and the
    /// symmetric part is used.
    pub w: &'a DMatrix<f64>,
    /// Free local displacements `q` (length `m`): `u` for `r = 0`.
    pub q: &'a DVector<f64>,
    /// Friction coefficient `mu_i >= 0` of each contact (`mu_i = 0`: frictionless).
    pub mu: &'a [f64],
}

/// Solution of the exact Coulomb problem.
#[derive(Clone, Debug)]
pub struct CoulombSolution {
    /// Contact forces `r` (per contact `[r_N, r_T..]`, `r_N >= 0` compressive).
    pub r: DVector<f64>,
    /// Local displacements `u = W r + q` (with the symmetric part of `W`).
    pub u: DVector<f64>,
    /// Shift `s_i = mu_i ||u_T,i||` of the returned solution; a warm start for the next call.
    pub shift: Vec<f64>,
    /// Fixed-point iterations performed (0 when `r = 0` is recognised without a conic solve).
    pub fixed_point_iterations: usize,
    /// Conic (clarabel) solves performed.
    pub conic_solves: usize,
    /// Semismooth Newton steps performed (each one dense solve on the closed contacts).
    pub newton_steps: usize,
    /// Natural-map error of `(r, u)`, see [`natural_map_error`].
    pub natural_map_error: f64,
}

/// Solve the exact Coulomb problem: semismooth Newton from `initial_forces`, then, if that does
/// not reach `settings.tolerance`, the fixed point on the De Saxcé shift
/// ([`CoulombMethod::NewtonFirst`]); or the fixed point alone ([`CoulombMethod::Conic`]).
///
/// `initial_forces` (length `m`, finite, e.g. the forces `r` of the previous solve) start the
/// Newton iteration; without them it starts from `r = 0`. The fixed point starts from the shift
/// `s_i = mu_i ||u_T,i||` of the best Newton iterate.
///
/// If every `q_N,i >= 0`, then `r = 0`, `u = q` solves the law exactly and is returned without a
/// conic solve (this includes the empty problem). Otherwise the SOCP is scaled so that clarabel
/// sees O(1) data (lengths by `L0 = max |q|`, forces by `F0 = L0 / mean(diag W)`) and one clarabel
/// solver is built and reused through `update_q`. Each fixed-point iteration solves the SOCP,
/// polishes the iterate by solving the exact law on the active set read off the natural map
/// (kept only if it lowers the natural-map error; it removes the interior-point accuracy floor
/// at nearly degenerate contacts and makes `u_N = 0` at sliding contacts exact to round-off)
/// and by Newton from the polished iterate, and stops once the natural-map error is below
/// `settings.tolerance`. Otherwise the shift is
/// updated to `s_i = mu_i ||u_T,i||` of the (polished) iterate. At a returned solution the shift
/// is consistent to the same tolerance, since `û` in the natural map uses the true slip.
///
/// Clarabel's `Solved` and `AlmostSolved` are both taken as iterates, but a solution is only ever
/// returned once its natural-map error passes the tolerance.
///
/// # Errors
/// [`ContactError::InvalidProblem`] for malformed input or settings;
/// [`ContactError::ConicSolveFailed`] when clarabel stops with another status;
/// [`ContactError::FixedPointNotConverged`] when the iteration limit is reached above tolerance.
/// The last two call for a time-step cutback.
pub fn solve_coulomb(
    problem: &FrictionProblem,
    settings: &CoulombSettings,
    initial_forces: Option<&DVector<f64>>,
) -> Result<CoulombSolution, ContactError> {
    check_settings(settings)?;
    let symmetric = check_problem(problem)?;
    if let Some(forces) = initial_forces {
        check_forces(forces, problem.q.len())?;
    }
    let dim = problem.dim;
    if settings.method == CoulombMethod::Conic
        || problem.q.iter().step_by(dim).all(|&q_n| q_n >= 0.0)
    {
        return solve_fixed_point(problem, settings, None, true);
    }
    let w = symmetric_part(problem.w, symmetric);
    let start = initial_forces.map_or_else(|| DVector::zeros(problem.q.len()), Clone::clone);
    let (candidate, newton_steps) = newton(
        problem,
        &w,
        Candidate::new(problem, &w, start),
        settings.tolerance,
    );
    let shift = slip_shift(dim, problem.mu, &candidate.u);
    if candidate.error <= settings.tolerance {
        return Ok(CoulombSolution {
            r: candidate.r,
            u: candidate.u,
            shift,
            fixed_point_iterations: 0,
            conic_solves: 0,
            newton_steps,
            natural_map_error: candidate.error,
        });
    }
    let mut solution = solve_fixed_point(problem, settings, Some(&shift), true)?;
    solution.newton_steps += newton_steps;
    Ok(solution)
}

/// The fixed point of [`solve_coulomb`] from the shift `initial_shift` (length `n_contacts`,
/// entries `>= 0`; without it `s_i = mu_i ||q_T,i||`, the slip if nothing pushed), with the
/// refinement (polish and Newton) of each iterate switched by `refining`. `W`'s entries are
/// those [`solve_coulomb`] checked: only the rest is checked again here.
fn solve_fixed_point(
    problem: &FrictionProblem,
    settings: &CoulombSettings,
    initial_shift: Option<&[f64]>,
    refining: bool,
) -> Result<CoulombSolution, ContactError> {
    check_settings(settings)?;
    let n_contacts = check_shape(problem)?;
    if let Some(shift) = initial_shift {
        check_shift(shift, n_contacts)?;
    }
    let dim = problem.dim;
    let q = problem.q;
    if (0..n_contacts).all(|i| q[dim * i] >= 0.0) {
        let r = DVector::zeros(q.len());
        let u = q.clone();
        return Ok(CoulombSolution {
            natural_map_error: natural_map(problem, &r, &u),
            shift: slip_shift(dim, problem.mu, &u),
            r,
            u,
            fixed_point_iterations: 0,
            conic_solves: 0,
            newton_steps: 0,
        });
    }

    let w = symmetric_part(problem.w, exactly_symmetric(problem.w));
    // positive: some q_N < 0, and the diagonal of W was checked positive
    let length_scale = q.amax();
    let compliance_scale = w.diagonal().mean();
    let force_scale = length_scale / compliance_scale;
    let scaled_linear_term = |shift: &[f64]| -> Vec<f64> {
        let mut linear: Vec<f64> = q.iter().map(|v| v / length_scale).collect();
        for (i, s) in shift.iter().enumerate() {
            linear[dim * i] += s / length_scale;
        }
        linear
    };

    let mut shift = match initial_shift {
        Some(shift) => shift.to_vec(),
        None => slip_shift(dim, problem.mu, q),
    };
    let mut program = ConicProgram::new(
        &(&*w / compliance_scale),
        &scaled_linear_term(&shift),
        dim,
        problem.mu,
        settings.conic_tolerance,
        settings.conic_max_iterations,
    )?;
    let mut error = f64::INFINITY;
    let mut newton_steps = 0;
    for iteration in 1..=settings.max_fixed_point_iterations {
        if iteration > 1 {
            program.set_linear_term(&scaled_linear_term(&shift))?;
        }
        let r = DVector::from_vec(program.solve(iteration)?) * force_scale;
        let mut candidate = Candidate::new(problem, &w, r);
        if refining {
            if let Some(polished) = polish(problem, &w, &candidate, settings.tolerance) {
                candidate = polished;
            }
            if candidate.error > settings.tolerance {
                let steps;
                (candidate, steps) = newton(problem, &w, candidate, settings.tolerance);
                newton_steps += steps;
            }
        }
        error = candidate.error;
        shift = slip_shift(dim, problem.mu, &candidate.u);
        if error <= settings.tolerance {
            return Ok(CoulombSolution {
                r: candidate.r,
                u: candidate.u,
                shift,
                fixed_point_iterations: iteration,
                conic_solves: iteration,
                newton_steps,
                natural_map_error: error,
            });
        }
    }
    Err(ContactError::FixedPointNotConverged {
        iterations: settings.max_fixed_point_iterations,
        error,
    })
}

/// Natural-map error of a candidate `(r, u)`:
///
/// `e = ||r - proj_K(r - rho ∘ û)|| / max(||r||, ||rho ∘ q||)`, `û_i = u_i + mu_i ||u_T,i|| e_N`,
///
/// with `proj_K` the projection onto `K_mu_1 × K_mu_2 × …` and `rho_i = 1 / mean(diag W_ii)` the
/// inverse mean compliance of contact `i`, so that `rho ∘ û` is a force. `e = 0` exactly when
/// `(r, u)` satisfies the Coulomb law; it is relative to the force scale `max(||r||, ||rho ∘ q||)`
/// (the second term is the force that would cancel `q` on decoupled contacts), and absolute if
/// both vanish. Only the diagonal of `W` is read. Returns `f64::INFINITY` for a problem with
/// invalid sizes, friction coefficients, `q` or diagonal of `W` (as [`solve_coulomb`] checks
/// them), or `r`, `u` of the wrong length or with non-finite entries.
pub fn natural_map_error(problem: &FrictionProblem, r: &DVector<f64>, u: &DVector<f64>) -> f64 {
    let valid = check_shape(problem).is_ok()
        && r.len() == problem.q.len()
        && u.len() == problem.q.len()
        && r.iter().chain(u.iter()).all(|v| v.is_finite());
    if valid {
        natural_map(problem, r, u)
    } else {
        f64::INFINITY
    }
}

/// [`natural_map_error`] for already validated data.
fn natural_map(problem: &FrictionProblem, r: &DVector<f64>, u: &DVector<f64>) -> f64 {
    let dim = problem.dim;
    let mut residual_squared = 0.0;
    let mut reference_squared: f64 = 0.0;
    for i in 0..problem.mu.len() {
        let (phi, rho) = contact_natural_map(problem, i, r, u);
        residual_squared += phi[..dim].iter().map(|p| p * p).sum::<f64>();
        reference_squared += problem.q.as_slice()[dim * i..dim * (i + 1)]
            .iter()
            .map(|v| (rho * v) * (rho * v))
            .sum::<f64>();
    }
    let reference = r.norm().max(reference_squared.sqrt());
    if reference > 0.0 {
        residual_squared.sqrt() / reference
    } else {
        residual_squared.sqrt()
    }
}

/// The natural map of contact `i` and its weight: `(phi_i, rho_i)` with
/// `phi_i = r_i - proj_K(r_i - rho_i û_i)` (first `dim` entries) and `rho_i` as in
/// [`natural_map_error`].
fn contact_natural_map(
    problem: &FrictionProblem,
    i: usize,
    r: &DVector<f64>,
    u: &DVector<f64>,
) -> ([f64; 3], f64) {
    let dim = problem.dim;
    let mu = problem.mu[i];
    let range = dim * i..dim * (i + 1);
    let rho = inverse_mean_compliance(problem, i);
    let r_i = &r.as_slice()[range.clone()];
    let u_i = &u.as_slice()[range];
    let shift = mu * tangential_norm(u_i);
    let mut trial = [0.0; 3];
    for (k, t) in trial[..dim].iter_mut().enumerate() {
        let u_hat = if k == 0 { u_i[0] + shift } else { u_i[k] };
        *t = r_i[k] - rho * u_hat;
    }
    let mut projected = [0.0; 3];
    project_onto_friction_cone(mu, &trial[..dim], &mut projected[..dim]);
    let mut phi = [0.0; 3];
    for k in 0..dim {
        phi[k] = r_i[k] - projected[k];
    }
    (phi, rho)
}

/// Length error of a candidate `(r, u)`: `max_i ||phi_i||_inf / rho_i`, with the natural map
/// `phi_i` and weight `rho_i` of [`natural_map_error`].
///
/// Where the law holds with the contact closed, `phi_i / rho_i` is the penetration or the slip
/// of a sticking contact (m); on an open contact it is the force carried, converted to a length
/// by the compliance. Unlike the relative error it does not shrink with `rho`: when `W` holds a
/// compliance far above the others (a body held only by its contacts, regularised by a small
/// mass shift), every `rho_i` is small and a relative error of `1e-8` can leave micrometres of
/// penetration, which this measure shows. Returns `f64::INFINITY` where
/// [`natural_map_error`] does.
pub fn natural_map_length_error(
    problem: &FrictionProblem,
    r: &DVector<f64>,
    u: &DVector<f64>,
) -> f64 {
    let valid = check_shape(problem).is_ok()
        && r.len() == problem.q.len()
        && u.len() == problem.q.len()
        && r.iter().chain(u.iter()).all(|v| v.is_finite());
    if !valid {
        return f64::INFINITY;
    }
    (0..problem.mu.len())
        .map(|i| {
            let (phi, rho) = contact_natural_map(problem, i, r, u);
            phi[..problem.dim]
                .iter()
                .fold(0.0_f64, |a, p| a.max(p.abs()))
                / rho
        })
        .fold(0.0, f64::max)
}

/// `rho_i = 1 / mean(diag W_ii)`: the inverse mean compliance of contact `i`.
fn inverse_mean_compliance(problem: &FrictionProblem, i: usize) -> f64 {
    let dim = problem.dim;
    dim as f64
        / (dim * i..dim * (i + 1))
            .map(|k| problem.w[(k, k)])
            .sum::<f64>()
}

/// The symmetric part `(W + W^T) / 2`: `W` itself, borrowed, where it already equals its
/// transpose (`symmetric`, as [`exactly_symmetric`] finds for the Delassus operators of the
/// integrator), a symmetrised copy otherwise.
fn symmetric_part(w: &DMatrix<f64>, symmetric: bool) -> Cow<'_, DMatrix<f64>> {
    if symmetric {
        return Cow::Borrowed(w);
    }
    let mut symmetrised = w.clone();
    for j in 0..w.ncols() {
        for i in j + 1..w.nrows() {
            let mean = 0.5 * (w[(i, j)] + w[(j, i)]);
            symmetrised[(i, j)] = mean;
            symmetrised[(j, i)] = mean;
        }
    }
    Cow::Owned(symmetrised)
}

/// Shift `s_i = mu_i ||u_T,i||` of each contact.
fn slip_shift(dim: usize, mu: &[f64], u: &DVector<f64>) -> Vec<f64> {
    mu.iter()
        .zip(u.as_slice().chunks_exact(dim))
        .map(|(mu, block)| mu * tangential_norm(block))
        .collect()
}
