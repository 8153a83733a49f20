//! No volumetric locking: a plane-strain cantilever of one-point elements under a uniform load
//! bends as beam theory says, for a compressible and a nearly incompressible material alike.

use nalgebra::SVector;
use skid_fem::hourglass::Hourglass;
use skid_fem::material::PolynomialN1;
use skid_fem::mesh::SolidMesh;
use skid_fem::rigid::{RigidBody, Rotation};
use skid_integrator::Section;
use skid_integrator::settings::Settings;
use skid_integrator::stepper::{IncrementReport, Observer, StaticIncrements, Step, StepKind, run};
use skid_integrator::{Model, PressureLoad, SolidPart, State, Tie, Variation};

const LENGTH: f64 = 0.1;
const HEIGHT: f64 = 0.01;
const THICKNESS: f64 = 0.01;
const MU: f64 = 1e6;
const PRESSURE: f64 = 100.0;

struct Last(Option<State>);

impl<const D: usize> Observer<D> for Last {
    fn on_increment(&mut self, _: &Model<D>, r: &IncrementReport<'_>) -> std::io::Result<()> {
        self.0 = Some(r.state.clone());
        Ok(())
    }
}

/// Tip deflection of the cantilever (clamped at x = 0, pressure on top) for bulk modulus
/// `k_over_mu` times the shear modulus.
fn tip_deflection(k_over_mu: f64) -> f64 {
    let mesh = SolidMesh::<2>::structured_block(
        SVector::<f64, 2>::zeros(),
        SVector::<f64, 2>::new(LENGTH, HEIGHT),
        [40, 4],
    )
    .expect("mesh");
    let clamped = mesh.node_sets["xmin"].clone();
    let top = mesh.surfaces["ymax"].clone();
    let tip = *mesh.node_sets["xmax"].get(2).expect("mid-height tip node");
    let material = PolynomialN1::new(MU / 2.0, 0.0, 2.0 / (k_over_mu * MU)).expect("material");
    let part = SolidPart {
        name: "block".into(),
        mesh,
        sections: vec![Section {
            material: Box::new(material),
            density: 1000.0,
            stiffness_damping: 0.0,
        }],
        element_sections: Vec::new(),
        thickness: THICKNESS,
        hourglass: Hourglass::default(),
        element_formulations: Vec::new(),
        quasi_static: false,
        fixed: vec![],
    };
    let wall = RigidBody::<2> {
        name: "wall".into(),
        reference_point: SVector::zeros(),
        mass: 0.0,
        rotary_inertia: 0.0,
        free_translations: [false, false],
        rotation: Rotation::None,
        initial_velocity: SVector::zeros(),
        initial_angular_velocity: 0.0,
    };
    let model = Model::new(
        part,
        vec![wall],
        vec![Tie {
            body: 0,
            nodes: clamped,
        }],
        vec![PressureLoad {
            faces: top,
            pressure: PRESSURE,
            variation: Variation::Ramp,
        }]
        .into(),
        vec![],
    )
    .expect("model");
    let steps = [Step {
        name: "load".into(),
        kind: StepKind::Static {
            increments: StaticIncrements::Fixed(1),
            regularization_time: 1.0,
        },
        held: vec![],
    }];
    let mut last = Last(None);
    let (_, result) = run(&model, &steps, &Settings::default(), &mut last);
    let state = result.expect("static solve converges");
    -model.dofs().node_displacement(&state.x, tip)[1]
}

/// Plane-strain Timoshenko cantilever under a uniform load w: bending `w L^4 / (8 E' I)` plus
/// shear `w L^2 / (2 kappa mu A)`, with `E' = E / (1 - nu^2)` and `kappa = 5/6`.
fn beam_theory(k_over_mu: f64) -> f64 {
    let nu = (3.0 * k_over_mu - 2.0) / (2.0 * (3.0 * k_over_mu + 1.0));
    let e_plane = 2.0 * MU * (1.0 + nu) / (1.0 - nu * nu);
    let w = PRESSURE * THICKNESS;
    let inertia = THICKNESS * HEIGHT.powi(3) / 12.0;
    let area = THICKNESS * HEIGHT;
    w * LENGTH.powi(4) / (8.0 * e_plane * inertia)
        + w * LENGTH.powi(2) / (2.0 * 5.0 / 6.0 * MU * area)
}

#[test]
fn nearly_incompressible_cantilever_does_not_lock() {
    let compressible = tip_deflection(13.0 / 6.0); // nu = 0.3
    let incompressible = tip_deflection(1e4); // nu = 0.49995
    for (k, measured) in [(13.0 / 6.0, compressible), (1e4, incompressible)] {
        let theory = beam_theory(k);
        assert!(
            (measured - theory).abs() < 0.05 * theory,
            "K/mu = {k}: tip deflection {measured:e} vs beam theory {theory:e}"
        );
    }
    // Beam theory: the deflection scales with 1 - nu (plane strain, fixed shear modulus). A
    // locking element would make the nearly incompressible beam far stiffer than that.
    let ratio = incompressible / compressible;
    let expected = beam_theory(1e4) / beam_theory(13.0 / 6.0);
    assert!(
        (ratio - expected).abs() < 0.03 * expected,
        "{ratio} vs {expected}"
    );
}
