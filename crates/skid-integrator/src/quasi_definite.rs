//! A symmetric quasi-definite approximation of the global contact system (see
//! [`crate::global_contact`]), factorized by sparse `L D L^T` as the preconditioner of GMRES on
//! the exact, unsymmetric system.
//!
//! With the contact rows negated, the global system of a Newton iteration is symmetric except
//! for the friction of sliding candidates. Keeping the constraint rows (the normal row of a
//! closed candidate, the tangential rows of a sticking one), the balanced tangential rows of a
//! sliding candidate in 3D across its sliding direction (`rho P du_T` softened by
//! `c rho P dr_T`, see [`skid_contact::coulomb::alart_curnier::LocalLaw::with_balanced_slide_rows`])
//! and decoupling the others (open candidates, frictionless tangential rows, the sliding
//! direction) gives
//!
//! ```text
//! S = [ K      -G   ]      G = rho H_C^T  (the constraint rows' columns; P H_T when sliding)
//!     [ -G^T   -E   ]      E = eps rho on constraint rows, rho on decoupled ones,
//!                              rho (d d^T + (c + eps) P) on a sliding candidate's tangential block
//! ```
//!
//! which is quasi-definite where `K` is positive definite, so `L D L^T` exists for any
//! symmetric ordering; faer's supernodal factorization costs about one Cholesky factorization
//! of `K`. The exact matrix `A` equals `diag(I, -I) S` but for the friction of sliding
//! candidates along their sliding direction (the force column `-rho H_d^T` and the row
//! `dr_d = mu dr_N`, of the order of `mu`) and the small `eps`, so
//! `M^{-1} v = S^{-1} diag(I, -I) v` is a close preconditioner of `A`. (Decoupling the whole
//! tangential block of a sliding candidate instead left GMRES short of its tolerance in 30
//! iterations on the 40 x 8 x 8 pad; with the balanced rows it takes 15-18.)
//! No pivot is regularised: where `K` is indefinite (a compressed pad in a static step) the
//! factorization may still exist with pivots of either sign, or fail; GMRES checks the result,
//! and the caller factorizes `A` itself where it does not converge. (faer's dynamic
//! regularisation by expected pivot signs gave wrong factors of these matrices in 0.24: a test
//! of a 24-equation case came back 375 times off.)

use std::sync::Arc;

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LdltRef, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
    factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::traits::ComplexField;
use faer::{Conj, MatMut, Side};
use nalgebra::DVector;

use crate::error::{IncrementFailure, LinearFailure};

/// Relative weight `eps` of the constraint rows' diagonal (see the module documentation). The
/// `L D L^T` factors lose accuracy as `eps` shrinks, since a constraint row eliminated before
/// its nodes leaves a pivot of `-eps rho`: in the unit test 1e-6 still inverts `S` to 1e-9,
/// 1e-8 does not (an error of 375 on entries of order 1). GMRES absorbs the `eps` that `S`
/// adds on the constraint rows.
pub const CONSTRAINT_REGULARIZATION: f64 = 1e-5;

/// The arithmetic of the factors.
///
/// GMRES only needs `M^{-1}` to a few digits (it solves to [`crate::global_contact`]'s inexact
/// tolerance, and checks its result on the true residual), so single-precision factors serve
/// as well as double ones where `S` is not too ill-conditioned, at half the memory traffic of
/// the triangular solves, which are bound by it, and with twice the width of the dense kernels.
/// Measured on `3d-refined` (20 ms of spin-down, 469 systems): the same 3,050 GMRES iterations
/// and the same history to 1e-10, the linear solves 12.9 s instead of 17.3 s. Single precision
/// needs an order that eliminates each constraint row after its nodes ([`crate::ordering`]):
/// a row eliminated first leaves a pivot of `-eps rho`, which costs `1 / eps` of the
/// precision (in the unit test, 5e-5 of error in the minimum degree order, against 1e-9 in
/// double).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Precision {
    /// `f32` factors.
    Single,
    /// `f64` factors.
    Double,
}

/// Scratch space of a numeric factorization and the requirement it was made for.
struct Scratch {
    required: StackReq,
    buffer: MemBuffer,
}

impl std::fmt::Debug for Scratch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Scratch")
            .field("required", &self.required)
            .finish_non_exhaustive()
    }
}

/// The numeric factor, in its precision.
#[derive(Debug)]
enum Factor {
    Single(Vec<f32>),
    Double(Vec<f64>),
}

/// The analysed pattern of `S` (lower triangle) and its last factorization.
#[derive(Debug, Default)]
pub struct QuasiDefinite {
    analysed: Option<Analysed>,
    /// The single-precision values of the last matrix factorized in single precision.
    single: Vec<f32>,
    /// The numeric factorization's scratch space, kept while the requirement stays the same.
    scratch: Option<Scratch>,
    /// Symbolic analyses performed.
    pub analyses: usize,
}

#[derive(Debug)]
struct Analysed {
    symbolic: Arc<SymbolicSparseColMat<usize>>,
    analysis: SymbolicCholesky<usize>,
    /// The last numeric factorization, if it succeeded.
    factor: Option<Factor>,
    /// Equations of the first block: rows from here on are contact rows.
    unknowns: usize,
    /// The elimination order, if not the minimum degree one.
    order: Option<Vec<usize>>,
    /// [`QuasiDefinite::factorization_cost`].
    cost: f64,
}

impl QuasiDefinite {
    /// Factorizes the matrix of lower triangle `symbolic` (entries `i >= j`) with `values`,
    /// whose first `unknowns` rows are the positive block, in the elimination order `order`
    /// (`order[k]` eliminated `k`-th; see [`crate::ordering`]) or, without one, the
    /// approximate minimum degree order, in the arithmetic `precision`. The symbolic analysis
    /// is kept for later matrices of the same pattern object (the same `Arc`), unknowns and
    /// order.
    ///
    /// # Errors
    /// [`IncrementFailure::LinearSolve`] if the pattern cannot be analysed, `order` is not a
    /// permutation of the unknowns, the values do not fit the pattern or are not finite, or the
    /// factorization fails.
    pub fn factorize(
        &mut self,
        symbolic: &Arc<SymbolicSparseColMat<usize>>,
        values: &[f64],
        unknowns: usize,
        order: Option<&[usize]>,
        precision: Precision,
    ) -> Result<(), IncrementFailure> {
        let fail = |what: &str, e: &dyn std::fmt::Debug| {
            IncrementFailure::linear(
                "quasi-definite preconditioner",
                LinearFailure::Structure(format!("{what}: {e:?}")),
            )
        };
        if values.len() != symbolic.row_idx().len() {
            return Err(fail("values", &"not one per entry of the pattern"));
        }
        if values.iter().any(|v| !v.is_finite()) {
            return Err(fail("values", &"not finite"));
        }
        let dim = symbolic.nrows();
        let same = self.analysed.as_ref().is_some_and(|a| {
            Arc::ptr_eq(&a.symbolic, symbolic)
                && a.unknowns == unknowns
                && a.order.as_deref() == order
        });
        if !same {
            let inverse = order.map(|order| inverse_permutation(order, dim));
            let ordering = match (order, &inverse) {
                (Some(forward), Some(Some(inverse))) => SymmetricOrdering::Custom(
                    faer::perm::PermRef::new_checked(forward, inverse, dim),
                ),
                (Some(_), _) => return Err(fail("order", &"not a permutation")),
                (None, _) => SymmetricOrdering::Amd,
            };
            let analysis = factorize_symbolic_cholesky(
                SymbolicSparseColMat::as_ref(symbolic),
                Side::Lower,
                ordering,
                CholeskySymbolicParams::default(),
            )
            .map_err(|e| fail("analysis", &e))?;
            self.analyses += 1;
            let cost = factorization_cost(&analysis);
            self.analysed = Some(Analysed {
                symbolic: Arc::clone(symbolic),
                analysis,
                factor: None,
                unknowns,
                order: order.map(<[usize]>::to_vec),
                cost,
            });
        }
        let a = self
            .analysed
            .as_mut()
            .ok_or_else(|| fail("analysis", &"missing"))?;
        let previous = a.factor.take();
        let scratch = &mut self.scratch;
        let factor = match precision {
            Precision::Single => {
                let single = &mut self.single;
                single.clear();
                single.extend(values.iter().map(|&v| v as f32));
                let mut factor = match previous {
                    Some(Factor::Single(factor)) => factor,
                    _ => Vec::new(),
                };
                factorize_numeric(&a.analysis, &a.symbolic, single, &mut factor, scratch)
                    .map_err(|e| fail("factorization", &e))?;
                Factor::Single(factor)
            }
            Precision::Double => {
                let mut factor = match previous {
                    Some(Factor::Double(factor)) => factor,
                    _ => Vec::new(),
                };
                factorize_numeric(&a.analysis, &a.symbolic, values, &mut factor, scratch)
                    .map_err(|e| fail("factorization", &e))?;
                Factor::Double(factor)
            }
        };
        a.factor = Some(factor);
        Ok(())
    }

    /// The time of a numeric factorization in units of one GMRES iteration preconditioned by
    /// it (see [`factorization_cost`]); 0 before the first analysis.
    pub fn factorization_cost(&self) -> f64 {
        self.analysed.as_ref().map_or(0.0, |a| a.cost)
    }

    /// True if the last factorization succeeded, for a matrix of dimension `dim`.
    pub fn factorizes(&self, dim: usize) -> bool {
        self.analysed
            .as_ref()
            .is_some_and(|a| a.factor.is_some() && a.symbolic.nrows() == dim)
    }

    /// Writes `M^{-1} v = S^{-1} diag(I, -I) v` into `out` (zeros if not factorized).
    pub fn precondition(&self, v: &DVector<f64>, out: &mut DVector<f64>) {
        let Some(a) = self.analysed.as_ref() else {
            out.fill(0.0);
            return;
        };
        let flip = |(i, vi): (usize, &f64)| if i < a.unknowns { *vi } else { -vi };
        match &a.factor {
            None => out.fill(0.0),
            Some(Factor::Double(factor)) => {
                for (o, value) in out.iter_mut().zip(v.iter().enumerate().map(flip)) {
                    *o = value;
                }
                solve_in_place(&a.analysis, factor, out.as_mut_slice());
            }
            Some(Factor::Single(factor)) => {
                let mut single: Vec<f32> =
                    v.iter().enumerate().map(flip).map(|x| x as f32).collect();
                solve_in_place(&a.analysis, factor, &mut single);
                for (o, &x) in out.iter_mut().zip(&single) {
                    *o = f64::from(x);
                }
            }
        }
    }
}

/// The numeric `L D L^T` factorization of the matrix of lower triangle `symbolic` with
/// `values`, into `factor` (resized to the analysis), without regularisation, in the scratch
/// space `kept` (made anew only when the requirement changes).
fn factorize_numeric<T: ComplexField>(
    analysis: &SymbolicCholesky<usize>,
    symbolic: &SymbolicSparseColMat<usize>,
    values: &[T],
    factor: &mut Vec<T>,
    kept: &mut Option<Scratch>,
) -> Result<(), String> {
    factor.resize(analysis.len_val(), T::zero_impl());
    let par = faer::get_global_parallelism();
    let required = analysis.factorize_numeric_ldlt_scratch::<T>(par, Default::default());
    let scratch = match kept.take() {
        Some(scratch) if scratch.required == required => kept.insert(scratch),
        _ => kept.insert(Scratch {
            required,
            buffer: MemBuffer::try_new(required).map_err(|e| format!("{e:?}"))?,
        }),
    };
    let scratch = &mut scratch.buffer;
    analysis
        .factorize_numeric_ldlt(
            factor,
            SparseColMatRef::new(symbolic.as_ref(), values),
            Side::Lower,
            LdltRegularization::default(),
            par,
            MemStack::new(scratch),
            Default::default(),
        )
        .map(|_| ())
        .map_err(|e| format!("{e:?}"))
}

/// Overwrites `x` with `(L D L^T)^{-1} x`.
fn solve_in_place<T: ComplexField>(analysis: &SymbolicCholesky<usize>, factor: &[T], x: &mut [T]) {
    let par = faer::get_global_parallelism();
    let mut scratch = MemBuffer::new(analysis.solve_in_place_scratch::<T>(1, par));
    let n = x.len();
    LdltRef::new(analysis, factor).solve_in_place_with_conj(
        Conj::No,
        MatMut::from_column_major_slice_mut(x, n, 1),
        par,
        MemStack::new(&mut scratch),
    );
}

/// How many times faster, per floating-point operation, the numeric factorization's dense
/// kernels run than the triangular solves, which stream the factor from memory once per flop
/// pair. Measured on the 3D analytical drum's global systems (release, one core): 9,965
/// unknowns, 8.5e8 factorization flops and 3.0e6 factor entries, 50 ms per factorization against
/// 6 ms per GMRES iteration (flop ratio 70, time ratio 8); 19,034 (60 x 8 x 12 pad): 96 against
/// 11; 114,000 (100 x 16 x 20): 273 against 24.
const FACTORIZATION_SPEEDUP: f64 = 10.0;

/// The time of a numeric factorization in the analysis `analysis`, in units of one GMRES
/// iteration (a solve with the factor, `4 nnz(L)` flops): the supernodal factorization's flops,
/// `sum_s w_s^3 / 3 + p_s w_s^2 + p_s^2 w_s` over supernodes of `w_s` columns and `p_s` rows
/// below their diagonal block, over `4 nnz(L)` and [`FACTORIZATION_SPEEDUP`]. A simplicial
/// analysis (small systems) counts as one iteration.
fn factorization_cost(analysis: &SymbolicCholesky<usize>) -> f64 {
    let SymbolicCholeskyRaw::Supernodal(supernodal) = analysis.raw() else {
        return 1.0;
    };
    let (begin, end) = (supernodal.supernode_begin(), supernodal.supernode_end());
    let rows = supernodal.col_ptr_for_row_idx();
    let flops: f64 = (0..supernodal.n_supernodes())
        .map(|s| {
            let w = (end[s] - begin[s]) as f64;
            let p = (rows[s + 1] - rows[s]) as f64;
            w * w * w / 3.0 + p * w * w + p * p * w
        })
        .sum();
    flops / (4.0 * analysis.len_val().max(1) as f64) / FACTORIZATION_SPEEDUP
}

/// `inverse[order[k]] = k`, or `None` if `order` is not a permutation of `0..dim`.
fn inverse_permutation(order: &[usize], dim: usize) -> Option<Vec<usize>> {
    if order.len() != dim {
        return None;
    }
    let mut inverse = vec![usize::MAX; dim];
    for (k, &unknown) in order.iter().enumerate() {
        match inverse.get_mut(unknown) {
            Some(slot) if *slot == usize::MAX => *slot = k,
            _ => return None,
        }
    }
    Some(inverse)
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::{SparseColMat, Triplet};
    use nalgebra::DMatrix;

    /// `S` of a spring chain with three constraint rows and one decoupled row: the
    /// preconditioner inverts `A = diag(I, -I) S` to round-off in double precision and to
    /// single precision's in single, in the minimum degree order and in an order that puts
    /// each constraint row after its nodes; a second factorization of the same pattern reuses
    /// the analysis, a new pattern object is analysed again, and an order that is not a
    /// permutation is refused.
    #[test]
    fn preconditioner_inverts_the_sign_flipped_quasi_definite_matrix() {
        let (n, m) = (20, 4);
        let dim = n + m;
        let mut entries: Vec<Triplet<usize, usize, f64>> = Vec::new();
        for i in 0..n {
            entries.push(Triplet::new(i, i, 2.5 + (i as f64 * 0.3).sin()));
            if i + 1 < n {
                entries.push(Triplet::new(i + 1, i, -1.0));
            }
        }
        let rho = 3.0;
        for (c, nodes) in [[2, 3], [9, 10], [15, 16]].iter().enumerate() {
            let row = n + c;
            entries.push(Triplet::new(row, nodes[0], -rho));
            entries.push(Triplet::new(row, nodes[1], 0.5 * rho));
            entries.push(Triplet::new(row, row, -CONSTRAINT_REGULARIZATION * rho));
        }
        entries.push(Triplet::new(n + 3, n + 3, -rho));
        let lower = SparseColMat::try_new_from_triplets(dim, dim, &entries).expect("matrix");
        let (symbolic, values) = lower.into_parts();
        let symbolic = Arc::new(symbolic);
        let mut s = DMatrix::<f64>::zeros(dim, dim);
        for e in &entries {
            s[(e.row, e.col)] += e.val;
            if e.row != e.col {
                s[(e.col, e.row)] += e.val;
            }
        }
        let flip = DMatrix::from_fn(dim, dim, |i, j| match (i == j, i < n) {
            (true, true) => 1.0,
            (true, false) => -1.0,
            _ => 0.0,
        });
        let a = &flip * &s;
        let rows_after_nodes: Vec<usize> = (0..n)
            .flat_map(|i| match i {
                3 => vec![3, n],
                10 => vec![10, n + 1],
                16 => vec![16, n + 2],
                _ => vec![i],
            })
            .chain([n + 3])
            .collect();
        let x = DVector::from_fn(dim, |i, _| (i as f64 * 0.7).cos());
        let orders = [None, Some(rows_after_nodes.as_slice())];
        for (precision, orders, tolerance) in [
            (Precision::Double, &orders[..], 1e-9),
            (Precision::Single, &orders[1..], 1e-5),
        ] {
            for &order in orders {
                let mut qd = QuasiDefinite::default();
                let mut back = DVector::zeros(dim);
                for _ in 0..2 {
                    qd.factorize(&symbolic, &values, n, order, precision)
                        .expect("factorize");
                    qd.precondition(&(&a * &x), &mut back);
                    assert!(
                        (&back - &x).amax() < tolerance,
                        "{precision:?} {order:?}: {back} vs {x}"
                    );
                }
                assert_eq!(qd.analyses, 1);
                assert!(qd.factorizes(dim) && !qd.factorizes(dim + 1));
                let copy = Arc::new((*symbolic).clone());
                qd.factorize(&copy, &values, n, order, precision)
                    .expect("factorize");
                assert_eq!(qd.analyses, 2);
            }
        }
        let mut twice = rows_after_nodes.clone();
        twice[0] = twice[1];
        assert!(
            QuasiDefinite::default()
                .factorize(&symbolic, &values, n, Some(&twice), Precision::Single)
                .is_err()
        );
    }
}
