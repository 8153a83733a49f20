//! The deformable part of a deck: its numbering from 0 in the order of `*NODE`, its element
//! block, node sets and surfaces of element faces, and the node sets of slave surfaces. Every
//! deformable element has one `*SOLID SECTION`: the first section listed is the part's, and each
//! other one's elements become an element set of its ELSET's name with its material
//! (`part.materials`); all share one thickness, and those with one-point elements one hourglass
//! control (`CONTROLS=`, see [`crate::deck::controls`]).

use super::*;
use crate::deck::controls::part_control;
use crate::deck::definitions::SectionDef;
use crate::model_spec::SetMaterialSpec;
use crate::schema::MaterialSpec;

pub(super) fn part_numbering(defs: &Definitions, deck: &Location) -> Result<Part, DeckError> {
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
            "the deck has no deformable elements (CPE4R, CPE4, CPE4H, CPE4I, C3D8R, C3D8, C3D8H \
             or C3D8I): skid needs one deformable part",
        ));
    };
    let dimension_of = |e: &u64| match defs.mesh.elements[e].kind {
        ElementKind::Quad(_) => 2,
        _ => 3,
    };
    let dimension = dimension_of(first);
    if let Some(other) = elements.iter().find(|e| dimension_of(e) != dimension) {
        return Err(error(
            &defs.mesh.elements[other].location,
            "*ELEMENT: quads (CPE4*) and hexahedra (C3D8*) cannot share a model (2D or 3D)",
        ));
    }
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

pub(super) fn part_spec(
    defs: &Definitions,
    part: &Part,
    deck: &Location,
) -> Result<PartSpec, DeckError> {
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
    let Some(first) = solid_sections.first() else {
        return Err(error(
            deck,
            "expected a *SOLID SECTION for the deformable elements, found none",
        ));
    };
    // the section of every deformable element, by its position in the part
    let position: BTreeMap<u64, usize> = part
        .elements
        .iter()
        .enumerate()
        .map(|(i, e)| (*e, i))
        .collect();
    let mut section_of: Vec<Option<usize>> = vec![None; part.elements.len()];
    let mut read = Vec::new();
    for (k, section) in solid_sections.iter().enumerate() {
        for e in defs.mesh.elements_named(&section.elset).unwrap_or_default() {
            let Some(&i) = position.get(&e) else {
                continue;
            };
            if let Some(other) = section_of[i].replace(k) {
                return Err(error(
                    &section.location,
                    format!(
                        "*SOLID SECTION, ELSET={}: element {e} already has the section of \
                         ELSET={}",
                        section.elset, solid_sections[other].elset
                    ),
                ));
            }
        }
        read.push(section_properties(defs, dim, section)?);
    }
    if let Some(i) = section_of.iter().position(Option::is_none) {
        let e = part.elements[i];
        return Err(error(
            &defs.mesh.elements[&e].location,
            format!("element {e} has no section: no *SOLID SECTION's ELSET holds it"),
        ));
    }
    let SectionProperties {
        law,
        density,
        thickness,
        stiffness_damping,
    } = read[0].clone();
    let hourglass = part_control(defs, &solid_sections)?;
    let mut element_sets = BTreeMap::new();
    let mut materials = Vec::new();
    for (k, (section, properties)) in solid_sections.iter().zip(&read).enumerate().skip(1) {
        let thickness_k = properties.thickness;
        if thickness_k != thickness {
            return Err(error(
                &section.location,
                format!(
                    "*SOLID SECTION, ELSET={}: thickness {thickness_k} differs from ELSET={}'s \
                     {thickness} (one thickness per part)",
                    section.elset, first.elset
                ),
            ));
        }
        let members: Vec<usize> = (0..part.elements.len())
            .filter(|&i| section_of[i] == Some(k))
            .collect();
        element_sets.insert(section.elset.clone(), members);
        materials.push(SetMaterialSpec {
            element_set: section.elset.clone(),
            material: properties.law.clone(),
            density: properties.density,
            stiffness_damping: properties.stiffness_damping,
        });
    }
    let mut nodes = vec![Vec::new(); part.number.len()];
    for (label, &i) in &part.number {
        nodes[i] = defs.mesh.nodes[label][..dim].to_vec();
    }
    // one block per run of consecutive elements of one formulation, so that the blocks keep the
    // part's element order
    let mut blocks: Vec<ElementBlockSpec> = Vec::new();
    for e in &part.elements {
        let element = &defs.mesh.elements[e];
        let kind = match element.kind {
            ElementKind::Quad(f) | ElementKind::Hex(f) => ElementType::of(f, dim),
            _ => ElementType::solid(dim),
        };
        let corners = element.nodes.iter().map(|n| part.number[n]).collect();
        match blocks.last_mut() {
            Some(block) if block.kind == kind => block.connectivity.push(corners),
            _ => blocks.push(ElementBlockSpec {
                kind,
                connectivity: vec![corners],
            }),
        }
    }
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
        name: first.elset.clone(),
        nodes,
        elements: blocks,
        node_sets,
        surfaces,
        materials,
        element_sets,
        section: SectionSpec {
            material: law,
            density,
            stiffness_damping,
            thickness,
            hourglass_scale: 1.0,
            hourglass,
            quasi_static: false,
            massless_contact_nodes: false,
        },
    })
}

/// What a `*SOLID SECTION` and its `*MATERIAL` give a part.
#[derive(Clone, Debug)]
struct SectionProperties {
    law: MaterialSpec,
    density: f64,
    thickness: f64,
    /// `*DAMPING, BETA` (0 without).
    stiffness_damping: f64,
}

/// The properties of a `*SOLID SECTION` of a part of dimension `dim`.
fn section_properties(
    defs: &Definitions,
    dim: usize,
    section: &SectionDef,
) -> Result<SectionProperties, DeckError> {
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
    Ok(SectionProperties {
        law,
        density,
        thickness,
        stiffness_damping: material.value.stiffness_damping.unwrap_or(0.0),
    })
}

/// Faces of solid elements as part node numbers, outward.
pub(super) fn solid_faces(
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
pub(super) fn exterior_faces(defs: &Definitions, part: &Part, elements: &[u64]) -> Vec<Vec<usize>> {
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

/// Part node numbers of a slave surface (element faces or nodes), sorted.
pub(super) fn slave_nodes(
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
pub(super) fn slave_set_name(
    sets: &BTreeMap<String, Vec<usize>>,
    surface: &str,
    nodes: &[usize],
) -> String {
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

pub(super) fn part_nodes(
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
