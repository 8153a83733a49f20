//! Tetrahedral (C3D4) meshes: a structured annular drum and its exterior faces.
//!
//! The drum of the benchmark's C3D4 idealization is a solid of four-node tetrahedra made rigid by
//! its rigid body; only its exterior faces matter for contact. The mesh is a structured grid in
//! (circumferential, radial, axial) index space over the annulus `r_in <= r <= R`,
//! `|z| <= width/2`, each cell split into the six tetrahedra of the Kuhn subdivision along its
//! local main diagonal. Because every cell face is then split along the diagonal joining its
//! lowest and highest local corner, neighbouring cells (also across the periodic seam) share
//! conforming faces. The outer lateral faces are flat chords of the circle, so each pair of
//! triangles on a 5 degree facet is coplanar: the contact geometry is the 72-facet polygon.

use std::collections::BTreeMap;

use nalgebra::Vector3;

use crate::error::FemError;

/// A tetrahedral mesh.
#[derive(Clone, Debug)]
pub struct TetMesh {
    /// Node coordinates.
    pub nodes: Vec<Vector3<f64>>,
    /// Tetrahedra (positive volume: `(b - a) x (c - a) . (d - a) > 0`).
    pub tets: Vec<[usize; 4]>,
}

/// The six tetrahedra of the Kuhn subdivision of the unit cube, as local corner indices
/// `i + 2 j + 4 k`: the paths from corner 0 to corner 7 along the three axes in every order.
const KUHN: [[usize; 4]; 6] = [
    [0, 1, 3, 7],
    [0, 1, 5, 7],
    [0, 2, 3, 7],
    [0, 2, 6, 7],
    [0, 4, 5, 7],
    [0, 4, 6, 7],
];

fn signed_volume(x: &[Vector3<f64>], t: &[usize; 4]) -> f64 {
    (x[t[1]] - x[t[0]])
        .cross(&(x[t[2]] - x[t[0]]))
        .dot(&(x[t[3]] - x[t[0]]))
        / 6.0
}

impl TetMesh {
    /// Annular drum about +z, centred at the origin: outer radius `radius`, inner radius
    /// `inner_radius`, axial `width`, with `sectors` cells around, `rings` through the wall and
    /// `layers` across the width (`cells = [sectors, rings, layers]`). Nodes sit at angles
    /// `first_angle + 2 pi k / sectors` from +x.
    ///
    /// # Errors
    /// [`FemError::InvalidMesh`] for non-positive sizes, `inner_radius >= radius`, fewer than 3
    /// sectors or zero rings/layers.
    pub fn annular_drum(
        radius: f64,
        inner_radius: f64,
        width: f64,
        cells: [usize; 3],
        first_angle: f64,
    ) -> Result<Self, FemError> {
        let [sectors, rings, layers] = cells;
        let finite_positive = |v: f64| v.is_finite() && v > 0.0;
        if !(finite_positive(radius)
            && finite_positive(inner_radius)
            && finite_positive(width)
            && first_angle.is_finite()
            && inner_radius < radius
            && sectors >= 3
            && rings >= 1
            && layers >= 1)
        {
            return Err(FemError::InvalidMesh(format!(
                "annular drum needs 0 < inner radius < radius, width > 0, >= 3 sectors and >= 1 \
                 ring and layer; got R = {radius}, r_in = {inner_radius}, w = {width}, \
                 {sectors} sectors, {rings} rings, {layers} layers"
            )));
        }
        let id = |s: usize, r: usize, l: usize| ((l * (rings + 1)) + r) * sectors + s % sectors;
        let mut nodes = Vec::with_capacity(sectors * (rings + 1) * (layers + 1));
        for l in 0..=layers {
            let z = -0.5 * width + width * l as f64 / layers as f64;
            for r in 0..=rings {
                let rho = inner_radius + (radius - inner_radius) * r as f64 / rings as f64;
                for s in 0..sectors {
                    let phi = first_angle + std::f64::consts::TAU * s as f64 / sectors as f64;
                    nodes.push(Vector3::new(rho * phi.cos(), rho * phi.sin(), z));
                }
            }
        }
        let mut tets = Vec::with_capacity(6 * sectors * rings * layers);
        for l in 0..layers {
            for r in 0..rings {
                for s in 0..sectors {
                    let corner = |c: usize| id(s + (c & 1), r + ((c >> 1) & 1), l + ((c >> 2) & 1));
                    for k in KUHN {
                        let mut t = k.map(corner);
                        if signed_volume(&nodes, &t) < 0.0 {
                            t.swap(2, 3);
                        }
                        tets.push(t);
                    }
                }
            }
        }
        Ok(Self { nodes, tets })
    }

    /// Faces that belong to exactly one tetrahedron, oriented outward (counter-clockwise seen
    /// from outside), in a deterministic order.
    pub fn exterior_faces(&self) -> Vec<[usize; 3]> {
        // Each face of a positively oriented tet (a, b, c, d), listed with outward orientation.
        const FACES: [[usize; 3]; 4] = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];
        let mut count: BTreeMap<[usize; 3], (usize, [usize; 3])> = BTreeMap::new();
        for t in &self.tets {
            for f in FACES {
                let face = f.map(|i| t[i]);
                let mut key = face;
                key.sort_unstable();
                count.entry(key).or_insert((0, face)).0 += 1;
            }
        }
        count
            .into_values()
            .filter(|(n, _)| *n == 1)
            .map(|(_, face)| face)
            .collect()
    }
}

/// The triangles `faces` of a mesh of `nodes` with only the vertices they use: the vertices
/// kept in their original order and the faces renumbered onto them.
pub fn compact_triangles(
    nodes: &[Vector3<f64>],
    faces: &[[usize; 3]],
) -> (Vec<Vector3<f64>>, Vec<[usize; 3]>) {
    let mut used = vec![false; nodes.len()];
    for &n in faces.iter().flatten() {
        used[n] = true;
    }
    let mut number = vec![0; nodes.len()];
    let mut vertices = Vec::new();
    for (n, _) in used.iter().enumerate().filter(|(_, used)| **used) {
        number[n] = vertices.len();
        vertices.push(nodes[n]);
    }
    (
        vertices,
        faces.iter().map(|t| t.map(|n| number[n])).collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{PI, TAU};

    fn drum() -> TetMesh {
        TetMesh::annular_drum(0.2, 0.1, 0.15, [72, 2, 1], 0.0).expect("mesh")
    }

    #[test]
    fn tets_are_positive_and_fill_the_faceted_annulus() {
        let m = drum();
        assert_eq!(m.tets.len(), 6 * 72 * 2);
        let volume: f64 = m.tets.iter().map(|t| signed_volume(&m.nodes, t)).sum();
        assert!(m.tets.iter().all(|t| signed_volume(&m.nodes, t) > 0.0));
        // Exact volume of the prism between the two inscribed 72-gons.
        let polygon = |r: f64| 0.5 * 72.0 * r * r * (TAU / 72.0).sin();
        let expected = (polygon(0.2) - polygon(0.1)) * 0.15;
        assert!(
            (volume - expected).abs() < 1e-12 * expected,
            "{volume} vs {expected}"
        );
    }

    #[test]
    fn exterior_faces_are_conforming_outward_and_flat_on_the_outer_facets() {
        let m = drum();
        let faces = m.exterior_faces();
        // Outer and inner lateral surfaces: 72 x 1 quads each, 2 triangles per quad; two end
        // annuli of 72 x 2 quads each. Any non-conforming interior face would add to this.
        assert_eq!(faces.len(), 2 * 72 * 2 + 2 * 72 * 2 * 2);
        let mut area = 0.0;
        for f in &faces {
            let [a, b, c] = f.map(|i| m.nodes[i]);
            let n = (b - a).cross(&(c - a));
            let centre = (a + b + c) / 3.0;
            let radial = Vector3::new(centre.x, centre.y, 0.0);
            let outward = if (centre.z.abs() - 0.075).abs() < 1e-12 {
                Vector3::new(0.0, 0.0, centre.z.signum())
            } else if radial.norm() > 0.15 {
                radial
            } else {
                -radial
            };
            assert!(n.dot(&outward) > 0.0, "face {f:?} points inward");
            if radial.norm() > 0.15 && (centre.z.abs() - 0.075).abs() > 1e-12 {
                // outer lateral triangle: in the plane of its 5 degree chord facet
                let k = (centre.y.atan2(centre.x).rem_euclid(TAU) / (TAU / 72.0)).floor();
                let mid = (k + 0.5) * TAU / 72.0;
                let normal = Vector3::new(mid.cos(), mid.sin(), 0.0);
                for p in [a, b, c] {
                    assert!((p.dot(&normal) - 0.2 * (PI / 72.0).cos()).abs() < 1e-12);
                }
                area += 0.5 * n.norm();
            }
        }
        let lateral = 72.0 * 2.0 * 0.2 * (PI / 72.0).sin() * 0.15;
        assert!((area - lateral).abs() < 1e-12, "{area} vs {lateral}");
    }

    #[test]
    fn invalid_drums_are_rejected() {
        assert!(TetMesh::annular_drum(0.2, 0.2, 0.15, [72, 1, 1], 0.0).is_err());
        assert!(TetMesh::annular_drum(0.2, 0.1, 0.15, [2, 1, 1], 0.0).is_err());
        assert!(TetMesh::annular_drum(0.2, 0.1, f64::NAN, [72, 1, 1], 0.0).is_err());
        assert!(TetMesh::annular_drum(0.2, 0.1, 0.15, [72, 0, 1], f64::INFINITY).is_err());
    }
}
