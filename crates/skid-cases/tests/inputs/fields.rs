//! The ParaView field output, read back with independent readers (`vtkio` for the `.vtu` files,
//! `roxmltree` for the `.pvd` collection) and checked against the run's `history.csv`.

use std::collections::HashMap;
use std::f64::consts::TAU;
use std::path::Path;

use skid_cases::csv_out::CsvTable;
use skid_cases::{parse_case, run_case};
use vtkio::model::CellType;

use crate::common;
use crate::common::{Vtu, cross, current, norm, sub};

const CASE_2D: &str = include_str!("../../../../cases/drum/2d-analytic.json");
const CASE_3D: &str = include_str!("../../../../cases/drum/3d-analytic.json");
/// Drum radius, pad width (the plane-strain thickness in 2D) and drum width of both cases.
const R: f64 = 0.2;
const PAD_WIDTH: f64 = 0.1;
const DRUM_WIDTH: f64 = 0.15;

fn run(text: &str, overrides: &[&str], dir: &Path) {
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let case = parse_case(text, Path::new("case.json"), &overrides).expect("case");
    let summary = run_case(&case, Path::new("case.json"), dir).expect("run");
    assert_eq!(summary.status, "completed", "{:?}", summary.error);
}

/// The frames of `skid.pvd`: (time, pad file, drum file), checking parts and order.
fn read_collection(dir: &Path) -> Vec<(f64, String, String)> {
    let text = std::fs::read_to_string(dir.join("fields").join("skid.pvd")).expect("pvd");
    let doc = roxmltree::Document::parse(&text).expect("pvd xml");
    let root = doc.root_element();
    assert_eq!(root.attribute("type"), Some("Collection"));
    let mut by_part: [Vec<(f64, String)>; 2] = [Vec::new(), Vec::new()];
    for node in root.descendants().filter(|n| n.has_tag_name("DataSet")) {
        let time: f64 = node
            .attribute("timestep")
            .expect("timestep")
            .parse()
            .expect("time");
        let part: usize = node.attribute("part").expect("part").parse().expect("part");
        by_part[part].push((time, node.attribute("file").expect("file").to_string()));
    }
    let [pad, drum] = by_part;
    assert_eq!(pad.len(), drum.len());
    assert!(!pad.is_empty());
    pad.into_iter()
        .zip(drum)
        .map(|((t, pad), (t_drum, drum))| {
            assert_eq!(t, t_drum);
            assert!(pad.starts_with("pad_") && drum.starts_with("drum_"));
            (t, pad, drum)
        })
        .collect()
}

/// The last row of `history.csv` at `time`.
fn history_at(dir: &Path, time: f64) -> HashMap<String, f64> {
    let path = dir.join("history.csv");
    let text = std::fs::read_to_string(&path).expect("history");
    let table = CsvTable::new(&text, &path).expect("header");
    let header: Vec<String> = table.header().map(str::to_string).collect();
    let rows: Vec<_> = table.map(|row| row.expect("record")).collect();
    rows.iter()
        .rev()
        .map(|row| {
            header
                .iter()
                .zip(row.fields())
                .filter_map(|(k, v)| Some((k.clone(), v.parse::<f64>().ok()?)))
                .collect::<HashMap<_, _>>()
        })
        .find(|row| (row["time"] - time).abs() <= 1e-9)
        .unwrap_or_else(|| panic!("no history row at t = {time}"))
}

/// Tributary areas of the front-face nodes (reference y = R).
fn tributary_areas(pad: &Vtu, dimension: usize) -> Vec<f64> {
    common::tributary_areas(pad, dimension, PAD_WIDTH, &|n| {
        (pad.points[n][1] - R).abs() < 1e-12
    })
}

/// Checks one pad frame against the history at its time.
fn check_pad(pad: &Vtu, dimension: usize, history: &HashMap<String, f64>) {
    let area = tributary_areas(pad, dimension);
    let pressure = pad.point("contact_pressure", 1);
    let shear = pad.point("contact_shear", 3);
    let status = pad.point("contact_status", 1);
    // Summed pressure x area is the normal force.
    let normal: f64 = pressure.iter().zip(&area).map(|(p, a)| p[0] * a).sum();
    let expected = history["normal_force"];
    assert!(expected > 1000.0, "the pad is pressed: {expected}");
    assert!(
        (normal - expected).abs() <= 1e-6 * expected,
        "normal force {normal} vs {expected}"
    );
    // Pressure only on the front face, where the tributary area is.
    for (p, a) in pressure.iter().zip(&area) {
        assert!(p[0] >= 0.0 && (a > &0.0 || p[0] == 0.0));
    }
    // Status counts match the history's.
    let count = |f: &dyn Fn(f64) -> bool| status.iter().filter(|s| f(s[0])).count() as f64;
    assert_eq!(count(&|s| s > 0.0), history["active_contacts"]);
    assert_eq!(count(&|s| s == 2.0), history["sliding_contacts"]);
    // The friction tractions, in the world frame, give the torque on the drum (whose normal
    // forces are radial): T = -sum (x x f)_z. Only while the drum is free to turn.
    if history["time"] > 0.0 {
        let x = current(pad);
        let torque: f64 = -(0..x.len())
            .map(|n| (x[n][0] * shear[n][1] - x[n][1] * shear[n][0]) * area[n])
            .sum::<f64>();
        let expected = history["friction_torque"];
        assert!(expected.abs() > 1.0, "torque {expected}");
        assert!(
            (torque - expected).abs() <= 1e-6 * expected.abs(),
            "torque {torque} vs {expected}"
        );
    }
    // Back-face nodes move with the plate.
    let u = pad.point("displacement", 3);
    let back: Vec<usize> = (0..pad.points.len())
        .filter(|&n| (pad.points[n][1] - (R + 0.05)).abs() < 1e-12)
        .collect();
    assert!(!back.is_empty());
    let plate = history["plate_displacement"];
    assert!(plate < -1e-4, "the plate moved down: {plate}");
    for n in back {
        assert!(u[n][0].abs() < 1e-15 && u[n][2].abs() < 1e-15);
        assert!(
            (u[n][1] - plate).abs() <= 1e-8 * plate.abs(),
            "{} vs {plate}",
            u[n][1]
        );
    }
    // Stresses: the pad carries the back pressure; J and von Mises agree with the stresses and
    // the displacements.
    let stress = pad.cell("cauchy_stress", 6);
    let j = pad.cell("volume_ratio", 1);
    let mises = pad.cell("mises", 1);
    let mean_syy = stress.iter().map(|s| s[1]).sum::<f64>() / stress.len() as f64;
    assert!(
        (mean_syy + 0.35e6).abs() < 0.1 * 0.35e6,
        "mean sigma_yy {mean_syy}"
    );
    for ((s, j), m) in stress.iter().zip(&j).zip(&mises) {
        let (xx, yy, zz, xy, yz, xz) = (s[0], s[1], s[2], s[3], s[4], s[5]);
        let expected = (0.5 * ((xx - yy).powi(2) + (yy - zz).powi(2) + (zz - xx).powi(2))
            + 3.0 * (xy * xy + yz * yz + xz * xz))
            .sqrt();
        assert!((m[0] - expected).abs() <= 1e-9 * expected);
        assert!((0.9..1.0).contains(&j[0]), "J {}", j[0]);
    }
    if dimension == 2 {
        // One-point quads on rectangles: F = I + grad u at the centre from the corner values.
        for (cell, j) in pad.cells.iter().zip(&j) {
            let p = |k: usize| &pad.points[cell[k]];
            let (a, b) = (p(1)[0] - p(0)[0], p(3)[1] - p(0)[1]);
            let d = |k: usize, i: usize| u[cell[k]][i];
            let grad = |i: usize| {
                (
                    (d(1, i) - d(0, i) + d(2, i) - d(3, i)) / (2.0 * a),
                    (d(3, i) - d(0, i) + d(2, i) - d(1, i)) / (2.0 * b),
                )
            };
            let ((uxx, uxy), (uyx, uyy)) = (grad(0), grad(1));
            let det = (1.0 + uxx) * (1.0 + uyy) - uxy * uyx;
            assert!((det - j[0]).abs() < 1e-9, "J {det} vs {}", j[0]);
        }
    }
}

/// The axial extent of the drum band: the pad's current axial extent with a quarter of it
/// added at both ends, which is the drum's width (1.5 pad widths) but for the pad's axial
/// strain.
fn band(pad: &Vtu) -> [f64; 2] {
    let z: Vec<f64> = current(pad).iter().map(|x| x[2]).collect();
    let lo = z.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = z.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let band = [lo - 0.25 * (hi - lo), hi + 0.25 * (hi - lo)];
    for (end, width) in band.iter().zip([-DRUM_WIDTH, DRUM_WIDTH]) {
        assert!((end - 0.5 * width).abs() < 0.05 * DRUM_WIDTH, "{band:?}");
    }
    band
}

/// Checks one drum frame: radius, rotation by the drum angle, axial extent over the pad,
/// velocity.
fn check_drum(drum: &Vtu, pad: &Vtu, dimension: usize, history: &HashMap<String, f64>) {
    let rings = dimension - 1;
    assert_eq!(drum.points.len(), 144 * rings);
    assert_eq!(drum.cells.len(), 144);
    let (angle, omega) = (history["drum_angle"], history["drum_omega"]);
    let velocity = drum.point("velocity", 3);
    for (i, (p, v)) in drum.points.iter().zip(&velocity).enumerate() {
        assert!(((p[0] * p[0] + p[1] * p[1]).sqrt() - R).abs() < 1e-12);
        let expected = angle + TAU * (i % 144) as f64 / 144.0;
        let phi = p[1].atan2(p[0]);
        let off = (phi - expected).rem_euclid(TAU);
        assert!(off.min(TAU - off) < 1e-8, "point {i}: {phi} vs {expected}");
        let z = if dimension == 2 {
            0.0
        } else {
            band(pad)[i / 144]
        };
        assert!((p[2] - z).abs() < 1e-15, "{} vs {z}", p[2]);
        let expected_v = [-omega * p[1], omega * p[0], 0.0];
        assert!(norm(sub(v, &expected_v)) <= 1e-8 * (omega.abs() * R).max(1e-12));
    }
    let (kind, nodes) = if dimension == 2 {
        (CellType::Line, 2)
    } else {
        (CellType::Quad, 4)
    };
    assert!(drum.types.iter().all(|t| *t == kind));
    assert!(drum.cells.iter().all(|c| c.len() == nodes));
    // Closed: every point starts one cell and ends another.
    let mut uses = vec![0; drum.points.len()];
    for c in &drum.cells {
        for &n in c {
            uses[n] += 1;
        }
    }
    assert!(uses.iter().all(|&u| u == 2));
}

fn frames_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir.join("fields"))
        .expect("fields dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn plane_strain_fields_match_the_history() {
    let dir = tempfile::tempdir().expect("tempdir");
    run(
        CASE_2D,
        &["steps[1].duration=0.002", "output.field_interval=0.001"],
        dir.path(),
    );
    let frames = read_collection(dir.path());
    // The preload's end (replacing the initial state at the same time), then every 1 ms.
    let times: Vec<f64> = frames.iter().map(|f| f.0).collect();
    assert_eq!(times.len(), 3, "{times:?}");
    assert!(times.windows(2).all(|w| w[1] > w[0]), "{times:?}");
    for (t, expected) in times.iter().zip([0.0, 0.001, 0.002]) {
        assert!((t - expected).abs() < 1e-9, "{times:?}");
    }
    // Exactly the listed files, no temporaries.
    let mut listed: Vec<String> = frames
        .iter()
        .flat_map(|(_, p, d)| [p.clone(), d.clone()])
        .chain(["skid.pvd".to_string()])
        .collect();
    listed.sort();
    assert_eq!(frames_in(dir.path()), listed);

    let mut angles = Vec::new();
    for (time, pad_file, drum_file) in &frames {
        let history = history_at(dir.path(), *time);
        let pad = Vtu::read(&dir.path().join("fields").join(pad_file));
        assert_eq!(pad.points.len(), 11 * 2);
        assert_eq!(pad.cells.len(), 10);
        assert!(pad.types.iter().all(|t| *t == CellType::Quad));
        for cell in &pad.cells {
            // Counter-clockwise, as VTK_QUAD wants: positive signed area.
            let p = |k: usize| pad.points[cell[k]];
            let area = 0.5
                * (0..4)
                    .map(|k| p(k)[0] * p((k + 1) % 4)[1] - p((k + 1) % 4)[0] * p(k)[1])
                    .sum::<f64>();
            assert!((area - 0.01 * 0.05).abs() < 1e-15, "area {area}");
        }
        assert!(pad.points.iter().all(|p| p[2] == 0.0));
        check_pad(&pad, 2, &history);
        let drum = Vtu::read(&dir.path().join("fields").join(drum_file));
        check_drum(&drum, &pad, 2, &history);
        angles.push(history["drum_angle"]);
    }
    // The drum visibly turns between frames (about 60 rad/s x 1 ms).
    assert!(angles[0].abs() < 1e-12);
    assert!((angles[2] - angles[1] - 0.06).abs() < 0.01, "{angles:?}");
}

#[test]
fn three_dimensional_fields_use_hexahedra_and_a_drum_band() {
    let dir = tempfile::tempdir().expect("tempdir");
    run(
        CASE_3D,
        &["steps[1].duration=0.0003", "output.field_interval=0.0001"],
        dir.path(),
    );
    let frames = read_collection(dir.path());
    assert_eq!(frames.len(), 4);
    assert!(frames.windows(2).all(|w| w[1].0 > w[0].0));
    for (time, pad_file, drum_file) in &frames {
        let history = history_at(dir.path(), *time);
        let pad = Vtu::read(&dir.path().join("fields").join(pad_file));
        assert_eq!(pad.points.len(), 11 * 2 * 2);
        assert_eq!(pad.cells.len(), 10);
        assert!(pad.types.iter().all(|t| *t == CellType::Hexahedron));
        for cell in &pad.cells {
            // VTK order: the bottom face (0..4), counter-clockwise seen from the top face.
            let p = |k: usize| pad.points[cell[k]];
            let normal = cross(sub(&p(1), &p(0)), sub(&p(3), &p(0)));
            let up = sub(&p(4), &p(0));
            let volume = normal[0] * up[0] + normal[1] * up[1] + normal[2] * up[2];
            assert!(
                (volume - 0.01 * 0.05 * 0.1).abs() < 1e-15,
                "volume {volume}"
            );
            for k in 0..4 {
                assert!(norm(sub(&sub(&p(k + 4), &p(k)), &up)) < 1e-15);
            }
        }
        check_pad(&pad, 3, &history);
        let drum = Vtu::read(&dir.path().join("fields").join(drum_file));
        check_drum(&drum, &pad, 3, &history);
    }
}

#[test]
fn without_field_output_stale_fields_are_removed() {
    let dir = tempfile::tempdir().expect("tempdir");
    let short = "steps[1].duration=0.0002";
    run(
        CASE_2D,
        &[short, "output.field_interval=0.0001"],
        dir.path(),
    );
    assert_eq!(read_collection(dir.path()).len(), 3);
    std::fs::write(dir.path().join("fields/notes.txt"), "mine").expect("write");
    run(CASE_2D, &[short], dir.path());
    assert_eq!(frames_in(dir.path()), vec!["notes.txt".to_string()]);
}

#[test]
fn field_interval_must_be_positive() {
    for bad in ["0", "-1e-3"] {
        let o = vec![format!("output.field_interval={bad}")];
        let err = parse_case(CASE_2D, Path::new("case.json"), &o).expect_err("invalid");
        assert!(err.to_string().contains("output.field_interval"), "{err}");
    }
    let o = vec!["output.frames=3".to_string()];
    assert!(parse_case(CASE_2D, Path::new("case.json"), &o).is_err());
}
