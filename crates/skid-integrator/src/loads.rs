//! Loads and how they vary over a run: follower pressures, concentrated forces and moments, and
//! gravity, each scaled by its amplitude or by the default ramp.
//!
//! A load's factor at an instant of a step follows its [`Variation`]: `A(t_s)` if it has an
//! [`Amplitude`] `A`, read against the step time `t_s` (the time since the step began in a
//! dynamic step; in a static step, which takes no physical time, the completed fraction of the
//! step, 0 to 1, as a static step of unit time period); by default the ramp: in a first step
//! that is static, the fraction of it completed, and 1 from then on (and throughout when the
//! first step is dynamic); or, for a load that changes between steps, its own variation in
//! each step ([`StepVariation`]). The nodal forces at an instant are `f = sum_l factor_l f_l`,
//! the pressures' `f_l` on the current geometry, the others fixed in direction and size (dead
//! loads).

use nalgebra::{DVector, SVector, Vector3};

use crate::dof::DofMap;
use crate::error::ModelError;
use skid_fem::element::SolidElement;
use skid_fem::rigid::{RigidBody, Rotation};

/// A piecewise-linear function of the step time given by points `(t_k, a_k)` with increasing
/// `t_k`: `a(t) = a_k + (a_{k+1} - a_k) (t - t_k) / (t_{k+1} - t_k)` on `[t_k, t_{k+1}]`, held
/// at `a_0` before the first point and at the last value after the last.
#[derive(Clone, Debug, PartialEq)]
pub struct Amplitude {
    points: Vec<(f64, f64)>,
}

impl Amplitude {
    /// The amplitude through `points`.
    ///
    /// # Errors
    /// [`AmplitudeError`] if there is no point, a time or value is not finite, or the times do
    /// not increase strictly.
    pub fn new(points: Vec<(f64, f64)>) -> Result<Self, AmplitudeError> {
        if points.is_empty() {
            return Err(AmplitudeError {
                point: None,
                message: "expected at least one (time, factor) point".into(),
            });
        }
        for (k, &(t, a)) in points.iter().enumerate() {
            let at = |message: String| {
                Err(AmplitudeError {
                    point: Some(k),
                    message,
                })
            };
            if !(t.is_finite() && a.is_finite()) {
                return at(format!("expected finite numbers, got [{t}, {a}]"));
            }
            if k > 0 && t <= points[k - 1].0 {
                return at(format!(
                    "the times must increase, got {t} after {}",
                    points[k - 1].0
                ));
            }
        }
        Ok(Self { points })
    }

    /// The points `(t_k, a_k)`.
    pub fn points(&self) -> &[(f64, f64)] {
        &self.points
    }

    /// `a(t)` (see [`Amplitude`]).
    pub fn at(&self, t: f64) -> f64 {
        let after = self.points.partition_point(|&(tk, _)| tk <= t);
        match (after.checked_sub(1), self.points.get(after)) {
            (None, _) => self.points[0].1,
            (Some(k), None) => self.points[k].1,
            (Some(k), Some(&(t1, a1))) => {
                let (t0, a0) = self.points[k];
                a0 + (a1 - a0) * (t - t0) / (t1 - t0)
            }
        }
    }
}

/// Why a table of points is not an amplitude.
#[derive(Clone, Debug, PartialEq)]
pub struct AmplitudeError {
    /// The point at fault, counted from 0 (`None`: the table as a whole).
    pub point: Option<usize>,
    /// What is wrong.
    pub message: String,
}

impl std::fmt::Display for AmplitudeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.point {
            Some(k) => write!(f, "point {k}: {}", self.message),
            None => f.write_str(&self.message),
        }
    }
}

/// How a load's factor varies over one step.
#[derive(Clone, Debug, PartialEq)]
pub enum StepVariation {
    /// Linear in the completed fraction `s` of the step: `from + (to - from) s`.
    Ramp {
        /// Factor at the start of the step.
        from: f64,
        /// Factor at its end.
        to: f64,
    },
    /// `scale A(t_s)`, with `A` read against the step time.
    Amplitude {
        /// The amplitude `A`.
        amplitude: Amplitude,
        /// Factor on it.
        scale: f64,
    },
}

/// How a load's factor varies over the run (see the module documentation).
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Variation {
    /// The default ramp.
    #[default]
    Ramp,
    /// `A(t_s)` in every step.
    Amplitude(Amplitude),
    /// One variation per step of the run, in order (the run checks that there is one for every
    /// step).
    PerStep(Vec<StepVariation>),
}

/// Where the loads stand at an instant of a step (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LoadInstant {
    /// Factor of the loads that follow the default ramp.
    pub ramp: f64,
    /// Step time the amplitudes are read against (s in a dynamic step, the completed fraction
    /// of a static step).
    pub step_time: f64,
    /// Index of the step in the run.
    pub step: usize,
    /// Completed fraction of the step, 0 to 1.
    pub fraction: f64,
}

impl LoadInstant {
    /// The factor of a load that varies as `variation`. A per-step variation missing for this
    /// step (which a run's check of its steps excludes) gives 0.
    pub fn factor(&self, variation: &Variation) -> f64 {
        match variation {
            Variation::Ramp => self.ramp,
            Variation::Amplitude(a) => a.at(self.step_time),
            Variation::PerStep(steps) => match steps.get(self.step) {
                Some(StepVariation::Ramp { from, to }) => from + (to - from) * self.fraction,
                Some(StepVariation::Amplitude { amplitude, scale }) => {
                    scale * amplitude.at(self.step_time)
                }
                None => 0.0,
            },
        }
    }
}

/// What a concentrated load acts on.
#[derive(Clone, Debug, PartialEq)]
pub enum LoadTarget {
    /// Every one of these nodes of the solid receives the whole force.
    Nodes(Vec<usize>),
    /// The reference node of this rigid body.
    Body(usize),
}

/// A force (and, on a rigid body, a moment) fixed in direction and size, at factor 1.
#[derive(Clone, Debug, PartialEq)]
pub struct ConcentratedLoad<const D: usize> {
    /// Nodes or body loaded.
    pub target: LoadTarget,
    /// Force on each node (or on the body's reference node), N.
    pub force: SVector<f64, D>,
    /// Moment on a rigid body, N m (zero on nodes); it must lie along the body's free rotation
    /// axis.
    pub moment: Vector3<f64>,
    /// Time variation.
    pub variation: Variation,
}

/// A uniform body-force acceleration at factor 1: the force `m_i g` on every lumped mass
/// `m_i = sum_e m_{e,i}` of the loaded elements' nodes (`m_{e,i}`: element e's lumped mass at
/// node i, [`SolidElement::lumped_node_masses`], the plane-strain thickness included in 2D),
/// and, for the whole model, `M_b g` on every rigid body's point mass.
#[derive(Clone, Debug, PartialEq)]
pub struct GravityLoad<const D: usize> {
    /// Acceleration `g`, m/s^2.
    pub acceleration: SVector<f64, D>,
    /// Elements loaded (`None`: every element and every rigid body).
    pub elements: Option<Vec<usize>>,
    /// Time variation.
    pub variation: Variation,
}

/// A uniform follower pressure on a set of faces (positive pushes into the solid).
///
/// The nodal forces follow the current face geometry. Their load stiffness, which is
/// unsymmetric, is not assembled: it vanishes when the loaded face translates rigidly (as the
/// pad's back face tied to the plate does), and otherwise Newton converges linearly.
#[derive(Clone, Debug)]
pub struct PressureLoad {
    /// Faces (node lists with outward orientation).
    pub faces: Vec<Vec<usize>>,
    /// Pressure at load factor 1, Pa.
    pub pressure: f64,
    /// Time variation (see [`crate::loads`]).
    pub variation: Variation,
}

/// Every load of a model.
#[derive(Clone, Debug, Default)]
pub struct Loads<const D: usize> {
    /// Follower pressures.
    pub pressures: Vec<PressureLoad>,
    /// Concentrated forces and moments.
    pub concentrated: Vec<ConcentratedLoad<D>>,
    /// Gravity.
    pub gravity: Vec<GravityLoad<D>>,
}

impl<const D: usize> From<Vec<PressureLoad>> for Loads<D> {
    fn from(pressures: Vec<PressureLoad>) -> Self {
        Self {
            pressures,
            ..Self::default()
        }
    }
}

/// A load fixed in direction and size: its nodal forces per equation at factor 1.
#[derive(Clone, Debug)]
pub struct DeadLoad {
    /// Forces (and moments) per equation at factor 1.
    pub force: DVector<f64>,
    /// Moments at factor 1 (global frame) on bodies free to turn, `(body, M)`: their rotation
    /// equations take the body-frame components `Q^T M`, which change as the body turns (see
    /// [`crate::assembly::external_forces`]).
    pub body_moments: Vec<(usize, Vector3<f64>)>,
    /// Time variation.
    pub variation: Variation,
}

/// What the nodal forces of dead loads are assembled from.
pub(crate) struct Scene<'a, const D: usize> {
    pub dofs: &'a DofMap<D>,
    pub bodies: &'a [RigidBody<D>],
    pub elements: &'a [SolidElement<D>],
    pub connectivity: &'a [Vec<usize>],
    /// Mass density of each element, kg/m^3.
    pub densities: &'a [f64],
    pub nodes: usize,
}

fn invalid<T>(msg: String) -> Result<T, ModelError> {
    Err(ModelError::Invalid(msg))
}

impl<const D: usize> ConcentratedLoad<D> {
    /// Its forces per equation at factor 1: `F` on every node's (or the body's) translations
    /// and `M . e` on the body's rotation about its free axis `e`. Components along fixed
    /// motions are carried by the supports.
    ///
    /// # Errors
    /// [`ModelError::Invalid`] for a non-finite value, a node or body that does not exist, a
    /// moment on nodes, or a moment not along the body's free rotation axis.
    pub(crate) fn dead(&self, scene: &Scene<'_, D>, index: usize) -> Result<DeadLoad, ModelError> {
        let what = format!("concentrated load {index}");
        if !(self
            .force
            .iter()
            .chain(self.moment.iter())
            .all(|v| v.is_finite()))
        {
            return invalid(format!("{what}: force and moment must be finite"));
        }
        let mut f = DVector::zeros(scene.dofs.len());
        let mut body_moments = Vec::new();
        let mut add = |eqs: &[Option<usize>; D]| {
            for (eq, fi) in eqs.iter().zip(self.force.iter()) {
                if let Some(eq) = eq {
                    f[*eq] += fi;
                }
            }
        };
        match &self.target {
            LoadTarget::Nodes(nodes) => {
                if self.moment != Vector3::zeros() {
                    return invalid(format!("{what}: nodes of the solid take no moment"));
                }
                for &n in nodes {
                    if n >= scene.nodes {
                        return invalid(format!(
                            "{what}: node {n} does not exist ({} nodes)",
                            scene.nodes
                        ));
                    }
                    add(scene.dofs.node(n));
                }
            }
            &LoadTarget::Body(b) => {
                let Some(body) = scene.bodies.get(b) else {
                    return invalid(format!("{what}: rigid body {b} does not exist"));
                };
                add(scene.dofs.body_translation(b));
                let axis = match body.rotation {
                    Rotation::Free { .. } => {
                        if self.moment != Vector3::zeros() {
                            body_moments.push((b, self.moment));
                        }
                        return Ok(DeadLoad {
                            force: f,
                            body_moments,
                            variation: self.variation.clone(),
                        });
                    }
                    Rotation::Axis(e) => Some(e),
                    Rotation::None => None,
                };
                let about_axis = axis.map_or(0.0, |e| self.moment.dot(&e));
                let off_axis = match axis {
                    Some(e) => self.moment - e * about_axis,
                    None => self.moment,
                };
                if off_axis != Vector3::zeros() {
                    return invalid(format!(
                        "{what}: the moment {:?} on rigid body '{}' is not along its free rotation \
                         axis {:?}",
                        self.moment.as_slice(),
                        body.name,
                        axis.map(|e| [e.x, e.y, e.z])
                    ));
                }
                if let Some(eq) = scene.dofs.body_rotation(b) {
                    f[eq] += about_axis;
                }
            }
        }
        Ok(DeadLoad {
            force: f,
            body_moments,
            variation: self.variation.clone(),
        })
    }
}

impl<const D: usize> GravityLoad<D> {
    /// Its forces per equation at factor 1 (see [`GravityLoad`]).
    ///
    /// # Errors
    /// [`ModelError::Invalid`] for a non-finite acceleration or an element that does not exist.
    pub(crate) fn dead(&self, scene: &Scene<'_, D>, index: usize) -> Result<DeadLoad, ModelError> {
        let what = format!("gravity load {index}");
        if !self.acceleration.iter().all(|v| v.is_finite()) {
            return invalid(format!("{what}: the acceleration must be finite"));
        }
        let mut f = DVector::zeros(scene.dofs.len());
        let mut add = |eqs: &[Option<usize>; D], mass: f64| {
            for (eq, g) in eqs.iter().zip(self.acceleration.iter()) {
                if let Some(eq) = eq {
                    f[*eq] += mass * g;
                }
            }
        };
        let all: Vec<usize>;
        let elements = match &self.elements {
            Some(list) => list,
            None => {
                all = (0..scene.elements.len()).collect();
                &all
            }
        };
        for &e in elements {
            let Some(element) = scene.elements.get(e) else {
                return invalid(format!(
                    "{what}: element {e} does not exist ({} elements)",
                    scene.elements.len()
                ));
            };
            let masses = element.lumped_node_masses(scene.densities[e]);
            for (&n, m) in scene.connectivity[e].iter().zip(masses) {
                add(scene.dofs.node(n), m);
            }
        }
        if self.elements.is_none() {
            for (b, body) in scene.bodies.iter().enumerate() {
                add(scene.dofs.body_translation(b), body.mass);
            }
        }
        Ok(DeadLoad {
            force: f,
            body_moments: Vec::new(),
            variation: self.variation.clone(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_amplitude_interpolates_and_holds_its_end_values() {
        let a = Amplitude::new(vec![(0.1, 0.0), (0.3, 2.0), (0.4, -1.0)]).expect("amplitude");
        for (t, expected) in [
            (-1.0, 0.0),
            (0.1, 0.0),
            (0.2, 1.0),
            (0.3, 2.0),
            (0.35, 0.5),
            (0.4, -1.0),
            (7.0, -1.0),
        ] {
            assert!((a.at(t) - expected).abs() < 1e-12, "a({t}) = {}", a.at(t));
        }
        let single = Amplitude::new(vec![(0.0, 0.5)]).expect("one point");
        assert_eq!(single.at(-3.0), 0.5);
        assert_eq!(single.at(3.0), 0.5);
    }

    #[test]
    fn an_amplitude_refuses_bad_points() {
        for (points, fragment) in [
            (vec![], "at least one"),
            (
                vec![(0.0, 0.0), (0.0, 1.0)],
                "point 1: the times must increase",
            ),
            (
                vec![(0.0, 0.0), (1.0, f64::NAN)],
                "point 1: expected finite",
            ),
            (vec![(f64::INFINITY, 0.0)], "point 0: expected finite"),
        ] {
            let error = Amplitude::new(points).expect_err(fragment).to_string();
            assert!(error.contains(fragment), "{error}");
        }
    }

    #[test]
    fn a_load_follows_the_ramp_its_amplitude_or_its_variation_in_the_step() {
        let instant = LoadInstant {
            ramp: 0.25,
            step_time: 0.5,
            step: 1,
            fraction: 0.75,
        };
        let a = Amplitude::new(vec![(0.0, 0.0), (1.0, 4.0)]).expect("amplitude");
        assert_eq!(instant.factor(&Variation::Ramp), 0.25);
        assert_eq!(instant.factor(&Variation::Amplitude(a.clone())), 2.0);
        let ramp = |from, to| StepVariation::Ramp { from, to };
        let per_step = |second| Variation::PerStep(vec![ramp(0.0, 1.0), second]);
        // from 1 to 3 over the step, three quarters done
        assert_eq!(instant.factor(&per_step(ramp(1.0, 3.0))), 2.5);
        let scaled = StepVariation::Amplitude {
            amplitude: a,
            scale: -0.5,
        };
        assert_eq!(instant.factor(&per_step(scaled)), -1.0);
        let beyond = LoadInstant { step: 2, ..instant };
        assert_eq!(beyond.factor(&per_step(ramp(1.0, 3.0))), 0.0);
    }
}
