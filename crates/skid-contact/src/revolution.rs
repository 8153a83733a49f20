//! Rigid surface of revolution (3D): a profile of straight segments and arcs in the `r-z`
//! half-plane revolved about an axis through the body origin, such as a stepped drum, a cone,
//! a roller with flanges or a spherical indenter.

use nalgebra::{Matrix2x3, Matrix3, Vector2, Vector3};

use crate::error::ContactError;
use crate::polyline::{RigidPolyline, lift_from_plane};
use crate::surface::{
    AnalyticCylinder, DiscreteGradient, Projection, RigidSurface, Slip, SurfacePoint, SurfaceShape,
};

/// The surface swept by the [`RigidPolyline`] `profile` of the `r-z` half-plane (`r >= 0` the
/// distance from the unit axis `e`, `z = e.y`; its outside on the right walking along it with
/// `r` to the right and `z` up, so that the cylinder `r = R` is walked towards `+z`) revolved
/// about `e` through the body origin.
///
/// The closest point of a body-frame point `y` lies in its meridian half-plane, so with
/// `z = e.y`, `r = |y - z e|`, `u = (y - z e)/r` and `w = e x u`, the gap is the profile's in
/// `(r, z)`, `g = g_p(r, z)`, and every profile function `f(r, z)` (gap, arc length) has
/// `df/dy = f_r u + f_z e` and `d^2f/dy^2 = [u e] H_f [u e]^T + f_r w w^T / r` (`H_f` its
/// `(r, z)` Hessian; `d^2 r/dy^2 = w w^T / r`). The coordinates are `xi_0 = R theta`, the angle
/// about `e` scaled by the chart radius `R` as on [`AnalyticCylinder`] (so that slip is a length
/// on the surface where `r = R`, and `r/R` of one elsewhere), and `xi_1 = s`, the profile's arc
/// length; friction measures slip in lengths in the tangent plane of the increment's start
/// point instead (see [`RigidSurface::slip`] below). On the axis the point is taken a round-off
/// distance off it (see [`RigidSurface::project`] below). An open profile's ends off the axis
/// are the surface's edges (see [`RigidPolyline`]); an end on the axis is not, since the
/// revolved surface closes there.
#[derive(Clone, Debug)]
pub struct RigidRevolution {
    profile: RigidPolyline,
    chart: AnalyticCylinder,
    /// The profile's largest distance from the origin of the `r-z` plane, its length scale.
    size: f64,
}

/// Distance from the axis, relative to the profile's size, below which a point is projected as
/// on the axis (see [`RigidRevolution::project`]).
const ON_AXIS: f64 = 1e-12;

impl RigidRevolution {
    /// The revolution of `profile` (in `(r, z)`, `r >= 0`) about `axis`, with the chart radius
    /// `radius` of the circumferential coordinate.
    ///
    /// # Errors
    /// [`ContactError::InvalidSurface`] for a profile that reaches `r < 0`, or an invalid axis
    /// or radius.
    pub fn new(
        axis: Vector3<f64>,
        mut profile: RigidPolyline,
        radius: f64,
    ) -> Result<Self, ContactError> {
        let (low, high) = profile.bounds();
        if low.x < 0.0 || low.x.is_nan() {
            return Err(ContactError::InvalidSurface(format!(
                "a profile of revolution lies at r >= 0, this one reaches r = {}",
                low.x
            )));
        }
        let size = low.abs().sup(&high.abs()).max();
        // an end on the axis is no edge: the revolved surface closes there
        for (end, point) in profile.ends().into_iter().enumerate() {
            if point.x <= ON_AXIS * size {
                profile = profile.continued_at(end);
            }
        }
        Ok(Self {
            size,
            profile,
            chart: AnalyticCylinder::new(radius, axis)?,
        })
    }
}

impl RigidSurface for RigidRevolution {
    fn shape(&self) -> SurfaceShape {
        SurfaceShape::Revolution {
            axis: self.chart.axis(),
            reference: self.chart.reference_direction(),
            profile: self.profile.drawn_points(),
            closed: self.profile.is_closed(),
        }
    }

    /// A point on the axis (`r` below [`ON_AXIS`] times the profile's size) is projected as if
    /// it stood that far off the axis towards the reference direction `b_1`: the gap and its
    /// derivatives are continuous there wherever the surface is smooth on the axis (a profile
    /// that meets it at a right angle, as a sphere's pole), and the limits of `f_r / r` come out
    /// of the profile's own derivatives; the angle, undefined on the axis, is taken as 0.
    fn project(&self, y: &Vector3<f64>) -> Option<Projection> {
        let e = self.chart.axis();
        let z = e.dot(y);
        let radial = y - e * z;
        let on_axis = ON_AXIS * self.size;
        // the unit radial direction u exactly b_1 on the axis (from the rounded radial part it
        // would be off by round-off over ON_AXIS)
        let (r, u, around) = match radial.norm() {
            r if r < on_axis => {
                let u = self.chart.reference_direction();
                (on_axis, u, self.chart.project(&(e * z + u * on_axis))?)
            }
            // the angle and its derivatives from the chart cylinder
            r => (r, radial / r, self.chart.project(y)?),
        };
        let w = e.cross(&u);
        let meridian = self.profile.project(&Vector3::new(r, z, 0.0))?;
        // [u e]^T: rows u and e map (r, z) derivatives to y
        let frame = Matrix2x3::from_rows(&[u.transpose(), e.transpose()]);
        // plus the curvature of r: f_r w w^T / r
        let lift = |gradient: &Vector3<f64>, hessian| {
            let (g, h) = lift_from_plane(&frame, gradient, hessian);
            (g, h + w * w.transpose() * (gradient.x / r))
        };
        let (gap_gradient, gap_hessian) = lift(&meridian.gap_gradient, &meridian.gap_hessian);
        let (arc_gradient, arc_hessian) =
            lift(&meridian.coords_gradient[0], &meridian.coords_hessian[0]);
        Some(Projection {
            gap: meridian.gap,
            gap_gradient,
            coords: Vector2::new(around.coords[0], meridian.coords[0]),
            coords_gradient: [around.coords_gradient[0], arc_gradient],
            gap_hessian,
            coords_hessian: [around.coords_hessian[0], arc_hessian],
        })
    }

    fn coords_period(&self) -> [Option<f64>; 2] {
        [
            self.chart.coords_period()[0],
            self.profile.coords_period()[0],
        ]
    }

    /// The slip in the tangent plane at the start point `p_0`, whose coordinates `from` give
    /// its angle `theta_0 = xi_0 / R` about the axis and its arc length `xi_1` along the
    /// profile, where the profile is at `(r_0, z_0)` with unit tangent `(t_r, t_z)`: with
    /// `u_0 = cos theta_0 b_1 + sin theta_0 b_2` and `p_0 = r_0 u_0 + z_0 e`, the
    /// circumferential and meridional unit tangents `t_0 = e x u_0` and `t_1 = t_r u_0 + t_z e`
    /// give `s_k = t_k . (y - p_0)`, gradients `t_k` and no curvature. The angle's increments
    /// are no lengths (`R dtheta` is one only where `r = R`: friction would be weighed by
    /// `R / r`); these are, at every radius, and orthonormal, as a plane's coordinates are.
    fn slip(&self, from: &SurfacePoint, y: &Vector3<f64>, to: &Projection) -> Slip {
        let from = &from.coords;
        let Some((point, tangent)) = self.profile.point_at(from.y) else {
            return Slip::of_coordinates(self.coords_period(), from, to);
        };
        let e = self.chart.axis();
        let b1 = self.chart.reference_direction();
        let (sin, cos) = (from.x / self.chart.radius()).sin_cos();
        let u = b1 * cos + e.cross(&b1) * sin;
        let moved = y - (u * point.x + e * point.y);
        let tangents = [e.cross(&u), u * tangent.x + e * tangent.y];
        Slip {
            value: Vector2::new(tangents[0].dot(&moved), tangents[1].dot(&moved)),
            gradient: tangents,
            hessian: [Matrix3::zeros(); 2],
        }
    }

    /// Where both points are closest to the interior of one profile segment, of outward normal
    /// `n = (n_r, n_z)`, the gap is `n_r r + n_z z` plus a constant, and with the cylinder's
    /// `r_end - r_start = (y_perp,start + y_perp,end)/S . (y_end - y_start)`
    /// (`S = r_start + r_end`) `G = n_r (y_perp,start + y_perp,end)/S + n_z e`, with
    /// `dG/dy_end` `n_r` times the cylinder's (see [`AnalyticCylinder`]). Elsewhere (a vertex
    /// between them) `None`. The gap is invariant under rotations about the surface's own axis
    /// only.
    fn gap_discrete_gradient(
        &self,
        y_start: &Vector3<f64>,
        y_end: &Vector3<f64>,
        rotation_axis: &Vector3<f64>,
    ) -> Option<DiscreteGradient> {
        // (the chart cylinder refuses another rotation axis)
        let e = self.chart.axis();
        let perp = |y: &Vector3<f64>| y - e * e.dot(y);
        let (start, end) = (perp(y_start), perp(y_end));
        let meridian =
            |y: &Vector3<f64>, radial: &Vector3<f64>| Vector2::new(radial.norm(), e.dot(y));
        let (k, normal) = self.profile.interior_segment(&meridian(y_start, &start))?;
        let (k_end, _) = self.profile.interior_segment(&meridian(y_end, &end))?;
        if k != k_end {
            return None;
        }
        // the radial part is the chart cylinder's discrete gradient of r
        let radial = self
            .chart
            .gap_discrete_gradient(y_start, y_end, rotation_axis)?;
        Some(DiscreteGradient {
            gradient: radial.gradient * normal.x + e * normal.y,
            jacobian: radial.jacobian * normal.x,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::facets::tests::check_gradients;

    fn project(surface: &dyn RigidSurface, y: &Vector3<f64>) -> Projection {
        surface.project(y).expect("projection defined")
    }

    /// A drum with a step and a cone: r = 0.2 for z in [-0.1, 0], a cone out to r = 0.25 at
    /// z = 0.05, then r = 0.25 to z = 0.1; walked towards +z so that the outside is at larger r.
    fn stepped() -> RigidRevolution {
        let profile = RigidPolyline::new(
            vec![
                Vector2::new(0.2, -0.1),
                Vector2::new(0.2, 0.0),
                Vector2::new(0.25, 0.05),
                Vector2::new(0.25, 0.1),
            ],
            false,
        )
        .expect("profile");
        RigidRevolution::new(Vector3::new(0.0, 0.0, 2.0), profile, 0.2).expect("revolution")
    }

    /// Slip is measured in lengths in the tangent plane of the start point: none at the start;
    /// a turn `dtheta` about the axis at radius `r` slips `r sin(dtheta)` round it (not the chart's
    /// `R dtheta`, `R = 0.2` here); a move along the cone's generator slips its length along
    /// the profile; the two directions are orthonormal and tangent to the surface at the start.
    #[test]
    fn slip_is_measured_in_lengths_in_the_start_tangent_plane() {
        let surface = stepped();
        // the cone runs from (r, z) = (0.2, 0) to (0.25, 0.05)
        let point = |theta: f64, r: f64, z: f64| Vector3::new(r * theta.cos(), r * theta.sin(), z);
        let start = point(0.3, 0.225, 0.025);
        let from = project(&surface, &start);
        assert!(from.gap.abs() < 1e-15);
        let slip =
            |y: Vector3<f64>| surface.slip(&from.closest(&start), &y, &project(&surface, &y));
        let still = slip(start);
        assert!(still.value.norm() < 1e-15, "{}", still.value);
        let [round, along] = still.gradient;
        assert!((round.norm() - 1.0).abs() < 1e-15 && (along.norm() - 1.0).abs() < 1e-15);
        assert!(round.dot(&along).abs() < 1e-15);
        assert!(round.dot(&from.gap_gradient).abs() < 1e-15);
        assert!(along.dot(&from.gap_gradient).abs() < 1e-15);
        assert_eq!(still.hessian, [Matrix3::zeros(); 2]);
        let turn = 0.01;
        let turned = slip(point(0.3 + turn, 0.225, 0.025));
        assert!(
            (turned.value.x - 0.225 * turn.sin()).abs() < 1e-15,
            "{}",
            turned.value
        );
        let step = 0.01 / 2f64.sqrt();
        let moved = slip(point(0.3, 0.225 + step, 0.025 + step));
        assert!(
            (moved.value - Vector2::new(0.0, 0.01)).norm() < 1e-15,
            "{}",
            moved.value
        );
        // the gradients are those of the value, which is linear in y
        let y = point(0.32, 0.231, 0.03);
        let h = Vector3::new(1e-3, -2e-3, 0.5e-3);
        let change = slip(y + h).value - slip(y).value;
        for k in 0..2 {
            assert!((change[k] - still.gradient[k].dot(&h)).abs() < 1e-15);
        }
    }

    /// A profile's end on the axis is no edge, its end off the axis is: under the apex of a
    /// cone whose solid lies below it (the profile walked down to the axis) a point is inside,
    /// while beyond the cone's rim, below its level, a point is off the surface.
    #[test]
    fn only_the_ends_off_the_axis_are_edges() -> Result<(), ContactError> {
        let cone = RigidRevolution::new(
            Vector3::z(),
            RigidPolyline::new(vec![Vector2::new(1.0, 1.0), Vector2::zeros()], false)?,
            1.0,
        )?;
        for y in [Vector3::new(0.0, 0.0, -0.1), Vector3::new(0.05, 0.0, -0.2)] {
            let p = project(&cone, &y);
            assert!((p.gap + y.norm()).abs() < 1e-12, "{y:?}: {}", p.gap);
        }
        // beyond the rim r = 1, z = 1 along the profile, below the cone's surface
        let beyond = Vector3::new(0.0, 1.2, 1.1);
        let p = project(&cone, &beyond);
        assert!((p.gap - 0.2_f64.hypot(0.1)).abs() < 1e-12, "{}", p.gap);
        Ok(())
    }

    /// The straight profile r = R is the analytical cylinder: the same gap, coordinates (the
    /// axial one from the profile's first point) and derivatives.
    #[test]
    fn a_straight_profile_is_the_cylinder() -> Result<(), ContactError> {
        let axis = Vector3::new(0.3, -0.2, 1.0);
        let cylinder = AnalyticCylinder::new(0.2, axis)?;
        let revolution = RigidRevolution::new(
            axis,
            RigidPolyline::new(vec![Vector2::new(0.2, -1.0), Vector2::new(0.2, 1.0)], false)?,
            0.2,
        )?;
        for y in [
            Vector3::new(0.21, 0.03, 0.05),
            Vector3::new(-0.1, 0.19, -0.2),
            Vector3::new(0.0, -0.15, 0.3),
        ] {
            let (a, b) = (project(&cylinder, &y), project(&revolution, &y));
            assert!((a.gap - b.gap).abs() < 1e-15);
            assert!((a.coords[0] - b.coords[0]).abs() < 1e-15);
            assert!((a.coords[1] - (b.coords[1] - 1.0)).abs() < 1e-14);
            assert!((a.gap_gradient - b.gap_gradient).norm() < 1e-14);
            assert!((a.gap_hessian - b.gap_hessian).norm() < 1e-12);
            for k in 0..2 {
                assert!((a.coords_gradient[k] - b.coords_gradient[k]).norm() < 1e-14);
                assert!((a.coords_hessian[k] - b.coords_hessian[k]).norm() < 1e-12);
            }
        }
        Ok(())
    }

    /// On one profile segment the discrete gradient gives the change of the gap exactly (the
    /// cone's points turned about the axis as well); across a vertex, or for a rotation about
    /// another axis, there is none; on a straight profile it is the cylinder's.
    #[test]
    fn the_discrete_gradient_gives_the_change_of_the_gap() -> Result<(), ContactError> {
        let surface = stepped();
        let e = Vector3::z();
        let (start, end) = (
            Vector3::new(0.0, 0.25, 0.0),
            Vector3::new(0.18, 0.17, 0.012),
        );
        let d = surface
            .gap_discrete_gradient(&start, &end, &e)
            .expect("both on the cone");
        let change = project(&surface, &end).gap - project(&surface, &start).gap;
        assert!(
            (d.gradient.dot(&(end - start)) - change).abs() < 1e-16,
            "{change}"
        );
        let across = Vector3::new(0.21, 0.0, -0.05);
        assert!(surface.gap_discrete_gradient(&start, &across, &e).is_none());
        assert!(
            surface
                .gap_discrete_gradient(&start, &end, &Vector3::x())
                .is_none()
        );
        let axis = Vector3::new(0.3, -0.2, 1.0);
        let cylinder = AnalyticCylinder::new(0.2, axis)?;
        let straight = RigidRevolution::new(
            axis,
            RigidPolyline::new(vec![Vector2::new(0.2, -1.0), Vector2::new(0.2, 1.0)], false)?,
            0.2,
        )?;
        let (a, b) = (
            Vector3::new(0.21, 0.03, 0.05),
            Vector3::new(0.2, 0.06, 0.04),
        );
        let (c, r) = (
            cylinder
                .gap_discrete_gradient(&a, &b, &axis)
                .expect("cylinder"),
            straight
                .gap_discrete_gradient(&a, &b, &axis)
                .expect("revolution"),
        );
        assert_eq!((c.gradient, c.jacobian), (r.gradient, r.jacobian));
        Ok(())
    }

    /// Gap and coordinates against finite differences on the cylinder, the cone, beyond its
    /// convex corner and inside the surface.
    #[test]
    fn gradients_match_finite_differences() {
        let surface = stepped();
        for y in [
            Vector3::new(0.21, 0.02, -0.05),
            Vector3::new(0.05, 0.22, 0.03),
            Vector3::new(-0.26, 0.02, 0.06),
            Vector3::new(0.18, -0.05, 0.09),
            Vector3::new(0.15, 0.1, -0.02),
        ] {
            check_gradients(&surface, &y, 1e-6);
        }
    }

    /// Two quarter circles about the origin, from the south pole up to the north pole,
    /// revolved: a sphere, whose gap is `|y| - R` and whose derivatives match finite
    /// differences.
    #[test]
    fn a_revolved_half_circle_is_a_sphere() -> Result<(), ContactError> {
        let r = 0.3;
        let profile = RigidPolyline::with_arcs(
            vec![
                Vector2::new(0.0, -r),
                Vector2::new(r, 0.0),
                Vector2::new(0.0, r),
            ],
            vec![Some(Vector2::zeros()), Some(Vector2::zeros())],
            false,
        )?;
        let sphere = RigidRevolution::new(Vector3::new(0.1, 0.0, 1.0), profile, r)?;
        for y in [
            Vector3::new(0.31, 0.02, -0.05),
            Vector3::new(-0.1, 0.2, 0.25),
            Vector3::new(0.05, -0.12, -0.2),
        ] {
            let p = project(&sphere, &y);
            assert!((p.gap - (y.norm() - r)).abs() < 1e-15, "{y:?}");
            assert!((p.gap_gradient - y.normalize()).norm() < 1e-14);
            check_gradients(&sphere, &y, 1e-6);
        }
        // on the axis, above a pole, at it and inside: the sphere's gap, normal and curvature
        // (I - n n^T) / |y|, also in the limit f_r / r of the profile's curvature
        let e = Vector3::new(0.1, 0.0, 1.0).normalize();
        for t in [0.45, -0.7, r, 0.1] {
            let y = e * t;
            let p = project(&sphere, &y);
            let n = e * t.signum();
            assert!((p.gap - (t.abs() - r)).abs() < 1e-15, "{t}: {}", p.gap);
            assert!(
                (p.gap_gradient - n).norm() < 1e-11,
                "{t}: {}",
                p.gap_gradient
            );
            let curvature = (Matrix3::identity() - n * n.transpose()) / t.abs();
            assert!(
                (p.gap_hessian - curvature).norm() < 1e-9,
                "{t}: {}",
                p.gap_hessian
            );
            assert!(p.coords.iter().all(|c| c.is_finite()));
        }
        Ok(())
    }

    /// On the cone the gap is the distance to it in the meridian half-plane, its normal the
    /// profile's normal turned about the axis.
    #[test]
    fn the_gap_is_measured_in_the_meridian_plane() {
        let surface = stepped();
        // the cone's outward normal in (r, z): (0.05, 0.05) turned clockwise, (1, -1)/sqrt 2
        let y = Vector3::new(0.0, 0.25, 0.0);
        let p = project(&surface, &y);
        let along = (Vector2::new(0.25, 0.0) - Vector2::new(0.2, 0.0))
            .dot(&(Vector2::new(1.0, -1.0) / 2f64.sqrt()));
        assert!((p.gap - along).abs() < 1e-15, "{} vs {along}", p.gap);
        let normal = Vector3::new(0.0, 1.0, -1.0) / 2f64.sqrt();
        assert!((p.gap_gradient - normal).norm() < 1e-15);
        assert_eq!(surface.coords_period()[1], None);
        assert!(
            RigidRevolution::new(
                Vector3::z(),
                RigidPolyline::new(vec![Vector2::new(-0.1, 0.0), Vector2::new(0.2, 0.0)], false)
                    .expect("profile"),
                0.2
            )
            .is_err()
        );
    }
}
