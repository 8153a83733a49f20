//! `skid run`: one case file or model file, or the continuation of an interrupted run
//! (`--resume DIR`).
//!
//! Exit codes: 0 the run completed (or, resuming, had completed already); 1 the run stopped
//! early (its summary says where and why); 2 the case file or the command line is invalid, or
//! the run cannot be resumed (no restart file, another input, or outputs written so far that
//! are missing or changed); 3 results could not be written.

use std::path::Path;
use std::process::ExitCode;

use skid_cases::restart::DEFAULT_RESTART_EVERY;
use skid_cases::{CaseError, Resumed, resume_run, run_file};

/// Runs `case` (a case file or a model file, with `overrides`) into `out`, writing a restart
/// file every `restart_every` increments (default [`DEFAULT_RESTART_EVERY`]), and prints the
/// summary as one line of JSON.
pub fn run(
    case: &Path,
    overrides: &[String],
    out: Option<&Path>,
    restart_every: Option<usize>,
) -> ExitCode {
    let every = restart_every.unwrap_or(DEFAULT_RESTART_EVERY);
    match run_file(case, overrides, out, every) {
        Ok(summary) => {
            let name = case.display().to_string();
            warn(&name, summary.warnings());
            finished(&name, serde_json::to_string(&summary), summary.error())
        }
        Err(e) => failed(&e),
    }
}

/// Continues the interrupted run in `dir` (checking it against `case` with `overrides` if
/// given) and prints its summary as one line of JSON; a run that had ended already is not run
/// again: its summary is printed with a note.
pub fn resume(
    dir: &Path,
    case: Option<&Path>,
    overrides: &[String],
    restart_every: Option<usize>,
) -> ExitCode {
    let name = dir.display().to_string();
    match resume_run(dir, case.map(|c| (c, overrides)), restart_every) {
        Ok(Resumed::Continued(summary)) => {
            warn(&name, summary.warnings());
            finished(&name, serde_json::to_string(&summary), summary.error())
        }
        Ok(Resumed::AlreadyEnded(summary)) => {
            eprintln!("skid: {name}: the run has ended already (summary.json); nothing to resume");
            let error = summary.get("error").and_then(|e| e.as_str());
            finished(&name, serde_json::to_string(&summary), error)
        }
        Err(e) => failed(&e),
    }
}

/// Prints the summary's warnings on standard error.
fn warn(name: &str, warnings: &[String]) {
    for warning in warnings {
        eprintln!("skid: {name}: warning: {warning}");
    }
}

/// Prints the summary, `line` (one line of JSON); exit code 0, or 1 with `error` (the run
/// stopped early).
fn finished(name: &str, line: serde_json::Result<String>, error: Option<&str>) -> ExitCode {
    match line {
        Ok(line) => println!("{line}"),
        Err(e) => eprintln!("skid: cannot print the summary: {e}"),
    }
    if let Some(error) = error {
        eprintln!("skid: {name}: run stopped early: {error}");
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}

/// Reports `e`; exit code 3 for unwritable results, 2 otherwise.
fn failed(e: &CaseError) -> ExitCode {
    eprintln!("skid: {e}");
    ExitCode::from(match e {
        CaseError::Output { .. } => 3,
        _ => 2,
    })
}
