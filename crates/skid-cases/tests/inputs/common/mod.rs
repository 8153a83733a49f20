//! What the field-output tests share: a `.vtu` file as read by the independent reader `vtkio`.

use std::collections::HashMap;
use std::path::Path;

use vtkio::model::{Attribute, CellType, UnstructuredGridPiece, VertexNumbers};

/// An unstructured grid as read by vtkio.
pub struct Vtu {
    pub points: Vec<[f64; 3]>,
    pub cells: Vec<Vec<usize>>,
    pub types: Vec<CellType>,
    pub point_data: HashMap<String, (usize, Vec<f64>)>,
    pub cell_data: HashMap<String, (usize, Vec<f64>)>,
}

impl Vtu {
    pub fn read(path: &Path) -> Self {
        let vtk = vtkio::Vtk::import(path).unwrap_or_else(|e| panic!("{path:?}: {e:?}"));
        let piece = UnstructuredGridPiece::try_from(vtk.data).expect("unstructured grid");
        let points: Vec<f64> = piece.points.cast_into().expect("points");
        let VertexNumbers::XML {
            connectivity,
            offsets,
        } = piece.cells.cell_verts
        else {
            panic!("expected XML cells");
        };
        let mut start = 0;
        let cells = offsets
            .iter()
            .map(|&end| {
                let cell = connectivity[start..end as usize]
                    .iter()
                    .map(|&i| i as usize)
                    .collect();
                start = end as usize;
                cell
            })
            .collect();
        let arrays = |attributes: Vec<Attribute>| {
            attributes
                .into_iter()
                .map(|a| match a {
                    Attribute::DataArray(a) => (
                        a.name,
                        (
                            a.elem.num_comp() as usize,
                            a.data.cast_into::<f64>().expect("numbers"),
                        ),
                    ),
                    Attribute::Field { .. } => panic!("unexpected field attribute"),
                })
                .collect::<HashMap<_, _>>()
        };
        Self {
            points: points.chunks(3).map(|p| [p[0], p[1], p[2]]).collect(),
            cells,
            types: piece.cells.types,
            point_data: arrays(piece.data.point),
            cell_data: arrays(piece.data.cell),
        }
    }

    /// A point array with `components` per point (checked), one `Vec` per point.
    pub fn point(&self, name: &str, components: usize) -> Vec<Vec<f64>> {
        tuples(&self.point_data, name, components, self.points.len())
    }

    pub fn cell(&self, name: &str, components: usize) -> Vec<Vec<f64>> {
        tuples(&self.cell_data, name, components, self.cells.len())
    }
}

fn tuples(
    arrays: &HashMap<String, (usize, Vec<f64>)>,
    name: &str,
    components: usize,
    count: usize,
) -> Vec<Vec<f64>> {
    let (n, values) = arrays
        .get(name)
        .unwrap_or_else(|| panic!("no array {name}"));
    assert_eq!(*n, components, "{name}");
    assert_eq!(values.len(), components * count, "{name}");
    values.chunks(components).map(<[f64]>::to_vec).collect()
}

/// Faces of a VTK hexahedron, each ordered around its boundary.
pub const HEX_FACES: [[usize; 4]; 6] = [
    [0, 3, 2, 1],
    [4, 5, 6, 7],
    [0, 1, 5, 4],
    [1, 2, 6, 5],
    [2, 3, 7, 6],
    [3, 0, 4, 7],
];

pub fn sub(a: &[f64], b: &[f64]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// Current positions: reference points plus `displacement`.
pub fn current(pad: &Vtu) -> Vec<Vec<f64>> {
    pad.points
        .iter()
        .zip(pad.point("displacement", 3))
        .map(|(x, u)| (0..3).map(|i| x[i] + u[i]).collect())
        .collect()
}

/// The faces of a cell with VTK's own edge (2D) and face (3D) definitions, each ordered around
/// its boundary.
pub fn cell_faces(cell: &[usize], dimension: usize) -> Vec<Vec<usize>> {
    if dimension == 2 {
        (0..4).map(|k| vec![cell[k], cell[(k + 1) % 4]]).collect()
    } else {
        HEX_FACES
            .iter()
            .map(|f| f.iter().map(|&k| cell[k]).collect())
            .collect()
    }
}

/// Tributary areas of the nodes `on_contact` selects: the current area of each exterior face
/// (one no other cell shares) all of whose nodes it selects, split equally among them (2D: the
/// edge length times `thickness`; 3D: half the cross product of the diagonals).
pub fn tributary_areas(
    grid: &Vtu,
    dimension: usize,
    thickness: f64,
    on_contact: &dyn Fn(usize) -> bool,
) -> Vec<f64> {
    let x = current(grid);
    let faces: Vec<Vec<usize>> = grid
        .cells
        .iter()
        .flat_map(|cell| cell_faces(cell, dimension))
        .collect();
    let key = |face: &[usize]| {
        let mut k = face.to_vec();
        k.sort_unstable();
        k
    };
    let mut count: HashMap<Vec<usize>, usize> = HashMap::new();
    for face in &faces {
        *count.entry(key(face)).or_default() += 1;
    }
    let mut area = vec![0.0; grid.points.len()];
    for face in faces
        .iter()
        .filter(|f| count[&key(f)] == 1 && f.iter().all(|&n| on_contact(n)))
    {
        let a = if dimension == 2 {
            norm(sub(&x[face[1]], &x[face[0]])) * thickness
        } else {
            0.5 * norm(cross(
                sub(&x[face[2]], &x[face[0]]),
                sub(&x[face[3]], &x[face[1]]),
            ))
        };
        for &n in face {
            area[n] += a / face.len() as f64;
        }
    }
    area
}
