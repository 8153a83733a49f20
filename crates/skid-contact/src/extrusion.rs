//! Rigid extruded profile (3D): a profile of straight segments and arcs in a plane through the
//! body origin, swept without end along the plane's normal, such as a step, a ramp or a die
//! profile with rounded edges.

use nalgebra::{Matrix2x3, Matrix3, Vector2, Vector3};

use crate::error::ContactError;
use crate::polyline::{RigidPolyline, lift_from_plane};
use crate::surface::{Projection, RigidSurface, SurfaceShape};

/// The [`RigidPolyline`] `profile` of the plane spanned by the unit `reference` direction `a`
/// and `b = e x a` (coordinates `(a.y, b.y)`; its outside on the right walking along it with
/// `a` to the right and `b` up), swept along the unit `axis` `e`.
///
/// With `q = (a.y, b.y)` every profile function `f(q)` (gap, arc length) has
/// `df/dy = f_1 a + f_2 b` and `d^2f/dy^2 = [a b] H_f [a b]^T`; the coordinates are the
/// profile's arc length and `xi_1 = e.y`, both lengths on the surface.
#[derive(Clone, Debug)]
pub struct RigidExtrusion {
    profile: RigidPolyline,
    axis: Vector3<f64>,
    reference: Vector3<f64>,
}

impl RigidExtrusion {
    /// The extrusion along `axis` of `profile`, given in the plane of `reference` (made
    /// perpendicular to `axis`) and `axis x reference`.
    ///
    /// # Errors
    /// [`ContactError::InvalidSurface`] for an axis or reference direction that is not finite,
    /// zero or parallel to the other.
    pub fn new(
        axis: Vector3<f64>,
        reference: Vector3<f64>,
        profile: RigidPolyline,
    ) -> Result<Self, ContactError> {
        let bad = || {
            ContactError::InvalidSurface(format!(
                "an extrusion needs a finite non-zero axis and a reference direction not \
                 parallel to it, got {axis:?} and {reference:?}"
            ))
        };
        let axis = axis
            .try_normalize(0.0)
            .filter(|a| a.iter().all(|c| c.is_finite()))
            .ok_or_else(bad)?;
        let reference = (reference - axis * axis.dot(&reference))
            .try_normalize(1e-12 * reference.norm())
            .filter(|r| r.iter().all(|c| c.is_finite()))
            .ok_or_else(bad)?;
        Ok(Self {
            profile,
            axis,
            reference,
        })
    }

    /// `[a b]^T`: the rows map profile-plane derivatives to the body frame.
    fn frame(&self) -> Matrix2x3<f64> {
        Matrix2x3::from_rows(&[
            self.reference.transpose(),
            self.axis.cross(&self.reference).transpose(),
        ])
    }
}

impl RigidSurface for RigidExtrusion {
    fn shape(&self) -> SurfaceShape {
        SurfaceShape::Extrusion {
            axis: self.axis,
            reference: self.reference,
            profile: self.profile.drawn_points(),
            closed: self.profile.is_closed(),
        }
    }

    fn project(&self, y: &Vector3<f64>) -> Option<Projection> {
        let frame = self.frame();
        let q = frame * y;
        let section = self.profile.project(&Vector3::new(q.x, q.y, 0.0))?;
        let lift = |gradient, hessian| lift_from_plane(&frame, gradient, hessian);
        let (gap_gradient, gap_hessian) = lift(&section.gap_gradient, &section.gap_hessian);
        let (arc_gradient, arc_hessian) =
            lift(&section.coords_gradient[0], &section.coords_hessian[0]);
        Some(Projection {
            gap: section.gap,
            gap_gradient,
            coords: Vector2::new(section.coords[0], self.axis.dot(y)),
            coords_gradient: [arc_gradient, self.axis],
            gap_hessian,
            coords_hessian: [arc_hessian, Matrix3::zeros()],
        })
    }

    fn coords_period(&self) -> [Option<f64>; 2] {
        [self.profile.coords_period()[0], None]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::facets::tests::check_gradients;
    use crate::plane::RigidPlane;

    fn project(surface: &dyn RigidSurface, y: &Vector3<f64>) -> Projection {
        surface.project(y).expect("projection defined")
    }

    /// A straight profile is its plane: the same gap and normal, and the coordinates along
    /// the profile and the axis.
    #[test]
    fn a_straight_profile_is_its_plane() -> Result<(), ContactError> {
        // profile plane x-y (a = x, b = y), axis z; walked towards -x: outside up (+y)
        let extrusion = RigidExtrusion::new(
            Vector3::z(),
            Vector3::x(),
            RigidPolyline::new(vec![Vector2::new(1.0, 0.0), Vector2::new(-1.0, 0.0)], false)?,
        )?;
        let plane = RigidPlane::new(Vector3::y(), Vector3::x())?;
        for y in [
            Vector3::new(0.2, 0.03, 0.4),
            Vector3::new(-0.5, -0.01, -0.1),
        ] {
            let (e, p) = (project(&extrusion, &y), project(&plane, &y));
            assert!((e.gap - p.gap).abs() < 1e-15);
            assert!((e.gap_gradient - p.gap_gradient).norm() < 1e-15);
            assert!((e.coords[0] - (1.0 - y.x)).abs() < 1e-15);
            assert!((e.coords[1] - y.z).abs() < 1e-15);
        }
        Ok(())
    }

    /// Gap and coordinates against finite differences on a step profile with a fillet in a
    /// tilted plane.
    #[test]
    fn gradients_match_finite_differences() -> Result<(), ContactError> {
        let extrusion = RigidExtrusion::new(
            Vector3::new(0.2, 0.1, 1.0),
            Vector3::new(1.0, 0.3, 0.0),
            RigidPolyline::with_arcs(
                vec![
                    Vector2::new(1.0, 0.1),
                    Vector2::new(0.3, 0.1),
                    Vector2::new(0.0, 0.0),
                    Vector2::new(-1.0, 0.0),
                    Vector2::new(-1.2, 0.2),
                ],
                vec![None, None, None, Some(Vector2::new(-1.0, 0.2))],
                false,
            )?,
        )?;
        for y in [
            Vector3::new(0.5, 0.2, 0.3),
            Vector3::new(0.1, 0.05, -0.2),
            Vector3::new(-0.4, 0.02, 0.1),
            Vector3::new(0.35, 0.25, 0.0),
            // over the concave fillet about (-1, 0.2)
            Vector3::new(-1.05, 0.1, 0.4),
        ] {
            check_gradients(&extrusion, &y, 1e-6);
        }
        assert!(
            RigidExtrusion::new(
                Vector3::z(),
                Vector3::z(),
                RigidPolyline::new(vec![Vector2::zeros(), Vector2::x()], false)?
            )
            .is_err()
        );
        Ok(())
    }
}
