//! The effective tangent's fixed sparsity pattern and its Cholesky factorization.
//!
//! The pattern (lower triangle) is fixed by the mesh connectivity, the ties and one diagonal
//! entry per equation; contact never enters it (friction is handled by the cone problem in the
//! contact forces). So the symbolic analysis (ordering, elimination tree) is computed once per
//! run and every Newton iteration only refactors numerically.

use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{Argsort, Pair, SparseColMat, SymbolicSparseColMat};
use faer::{Mat, Side};
use nalgebra::{DMatrix, DVector};

use crate::error::IncrementFailure;

/// Message of [`SparsePattern::factorize`] for a matrix with NaN or infinite entries.
pub const NON_FINITE_TANGENT: &str = "non-finite entries in the effective tangent";

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
    argsort: Argsort<usize>,
    slots: usize,
    analysis: SymbolicLlt<usize>,
}

impl SparsePattern {
    /// Builds the pattern of an `n x n` matrix from the registered entries (duplicates are
    /// summed) and analyses it once.
    ///
    /// # Errors
    /// A message if faer rejects the pattern (an index out of range).
    pub fn new(n: usize, builder: PatternBuilder) -> Result<Self, String> {
        let (symbolic, argsort) = SymbolicSparseColMat::try_new_from_indices(n, n, &builder.pairs)
            .map_err(|e| format!("sparsity pattern: {e:?}"))?;
        let analysis = SymbolicLlt::try_new(symbolic.as_ref(), Side::Lower)
            .map_err(|e| format!("symbolic factorization: {e:?}"))?;
        Ok(Self {
            n,
            symbolic,
            argsort,
            slots: builder.pairs.len(),
            analysis,
        })
    }

    /// Number of value slots (registered entries, duplicates counted).
    pub fn slots(&self) -> usize {
        self.slots
    }

    /// Matrix dimension.
    pub fn dim(&self) -> usize {
        self.n
    }

    /// Numeric Cholesky factorization `K = L L^T` of the matrix whose slot values are `values`,
    /// reusing the symbolic analysis.
    ///
    /// # Errors
    /// [`IncrementFailure::LinearSolve`] if the matrix is not positive definite or not finite.
    pub fn factorize(&self, values: &[f64]) -> Result<Factorization, IncrementFailure> {
        if values.iter().any(|v| !v.is_finite()) {
            return Err(IncrementFailure::LinearSolve(NON_FINITE_TANGENT.into()));
        }
        let matrix = SparseColMat::new_from_argsort(self.symbolic.clone(), &self.argsort, values)
            .map_err(|e| IncrementFailure::LinearSolve(format!("{e:?}")))?;
        let llt = Llt::try_new_with_symbolic(self.analysis.clone(), matrix.as_ref(), Side::Lower)
            .map_err(|e| {
            IncrementFailure::LinearSolve(format!(
                "effective tangent is not positive definite ({e:?})"
            ))
        })?;
        Ok(Factorization { llt, n: self.n })
    }
}

/// A numeric Cholesky factorization.
pub struct Factorization {
    llt: Llt<usize, f64>,
    n: usize,
}

impl Factorization {
    /// Solves `K x = b`.
    pub fn solve(&self, b: &DVector<f64>) -> DVector<f64> {
        let mut rhs = Mat::<f64>::from_fn(self.n, 1, |i, _| b[i]);
        self.llt.solve_in_place(rhs.as_mut());
        DVector::from_fn(self.n, |i, _| rhs[(i, 0)])
    }

    /// Solves `K X = B` for several right-hand sides at once.
    pub fn solve_many(&self, b: &DMatrix<f64>) -> DMatrix<f64> {
        let mut rhs = Mat::<f64>::from_fn(self.n, b.ncols(), |i, j| b[(i, j)]);
        self.llt.solve_in_place(rhs.as_mut());
        DMatrix::from_fn(self.n, b.ncols(), |i, j| rhs[(i, j)])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
        let pattern = SparsePattern::new(n, builder).expect("pattern");
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
            let f = pattern.factorize(&values).expect("spd");
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
            let many = f.solve_many(&DMatrix::from_columns(&[b.clone(), b * 2.0]));
            assert!((many.column(1) - x_true * 2.0).amax() < 1e-10);
        }
    }

    #[test]
    fn indefinite_matrix_is_reported_not_panicked() {
        let mut builder = PatternBuilder::default();
        let a = builder.push(0, 0);
        let b = builder.push(1, 1);
        let pattern = SparsePattern::new(2, builder).expect("pattern");
        let mut values = vec![0.0; pattern.slots()];
        values[a] = 1.0;
        values[b] = -1.0;
        assert!(matches!(
            pattern.factorize(&values),
            Err(IncrementFailure::LinearSolve(_))
        ));
        values[b] = f64::NAN;
        assert!(pattern.factorize(&values).is_err());
    }
}
