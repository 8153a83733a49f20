//! `skid convert`: the model file of a drum case file.
//!
//! Exit codes: 0 written; 2 the case file or the command line is invalid; 3 the model file
//! could not be written.

use std::path::Path;
use std::process::ExitCode;

use skid_cases::atomic::write_atomic;
use skid_cases::drum::model_spec;
use skid_cases::load_case;
use skid_cases::model_file::to_json;

/// Writes the model file of `case` (with `overrides`) to `out`; running it gives the same
/// results as running the case.
pub fn run(case: &Path, overrides: &[String], out: &Path) -> ExitCode {
    let case_spec = match load_case(case, overrides) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("skid: {e}");
            return ExitCode::from(2);
        }
    };
    let spec = match model_spec(&case_spec) {
        Ok(spec) => spec,
        Err(message) => {
            eprintln!("skid: {}: model: {message}", case.display());
            return ExitCode::from(2);
        }
    };
    match write_atomic(out, to_json(&spec)) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("skid: {}: cannot write: {e}", out.display());
            ExitCode::from(3)
        }
    }
}
