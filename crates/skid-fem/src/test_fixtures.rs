//! Elements, deformations and helpers shared by the element kernels' unit tests.

use nalgebra::{DMatrix, Matrix3, SVector};

use crate::cell::{corners, embed, restrict};
use crate::error::FemError;
use crate::material::PolynomialN1;

/// The drum pad's material (nearly incompressible, K / mu about 2e4).
pub fn material() -> Result<PolynomialN1, FemError> {
    PolynomialN1::new(0.552e6, 0.138e6, 0.145e-6)
}

/// Deterministic pseudo-random number in [-0.5, 0.5].
pub fn jitter(k: usize) -> f64 {
    let s = (k as f64 * 12.9898 + 78.233).sin() * 43758.5453;
    s - s.floor() - 0.5
}

/// A distorted element around the box with half-widths 1.0, 0.6, 0.8.
pub fn distorted<const D: usize>() -> Vec<SVector<f64, D>> {
    let half = [1.0, 0.6, 0.8];
    corners::<D>()
        .iter()
        .enumerate()
        .map(|(a, c)| SVector::from_fn(|k, _| half[k] * c[k] + 0.3 * jitter(a * D + k)))
        .collect()
}

/// The deformation gradient `f` restricted to D dimensions: its in-plane block in 2D, with
/// `F33 = 1` and no out-of-plane shear.
pub fn in_plane<const D: usize>(f: Matrix3<f64>) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| {
        if i < D && j < D {
            f[(i, j)]
        } else if i == j {
            1.0
        } else {
            0.0
        }
    })
}

/// The displacements `(F - I) X` of the homogeneous deformation `f` at the points `x`.
pub fn affine<const D: usize>(f: &Matrix3<f64>, x: &[SVector<f64, D>]) -> Vec<SVector<f64, D>> {
    x.iter()
        .map(|x| restrict(&((f - Matrix3::identity()) * embed(x))))
        .collect()
}

/// A general finite deformation of the points `x`: the homogeneous `f` plus a non-affine
/// (hourglass-exciting) part of size `amplitude`.
pub fn general_u<const D: usize>(
    x: &[SVector<f64, D>],
    f: &Matrix3<f64>,
    amplitude: f64,
) -> Vec<SVector<f64, D>> {
    affine(f, x)
        .iter()
        .enumerate()
        .map(|(a, u)| u + SVector::from_fn(|k, _| amplitude * jitter(100 + a * D + k)))
        .collect()
}

/// `u` with its component `dof` (node-major) moved by `h`.
pub fn perturb<const D: usize>(u: &[SVector<f64, D>], dof: usize, h: f64) -> Vec<SVector<f64, D>> {
    let mut u = u.to_vec();
    u[dof / D][dof % D] += h;
    u
}

/// The response of `respond`, which writes an `n x n` tangent into its buffer (filled with NaN
/// first, so that an entry left unwritten shows), and that tangent as a dense matrix.
pub fn dense_tangent<R>(
    n: usize,
    respond: impl FnOnce(&mut [f64]) -> Result<R, FemError>,
) -> Result<(R, DMatrix<f64>), FemError> {
    let mut k = vec![f64::NAN; n * n];
    let r = respond(&mut k)?;
    Ok((r, DMatrix::from_vec(n, n, k)))
}
