//! Prescribed motions of a deck: a step's `*BOUNDARY` line with a nonzero magnitude on a rigid
//! body's reference node moves that degree of freedom to the magnitude (a displacement or a
//! rotation from the reference configuration), carried into later steps as the loads are.
//!
//! A degree of freedom with a nonzero magnitude in some step becomes one `boundary` entry of
//! the model with a `value` (its first nonzero magnitude) and a factor per step (its magnitude
//! there over the value; 0 where it is held at zero, by model data or a line without magnitude),
//! so that it varies as the model file says a load does: ramped over a static step from the
//! previous step's value, at once in a dynamic one, or times its `AMPLITUDE=` in the step time.
//! The model holds a prescribed degree of freedom in every step, so a deck that leaves it free
//! in one step (before it is prescribed, or after `OP=NEW` drops it) is refused, as is one that
//! gives it different amplitudes in different steps.

use super::*;

/// A degree of freedom of a rigid body held by a step's `*BOUNDARY`: at `magnitude`, times
/// `amplitude` if one is named.
#[derive(Clone, Debug)]
pub(super) struct Held {
    pub magnitude: f64,
    pub amplitude: Option<String>,
    pub location: Location,
}

/// The prescribed motions of a deck (see the module documentation).
pub(super) struct Prescribed {
    /// The model's `boundary` entries with a value.
    pub motions: Vec<BoundarySpec>,
    /// The degrees of freedom they move: (body, degree of freedom 1..=6).
    moved: BTreeSet<(usize, usize)>,
}

impl Prescribed {
    /// Whether degree of freedom `k` of body `b` is prescribed.
    pub fn moves(&self, b: usize, k: usize) -> bool {
        self.moved.contains(&(b, k))
    }
}

/// The prescribed motions of the bodies' degrees of freedom from the conditions in force in
/// each step, `held[s]` (body -> degree of freedom -> condition).
///
/// # Errors
/// At the line of a nonzero magnitude whose degree of freedom is free in some step, that
/// changes its amplitude between steps, or that rotates a body held in that rotation by model
/// data (model data fixes which rotation a body has).
pub(super) fn prescribed_motions(
    defs: &Definitions,
    part: &Part,
    bodies: &[Body],
    held: &[BTreeMap<usize, BTreeMap<usize, Held>>],
) -> Result<Prescribed, DeckError> {
    let dim = part.dimension;
    let mut places: BTreeMap<(usize, usize), &Held> = BTreeMap::new();
    for conditions in held {
        for (&b, dofs) in conditions {
            for (&k, h) in dofs {
                if h.magnitude != 0.0 {
                    places.entry((b, k)).or_insert(h);
                }
            }
        }
    }
    // one entry per body, value, amplitude and factors, by body and degree of freedom
    let mut motions: Vec<BoundarySpec> = Vec::new();
    for (&(b, k), first) in &places {
        let name = &bodies[b].def.name;
        let in_model_data = bodies[b].fixed.contains(&k);
        if in_model_data && k > 3 {
            return Err(error(
                &first.location,
                format!(
                    "*BOUNDARY: rotation {k} of rigid body {name} is prescribed here and held by \
                     model data, which leaves the body another rotation: hold it in the steps instead"
                ),
            ));
        }
        let mut magnitudes = Vec::with_capacity(held.len());
        let mut amplitude: Option<&String> = None;
        for (s, conditions) in held.iter().enumerate() {
            let condition = conditions.get(&b).and_then(|dofs| dofs.get(&k));
            match condition {
                Some(h) => {
                    if let (Some(earlier), Some(a)) = (amplitude, &h.amplitude)
                        && earlier != a
                    {
                        return Err(error(
                            &h.location,
                            format!(
                                "*BOUNDARY, AMPLITUDE={a}: degree of freedom {k} of rigid body \
                                 {name} follows amplitude {earlier} in an earlier step; skid \
                                 gives a prescribed motion one amplitude for the whole run"
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
                            "*BOUNDARY: degree of freedom {k} of rigid body {name} is prescribed \
                             here but free in step {} ({}); skid holds a prescribed degree of \
                             freedom throughout the run: hold it (at zero) in model data or in \
                             that step",
                            s + 1,
                            defs.steps[s].name
                        ),
                    ));
                }
            }
        }
        let value = first.magnitude;
        let factors: Vec<f64> = magnitudes.iter().map(|m| m / value).collect();
        let motion = BoundarySpec {
            body: Some(name.clone()),
            node_set: None,
            dofs: vec![dof_of(dim, k, &first.location)?],
            value: Some(value),
            amplitude: amplitude.cloned(),
            step_factors: factors.iter().any(|&c| c != 1.0).then_some(factors),
        };
        let same = |m: &&mut BoundarySpec| {
            (&m.body, m.value, &m.amplitude, &m.step_factors)
                == (
                    &motion.body,
                    motion.value,
                    &motion.amplitude,
                    &motion.step_factors,
                )
        };
        match motions.iter_mut().find(same) {
            Some(m) => m.dofs.extend(motion.dofs),
            None => motions.push(motion),
        }
    }
    Ok(Prescribed {
        motions,
        moved: places.into_keys().collect(),
    })
}

/// Model-data `boundary` entries without the degrees of freedom that `motions` prescribe (the
/// motion holds them at zero where it is not in force); entries left without any are dropped.
pub(super) fn without_prescribed(
    boundary: Vec<BoundarySpec>,
    motions: &[BoundarySpec],
) -> Vec<BoundarySpec> {
    boundary
        .into_iter()
        .filter_map(|mut bc| {
            let Some(body) = bc.body.as_deref() else {
                return Some(bc);
            };
            bc.dofs.retain(|dof| {
                !motions
                    .iter()
                    .any(|m| m.body.as_deref() == Some(body) && m.dofs.contains(dof))
            });
            (!bc.dofs.is_empty()).then_some(bc)
        })
        .collect()
}
