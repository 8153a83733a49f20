//! The loads of a model file: amplitudes resolved by name, element sets, and every load's
//! values checked against the part and the rigid bodies it acts on.

use std::collections::BTreeMap;

use nalgebra::{SVector, Vector3};
use skid_fem::mesh::SolidMesh;
use skid_fem::rigid::{RigidBody, Rotation};
use skid_integrator::{
    Amplitude, ConcentratedLoad, GravityLoad, LoadTarget, Loads, PressureLoad, StepVariation,
    Variation,
};

use super::{SpecError, fail, finite_point, vector3};
use crate::model_spec::{AmplitudeSpec, AmplitudeTime, Dof, LoadSpec, ModelSpec, ModelStepSpec};

/// Checks that every element of every element set exists (`elements` of them).
pub(super) fn check_element_sets(spec: &ModelSpec, elements: usize) -> Result<(), SpecError> {
    for (name, set) in &spec.part.element_sets {
        if let Some(e) = set.iter().find(|&&e| e >= elements) {
            return fail(
                format!("part.element_sets.{name}"),
                format!("element {e} does not exist ({elements} elements)"),
            );
        }
    }
    Ok(())
}

/// A moment on `body`, which must lie along the body's free rotation axis (in 2D: z), or be any
/// vector on a body free to turn.
fn body_moment<const D: usize>(
    field: &str,
    moment: [f64; 3],
    body: &RigidBody<D>,
) -> Result<Vector3<f64>, SpecError> {
    let m = vector3(field, moment)?;
    for (axis, dof) in [Dof::Rx, Dof::Ry, Dof::Rz].into_iter().enumerate() {
        if m[axis] == 0.0 {
            continue;
        }
        if !Dof::all(D).contains(&dof) {
            return fail(
                field,
                format!("{dof:?} is not a degree of freedom in {D}D: expected 0 there"),
            );
        }
        let turns = match body.rotation {
            Rotation::Free { .. } => true,
            Rotation::Axis(e) => e[axis] == 1.0,
            Rotation::None => false,
        };
        if !turns {
            return fail(
                field,
                format!(
                    "rigid body '{}' does not rotate about {dof:?} (a boundary condition fixes \
                     it): expected 0 there",
                    body.name
                ),
            );
        }
    }
    Ok(m)
}

/// An amplitude of the model file with the time it is read against.
#[derive(Clone, Debug)]
pub(super) struct TimedAmplitude {
    amplitude: Amplitude,
    time: AmplitudeTime,
}

/// The amplitudes by name, each checked: a unique non-empty name, at least one point, finite
/// times >= 0 that increase strictly, finite factors.
pub(super) fn amplitudes(
    specs: &[AmplitudeSpec],
) -> Result<BTreeMap<&str, TimedAmplitude>, SpecError> {
    let mut named = BTreeMap::new();
    for (i, a) in specs.iter().enumerate() {
        let f = |name: &str| format!("amplitudes[{i}].{name}");
        if a.name.is_empty() || named.contains_key(a.name.as_str()) {
            return fail(
                f("name"),
                format!("expected a unique non-empty name, got '{}'", a.name),
            );
        }
        if let Some(k) = a.points.iter().position(|&[t, _]| t < 0.0) {
            return fail(
                format!("{}[{k}]", f("points")),
                format!(
                    "expected a time >= 0, got {} (step and total time start at 0)",
                    a.points[k][0]
                ),
            );
        }
        let points = a.points.iter().map(|&[t, v]| (t, v)).collect();
        let amplitude = Amplitude::new(points).map_err(|e| SpecError {
            field: match e.point {
                Some(k) => format!("{}[{k}]", f("points")),
                None => f("points"),
            },
            message: e.message,
        })?;
        named.insert(
            a.name.as_str(),
            TimedAmplitude {
                amplitude,
                time: a.time,
            },
        );
    }
    Ok(named)
}

/// The amplitude a load or motion names (`field`), if it names one.
pub(super) fn amplitude_named(
    named: &BTreeMap<&str, TimedAmplitude>,
    name: Option<&str>,
    field: &str,
) -> Result<Option<TimedAmplitude>, SpecError> {
    name.map(|name| {
        named.get(name).cloned().ok_or_else(|| SpecError {
            field: field.into(),
            message: format!("no amplitude named '{name}'"),
        })
    })
    .transpose()
}

/// The time period of each step (a dynamic step's duration, a static step's `time_period`, 1
/// by default) and the total time at its start.
///
/// # Errors
/// A time period that is not a finite number > 0.
fn step_periods(steps: &[ModelStepSpec]) -> Result<Vec<(f64, f64)>, SpecError> {
    let mut start = 0.0;
    let mut periods = Vec::with_capacity(steps.len());
    for (k, step) in steps.iter().enumerate() {
        let period = match step {
            ModelStepSpec::Static { time_period, .. } => time_period.unwrap_or(1.0),
            ModelStepSpec::Dynamic { duration, .. } => *duration,
        };
        if !(period.is_finite() && period > 0.0) {
            let field = match step {
                ModelStepSpec::Static { .. } => "time_period",
                ModelStepSpec::Dynamic { .. } => "duration",
            };
            return fail(
                format!("steps[{k}].{field}"),
                format!("expected a finite value > 0, got {period}"),
            );
        }
        periods.push((period, start));
        start += period;
    }
    Ok(periods)
}

/// `a` as the solver reads it in step `step` of `steps` with `periods` (see [`step_periods`]):
/// against the solver's step time `s` (s in a dynamic step, the completed fraction of a static
/// one), `a(t_0 + c s)`, `t_0` the total time at the step's start for a total-time amplitude
/// (0 otherwise) and `c` the time period of a static step (1 in a dynamic one). A
/// piecewise-linear table transforms exactly: its times become `(t_k - t_0) / c`. `None` if
/// `a` is read unchanged (`t_0 = 0`, `c = 1`).
fn in_step(
    a: &TimedAmplitude,
    step: &ModelStepSpec,
    (period, start): (f64, f64),
    field: &str,
) -> Result<Option<Amplitude>, SpecError> {
    let offset = match a.time {
        AmplitudeTime::Step => 0.0,
        AmplitudeTime::Total => start,
    };
    let scale = match step {
        ModelStepSpec::Static { .. } => period,
        ModelStepSpec::Dynamic { .. } => 1.0,
    };
    if offset == 0.0 && scale == 1.0 {
        return Ok(None);
    }
    let points = a
        .amplitude
        .points()
        .iter()
        .map(|&(t, v)| ((t - offset) / scale, v))
        .collect();
    Amplitude::new(points).map(Some).map_err(|e| SpecError {
        field: field.into(),
        message: format!("the amplitude read in this step: {e}"),
    })
}

/// How a load with `amplitude` and `step_factors` (`field`) varies over `steps` (see
/// [`ModelSpec::loads`]): with factors `c_k`, `c_k A(t)` with an amplitude `A` (read as
/// [`in_step`] says); without one the ramp from `c_{k-1}` (`c_{-1} = 0`) to `c_k` over a step
/// that ramps ([`ModelStepSpec::ramps`]: by default a static one) and `c_k` throughout any
/// other. Without factors, the amplitude in every step, or the default ramp (factors of 1 in
/// every step if a step departs from its procedure's default amplitude).
pub(super) fn variation(
    amplitude: Option<TimedAmplitude>,
    step_factors: Option<&[f64]>,
    steps: &[ModelStepSpec],
    field: &str,
) -> Result<Variation, SpecError> {
    let periods = step_periods(steps)?;
    // the amplitude as each step reads it (`None`: unchanged)
    let read = amplitude
        .as_ref()
        .map(|a| {
            steps
                .iter()
                .zip(&periods)
                .map(|(step, &p)| in_step(a, step, p, field))
                .collect::<Result<Vec<_>, _>>()
        })
        .transpose()?;
    // a load without factors varies step by step, with a factor of 1 in each, if a step reads
    // its amplitude transformed or, without one, departs from its procedure's default amplitude
    let varies_per_step = match &read {
        Some(read) => read.iter().any(Option::is_some),
        None => steps
            .iter()
            .any(ModelStepSpec::departs_from_default_amplitude),
    };
    let unit_factors;
    let factors = match step_factors {
        Some(factors) => factors,
        None if varies_per_step => {
            unit_factors = vec![1.0; steps.len()];
            unit_factors.as_slice()
        }
        None => return Ok(amplitude.map_or(Variation::Ramp, |a| Variation::Amplitude(a.amplitude))),
    };
    if factors.len() != steps.len() {
        return fail(
            field,
            format!(
                "expected one factor per step ({} steps), got {}",
                steps.len(),
                factors.len()
            ),
        );
    }
    if let Some(k) = factors.iter().position(|c| !c.is_finite()) {
        return fail(
            format!("{field}[{k}]"),
            format!("expected a finite number, got {}", factors[k]),
        );
    }
    let mut previous = 0.0;
    let per_step = factors
        .iter()
        .zip(steps)
        .enumerate()
        .map(|(k, (&c, step))| {
            let from = if step.ramps() { previous } else { c };
            previous = c;
            match (&amplitude, &read) {
                (Some(a), Some(read)) => StepVariation::Amplitude {
                    amplitude: read[k].clone().unwrap_or_else(|| a.amplitude.clone()),
                    scale: c,
                },
                _ => StepVariation::Ramp { from, to: c },
            }
        })
        .collect();
    Ok(Variation::PerStep(per_step))
}

/// Every load of `spec`, resolved and checked, given the model's amplitudes by name.
///
/// # Errors
/// The first problem, with its field path.
pub(super) fn loads<const D: usize>(
    spec: &ModelSpec,
    mesh: &SolidMesh<D>,
    bodies: &[RigidBody<D>],
    named: &BTreeMap<&str, TimedAmplitude>,
    body_of: &impl Fn(&str, &str) -> Result<usize, SpecError>,
) -> Result<Loads<D>, SpecError> {
    let mut loads = Loads::default();
    for (i, load) in spec.loads.iter().enumerate() {
        let f = |name: &str| format!("loads[{i}].{name}");
        let amplitude = amplitude_named(named, load.amplitude(), &f("amplitude"))?;
        let variation = variation(
            amplitude,
            load.step_factors(),
            &spec.steps,
            &f("step_factors"),
        )?;
        match load {
            LoadSpec::Pressure {
                surface, pressure, ..
            } => {
                if !pressure.is_finite() {
                    return fail(
                        f("pressure"),
                        format!("expected a finite value, got {pressure}"),
                    );
                }
                let faces = mesh.surfaces.get(surface).ok_or_else(|| SpecError {
                    field: f("surface"),
                    message: format!("no surface named '{surface}' in part '{}'", spec.part.name),
                })?;
                loads.pressures.push(PressureLoad {
                    faces: faces.clone(),
                    pressure: *pressure,
                    variation,
                });
            }
            LoadSpec::Concentrated {
                node_set,
                body,
                force,
                moment,
                ..
            } => {
                if force.is_none() && moment.is_none() {
                    return fail(format!("loads[{i}]"), "expected a force, a moment or both");
                }
                let force = match force {
                    Some(v) => finite_point::<D>(&f("force"), v)?,
                    None => SVector::zeros(),
                };
                let (target, moment) = match (node_set, body) {
                    (Some(set), None) => {
                        if moment.is_some() {
                            return fail(f("moment"), "nodes of a solid part take no moment");
                        }
                        let nodes = mesh.node_sets.get(set).ok_or_else(|| SpecError {
                            field: f("node_set"),
                            message: format!(
                                "no node set named '{set}' in part '{}'",
                                spec.part.name
                            ),
                        })?;
                        (LoadTarget::Nodes(nodes.clone()), Vector3::zeros())
                    }
                    (None, Some(name)) => {
                        let b = body_of(&f("body"), name)?;
                        let moment = match moment {
                            Some(m) => body_moment(&f("moment"), *m, &bodies[b])?,
                            None => Vector3::zeros(),
                        };
                        (LoadTarget::Body(b), moment)
                    }
                    _ => {
                        return fail(
                            format!("loads[{i}]"),
                            "expected exactly one of node_set and body",
                        );
                    }
                };
                loads.concentrated.push(ConcentratedLoad {
                    target,
                    force,
                    moment,
                    variation,
                });
            }
            LoadSpec::Gravity {
                acceleration,
                element_set,
                ..
            } => {
                let acceleration = finite_point::<D>(&f("acceleration"), acceleration)?;
                let elements = element_set
                    .as_ref()
                    .map(|name| {
                        spec.part
                            .element_sets
                            .get(name)
                            .cloned()
                            .ok_or_else(|| SpecError {
                                field: f("element_set"),
                                message: format!(
                                    "no element set named '{name}' in part '{}'",
                                    spec.part.name
                                ),
                            })
                    })
                    .transpose()?;
                loads.gravity.push(GravityLoad {
                    acceleration,
                    elements,
                    variation,
                });
            }
        }
    }
    Ok(loads)
}
