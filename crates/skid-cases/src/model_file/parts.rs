//! Several deformable parts: a model file's `parts` merged into its `part`, the one mesh the
//! solver integrates (bodies that share no node are independent in it).
//!
//! Each further part's nodes and elements are numbered after those before it; its node sets,
//! surfaces and element sets are named `<part>.<set>`, and the node set and element set
//! `<part>` hold all of its nodes and elements. Its material and density become the material of
//! its element set `<part>` where they differ from the first part's section, and its own
//! `materials` those of its renamed sets; the section's thickness, hourglass scale and control
//! and quasi-static setting hold for the whole mesh, so they must agree with the first part's.

use std::collections::BTreeMap;

use super::build::SpecError;
use crate::model_spec::{ModelSpec, PartSpec, SetMaterialSpec};

/// `spec` with its `parts` merged into `part` (see the module documentation); unchanged if it
/// has none.
///
/// # Errors
/// [`SpecError`] naming the field of a part whose name is empty or taken, whose section
/// disagrees with the first part's, whose set or element refers to a node or element it does
/// not have, or whose renamed set takes a name already in use.
pub fn merge_parts(mut spec: ModelSpec) -> Result<ModelSpec, SpecError> {
    for (i, part) in std::mem::take(&mut spec.parts).into_iter().enumerate() {
        append(&mut spec.part, part, &format!("parts[{i}]"))?;
    }
    Ok(spec)
}

fn fail<T>(field: String, message: impl Into<String>) -> Result<T, SpecError> {
    Err(SpecError {
        field,
        message: message.into(),
    })
}

/// Appends `part` (its field path `field`) to `merged`.
fn append(merged: &mut PartSpec, part: PartSpec, field: &str) -> Result<(), SpecError> {
    let name = part.name.clone();
    if name.is_empty() || name == merged.name {
        return fail(
            format!("{field}.name"),
            format!("expected a name of its own, got '{name}'"),
        );
    }
    let (base, own) = (&merged.section, &part.section);
    for (what, differs) in [
        ("thickness", base.thickness != own.thickness),
        (
            "hourglass_scale",
            base.hourglass_scale != own.hourglass_scale,
        ),
        ("hourglass", base.hourglass != own.hourglass),
        ("quasi_static", base.quasi_static != own.quasi_static),
    ] {
        if differs {
            return fail(
                format!("{field}.section.{what}"),
                "expected the first part's: the section's thickness, hourglass scale and \
                 control and quasi-static setting hold for every part",
            );
        }
    }
    let nodes = part.nodes.len();
    let elements: usize = part.elements.iter().map(|b| b.connectivity.len()).sum();
    let node_offset = merged.nodes.len();
    let element_offset: usize = merged.elements.iter().map(|b| b.connectivity.len()).sum();
    let shift = |indices: &[usize], count: usize, offset: usize, at: &str| {
        indices
            .iter()
            .map(|&k| {
                if k < count {
                    Ok(k + offset)
                } else {
                    fail(
                        format!("{field}.{at}"),
                        format!("no number {k}: it has {count}"),
                    )
                }
            })
            .collect::<Result<Vec<usize>, SpecError>>()
    };
    let mut blocks = Vec::with_capacity(part.elements.len());
    for (b, mut block) in part.elements.into_iter().enumerate() {
        for (e, corners) in block.connectivity.iter_mut().enumerate() {
            let at = format!("elements[{b}].connectivity[{e}]");
            *corners = shift(corners, nodes, node_offset, &at)?;
        }
        blocks.push(block);
    }
    let renamed = |set: &str| format!("{name}.{set}");
    let mut node_sets = BTreeMap::new();
    node_sets.insert(name.clone(), (node_offset..node_offset + nodes).collect());
    for (set, members) in &part.node_sets {
        let at = format!("node_sets.{set}");
        node_sets.insert(renamed(set), shift(members, nodes, node_offset, &at)?);
    }
    let mut surfaces = BTreeMap::new();
    for (surface, faces) in &part.surfaces {
        let faces = faces
            .iter()
            .map(|face| shift(face, nodes, node_offset, &format!("surfaces.{surface}")))
            .collect::<Result<Vec<_>, _>>()?;
        surfaces.insert(renamed(surface), faces);
    }
    let mut element_sets = BTreeMap::new();
    element_sets.insert(
        name.clone(),
        (element_offset..element_offset + elements).collect(),
    );
    for (set, members) in &part.element_sets {
        let at = format!("element_sets.{set}");
        element_sets.insert(renamed(set), shift(members, elements, element_offset, &at)?);
    }
    insert_all(&mut merged.node_sets, node_sets, field, "node set")?;
    insert_all(&mut merged.surfaces, surfaces, field, "surface")?;
    insert_all(&mut merged.element_sets, element_sets, field, "element set")?;
    if own.material != base.material
        || own.density != base.density
        || own.stiffness_damping != base.stiffness_damping
    {
        merged.materials.push(SetMaterialSpec {
            element_set: name.clone(),
            material: own.material.clone(),
            density: own.density,
            stiffness_damping: own.stiffness_damping,
        });
    }
    merged
        .materials
        .extend(part.materials.into_iter().map(|m| SetMaterialSpec {
            element_set: renamed(&m.element_set),
            ..m
        }));
    merged.nodes.extend(part.nodes);
    merged.elements.extend(blocks);
    Ok(())
}

/// Inserts `sets` into `into`, refusing a name already there.
fn insert_all<V>(
    into: &mut BTreeMap<String, V>,
    sets: BTreeMap<String, V>,
    field: &str,
    kind: &str,
) -> Result<(), SpecError> {
    for (name, members) in sets {
        if into.contains_key(&name) {
            return fail(
                field.to_string(),
                format!("its {kind} '{name}' takes a name already in use"),
            );
        }
        into.insert(name, members);
    }
    Ok(())
}
