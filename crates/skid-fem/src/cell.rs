//! The multilinear reference cell `[-1, 1]^D`: the bilinear quad (D = 2) and the trilinear hex
//! (D = 3).
//!
//! Corner order: D = 2: (-1,-1), (1,-1), (1,1), (-1,1) (counter-clockwise); D = 3: the same four
//! corners with zeta = -1, then the same four with zeta = +1.

use nalgebra::{DVector, Matrix3, SVector, Vector3};

use crate::error::FemError;

/// Most nodes of an element: `2^D` (the corners of the cell) for D <= 3.
pub const MAX_NODES: usize = 8;

/// Most displacement components of an element: `D 2^D` for D <= 3. An element stiffness has
/// at most its square entries.
pub const MAX_COMPONENTS: usize = 3 * MAX_NODES;

/// Number of corners `2^dim` of the reference cell.
pub const fn corner_count(dim: usize) -> usize {
    1 << dim
}

/// `Ok` for the supported dimensions 2 and 3.
///
/// # Errors
/// [`FemError::UnsupportedDimension`] otherwise.
pub fn check_dimension<const D: usize>() -> Result<(), FemError> {
    if D == 2 || D == 3 {
        Ok(())
    } else {
        Err(FemError::UnsupportedDimension { dim: D })
    }
}

/// Coordinates `xi_I` of the `2^D` corners in the cell corner order.
pub fn corners<const D: usize>() -> Vec<SVector<f64, D>> {
    (0..corner_count(D))
        .map(|corner| SVector::from_fn(|axis, _| corner_sign(corner, axis)))
        .collect()
}

/// Sign of coordinate `axis` of corner number `corner`: the first two axes run
/// counter-clockwise through (-,-), (+,-), (+,+), (-,+); further axes follow the binary digits.
pub fn corner_sign(corner: usize, axis: usize) -> f64 {
    let positive = match axis {
        0 => matches!(corner & 3, 1 | 2),
        1 => corner & 2 != 0,
        _ => (corner >> axis) & 1 == 1,
    };
    if positive { 1.0 } else { -1.0 }
}

/// Shape functions `N_I(xi) = prod_k (1 + xi_k xi_Ik) / 2` in the corner order.
pub fn shape_functions<const D: usize>(xi: &SVector<f64, D>) -> Vec<f64> {
    corners::<D>()
        .iter()
        .map(|c| {
            c.iter()
                .zip(xi.iter())
                .map(|(ci, x)| 0.5 * (1.0 + ci * x))
                .product()
        })
        .collect()
}

/// Shape function gradients `dN_I/dxi_k = (xi_Ik / 2) prod_{m != k} (1 + xi_m xi_Im) / 2`.
pub fn shape_gradients<const D: usize>(xi: &SVector<f64, D>) -> Vec<SVector<f64, D>> {
    corners::<D>()
        .iter()
        .map(|c| {
            SVector::from_fn(|k, _| {
                (0..D)
                    .map(|m| {
                        if m == k {
                            0.5 * c[m]
                        } else {
                            0.5 * (1.0 + c[m] * xi[m])
                        }
                    })
                    .product()
            })
        })
        .collect()
}

/// The parametric axes whose coordinates multiply to each hourglass base function `h_alpha`
/// (in the order of [`hourglass_base_vectors`]): D = 2: `[{0, 1}]`; D = 3:
/// `[{0, 1}, {1, 2}, {2, 0}, {0, 1, 2}]`.
///
/// # Errors
/// [`FemError::UnsupportedDimension`] unless D is 2 or 3.
pub fn hourglass_mode_axes<const D: usize>() -> Result<&'static [&'static [usize]], FemError> {
    match D {
        2 => Ok(&[&[0, 1]]),
        3 => Ok(&[&[0, 1], &[1, 2], &[2, 0], &[0, 1, 2]]),
        _ => Err(FemError::UnsupportedDimension { dim: D }),
    }
}

/// Hourglass base vectors `h_alpha` (values at the corners): D = 2: `[xi eta]`;
/// D = 3: `[xi eta, eta zeta, zeta xi, xi eta zeta]`.
///
/// # Errors
/// [`FemError::UnsupportedDimension`] unless D is 2 or 3.
pub fn hourglass_base_vectors<const D: usize>() -> Result<Vec<DVector<f64>>, FemError> {
    let corners = corners::<D>();
    Ok(hourglass_mode_axes::<D>()?
        .iter()
        .map(|axes| {
            DVector::from_iterator(
                corners.len(),
                corners.iter().map(|c| axes.iter().map(|&k| c[k]).product()),
            )
        })
        .collect())
}

/// The `2^D`-point Gauss rule on `[-1, 1]^D`: points `xi_I / sqrt(3)`, each of weight 1.
pub fn gauss_points<const D: usize>() -> Vec<(SVector<f64, D>, f64)> {
    let a = 1.0 / 3.0_f64.sqrt();
    corners::<D>().into_iter().map(|c| (c * a, 1.0)).collect()
}

/// Embeds a D-vector (D <= 3) into 3D, padding with zeros.
pub fn embed<const D: usize>(v: &SVector<f64, D>) -> Vector3<f64> {
    Vector3::from_fn(|i, _| v.get(i).copied().unwrap_or(0.0))
}

/// The first D components of a 3D vector (zeros beyond the third).
pub fn restrict<const D: usize>(v: &Vector3<f64>) -> SVector<f64, D> {
    SVector::from_fn(|i, _| v.get(i).copied().unwrap_or(0.0))
}

/// Jacobian `J_jk = dX_j/dxi_k = sum_I X_Ij dN_I/dxi_k` of the isoparametric map at `xi`,
/// embedded in 3D (`J33 = 1` in 2D) so that `det J` is the area or volume ratio.
pub fn jacobian<const D: usize>(x_ref: &[SVector<f64, D>], xi: &SVector<f64, D>) -> Matrix3<f64> {
    let mut j = Matrix3::from_fn(|r, c| if r == c && r >= D { 1.0 } else { 0.0 });
    for (x, dn) in x_ref.iter().zip(shape_gradients::<D>(xi)) {
        j += embed(x) * embed(&dn).transpose();
    }
    j
}

/// Reference measure and mean shape-function gradients of one cell.
#[derive(Clone, Debug)]
pub struct ReferenceGeometry<const D: usize> {
    /// Area (D = 2, per unit thickness) or volume (D = 3) `V = int dV`.
    pub measure: f64,
    /// Mean gradients `b_I = (1/V) int dN_I/dX dV`, in the corner order.
    pub mean_gradients: Vec<SVector<f64, D>>,
}

impl<const D: usize> ReferenceGeometry<D> {
    /// Integrates the measure and the mean gradients with the `2^D`-point Gauss rule, after
    /// checking that `det J > 0` at every corner and every Gauss point.
    ///
    /// # Errors
    /// [`FemError::UnsupportedDimension`], [`FemError::LengthMismatch`] if `x_ref` does not hold
    /// `2^D` points, [`FemError::DegenerateElement`] for `det J <= 0` or non-finite.
    pub fn new(x_ref: &[SVector<f64, D>]) -> Result<Self, FemError> {
        check_dimension::<D>()?;
        let n = corner_count(D);
        if x_ref.len() != n {
            return Err(FemError::LengthMismatch {
                what: "reference nodal coordinates",
                expected: n,
                found: x_ref.len(),
            });
        }
        for xi in corners::<D>() {
            let det_j = jacobian(x_ref, &xi).determinant();
            if !(det_j > 0.0 && det_j.is_finite()) {
                return Err(FemError::DegenerateElement { det_j });
            }
        }
        let mut measure = 0.0;
        let mut integrals = vec![Vector3::zeros(); n];
        for (xi, weight) in gauss_points::<D>() {
            let j = jacobian(x_ref, &xi);
            let det_j = j.determinant();
            let j_inv = match j.try_inverse() {
                Some(inv) if det_j > 0.0 && det_j.is_finite() => inv,
                _ => return Err(FemError::DegenerateElement { det_j }),
            };
            let dv = det_j * weight;
            measure += dv;
            for (integral, dn) in integrals.iter_mut().zip(shape_gradients::<D>(&xi)) {
                *integral += j_inv.transpose() * embed(&dn) * dv;
            }
        }
        let mean_gradients = integrals.iter().map(|v| restrict(&(v / measure))).collect();
        Ok(Self {
            measure,
            mean_gradients,
        })
    }
}

/// Corners of the cell face on `axis` (`upper`: the face `xi_axis = +1`), ordered so that the
/// outward normal follows: D = 2: edge `[a, b]` with outward normal `(dy, -dx)/L`;
/// D = 3: counter-clockwise seen from outside (right-hand rule).
///
/// # Errors
/// [`FemError::UnsupportedDimension`] unless D is 2 or 3; [`FemError::InvalidMesh`] if
/// `axis >= D`.
pub fn face_corners<const D: usize>(
    axis: usize,
    upper: bool,
) -> Result<&'static [usize], FemError> {
    check_dimension::<D>()?;
    Ok(match (D, axis, upper) {
        (2, 0, false) => &[3, 0],
        (2, 0, true) => &[1, 2],
        (2, 1, false) => &[0, 1],
        (2, 1, true) => &[2, 3],
        (3, 0, false) => &[3, 0, 4, 7],
        (3, 0, true) => &[1, 2, 6, 5],
        (3, 1, false) => &[0, 1, 5, 4],
        (3, 1, true) => &[2, 3, 7, 6],
        (3, 2, false) => &[0, 3, 2, 1],
        (3, 2, true) => &[4, 5, 6, 7],
        _ => {
            return Err(FemError::InvalidMesh(format!(
                "a {D}-dimensional cell has no face on axis {axis}"
            )));
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    #[test]
    fn corner_order_matches_convention() {
        let c2 = corners::<2>();
        let expected2 = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
        for (c, (x, y)) in c2.iter().zip(expected2) {
            assert_eq!(*c, Vector2::new(x, y));
        }
        let c3 = corners::<3>();
        for (k, c) in c3.iter().enumerate() {
            let z = if k < 4 { -1.0 } else { 1.0 };
            assert_eq!(*c, Vector3::new(c2[k % 4].x, c2[k % 4].y, z));
        }
    }

    fn check_partition_and_gradients<const D: usize>(xi: SVector<f64, D>) {
        let n = shape_functions(&xi);
        assert!((n.iter().sum::<f64>() - 1.0).abs() < 1e-14);
        // Kronecker property at the corners.
        for (i, c) in corners::<D>().iter().enumerate() {
            for (j, value) in shape_functions(c).iter().enumerate() {
                assert!((value - if i == j { 1.0 } else { 0.0 }).abs() < 1e-14);
            }
        }
        // Gradients by central differences.
        let h = 1e-6;
        let grads = shape_gradients(&xi);
        for k in 0..D {
            let mut dxi = SVector::<f64, D>::zeros();
            dxi[k] = h;
            let plus = shape_functions(&(xi + dxi));
            let minus = shape_functions(&(xi - dxi));
            for (i, g) in grads.iter().enumerate() {
                assert!((g[k] - (plus[i] - minus[i]) / (2.0 * h)).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn shape_functions_partition_unity_and_gradients_match_fd() {
        check_partition_and_gradients(Vector2::new(0.3, -0.7));
        check_partition_and_gradients(Vector3::new(0.3, -0.7, 0.45));
    }

    #[test]
    fn hourglass_vectors_are_orthogonal_to_linear_fields() -> Result<(), FemError> {
        let c = corners::<3>();
        let hs = hourglass_base_vectors::<3>()?;
        assert_eq!(hs.len(), 4);
        for h in &hs {
            assert!(h.sum().abs() < 1e-14);
            for k in 0..3 {
                let linear: f64 = c.iter().zip(h.iter()).map(|(x, v)| x[k] * v).sum();
                assert!(linear.abs() < 1e-14);
            }
        }
        assert_eq!(hourglass_base_vectors::<2>()?.len(), 1);
        assert!(matches!(
            hourglass_base_vectors::<4>(),
            Err(FemError::UnsupportedDimension { dim: 4 })
        ));
        Ok(())
    }

    #[test]
    fn gauss_rule_integrates_bilinear_times_bilinear() {
        // int_{[-1,1]^2} xi^2 eta^2 = 4/9; the 2x2 rule is exact for degree 3 per direction.
        let integral: f64 = gauss_points::<2>()
            .iter()
            .map(|(p, w)| w * p.x * p.x * p.y * p.y)
            .sum();
        assert!((integral - 4.0 / 9.0).abs() < 1e-14);
        let volume: f64 = gauss_points::<3>().iter().map(|(_, w)| w).sum();
        assert!((volume - 8.0).abs() < 1e-14);
    }

    /// Affine image `X = A xi + c` of the cell: `b_I = A^{-T} xi_I / 2^D`, measure `2^D det A`.
    fn check_affine_cell<const D: usize>(a: Matrix3<f64>) -> Result<(), FemError> {
        let c = Vector3::new(0.1, -0.2, 0.3);
        let x: Vec<SVector<f64, D>> = corners::<D>()
            .iter()
            .map(|xi| restrict(&(a * embed(xi) + c)))
            .collect();
        let geo = ReferenceGeometry::new(&x)?;
        let n = corner_count(D) as f64;
        assert!((geo.measure - n * a.determinant()).abs() < 1e-12);
        let a_inv = a
            .try_inverse()
            .ok_or(FemError::DegenerateElement { det_j: 0.0 })?;
        for (b, xi) in geo.mean_gradients.iter().zip(corners::<D>()) {
            assert!((embed(b) - a_inv.transpose() * embed(&xi) / n).norm() < 1e-12);
        }
        Ok(())
    }

    #[test]
    fn mean_gradients_of_affine_cells_are_exact() -> Result<(), FemError> {
        check_affine_cell::<2>(Matrix3::new(2.0, 0.5, 0.0, 0.3, 1.5, 0.0, 0.0, 0.0, 1.0))?;
        check_affine_cell::<3>(Matrix3::new(2.0, 0.5, -0.2, 0.3, 1.5, 0.1, 0.2, -0.4, 0.9))
    }

    #[test]
    fn wrong_dimension_and_face_axis_are_errors() {
        assert!(matches!(
            check_dimension::<1>(),
            Err(FemError::UnsupportedDimension { dim: 1 })
        ));
        assert!(matches!(
            face_corners::<2>(2, true),
            Err(FemError::InvalidMesh(_))
        ));
        assert!(matches!(
            ReferenceGeometry::<2>::new(&[Vector2::zeros(); 3]),
            Err(FemError::LengthMismatch { .. })
        ));
    }
}
