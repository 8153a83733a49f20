//! Analytical surfaces beyond the drum's: surfaces of revolution (the 3D drum as the revolution
//! of the straight profile `r = R` spins down as the analytical cylinder does, its slip measured
//! in lengths in the tangent plane of each increment's start; the pushed block slides round a
//! revolved disc as on the plane) and
//! extruded profiles (the pushed block on an extruded straight profile slides as on the plane);
//! a deck's revolved profile of lines that is no cylinder, and its `TYPE=CYLINDER` profile of
//! lines that is no plane through the reference node, read to them (profiles in the body frame,
//! listed as a polyline's), which the deck writer writes back; their `CIRCL` pieces are arcs
//! (the 2D drum as four quarter circles spins down as the circle); inward closed profiles,
//! arcs whose ends miss their circle and arcs of 180 degrees or more are refused. An open
//! surface ends at its edge: the pushed block slides off an extruded floor and off a floor of
//! rigid elements, its nodes leaving the surface as they pass the edge.

use std::path::{Path, PathBuf};

use crate::deck_text::{assert_refused_at, read_deck_text};

use crate::common::Vtu;
use vtkio::model::CellType;

use skid_cases::csv_out::CsvTable;
use skid_cases::deck::write::write_deck;
use skid_cases::drum::model_spec;
use skid_cases::load_case;
use skid_cases::model_file::parse_model;
use skid_cases::model_spec::{ChartSpec, ModelSpec, RigidSurfaceSpec};
use skid_cases::runner::run_model;

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(path)
}

/// The drum's omega over the spin-down of `model`, run into `dir`.
fn omega(model: &ModelSpec, dir: &Path) -> Vec<f64> {
    let summary = run_model(model, Path::new("drum.json"), dir).expect("runs");
    assert!(summary.error.is_none(), "{:?}", summary.error);
    let path = dir.join("history.csv");
    let text = std::fs::read_to_string(&path).expect("history");
    let table = CsvTable::new(&text, &path).expect("table");
    let column = table.column("drum.omega").expect("drum.omega");
    table
        .map(|row| row.expect("row").number::<f64>(column).expect("omega"))
        .collect()
}

#[test]
fn the_drum_as_a_revolved_line_spins_down_as_the_cylinder() {
    let case = load_case(
        &repo("cases/drum/3d-analytic.json"),
        &["steps[1].duration=0.01".to_string()],
    )
    .expect("case");
    let cylinder = model_spec(&case).expect("model");
    let mut revolved = cylinder.clone();
    let drum = revolved
        .rigid_bodies
        .iter_mut()
        .find(|b| b.name == "drum")
        .expect("drum");
    let Some(RigidSurfaceSpec::Cylinder { radius, axis }) = drum.surface.clone() else {
        panic!("{:?}", drum.surface);
    };
    drum.surface = Some(RigidSurfaceSpec::Revolution {
        axis,
        profile: vec![[radius, -1.0], [radius, 1.0]],
        centres: Vec::new(),
        closed: false,
        radius: None,
    });
    revolved.output.field_interval = Some(0.01);
    let dir = tempfile::tempdir().expect("tempdir");
    let (a, b) = (
        omega(&cylinder, tempfile::tempdir().expect("tempdir").path()),
        omega(&revolved, dir.path()),
    );
    assert!(a.len() > 100, "{} rows", a.len());
    // The same gap, normal, curvature and discrete gradient; the slip differs: the cylinder's
    // is the increment of its arc length, the revolution's is measured in the tangent plane of
    // the increment's start point, which the drum turns by 6 mrad in an increment (friction
    // along the start's tangent: 4e-3 rad/s apart after 10 ms, measured).
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert!(
            (x - y).abs() <= 1e-4 * 60.0,
            "omega {x} on the cylinder, {y} revolved"
        );
    }
    assert!(a[a.len() - 1] < 59.0, "the drum slows: {}", a[a.len() - 1]);
    // drawn as one band of quadrilaterals between the profile's two rings, on the cylinder
    let fields = dir.path().join("fields");
    let mut drawn: Vec<PathBuf> = std::fs::read_dir(&fields)
        .expect("fields")
        .map(|e| e.expect("entry").path())
        .filter(|p| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with("drum_"))
        })
        .collect();
    drawn.sort();
    let drum = Vtu::read(drawn.last().expect("a drum frame"));
    assert_eq!((drum.points.len(), drum.cells.len()), (288, 144));
    assert!(drum.types.iter().all(|t| *t == CellType::Quad));
    for p in &drum.points {
        let r = (p[0] * p[0] + p[1] * p[1]).sqrt();
        assert!(
            (r - radius).abs() < 1e-12 && (p[2].abs() - 1.0).abs() < 1e-12,
            "{p:?}"
        );
    }
}

/// The 2D drum as a closed polyline of four quarter circles about its centre (its arcs'
/// gap, normal and curvature those of the circle) brakes as the analytical circle does: the
/// sliding deceleration over the first 30 ms within 0.1 % (measured 0.042 %: the circle's rows
/// take the secant normal over the increment, the arcs' the end-point normal with the secant
/// rotation column, two exact-work schemes that differ by a discretisation error). A deck's
/// `SEGMENTS` profile of lines and arcs reads to such a polyline, written back as a profile.
#[test]
fn the_drum_as_a_polyline_of_arcs_spins_down_as_the_circle() {
    let case = load_case(
        &repo("cases/drum/2d-analytic.json"),
        &["steps[1].duration=0.03".to_string()],
    )
    .expect("case");
    let circle = model_spec(&case).expect("model");
    let mut arcs = circle.clone();
    let drum = arcs
        .rigid_bodies
        .iter_mut()
        .find(|b| b.name == "drum")
        .expect("drum");
    let Some(RigidSurfaceSpec::Cylinder { radius: r, .. }) = drum.surface.clone() else {
        panic!("{:?}", drum.surface);
    };
    // counter-clockwise: contacted from outside
    drum.surface = Some(RigidSurfaceSpec::Polyline {
        points: vec![[r, 0.0], [0.0, r], [-r, 0.0], [0.0, -r]],
        centres: vec![Some([0.0, 0.0]); 4],
        closed: true,
    });
    let (a, b) = (
        omega(&circle, tempfile::tempdir().expect("tempdir").path()),
        omega(&arcs, tempfile::tempdir().expect("tempdir").path()),
    );
    assert_eq!(a.len(), b.len());
    // least-squares slope of omega over the rows after the preload's (dt = 0.1 ms)
    let deceleration = |omega: &[f64]| {
        let rows = &omega[omega.len() - 300..];
        let n = rows.len() as f64;
        let (mean_t, mean_w) = ((n - 1.0) / 2.0, rows.iter().sum::<f64>() / n);
        let (mut sxy, mut sxx) = (0.0, 0.0);
        for (k, w) in rows.iter().enumerate() {
            sxy += (k as f64 - mean_t) * (w - mean_w);
            sxx += (k as f64 - mean_t).powi(2);
        }
        -sxy / sxx / 1e-4
    };
    let (da, db) = (deceleration(&a), deceleration(&b));
    assert!((da - 600.0).abs() < 6.0, "{da}");
    assert!(((db - da) / da).abs() < 1e-3, "{db} against {da}");

    let text = std::fs::read_to_string(repo("cases/inp/2d-analytic.inp")).expect("deck");
    let start = text.find("*SURFACE, NAME=drum").expect("drum surface");
    let end = start + text[start..].find("*RIGID BODY").expect("rigid body");
    // the drum's bottom half as a clockwise arc pair, its top half a flat lid
    let profile = format!(
        "*SURFACE, NAME=drum, TYPE=SEGMENTS\nSTART, {r}, 0.\nCIRCL, 0., {m}, 0., 0.\n\
         CIRCL, {m}, 0., 0., 0.\nLINE, {r}, 0.\n",
        m = -r
    );
    let deck = format!("{}{profile}{}", &text[..start], &text[end..]);
    let model = read_deck_text(&deck).expect("profile of arcs");
    let drum = model
        .rigid_bodies
        .iter()
        .find(|b| b.name == "drum")
        .expect("drum");
    assert_eq!(
        drum.surface,
        Some(RigidSurfaceSpec::Polyline {
            points: vec![[-r, 0.0], [0.0, -r], [r, 0.0]],
            centres: vec![Some([0.0, 0.0]), Some([0.0, 0.0]), None],
            closed: true,
        })
    );
    let written = write_deck(&model, &Default::default()).expect("written");
    assert!(written.contains("TYPE=SEGMENTS"), "{written}");
    let read = read_deck_text(&written).expect("read back");
    assert_eq!(read.rigid_bodies, model.rigid_bodies);
}

/// The surface of the rigid body `ground`.
fn ground(model: &ModelSpec) -> Option<&RigidSurfaceSpec> {
    let body = model.rigid_bodies.iter().find(|b| b.name == "ground");
    body.expect("ground").surface.as_ref()
}

/// The 3D verification block's ground replaced by an analytical surface of revolution.
fn deck_with(surface: &str) -> String {
    let deck = std::fs::read_to_string(repo(
        "cases/verification/3d-block-pushed-on-facets-deck.inp",
    ))
    .expect("deck");
    let start = deck.find("*NODE\n41,").expect("facet nodes");
    let end = deck.find("*RIGID BODY, REF NODE=ground").expect("ground");
    let end = end + deck[end..].find('\n').expect("line end") + 1;
    format!("{}{surface}\n{}", &deck[..start], &deck[end..])
}

#[test]
fn a_revolved_profile_of_lines_is_a_surface_of_revolution() {
    // a roller about x through the ground's reference node (0, 0, 0): r = 0.5 with a cone
    // up to r = 0.6, traversed from high to low local z (outward normal +r)
    let surface = "*SURFACE, NAME=ground, TYPE=REVOLUTION\n\
                   0.0, 0.0, 0.0, 1.0, 0.0, 0.0\n\
                   START, 0.6, 2.0\nLINE, 0.6, 1.0\nLINE, 0.5, 0.5\nLINE, 0.5, -2.0\n\
                   *RIGID BODY, REF NODE=ground, ANALYTICAL SURFACE=ground";
    let model = read_deck_text(&deck_with(surface)).expect("revolution");
    assert_eq!(
        ground(&model),
        Some(&RigidSurfaceSpec::Revolution {
            axis: [1.0, 0.0, 0.0],
            profile: vec![[0.5, -2.0], [0.5, 0.5], [0.6, 1.0], [0.6, 2.0]],
            centres: Vec::new(),
            closed: false,
            radius: None,
        })
    );
    let written = write_deck(&model, &Default::default()).expect("written");
    assert!(written.contains("TYPE=REVOLUTION"), "{written}");
    let read = read_deck_text(&written).expect("read back");
    assert_eq!(read.rigid_bodies, model.rigid_bodies);

    let at = "*SURFACE, NAME=ground, TYPE=REVOLUTION";
    // the cone replaced by a rounded shoulder: a clockwise quarter circle of radius 0.1 about
    // (0.5, 1.0), convex (the deck's outward normal is the travel turned counter-clockwise)
    let fillet = surface.replace(
        "LINE, 0.5, 0.5\nLINE, 0.5, -2.0",
        "CIRCL, 0.5, 0.9, 0.5, 1.0\nLINE, 0.5, -2.0",
    );
    let model = read_deck_text(&deck_with(&fillet)).expect("fillet");
    assert_eq!(
        ground(&model),
        Some(&RigidSurfaceSpec::Revolution {
            axis: [1.0, 0.0, 0.0],
            profile: vec![[0.5, -2.0], [0.5, 0.9], [0.6, 1.0], [0.6, 2.0]],
            centres: vec![None, Some([0.5, 1.0]), None],
            closed: false,
            radius: None,
        })
    );
    let written = write_deck(&model, &Default::default()).expect("written");
    assert!(written.contains("CIRCL, 0.5, 0.9, 0.5, 1.0"), "{written}");
    let read = read_deck_text(&written).expect("read back");
    assert_eq!(read.rigid_bodies, model.rigid_bodies);
    let arc = surface.replace("LINE, 0.5, 0.5", "CIRCL, 0.5, 0.5, 0.5, 1.0");
    assert_refused_at(&deck_with(&arc), at, "lie at");
    // a closed square profile walked the inward way round
    let inward = surface.replace(
        "START, 0.6, 2.0\nLINE, 0.6, 1.0\nLINE, 0.5, 0.5\nLINE, 0.5, -2.0",
        "START, 0.5, 1.0\nLINE, 0.6, 1.0\nLINE, 0.6, 2.0\nLINE, 0.5, 2.0\nLINE, 0.5, 1.0",
    );
    assert_refused_at(&deck_with(&inward), at, "faces inwards");
}

#[test]
fn a_profile_of_lines_swept_along_its_generator_is_an_extrusion() {
    // a step down along x, swept along z through the ground's reference node: local x =
    // global x, generator z, local y = z x x = y; traversed towards +x so that its normal
    // (travel turned counter-clockwise) points up
    let surface = "*SURFACE, NAME=ground, TYPE=CYLINDER\n\
                   0.0, 0.0, 0.0, 1.0, 0.0, 0.0\n0.0, 0.0, 1.0\n\
                   START, -2.0, 0.0\nLINE, 0.015, 0.0\nLINE, 0.02, -0.001\nLINE, 2.0, -0.001\n\
                   *RIGID BODY, REF NODE=ground, ANALYTICAL SURFACE=ground";
    let model = read_deck_text(&deck_with(surface)).expect("extrusion");
    assert_eq!(
        ground(&model),
        Some(&RigidSurfaceSpec::Extrusion {
            axis: [0.0, 0.0, 1.0],
            reference: [1.0, 0.0, 0.0],
            profile: vec![[2.0, -0.001], [0.02, -0.001], [0.015, 0.0], [-2.0, 0.0]],
            centres: Vec::new(),
            closed: false,
        })
    );
    let written = write_deck(&model, &Default::default()).expect("written");
    let read = read_deck_text(&written).expect("read back");
    assert_eq!(read.rigid_bodies, model.rigid_bodies);
    let arc = surface.replace("LINE, 0.015, 0.0", "CIRCL, 0.015, 0.0, -0.9925, 0.0");
    assert_refused_at(
        &deck_with(&arc),
        "*SURFACE, NAME=ground, TYPE=CYLINDER",
        "180 degrees or more",
    );
}

/// The pushed block of `3d-block-pushed-on-flat.json` (30 ms of it) and the same scene with
/// its ground's surface replaced by `surface` and its reference point moved to `reference`.
fn pushed_block_on(surface: RigidSurfaceSpec, reference: [f64; 3]) -> (ModelSpec, ModelSpec) {
    let path = repo("cases/verification/3d-block-pushed-on-flat.json");
    let text = std::fs::read_to_string(&path).expect("scene");
    let plane = parse_model(&text, &path, &["steps[0].duration=0.03".to_string()]).expect("model");
    let mut other = plane.clone();
    let ground = other
        .rigid_bodies
        .iter_mut()
        .find(|b| b.name == "ground")
        .expect("ground");
    assert!(matches!(
        ground.surface,
        Some(RigidSurfaceSpec::Plane { .. })
    ));
    ground.surface = Some(surface);
    ground.reference_point = reference.to_vec();
    (plane, other)
}

/// The history column `name` of `model`'s run.
fn history_column(model: &ModelSpec, name: &str) -> Vec<f64> {
    let dir = tempfile::tempdir().expect("tempdir");
    let summary = run_model(model, Path::new("block.json"), dir.path()).expect("runs");
    assert!(summary.error.is_none(), "{:?}", summary.error);
    let path = dir.path().join("history.csv");
    let text = std::fs::read_to_string(&path).expect("history");
    let table = CsvTable::new(&text, &path).expect("table");
    let c = table.column(name).expect("column");
    table
        .map(|row| row.expect("row").number::<f64>(c).expect("number"))
        .collect()
}

/// The pushed block of `3d-block-pushed-on-flat.json` on the extrusion of a straight profile
/// of two segments instead of the plane y = 0: the same run to round-off.
#[test]
fn the_pushed_block_slides_on_an_extruded_line_as_on_the_plane() {
    let (plane, extruded) = pushed_block_on(
        RigidSurfaceSpec::Extrusion {
            axis: [0.0, 0.0, 1.0],
            reference: [1.0, 0.0, 0.0],
            // walked towards -x: the outside (on the right) is up
            profile: vec![[2.0, 0.0], [0.0025, 0.0], [-2.0, 0.0]],
            centres: Vec::new(),
            closed: false,
        },
        [0.0, 0.0, 0.0],
    );
    // the extrusion's first coordinate runs along -x, the plane's along +x
    follows_the_plane(&plane, &extruded, |x| x.abs());
}

/// Checks that the run of `other` follows that of `plane` in the plate's travel and the
/// friction force, read through `seen`, to 1e-9 of each one's largest magnitude.
fn follows_the_plane(plane: &ModelSpec, other: &ModelSpec, seen: fn(f64) -> f64) {
    for name in ["plate.u_x", "block-ground.tangential_force_1"] {
        let (a, b) = (history_column(plane, name), history_column(other, name));
        assert_eq!(a.len(), b.len());
        let scale = a.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        assert!(scale > 0.0, "{name} moves");
        for (x, y) in a.iter().zip(&b) {
            assert!(
                (seen(*x) - seen(*y)).abs() <= 1e-9 * scale,
                "{name}: {x} against {y}"
            );
        }
    }
}

/// The pushed block on the plane y = 0 given as two triangles whose plane chart is tilted by
/// atan(1/2) about z against them: its first coordinate's increments are `cos a = 0.894` times
/// the lengths slid along x. Slip is measured in lengths in the tangent plane of each
/// increment's start point, so the block slides as on the plane (weighed by the chart's
/// coordinates, friction would be 0.894 mu N and the block would move further).
#[test]
fn the_pushed_block_slides_on_a_mesh_with_a_tilted_chart_as_on_the_plane() {
    let (plane, mesh) = pushed_block_on(
        RigidSurfaceSpec::Triangles {
            vertices: vec![
                [-2.0, 0.0, -0.05],
                [-2.0, 0.0, 0.05],
                [2.0, 0.0, 0.05],
                [2.0, 0.0, -0.05],
            ],
            // counter-clockwise seen from +y
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            chart: ChartSpec::Plane {
                normal: [0.5, 1.0, 0.0],
                tangent: [1.0, 0.0, 0.0],
            },
        },
        [0.0, 0.0, 0.0],
    );
    follows_the_plane(&plane, &mesh, |x| x);
}

/// The pushed block on an extruded floor that ends at x = 2 cm, 1 cm ahead of the block: the
/// block slides past the floor's edge, and each node that has passed it leaves the surface
/// (beyond an open profile's end a point is off the surface, whichever side of the floor's
/// level it stands). (Signed by the floor's normal alone, the nodes past the edge count as
/// penetrating the floor and are caught on it: the run fails.)
#[test]
fn the_pushed_block_leaves_an_extruded_floor_past_its_edge() {
    let (_, floor) = pushed_block_on(
        RigidSurfaceSpec::Extrusion {
            axis: [0.0, 0.0, 1.0],
            reference: [1.0, 0.0, 0.0],
            // walked towards -x: the outside (on the right) is up
            profile: vec![[0.02, 0.0], [-2.0, 0.0]],
            centres: Vec::new(),
            closed: false,
        },
        [0.0, 0.0, 0.0],
    );
    leaves_the_floor_past(&floor, 0.02);
}

/// The pushed block of the facet deck (its flat of R3D4 and R3D3 rigid elements) with the flat
/// ending at x = 2 cm, for 30 ms: past the mesh's boundary the nodes leave the surface.
#[test]
fn the_pushed_block_leaves_a_mesh_floor_past_its_boundary() {
    let deck = std::fs::read_to_string(repo(
        "cases/verification/3d-block-pushed-on-facets-deck.inp",
    ))
    .expect("deck");
    let mut cut = deck.replace("0.0005, 0.04", "0.0005, 0.03");
    // the flat's vertices at x = 2 m: node number and z
    for (node, z) in [(44, "-0.05"), (48, "0.001"), (52, "0.05")] {
        let line = |x: &str| format!("\n{node}, {x}, 0.0, {z}\n");
        assert!(cut.contains(&line("2.0")), "node {node}");
        cut = cut.replace(&line("2.0"), &line("0.02"));
    }
    let model = read_deck_text(&cut).expect("deck");
    leaves_the_floor_past(&model, 0.02);
}

/// Checks the run of `model`, the pushed block on a floor that ends at `x = edge` ahead of it:
/// once the block is pressed, the closed contacts are those of the node columns still over the
/// floor, three per column, all of them sliding once the block moves; the run sees the block on
/// the floor, partly past its edge and wholly past it.
fn leaves_the_floor_past(model: &ModelSpec, edge: f64) {
    let column = |name: &str| history_column(model, name);
    let (time, u, active, sliding) = (
        column("time"),
        column("plate.u_x"),
        column("block-ground.active"),
        column("block-ground.sliding"),
    );
    // the columns of bottom nodes, at x0 = -1, -0.5, 0, 0.5 and 1 cm
    let columns = [-0.01, -0.005, 0.0, 0.005, 0.01];
    let mut compared = [0; 6];
    for (((t, u), active), sliding) in time.iter().zip(&u).zip(&active).zip(&sliding) {
        // once pressed (the press ramps up over 10 ms); the block moves as a whole, and a
        // column within 1 mm of the edge could go either way
        if *t < 0.01 || columns.iter().any(|x0| (x0 + u - edge).abs() < 1e-3) {
            continue;
        }
        let over = columns.iter().filter(|x0| *x0 + u < edge).count();
        assert_eq!(*active, 3.0 * over as f64, "u_x = {u}");
        if over > 0 && *u > 1e-3 {
            assert_eq!(sliding, active, "u_x = {u}");
        }
        compared[over] += 1;
    }
    assert!(compared[5] > 0 && compared[0] > 0, "{compared:?}");
    assert!(compared[1..5].iter().sum::<usize>() > 0, "{compared:?}");
}

/// The pushed block on the plane y = 0 given as a disc of revolution about the vertical axis
/// 0.05 m behind it (its chart radius 1 m, twenty times the block's distance from the axis):
/// the block is pushed round the axis, so friction acts along the circumferential coordinate,
/// whose increments are lengths only at the chart radius. Slip is measured in the tangent plane
/// of each increment's start point, so the block slides as on the plane: the same motion, and
/// the same contacts sliding (friction weighed by the angle's increments, 20 times mu N, would
/// hold the block under its 9 N push).
#[test]
fn the_pushed_block_slides_round_a_revolved_disc_as_on_the_plane() {
    slides_on_a_disc_as_on_the_plane(0.001, [0.0, 0.0, -0.05]);
}

/// The pushed block on a disc that reaches the axis, with the axis through the middle node of
/// the block's bottom face: that node's projection is taken on the axis, the others' round it,
/// and the block slides as on the plane.
#[test]
fn a_node_on_the_axis_of_a_revolved_disc_slides_as_on_the_plane() {
    slides_on_a_disc_as_on_the_plane(0.0, [0.0, 0.0, 0.0]);
}

/// The pushed block on the plane and on the disc of revolution of the profile from r = 1 in
/// to `inner` about the vertical axis through `reference` (the ground's reference point): the
/// same motion to 1e-8 of its travel (each run converges its contacts to 1e-8 of the model
/// size), and the same contacts sliding.
fn slides_on_a_disc_as_on_the_plane(inner: f64, reference: [f64; 3]) {
    let (plane, disc) = pushed_block_on(
        RigidSurfaceSpec::Revolution {
            axis: [0.0, 1.0, 0.0],
            // walked towards the axis: the outside (on the right) is up
            profile: vec![[1.0, 0.0], [inner, 0.0]],
            centres: Vec::new(),
            closed: false,
            radius: None,
        },
        reference,
    );
    let (a, b) = (
        history_column(&plane, "plate.u_x"),
        history_column(&disc, "plate.u_x"),
    );
    assert_eq!(a.len(), b.len());
    let travel = a.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    assert!(travel > 0.05, "the block slides: {travel} m");
    for (x, y) in a.iter().zip(&b) {
        assert!(
            (x - y).abs() <= 1e-8 * travel,
            "u_x {x} on the plane, {y} on the disc"
        );
    }
    // every contact slides (or sticks) when it does on the plane
    let sliding = |model: &ModelSpec| history_column(model, "block-ground.sliding");
    assert_eq!(sliding(&plane), sliding(&disc));
    assert!(sliding(&disc).iter().any(|&n| n > 0.0), "contacts slide");
}
