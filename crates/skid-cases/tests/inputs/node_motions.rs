//! Prescribed motions of part nodes in decks: the scene
//! `cases/verification/2d-block-sheared-on-flat-deck.inp`, a block on a fixed flat (mu = 0.3)
//! whose top nodes are pushed down 0.1 mm in a static step (`*BOUNDARY top, 2, 2, -0.0001`,
//! x held at 0) and moved 1 mm sideways in a second one (`top, 1, 1, 0.001`).
//!
//! The deck reads to motions of the node set `top`; the nodes follow them exactly; the sums of
//! their reactions balance the contact resultants at every increment (static equilibrium: no
//! other force acts), the friction is mu N once every contact slides, and the reactions' work
//! goes into the frictional dissipation and the strain energy. The history carries the sums as
//! `top.reaction_x` and `top.reaction_y`. The deck writer writes the motions back to a deck
//! that reads to the same model; a model-data hold of a prescribed node's degree of freedom
//! keeps holding the set's other nodes; part nodes held in one step only are held by that
//! step; and what the model cannot express of a part node's condition is refused at its line.

use std::path::{Path, PathBuf};

use crate::deck_text::{assert_refused_at, read_deck_text};

use skid_cases::deck::read_model;
use skid_cases::deck::write::write_deck;
use skid_cases::model_file;
use skid_cases::model_spec::{BoundarySpec, Dof, ModelStepSpec, StepBoundarySpec};
use skid_cases::runner::run_model;
use skid_integrator::stepper::{IncrementReport, Observer, run};
use skid_integrator::{Model, State};

const MU: f64 = 0.3;
const PUSH: f64 = -1e-4;
const TRAVEL: f64 = 1e-3;

fn deck_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../cases/verification/2d-block-sheared-on-flat-deck.inp")
}

fn deck_text() -> String {
    std::fs::read_to_string(deck_path()).expect("read deck")
}

fn motion(set: &str, dof: Dof, value: f64, factors: Option<Vec<f64>>) -> BoundarySpec {
    BoundarySpec {
        body: None,
        node_set: Some(set.into()),
        dofs: vec![dof],
        value: Some(value),
        amplitude: None,
        step_factors: factors,
    }
}

/// Every converged state with its step name.
struct Record(Vec<(String, State)>);

impl<const D: usize> Observer<D> for Record {
    fn on_increment(&mut self, _: &Model<D>, r: &IncrementReport<'_>) -> std::io::Result<()> {
        self.0.push((r.step.to_string(), r.state.clone()));
        Ok(())
    }
}

#[test]
fn the_deck_moves_the_top_nodes_as_a_node_set() {
    let spec = read_model(&deck_path()).expect("deck reads").model;
    let motions: Vec<&BoundarySpec> = spec.boundary.iter().filter(|b| b.is_prescribed()).collect();
    assert_eq!(
        motions,
        [
            &motion("top", Dof::X, TRAVEL, Some(vec![0.0, 1.0])),
            &motion("top", Dof::Y, PUSH, None),
        ]
    );
    assert_eq!(spec.part.node_sets["top"], [5, 6, 7, 8, 9]);
}

#[test]
fn a_block_sheared_by_its_top_nodes_resists_with_exactly_mu_n() {
    let spec = read_model(&deck_path()).expect("deck reads").model;
    let scene = model_file::build::<2>(&spec).expect("scene builds");
    let model = &scene.model;
    let mut record = Record(Vec::new());
    let (_, result) = run(model, &scene.steps, &scene.settings, &mut record);
    result.expect("run completes");
    let top = &spec.part.node_sets["top"];
    let equations = |axis: usize| -> Vec<usize> {
        top.iter()
            .map(|&n| model.dofs().node(n)[axis].expect("a free equation"))
            .collect()
    };
    let (ex, ey) = (equations(0), equations(1));
    let sum = |v: &nalgebra::DVector<f64>, eqs: &[usize]| eqs.iter().map(|&e| v[e]).sum::<f64>();
    let shear: Vec<&(String, State)> = record.0.iter().filter(|(s, _)| s == "shear").collect();
    assert_eq!(shear.len(), 20);
    let mut sliding = 0;
    for (step, s) in &record.0[1..] {
        let normal: f64 = s.contacts.iter().map(|c| c.normal_force).sum();
        let friction: f64 = s.contacts.iter().map(|c| c.tangential_force[0]).sum();
        // the pushed block carries 2.8 N after the first increment, about 11 N at full push;
        // Newton's force tolerance is 1e-6 of the forces
        assert!(normal > 2.0, "{step}: N = {normal}");
        let tolerance = 1e-6 * normal;
        assert!(
            (sum(&s.reaction, &ey) + normal).abs() <= tolerance,
            "{step}: the top's vertical reaction {} N against N = {normal} N",
            sum(&s.reaction, &ey)
        );
        assert!(
            (sum(&s.reaction, &ex) + friction).abs() <= tolerance,
            "{step}: the top's horizontal reaction {} N against the friction {friction} N",
            sum(&s.reaction, &ex)
        );
        // every top node at the same prescribed displacement: the push ramped over the press
        // and carried into the shear, x held at 0 and then ramped to the travel
        for (&x, &y) in ex.iter().zip(&ey) {
            assert_eq!((s.x[x], s.x[y]), (s.x[ex[0]], s.x[ey[0]]), "{step}");
        }
        if step == "shear" {
            assert_eq!(s.x[ey[0]], PUSH, "the push is carried into the shear");
            assert!(s.x[ex[0]] > 0.0 && s.x[ex[0]] <= TRAVEL);
        } else {
            assert_eq!(s.x[ex[0]], 0.0, "{step}: x is held at 0");
            assert!(s.x[ey[0]] < 0.0 && s.x[ey[0]] >= PUSH, "{step}");
        }
        if step == "shear" && s.contacts.iter().all(|c| c.is_closed() && c.slip[0] > 0.0) {
            sliding += 1;
            assert!(
                (friction + MU * normal).abs() <= 1e-6 * MU * normal,
                "{step}: friction {friction} N, mu N = {} N",
                MU * normal
            );
        } else {
            assert!(friction.abs() <= MU * normal * (1.0 + 1e-9), "{step}");
        }
    }
    // the shear at mu N takes a fraction of the travel; the contacts slide after it
    assert!(sliding >= 18, "{sliding} sliding increments of 20");
    assert_eq!(shear[shear.len() - 1].1.x[ex[0]], TRAVEL);
    assert_eq!(record.0[5].1.x[ey[0]], PUSH, "the press ends at the push");
    let (start, end) = (&record.0[4].1, &shear[shear.len() - 1].1);
    let work = end.energy.reaction_work - start.energy.reaction_work;
    let unaccounted = end.energy.unaccounted_since(&start.energy);
    assert!(
        work > MU * 11.0 * (TRAVEL - 0.2e-3),
        "reaction work {work} J over the shear"
    );
    assert!(
        unaccounted.abs() <= 1e-4 * work,
        "energy unaccounted {unaccounted:e} J of the reactions' work {work:e} J"
    );
}

#[test]
fn the_history_sums_the_reactions_of_the_moved_node_set() {
    let spec = read_model(&deck_path()).expect("deck reads").model;
    let dir = std::env::temp_dir().join(format!("skid-node-motions-run-{}", std::process::id()));
    run_model(&spec, &deck_path(), &dir).expect("run completes");
    let text = std::fs::read_to_string(dir.join("history.csv")).expect("history");
    let _ = std::fs::remove_dir_all(&dir);
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let column = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
    };
    let (rx, ry) = (column("top.reaction_x"), column("top.reaction_y"));
    let (n, t) = (
        column("block-ground.normal_force"),
        column("block-ground.tangential_force_1"),
    );
    let last: Vec<f64> = lines
        .last()
        .expect("rows")
        .split(',')
        .map(|v| v.parse().unwrap_or(f64::NAN))
        .collect();
    assert!((last[ry] + last[n]).abs() <= 1e-6 * last[n], "{last:?}");
    assert!((last[rx] + last[t]).abs() <= 1e-6 * last[n], "{last:?}");
    assert!(
        (last[rx] - MU * last[n]).abs() <= 1e-6 * last[n],
        "{last:?}"
    );
}

#[test]
fn the_deck_writer_writes_node_set_motions_that_read_back_alike() {
    let spec = read_model(&deck_path()).expect("deck reads").model;
    let text = write_deck(&spec, &Default::default()).expect("the writer writes node-set motions");
    assert!(text.contains("top, 1, 1, 0.0\n") && text.contains("top, 2, 2, -0.0001\n"));
    let again = read_deck_text(&text).expect("the written deck reads");
    assert_eq!(again.boundary, spec.boundary);
    assert_eq!(again.part.node_sets, spec.part.node_sets);
    assert_eq!(again.steps, spec.steps);
}

/// A model-data hold of a degree of freedom that a step prescribes on some of its nodes holds
/// the others on a new set; one that a step prescribes on all of them is left to the motion.
#[test]
fn model_data_holds_give_way_to_the_motions_of_their_nodes() {
    let text = deck_text().replacen("ground, 6, 6\n", "ground, 6, 6\ntop, 1, 2\n", 1);
    let spec = read_deck_text(&text).expect("deck reads");
    let on_top: Vec<&BoundarySpec> = spec
        .boundary
        .iter()
        .filter(|b| b.node_set.is_some())
        .collect();
    assert_eq!(
        on_top,
        [
            &motion("top", Dof::X, TRAVEL, Some(vec![0.0, 1.0])),
            &motion("top", Dof::Y, PUSH, None),
        ]
    );

    // node 6 (number 5) alone is pushed down; the rest of the top stays held vertically
    let text = text.replacen("\ntop, 2, 2, -0.0001\n", "\n6, 2, 2, -0.0001\n", 1);
    let spec = read_deck_text(&text).expect("deck reads");
    let held = BoundarySpec {
        body: None,
        node_set: Some("top-held-1".into()),
        dofs: vec![Dof::Y],
        value: None,
        amplitude: None,
        step_factors: None,
    };
    assert!(spec.boundary.contains(&held), "{:?}", spec.boundary);
    assert_eq!(spec.part.node_sets["top-held-1"], [6, 7, 8, 9]);
    assert_eq!(spec.part.node_sets["motion-1"], [5]);
    assert!(
        spec.boundary
            .contains(&motion("motion-1", Dof::Y, PUSH, None))
    );
    model_file::build::<2>(&spec).expect("the model builds: no degree of freedom twice");
}

/// Part nodes held at zero in the first step only (the push moved to a node set of its own,
/// `OP=NEW` in the second step dropping the hold of x): the first step holds them, at their
/// value at its start, and the second leaves them free, without reaction; with nothing pushing
/// along x, the top only relaxes.
#[test]
fn part_nodes_held_in_one_step_only_are_held_by_that_step() {
    let text = deck_text()
        .replacen("\ntop, 1, 1, 0.001\n", "\ntop, 2, 2, -0.0001\n", 1)
        .replacen(
            "*STEP, NAME=shear, NLGEOM=YES\n*STATIC, DIRECT\n0.05, 1.0\n*BOUNDARY\n",
            "*STEP, NAME=shear, NLGEOM=YES\n*STATIC, DIRECT\n0.05, 1.0\n*BOUNDARY, OP=NEW\n",
            1,
        );
    let spec = read_deck_text(&text).expect("deck reads");
    let hold = StepBoundarySpec {
        body: None,
        node_set: Some("top".into()),
        dofs: Some(vec![Dof::X]),
    };
    let holds = |k: usize| match &spec.steps[k] {
        ModelStepSpec::Static { boundary, .. } => boundary.clone(),
        ModelStepSpec::Dynamic { boundary, .. } => boundary.clone(),
    };
    assert_eq!(holds(0), [hold]);
    assert_eq!(holds(1), []);
    let scene = model_file::build::<2>(&spec).expect("scene builds");
    let mut record = Record(Vec::new());
    let (_, result) = run(&scene.model, &scene.steps, &scene.settings, &mut record);
    result.expect("run completes");
    let top: Vec<usize> = spec.part.node_sets["top"]
        .iter()
        .map(|&n| scene.model.dofs().node(n)[0].expect("a free x"))
        .collect();
    for (step, s) in &record.0[1..] {
        for &x in &top {
            if step == "press" {
                assert_eq!(s.x[x], 0.0, "held in the press");
            } else {
                // released: no reaction; the nodes relax the press's small shear at the
                // corners, far less than a slip (measured 1.1e-6 m)
                assert_eq!(s.reaction[x], 0.0, "released in the shear");
                assert!(s.x[x].abs() < 1e-5, "top x moved to {}", s.x[x]);
            }
        }
    }
    // the written deck reads back to the same steps
    let written = write_deck(&spec, &Default::default()).expect("the writer writes it");
    let again = read_deck_text(&written).expect("the written deck reads");
    assert_eq!(again.steps, spec.steps);
}

#[test]
fn part_node_conditions_the_model_cannot_express_are_refused_at_their_line() {
    let text = deck_text();
    for (edit, needle, fragment) in [
        // prescribed in the second step only: free in the first
        (
            text.replacen("\ntop, 1, 1, 0.0\n", "\n", 1),
            "top, 1, 1, 0.001",
            "is prescribed here but free in step 1 (press)",
        ),
        // a rotation of solid nodes
        (
            text.replacen(
                "\ntop, 1, 1, 0.0\n",
                "\ntop, 1, 1, 0.0\ntop, 6, 6, 0.1\n",
                1,
            ),
            "top, 6, 6, 0.1",
            "degree of freedom 6 does not exist on the nodes of a 2D solid",
        ),
    ] {
        assert_refused_at(&edit, needle, fragment);
    }
}
