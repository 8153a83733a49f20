//! The model-file format: one JSON document, the serialization of [`ModelSpec`].
//!
//! Nodes and elements are numbered from 0 in the order they are listed; node sets and surfaces
//! refer to those numbers, and everything else refers to sets, surfaces and bodies by name.
//! Element corners follow the Abaqus order, which is also the solver's cell order: CPE4R
//! counter-clockwise; C3D8R four corners of one face, counter-clockwise seen from the opposite
//! face, then the opposite face's corners in the same order.

use std::collections::BTreeMap;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use skid_fem::element::Formulation;

use crate::schema::{
    AdaptiveSpec, HourglassControl, MaterialSpec, OutputSpec, SolverSpec, default_alpha,
    default_regularization_time, one,
};

/// Format version a model file must declare in `skid_model`.
pub const MODEL_FORMAT_VERSION: u32 = 1;

/// Whether text is a model file: JSON that declares `skid_model` (rather than a drum case
/// file); text that is not JSON is not, and is left to the parser that reads it to report.
pub fn declares_model(text: &str) -> bool {
    serde_json::from_str::<serde_json::Value>(text).is_ok_and(|v| v.get("skid_model").is_some())
}

/// A whole scene: deformable parts, rigid bodies, constraints, loads, contact, steps.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ModelSpec {
    /// Format version (1, the only one so far); its presence marks the file as a model file.
    pub skid_model: u32,
    /// Name of the model (default output directory `out/<name>`).
    pub name: String,
    /// Free text.
    #[serde(default)]
    pub description: String,
    /// 2 (plane strain) or 3.
    pub dimension: usize,
    /// The deformable part (the first, if `parts` names more).
    pub part: PartSpec,
    /// Further deformable parts, merged with `part` into the one mesh the solver integrates:
    /// their nodes and elements numbered after those before, their sets and surfaces named
    /// `<part>.<set>`, and the node and element set `<part>` holding all of theirs; their
    /// section's material and density become the material of the element set `<part>`, and
    /// its thickness, hourglass scale and quasi-static setting must be the first part's. A
    /// model as run holds the merged `part`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub parts: Vec<PartSpec>,
    /// Rigid bodies; each moves in all its degrees of freedom unless `boundary` fixes some.
    #[serde(default)]
    pub rigid_bodies: Vec<RigidBodySpec>,
    /// Boundary conditions held throughout the analysis.
    #[serde(default)]
    pub boundary: Vec<BoundarySpec>,
    /// Node sets tied to rigid bodies.
    #[serde(default)]
    pub ties: Vec<TieSpec>,
    /// Initial velocities of the part's nodes (rigid bodies give theirs in
    /// `rigid_bodies`); nodes not listed start at rest.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub initial_velocities: Vec<NodeVelocitySpec>,
    /// Loads. A load acts in every step at its value times its factor in the step
    /// (`step_factors`, 1 in every step if absent). A load with an `amplitude` is that
    /// amplitude's value at its time times the step's factor and its value: the step time is the
    /// time since the step began in a dynamic step, and in a static step (which takes no
    /// physical time) the completed fraction of the step times its time period (1 by default);
    /// the total time adds the time periods of the steps before (see [`AmplitudeTime`]). A load without
    /// amplitude goes linearly over a static step from its factor at the end of the previous
    /// step (0 before the first step) to the step's factor, and takes the step's factor at once
    /// in a dynamic step: without `step_factors` it is ramped from 0 to full value over the
    /// first step if that is static and held at full value after (from the start if the first
    /// step is dynamic).
    #[serde(default)]
    pub loads: Vec<LoadSpec>,
    /// Named amplitudes: piecewise-linear factors of the step or total time that loads and
    /// prescribed motions may name.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub amplitudes: Vec<AmplitudeSpec>,
    /// Contact pairs: nodes of the part against the surface of a rigid body.
    #[serde(default)]
    pub contact: Vec<ContactPairSpec>,
    /// Analysis steps, run in order.
    pub steps: Vec<ModelStepSpec>,
    /// Solver settings; every field is optional.
    #[serde(default)]
    pub solver: SolverSpec,
    /// Output settings; every field is optional.
    #[serde(default)]
    pub output: ModelOutputSpec,
}

impl ModelSpec {
    /// The `(node, axis)` components of the part that the boundary conditions hold at zero
    /// (node sets only; prescribed motions and rigid bodies left out).
    pub fn held_node_components(&self) -> Vec<(usize, usize)> {
        self.boundary
            .iter()
            .filter(|bc| !bc.is_prescribed())
            .filter_map(|bc| Some((bc, self.part.node_sets.get(bc.node_set.as_ref()?)?)))
            .flat_map(|(bc, nodes)| {
                bc.dofs
                    .iter()
                    .filter_map(|d| d.translation_axis())
                    .flat_map(move |axis| nodes.iter().map(move |&n| (n, axis)))
            })
            .collect()
    }
}

/// Output settings of a model; every field is optional.
#[derive(Clone, Debug, Default, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct ModelOutputSpec {
    /// Physical time between ParaView field frames in dynamic steps, s (written to
    /// `<out>/fields/`); frames are also written for the initial state, at the end of every
    /// static step and at the end of the run. Absent or null: no field output.
    pub field_interval: Option<f64>,
    /// Node sets of the part whose nodes' displacements go into `history.csv` in every
    /// increment: for each set `S`, in this order, and each of its nodes `n` (node number), in
    /// the set's order, the columns `S.n.u_x`, `S.n.u_y` (and `S.n.u_z` in 3D), m.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub history_nodes: Vec<String>,
}

impl From<OutputSpec> for ModelOutputSpec {
    /// A case file's output settings: its field interval, no node history.
    fn from(output: OutputSpec) -> Self {
        Self {
            field_interval: output.field_interval,
            history_nodes: Vec::new(),
        }
    }
}

/// The deformable part: a mesh of one-point elements with one section.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PartSpec {
    /// Name used in messages.
    pub name: String,
    /// Reference coordinates of the nodes, `dimension` numbers each, m.
    pub nodes: Vec<Vec<f64>>,
    /// Element blocks, each of one type; elements are numbered across blocks in order.
    pub elements: Vec<ElementBlockSpec>,
    /// Named node sets (node numbers).
    #[serde(default)]
    pub node_sets: BTreeMap<String, Vec<usize>>,
    /// Named surfaces: element faces given by their corner nodes, ordered so that the face's
    /// normal points out of its element (2D: the outward normal is the edge direction turned
    /// clockwise; 3D: counter-clockwise seen from outside).
    #[serde(default)]
    pub surfaces: BTreeMap<String, Vec<Vec<usize>>>,
    /// Named element sets (element numbers, counted across blocks), for gravity and materials.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub element_sets: BTreeMap<String, Vec<usize>>,
    /// Material and section of every element (but those of `materials`).
    pub section: SectionSpec,
    /// Materials of element sets: their elements take this material and density instead of
    /// the section's (the section's thickness, hourglass scale and quasi-static setting hold
    /// for every element); an element in two of these sets is refused.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub materials: Vec<SetMaterialSpec>,
}

/// The material and density of an element set of the part.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SetMaterialSpec {
    /// Element set (`part.element_sets`).
    pub element_set: String,
    /// Hyperelastic material.
    pub material: MaterialSpec,
    /// Mass density, kg/m^3.
    pub density: f64,
    /// Stiffness-proportional (Rayleigh) damping factor `beta`, s (see
    /// `part.section.stiffness_damping`).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub stiffness_damping: f64,
}

/// Whether a factor is 0 (left out when written).
fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

/// Element types of a deformable part: bilinear quads (plane strain, 2D) and trilinear hexes
/// (3D), in the formulations of [`Formulation`].
#[derive(Clone, Copy, Debug, Deserialize, Serialize, JsonSchema, PartialEq, Eq)]
pub enum ElementType {
    /// 4-node plane-strain quadrilateral, one-point integration with hourglass control (2D).
    #[serde(rename = "CPE4R")]
    Cpe4r,
    /// 4-node plane-strain quadrilateral, full (2 x 2) integration (2D).
    #[serde(rename = "CPE4")]
    Cpe4,
    /// 4-node plane-strain quadrilateral, full integration, constant-pressure hybrid (2D).
    #[serde(rename = "CPE4H")]
    Cpe4h,
    /// 4-node plane-strain quadrilateral, full integration with incompatible modes (2D).
    #[serde(rename = "CPE4I")]
    Cpe4i,
    /// 8-node hexahedron, one-point integration with hourglass control (3D).
    #[serde(rename = "C3D8R")]
    C3d8r,
    /// 8-node hexahedron, full (2 x 2 x 2) integration (3D).
    #[serde(rename = "C3D8")]
    C3d8,
    /// 8-node hexahedron, full integration, constant-pressure hybrid (3D).
    #[serde(rename = "C3D8H")]
    C3d8h,
    /// 8-node hexahedron, full integration with incompatible modes (3D).
    #[serde(rename = "C3D8I")]
    C3d8i,
}

impl ElementType {
    /// Dimension the element lives in.
    pub fn dimension(self) -> usize {
        match self {
            Self::Cpe4r | Self::Cpe4 | Self::Cpe4h | Self::Cpe4i => 2,
            Self::C3d8r | Self::C3d8 | Self::C3d8h | Self::C3d8i => 3,
        }
    }

    /// The element's formulation.
    pub fn formulation(self) -> Formulation {
        match self {
            Self::Cpe4r | Self::C3d8r => Formulation::Reduced,
            Self::Cpe4 | Self::C3d8 => Formulation::Full,
            Self::Cpe4h | Self::C3d8h => Formulation::Hybrid,
            Self::Cpe4i | Self::C3d8i => Formulation::Incompatible,
        }
    }

    /// The element type of `formulation` in dimension `dim` (2D for `dim = 2`, 3D otherwise).
    pub fn of(formulation: Formulation, dim: usize) -> Self {
        match (formulation, dim == 2) {
            (Formulation::Reduced, true) => Self::Cpe4r,
            (Formulation::Full, true) => Self::Cpe4,
            (Formulation::Hybrid, true) => Self::Cpe4h,
            (Formulation::Incompatible, true) => Self::Cpe4i,
            (Formulation::Reduced, false) => Self::C3d8r,
            (Formulation::Full, false) => Self::C3d8,
            (Formulation::Hybrid, false) => Self::C3d8h,
            (Formulation::Incompatible, false) => Self::C3d8i,
        }
    }

    /// The element type of a part's solid elements in dimension `dim` (the one-point
    /// element, skid's default).
    pub fn solid(dim: usize) -> Self {
        Self::of(Formulation::Reduced, dim)
    }

    /// The Abaqus name, `CPE4R` ... `C3D8I`.
    pub fn name(self) -> &'static str {
        self.formulation().abaqus_name(self.dimension())
    }
}

/// Elements of one type.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ElementBlockSpec {
    /// Element type.
    #[serde(rename = "type")]
    pub kind: ElementType,
    /// Corner nodes of each element.
    pub connectivity: Vec<Vec<usize>>,
}

/// The section of a part: its material and what the element formulation needs.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SectionSpec {
    /// Hyperelastic material.
    pub material: MaterialSpec,
    /// Mass density, kg/m^3.
    pub density: f64,
    /// Stiffness-proportional (Rayleigh) damping factor `beta`, s (Abaqus' `*DAMPING, BETA`):
    /// in dynamic steps each element adds the viscous force `beta K_T v`, `K_T` its tangent
    /// stiffness and `v` its nodal velocities, which damps a mode of frequency `omega` at the
    /// ratio `beta omega / 2`. A real rubber's loss factor of 0.1 is about `beta = 0.1 /
    /// omega` at the frequencies that matter. 0 (the default): no damping.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub stiffness_damping: f64,
    /// Out-of-plane thickness in 2D, m (must be 1 in 3D).
    #[serde(default = "one")]
    pub thickness: f64,
    /// Factor on the hourglass stabilisation stiffness of the one-point elements, with the
    /// `stiffness` hourglass control.
    #[serde(default = "one")]
    pub hourglass_scale: f64,
    /// Hourglass control of the one-point elements (CPE4R / C3D8R): `stiffness` (the default)
    /// or `enhanced`; `enhanced` needs at least one block of one-point elements and the
    /// default `hourglass_scale`.
    #[serde(default, skip_serializing_if = "HourglassControl::is_default")]
    pub hourglass: HourglassControl,
    /// No inertia: in dynamic steps the part is in equilibrium with the mean contact forces of
    /// each increment; rigid bodies tied to it must then be massless.
    #[serde(default)]
    pub quasi_static: bool,
    /// The lumped mass of the contact nodes (every slave node of a contact pair) moved to the
    /// other nodes of their elements: the contact nodes are then in equilibrium at the end of
    /// each dynamic increment, and their contact forces do not ring as the time step shrinks
    /// (the total mass is kept). Every element needs a node that is not a contact node.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub massless_contact_nodes: bool,
}

/// A rigid body: a reference node with a point mass and a rotary inertia, and optionally a
/// contact surface described in its body frame (origin at the reference node).
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RigidBodySpec {
    /// Name (boundary conditions, ties and contact pairs refer to it).
    pub name: String,
    /// Reference node, `dimension` coordinates, m.
    pub reference_point: Vec<f64>,
    /// Point mass, kg.
    #[serde(default)]
    pub mass: f64,
    /// Rotary inertia about the free rotation axis of a body turning about one axis, kg m^2.
    #[serde(default)]
    pub rotary_inertia: f64,
    /// Moments of inertia `[Ixx, Iyy, Izz]` about the global axes through the reference node
    /// at the start, kg m^2. A body free to turn about all three axes needs them; a body
    /// turning about one axis may take its moment from here instead of `rotary_inertia` (give
    /// one or the other).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub moments_of_inertia: Option<[f64; 3]>,
    /// Products of inertia `[Ixy, Ixz, Iyz]`, the off-diagonal components of the inertia tensor
    /// about the reference node at the start (`Ixy = -integral x y dm`), kg m^2 (absent: 0,
    /// the global axes are principal axes); only with `moments_of_inertia`. A body free to
    /// turn turns about its principal axes, the tensor's eigenvectors.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub products_of_inertia: Option<[f64; 3]>,
    /// Contact surface, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub surface: Option<RigidSurfaceSpec>,
    /// Initial velocity of the reference node, `dimension` components, m/s (absent: 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial_velocity: Option<Vec<f64>>,
    /// Initial angular velocity vector `[wx, wy, wz]`, rad/s (absent: 0); it must lie along the
    /// body's free rotation axis, or be any vector for a body free to turn about all three.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial_angular_velocity: Option<[f64; 3]>,
}

/// Rigid surfaces, in the body frame.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum RigidSurfaceSpec {
    /// The cylinder `|y - (e.y) e| = radius` about the axis `e` through the origin (in 2D the
    /// circle, `e = +z`).
    Cylinder {
        /// Radius, m.
        radius: f64,
        /// Axis direction.
        axis: [f64; 3],
    },
    /// The plane (2D: line) through the origin with outward `normal`; `tangent` gives the
    /// first in-plane direction of its surface coordinates.
    Plane {
        /// Outward normal.
        normal: [f64; 3],
        /// First in-plane direction.
        tangent: [f64; 3],
    },
    /// A regular polygon of `facets` sides inscribed in the circle of `radius`, extruded along
    /// `axis` (2D: the polygon of rigid lines); vertex `k` at the angle `phase + 2 pi k /
    /// facets` from the cylinder's reference direction (+x for the axis +z).
    FacetedCylinder {
        /// Circumscribed radius, m.
        radius: f64,
        /// Axis direction.
        axis: [f64; 3],
        /// Number of facets (>= 3).
        facets: usize,
        /// Angle of the first vertex, rad.
        phase: f64,
    },
    /// A chain of straight segments (2D: rigid line elements) and circular arcs through
    /// `points`, back to the first point if `closed`. Its outward normal is each piece's
    /// direction turned clockwise (a closed chain counter-clockwise is contacted from outside,
    /// clockwise from inside; a counter-clockwise arc from outside its circle); the surface
    /// coordinate is the arc length from the first point. An open chain's ends are the
    /// surface's edges: beyond them a point is off the surface, its gap the distance to the
    /// end point (positive on either side), so a node that slides past an end leaves it.
    Polyline {
        /// Points `[x, y]`, m.
        points: Vec<[f64; 2]>,
        /// The centre `[x, y]` of each piece that is a circular arc (under 180 degrees) from
        /// its point to the next, `null` for a straight piece (absent or empty: all straight).
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        centres: Vec<Option<[f64; 2]>>,
        /// Whether the last point joins the first.
        #[serde(default)]
        closed: bool,
    },
    /// An extruded profile (3D): the `profile` of points `(u, v)` in the plane through the origin
    /// spanned by `reference` (made perpendicular to `axis`, the `u` direction) and
    /// `axis x reference` (`v`), swept along `axis` without end (back to the first point if
    /// `closed`). Its outside is on the right walking along the profile with `u` to the right
    /// and `v` up; the surface coordinates are the profile's arc length and the position along
    /// `axis`. An open profile's ends are the surface's edges, as a polyline's.
    Extrusion {
        /// Sweep direction.
        axis: [f64; 3],
        /// First direction of the profile's plane.
        reference: [f64; 3],
        /// Profile points `[u, v]`, m.
        profile: Vec<[f64; 2]>,
        /// The centre `[u, v]` of each piece that is a circular arc (under 180 degrees) from
        /// its point to the next, `null` for a straight piece (absent or empty: all straight).
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        centres: Vec<Option<[f64; 2]>>,
        /// Whether the last point joins the first.
        #[serde(default)]
        closed: bool,
    },
    /// A surface of revolution (3D): the `profile` of points `(r, z)` (`r >= 0` the distance
    /// from `axis`, `z` the position along it; back to the first point if `closed`) revolved
    /// about `axis` through the origin. Its outside is on the right walking along the profile
    /// with `r` to the right and `z` up (the cylinder `r = R` is walked towards `+z`). The
    /// surface coordinates are the angle about the axis times `radius` and the profile's arc
    /// length, so that slip is a length where `r = radius`. An open profile's ends off the
    /// axis are the surface's edges, as a polyline's; an end on the axis is not (the surface
    /// closes there).
    Revolution {
        /// Axis direction.
        axis: [f64; 3],
        /// Profile points `[r, z]`, m.
        profile: Vec<[f64; 2]>,
        /// The centre `[r, z]` of each piece that is a circular arc (under 180 degrees) from
        /// its point to the next, `null` for a straight piece (absent or empty: all straight).
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        centres: Vec<Option<[f64; 2]>>,
        /// Whether the last point joins the first.
        #[serde(default)]
        closed: bool,
        /// Radius of the circumferential coordinate, m (absent: the profile's largest `r`); it
        /// labels contact points only: friction measures slip in lengths at every radius.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        radius: Option<f64>,
    },
    /// Triangles (3D), counter-clockwise seen from outside, with surface coordinates read on
    /// the `chart` at each closest point. An open mesh's boundary (edges of one triangle only)
    /// is the surface's edge: beyond it a point is off the surface, its gap the distance to the
    /// boundary (positive on either side).
    Triangles {
        /// Vertices, m.
        vertices: Vec<[f64; 3]>,
        /// Vertex numbers of each triangle.
        triangles: Vec<[usize; 3]>,
        /// The surface whose coordinates label the mesh's points.
        chart: ChartSpec,
    },
}

/// The surface coordinates of a triangle mesh: those of its closest point read on a cylinder or a
/// plane through the body origin. On a cylinder chart friction measures slip in these
/// coordinates, which are lengths on the mesh only where it lies on the cylinder (a faceted drum
/// up to the facets' chord, `1 - cos(pi / n)`, 1e-3 for 72 facets): each triangle must lie on a
/// cylinder about the chart's axis or across the axis (a drum's end), or the model is refused.
/// On a plane chart the
/// coordinates only label points, and slip is measured in lengths in the tangent plane at the
/// contact point where each increment starts, whatever the mesh's shape (any curved mesh, or a
/// chart plane sloped against the mesh).
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum ChartSpec {
    /// Arc length `radius * angle` about `axis` from the cylinder's reference direction, and the
    /// position along `axis`.
    Cylinder {
        /// Radius, m.
        radius: f64,
        /// Axis direction.
        axis: [f64; 3],
    },
    /// The positions along `tangent` and along `normal x tangent`.
    Plane {
        /// Normal of the chart plane.
        normal: [f64; 3],
        /// First in-plane direction.
        tangent: [f64; 3],
    },
}

/// Automatic increments of a static step, as fractions of the step (its time period is 1):
/// the first `initial`; after two increments in a row that converge within 4 Newton iterations
/// the size grows by 1.5, to at most `max`; a failed increment is cut back, and the step fails
/// rather than go below `min`; the last increment ends on the step's end.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct AutomaticIncrementsSpec {
    /// First size, in `[min, max]`.
    pub initial: f64,
    /// Smallest size, `> 0`.
    pub min: f64,
    /// Largest size, `<= 1`.
    pub max: f64,
}

/// A degree of freedom: translations `x`, `y`, `z`, rotations `rx`, `ry`, `rz`.
#[derive(
    Clone, Copy, Debug, Deserialize, Serialize, JsonSchema, PartialEq, Eq, PartialOrd, Ord,
)]
#[serde(rename_all = "lowercase")]
pub enum Dof {
    /// Translation along x.
    X,
    /// Translation along y.
    Y,
    /// Translation along z (3D).
    Z,
    /// Rotation about x (3D).
    Rx,
    /// Rotation about y (3D).
    Ry,
    /// Rotation about z.
    Rz,
}

impl Dof {
    /// Every degree of freedom of a rigid body in dimension `dim`.
    pub fn all(dim: usize) -> &'static [Dof] {
        if dim == 2 {
            &[Dof::X, Dof::Y, Dof::Rz]
        } else {
            &[Dof::X, Dof::Y, Dof::Z, Dof::Rx, Dof::Ry, Dof::Rz]
        }
    }

    /// Axis of a translation (`None` for a rotation).
    pub fn translation_axis(self) -> Option<usize> {
        match self {
            Dof::X => Some(0),
            Dof::Y => Some(1),
            Dof::Z => Some(2),
            _ => None,
        }
    }

    /// Axis of a rotation (`None` for a translation).
    pub fn rotation_axis(self) -> Option<usize> {
        match self {
            Dof::Rx => Some(0),
            Dof::Ry => Some(1),
            Dof::Rz => Some(2),
            _ => None,
        }
    }
}

/// Degrees of freedom of a rigid body's reference node, or of the nodes of a node set
/// (translations only), held at zero displacement or, with a `value`, moved as prescribed.
///
/// A prescribed degree of freedom is `value` times a factor (a displacement from the reference
/// configuration, m, or a rotation angle, rad) that varies exactly as a load's does (see
/// `loads`): its `amplitude` and `step_factors`, else the default ramp. Its reaction (the force
/// or moment that moves it) does work that the energy balance counts.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct BoundarySpec {
    /// Rigid body whose reference node is held (exactly one of `body` and `node_set`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body: Option<String>,
    /// Node set of the part whose nodes are held.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub node_set: Option<String>,
    /// The degrees of freedom held.
    pub dofs: Vec<Dof>,
    /// Full value of a prescribed motion of each degree of freedom, m or rad (absent: held at
    /// 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub value: Option<f64>,
    /// Amplitude of the prescribed motion, by name (`amplitudes`); only with `value`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub amplitude: Option<String>,
    /// The prescribed motion's factor in each step, as a load's; only with `value`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step_factors: Option<Vec<f64>>,
}

impl BoundarySpec {
    /// Whether the degrees of freedom move as prescribed rather than being held at 0.
    pub fn is_prescribed(&self) -> bool {
        self.value.is_some()
    }
}

/// The initial velocity of the nodes of a node set.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct NodeVelocitySpec {
    /// Node set of the part (its nodes must be free along every nonzero component and not tied
    /// to a rigid body).
    pub node_set: String,
    /// Velocity, `dimension` components, m/s.
    pub velocity: Vec<f64>,
}

/// Nodes that translate with a rigid body's reference node.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct TieSpec {
    /// Node set of the part.
    pub node_set: String,
    /// Rigid body.
    pub body: String,
}

/// Loads; `amplitude` names an entry of `amplitudes` (absent: the default ramp, see
/// `ModelSpec::loads`).
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum LoadSpec {
    /// A uniform follower pressure on a surface of the part (positive pushes into it), Pa.
    Pressure {
        /// Surface name.
        surface: String,
        /// Pressure, Pa.
        pressure: f64,
        /// Amplitude name.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        amplitude: Option<String>,
        /// Factor on the load in each step, one per step (absent: 1 in every step).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        step_factors: Option<Vec<f64>>,
    },
    /// A force fixed in direction and size on every node of a node set (each node receives
    /// the whole force), or a force and a moment on a rigid body's reference node.
    Concentrated {
        /// Node set of the part loaded (exactly one of `node_set` and `body`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        node_set: Option<String>,
        /// Rigid body whose reference node is loaded.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        body: Option<String>,
        /// Force, `dimension` components, N (absent: none).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        force: Option<Vec<f64>>,
        /// Moment on a rigid body `[mx, my, mz]`, N m (absent: none), fixed in the global
        /// frame; it must lie along the body's free rotation axis, or be any vector on a body
        /// free to turn.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        moment: Option<[f64; 3]>,
        /// Amplitude name.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        amplitude: Option<String>,
        /// Factor on the load in each step, one per step (absent: 1 in every step).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        step_factors: Option<Vec<f64>>,
    },
    /// A uniform body-force acceleration: the force `m g` on every lumped node mass of the
    /// loaded elements (`rho V / 2^D` per element corner, `V` counting the thickness in 2D),
    /// and on every rigid body's point mass when no element set is named.
    Gravity {
        /// Acceleration `g`, `dimension` components, m/s^2.
        acceleration: Vec<f64>,
        /// Element set of the part loaded (absent: the whole model, part and rigid bodies).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        element_set: Option<String>,
        /// Amplitude name.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        amplitude: Option<String>,
        /// Factor on the load in each step, one per step (absent: 1 in every step).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        step_factors: Option<Vec<f64>>,
    },
}

impl LoadSpec {
    /// The amplitude the load names, if any.
    pub fn amplitude(&self) -> Option<&str> {
        match self {
            Self::Pressure { amplitude, .. }
            | Self::Concentrated { amplitude, .. }
            | Self::Gravity { amplitude, .. } => amplitude.as_deref(),
        }
    }

    /// The load's factor in each step, if given.
    pub fn step_factors(&self) -> Option<&[f64]> {
        match self {
            Self::Pressure { step_factors, .. }
            | Self::Concentrated { step_factors, .. }
            | Self::Gravity { step_factors, .. } => step_factors.as_deref(),
        }
    }
}

/// A named amplitude: the factor `a(t)` of the loads that name it, linear between the points
/// `(t_k, a_k)` (times >= 0, strictly increasing, in the step time or the total time), `a_0`
/// before the first point and the last value after the last.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct AmplitudeSpec {
    /// Name (loads refer to it).
    pub name: String,
    /// Points `[time, factor]`: the time (see `time`) and the factor.
    pub points: Vec<[f64; 2]>,
    /// The time the points are read against.
    #[serde(default, skip_serializing_if = "AmplitudeTime::is_step")]
    pub time: AmplitudeTime,
}

/// The time an amplitude is read against.
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum AmplitudeTime {
    /// The step time, from 0 at each step's start: s in a dynamic step, and in a static step
    /// the completed fraction of the step times its time period (1 by default).
    #[default]
    Step,
    /// The total time: the step time plus the time periods of the steps before (a dynamic
    /// step's duration, a static step's time period), so that the amplitude runs on across
    /// steps.
    Total,
}

impl AmplitudeTime {
    /// Whether this is the step time (the default, left out of model files).
    pub fn is_step(&self) -> bool {
        *self == Self::Step
    }
}

/// Frictional contact between nodes of the part and a rigid body's surface.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ContactPairSpec {
    /// Name used in outputs and messages.
    pub name: String,
    /// Which nodes are contact candidates.
    pub slave: SlaveSpec,
    /// Rigid body whose surface is the master.
    pub master: String,
    /// Coulomb friction coefficient.
    pub mu: f64,
}

/// Contact candidates of a pair.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum SlaveSpec {
    /// The nodes of a node set.
    NodeSet {
        /// Node set name.
        name: String,
    },
    /// General contact: every node on a surface of the part whose initial distance to the
    /// master surface is below `search_distance`.
    General {
        /// Search distance, m.
        search_distance: f64,
    },
}

/// One analysis step; `boundary` adds rigid-body conditions held during this step only.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum ModelStepSpec {
    /// Static equilibrium with loads ramped to full value.
    Static {
        /// Step name.
        name: String,
        /// Number of equal increments (exactly one of `increments` and `automatic`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        increments: Option<usize>,
        /// Increments sized by Newton's effort (exactly one of `increments` and `automatic`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        automatic: Option<AutomaticIncrementsSpec>,
        /// Time scale of the Newton regularisation `M/h_s^2`, s.
        #[serde(default = "default_regularization_time")]
        regularization_time: f64,
        /// Time period of the step (1 if absent): a static step takes no physical time, but
        /// its amplitudes read the step time from 0 to this period as the step goes from start
        /// to end, and the total time advances by it.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        time_period: Option<f64>,
        /// How loads and prescribed motions without an amplitude vary over the step (absent:
        /// `ramp`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        default_amplitude: Option<DefaultAmplitude>,
        /// Rigid-body degrees of freedom held during the step (absent `dofs`: all).
        #[serde(default)]
        boundary: Vec<StepBoundarySpec>,
    },
    /// HHT-alpha dynamics.
    Dynamic {
        /// Step name.
        name: String,
        /// Duration, s.
        duration: f64,
        /// Time increment (the first one if adaptive), s.
        dt: f64,
        /// HHT alpha in [-1/3, 0].
        #[serde(default = "default_alpha")]
        alpha: f64,
        /// Rigid-body degrees of freedom held during the step.
        #[serde(default)]
        boundary: Vec<StepBoundarySpec>,
        /// Error-controlled increments (absent: `dt` throughout).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        adaptive: Option<AdaptiveSpec>,
        /// How loads and prescribed motions without an amplitude vary over the step (absent:
        /// `step`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        default_amplitude: Option<DefaultAmplitude>,
    },
}

impl ModelStepSpec {
    /// Whether loads and prescribed motions without an amplitude go linearly over the step from
    /// their value at the end of the previous one (a ramp), rather than take their value at
    /// once (a step): `default_amplitude`, or by default a ramp in a static step and a step in
    /// a dynamic one.
    pub fn ramps(&self) -> bool {
        match self {
            Self::Static {
                default_amplitude, ..
            } => *default_amplitude != Some(DefaultAmplitude::Step),
            Self::Dynamic {
                default_amplitude, ..
            } => *default_amplitude == Some(DefaultAmplitude::Ramp),
        }
    }

    /// Whether the step sets `default_amplitude` to something other than its procedure's
    /// default.
    pub fn departs_from_default_amplitude(&self) -> bool {
        match self {
            Self::Static { .. } => !self.ramps(),
            Self::Dynamic { .. } => self.ramps(),
        }
    }
}

/// How loads and prescribed motions without an amplitude vary over a step.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum DefaultAmplitude {
    /// Linearly over the step, from the value at the end of the previous step (0 before the
    /// first) to the step's.
    Ramp,
    /// The step's value at once, from the step's start.
    Step,
}

/// Degrees of freedom of a rigid body, or of every node of a node set, held at their value at
/// the start of a step.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct StepBoundarySpec {
    /// Rigid body (exactly one of `body` and `node_set`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body: Option<String>,
    /// Node set of the part (not tied to a rigid body).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub node_set: Option<String>,
    /// Degrees of freedom held (absent: every free one; translations only on nodes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dofs: Option<Vec<Dof>>,
}

/// The [`skid_contact::RigidPolyline`] of a spec's profile `points` (of a polyline, an extrusion or a
/// surface of revolution), piece `k` an arc about `centres[k]` where that is given.
///
/// # Errors
/// As [`skid_contact::RigidPolyline::with_arcs`].
pub fn profile_polyline(
    points: &[[f64; 2]],
    centres: &[Option<[f64; 2]>],
    closed: bool,
) -> Result<skid_contact::RigidPolyline, skid_contact::ContactError> {
    skid_contact::RigidPolyline::with_arcs(
        points.iter().map(|p| nalgebra::Vector2::from(*p)).collect(),
        centres
            .iter()
            .map(|c| c.map(nalgebra::Vector2::from))
            .collect(),
        closed,
    )
}
