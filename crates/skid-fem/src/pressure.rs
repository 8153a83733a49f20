//! Follower pressure loads on element faces.

use nalgebra::{SVector, Vector2, Vector3};

use crate::cell::{check_dimension, corner_count, corner_sign, embed, restrict};
use crate::error::FemError;

/// Nodal forces of a uniform pressure p (positive pushes INTO the body, i.e. force = -p n dA
/// with n the outward normal) on one face in its CURRENT configuration. 2D: face = 2 nodes
/// [a, b] of an edge of a counter-clockwise element, outward normal n = (dy, -dx)/L,
/// area = L * thickness; 3D: face = 4 nodes ordered counter-clockwise seen from outside
/// (outward normal by the right-hand rule), integrated with 2x2 Gauss on the bilinear face
/// (thickness ignored).
///
/// 2D: each node receives `-p t (dy, -dx) / 2`. 3D: `f_I = -p sum_g N_I(s_g) (x_s x x_t)(s_g)`,
/// which integrates the bilinear vector-area density exactly.
///
/// # Errors
/// [`FemError::UnsupportedDimension`] unless D is 2 or 3, [`FemError::LengthMismatch`] unless
/// the face has `2^(D-1)` nodes, [`FemError::InvalidParameter`] for a non-finite pressure or a
/// non-positive thickness in 2D.
pub fn pressure_face_forces<const D: usize>(
    x: &[SVector<f64, D>],
    pressure: f64,
    thickness: f64,
) -> Result<Vec<SVector<f64, D>>, FemError> {
    check_dimension::<D>()?;
    let expected = corner_count(D.saturating_sub(1));
    if x.len() != expected {
        return Err(FemError::LengthMismatch {
            what: "face nodes",
            expected,
            found: x.len(),
        });
    }
    if !pressure.is_finite() {
        return Err(FemError::InvalidParameter {
            name: "pressure",
            value: pressure,
            expected: "finite",
        });
    }
    if D == 2 {
        if !(thickness > 0.0 && thickness.is_finite()) {
            return Err(FemError::InvalidParameter {
                name: "thickness",
                value: thickness,
                expected: "finite and > 0",
            });
        }
        let d = embed(&x[1]) - embed(&x[0]);
        let half = Vector3::new(d.y, -d.x, 0.0) * (-0.5 * pressure * thickness);
        return Ok(vec![restrict(&half); 2]);
    }
    let x: [Vector3<f64>; 4] = std::array::from_fn(|i| embed(&x[i]));
    // the face's corners (s_I, t_I) in the cell corner order, and the 2 x 2 Gauss points
    // (s_I, t_I) / sqrt(3), each of weight 1
    let corners: [Vector2<f64>; 4] =
        std::array::from_fn(|i| Vector2::new(corner_sign(i, 0), corner_sign(i, 1)));
    let a = 1.0 / 3.0_f64.sqrt();
    let mut forces = [Vector3::zeros(); 4];
    for point in &corners {
        let (s, t) = (point.x * a, point.y * a);
        // N_I = (1 + s s_I)(1 + t t_I) / 4 and its derivatives along s and t
        let along_s = |c: &Vector2<f64>| 0.5 * (1.0 + c.x * s);
        let along_t = |c: &Vector2<f64>| 0.5 * (1.0 + c.y * t);
        let (mut x_s, mut x_t) = (Vector3::zeros(), Vector3::zeros());
        for (x_i, c) in x.iter().zip(&corners) {
            x_s += x_i * (0.5 * c.x * along_t(c));
            x_t += x_i * (along_s(c) * (0.5 * c.y));
        }
        let area = x_s.cross(&x_t);
        for (f, c) in forces.iter_mut().zip(&corners) {
            *f -= area * (pressure * (along_s(c) * along_t(c)));
        }
    }
    Ok(forces.iter().map(restrict).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3 as V3;

    #[test]
    fn edge_force_is_minus_p_n_l_t_split_equally() -> Result<(), FemError> {
        // Bottom edge of a counter-clockwise element: outward normal -y.
        let f = pressure_face_forces(&[Vector2::new(0.0, 0.0), Vector2::new(2.0, 0.0)], 3.0, 0.5)?;
        for f_i in &f {
            assert!((f_i - Vector2::new(0.0, 1.5)).norm() < 1e-14);
        }
        // Slanted edge: total = -p n L t.
        let (a, b) = (Vector2::new(1.0, 0.5), Vector2::new(-0.5, 2.5));
        let (p, t) = (2.0, 0.1);
        let d = b - a;
        let n = Vector2::new(d.y, -d.x) / d.norm();
        let f = pressure_face_forces(&[a, b], p, t)?;
        assert!((f[0] + f[1] + n * (p * d.norm() * t)).norm() < 1e-14);
        assert!((f[0] - f[1]).norm() < 1e-14);
        Ok(())
    }

    #[test]
    fn flat_rectangle_face_force_is_minus_p_n_a_split_equally() -> Result<(), FemError> {
        // Face z = 1 of a box, counter-clockwise seen from +z.
        let x = [
            V3::new(0.0, 0.0, 1.0),
            V3::new(2.0, 0.0, 1.0),
            V3::new(2.0, 3.0, 1.0),
            V3::new(0.0, 3.0, 1.0),
        ];
        let f = pressure_face_forces(&x, 5.0, 1.0)?;
        for f_i in &f {
            assert!((f_i - V3::new(0.0, 0.0, -5.0 * 6.0 / 4.0)).norm() < 1e-12);
        }
        Ok(())
    }

    #[test]
    fn warped_face_total_is_minus_p_vector_area() -> Result<(), FemError> {
        let x = [
            V3::new(0.1, -0.2, 0.3),
            V3::new(2.0, 0.1, -0.2),
            V3::new(2.3, 1.9, 0.6),
            V3::new(-0.2, 1.7, -0.1),
        ];
        let p = 1.7;
        let f = pressure_face_forces(&x, p, 1.0)?;
        // Vector area of a bilinear quadrilateral = (1/2) (x3 - x1) x (x4 - x2).
        let vector_area = (x[2] - x[0]).cross(&(x[3] - x[1])) * 0.5;
        let total: V3<f64> = f.iter().sum();
        assert!((total + vector_area * p).norm() < 1e-12);
        Ok(())
    }

    #[test]
    fn wrong_node_count_and_pressure_are_errors() {
        assert!(matches!(
            pressure_face_forces(&[V3::zeros(); 3], 1.0, 1.0),
            Err(FemError::LengthMismatch { expected: 4, .. })
        ));
        assert!(matches!(
            pressure_face_forces(&[Vector2::zeros(); 2], f64::NAN, 1.0),
            Err(FemError::InvalidParameter { .. })
        ));
        assert!(matches!(
            pressure_face_forces(&[Vector2::zeros(); 2], 1.0, 0.0),
            Err(FemError::InvalidParameter {
                name: "thickness",
                ..
            })
        ));
    }
}
