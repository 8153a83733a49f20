//! The deformable part's frame: its reference mesh with displacements, contact tractions and
//! element stresses.

use std::collections::BTreeSet;
use std::io;

use nalgebra::{Matrix3, SVector, Vector3};
use skid_contact::kinematics::evaluate;
use skid_fem::cell::embed;
use skid_integrator::{Model, State};

use super::invalid_data;
use super::vtu::{DataArray, Grid};

/// Tensor index pairs of the six stress components, in output order.
const STRESS_COMPONENTS: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (0, 2)];

/// The nodes' current positions, embedded in 3D (z = 0 in 2D).
pub(super) fn current_positions<const D: usize>(
    model: &Model<D>,
    state: &State,
) -> Vec<Vector3<f64>> {
    (0..model.part().mesh.nodes.len())
        .map(|n| model.node_position(&state.x, n))
        .collect()
}

/// The part: reference mesh, displacements, contact tractions and element stresses.
/// `current`: the nodes' current positions.
pub(super) fn part_grid<const D: usize>(
    model: &Model<D>,
    state: &State,
    current: &[Vector3<f64>],
) -> io::Result<Grid> {
    let part = model.part();
    let mesh = &part.mesh;
    let u: Vec<SVector<f64, D>> = (0..mesh.nodes.len())
        .map(|n| model.dofs().node_displacement(&state.x, n))
        .collect();
    let contact = contact_tractions(model, state, current)?;
    let cells = mesh.elements.len();
    let (mut stress, mut ratio, mut mises) = (
        Vec::with_capacity(6 * cells),
        Vec::with_capacity(cells),
        Vec::with_capacity(cells),
    );
    for (e, (element, nodes)) in model.elements().iter().zip(&mesh.elements).enumerate() {
        let u_e: Vec<_> = nodes.iter().map(|&n| u[n]).collect();
        let response = element
            .respond(part.material(e), &u_e)
            .map_err(|err| invalid_data(format!("part '{}' element {e}: {err}", part.name)))?;
        let s = response.cauchy_stress;
        stress.extend(STRESS_COMPONENTS.map(|(i, j)| s[(i, j)]));
        ratio.push(response.volume_ratio);
        let deviator = s - Matrix3::identity() * (s.trace() / 3.0);
        mises.push((1.5 * deviator.norm_squared()).sqrt());
    }
    Ok(Grid {
        points: mesh.nodes.iter().map(embed).collect(),
        cells: mesh.elements.clone(),
        point_data: vec![
            DataArray::vectors("displacement", &u.iter().map(embed).collect::<Vec<_>>()),
            DataArray::floats("contact_pressure", 1, contact.pressure),
            DataArray::vectors("contact_shear", &contact.shear),
            DataArray::integers("contact_status", "Int32", contact.status),
        ],
        cell_data: vec![
            DataArray::floats("cauchy_stress", 6, stress),
            DataArray::floats("volume_ratio", 1, ratio),
            DataArray::floats("mises", 1, mises),
        ],
    })
}

/// Contact tractions and status per node of the part.
struct ContactTractions {
    pressure: Vec<f64>,
    shear: Vec<Vector3<f64>>,
    status: Vec<i32>,
}

/// Sums the contact forces of every pair on each node and divides them by the node's tributary
/// area ([`tributary_areas`]). `current`: the nodes' current positions.
fn contact_tractions<const D: usize>(
    model: &Model<D>,
    state: &State,
    current: &[Vector3<f64>],
) -> io::Result<ContactTractions> {
    let n = current.len();
    let mut normal = vec![0.0; n];
    let mut shear = vec![Vector3::zeros(); n];
    let mut status = vec![0; n];
    for c in state.contacts.iter().filter(|c| c.is_closed()) {
        let pair = model
            .contacts()
            .get(c.pair)
            .ok_or_else(|| invalid_data(format!("contact pair {} does not exist", c.pair)))?;
        let frame = model.body_frame(&state.x, pair.body, &state.orientations);
        let position = current
            .get(c.node)
            .ok_or_else(|| invalid_data(format!("contact node {} does not exist", c.node)))?;
        let kinematics = evaluate(pair.surface.as_ref(), &frame, position, Some(&c.closest))
            .ok_or_else(|| {
                invalid_data(format!(
                    "contact pair '{}': node {} has no projection",
                    pair.name, c.node
                ))
            })?;
        normal[c.node] += c.normal_force;
        // The tangential forces are conjugate to the slip: their force on the node is
        // r_T,k d s_k / dx, here with the slip's rows at the converged contact point (those of
        // the increment, which start at its contact point, differ by the increment's turn of
        // the surface's tangents on a surface of revolution or a plane-charted mesh).
        for k in 0..D - 1 {
            shear[c.node] += kinematics.d_dx[k + 1] * c.tangential_force[k];
        }
        let sliding =
            pair.mu > 0.0 && c.tangential_force.norm() >= pair.mu * c.normal_force * (1.0 - 1e-6);
        status[c.node] = status[c.node].max(if sliding { 2 } else { 1 });
    }
    let area = tributary_areas(model, current);
    let per_area = |force: f64, a: f64| if a > 0.0 { force / a } else { 0.0 };
    Ok(ContactTractions {
        pressure: normal
            .iter()
            .zip(&area)
            .map(|(&f, &a)| per_area(f, a))
            .collect(),
        shear: shear
            .iter()
            .zip(&area)
            .map(|(f, &a)| f.map(|c| per_area(c, a)))
            .collect(),
        status,
    })
}

/// Tributary area of each node: its shares of the contact faces, the exterior faces of the
/// part all of whose nodes are candidates of one same contact pair; a node on no contact face
/// (a candidate off the faces of its pair's candidates) takes its shares of all the exterior
/// faces instead. A face's share is its current area split equally among its nodes (2D: the
/// segment length times the plane-strain thickness; 3D: the quadrilateral's area from its
/// diagonals, `|d_1 x d_2| / 2`).
///
/// So `sum_n p_n A_n` over the nodes is the sum of the normal contact forces of every pair,
/// and a node that is a candidate of several pairs divides their summed force by one area.
fn tributary_areas<const D: usize>(model: &Model<D>, current: &[Vector3<f64>]) -> Vec<f64> {
    let thickness = if D == 2 { model.part().thickness } else { 1.0 };
    let exterior = model.part().mesh.exterior_faces();
    let candidates: Vec<BTreeSet<usize>> = model
        .contacts()
        .iter()
        .map(|pair| pair.nodes.iter().copied().collect())
        .collect();
    let on_contact = |face: &&Vec<usize>| {
        candidates
            .iter()
            .any(|set| face.iter().all(|n| set.contains(n)))
    };
    let contact = shares(exterior.iter().filter(on_contact), current, thickness);
    let all = shares(&exterior, current, thickness);
    contact
        .iter()
        .zip(&all)
        .map(|(&c, &a)| if c > 0.0 { c } else { a })
        .collect()
}

/// Current area of the faces split equally among their nodes (2D: segment length times
/// `thickness`; 3D: quadrilateral area from its diagonals).
fn shares<'a>(
    faces: impl IntoIterator<Item = &'a Vec<usize>>,
    x: &[Vector3<f64>],
    thickness: f64,
) -> Vec<f64> {
    let mut area = vec![0.0; x.len()];
    for face in faces {
        let a = match *face.as_slice() {
            [p, q] => (x[q] - x[p]).norm() * thickness,
            [p, q, r, s] => 0.5 * (x[r] - x[p]).cross(&(x[s] - x[q])).norm(),
            _ => continue,
        };
        for &node in face {
            area[node] += a / face.len() as f64;
        }
    }
    area
}
