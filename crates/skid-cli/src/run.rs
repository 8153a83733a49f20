//! `skid run`: one case file or model file.
//!
//! Exit codes: 0 the run completed; 1 the run stopped early (its summary says where and why);
//! 2 the case file or the command line is invalid; 3 results could not be written.

use std::path::Path;
use std::process::ExitCode;

use skid_cases::{CaseError, run_file};

/// Runs `case` (a case file or a model file, with `overrides`) into `out`, printing the summary
/// as one line of JSON.
pub fn run(case: &Path, overrides: &[String], out: Option<&Path>) -> ExitCode {
    match run_file(case, overrides, out) {
        Ok(summary) => {
            match serde_json::to_string(&summary) {
                Ok(line) => println!("{line}"),
                Err(e) => eprintln!("skid: cannot print the summary: {e}"),
            }
            if let Some(error) = summary.error() {
                eprintln!("skid: {}: run stopped early: {error}", case.display());
                ExitCode::from(1)
            } else {
                ExitCode::SUCCESS
            }
        }
        Err(e) => {
            eprintln!("skid: {e}");
            ExitCode::from(match e {
                CaseError::Output { .. } => 3,
                _ => 2,
            })
        }
    }
}
