//! Boundary conditions of a deck (model data on bodies and part nodes, changes per step) and
//! its steps with their loads.

use super::carried::Frozen;
use super::loads::{Given, InForce, amplitude_name, amplitude_spec, apply_loads, model_loads};
use super::motions::{Held, HeldInStep, Holder, prescribed_motions};
use super::*;
use crate::deck::read::AUTOMATIC_DYNAMIC_TOLERANCE;
use crate::model_spec::{AmplitudeSpec, DefaultAmplitude};
use crate::schema::AdaptiveSpec;

pub(super) fn apply_model_boundary(
    defs: &Definitions,
    part: &Part,
    bodies: &mut [Body],
    bc: &BoundaryDef,
    index: usize,
    node_sets: &mut BTreeMap<String, Vec<usize>>,
    out: &mut Vec<BoundarySpec>,
) -> Result<(), DeckError> {
    let dim = part.dimension;
    let labels = node_labels(defs, &bc.target, "*BOUNDARY", &bc.location)?;
    let mut part_nodes = Vec::new();
    for label in labels {
        match role(part, bodies, label) {
            NodeRole::Reference(b) => {
                let mut dofs = Vec::new();
                for k in body_dofs(dim, &bc.dofs) {
                    dofs.push(dof_of(dim, k, &bc.location)?);
                    bodies[b].fixed.insert(k);
                }
                out.push(BoundarySpec {
                    body: Some(bodies[b].def.name.clone()),
                    node_set: None,
                    dofs,
                    value: None,
                    amplitude: None,
                    step_factors: None,
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
        let dofs = solid_dofs(dim, bc)?
            .into_iter()
            .map(|k| dof_of(dim, k, &bc.location))
            .collect::<Result<_, _>>()?;
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
            value: None,
            amplitude: None,
            step_factors: None,
        });
    }
    Ok(())
}

/// The degrees of freedom (1..=3) that a boundary condition holds on the nodes of a solid in
/// dimension `dim`: solid nodes have no rotations, so a range or a named condition (ENCASTRE,
/// symmetry) drops them, and a single one is refused.
fn solid_dofs(dim: usize, bc: &BoundaryDef) -> Result<Vec<usize>, DeckError> {
    let mut dofs = Vec::new();
    for &k in &bc.dofs {
        match k {
            1..=3 if k <= dim => dofs.push(k),
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
    Ok(dofs)
}

/// Refuses a boundary condition (model data or a step's) on a part node that a `TIE NSET` ties
/// to a rigid body: the tied node moves with the body, so holding it contradicts the tie.
pub(super) fn check_held_ties(
    defs: &Definitions,
    part: &Part,
    bodies: &[Body],
) -> Result<(), DeckError> {
    for body in bodies {
        let Some(tie) = &body.def.tie else { continue };
        let tied = defs.mesh.nodes_named(tie).unwrap_or_default();
        let in_steps = defs
            .steps
            .iter()
            .flat_map(|step| &step.boundary)
            .flat_map(|change| &change.items);
        for bc in defs.boundary.iter().chain(in_steps) {
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

/// A deck's steps and the model's loads and prescribed motions with the amplitudes they name
/// (in the order first named).
pub(super) struct StepsAndLoads {
    pub steps: Vec<ModelStepSpec>,
    pub loads: Vec<LoadSpec>,
    pub motions: Vec<BoundarySpec>,
    pub amplitudes: Vec<AmplitudeSpec>,
}

/// Steps and the loads they apply: boundary conditions and loads with `OP=MOD` accumulate and
/// `OP=NEW` replaces those of earlier steps (model-data conditions hold throughout); the loads
/// in force in each step become the model's loads with their factors in each step (see
/// [`model_loads`]).
pub(super) fn steps(
    defs: &Definitions,
    part: &Part,
    bodies: &[Body],
    part_spec: &mut PartSpec,
    model_held: &BTreeSet<(usize, usize)>,
    deck: &Location,
) -> Result<StepsAndLoads, DeckError> {
    let dim = part.dimension;
    if defs.steps.is_empty() {
        return Err(error(deck, "the deck has no *STEP"));
    }
    let mut held = HeldInStep::new();
    let mut loads_in_force: Vec<Given> = Vec::new();
    let mut given_per_step = Vec::new();
    let mut held_per_step = Vec::new();
    let mut frozen = Frozen::default();
    for (i, step) in defs.steps.iter().enumerate() {
        if step.nlgeom == Some(false) || (i == 0 && step.nlgeom.is_none()) {
            return Err(error(
                &step.location,
                "*STEP: skid always accounts for large deformation: give NLGEOM=YES on the first step",
            ));
        }
        for change in &step.boundary {
            apply_step_boundary(defs, (part, bodies), (i, change), &mut held)?;
        }
        for change in &step.loads {
            apply_loads(
                defs,
                (part, bodies),
                part_spec,
                (i, change),
                &mut loads_in_force,
            )?;
        }
        for given in &loads_in_force {
            if let Some(name) = given.load.amplitude() {
                frozen.note(defs, name, (given.step, i), &given.location);
            }
        }
        for dofs in held.values() {
            for h in dofs.values() {
                if let Some(name) = &h.amplitude {
                    frozen.note(defs, name, (h.step, i), &h.location);
                }
            }
        }
        given_per_step.push(loads_in_force.clone());
        held_per_step.push(held.clone());
    }
    // the carried loads and motions that follow a generated amplitude, in every step
    let per_step: Vec<Vec<InForce>> = given_per_step
        .into_iter()
        .map(|loads| {
            loads
                .into_iter()
                .map(|mut g| {
                    if let Some(name) = frozen.of(g.step, &g.location) {
                        g.load.set_amplitude(name.clone());
                    }
                    g.load
                })
                .collect()
        })
        .collect();
    for held in &mut held_per_step {
        for h in held.values_mut().flat_map(|dofs| dofs.values_mut()) {
            if let Some(name) = frozen.of(h.step, &h.location) {
                h.amplitude = Some(name.clone());
            }
        }
    }
    let prescribed = prescribed_motions(
        defs,
        part,
        bodies,
        &held_per_step,
        model_held,
        &mut part_spec.node_sets,
    )?;
    let mut out = Vec::new();
    for ((step, held), nodes) in defs
        .steps
        .iter()
        .zip(&held_per_step)
        .zip(&prescribed.in_steps)
    {
        let boundary = held
            .iter()
            .filter_map(|(&who, dofs)| {
                let Holder::Body(b) = who else { return None };
                let dofs: Vec<usize> = dofs
                    .keys()
                    .copied()
                    .filter(|&k| !bodies[b].fixed.contains(&k) && !prescribed.moves(b, k))
                    .collect();
                (!dofs.is_empty()).then_some((b, dofs))
            })
            .map(|(b, dofs)| {
                Ok(StepBoundarySpec {
                    body: Some(bodies[b].def.name.clone()),
                    node_set: None,
                    dofs: Some(
                        dofs.iter()
                            .map(|&k| dof_of(dim, k, &step.location))
                            .collect::<Result<_, _>>()?,
                    ),
                })
            })
            .chain(nodes.iter().cloned().map(Ok))
            .collect::<Result<Vec<_>, DeckError>>()?;
        out.push(step_spec(step, boundary)?);
    }
    let loads = model_loads(part, bodies, &per_step);
    let mut amplitudes: Vec<AmplitudeSpec> = Vec::new();
    let named = loads.iter().filter_map(LoadSpec::amplitude).chain(
        prescribed
            .boundary
            .iter()
            .filter_map(|m| m.amplitude.as_deref()),
    );
    for name in named {
        if !amplitudes.iter().any(|a| a.name == name) {
            let generated = frozen.amplitudes.iter().find(|a| a.name == name);
            amplitudes.push(
                generated
                    .cloned()
                    .unwrap_or_else(|| amplitude_spec(defs, name)),
            );
        }
    }
    Ok(StepsAndLoads {
        steps: out,
        loads,
        motions: prescribed.boundary,
        amplitudes,
    })
}

/// Applies one `*BOUNDARY` block of a step to the conditions in force: `OP=NEW` first drops
/// those of earlier steps, then each line sets its degrees of freedom on rigid-body reference
/// nodes and part nodes.
pub(super) fn apply_step_boundary(
    defs: &Definitions,
    (part, bodies): (&Part, &[Body]),
    (step, change): (usize, &Change<BoundaryDef>),
    held: &mut HeldInStep,
) -> Result<(), DeckError> {
    if change.replace {
        held.clear();
    }
    for bc in &change.items {
        let labels = node_labels(defs, &bc.target, "*BOUNDARY", &bc.location)?;
        let amplitude = bc
            .amplitude
            .as_deref()
            .map(|name| amplitude_name(defs, name));
        for label in labels {
            let (who, dofs) = match role(part, bodies, label) {
                NodeRole::Reference(b) => {
                    let dofs: Vec<usize> = body_dofs(part.dimension, &bc.dofs).collect();
                    for &k in &dofs {
                        dof_of(part.dimension, k, &bc.location)?;
                    }
                    (Holder::Body(b), dofs)
                }
                NodeRole::Part(i) => (Holder::Node(i), solid_dofs(part.dimension, bc)?),
                NodeRole::Other => {
                    return Err(error(
                        &bc.location,
                        format!(
                            "*BOUNDARY: node {label} is a node of a rigid body but not its \
                             reference node: hold the reference node"
                        ),
                    ));
                }
            };
            for k in dofs {
                held.entry(who).or_default().insert(
                    k,
                    Held {
                        magnitude: bc.magnitude,
                        amplitude: amplitude.clone(),
                        target: bc.target.clone(),
                        step,
                        location: bc.location.clone(),
                    },
                );
            }
        }
    }
    Ok(())
}

pub(super) fn step_spec(
    step: &StepDef,
    boundary: Vec<StepBoundarySpec>,
) -> Result<ModelStepSpec, DeckError> {
    let Some((procedure, location)) = &step.procedure else {
        return Err(error(
            &step.location,
            format!("*STEP {}: give *STATIC or *DYNAMIC", step.name),
        ));
    };
    Ok(match procedure {
        Procedure::Static {
            initial,
            period,
            automatic,
        } => {
            let (increments, automatic) = match automatic {
                Some([min, max]) => (
                    None,
                    Some(AutomaticIncrementsSpec {
                        initial: initial / period,
                        min: min / period,
                        max: max / period,
                    }),
                ),
                None => (Some(direct_increments(*initial, *period, location)?), None),
            };
            ModelStepSpec::Static {
                name: step.name.clone(),
                increments,
                automatic,
                regularization_time: default_regularization_time(),
                time_period: (*period != 1.0).then_some(*period),
                default_amplitude: step
                    .default_amplitude
                    .filter(|&a| a == DefaultAmplitude::Step),
                boundary,
            }
        }
        Procedure::Dynamic {
            dt,
            period,
            alpha,
            automatic,
        } => ModelStepSpec::Dynamic {
            name: step.name.clone(),
            duration: *period,
            dt: *dt,
            alpha: *alpha,
            boundary,
            adaptive: automatic.map(|[min_dt, max_dt]| AdaptiveSpec {
                tolerance: AUTOMATIC_DYNAMIC_TOLERANCE,
                min_dt,
                max_dt,
            }),
            default_amplitude: step
                .default_amplitude
                .filter(|&a| a == DefaultAmplitude::Ramp),
        },
    })
}

/// The number of increments of `*STATIC, DIRECT`: the period must be a whole number of them.
fn direct_increments(initial: f64, period: f64, location: &Location) -> Result<usize, DeckError> {
    let count = period / initial;
    let increments = count.round();
    if !(initial > 0.0 && period > 0.0)
        || (count - increments).abs() > 1e-9 * count
        || increments > 1e7
    {
        return Err(error(
            location,
            format!(
                "*STATIC, DIRECT: the period {period} must be a whole number (at most 1e7) of \
                 increments {initial}"
            ),
        ));
    }
    Ok(increments as usize)
}

/// The model's field interval from the steps' `*OUTPUT, FIELD` requests (skid writes one
/// interval for the whole run): `TIME INTERVAL` as given, `NUMBER INTERVAL=n` the step's time
/// period over `n`; the smallest over the dynamic steps' requests, or, if only static steps
/// ask (whose frames are written at their end whatever the interval), over theirs. `None`
/// without a request.
pub(super) fn field_interval(steps: &[StepDef]) -> Option<f64> {
    let smallest = |dynamic: bool| {
        steps
            .iter()
            .filter_map(|step| {
                match step.procedure.as_ref()?.0 {
                    Procedure::Static { period, .. } if !dynamic => Some(period),
                    Procedure::Dynamic { period, .. } if dynamic => Some(period),
                    _ => None,
                }
                .map(|period| (step, period))
            })
            .flat_map(|(step, period)| {
                step.field_output.iter().map(move |request| match *request {
                    FieldRequest::Time(t) => t,
                    FieldRequest::Number(n) => period / n as f64,
                })
            })
            .reduce(f64::min)
    };
    smallest(true).or_else(|| smallest(false))
}

/// The model's `output.history_nodes` from the steps' `*NODE OUTPUT, NSET=` history requests
/// of `U` (skid writes them for the whole run): each set once, by its name as defined, in the
/// order first asked for.
///
/// # Errors
/// [`DeckError`] at a request whose set is not defined or holds a node outside the part.
pub(super) fn history_nodes(defs: &Definitions, part: &Part) -> Result<Vec<String>, DeckError> {
    let mut names: Vec<String> = Vec::new();
    for (set, location) in defs.steps.iter().flat_map(|step| &step.history_nodes) {
        let Some(defined) = defs.mesh.node_sets.get(&key(set)) else {
            return Err(error(
                location,
                format!("*NODE OUTPUT, NSET={set}: no node set of that name is defined"),
            ));
        };
        if let Some(label) = defined.labels.iter().find(|n| !part.number.contains_key(n)) {
            return Err(error(
                location,
                format!(
                    "*NODE OUTPUT, NSET={set}: node {label} is not a node of the part, whose \
                     displacements are the only ones skid writes"
                ),
            ));
        }
        if !names.contains(&defined.name) {
            names.push(defined.name.clone());
        }
    }
    Ok(names)
}

/// The degrees of freedom (1..=6) of a boundary condition that apply to a rigid body in
/// dimension `dim`: a 2D body has no z translation and no in-plane rotations, so a range or a
/// named condition (ENCASTRE, symmetry) drops 3 to 5; a single one of them stays, to be refused.
fn body_dofs(dim: usize, dofs: &[usize]) -> impl Iterator<Item = usize> + '_ {
    dofs.iter()
        .copied()
        .filter(move |k| !(dim == 2 && (3..=5).contains(k) && dofs.len() > 1))
}
