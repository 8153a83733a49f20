//! The bad-input corpus (`cases/bad/`, see its README): `skid run` on each entry exits 2 with a
//! message naming the case file and every fragment the entry's `.expect` lists, never panics,
//! and leaves no output behind.

use std::path::Path;
use std::process::Command;

use crate::common;
use crate::common::{Entry, corpus, files_with};

fn any_file_named(dir: &Path, name: &str) -> bool {
    std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .flatten()
        .any(|e| {
            let p = e.path();
            p.file_name().is_some_and(|n| n == name) || (p.is_dir() && any_file_named(&p, name))
        })
}

#[test]
fn every_case_file_of_the_corpus_has_its_expected_message() {
    for case in files_with("json").into_iter().chain(files_with("inp")) {
        assert!(
            case.with_extension("expect").exists(),
            "{} has no .expect",
            case.display()
        );
    }
}

#[test]
fn every_bad_input_exits_2_naming_the_file_and_field_and_writes_nothing() {
    let entries: Vec<Entry> = common::entries();
    assert!(entries.len() >= 45, "{} entries", entries.len());
    for entry in &entries {
        // Run where a default output directory (out/<name>) would land in a fresh directory.
        let cwd = tempfile::tempdir().expect("tempdir");
        let mut command = Command::new(env!("CARGO_BIN_EXE_skid"));
        command.current_dir(cwd.path()).arg("run").arg(&entry.case);
        for spec in &entry.overrides {
            command.args(["--set", spec]);
        }
        let out = command.output().expect("skid runs");
        let stderr = String::from_utf8_lossy(&out.stderr);
        let label = entry.expect.display();
        assert_eq!(out.status.code(), Some(2), "{label}: {stderr}");
        assert!(!stderr.contains("panicked"), "{label}: {stderr}");
        assert!(
            stderr.contains(&entry.case.display().to_string()),
            "{label}: the message names the file: {stderr}"
        );
        for fragment in &entry.messages {
            assert!(
                stderr.contains(fragment),
                "{label}: {fragment:?} in {stderr}"
            );
        }
        assert_eq!(
            stderr.lines().count(),
            1,
            "{label}: one line of message: {stderr}"
        );
        assert!(out.stdout.is_empty(), "{label}: no summary printed");
        assert!(
            std::fs::read_dir(cwd.path()).expect("cwd").next().is_none(),
            "{label}: nothing written"
        );
        assert!(!any_file_named(cwd.path(), "summary.json"));
    }
}

#[test]
fn a_batch_of_the_corpus_records_every_file_as_an_error_and_runs_none() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = Command::new(env!("CARGO_BIN_EXE_skid"))
        .arg("batch")
        .arg(corpus())
        .arg("--out")
        .arg(dir.path())
        .output()
        .expect("skid runs");
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    let batch: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("batch.json")).expect("batch.json"),
    )
    .expect("json");
    let entries = batch.as_array().expect("array");
    assert_eq!(
        entries.len(),
        files_with("json").len() + files_with("inp").len()
    );
    for entry in entries {
        assert_eq!(entry["status"], "error", "{entry}");
        assert!(entry["summary"].is_null(), "{entry}");
    }
    assert!(!any_file_named(dir.path(), "summary.json"));
}
