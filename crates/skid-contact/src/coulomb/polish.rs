//! Active-set polishing of an interior-point iterate.
//!
//! An interior-point solution is accurate only to about the fourth root of its tolerance at
//! nearly degenerate contacts (`r ≈ 0` and `u ≈ 0` together), which leaves a floor in the
//! natural-map error. Polishing reads the contact states off the natural map of the exact law at
//! the iterate, `v_i = r_i - rho_i û_i` (inside `K_mu`: stick; inside the polar cone: open;
//! otherwise: slide along `d_i = -v_T,i / ||v_T,i||`), and solves the exact law for that active set,
//! which is linear:
//!
//! * open: `r_i = 0`;
//! * stick: `u_i = (W r + q)_i = 0` (frictionless contacts are never stuck);
//! * slide: `u_N,i = 0` with `r_T,i = -mu_i r_N,i d_i`.
//!
//! In 3D the slip direction is refreshed and the solve repeated a few times.

use nalgebra::{DMatrix, DVector};

use super::cone::tangential_norm;
use super::{FrictionProblem, inverse_mean_compliance, natural_map};

/// Maximum number of active-set solves (the 3D slip directions are refreshed between them; the
/// refresh converges linearly, and the 3D drum preload, with nodes sliding outward in two
/// directions, needs more than a handful of rounds to get below 1e-8).
const POLISH_ROUNDS: usize = 25;

/// State of one contact in the active set.
enum ActiveState {
    Open,
    Stick,
    /// Sliding along the unit tangential direction (components `T1[, T2]`).
    Slide([f64; 2]),
}

/// A candidate solution with its natural-map error.
pub(crate) struct Candidate {
    pub(crate) r: DVector<f64>,
    pub(crate) u: DVector<f64>,
    pub(crate) error: f64,
}

impl Candidate {
    /// Candidate for forces `r`: `u = W r + q` (with the symmetric `w`) and its error.
    pub(crate) fn new(problem: &FrictionProblem, w: &DMatrix<f64>, r: DVector<f64>) -> Self {
        let u = w * &r + problem.q;
        let error = natural_map(problem, &r, &u);
        Self { r, u, error }
    }
}

/// Polish `start`: return the best candidate found by active-set solves if it improves on
/// `start`'s error, stopping early once the error is below `tolerance`.
pub(crate) fn polish(
    problem: &FrictionProblem,
    w: &DMatrix<f64>,
    start: &Candidate,
    tolerance: f64,
) -> Option<Candidate> {
    let mut best: Option<Candidate> = None;
    for _ in 0..POLISH_ROUNDS {
        let current = best.as_ref().unwrap_or(start);
        let states = active_states(problem, current);
        let polished = solve_active_set(problem, w, &states)?;
        if polished.error >= best.as_ref().unwrap_or(start).error {
            break;
        }
        let done = polished.error <= tolerance;
        best = Some(polished);
        if done {
            break;
        }
    }
    best
}

/// Contact states read off `v_i = r_i - rho_i û_i` at a candidate.
fn active_states(problem: &FrictionProblem, candidate: &Candidate) -> Vec<ActiveState> {
    let dim = problem.dim;
    problem
        .mu
        .iter()
        .enumerate()
        .map(|(i, &mu)| {
            let r = &candidate.r.as_slice()[dim * i..dim * (i + 1)];
            let u = &candidate.u.as_slice()[dim * i..dim * (i + 1)];
            let rho = inverse_mean_compliance(problem, i);
            let v_n = r[0] - rho * (u[0] + mu * tangential_norm(u));
            let mut v_t = [0.0; 2];
            for k in 1..dim {
                v_t[k - 1] = r[k] - rho * u[k];
            }
            let t = v_t.iter().map(|c| c * c).sum::<f64>().sqrt();
            if mu * t <= -v_n {
                ActiveState::Open
            } else if mu > 0.0 && t <= mu * v_n {
                ActiveState::Stick
            } else if t > 0.0 {
                ActiveState::Slide(v_t.map(|c| -c / t))
            } else {
                // frictionless with v_T = 0: any direction, the friction force is zero
                ActiveState::Slide([0.0; 2])
            }
        })
        .collect()
}

/// Solve `S (W E z + q) = 0` for the reduced unknowns `z`, with `r = E z` (stick: all
/// components; slide: `r_N` with `r_T = -mu r_N d`) and `S` selecting the active equations
/// (stick: all of `u_i`; slide: `u_N,i`). `None` if the reduced matrix is singular.
fn solve_active_set(
    problem: &FrictionProblem,
    w: &DMatrix<f64>,
    states: &[ActiveState],
) -> Option<Candidate> {
    let dim = problem.dim;
    let m = w.nrows();
    let mut columns: Vec<DVector<f64>> = Vec::new();
    let mut rows: Vec<usize> = Vec::new();
    for (i, state) in states.iter().enumerate() {
        match state {
            ActiveState::Open => {}
            ActiveState::Stick => {
                for k in 0..dim {
                    let mut column = DVector::zeros(m);
                    column[dim * i + k] = 1.0;
                    columns.push(column);
                    rows.push(dim * i + k);
                }
            }
            ActiveState::Slide(direction) => {
                let mut column = DVector::zeros(m);
                column[dim * i] = 1.0;
                for k in 1..dim {
                    column[dim * i + k] = -problem.mu[i] * direction[k - 1];
                }
                columns.push(column);
                rows.push(dim * i);
            }
        }
    }
    let r = if columns.is_empty() {
        DVector::zeros(m)
    } else {
        let expansion = DMatrix::from_columns(&columns);
        let w_expanded = w * &expansion;
        let reduced = DMatrix::from_fn(rows.len(), rows.len(), |a, b| w_expanded[(rows[a], b)]);
        let rhs = DVector::from_fn(rows.len(), |a, _| -problem.q[rows[a]]);
        let z = reduced.lu().solve(&rhs)?;
        expansion * z
    };
    r.iter()
        .all(|v| v.is_finite())
        .then(|| Candidate::new(problem, w, r))
}
