//! Rigid bodies of a deck: reference nodes, point masses and inertias, the surfaces that the
//! analytical definitions or the rigid elements of contact masters give, initial velocities.

use super::*;

pub(super) fn rigid_bodies(defs: &Definitions, part: &Part) -> Result<Vec<Body>, DeckError> {
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
                            "*RIGID BODY: element {e} of ELSET={elset} is a deformable {kind:?}: only R2D2, R3D3, R3D4, M3D4R, S4R and C3D4 elements are made rigid"
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
    // point elements elsewhere than at a reference node
    for e in &defs.mesh.element_order {
        let el = &defs.mesh.elements[e];
        if matches!(el.kind, ElementKind::Mass | ElementKind::RotaryI)
            && !bodies.iter().any(|b| b.def.reference == el.nodes[0])
        {
            return Err(error(
                &el.location,
                format!(
                    "element {e}: point masses and inertias sit at rigid-body reference nodes only"
                ),
            ));
        }
    }
    Ok(bodies)
}

/// The axis of a body's one free rotation, if it has exactly one.
pub(super) fn free_axis(dim: usize, body: &Body) -> Option<Vector3<f64>> {
    if dim == 2 {
        return (!body.fixed.contains(&6)).then(Vector3::z);
    }
    let free: Vec<usize> = (4..=6).filter(|k| !body.fixed.contains(k)).collect();
    match free.as_slice() {
        [k] => Some(Vector3::ith(k - 4, 1.0)),
        _ => None,
    }
}

pub(super) fn body_spec(
    defs: &Definitions,
    part: &Part,
    body: &Body,
) -> Result<RigidBodySpec, DeckError> {
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
    let turns_freely = dim == 3 && (4..=6).all(|k| !body.fixed.contains(&k));
    let (rotary_inertia, moments_of_inertia, products_of_inertia) = if turns_freely {
        let products = [inertia[(0, 1)], inertia[(0, 2)], inertia[(1, 2)]];
        (
            0.0,
            Some(inertia.diagonal().into()),
            (products != [0.0; 3]).then_some(products),
        )
    } else {
        let about = match free_axis(dim, body) {
            Some(e) => (e.transpose() * inertia * e)[(0, 0)],
            None => inertia[(2, 2)],
        };
        (about, None, None)
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
        moments_of_inertia,
        products_of_inertia,
        surface: analytical,
        initial_velocity: None,
        initial_angular_velocity: None,
    })
}

pub(super) fn set_body_surface(
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
pub(super) fn master_surface(
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
pub(super) fn all_facets(
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

/// Facets of rigid elements in the body frame: lines and quadrilaterals that form a regular
/// prism give a faceted cylinder; other lines one chain (a polyline), other quadrilaterals and
/// triangles a triangle mesh (each quadrilateral split along its 1-3 diagonal, exact for flat
/// ones); tetrahedra give their exterior (or listed) faces as triangles.
pub(super) fn facets_surface(
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
        let (vertices, triangles_list) = compact_triangles(&mesh.nodes, &listed);
        let vertices = vertices.into_iter().map(Into::into).collect();
        let surface = triangles(vertices, triangles_list, free_axis(dim, body))?;
        return Ok((surface, None));
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
            ElementKind::R3d3 | ElementKind::R3d4 | ElementKind::M3d4r | ElementKind::S4r => {
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
    // why the facets are no regular prism, if they are lines or quadrilaterals
    let mut not_prism = None;
    if facets.iter().all(|f| f.len() == 2 || f.len() == 4) {
        let reversed: Vec<Vec<Vector3<f64>>> = facets
            .iter()
            .map(|f| f.iter().rev().copied().collect())
            .collect();
        match prism(&facets, dim) {
            Ok(found) => return Ok(found),
            // a regular prism facing its axis is refused, not read as a general surface
            Err(why) if prism(&reversed, dim).is_ok() => return Err(why),
            Err(why) => not_prism = Some(why),
        }
    }
    let general = if dim == 2 {
        let segments: Vec<[Vector3<f64>; 2]> = facets.iter().map(|f| [f[0], f[1]]).collect();
        chain(&segments)
    } else {
        let mut corners: Vec<Vector3<f64>> = Vec::new();
        let mut list = Vec::new();
        for f in &facets {
            let at = corners.len();
            corners.extend(f.iter().copied());
            list.push([at, at + 1, at + 2]);
            if f.len() == 4 {
                list.push([at, at + 2, at + 3]);
            }
        }
        let (vertices, list) = merge_corners(&corners, &list);
        triangles(vertices, list, free_axis(dim, body))
    };
    general
        .map(|s| (s, None))
        .map_err(|general| match not_prism {
            Some(why) if dim == 3 => {
                format!("{general} (nor do the facets form a regular prism: {why})")
            }
            _ => general,
        })
}

/// The distinct points of `corners` (equal bits; corners of one node are), numbered in order of
/// first appearance, and the triangles renumbered onto them.
fn merge_corners(
    corners: &[Vector3<f64>],
    triangles: &[[usize; 3]],
) -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
    let mut number: HashMap<[u64; 3], usize> = HashMap::new();
    let mut vertices = Vec::new();
    let renumbered: Vec<usize> = corners
        .iter()
        .map(|c| {
            *number.entry(c.map(f64::to_bits).into()).or_insert_with(|| {
                vertices.push([c.x, c.y, c.z]);
                vertices.len() - 1
            })
        })
        .collect();
    let triangles = triangles.iter().map(|t| t.map(|i| renumbered[i])).collect();
    (vertices, triangles)
}

pub(super) fn check_axial_range(
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

/// Applies one initial condition: to the bodies whose reference nodes it names, and to the
/// part's nodes it names, whose velocities (by part node, 3 components) it sets in
/// `part_velocities` (`coordinates`: the part's nodes).
pub(super) fn apply_initial(
    defs: &Definitions,
    (part, coordinates): (&Part, &[Vec<f64>]),
    bodies: &[Body],
    (specs, part_velocities): (&mut [RigidBodySpec], &mut BTreeMap<usize, [f64; 3]>),
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
    let labels = node_labels(defs, target, "*INITIAL CONDITIONS", location)?;
    for label in labels {
        let b = match role(part, bodies, label) {
            NodeRole::Reference(b) => b,
            NodeRole::Part(i) => {
                let x = Vector3::from_fn(|k, _| coordinates[i].get(k).copied().unwrap_or(0.0));
                let v = part_velocities.entry(i).or_insert([0.0; 3]);
                part_node_velocity(dim, def, &x, v)?;
                continue;
            }
            NodeRole::Other => {
                return Err(error(
                    location,
                    format!(
                        "*INITIAL CONDITIONS: node {label} is neither a node of the part nor a \
                         rigid-body reference node"
                    ),
                ));
            }
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
                let (a, axis) = rotation_axis(dim, a, point_b, location)?;
                w = axis * *omega;
                v = Vector3::from(*velocity) + w.cross(&(bodies[b].reference - a));
            }
        }
        spec.initial_velocity = Some(v.as_slice()[..dim].to_vec());
        spec.initial_angular_velocity = Some(w.into());
    }
    Ok(())
}

/// Sets the components of a part node's velocity `v` (at `x`) that `def` gives: a translation
/// of `TYPE=VELOCITY`, or the whole velocity `v0 + omega e x (x - a)` of `TYPE=ROTATING
/// VELOCITY`. A node of the part has no rotations.
fn part_node_velocity(
    dim: usize,
    def: &InitialDef,
    x: &Vector3<f64>,
    v: &mut [f64; 3],
) -> Result<(), DeckError> {
    match def {
        InitialDef::Velocity {
            dof,
            value,
            location,
            ..
        } => {
            let Some(axis) = dof_of(dim, *dof, location)?.translation_axis() else {
                return Err(error(
                    location,
                    format!(
                        "*INITIAL CONDITIONS: degree of freedom {dof} is a rotation, which a \
                         node of the deformable part does not have"
                    ),
                ));
            };
            v[axis] = *value;
        }
        InitialDef::Rotating {
            omega,
            velocity,
            a,
            b,
            location,
            ..
        } => {
            let (a, axis) = rotation_axis(dim, a, b, location)?;
            let w = Vector3::from(*velocity) + (axis * *omega).cross(&(x - a));
            *v = w.into();
        }
    }
    Ok(())
}

/// The part's initial velocities as node sets: the nodes of equal velocity together, under the
/// name of a node set of the deck that holds exactly them (one that an initial condition
/// names, if any does), else `initial-velocity-<k>` (added to `part_spec`), in the order of
/// their first node.
pub(super) fn part_initial_velocities(
    dim: usize,
    velocities: &BTreeMap<usize, [f64; 3]>,
    named: &[String],
    part_spec: &mut PartSpec,
) -> Vec<NodeVelocitySpec> {
    let mut groups: Vec<([f64; 3], Vec<usize>)> = Vec::new();
    for (&node, v) in velocities {
        match groups.iter_mut().find(|(w, _)| w == v) {
            Some((_, nodes)) => nodes.push(node),
            None => groups.push((*v, vec![node])),
        }
    }
    let mut out = Vec::new();
    for (k, (v, nodes)) in groups.into_iter().enumerate() {
        let holding: Vec<&String> = part_spec
            .node_sets
            .iter()
            .filter(|(_, set)| {
                let mut sorted = (*set).clone();
                sorted.sort_unstable();
                sorted == nodes
            })
            .map(|(name, _)| name)
            .collect();
        let existing = holding
            .iter()
            .find(|name| named.iter().any(|n| n.eq_ignore_ascii_case(name)))
            .or(holding.first())
            .map(|name| (*name).clone());
        let node_set = existing.unwrap_or_else(|| {
            let mut name = format!("initial-velocity-{}", k + 1);
            while part_spec.node_sets.contains_key(&name) {
                name.push('_');
            }
            part_spec.node_sets.insert(name.clone(), nodes);
            name
        });
        out.push(NodeVelocitySpec {
            node_set,
            velocity: v[..dim].to_vec(),
        });
    }
    out
}

/// The axis of a `TYPE=ROTATING VELOCITY` condition through its points `a` and `b`: the point
/// `a` and the unit direction `e = (b - a) / |b - a|` (in 2D always `+z`).
fn rotation_axis(
    dim: usize,
    a: &[f64; 3],
    b: &[f64; 3],
    location: &Location,
) -> Result<(Vector3<f64>, Vector3<f64>), DeckError> {
    let a = Vector3::from(*a);
    if dim == 2 {
        return Ok((a, Vector3::z()));
    }
    let e = (Vector3::from(*b) - a).try_normalize(0.0).ok_or_else(|| {
        error(
            location,
            "*INITIAL CONDITIONS: the axis points a and b coincide",
        )
    })?;
    Ok((a, e))
}
