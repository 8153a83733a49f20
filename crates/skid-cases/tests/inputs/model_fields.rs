//! The ParaView field output of model files, read back with the independent reader `vtkio`
//! (`roxmltree` for the collection) and checked against the model file, the run's summary and
//! its final state (the model run again, without outputs): a block pressed on a sliding ground
//! (a plane; 2D and 3D, a static step then a dynamic one) and the Hertz indenter (a cylinder,
//! 2D, a static step).

use std::collections::BTreeSet;
use std::f64::consts::TAU;
use std::path::{Path, PathBuf};

use serde_json::Value;
use skid_cases::model_file::{build, parse_model};
use skid_cases::restart::DEFAULT_RESTART_EVERY;
use skid_cases::{RunSummary, run_file};
use skid_integrator::stepper::{IncrementReport, Observer, run};
use vtkio::model::CellType;

use crate::common;
use crate::common::{Vtu, current, norm, sub, tributary_areas};

fn shipped(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../cases/verification")
        .join(name)
}

fn strings(overrides: &[&str]) -> Vec<String> {
    overrides.iter().map(|s| s.to_string()).collect()
}

/// An observer that keeps nothing.
struct Quiet;

impl<const D: usize> Observer<D> for Quiet {
    fn on_increment(
        &mut self,
        _model: &skid_integrator::Model<D>,
        _report: &IncrementReport<'_>,
    ) -> std::io::Result<()> {
        Ok(())
    }
}

/// A model-file run's outputs: the model as run, its summary and the frames of `skid.pvd`
/// (time and files, by part number).
struct Outputs {
    model: Value,
    summary: Value,
    frames: Vec<(f64, Vec<String>)>,
}

/// Runs the shipped model file `file` with `overrides` into `dir`.
fn run_into(file: &str, overrides: &[&str], dir: &Path) -> Outputs {
    let summary = run_file(
        &shipped(file),
        &strings(overrides),
        Some(dir),
        DEFAULT_RESTART_EVERY,
    )
    .expect("run");
    let RunSummary::Model(summary) = summary else {
        panic!("a model file's summary");
    };
    assert_eq!(summary.status, "completed", "{:?}", summary.error);
    let json = |name: &str| -> Value {
        serde_json::from_str(&std::fs::read_to_string(dir.join(name)).expect(name)).expect(name)
    };
    Outputs {
        model: json("model.json"),
        summary: json("summary.json"),
        frames: collection(dir),
    }
}

/// The frames of `fields/skid.pvd`: each time with its files in part order.
fn collection(dir: &Path) -> Vec<(f64, Vec<String>)> {
    let text = std::fs::read_to_string(dir.join("fields/skid.pvd")).expect("pvd");
    let doc = roxmltree::Document::parse(&text).expect("pvd xml");
    let mut frames: Vec<(f64, Vec<String>)> = Vec::new();
    for node in doc.descendants().filter(|n| n.has_tag_name("DataSet")) {
        let time: f64 = node
            .attribute("timestep")
            .expect("time")
            .parse()
            .expect("t");
        let part: usize = node.attribute("part").expect("part").parse().expect("part");
        let file = node.attribute("file").expect("file").to_string();
        match frames.last_mut() {
            Some((t, files)) if *t == time && part == files.len() => files.push(file),
            _ => {
                assert_eq!(part, 0, "a frame starts with part 0");
                frames.push((time, vec![file]));
            }
        }
    }
    frames
}

/// The final displacement of every node (3 components) of the shipped model file `file` with
/// `overrides`, run again without outputs.
fn final_displacements<const D: usize>(file: &str, overrides: &[&str]) -> Vec<[f64; 3]> {
    let path = shipped(file);
    let text = std::fs::read_to_string(&path).expect("model file");
    let spec = parse_model(&text, &path, &strings(overrides)).expect("model");
    let scene = build::<D>(&spec).expect("scene");
    let (_, result) = run(&scene.model, &scene.steps, &scene.settings, &mut Quiet);
    let state = result.expect("run");
    (0..scene.model.part().mesh.nodes.len())
        .map(|n| {
            let u = scene.model.dofs().node_displacement(&state.x, n);
            std::array::from_fn(|i| if i < D { u[i] } else { 0.0 })
        })
        .collect()
}

fn numbers(value: &Value) -> Vec<f64> {
    value
        .as_array()
        .expect("array")
        .iter()
        .map(|v| v.as_f64().expect("number"))
        .collect()
}

/// The body `name` of the summary: (displacement, velocity), 3 components each.
fn body_motion(summary: &Value, name: &str) -> ([f64; 3], [f64; 3]) {
    let body = summary["bodies"]
        .as_array()
        .expect("bodies")
        .iter()
        .find(|b| b["name"] == name)
        .expect("body");
    let three = |v: &Value| {
        let v = numbers(v);
        [v[0], v[1], v.get(2).copied().unwrap_or(0.0)]
    };
    (three(&body["displacement"]), three(&body["velocity"]))
}

/// Checks the part's file of the last frame: the mesh of the model file at its reference
/// coordinates, the final displacements, and contact tractions that integrate to the pair's
/// resultants. Returns the part's grid.
fn check_part(dir: &Path, out: &Outputs, dimension: usize, u: &[[f64; 3]]) -> Vtu {
    let (_, files) = out.frames.last().expect("a frame");
    let part = &out.model["part"];
    let name = part["name"].as_str().expect("name");
    assert_eq!(files[0], format!("{name}_{:04}.vtu", out.frames.len() - 1));
    let grid = Vtu::read(&dir.join("fields").join(&files[0]));
    let nodes: Vec<Vec<f64>> = part["nodes"]
        .as_array()
        .expect("nodes")
        .iter()
        .map(numbers)
        .collect();
    let cells: Vec<Vec<usize>> = part["elements"]
        .as_array()
        .expect("blocks")
        .iter()
        .flat_map(|b| b["connectivity"].as_array().expect("connectivity").clone())
        .map(|c| numbers(&c).iter().map(|&n| n as usize).collect())
        .collect();
    assert_eq!(grid.points.len(), nodes.len());
    assert_eq!(grid.cells, cells);
    let kind = if dimension == 2 {
        CellType::Quad
    } else {
        CellType::Hexahedron
    };
    assert!(grid.types.iter().all(|t| *t == kind));
    for (p, x) in grid.points.iter().zip(&nodes) {
        assert_eq!(&p[..dimension], &x[..], "reference coordinates");
    }
    // the displacements are the final state's, to the bit
    let displacement = grid.point("displacement", 3);
    for (n, d) in displacement.iter().enumerate() {
        assert_eq!(d[..], u[n], "node {n}");
    }
    // one stress tensor, volume ratio and von Mises stress per cell
    let stress = grid.cell("cauchy_stress", 6);
    let mises = grid.cell("mises", 1);
    assert!(stress.iter().flatten().all(|s| s.is_finite()));
    assert!(mises.iter().all(|m| m[0] >= 0.0));
    let j = grid.cell("volume_ratio", 1);
    assert!(j.iter().all(|j| (0.5..1.5).contains(&j[0])), "{j:?}");
    // pressure x tributary area over the pair's candidates is the pair's normal force
    let pair = &out.summary["pairs"][0];
    let slave = &out.model["contact"][0]["slave"]["name"];
    let candidates: BTreeSet<usize> = numbers(&part["node_sets"][slave.as_str().expect("set")])
        .iter()
        .map(|&n| n as usize)
        .collect();
    let thickness = part["section"]["thickness"].as_f64().unwrap_or(1.0);
    let area = tributary_areas(&grid, dimension, thickness, &|n| candidates.contains(&n));
    let pressure = grid.point("contact_pressure", 1);
    let normal: f64 = pressure.iter().zip(&area).map(|(p, a)| p[0] * a).sum();
    let expected = pair["normal_force"].as_f64().expect("normal force");
    assert!(expected > 1.0, "pressed: {expected}");
    assert!(
        (normal - expected).abs() <= 1e-9 * expected,
        "normal force {normal} vs {expected}"
    );
    for (n, p) in pressure.iter().enumerate() {
        assert!(p[0] >= 0.0 && (candidates.contains(&n) || p[0] == 0.0));
    }
    let status = grid.point("contact_status", 1);
    let count = |f: &dyn Fn(f64) -> bool| status.iter().filter(|s| f(s[0])).count() as u64;
    assert_eq!(
        count(&|s| s > 0.0),
        pair["active"].as_u64().expect("active")
    );
    assert_eq!(
        count(&|s| s == 2.0),
        pair["sliding"].as_u64().expect("sliding")
    );
    // the friction traction along the first surface direction (x for the ground and the
    // indenter at the top) integrates to the pair's first tangential force
    let shear = grid.point("contact_shear", 3);
    let along: f64 = shear.iter().zip(&area).map(|(s, a)| s[0] * a).sum();
    let expected = pair["tangential_force"][0]
        .as_f64()
        .expect("tangential force");
    assert!(
        (along - expected).abs() <= 1e-9 * pair["normal_force"].as_f64().unwrap_or(1.0),
        "tangential force {along} vs {expected}"
    );
    grid
}

/// Range `[lo - m, hi + m]`, `m` a quarter of `hi - lo`, of a coordinate over the part's
/// current nodes.
fn drawn_span(part: &Vtu, axis: usize) -> [f64; 2] {
    let x: Vec<f64> = current(part).iter().map(|p| p[axis]).collect();
    let lo = x.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    [lo - 0.25 * (hi - lo), hi + 0.25 * (hi - lo)]
}

/// The body's file of the last frame, with every point moving at the body's velocity.
fn body_grid(dir: &Path, out: &Outputs, name: &str) -> Vtu {
    let (_, files) = out.frames.last().expect("a frame");
    assert_eq!(files.len(), 2, "the part and the one body with a surface");
    assert_eq!(files[1], format!("{name}_{:04}.vtu", out.frames.len() - 1));
    let grid = Vtu::read(&dir.join("fields").join(&files[1]));
    let (_, velocity) = body_motion(&out.summary, name);
    for v in grid.point("velocity", 3) {
        assert!(norm(sub(&v, &velocity)) <= 1e-12 * (1.0 + norm(velocity)));
    }
    grid
}

/// The block on the sliding ground: frames at the end of the press (replacing the initial
/// state) and every millisecond of the slide; the ground drawn as the plane y = 0 under the
/// block's current extent with a quarter of it as margin, moving at the ground's velocity.
fn sliding_ground<const D: usize>(file: &str) {
    let tmp = tempfile::tempdir().expect("tempdir");
    let overrides = ["steps[1].duration=0.002", "output.field_interval=0.001"];
    let out = run_into(file, &overrides, tmp.path());
    let times: Vec<f64> = out.frames.iter().map(|f| f.0).collect();
    assert_eq!(times.len(), 3, "{times:?}");
    for (t, expected) in times.iter().zip([0.0, 0.001, 0.002]) {
        assert!((t - expected).abs() < 1e-9, "{times:?}");
    }
    let u = final_displacements::<D>(file, &overrides);
    let part = check_part(tmp.path(), &out, D, &u);
    let ground = body_grid(tmp.path(), &out, "ground");
    let (_, velocity) = body_motion(&out.summary, "ground");
    assert!(velocity[0] > 0.1, "the ground slides: {velocity:?}");
    let x = drawn_span(&part, 0);
    if D == 2 {
        assert_eq!(ground.types, [CellType::Line]);
        let mut ends: Vec<f64> = ground.points.iter().map(|p| p[0]).collect();
        ends.sort_by(f64::total_cmp);
        for (end, expected) in ends.iter().zip(x) {
            assert!((end - expected).abs() < 1e-15, "{ends:?} vs {x:?}");
        }
        // the outward normal (+y) is the segment's direction turned clockwise
        let [a, b] = [ground.points[0], ground.points[1]];
        assert!(b[0] < a[0], "runs along -x");
    } else {
        assert_eq!(ground.types, [CellType::Quad]);
        let z = drawn_span(&part, 2);
        for p in &ground.points {
            assert!(x.iter().any(|e| (p[0] - e).abs() < 1e-15), "{p:?} vs {x:?}");
            assert!(z.iter().any(|e| (p[2] - e).abs() < 1e-15), "{p:?} vs {z:?}");
        }
        // counter-clockwise seen from above (+y, the outward normal)
        let p = &ground.points;
        let normal = common::cross(sub(&p[1], &p[0]), sub(&p[3], &p[0]));
        assert!(normal[1] > 0.0, "{normal:?}");
    }
    assert!(ground.points.iter().all(|p| p[1] == 0.0), "on y = 0");
}

#[test]
fn plane_strain_model_file_fields_match_the_final_state() {
    sliding_ground::<2>("2d-block-on-sliding-ground.json");
}

#[test]
fn three_dimensional_model_file_fields_match_the_final_state() {
    sliding_ground::<3>("3d-block-on-sliding-ground.json");
}

/// The Hertz indenter: one frame (a static step takes no time), the cylinder drawn as a closed
/// polyline of 144 lines at radius R about its final reference point, pressed down.
#[test]
fn a_cylinder_is_drawn_about_its_final_reference_point() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let file = "2d-hertz-n4.json";
    let overrides = ["output.field_interval=1"];
    let out = run_into(file, &overrides, tmp.path());
    assert_eq!(out.frames.len(), 1);
    let u_final = final_displacements::<2>(file, &overrides);
    check_part(tmp.path(), &out, 2, &u_final);
    let indenter = body_grid(tmp.path(), &out, "indenter");
    let (u, _) = body_motion(&out.summary, "indenter");
    assert!(u[1] < -1e-5, "pressed down: {u:?}");
    let reference = numbers(&out.model["rigid_bodies"][0]["reference_point"]);
    let centre = [reference[0] + u[0], reference[1] + u[1], 0.0];
    assert_eq!(indenter.points.len(), 144);
    assert_eq!(indenter.cells.len(), 144);
    assert!(indenter.types.iter().all(|t| *t == CellType::Line));
    for (k, p) in indenter.points.iter().enumerate() {
        let r = sub(p, &centre);
        assert!(
            (norm(r) - 0.05).abs() < 1e-15,
            "point {k}: radius {}",
            norm(r)
        );
        // point k at 2 pi k / 144 from +x (the indenter does not turn)
        let off = (r[1].atan2(r[0]) - TAU * k as f64 / 144.0).rem_euclid(TAU);
        assert!(off.min(TAU - off) < 1e-12, "point {k}");
        assert_eq!(indenter.cells[k], [k, (k + 1) % 144]);
    }
}

/// A floor of three rigid lines is drawn as its polyline: its four points in the world frame
/// (the floor does not move), three lines, the outside on the right of each.
#[test]
fn a_polyline_is_drawn_as_its_lines() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let file = "2d-block-dragged-on-lines-deck.inp";
    let out = run_into(file, &["output.field_interval=1"], tmp.path());
    let ground = body_grid(tmp.path(), &out, "ground");
    let expected = [[2.0, 0.0], [0.0055, 0.0], [-0.0025, 0.0], [-2.0, 0.0]];
    assert_eq!(ground.points.len(), expected.len());
    for (p, e) in ground.points.iter().zip(expected) {
        assert_eq!([p[0], p[1], p[2]], [e[0], e[1], 0.0]);
    }
    assert_eq!(ground.cells, [[0, 1], [1, 2], [2, 3]]);
    assert!(ground.types.iter().all(|t| *t == CellType::Line));
}

/// Field output names files after the part and the drawn bodies: a name that is no file name,
/// or two names of the same files, are refused with the field at fault, and only when field
/// output is asked for.
#[test]
fn field_file_names_must_be_file_names_and_distinct() {
    let file = "2d-block-on-sliding-ground.json";
    let path = shipped(file);
    let text = std::fs::read_to_string(&path).expect("model file");
    let scene = |overrides: &[&str]| {
        let spec = parse_model(&text, &path, &strings(overrides)).expect("model");
        build::<2>(&spec).map(|_| ())
    };
    let fields = "output.field_interval=0.001";
    let err = scene(&["part.name=my block", fields]).expect_err("not a file name");
    assert_eq!(err.field, "part.name");
    assert!(err.message.contains("field output"), "{}", err.message);
    let err = scene(&["part.name=Ground", fields]).expect_err("the ground's files");
    assert_eq!(err.field, "rigid_bodies[0].name");
    assert!(err.message.contains("part.name"), "{}", err.message);
    // the plate carries no surface, so it has no files
    scene(&["part.name=plate", fields]).expect("no collision");
    scene(&["part.name=my block"]).expect("no field output, no file names");
}
