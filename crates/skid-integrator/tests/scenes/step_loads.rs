//! Loads that change between steps: a plane-strain cantilever whose tip load is ramped on,
//! doubled, removed in static steps and then follows a scaled amplitude in a dynamic step. The
//! applied force follows each step's variation at every increment, the doubled load reaches
//! the equilibrium of a single step at twice the load, and removing it brings the elastic beam
//! back to its reference shape.

use crate::common;

use nalgebra::SVector;
use skid_integrator::settings::Settings;
use skid_integrator::stepper::{IncrementReport, Observer, StaticIncrements, Step, StepKind, run};
use skid_integrator::{
    Amplitude, ConcentratedLoad, LoadTarget, Loads, Model, RunError, State, StepVariation, Tie,
    Variation,
};

/// Force on each tip node at factor 1, N (downwards).
const TIP_FORCE: f64 = -0.2;
/// Duration of the dynamic step, s.
const DURATION: f64 = 1e-3;

/// Every converged increment: step, its end time, the state.
#[derive(Default)]
struct Record(Vec<(String, State)>);

impl<const D: usize> Observer<D> for Record {
    fn on_increment(&mut self, _: &Model<D>, r: &IncrementReport<'_>) -> std::io::Result<()> {
        self.0.push((r.step.to_string(), r.state.clone()));
        Ok(())
    }
}

/// A 20 x 2 cantilever 0.1 m long and 0.01 m high (the pad material, nearly incompressible),
/// clamped at x = 0 to a held wall, with the tip load varying as `variation`.
fn cantilever(variation: Variation) -> (Model<2>, Vec<usize>) {
    let part = common::block_part([0.0, 0.0], [0.1, 0.01], [20, 2], 0.01, 1.45e-7, false);
    let clamped = part.mesh.node_sets["xmin"].clone();
    let tip = part.mesh.node_sets["xmax"].clone();
    let wall = common::translating_body("wall", [false, false], 0.0);
    let loads = Loads {
        concentrated: vec![ConcentratedLoad {
            target: LoadTarget::Nodes(tip.clone()),
            force: SVector::<f64, 2>::new(0.0, TIP_FORCE),
            moment: nalgebra::Vector3::zeros(),
            variation,
        }],
        ..Loads::default()
    };
    let tie = Tie {
        body: 0,
        nodes: clamped,
    };
    let model = Model::new(part, vec![wall], vec![tie], loads, vec![]).expect("model");
    (model, tip)
}

fn static_step(name: &str, increments: usize) -> Step {
    Step {
        name: name.into(),
        kind: StepKind::Static {
            increments: StaticIncrements::Fixed(increments),
            regularization_time: 1.0,
        },
        held: vec![],
    }
}

fn ramp(from: f64, to: f64) -> StepVariation {
    StepVariation::Ramp { from, to }
}

/// The applied vertical force on the tip nodes, over the tip force.
fn applied_factor(model: &Model<2>, tip: &[usize], state: &State) -> f64 {
    let total: f64 = tip
        .iter()
        .filter_map(|&n| model.dofs().node(n)[1])
        .map(|eq| state.external_force[eq])
        .sum();
    total / (TIP_FORCE * tip.len() as f64)
}

/// Vertical displacement of the tip's first node.
fn deflection(model: &Model<2>, tip: &[usize], state: &State) -> f64 {
    model.dofs().node_displacement(&state.x, tip[0])[1]
}

#[test]
fn a_load_follows_its_variation_in_every_step() {
    let rise = Amplitude::new(vec![(0.0, 0.0), (DURATION, 1.0)]).expect("amplitude");
    let per_step = vec![
        ramp(0.0, 1.0),
        ramp(1.0, 2.0),
        ramp(2.0, 0.0),
        StepVariation::Amplitude {
            amplitude: rise,
            scale: 0.5,
        },
    ];
    let (model, tip) = cantilever(Variation::PerStep(per_step));
    let steps = [
        static_step("load", 2),
        static_step("double", 4),
        static_step("remove", 2),
        Step {
            name: "shake".into(),
            kind: StepKind::Dynamic {
                duration: DURATION,
                dt: DURATION / 5.0,
                alpha: -0.1,
                adaptive: None,
            },
            held: vec![],
        },
    ];
    let mut record = Record::default();
    let (_, result) = run(&model, &steps, &Settings::default(), &mut record);
    result.expect("the run completes");

    // the factor at the end of each increment: the step's ramp at its completed fraction, the
    // amplitude's value at the step time in the dynamic step
    let expected = [
        ("load", vec![0.5, 1.0]),
        ("double", vec![1.25, 1.5, 1.75, 2.0]),
        ("remove", vec![1.0, 0.0]),
        ("shake", vec![0.1, 0.2, 0.3, 0.4, 0.5]),
    ];
    let names: Vec<&str> = steps.iter().map(|s| s.name.as_str()).collect();
    let taken: Vec<&(String, State)> = record
        .0
        .iter()
        .filter(|(name, _)| names.contains(&name.as_str()))
        .collect();
    let mut increments = taken.iter();
    for (step, factors) in expected {
        for factor in factors {
            let (name, state) = increments.next().expect("an increment");
            assert_eq!(name, step);
            let applied = applied_factor(&model, &tip, state);
            assert!(
                (applied - factor).abs() < 1e-12,
                "step {step}: factor {applied}, expected {factor}"
            );
        }
    }
    assert!(
        increments.next().is_none(),
        "more increments than steps ask"
    );

    // the doubled load reaches the equilibrium of one step at twice the load
    let doubled = &taken[5].1;
    let (single, single_tip) = cantilever(Variation::PerStep(vec![ramp(0.0, 2.0)]));
    let mut once = Record::default();
    let (_, result) = run(
        &single,
        &[static_step("at once", 6)],
        &Settings::default(),
        &mut once,
    );
    let at_once = result.expect("single step converges");
    let (a, b) = (
        deflection(&model, &tip, doubled),
        deflection(&single, &single_tip, &at_once),
    );
    assert!(a < 0.0, "the load bends the beam down: {a}");
    assert!((a - b).abs() < 1e-6 * b.abs(), "{a} against {b}");

    // without load the elastic beam is back in its reference shape
    let removed = &taken[7].1;
    let back = removed.x.amax();
    assert!(
        back < 1e-7 * a.abs(),
        "displacement {back} left after removal"
    );
}

#[test]
fn a_variation_for_another_number_of_steps_is_refused() {
    let (model, _) = cantilever(Variation::PerStep(vec![ramp(0.0, 1.0)]));
    let steps = [static_step("load", 1), static_step("hold", 1)];
    let (_, result) = run(&model, &steps, &Settings::default(), &mut Record::default());
    match result {
        Err(RunError::Invalid(message)) => assert!(
            message.contains("varies in 1 steps, the run has 2"),
            "{message}"
        ),
        other => panic!("expected the steps to be refused, got {other:?}"),
    }
}

/// Automatic increments of a static step: they start at the initial size, grow by 1.5 after
/// two easy increments (this linear-ish bending converges in a few Newton iterations), land on
/// the step's end, and reach the equilibrium of fixed increments; invalid sizes are refused.
#[test]
fn automatic_static_increments_grow_and_land_on_the_step_end() {
    let automatic = |initial: f64, min: f64, max: f64| Step {
        name: "load".into(),
        kind: StepKind::Static {
            increments: StaticIncrements::Automatic { initial, min, max },
            regularization_time: 1.0,
        },
        held: vec![],
    };
    let (model, tip) = cantilever(Variation::PerStep(vec![ramp(0.0, 2.0)]));
    let mut record = Record::default();
    let (_, result) = run(
        &model,
        &[automatic(0.1, 1e-5, 0.4)],
        &Settings::default(),
        &mut record,
    );
    let end = result.expect("automatic increments converge");
    let factors: Vec<f64> = record
        .0
        .iter()
        .filter(|(name, _)| name == "load")
        .map(|(_, state)| applied_factor(&model, &tip, state) / 2.0)
        .collect();
    let sizes: Vec<f64> = std::iter::once(0.0)
        .chain(factors.iter().copied())
        .collect::<Vec<_>>()
        .windows(2)
        .map(|w| w[1] - w[0])
        .collect();
    assert!((sizes[0] - 0.1).abs() < 1e-12, "{sizes:?}");
    assert!(sizes.iter().all(|s| *s <= 0.4 + 1e-12), "{sizes:?}");
    assert!(
        sizes.windows(2).any(|w| w[1] > 1.4 * w[0]),
        "the size grows: {sizes:?}"
    );
    assert!(sizes.len() < 10, "fewer than fixed 0.1 steps: {sizes:?}");
    assert_eq!(*factors.last().expect("increments"), 1.0);
    let mut fixed = Record::default();
    let (_, result) = run(
        &model,
        &[static_step("load", 10)],
        &Settings::default(),
        &mut fixed,
    );
    let reference = result.expect("fixed increments converge");
    let (a, b) = (
        deflection(&model, &tip, &end),
        deflection(&model, &tip, &reference),
    );
    assert!((a - b).abs() < 1e-6 * b.abs(), "{a} against {b}");

    for (initial, min, max) in [(0.5, 0.6, 1.0), (0.1, 0.0, 1.0), (0.5, 0.1, 1.5)] {
        let (_, result) = run(
            &model,
            &[automatic(initial, min, max)],
            &Settings::default(),
            &mut Record::default(),
        );
        assert!(
            matches!(&result, Err(RunError::Invalid(m)) if m.contains("0 < min <= initial")),
            "{result:?}"
        );
    }
}

/// An automatic static step whose increments cannot converge (one Newton iteration allowed)
/// is cut back by the settings' factor until the next size would fall below its minimum, and
/// then fails with the size it last tried, rather than crawl on.
#[test]
fn automatic_static_increments_stop_at_their_minimum() {
    let (model, _) = cantilever(Variation::PerStep(vec![ramp(0.0, 2.0)]));
    let mut settings = Settings::default();
    settings.newton.max_iterations = 1;
    let step = Step {
        name: "load".into(),
        kind: StepKind::Static {
            increments: StaticIncrements::Automatic {
                initial: 0.5,
                min: 0.1,
                max: 1.0,
            },
            regularization_time: 1.0,
        },
        held: vec![],
    };
    let (_, result) = run(&model, &[step], &settings, &mut Record::default());
    let factor = settings.cutback.factor;
    let mut tried = vec![0.5];
    while tried[tried.len() - 1] * factor >= 0.1 {
        tried.push(tried[tried.len() - 1] * factor);
    }
    match result {
        Err(RunError::StepFailed {
            increment,
            size,
            cutbacks,
            ..
        }) => {
            assert_eq!(increment, 1);
            assert_eq!(size, tried[tried.len() - 1], "sizes tried {tried:?}");
            assert_eq!(cutbacks, tried.len() - 1);
        }
        other => panic!("expected the step to fail at its minimum, got {other:?}"),
    }
}
