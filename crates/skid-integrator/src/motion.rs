//! Motions of single degrees of freedom: those a step holds at their value ([`BodyMotion`] in
//! [`crate::stepper::HeldMotion`]) and those the model prescribes ([`PrescribedMotion`]).
//!
//! A prescribed motion sets one equation's unknown, a displacement from the reference
//! configuration (or a rotation angle), to `u(t) = value * f(t)`, `f` the factor of its
//! [`Variation`] at the increment's end, exactly as a load of that variation is scaled (see
//! [`crate::loads`]). The equation keeps its place in the system with an identity row, and
//! its residual, the force the constraint must apply, is its reaction (see
//! [`crate::increment`]).

use crate::dof::DofMap;
use crate::loads::{LoadInstant, Variation};

/// A motion of a rigid body's reference node.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BodyMotion {
    /// Translation along global axis `i`.
    Translation(usize),
    /// The rotation about the body's free axis. Held in a step (see
    /// [`crate::stepper::HeldMotion`]), the rotations of a body free to turn: all three.
    Rotation,
}

/// What a prescribed motion moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MotionTarget {
    /// One motion of a rigid body's reference node.
    Body {
        /// Index of the body.
        body: usize,
        /// The motion.
        motion: BodyMotion,
    },
    /// The displacement of a node of the solid along global axis `axis`.
    Node {
        /// Index of the node.
        node: usize,
        /// Global axis.
        axis: usize,
    },
}

/// A displacement (m) or rotation angle (rad) prescribed on one degree of freedom.
#[derive(Clone, Debug, PartialEq)]
pub struct PrescribedMotion {
    /// The degree of freedom.
    pub target: MotionTarget,
    /// Its full value: the unknown is `value` times the variation's factor.
    pub value: f64,
    /// How the value varies in time, as a load would.
    pub variation: Variation,
}

impl PrescribedMotion {
    /// The prescribed value at `instant`.
    pub fn at(&self, instant: &LoadInstant) -> f64 {
        self.value * instant.factor(&self.variation)
    }
}

/// The equation of a body motion among `dofs` (`None` if the model fixes it or has no such
/// motion).
pub fn body_equation<const D: usize>(
    dofs: &DofMap<D>,
    body: usize,
    motion: BodyMotion,
) -> Option<usize> {
    match motion {
        BodyMotion::Translation(i) => dofs.body_translation(body).get(i).copied().flatten(),
        BodyMotion::Rotation => dofs.body_rotation(body),
    }
}
