//! `skid report`: the validation report of a batch of runs.
//!
//! Exit codes: 0 the report was written and every acceptance check passed (or was skipped);
//! 1 the report was written but a check failed; 2 the runs or the reference could not be read;
//! 3 the report or its plots could not be written.

use std::path::Path;
use std::process::ExitCode;

use skid_cases::{ReportError, write_report};

/// Writes the report of the runs in `runs` to `out`.
pub fn run(runs: &Path, reference: Option<&str>, out: &Path) -> ExitCode {
    match write_report(runs, reference, out) {
        Ok(outcome) => {
            for file in &outcome.files {
                println!("wrote {}", file.display());
            }
            let n = outcome.counts;
            println!(
                "reference {}: {} passed, {} failed, {} skipped",
                outcome.reference, n.passed, n.failed, n.skipped
            );
            if n.failed > 0 {
                ExitCode::from(1)
            } else {
                ExitCode::SUCCESS
            }
        }
        Err(e) => {
            eprintln!("skid: {e}");
            ExitCode::from(match e {
                ReportError::Plot { .. } | ReportError::Write { .. } => 3,
                _ => 2,
            })
        }
    }
}
