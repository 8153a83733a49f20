//! `skid schema`: the JSON Schema of case files or model files, or their markdown reference,
//! generated from the types that read them.
//!
//! Exit codes: 0 written; 2 the command line is invalid; 3 the output file could not be
//! written.

use std::path::Path;
use std::process::ExitCode;

use skid_cases::reference::{Format, markdown as reference, schema_text};

/// Prints the schema (or with `markdown` the reference) of `format`, or writes it to `out`.
pub fn run(format: Format, markdown: bool, out: Option<&Path>) -> ExitCode {
    let text = if markdown {
        reference(format)
    } else {
        schema_text(format)
    };
    match out {
        None => {
            print!("{text}");
            ExitCode::SUCCESS
        }
        Some(path) => match std::fs::write(path, text) {
            Ok(()) => {
                println!("wrote {}", path.display());
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("skid: {}: cannot write: {e}", path.display());
                ExitCode::from(3)
            }
        },
    }
}
