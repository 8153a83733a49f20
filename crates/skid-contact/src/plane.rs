//! Analytical rigid plane (a line in 2D).

use nalgebra::{Matrix3, Vector2, Vector3};

use crate::error::ContactError;
use crate::surface::{Projection, RigidSurface, SurfaceShape};

/// The plane through the body-frame origin with outward unit normal `n`.
///
/// `g = n . y`, `dg/dy = n` (all second derivatives vanish); convected coordinates `xi_0 = t1 . y`, `xi_1 = t2 . y` with the
/// in-plane unit vectors `t1` (given) and `t2 = n x t1`.
#[derive(Clone, Debug)]
pub struct RigidPlane {
    normal: Vector3<f64>,
    t1: Vector3<f64>,
    t2: Vector3<f64>,
}

impl RigidPlane {
    /// Plane with outward `normal` and first in-plane direction `tangent` (both are normalised;
    /// `tangent` must not be parallel to `normal`, its normal component is removed).
    ///
    /// # Errors
    /// [`ContactError::InvalidSurface`] for zero, non-finite or parallel vectors.
    pub fn new(normal: Vector3<f64>, tangent: Vector3<f64>) -> Result<Self, ContactError> {
        let bad = || {
            ContactError::InvalidSurface(format!(
                "plane needs a finite non-zero normal and a tangent not parallel to it, got \
                 {normal:?} and {tangent:?}"
            ))
        };
        let n = normal.try_normalize(1e-300).ok_or_else(bad)?;
        let t1 = (tangent - n * n.dot(&tangent))
            .try_normalize(1e-12 * tangent.norm())
            .ok_or_else(bad)?;
        if !(n.iter().chain(t1.iter()).all(|c| c.is_finite())) {
            return Err(bad());
        }
        Ok(Self {
            normal: n,
            t1,
            t2: n.cross(&t1),
        })
    }

    /// The plane's directions turned into the tangent plane of a surface of unit normal `n`:
    /// `t_1` is the part of `t1` perpendicular to `n` made unit, and `t_2 = n x t_1`; on a
    /// surface parallel to the plane, `t1` and `t2` themselves. They turn continuously with `n`
    /// but where `t1` is within 1e-3 of `n` (a face across the plane's first direction), which
    /// takes the part of `t2` instead (then nearly all of it). `None` if `n` is not a finite
    /// unit vector.
    pub(crate) fn tangents_across(&self, n: &Vector3<f64>) -> Option<[Vector3<f64>; 2]> {
        let off_unit = (n.norm() - 1.0).abs();
        if off_unit.is_nan() || off_unit > 1e-9 {
            return None;
        }
        let along = |t: &Vector3<f64>| t - n * n.dot(t);
        let (first, second) = (along(&self.t1), along(&self.t2));
        let t1 = if first.norm() >= 1e-3 { first } else { second }.try_normalize(0.0)?;
        Some([t1, n.cross(&t1)])
    }
}

impl RigidSurface for RigidPlane {
    fn shape(&self) -> SurfaceShape {
        SurfaceShape::Plane {
            normal: self.normal,
            tangents: [self.t1, self.t2],
        }
    }

    fn project(&self, y: &Vector3<f64>) -> Option<Projection> {
        y.iter().all(|c| c.is_finite()).then(|| Projection {
            gap: self.normal.dot(y),
            gap_gradient: self.normal,
            coords: Vector2::new(self.t1.dot(y), self.t2.dot(y)),
            coords_gradient: [self.t1, self.t2],
            gap_hessian: Matrix3::zeros(),
            coords_hessian: [Matrix3::zeros(); 2],
        })
    }

    fn coords_period(&self) -> [Option<f64>; 2] {
        [None, None]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gap_and_coordinates_are_distances_along_the_frame() {
        let plane = RigidPlane::new(Vector3::new(0.0, 2.0, 0.0), Vector3::new(1.0, 0.5, 0.0))
            .expect("plane");
        let p = plane
            .project(&Vector3::new(0.3, -0.01, 0.2))
            .expect("projection");
        assert!((p.gap + 0.01).abs() < 1e-15);
        assert!((p.coords[0] - 0.3).abs() < 1e-15);
        assert!((p.coords[1] + 0.2).abs() < 1e-15, "t2 = y x x = -z");
        assert_eq!(plane.coords_period(), [None, None]);
    }

    #[test]
    fn degenerate_frames_are_rejected() {
        assert!(RigidPlane::new(Vector3::zeros(), Vector3::x()).is_err());
        assert!(RigidPlane::new(Vector3::y(), Vector3::y() * 3.0).is_err());
        assert!(RigidPlane::new(Vector3::new(f64::NAN, 1.0, 0.0), Vector3::x()).is_err());
    }
}
