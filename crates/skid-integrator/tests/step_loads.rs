//! Loads that change between steps: a plane-strain cantilever whose tip load is ramped on,
//! doubled, removed in static steps and then follows a scaled amplitude in a dynamic step. The
//! applied force follows each step's variation at every increment, the doubled load reaches
//! the equilibrium of a single step at twice the load, and removing it brings the elastic beam
//! back to its reference shape.

mod common;

use nalgebra::SVector;
use skid_integrator::settings::Settings;
use skid_integrator::stepper::{IncrementReport, Observer, Step, StepKind, run};
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
            increments,
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
