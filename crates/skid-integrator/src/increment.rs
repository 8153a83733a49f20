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
//! A step whose end folds an element (`J <= 0` at an element's centre or corner) is halved, up to
//! [`MAX_STEP_HALVINGS`] times, before the increment is given up for a cutback; so is the HHT
//! predictor, which extrapolates the start velocity over the whole increment.
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

use std::borrow::Cow;
use std::time::{Duration, Instant};

use faer::sparse::SparseColMatRef;
use nalgebra::{DVector, Vector2};
use skid_contact::SurfacePoint;

use crate::assembly::{
    Assembler, Damping, InternalState, Solver, external_forces, is_not_factorized,
};
use crate::contact_rows::{ContactRows, RowStart, contact_rows};
use crate::cost::{SolveCounts, Timings};
use crate::coupling::contact_step;
use crate::dof::EquationKind;
use crate::error::{IncrementFailure, WorstResidual};
use crate::global_contact::{GlobalContactSolver, GlobalStep, contact_weights, law_residuals};
use crate::hht::{Hht, IncrementEnds};
use crate::loads::LoadInstant;
use crate::model::Model;
use crate::settings::{ContactSolve, NewtonSettings, Settings};
use crate::sparse::Factorization;
use crate::state::{ContactPointState, EnergyLedger, State};

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
    let increment = Increment::new(model, assembler, start, kind, constraints, settings)?;
    let mut newton = Newton::new(&increment, (method, may_switch));
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
        assembler.advance_mixed_pressures(model, &dx);
        newton.x += &dx;
        newton.last_step = Some(dx);
        newton.halvings = 0;
    }
    // The loop returns from inside, converged or at the last convergence check, unless its
    // last iterations went to halving steps that fold an element: report the last residuals
    // that were measured.
    Err(newton.not_converged(counters, max_iterations))
}

/// What an increment's Newton iterations share and do not change.
struct Increment<'a, const D: usize> {
    model: &'a Model<D>,
    start: &'a State,
    kind: IncrementKind,
    /// The constrained equations.
    held: &'a [bool],
    /// The equations that move as prescribed.
    moving: Vec<bool>,
    settings: &'a Settings,
    factors: Factors<'a>,
    /// The increment's first iterate.
    predictor: DVector<f64>,
    /// Where the contact rows start: dynamic increments take the normal rows between the
    /// start and the end positions, so that the contact impulse does the work `p_N dg` (see
    /// `contact_rows`); a static equilibrium takes the normal at the solution itself.
    row_start: Option<RowStart<'a>>,
    /// The closest points of the start's contacts.
    previous: Vec<SurfacePoint>,
    /// The gyroscopic moments at the start, HHT's history term for bodies free to turn.
    start_gyroscopic: Option<DVector<f64>>,
    /// The internal forces are as exact as the stresses they sum: an equation's force is
    /// known to `eps` of its elements' stiffness times their size (the round-off of
    /// `K (J - 1)` of a nearly incompressible solid: Cook's membrane at nu = 0.4999 under a
    /// load of 1e-3 stalled at 1e-5 of it), see [`Assembler::stiffness_scale`].
    stiffness_roundoff: DVector<f64>,
}

impl<'a, const D: usize> Increment<'a, D> {
    /// The increment of `kind` from `start` with the `constraints` (held equations, and the
    /// `(equation, value)` of the prescribed ones); starts the assembler's mixed pressures.
    fn new(
        model: &'a Model<D>,
        assembler: &mut Assembler,
        start: &'a State,
        kind: IncrementKind,
        (held, prescribed): (&'a [bool], &[(usize, f64)]),
        settings: &'a Settings,
    ) -> Result<Self, IncrementFailure> {
        let row_start = match kind {
            IncrementKind::Static { .. } => None,
            IncrementKind::Dynamic { .. } => Some(RowStart::new(model, &start.x)),
        };
        let stiffness_roundoff = assembler.stiffness_scale() * (ROUNDOFF_ULPS * f64::EPSILON);
        let (predictor, moving) = predictor(start, kind, (held, prescribed));
        assembler.start_mixed_pressures(model, &start.x)?;
        Ok(Self {
            model,
            start,
            kind,
            held,
            moving,
            settings,
            factors: Factors::new(model, kind),
            predictor,
            row_start,
            previous: start.contacts.iter().map(|c| c.closest).collect(),
            start_gyroscopic: model.gyroscopic_moments(&start.v),
            stiffness_roundoff,
        })
    }

    /// The contact rows at `x`, of the equations not `held` (every equation's with none).
    fn contact_rows(
        &self,
        x: &DVector<f64>,
        held: &[bool],
    ) -> Result<ContactRows, IncrementFailure> {
        contact_rows(
            self.model,
            x,
            &self.start.orientations,
            self.row_start.as_ref(),
            Some(&self.previous),
            held,
        )
    }

    /// What the constrained equations of a converged iterate `x` must balance: `held_residual`'s
    /// `(equation, R)` as the force of the constraint, and the reaction `R - H^T r` without the
    /// contact forces `r` on those equations, which their rows leave out (taken again here
    /// from contact rows of every equation).
    fn reactions(
        &self,
        x: &DVector<f64>,
        held_residual: &[(usize, f64)],
        r: &DVector<f64>,
    ) -> Result<(DVector<f64>, DVector<f64>), IncrementFailure> {
        let n = x.len();
        let held_contact = if held_residual.is_empty() {
            None
        } else {
            Some(self.contact_rows(x, &vec![false; n])?.transpose_times(r, n))
        };
        let (mut constrained, mut reaction) = (DVector::zeros(n), DVector::zeros(n));
        for &(eq, value) in held_residual {
            constrained[eq] = value;
            reaction[eq] = value - held_contact.as_ref().map_or(0.0, |c| c[eq]);
        }
        Ok((constrained, reaction))
    }

    /// The sections' stiffness damping of a dynamic increment acts on the iterate's mean
    /// velocity over it, `(x - x_n) rate` (see [`Damping`]).
    fn mean_velocity(&self, x: &DVector<f64>) -> Option<DVector<f64>> {
        self.factors
            .damping_rate
            .map(|rate| (x - &self.start.x) * rate)
    }
}

/// One iterate's forces, residual and contact rows.
struct Evaluation {
    v: DVector<f64>,
    a: DVector<f64>,
    internal: InternalState,
    f_ext: DVector<f64>,
    /// `f_int + f_damping - f_ext`.
    net: DVector<f64>,
    inertia: DVector<f64>,
    /// The residual without contact, zero on the held equations.
    residual: DVector<f64>,
    rows: ContactRows,
    /// What the constraints must balance (see [`take_held`]).
    held_residual: Vec<(usize, f64)>,
    /// Whether the tangent was assembled with the forces.
    tangent_now: bool,
}

/// What a convergence check found.
enum Check {
    Converged,
    NotConverged,
    /// The iterate went back half way (see [`Newton::check`]).
    Halved,
}

/// The state of an increment's Newton iterations.
struct Newton {
    /// How the contact forces of a step are found.
    method: ContactSolve,
    /// Whether a reduced step may switch to global steps (see [`solve_increment`]).
    may_switch: bool,
    /// `c_M` and the first mass shift (see [`Factors`]); a static increment's first tangent
    /// may drop the regularisation.
    m_factor: f64,
    shift: (f64, f64),
    /// The iterate.
    x: DVector<f64>,
    /// The contact forces a step starts from.
    warm: DVector<f64>,
    /// The contact forces of the last step and what the next iterate's contact state is
    /// checked against.
    last: Option<LastForces>,
    /// The last step (at first the predictor's) and how often it has been halved.
    last_step: Option<DVector<f64>>,
    halvings: usize,
    /// Whether global steps solve their linearisation's contact problem (see
    /// [`is_stagnating`]).
    exact_contact: bool,
    worst: Option<WorstResidual>,
    /// The forces before the last global step, to go back half way with the step.
    forces_before: Option<DVector<f64>>,
    /// The factorization of the last contact step (see [`Newton::step`]).
    reusable: Option<Factorization>,
    /// The candidates' weights of the contact law residual, fixed for the increment so that
    /// the law residual measures every iterate alike (see [`crate::global_contact`]).
    weights: Option<Vec<f64>>,
}

impl Newton {
    /// The iterations of `increment` with the contact solve `method`, from its predictor.
    fn new<const D: usize>(
        increment: &Increment<'_, D>,
        (method, may_switch): (ContactSolve, bool),
    ) -> Self {
        let x = increment.predictor.clone();
        let last_step = match increment.kind {
            IncrementKind::Static { .. } => None,
            IncrementKind::Dynamic { .. } => Some(&x - &increment.start.x),
        };
        Self {
            method,
            may_switch,
            m_factor: increment.factors.m_factor,
            shift: increment.factors.shift,
            x,
            warm: increment.start.warm_forces.clone(),
            last: None,
            last_step,
            halvings: 0,
            exact_contact: false,
            worst: None,
            forces_before: None,
            reusable: None,
            weights: None,
        }
    }

    /// The iterate's forces, residual and contact rows; `None` if the last step folded an
    /// element and was halved instead.
    fn evaluate<const D: usize>(
        &mut self,
        increment: &Increment<'_, D>,
        assembler: &mut Assembler,
        counters: &IncrementCounters,
        timings: &mut Timings,
    ) -> Result<Option<Evaluation>, IncrementFailure> {
        let Increment {
            model,
            start,
            kind,
            held,
            ..
        } = *increment;
        let clock = Instant::now();
        let x = &self.x;
        let (v, a) = rates(
            model.quasi_static(),
            start,
            kind,
            x,
            (held, &increment.moving),
        );
        // A convergence check needs the forces alone; the tangent is assembled only if the
        // iterate is not accepted (about half of the checks in a spin-down accept it). The
        // global contact solve's first check rarely accepts (one in twenty on `3d-refined`):
        // there the tangent comes with the forces, so that its elements are evaluated once.
        let tangent_now = self.last.is_none()
            || (self.method == ContactSolve::Global && counters.newton_iterations == 1);
        let mean_velocity = increment.mean_velocity(x);
        let damping = increment
            .factors
            .damping_rate
            .zip(mean_velocity.as_ref())
            .map(|(rate, velocity)| Damping { velocity, rate });
        let k_factor = tangent_now.then_some(increment.factors.k_factor);
        let internal = match assembler.internal_damped(model, x, k_factor, damping) {
            Ok(internal) => internal,
            // A full Newton step that folds an element overshoots; half of it may not. The
            // iterate stays a Newton iterate (the next step starts from it, and convergence
            // is still judged by the residuals), so only the path changes.
            Err(IncrementFailure::InvertedElement { .. })
                if self.halvings < MAX_STEP_HALVINGS && self.last_step.is_some() =>
            {
                if let Some(step) = self.last_step.as_mut() {
                    *step *= 0.5;
                    self.x -= &*step;
                    assembler.advance_mixed_pressures(model, step);
                }
                self.halvings += 1;
                return Ok(None);
            }
            Err(failure) => return Err(failure),
        };
        let f_ext = external_forces(model, x, &start.orientations, kind.loads())?;
        let net = &internal.force + &internal.damping_force - &f_ext;
        let inertia = inertia_forces(model, kind, (&v, &a), increment.start_gyroscopic.as_ref());
        let mut residual = residual_without_contact(
            (model, start, kind),
            increment.factors.row_scale,
            &inertia,
            &net,
        );
        let rows = increment.contact_rows(x, held)?;
        let held_residual = take_held(&mut residual, held);
        timings.assembly += clock.elapsed();
        Ok(Some(Evaluation {
            v,
            a,
            internal,
            f_ext,
            net,
            inertia,
            residual,
            rows,
            held_residual,
            tangent_now,
        }))
    }

    /// The convergence check of an evaluated iterate against the contact `forces` of the last
    /// step: its scaled force and contact residuals (kept in `counters`). An iterate that does
    /// not converge may switch global steps to exact contact solves, or go back half way out
    /// of a cycle (then with the forces half way back as the last step's).
    fn check<const D: usize>(
        &mut self,
        increment: &Increment<'_, D>,
        assembler: &mut Assembler,
        (evaluation, forces): (&Evaluation, &LastForces),
        counters: &mut IncrementCounters,
        iteration: usize,
    ) -> Result<Check, IncrementFailure> {
        let Increment {
            model, start, kind, ..
        } = *increment;
        let newton = &increment.settings.newton;
        let length = model.length_scale();
        let rows = &evaluation.rows;
        let contact_force = rows.transpose_times(forces.r(), self.x.len());
        let full = in_force_units(
            &evaluation.residual - &contact_force,
            increment.factors.row_scale,
            model.quasi_static(),
        );
        let roundoff = force_roundoff(
            kind,
            model.mass(),
            (&start.x, &self.x),
            &increment.stiffness_roundoff,
        );
        let (force_residual, force_worst) = scaled_force_residual(
            model,
            &full,
            &[
                &evaluation.internal.force,
                &evaluation.internal.damping_force,
                &evaluation.f_ext,
                &start.external_force,
                &evaluation.inertia,
                &contact_force,
            ],
            &roundoff,
            length,
        );
        let (contact_residual, contact_worst) = forces.contact_residual(rows, length);
        counters.residuals.push((force_residual, contact_residual));
        self.worst = worst_residual(
            model,
            newton,
            (force_residual, force_worst),
            (contact_residual, contact_worst),
        );
        if !force_residual.is_finite() || !contact_residual.is_finite() {
            return Err(IncrementFailure::NonFinite { iteration });
        }
        if force_residual <= newton.force_tolerance && contact_residual <= newton.contact_tolerance
        {
            return Ok(Check::Converged);
        }
        // Once global steps stop converging (branches that keep changing, or the inexact
        // solve's error on a few candidates), each later step solves its linearisation's
        // contact problem, as the reduced path does but on the sparse system (measured in
        // the static preload of `3d-refined`: without this, four of five increments
        // stagnate with the law residual near 3e-4 for 12 iterations).
        let global = self.method == ContactSolve::Global;
        self.exact_contact |= global && is_stagnating(&counters.residuals, newton);
        // Semismooth Newton can cycle between two sets of contact branches, each step
        // undoing the last: then the iterate goes back half way (forces too), which
        // leaves the cycle.
        if global
            && self.halvings < MAX_STEP_HALVINGS
            && is_cycling(&counters.residuals)
            && let (Some(step), Some(before)) =
                (self.last_step.as_mut(), self.forces_before.as_ref())
        {
            *step *= 0.5;
            self.x -= &*step;
            assembler.advance_mixed_pressures(model, &(-&*step));
            self.warm = (&self.warm + before) * 0.5;
            self.last = Some(LastForces::Law {
                r: self.warm.clone(),
                rho: self.weights.clone().unwrap_or_default(),
            });
            self.halvings += 1;
            return Ok(Check::Halved);
        }
        Ok(Check::NotConverged)
    }

    /// The end state of the increment converged at the evaluated iterate with the contact
    /// `forces` of the last step.
    fn into_state<const D: usize>(
        self,
        increment: &Increment<'_, D>,
        evaluation: Evaluation,
        forces: &LastForces,
    ) -> Result<State, IncrementFailure> {
        let r = forces.r();
        let (constrained, reaction) = increment.reactions(&self.x, &evaluation.held_residual, r)?;
        let Evaluation {
            v,
            a,
            internal,
            f_ext,
            net,
            rows,
            ..
        } = evaluation;
        let iterate = Iterate {
            x: self.x,
            v,
            a,
            net,
            f_ext,
            internal,
            constrained,
            reaction,
            moving: increment.moving.clone(),
        };
        Ok(finish(
            increment.model,
            increment.start,
            increment.kind,
            iterate,
            &rows,
            r,
            self.warm,
        ))
    }

    /// The failure of iterations that did not converge in `iterations`, with the last
    /// residuals measured.
    fn not_converged(&self, counters: &IncrementCounters, iterations: usize) -> IncrementFailure {
        let (force_residual, contact_residual) = counters
            .residuals
            .last()
            .copied()
            .unwrap_or((f64::NAN, f64::NAN));
        IncrementFailure::NewtonNotConverged {
            iterations,
            force_residual,
            contact_residual,
            worst: self.worst,
        }
    }

    /// Whether the step reuses the reduced path's last factorization (a chord step): once the
    /// forces nearly balance (see [`CHORD_WITHIN`]) or only the contact kinematics is left to
    /// converge (the secant rows' gap converges linearly, see `contact_rows`), it serves
    /// again: the matrix has changed by the order of the last, small step, so the chord step
    /// reaches the tolerance as the Newton step would, at a fraction of the cost. Its tangent
    /// is then not assembled: the assembler keeps the matrix of that factorization, which also
    /// serves if the step must factorize after all (a candidate joining the near set, see
    /// `contact_step`).
    fn is_chord<const D: usize>(
        &self,
        increment: &Increment<'_, D>,
        evaluation: &Evaluation,
        counters: &IncrementCounters,
    ) -> bool {
        self.method == ContactSolve::Reduced
            && !evaluation.rows.is_empty()
            && self.reusable.is_some()
            && counters.residuals.last().is_some_and(|&(force, _)| {
                force <= CHORD_WITHIN * increment.settings.newton.force_tolerance
            })
    }

    /// The iterate's tangent `c_K K_T + c_M M` with the contact rows' curvature, the held
    /// equations' rows made identities. A static increment's first tangent drops the
    /// regularisation where `K_T` holds every motion without the contacts (see
    /// [`Assembler::is_held`]).
    fn complete_tangent<const D: usize>(
        &mut self,
        increment: &Increment<'_, D>,
        assembler: &mut Assembler,
        evaluation: &Evaluation,
        counters: &IncrementCounters,
    ) -> Result<(), IncrementFailure> {
        let Increment {
            model, kind, held, ..
        } = *increment;
        if !evaluation.tangent_now {
            let mean_velocity = increment.mean_velocity(&self.x);
            let damping = increment
                .factors
                .damping_rate
                .zip(mean_velocity.as_ref())
                .map(|(rate, velocity)| Damping { velocity, rate });
            let k_factor = Some(increment.factors.k_factor);
            assembler.internal_damped(model, &self.x, k_factor, damping)?;
        }
        if matches!(kind, IncrementKind::Static { .. }) && counters.newton_iterations == 0 {
            assembler.hold(held);
            if assembler.is_held(model.regularization_mass(), held)? {
                self.m_factor = 0.0;
                self.shift.0 = 0.0;
            }
        }
        assembler.add_diagonal(&(increment.factors.m_term.as_ref() * self.m_factor));
        assembler.add_contact_curvature(&evaluation.rows, &self.warm);
        assembler.hold(held);
        Ok(())
    }

    /// The Newton step `dx` and the contact forces of the next iterate: without contacts on
    /// `K + c M` itself (its mass term raised only where it is singular, see
    /// [`Assembler::with_mass_shift`]); with contacts reduced onto their forces while
    /// `K + c M` factorizes, else (or by request) global on the full system. The residual
    /// keeps the true inertia, so a raised mass term changes only the path.
    fn step<const D: usize>(
        &mut self,
        increment: &Increment<'_, D>,
        (assembler, global): (&mut Assembler, &mut GlobalContactSolver),
        evaluation: &Evaluation,
        chord: bool,
        counters: &mut IncrementCounters,
        timings: &mut Timings,
    ) -> Result<DVector<f64>, IncrementFailure> {
        let Increment {
            model,
            kind,
            held,
            settings,
            ..
        } = *increment;
        let (rows, residual) = (&evaluation.rows, &evaluation.residual);
        let length = model.length_scale();
        let shift_mass = model.regularization_mass();
        let contact_tolerance = settings.newton.contact_tolerance * length;
        if rows.is_empty() {
            let clock = Instant::now();
            let consistent = matches!(kind, IncrementKind::Static { .. }) && self.m_factor == 0.0;
            let dx = step_without_contact(
                assembler,
                consistent,
                (shift_mass, self.shift),
                held,
                residual,
            )?;
            timings.linear_solve += clock.elapsed();
            self.last = Some(LastForces::Linearised {
                r: DVector::zeros(0),
                u: DVector::zeros(0),
                rho: Vec::new(),
            });
            return Ok(dx);
        }
        if self.method == ContactSolve::Reduced {
            let mut reuse = self.reusable.take().filter(|_| chord);
            if self.weights.is_none() {
                let k = assembler.lower_triangle()?;
                self.weights = Some(contact_weights(k, rows));
            }
            let warm = &self.warm;
            let step = |a: &mut Assembler| {
                contact_step(
                    a,
                    rows,
                    residual,
                    warm,
                    length,
                    contact_tolerance,
                    &settings.coulomb,
                    reuse.take(),
                    timings,
                )
            };
            let stepped = on_factorized_tangent(
                assembler,
                self.may_switch,
                (shift_mass, self.shift),
                held,
                step,
            )?;
            match stepped {
                Some((dx, solution, factor)) => {
                    self.reusable = Some(factor);
                    counters.contact_solves += solution.conic_solves;
                    counters.fixed_point_iterations += solution.fixed_point_iterations;
                    counters.contact_newton_steps += solution.newton_steps;
                    self.warm.clone_from(&solution.r);
                    self.last = Some(LastForces::Linearised {
                        r: solution.r,
                        u: solution.u,
                        rho: self.weights.clone().unwrap_or_default(),
                    });
                    return Ok(dx);
                }
                // the tangent without the contacts is indefinite: global steps from here on
                // (see `solve_increment`)
                None => {
                    self.method = ContactSolve::Global;
                    counters.global_switches += 1;
                }
            }
        }
        let clock = Instant::now();
        let k = assembler.lower_triangle()?;
        let rho = self.weights.get_or_insert_with(|| contact_weights(k, rows));
        if self.warm.len() != rows.rows.len() {
            self.warm = DVector::zeros(rows.rows.len());
        }
        let exact = self
            .exact_contact
            .then_some((contact_tolerance, LINEARISED_MAX_STEPS));
        let step = global_step(
            global,
            model,
            k,
            (rows, held),
            residual,
            (&self.warm, rho),
            exact,
        );
        timings.linear_solve += clock.elapsed();
        let step = step?;
        self.forces_before = Some(std::mem::replace(&mut self.warm, step.r.clone()));
        self.last = Some(LastForces::Law {
            r: step.r,
            rho: rho.clone(),
        });
        Ok(step.dx)
    }
}

/// The constant factors of an increment's residual and tangent: the solid's rows of the tangent
/// are `c_K K_T`, the mass term `c_M M` (regularising in a static increment, inertial in a
/// dynamic one).
struct Factors<'m> {
    /// `(c, rows)`: with the contact nodes' mass moved off them, a dynamic increment multiplies
    /// the rows of the solid and its tied bodies by `c = 1 / (2 beta (1 + alpha))`, so that the
    /// stiffness enters them as `K / (2 beta)`, as it enters the contact nodes' equilibrium
    /// rows: the tangent stays symmetric (see the module documentation).
    row_scale: Option<(f64, &'m [bool])>,
    /// `c_K`.
    k_factor: f64,
    /// `c_M`: the regularisation of a static increment, `1/(beta h^2)` of a dynamic one.
    m_factor: f64,
    /// `M`: the regularisation mass of a static increment, the (row-scaled) inertia of a
    /// dynamic one.
    m_term: Cow<'m, DVector<f64>>,
    /// The mass factors the first shift starts from (see [`Assembler::with_mass_shift`]). A
    /// quasi-static solid has no mass term in a dynamic tangent; if the tangent is indefinite
    /// without the contacts, the shift starts far below the inertia its density would give.
    /// A static increment whose tangent holds every motion without the contacts drops its
    /// regularisation (`m_factor = 0`, decided on the first tangent), so that Newton takes the
    /// consistent tangent of the residual it solves; the regularisation is then the first
    /// shift of a tangent that turns indefinite.
    shift: (f64, f64),
    /// `1/h`: the sections' stiffness damping acts in a dynamic increment, on the iterate's
    /// mean velocity over it (see [`Damping`]).
    damping_rate: Option<f64>,
}

impl<'m> Factors<'m> {
    /// The factors of an increment of `kind` on `model`.
    fn new<const D: usize>(model: &'m Model<D>, kind: IncrementKind) -> Self {
        let mass = model.mass();
        let row_scale = match (kind, model.solid_rows()) {
            (IncrementKind::Dynamic { hht, .. }, Some(rows)) => {
                Some((hht.quasi_static_factor() / (1.0 + hht.alpha), rows))
            }
            _ => None,
        };
        let inertia_mass = match row_scale {
            Some((c, rows)) => Cow::Owned(DVector::from_fn(mass.len(), |i, _| {
                if rows[i] { c * mass[i] } else { mass[i] }
            })),
            None => Cow::Borrowed(mass),
        };
        let (k_factor, m_factor, m_term) = match kind {
            IncrementKind::Static { regularization, .. } => (
                1.0,
                regularization,
                Cow::Borrowed(model.regularization_mass()),
            ),
            IncrementKind::Dynamic { hht, h, .. } => {
                let k_factor = if model.part().quasi_static || row_scale.is_some() {
                    hht.quasi_static_factor()
                } else {
                    1.0 + hht.alpha
                };
                (k_factor, hht.mass_factor(h), inertia_mass)
            }
        };
        let shift = match kind {
            IncrementKind::Dynamic { .. } if model.part().quasi_static => {
                let first = m_factor * QUASI_STATIC_SHIFT;
                (first, first)
            }
            _ => (m_factor, m_factor),
        };
        let damping_rate = match kind {
            IncrementKind::Dynamic { h, .. } if model.has_stiffness_damping() => Some(1.0 / h),
            _ => None,
        };
        Self {
            row_scale,
            k_factor,
            m_factor,
            m_term,
            shift,
            damping_rate,
        }
    }
}

/// The contact forces of a Newton step and how the next iterate's contact state is judged.
enum LastForces {
    /// A reduced step: the forces `r` satisfy the Coulomb law with the linearised local
    /// quantities `u`; the contact residual is how far the actual ones are from `u`, or the
    /// law's own residual at the new kinematics with the increment's weights `rho` (as for
    /// [`LastForces::Law`]) if that is larger: the Coulomb solver's relative tolerance does not
    /// bound the penetration where one compliance dominates the Delassus operator.
    Linearised {
        r: DVector<f64>,
        u: DVector<f64>,
        rho: Vec<f64>,
    },
    /// A global step: the contact residual is the law's own residual at the new kinematics
    /// with the forces `r` and the increment's weights `rho`.
    Law { r: DVector<f64>, rho: Vec<f64> },
}

impl LastForces {
    /// The forces, one per contact row.
    fn r(&self) -> &DVector<f64> {
        match self {
            Self::Linearised { r, .. } | Self::Law { r, .. } => r,
        }
    }

    /// The contact residual of the iterate whose contact rows are `rows`, in units of the model
    /// size `length`, and the candidate where it is largest (see the variants).
    fn contact_residual(&self, rows: &ContactRows, length: f64) -> (f64, Option<usize>) {
        let d = rows.components;
        match self {
            _ if rows.is_empty() => (0.0, None),
            Self::Linearised { r, u, rho } => largest(
                law_residuals(rows, r, rho)
                    .zip((&rows.u - u).as_slice().chunks(d.max(1)))
                    .map(|(law, du)| du.iter().fold(law, |a, v| a.max(v.abs())) / length),
            ),
            Self::Law { r, rho } => largest(law_residuals(rows, r, rho).map(|law| law / length)),
        }
    }
}

/// The inertia forces `M a` of an iterate with rates `(v, a)`, and in a dynamic increment the
/// gyroscopic moments of bodies free to turn, weighted as HHT weights the forces:
/// `(1 + alpha) G(v) - alpha G(v_n)` (`start_gyroscopic` being `G(v_n)`).
fn inertia_forces<const D: usize>(
    model: &Model<D>,
    kind: IncrementKind,
    (v, a): (&DVector<f64>, &DVector<f64>),
    start_gyroscopic: Option<&DVector<f64>>,
) -> DVector<f64> {
    let mut inertia = model.mass().component_mul(a);
    if let IncrementKind::Dynamic { hht, .. } = kind
        && let (Some(end), Some(begin)) = (model.gyroscopic_moments(v), start_gyroscopic)
    {
        inertia += end * (1.0 + hht.alpha) - begin * hht.alpha;
    }
    inertia
}

/// The residual without contact of an iterate whose net force is `F = f_int + f_damping -
/// f_ext` and whose inertia forces are `inertia`: `F` in a static increment; in a dynamic one
/// HHT's `inertia + (1 + alpha) F - alpha F_n`, its solid's rows scaled by `row_scale`'s
/// factor, and `F / (2 beta)` on quasi-static equations (see the module documentation).
fn residual_without_contact<const D: usize>(
    (model, start, kind): (&Model<D>, &State, IncrementKind),
    row_scale: Option<(f64, &[bool])>,
    inertia: &DVector<f64>,
    net: &DVector<f64>,
) -> DVector<f64> {
    match kind {
        IncrementKind::Static { .. } => net.clone(),
        IncrementKind::Dynamic { hht, .. } => {
            let mut r = inertia + net * (1.0 + hht.alpha) - &start.net_force * hht.alpha;
            if let Some((c, rows)) = row_scale {
                for (eq, _) in rows.iter().enumerate().filter(|(_, s)| **s) {
                    r[eq] *= c;
                }
            }
            for (eq, _) in model.quasi_static().iter().enumerate().filter(|(_, q)| **q) {
                r[eq] = net[eq] * hht.quasi_static_factor();
            }
            r
        }
    }
}

/// The residual's values on the `held` equations, `(equation, R)`: what the constraints must
/// balance; `residual` is zero there afterwards, as the constrained rows become identities.
fn take_held(residual: &mut DVector<f64>, held: &[bool]) -> Vec<(usize, f64)> {
    let taken = held
        .iter()
        .enumerate()
        .filter(|(_, h)| **h)
        .map(|(eq, _)| (eq, residual[eq]))
        .collect();
    for (eq, &h) in held.iter().enumerate() {
        if h {
            residual[eq] = 0.0;
        }
    }
    taken
}

/// `step` on the assembled tangent: if `may_switch`, on that tangent itself, `None` if it is
/// indefinite (it has no Cholesky factor); otherwise with the mass term raised from `shift`
/// until it has one (see [`Assembler::with_mass_shift`]).
fn on_factorized_tangent<T>(
    assembler: &mut Assembler,
    may_switch: bool,
    (mass, shift): (&DVector<f64>, (f64, f64)),
    held: &[bool],
    mut step: impl FnMut(&mut Assembler) -> Result<T, IncrementFailure>,
) -> Result<Option<T>, IncrementFailure> {
    if may_switch {
        match step(assembler) {
            Err(e) if is_not_factorized(&e) => Ok(None),
            stepped => stepped.map(Some),
        }
    } else {
        Ok(Some(assembler.with_mass_shift(mass, shift, held, step)?.0))
    }
}

/// The Newton step `dx = -A^-1 R` of an iterate without contacts, `A` the assembled tangent: on
/// a static increment's `consistent` tangent it is factored as `L D L^T` where it is indefinite
/// (see [`Assembler::is_held`]); otherwise, or where that fails, by Cholesky with the mass term
/// raised from `shift` where the tangent is singular (see [`Assembler::with_mass_shift`]).
fn step_without_contact(
    assembler: &mut Assembler,
    consistent: bool,
    (mass, shift): (&DVector<f64>, (f64, f64)),
    held: &[bool],
    residual: &DVector<f64>,
) -> Result<DVector<f64>, IncrementFailure> {
    let symmetric = if consistent {
        match assembler.factorize_symmetric() {
            Ok(factor) => Some(factor),
            Err(e) if is_not_factorized(&e) => None,
            Err(e) => return Err(e),
        }
    } else {
        None
    };
    let factor = match symmetric {
        Some(factor) => factor,
        None => Solver::Definite(
            assembler
                .with_mass_shift(mass, shift, held, |a| a.factorize())?
                .0,
        ),
    };
    Ok(factor.solve(&(-residual)))
}

/// A global contact step on the full system of the tangent `k` and the contact rows (see
/// [`crate::global_contact`]), from the forces `warm` with the candidates' weights `rho`: the
/// solution of its linearisation's contact problem to `exact`'s (tolerance, steps) where given
/// (see [`GlobalContactSolver::linearised_solution`]), else one semismooth step.
fn global_step<const D: usize>(
    global: &mut GlobalContactSolver,
    model: &Model<D>,
    k: SparseColMatRef<'_, usize, f64>,
    (rows, held): (&ContactRows, &[bool]),
    residual: &DVector<f64>,
    (warm, rho): (&DVector<f64>, &[f64]),
    exact: Option<(f64, usize)>,
) -> Result<GlobalStep, IncrementFailure> {
    match exact {
        Some(limits) => {
            global.linearised_solution(model, k, rows, residual, warm, rho, held, limits)
        }
        None => global.step(model, k, rows, residual, warm, rho, held),
    }
}

/// The round-off of each equation's residual at the iterate `x` of an increment from `x_n`:
/// that of its stiffness, `stiffness_roundoff`, and in a dynamic increment that of its inertia
/// `M (x - x_pred) / (beta h^2)` plus terms of the start, where the round-off of `x` reaches
/// the residual amplified by `1 / (beta h^2)`: on a very short increment that exceeds the
/// force tolerance (2e-5 of the forces on the spinning drum at h = 5e-8 s), so that Newton
/// could never converge without it.
fn force_roundoff(
    kind: IncrementKind,
    mass: &DVector<f64>,
    (x_n, x): (&DVector<f64>, &DVector<f64>),
    stiffness_roundoff: &DVector<f64>,
) -> DVector<f64> {
    match kind {
        IncrementKind::Static { .. } => stiffness_roundoff.clone(),
        IncrementKind::Dynamic { hht, h, .. } => {
            let factor = ROUNDOFF_ULPS * f64::EPSILON * hht.mass_factor(h);
            DVector::from_fn(x.len(), |i, _| {
                (factor * mass[i] * x[i].abs().max(x_n[i].abs())).max(stiffness_roundoff[i])
            })
        }
    }
}

/// The first iterate of an increment of `kind` from `start` (the start itself, or HHT's
/// predictor), with the `held` equations at their start values and the `prescribed` ones
/// (`(equation, value)`) at theirs; and which equations are prescribed (`moving`).
fn predictor(
    start: &State,
    kind: IncrementKind,
    (held, prescribed): (&[bool], &[(usize, f64)]),
) -> (DVector<f64>, Vec<bool>) {
    let mut x = match kind {
        IncrementKind::Static { .. } => start.x.clone(),
        IncrementKind::Dynamic { hht, h, .. } => hht.predict(h, &start.x, &start.v),
    };
    for (eq, &h) in held.iter().enumerate() {
        if h {
            x[eq] = start.x[eq];
        }
    }
    let mut moving = vec![false; x.len()];
    for &(eq, value) in prescribed {
        x[eq] = value;
        moving[eq] = true;
    }
    (x, moving)
}

/// The velocity and acceleration of the iterate `x` of an increment of `kind` from `start`:
/// the start's velocity and no acceleration in a static increment; Newmark's relations in a
/// dynamic one, the mean rates on `quasi_static` equations (see [`mean_rates`]), and a `held`
/// equation standing still unless it is `moving` (prescribed), which moves as Newmark's
/// relations give for its prescribed path.
fn rates(
    quasi_static: &[bool],
    start: &State,
    kind: IncrementKind,
    x: &DVector<f64>,
    (held, moving): (&[bool], &[bool]),
) -> (DVector<f64>, DVector<f64>) {
    match kind {
        IncrementKind::Static { .. } => (start.v.clone(), DVector::zeros(x.len())),
        IncrementKind::Dynamic { hht, h, .. } => {
            let (mut v, mut a) = hht.velocity_and_acceleration(h, &start.x, &start.v, &start.a, x);
            mean_rates(quasi_static, h, &start.x, x, &mut v, &mut a);
            for (eq, &h) in held.iter().enumerate() {
                if h && !moving[eq] {
                    v[eq] = 0.0;
                    a[eq] = 0.0;
                }
            }
            (v, a)
        }
    }
}

/// True if the last convergence check repeats the one two before it (both residuals within
/// 5 %): Newton alternating between two iterates.
fn is_cycling(residuals: &[(f64, f64)]) -> bool {
    let [.., (f0, c0), _, (f2, c2)] = residuals else {
        return false;
    };
    let repeats = |a: f64, b: f64| (a - b).abs() <= 0.05 * a.max(b);
    repeats(*f0, *f2) && repeats(*c0, *c2)
}

/// True if the last convergence check is not below half the one before it, each measured
/// against its tolerance (the larger of the two ratios): Newton is not converging.
fn is_stagnating(residuals: &[(f64, f64)], newton: &NewtonSettings) -> bool {
    let [.., before, last] = residuals else {
        return false;
    };
    let measure =
        |(f, c): &(f64, f64)| (f / newton.force_tolerance).max(c / newton.contact_tolerance);
    measure(last) > 0.5 * measure(before)
}

/// Semismooth steps on one linearisation before its contact problem is taken as solved.
const LINEARISED_MAX_STEPS: usize = 30;

/// A reduced step reuses the last factorization (a chord step) once the force residual is
/// within this factor of its tolerance. Measured on the drum's spin-downs, where the first
/// Newton step leaves a relative force residual of 1e-5 to 1e-4: the chord step takes it below
/// 1e-6 as often as the Newton step does (Newton iterations 3020 and 3024 on `3d-r3d4`, 2304
/// and 2312 on `3d-analytic`) with half the factorizations.
const CHORD_WITHIN: f64 = 1e3;

/// Newton iterations the global contact solve gets before the increment is handed to the
/// reduced one. Semismooth Newton without a line search can cycle between active sets: in the
/// static preload of the block-on-flat test it repeats a 4-cycle of force residuals
/// (7.5e-2, 7.5e-2, 7.5e-2, 2.2e-1) indefinitely; a converging increment needs 2 to 5.
const GLOBAL_MAX_ITERATIONS: usize = 12;

/// First mass shift of a quasi-static solid's dynamic tangent (see
/// [`Assembler::with_mass_shift`]), relative to the inertial term `M/(beta h^2)` its density would
/// give. Measured on `2d-analytic` with a quasi-static pad (indefinite without its contacts) at
/// 0.1 to 5 ms steps: 1e-6 converges every increment in about two iterations, 1e-3 takes 50 %
/// more iterations, 1e-2 and above fail at 0.1 ms (the shifted Newton step crawls).
const QUASI_STATIC_SHIFT: f64 = 1e-6;

/// The round-off of an equation's inertia term, in units of `eps M |x| / (beta h^2)`: the
/// rounding of `x`, of the predictor and of the differences that form the acceleration.
const ROUNDOFF_ULPS: f64 = 16.0;

/// How often one Newton step may be halved because its end folds an element, before the
/// increment fails (and is cut back).
const MAX_STEP_HALVINGS: usize = 4;

/// A residual of the tangent's rows in force units: the scaled rows of the solid (see
/// [`Factors::row_scale`]) divided by their factor again, except on `quasi_static` equations,
/// whose rows are measured as they are.
fn in_force_units(
    mut residual: DVector<f64>,
    row_scale: Option<(f64, &[bool])>,
    quasi_static: &[bool],
) -> DVector<f64> {
    if let Some((c, rows)) = row_scale {
        for (eq, _) in rows
            .iter()
            .enumerate()
            .filter(|(eq, s)| **s && !quasi_static[*eq])
        {
            residual[eq] /= c;
        }
    }
    residual
}

/// Where an iterate's larger residual, each against its tolerance, is worst: the owner of the
/// force residual's equation, or the contact residual's candidate.
fn worst_residual<const D: usize>(
    model: &Model<D>,
    newton: &NewtonSettings,
    (force_residual, force_worst): (f64, Option<usize>),
    (contact_residual, contact_worst): (f64, Option<usize>),
) -> Option<WorstResidual> {
    if force_residual / newton.force_tolerance >= contact_residual / newton.contact_tolerance {
        force_worst
            .and_then(|eq| model.dofs().owner(eq))
            .map(WorstResidual::Equation)
    } else {
        contact_worst.and_then(|c| candidate(model, c))
    }
}

/// `max_i |R_i| / s` with `s` the largest magnitude among the given force vectors, and the
/// equation `i` where it is reached (`None` without equations); moments are divided by the
/// model size so that both compare as forces. The forces include the loads at the start of
/// the increment, so that an increment that removes every load is judged against the loads it
/// removes rather than against forces that vanish with them. A residual within its round-off
/// `roundoff_i` counts as zero.
fn scaled_force_residual<const D: usize>(
    model: &Model<D>,
    residual: &DVector<f64>,
    forces: &[&DVector<f64>],
    roundoff: &DVector<f64>,
    length: f64,
) -> (f64, Option<usize>) {
    let kinds = model.dofs().kinds();
    let as_force = |i: usize, v: f64| match kinds[i] {
        EquationKind::Translation => v.abs(),
        EquationKind::Rotation => v.abs() / length,
    };
    let mut scale = 0.0_f64;
    for f in forces {
        for (i, &v) in f.iter().enumerate() {
            scale = scale.max(as_force(i, v));
        }
    }
    let (worst, at) = largest(residual.iter().zip(roundoff).enumerate().map(
        |(i, (&v, &floor))| {
            if v.abs() <= floor {
                0.0
            } else {
                as_force(i, v)
            }
        },
    ));
    (if scale > 0.0 { worst / scale } else { worst }, at)
}

/// The largest of `values` and its position (0 and `None` if empty; a NaN wins, so that it is
/// reported where it appeared).
fn largest(values: impl Iterator<Item = f64>) -> (f64, Option<usize>) {
    values.enumerate().fold((0.0, None), |(best, at), (i, v)| {
        if v > best || v.is_nan() && !best.is_nan() || at.is_none() {
            (v, Some(i))
        } else {
            (best, at)
        }
    })
}

/// The contact pair and slave node of candidate `c` (candidates numbered pair by pair).
fn candidate<const D: usize>(model: &Model<D>, c: usize) -> Option<WorstResidual> {
    let mut first = 0;
    for (pair, contact) in model.contacts().iter().enumerate() {
        if let Some(&node) = contact.nodes.get(c - first) {
            return Some(WorstResidual::Contact { pair, node });
        }
        first += contact.nodes.len();
    }
    None
}

/// The rates of quasi-static equations over an increment of size `h` from `x_n` to `x`: the
/// mean velocity `(x - x_n)/h` and no acceleration.
fn mean_rates(
    quasi_static: &[bool],
    h: f64,
    x_n: &DVector<f64>,
    x: &DVector<f64>,
    v: &mut DVector<f64>,
    a: &mut DVector<f64>,
) {
    for (eq, _) in quasi_static.iter().enumerate().filter(|(_, q)| **q) {
        v[eq] = (x[eq] - x_n[eq]) / h;
        a[eq] = 0.0;
    }
}

/// The converged iterate: unknowns, their rates, and the forces evaluated there.
struct Iterate {
    x: DVector<f64>,
    v: DVector<f64>,
    a: DVector<f64>,
    /// `f_int - f_ext`.
    net: DVector<f64>,
    f_ext: DVector<f64>,
    internal: InternalState,
    /// The residual `R_i` of each constrained equation without contact (zero elsewhere): what
    /// its constraint and the contact forces on it together balance.
    constrained: DVector<f64>,
    /// What each constraint adds: `R_i` less the contact forces on the equation, `(H^T r)_i`
    /// over every candidate.
    reaction: DVector<f64>,
    /// The equations that move as prescribed.
    moving: Vec<bool>,
}

/// Builds the converged state and updates the energy ledger.
fn finish<const D: usize>(
    model: &Model<D>,
    start: &State,
    kind: IncrementKind,
    iterate: Iterate,
    rows: &ContactRows,
    r: &DVector<f64>,
    warm_forces: DVector<f64>,
) -> State {
    let Iterate {
        x,
        v,
        a,
        net,
        f_ext,
        internal,
        constrained,
        reaction,
        moving,
    } = iterate;
    // The mean contact force over the increment and, for a dynamic increment, the velocity and
    // smooth acceleration with the contact impulse (see `crate::hht`); a prescribed
    // equation's reaction, and the contact forces on it, act as the contact forces do: an
    // impulse over the increment.
    let (r, reaction, constrained, v, a) = match kind {
        IncrementKind::Static { .. } => (r.clone(), reaction, constrained, v, a),
        IncrementKind::Dynamic { hht, h, .. } => {
            let mut impulse = rows.transpose_times(r, x.len());
            for (eq, _) in moving.iter().enumerate().filter(|(_, m)| **m) {
                impulse[eq] += constrained[eq];
            }
            let contact = model.acceleration_of(&impulse);
            let (mut v, mut a) = hht.split_impulse(h, &start.v, &start.a, &a, &contact);
            mean_rates(model.quasi_static(), h, &start.x, &x, &mut v, &mut a);
            let mean = hht.impulse_force_factor();
            (r * mean, reaction * mean, constrained * mean, v, a)
        }
    };
    let r = &r;
    let d = rows.components;
    let mut contacts = Vec::with_capacity(rows.len());
    let mut friction = 0.0;
    let mut normal_work = 0.0;
    for (k, old) in start.contacts.iter().enumerate() {
        let force = |c: usize| r.get(k * d + c).copied().unwrap_or(0.0);
        let slip = Vector2::from_fn(|c, _| {
            if c + 1 < d {
                rows.u[k * d + c + 1]
            } else {
                0.0
            }
        });
        let tangential = Vector2::from_fn(|c, _| if c + 1 < d { force(c + 1) } else { 0.0 });
        let gap = rows.u[k * d];
        // The work of the contact forces over the increment: in a dynamic increment `r` is the
        // mean force of the impulse; a static increment ramps the forces from `old` to `r`
        // along with the load, so the trapezoidal rule (as for the external work) keeps the
        // ledger's error of order 1/increments^2 rather than 1/increments.
        let (mean_tangential, mean_normal) = match kind {
            IncrementKind::Static { .. } => (
                0.5 * (tangential + old.tangential_force),
                0.5 * (force(0) + old.normal_force),
            ),
            IncrementKind::Dynamic { .. } => (tangential, force(0)),
        };
        friction -= mean_tangential.dot(&slip);
        normal_work += mean_normal * (gap - old.gap);
        contacts.push(ContactPointState {
            pair: old.pair,
            node: old.node,
            closest: rows.closest[k],
            gap,
            slip,
            normal_force: force(0),
            tangential_force: tangential,
        });
    }
    let (time, load_factor) = match kind {
        IncrementKind::Static { load_factor, .. } => (start.time, load_factor),
        IncrementKind::Dynamic { h, .. } => (start.time + h, 1.0),
    };
    let dx = &x - &start.x;
    let contact_reaction = rows.transpose_times(r, x.len());
    let moved: Vec<usize> = (0..x.len()).filter(|&eq| moving[eq]).collect();
    let reaction_work: f64 = moved
        .iter()
        .map(|&eq| {
            let mean = match kind {
                IncrementKind::Static { .. } => {
                    0.5 * (reaction[eq] + start.reaction.get(eq).copied().unwrap_or(0.0))
                }
                IncrementKind::Dynamic { .. } => reaction[eq],
            };
            mean * dx[eq]
        })
        .sum();
    let algorithmic = match kind {
        IncrementKind::Static { .. } => 0.0,
        IncrementKind::Dynamic { hht, h, .. } => {
            // the forces that act as impulses: the contacts', and all that the constraint of
            // a prescribed equation balances (its reaction and the contact forces on it)
            let mut impulse_forces = contact_reaction.clone();
            for &eq in &moved {
                impulse_forces[eq] += constrained[eq];
            }
            // the gyroscopic moments enter HHT's equations as the forces do (see the module
            // documentation), so they are part of the smooth forces here
            let (f0, f1) = match (
                model.gyroscopic_moments(&start.v),
                model.gyroscopic_moments(&v),
            ) {
                (Some(g0), Some(g1)) => (&start.net_force + g0, &net + g1),
                _ => (start.net_force.clone(), net.clone()),
            };
            hht.algorithmic_dissipation(
                h,
                &IncrementEnds {
                    mass: model.mass(),
                    quasi_static: model.quasi_static(),
                    dx: &dx,
                    f0: &f0,
                    f1: &f1,
                    a0: &start.a,
                    a1: &a,
                    contact: &impulse_forces,
                },
            )
        }
    };
    // the viscous forces' work by the trapezoidal rule, as the algorithmic dissipation takes
    // them among the smooth forces
    let damping = match start.damping_force.len() {
        0 => 0.5 * internal.damping_force.dot(&dx),
        _ => 0.5 * (&start.damping_force + &internal.damping_force).dot(&dx),
    };
    let energy = EnergyLedger {
        kinetic: 0.5 * v.component_mul(&v).dot(model.mass()),
        strain: internal.strain_energy,
        hourglass: internal.hourglass_energy,
        external_work: start.energy.external_work + 0.5 * (&start.external_force + &f_ext).dot(&dx),
        reaction_work: start.energy.reaction_work + reaction_work,
        friction_dissipation: start.energy.friction_dissipation + friction,
        normal_work: start.energy.normal_work + normal_work,
        algorithmic_dissipation: start.energy.algorithmic_dissipation + algorithmic,
        damping_dissipation: start.energy.damping_dissipation + damping,
    };
    let orientations = model.record_orientations(&start.orientations, &x);
    State {
        time,
        load_factor,
        orientations,
        contact_reaction,
        reaction,
        x,
        v,
        a,
        net_force: net,
        damping_force: internal.damping_force,
        external_force: f_ext,
        contacts,
        warm_forces,
        energy,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A check that repeats the one two before (both residuals within 5 %) is a cycle; a
    /// falling sequence or a single repeat of the one just before is not.
    #[test]
    fn a_residual_repeating_every_other_check_is_a_cycle() {
        let cycle = [(9.59e-3, 1.44e-3), (9.60e-3, 1.35e-3), (9.589e-3, 1.444e-3)];
        assert!(is_cycling(&cycle));
        let converging = [(1e-2, 1e-3), (1e-4, 1e-5), (1e-8, 1e-10)];
        assert!(!is_cycling(&converging));
        assert!(!is_cycling(&cycle[1..]));
        let force_only = [(9.59e-3, 1.44e-3), (9.60e-3, 1.35e-3), (9.589e-3, 1.0e-5)];
        assert!(!is_cycling(&force_only));
    }

    /// The worst residual is where the largest one is, or where a NaN first appeared.
    #[test]
    fn the_largest_residual_and_its_position() {
        assert_eq!(largest([0.5, 2.0, 1.0].into_iter()), (2.0, Some(1)));
        let (value, at) = largest([0.5, f64::NAN, 3.0, f64::NAN].into_iter());
        assert!(value.is_nan() && at == Some(1));
        assert_eq!(largest([0.0, 0.0].into_iter()), (0.0, Some(0)));
        assert_eq!(largest(std::iter::empty()), (0.0, None));
    }
}
