//! Two deformable bodies in one model: `cases/verification/2d-two-pads-on-drum.json`, the drum
//! of `cases/drum/2d-analytic.json` braked by its pad and by a copy of it turned by 180 degrees
//! about the drum axis, each pressed by its own back plate.
//!
//! While the drum slides under both pads, Coulomb friction is mu N whatever the slip speed, so
//! each pad goes through exactly the history of the single pad, and the drum, whose equation
//! is linear in the friction torque, loses speed twice as fast: omega_2(t) = 2 omega_1(t) -
//! omega0 increment by increment, and each pad's resultants are the single pad's.

use std::path::{Path, PathBuf};

use skid_cases::drum::model_spec;
use skid_cases::load_case;
use skid_cases::model_file::{self, parse_model};
use skid_cases::model_spec::ModelSpec;
use skid_integrator::stepper::{IncrementReport, Observer, run};
use skid_integrator::{Model, State};

/// The spin-down is cut to 40 ms, before the two-pad drum stops (at 50.7 ms).
const SPIN_DOWN: &str = "steps[1].duration=0.04";

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(path)
}

/// Every converged state.
struct Record(Vec<State>);

impl<const D: usize> Observer<D> for Record {
    fn on_increment(&mut self, _: &Model<D>, r: &IncrementReport<'_>) -> std::io::Result<()> {
        self.0.push(r.state.clone());
        Ok(())
    }
}

/// The drum's angular velocity and the pairs' normal and friction resultants at every
/// converged state of `spec`.
fn drum_history(spec: &ModelSpec) -> Vec<(f64, Vec<(f64, f64)>)> {
    let scene = model_file::build::<2>(spec).expect("scene builds");
    let mut record = Record(Vec::new());
    let (_, result) = run(&scene.model, &scene.steps, &scene.settings, &mut record);
    result.expect("run completes");
    let omega = scene.model.dofs().body_rotation(0).expect("the drum turns");
    let pairs = scene.model.contacts().len();
    record
        .0
        .iter()
        .map(|s| {
            let resultants = (0..pairs)
                .map(|p| {
                    let of = s.contacts.iter().filter(|c| c.pair == p);
                    (
                        of.clone().map(|c| c.normal_force).sum(),
                        of.map(|c| c.tangential_force[0]).sum(),
                    )
                })
                .collect();
            (s.v[omega], resultants)
        })
        .collect()
}

#[test]
fn two_pads_brake_the_drum_exactly_twice_as_hard_as_one() {
    let path = repo("cases/verification/2d-two-pads-on-drum.json");
    let text = std::fs::read_to_string(&path).expect("read scene");
    let two = parse_model(&text, &path, &[SPIN_DOWN.to_string()]).expect("scene parses");
    let case = load_case(
        &repo("cases/drum/2d-analytic.json"),
        &[SPIN_DOWN.to_string()],
    )
    .expect("case loads");
    let one = model_spec(&case).expect("the drum case as a model");
    let (two, one) = (drum_history(&two), drum_history(&one));
    assert_eq!(two.len(), one.len(), "increments");
    let omega0 = 60.0;
    let (mut worst_omega, mut worst_force) = (0.0_f64, 0.0_f64);
    for (k, ((w2, pads), (w1, pad))) in two.iter().zip(&one).enumerate() {
        assert!(*w2 > 0.0, "increment {k}: the drum still turns");
        worst_omega = worst_omega.max((w2 - (2.0 * w1 - omega0)).abs() / omega0);
        let (n, t) = pad[0];
        for &(np, tp) in pads {
            worst_force = worst_force.max((np - n).abs().max((tp - t).abs()) / n.max(1.0));
        }
    }
    // the two solves differ by what Newton leaves, 1e-6 of the forces at most (measured: the
    // forces by 2.7e-7 of N, omega by 7.2e-11 of omega0)
    assert!(
        worst_omega <= 1e-8,
        "omega differs by {worst_omega:e} of omega0"
    );
    assert!(
        worst_force <= 1e-6,
        "the pad forces differ by {worst_force:e} of N"
    );
    // the pads brake: by 40 ms the drum has lost more than 45 of its 60 rad/s
    assert!(two.last().expect("increments").0 < 15.0);
}
