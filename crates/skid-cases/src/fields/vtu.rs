//! VTK XML unstructured grids (ASCII `.vtu`) and the collection (`.pvd`) that lists them.

use std::fmt::{self, Write as _};

use nalgebra::Vector3;

/// One named data array, its values already formatted.
pub(super) struct DataArray {
    name: &'static str,
    scalar: &'static str,
    components: usize,
    values: String,
}

impl DataArray {
    /// `Float64` values, `components` per tuple (shortest round-trip representation).
    pub(super) fn floats(
        name: &'static str,
        components: usize,
        values: impl IntoIterator<Item = f64>,
    ) -> Self {
        let values = values
            .into_iter()
            .map(|v| format!("{v:e}"))
            .collect::<Vec<_>>()
            .join(" ");
        Self {
            name,
            scalar: "Float64",
            components,
            values,
        }
    }

    /// Vectors of 3 `Float64` components.
    pub(super) fn vectors(name: &'static str, values: &[Vector3<f64>]) -> Self {
        Self::floats(name, 3, values.iter().flat_map(|v| v.iter().copied()))
    }

    /// Integers of the given VTK type (one component).
    pub(super) fn integers<T: fmt::Display>(
        name: &'static str,
        scalar: &'static str,
        values: impl IntoIterator<Item = T>,
    ) -> Self {
        let values = values
            .into_iter()
            .map(|v| v.to_string())
            .collect::<Vec<_>>()
            .join(" ");
        Self {
            name,
            scalar,
            components: 1,
            values,
        }
    }

    fn write(&self, out: &mut String) -> fmt::Result {
        writeln!(
            out,
            "        <DataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\" \
             format=\"ascii\">\n          {}\n        </DataArray>",
            self.scalar, self.name, self.components, self.values
        )
    }
}

/// The VTK cell type of a cell with `corners` corners: `VTK_LINE` (3), `VTK_TRIANGLE` (5),
/// `VTK_QUAD` (9) or `VTK_HEXAHEDRON` (12), the only cells the field output draws.
fn cell_type(corners: usize) -> Result<u8, fmt::Error> {
    match corners {
        2 => Ok(3),
        3 => Ok(5),
        4 => Ok(9),
        8 => Ok(12),
        _ => Err(fmt::Error),
    }
}

/// An unstructured grid of lines, triangles, quadrilaterals or hexahedra, each cell's type
/// given by its number of corners (listed in VTK's order).
pub(super) struct Grid {
    pub(super) points: Vec<Vector3<f64>>,
    pub(super) cells: Vec<Vec<usize>>,
    pub(super) point_data: Vec<DataArray>,
    pub(super) cell_data: Vec<DataArray>,
}

impl Grid {
    /// The grid as an ASCII VTK XML `UnstructuredGrid` file.
    ///
    /// # Errors
    /// A cell whose number of corners is none of 2, 3, 4 and 8.
    pub(super) fn to_vtu(&self) -> Result<String, fmt::Error> {
        let mut out = String::new();
        writeln!(
            out,
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" \
             byte_order=\"LittleEndian\" header_type=\"UInt64\">\n  <UnstructuredGrid>\n    \
             <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
            self.points.len(),
            self.cells.len()
        )?;
        for (tag, arrays) in [
            ("PointData", &self.point_data),
            ("CellData", &self.cell_data),
        ] {
            if arrays.is_empty() {
                continue;
            }
            writeln!(out, "      <{tag}>")?;
            for array in arrays {
                array.write(&mut out)?;
            }
            writeln!(out, "      </{tag}>")?;
        }
        writeln!(out, "      <Points>")?;
        DataArray::vectors("Points", &self.points).write(&mut out)?;
        writeln!(out, "      </Points>\n      <Cells>")?;
        let offsets = self.cells.iter().scan(0, |end, cell| {
            *end += cell.len();
            Some(*end)
        });
        let types = self
            .cells
            .iter()
            .map(|cell| cell_type(cell.len()))
            .collect::<Result<Vec<_>, _>>()?;
        for array in [
            DataArray::integers("connectivity", "Int64", self.cells.iter().flatten()),
            DataArray::integers("offsets", "Int64", offsets),
            DataArray::integers("types", "UInt8", types),
        ] {
            array.write(&mut out)?;
        }
        writeln!(
            out,
            "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>"
        )?;
        Ok(out)
    }
}

/// The collection listing, for every frame `i` at `times[i]`, one `DataSet` per file of
/// `files(i)`, numbered as parts in that order.
pub(super) fn collection(
    times: &[f64],
    files: impl Fn(usize) -> Vec<String>,
) -> Result<String, fmt::Error> {
    let mut out = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" \
         byte_order=\"LittleEndian\">\n  <Collection>\n",
    );
    for (index, time) in times.iter().enumerate() {
        for (part, file) in files(index).iter().enumerate() {
            writeln!(
                out,
                "    <DataSet timestep=\"{time:e}\" group=\"\" part=\"{part}\" file=\"{file}\"/>"
            )?;
        }
    }
    out.push_str("  </Collection>\n</VTKFile>\n");
    Ok(out)
}
