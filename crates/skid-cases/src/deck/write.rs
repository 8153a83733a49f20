//! A model written as a deck of the keyword subset, which [`super::read_model`] reads back to
//! the same scene: the part with its sets and surfaces, each rigid body as a reference node with
//! its point mass and inertia and its surface (analytical, or the rigid elements the caller
//! gives for faceted and triangulated surfaces), contact, boundary and initial conditions, and
//! the steps, with the field interval as an `*OUTPUT, FIELD, TIME INTERVAL=` request and the
//! history nodes as `*NODE OUTPUT, NSET=` requests of `U` under `*OUTPUT, HISTORY`, the
//! enhanced hourglass control as a `*SECTION CONTROLS` that every `*SOLID SECTION` names.
//! Numbers are written so that they read back to the same bits.
//!
//! Two settings have no keyword and are refused: a static step's regularisation time other
//! than the default, and an adaptive dynamic step's tolerance other than that of `*DYNAMIC`
//! without `DIRECT`; loads that change between steps are refused too
//! (prescribed motions of rigid bodies and node sets are written in every step, at their value
//! times the step's factor). General contact is written as `*CONTACT` with
//! all exterior faces, so its search distance is not kept (every exterior node becomes a
//! candidate).

use std::collections::{BTreeMap, HashMap};
use std::fmt::Write as _;

use nalgebra::Vector3;
use skid_contact::surface::AnalyticCylinder;
use skid_fem::element::Formulation;
use skid_fem::tetra::TetMesh;

use super::mesh::ElementKind;
use super::read::AUTOMATIC_DYNAMIC_TOLERANCE;
use crate::model_spec::profile_polyline;
use crate::model_spec::{
    AmplitudeTime, BoundarySpec, DefaultAmplitude, Dof, LoadSpec, ModelSpec, ModelStepSpec,
    RigidBodySpec, RigidSurfaceSpec, SlaveSpec,
};
use crate::schema::{HourglassControl, MaterialSpec, default_regularization_time};

/// Rigid elements that carry a rigid body's faceted or triangulated surface in a deck.
#[derive(Clone, Debug)]
pub enum RigidElements {
    /// The facets of a faceted cylinder as elements of `kind` (R2D2 in 2D; R3D4, M3D4R or S4R
    /// in 3D) spanning `axial_range` along the axis (3D).
    Facets {
        /// Element type.
        kind: ElementKind,
        /// Axial extent of the quadrilaterals, body frame (ignored in 2D).
        axial_range: [f64; 2],
    },
    /// A tetrahedral mesh (C3D4) in the body frame whose exterior faces are the surface.
    Tetrahedra(TetMesh),
}

/// Numbers as written: the shortest text that reads back to the same bits.
fn num(v: f64) -> String {
    format!("{v:?}")
}

fn list(values: impl IntoIterator<Item = String>) -> String {
    values.into_iter().collect::<Vec<_>>().join(", ")
}

/// Writes labels 16 to a line.
fn label_lines(out: &mut String, labels: impl IntoIterator<Item = usize>) {
    let labels: Vec<String> = labels.into_iter().map(|l| l.to_string()).collect();
    for chunk in labels.chunks(16) {
        let _ = writeln!(out, "{}", chunk.join(", "));
    }
}

/// The deck of `spec`; `rigid` gives the elements of bodies (by name) whose surfaces are
/// faceted or triangulated (a faceted cylinder without them is written as R2D2 in 2D; in 3D
/// the elements are required).
///
/// # Errors
/// A message naming what the keyword subset cannot express.
pub fn write_deck(
    spec: &ModelSpec,
    rigid: &BTreeMap<String, RigidElements>,
) -> Result<String, String> {
    if !spec.parts.is_empty() {
        return Err(
            "parts: a deck holds one mesh; merge the parts into `part` first (reading a model \
             file does, see `model_file::merge_parts`)"
                .into(),
        );
    }
    let dim = spec.dimension;
    let part = &spec.part;
    let mut out = String::new();
    let _ = writeln!(out, "*HEADING");
    for line in spec.description.lines().filter(|l| !l.trim().is_empty()) {
        let _ = writeln!(out, "{}", line.replace('*', " "));
    }
    let _ = writeln!(
        out,
        "** Model '{}', written by skid: `skid run` reads it.",
        spec.name
    );
    let section = &part.section;
    if section.hourglass_scale != 1.0 || section.quasi_static || section.massless_contact_nodes {
        return Err(
            "part.section: hourglass_scale, quasi_static and massless_contact_nodes have no \
             keyword"
                .into(),
        );
    }
    // part
    let _ = writeln!(out, "**\n** deformable part '{}'\n*NODE", part.name);
    for (i, x) in part.nodes.iter().enumerate() {
        let _ = writeln!(out, "{}, {}", i + 1, list(x.iter().map(|v| num(*v))));
    }
    // one *ELEMENT block per element block, labels running on from block to block; with
    // materials by element set, the part's own section holds the other elements only
    let mut elements = Vec::new();
    for block in &part.elements {
        let kind = block.kind.name();
        if part.materials.is_empty() {
            let _ = writeln!(out, "*ELEMENT, TYPE={kind}, ELSET={}", part.name);
        } else {
            let _ = writeln!(out, "*ELEMENT, TYPE={kind}");
        }
        for nodes in &block.connectivity {
            elements.push(nodes.clone());
            let _ = writeln!(
                out,
                "{}, {}",
                elements.len(),
                list(nodes.iter().map(|n| (n + 1).to_string()))
            );
        }
    }
    for (name, nodes) in &part.node_sets {
        let _ = writeln!(out, "*NSET, NSET={name}");
        label_lines(&mut out, nodes.iter().map(|n| n + 1));
    }
    for (name, elements) in &part.element_sets {
        let _ = writeln!(out, "*ELSET, ELSET={name}");
        label_lines(&mut out, elements.iter().map(|e| e + 1));
    }
    let solid = if dim == 2 {
        ElementKind::Quad(Formulation::Reduced)
    } else {
        ElementKind::Hex(Formulation::Reduced)
    };
    let mut face_of: HashMap<Vec<usize>, (usize, usize)> = HashMap::new();
    for (e, nodes) in elements.iter().enumerate() {
        for k in 1..=solid.face_count() {
            if let Some(corners) = solid.face(k) {
                let mut key: Vec<usize> = corners.iter().map(|&c| nodes[c]).collect();
                key.sort_unstable();
                face_of.insert(key, (e + 1, k));
            }
        }
    }
    for (name, faces) in &part.surfaces {
        let _ = writeln!(out, "*SURFACE, NAME={name}, TYPE=ELEMENT");
        for face in faces {
            let mut key = face.clone();
            key.sort_unstable();
            let (e, k) = face_of.get(&key).ok_or(format!(
                "part.surfaces.{name}: a face is not a face of an element"
            ))?;
            let _ = writeln!(out, "{e}, S{k}");
        }
    }
    if !part.materials.is_empty() {
        let mut own = vec![true; elements.len()];
        for set in &part.materials {
            let members = part.element_sets.get(&set.element_set).ok_or(format!(
                "part.materials: no element set named '{}'",
                set.element_set
            ))?;
            for &e in members {
                if let Some(slot) = own.get_mut(e) {
                    *slot = false;
                }
            }
        }
        if part.element_sets.contains_key(&part.name) {
            return Err(format!(
                "part.element_sets.{}: the part's name is the element set of its own section",
                part.name
            ));
        }
        let _ = writeln!(out, "*ELSET, ELSET={}", part.name);
        label_lines(
            &mut out,
            (0..elements.len()).filter(|&e| own[e]).map(|e| e + 1),
        );
    }
    let thickness = part.section.thickness;
    let own = [(
        part.name.as_str(),
        &part.section.material,
        part.section.density,
        part.section.stiffness_damping,
    )];
    let others = part.materials.iter().map(|m| {
        let set = m.element_set.as_str();
        (set, &m.material, m.density, m.stiffness_damping)
    });
    // the part's hourglass control, on every section of it
    let controls = match part.section.hourglass {
        HourglassControl::Stiffness => String::new(),
        HourglassControl::Enhanced => {
            let name = format!("{}-controls", part.name);
            let _ = writeln!(out, "*SECTION CONTROLS, NAME={name}, HOURGLASS=ENHANCED");
            format!(", CONTROLS={name}")
        }
    };
    for (elset, law, density, beta) in own.into_iter().chain(others) {
        let material = format!("{elset}-material");
        let _ = writeln!(
            out,
            "*SOLID SECTION, ELSET={elset}, MATERIAL={material}{controls}"
        );
        if dim == 2 {
            let _ = writeln!(out, "{}", num(thickness));
        }
        let _ = writeln!(out, "*MATERIAL, NAME={material}");
        match law {
            MaterialSpec::PolynomialN1 { c10, c01, d1 } => {
                let _ = writeln!(
                    out,
                    "*HYPERELASTIC, POLYNOMIAL, N=1\n{}, {}, {}",
                    num(*c10),
                    num(*c01),
                    num(*d1)
                );
            }
        }
        let _ = writeln!(out, "*DENSITY\n{}", num(density));
        if beta != 0.0 {
            let _ = writeln!(out, "*DAMPING, BETA={}", num(beta));
        }
    }

    // rigid bodies
    let mut next_node = part.nodes.len() + 1;
    let mut next_element = elements.len() + 1;
    let fixed = |body: &str| -> Vec<Dof> {
        spec.boundary
            .iter()
            .filter(|b| b.body.as_deref() == Some(body))
            .flat_map(|b| b.dofs.iter().copied())
            .collect()
    };
    for body in &spec.rigid_bodies {
        let reference = next_node;
        next_node += 1;
        let _ = writeln!(
            out,
            "**\n** rigid body '{}'\n*NODE, NSET={}",
            body.name, body.name
        );
        let _ = writeln!(
            out,
            "{reference}, {}",
            list(body.reference_point.iter().map(|v| num(*v)))
        );
        point_inertia(&mut out, body, reference, &mut next_element, dim);
        let ties: Vec<&str> = spec
            .ties
            .iter()
            .filter(|t| t.body == body.name)
            .map(|t| t.node_set.as_str())
            .collect();
        let tie = match ties.as_slice() {
            [] => String::new(),
            [one] => format!(", TIE NSET={one}"),
            many => {
                let name = format!("{}-tie", body.name);
                let _ = writeln!(out, "*NSET, NSET={name}\n{}", many.join(", "));
                format!(", TIE NSET={name}")
            }
        };
        let carrier = surface_deck(
            &mut out,
            spec,
            body,
            rigid.get(&body.name),
            (&mut next_node, &mut next_element),
        )?;
        let _ = writeln!(out, "*RIGID BODY, REF NODE={}{carrier}{tie}", body.name);
    }

    // contact
    let mut general = Vec::new();
    for pair in &spec.contact {
        match &pair.slave {
            SlaveSpec::NodeSet { name } => {
                let _ = writeln!(
                    out,
                    "**\n*SURFACE INTERACTION, NAME={0}\n*FRICTION\n{1}\n*SURFACE, NAME={0}-slave, TYPE=NODE\n{name}\n*CONTACT PAIR, INTERACTION={0}\n{0}-slave, {2}",
                    pair.name,
                    num(pair.mu),
                    pair.master
                );
            }
            SlaveSpec::General { .. } => general.push(pair),
        }
    }
    if let Some(first) = general.first() {
        if general.iter().any(|p| p.mu != first.mu) {
            return Err("general contact pairs with different friction have no keyword".into());
        }
        let _ = writeln!(
            out,
            "**\n*SURFACE INTERACTION, NAME={0}\n*FRICTION\n{1}\n*CONTACT\n*CONTACT INCLUSIONS, ALL EXTERIOR\n*CONTACT PROPERTY ASSIGNMENT\n, , {0}",
            first.name,
            num(first.mu)
        );
    }

    // boundary and initial conditions
    let (prescribed, held): (Vec<&BoundarySpec>, Vec<&BoundarySpec>) =
        spec.boundary.iter().partition(|bc| bc.is_prescribed());
    if !held.is_empty() {
        let _ = writeln!(out, "**\n*BOUNDARY");
        for bc in held {
            let target = bc
                .body
                .as_deref()
                .or(bc.node_set.as_deref())
                .unwrap_or_default();
            for dof in &bc.dofs {
                let k = dof_number(*dof);
                let _ = writeln!(out, "{target}, {k}, {k}");
            }
        }
    }
    for body in &spec.rigid_bodies {
        initial_conditions(&mut out, body, dim);
    }
    for initial in &spec.initial_velocities {
        let _ = writeln!(out, "*INITIAL CONDITIONS, TYPE=VELOCITY");
        for (i, v) in initial.velocity.iter().enumerate().take(dim) {
            let _ = writeln!(out, "{}, {}, {}", initial.node_set, i + 1, num(*v));
        }
    }

    for amplitude in &spec.amplitudes {
        let time = match amplitude.time {
            AmplitudeTime::Step => "",
            AmplitudeTime::Total => ", TIME=TOTAL TIME",
        };
        let _ = writeln!(out, "**\n*AMPLITUDE, NAME={}{time}", amplitude.name);
        for chunk in amplitude.points.chunks(4) {
            let _ = writeln!(
                out,
                "{}",
                list(chunk.iter().flat_map(|[t, a]| [num(*t), num(*a)]))
            );
        }
    }

    // steps
    for (i, step) in spec.steps.iter().enumerate() {
        let (name, boundary) = match step {
            ModelStepSpec::Static { name, boundary, .. }
            | ModelStepSpec::Dynamic { name, boundary, .. } => (name, boundary),
        };
        let default = match step {
            ModelStepSpec::Static {
                default_amplitude, ..
            }
            | ModelStepSpec::Dynamic {
                default_amplitude, ..
            } => match default_amplitude {
                None => "",
                Some(DefaultAmplitude::Ramp) => ", AMPLITUDE=RAMP",
                Some(DefaultAmplitude::Step) => ", AMPLITUDE=STEP",
            },
        };
        let _ = writeln!(out, "**\n*STEP, NAME={name}, NLGEOM=YES{default}");
        match step {
            ModelStepSpec::Static {
                increments,
                automatic,
                regularization_time,
                time_period,
                ..
            } => {
                if *regularization_time != default_regularization_time() {
                    return Err(format!("steps[{i}].regularization_time has no keyword"));
                }
                let period = time_period.unwrap_or(1.0);
                match (increments, automatic) {
                    (Some(n), None) => {
                        let _ = writeln!(
                            out,
                            "*STATIC, DIRECT\n{}, {}",
                            num(period / *n as f64),
                            num(period)
                        );
                    }
                    (None, Some(a)) => {
                        let _ = writeln!(
                            out,
                            "*STATIC\n{}, {}, {}, {}",
                            num(a.initial * period),
                            num(period),
                            num(a.min * period),
                            num(a.max * period)
                        );
                    }
                    _ => {
                        return Err(format!(
                            "steps[{i}]: give exactly one of increments and automatic"
                        ));
                    }
                }
            }
            ModelStepSpec::Dynamic {
                duration,
                dt,
                alpha,
                adaptive,
                ..
            } => match adaptive {
                None => {
                    let _ = writeln!(
                        out,
                        "*DYNAMIC, DIRECT, ALPHA={}\n{}, {}",
                        num(*alpha),
                        num(*dt),
                        num(*duration)
                    );
                }
                Some(a) if a.tolerance == AUTOMATIC_DYNAMIC_TOLERANCE => {
                    let _ = writeln!(
                        out,
                        "*DYNAMIC, ALPHA={}\n{}, {}, {}, {}",
                        num(*alpha),
                        num(*dt),
                        num(*duration),
                        num(a.min_dt),
                        num(a.max_dt)
                    );
                }
                Some(a) => {
                    return Err(format!(
                        "steps[{i}].adaptive.tolerance: a deck's *DYNAMIC without DIRECT \
                             takes the tolerance {AUTOMATIC_DYNAMIC_TOLERANCE:e}, not {:e}",
                        a.tolerance
                    ));
                }
            },
        }
        let _ = writeln!(
            out,
            "{}",
            if i == 0 {
                "*BOUNDARY"
            } else {
                "*BOUNDARY, OP=NEW"
            }
        );
        for hold in boundary {
            let (target, held) = match (&hold.body, &hold.node_set) {
                (Some(body), _) => (body, fixed(body)),
                (None, Some(set)) => (set, Vec::new()),
                (None, None) => {
                    return Err(format!(
                        "steps[{i}].boundary: expected a body or a node set"
                    ));
                }
            };
            let dofs: Vec<Dof> = match &hold.dofs {
                Some(d) => d.clone(),
                None if hold.body.is_some() => Dof::all(dim)
                    .iter()
                    .copied()
                    .filter(|d| !held.contains(d))
                    .collect(),
                None => Dof::all(dim)
                    .iter()
                    .copied()
                    .filter(|d| d.translation_axis().is_some())
                    .collect(),
            };
            for dof in dofs {
                let k = dof_number(dof);
                let _ = writeln!(out, "{target}, {k}, {k}");
            }
        }
        write_motions(&mut out, &prescribed, i);
        if i == 0 {
            write_loads(&mut out, spec)?;
            // a request holds in the later steps too
            if let Some(interval) = spec.output.field_interval {
                let _ = writeln!(out, "*OUTPUT, FIELD, TIME INTERVAL={}", num(interval));
            }
            if !spec.output.history_nodes.is_empty() {
                let _ = writeln!(out, "*OUTPUT, HISTORY");
            }
            for set in &spec.output.history_nodes {
                let _ = writeln!(out, "*NODE OUTPUT, NSET={set}\nU");
            }
        }
        let _ = writeln!(out, "*END STEP");
    }
    Ok(out)
}

/// The prescribed motions of rigid bodies and node sets in step `step`: a `*BOUNDARY` block each (with its
/// amplitude as a parameter), each degree of freedom at its value times the step's factor.
fn write_motions(out: &mut String, motions: &[&BoundarySpec], step: usize) {
    for motion in motions {
        let (Some(target), Some(value)) = (
            motion.body.as_ref().or(motion.node_set.as_ref()),
            motion.value,
        ) else {
            continue;
        };
        let factor = motion.step_factors.as_ref().map_or(1.0, |f| f[step]);
        match &motion.amplitude {
            Some(name) => {
                let _ = writeln!(out, "*BOUNDARY, AMPLITUDE={name}");
            }
            None => {
                let _ = writeln!(out, "*BOUNDARY");
            }
        }
        for dof in &motion.dofs {
            let k = dof_number(*dof);
            let _ = writeln!(out, "{target}, {k}, {k}, {}", num(value * factor));
        }
    }
}

/// The loads, one keyword block each (its amplitude is a parameter of the keyword):
/// `*DSLOAD` pressures, `*CLOAD` non-zero components on a node set or a body's reference node
/// (its node set has the body's name; two loads on one degree of freedom are refused), `*DLOAD, GRAV` with the acceleration as the direction and
/// its norm as the magnitude, which reads back to the same bits.
fn write_loads(out: &mut String, spec: &ModelSpec) -> Result<(), String> {
    // the load that acts on each (target, degree of freedom) so far
    let mut loaded: BTreeMap<(String, usize), usize> = BTreeMap::new();
    for (k, load) in spec.loads.iter().enumerate() {
        if load.step_factors().is_some() {
            return Err(format!(
                "loads[{k}].step_factors: a load that changes between steps is not written as a \
                 deck (its value in each step would not read back to the same bits)"
            ));
        }
        let keyword = match load {
            LoadSpec::Pressure { .. } => "DSLOAD",
            LoadSpec::Concentrated { .. } => "CLOAD",
            LoadSpec::Gravity { .. } => "DLOAD",
        };
        let amplitude = load
            .amplitude()
            .map_or_else(String::new, |a| format!(", AMPLITUDE={a}"));
        let _ = writeln!(out, "*{keyword}{amplitude}");
        match load {
            LoadSpec::Pressure {
                surface, pressure, ..
            } => {
                let _ = writeln!(out, "{surface}, P, {}", num(*pressure));
            }
            LoadSpec::Concentrated {
                node_set,
                body,
                force,
                moment,
                ..
            } => {
                let target = node_set.as_deref().or(body.as_deref()).ok_or(format!(
                    "loads[{k}]: a concentrated load needs a node set or a body"
                ))?;
                let components = force.iter().flatten().copied().enumerate().chain(
                    moment
                        .iter()
                        .flatten()
                        .copied()
                        .enumerate()
                        .filter(|&(axis, _)| spec.dimension == 3 || axis == 2)
                        .map(|(axis, m)| (axis + 3, m)),
                );
                // only the components the load has: a later *CLOAD line on the same degree of
                // freedom replaces an earlier one (OP=MOD), whatever its amplitude
                for (index, value) in components.filter(|&(_, value)| value != 0.0) {
                    if let Some(earlier) = loaded.insert((target.to_string(), index), k) {
                        return Err(format!(
                            "loads[{earlier}] and loads[{k}] both act on degree of freedom {} \
                             of {target}: in a deck the later *CLOAD would replace the earlier \
                             (OP=MOD), so the model is not written as a deck",
                            index + 1
                        ));
                    }
                    let _ = writeln!(out, "{target}, {}, {}", index + 1, num(value));
                }
            }
            LoadSpec::Gravity {
                acceleration,
                element_set,
                ..
            } => {
                let mut g = acceleration.clone();
                g.resize(3, 0.0);
                let norm = g.iter().map(|c| c * c).sum::<f64>().sqrt();
                let _ = writeln!(
                    out,
                    "{}, GRAV, {}, {}",
                    element_set.as_deref().unwrap_or_default(),
                    num(norm),
                    list(g.iter().map(|c| num(*c)))
                );
            }
        }
    }
    Ok(())
}

/// A point of 2 or 3 coordinates in 3D (z = 0 in 2D).
fn embed(x: &[f64]) -> Vector3<f64> {
    Vector3::from_iterator(x.iter().copied().chain(std::iter::repeat(0.0)).take(3))
}

fn dof_number(dof: Dof) -> usize {
    match dof {
        Dof::X => 1,
        Dof::Y => 2,
        Dof::Z => 3,
        Dof::Rx => 4,
        Dof::Ry => 5,
        Dof::Rz => 6,
    }
}

/// `MASS` and `ROTARYI` elements at the reference node (3D: an isotropic inertia, so that it
/// counts the same about whichever axis the body turns).
fn point_inertia(
    out: &mut String,
    body: &RigidBodySpec,
    reference: usize,
    next_element: &mut usize,
    dim: usize,
) {
    if body.mass > 0.0 {
        let _ = writeln!(
            out,
            "*ELEMENT, TYPE=MASS, ELSET={0}-mass\n{1}, {reference}\n*MASS, ELSET={0}-mass\n{2}",
            body.name,
            next_element,
            num(body.mass)
        );
        *next_element += 1;
    }
    let values = match body.moments_of_inertia {
        Some(j) if j.iter().any(|&v| v > 0.0) => Some(if dim == 2 {
            num(j[2])
        } else {
            // I11, I22, I33, then I12, I13, I23 where there are products
            let products = body.products_of_inertia.filter(|p| *p != [0.0; 3]);
            j.iter()
                .chain(products.iter().flatten())
                .map(|&v| num(v))
                .collect::<Vec<_>>()
                .join(", ")
        }),
        _ if body.rotary_inertia > 0.0 => {
            let i = num(body.rotary_inertia);
            Some(if dim == 2 {
                i
            } else {
                format!("{i}, {i}, {i}")
            })
        }
        _ => None,
    };
    if let Some(values) = values {
        let _ = writeln!(
            out,
            "*ELEMENT, TYPE=ROTARYI, ELSET={0}-inertia\n{1}, {reference}\n*ROTARY INERTIA, ELSET={0}-inertia\n{values}",
            body.name, next_element
        );
        *next_element += 1;
    }
}

/// Writes the surface of `body`, if it has one, and returns the `*RIGID BODY` parameter that
/// attaches it (empty without a surface).
fn surface_deck(
    out: &mut String,
    spec: &ModelSpec,
    body: &RigidBodySpec,
    elements: Option<&RigidElements>,
    (next_node, next_element): (&mut usize, &mut usize),
) -> Result<String, String> {
    let Some(surface) = &body.surface else {
        return Ok(String::new());
    };
    let c = &embed(&body.reference_point);
    let dim = spec.dimension;
    let name = &body.name;
    let p = |v: &Vector3<f64>| list(v.iter().take(dim).map(|x| num(*x)));
    match surface {
        RigidSurfaceSpec::Cylinder { radius, axis } => {
            let r = *radius;
            if dim == 2 {
                let _ = writeln!(
                    out,
                    "*SURFACE, NAME={name}, TYPE=SEGMENTS\nSTART, {}, {}",
                    num(c.x + r),
                    num(c.y)
                );
                for (x, y) in [
                    (c.x, c.y - r),
                    (c.x - r, c.y),
                    (c.x, c.y + r),
                    (c.x + r, c.y),
                ] {
                    let _ = writeln!(
                        out,
                        "CIRCL, {}, {}, {}, {}",
                        num(x),
                        num(y),
                        num(c.x),
                        num(c.y)
                    );
                }
            } else {
                let e = Vector3::from(*axis).normalize();
                let reach = spec
                    .part
                    .nodes
                    .iter()
                    .map(|x| (embed(x) - c).norm())
                    .fold(r, f64::max);
                let h = 2.0 * reach;
                let _ = writeln!(
                    out,
                    "*SURFACE, NAME={name}, TYPE=REVOLUTION\n{}, {}\nSTART, {}, {}\nLINE, {}, {}",
                    list(c.iter().map(|x| num(*x))),
                    list((c + e).iter().map(|x| num(*x))),
                    num(r),
                    num(h),
                    num(r),
                    num(-h)
                );
            }
            Ok(format!(", ANALYTICAL SURFACE={name}"))
        }
        RigidSurfaceSpec::Plane { normal, tangent } => {
            let (n, t) = (Vector3::from(*normal), Vector3::from(*tangent));
            let reach = spec
                .part
                .nodes
                .iter()
                .map(|x| (embed(x) - c).norm())
                .fold(1.0, f64::max);
            let l = 2.0 * reach;
            if dim == 2 {
                // travel along t whose counter-clockwise normal is n
                let t = if Vector3::z().cross(&t).dot(&n) > 0.0 {
                    t
                } else {
                    -t
                };
                let (a, b) = (c - t * l, c + t * l);
                let _ = writeln!(
                    out,
                    "*SURFACE, NAME={name}, TYPE=SEGMENTS\nSTART, {}\nLINE, {}",
                    p(&a),
                    p(&b)
                );
            } else {
                let generator = c + t.cross(&n);
                let _ = writeln!(
                    out,
                    "*SURFACE, NAME={name}, TYPE=CYLINDER\n{}, {}\n{}\nSTART, {}, 0.0\nLINE, {}, 0.0",
                    list(c.iter().map(|x| num(*x))),
                    list((c + t).iter().map(|x| num(*x))),
                    list(generator.iter().map(|x| num(*x))),
                    num(-l),
                    num(l)
                );
            }
            Ok(format!(", ANALYTICAL SURFACE={name}"))
        }
        RigidSurfaceSpec::FacetedCylinder {
            radius,
            axis,
            facets,
            phase,
        } => {
            let (kind, range) = match elements {
                Some(RigidElements::Facets { kind, axial_range }) => (*kind, *axial_range),
                None if dim == 2 => (ElementKind::R2d2, [0.0, 0.0]),
                _ => {
                    return Err(format!(
                        "rigid body {name}: a 3D faceted cylinder is written with its elements and \
                         axial range"
                    ));
                }
            };
            let e = Vector3::from(*axis).normalize();
            let frame = AnalyticCylinder::new(*radius, e).map_err(|err| err.to_string())?;
            let b1 = frame.reference_direction();
            let b2 = e.cross(&b1);
            let n = *facets;
            let vertex = |k: usize| {
                let a = phase + std::f64::consts::TAU * k as f64 / n as f64;
                c + (b1 * a.cos() + b2 * a.sin()) * *radius
            };
            let first = *next_node;
            let _ = writeln!(out, "*NODE");
            let rings: &[f64] = if dim == 2 { &[0.0] } else { &range };
            for h in rings {
                for k in 0..n {
                    let _ = writeln!(out, "{}, {}", *next_node, p(&(vertex(k) + e * *h)));
                    *next_node += 1;
                }
            }
            let type_name = match kind {
                ElementKind::R2d2 => "R2D2",
                ElementKind::R3d4 => "R3D4",
                ElementKind::M3d4r => "M3D4R",
                ElementKind::S4r => "S4R",
                other => return Err(format!("{other:?} elements cannot carry facets")),
            };
            let elset = format!("{name}-facets");
            let _ = writeln!(out, "*ELEMENT, TYPE={type_name}, ELSET={elset}");
            for k in 0..n {
                let next = (k + 1) % n;
                let nodes = if dim == 2 {
                    // SPOS (e_z x t) outward: clockwise travel
                    vec![first + next, first + k]
                } else {
                    vec![first + k, first + next, first + n + next, first + n + k]
                };
                let _ = writeln!(
                    out,
                    "{}, {}",
                    *next_element,
                    list(nodes.iter().map(|v| v.to_string()))
                );
                *next_element += 1;
            }
            if matches!(kind, ElementKind::M3d4r | ElementKind::S4r) {
                let section = if kind == ElementKind::M3d4r {
                    "MEMBRANE"
                } else {
                    "SHELL"
                };
                let _ = writeln!(
                    out,
                    "** rigid: the section's thickness and elasticity are not used\n*{section} SECTION, ELSET={elset}, MATERIAL={name}-material\n0.001\n*MATERIAL, NAME={name}-material\n*ELASTIC\n2.0e11, 0.3\n*DENSITY\n0.0"
                );
            }
            let _ = writeln!(out, "*SURFACE, NAME={name}, TYPE=ELEMENT\n{elset}, SPOS");
            Ok(format!(", ELSET={elset}"))
        }
        RigidSurfaceSpec::Extrusion {
            axis,
            reference,
            profile,
            centres,
            closed,
        } => {
            let e = Vector3::from(*axis).normalize();
            let a = Vector3::from(*reference);
            let a = (a - e * e.dot(&a)).normalize();
            let _ = writeln!(
                out,
                "*SURFACE, NAME={name}, TYPE=CYLINDER\n{}, {}\n{}",
                list(c.iter().map(|x| num(*x))),
                list((c + a).iter().map(|x| num(*x))),
                list((c + e).iter().map(|x| num(*x)))
            );
            profile_lines(out, profile, centres, *closed, |q| q);
            Ok(format!(", ANALYTICAL SURFACE={name}"))
        }
        RigidSurfaceSpec::Revolution {
            axis,
            profile,
            centres,
            closed,
            radius,
        } => {
            let largest = profile_polyline(profile, centres, *closed)
                .map_err(|e| format!("rigid body {name}: {e}"))?
                .bounds()
                .1
                .x;
            if radius.is_some_and(|r| r != largest) {
                return Err(format!(
                    "rigid body {name}: the radius of a surface of revolution's circumferential \
                     coordinate has no keyword (a deck's is the profile's largest r)"
                ));
            }
            let e = Vector3::from(*axis).normalize();
            let _ = writeln!(
                out,
                "*SURFACE, NAME={name}, TYPE=REVOLUTION\n{}, {}",
                list(c.iter().map(|x| num(*x))),
                list((c + e).iter().map(|x| num(*x)))
            );
            profile_lines(out, profile, centres, *closed, |q| q);
            Ok(format!(", ANALYTICAL SURFACE={name}"))
        }
        RigidSurfaceSpec::Polyline {
            points,
            centres,
            closed,
        } if !centres.is_empty() => {
            // arcs have no rigid element: the analytical profile, in global x-y
            let _ = writeln!(out, "*SURFACE, NAME={name}, TYPE=SEGMENTS");
            profile_lines(out, points, centres, *closed, |q| [q[0] + c.x, q[1] + c.y]);
            Ok(format!(", ANALYTICAL SURFACE={name}"))
        }
        RigidSurfaceSpec::Polyline { points, closed, .. } => {
            let first = *next_node;
            let _ = writeln!(out, "*NODE");
            for q in points {
                let _ = writeln!(
                    out,
                    "{}, {}",
                    *next_node,
                    p(&(c + Vector3::new(q[0], q[1], 0.0)))
                );
                *next_node += 1;
            }
            let elset = format!("{name}-lines");
            let _ = writeln!(out, "*ELEMENT, TYPE=R2D2, ELSET={elset}");
            let n = points.len();
            let segments = if *closed { n } else { n.saturating_sub(1) };
            for k in 0..segments {
                // SPOS (e_z x t) outward: each line from the polyline's next point back
                let _ = writeln!(
                    out,
                    "{}, {}, {}",
                    *next_element,
                    first + (k + 1) % n,
                    first + k
                );
                *next_element += 1;
            }
            let _ = writeln!(out, "*SURFACE, NAME={name}, TYPE=ELEMENT\n{elset}, SPOS");
            Ok(format!(", ELSET={elset}"))
        }
        RigidSurfaceSpec::Triangles {
            vertices,
            triangles,
            ..
        } => {
            let Some(RigidElements::Tetrahedra(mesh)) = elements else {
                let first = *next_node;
                let _ = writeln!(out, "*NODE");
                for v in vertices {
                    let _ = writeln!(out, "{}, {}", *next_node, p(&(c + Vector3::from(*v))));
                    *next_node += 1;
                }
                let elset = format!("{name}-triangles");
                let _ = writeln!(out, "*ELEMENT, TYPE=R3D3, ELSET={elset}");
                for t in triangles {
                    let _ = writeln!(
                        out,
                        "{}, {}",
                        *next_element,
                        list(t.iter().map(|v| (first + v).to_string()))
                    );
                    *next_element += 1;
                }
                let _ = writeln!(out, "*SURFACE, NAME={name}, TYPE=ELEMENT\n{elset}, SPOS");
                return Ok(format!(", ELSET={elset}"));
            };
            let first = *next_node;
            let _ = writeln!(out, "*NODE");
            for x in &mesh.nodes {
                let _ = writeln!(out, "{}, {}", *next_node, p(&(x + c)));
                *next_node += 1;
            }
            let elset = format!("{name}-tets");
            let _ = writeln!(out, "*ELEMENT, TYPE=C3D4, ELSET={elset}");
            for t in &mesh.tets {
                let _ = writeln!(
                    out,
                    "{}, {}",
                    *next_element,
                    list(t.iter().map(|v| (first + v).to_string()))
                );
                *next_element += 1;
            }
            let _ = writeln!(
                out,
                "** rigid: the section's elasticity is not used\n*SOLID SECTION, ELSET={elset}, MATERIAL={name}-material\n*MATERIAL, NAME={name}-material\n*ELASTIC\n2.0e11, 0.3\n*DENSITY\n0.0\n*SURFACE, NAME={name}, TYPE=ELEMENT\n{elset}"
            );
            Ok(format!(", ELSET={elset}"))
        }
    }
}

/// The `START` and `LINE` lines of an analytical profile given as a polyline: the deck's travel
/// runs against the polyline's (its outward normal is the travel turned counter-clockwise),
/// and a closed profile ends on its start.
/// The `START`, `LINE` and `CIRCL` lines of a profile (piece `k` from point `k` to the next an
/// arc about `centres[k]` where given), each point placed by `place`, walked in reverse: a
/// deck's outward normal is the travel turned counter-clockwise, a profile's turned clockwise.
fn profile_lines(
    out: &mut String,
    profile: &[[f64; 2]],
    centres: &[Option<[f64; 2]>],
    closed: bool,
    place: impl Fn([f64; 2]) -> [f64; 2],
) {
    let n = profile.len();
    let mut points: Vec<[f64; 2]> = profile.iter().rev().copied().collect();
    if closed {
        points.extend(points.first().copied());
    }
    for (k, q) in points.iter().enumerate() {
        let q = place(*q);
        // the piece walked from the last point to this one: reversed, piece n - 1 - k, or
        // the closing piece n - 1
        let piece = if k < n { n.wrapping_sub(1 + k) } else { n - 1 };
        match (k, centres.get(piece).copied().flatten()) {
            (0, _) => {
                let _ = writeln!(out, "START, {}, {}", num(q[0]), num(q[1]));
            }
            (_, Some(centre)) => {
                let centre = place(centre);
                let _ = writeln!(
                    out,
                    "CIRCL, {}, {}, {}, {}",
                    num(q[0]),
                    num(q[1]),
                    num(centre[0]),
                    num(centre[1])
                );
            }
            (_, None) => {
                let _ = writeln!(out, "LINE, {}, {}", num(q[0]), num(q[1]));
            }
        }
    }
}

fn initial_conditions(out: &mut String, body: &RigidBodySpec, dim: usize) {
    let v = body.initial_velocity.clone().unwrap_or_default();
    let w = body.initial_angular_velocity.unwrap_or([0.0; 3]);
    let w = Vector3::from(w);
    if w.norm() > 0.0 {
        let c = embed(&body.reference_point);
        let e = w.normalize();
        let mut velocity = [0.0; 3];
        for (i, x) in v.iter().enumerate() {
            velocity[i] = *x;
        }
        let _ = writeln!(
            out,
            "*INITIAL CONDITIONS, TYPE=ROTATING VELOCITY\n{}, {}, {}\n{}, {}",
            body.name,
            num(w.norm()),
            list(velocity.iter().map(|x| num(*x))),
            list(c.iter().map(|x| num(*x))),
            list((c + e).iter().map(|x| num(*x)))
        );
    } else if v.iter().any(|x| *x != 0.0) {
        let _ = writeln!(out, "*INITIAL CONDITIONS, TYPE=VELOCITY");
        for (i, x) in v.iter().enumerate().take(dim) {
            let _ = writeln!(out, "{}, {}, {}", body.name, i + 1, num(*x));
        }
    }
}
