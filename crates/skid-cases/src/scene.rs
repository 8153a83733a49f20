//! Where an input becomes the scene skid integrates: a case file through the drum builder, a
//! model file through its builder, an input deck through its reader into a model file first.
//! The runner and the check build their scenes here, so that `skid check` refuses exactly what
//! `skid run` would.

use std::path::Path;

use crate::deck::read_model;
use crate::drum;
use crate::model_file::{self, Scene};
use crate::model_spec::ModelSpec;
use crate::schema::Case;
use crate::validate::CaseError;

/// Reads an input deck into its model with `overrides` applied to the model's fields (as in a
/// model file), with the notes on what skid reads differently from the deck's requests.
///
/// # Errors
/// [`CaseError::Deck`] naming the deck line at fault, or a bad override.
pub fn read_deck_model(
    path: &Path,
    overrides: &[String],
) -> Result<(ModelSpec, Vec<String>), CaseError> {
    let deck = read_model(path)?;
    if overrides.is_empty() {
        return Ok((deck.model, deck.notes));
    }
    let text = model_file::to_json(&deck.model).map_err(|e| CaseError::Read {
        path: path.to_path_buf(),
        source: std::io::Error::new(std::io::ErrorKind::InvalidData, e),
    })?;
    let model = model_file::parse_model(&text, path, overrides)?;
    Ok((model, deck.notes))
}

/// The scene of a validated case, as run.
///
/// # Errors
/// [`CaseError::Model`] if the model cannot be built.
pub(crate) fn case_scene<const D: usize>(
    case: &Case,
    source: &Path,
) -> Result<Scene<D>, CaseError> {
    drum::build::<D>(case).map_err(|message| CaseError::Model {
        path: source.to_path_buf(),
        message,
    })
}

/// The scene of a model, as run.
///
/// # Errors
/// [`CaseError::Invalid`] naming the field at fault.
pub(crate) fn model_scene<const D: usize>(
    spec: &ModelSpec,
    source: &Path,
) -> Result<Scene<D>, CaseError> {
    model_file::build::<D>(spec).map_err(|e| CaseError::Invalid {
        path: source.to_path_buf(),
        field: e.field,
        message: e.message,
    })
}
