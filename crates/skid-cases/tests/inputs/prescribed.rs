//! Prescribed motions in model files (`boundary` entries with a `value`): the scene
//! `cases/verification/2d-block-dragged-on-flat.json`, a quasi-static block pressed with
//! N = 20 N onto a fixed flat (mu = 0.3) in a static step, then dragged sideways by the plate
//! tied to its top, whose x displacement is prescribed to go from 0 to 1 mm over a second
//! static step (`step_factors` [0, 1]).
//!
//! The plate follows the prescription exactly; the block, in equilibrium, makes the plate's
//! reaction balance the friction at every increment (the plate is massless); the contacts
//! stick while the block's shear builds up, then all slide with a friction resultant of
//! exactly mu N; and the reaction's work goes into the frictional dissipation and the strain
//! energy. Prescriptions the model cannot take are refused with their field. The scene's deck
//! prescribes the same motion with `*BOUNDARY` magnitudes in its steps, and what a deck cannot
//! express of a motion is refused at its line (part nodes' motions: `node_motions.rs`).

use std::path::{Path, PathBuf};

use crate::deck_text::{assert_refused_at, read_deck_text};

use skid_cases::deck::read_model;
use skid_cases::model_file::{self, parse_model};
use skid_cases::model_spec::{BoundarySpec, ModelSpec};
use skid_integrator::stepper::{IncrementReport, Observer, run};
use skid_integrator::{Model, State};

const MU: f64 = 0.3;
const PRESS: f64 = 20.0;
const TRAVEL: f64 = 1e-3;

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(path)
}

fn dragged_block(overrides: &[&str]) -> ModelSpec {
    let path = repo("cases/verification/2d-block-dragged-on-flat.json");
    let text = std::fs::read_to_string(&path).expect("read scene");
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    parse_model(&text, &path, &overrides).expect("scene parses")
}

/// Every converged state with its step name and increment.
struct Record(Vec<(String, usize, State)>);

impl<const D: usize> Observer<D> for Record {
    fn on_increment(&mut self, _: &Model<D>, r: &IncrementReport<'_>) -> std::io::Result<()> {
        self.0
            .push((r.step.to_string(), r.increment, r.state.clone()));
        Ok(())
    }
}

#[test]
fn a_block_dragged_by_a_prescribed_plate_resists_with_exactly_mu_n() {
    resists_with_exactly_mu_n(&dragged_block(&[]));
}

/// The scene's deck (`2d-block-dragged-on-flat-deck.inp`: the plate's x held at 0 by
/// `*BOUNDARY plate, 1, 1, 0.0` in the first step and moved by `plate, 1, 1, 0.001` in the
/// second) reads to the same prescribed motion, and so does the deck that moves it with an
/// `AMPLITUDE=` instead; both resist as the model file does.
#[test]
fn the_decks_of_the_dragged_block_prescribe_the_same_motion() {
    let json = dragged_block(&[]);
    let motions = |spec: &ModelSpec| -> Vec<BoundarySpec> {
        spec.boundary
            .iter()
            .filter(|bc| bc.is_prescribed())
            .cloned()
            .collect()
    };
    let path = repo("cases/verification/2d-block-dragged-on-flat-deck.inp");
    let deck = read_model(&path).expect("deck reads").model;
    assert_eq!(motions(&deck), motions(&json));
    resists_with_exactly_mu_n(&deck);

    let text = std::fs::read_to_string(&path).expect("read deck");
    let with_amplitude = text
        .replacen(
            "*STEP",
            "*AMPLITUDE, NAME=Drag\n0.0, 0.0, 1.0, 1.0\n*STEP",
            1,
        )
        .replace(
            "*BOUNDARY\nplate, 1, 1, 0.001",
            "*BOUNDARY, AMPLITUDE=drag\nplate, 1, 1, 0.001",
        );
    let deck = read_deck_text(&with_amplitude).expect("deck with an amplitude reads");
    let mut expected = motions(&json);
    expected[0].amplitude = Some("Drag".into());
    assert_eq!(motions(&deck), expected);
    assert_eq!(
        deck.amplitudes.iter().map(|a| &a.name).collect::<Vec<_>>(),
        ["Drag"]
    );
    resists_with_exactly_mu_n(&deck);
}

/// What a deck cannot ask of a prescribed motion is refused at its line.
#[test]
fn prescribed_motions_a_deck_cannot_express_are_refused_at_their_line() {
    let path = repo("cases/verification/2d-block-dragged-on-flat-deck.inp");
    let text = std::fs::read_to_string(&path).expect("read deck");
    for (edit, needle, fragment) in [
        // free in the first step: the model would hold it there
        (
            text.replacen("*BOUNDARY\nplate, 1, 1, 0.0\n", "", 1),
            "plate, 1, 1, 0.001",
            "free in step 1 (press)",
        ),
        // a motion of nodes tied to the plate
        (
            text.replacen(
                "*BOUNDARY\nplate, 1, 1, 0.0\n",
                "*BOUNDARY\nplate, 1, 1, 0.0\ntop, 2, 2, -0.0001\n",
                1,
            ),
            "top, 2, 2, -0.0001",
            "tied to rigid body plate",
        ),
        // a magnitude in model data
        (
            text.replacen("plate, 6, 6\n", "plate, 6, 6\nplate, 2, 2, 0.001\n", 1),
            "plate, 2, 2, 0.001",
            "prescribe a motion inside a step",
        ),
        // two amplitudes for one degree of freedom
        (
            text.replacen(
                "*STEP",
                "*AMPLITUDE, NAME=a\n0.0, 0.0, 1.0, 1.0\n*AMPLITUDE, NAME=b\n0.0, 1.0\n*STEP",
                1,
            )
            .replace(
                "*BOUNDARY\nplate, 1, 1, 0.0\n",
                "*BOUNDARY, AMPLITUDE=b\nplate, 1, 1, 0.0005\n",
            )
            .replace(
                "*BOUNDARY\nplate, 1, 1, 0.001",
                "*BOUNDARY, AMPLITUDE=a\nplate, 1, 1, 0.001",
            ),
            "plate, 1, 1, 0.001",
            "one amplitude for the whole run",
        ),
    ] {
        assert_refused_at(&edit, needle, fragment);
    }
}

/// Runs `spec`, the dragged block, and checks that the plate follows its prescription, that
/// its reaction balances the friction, that every contact slides with `mu N` from the second
/// or third increment of the drag on, and that the reaction's work is accounted for.
fn resists_with_exactly_mu_n(spec: &ModelSpec) {
    let scene = model_file::build::<2>(spec).expect("scene builds");
    let model = &scene.model;
    let mut record = Record(Vec::new());
    let (_, result) = run(model, &scene.steps, &scene.settings, &mut record);
    result.expect("run completes");
    let eq = model.dofs().body_translation(1)[0].expect("the plate's x");
    let drag: Vec<&(String, usize, State)> = record
        .0
        .iter()
        .filter(|(step, ..)| step == "drag")
        .collect();
    assert_eq!(drag.len(), 20);
    let mut first_sliding = None;
    for (_, k, s) in &drag {
        let k = *k;
        let expected = TRAVEL * k as f64 / 20.0;
        assert!(
            (s.x[eq] - expected).abs() <= 1e-15 * TRAVEL,
            "increment {k}: plate at {} m, prescribed {expected} m",
            s.x[eq]
        );
        let friction: f64 = s.contacts.iter().map(|c| c.tangential_force[0]).sum();
        let normal: f64 = s.contacts.iter().map(|c| c.normal_force).sum();
        // to Newton's force tolerance: the plate's equation and each contact node's balance
        // to 1e-6 of the largest force (PRESS), and the sum adds their residuals
        let equations = 1 + s.contacts.len();
        assert!(
            (s.reaction[eq] + friction).abs() <= 1e-6 * PRESS * equations as f64,
            "increment {k}: the plate's reaction {} N against the friction {friction} N",
            s.reaction[eq]
        );
        assert!(
            (normal - PRESS).abs() <= 1e-6 * PRESS,
            "increment {k}: N = {normal}"
        );
        let all_slide = s
            .contacts
            .iter()
            .all(|c| c.is_closed() && c.slip[0] > 1e-9 * TRAVEL);
        if all_slide {
            first_sliding.get_or_insert(k);
            assert!(
                (friction + MU * normal).abs() <= 1e-6 * MU * normal,
                "increment {k}: friction {friction} N, mu N = {} N",
                MU * normal
            );
        } else {
            assert!(
                friction.abs() <= MU * normal * (1.0 + 1e-9),
                "increment {k}"
            );
        }
    }
    // the shear at mu N takes T h / (G A) = 0.11 mm: the contacts stick over the first
    // increment (0.05 mm) and slide from the third on
    let first_sliding = first_sliding.expect("the block slides");
    assert!(
        (2..=3).contains(&first_sliding),
        "every contact slides from increment {first_sliding}"
    );
    let (start, end) = (&record.0[4].2, &drag[drag.len() - 1].2);
    assert_eq!(record.0[4].0, "press");
    let work = end.energy.reaction_work - start.energy.reaction_work;
    let unaccounted = end.energy.unaccounted_since(&start.energy);
    // the slide's friction alone dissipates mu N times the travel less the shear's
    assert!(
        work > MU * PRESS * (TRAVEL - 0.2e-3),
        "reaction work {work} J over the drag"
    );
    // a static step's ledger is a trapezoidal rule over its increments, as for the loads
    // (measured 1.8e-6 of the work)
    assert!(
        unaccounted.abs() <= 1e-4 * work,
        "energy unaccounted {unaccounted:e} J of the reaction's work {work:e} J"
    );
}

#[test]
fn prescribed_motions_the_model_cannot_take_are_refused_with_their_field() {
    for (set, field, fragment) in [
        (
            r#"boundary[2]={"body": "plate", "dofs": ["x"], "amplitude": "drag"}"#,
            "boundary[2].value",
            "give its value",
        ),
        (
            r#"boundary[2]={"body": "plate", "dofs": ["x"], "value": 1e-3, "amplitude": "drag"}"#,
            "boundary[2].amplitude",
            "no amplitude named 'drag'",
        ),
        (
            r#"boundary[2]={"body": "plate", "dofs": ["x"], "value": 1e-3, "step_factors": [1.0]}"#,
            "boundary[2].step_factors",
            "one factor per step",
        ),
        (
            r#"boundary[2]={"node_set": "top", "dofs": ["x"], "value": 1e-3}"#,
            "boundary[2]",
            "tied to rigid body 'plate'",
        ),
        (
            r#"boundary[2]={"node_set": "bottom", "dofs": ["rz"], "value": 1e-3}"#,
            "boundary[2].dofs",
            "no rotation",
        ),
        (
            r#"boundary[2]={"body": "ground", "dofs": ["x"], "value": 1e-3}"#,
            "boundary[2]",
            "the model fixes this degree of freedom",
        ),
        (
            r#"boundary[2]={"body": "plate", "dofs": ["x"], "value": 1e-3, "node_set": "top"}"#,
            "boundary[2]",
            "exactly one of body and node_set",
        ),
        // a step's holds of node sets
        (
            r#"steps[0].boundary=[{"node_set": "top", "dofs": ["x"]}]"#,
            "steps[0].boundary[0].node_set",
            "tied to rigid body 'plate'",
        ),
        (
            r#"steps[0].boundary=[{"node_set": "bottom", "dofs": ["rz"]}]"#,
            "steps[0].boundary[0].dofs",
            "no rotation",
        ),
        (
            r#"steps[0].boundary=[{"node_set": "bottom", "body": "plate"}]"#,
            "steps[0].boundary[0]",
            "exactly one of body and node_set",
        ),
    ] {
        let error = model_file::build::<2>(&dragged_block(&[set])).expect_err(set);
        assert_eq!(error.field, field, "{set}: {error:?}");
        assert!(error.message.contains(fragment), "{set}: {}", error.message);
    }
}
