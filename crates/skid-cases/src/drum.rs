//! The braking-drum scene of a case, generated as a model file ([`model_spec`]) and built as
//! any model file is (2D or 3D, one code path):
//!
//! - the pad: a structured block of one-point elements; its front face (`ymin`) is the slave
//!   side of the contact, its back face (`ymax`) is tied to the back plate and loaded by the
//!   pressure;
//! - the drum: a rigid body whose only free motion is the spin about +z, carrying all the
//!   drum's inertia at its reference node on the axis; its surface has no mass and no degrees
//!   of freedom of its own;
//! - the back plate: a rigid body whose only free motion is the radial (y) translation.

use std::collections::BTreeMap;

use nalgebra::SVector;
use skid_fem::mesh::SolidMesh;
use skid_fem::tetra::{TetMesh, compact_triangles};

use crate::deck::mesh::ElementKind;
use crate::deck::write::{RigidElements, write_deck};
use crate::model_file::{self, Scene};
use crate::model_spec::ContactPairSpec;
use crate::model_spec::{
    BoundarySpec, ChartSpec, Dof, ElementBlockSpec, ElementType, LoadSpec, ModelStepSpec, PartSpec,
    RigidBodySpec, RigidSurfaceSpec, SectionSpec, SlaveSpec, StepBoundarySpec, TieSpec,
};
use crate::model_spec::{MODEL_FORMAT_VERSION, ModelSpec};
use crate::schema::{
    BACK_PLATE, BODY_NAMES, Case, ContactFormulation, DRUM, DrumSurfaceSpec, FacetElement, StepSpec,
};

/// Builds the scene of a validated case in dimension `D` (which must equal `case.dimension`):
/// the case's model file ([`model_spec`]) built as any model file is.
///
/// # Errors
/// A message if the model is inconsistent (the case was validated, so this means a mesh or
/// element problem such as a degenerate geometry).
pub fn build<const D: usize>(case: &Case) -> Result<Scene<D>, String> {
    if case.dimension != D {
        return Err(format!("case is {}D, builder is {D}D", case.dimension));
    }
    let spec = model_spec(case)?;
    model_file::build::<D>(&spec).map_err(|e| format!("{}: {}", e.field, e.message))
}

/// The model file of a validated case: the pad as a structured block of one-point elements
/// (node sets and surfaces `xmin` ... `zmax` of its boundary planes, `ymin` facing the drum),
/// the drum and the back plate as rigid bodies whose fixed motions are boundary conditions,
/// the back face `ymax` tied to the plate and loaded by the pressure, one contact pair
/// `pad-drum`.
///
/// # Errors
/// A message if the pad or drum mesh cannot be generated.
pub fn model_spec(case: &Case) -> Result<ModelSpec, String> {
    match case.dimension {
        2 => model_spec_in::<2>(case),
        3 => model_spec_in::<3>(case),
        d => Err(format!("dimension must be 2 or 3, got {d}")),
    }
}

/// The input deck of a validated case: its model file ([`model_spec`]) written with the drum's
/// own elements (R2D2 lines, R3D4, M3D4R or S4R quadrilaterals across the drum's width, C3D4
/// tetrahedra) so that the deck describes the idealization, not only its contact surface.
///
/// # Errors
/// A message if the model cannot be generated or written as a deck.
pub fn deck(case: &Case) -> Result<String, String> {
    let spec = model_spec(case)?;
    let half = case.drum.width / 2.0;
    let elements = match case.drum.surface {
        DrumSurfaceSpec::Analytic => None,
        DrumSurfaceSpec::Facets { element, .. } => Some(RigidElements::Facets {
            kind: match element {
                FacetElement::R2d2 => ElementKind::R2d2,
                FacetElement::R3d4 => ElementKind::R3d4,
                FacetElement::M3d4r => ElementKind::M3d4r,
                FacetElement::S4r => ElementKind::S4r,
            },
            axial_range: [-half, half],
        }),
        DrumSurfaceSpec::Tetrahedra {
            sectors,
            rings,
            layers,
            inner_radius,
        } => Some(RigidElements::Tetrahedra(
            TetMesh::annular_drum(
                case.drum.radius,
                inner_radius,
                case.drum.width,
                [sectors, rings, layers],
                std::f64::consts::PI / sectors as f64,
            )
            .map_err(|e| format!("drum.surface: {e}"))?,
        )),
    };
    let rigid: BTreeMap<String, RigidElements> = elements
        .into_iter()
        .map(|e| ("drum".to_string(), e))
        .collect();
    write_deck(&spec, &rigid)
}

fn model_spec_in<const D: usize>(case: &Case) -> Result<ModelSpec, String> {
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
    let part = PartSpec {
        name: "pad".into(),
        nodes: mesh
            .nodes
            .iter()
            .map(|p| p.iter().copied().collect())
            .collect(),
        elements: vec![ElementBlockSpec {
            kind: ElementType::of(pad.formulation.formulation(), D),
            connectivity: mesh.elements,
        }],
        node_sets: mesh.node_sets,
        element_sets: BTreeMap::new(),
        materials: Vec::new(),
        surfaces: mesh.surfaces,
        section: SectionSpec {
            material: pad.material.clone(),
            density: pad.density,
            stiffness_damping: pad.stiffness_damping,
            thickness: if D == 2 { pad.width } else { 1.0 },
            hourglass_scale: pad.hourglass_scale,
            hourglass: pad.hourglass,
            quasi_static: pad.quasi_static,
            massless_contact_nodes: pad.massless_contact_nodes,
        },
    };
    let mut plate_point = vec![0.0; D];
    plate_point[1] = r + pad.standoff + pad.thickness;
    let drum = RigidBodySpec {
        name: BODY_NAMES[DRUM].into(),
        reference_point: vec![0.0; D],
        mass: case.drum.mass,
        rotary_inertia: case.drum.rotary_inertia,
        moments_of_inertia: None,
        products_of_inertia: None,
        surface: Some(drum_surface(case)?),
        initial_velocity: None,
        initial_angular_velocity: Some([0.0, 0.0, case.drum.omega0]),
    };
    let plate = RigidBodySpec {
        name: BODY_NAMES[BACK_PLATE].into(),
        reference_point: plate_point,
        mass: case.back_plate.mass,
        rotary_inertia: 0.0,
        moments_of_inertia: None,
        products_of_inertia: None,
        surface: None,
        initial_velocity: None,
        initial_angular_velocity: None,
    };
    // the drum spins about its fixed axis; the plate only moves radially (along y)
    let fixed = |body: usize, free: &[Dof]| BoundarySpec {
        body: Some(BODY_NAMES[body].into()),
        node_set: None,
        dofs: Dof::all(D)
            .iter()
            .filter(|d| !free.contains(d))
            .copied()
            .collect(),
        value: None,
        amplitude: None,
        step_factors: None,
    };
    let slave = match case.contact.formulation {
        ContactFormulation::Pair => SlaveSpec::NodeSet {
            name: "ymin".into(),
        },
        ContactFormulation::General { search_distance } => SlaveSpec::General { search_distance },
    };
    let hold = |hold: &[String]| {
        hold.iter()
            .map(|body| StepBoundarySpec {
                body: Some(body.clone()),
                node_set: None,
                dofs: None,
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
                hold: held,
                regularization_time,
            } => ModelStepSpec::Static {
                name: name.clone(),
                increments: Some(*increments),
                automatic: None,
                regularization_time: *regularization_time,
                time_period: None,
                default_amplitude: None,
                boundary: hold(held),
            },
            StepSpec::Dynamic {
                name,
                duration,
                dt,
                alpha,
                hold: held,
                adaptive,
            } => ModelStepSpec::Dynamic {
                name: name.clone(),
                duration: *duration,
                dt: *dt,
                alpha: *alpha,
                boundary: hold(held),
                adaptive: *adaptive,
                default_amplitude: None,
            },
        })
        .collect();
    Ok(ModelSpec {
        skid_model: MODEL_FORMAT_VERSION,
        name: case.name.clone(),
        description: case.description.clone(),
        dimension: D,
        part,
        parts: Vec::new(),
        rigid_bodies: vec![drum, plate],
        boundary: vec![fixed(DRUM, &[Dof::Rz]), fixed(BACK_PLATE, &[Dof::Y])],
        ties: vec![TieSpec {
            node_set: "ymax".into(),
            body: BODY_NAMES[BACK_PLATE].into(),
        }],
        initial_velocities: Vec::new(),
        loads: vec![LoadSpec::Pressure {
            surface: "ymax".into(),
            pressure: case.back_plate.pressure,
            amplitude: None,
            step_factors: None,
        }],
        amplitudes: Vec::new(),
        contact: vec![ContactPairSpec {
            name: "pad-drum".into(),
            slave,
            master: BODY_NAMES[DRUM].into(),
            mu: case.contact.mu,
        }],
        steps,
        solver: case.solver.clone(),
        output: case.output.clone().into(),
    })
}

/// The drum's contact surface in its body frame (origin on the axis, axis +z). Faceted and
/// tetrahedral drums have their vertices at `(2 k + 1) pi / n` from +x (n facets or sectors), so
/// that for the benchmark's 72 a facet's midpoint, not a vertex, lies under the pad's centre
/// (the statement does not say; a vertex there would hold the pad's centre node on a corner).
/// A tetrahedral drum contributes the exterior faces of its mesh.
fn drum_surface(case: &Case) -> Result<RigidSurfaceSpec, String> {
    let r = case.drum.radius;
    let axis = [0.0, 0.0, 1.0];
    Ok(match case.drum.surface {
        DrumSurfaceSpec::Analytic => RigidSurfaceSpec::Cylinder { radius: r, axis },
        DrumSurfaceSpec::Facets { count, .. } => RigidSurfaceSpec::FacetedCylinder {
            radius: r,
            axis,
            facets: count,
            phase: std::f64::consts::PI / count as f64,
        },
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
            .map_err(|e| format!("drum.surface: {e}"))?;
            let (vertices, triangles) = compact_triangles(&mesh.nodes, &mesh.exterior_faces());
            RigidSurfaceSpec::Triangles {
                vertices: vertices.into_iter().map(Into::into).collect(),
                triangles,
                chart: ChartSpec::Cylinder { radius: r, axis },
            }
        }
    })
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
