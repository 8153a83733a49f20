//! A prescribed motion drags a block along a rigid flat: a massless slider tied to the block's
//! top is pressed down by a constant force N and moved sideways as prescribed (at rest in a
//! static preload, then at constant speed in a dynamic step). Checked: the slider follows the
//! prescription exactly; in every increment the reaction that moves it and the friction change
//! the momentum of block and slider by their impulse (both are the mean forces of the
//! increment); the friction is mu N whenever every contact slips; and the energy ledger closes
//! with the reaction's work. A prescription the model cannot take is refused.

use crate::common;

use nalgebra::{SVector, Vector3};
use skid_contact::plane::RigidPlane;
use skid_integrator::settings::Settings;
use skid_integrator::stepper::{IncrementReport, Observer, StaticIncrements, Step, StepKind, run};
use skid_integrator::{
    Amplitude, BodyMotion, ConcentratedLoad, ContactPair, LoadTarget, Loads, Model, MotionTarget,
    PrescribedMotion, State, StepVariation, Tie, Variation,
};

const MU: f64 = 0.3;
const NORMAL: f64 = 20.0;
/// Speed of the slider in the dynamic step, m/s.
const SPEED: f64 = 0.5;
const DURATION: f64 = 4e-3;

struct Record(Vec<State>);

impl<const D: usize> Observer<D> for Record {
    fn on_increment(&mut self, _: &Model<D>, r: &IncrementReport<'_>) -> std::io::Result<()> {
        self.0.push(r.state.clone());
        Ok(())
    }
}

/// The block of 4 x 1 elements (0.02 x 0.005 m, 0.01 m thick: 1 g) on the plane y = 0, its
/// top tied to a massless slider pressed down with `NORMAL` and moved along x: at rest over the
/// static preload, then `SPEED t` from the dynamic step's start.
fn dragged_block() -> Model<2> {
    let part = common::block_part([-0.01, 0.0], [0.02, 0.005], [4, 1], 0.01, 2.17e-6, false);
    let bottom = part.mesh.node_sets["ymin"].clone();
    let top = part.mesh.node_sets["ymax"].clone();
    let body = common::translating_body;
    let loads = Loads {
        concentrated: vec![ConcentratedLoad {
            target: LoadTarget::Body(1),
            force: SVector::<f64, 2>::new(0.0, -NORMAL),
            moment: Vector3::zeros(),
            variation: Variation::Ramp,
        }],
        ..Loads::default()
    };
    let ramp = Amplitude::new(vec![(0.0, 0.0), (DURATION, 1.0)]).expect("amplitude");
    Model::new(
        part,
        vec![
            body("ground", [false, false], 0.0),
            body("slider", [true, true], 0.005),
        ],
        vec![Tie {
            body: 1,
            nodes: top,
        }],
        loads,
        vec![ContactPair {
            name: "block-ground".into(),
            nodes: bottom,
            body: 0,
            surface: Box::new(RigidPlane::new(Vector3::y(), Vector3::x()).expect("plane")),
            mu: MU,
        }],
    )
    .expect("model")
    .with_prescribed_motions(vec![PrescribedMotion {
        target: MotionTarget::Body {
            body: 1,
            motion: BodyMotion::Translation(0),
        },
        value: SPEED * DURATION,
        variation: Variation::PerStep(vec![
            StepVariation::Ramp { from: 0.0, to: 0.0 },
            StepVariation::Amplitude {
                amplitude: ramp,
                scale: 1.0,
            },
        ]),
    }])
    .expect("prescribed motion")
}

fn steps() -> Vec<Step> {
    vec![
        Step {
            name: "press".into(),
            kind: StepKind::Static {
                increments: StaticIncrements::Fixed(4),
                regularization_time: 1e-2,
            },
            held: vec![],
        },
        Step {
            name: "drag".into(),
            kind: StepKind::Dynamic {
                duration: DURATION,
                dt: 5e-5,
                alpha: -0.3,
                adaptive: None,
            },
            held: vec![],
        },
    ]
}

#[test]
fn a_prescribed_slider_drags_the_block_against_exactly_mu_n() {
    let model = dragged_block();
    let mut record = Record(Vec::new());
    let (_, result) = run(&model, &steps(), &Settings::default(), &mut record);
    result.expect("run completes");
    let states = record.0;
    let dofs = model.dofs();
    let eq = dofs.body_translation(1)[0].expect("slider x");
    let y = dofs.body_translation(1)[1].expect("slider y");
    for s in &states {
        assert!(
            (s.x[eq] - SPEED * s.time).abs() <= 1e-15 * SPEED * DURATION,
            "slider at {} m at t = {}",
            s.x[eq],
            s.time
        );
        assert_eq!(s.reaction[y], 0.0, "the slider's y moves freely");
    }

    let drag: Vec<&State> = states.iter().filter(|s| s.time > 0.0).collect();
    let press_end = states
        .iter()
        .rev()
        .find(|s| s.time == 0.0)
        .expect("preload");
    let mut sliding = 0;
    let mut before = press_end;
    for &s in &drag {
        let t = s.time;
        let h = t - before.time;
        let friction: f64 = s.contacts.iter().map(|c| c.tangential_force[0]).sum();
        let normal: f64 = s.contacts.iter().map(|c| c.normal_force).sum();
        // the reaction and the friction are the mean forces of the increment: together they
        // change the momentum by their impulse
        let change = (model.linear_momentum(&s.v) - model.linear_momentum(&before.v))[0];
        assert!(
            (change - h * (s.reaction[eq] + friction)).abs() <= 1e-6 * h * NORMAL,
            "t = {t}: momentum change {change} against the impulse {}",
            h * (s.reaction[eq] + friction)
        );
        // every contact closed and slipping along +x (by more than round-off of the speed's
        // travel in the increment): friction is mu N against the motion
        if s.contacts
            .iter()
            .all(|c| c.is_closed() && c.slip[0] > 1e-9 * SPEED * h)
        {
            sliding += 1;
            assert!(
                (friction + MU * normal).abs() <= 1e-9 * MU * normal,
                "t = {t}: friction {friction} N, normal {normal} N"
            );
        }
        before = s;
    }
    assert!(
        sliding > drag.len() / 2,
        "{sliding} of {} increments slide",
        drag.len()
    );
    // the drag's energy: the reaction's work goes into the block's motion, its strain and the
    // friction; what is left is the trapezoidal rule's error on the nonlinear strain energy
    // (measured 2e-6 of the work at this step, 6e-7 and 2e-7 at half and a quarter of it)
    let last = &states[states.len() - 1];
    let work = last.energy.reaction_work - press_end.energy.reaction_work;
    let unaccounted = last.energy.unaccounted_since(&press_end.energy);
    assert!(
        work > 0.5 * MU * NORMAL * SPEED * DURATION,
        "reaction work {work} J"
    );
    assert!(
        unaccounted.abs() < 1e-5 * work,
        "energy unaccounted {unaccounted:e} J of the reaction's work {work:e} J"
    );
}

#[test]
fn prescriptions_the_model_cannot_take_are_refused() {
    let motion = |target| PrescribedMotion {
        target,
        value: 1e-3,
        variation: Variation::Ramp,
    };
    let slider_x = MotionTarget::Body {
        body: 1,
        motion: BodyMotion::Translation(0),
    };
    let cases = [
        (
            vec![motion(MotionTarget::Body {
                body: 0,
                motion: BodyMotion::Translation(0),
            })],
            "the model fixes this degree of freedom",
        ),
        (
            vec![motion(MotionTarget::Body {
                body: 2,
                motion: BodyMotion::Translation(0),
            })],
            "the body does not exist",
        ),
        // node 9 is on the block's top, tied to the slider
        (
            vec![motion(MotionTarget::Node { node: 9, axis: 0 })],
            "tied to rigid body 'slider'",
        ),
        (
            vec![motion(MotionTarget::Node { node: 0, axis: 2 })],
            "an axis below 2",
        ),
        (vec![motion(slider_x), motion(slider_x)], "prescribed twice"),
        (
            vec![PrescribedMotion {
                value: f64::NAN,
                ..motion(slider_x)
            }],
            "expected a finite value",
        ),
    ];
    for (motions, expected) in cases {
        let err = dragged_block()
            .with_prescribed_motions(motions)
            .map(|_| ())
            .expect_err(expected)
            .to_string();
        assert!(err.contains(expected), "{err}");
    }
}
