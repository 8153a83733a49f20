//! Frictional contact for `skid`: rigid surfaces, gap and slip kinematics against a rotating rigid
//! body, and the exact Coulomb friction problem.
//!
//! * [`surface`]: rigid surfaces described in the body frame of their rigid body, with closest-point
//!   projections giving the signed gap and convected (arc-length, axial) coordinates.
//! * [`plane`]: the analytical rigid plane (a line in 2D).
//! * [`polyline`]: the rigid polyline in 2D (rigid line elements in a chain, open or closed).
//! * [`revolution`]: a profile of straight segments revolved about an axis (3D).
//! * [`extrusion`]: a profile of straight segments swept along an axis (3D).
//! * [`facets`]: the faceted cylinder (rigid line, quad, membrane or shell facets of a drum).
//! * [`triangles`]: triangulated surfaces (exterior faces of a tetrahedral drum).
//! * `search`: the closest-piece search of the polyline's and the triangles' R*-trees.
//! * [`kinematics`]: gap, convected coordinates and their exact first derivatives for a slave node
//!   against a surface carried by a body rotating about a fixed axis; slip increments unwrapped
//!   across periodic coordinates.
//! * [`coulomb`]: the exact (De Saxcé bipotential) Coulomb law in Delassus form,
//!   `K*_mu ∋ u + mu ||u_T|| e_N ⊥ r ∈ K_mu` with `u = W r + q`, solved as a fixed point on the normal
//!   shift over convex second-order-cone programs (clarabel). Unlike the plain convex relaxation,
//!   sliding contacts do not dilate (`u_N = 0`).

pub mod coulomb;
pub mod error;
pub mod extrusion;
pub mod facets;
pub mod kinematics;
pub mod plane;
pub mod polyline;
pub mod revolution;
mod search;
pub mod surface;
pub mod triangles;

pub use coulomb::{
    CoulombSettings, CoulombSolution, FrictionProblem, natural_map_error, natural_map_length_error,
    solve_coulomb,
};
pub use error::ContactError;
pub use extrusion::RigidExtrusion;
pub use facets::FacetedCylinder;
pub use kinematics::{
    ContactKinematics, IncrementStart, MAX_COLUMN_LEVER, MIN_SECANT_TURN, RotatingFrame, evaluate,
    gap_discrete_gradient, rotation_column,
};
pub use plane::RigidPlane;
pub use polyline::RigidPolyline;
pub use revolution::RigidRevolution;
pub use surface::{
    AnalyticCylinder, DiscreteGradient, Projection, RigidSurface, Slip, SurfacePoint, SurfaceShape,
    unwrapped_increment,
};
pub use triangles::{CylinderChart, SurfaceChart, TriangulatedSurface};
