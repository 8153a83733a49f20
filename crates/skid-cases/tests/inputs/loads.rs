//! Verification scenes of concentrated loads, gravity and amplitudes (`cases/verification/`):
//! a block pushed sideways on a rigid flat sticks below mu N and slides at exactly mu N above it;
//! a block pushed up an incline under gravity slides exactly past the Coulomb threshold.
//!
//! Every scene runs in a dynamic step, whose contact forces act as impulses: the velocity of a
//! contact node that sticks flips sign every increment (the trapezoidal rule with its position
//! held), and the mean contact force of an increment alternates about the static value by as
//! much. The forces are therefore compared as the mean of two successive increments, which is
//! the static value.

use std::path::{Path, PathBuf};

use skid_cases::model_file::{self, parse_model};
use skid_cases::model_spec::LoadSpec;
use skid_cases::model_spec::ModelSpec;
use skid_integrator::stepper::{IncrementReport, Observer, run};
use skid_integrator::{Model, State};

const MU: f64 = 0.3;
/// Width of the block, m.
const WIDTH: f64 = 0.02;
/// Mass of the block, kg: 1000 kg/m^3 times 0.02 x 0.005 x 0.01 m (the 2D thickness or the 3D
/// depth).
const MASS: f64 = 1e-3;

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(path)
}

/// The shipped scene `name` with `overrides`.
fn scene_spec(name: &str, overrides: &[String]) -> ModelSpec {
    let path = repo(&format!("cases/verification/{name}.json"));
    let text = std::fs::read_to_string(&path).expect("read scene");
    parse_model(&text, &path, overrides).expect("scene parses")
}

/// Keeps every converged state.
struct Record(Vec<State>);

impl<const D: usize> Observer<D> for Record {
    fn on_increment(&mut self, _: &Model<D>, r: &IncrementReport<'_>) -> std::io::Result<()> {
        self.0.push(r.state.clone());
        Ok(())
    }
}

/// Runs `spec` in dimension `D`; the model and every converged state.
fn simulate<const D: usize>(spec: &ModelSpec) -> (Model<D>, Vec<State>) {
    let scene = model_file::build::<D>(spec).expect("scene builds");
    let mut record = Record(Vec::new());
    let (_, result) = run(&scene.model, &scene.steps, &scene.settings, &mut record);
    result.expect("run completes");
    (scene.model, record.0)
}

/// Friction (along x) and normal resultants of a state's contacts, N.
fn resultants(state: &State) -> (f64, f64) {
    let t = state.contacts.iter().map(|c| c.tangential_force[0]).sum();
    let n = state.contacts.iter().map(|c| c.normal_force).sum();
    (t, n)
}

/// The resultants as the mean of the last two increments (see the module documentation).
fn static_resultants(states: &[State]) -> (f64, f64) {
    let [.., a, b] = states else {
        panic!("fewer than two states");
    };
    let ((ta, na), (tb, nb)) = (resultants(a), resultants(b));
    (0.5 * (ta + tb), 0.5 * (na + nb))
}

/// A force along x in dimension `D`, as a `--set` value.
fn push_override(load: usize, components: [f64; 2], dim: usize) -> String {
    let mut v = components.to_vec();
    v.resize(dim, 0.0);
    format!("loads[{load}].force={v:?}")
}

/// The plate's translation equation along x (the slope).
fn plate_x<const D: usize>(model: &Model<D>) -> usize {
    let plate = model.body_index("plate").expect("plate");
    model.dofs().body_translation(plate)[0].expect("the plate moves along x")
}

/// A block (1 g, 4 x 1 elements, Poisson's ratio 0) on a fixed rigid flat with mu = 0.3, its
/// top tied to a massless plate loaded by N = 20 N (ramped over 0-10 ms) and a sideways push F
/// (ramped over 15-25 ms, held to 40 ms), in a dynamic step.
///
/// Coulomb's law at every contact node `i`, `|T_i| <= mu N_i`, summed: the friction resultant
/// can balance F only while `F <= mu N = 6 N`.
/// - F = 3 N = 0.5 mu N: the block sticks. From the moment the push starts, no contact node
///   slips more than 1e-9 of the block's width in all (measured: 2e-17 m), and at the end the
///   friction resultant is -F to 1e-5 (measured 6.4e-7: the shear vibration the ramp left) and
///   the normal one N to 1e-6.
/// - F = 9 N = 1.5 mu N: once every contact slides along +x (its slip across it below 1e-3 of
///   its slip along it: in 3D the slip directions first settle), each carries exactly
///   `T_i = -mu N_i`, so the friction resultant is exactly -mu times the normal one (to 1e-6;
///   the Coulomb tolerance is 1e-8; measured 3e-16 in 2D, 8e-9 in 3D), the normal one is N (to
///   1e-4: the plate bounces a little on the block), and the block accelerates at
///   `(F - mu N) / m = 3000 m/s^2` (to 1e-4, measured 5e-6, from the plate's velocity over the
///   last 10 ms).
#[test]
fn a_block_pushed_below_mu_n_sticks_and_above_slides_at_exactly_mu_n() {
    block_pushed::<2>();
    block_pushed::<3>();
}

fn block_pushed<const D: usize>() {
    let name = format!("{D}d-block-pushed-on-flat");
    let normal = 20.0;
    let push_start = 0.015;

    let stick = 0.5 * MU * normal;
    let spec = scene_spec(&name, &[push_override(1, [stick, 0.0], D)]);
    let (_, states) = simulate::<D>(&spec);
    let mut slip = vec![0.0; states[0].contacts.len()];
    for s in states.iter().filter(|s| s.time > push_start) {
        for (total, c) in slip.iter_mut().zip(&s.contacts) {
            *total += c.slip.norm();
        }
    }
    let worst = slip.iter().copied().fold(0.0, f64::max);
    assert!(
        worst < 1e-9 * WIDTH,
        "{D}D stick: a node slipped {worst:e} m"
    );
    let (t, n) = static_resultants(&states);
    assert!(
        (t + stick).abs() < 1e-5 * stick && (n - normal).abs() < 1e-6 * normal,
        "{D}D stick: friction {t} N against the push {stick} N, normal {n} N"
    );

    let push = 1.5 * MU * normal;
    let spec = scene_spec(&name, &[]);
    let (model, states) = simulate::<D>(&spec);
    let mut sliding = 0;
    for s in &states {
        let aligned = s.contacts.iter().all(|c| {
            c.normal_force > 0.0 && c.slip[0] > 0.0 && c.slip[1].abs() <= 1e-3 * c.slip[0]
        });
        if !aligned {
            continue;
        }
        sliding += 1;
        let (t, n) = resultants(s);
        assert!(
            (t + MU * n).abs() <= 1e-6 * MU * n,
            "{D}D slide at t = {}: friction {t} N, normal {n} N",
            s.time
        );
        assert!(
            (n - normal).abs() < 1e-4 * normal,
            "{D}D slide at t = {}: normal {n} N",
            s.time
        );
    }
    assert!(sliding >= 30, "{D}D: {sliding} sliding increments");
    let eq = plate_x(&model);
    let last = states.last().expect("states");
    let earlier = states
        .iter()
        .rev()
        .find(|s| s.time <= last.time - 0.01 + 1e-9)
        .expect("10 ms earlier");
    let acceleration = (last.v[eq] - earlier.v[eq]) / (last.time - earlier.time);
    let expected = (push - MU * normal) / MASS;
    assert!(
        (acceleration - expected).abs() < 1e-4 * expected,
        "{D}D slide: acceleration {acceleration} m/s^2, expected {expected}"
    );
}

/// The block of the push scene on a rigid incline of angle a = 10 degrees (mu = 0.3) under its
/// weight G = m g (g = 9.81 m/s^2, m = 1 g: the lumped masses `rho V / 2^D`, with the 2D
/// thickness) and a horizontal push F, both ramped over 10 ms and held to 40 ms. The scene is
/// turned so that the incline is the plane y = 0: gravity `g (-sin a, -cos a)`, push
/// `F (cos a, -sin a)`.
///
/// In equilibrium along and across the slope, `T = F cos a - G sin a` and
/// `N = G cos a + F sin a`; `T <= mu N` holds while
/// `F (cos a - mu sin a) <= G (sin a + mu cos a)`, that is up to the threshold
/// `F / G = (tan a + mu) / (1 - mu tan a) = 0.50293`.
/// - At 0.995 times the threshold the block sticks: over the last 20 ms the plate moves less
///   than 1e-9 of the block's width, and the friction and normal resultants are T and N above
///   (to 1e-6; measured 4e-10 and 1e-12).
/// - At 1.005 times it slides up the slope: over the last 20 ms every contact slides, with a
///   friction resultant of exactly -mu times the normal one (to 1e-6), and the block
///   accelerates at `(F (cos a - mu sin a) - G (sin a + mu cos a)) / m
///   = 0.005 g (sin a + mu cos a) = 0.0230 m/s^2` (to 1e-3; measured 1.4e-5).
///
/// So the threshold lies within 0.5 % of the Coulomb value. The 2D scene's deck
/// (`2d-block-on-incline-deck.inp`: `*AMPLITUDE`, `*DLOAD` with `GRAV`, `*CLOAD` on the plate's
/// reference node) reads to the same loads and amplitudes, bit for bit, and passes the same
/// checks.
#[test]
fn a_block_on_an_incline_slides_up_exactly_past_the_coulomb_threshold() {
    block_on_incline::<2>(&scene_spec("2d-block-on-incline", &[]));
    block_on_incline::<3>(&scene_spec("3d-block-on-incline", &[]));
    let deck =
        skid_cases::deck::read_model(&repo("cases/verification/2d-block-on-incline-deck.inp"))
            .expect("deck reads")
            .model;
    let json = scene_spec("2d-block-on-incline", &[]);
    assert_eq!(
        (&deck.loads, &deck.amplitudes),
        (&json.loads, &json.amplitudes)
    );
    block_on_incline::<2>(&deck);
}

/// `spec` with the force of its load `load` (a concentrated load) set to `force`.
fn with_force(spec: &ModelSpec, load: usize, force: Vec<f64>) -> ModelSpec {
    let mut spec = spec.clone();
    match &mut spec.loads[load] {
        LoadSpec::Concentrated { force: f, .. } => *f = Some(force),
        other => panic!("load {load} is {other:?}"),
    }
    spec
}

fn block_on_incline<const D: usize>(scene: &ModelSpec) {
    let (a, g) = (10f64.to_radians(), 9.81);
    let weight = MASS * g;
    let threshold = (a.tan() + MU) / (1.0 - MU * a.tan());
    let hold_from = 0.02;

    let low = 0.995 * threshold * weight;
    let mut force = vec![low * a.cos(), -low * a.sin()];
    force.resize(D, 0.0);
    let spec = with_force(scene, 1, force);
    let (model, states) = simulate::<D>(&spec);
    let eq = plate_x(&model);
    let held: Vec<&State> = states.iter().filter(|s| s.time >= hold_from).collect();
    let moved = held
        .iter()
        .map(|s| (s.x[eq] - held[0].x[eq]).abs())
        .fold(0.0, f64::max);
    assert!(
        moved < 1e-9 * WIDTH,
        "{D}D below: the block moved {moved:e} m"
    );
    let (t, n) = static_resultants(&states);
    let (t_static, n_static) = (
        low * a.cos() - weight * a.sin(),
        weight * a.cos() + low * a.sin(),
    );
    assert!(
        (t + t_static).abs() < 1e-6 * t_static && (n - n_static).abs() < 1e-6 * n_static,
        "{D}D below: friction {t} N (expected {}), normal {n} N (expected {n_static})",
        -t_static
    );

    let (model, states) = simulate::<D>(scene);
    let eq = plate_x(&model);
    let held: Vec<&State> = states.iter().filter(|s| s.time >= hold_from).collect();
    for s in &held {
        assert!(
            s.contacts.iter().all(|c| c.slip[0] > 0.0),
            "{D}D above: a contact sticks at t = {}",
            s.time
        );
        let (t, n) = resultants(s);
        assert!(
            (t + MU * n).abs() <= 1e-6 * MU * n,
            "{D}D above at t = {}: friction {t} N, normal {n} N",
            s.time
        );
    }
    let (first, last) = (held[0], held[held.len() - 1]);
    let acceleration = (last.v[eq] - first.v[eq]) / (last.time - first.time);
    let expected = 0.005 * g * (a.sin() + MU * a.cos());
    assert!(
        (acceleration - expected).abs() < 1e-3 * expected,
        "{D}D above: acceleration {acceleration} m/s^2, expected {expected}"
    );
}

/// Amplitudes are read against the step time, so they start again with every step. The push
/// scene (at F = 3 N, which the block holds) first settles in a static step, whose step time
/// runs from 0 to 1, so both loads stand at full value at its end; the dynamic step then starts
/// at step time 0, where both amplitudes are 0: the loads drop at once, without work (nothing
/// moves at that instant), and the block springs up off the flat before the loads ramp again.
/// The ledger must take the loads as they stand at the step's start: the work of the first
/// dynamic increment by the trapezoidal rule is `(f(0) + f_1) / 2 . dx` with `f(0) = 0`, not
/// with the static step's 20 N. Over the release the ledger then balances to 1e-3 of the strain
/// energy the static step stored (20 us steps, alpha = 0; what is left is the trapezoidal
/// rule's error on the strain energy: the summary's energy balance error of this run is
/// 1.7 % at 0.5 ms steps, 0.27 % at 0.1 ms, 0.014 % at 20 us).
#[test]
fn loads_whose_amplitudes_restart_with_a_step_jump_there_without_work() {
    let overrides = [
        push_override(1, [3.0, 0.0], 2),
        concat!(
            r#"steps=[{"type": "static", "name": "settle", "increments": 2}, "#,
            r#"{"type": "dynamic", "name": "release", "duration": 0.005, "dt": 2e-5, "alpha": 0.0}]"#
        )
        .to_string(),
    ];
    let spec = scene_spec("2d-block-pushed-on-flat", &overrides);
    let (_, states) = simulate::<2>(&spec);
    let settled = states
        .iter()
        .rposition(|s| s.time == 0.0)
        .expect("static step");
    let (s0, s1) = (&states[settled], &states[settled + 1]);
    let (_, n0) = resultants(s0);
    assert!((n0 - 20.0).abs() < 1e-6, "settled on {n0} N");
    let work = s1.energy.external_work - s0.energy.external_work;
    let dx = &s1.x - &s0.x;
    let trapezoid = 0.5 * s1.external_force.dot(&dx);
    let stale = 0.5 * s0.external_force.dot(&dx);
    assert!(
        (work - trapezoid).abs() < 1e-9 * stale.abs(),
        "work of the first increment {work:e} J; from the loads at the step's start \
         {trapezoid:e} J, from those of the static step's end {:e} J",
        trapezoid + stale
    );
    assert!(
        states[settled..].iter().any(|s| resultants(s).1 == 0.0),
        "the block lifts off"
    );
    let last = states.last().expect("states");
    let unaccounted = last.energy.unaccounted_since(&s0.energy);
    assert!(
        unaccounted.abs() < 1e-3 * s0.energy.strain,
        "{unaccounted:e} J unaccounted of {:e} J stored",
        s0.energy.strain
    );
}

/// Each problem in a load or an amplitude is reported with its field path.
#[test]
fn every_load_error_names_its_field() {
    let cases: [(&str, &str, &str); 15] = [
        (
            r#"loads[1].amplitude="ramp""#,
            "loads[1].amplitude",
            "no amplitude named 'ramp'",
        ),
        (
            r#"amplitudes[1].points=[[0.0, 0.0], [0.0, 1.0]]"#,
            "amplitudes[1].points[1]",
            "the times must increase",
        ),
        (
            r#"amplitudes[0].points=[[-1.0, 0.0]]"#,
            "amplitudes[0].points[0]",
            "expected a time >= 0",
        ),
        (
            r#"amplitudes[0].points=[]"#,
            "amplitudes[0].points",
            "at least one",
        ),
        (
            r#"amplitudes[1].name="press""#,
            "amplitudes[1].name",
            "unique",
        ),
        (
            r#"loads[0].body="nobody""#,
            "loads[0].body",
            "no rigid body named 'nobody'",
        ),
        (
            r#"loads[0]={"type": "concentrated", "node_set": "top", "body": "plate", "force": [1.0, 0.0]}"#,
            "loads[0]",
            "exactly one of node_set and body",
        ),
        (
            r#"loads[0]={"type": "concentrated", "body": "plate"}"#,
            "loads[0]",
            "a force, a moment or both",
        ),
        (r#"loads[0].force=[1.0]"#, "loads[0].force", "expected 2"),
        (
            r#"loads[0]={"type": "concentrated", "node_set": "top", "moment": [0.0, 0.0, 1.0]}"#,
            "loads[0].moment",
            "take no moment",
        ),
        (
            r#"loads[0].moment=[1.0, 0.0, 0.0]"#,
            "loads[0].moment",
            "Rx is not a degree of freedom in 2D",
        ),
        (
            r#"loads[0]={"type": "gravity", "acceleration": [0.0, -9.81, 0.0]}"#,
            "loads[0].acceleration",
            "expected 2",
        ),
        (
            r#"part.element_sets={"upper": [0, 4]}"#,
            "part.element_sets.upper",
            "element 4 does not exist (4 elements)",
        ),
        (
            r#"loads[0]={"type": "pressure", "surface": "top", "pressure": 1.0}"#,
            "loads[0].surface",
            "no surface named 'top'",
        ),
        (
            r#"loads[1].step_factors=[1.0, 2.0]"#,
            "loads[1].step_factors",
            "expected one factor per step (1 steps), got 2",
        ),
    ];
    for (set, field, fragment) in cases {
        let spec = scene_spec("2d-block-pushed-on-flat", &[set.to_string()]);
        let error = model_file::build::<2>(&spec).expect_err(set);
        assert_eq!(error.field, field, "{set}: {error:?}");
        assert!(error.message.contains(fragment), "{set}: {}", error.message);
    }
}

/// Loads that change between steps, from a deck (`2d-block-stick-then-slide-deck.inp`): the
/// block of the pushed scene pressed by N = 20 N in a static step, pushed sideways by
/// F = 3 N = 0.5 mu N in a second static step (`*CLOAD` adding a component), then by
/// F = 9 N = 1.5 mu N in a dynamic step (`*CLOAD` changing it).
///
/// The deck's loads become two loads of the model: the press, and the push with its factor in
/// each step (0, 1, 3). In the static steps the block is in equilibrium: no contact slides,
/// the friction resultant is -F at every increment of the push's ramp (F/4, F/2, 3F/4, F) and
/// the normal one N (during the press, its share of N), to the force tolerance (1e-6 of the
/// largest force; measured: 9e-8 of N for the normal resultant, 4e-10 for the friction one). Once the push is raised
/// every contact slides and the friction resultant is exactly -mu times the normal one (to
/// 1e-6, as in the pushed scene), and the block accelerates at `(F - mu N) / m = 3000 m/s^2`
/// (the plate's velocity after the 10 ms of the step, to 1e-3: the jump of the push sets the
/// block vibrating on its contacts).
#[test]
fn a_block_sticks_then_slides_as_the_loads_of_a_deck_change_between_steps() {
    let deck = skid_cases::deck::read_model(&repo(
        "cases/verification/2d-block-stick-then-slide-deck.inp",
    ))
    .expect("deck reads")
    .model;
    let expected_loads: Vec<(Vec<f64>, Option<Vec<f64>>)> = vec![
        (vec![0.0, -20.0], None),
        (vec![3.0, 0.0], Some(vec![0.0, 1.0, 3.0])),
    ];
    let loads: Vec<(Vec<f64>, Option<Vec<f64>>)> = deck
        .loads
        .iter()
        .map(|l| match l {
            LoadSpec::Concentrated {
                force: Some(force),
                step_factors,
                ..
            } => (force.clone(), step_factors.clone()),
            other => panic!("expected concentrated loads, got {other:?}"),
        })
        .collect();
    assert_eq!(loads, expected_loads);

    let scene = model_file::build::<2>(&deck).expect("scene builds");
    struct Steps(Vec<(String, State)>);
    impl Observer<2> for Steps {
        fn on_increment(&mut self, _: &Model<2>, r: &IncrementReport<'_>) -> std::io::Result<()> {
            self.0.push((r.step.to_string(), r.state.clone()));
            Ok(())
        }
    }
    let mut record = Steps(Vec::new());
    let (_, result) = run(&scene.model, &scene.steps, &scene.settings, &mut record);
    let last = result.expect("run completes");
    let in_step = |name: &str| -> Vec<&State> {
        record
            .0
            .iter()
            .filter(|(step, _)| step == name)
            .map(|(_, s)| s)
            .collect()
    };
    let (n, f) = (20.0, 3.0);
    let ramp = [0.25, 0.5, 0.75, 1.0];
    for (step, presses, pushes) in [("press", ramp, [0.0; 4]), ("stick", [1.0; 4], ramp)] {
        let states = in_step(step);
        assert_eq!(states.len(), 4, "{step}: increments");
        for ((state, press), push) in states.iter().zip(presses).zip(pushes) {
            let (t, normal) = resultants(state);
            assert!(
                (normal - press * n).abs() <= 1e-6 * n,
                "{step}: N = {normal}"
            );
            assert!((t + push * f).abs() <= 1e-6 * n, "{step}: T = {t}");
            let slipping = state
                .contacts
                .iter()
                .filter(|c| c.tangential_force.norm() >= MU * c.normal_force * (1.0 - 1e-9))
                .count();
            assert_eq!(slipping, 0, "{step}: contacts at the cone's edge, T = {t}");
        }
    }
    let sliding = in_step("slide");
    assert!(!sliding.is_empty());
    for state in &sliding {
        let (t, normal) = resultants(state);
        assert!(
            (t + MU * normal).abs() <= 1e-6 * MU * normal,
            "T = {t}, mu N = {}",
            MU * normal
        );
    }
    let v = last.v[plate_x(&scene.model)];
    let expected = (3.0 * f - MU * n) / MASS * 0.01;
    assert!(
        (v - expected).abs() <= 1e-3 * expected,
        "v = {v}, expected {expected}"
    );
}
