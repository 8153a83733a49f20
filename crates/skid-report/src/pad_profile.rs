//! The drum pad's contact pressure and friction profiles, read from a run's field frames
//! (`fields/skid.pvd` and the pad's `.vtu` files, written with `output.field_interval`), and
//! their node-to-node alternation.
//!
//! In each frame of the spin-down (time above 0 and below the stop), along each row of the
//! pad's front face in the sliding direction (2D: the face; 3D: one row per axial position),
//! sorted by reference x: the nodal `contact_pressure` `p` and the size of `contact_shear`
//! `q`, and their alternation
//! `A = max |f_(i-2) - 4 f_(i-1) + 6 f_i - 4 f_(i+1) + f_(i+2)| / 16` over five consecutive
//! nodes in contact (`p`) or sliding (`q`, `contact_status` 2) ([`fourth_difference`]), over
//! the frame's largest `p` (`q`). Sticking nodes are left out of the friction profile: where a
//! whole row sticks (the drum about to stop) the traction is an elastic stick solution, singular
//! at the contact's edges as in Cattaneo's full stick, and reverses its direction there, so its
//! fourth difference measures that edge (8-11 % of the peak on the 40 x 8 x 8 pad at 0.1 s,
//! within 2.3 % away from the two nodes at each end) rather than an alternation. The stick-zone
//! traction is checked against its closed form in the Cattaneo-Mindlin scenes instead. A pattern
//! `+A, -A, ...` measures `A`; the smooth profile of a pad pressed on a drum measures its
//! fourth derivative's share, largest near the contact's edges (0.6-1.2 % of the peak on the
//! 40 x 8 pad). The front face is the reference plane of the nodes in contact: the pad's
//! nodes at the reference `y` of the first node carrying pressure.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use vtkio::model::{Attribute, UnstructuredGridPiece};

use crate::ReportError;
use crate::alternation::fourth_difference;

/// The collection of a run's field frames, in its `fields/` directory.
pub const COLLECTION: &str = "skid.pvd";

/// `contact_status` of a sliding node.
const SLIDING: f64 = 2.0;

/// Nodes on the same reference plane or row: within this of each other, m.
const SAME: f64 = 1e-9;

/// The largest alternations over a run's frames.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProfileAlternation {
    /// Frames measured.
    pub frames: usize,
    /// The most nodes in contact along one row of any frame.
    pub row_nodes: usize,
    /// Largest pressure alternation, of the frame's largest pressure (`None`: no row of five
    /// nodes in contact).
    pub pressure: Option<f64>,
    /// Largest friction alternation, of the frame's largest friction traction.
    pub friction: Option<f64>,
}

/// One frame of the pad: reference points, pressure, friction traction and sliding per node.
struct Frame {
    points: Vec<[f64; 3]>,
    pressure: Vec<f64>,
    friction: Vec<f64>,
    sliding: Vec<bool>,
}

/// The pad frames of `fields` (the run's `fields/` directory) at times in `(0, until)`, and their
/// alternation; `None` if the run wrote no field frames.
///
/// # Errors
/// [`ReportError`] if the collection or a frame cannot be read or lacks the arrays.
pub fn measure(fields: &Path, until: f64) -> Result<Option<ProfileAlternation>, ReportError> {
    let collection = fields.join(COLLECTION);
    if !collection.is_file() {
        return Ok(None);
    }
    let mut result = ProfileAlternation {
        frames: 0,
        row_nodes: 0,
        pressure: None,
        friction: None,
    };
    for (time, file) in pad_frames(&collection)? {
        if time <= 0.0 || time >= until {
            continue;
        }
        let frame = alternation(&read_frame(&fields.join(file))?);
        result = ProfileAlternation {
            frames: result.frames + 1,
            row_nodes: result.row_nodes.max(frame.row_nodes),
            pressure: larger(result.pressure, frame.pressure),
            friction: larger(result.friction, frame.friction),
        };
    }
    Ok(Some(result))
}

/// The larger of two measures, either of which may be missing.
fn larger(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    match (a, b) {
        (Some(a), Some(b)) => Some(a.max(b)),
        (a, b) => a.or(b),
    }
}

/// The alternation of one frame's rows: pressure over the nodes in contact, friction over the
/// sliding ones (see the module documentation).
fn alternation(frame: &Frame) -> ProfileAlternation {
    let mut result = ProfileAlternation {
        frames: 1,
        row_nodes: 0,
        pressure: None,
        friction: None,
    };
    for row in rows(frame) {
        let touching: Vec<bool> = row.iter().map(|&n| frame.pressure[n] > 0.0).collect();
        let sliding: Vec<bool> = row.iter().map(|&n| frame.sliding[n]).collect();
        result.row_nodes = result
            .row_nodes
            .max(touching.iter().filter(|&&c| c).count());
        for (values, counted, into) in [
            (&frame.pressure, &touching, &mut result.pressure),
            (&frame.friction, &sliding, &mut result.friction),
        ] {
            let peak = values.iter().copied().fold(0.0, f64::max);
            let along: Vec<f64> = row.iter().map(|&n| values[n]).collect();
            if peak > 0.0 {
                *into = larger(*into, fourth_difference(&along, counted).map(|a| a / peak));
            }
        }
    }
    result
}

/// The (time, file) of every frame of the pad (part 0) in the collection `path`.
fn pad_frames(path: &Path) -> Result<Vec<(f64, PathBuf)>, ReportError> {
    let text = crate::read(path)?;
    let parse = |message: String| ReportError::Parse {
        path: path.to_path_buf(),
        message,
    };
    let doc = roxmltree::Document::parse(&text)
        .map_err(|e| parse(format!("expected a ParaView collection: {e}")))?;
    let mut frames = Vec::new();
    for node in doc.descendants().filter(|n| n.has_tag_name("DataSet")) {
        if node.attribute("part") != Some("0") {
            continue;
        }
        let (Some(time), Some(file)) = (node.attribute("timestep"), node.attribute("file")) else {
            return Err(parse("a DataSet without timestep or file".into()));
        };
        let time: f64 = time
            .parse()
            .map_err(|_| parse(format!("timestep {time:?} is not a number")))?;
        frames.push((time, PathBuf::from(file)));
    }
    Ok(frames)
}

/// A pad frame's reference points, `contact_pressure`, `|contact_shear|` and sliding nodes
/// (`contact_status` 2).
fn read_frame(path: &Path) -> Result<Frame, ReportError> {
    let parse = |message: String| ReportError::Parse {
        path: path.to_path_buf(),
        message,
    };
    let vtk = vtkio::Vtk::import(path).map_err(|e| parse(format!("expected a .vtu file: {e}")))?;
    let piece = UnstructuredGridPiece::try_from(vtk.data)
        .map_err(|e| parse(format!("expected an unstructured grid: {e}")))?;
    let coordinates: Vec<f64> = piece
        .points
        .cast_into()
        .ok_or_else(|| parse("points are not numbers".into()))?;
    let points: Vec<[f64; 3]> = coordinates.chunks(3).map(|p| [p[0], p[1], p[2]]).collect();
    let mut arrays = BTreeMap::new();
    for attribute in piece.data.point {
        if let Attribute::DataArray(a) = attribute {
            let values: Option<Vec<f64>> = a.data.cast_into();
            arrays.insert(a.name, (a.elem.num_comp() as usize, values));
        }
    }
    let mut array = |name: &str, components: usize| match arrays.remove(name) {
        Some((c, Some(values))) if c == components && values.len() == components * points.len() => {
            Ok(values)
        }
        _ => Err(parse(format!(
            "expected the point array {name} of {components} component(s) per point"
        ))),
    };
    let pressure = array("contact_pressure", 1)?;
    let shear = array("contact_shear", 3)?;
    let status = array("contact_status", 1)?;
    Ok(Frame {
        sliding: status.iter().map(|&s| s == SLIDING).collect(),
        friction: shear
            .chunks(3)
            .map(|s| (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt())
            .collect(),
        points,
        pressure,
    })
}

/// The rows of the front face (see the module documentation): node indices, each row at one
/// reference z, sorted by reference x.
fn rows(frame: &Frame) -> Vec<Vec<usize>> {
    let Some(first) = frame.pressure.iter().position(|&p| p > 0.0) else {
        return Vec::new();
    };
    let face_y = frame.points[first][1];
    let mut face: Vec<usize> = (0..frame.points.len())
        .filter(|&n| (frame.points[n][1] - face_y).abs() <= SAME)
        .collect();
    face.sort_by(|&a, &b| {
        let (p, q) = (frame.points[a], frame.points[b]);
        p[2].total_cmp(&q[2]).then(p[0].total_cmp(&q[0]))
    });
    let mut rows: Vec<Vec<usize>> = Vec::new();
    for n in face {
        match rows.last_mut() {
            Some(row) if (frame.points[row[0]][2] - frame.points[n][2]).abs() <= SAME => {
                row.push(n);
            }
            _ => rows.push(vec![n]),
        }
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 3D face of two rows (z = 0, 0.1) of seven nodes at y = 0.2, above a row at y = 0.15
    /// that carries nothing, with pressure `p(x)` plus `zigzag` alternating on the row z = 0.1.
    fn frame(zigzag: f64) -> Frame {
        let mut points = Vec::new();
        let mut pressure = Vec::new();
        for (y, z) in [(0.15, 0.0), (0.2, 0.1), (0.2, 0.0)] {
            for i in (0..7).rev() {
                let x = 0.01 * f64::from(i);
                points.push([x, y, z]);
                let on_face = y == 0.2;
                let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
                let extra = if z == 0.1 { sign * zigzag } else { 0.0 };
                pressure.push(if on_face {
                    1e5 * (2.0 - 10.0 * x) + extra
                } else {
                    0.0
                });
            }
        }
        let friction: Vec<f64> = pressure.iter().map(|p| 0.3 * p).collect();
        Frame {
            sliding: pressure.iter().map(|&p| p > 0.0).collect(),
            points,
            pressure,
            friction,
        }
    }

    #[test]
    fn the_face_splits_into_rows_sorted_along_x() {
        let f = frame(0.0);
        let rows = rows(&f);
        assert_eq!(rows.len(), 2);
        for row in &rows {
            assert_eq!(row.len(), 7);
            assert!(
                row.windows(2)
                    .all(|w| f.points[w[0]][0] < f.points[w[1]][0])
            );
            assert!(row.iter().all(|&n| f.points[n][1] == 0.2));
        }
        assert_eq!(f.points[rows[0][0]][2], 0.0);
    }

    #[test]
    fn a_linear_profile_does_not_alternate_and_a_zigzag_does() {
        for (zigzag, expected) in [(0.0, 0.0), (4e3, 4e3)] {
            let f = frame(zigzag);
            let peak = f.pressure.iter().copied().fold(0.0, f64::max);
            let worst = rows(&f)
                .iter()
                .filter_map(|row| {
                    let along: Vec<f64> = row.iter().map(|&n| f.pressure[n]).collect();
                    fourth_difference(&along, &vec![true; row.len()])
                })
                .fold(0.0, f64::max);
            assert!((worst - expected).abs() < 1e-9 * peak, "{worst}");
        }
    }

    #[test]
    fn friction_alternates_only_where_it_slides() {
        let mut f = frame(4e3);
        let peak = f.pressure.iter().copied().fold(0.0, f64::max);
        let sliding = alternation(&f);
        assert_eq!(sliding.row_nodes, 7);
        let expected = 4e3 / peak;
        for measured in [sliding.pressure, sliding.friction] {
            assert!(
                (measured.expect("measured") - expected).abs() < 1e-12,
                "{measured:?}"
            );
        }
        // The zigzag row sticks but one node in the middle: no five sliding nodes in a row
        // there, so only the smooth row's friction counts.
        for (n, p) in f.points.iter().enumerate() {
            if p[2] == 0.1 && p[0] != 0.03 {
                f.sliding[n] = false;
            }
        }
        let sticking = alternation(&f);
        assert!((sticking.pressure.expect("measured") - expected).abs() < 1e-12);
        assert!(sticking.friction.expect("the other row") < 1e-12);
    }

    #[test]
    fn a_run_without_frames_has_no_profile_and_a_bad_collection_is_an_error() {
        let dir = tempfile::tempdir().expect("tempdir");
        assert_eq!(measure(dir.path(), 1.0).expect("no frames"), None);
        std::fs::write(dir.path().join(COLLECTION), "<VTKFile").expect("write");
        let e = measure(dir.path(), 1.0).expect_err("malformed");
        assert!(
            e.to_string().contains("expected a ParaView collection"),
            "{e}"
        );
    }
}
