//! Kinematics and stiffness assembly shared by the solid elements: deformation gradients from
//! shape-function gradients, the corner inversion check, input checks and the node-pair blocks
//! of the material and geometric stiffness.

use nalgebra::{Matrix3, Matrix6, SMatrix, SVector, Vector3};

use crate::cell::{MAX_NODES, corners, embed, jacobian, restrict, shape_gradients};
use crate::error::FemError;
use crate::material::VOIGT_INDEX;

/// Most gradients entering one integration point: the `2^D` nodes and up to 3 incompatible
/// modes, which enter the kinematics like extra nodes.
pub(crate) const MAX_GRADIENTS: usize = MAX_NODES + 3;

/// Per corner of the cell, the reference gradients `grad_X N_I` there that do not vanish, with
/// their node `I`.
pub(crate) type CornerGradients<const D: usize> = Vec<Vec<(usize, SVector<f64, D>)>>;

/// `value` if it is finite and `admissible`, else [`FemError::InvalidParameter`].
pub(crate) fn check_parameter(
    name: &'static str,
    value: f64,
    admissible: bool,
    expected: &'static str,
) -> Result<f64, FemError> {
    if admissible && value.is_finite() {
        Ok(value)
    } else {
        Err(FemError::InvalidParameter {
            name,
            value,
            expected,
        })
    }
}

/// Checks an element evaluation's inputs: `u` holds `nodes` finite vectors, and a stiffness
/// buffer of `stiffness_len` entries (if any) holds `(D nodes)^2`.
///
/// # Errors
/// [`FemError::LengthMismatch`], [`FemError::NonFinite`].
pub(crate) fn check_inputs<const D: usize>(
    u: &[SVector<f64, D>],
    nodes: usize,
    stiffness_len: Option<usize>,
) -> Result<(), FemError> {
    if u.len() != nodes {
        return Err(FemError::LengthMismatch {
            what: "nodal displacements",
            expected: nodes,
            found: u.len(),
        });
    }
    let components = D * nodes;
    if let Some(found) = stiffness_len
        && found != components * components
    {
        return Err(FemError::LengthMismatch {
            what: "element stiffness entries",
            expected: components * components,
            found,
        });
    }
    if u.iter().any(|v| !v.iter().all(|c| c.is_finite())) {
        return Err(FemError::NonFinite {
            what: "nodal displacements",
        });
    }
    Ok(())
}

/// `F = I + sum_I u_I (x) g_I` for the shape-function gradients `g_I` at one point, embedded in
/// 3D, from the pairs `(g_I, u_I)` (a node whose gradient vanishes adds nothing and may be left
/// out).
pub(crate) fn gradient_of<'a, const D: usize>(
    terms: impl Iterator<Item = (&'a SVector<f64, D>, &'a SVector<f64, D>)>,
) -> Matrix3<f64> {
    terms.fold(Matrix3::identity(), |f, (g, u)| {
        f + embed(u) * embed(g).transpose()
    })
}

/// The inverse reference Jacobian at `xi`, `J^-1 = d xi / dX`.
///
/// # Errors
/// [`FemError::DegenerateElement`] if the Jacobian is singular.
pub(crate) fn inverse_jacobian<const D: usize>(
    x_ref: &[SVector<f64, D>],
    xi: &SVector<f64, D>,
) -> Result<Matrix3<f64>, FemError> {
    let j = jacobian(x_ref, xi);
    j.try_inverse().ok_or(FemError::DegenerateElement {
        det_j: j.determinant(),
    })
}

/// `grad_X N_I = J^-T grad_xi N_I` at `xi`: then `det F` there, with [`gradient_of`], is
/// `det J(xi; X + u) / det J(xi; X)`.
///
/// # Errors
/// [`FemError::DegenerateElement`] if the Jacobian is singular.
pub(crate) fn reference_gradients<const D: usize>(
    x_ref: &[SVector<f64, D>],
    xi: &SVector<f64, D>,
) -> Result<Vec<SVector<f64, D>>, FemError> {
    let inverse_t = inverse_jacobian(x_ref, xi)?.transpose();
    Ok(shape_gradients::<D>(xi)
        .iter()
        .map(|dn| restrict(&(inverse_t * embed(dn))))
        .collect())
}

/// The non-vanishing reference gradients at every corner of the cell (those of the corner's
/// node and of its D neighbours along the edges), for [`check_corners`].
///
/// # Errors
/// [`FemError::DegenerateElement`] if a corner Jacobian is singular.
pub(crate) fn corner_gradients<const D: usize>(
    x_ref: &[SVector<f64, D>],
) -> Result<CornerGradients<D>, FemError> {
    corners::<D>()
        .iter()
        .map(|xi| {
            let gradients = reference_gradients(x_ref, xi)?.into_iter().enumerate();
            Ok(gradients
                .filter(|(_, g)| g.iter().any(|&c| c != 0.0))
                .collect())
        })
        .collect()
}

/// The volume ratio `J_c = det J(xi_c; X + u) / det J(xi_c; X)` of the multilinear field `u`
/// at every corner `c` must be positive.
///
/// # Errors
/// [`FemError::InvertedElement`] naming the first corner with `J_c <= 0` or NaN.
pub(crate) fn check_corners<const D: usize>(
    corner_gradients: &CornerGradients<D>,
    u: &[SVector<f64, D>],
) -> Result<(), FemError> {
    for (corner, gradients) in corner_gradients.iter().enumerate() {
        let det_f = gradient_of(gradients.iter().map(|(a, g)| (g, &u[*a]))).determinant();
        if det_f.is_nan() || det_f <= 0.0 {
            return Err(FemError::InvertedElement {
                det_f,
                corner: Some(corner),
            });
        }
    }
    Ok(())
}

/// Adds one integration point's material and geometric stiffness to the column-major matrix
/// `k` of the node-major unknowns of the spatial gradients `g` (size `n = D g.len()`, `n^2`
/// entries), from the weighted Kirchhoff stress `tau` and tangent `c` (Voigt, tensor
/// components; both already multiplied by the point's reference volume):
///
/// `K_ab,ik += sum_jl g_aj c_ijkl g_bl + delta_ik g_a . (tau g_b)`, with only in-plane `i, k`
/// in 2D.
///
/// By the major symmetry of `c`, `K_ba = K_ab^T`: each pair `b >= a` is evaluated once and
/// added to both blocks, and a diagonal block `K_aa` takes its upper triangle for both
/// triangles, so that `k` stays exactly symmetric.
pub(crate) fn add_pair_stiffness<const D: usize>(
    g: &[Vector3<f64>],
    tau: &Matrix3<f64>,
    c: &Matrix6<f64>,
    k: &mut [f64],
) {
    let components = D * g.len();
    // per gradient b: c B_b, the Voigt tangent times the Voigt vectors of sym(e_m (x) g_b)
    // (entries g_bl at the rows of the pairs (m, l)): `[b][R][m] = sum_l c_{R (ml)} g_bl`;
    // and tau g_b
    let mut c_b = [[[0.0; 3]; 6]; MAX_GRADIENTS];
    let mut tau_g = [Vector3::zeros(); MAX_GRADIENTS];
    for ((c_b, tau_g_b), g_b) in c_b.iter_mut().zip(&mut tau_g).zip(g) {
        *tau_g_b = tau * g_b;
        for (r, row) in c_b.iter_mut().enumerate() {
            for (m, value) in row.iter_mut().enumerate().take(D) {
                *value = (0..D).map(|l| c[(r, VOIGT_INDEX[m][l])] * g_b[l]).sum();
            }
        }
    }
    for (a, g_a) in g.iter().enumerate() {
        for (b, (c_b, tau_g_b)) in c_b.iter().zip(&tau_g).enumerate().take(g.len()).skip(a) {
            let geometric = g_a.dot(tau_g_b);
            let block = SMatrix::<f64, D, D>::from_fn(|i, m| {
                // K_aa is symmetric up to round-off: its upper triangle stands for both
                let (i, m) = if a == b && i > m { (m, i) } else { (i, m) };
                let material: f64 = (0..D).map(|j| g_a[j] * c_b[VOIGT_INDEX[i][j]][m]).sum();
                if i == m {
                    material + geometric
                } else {
                    material
                }
            });
            // K_ab: column b D + m holds the block's column m in rows a D..a D + D;
            // K_ba = K_ab^T: column a D + i holds its row i in rows b D..b D + D
            for (m, column) in block.column_iter().enumerate() {
                let start = (b * D + m) * components + a * D;
                for (entry, value) in k[start..start + D].iter_mut().zip(column.iter()) {
                    *entry += *value;
                }
            }
            if a != b {
                for (i, row) in block.row_iter().enumerate() {
                    let start = (a * D + i) * components + b * D;
                    for (entry, value) in k[start..start + D].iter_mut().zip(row.iter()) {
                        *entry += *value;
                    }
                }
            }
        }
    }
}
