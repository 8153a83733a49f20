//! `skid convert`: a drum case file, a model file or an input deck written as a model file
//! (`.json`) or as a deck (`.inp`), by the output's extension.
//!
//! - case file -> model file or deck (the deck carries the drum's own rigid elements);
//! - model file -> deck;
//! - deck -> model file.
//!
//! Exit codes: 0 written; 2 the input or the command line is invalid, or the output format
//! cannot express the input; 3 the output could not be written.

use std::path::Path;
use std::process::ExitCode;

use skid_cases::atomic::write_atomic;
use skid_cases::deck::is_deck;
use skid_cases::deck::write::write_deck;
use skid_cases::drum::{deck, model_spec};
use skid_cases::model_file::{parse_model, to_json};
use skid_cases::model_spec::declares_model;
use skid_cases::{load_case, read_deck_model};

/// Writes `input` (with `overrides`) to `out` as a model file or a deck; running the output
/// gives the same results as running the input.
pub fn run(input: &Path, overrides: &[String], out: &Path) -> ExitCode {
    let to_deck = is_deck(out);
    let text = match convert(input, overrides, to_deck) {
        Ok(text) => text,
        Err(message) => {
            eprintln!("skid: {message}");
            return ExitCode::from(2);
        }
    };
    match write_atomic(out, text) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("skid: {}: cannot write: {e}", out.display());
            ExitCode::from(3)
        }
    }
}

fn convert(input: &Path, overrides: &[String], to_deck: bool) -> Result<String, String> {
    let shown = input.display();
    if is_deck(input) {
        if to_deck {
            return Err(format!(
                "{shown}: is already a deck; write a model file (.json)"
            ));
        }
        let (spec, notes) = read_deck_model(input, overrides).map_err(|e| e.to_string())?;
        for note in notes {
            eprintln!("skid: note: {note}");
        }
        return to_json(&spec).map_err(|e| format!("{shown}: cannot be written as JSON: {e}"));
    }
    let text = std::fs::read_to_string(input).map_err(|e| format!("{shown}: cannot read: {e}"))?;
    if declares_model(&text) {
        if !to_deck {
            return Err(format!(
                "{shown}: is already a model file; write a deck (.inp)"
            ));
        }
        let spec = parse_model(&text, input, overrides).map_err(|e| e.to_string())?;
        return write_deck(&spec, &Default::default())
            .map_err(|m| format!("{shown}: cannot be written as a deck: {m}"));
    }
    let case = load_case(input, overrides).map_err(|e| e.to_string())?;
    if to_deck {
        deck(&case).map_err(|m| format!("{shown}: cannot be written as a deck: {m}"))
    } else {
        let spec = model_spec(&case).map_err(|m| format!("{shown}: model: {m}"))?;
        to_json(&spec).map_err(|e| format!("{shown}: cannot be written as JSON: {e}"))
    }
}
