//! The torque-free rigid body of the verification section: a scene whose only motion is a
//! rigid body free to turn about all three axes, its principal axes along the global ones, with
//! no contact and no load. From its
//! `history.csv` (the rotation vector `B.rotation_*` of its orientation `Q` and its global
//! angular velocity `B.omega_*`), with the body-frame angular velocity `W = Q^T omega` and the
//! principal moments of inertia `J` of its model:
//!
//! - the angular momentum `Q J W` in the global frame stays within [`CONSERVATION_TOLERANCE`]
//!   of its initial value, relative, in every increment, and so does the kinetic energy
//!   `1/2 W . J W`;
//! - for a symmetric top (two moments equal, `J_a = J_b = J` and the third `J_s`), `W` follows
//!   Euler's solution: its axial component stays `W_s(0)` and its transverse part turns in the
//!   body frame at `Omega = (J_s - J) / J W_s(0)` about the symmetry axis; the largest
//!   difference, relative to the transverse spin, stays within [`PRECESSION_TOLERANCE`].

use std::fmt::Write as _;
use std::path::Path;

use nalgebra::{Rotation3, UnitQuaternion, Vector3};

use super::SceneRun;
use crate::ReportError;
use crate::format::{Checks, Sig};
use crate::read;
use skid_cases::csv_out::CsvTable;
use skid_cases::model_spec::{Dof, ModelSpec};

/// Largest drift of the angular momentum and of the kinetic energy, relative (measured on
/// `3d-torque-free-top`: 1.2e-6 and 2.6e-7 over 500 increments).
pub const CONSERVATION_TOLERANCE: f64 = 1e-5;
/// Largest difference of `W` from Euler's solution, relative to the transverse spin (measured:
/// 5.7e-4 over ten radians of precession at `Omega h = 0.02`; HHT's phase error is of second
/// order in `Omega h`).
pub const PRECESSION_TOLERANCE: f64 = 2e-3;

/// A torque-free rigid body: its name, principal moments of inertia and initial angular
/// velocity (the body and global axes coincide at the start).
#[derive(Clone, Debug, PartialEq)]
pub struct FreeBody {
    /// The body's name (its history columns' prefix).
    pub name: String,
    /// `(J_x, J_y, J_z)`, kg m^2.
    pub inertia: Vector3<f64>,
    /// `W(0)`, rad/s.
    pub spin: Vector3<f64>,
}

impl FreeBody {
    /// The body of a scene with no contact and no load whose only rigid body is free to turn
    /// about all three axes (no boundary condition on its rotations).
    pub fn recognise(spec: &ModelSpec) -> Option<Self> {
        if spec.dimension != 3 || !spec.contact.is_empty() || !spec.loads.is_empty() {
            return None;
        }
        let [body] = spec.rigid_bodies.as_slice() else {
            return None;
        };
        let turns = |d: &Dof| {
            !spec
                .boundary
                .iter()
                .any(|b| b.body.as_deref() == Some(body.name.as_str()) && b.dofs.contains(d))
        };
        if ![Dof::Rx, Dof::Ry, Dof::Rz].iter().all(turns) {
            return None;
        }
        if body.products_of_inertia.is_some_and(|p| p != [0.0; 3]) {
            return None;
        }
        Some(Self {
            name: body.name.clone(),
            inertia: Vector3::from(body.moments_of_inertia?),
            spin: Vector3::from(body.initial_angular_velocity.unwrap_or([0.0; 3])),
        })
    }

    /// The symmetry axis of a symmetric top (the one whose moment differs from the two equal
    /// others, or any if all three are equal) and its precession rate
    /// `Omega = (J_s - J) / J W_s(0)`; `None` if no two moments are equal.
    pub fn symmetry(&self) -> Option<(usize, f64)> {
        let j = &self.inertia;
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * (a.abs() + b.abs());
        let axis = (0..3).find(|&k| close(j[(k + 1) % 3], j[(k + 2) % 3]))?;
        let equal = j[(axis + 1) % 3];
        Some((axis, (j[axis] - equal) / equal * self.spin[axis]))
    }

    /// `W(t)` by Euler's solution for a symmetric top (`None` if it is not one): the axial
    /// component constant, the transverse part turned by `Omega t` about the axis.
    pub fn euler_spin(&self, t: f64) -> Option<Vector3<f64>> {
        let (axis, omega) = self.symmetry()?;
        Some(Rotation3::from_axis_angle(&Vector3::ith_axis(axis), omega * t) * self.spin)
    }

    /// `|W_perp(0)|`, the spin across the symmetry axis (0 if it is not a symmetric top).
    fn transverse_spin(&self) -> f64 {
        self.symmetry().map_or(0.0, |(axis, _)| {
            let mut w = self.spin;
            w[axis] = 0.0;
            w.norm()
        })
    }
}

/// What a run of a torque-free body measured.
struct Measured {
    /// Largest `|L - L_0| / |L_0|`.
    momentum: f64,
    /// Largest `|T - T_0| / T_0`.
    energy: f64,
    /// Largest `|W - W_Euler| / |W_perp(0)|` (symmetric tops only).
    precession: Option<f64>,
    /// Converged states read.
    states: usize,
}

/// `Measured` from a run's `history.csv` text.
fn measure(body: &FreeBody, text: &str, path: &Path) -> Result<Measured, ReportError> {
    let table = CsvTable::new(text, path)?;
    let time = table.column("time")?;
    let names: Vec<String> = ["rotation", "omega"]
        .iter()
        .flat_map(|what| ["x", "y", "z"].map(|axis| format!("{}.{what}_{axis}", body.name)))
        .collect();
    let columns = names
        .iter()
        .map(|n| table.column(n))
        .collect::<Result<Vec<_>, _>>()?;
    let j = body.inertia;
    let transverse = body.transverse_spin();
    let mut start = None;
    let mut measured = Measured {
        momentum: 0.0,
        energy: 0.0,
        precession: None,
        states: 0,
    };
    for row in table {
        let row = row?;
        let t: f64 = row.number(time)?;
        let mut r = Vector3::zeros();
        let mut w_global = Vector3::zeros();
        for k in 0..3 {
            r[k] = row.number(columns[k])?;
            w_global[k] = row.number(columns[k + 3])?;
        }
        let q = UnitQuaternion::from_scaled_axis(r);
        let w = q.inverse() * w_global;
        let momentum = q * j.component_mul(&w);
        let energy = 0.5 * w.dot(&j.component_mul(&w));
        let (l0, e0) = *start.get_or_insert((momentum, energy));
        measured.momentum = measured.momentum.max((momentum - l0).norm() / l0.norm());
        measured.energy = measured.energy.max((energy - e0).abs() / e0);
        if let Some(exact) = body.euler_spin(t)
            && transverse > 0.0
        {
            let error = (w - exact).norm() / transverse;
            measured.precession = Some(measured.precession.unwrap_or(0.0).max(error));
        }
        measured.states += 1;
    }
    Ok(measured)
}

/// The torque-free bodies' part of the section: a table and the checks (see the module
/// documentation).
///
/// # Errors
/// [`ReportError`] if a completed run's `history.csv` is absent or lacks the body's columns.
pub fn section(runs: &[(&SceneRun, FreeBody)], checks: &mut Checks) -> Result<String, ReportError> {
    let mut out = String::from(
        "### Torque-free rigid bodies\n\n\
         A rigid body free to turn, with no contact and no load: its angular momentum in the \
         global frame and its kinetic energy are constant, and a symmetric top's body-frame \
         angular velocity follows Euler's solution (its transverse part turning at \
         `Omega = (J_s - J) / J W_s` about the symmetry axis).\n\n\
         | scene | states | momentum drift | energy drift | error against Euler |\n\
         |---|---|---|---|---|\n",
    );
    for (run, body) in runs {
        if !run.completed_or_recorded(checks) {
            continue;
        }
        let path = run.dir.join("history.csv");
        let measured = measure(body, &read(&path)?, &path)?;
        let precession = measured
            .precession
            .map_or_else(|| "n/a".to_string(), |p| Sig(p).to_string());
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {precession} |",
            run.name,
            measured.states,
            Sig(measured.momentum),
            Sig(measured.energy)
        );
        let name = &run.name;
        checks.check(
            &format!(
                "{name}: angular momentum drift < {}",
                Sig(CONSERVATION_TOLERANCE)
            ),
            Some(measured.momentum),
            CONSERVATION_TOLERANCE,
            "",
        );
        checks.check(
            &format!(
                "{name}: kinetic energy drift < {}",
                Sig(CONSERVATION_TOLERANCE)
            ),
            Some(measured.energy),
            CONSERVATION_TOLERANCE,
            "",
        );
        if body.symmetry().is_some() {
            checks.check(
                &format!(
                    "{name}: angular velocity against Euler's solution < {} of the transverse spin",
                    Sig(PRECESSION_TOLERANCE)
                ),
                measured.precession,
                PRECESSION_TOLERANCE,
                "no transverse spin to precess",
            );
        }
    }
    out.push('\n');
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The symmetric top of `cases/verification/3d-torque-free-top.json`.
    fn top() -> FreeBody {
        FreeBody {
            name: "top".into(),
            inertia: Vector3::new(0.01, 0.01, 0.02),
            spin: Vector3::new(2.0, 0.0, 20.0),
        }
    }

    /// A history of the top's exact motion, `Q(t) = exp(t [J W_0 / J]x) exp(-t Omega [e_z]x)`
    /// (the precession about the angular momentum and the spin back about the axis), with
    /// `spin` in place of the exact body-frame angular velocity.
    fn history(spin: impl Fn(f64) -> Vector3<f64>) -> String {
        let body = top();
        let (_, omega) = body.symmetry().expect("symmetric");
        let precession = body.inertia.component_mul(&body.spin) / body.inertia.x;
        let mut text = String::from(
            "time,top.rotation_x,top.rotation_y,top.rotation_z,top.omega_x,top.omega_y,top.omega_z\n",
        );
        for k in 0..=500 {
            let t = k as f64 * 1e-3;
            let q = UnitQuaternion::from_scaled_axis(precession * t)
                * UnitQuaternion::from_scaled_axis(Vector3::z() * (-omega * t));
            let (r, w) = (q.scaled_axis(), q * spin(t));
            let _ = writeln!(
                text,
                "{t:.9e},{:.9e},{:.9e},{:.9e},{:.9e},{:.9e},{:.9e}",
                r.x, r.y, r.z, w.x, w.y, w.z
            );
        }
        text
    }

    #[test]
    fn the_exact_top_passes_and_a_wrong_precession_fails() {
        let body = top();
        assert_eq!(body.symmetry(), Some((2, 20.0)));
        let path = Path::new("history.csv");
        let exact = measure(&body, &history(|t| body.euler_spin(t).expect("top")), path)
            .expect("history reads");
        assert_eq!(exact.states, 501);
        assert!(exact.momentum < 1e-8, "{}", exact.momentum);
        assert!(exact.energy < 1e-8, "{}", exact.energy);
        assert!(exact.precession.expect("symmetric") < 1e-8);
        // precessing 1 % too fast: the motion no longer keeps its momentum, nor Euler's rate
        let fast = FreeBody {
            spin: Vector3::new(2.0, 0.0, 20.2),
            ..top()
        };
        let wrong = measure(&body, &history(|t| fast.euler_spin(t).expect("top")), path)
            .expect("history reads");
        assert!(wrong.precession.expect("symmetric") > PRECESSION_TOLERANCE);
        assert!(wrong.momentum > CONSERVATION_TOLERANCE);
        // a history without the body's columns is an error, not a pass
        assert!(measure(&body, "time\n0\n", path).is_err());
    }

    #[test]
    fn only_a_lone_free_body_without_contact_or_load_is_recognised() {
        let text = std::fs::read_to_string(
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../cases/verification/3d-torque-free-top.json"),
        )
        .expect("scene");
        let spec: ModelSpec = serde_json::from_str(&text).expect("model");
        assert_eq!(FreeBody::recognise(&spec), Some(top()));
        let mut held = spec.clone();
        held.boundary[0].dofs.push(Dof::Rx);
        assert_eq!(FreeBody::recognise(&held), None);
        let mut asymmetric = spec;
        asymmetric.rigid_bodies[0].moments_of_inertia = Some([0.01, 0.015, 0.02]);
        let body = FreeBody::recognise(&asymmetric).expect("still a free body");
        assert_eq!(body.symmetry(), None);
    }
}
