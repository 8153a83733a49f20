//! The time amplitudes are read against: a static step's time period, and the total time.
//!
//! The scene `cases/verification/2d-block-dragged-on-flat.json` drags its plate 1 mm over its
//! second static step (`step_factors` [0, 1]: ramped from 0 to the value over the step). Three
//! other ways of saying the same motion must move the plate identically, increment by
//! increment, and so give the same run:
//! - a step-time amplitude `(0, 0), (2, 1)` in the drag step, given a time period of 2 (its
//!   step time runs from 0 to 2), with the same step factors;
//! - a total-time amplitude `(0, 0), (1, 0), (3, 1)` in every step, the drag step's period 2
//!   (the press, of period 1, reads it from 0 to 1, where it is 0; the drag from 1 to 3);
//! - the deck of that model, `*AMPLITUDE, TIME=TOTAL TIME` and `*STATIC` with period 2, which
//!   reads to the same model and is what the deck writer writes of it.
//!
//! A deck's load or motion carried into a later step with a step-time amplitude holds there
//! the value the amplitude reached, as Abaqus holds it; and a step may apply its loads at once
//! or ramp them (`default_amplitude`, `*STEP, AMPLITUDE=`).

use std::path::{Path, PathBuf};

use crate::deck_text::read_deck_text;

use skid_cases::deck::read_model;
use skid_cases::deck::write::write_deck;
use skid_cases::model_file::{self, parse_model};
use skid_cases::model_spec::{AmplitudeSpec, AmplitudeTime, ModelSpec, ModelStepSpec};
use skid_integrator::stepper::{IncrementReport, Observer, run};
use skid_integrator::{LoadInstant, Model, State};

fn dragged_block(overrides: &[&str]) -> ModelSpec {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../cases/verification/2d-block-dragged-on-flat.json");
    let text = std::fs::read_to_string(&path).expect("read scene");
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    parse_model(&text, &path, &overrides).expect("scene parses")
}

/// The dragged block's deck, `cases/verification/2d-block-dragged-on-flat-deck.inp`.
fn dragged_deck() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../cases/verification/2d-block-dragged-on-flat-deck.inp")
}

/// Every converged state.
struct Record(Vec<State>);

impl<const D: usize> Observer<D> for Record {
    fn on_increment(&mut self, _: &Model<D>, r: &IncrementReport<'_>) -> std::io::Result<()> {
        self.0.push(r.state.clone());
        Ok(())
    }
}

/// The plate's x displacement and reaction at every converged increment of `spec`.
fn plate_motion(spec: &ModelSpec) -> Vec<(f64, f64)> {
    let scene = model_file::build::<2>(spec).expect("scene builds");
    let mut record = Record(Vec::new());
    let (_, result) = run(&scene.model, &scene.steps, &scene.settings, &mut record);
    result.expect("run completes");
    let eq = scene.model.dofs().body_translation(1)[0].expect("the plate's x");
    record.0.iter().map(|s| (s.x[eq], s.reaction[eq])).collect()
}

/// `a` and `b` agree increment by increment: the prescribed displacements to 1e-15 of the
/// travel (the amplitudes' tables are transformed, so their interpolation may round
/// differently), the reactions to Newton's tolerance, 1e-6 of the 20 N load.
fn assert_same_motion(a: &[(f64, f64)], b: &[(f64, f64)], what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: increments");
    for (k, ((xa, ra), (xb, rb))) in a.iter().zip(b).enumerate() {
        assert!(
            (xa - xb).abs() <= 1e-18,
            "{what}, increment {k}: x {xa} against {xb}"
        );
        assert!(
            (ra - rb).abs() <= 2e-5,
            "{what}, increment {k}: reaction {ra} against {rb}"
        );
    }
}

const STEP_TIME: &[&str] = &[
    r#"amplitudes=[{"name": "drag", "points": [[0.0, 0.0], [2.0, 1.0]]}]"#,
    "boundary[2].amplitude=\"drag\"",
    "steps[1].time_period=2.0",
];

const TOTAL_TIME: &[&str] = &[
    r#"amplitudes=[{"name": "drag", "points": [[0.0, 0.0], [1.0, 0.0], [3.0, 1.0]], "time": "total"}]"#,
    "boundary[2].amplitude=\"drag\"",
    "boundary[2].step_factors=null",
    "steps[1].time_period=2.0",
];

#[test]
fn a_static_steps_time_period_scales_the_step_time_of_its_amplitudes() {
    let reference = plate_motion(&dragged_block(&[]));
    assert_eq!(reference.last().map(|m| m.0), Some(1e-3));
    assert_same_motion(
        &plate_motion(&dragged_block(STEP_TIME)),
        &reference,
        "step time over a period of 2",
    );
    // without the period, the step time runs to 1 only: the plate goes half the way
    let half = plate_motion(&dragged_block(&STEP_TIME[..2]));
    assert!((half.last().expect("increments").0 - 0.5e-3).abs() <= 1e-18);
}

#[test]
fn a_total_time_amplitude_runs_on_across_steps() {
    let reference = plate_motion(&dragged_block(&[]));
    let total = dragged_block(TOTAL_TIME);
    assert_eq!(total.amplitudes[0].time, AmplitudeTime::Total);
    assert_same_motion(&plate_motion(&total), &reference, "total time");
    // read against the step time, the same table would hold the plate at 0 in the drag step
    // up to step time 1 and take it to half the travel at its end (the table at t = 2)
    let as_step_time = dragged_block(&[
        &TOTAL_TIME[0].replace(r#", "time": "total""#, ""),
        TOTAL_TIME[1],
        TOTAL_TIME[2],
        TOTAL_TIME[3],
    ]);
    let moved = plate_motion(&as_step_time);
    assert!((moved.last().expect("increments").0 - 0.5e-3).abs() <= 1e-18);
}

#[test]
fn decks_read_and_write_total_time_amplitudes_and_static_periods() {
    let spec = dragged_block(&[TOTAL_TIME, &["part.section.quasi_static=false"]].concat());
    let text = write_deck(&spec, &Default::default()).expect("the writer writes it");
    assert!(
        text.contains("*AMPLITUDE, NAME=drag, TIME=TOTAL TIME\n"),
        "{text}"
    );
    assert!(text.contains("*STATIC, DIRECT\n0.1, 2.0\n"), "{text}");
    let deck = read_deck_text(&text).expect("the written deck reads");
    assert_eq!(deck.amplitudes, spec.amplitudes);
    assert_eq!(deck.steps, spec.steps);
    let motions = |m: &ModelSpec| {
        m.boundary
            .iter()
            .filter(|b| b.is_prescribed())
            .cloned()
            .collect::<Vec<_>>()
    };
    assert_eq!(motions(&deck), motions(&spec));
    let ModelStepSpec::Static { time_period, .. } = &deck.steps[1] else {
        panic!("a static drag");
    };
    assert_eq!(*time_period, Some(2.0));
    assert_same_motion(
        &plate_motion(&deck),
        &plate_motion(&spec),
        "the deck of the total-time model",
    );
}

#[test]
fn a_time_period_that_is_not_positive_is_refused_with_its_field() {
    for period in ["0.0", "-1.0"] {
        let spec = dragged_block(&[&format!("steps[1].time_period={period}")]);
        let error = model_file::build::<2>(&spec).expect_err(period);
        assert_eq!(error.field, "steps[1].time_period", "{error:?}");
        assert!(
            error.message.contains("expected a finite value > 0"),
            "{error:?}"
        );
    }
}

/// The deck of the dragged block with its press ramped by `*AMPLITUDE, NAME=ramp` (`time`:
/// the parameter added to the keyword line, if any), written to a temporary file and read.
fn ramped_press_deck(time: &str) -> Result<ModelSpec, String> {
    let text = std::fs::read_to_string(dragged_deck())
        .expect("read deck")
        .replacen(
            "*STEP",
            &format!("*AMPLITUDE, NAME=ramp{time}\n0.0, 0.0, 1.0, 1.0\n*STEP"),
            1,
        )
        .replacen("*CLOAD\n", "*CLOAD, AMPLITUDE=ramp\n", 1);
    read_deck_text(&text)
}

/// A load ramped by a step-time amplitude over the press and carried into the drag: Abaqus
/// holds it at the amplitude's end value, so the deck reader gives it a total-time amplitude of
/// its own, `ramp@1`, the press's table held after it; the run is that of the shipped deck,
/// whose press is ramped by default and held, and that of the same deck with `TIME=TOTAL TIME`.
#[test]
fn a_step_time_amplitude_carried_into_a_later_step_holds_its_end_value() {
    let carried = ramped_press_deck("").expect("a carried step-time ramp reads");
    let frozen = AmplitudeSpec {
        name: "ramp@1".into(),
        points: vec![[0.0, 0.0], [1.0, 1.0]],
        time: AmplitudeTime::Total,
    };
    assert_eq!(carried.amplitudes, [frozen]);
    let total = ramped_press_deck(", TIME=TOTAL TIME").expect("a total-time ramp reads");
    assert_eq!(total.amplitudes[0].time, AmplitudeTime::Total);
    let shipped = plate_motion(&read_model(&dragged_deck()).expect("deck reads").model);
    for (what, spec) in [("carried", &carried), ("total time", &total)] {
        assert_same_motion(&plate_motion(spec), &shipped, what);
    }
    // the generated amplitude writes and reads back as it is
    let text = write_deck(&carried, &Default::default()).expect("the writer writes it");
    let again = read_deck_text(&text).expect("the written deck reads");
    assert_eq!(again.amplitudes, carried.amplitudes);
    assert_eq!(again.loads, carried.loads);
}

/// A motion given in the second step with a step-time amplitude that ends short of its value
/// (`(0, 0), (2, 1)` over a static step of period 1 reaches 0.5) and carried into a third
/// step: held at half the travel there, through the amplitude `drag@2` = `(1, 0), (2, 0.5)`
/// in the total time.
#[test]
fn a_motion_carried_into_a_third_step_holds_where_its_amplitude_left_it() {
    let text = std::fs::read_to_string(dragged_deck())
        .expect("read deck")
        .replacen(
            "*STEP",
            "*AMPLITUDE, NAME=drag\n0.0, 0.0, 2.0, 1.0\n*STEP",
            1,
        )
        .replace(
            "*BOUNDARY\nplate, 1, 1, 0.001",
            "*BOUNDARY, AMPLITUDE=drag\nplate, 1, 1, 0.001",
        )
        + "**\n*STEP, NAME=hold, NLGEOM=YES\n*STATIC, DIRECT\n0.25, 1.0\n*END STEP\n";
    let spec = read_deck_text(&text).expect("deck reads");
    assert_eq!(
        spec.amplitudes,
        [AmplitudeSpec {
            name: "drag@2".into(),
            points: vec![[1.0, 0.0], [2.0, 0.5]],
            time: AmplitudeTime::Total,
        }]
    );
    let motion = plate_motion(&spec);
    // the initial state, 4 increments of press, 20 of drag, 4 of hold
    assert_eq!(motion.len(), 29);
    assert!((motion[24].0 - 0.5e-3).abs() <= 1e-18, "{:?}", motion[24]);
    for (x, _) in &motion[25..] {
        assert_eq!(*x, motion[24].0, "held where the drag left it");
    }
}

/// A step's default amplitude: the drag step with `default_amplitude` `step` moves the plate
/// the whole 1 mm in its first increment and holds it there (its step factor 1 at once),
/// while the press, which still ramps, is unchanged; a deck says so with `*STEP,
/// AMPLITUDE=STEP`, which reads to the same model, and the writer writes it back.
#[test]
fn a_step_that_applies_its_loads_at_once_moves_the_plate_in_its_first_increment() {
    let ramped = plate_motion(&dragged_block(&[]));
    let at_once = dragged_block(&["steps[1].default_amplitude=\"step\""]);
    let motion = plate_motion(&at_once);
    assert_eq!(motion.len(), ramped.len());
    // the initial state and the 4 increments of the press, then the drag
    for (k, ((x, _), (x_ramped, _))) in motion.iter().zip(&ramped).enumerate() {
        if k <= 4 {
            assert_eq!(x, x_ramped, "increment {k}: the press is unchanged");
        } else {
            assert_eq!(*x, 1e-3, "increment {k}: the drag applied at once");
        }
    }
    let deck = dragged_block(&[
        "steps[1].default_amplitude=\"step\"",
        "part.section.quasi_static=false",
    ]);
    let text = write_deck(&deck, &Default::default()).expect("the writer writes it");
    assert!(
        text.contains("*STEP, NAME=drag, NLGEOM=YES, AMPLITUDE=STEP\n"),
        "{text}"
    );
    let read = read_deck_text(&text).expect("the written deck reads");
    assert_eq!(read.steps, deck.steps);
}

/// A dynamic step takes its loads and motions at once by default; with `default_amplitude`
/// `ramp` they go linearly over it from their value at the end of the previous step.
#[test]
fn a_dynamic_step_with_a_ramp_takes_its_motions_linearly() {
    let drag = r#"steps[1]={"type": "dynamic", "name": "drag", "duration": 0.01, "dt": 0.001}"#;
    let ramp = r#"steps[1]={"type": "dynamic", "name": "drag", "duration": 0.01, "dt": 0.001, "default_amplitude": "ramp"}"#;
    let halfway = LoadInstant {
        ramp: 1.0,
        step_time: 0.005,
        step: 1,
        fraction: 0.5,
    };
    for (set, expected) in [(drag, 1e-3), (ramp, 0.5e-3)] {
        let scene = model_file::build::<2>(&dragged_block(&[set])).expect("scene builds");
        let (_, motion) = &scene.model.prescribed()[0];
        assert_eq!(motion.at(&halfway), expected, "{set}");
    }
}
