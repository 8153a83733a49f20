//! Newton-Raphson for one increment, static or dynamic, with exact Coulomb contact.
//!
//! Each iteration assembles the residual `R` (without contact) and the effective tangent at the
//! current iterate, linearises the contact kinematics (rows `H`), reduces the linear step to the
//! friction-cone problem in the contact forces (see [`crate::coupling`]), solves it exactly, and
//! updates `x += dx_0 + Z r`. The increment has converged when, at the new iterate,
//! - the force residual `R - H^T r`, scaled by the largest force in play (moments by the model
//!   size), is below `force_tolerance`, and
//! - the actual gaps and slips differ from those the linearised problem predicted (and for which
//!   the Coulomb law holds exactly) by less than `contact_tolerance` times the model size.
//!
//! Once the force residual is below its tolerance and only the contact residual is not (the gap
//! of a secant row converges linearly), the next step reuses the last factorization (a
//! modified Newton step): the dense block of the contact equations is most of an iteration's
//! cost on large contact sets, and the matrix has barely changed.
//!
//! A step whose end folds an element (`J <= 0` at an element's centre or corner) is halved, up
//! to [`newton::MAX_STEP_HALVINGS`] times, before the increment is given up for a cutback; so is
//! the HHT predictor, which extrapolates the start velocity over the whole increment.
//!
//! Dynamic residual (HHT): `R = M a + (1 + alpha) (F(x) + G(v)) - alpha (F_n + G(v_n))`, with
//! the gyroscopic moments `G = W x J W` of bodies free to turn (see [`crate::orientation`]),
//! weighted as the forces are to keep the scheme of second order; tangent
//! `M/(beta h^2) + (1 + alpha) K_T`, without `dG/dx` (about `gamma h |W|` of the inertia term,
//! so Newton converges linearly at that rate on such bodies' equations). Static residual:
//! `R = F(x)` with `F = f_int - lambda f_ext`; tangent `K_T`, the consistent one, where `K_T`
//! without the contacts holds every motion (tested on the increment's first tangent, see
//! [`Assembler::is_held`]), so that Newton converges quadratically; otherwise `K_T + M/h_s^2`.
//! That mass term only regularises the Newton step (it keeps a pad that is not yet held by
//! contact from being singular, at the price of a linear rate); it is not in the residual, so
//! the converged state is exactly static. A static increment on the consistent tangent without
//! contacts keeps that tangent where it is indefinite (a compressed solid's iterate that has
//! not relaxed yet), factored as `L D L^T`, so that its rate stays quadratic. An increment on
//! the reduced contact path whose tangent without the contacts is indefinite (the
//! Cholesky-based reduction needs a definite one; the contacts hold the pad) goes on with
//! global steps on that same tangent, which keeps the rate (see [`solve_increment`]). Where
//! that fails, or the tangent is singular, the mass term of either matrix grows tenfold at a
//! time (from `M/h_s^2` for a static tangent without one) until it can be factorized (see
//! [`Assembler::with_mass_shift`]), which again changes only Newton's path.
//!
//! Stiffness damping (a section's `beta`, see [`crate::assembly::Damping`]) is part of `F` in
//! a dynamic increment, `F = f_int + beta K_T (x - x_n)/h - f_ext`, weighted and stored as the
//! other forces (so HHT's history term carries it), its tangent `(1 + beta/h) K_T` in place of
//! `K_T`; its work by the trapezoidal rule is the ledger's damping dissipation.
//!
//! Quasi-static equations (a solid declared without inertia, [`crate::model::SolidPart`]) are
//! in equilibrium at the end of each dynamic increment with the mean contact force
//! `p = 2 beta r` that the bodies with inertia receive as an impulse (see [`crate::hht`]):
//! their rows are `R = F(x) / (2 beta)`, tangent `K_T / (2 beta)`, so that `R - H^T r = 0` says
//! `F = H^T p` and action equals reaction. Their rate is the mean one, `v = (x - x_n)/h`,
//! `a = 0`. The regularisation and the mass shift use the solid's density all the same.
//!
//! Contact nodes whose mass was moved off them ([`Model::with_massless_contact_nodes`]) are
//! such equations too, inside a solid with inertia. Their rows `F / (2 beta)` meet the
//! solid's HHT rows through the stiffness, so a dynamic increment multiplies the rows of the
//! solid and of the bodies tied to it by `c = 1 / (2 beta (1 + alpha))`: every one of them
//! then takes the stiffness as `K / (2 beta)` and the tangent stays symmetric, while the
//! other bodies' rows (a drum's, which meets the solid only through contact) keep theirs.
//! Scaling a row does not move its root; the force residual is measured on the unscaled rows.

mod end_state;
mod newton;
mod residual;

use std::time::{Duration, Instant};

use crate::assembly::Assembler;
use crate::cost::{SolveCounts, Timings};
use crate::error::IncrementFailure;
use crate::global_contact::GlobalContactSolver;
use crate::hht::Hht;
use crate::loads::LoadInstant;
use crate::model::Model;
use crate::settings::{ContactSolve, Settings};
use crate::state::State;

use newton::{Check, Increment, Newton};

/// What kind of increment to take.
#[derive(Clone, Copy, Debug)]
pub enum IncrementKind {
    /// Static equilibrium at load factor `load_factor`; `regularization` is the mass factor
    /// `1/h_s^2` of the Newton step.
    Static {
        /// Load factor at the end of the increment.
        load_factor: f64,
        /// Factor on the mass matrix added to the Newton tangent.
        regularization: f64,
        /// Step time at the end of the increment (the completed fraction of the step).
        step_time: f64,
        /// Index of the step in the run.
        step: usize,
    },
    /// HHT increment of size `h`.
    Dynamic {
        /// HHT parameters.
        hht: Hht,
        /// Time increment.
        h: f64,
        /// Step time at the end of the increment, s.
        step_time: f64,
        /// Index of the step in the run.
        step: usize,
        /// Completed fraction of the step at the end of the increment.
        fraction: f64,
    },
}

impl IncrementKind {
    /// Where the loads stand at the end of the increment: the ramp of a static increment's load
    /// factor (1 in a dynamic one), the step time, the step and its completed fraction.
    pub fn loads(&self) -> LoadInstant {
        match *self {
            Self::Static {
                load_factor,
                step_time,
                step,
                ..
            } => LoadInstant {
                ramp: load_factor,
                step_time,
                step,
                fraction: step_time,
            },
            Self::Dynamic {
                step_time,
                step,
                fraction,
                ..
            } => LoadInstant {
                ramp: 1.0,
                step_time,
                step,
                fraction,
            },
        }
    }
}

/// Counters of one converged increment.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct IncrementCounters {
    /// Newton iterations (linear solves).
    pub newton_iterations: usize,
    /// Conic solves.
    pub contact_solves: usize,
    /// De Saxce fixed-point iterations.
    pub fixed_point_iterations: usize,
    /// Semismooth Newton steps of the contact solves.
    pub contact_newton_steps: usize,
    /// 1 if the increment was solved by the reduced contact step after the global one failed.
    pub contact_fallbacks: usize,
    /// 1 if a reduced increment went on with global contact steps because its tangent without
    /// the contacts was indefinite (see [`solve_increment`]).
    pub global_switches: usize,
    /// Scaled (force, contact) residuals at each convergence check.
    pub residuals: Vec<(f64, f64)>,
}

/// The workspace an increment reuses: the tangent's assembler and the global contact solver.
#[derive(Debug)]
pub struct Workspace {
    /// Assembly of the effective tangent and its Cholesky factorizations.
    pub assembler: Assembler,
    /// The global contact system's factorizations.
    pub global: GlobalContactSolver,
}

impl Workspace {
    /// The factorizations and GMRES iterations of this workspace so far.
    pub fn counts(&self) -> SolveCounts {
        SolveCounts {
            tangent_factorizations: self.assembler.factorizations,
            ..self.global.counts
        }
    }

    /// The wall time of this workspace's numeric factorizations so far.
    pub fn factorization_time(&self) -> Duration {
        self.assembler.factorization_time + self.global.factorization_time
    }
}

/// An increment that failed: why, and the residuals of its convergence checks (as in
/// [`IncrementCounters::residuals`]), so that the failed attempt can be read as a converged one
/// is.
#[derive(Clone, Debug)]
pub struct Rejection {
    /// Why Newton failed.
    pub failure: IncrementFailure,
    /// Scaled (force, contact) residuals at each convergence check of the failed attempt.
    pub residuals: Vec<(f64, f64)>,
}

/// Solves one increment from `start`. `held[eq]` marks the constrained equations: kept at
/// their start value, or, for those of `prescribed` (`(equation, value)`), set to the value
/// there at the increment's end.
///
/// With [`ContactSolve::Global`], an increment that fails is tried once more with
/// [`ContactSolve::Reduced`] (counted in [`IncrementCounters::contact_fallbacks`]), and the
/// failure reported is that of the second attempt, with its residuals.
///
/// With [`ContactSolve::Reduced`], an iteration whose tangent `K + c M` without the contacts
/// is indefinite (a compressed pad held only by its contacts) has no Cholesky factor for the
/// reduction to the contact forces. The contacts make the full system definite on the
/// motions they hold, so the increment goes on with global steps on that same matrix
/// (counted in [`IncrementCounters::global_switches`]): Newton keeps the tangent of the
/// residual and its rate. If that attempt fails, the increment is solved again on the reduced
/// path with the mass term raised until the tangent factorizes (see
/// [`Assembler::with_mass_shift`]), which changes only Newton's path.
///
/// # Errors
/// A [`Rejection`] saying why Newton failed; the caller cuts back.
pub fn solve_increment<const D: usize>(
    model: &Model<D>,
    workspace: &mut Workspace,
    start: &State,
    kind: IncrementKind,
    (held, prescribed): (&[bool], &[(usize, f64)]),
    settings: &Settings,
    timings: &mut Timings,
) -> Result<(State, IncrementCounters), Rejection> {
    // the state, or the rejection and whether the attempt had switched to global steps
    let mut attempt = |method, may_switch| {
        let mut counters = IncrementCounters::default();
        match solve_increment_with(
            model,
            workspace,
            start,
            kind,
            (held, prescribed),
            settings,
            (method, may_switch, &mut counters),
            timings,
        ) {
            Ok(state) => Ok((state, counters)),
            Err(failure) => Err((
                Rejection {
                    failure,
                    residuals: counters.residuals,
                },
                counters.global_switches > 0,
            )),
        }
    };
    match settings.contact_solve {
        ContactSolve::Reduced => match attempt(ContactSolve::Reduced, true) {
            Ok(solved) => Ok(solved),
            Err((_, true)) => attempt(ContactSolve::Reduced, false).map_err(|(r, _)| r),
            Err((rejection, false)) => Err(rejection),
        },
        ContactSolve::Global => match attempt(ContactSolve::Global, false) {
            Ok(solved) => Ok(solved),
            Err(_) if !model.contacts().is_empty() => {
                let (state, mut counters) =
                    attempt(ContactSolve::Reduced, false).map_err(|(r, _)| r)?;
                counters.contact_fallbacks += 1;
                Ok((state, counters))
            }
            Err((rejection, _)) => Err(rejection),
        },
    }
}

/// [`solve_increment`] with the contact forces of every iteration from `method`, or, if
/// `may_switch`, from global steps once a reduced one finds its tangent indefinite; counting
/// into `counters` (which keep the residuals of a failed attempt too).
#[allow(clippy::too_many_arguments)] // solve_increment's inputs and the method
fn solve_increment_with<const D: usize>(
    model: &Model<D>,
    workspace: &mut Workspace,
    start: &State,
    kind: IncrementKind,
    constraints: (&[bool], &[(usize, f64)]),
    settings: &Settings,
    (method, may_switch, counters): (ContactSolve, bool, &mut IncrementCounters),
    timings: &mut Timings,
) -> Result<State, IncrementFailure> {
    let Workspace { assembler, global } = workspace;
    let max_iterations = match method {
        ContactSolve::Global => settings.newton.max_iterations.min(GLOBAL_MAX_ITERATIONS),
        ContactSolve::Reduced => settings.newton.max_iterations,
    };
    let (increment, predictor) =
        Increment::new(model, assembler, start, kind, constraints, settings)?;
    let mut newton = Newton::new(&increment, predictor, (method, may_switch));
    for iteration in 0..=max_iterations {
        if newton.x.iter().any(|v| !v.is_finite()) {
            return Err(IncrementFailure::NonFinite { iteration });
        }
        let Some(evaluation) = newton.evaluate(&increment, assembler, counters, timings)? else {
            continue;
        };
        if let Some(forces) = newton.last.take() {
            let check = (&evaluation, &forces);
            match newton.check(&increment, assembler, check, counters, iteration)? {
                Check::Converged => return newton.into_state(&increment, evaluation, &forces),
                Check::NotConverged if iteration == max_iterations => {
                    return Err(newton.not_converged(counters, iteration));
                }
                Check::NotConverged => newton.last = Some(forces),
                Check::Halved => continue,
            }
        }
        let chord = newton.is_chord(&increment, &evaluation, counters);
        let clock = Instant::now();
        if !chord {
            newton.complete_tangent(&increment, assembler, &evaluation, counters)?;
        }
        timings.assembly += clock.elapsed();
        let dx = newton.step(
            &increment,
            (assembler, global),
            &evaluation,
            chord,
            counters,
            timings,
        )?;
        counters.newton_iterations += 1;
        if dx.iter().any(|v| !v.is_finite()) {
            return Err(IncrementFailure::NonFinite { iteration });
        }
        newton.advance(model, assembler, dx);
    }
    // The loop returns from inside, converged or at the last convergence check, unless its
    // last iterations went to halving steps that fold an element: report the last residuals
    // that were measured.
    Err(newton.not_converged(counters, max_iterations))
}

/// Newton iterations the global contact solve gets before the increment is handed to the
/// reduced one. Semismooth Newton without a line search can cycle between active sets: in the
/// static preload of the block-on-flat test it repeats a 4-cycle of force residuals
/// (7.5e-2, 7.5e-2, 7.5e-2, 2.2e-1) indefinitely; a converging increment needs 2 to 5.
const GLOBAL_MAX_ITERATIONS: usize = 12;
