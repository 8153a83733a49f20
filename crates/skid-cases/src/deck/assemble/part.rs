//! The deformable part of a deck: its numbering from 0 in the order of `*NODE`, its element
//! block, node sets and surfaces of element faces, and the node sets of slave surfaces.

use super::*;

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
        materials: Vec::new(),
        element_sets: BTreeMap::new(),
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
