//! `skid batch` on a directory with two short drum cases and a malformed file, then
//! `skid report` on its runs.

use std::path::Path;
use std::process::Command;

fn skid() -> Command {
    Command::new(env!("CARGO_BIN_EXE_skid"))
}

const CASE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../cases/drum/2d-analytic.json"
);

/// The shipped 2D case renamed `name`, with its spin-down shortened to 0.01 s.
fn short_case(dir: &Path, name: &str) {
    let text = std::fs::read_to_string(CASE).expect("shipped case");
    let mut case: serde_json::Value = serde_json::from_str(&text).expect("json");
    case["name"] = name.into();
    case["steps"][1]["duration"] = 0.01.into();
    let text = serde_json::to_string_pretty(&case).expect("json");
    std::fs::write(dir.join(format!("{name}.json")), text).expect("write");
}

#[test]
fn batch_runs_good_cases_past_a_bad_one_and_report_compares_them() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let cases = tmp.path().join("cases");
    std::fs::create_dir(&cases).expect("mkdir");
    short_case(&cases, "short-a");
    short_case(&cases, "short-b");
    std::fs::write(cases.join("broken.json"), "{ \"name\": ").expect("write");
    let runs = tmp.path().join("runs");

    let out = skid()
        .arg("batch")
        .arg(&cases)
        .arg("--out")
        .arg(&runs)
        .args(["--jobs", "2"])
        .output()
        .expect("runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stdout}\n{stderr}");
    assert!(stderr.contains("broken.json"), "{stderr}");
    for name in ["short-a", "short-b"] {
        let line = stdout
            .lines()
            .find(|l| l.starts_with(name))
            .unwrap_or_else(|| panic!("no line for {name}: {stdout}"));
        assert!(line.contains("completed"), "{line}");
        for file in ["history.csv", "summary.json"] {
            assert!(runs.join(name).join(file).is_file(), "{name}/{file}");
        }
    }
    assert!(
        stdout
            .lines()
            .any(|l| l.starts_with("broken") && l.contains("error")),
        "{stdout}"
    );

    let batch: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(runs.join("batch.json")).expect("read"))
            .expect("batch.json is JSON");
    let entries = batch.as_array().expect("an array");
    assert_eq!(entries.len(), 3);
    let status = |name: &str| {
        entries
            .iter()
            .find(|e| e["name"] == name)
            .map(|e| (e["status"].clone(), e["case_file"].clone()))
            .unwrap_or_else(|| panic!("no entry {name}"))
    };
    // Sorted by file name: broken.json, short-a.json, short-b.json.
    assert_eq!(entries[0]["name"], "broken");
    assert_eq!(status("broken").0, "error");
    assert!(
        entries[0]["error"]
            .as_str()
            .is_some_and(|e| e.contains("broken.json"))
    );
    for name in ["short-a", "short-b"] {
        assert_eq!(status(name).0, "completed");
        assert!(
            status(name)
                .1
                .as_str()
                .is_some_and(|f| f.ends_with(&format!("{name}.json")))
        );
        let entry = entries.iter().find(|e| e["name"] == name).expect("entry");
        assert_eq!(entry["summary"]["case"], name);
        assert!(
            entry["summary"]["increments"]
                .as_u64()
                .is_some_and(|n| n > 100)
        );
    }

    let report = tmp.path().join("report").join("report.md");
    let out = skid()
        .arg("report")
        .arg("--runs")
        .arg(&runs)
        .args(["--reference", "short-a", "--out"])
        .arg(&report)
        .output()
        .expect("runs");
    // The exit status says whether every acceptance check passed: these 10 ms runs never
    // stop the drum, so some checks fail, and the report is written all the same.
    let stdout = String::from_utf8_lossy(&out.stdout);
    let failed = !stdout.contains(" 0 failed");
    assert_eq!(
        out.status.code(),
        Some(if failed { 1 } else { 0 }),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&report).expect("report written");
    assert!(text.contains("Reference: **short-a**"), "{text}");
    for name in ["short-a", "short-b"] {
        assert!(
            text.contains(&format!("| {name} | 2D | completed |")),
            "{text}"
        );
    }
    for svg in ["omega.svg", "omega-difference.svg"] {
        let plot = std::fs::read_to_string(report.with_file_name(svg)).expect("plot written");
        assert!(
            plot.starts_with("<svg") && plot.contains("<polyline"),
            "{svg}"
        );
        assert!(
            plot.contains("\nshort-b\n</text>"),
            "{svg} lacks the legend"
        );
        assert!(text.contains(&format!("]({svg})")), "{svg} not linked");
    }

    let missing = skid()
        .arg("report")
        .arg("--runs")
        .arg(&runs)
        .args(["--reference", "nope", "--out"])
        .arg(tmp.path().join("x.md"))
        .output()
        .expect("runs");
    assert_eq!(missing.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&missing.stderr).contains("short-a"));
}

/// A case that stops with the failure it expects does not fail the batch; one that expects
/// another failure does, and both keep their results.
#[test]
fn batch_exits_0_when_a_case_fails_as_it_expects() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let cases = tmp.path().join("cases");
    std::fs::create_dir(&cases).expect("mkdir");
    let shipped = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../cases/hard/2d-pressure-x10.json"
    );
    // on one-point elements the pad folds under this load (the case runs it on CPE4)
    let text = std::fs::read_to_string(shipped).expect("shipped case");
    let mut case: serde_json::Value = serde_json::from_str(&text).expect("json");
    case["pad"]["formulation"] = "reduced".into();
    case["expect"]["failure"] = "inverted_element".into();
    std::fs::write(cases.join("folds.json"), case.to_string()).expect("write");
    let runs = tmp.path().join("runs");
    let batch = |dir: &Path| {
        let out = skid()
            .arg("batch")
            .arg(dir)
            .arg("--out")
            .arg(&runs)
            .output()
            .expect("runs");
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stdout).to_string(),
        )
    };
    let (code, stdout) = batch(&cases);
    assert_eq!(code, Some(0), "{stdout}");
    assert!(
        stdout.contains("2d-pressure-x10  failed_as_expected"),
        "{stdout}"
    );
    assert!(
        stdout.contains("0 of 1 cases completed, 1 stopped with the failure their case expects"),
        "{stdout}"
    );
    assert!(runs.join("2d-pressure-x10/history.csv").is_file());

    case["expect"]["failure"] = "newton_not_converged".into();
    std::fs::write(cases.join("folds.json"), case.to_string()).expect("write");
    let (code, stdout) = batch(&cases);
    assert_eq!(code, Some(1), "{stdout}");
    assert!(stdout.contains("2d-pressure-x10  failed "), "{stdout}");
    assert!(runs.join("2d-pressure-x10/summary.json").is_file());
}
