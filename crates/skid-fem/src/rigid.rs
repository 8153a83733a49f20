//! Rigid bodies: a reference node carrying a point mass and a rotary inertia.
//!
//! A rigid body in skid moves with the degrees of freedom a scene leaves it: translations of its
//! reference node along chosen global axes, and either no rotation, a rotation about ONE fixed
//! axis through the reference node, or (in 3D) rotations about all three axes. The drum of the
//! braking benchmark is a body with only its spin free; the back plate is a body with only its
//! radial translation free.
//!
//! About a single fixed axis the rotation is additive (`Q(theta) = exp(theta [e]x)`), so its
//! equation of motion is the scalar `I theta'' = M_e`. A body free to turn rotates about its
//! principal axes of inertia by material increments, `Q <- Q exp([delta]x)`; its equations are
//! Euler's, `J W' + W x J W = M` in those axes (see the integrator's dynamics).
//!
//! Nodes tied to a body follow its translations only (see the integrator's DOF map), which is
//! exact for bodies without a free rotation such as the back plate.

use nalgebra::{Rotation3, SVector, Vector3};

/// How a rigid body may rotate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Rotation {
    /// It cannot rotate.
    None,
    /// About one fixed unit axis through the reference node (world frame; `+z` in 2D), with
    /// the body's `rotary_inertia` about it.
    Axis(Vector3<f64>),
    /// About all three axes (3D only). The body's axes are its principal axes of inertia:
    /// `principal_axes` `P` holds their global directions at the start as columns, so that the
    /// inertia tensor about the reference node is `P diag(J) P^T` then; the body's surfaces
    /// are given in the global orientation at the start, as every body's are.
    Free {
        /// Principal moments of inertia `(J_1, J_2, J_3)` about the principal axes, kg m^2.
        principal_inertia: Vector3<f64>,
        /// `P`: the principal axes at the start (columns, global frame).
        principal_axes: Rotation3<f64>,
        /// Initial angular velocity (global frame), rad/s.
        initial_angular_velocity: Vector3<f64>,
    },
}

impl Rotation {
    /// Number of rotation unknowns: 0, 1 or 3.
    pub fn unknowns(&self) -> usize {
        match self {
            Self::None => 0,
            Self::Axis(_) => 1,
            Self::Free { .. } => 3,
        }
    }
}

use crate::error::FemError;

/// A rigid body with its inertia lumped at the reference node.
#[derive(Clone, Debug)]
pub struct RigidBody<const D: usize> {
    /// Name used in case files and messages.
    pub name: String,
    /// Reference node (centre of mass and point on the rotation axis), m.
    pub reference_point: SVector<f64, D>,
    /// Point mass at the reference node, kg (used by free translations).
    pub mass: f64,
    /// Rotary inertia about the rotation axis of [`Rotation::Axis`], kg m^2.
    pub rotary_inertia: f64,
    /// Global axes along which the reference node may translate.
    pub free_translations: [bool; D],
    /// How the body may rotate.
    pub rotation: Rotation,
    /// Initial velocity of the reference node, m/s.
    pub initial_velocity: SVector<f64, D>,
    /// Initial angular velocity about the axis of [`Rotation::Axis`], rad/s.
    pub initial_angular_velocity: f64,
}

impl<const D: usize> RigidBody<D> {
    /// Checks that the inertia is physical for the free motions and the axis is admissible.
    ///
    /// # Errors
    /// [`FemError::InvalidRigidBody`] naming the body and the offending quantity.
    pub fn validate(&self) -> Result<(), FemError> {
        let fail = |what: String| {
            Err(FemError::InvalidRigidBody {
                body: self.name.clone(),
                reason: what,
            })
        };
        if !(self.mass.is_finite() && self.mass >= 0.0) {
            return fail(format!("mass must be finite and >= 0, got {}", self.mass));
        }
        if !(self.rotary_inertia.is_finite() && self.rotary_inertia >= 0.0) {
            return fail(format!(
                "rotary inertia must be finite and >= 0, got {}",
                self.rotary_inertia
            ));
        }
        if !self.reference_point.iter().all(|v| v.is_finite())
            || !self.initial_velocity.iter().all(|v| v.is_finite())
            || !self.initial_angular_velocity.is_finite()
        {
            return fail("reference point and initial velocities must be finite".into());
        }
        if !matches!(self.rotation, Rotation::Axis(_)) && self.initial_angular_velocity != 0.0 {
            return fail("an initial angular velocity about an axis needs that axis free".into());
        }
        match self.rotation {
            Rotation::None => {}
            Rotation::Axis(axis) => {
                let norm = axis.norm();
                if (norm - 1.0).abs() >= 1e-9 || !norm.is_finite() {
                    return fail(format!("rotation axis must be a unit vector, |e| = {norm}"));
                }
                if D == 2 && (axis.z - 1.0).abs() > 1e-12 {
                    return fail("in 2D the rotation axis must be +z".into());
                }
            }
            Rotation::Free {
                principal_inertia,
                principal_axes,
                initial_angular_velocity,
            } => {
                if D == 2 {
                    return fail("in 2D a body turns about +z only".into());
                }
                if !principal_inertia.iter().all(|j| j.is_finite() && *j >= 0.0) {
                    return fail(format!(
                        "principal moments of inertia must be finite and >= 0, got {:?}",
                        principal_inertia.as_slice()
                    ));
                }
                let sum = principal_inertia.sum();
                if principal_inertia
                    .iter()
                    .any(|j| *j > 0.5 * sum * (1.0 + 1e-12))
                {
                    return fail(format!(
                        "principal moments of inertia {:?}: none may exceed the sum of the \
                         other two (no mass distribution has them)",
                        principal_inertia.as_slice()
                    ));
                }
                let p = principal_axes.matrix();
                if !p.iter().all(|v| v.is_finite())
                    || (p.transpose() * p - nalgebra::Matrix3::identity()).amax() > 1e-9
                    || p.determinant() <= 0.0
                {
                    return fail(format!("principal axes must be a rotation, got {p}"));
                }
                if !initial_angular_velocity.iter().all(|w| w.is_finite()) {
                    return fail("initial angular velocity must be finite".into());
                }
            }
        }
        for (i, free) in self.free_translations.iter().enumerate() {
            if !free && self.initial_velocity[i] != 0.0 {
                return fail(format!("initial velocity along fixed axis {i} must be 0"));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn drum() -> RigidBody<2> {
        RigidBody {
            name: "drum".into(),
            reference_point: SVector::<f64, 2>::zeros(),
            mass: 5.0,
            rotary_inertia: 0.175,
            free_translations: [false, false],
            rotation: Rotation::Axis(Vector3::z()),
            initial_velocity: SVector::<f64, 2>::zeros(),
            initial_angular_velocity: 60.0,
        }
    }

    #[test]
    fn valid_drum_passes() {
        drum().validate().expect("valid");
    }

    #[test]
    fn non_physical_inertia_and_axes_are_rejected() {
        let mut d = drum();
        d.rotary_inertia = -1.0;
        assert!(d.validate().is_err());
        let mut d = drum();
        d.rotation = Rotation::Axis(Vector3::x());
        assert!(d.validate().is_err(), "2D axis must be z");
        let mut d = drum();
        d.rotation = Rotation::None;
        assert!(d.validate().is_err(), "spin without an axis");
        let mut d = drum();
        d.initial_angular_velocity = 0.0;
        d.rotation = Rotation::Free {
            principal_inertia: Vector3::repeat(0.1),
            principal_axes: Rotation3::identity(),
            initial_angular_velocity: Vector3::zeros(),
        };
        assert!(d.validate().is_err(), "free rotation in 2D");
    }

    #[test]
    fn a_free_body_needs_a_physical_inertia() {
        let top = |principal_inertia: Vector3<f64>| RigidBody::<3> {
            name: "top".into(),
            reference_point: SVector::<f64, 3>::zeros(),
            mass: 1.0,
            rotary_inertia: 0.0,
            free_translations: [true; 3],
            rotation: Rotation::Free {
                principal_inertia,
                principal_axes: Rotation3::identity(),
                initial_angular_velocity: Vector3::new(0.0, 1.0, 30.0),
            },
            initial_velocity: SVector::<f64, 3>::zeros(),
            initial_angular_velocity: 0.0,
        };
        top(Vector3::new(0.3, 0.3, 0.5))
            .validate()
            .expect("a flat disc");
        assert!(
            top(Vector3::new(0.3, 0.3, 0.7)).validate().is_err(),
            "J3 > J1 + J2"
        );
        assert!(
            top(Vector3::new(-0.3, 0.3, 0.5)).validate().is_err(),
            "negative"
        );
        assert_eq!(top(Vector3::new(0.3, 0.3, 0.5)).rotation.unknowns(), 3);
        let mut d = drum();
        d.initial_velocity[0] = 1.0;
        assert!(d.validate().is_err(), "velocity along a fixed axis");
    }
}
