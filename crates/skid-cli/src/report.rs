//! `skid report`: the validation report of the benchmark runs, the hard cases and the
//! convergence study.
//!
//! Exit codes: 0 the report was written and every acceptance check passed (or was skipped);
//! 1 the report was written but a check failed; 2 the runs, the reference or the study could
//! not be read; 3 the report or its plots could not be written.

use std::path::Path;
use std::process::ExitCode;

use skid_cases::{ReportError, ReportSources, write_report};

/// Writes the report of `sources` to `out`.
pub fn run(sources: &ReportSources<'_>, out: &Path) -> ExitCode {
    match write_report(sources, out) {
        Ok(outcome) => {
            for file in &outcome.files {
                println!("wrote {}", file.display());
            }
            let n = outcome.counts;
            if let Some(reference) = &outcome.reference {
                println!("reference {reference}");
            }
            println!("{}", n.line());
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
