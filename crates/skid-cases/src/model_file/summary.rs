//! The summary of a model-file run (`summary.json`): how it ended, the final motions and
//! contact resultants, the energy balance, the contact accuracy and the cost.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};
use skid_integrator::{Model, RunError, RunStatistics};

use super::history::{BodyState, RunRecord};
use crate::peak_memory;

/// The cost of a run.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct RunCost {
    /// Equations (unknowns) of the model.
    pub equations: usize,
    /// Contact candidates (slave nodes over all pairs).
    pub contact_candidates: usize,
    /// Converged increments.
    pub increments: usize,
    /// Newton iterations.
    pub newton_iterations: usize,
    /// Conic (clarabel) solves.
    pub contact_solves: usize,
    /// De Saxce fixed-point iterations.
    pub fixed_point_iterations: usize,
    /// Semismooth Newton steps of the contact solves.
    pub contact_newton_steps: usize,
    /// Increments the global contact solve did not converge and the reduced one solved.
    pub contact_fallbacks: usize,
    /// Reduced increments that went on with global contact steps, their tangent without the
    /// contacts being indefinite.
    #[serde(default)]
    pub global_switches: usize,
    /// Cholesky factorizations of the effective tangent.
    pub tangent_factorizations: usize,
    /// LU factorizations of the global contact system.
    pub lu_factorizations: usize,
    /// Factorizations of its quasi-definite approximation (the GMRES preconditioner).
    pub preconditioner_factorizations: usize,
    /// GMRES iterations on the global contact system.
    pub krylov_iterations: usize,
    /// Failed attempts answered by a cutback.
    pub cutbacks: usize,
    /// Converged increments of adaptive steps taken again shorter for their local error.
    pub error_rejections: usize,
    /// The failed attempts by cause.
    pub cutback_causes: BTreeMap<String, usize>,
    /// Wall time of the run, s.
    pub wall_time_s: f64,
    /// Of which: element loop, loads and contact kinematics, s.
    pub assembly_s: f64,
    /// Of which: factorizations and solves, s.
    pub linear_solve_s: f64,
    /// Of `linear_solve_s`: the numeric factorizations of every kind, s.
    pub factorization_s: f64,
    /// Of which: the exact Coulomb solves of the reduced contact path, s.
    pub contact_solve_s: f64,
    /// Of which: history and field output and restart files, s.
    pub output_s: f64,
    /// The peak resident memory of the process when the run ended, MB (MiB; Linux, else
    /// `None`): the run's own where the process ran nothing before it, as `skid run` and each
    /// run of `skid bench`; in `skid batch`, whose jobs share the process, the batch's so far.
    #[serde(default)]
    pub peak_memory_mb: Option<f64>,
    /// The cost of each step reached, in order.
    pub steps: Vec<StepCost>,
}

/// The cost of one step of a run.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct StepCost {
    /// The step's name.
    pub step: String,
    /// Its converged increments.
    pub increments: usize,
    /// Their Newton iterations.
    pub newton_iterations: usize,
    /// Factorizations of every kind (tangent, LU, quasi-definite), all attempts.
    pub factorizations: usize,
    /// GMRES iterations, all attempts.
    pub krylov_iterations: usize,
    /// Wall time spent in the step (outputs of its increments included), s.
    pub wall_time_s: f64,
}

impl RunCost {
    /// Factorizations of every kind.
    pub fn factorizations(&self) -> usize {
        self.tangent_factorizations + self.lu_factorizations + self.preconditioner_factorizations
    }
}

/// The cost in a run's statistics, at the end of the run: the process's peak memory is read
/// when this is made.
impl From<&RunStatistics> for RunCost {
    fn from(stats: &RunStatistics) -> Self {
        Self {
            equations: stats.equations,
            contact_candidates: stats.contact_candidates,
            increments: stats.increments,
            newton_iterations: stats.newton_iterations,
            contact_solves: stats.contact_solves,
            fixed_point_iterations: stats.fixed_point_iterations,
            contact_newton_steps: stats.contact_newton_steps,
            contact_fallbacks: stats.contact_fallbacks,
            global_switches: stats.global_switches,
            tangent_factorizations: stats.solves.tangent_factorizations,
            lu_factorizations: stats.solves.lu_factorizations,
            preconditioner_factorizations: stats.solves.preconditioner_factorizations,
            krylov_iterations: stats.solves.krylov_iterations,
            cutbacks: stats.cutbacks,
            error_rejections: stats.error_rejections,
            cutback_causes: stats.cutback_causes.clone(),
            wall_time_s: stats.wall_time.as_secs_f64(),
            assembly_s: stats.timings.assembly.as_secs_f64(),
            linear_solve_s: stats.timings.linear_solve.as_secs_f64(),
            factorization_s: stats.timings.factorization.as_secs_f64(),
            contact_solve_s: stats.timings.contact_solve.as_secs_f64(),
            output_s: stats.timings.output.as_secs_f64(),
            peak_memory_mb: peak_memory::read().map(|bytes| bytes as f64 / peak_memory::MIB),
            steps: stats
                .steps
                .iter()
                .map(|s| StepCost {
                    step: s.name.clone(),
                    increments: s.increments,
                    newton_iterations: s.newton_iterations,
                    factorizations: s.solves.factorizations(),
                    krylov_iterations: s.solves.krylov_iterations,
                    wall_time_s: s.wall_time.as_secs_f64(),
                })
                .collect(),
        }
    }
}

/// A contact pair's resultants in the final state.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct PairSummary {
    /// Pair name.
    pub name: String,
    /// Sum of the normal forces, N.
    pub normal_force: f64,
    /// Sums of the friction force components along the surface coordinates, N.
    pub tangential_force: [f64; 2],
    /// Closed contacts.
    pub active: usize,
    /// Closed contacts at the friction cone's boundary.
    pub sliding: usize,
}

/// `summary.json` of a model-file run.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct ModelSummary {
    /// Model name.
    pub model: String,
    /// Spatial dimension.
    pub dimension: usize,
    /// `"completed"` or `"failed"`.
    pub status: String,
    /// Why the run stopped early, if it did.
    pub error: Option<String>,
    /// The kind of failure that stopped it, if it did ([`RunError::kind`]).
    pub failure: Option<String>,
    /// Time reached, s.
    pub final_time: f64,
    /// Rigid-body motions in the last converged state.
    pub bodies: Vec<BodyState>,
    /// Contact resultants in the last converged state.
    pub pairs: Vec<PairSummary>,
    /// Energy the run lost unaccounted for, J:
    /// `-(dE - dW_ext - dW_N + D_friction + D_algorithmic)` between the state the first
    /// dynamic step started from (the initial state if the run has no dynamic step) and the
    /// last state (`E` kinetic + strain + hourglass, `W_ext` the loads' work, `W_N` the normal
    /// contact forces' work, `D_algorithmic` what the time integration removed).
    pub energy_balance_residual_j: Option<f64>,
    /// Energy removed by the time integration itself over the same span, J (HHT's damping,
    /// the end-point equilibrium of quasi-static solids).
    pub algorithmic_dissipation_j: Option<f64>,
    /// `|residual| / scale` with the scale the largest energy, work or dissipation of the run;
    /// `None` if nothing in the run carries energy.
    pub energy_balance_error: Option<f64>,
    /// Deepest penetration over the run, m.
    pub max_gap_violation_m: f64,
    /// Largest gap at a contact carrying force while sliding, m.
    pub max_sliding_separation_m: f64,
    /// What a user should know before trusting a completed run (see [`dissipation_warning`]).
    pub warnings: Vec<String>,
    /// Cost of the run.
    #[serde(flatten)]
    pub cost: RunCost,
}

/// Share of the energy in play above which a summary warns that the time integration itself
/// removed it.
pub const DISSIPATION_WARNING_SHARE: f64 = 0.05;

/// The warning for a run whose time integration removed `dissipated` J, more than
/// [`DISSIPATION_WARNING_SHARE`] of the energy in play `scale`: the answer then depends on the
/// time step (the ledger still balances, so the solution is the scheme's, not a wrong one).
pub fn dissipation_warning(dissipated: f64, scale: f64) -> Option<String> {
    (scale > 0.0 && dissipated > DISSIPATION_WARNING_SHARE * scale).then(|| {
        format!(
            "the time integration removed {:.1} % of the energy in play ({dissipated:.4e} J of \
             {scale:.4e} J: HHT damping, or the end-point equilibrium of quasi-static solids); \
             the answer depends on the time step, take smaller increments",
            100.0 * dissipated / scale
        )
    })
}

/// Summarizes a run of `model` (named `name`) from its history record and statistics; `error` is why it
/// stopped early, if it did.
pub fn summarize<const D: usize>(
    name: &str,
    model: &Model<D>,
    record: &RunRecord,
    stats: &RunStatistics,
    error: Option<&RunError>,
) -> ModelSummary {
    // Over the dynamic steps if the run has any: a static step's states are equilibria (which
    // Newton checks), and its ledger integrates the work of loads ramped over its increments
    // by the trapezoidal rule, exact only as the increments shrink (seed 1 run 229 of the stress
    // sweep: one increment to 8.5 MPa left 33 % of the energy in play as quadrature error).
    let start = record
        .dynamic_start_energy
        .as_ref()
        .or(record.first_energy.as_ref());
    let ends = start.zip(record.last_energy.as_ref());
    let residual = ends.map(|(a, b)| b.unaccounted_since(a));
    let algorithmic = ends.map(|(a, b)| b.algorithmic_dissipation - a.algorithmic_dissipation);
    let scale = record.energy_scale;
    ModelSummary {
        model: name.to_string(),
        dimension: D,
        status: if error.is_none() {
            "completed"
        } else {
            "failed"
        }
        .into(),
        error: error.map(ToString::to_string),
        failure: error.map(|e| e.kind().to_string()),
        final_time: record.final_time,
        bodies: record.final_bodies.clone(),
        pairs: model
            .contacts()
            .iter()
            .zip(&record.final_pairs)
            .map(|(pair, t)| PairSummary {
                name: pair.name.clone(),
                normal_force: t.normal_force,
                tangential_force: t.tangential_force,
                active: t.active,
                sliding: t.sliding,
            })
            .collect(),
        energy_balance_residual_j: residual,
        algorithmic_dissipation_j: algorithmic,
        energy_balance_error: residual.filter(|_| scale > 0.0).map(|r| r.abs() / scale),
        warnings: algorithmic
            .and_then(|d| dissipation_warning(d, scale))
            .into_iter()
            .collect(),
        max_gap_violation_m: record.max_penetration.max(0.0),
        max_sliding_separation_m: record.max_sliding_separation,
        cost: RunCost::from(stats),
    }
}
