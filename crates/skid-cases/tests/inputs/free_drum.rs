//! A drum free to turn about all three axes: `cases/drum/3d-analytic.json` with the drum's
//! rotations about x and y freed as well, principal moments of inertia (0.1, 0.1, 0.175) kg m^2.
//!
//! The pad is symmetric about the drum's mid-plane `z = 0`, so the moments of its contact forces
//! about x and y cancel: the drum keeps spinning about z, and its spin-down is the fixed-axis
//! drum's. Any error in the free body's contact rows, orientation or gyroscopic moments would
//! tilt it or change its deceleration. The free drum's rows are the end-point derivatives, the
//! fixed drum's the discrete gradients over the increment (see `skid_integrator::contact_rows`),
//! so the two differ by the pad's vibration: measured, 4.7e-3 rad/s at most in omega_z and 5e-5
//! in the deceleration over the first 20 ms, on either contact path.
//!
//! Over a longer run the free drum's tilt grows exponentially from round-off (6e-8 rad/s at
//! 20 ms, 3e-4 at 30 ms) and levels off near 1e-3 rad/s; near the stop omega_z differs by
//! 5e-3 rad/s, about 9 us of the 600 rad/s^2 deceleration. The
//! growth needs friction (with mu = 0 the tilt stays at 1e-12 rad/s) and is faster at half the
//! time step (4e-4 rad/s at 20 ms), where HHT damps less: the friction-induced flutter of a drum
//! without bearings, not the integration's. The run is cut at 20 ms, before it shows.

use std::path::{Path, PathBuf};

use nalgebra::Vector3;
use skid_cases::drum::model_spec;
use skid_cases::load_case;
use skid_cases::model_file;
use skid_cases::model_spec::{Dof, ModelSpec};
use skid_cases::schema::ContactSolveSpec;
use skid_integrator::orientation::orientation;
use skid_integrator::stepper::{IncrementReport, Observer, run};
use skid_integrator::{Model, State};

/// The spin-down is cut to 20 ms (the drum stops at about 100 ms).
const SPIN_DOWN: &str = "steps[1].duration=0.02";

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(path)
}

/// The drum's angular velocity in the global frame at every converged state of `spec`.
fn drum_spin(spec: &ModelSpec) -> Vec<(f64, Vector3<f64>)> {
    struct Spin(Vec<(f64, Vector3<f64>)>);
    impl Observer<3> for Spin {
        fn on_increment(
            &mut self,
            model: &Model<3>,
            r: &IncrementReport<'_>,
        ) -> std::io::Result<()> {
            let s: &State = r.state;
            let dofs = model.dofs();
            let spin = match dofs.body_rotations(0) {
                &[about_z] => Vector3::new(0.0, 0.0, s.v[about_z]),
                &[e0, e1, e2] => {
                    orientation(dofs, model.bodies(), &s.orientations, &s.x, 0)
                        * Vector3::new(s.v[e0], s.v[e1], s.v[e2])
                }
                other => panic!("drum rotations {other:?}"),
            };
            self.0.push((s.time, spin));
            Ok(())
        }
    }
    let scene = model_file::build::<3>(spec).expect("scene builds");
    let mut record = Spin(Vec::new());
    let (_, result) = run(&scene.model, &scene.steps, &scene.settings, &mut record);
    result.expect("run completes");
    record.0
}

/// The drum case and its variant free to turn, with the contact solve `solve`.
fn drums(solve: ContactSolveSpec) -> (f64, ModelSpec, ModelSpec) {
    let case = load_case(
        &repo("cases/drum/3d-analytic.json"),
        &[SPIN_DOWN.to_string()],
    )
    .expect("case loads");
    let mut fixed = model_spec(&case).expect("the drum case as a model");
    fixed.solver.contact_solve = solve;
    let mut free = fixed.clone();
    let drum = free.boundary[0].body.clone().expect("the drum's boundary");
    assert_eq!(drum, free.rigid_bodies[0].name);
    free.boundary[0].dofs = vec![Dof::X, Dof::Y, Dof::Z];
    free.rigid_bodies[0].rotary_inertia = 0.0;
    free.rigid_bodies[0].moments_of_inertia = Some([0.1, 0.1, case.drum.rotary_inertia]);
    (case.drum.omega0, fixed, free)
}

/// The free drum against the fixed one, both with the contact solve `solve`; the free drum's
/// tilt must stay below `tilt` rad/s.
fn spins_down_as_on_its_axis(solve: ContactSolveSpec, tilt: f64) {
    let (omega0, fixed, free) = drums(solve);
    let (fixed, free) = (drum_spin(&fixed), drum_spin(&free));
    assert_eq!(fixed.len(), free.len(), "increments");
    let (mut worst_spin, mut worst_tilt) = (0.0_f64, 0.0_f64);
    for ((t1, w1), (t2, w2)) in fixed.iter().zip(&free) {
        assert_eq!(t1, t2);
        worst_spin = worst_spin.max((w1.z - w2.z).abs());
        worst_tilt = worst_tilt.max(w2.xy().norm());
    }
    let (a1, a2) = (deceleration(&fixed), deceleration(&free));
    assert!(a1 > 500.0, "{solve:?}: the drum slows down: {a1} rad/s^2");
    assert!(
        (a1 - a2).abs() < 1e-4 * a1,
        "{solve:?}: decelerations {a1} and {a2}"
    );
    assert!(
        worst_spin < 2e-4 * omega0,
        "{solve:?}: omega_z differs by {worst_spin}"
    );
    assert!(
        worst_tilt < tilt,
        "{solve:?}: the drum tilts at {worst_tilt} rad/s"
    );
}

/// Measured: omega_z within 4.7e-3 rad/s, the deceleration within 4.9e-5, a tilt of 6e-8 rad/s.
#[test]
fn a_drum_free_to_turn_spins_down_as_the_drum_on_its_axis() {
    spins_down_as_on_its_axis(ContactSolveSpec::Reduced, 1e-6);
}

/// Measured: omega_z within 4.4e-3 rad/s, the deceleration within 5.4e-5, a tilt of 4e-5
/// rad/s. The global path's iterative solves leave residuals up to the Newton tolerance, a
/// moment of up to 1e-6 of the largest force times the model size (about 1e-3 N m here), which
/// over 20 ms may tilt the drum by 2e-4 rad/s; the reduced path's direct solves leave far less.
#[test]
fn a_drum_free_to_turn_spins_down_alike_on_the_global_contact_path() {
    spins_down_as_on_its_axis(ContactSolveSpec::Global, 2e-4);
}

/// The least-squares deceleration `-d omega_z / dt` over the spin-down (the states after the
/// preload, which all sit at t = 0).
fn deceleration(spin: &[(f64, Vector3<f64>)]) -> f64 {
    let points: Vec<(f64, f64)> = spin
        .iter()
        .filter(|(t, _)| *t > 0.0)
        .map(|(t, w)| (*t, w.z))
        .collect();
    let n = points.len() as f64;
    let (mt, mw) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), (t, w)| (a + t / n, b + w / n));
    let (stw, stt) = points.iter().fold((0.0, 0.0), |(a, b), (t, w)| {
        (a + (t - mt) * (w - mw), b + (t - mt) * (t - mt))
    });
    -stw / stt
}
