//! Input checks for the friction problem, done before any data reaches clarabel (which asserts).

use nalgebra::{DMatrix, DVector};

use super::{CoulombSettings, FrictionProblem};
use crate::error::ContactError;

/// Largest accepted asymmetry `max |W_ij - W_ji|`, relative to `max |W_ij|`.
const SYMMETRY_TOLERANCE: f64 = 1e-6;

fn invalid(message: String) -> Result<(), ContactError> {
    Err(ContactError::InvalidProblem(message))
}

/// Check sizes, finiteness, `dim ∈ {2, 3}`, `mu_i >= 0`, `W` square, finite and symmetric (to
/// [`SYMMETRY_TOLERANCE`]) with a positive normal diagonal and a non-negative tangential one (a
/// zero tangential compliance is legitimate: a node on a facet vertex whose slip the forces
/// cannot change). Returns whether `W` is exactly symmetric (see [`exactly_symmetric`]).
pub(crate) fn check_problem(problem: &FrictionProblem) -> Result<bool, ContactError> {
    check_sizes(problem)?;
    let symmetric = check_delassus(problem.w)?;
    check_diagonal(problem.w, problem.dim)?;
    Ok(symmetric)
}

/// The checks of [`check_problem`] that read `W` only on its diagonal (`O(m)` against the
/// `O(m^2)` of its finiteness and symmetry): what a measure of a candidate's error needs, which
/// weighs each contact by its diagonal compliance. Returns the number of contacts.
pub(crate) fn check_shape(problem: &FrictionProblem) -> Result<usize, ContactError> {
    let n_contacts = check_sizes(problem)?;
    check_diagonal(problem.w, problem.dim)?;
    Ok(n_contacts)
}

/// Sizes, `dim`, `mu` and `q` (everything but `W`'s entries).
fn check_sizes(problem: &FrictionProblem) -> Result<usize, ContactError> {
    let dim = problem.dim;
    if dim != 2 && dim != 3 {
        invalid(format!("contact dimension must be 2 or 3, got {dim}"))?;
    }
    let n_contacts = problem.mu.len();
    let m = dim * n_contacts;
    if problem.q.len() != m {
        invalid(format!(
            "q has length {} but {n_contacts} contacts of dimension {dim} need {m}",
            problem.q.len()
        ))?;
    }
    if problem.w.nrows() != m || problem.w.ncols() != m {
        invalid(format!(
            "W is {}x{} but must be {m}x{m}",
            problem.w.nrows(),
            problem.w.ncols()
        ))?;
    }
    if let Some((i, mu)) = problem
        .mu
        .iter()
        .enumerate()
        .find(|(_, mu)| !(mu.is_finite() && **mu >= 0.0))
    {
        invalid(format!(
            "friction coefficient of contact {i} must be finite and >= 0, got {mu}"
        ))?;
    }
    if !problem.q.iter().all(|v| v.is_finite()) {
        invalid("q has non-finite entries".into())?;
    }
    Ok(n_contacts)
}

/// `W` has a finite diagonal, positive on normal rows (every `dim`-th) and non-negative on
/// tangential ones.
fn check_diagonal(w: &DMatrix<f64>, dim: usize) -> Result<(), ContactError> {
    let admissible = |i: usize| {
        let d = w[(i, i)];
        d.is_finite() && d >= 0.0 && (!i.is_multiple_of(dim) || d > 0.0)
    };
    if let Some(i) = (0..w.nrows()).find(|&i| !admissible(i)) {
        invalid(format!(
            "W must have a finite diagonal, positive on normal rows and non-negative on \
             tangential ones, W[{i},{i}] = {}",
            w[(i, i)]
        ))?;
    }
    Ok(())
}

/// Whether the square `w` equals its transpose exactly, `W_ij == W_ji` for every pair `i > j`
/// (never with a NaN): then its symmetric part is `W` itself.
pub(crate) fn exactly_symmetric(w: &DMatrix<f64>) -> bool {
    let (m, entries) = (w.nrows(), w.as_slice());
    entries
        .chunks_exact(m.max(1))
        .enumerate()
        .all(|(j, column)| {
            // W_ij down column j (contiguous) against W_ji along row j (stride m)
            let row = entries[j * m + j..].iter().step_by(m);
            column[j..]
                .iter()
                .zip(row)
                .all(|(lower, upper)| lower == upper)
        })
}

/// `W` is finite and symmetric to [`SYMMETRY_TOLERANCE`] of its largest entry:
/// `max |W_ij - W_ji| <= SYMMETRY_TOLERANCE max |W_ij|`. An exactly symmetric `W` (the
/// integrator's Delassus operators) is only checked for finiteness; the asymmetry is measured
/// only where it is not zero. Returns whether `W` is exactly symmetric.
fn check_delassus(w: &DMatrix<f64>) -> Result<bool, ContactError> {
    if !w.as_slice().iter().all(|v| v.is_finite()) {
        invalid("W has non-finite entries".into())?;
    }
    if exactly_symmetric(w) {
        return Ok(true);
    }
    let magnitude = w.amax();
    let asymmetry = (0..w.ncols())
        .flat_map(|j| (j + 1..w.nrows()).map(move |i| (w[(i, j)] - w[(j, i)]).abs()))
        .fold(0.0, f64::max);
    if asymmetry > SYMMETRY_TOLERANCE * magnitude {
        invalid(format!(
            "W is not symmetric: max |W - W^T| = {asymmetry:e} against max |W| = {magnitude:e}"
        ))?;
    }
    Ok(false)
}

/// Check the settings: positive finite tolerances and at least one iteration of each loop.
pub(crate) fn check_settings(settings: &CoulombSettings) -> Result<(), ContactError> {
    if !(settings.tolerance.is_finite() && settings.tolerance > 0.0) {
        invalid(format!(
            "tolerance must be finite and positive, got {}",
            settings.tolerance
        ))?;
    }
    if !(settings.conic_tolerance.is_finite() && settings.conic_tolerance > 0.0) {
        invalid(format!(
            "conic tolerance must be finite and positive, got {}",
            settings.conic_tolerance
        ))?;
    }
    if settings.max_fixed_point_iterations == 0 || settings.conic_max_iterations == 0 {
        invalid("iteration limits must be at least 1".into())?;
    }
    Ok(())
}

/// Check a warm-start shift: one finite, non-negative entry per contact.
pub(crate) fn check_shift(shift: &[f64], n_contacts: usize) -> Result<(), ContactError> {
    if shift.len() != n_contacts {
        invalid(format!(
            "initial shift has length {} but there are {n_contacts} contacts",
            shift.len()
        ))?;
    }
    if !shift.iter().all(|s| s.is_finite() && *s >= 0.0) {
        invalid("initial shift entries must be finite and >= 0".into())?;
    }
    Ok(())
}

/// Check warm-start forces: one finite entry per unknown.
pub(crate) fn check_forces(forces: &DVector<f64>, unknowns: usize) -> Result<(), ContactError> {
    if forces.len() != unknowns {
        invalid(format!(
            "initial forces have length {} but there are {unknowns} unknowns",
            forces.len()
        ))?;
    }
    if !forces.iter().all(|f| f.is_finite()) {
        invalid("initial forces must be finite".into())?;
    }
    Ok(())
}
