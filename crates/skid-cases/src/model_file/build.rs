//! Building a [`Scene`] from a [`ModelSpec`]: every name resolved, every value checked, each
//! problem reported with the field path at fault.

use std::collections::{BTreeMap, BTreeSet};

use nalgebra::{Matrix3, Rotation3, SVector, Vector3};
use skid_contact::extrusion::RigidExtrusion;
use skid_contact::facets::FacetedCylinder;
use skid_contact::plane::RigidPlane;
use skid_contact::revolution::RigidRevolution;
use skid_contact::surface::{AnalyticCylinder, RigidSurface};
use skid_contact::triangles::{CylinderChart, SurfaceChart, TriangulatedSurface};
use skid_fem::cell::{embed, face_corners};
use skid_fem::element::Formulation;
use skid_fem::material::{Hyperelastic, PolynomialN1};
use skid_fem::mesh::SolidMesh;
use skid_fem::rigid::{RigidBody, Rotation};
use skid_integrator::BodyMotion;
use skid_integrator::settings::{ContactSolve, NewtonSettings};
use skid_integrator::settings::{CutbackSettings, Settings};
use skid_integrator::stepper::{Adaptive, HeldMotion, StaticIncrements, Step, StepKind};
use skid_integrator::{ContactPair, Model, Section, SolidPart, Tie};

mod loads;
mod motions;

use crate::model_spec::{
    BoundarySpec, ChartSpec, Dof, MODEL_FORMAT_VERSION, ModelSpec, ModelStepSpec, RigidSurfaceSpec,
    SlaveSpec, StepBoundarySpec, profile_polyline,
};
use crate::schema::{AdaptiveSpec, HourglassControl, MaterialSpec, SolverSpec};
use crate::validate::check_file_name;

/// A built scene: model, steps and solver settings.
#[derive(Debug)]
pub struct Scene<const D: usize> {
    /// The model.
    pub model: Model<D>,
    /// Analysis steps.
    pub steps: Vec<Step>,
    /// Solver settings.
    pub settings: Settings,
}

/// A problem in a model: the field path at fault and what was expected.
#[derive(Clone, Debug, PartialEq)]
pub struct SpecError {
    /// Field path, e.g. `rigid_bodies[0].mass`.
    pub field: String,
    /// What is wrong and what was expected.
    pub message: String,
}

fn fail<T>(field: impl Into<String>, message: impl Into<String>) -> Result<T, SpecError> {
    Err(SpecError {
        field: field.into(),
        message: message.into(),
    })
}

/// `Ok` for a finite `v > 0`.
pub(crate) fn positive(field: &str, v: f64) -> Result<(), SpecError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        fail(field, format!("expected a finite value > 0, got {v}"))
    }
}

/// `Ok` for a finite `v >= 0`.
pub(crate) fn non_negative(field: &str, v: f64) -> Result<(), SpecError> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        fail(field, format!("expected a finite value >= 0, got {v}"))
    }
}

fn finite_point<const D: usize>(field: &str, p: &[f64]) -> Result<SVector<f64, D>, SpecError> {
    if p.len() != D {
        return fail(field, format!("expected {D} coordinates, got {}", p.len()));
    }
    if let Some(v) = p.iter().find(|v| !v.is_finite()) {
        return fail(field, format!("expected finite coordinates, got {v}"));
    }
    Ok(SVector::from_fn(|i, _| p[i]))
}

fn vector3(field: &str, v: [f64; 3]) -> Result<Vector3<f64>, SpecError> {
    if v.iter().all(|c| c.is_finite()) {
        Ok(Vector3::from(v))
    } else {
        fail(field, format!("expected finite components, got {v:?}"))
    }
}

/// Builds the scene of `spec` in dimension `D` (which must equal `spec.dimension`).
///
/// # Errors
/// The first problem found, as a [`SpecError`].
pub fn build<const D: usize>(spec: &ModelSpec) -> Result<Scene<D>, SpecError> {
    if !spec.parts.is_empty() {
        return build::<D>(&super::merge_parts(spec.clone())?);
    }
    if spec.skid_model != MODEL_FORMAT_VERSION {
        return fail(
            "skid_model",
            format!(
                "expected format version {MODEL_FORMAT_VERSION}, got {}",
                spec.skid_model
            ),
        );
    }
    if spec.dimension != D {
        return fail(
            "dimension",
            format!("expected {D} (2 or 3), got {}", spec.dimension),
        );
    }
    let mesh = part_mesh::<D>(spec)?;
    loads::check_element_sets(spec, mesh.elements.len())?;
    let section = &spec.part.section;
    let (sections, element_sections) = sections(spec, mesh.elements.len())?;
    positive("part.section.thickness", section.thickness)?;
    if D == 3 && section.thickness != 1.0 {
        return fail(
            "part.section.thickness",
            format!(
                "a 3D part has no out-of-plane thickness: expected 1, got {}",
                section.thickness
            ),
        );
    }
    positive("part.section.hourglass_scale", section.hourglass_scale)?;
    check_hourglass(spec)?;

    let body_index = body_names(spec)?;
    let body_of = |field: &str, name: &str| {
        body_index.get(name).copied().ok_or_else(|| SpecError {
            field: field.into(),
            message: format!("no rigid body named '{name}'"),
        })
    };
    let node_set = |field: &str, name: &str| {
        mesh.node_sets.get(name).ok_or_else(|| SpecError {
            field: field.into(),
            message: format!("no node set named '{name}' in part '{}'", spec.part.name),
        })
    };

    let mut body_fixed: Vec<BTreeSet<Dof>> = vec![BTreeSet::new(); spec.rigid_bodies.len()];
    let mut fixed_nodes = Vec::new();
    for (i, bc) in spec.boundary.iter().enumerate() {
        let f = |name: &str| format!("boundary[{i}].{name}");
        check_dofs::<D>(&f("dofs"), &bc.dofs)?;
        // a prescribed motion leaves its degrees of freedom free (see `motions`)
        let prescribed = bc.is_prescribed();
        match bc {
            BoundarySpec {
                body: Some(body),
                node_set: None,
                dofs,
                ..
            } => {
                let body = body_of(&f("body"), body)?;
                if !prescribed {
                    body_fixed[body].extend(dofs);
                }
            }
            BoundarySpec {
                body: None,
                node_set: Some(_),
                ..
            } if prescribed => {}
            BoundarySpec {
                body: None,
                node_set: Some(set),
                dofs,
                ..
            } => {
                let nodes = node_set(&f("node_set"), set)?;
                for dof in dofs {
                    let Some(axis) = dof.translation_axis() else {
                        return fail(
                            f("dofs"),
                            format!("nodes of a solid part have no rotation {dof:?}"),
                        );
                    };
                    fixed_nodes.extend(nodes.iter().map(|&n| (n, axis)));
                }
            }
            _ => {
                return fail(
                    format!("boundary[{i}]"),
                    "expected exactly one of body and node_set",
                );
            }
        }
    }
    fixed_nodes.sort_unstable();
    fixed_nodes.dedup();

    let bodies = spec
        .rigid_bodies
        .iter()
        .zip(&body_fixed)
        .enumerate()
        .map(|(i, (b, fixed))| rigid_body::<D>(i, b, fixed))
        .collect::<Result<Vec<_>, _>>()?;

    let ties = spec
        .ties
        .iter()
        .enumerate()
        .map(|(i, t)| {
            Ok(Tie {
                body: body_of(&format!("ties[{i}].body"), &t.body)?,
                nodes: node_set(&format!("ties[{i}].node_set"), &t.node_set)?.clone(),
            })
        })
        .collect::<Result<Vec<_>, SpecError>>()?;

    let mut pair_names = BTreeSet::new();
    let mut contacts = Vec::with_capacity(spec.contact.len());
    for (i, pair) in spec.contact.iter().enumerate() {
        let f = |name: &str| format!("contact[{i}].{name}");
        if pair.name.is_empty() || !pair_names.insert(pair.name.as_str()) {
            return fail(
                f("name"),
                format!("expected a unique non-empty name, got '{}'", pair.name),
            );
        }
        non_negative(&f("mu"), pair.mu)?;
        let body = body_of(&f("master"), &pair.master)?;
        let Some(surface_spec) = &spec.rigid_bodies[body].surface else {
            return fail(
                f("master"),
                format!("rigid body '{}' has no surface", pair.master),
            );
        };
        let surface = rigid_surface::<D>(&format!("rigid_bodies[{body}].surface"), surface_spec)?;
        let nodes = match &pair.slave {
            SlaveSpec::NodeSet { name } => node_set(&f("slave.name"), name)?.clone(),
            SlaveSpec::General { search_distance } => {
                positive(&f("slave.search_distance"), *search_distance)?;
                let origin = bodies[body].reference_point;
                nodes_near(&mesh, surface.as_ref(), &origin, *search_distance)
            }
        };
        contacts.push(ContactPair {
            name: pair.name.clone(),
            nodes,
            body,
            surface,
            mu: pair.mu,
        });
    }

    // the nodes a step holds: a node set without nodes tied to a body
    let step_nodes = |field: &str, name: &str| -> Result<Vec<usize>, SpecError> {
        let nodes = node_set(field, name)?.clone();
        let tied = spec.ties.iter().find(|t| {
            mesh.node_sets
                .get(&t.node_set)
                .is_some_and(|set| set.iter().any(|n| nodes.contains(n)))
        });
        match tied {
            Some(t) => fail(
                field,
                format!(
                    "node set '{name}' holds nodes tied to rigid body '{}' (they move with it): \
                     hold the body",
                    t.body
                ),
            ),
            None => Ok(nodes),
        }
    };
    let named = loads::amplitudes(&spec.amplitudes)?;
    let loads = loads::loads::<D>(spec, &mesh, &bodies, &named, &body_of)?;
    let steps = spec
        .steps
        .iter()
        .enumerate()
        .map(|(i, s)| step::<D>(i, s, (&body_of, &step_nodes)))
        .collect::<Result<Vec<_>, _>>()?;
    if steps.is_empty() {
        return fail("steps", "expected at least one step");
    }
    whole_rotation_holds(spec, &bodies, &body_of)?;
    if let Some(interval) = spec.output.field_interval {
        positive("output.field_interval", interval)?;
        check_field_file_names(spec)?;
    }
    for (i, set) in spec.output.history_nodes.iter().enumerate() {
        node_set(&format!("output.history_nodes[{i}]"), set)?;
    }

    let part = SolidPart {
        name: spec.part.name.clone(),
        mesh,
        sections,
        element_sections,
        thickness: section.thickness,
        hourglass: section.hourglass.hourglass(section.hourglass_scale),
        element_formulations: element_formulations(spec),
        quasi_static: section.quasi_static,
        fixed: fixed_nodes,
    };
    let mut model = Model::new(part, bodies, ties, loads, contacts).map_err(|e| SpecError {
        field: "(model)".into(),
        message: e.to_string(),
    })?;
    if section.massless_contact_nodes {
        model = model.with_massless_contact_nodes().map_err(|e| SpecError {
            field: "part.section.massless_contact_nodes".into(),
            message: e.to_string(),
        })?;
    }
    for (i, initial) in spec.initial_velocities.iter().enumerate() {
        let field = |name: &str| format!("initial_velocities[{i}].{name}");
        let velocity = finite_point::<D>(&field("velocity"), &initial.velocity)?;
        let nodes = model
            .part()
            .mesh
            .node_sets
            .get(&initial.node_set)
            .ok_or_else(|| SpecError {
                field: field("node_set"),
                message: format!(
                    "no node set named '{}' in part '{}'",
                    initial.node_set, spec.part.name
                ),
            })?;
        let velocities = nodes.iter().map(|&n| (n, velocity)).collect();
        model = model
            .with_node_velocities(velocities)
            .map_err(|e| SpecError {
                field: format!("initial_velocities[{i}]"),
                message: e.to_string(),
            })?;
    }
    let prescribed =
        motions::prescribed_motions(spec, &model.part().mesh, model.bodies(), &named, &body_of)?;
    for (i, motions) in prescribed {
        model = model
            .with_prescribed_motions(motions)
            .map_err(|e| SpecError {
                field: format!("boundary[{i}]"),
                message: e.to_string(),
            })?;
    }
    let settings = solver_settings(&spec.solver, ContactSolve::preferred_for(&model))?;
    Ok(Scene {
        model,
        steps,
        settings,
    })
}

/// A material of the format, checked, as the solver's (`field` names it in errors).
fn material(field: &str, spec: &MaterialSpec) -> Result<Box<dyn Hyperelastic>, SpecError> {
    match *spec {
        MaterialSpec::PolynomialN1 { c10, c01, d1 } => PolynomialN1::new(c10, c01, d1)
            .map(|m| Box::new(m) as Box<dyn Hyperelastic>)
            .map_err(|e| SpecError {
                field: field.into(),
                message: e.to_string(),
            }),
    }
}

/// The part's sections: the part's own first, then one per entry of `part.materials`, and the
/// section of each of the `elements` (empty when there is one section).
fn sections(spec: &ModelSpec, elements: usize) -> Result<(Vec<Section>, Vec<usize>), SpecError> {
    let part = &spec.part;
    positive("part.section.density", part.section.density)?;
    non_negative(
        "part.section.stiffness_damping",
        part.section.stiffness_damping,
    )?;
    let mut sections = vec![Section {
        material: material("part.section.material", &part.section.material)?,
        density: part.section.density,
        stiffness_damping: part.section.stiffness_damping,
    }];
    let mut of_element = vec![0; elements];
    for (i, set) in part.materials.iter().enumerate() {
        let f = |name: &str| format!("part.materials[{i}].{name}");
        let members = part
            .element_sets
            .get(&set.element_set)
            .ok_or_else(|| SpecError {
                field: f("element_set"),
                message: format!(
                    "no element set named '{}' in part '{}'",
                    set.element_set, part.name
                ),
            })?;
        positive(&f("density"), set.density)?;
        non_negative(&f("stiffness_damping"), set.stiffness_damping)?;
        sections.push(Section {
            material: material(&f("material"), &set.material)?,
            density: set.density,
            stiffness_damping: set.stiffness_damping,
        });
        for &e in members {
            if of_element[e] != 0 {
                return fail(
                    f("element_set"),
                    format!(
                        "element {e} is also in element set '{}' of part.materials[{}]",
                        part.materials[of_element[e] - 1].element_set,
                        of_element[e] - 1
                    ),
                );
            }
            of_element[e] = i + 1;
        }
    }
    if sections.len() == 1 {
        of_element.clear();
    }
    Ok((sections, of_element))
}

/// The field output ([`crate::fields`]) names its files after the part and the rigid bodies
/// that carry a contact pair's master surface: those names must be file names, and distinct
/// also where a file system ignores the case of letters.
fn check_field_file_names(spec: &ModelSpec) -> Result<(), SpecError> {
    let mut named = vec![("part.name".to_string(), spec.part.name.as_str())];
    for (i, body) in spec.rigid_bodies.iter().enumerate() {
        if spec.contact.iter().any(|pair| pair.master == body.name) {
            named.push((format!("rigid_bodies[{i}].name"), body.name.as_str()));
        }
    }
    let mut seen = BTreeMap::new();
    for (field, name) in named {
        let role = "it names the field output's files, as output.field_interval asks";
        check_file_name(&field, name, role)
            .map_err(|(field, message)| SpecError { field, message })?;
        if let Some(first) = seen.insert(name.to_ascii_lowercase(), field.clone()) {
            return fail(
                field,
                format!("'{name}' names the same field output files as {first}: rename one"),
            );
        }
    }
    Ok(())
}

/// The formulation of each element of the part, block by block as [`part_mesh`] numbers them;
/// empty when every element is the one-point default.
/// The enhanced hourglass control needs one-point elements and takes no hourglass scale.
///
/// # Errors
/// [`SpecError`] naming `part.section.hourglass` if no element block is of one-point
/// elements, `part.section.hourglass_scale` if it is not the default.
fn check_hourglass(spec: &ModelSpec) -> Result<(), SpecError> {
    let section = &spec.part.section;
    if section.hourglass != HourglassControl::Enhanced {
        return Ok(());
    }
    let blocks = &spec.part.elements;
    if !blocks
        .iter()
        .any(|b| b.kind.formulation() == Formulation::Reduced)
    {
        let kinds: Vec<&str> = blocks.iter().map(|b| b.kind.name()).collect();
        return fail(
            "part.section.hourglass",
            format!(
                "the enhanced hourglass control is for one-point elements (CPE4R / C3D8R); \
                 the part has only {}",
                kinds.join(", ")
            ),
        );
    }
    section
        .hourglass
        .check_scale(section.hourglass_scale)
        .or_else(|message| fail("part.section.hourglass_scale", message))
}

fn element_formulations(spec: &ModelSpec) -> Vec<Formulation> {
    let blocks = &spec.part.elements;
    if blocks
        .iter()
        .all(|b| b.kind.formulation() == Formulation::Reduced)
    {
        return Vec::new();
    }
    blocks
        .iter()
        .flat_map(|b| std::iter::repeat_n(b.kind.formulation(), b.connectivity.len()))
        .collect()
}

/// The part's mesh: nodes, elements of every block, sorted node sets, checked surfaces.
fn part_mesh<const D: usize>(spec: &ModelSpec) -> Result<SolidMesh<D>, SpecError> {
    let part = &spec.part;
    let nodes = part
        .nodes
        .iter()
        .enumerate()
        .map(|(i, p)| finite_point::<D>(&format!("part.nodes[{i}]"), p))
        .collect::<Result<Vec<_>, _>>()?;
    if nodes.is_empty() {
        return fail("part.nodes", "expected at least one node");
    }
    let corners = 1 << D;
    let mut elements = Vec::new();
    for (b, block) in part.elements.iter().enumerate() {
        if block.kind.dimension() != D {
            return fail(
                format!("part.elements[{b}].type"),
                format!("expected a {D}D element type, got {:?}", block.kind),
            );
        }
        for (e, conn) in block.connectivity.iter().enumerate() {
            let field = || format!("part.elements[{b}].connectivity[{e}]");
            if conn.len() != corners {
                return fail(
                    field(),
                    format!("expected {corners} nodes, got {}", conn.len()),
                );
            }
            if let Some(n) = conn.iter().find(|&&n| n >= nodes.len()) {
                return fail(
                    field(),
                    format!("node {n} does not exist ({} nodes)", nodes.len()),
                );
            }
            elements.push(conn.clone());
        }
    }
    if elements.is_empty() {
        return fail("part.elements", "expected at least one element");
    }
    let mut node_sets = BTreeMap::new();
    for (name, set) in &part.node_sets {
        if let Some(n) = set.iter().find(|&&n| n >= nodes.len()) {
            return fail(
                format!("part.node_sets.{name}"),
                format!("node {n} does not exist ({} nodes)", nodes.len()),
            );
        }
        let mut set = set.clone();
        set.sort_unstable();
        set.dedup();
        node_sets.insert(name.clone(), set);
    }
    let faces = element_faces::<D>(&elements);
    let mut surfaces = BTreeMap::new();
    for (name, list) in &part.surfaces {
        if list.is_empty() {
            return fail(
                format!("part.surfaces.{name}"),
                "expected at least one face",
            );
        }
        for (i, face) in list.iter().enumerate() {
            check_face(&format!("part.surfaces.{name}[{i}]"), face, &faces)?;
        }
        surfaces.insert(name.clone(), list.clone());
    }
    Ok(SolidMesh {
        nodes,
        elements,
        node_sets,
        surfaces,
    })
}

/// Every element face with its outward corner order, keyed by its sorted corner nodes.
fn element_faces<const D: usize>(elements: &[Vec<usize>]) -> BTreeMap<Vec<usize>, Vec<Vec<usize>>> {
    let mut faces: BTreeMap<Vec<usize>, Vec<Vec<usize>>> = BTreeMap::new();
    for conn in elements {
        for axis in 0..D {
            for upper in [false, true] {
                let local = face_corners::<D>(axis, upper).unwrap_or(&[]);
                let face: Vec<usize> = local.iter().map(|&c| conn[c]).collect();
                let mut key = face.clone();
                key.sort_unstable();
                faces.entry(key).or_default().push(face);
            }
        }
    }
    faces
}

/// `Ok` if `face` is an element face listed in its outward order (in 3D up to a cyclic shift;
/// a 2D edge reversed points inward).
fn check_face(
    field: &str,
    face: &[usize],
    faces: &BTreeMap<Vec<usize>, Vec<Vec<usize>>>,
) -> Result<(), SpecError> {
    let mut key = face.to_vec();
    key.sort_unstable();
    let Some(candidates) = faces.get(&key) else {
        return fail(
            field,
            format!("nodes {face:?} are not a face of any element"),
        );
    };
    let shifts = if face.len() > 2 { face.len() } else { 1 };
    let same_cycle = |a: &[usize], b: &[usize]| {
        (0..shifts).any(|shift| (0..a.len()).all(|k| a[(k + shift) % a.len()] == b[k]))
    };
    if candidates.iter().any(|c| same_cycle(c, face)) {
        Ok(())
    } else {
        fail(
            field,
            format!(
                "face {face:?} points into its element: list its nodes as {:?}",
                candidates[0]
            ),
        )
    }
}

/// Rejects degrees of freedom that do not exist in dimension `D`.
fn check_dofs<const D: usize>(field: &str, dofs: &[Dof]) -> Result<(), SpecError> {
    if dofs.is_empty() {
        return fail(field, "expected at least one degree of freedom");
    }
    match dofs.iter().find(|d| !Dof::all(D).contains(d)) {
        Some(d) => fail(field, format!("{d:?} is not a degree of freedom in {D}D")),
        None => Ok(()),
    }
}

fn body_names(spec: &ModelSpec) -> Result<BTreeMap<&str, usize>, SpecError> {
    let mut index = BTreeMap::new();
    for (i, b) in spec.rigid_bodies.iter().enumerate() {
        if b.name.is_empty() || index.insert(b.name.as_str(), i).is_some() {
            return fail(
                format!("rigid_bodies[{i}].name"),
                format!("expected a unique non-empty name, got '{}'", b.name),
            );
        }
    }
    Ok(index)
}

/// A rigid body whose motions are those `fixed` leaves free: no rotation, one about a global
/// axis, or (in 3D) all three.
fn rigid_body<const D: usize>(
    i: usize,
    b: &crate::model_spec::RigidBodySpec,
    fixed: &BTreeSet<Dof>,
) -> Result<RigidBody<D>, SpecError> {
    let f = |name: &str| format!("rigid_bodies[{i}].{name}");
    let reference_point = finite_point::<D>(&f("reference_point"), &b.reference_point)?;
    non_negative(&f("mass"), b.mass)?;
    non_negative(&f("rotary_inertia"), b.rotary_inertia)?;
    let tensor = inertia_tensor(&f, b)?;
    let free = |d: &Dof| !fixed.contains(d);
    let free_translations: [bool; D] =
        std::array::from_fn(|axis| [Dof::X, Dof::Y, Dof::Z][axis]).map(|d| free(&d));
    let free_rotations: Vec<usize> = Dof::all(D)
        .iter()
        .filter(|d| free(d))
        .filter_map(|d| d.rotation_axis())
        .collect();
    let initial_velocity = match &b.initial_velocity {
        Some(v) => finite_point::<D>(&f("initial_velocity"), v)?,
        None => SVector::zeros(),
    };
    if let Some(axis) = (0..D).find(|&a| !free_translations[a] && initial_velocity[a] != 0.0) {
        return fail(
            f("initial_velocity"),
            format!("the translation along axis {axis} is fixed: expected 0 there"),
        );
    }
    let w = vector3(
        &f("initial_angular_velocity"),
        b.initial_angular_velocity.unwrap_or([0.0; 3]),
    )?;
    let (rotation, rotary_inertia, initial_angular_velocity) = match free_rotations.as_slice() {
        [] if w.norm() == 0.0 => (Rotation::None, b.rotary_inertia, 0.0),
        [k] if (0..3).all(|a| a == *k || w[a] == 0.0) => {
            let axis = Vector3::ith(*k, 1.0);
            let inertia = tensor.map_or(b.rotary_inertia, |t| t[(*k, *k)]);
            (Rotation::Axis(axis), inertia, w[*k])
        }
        [_, _, _] => {
            let Some(tensor) = tensor else {
                return fail(
                    f("moments_of_inertia"),
                    format!(
                        "rigid body '{}' is free to turn about x, y and z: expected its moments \
                         of inertia [Ixx, Iyy, Izz]",
                        b.name
                    ),
                );
            };
            let (principal_inertia, principal_axes) = principal_axes(&tensor);
            let rotation = Rotation::Free {
                principal_inertia,
                principal_axes,
                initial_angular_velocity: w,
            };
            (rotation, 0.0, 0.0)
        }
        [] | [_] => {
            return fail(
                f("initial_angular_velocity"),
                format!(
                    "expected a vector along the free rotation axes {:?}, got {:?}",
                    free_rotations,
                    w.as_slice()
                ),
            );
        }
        two => {
            return fail(
                format!("rigid_bodies[{i}]"),
                format!(
                    "rigid body '{}' may rotate about the axes {two:?} only: a rigid body turns \
                     about no axis, one, or all three; fix the other with a boundary condition \
                     or free it",
                    b.name
                ),
            );
        }
    };
    Ok(RigidBody {
        name: b.name.clone(),
        reference_point,
        mass: b.mass,
        rotary_inertia,
        free_translations,
        rotation,
        initial_velocity,
        initial_angular_velocity,
    })
}

/// The inertia tensor about the reference node of body `b`, from its moments and products of
/// inertia (`None` without moments).
fn inertia_tensor(
    f: &dyn Fn(&str) -> String,
    b: &crate::model_spec::RigidBodySpec,
) -> Result<Option<Matrix3<f64>>, SpecError> {
    let Some(moments) = b.moments_of_inertia else {
        if b.products_of_inertia.is_some() {
            return fail(
                f("products_of_inertia"),
                "expected moments_of_inertia beside the products",
            );
        }
        return Ok(None);
    };
    if b.rotary_inertia != 0.0 {
        return fail(
            f("moments_of_inertia"),
            "give either rotary_inertia or moments_of_inertia, not both",
        );
    }
    let j = vector3(&f("moments_of_inertia"), moments)?;
    if let Some(k) = (0..3).find(|&k| j[k] < 0.0) {
        return fail(
            f("moments_of_inertia"),
            format!("expected moments >= 0, got {} at {k}", j[k]),
        );
    }
    let p = vector3(
        &f("products_of_inertia"),
        b.products_of_inertia.unwrap_or([0.0; 3]),
    )?;
    let tensor = Matrix3::new(j.x, p.x, p.y, p.x, j.y, p.z, p.y, p.z, j.z);
    if tensor.symmetric_eigenvalues().min() < -1e-12 * j.amax() {
        return fail(
            f("products_of_inertia"),
            format!(
                "the inertia tensor {tensor} is not positive semi-definite: no mass \
                 distribution has it"
            ),
        );
    }
    Ok(Some(tensor))
}

/// The principal moments and axes `(J, P)` of an inertia tensor `I = P diag(J) P^T`, `P` a
/// rotation; `P` is the identity for a diagonal tensor.
fn principal_axes(tensor: &Matrix3<f64>) -> (Vector3<f64>, Rotation3<f64>) {
    let diagonal = tensor.diagonal();
    if *tensor == Matrix3::from_diagonal(&diagonal) {
        return (diagonal, Rotation3::identity());
    }
    let eigen = tensor.symmetric_eigen();
    let mut axes = eigen.eigenvectors;
    if axes.determinant() < 0.0 {
        axes.column_mut(2).neg_mut();
    }
    (eigen.eigenvalues, Rotation3::from_matrix_unchecked(axes))
}

/// The contact surface of a body, in its body frame.
fn rigid_surface<const D: usize>(
    field: &str,
    spec: &RigidSurfaceSpec,
) -> Result<Box<dyn RigidSurface>, SpecError> {
    let invalid = |e: skid_contact::error::ContactError| SpecError {
        field: field.into(),
        message: e.to_string(),
    };
    Ok(match spec {
        RigidSurfaceSpec::Cylinder { radius, axis } => {
            positive(&format!("{field}.radius"), *radius)?;
            let axis = vector3(&format!("{field}.axis"), *axis)?;
            Box::new(AnalyticCylinder::new(*radius, axis).map_err(invalid)?)
        }
        RigidSurfaceSpec::Plane { normal, tangent } => Box::new(
            RigidPlane::new(
                vector3(&format!("{field}.normal"), *normal)?,
                vector3(&format!("{field}.tangent"), *tangent)?,
            )
            .map_err(invalid)?,
        ),
        RigidSurfaceSpec::FacetedCylinder {
            radius,
            axis,
            facets,
            phase,
        } => {
            positive(&format!("{field}.radius"), *radius)?;
            if !phase.is_finite() {
                return fail(
                    format!("{field}.phase"),
                    format!("expected a finite angle, got {phase}"),
                );
            }
            let axis = vector3(&format!("{field}.axis"), *axis)?;
            Box::new(FacetedCylinder::new(*radius, axis, *facets, *phase).map_err(invalid)?)
        }
        RigidSurfaceSpec::Polyline {
            points,
            centres,
            closed,
        } => {
            if D != 2 {
                return fail(field, "a polyline is a 2D surface");
            }
            Box::new(profile_polyline(points, centres, *closed).map_err(invalid)?)
        }
        RigidSurfaceSpec::Extrusion {
            axis,
            reference,
            profile: points,
            centres,
            closed,
        } => {
            if D != 3 {
                return fail(
                    field,
                    "an extrusion is a 3D surface (in 2D give a polyline)",
                );
            }
            Box::new(
                RigidExtrusion::new(
                    vector3(&format!("{field}.axis"), *axis)?,
                    vector3(&format!("{field}.reference"), *reference)?,
                    profile_polyline(points, centres, *closed).map_err(invalid)?,
                )
                .map_err(invalid)?,
            )
        }
        RigidSurfaceSpec::Revolution {
            axis,
            profile: points,
            centres,
            closed,
            radius,
        } => {
            if D != 3 {
                return fail(field, "a surface of revolution is a 3D surface");
            }
            let axis = vector3(&format!("{field}.axis"), *axis)?;
            let meridian = profile_polyline(points, centres, *closed).map_err(invalid)?;
            let radius = match radius {
                Some(r) => positive(&format!("{field}.radius"), *r).map(|()| *r)?,
                None => meridian.bounds().1.x,
            };
            Box::new(RigidRevolution::new(axis, meridian, radius).map_err(invalid)?)
        }
        RigidSurfaceSpec::Triangles {
            vertices,
            triangles,
            chart,
        } => {
            if D != 3 {
                return fail(field, "triangles are a 3D surface");
            }
            let vertices: Vec<Vector3<f64>> = vertices.iter().map(|v| Vector3::from(*v)).collect();
            let chart = match chart {
                ChartSpec::Cylinder { radius, axis } => {
                    positive(&format!("{field}.chart.radius"), *radius)?;
                    let cylinder = CylinderChart {
                        radius: *radius,
                        axis: vector3(&format!("{field}.chart.axis"), *axis)?,
                    };
                    if let Some(t) = cylinder.first_triangle_off(&vertices, triangles) {
                        return fail(
                            format!("{field}.triangles[{t}]"),
                            "a cylinder chart counts slip in its arc length, a length only on \
                             the cylinder; this triangle lies neither on a cylinder about its \
                             axis nor across it (an end face): give the mesh a plane chart, \
                             which measures slip in lengths on any mesh",
                        );
                    }
                    SurfaceChart::Cylinder(cylinder)
                }
                ChartSpec::Plane { normal, tangent } => SurfaceChart::Plane {
                    normal: vector3(&format!("{field}.chart.normal"), *normal)?,
                    tangent: vector3(&format!("{field}.chart.tangent"), *tangent)?,
                },
            };
            Box::new(TriangulatedSurface::new(vertices, triangles.clone(), chart).map_err(invalid)?)
        }
    })
}

/// General contact: the nodes of every surface of the part whose distance to `surface` (carried
/// by a body whose reference node is at `origin`) is below `search_distance` in the initial
/// configuration, sorted.
fn nodes_near<const D: usize>(
    mesh: &SolidMesh<D>,
    surface: &dyn RigidSurface,
    origin: &SVector<f64, D>,
    search_distance: f64,
) -> Vec<usize> {
    let mut nodes: Vec<usize> = mesh
        .surfaces
        .values()
        .flat_map(|faces| faces.iter().flatten().copied())
        .filter(|&n| {
            surface
                .project(&embed(&(mesh.nodes[n] - origin)))
                .is_some_and(|p| p.gap < search_distance)
        })
        .collect();
    nodes.sort_unstable();
    nodes.dedup();
    nodes
}

fn step<const D: usize>(
    i: usize,
    spec: &ModelStepSpec,
    of: (
        &impl Fn(&str, &str) -> Result<usize, SpecError>,
        &impl Fn(&str, &str) -> Result<Vec<usize>, SpecError>,
    ),
) -> Result<Step, SpecError> {
    let f = |name: &str| format!("steps[{i}].{name}");
    let (name, boundary) = match spec {
        ModelStepSpec::Static { name, boundary, .. }
        | ModelStepSpec::Dynamic { name, boundary, .. } => (name, boundary),
    };
    if name.is_empty() {
        return fail(f("name"), "expected a non-empty name");
    }
    let held = held_motions::<D>(&f("boundary"), boundary, of)?;
    let kind = match spec {
        ModelStepSpec::Static {
            increments,
            automatic,
            regularization_time,
            time_period,
            ..
        } => {
            let increments = match (increments, automatic) {
                (Some(0), None) => return fail(f("increments"), "expected at least 1"),
                (Some(n), None) => StaticIncrements::Fixed(*n),
                (None, Some(a)) => {
                    let ok = a.min > 0.0 && a.min <= a.initial && a.initial <= a.max;
                    if !(ok && a.max <= 1.0) {
                        return fail(
                            f("automatic"),
                            format!(
                                "expected 0 < min <= initial <= max <= 1, got min {}, initial \
                                 {}, max {}",
                                a.min, a.initial, a.max
                            ),
                        );
                    }
                    StaticIncrements::Automatic {
                        initial: a.initial,
                        min: a.min,
                        max: a.max,
                    }
                }
                _ => {
                    return fail(
                        f("increments"),
                        "expected exactly one of increments (fixed) and automatic",
                    );
                }
            };
            positive(&f("regularization_time"), *regularization_time)?;
            if let Some(period) = time_period {
                positive(&f("time_period"), *period)?;
            }
            StepKind::Static {
                increments,
                regularization_time: *regularization_time,
            }
        }
        ModelStepSpec::Dynamic {
            duration,
            dt,
            alpha,
            adaptive,
            ..
        } => {
            check_dynamic_timing(*duration, *dt, *alpha, adaptive.as_ref()).map_err(
                |(field, message)| SpecError {
                    field: f(&field),
                    message,
                },
            )?;
            StepKind::Dynamic {
                duration: *duration,
                dt: *dt,
                alpha: *alpha,
                adaptive: adaptive.map(|a| Adaptive {
                    tolerance: a.tolerance,
                    min_dt: a.min_dt,
                    max_dt: a.max_dt,
                }),
            }
        }
    };
    Ok(Step {
        name: name.clone(),
        kind,
        held,
    })
}

/// Checks a dynamic step's timing: `0 < dt <= duration`, an admissible HHT `alpha`, and for
/// adaptive increments `min_dt <= dt <= max_dt <= duration` with a positive tolerance.
///
/// # Errors
/// The first problem as (field name within the step, what was expected).
pub fn check_dynamic_timing(
    duration: f64,
    dt: f64,
    alpha: f64,
    adaptive: Option<&AdaptiveSpec>,
) -> Result<(), (String, String)> {
    let positive = |field: &str, v: f64| positive(field, v).map_err(|e| (e.field, e.message));
    positive("duration", duration)?;
    positive("dt", dt)?;
    if dt > duration {
        return Err(("dt".into(), format!("expected dt <= duration ({duration})")));
    }
    if let Some(a) = adaptive {
        positive("adaptive.tolerance", a.tolerance)?;
        positive("adaptive.min_dt", a.min_dt)?;
        positive("adaptive.max_dt", a.max_dt)?;
        if a.min_dt > dt {
            return Err((
                "adaptive.min_dt".into(),
                format!("expected min_dt <= dt ({dt})"),
            ));
        }
        if a.max_dt < dt || a.max_dt > duration {
            return Err((
                "adaptive.max_dt".into(),
                format!("expected dt ({dt}) <= max_dt <= duration ({duration})"),
            ));
        }
    }
    // The integrator owns the admissible range; its message names it.
    skid_integrator::hht::Hht::new(alpha).map_err(|message| ("alpha".to_string(), message))?;
    Ok(())
}

/// The motions a step's `boundary` (`field`) holds: of rigid bodies (`body_of`), or the
/// translations of every node of a node set (`nodes_of`, which refuses sets with tied nodes).
fn held_motions<const D: usize>(
    field: &str,
    boundary: &[StepBoundarySpec],
    (body_of, nodes_of): (
        &impl Fn(&str, &str) -> Result<usize, SpecError>,
        &impl Fn(&str, &str) -> Result<Vec<usize>, SpecError>,
    ),
) -> Result<Vec<HeldMotion>, SpecError> {
    let mut held = Vec::new();
    for (k, bc) in boundary.iter().enumerate() {
        let f = |name: &str| format!("{field}[{k}].{name}");
        let body = match (&bc.body, &bc.node_set) {
            (Some(body), None) => body_of(&f("body"), body)?,
            (None, Some(set)) => {
                let nodes = nodes_of(&f("node_set"), set)?;
                let axes: Vec<usize> = match &bc.dofs {
                    None => (0..D).collect(),
                    Some(dofs) => {
                        check_dofs::<D>(&f("dofs"), dofs)?;
                        dofs.iter()
                            .map(|dof| {
                                dof.translation_axis().ok_or_else(|| SpecError {
                                    field: f("dofs"),
                                    message: format!(
                                        "the nodes of a solid have no rotation {dof:?}"
                                    ),
                                })
                            })
                            .collect::<Result<_, _>>()?
                    }
                };
                for &node in &nodes {
                    held.extend(axes.iter().map(|&axis| HeldMotion::Node { node, axis }));
                }
                continue;
            }
            _ => {
                return fail(
                    format!("{field}[{k}]"),
                    "expected exactly one of body and node_set",
                );
            }
        };
        let Some(dofs) = &bc.dofs else {
            held.push(HeldMotion::body(body));
            continue;
        };
        check_dofs::<D>(&format!("{field}[{k}].dofs"), dofs)?;
        for dof in dofs {
            let motion = match (dof.translation_axis(), dof.rotation_axis()) {
                (Some(axis), _) => BodyMotion::Translation(axis),
                // a body has one rotation equation; holding any rotation holds it
                _ => BodyMotion::Rotation,
            };
            held.push(HeldMotion::Body {
                body,
                motion: Some(motion),
            });
        }
    }
    Ok(held)
}

/// Checks that every step holding rotations of a body free to turn holds all three: a hold
/// fixes its rotation unknowns, material increments about its own axes, which are the global
/// axes only at the start, so that one of them alone is not a rotation about a global axis.
fn whole_rotation_holds<const D: usize>(
    spec: &ModelSpec,
    bodies: &[RigidBody<D>],
    body_of: &impl Fn(&str, &str) -> Result<usize, SpecError>,
) -> Result<(), SpecError> {
    for (i, step) in spec.steps.iter().enumerate() {
        let (ModelStepSpec::Static { boundary, .. } | ModelStepSpec::Dynamic { boundary, .. }) =
            step;
        for (k, bc) in boundary.iter().enumerate() {
            let (Some(name), Some(dofs)) = (&bc.body, &bc.dofs) else {
                continue;
            };
            let field = format!("steps[{i}].boundary[{k}].dofs");
            let body = body_of(&field, name)?;
            let rotations = [Dof::Rx, Dof::Ry, Dof::Rz]
                .iter()
                .filter(|d| dofs.contains(d))
                .count();
            if matches!(bodies[body].rotation, Rotation::Free { .. }) && rotations % 3 != 0 {
                return fail(
                    field,
                    format!(
                        "rigid body '{name}' is free to turn: a step holds all its rotations \
                         (rx, ry, rz) or none"
                    ),
                );
            }
        }
    }
    Ok(())
}

/// Solver settings; `auto` takes the contact solve `preferred` for the model
/// ([`SolverSpec::contact_solve_with`]).
fn solver_settings(s: &SolverSpec, preferred: ContactSolve) -> Result<Settings, SpecError> {
    if s.max_newton_iterations == 0 {
        return fail("solver.max_newton_iterations", "expected at least 1");
    }
    positive("solver.force_tolerance", s.force_tolerance)?;
    positive("solver.contact_tolerance", s.contact_tolerance)?;
    positive("solver.coulomb_tolerance", s.coulomb_tolerance)?;
    if s.max_fixed_point_iterations == 0 {
        return fail("solver.max_fixed_point_iterations", "expected at least 1");
    }
    if !(s.cutback_factor > 0.0 && s.cutback_factor < 1.0) {
        return fail(
            "solver.cutback_factor",
            format!("expected a value in (0, 1), got {}", s.cutback_factor),
        );
    }
    Ok(Settings {
        newton: NewtonSettings {
            max_iterations: s.max_newton_iterations,
            force_tolerance: s.force_tolerance,
            contact_tolerance: s.contact_tolerance,
        },
        coulomb: skid_contact::coulomb::CoulombSettings {
            tolerance: s.coulomb_tolerance,
            max_fixed_point_iterations: s.max_fixed_point_iterations,
            method: s.coulomb_method.into(),
            ..Default::default()
        },
        contact_solve: s.contact_solve_with(preferred),
        cutback: CutbackSettings {
            factor: s.cutback_factor,
            max_cutbacks: s.max_cutbacks,
            ..Default::default()
        },
    })
}
