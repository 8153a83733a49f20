//! `skid report`: the validation report of the benchmark runs, the hard cases, the
//! convergence study and the cost against problem size; or the sweep report of batch
//! directories.
//!
//! Exit codes: 0 the report was written and every acceptance check passed (or was skipped),
//! or for a sweep every run is listed and ended as expected; 1 the report was written but a
//! check failed, or runs are missing or did not end as expected; 2 the runs, the reference,
//! the study or a batch could not be read; 3 the report or its plots could not be written.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use skid_report::sweep::write_sweep_report;
use skid_report::{ReportError, ReportSources, write_report};

/// The exit code of a report that could not be written.
fn failure(e: &ReportError) -> ExitCode {
    eprintln!("skid: {e}");
    ExitCode::from(match e {
        ReportError::Plot { .. } | ReportError::Write { .. } => 3,
        _ => 2,
    })
}

/// Writes the sweep report of the batch directories `dirs` to `out`.
pub fn run_sweep(dirs: &[PathBuf], out: &Path) -> ExitCode {
    match write_sweep_report(dirs, out) {
        Ok(outcome) => {
            println!("wrote {}", out.display());
            println!("{}", outcome.line());
            if outcome.missing > 0 || outcome.unexpected > 0 {
                ExitCode::from(1)
            } else {
                ExitCode::SUCCESS
            }
        }
        Err(e) => failure(&e),
    }
}

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
        Err(e) => failure(&e),
    }
}
