//! Contact rows of the Newton system and its reduction to the exact-Coulomb problem.
//!
//! For every contact candidate `c` (a slave node of a pair) the local quantities
//! `u_c = (g, Delta s_1[, Delta s_2])` (normal gap at the end of the increment and the slip
//! increment in the master surface's convected coordinates) are linearised in the global
//! unknowns: `u_c(x + dx) ~ u_c(x) + H_c dx`. The rows of `H` hold the derivatives with respect
//! to the node's components and the carrying body's translation and rotation.
//!
//! One Newton step solves `K_eff dx = -R + H^T r`, hence `dx = dx_0 + Z r` with
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

use nalgebra::{DMatrix, DVector, Vector2, Vector3};
use skid_contact::coulomb::{
    CoulombSettings, CoulombSolution, FrictionProblem, natural_map_length_error, solve_coulomb,
};
use skid_contact::error::ContactError;
use skid_contact::kinematics::{
    ContactKinematics, IncrementStart, RotatingFrame, evaluate, gap_discrete_gradient,
    rotation_column, slip_increment,
};

use crate::error::{IncrementFailure, LinearFailure};
use skid_fem::cell::embed;

use std::time::Instant;

use crate::assembly::Assembler;
use crate::increment::Timings;
use crate::model::Model;
use crate::sparse::Factorization;

/// Linearised contact kinematics at one configuration.
#[derive(Clone, Debug)]
pub struct ContactRows {
    /// Components per contact: 1 normal + (D - 1) tangential.
    pub components: usize,
    /// Sparse rows of H: (equation, coefficient); `components` rows per contact.
    pub rows: Vec<Vec<(usize, f64)>>,
    /// Current local quantities u (gap, slip increment per tangent), per row.
    pub u: DVector<f64>,
    /// Current convected coordinates per contact.
    pub coords: Vec<Vector2<f64>>,
    /// Friction coefficient per contact.
    pub mu: Vec<f64>,
    /// Per row, the second derivatives of its `u` in the candidate's local coordinates
    /// `z = (node position [D], body translation [D], body angle)` (see [`contact_coordinates`]),
    /// a symmetric `(2D + 1)^2` matrix.
    pub curvature: Vec<DMatrix<f64>>,
}

impl ContactRows {
    /// Number of contact candidates.
    pub fn len(&self) -> usize {
        self.coords.len()
    }

    /// True if there are no candidates.
    pub fn is_empty(&self) -> bool {
        self.coords.is_empty()
    }

    /// `H^T r`: the generalized contact forces on the equations.
    pub fn transpose_times(&self, r: &DVector<f64>, n: usize) -> DVector<f64> {
        let mut f = DVector::zeros(n);
        for (row, &rk) in self.rows.iter().zip(r.iter()) {
            for &(eq, c) in row {
                f[eq] += c * rk;
            }
        }
        f
    }

    /// The stiffness of the contact forces `r` of candidate `c` on its local coordinates:
    /// `-sum_k r_k d^2 u_k / dz^2` over the candidate's rows. The force on the equations is
    /// `H^T r`, so the residual `R - H^T r` has the derivative `K - H^T dr/dx - sum_k r_k
    /// d^2 u_k/dx^2`; this is the last term, the geometric stiffness of contact on a curved or
    /// rotating surface (a normal force on a convex drum softens the tangential motion by
    /// `r_N / rho`). `None` for a candidate without force.
    pub fn curvature_stiffness(&self, c: usize, r: &DVector<f64>) -> Option<DMatrix<f64>> {
        let d = self.components;
        let forces = (c * d..(c + 1) * d).map(|row| (row, r.get(row).copied().unwrap_or(0.0)));
        forces
            .filter(|&(_, force)| force != 0.0)
            .map(|(row, force)| &self.curvature[row] * -force)
            .reduce(|k, term| k + term)
    }

    /// `H dx`.
    pub fn times(&self, dx: &DVector<f64>) -> DVector<f64> {
        DVector::from_iterator(
            self.rows.len(),
            self.rows
                .iter()
                .map(|row| row.iter().map(|&(eq, c)| c * dx[eq]).sum()),
        )
    }

    /// Indices of the rows of the given candidates, `components` per candidate.
    fn row_indices(&self, candidates: &[usize]) -> Vec<usize> {
        let d = self.components;
        candidates
            .iter()
            .flat_map(|&c| (c * d)..(c + 1) * d)
            .collect()
    }

    /// The equations the rows of the given candidates involve, sorted.
    pub fn equations(&self, candidates: &[usize]) -> Vec<usize> {
        let mut eqs: Vec<usize> = self
            .row_indices(candidates)
            .into_iter()
            .flat_map(|k| self.rows[k].iter().map(|&(eq, _)| eq))
            .collect();
        eqs.sort_unstable();
        eqs.dedup();
        eqs
    }

    /// The Delassus operator `W = H_S K^{-1} H_S^T` of the rows `H_S` of the given candidates.
    ///
    /// `H_S` only involves equations `C` that the factorization eliminates last, so
    /// `W = H_S (K^{-1})_CC H_S^T` with the dense block `(K^{-1})_CC` of the size of `C` (see
    /// [`Factorization::trailing_inverse`]).
    ///
    /// # Errors
    /// [`IncrementFailure::LinearSolve`] if a row involves an equation outside the trailing set.
    pub fn delassus(
        &self,
        factor: &Factorization,
        candidates: &[usize],
    ) -> Result<DMatrix<f64>, IncrementFailure> {
        let mut position = std::collections::HashMap::new();
        for (k, &eq) in factor.trailing().iter().enumerate() {
            position.insert(eq, k);
        }
        let local: Vec<Vec<(usize, f64)>> = self
            .row_indices(candidates)
            .into_iter()
            .map(|k| &self.rows[k])
            .map(|row| {
                row.iter()
                    .map(|&(eq, c)| position.get(&eq).map(|&k| (k, c)))
                    .collect::<Option<Vec<_>>>()
            })
            .collect::<Option<_>>()
            .ok_or_else(|| {
                IncrementFailure::linear(
                    "Delassus operator",
                    LinearFailure::Structure(
                        "a contact row involves an equation the factorization does not \
                         eliminate last"
                            .into(),
                    ),
                )
            })?;
        let inverse = factor.trailing_inverse();
        let m = local.len();
        // G = (K^-1)_CC H_C^T, column by column
        let mut g = DMatrix::zeros(inverse.nrows(), m);
        for (j, row) in local.iter().enumerate() {
            for &(k, c) in row {
                g.column_mut(j).axpy(c, &inverse.column(k), 1.0);
            }
        }
        // W = H_C G
        let w = DMatrix::from_fn(m, m, |i, j| {
            local[i].iter().map(|&(k, c)| c * g[(k, j)]).sum::<f64>()
        });
        Ok((&w + w.transpose()) * 0.5)
    }
}

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

/// Evaluates the contact rows of all pairs at displacement `x`. `previous` holds the convected
/// coordinates at the start of the increment (one per candidate, pair by pair); `held` marks
/// equations whose increment is zero in this step (their columns are dropped).
///
/// `start` is the displacement at the start of a dynamic increment (`None` for rows at the
/// start itself and for static equilibrium, which needs the normal at the solution). Against a
/// surface with a discrete gap gradient (the analytical circle and cylinder, see
/// [`skid_contact::RigidSurface::gap_discrete_gradient`]) the normal row is that gradient
/// between the start and current positions instead of the current normal: the contact force
/// acts along it, so its work over the increment, `p_N H_N dx`, is exactly `p_N dg` (zero for a
/// node sliding along the drum at zero gap). With the current normal a loaded node moving `ds`
/// along the circle of radius R gains `p_N ds^2 / (2 R)` per increment. Against any other
/// surface the rotation column is the one that makes the rows a discrete gradient over the
/// increment ([`skid_contact::rotation_column`]), so that the work is exact there too; with the
/// end-point derivative a node pressed on a facet of a drum turning by `dtheta` gains or loses
/// about `p_N R dtheta^2 / 2` per increment. `u` stays the
/// exact gap and slip, so a converged increment satisfies the contact law exactly either way.
///
/// # Errors
/// [`IncrementFailure::NoProjection`] if a node has no projection on its master surface.
pub fn contact_rows<const D: usize>(
    model: &Model<D>,
    x: &DVector<f64>,
    start: Option<&DVector<f64>>,
    previous: &[Vector2<f64>],
    held: &[bool],
) -> Result<ContactRows, IncrementFailure> {
    let components = D;
    let dofs = model.dofs();
    let mut out = ContactRows {
        components,
        rows: Vec::new(),
        u: DVector::zeros(0),
        coords: Vec::new(),
        mu: Vec::new(),
        curvature: Vec::new(),
    };
    let mut u = Vec::new();
    let mut k = 0;
    for (p, pair) in model.contacts().iter().enumerate() {
        let body = &model.bodies()[pair.body];
        let frame = RotatingFrame {
            center: embed(&(body.reference_point + dofs.body_displacement(x, pair.body))),
            axis: body.rotation_axis.unwrap_or_else(Vector3::z),
            angle: dofs.body_angle(x, pair.body),
        };
        let start_center =
            start.map(|x0| embed(&(body.reference_point + dofs.body_displacement(x0, pair.body))));
        for &node in &pair.nodes {
            let pos = model.node_position(x, node);
            let mut kin = evaluate(pair.surface.as_ref(), &frame, &pos)
                .ok_or(IncrementFailure::NoProjection { pair: p, node })?;
            if let (Some(x0), Some(c0)) = (start, start_center) {
                let offset = model.node_position(x0, node) - c0;
                if let Some(secant) =
                    gap_discrete_gradient(pair.surface.as_ref(), &frame, &offset, &pos)
                {
                    // the surface is invariant under the body's rotation: no angle terms
                    kin.d_dx[0] = secant.gradient;
                    kin.d_dangle[0] = 0.0;
                    kin.d2_dx2[0] = secant.jacobian;
                    kin.d2_dx_dangle[0] = Vector3::zeros();
                    kin.d2_dangle2[0] = 0.0;
                } else {
                    let begin = IncrementStart {
                        angle: dofs.body_angle(x0, pair.body),
                        offset,
                    };
                    let end_offset = pos - frame.center;
                    if let Some(column) =
                        rotation_column(pair.surface.as_ref(), &frame, &begin, &end_offset, &kin)
                    {
                        kin.d_dangle = column;
                    }
                }
            }
            let slip = slip_increment(pair.surface.as_ref(), &previous[k], &kin.coords);
            for comp in 0..components {
                let mut row: Vec<(usize, f64)> = Vec::with_capacity(2 * D + 1);
                let mut add = |eq: Option<usize>, c: f64| {
                    if let Some(eq) = eq
                        && !held[eq]
                        && c != 0.0
                    {
                        match row.iter_mut().find(|(e, _)| *e == eq) {
                            Some(entry) => entry.1 += c,
                            None => row.push((eq, c)),
                        }
                    }
                };
                for i in 0..D {
                    add(dofs.node(node)[i], kin.d_dx[comp][i]);
                    // Moving the body by dc moves the body-frame point by -Q^T dc.
                    add(dofs.body_translation(pair.body)[i], -kin.d_dx[comp][i]);
                }
                add(dofs.body_rotation(pair.body), kin.d_dangle[comp]);
                out.rows.push(row);
                out.curvature.push(local_curvature::<D>(&kin, comp));
                u.push(if comp == 0 { kin.gap } else { slip[comp - 1] });
            }
            out.coords.push(kin.coords);
            out.mu.push(pair.mu);
            k += 1;
        }
    }
    out.u = DVector::from_vec(u);
    Ok(out)
}

/// The equations of a candidate's local coordinates `z = (node position [D], body translation
/// [D], body angle)`, `None` where fixed: the order of [`ContactRows::curvature`].
pub fn contact_coordinates<const D: usize>(
    model: &Model<D>,
    pair: usize,
    node: usize,
) -> Vec<Option<usize>> {
    let dofs = model.dofs();
    let body = model.contacts()[pair].body;
    dofs.node(node)
        .iter()
        .chain(dofs.body_translation(body))
        .copied()
        .chain([dofs.body_rotation(body)])
        .collect()
}

/// Second derivatives of component `comp` of `u` in the local coordinates of
/// [`contact_coordinates`]. The node position `x` and the body translation `c` enter only as
/// `x - c`, so with `A = d^2u/dx^2`, `b = d^2u/dx dtheta` and `s = d^2u/dtheta^2`:
/// `[[A, -A, b], [-A, A, -b], [b^T, -b^T, s]]`.
fn local_curvature<const D: usize>(kin: &ContactKinematics, comp: usize) -> DMatrix<f64> {
    let a = &kin.d2_dx2[comp];
    let b = &kin.d2_dx_dangle[comp];
    let m = 2 * D + 1;
    let sign = |i: usize| if i < D { 1.0 } else { -1.0 };
    DMatrix::from_fn(m, m, |i, j| match (i, j) {
        (i, j) if i == 2 * D && j == 2 * D => kin.d2_dangle2[comp],
        (i, j) if i == 2 * D => sign(j) * b[j % D],
        (i, j) if j == 2 * D => sign(i) * b[i % D],
        (i, j) => sign(i) * sign(j) * a[(i % D, j % D)],
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::Assembler;
    use crate::test_support::block_on_drum;

    /// `H dx` predicts the change of gaps and slips for a small motion of nodes and drum.
    fn rows_are_the_derivative_of_the_kinematics<const D: usize>() {
        let model = block_on_drum::<D>();
        let n = model.dofs().len();
        let held = vec![false; n];
        let x = DVector::from_fn(n, |i, _| 1e-3 * (i as f64 * 0.9).sin());
        let start: Vec<Vector2<f64>> = vec![Vector2::zeros(); model.contacts()[0].nodes.len()];
        let rows = contact_rows(&model, &x, None, &start, &held).expect("rows");
        let previous = rows.coords.clone();
        let dx = DVector::from_fn(n, |i, _| 1e-7 * (i as f64 * 2.3).cos());
        let plus = contact_rows(&model, &(&x + &dx), None, &previous, &held).expect("rows");
        let minus = contact_rows(&model, &(&x - &dx), None, &previous, &held).expect("rows");
        let predicted = rows.times(&dx);
        let measured = (&plus.u - &minus.u) / 2.0;
        assert!(
            (&predicted - &measured).amax() < 1e-6 * predicted.amax(),
            "{D}D: {predicted} vs {measured}"
        );
        // The drum's rotation and translation both enter the rows.
        let drum_eqs = model.dofs().body_equations(0);
        assert!(
            rows.rows
                .iter()
                .any(|r| r.iter().any(|(eq, _)| drum_eqs.contains(eq)))
        );
        // Held equations are dropped.
        let mut held = held;
        for &eq in &drum_eqs {
            held[eq] = true;
        }
        let rows = contact_rows(&model, &x, None, &start, &held).expect("rows");
        assert!(
            rows.rows
                .iter()
                .all(|r| r.iter().all(|(eq, _)| !drum_eqs.contains(eq)))
        );
    }

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
        let start = vec![Vector2::zeros(); model.contacts()[0].nodes.len()];
        let rows = contact_rows(&model, &x, None, &start, &held).expect("rows");
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
        let start = vec![Vector2::zeros(); model.contacts()[0].nodes.len()];
        let rows = contact_rows(&model, &x, None, &start, &held).expect("rows");
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
        let increment_start = secant.then_some(&x0);
        let (model, mut assembler) = assembled::<D>(&x);
        let held = vec![false; n];
        let start = vec![Vector2::zeros(); model.contacts()[0].nodes.len()];
        let rows = contact_rows(&model, &x, increment_start, &start, &held).expect("rows");
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
            let rows = contact_rows(&model, x, increment_start, &start, &held).expect("rows");
            assembler.internal(&model, x, None).expect("internal").force
                - rows.transpose_times(&r, n)
        };
        let eps = 1e-7;
        let mut worst: f64 = 0.0;
        let mut worst_without: f64 = 0.0;
        for j in 0..n {
            let mut xp = x.clone();
            let mut xm = x.clone();
            xp[j] += eps;
            xm[j] -= eps;
            let column =
                (residual(&mut assembler, &xp) - residual(&mut assembler, &xm)) / (2.0 * eps);
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

    #[test]
    fn rows_are_the_derivative_of_the_kinematics_2d() {
        rows_are_the_derivative_of_the_kinematics::<2>();
    }

    #[test]
    fn rows_are_the_derivative_of_the_kinematics_3d() {
        rows_are_the_derivative_of_the_kinematics::<3>();
    }
}
