//! The effective tangent's fixed sparsity pattern and its Cholesky factorization.
//!
//! The pattern (lower triangle) is fixed by the mesh connectivity, the ties and one diagonal
//! entry per equation; contact never enters it (friction is handled by the cone problem in the
//! contact forces). So the symbolic analysis (ordering, elimination tree) is computed once per
//! run and every Newton iteration only refactors numerically.
//!
//! Equations named as *trailing* (the contact equations) are eliminated last: the ordering is
//! the approximate minimum degree ordering of the other equations followed by the trailing ones.
//! With `P K P^T = L L^T` and the trailing set `C` last, the trailing diagonal block of `L` is the
//! Cholesky factor of the Schur complement `S = K_CC - K_CI K_II^{-1} K_IC`, and by the block
//! inverse formula `(K^{-1})_CC = S^{-1} = L_CC^{-T} L_CC^{-1}`: a dense inverse of the size of
//! `C`, instead of `|C|` sparse solves with the whole factor.
//!
//! A symmetric indefinite matrix (a compressed solid's tangent before its iterate has relaxed)
//! has no Cholesky factor; [`SparsePattern::factorize_indefinite`] factors it as
//! `P K P^T = L D L^T` (`D` diagonal of either sign, no pivoting) on the same analysis.

use std::sync::{Arc, OnceLock};

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::amd;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LdltRef, LltRef, SymbolicCholesky, SymbolicCholeskyRaw,
    SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::sparse::{Pair, SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};
use faer::{Conj, Mat, MatMut, MatRef, Side};
use nalgebra::{DMatrix, DVector};

use crate::error::{IncrementFailure, LinearFailure};

/// The system [`SparsePattern`]'s failures name.
const TANGENT: &str = "effective tangent";

/// `v` as a one-column faer matrix, for faer's solves and products in
/// place.
pub(crate) fn column_mut(v: &mut DVector<f64>) -> MatMut<'_, f64> {
    let n = v.len();
    MatMut::from_column_major_slice_mut(v.as_mut_slice(), n, 1)
}

/// The diagonal `K_jj` of a matrix given by its lower triangle `lower` (duplicate entries
/// summed).
pub(crate) fn diagonal(lower: SparseColMatRef<'_, usize, f64>) -> Vec<f64> {
    (0..lower.ncols())
        .map(|j| {
            let column = lower.row_idx_of_col_raw(j).iter().zip(lower.val_of_col(j));
            column.filter(|(i, _)| **i == j).map(|(_, v)| v).sum()
        })
        .collect()
}

/// `out = K x` for a symmetric `K` given by its lower triangle `lower` (an entry above the
/// diagonal would be counted twice, so there must be none).
pub(crate) fn symmetric_times(lower: SparseColMatRef<'_, usize, f64>, x: &[f64], out: &mut [f64]) {
    out.fill(0.0);
    for (j, &x_j) in x.iter().enumerate().take(lower.ncols()) {
        let mut column_sum = 0.0;
        for (&i, &a) in lower.row_idx_of_col_raw(j).iter().zip(lower.val_of_col(j)) {
            out[i] += a * x_j;
            if i != j {
                column_sum += a * x[i];
            }
        }
        out[j] += column_sum;
    }
}

/// Collects the (row, column) positions of the lower triangle in the order values will be
/// written, and hands out the slot of each.
#[derive(Debug, Default)]
pub struct PatternBuilder {
    pairs: Vec<Pair<usize, usize>>,
}

impl PatternBuilder {
    /// Registers entry (i, j) of the symmetric matrix and returns its value slot. Only the lower
    /// triangle is stored: (i, j) and (j, i) are the same entry.
    pub fn push(&mut self, i: usize, j: usize) -> usize {
        let (row, col) = if i >= j { (i, j) } else { (j, i) };
        self.pairs.push(Pair::new(row, col));
        self.pairs.len() - 1
    }
}

/// Fixed pattern plus the symbolic Cholesky analysis.
#[derive(Debug)]
pub struct SparsePattern {
    n: usize,
    symbolic: SymbolicSparseColMat<usize>,
    /// Per value slot, the position of its entry among the compressed values.
    positions: Vec<usize>,
    analysis: Arc<SymbolicCholesky<usize>>,
    trailing: Arc<[usize]>,
}

impl SparsePattern {
    /// Builds the pattern of an `n x n` matrix from the registered entries (duplicates are
    /// summed) and analyses it once, with the equations `trailing` (distinct, `< n`) eliminated
    /// last in the given order.
    ///
    /// # Errors
    /// A message if faer rejects the pattern (an index out of range) or `trailing` is not a set
    /// of distinct equations.
    pub fn new(n: usize, builder: PatternBuilder, trailing: &[usize]) -> Result<Self, String> {
        let (symbolic, _) = SymbolicSparseColMat::try_new_from_indices(n, n, &builder.pairs)
            .map_err(|e| format!("sparsity pattern: {e:?}"))?;
        let positions = builder
            .pairs
            .iter()
            .map(|p| {
                let start = symbolic.col_ptr()[p.col];
                let rows = symbolic.row_idx_of_col_raw(p.col);
                rows.binary_search(&p.row)
                    .map(|k| start + k)
                    .map_err(|_| format!("sparsity pattern: entry ({}, {}) lost", p.row, p.col))
            })
            .collect::<Result<_, _>>()?;
        let analysis = analyse(n, &symbolic, trailing)?;
        Ok(Self {
            n,
            symbolic,
            positions,
            analysis,
            trailing: trailing.into(),
        })
    }

    /// The equations eliminated last.
    pub fn trailing(&self) -> &[usize] {
        &self.trailing
    }

    /// Analyses the pattern again with the equations `trailing` eliminated last (nothing to do
    /// if they already are, in that order).
    ///
    /// # Errors
    /// A message if `trailing` is not a set of distinct equations `< n`.
    pub fn eliminate_last(&mut self, trailing: &[usize]) -> Result<(), String> {
        if *self.trailing != *trailing {
            self.analysis = analyse(self.n, &self.symbolic, trailing)?;
            self.trailing = trailing.into();
        }
        Ok(())
    }

    /// Number of value slots (registered entries, duplicates counted).
    pub fn slots(&self) -> usize {
        self.positions.len()
    }

    /// Matrix dimension.
    pub fn dim(&self) -> usize {
        self.n
    }

    /// Writes into `compressed` the values of the lower triangle of the matrix whose slot
    /// values are `values`, entries at the same position summed, in the order of the pattern
    /// (see [`Self::matrix`]).
    ///
    /// # Errors
    /// [`IncrementFailure::LinearSolve`] for non-finite values.
    pub fn compress(
        &self,
        values: &[f64],
        compressed: &mut Vec<f64>,
    ) -> Result<(), IncrementFailure> {
        if values.iter().any(|v| !v.is_finite()) {
            return Err(IncrementFailure::linear(TANGENT, LinearFailure::NonFinite));
        }
        compressed.clear();
        compressed.resize(self.symbolic.row_idx().len(), 0.0);
        for (&position, &value) in self.positions.iter().zip(values) {
            compressed[position] += value;
        }
        Ok(())
    }

    /// The lower triangle with the compressed values `compressed` (see [`Self::compress`]).
    pub fn matrix<'a>(&'a self, compressed: &'a [f64]) -> SparseColMatRef<'a, usize, f64> {
        SparseColMatRef::new(self.symbolic.as_ref(), compressed)
    }

    /// Numeric Cholesky factorization `K = L L^T` of the matrix of compressed values
    /// `compressed` (see [`Self::compress`]), reusing the symbolic analysis.
    ///
    /// # Errors
    /// [`IncrementFailure::LinearSolve`] if the matrix is not positive definite.
    pub fn factorize(&self, compressed: &[f64]) -> Result<Factorization, IncrementFailure> {
        let matrix = self.matrix(compressed);
        let par = faer::get_global_parallelism();
        let mut factor = vec![0.0; self.analysis.len_val()];
        let mut scratch = MemBuffer::new(
            self.analysis
                .factorize_numeric_llt_scratch::<f64>(par, Default::default()),
        );
        self.analysis
            .factorize_numeric_llt(
                &mut factor,
                matrix,
                Side::Lower,
                LltRegularization::default(),
                par,
                MemStack::new(&mut scratch),
                Default::default(),
            )
            .map_err(|_| IncrementFailure::linear(TANGENT, LinearFailure::NotPositiveDefinite))?;
        Ok(Factorization {
            analysis: Arc::clone(&self.analysis),
            factor,
            trailing: Arc::clone(&self.trailing),
            n: self.n,
            trailing_inverse: OnceLock::new(),
        })
    }

    /// Numeric `K = L D L^T` factorization without pivoting (`D` diagonal, of either sign) of
    /// the matrix of compressed values `compressed`, for a symmetric matrix that may be
    /// indefinite, reusing the symbolic analysis.
    ///
    /// # Errors
    /// [`IncrementFailure::LinearSolve`] with [`LinearFailure::Singular`] for a zero pivot or a
    /// factor that is not finite.
    pub fn factorize_indefinite(
        &self,
        compressed: &[f64],
    ) -> Result<IndefiniteFactorization, IncrementFailure> {
        let matrix = self.matrix(compressed);
        let par = faer::get_global_parallelism();
        let mut factor = vec![0.0; self.analysis.len_val()];
        let mut scratch = MemBuffer::new(
            self.analysis
                .factorize_numeric_ldlt_scratch::<f64>(par, Default::default()),
        );
        let singular = || IncrementFailure::linear(TANGENT, LinearFailure::Singular);
        self.analysis
            .factorize_numeric_ldlt(
                &mut factor,
                matrix,
                Side::Lower,
                LdltRegularization::default(),
                par,
                MemStack::new(&mut scratch),
                Default::default(),
            )
            .map_err(|_| singular())?;
        if factor.iter().any(|v| !v.is_finite()) {
            return Err(singular());
        }
        Ok(IndefiniteFactorization {
            analysis: Arc::clone(&self.analysis),
            factor,
            n: self.n,
        })
    }
}

/// A numeric `L D L^T` factorization of a symmetric, possibly indefinite matrix (see
/// [`SparsePattern::factorize_indefinite`]).
pub struct IndefiniteFactorization {
    analysis: Arc<SymbolicCholesky<usize>>,
    factor: Vec<f64>,
    n: usize,
}

impl IndefiniteFactorization {
    /// Solves `K x = b`.
    pub fn solve(&self, b: &DVector<f64>) -> DVector<f64> {
        let mut rhs = Mat::<f64>::from_fn(self.n, 1, |i, _| b[i]);
        let par = faer::get_global_parallelism();
        let mut scratch = MemBuffer::new(self.analysis.solve_in_place_scratch::<f64>(1, par));
        LdltRef::new(&self.analysis, &self.factor).solve_in_place_with_conj(
            Conj::No,
            rhs.as_mut(),
            par,
            MemStack::new(&mut scratch),
        );
        DVector::from_fn(self.n, |i, _| rhs[(i, 0)])
    }
}

/// The supernodal symbolic Cholesky analysis of `symbolic` with `trailing` eliminated last.
fn analyse(
    n: usize,
    symbolic: &SymbolicSparseColMat<usize>,
    trailing: &[usize],
) -> Result<Arc<SymbolicCholesky<usize>>, String> {
    let (forward, inverse) = trailing_last_ordering(n, symbolic.as_ref(), trailing)?;
    let permutation = faer::perm::PermRef::new_checked(&forward, &inverse, n);
    let params = CholeskySymbolicParams {
        supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
        ..Default::default()
    };
    factorize_symbolic_cholesky(
        symbolic.as_ref(),
        Side::Lower,
        SymmetricOrdering::Custom(permutation),
        params,
    )
    .map(Arc::new)
    .map_err(|e| format!("symbolic factorization: {e:?}"))
}

/// Elimination order (`forward[new] = old`, `inverse[old] = new`): the approximate minimum degree
/// ordering of the whole pattern with the `trailing` equations taken out of it and appended in the
/// given order. (Ordering the other equations by their own graph alone ignores their coupling to
/// the trailing block and gives more fill.)
fn trailing_last_ordering(
    n: usize,
    pattern: SymbolicSparseColMatRef<'_, usize>,
    trailing: &[usize],
) -> Result<(Vec<usize>, Vec<usize>), String> {
    let mut is_trailing = vec![false; n];
    for &eq in trailing {
        match is_trailing.get_mut(eq) {
            Some(flag) if !*flag => *flag = true,
            _ => return Err(format!("trailing equation {eq} repeated or out of range")),
        }
    }
    let mut order = vec![0usize; n];
    let mut order_inverse = vec![0usize; n];
    let mut scratch = MemBuffer::try_new(amd::order_maybe_unsorted_scratch::<usize>(
        n,
        pattern.compute_nnz(),
    ))
    .map_err(|e| format!("ordering: {e:?}"))?;
    amd::order_maybe_unsorted(
        &mut order,
        &mut order_inverse,
        pattern,
        amd::Control::default(),
        MemStack::new(&mut scratch),
    )
    .map_err(|e| format!("ordering: {e:?}"))?;
    let forward: Vec<usize> = order
        .into_iter()
        .filter(|&eq| !is_trailing[eq])
        .chain(trailing.iter().copied())
        .collect();
    let mut inverse = vec![0; n];
    for (new, &old) in forward.iter().enumerate() {
        inverse[old] = new;
    }
    Ok((forward, inverse))
}

/// A numeric Cholesky factorization.
pub struct Factorization {
    analysis: Arc<SymbolicCholesky<usize>>,
    factor: Vec<f64>,
    trailing: Arc<[usize]>,
    n: usize,
    /// [`Self::trailing_inverse`], computed on first use.
    trailing_inverse: OnceLock<DMatrix<f64>>,
}

impl Factorization {
    /// Solves `K x = b`.
    pub fn solve(&self, b: &DVector<f64>) -> DVector<f64> {
        let mut rhs = Mat::<f64>::from_fn(self.n, 1, |i, _| b[i]);
        self.solve_in_place(rhs.as_mut());
        DVector::from_fn(self.n, |i, _| rhs[(i, 0)])
    }

    fn solve_in_place(&self, rhs: MatMut<'_, f64>) {
        let par = faer::get_global_parallelism();
        let mut scratch = MemBuffer::new(
            self.analysis
                .solve_in_place_scratch::<f64>(rhs.ncols(), par),
        );
        LltRef::new(&self.analysis, &self.factor).solve_in_place_with_conj(
            Conj::No,
            rhs,
            par,
            MemStack::new(&mut scratch),
        );
    }

    /// The equations eliminated last, in the order of [`Self::trailing_inverse`].
    pub fn trailing(&self) -> &[usize] {
        &self.trailing
    }

    /// `(K^{-1})_CC`, the block of the inverse on the trailing equations `C` (in the order of
    /// [`Self::trailing`]): `S^{-1} = L_CC^{-T} L_CC^{-1}` from the trailing diagonal block of the
    /// factor (see the module documentation). Computed once per factorization.
    pub fn trailing_inverse(&self) -> &DMatrix<f64> {
        self.trailing_inverse
            .get_or_init(|| self.compute_trailing_inverse())
    }

    fn compute_trailing_inverse(&self) -> DMatrix<f64> {
        let c = self.trailing.len();
        let first = self.n - c;
        let mut l_cc = DMatrix::<f64>::zeros(c, c);
        let SymbolicCholeskyRaw::Supernodal(symbolic) = self.analysis.raw() else {
            unreachable!("the analysis is forced supernodal")
        };
        let factor = faer::sparse::linalg::cholesky::supernodal::SupernodalLltRef::new(
            symbolic,
            &self.factor,
        );
        for s in 0..symbolic.n_supernodes() {
            let node = factor.supernode(s);
            let (start, values) = (node.start(), node.val());
            // rows: the diagonal block start..start+width, then the pattern
            let rows = || (start..start + values.ncols()).chain(node.pattern().iter().copied());
            for local_col in first.saturating_sub(start)..values.ncols() {
                let (col, column) = (start + local_col - first, values.col(local_col));
                for (local_row, row) in rows().enumerate().skip(local_col) {
                    l_cc[(row - first, col)] = column[local_row];
                }
            }
        }
        let par = faer::get_global_parallelism();
        let mut inverse = DMatrix::<f64>::zeros(c, c);
        let mut scratch =
            MemBuffer::new(faer::linalg::cholesky::llt::inverse::inverse_scratch::<f64>(c, par));
        faer::linalg::cholesky::llt::inverse::inverse(
            MatMut::from_column_major_slice_mut(inverse.as_mut_slice(), c, c),
            MatRef::from_column_major_slice(l_cc.as_slice(), c, c),
            par,
            MemStack::new(&mut scratch),
        );
        // only the lower triangle is written
        inverse.fill_upper_triangle_with_lower_triangle();
        inverse
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The factorization of the matrix of slot values `values`.
    fn factorize_slots(
        pattern: &SparsePattern,
        values: &[f64],
    ) -> Result<Factorization, IncrementFailure> {
        let mut compressed = Vec::new();
        pattern.compress(values, &mut compressed)?;
        pattern.factorize(&compressed)
    }

    /// A 1D chain of springs plus masses: tridiagonal SPD matrix assembled element by element
    /// (duplicates summed), solved twice with the same symbolic analysis.
    #[test]
    fn assembled_chain_solves_and_reuses_the_analysis() {
        let n = 50;
        let mut builder = PatternBuilder::default();
        let mut element_slots = Vec::new();
        for e in 0..n - 1 {
            element_slots.push([
                builder.push(e, e),
                builder.push(e + 1, e),
                builder.push(e, e + 1),
                builder.push(e + 1, e + 1),
            ]);
        }
        let diag: Vec<usize> = (0..n).map(|i| builder.push(i, i)).collect();
        let pattern = SparsePattern::new(n, builder, &[]).expect("pattern");
        for k in [1.0, 7.5] {
            let mut values = vec![0.0; pattern.slots()];
            for s in &element_slots {
                values[s[0]] += k;
                values[s[1]] -= k; // lower entry
                // s[2] is the same (upper) entry stored as lower: add nothing twice
                values[s[3]] += k;
            }
            for &d in &diag {
                values[d] += 1.0;
            }
            let f = factorize_slots(&pattern, &values).expect("spd");
            let x_true = DVector::from_fn(n, |i, _| (i as f64 * 0.3).sin());
            // b = K x_true
            let mut b = x_true.clone();
            for e in 0..n - 1 {
                let d = x_true[e] - x_true[e + 1];
                b[e] += k * d;
                b[e + 1] -= k * d;
            }
            let x = f.solve(&b);
            assert!((x - &x_true).amax() < 1e-10);
        }
    }

    /// The block of the inverse on the trailing equations, read off the trailing block of the
    /// factor, is the block of the dense inverse: a 2D grid Laplacian plus a diagonal, with an
    /// edge of the grid and a scattered equation eliminated last.
    #[test]
    fn trailing_inverse_is_the_block_of_the_inverse() {
        let side = 9;
        let n = side * side;
        let mut builder = PatternBuilder::default();
        let mut entries = Vec::new();
        for i in 0..n {
            entries.push((builder.push(i, i), i, i, 4.5 + (i as f64 * 0.7).sin()));
            for j in [i + 1, i + side] {
                let neighbour = (j < n) && (j != i + 1 || j % side != 0);
                if neighbour {
                    entries.push((builder.push(j, i), j, i, -1.0));
                }
            }
        }
        let trailing: Vec<usize> = (0..side).map(|k| k * side).chain([40, 3]).collect();
        let pattern = SparsePattern::new(n, builder, &trailing).expect("pattern");
        let mut values = vec![0.0; pattern.slots()];
        let mut dense = DMatrix::<f64>::zeros(n, n);
        for &(slot, i, j, v) in &entries {
            values[slot] = v;
            dense[(i, j)] = v;
            dense[(j, i)] = v;
        }
        let factor = factorize_slots(&pattern, &values).expect("spd");
        assert_eq!(factor.trailing(), trailing.as_slice());
        let block = factor.trailing_inverse();
        let inverse = dense.try_inverse().expect("invertible");
        let expected = DMatrix::from_fn(trailing.len(), trailing.len(), |a, b| {
            inverse[(trailing[a], trailing[b])]
        });
        assert!(
            (block - &expected).amax() < 1e-12 * expected.amax(),
            "{block} vs {expected}"
        );
        // the solve is unaffected by the ordering
        let b = DVector::from_fn(n, |i, _| (i as f64).cos());
        assert!((factor.solve(&b) - &inverse * &b).amax() < 1e-12);
        // a repeated trailing equation is rejected
        assert!(SparsePattern::new(n, PatternBuilder::default(), &[1, 1]).is_err());
    }

    #[test]
    fn indefinite_matrix_is_reported_not_panicked() {
        let mut builder = PatternBuilder::default();
        let a = builder.push(0, 0);
        let b = builder.push(1, 1);
        let pattern = SparsePattern::new(2, builder, &[]).expect("pattern");
        let mut values = vec![0.0; pattern.slots()];
        values[a] = 1.0;
        values[b] = -1.0;
        assert!(matches!(
            factorize_slots(&pattern, &values),
            Err(IncrementFailure::LinearSolve {
                failure: LinearFailure::NotPositiveDefinite,
                ..
            })
        ));
        values[b] = f64::NAN;
        assert!(factorize_slots(&pattern, &values).is_err());
    }

    /// A symmetric indefinite tridiagonal matrix (diagonal alternating in sign) has no Cholesky
    /// factor but an `L D L^T` one, which solves it; a zero matrix is singular for it too.
    #[test]
    fn indefinite_matrix_factors_as_ldlt_and_solves() {
        let n = 6;
        let mut builder = PatternBuilder::default();
        let mut slots = Vec::new();
        for i in 0..n {
            slots.push((i, i, builder.push(i, i)));
            if i + 1 < n {
                slots.push((i + 1, i, builder.push(i + 1, i)));
            }
        }
        let pattern = SparsePattern::new(n, builder, &[]).expect("pattern");
        let entry = |i: usize, j: usize| {
            if i == j {
                if i.is_multiple_of(2) { 3.0 } else { -2.0 }
            } else {
                1.0
            }
        };
        let mut values = vec![0.0; pattern.slots()];
        for &(i, j, slot) in &slots {
            values[slot] = entry(i, j);
        }
        assert!(factorize_slots(&pattern, &values).is_err());
        let mut compressed = Vec::new();
        pattern.compress(&values, &mut compressed).expect("finite");
        let factor = pattern.factorize_indefinite(&compressed).expect("LDL^T");
        let b = DVector::from_fn(n, |i, _| 1.0 + i as f64);
        let x = factor.solve(&b);
        let k = DMatrix::from_fn(n, n, |i, j| {
            if i.abs_diff(j) <= 1 {
                entry(i.max(j), i.min(j))
            } else {
                0.0
            }
        });
        assert!((&k * &x - &b).amax() < 1e-12 * b.amax(), "{x}");
        let zero = vec![0.0; pattern.slots()];
        pattern.compress(&zero, &mut compressed).expect("finite");
        assert!(matches!(
            pattern.factorize_indefinite(&compressed),
            Err(IncrementFailure::LinearSolve {
                failure: LinearFailure::Singular,
                ..
            })
        ));
    }
}
