//! The loads of a deck's steps as the model's loads: pressures on surfaces, concentrated forces
//! on part node sets or moments and forces on rigid bodies' reference nodes, gravity on element
//! sets or the whole model, each with the amplitude its keyword names.

use super::*;
use crate::deck::definitions::{LoadChange, LoadKind};
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
    /// The amplitude it follows, by name.
    pub fn amplitude(&self) -> Option<&str> {
        match self {
            Self::Pressure { amplitude, .. }
            | Self::Concentrated { amplitude, .. }
            | Self::Gravity { amplitude, .. } => amplitude.as_deref(),
        }
    }

    /// Makes it follow the amplitude `name`.
    pub fn set_amplitude(&mut self, name: String) {
        match self {
            Self::Pressure { amplitude, .. }
            | Self::Concentrated { amplitude, .. }
            | Self::Gravity { amplitude, .. } => *amplitude = Some(name),
        }
    }

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

/// A load in force and where it was last given: the step (from 0) and the line.
#[derive(Clone, Debug)]
pub(super) struct Given {
    pub load: InForce,
    pub step: usize,
    pub location: Location,
}

/// Applies one load keyword block of step `step` to the loads in force: `OP=NEW` first drops
/// those of its keyword, then each line replaces the load at its place or adds one.
pub(super) fn apply_loads(
    defs: &Definitions,
    (part, bodies): (&Part, &[Body]),
    part_spec: &mut PartSpec,
    (step, change): (usize, &LoadChange),
    in_force: &mut Vec<Given>,
) -> Result<(), DeckError> {
    if change.replace {
        in_force.retain(|l| l.load.keyword() != change.keyword);
    }
    for load in &change.items {
        let location = match &load.kind {
            LoadKind::Pressure(p) => p.location.clone(),
            LoadKind::Concentrated(c) => c.location.clone(),
            LoadKind::Gravity(g) => g.location.clone(),
        };
        let amplitude = load
            .amplitude
            .as_deref()
            .map(|name| amplitude_name(defs, name));
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
        let given = Given {
            load: resolved,
            step,
            location,
        };
        match in_force.iter_mut().find(|l| l.load.same_place(&given.load)) {
            Some(existing) => *existing = given,
            None => in_force.push(given),
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
    load: &crate::deck::definitions::PressureDef,
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

/// Where a load of the model acts and the amplitude it follows: the loads in force that share
/// these make one load of the model.
#[derive(Clone, Debug, PartialEq)]
enum Place {
    Pressure {
        keyword: &'static str,
        surface: String,
        amplitude: Option<String>,
    },
    /// Components 0-2 force, 3-5 moment.
    Concentrated {
        target: CloadTarget,
        amplitude: Option<String>,
    },
    Gravity {
        element_set: Option<String>,
        amplitude: Option<String>,
    },
}

impl InForce {
    /// The load of the model it is part of, its component there and its value.
    fn component(&self) -> (Place, Vec<(usize, f64)>) {
        match self {
            Self::Pressure {
                keyword,
                surface,
                pressure,
                amplitude,
            } => (
                Place::Pressure {
                    keyword,
                    surface: surface.clone(),
                    amplitude: amplitude.clone(),
                },
                vec![(0, *pressure)],
            ),
            Self::Concentrated {
                target,
                dof,
                magnitude,
                amplitude,
            } => (
                Place::Concentrated {
                    target: target.clone(),
                    amplitude: amplitude.clone(),
                },
                vec![(dof - 1, *magnitude)],
            ),
            Self::Gravity {
                element_set,
                acceleration,
                amplitude,
            } => (
                Place::Gravity {
                    element_set: element_set.clone(),
                    amplitude: amplitude.clone(),
                },
                acceleration.iter().copied().enumerate().collect(),
            ),
        }
    }
}

/// A load of the model over the steps: the value of each of its components in each step (0
/// where no line gives it), and which components some line gives.
struct History {
    place: Place,
    values: Vec<[f64; 6]>,
    given: [bool; 6],
}

/// The loads of the model from the loads in force in each step.
///
/// The loads in force that act at one place with one amplitude make one load of the model
/// (a concentrated load on one target gathers its force components from DOFs 1-3 and its moment
/// from 4-6; in 2D DOF 6 is the moment about z). Its value is that of the first step where it
/// acts, and its factor in each step the ratio of its value there to that one (0 where it is
/// removed). Components that change in different ratios become loads of their own, one per
/// ratio sequence; a load whose factors are all 1 has none.
pub(super) fn model_loads(
    part: &Part,
    bodies: &[Body],
    per_step: &[Vec<InForce>],
) -> Vec<LoadSpec> {
    let dim = part.dimension;
    let steps = per_step.len();
    let mut histories: Vec<History> = Vec::new();
    for (step, in_force) in per_step.iter().enumerate() {
        for load in in_force {
            let (place, components) = load.component();
            let index = match histories.iter().position(|h| h.place == place) {
                Some(index) => index,
                None => {
                    histories.push(History {
                        place,
                        values: vec![[0.0; 6]; steps],
                        given: [false; 6],
                    });
                    histories.len() - 1
                }
            };
            let history = &mut histories[index];
            for (component, value) in components {
                history.values[step][component] = value;
                history.given[component] = true;
            }
        }
    }
    let mut loads = Vec::new();
    for history in &histories {
        for ProportionalPart {
            value,
            holds,
            factors,
        } in proportional_parts(history)
        {
            let step_factors = factors.filter(|f| f.iter().any(|&c| c != 1.0));
            loads.push(match &history.place {
                Place::Pressure {
                    surface, amplitude, ..
                } => LoadSpec::Pressure {
                    surface: surface.clone(),
                    pressure: value[0],
                    amplitude: amplitude.clone(),
                    step_factors,
                },
                Place::Gravity {
                    element_set,
                    amplitude,
                } => LoadSpec::Gravity {
                    acceleration: value[..dim].to_vec(),
                    element_set: element_set.clone(),
                    amplitude: amplitude.clone(),
                    step_factors,
                },
                Place::Concentrated { target, amplitude } => {
                    let (node_set, body) = match target {
                        CloadTarget::Nodes(name) => (Some(name.clone()), None),
                        CloadTarget::Body(b) => (None, Some(bodies[*b].def.name.clone())),
                    };
                    LoadSpec::Concentrated {
                        node_set,
                        body,
                        force: (0..3).any(|c| holds[c]).then(|| value[..dim].to_vec()),
                        moment: (3..6)
                            .any(|c| holds[c])
                            .then(|| [value[3], value[4], value[5]]),
                        amplitude: amplitude.clone(),
                        step_factors,
                    }
                }
            });
        }
    }
    loads
}

/// The name of the deck's amplitude that a keyword's `AMPLITUDE=name` refers to, as the
/// `*AMPLITUDE` spells it (names are case-insensitive; the reader has checked that it exists).
pub(super) fn amplitude_name(defs: &Definitions, name: &str) -> String {
    defs.amplitudes
        .get(&key(name))
        .map_or_else(|| name.to_string(), |a| a.name.clone())
}

/// The model's amplitude of the deck's `*AMPLITUDE` named `name`.
pub(super) fn amplitude_spec(defs: &Definitions, name: &str) -> AmplitudeSpec {
    let amplitude = defs.amplitudes.get(&key(name));
    AmplitudeSpec {
        name: name.to_string(),
        points: amplitude
            .map(|a| a.value.points.iter().map(|&(t, v)| [t, v]).collect())
            .unwrap_or_default(),
        time: amplitude.map(|a| a.value.time).unwrap_or_default(),
    }
}

/// A load's history split into parts that change in one ratio: each part's value (that of the
/// first step where it is not zero), the components it holds and its factor in each step.
/// Parts come in the order they start to act; components given but zero in every step go with
/// the first; a load zero throughout is one part without factors.
fn proportional_parts(history: &History) -> Vec<ProportionalPart> {
    let mut parts: Vec<ProportionalPart> = Vec::new();
    let mut zero = [false; 6];
    for c in 0..6 {
        let series: Vec<f64> = history.values.iter().map(|v| v[c]).collect();
        let Some(&reference) = series.iter().find(|&&v| v != 0.0) else {
            zero[c] = history.given[c];
            continue;
        };
        let factors: Vec<f64> = series.iter().map(|v| v / reference).collect();
        let index = match parts
            .iter()
            .position(|p| p.factors.as_ref() == Some(&factors))
        {
            Some(index) => index,
            None => {
                parts.push(ProportionalPart {
                    value: [0.0; 6],
                    holds: [false; 6],
                    factors: Some(factors),
                });
                parts.len() - 1
            }
        };
        parts[index].value[c] = reference;
        parts[index].holds[c] = true;
    }
    // the parts in the order they start to act
    parts.sort_by_key(|p| {
        p.factors
            .as_ref()
            .and_then(|f| f.iter().position(|&c| c != 0.0))
    });
    if parts.is_empty() {
        parts.push(ProportionalPart {
            value: [0.0; 6],
            holds: [false; 6],
            factors: None,
        });
    }
    for (holds, zero) in parts[0].holds.iter_mut().zip(zero) {
        *holds |= zero;
    }
    parts
}

/// One part of a load's history (see [`proportional_parts`]).
struct ProportionalPart {
    value: [f64; 6],
    holds: [bool; 6],
    factors: Option<Vec<f64>>,
}
