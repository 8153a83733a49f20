//! Assembly of internal forces, the effective tangent and external loads on the fixed pattern.
//!
//! Element vectors and matrices are scattered through the [`DofMap`](crate::dof::DofMap):
//! components of tied nodes land in their body's equation, fixed components are dropped. The
//! effective tangent has the form `K_eff = c_K K_T + diag(c_M m)` (HHT: `c_K = 1 + alpha`,
//! `c_M = 1/(beta h^2)`); equations held fixed in a step get an identity row and column.

use faer::sparse::SparseColMat;
use nalgebra::{DVector, SVector};
use rayon::prelude::*;
use skid_fem::error::FemError;
use skid_fem::pressure::pressure_face_forces;
use skid_fem::solid::ElementResponse;

use crate::contact_rows::{ContactRows, contact_coordinates};
use crate::error::{IncrementFailure, LinearFailure, ModelError};
use crate::loads::LoadInstant;
use crate::mixed::MixedPressures;
use crate::model::Model;
use crate::sparse::{Factorization, PatternBuilder, SparsePattern};

/// Below this many elements the element loop runs sequentially (threads cost more than they
/// save on tiny meshes).
const PARALLEL_ELEMENT_THRESHOLD: usize = 256;

/// Where one element's matrix entries go.
#[derive(Debug)]
struct ElementScatter {
    /// Global equation of each local component (node-major), `None` if fixed.
    eqs: Vec<Option<usize>>,
    /// The value slot of the first stored lower-triangle contribution; the others follow it.
    first_slot: usize,
    /// For every stored contribution, in slot order, its position `p + q n` in the column-major
    /// `n x n` element matrix (local row `p`, column `q`).
    entries: Vec<u32>,
}

impl ElementScatter {
    /// Adds `c k` (the element matrix, column-major `n x n`, read at the stored positions) to
    /// the element's slots of `values`.
    fn add(&self, values: &mut [f64], c: f64, k: &[f64]) {
        debug_assert_eq!(
            k.len(),
            self.eqs.len() * self.eqs.len(),
            "element matrix size"
        );
        let slots = &mut values[self.first_slot..self.first_slot + self.entries.len()];
        for (value, &position) in slots.iter_mut().zip(&self.entries) {
            *value += c * k[position as usize];
        }
    }
}

/// The value slots whose entries lie in the row or column of an equation of `held`.
#[derive(Debug)]
struct HeldSlots {
    held: Vec<bool>,
    slots: Vec<usize>,
}

/// Internal forces and energies of the solid at one configuration.
#[derive(Clone, Debug)]
pub struct InternalState {
    /// Internal force per equation, N (N m for rotations).
    pub force: DVector<f64>,
    /// Elastic strain energy, J.
    pub strain_energy: f64,
    /// Hourglass stabilisation energy, J.
    pub hourglass_energy: f64,
}

/// Owns the pattern, the scatter maps and the value array of the effective tangent.
#[derive(Debug)]
pub struct Assembler {
    pattern: SparsePattern,
    scatter: Vec<ElementScatter>,
    /// Per contact candidate (pairs in order, then their nodes), where its local coordinates'
    /// stiffness goes (see [`crate::contact_rows::contact_coordinates`]).
    contact_scatter: Vec<ElementScatter>,
    diagonal: Vec<usize>,
    slot_position: Vec<(usize, usize)>,
    /// The slots of entries in the rows or columns of held equations, for the held set of the
    /// last [`Self::hold`] call (a step's held set stays the same over its increments).
    held_slots: Option<HeldSlots>,
    values: Vec<f64>,
    /// Element pressures of the mixed tangent between Newton iterates.
    mixed: MixedPressures,
    /// Numeric factorizations of the tangent so far.
    pub factorizations: usize,
}

impl Assembler {
    /// Builds the pattern from the model's connectivity and analyses it once (no equations
    /// eliminated last until [`Self::eliminate_last`] asks for them).
    ///
    /// # Errors
    /// [`ModelError::Invalid`] if the pattern cannot be analysed.
    pub fn new<const D: usize>(model: &Model<D>) -> Result<Self, ModelError> {
        let mut builder = PatternBuilder::default();
        let mut slot_position = Vec::new();
        let mut push = |builder: &mut PatternBuilder, i: usize, j: usize| {
            slot_position.push((i.max(j), i.min(j)));
            builder.push(i, j)
        };
        let mut scatter_of = |eqs: Vec<Option<usize>>| -> Result<ElementScatter, ModelError> {
            let n = eqs.len();
            let too_large = || ModelError::Invalid(format!("an element with {n} components"));
            let mut entries = Vec::new();
            let mut first_slot = None;
            for (p, ep) in eqs.iter().enumerate() {
                for (q, eq) in eqs.iter().enumerate() {
                    if let (Some(i), Some(j)) = (ep, eq)
                        && i >= j
                    {
                        let slot = push(&mut builder, *i, *j);
                        first_slot.get_or_insert(slot);
                        entries.push(u32::try_from(p + q * n).map_err(|_| too_large())?);
                    }
                }
            }
            Ok(ElementScatter {
                eqs,
                first_slot: first_slot.unwrap_or_default(),
                entries,
            })
        };
        let scatter = model
            .part()
            .mesh
            .elements
            .iter()
            .map(|conn| scatter_of(conn.iter().flat_map(|&n| *model.dofs().node(n)).collect()))
            .collect::<Result<_, _>>()?;
        let contact_scatter = model
            .contacts()
            .iter()
            .enumerate()
            .flat_map(|(p, pair)| pair.nodes.iter().map(move |&node| (p, node)))
            .map(|(p, node)| scatter_of(contact_coordinates(model, p, node)))
            .collect::<Result<_, _>>()?;
        let n = model.dofs().len();
        let diagonal = (0..n).map(|i| push(&mut builder, i, i)).collect();
        let pattern = SparsePattern::new(n, builder, &[]).map_err(ModelError::Invalid)?;
        let values = vec![0.0; pattern.slots()];
        Ok(Self {
            pattern,
            scatter,
            contact_scatter,
            diagonal,
            slot_position,
            held_slots: None,
            values,
            mixed: MixedPressures::new(model.elements().len()),
            factorizations: 0,
        })
    }

    /// Internal forces at displacement `x`; if `tangent_factor` is `Some(c_K)`, also resets the
    /// effective tangent to `c_K K_T(x)`.
    ///
    /// # Errors
    /// [`IncrementFailure::InvertedElement`] if an element has J <= 0.
    pub fn internal<const D: usize>(
        &mut self,
        model: &Model<D>,
        x: &DVector<f64>,
        tangent_factor: Option<f64>,
    ) -> Result<InternalState, IncrementFailure> {
        let part = model.part();
        let mixed = &self.mixed;
        let evaluate = |e: usize| -> Result<(ElementResponse, Vec<f64>), IncrementFailure> {
            let u: Vec<SVector<f64, D>> = part.mesh.elements[e]
                .iter()
                .map(|&n| model.dofs().node_displacement(x, n))
                .collect();
            let element = &model.elements()[e];
            let components = D * element.node_count();
            if tangent_factor.is_some() {
                let mut k = vec![0.0; components * components];
                element
                    .respond_with_tangent(part.material(e), &u, mixed.tangent(e), &mut k)
                    .map(|r| (r, k))
            } else {
                element
                    .respond(part.material(e), &u)
                    .map(|r| (r, Vec::new()))
            }
            .map_err(|err| match err {
                FemError::InvertedElement { det_f, corner } => IncrementFailure::InvertedElement {
                    element: e,
                    det_f,
                    corner,
                },
                other => IncrementFailure::Element {
                    element: e,
                    message: other.to_string(),
                },
            })
        };
        let n_el = model.elements().len();
        let responses: Vec<(ElementResponse, Vec<f64>)> = if n_el >= PARALLEL_ELEMENT_THRESHOLD {
            (0..n_el)
                .into_par_iter()
                .map(evaluate)
                .collect::<Result<_, _>>()?
        } else {
            (0..n_el).map(evaluate).collect::<Result<_, _>>()?
        };

        self.mixed
            .record(model, x, responses.iter().map(|(r, _)| r));
        let mut state = InternalState {
            force: DVector::zeros(model.dofs().len()),
            strain_energy: 0.0,
            hourglass_energy: 0.0,
        };
        if tangent_factor.is_some() {
            self.values.iter_mut().for_each(|v| *v = 0.0);
        }
        for ((response, k), scatter) in responses.iter().zip(&self.scatter) {
            state.strain_energy += response.strain_energy;
            state.hourglass_energy += response.hourglass_energy;
            for (p, eq) in scatter.eqs.iter().enumerate() {
                if let Some(eq) = eq {
                    state.force[*eq] += response.force()[p];
                }
            }
            if let Some(c) = tangent_factor {
                scatter.add(&mut self.values, c, k);
            }
        }
        Ok(state)
    }

    /// At the start of an increment from the converged configuration `start`: the first
    /// tangent takes the element pressures `U'(J)` there (evaluated again unless the last
    /// [`Self::internal`] call was at `start`); see [`crate::mixed`].
    ///
    /// # Errors
    /// As [`Self::internal`].
    pub fn start_mixed_pressures<const D: usize>(
        &mut self,
        model: &Model<D>,
        start: &DVector<f64>,
    ) -> Result<(), IncrementFailure> {
        if !self.mixed.recorded_at(start) {
            self.internal(model, start, None)?;
        }
        self.mixed.hold();
        Ok(())
    }

    /// After the Newton step `dx` from the configuration of the last [`Self::internal`] call,
    /// predicts the element pressures the next tangent uses; see [`crate::mixed`].
    pub fn advance_mixed_pressures<const D: usize>(&mut self, model: &Model<D>, dx: &DVector<f64>) {
        self.mixed.advance(model, dx);
    }

    /// Adds the geometric stiffness of the contact forces `r` (one per contact row) to the
    /// effective tangent: [`ContactRows::curvature_stiffness`] of every candidate.
    pub fn add_contact_curvature(&mut self, rows: &ContactRows, r: &DVector<f64>) {
        for (c, scatter) in self.contact_scatter.iter().enumerate().take(rows.len()) {
            let Some(k) = rows.curvature_stiffness(c, r) else {
                continue;
            };
            scatter.add(&mut self.values, 1.0, k.as_slice());
        }
    }

    /// Adds `d_i` to each diagonal entry of the effective tangent (mass terms).
    pub fn add_diagonal(&mut self, d: &DVector<f64>) {
        for (i, &slot) in self.diagonal.iter().enumerate() {
            self.values[slot] += d[i];
        }
    }

    /// Replaces the rows and columns of `held` equations by those of the identity, so that their
    /// increments come out as zero for a zero right-hand side.
    pub fn hold(&mut self, held: &[bool]) {
        if self.held_slots.as_ref().is_none_or(|h| h.held != held) {
            let slots = (self.slot_position.iter().enumerate())
                .filter(|(_, (i, j))| held[*i] || held[*j])
                .map(|(slot, _)| slot)
                .collect();
            self.held_slots = Some(HeldSlots {
                held: held.to_vec(),
                slots,
            });
        }
        for &slot in self.held_slots.iter().flat_map(|h| &h.slots) {
            self.values[slot] = 0.0;
        }
        for (i, &slot) in self.diagonal.iter().enumerate() {
            if held[i] {
                self.values[slot] = 1.0;
            }
        }
    }

    /// The equations the factorization eliminates last.
    pub fn trailing(&self) -> &[usize] {
        self.pattern.trailing()
    }

    /// Has the factorization eliminate the equations `trailing` last (see [`crate::sparse`]);
    /// analyses the pattern again if they change.
    ///
    /// # Errors
    /// [`IncrementFailure::LinearSolve`] if they are not distinct equations of the model.
    pub fn eliminate_last(&mut self, trailing: &[usize]) -> Result<(), IncrementFailure> {
        self.pattern
            .eliminate_last(trailing)
            .map_err(|e| IncrementFailure::linear("effective tangent", LinearFailure::Structure(e)))
    }

    /// The lower triangle of the current effective tangent, compressed.
    ///
    /// # Errors
    /// [`IncrementFailure::LinearSolve`] for non-finite entries.
    pub fn lower_triangle(&self) -> Result<SparseColMat<usize, f64>, IncrementFailure> {
        self.pattern.lower_triangle(&self.values)
    }

    /// Factorizes the current effective tangent.
    ///
    /// # Errors
    /// [`IncrementFailure::LinearSolve`] if it is not positive definite.
    pub fn factorize(&mut self) -> Result<Factorization, IncrementFailure> {
        self.factorizations += 1;
        self.pattern.factorize(&self.values)
    }

    /// Runs `solve` (which factorizes the current matrix) on `K + c_k M` (the current values
    /// hold `K + c_0 M`, held equations already replaced by identity rows), with the first
    /// `c_k = c_0 10^k`, `k = 0, 1, ...,` [`MAX_SHIFT_DECADES`], for which the factorization
    /// succeeds; returns its result and `c_k`.
    ///
    /// This is pseudo-transient continuation: the mass term of the matrix is not that of the
    /// residual, so the converged state does not depend on it; a larger `c` only turns Newton's
    /// step into a damped, shorter one. It is needed where the tangent of the solid *without its
    /// contacts* is indefinite although the contact-constrained problem is stable: a pad pressed
    /// harder than its shear modulus by a load balanced only by contact forces (its free front
    /// face may shear and tilt at negative stiffness, `tau : Omega^T Omega < 0` for a
    /// compressive Kirchhoff stress), which the Cholesky-based contact reduction cannot factor.
    /// A static step meets it with its regularisation `c_0 = 1/h_s^2`, a long dynamic step
    /// (5 ms) with `c_0 = 1/(beta h^2)`. A `c_0` of zero is not escalated.
    ///
    /// # Errors
    /// [`IncrementFailure::LinearSolve`] if even `c_0 10^MAX_SHIFT_DECADES` leaves the matrix
    /// indefinite, or for non-finite entries; any other failure of `solve`.
    pub fn with_mass_shift<T>(
        &mut self,
        mass: &DVector<f64>,
        c0: f64,
        held: &[bool],
        mut solve: impl FnMut(&mut Self) -> Result<T, IncrementFailure>,
    ) -> Result<(T, f64), IncrementFailure> {
        let mut c = c0;
        let mut decades = 0;
        loop {
            match solve(self) {
                Ok(result) => return Ok((result, c)),
                Err(IncrementFailure::LinearSolve {
                    failure: LinearFailure::NotPositiveDefinite | LinearFailure::Singular,
                    ..
                }) if decades < MAX_SHIFT_DECADES && c > 0.0 => {
                    self.add_diagonal(&(mass * (9.0 * c)));
                    self.hold(held);
                    c *= 10.0;
                    decades += 1;
                }
                Err(e) => return Err(e),
            }
        }
    }
}

/// How many tenfold increases of the mass shift [`Assembler::with_mass_shift`] tries before it
/// reports the tangent as indefinite.
pub const MAX_SHIFT_DECADES: usize = 8;

/// External nodal forces per equation at `instant`: `f = sum_l c_l f_l` with each load's
/// factor `c_l` (its amplitude at the step time, or the ramp; see [`crate::loads`]), the
/// pressures' `f_l` on the current geometry at `x` (follower pressure), the dead loads' fixed.
pub fn external_forces<const D: usize>(
    model: &Model<D>,
    x: &DVector<f64>,
    instant: LoadInstant,
) -> Result<DVector<f64>, IncrementFailure> {
    let mut f = DVector::zeros(model.dofs().len());
    let mesh = &model.part().mesh;
    for load in model.pressures() {
        let pressure = instant.factor(&load.variation) * load.pressure;
        for face in &load.faces {
            let xf: Vec<SVector<f64, D>> = face
                .iter()
                .map(|&n| mesh.nodes[n] + model.dofs().node_displacement(x, n))
                .collect();
            let forces =
                pressure_face_forces(&xf, pressure, model.part().thickness).map_err(|err| {
                    IncrementFailure::Load(format!("pressure on face {face:?}: {err}"))
                })?;
            for (&n, fn_) in face.iter().zip(&forces) {
                for (i, eq) in model.dofs().node(n).iter().enumerate() {
                    if let Some(eq) = eq {
                        f[*eq] += fn_[i];
                    }
                }
            }
        }
    }
    for load in model.dead_loads() {
        f.axpy(instant.factor(&load.variation), &load.force, 1.0);
    }
    Ok(f)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::loads::Loads;
    use crate::model::Tie;
    use crate::test_support::{body, pad_block};
    use nalgebra::DMatrix;

    impl Assembler {
        /// The stored lower triangle expanded to a dense symmetric matrix.
        pub(crate) fn dense(&self, n: usize) -> DMatrix<f64> {
            let mut k = DMatrix::zeros(n, n);
            for (slot, &(i, j)) in self.slot_position.iter().enumerate() {
                k[(i, j)] += self.values[slot];
                if i != j {
                    k[(j, i)] += self.values[slot];
                }
            }
            k
        }
    }

    /// A 3 x 2 block whose top nodes are tied to a plate translating in y, in 2D or 3D.
    fn tied_block<const D: usize>() -> Model<D> {
        let part = pad_block::<D>([0.0; 3], [0.03, 0.02, 0.01], [3, 2, 1]);
        let top = part.mesh.node_sets["ymax"].clone();
        let mut free = [false; D];
        free[1] = true;
        let plate = body::<D>("plate", free, None, 0.0, 0.0);
        let tie = Tie {
            body: 0,
            nodes: top,
        };
        Model::new(part, vec![plate], vec![tie], Loads::default(), vec![]).expect("model")
    }

    /// The assembled tangent (through the DOF map, ties included) is the derivative of the
    /// assembled internal force.
    fn tangent_matches_finite_differences<const D: usize>() {
        let model = tied_block::<D>();
        let n = model.dofs().len();
        let mut assembler = Assembler::new(&model).expect("assembler");
        let x = DVector::from_fn(n, |i, _| {
            1e-3 * ((i as f64 * 1.7).sin() + 0.3 * (i as f64).cos())
        });
        assembler.internal(&model, &x, Some(1.0)).expect("internal");
        let k = assembler.dense(n);
        let eps = 1e-7;
        let mut worst: f64 = 0.0;
        for j in 0..n {
            let mut xp = x.clone();
            let mut xm = x.clone();
            xp[j] += eps;
            xm[j] -= eps;
            let fp = assembler.internal(&model, &xp, None).expect("f").force;
            let fm = assembler.internal(&model, &xm, None).expect("f").force;
            let column = (fp - fm) / (2.0 * eps);
            worst = worst.max((column - k.column(j)).amax());
        }
        assert!(
            worst < 1e-6 * k.amax(),
            "{D}D: worst {worst:e} vs {:e}",
            k.amax()
        );
        // Ties: the plate equation collects the whole top face.
        let plate_eq = model.dofs().body_translation(0)[1].expect("plate y");
        assert!(k[(plate_eq, plate_eq)] > 0.0);
    }

    #[test]
    fn assembled_tangent_matches_finite_differences_2d() {
        tangent_matches_finite_differences::<2>();
    }

    #[test]
    fn assembled_tangent_matches_finite_differences_3d() {
        tangent_matches_finite_differences::<3>();
    }

    /// An indefinite matrix gets mass added tenfold at a time until it factorizes; a failure
    /// other than an indefinite matrix is passed on at once.
    #[test]
    fn mass_shift_escalates_until_the_matrix_factorizes() {
        let model = tied_block::<2>();
        let n = model.dofs().len();
        let mut assembler = Assembler::new(&model).expect("assembler");
        let x = DVector::zeros(n);
        assembler.internal(&model, &x, Some(1.0)).expect("internal");
        let mass = model.mass().clone();
        let held = vec![false; n];
        // pretend the values hold K + 1e3 M while they hold K - 1e9 M
        assembler.add_diagonal(&(&mass * -1e9));
        assert!(assembler.factorize().is_err());
        let (_, c) = assembler
            .with_mass_shift(&mass, 1e3, &held, |a| a.factorize())
            .expect("shifted");
        assert!((1e9..=1e11).contains(&c), "c = {c:e}");
        let mut calls = 0;
        let failure = assembler.with_mass_shift(&mass, 1e3, &held, |_| -> Result<(), _> {
            calls += 1;
            Err(IncrementFailure::NonFinite { iteration: 0 })
        });
        assert!(matches!(failure, Err(IncrementFailure::NonFinite { .. })));
        assert_eq!(calls, 1);
    }

    #[test]
    fn held_equations_get_identity_rows() {
        let model = tied_block::<2>();
        let n = model.dofs().len();
        let mut assembler = Assembler::new(&model).expect("assembler");
        assembler
            .internal(&model, &DVector::zeros(n), Some(1.0))
            .expect("internal");
        let mut held = vec![false; n];
        held[0] = true;
        assembler.hold(&held);
        let k = assembler.dense(n);
        assert_eq!(k[(0, 0)], 1.0);
        assert!(k.row(0).iter().skip(1).all(|&v| v == 0.0));
        assert!(k.column(0).iter().skip(1).all(|&v| v == 0.0));
    }
}
