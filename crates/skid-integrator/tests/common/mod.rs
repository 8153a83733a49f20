//! Fixtures shared by the integration tests.

use nalgebra::SVector;
use skid_fem::rigid::RigidBody;

/// A massless 2D rigid body at `(0, y)` that may translate along the axes marked in `free` and
/// never rotates: a held ground (`[false, false]`) or a loaded plate.
pub fn translating_body(name: &str, free: [bool; 2], y: f64) -> RigidBody<2> {
    RigidBody::<2> {
        name: name.into(),
        reference_point: SVector::<f64, 2>::new(0.0, y),
        mass: 0.0,
        rotary_inertia: 0.0,
        free_translations: free,
        rotation_axis: None,
        initial_velocity: SVector::zeros(),
        initial_angular_velocity: 0.0,
    }
}
