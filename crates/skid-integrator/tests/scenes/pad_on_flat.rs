//! The drum pad's material pressed onto a rigid flat under hard conditions:
//! - by more than its shear modulus: its tangent without the contacts is indefinite (the free
//!   front face may shear and tilt at negative stiffness under the compressive stress), yet the
//!   pad held by the contact is in stable equilibrium. The static preload must find that
//!   equilibrium, and the equilibrium must not depend on the Newton matrix's mass regularisation;
//! - nearly incompressible (K/mu = 1e7): preload and dynamics must run without cutbacks.

use crate::common;

use nalgebra::Vector3;
use skid_contact::plane::RigidPlane;
use skid_integrator::settings::Settings;
use skid_integrator::stepper::{IncrementReport, Observer, StaticIncrements, Step, StepKind, run};
use skid_integrator::{ContactPair, Model, PressureLoad, State, Tie, Variation};

const LENGTH: f64 = 0.1;
const THICKNESS: f64 = 0.05;
const WIDTH: f64 = 0.1;
/// 2.5 times the shear modulus 1.38 MPa of the pad material.
const HIGH_PRESSURE: f64 = 3.5e6;
/// The drum benchmark's D1 (K/mu = 10) and its literal reading (K/mu = 1e7).
const D1: f64 = 0.145e-6;
const D1_LITERAL: f64 = 0.145e-12;

struct Last(Option<State>);

impl<const D: usize> Observer<D> for Last {
    fn on_increment(&mut self, _: &Model<D>, r: &IncrementReport<'_>) -> std::io::Result<()> {
        self.0 = Some(r.state.clone());
        Ok(())
    }
}

/// The pad (4 x 1 plane-strain elements, compressibility `d1`) on the plane y = 0, its back face
/// tied to a plate that may only translate in y and loaded by `pressure`.
fn pad(pressure: f64, d1: f64) -> Model<2> {
    let part = common::block_part(
        [-0.5 * LENGTH, 0.0],
        [LENGTH, THICKNESS],
        [4, 1],
        WIDTH,
        d1,
        false,
    );
    let front = part.mesh.node_sets["ymin"].clone();
    let back = part.mesh.node_sets["ymax"].clone();
    let back_faces = part.mesh.surfaces["ymax"].clone();
    let body = common::translating_body;
    Model::new(
        part,
        vec![
            body("ground", [false, false], 0.0),
            body("plate", [false, true], THICKNESS),
        ],
        vec![Tie {
            body: 1,
            nodes: back,
        }],
        vec![PressureLoad {
            faces: back_faces,
            pressure,
            variation: Variation::Ramp,
        }]
        .into(),
        vec![ContactPair {
            name: "pad-ground".into(),
            nodes: front,
            body: 0,
            surface: Box::new(RigidPlane::new(Vector3::y(), Vector3::x()).expect("plane")),
            mu: 0.15,
        }],
    )
    .expect("model")
}

/// A static preload in 4 increments, then `settle` increments of 1e-4 s of HHT dynamics; the
/// final state. Asserts that no increment needed a cutback.
fn load(model: &Model<2>, regularization_time: f64, settle: usize) -> State {
    let mut steps = vec![Step {
        name: "preload".into(),
        kind: StepKind::Static {
            increments: StaticIncrements::Fixed(4),
            regularization_time,
        },
        held: vec![],
    }];
    if settle > 0 {
        steps.push(Step {
            name: "settle".into(),
            kind: StepKind::Dynamic {
                duration: 1e-4 * settle as f64,
                dt: 1e-4,
                alpha: -0.3,
                adaptive: None,
            },
            held: vec![],
        });
    }
    let mut last = Last(None);
    let (stats, result) = run(model, &steps, &Settings::default(), &mut last);
    let state = result.expect("the run completes");
    assert_eq!(stats.cutbacks, 0, "no cutbacks");
    state
}

#[test]
fn pad_pressed_beyond_its_shear_modulus_reaches_the_same_equilibrium() {
    let model = pad(HIGH_PRESSURE, D1);
    let plate = model.dofs().body_translation(1)[1].expect("plate y");
    let a = load(&model, 1e-2, 0);
    let b = load(&model, 1e-3, 0);
    // Equilibrium of the plate: the contact forces carry the whole load.
    let normal: f64 = a.contacts.iter().map(|c| c.normal_force).sum();
    let force = HIGH_PRESSURE * LENGTH * WIDTH;
    assert!((normal - force).abs() < 1e-6 * force, "{normal} vs {force}");
    // Strongly compressed, and the same state whatever the regularisation.
    assert!(a.x[plate] < -0.25 * THICKNESS, "plate {}", a.x[plate]);
    let scale = a.x.amax();
    assert!(
        (&a.x - &b.x).amax() < 1e-5 * scale,
        "{} vs {}",
        a.x[plate],
        b.x[plate]
    );
}

/// K/mu = 1e7 under the drum's pressure: the static preload runs without cutbacks and the nearly
/// incompressible pad settles to the same contact force, with J = 1 to 1e-6. (This static case
/// passes with the displacement tangent too; the dynamic case where that tangent turns
/// indefinite, and the mixed tangent is needed, is `skid-cases/tests/inputs/incompressible.rs`.)
#[test]
fn nearly_incompressible_pad_preloads_and_settles_without_cutbacks() {
    let pressure = 0.35e6;
    let model = pad(pressure, D1_LITERAL);
    let state = load(&model, 1e-2, 20);
    let normal: f64 = state.contacts.iter().map(|c| c.normal_force).sum();
    let force = pressure * LENGTH * WIDTH;
    assert!((normal - force).abs() < 0.05 * force, "{normal} vs {force}");
    let plate = model.dofs().body_translation(1)[1].expect("plate y");
    let compressible = load(&pad(pressure, D1), 1e-2, 0);
    // Incompressible: the pad squeezes out sideways instead of losing volume, so it gives less.
    assert!(state.x[plate] < 0.0 && state.x[plate] > compressible.x[plate]);
    let part = model.part();
    for (e, (element, nodes)) in model.elements().iter().zip(&part.mesh.elements).enumerate() {
        let u: Vec<_> = nodes
            .iter()
            .map(|&n| model.dofs().node_displacement(&state.x, n))
            .collect();
        let r = element.respond(part.material(e), &u).expect("element");
        assert!(
            (r.volume_ratio - 1.0).abs() < 1e-6,
            "J = {}",
            r.volume_ratio
        );
    }
}
