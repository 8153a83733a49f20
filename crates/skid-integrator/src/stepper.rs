//! Steps, increments and automatic cutback.
//!
//! A run is a sequence of steps. A static step ramps the loads linearly from their current
//! factor to 1 over its increments (pseudo-time, no physical time elapses); a dynamic step
//! advances time with HHT-alpha at full load. Loads with an amplitude follow it in the step
//! time instead (see [`crate::loads`]), and are taken again at each step's start. A failed increment (Newton, conic solve, inverted
//! element, ...) is retried with its size multiplied by the cutback factor; after a few
//! successes the size grows back to nominal. When the cutbacks are exhausted the run stops with
//! an error saying where and why; every increment converged before that has already been
//! reported to the [`Observer`].
//!
//! A dynamic step may choose its increments itself ([`Adaptive`]): each converged increment's
//! local error is estimated, an increment whose error exceeds the tolerance is taken again
//! shorter, and the next size follows from the error (see [`Adaptive`]); an increment also ends
//! where a spinning rigid body's angular velocity would reach zero (the stop of a braked drum).
//!
//! A run can be continued from a [`Checkpoint`]: the state after a converged increment with the
//! stepper's position in its step, the counters so far and what the solver carries from one
//! increment to the next. An observer asks for checkpoints ([`Observer::wants_checkpoint`]);
//! [`resume`] continues from one and reports the same increments, with the same bits, as the
//! uninterrupted run would have after it (at one factorization thread). Where checkpoints are
//! stored is the caller's business.

use std::time::{Duration, Instant};

use nalgebra::DVector;
use serde::{Deserialize, Serialize};

use crate::assembly::{Assembler, external_forces};
use crate::contact_rows::contact_rows;
use crate::cost::{SolveCounts, Timings};
use crate::dof::EquationKind;
use crate::error::{IncrementFailure, RunError};
use crate::global_contact::{GlobalContactSolver, GlobalSolverMemory};
use crate::hht::Hht;
use crate::increment::{IncrementCounters, IncrementKind, Rejection, Workspace, solve_increment};
use crate::loads::{LoadInstant, Variation};
use crate::model::Model;
use crate::motion::{BodyMotion, body_equation};
use crate::settings::Settings;
use crate::state::{ContactPointState, EnergyLedger, State};

/// What a step does.
#[derive(Clone, Debug, PartialEq)]
pub enum StepKind {
    /// Static equilibrium, loads ramped to full value over `increments`.
    Static {
        /// How the ramp is divided into increments.
        increments: StaticIncrements,
        /// Time scale `h_s` of the mass regularisation `M/h_s^2` of the Newton tangent, s.
        regularization_time: f64,
    },
    /// Implicit dynamics with HHT-alpha.
    Dynamic {
        /// Step duration, s.
        duration: f64,
        /// Nominal time increment, s (with `adaptive`, the first one).
        dt: f64,
        /// HHT alpha in [-1/3, 0].
        alpha: f64,
        /// Increments chosen by the local error (`None`: `dt` throughout, cut back on failure).
        adaptive: Option<Adaptive>,
    },
}

/// Newton iterations within which an increment of an automatic static step counts as easy.
pub const EASY_ITERATIONS: usize = 4;
/// Growth of an automatic static step's increment after two easy increments in a row.
pub const AUTOMATIC_GROWTH: f64 = 1.5;

/// How a static step divides its load ramp (its progress from 0 to 1) into increments.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StaticIncrements {
    /// `n` increments of `1/n`; a failed increment is cut back by the settings' factor (to at
    /// least `min_fraction / n`) and the size grows back to `1/n` after successes.
    Fixed(usize),
    /// Sizes chosen by Newton's effort, as fractions of the step: the first `initial`; after two
    /// increments in a row that converge within [`EASY_ITERATIONS`] Newton iterations the size
    /// grows by [`AUTOMATIC_GROWTH`], to at most `max`; a failed increment is cut back by the
    /// settings' factor, and the step fails rather than go below `min`. The last increment is
    /// shortened to end on the step's end.
    Automatic {
        /// First size, in `[min, max]`.
        initial: f64,
        /// Smallest size, `> 0`.
        min: f64,
        /// Largest size, `<= 1`.
        max: f64,
    },
}

/// Error-controlled increments of a dynamic step.
///
/// The local error of an HHT increment of size `h` is estimated as in Zienkiewicz & Xie
/// (1991), from the change of the mean acceleration `abar = (v_{n+1} - v_n)/h` (contact
/// impulses included) between successive increments:
/// `e = h^2 |beta - 1/6| (abar_{n+1} - abar_n)`. Its measure is
/// `eta = max_i |e_i| / (tolerance l_i)`, with `l_i` the model size for translations and
/// 1 rad for rotations, over the equations with inertia. A quasi-static solid's equations are
/// left out: their mean velocities jump where a pad rides over a faceted drum's corners
/// (counting them drove `2d-r2d2` to the smallest increment and a Newton failure at 5 ms), so
/// the estimate does not see the pad, and large increments over facets change the answer
/// (`3d-r3d4` at tolerance 1e-6: deceleration 605.9 against 605.1 at fixed 0.1 ms). An increment with `eta > 1` is taken again; the next size is
/// `h min(2, max(0.2, 0.9 eta^(-1/3)))`, within `[min_dt, max_dt]`. An increment at `min_dt`
/// is accepted whatever its error. The first increment of a step, with no earlier mean
/// acceleration, is accepted and the next one at most doubles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Adaptive {
    /// Local error tolerance, relative to the model size (translations) or 1 rad (rotations).
    pub tolerance: f64,
    /// Smallest increment, s.
    pub min_dt: f64,
    /// Largest increment, s.
    pub max_dt: f64,
}

impl Adaptive {
    /// `eta` of an increment of size `h` (see [`Adaptive`]); `mean_acceleration` and `previous`
    /// are `abar` of this increment and the one before.
    fn error_measure<const D: usize>(
        &self,
        model: &Model<D>,
        hht: &Hht,
        h: f64,
        mean_acceleration: &DVector<f64>,
        previous: &DVector<f64>,
        held: &[bool],
    ) -> f64 {
        let factor = h * h * (hht.beta - 1.0 / 6.0).abs();
        let kinds = model.dofs().kinds();
        let mut eta = 0.0_f64;
        for i in 0..mean_acceleration.len() {
            if held[i] || model.mass()[i] <= 0.0 {
                continue;
            }
            let scale = match kinds[i] {
                EquationKind::Translation => model.length_scale(),
                EquationKind::Rotation => 1.0,
            };
            let e = factor * (mean_acceleration[i] - previous[i]).abs();
            eta = eta.max(e / (self.tolerance * scale));
        }
        eta
    }

    /// The next increment's size after one of size `h` with error measure `eta`.
    fn next_size(&self, h: f64, eta: f64) -> f64 {
        let factor = if eta > 0.0 {
            (0.9 * eta.powf(-1.0 / 3.0)).clamp(0.2, 2.0)
        } else {
            2.0
        };
        (h * factor).clamp(self.min_dt, self.max_dt)
    }
}

/// An adaptive step's memory between increments.
struct AdaptiveRun {
    control: Adaptive,
    /// `abar` of the last accepted increment (none before the first).
    mean_acceleration: Option<DVector<f64>>,
    /// The rotations that have stopped in this step.
    stopped: Vec<bool>,
}

/// What an adaptive step makes of a converged increment.
enum Verdict {
    /// Take it again with this size, s.
    Retry(f64),
    /// Keep it; the next increment's size, s.
    Accept(f64),
}

impl AdaptiveRun {
    /// The memory of an adaptive step with `control`, as a checkpoint left it (`None`: at the
    /// step's start, over `n` equations).
    fn new(control: Adaptive, memory: Option<&AdaptiveMemory>, n: usize) -> Self {
        Self {
            control,
            mean_acceleration: memory
                .and_then(|m| m.mean_acceleration.as_ref())
                .map(|a| DVector::from_column_slice(a)),
            stopped: memory.map_or_else(|| vec![false; n], |m| m.stopped.clone()),
        }
    }

    /// This memory, for a checkpoint.
    fn memory(&self) -> AdaptiveMemory {
        AdaptiveMemory {
            mean_acceleration: self
                .mean_acceleration
                .as_ref()
                .map(|a| a.as_slice().to_vec()),
            stopped: self.stopped.clone(),
        }
    }

    /// Judges the converged increment of size `h` from `start` to `end` (see [`Adaptive`]): its
    /// error measure decides whether it is kept and the next size, which is then shortened to
    /// end where a spinning body would stop.
    fn judge<const D: usize>(
        &mut self,
        model: &Model<D>,
        hht: &Hht,
        h: f64,
        start: &State,
        end: &State,
        held: &[bool],
    ) -> Verdict {
        let control = self.control;
        let abar = (&end.v - &start.v) / h;
        let mut next = match &self.mean_acceleration {
            Some(previous) => {
                let eta = control.error_measure(model, hht, h, &abar, previous, held);
                if eta > 1.0 && h > control.min_dt * (1.0 + 1e-9) {
                    return Verdict::Retry(control.next_size(h, eta));
                }
                control.next_size(h, eta)
            }
            None => (2.0 * h).min(control.max_dt),
        };
        for (eq, stopped) in self.stopped.iter_mut().enumerate() {
            *stopped |= start.v[eq] * end.v[eq] <= 0.0 && start.v[eq] != 0.0;
        }
        if let Some(stop) = time_to_stop(model, &end.v, &abar, held, &self.stopped)
            && stop < next
            && stop > control.min_dt
        {
            next = stop;
        }
        self.mean_acceleration = Some(abar);
        Verdict::Accept(next)
    }
}

/// The time from the end of an increment until a spinning rigid body's angular velocity `v`,
/// changing at the mean rate `abar` of the increment, reaches zero: `-v / abar` where that is
/// positive; the soonest over the free, unheld rotations with inertia that have not stopped
/// yet in this step (`stopped`: the rocking after a stop is not a stop).
fn time_to_stop<const D: usize>(
    model: &Model<D>,
    v: &DVector<f64>,
    mean_acceleration: &DVector<f64>,
    held: &[bool],
    stopped: &[bool],
) -> Option<f64> {
    (0..model.bodies().len())
        .filter_map(|b| model.dofs().body_rotation(b))
        .filter(|&eq| !held[eq] && !stopped[eq] && model.mass()[eq] > 0.0)
        .filter(|&eq| v[eq] * mean_acceleration[eq] < 0.0)
        .map(|eq| -v[eq] / mean_acceleration[eq])
        .min_by(f64::total_cmp)
}

/// One analysis step.
#[derive(Clone, Debug, PartialEq)]
pub struct Step {
    /// Name used in outputs and messages.
    pub name: String,
    /// What the step does.
    pub kind: StepKind,
    /// Motions held at their value at the start of the step.
    pub held: Vec<HeldMotion>,
}

/// A motion held during a step at its value at the step's start: one motion of a rigid body
/// or every free motion of it, or one displacement of a node of the solid. Holding a motion
/// that the model already fixes changes nothing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HeldMotion {
    /// A motion of a rigid body's reference node.
    Body {
        /// Index of the rigid body.
        body: usize,
        /// The motion held; `None`: all the body's free motions.
        motion: Option<BodyMotion>,
    },
    /// The displacement of a node of the solid along a global axis.
    Node {
        /// Index of the node.
        node: usize,
        /// Global axis.
        axis: usize,
    },
}

impl HeldMotion {
    /// Holds every free motion of `body`.
    pub fn body(body: usize) -> Self {
        Self::Body { body, motion: None }
    }

    /// Equations this hold fixes (none for a motion the model already fixes).
    fn equations<const D: usize>(&self, model: &Model<D>) -> Vec<usize> {
        match *self {
            Self::Body { body, motion: None } => model.dofs().body_equations(body),
            // the angle of a body turning about one axis, or all the rotations of a body free
            // to turn (see `BodyMotion::Rotation`)
            Self::Body {
                body,
                motion: Some(BodyMotion::Rotation),
            } => model.dofs().body_rotations(body).to_vec(),
            Self::Body {
                body,
                motion: Some(motion),
            } => body_equation(model.dofs(), body, motion)
                .into_iter()
                .collect(),
            Self::Node { node, axis } => model.dofs().node(node)[axis].into_iter().collect(),
        }
    }
}

/// What the observer is told about a converged increment.
#[derive(Debug)]
pub struct IncrementReport<'a> {
    /// Step name (`"initial"` for the initial state).
    pub step: &'a str,
    /// Whether the step is dynamic.
    pub dynamic: bool,
    /// Increment number within the step (0 for the initial state).
    pub increment: usize,
    /// Size of the increment (time, or load-factor fraction for static steps).
    pub size: f64,
    /// Converged state.
    pub state: &'a State,
    /// Iteration counts of the increment.
    pub counters: &'a IncrementCounters,
}

/// A failed attempt at an increment, answered by a cutback or ending the step.
#[derive(Clone, Copy, Debug)]
pub struct RejectionReport<'a> {
    /// Step name.
    pub step: &'a str,
    /// Number the increment would have had within the step.
    pub increment: usize,
    /// Time at the end of the attempted increment (the start's in a static step), s.
    pub time: f64,
    /// Size of the attempted increment (time, or load-factor fraction for static steps).
    pub size: f64,
    /// Why it failed, and the residuals of its convergence checks.
    pub rejection: &'a Rejection,
}

/// Receives every converged increment (history and field output).
pub trait Observer<const D: usize> {
    /// Called once per converged increment, and once for the initial state.
    ///
    /// # Errors
    /// An I/O error stops the run.
    fn on_increment(
        &mut self,
        model: &Model<D>,
        report: &IncrementReport<'_>,
    ) -> std::io::Result<()>;

    /// Called once per failed attempt at an increment, before the cutback (or the end of the
    /// step); the default ignores it.
    ///
    /// # Errors
    /// An I/O error stops the run.
    fn on_rejection(
        &mut self,
        model: &Model<D>,
        report: &RejectionReport<'_>,
    ) -> std::io::Result<()> {
        let _ = (model, report);
        Ok(())
    }

    /// Whether to receive a [`Checkpoint`] of the run as it stands after the increment just
    /// reported (asked after every [`Self::on_increment`]); `boundary` is true for the initial
    /// state and the last increment of each step. A checkpoint copies the state, so the default
    /// asks for none.
    fn wants_checkpoint(&mut self, boundary: bool) -> bool {
        let _ = boundary;
        false
    }

    /// Receives the checkpoint [`Self::wants_checkpoint`] asked for.
    ///
    /// # Errors
    /// An I/O error stops the run.
    fn on_checkpoint(&mut self, model: &Model<D>, checkpoint: &Checkpoint) -> std::io::Result<()> {
        let _ = (model, checkpoint);
        Ok(())
    }
}

/// What the solver carries from one increment to the next that changes later results: a run
/// continued from a [`Checkpoint`] starts from it instead of from an empty workspace.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SolverMemory {
    /// Equations the tangent's factorization eliminates last (grown by the reduced contact
    /// step, see [`crate::sparse`]).
    pub trailing: Vec<usize>,
    /// The global contact system's last factorization.
    pub global: GlobalSolverMemory,
}

impl SolverMemory {
    /// The memory of `workspace`.
    fn of(workspace: &Workspace) -> Self {
        Self {
            trailing: workspace.assembler.trailing().to_vec(),
            global: workspace.global.memory(),
        }
    }
}

/// An adaptive step's memory in a [`Checkpoint`] (see [`Adaptive`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AdaptiveMemory {
    /// Mean acceleration `abar` of the last accepted increment, per equation (none before the
    /// first increment of the step).
    pub mean_acceleration: Option<Vec<f64>>,
    /// Per equation: whether its rotation has stopped in this step.
    pub stopped: Vec<bool>,
}

/// Where the stepper stands within a step after a converged increment.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StepPosition {
    /// Load factor at the start of the step.
    pub start_load_factor: f64,
    /// Time at the start of the step, s.
    pub start_time: f64,
    /// Fraction of the step done, in [0, 1].
    pub progress: f64,
    /// Size of the next increment, as a fraction of the step.
    pub size: f64,
    /// Successful increments since the last cutback or growth of the size (of an automatic
    /// static step, easy ones in a row).
    pub successes: usize,
    /// Converged increments of the step so far.
    pub increment: usize,
    /// An adaptive step's memory (`None` for a step of fixed increments).
    pub adaptive: Option<AdaptiveMemory>,
}

/// A run as it stands after a converged increment or at its initial state: everything
/// [`resume`] needs to continue it as the uninterrupted run continues.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Checkpoint {
    /// The converged state.
    pub state: State,
    /// Index of the current step.
    pub step: usize,
    /// Position within that step (`None`: it has not begun).
    pub position: Option<StepPosition>,
    /// Totals of the run so far (the wall times included).
    pub statistics: RunStatistics,
    /// What the solver carries into the next increment.
    pub solver: SolverMemory,
}

impl Checkpoint {
    /// Checks that this checkpoint belongs to a run of `model` over `steps`: sizes of every
    /// vector, the contact candidates, the step index, the position.
    ///
    /// # Errors
    /// [`RunError::Invalid`] saying what does not fit.
    pub fn check<const D: usize>(&self, model: &Model<D>, steps: &[Step]) -> Result<(), RunError> {
        let bad = |what: String| Err(RunError::Invalid(format!("checkpoint: {what}")));
        let n = model.dofs().len();
        let s = &self.state;
        for (name, v) in [
            ("x", &s.x),
            ("v", &s.v),
            ("a", &s.a),
            ("net_force", &s.net_force),
            ("external_force", &s.external_force),
            ("contact_reaction", &s.contact_reaction),
        ] {
            if v.len() != n {
                return bad(format!(
                    "state.{name} has {} entries, the model {n} equations",
                    v.len()
                ));
            }
        }
        let candidates: Vec<(usize, usize)> = model
            .contacts()
            .iter()
            .enumerate()
            .flat_map(|(p, pair)| pair.nodes.iter().map(move |&node| (p, node)))
            .collect();
        let held: Vec<(usize, usize)> = s.contacts.iter().map(|c| (c.pair, c.node)).collect();
        if held != candidates {
            return bad("the contact candidates are not the model's".into());
        }
        if s.warm_forces.len() != candidates.len() * D {
            return bad(format!(
                "{} warm-start forces for {} candidates in {D}D",
                s.warm_forces.len(),
                candidates.len()
            ));
        }
        if self.solver.trailing.iter().any(|&eq| eq >= n) {
            return bad("an equation eliminated last is not the model's".into());
        }
        if self.step > steps.len() || (self.step == steps.len() && self.position.is_some()) {
            return bad(format!(
                "step {} of a run of {} steps",
                self.step,
                steps.len()
            ));
        }
        let Some(position) = &self.position else {
            return Ok(());
        };
        let adaptive = matches!(
            steps[self.step].kind,
            StepKind::Dynamic {
                adaptive: Some(_),
                ..
            }
        );
        if !(position.progress.is_finite()
            && (0.0..=1.0 + 1e-9).contains(&position.progress)
            && position.size.is_finite()
            && position.size > 0.0)
        {
            return bad(format!(
                "progress {} and size {} of the step",
                position.progress, position.size
            ));
        }
        match (&position.adaptive, adaptive) {
            (None, false) => Ok(()),
            (Some(m), true)
                if m.stopped.len() == n
                    && m.mean_acceleration.as_ref().is_none_or(|a| a.len() == n) =>
            {
                Ok(())
            }
            _ => bad(format!(
                "the adaptive memory does not fit step '{}'",
                steps[self.step].name
            )),
        }
    }
}

/// Totals of a run.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RunStatistics {
    /// Equations (unknowns) of the model.
    pub equations: usize,
    /// Contact candidates (slave nodes over all pairs).
    pub contact_candidates: usize,
    /// Converged increments.
    pub increments: usize,
    /// Newton iterations of converged increments.
    pub newton_iterations: usize,
    /// Conic solves of converged increments.
    pub contact_solves: usize,
    /// De Saxce fixed-point iterations of converged increments.
    pub fixed_point_iterations: usize,
    /// Semismooth Newton steps of the contact solves of converged increments.
    pub contact_newton_steps: usize,
    /// Converged increments whose global contact solve failed and that the reduced one solved
    /// (see [`crate::increment::solve_increment`]).
    pub contact_fallbacks: usize,
    /// Converged reduced increments that went on with global contact steps where the tangent
    /// without the contacts was indefinite (see [`crate::increment::solve_increment`]).
    pub global_switches: usize,
    /// Failed attempts answered by a cutback.
    pub cutbacks: usize,
    /// Converged increments taken again shorter because their local error exceeded the
    /// tolerance of an adaptive step ([`Adaptive`]).
    pub error_rejections: usize,
    /// The failed attempts by kind of failure ([`IncrementFailure::kind`]).
    pub cutback_causes: std::collections::BTreeMap<String, usize>,
    /// Time spent in the parts of Newton (all attempts).
    pub timings: Timings,
    /// Factorizations and GMRES iterations (all attempts).
    #[serde(default)]
    pub solves: SolveCounts,
    /// Wall time of the whole run.
    pub wall_time: Duration,
    /// The part of each step reached, in order.
    #[serde(default)]
    pub steps: Vec<StepStatistics>,
}

/// The cost of one step of a run.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StepStatistics {
    /// The step's name.
    pub name: String,
    /// Its converged increments.
    pub increments: usize,
    /// Their Newton iterations.
    pub newton_iterations: usize,
    /// Factorizations and GMRES iterations (all attempts).
    pub solves: SolveCounts,
    /// Wall time spent in the step: every attempt, the outputs and restart files of its
    /// increments included.
    pub wall_time: Duration,
}

/// The state before the first step: undeformed, rigid bodies at their initial velocities,
/// loads at `load_factor`.
///
/// # Errors
/// If the contact projection or the loads cannot be evaluated on the initial geometry.
pub fn initial_state<const D: usize>(
    model: &Model<D>,
    load_factor: f64,
) -> Result<State, IncrementFailure> {
    let n = model.dofs().len();
    let x = DVector::zeros(n);
    let v = model.initial_velocity();
    let held = vec![false; n];
    let rows = contact_rows(model, &x, &[], None, None, &held)?;
    let d = rows.components;
    let contacts = model
        .contacts()
        .iter()
        .enumerate()
        .flat_map(|(p, pair)| pair.nodes.iter().map(move |&node| (p, node)))
        .enumerate()
        .map(|(k, (pair, node))| ContactPointState {
            pair,
            node,
            closest: rows.closest[k],
            gap: rows.u[k * d],
            slip: nalgebra::Vector2::zeros(),
            normal_force: 0.0,
            tangential_force: nalgebra::Vector2::zeros(),
        })
        .collect::<Vec<_>>();
    let f_ext = external_forces(
        model,
        &x,
        &[],
        LoadInstant {
            ramp: load_factor,
            step_time: 0.0,
            step: 0,
            fraction: 0.0,
        },
    )?;
    let energy = EnergyLedger {
        kinetic: 0.5 * v.component_mul(&v).dot(model.mass()),
        ..EnergyLedger::default()
    };
    Ok(State {
        time: 0.0,
        load_factor,
        x,
        v,
        a: DVector::zeros(n),
        net_force: -&f_ext,
        damping_force: DVector::zeros(n),
        contact_reaction: DVector::zeros(n),
        reaction: DVector::zeros(n),
        external_force: f_ext,
        warm_forces: DVector::zeros(contacts.len() * D),
        contacts,
        energy,
        orientations: model.record_orientations(&[], &DVector::zeros(n)),
    })
}

/// The loads at the start of `step` (step time 0, the ramp where the last step left it, 1 in a
/// dynamic step): an amplitude that restarts with the step, or a load's own variation in the
/// step, may change them from the end of the last step. The state's external force and `f_int - f_ext` take the new loads, so that the
/// step's first increment starts from them (its work by the trapezoidal rule, the HHT history
/// term); a load that does not change leaves the state untouched.
fn start_loads<const D: usize>(
    model: &Model<D>,
    (index, step): (usize, &Step),
    state: &mut State,
) -> Result<(), IncrementFailure> {
    let ramp = match step.kind {
        StepKind::Static { .. } => state.load_factor,
        StepKind::Dynamic { .. } => 1.0,
    };
    let instant = LoadInstant {
        ramp,
        step_time: 0.0,
        step: index,
        fraction: 0.0,
    };
    let f_ext = external_forces(model, &state.x, &state.orientations, instant)?;
    if f_ext != state.external_force {
        state.net_force += &state.external_force - &f_ext;
        state.external_force = f_ext;
    }
    Ok(())
}

/// Smooth acceleration at the start of a dynamic step, `a = -M^{-1} (f_int - f_ext + G(v))`
/// with the gyroscopic moments `G` of bodies free to turn: the contact forces act as impulses
/// and are never part of `a` (see [`crate::hht`]). Held and massless equations get zero.
fn consistent_acceleration<const D: usize>(
    model: &Model<D>,
    state: &State,
    held: &[bool],
) -> DVector<f64> {
    let mut force = state.net_force.clone();
    if let Some(gyroscopic) = model.gyroscopic_moments(&state.v) {
        force += gyroscopic;
    }
    let mut a = -model.acceleration_of(&force);
    for (a, _) in a.iter_mut().zip(held).filter(|(_, h)| **h) {
        *a = 0.0;
    }
    a
}

fn validate_steps<const D: usize>(model: &Model<D>, steps: &[Step]) -> Result<(), RunError> {
    let bad = |s: &Step, msg: String| Err(RunError::Invalid(format!("step '{}': {msg}", s.name)));
    let pressures = model.pressures().iter().map(|l| &l.variation).enumerate();
    let dead = model.dead_loads().iter().map(|l| &l.variation).enumerate();
    let motions = model
        .prescribed()
        .iter()
        .map(|(_, m)| &m.variation)
        .enumerate();
    let variations = pressures
        .map(|(i, v)| (format!("pressure load {i}"), v))
        .chain(dead.map(|(i, v)| (format!("concentrated or gravity load {i}"), v)))
        .chain(motions.map(|(i, v)| (format!("prescribed motion {i}"), v)));
    for (what, variation) in variations {
        if let Variation::PerStep(per_step) = variation
            && per_step.len() != steps.len()
        {
            return Err(RunError::Invalid(format!(
                "{what}: it varies in {} steps, the run has {}",
                per_step.len(),
                steps.len()
            )));
        }
    }
    for s in steps {
        for hold in &s.held {
            match *hold {
                HeldMotion::Body { body, motion } => {
                    if body >= model.bodies().len() {
                        return bad(s, format!("held body {body} does not exist"));
                    }
                    if let Some(BodyMotion::Translation(i)) = motion
                        && i >= D
                    {
                        return bad(s, format!("held translation along axis {i} in {D}D"));
                    }
                }
                HeldMotion::Node { node, axis } => {
                    if node >= model.part().mesh.nodes.len() || axis >= D {
                        return bad(
                            s,
                            format!("held node {node} along axis {axis}: no such node or axis"),
                        );
                    }
                    if model.ties().iter().any(|t| t.nodes.contains(&node)) {
                        return bad(
                            s,
                            format!("held node {node} is tied to a rigid body: hold the body"),
                        );
                    }
                }
            }
        }
        match s.kind {
            StepKind::Static {
                increments,
                regularization_time,
            } => {
                match increments {
                    StaticIncrements::Fixed(0) => {
                        return bad(s, "a static step needs at least one increment".into());
                    }
                    StaticIncrements::Fixed(_) => {}
                    StaticIncrements::Automatic { initial, min, max } => {
                        if !(min > 0.0 && min <= initial && initial <= max && max <= 1.0) {
                            return bad(
                                s,
                                format!(
                                    "automatic increments need 0 < min <= initial <= max <= 1, \
                                     got min {min}, initial {initial}, max {max}"
                                ),
                            );
                        }
                    }
                }
                if !(regularization_time.is_finite() && regularization_time > 0.0) {
                    return bad(
                        s,
                        format!("regularization time must be > 0, got {regularization_time}"),
                    );
                }
            }
            StepKind::Dynamic {
                duration,
                dt,
                alpha,
                adaptive,
            } => {
                if !(duration.is_finite() && duration > 0.0) {
                    return bad(s, format!("duration must be > 0, got {duration}"));
                }
                if !(dt.is_finite() && dt > 0.0 && dt <= duration) {
                    return bad(s, format!("dt must be in (0, duration], got {dt}"));
                }
                Hht::new(alpha).map_err(RunError::Invalid)?;
                if let Some(a) = adaptive {
                    if !(a.tolerance.is_finite() && a.tolerance > 0.0) {
                        return bad(s, format!("tolerance must be > 0, got {}", a.tolerance));
                    }
                    if !(a.min_dt.is_finite()
                        && a.min_dt > 0.0
                        && a.min_dt <= dt
                        && dt <= a.max_dt
                        && a.max_dt <= duration)
                    {
                        return bad(
                            s,
                            format!(
                                "expected 0 < min_dt <= dt <= max_dt <= duration, got {} <= {dt} \
                                 <= {} <= {duration}",
                                a.min_dt, a.max_dt
                            ),
                        );
                    }
                }
            }
        }
    }
    Ok(())
}

/// Runs the steps in order, reporting each converged increment to `observer`.
///
/// Returns the statistics in every case, with the final state or the error that stopped the run.
pub fn run<const D: usize>(
    model: &Model<D>,
    steps: &[Step],
    settings: &Settings,
    observer: &mut dyn Observer<D>,
) -> (RunStatistics, Result<State, RunError>) {
    run_from(model, steps, settings, observer, None)
}

/// Continues the run of `steps` from `checkpoint` (taken from a run of the same model, steps
/// and settings), reporting the increments after it to `observer` as the uninterrupted run
/// reports them; the initial state is not reported again. The statistics go on from the
/// checkpoint's (its wall time included).
///
/// Returns as [`run`]; a checkpoint that does not fit the model or the steps stops the run with
/// [`RunError::Invalid`].
pub fn resume<const D: usize>(
    model: &Model<D>,
    steps: &[Step],
    settings: &Settings,
    observer: &mut dyn Observer<D>,
    checkpoint: &Checkpoint,
) -> (RunStatistics, Result<State, RunError>) {
    run_from(model, steps, settings, observer, Some(checkpoint))
}

/// [`run`] from the start (`checkpoint` `None`) or [`resume`] from a checkpoint.
fn run_from<const D: usize>(
    model: &Model<D>,
    steps: &[Step],
    settings: &Settings,
    observer: &mut dyn Observer<D>,
    checkpoint: Option<&Checkpoint>,
) -> (RunStatistics, Result<State, RunError>) {
    let clock = Instant::now();
    let mut stats = match checkpoint {
        Some(c) => c.statistics.clone(),
        None => RunStatistics {
            equations: model.dofs().len(),
            contact_candidates: model.contacts().iter().map(|p| p.nodes.len()).sum(),
            ..RunStatistics::default()
        },
    };
    let earlier = stats.wall_time;
    let mut run = Run {
        model,
        settings,
        observer,
        clock,
        earlier,
    };
    let result = run.steps(steps, &mut stats, checkpoint);
    stats.wall_time = earlier + clock.elapsed();
    (stats, result)
}

/// A run in progress: what every increment uses, and the wall time so far.
struct Run<'a, const D: usize> {
    model: &'a Model<D>,
    settings: &'a Settings,
    observer: &'a mut dyn Observer<D>,
    /// Started when this process took up the run.
    clock: Instant,
    /// Wall time of the run before this process took it up.
    earlier: Duration,
}

impl<const D: usize> Run<'_, D> {
    /// Hands the observer the converged increment `report`; the time it takes is added to
    /// `output`.
    fn report(
        &mut self,
        report: &IncrementReport<'_>,
        output: &mut Duration,
    ) -> Result<(), RunError> {
        let clock = Instant::now();
        let written = self.observer.on_increment(self.model, report);
        *output += clock.elapsed();
        Ok(written?)
    }

    /// Hands the observer a checkpoint if it wants one after the increment just reported,
    /// made by `make` from the workspace; a checkpoint ends the reuse of the global solver's
    /// quasi-definite factors (see [`GlobalContactSolver::forget_preconditioner`]), so that the
    /// run goes on as one resumed from it would. Returns the time the observer took with it
    /// (the checkpoint's own statistics cannot hold that).
    fn offer_checkpoint(
        &mut self,
        boundary: bool,
        workspace: &mut Workspace,
        make: impl FnOnce(&Workspace) -> Checkpoint,
    ) -> Result<Duration, RunError> {
        let clock = Instant::now();
        if self.observer.wants_checkpoint(boundary) {
            let mut checkpoint = make(workspace);
            checkpoint.statistics.wall_time = self.earlier + self.clock.elapsed();
            self.observer.on_checkpoint(self.model, &checkpoint)?;
            workspace.global.forget_preconditioner();
        }
        Ok(clock.elapsed())
    }

    /// The steps from the start, or from `checkpoint`.
    fn steps(
        &mut self,
        steps: &[Step],
        stats: &mut RunStatistics,
        checkpoint: Option<&Checkpoint>,
    ) -> Result<State, RunError> {
        let model = self.model;
        validate_steps(model, steps)?;
        let mut assembler = Assembler::new(model).map_err(|e| RunError::Invalid(e.to_string()))?;
        let (mut state, first_step, mut position) = match checkpoint {
            Some(c) => {
                c.check(model, steps)?;
                (c.state.clone(), c.step, c.position.clone())
            }
            None => {
                let starts_static = matches!(
                    steps.first().map(|s| &s.kind),
                    Some(StepKind::Static { .. })
                );
                let fail_initial = |cause| RunError::StepFailed {
                    step: "initial".into(),
                    increment: 0,
                    time: 0.0,
                    size: 0.0,
                    cutbacks: 0,
                    cause,
                };
                let state = initial_state(model, if starts_static { 0.0 } else { 1.0 })
                    .map_err(fail_initial)?;
                (state, 0, None)
            }
        };
        let global = match checkpoint {
            Some(c) => {
                let invalid = |e: IncrementFailure| {
                    RunError::Invalid(format!("checkpoint: solver memory: {e}"))
                };
                assembler
                    .eliminate_last(&c.solver.trailing)
                    .map_err(invalid)?;
                GlobalContactSolver::restore(&c.solver.global).map_err(invalid)?
            }
            None => GlobalContactSolver::default(),
        };
        let mut workspace = Workspace { assembler, global };
        if checkpoint.is_none() {
            let none = IncrementCounters::default();
            self.report(
                &IncrementReport {
                    step: "initial",
                    dynamic: false,
                    increment: 0,
                    size: 0.0,
                    state: &state,
                    counters: &none,
                },
                &mut stats.timings.output,
            )?;
            stats.timings.output +=
                self.offer_checkpoint(true, &mut workspace, |workspace| Checkpoint {
                    state: state.clone(),
                    step: 0,
                    position: None,
                    statistics: stats.clone(),
                    solver: SolverMemory::of(workspace),
                })?;
        }
        for (index, step) in steps.iter().enumerate().skip(first_step) {
            let at = position.take();
            state = self.step(index, step, state, at, &mut workspace, stats)?;
        }
        Ok(state)
    }

    /// Step `index` from its start (`position` `None`, `state` the end of the previous step)
    /// or from `position` within it; returns the state at its end.
    fn step(
        &mut self,
        index: usize,
        step: &Step,
        mut state: State,
        position: Option<StepPosition>,
        workspace: &mut Workspace,
        stats: &mut RunStatistics,
    ) -> Result<State, RunError> {
        let model = self.model;
        let settings = self.settings;
        let n = model.dofs().len();
        let mut held = vec![false; n];
        for eq in step.held.iter().flat_map(|h| h.equations(model)) {
            held[eq] = true;
        }
        // a prescribed motion moves as prescribed, held by the step or not
        for (eq, _) in model.prescribed() {
            held[*eq] = true;
        }
        // an automatic static step's smallest and largest sizes
        let mut automatic = None;
        let (nominal, span, adaptive) = match step.kind {
            StepKind::Static {
                increments: StaticIncrements::Fixed(n),
                ..
            } => (1.0 / n as f64, 1.0, None),
            StepKind::Static {
                increments: StaticIncrements::Automatic { initial, min, max },
                ..
            } => {
                automatic = Some((min, max));
                (initial, 1.0, None)
            }
            StepKind::Dynamic {
                duration,
                dt,
                adaptive,
                ..
            } => (dt / duration, duration, adaptive),
        };
        if position.is_none() {
            start_loads(model, (index, step), &mut state).map_err(|cause| {
                RunError::StepFailed {
                    step: step.name.clone(),
                    increment: 0,
                    time: state.time,
                    size: 0.0,
                    cutbacks: 0,
                    cause,
                }
            })?;
            if matches!(step.kind, StepKind::Dynamic { .. }) {
                state.a = consistent_acceleration(model, &state, &held);
            }
        }
        // With adaptive increments the size may shrink to `min_dt`.
        let smallest = match (adaptive, automatic) {
            (Some(a), _) => a.min_dt / span,
            (None, Some((min, _))) => min,
            (None, None) => nominal * settings.cutback.min_fraction,
        };
        let memory = position.as_ref().and_then(|p| p.adaptive.as_ref());
        let mut adaptive = adaptive.map(|control| AdaptiveRun::new(control, memory, n));
        let StepPosition {
            start_load_factor: lambda0,
            start_time: t0,
            mut progress,
            mut size,
            mut successes,
            mut increment,
            ..
        } = position.unwrap_or(StepPosition {
            start_load_factor: state.load_factor,
            start_time: state.time,
            progress: 0.0,
            size: nominal,
            successes: 0,
            increment: 0,
            adaptive: None,
        });
        stats.steps.resize_with(index + 1, StepStatistics::default);
        stats.steps[index].name.clone_from(&step.name);
        let (spent, started) = (stats.steps[index].wall_time, Instant::now());
        let mut consecutive_failures = 0;
        while progress < 1.0 - 1e-12 {
            let dp = size.min(1.0 - progress);
            let kind = match step.kind {
                StepKind::Static {
                    regularization_time,
                    ..
                } => IncrementKind::Static {
                    load_factor: lambda0 + (1.0 - lambda0) * (progress + dp),
                    regularization: 1.0 / (regularization_time * regularization_time),
                    step_time: progress + dp,
                    step: index,
                },
                StepKind::Dynamic { alpha, .. } => IncrementKind::Dynamic {
                    hht: Hht::new(alpha).map_err(RunError::Invalid)?,
                    h: dp * span,
                    step_time: (progress + dp) * span,
                    step: index,
                    fraction: progress + dp,
                },
            };
            let instant = kind.loads();
            let prescribed: Vec<(usize, f64)> = model
                .prescribed()
                .iter()
                .map(|(eq, motion)| (*eq, motion.at(&instant)))
                .collect();
            let (before, factorizing) = (workspace.counts(), workspace.factorization_time());
            let solved = solve_increment(
                model,
                workspace,
                &state,
                kind,
                (&held, &prescribed),
                settings,
                &mut stats.timings,
            );
            stats.solves.add_between(&before, &workspace.counts());
            stats.timings.factorization += workspace.factorization_time() - factorizing;
            stats.steps[index]
                .solves
                .add_between(&before, &workspace.counts());
            match solved {
                Ok((mut next, counters)) => {
                    let mut next_size = None;
                    if let (Some(run), IncrementKind::Dynamic { hht, h, .. }) =
                        (&mut adaptive, kind)
                    {
                        match run.judge(model, &hht, h, &state, &next, &held) {
                            Verdict::Retry(h) => {
                                stats.error_rejections += 1;
                                size = h / span;
                                continue;
                            }
                            Verdict::Accept(h) => next_size = Some(h / span),
                        }
                    }
                    progress += dp;
                    increment += 1;
                    if let StepKind::Dynamic { .. } = step.kind {
                        // Land exactly on the step end despite round-off in the progress sum.
                        next.time = t0 + progress * span;
                    }
                    state = next;
                    stats.increments += 1;
                    stats.newton_iterations += counters.newton_iterations;
                    stats.contact_solves += counters.contact_solves;
                    stats.fixed_point_iterations += counters.fixed_point_iterations;
                    stats.contact_newton_steps += counters.contact_newton_steps;
                    stats.contact_fallbacks += counters.contact_fallbacks;
                    stats.global_switches += counters.global_switches;
                    let cost = &mut stats.steps[index];
                    cost.increments += 1;
                    cost.newton_iterations += counters.newton_iterations;
                    self.report(
                        &IncrementReport {
                            step: &step.name,
                            dynamic: matches!(step.kind, StepKind::Dynamic { .. }),
                            increment,
                            size: dp * span,
                            state: &state,
                            counters: &counters,
                        },
                        &mut stats.timings.output,
                    )?;
                    consecutive_failures = 0;
                    successes += 1;
                    if let Some(next) = next_size {
                        size = next;
                    } else if let Some((_, max)) = automatic {
                        if counters.newton_iterations > EASY_ITERATIONS {
                            successes = 0;
                        } else if successes >= 2 {
                            size = (size * AUTOMATIC_GROWTH).min(max);
                            successes = 0;
                        }
                    } else if size < nominal && successes >= settings.cutback.growth_after {
                        size = (size * settings.cutback.growth_factor).min(nominal);
                        successes = 0;
                    }
                    stats.steps[index].wall_time = spent + started.elapsed();
                    let output =
                        self.offer_checkpoint(progress >= 1.0 - 1e-12, workspace, |workspace| {
                            Checkpoint {
                                state: state.clone(),
                                step: index,
                                position: Some(StepPosition {
                                    start_load_factor: lambda0,
                                    start_time: t0,
                                    progress,
                                    size,
                                    successes,
                                    increment,
                                    adaptive: adaptive.as_ref().map(AdaptiveRun::memory),
                                }),
                                statistics: stats.clone(),
                                solver: SolverMemory::of(workspace),
                            }
                        })?;
                    stats.timings.output += output;
                }
                Err(rejection) => {
                    let clock = Instant::now();
                    let written = self.observer.on_rejection(
                        model,
                        &RejectionReport {
                            step: &step.name,
                            increment: increment + 1,
                            time: match step.kind {
                                StepKind::Static { .. } => state.time,
                                StepKind::Dynamic { .. } => t0 + (progress + dp) * span,
                            },
                            size: dp * span,
                            rejection: &rejection,
                        },
                    );
                    stats.timings.output += clock.elapsed();
                    written?;
                    let cause = rejection.failure;
                    stats.steps[index].wall_time = spent + started.elapsed();
                    stats.cutbacks += 1;
                    *stats
                        .cutback_causes
                        .entry(cause.kind().to_string())
                        .or_default() += 1;
                    consecutive_failures += 1;
                    successes = 0;
                    let cut = dp * settings.cutback.factor;
                    let exhausted = !cause.calls_for_cutback()
                        || match &adaptive {
                            // an adaptive step cuts back to its smallest increment, then gives up
                            Some(_) => dp <= smallest * (1.0 + 1e-9),
                            None => cut < smallest,
                        };
                    if consecutive_failures > settings.cutback.max_cutbacks || exhausted {
                        return Err(RunError::StepFailed {
                            step: step.name.clone(),
                            increment: increment + 1,
                            time: state.time,
                            size: dp * span,
                            cutbacks: consecutive_failures - 1,
                            cause,
                        });
                    }
                    size = cut.max(if adaptive.is_some() { smallest } else { 0.0 });
                }
            }
        }
        stats.steps[index].wall_time = spent + started.elapsed();
        Ok(state)
    }
}
