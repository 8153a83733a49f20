//! Right-preconditioned GMRES for unsymmetric systems `A z = b` that an earlier factorization
//! nearly solves.
//!
//! With the preconditioner `M^{-1}` (here the LU factors of a nearby matrix), GMRES builds the
//! Krylov basis `V` of `A M^{-1}` by Arnoldi with modified Gram–Schmidt and minimises
//! `||b - A M^{-1} V y||` over `y` by Givens rotations of the Hessenberg matrix; the solution is
//! `z = Z y` with `Z = M^{-1} V` kept column by column. Where `A` differs from the factorized
//! matrix by a term of rank `k`, `A M^{-1}` is the identity plus a rank-`k` term and GMRES
//! terminates in at most `k + 1` iterations.

use nalgebra::{DMatrix, DVector};

/// The vectors [`gmres`] works with, kept from one call to the next so that repeated solves of
/// one size allocate nothing (on systems of 1e5 unknowns each vector is 0.8 MB, which the
/// allocator would otherwise map and fault in afresh at every call).
#[derive(Debug, Default)]
pub struct Workspace {
    /// The orthonormal Krylov basis `V`, column by column.
    basis: Vec<DVector<f64>>,
    /// `Z = M^{-1} V`, column by column.
    preconditioned: Vec<DVector<f64>>,
    /// `A z_j`, orthogonalised into the next basis vector.
    w: DVector<f64>,
}

/// Vector `j` of `list`, of length `n` (added or resized as needed; its values are stale).
fn slot(list: &mut Vec<DVector<f64>>, j: usize, n: usize) -> &mut DVector<f64> {
    while list.len() <= j {
        list.push(DVector::zeros(n));
    }
    let v = &mut list[j];
    if v.len() != n {
        *v = DVector::zeros(n);
    }
    v
}

/// Solves `A z = b` from `z = 0` by GMRES without restart, right-preconditioned by `m_inv`,
/// stopping once the residual estimate is below `tolerance ||b||` or after `max_iterations`.
/// `apply_a(v, out)` writes `A v`, `m_inv(v, out)` writes `M^{-1} v` (every entry of `out`).
/// Returns `z` and the number of iterations, or `None` if the tolerance was not reached.
pub fn gmres(
    mut apply_a: impl FnMut(&DVector<f64>, &mut DVector<f64>),
    mut m_inv: impl FnMut(&DVector<f64>, &mut DVector<f64>),
    b: &DVector<f64>,
    (tolerance, max_iterations): (f64, usize),
    workspace: &mut Workspace,
) -> Option<(DVector<f64>, usize)> {
    let n = b.len();
    let beta = b.norm();
    if beta == 0.0 {
        return Some((DVector::zeros(n), 0));
    }
    if !beta.is_finite() {
        return None;
    }
    let k = max_iterations;
    let Workspace {
        basis,
        preconditioned,
        w,
    } = workspace;
    if w.len() != n {
        *w = DVector::zeros(n);
    }
    slot(basis, 0, n).copy_from(&(b / beta));
    let mut hessenberg = DMatrix::<f64>::zeros(k + 1, k);
    let mut rotations: Vec<(f64, f64)> = Vec::with_capacity(k);
    let mut g = DVector::<f64>::zeros(k + 1);
    g[0] = beta;
    for j in 0..k {
        let z = slot(preconditioned, j, n);
        m_inv(&basis[j], z);
        apply_a(z, w);
        for (i, v) in basis.iter().take(j + 1).enumerate() {
            let h = w.dot(v);
            hessenberg[(i, j)] = h;
            w.axpy(-h, v, 1.0);
        }
        let norm = w.norm();
        hessenberg[(j + 1, j)] = norm;
        for (i, &(c, s)) in rotations.iter().enumerate() {
            let (a, b) = (hessenberg[(i, j)], hessenberg[(i + 1, j)]);
            hessenberg[(i, j)] = c * a + s * b;
            hessenberg[(i + 1, j)] = -s * a + c * b;
        }
        let (a, b) = (hessenberg[(j, j)], hessenberg[(j + 1, j)]);
        let radius = a.hypot(b);
        if radius == 0.0 || !radius.is_finite() {
            return None;
        }
        let (c, s) = (a / radius, b / radius);
        rotations.push((c, s));
        hessenberg[(j, j)] = radius;
        hessenberg[(j + 1, j)] = 0.0;
        g[j + 1] = -s * g[j];
        g[j] *= c;
        let converged = g[j + 1].abs() <= tolerance * beta;
        if converged || norm == 0.0 {
            let size = j + 1;
            let upper = hessenberg.view((0, 0), (size, size));
            let y = upper.solve_upper_triangular(&g.rows(0, size))?;
            let mut solution = DVector::zeros(n);
            for (yi, zi) in y.iter().zip(preconditioned.iter()) {
                solution.axpy(*yi, zi, 1.0);
            }
            return Some((solution, size));
        }
        let next = slot(basis, j + 1, n);
        next.copy_from(w);
        *next /= norm;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An unsymmetric matrix and its factorization before a rank-2 change: GMRES on the changed
    /// matrix, preconditioned by the old inverse, solves it to round-off in at most 3 iterations;
    /// a budget too small for the change gives `None`.
    #[test]
    fn low_rank_change_needs_rank_plus_one_iterations() {
        let n = 40;
        let old = DMatrix::from_fn(n, n, |i, j| {
            if i == j {
                4.0 + (i as f64).sin()
            } else {
                0.3 * ((3 * i + 7 * j) as f64).cos() / n as f64
            }
        });
        let u = DMatrix::from_fn(n, 2, |i, j| ((i + 5 * j) as f64 * 0.7).sin());
        let v = DMatrix::from_fn(2, n, |i, j| ((2 * j + i) as f64 * 1.1).cos());
        let new = &old + &u * &v;
        let old_inverse = old.clone().try_inverse().expect("invertible");
        let b = DVector::from_fn(n, |i, _| 1.0 + (i as f64 * 0.37).cos());
        let apply = |x: &DVector<f64>, out: &mut DVector<f64>| out.copy_from(&(&new * x));
        let precondition =
            |x: &DVector<f64>, out: &mut DVector<f64>| out.copy_from(&(&old_inverse * x));
        let mut workspace = Workspace::default();
        let (z, iterations) =
            gmres(apply, precondition, &b, (1e-12, 10), &mut workspace).expect("converges");
        assert!(iterations <= 3, "{iterations} iterations");
        assert!((&new * &z - &b).norm() <= 1e-11 * b.norm());
        assert!(gmres(apply, precondition, &b, (1e-12, 1), &mut workspace).is_none());
        // the workspace of a larger system serves a smaller one
        let small = DMatrix::from_fn(5, 5, |i, j| if i == j { 2.0 } else { 0.1 });
        let rhs = DVector::from_element(5, 1.0);
        let (z, _) = gmres(
            |x, out| out.copy_from(&(&small * x)),
            |x, out| out.copy_from(x),
            &rhs,
            (1e-12, 5),
            &mut workspace,
        )
        .expect("converges");
        assert!((&small * &z - &rhs).norm() <= 1e-11);
    }
}
