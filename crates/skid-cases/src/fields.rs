//! ParaView field output: the deformable part's fields and the rigid bodies' contact surfaces
//! as VTK XML unstructured grids (ASCII `.vtu`), listed over time in the collection `skid.pvd`.
//! Drum case files, model files and decks write the same output (the drum case's part is
//! `pad` and its drum body `drum`).
//!
//! Files in `<out>/fields/`, for frame number `NNNN`:
//!
//! - `<part>_NNNN.vtu`, named after the part: its mesh at its reference coordinates (z = 0 in
//!   2D); cells `VTK_QUAD` (9) in 2D and `VTK_HEXAHEDRON` (12) in 3D, in the mesh's corner
//!   order, which is VTK's (counter-clockwise; in 3D the bottom face, then the top face). Point
//!   data:
//!   - `displacement` (3 components, m): "Warp By Vector" shows the deformed part;
//!   - `contact_pressure` (Pa): the node's normal contact force, summed over the contact pairs
//!     it is a candidate of, over its tributary area; 0 at nodes that carry no contact force;
//!   - `contact_shear` (3 components, Pa, world frame): the tangential (friction) part of the
//!     contact force on the node over the same area;
//!   - `contact_status`: 0 open (or no candidate), 1 sticking, 2 sliding (the highest over
//!     the node's pairs).
//!
//!   Cell data: `cauchy_stress` (6 components xx yy zz xy yz xz, Pa; zz is the plane-strain
//!   stress in 2D), `volume_ratio` (J) and `mises` (von Mises stress, Pa).
//! - `<body>_NNNN.vtu`, one per rigid body that carries a contact pair's master surface, named
//!   after the body: the surface in the body's current pose (reference point plus translation,
//!   rotation by its angle about its axis). Unbounded surfaces are drawn over the part: a
//!   cylinder over the axial extent of the part's current nodes projected on its axis, a plane
//!   over their projection on it, each extent widened by [`MARGIN`] of itself at both ends. A
//!   cylinder is a band of [`CIRCLE_SEGMENTS`] quadrilaterals (2D: a closed polyline of as many
//!   lines), a faceted cylinder one quadrilateral per facet (2D: its polygon), a plane one
//!   quadrilateral (2D: a segment), triangles as they are (`VTK_TRIANGLE`); cells are ordered
//!   with the surface's outward normal. Point data `velocity` (3 components, m/s): the rigid-body velocity
//!   `v_c + omega e x (x - c)`.
//! - `skid.pvd`: the collection, one `DataSet` per file and frame (part 0 the deformable
//!   part, then the bodies in the model's order) with the frame's time as `timestep`.
//!
//! Tributary area: the current area of each contact face (an exterior face of the part all of
//! whose nodes are candidates of one contact pair; in 2D the segment length times the
//! plane-strain thickness), split equally among the face's nodes. A candidate on no contact
//! face takes its shares of all exterior faces instead. Summing pressure times area over the
//! nodes gives the total normal contact force.
//!
//! Frames: the initial state; the end of every static step; in dynamic steps the first increment
//! at or past each multiple of the field interval; and the end of the run (also of a run stopped
//! by an error). A frame at the same time as the previous one (static steps take no time)
//! replaces it, under the same number. Every file is written to a temporary name and renamed, and
//! the collection is rewritten after the frame's files, so it lists only complete frames.

mod body;
mod part;
mod vtu;

use std::io;
use std::path::{Path, PathBuf};

use skid_contact::surface::RigidSurface;
use skid_integrator::stepper::{IncrementReport, Observer};
use skid_integrator::{Model, State};

use crate::atomic::write_atomic;

pub use body::{CIRCLE_SEGMENTS, MARGIN};

/// Subdirectory of a case's output directory that holds the field output.
pub const FIELDS_DIR: &str = "fields";
/// File name of the collection.
pub const COLLECTION: &str = "skid.pvd";

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
    /// Times of the frames written so far (frame `i` at `times[i]`).
    times: Vec<f64>,
    last: Option<Last>,
}

/// Removes the field files of an earlier run from `<out>/fields/` (only the files this module
/// writes: the collection and the frames `<name>_<digits>.vtu`, with their temporaries, whatever
/// the names of that run's part and bodies), and the directory itself if that leaves it empty.
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
        let frame = name
            .strip_suffix(".vtu")
            .or_else(|| name.strip_suffix(".vtu.partial"))
            .is_some_and(is_frame_stem);
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
    pub fn create(out: &Path, interval: f64) -> io::Result<Self> {
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
        memory: FieldMemory,
        state: State,
    ) -> io::Result<Self> {
        let mut writer = Self::create(out, interval)?;
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
        let current = part::current_positions(model, state);
        let mut grids = vec![(
            part::part_grid(model, state, &current)?,
            model.part().name.as_str(),
        )];
        for (body, surface) in drawn_bodies(model) {
            grids.push((
                body::body_grid(model, state, body, surface, &current)?,
                model.bodies()[body].name.as_str(),
            ));
        }
        for (grid, name) in &grids {
            let text = grid.to_vtu().map_err(io::Error::other)?;
            write_atomic(&self.dir.join(frame_file(name, index)), &text)?;
        }
        self.times.truncate(index);
        self.times.push(state.time);
        let names: Vec<&str> = grids.iter().map(|(_, name)| *name).collect();
        let text = vtu::collection(&self.times, |i| {
            names.iter().map(|name| frame_file(name, i)).collect()
        })
        .map_err(io::Error::other)?;
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

/// The rigid bodies drawn: each one that carries a contact pair's master surface, in the
/// model's order, with the surface of its first pair.
fn drawn_bodies<const D: usize>(model: &Model<D>) -> Vec<(usize, &dyn RigidSurface)> {
    (0..model.bodies().len())
        .filter_map(|body| {
            let pair = model.contacts().iter().find(|pair| pair.body == body)?;
            Some((body, pair.surface.as_ref()))
        })
        .collect()
}

/// The file of frame `index` of the part or body `name`: `<name>_NNNN.vtu`.
fn frame_file(name: &str, index: usize) -> String {
    format!("{name}_{index:04}.vtu")
}

/// Whether a file stem is that of a frame file, `<name>_<digits>`.
fn is_frame_stem(stem: &str) -> bool {
    stem.rsplit_once('_').is_some_and(|(name, digits)| {
        !name.is_empty() && !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit())
    })
}

fn invalid_data(message: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidData, message)
}
