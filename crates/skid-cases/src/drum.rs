//! Builds the braking-drum scene of a case as a finite-element model (2D or 3D, one code path).
//!
//! - the pad: a structured block of one-point elements; its front face (`ymin`) is the slave
//!   side of the contact, its back face (`ymax`) is tied to the back plate and loaded by the
//!   pressure;
//! - the drum: a rigid body whose only free motion is the spin about +z, carrying all the
//!   drum's inertia at its reference node on the axis; its surface has no mass and no degrees
//!   of freedom of its own;
//! - the back plate: a rigid body whose only free motion is the radial (y) translation.

use nalgebra::{SVector, Vector3};
use skid_contact::error::ContactError;
use skid_contact::facets::FacetedCylinder;
use skid_contact::surface::{AnalyticCylinder, RigidSurface};
use skid_contact::triangles::{CylinderChart, TriangulatedSurface};
use skid_fem::cell::embed;
use skid_fem::material::PolynomialN1;
use skid_fem::mesh::SolidMesh;
use skid_fem::rigid::RigidBody;
use skid_fem::tetra::TetMesh;
use skid_integrator::increment::{ContactSolve, NewtonSettings};
use skid_integrator::stepper::{Adaptive, CutbackSettings, Settings, Step, StepKind};
use skid_integrator::{ContactPair, Model, PressureLoad, SolidPart, Tie};

use crate::schema::{
    Case, ContactFormulation, ContactSolveSpec, CoulombMethodSpec, DrumSurfaceSpec, MaterialSpec,
    StepSpec,
};

/// Index of the drum among the model's rigid bodies.
pub const DRUM: usize = 0;
/// Index of the back plate among the model's rigid bodies.
pub const BACK_PLATE: usize = 1;
/// Names of the rigid bodies, by index (as case files name them in a step's `hold`).
pub const BODY_NAMES: [&str; 2] = ["drum", "back_plate"];

/// A built scene: model, steps and solver settings.
#[derive(Debug)]
pub struct DrumScene<const D: usize> {
    /// The model.
    pub model: Model<D>,
    /// Analysis steps.
    pub steps: Vec<Step>,
    /// Solver settings.
    pub settings: Settings,
}

/// Builds the scene of a validated case in dimension `D` (which must equal `case.dimension`).
///
/// # Errors
/// A message if the model is inconsistent (the case was validated, so this means a mesh or
/// element problem such as a degenerate geometry).
pub fn build<const D: usize>(case: &Case) -> Result<DrumScene<D>, String> {
    if case.dimension != D {
        return Err(format!("case is {}D, builder is {D}D", case.dimension));
    }
    let pad = &case.pad;
    let r = case.drum.radius;
    let extent = [pad.length, pad.thickness, pad.width];
    let corner = [-0.5 * pad.length, r + pad.standoff, -0.5 * pad.width];
    let counts = [
        pad.elements.circumferential,
        pad.elements.radial,
        pad.elements.axial,
    ];
    let mesh = SolidMesh::<D>::structured_block(
        SVector::<f64, D>::from_fn(|i, _| corner[i]),
        SVector::<f64, D>::from_fn(|i, _| extent[i]),
        std::array::from_fn(|i| counts[i]),
    )
    .map_err(|e| format!("pad mesh: {e}"))?;
    let material = match pad.material {
        MaterialSpec::PolynomialN1 { c10, c01, d1 } => {
            PolynomialN1::new(c10, c01, d1).map_err(|e| format!("pad.material: {e}"))?
        }
    };
    let set = |name: &str| {
        mesh.node_sets
            .get(name)
            .cloned()
            .ok_or_else(|| format!("pad mesh has no node set '{name}'"))
    };
    let front = set("ymin")?;
    let back = set("ymax")?;
    let back_faces = mesh
        .surfaces
        .get("ymax")
        .cloned()
        .ok_or("pad mesh has no surface 'ymax'")?;

    let drum = RigidBody::<D> {
        name: BODY_NAMES[DRUM].into(),
        reference_point: SVector::zeros(),
        mass: case.drum.mass,
        rotary_inertia: case.drum.rotary_inertia,
        free_translations: [false; D],
        rotation_axis: Some(Vector3::z()),
        initial_velocity: SVector::zeros(),
        initial_angular_velocity: case.drum.omega0,
    };
    let mut plate_point = SVector::<f64, D>::zeros();
    plate_point[1] = r + pad.standoff + pad.thickness;
    let mut free = [false; D];
    free[1] = true;
    let plate = RigidBody::<D> {
        name: BODY_NAMES[BACK_PLATE].into(),
        reference_point: plate_point,
        mass: case.back_plate.mass,
        rotary_inertia: 0.0,
        free_translations: free,
        rotation_axis: None,
        initial_velocity: SVector::zeros(),
        initial_angular_velocity: 0.0,
    };
    let surface = drum_surface(case).map_err(|e| format!("drum.surface: {e}"))?;
    let contact_nodes = match case.contact.formulation {
        ContactFormulation::Pair => front,
        ContactFormulation::General { search_distance } => {
            general_contact_candidates(&mesh, surface.as_ref(), search_distance)
        }
    };
    let part = SolidPart {
        mesh,
        material: Box::new(material),
        density: pad.density,
        thickness: if D == 2 { pad.width } else { 1.0 },
        hourglass_scale: pad.hourglass_scale,
        quasi_static: pad.quasi_static,
    };
    let model = Model::new(
        part,
        vec![drum, plate],
        vec![Tie {
            body: BACK_PLATE,
            nodes: back,
        }],
        vec![PressureLoad {
            faces: back_faces,
            pressure: case.back_plate.pressure,
        }],
        vec![ContactPair {
            name: "pad-drum".into(),
            nodes: contact_nodes,
            body: DRUM,
            surface,
            mu: case.contact.mu,
        }],
    )
    .map_err(|e| e.to_string())?;

    let held = |hold: &[String]| -> Result<Vec<usize>, String> {
        hold.iter()
            .map(|h| {
                BODY_NAMES
                    .iter()
                    .position(|b| b == h)
                    .ok_or_else(|| format!("no rigid body named '{h}' to hold"))
            })
            .collect()
    };
    let steps = case
        .steps
        .iter()
        .map(|s| match s {
            StepSpec::Static {
                name,
                increments,
                hold,
                regularization_time,
            } => Ok(Step {
                name: name.clone(),
                kind: StepKind::Static {
                    increments: *increments,
                    regularization_time: *regularization_time,
                },
                held_bodies: held(hold)?,
            }),
            StepSpec::Dynamic {
                name,
                duration,
                dt,
                alpha,
                hold,
                adaptive,
            } => Ok(Step {
                name: name.clone(),
                kind: StepKind::Dynamic {
                    duration: *duration,
                    dt: *dt,
                    alpha: *alpha,
                    adaptive: adaptive.map(|a| Adaptive {
                        tolerance: a.tolerance,
                        min_dt: a.min_dt,
                        max_dt: a.max_dt,
                    }),
                },
                held_bodies: held(hold)?,
            }),
        })
        .collect::<Result<Vec<_>, String>>()?;
    let s = &case.solver;
    let settings = Settings {
        newton: NewtonSettings {
            max_iterations: s.max_newton_iterations,
            force_tolerance: s.force_tolerance,
            contact_tolerance: s.contact_tolerance,
        },
        coulomb: skid_contact::coulomb::CoulombSettings {
            tolerance: s.coulomb_tolerance,
            max_fixed_point_iterations: s.max_fixed_point_iterations,
            method: s.coulomb_method.into(),
            ..Default::default()
        },
        // the conic method solves the Coulomb problem on the Delassus operator: the reduced path
        contact_solve: match (s.contact_solve, s.coulomb_method) {
            (_, CoulombMethodSpec::Conic) | (ContactSolveSpec::Reduced, _) => ContactSolve::Reduced,
            (ContactSolveSpec::Auto, _) if !case.pad.quasi_static => ContactSolve::Reduced,
            _ => ContactSolve::Global,
        },
        cutback: CutbackSettings {
            factor: s.cutback_factor,
            max_cutbacks: s.max_cutbacks,
            ..Default::default()
        },
    };
    Ok(DrumScene {
        model,
        steps,
        settings,
    })
}

/// The drum's contact surface in its body frame (origin on the axis, axis +z). Faceted and
/// tetrahedral drums have their vertices at `(2 k + 1) pi / n` from +x (n facets or sectors), so
/// that for the benchmark's 72 a facet's midpoint, not a vertex, lies under the pad's centre
/// (the statement does not say; a vertex there would hold the pad's centre node on a corner).
///
/// # Errors
/// If the surface geometry is invalid.
pub fn drum_surface(case: &Case) -> Result<Box<dyn RigidSurface>, ContactError> {
    let r = case.drum.radius;
    Ok(match case.drum.surface {
        DrumSurfaceSpec::Analytic => Box::new(AnalyticCylinder::new(r, Vector3::z())?),
        DrumSurfaceSpec::Facets { count, .. } => Box::new(FacetedCylinder::new(
            r,
            Vector3::z(),
            count,
            std::f64::consts::PI / count as f64,
        )?),
        DrumSurfaceSpec::Tetrahedra {
            sectors,
            rings,
            layers,
            inner_radius,
        } => {
            let mesh = TetMesh::annular_drum(
                r,
                inner_radius,
                case.drum.width,
                [sectors, rings, layers],
                std::f64::consts::PI / sectors as f64,
            )
            .map_err(|e| ContactError::InvalidSurface(e.to_string()))?;
            let faces = mesh.exterior_faces();
            Box::new(TriangulatedSurface::new(
                mesh.nodes,
                faces,
                CylinderChart {
                    radius: r,
                    axis: Vector3::z(),
                },
            )?)
        }
    })
}

/// General contact: the nodes of every exterior face of the pad whose distance to the drum
/// surface (in the initial configuration) is below `search_distance`, sorted.
fn general_contact_candidates<const D: usize>(
    mesh: &SolidMesh<D>,
    surface: &dyn RigidSurface,
    search_distance: f64,
) -> Vec<usize> {
    let mut nodes: Vec<usize> = mesh
        .surfaces
        .values()
        .flat_map(|faces| faces.iter().flatten().copied())
        .filter(|&n| {
            surface
                .project(&embed(&mesh.nodes[n]))
                .is_some_and(|p| p.gap < search_distance)
        })
        .collect();
    nodes.sort_unstable();
    nodes.dedup();
    nodes
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::validate::parse_case;
    use std::path::Path;

    /// General contact finds, by distance, exactly the front-face nodes the pair names: the
    /// back face stands a pad thickness away.
    #[test]
    fn general_contact_search_finds_the_front_face() {
        let text = include_str!("../../../cases/drum/3d-analytic-general.json");
        let case = parse_case(text, Path::new("g.json"), &[]).expect("case");
        let scene = build::<3>(&case).expect("scene");
        let mesh = &scene.model.part().mesh;
        assert_eq!(scene.model.contacts()[0].nodes, mesh.node_sets["ymin"]);
        // A search distance beyond the pad thickness also takes the back face.
        let wide = parse_case(
            text,
            Path::new("g.json"),
            &["contact.formulation.search_distance=0.2".into()],
        )
        .expect("case");
        let scene = build::<3>(&wide).expect("scene");
        assert_eq!(scene.model.contacts()[0].nodes.len(), mesh.nodes.len());
    }
}
