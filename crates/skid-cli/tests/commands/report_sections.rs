//! `skid report --hard` and `--convergence` on small synthetic run directories: the checks,
//! the observed orders and the exit codes.

use std::path::Path;
use std::process::Command;

use serde_json::{Value, json};

fn skid() -> Command {
    Command::new(env!("CARGO_BIN_EXE_skid"))
}

const CASE: &str = include_str!("../../../../cases/drum/2d-analytic.json");

/// The shipped 2D case with `edit` applied.
fn case(edit: impl Fn(&mut Value)) -> Value {
    let mut case: Value = serde_json::from_str(CASE).expect("shipped case");
    edit(&mut case);
    case
}

/// A run directory `dir`: the case as run, a history where the drum decelerates at `decel` from
/// 60 rad/s every `dt` to 0.15 s (after a static preload row), with the contact torque that
/// does it (I = 0.175 kg m^2, R = 0.2 m) from a friction of mu N on six sliding contacts (mu =
/// 0.15), and a summary that says so; `energy_error` is the energy balance error it reports.
fn write_run(dir: &Path, case: &Value, decel: f64, dt: f64, energy_error: f64) {
    std::fs::create_dir_all(dir).expect("mkdir");
    std::fs::write(dir.join("case.json"), case.to_string()).expect("case");
    let mut history = String::from(
        "time,step,drum_omega,normal_force,friction_force,friction_torque,active_contacts,\
         sliding_contacts\n0,initial,60,0,0,0,0,0\n0,preload,60,3500,0,0,6,0\n",
    );
    let n = (0.15 / dt).round() as usize;
    let omega = |k: usize| (60.0 - decel * k as f64 * dt).max(0.0);
    for k in 1..=n {
        let t = k as f64 * dt;
        let torque = 0.175 * (omega(k) - omega(k - 1)) / dt;
        let (friction, sliding) = (torque.abs() / 0.2, if torque != 0.0 { 6 } else { 0 });
        let normal = if sliding > 0 { friction / 0.15 } else { 3500.0 };
        history.push_str(&format!(
            "{t},spin-down,{},{normal},{friction},{torque},6,{sliding}\n",
            omega(k)
        ));
    }
    std::fs::write(dir.join("history.csv"), history).expect("history");
    let summary = json!({
        "case": case["name"],
        "dimension": 2,
        "status": "completed",
        "error": null,
        "t_stop": 60.0 / decel,
        "omega0": 60.0,
        "deceleration": decel,
        "deceleration_analytic": 600.0,
        "post_stop_max_abs_omega": 2.0,
        "post_stop_max_angle_change": 0.02,
        "energy_balance_error": energy_error,
        "energy_balance_residual_j": energy_error * 315.0,
        "max_gap_violation_m": 1e-12,
        "max_hourglass_ratio": 0.005,
        "max_sliding_separation_m": 1e-11,
        "increments": n + 5,
        "newton_iterations": 2 * n,
        "contact_solves": 2 * n,
        "cutbacks": 0,
        "wall_time_s": 0.5
    });
    std::fs::write(dir.join("summary.json"), summary.to_string()).expect("summary");
}

/// `skid report FLAG ROOT/DIR ... --out ROOT/report/report.md`: exit code, stdout, stderr and
/// the report text.
fn report(sections: &[(&str, &str)], root: &Path) -> (Option<i32>, String, String, String) {
    let out = root.join("report").join("report.md");
    let mut command = skid();
    command.arg("report");
    for (flag, dir) in sections {
        command.arg(flag).arg(root.join(dir));
    }
    let output = command.arg("--out").arg(&out).output().expect("runs");
    let text = std::fs::read_to_string(&out).unwrap_or_default();
    (
        output.status.code(),
        String::from_utf8_lossy(&output.stdout).into(),
        String::from_utf8_lossy(&output.stderr).into(),
        text,
    )
}

#[test]
fn hard_cases_are_checked_from_their_case_and_failures_exit_1() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let hard = tmp.path().join("hard");
    // t_stop 0.1007 s against the estimate 0.1 s; then a run losing 2 % of its energy.
    let good = case(|c| c["name"] = "2d-good".into());
    write_run(&hard.join("2d-good"), &good, 600.0 / 1.007, 1e-3, 1e-3);
    // Seven checks: the hourglass check does not apply to a pad one element thick.
    let (code, stdout, stderr, text) = report(&[("--hard", "hard")], tmp.path());
    assert_eq!(code, Some(0), "{stdout}\n{stderr}\n{text}");
    assert!(stdout.contains("7 passed, 0 failed"), "{stdout}");
    assert!(text.contains("## Hard cases"), "{text}");
    assert!(
        !text.contains("## Benchmark"),
        "only the sections asked for: {text}"
    );
    assert!(
        text.contains("| 2d-good | CPE4R | completed | 0.1007 | 0.1000 | +0.70 | 0.1000 |"),
        "{text}"
    );
    assert!(text.contains("skid batch cases/hard --out"), "{text}");
    let svg = std::fs::read_to_string(tmp.path().join("report/hard-omega.svg")).expect("plot");
    assert!(svg.contains("\n2d-good\n</text>"), "legend");

    let lossy = case(|c| c["name"] = "2d-lossy".into());
    write_run(&hard.join("2d-lossy"), &lossy, 600.0, 1e-3, 0.02);
    let (code, stdout, _, text) = report(&[("--hard", "hard")], tmp.path());
    assert_eq!(code, Some(1), "{stdout}");
    assert!(stdout.contains("13 passed, 1 failed"), "{stdout}");
    assert!(
        text.contains("- **FAIL** energy: 2.000 % of the drum energy lost (limit 1 %)"),
        "{text}"
    );

    // A run directory without its case cannot be checked: exit 2, naming the file.
    std::fs::remove_file(hard.join("2d-lossy/case.json")).expect("rm");
    let (code, _, stderr, _) = report(&[("--hard", "hard")], tmp.path());
    assert_eq!(code, Some(2));
    assert!(stderr.contains("2d-lossy/case.json"), "{stderr}");
}

#[test]
fn convergence_series_give_observed_orders_and_newton_rates() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let series = tmp.path().join("study").join("2d-time-step");
    // The deceleration converges as 600 + 4e6 dt^2 (order 2) at dt = 4e-4, 2e-4, 1e-4.
    for dt in [4e-4, 2e-4, 1e-4] {
        let c = case(|c| c["steps"][1]["dt"] = dt.into());
        write_run(
            &series.join(format!("dt-{dt}")),
            &c,
            600.0 + 4e6 * dt * dt,
            dt,
            1e-3,
        );
    }
    // increment 1's failed attempt has more checks than any converged increment: not shown
    let newton = "step,increment,time,size,iteration,force_residual,contact_residual,status\n\
                  preload,1,0,0.2,1,1e-2,1e-6,converged\n\
                  spin-down,1,8e-4,8e-4,1,1e-1,1e-7,rejected: newton not converged\n\
                  spin-down,1,8e-4,8e-4,2,1e-1,1e-7,rejected: newton not converged\n\
                  spin-down,1,8e-4,8e-4,3,1e-1,1e-7,rejected: newton not converged\n\
                  spin-down,1,8e-4,8e-4,4,1e-1,1e-7,rejected: newton not converged\n\
                  spin-down,1,4e-4,4e-4,1,1e-3,1e-7,converged\n\
                  spin-down,1,4e-4,4e-4,2,1e-6,1e-14,converged\n\
                  spin-down,2,8e-4,4e-4,1,1e-2,1e-5,converged\n\
                  spin-down,2,8e-4,4e-4,2,1e-4,1e-9,converged\n\
                  spin-down,2,8e-4,4e-4,3,1e-8,1e-16,converged\n";
    std::fs::write(series.join("dt-0.0004/newton.csv"), newton).expect("newton");
    let (code, stdout, stderr, text) = report(&[("--convergence", "study")], tmp.path());
    assert_eq!(code, Some(0), "{stdout}\n{stderr}");
    assert!(text.contains("### 2d-time-step (time step)"), "{text}");
    let orders = text
        .lines()
        .find(|l| l.starts_with("- dt-0.0004, dt-0.0002, dt-0.0001 (r = 2.000)"))
        .unwrap_or_else(|| panic!("no observed orders in\n{text}"));
    // t_stop = 60 / decel is smooth in dt^2 as well; the deceleration is exactly order 2
    // and extrapolates to 600.
    assert!(
        orders.contains("of the deceleration 2.000, extrapolated 600.0"),
        "{orders}"
    );
    assert!(
        orders.contains("observed order of t_stop 1.999"),
        "{orders}"
    );
    assert!(
        text.contains("step spin-down increment 2 (t = 8.000e-4 s)"),
        "the increment with the most iterations: {text}"
    );
    assert!(
        text.contains("| 3 | 1.000e-8 | 1.000e-16 | 1.000e-4 | 2.000 |"),
        "{text}"
    );
    assert!(tmp.path().join("report/newton.svg").is_file());

    // A level that differs in anything but the time step is not part of the series.
    let other = case(|c| {
        c["steps"][1]["dt"] = 5e-5.into();
        c["contact"]["mu"] = 0.2.into();
    });
    write_run(&series.join("dt-5e-5"), &other, 600.0, 5e-5, 1e-3);
    let (code, _, stderr, _) = report(&[("--convergence", "study")], tmp.path());
    assert_eq!(code, Some(2));
    assert!(
        stderr.contains("2d-time-step") && stderr.contains("differ in more than"),
        "{stderr}"
    );
}
