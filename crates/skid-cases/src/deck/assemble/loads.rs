//! The loads of a deck's steps as the model's loads: pressures on surfaces, concentrated forces
//! on part node sets or moments and forces on rigid bodies' reference nodes, gravity on element
//! sets or the whole model, each with the amplitude its keyword names.

use super::*;
use crate::deck::loads::{LoadChange, LoadKind};
use crate::model_spec::AmplitudeSpec;

/// What a concentrated load acts on.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum CloadTarget {
    /// Nodes of the part, by the name of their node set in the model.
    Nodes(String),
    /// A rigid body's reference node.
    Body(usize),
}

/// A load in force, with what identifies it for `OP=MOD` (the keyword and where it acts).
#[derive(Clone, Debug, PartialEq)]
pub(super) enum InForce {
    Pressure {
        keyword: &'static str,
        surface: String,
        pressure: f64,
        amplitude: Option<String>,
    },
    Concentrated {
        target: CloadTarget,
        dof: usize,
        magnitude: f64,
        amplitude: Option<String>,
    },
    Gravity {
        element_set: Option<String>,
        acceleration: [f64; 3],
        amplitude: Option<String>,
    },
}

impl InForce {
    fn keyword(&self) -> &'static str {
        match self {
            Self::Pressure { keyword, .. } => keyword,
            Self::Concentrated { .. } => "CLOAD",
            Self::Gravity { .. } => "DLOAD",
        }
    }

    /// Whether `other` acts at the same place (so that `OP=MOD` replaces this one by it).
    fn same_place(&self, other: &Self) -> bool {
        match (self, other) {
            (
                Self::Pressure {
                    keyword, surface, ..
                },
                Self::Pressure {
                    keyword: k,
                    surface: s,
                    ..
                },
            ) => keyword == k && surface == s,
            (
                Self::Concentrated { target, dof, .. },
                Self::Concentrated {
                    target: t, dof: d, ..
                },
            ) => target == t && dof == d,
            (Self::Gravity { element_set, .. }, Self::Gravity { element_set: e, .. }) => {
                element_set == e
            }
            _ => false,
        }
    }
}

/// Applies one load keyword block of a step to the loads in force: `OP=NEW` first drops those
/// of its keyword, then each line replaces the load at its place or adds one.
pub(super) fn apply_loads(
    defs: &Definitions,
    part: &Part,
    bodies: &[Body],
    part_spec: &mut PartSpec,
    change: &LoadChange,
    in_force: &mut Vec<InForce>,
) -> Result<(), DeckError> {
    if change.replace {
        in_force.retain(|l| l.keyword() != change.keyword);
    }
    for load in &change.items {
        let amplitude = load.amplitude.as_ref().map(|name| {
            defs.amplitudes
                .get(&key(name))
                .map_or_else(|| name.clone(), |a| a.name.clone())
        });
        let resolved = match &load.kind {
            LoadKind::Pressure(p) => InForce::Pressure {
                keyword: change.keyword,
                surface: pressure_surface(defs, part, part_spec, p)?,
                pressure: p.magnitude,
                amplitude,
            },
            LoadKind::Concentrated(c) => {
                let target = cload_target(defs, part, bodies, part_spec, &c.target, &c.location)?;
                dof_of(part.dimension, c.dof, &c.location).map_err(|e| {
                    error(&c.location, format!("*CLOAD {}: {}", c.target, e.message))
                })?;
                if c.dof > 3 && matches!(target, CloadTarget::Nodes(_)) {
                    return Err(error(
                        &c.location,
                        format!(
                            "*CLOAD {}: degree of freedom {}: the nodes of a solid part take no moment",
                            c.target, c.dof
                        ),
                    ));
                }
                InForce::Concentrated {
                    target,
                    dof: c.dof,
                    magnitude: c.magnitude,
                    amplitude,
                }
            }
            LoadKind::Gravity(g) => {
                if part.dimension == 2 && g.acceleration[2] != 0.0 {
                    return Err(error(
                        &g.location,
                        "*DLOAD: GRAV: a 2D model has no direction 3 (field 6 must be 0)",
                    ));
                }
                InForce::Gravity {
                    element_set: match &g.target {
                        Some(target) => {
                            Some(gravity_set(defs, part, part_spec, target, &g.location)?)
                        }
                        None => None,
                    },
                    acceleration: g.acceleration,
                    amplitude,
                }
            }
        };
        match in_force.iter_mut().find(|l| l.same_place(&resolved)) {
            Some(existing) => *existing = resolved,
            None => in_force.push(resolved),
        }
    }
    Ok(())
}

/// A `*CLOAD` target: a node set or node of the part, or a rigid body's reference node (or a
/// set holding just it).
fn cload_target(
    defs: &Definitions,
    part: &Part,
    bodies: &[Body],
    part_spec: &mut PartSpec,
    target: &str,
    location: &Location,
) -> Result<CloadTarget, DeckError> {
    let labels = node_labels(defs, target, "*CLOAD", location)?;
    if let [label] = labels.as_slice()
        && let NodeRole::Reference(b) = role(part, bodies, *label)
    {
        return Ok(CloadTarget::Body(b));
    }
    let mut nodes = Vec::with_capacity(labels.len());
    for &label in &labels {
        let NodeRole::Part(i) = role(part, bodies, label) else {
            return Err(error(
                location,
                format!(
                    "*CLOAD {target}: node {label} is not a node of the deformable part: load a \
                     rigid body through its reference node alone"
                ),
            ));
        };
        nodes.push(i);
    }
    let name = defs
        .mesh
        .node_sets
        .get(&key(target))
        .map_or_else(|| format!("cload-{target}"), |s| s.name.clone());
    part_spec.node_sets.insert(name.clone(), nodes);
    Ok(CloadTarget::Nodes(name))
}

/// The element set of the part a `*DLOAD, GRAV` line names (an element label gets a set of
/// its own), made an element set of the part.
fn gravity_set(
    defs: &Definitions,
    part: &Part,
    part_spec: &mut PartSpec,
    target: &str,
    location: &Location,
) -> Result<String, DeckError> {
    let labels = defs.mesh.elements_named(target).ok_or_else(|| {
        error(
            location,
            format!("*DLOAD: '{target}' is neither an element nor an element set"),
        )
    })?;
    let elements = labels
        .iter()
        .map(|label| part.elements.iter().position(|e| e == label))
        .collect::<Option<Vec<usize>>>()
        .ok_or_else(|| {
            error(
                location,
                format!(
                    "*DLOAD: GRAV on {target}: gravity on an element set acts on the deformable \
                     part's elements only; leave the set out for the whole model (part and rigid \
                     bodies)"
                ),
            )
        })?;
    let name = defs
        .mesh
        .element_sets
        .get(&key(target))
        .map_or_else(|| format!("grav-{target}"), |s| s.name.clone());
    part_spec.element_sets.insert(name.clone(), elements);
    Ok(name)
}

/// The surface of the part a pressure acts on (`*DLOAD, Pk` on elements gets a surface of its
/// own).
fn pressure_surface(
    defs: &Definitions,
    part: &Part,
    part_spec: &mut PartSpec,
    load: &crate::deck::loads::PressureDef,
) -> Result<String, DeckError> {
    Ok(match load.face {
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
    })
}

/// The model's loads and the amplitudes they name (in the order first named): the
/// concentrated components on one target with one amplitude make one load (forces from DOFs
/// 1-3, the moment from 4-6; in 2D DOF 6 is the moment about z).
pub(super) fn model_loads(
    defs: &Definitions,
    part: &Part,
    bodies: &[Body],
    in_force: &[InForce],
) -> (Vec<LoadSpec>, Vec<AmplitudeSpec>) {
    let dim = part.dimension;
    let mut loads = Vec::new();
    // concentrated loads: (target, amplitude) -> index in `loads`
    let mut grouped: Vec<(CloadTarget, Option<String>, usize)> = Vec::new();
    for load in in_force {
        match load {
            InForce::Pressure {
                surface,
                pressure,
                amplitude,
                ..
            } => loads.push(LoadSpec::Pressure {
                surface: surface.clone(),
                pressure: *pressure,
                amplitude: amplitude.clone(),
            }),
            InForce::Gravity {
                element_set,
                acceleration,
                amplitude,
            } => loads.push(LoadSpec::Gravity {
                acceleration: acceleration[..dim].to_vec(),
                element_set: element_set.clone(),
                amplitude: amplitude.clone(),
            }),
            InForce::Concentrated {
                target,
                dof,
                magnitude,
                amplitude,
            } => {
                let index = match grouped
                    .iter()
                    .find(|(t, a, _)| t == target && a == amplitude)
                {
                    Some(&(_, _, index)) => index,
                    None => {
                        let (node_set, body) = match target {
                            CloadTarget::Nodes(name) => (Some(name.clone()), None),
                            CloadTarget::Body(b) => (None, Some(bodies[*b].def.name.clone())),
                        };
                        loads.push(LoadSpec::Concentrated {
                            node_set,
                            body,
                            force: None,
                            moment: None,
                            amplitude: amplitude.clone(),
                        });
                        grouped.push((target.clone(), amplitude.clone(), loads.len() - 1));
                        loads.len() - 1
                    }
                };
                let LoadSpec::Concentrated { force, moment, .. } = &mut loads[index] else {
                    continue;
                };
                if *dof <= 3 {
                    force.get_or_insert_with(|| vec![0.0; dim])[dof - 1] = *magnitude;
                } else {
                    moment.get_or_insert([0.0; 3])[dof - 4] = *magnitude;
                }
            }
        }
    }
    let mut amplitudes: Vec<AmplitudeSpec> = Vec::new();
    for name in loads.iter().filter_map(LoadSpec::amplitude) {
        if amplitudes.iter().any(|a| a.name == name) {
            continue;
        }
        let points = defs
            .amplitudes
            .get(&key(name))
            .map(|a| a.value.iter().map(|&(t, v)| [t, v]).collect())
            .unwrap_or_default();
        amplitudes.push(AmplitudeSpec {
            name: name.to_string(),
            points,
        });
    }
    (loads, amplitudes)
}
