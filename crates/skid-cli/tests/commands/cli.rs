//! The `skid` binary: exit codes, messages and output files.

use skid_cases::csv_out::CsvTable;

use crate::common::{skid, succeeds};

const CASE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../cases/drum/2d-analytic.json"
);

#[test]
fn run_writes_history_and_summary_and_prints_one_json_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = succeeds(
        skid()
            .args(["run", CASE, "--out"])
            .arg(dir.path())
            .args(["--set", "steps[1].duration=0.005"]),
    );
    let stdout = String::from_utf8(out.stdout).expect("utf8");
    assert_eq!(stdout.lines().count(), 1);
    let summary: serde_json::Value = serde_json::from_str(&stdout).expect("json line");
    assert_eq!(summary["case"], "2d-analytic");
    assert_eq!(summary["status"], "completed");
    for key in [
        "t_stop",
        "omega0",
        "increments",
        "newton_iterations",
        "contact_solves",
        "wall_time_s",
        "energy_balance_error",
        "max_gap_violation_m",
        "max_sliding_separation_m",
    ] {
        assert!(summary.get(key).is_some(), "summary lacks {key}");
    }
    let history_path = dir.path().join("history.csv");
    let history = std::fs::read_to_string(&history_path).expect("history");
    let table = CsvTable::new(&history, &history_path).expect("header");
    for column in [
        "time",
        "drum_angle",
        "drum_omega",
        "normal_force",
        "friction_force",
        "friction_torque",
        "active_contacts",
        "newton_iterations",
        "contact_solves",
    ] {
        assert!(table.column(column).is_ok(), "history lacks {column}");
    }
    assert!(dir.path().join("summary.json").exists());

    // newton.csv: one row per Newton iteration of every converged increment (and of failed
    // attempts, marked as rejected), the residuals of the last one of each converged increment
    // within the tolerances.
    let newton_path = dir.path().join("newton.csv");
    let newton = std::fs::read_to_string(&newton_path).expect("newton.csv");
    let table = CsvTable::new(&newton, &newton_path).expect("header");
    let column = |name| table.column(name).expect(name);
    let (iteration, force_column, contact_column, status) = (
        column("iteration"),
        column("force_residual"),
        column("contact_residual"),
        column("status"),
    );
    let rows: Vec<_> = table
        .map(|row| row.expect("record"))
        .filter(|row| row.text(status).expect("status") == "converged")
        .collect();
    assert_eq!(
        Some(rows.len() as u64),
        summary["newton_iterations"].as_u64()
    );
    for (k, row) in rows.iter().enumerate() {
        let last_of_increment = rows
            .get(k + 1)
            .is_none_or(|next| next.number::<usize>(iteration).expect("iteration") == 1);
        let force: f64 = row.number(force_column).expect("force residual");
        let contact: f64 = row.number(contact_column).expect("contact residual");
        assert!(force.is_finite() && contact.is_finite(), "{row:?}");
        if last_of_increment {
            assert!(force <= 1e-6 && contact <= 1e-9, "not converged: {row:?}");
        }
    }
    // case.json: the case as run, overrides applied.
    let case: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("case.json")).expect("case.json"),
    )
    .expect("json");
    assert_eq!(case["steps"][1]["duration"].as_f64(), Some(0.005));
    assert_eq!(case["name"], "2d-analytic");
}

#[test]
fn bad_case_file_exits_2_naming_file_and_field() {
    let dir = tempfile::tempdir().expect("tempdir");
    let bad = dir.path().join("bad.json");
    let text = std::fs::read_to_string(CASE)
        .expect("case")
        .replace("\"density\": 1000.0", "\"density\": -1000.0");
    std::fs::write(&bad, text).expect("write");
    let out = skid().arg("run").arg(&bad).output().expect("runs");
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("bad.json"), "{stderr}");
    assert!(stderr.contains("pad.density"), "{stderr}");
    assert!(stderr.contains("expected a finite value > 0"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");

    let missing = skid()
        .args(["run", "/nonexistent.json"])
        .output()
        .expect("runs");
    assert_eq!(missing.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&missing.stderr).contains("cannot read"));
}

#[test]
fn a_run_that_cannot_converge_exits_1_and_says_where() {
    // One Newton iteration with no cutback cannot converge the preload.
    let dir = tempfile::tempdir().expect("tempdir");
    let out = skid()
        .args(["run", CASE, "--out"])
        .arg(dir.path())
        .args([
            "--set",
            "solver.max_newton_iterations=1",
            "--set",
            "solver.max_cutbacks=0",
        ])
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("step 'preload' failed at increment 1"),
        "{stderr}"
    );
    let summary: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("summary.json")).expect("summary kept"),
    )
    .expect("json");
    assert_eq!(summary["status"], "failed");
    assert!(
        dir.path().join("history.csv").exists(),
        "results so far are kept"
    );
}

#[test]
fn bench_rejects_an_unknown_method_and_a_ladder_without_the_case_time_step() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = skid()
        .args(["bench", CASE, "--methods", "dense", "--out"])
        .arg(dir.path())
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains(
            "expected one of case, reduced, global, adaptive, quasi-static, quasi-static-adaptive, got \"dense\""
        ),
        "{stderr}"
    );
    let out = skid()
        .args(["bench", CASE, "--levels", "1", "--coarser", "1", "--out"])
        .arg(dir.path())
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("fewer coarser levels than levels, got 1 levels"),
        "{stderr}"
    );
    assert!(!dir.path().join("bench.json").exists());
}

/// `skid bench` runs every run in a process of its own: the level's case file is written beside
/// its run, the record's answer is the one `skid run` gives for that file, bit for bit, and on
/// Linux the record has the peak memory of that process.
#[test]
fn bench_runs_each_level_in_a_process_of_its_own() {
    let dir = tempfile::tempdir().expect("tempdir");
    let text = std::fs::read_to_string(CASE).expect("case");
    let mut case: serde_json::Value = serde_json::from_str(&text).expect("json");
    case["steps"][1]["duration"] = serde_json::json!(0.005);
    let short = dir.path().join("short.json");
    std::fs::write(&short, case.to_string()).expect("write");
    let bench = dir.path().join("bench");
    succeeds(
        skid()
            .arg("bench")
            .arg(&short)
            .args(["--levels", "1", "--coarser", "0", "--repeats", "1"])
            .args(["--methods", "reduced", "--out"])
            .arg(&bench),
    );
    let records: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(bench.join("bench.json")).expect("bench.json"),
    )
    .expect("json");
    let record = &records[0];
    assert_eq!(records.as_array().map(Vec::len), Some(1));
    let level = bench.join("runs/2d-analytic/reduced/0.json");
    assert!(level.is_file(), "the level's case file");
    let alone = dir.path().join("alone");
    let out = succeeds(
        skid()
            .arg("run")
            .arg(&level)
            .arg("--out")
            .arg(&alone)
            .args(["--restart-every", "0"]),
    );
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).expect("summary");
    for key in ["deceleration", "t_stop", "increments", "newton_iterations"] {
        assert_eq!(record[key], summary[key], "{key}");
    }
    assert!(record["deceleration"].is_f64());
    if cfg!(target_os = "linux") {
        let peak = record["peak_memory_mb"]
            .as_f64()
            .expect("peak memory on Linux");
        assert!(peak > 1.0, "{peak} MB");
        assert!(summary["peak_memory_mb"].as_f64().is_some_and(|p| p > 1.0));
    }
}
