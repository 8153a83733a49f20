//! One Newton iteration of the contact-coupled problem in global form: the step of the unknowns
//! and the new contact forces from one sparse unsymmetric system, with no dense operator on the
//! contact set.
//!
//! The increment solves, for the unknowns `x` and the contact forces `r` (`dim` per candidate),
//!
//! `R(x) - H(x)^T r = 0`,  `Phi_c(u_c(x), r_c) = 0` for every candidate `c`,
//!
//! with `R` the residual without contact, `u_c` the candidate's gap and slip and `Phi_c` the
//! Alart–Curnier function of the exact Coulomb law ([`skid_contact::coulomb::alart_curnier`]).
//! Semismooth Newton at `(x, r)` with the generalized derivatives `Phi_u`, `Phi_r` of every
//! candidate's branch gives, for the step `dx` and the change of the forces `dr`
//! (new forces `r' = r + dr`),
//!
//! ```text
//! [ K          -H^T  ] [dx]   [ -(R - H^T r) ]
//! [ Phi_u H    Phi_r ] [dr] = [ -Phi         ]
//! ```
//!
//! where `K` is the effective tangent with the curvature stiffness of the forces `r` (see
//! [`crate::contact_rows::ContactRows::curvature_stiffness`]), so that the first block row is the
//! exact linearisation of `R - H^T r`. An open candidate has `Phi_r = I`, `Phi_u = 0` (its new
//! force is zero), a sticking one `H_c dx = -u_c`, a sliding one `u_N = 0` with its friction on
//! the cone's edge (its tangential rows balanced by `T = d d^T + P / f`, see
//! [`LocalLaw::with_balanced_slide_rows`], which leaves the step unchanged and makes the rows
//! across the sliding direction symmetric with the force columns). Nothing requires `K` to be positive definite, and sliding rows make the
//! matrix unsymmetric.
//!
//! The right-hand side is the Newton residual itself, so it shrinks as Newton converges. A
//! system solved on the factors of an earlier, nearby one (small systems, see below) is solved
//! to round-off ([`KRYLOV_TOLERANCE`]); a large one, preconditioned by an approximation, only to
//! a fixed fraction [`INEXACT_TOLERANCE`] of it (an inexact Newton method: the error of the
//! step is that fraction of a residual that is itself converging, so Newton's iteration count
//! does not change, and the increment's convergence is still judged on the true residuals;
//! but the converged state then balances its forces to the force tolerance, not to round-off).
//! Each system is solved, in this order,
//! - by GMRES on the LU factors of an earlier system, while they serve;
//! - from [`QUASI_DEFINITE_FROM`] equations, by GMRES preconditioned with the `L D L^T`
//!   factors of the quasi-definite approximation `S` of [`crate::quasi_definite`] (in the
//!   nested-dissection order of [`crate::ordering`]; single-precision factors, see
//!   [`crate::quasi_definite::Precision`]): first those of an earlier system, where
//!   that is expected to cost fewer iterations than a factorization of this one's (the
//!   tangent changes little from one iteration or increment to the next, but every candidate
//!   that changed branch since adds iterations, see [`GlobalContactSolver::reuse_budget`]),
//!   then those of this system's `S`;
//! - by a new sparse LU factorization with partial pivoting, below [`LU_UNTIL`] unknowns
//!   (above, the GMRES on this system's factors gets more iterations instead).
//!
//! An iterative result counts only if its true residual is below its tolerance. Then each
//! sliding candidate's tangential rows are solved exactly for its friction (see
//! [`exact_friction_rows`]), so that friction is `mu` times the normal force to Newton's
//! convergence, not to GMRES's tolerance.
//!
//! Each candidate's forces enter scaled by its weight `rho_c`, the unknown being
//! `dy_c = dr_c / rho_c` (a length), so that every block of the matrix is a stiffness and the
//! pivoting compares like with like. `rho_c` is the inverse of the diagonal approximation
//! `sum_j H_kj^2 / K_jj` of the candidate's compliance (averaged over its rows).
//!
//! GMRES applies the matrix as an operator ([`system`]: `K` from its lower triangle, each
//! candidate's rows from its own block), so that the explicit matrix is formed only for an LU
//! factorization. The pattern of the explicit matrix and of `S` only depends on which
//! equations each candidate involves, so their symbolic analyses (ordering and elimination
//! structure) are computed once and reused for as long as that does not change.

use std::sync::Arc;
use std::time::{Duration, Instant};

use faer::Conj;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::lu::{
    LuRef, LuSymbolicParams, NumericLu, SymbolicLu, factorize_symbolic_lu,
};
use faer::sparse::{Argsort, Pair, SparseColMat, SparseColMatRef, SymbolicSparseColMat};
use nalgebra::DVector;
use serde::{Deserialize, Serialize};
use skid_contact::coulomb::alart_curnier::{LocalBranch, LocalLaw};

use crate::contact_rows::ContactRows;
use crate::cost::SolveCounts;
use crate::error::{IncrementFailure, LinearFailure};
use crate::krylov::{self, gmres};
use crate::model::Model;
use crate::ordering::global_system_order;
use crate::quasi_definite::{Precision, QuasiDefinite};
use crate::sparse::{column_mut, diagonal, symmetric_times};
use system::{Approximation, LinearSystem};

mod system;

/// The system this module's failures name.
const SYSTEM: &str = "global contact system";

/// Relative residual `||b - A z|| / ||b||` to which a system is solved by GMRES on the LU
/// factors of an earlier system: far below what Newton's quadratic convergence needs.
const KRYLOV_TOLERANCE: f64 = 1e-12;
/// Relative residual `||b - A z|| / ||b||` to which a system is solved by GMRES on the
/// quasi-definite preconditioner, `b` being the Newton residual. Measured on
/// `3d-refined` (2 ms of spin-down, 77 systems, one factorization per system): 1e-12 takes 15.4
/// GMRES iterations per system, 1e-6 8.0 and 1e-4 5.7, all with the same Newton iterations (77,
/// 76, 78) and histories equal to 2e-8 relative; over 4 ms with factors reused, 1e-6 took 9.5
/// iterations per system and 1e-4 7.0, with 123 and 124 Newton iterations.
const INEXACT_TOLERANCE: f64 = 1e-4;
/// Halvings of a step of [`GlobalContactSolver::linearised_solution`] in its line search.
const LINE_SEARCH_HALVINGS: usize = 10;
/// GMRES iterations on an earlier factorization before the next preconditioner is tried.
const KRYLOV_MAX_ITERATIONS: usize = 8;
/// Systems of at least this many equations try the quasi-definite preconditioner before an LU
/// factorization. Measured on the 3D analytical drum (2 ms of spin-down, release): at 1,577
/// equations (pad 20 x 4 x 4) the LU alone is faster (1.01 s against 1.10 s), at 3,077
/// (40 x 4 x 4) the preconditioner is (2.31 s against 3.96 s); at 9,965 (40 x 8 x 8) a dynamic
/// iteration takes 0.10-0.15 s with it against 0.55-0.75 s for the LU.
pub const QUASI_DEFINITE_FROM: usize = 2000;
/// GMRES iterations on the quasi-definite preconditioner of this system's `S` before the
/// matrix is factorized.
const QUASI_DEFINITE_MAX_ITERATIONS: usize = 30;
/// Systems of this many unknowns or more are never LU-factorized: the LU's fill (its column
/// ordering comes from `A^T A`) grows faster than the machine's memory (measured peak resident
/// memory of a short run of the 3D pad, the LU taken in the static preload: 1.8 GB at 21,000
/// unknowns, 8.2 GB at 54,000, 20.7 GB at 108,000). GMRES on this system's quasi-definite
/// factors gets [`WITHOUT_LU_MAX_ITERATIONS`] instead, and a system it does not solve fails
/// the Newton iteration (the increment is then solved by the reduced path, or cut back). Nor
/// does the LU pay where it fits: at 49,574 unknowns (pad 80 x 12 x 16 on the analytical drum,
/// one thread) a dynamic increment takes 0.92 s either way, and the static preload 205 s with
/// four LU factorizations against 56 s without (two of its increments on the reduced path).
const LU_UNTIL: usize = 20_000;
/// GMRES iterations on the quasi-definite preconditioner of this system's `S` for systems that
/// are not LU-factorized.
const WITHOUT_LU_MAX_ITERATIONS: usize = 200;
/// GMRES iterations on the quasi-definite factors of an earlier system beyond those of the
/// factorized system, with no candidate changing branch (see
/// [`GlobalContactSolver::reuse_budget`]); measured on `3d-refined`: 11-13 against 7-8.
const REUSE_EXTRA_ITERATIONS: f64 = 5.0;
/// Further GMRES iterations per candidate that changed branch; measured on `3d-refined`: 16-20
/// with 2 changed, 17-25 with 4, 27-30 with 6.
const REUSE_ITERATIONS_PER_SWITCH: f64 = 5.0;
/// Earlier factors are reused if the iterations they are expected to cost in addition are at
/// most this share of a factorization's cost.
const REUSE_SHARE: f64 = 0.8;
/// The most GMRES iterations earlier factors get.
const REUSE_MAX_ITERATIONS: usize = 60;

/// A candidate's branch of the Alart–Curnier function as a number: 0 open, 1 frictionless,
/// 2 stick, 3 slide.
fn branch_code(branch: LocalBranch) -> u8 {
    match branch {
        LocalBranch::Open => 0,
        LocalBranch::Frictionless => 1,
        LocalBranch::Stick => 2,
        LocalBranch::Slide => 3,
    }
}

/// The symbolic analysis of the last pattern, kept while the pattern stays the same.
#[derive(Debug)]
struct Analysed {
    pairs: Vec<Pair<usize, usize>>,
    symbolic: SymbolicSparseColMat<usize>,
    argsort: Argsort<usize>,
    lu: Arc<SymbolicLu<usize>>,
}

/// A numeric LU factorization of an earlier matrix of the current pattern, applied as `A^{-1}`.
#[derive(Debug)]
struct Factors {
    symbolic: Arc<SymbolicLu<usize>>,
    numeric: NumericLu<usize, f64>,
}

impl Factors {
    /// The dimension of the factorized matrix.
    fn dim(&self) -> usize {
        self.symbolic.nrows()
    }

    /// Writes `A^{-1} b` into `out`.
    fn solve(&self, b: &DVector<f64>, out: &mut DVector<f64>) {
        let par = faer::get_global_parallelism();
        let mut scratch = MemBuffer::new(self.symbolic.solve_in_place_scratch::<f64>(1, par));
        out.copy_from(b);
        LuRef::new_unchecked(&self.symbolic, &self.numeric).solve_in_place_with_conj(
            Conj::No,
            column_mut(out),
            par,
            MemStack::new(&mut scratch),
        );
    }
}

/// GMRES on `matrix z = rhs` with the preconditioner `m_inv` and at most `max_iterations`;
/// `Some((z, iterations))` only if the true residual `||rhs - matrix z||` is below
/// `tolerance ||rhs||` (GMRES's own estimate is not trusted alone). The iterations taken (all
/// `max_iterations` if it fails) are added to `count`.
fn checked_gmres(
    system: &LinearSystem<'_>,
    rhs: &DVector<f64>,
    m_inv: impl FnMut(&DVector<f64>, &mut DVector<f64>),
    (tolerance, max_iterations): (f64, usize),
    (count, workspace): (&mut usize, &mut krylov::Workspace),
) -> Option<(DVector<f64>, usize)> {
    let apply = |x: &DVector<f64>, out: &mut DVector<f64>| system.apply(x, out);
    let limits = (0.1 * tolerance, max_iterations);
    let Some((z, iterations)) = gmres(apply, m_inv, rhs, limits, workspace) else {
        *count += max_iterations;
        return None;
    };
    *count += iterations;
    let mut residual = DVector::zeros(rhs.len());
    system.apply(&z, &mut residual);
    residual -= rhs;
    (residual.norm() <= tolerance * rhs.norm()).then_some((z, iterations))
}

/// The global contact step, with what it reuses across Newton iterations and increments: the
/// symbolic analysis of the pattern, the last LU factors and the quasi-definite preconditioner
/// (see [`GlobalContactSolver::step`] for the order in which they are tried).
#[derive(Debug)]
pub struct GlobalContactSolver {
    /// Systems of at least this many equations are preconditioned by the quasi-definite
    /// approximation ([`QUASI_DEFINITE_FROM`] unless set otherwise).
    pub quasi_definite_from: usize,
    /// Systems of at least this many equations are never LU-factorized ([`LU_UNTIL`] unless set
    /// otherwise).
    pub lu_until: usize,
    analysed: Option<Analysed>,
    factors: Option<Factors>,
    /// The compressed values of the matrix `factors` factorize (of the analysed pattern): what
    /// [`GlobalContactSolver::restore`] factorizes again to continue a run exactly.
    factored_values: Option<Vec<f64>>,
    /// The last GMRES on `factors` failed: skip them until the next factorization.
    factors_stale: bool,
    /// The quasi-definite preconditioner, factorized for an earlier system or this one.
    quasi_definite: QuasiDefinite,
    /// GMRES's vectors, kept from one solve to the next.
    krylov: krylov::Workspace,
    /// The pattern of the quasi-definite approximations, kept while systems share it.
    approximation: Approximation,
    /// The precision of the quasi-definite factors (see
    /// [`GlobalContactSolver::iterate_quasi_definite`]).
    precision: Precision,
    /// The candidates' branches (see [`branch_code`]) of the `S` that `quasi_definite`
    /// factorizes, if it serves as a preconditioner.
    preconditioner_branches: Option<Vec<u8>>,
    /// GMRES iterations of the system `quasi_definite` was factorized for.
    fresh_iterations: usize,
    /// The elimination order of `S` ([`crate::ordering::global_system_order`]), computed for
    /// the first system that uses it.
    order: Option<Vec<usize>>,
    /// Symbolic analyses performed.
    pub analyses: usize,
    /// Its factorizations and GMRES iterations so far (the tangent's factorizations are the
    /// assembler's).
    pub counts: SolveCounts,
    /// The wall time of its numeric factorizations so far.
    pub factorization_time: Duration,
}

impl Default for GlobalContactSolver {
    fn default() -> Self {
        Self {
            quasi_definite_from: QUASI_DEFINITE_FROM,
            lu_until: LU_UNTIL,
            analysed: None,
            factors: None,
            factored_values: None,
            factors_stale: false,
            quasi_definite: QuasiDefinite::default(),
            krylov: krylov::Workspace::default(),
            approximation: Approximation::default(),
            precision: Precision::Single,
            preconditioner_branches: None,
            fresh_iterations: 0,
            order: None,
            analyses: 0,
            counts: SolveCounts::default(),
            factorization_time: Duration::ZERO,
        }
    }
}

/// What a [`GlobalContactSolver`] carries from one increment to the next and that changes its
/// results: the last LU factorization, while it still preconditions GMRES on later systems
/// (factors that have stopped serving are not tried again before the next factorization, so
/// they are left out). Rebuilt from the matrix it factorized, the factors are the same bits
/// (the factorization is deterministic at one thread), so a run continued from a checkpoint
/// takes the same path. The quasi-definite factors are not carried: a checkpoint ends their
/// reuse (see [`GlobalContactSolver::forget_preconditioner`]), since on a system of 1e5
/// equations its matrix alone would make a restart file of 130 MB.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct GlobalSolverMemory {
    /// The factorized matrix, if any: its dimension, the entries `(row, column)` of its pattern
    /// as assembled (duplicates included, in order) and its compressed values.
    pub factored: Option<FactoredMatrix>,
}

/// A matrix of the global contact system that was factorized (see [`GlobalSolverMemory`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FactoredMatrix {
    /// Number of rows and columns.
    pub dim: usize,
    /// Entries `(row, column)` as assembled, duplicates included.
    pub entries: Vec<(usize, usize)>,
    /// Values of the compressed (duplicates summed) matrix, column by column.
    pub values: Vec<f64>,
}

/// The result of [`GlobalContactSolver::step`].
#[derive(Clone, Debug)]
pub struct GlobalStep {
    /// Step of the unknowns.
    pub dx: DVector<f64>,
    /// New contact forces `r'` (one per contact row).
    pub r: DVector<f64>,
}

impl GlobalContactSolver {
    /// What this solver carries into the next increment (see [`GlobalSolverMemory`]).
    pub fn memory(&self) -> GlobalSolverMemory {
        let factored = self
            .analysed
            .as_ref()
            .zip(self.factored_values.as_ref())
            .filter(|_| self.factors.is_some() && !self.factors_stale)
            .map(|(analysed, values)| FactoredMatrix {
                dim: analysed.symbolic.nrows(),
                entries: analysed.pairs.iter().map(|p| (p.row, p.col)).collect(),
                values: values.clone(),
            });
        GlobalSolverMemory { factored }
    }

    /// Ends the reuse of the quasi-definite factors: the next system factorizes its own `S`.
    /// Called at every checkpoint, so that a run continued from it and the run that goes on
    /// take the same path without the checkpoint holding those factors.
    pub fn forget_preconditioner(&mut self) {
        self.preconditioner_branches = None;
    }

    /// A solver in the state `memory` describes: the pattern analysed and the matrix
    /// factorized again.
    ///
    /// # Errors
    /// [`IncrementFailure::LinearSolve`] if the entries do not form a pattern of `dim` rows,
    /// the values do not fit it, or the factorization fails.
    pub fn restore(memory: &GlobalSolverMemory) -> Result<Self, IncrementFailure> {
        let mut solver = Self::default();
        if let Some(m) = &memory.factored {
            if m.entries.iter().any(|&(i, j)| i >= m.dim || j >= m.dim) {
                return Err(IncrementFailure::linear(
                    SYSTEM,
                    LinearFailure::Structure("restored entries outside the matrix".into()),
                ));
            }
            let pairs = m.entries.iter().map(|&(i, j)| Pair::new(i, j)).collect();
            let zeros = vec![0.0; m.entries.len()];
            solver.assemble(m.dim, pairs, &zeros)?;
            let symbolic = solver
                .analysed
                .as_ref()
                .map(|a| a.symbolic.clone())
                .ok_or_else(|| {
                    IncrementFailure::linear(SYSTEM, LinearFailure::Structure("no pattern".into()))
                })?;
            if symbolic.row_idx().len() != m.values.len() {
                return Err(IncrementFailure::linear(
                    SYSTEM,
                    LinearFailure::Structure(format!(
                        "restored matrix has {} values for {} entries",
                        m.values.len(),
                        symbolic.row_idx().len()
                    )),
                ));
            }
            if m.values.iter().any(|v| !v.is_finite()) {
                return Err(IncrementFailure::linear(SYSTEM, LinearFailure::NonFinite));
            }
            let matrix = SparseColMat::new(symbolic, m.values.clone());
            solver.factorize(matrix.as_ref())?;
        }
        Ok(solver)
    }

    /// Solves the linearised system of the module documentation at the current iterate: `k` is
    /// the lower triangle of the effective tangent (with the contact curvature of `r` and the
    /// held equations replaced by identity rows), `rows` the contact rows at the iterate,
    /// `residual` the residual without contact (zero on held equations), `r` the current
    /// forces and `rho` the candidates' weights (see [`contact_weights`]).
    ///
    /// # Errors
    /// [`IncrementFailure::LinearSolve`] if the system is singular or not finite.
    #[allow(clippy::too_many_arguments)] // the data of one Newton iteration, each used once
    pub fn step<const D: usize>(
        &mut self,
        model: &Model<D>,
        k: SparseColMatRef<'_, usize, f64>,
        rows: &ContactRows,
        residual: &DVector<f64>,
        r: &DVector<f64>,
        rho: &[f64],
        held: &[bool],
    ) -> Result<GlobalStep, IncrementFailure> {
        let n = residual.len();
        let d = rows.components;
        let m = rows.rows.len();
        let system = LinearSystem::new(model, k, rows, r, rho, held);
        let rhs = system.right_hand_side(residual, r);
        let mut solution = self.solve_system(model, &system, &rhs)?;
        for (c, law) in system.sliding() {
            exact_friction_rows(law, rows, rho[c], c, n, &mut solution);
        }
        let dx = DVector::from_fn(n, |i, _| solution[i]);
        // An open candidate's rows say `r' = 0`: exactly zero, not the linear solve's round-off.
        let forces = DVector::from_fn(m, |k, _| {
            if system.branch(k / d) == LocalBranch::Open {
                0.0
            } else {
                r[k] + rho[k / d] * solution[n + k]
            }
        });
        if dx.iter().chain(forces.iter()).any(|v| !v.is_finite()) {
            return Err(IncrementFailure::linear(SYSTEM, LinearFailure::Singular));
        }
        Ok(GlobalStep { dx, r: forces })
    }

    /// Solves the contact problem of one linearisation, as the reduced path does: semismooth
    /// Newton steps of [`GlobalContactSolver::step`] on the system with `K` and `H` fixed,
    /// each from the linearised state `R + K dx`, `u + H dx` of the steps so far, until the
    /// law holds there (`max_c ||Phi_c|| / rho_c`, see [`law_residual`]) to `tolerance`, or
    /// for `max_steps`. Only the candidates' branches change from one step to the next, so the
    /// step's preconditioner mostly serves again. Its result is the sum of the steps and the
    /// last forces.
    ///
    /// # Errors
    /// As [`GlobalContactSolver::step`].
    #[allow(clippy::too_many_arguments)] // step's inputs and the inner iteration's limits
    pub fn linearised_solution<const D: usize>(
        &mut self,
        model: &Model<D>,
        k: SparseColMatRef<'_, usize, f64>,
        rows: &ContactRows,
        residual: &DVector<f64>,
        r: &DVector<f64>,
        rho: &[f64],
        held: &[bool],
        (tolerance, max_steps): (f64, usize),
    ) -> Result<GlobalStep, IncrementFailure> {
        let n = residual.len();
        // the merit 0.5 ||F||^2 of the linearised problem, each row a length: the balance
        // rows g = R + K dx - H^T r over K's diagonal, the law rows Phi_c / rho_c
        let diagonal: Vec<f64> = diagonal(k)
            .into_iter()
            .map(|v| if v != 0.0 { v.abs() } else { 1.0 })
            .collect();
        let merit = |balance: &DVector<f64>, linear: &ContactRows, forces: &DVector<f64>| {
            let g: f64 = balance
                .iter()
                .zip(&diagonal)
                .map(|(g, d)| (g / d).powi(2))
                .sum();
            0.5 * (g + law_residuals(linear, forces, rho)
                .map(|l| l * l)
                .sum::<f64>())
        };
        let mut linear = rows.clone();
        let mut dx = DVector::zeros(n);
        let mut forces = r.clone();
        let mut linear_residual = residual.clone();
        let mut balance = residual - rows.transpose_times(&forces, n);
        let mut current = merit(&balance, &linear, &forces);
        let mut k_step = DVector::zeros(n);
        for _ in 0..max_steps {
            let step = self.step(model, k, &linear, &linear_residual, &forces, rho, held)?;
            let u = linear.u.clone();
            let du = rows.times(&step.dx);
            let dr = &step.r - &forces;
            // the balance rows are linear: g(t) = g + t (K ddx - H^T dr)
            symmetric_times(k, step.dx.as_slice(), k_step.as_mut_slice());
            let dg = &k_step - rows.transpose_times(&dr, n);
            // backtracking (Armijo) on the merit
            let (mut t, mut halvings) = (1.0, 0);
            loop {
                linear.u = &u + &du * t;
                let value = merit(&(&balance + &dg * t), &linear, &(&forces + &dr * t));
                if value <= (1.0 - 1e-4 * t) * current || halvings == LINE_SEARCH_HALVINGS {
                    current = value;
                    break;
                }
                t *= 0.5;
                halvings += 1;
            }
            dx.axpy(t, &step.dx, 1.0);
            forces.axpy(t, &dr, 1.0);
            balance.axpy(t, &dg, 1.0);
            symmetric_times(k, dx.as_slice(), linear_residual.as_mut_slice());
            linear_residual += residual;
            if law_residual(&linear, &forces, rho) <= tolerance {
                break;
            }
        }
        Ok(GlobalStep { dx, r: forces })
    }

    /// Solves `system z = rhs`: by GMRES on the last LU factors while they serve; then, for
    /// systems of [`GlobalContactSolver::quasi_definite_from`] unknowns or more, by GMRES on
    /// the factors of an earlier quasi-definite approximation `S` where that is expected to be
    /// cheaper than a factorization (see [`GlobalContactSolver::reuse_budget`]), or else on the
    /// factors of this system's `S`; else by a new LU factorization.
    ///
    /// # Errors
    /// [`IncrementFailure::LinearSolve`] if the LU factorization fails, or the system is too
    /// large for one and GMRES did not solve it.
    fn solve_system<const D: usize>(
        &mut self,
        model: &Model<D>,
        system: &LinearSystem<'_>,
        rhs: &DVector<f64>,
    ) -> Result<DVector<f64>, IncrementFailure> {
        if let Some(z) = self.iterate(system, rhs) {
            return Ok(z);
        }
        let dim = system.dim();
        if dim >= self.quasi_definite_from {
            let branches: Vec<u8> = (0..system.candidates())
                .map(|c| branch_code(system.branch(c)))
                .collect();
            if let Some(budget) = self.reuse_budget(dim, &branches) {
                let preconditioner = &self.quasi_definite;
                if let Some((z, _)) = checked_gmres(
                    system,
                    rhs,
                    |x, out| preconditioner.precondition(x, out),
                    (INEXACT_TOLERANCE, budget),
                    (&mut self.counts.krylov_iterations, &mut self.krylov),
                ) {
                    return Ok(z);
                }
            }
            if let Some(z) = self.iterate_quasi_definite(model, system, rhs, branches) {
                return Ok(z);
            }
            if dim >= self.lu_until {
                return Err(IncrementFailure::linear(
                    SYSTEM,
                    LinearFailure::Solver(format!(
                        "GMRES on the quasi-definite preconditioner did not reach {INEXACT_TOLERANCE:e} \
                         of the residual in {WITHOUT_LU_MAX_ITERATIONS} iterations (no LU \
                         factorization from {} unknowns)",
                        self.lu_until
                    )),
                ));
            }
        }
        self.counts.lu_factorizations += 1;
        let (pairs, values) = system.entries();
        let matrix = self.assemble(dim, pairs, &values)?;
        let clock = Instant::now();
        let factorized = self.factorize(matrix.as_ref());
        self.factorization_time += clock.elapsed();
        factorized?;
        let factors = self.factors.as_ref().ok_or_else(|| {
            IncrementFailure::linear(SYSTEM, LinearFailure::Structure("not factorized".into()))
        })?;
        let mut z = DVector::zeros(rhs.len());
        factors.solve(rhs, &mut z);
        Ok(z)
    }

    /// GMRES on `system z = rhs`, right-preconditioned by the last LU factors unless they are
    /// stale or of another dimension; `Some(z)` if its true relative residual reaches
    /// [`KRYLOV_TOLERANCE`] within [`KRYLOV_MAX_ITERATIONS`]. A failure marks the factors
    /// stale: once they no longer serve, they are not tried again until the next
    /// factorization.
    fn iterate(&mut self, system: &LinearSystem<'_>, rhs: &DVector<f64>) -> Option<DVector<f64>> {
        if self.factors_stale {
            return None;
        }
        let factors = self.factors.as_ref().filter(|f| f.dim() == rhs.len())?;
        let solution = checked_gmres(
            system,
            rhs,
            |x, out| factors.solve(x, out),
            (KRYLOV_TOLERANCE, KRYLOV_MAX_ITERATIONS),
            (&mut self.counts.krylov_iterations, &mut self.krylov),
        );
        self.factors_stale = solution.is_none();
        solution.map(|(z, _)| z)
    }

    /// GMRES on `system z = rhs` preconditioned by the `L D L^T` factorization of its
    /// symmetric quasi-definite approximation `S` (see [`crate::quasi_definite`]); `Some(z)`
    /// if its true relative residual reaches [`INEXACT_TOLERANCE`] within
    /// [`QUASI_DEFINITE_MAX_ITERATIONS`] (or [`WITHOUT_LU_MAX_ITERATIONS`] from
    /// [`GlobalContactSolver::lu_until`] unknowns). The factors are single-precision until
    /// they once fail where double-precision ones serve; from then on, double.
    fn iterate_quasi_definite<const D: usize>(
        &mut self,
        model: &Model<D>,
        system: &LinearSystem<'_>,
        rhs: &DVector<f64>,
        branches: Vec<u8>,
    ) -> Option<DVector<f64>> {
        // factors that fail to factorize or to precondition do not serve a later system
        self.preconditioner_branches = None;
        let dim = rhs.len();
        let budget = if dim >= self.lu_until {
            WITHOUT_LU_MAX_ITERATIONS
        } else {
            QUASI_DEFINITE_MAX_ITERATIONS
        };
        self.order_for(model, dim);
        let order = self.order.as_deref();
        let (symbolic, values) = self.approximation.of(system);
        let precisions: &[Precision] = match self.precision {
            Precision::Single => &[Precision::Single, Precision::Double],
            Precision::Double => &[Precision::Double],
        };
        for &precision in precisions {
            self.counts.preconditioner_factorizations += 1;
            let clock = Instant::now();
            let factorized = self.quasi_definite.factorize(
                symbolic,
                values,
                system.equations(),
                order,
                precision,
            );
            self.factorization_time += clock.elapsed();
            if factorized.is_err() {
                continue;
            }
            let preconditioner = &self.quasi_definite;
            if let Some((z, iterations)) = checked_gmres(
                system,
                rhs,
                |x, out| preconditioner.precondition(x, out),
                (INEXACT_TOLERANCE, budget),
                (&mut self.counts.krylov_iterations, &mut self.krylov),
            ) {
                self.precision = precision;
                self.preconditioner_branches = Some(branches);
                self.fresh_iterations = iterations;
                return Some(z);
            }
        }
        None
    }

    /// The GMRES iterations to give the quasi-definite factors of an earlier system on a
    /// system of dimension `dim` whose candidates are on `branches`, or `None` if refactorizing
    /// is expected to be cheaper. Each candidate that changed branch since the factorization
    /// changes `S` by a term of rank up to its rows, which GMRES needs iterations to absorb:
    /// measured on `3d-refined`, [`REUSE_EXTRA_ITERATIONS`] more than the factorized system
    /// took with no change, and about [`REUSE_ITERATIONS_PER_SWITCH`] more for every changed
    /// candidate. The factors are reused if that is below [`REUSE_SHARE`] of the cost of a
    /// factorization (in iterations, [`QuasiDefinite::factorization_cost`]), with a budget of
    /// the factorized system's iterations plus that cost.
    fn reuse_budget(&self, dim: usize, branches: &[u8]) -> Option<usize> {
        let factorized = self.preconditioner_branches.as_ref()?;
        if !self.quasi_definite.factorizes(dim) || factorized.len() != branches.len() {
            return None;
        }
        let switched = factorized
            .iter()
            .zip(branches)
            .filter(|(a, b)| a != b)
            .count();
        reuse_budget(
            switched,
            self.quasi_definite.factorization_cost(),
            self.fresh_iterations,
        )
    }

    /// The elimination order of the quasi-definite approximation of `model`'s global system
    /// with `dim` unknowns, computed once.
    fn order_for<const D: usize>(&mut self, model: &Model<D>, dim: usize) -> &[usize] {
        let n = model.dofs().len();
        let candidates = model
            .contacts()
            .iter()
            .map(|p| p.nodes.len())
            .sum::<usize>();
        let components = dim
            .saturating_sub(n)
            .checked_div(candidates)
            .unwrap_or_default();
        self.order
            .get_or_insert_with(|| global_system_order(model, components))
    }

    /// Factorizes `matrix` (of the analysed pattern) into the factors kept for later systems.
    fn factorize(
        &mut self,
        matrix: SparseColMatRef<'_, usize, f64>,
    ) -> Result<(), IncrementFailure> {
        let fail = |e: &dyn std::fmt::Debug| {
            IncrementFailure::linear(SYSTEM, LinearFailure::Solver(format!("{e:?}")))
        };
        let symbolic = Arc::clone(
            &self
                .analysed
                .as_ref()
                .ok_or_else(|| fail(&"no symbolic analysis"))?
                .lu,
        );
        let mut numeric = self
            .factors
            .take()
            .map_or_else(NumericLu::new, |factors| factors.numeric);
        let par = faer::get_global_parallelism();
        let mut scratch = MemBuffer::try_new(
            symbolic.factorize_numeric_lu_scratch::<f64>(par, Default::default()),
        )
        .map_err(|e| fail(&e))?;
        symbolic
            .factorize_numeric_lu(
                &mut numeric,
                matrix,
                par,
                MemStack::new(&mut scratch),
                Default::default(),
            )
            .map_err(|e| fail(&e))?;
        self.factors = Some(Factors { symbolic, numeric });
        self.factored_values = Some(matrix.val().to_vec());
        self.factors_stale = false;
        Ok(())
    }

    /// The matrix of the entries `pairs` (duplicates summed) with `values`, analysing the
    /// pattern unless it is the last one.
    fn assemble(
        &mut self,
        dim: usize,
        pairs: Vec<Pair<usize, usize>>,
        values: &[f64],
    ) -> Result<SparseColMat<usize, f64>, IncrementFailure> {
        let fail = |what: &str, e: &dyn std::fmt::Debug| {
            IncrementFailure::linear(SYSTEM, LinearFailure::Structure(format!("{what}: {e:?}")))
        };
        if values.iter().any(|v| !v.is_finite()) {
            return Err(IncrementFailure::linear(SYSTEM, LinearFailure::NonFinite));
        }
        let same = self.analysed.as_ref().is_some_and(|a| a.pairs == pairs);
        if !same {
            let (symbolic, argsort) = SymbolicSparseColMat::try_new_from_indices(dim, dim, &pairs)
                .map_err(|e| fail("pattern", &e))?;
            let params = LuSymbolicParams {
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                ..Default::default()
            };
            let lu = factorize_symbolic_lu(symbolic.as_ref(), params)
                .map_err(|e| fail("analysis", &e))?;
            self.analyses += 1;
            self.factors = None;
            self.factored_values = None;
            self.analysed = Some(Analysed {
                pairs,
                symbolic,
                argsort,
                lu: Arc::new(lu),
            });
        }
        let analysed = self
            .analysed
            .as_ref()
            .ok_or_else(|| fail("analysis", &"missing"))?;
        SparseColMat::new_from_argsort(analysed.symbolic.clone(), &analysed.argsort, values)
            .map_err(|e| fail("values", &e))
    }
}

/// Solves the tangential rows of sliding candidate `c` (law `law`, weight `rho`) exactly for
/// its tangential force changes, given the step `dx` and its normal force change in the
/// solution `z = [dx, dy]` of the global system (`n` unknowns before the contact rows):
/// `sum_{s >= 1} Phi_r[t][s] rho dy_s = -Phi_t - Phi_r[t][0] rho dy_N - Phi_u[t] H_c dx` for
/// every tangential row `t`. An iterative solve leaves the rows a small residual; solved
/// exactly, the new forces satisfy the linearised law of sliding, so friction is `mu` times
/// the normal force to the accuracy of Newton's convergence, as with a direct solve.
fn exact_friction_rows(
    law: &LocalLaw,
    rows: &ContactRows,
    rho: f64,
    c: usize,
    n: usize,
    z: &mut DVector<f64>,
) {
    let d = rows.components;
    let h_dx: Vec<f64> = (0..d)
        .map(|t| rows.rows[c * d + t].iter().map(|&(eq, h)| h * z[eq]).sum())
        .collect();
    let dy_n = z[n + c * d];
    let right: Vec<f64> = (1..d)
        .map(|t| {
            -law.phi[t]
                - law.d_r[t][0] * rho * dy_n
                - (0..d).map(|s| law.d_u[t][s] * h_dx[s]).sum::<f64>()
        })
        .collect();
    let block = |t: usize, s: usize| law.d_r[t][s] * rho;
    if d == 2 {
        z[n + c * d + 1] = right[0] / block(1, 1);
    } else {
        let det = block(1, 1) * block(2, 2) - block(1, 2) * block(2, 1);
        z[n + c * d + 1] = (right[0] * block(2, 2) - block(1, 2) * right[1]) / det;
        z[n + c * d + 2] = (block(1, 1) * right[1] - block(2, 1) * right[0]) / det;
    }
}

/// The GMRES budget for earlier quasi-definite factors on a system where `switched` candidates
/// changed branch since their factorization, which took `fresh` iterations and costs `cost`
/// iterations (see [`GlobalContactSolver::reuse_budget`]); `None`: factorize instead.
fn reuse_budget(switched: usize, cost: f64, fresh: usize) -> Option<usize> {
    let expected = REUSE_EXTRA_ITERATIONS + REUSE_ITERATIONS_PER_SWITCH * switched as f64;
    (expected <= REUSE_SHARE * cost)
        .then(|| (fresh + cost.ceil() as usize).min(REUSE_MAX_ITERATIONS))
}

/// The weight `rho_c = 1 / w_c` of every candidate, `w_c` the mean over its rows `k` of
/// `sum_j H_kj^2 / |K_jj|`: the compliance the candidate would have if the tangent `k` (lower
/// triangle) were diagonal. A candidate whose rows involve no equation gets the mean weight of
/// the others (1 if there are none).
pub fn contact_weights(k: SparseColMatRef<'_, usize, f64>, rows: &ContactRows) -> Vec<f64> {
    let diagonal = diagonal(k);
    let d = rows.components;
    let compliance: Vec<f64> = (0..rows.len())
        .map(|c| {
            (c * d..(c + 1) * d)
                .flat_map(|row| rows.rows[row].iter())
                .map(|&(eq, h)| h * h / diagonal[eq].abs())
                .sum::<f64>()
                / d as f64
        })
        .collect();
    let valid = |w: &f64| w.is_finite() && *w > 0.0;
    let weights: Vec<f64> = compliance
        .iter()
        .filter(|w| valid(w))
        .map(|w| 1.0 / w)
        .collect();
    let fallback = if weights.is_empty() {
        1.0
    } else {
        weights.iter().sum::<f64>() / weights.len() as f64
    };
    compliance
        .iter()
        .map(|w| if valid(w) { 1.0 / w } else { fallback })
        .collect()
}

/// `max_c ||Phi_c(u_c, r_c)||_inf / rho_c`: how far, as a length, the contact state `(u, r)`
/// is from the exact Coulomb law (a penetration, a slip while sticking, a force off the cone
/// or on an open contact, each converted by the candidate's weight).
pub fn law_residual(rows: &ContactRows, r: &DVector<f64>, rho: &[f64]) -> f64 {
    law_residuals(rows, r, rho).fold(0.0, f64::max)
}

/// Each candidate's `||Phi_c(u_c, r_c)||_inf / rho_c` (see [`law_residual`]).
pub fn law_residuals<'a>(
    rows: &'a ContactRows,
    r: &'a DVector<f64>,
    rho: &'a [f64],
) -> impl Iterator<Item = f64> + 'a {
    let d = rows.components;
    (0..rows.len()).map(move |c| {
        let block = c * d..(c + 1) * d;
        let law = LocalLaw::evaluate(
            d,
            rows.mu[c],
            rho[c],
            &r.as_slice()[block.clone()],
            &rows.u.as_slice()[block],
        );
        law.phi[..d].iter().fold(0.0_f64, |a, p| a.max(p.abs())) / rho[c]
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::Assembler;
    use crate::contact_rows::contact_rows;
    use crate::cost::Timings;
    use crate::coupling::contact_step;
    use crate::model::Model;
    use crate::quasi_definite::CONSTRAINT_REGULARIZATION;
    use crate::sparse::symmetric_times;
    use crate::test_support::block_on_drum;
    use nalgebra::DMatrix;
    use skid_contact::coulomb::CoulombSettings;

    /// `K v` from the lower triangle of a symmetric `K`.
    fn symmetric_product(k: SparseColMatRef<'_, usize, f64>, v: &DVector<f64>) -> DVector<f64> {
        let mut out = DVector::zeros(v.len());
        symmetric_times(k, v.as_slice(), out.as_mut_slice());
        out
    }

    /// One linearisation of the block pressed on the drum (held, as in a preload): the
    /// assembler holding the tangent, the contact rows, and a residual that pushes the pad
    /// down into the drum, less towards x = -0.05 (where it may stay open), and sideways, more
    /// towards x = -0.05 (where it slides; it sticks towards x = +0.05).
    fn pressed_block<const D: usize>() -> (Model<D>, Assembler, ContactRows, DVector<f64>, Vec<bool>)
    {
        let model = block_on_drum::<D>();
        let n = model.dofs().len();
        let x = DVector::zeros(n);
        let mut assembler = Assembler::new(&model).expect("assembler");
        assembler.internal(&model, &x, Some(1.0)).expect("internal");
        assembler.add_diagonal(&(model.mass() * 1e8));
        let mut held = vec![false; n];
        for eq in model.dofs().body_equations(0) {
            held[eq] = true;
        }
        assembler.hold(&held);
        // slips counted from the nodes' current positions on the drum
        let rows = contact_rows(&model, &x, &[], None, None, &held).expect("rows");
        let mut residual = DVector::zeros(n);
        for (node, p) in model.part().mesh.nodes.iter().enumerate() {
            let [Some(ex), Some(ey)] = [model.dofs().node(node)[0], model.dofs().node(node)[1]]
            else {
                continue;
            };
            let scale = model.mass()[ey] * 1e8;
            residual[ey] = 1e-2 * scale * (0.5 + 10.0 * p[0]).max(0.0);
            residual[ex] = -2e-4 * scale * (1.0 - 18.0 * p[0]);
        }
        (model, assembler, rows, residual, held)
    }

    /// On one linearisation (`K`, `H` fixed), semismooth Newton on the global system converges
    /// to the solution of the reduced (Delassus) path: the same forces to 1e-8 relative and the
    /// same step, with open, sticking and sliding candidates among them. Its last steps
    /// converge quadratically.
    fn global_iteration_solves_the_reduced_problem<const D: usize>(
        quasi_definite_from: usize,
        lu_until: usize,
    ) {
        let (model, mut assembler, rows, residual, held) = pressed_block::<D>();
        let n = model.dofs().len();
        let settings = CoulombSettings::default();
        let mut timings = Timings::default();
        let warm = DVector::zeros(rows.rows.len());
        let (dx_reduced, reduced, _) = contact_step(
            &mut assembler,
            &rows,
            &residual,
            &warm,
            1e3,
            1e-9 * 1e3,
            &settings,
            None,
            &mut timings,
        )
        .expect("reduced");

        let k = assembler.lower_triangle().expect("lower");
        let rho = contact_weights(k, &rows);
        let mut solver = GlobalContactSolver {
            quasi_definite_from,
            lu_until,
            ..Default::default()
        };
        let (mut dx, mut r) = (DVector::zeros(n), DVector::zeros(rows.rows.len()));
        let mut sizes = Vec::new();
        for _ in 0..30 {
            let mut linear = rows.clone();
            linear.u = &rows.u + rows.times(&dx);
            let linear_residual = &residual + symmetric_product(k, &dx);
            let step = solver
                .step(&model, k, &linear, &linear_residual, &r, &rho, &held)
                .expect("global step");
            dx += &step.dx;
            sizes.push(step.dx.amax() / dx.amax());
            r = step.r;
            if sizes.last().is_some_and(|&s| s < 1e-14) {
                break;
            }
        }
        assert!(
            solver.analyses <= 1,
            "{D}D: one symbolic analysis serves every step"
        );
        let counts = solver.counts;
        if quasi_definite_from == 0 {
            // solved on the quasi-definite factors alone, never by an LU factorization
            assert!(
                counts.preconditioner_factorizations >= 1,
                "{D}D: {counts:?}"
            );
            assert_eq!(counts.lu_factorizations, 0, "{D}D: {counts:?}");
        } else {
            assert_eq!(counts.preconditioner_factorizations, 0, "{D}D: {counts:?}");
            assert!(counts.lu_factorizations >= 1, "{D}D: {counts:?}");
        }
        let mut linear = rows.clone();
        linear.u = &rows.u + rows.times(&dx);
        assert!(law_residual(&linear, &r, &rho) < 1e-14, "{D}D: {sizes:?}");
        let branches: Vec<LocalBranch> = (0..rows.len())
            .map(|c| {
                let block = c * D..(c + 1) * D;
                LocalLaw::evaluate(
                    D,
                    rows.mu[c],
                    rho[c],
                    &r.as_slice()[block.clone()],
                    &linear.u.as_slice()[block],
                )
                .branch
            })
            .collect();
        for wanted in [LocalBranch::Open, LocalBranch::Stick, LocalBranch::Slide] {
            assert!(branches.contains(&wanted), "{D}D: {branches:?}");
        }
        assert!(
            (&r - &reduced.r).amax() <= 1e-8 * reduced.r.amax(),
            "{D}D: {r} vs {}",
            reduced.r
        );
        assert!((&dx - &dx_reduced).amax() <= 1e-8 * dx_reduced.amax());
        // quadratic at the end, up to the inexact solve: each of the last steps at most about
        // the square of the one before, or the linear tolerance times it
        let last = &sizes[sizes.len().saturating_sub(3)..];
        assert!(
            last.windows(2)
                .all(|w| w[1] <= 10.0 * (w[0] * w[0] + INEXACT_TOLERANCE * w[0]) + 1e-14),
            "{D}D: {sizes:?}"
        );
    }

    /// [`GlobalContactSolver::linearised_solution`] solves the contact problem of one
    /// linearisation in one call: the reduced path's forces and step to 1e-8, the law
    /// holding at the linearised kinematics to its tolerance; given a single step, it is one
    /// step of [`GlobalContactSolver::step`] (which leaves the law unsatisfied).
    fn linearised_solution_is_the_reduced_step<const D: usize>() {
        let (model, mut assembler, rows, residual, held) = pressed_block::<D>();
        let warm = DVector::zeros(rows.rows.len());
        let (dx_reduced, reduced, _) = contact_step(
            &mut assembler,
            &rows,
            &residual,
            &warm,
            1e3,
            1e-9 * 1e3,
            &CoulombSettings::default(),
            None,
            &mut Timings::default(),
        )
        .expect("reduced");
        let k = assembler.lower_triangle().expect("lower");
        let rho = contact_weights(k, &rows);
        let law_after = |step: &GlobalStep| {
            let mut linear = rows.clone();
            linear.u = &rows.u + rows.times(&step.dx);
            law_residual(&linear, &step.r, &rho)
        };
        let mut solver = GlobalContactSolver::default();
        let solved = solver
            .linearised_solution(&model, k, &rows, &residual, &warm, &rho, &held, (1e-12, 30))
            .expect("linearised solution");
        assert!(law_after(&solved) <= 1e-12, "{D}D: {}", law_after(&solved));
        assert!(
            (&solved.r - &reduced.r).amax() <= 1e-8 * reduced.r.amax(),
            "{D}D"
        );
        assert!(
            (&solved.dx - &dx_reduced).amax() <= 1e-8 * dx_reduced.amax(),
            "{D}D"
        );

        let one = GlobalContactSolver::default()
            .linearised_solution(&model, k, &rows, &residual, &warm, &rho, &held, (0.0, 1))
            .expect("one step");
        let step = GlobalContactSolver::default()
            .step(&model, k, &rows, &residual, &warm, &rho, &held)
            .expect("global step");
        assert_eq!((&one.dx, &one.r), (&step.dx, &step.r), "{D}D");
        assert!(law_after(&one) > 1e-6, "{D}D: {}", law_after(&one));
    }

    #[test]
    fn linearised_solution_is_the_reduced_step_2d_and_3d() {
        linearised_solution_is_the_reduced_step::<2>();
        linearised_solution_is_the_reduced_step::<3>();
    }

    #[test]
    fn global_iteration_solves_the_reduced_problem_2d() {
        global_iteration_solves_the_reduced_problem::<2>(QUASI_DEFINITE_FROM, LU_UNTIL);
    }

    #[test]
    fn global_iteration_solves_the_reduced_problem_3d() {
        global_iteration_solves_the_reduced_problem::<3>(QUASI_DEFINITE_FROM, LU_UNTIL);
    }

    /// The same on the preconditioned path (GMRES on the quasi-definite factors, in the
    /// nested-dissection order) that systems of 2,000 equations and more take, with the LU
    /// factorization as the last resort or, as from [`LU_UNTIL`] equations, without it.
    #[test]
    fn preconditioned_global_iteration_solves_the_reduced_problem() {
        for lu_until in [LU_UNTIL, 0] {
            global_iteration_solves_the_reduced_problem::<2>(0, lu_until);
            global_iteration_solves_the_reduced_problem::<3>(0, lu_until);
        }
    }

    /// The operator `A v` and the explicit entries of `A` agree; the quasi-definite
    /// approximation `S` built on its pattern holds `K` and, flipped (`diag(I, -I) S`), equals
    /// `A` on the rows and columns of every candidate that does not slide, but for the
    /// constraint rows' regularisation `-eps rho`; `S` on a second system of the same pattern
    /// reuses it.
    fn operator_entries_and_approximation_agree<const D: usize>() {
        let (model, mut assembler, rows, _, held) = pressed_block::<D>();
        let n = model.dofs().len();
        let k = assembler.lower_triangle().expect("lower");
        let rho = contact_weights(k, &rows);
        // forces that open every fourth candidate, and of the others make one in three slide
        // (twice the friction the cone holds) and the rest stick (half of it)
        let mut r = DVector::zeros(rows.rows.len());
        for c in 0..rows.len() {
            let tau = if c % 4 == 3 { -50.0 } else { 100.0 };
            r[c * D] = rho[c] * rows.u[c * D] + tau;
            let share = if c % 3 == 0 { 2.0 } else { 0.5 };
            r[c * D + 1] = rho[c] * rows.u[c * D + 1] + share * rows.mu[c] * tau;
        }
        let system = LinearSystem::new(&model, k, &rows, &r, &rho, &held);
        let dim = system.dim();
        let (pairs, values) = system.entries();
        let mut a = DMatrix::<f64>::zeros(dim, dim);
        for (p, v) in pairs.iter().zip(&values) {
            a[(p.row, p.col)] += v;
        }
        let v = DVector::from_fn(dim, |i, _| (0.3 * i as f64).sin());
        let mut av = DVector::zeros(dim);
        system.apply(&v, &mut av);
        assert!((&a * &v - &av).amax() <= 1e-12 * av.amax(), "{D}D");

        let mut approximation = Approximation::default();
        let (symbolic, values) = approximation.of(&system);
        let pattern = Arc::clone(symbolic);
        let mut s = DMatrix::<f64>::zeros(dim, dim);
        for j in 0..dim {
            let range = pattern.col_ptr()[j]..pattern.col_ptr()[j + 1];
            for (&i, &value) in pattern.row_idx()[range.clone()].iter().zip(&values[range]) {
                assert!(i >= j, "{D}D: ({i}, {j}) above the diagonal");
                s[(i, j)] += value;
                if i != j {
                    s[(j, i)] += value;
                }
            }
        }
        let k_dense = DMatrix::from_fn(n, n, |i, j| a[(i, j)]);
        assert_eq!(s.view((0, 0), (n, n)), k_dense, "{D}D");
        let mut kinds = Vec::new();
        for (c, &rho_c) in rho.iter().enumerate().take(system.candidates()) {
            let branch = system.branch(c);
            kinds.push(branch);
            if branch == LocalBranch::Slide {
                continue;
            }
            for t in 0..D {
                let row = n + c * D + t;
                let constraint = match branch {
                    LocalBranch::Open => false,
                    LocalBranch::Stick => true,
                    LocalBranch::Frictionless | LocalBranch::Slide => t == 0,
                };
                for j in 0..dim {
                    let regularisation = if j == row && constraint {
                        CONSTRAINT_REGULARIZATION * rho_c
                    } else {
                        0.0
                    };
                    assert!(
                        (-s[(row, j)] - a[(row, j)] - regularisation).abs() <= 1e-12 * rho_c,
                        "{D}D: candidate {c} ({branch:?}) row {t}, column {j}: {} vs {}",
                        -s[(row, j)],
                        a[(row, j)]
                    );
                }
                // a constraint row's force acts on the equations; any other's is decoupled
                for j in 0..n {
                    let expected = if constraint { a[(j, row)] } else { 0.0 };
                    assert!((s[(j, row)] - expected).abs() <= 1e-12 * rho_c, "{D}D");
                }
            }
        }
        for wanted in [LocalBranch::Open, LocalBranch::Stick, LocalBranch::Slide] {
            assert!(kinds.contains(&wanted), "{D}D: {kinds:?}");
        }
        let (again, _) = approximation.of(&system);
        assert!(Arc::ptr_eq(again, &pattern), "{D}D: the pattern is kept");
    }

    #[test]
    fn operator_entries_and_approximation_agree_2d() {
        operator_entries_and_approximation_agree::<2>();
    }

    #[test]
    fn operator_entries_and_approximation_agree_3d() {
        operator_entries_and_approximation_agree::<3>();
    }

    /// Earlier factors are reused where the iterations they are expected to add cost less
    /// than a factorization: not where the factorization is cheap, nor once enough candidates
    /// changed branch; the budget is the earlier iterations plus the cost, within the cap.
    #[test]
    fn earlier_factors_are_reused_where_they_are_cheaper_than_a_factorization() {
        assert_eq!(reuse_budget(0, 2.0, 7), None);
        assert_eq!(reuse_budget(0, 25.0, 7), Some(32));
        assert_eq!(reuse_budget(2, 25.0, 7), Some(32));
        assert_eq!(reuse_budget(4, 25.0, 7), None);
        assert_eq!(reuse_budget(0, 500.0, 7), Some(REUSE_MAX_ITERATIONS));
    }
}
