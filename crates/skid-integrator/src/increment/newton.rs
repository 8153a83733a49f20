//! An increment's Newton iterations: what they share ([`Increment`]), what they carry from
//! one to the next ([`Newton`]), and their stages: evaluate the iterate, check its
//! convergence, complete the tangent, and step (without contacts, reduced onto the contact
//! forces, or global).

use std::time::Instant;

use faer::sparse::SparseColMatRef;
use nalgebra::DVector;
use skid_contact::SurfacePoint;

use crate::assembly::{
    Assembler, Damping, InternalState, Solver, external_forces, is_not_factorized,
};
use crate::contact_rows::{ContactRows, RowStart, contact_rows};
use crate::cost::Timings;
use crate::coupling::contact_step;
use crate::error::{IncrementFailure, WorstResidual};
use crate::global_contact::{GlobalContactSolver, GlobalStep, contact_weights, law_residuals};
use crate::model::Model;
use crate::settings::{ContactSolve, NewtonSettings, Settings};
use crate::sparse::Factorization;
use crate::state::State;

use super::end_state::{Iterate, finish};
use super::residual::{
    Factors, ROUNDOFF_ULPS, force_roundoff, in_force_units, inertia_forces, largest, predictor,
    rates, residual_without_contact, scaled_force_residual, take_held, worst_residual,
};
use super::{IncrementCounters, IncrementKind};

/// What an increment's Newton iterations share and do not change.
pub(super) struct Increment<'a, const D: usize> {
    model: &'a Model<D>,
    start: &'a State,
    kind: IncrementKind,
    /// The constrained equations.
    held: &'a [bool],
    /// The equations that move as prescribed.
    moving: Vec<bool>,
    settings: &'a Settings,
    factors: Factors<'a>,
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
    /// `(equation, value)` of the prescribed ones), and its first iterate (see [`predictor`]);
    /// starts the assembler's mixed pressures.
    pub(super) fn new(
        model: &'a Model<D>,
        assembler: &mut Assembler,
        start: &'a State,
        kind: IncrementKind,
        (held, prescribed): (&'a [bool], &[(usize, f64)]),
        settings: &'a Settings,
    ) -> Result<(Self, DVector<f64>), IncrementFailure> {
        let row_start = match kind {
            IncrementKind::Static { .. } => None,
            IncrementKind::Dynamic { .. } => Some(RowStart::new(model, &start.x)),
        };
        let stiffness_roundoff = assembler.stiffness_scale() * (ROUNDOFF_ULPS * f64::EPSILON);
        let (predictor, moving) = predictor(start, kind, (held, prescribed));
        assembler.start_mixed_pressures(model, &start.x)?;
        let increment = Self {
            model,
            start,
            kind,
            held,
            moving,
            settings,
            factors: Factors::new(model, kind),
            row_start,
            previous: start.contacts.iter().map(|c| c.closest).collect(),
            start_gyroscopic: model.gyroscopic_moments(&start.v),
            stiffness_roundoff,
        };
        Ok((increment, predictor))
    }

    /// The contact rows at `x`, of the equations not `held` (every equation's with none).
    pub(super) fn contact_rows(
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
    pub(super) fn reactions(
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
    pub(super) fn mean_velocity(&self, x: &DVector<f64>) -> Option<DVector<f64>> {
        self.factors
            .damping_rate
            .map(|rate| (x - &self.start.x) * rate)
    }

    /// The stiffness damping at the mean velocity `velocity` (see [`Increment::mean_velocity`]).
    pub(super) fn damping<'v>(&self, velocity: Option<&'v DVector<f64>>) -> Option<Damping<'v>> {
        self.factors
            .damping_rate
            .zip(velocity)
            .map(|(rate, velocity)| Damping { velocity, rate })
    }
}

/// One iterate's forces, residual and contact rows.
pub(super) struct Evaluation {
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
pub(super) enum Check {
    Converged,
    NotConverged,
    /// The iterate went back half way (see [`Newton::check`]).
    Halved,
}

/// The state of an increment's Newton iterations.
pub(super) struct Newton {
    /// How the contact forces of a step are found.
    method: ContactSolve,
    /// Whether a reduced step may switch to global steps (see [`super::solve_increment`]).
    may_switch: bool,
    /// `c_M` and the first mass shift (see [`Factors`]); a static increment's first tangent
    /// may drop the regularisation.
    m_factor: f64,
    shift: (f64, f64),
    /// The iterate.
    pub(super) x: DVector<f64>,
    /// The contact forces a step starts from.
    warm: DVector<f64>,
    /// The contact forces of the last step and what the next iterate's contact state is
    /// checked against.
    pub(super) last: Option<LastForces>,
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
    /// The iterations of `increment` with the contact solve `method`, from its predictor `x`.
    pub(super) fn new<const D: usize>(
        increment: &Increment<'_, D>,
        x: DVector<f64>,
        (method, may_switch): (ContactSolve, bool),
    ) -> Self {
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

    /// Takes the Newton step `dx` (the mixed pressures with it).
    pub(super) fn advance<const D: usize>(
        &mut self,
        model: &Model<D>,
        assembler: &mut Assembler,
        dx: DVector<f64>,
    ) {
        assembler.advance_mixed_pressures(model, &dx);
        self.x += &dx;
        self.last_step = Some(dx);
        self.halvings = 0;
    }

    /// The iterate's forces, residual and contact rows; `None` if the last step folded an
    /// element and was halved instead.
    pub(super) fn evaluate<const D: usize>(
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
        let damping = increment.damping(mean_velocity.as_ref());
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
    pub(super) fn check<const D: usize>(
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
    pub(super) fn into_state<const D: usize>(
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
    pub(super) fn not_converged(
        &self,
        counters: &IncrementCounters,
        iterations: usize,
    ) -> IncrementFailure {
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
    pub(super) fn is_chord<const D: usize>(
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
    pub(super) fn complete_tangent<const D: usize>(
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
            let damping = increment.damping(mean_velocity.as_ref());
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
    pub(super) fn step<const D: usize>(
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

/// The contact forces of a Newton step and how the next iterate's contact state is judged.
pub(super) enum LastForces {
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
    pub(super) fn r(&self) -> &DVector<f64> {
        match self {
            Self::Linearised { r, .. } | Self::Law { r, .. } => r,
        }
    }

    /// The contact residual of the iterate whose contact rows are `rows`, in units of the model
    /// size `length`, and the candidate where it is largest (see the variants).
    pub(super) fn contact_residual(&self, rows: &ContactRows, length: f64) -> (f64, Option<usize>) {
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

/// How often one Newton step may be halved because its end folds an element, before the
/// increment fails (and is cut back).
pub(super) const MAX_STEP_HALVINGS: usize = 4;

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
}
