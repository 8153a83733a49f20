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

use nalgebra::{DMatrix, DVector, Vector2, Vector3};
use skid_contact::coulomb::{CoulombSettings, CoulombSolution, FrictionProblem, solve_coulomb};
use skid_contact::error::ContactError;
use skid_contact::kinematics::{RotatingFrame, evaluate, slip_increment};

use crate::error::IncrementFailure;
use skid_fem::cell::embed;

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

    /// `H dx`.
    pub fn times(&self, dx: &DVector<f64>) -> DVector<f64> {
        DVector::from_iterator(
            self.rows.len(),
            self.rows
                .iter()
                .map(|row| row.iter().map(|&(eq, c)| c * dx[eq]).sum()),
        )
    }

    /// The Delassus operator `W = H K^{-1} H^T`.
    ///
    /// `H` only involves the contact equations `C`, which the factorization eliminates last, so
    /// `W = H_C (K^{-1})_CC H_C^T` with the dense block `(K^{-1})_CC` of the size of `C` (see
    /// [`Factorization::trailing_inverse`]).
    ///
    /// # Errors
    /// [`IncrementFailure::LinearSolve`] if a row involves an equation outside the trailing set
    /// (the assembler was built for another model).
    pub fn delassus(&self, factor: &Factorization) -> Result<DMatrix<f64>, IncrementFailure> {
        let mut position = std::collections::HashMap::new();
        for (k, &eq) in factor.trailing().iter().enumerate() {
            position.insert(eq, k);
        }
        let local: Vec<Vec<(usize, f64)>> = self
            .rows
            .iter()
            .map(|row| {
                row.iter()
                    .map(|&(eq, c)| position.get(&eq).map(|&k| (k, c)))
                    .collect::<Option<Vec<_>>>()
            })
            .collect::<Option<_>>()
            .ok_or_else(|| {
                IncrementFailure::LinearSolve(
                    "a contact row involves an equation outside the contact equations".into(),
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

/// Solves the exact Coulomb law for all candidates of `rows` in `u = W r + q`, handing the
/// conic solver only the candidates that can carry force.
///
/// A candidate that is open (`q_N > 0`) and stays open under the forces of the others
/// (`u_N = q_N + (W r)_N >= 0`) satisfies the law with `r = 0`. So the problem is first solved
/// on the candidates with `q_N <= 0`; any excluded candidate that the resulting forces would
/// push into penetration is added and the reduced problem solved again. The result solves the
/// full problem exactly; the far ends of a pad, standing millimetres off the drum, never enter
/// a conic solve. `warm` (one force per row, e.g. the forces of the last solve) warm-starts the
/// solve of each reduced problem (see [`solve_coulomb`]).
///
/// # Errors
/// The conic solver's failure.
pub fn solve_contact_forces(
    rows: &ContactRows,
    w: &DMatrix<f64>,
    q: &DVector<f64>,
    warm: &DVector<f64>,
    settings: &CoulombSettings,
) -> Result<CoulombSolution, ContactError> {
    let d = rows.components;
    let nc = rows.len();
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
            let mu: Vec<f64> = members.iter().map(|&c| rows.mu[c]).collect();
            let warm = DVector::from_iterator(
                index.len(),
                index.iter().map(|&k| warm.get(k).copied().unwrap_or(0.0)),
            );
            let problem = FrictionProblem {
                dim: d,
                w: &w_sub,
                q: &q_sub,
                mu: &mu,
            };
            let solution = solve_coulomb(&problem, settings, Some(&warm))?;
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
                .map(|c| rows.mu[c] * u.rows(c * d + 1, d - 1).norm())
                .collect();
            let natural_map_error = skid_contact::coulomb::natural_map_error(
                &FrictionProblem {
                    dim: d,
                    w,
                    q,
                    mu: &rows.mu,
                },
                &r,
                &u,
            );
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
/// # Errors
/// [`IncrementFailure::NoProjection`] if a node has no projection on its master surface.
pub fn contact_rows<const D: usize>(
    model: &Model<D>,
    x: &DVector<f64>,
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
        for &node in &pair.nodes {
            let pos = model.node_position(x, node);
            let kin = evaluate(pair.surface.as_ref(), &frame, &pos)
                .ok_or(IncrementFailure::NoProjection { pair: p, node })?;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::Assembler;
    use crate::model::ContactPair;
    use crate::test_support::{body, pad_block};
    use skid_contact::surface::AnalyticCylinder;

    /// A block above a drum of radius 0.2 that spins about z and may also translate in x.
    fn block_on_drum<const D: usize>() -> Model<D> {
        let part = pad_block::<D>([-0.05, 0.2, -0.05], [0.1, 0.05, 0.1], [4, 1, 2]);
        let front = part.mesh.node_sets["ymin"].clone();
        let mut free = [false; D];
        free[0] = true;
        let drum = body::<D>("drum", free, Some(Vector3::z()), 5.0, 0.175);
        let pair = ContactPair {
            name: "pad-drum".into(),
            nodes: front,
            body: 0,
            surface: Box::new(AnalyticCylinder::new(0.2, Vector3::z()).expect("surface")),
            mu: 0.15,
        };
        Model::new(part, vec![drum], vec![], vec![], vec![pair]).expect("model")
    }

    /// `H dx` predicts the change of gaps and slips for a small motion of nodes and drum.
    fn rows_are_the_derivative_of_the_kinematics<const D: usize>() {
        let model = block_on_drum::<D>();
        let n = model.dofs().len();
        let held = vec![false; n];
        let x = DVector::from_fn(n, |i, _| 1e-3 * (i as f64 * 0.9).sin());
        let start: Vec<Vector2<f64>> = vec![Vector2::zeros(); model.contacts()[0].nodes.len()];
        let rows = contact_rows(&model, &x, &start, &held).expect("rows");
        let previous = rows.coords.clone();
        let dx = DVector::from_fn(n, |i, _| 1e-7 * (i as f64 * 2.3).cos());
        let plus = contact_rows(&model, &(&x + &dx), &previous, &held).expect("rows");
        let minus = contact_rows(&model, &(&x - &dx), &previous, &held).expect("rows");
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
        let rows = contact_rows(&model, &x, &start, &held).expect("rows");
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
        let rows = ContactRows {
            components: d,
            rows: vec![Vec::new(); d * nc],
            u: DVector::zeros(d * nc),
            coords: vec![Vector2::zeros(); nc],
            mu: vec![0.3; nc],
        };
        let settings = CoulombSettings::default();
        let screened = solve_contact_forces(&rows, &w, &q, &DVector::zeros(d * nc), &settings).expect("screened");
        let full = solve_coulomb(
            &FrictionProblem {
                dim: d,
                w: &w,
                q: &q,
                mu: &rows.mu,
            },
            &settings,
            None,
        )
        .expect("full");
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

    /// The Delassus operator from the trailing block of the factor equals `H K^-1 H^T` computed
    /// column by column with full solves.
    fn delassus_is_h_k_inverse_h_transpose<const D: usize>() {
        let model = block_on_drum::<D>();
        let n = model.dofs().len();
        let mut assembler = Assembler::new(&model).expect("assembler");
        let x = DVector::from_fn(n, |i, _| 1e-4 * (i as f64 * 1.3).sin());
        assembler.internal(&model, &x, Some(1.0)).expect("internal");
        // the mass term of a time step makes the free pad and drum definite
        assembler.add_diagonal(&(model.mass() * 1e8));
        let factor = assembler.factorize().expect("factor");
        let held = vec![false; n];
        let start = vec![Vector2::zeros(); model.contacts()[0].nodes.len()];
        let rows = contact_rows(&model, &x, &start, &held).expect("rows");
        let w = rows.delassus(&factor).expect("delassus");
        let m = rows.rows.len();
        let mut expected = DMatrix::zeros(m, m);
        for k in 0..m {
            let mut unit = DVector::zeros(m);
            unit[k] = 1.0;
            let z = factor.solve(&rows.transpose_times(&unit, n));
            expected.set_column(k, &rows.times(&z));
        }
        assert!(
            (&w - &expected).amax() < 1e-10 * expected.amax(),
            "{D}D: {w} vs {expected}"
        );
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
