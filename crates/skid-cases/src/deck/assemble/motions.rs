//! Prescribed motions of a deck: a step's `*BOUNDARY` line with a nonzero magnitude on a rigid
//! body's reference node or on nodes of the part moves that degree of freedom to the magnitude
//! (a displacement or a rotation from the reference configuration), carried into later steps
//! as the loads are.
//!
//! A degree of freedom with a nonzero magnitude in some step becomes part of one `boundary`
//! entry of the model with a `value` (its first nonzero magnitude) and a factor per step (its
//! magnitude there over the value; 0 where it is held at zero, by model data or a line without
//! magnitude), so that it varies as the model file says a load does: ramped over a static step
//! from the previous step's value, at once in a dynamic one, or times its `AMPLITUDE=` in the
//! step time. Part nodes that move alike (same degree of freedom, value, amplitude and factors)
//! share one entry on a node set: the deck's set of exactly those nodes if it has one, a new
//! `motion-N` set otherwise. The model holds a prescribed degree of freedom in every step, so a
//! deck that leaves it free in one step (before it is prescribed, or after `OP=NEW` drops it) is
//! refused, as is one that gives it different amplitudes in different steps. A part node that
//! steps hold at zero only is held throughout if every step holds it (a `held-N` set), and
//! otherwise by the steps that hold it, at its value at the step's start, as the reference nodes
//! of rigid bodies are.

use super::*;

/// Who a step's `*BOUNDARY` holds: a rigid body's reference node or a node of the part.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(super) enum Holder {
    /// Rigid body, by index.
    Body(usize),
    /// Node of the part, by its number from 0.
    Node(usize),
}

/// A degree of freedom held by a step's `*BOUNDARY`: at `magnitude`, times `amplitude` if one
/// is named.
#[derive(Clone, Debug)]
pub(super) struct Held {
    pub magnitude: f64,
    pub amplitude: Option<String>,
    /// The node or node set the line names.
    pub target: String,
    /// The step (from 0) whose line gives it.
    pub step: usize,
    pub location: Location,
}

/// The conditions in force in one step: holder -> degree of freedom (1..=6) -> condition.
pub(super) type HeldInStep = BTreeMap<Holder, BTreeMap<usize, Held>>;

/// The prescribed motions of a deck (see the module documentation).
pub(super) struct Prescribed {
    /// The model's `boundary` entries with a value, and the part nodes held at zero by every
    /// step.
    pub boundary: Vec<BoundarySpec>,
    /// The degrees of freedom of rigid bodies they move: (body, degree of freedom 1..=6).
    moved: BTreeSet<(usize, usize)>,
    /// The holds of part nodes that some steps hold and others leave free, by step.
    pub in_steps: Vec<Vec<StepBoundarySpec>>,
}

impl Prescribed {
    /// Whether degree of freedom `k` of body `b` is prescribed.
    pub fn moves(&self, b: usize, k: usize) -> bool {
        self.moved.contains(&(b, k))
    }
}

/// How one degree of freedom is held over the steps: its value, amplitude and factor per step
/// (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
struct History {
    value: f64,
    amplitude: Option<String>,
    factors: Option<Vec<f64>>,
}

/// Part nodes held alike in one degree of freedom.
struct NodeGroup<'a> {
    /// The degree of freedom, 1..=3.
    dof: usize,
    /// How it is held (`None`: at zero in every step).
    history: Option<History>,
    /// The node or node set named by the first line that holds one of them.
    target: &'a str,
    /// The nodes, in increasing order.
    nodes: Vec<usize>,
}

/// The prescribed motions of the degrees of freedom from the conditions in force in each step,
/// `held[s]`; `model_held` holds the part's (node, degree of freedom) that model data holds, and
/// `node_sets` the part's node sets, to which the sets of moved nodes are added.
///
/// # Errors
/// At the line of a nonzero magnitude whose degree of freedom is free in some step, that
/// changes its amplitude between steps, or that rotates a body held in that rotation by model
/// data (model data fixes which rotation a body has).
pub(super) fn prescribed_motions(
    defs: &Definitions,
    part: &Part,
    bodies: &[Body],
    held: &[HeldInStep],
    model_held: &BTreeSet<(usize, usize)>,
    node_sets: &mut BTreeMap<String, Vec<usize>>,
) -> Result<Prescribed, DeckError> {
    let dim = part.dimension;
    // the first condition of each degree of freedom, and whether it ever has a magnitude
    let mut places: BTreeMap<(Holder, usize), (&Held, bool)> = BTreeMap::new();
    for conditions in held {
        for (&who, dofs) in conditions {
            for (&k, h) in dofs {
                let place = places.entry((who, k)).or_insert((h, false));
                if h.magnitude != 0.0 && !place.1 {
                    *place = (h, true);
                }
            }
        }
    }
    let mut boundary: Vec<BoundarySpec> = Vec::new();
    let mut moved = BTreeSet::new();
    let mut node_groups: Vec<NodeGroup> = Vec::new();
    // part nodes held in some steps only: (step, degree of freedom, first line's target, nodes)
    let mut step_holds: Vec<(usize, usize, &str, Vec<usize>)> = Vec::new();
    for (&(who, k), &(first, prescribed)) in &places {
        let (name, in_model_data) = match who {
            Holder::Body(b) => (
                format!("rigid body {}", bodies[b].def.name),
                bodies[b].fixed.contains(&k),
            ),
            Holder::Node(i) => (
                format!("node {}", part.labels[i]),
                model_held.contains(&(i, k)),
            ),
        };
        if !prescribed && (in_model_data || matches!(who, Holder::Body(_))) {
            continue;
        }
        // a part node held at zero in some steps only: held by those steps
        if let (Holder::Node(i), false) = (who, prescribed) {
            let in_steps: Vec<usize> = (0..held.len())
                .filter(|&s| held[s].get(&who).is_some_and(|dofs| dofs.contains_key(&k)))
                .collect();
            if in_steps.len() < held.len() {
                dof_of(dim, k, &first.location)?;
                for s in in_steps {
                    match step_holds
                        .iter_mut()
                        .find(|(step, dof, _, _)| (*step, *dof) == (s, k))
                    {
                        Some((.., nodes)) => nodes.push(i),
                        None => step_holds.push((s, k, &first.target, vec![i])),
                    }
                }
                continue;
            }
        }
        if prescribed && in_model_data && k > 3 {
            return Err(error(
                &first.location,
                format!(
                    "*BOUNDARY: rotation {k} of {name} is prescribed here and held by model \
                     data, which leaves the body another rotation: hold it in the steps instead"
                ),
            ));
        }
        let mut magnitudes = Vec::with_capacity(held.len());
        let mut amplitude: Option<&String> = None;
        for (s, conditions) in held.iter().enumerate() {
            match conditions.get(&who).and_then(|dofs| dofs.get(&k)) {
                Some(h) => {
                    if let (Some(earlier), Some(a)) = (amplitude, &h.amplitude)
                        && earlier != a
                    {
                        return Err(error(
                            &h.location,
                            format!(
                                "*BOUNDARY, AMPLITUDE={a}: degree of freedom {k} of {name} \
                                 follows amplitude {earlier} in an earlier step; skid gives a \
                                 prescribed motion one amplitude for the whole run"
                            ),
                        ));
                    }
                    amplitude = amplitude.or(h.amplitude.as_ref());
                    magnitudes.push(h.magnitude);
                }
                None if in_model_data => magnitudes.push(0.0),
                None => {
                    return Err(error(
                        &first.location,
                        format!(
                            "*BOUNDARY: degree of freedom {k} of {name} is prescribed here but \
                             free in step {} ({}); skid holds a prescribed degree of freedom \
                             throughout the run: hold it (at zero) in model data or in that step",
                            s + 1,
                            defs.steps[s].name
                        ),
                    ));
                }
            }
        }
        let history = prescribed.then(|| {
            let value = first.magnitude;
            let factors: Vec<f64> = magnitudes.iter().map(|m| m / value).collect();
            History {
                value,
                amplitude: amplitude.cloned(),
                factors: factors.iter().any(|&c| c != 1.0).then_some(factors),
            }
        });
        match who {
            Holder::Body(b) => {
                let history = history.expect("bodies held at zero only were skipped");
                moved.insert((b, k));
                push_merged(
                    &mut boundary,
                    BoundarySpec {
                        body: Some(bodies[b].def.name.clone()),
                        node_set: None,
                        dofs: vec![dof_of(dim, k, &first.location)?],
                        value: Some(history.value),
                        amplitude: history.amplitude,
                        step_factors: history.factors,
                    },
                );
            }
            Holder::Node(i) => {
                dof_of(dim, k, &first.location)?;
                match node_groups
                    .iter_mut()
                    .find(|g| (g.dof, &g.history) == (k, &history))
                {
                    Some(group) => group.nodes.push(i),
                    None => node_groups.push(NodeGroup {
                        dof: k,
                        history,
                        target: &first.target,
                        nodes: vec![i],
                    }),
                }
            }
        }
    }
    for NodeGroup {
        dof: k,
        history,
        target,
        nodes,
    } in node_groups
    {
        let prefix = if history.is_some() { "motion" } else { "held" };
        let set = node_set_of(node_sets, nodes, deck_set(defs, target), prefix);
        let dof = dof_of(dim, k, &defs.steps[0].location)?;
        push_merged(
            &mut boundary,
            BoundarySpec {
                body: None,
                node_set: Some(set),
                dofs: vec![dof],
                value: history.as_ref().map(|h| h.value),
                amplitude: history.as_ref().and_then(|h| h.amplitude.clone()),
                step_factors: history.and_then(|h| h.factors),
            },
        );
    }
    let mut in_steps = vec![Vec::new(); held.len()];
    for (s, k, target, nodes) in step_holds {
        let set = node_set_of(node_sets, nodes, deck_set(defs, target), "held");
        let dof = dof_of(dim, k, &defs.steps[s].location)?;
        let holds: &mut Vec<StepBoundarySpec> = &mut in_steps[s];
        match holds
            .iter_mut()
            .find(|h| h.node_set.as_deref() == Some(set.as_str()))
        {
            Some(h) => h.dofs.get_or_insert_with(Vec::new).push(dof),
            None => holds.push(StepBoundarySpec {
                body: None,
                node_set: Some(set),
                dofs: Some(vec![dof]),
            }),
        }
    }
    Ok(Prescribed {
        boundary,
        moved,
        in_steps,
    })
}

/// Adds `entry` to `boundary`, as more degrees of freedom of an entry that holds the same
/// body or node set alike if there is one.
fn push_merged(boundary: &mut Vec<BoundarySpec>, entry: BoundarySpec) {
    let alike = |m: &&mut BoundarySpec| {
        (&m.body, &m.node_set, m.value, &m.amplitude, &m.step_factors)
            == (
                &entry.body,
                &entry.node_set,
                entry.value,
                &entry.amplitude,
                &entry.step_factors,
            )
    };
    match boundary.iter_mut().find(alike) {
        Some(m) => m.dofs.extend(entry.dofs),
        None => boundary.push(entry),
    }
}

/// The deck's spelling of `target` if it names a node set (`None` for a node label).
fn deck_set<'a>(defs: &'a Definitions, target: &str) -> Option<&'a str> {
    defs.mesh
        .node_sets
        .get(&key(target))
        .map(|s| s.name.as_str())
}

/// The name of a node set of exactly `nodes` (in increasing order): `named` if it is that set,
/// else an existing one if there is one, else a new one, `prefix-N` with the first free `N`
/// from 1.
fn node_set_of(
    node_sets: &mut BTreeMap<String, Vec<usize>>,
    nodes: Vec<usize>,
    named: Option<&str>,
    prefix: &str,
) -> String {
    let same = |set: &Vec<usize>| {
        let mut set = set.clone();
        set.sort_unstable();
        set == nodes
    };
    if let Some(name) = named.filter(|name| node_sets.get(*name).is_some_and(same)) {
        return name.to_string();
    }
    if let Some((name, _)) = node_sets.iter().find(|(_, set)| same(set)) {
        return name.clone();
    }
    let name = (1..)
        .map(|n| format!("{prefix}-{n}"))
        .find(|name| !node_sets.contains_key(name))
        .expect("a free name");
    node_sets.insert(name.clone(), nodes);
    name
}

/// Model-data `boundary` entries without the degrees of freedom that `motions` prescribe (the
/// motion holds them at zero where it is not in force): a body's entry loses those degrees of
/// freedom, a node set's entry keeps holding its other nodes in them on a new set
/// `<set>-held-N`; entries left without any are dropped.
pub(super) fn without_prescribed(
    boundary: Vec<BoundarySpec>,
    motions: &[BoundarySpec],
    node_sets: &mut BTreeMap<String, Vec<usize>>,
) -> Vec<BoundarySpec> {
    let mut out = Vec::new();
    for mut bc in boundary {
        if let Some(body) = bc.body.as_deref() {
            bc.dofs.retain(|dof| {
                !motions
                    .iter()
                    .any(|m| m.body.as_deref() == Some(body) && m.dofs.contains(dof))
            });
        } else if let Some(set) = bc.node_set.clone() {
            let nodes = node_sets.get(&set).cloned().unwrap_or_default();
            let mut kept = Vec::new();
            for dof in std::mem::take(&mut bc.dofs) {
                let moved: BTreeSet<usize> = motions
                    .iter()
                    .filter(|m| m.dofs.contains(&dof))
                    .filter_map(|m| m.node_set.as_ref().and_then(|s| node_sets.get(s)))
                    .flatten()
                    .copied()
                    .collect();
                let rest: Vec<usize> = nodes
                    .iter()
                    .copied()
                    .filter(|n| !moved.contains(n))
                    .collect();
                if rest.len() == nodes.len() {
                    kept.push(dof);
                } else if !rest.is_empty() {
                    let name = node_set_of(node_sets, rest, None, &format!("{set}-held"));
                    out.push(BoundarySpec {
                        node_set: Some(name),
                        dofs: vec![dof],
                        ..bc.clone()
                    });
                }
            }
            bc.dofs = kept;
        }
        if !bc.dofs.is_empty() {
            out.push(bc);
        }
    }
    out
}
