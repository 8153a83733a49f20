//! End to end: the drum against the analytical circle (2D) and cylinder (3D) spins down as the
//! benchmark says (DRUM.md sections 2.2 and 3), and without friction it keeps spinning.

use std::path::Path;

use skid_cases::csv_out::CsvTable;
use skid_cases::{Summary, parse_case, run_case};

const CASE_2D: &str = include_str!("../../../../cases/drum/2d-analytic.json");
const CASE_3D: &str = include_str!("../../../../cases/drum/3d-analytic.json");
const CASE_2D_R2D2: &str = include_str!("../../../../cases/drum/2d-r2d2.json");
const CASE_3D_C3D4: &str = include_str!("../../../../cases/drum/3d-c3d4.json");
const CASE_3D_GENERAL: &str = include_str!("../../../../cases/drum/3d-analytic-general.json");

fn run_text(text: &str, overrides: &[&str]) -> (Summary, tempfile::TempDir) {
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let case = parse_case(text, Path::new("case.json"), &overrides).expect("case");
    let dir = tempfile::tempdir().expect("tempdir");
    let summary = run_case(&case, Path::new("case.json"), dir.path()).expect("run");
    (summary, dir)
}

fn run(overrides: &[&str]) -> (Summary, tempfile::TempDir) {
    run_text(CASE_2D, overrides)
}

/// The benchmark's acceptance band for one run.
fn assert_benchmark_spin_down(s: &Summary) {
    assert_eq!(s.status, "completed", "{:?}", s.error);
    let t_stop = s.t_stop.expect("the drum stops");
    assert!((0.0990..=0.1015).contains(&t_stop), "t_stop {t_stop}");
    let decel = s.deceleration.expect("fit");
    assert!(
        (decel - 600.0).abs() < 0.015 * 600.0,
        "deceleration {decel}"
    );
    // While sliding the normal force is the plate force plus the tilt of the side contacts
    // (3510.6 N in the independent 2D model).
    let n = s.mean_normal_force_sliding.expect("normal force");
    assert!((n - 3510.6).abs() < 10.0, "normal force {n}");
    assert!(s.post_stop_max_abs_omega.expect("post") < 5.0);
    assert!(s.post_stop_max_angle_change.expect("post") < 0.03);
    assert!(s.energy_balance_error.expect("balance") < 0.005);
    assert!(s.max_gap_violation_m < 1e-6 && s.max_sliding_separation_m < 1e-6);
}

/// Against a smooth drum, the normal forces do no work: all 315 J of kinetic energy go into
/// friction (facets make the pad ride over their corners, so there part of it is normal work).
fn assert_all_energy_goes_into_friction(s: &Summary) {
    let friction = s.friction_work_j.expect("friction");
    assert!((friction - 315.0).abs() < 2.0, "friction work {friction}");
}

#[test]
fn drum_3d_spins_down_like_the_2d_one() {
    let (s3, _dir) = run_text(CASE_3D, &[]);
    assert_eq!(s3.dimension, 3);
    assert_benchmark_spin_down(&s3);
    assert_all_energy_goes_into_friction(&s3);
}

#[test]
fn drum_spins_down_in_a_straight_line_and_rocks_in_stick_after_the_stop() {
    let (s, dir) = run(&[]);
    assert_benchmark_spin_down(&s);
    assert_all_energy_goes_into_friction(&s);
    let t_stop = s.t_stop.expect("the drum stops");
    // Outputs are complete: renamed from .partial, one history row per increment plus the
    // initial state.
    let path = dir.path().join("history.csv");
    let history = std::fs::read_to_string(&path).expect("history");
    let records = CsvTable::new(&history, &path).expect("header").count();
    assert_eq!(records, s.cost.increments + 1);
    assert!(!dir.path().join("history.csv.partial").exists());
    let written: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("summary.json")).expect("summary"),
    )
    .expect("json");
    assert_eq!(written["t_stop"].as_f64(), Some(t_stop));
}

/// Under ten times the pressure, friction switched on at full speed sets the pad's contact
/// nodes sliding back and forth along the drum by about a millimetre per increment under some
/// 5 kN each. The contact force must do no work on that motion beyond `p_N dg`: along the
/// end-of-increment normal it did `p_N ds^2 / (2 R)` per node and increment, 1.9 J created in
/// these 2 ms (first order in the time step). Without numerical dissipation (alpha = 0) what is
/// left is the trapezoidal rule's error, 0.1 J. (Half a millisecond later the one-point pad's
/// leading element folds; the hard case 2d-pressure-x10 runs this load on CPE4.)
#[test]
fn normal_contact_forces_do_no_work_on_nodes_sliding_along_the_drum() {
    let (s, _dir) = run(&[
        "back_plate.pressure=3.5e6",
        "pad.hourglass_scale=3",
        "steps[1].alpha=0",
        "steps[1].duration=0.002",
    ]);
    assert_eq!(s.status, "completed", "{:?}", s.error);
    let residual = s.energy_balance_residual_j.expect("residual");
    assert!(residual.abs() < 0.5, "energy residual {residual} J");
}

/// A faceted drum braked from 7 rad/s at mu = 1.5 by a coarse pad in 9 ms steps rocks back and
/// forth in stick-slip, turning by up to 4 degrees (most of a 5-degree facet) per increment. The
/// contact rows must stay a discrete gradient over such a turn: with the end-point derivative in
/// the drum's angle the contact created 16.5 J of the 45 J in play (a seeded stress run, see
/// `scripts/stress.py --seed 1 --only 306`); what is left is round-off.
#[test]
fn contact_forces_on_a_turning_facet_do_exactly_the_work_of_the_contact_law() {
    let (s, _dir) = run_text(
        CASE_2D_R2D2,
        &[
            "contact.mu=1.547",
            "back_plate.pressure=1164000.0",
            "drum.omega0=7.252",
            "pad.elements.circumferential=4",
            "pad.elements.radial=1",
            "steps[0].increments=4",
            "steps[1].dt=0.009357",
            "steps[1].duration=0.205854",
            "steps[1].alpha=-0.211",
        ],
    );
    assert_eq!(s.status, "completed", "{:?}", s.error);
    let residual = s.energy_balance_residual_j.expect("residual");
    assert!(residual.abs() < 0.05, "energy residual {residual} J");
}

/// A run that Newton cannot finish says where its residual is worst.
#[test]
fn an_unconverged_increment_names_where_its_residual_is_worst() {
    let (s, _dir) = run(&["solver.max_newton_iterations=1", "solver.max_cutbacks=0"]);
    assert_eq!(s.status, "failed");
    assert_eq!(s.failure.as_deref(), Some("newton not converged"));
    let error = s.error.expect("a diagnosis");
    let worst = error
        .split("; worst ")
        .nth(1)
        .expect("the worst residual is named");
    assert!(
        worst.starts_with("force at node ")
            || worst.starts_with("force on rigid body ")
            || worst.starts_with("moment on rigid body ")
            || worst.starts_with("contact of node "),
        "{error}"
    );
}

#[test]
fn without_friction_the_drum_keeps_its_speed() {
    let (s, dir) = run(&["contact.mu=0", "steps[1].duration=0.01"]);
    assert_eq!(s.status, "completed", "{:?}", s.error);
    assert_eq!(s.t_stop, None);
    // Nothing to lose: the balance is judged in joules, against the drum's 315 J.
    assert_eq!(s.energy_balance_error, None);
    let residual = s.energy_balance_residual_j.expect("residual");
    assert!(
        residual.abs() < 1e-3 * 315.0,
        "energy residual {residual} J"
    );
    let path = dir.path().join("history.csv");
    let history = std::fs::read_to_string(&path).expect("history");
    let table = CsvTable::new(&history, &path).expect("header");
    let col = table.column("drum_omega").expect("column");
    for row in table {
        let omega: f64 = row.expect("record").number(col).expect("number");
        assert!((omega - 60.0).abs() < 1e-9 * 60.0, "omega {omega}");
    }
}

fn relative(a: Option<f64>, b: Option<f64>) -> f64 {
    let (a, b) = (a.expect("stops"), b.expect("stops"));
    (a - b).abs() / b
}

#[test]
fn faceted_2d_drum_agrees_with_the_analytic_circle() {
    let (facets, _d1) = run_text(CASE_2D_R2D2, &[]);
    let (circle, _d2) = run(&[]);
    assert_benchmark_spin_down(&facets);
    assert!(relative(facets.t_stop, circle.t_stop) < 0.01);
}

#[test]
fn tetrahedral_drum_and_general_contact_agree_with_the_3d_analytic_pair() {
    let (tets, _d1) = run_text(CASE_3D_C3D4, &[]);
    let (general, _d2) = run_text(CASE_3D_GENERAL, &[]);
    let (pair, _d3) = run_text(CASE_3D, &[]);
    assert_benchmark_spin_down(&tets);
    assert_benchmark_spin_down(&general);
    assert!(relative(tets.t_stop, pair.t_stop) < 0.01);
    // General contact finds the same contacts as the pair: same spin-down to 0.1 %.
    assert!(relative(general.t_stop, pair.t_stop) < 0.001);
}

/// With 1.6 ms steps (sixteen times the benchmark's) the mass term no longer hides the
/// stiffness of the contact forces on the curved drum: Newton converges quadratically only
/// because that term is in its matrix. Read from `newton.csv`: each force residual between
/// 1e-3 and 0.1 is followed by one below its square (`e_k+1 <= C e_k^2` with `C = 1`; measured
/// `C` up to 0.15, while the linear rate 0.05 that the matrix without the term gave means
/// `C ~ 50` at `e_k = 1e-3`), wherever the next one is above 1e-9, the accuracy of the contact
/// forces. Below 1e-3 (a thousand times the force tolerance) the step reuses the last
/// factorization by design, a chord step that converges linearly.
#[test]
fn large_steps_converge_quadratically() {
    let (s, dir) = run(&["steps[1].dt=1.6e-3", "steps[1].duration=0.02"]);
    assert_eq!(s.status, "completed", "{:?}", s.error);
    let path = dir.path().join("newton.csv");
    let text = std::fs::read_to_string(&path).expect("newton.csv");
    let table = CsvTable::new(&text, &path).expect("header");
    let column = |name| table.column(name).expect(name);
    let (step, number, force, status) = (
        column("step"),
        column("increment"),
        column("force_residual"),
        column("status"),
    );
    let mut histories: std::collections::BTreeMap<usize, Vec<f64>> = Default::default();
    for row in table {
        let row = row.expect("record");
        if row.text(step).expect("step") == "spin-down"
            && row.text(status).expect("status") == skid_cases::newton::CONVERGED
        {
            let increment = row.number(number).expect("increment");
            let residual = row.number(force).expect("force residual");
            histories.entry(increment).or_default().push(residual);
        }
    }
    let constants: Vec<f64> = histories
        .values()
        .flat_map(|history| history.windows(2))
        .filter(|e| e[0] < 0.1 && e[0] > 1e-3 && e[1] > 1e-9)
        .map(|e| e[1] / (e[0] * e[0]))
        .collect();
    assert!(constants.len() >= 10, "too few iterations: {histories:?}");
    assert!(
        constants.iter().all(|&c| c <= 1.0),
        "e_k+1 / e_k^2: {constants:?}"
    );
}

/// Adaptive increments down to 5e-8 s on the spinning drum (the controller takes them near
/// contact changes at a tolerance of 2.5e-7): the inertia term amplifies the round-off of the
/// drum's angle by `1 / (beta h^2)` to 2e-5 of the forces there, above the force tolerance, and
/// Newton stalled at that floor until the increment failed (at 13 ms, measured). A residual
/// within the round-off of its inertia term now counts as converged.
#[test]
fn very_short_increments_converge_to_their_round_off() {
    let (s, dir) = run(&[
        "steps[1].dt=5e-5",
        "steps[1].duration=0.02",
        r#"steps[1].adaptive={"tolerance":2.5e-7,"min_dt":5e-8,"max_dt":2.5e-3}"#,
    ]);
    assert_eq!(s.status, "completed", "{:?}", s.error);
    // the controller did take increments near the smallest
    let path = dir.path().join("history.csv");
    let text = std::fs::read_to_string(&path).expect("history");
    let table = CsvTable::new(&text, &path).expect("header");
    let dt = table.column("dt").expect("dt");
    let smallest = table
        .map(|row| row.expect("row").number::<f64>(dt).expect("dt"))
        .filter(|&h| h > 0.0)
        .fold(f64::INFINITY, f64::min);
    assert!(smallest < 1e-6, "smallest increment {smallest} s");
}

/// A pad preloaded at 1 MPa onto a resting, frictionless tetrahedral drum must stay where the
/// static step put it when the dynamic step takes 1 ms increments. With the smooth acceleration
/// (which leaves out the contact forces) extrapolated into Newton's first iterate, the loaded
/// front nodes started each increment about a centimetre inside the drum, bulged over its rim
/// onto the end caps, and the pad slid down the drum's side (the plate moved 18 cm in 5 ms).
#[test]
fn a_preloaded_pad_stays_put_on_a_resting_drum_at_millisecond_steps() {
    let (s, dir) = run_text(
        CASE_3D_C3D4,
        &[
            "contact.mu=0",
            "back_plate.pressure=1e6",
            "drum.omega0=0",
            "steps[1].dt=1e-3",
            "steps[1].duration=0.005",
        ],
    );
    assert_eq!(s.status, "completed", "{:?}", s.error);
    let path = dir.path().join("history.csv");
    let history = std::fs::read_to_string(&path).expect("history");
    let table = CsvTable::new(&history, &path).expect("header");
    let column = |name| table.column(name).expect(name);
    let (step, plate) = (column("step"), column("plate_displacement"));
    let rows: Vec<(String, f64)> = table
        .map(|row| {
            let row = row.expect("record");
            let name = row.text(step).expect("step").to_string();
            (name, row.number(plate).expect("number"))
        })
        .collect();
    let preloaded = rows
        .iter()
        .rev()
        .find(|(name, _)| name == "preload")
        .expect("preload rows")
        .1;
    for (_, displacement) in rows.iter().filter(|(name, _)| name == "spin-down") {
        let moved = displacement - preloaded;
        assert!(moved.abs() < 1e-6, "the plate moved {moved} m");
    }
    assert!(s.max_gap_violation_m < 1e-6);
}

/// A quasi-static pad (no inertia) spins the drum down within the benchmark's band, with a
/// deceleration that no longer depends on the time step: the pad vibration that moves the
/// dynamic pad's deceleration with dt and density is gone.
#[test]
fn a_quasi_static_pad_gives_a_deceleration_independent_of_the_time_step() {
    let (fine, _d1) = run(&["pad.quasi_static=true", "steps[1].dt=4e-4"]);
    let (coarse, _d2) = run(&["pad.quasi_static=true", "steps[1].dt=1.6e-3"]);
    for s in [&fine, &coarse] {
        assert_benchmark_spin_down(s);
        assert_all_energy_goes_into_friction(s);
    }
    let d = relative(fine.deceleration, coarse.deceleration);
    assert!(d < 1e-7, "deceleration moves by {d} between 0.4 and 1.6 ms");
}

/// Adaptive increments on the quasi-static pad: a fraction of the fixed steps' increments for
/// the same deceleration, and an increment that ends where the drum stops (omega = 0 there
/// to round-off), so the stop time is not an interpolation across a sticking increment.
#[test]
fn adaptive_increments_land_on_the_stop_with_the_fixed_steps_answer() {
    let adaptive = r#"steps[1].adaptive={"tolerance":1e-4,"min_dt":1e-7,"max_dt":5e-3}"#;
    let (fixed, _d1) = run(&["pad.quasi_static=true"]);
    let (s, dir) = run(&["pad.quasi_static=true", adaptive]);
    assert_benchmark_spin_down(&s);
    assert!(
        s.cost.increments * 10 < fixed.cost.increments,
        "{} adaptive increments against {} fixed",
        s.cost.increments,
        fixed.cost.increments
    );
    let d = relative(s.deceleration, fixed.deceleration);
    assert!(d < 1e-7, "deceleration differs by {d}");
    let t = relative(s.t_stop, fixed.t_stop);
    assert!(t < 5e-4, "t_stop differs by {t}");
    let path = dir.path().join("history.csv");
    let history = std::fs::read_to_string(&path).expect("history");
    let table = CsvTable::new(&history, &path).expect("header");
    let (time, omega) = (
        table.column("time").expect("time"),
        table.column("drum_omega").expect("omega"),
    );
    let t_stop = s.t_stop.expect("stops");
    let landed = table.map(|row| row.expect("record")).any(|row| {
        let t: f64 = row.number(time).expect("time");
        let w: f64 = row.number(omega).expect("omega");
        (t - t_stop).abs() < 1e-9 && w.abs() < 1e-9 * 60.0
    });
    assert!(landed, "no increment ends at the stop {t_stop}");
}

/// The pad of fully integrated elements (CPE4, CPE4H, CPE4I) spins the drum down as the
/// one-point pad does: the benchmark's band, all the energy into friction.
#[test]
fn every_pad_element_formulation_gives_the_benchmark_spin_down() {
    for formulation in ["full", "hybrid", "incompatible"] {
        let (s, _dir) = run(&[&format!("pad.formulation=\"{formulation}\"")]);
        assert_benchmark_spin_down(&s);
        assert_all_energy_goes_into_friction(&s);
    }
}

/// The 40 x 4 pad of incompatible-mode elements, pressed onto the held drum, has a tangent
/// without its contacts that is indefinite: the Cholesky-based reduction to the contact forces
/// could factor it only with the mass term raised a thousandfold, and Newton then contracted by
/// 0.87 per iteration until the increment was cut back (25 iterations, measured). The preload
/// now goes on with global contact steps on the tangent itself: every preload increment
/// converges at its first attempt, in at most five iterations.
#[test]
fn an_indefinite_pad_tangent_preloads_in_a_few_newton_iterations() {
    let (s, dir) = run(&[
        "pad.formulation=\"incompatible\"",
        "pad.elements.circumferential=40",
        "pad.elements.radial=4",
        "steps[1].duration=0.002",
    ]);
    assert_eq!(s.status, "completed", "{:?}", s.error);
    assert!(s.cost.global_switches > 0, "no increment switched");
    assert_eq!(s.cost.cutbacks, 0);
    let path = dir.path().join("newton.csv");
    let text = std::fs::read_to_string(&path).expect("newton.csv");
    let table = CsvTable::new(&text, &path).expect("header");
    let column = |name| table.column(name).expect(name);
    let (step, number, status) = (column("step"), column("increment"), column("status"));
    let mut iterations: std::collections::BTreeMap<usize, usize> = Default::default();
    for row in table {
        let row = row.expect("record");
        if row.text(step).expect("step") == "preload" {
            assert_eq!(
                row.text(status).expect("status"),
                skid_cases::newton::CONVERGED
            );
            *iterations
                .entry(row.number(number).expect("increment"))
                .or_default() += 1;
        }
    }
    assert_eq!(iterations.len(), 5, "{iterations:?}");
    assert!(iterations.values().all(|&n| n <= 5), "{iterations:?}");
}
