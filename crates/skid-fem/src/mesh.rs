//! Solid meshes of quads (D = 2) or hexes (D = 3) with named node sets and surfaces.

use std::collections::BTreeMap;

use nalgebra::SVector;

use crate::cell::{ReferenceGeometry, check_dimension, corner_count, corners, face_corners};
use crate::error::FemError;

/// Names of the coordinate axes, used for the boundary sets of structured blocks.
const AXIS_NAMES: [&str; 3] = ["x", "y", "z"];

/// A mesh of multilinear solid elements.
#[derive(Clone, Debug)]
pub struct SolidMesh<const D: usize> {
    /// Reference nodal coordinates.
    pub nodes: Vec<SVector<f64, D>>,
    /// Element connectivity: 2^D node ids each, in the cell corner order.
    pub elements: Vec<Vec<usize>>,
    /// Named node sets (sorted, unique ids).
    pub node_sets: BTreeMap<String, Vec<usize>>,
    /// Named surfaces: faces with outward orientation (see [`crate::pressure`]).
    pub surfaces: BTreeMap<String, Vec<Vec<usize>>>,
}

/// Multi-index of `id` in a grid with `counts` points per direction, first direction fastest.
fn grid_index<const D: usize>(mut id: usize, counts: &[usize; D]) -> [usize; D] {
    let mut index = [0; D];
    for (slot, &count) in index.iter_mut().zip(counts) {
        *slot = id % count;
        id /= count;
    }
    index
}

/// Linear id of the multi-index `index`, first direction fastest.
fn grid_id<const D: usize>(index: &[usize; D], counts: &[usize; D]) -> usize {
    index
        .iter()
        .zip(counts)
        .rev()
        .fold(0, |id, (&i, &count)| id * count + i)
}

impl<const D: usize> SolidMesh<D> {
    /// Structured block: origin (min corner), size (edge lengths > 0), divisions per direction
    /// (>= 1). Nodes numbered x fastest, then y, then z. Defines node sets and surfaces named
    /// "xmin", "xmax", "ymin", "ymax" (and "zmin", "zmax" in 3D) for the boundary planes.
    ///
    /// # Errors
    /// [`FemError::UnsupportedDimension`] unless D is 2 or 3; [`FemError::InvalidMesh`] for a
    /// non-finite origin, a non-positive or non-finite size, or zero divisions.
    pub fn structured_block(
        origin: SVector<f64, D>,
        size: SVector<f64, D>,
        divisions: [usize; D],
    ) -> Result<Self, FemError> {
        check_dimension::<D>()?;
        if !origin.iter().all(|v| v.is_finite()) {
            return Err(FemError::InvalidMesh(format!(
                "non-finite block origin {origin:?}"
            )));
        }
        if !size.iter().all(|&v| v > 0.0 && v.is_finite()) {
            return Err(FemError::InvalidMesh(format!(
                "block size must be finite and > 0, got {size:?}"
            )));
        }
        if divisions.contains(&0) {
            return Err(FemError::InvalidMesh(format!(
                "block divisions must be >= 1, got {divisions:?}"
            )));
        }
        let counts = divisions.map(|d| d + 1);
        let node_count: usize = counts.iter().product();
        let nodes = (0..node_count)
            .map(|id| {
                let index = grid_index(id, &counts);
                SVector::from_fn(|k, _| origin[k] + size[k] * index[k] as f64 / divisions[k] as f64)
            })
            .collect();

        let cell_offsets: Vec<[usize; D]> = corners::<D>()
            .iter()
            .map(|c| std::array::from_fn(|k| usize::from(c[k] > 0.0)))
            .collect();
        let cell_count: usize = divisions.iter().product();
        let mut elements = Vec::with_capacity(cell_count);
        let mut node_sets = BTreeMap::new();
        let mut surfaces = BTreeMap::new();
        let mut cell_indices = Vec::with_capacity(cell_count);
        for cell in 0..cell_count {
            let base = grid_index(cell, &divisions);
            let element = cell_offsets
                .iter()
                .map(|offset| grid_id(&std::array::from_fn(|k| base[k] + offset[k]), &counts))
                .collect::<Vec<_>>();
            elements.push(element);
            cell_indices.push(base);
        }
        for (axis, axis_name) in AXIS_NAMES.iter().enumerate().take(D) {
            for upper in [false, true] {
                let name = format!("{axis_name}{}", if upper { "max" } else { "min" });
                let node_layer = if upper { divisions[axis] } else { 0 };
                let set: Vec<usize> = (0..node_count)
                    .filter(|&id| grid_index(id, &counts)[axis] == node_layer)
                    .collect();
                let cell_layer = if upper { divisions[axis] - 1 } else { 0 };
                let local = face_corners::<D>(axis, upper)?;
                let faces: Vec<Vec<usize>> = elements
                    .iter()
                    .zip(&cell_indices)
                    .filter(|(_, index)| index[axis] == cell_layer)
                    .map(|(element, _)| local.iter().map(|&c| element[c]).collect())
                    .collect();
                node_sets.insert(name.clone(), set);
                surfaces.insert(name, faces);
            }
        }
        Ok(Self {
            nodes,
            elements,
            node_sets,
            surfaces,
        })
    }

    /// Consistency checks (node ids in range, 2^D nodes per element, sets/surfaces refer to
    /// existing nodes, node sets sorted and unique, 2^(D-1) nodes per face, positive reference
    /// Jacobian of every element).
    ///
    /// # Errors
    /// [`FemError::InvalidMesh`] describing the first inconsistency, or [`FemError::Element`]
    /// wrapping the geometric error of an element.
    pub fn validate(&self) -> Result<(), FemError> {
        check_dimension::<D>()?;
        let node_count = self.nodes.len();
        let check_ids = |ids: &[usize], owner: &dyn Fn() -> String| match ids
            .iter()
            .find(|&&id| id >= node_count)
        {
            Some(id) => Err(FemError::InvalidMesh(format!(
                "{} refers to node {id}, but the mesh has {node_count} nodes",
                owner()
            ))),
            None => Ok(()),
        };
        if let Some(id) = self
            .nodes
            .iter()
            .position(|x| !x.iter().all(|v| v.is_finite()))
        {
            return Err(FemError::InvalidMesh(format!(
                "node {id} has non-finite coordinates"
            )));
        }
        for (index, element) in self.elements.iter().enumerate() {
            if element.len() != corner_count(D) {
                return Err(FemError::InvalidMesh(format!(
                    "element {index} has {} nodes, expected {}",
                    element.len(),
                    corner_count(D)
                )));
            }
            check_ids(element, &|| format!("element {index}"))?;
            let x: Vec<SVector<f64, D>> = element.iter().map(|&id| self.nodes[id]).collect();
            ReferenceGeometry::new(&x).map_err(|source| FemError::Element {
                index,
                source: Box::new(source),
            })?;
        }
        for (name, set) in &self.node_sets {
            check_ids(set, &|| format!("node set {name:?}"))?;
            if set.windows(2).any(|w| w[0] >= w[1]) {
                return Err(FemError::InvalidMesh(format!(
                    "node set {name:?} is not sorted and unique"
                )));
            }
        }
        let face_size = corner_count(D - 1);
        for (name, faces) in &self.surfaces {
            for face in faces {
                if face.len() != face_size {
                    return Err(FemError::InvalidMesh(format!(
                        "surface {name:?} has a face with {} nodes, expected {face_size}",
                        face.len()
                    )));
                }
                check_ids(face, &|| format!("surface {name:?}"))?;
            }
        }
        Ok(())
    }

    /// The faces of the elements that no other element shares (the mesh's boundary), each
    /// with its corners in the outward order of [`face_corners`], in element order. Elements
    /// of the wrong corner count are skipped ([`Self::validate`] refuses them).
    pub fn exterior_faces(&self) -> Vec<Vec<usize>> {
        let faces: Vec<Vec<usize>> = self
            .elements
            .iter()
            .filter(|element| element.len() == corner_count(D))
            .flat_map(|element| {
                (0..D).flat_map(move |axis| {
                    [false, true].into_iter().filter_map(move |upper| {
                        let local = face_corners::<D>(axis, upper).ok()?;
                        Some(local.iter().map(|&c| element[c]).collect::<Vec<usize>>())
                    })
                })
            })
            .collect();
        let sorted = |face: &[usize]| {
            let mut key = face.to_vec();
            key.sort_unstable();
            key
        };
        let mut count: BTreeMap<Vec<usize>, usize> = BTreeMap::new();
        for face in &faces {
            *count.entry(sorted(face)).or_default() += 1;
        }
        faces
            .into_iter()
            .filter(|face| count.get(&sorted(face)) == Some(&1))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pressure::pressure_face_forces;
    use nalgebra::{Vector2, Vector3};

    fn block_2d() -> Result<SolidMesh<2>, FemError> {
        SolidMesh::structured_block(Vector2::new(1.0, -1.0), Vector2::new(3.0, 2.0), [3, 2])
    }

    fn block_3d() -> Result<SolidMesh<3>, FemError> {
        SolidMesh::structured_block(
            Vector3::new(0.5, 0.0, -1.0),
            Vector3::new(2.0, 3.0, 4.0),
            [2, 3, 4],
        )
    }

    #[test]
    fn structured_block_counts_and_numbering() -> Result<(), FemError> {
        let m2 = block_2d()?;
        assert_eq!((m2.nodes.len(), m2.elements.len()), (12, 6));
        assert_eq!(m2.nodes[1], Vector2::new(2.0, -1.0)); // x fastest
        assert_eq!(m2.nodes[4], Vector2::new(1.0, 0.0));
        assert_eq!(m2.node_sets["xmin"], vec![0, 4, 8]);
        assert_eq!(m2.surfaces["ymax"].len(), 3);
        let m3 = block_3d()?;
        assert_eq!((m3.nodes.len(), m3.elements.len()), (60, 24));
        assert_eq!(m3.nodes[12], Vector3::new(0.5, 0.0, 0.0)); // z layer 1 starts at 3 * 4
        assert_eq!(m3.node_sets["zmax"].len(), 12);
        assert_eq!(m3.surfaces["xmin"].len(), 12);
        assert_eq!(m3.node_sets.len(), 6);
        m2.validate()?;
        m3.validate()
    }

    /// A structured block's exterior faces are exactly the faces of its boundary surfaces, in
    /// the same outward order.
    #[test]
    fn exterior_faces_are_the_boundary_surfaces() -> Result<(), FemError> {
        fn check<const D: usize>(mesh: &SolidMesh<D>) {
            let mut exterior = mesh.exterior_faces();
            let mut boundary: Vec<Vec<usize>> = mesh.surfaces.values().flatten().cloned().collect();
            exterior.sort();
            boundary.sort();
            assert_eq!(exterior, boundary);
        }
        check(&block_2d()?);
        check(&block_3d()?);
        Ok(())
    }

    #[test]
    fn element_jacobians_are_positive() -> Result<(), FemError> {
        let m = block_3d()?;
        for element in &m.elements {
            let x: Vec<_> = element.iter().map(|&id| m.nodes[id]).collect();
            let geo = ReferenceGeometry::new(&x)?;
            assert!((geo.measure - 1.0 * 1.0 * 1.0).abs() < 1e-12);
        }
        Ok(())
    }

    fn check_outward<const D: usize>(
        m: &SolidMesh<D>,
        centre: SVector<f64, D>,
    ) -> Result<(), FemError> {
        for (name, faces) in &m.surfaces {
            for face in faces {
                let x: Vec<_> = face.iter().map(|&id| m.nodes[id]).collect();
                // With p = -1 the nodal forces add up to +n A (outward).
                let total: SVector<f64, D> = pressure_face_forces(&x, -1.0, 1.0)?.iter().sum();
                let face_centre: SVector<f64, D> =
                    x.iter().sum::<SVector<f64, D>>() / x.len() as f64;
                assert!(total.dot(&(face_centre - centre)) > 0.0, "surface {name}");
                let axis = AXIS_NAMES
                    .iter()
                    .position(|a| name.starts_with(a))
                    .unwrap_or(D);
                let sign = if name.ends_with("max") { 1.0 } else { -1.0 };
                assert!((total[axis] * sign - total.norm()).abs() < 1e-12 * total.norm());
            }
        }
        Ok(())
    }

    #[test]
    fn surfaces_point_outward() -> Result<(), FemError> {
        check_outward(&block_2d()?, Vector2::new(2.5, 0.0))?;
        check_outward(&block_3d()?, Vector3::new(1.5, 1.5, 1.0))
    }

    #[test]
    fn ymin_surface_area_equals_face_area() -> Result<(), FemError> {
        let m = block_3d()?;
        let mut total = Vector3::zeros();
        for face in &m.surfaces["ymin"] {
            let x: Vec<_> = face.iter().map(|&id| m.nodes[id]).collect();
            total += pressure_face_forces(&x, 1.0, 1.0)?
                .iter()
                .sum::<Vector3<f64>>();
        }
        // p = 1 on the face y = 0 (outward -y) pushes in +y with total force = area.
        assert!((total - Vector3::new(0.0, 2.0 * 4.0, 0.0)).norm() < 1e-12);
        let m = block_2d()?;
        let thickness = 0.25;
        let mut total = Vector2::zeros();
        for face in &m.surfaces["ymin"] {
            let x: Vec<_> = face.iter().map(|&id| m.nodes[id]).collect();
            total += pressure_face_forces(&x, 1.0, thickness)?
                .iter()
                .sum::<Vector2<f64>>();
        }
        assert!((total - Vector2::new(0.0, 3.0 * thickness)).norm() < 1e-12);
        Ok(())
    }

    #[test]
    fn invalid_meshes_are_rejected() -> Result<(), FemError> {
        assert!(matches!(
            SolidMesh::structured_block(Vector2::zeros(), Vector2::new(1.0, 0.0), [1, 1]),
            Err(FemError::InvalidMesh(_))
        ));
        assert!(matches!(
            SolidMesh::structured_block(Vector2::zeros(), Vector2::new(1.0, 1.0), [0, 1]),
            Err(FemError::InvalidMesh(_))
        ));
        let mut m = block_2d()?;
        m.elements[2][1] = 99;
        assert!(matches!(m.validate(), Err(FemError::InvalidMesh(_))));
        let mut m = block_2d()?;
        m.elements[4].swap(1, 3); // clockwise
        assert!(matches!(
            m.validate(),
            Err(FemError::Element { index: 4, ref source }) if matches!(**source, FemError::DegenerateElement { .. })
        ));
        let mut m = block_3d()?;
        m.node_sets.insert("bad".into(), vec![3, 2]);
        assert!(matches!(m.validate(), Err(FemError::InvalidMesh(_))));
        let mut m = block_3d()?;
        m.surfaces.insert("bad".into(), vec![vec![0, 1, 2]]);
        assert!(matches!(m.validate(), Err(FemError::InvalidMesh(_))));
        Ok(())
    }
}
