//! Definitions of a deck turned into a [`ModelSpec`]: the deformable part renumbered from 0 in
//! the order of `*NODE` and `*ELEMENT`, rigid bodies with their reference nodes, masses and
//! surfaces, boundary conditions split between bodies and part nodes, contact, initial
//! velocities and steps. Every reference is resolved here, and a deck that the model file
//! cannot express exactly is refused at the line that asks for it.

use std::collections::{BTreeMap, BTreeSet, HashMap};

use nalgebra::{Matrix3, Vector3};
use skid_fem::tetra::{TetMesh, compact_triangles};

use super::definitions::{
    BoundaryDef, Change, Definitions, FaceLabel, FieldRequest, InitialDef, Procedure, RigidDef,
    SectionKind, StepDef, SurfaceDef,
};
use super::fields::key;
use super::keywords::{DeckError, Location};
use super::mesh::ElementKind;
use super::rigid::{chain, prism, triangles};
use crate::model_spec::{
    AutomaticIncrementsSpec, BoundarySpec, ContactPairSpec, Dof, ElementBlockSpec, ElementType,
    LoadSpec, MODEL_FORMAT_VERSION, ModelOutputSpec, ModelSpec, ModelStepSpec, NodeVelocitySpec,
    PartSpec, RigidBodySpec, RigidSurfaceSpec, SectionSpec, SlaveSpec, StepBoundarySpec, TieSpec,
};
use crate::schema::{SolverSpec, default_regularization_time};

mod bodies;
mod carried;
mod conditions;
mod loads;
mod motions;
mod part;

use bodies::*;
use conditions::*;
use part::*;

fn error(location: &Location, message: impl Into<String>) -> DeckError {
    DeckError {
        location: location.clone(),
        message: message.into(),
    }
}

/// The node labels a data-line field names (a node label or a node set), or an error at
/// `location` for `keyword`.
fn node_labels(
    defs: &Definitions,
    target: &str,
    keyword: &str,
    location: &Location,
) -> Result<Vec<u64>, DeckError> {
    defs.mesh.nodes_named(target).ok_or_else(|| {
        error(
            location,
            format!("{keyword}: '{target}' is neither a node nor a node set"),
        )
    })
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
    let mut part_velocities = BTreeMap::new();
    for def in &defs.initial {
        apply_initial(
            defs,
            (&part, &part_spec.nodes),
            &bodies,
            (&mut rigid_specs, &mut part_velocities),
            def,
        )?;
    }
    let named: Vec<String> = defs
        .initial
        .iter()
        .map(|def| match def {
            InitialDef::Velocity { target, .. } | InitialDef::Rotating { target, .. } => {
                target.clone()
            }
        })
        .collect();
    let initial_velocities = part_initial_velocities(dim, &part_velocities, &named, &mut part_spec);
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
    let model_held = held_part_dofs(&spec_boundary, &part_spec.node_sets);
    let StepsAndLoads {
        steps,
        loads,
        motions,
        amplitudes,
    } = steps(defs, &part, &bodies, &mut part_spec, &model_held, deck)?;
    let mut spec_boundary =
        motions::without_prescribed(spec_boundary, &motions, &mut part_spec.node_sets);
    spec_boundary.extend(motions);
    Ok(ModelSpec {
        skid_model: MODEL_FORMAT_VERSION,
        name: name.to_string(),
        description: defs.heading.clone(),
        dimension: dim,
        part: part_spec,
        parts: Vec::new(),
        rigid_bodies: rigid_specs,
        boundary: spec_boundary,
        ties,
        initial_velocities,
        loads,
        amplitudes,
        contact,
        steps,
        solver: SolverSpec::default(),
        output: ModelOutputSpec {
            field_interval: field_interval(&defs.steps),
            history_nodes: history_nodes(defs, &part)?,
        },
    })
}

/// The (node, degree of freedom 1..=3) of the part that the node-set entries of `boundary`
/// hold.
fn held_part_dofs(
    boundary: &[BoundarySpec],
    node_sets: &BTreeMap<String, Vec<usize>>,
) -> BTreeSet<(usize, usize)> {
    boundary
        .iter()
        .filter_map(|bc| Some((bc, node_sets.get(bc.node_set.as_ref()?)?)))
        .flat_map(|(bc, nodes)| {
            bc.dofs
                .iter()
                .filter_map(|dof| dof.translation_axis())
                .flat_map(move |axis| nodes.iter().map(move |&n| (n, axis + 1)))
        })
        .collect()
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
