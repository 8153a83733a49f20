//! A deformable block on a fixed rigid flat under loads that are then held (the scenes
//! `cases/verification/*-block-pushed-on-flat*` and `*-block-on-incline*`): whether Coulomb's
//! law makes it stick or slide, from the model as run.
//!
//! The flat is the master of the scene's one frictional pair: a rigid plane on a body held in
//! every degree of freedom. The loads are concentrated forces (on rigid bodies, or on every
//! node of a node set) and gravity on the whole model, each its amplitude's value at the step
//! time times its full value, in one dynamic step. Once every amplitude has reached its last
//! point at `t_hold`, the loads are held at their resultant `R`. In equilibrium the flat alone
//! carries it (the scene must leave nothing to other supports): a normal resultant
//! `N = -R . n` across the flat's normal `n` and a friction resultant of size
//! `T = |R - (R . n) n|` along it. Coulomb's law lets the block stick while `T < mu N`, so the
//! ratio `r = T / (mu N)` of the held loads decides: below 1 it sticks, above 1 it slides.
//!
//! The dynamic step's response to the loading takes time to settle (partial slip near the
//! threshold persists for a few increments after `t_hold`: measured on the incline at 0.995 of
//! its threshold, the last sliding contact at 10.5 ms for a hold from 10 ms), so the held state
//! is judged in the second half of the hold, from `t_hold + (t_end - t_hold) / 2` on.

use skid_cases::model_file::build::build;
use skid_cases::model_spec::{
    ContactPairSpec, Dof, LoadSpec, ModelSpec, ModelStepSpec, RigidBodySpec, RigidSurfaceSpec,
};

/// A block on a fixed flat: what the stick or slip of its held loads needs.
#[derive(Clone, Debug, PartialEq)]
pub struct BlockOnFlat {
    /// Name of the frictional pair between the block and the flat.
    pub pair: String,
    /// Friction coefficient of the pair.
    pub mu: f64,
    /// Normal resultant `N` of the held loads, N.
    pub normal: f64,
    /// Size `T` of the tangential resultant of the held loads, N.
    pub tangential: f64,
    /// Time from which every amplitude has reached its last point, s.
    pub hold_time: f64,
    /// End of the step, s.
    pub end_time: f64,
}

impl BlockOnFlat {
    /// The scene of `spec`, if it is one (see the module documentation): one contact pair,
    /// frictional, whose master is a plane on a body held in all its degrees of freedom; no
    /// other support (no boundary condition on the part, none on another body that the held
    /// loads push along); concentrated forces without moments and gravity on the whole model,
    /// none changed per step; one dynamic step whose loads are held before it ends; every
    /// other body tied to the part; and a held normal resultant pressing the block onto the
    /// flat.
    pub fn recognise(spec: &ModelSpec) -> Option<Self> {
        let dim = spec.dimension;
        let (pair, flat, n) = flat_pair(spec)?;
        let [
            ModelStepSpec::Dynamic {
                duration, boundary, ..
            },
        ] = spec.steps.as_slice()
        else {
            return None;
        };
        let held = |body: &str, dof: Dof| {
            spec.boundary
                .iter()
                .any(|b| b.body.as_deref() == Some(body) && b.dofs.contains(&dof))
        };
        let others_tied = spec
            .rigid_bodies
            .iter()
            .all(|b| b.name == flat.name || spec.ties.iter().any(|t| t.body == b.name));
        if pair.mu <= 0.0
            || !boundary.is_empty()
            || !others_tied
            || spec.boundary.iter().any(|b| b.node_set.is_some())
            || !Dof::all(dim).iter().all(|&dof| held(&flat.name, dof))
        {
            return None;
        }

        let mut resultant = [0.0; 3];
        let mut hold_time: f64 = 0.0;
        for load in &spec.loads {
            if load.step_factors().is_some() {
                return None;
            }
            let (factor, last) = match load.amplitude() {
                None => (1.0, 0.0),
                Some(name) => {
                    let amplitude = spec.amplitudes.iter().find(|a| a.name == name)?;
                    let &[t, value] = amplitude.points.last()?;
                    (value, t)
                }
            };
            hold_time = hold_time.max(last);
            let (vector, times) = match load {
                LoadSpec::Concentrated {
                    node_set,
                    body,
                    force,
                    moment,
                    ..
                } => {
                    if moment.is_some_and(|m| m.iter().any(|&c| c != 0.0)) {
                        return None;
                    }
                    let count = match (node_set, body) {
                        (Some(set), None) => spec.part.node_sets.get(set)?.len() as f64,
                        (None, Some(_)) => 1.0,
                        _ => return None,
                    };
                    (force.clone().unwrap_or_default(), count)
                }
                LoadSpec::Gravity {
                    acceleration,
                    element_set: None,
                    ..
                } => (acceleration.clone(), carried_mass(spec)?),
                _ => return None,
            };
            if vector.len() != dim {
                return None;
            }
            for (r, v) in resultant.iter_mut().zip(&vector) {
                *r += factor * times * v;
            }
        }
        // a support other than the flat would carry what pushes along one of its held axes
        for body in spec.rigid_bodies.iter().filter(|b| b.name != flat.name) {
            for dof in Dof::all(dim) {
                if let Some(axis) = dof.translation_axis()
                    && held(&body.name, *dof)
                    && resultant[axis] != 0.0
                {
                    return None;
                }
            }
        }
        let along: f64 = resultant.iter().zip(&n).map(|(r, n)| r * n).sum();
        let tangential = along_plane(&resultant, &n);
        (-along > 0.0 && hold_time < *duration).then(|| Self {
            pair: pair.name.clone(),
            mu: pair.mu,
            normal: -along,
            tangential,
            hold_time,
            end_time: *duration,
        })
    }

    /// `r = T / (mu N)` of the held loads.
    pub fn ratio(&self) -> f64 {
        self.tangential / (self.mu * self.normal)
    }

    /// Whether Coulomb's law lets the block stick under the held loads (`r < 1`).
    pub fn sticks(&self) -> bool {
        self.ratio() < 1.0
    }

    /// The time from which the held state is judged, s.
    pub fn settled_from(&self) -> f64 {
        self.hold_time + 0.5 * (self.end_time - self.hold_time)
    }
}

/// The scene's one contact pair, if its master is flat (a rigid plane, or rigid elements that
/// lie in one plane): the pair, the flat's body and its unit normal.
pub(crate) fn flat_pair(spec: &ModelSpec) -> Option<(&ContactPairSpec, &RigidBodySpec, [f64; 3])> {
    let [pair] = spec.contact.as_slice() else {
        return None;
    };
    let flat = spec.rigid_bodies.iter().find(|b| b.name == pair.master)?;
    Some((pair, flat, flat_normal(flat.surface.as_ref()?)?))
}

/// The unit outward normal of a flat surface: a plane's; a polyline's whose segments all run
/// one way (their direction turned clockwise), and the extrusion of one; a triangle mesh's whose
/// triangles all face one way (within 1e-9). `None` for any other surface.
fn flat_normal(surface: &RigidSurfaceSpec) -> Option<[f64; 3]> {
    let same = |normals: Vec<[f64; 3]>| {
        let first = *normals.first()?;
        normals
            .iter()
            .all(|n| n.iter().zip(&first).all(|(a, b)| (a - b).abs() <= 1e-9))
            .then_some(first)
    };
    match surface {
        RigidSurfaceSpec::Plane { normal, .. } => Some(unit(*normal)),
        // an arc is never flat
        RigidSurfaceSpec::Polyline { centres, .. } if centres.iter().any(Option::is_some) => None,
        RigidSurfaceSpec::Polyline { points, .. } => same(
            points
                .windows(2)
                .map(|w| unit([w[1][1] - w[0][1], w[0][0] - w[1][0], 0.0]))
                .collect(),
        ),
        RigidSurfaceSpec::Extrusion {
            axis,
            reference,
            profile,
            centres,
            ..
        } => {
            // the profile's plane: u along the reference (made perpendicular to the axis), v
            // along axis x u
            let e = unit(*axis);
            let along: f64 = reference.iter().zip(&e).map(|(a, b)| a * b).sum();
            let u = unit([0, 1, 2].map(|k| reference[k] - along * e[k]));
            let v = [
                e[1] * u[2] - e[2] * u[1],
                e[2] * u[0] - e[0] * u[2],
                e[0] * u[1] - e[1] * u[0],
            ];
            let normal = flat_normal(&RigidSurfaceSpec::Polyline {
                points: profile.clone(),
                centres: centres.clone(),
                closed: false,
            })?;
            Some([0, 1, 2].map(|k| normal[0] * u[k] + normal[1] * v[k]))
        }
        RigidSurfaceSpec::Triangles {
            vertices,
            triangles,
            ..
        } => same(
            triangles
                .iter()
                .map(|t| {
                    let [a, b, c] = t.map(|i| vertices[i]);
                    let (u, v) = (
                        [0, 1, 2].map(|k| b[k] - a[k]),
                        [0, 1, 2].map(|k| c[k] - a[k]),
                    );
                    unit([
                        u[1] * v[2] - u[2] * v[1],
                        u[2] * v[0] - u[0] * v[2],
                        u[0] * v[1] - u[1] * v[0],
                    ])
                })
                .collect(),
        ),
        _ => None,
    }
}

/// `v / |v|`.
fn unit(v: [f64; 3]) -> [f64; 3] {
    let length = v.iter().map(|c| c * c).sum::<f64>().sqrt();
    v.map(|c| c / length)
}

/// `|v - (v . n) n|`, the size of the component of `v` (its first components, the others 0)
/// in the plane of unit normal `n`.
pub(crate) fn along_plane(v: &[f64], n: &[f64; 3]) -> f64 {
    let across: f64 = v.iter().zip(n).map(|(a, b)| a * b).sum();
    (0..3)
        .map(|k| (v.get(k).copied().unwrap_or(0.0) - across * n[k]).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// The mass that gravity pulls onto the flat: the part's, `sum_e rho_e V_e` over its elements
/// as the solver builds them, and the point masses of the bodies tied to it (`None` if the
/// model does not build).
fn carried_mass(spec: &ModelSpec) -> Option<f64> {
    let part = match spec.dimension {
        2 => part_mass::<2>(spec)?,
        3 => part_mass::<3>(spec)?,
        _ => return None,
    };
    let bodies: f64 = spec
        .rigid_bodies
        .iter()
        .filter(|b| spec.ties.iter().any(|t| t.body == b.name))
        .map(|b| b.mass)
        .sum();
    Some(part + bodies)
}

fn part_mass<const D: usize>(spec: &ModelSpec) -> Option<f64> {
    let scene = build::<D>(spec).ok()?;
    let part = scene.model.part();
    let mass = scene
        .model
        .elements()
        .iter()
        .enumerate()
        .map(|(e, element)| part.density(e) * element.volume())
        .sum();
    Some(mass)
}

/// The shipped verification scene `file` (a model file of `cases/verification`), for tests.
#[cfg(test)]
pub(crate) fn scene(file: &str) -> ModelSpec {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../cases/verification")
        .join(file);
    let text = std::fs::read_to_string(&path).expect("scene");
    serde_json::from_str(&text).expect("model file")
}

#[cfg(test)]
mod tests {
    use super::*;
    use skid_cases::model_spec::ChartSpec;

    /// Rigid elements in one plane are a flat with that plane's normal; bent ones are not.
    #[test]
    fn flat_element_surfaces_have_one_normal() {
        let line = |points: Vec<[f64; 2]>| RigidSurfaceSpec::Polyline {
            points,
            centres: Vec::new(),
            closed: false,
        };
        // walked towards -x: the outside (right-hand side) is up
        let floor = line(vec![[1.0, 0.0], [0.2, 0.0], [-1.0, 0.0]]);
        assert_eq!(flat_normal(&floor), Some([0.0, 1.0, 0.0]));
        // the same points with a shallow arc between the last two
        let bump = RigidSurfaceSpec::Polyline {
            points: vec![[1.0, 0.0], [0.2, 0.0], [-1.0, 0.0]],
            centres: vec![None, Some([-0.4, -5.0])],
            closed: false,
        };
        assert_eq!(flat_normal(&bump), None);
        let ramp = line(vec![[1.0, 0.1], [0.2, 0.0], [-1.0, 0.0]]);
        assert_eq!(flat_normal(&ramp), None);
        let mesh = |lift: f64| RigidSurfaceSpec::Triangles {
            vertices: vec![
                [0.0, 0.0, 0.0],
                [0.0, 0.0, 1.0],
                [1.0, 0.0, 1.0],
                [1.0, lift, 0.0],
            ],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            chart: ChartSpec::Plane {
                normal: [0.0, 1.0, 0.0],
                tangent: [1.0, 0.0, 0.0],
            },
        };
        assert_eq!(flat_normal(&mesh(0.0)), Some([0.0, 1.0, 0.0]));
        // a straight profile in the x-y plane swept along z, walked towards -x: outside up
        let extruded = RigidSurfaceSpec::Extrusion {
            axis: [0.0, 0.0, 2.0],
            reference: [1.0, 0.0, 0.0],
            profile: vec![[1.0, 0.0], [0.0, 0.0], [-1.0, 0.0]],
            centres: Vec::new(),
            closed: false,
        };
        assert_eq!(flat_normal(&extruded), Some([0.0, 1.0, 0.0]));
        assert_eq!(flat_normal(&mesh(0.1)), None);
    }

    /// The pushed block: N = 20 N down, F = 9 N sideways (1.5 mu N), held from 25 ms.
    #[test]
    fn the_pushed_block_slides_at_one_and_a_half_times_mu_n() {
        for file in [
            "2d-block-pushed-on-flat.json",
            "3d-block-pushed-on-flat.json",
        ] {
            let block = BlockOnFlat::recognise(&scene(file)).expect(file);
            assert_eq!((block.normal, block.tangential), (20.0, 9.0), "{file}");
            assert!(
                (block.ratio() - 1.5).abs() < 1e-12 && !block.sticks(),
                "{file}"
            );
            assert_eq!((block.hold_time, block.end_time), (0.025, 0.04), "{file}");
            assert!((block.settled_from() - 0.0325).abs() < 1e-15, "{file}");
        }
    }

    /// The incline: gravity on the 1 g block (its mass from the mesh) and the push, turned so
    /// that the flat is y = 0: `N = G cos a + F sin a`, `T = F cos a - G sin a`, and the push
    /// given is 1.005 times the threshold `F / G = (tan a + mu) / (1 - mu tan a)`.
    #[test]
    fn the_incline_carries_the_weight_of_its_mesh() {
        let (a, mu, weight) = (10f64.to_radians(), 0.3, 1e-3 * 9.81);
        let push = 1.005 * (a.tan() + mu) / (1.0 - mu * a.tan()) * weight;
        for file in ["2d-block-on-incline.json", "3d-block-on-incline.json"] {
            let block = BlockOnFlat::recognise(&scene(file)).expect(file);
            let (n, t) = (
                weight * a.cos() + push * a.sin(),
                push * a.cos() - weight * a.sin(),
            );
            assert!(
                (block.normal - n).abs() < 1e-12 * n,
                "{file}: N {}",
                block.normal
            );
            assert!(
                (block.tangential - t).abs() < 1e-9 * t,
                "{file}: T {}",
                block.tangential
            );
            assert!(!block.sticks(), "{file}");
        }
    }

    /// What the flat does not carry alone is not this scene: a flat that may move, a support
    /// along the push, a pressure load, two steps.
    #[test]
    fn scenes_with_other_supports_or_loads_are_not_recognised() {
        let pushed = scene("2d-block-pushed-on-flat.json");
        assert!(BlockOnFlat::recognise(&pushed).is_some());
        let mut free_flat = pushed.clone();
        free_flat.boundary[0].dofs.retain(|&d| d != Dof::X);
        assert_eq!(BlockOnFlat::recognise(&free_flat), None);
        let mut held_plate = pushed.clone();
        held_plate.boundary[1].dofs.push(Dof::X);
        assert_eq!(BlockOnFlat::recognise(&held_plate), None);
        let ground = scene("2d-block-on-sliding-ground.json");
        assert_eq!(BlockOnFlat::recognise(&ground), None);
        let mut two_steps = pushed.clone();
        two_steps.steps.push(two_steps.steps[0].clone());
        assert_eq!(BlockOnFlat::recognise(&two_steps), None);
    }
}
