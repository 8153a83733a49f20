//! The prescribed motions of a model file: every `boundary` entry with a `value` moves each of
//! its degrees of freedom, of its body or of every node of its node set, to `value` times the
//! factor of its variation (amplitude, step factors, or the default ramp, as a load's).

use std::collections::BTreeMap;

use skid_fem::mesh::SolidMesh;
use skid_fem::rigid::{RigidBody, Rotation};
use skid_integrator::{BodyMotion, MotionTarget, PrescribedMotion};

use super::loads::{TimedAmplitude, amplitude_named, variation};
use super::{SpecError, fail};
use crate::model_spec::ModelSpec;

/// The prescribed motions of `spec` (see the module documentation), given its checked mesh,
/// bodies and amplitudes by name: those of each `boundary` entry that prescribes, with its
/// index.
///
/// # Errors
/// A [`SpecError`] for an amplitude or step factors without a value, a value that is not
/// finite, an unknown amplitude, body or node set, a rotation of a part's nodes, or a rotation
/// about another axis than the body's free one.
pub(super) fn prescribed_motions<const D: usize>(
    spec: &ModelSpec,
    mesh: &SolidMesh<D>,
    bodies: &[RigidBody<D>],
    amplitudes: &BTreeMap<&str, TimedAmplitude>,
    body_of: &impl Fn(&str, &str) -> Result<usize, SpecError>,
) -> Result<Vec<(usize, Vec<PrescribedMotion>)>, SpecError> {
    let mut motions = Vec::new();
    for (i, bc) in spec.boundary.iter().enumerate() {
        let f = |name: &str| format!("boundary[{i}].{name}");
        let Some(value) = bc.value else {
            if bc.amplitude.is_some() || bc.step_factors.is_some() {
                return fail(
                    f("value"),
                    "amplitude and step_factors vary a prescribed motion: give its value",
                );
            }
            continue;
        };
        if !value.is_finite() {
            return fail(f("value"), format!("expected a finite number, got {value}"));
        }
        let amplitude = amplitude_named(amplitudes, bc.amplitude.as_deref(), &f("amplitude"))?;
        let variation = variation(
            amplitude,
            bc.step_factors.as_deref(),
            &spec.steps,
            &f("step_factors"),
        )?;
        let mut targets = Vec::new();
        if let Some(name) = &bc.body {
            let body = body_of(&f("body"), name)?;
            for dof in &bc.dofs {
                let motion = match dof.translation_axis() {
                    Some(axis) => BodyMotion::Translation(axis),
                    None => {
                        let rotation = bodies[body].rotation;
                        if let Rotation::Free { .. } = rotation {
                            return fail(
                                f("dofs"),
                                format!(
                                    "rigid body '{name}' is free to turn: prescribing its \
                                     {dof:?} is not supported; fix its other rotations with a \
                                     boundary condition"
                                ),
                            );
                        }
                        if let (Rotation::Axis(e), Some(k)) = (rotation, dof.rotation_axis())
                            && e[k].abs() != 1.0
                        {
                            return fail(
                                f("dofs"),
                                format!(
                                    "rigid body '{name}' rotates about {:?}, not about {dof:?}",
                                    [e.x, e.y, e.z]
                                ),
                            );
                        }
                        BodyMotion::Rotation
                    }
                };
                targets.push(MotionTarget::Body { body, motion });
            }
        } else if let Some(set) = &bc.node_set {
            let nodes = mesh.node_sets.get(set).ok_or_else(|| SpecError {
                field: f("node_set"),
                message: format!("no node set named '{set}' in part '{}'", spec.part.name),
            })?;
            for dof in &bc.dofs {
                let Some(axis) = dof.translation_axis() else {
                    return fail(
                        f("dofs"),
                        format!("nodes of a solid part have no rotation {dof:?}"),
                    );
                };
                targets.extend(nodes.iter().map(|&node| MotionTarget::Node { node, axis }));
            }
        }
        let prescribed = targets.into_iter().map(|target| PrescribedMotion {
            target,
            value,
            variation: variation.clone(),
        });
        motions.push((i, prescribed.collect()));
    }
    Ok(motions)
}
