//! Finite-element kernels of skid, an implicit solver for frictional contact.
//!
//! * [`material`]: hyperelastic laws in Kirchhoff-stress form with their spatial tangents
//!   ([`PolynomialN1`]: Mooney-Rivlin deviatoric part plus the Abaqus volumetric term).
//! * [`cell`]: the multilinear reference quad/hex (corner order, shape functions, Gauss rule,
//!   hourglass base vectors, reference geometry).
//! * [`solid`]: the one-point solid element with hourglass control ([`OnePointSolid`]), one
//!   code path for 2D plane strain (D = 2) and 3D (D = 3).
//! * [`hourglass`]: its hourglass controls ([`Hourglass`]): the Flanagan-Belytschko stiffness
//!   and the enhanced control, the incompatible-mode element's stiffness of the hourglass
//!   modes.
//! * [`integrated`]: fully integrated solid elements ([`IntegratedSolid`], 2^D Gauss points) in
//!   three [`Technology`]s: displacement (CPE4/C3D8), hybrid constant pressure (CPE4H/C3D8H),
//!   incompatible modes (CPE4I/C3D8I).
//! * [`element`]: a solid element of any [`Formulation`] ([`SolidElement`]: reduced or fully
//!   integrated).
//! * `kinematics` (crate-internal): deformation gradients, the corner inversion check and
//!   the node-pair stiffness blocks shared by the solid elements.
//! * [`pressure`]: follower pressure on element faces.
//! * [`mesh`]: solid meshes with node sets and surfaces ([`SolidMesh`]).
//! * [`ordering`]: a fill-reducing order of a mesh's nodes (nested dissection).
//! * [`tetra`]: tetrahedral meshes (the C3D4 drum) and their exterior faces.
//! * [`rigid`]: rigid bodies (reference node with point mass and rotary inertia).
//!
//! All kernels work in SI units and report failures as [`FemError`].

pub mod cell;
pub mod element;
pub mod error;
pub mod hourglass;
pub mod integrated;
mod kinematics;
pub mod material;
pub mod mesh;
pub mod ordering;
pub mod pressure;
mod response;
pub mod rigid;
pub mod solid;
#[cfg(test)]
mod test_fixtures;
pub mod tetra;

pub use element::{Formulation, SolidElement};
pub use error::FemError;
pub use hourglass::Hourglass;
pub use integrated::{IntegratedSolid, Technology};
pub use material::{Hyperelastic, PolynomialN1, SpatialTangent};
pub use mesh::SolidMesh;
pub use pressure::pressure_face_forces;
pub use rigid::RigidBody;
pub use solid::{ElementResponse, OnePointSolid, Tangent};
