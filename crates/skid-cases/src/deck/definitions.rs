//! What a deck defines, keeping its labels and names: the model data before the first `*STEP`
//! (mesh, surfaces, materials, sections, rigid bodies, boundary and initial conditions,
//! amplitudes, contact) and each step's history data (procedure, boundary changes, loads,
//! output requests). [`super::read`] fills them from the keyword blocks, [`super::loads`] and
//! [`super::controls`] the loads and section controls among them; [`super::assemble`] turns
//! them into a model.

use std::collections::HashMap;

use super::keywords::Location;
use super::mesh::Mesh;
use super::rigid::AnalyticalSurface;
use crate::model_spec::{AmplitudeTime, DefaultAmplitude};
use crate::schema::{HourglassControl, MaterialSpec};

/// A face of an element-based surface.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FaceLabel {
    /// Numbered face `S<k>` of a solid element.
    Numbered(usize),
    /// The positive side of a line, membrane, shell or rigid element.
    Positive,
    /// Its negative side.
    Negative,
    /// No face given: the exterior faces of solid elements, the positive side of others.
    Exterior,
}

/// A `*SURFACE`.
#[derive(Clone, Debug)]
pub enum SurfaceDef {
    /// Element faces: element label and face.
    Faces(Vec<(u64, FaceLabel)>),
    /// Nodes.
    Nodes(Vec<u64>),
    /// An analytical rigid surface.
    Analytical(AnalyticalSurface),
}

/// A named definition with its name as written and its keyword line.
#[derive(Clone, Debug)]
pub struct Named<T> {
    /// Name as written.
    pub name: String,
    /// The definition.
    pub value: T,
    /// Where it is defined.
    pub location: Location,
}

/// A `*MATERIAL` and its sub-options.
#[derive(Clone, Debug, Default)]
pub struct MaterialDef {
    /// Constitutive law.
    pub law: Option<MaterialSpec>,
    /// Mass density.
    pub density: Option<f64>,
    /// `*DAMPING, BETA`: the stiffness-proportional damping factor.
    pub stiffness_damping: Option<f64>,
}

/// Kinds of section.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SectionKind {
    /// `*SOLID SECTION`.
    Solid,
    /// `*MEMBRANE SECTION`.
    Membrane,
    /// `*SHELL SECTION`.
    Shell,
}

/// A section: element set, material, thickness.
#[derive(Clone, Debug)]
pub struct SectionDef {
    /// Kind.
    pub kind: SectionKind,
    /// Element set name.
    pub elset: String,
    /// Material name.
    pub material: String,
    /// Thickness (2D out-of-plane, membrane or shell).
    pub thickness: Option<f64>,
    /// `CONTROLS=`: the name of its `*SECTION CONTROLS` (solid sections).
    pub controls: Option<String>,
    /// Where.
    pub location: Location,
}

/// A `*RIGID BODY`.
#[derive(Clone, Debug)]
pub struct RigidDef {
    /// Reference node: its label and the name the body takes.
    pub reference: u64,
    /// Body name: the reference node set's name, or `body-<label>`.
    pub name: String,
    /// Element set made rigid.
    pub elset: Option<String>,
    /// Analytical surface carried.
    pub analytical: Option<String>,
    /// Node set of the part tied to the body.
    pub tie: Option<String>,
    /// Where.
    pub location: Location,
}

/// Degrees of freedom (1..=6) of a node or node set held at zero or, in a step, at a
/// magnitude (the total displacement or rotation from the reference configuration).
#[derive(Clone, Debug)]
pub struct BoundaryDef {
    /// Node label or node set name.
    pub target: String,
    /// Degrees of freedom 1..=6.
    pub dofs: Vec<usize>,
    /// The magnitude (0 unless given on a line with a first and last degree of freedom).
    pub magnitude: f64,
    /// The keyword's `AMPLITUDE=` (steps only).
    pub amplitude: Option<String>,
    /// Where.
    pub location: Location,
}

/// An initial condition.
#[derive(Clone, Debug)]
pub enum InitialDef {
    /// `TYPE=VELOCITY`: one component.
    Velocity {
        /// Node label or set.
        target: String,
        /// Degree of freedom 1..=6.
        dof: usize,
        /// Value.
        value: f64,
        /// Where.
        location: Location,
    },
    /// `TYPE=ROTATING VELOCITY`: `v = v0 + omega e x (x - a)`, `e = (b - a)/|b - a|`.
    Rotating {
        /// Node label or set.
        target: String,
        /// Angular speed.
        omega: f64,
        /// Translational velocity.
        velocity: [f64; 3],
        /// First axis point.
        a: [f64; 3],
        /// Second axis point.
        b: [f64; 3],
        /// Where.
        location: Location,
    },
}

/// Step procedures.
#[derive(Clone, Debug)]
pub enum Procedure {
    /// `*STATIC`: `initial` increment over `period`; with `DIRECT` fixed, without it automatic
    /// between `[min, max]`.
    Static {
        /// Increment (the first one if automatic).
        initial: f64,
        /// Step period.
        period: f64,
        /// Smallest and largest increment of automatic incrementation (`None`: `DIRECT`).
        automatic: Option<[f64; 2]>,
    },
    /// `*DYNAMIC`: `dt` over `period`; with `DIRECT` fixed, without it error-controlled
    /// between `[min, max]` (see [`super::read::AUTOMATIC_DYNAMIC_TOLERANCE`]).
    Dynamic {
        /// Time increment (the first one if automatic).
        dt: f64,
        /// Duration.
        period: f64,
        /// HHT alpha.
        alpha: f64,
        /// Smallest and largest increment of automatic incrementation (`None`: `DIRECT`).
        automatic: Option<[f64; 2]>,
    },
}

/// Changes of a step: boundary conditions or loads, with `OP=NEW` (replace) or `OP=MOD`.
#[derive(Clone, Debug)]
pub struct Change<T> {
    /// `OP=NEW`.
    pub replace: bool,
    /// Definitions.
    pub items: Vec<T>,
}

/// A `*STEP ... *END STEP`.
#[derive(Clone, Debug)]
pub struct StepDef {
    /// Step name.
    pub name: String,
    /// Where the `*STEP` line is.
    pub location: Location,
    /// Procedure with its keyword line.
    pub procedure: Option<(Procedure, Location)>,
    /// Boundary-condition changes in order.
    pub boundary: Vec<Change<BoundaryDef>>,
    /// Load changes in order.
    pub loads: Vec<LoadChange>,
    /// `NLGEOM` as given (`None`: absent).
    pub nlgeom: Option<bool>,
    /// `AMPLITUDE=RAMP|STEP` as given (`None`: absent, the procedure's default).
    pub default_amplitude: Option<DefaultAmplitude>,
    /// The step's `*OUTPUT, FIELD` requests that give an interval.
    pub field_output: Vec<FieldRequest>,
    /// Whether the step's latest `*OUTPUT` is `HISTORY`, so that a `*NODE OUTPUT` after it
    /// asks for history output.
    pub history_output: bool,
    /// The node sets (`NSET=` as given, with the keyword line) of the step's `*NODE OUTPUT`
    /// requests under `*OUTPUT, HISTORY` that ask for `U` or one of its components.
    pub history_nodes: Vec<(String, Location)>,
}

/// When an `*OUTPUT, FIELD` request asks for frames: every `TIME INTERVAL`, or at `NUMBER
/// INTERVAL` equal divisions of the step's time period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FieldRequest {
    /// `TIME INTERVAL=t`, s.
    Time(f64),
    /// `NUMBER INTERVAL=n`.
    Number(u64),
}

/// General contact: `*CONTACT` with its inclusions and property assignment.
#[derive(Clone, Debug)]
pub struct GeneralContactDef {
    /// `*CONTACT INCLUSIONS, ALL EXTERIOR` given.
    pub all_exterior: bool,
    /// Interaction assigned to all pairs.
    pub interaction: Option<String>,
    /// Where `*CONTACT` is.
    pub location: Location,
}

/// Everything a deck defines, by kind, with its names and lines.
#[derive(Debug, Default)]
pub struct Definitions {
    /// Text of `*HEADING`.
    pub heading: String,
    /// Nodes, elements, sets.
    pub mesh: Mesh,
    /// Surfaces by key.
    pub surfaces: HashMap<String, Named<SurfaceDef>>,
    /// Materials by key.
    pub materials: HashMap<String, Named<MaterialDef>>,
    /// Sections in order.
    pub sections: Vec<SectionDef>,
    /// `*SECTION CONTROLS` by key: their hourglass controls.
    pub section_controls: HashMap<String, Named<HourglassControl>>,
    /// Rigid bodies in order.
    pub rigid_bodies: Vec<RigidDef>,
    /// `*MASS`: element set and mass.
    pub masses: Vec<(String, f64, Location)>,
    /// `*ROTARY INERTIA`: element set and `I11, I22, I33, I12, I13, I23`.
    pub inertias: Vec<(String, [f64; 6], Location)>,
    /// Surface interactions by key: friction coefficient (0 without `*FRICTION`).
    pub interactions: HashMap<String, Named<f64>>,
    /// `*CONTACT PAIR` lines: interaction, slave surface, master surface.
    pub pairs: Vec<(String, String, String, Location)>,
    /// `*CONTACT`.
    pub general: Option<GeneralContactDef>,
    /// Model-data boundary conditions.
    pub boundary: Vec<BoundaryDef>,
    /// Initial conditions.
    pub initial: Vec<InitialDef>,
    /// Amplitudes by key.
    pub amplitudes: HashMap<String, Named<AmplitudeDef>>,
    /// Steps in order.
    pub steps: Vec<StepDef>,
    /// What skid reads differently from the deck's request, one line each with its location.
    pub notes: Vec<String>,
}

/// A distributed pressure: on a surface (`*DSLOAD`) or on face `k` of elements (`*DLOAD`).
#[derive(Clone, Debug)]
pub struct PressureDef {
    /// Surface name (`*DSLOAD`) or element label or set (`*DLOAD`).
    pub target: String,
    /// Face of `*DLOAD, Pk` (`None` for a surface).
    pub face: Option<usize>,
    /// Pressure.
    pub magnitude: f64,
    /// Where.
    pub location: Location,
}

/// A `*CLOAD` line: one component on a node, a node set or a reference node.
#[derive(Clone, Debug)]
pub struct ConcentratedDef {
    /// Node label or node set name.
    pub target: String,
    /// Degree of freedom 1..=6.
    pub dof: usize,
    /// Force or moment.
    pub magnitude: f64,
    /// Where.
    pub location: Location,
}

/// A `*DLOAD, GRAV` line.
#[derive(Clone, Debug)]
pub struct GravityDef {
    /// Element label or set (`None`: the whole model).
    pub target: Option<String>,
    /// Acceleration vector `d (g / |d|)` for the magnitude `g` and the direction `d` as given
    /// (so that a direction given as the acceleration itself, with its norm as the magnitude,
    /// reads back to its bits), m/s^2.
    pub acceleration: [f64; 3],
    /// Where.
    pub location: Location,
}

/// What a load line defines.
#[derive(Clone, Debug)]
pub enum LoadKind {
    /// A pressure.
    Pressure(PressureDef),
    /// A concentrated force or moment component.
    Concentrated(ConcentratedDef),
    /// Gravity.
    Gravity(GravityDef),
}

/// A load line with the amplitude of its keyword.
#[derive(Clone, Debug)]
pub struct LoadDef {
    /// The load.
    pub kind: LoadKind,
    /// `AMPLITUDE=` of its keyword, as written.
    pub amplitude: Option<String>,
}

/// The loads of one keyword block of a step.
#[derive(Clone, Debug)]
pub struct LoadChange {
    /// The keyword (`CLOAD`, `DLOAD` or `DSLOAD`).
    pub keyword: &'static str,
    /// `OP=NEW`: the block replaces the loads of earlier steps given with its keyword.
    pub replace: bool,
    /// Its loads.
    pub items: Vec<LoadDef>,
}

/// A `*AMPLITUDE` table: `(time, factor)` points, and the time they are read against.
#[derive(Clone, Debug)]
pub struct AmplitudeDef {
    /// The points.
    pub points: Vec<(f64, f64)>,
    /// `TIME=STEP TIME` (the default) or `TIME=TOTAL TIME`.
    pub time: AmplitudeTime,
}
