//! `skid check`: every shipped case file, model file and deck builds (exit 0, one `ok` line
//! each); every entry of the bad-input corpus fails with exactly the message `skid run` gives
//! for it (exit 2), and nothing is written.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn skid(cwd: &Path, args: &[&std::ffi::OsStr]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_skid"))
        .current_dir(cwd)
        .args(args)
        .output()
        .expect("skid runs")
}

/// The command line of `command` on an entry, with its overrides.
fn entry_args<'a>(command: &'a str, entry: &'a common::Entry) -> Vec<&'a std::ffi::OsStr> {
    let mut args = vec![command.as_ref(), entry.case.as_os_str()];
    for spec in &entry.overrides {
        args.push("--set".as_ref());
        args.push(spec.as_ref());
    }
    args
}

#[test]
fn every_bad_input_fails_check_with_the_message_of_run() {
    let entries = common::entries();
    assert!(
        entries.len() >= common::files_with("json").len() + common::files_with("inp").len(),
        "every file of the corpus has an entry"
    );
    for entry in &entries {
        let cwd = tempfile::tempdir().expect("tempdir");
        let label = entry.expect.display();
        let check = skid(cwd.path(), &entry_args("check", entry));
        let run = skid(cwd.path(), &entry_args("run", entry));
        let stderr = String::from_utf8_lossy(&check.stderr);
        assert_eq!(check.status.code(), Some(2), "{label}: {stderr}");
        assert_eq!(
            stderr,
            String::from_utf8_lossy(&run.stderr),
            "{label}: check and run give the same message"
        );
        for fragment in &entry.messages {
            assert!(
                stderr.contains(fragment),
                "{label}: {fragment:?} in {stderr}"
            );
        }
        assert!(check.stdout.is_empty(), "{label}: no ok line");
        assert!(
            std::fs::read_dir(cwd.path()).expect("cwd").next().is_none(),
            "{label}: nothing written"
        );
    }
}

/// The shipped inputs of a directory of the repository: its `*.json` and `*.inp` files.
fn shipped(dir: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(dir);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("shipped directory")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "json" || e == "inp"))
        .collect();
    files.sort();
    files
}

#[test]
fn every_shipped_input_checks_ok_and_nothing_is_written() {
    let files: Vec<PathBuf> = [
        "cases/drum",
        "cases/hard",
        "cases/verification",
        "cases/inp",
    ]
    .iter()
    .flat_map(|dir| shipped(dir))
    .collect();
    assert!(files.len() >= 35, "{} files", files.len());
    let cwd = tempfile::tempdir().expect("tempdir");
    let mut args: Vec<&std::ffi::OsStr> = vec!["check".as_ref()];
    args.extend(files.iter().map(|f| f.as_os_str()));
    let out = skid(cwd.path(), &args);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert!(!stderr.contains("skid: ") || stderr.lines().all(|l| l.starts_with("skid: note: ")));
    let lines: Vec<&str> = stdout.lines().collect();
    // a line per file, a sweep file's per run (`FILE: RUN: ok (...)`)
    let of = |file: &PathBuf| {
        let prefix = format!("{}: ", file.display());
        lines
            .iter()
            .filter(move |l| l.starts_with(&prefix))
            .collect::<Vec<_>>()
    };
    for file in &files {
        let own = of(file);
        assert!(!own.is_empty(), "{} not checked: {stdout}", file.display());
        for line in own {
            assert!(
                line.contains("ok (") && line.contains(" equations, "),
                "{line}"
            );
        }
    }
    assert_eq!(
        files.iter().map(|f| of(f).len()).sum::<usize>(),
        lines.len(),
        "{stdout}"
    );
    let analytic = lines
        .iter()
        .find(|l| l.contains("cases/drum/2d-analytic.json: ok"))
        .expect("2d-analytic checked");
    assert!(
        analytic.contains("case file '2d-analytic', 2D,")
            && analytic.contains(" 10 elements, ")
            && analytic.contains(" 11 contact candidates, ")
            && analytic.contains(" 2 steps, at least ")
            && analytic.ends_with(" kB of memory)"),
        "{analytic}"
    );
    assert!(
        std::fs::read_dir(cwd.path()).expect("cwd").next().is_none(),
        "nothing written"
    );
}

#[test]
fn one_bad_file_among_good_ones_exits_2_and_the_others_are_still_checked() {
    let cwd = tempfile::tempdir().expect("tempdir");
    let bad = cwd.path().join("broken.json");
    std::fs::write(&bad, "{ \"name\": ").expect("write");
    let good = shipped("cases/drum").remove(0);
    let out = skid(
        cwd.path(),
        &["check".as_ref(), bad.as_os_str(), good.as_os_str()],
    );
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("broken.json"), "{stderr}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains(&format!("{}: ok (", good.display())),
        "{stdout}"
    );
}

#[test]
fn a_sweep_file_is_checked_run_by_run() {
    let cwd = tempfile::tempdir().expect("tempdir");
    let sweeps = shipped("cases/sweeps");
    assert!(!sweeps.is_empty());
    let mut args: Vec<&std::ffi::OsStr> = vec!["check".as_ref()];
    args.extend(sweeps.iter().map(|f| f.as_os_str()));
    let out = skid(cwd.path(), &args);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    let friction = sweeps
        .iter()
        .find(|f| f.ends_with("2d-friction-pressure.json"))
        .expect("the friction sweep");
    for i in 1..=12 {
        let line = format!(
            "{}: 2d-friction-pressure-{i:02}: ok (case file '2d-friction-pressure-{i:02}', 2D,",
            friction.display()
        );
        assert!(stdout.contains(&line), "{line} in {stdout}");
    }
    let bad = skid(
        cwd.path(),
        &[
            "check".as_ref(),
            friction.as_os_str(),
            "--set".as_ref(),
            "pad.density=0".as_ref(),
        ],
    );
    assert_eq!(bad.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&bad.stderr);
    assert_eq!(stderr.lines().count(), 12, "{stderr}");
    assert!(
        stderr.lines().all(|l| l.contains("pad.density")),
        "{stderr}"
    );
}
