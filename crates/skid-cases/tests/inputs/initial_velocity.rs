//! Initial velocities of a part's nodes (`initial_velocities` of a model file): the block of
//! `2d-block-pushed-on-flat` launched along the flat at v0 = 3 m/s, pressed by N = 20 N in a
//! static step (which leaves velocities as they are), slides to a stop under Coulomb friction
//! in a dynamic step.
//!
//! The block's momentum changes by the friction impulse, increment by increment (the contact
//! forces act as impulses, see `skid_integrator::hht`), `p(t_k) - p(t_{k-1}) = h T_k`, from
//! `p(0) = m v0`; the friction resultant never exceeds `mu N`, and equals it (to 1e-6) from the
//! start until the contacts stop sliding, so the block decelerates at `mu N / m = 6000 m/s^2`.
//! A rigid block would stop at `m v0 / (mu N) = 0.5 ms`; the elastic one's contacts stop
//! sliding a little before (measured 0.46 ms, checked within 80-100 % of it): its top still
//! moves on the shear it carries, and it then rocks on its sticking contacts.

use std::path::{Path, PathBuf};

use skid_cases::model_file::{self, parse_model};
use skid_integrator::stepper::{IncrementReport, Observer, run};
use skid_integrator::{Model, State};

const MU: f64 = 0.3;
const PRESS: f64 = 20.0;
const MASS: f64 = 1e-3;
const V0: f64 = 3.0;

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(path)
}

/// The pushed block with the press ramped over a static step, no push, and every node moving
/// at v0.
fn launched_block(extra: &[&str]) -> skid_cases::model_spec::ModelSpec {
    let path = repo("cases/verification/2d-block-pushed-on-flat.json");
    let text = std::fs::read_to_string(&path).expect("read scene");
    let mut overrides: Vec<String> = [
        r#"loads=[{"type": "concentrated", "body": "plate", "force": [0.0, -20.0]}]"#,
        "amplitudes=[]",
        r#"steps=[{"type": "static", "name": "press", "increments": 4}, {"type": "dynamic", "name": "slide", "duration": 0.001, "dt": 1e-5, "alpha": -0.3}]"#,
        r#"rigid_bodies[1].initial_velocity=[3.0, 0.0]"#,
        r#"part.node_sets.lower=[0, 1, 2, 3, 4]"#,
        r#"initial_velocities=[{"node_set": "lower", "velocity": [3.0, 0.0]}]"#,
    ]
    .map(String::from)
    .to_vec();
    overrides.extend(extra.iter().map(|s| s.to_string()));
    parse_model(&text, &path, &overrides).expect("scene parses")
}

struct Record(Vec<(f64, State)>);

impl<const D: usize> Observer<D> for Record {
    fn on_increment(&mut self, _: &Model<D>, r: &IncrementReport<'_>) -> std::io::Result<()> {
        self.0.push((r.size, r.state.clone()));
        Ok(())
    }
}

#[test]
fn a_block_launched_along_a_flat_slides_to_a_stop_under_coulomb_friction() {
    let spec = launched_block(&[]);
    let scene = model_file::build::<2>(&spec).expect("scene builds");
    let model = &scene.model;
    let v = model.initial_velocity();
    for n in 0..model.part().mesh.nodes.len() {
        let eq = model.dofs().node(n)[0].expect("x is free");
        assert_eq!(v[eq], V0, "node {n} starts at v0");
    }
    let mut record = Record(Vec::new());
    let (_, result) = run(model, &scene.steps, &scene.settings, &mut record);
    result.expect("run completes");

    let p0 = model.linear_momentum(&record.0[0].1.v)[0];
    assert!(
        (p0 - MASS * V0).abs() < 1e-9 * MASS * V0,
        "initial momentum {p0}"
    );
    let mut stop = None;
    let mut time = 0.0;
    let slide = &record.0[record.0.len() - 100 - 1..];
    assert!(
        (model.linear_momentum(&slide[0].1.v)[0] - p0).abs() < 1e-9 * p0,
        "the static press leaves the velocity as it was"
    );
    for pair in slide.windows(2) {
        let [(_, before), (h, after)] = pair else {
            unreachable!()
        };
        time += h;
        let friction: f64 = after.contacts.iter().map(|c| c.tangential_force[0]).sum();
        let normal: f64 = after.contacts.iter().map(|c| c.normal_force).sum();
        let change = (model.linear_momentum(&after.v) - model.linear_momentum(&before.v))[0];
        assert!(
            (change - h * friction).abs() <= 1e-6 * MASS * V0,
            "t = {time}: momentum change {change} against the friction impulse {}",
            h * friction
        );
        assert!(
            friction.abs() <= MU * normal * (1.0 + 1e-6),
            "t = {time}: |T| = {} above mu N = {}",
            friction.abs(),
            MU * normal
        );
        let sliding = (friction + MU * normal).abs() <= 1e-6 * MU * normal;
        if stop.is_none() && !sliding {
            stop = Some(time);
        }
    }
    let rigid = MASS * V0 / (MU * PRESS);
    let stop = stop.expect("the contacts stop sliding");
    assert!(
        (0.8 * rigid..=rigid).contains(&stop),
        "the contacts stop sliding at {stop} s, a rigid block would at {rigid} s"
    );
}

#[test]
fn initial_velocities_the_model_cannot_take_are_refused_with_their_field() {
    for (set, field, fragment) in [
        (
            r#"initial_velocities=[{"node_set": "top", "velocity": [3.0, 0.0]}]"#,
            "initial_velocities[0]",
            "tied to rigid body 'plate'",
        ),
        (
            r#"initial_velocities=[{"node_set": "nowhere", "velocity": [3.0, 0.0]}]"#,
            "initial_velocities[0].node_set",
            "no node set named 'nowhere'",
        ),
        (
            r#"initial_velocities=[{"node_set": "lower", "velocity": [3.0]}]"#,
            "initial_velocities[0].velocity",
            "expected 2",
        ),
        (
            "part.section.quasi_static=true",
            "initial_velocities[0]",
            "quasi-static",
        ),
    ] {
        let spec = launched_block(&[set]);
        let error = model_file::build::<2>(&spec).expect_err(set);
        assert_eq!(error.field, field, "{set}: {error:?}");
        assert!(error.message.contains(fragment), "{set}: {}", error.message);
    }
}

/// The launched block as a deck: the writer puts the node velocities in `*INITIAL
/// CONDITIONS, TYPE=VELOCITY` on their node set, which reads back to the same model; the
/// components of a node given on several lines and sets combine, a rotating velocity gives
/// each node its own, and a rotation of a part's node is refused at its line.
#[test]
fn initial_velocities_of_part_nodes_go_through_decks() {
    let spec = launched_block(&[]);
    let deck = skid_cases::deck::write::write_deck(&spec, &Default::default()).expect("written");
    assert!(
        deck.contains("*INITIAL CONDITIONS, TYPE=VELOCITY\nlower, 1, 3.0\nlower, 2, 0.0\n"),
        "{deck}"
    );
    let dir = tempfile::tempdir().expect("tempdir");
    let read = |text: &str| {
        let path = dir.path().join("scene.inp");
        std::fs::write(&path, text).expect("write deck");
        skid_cases::deck::read_model(&path).map(|d| d.model)
    };
    let back = read(&deck).expect("reads back");
    assert_eq!(back.initial_velocities, spec.initial_velocities);
    assert_eq!(back.part.node_sets["lower"], spec.part.node_sets["lower"]);

    // two lines on two sets: node 0 is in both, so it takes both components
    let combined = deck.replace(
        "lower, 2, 0.0\n",
        "lower, 2, 0.0\n*INITIAL CONDITIONS, TYPE=VELOCITY\n1, 2, -1.0\n",
    );
    let model = read(&combined).expect("reads");
    let mut velocities: Vec<(Vec<usize>, Vec<f64>)> = model
        .initial_velocities
        .iter()
        .map(|v| {
            (
                model.part.node_sets[&v.node_set].clone(),
                v.velocity.clone(),
            )
        })
        .collect();
    velocities.sort_by(|a, b| a.0.cmp(&b.0));
    assert_eq!(
        velocities,
        vec![
            (vec![0], vec![3.0, -1.0]),
            (vec![1, 2, 3, 4], vec![3.0, 0.0]),
        ]
    );

    // a rotating velocity about z through the origin: v = omega (-y, x) at every node
    let rotating = deck.replace(
        "*INITIAL CONDITIONS, TYPE=VELOCITY\nlower, 1, 3.0\nlower, 2, 0.0\n",
        "*INITIAL CONDITIONS, TYPE=ROTATING VELOCITY\nlower, 10.0, 0.0, 0.0, 0.0\n0., 0., 0., 0., 0., 1.\n",
    );
    let model = read(&rotating).expect("reads");
    for v in &model.initial_velocities {
        for &n in &model.part.node_sets[&v.node_set] {
            let x = &model.part.nodes[n];
            assert_eq!(v.velocity, vec![-10.0 * x[1], 10.0 * x[0]], "node {n}");
        }
    }

    let rotation = deck.replace("lower, 2, 0.0\n", "lower, 6, 1.0\n");
    let err = read(&rotation)
        .expect_err("a part node has no rotation")
        .to_string();
    assert!(
        err.contains("scene.inp:") && err.contains("is a rotation"),
        "{err}"
    );
}
