//! Fixtures shared by the integration tests.

use nalgebra::SVector;
use skid_fem::hourglass::Hourglass;
use skid_fem::material::PolynomialN1;
use skid_fem::mesh::SolidMesh;
use skid_fem::rigid::{RigidBody, Rotation};
use skid_integrator::Section;
use skid_integrator::SolidPart;

/// A massless 2D rigid body at `(0, y)` that may translate along the axes marked in `free` and
/// never rotates: a held ground (`[false, false]`) or a loaded plate.
pub fn translating_body(name: &str, free: [bool; 2], y: f64) -> RigidBody<2> {
    RigidBody::<2> {
        name: name.into(),
        reference_point: SVector::<f64, 2>::new(0.0, y),
        mass: 0.0,
        rotary_inertia: 0.0,
        free_translations: free,
        rotation: Rotation::None,
        initial_velocity: SVector::zeros(),
        initial_angular_velocity: 0.0,
    }
}

/// A plane-strain block of the DRUM.md pad material (with bulk compliance `d1`) from `corner`,
/// `size` and `divisions` elements, out-of-plane `thickness`, density 1000 kg/m^3.
pub fn block_part(
    corner: [f64; 2],
    size: [f64; 2],
    divisions: [usize; 2],
    thickness: f64,
    d1: f64,
    quasi_static: bool,
) -> SolidPart<2> {
    let mesh = SolidMesh::<2>::structured_block(
        SVector::<f64, 2>::new(corner[0], corner[1]),
        SVector::<f64, 2>::new(size[0], size[1]),
        divisions,
    )
    .expect("mesh");
    SolidPart {
        name: "pad".into(),
        mesh,
        sections: vec![Section {
            material: Box::new(PolynomialN1::new(0.552e6, 0.138e6, d1).expect("material")),
            density: 1000.0,
            stiffness_damping: 0.0,
        }],
        element_sections: Vec::new(),
        thickness,
        hourglass: Hourglass::default(),
        element_formulations: Vec::new(),
        quasi_static,
        fixed: vec![],
    }
}
