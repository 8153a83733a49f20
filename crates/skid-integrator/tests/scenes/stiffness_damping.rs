//! Stiffness-proportional (Rayleigh) damping: a block held at its base carries a plate of mass
//! `m` (tied to its top, free along y) launched downward at `v0`, an oscillator of stiffness `k`
//! (the block) and mass `m` (the plate; the block's own mass is 1 % of it). Without numerical
//! dissipation (alpha = 0), checked against the undamped run: the damping force `beta K v`
//! takes the oscillator's energy at the rate `beta omega^2` of a viscous damper `c = beta k`
//! (`E(t) = E0 exp(-beta omega^2 t)` averaged over a period), the ledger books what it takes
//! as damping dissipation and closes, and the undamped run keeps its energy.

use crate::common;

use nalgebra::{SVector, Vector3};
use skid_contact::plane::RigidPlane;
use skid_integrator::settings::Settings;
use skid_integrator::stepper::{IncrementReport, Observer, Step, StepKind, run};
use skid_integrator::{
    ConcentratedLoad, ContactPair, LoadTarget, Loads, Model, State, Tie, Variation,
};

const PLATE_MASS: f64 = 0.1;
const V0: f64 = -0.05;
const DT: f64 = 2e-5;
const DURATION: f64 = 0.03;

struct Record(Vec<State>);

impl<const D: usize> Observer<D> for Record {
    fn on_increment(&mut self, _: &Model<D>, r: &IncrementReport<'_>) -> std::io::Result<()> {
        self.0.push(r.state.clone());
        Ok(())
    }
}

/// The oscillator with damping factor `beta` (s), and the plate's y equation.
fn oscillator(beta: f64) -> (Model<2>, usize) {
    let mut part = common::block_part([-0.01, 0.0], [0.02, 0.005], [4, 1], 0.01, 2.17e-6, false);
    part.sections[0].stiffness_damping = beta;
    part.fixed = part.mesh.node_sets["ymin"]
        .iter()
        .flat_map(|&n| [(n, 0), (n, 1)])
        .collect();
    let top = part.mesh.node_sets["ymax"].clone();
    let mut plate = common::translating_body("plate", [false, true], 0.005);
    plate.mass = PLATE_MASS;
    plate.initial_velocity = SVector::<f64, 2>::new(0.0, V0);
    let model = Model::new(
        part,
        vec![plate],
        vec![Tie {
            body: 0,
            nodes: top,
        }],
        Loads::default(),
        vec![],
    )
    .expect("model");
    let eq = model.dofs().body_translation(0)[1].expect("plate y");
    (model, eq)
}

fn run_oscillator(beta: f64) -> (Model<2>, usize, Vec<State>) {
    let (model, eq) = oscillator(beta);
    let steps = [Step {
        name: "ring".into(),
        kind: StepKind::Dynamic {
            duration: DURATION,
            dt: DT,
            alpha: 0.0,
            adaptive: None,
        },
        held: vec![],
    }];
    let mut record = Record(Vec::new());
    let (_, result) = run(&model, &steps, &Settings::default(), &mut record);
    result.expect("run completes");
    (model, eq, record.0)
}

/// Times at which the plate's velocity crosses zero upward (linear interpolation).
fn upward_crossings(states: &[State], eq: usize) -> Vec<f64> {
    states
        .windows(2)
        .filter(|w| w[0].v[eq] < 0.0 && w[1].v[eq] >= 0.0)
        .map(|w| {
            let s = w[0].v[eq] / (w[0].v[eq] - w[1].v[eq]);
            w[0].time + s * (w[1].time - w[0].time)
        })
        .collect()
}

#[test]
fn stiffness_damping_takes_the_oscillator_energy_at_beta_omega_squared() {
    let (_, eq, free) = run_oscillator(0.0);
    let beta = 2e-5;
    let (_, _, damped) = run_oscillator(beta);
    // the plate's and the block's top nodes' kinetic energy
    let e0 = free[0].energy.mechanical();
    assert!(e0 > 0.5 * PLATE_MASS * V0 * V0);

    // the undamped oscillator keeps its energy; its period gives omega
    let last = free.last().expect("states");
    assert_eq!(last.energy.damping_dissipation, 0.0);
    let drift = (last.energy.mechanical() - e0).abs();
    assert!(
        drift < 1e-6 * e0,
        "undamped energy drift {drift:e} J of {e0:e} J"
    );
    let crossings = upward_crossings(&free, eq);
    assert!(crossings.len() >= 4, "{} periods", crossings.len());
    let periods = crossings.len() - 1;
    let period = (crossings[periods] - crossings[0]) / periods as f64;
    let omega = 2.0 * std::f64::consts::PI / period;

    // the damped one loses energy at beta omega^2 (measured: to 2e-5): compare the energies
    // two periods apart,
    // at the same phase of the motion (the upward crossings, where the plate's kinetic
    // energy is zero and the block's strain energy is largest)
    let energy_at = |t: f64| {
        let k = damped.partition_point(|s| s.time < t);
        damped[k].energy.mechanical()
    };
    let damped_crossings = upward_crossings(&damped, eq);
    let (t1, t2) = (damped_crossings[1], damped_crossings[3]);
    let rate = (energy_at(t1) / energy_at(t2)).ln() / (t2 - t1);
    let expected = beta * omega * omega;
    assert!(
        (rate / expected - 1.0).abs() < 1e-3,
        "energy decay rate {rate} 1/s against beta omega^2 = {expected} 1/s (omega {omega} rad/s)"
    );

    // the ledger books the loss as damping dissipation (measured: to 2e-7) and closes
    let end = damped.last().expect("states");
    let lost = e0 - end.energy.mechanical();
    assert!(lost > 0.3 * e0, "lost {lost:e} J of {e0:e} J");
    let booked = end.energy.damping_dissipation;
    assert!(
        (booked - lost).abs() < 1e-5 * lost,
        "damping dissipation {booked:e} J, energy lost {lost:e} J"
    );
    let unaccounted = end.energy.unaccounted_since(&damped[0].energy).abs();
    assert!(unaccounted < 1e-6 * lost, "unaccounted {unaccounted:e} J");
}

/// The viscous force takes the mean velocity of the increment on every equation, so it also
/// acts on massless contact nodes (in equilibrium at the end of each increment): a damped
/// block whose contact nodes carry no mass slides on a flat, and its ledger closes with the
/// damping dissipation booked.
#[test]
fn stiffness_damping_acts_with_massless_contact_nodes() {
    let mut part = common::block_part([-0.01, 0.0], [0.02, 0.005], [4, 1], 0.01, 2.17e-6, false);
    part.sections[0].stiffness_damping = 1e-5;
    let bottom = part.mesh.node_sets["ymin"].clone();
    let top = part.mesh.node_sets["ymax"].clone();
    let ground = common::translating_body("ground", [false, false], 0.0);
    let mut plate = common::translating_body("plate", [true, true], 0.005);
    plate.mass = PLATE_MASS;
    plate.initial_velocity = SVector::<f64, 2>::new(0.5, 0.0);
    let plane = RigidPlane::new(Vector3::y(), Vector3::x()).expect("plane");
    let loads = Loads {
        concentrated: vec![ConcentratedLoad {
            target: LoadTarget::Body(1),
            force: SVector::<f64, 2>::new(0.0, -20.0),
            moment: Vector3::zeros(),
            variation: Variation::Ramp,
        }],
        ..Loads::default()
    };
    let model = Model::new(
        part,
        vec![ground, plate],
        vec![Tie {
            body: 1,
            nodes: top,
        }],
        loads,
        vec![ContactPair {
            name: "block-ground".into(),
            nodes: bottom,
            body: 0,
            surface: Box::new(plane),
            mu: 0.3,
        }],
    )
    .expect("model")
    .with_massless_contact_nodes()
    .expect("massless contact nodes");
    let steps = [Step {
        name: "slide".into(),
        kind: StepKind::Dynamic {
            duration: 5e-3,
            dt: 2e-5,
            alpha: -0.3,
            adaptive: None,
        },
        held: vec![],
    }];
    let mut record = Record(Vec::new());
    let (_, result) = run(&model, &steps, &Settings::default(), &mut record);
    result.expect("run completes");
    let (first, last) = (&record.0[0], record.0.last().expect("states"));
    assert!(last.energy.damping_dissipation > 0.0);
    let work =
        last.energy.external_work - first.energy.external_work + last.energy.friction_dissipation;
    let unaccounted = last.energy.unaccounted_since(&first.energy).abs();
    assert!(
        unaccounted < 1e-4 * work,
        "unaccounted {unaccounted:e} J of {work:e} J"
    );
}
