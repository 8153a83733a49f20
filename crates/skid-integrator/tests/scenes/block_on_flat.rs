//! A block pressed on a rigid flat and pushed sideways: it sticks while the push is below
//! mu N, and slides with a friction force of exactly mu N above it. Every check runs with both
//! contact solves (global and reduced), which must also agree with each other.

use crate::common;

use nalgebra::Vector3;
use skid_contact::plane::RigidPlane;
use skid_integrator::settings::ContactSolve;
use skid_integrator::settings::Settings;
use skid_integrator::stepper::{
    Adaptive, Checkpoint, IncrementReport, Observer, RunStatistics, StaticIncrements, Step,
    StepKind, resume, run,
};
use skid_integrator::{ContactPair, Model, PressureLoad, State, Tie, Variation};

const MU: f64 = 0.3;
const WIDTH: f64 = 0.02;
const HEIGHT: f64 = 0.01;
const THICKNESS: f64 = 0.01;
const P_TOP: f64 = 1e5; // normal force N = P_TOP * WIDTH * THICKNESS = 20 N

struct Record(Vec<State>);

impl<const D: usize> Observer<D> for Record {
    fn on_increment(&mut self, _: &Model<D>, r: &IncrementReport<'_>) -> std::io::Result<()> {
        self.0.push(r.state.clone());
        Ok(())
    }
}

/// Block of 2 x 1 plane-strain elements on the plane y = 0; its top face is tied to a slider
/// that may translate in x and y; pressure on top and on the left face.
fn block(side_force: f64) -> (Model<2>, f64) {
    let part = common::block_part(
        [0.0, 0.0],
        [WIDTH, HEIGHT],
        [2, 1],
        THICKNESS,
        0.145e-6,
        false,
    );
    let bottom = part.mesh.node_sets["ymin"].clone();
    let top = part.mesh.node_sets["ymax"].clone();
    let top_faces = part.mesh.surfaces["ymax"].clone();
    let left_faces = part.mesh.surfaces["xmin"].clone();
    let body = common::translating_body;
    let model = Model::new(
        part,
        vec![
            body("ground", [false, false], 0.0),
            body("slider", [true, true], HEIGHT),
        ],
        vec![Tie {
            body: 1,
            nodes: top,
        }],
        vec![
            PressureLoad {
                faces: top_faces,
                pressure: P_TOP,
                variation: Variation::Ramp,
            },
            PressureLoad {
                faces: left_faces,
                pressure: side_force / (HEIGHT * THICKNESS),
                variation: Variation::Ramp,
            },
        ]
        .into(),
        vec![ContactPair {
            name: "block-ground".into(),
            nodes: bottom,
            body: 0,
            surface: Box::new(RigidPlane::new(Vector3::y(), Vector3::x()).expect("plane")),
            mu: MU,
        }],
    )
    .expect("model");
    let mass = 1000.0 * WIDTH * HEIGHT * THICKNESS;
    (model, mass)
}

/// Both ways of solving the contact problem of a Newton iteration.
const METHODS: [ContactSolve; 2] = [ContactSolve::Global, ContactSolve::Reduced];

/// Runs a static preload ramping both loads (if `preload`), then 2 ms of dynamics with HHT
/// parameter `alpha`, the contact forces of every Newton iteration from `method`.
fn simulate(
    side_force: f64,
    preload: bool,
    alpha: f64,
    method: ContactSolve,
) -> (Model<2>, f64, Vec<State>) {
    let (model, mass) = block(side_force);
    let mut steps = vec![Step {
        name: "push".into(),
        kind: StepKind::Dynamic {
            duration: 2e-3,
            dt: 2e-5,
            alpha,
            adaptive: None,
        },
        held: vec![],
    }];
    if preload {
        steps.insert(
            0,
            Step {
                name: "preload".into(),
                kind: StepKind::Static {
                    increments: StaticIncrements::Fixed(4),
                    regularization_time: 1e-2,
                },
                held: vec![],
            },
        );
    }
    let mut record = Record(Vec::new());
    let settings = Settings {
        contact_solve: method,
        ..Settings::default()
    };
    let (stats, result) = run(&model, &steps, &settings, &mut record);
    result.expect("run completes");
    // the global solve manages alone, the static preload included (where its plain semismooth
    // steps cycle between active sets, see `skid_integrator::increment`)
    assert_eq!(stats.contact_fallbacks, 0, "{method:?} preload {preload}");
    (model, mass, record.0)
}

#[test]
fn block_sticks_below_mu_n() {
    METHODS.into_iter().for_each(block_sticks_below_mu_n_with);
}

fn block_sticks_below_mu_n_with(method: ContactSolve) {
    let normal = P_TOP * WIDTH * THICKNESS;
    // Both loads ramp together in the static preload, so the push stays at half the friction
    // limit throughout; the dynamic step that follows must keep the block stuck.
    // (During the preload itself the bottom corners may slip outward as the block bulges.)
    let (_, _, states) = simulate(0.5 * MU * normal, true, -1.0 / 3.0, method);
    let states: Vec<State> = states.into_iter().filter(|s| s.time > 0.0).collect();
    assert_eq!(states.len(), 100);
    for s in &states {
        let n: f64 = s.contacts.iter().map(|c| c.normal_force).sum();
        let t: f64 = s.contacts.iter().map(|c| c.tangential_force[0]).sum();
        assert!(n > 0.0, "block must stay in contact");
        assert!(
            t.abs() <= MU * n * (1.0 + 1e-9),
            "friction {t} within the cone {n}"
        );
        for c in &s.contacts {
            assert!(
                c.slip[0].abs() < 1e-10,
                "stick: slip {} at t = {}",
                c.slip[0],
                s.time
            );
        }
    }
    // The mean friction force balances the push.
    let tail = &states[states.len() / 2..];
    let mean_t: f64 = tail
        .iter()
        .map(|s| {
            s.contacts
                .iter()
                .map(|c| c.tangential_force[0])
                .sum::<f64>()
        })
        .sum::<f64>()
        / tail.len() as f64;
    assert!(
        (mean_t.abs() - 0.5 * MU * normal).abs() < 0.05 * MU * normal,
        "{mean_t}"
    );
}

#[test]
fn block_slides_above_mu_n_with_friction_exactly_mu_n() {
    METHODS.into_iter().for_each(block_slides_with);
}

fn block_slides_with(method: ContactSolve) {
    let normal = P_TOP * WIDTH * THICKNESS;
    let push = 2.0 * MU * normal;
    // Loads applied suddenly: the block is pressed down and pushed at once.
    let (model, mass, states) = simulate(push, false, -1.0 / 3.0, method);
    let slider_x = model.dofs().body_translation(1)[0].expect("slider x is free");
    let mut sliding_seen = 0;
    for s in &states[1..] {
        // a force of round-off size (1e-19 N) is an open contact
        let carrying = |c: &&skid_integrator::state::ContactPointState| {
            c.is_closed() && c.normal_force > 1e-12 * normal
        };
        for c in s.contacts.iter().filter(carrying) {
            if c.slip[0].abs() > 1e-9 {
                sliding_seen += 1;
                let rt = c.tangential_force[0];
                assert!(
                    (rt.abs() - MU * c.normal_force).abs() <= 1e-7 * MU * c.normal_force,
                    "sliding friction {rt} vs mu N {}",
                    MU * c.normal_force
                );
                assert!(rt * c.slip[0] < 0.0, "friction opposes slip");
                assert!(
                    c.gap.abs() < 1e-9,
                    "no dilation while sliding: gap {}",
                    c.gap
                );
            }
        }
    }
    assert!(sliding_seen > 50, "the block slides");
    // Momentum: the push and the friction forces accelerate the whole block,
    // v(T) = sum_n h (push + sum_c r_T,c) / m, and once the normal force has settled the
    // friction force is mu times it.
    let mut expected = 0.0;
    for w in states.windows(2) {
        let friction: f64 = w[1].contacts.iter().map(|c| c.tangential_force[0]).sum();
        expected += (w[1].time - w[0].time) * (push + friction) / mass;
    }
    let last = states.last().expect("states");
    assert!(
        (last.v[slider_x] - expected).abs() < 0.02 * expected,
        "slider velocity {} vs {expected}",
        last.v[slider_x]
    );
    let total = |s: &State, f: &dyn Fn(&skid_integrator::state::ContactPointState) -> f64| {
        s.contacts.iter().map(f).sum::<f64>()
    };
    let n = total(last, &|c| c.normal_force);
    let t = total(last, &|c| c.tangential_force[0]);
    assert!(
        (t + MU * n).abs() < 1e-7 * MU * n,
        "friction {t} = -mu N {}",
        MU * n
    );
}

/// Loads applied suddenly with the trapezoidal rule (alpha = 0, no numerical dissipation): the
/// bottom nodes bounce and slide, contacts open and close many times. The contact impulses are
/// integrated so that their work is exactly `p . du` (see `skid_integrator::hht`), so the
/// energy ledger must close: kinetic + strain + hourglass = pressure work + normal contact work
/// minus friction dissipation, up to the trapezoidal rule's error on the nonlinear forces. A contact
/// force that kept acting after its contact opened would break this balance.
#[test]
fn energy_balance_closes_through_contact_chatter() {
    METHODS.into_iter().for_each(energy_balance_closes_with);
}

fn energy_balance_closes_with(method: ContactSolve) {
    let normal = P_TOP * WIDTH * THICKNESS;
    let (_, _, states) = simulate(2.0 * MU * normal, false, 0.0, method);
    let mut switches = 0;
    for w in states.windows(2) {
        for (a, b) in w[0].contacts.iter().zip(&w[1].contacts) {
            if a.is_closed() != b.is_closed() {
                switches += 1;
            }
        }
    }
    assert!(
        switches >= 5,
        "contacts open and close: {switches} switches"
    );
    let last = states.last().expect("states");
    assert!(last.energy.friction_dissipation > 0.0, "the block slides");
    let mut worst: f64 = 0.0;
    for s in &states {
        let e = &s.energy;
        let residual = e.kinetic + e.strain + e.hourglass - e.external_work - e.normal_work
            + e.friction_dissipation;
        worst = worst.max(residual.abs());
    }
    let scale = last.energy.external_work;
    assert!(
        worst <= 1e-4 * scale,
        "energy balance residual {worst:e} J vs pressure work {scale:e} J ({switches} switches)"
    );
}

/// The global and the reduced contact solves converge to the same increments: through the
/// sudden load, contact chatter and sliding of the trapezoidal run, every state's contact
/// forces and positions agree to the Newton tolerances.
#[test]
fn global_and_reduced_solves_give_the_same_run() {
    let normal = P_TOP * WIDTH * THICKNESS;
    let runs = METHODS.map(|method| simulate(2.0 * MU * normal, false, 0.0, method).2);
    let [global, reduced] = &runs;
    assert_eq!(global.len(), reduced.len());
    let force_scale = normal;
    let mut worst_force: f64 = 0.0;
    let mut worst_position: f64 = 0.0;
    for (a, b) in global.iter().zip(reduced) {
        assert_eq!(a.time, b.time);
        for (ca, cb) in a.contacts.iter().zip(&b.contacts) {
            worst_force = worst_force
                .max((ca.normal_force - cb.normal_force).abs())
                .max((ca.tangential_force - cb.tangential_force).amax());
        }
        worst_position = worst_position.max((&a.x - &b.x).amax());
    }
    assert!(
        worst_force <= 1e-4 * force_scale && worst_position <= 1e-7 * WIDTH,
        "forces differ by {worst_force:e} N, positions by {worst_position:e} m"
    );
}

/// Records every reported state and takes a checkpoint after every increment.
struct Checkpointing {
    states: Vec<State>,
    checkpoints: Vec<Checkpoint>,
}

impl<const D: usize> Observer<D> for Checkpointing {
    fn on_increment(&mut self, _: &Model<D>, r: &IncrementReport<'_>) -> std::io::Result<()> {
        self.states.push(r.state.clone());
        Ok(())
    }

    fn wants_checkpoint(&mut self, _boundary: bool) -> bool {
        true
    }

    fn on_checkpoint(&mut self, _: &Model<D>, checkpoint: &Checkpoint) -> std::io::Result<()> {
        self.checkpoints.push(checkpoint.clone());
        Ok(())
    }
}

/// A state as JSON: the shortest decimals that read back to each value's bits, so equal text
/// is equal bits.
fn bits(state: &State) -> String {
    serde_json::to_string(state).expect("state as JSON")
}

/// The counters of `stats` (its wall times, the steps' included, zeroed).
fn counters(stats: &RunStatistics) -> RunStatistics {
    let mut steps = stats.steps.clone();
    for step in &mut steps {
        step.wall_time = Default::default();
    }
    RunStatistics {
        timings: Default::default(),
        wall_time: Default::default(),
        steps,
        ..stats.clone()
    }
}

#[test]
fn a_run_resumed_from_any_checkpoint_continues_bit_for_bit() {
    // below mu N the block sticks through a preload and two dynamic steps; above, it slides
    // through the dynamic steps alone (no static equilibrium)
    for (side_force, first) in [(4.0, 0), (15.0, 1)] {
        resumes_bit_for_bit(side_force, first);
    }
}

/// Every third checkpoint of a run with `side_force` over the steps from `first` on (a preload,
/// a dynamic step, an adaptive one) resumed: the same states, bits and counters.
fn resumes_bit_for_bit(side_force: f64, first: usize) {
    let (model, _) = block(side_force);
    let mut steps = vec![
        Step {
            name: "preload".into(),
            kind: StepKind::Static {
                increments: StaticIncrements::Fixed(3),
                regularization_time: 1e-2,
            },
            held: vec![],
        },
        Step {
            name: "push".into(),
            kind: StepKind::Dynamic {
                duration: 4e-4,
                dt: 2e-5,
                alpha: -0.1,
                adaptive: None,
            },
            held: vec![],
        },
        Step {
            name: "adaptive".into(),
            kind: StepKind::Dynamic {
                duration: 4e-4,
                dt: 2e-5,
                alpha: -0.1,
                adaptive: Some(Adaptive {
                    tolerance: 1e-7,
                    min_dt: 1e-6,
                    max_dt: 1e-4,
                }),
            },
            held: vec![],
        },
    ];
    steps.drain(..first);
    for method in METHODS {
        let settings = Settings {
            contact_solve: method,
            ..Settings::default()
        };
        let mut whole = Checkpointing {
            states: Vec::new(),
            checkpoints: Vec::new(),
        };
        let (stats, result) = run(&model, &steps, &settings, &mut whole);
        let end = result.expect("run completes");
        // one checkpoint per reported state (the initial one included)
        assert_eq!(whole.checkpoints.len(), whole.states.len());
        assert!(
            whole.states.len() > 25,
            "{method:?}: {}",
            whole.states.len()
        );
        for (k, checkpoint) in whole.checkpoints.iter().enumerate().step_by(3) {
            // through its text, as a restart file holds it
            let text = serde_json::to_string(checkpoint).expect("checkpoint as JSON");
            let checkpoint: Checkpoint = serde_json::from_str(&text).expect("read back");
            assert_eq!(bits(&checkpoint.state), bits(&whole.states[k]));
            let mut rest = Checkpointing {
                states: Vec::new(),
                checkpoints: Vec::new(),
            };
            let (resumed, result) = resume(&model, &steps, &settings, &mut rest, &checkpoint);
            let resumed_end = result.expect("resumed run completes");
            assert_eq!(
                rest.states.len(),
                whole.states.len() - k - 1,
                "{method:?} at {k}"
            );
            for (a, b) in rest.states.iter().zip(&whole.states[k + 1..]) {
                assert_eq!(bits(a), bits(b), "{method:?}: resumed at {k}");
            }
            assert_eq!(bits(&resumed_end), bits(&end), "{method:?}: resumed at {k}");
            assert_eq!(
                counters(&resumed),
                counters(&stats),
                "{method:?}: resumed at {k}"
            );
        }
    }
}

#[test]
fn a_checkpoint_of_another_model_is_refused_not_a_panic() {
    let (model, _) = block(15.0);
    let steps = vec![Step {
        name: "push".into(),
        kind: StepKind::Dynamic {
            duration: 1e-4,
            dt: 2e-5,
            alpha: -0.1,
            adaptive: None,
        },
        held: vec![],
    }];
    let mut whole = Checkpointing {
        states: Vec::new(),
        checkpoints: Vec::new(),
    };
    let settings = Settings::default();
    let (_, result) = run(&model, &steps, &settings, &mut whole);
    result.expect("run completes");
    let mut shorter = whole.checkpoints[2].clone();
    shorter.state.x = shorter.state.x.rows(0, 3).into_owned();
    let mut late = whole.checkpoints[2].clone();
    late.step = 5;
    let mut wrong_solver = whole.checkpoints[2].clone();
    if let Some(m) = wrong_solver.solver.global.factored.as_mut() {
        m.values.pop();
    }
    wrong_solver.solver.trailing = vec![usize::MAX];
    for bad in [shorter, late, wrong_solver] {
        let (_, result) = resume(&model, &steps, &settings, &mut Record(Vec::new()), &bad);
        let error = result.expect_err("refused");
        assert!(error.to_string().contains("checkpoint"), "{error}");
    }
}
