//! The orientations of rigid bodies free to turn, and their gyroscopic moments.
//!
//! A body free to turn has three rotation unknowns `x_r` whose changes are material rotation
//! increments. Its orientation is recorded at the end of every converged increment together with
//! the unknowns there, `(Q_n, x_r,n)`, and at any later iterate
//! `Q = Q_n exp([x_r - x_r,n]x)`: the increment's turn `Theta = x_r - x_r,n` is a rotation
//! vector in the body frame. The Newmark relations then hold for `Theta`, the body-frame angular
//! velocity `W` and acceleration `W'` (the material form of Simo and Vu-Quoc), and with its
//! principal axes as the unknowns' axes the mass stays the diagonal `J`; Euler's equations add the
//! gyroscopic moment `W x J W` (see [`gyroscopic_moments`]).
//!
//! A body never recorded (the start of a run) has its principal axes at their initial
//! directions `P` with `x_r = 0`.

use nalgebra::{DVector, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};
use skid_fem::rigid::{RigidBody, Rotation};

use crate::dof::DofMap;

/// The recorded orientation of one body free to turn.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Orientation {
    /// Body index in the model.
    pub body: usize,
    /// `Q_n` as a unit quaternion `[w, i, j, k]`.
    pub quaternion: [f64; 4],
    /// `x_r,n`, the rotation unknowns where `Q_n` was recorded, rad.
    pub at: [f64; 3],
}

/// The rotation unknowns of `body` in `x` (zeros beyond those it has).
fn rotation_unknowns<const D: usize>(
    dofs: &DofMap<D>,
    x: &DVector<f64>,
    body: usize,
) -> Vector3<f64> {
    let mut r = Vector3::zeros();
    for (i, &eq) in dofs.body_rotations(body).iter().enumerate().take(3) {
        r[i] = x[eq];
    }
    r
}

/// The orientation of the principal axes of the body free to turn `body` at `x`, from the
/// records `recorded`: `Q_n exp([x_r - x_r,n]x)`, or `P exp([x_r]x)` for a body never
/// recorded, `P` its principal axes at the start.
pub fn orientation<const D: usize>(
    dofs: &DofMap<D>,
    bodies: &[RigidBody<D>],
    recorded: &[Orientation],
    x: &DVector<f64>,
    body: usize,
) -> UnitQuaternion<f64> {
    let r = rotation_unknowns(dofs, x, body);
    match recorded.iter().find(|o| o.body == body) {
        Some(o) => {
            let [w, i, j, k] = o.quaternion;
            let q = UnitQuaternion::new_normalize(nalgebra::Quaternion::new(w, i, j, k));
            q * UnitQuaternion::from_scaled_axis(r - Vector3::from(o.at))
        }
        None => {
            let start = match bodies.get(body).map(|b| b.rotation) {
                Some(Rotation::Free { principal_axes, .. }) => {
                    UnitQuaternion::from_rotation_matrix(&principal_axes)
                }
                _ => UnitQuaternion::identity(),
            };
            start * UnitQuaternion::from_scaled_axis(r)
        }
    }
}

/// The orientations of all bodies free to turn at `x`, recorded there: what a converged
/// increment ending at `x` passes on (empty for a model without such bodies).
pub fn record<const D: usize>(
    dofs: &DofMap<D>,
    bodies: &[RigidBody<D>],
    recorded: &[Orientation],
    x: &DVector<f64>,
) -> Vec<Orientation> {
    (0..bodies.len())
        .filter(|&b| matches!(bodies[b].rotation, Rotation::Free { .. }))
        .map(|body| {
            let q = orientation(dofs, bodies, recorded, x, body);
            Orientation {
                body,
                quaternion: [q.w, q.i, q.j, q.k],
                at: rotation_unknowns(dofs, x, body).into(),
            }
        })
        .collect()
}

/// The gyroscopic moments `W x J W` of the bodies free to turn, on their rotation equations,
/// for the body-frame angular velocities `v` (zero elsewhere). They do no work (`W . (W x J W)
/// = 0`); added to the inertia `J W'` they give Euler's equations.
/// `None` if there is no such body.
pub fn gyroscopic_moments<const D: usize>(
    dofs: &DofMap<D>,
    bodies: &[RigidBody<D>],
    v: &DVector<f64>,
) -> Option<DVector<f64>> {
    let mut moments: Option<DVector<f64>> = None;
    for (b, body) in bodies.iter().enumerate() {
        if let Rotation::Free {
            principal_inertia, ..
        } = body.rotation
        {
            let w = rotation_unknowns(dofs, v, b);
            let m = w.cross(&principal_inertia.component_mul(&w));
            let out = moments.get_or_insert_with(|| DVector::zeros(v.len()));
            for (i, &eq) in dofs.body_rotations(b).iter().enumerate() {
                out[eq] += m[i];
            }
        }
    }
    moments
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::SVector;

    fn spinning_body() -> (DofMap<3>, Vec<RigidBody<3>>) {
        let body = RigidBody::<3> {
            name: "top".into(),
            reference_point: SVector::zeros(),
            mass: 1.0,
            rotary_inertia: 0.0,
            free_translations: [true, false, false],
            rotation: Rotation::Free {
                principal_inertia: Vector3::new(1.0, 2.0, 2.5),
                principal_axes: nalgebra::Rotation3::identity(),
                initial_angular_velocity: Vector3::zeros(),
            },
            initial_velocity: SVector::zeros(),
            initial_angular_velocity: 0.0,
        };
        (
            DofMap::new(0, &[], &[], &[[true, false, false]], &[3]),
            vec![body],
        )
    }

    /// A record keeps the orientation where it was made, and later turns compose on it as
    /// material increments: recording after each of two turns gives `exp(a) exp(b)`, not
    /// `exp(a + b)`.
    #[test]
    fn records_compose_material_increments() {
        let (dofs, bodies) = spinning_body();
        let (a, b) = (Vector3::new(0.3, -0.2, 0.5), Vector3::new(-0.1, 0.4, 0.2));
        let x = |r: Vector3<f64>| DVector::from_vec(vec![0.7, r.x, r.y, r.z]);
        let first = record(&dofs, &bodies, &[], &x(a));
        assert_eq!(first[0].at, [a.x, a.y, a.z]);
        let expected = UnitQuaternion::from_scaled_axis(a);
        assert!(orientation(&dofs, &bodies, &first, &x(a), 0).angle_to(&expected) < 1e-15);
        let second = orientation(&dofs, &bodies, &first, &x(a + b), 0);
        let composed = expected * UnitQuaternion::from_scaled_axis(b);
        assert!(second.angle_to(&composed) < 1e-15);
        assert!(second.angle_to(&UnitQuaternion::from_scaled_axis(a + b)) > 1e-3);
        // without a record the body starts at the world orientation with x_r = 0
        assert!(orientation(&dofs, &bodies, &[], &x(a), 0).angle_to(&expected) < 1e-15);
    }

    /// The gyroscopic moment `W x J W` does no work and vanishes about a principal axis.
    #[test]
    fn gyroscopic_moments_are_euler_s() {
        let (dofs, bodies) = spinning_body();
        let w = Vector3::new(1.0, -2.0, 3.0);
        let v = DVector::from_vec(vec![5.0, w.x, w.y, w.z]);
        let g = gyroscopic_moments(&dofs, &bodies, &v).expect("a free body");
        let expected = w.cross(&Vector3::new(1.0, 2.0, 2.5).component_mul(&w));
        assert_eq!(g.as_slice(), &[0.0, expected.x, expected.y, expected.z]);
        assert!(expected.dot(&w).abs() < 1e-14);
        let about_z = DVector::from_vec(vec![5.0, 0.0, 0.0, 3.0]);
        let g = gyroscopic_moments(&dofs, &bodies, &about_z).expect("a free body");
        assert_eq!(g.amax(), 0.0);
    }
}
