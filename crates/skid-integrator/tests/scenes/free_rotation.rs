//! A rigid body free to turn, with no moment on it: a torque-free symmetric top. With principal
//! moments of inertia `(J, J, J_3)` and body-frame angular velocity `W(0) = (W_p, 0, W_3)`,
//! Euler's equations `J W' + W x J W = 0` give `W_3` constant and `(W_1, W_2)` turning in the
//! body frame at `Omega = (J_3 - J) / J W_3`: `W_1 = W_p cos(Omega t)`, `W_2 = W_p sin(Omega t)`.
//! The kinetic energy and the spatial angular momentum `Q J W` are constant. The solid of the
//! model is one element held fixed, away from the body.

use nalgebra::{Rotation3, SVector, Vector3};
use skid_fem::hourglass::Hourglass;
use skid_fem::material::PolynomialN1;
use skid_fem::mesh::SolidMesh;
use skid_fem::rigid::{RigidBody, Rotation};
use skid_integrator::orientation::orientation;
use skid_integrator::settings::Settings;
use skid_integrator::stepper::{
    Checkpoint, IncrementReport, Observer, Step, StepKind, resume, run,
};
use skid_integrator::{
    ConcentratedLoad, LoadTarget, Loads, Model, Section, SolidPart, State, Variation,
};

const J: f64 = 0.01;
const J3: f64 = 0.02;
const W_P: f64 = 2.0;
const W_3: f64 = 20.0;
const DURATION: f64 = 0.5;

struct Record(Vec<State>);

impl<const D: usize> Observer<D> for Record {
    fn on_increment(&mut self, _: &Model<D>, r: &IncrementReport<'_>) -> std::io::Result<()> {
        self.0.push(r.state.clone());
        Ok(())
    }
}

/// One fixed hexahedron of the pad material and the top.
fn top() -> Model<3> {
    top_with(Loads::default(), Rotation3::identity())
}

/// [`top`] with `loads`, its principal axes at `axes` at the start (columns) and its initial
/// angular velocity turned alike.
fn top_with(loads: Loads<3>, axes: Rotation3<f64>) -> Model<3> {
    let mesh = SolidMesh::<3>::structured_block(
        SVector::<f64, 3>::new(1.0, 1.0, 1.0),
        SVector::<f64, 3>::repeat(0.01),
        [1, 1, 1],
    )
    .expect("mesh");
    let fixed = (0..mesh.nodes.len())
        .flat_map(|n| (0..3).map(move |axis| (n, axis)))
        .collect();
    let part = SolidPart {
        name: "block".into(),
        mesh,
        sections: vec![Section {
            material: Box::new(PolynomialN1::new(0.552e6, 0.138e6, 1e-7).expect("material")),
            density: 1000.0,
            stiffness_damping: 0.0,
        }],
        element_sections: Vec::new(),
        thickness: 1.0,
        hourglass: Hourglass::default(),
        element_formulations: Vec::new(),
        quasi_static: false,
        fixed,
    };
    let body = RigidBody::<3> {
        name: "top".into(),
        reference_point: SVector::zeros(),
        mass: 1.0,
        rotary_inertia: 0.0,
        free_translations: [false; 3],
        rotation: Rotation::Free {
            principal_inertia: Vector3::new(J, J, J3),
            principal_axes: axes,
            initial_angular_velocity: axes * Vector3::new(W_P, 0.0, W_3),
        },
        initial_velocity: SVector::zeros(),
        initial_angular_velocity: 0.0,
    };
    Model::new(part, vec![body], vec![], loads, vec![]).expect("model")
}

/// The spin of the top: one dynamic step of increments `dt`.
fn spin(dt: f64) -> Vec<Step> {
    vec![Step {
        name: "spin".into(),
        kind: StepKind::Dynamic {
            duration: DURATION,
            dt,
            alpha: -0.3,
            adaptive: None,
        },
        held: vec![],
    }]
}

/// The worst errors of a run with increments `dt`, relative: the body-frame angular velocity
/// against Euler's solution (over `W_p`), the drift of the spatial angular momentum and of the
/// kinetic energy, and the ledger's kinetic energy against `1/2 W . J W`.
fn worst_errors(dt: f64) -> [f64; 4] {
    let model = top();
    let dofs = model.dofs();
    let rotations = dofs.body_rotations(0).to_vec();
    assert_eq!(rotations.len(), 3);
    let mut record = Record(Vec::new());
    let (_, result) = run(&model, &spin(dt), &Settings::default(), &mut record);
    result.expect("run completes");
    let states = record.0;
    let last = states.last().expect("states");
    assert!((last.time - DURATION).abs() < 1e-9);
    assert_eq!(last.orientations.len(), 1);
    let inertia = Vector3::new(J, J, J3);
    let w = |s: &State| Vector3::from_fn(|i, _| s.v[rotations[i]]);
    let momentum = |s: &State| {
        orientation(dofs, model.bodies(), &s.orientations, &s.x, 0) * inertia.component_mul(&w(s))
    };
    let energy = |s: &State| 0.5 * w(s).dot(&inertia.component_mul(&w(s)));
    let (l0, e0) = (momentum(&states[0]), energy(&states[0]));
    let omega = (J3 - J) / J * W_3;
    let mut worst = [0.0_f64; 4];
    for s in &states {
        let t = s.time;
        let expected = Vector3::new(W_P * (omega * t).cos(), W_P * (omega * t).sin(), W_3);
        worst[0] = worst[0].max((w(s) - expected).norm() / W_P);
        worst[1] = worst[1].max((momentum(s) - l0).norm() / l0.norm());
        worst[2] = worst[2].max((energy(s) - e0).abs() / e0);
        worst[3] = worst[3].max((s.energy.kinetic - energy(s)).abs() / e0);
    }
    worst
}

/// Measured: 5.7e-4 of `W_p` over ten radians of precession at `Omega h = 0.02`, the angular
/// momentum constant to 1.2e-6 and the energy to 2.6e-7; halving the increment divides the
/// angular velocity's error by four. Taking the gyroscopic moment at the end of the increment
/// instead of HHT's `alpha` point makes the scheme first order: 5.8e-2 at `h = 1 ms`.
#[test]
fn a_torque_free_symmetric_top_precesses_at_the_rate_of_euler_s_equations() {
    let fine = worst_errors(1e-3);
    assert!(fine[0] < 1e-3, "angular velocity off by {} W_p", fine[0]);
    assert!(
        fine[1] < 1e-5,
        "spatial angular momentum drifts by {}",
        fine[1]
    );
    assert!(fine[2] < 1e-5, "kinetic energy drifts by {}", fine[2]);
    assert!(
        fine[3] < 1e-12,
        "the ledger's kinetic energy is 1/2 W . J W: {}",
        fine[3]
    );
    let coarse = worst_errors(2e-3);
    let order = (coarse[0] / fine[0]).log2();
    assert!(order > 1.8, "order {order}: {} then {}", coarse[0], fine[0]);
}

/// Records the states and keeps a checkpoint, as JSON, after the increment `at` (counting the
/// initial state).
struct Checkpointing {
    at: usize,
    seen: usize,
    states: Vec<State>,
    checkpoint: Option<String>,
}

impl Observer<3> for Checkpointing {
    fn on_increment(&mut self, _: &Model<3>, r: &IncrementReport<'_>) -> std::io::Result<()> {
        self.seen += 1;
        self.states.push(r.state.clone());
        Ok(())
    }

    fn wants_checkpoint(&mut self, _: bool) -> bool {
        self.seen == self.at
    }

    fn on_checkpoint(&mut self, _: &Model<3>, checkpoint: &Checkpoint) -> std::io::Result<()> {
        self.checkpoint = Some(serde_json::to_string(checkpoint).map_err(std::io::Error::other)?);
        Ok(())
    }
}

/// A run resumed from a checkpoint written as JSON after 200 increments ends in the
/// uninterrupted run's state, bit for bit: the checkpoint carries the orientation the run goes
/// on from (without it the resumed top would start from the world orientation).
#[test]
fn a_top_resumed_from_a_checkpoint_ends_where_the_whole_run_ends() {
    let model = top();
    let settings = Settings::default();
    let mut whole = Checkpointing {
        at: 201,
        seen: 0,
        states: Vec::new(),
        checkpoint: None,
    };
    run(&model, &spin(1e-3), &settings, &mut whole)
        .1
        .expect("run");
    let text = whole.checkpoint.expect("a checkpoint");
    let checkpoint: Checkpoint = serde_json::from_str(&text).expect("checkpoint reads");
    assert_eq!(checkpoint.state.orientations.len(), 1);
    assert!((checkpoint.state.time - 0.2).abs() < 1e-12);
    let mut resumed = Record(Vec::new());
    resume(&model, &spin(1e-3), &settings, &mut resumed, &checkpoint)
        .1
        .expect("resumed run");
    let (a, b) = (
        whole.states.last().expect("states"),
        resumed.0.last().expect("states"),
    );
    assert_eq!(a.time, b.time);
    assert_eq!(a.x, b.x);
    assert_eq!(a.v, b.v);
    assert_eq!(a.orientations, b.orientations);
}

/// The top under a constant moment `M` fixed in the global frame: its angular momentum in the
/// global frame grows as `L(t) = L(0) + M t`, whichever way the top turns meanwhile, and the
/// energy ledger closes with the moment's work.
#[test]
fn a_constant_moment_changes_the_angular_momentum_at_its_rate() {
    let moment = Vector3::new(0.01, -0.02, 0.005);
    let loads = Loads {
        concentrated: vec![ConcentratedLoad {
            target: LoadTarget::Body(0),
            force: SVector::zeros(),
            moment,
            variation: Variation::Ramp,
        }],
        ..Loads::default()
    };
    let model = top_with(loads, Rotation3::identity());
    let dofs = model.dofs();
    let rotations = dofs.body_rotations(0).to_vec();
    let mut record = Record(Vec::new());
    run(&model, &spin(1e-3), &Settings::default(), &mut record)
        .1
        .expect("run completes");
    let inertia = Vector3::new(J, J, J3);
    let momentum = |s: &State| {
        let w = Vector3::from_fn(|i, _| s.v[rotations[i]]);
        orientation(dofs, model.bodies(), &s.orientations, &s.x, 0) * inertia.component_mul(&w)
    };
    let l0 = momentum(&record.0[0]);
    let mut worst: f64 = 0.0;
    for s in &record.0 {
        worst = worst.max((momentum(s) - (l0 + moment * s.time)).norm());
    }
    let last = record.0.last().expect("states");
    let (start, end) = (&record.0[0].energy, &last.energy);
    let balance = end.unaccounted_since(start).abs() / end.kinetic;
    // measured: 1.5e-6 N m s (3.7e-6 of L(0), 1.3e-4 of the moment's impulse); the ledger
    // closes to 1.4e-10 of the kinetic energy
    assert!(worst < 1e-5 * l0.norm(), "L off by {worst}");
    assert!(
        end.external_work.abs() > 1e-3 * end.kinetic,
        "the moment works"
    );
    assert!(
        balance < 1e-6,
        "the ledger misses {balance} of the kinetic energy"
    );
}

/// The top with its principal axes tilted at the start moves as the aligned top turned by the
/// tilt `P`: the same body-frame angular velocity in every increment (to round-off) and its
/// orientation `P` times the aligned one's, so that its angular momentum is `P` times the
/// aligned one's.
#[test]
fn a_top_with_tilted_principal_axes_moves_as_the_aligned_top_turned() {
    let tilt = Rotation3::from_scaled_axis(Vector3::new(0.3, -0.5, 0.8));
    let (aligned, tilted) = (top(), top_with(Loads::default(), tilt));
    let mut records = [Record(Vec::new()), Record(Vec::new())];
    for (model, record) in [&aligned, &tilted].into_iter().zip(records.iter_mut()) {
        run(model, &spin(1e-3), &Settings::default(), record)
            .1
            .expect("run completes");
    }
    let [a, b] = &records;
    assert_eq!(a.0.len(), b.0.len());
    let dofs = aligned.dofs();
    let mut worst: [f64; 2] = [0.0; 2];
    for (sa, sb) in a.0.iter().zip(&b.0) {
        worst[0] = worst[0].max((&sa.v - &sb.v).amax());
        let qa = orientation(dofs, aligned.bodies(), &sa.orientations, &sa.x, 0);
        let qb = orientation(dofs, tilted.bodies(), &sb.orientations, &sb.x, 0);
        let turned = nalgebra::UnitQuaternion::from_rotation_matrix(&tilt) * qa;
        worst[1] = worst[1].max(qb.angle_to(&turned));
    }
    assert!(
        worst[0] < 1e-9 * W_3,
        "body-frame angular velocities differ by {}",
        worst[0]
    );
    assert!(worst[1] < 1e-9, "orientations differ by {} rad", worst[1]);
}
