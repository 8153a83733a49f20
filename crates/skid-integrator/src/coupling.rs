//! The reduction of a contact-coupled Newton step to the exact-Coulomb problem in the contact
//! forces (the reference path; [`crate::global_contact`] is the sparse one).
//!
//! With the contact rows `H` of [`crate::contact_rows`] (`u_c(x + dx) ~ u_c(x) + H_c dx` for the
//! gap and slip of every candidate), one Newton step solves `K_eff dx = -R + H^T r`, hence
//! `dx = dx_0 + Z r` with
//! `dx_0 = -K_eff^{-1} R` and `Z = K_eff^{-1} H^T`, and the local quantities become
//! `u = W r + q` with the Delassus operator `W = H Z` and `q = u(x) + H dx_0`. The contact
//! forces `r` then come from the exact Coulomb law in (W, q) (see `skid_contact::coulomb`), and
//! the step is `dx = K_eff^{-1} (-R + H^T r)`, one more solve. `Z` itself is never formed: `W`
//! comes from the block of `K_eff^{-1}` on the contact equations, which the factorization
//! eliminates last (see [`crate::sparse`]), at the cost of a dense inverse of that size rather
//! than one sparse solve per contact row.
//!
//! That dense block costs the cube of its size, so only the candidates *near* contact enter
//! it (see [`contact_step`]): those with a gap below a fraction of the model size or carrying
//! force at the warm start. The others get `r = 0`, which is exact as long as the step leaves
//! them open; one that the step would push into the surface joins the near set and the step is
//! repeated.

use nalgebra::DVector;
use skid_contact::coulomb::{
    CoulombSettings, CoulombSolution, FrictionProblem, natural_map_length_error, solve_coulomb,
};
use skid_contact::error::ContactError;

use crate::error::IncrementFailure;

use std::time::Instant;

use crate::assembly::Assembler;
use crate::contact_rows::ContactRows;
use crate::cost::Timings;
use crate::sparse::Factorization;

/// Gap below which a candidate is near contact, as a fraction of the model size.
const NEAR_GAP_FRACTION: f64 = 0.001;

/// One contact-coupled Newton step `dx = K^{-1} (-R + H^T r)` with the forces `r` of the exact
/// Coulomb law in `u = W r + q` (see the module documentation), and the Coulomb solution with
/// `r` and the linearised `u = u(x) + H dx` over all candidates.
///
/// Only the candidates near contact (gap `u_N < NEAR_GAP_FRACTION * length`, or a normal force
/// in `warm`) enter `W`, whose equations the assembler is asked to eliminate last (the set only
/// grows, so the pattern is analysed again rarely). A far candidate that the step would push
/// into the surface (`u_N < 0`) joins them and the step is repeated; the result then solves the
/// Coulomb law for all candidates. `warm` (one force per row) warm-starts the solve.
///
/// `K` is the assembler's current matrix, or the factorization `reuse` of an earlier one (a
/// modified Newton step: see [`crate::increment`]) unless the near set needs equations it does
/// not eliminate last. Returns the step, the Coulomb solution and the factorization used.
///
/// # Errors
/// The failures of the factorization and of the Coulomb solve.
#[allow(clippy::too_many_arguments)] // the inputs of one Newton step, each used once
pub fn contact_step(
    assembler: &mut Assembler,
    rows: &ContactRows,
    residual: &DVector<f64>,
    warm: &DVector<f64>,
    length: f64,
    length_tolerance: f64,
    settings: &CoulombSettings,
    reuse: Option<Factorization>,
    timings: &mut Timings,
) -> Result<(DVector<f64>, CoulombSolution, Factorization), IncrementFailure> {
    let d = rows.components;
    let nc = rows.len();
    let n = residual.len();
    let mut near: Vec<bool> = (0..nc)
        .map(|c| {
            rows.u[c * d] < NEAR_GAP_FRACTION * length || warm.get(c * d).is_some_and(|&f| f != 0.0)
        })
        .collect();
    let (mut conic_solves, mut fixed_point_iterations, mut newton_steps) = (0, 0, 0);
    let mut reuse = reuse;
    let mut current = None;
    loop {
        let clock = Instant::now();
        let candidates: Vec<usize> = (0..nc).filter(|&c| near[c]).collect();
        let needed = rows.equations(&candidates);
        let eliminated_last =
            |trailing: &[usize]| needed.iter().all(|eq| trailing.binary_search(eq).is_ok());
        if reuse
            .as_ref()
            .is_some_and(|f| !eliminated_last(f.trailing()))
        {
            reuse = None;
        }
        let trailing = assembler.trailing();
        if !eliminated_last(trailing) {
            let mut grown = [trailing, &needed].concat();
            grown.sort_unstable();
            grown.dedup();
            assembler.eliminate_last(&grown)?;
            current = None;
        }
        let (factor, dx0) = match current.take() {
            Some(current) => current,
            None => {
                let f = match reuse.take() {
                    Some(f) => f,
                    None => assembler.factorize()?,
                };
                let dx0 = f.solve(&(-residual));
                (f, dx0)
            }
        };
        let index = rows.row_indices(&candidates);
        let w = rows.delassus(&factor, &candidates)?;
        let q = (&rows.u + rows.times(&dx0)).select_rows(&index);
        timings.linear_solve += clock.elapsed();
        let clock = Instant::now();
        let mu: Vec<f64> = candidates.iter().map(|&c| rows.mu[c]).collect();
        let warm_near = DVector::from_iterator(
            index.len(),
            index.iter().map(|&k| warm.get(k).copied().unwrap_or(0.0)),
        );
        let problem = FrictionProblem {
            dim: d,
            w: &w,
            q: &q,
            mu: &mu,
        };
        let solution = solve_to_length(&problem, &warm_near, settings, length_tolerance);
        // Failed solves cost time too: count it before reporting the failure.
        timings.contact_solve += clock.elapsed();
        let solution = solution.map_err(IncrementFailure::Contact)?;
        conic_solves += solution.conic_solves;
        fixed_point_iterations += solution.fixed_point_iterations;
        newton_steps += solution.newton_steps;
        let clock = Instant::now();
        let mut r = DVector::zeros(rows.rows.len());
        for (k, &i) in index.iter().enumerate() {
            r[i] = solution.r[k];
        }
        let dx = &dx0 + factor.solve(&rows.transpose_times(&r, n));
        let u = &rows.u + rows.times(&dx);
        timings.linear_solve += clock.elapsed();
        let mut grew = false;
        for c in 0..nc {
            if !near[c] && u[c * d] < 0.0 {
                near[c] = true;
                grew = true;
            }
        }
        if !grew {
            let shift = (0..nc)
                .map(|c| rows.mu[c] * u.rows(c * d + 1, d - 1).norm())
                .collect();
            let solution = CoulombSolution {
                r,
                u,
                shift,
                fixed_point_iterations,
                conic_solves,
                newton_steps,
                natural_map_error: solution.natural_map_error,
            };
            return Ok((dx, solution, factor));
        }
        current = Some((factor, dx0));
    }
}

/// Smallest relative tolerance [`solve_to_length`] asks of the Coulomb solver: near round-off
/// of the natural map, which the semismooth Newton refinement reaches in a step or two.
const TIGHTEST_COULOMB_TOLERANCE: f64 = 1e-15;

/// How often [`solve_to_length`] tightens the relative tolerance.
const MAX_TIGHTENINGS: usize = 3;

/// [`solve_contact_forces`] to a relative error within `settings.tolerance` and a length error
/// ([`natural_map_length_error`]) within `length_tolerance` (m).
///
/// The relative error weighs each contact by its inverse compliance; when the Delassus operator
/// holds a compliance far above the others (a body held only by its contacts, whose tangent a
/// small mass shift regularises), a relative `1e-8` leaves penetrations of micrometres. The
/// solve is then repeated from its own forces with the relative tolerance scaled by
/// `length_tolerance / error` (halved, at least [`TIGHTEST_COULOMB_TOLERANCE`]), at most
/// [`MAX_TIGHTENINGS`] times. Whatever it reaches is returned, also where a tightened solve
/// does not converge to its tighter tolerance (the forces it started from stand): the Newton
/// iteration judges the contact law at the new kinematics in lengths and rejects what is not
/// good enough.
///
/// # Errors
/// The Coulomb solver's failure on the first solve.
fn solve_to_length(
    problem: &FrictionProblem,
    warm: &DVector<f64>,
    settings: &CoulombSettings,
    length_tolerance: f64,
) -> Result<CoulombSolution, ContactError> {
    let mut solution = solve_contact_forces(problem, warm, settings)?;
    let mut tolerance = settings.tolerance;
    for _ in 0..MAX_TIGHTENINGS {
        let error = natural_map_length_error(problem, &solution.r, &solution.u);
        if error <= length_tolerance || tolerance <= TIGHTEST_COULOMB_TOLERANCE {
            break;
        }
        tolerance = (0.5 * tolerance * length_tolerance / error).max(TIGHTEST_COULOMB_TOLERANCE);
        let tighter = CoulombSettings {
            tolerance,
            ..settings.clone()
        };
        let refined = match solve_contact_forces(problem, &solution.r, &tighter) {
            Ok(refined) => refined,
            Err(ContactError::FixedPointNotConverged { .. }) => break,
            Err(other) => return Err(other),
        };
        solution = CoulombSolution {
            conic_solves: solution.conic_solves + refined.conic_solves,
            fixed_point_iterations: solution.fixed_point_iterations
                + refined.fixed_point_iterations,
            newton_steps: solution.newton_steps + refined.newton_steps,
            ..refined
        };
    }
    Ok(solution)
}

/// Solves the exact Coulomb law `problem` for all its contacts, handing the solver only the
/// contacts that can carry force.
///
/// A contact that is open (`q_N > 0`) and stays open under the forces of the others
/// (`u_N = q_N + (W r)_N >= 0`) satisfies the law with `r = 0`. So the problem is first solved
/// on the contacts with `q_N <= 0`; any excluded contact that the resulting forces would
/// push into penetration is added and the reduced problem solved again. The result solves the
/// full problem exactly. `warm` (one force per row, e.g. the forces of the last solve)
/// warm-starts the solve of each reduced problem (see [`solve_coulomb`]).
///
/// # Errors
/// The Coulomb solver's failure.
pub fn solve_contact_forces(
    problem: &FrictionProblem,
    warm: &DVector<f64>,
    settings: &CoulombSettings,
) -> Result<CoulombSolution, ContactError> {
    let &FrictionProblem { dim: d, w, q, mu } = problem;
    let nc = mu.len();
    let mut active: Vec<bool> = (0..nc).map(|c| q[c * d] <= 0.0).collect();
    let (mut conic_solves, mut fixed_point_iterations, mut newton_steps) = (0, 0, 0);
    loop {
        let members: Vec<usize> = (0..nc).filter(|&c| active[c]).collect();
        let index: Vec<usize> = members
            .iter()
            .flat_map(|&c| (0..d).map(move |k| c * d + k))
            .collect();
        let mut r = DVector::zeros(q.len());
        if !members.is_empty() {
            let w_sub = w.select_rows(&index).select_columns(&index);
            let q_sub = q.select_rows(&index);
            let mu_sub: Vec<f64> = members.iter().map(|&c| mu[c]).collect();
            let warm = DVector::from_iterator(
                index.len(),
                index.iter().map(|&k| warm.get(k).copied().unwrap_or(0.0)),
            );
            let reduced = FrictionProblem {
                dim: d,
                w: &w_sub,
                q: &q_sub,
                mu: &mu_sub,
            };
            let solution = solve_coulomb(&reduced, settings, Some(&warm))?;
            conic_solves += solution.conic_solves;
            fixed_point_iterations += solution.fixed_point_iterations;
            newton_steps += solution.newton_steps;
            for (k, &i) in index.iter().enumerate() {
                r[i] = solution.r[k];
            }
        }
        let u = w * &r + q;
        let mut grew = false;
        for c in 0..nc {
            if !active[c] && u[c * d] < 0.0 {
                active[c] = true;
                grew = true;
            }
        }
        if !grew {
            let shift = (0..nc)
                .map(|c| mu[c] * u.rows(c * d + 1, d - 1).norm())
                .collect();
            let natural_map_error = skid_contact::coulomb::natural_map_error(problem, &r, &u);
            return Ok(CoulombSolution {
                r,
                u,
                shift,
                fixed_point_iterations,
                conic_solves,
                newton_steps,
                natural_map_error,
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::DMatrix;

    use super::*;
    use crate::contact_rows::{RowStart, contact_rows};
    use crate::error::LinearFailure;
    use crate::model::Model;
    use crate::orientation::Orientation;
    use crate::test_support::{block_on_drum, central_difference, coordinate_origins};

    /// Screening open candidates out of the conic solve gives the full problem's solution,
    /// including for a candidate that only closes because a neighbour's force pulls it in.
    #[test]
    fn screened_solve_equals_the_full_solve() {
        let d = 2;
        let nc = 3;
        // Contact 1 is open in q, but the normal force at contact 0 drags it down
        // (negative coupling W_N1,N0); contact 2 is open and stays open.
        let mut w = DMatrix::<f64>::identity(d * nc, d * nc) * 1e-6;
        w[(0, 2)] = -0.8e-6;
        w[(2, 0)] = -0.8e-6;
        w[(1, 3)] = 0.2e-6;
        w[(3, 1)] = 0.2e-6;
        let q = DVector::from_vec(vec![-1e-3, 2e-3, 1e-4, 1.5e-3, 5e-3, 1e-3]);
        let problem = FrictionProblem {
            dim: d,
            w: &w,
            q: &q,
            mu: &[0.3; 3],
        };
        let settings = CoulombSettings::default();
        let screened =
            solve_contact_forces(&problem, &DVector::zeros(d * nc), &settings).expect("screened");
        let full = solve_coulomb(&problem, &settings, None).expect("full");
        assert!(
            screened.r[2] > 0.0,
            "contact 1 was pulled into contact and carries force"
        );
        assert_eq!(screened.r[4], 0.0);
        assert!(
            (&screened.r - &full.r).amax() < 1e-6 * full.r.amax(),
            "{} vs {}",
            screened.r,
            full.r
        );
        assert!(screened.natural_map_error < 1e-8);
    }

    /// The block-on-drum model with its effective tangent assembled at `x` (with the mass term
    /// of a time step, which makes the free pad and drum definite).
    fn assembled<const D: usize>(x: &DVector<f64>) -> (Model<D>, Assembler) {
        let model = block_on_drum::<D>();
        let mut assembler = Assembler::new(&model).expect("assembler");
        assembler.internal(&model, x, Some(1.0)).expect("internal");
        assembler.add_diagonal(&(model.mass() * 1e8));
        (model, assembler)
    }

    /// The Delassus operator of a subset of the candidates, from the trailing block of the
    /// factor, equals `H_S K^-1 H_S^T` computed column by column with full solves; a candidate
    /// whose equations are not eliminated last is reported, not mishandled.
    fn delassus_is_h_k_inverse_h_transpose<const D: usize>() {
        let n = block_on_drum::<D>().dofs().len();
        let x = DVector::from_fn(n, |i, _| 1e-4 * (i as f64 * 1.3).sin());
        let (model, mut assembler) = assembled::<D>(&x);
        let held = vec![false; n];
        let start = coordinate_origins(&model);
        let rows = contact_rows(&model, &x, &[], None, Some(&start), &held).expect("rows");
        let subset: Vec<usize> = (0..rows.len()).step_by(2).collect();
        assembler
            .eliminate_last(&rows.equations(&subset))
            .expect("trailing");
        let factor = assembler.factorize().expect("factor");
        let w = rows.delassus(&factor, &subset).expect("delassus");
        let index = rows.row_indices(&subset);
        let mut expected = DMatrix::zeros(index.len(), index.len());
        for (a, &k) in index.iter().enumerate() {
            let mut unit = DVector::zeros(rows.rows.len());
            unit[k] = 1.0;
            let z = factor.solve(&rows.transpose_times(&unit, n));
            expected.set_column(a, &rows.times(&z).select_rows(&index));
        }
        assert!(
            (&w - &expected).amax() < 1e-10 * expected.amax(),
            "{D}D: {w} vs {expected}"
        );
        let all: Vec<usize> = (0..rows.len()).collect();
        assert!(matches!(
            rows.delassus(&factor, &all),
            Err(IncrementFailure::LinearSolve {
                failure: LinearFailure::Structure(_),
                ..
            })
        ));
    }

    /// A step that pushes the whole pad into the drum: starting from the one candidate row
    /// touching the drum, the far candidates that the step pushes in join, and the step equals
    /// the one with every candidate in the Delassus operator from the start.
    fn far_candidates_pushed_in_join_the_contact_step<const D: usize>() {
        let n = block_on_drum::<D>().dofs().len();
        let x = DVector::zeros(n);
        let (model, mut assembler) = assembled::<D>(&x);
        let held = vec![false; n];
        let start = coordinate_origins(&model);
        let rows = contact_rows(&model, &x, &[], None, Some(&start), &held).expect("rows");
        // the drum is held by its mass term; every pad node is pushed down by 1 cm
        let mut residual = DVector::zeros(n);
        for node in 0..model.part().mesh.nodes.len() {
            if let Some(eq) = model.dofs().node(node)[1] {
                residual[eq] = 1e-2 * model.mass()[eq] * 1e8;
            }
        }
        let warm = DVector::zeros(rows.rows.len());
        let settings = CoulombSettings::default();
        let mut timings = Timings::default();
        let touching = (0..rows.len()).filter(|&c| rows.u[c * D] < 1e-12).count();
        assert!(touching > 0 && touching < rows.len());
        let mut step = |length, reuse| {
            contact_step(
                &mut assembler,
                &rows,
                &residual,
                &warm,
                length,
                1e-9 * length,
                &settings,
                reuse,
                &mut timings,
            )
        };
        // a tiny model length: only the touching candidates are near at first
        let (dx, local, local_factor) = step(1e-9, None).expect("local");
        // a huge one: every candidate is near; the local factorization offered for reuse does
        // not eliminate their equations last, so the matrix is factorized again
        let (dx_all, all, all_factor) = step(1e3, Some(local_factor)).expect("all");
        // reusing the factorization of the same matrix gives the same step
        let (dx_reused, reused, _) = step(1e3, Some(all_factor)).expect("reused");
        assert!((&dx_reused - &dx_all).amax() <= 1e-12 * dx_all.amax());
        assert!((&reused.r - &all.r).amax() <= 1e-12 * all.r.amax());
        let carrying = (0..rows.len()).filter(|&c| local.r[c * D] > 0.0).count();
        assert!(carrying > touching, "{D}D: {carrying} carry force");
        assert!(
            (&dx - &dx_all).amax() < 1e-8 * dx_all.amax(),
            "{D}D: {dx} vs {dx_all}"
        );
        assert!((&local.r - &all.r).amax() < 1e-6 * all.r.amax());
        assert!(local.u.iter().step_by(D).all(|&g| g > -1e-9));
    }

    /// With the contact forces `r` held fixed, the tangent `K_T` plus the contact curvature
    /// stiffness is the derivative of `f_int(x) - H(x)^T r`: node, drum translation and drum
    /// rotation coupled through the curved, rotating surface. With `secant`, the normal rows are
    /// the discrete gap gradients from a start 10 um away (a dynamic increment), whose
    /// derivative Newton takes in its symmetric part.
    fn contact_curvature_completes_the_tangent<const D: usize>(secant: bool) {
        let n = block_on_drum::<D>().dofs().len();
        // the block pressed 1 mm into the drum, sheared, the drum turned and shifted
        let x = DVector::from_fn(n, |i, _| 1e-3 * ((i as f64 * 1.3).sin() - 0.5));
        let x0 = DVector::from_fn(n, |i, _| x[i] - 1e-5 * (i as f64 * 0.7).cos());
        let (model, mut assembler) = assembled::<D>(&x);
        let row_start = RowStart::new(&model, &x0);
        let increment_start = secant.then_some(&row_start);
        let held = vec![false; n];
        let start = coordinate_origins(&model);
        let rows =
            contact_rows(&model, &x, &[], increment_start, Some(&start), &held).expect("rows");
        let r = DVector::from_fn(rows.rows.len(), |k, _| {
            if k % D == 0 {
                700.0 + 10.0 * k as f64
            } else {
                -80.0 + 3.0 * k as f64
            }
        });
        assembler.internal(&model, &x, Some(1.0)).expect("internal");
        let without = assembler.dense(n);
        assembler.add_contact_curvature(&rows, &r);
        let k = assembler.dense(n);
        let residual = |assembler: &mut Assembler, x: &DVector<f64>| {
            let rows =
                contact_rows(&model, x, &[], increment_start, Some(&start), &held).expect("rows");
            assembler.internal(&model, x, None).expect("internal").force
                - rows.transpose_times(&r, n)
        };
        let eps = 1e-7;
        let mut worst: f64 = 0.0;
        let mut worst_without: f64 = 0.0;
        for j in 0..n {
            let column = central_difference(&x, j, eps, |x| residual(&mut assembler, x));
            worst = worst.max((&column - k.column(j)).amax());
            worst_without = worst_without.max((&column - without.column(j)).amax());
        }
        assert!(
            worst < 1e-6 * k.amax(),
            "{D}D, secant {secant}: worst {worst:e} vs {:e}",
            k.amax()
        );
        // the curvature term is not negligible here: without it the tangent is visibly wrong
        assert!(
            worst_without > 1e3 * worst,
            "{D}D: {worst_without:e} vs {worst:e}"
        );
    }

    /// A drum free to turn, at an orientation recorded where the rotation unknowns are: the
    /// tangent with the contact curvature is the derivative of `f_int - H^T r` but in the
    /// rotations' own block, where turning about `a_j` and then about `a_i` differs from the
    /// reverse order; the difference is the skew matrix `1/2 [M]x` of the contact moment
    /// `M = (H^T r)_rot`, which the symmetric tangent leaves out.
    #[test]
    fn contact_curvature_completes_the_tangent_of_a_drum_free_to_turn() {
        let model = crate::test_support::block_on_free_drum();
        let n = model.dofs().len();
        let rotations = model.dofs().body_rotations(0).to_vec();
        let x = DVector::from_fn(n, |i, _| 1e-3 * ((i as f64 * 1.3).sin() - 0.5));
        let record = vec![Orientation {
            body: 0,
            quaternion: {
                let q = nalgebra::UnitQuaternion::from_scaled_axis(nalgebra::Vector3::new(
                    0.02, -0.03, 0.4,
                ));
                [q.w, q.i, q.j, q.k]
            },
            at: std::array::from_fn(|i| x[rotations[i]]),
        }];
        let mut assembler = Assembler::new(&model).expect("assembler");
        let held = vec![false; n];
        let start = coordinate_origins(&model);
        let rows = contact_rows(&model, &x, &record, None, Some(&start), &held).expect("rows");
        assert_eq!(rows.coordinates, 9);
        let r = DVector::from_fn(rows.rows.len(), |k, _| {
            if k % 3 == 0 {
                700.0 + 10.0 * k as f64
            } else {
                -80.0 + 3.0 * k as f64
            }
        });
        assembler.internal(&model, &x, Some(1.0)).expect("internal");
        assembler.add_contact_curvature(&rows, &r);
        let k = assembler.dense(n);
        let moment = rows.transpose_times(&r, n);
        let m = nalgebra::Vector3::from_fn(|i, _| moment[rotations[i]]);
        assert!(m.norm() > 1.0, "the forces turn the drum: {m}");
        let skew = m.cross_matrix() * -0.5;
        let residual = |assembler: &mut Assembler, x: &DVector<f64>| {
            let rows = contact_rows(&model, x, &record, None, Some(&start), &held).expect("rows");
            assembler.internal(&model, x, None).expect("internal").force
                - rows.transpose_times(&r, n)
        };
        let eps = 1e-7;
        let mut worst: f64 = 0.0;
        for j in 0..n {
            let mut column = central_difference(&x, j, eps, |x| residual(&mut assembler, x));
            if let Some(b) = rotations.iter().position(|&eq| eq == j) {
                for (a, &eq) in rotations.iter().enumerate() {
                    column[eq] -= skew[(a, b)];
                }
            }
            worst = worst.max((&column - k.column(j)).amax());
        }
        assert!(worst < 1e-6 * k.amax(), "worst {worst:e} vs {:e}", k.amax());
    }

    #[test]
    fn contact_curvature_completes_the_tangent_2d() {
        contact_curvature_completes_the_tangent::<2>(false);
        contact_curvature_completes_the_tangent::<2>(true);
    }

    #[test]
    fn contact_curvature_completes_the_tangent_3d() {
        contact_curvature_completes_the_tangent::<3>(false);
        contact_curvature_completes_the_tangent::<3>(true);
    }

    #[test]
    fn far_candidates_pushed_in_join_the_contact_step_2d() {
        far_candidates_pushed_in_join_the_contact_step::<2>();
    }

    #[test]
    fn far_candidates_pushed_in_join_the_contact_step_3d() {
        far_candidates_pushed_in_join_the_contact_step::<3>();
    }

    #[test]
    fn delassus_is_h_k_inverse_h_transpose_2d() {
        delassus_is_h_k_inverse_h_transpose::<2>();
    }

    #[test]
    fn delassus_is_h_k_inverse_h_transpose_3d() {
        delassus_is_h_k_inverse_h_transpose::<3>();
    }
}
