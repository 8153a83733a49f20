//! The contact rows of the Newton system: the kinematics of every contact candidate
//! linearised in the global unknowns.
//!
//! For every contact candidate `c` (a slave node of a pair) the local quantities
//! `u_c = (g, s_1[, s_2])` (normal gap at the end of the increment and the slip over the
//! increment, lengths along the master surface, see `RigidSurface::slip`) are linearised in the global
//! unknowns: `u_c(x + dx) ~ u_c(x) + H_c dx`. The rows of `H` hold the derivatives with respect
//! to the node's components and the carrying body's translation and rotation, and each row's
//! second derivatives give the stiffness of the contact forces on a curved, turning surface.

use std::cell::OnceCell;

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use skid_contact::kinematics::{
    ContactKinematics, IncrementStart, evaluate, gap_discrete_gradient, rotation_column,
};
use skid_contact::{Projection, SurfacePoint};

use crate::error::{IncrementFailure, LinearFailure};
use crate::model::Model;
use crate::orientation::Orientation;
use crate::sparse::Factorization;

/// The rows of a sparse matrix, one after another: row `k`'s `(column, value)` entries are
/// `entries[starts[k]..starts[k + 1]]`, one allocation for all rows.
#[derive(Clone, Debug, PartialEq)]
pub struct SparseRows {
    entries: Vec<(usize, f64)>,
    starts: Vec<usize>,
}

impl SparseRows {
    /// No rows, with room for `rows` rows of `entries` entries in all.
    pub fn with_capacity(rows: usize, entries: usize) -> Self {
        let mut starts = Vec::with_capacity(rows + 1);
        starts.push(0);
        Self {
            entries: Vec::with_capacity(entries),
            starts,
        }
    }

    /// The number of rows.
    pub fn len(&self) -> usize {
        self.starts.len() - 1
    }

    /// True if there are no rows.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The rows in order, each as its entries.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = &[(usize, f64)]> + '_ {
        self.starts
            .windows(2)
            .map(|range| &self.entries[range[0]..range[1]])
    }

    /// Adds `value` to column `column` of the row being built (see [`Self::end_row`]): to its
    /// entry there, or as a new entry.
    pub fn add(&mut self, column: usize, value: f64) {
        let start = self.starts[self.starts.len() - 1];
        match self.entries[start..].iter_mut().find(|(c, _)| *c == column) {
            Some(entry) => entry.1 += value,
            None => self.entries.push((column, value)),
        }
    }

    /// Ends the row being built: the entries added since the last call make row [`Self::len`].
    pub fn end_row(&mut self) {
        self.starts.push(self.entries.len());
    }
}

impl std::ops::Index<usize> for SparseRows {
    type Output = [(usize, f64)];

    fn index(&self, row: usize) -> &[(usize, f64)] {
        &self.entries[self.starts[row]..self.starts[row + 1]]
    }
}

/// Linearised contact kinematics at one configuration.
#[derive(Clone, Debug)]
pub struct ContactRows {
    /// Components per contact: 1 normal + (D - 1) tangential.
    pub components: usize,
    /// Sparse rows of H: (equation, coefficient); `components` rows per contact.
    pub rows: SparseRows,
    /// Current local quantities u (gap, slip increment per tangent), per row.
    pub u: DVector<f64>,
    /// Current closest point per contact (body frame), where the next increment's slip starts.
    pub closest: Vec<SurfacePoint>,
    /// Friction coefficient per contact.
    pub mu: Vec<f64>,
    /// Number `m = 2D + r` of a candidate's local coordinates `z = (node position [D], body
    /// translation [D], body rotations [r])` (see [`contact_coordinates`]); `r` is 3 if a pair's
    /// body is free to turn, else 1.
    pub coordinates: usize,
    /// Per row, the second derivatives of its `u` in the candidate's local coordinates `z`, a
    /// symmetric `m^2` matrix: row `k`'s entries, column-major, at `k m^2..(k + 1) m^2`, one
    /// allocation for all rows.
    pub curvature: Vec<f64>,
}

impl ContactRows {
    /// Number of contact candidates.
    pub fn len(&self) -> usize {
        self.closest.len()
    }

    /// True if there are no candidates.
    pub fn is_empty(&self) -> bool {
        self.closest.is_empty()
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
        let size = self.coordinates;
        let mut stiffness: Option<DMatrix<f64>> = None;
        for row in c * d..(c + 1) * d {
            let force = r.get(row).copied().unwrap_or(0.0);
            if force == 0.0 {
                continue;
            }
            let curvature = &self.curvature[row * size * size..(row + 1) * size * size];
            match stiffness.as_mut() {
                None => {
                    stiffness = Some(DMatrix::from_iterator(
                        size,
                        size,
                        curvature.iter().map(|&v| v * -force),
                    ));
                }
                Some(k) => {
                    for (k, &v) in k.as_mut_slice().iter_mut().zip(curvature) {
                        *k += v * -force;
                    }
                }
            }
        }
        stiffness
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
    pub(crate) fn row_indices(&self, candidates: &[usize]) -> Vec<usize> {
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
        let trailing = factor.trailing();
        // position[eq]: eq's place among the trailing equations (usize::MAX: not among them)
        let mut position = vec![usize::MAX; trailing.iter().max().map_or(0, |&eq| eq + 1)];
        for (k, &eq) in trailing.iter().enumerate() {
            position[eq] = k;
        }
        let index = self.row_indices(candidates);
        let m = index.len();
        // the rows H_C in trailing positions, entries of row a at starts[a]..starts[a + 1]
        let mut local = Vec::with_capacity(index.iter().map(|&k| self.rows[k].len()).sum());
        let mut starts = Vec::with_capacity(m + 1);
        for &k in &index {
            starts.push(local.len());
            for &(eq, c) in &self.rows[k] {
                match position.get(eq) {
                    Some(&p) if p != usize::MAX => local.push((p, c)),
                    _ => {
                        return Err(IncrementFailure::linear(
                            "Delassus operator",
                            LinearFailure::Structure(
                                "a contact row involves an equation the factorization does \
                                 not eliminate last"
                                    .into(),
                            ),
                        ));
                    }
                }
            }
        }
        starts.push(local.len());
        let row = |a: usize| &local[starts[a]..starts[a + 1]];
        let inverse = factor.trailing_inverse();
        // G = (K^-1)_CC H_C^T, column by column (with no trailing equation G has no rows:
        // the chunk length is kept positive and the empty slice yields no column)
        let size = inverse.nrows();
        let mut g = DMatrix::<f64>::zeros(size, m);
        for (j, column) in g.as_mut_slice().chunks_exact_mut(size.max(1)).enumerate() {
            for &(k, c) in row(j) {
                let source = &inverse.as_slice()[k * size..(k + 1) * size];
                for (target, &value) in column.iter_mut().zip(source) {
                    *target += c * value;
                }
            }
        }
        // W = H_C G, symmetric: its lower triangle, mirrored
        let mut w = DMatrix::<f64>::zeros(m, m);
        for j in 0..m {
            let g_j = &g.as_slice()[j * size..(j + 1) * size];
            for i in j..m {
                let value: f64 = row(i).iter().map(|&(k, c)| c * g_j[k]).sum();
                w[(i, j)] = value;
                w[(j, i)] = value;
            }
        }
        Ok(w)
    }
}

/// The start of a dynamic increment for [`contact_rows`]: the displacement there and, for each
/// candidate whose rows take a rotation column, the projection of its start position on its
/// surface ([`skid_contact::rotation_column`]). That projection depends on the start alone, so
/// it is made at the first Newton iteration that needs it and shared by the later ones.
#[derive(Debug)]
pub struct RowStart<'a> {
    x: &'a DVector<f64>,
    projections: Vec<OnceCell<Option<Projection>>>,
}

impl<'a> RowStart<'a> {
    /// The start at displacement `x` of an increment of `model`.
    pub fn new<const D: usize>(model: &Model<D>, x: &'a DVector<f64>) -> Self {
        let candidates = model.contacts().iter().map(|pair| pair.nodes.len()).sum();
        Self {
            x,
            projections: (0..candidates).map(|_| OnceCell::new()).collect(),
        }
    }
}

/// Evaluates the contact rows of all pairs at displacement `x`, with the orientations of bodies
/// free to turn from the records `orientations` (see [`crate::orientation`]). `previous` holds
/// the closest points at the start of the increment, where the slips start (one per candidate,
/// pair by pair; `None`: each node's own closest point, zero slips); `held` marks equations
/// whose increment is zero in this step (their columns are dropped).
///
/// `start` is the start of a dynamic increment (`None` for rows at the start itself and for
/// static equilibrium, which needs the normal at the solution; it is the same `start` for
/// every iteration of an increment, whose orientations are `orientations`). Against a
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
    orientations: &[Orientation],
    start: Option<&RowStart<'_>>,
    previous: Option<&[SurfacePoint]>,
    held: &[bool],
) -> Result<ContactRows, IncrementFailure> {
    let components = D;
    let dofs = model.dofs();
    let candidates: usize = model.contacts().iter().map(|pair| pair.nodes.len()).sum();
    let size = 2 * D + rotation_coordinates(model);
    let mut out = ContactRows {
        components,
        coordinates: size,
        rows: SparseRows::with_capacity(candidates * D, candidates * D * size),
        u: DVector::zeros(0),
        closest: Vec::with_capacity(candidates),
        mu: Vec::with_capacity(candidates),
        curvature: Vec::with_capacity(candidates * D * size * size),
    };
    let mut u = Vec::with_capacity(candidates * D);
    let mut k = 0;
    for (p, pair) in model.contacts().iter().enumerate() {
        let frame = model.body_frame(x, pair.body, orientations);
        let start_frame = start.map(|s| model.body_frame(s.x, pair.body, orientations));
        let rotations = dofs.body_rotations(pair.body);
        for &node in &pair.nodes {
            let pos = model.node_position(x, node);
            let from = previous.map(|points| &points[k]);
            let mut kin = evaluate(pair.surface.as_ref(), &frame, &pos, from)
                .ok_or(IncrementFailure::NoProjection { pair: p, node })?;
            if let (Some(start), Some(frame0)) = (start, start_frame) {
                let x0 = start.x;
                let offset = model.node_position(x0, node) - frame0.center;
                if let Some(secant) =
                    gap_discrete_gradient(pair.surface.as_ref(), &frame, &offset, &pos)
                {
                    // the surface is invariant under the body's rotation: no angle terms
                    kin.d_dx[0] = secant.gradient;
                    kin.d_drotation[0] = Vector3::zeros();
                    kin.d2_dx2[0] = secant.jacobian;
                    kin.d2_dx_drotation[0] = Matrix3::zeros();
                    kin.d2_drotation2[0] = Matrix3::zeros();
                } else if let Some(angle) = dofs.body_rotation(pair.body) {
                    let begin = IncrementStart {
                        orientation: frame0.orientation,
                        turn: x[angle] - x0[angle],
                        offset,
                    };
                    let end_offset = pos - frame.center;
                    let surface = pair.surface.as_ref();
                    let before = start.projections.get(k).and_then(|cell| {
                        cell.get_or_init(|| surface.project(&begin.body_point()))
                            .as_ref()
                    });
                    if let Some(column) = before.and_then(|before| {
                        rotation_column(surface, &frame, &begin, before, &end_offset, &kin)
                    }) {
                        for (derivative, c) in kin.d_drotation.iter_mut().zip(column) {
                            derivative[0] = c;
                        }
                    }
                }
            }
            for comp in 0..components {
                let row = &mut out.rows;
                let mut add = |eq: Option<usize>, c: f64| {
                    if let Some(eq) = eq
                        && !held[eq]
                        && c != 0.0
                    {
                        row.add(eq, c);
                    }
                };
                for i in 0..D {
                    add(dofs.node(node)[i], kin.d_dx[comp][i]);
                    // Moving the body by dc moves the body-frame point by -Q^T dc.
                    add(dofs.body_translation(pair.body)[i], -kin.d_dx[comp][i]);
                }
                for (i, &eq) in rotations.iter().enumerate() {
                    add(Some(eq), kin.d_drotation[comp][i]);
                }
                out.rows.end_row();
                push_local_curvature::<D>(&kin, comp, size, &mut out.curvature);
                u.push(if comp == 0 {
                    kin.gap
                } else {
                    kin.slip[comp - 1]
                });
            }
            out.closest.push(kin.closest);
            out.mu.push(pair.mu);
            k += 1;
        }
    }
    out.u = DVector::from_vec(u);
    Ok(out)
}

/// The number `r` of rotation coordinates in a candidate's local coordinates: 3 if a contact
/// pair's body is free to turn, else 1 (see [`ContactRows::coordinates`]).
fn rotation_coordinates<const D: usize>(model: &Model<D>) -> usize {
    let dofs = model.dofs();
    model
        .contacts()
        .iter()
        .map(|pair| dofs.body_rotations(pair.body).len())
        .max()
        .unwrap_or(0)
        .max(1)
}

/// The equations of a candidate's local coordinates `z = (node position [D], body translation
/// [D], body rotations [r])`, `None` where fixed or beyond the body's rotations: the order of
/// [`ContactRows::curvature`].
pub fn contact_coordinates<const D: usize>(
    model: &Model<D>,
    pair: usize,
    node: usize,
) -> Vec<Option<usize>> {
    let dofs = model.dofs();
    let body = model.contacts()[pair].body;
    let rotations = dofs.body_rotations(body);
    let slots = rotation_coordinates(model);
    dofs.node(node)
        .iter()
        .chain(dofs.body_translation(body))
        .copied()
        .chain((0..slots).map(|i| rotations.get(i).copied()))
        .collect()
}

/// Second derivatives of component `comp` of `u` in the `m` local coordinates of
/// [`contact_coordinates`], appended to `out` column by column. The node position `x` and the
/// body translation `c` enter only as `x - c`, so with `A = d^2u/dx^2`, `B = d^2u/dx ddelta`
/// (`D x r`) and `S = d^2u/ddelta^2`: `[[A, -A, B], [-A, A, -B], [B^T, -B^T, S]]`.
fn push_local_curvature<const D: usize>(
    kin: &ContactKinematics,
    comp: usize,
    m: usize,
    out: &mut Vec<f64>,
) {
    let a = &kin.d2_dx2[comp];
    let b = &kin.d2_dx_drotation[comp];
    let s = &kin.d2_drotation2[comp];
    let r = m - 2 * D;
    let start = out.len();
    out.resize(start + m * m, 0.0);
    let block = &mut out[start..];
    for j in 0..D {
        for i in 0..D {
            let v = a[(i, j)];
            block[j * m + i] = v;
            block[j * m + i + D] = -v;
            block[(j + D) * m + i] = -v;
            block[(j + D) * m + i + D] = v;
        }
        for k in 0..r {
            let v = b[(j, k)];
            block[(2 * D + k) * m + j] = v;
            block[(2 * D + k) * m + j + D] = -v;
            block[j * m + 2 * D + k] = v;
            block[(j + D) * m + 2 * D + k] = -v;
        }
    }
    for k in 0..r {
        for l in 0..r {
            block[(2 * D + l) * m + 2 * D + k] = s[(k, l)];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::{block_on_drum, block_on_faceted_drum, coordinate_origins};

    /// Entries added to one column of a row sum into one entry; each row keeps its own entries,
    /// in the order first added, and a row may be empty.
    #[test]
    fn sparse_rows_merge_a_row_s_entries_per_column() {
        let mut rows = SparseRows::with_capacity(3, 4);
        assert!(rows.is_empty());
        rows.add(4, 1.0);
        rows.add(2, -0.5);
        rows.add(4, 0.25);
        rows.end_row();
        rows.end_row();
        rows.add(4, 3.0);
        rows.end_row();
        assert_eq!(rows.len(), 3);
        assert_eq!(&rows[0], &[(4, 1.25), (2, -0.5)]);
        assert!(rows[1].is_empty());
        assert_eq!(&rows[2], &[(4, 3.0)]);
        let lengths: Vec<usize> = rows.iter().map(<[(usize, f64)]>::len).collect();
        assert_eq!(lengths, [2, 0, 1]);
    }

    /// Against a faceted drum, the rows of an iterate take rotation columns from the start's
    /// projections, which a [`RowStart`] makes once: rows from a start already used by an
    /// earlier iterate are those from a new one, and the columns differ from the end-point
    /// derivatives that rows without a start take.
    fn a_shared_start_gives_the_rows_of_a_new_one<const D: usize>() {
        let model = block_on_faceted_drum::<D>();
        let n = model.dofs().len();
        let held = vec![false; n];
        let angle = model.dofs().body_rotation(0).expect("the drum turns");
        let x0 = DVector::from_fn(n, |i, _| 1e-3 * ((i as f64 * 1.3).sin() - 0.5));
        let at_start = contact_rows(&model, &x0, &[], None, None, &held).expect("rows");
        let previous = Some(at_start.closest.as_slice());
        let iterate = |scale: f64| {
            let mut x = &x0 + DVector::from_fn(n, |i, _| scale * (i as f64 * 0.7).cos());
            x[angle] = x0[angle] + 40.0 * scale;
            x
        };
        let (x1, x2) = (iterate(1e-5), iterate(2e-5));
        let shared = RowStart::new(&model, &x0);
        let first = contact_rows(&model, &x1, &[], Some(&shared), previous, &held).expect("rows");
        assert!(shared.projections.iter().all(|p| p.get().is_some()));
        let again = contact_rows(&model, &x2, &[], Some(&shared), previous, &held).expect("rows");
        let fresh = RowStart::new(&model, &x0);
        let new = contact_rows(&model, &x2, &[], Some(&fresh), previous, &held).expect("rows");
        assert_eq!(again.rows, new.rows, "{D}D");
        assert_eq!(again.u, new.u, "{D}D");
        assert_ne!(first.rows, again.rows, "{D}D: the iterates differ");
        let end_point = contact_rows(&model, &x2, &[], None, previous, &held).expect("rows");
        let column = |rows: &ContactRows| -> Vec<f64> {
            (rows.rows.iter())
                .flat_map(|row| row.iter().filter(|(eq, _)| *eq == angle).map(|e| e.1))
                .collect()
        };
        assert_ne!(
            column(&again),
            column(&end_point),
            "{D}D: rotation columns formed"
        );
    }

    #[test]
    fn a_shared_start_gives_the_rows_of_a_new_one_2d_and_3d() {
        a_shared_start_gives_the_rows_of_a_new_one::<2>();
        a_shared_start_gives_the_rows_of_a_new_one::<3>();
    }

    /// `H dx` predicts the change of gaps and slips for a small motion of nodes and drum.
    fn rows_are_the_derivative_of_the_kinematics<const D: usize>() {
        let model = block_on_drum::<D>();
        let n = model.dofs().len();
        let held = vec![false; n];
        let x = DVector::from_fn(n, |i, _| 1e-3 * (i as f64 * 0.9).sin());
        let rows = contact_rows(&model, &x, &[], None, None, &held).expect("rows");
        let previous = Some(rows.closest.as_slice());
        let dx = DVector::from_fn(n, |i, _| 1e-7 * (i as f64 * 2.3).cos());
        let plus = contact_rows(&model, &(&x + &dx), &[], None, previous, &held).expect("rows");
        let minus = contact_rows(&model, &(&x - &dx), &[], None, previous, &held).expect("rows");
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
        let rows = contact_rows(&model, &x, &[], None, None, &held).expect("rows");
        assert!(
            rows.rows
                .iter()
                .all(|r| r.iter().all(|(eq, _)| !drum_eqs.contains(eq)))
        );
    }

    /// Each row's stored curvature is the symmetric `[[A, -A, b], [-A, A, -b], [b^T, -b^T, s]]`
    /// of its kinematics, and a candidate's stiffness is `-sum_k r_k` of its rows' blocks.
    fn curvature_blocks_have_the_documented_form<const D: usize>() {
        let model = block_on_drum::<D>();
        let n = model.dofs().len();
        let x = DVector::from_fn(n, |i, _| 1e-3 * ((i as f64 * 1.3).sin() - 0.5));
        let start = coordinate_origins(&model);
        let rows =
            contact_rows(&model, &x, &[], None, Some(&start), &vec![false; n]).expect("rows");
        let m = 2 * D + 1;
        assert_eq!(rows.curvature.len(), rows.rows.len() * m * m);
        let block =
            |k: usize| DMatrix::from_column_slice(m, m, &rows.curvature[k * m * m..][..m * m]);
        let mut curved = 0;
        for k in 0..rows.rows.len() {
            let b = block(k);
            // A = Q F Q^T is symmetric to round-off
            assert!(
                (&b - b.transpose()).amax() <= 1e-14 * b.amax(),
                "{D}D row {k}: {b}"
            );
            for i in 0..D {
                for j in 0..D {
                    assert_eq!(b[(i, j + D)], -b[(i, j)]);
                    assert_eq!(b[(i + D, j + D)], b[(i, j)]);
                }
                assert_eq!(b[(i + D, 2 * D)], -b[(i, 2 * D)]);
            }
            curved += usize::from(b.amax() > 0.0);
        }
        assert!(curved > 0, "{D}D: no curvature at all");
        let r = DVector::from_fn(rows.rows.len(), |k, _| 1.0 + k as f64);
        for c in 0..rows.len() {
            let expected =
                (c * D..(c + 1) * D).fold(DMatrix::zeros(m, m), |sum, k| sum - block(k) * r[k]);
            let stiffness = rows.curvature_stiffness(c, &r).expect("forces");
            assert!((stiffness - &expected).amax() <= 1e-12 * expected.amax());
        }
        assert!(rows.curvature_stiffness(0, &(r * 0.0)).is_none());
    }

    #[test]
    fn curvature_blocks_have_the_documented_form_2d() {
        curvature_blocks_have_the_documented_form::<2>();
    }

    #[test]
    fn curvature_blocks_have_the_documented_form_3d() {
        curvature_blocks_have_the_documented_form::<3>();
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
