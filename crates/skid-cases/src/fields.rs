//! ParaView field output: the pad's fields and the drum's surface as VTK XML unstructured grids
//! (ASCII `.vtu`), listed over time in the collection `skid.pvd`.
//!
//! Files in `<out>/fields/`, for frame number `NNNN`:
//!
//! - `pad_NNNN.vtu`: the pad mesh at its reference coordinates (z = 0 in 2D); cells `VTK_QUAD`
//!   (9) in 2D and `VTK_HEXAHEDRON` (12) in 3D, in the mesh's corner order, which is VTK's
//!   (counter-clockwise; in 3D the bottom face, then the top face). Point data:
//!   - `displacement` (3 components, m): "Warp By Vector" shows the deformed pad;
//!   - `contact_pressure` (Pa): the node's normal contact force over its tributary area, 0 at
//!     nodes that carry no contact force;
//!   - `contact_shear` (3 components, Pa, world frame): the tangential (friction) part of the
//!     contact force on the pad node over the same area;
//!   - `contact_status`: 0 open (or no candidate), 1 sticking, 2 sliding.
//!
//!   Cell data: `cauchy_stress` (6 components xx yy zz xy yz xz, Pa; zz is the plane-strain
//!   stress in 2D), `volume_ratio` (J) and `mises` (von Mises stress, Pa).
//! - `drum_NNNN.vtu`: the drum's lateral surface at radius R, whatever its idealization, rotated
//!   by the current drum angle about +z through its reference point: in 2D a closed polyline of
//!   [`DRUM_SEGMENTS`] `VTK_LINE` cells, in 3D a band of [`DRUM_SEGMENTS`] `VTK_QUAD` cells over
//!   the drum width. Point data `velocity` (3 components, m/s) = omega e_z x r.
//! - `skid.pvd`: the collection, one `DataSet` per part and frame (part 0 the pad, part 1 the
//!   drum) with the frame's time as `timestep`.
//!
//! Tributary area: the current area of each face of the pad's front surface (in 2D the segment
//! length times the plane-strain thickness), split equally among the face's nodes. A candidate
//! off the front face (general contact) takes its shares of all exterior faces instead.
//!
//! Frames: the initial state; the end of every static step; in dynamic steps the first increment
//! at or past each multiple of the field interval; and the end of the run (also of a run stopped
//! by an error). A frame at the same time as the previous one (static steps take no time)
//! replaces it, under the same number. Every file is written to a temporary name and renamed, and
//! the collection is rewritten after the frame's files, so it lists only complete frames.

use std::fmt::{self, Write as _};
use std::io;
use std::path::{Path, PathBuf};

use nalgebra::{SVector, Vector3};
use skid_contact::kinematics::{RotatingFrame, evaluate};
use skid_fem::cell::embed;
use skid_integrator::stepper::{IncrementReport, Observer};
use skid_integrator::{Model, State};

use crate::atomic::write_atomic;
use crate::schema::DRUM;

/// Subdirectory of a case's output directory that holds the field output.
pub const FIELDS_DIR: &str = "fields";
/// File name of the collection.
pub const COLLECTION: &str = "skid.pvd";
/// Segments of the drum outline around the circumference.
pub const DRUM_SEGMENTS: usize = 144;
/// Surface of the pad mesh that faces the drum (see [`crate::drum`]).
const FRONT_SURFACE: &str = "ymin";

const VTK_LINE: u8 = 3;
const VTK_QUAD: u8 = 9;
const VTK_HEXAHEDRON: u8 = 12;
/// Tensor index pairs of the six stress components, in output order.
const STRESS_COMPONENTS: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (0, 2)];

/// Drum dimensions used to draw its surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DrumOutline {
    /// Radius R, m.
    pub radius: f64,
    /// Axial width (extent of the 3D band), m.
    pub width: f64,
}

/// The last converged state seen, kept for the frame at the end of a static step or run.
struct Last {
    state: State,
    in_static_step: bool,
    written: bool,
}

/// What a [`FieldWriter`] carries to a restart point: the frames written and whether the last
/// state seen (the restart point's) has a frame.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FieldMemory {
    /// Times of the frames written (frame `i` at `times[i]`).
    pub times: Vec<f64>,
    /// Whether the last state seen ended an increment of a static step.
    pub last_in_static_step: bool,
    /// Whether the last state seen has been written as a frame.
    pub last_written: bool,
}

/// Observer writing the field frames into `<out>/fields/` (see the module documentation).
pub struct FieldWriter {
    dir: PathBuf,
    interval: f64,
    drum: DrumOutline,
    /// Times of the frames written so far (frame `i` at `times[i]`).
    times: Vec<f64>,
    last: Option<Last>,
}

/// Removes the field files of an earlier run from `<out>/fields/` (only the files this module
/// writes), and the directory itself if that leaves it empty.
///
/// # Errors
/// I/O errors.
pub fn clear(out: &Path) -> io::Result<()> {
    let dir = out.join(FIELDS_DIR);
    if !dir.is_dir() {
        return Ok(());
    }
    for entry in std::fs::read_dir(&dir)? {
        let path = entry?.path();
        let name = path
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or_default();
        let frame = (name.starts_with("pad_") || name.starts_with("drum_"))
            && (name.ends_with(".vtu") || name.ends_with(".vtu.partial"));
        if frame || name == COLLECTION || name == format!("{COLLECTION}.partial") {
            std::fs::remove_file(&path)?;
        }
    }
    if std::fs::read_dir(&dir)?.next().is_none() {
        std::fs::remove_dir(&dir)?;
    }
    Ok(())
}

impl FieldWriter {
    /// Creates `<out>/fields/` for frames every `interval` seconds of dynamic steps.
    ///
    /// # Errors
    /// An `InvalidInput` error unless `interval` is finite and > 0; I/O errors.
    pub fn create(out: &Path, interval: f64, drum: DrumOutline) -> io::Result<Self> {
        if !(interval.is_finite() && interval > 0.0) {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("field interval must be finite and > 0, got {interval}"),
            ));
        }
        let dir = out.join(FIELDS_DIR);
        std::fs::create_dir_all(&dir)?;
        Ok(Self {
            dir,
            interval,
            drum,
            times: Vec::new(),
            last: None,
        })
    }

    /// Continues the field output of an interrupted run in `<out>/fields/` as it stood at a
    /// restart point: `memory` and `state`, the restart point's state. Frames written after the
    /// restart point are written again, the same, under the same numbers.
    ///
    /// # Errors
    /// As [`Self::create`].
    pub fn reopen(
        out: &Path,
        interval: f64,
        drum: DrumOutline,
        memory: FieldMemory,
        state: State,
    ) -> io::Result<Self> {
        let mut writer = Self::create(out, interval, drum)?;
        writer.times = memory.times;
        writer.last = Some(Last {
            state,
            in_static_step: memory.last_in_static_step,
            written: memory.last_written,
        });
        Ok(writer)
    }

    /// What this writer carries to a restart point (see [`FieldMemory`]).
    pub fn memory(&self) -> FieldMemory {
        FieldMemory {
            times: self.times.clone(),
            last_in_static_step: self.last.as_ref().is_some_and(|l| l.in_static_step),
            last_written: self.last.as_ref().is_none_or(|l| l.written),
        }
    }

    /// Writes the frame of the end of the run (the last converged state) unless it has been
    /// written already, and returns the number of frames.
    ///
    /// # Errors
    /// I/O errors, or a state whose fields cannot be evaluated.
    pub fn finish<const D: usize>(mut self, model: &Model<D>) -> io::Result<usize> {
        self.flush_last(model, |_| true)?;
        Ok(self.times.len())
    }

    /// Writes the kept last state if it has not been written and `wanted` says so.
    fn flush_last<const D: usize>(
        &mut self,
        model: &Model<D>,
        wanted: impl Fn(&Last) -> bool,
    ) -> io::Result<()> {
        if let Some(mut last) = self.last.take() {
            if !last.written && wanted(&last) {
                self.write_frame(model, &last.state)?;
                last.written = true;
            }
            self.last = Some(last);
        }
        Ok(())
    }

    /// Whether a dynamic increment ending at `time` reaches the next multiple of the interval
    /// after the last frame.
    fn due(&self, time: f64) -> bool {
        let slack = 1e-6;
        let previous = self.times.last().copied().unwrap_or(f64::NEG_INFINITY);
        let next = ((previous / self.interval + slack).floor() + 1.0) * self.interval;
        time >= next - slack * self.interval
    }

    fn write_frame<const D: usize>(&mut self, model: &Model<D>, state: &State) -> io::Result<()> {
        let index = match self.times.last() {
            Some(&t) if state.time <= t => self.times.len() - 1,
            _ => self.times.len(),
        };
        let pad = pad_grid(model, state)?;
        let drum = drum_grid(model, state, self.drum)?;
        for (grid, file) in [(pad, pad_file(index)), (drum, drum_file(index))] {
            let text = grid.to_vtu().map_err(io::Error::other)?;
            write_atomic(&self.dir.join(file), &text)?;
        }
        self.times.truncate(index);
        self.times.push(state.time);
        let text = collection(&self.times).map_err(io::Error::other)?;
        write_atomic(&self.dir.join(COLLECTION), &text)
    }
}

impl<const D: usize> Observer<D> for FieldWriter {
    fn on_increment(&mut self, model: &Model<D>, report: &IncrementReport<'_>) -> io::Result<()> {
        if report.increment == 1 {
            // A new step begins, so the previous one has ended.
            self.flush_last(model, |last| last.in_static_step)?;
        }
        let frame = report.increment == 0 || (report.dynamic && self.due(report.state.time));
        if frame {
            self.write_frame(model, report.state)?;
        }
        self.last = Some(Last {
            state: report.state.clone(),
            in_static_step: !report.dynamic && report.increment > 0,
            written: frame,
        });
        Ok(())
    }
}

fn pad_file(index: usize) -> String {
    format!("pad_{index:04}.vtu")
}

fn drum_file(index: usize) -> String {
    format!("drum_{index:04}.vtu")
}

fn invalid_data(message: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidData, message)
}

/// The collection listing both parts of every frame.
fn collection(times: &[f64]) -> Result<String, fmt::Error> {
    let mut out = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" \
         byte_order=\"LittleEndian\">\n  <Collection>\n",
    );
    for (index, time) in times.iter().enumerate() {
        for (part, file) in [(0, pad_file(index)), (1, drum_file(index))] {
            writeln!(
                out,
                "    <DataSet timestep=\"{time:e}\" group=\"\" part=\"{part}\" file=\"{file}\"/>"
            )?;
        }
    }
    out.push_str("  </Collection>\n</VTKFile>\n");
    Ok(out)
}

/// One named data array, its values already formatted.
struct DataArray {
    name: &'static str,
    scalar: &'static str,
    components: usize,
    values: String,
}

impl DataArray {
    /// `Float64` values, `components` per tuple (shortest round-trip representation).
    fn floats(
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
    fn vectors(name: &'static str, values: &[Vector3<f64>]) -> Self {
        Self::floats(name, 3, values.iter().flat_map(|v| v.iter().copied()))
    }

    /// Integers of the given VTK type (one component).
    fn integers<T: fmt::Display>(
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

/// An unstructured grid with one cell type.
struct Grid {
    points: Vec<Vector3<f64>>,
    cells: Vec<Vec<usize>>,
    cell_type: u8,
    point_data: Vec<DataArray>,
    cell_data: Vec<DataArray>,
}

impl Grid {
    /// The grid as an ASCII VTK XML `UnstructuredGrid` file.
    fn to_vtu(&self) -> Result<String, fmt::Error> {
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
        for array in [
            DataArray::integers("connectivity", "Int64", self.cells.iter().flatten()),
            DataArray::integers("offsets", "Int64", offsets),
            DataArray::integers("types", "UInt8", self.cells.iter().map(|_| self.cell_type)),
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

/// The pad: reference mesh, displacements, contact tractions and element stresses.
fn pad_grid<const D: usize>(model: &Model<D>, state: &State) -> io::Result<Grid> {
    let part = model.part();
    let mesh = &part.mesh;
    let u: Vec<SVector<f64, D>> = (0..mesh.nodes.len())
        .map(|n| model.dofs().node_displacement(&state.x, n))
        .collect();
    let current: Vec<Vector3<f64>> = mesh
        .nodes
        .iter()
        .zip(&u)
        .map(|(x, u)| embed(&(x + u)))
        .collect();
    let contact = contact_tractions(model, state, &current)?;
    let cells = mesh.elements.len();
    let (mut stress, mut ratio, mut mises) = (
        Vec::with_capacity(6 * cells),
        Vec::with_capacity(cells),
        Vec::with_capacity(cells),
    );
    for (e, (element, nodes)) in model.elements().iter().zip(&mesh.elements).enumerate() {
        let u_e: Vec<_> = nodes.iter().map(|&n| u[n]).collect();
        let response = element
            .evaluate(part.material(e), &u_e, false)
            .map_err(|err| invalid_data(format!("pad element {e}: {err}")))?;
        let s = response.cauchy_stress;
        stress.extend(STRESS_COMPONENTS.map(|(i, j)| s[(i, j)]));
        ratio.push(response.volume_ratio);
        let deviator = s - nalgebra::Matrix3::identity() * (s.trace() / 3.0);
        mises.push((1.5 * deviator.norm_squared()).sqrt());
    }
    Ok(Grid {
        points: mesh.nodes.iter().map(embed).collect(),
        cells: mesh.elements.clone(),
        cell_type: if D == 2 { VTK_QUAD } else { VTK_HEXAHEDRON },
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

/// Contact tractions and status per node of the pad.
struct ContactTractions {
    pressure: Vec<f64>,
    shear: Vec<Vector3<f64>>,
    status: Vec<i32>,
}

/// Sums the contact forces of every candidate on its node and divides them by the node's
/// tributary area. `current`: the nodes' current positions.
fn contact_tractions<const D: usize>(
    model: &Model<D>,
    state: &State,
    current: &[Vector3<f64>],
) -> io::Result<ContactTractions> {
    let n = current.len();
    let mut normal = vec![0.0; n];
    let mut shear = vec![Vector3::zeros(); n];
    let mut status = vec![0; n];
    let dofs = model.dofs();
    for c in state.contacts.iter().filter(|c| c.is_closed()) {
        let pair = model
            .contacts()
            .get(c.pair)
            .ok_or_else(|| invalid_data(format!("contact pair {} does not exist", c.pair)))?;
        let body = &model.bodies()[pair.body];
        let frame = RotatingFrame {
            center: embed(&(body.reference_point + dofs.body_displacement(&state.x, pair.body))),
            axis: body.rotation_axis.unwrap_or_else(Vector3::z),
            angle: dofs.body_angle(&state.x, pair.body),
        };
        let position = current
            .get(c.node)
            .ok_or_else(|| invalid_data(format!("contact node {} does not exist", c.node)))?;
        let kinematics = evaluate(pair.surface.as_ref(), &frame, position).ok_or_else(|| {
            invalid_data(format!(
                "contact pair '{}': node {} has no projection",
                pair.name, c.node
            ))
        })?;
        normal[c.node] += c.normal_force;
        // The tangential forces are conjugate to the convected coordinates: their force on
        // the node is r_T,k d xi_k / dx.
        for k in 0..D - 1 {
            shear[c.node] += kinematics.d_dx[k + 1] * c.tangential_force[k];
        }
        let sliding =
            pair.mu > 0.0 && c.tangential_force.norm() >= pair.mu * c.normal_force * (1.0 - 1e-6);
        status[c.node] = status[c.node].max(if sliding { 2 } else { 1 });
    }
    let mesh = &model.part().mesh;
    let thickness = if D == 2 { model.part().thickness } else { 1.0 };
    let front = tributary_areas(
        mesh.surfaces.get(FRONT_SURFACE).into_iter().flatten(),
        current,
        thickness,
    );
    let exterior = tributary_areas(mesh.surfaces.values().flatten(), current, thickness);
    let area: Vec<f64> = front
        .iter()
        .zip(&exterior)
        .map(|(&f, &e)| if f > 0.0 { f } else { e })
        .collect();
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

/// Current area of the faces split equally among their nodes (2D: segment length times
/// `thickness`; 3D: quadrilateral area from its diagonals).
fn tributary_areas<'a>(
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

/// The drum's lateral surface at the current angle, with its velocity.
fn drum_grid<const D: usize>(
    model: &Model<D>,
    state: &State,
    outline: DrumOutline,
) -> io::Result<Grid> {
    let body = model
        .bodies()
        .get(DRUM)
        .ok_or_else(|| invalid_data("the model has no drum".into()))?;
    let dofs = model.dofs();
    let center = embed(&(body.reference_point + dofs.body_displacement(&state.x, DRUM)));
    let angle = dofs.body_angle(&state.x, DRUM);
    let omega = dofs.body_rotation(DRUM).map_or(0.0, |eq| state.v[eq]);
    let n = DRUM_SEGMENTS;
    let rings: &[f64] = if D == 2 {
        &[0.0]
    } else {
        &[-0.5 * outline.width, 0.5 * outline.width]
    };
    let points: Vec<Vector3<f64>> = rings
        .iter()
        .flat_map(|&z| {
            (0..n).map(move |k| {
                let phi = angle + std::f64::consts::TAU * k as f64 / n as f64;
                center + Vector3::new(outline.radius * phi.cos(), outline.radius * phi.sin(), z)
            })
        })
        .collect();
    let velocity: Vec<Vector3<f64>> = points
        .iter()
        .map(|p| Vector3::z().cross(&(p - center)) * omega)
        .collect();
    let next = |k: usize| (k + 1) % n;
    let (cells, cell_type) = if D == 2 {
        ((0..n).map(|k| vec![k, next(k)]).collect(), VTK_LINE)
    } else {
        let cells = (0..n).map(|k| vec![k, next(k), n + next(k), n + k]);
        (cells.collect(), VTK_QUAD)
    };
    Ok(Grid {
        points,
        cells,
        cell_type,
        point_data: vec![DataArray::vectors("velocity", &velocity)],
        cell_data: Vec::new(),
    })
}
