//! Assembly of internal forces, the effective tangent and external loads on the fixed pattern.
//!
//! Element vectors and matrices are scattered through the [`DofMap`](crate::dof::DofMap):
//! components of tied nodes land in their body's equation, fixed components are dropped. The
//! effective tangent has the form `K_eff = c_K K_T + diag(c_M m)` (HHT: `c_K = 1 + alpha`,
//! `c_M = 1/(beta h^2)`); equations held fixed in a step get an identity row and column.

use std::time::{Duration, Instant};

use faer::sparse::SparseColMatRef;
use nalgebra::{DVector, SVector};
use skid_fem::error::FemError;
use skid_fem::pressure::pressure_face_forces;
use skid_fem::solid::{ElementResponse, MAX_COMPONENTS, MAX_NODES, Tangent};

use crate::contact_rows::{ContactRows, contact_coordinates};
use crate::error::{IncrementFailure, LinearFailure, ModelError};
use crate::loads::LoadInstant;
use crate::mixed::MixedPressures;
use crate::model::Model;
use crate::orientation::{Orientation, orientation};
use crate::sparse::{
    Factorization, IndefiniteFactorization, PatternBuilder, SparsePattern, diagonal,
    symmetric_times,
};

/// Below this many elements the element loop runs sequentially (threads cost more than they
/// save on tiny meshes).
const PARALLEL_ELEMENT_THRESHOLD: usize = 256;

/// The parallel element loop halves its range until a part has at most this many elements,
/// which one task evaluates in order.
const ELEMENTS_PER_TASK: usize = 32;

/// Where one element's matrix entries go.
#[derive(Debug)]
struct ElementScatter {
    /// Global equation of each local component (node-major), `None` if fixed.
    eqs: Vec<Option<usize>>,
    /// The value slot of the first stored lower-triangle contribution; the others follow it.
    /// (Without any, the slot the next scatter starts at.)
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

    /// Sets the element's own slots, `slots` (the `entries.len()` values from its first slot
    /// on), to `c k` (the element matrix, column-major `n x n`, read at the stored positions).
    fn write(&self, slots: &mut [f64], c: f64, k: &[f64]) {
        debug_assert_eq!(slots.len(), self.entries.len(), "element slots");
        for (value, &position) in slots.iter_mut().zip(&self.entries) {
            *value = c * k[position as usize];
        }
    }
}

/// The symmetric pattern being built and the (row, column) of each of its value slots.
#[derive(Default)]
struct Slots {
    builder: PatternBuilder,
    position: Vec<(usize, usize)>,
}

impl Slots {
    /// Registers entry (i, j) of the lower triangle and returns its value slot.
    fn push(&mut self, i: usize, j: usize) -> usize {
        self.position.push((i.max(j), i.min(j)));
        self.builder.push(i, j)
    }

    /// The next value slots, one for each lower-triangle entry of the element matrix on the
    /// equations `eqs` (one per local component, `None` for fixed ones).
    ///
    /// # Errors
    /// [`ModelError::Invalid`] if the element matrix has more than `u32::MAX` entries.
    fn scatter(&mut self, eqs: Vec<Option<usize>>) -> Result<ElementScatter, ModelError> {
        let n = eqs.len();
        let too_large = || ModelError::Invalid(format!("an element with {n} components"));
        let first_slot = self.position.len();
        let mut entries = Vec::new();
        for (p, ep) in eqs.iter().enumerate() {
            for (q, eq) in eqs.iter().enumerate() {
                if let (Some(i), Some(j)) = (ep, eq)
                    && i >= j
                {
                    self.push(*i, *j);
                    entries.push(u32::try_from(p + q * n).map_err(|_| too_large())?);
                }
            }
        }
        Ok(ElementScatter {
            eqs,
            first_slot,
            entries,
        })
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
    /// The viscous force of the sections' stiffness damping per equation, N (zero without
    /// [`Damping`]).
    pub damping_force: DVector<f64>,
    /// Elastic strain energy, J.
    pub strain_energy: f64,
    /// Hourglass stabilisation energy, J.
    pub hourglass_energy: f64,
}

/// Stiffness-proportional (Rayleigh) damping in a dynamic increment: each element of a
/// section with damping factor `beta > 0` adds the viscous force `f_d = beta K_T(x) v_e`, `K_T`
/// the element's consistent tangent and `v_e` its nodal velocities, and to the tangent
/// `beta K_T dv/dx = beta rate K_T` (the derivative of `K_T` itself along `v` is left out, a
/// term of order `beta |v| / L` against the rest). The increment takes the mean velocity
/// `v = (x - x_n) / h`, `rate = 1 / h`, for every equation: the same rate for the nodes with
/// inertia, the massless contact nodes and a quasi-static solid keeps the tangent symmetric,
/// and `f_d . dx = beta dx^T K_T dx / h >= 0` dissipates wherever `K_T` is positive. Against
/// the end velocity it lags by half an increment, which changes a mode's damping by the
/// factor `cos(omega h / 2)`. `K_T` includes the geometric stiffness, so a stressed element
/// turning rigidly at `W` feels `beta W f_int`, of order `beta |W|` of its internal force.
#[derive(Clone, Copy, Debug)]
pub struct Damping<'a> {
    /// The velocity per equation the viscous force acts on.
    pub velocity: &'a DVector<f64>,
    /// `dv/dx`, the same for every equation.
    pub rate: f64,
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
    /// The value of each slot: first the elements' slots (`values[..element_slots]`, each
    /// element's in one range, in element order), then the contact candidates', then the
    /// diagonal.
    values: Vec<f64>,
    /// The values of the compressed lower triangle, written by [`Self::lower_triangle`] and
    /// [`Self::factorize`] (storage kept from call to call).
    compressed: Vec<f64>,
    element_slots: usize,
    /// Per element, its response at the configuration of the last [`Self::internal`] call
    /// (storage kept from call to call).
    responses: Vec<ElementResponse>,
    /// Per element, its damping force at that call (zero without damping).
    damping_forces: Vec<[f64; MAX_COMPONENTS]>,
    /// Per equation, the force of a displacement of one element size along it, `sum_e
    /// |K_e,ii| h_e` at the reference configuration (see [`Self::stiffness_scale`]).
    stiffness_scale: DVector<f64>,
    /// Element pressures of the mixed tangent between Newton iterates.
    mixed: MixedPressures,
    /// Numeric factorizations of the tangent so far.
    pub factorizations: usize,
    /// Their wall time.
    pub factorization_time: Duration,
}

impl Assembler {
    /// Builds the pattern from the model's connectivity and analyses it once (no equations
    /// eliminated last until [`Self::eliminate_last`] asks for them).
    ///
    /// # Errors
    /// [`ModelError::Invalid`] if the pattern cannot be analysed.
    pub fn new<const D: usize>(model: &Model<D>) -> Result<Self, ModelError> {
        let mut slots = Slots::default();
        let scatter: Vec<ElementScatter> = model
            .part()
            .mesh
            .elements
            .iter()
            .map(|conn| slots.scatter(conn.iter().flat_map(|&n| *model.dofs().node(n)).collect()))
            .collect::<Result<_, _>>()?;
        let element_slots = slots.position.len();
        let contact_scatter = model
            .contacts()
            .iter()
            .enumerate()
            .flat_map(|(p, pair)| pair.nodes.iter().map(move |&node| (p, node)))
            .map(|(p, node)| slots.scatter(contact_coordinates(model, p, node)))
            .collect::<Result<_, _>>()?;
        let n = model.dofs().len();
        let diagonal = (0..n).map(|i| slots.push(i, i)).collect();
        let pattern = SparsePattern::new(n, slots.builder, &[]).map_err(ModelError::Invalid)?;
        let values = vec![0.0; pattern.slots()];
        let elements = model.elements().len();
        let stiffness_scale = stiffness_scale(model, &scatter)?;
        Ok(Self {
            pattern,
            scatter,
            contact_scatter,
            diagonal,
            slot_position: slots.position,
            held_slots: None,
            values,
            compressed: Vec::new(),
            element_slots,
            responses: vec![ElementResponse::default(); elements],
            damping_forces: vec![[0.0; MAX_COMPONENTS]; elements],
            stiffness_scale,
            mixed: MixedPressures::new(elements),
            factorizations: 0,
            factorization_time: Duration::ZERO,
        })
    }

    /// Per equation, `sum_e |K_e,ii| h_e`: the diagonal stiffness of the elements on it at the
    /// reference configuration, each times its element's size `h_e` (`V^(1/D)`, the area's
    /// square root in 2D). Internal forces are sums of stresses whose round-off is `eps` of the
    /// element's stiffness times its size, so `eps` times this bounds the noise with which the
    /// force of an equation can be computed (`K (J - 1)` of a nearly incompressible solid,
    /// `J` rounded from `F = I + H`): the force of a displacement of `eps h`.
    pub fn stiffness_scale(&self) -> &DVector<f64> {
        &self.stiffness_scale
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
        self.internal_damped(model, x, tangent_factor, None)
    }

    /// [`Self::internal`] with the sections' stiffness damping at the velocity and rate of
    /// `damping` (none if `None`): its force in [`InternalState::damping_force`], its tangent
    /// added to `c_K K_T`.
    ///
    /// # Errors
    /// As [`Self::internal`].
    pub fn internal_damped<const D: usize>(
        &mut self,
        model: &Model<D>,
        x: &DVector<f64>,
        tangent_factor: Option<f64>,
        damping: Option<Damping<'_>>,
    ) -> Result<InternalState, IncrementFailure> {
        let element_loop = ElementLoop {
            model,
            x,
            tangent_factor,
            damping,
            mixed: &self.mixed,
            scatter: &self.scatter,
        };
        let (element_values, other_values) = self.values.split_at_mut(self.element_slots);
        let out = ElementOutputs {
            responses: &mut self.responses,
            damping: &mut self.damping_forces,
        };
        if out.responses.len() >= PARALLEL_ELEMENT_THRESHOLD {
            element_loop.run_parallel(0, out, element_values)?;
        } else {
            element_loop.run(0, out, element_values)?;
        }
        if tangent_factor.is_some() {
            other_values.fill(0.0);
        }

        self.mixed.record(model, x, &self.responses);
        let n = model.dofs().len();
        let mut state = InternalState {
            force: DVector::zeros(n),
            damping_force: DVector::zeros(n),
            strain_energy: 0.0,
            hourglass_energy: 0.0,
        };
        for (e, (response, scatter)) in self.responses.iter().zip(&self.scatter).enumerate() {
            state.strain_energy += response.strain_energy;
            state.hourglass_energy += response.hourglass_energy;
            for (eq, force) in scatter.eqs.iter().zip(response.force()) {
                if let Some(eq) = eq {
                    state.force[*eq] += force;
                }
            }
            if damping.is_some() {
                for (eq, force) in scatter.eqs.iter().zip(&self.damping_forces[e]) {
                    if let Some(eq) = eq {
                        state.damping_force[*eq] += force;
                    }
                }
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
    pub fn lower_triangle(&mut self) -> Result<SparseColMatRef<'_, usize, f64>, IncrementFailure> {
        self.pattern.compress(&self.values, &mut self.compressed)?;
        Ok(self.pattern.matrix(&self.compressed))
    }

    /// Factorizes the current effective tangent.
    ///
    /// # Errors
    /// [`IncrementFailure::LinearSolve`] if it is not positive definite.
    pub fn factorize(&mut self) -> Result<Factorization, IncrementFailure> {
        self.factorizations += 1;
        let clock = Instant::now();
        self.pattern.compress(&self.values, &mut self.compressed)?;
        let factor = self.pattern.factorize(&self.compressed);
        self.factorization_time += clock.elapsed();
        factor
    }

    /// Factorizes the current effective tangent as `L D L^T`, which may be indefinite (see
    /// [`SparsePattern::factorize_indefinite`]).
    ///
    /// # Errors
    /// [`IncrementFailure::LinearSolve`] if it is singular or not finite.
    pub fn factorize_indefinite(&mut self) -> Result<IndefiniteFactorization, IncrementFailure> {
        self.factorizations += 1;
        let clock = Instant::now();
        self.pattern.compress(&self.values, &mut self.compressed)?;
        let factor = self.pattern.factorize_indefinite(&self.compressed);
        self.factorization_time += clock.elapsed();
        factor
    }

    /// Factorizes the current effective tangent by Cholesky, or where it is not positive
    /// definite by `L D L^T` (two factorizations then).
    ///
    /// # Errors
    /// [`IncrementFailure::LinearSolve`] if it is singular or not finite.
    pub fn factorize_symmetric(&mut self) -> Result<Solver, IncrementFailure> {
        match self.factorize() {
            Ok(factor) => Ok(Solver::Definite(factor)),
            Err(e) if is_not_factorized(&e) => self.factorize_indefinite().map(Solver::Indefinite),
            Err(e) => Err(e),
        }
    }

    /// Whether the current matrix `K` (held equations already identity rows) holds every
    /// motion: it factorizes (by Cholesky, or where it is indefinite by `L D L^T`), and the
    /// eigenvalue of least magnitude of `K y = lambda M y` on the equations not held, estimated
    /// by [`INVERSE_ITERATIONS`] steps of inverse iteration (`y <- K^{-1} M y`, then the Rayleigh
    /// quotient `y.K y / y.M y`), is above [`SINGULAR_RATIO`] times the largest `K_ii / M_ii` in
    /// magnitude.
    ///
    /// An indefinite `K` that holds every motion is a compressed solid's tangent at an iterate
    /// that has not relaxed yet (the top of a block moved down, the rest still in place, a
    /// volumetric stress far above the shear modulus): Newton's step with it is the consistent
    /// one, which converges quadratically once the iterate is near the solution.
    ///
    /// A motion no support or stiffness holds (a pad held only by its contacts, a body on
    /// rollers free to slide) is an eigenvalue of round-off size, `eps max K_ii / M_ii`; Cholesky
    /// may or may not meet the zero pivot, so the eigenvalue is measured. Inverse iteration
    /// amplifies such a mode by `1/eps` per step from any start vector that is not orthogonal to
    /// it (a pseudo-random one). A held structure's lowest eigenvalue is about `(c_s / L)^2`
    /// for its shear wave speed `c_s` over its length `L`, the largest `K_ii / M_ii` about
    /// `(c_p / h)^2` for the compression wave speed `c_p` over the element size `h`: their ratio
    /// `(mu / (K + 4 mu / 3)) (h / L)^2` is 1e-11 for `K / mu = 1e7` and 100 elements along
    /// `L`, while a free motion measures 1e-16 to 1e-14. Counts as one factorization.
    ///
    /// # Errors
    /// [`IncrementFailure::LinearSolve`] for non-finite entries.
    pub fn is_held(
        &mut self,
        mass: &DVector<f64>,
        held: &[bool],
    ) -> Result<bool, IncrementFailure> {
        let factor = match self.factorize_symmetric() {
            Ok(factor) => factor,
            Err(e) if is_not_factorized(&e) => return Ok(false),
            Err(e) => return Err(e),
        };
        let k = self.lower_triangle()?;
        let free = |i: usize| !held[i] && mass[i] > 0.0;
        let n = mass.len();
        let scale = diagonal(k)
            .iter()
            .enumerate()
            .filter(|(i, _)| free(*i))
            .map(|(i, k_ii)| k_ii / mass[i])
            .fold(0.0_f64, f64::max);
        if scale <= 0.0 {
            return Ok(true);
        }
        // a deterministic pseudo-random start (a linear congruential sequence in [-1, 1])
        let mut seed: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut y = DVector::from_fn(n, |i, _| {
            seed = seed
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            if free(i) {
                (seed >> 11) as f64 / (1u64 << 52) as f64 - 1.0
            } else {
                0.0
            }
        });
        let mut k_y = vec![0.0; n];
        let mut lowest = f64::INFINITY;
        for _ in 0..INVERSE_ITERATIONS {
            let m_y = y.component_mul(mass);
            y = factor.solve(&m_y);
            for (i, v) in y.iter_mut().enumerate() {
                if !free(i) {
                    *v = 0.0;
                }
            }
            let m_norm = y.component_mul(&y).dot(mass).sqrt();
            if !(m_norm.is_finite() && m_norm > 0.0) {
                return Ok(false);
            }
            y /= m_norm;
            symmetric_times(k, y.as_slice(), &mut k_y);
            lowest = y.iter().zip(&k_y).map(|(a, b)| a * b).sum::<f64>();
        }
        Ok(lowest.abs() > SINGULAR_RATIO * scale)
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
    /// (5 ms) with `c_0 = 1/(beta h^2)`. A static step whose tangent is held without its
    /// contacts starts from `c_0 = 0`, the consistent tangent (see [`Self::is_held`]): its first
    /// shift is `first` (the regularisation `1/h_s^2`), and so is that of any `c_0 = 0`; a
    /// `first` of zero is not escalated.
    ///
    /// # Errors
    /// [`IncrementFailure::LinearSolve`] if even `c_0 10^MAX_SHIFT_DECADES` leaves the matrix
    /// indefinite, or for non-finite entries; any other failure of `solve`.
    pub fn with_mass_shift<T>(
        &mut self,
        mass: &DVector<f64>,
        (c0, first): (f64, f64),
        held: &[bool],
        mut solve: impl FnMut(&mut Self) -> Result<T, IncrementFailure>,
    ) -> Result<(T, f64), IncrementFailure> {
        let mut c = c0;
        let mut decades = 0;
        loop {
            match solve(self) {
                Ok(result) => return Ok((result, c)),
                Err(e)
                    if is_not_factorized(&e)
                        && decades < MAX_SHIFT_DECADES
                        && c.max(first) > 0.0 =>
                {
                    let next = if c > 0.0 { 10.0 * c } else { first };
                    self.add_diagonal(&(mass * (next - c)));
                    self.hold(held);
                    c = next;
                    decades += 1;
                }
                Err(e) => return Err(e),
            }
        }
    }
}

/// Whether a failure is a matrix that has no factor of the kind asked for (not positive
/// definite, or singular), rather than one that is not finite.
pub fn is_not_factorized(e: &IncrementFailure) -> bool {
    matches!(
        e,
        IncrementFailure::LinearSolve {
            failure: LinearFailure::NotPositiveDefinite | LinearFailure::Singular,
            ..
        }
    )
}

/// A factorization of the tangent, by Cholesky or, where it is indefinite, `L D L^T`.
pub enum Solver {
    /// `K = L L^T`.
    Definite(Factorization),
    /// `K = L D L^T`.
    Indefinite(IndefiniteFactorization),
}

impl Solver {
    /// Solves `K x = b`.
    pub fn solve(&self, b: &DVector<f64>) -> DVector<f64> {
        match self {
            Self::Definite(f) => f.solve(b),
            Self::Indefinite(f) => f.solve(b),
        }
    }
}

/// The element loop of [`Assembler::internal`] and what it reads.
struct ElementLoop<'a, const D: usize> {
    model: &'a Model<D>,
    x: &'a DVector<f64>,
    /// `c_K`, if the tangent is assembled.
    tangent_factor: Option<f64>,
    damping: Option<Damping<'a>>,
    mixed: &'a MixedPressures,
    scatter: &'a [ElementScatter],
}

/// What the element loop writes per element, for a range of elements.
struct ElementOutputs<'a> {
    responses: &'a mut [ElementResponse],
    damping: &'a mut [[f64; MAX_COMPONENTS]],
}

impl<const D: usize> ElementLoop<'_, D> {
    /// Evaluates the elements `first..first + responses.len()` in order into `out`, and with
    /// a tangent factor `c` sets their value slots, `values` (theirs alone: they follow one
    /// another in element order), to `c K_e`, or with damping (see [`Damping`]) to
    /// `c (K_e + beta rate K_e^cons)`.
    ///
    /// # Errors
    /// The failure of the first element that fails; the elements after it are not evaluated.
    fn run(
        &self,
        first: usize,
        out: ElementOutputs<'_>,
        mut values: &mut [f64],
    ) -> Result<(), IncrementFailure> {
        let (part, dofs) = (self.model.part(), self.model.dofs());
        let mut k = [0.0; MAX_COMPONENTS * MAX_COMPONENTS];
        let mut k_mixed = [0.0; MAX_COMPONENTS * MAX_COMPONENTS];
        for (e, (response, damping_force)) in
            (first..).zip(out.responses.iter_mut().zip(out.damping.iter_mut()))
        {
            let element = &self.model.elements()[e];
            let mut u = [SVector::zeros(); MAX_NODES];
            for (u_a, &node) in u.iter_mut().zip(&part.mesh.elements[e]) {
                *u_a = dofs.node_displacement(self.x, node);
            }
            let u = &u[..element.node_count()];
            let failure = |err| element_failure(e, err);
            let components = D * element.node_count();
            let scatter = &self.scatter[e];
            let beta = part.section(e).stiffness_damping;
            let damping = self.damping.filter(|_| beta > 0.0);
            let tangent = self.mixed.tangent(e);
            let k = &mut k[..components * components];
            match (self.tangent_factor, damping) {
                (None, None) => {
                    *response = element.respond(part.material(e), u).map_err(failure)?;
                    continue;
                }
                (Some(_), None) => {
                    *response = element
                        .respond_with_tangent(part.material(e), u, tangent, k)
                        .map_err(failure)?;
                }
                (_, Some(d)) => {
                    // the damping force takes the consistent tangent, so that the residual
                    // does not depend on the Newton path
                    *response = element
                        .respond_with_tangent(part.material(e), u, Tangent::Consistent, k)
                        .map_err(failure)?;
                    for (p, f) in damping_force[..components].iter_mut().enumerate() {
                        *f = beta
                            * (scatter.eqs.iter().enumerate())
                                .filter_map(|(q, eq)| {
                                    eq.map(|eq| k[p + q * components] * d.velocity[eq])
                                })
                                .sum::<f64>();
                    }
                    if self.tangent_factor.is_none() {
                        continue;
                    }
                    if tangent == Tangent::Consistent {
                        k.iter_mut().for_each(|v| *v *= 1.0 + beta * d.rate);
                    } else {
                        let k_mixed = &mut k_mixed[..components * components];
                        element
                            .respond_with_tangent(part.material(e), u, tangent, k_mixed)
                            .map_err(failure)?;
                        for (v, m) in k.iter_mut().zip(k_mixed.iter()) {
                            *v = m + beta * d.rate * *v;
                        }
                    }
                }
            }
            let Some(c) = self.tangent_factor else {
                continue;
            };
            let (own, rest) = std::mem::take(&mut values).split_at_mut(scatter.entries.len());
            scatter.write(own, c, k);
            values = rest;
        }
        Ok(())
    }

    /// [`Self::run`] on halves of the range, evaluated in parallel, until a part has at most
    /// [`ELEMENTS_PER_TASK`] elements. Every element writes only its own outputs and slots,
    /// so the results do not depend on the threads.
    ///
    /// # Errors
    /// The failure of the lowest-numbered failing element, as [`Self::run`] on the whole range
    /// (the first half's failure is returned before the second's).
    fn run_parallel(
        &self,
        first: usize,
        out: ElementOutputs<'_>,
        values: &mut [f64],
    ) -> Result<(), IncrementFailure> {
        if out.responses.len() <= ELEMENTS_PER_TASK {
            return self.run(first, out, values);
        }
        let middle = out.responses.len() / 2;
        let (left, right) = out.responses.split_at_mut(middle);
        let (left_damping, right_damping) = out.damping.split_at_mut(middle);
        let split = self.scatter[first + middle].first_slot - self.scatter[first].first_slot;
        let (left_values, right_values) = values.split_at_mut(split);
        let (left, right) = rayon::join(
            || {
                let out = ElementOutputs {
                    responses: left,
                    damping: left_damping,
                };
                self.run_parallel(first, out, left_values)
            },
            || {
                let out = ElementOutputs {
                    responses: right,
                    damping: right_damping,
                };
                self.run_parallel(first + middle, out, right_values)
            },
        );
        left.and(right)
    }
}

/// [`Assembler::stiffness_scale`] of `model`, from its elements' consistent tangents at the
/// reference configuration.
///
/// # Errors
/// The failure of an element that cannot be evaluated there.
fn stiffness_scale<const D: usize>(
    model: &Model<D>,
    scatter: &[ElementScatter],
) -> Result<DVector<f64>, ModelError> {
    let part = model.part();
    let mut scale = DVector::zeros(model.dofs().len());
    let mut k = [0.0; MAX_COMPONENTS * MAX_COMPONENTS];
    let u = [SVector::<f64, D>::zeros(); MAX_NODES];
    for (e, (element, scatter)) in model.elements().iter().zip(scatter).enumerate() {
        let components = D * element.node_count();
        let k = &mut k[..components * components];
        element
            .respond_with_tangent(
                part.material(e),
                &u[..element.node_count()],
                Tangent::Consistent,
                k,
            )
            .map_err(|err| ModelError::Invalid(format!("element {e}: {err}")))?;
        let measure = if D == 2 {
            element.volume() / part.thickness
        } else {
            element.volume()
        };
        let size = measure.powf(1.0 / D as f64);
        for (p, eq) in scatter.eqs.iter().enumerate() {
            if let Some(eq) = eq {
                scale[*eq] += k[p + p * components].abs() * size;
            }
        }
    }
    Ok(scale)
}

/// The increment failure of element `e` failing with `err`.
fn element_failure(e: usize, err: FemError) -> IncrementFailure {
    match err {
        FemError::InvertedElement { det_f, corner } => IncrementFailure::InvertedElement {
            element: e,
            det_f,
            corner,
        },
        other => IncrementFailure::Element {
            element: e,
            message: other.to_string(),
        },
    }
}

/// How many tenfold increases of the mass shift [`Assembler::with_mass_shift`] tries before it
/// reports the tangent as indefinite.
pub const MAX_SHIFT_DECADES: usize = 8;

/// Inverse-iteration steps of [`Assembler::is_held`].
const INVERSE_ITERATIONS: usize = 3;

/// A tangent whose lowest eigenvalue against the mass is below this fraction of its largest
/// diagonal ratio `K_ii / M_ii` leaves a motion free (see [`Assembler::is_held`]).
const SINGULAR_RATIO: f64 = 1e-12;

/// External nodal forces per equation at `instant`: `f = sum_l c_l f_l` with each load's
/// factor `c_l` (its amplitude at the step time, or the ramp; see [`crate::loads`]), the
/// pressures' `f_l` on the current geometry at `x` (follower pressure), the dead loads' fixed,
/// but for their moments `M` on bodies free to turn, which act on the body-frame rotation
/// equations as `Q^T M` with the body's orientation `Q` at `x` from the records `orientations`
/// (see [`crate::orientation`]; their load stiffness, the skew `[Q^T M]x`, is left out of the
/// tangent).
pub fn external_forces<const D: usize>(
    model: &Model<D>,
    x: &DVector<f64>,
    orientations: &[Orientation],
    instant: LoadInstant,
) -> Result<DVector<f64>, IncrementFailure> {
    let mut f = DVector::zeros(model.dofs().len());
    let mesh = &model.part().mesh;
    let mut xf: Vec<SVector<f64, D>> = Vec::new();
    for load in model.pressures() {
        let pressure = instant.factor(&load.variation) * load.pressure;
        for face in &load.faces {
            xf.clear();
            xf.extend(
                face.iter()
                    .map(|&n| mesh.nodes[n] + model.dofs().node_displacement(x, n)),
            );
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
        let factor = instant.factor(&load.variation);
        f.axpy(factor, &load.force, 1.0);
        for &(body, moment) in &load.body_moments {
            let q = orientation(model.dofs(), model.bodies(), orientations, x, body);
            let local = q.inverse_transform_vector(&moment) * factor;
            for (&eq, m) in model.dofs().body_rotations(body).iter().zip(local.iter()) {
                f[eq] += m;
            }
        }
    }
    Ok(f)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::loads::Loads;
    use crate::model::Tie;
    use crate::test_support::{body, central_difference, pad_block};
    use nalgebra::DMatrix;
    use skid_fem::rigid::Rotation;
    use skid_fem::solid::Tangent;

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

    /// A 3 x 2 block whose top nodes are tied to a plate translating in y, in 2D or 3D, with
    /// stiffness damping `beta`.
    fn tied_block<const D: usize>(beta: f64) -> Model<D> {
        let mut part = pad_block::<D>([0.0; 3], [0.03, 0.02, 0.01], [3, 2, 1]);
        part.sections[0].stiffness_damping = beta;
        let top = part.mesh.node_sets["ymax"].clone();
        let mut free = [false; D];
        free[1] = true;
        let plate = body::<D>("plate", free, Rotation::None, 0.0, 0.0);
        let tie = Tie {
            body: 0,
            nodes: top,
        };
        Model::new(part, vec![plate], vec![tie], Loads::default(), vec![]).expect("model")
    }

    /// The assembled tangent (through the DOF map, ties included) is the derivative of the
    /// assembled internal force.
    fn tangent_matches_finite_differences<const D: usize>() {
        let model = tied_block::<D>(0.0);
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
            let column = central_difference(&x, j, eps, |x| {
                assembler.internal(&model, x, None).expect("f").force
            });
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

    /// With stiffness damping `beta`, the force is `beta K v` and the tangent
    /// `K + beta rate K`: the derivative of `f_int(x) + beta K(x) v(x)` with
    /// `v(x) = rate (x - x0)` at `x0`, where `v = 0` and the left-out `beta (dK/dx) v`
    /// vanishes.
    fn damped_tangent_matches_finite_differences<const D: usize>() {
        let (beta, rate) = (2e-4, 3.0e3);
        let model = tied_block::<D>(beta);
        let n = model.dofs().len();
        let mut assembler = Assembler::new(&model).expect("assembler");
        let x0 = DVector::from_fn(n, |i, _| {
            1e-3 * ((i as f64 * 1.7).sin() + 0.3 * (i as f64).cos())
        });
        // the force: beta K v, K the undamped tangent
        assembler
            .internal(&model, &x0, Some(1.0))
            .expect("internal");
        let k = assembler.dense(n);
        let v = DVector::from_fn(n, |i, _| (i as f64 * 0.9).cos());
        let damping = Some(Damping { velocity: &v, rate });
        let state = assembler
            .internal_damped(&model, &x0, None, damping)
            .expect("damped");
        let expected = &k * &v * beta;
        assert!(
            (&state.damping_force - &expected).amax() < 1e-12 * expected.amax(),
            "{D}D: damping force"
        );
        // the tangent
        let zero = DVector::zeros(n);
        let at_rest = Some(Damping {
            velocity: &zero,
            rate,
        });
        assembler
            .internal_damped(&model, &x0, Some(1.0), at_rest)
            .expect("damped tangent");
        let kd = assembler.dense(n);
        let eps = 1e-7;
        let mut worst: f64 = 0.0;
        for j in 0..n {
            let column = central_difference(&x0, j, eps, |x| {
                let v = (x - &x0) * rate;
                let damping = Some(Damping { velocity: &v, rate });
                let s = assembler
                    .internal_damped(&model, x, None, damping)
                    .expect("f");
                s.force + s.damping_force
            });
            worst = worst.max((column - kd.column(j)).amax());
        }
        assert!(
            worst < 1e-6 * kd.amax(),
            "{D}D: worst {worst:e} vs {:e}",
            kd.amax()
        );
        assert!((kd.amax() / k.amax() - (1.0 + beta * rate)).abs() < 1e-12);
    }

    /// Between Newton iterates an element's tangent may take its mixed pressure (see
    /// [`crate::mixed`]); the damping then adds `beta rate` times the consistent tangent, as
    /// its force takes the consistent one.
    #[test]
    fn damping_adds_the_consistent_tangent_to_a_mixed_one() {
        let (beta, rate) = (2e-4, 3.0e3);
        let mut part = pad_block::<2>([0.0; 3], [0.03, 0.02, 0.01], [3, 2, 1]);
        part.sections[0].stiffness_damping = beta;
        part.fixed = part.mesh.node_sets["ymin"]
            .iter()
            .flat_map(|&n| [(n, 0), (n, 1)])
            .collect();
        let model = Model::new(part, vec![], vec![], Loads::default(), vec![]).expect("model");
        let n = model.dofs().len();
        let x0 = DVector::zeros(n);
        let x1 = DVector::from_fn(n, |i, _| 2e-3 * (i as f64 * 1.3).sin());
        let mut mixed = Assembler::new(&model).expect("assembler");
        mixed.start_mixed_pressures(&model, &x0).expect("start");
        mixed.advance_mixed_pressures(&model, &(&x1 - &x0));
        mixed.internal(&model, &x1, Some(1.0)).expect("mixed");
        let k_mixed = mixed.dense(n);
        let zero = DVector::zeros(n);
        let at_rest = Some(Damping {
            velocity: &zero,
            rate,
        });
        mixed
            .internal_damped(&model, &x1, Some(1.0), at_rest)
            .expect("damped");
        let k_damped = mixed.dense(n);
        let mut consistent = Assembler::new(&model).expect("assembler");
        consistent
            .internal(&model, &x1, Some(1.0))
            .expect("consistent");
        let k_consistent = consistent.dense(n);
        assert!(
            (&k_mixed - &k_consistent).amax() > 1e-6 * k_consistent.amax(),
            "the mixed tangent differs from the consistent one here"
        );
        let expected = &k_mixed + &k_consistent * (beta * rate);
        assert!((&k_damped - &expected).amax() < 1e-12 * expected.amax());
    }

    #[test]
    fn damped_tangent_matches_finite_differences_2d() {
        damped_tangent_matches_finite_differences::<2>();
    }

    #[test]
    fn damped_tangent_matches_finite_differences_3d() {
        damped_tangent_matches_finite_differences::<3>();
    }

    #[test]
    fn assembled_tangent_matches_finite_differences_2d() {
        tangent_matches_finite_differences::<2>();
    }

    #[test]
    fn assembled_tangent_matches_finite_differences_3d() {
        tangent_matches_finite_differences::<3>();
    }

    /// A 3D block of [`PARALLEL_ELEMENT_THRESHOLD`] elements (the parallel loop), its base
    /// fixed.
    fn large_block() -> Model<3> {
        let mut part = pad_block::<3>([0.0; 3], [0.08, 0.04, 0.04], [8, 8, 4]);
        assert_eq!(part.mesh.elements.len(), PARALLEL_ELEMENT_THRESHOLD);
        part.fixed = part.mesh.node_sets["ymin"]
            .iter()
            .flat_map(|&n| (0..3).map(move |i| (n, i)))
            .collect();
        Model::new(part, vec![], vec![], Loads::default(), vec![]).expect("model")
    }

    /// Writing each element's scaled stiffness straight into its own slots (in parallel on a
    /// large model, in sequence on a small one) assembles, bit for bit, what adding the element
    /// responses one by one into zeroed values gives; so do the forces.
    fn check_in_place_assembly<const D: usize>(model: &Model<D>) {
        let n = model.dofs().len();
        let mut assembler = Assembler::new(model).expect("assembler");
        let x = DVector::from_fn(n, |i, _| 1e-3 * (i as f64 * 0.7).sin());
        // a mixed tangent at predicted pressures, as in a Newton iteration
        assembler.internal(model, &x, None).expect("internal");
        let dx = DVector::from_fn(n, |i, _| 1e-4 * (i as f64 * 1.3).cos());
        assembler.advance_mixed_pressures(model, &dx);
        let x = &x + &dx;
        let c = 1.7;
        let state = assembler.internal(model, &x, Some(c)).expect("internal");

        let mut values = vec![0.0; assembler.values.len()];
        let mut force = DVector::zeros(n);
        let elements = model.elements().iter().zip(&assembler.scatter);
        for (e, (element, scatter)) in elements.enumerate() {
            let u: Vec<_> = (model.part().mesh.elements[e].iter())
                .map(|&node| model.dofs().node_displacement(&x, node))
                .collect();
            let m = D * element.node_count();
            let mut k = vec![0.0; m * m];
            let tangent = assembler.mixed.tangent(e);
            assert!(matches!(tangent, Tangent::Mixed { .. }));
            let r = element
                .respond_with_tangent(model.part().material(e), &u, tangent, &mut k)
                .expect("element");
            scatter.add(&mut values, c, &k);
            for (eq, f) in scatter.eqs.iter().zip(r.force()) {
                if let Some(eq) = eq {
                    force[*eq] += f;
                }
            }
        }
        assert_eq!(assembler.values, values, "{D}D");
        assert_eq!(state.force, force, "{D}D");
    }

    #[test]
    fn in_place_assembly_matches_element_by_element_addition() {
        check_in_place_assembly(&large_block());
        check_in_place_assembly(&tied_block::<2>(0.0));
        check_in_place_assembly(&tied_block::<3>(0.0));
    }

    /// The parallel loop reports the failure of the lowest-numbered failing element, as the
    /// sequential loop does, with or without a tangent.
    #[test]
    fn element_loop_reports_the_first_failing_element() {
        let model = large_block();
        let mut x = DVector::zeros(model.dofs().len());
        let nodes = model.part().mesh.nodes.len();
        for node in [nodes - 20, nodes / 2] {
            for eq in model.dofs().node(node).iter().flatten() {
                x[*eq] = -0.05;
            }
        }
        let fails = |e: usize| {
            let u: Vec<_> = (model.part().mesh.elements[e].iter())
                .map(|&node| model.dofs().node_displacement(&x, node))
                .collect();
            model.elements()[e]
                .respond(model.part().material(e), &u)
                .is_err()
        };
        let first = (0..model.elements().len()).find(|&e| fails(e));
        assert!(first.is_some_and(|e| e > 0));
        let mut assembler = Assembler::new(&model).expect("assembler");
        for tangent_factor in [None, Some(1.0)] {
            let failure = assembler.internal(&model, &x, tangent_factor);
            assert!(
                matches!(failure, Err(IncrementFailure::InvertedElement { element, .. }) if Some(element) == first),
                "{failure:?} vs {first:?}"
            );
        }
    }

    /// An indefinite matrix gets mass added tenfold at a time until it factorizes; a failure
    /// other than an indefinite matrix is passed on at once.
    #[test]
    fn mass_shift_escalates_until_the_matrix_factorizes() {
        let model = tied_block::<2>(0.0);
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
            .with_mass_shift(&mass, (1e3, 1e3), &held, |a| a.factorize())
            .expect("shifted");
        assert!((1e9..=1e11).contains(&c), "c = {c:e}");
        let mut calls = 0;
        let failure = assembler.with_mass_shift(&mass, (1e3, 1e3), &held, |_| -> Result<(), _> {
            calls += 1;
            Err(IncrementFailure::NonFinite { iteration: 0 })
        });
        assert!(matches!(failure, Err(IncrementFailure::NonFinite { .. })));
        assert_eq!(calls, 1);
    }

    #[test]
    fn held_equations_get_identity_rows() {
        let model = tied_block::<2>(0.0);
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
