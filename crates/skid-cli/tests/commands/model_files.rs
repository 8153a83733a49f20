//! `skid convert` and `skid run` of model files: a converted case runs as a model file, a model
//! error exits with status 2 naming the file and the field, and `skid batch` says a model file is
//! not a case file.

use crate::common::{skid, succeeds};

const CASE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../cases/drum/2d-analytic.json"
);

#[test]
fn a_converted_case_runs_as_a_model_file() {
    let dir = tempfile::tempdir().expect("tempdir");
    let model = dir.path().join("model.json");
    succeeds(skid().args(["convert", CASE, "-o"]).arg(&model));
    let text = std::fs::read_to_string(&model).expect("model file");
    assert!(text.contains("\"skid_model\": 1"), "{}", &text[..200]);
    let out = succeeds(
        skid()
            .arg("run")
            .arg(&model)
            .arg("--out")
            .arg(dir.path().join("run"))
            .args(["--set", "steps[1].duration=0.002"]),
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

/// A batch runs case files, model files and decks side by side, each into its own directory,
/// and the model file and the deck of one case give its history.
#[test]
fn batch_runs_case_files_model_files_and_decks() {
    let dir = tempfile::tempdir().expect("tempdir");
    let inputs = dir.path().join("inputs");
    std::fs::create_dir(&inputs).expect("mkdir");
    for (to, name) in [("model.json", "as-model"), ("deck.inp", "as-deck")] {
        let target = inputs.join(to);
        assert!(
            skid()
                .args(["convert", CASE, "-o"])
                .arg(&target)
                .args(["--set", &format!("name=\"{name}\"")])
                .args(["--set", "steps[1].duration=0.001"])
                .status()
                .expect("converts")
                .success()
        );
    }
    // a model file keeps its name; a deck is named after its file
    let out = skid()
        .arg("batch")
        .arg(&inputs)
        .arg("--out")
        .arg(dir.path().join("batch"))
        .output()
        .expect("runs");
    let all = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.status.success(), "{all}");
    let batch: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("batch/batch.json")).expect("batch.json"),
    )
    .expect("json");
    let names: Vec<&str> = batch
        .as_array()
        .expect("array")
        .iter()
        .map(|e| e["name"].as_str().expect("name"))
        .collect();
    assert_eq!(names, ["deck", "as-model"]);
    let deck = std::fs::read_to_string(dir.path().join("batch/deck/history.csv")).expect("deck");
    let model =
        std::fs::read_to_string(dir.path().join("batch/as-model/history.csv")).expect("model");
    assert_eq!(deck, model);
}
