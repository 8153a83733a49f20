//! The general model file: every drum case becomes a model file that reads back to the same
//! bits and runs to the same history; a verification scene beyond the drum matches its analytic
//! answer; fixed nodes give the homogeneous elastic solution; every model error names its field.

use std::path::{Path, PathBuf};

use serde_json::{Value, json};
use skid_cases::csv_out::CsvTable;
use skid_cases::drum::model_spec;
use skid_cases::model_file::summary::ModelSummary;
use skid_cases::model_file::{self, SpecError, parse_model, to_json};
use skid_cases::model_spec::ModelSpec;
use skid_cases::restart::DEFAULT_RESTART_EVERY;
use skid_cases::{RunSummary, load_case, run_case_file, run_file};
use skid_integrator::stepper::{IncrementReport, Observer, run};

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(path)
}

fn case_files(dir: &str) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(repo(dir))
        .expect("case directory")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    files.sort();
    files
}

/// A CSV file as named columns of text.
struct Columns {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Columns {
    fn read(path: &Path) -> Self {
        let text = std::fs::read_to_string(path).expect("read csv");
        let table = CsvTable::new(&text, path).expect("csv header");
        let header = table.header().map(String::from).collect();
        let rows = table
            .map(|row| row.expect("csv row").fields().map(String::from).collect())
            .collect();
        Self { header, rows }
    }

    fn text(&self, name: &str) -> Vec<&str> {
        let i = self
            .header
            .iter()
            .position(|c| c == name)
            .unwrap_or_else(|| panic!("no column {name} in {:?}", self.header));
        self.rows.iter().map(|r| r[i].as_str()).collect()
    }

    fn numbers(&self, name: &str) -> Vec<f64> {
        self.text(name)
            .iter()
            .map(|t| t.parse().expect("number"))
            .collect()
    }
}

/// Builds `spec` in its own dimension, returning the first problem.
fn build(spec: &ModelSpec) -> Result<(), SpecError> {
    match spec.dimension {
        2 => model_file::build::<2>(spec).map(drop),
        _ => model_file::build::<3>(spec).map(drop),
    }
}

#[test]
fn every_shipped_case_reads_back_from_its_model_file_to_the_same_bits() {
    let files: Vec<PathBuf> = ["cases/drum", "cases/hard"]
        .iter()
        .flat_map(|d| case_files(d))
        .collect();
    assert!(files.len() >= 20, "{files:?}");
    for path in files {
        let case = load_case(&path, &[]).expect("shipped case");
        let spec = model_spec(&case).expect("model of the case");
        let text = to_json(&spec).expect("serializes");
        let back = parse_model(&text, Path::new("model.json"), &[]).expect("model file parses");
        assert!(
            back == spec,
            "{}: the model file does not read back exactly",
            path.display()
        );
        build(&back).unwrap_or_else(|e| panic!("{}: {e:?}", path.display()));
    }
}

/// The drum columns of a case run and the generic columns of its model file's run.
const SAME_COLUMNS: [(&str, &str); 9] = [
    ("time", "time"),
    ("drum_angle", "drum.angle"),
    ("drum_omega", "drum.omega"),
    ("plate_displacement", "back_plate.u_y"),
    ("normal_force", "pad-drum.normal_force"),
    ("friction_force", "pad-drum.tangential_force_1"),
    ("newton_iterations", "newton_iterations"),
    ("kinetic_energy", "kinetic_energy"),
    ("friction_dissipation", "friction_dissipation"),
];

#[test]
fn a_case_and_its_model_file_give_bit_identical_runs() {
    let overrides = ["steps[1].duration=0.003".to_string()];
    for name in ["2d-r2d2", "3d-c3d4"] {
        let path = repo(&format!("cases/drum/{name}.json"));
        let dir = tempfile::tempdir().expect("tempdir");
        run_case_file(&path, &overrides, Some(&dir.path().join("case"))).expect("case runs");
        let spec = model_spec(&load_case(&path, &overrides).expect("case")).expect("model");
        let model_path = dir.path().join("model.json");
        std::fs::write(&model_path, to_json(&spec).expect("serializes")).expect("write model");
        let summary = run_file(
            &model_path,
            &[],
            Some(&dir.path().join("model")),
            DEFAULT_RESTART_EVERY,
        )
        .expect("model runs");
        assert!(
            matches!(summary, RunSummary::Model(_)),
            "{name}: run as a model file"
        );
        assert_eq!(summary.error(), None, "{name}");
        let read = |sub: &str| Columns::read(&dir.path().join(sub).join("history.csv"));
        let (case, model) = (read("case"), read("model"));
        assert_eq!(case.rows.len(), model.rows.len(), "{name}: rows");
        assert!(case.rows.len() > 30, "{name}: {} rows", case.rows.len());
        for (a, b) in SAME_COLUMNS {
            assert_eq!(case.text(a), model.text(b), "{name}: {a} against {b}");
        }
    }
}

/// The block pressed (N = 20 N) on a ground of mass m = 0.05 kg that slides at 1 m/s with
/// mu = 0.3. In every increment until it first stops the block carries the pressure (to the
/// Newton tolerance, 1e-8) and the ground's velocity drops by exactly
/// `h T / m` for the friction force T the block receives (action and reaction), and T never
/// exceeds mu N; once the slip directions have settled (2 ms: in 3D the block's Poisson
/// expansion first slips its contacts sideways too), T is exactly mu N, so the ground is braked
/// at exactly mu N / m.
#[test]
fn a_block_on_a_sliding_ground_brakes_it_at_exactly_mu_n_over_m() {
    let (normal, mu, mass, h) = (20.0, 0.3, 0.05, 0.00025);
    for dim in [2, 3] {
        let path = repo(&format!(
            "cases/verification/{dim}d-block-on-sliding-ground.json"
        ));
        let dir = tempfile::tempdir().expect("tempdir");
        let summary = run_file(&path, &[], Some(dir.path()), DEFAULT_RESTART_EVERY).expect("runs");
        assert_eq!(summary.error(), None, "{dim}D");
        let table = Columns::read(&dir.path().join("history.csv"));
        let col = |name: &str| table.numbers(name);
        let (step, time, v) = (table.text("step"), col("time"), col("ground.v_x"));
        let (n, t) = (
            col("block-ground.normal_force"),
            col("block-ground.tangential_force_1"),
        );
        let (active, sliding) = (col("block-ground.active"), col("block-ground.sliding"));
        let mut exact = 0;
        for k in 1..v.len() {
            if step[k] != "slide" {
                continue;
            }
            if v[k] <= 0.0 {
                break;
            }
            assert!(
                (n[k] - normal).abs() < 1e-8 * normal,
                "{dim}D row {k}: N = {}",
                n[k]
            );
            let dv = v[k] - v[k - 1];
            assert!(
                (dv + h * t[k] / mass).abs() < 1e-9,
                "{dim}D row {k}: dv = {dv}, T = {}",
                t[k]
            );
            // within the cone to Newton's convergence (its contact tolerance is 1e-8)
            assert!(
                t[k].abs() <= mu * n[k] * (1.0 + 1e-8),
                "{dim}D row {k}: T = {}, N = {}",
                t[k],
                n[k]
            );
            if time[k] >= 0.002 {
                assert!(
                    active[k] > 0.0 && sliding[k] == active[k],
                    "{dim}D row {k} sticks"
                );
                assert!(
                    (t[k].abs() - mu * normal).abs() < 1e-9 * normal,
                    "{dim}D row {k}: T = {}",
                    t[k]
                );
                exact += 1;
            }
        }
        // 1 m/s at 0.03 m/s per increment: 33 sliding increments, 25 of them after 2 ms
        assert!(exact >= 24, "{dim}D: only {exact} increments checked");
        // it stops once, near m v0 / (mu N) = 8.3 ms
        let stop = v.iter().position(|&v| v <= 0.0).expect("the ground stops");
        assert!(
            (0.0083..0.0090).contains(&time[stop]),
            "{dim}D: stops at {}",
            time[stop]
        );
    }
}

/// The frictionless 3D block pressed by 3.042e5 Pa with the reduced contact solve and 0.84 ms
/// steps (stress sweep, seed 1, run 2). The block and its massless plate are quasi-static and
/// held vertically only by the contacts, so the Delassus operator holds the large compliance
/// of that mode; the Coulomb solver's relative tolerance then allowed 1e-5 m of penetration
/// and a plate velocity zig-zagging up to 1e-2 m/s. The plate must stay at rest and the
/// contacts closed to the contact tolerance.
#[test]
fn a_frictionless_block_held_only_by_its_contacts_stays_at_rest_on_the_reduced_path() {
    let (dir, summary) = run_scene(
        "3d-block-on-sliding-ground",
        &[
            "contact[0].mu=0.0",
            "loads[0].pressure=304200.0",
            "rigid_bodies[0].initial_velocity=[-0.02921, 0.0, 0.0]",
            "steps[1].dt=0.0008356",
            "steps[1].duration=0.0100272",
            "steps[1].alpha=-0.177",
            "solver.contact_solve=\"reduced\"",
        ],
    );
    let table = Columns::read(&dir.path().join("history.csv"));
    let step = table.text("step");
    let v = table.numbers("plate.v_y");
    let worst = (0..v.len())
        .filter(|&k| step[k] == "slide")
        .map(|k| v[k].abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-5, "plate speed up to {worst} m/s");
    // contact tolerance 1e-9 of the 0.02 m block, with a margin for the last iteration's step
    assert!(
        summary.max_gap_violation_m < 1e-10,
        "penetration {} m",
        summary.max_gap_violation_m
    );
}

/// Runs the shipped verification scene `name` with `overrides` into a temporary directory
/// (returned with the summary), and checks that it completed.
fn run_scene(name: &str, overrides: &[&str]) -> (tempfile::TempDir, ModelSummary) {
    let path = repo(&format!("cases/verification/{name}.json"));
    let overrides: Vec<String> = overrides.iter().map(ToString::to_string).collect();
    let dir = tempfile::tempdir().expect("tempdir");
    let RunSummary::Model(summary) =
        run_file(&path, &overrides, Some(dir.path()), DEFAULT_RESTART_EVERY).expect("runs")
    else {
        panic!("a model file gives a model summary");
    };
    assert_eq!(summary.error, None);
    (dir, summary)
}

/// The quasi-static block sticking to the ground it swings back, at coarse steps (seed 1 run 188
/// of the stress sweep, shortened): the end-point equilibrium of the block damps the swing like
/// backward Euler (its swing, of period about 8.5 ms, loses a share `pi omega dt` of its
/// amplitude per period), so most of the energy goes to the time integration. The ledger counts
/// it and balances; the summary warns that the answer depends on the time step.
#[test]
fn a_coarsely_stepped_quasi_static_block_balances_its_energy_and_warns() {
    let (_dir, summary) = run_scene(
        "2d-block-on-sliding-ground",
        &[
            "contact[0].mu=1.801",
            "loads[0].pressure=1478000.0",
            "rigid_bodies[0].initial_velocity=[-3.705, 0.0]",
            "steps[1].dt=0.002505",
            "steps[1].duration=0.02505",
            "steps[1].alpha=0.0",
        ],
    );
    let error = summary.energy_balance_error.expect("energy in play");
    let residual = summary.energy_balance_residual_j.expect("residual");
    let algorithmic = summary.algorithmic_dissipation_j.expect("dissipation");
    let scale = residual.abs() / error;
    assert!(error < 0.01, "energy balance error {error}");
    assert!(
        algorithmic > 0.2 * scale,
        "the time integration removed {algorithmic} J of {scale} J"
    );
    assert_eq!(summary.warnings.len(), 1, "{:?}", summary.warnings);
    assert!(
        summary.warnings[0].contains("time step"),
        "{:?}",
        summary.warnings
    );
}

/// A 2D block on rollers (bottom nodes fixed in y, one of them in x) under a small pressure on
/// its top: homogeneous uniaxial stress in plane strain, `eps_yy = -p (1 - nu^2) / E` and
/// `eps_xx = p nu (1 + nu) / E`, with E and nu of the initial shear and bulk moduli.
#[test]
fn a_block_on_rollers_compresses_homogeneously() {
    let path = repo("cases/verification/2d-block-on-sliding-ground.json");
    let mut value: Value =
        serde_json::from_str(&std::fs::read_to_string(&path).expect("read")).expect("json");
    let p = 100.0;
    let nodes = value["part"]["nodes"].as_array().expect("nodes").clone();
    let corner = nodes
        .iter()
        .position(|n| n[0].as_f64() == Some(-0.01) && n[1].as_f64() == Some(0.0))
        .expect("corner node");
    value["part"]["node_sets"]["corner"] = json!([corner]);
    for key in ["rigid_bodies", "ties", "contact"] {
        value[key] = json!([]);
    }
    value["boundary"] = json!([
        {"node_set": "bottom", "dofs": ["y"]},
        {"node_set": "corner", "dofs": ["x"]},
    ]);
    value["loads"][0]["pressure"] = json!(p);
    value["steps"] = json!([{"type": "static", "name": "press", "increments": 2}]);
    let spec = parse_model(&value.to_string(), Path::new("rollers.json"), &[]).expect("model");
    let scene = model_file::build::<2>(&spec).expect("scene");
    let (_, result) = run(&scene.model, &scene.steps, &scene.settings, &mut Silent);
    let state = result.expect("converges");
    let (c10, c01, d1) = (552000.0, 138000.0, 1.45e-7);
    let (mu, k) = (2.0 * (c10 + c01), 2.0 / d1);
    let e = 9.0 * k * mu / (3.0 * k + mu);
    let nu = (3.0 * k - 2.0 * mu) / (2.0 * (3.0 * k + mu));
    let (eps_yy, eps_xx) = (-p * (1.0 - nu * nu) / e, p * nu * (1.0 + nu) / e);
    let mesh = &scene.model.part().mesh;
    for (n, x0) in mesh.nodes.iter().enumerate() {
        let u = scene.model.dofs().node_displacement(&state.x, n);
        let expected = [eps_xx * (x0[0] + 0.01), eps_yy * x0[1]];
        for i in 0..2 {
            assert!(
                (u[i] - expected[i]).abs() < 1e-3 * (eps_yy * 0.01).abs(),
                "node {n} axis {i}: u = {}, expected {}",
                u[i],
                expected[i]
            );
        }
    }
    let bottom = &mesh.node_sets["bottom"];
    assert!(
        bottom
            .iter()
            .all(|&n| scene.model.dofs().node(n)[1].is_none())
    );
}

/// Records nothing.
struct Silent;

impl<const D: usize> Observer<D> for Silent {
    fn on_increment(
        &mut self,
        _: &skid_integrator::Model<D>,
        _: &IncrementReport<'_>,
    ) -> std::io::Result<()> {
        Ok(())
    }
}

/// Each problem in a model file is reported with its field path.
#[test]
fn every_model_error_names_its_field() {
    let base: Value = serde_json::from_str(
        &std::fs::read_to_string(repo("cases/verification/2d-block-on-sliding-ground.json"))
            .expect("read"),
    )
    .expect("json");
    let base3: Value = serde_json::from_str(
        &std::fs::read_to_string(repo("cases/verification/3d-block-on-sliding-ground.json"))
            .expect("read"),
    )
    .expect("json");
    type Edit = fn(&mut Value);
    let cases: [(&Value, Edit, &str, &str); 25] = [
        (
            &base,
            |v| v["output"]["history_nodes"] = json!(["top", "nowhere"]),
            "output.history_nodes[1]",
            "no node set named 'nowhere'",
        ),
        (
            &base,
            |v| v["skid_model"] = json!(2),
            "skid_model",
            "format version 1",
        ),
        (
            &base,
            |v| v["ties"][0]["body"] = json!("nobody"),
            "ties[0].body",
            "no rigid body named 'nobody'",
        ),
        (
            &base,
            |v| v["ties"][0]["node_set"] = json!("nowhere"),
            "ties[0].node_set",
            "no node set named 'nowhere'",
        ),
        (
            &base,
            |v| {
                let face = v["part"]["surfaces"]["top"][0]
                    .as_array()
                    .expect("face")
                    .clone();
                v["part"]["surfaces"]["top"][0] = json!([face[1], face[0]]);
            },
            "part.surfaces.top[0]",
            "points into its element",
        ),
        (
            &base,
            |v| v["part"]["surfaces"]["top"][0] = json!([0, 14]),
            "part.surfaces.top[0]",
            "not a face of any element",
        ),
        (
            &base,
            |v| v["part"]["elements"][0]["type"] = json!("C3D8R"),
            "part.elements[0].type",
            "2D element type",
        ),
        (
            &base,
            |v| v["boundary"][0]["dofs"] = json!(["rx"]),
            "boundary[0].dofs",
            "not a degree of freedom in 2D",
        ),
        (
            &base,
            |v| v["rigid_bodies"][0]["initial_velocity"] = json!([1.0, 1.0]),
            "rigid_bodies[0].initial_velocity",
            "fixed",
        ),
        (
            &base,
            |v| v["contact"][0]["master"] = json!("plate"),
            "contact[0].master",
            "has no surface",
        ),
        (
            &base,
            |v| v["boundary"] = json!([{"body": "ground", "dofs": ["y", "rz"]}, {"body": "plate", "dofs": ["rz"]}, {"node_set": "top", "dofs": ["x"]}]),
            "(model)",
            "both fixed and tied",
        ),
        (
            &base3,
            |v| v["boundary"][1]["dofs"] = json!(["x", "z", "rz"]),
            "rigid_bodies[1]",
            "about no axis, one, or all three",
        ),
        (
            &base3,
            |v| v["boundary"][1]["dofs"] = json!(["x", "z"]),
            "rigid_bodies[1].moments_of_inertia",
            "expected its moments of inertia",
        ),
        (
            &base3,
            |v| {
                v["boundary"][1]["dofs"] = json!(["x", "z"]);
                v["rigid_bodies"][1]["moments_of_inertia"] = json!([0.1, 0.1, -0.2]);
            },
            "rigid_bodies[1].moments_of_inertia",
            "expected moments >= 0",
        ),
        (
            &base3,
            |v| {
                v["boundary"][1]["dofs"] = json!(["x", "z"]);
                v["rigid_bodies"][1]["products_of_inertia"] = json!([0.01, 0.0, 0.0]);
            },
            "rigid_bodies[1].products_of_inertia",
            "expected moments_of_inertia beside the products",
        ),
        (
            &base3,
            |v| {
                v["boundary"][1]["dofs"] = json!(["x", "z"]);
                v["rigid_bodies"][1]["moments_of_inertia"] = json!([0.1, 0.1, 0.1]);
                v["rigid_bodies"][1]["products_of_inertia"] = json!([0.2, 0.0, 0.0]);
            },
            "rigid_bodies[1].products_of_inertia",
            "not positive semi-definite",
        ),
        (
            &base3,
            |v| {
                v["boundary"][1]["dofs"] = json!(["x", "z"]);
                v["rigid_bodies"][1]["moments_of_inertia"] = json!([0.1, 0.1, 0.1]);
                v["steps"][0]["boundary"] = json!([{"body": "plate", "dofs": ["y", "rz"]}]);
            },
            "steps[0].boundary[0].dofs",
            "holds all its rotations (rx, ry, rz) or none",
        ),
        (
            &base3,
            |v| {
                v["rigid_bodies"][1]["rotary_inertia"] = json!(0.1);
                v["rigid_bodies"][1]["moments_of_inertia"] = json!([0.1, 0.1, 0.1]);
            },
            "rigid_bodies[1].moments_of_inertia",
            "not both",
        ),
        (
            &base,
            |v| {
                v["rigid_bodies"][0]["surface"] = json!({"type": "extrusion", "axis": [0, 0, 1],
                    "reference": [1, 0, 0], "profile": [[1, 0], [-1, 0]]})
            },
            "rigid_bodies[0].surface",
            "a 3D surface",
        ),
        (
            &base,
            |v| v["rigid_bodies"][0]["surface"] = json!({"type": "polyline", "points": [[1, 0]]}),
            "rigid_bodies[0].surface",
            "at least 2 vertices",
        ),
        (
            &base3,
            |v| {
                v["rigid_bodies"][0]["surface"] =
                    json!({"type": "polyline", "points": [[1, 0], [-1, 0]]})
            },
            "rigid_bodies[0].surface",
            "a 2D surface",
        ),
        (
            &base3,
            |v| {
                v["rigid_bodies"][0]["surface"] = json!({"type": "revolution", "axis": [1, 0, 0],
                    "profile": [[-0.1, -1], [0.2, 1]]})
            },
            "rigid_bodies[0].surface",
            "r >= 0",
        ),
        (
            &base3,
            |v| {
                v["rigid_bodies"][0]["surface"] = json!({"type": "triangles",
                    "vertices": [[0, 0, 0], [0, 0, 1], [1, 0, 0]], "triangles": [[0, 1, 2]],
                    "chart": {"type": "plane", "normal": [0, 1, 0], "tangent": [0, 2, 0]}})
            },
            "rigid_bodies[0].surface",
            "not parallel",
        ),
        (
            &base3,
            |v| {
                // a face on the cylinder r = 1 about z, and one leaning across it
                v["rigid_bodies"][0]["surface"] = json!({"type": "triangles",
                    "vertices": [[1, 0, 0], [0, 1, 0], [0, 1, 1], [0.5, 0, 2]],
                    "triangles": [[0, 1, 2], [0, 2, 3]],
                    "chart": {"type": "cylinder", "radius": 1, "axis": [0, 0, 1]}})
            },
            "rigid_bodies[0].surface.triangles[1]",
            "neither on a cylinder about its axis nor across it",
        ),
        (
            &base3,
            |v| v["steps"][0]["automatic"] = json!({"initial": 0.5, "min": 0.1, "max": 1.0}),
            "steps[0].increments",
            "exactly one of increments (fixed) and automatic",
        ),
    ];
    for (base, edit, field, fragment) in cases {
        let mut value = base.clone();
        edit(&mut value);
        let spec = parse_model(&value.to_string(), Path::new("m.json"), &[]).expect("parses");
        let error = build(&spec).expect_err(field);
        assert_eq!(error.field, field, "{error:?}");
        assert!(
            error.message.contains(fragment),
            "{field}: {}",
            error.message
        );
    }
    // text that is not of the format names the field
    let mut value = base.clone();
    value["part"]["section"]["densty"] = json!(1.0);
    let error = parse_model(&value.to_string(), Path::new("m.json"), &[]).expect_err("unknown");
    let text = error.to_string();
    assert!(
        text.contains("m.json") && text.contains("part.section") && text.contains("densty"),
        "{text}"
    );
}

/// The sliding block with massless contact nodes (`cases/verification/2d-block-sliding.json`):
/// pulled by twice the friction it accelerates at `(F - mu N) / m` as momentum balance says,
/// within 0.2 % at every step of a ladder from 4e-5 to 2.5e-6 s, and its contact normal force
/// stays steady (scatter under 2 %) however short the step. With the lumped mass on its contact
/// nodes the scatter grew from 0.1 % to 68 % over the same ladder (`scripts/sliding.py`).
#[test]
fn a_sliding_block_with_massless_contact_nodes_converges_as_the_step_shrinks() {
    for dt in ["4e-5", "1e-5", "2.5e-6"] {
        let (dir, summary) = run_scene("2d-block-sliding", &[&format!("steps[0].dt={dt}")]);
        let history = Columns::read(&dir.path().join("history.csv"));
        let (t, v, n) = (
            history.numbers("time"),
            history.numbers("plate.v_x"),
            history.numbers("block-ground.normal_force"),
        );
        let window: Vec<usize> = (0..t.len())
            .filter(|&i| (0.027..=0.040).contains(&t[i]))
            .collect();
        let mean = |f: &dyn Fn(usize) -> f64| {
            window.iter().map(|&i| f(i)).sum::<f64>() / window.len() as f64
        };
        let (tm, vm, nm) = (mean(&|i| t[i]), mean(&|i| v[i]), mean(&|i| n[i]));
        let slope = mean(&|i| (t[i] - tm) * (v[i] - vm)) / mean(&|i| (t[i] - tm).powi(2));
        let scatter = mean(&|i| (n[i] - nm).powi(2)).sqrt() / nm;
        // (F - mu N) / m with F = 2 mu N, N = 20 N, mu = 0.3, m = 1 g
        let exact = 0.3 * 20.0 / 1e-3;
        assert!(
            (slope / exact - 1.0).abs() < 2e-3,
            "dt {dt}: acceleration {slope} against {exact}"
        );
        assert!((nm - 20.0).abs() < 0.02, "dt {dt}: mean normal force {nm}");
        assert!(scatter < 0.02, "dt {dt}: normal force scatter {scatter}");
        assert!(
            summary.energy_balance_error.expect("balance") < 1e-6,
            "dt {dt}: {:?}",
            summary.energy_balance_error
        );
    }
}
