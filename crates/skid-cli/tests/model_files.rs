//! `skid convert` and `skid run` of model files: a converted case runs as a model file, a model
//! error exits with status 2 naming the file and the field, and `skid batch` says a model file is
//! not a case file.

use std::process::Command;

fn skid() -> Command {
    Command::new(env!("CARGO_BIN_EXE_skid"))
}

const CASE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../cases/drum/2d-analytic.json"
);

#[test]
fn a_converted_case_runs_as_a_model_file() {
    let dir = tempfile::tempdir().expect("tempdir");
    let model = dir.path().join("model.json");
    let out = skid()
        .args(["convert", CASE, "-o"])
        .arg(&model)
        .output()
        .expect("converts");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&model).expect("model file");
    assert!(text.contains("\"skid_model\": 1"), "{}", &text[..200]);
    let out = skid()
        .arg("run")
        .arg(&model)
        .arg("--out")
        .arg(dir.path().join("run"))
        .args(["--set", "steps[1].duration=0.002"])
        .output()
        .expect("runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one line of JSON");
    assert_eq!(summary["model"], "2d-analytic");
    assert_eq!(summary["status"], "completed");
    assert_eq!(summary["bodies"][0]["name"], "drum");
    assert!(summary["bodies"][0]["omega"].as_f64().expect("omega") < 60.0);
    for file in ["model.json", "history.csv", "newton.csv", "summary.json"] {
        assert!(dir.path().join("run").join(file).is_file(), "{file}");
    }
}

#[test]
fn a_model_error_exits_with_status_2_naming_the_field() {
    let dir = tempfile::tempdir().expect("tempdir");
    let model = dir.path().join("model.json");
    assert!(
        skid()
            .args(["convert", CASE, "-o"])
            .arg(&model)
            .status()
            .expect("converts")
            .success()
    );
    let out = skid()
        .arg("run")
        .arg(&model)
        .arg("--out")
        .arg(dir.path().join("run"))
        .args(["--set", "ties[0].body=\"plate\""])
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("model.json")
            && stderr.contains("ties[0].body")
            && stderr.contains("no rigid body named 'plate'"),
        "{stderr}"
    );
    assert!(!dir.path().join("run").join("summary.json").exists());
}

#[test]
fn batch_says_a_model_file_is_not_a_case_file() {
    let dir = tempfile::tempdir().expect("tempdir");
    let model = dir.path().join("model.json");
    assert!(
        skid()
            .args(["convert", CASE, "-o"])
            .arg(&model)
            .status()
            .expect("converts")
            .success()
    );
    let out = skid()
        .arg("batch")
        .arg(&model)
        .arg("--out")
        .arg(dir.path().join("batch"))
        .output()
        .expect("runs");
    assert!(!out.status.success());
    let all = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(all.contains("model file"), "{all}");
}
