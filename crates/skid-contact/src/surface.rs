//! Rigid surfaces, described in the body frame of the rigid body that carries them (they are
//! static in that frame), with closest-point projections.

use nalgebra::{Matrix3, Vector2, Vector3};
use serde::{Deserialize, Serialize};

use crate::error::ContactError;

/// Closest-point projection of a point `y` (body frame) onto a surface.
#[derive(Clone, Debug)]
pub struct Projection {
    /// Signed normal distance `g(y)`: `> 0` open, `< 0` penetration.
    pub gap: f64,
    /// `dg/dy`; the outward unit normal at the closest point for a distance function.
    pub gap_gradient: Vector3<f64>,
    /// Convected surface coordinates `xi = [arc length along the circumference, axial position]`.
    pub coords: Vector2<f64>,
    /// `d xi_k / dy` for `k = 0, 1`.
    pub coords_gradient: [Vector3<f64>; 2],
    /// `d^2 g / dy^2` (symmetric; the curvature of the distance function).
    pub gap_hessian: Matrix3<f64>,
    /// `d^2 xi_k / dy^2` for `k = 0, 1` (symmetric).
    pub coords_hessian: [Matrix3<f64>; 2],
}

/// The geometry of a rigid surface in its body frame, for drawing it: what the surface is, not
/// how it is projected on.
#[derive(Clone, Debug, PartialEq)]
pub enum SurfaceShape {
    /// The cylinder of `radius` about the unit `axis` through the origin, unbounded along it;
    /// `reference` is the unit direction perpendicular to the axis where the arc-length
    /// coordinate is zero.
    Cylinder {
        /// Radius `R`.
        radius: f64,
        /// Unit axis `e`.
        axis: Vector3<f64>,
        /// Unit reference direction `b1`, perpendicular to `e`.
        reference: Vector3<f64>,
    },
    /// The plane through the origin with unit outward `normal`, unbounded; `tangents` are the
    /// unit in-plane directions `t1` and `t2 = n x t1`.
    Plane {
        /// Unit outward normal `n`.
        normal: Vector3<f64>,
        /// `[t1, t2]`.
        tangents: [Vector3<f64>; 2],
    },
    /// The prism over the closed polygon `vertices` (in the plane `e.y = 0`, counter-clockwise
    /// about `axis`), unbounded along the unit `axis`.
    Prism {
        /// Unit axis `e`.
        axis: Vector3<f64>,
        /// Polygon vertices in order.
        vertices: Vec<Vector3<f64>>,
    },
    /// The chain of straight segments through `vertices` (in the plane `z = 0`), back to the
    /// first vertex if `closed`; the outside is on the right walking along it.
    Polyline {
        /// Vertices in order.
        vertices: Vec<Vector3<f64>>,
        /// Whether the last vertex joins the first.
        closed: bool,
    },
    /// The `(r, z)` profile `profile` (back to its first point if `closed`) revolved about the
    /// unit `axis`; `reference` is the unit direction perpendicular to the axis where the
    /// angle is zero.
    Revolution {
        /// Unit axis `e`.
        axis: Vector3<f64>,
        /// Unit reference direction `b1`, perpendicular to `e`.
        reference: Vector3<f64>,
        /// Profile points `(r, z)`.
        profile: Vec<Vector2<f64>>,
        /// Whether the last point joins the first.
        closed: bool,
    },
    /// The profile `profile` (back to its first point if `closed`) of the plane of `reference`
    /// and `axis x reference`, swept along the unit `axis` without end.
    Extrusion {
        /// Unit sweep direction `e`.
        axis: Vector3<f64>,
        /// Unit first direction `a` of the profile's plane, perpendicular to `e`.
        reference: Vector3<f64>,
        /// Profile points `(a.y, (e x a).y)`.
        profile: Vec<Vector2<f64>>,
        /// Whether the last point joins the first.
        closed: bool,
    },
    /// Triangles by their corners, counter-clockwise seen from outside.
    Triangles(Vec<[Vector3<f64>; 3]>),
}

/// A rigid surface, static in the body frame of its rigid body.
pub trait RigidSurface: Send + Sync + std::fmt::Debug {
    /// The surface's geometry in the body frame (see [`SurfaceShape`]).
    fn shape(&self) -> SurfaceShape;
    /// Closest-point projection of the body-frame point `y`; `None` only where the projection is
    /// undefined (e.g. on the axis of a cylinder) or `y` is not finite.
    fn project(&self, y: &Vector3<f64>) -> Option<Projection>;
    /// Period of each convected coordinate (`Some(2 pi R)` for the arc length of a closed
    /// circumference, `None` for a non-periodic coordinate), used to unwrap increments.
    fn coords_period(&self) -> [Option<f64>; 2];
    /// A discrete gradient of the gap between two body-frame points: a vector `G` with
    /// `G . (y_end - y_start) = g(y_end) - g(y_start)` exactly, tending to `dg/dy` as the points
    /// merge. Offered only by a surface whose gap is invariant under rotations about
    /// `rotation_axis` (unit, body frame) through the body origin, so that the body's rotation
    /// moves no gap and `G` accounts for the whole change of the gap over an increment.
    ///
    /// A contact force along the end-point normal `dg/dy(y_end)` does the work
    /// `p_N dg/dy(y_end) . dy`, which on a convex curved surface exceeds `p_N dg` by about
    /// `p_N |dy_t|^2 / (2 R)` for a node moving `dy_t` along it: energy from nothing, first order
    /// in the time step. Along `G` the work is exactly `p_N dg`. `None` (the default): the
    /// surface has no such gradient and the end-point gradient is used.
    fn gap_discrete_gradient(
        &self,
        _y_start: &Vector3<f64>,
        _y_end: &Vector3<f64>,
        _rotation_axis: &Vector3<f64>,
    ) -> Option<DiscreteGradient> {
        None
    }
    /// The slip from the surface point `from` (the contact point at the start of an increment)
    /// to the body-frame point `y` of projection `to`: two lengths along the surface, the
    /// friction law's tangential displacements, with their gradients and Hessians in `y`. The
    /// default, right where the coordinates are lengths on the surface (arc lengths, plane
    /// coordinates): the coordinates' increments `to.coords - from.coords`, each periodic one
    /// unwrapped into `(-p/2, p/2]`, with the coordinates' own derivatives.
    fn slip(&self, from: &SurfacePoint, _y: &Vector3<f64>, to: &Projection) -> Slip {
        Slip::of_coordinates(self.coords_period(), &from.coords, to)
    }
}

/// A point of a rigid surface where a node's contact was (at the start of an increment): its
/// convected coordinates, its body-frame position and the surface's outward unit normal there,
/// from which [`RigidSurface::slip`] measures.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SurfacePoint {
    /// Convected coordinates `xi`.
    pub coords: Vector2<f64>,
    /// Position `p` (body frame).
    pub position: Vector3<f64>,
    /// Outward unit normal `n` (body frame): the gap gradient at the projected point.
    pub normal: Vector3<f64>,
}

#[cfg(test)]
impl SurfacePoint {
    /// A point known by its coordinates alone, for surfaces whose slip reads only those (its
    /// position and normal are NaN, so that any other use shows).
    pub(crate) fn of_coords(coords: Vector2<f64>) -> Self {
        let unknown = Vector3::repeat(f64::NAN);
        Self {
            coords,
            position: unknown,
            normal: unknown,
        }
    }
}

impl Projection {
    /// The closest point of the body-frame point `y` this is the projection of: `p = y - g
    /// dg/dy`, `n = dg/dy` (the gap is a signed distance, so that `dg/dy` is the unit vector
    /// from the closest point towards `y`, or the outward normal where `y` is on the surface).
    pub fn closest(&self, y: &Vector3<f64>) -> SurfacePoint {
        SurfacePoint {
            coords: self.coords,
            position: y - self.gap_gradient * self.gap,
            normal: self.gap_gradient,
        }
    }
}

/// The slip of [`RigidSurface::slip`]: its two components, their gradients and their
/// (symmetric) Hessians in the body-frame point.
#[derive(Clone, Debug, PartialEq)]
pub struct Slip {
    /// The two tangential displacements, lengths along the surface.
    pub value: Vector2<f64>,
    /// The gradient of each component.
    pub gradient: [Vector3<f64>; 2],
    /// The Hessian of each component.
    pub hessian: [Matrix3<f64>; 2],
}

impl Slip {
    /// The increments of the coordinates from `from` to those of `to`, each with a period in
    /// `periods` unwrapped (see [`unwrapped_increment`]), with the coordinates' derivatives.
    pub fn of_coordinates(periods: [Option<f64>; 2], from: &Vector2<f64>, to: &Projection) -> Self {
        Self {
            value: unwrapped_increment(periods, to.coords - from),
            gradient: to.coords_gradient,
            hessian: to.coords_hessian,
        }
    }
}

/// `increment` with each component that has a period `p` (finite, positive) unwrapped into
/// `(-p/2, p/2]`.
pub fn unwrapped_increment(periods: [Option<f64>; 2], mut increment: Vector2<f64>) -> Vector2<f64> {
    for (component, period) in increment.iter_mut().zip(periods) {
        if let Some(p) = period.filter(|p| p.is_finite() && *p > 0.0) {
            *component -= p * (*component / p).round();
            if *component <= -0.5 * p {
                *component += p;
            } else if *component > 0.5 * p {
                *component -= p;
            }
        }
    }
    increment
}

/// A discrete gradient `G(y_start, y_end)` of the gap (see
/// [`RigidSurface::gap_discrete_gradient`]) and its derivative in the end point.
#[derive(Clone, Copy, Debug)]
pub struct DiscreteGradient {
    /// `G`, with `G . (y_end - y_start) = g(y_end) - g(y_start)`.
    pub gradient: Vector3<f64>,
    /// The symmetric part of `dG/dy_end`: the stiffness of a normal force along `G` is
    /// `-r_N dG/dy_end`, of which Newton's symmetric matrix takes this part. The skew part is of
    /// the order of `|y_end - y_start| / R^2`, which leaves Newton's convergence practically
    /// quadratic for increments short against the radius.
    pub jacobian: Matrix3<f64>,
}

/// Analytical circle (2D) / cylinder (3D) of radius `R` about the body-frame unit axis `e` through
/// the body-frame origin.
///
/// With `y_perp = y - (e.y) e`, `rho = |y_perp|`, `n = y_perp / rho` and `t = e x n`:
/// `g = rho - R`, `dg/dy = n`, `d^2g/dy^2 = t t^T / rho`; `xi_0 = R atan2(y.b2, y.b1)` (arc
/// length, counter-clockwise about `e`), `d xi_0/dy = (R/rho) t`,
/// `d^2 xi_0/dy^2 = -(R/rho^2) (t n^T + n t^T)`; `xi_1 = e.y`, `d xi_1/dy = e`, no curvature.
#[derive(Clone, Debug)]
pub struct AnalyticCylinder {
    radius: f64,
    axis: Vector3<f64>,
    b1: Vector3<f64>,
    b2: Vector3<f64>,
}

impl AnalyticCylinder {
    /// Cylinder of `radius > 0` about `axis` (normalised here; must be finite and non-zero).
    ///
    /// The reference direction `b1` (where the arc length is zero) is the normalised projection,
    /// perpendicular to the axis, of the Cartesian basis vector least aligned with the axis (the
    /// first one on ties), and `b2 = e x b1`; for `e = e_z` that gives `b1 = e_x`, `b2 = e_y`.
    pub fn new(radius: f64, axis: Vector3<f64>) -> Result<Self, ContactError> {
        if !(radius.is_finite() && radius > 0.0) {
            return Err(ContactError::InvalidSurface(format!(
                "cylinder radius must be finite and positive, got {radius}"
            )));
        }
        let norm = axis.norm();
        if !(norm.is_finite() && norm > 0.0) {
            return Err(ContactError::InvalidSurface(format!(
                "cylinder axis must be finite and non-zero, got {axis:?}"
            )));
        }
        let axis = axis / norm;
        let least_aligned = (0..3)
            .min_by(|&i, &j| axis[i].abs().total_cmp(&axis[j].abs()))
            .unwrap_or(0);
        let mut reference = Vector3::zeros();
        reference[least_aligned] = 1.0;
        let b1 = (reference - axis * axis.dot(&reference)).normalize();
        let b2 = axis.cross(&b1);
        Ok(Self {
            radius,
            axis,
            b1,
            b2,
        })
    }

    /// Radius `R`.
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// Unit axis `e` (body frame).
    pub fn axis(&self) -> Vector3<f64> {
        self.axis
    }

    /// Reference direction `b1` (body frame), where the arc-length coordinate is zero.
    pub fn reference_direction(&self) -> Vector3<f64> {
        self.b1
    }
}

impl RigidSurface for AnalyticCylinder {
    fn shape(&self) -> SurfaceShape {
        SurfaceShape::Cylinder {
            radius: self.radius,
            axis: self.axis,
            reference: self.b1,
        }
    }

    fn project(&self, y: &Vector3<f64>) -> Option<Projection> {
        if !y.iter().all(|c| c.is_finite()) {
            return None;
        }
        let axial = self.axis.dot(y);
        let radial = y - self.axis * axial;
        let rho = radial.norm();
        // below this, the direction of y_perp is round-off
        if rho <= 64.0 * f64::EPSILON * (self.radius + y.norm()) {
            return None;
        }
        let normal = radial / rho;
        let tangent = self.axis.cross(&normal);
        let angle = self.b2.dot(y).atan2(self.b1.dot(y));
        let twist = tangent * normal.transpose();
        Some(Projection {
            gap: rho - self.radius,
            gap_gradient: normal,
            coords: Vector2::new(self.radius * angle, axial),
            coords_gradient: [tangent * (self.radius / rho), self.axis],
            gap_hessian: tangent * tangent.transpose() / rho,
            coords_hessian: [
                -(twist + twist.transpose()) * (self.radius / (rho * rho)),
                Matrix3::zeros(),
            ],
        })
    }

    fn coords_period(&self) -> [Option<f64>; 2] {
        [Some(std::f64::consts::TAU * self.radius), None]
    }

    /// With `rho = |y_perp|`, `g = rho - R` and `rho_end^2 - rho_start^2 = (y_perp,start +
    /// y_perp,end) . (y_end - y_start)`, so `G = (y_perp,start + y_perp,end) / S` with
    /// `S = rho_start + rho_end`, and `dG/dy_end = (P - G n_end^T) / S` (`P = I - e e^T`), which
    /// is half the Hessian `t t^T / rho` when the points merge. The gap is invariant under
    /// rotations about the cylinder's own axis only.
    fn gap_discrete_gradient(
        &self,
        y_start: &Vector3<f64>,
        y_end: &Vector3<f64>,
        rotation_axis: &Vector3<f64>,
    ) -> Option<DiscreteGradient> {
        if self.axis.cross(rotation_axis).norm() > 1e-12 {
            return None;
        }
        let perp = |y: &Vector3<f64>| y - self.axis * self.axis.dot(y);
        let (start, end) = (perp(y_start), perp(y_end));
        let sum = start.norm() + end.norm();
        let gradient = (start + end) / sum;
        let across = Matrix3::identity() - self.axis * self.axis.transpose();
        let pull = gradient * (end / end.norm()).transpose();
        let jacobian = (across - (pull + pull.transpose()) * 0.5) / sum;
        (sum > 0.0
            && gradient
                .iter()
                .chain(jacobian.iter())
                .all(|c| c.is_finite()))
        .then_some(DiscreteGradient { gradient, jacobian })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// The discrete gradient turns the change of the gap into an exact dot product, tends to the
    /// normal as the points merge, and is refused for a rotation that moves the surface.
    #[test]
    fn cylinder_discrete_gradient_is_exact_over_a_finite_step() -> Result<(), ContactError> {
        let axis = Vector3::new(0.3, -0.2, 1.0);
        let c = AnalyticCylinder::new(0.2, axis)?;
        let e = c.axis();
        let gap = |y: &Vector3<f64>| c.project(y).map(|p| p.gap).unwrap_or(f64::NAN);
        let y0 = Vector3::new(0.05, 0.19, 0.01);
        // a node moving mostly along the surface: the end-point normal does not see the change
        for y1 in [
            Vector3::new(-0.02, 0.2, 0.03),
            Vector3::new(0.06, 0.185, -0.02),
            Vector3::new(0.1, 0.1, 0.0),
        ] {
            let discrete = c.gap_discrete_gradient(&y0, &y1, &e).expect("gradient");
            let g = discrete.gradient;
            let exact = gap(&y1) - gap(&y0);
            // the jacobian is the symmetric part of the derivative in the end point
            let h = 1e-7;
            let derivative = Matrix3::from_fn(|i, j| {
                let step = Vector3::ith(j, h);
                let at =
                    |y: Vector3<f64>| c.gap_discrete_gradient(&y0, &y, &e).expect("g").gradient;
                (at(y1 + step)[i] - at(y1 - step)[i]) / (2.0 * h)
            });
            let symmetric = (derivative + derivative.transpose()) * 0.5;
            assert!(
                (symmetric - discrete.jacobian).amax() < 1e-6,
                "{symmetric} vs {}",
                discrete.jacobian
            );
            assert!((g.dot(&(y1 - y0)) - exact).abs() < 1e-15, "{exact}");
            let end_normal = c.project(&y1).expect("projection").gap_gradient;
            assert!((end_normal.dot(&(y1 - y0)) - exact).abs() > 1e-5);
        }
        let y1 = y0 + Vector3::new(1e-9, -2e-9, 3e-9);
        let discrete = c.gap_discrete_gradient(&y0, &y1, &e).expect("gradient");
        let at_start = c.project(&y0).expect("projection");
        assert!((discrete.gradient - at_start.gap_gradient).norm() < 1e-7);
        assert!((discrete.jacobian * 2.0 - at_start.gap_hessian).amax() < 1e-6);
        assert!(
            c.gap_discrete_gradient(&y0, &y1, &Vector3::new(1.0, 0.0, 0.0))
                .is_none()
        );
        Ok(())
    }

    /// Every surface's shape lies on it: the cylinder's reference direction at radius R (arc
    /// length 0), the plane's span, the prism's vertices, the triangles' corners; the frames are
    /// orthonormal and right-handed.
    #[test]
    fn shapes_lie_on_their_surfaces() -> Result<(), ContactError> {
        use crate::facets::FacetedCylinder;
        use crate::plane::RigidPlane;
        use crate::triangles::TriangulatedSurface;
        let axis = Vector3::new(0.3, -0.5, 0.8);
        let on_surface = |s: &dyn RigidSurface, y: Vector3<f64>| {
            let p = s.project(&y).expect("projection");
            assert!(p.gap.abs() < 1e-14, "gap {} at {y:?}", p.gap);
            p
        };
        let cylinder = AnalyticCylinder::new(0.2, axis)?;
        let SurfaceShape::Cylinder {
            radius,
            axis: e,
            reference,
        } = cylinder.shape()
        else {
            panic!("a cylinder");
        };
        assert_eq!(radius, 0.2);
        assert!(e.dot(&reference).abs() < 1e-15 && (e.norm() - 1.0).abs() < 1e-15);
        let p = on_surface(&cylinder, reference * radius + e * 0.3);
        assert!(p.coords[0].abs() < 1e-15 && (p.coords[1] - 0.3).abs() < 1e-15);

        let plane = RigidPlane::new(Vector3::new(0.0, 2.0, 1.0), Vector3::x())?;
        let SurfaceShape::Plane { normal, tangents } = plane.shape() else {
            panic!("a plane");
        };
        assert!((tangents[0].cross(&tangents[1]) - normal).norm() < 1e-15);
        let p = on_surface(&plane, tangents[0] * 0.4 - tangents[1] * 0.1);
        assert!((p.coords - Vector2::new(0.4, -0.1)).norm() < 1e-15);

        let prism = FacetedCylinder::new(0.2, axis, 7, 0.1)?;
        let SurfaceShape::Prism { axis: e, vertices } = prism.shape() else {
            panic!("a prism");
        };
        assert_eq!(vertices.len(), 7);
        for (k, v) in vertices.iter().enumerate() {
            on_surface(&prism, *v + e * 0.05);
            // counter-clockwise about the axis
            let next = vertices[(k + 1) % 7];
            assert!(v.cross(&next).dot(&e) > 0.0);
        }

        let triangles = TriangulatedSurface::closed_prism(
            &FacetedCylinder::new(0.2, Vector3::z(), 6, 0.0)?,
            [-0.1, 0.1],
        )?;
        let SurfaceShape::Triangles(corners) = triangles.shape() else {
            panic!("triangles");
        };
        assert_eq!(corners.len(), 4 * 6);
        // the end caps' centres lie on the chart axis, where the projection is undefined
        for corner in corners.iter().flatten().filter(|c| c.xy().norm() > 0.0) {
            on_surface(&triangles, *corner);
        }
        Ok(())
    }

    #[test]
    fn rejects_invalid_data() {
        assert!(matches!(
            AnalyticCylinder::new(0.0, Vector3::z()),
            Err(ContactError::InvalidSurface(_))
        ));
        assert!(AnalyticCylinder::new(f64::NAN, Vector3::z()).is_err());
        assert!(AnalyticCylinder::new(0.2, Vector3::zeros()).is_err());
        assert!(AnalyticCylinder::new(0.2, Vector3::new(f64::INFINITY, 0.0, 1.0)).is_err());
    }

    #[test]
    fn z_axis_uses_conventional_polar_angle() -> Result<(), ContactError> {
        let drum = AnalyticCylinder::new(0.2, Vector3::new(0.0, 0.0, 3.0))?;
        assert_relative_eq!(drum.axis(), Vector3::z());
        assert_relative_eq!(drum.reference_direction(), Vector3::x());
        let y = Vector3::new(0.0, 0.25, 0.07);
        let p = drum
            .project(&y)
            .ok_or(ContactError::InvalidSurface("none".into()))?;
        assert_relative_eq!(p.gap, 0.05, epsilon = 1e-15);
        assert_relative_eq!(p.gap_gradient, Vector3::y(), epsilon = 1e-15);
        assert_relative_eq!(
            p.coords[0],
            0.2 * std::f64::consts::FRAC_PI_2,
            epsilon = 1e-15
        );
        assert_relative_eq!(p.coords[1], 0.07, epsilon = 1e-15);
        // counter-clockwise tangent at +y is -x, scaled by R / rho
        assert_relative_eq!(p.coords_gradient[0], -Vector3::x() * 0.8, epsilon = 1e-15);
        assert_eq!(drum.coords_period()[0], Some(0.4 * std::f64::consts::PI));
        assert_eq!(drum.coords_period()[1], None);
        Ok(())
    }

    #[test]
    fn undefined_on_axis() -> Result<(), ContactError> {
        let drum = AnalyticCylinder::new(0.2, Vector3::new(1.0, 1.0, 0.0))?;
        assert!(drum.project(&Vector3::new(0.3, 0.3, 0.0)).is_none());
        assert!(drum.project(&Vector3::new(f64::NAN, 0.0, 0.0)).is_none());
        Ok(())
    }

    #[test]
    fn gradients_match_finite_differences_for_oblique_axis() -> Result<(), ContactError> {
        let drum = AnalyticCylinder::new(0.2, Vector3::new(0.3, -0.5, 0.8))?;
        let y = Vector3::new(0.11, 0.17, -0.05);
        crate::facets::tests::check_gradients(&drum, &y, 1e-6);
        let p = drum
            .project(&y)
            .ok_or(ContactError::InvalidSurface("none".into()))?;
        let h = 1e-6;
        for k in 0..3 {
            let mut yp = y;
            let mut ym = y;
            yp[k] += h;
            ym[k] -= h;
            let pp = drum
                .project(&yp)
                .ok_or(ContactError::InvalidSurface("none".into()))?;
            let pm = drum
                .project(&ym)
                .ok_or(ContactError::InvalidSurface("none".into()))?;
            assert_relative_eq!(
                (pp.gap - pm.gap) / (2.0 * h),
                p.gap_gradient[k],
                epsilon = 1e-8
            );
            for c in 0..2 {
                assert_relative_eq!(
                    (pp.coords[c] - pm.coords[c]) / (2.0 * h),
                    p.coords_gradient[c][k],
                    epsilon = 1e-8
                );
            }
        }
        Ok(())
    }
}
