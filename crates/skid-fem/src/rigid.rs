//! Rigid bodies: a reference node carrying a point mass and a rotary inertia.
//!
//! A rigid body in skid moves with at most the degrees of freedom a scene needs: translations of
//! its reference node along chosen global axes, and a rotation about ONE fixed axis through the
//! reference node. The drum of the braking benchmark is a body with only its spin free; the back
//! plate is a body with only its radial translation free. With a single fixed axis the rotation is
//! additive (Q(theta) = exp(theta [e]x)), so its equation of motion is the scalar
//! `I theta'' = M_e` and no SO(3) update is needed.
//!
//! Nodes tied to a body follow its translations only (see the integrator's DOF map), which is
//! exact for bodies without a free rotation such as the back plate.

use nalgebra::{SVector, Vector3};

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
    /// Rotary inertia about the rotation axis, kg m^2 (used when the rotation is free).
    pub rotary_inertia: f64,
    /// Global axes along which the reference node may translate.
    pub free_translations: [bool; D],
    /// Unit axis (world) of the one free rotation, or `None` if the body cannot rotate.
    /// In 2D the only admissible axis is +z.
    pub rotation_axis: Option<Vector3<f64>>,
    /// Initial velocity of the reference node, m/s.
    pub initial_velocity: SVector<f64, D>,
    /// Initial angular velocity about `rotation_axis`, rad/s.
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
        if let Some(axis) = self.rotation_axis {
            let norm = axis.norm();
            if (norm - 1.0).abs() >= 1e-9 || !norm.is_finite() {
                return fail(format!("rotation axis must be a unit vector, |e| = {norm}"));
            }
            if D == 2 && (axis.z - 1.0).abs() > 1e-12 {
                return fail("in 2D the rotation axis must be +z".into());
            }
        } else if self.initial_angular_velocity != 0.0 {
            return fail("an initial angular velocity needs a free rotation axis".into());
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
            rotation_axis: Some(Vector3::z()),
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
        d.rotation_axis = Some(Vector3::x());
        assert!(d.validate().is_err(), "2D axis must be z");
        let mut d = drum();
        d.rotation_axis = None;
        assert!(d.validate().is_err(), "spin without an axis");
        let mut d = drum();
        d.initial_velocity[0] = 1.0;
        assert!(d.validate().is_err(), "velocity along a fixed axis");
    }
}
