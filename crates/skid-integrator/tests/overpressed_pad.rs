//! A pad pressed onto a rigid flat by more than its shear modulus: its tangent without the
//! contacts is indefinite (the free front face may shear and tilt at negative stiffness under
//! the compressive stress), yet the pad held by the contact is in stable equilibrium. The static
//! preload must find that equilibrium, and the equilibrium must not depend on the Newton
//! matrix's mass regularisation.

use nalgebra::{SVector, Vector3};
use skid_contact::plane::RigidPlane;
use skid_fem::material::PolynomialN1;
use skid_fem::mesh::SolidMesh;
use skid_fem::rigid::RigidBody;
use skid_integrator::stepper::{IncrementReport, Observer, Settings, Step, StepKind, run};
use skid_integrator::{ContactPair, Model, PressureLoad, SolidPart, State, Tie};

const LENGTH: f64 = 0.1;
const THICKNESS: f64 = 0.05;
const WIDTH: f64 = 0.1;
/// 2.5 times the shear modulus 1.38 MPa of the pad material.
const PRESSURE: f64 = 3.5e6;

struct Last(Option<State>);

impl<const D: usize> Observer<D> for Last {
    fn on_increment(&mut self, _: &Model<D>, r: &IncrementReport<'_>) -> std::io::Result<()> {
        self.0 = Some(r.state.clone());
        Ok(())
    }
}

/// The pad (4 x 1 plane-strain elements) on the plane y = 0, its back face tied to a plate that
/// may only translate in y and loaded by the pressure.
fn pad() -> Model<2> {
    let mesh = SolidMesh::<2>::structured_block(
        SVector::<f64, 2>::new(-0.5 * LENGTH, 0.0),
        SVector::<f64, 2>::new(LENGTH, THICKNESS),
        [4, 1],
    )
    .expect("mesh");
    let front = mesh.node_sets["ymin"].clone();
    let back = mesh.node_sets["ymax"].clone();
    let back_faces = mesh.surfaces["ymax"].clone();
    let part = SolidPart {
        mesh,
        material: Box::new(PolynomialN1::new(0.552e6, 0.138e6, 0.145e-6).expect("material")),
        density: 1000.0,
        thickness: WIDTH,
        hourglass_scale: 1.0,
    };
    let body = |name: &str, free: [bool; 2], y: f64| RigidBody::<2> {
        name: name.into(),
        reference_point: SVector::<f64, 2>::new(0.0, y),
        mass: 0.0,
        rotary_inertia: 0.0,
        free_translations: free,
        rotation_axis: None,
        initial_velocity: SVector::zeros(),
        initial_angular_velocity: 0.0,
    };
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
            pressure: PRESSURE,
        }],
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

fn preload(model: &Model<2>, regularization_time: f64) -> State {
    let steps = [Step {
        name: "preload".into(),
        kind: StepKind::Static {
            increments: 4,
            regularization_time,
        },
        held_bodies: vec![],
    }];
    let mut last = Last(None);
    let (stats, result) = run(model, &steps, &Settings::default(), &mut last);
    let state = result.expect("the preload converges");
    assert_eq!(stats.cutbacks, 0, "no cutbacks");
    state
}

#[test]
fn pad_pressed_beyond_its_shear_modulus_reaches_the_same_equilibrium() {
    let model = pad();
    let plate = model.dofs().body_translation(1)[1].expect("plate y");
    let a = preload(&model, 1e-2);
    let b = preload(&model, 1e-3);
    // Equilibrium of the plate: the contact forces carry the whole load.
    let normal: f64 = a.contacts.iter().map(|c| c.normal_force).sum();
    let load = PRESSURE * LENGTH * WIDTH;
    assert!((normal - load).abs() < 1e-6 * load, "{normal} vs {load}");
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
