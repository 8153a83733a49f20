//! Definitions of a deck turned into a [`ModelSpec`]: the deformable part renumbered from 0 in
//! the order of `*NODE` and `*ELEMENT`, rigid bodies with their reference nodes, masses and
//! surfaces, boundary conditions split between bodies and part nodes, contact, initial
//! velocities and steps. Every reference is resolved here, and a deck that the model file
//! cannot express exactly is refused at the line that asks for it.

use std::collections::{BTreeMap, BTreeSet, HashMap};

use nalgebra::{Matrix3, Vector3};
use skid_fem::tetra::TetMesh;

use super::fields::key;
use super::keywords::{DeckError, Location};
use super::mesh::ElementKind;
use super::read::{
    BoundaryDef, Change, Definitions, FaceLabel, InitialDef, PressureDef, Procedure, RigidDef,
    SectionKind, StepDef, SurfaceDef,
};
use super::rigid::{prism, triangles};
use crate::model_file::spec::{
    BoundarySpec, ContactPairSpec, Dof, ElementBlockSpec, ElementType, LoadSpec,
    MODEL_FORMAT_VERSION, ModelSpec, ModelStepSpec, PartSpec, RigidBodySpec, RigidSurfaceSpec,
    SectionSpec, SlaveSpec, StepBoundarySpec, TieSpec,
};
use crate::schema::{OutputSpec, SolverSpec, default_regularization_time};

fn error(location: &Location, message: impl Into<String>) -> DeckError {
    DeckError {
        location: location.clone(),
        message: message.into(),
    }
}

/// The part: dimension, node numbering, and which labels are part nodes.
struct Part {
    dimension: usize,
    number: HashMap<u64, usize>,
    labels: Vec<u64>,
    elements: Vec<u64>,
}

/// A rigid body being assembled.
struct Body {
    def: RigidDef,
    reference: Vector3<f64>,
    fixed: BTreeSet<usize>,
}

/// Builds the model of `defs`; `name` is the model's name (the deck's file stem).
///
/// # Errors
/// [`DeckError`] at the definition that cannot be resolved or expressed.
pub fn assemble(defs: &Definitions, name: &str, deck: &Location) -> Result<ModelSpec, DeckError> {
    defs.mesh.check_references()?;
    let part = part_numbering(defs, deck)?;
    let dim = part.dimension;
    let part_spec = part_spec(defs, &part, deck)?;
    let mut bodies = rigid_bodies(defs, &part)?;
    let mut spec_boundary = Vec::new();
    let mut node_sets = part_spec.node_sets.clone();
    for (i, bc) in defs.boundary.iter().enumerate() {
        apply_model_boundary(
            defs,
            &part,
            &mut bodies,
            bc,
            i,
            &mut node_sets,
            &mut spec_boundary,
        )?;
    }
    let mut part_spec = part_spec;
    part_spec.node_sets = node_sets;

    let mut rigid_specs = Vec::new();
    for body in &bodies {
        rigid_specs.push(body_spec(defs, &part, body)?);
    }
    // surfaces of rigid bodies, from the contact definitions that use them
    let mut contact = Vec::new();
    let mut used_interactions: BTreeMap<String, usize> = BTreeMap::new();
    for (interaction, _, _, _) in &defs.pairs {
        *used_interactions.entry(key(interaction)).or_default() += 1;
    }
    for (interaction, slave, master, location) in &defs.pairs {
        let mu = friction(defs, interaction, location)?;
        let (b, surface, range) = master_surface(defs, &part, &bodies, master, location)?;
        set_body_surface(&mut rigid_specs[b], surface, location)?;
        let slave_nodes = slave_nodes(defs, &part, slave, location)?;
        if let Some(range) = range {
            check_axial_range(
                defs,
                &part,
                &bodies[b],
                &rigid_specs[b],
                &slave_nodes,
                range,
                location,
            )?;
        }
        let set_name = slave_set_name(&part_spec.node_sets, slave, &slave_nodes);
        part_spec.node_sets.insert(set_name.clone(), slave_nodes);
        let pair_name = if used_interactions.get(&key(interaction)) == Some(&1) {
            defs.interactions
                .get(&key(interaction))
                .map_or_else(|| interaction.clone(), |i| i.name.clone())
        } else {
            format!("{slave}-{master}")
        };
        contact.push(ContactPairSpec {
            name: pair_name,
            slave: SlaveSpec::NodeSet { name: set_name },
            master: bodies[b].def.name.clone(),
            mu,
        });
    }
    if let Some(general) = &defs.general {
        if !general.all_exterior {
            return Err(error(
                &general.location,
                "*CONTACT: add *CONTACT INCLUSIONS, ALL EXTERIOR",
            ));
        }
        let interaction = general.interaction.as_deref().ok_or_else(|| {
            error(
                &general.location,
                "*CONTACT: add *CONTACT PROPERTY ASSIGNMENT with ', , interaction'",
            )
        })?;
        let mu = friction(defs, interaction, &general.location)?;
        for (b, body) in bodies.iter().enumerate() {
            if rigid_specs[b].surface.is_none()
                && let Some(surface) = all_facets(defs, &part, body)?
            {
                rigid_specs[b].surface = Some(surface);
            }
        }
        let with_surface: Vec<usize> = (0..bodies.len())
            .filter(|&b| rigid_specs[b].surface.is_some())
            .collect();
        if with_surface.is_empty() {
            return Err(error(
                &general.location,
                "*CONTACT: no rigid body has a surface",
            ));
        }
        // every exterior face of the part is a surface, so that every exterior node is a
        // candidate (skid's general contact keeps the nodes of the part's surfaces)
        let exterior = exterior_faces(defs, &part, &part.elements);
        let mut surface_name = "exterior".to_string();
        while part_spec.surfaces.contains_key(&surface_name) {
            surface_name.push('_');
        }
        part_spec.surfaces.insert(surface_name, exterior);
        let interaction_name = defs
            .interactions
            .get(&key(interaction))
            .map_or_else(|| interaction.to_string(), |i| i.name.clone());
        for &b in &with_surface {
            contact.push(ContactPairSpec {
                name: if with_surface.len() == 1 {
                    interaction_name.clone()
                } else {
                    format!("{interaction_name}-{}", bodies[b].def.name)
                },
                slave: SlaveSpec::General {
                    search_distance: f64::MAX,
                },
                master: bodies[b].def.name.clone(),
                mu,
            });
        }
    }
    for def in &defs.initial {
        apply_initial(defs, &part, &bodies, &mut rigid_specs, def)?;
    }
    let ties = bodies
        .iter()
        .filter_map(|b| b.def.tie.as_ref().map(|t| (b, t)))
        .map(|(b, tie)| {
            let nodes = part_nodes(defs, &part, tie, &b.def.location)?;
            let set_name = defs
                .mesh
                .node_sets
                .get(&key(tie))
                .map_or_else(|| tie.clone(), |s| s.name.clone());
            part_spec.node_sets.insert(set_name.clone(), nodes);
            Ok(TieSpec {
                node_set: set_name,
                body: b.def.name.clone(),
            })
        })
        .collect::<Result<Vec<_>, DeckError>>()?;
    check_held_ties(defs, &part, &bodies)?;
    let (steps, loads) = steps(defs, &part, &bodies, &mut part_spec, deck)?;
    Ok(ModelSpec {
        skid_model: MODEL_FORMAT_VERSION,
        name: name.to_string(),
        description: defs.heading.clone(),
        dimension: dim,
        part: part_spec,
        rigid_bodies: rigid_specs,
        boundary: spec_boundary,
        ties,
        loads,
        contact,
        steps,
        solver: SolverSpec::default(),
        output: OutputSpec::default(),
    })
}

fn part_numbering(defs: &Definitions, deck: &Location) -> Result<Part, DeckError> {
    let elements: Vec<u64> = defs
        .mesh
        .element_order
        .iter()
        .copied()
        .filter(|e| defs.mesh.elements[e].kind.is_solid())
        .collect();
    let Some(first) = elements.first() else {
        return Err(error(
            deck,
            "the deck has no deformable elements (CPE4R or C3D8R): skid needs one deformable part",
        ));
    };
    let kind = defs.mesh.elements[first].kind;
    if let Some(other) = elements
        .iter()
        .find(|e| defs.mesh.elements[*e].kind != kind)
    {
        return Err(error(
            &defs.mesh.elements[other].location,
            "*ELEMENT: CPE4R and C3D8R elements cannot share a model (2D or 3D)",
        ));
    }
    let dimension = if kind == ElementKind::Cpe4r { 2 } else { 3 };
    let used: BTreeSet<u64> = elements
        .iter()
        .flat_map(|e| defs.mesh.elements[e].nodes.iter().copied())
        .collect();
    let labels: Vec<u64> = defs
        .mesh
        .node_order
        .iter()
        .copied()
        .filter(|n| used.contains(n))
        .collect();
    let number = labels.iter().enumerate().map(|(i, n)| (*n, i)).collect();
    Ok(Part {
        dimension,
        number,
        labels,
        elements,
    })
}

fn part_spec(defs: &Definitions, part: &Part, deck: &Location) -> Result<PartSpec, DeckError> {
    let dim = part.dimension;
    let solid_sections: Vec<_> = defs
        .sections
        .iter()
        .filter(|s| {
            s.kind == SectionKind::Solid
                && defs
                    .mesh
                    .elements_named(&s.elset)
                    .is_some_and(|es| es.iter().any(|e| defs.mesh.elements[e].kind.is_solid()))
        })
        .collect();
    let [section] = solid_sections.as_slice() else {
        return Err(error(
            solid_sections.get(1).map_or(deck, |s| &s.location),
            format!(
                "expected one *SOLID SECTION for the deformable elements, found {} (one \
                 material per part so far)",
                solid_sections.len()
            ),
        ));
    };
    let members: BTreeSet<u64> = defs
        .mesh
        .elements_named(&section.elset)
        .unwrap_or_default()
        .into_iter()
        .collect();
    if let Some(e) = part.elements.iter().find(|e| !members.contains(e)) {
        return Err(error(
            &defs.mesh.elements[e].location,
            format!(
                "element {e} has no section: the *SOLID SECTION's ELSET={} does not hold it",
                section.elset
            ),
        ));
    }
    let material = defs.materials.get(&key(&section.material)).ok_or_else(|| {
        error(
            &section.location,
            format!("*SOLID SECTION: no *MATERIAL named {}", section.material),
        )
    })?;
    let law = material.value.law.clone().ok_or_else(|| {
        error(
            &material.location,
            format!(
                "*MATERIAL {}: give *HYPERELASTIC or *ELASTIC",
                material.name
            ),
        )
    })?;
    let density = material.value.density.ok_or_else(|| {
        error(
            &material.location,
            format!("*MATERIAL {}: give *DENSITY", material.name),
        )
    })?;
    let thickness = match (dim, section.thickness) {
        (2, t) => t.unwrap_or(1.0),
        (_, Some(t)) if t != 1.0 => {
            return Err(error(
                &section.location,
                format!("*SOLID SECTION: a 3D solid takes no thickness (got {t})"),
            ));
        }
        _ => 1.0,
    };
    let mut nodes = vec![Vec::new(); part.number.len()];
    for (label, &i) in &part.number {
        nodes[i] = defs.mesh.nodes[label][..dim].to_vec();
    }
    let connectivity = part
        .elements
        .iter()
        .map(|e| {
            defs.mesh.elements[e]
                .nodes
                .iter()
                .map(|n| part.number[n])
                .collect()
        })
        .collect();
    let mut node_sets = BTreeMap::new();
    for set in defs.mesh.node_sets.values() {
        if !set.labels.is_empty() && set.labels.iter().all(|n| part.number.contains_key(n)) {
            node_sets.insert(
                set.name.clone(),
                set.labels.iter().map(|n| part.number[n]).collect(),
            );
        }
    }
    let mut surfaces = BTreeMap::new();
    for surface in defs.surfaces.values() {
        if let SurfaceDef::Faces(faces) = &surface.value
            && faces
                .iter()
                .all(|(e, _)| defs.mesh.elements[e].kind.is_solid())
        {
            surfaces.insert(
                surface.name.clone(),
                solid_faces(defs, part, faces, &surface.location)?,
            );
        }
    }
    Ok(PartSpec {
        name: section.elset.clone(),
        nodes,
        elements: vec![ElementBlockSpec {
            kind: ElementType::solid(dim),
            connectivity,
        }],
        node_sets,
        surfaces,
        section: SectionSpec {
            material: law,
            density,
            thickness,
            hourglass_scale: 1.0,
            quasi_static: false,
        },
    })
}

/// Faces of solid elements as part node numbers, outward.
fn solid_faces(
    defs: &Definitions,
    part: &Part,
    faces: &[(u64, FaceLabel)],
    location: &Location,
) -> Result<Vec<Vec<usize>>, DeckError> {
    let mut out = Vec::new();
    let mut exterior_of = Vec::new();
    for (e, face) in faces {
        let element = &defs.mesh.elements[e];
        match face {
            FaceLabel::Numbered(k) => {
                let corners = element.kind.face(*k).ok_or_else(|| {
                    error(
                        location,
                        format!(
                            "*SURFACE: element {e} has faces S1 to S{}, not S{k}",
                            element.kind.face_count()
                        ),
                    )
                })?;
                out.push(
                    corners
                        .iter()
                        .map(|&c| part.number[&element.nodes[c]])
                        .collect(),
                );
            }
            FaceLabel::Exterior => exterior_of.push(*e),
            FaceLabel::Positive | FaceLabel::Negative => {
                return Err(error(
                    location,
                    format!(
                        "*SURFACE: SPOS and SNEG name sides of shells and rigid elements, not of solid element {e}"
                    ),
                ));
            }
        }
    }
    if !exterior_of.is_empty() {
        out.extend(exterior_faces(defs, part, &exterior_of));
    }
    Ok(out)
}

/// The faces of `elements` that no other element of the part shares, outward.
fn exterior_faces(defs: &Definitions, part: &Part, elements: &[u64]) -> Vec<Vec<usize>> {
    let face_list = |e: &u64| {
        let element = &defs.mesh.elements[e];
        (1..=element.kind.face_count())
            .filter_map(|k| element.kind.face(k))
            .map(|corners| {
                corners
                    .iter()
                    .map(|&c| part.number[&element.nodes[c]])
                    .collect::<Vec<usize>>()
            })
            .collect::<Vec<_>>()
    };
    let mut count: HashMap<Vec<usize>, usize> = HashMap::new();
    for e in &part.elements {
        for face in face_list(e) {
            let mut k = face.clone();
            k.sort_unstable();
            *count.entry(k).or_default() += 1;
        }
    }
    elements
        .iter()
        .flat_map(face_list)
        .filter(|face| {
            let mut k = face.clone();
            k.sort_unstable();
            count.get(&k) == Some(&1)
        })
        .collect()
}

fn rigid_bodies(defs: &Definitions, part: &Part) -> Result<Vec<Body>, DeckError> {
    let mut owner: HashMap<u64, usize> = HashMap::new();
    let mut bodies = Vec::new();
    for (b, def) in defs.rigid_bodies.iter().enumerate() {
        if part.number.contains_key(&def.reference) {
            return Err(error(
                &def.location,
                format!(
                    "*RIGID BODY: reference node {} belongs to the deformable part",
                    def.reference
                ),
            ));
        }
        if let Some(elset) = &def.elset {
            let elements = defs.mesh.elements_named(elset).ok_or_else(|| {
                error(
                    &def.location,
                    format!("*RIGID BODY: no element set named {elset}"),
                )
            })?;
            if elements.is_empty() {
                return Err(error(
                    &def.location,
                    format!(
                        "*RIGID BODY: ELSET={elset} holds no elements, so the body has no nodes"
                    ),
                ));
            }
            for e in elements {
                let kind = defs.mesh.elements[&e].kind;
                if kind.is_solid() {
                    return Err(error(
                        &def.location,
                        format!(
                            "*RIGID BODY: element {e} of ELSET={elset} is a deformable {kind:?}: only R2D2, R3D4, M3D4R, S4R and C3D4 elements are made rigid"
                        ),
                    ));
                }
                if owner.insert(e, b).is_some() {
                    return Err(error(
                        &def.location,
                        format!("*RIGID BODY: element {e} belongs to two rigid bodies"),
                    ));
                }
            }
        }
        let x = defs.mesh.nodes[&def.reference];
        bodies.push(Body {
            def: def.clone(),
            reference: Vector3::from(x),
            fixed: BTreeSet::new(),
        });
    }
    for e in &defs.mesh.element_order {
        let element = &defs.mesh.elements[e];
        let rigid_kind = !element.kind.is_solid()
            && !matches!(element.kind, ElementKind::Mass | ElementKind::RotaryI);
        if rigid_kind && !owner.contains_key(e) {
            return Err(error(
                &element.location,
                format!(
                    "element {e} ({:?}) belongs to no *RIGID BODY: skid's only deformable elements are CPE4R and C3D8R",
                    element.kind
                ),
            ));
        }
    }
    // rigid elements' sections carry no mass
    for section in &defs.sections {
        if section.kind == SectionKind::Solid
            && defs
                .mesh
                .elements_named(&section.elset)
                .is_some_and(|es| es.iter().any(|e| defs.mesh.elements[e].kind.is_solid()))
        {
            continue;
        }
        let density = defs
            .materials
            .get(&key(&section.material))
            .and_then(|m| m.value.density)
            .unwrap_or(0.0);
        if density != 0.0 {
            return Err(error(
                &section.location,
                format!(
                    "the section of rigid elements ELSET={} has density {density}: give the \
                     rigid body's mass and inertia with *MASS and *ROTARY INERTIA at its \
                     reference node and density 0 for its elements",
                    section.elset
                ),
            ));
        }
    }
    Ok(bodies)
}

/// The body and rigid-node role of a node label.
enum NodeRole {
    Part(usize),
    Reference(usize),
    Other,
}

fn role(part: &Part, bodies: &[Body], label: u64) -> NodeRole {
    if let Some(&i) = part.number.get(&label) {
        NodeRole::Part(i)
    } else if let Some(b) = bodies.iter().position(|b| b.def.reference == label) {
        NodeRole::Reference(b)
    } else {
        NodeRole::Other
    }
}

fn dof_of(dim: usize, k: usize, location: &Location) -> Result<Dof, DeckError> {
    match (dim, k) {
        (_, 1) => Ok(Dof::X),
        (_, 2) => Ok(Dof::Y),
        (3, 3) => Ok(Dof::Z),
        (3, 4) => Ok(Dof::Rx),
        (3, 5) => Ok(Dof::Ry),
        (_, 6) => Ok(Dof::Rz),
        _ => Err(error(
            location,
            format!("degree of freedom {k} does not exist in 2D (1, 2 and 6 do)"),
        )),
    }
}

fn apply_model_boundary(
    defs: &Definitions,
    part: &Part,
    bodies: &mut [Body],
    bc: &BoundaryDef,
    index: usize,
    node_sets: &mut BTreeMap<String, Vec<usize>>,
    out: &mut Vec<BoundarySpec>,
) -> Result<(), DeckError> {
    let dim = part.dimension;
    let labels = defs.mesh.nodes_named(&bc.target).ok_or_else(|| {
        error(
            &bc.location,
            format!(
                "*BOUNDARY: '{}' is neither a node nor a node set",
                bc.target
            ),
        )
    })?;
    let mut part_nodes = Vec::new();
    for label in labels {
        match role(part, bodies, label) {
            NodeRole::Reference(b) => {
                let mut dofs = Vec::new();
                for &k in &bc.dofs {
                    // a 2D body has no z translation and no in-plane rotations
                    if dim == 2 && (3..=5).contains(&k) && bc.dofs.len() > 1 {
                        continue;
                    }
                    dofs.push(dof_of(dim, k, &bc.location)?);
                    bodies[b].fixed.insert(k);
                }
                out.push(BoundarySpec {
                    body: Some(bodies[b].def.name.clone()),
                    node_set: None,
                    dofs,
                });
            }
            NodeRole::Part(i) => part_nodes.push(i),
            NodeRole::Other => {
                return Err(error(
                    &bc.location,
                    format!(
                        "*BOUNDARY: node {label} is a node of a rigid body but not its reference \
                         node: hold the reference node"
                    ),
                ));
            }
        }
    }
    if !part_nodes.is_empty() {
        let mut dofs = Vec::new();
        for &k in &bc.dofs {
            match k {
                1..=3 if k <= dim => dofs.push(dof_of(dim, k, &bc.location)?),
                // solid nodes have no rotations (ENCASTRE and symmetry conditions name them)
                4..=6 if bc.dofs.len() > 1 => {}
                _ => {
                    return Err(error(
                        &bc.location,
                        format!(
                            "*BOUNDARY: degree of freedom {k} does not exist on the nodes of a {dim}D solid"
                        ),
                    ));
                }
            }
        }
        let name = defs
            .mesh
            .node_sets
            .get(&key(&bc.target))
            .filter(|s| s.labels.iter().all(|n| part.number.contains_key(n)))
            .map_or_else(|| format!("boundary-{index}"), |s| s.name.clone());
        node_sets.insert(name.clone(), part_nodes);
        out.push(BoundarySpec {
            body: None,
            node_set: Some(name),
            dofs,
        });
    }
    Ok(())
}

/// Refuses a model-data boundary condition on a part node that a `TIE NSET` ties to a rigid
/// body: the tied node moves with the body, so holding it contradicts the tie.
fn check_held_ties(defs: &Definitions, part: &Part, bodies: &[Body]) -> Result<(), DeckError> {
    for body in bodies {
        let Some(tie) = &body.def.tie else { continue };
        let tied = defs.mesh.nodes_named(tie).unwrap_or_default();
        for bc in &defs.boundary {
            let held = defs.mesh.nodes_named(&bc.target).unwrap_or_default();
            if let Some(n) = held
                .iter()
                .find(|n| part.number.contains_key(n) && tied.contains(n))
            {
                return Err(error(
                    &bc.location,
                    format!(
                        "*BOUNDARY: node {n} is held here and tied to rigid body {} by TIE \
                         NSET={tie} (a tied node moves with its body): hold the body's reference \
                         node instead",
                        body.def.name
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// The axis of a body's one free rotation, if it has exactly one.
fn free_axis(dim: usize, body: &Body) -> Option<Vector3<f64>> {
    if dim == 2 {
        return (!body.fixed.contains(&6)).then(Vector3::z);
    }
    let free: Vec<usize> = (4..=6).filter(|k| !body.fixed.contains(k)).collect();
    match free.as_slice() {
        [k] => Some(Vector3::ith(k - 4, 1.0)),
        _ => None,
    }
}

fn body_spec(defs: &Definitions, part: &Part, body: &Body) -> Result<RigidBodySpec, DeckError> {
    let dim = part.dimension;
    let mut mass = 0.0;
    for (elset, m, location) in &defs.masses {
        let elements = defs
            .mesh
            .elements_named(elset)
            .ok_or_else(|| error(location, format!("*MASS: no element set named {elset}")))?;
        for e in elements {
            let el = &defs.mesh.elements[&e];
            if el.kind != ElementKind::Mass {
                return Err(error(
                    location,
                    format!("*MASS: element {e} is not a MASS element"),
                ));
            }
            if el.nodes[0] == body.def.reference {
                mass += m;
            }
        }
    }
    let mut inertia = Matrix3::zeros();
    for (elset, i, location) in &defs.inertias {
        let elements = defs.mesh.elements_named(elset).ok_or_else(|| {
            error(
                location,
                format!("*ROTARY INERTIA: no element set named {elset}"),
            )
        })?;
        for e in elements {
            let el = &defs.mesh.elements[&e];
            if el.kind != ElementKind::RotaryI {
                return Err(error(
                    location,
                    format!("*ROTARY INERTIA: element {e} is not a ROTARYI element"),
                ));
            }
            if el.nodes[0] == body.def.reference {
                inertia += Matrix3::new(i[0], i[3], i[4], i[3], i[1], i[5], i[4], i[5], i[2]);
            }
        }
    }
    // point elements elsewhere than at a reference node
    for kind in [ElementKind::Mass, ElementKind::RotaryI] {
        for e in &defs.mesh.element_order {
            let el = &defs.mesh.elements[e];
            if el.kind == kind && !defs.rigid_bodies.iter().any(|b| b.reference == el.nodes[0]) {
                return Err(error(
                    &el.location,
                    format!(
                        "element {e}: point masses and inertias sit at rigid-body reference nodes only"
                    ),
                ));
            }
        }
    }
    let rotary_inertia = match free_axis(dim, body) {
        Some(e) => (e.transpose() * inertia * e)[(0, 0)],
        None => inertia[(2, 2)],
    };
    let analytical = match &body.def.analytical {
        Some(name) => {
            let surface = defs.surfaces.get(&key(name)).ok_or_else(|| {
                error(
                    &body.def.location,
                    format!("*RIGID BODY: no surface named {name}"),
                )
            })?;
            let SurfaceDef::Analytical(a) = &surface.value else {
                return Err(error(
                    &body.def.location,
                    format!(
                        "*RIGID BODY: ANALYTICAL SURFACE={name} is not an analytical surface (TYPE=SEGMENTS, CYLINDER or REVOLUTION)"
                    ),
                ));
            };
            Some(
                a.spec(&body.reference).map_err(|m| {
                    error(&surface.location, format!("*SURFACE {}: {m}", surface.name))
                })?,
            )
        }
        None => None,
    };
    Ok(RigidBodySpec {
        name: body.def.name.clone(),
        reference_point: body.reference.as_slice()[..dim].to_vec(),
        mass,
        rotary_inertia,
        surface: analytical,
        initial_velocity: None,
        initial_angular_velocity: None,
    })
}

fn friction(defs: &Definitions, interaction: &str, location: &Location) -> Result<f64, DeckError> {
    defs.interactions
        .get(&key(interaction))
        .map(|i| i.value)
        .ok_or_else(|| {
            error(
                location,
                format!("no *SURFACE INTERACTION named {interaction}"),
            )
        })
}

fn set_body_surface(
    body: &mut RigidBodySpec,
    surface: Option<RigidSurfaceSpec>,
    location: &Location,
) -> Result<(), DeckError> {
    match (&body.surface, surface) {
        (_, None) => Ok(()),
        (None, Some(s)) => {
            body.surface = Some(s);
            Ok(())
        }
        (Some(old), Some(s)) if *old == s => Ok(()),
        (Some(_), Some(_)) => Err(error(
            location,
            format!(
                "rigid body {} would get a second surface: one surface per rigid body",
                body.name
            ),
        )),
    }
}

/// The body a master surface belongs to, its surface built from facets (`None` for an
/// analytical surface, already set) and the facets' axial range (3D prisms).
#[allow(clippy::type_complexity)]
fn master_surface(
    defs: &Definitions,
    part: &Part,
    bodies: &[Body],
    master: &str,
    location: &Location,
) -> Result<(usize, Option<RigidSurfaceSpec>, Option<[f64; 2]>), DeckError> {
    let surface = defs.surfaces.get(&key(master)).ok_or_else(|| {
        error(
            location,
            format!("*CONTACT PAIR: no surface named {master}"),
        )
    })?;
    match &surface.value {
        SurfaceDef::Analytical(_) => {
            let b = bodies
                .iter()
                .position(|b| {
                    b.def
                        .analytical
                        .as_deref()
                        .is_some_and(|a| key(a) == key(master))
                })
                .ok_or_else(|| {
                    error(
                        location,
                        format!(
                            "*CONTACT PAIR: analytical surface {master} belongs to no *RIGID BODY"
                        ),
                    )
                })?;
            Ok((b, None, None))
        }
        SurfaceDef::Nodes(_) => Err(error(
            location,
            format!(
                "*CONTACT PAIR: master {master} is a node surface; a master is a rigid body's surface"
            ),
        )),
        SurfaceDef::Faces(faces) => {
            let owner = |e: &u64| {
                bodies.iter().position(|b| {
                    b.def.elset.as_ref().is_some_and(|s| {
                        defs.mesh.elements_named(s).is_some_and(|es| es.contains(e))
                    })
                })
            };
            let Some(b) = faces.first().and_then(|(e, _)| owner(e)) else {
                return Err(error(
                    location,
                    format!(
                        "*CONTACT PAIR: master {master} is not made of rigid-body elements (skid's masters are rigid)"
                    ),
                ));
            };
            if faces.iter().any(|(e, _)| owner(e) != Some(b)) {
                return Err(error(
                    location,
                    format!("*CONTACT PAIR: master {master} spans several bodies"),
                ));
            }
            let (spec, range) = facets_surface(defs, part, &bodies[b], faces)
                .map_err(|m| error(&surface.location, format!("*SURFACE {}: {m}", surface.name)))?;
            Ok((b, Some(spec), range))
        }
    }
}

/// A body's surface from all its elements (general contact).
fn all_facets(
    defs: &Definitions,
    part: &Part,
    body: &Body,
) -> Result<Option<RigidSurfaceSpec>, DeckError> {
    let Some(elset) = &body.def.elset else {
        return Ok(None);
    };
    let faces: Vec<(u64, FaceLabel)> = defs
        .mesh
        .elements_named(elset)
        .unwrap_or_default()
        .into_iter()
        .map(|e| (e, FaceLabel::Exterior))
        .collect();
    facets_surface(defs, part, body, &faces)
        .map(|(s, _)| Some(s))
        .map_err(|m| {
            error(
                &body.def.location,
                format!("*RIGID BODY {}: {m}", body.def.name),
            )
        })
}

/// Facets of rigid elements in the body frame: lines and quadrilaterals must form a regular
/// prism; tetrahedra give their exterior (or listed) faces as triangles.
fn facets_surface(
    defs: &Definitions,
    part: &Part,
    body: &Body,
    faces: &[(u64, FaceLabel)],
) -> Result<(RigidSurfaceSpec, Option<[f64; 2]>), String> {
    let dim = part.dimension;
    let at = |n: &u64| {
        let x = Vector3::from(defs.mesh.nodes[n]) - body.reference;
        if dim == 2 {
            Vector3::new(x.x, x.y, 0.0)
        } else {
            x
        }
    };
    let tets: Vec<u64> = faces
        .iter()
        .filter(|(e, _)| defs.mesh.elements[e].kind == ElementKind::C3d4)
        .map(|(e, _)| *e)
        .collect();
    if !tets.is_empty() {
        if tets.len() != faces.len() {
            return Err("a surface mixes tetrahedra with other rigid elements".into());
        }
        let axis = free_axis(dim, body).ok_or_else(|| {
            format!(
                "a triangulated surface takes its surface coordinates about its body's one free \
                 rotation, and {} has none or several",
                body.def.name
            )
        })?;
        // the tetrahedra's nodes, numbered in the order *NODE defines them
        let used: BTreeSet<u64> = tets
            .iter()
            .flat_map(|e| defs.mesh.elements[e].nodes.iter().copied())
            .collect();
        let mut vertex_of: BTreeMap<u64, usize> = BTreeMap::new();
        let mut nodes = Vec::new();
        for n in defs.mesh.node_order.iter().filter(|n| used.contains(n)) {
            vertex_of.insert(*n, nodes.len());
            nodes.push(at(n));
        }
        let cells: Vec<[usize; 4]> = tets
            .iter()
            .map(|e| {
                let n = &defs.mesh.elements[e].nodes;
                [n[0], n[1], n[2], n[3]].map(|l| vertex_of[&l])
            })
            .collect();
        let mut listed = Vec::new();
        let mut exterior = false;
        for ((e, face), cell) in faces.iter().zip(&cells) {
            match face {
                FaceLabel::Exterior => exterior = true,
                FaceLabel::Numbered(k) => {
                    let corners = ElementKind::C3d4
                        .face(*k)
                        .ok_or(format!("element {e} has faces S1 to S4, not S{k}"))?;
                    listed.push([cell[corners[0]], cell[corners[1]], cell[corners[2]]]);
                }
                _ => {
                    return Err(format!(
                        "SPOS and SNEG do not name faces of tetrahedron {e}"
                    ));
                }
            }
        }
        let mesh = TetMesh { nodes, tets: cells };
        if exterior {
            listed.extend(mesh.exterior_faces());
        }
        // keep the vertices the faces use, in their original order
        let mut used = vec![false; mesh.nodes.len()];
        for &n in listed.iter().flatten() {
            used[n] = true;
        }
        let mut number = vec![0; mesh.nodes.len()];
        let mut vertices = Vec::new();
        for (n, _) in used.iter().enumerate().filter(|(_, u)| **u) {
            number[n] = vertices.len();
            vertices.push(mesh.nodes[n].into());
        }
        let triangles_list = listed.iter().map(|t| t.map(|n| number[n])).collect();
        return Ok((triangles(vertices, triangles_list, axis), None));
    }
    let mut facets = Vec::new();
    for (e, face) in faces {
        let element = &defs.mesh.elements[e];
        let mut corners: Vec<Vector3<f64>> = element.nodes.iter().map(at).collect();
        let positive = match face {
            FaceLabel::Positive | FaceLabel::Exterior => true,
            FaceLabel::Negative => false,
            FaceLabel::Numbered(_) => {
                return Err(format!(
                    "element {e} ({:?}) has sides SPOS and SNEG, not numbered faces",
                    element.kind
                ));
            }
        };
        match element.kind {
            // SPOS of a line is e_z x t; skid's outward convention turns t clockwise
            ElementKind::R2d2 => {
                if positive {
                    corners.reverse();
                }
            }
            ElementKind::R3d4 | ElementKind::M3d4r | ElementKind::S4r => {
                if !positive {
                    corners.reverse();
                }
            }
            other => {
                return Err(format!(
                    "element {e} ({other:?}) cannot form a contact surface"
                ));
            }
        }
        facets.push(corners);
    }
    prism(&facets, dim)
}

fn check_axial_range(
    defs: &Definitions,
    part: &Part,
    body: &Body,
    spec: &RigidBodySpec,
    slave: &[usize],
    range: [f64; 2],
    location: &Location,
) -> Result<(), DeckError> {
    let Some(RigidSurfaceSpec::FacetedCylinder { axis, .. }) = &spec.surface else {
        return Ok(());
    };
    let axis = Vector3::from(*axis);
    let tol = 1e-9 * (range[1] - range[0]).abs().max(1.0);
    for &i in slave {
        let label = part.labels[i];
        let h = (Vector3::from(defs.mesh.nodes[&label]) - body.reference).dot(&axis);
        if h < range[0] - tol || h > range[1] + tol {
            return Err(error(
                location,
                format!(
                    "*CONTACT PAIR: slave node {label} lies at {h} along the axis of {}, beyond \
                     its facets ({} to {}): skid's faceted cylinders have no ends",
                    body.def.name, range[0], range[1]
                ),
            ));
        }
    }
    Ok(())
}

/// Part node numbers of a slave surface (element faces or nodes), sorted.
fn slave_nodes(
    defs: &Definitions,
    part: &Part,
    slave: &str,
    location: &Location,
) -> Result<Vec<usize>, DeckError> {
    let surface = defs
        .surfaces
        .get(&key(slave))
        .ok_or_else(|| error(location, format!("*CONTACT PAIR: no surface named {slave}")))?;
    let mut nodes: Vec<usize> = match &surface.value {
        SurfaceDef::Faces(faces) => {
            if faces.iter().any(|(e, _)| !defs.mesh.elements[e].kind.is_solid()) {
                return Err(error(location, format!("*CONTACT PAIR: slave {slave} must be a surface of the deformable part")));
            }
            solid_faces(defs, part, faces, &surface.location)?
                .into_iter()
                .flatten()
                .collect()
        }
        SurfaceDef::Nodes(labels) => labels
            .iter()
            .map(|n| {
                part.number.get(n).copied().ok_or_else(|| {
                    error(location, format!("*CONTACT PAIR: node {n} of slave {slave} is not a node of the deformable part"))
                })
            })
            .collect::<Result<_, _>>()?,
        SurfaceDef::Analytical(_) => {
            return Err(error(location, format!("*CONTACT PAIR: slave {slave} is analytical; the slave is the deformable part")));
        }
    };
    nodes.sort_unstable();
    nodes.dedup();
    Ok(nodes)
}

/// A node-set name for a slave surface's nodes: the surface's name unless a different set has
/// it.
fn slave_set_name(sets: &BTreeMap<String, Vec<usize>>, surface: &str, nodes: &[usize]) -> String {
    let mut name = surface.to_string();
    while sets.get(&name).is_some_and(|existing| {
        let mut e = existing.clone();
        e.sort_unstable();
        e != nodes
    }) {
        name.push_str("-nodes");
    }
    name
}

fn part_nodes(
    defs: &Definitions,
    part: &Part,
    set: &str,
    location: &Location,
) -> Result<Vec<usize>, DeckError> {
    let labels = defs
        .mesh
        .nodes_named(set)
        .ok_or_else(|| error(location, format!("no node set named {set}")))?;
    labels
        .iter()
        .map(|n| {
            part.number.get(n).copied().ok_or_else(|| {
                error(
                    location,
                    format!("node {n} of {set} is not a node of the deformable part"),
                )
            })
        })
        .collect()
}

fn apply_initial(
    defs: &Definitions,
    part: &Part,
    bodies: &[Body],
    specs: &mut [RigidBodySpec],
    def: &InitialDef,
) -> Result<(), DeckError> {
    let dim = part.dimension;
    let (target, location) = match def {
        InitialDef::Velocity {
            target, location, ..
        }
        | InitialDef::Rotating {
            target, location, ..
        } => (target, location),
    };
    let labels = defs.mesh.nodes_named(target).ok_or_else(|| {
        error(
            location,
            format!("*INITIAL CONDITIONS: '{target}' is neither a node nor a node set"),
        )
    })?;
    for label in labels {
        let NodeRole::Reference(b) = role(part, bodies, label) else {
            return Err(error(
                location,
                format!(
                    "*INITIAL CONDITIONS: node {label} is not a rigid-body reference node; initial \
                     velocities of the deformable part are not supported yet"
                ),
            ));
        };
        let spec = &mut specs[b];
        let mut v = spec.initial_velocity.clone().map_or(Vector3::zeros(), |v| {
            Vector3::new(v[0], v[1], v.get(2).copied().unwrap_or(0.0))
        });
        let mut w = Vector3::from(spec.initial_angular_velocity.unwrap_or([0.0; 3]));
        match def {
            InitialDef::Velocity { dof, value, .. } => match dof_of(dim, *dof, location)? {
                Dof::X => v.x = *value,
                Dof::Y => v.y = *value,
                Dof::Z => v.z = *value,
                Dof::Rx => w.x = *value,
                Dof::Ry => w.y = *value,
                Dof::Rz => w.z = *value,
            },
            InitialDef::Rotating {
                omega,
                velocity,
                a,
                b: point_b,
                ..
            } => {
                let a = Vector3::from(*a);
                let axis = if dim == 2 {
                    Vector3::z()
                } else {
                    (Vector3::from(*point_b) - a)
                        .try_normalize(0.0)
                        .ok_or_else(|| {
                            error(
                                location,
                                "*INITIAL CONDITIONS: the axis points a and b coincide",
                            )
                        })?
                };
                w = axis * *omega;
                v = Vector3::from(*velocity) + w.cross(&(bodies[b].reference - a));
            }
        }
        spec.initial_velocity = Some(v.as_slice()[..dim].to_vec());
        spec.initial_angular_velocity = Some(w.into());
    }
    Ok(())
}

/// Steps and the loads they apply: boundary conditions with `OP=MOD` accumulate and `OP=NEW`
/// replaces those of earlier steps (model-data conditions hold throughout); the loads of the
/// first step are the model's, and later steps must keep them.
fn steps(
    defs: &Definitions,
    part: &Part,
    bodies: &[Body],
    part_spec: &mut PartSpec,
    deck: &Location,
) -> Result<(Vec<ModelStepSpec>, Vec<LoadSpec>), DeckError> {
    let dim = part.dimension;
    if defs.steps.is_empty() {
        return Err(error(deck, "the deck has no *STEP"));
    }
    let mut held: BTreeMap<usize, BTreeSet<usize>> = BTreeMap::new();
    let mut loads_in_force: Vec<(String, f64)> = Vec::new();
    let mut first_loads = None;
    let mut out = Vec::new();
    for (i, step) in defs.steps.iter().enumerate() {
        if step.nlgeom == Some(false) || (i == 0 && step.nlgeom.is_none()) {
            return Err(error(
                &step.location,
                "*STEP: skid always accounts for large deformation: give NLGEOM=YES on the first step",
            ));
        }
        for change in &step.boundary {
            apply_step_boundary(defs, part, bodies, change, &mut held)?;
        }
        for change in &step.loads {
            apply_loads(defs, part, part_spec, change, &mut loads_in_force)?;
        }
        match &first_loads {
            None => first_loads = Some(loads_in_force.clone()),
            Some(first) if *first != loads_in_force => {
                return Err(error(
                    &step.location,
                    format!(
                        "*STEP {}: the loads differ from the first step's; skid applies the first \
                         step's loads (ramped over it if static) and holds them (loads that change \
                         between steps are not supported yet)",
                        step.name
                    ),
                ));
            }
            Some(_) => {}
        }
        let boundary = held
            .iter()
            .filter_map(|(&b, dofs)| {
                let dofs: Vec<usize> = dofs
                    .iter()
                    .copied()
                    .filter(|k| !bodies[b].fixed.contains(k))
                    .collect();
                (!dofs.is_empty()).then_some((b, dofs))
            })
            .map(|(b, dofs)| {
                Ok(StepBoundarySpec {
                    body: bodies[b].def.name.clone(),
                    dofs: Some(
                        dofs.iter()
                            .map(|&k| dof_of(dim, k, &step.location))
                            .collect::<Result<_, _>>()?,
                    ),
                })
            })
            .collect::<Result<Vec<_>, DeckError>>()?;
        out.push(step_spec(step, boundary)?);
    }
    let loads = first_loads
        .unwrap_or_default()
        .into_iter()
        .map(|(surface, pressure)| LoadSpec::Pressure { surface, pressure })
        .collect();
    Ok((out, loads))
}

fn apply_step_boundary(
    defs: &Definitions,
    part: &Part,
    bodies: &[Body],
    change: &Change<BoundaryDef>,
    held: &mut BTreeMap<usize, BTreeSet<usize>>,
) -> Result<(), DeckError> {
    if change.replace {
        held.clear();
    }
    for bc in &change.items {
        let labels = defs.mesh.nodes_named(&bc.target).ok_or_else(|| {
            error(
                &bc.location,
                format!(
                    "*BOUNDARY: '{}' is neither a node nor a node set",
                    bc.target
                ),
            )
        })?;
        for label in labels {
            let NodeRole::Reference(b) = role(part, bodies, label) else {
                return Err(error(
                    &bc.location,
                    format!(
                        "*BOUNDARY: node {label}: boundary conditions inside steps apply to \
                         rigid-body reference nodes only so far (give those on the part as model data)"
                    ),
                ));
            };
            for &k in &bc.dofs {
                if part.dimension == 2 && (3..=5).contains(&k) && bc.dofs.len() > 1 {
                    continue;
                }
                dof_of(part.dimension, k, &bc.location)?;
                held.entry(b).or_default().insert(k);
            }
        }
    }
    Ok(())
}

fn apply_loads(
    defs: &Definitions,
    part: &Part,
    part_spec: &mut PartSpec,
    change: &Change<PressureDef>,
    in_force: &mut Vec<(String, f64)>,
) -> Result<(), DeckError> {
    if change.replace {
        in_force.clear();
    }
    for load in &change.items {
        let surface = match load.face {
            None => {
                let surface = defs.surfaces.get(&key(&load.target)).ok_or_else(|| {
                    error(
                        &load.location,
                        format!("*DSLOAD: no surface named {}", load.target),
                    )
                })?;
                if !part_spec.surfaces.contains_key(&surface.name) {
                    return Err(error(
                        &load.location,
                        format!(
                            "*DSLOAD: {} is not a surface of element faces of the deformable part",
                            surface.name
                        ),
                    ));
                }
                surface.name.clone()
            }
            Some(k) => {
                let elements = defs.mesh.elements_named(&load.target).ok_or_else(|| {
                    error(
                        &load.location,
                        format!(
                            "*DLOAD: '{}' is neither an element nor an element set",
                            load.target
                        ),
                    )
                })?;
                if elements
                    .iter()
                    .any(|e| !defs.mesh.elements[e].kind.is_solid())
                {
                    return Err(error(
                        &load.location,
                        "*DLOAD: pressures act on the deformable part's elements only",
                    ));
                }
                let faces: Vec<(u64, FaceLabel)> = elements
                    .into_iter()
                    .map(|e| (e, FaceLabel::Numbered(k)))
                    .collect();
                let name = format!("{}-P{k}", load.target);
                let corners = solid_faces(defs, part, &faces, &load.location)?;
                part_spec.surfaces.insert(name.clone(), corners);
                name
            }
        };
        match in_force.iter_mut().find(|(s, _)| *s == surface) {
            Some(existing) => existing.1 = load.magnitude,
            None => in_force.push((surface, load.magnitude)),
        }
    }
    Ok(())
}

fn step_spec(step: &StepDef, boundary: Vec<StepBoundarySpec>) -> Result<ModelStepSpec, DeckError> {
    let Some((procedure, location)) = &step.procedure else {
        return Err(error(
            &step.location,
            format!("*STEP {}: give *STATIC or *DYNAMIC", step.name),
        ));
    };
    Ok(match procedure {
        Procedure::Static { initial, period } => {
            let count = period / initial;
            let increments = count.round();
            if !(initial > &0.0 && period > &0.0)
                || (count - increments).abs() > 1e-9 * count
                || increments > 1e7
            {
                return Err(error(
                    location,
                    format!(
                        "*STATIC: the period {period} must be a whole number (at most 1e7) of \
                         increments {initial} (skid's static steps take fixed increments)"
                    ),
                ));
            }
            ModelStepSpec::Static {
                name: step.name.clone(),
                increments: increments as usize,
                regularization_time: default_regularization_time(),
                boundary,
            }
        }
        Procedure::Dynamic { dt, period, alpha } => ModelStepSpec::Dynamic {
            name: step.name.clone(),
            duration: *period,
            dt: *dt,
            alpha: *alpha,
            boundary,
            adaptive: None,
        },
    })
}
