//! Gap and slip kinematics of a slave node against a surface carried by a rigid body, turning
//! about a fixed axis or freely.
//!
//! With body reference point `c` and orientation `Q`, the body frame is `y = Q^T (x - c)`. The
//! body's rotation unknowns are material increments `delta_i` about unit body-frame axes `a_i`,
//! `Q <- Q exp(sum_i delta_i [a_i]x)`: one about the axis `e` of a body turning about a fixed
//! axis (there `Q^T e = e` and `delta` is the increment of its angle), or three about the body's
//! own axes for a body free to turn. Then `dy = Q^T dx - sum_i w_i delta_i` with `w_i = a_i x y`,
//! and to second order `y` gains `1/2 sum_ij delta_i delta_j a_i x w_j`. For any surface
//! function `f(y)` with gradient `G = df/dy` and Hessian `F = d^2f/dy^2` this gives
//! - `df/dx = Q G` and `df/ddelta_i = -G . w_i`;
//! - `d^2f/dx^2 = Q F Q^T` and `d^2f/dx ddelta_i = Q (a_i x G - F w_i)`;
//! - `d^2f/ddelta_i ddelta_j = w_i . F w_j + 1/2 G . (a_i x w_j + a_j x w_i)`.
//!
//! The second derivatives give the stiffness of the contact forces `r` on a curved or rotating
//! surface, `sum_k r_k d^2 u_k` (see `skid_integrator::coupling`).

use nalgebra::{Matrix3, Rotation3, Unit, UnitQuaternion, Vector2, Vector3};

use crate::surface::{DiscreteGradient, Projection, RigidSurface, SurfacePoint};

/// How a rigid body may turn: which rotation unknowns its kinematics are differentiated in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Turning {
    /// About one fixed unit axis `e` (world frame, which is also its body frame direction):
    /// one unknown, the angle.
    About(Unit<Vector3<f64>>),
    /// Freely: three unknowns, the material increments about the body's own axes, whose
    /// directions in the body frame are the columns of `P` (the identity for a body whose own
    /// axes are its frame's).
    Free(Rotation3<f64>),
}

/// Placement of a rigid body: reference point, orientation and rotation unknowns.
#[derive(Clone, Copy, Debug)]
pub struct RotatingFrame {
    /// Reference point `c` of the body (world frame): on the rotation axis, or the centre of mass
    /// of a body free to turn.
    pub center: Vector3<f64>,
    /// Orientation `Q`: a body-frame point `y` is at `c + Q y`.
    pub orientation: Rotation3<f64>,
    /// The rotation unknowns.
    pub turning: Turning,
}

impl RotatingFrame {
    /// The frame of a body turned by `angle` (rad, counter-clockwise) about the fixed `axis`
    /// through `center`, from the world orientation; a zero or non-finite axis or a non-finite
    /// angle gives a frame that [`Self::is_finite`] rejects.
    pub fn about(center: Vector3<f64>, axis: Vector3<f64>, angle: f64) -> Self {
        let axis = Unit::new_unchecked(axis / axis.norm());
        Self {
            center,
            orientation: Rotation3::from_axis_angle(&axis, angle),
            turning: Turning::About(axis),
        }
    }

    /// The frame of a body free to turn with its reference point at `center`, whose own axes
    /// are at `orientation` `R` and were at `axes` `P` when the body frame was the world's: the
    /// frame's orientation is `Q = R P^T`, and the unknowns turn about `P`'s columns.
    pub fn free(
        center: Vector3<f64>,
        orientation: &UnitQuaternion<f64>,
        axes: &Rotation3<f64>,
    ) -> Self {
        Self {
            center,
            orientation: orientation.to_rotation_matrix() * axes.inverse(),
            turning: Turning::Free(*axes),
        }
    }

    /// Number of rotation unknowns (1 or 3).
    pub fn rotations(&self) -> usize {
        match self.turning {
            Turning::About(_) => 1,
            Turning::Free(_) => 3,
        }
    }

    /// Body-frame unit axis `a_i` of rotation unknown `i`.
    pub fn rotation_axis(&self, i: usize) -> Vector3<f64> {
        match self.turning {
            Turning::About(axis) => axis.into_inner(),
            Turning::Free(axes) => axes.matrix().column(i).into_owned(),
        }
    }

    /// True if the centre, the orientation and the axis are finite (a frame made from a zero
    /// axis or a non-finite angle is not).
    pub fn is_finite(&self) -> bool {
        let axis_finite = match self.turning {
            Turning::About(axis) => axis.iter().all(|c| c.is_finite()),
            Turning::Free(axes) => axes.matrix().iter().all(|c| c.is_finite()),
        };
        axis_finite
            && self.center.iter().all(|c| c.is_finite())
            && self.orientation.matrix().iter().all(|c| c.is_finite())
    }

    /// The world position `x = c + Q y` of the body-frame point `y`; `None` if the frame is not
    /// finite.
    pub fn to_world(&self, y: &Vector3<f64>) -> Option<Vector3<f64>> {
        self.is_finite().then(|| self.center + self.orientation * y)
    }

    /// The body-frame point `y = Q^T (x - c)` at the world position `x`; `None` if the frame is
    /// not finite.
    pub fn to_body(&self, x: &Vector3<f64>) -> Option<Vector3<f64>> {
        self.is_finite().then(|| {
            self.orientation
                .inverse_transform_vector(&(x - self.center))
        })
    }
}

/// Gap, slip and their exact first and second derivatives for one slave node, with its closest
/// point. Rotation derivatives are per rotation unknown of the frame ([`RotatingFrame::rotations`]
/// of them; the others are zero).
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
    /// Derivatives of `[g, s_0, s_1]` with respect to the rotation unknowns, entry `i` for
    /// `delta_i`: `-G . w_i`.
    pub d_drotation: [Vector3<f64>; 3],
    /// Second derivatives of `[g, s_0, s_1]` with respect to `x`: `Q F Q^T`.
    pub d2_dx2: [Matrix3<f64>; 3],
    /// Mixed second derivatives, column `i` with respect to `x` and `delta_i`:
    /// `Q (a_i x G - F w_i)`.
    pub d2_dx_drotation: [Matrix3<f64>; 3],
    /// Second derivatives with respect to the rotation unknowns (symmetric):
    /// `w_i . F w_j + 1/2 G . (a_i x w_j + a_j x w_i)`.
    pub d2_drotation2: [Matrix3<f64>; 3],
}

/// Evaluate gap, slip since the contact point `from` (see [`RigidSurface::slip`]; `None`: since
/// the node's own closest point, a zero slip with its derivatives) and their exact first and
/// second derivatives for a node at world position `x` (2D problems pass `z = 0` and a `z`
/// axis).
///
/// Returns `None` if the frame is not finite or the surface projection is undefined at
/// `y = Q^T (x - c)`.
pub fn evaluate(
    surface: &dyn RigidSurface,
    frame: &RotatingFrame,
    x: &Vector3<f64>,
    from: Option<&SurfacePoint>,
) -> Option<ContactKinematics> {
    let y = frame.to_body(x)?;
    let rotation = &frame.orientation;
    let projection = surface.project(&y)?;
    let closest = projection.closest(&y);
    let slip = surface.slip(from.unwrap_or(&closest), &y, &projection);
    let rotations = frame.rotations();
    let axes: [Vector3<f64>; 3] = std::array::from_fn(|i| frame.rotation_axis(i));
    let w: [Vector3<f64>; 3] = std::array::from_fn(|i| axes[i].cross(&y));
    let gradients = [projection.gap_gradient, slip.gradient[0], slip.gradient[1]];
    let hessians = [projection.gap_hessian, slip.hessian[0], slip.hessian[1]];
    let world = rotation.matrix();
    let mut d_drotation = [Vector3::zeros(); 3];
    let mut d2_dx_drotation = [Matrix3::zeros(); 3];
    let mut d2_drotation2 = [Matrix3::zeros(); 3];
    for (k, (g, f)) in gradients.iter().zip(&hessians).enumerate() {
        let f_w: [Vector3<f64>; 3] = std::array::from_fn(|i| f * w[i]);
        for i in 0..rotations {
            d_drotation[k][i] = -g.dot(&w[i]);
            d2_dx_drotation[k].set_column(i, &(world * (axes[i].cross(g) - f_w[i])));
            for j in 0..=i {
                let value =
                    w[i].dot(&f_w[j]) + 0.5 * g.dot(&(axes[i].cross(&w[j]) + axes[j].cross(&w[i])));
                d2_drotation2[k][(i, j)] = value;
                d2_drotation2[k][(j, i)] = value;
            }
        }
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
        d_drotation,
        d2_dx2: hessians.map(|f| world * f * world.transpose()),
        d2_dx_drotation,
        d2_drotation2,
    })
}

/// World-frame discrete gradient of the gap over an increment (see
/// [`RigidSurface::gap_discrete_gradient`]) for a node now at world position `x` that started
/// the increment at `start_offset = x_start - c_start` from the body reference point: the start
/// point is taken into the current body frame, which the surface's invariance under the body's
/// rotation about its fixed axis allows. Then `G . ((x - c) - start_offset)` is exactly the
/// change of the gap over the increment.
///
/// Its Jacobian (in `x`, rotated to the world frame alike) is independent of the body's angle
/// for the same reason.
///
/// `None` if the frame is not finite, the body is free to turn (no axis of invariance), or the
/// surface offers no discrete gradient.
pub fn gap_discrete_gradient(
    surface: &dyn RigidSurface,
    frame: &RotatingFrame,
    start_offset: &Vector3<f64>,
    x: &Vector3<f64>,
) -> Option<DiscreteGradient> {
    let Turning::About(axis) = frame.turning else {
        return None;
    };
    let y_end = frame.to_body(x)?;
    let rotation = &frame.orientation;
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

/// The start of an increment for [`rotation_column`]: the body's orientation `Q_0`, its turn
/// over the increment `theta_1 - theta_0` about its fixed axis, and the node's offset
/// `r_0 = x_0 - c_0` from the body's reference point.
#[derive(Clone, Copy, Debug)]
pub struct IncrementStart {
    /// `Q_0`.
    pub orientation: Rotation3<f64>,
    /// `theta_1 - theta_0`, rad.
    pub turn: f64,
    /// `r_0` (world frame).
    pub offset: Vector3<f64>,
}

impl IncrementStart {
    /// The node's start position in the body frame of the start, `y_0 = Q_0^T r_0`: the
    /// projection [`rotation_column`] takes is this point's, the same in every Newton iteration
    /// of the increment.
    pub fn body_point(&self) -> Vector3<f64> {
        self.orientation.inverse_transform_vector(&self.offset)
    }
}

/// Rotation column of a node's rows `f = [g, s_0, s_1]` over an increment that makes them a
/// discrete gradient, for a body turning about a fixed axis. With the end-point `df/dx`
/// (`end.d_dx`, the kinematics evaluated from the contact point at the start `y_0`, so that
/// `end.slip` is the slip over the increment) in the node and translation columns, the body now
/// at `frame` and the node at offset `r_1 = x_1 - c_1`:
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
/// `before` is the projection of the start point [`IncrementStart::body_point`] on `surface`.
///
/// `None` if the turn is below [`MIN_SECANT_TURN`] or not finite, the body is free to turn (its
/// end-point derivatives stand), the frame is not finite, or a projection is undefined: then the
/// end-point derivative stands.
pub fn rotation_column(
    surface: &dyn RigidSurface,
    frame: &RotatingFrame,
    start: &IncrementStart,
    before: &Projection,
    end_offset: &Vector3<f64>,
    end: &ContactKinematics,
) -> Option<[f64; 3]> {
    let turn = start.turn;
    if !(turn.abs() >= MIN_SECANT_TURN && turn.is_finite())
        || matches!(frame.turning, Turning::Free(_))
        || !frame.is_finite()
    {
        return None;
    }
    let moved = end_offset - start.offset;
    let whole = [end.gap - before.gap, end.slip[0], end.slip[1]];
    let column: [f64; 3] = std::array::from_fn(|k| (whole[k] - end.d_dx[k].dot(&moved)) / turn);
    let bound = MAX_COLUMN_LEVER * start.offset.norm();
    if column.iter().all(|c| c.abs() <= bound) {
        return Some(column);
    }
    let y_turned = frame.orientation.inverse_transform_vector(&start.offset);
    let turned = surface.project(&y_turned)?;
    let slip = surface
        .slip(&before.closest(&start.body_point()), &y_turned, &turned)
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

    /// The frame after the material increment `by` of rotation unknown `i`:
    /// `Q exp(by [a_i]x)`.
    fn turned(frame: &RotatingFrame, i: usize, by: f64) -> RotatingFrame {
        let axis = Unit::new_normalize(frame.rotation_axis(i));
        RotatingFrame {
            orientation: frame.orientation * Rotation3::from_axis_angle(&axis, by),
            ..*frame
        }
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
        for i in 0..frame.rotations() {
            let d = difference(
                surface,
                &eval(surface, &turned(frame, i, h), x)?,
                &eval(surface, &turned(frame, i, -h), x)?,
            );
            for (difference, derivative) in d.iter().zip(&k.d_drotation) {
                assert_relative_eq!(difference / (2.0 * h), derivative[i], epsilon = 1e-7);
            }
        }
        check_second_derivatives(surface, frame, x)
    }

    /// Central differences of the first derivatives against the second ones. Turning by
    /// `delta_j` first and then differentiating in `delta_i` gives `d^2f/ddelta_i ddelta_j`
    /// plus half the first derivative about `a_j x a_i` (the increments do not commute):
    /// `G . (a_i x w_j) - 1/2 G . (a_i x w_j + a_j x w_i) = 1/2 G . ((a_i x a_j) x y)`.
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
                for i in 0..frame.rotations() {
                    let mixed = (plus.d_drotation[c][i] - minus.d_drotation[c][i]) / (2.0 * h);
                    let exact = k.d2_dx_drotation[c][(j, i)];
                    assert!(
                        (mixed - exact).abs() <= tolerance(exact),
                        "d2/dx ddelta {c} x{j} delta{i}: {mixed} vs {exact}"
                    );
                }
            }
        }
        let y = frame
            .orientation
            .inverse_transform_vector(&(x - frame.center));
        for j in 0..frame.rotations() {
            let (plus, minus) = (
                eval(surface, &turned(frame, j, h), x)?,
                eval(surface, &turned(frame, j, -h), x)?,
            );
            for c in 0..3 {
                let mixed = (plus.d_dx[c] - minus.d_dx[c]) / (2.0 * h);
                for i in 0..3 {
                    let exact = k.d2_dx_drotation[c][(i, j)];
                    assert!(
                        (mixed[i] - exact).abs() <= tolerance(exact),
                        "d2/ddelta dx {c} delta{j} x{i}: {} vs {exact}",
                        mixed[i]
                    );
                }
                let gradient = frame.orientation.inverse_transform_vector(&k.d_dx[c]);
                for i in 0..frame.rotations() {
                    let second = (plus.d_drotation[c][i] - minus.d_drotation[c][i]) / (2.0 * h);
                    let across = frame.rotation_axis(i).cross(&frame.rotation_axis(j));
                    let exact = k.d2_drotation2[c][(i, j)] + 0.5 * gradient.dot(&across.cross(&y));
                    assert!(
                        (second - exact).abs() <= tolerance(exact),
                        "d2/ddelta2 {c} ({i},{j}): {second} vs {exact}"
                    );
                }
            }
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
            let frame = RotatingFrame::about(Vector3::new(0.9, 0.5, 0.3), axis, angle);
            for x in &points {
                check_derivatives(&drum, &frame, x)?;
            }
        }
        Ok(())
    }

    /// A body free to turn: the three material increments' first and second derivatives
    /// against differences, on a tilted cylinder and on the faceted drum, at several
    /// orientations.
    #[test]
    fn free_body_derivatives_match_finite_differences() -> Result<(), ContactError> {
        let axis = Vector3::new(0.2, -0.4, 0.9).normalize();
        let cylinder = AnalyticCylinder::new(0.2, axis)?;
        let facets = crate::facets::FacetedCylinder::new(0.2, axis, 72, 0.0)?;
        let points = [
            Vector3::new(0.3, 0.1, 0.5),
            Vector3::new(-0.21, 0.05, -0.1),
            Vector3::new(1.1, 0.7, 0.4),
        ];
        let center = Vector3::new(0.9, 0.5, 0.3);
        // the body's own axes along the frame's, and tilted
        for axes in [
            Rotation3::identity(),
            Rotation3::from_scaled_axis(Vector3::new(0.4, 0.2, -0.7)),
        ] {
            for turn in [
                Vector3::zeros(),
                Vector3::new(0.3, -1.2, 0.4),
                Vector3::new(-2.0, 0.1, 1.5),
            ] {
                let own = UnitQuaternion::from_scaled_axis(turn);
                let frame = RotatingFrame::free(center, &own, &axes);
                assert_eq!(frame.rotations(), 3);
                for x in &points {
                    check_derivatives(&cylinder, &frame, x)?;
                    check_derivatives(&facets, &frame, &(center + (x - center) * 0.21 / 0.2))?;
                }
            }
        }
        // about a fixed axis the free body's derivative along that axis is the angle's
        let fixed = RotatingFrame::about(center, axis, 0.7);
        let free = RotatingFrame::free(
            center,
            &UnitQuaternion::from_axis_angle(&Unit::new_normalize(axis), 0.7),
            &Rotation3::identity(),
        );
        let (a, b) = (
            eval(&cylinder, &fixed, &points[0])?,
            eval(&cylinder, &free, &points[0])?,
        );
        for c in 0..3 {
            assert_relative_eq!(
                a.d_drotation[c][0],
                b.d_drotation[c].dot(&axis),
                epsilon = 1e-14
            );
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
            let start = RotatingFrame::about(c0, axis, theta0);
            let end = RotatingFrame::about(c1, axis, theta1);
            let k0 = eval(&drum, &start, &(c0 + r0))?;
            let k1 = eval_from(&drum, &end, &(c1 + r1), &k0.closest)?;
            let change = difference(&drum, &k1, &k0);
            let begin = IncrementStart {
                orientation: start.orientation,
                turn: theta1 - theta0,
                offset: r0,
            };
            let before = drum.project(&begin.body_point()).ok_or_else(none)?;
            let column =
                rotation_column(&drum, &end, &begin, &before, &r1, &k1).ok_or_else(none)?;
            let turn = theta1 - theta0;
            for c in 0..2 {
                let predicted = k1.d_dx[c].dot(&(r1 - r0)) + column[c] * turn;
                assert_relative_eq!(predicted, change[c], epsilon = 1e-14);
                let tangent = k1.d_dx[c].dot(&(r1 - r0)) + k1.d_drotation[c][0] * turn;
                assert!(
                    (tangent - change[c]).abs() > 1e-8,
                    "{c}: the end-point row is exact"
                );
            }
        }
        let r0 = at(theta0, 2.0_f64.to_radians(), 0.1995);
        let start = RotatingFrame::about(c0, axis, theta0);
        let begin = IncrementStart {
            orientation: start.orientation,
            turn: 1e-6,
            offset: r0,
        };
        let k0 = eval(&drum, &start, &(c0 + r0))?;
        let close = RotatingFrame::about(c0, axis, theta0 + 1e-6);
        let still = eval_from(&drum, &close, &(c0 + r0), &k0.closest)?;
        let before = drum.project(&begin.body_point()).ok_or_else(none)?;
        let limit =
            rotation_column(&drum, &close, &begin, &before, &r0, &still).ok_or_else(none)?;
        for (secant, derivative) in limit.iter().zip(k0.d_drotation).take(2) {
            assert_relative_eq!(*secant, derivative[0], epsilon = 1e-6);
        }
        let stopped = RotatingFrame::about(c0, axis, theta0 + 0.1 * MIN_SECANT_TURN);
        let barely = IncrementStart {
            turn: 0.1 * MIN_SECANT_TURN,
            ..begin
        };
        assert!(rotation_column(&drum, &stopped, &barely, &before, &r0, &still).is_none());
        // a body free to turn keeps its end-point derivatives
        let free = RotatingFrame::free(
            c0,
            &UnitQuaternion::from_axis_angle(&Vector3::z_axis(), theta0 + 1e-6),
            &Rotation3::identity(),
        );
        assert!(rotation_column(&drum, &free, &begin, &before, &r0, &still).is_none());
        Ok(())
    }

    /// A turn that is tiny against the node's motion over a vertex would divide the remainder of
    /// the translation by it: the column falls back to the secant in the rotation, of the size
    /// of the lever arm.
    #[test]
    fn rotation_column_stays_of_the_lever_arm_size() -> Result<(), ContactError> {
        let drum = crate::facets::FacetedCylinder::new(0.2, Vector3::z(), 72, 0.0)?;
        let frame = RotatingFrame::about(Vector3::zeros(), Vector3::z(), 1e-6);
        let at = |body: f64| Vector3::new(body.cos(), body.sin(), 0.0) * 0.1995;
        // from one facet over the vertex at 5 degrees onto the next one
        let (r0, r1) = (at(4.0_f64.to_radians()), at(6.0_f64.to_radians()));
        let unturned = RotatingFrame::about(Vector3::zeros(), Vector3::z(), 0.0);
        let begin = IncrementStart {
            orientation: unturned.orientation,
            turn: 1e-6,
            offset: r0,
        };
        let end = eval_from(&drum, &frame, &r1, &eval(&drum, &unturned, &r0)?.closest)?;
        let none = || ContactError::InvalidSurface("no rotation column".into());
        let before = drum.project(&begin.body_point()).ok_or_else(none)?;
        let column = rotation_column(&drum, &frame, &begin, &before, &r1, &end).ok_or_else(none)?;
        for c in column {
            assert!(c.abs() <= MAX_COLUMN_LEVER * r0.norm(), "{c}");
        }
        assert_relative_eq!(column[1], end.d_drotation[1][0], epsilon = 1e-4);
        Ok(())
    }

    /// On a faceted drum the body-frame curvature vanishes on a facet but the rotation still
    /// turns the facet under the node; in a vertex wedge the gap is curved.
    #[test]
    fn faceted_drum_derivatives_match_finite_differences() -> Result<(), ContactError> {
        let drum = crate::facets::FacetedCylinder::new(0.2, Vector3::z(), 72, 0.0)?;
        let frame = RotatingFrame::about(Vector3::new(0.05, -0.1, 0.0), Vector3::z(), 0.4);
        // in front of a facet (body angle 2.5 degrees, mid-facet) and off a vertex (0 degrees)
        for body_angle in [2.5_f64.to_radians(), 0.0] {
            let offset = Vector3::new(body_angle.cos(), body_angle.sin(), 0.0) * 0.203;
            check_derivatives(&drum, &frame, &(frame.center + frame.orientation * offset))?;
        }
        Ok(())
    }

    #[test]
    fn derivatives_across_branch_cut() -> Result<(), ContactError> {
        let drum = AnalyticCylinder::new(0.2, Vector3::z())?;
        let frame = RotatingFrame::about(Vector3::zeros(), Vector3::z(), 0.0);
        // body-frame angle pi: atan2 jumps from +pi to -pi within the finite-difference stencil
        let x = Vector3::new(-0.2005, 1e-8, 0.0);
        let k = eval(&drum, &frame, &x)?;
        assert!(k.closest.coords[0] > 0.0);
        let xm = Vector3::new(-0.2005, -1e-7, 0.0);
        assert!(eval(&drum, &frame, &xm)?.closest.coords[0] < 0.0);
        check_derivatives(&drum, &frame, &x)?;
        // a body rotated by pi/2 brings the cut to world angle 3 pi / 2 (below the centre)
        let rotated = RotatingFrame::about(Vector3::zeros(), Vector3::z(), PI / 2.0);
        check_derivatives(&drum, &rotated, &Vector3::new(1e-9, -0.21, 0.0))?;
        Ok(())
    }

    #[test]
    fn circle_rotation_derivatives_are_exact() -> Result<(), ContactError> {
        let radius = 0.2;
        let drum = AnalyticCylinder::new(radius, Vector3::z())?;
        for angle in [0.0, 1.0, -4.0] {
            let frame = RotatingFrame::about(Vector3::new(0.1, -0.3, 0.0), Vector3::z(), angle);
            let x = Vector3::new(0.17, -0.05, 0.0);
            let k = eval(&drum, &frame, &x)?;
            assert_relative_eq!(k.d_drotation[0][0], 0.0, epsilon = 1e-15);
            assert_relative_eq!(k.d_drotation[1][0], -radius, epsilon = 1e-14);
            assert_relative_eq!(k.d_drotation[2][0], 0.0, epsilon = 1e-15);
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
            let frame = RotatingFrame::about(Vector3::zeros(), Vector3::z(), angle);
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
        let center = Vector3::new(1.0, 2.0, 0.0);
        let frame = RotatingFrame::about(center, Vector3::z(), 0.3);
        assert!(eval(&drum, &frame, &Vector3::new(1.0, 2.0, 0.5)).is_err());
        let no_axis = RotatingFrame::about(center, Vector3::zeros(), 0.3);
        assert!(eval(&drum, &no_axis, &Vector3::new(0.0, 0.0, 0.0)).is_err());
        let nan_angle = RotatingFrame::about(center, Vector3::z(), f64::NAN);
        assert!(eval(&drum, &nan_angle, &Vector3::new(0.0, 0.0, 0.0)).is_err());
        Ok(())
    }
}
