//! Small scenes shared by the unit tests.

use crate::model::Section;
use nalgebra::{DVector, SVector, Vector2, Vector3};
use skid_fem::hourglass::Hourglass;
use skid_fem::material::PolynomialN1;
use skid_fem::mesh::SolidMesh;
use skid_fem::rigid::{RigidBody, Rotation};

use skid_contact::surface::{AnalyticCylinder, RigidSurface};
use skid_contact::{FacetedCylinder, SurfacePoint};

use crate::loads::Loads;
use crate::model::{ContactPair, Model, SolidPart};

/// A structured block of the benchmark pad material (first D entries of each array are used).
pub(crate) fn pad_block<const D: usize>(
    corner: [f64; 3],
    size: [f64; 3],
    divisions: [usize; 3],
) -> SolidPart<D> {
    let mesh = SolidMesh::<D>::structured_block(
        SVector::from_fn(|i, _| corner[i]),
        SVector::from_fn(|i, _| size[i]),
        std::array::from_fn(|i| divisions[i]),
    )
    .expect("mesh");
    SolidPart {
        name: "pad".into(),
        mesh,
        sections: vec![Section {
            material: Box::new(PolynomialN1::new(0.552e6, 0.138e6, 0.145e-6).expect("material")),
            density: 1000.0,
            stiffness_damping: 0.0,
        }],
        element_sections: Vec::new(),
        thickness: 0.1,
        hourglass: Hourglass::default(),
        element_formulations: Vec::new(),
        quasi_static: false,
        fixed: vec![],
    }
}

/// A rigid body at the origin, at rest, with the given free translations and rotation.
pub(crate) fn body<const D: usize>(
    name: &str,
    free_translations: [bool; D],
    rotation: Rotation,
    mass: f64,
    rotary_inertia: f64,
) -> RigidBody<D> {
    RigidBody {
        name: name.into(),
        reference_point: SVector::zeros(),
        mass,
        rotary_inertia,
        free_translations,
        rotation,
        initial_velocity: SVector::zeros(),
        initial_angular_velocity: 0.0,
    }
}

/// A block above a drum of radius 0.2 that spins about z and may also translate in x.
pub(crate) fn block_on_drum<const D: usize>() -> Model<D> {
    block_on_turning_drum(Rotation::Axis(Vector3::z()))
}

/// [`block_on_drum`] with the drum free to turn about all three axes (3D).
pub(crate) fn block_on_free_drum() -> Model<3> {
    block_on_turning_drum(Rotation::Free {
        principal_inertia: Vector3::new(0.1, 0.1, 0.175),
        principal_axes: nalgebra::Rotation3::identity(),
        initial_angular_velocity: Vector3::zeros(),
    })
}

/// [`block_on_drum`] against a drum of 72 flat facets.
pub(crate) fn block_on_faceted_drum<const D: usize>() -> Model<D> {
    let facets = FacetedCylinder::new(0.2, Vector3::z(), 72, 0.0).expect("surface");
    block_on_surface(Rotation::Axis(Vector3::z()), Box::new(facets))
}

fn block_on_turning_drum<const D: usize>(rotation: Rotation) -> Model<D> {
    let cylinder = AnalyticCylinder::new(0.2, Vector3::z()).expect("surface");
    block_on_surface(rotation, Box::new(cylinder))
}

fn block_on_surface<const D: usize>(
    rotation: Rotation,
    surface: Box<dyn RigidSurface>,
) -> Model<D> {
    let part = pad_block::<D>([-0.05, 0.2, -0.05], [0.1, 0.05, 0.1], [4, 1, 2]);
    let front = part.mesh.node_sets["ymin"].clone();
    let mut free = [false; D];
    free[0] = true;
    let drum = body::<D>("drum", free, rotation, 5.0, 0.175);
    let pair = ContactPair {
        name: "pad-drum".into(),
        nodes: front,
        body: 0,
        surface,
        mu: 0.15,
    };
    Model::new(part, vec![drum], vec![], Loads::default(), vec![pair]).expect("model")
}

/// One slip origin per contact candidate at the surface coordinates' origin, for drums whose
/// slip reads their coordinates only (the position and normal are NaN, so that any other use
/// shows).
pub(crate) fn coordinate_origins<const D: usize>(model: &Model<D>) -> Vec<SurfacePoint> {
    let unknown = Vector3::repeat(f64::NAN);
    let origin = SurfacePoint {
        coords: Vector2::zeros(),
        position: unknown,
        normal: unknown,
    };
    let candidates = model.contacts().iter().map(|p| p.nodes.len()).sum();
    vec![origin; candidates]
}

/// The central difference of `f` along unknown `j` at `x`:
/// `(f(x + eps e_j) - f(x - eps e_j)) / (2 eps)`, a column of its Jacobian.
pub(crate) fn central_difference(
    x: &DVector<f64>,
    j: usize,
    eps: f64,
    mut f: impl FnMut(&DVector<f64>) -> DVector<f64>,
) -> DVector<f64> {
    let mut plus = x.clone();
    let mut minus = x.clone();
    plus[j] += eps;
    minus[j] -= eps;
    (f(&plus) - f(&minus)) / (2.0 * eps)
}
