//! `skid check`: reads, validates and builds case files, model files, decks and the runs of
//! sweep files without running them; prints `FILE: ok (...)` (`FILE: RUN: ok (...)` for a sweep
//! run) for each that builds, and for each that does not the message `skid run` would give.
//!
//! Exit codes: 0 every file builds; 2 some file is invalid (as `skid run` exits on it).

use std::path::PathBuf;
use std::process::ExitCode;

use skid_cases::check::check_path;

/// Checks every file of `files` with `overrides` applied to each.
pub fn run(files: &[PathBuf], overrides: &[String]) -> ExitCode {
    let mut bad = 0;
    for checked in files.iter().flat_map(|file| check_path(file, overrides)) {
        match checked.result {
            Ok(report) => {
                for note in &report.notes {
                    eprintln!("skid: note: {note}");
                }
                println!("{}: ok ({})", checked.label, report.line());
            }
            Err(e) => {
                eprintln!("skid: {e}");
                bad += 1;
            }
        }
    }
    if bad == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(2)
    }
}
