//! A quasi-static block pressed on a rigid ground that slides under it. The block has no
//! inertia, so at every increment it is in equilibrium with the mean contact forces: they carry
//! exactly the pressure, and once the block has sheared enough to slide, exactly mu N. The
//! ground (mass m) receives the same forces as an impulse: it is braked at exactly `mu N / m`,
//! whatever the time step.
//!
//! The global contact solve runs it: held only by its contacts, the massless block and plate
//! have a singular stiffness without them, which the reduced solve can only invert with a mass
//! shift that slows Newton down (at 0.25 ms steps it needs 9 cutbacks and stops at 3.1 ms with a
//! folded element; the global solve takes 20 increments and 33 iterations).

use crate::common;

use nalgebra::{SVector, Vector3};
use skid_contact::plane::RigidPlane;
use skid_fem::rigid::RigidBody;
use skid_integrator::settings::ContactSolve;
use skid_integrator::settings::Settings;
use skid_integrator::stepper::{
    HeldMotion, IncrementReport, Observer, StaticIncrements, Step, StepKind, run,
};
use skid_integrator::{ContactPair, Model, PressureLoad, State, Tie, Variation};

const MU: f64 = 0.3;
const WIDTH: f64 = 0.02;
const HEIGHT: f64 = 0.01;
const THICKNESS: f64 = 0.01;
const P_TOP: f64 = 1e5; // normal force N = P_TOP * WIDTH * THICKNESS = 20 N
const GROUND_MASS: f64 = 0.05;
const V0: f64 = 1.0; // braked at mu N / m = 120 m/s^2, stops after 8.3 ms

struct Record(Vec<(bool, State)>);

impl<const D: usize> Observer<D> for Record {
    fn on_increment(&mut self, _: &Model<D>, r: &IncrementReport<'_>) -> std::io::Result<()> {
        self.0.push((r.dynamic, r.state.clone()));
        Ok(())
    }
}

/// A 2 x 1 block on the plane y = 0 of a ground that slides along x; the block's top face is
/// tied to a massless plate that may only move vertically and carries the pressure.
fn scene(quasi_static: bool, plate_mass: f64) -> Result<Model<2>, skid_integrator::ModelError> {
    let part = common::block_part(
        [-WIDTH / 2.0, 0.0],
        [WIDTH, HEIGHT],
        [2, 1],
        THICKNESS,
        0.145e-6,
        quasi_static,
    );
    let bottom = part.mesh.node_sets["ymin"].clone();
    let top = part.mesh.node_sets["ymax"].clone();
    let top_faces = part.mesh.surfaces["ymax"].clone();
    let ground = RigidBody::<2> {
        mass: GROUND_MASS,
        initial_velocity: SVector::<f64, 2>::new(V0, 0.0),
        ..common::translating_body("ground", [true, false], 0.0)
    };
    let plate = RigidBody::<2> {
        mass: plate_mass,
        ..common::translating_body("plate", [false, true], HEIGHT)
    };
    Model::new(
        part,
        vec![ground, plate],
        vec![Tie {
            body: 1,
            nodes: top,
        }],
        vec![PressureLoad {
            faces: top_faces,
            pressure: P_TOP,
            variation: Variation::Ramp,
        }]
        .into(),
        vec![ContactPair {
            name: "block-ground".into(),
            nodes: bottom,
            body: 0,
            surface: Box::new(RigidPlane::new(Vector3::y(), Vector3::x()).expect("plane")),
            mu: MU,
        }],
    )
}

/// Preload with the ground held, then 4 ms of sliding with steps of `dt`: the ground's velocity
/// and the block's contact forces at the end of every dynamic increment.
fn slide(dt: f64, method: ContactSolve) -> Vec<State> {
    let model = scene(true, 0.0).expect("model");
    let steps = [
        Step {
            name: "preload".into(),
            kind: StepKind::Static {
                increments: StaticIncrements::Fixed(4),
                regularization_time: 1e-2,
            },
            held: vec![HeldMotion::body(0)],
        },
        Step {
            name: "slide".into(),
            kind: StepKind::Dynamic {
                duration: 4e-3,
                dt,
                alpha: -0.3,
                adaptive: None,
            },
            held: vec![],
        },
    ];
    let settings = Settings {
        contact_solve: method,
        ..Settings::default()
    };
    let mut record = Record(Vec::new());
    let (stats, result) = run(&model, &steps, &settings, &mut record);
    if let Err(e) = result {
        panic!("{method:?} at dt {dt}: {e:?}");
    }
    assert_eq!(stats.cutbacks, 0, "{method:?} at dt {dt}");
    record
        .0
        .into_iter()
        .filter_map(|(dynamic, s)| dynamic.then_some(s))
        .collect()
}

#[test]
fn a_massless_block_brakes_the_ground_at_exactly_mu_n_over_m() {
    let normal = P_TOP * WIDTH * THICKNESS;
    let eq = scene(true, 0.0).expect("model").dofs().body_translation(0)[0]
        .expect("the ground's free x");
    let method = ContactSolve::Global;
    for dt in [1e-3, 2.5e-4] {
        let states = slide(dt, method);
        let mut sliding = 0;
        for (s0, s) in states.iter().zip(&states[1..]) {
            // in equilibrium with its contact forces: they carry the whole pressure
            let n: f64 = s.contacts.iter().map(|c| c.normal_force).sum();
            let t: f64 = s.contacts.iter().map(|c| c.tangential_force[0]).sum();
            assert!((n - normal).abs() <= 1e-5 * normal, "N {n} vs {normal}");
            // the ground gets the reaction to the block's friction force as an impulse
            let dv = s.v[eq] - s0.v[eq];
            let h = s.time - s0.time;
            assert!(
                (dv + h * t / GROUND_MASS).abs() <= 1e-9 * V0,
                "{method:?} dt {dt} t {}: dv {dv} vs -h T / m {}",
                s.time,
                -h * t / GROUND_MASS
            );
            // no inertia: no kinetic energy but the ground's
            let ground = 0.5 * GROUND_MASS * s.v[eq] * s.v[eq];
            assert!((s.energy.kinetic - ground).abs() <= 1e-12 * ground);
            if s.contacts.iter().all(|c| c.slip[0] < 0.0) {
                // sliding: the ground drags the block along +x with exactly mu N, so its
                // deceleration is mu N / m
                sliding += 1;
                assert!(
                    (t - MU * n).abs() <= 1e-6 * normal,
                    "friction {t} vs mu N {}",
                    MU * n
                );
                assert!(
                    (dv + h * MU * normal / GROUND_MASS).abs()
                        <= 1e-5 * h * MU * normal / GROUND_MASS,
                    "{method:?} dt {dt} t {}: dv {dv}",
                    s.time
                );
            }
        }
        // it slides after shearing by mu N / (G A / H) = 0.2 mm, in well under 1 ms
        assert!(
            sliding + 2 >= states.len(),
            "{method:?} dt {dt}: {sliding} sliding increments of {}",
            states.len()
        );
    }
}

#[test]
fn a_body_tied_to_a_quasi_static_solid_must_be_massless() {
    let err = scene(true, 0.5).expect_err("a massive plate on a quasi-static block");
    let msg = err.to_string();
    assert!(
        msg.contains("'plate'") && msg.contains("quasi-static"),
        "{msg}"
    );
    assert!(scene(false, 0.5).is_ok());
}
