//! Gap and slip kinematics of a slave node against a surface carried by a rigid body rotating
//! about a fixed axis.
//!
//! With body reference point `c`, unit world axis `e` and angle `theta`, `Q(theta)` is the rotation
//! by `theta` about `e` and the body frame is `y = Q^T (x - c)`. Since `dQ/dtheta = [e]x Q` and
//! `Q^T e = e`, `dy = Q^T dx - (e x y) dtheta`. For any surface function `f(y)` with gradient
//! `G = df/dy` and Hessian `F = d^2f/dy^2` this gives, with `w = e x y`,
//! - `df/dx = Q G` and `df/dtheta = -G . w`;
//! - `d^2f/dx^2 = Q F Q^T`, `d^2f/dx dtheta = e x (Q G) - Q F w` and
//!   `d^2f/dtheta^2 = w . F w + G . (e x w)` (from `dw/dtheta = -e x w`).
//!
//! The second derivatives give the stiffness of the contact forces `r` on a curved or rotating
//! surface, `sum_k r_k d^2 u_k` (see `skid_integrator::coupling`).

use nalgebra::{Matrix3, Rotation3, Unit, Vector2, Vector3};

use crate::surface::{DiscreteGradient, RigidSurface, SurfacePoint};

/// Placement of a rigid body rotating about a fixed axis.
#[derive(Clone, Copy, Debug)]
pub struct RotatingFrame {
    /// Reference point `c` of the body on the rotation axis (world frame).
    pub center: Vector3<f64>,
    /// Unit rotation axis `e` (world frame); it is normalised again on use.
    pub axis: Vector3<f64>,
    /// Rotation angle `theta` (radians, counter-clockwise about `axis`); the body frame coincides
    /// with the world orientation at `theta = 0`.
    pub angle: f64,
}

impl RotatingFrame {
    /// The unit axis `e` and the rotation `Q(theta)`; `None` if the frame is degenerate (zero or
    /// non-finite axis, non-finite centre or angle).
    fn orientation(&self) -> Option<(Unit<Vector3<f64>>, Rotation3<f64>)> {
        let axis = self.unit_axis()?;
        Some((axis, Rotation3::from_axis_angle(&axis, self.angle)))
    }

    /// The unit axis `e` alone, without the rotation (whose sine and cosine cost more than the
    /// rest); `None` where [`Self::orientation`] is.
    fn unit_axis(&self) -> Option<Unit<Vector3<f64>>> {
        if !(self.angle.is_finite() && self.center.iter().all(|c| c.is_finite())) {
            return None;
        }
        Unit::try_new(self.axis, 0.0).filter(|a| a.iter().all(|c| c.is_finite()))
    }

    /// The world position `x = c + Q(theta) y` of the body-frame point `y`; `None` if the frame
    /// is degenerate.
    pub fn to_world(&self, y: &Vector3<f64>) -> Option<Vector3<f64>> {
        let (_, rotation) = self.orientation()?;
        Some(self.center + rotation * y)
    }

    /// The body-frame point `y = Q(theta)^T (x - c)` at the world position `x`; `None` if the
    /// frame is degenerate.
    pub fn to_body(&self, x: &Vector3<f64>) -> Option<Vector3<f64>> {
        let (_, rotation) = self.orientation()?;
        Some(rotation.inverse_transform_vector(&(x - self.center)))
    }
}

/// Gap, slip and their exact first and second derivatives for one slave node, with its closest
/// point.
#[derive(Clone, Debug)]
pub struct ContactKinematics {
    /// Signed gap `g` (`> 0` open).
    pub gap: f64,
    /// The closest point on the surface (body frame): where the next increment's slip starts.
    pub closest: SurfacePoint,
    /// The slip `s` since the contact point the kinematics were evaluated from (see
    /// [`RigidSurface::slip`]): two lengths along the surface.
    pub slip: Vector2<f64>,
    /// World-frame outward unit normal of the surface at the closest point, `Q dg/dy` normalised.
    pub normal: Vector3<f64>,
    /// Derivatives of `[g, s_0, s_1]` with respect to the slave node's world position `x`:
    /// `Q df/dy`.
    pub d_dx: [Vector3<f64>; 3],
    /// Derivatives of `[g, s_0, s_1]` with respect to the body's rotation angle `theta`:
    /// `-(df/dy) . (e x y)`.
    pub d_dangle: [f64; 3],
    /// Second derivatives of `[g, s_0, s_1]` with respect to `x`: `Q F Q^T`.
    pub d2_dx2: [Matrix3<f64>; 3],
    /// Mixed second derivatives with respect to `x` and `theta`: `e x (Q G) - Q F w`.
    pub d2_dx_dangle: [Vector3<f64>; 3],
    /// Second derivatives with respect to `theta`: `w . F w + G . (e x w)`.
    pub d2_dangle2: [f64; 3],
}

/// Evaluate gap, slip since the contact point `from` (see [`RigidSurface::slip`]; `None`: since
/// the node's own closest point, a zero slip with its derivatives) and their exact first and
/// second derivatives for a node at world position `x` (2D problems pass `z = 0` and a `z`
/// axis).
///
/// Returns `None` if the frame is degenerate (zero or non-finite axis, non-finite centre or angle)
/// or the surface projection is undefined at `y = Q^T (x - c)`.
pub fn evaluate(
    surface: &dyn RigidSurface,
    frame: &RotatingFrame,
    x: &Vector3<f64>,
    from: Option<&SurfacePoint>,
) -> Option<ContactKinematics> {
    let (axis, rotation) = frame.orientation()?;
    let y = rotation.inverse_transform_vector(&(x - frame.center));
    let projection = surface.project(&y)?;
    let closest = projection.closest(&y);
    let slip = surface.slip(from.unwrap_or(&closest), &y, &projection);
    let body_velocity = axis.cross(&y);
    let gradients = [projection.gap_gradient, slip.gradient[0], slip.gradient[1]];
    let hessians = [projection.gap_hessian, slip.hessian[0], slip.hessian[1]];
    let world = rotation.matrix();
    let mut d2_dx_dangle = [Vector3::zeros(); 3];
    let mut d2_dangle2 = [0.0; 3];
    for (k, (g, f)) in gradients.iter().zip(&hessians).enumerate() {
        let f_w = f * body_velocity;
        d2_dx_dangle[k] = axis.cross(&(rotation * g)) - rotation * f_w;
        d2_dangle2[k] = body_velocity.dot(&f_w) + g.dot(&axis.cross(&body_velocity));
    }
    let normal_world = rotation * projection.gap_gradient;
    let normal_norm = normal_world.norm();
    let normal = if normal_norm > 0.0 {
        normal_world / normal_norm
    } else {
        normal_world
    };
    Some(ContactKinematics {
        gap: projection.gap,
        closest,
        slip: slip.value,
        normal,
        d_dx: gradients.map(|g| rotation * g),
        d_dangle: gradients.map(|g| -g.dot(&body_velocity)),
        d2_dx2: hessians.map(|f| world * f * world.transpose()),
        d2_dx_dangle,
        d2_dangle2,
    })
}

/// World-frame discrete gradient of the gap over an increment (see
/// [`RigidSurface::gap_discrete_gradient`]) for a node now at world position `x` that started
/// the increment at `start_offset = x_start - c_start` from the body reference point: the start
/// point is taken into the current body frame, which the surface's rotation invariance allows.
/// Then `G . ((x - c) - start_offset)` is exactly the change of the gap over the increment.
///
/// Its Jacobian (in `x`, rotated to the world frame alike) is independent of the body's angle
/// for the same reason.
///
/// `None` if the frame is degenerate or the surface offers no discrete gradient.
pub fn gap_discrete_gradient(
    surface: &dyn RigidSurface,
    frame: &RotatingFrame,
    start_offset: &Vector3<f64>,
    x: &Vector3<f64>,
) -> Option<DiscreteGradient> {
    let (axis, rotation) = frame.orientation()?;
    let y_end = rotation.inverse_transform_vector(&(x - frame.center));
    let y_start = rotation.inverse_transform_vector(start_offset);
    let world = rotation.matrix();
    surface
        .gap_discrete_gradient(&y_start, &y_end, &axis)
        .map(|g| DiscreteGradient {
            gradient: rotation * g.gradient,
            jacobian: world * g.jacobian * world.transpose(),
        })
}

/// Smallest body rotation over an increment, rad, for which [`rotation_column`] is formed: below
/// it the difference quotients lose more to round-off (about `eps |f| / dtheta`) than the
/// end-point derivative misses (about `|d^2f/dtheta^2| dtheta / 2`).
pub const MIN_SECANT_TURN: f64 = 1e-8;

/// Largest rotation column, over the node's lever arm `|r_0|`, that [`rotation_column`] gives
/// with the translation's remainder: a rotation row is at most about `|r_0|` (`df/dtheta =
/// -(df/dy) . (e x y)`), so a larger one is a remainder divided by a turn that is small against
/// the node's motion.
pub const MAX_COLUMN_LEVER: f64 = 2.0;

/// The start of an increment for [`rotation_column`]: the body's angle `theta_0` and the node's
/// offset `r_0 = x_0 - c_0` from the body's reference point.
#[derive(Clone, Copy, Debug)]
pub struct IncrementStart {
    /// `theta_0`, rad.
    pub angle: f64,
    /// `r_0` (world frame).
    pub offset: Vector3<f64>,
}

/// Rotation column of a node's rows `f = [g, s_0, s_1]` over an increment that makes them a
/// discrete gradient. With the end-point `df/dx` (`end.d_dx`, the kinematics evaluated from the
/// contact point at the start `y_0`, so that `end.slip` is the slip over the increment) in the
/// node and translation columns, the body now at `theta_1 = frame.angle` and the node at offset
/// `r_1 = x_1 - c_1`:
///
/// `col = (f(y_1) - f(y_0) - df/dx . (r_1 - r_0)) / (theta_1 - theta_0)`,
///
/// so that `H dz = f(y_1) - f(y_0)` exactly (the slip from `y_0`, see
/// [`RigidSurface::slip`]), and a contact force along the rows does exactly the work `p . df` of the
/// contact law. Where `f` is affine between `Q_1^T r_0` and `y_1` (on one flat facet or plane)
/// the column is the secant in the rotation, `(f(Q_1^T r_0) - f(Q_0^T r_0)) / dtheta`, which
/// tends to `df/dtheta`; the end-point `df/dtheta` would miss the second-order term
/// `p_N (d^2 g/dtheta^2) dtheta^2 / 2` (about `p_N R dtheta^2 / 2` on a drum of radius `R`),
/// energy created or lost every increment. Where `f` is curved or kinked in between (a vertex
/// wedge or an edge passed), the column also carries the translation's remainder over `dtheta`;
/// if that makes a component exceed [`MAX_COLUMN_LEVER`] `|r_0|`, the secant in the rotation
/// alone is returned instead.
///
/// `None` if the turn is below [`MIN_SECANT_TURN`] or not finite, the frame is degenerate, or a
/// projection is undefined: then the end-point derivative stands.
pub fn rotation_column(
    surface: &dyn RigidSurface,
    frame: &RotatingFrame,
    start: &IncrementStart,
    end_offset: &Vector3<f64>,
    end: &ContactKinematics,
) -> Option<[f64; 3]> {
    let turn = frame.angle - start.angle;
    if !(turn.abs() >= MIN_SECANT_TURN && turn.is_finite()) {
        return None;
    }
    let axis = frame.unit_axis()?;
    let start_rotation = Rotation3::from_axis_angle(&axis, start.angle);
    let y_before = start_rotation.inverse_transform_vector(&start.offset);
    let before = surface.project(&y_before)?;
    let moved = end_offset - start.offset;
    let whole = [end.gap - before.gap, end.slip[0], end.slip[1]];
    let column: [f64; 3] = std::array::from_fn(|k| (whole[k] - end.d_dx[k].dot(&moved)) / turn);
    let bound = MAX_COLUMN_LEVER * start.offset.norm();
    if column.iter().all(|c| c.abs() <= bound) {
        return Some(column);
    }
    let rotation = Rotation3::from_axis_angle(&axis, frame.angle);
    let y_turned = rotation.inverse_transform_vector(&start.offset);
    let turned = surface.project(&y_turned)?;
    let slip = surface
        .slip(&before.closest(&y_before), &y_turned, &turned)
        .value;
    let secant = [turned.gap - before.gap, slip[0], slip[1]].map(|d| d / turn);
    secant.iter().all(|c| c.is_finite()).then_some(secant)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::ContactError;
    use crate::surface::{AnalyticCylinder, unwrapped_increment};
    use approx::assert_relative_eq;
    use std::f64::consts::PI;

    /// The kinematics at `x`, the slip measured from the coordinates' origin.
    fn eval(
        surface: &dyn RigidSurface,
        frame: &RotatingFrame,
        x: &Vector3<f64>,
    ) -> Result<ContactKinematics, ContactError> {
        eval_from(
            surface,
            frame,
            x,
            &SurfacePoint::of_coords(Vector2::zeros()),
        )
    }

    /// The kinematics at `x`, the slip measured from the contact point `from`.
    fn eval_from(
        surface: &dyn RigidSurface,
        frame: &RotatingFrame,
        x: &Vector3<f64>,
        from: &SurfacePoint,
    ) -> Result<ContactKinematics, ContactError> {
        evaluate(surface, frame, x, Some(from))
            .ok_or(ContactError::InvalidSurface("undefined".into()))
    }

    /// Differences of `[g, xi_0, xi_1]` between two states, with `xi` unwrapped.
    fn difference(
        surface: &dyn RigidSurface,
        plus: &ContactKinematics,
        minus: &ContactKinematics,
    ) -> [f64; 3] {
        let slip = unwrapped_increment(
            surface.coords_period(),
            plus.closest.coords - minus.closest.coords,
        );
        [plus.gap - minus.gap, slip[0], slip[1]]
    }

    fn check_derivatives(
        surface: &dyn RigidSurface,
        frame: &RotatingFrame,
        x: &Vector3<f64>,
    ) -> Result<(), ContactError> {
        let k = eval(surface, frame, x)?;
        let h = 1e-6;
        for j in 0..3 {
            let mut xp = *x;
            let mut xm = *x;
            xp[j] += h;
            xm[j] -= h;
            let d = difference(
                surface,
                &eval(surface, frame, &xp)?,
                &eval(surface, frame, &xm)?,
            );
            for (difference, derivative) in d.iter().zip(&k.d_dx) {
                assert_relative_eq!(difference / (2.0 * h), derivative[j], epsilon = 1e-7);
            }
        }
        let plus = RotatingFrame {
            angle: frame.angle + h,
            ..*frame
        };
        let minus = RotatingFrame {
            angle: frame.angle - h,
            ..*frame
        };
        let d = difference(
            surface,
            &eval(surface, &plus, x)?,
            &eval(surface, &minus, x)?,
        );
        for (difference, derivative) in d.iter().zip(k.d_dangle) {
            assert_relative_eq!(difference / (2.0 * h), derivative, epsilon = 1e-7);
        }
        check_second_derivatives(surface, frame, x)
    }

    /// Central differences of the first derivatives against the second ones.
    fn check_second_derivatives(
        surface: &dyn RigidSurface,
        frame: &RotatingFrame,
        x: &Vector3<f64>,
    ) -> Result<(), ContactError> {
        let k = eval(surface, frame, x)?;
        let h = 1e-7;
        let tolerance = |exact: f64| 1e-6 * (1.0 + exact.abs());
        for j in 0..3 {
            let mut xp = *x;
            let mut xm = *x;
            xp[j] += h;
            xm[j] -= h;
            let (plus, minus) = (eval(surface, frame, &xp)?, eval(surface, frame, &xm)?);
            for c in 0..3 {
                let column = (plus.d_dx[c] - minus.d_dx[c]) / (2.0 * h);
                for i in 0..3 {
                    let exact = k.d2_dx2[c][(i, j)];
                    assert!(
                        (column[i] - exact).abs() <= tolerance(exact),
                        "d2/dx2 {c} ({i},{j}): {} vs {exact}",
                        column[i]
                    );
                }
                let mixed = (plus.d_dangle[c] - minus.d_dangle[c]) / (2.0 * h);
                let exact = k.d2_dx_dangle[c][j];
                assert!(
                    (mixed - exact).abs() <= tolerance(exact),
                    "d2/dx dtheta {c} {j}: {mixed} vs {exact}"
                );
            }
        }
        let turned = |angle: f64| eval(surface, &RotatingFrame { angle, ..*frame }, x);
        let (plus, minus) = (turned(frame.angle + h)?, turned(frame.angle - h)?);
        for c in 0..3 {
            let mixed = (plus.d_dx[c] - minus.d_dx[c]) / (2.0 * h);
            for i in 0..3 {
                let exact = k.d2_dx_dangle[c][i];
                assert!(
                    (mixed[i] - exact).abs() <= tolerance(exact),
                    "d2/dtheta dx {c} {i}: {} vs {exact}",
                    mixed[i]
                );
            }
            let second = (plus.d_dangle[c] - minus.d_dangle[c]) / (2.0 * h);
            let exact = k.d2_dangle2[c];
            assert!(
                (second - exact).abs() <= tolerance(exact),
                "d2/dtheta2 {c}: {second} vs {exact}"
            );
        }
        Ok(())
    }

    #[test]
    fn derivatives_match_finite_differences_3d() -> Result<(), ContactError> {
        let axis = Vector3::new(0.2, -0.4, 0.9).normalize();
        let drum = AnalyticCylinder::new(0.2, axis)?;
        let points = [
            Vector3::new(0.3, 0.1, 0.5),
            Vector3::new(-0.21, 0.05, -0.1),
            Vector3::new(0.0, -0.19, 0.3),
            Vector3::new(1.1, 0.7, 0.4),
        ];
        for angle in [0.0, 0.7, -2.5, 3.1, 11.0] {
            let frame = RotatingFrame {
                center: Vector3::new(0.9, 0.5, 0.3),
                axis,
                angle,
            };
            for x in &points {
                check_derivatives(&drum, &frame, x)?;
            }
        }
        Ok(())
    }

    /// The rotation column with the end-point `df/dx` gives the increment's change of gap and
    /// slip exactly (to round-off), on one facet and across a facet's edge, where the
    /// end-point `df/dtheta` misses a term of second order in the turn; on one facet it tends
    /// to `df/dtheta` as the turn vanishes.
    #[test]
    fn rotation_column_makes_the_rows_a_discrete_gradient() -> Result<(), ContactError> {
        let drum = crate::facets::FacetedCylinder::new(0.2, Vector3::z(), 72, 0.0)?;
        let axis = Vector3::z();
        let (c0, c1) = (
            Vector3::new(0.01, 0.0, 0.0),
            Vector3::new(0.012, -0.001, 0.0),
        );
        let theta0 = 0.3;
        let at = |angle: f64, body: f64, radius: f64| {
            Rotation3::from_axis_angle(&Vector3::z_axis(), angle)
                * Vector3::new(body.cos(), body.sin(), 0.0)
                * radius
        };
        let none = || ContactError::InvalidSurface("no rotation column".into());
        // (turn, end body angle, deg): within the facet of 0-5 degrees, then past its edge
        for (turn_deg, end_deg) in [(0.4, 2.7), (3.0, 6.5)] {
            let theta1 = theta0 + f64::to_radians(turn_deg);
            let r0 = at(theta0, 2.0_f64.to_radians(), 0.1995);
            let r1 = at(theta1, f64::to_radians(end_deg), 0.1993);
            let start = RotatingFrame {
                center: c0,
                axis,
                angle: theta0,
            };
            let end = RotatingFrame {
                center: c1,
                axis,
                angle: theta1,
            };
            let k0 = eval(&drum, &start, &(c0 + r0))?;
            let k1 = eval_from(&drum, &end, &(c1 + r1), &k0.closest)?;
            let change = difference(&drum, &k1, &k0);
            let begin = IncrementStart {
                angle: theta0,
                offset: r0,
            };
            let column = rotation_column(&drum, &end, &begin, &r1, &k1).ok_or_else(none)?;
            let turn = theta1 - theta0;
            for c in 0..2 {
                let predicted = k1.d_dx[c].dot(&(r1 - r0)) + column[c] * turn;
                assert_relative_eq!(predicted, change[c], epsilon = 1e-14);
                let tangent = k1.d_dx[c].dot(&(r1 - r0)) + k1.d_dangle[c] * turn;
                assert!(
                    (tangent - change[c]).abs() > 1e-8,
                    "{c}: the end-point row is exact"
                );
            }
        }
        let r0 = at(theta0, 2.0_f64.to_radians(), 0.1995);
        let begin = IncrementStart {
            angle: theta0,
            offset: r0,
        };
        let start = RotatingFrame {
            center: c0,
            axis,
            angle: theta0,
        };
        let k0 = eval(&drum, &start, &(c0 + r0))?;
        let close = RotatingFrame {
            angle: theta0 + 1e-6,
            ..start
        };
        let still = eval_from(&drum, &close, &(c0 + r0), &k0.closest)?;
        let limit = rotation_column(&drum, &close, &begin, &r0, &still).ok_or_else(none)?;
        for (secant, derivative) in limit.iter().zip(k0.d_dangle).take(2) {
            assert_relative_eq!(*secant, derivative, epsilon = 1e-6);
        }
        let stopped = RotatingFrame {
            angle: theta0 + 0.1 * MIN_SECANT_TURN,
            ..start
        };
        assert!(rotation_column(&drum, &stopped, &begin, &r0, &still).is_none());
        Ok(())
    }

    /// A turn that is tiny against the node's motion over a vertex would divide the remainder of
    /// the translation by it: the column falls back to the secant in the rotation, of the size
    /// of the lever arm.
    #[test]
    fn rotation_column_stays_of_the_lever_arm_size() -> Result<(), ContactError> {
        let drum = crate::facets::FacetedCylinder::new(0.2, Vector3::z(), 72, 0.0)?;
        let frame = RotatingFrame {
            center: Vector3::zeros(),
            axis: Vector3::z(),
            angle: 1e-6,
        };
        let at = |body: f64| Vector3::new(body.cos(), body.sin(), 0.0) * 0.1995;
        // from one facet over the vertex at 5 degrees onto the next one
        let (r0, r1) = (at(4.0_f64.to_radians()), at(6.0_f64.to_radians()));
        let begin = IncrementStart {
            angle: 0.0,
            offset: r0,
        };
        let unturned = RotatingFrame {
            angle: 0.0,
            ..frame
        };
        let end = eval_from(&drum, &frame, &r1, &eval(&drum, &unturned, &r0)?.closest)?;
        let column = rotation_column(&drum, &frame, &begin, &r1, &end)
            .ok_or_else(|| ContactError::InvalidSurface("no rotation column".into()))?;
        for c in column {
            assert!(c.abs() <= MAX_COLUMN_LEVER * r0.norm(), "{c}");
        }
        assert_relative_eq!(column[1], end.d_dangle[1], epsilon = 1e-4);
        Ok(())
    }

    /// On a faceted drum the body-frame curvature vanishes on a facet but the rotation still
    /// turns the facet under the node; in a vertex wedge the gap is curved.
    #[test]
    fn faceted_drum_derivatives_match_finite_differences() -> Result<(), ContactError> {
        let drum = crate::facets::FacetedCylinder::new(0.2, Vector3::z(), 72, 0.0)?;
        let frame = RotatingFrame {
            center: Vector3::new(0.05, -0.1, 0.0),
            axis: Vector3::z(),
            angle: 0.4,
        };
        // in front of a facet (body angle 2.5 degrees, mid-facet) and off a vertex (0 degrees)
        for body_angle in [2.5_f64.to_radians(), 0.0] {
            let offset = Vector3::new(body_angle.cos(), body_angle.sin(), 0.0) * 0.203;
            let rotation = Rotation3::from_axis_angle(&Vector3::z_axis(), frame.angle);
            check_derivatives(&drum, &frame, &(frame.center + rotation * offset))?;
        }
        Ok(())
    }

    #[test]
    fn derivatives_across_branch_cut() -> Result<(), ContactError> {
        let drum = AnalyticCylinder::new(0.2, Vector3::z())?;
        let frame = RotatingFrame {
            center: Vector3::zeros(),
            axis: Vector3::z(),
            angle: 0.0,
        };
        // body-frame angle pi: atan2 jumps from +pi to -pi within the finite-difference stencil
        let x = Vector3::new(-0.2005, 1e-8, 0.0);
        let k = eval(&drum, &frame, &x)?;
        assert!(k.closest.coords[0] > 0.0);
        let xm = Vector3::new(-0.2005, -1e-7, 0.0);
        assert!(eval(&drum, &frame, &xm)?.closest.coords[0] < 0.0);
        check_derivatives(&drum, &frame, &x)?;
        // a body rotated by pi/2 brings the cut to world angle 3 pi / 2 (below the centre)
        let rotated = RotatingFrame {
            angle: PI / 2.0,
            ..frame
        };
        check_derivatives(&drum, &rotated, &Vector3::new(1e-9, -0.21, 0.0))?;
        Ok(())
    }

    #[test]
    fn circle_rotation_derivatives_are_exact() -> Result<(), ContactError> {
        let radius = 0.2;
        let drum = AnalyticCylinder::new(radius, Vector3::z())?;
        for angle in [0.0, 1.0, -4.0] {
            let frame = RotatingFrame {
                center: Vector3::new(0.1, -0.3, 0.0),
                axis: Vector3::z(),
                angle,
            };
            let x = Vector3::new(0.17, -0.05, 0.0);
            let k = eval(&drum, &frame, &x)?;
            assert_relative_eq!(k.d_dangle[0], 0.0, epsilon = 1e-15);
            assert_relative_eq!(k.d_dangle[1], -radius, epsilon = 1e-14);
            assert_relative_eq!(k.d_dangle[2], 0.0, epsilon = 1e-15);
            // 2D point in the z = 0 plane with a z axis has axial coordinate 0
            assert_eq!(k.closest.coords[1], 0.0);
            // the world normal is radial from the centre, independent of the angle
            let radial = (x - frame.center).normalize();
            assert_relative_eq!(k.normal, radial, epsilon = 1e-14);
            assert_relative_eq!(k.gap, (x - frame.center).norm() - radius, epsilon = 1e-15);
        }
        Ok(())
    }

    #[test]
    fn rotating_the_body_moves_material_points_under_a_fixed_node() -> Result<(), ContactError> {
        let radius = 0.2;
        let drum = AnalyticCylinder::new(radius, Vector3::z())?;
        let x = Vector3::new(0.0, 0.2, 0.0);
        let at = |angle: f64| -> Result<ContactKinematics, ContactError> {
            let frame = RotatingFrame {
                center: Vector3::zeros(),
                axis: Vector3::z(),
                angle,
            };
            eval(&drum, &frame, &x)
        };
        // a full turn in 0.1 rad steps: the unwrapped slip sums to -2 pi R
        let mut total = 0.0;
        let mut previous = at(0.0)?.closest.coords;
        for step in 1..=63 {
            let current = at(step as f64 * 0.1)?.closest.coords;
            total += unwrapped_increment(drum.coords_period(), current - previous)[0];
            previous = current;
        }
        assert_relative_eq!(total, -6.3 * radius, epsilon = 1e-12);
        Ok(())
    }

    #[test]
    fn unwrapping_across_branch_cut() -> Result<(), ContactError> {
        let drum = AnalyticCylinder::new(0.2, Vector3::z())?;
        let period = 0.4 * PI;
        let before = Vector2::new(0.2 * (PI - 0.01), 0.3);
        let after = Vector2::new(0.2 * (-PI + 0.02), 0.1);
        let slip = unwrapped_increment(drum.coords_period(), after - before);
        assert_relative_eq!(slip[0], 0.2 * 0.03, epsilon = 1e-14);
        assert_relative_eq!(slip[1], -0.2, epsilon = 1e-15);
        let back = unwrapped_increment(drum.coords_period(), before - after);
        assert_relative_eq!(back[0], -0.2 * 0.03, epsilon = 1e-14);
        // exactly half a period maps to +p/2 (the interval is (-p/2, p/2])
        let half = unwrapped_increment(drum.coords_period(), Vector2::new(-0.5 * period, 0.0));
        assert_relative_eq!(half[0], 0.5 * period, epsilon = 1e-15);
        Ok(())
    }

    #[test]
    fn degenerate_frame_or_axis_point_gives_none() -> Result<(), ContactError> {
        let drum = AnalyticCylinder::new(0.2, Vector3::z())?;
        let frame = RotatingFrame {
            center: Vector3::new(1.0, 2.0, 0.0),
            axis: Vector3::z(),
            angle: 0.3,
        };
        assert!(eval(&drum, &frame, &Vector3::new(1.0, 2.0, 0.5)).is_err());
        let no_axis = RotatingFrame {
            axis: Vector3::zeros(),
            ..frame
        };
        assert!(eval(&drum, &no_axis, &Vector3::new(0.0, 0.0, 0.0)).is_err());
        let nan_angle = RotatingFrame {
            angle: f64::NAN,
            ..frame
        };
        assert!(eval(&drum, &nan_angle, &Vector3::new(0.0, 0.0, 0.0)).is_err());
        Ok(())
    }
}
